// SPDX-License-Identifier: MIT
// The rigid part of an MRL-Tree (Lim & Gobeawan 2024, sec. 3.2): one rigid body made of the nodes
// that have hardened, with orientation as a quaternion (Betsch & Siebert 2009) and classical
// fourth-order Runge-Kutta on centre, orientation, linear and angular momentum (Pedersen 2003;
// Baraff 2001).
//
// Nodes join by eqs. 6-8: the new centre of mass is the mass-weighted mean (eq. 6), the linear
// momentum gains the joining nodes' momenta (eq. 7), and the angular momentum about the new
// centre is eq. 8. As printed, eq. 8 adds to L^t the term sum_i (x_i - x') x m_i v_i over the old
// body's nodes; but that sum already is the old body's angular momentum about the new centre,
// L^t + (x - x') x p^t, so the printed form counts the old body's own angular momentum twice.
// The corrected term (x - x') x p^t (the transfer of L^t to the new centre) conserves angular
// momentum exactly; vd_mss_rigid_join offers both and reports what each gives
// (docs/physics.md, docs/validation.md).
//
// Each member is a point mass plus a small sphere of its node's radius (2/5 m r^2), so the
// inertia of a straight trunk (points on a line) is never singular.
#include "mss_internal.h"

// ---------------------------------------------------------------------------------------------
// the body alone

vd_vec3 vd_rigid_omega(const vd_rigid* b) {
  if (b->n <= 0 || b->mass <= 0) return vd_v3(0, 0, 0);
  double r[9], t[9], w[9];
  m3_from_quat(r, b->q);
  // I^-1 = R Ib^-1 R^T
  m3_mul(t, r, b->ibody_inv);
  double rt[9];
  m3_transpose(rt, r);
  m3_mul(w, t, rt);
  return m3_mul_v(w, b->L);
}

double vd_rigid_energy(const vd_rigid* b) {
  if (b->n <= 0 || b->mass <= 0) return 0;
  vd_vec3 w = vd_rigid_omega(b);
  return 0.5 * vd_dot(b->p, b->p) / b->mass + 0.5 * vd_dot(b->L, w);
}

typedef struct rk_state {
  vd_vec3 x, p, L;
  vd_quat q;
} rk_state;

// time derivative of the state under a constant force and torque
static rk_state rk_deriv(const vd_rigid* b, const rk_state* s, vd_vec3 f, vd_vec3 tau) {
  vd_rigid t = *b;
  t.q = q_normalize(s->q);
  t.L = s->L;
  vd_vec3 w = vd_rigid_omega(&t);
  rk_state d;
  d.x = vd_scale(s->p, 1.0 / b->mass);
  vd_quat wq = {0, w.x, w.y, w.z};
  vd_quat dq = q_mul(wq, s->q);
  d.q = (vd_quat){0.5 * dq.w, 0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z};
  d.p = f;
  d.L = tau;
  return d;
}

static rk_state rk_add(const rk_state* s, const rk_state* d, double h) {
  rk_state r;
  r.x = vd_madd(s->x, d->x, h);
  r.p = vd_madd(s->p, d->p, h);
  r.L = vd_madd(s->L, d->L, h);
  r.q = (vd_quat){s->q.w + h * d->q.w, s->q.x + h * d->q.x, s->q.y + h * d->q.y, s->q.z + h * d->q.z};
  return r;
}

void vd_rigid_step(vd_rigid* b, vd_vec3 force, vd_vec3 torque, double h) {
  if (b->n <= 0 || b->mass <= 0) return;
  rk_state s0 = {b->x, b->p, b->L, b->q};
  rk_state k1 = rk_deriv(b, &s0, force, torque);
  rk_state s1 = rk_add(&s0, &k1, h / 2);
  rk_state k2 = rk_deriv(b, &s1, force, torque);
  rk_state s2 = rk_add(&s0, &k2, h / 2);
  rk_state k3 = rk_deriv(b, &s2, force, torque);
  rk_state s3 = rk_add(&s0, &k3, h);
  rk_state k4 = rk_deriv(b, &s3, force, torque);
  // y += h/6 (k1 + 2 k2 + 2 k3 + k4)
  rk_state sum = k1;
  sum = rk_add(&sum, &k2, 2);
  sum = rk_add(&sum, &k3, 2);
  sum = rk_add(&sum, &k4, 1);
  rk_state out = rk_add(&s0, &sum, h / 6);
  b->x = out.x;
  b->p = out.p;
  b->L = out.L;
  b->q = q_normalize(out.q);
}

