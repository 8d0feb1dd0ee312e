// SPDX-License-Identifier: MIT
// The two Cosserat constraints of a rod segment t, linearised at the current state:
//   stretch-shear  C_s = R_t^T (x_end - x_start) / l0 - e3            (material frame, -)
//   bend-twist     C_b = (2 / l-bar) (s Im(q_rel) - Im(q_rel0))        (parent frame, 1/m)
// with q_rel = conj(q_parent) q_t and s = +-1 the sign that puts s q_rel on the side of the
// rest rotation q_rel0 (Kugelstadt & Schomer 2016 eq. 31 and the +-Omega0 choice of Gazebo
// Plants; we compare whole quaternions, the augmented Darboux vector of Hsu et al. 2023).
// Derivatives are taken for world-frame rotation vectors theta: q' = exp(theta) q.
#include "sim_internal.h"

// parent body of joint t in the direct solver's numbering, -1 when kinematic
static int parent_body(const vd_sim_model* m, const vd_sim_data* d, int t) {
  if (d->seg_broken[t]) return m->nseg + (m->seg_spare[t] - m->nnode);
  int p = m->seg_parent[t];
  if (p < 0 || (m->seg_flags[p] & VD_SIM_FIXED)) return -1;
  return p;
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
  vd_quat qr = q_mul(q_conj(qp), d->seg_quat[t]);
  vd_quat q0 = m->seg_rest[t];
  double s = quat_dot(qr, q0) < 0 ? -1.0 : 1.0;
  double lbar = m->seg_lbar[t], k = 2.0 / lbar;
  j->c[3] = k * (s * qr.x - q0.x);
  j->c[4] = k * (s * qr.y - q0.y);
  j->c[5] = k * (s * qr.z - q0.z);
  // G = (s / l-bar) (w I - [v]x) R_p^T
  double rp[9], rpt[9], w[9];
  m3_from_quat(rp, qp);
  m3_transpose(rpt, rp);
  m3_skew(w, vd_v3(qr.x, qr.y, qr.z));
  for (int i = 0; i < 9; i++) w[i] = -w[i];
  w[0] += qr.w, w[4] += qr.w, w[8] += qr.w;
  m3_mul(j->g, w, rpt);
  double f = s / lbar;
  for (int i = 0; i < 9; i++) j->g[i] *= f;
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
  vd_quat qr = q_mul(q_conj(d->seg_quat[p]), d->seg_quat[t]);
  vd_quat q0 = m->seg_rest[t];
  double s = quat_dot(qr, q0) < 0 ? -1.0 : 1.0, k = 2.0 / m->seg_lbar[t];
  c[3] = k * (s * qr.x - q0.x);
  c[4] = k * (s * qr.y - q0.y);
  c[5] = k * (s * qr.z - q0.z);
}
