// SPDX-License-Identifier: MIT
// The two Cosserat constraints of a rod segment t, linearised at the current state:
//   stretch-shear  C_s = R_t^T (x_end - x_start) / l0 - e3            (material frame, -)
//   bend-twist     C_b = log(conj(q_rel0) s q_rel) / l-bar             (log measure, 1/m)
//              or  C_b = (2 / l-bar) (s Im(q_rel) - Im(q_rel0))        (quat measure, parent frame)
// with q_rel = conj(q_parent) q_t and s = +-1 the sign that puts s q_rel on the side of the
// rest rotation q_rel0 (the +-Omega0 choice of Gazebo Plants done on whole quaternions, the
// augmented Darboux vector of Hsu et al. 2023). The quat measure is Kugelstadt & Schomer 2016
// eq. 31: its moment sin(angle) / flexibility peaks at 90 degrees and is gone at 180, so a soft
// joint folded far back is held by almost nothing. The log measure is the rotation vector of
// the joint's turn away from rest (in the child's rest frame): moment angle / flexibility up to
// 180 degrees, the same stiffness at any rest angle (the quat measure's is cos^2 of half the
// rest angle: a 60-degree branching kink is a quarter softer, an error of first order in sigma).
// Derivatives are taken for world-frame rotation vectors theta: q' = exp(theta) q.
#include "sim_internal.h"

// parent body of joint t in the direct solver's numbering, -1 when kinematic
static int parent_body(const vd_sim_model* m, const vd_sim_data* d, int t) {
  if (d->seg_broken[t]) return m->nseg + (m->seg_spare[t] - m->nnode);
  int p = m->seg_parent[t];
  if (p < 0 || (m->seg_flags[p] & VD_SIM_FIXED)) return -1;
  return p;
}

void sim_jl_inv(vd_vec3 v, double* o) {
  // I - [v]x / 2 + beta [v]x^2, beta = (1 - (a / 2) cot(a / 2)) / a^2 (series below 1e-3 rad)
  double a2 = v.x * v.x + v.y * v.y + v.z * v.z, a = sqrt(a2), beta;
  if (a < 1e-3) beta = 1.0 / 12 + a2 / 720 + a2 * a2 / 30240;
  else beta = (1 - 0.5 * a * cos(0.5 * a) / sin(0.5 * a)) / a2;
  // [v]x^2 = v v^T - a^2 I
  double d = 1 - beta * a2;
  o[0] = d + beta * v.x * v.x, o[1] = beta * v.x * v.y + 0.5 * v.z, o[2] = beta * v.x * v.z - 0.5 * v.y;
  o[3] = beta * v.y * v.x - 0.5 * v.z, o[4] = d + beta * v.y * v.y, o[5] = beta * v.y * v.z + 0.5 * v.x;
  o[6] = beta * v.z * v.x + 0.5 * v.y, o[7] = beta * v.z * v.y - 0.5 * v.x, o[8] = d + beta * v.z * v.z;
}

void sim_bend_strain(vd_sim_bend kind, vd_quat qr, vd_quat q0, double lbar, double* c, double* dc) {
  double s = quat_dot(qr, q0) < 0 ? -1.0 : 1.0;
  vd_quat q = {s * qr.w, s * qr.x, s * qr.y, s * qr.z};
  if (kind == VD_SIM_BEND_QUAT) {
    double k = 2.0 / lbar;
    c[0] = k * (q.x - q0.x), c[1] = k * (q.y - q0.y), c[2] = k * (q.z - q0.z);
    if (!dc) return;
    // (1 / l-bar)(w I - [v]x)
    double f = 1.0 / lbar;
    dc[0] = f * q.w, dc[1] = f * q.z, dc[2] = -f * q.y;
    dc[3] = -f * q.z, dc[4] = f * q.w, dc[5] = f * q.x;
    dc[6] = f * q.y, dc[7] = -f * q.x, dc[8] = f * q.w;
    return;
  }
  // the turn away from rest, qd = conj(q0) q (its w = q0 . q >= 0: at most 180 degrees)
  vd_quat qd = vd_quat_mul(vd_quat_conj(q0), q);
  vd_vec3 ph = quat_log(qd);
  double f = 1.0 / lbar;
  c[0] = f * ph.x, c[1] = f * ph.y, c[2] = f * ph.z;
  if (!dc) return;
  // qd' = conj(q0) exp(psi) q = exp(R0^T psi) qd: dC/dpsi = J_l^-1(ph) R0^T / l-bar
  double jl[9], r0[9];
  sim_jl_inv(ph, jl);
  m3_from_quat(r0, q0);
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      dc[3 * i + k] = f * (jl[3 * i] * r0[3 * k] + jl[3 * i + 1] * r0[3 * k + 1] + jl[3 * i + 2] * r0[3 * k + 2]);
}