// ---------------------------------------------------------------------------------------------
// the body of a mass-spring tree

// inertia (world frame, about c) of the members and the nodes flagged in extra (Nullable)
static void members_inertia(const vd_mss_model* m, const vd_mss_data* d, const unsigned char* extra, vd_vec3 c,
                            double* iw) {
  m3_zero(iw);
  for (int i = 0; i < m->nnode; i++) {
    if (d->removed[i] || !(d->rigid[i] || (extra && extra[i]))) continue;
    vd_vec3 r = vd_sub(d->pos[i], c);
    double mi = d->mass[i], rr = vd_dot(r, r), rad = m->node_radius[i];
    double s = 0.4 * mi * rad * rad;  // the node's own sphere
    double a[3] = {r.x, r.y, r.z};
    for (int u = 0; u < 3; u++)
      for (int v = 0; v < 3; v++) iw[3 * u + v] += mi * ((u == v ? rr : 0) - a[u] * a[v]) + (u == v ? s : 0);
  }
}

// invert a symmetric positive definite 3 x 3 (cofactors); 0 when singular
static int m3_inverse(double* out, const double* a) {
  double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8], c02 = a[3] * a[7] - a[4] * a[6];
  double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  if (!(fabs(det) > 0) || !isfinite(det)) return 0;
  double id = 1.0 / det;
  out[0] = c00 * id;
  out[1] = (a[2] * a[7] - a[1] * a[8]) * id;
  out[2] = (a[1] * a[5] - a[2] * a[4]) * id;
  out[3] = c01 * id;
  out[4] = (a[0] * a[8] - a[2] * a[6]) * id;
  out[5] = (a[2] * a[3] - a[0] * a[5]) * id;
  out[6] = c02 * id;
  out[7] = (a[1] * a[6] - a[0] * a[7]) * id;
  out[8] = (a[0] * a[4] - a[1] * a[3]) * id;
  return 1;
}

// new centre, mass, body frame and body inertia from the members' positions (q kept); members'
// velocities then follow the body's p and L
static void rebody(const vd_mss_model* m, vd_mss_data* d, vd_vec3 center, double mass) {
  vd_rigid* b = &d->rb;
  b->x = center;
  b->mass = mass;
  double iw[9], r[9], rt[9], t[9];
  members_inertia(m, d, NULL, center, iw);
  m3_from_quat(r, b->q);
  m3_transpose(rt, r);
  m3_mul(t, rt, iw);
  m3_mul(b->ibody, t, r);  // Ib = R^T Iw R
  if (!m3_inverse(b->ibody_inv, b->ibody)) m3_zero(b->ibody_inv);
  int n = 0;
  for (int i = 0; i < m->nnode; i++)
    if (d->rigid[i] && !d->removed[i]) {
      d->body[i] = m3_mul_v(rt, vd_sub(d->pos[i], center));
      n++;
    }
  b->n = n;
  mss_rigid_sync(m, d);
}

void mss_rigid_sync(const vd_mss_model* m, vd_mss_data* d) {
  const vd_rigid* b = &d->rb;
  if (b->n <= 0) return;
  vd_vec3 w = vd_rigid_omega(b), v0 = vd_scale(b->p, 1.0 / b->mass);
  for (int i = 0; i < m->nnode; i++)
    if (d->rigid[i] && !d->removed[i]) {
      vd_vec3 r = q_rotate(b->q, d->body[i]);
      d->pos[i] = vd_add(b->x, r);
      d->vel[i] = vd_add(v0, vd_cross(w, r));
    }
}

