// SPDX-License-Identifier: MIT
// Sag-free initialisation: choose the rest state (rest lengths, rest frames, rest relative
// rotations) so that the modelled shape is the static equilibrium under gravity, as the
// Gazebo Plants conclusion asks ("the initial Darboux vector should be tuned by
// optimization") and Hsu et al. 2023 do for hair. For a tree under dead loads no optimisation
// is needed: the constraint forces are statically determinate. One sweep from the tips to the
// root gives every segment's force F (the weight hanging below it) and every joint's moment T,
//   F_t = sum_{children c} F_c - m_end g,     T_t = sum_{bend children c} T_c + e_t x F_t,
// and the constitutive laws C = -alpha mu (mu = lambda / h^2, the constraint force) give the
// strains the rest state must leave at the modelled shape. Ties are assumed to carry nothing.
#include <stdlib.h>

#include "sim_internal.h"

// solve G^T x = y for a general 3x3 G (row-major); 0 when singular
static int solve_t3(const double* g, vd_vec3 y, vd_vec3* x) {
  // G^T = transpose: build it and use Cramer's rule
  double a[9];
  m3_transpose(a, g);
  double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
               a[2] * (a[3] * a[7] - a[4] * a[6]);
  if (fabs(det) < 1e-300) return 0;
  double yv[3] = {y.x, y.y, y.z}, r[3];
  for (int c = 0; c < 3; c++) {
    double b[9];
    memcpy(b, a, sizeof b);
    for (int i = 0; i < 3; i++) b[3 * i + c] = yv[i];
    r[c] = (b[0] * (b[4] * b[8] - b[5] * b[7]) - b[1] * (b[3] * b[8] - b[5] * b[6]) +
            b[2] * (b[3] * b[7] - b[4] * b[6])) / det;
  }
  *x = vd_v3(r[0], r[1], r[2]);
  return 1;
}

