// SPDX-License-Identifier: MIT
// Moments and bending stress from a state's geometry. The bend-twist constraint of a joint is
// C_b = Omega - Omega_rest (1/m) with compliance alpha = f / l-bar^2, f the joint's flexibility
// (half of each segment: l / (2 E I)); its elastic energy C_b^2 / (2 alpha) gives the moment
// M = C_b / (alpha l-bar), which is E I kappa for a uniform rod (Euler-Bernoulli). A circular
// section of radius r carries the largest bending stress sigma = M r / I = 4 M / (pi r^3) at its
// surface. Only positions and frames are read, so frames read back from a file have stress too.
#include "sim_internal.h"

// moment of joint t (N m) in its parent's frame; 0 when broken or without a parent
static vd_vec3 joint_moment(const vd_sim_model* m, const vd_sim_data* d, int t) {
  if (d->seg_broken[t] || m->seg_parent[t] < 0) return vd_v3(0, 0, 0);
  double c[6];
  sim_joint_values(m, d, t, c);
  const double* cb = m->seg_cb + 3 * t;
  double lbar = m->seg_lbar[t];
  return vd_v3(c[3] / (cb[0] * lbar), c[4] / (cb[1] * lbar), c[5] / (cb[2] * lbar));
}

// largest bending stress of a moment on a section of radius r (Pa)
static double bending_stress(vd_vec3 mo, double r) {
  return 4.0 * sqrt(mo.x * mo.x + mo.y * mo.y) / (VD_PI * r * r * r);
}

void vd_sim_joint_moment(const vd_sim_model* m, const vd_sim_data* d, double* out) {
  for (int t = 0; t < m->nseg; t++) {
    vd_vec3 mo = joint_moment(m, d, t);
    out[3 * t] = mo.x, out[3 * t + 1] = mo.y, out[3 * t + 2] = mo.z;
  }
}

void vd_sim_seg_stress(const vd_sim_model* m, const vd_sim_data* d, double* out) {
  for (int t = 0; t < m->nseg; t++)
    out[t] = 0;
  // each joint loads the segment on either side of it, each with its own section
  for (int t = 0; t < m->nseg; t++) {
    int p = m->seg_parent[t];
    if (p < 0 || d->seg_broken[t]) continue;
    vd_vec3 mo = joint_moment(m, d, t);
    out[t] = fmax(out[t], bending_stress(mo, m->seg_radius[t]));
    out[p] = fmax(out[p], bending_stress(mo, m->seg_radius[p]));
  }
}

void vd_sim_plant_stress(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant,
                         double* out) {
  VD_ASSERT(plant->nseg == m->nbind_seg);
  for (int j = 0; j < plant->nseg; j++)
    out[j] = NAN;
  // rod segments that resample a plant segment start at 0 (a segment without load)
  for (int t = 0; t < m->nseg; t++)
    if (m->seg_plant[t] >= 0) out[m->seg_plant[t]] = 0;
  for (int t = 0; t < m->nseg; t++) {
    int p = m->seg_parent[t];
    if (p < 0 || d->seg_broken[t]) continue;
    vd_vec3 mo = joint_moment(m, d, t);
    int jt = m->seg_plant[t], jp = m->seg_plant[p];
    if (jt >= 0) out[jt] = fmax(out[jt], bending_stress(mo, m->seg_radius[t]));
    if (jp >= 0) out[jp] = fmax(out[jp], bending_stress(mo, m->seg_radius[p]));
  }
}