void vd_mss_rigid_join(const vd_mss_model* m, vd_mss_data* d, const unsigned char* join, int paper_eq8,
                       double* lcheck) {
  vd_rigid* b = &d->rb;
  // eq. 6: the new centre of mass from the old body and the joining nodes
  double mass = b->n > 0 ? b->mass : 0;
  vd_vec3 mx = b->n > 0 ? vd_scale(b->x, b->mass) : vd_v3(0, 0, 0);
  vd_vec3 pj = vd_v3(0, 0, 0);
  int nj = 0;
  for (int i = 0; i < m->nnode; i++)
    if (join[i] && !d->rigid[i] && !d->removed[i]) {
      mass += d->mass[i];
      mx = vd_madd(mx, d->pos[i], d->mass[i]);
      pj = vd_madd(pj, d->vel[i], d->mass[i]);
      nj++;
    }
  if (!nj || mass <= 0) {
    if (lcheck) memset(lcheck, 0, 6 * sizeof(double));
    return;
  }
  vd_vec3 c = vd_scale(mx, 1.0 / mass);
  // eq. 7: p' = p + sum m_j v_j
  vd_vec3 p_old = b->n > 0 ? b->p : vd_v3(0, 0, 0);
  vd_vec3 l_old = b->n > 0 ? b->L : vd_v3(0, 0, 0);
  vd_vec3 p_new = vd_add(p_old, pj);
  // eq. 8: the joining nodes' angular momentum about the new centre ...
  vd_vec3 lj = vd_v3(0, 0, 0);
  for (int i = 0; i < m->nnode; i++)
    if (join[i] && !d->rigid[i] && !d->removed[i])
      lj = vd_add(lj, vd_cross(vd_sub(d->pos[i], c), vd_scale(d->vel[i], d->mass[i])));
  // ... and the old body's: exactly L^t + (x - x') x p^t
  vd_vec3 shift = b->n > 0 ? vd_cross(vd_sub(b->x, c), p_old) : vd_v3(0, 0, 0);
  vd_vec3 l_true = vd_add(vd_add(l_old, shift), lj);
  vd_vec3 l_new = l_true;
  if (paper_eq8 && b->n > 0) {
    // as printed: L^t + sum_j ... + sum_i (x_i - x') x m_i v_i over the old members
    vd_vec3 li = vd_v3(0, 0, 0);
    for (int i = 0; i < m->nnode; i++)
      if (d->rigid[i] && !d->removed[i])
        li = vd_add(li, vd_cross(vd_sub(d->pos[i], c), vd_scale(d->vel[i], d->mass[i])));
    l_new = vd_add(vd_add(l_old, lj), li);
  }
  if (lcheck) {
    lcheck[0] = l_true.x, lcheck[1] = l_true.y, lcheck[2] = l_true.z;
    lcheck[3] = l_new.x, lcheck[4] = l_new.y, lcheck[5] = l_new.z;
  }
  if (b->n <= 0) b->q = vd_quat_identity();
  for (int i = 0; i < m->nnode; i++)
    if (join[i] && !d->removed[i]) d->rigid[i] = 1;
  b->p = p_new;
  b->L = l_new;
  rebody(m, d, c, mass);
}

void vd_mss_rigid_refit(const vd_mss_model* m, vd_mss_data* d, vd_vec3 omega) {
  vd_rigid* b = &d->rb;
  double mass = 0;
  vd_vec3 mx = vd_v3(0, 0, 0), p = vd_v3(0, 0, 0);
  int n = 0;
  for (int i = 0; i < m->nnode; i++) {
    if (!d->rigid[i] || d->removed[i]) continue;
    mass += d->mass[i];
    mx = vd_madd(mx, d->pos[i], d->mass[i]);
    p = vd_madd(p, d->vel[i], d->mass[i]);
    n++;
  }
  if (!n || mass <= 0) {
    memset(b, 0, sizeof *b);
    b->q = vd_quat_identity();
    return;
  }
  vd_vec3 c = vd_scale(mx, 1.0 / mass), l = vd_v3(0, 0, 0);
  for (int i = 0; i < m->nnode; i++) {
    if (!d->rigid[i] || d->removed[i]) continue;
    double rad = m->node_radius[i];
    l = vd_add(l, vd_cross(vd_sub(d->pos[i], c), vd_scale(d->vel[i], d->mass[i])));
    l = vd_madd(l, omega, 0.4 * d->mass[i] * rad * rad);  // the members' own spheres spin too
  }
  b->p = p;
  b->L = l;
  rebody(m, d, c, mass);
}