int sim_sagfree(vd_sim_model* m, vd_vec3 g) {
  int ns = m->nseg, nn = m->nnode;
  vd_vec3* f = vd_calloc((size_t)ns + 1, sizeof(vd_vec3));   // F_t
  vd_vec3* tq = vd_calloc((size_t)ns + 1, sizeof(vd_vec3));  // T_t
  vd_vec3* nf = vd_calloc((size_t)nn + 1, sizeof(vd_vec3));  // sum of F_c leaving a node
  vd_vec3* ct = vd_calloc((size_t)ns + 1, sizeof(vd_vec3));  // sum of T_c of bend children
  int clamped = 0;
  if (!f || !tq || !nf || !ct) {
    clamped = -1;
    goto done;
  }
  // forces and moments, tips first
  for (int oi = 0; oi < ns; oi++) {
    int t = m->seg_order[oi];
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    int a = m->seg_node[2 * t], b = m->seg_node[2 * t + 1];
    f[t] = vd_sub(nf[b], vd_scale(g, m->node_mass[b]));
    nf[a] = vd_add(nf[a], f[t]);
    vd_vec3 e = vd_sub(m->node_pos0[b], m->node_pos0[a]);
    tq[t] = vd_add(ct[t], vd_cross(e, f[t]));
    if (m->seg_parent[t] >= 0) ct[m->seg_parent[t]] = vd_add(ct[m->seg_parent[t]], tq[t]);
  }
  // stretch-shear: rest length and frame so that C_s = -alpha_s mu_s at the modelled shape
  for (int t = 0; t < ns; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    vd_vec3 e = vd_sub(m->node_pos0[m->seg_node[2 * t + 1]], m->node_pos0[m->seg_node[2 * t]]);
    double le = vd_norm(e);
    vd_quat q0 = m->seg_quat0[t];  // d3 along e
    vd_quat q = q0;
    double l0 = m->seg_len0[t];
    double kin[3] = {1.0 / (m->seg_cs[3 * t] * l0), 1.0 / (m->seg_cs[3 * t + 1] * l0), 1.0 / (m->seg_cs[3 * t + 2] * l0)};
    for (int it = 0; it < 4; it++) {
      // mu_s = l0 R^T F; target C_s = -mu_s / (l0 K) = -R^T F / K
      vd_vec3 fl = vd_quat_rotate(vd_quat_conj(q), f[t]);
      vd_vec3 c = vd_v3(-fl.x / kin[0], -fl.y / kin[1], -fl.z / kin[2]);
      vd_vec3 u = vd_v3(c.x, c.y, 1 + c.z);
      double lu = vd_norm(u);
      l0 = le / lu;
      q = q_normalize(vd_quat_mul(q0, quat_between(vd_scale(u, 1.0 / lu), vd_v3(0, 0, 1))));
    }
    m->seg_len0[t] = l0;
    for (int k = 0; k < 3; k++) m->seg_cs[3 * t + k] = 1.0 / (kin[k] * l0);
    m->seg_quat0[t] = q;
  }
  // bend-twist: rest relative rotation so that C_b = -alpha_b mu_b, with G^T mu_b = T
  for (int t = 0; t < ns; t++) {
    int p = m->seg_parent[t];
    if ((m->seg_flags[t] & VD_SIM_FIXED) || p < 0) continue;
    vd_quat qp = m->seg_quat0[p];
    vd_quat qr = vd_quat_mul(vd_quat_conj(qp), m->seg_quat0[t]);
    if (qr.w < 0) qr.w = -qr.w, qr.x = -qr.x, qr.y = -qr.y, qr.z = -qr.z;
    double lbar = m->seg_lbar[t], rp[9];
    m3_from_quat(rp, qp);
    // the quat measure gives G = dC_b/dtheta = (1 / l-bar)(w I - [v]x) R_p^T at the modelled shape
    // whatever the rest rotation, so one pass inverts it; the log measure's G depends on the
    // rest rotation through J_l^-1(turn) R_0^T: fixed-point iterations from q_rel0 = q_rel
    vd_quat r0 = qr;
    int log = m->bend_measure == VD_SIM_BEND_LOG, out = 0, fail = 0;
    vd_vec3 prev = vd_v3(0, 0, 0);
    for (int it = 0; it < (log ? 100 : 1); it++) {
      double dc[9], gm[9], cur[3];
      sim_bend_strain(m->bend_measure, qr, r0, lbar, cur, dc);
      for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
          gm[3 * i + k] = dc[3 * i] * rp[3 * k] + dc[3 * i + 1] * rp[3 * k + 1] + dc[3 * i + 2] * rp[3 * k + 2];
      vd_vec3 mu;
      if (!solve_t3(gm, tq[t], &mu)) {
        fail = 1;
        break;
      }
      vd_vec3 cb = vd_v3(-m->seg_cb[3 * t] * mu.x, -m->seg_cb[3 * t + 1] * mu.y, -m->seg_cb[3 * t + 2] * mu.z);
      if (!log) {
        // C_b = (2 / l-bar)(Im q_rel - Im q_rel0)  =>  Im q_rel0 = Im q_rel - (l-bar / 2) C_b
        vd_vec3 v0 = vd_madd(quat_im(qr), cb, -0.5 * lbar);
        double sn = vd_norm(v0);
        if (sn > 0.999) v0 = vd_scale(v0, 0.999 / sn), sn = 0.999, out = 1;
        r0 = (vd_quat){sqrt(1 - sn * sn), v0.x, v0.y, v0.z};
        break;
      }
      // C_b = log(conj(q_rel0) q_rel) / l-bar  =>  q_rel0 = q_rel exp(l-bar C_b)^-1; a turn of
      // 180 degrees or more is out of reach
      vd_vec3 ph = vd_scale(cb, lbar);
      double an = vd_norm(ph);
      out = an > 0.999 * VD_PI;
      if (out) ph = vd_scale(ph, 0.999 * VD_PI / an);
      r0 = q_normalize(vd_quat_mul(qr, vd_quat_conj(quat_exp(ph))));
      double dd = vd_norm(vd_sub(ph, prev));
      prev = ph;
      if (dd <= 1e-15 * (1 + an)) break;
    }
    if (fail) continue;
    clamped += out;
    if (r0.w < 0) r0.w = -r0.w, r0.x = -r0.x, r0.y = -r0.y, r0.z = -r0.z;
    m->seg_rest[t] = r0;
  }
done:
  vd_free(f, ((size_t)ns + 1) * sizeof(vd_vec3));
  vd_free(tq, ((size_t)ns + 1) * sizeof(vd_vec3));
  vd_free(nf, ((size_t)nn + 1) * sizeof(vd_vec3));
  vd_free(ct, ((size_t)ns + 1) * sizeof(vd_vec3));
  return clamped;
}
