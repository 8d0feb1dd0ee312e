// SPDX-License-Identifier: MIT
// External loads of a step: gravity on the lumped node masses, the caller's forces and
// torques, aerodynamic forces from the wind and the plant's own motion, optional Stokes drag.
//
// Aerodynamics: dynamic pressure P = rho_air |u|^2 / 2 (= 0.613 |u|^2 for rho_air = 1.226
// kg/m^3, the ASCE 7 velocity pressure) on the relative air velocity u = wind - v, quadratic
// in |u| at plant Reynolds numbers (10^2 - 10^5): cylinders see the normal component of u on
// their projected area 2 r l with C_d ~ 1.2, spheres C_d ~ 0.47 on pi r^2, leaf laminae the
// normal component on their area with C_d ~ 1.17. Stokes drag 6 pi eta r v holds only for
// Re < 1 (a 5 mm stem at 0.1 m/s in air already has Re ~ 30), so it is offered as optional
// numerical damping, never as the air model.
#include "sim_internal.h"

// the rods' wind: the one implementation the mass-spring trees use too (sim_mss_forces.c)
vd_vec3 sim_wind_at(const vd_sim_opt* o, double t) {
  return vd_wind_at(o->wind, o->gust_amplitude, o->gust_period, o->wind_series, o->nwind, t);
}

typedef struct forces_ctx {
  const vd_sim_model* m;
  vd_sim_data* d;
  sim_work* w;
  vd_vec3 wind;
  double q;  // rho_air / 2
} forces_ctx;

// gravity and the caller's loads on nodes; spheres' drag on their centre node
static void node_loads(void* p, int k, int i0, int i1) {
  const forces_ctx* c = p;
  const vd_sim_model* m = c->m;
  const vd_sim_opt* o = &m->opt;
  vd_sim_data* d = c->d;
  sim_work* w = c->w;
  (void)k;
  for (int n = i0; n < i1; n++) {
    int moves = sim_node_moves(m, d, n);
    w->node_fext[n] = moves ? vd_add(vd_scale(o->gravity, d->node_mass[n]), d->node_force[n]) : vd_v3(0, 0, 0);
    w->node_drag[n] = 0;
    if (!moves) continue;
    // Stokes drag (numerical damping only)
    if (o->stokes_viscosity > 0) {
      double sc = 6 * VD_PI * o->stokes_viscosity * m->node_radius[n];
      w->node_fext[n] = vd_madd(w->node_fext[n], d->node_vel[n], -sc);
      w->node_drag[n] += sc;
    }
    if (!o->drag || m->node_sphere[n] <= 0) continue;
    vd_vec3 u = vd_sub(c->wind, d->node_vel[n]);
    int o2 = m->node_owner[n];
    double cd = o2 >= 0 ? m->seg_cd[o2] : 0.47, r = m->node_sphere[n];
    double kq = c->q * cd * VD_PI * r * r * v_norm(u);
    w->node_fext[n] = vd_madd(w->node_fext[n], u, kq);
    w->node_drag[n] += 2 * kq;
  }
}

void sim_seg_drag_one(const vd_sim_model* m, const vd_sim_data* d, sim_work* w, vd_vec3 wind, double q, int t) {
  double* sd = w->seg_drag + 5 * t;
  sd[4] = -1;  // no drag
  if (m->seg_flags[t] & (VD_SIM_FIXED | VD_SIM_FRUITSEG)) return;
  int na = d->seg_start[t], nb = m->seg_node[2 * t + 1];
  int ma = sim_node_moves(m, d, na), mb = sim_node_moves(m, d, nb);
  if (!ma && !mb) return;
  vd_vec3 z = vd_v3(0, 0, 0), u = vd_sub(wind, vd_scale(vd_add(ma ? d->node_vel[na] : z, mb ? d->node_vel[nb] : z), 0.5));
  vd_quat qt = d->seg_quat[t];
  vd_vec3 d3 = quat_d3(qt);
  vd_vec3 up = vd_madd(u, d3, -vd_dot(u, d3));
  double area = 2 * m->seg_radius[t] * m->seg_len0[t];
  double kq = q * m->seg_cd[t] * area * v_norm(up);
  vd_vec3 f = vd_scale(up, kq);
  // damping of F = k |u| u: dF/du has eigenvalues k |u| and 2 k |u|; the larger is taken
  double cc = 2 * kq;
  const double* ln = m->seg_leaf_normal + 3 * t;
  if (ln[0] != 0 || ln[1] != 0 || ln[2] != 0) {
    vd_vec3 nw = q_rotate(qt, vd_v3(ln[0], ln[1], ln[2]));
    double a = v_norm(nw);
    double un = vd_dot(u, nw) / a;
    f = vd_madd(f, nw, q * m->leaf_cd * fabs(un) * un);
    cc += 2 * q * m->leaf_cd * a * fabs(un);
  }
  // half to each end that moves (all of it when the other end is held)
  sd[0] = f.x, sd[1] = f.y, sd[2] = f.z, sd[3] = cc, sd[4] = ma ? (mb ? 0.5 : 1.0) : 0.0;
}

// the segments' drag: whole groups of SIM_W lane-parallel (sim_direct.c), the rest one by one
static void seg_drag(void* p, int k, int t0, int t1) {
  const forces_ctx* c = p;
  (void)k;
  for (int t = sim_seg_drag_lanes(c->m, c->d, c->w, c->wind, c->q, t0, t1); t < t1; t++)
    sim_seg_drag_one(c->m, c->d, c->w, c->wind, c->q, t);
}

void sim_forces(const vd_sim_model* m, vd_sim_data* d, sim_work* w) {
  const vd_sim_opt* o = &m->opt;
  int nt = sim_threads(m);
  forces_ctx c = {m, d, w, sim_wind_at(o, d->time), 0.5 * o->air_density};
  for (int t = 0; t < m->nseg; t++) w->seg_text[t] = d->seg_torque[t];
  sim_parallel(nt, m->nnode_all, node_loads, &c);
  if (!o->drag) return;
  // the segments' drag in parallel, added to their nodes in order
  sim_parallel(nt, m->nseg, seg_drag, &c);
  for (int t = 0; t < m->nseg; t++) {
    const double* sd = w->seg_drag + 5 * t;
    double sa = sd[4], cc = sd[3];
    if (sa < 0) continue;
    int na = d->seg_start[t], nb = m->seg_node[2 * t + 1];
    vd_vec3 f = vd_v3(sd[0], sd[1], sd[2]);
    w->node_fext[na] = vd_madd(w->node_fext[na], f, sa);
    w->node_fext[nb] = vd_madd(w->node_fext[nb], f, 1.0 - sa);
    w->node_drag[na] += sa * cc;
    w->node_drag[nb] += (1.0 - sa) * cc;
  }
}