void vd_mss_rigid_update(const vd_mss_model* m, vd_mss_data* d) {
  vd_rigid* b = &d->rb;
  if (b->n <= 0) return;
  // members that fell with a branch take their momentum with them
  vd_vec3 p = b->p, l = b->L;
  double mass = 0;
  vd_vec3 mx = vd_v3(0, 0, 0);
  int n = 0;
  for (int i = 0; i < m->nnode; i++) {
    if (!d->rigid[i]) continue;
    if (d->removed[i]) {
      vd_vec3 mv = vd_scale(d->vel[i], d->mass[i]);
      p = vd_sub(p, mv);
      l = vd_sub(l, vd_cross(vd_sub(d->pos[i], b->x), mv));
      d->rigid[i] = 0;
      continue;
    }
    mass += d->mass[i];
    mx = vd_madd(mx, d->pos[i], d->mass[i]);
    n++;
  }
  if (!n || mass <= 0) {
    memset(b, 0, sizeof *b);
    b->q = vd_quat_identity();
    return;
  }
  vd_vec3 c = vd_scale(mx, 1.0 / mass);
  // the angular momentum moves to the new centre with the transfer term
  b->L = vd_add(l, vd_cross(vd_sub(b->x, c), p));
  b->p = p;
  rebody(m, d, c, mass);
}

// ---------------------------------------------------------------------------------------------
// the body turning about its anchor

// a node's position and velocity with the body at orientation q turning at w (outside nodes
// stay where they are for the substep)
static vd_vec3 pos_at(const vd_mss_data* d, const mss_anchor* an, vd_quat q, int i) {
  return d->rigid[i] ? vd_add(an->pivot, q_rotate(q, vd_sub(d->body[i], an->pivot_body))) : d->pos[i];
}

static vd_vec3 vel_at(const vd_mss_data* d, const mss_anchor* an, vd_quat q, vd_vec3 w, int i) {
  return d->rigid[i] ? vd_cross(w, vd_sub(pos_at(d, an, q, i), an->pivot)) : d->vel[i];
}

// the torque about the pivot of the springs and hinges that join the body to outside nodes, the
// body at orientation q turning at w (spring damping eq. 5 as in the substep)
static vd_vec3 coupling_torque(const vd_mss_model* m, const vd_mss_data* d, const mss_anchor* an, vd_quat q, vd_vec3 w) {
  const mss_work* wk = d->work;
  vd_vec3 tau = vd_v3(0, 0, 0);
  int material = m->springs == VD_MSS_MATERIAL;
  for (int k = 0; k < an->nspring; k++) {
    int s = an->spring[k], i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    vd_vec3 xi = pos_at(d, an, q, i), xj = pos_at(d, an, q, j), e = vd_sub(xj, xi);
    double l = v_norm(e);
    if (!(l > 0)) continue;
    vd_vec3 u = vd_scale(e, 1.0 / l), dv = vd_sub(vel_at(d, an, q, w, j), vel_at(d, an, q, w, i));
    vd_vec3 f = vd_scale(u, m->spring_k[s] * (l - m->spring_l0[s]));
    f = material ? vd_madd(f, u, wk->spring_c[s] * vd_dot(dv, u)) : vd_madd(f, dv, wk->spring_c[s]);
    if (d->rigid[i]) tau = vd_add(tau, vd_cross(vd_sub(xi, an->pivot), f));
    if (d->rigid[j]) tau = vd_sub(tau, vd_cross(vd_sub(xj, an->pivot), f));
  }
  for (int k = 0; k < an->nhinge; k++) {
    int h = an->hinge[k];
    const int* hn = m->hinge_node + 3 * h;
    vd_vec3 xa = hn[0] >= 0 ? pos_at(d, an, q, hn[0]) : vd_v3(0, 0, 0), xb = pos_at(d, an, q, hn[1]), xc = pos_at(d, an, q, hn[2]);
    vd_vec3 f[3];
    mss_hinge_force_at(m, h, xa, xb, xc, &f[0], &f[1], &f[2]);
    vd_vec3 x[3] = {xa, xb, xc};
    for (int e = 0; e < 3; e++)
      if (hn[e] >= 0 && d->rigid[hn[e]]) tau = vd_add(tau, vd_cross(vd_sub(x[e], an->pivot), f[e]));
  }
  return tau;
}

// inertia about the pivot in the world frame at orientation q, and its inverse
static void pinned_inertia(const vd_rigid* b, vd_vec3 ab, vd_quat q, double* ia, double* ia_inv) {
  double ibp[9], r[9], rt[9], t[9];
  double a[3] = {ab.x, ab.y, ab.z}, aa = vd_dot(ab, ab);
  for (int u = 0; u < 3; u++)
    for (int v = 0; v < 3; v++) ibp[3 * u + v] = b->ibody[3 * u + v] + b->mass * ((u == v ? aa : 0) - a[u] * a[v]);
  m3_from_quat(r, q);
  m3_transpose(rt, r);
  m3_mul(t, r, ibp);
  m3_mul(ia, t, rt);
  if (!m3_inverse(ia_inv, ia)) m3_zero(ia_inv);
}

