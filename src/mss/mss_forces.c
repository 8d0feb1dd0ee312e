// SPDX-License-Identifier: MIT
// Forces on a mass-spring tree (Lim & Gobeawan 2024 sec. 3.3): gravity, wind, air drag,
// phototropism, gravitropism; and the internal forces of its springs and hinges.
//
// Wind and drag. The paper's load (eqs. 9-10) is F = A P C_d along the wind, P = 0.613 |v|^2
// (= rho |v|^2 / 2 at rho = 1.226 kg/m^3, the ASCE 7 velocity pressure), A the node's
// cross-section pi r^2. The default load is the rods': the air velocity relative to the plant,
// u = wind - v, its component normal to each internode on the projected area 2 r l (a cylinder in
// cross flow, C_d ~ 1.2), and on the leaf area hanging from a node (C_d leaf). Quadratic drag is
// that relative velocity: a tree moving through still air feels rho C_d A |v| v / 2, right at
// plant Reynolds numbers (10^2 - 10^5). Stokes' law 6 pi eta R v (eq. 11) holds only for Re < 1
// (a 5 mm stem at 0.1 m/s in air has Re ~ 30); it is the paper's option, not the default.
//
// Tropisms. Phototropism pulls each bud toward the light point with light_k / d^2 (intensity
// falls as 1/d^2). Gravitropism by the sine law (Dumais 2013) pushes every node but the buds
// across its internode, upward, with gravi_k sin A (A the internode's angle to the vertical);
// Bastien et al.'s AC model acts on the rest shape instead (sim_mss_stress.c).
#include "mss_internal.h"

// the upward direction: against gravity, +z without gravity
static vd_vec3 up_dir(const vd_mss_opt* o) {
  double g = v_norm(o->gravity);
  return g > 0 ? vd_scale(o->gravity, -1.0 / g) : vd_v3(0, 0, 1);
}

void mss_external(const vd_mss_model* m, vd_mss_data* d, mss_work* w) {
  const vd_mss_opt* o = &m->opt;
  int nn = m->nnode;
  for (int i = 0; i < nn; i++) {
    d->fext[i] = vd_v3(0, 0, 0);
    w->cdrag[i] = 0;
    if (d->removed[i]) continue;
    d->fext[i] = vd_add(vd_scale(o->gravity, d->mass[i]), d->force[i]);
  }
  vd_vec3 wind = vd_wind_at(o->wind, o->gust_amplitude, o->gust_period, o->wind_series, o->nwind, d->time);
  double q = 0.5 * o->air_density;
  int relative = o->drag == VD_MSS_DRAG_QUADRATIC;
  if (o->wind_model == VD_MSS_WIND_PAPER) {
    // eqs. 9-10 on each node's cross-section (relative to the node's motion with quadratic drag)
    for (int i = 0; i < nn; i++) {
      if (d->removed[i] || (m->node_flags[i] & (VD_MSS_SOIL | VD_MSS_ROOT))) continue;
      vd_vec3 u = relative ? vd_sub(wind, d->vel[i]) : wind;
      double a = VD_PI * m->node_radius[i] * m->node_radius[i], un = v_norm(u);
      d->fext[i] = vd_madd(d->fext[i], u, q * o->drag_cd * a * un);
      if (relative) w->cdrag[i] += 2 * q * o->drag_cd * a * un;
    }
  } else {
    // internodes as cylinders in cross flow, half of each on either end
    for (int s = 0; s < m->ninter; s++) {
      if (d->spring_broken[s]) continue;
      int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
      if (d->removed[i] || d->removed[j] || (m->node_flags[j] & VD_MSS_ROOT)) continue;
      vd_vec3 v = relative ? vd_scale(vd_add(d->vel[i], d->vel[j]), 0.5) : vd_v3(0, 0, 0);
      vd_vec3 u = vd_sub(wind, v);
      vd_vec3 e = vd_normalize(vd_sub(d->pos[j], d->pos[i]));
      vd_vec3 un = vd_madd(u, e, -vd_dot(u, e));
      double area = (m->spring_radius[2 * s] + m->spring_radius[2 * s + 1]) * m->spring_l0[s];
      double nu = v_norm(un);
      vd_vec3 f = vd_scale(un, q * o->drag_cd * area * nu);
      double c = relative ? 2 * q * o->drag_cd * area * nu : 0;
      int hi = !(m->node_flags[i] & VD_MSS_SOIL);
      double si = hi ? 0.5 : 0.0;
      d->fext[i] = vd_madd(d->fext[i], f, si);
      d->fext[j] = vd_madd(d->fext[j], f, 1 - si);
      w->cdrag[i] += si * c;
      w->cdrag[j] += (1 - si) * c;
    }
    // leaves, fruits and flowers on their node
    for (int i = 0; i < nn; i++) {
      if (d->removed[i] || m->node_leaf_area[i] <= 0) continue;
      vd_vec3 u = relative ? vd_sub(wind, d->vel[i]) : wind;
      double un = v_norm(u), a = m->node_leaf_area[i];
      d->fext[i] = vd_madd(d->fext[i], u, q * o->leaf_cd * a * un);
      if (relative) w->cdrag[i] += 2 * q * o->leaf_cd * a * un;
    }
  }
  // Stokes drag (eq. 11)
  if (o->drag == VD_MSS_DRAG_STOKES)
    for (int i = 0; i < nn; i++) {
      if (d->removed[i] || (m->node_flags[i] & VD_MSS_SOIL)) continue;
      double c = 6 * VD_PI * o->viscosity * m->node_radius[i];
      d->fext[i] = vd_madd(d->fext[i], d->vel[i], -c);
      w->cdrag[i] += c;
    }
  // phototropism on the buds
  if (o->light)
    for (int i = 0; i < nn; i++) {
      if (d->removed[i] || !(m->node_flags[i] & VD_MSS_TIP) || (m->node_flags[i] & VD_MSS_ROOT)) continue;
      vd_vec3 e = vd_sub(o->light_pos, d->pos[i]);
      double r2 = vd_dot(e, e);
      if (!(r2 > 0)) continue;
      d->fext[i] = vd_madd(d->fext[i], e, o->light_k / (r2 * sqrt(r2)));
    }
  // gravitropism by the sine law on every stem node but the buds
  if (o->gravitropism == VD_MSS_GRAVI_SINE) {
    vd_vec3 up = up_dir(o);
    for (int i = 0; i < nn; i++) {
      int s = m->node_owner[i];
      if (s < 0 || d->removed[i] || (m->node_flags[i] & (VD_MSS_TIP | VD_MSS_ROOT | VD_MSS_SOIL))) continue;
      vd_vec3 e = vd_normalize(vd_sub(d->pos[i], d->pos[m->spring_node[2 * s]]));
      vd_vec3 t = vd_madd(up, e, -vd_dot(up, e));  // |t| = sin A
      d->fext[i] = vd_madd(d->fext[i], t, o->gravi_k);
    }
  }
}