void sim_joint_eval(const vd_sim_model* m, const vd_sim_data* d, int t, sim_joint* j) {
  // stretch-shear: values and the two Jacobian blocks
  int na = d->seg_start[t], nb = m->seg_node[2 * t + 1];
  double l0 = m->seg_len0[t];
  double r[9];
  m3_from_quat(r, d->seg_quat[t]);
  vd_vec3 e = vd_scale(vd_sub(d->node_pos[nb], d->node_pos[na]), 1.0 / l0);
  vd_vec3 cs = m3_tmul_v(r, e);
  j->c[0] = cs.x, j->c[1] = cs.y, j->c[2] = cs.z - 1.0;
  double inv = 1.0 / l0, sk[9];
  m3_transpose(j->a, r);
  for (int k = 0; k < 9; k++) j->a[k] *= inv;
  m3_skew(sk, e);
  double rt[9];
  m3_transpose(rt, r);
  m3_mul(j->b, rt, sk);
  memcpy(j->alpha, m->seg_cs + 3 * t, 3 * sizeof(double));
  j->parent_body = parent_body(m, d, t);
  // bend-twist with the parent, unless broken off or parentless
  int p = m->seg_parent[t];
  if (d->seg_broken[t] || p < 0) {
    j->bend = 0;
    j->c[3] = j->c[4] = j->c[5] = 0;
    j->alpha[3] = j->alpha[4] = j->alpha[5] = 1;
    m3_zero(j->g);
    return;
  }
  j->bend = 1;
  vd_quat qp = d->seg_quat[p];
  vd_quat qr = vd_quat_mul(vd_quat_conj(qp), d->seg_quat[t]);
  // G = dC_b/dpsi R_p^T
  double dc[9], rp[9];
  sim_bend_strain(m->bend_measure, qr, m->seg_rest[t], m->seg_lbar[t], j->c + 3, dc);
  m3_from_quat(rp, qp);
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      j->g[3 * i + k] = dc[3 * i] * rp[3 * k] + dc[3 * i + 1] * rp[3 * k + 1] + dc[3 * i + 2] * rp[3 * k + 2];
  memcpy(j->alpha + 3, m->seg_cb + 3 * t, 3 * sizeof(double));
}

void sim_joint_values(const vd_sim_model* m, const vd_sim_data* d, int t, double c[6]) {
  int na = d->seg_start[t], nb = m->seg_node[2 * t + 1];
  double r[9];
  m3_from_quat(r, d->seg_quat[t]);
  vd_vec3 e = vd_scale(vd_sub(d->node_pos[nb], d->node_pos[na]), 1.0 / m->seg_len0[t]);
  vd_vec3 cs = m3_tmul_v(r, e);
  c[0] = cs.x, c[1] = cs.y, c[2] = cs.z - 1.0;
  int p = m->seg_parent[t];
  if (d->seg_broken[t] || p < 0) {
    c[3] = c[4] = c[5] = 0;
    return;
  }
  vd_quat qr = vd_quat_mul(vd_quat_conj(d->seg_quat[p]), d->seg_quat[t]);
  sim_bend_strain(m->bend_measure, qr, m->seg_rest[t], m->seg_lbar[t], c + 3, NULL);
}