typedef struct pin_state {
  vd_quat q;
  vd_vec3 la;  // angular momentum about the pivot (kg m^2/s)
} pin_state;

static pin_state pin_deriv(const vd_mss_model* m, const vd_mss_data* d, const mss_anchor* an, const pin_state* s,
                           vd_vec3 torque) {
  double ia[9], iai[9];
  vd_quat q = q_normalize(s->q);
  pinned_inertia(&d->rb, an->pivot_body, q, ia, iai);
  vd_vec3 w = m3_mul_v(iai, s->la);
  pin_state r;
  vd_quat wq = {0, w.x, w.y, w.z};
  vd_quat dq = q_mul(wq, q);
  r.q = (vd_quat){0.5 * dq.w, 0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z};
  // the anchor's bending is damped like eq. 5, c sqrt(k I) on the turn across the trunk's axis
  vd_vec3 axis = q_rotate(q, an->axis_body);
  vd_vec3 wp = vd_madd(w, axis, -vd_dot(w, axis));
  r.la = vd_madd(vd_add(torque, coupling_torque(m, d, an, q, w)), wp, -an->damping);
  return r;
}

static pin_state pin_add(const pin_state* s, const pin_state* k, double h) {
  pin_state r;
  r.q = (vd_quat){s->q.w + h * k->q.w, s->q.x + h * k->q.x, s->q.y + h * k->q.y, s->q.z + h * k->q.z};
  r.la = vd_madd(s->la, k->la, h);
  return r;
}

void mss_rigid_pinned_step(const vd_mss_model* m, vd_mss_data* d, mss_anchor* an, vd_vec3 torque, double h) {
  vd_rigid* b = &d->rb;
  if (b->n <= 0 || b->mass <= 0) return;
  vd_vec3 rc = vd_sub(b->x, an->pivot);
  pin_state s = {b->q, vd_add(b->L, vd_cross(rc, b->p))};
  // the inertia across the trunk (half the trace about the pivot: a slender body's two equal
  // bending moments) sets the anchor's damping and the substeps
  double ia0[9], iai0[9];
  pinned_inertia(b, an->pivot_body, b->q, ia0, iai0);
  double ie = 0.5 * (ia0[0] + ia0[4] + ia0[8]);
  an->damping = ie > 0 ? m->damping * sqrt(an->hinge_k * ie) : 0;
  an->omega = ie > 0 ? sqrt(an->stiffness / ie) : 0;
  // substeps short enough for the anchor's stiffness (RK4 of an oscillator is stable to h w < 2.8)
  int nsub = (int)ceil(h * an->omega / 0.5);
  if (nsub < 1) nsub = 1;
  if (nsub > 10000) nsub = 10000;
  double hs = h / nsub;
  for (int k = 0; k < nsub; k++) {
    pin_state k1 = pin_deriv(m, d, an, &s, torque);
    pin_state s1 = pin_add(&s, &k1, hs / 2);
    pin_state k2 = pin_deriv(m, d, an, &s1, torque);
    pin_state s2 = pin_add(&s, &k2, hs / 2);
    pin_state k3 = pin_deriv(m, d, an, &s2, torque);
    pin_state s3 = pin_add(&s, &k3, hs);
    pin_state k4 = pin_deriv(m, d, an, &s3, torque);
    pin_state sum = k1;
    sum = pin_add(&sum, &k2, 2);
    sum = pin_add(&sum, &k3, 2);
    sum = pin_add(&sum, &k4, 1);
    s = pin_add(&s, &sum, hs / 6);
    s.q = q_normalize(s.q);
  }
  // the centre turns about the pivot; momenta from the angular velocity
  double ia[9], iai[9];
  pinned_inertia(b, an->pivot_body, s.q, ia, iai);
  vd_vec3 w = m3_mul_v(iai, s.la);
  b->q = s.q;
  b->x = vd_sub(an->pivot, q_rotate(s.q, an->pivot_body));
  vd_vec3 r = vd_sub(b->x, an->pivot);
  b->p = vd_scale(vd_cross(w, r), b->mass);
  b->L = vd_sub(s.la, vd_cross(r, b->p));
}