// hinge force: the moment k theta that turns arm b->c back to its rest angle with arm b->a
static void hinge_force(const vd_mss_model* m, const vd_mss_data* d, int h, vd_vec3* fa, vd_vec3* fb, vd_vec3* fc) {
  const int* hn = m->hinge_node + 3 * h;
  vd_vec3 xa = hn[0] >= 0 ? d->pos[hn[0]] : vd_v3(0, 0, 0);
  mss_hinge_force_at(m, h, xa, d->pos[hn[1]], d->pos[hn[2]], fa, fb, fc);
}

void mss_hinge_force_at(const vd_mss_model* m, int h, vd_vec3 xa, vd_vec3 xb, vd_vec3 xc, vd_vec3* fa, vd_vec3* fb,
                        vd_vec3* fc) {
  int a = m->hinge_node[3 * h];
  *fa = *fb = *fc = vd_v3(0, 0, 0);
  vd_vec3 qv = vd_sub(xc, xb);
  double lq = v_norm(qv);
  if (!(lq > 0)) return;
  vd_vec3 q = vd_scale(qv, 1.0 / lq), p = m->hinge_p0[h];
  double lp = 0;
  if (a >= 0) {
    vd_vec3 pv = vd_sub(xa, xb);
    lp = v_norm(pv);
    if (!(lp > 0)) return;
    p = vd_scale(pv, 1.0 / lp);
  }
  // target: the rest direction of b->c carried by the smallest rotation of the other arm
  vd_vec3 t = q_rotate(quat_between(m->hinge_p0[h], p), m->hinge_q0[h]);
  vd_vec3 n = vd_cross(q, t);
  double sn = v_norm(n), theta = atan2(sn, vd_dot(q, t));
  if (!(sn > 1e-15)) return;
  vd_vec3 mo = vd_scale(n, m->hinge_k[h] * theta / sn);
  *fc = vd_scale(vd_cross(mo, q), 1.0 / lq);
  if (a >= 0) *fa = vd_scale(vd_cross(mo, p), -1.0 / lp);
  *fb = vd_scale(vd_add(*fa, *fc), -1);
}

void mss_internal(const vd_mss_model* m, const vd_mss_data* d, mss_work* w) {
  int nn = m->nnode, material = m->springs == VD_MSS_MATERIAL;
  for (int i = 0; i < nn; i++) w->fint[i] = vd_v3(0, 0, 0);
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    if (d->removed[i] || d->removed[j] || (d->rigid[i] && d->rigid[j])) continue;
    vd_vec3 e = vd_sub(d->pos[j], d->pos[i]);
    double l = v_norm(e);
    if (!(l > 0)) continue;
    vd_vec3 u = vd_scale(e, 1.0 / l);
    vd_vec3 f = vd_scale(u, m->spring_k[s] * (l - m->spring_l0[s]));
    // eq. 5: c sqrt(k (m1 + m2)) (v_j - v_i); along the spring only with material springs, so a
    // tree turning as a whole is not damped
    vd_vec3 dv = vd_sub(d->vel[j], d->vel[i]);
    double c = w->spring_c[s];
    f = material ? vd_madd(f, u, c * vd_dot(dv, u)) : vd_madd(f, dv, c);
    w->fint[i] = vd_add(w->fint[i], f);
    w->fint[j] = vd_sub(w->fint[j], f);
  }
  for (int h = 0; h < m->nhinge; h++) {
    const int* hn = m->hinge_node + 3 * h;
    int a = hn[0], b = hn[1], c = hn[2];
    if (!mss_hinge_on(m, d, h) || (a >= 0 && d->removed[a]) || d->removed[b] || d->removed[c]) continue;
    if ((a < 0 || d->rigid[a]) && d->rigid[b] && d->rigid[c]) continue;
    vd_vec3 fa, fb, fc;
    hinge_force(m, d, h, &fa, &fb, &fc);
    if (a >= 0) w->fint[a] = vd_add(w->fint[a], fa);
    w->fint[b] = vd_add(w->fint[b], fb);
    w->fint[c] = vd_add(w->fint[c], fc);
  }
}
