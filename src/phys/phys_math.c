// SPDX-License-Identifier: MIT
// Small dense linear algebra (3x3, 6x6 Cholesky) and quaternion maps for both engines.
#include "phys_internal.h"

int m3_solve_spd(const double* a, vd_vec3 b, vd_vec3* x) {
  // Cholesky of the 3x3 matrix, then two triangular solves
  double l00 = a[0];
  if (!(l00 > 0)) return 0;
  l00 = sqrt(l00);
  double l10 = a[3] / l00, l20 = a[6] / l00;
  double d1 = a[4] - l10 * l10;
  if (!(d1 > 0)) return 0;
  double l11 = sqrt(d1);
  double l21 = (a[7] - l20 * l10) / l11;
  double d2 = a[8] - l20 * l20 - l21 * l21;
  if (!(d2 > 0)) return 0;
  double l22 = sqrt(d2);
  double y0 = b.x / l00, y1 = (b.y - l10 * y0) / l11, y2 = (b.z - l20 * y0 - l21 * y1) / l22;
  double z2 = y2 / l22, z1 = (y1 - l21 * z2) / l11, z0 = (y0 - l10 * z1 - l20 * z2) / l00;
  *x = vd_v3(z0, z1, z2);
  return 1;
}

void m3_inv_inertia(double* out, const double* r, double ib, double it) {
  // R diag(1/ib, 1/ib, 1/it) R^T = (1/ib) I + (1/it - 1/ib) d3 d3^T
  double a = 1.0 / ib, c = 1.0 / it - a;
  double d[3] = {r[2], r[5], r[8]};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) out[3 * i + j] = (i == j ? a : 0.0) + c * d[i] * d[j];
}

int m6_cholesky(double* a) {
  for (int j = 0; j < 6; j++) {
    // diagonal entry, then the column below it
    double s = a[6 * j + j];
    for (int k = 0; k < j; k++) s -= a[6 * j + k] * a[6 * j + k];
    if (!(s > 0)) return 0;
    double ljj = sqrt(s);
    a[6 * j + j] = ljj;
    double inv = 1.0 / ljj;
    for (int i = j + 1; i < 6; i++) {
      double v = a[6 * i + j];
      for (int k = 0; k < j; k++) v -= a[6 * i + k] * a[6 * j + k];
      a[6 * i + j] = v * inv;
    }
  }
  return 1;
}

void m6_chol_solve(const double* l, double* b) {
  // forward L y = b, then backward L^T x = y
  for (int i = 0; i < 6; i++) {
    double v = b[i];
    for (int k = 0; k < i; k++) v -= l[6 * i + k] * b[k];
    b[i] = v / l[6 * i + i];
  }
  for (int i = 5; i >= 0; i--) {
    double v = b[i];
    for (int k = i + 1; k < 6; k++) v -= l[6 * k + i] * b[k];
    b[i] = v / l[6 * i + i];
  }
}

vd_quat quat_exp_big(vd_vec3 v) {
  double a = v_norm(v), k = sin(0.5 * a) / a;
  vd_quat q = {cos(0.5 * a), v.x * k, v.y * k, v.z * k};
  return q;
}

vd_vec3 quat_log_big(vd_quat q) {
  if (q.w < 0) q.w = -q.w, q.x = -q.x, q.y = -q.y, q.z = -q.z;
  double s = sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  if (s < 1e-12) return vd_v3(2 * q.x, 2 * q.y, 2 * q.z);
  double k = 2 * atan2(s, q.w) / s;
  return vd_v3(q.x * k, q.y * k, q.z * k);
}

vd_quat quat_between(vd_vec3 a, vd_vec3 b) {
  double c = vd_dot(a, b);
  vd_vec3 ax = vd_cross(a, b);
  if (c < -1 + 1e-12) {
    // opposite: any axis normal to a
    vd_vec3 o = fabs(a.x) < 0.9 ? vd_v3(1, 0, 0) : vd_v3(0, 1, 0);
    ax = vd_normalize(vd_cross(a, o));
    vd_quat q = {0, ax.x, ax.y, ax.z};
    return q;
  }
  vd_quat q = {1 + c, ax.x, ax.y, ax.z};
  return q_normalize(q);
}

