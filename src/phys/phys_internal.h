// SPDX-License-Identifier: MIT
// Private pieces of the phys module that both engines use: small dense math (3x3, 6x6) and the
// quaternion maps (phys_math.c).
#ifndef VERDANT_PHYS_INTERNAL_H
#define VERDANT_PHYS_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "verdant/phys.h"

// ---------------------------------------------------------------------------------------------
// 3x3 matrices, row-major double[9]

static inline void m3_zero(double* a) { memset(a, 0, 9 * sizeof(double)); }
static inline void m3_ident(double* a, double s) {
  m3_zero(a);
  a[0] = a[4] = a[8] = s;
}
// rotation matrix of a unit quaternion
static inline void m3_from_quat(double* r, vd_quat q) {
  double w = q.w, x = q.x, y = q.y, z = q.z;
  r[0] = 1 - 2 * (y * y + z * z), r[1] = 2 * (x * y - w * z), r[2] = 2 * (x * z + w * y);
  r[3] = 2 * (x * y + w * z), r[4] = 1 - 2 * (x * x + z * z), r[5] = 2 * (y * z - w * x);
  r[6] = 2 * (x * z - w * y), r[7] = 2 * (y * z + w * x), r[8] = 1 - 2 * (x * x + y * y);
}
static inline vd_vec3 m3_mul_v(const double* a, vd_vec3 v) {
  return vd_v3(a[0] * v.x + a[1] * v.y + a[2] * v.z, a[3] * v.x + a[4] * v.y + a[5] * v.z,
               a[6] * v.x + a[7] * v.y + a[8] * v.z);
}
static inline vd_vec3 m3_tmul_v(const double* a, vd_vec3 v) {
  return vd_v3(a[0] * v.x + a[3] * v.y + a[6] * v.z, a[1] * v.x + a[4] * v.y + a[7] * v.z,
               a[2] * v.x + a[5] * v.y + a[8] * v.z);
}
// c = a b
static inline void m3_mul(double* c, const double* a, const double* b) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}
// c = a^T
static inline void m3_transpose(double* c, const double* a) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[3 * j + i];
}
// cross-product matrix [v]x
static inline void m3_skew(double* a, vd_vec3 v) {
  a[0] = 0, a[1] = -v.z, a[2] = v.y;
  a[3] = v.z, a[4] = 0, a[5] = -v.x;
  a[6] = -v.y, a[7] = v.x, a[8] = 0;
}
// solve the symmetric positive definite 3x3 system a x = b (a is not changed); 0 if singular
int m3_solve_spd(const double* a, vd_vec3 b, vd_vec3* x);
// world inverse inertia R diag(1/ib, 1/ib, 1/it) R^T of a rod segment with frame r (0 if fixed)
void m3_inv_inertia(double* out, const double* r, double ib, double it);

// ---------------------------------------------------------------------------------------------
// 6x6 matrices, row-major double[36]; Cholesky factors stored in place (lower triangle)

// in-place Cholesky a = L L^T; returns 0 if not positive definite
int m6_cholesky(double* a);
// solve L L^T x = b in place (b has 6 entries)
void m6_chol_solve(const double* l, double* b);

// ---------------------------------------------------------------------------------------------
// quaternions: inline copies of the core operations for the hot loops

static inline vd_quat q_mul(vd_quat a, vd_quat b) {
  vd_quat q = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
               a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
  return q;
}
static inline vd_quat q_conj(vd_quat q) {
  vd_quat c = {q.w, -q.x, -q.y, -q.z};
  return c;
}
static inline vd_quat q_normalize(vd_quat q) {
  double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(n > 0)) return vd_quat_identity();
  double in = 1.0 / n;
  vd_quat r = {q.w * in, q.x * in, q.y * in, q.z * in};
  return r;
}
// v rotated by the unit quaternion q
static inline vd_vec3 q_rotate(vd_quat q, vd_vec3 v) {
  // t = 2 (u x v), v' = v + w t + u x t
  vd_vec3 u = {q.x, q.y, q.z};
  vd_vec3 t = vd_scale(vd_cross(u, v), 2.0);
  return vd_add(vd_add(v, vd_scale(t, q.w)), vd_cross(u, t));
}
static inline double v_norm(vd_vec3 a) { return sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }

// Series of the maps for small angles, shared by the scalar maps below and the direct solver's
// lane code (same operations, same bytes). For a rotation vector of squared angle a2 <= 0.01:
// cos(a / 2) and sin(a / 2) / a (to 1e-20).
static inline void sim_exp_series(double a2, double* c, double* k) {
  double x2 = 0.25 * a2;
  *c = 1 - x2 * (1.0 / 2 - x2 * (1.0 / 24 - x2 * (1.0 / 720 - x2 * (1.0 / 40320 - x2 * (1.0 / 3628800)))));
  *k = 0.5 * (1 - x2 * (1.0 / 6 - x2 * (1.0 / 120 - x2 * (1.0 / 5040 - x2 * (1.0 / 362880 - x2 * (1.0 / 39916800))))));
}
// atan(t) / t for t2 = t^2 <= 0.01 (to 1e-19)
static inline double sim_atan_ratio(double t2) {
  double p = 1.0 / 17;
  p = 1.0 / 15 - t2 * p, p = 1.0 / 13 - t2 * p, p = 1.0 / 11 - t2 * p, p = 1.0 / 9 - t2 * p;
  p = 1.0 / 7 - t2 * p, p = 1.0 / 5 - t2 * p, p = 1.0 / 3 - t2 * p;
  return 1.0 - t2 * p;
}

// rotation by the rotation vector v (exponential map)
vd_quat quat_exp_big(vd_vec3 v);
static inline vd_quat quat_exp(vd_vec3 v) {
  double a2 = v.x * v.x + v.y * v.y + v.z * v.z, c, k;
  if (!(a2 <= 0.01)) return quat_exp_big(v);
  sim_exp_series(a2, &c, &k);  // below 0.1 rad (the steps' turns): no libm call
  vd_quat q = {c, v.x * k, v.y * k, v.z * k};
  return q;
}
// rotation vector of q (logarithm map), shortest (|angle| <= pi)
vd_vec3 quat_log_big(vd_quat q);
static inline vd_vec3 quat_log(vd_quat q) {
  if (q.w < 0) q.w = -q.w, q.x = -q.x, q.y = -q.y, q.z = -q.z;
  double s2 = q.x * q.x + q.y * q.y + q.z * q.z, w2 = q.w * q.w;
  if (!(q.w > 0 && s2 <= 0.01 * w2)) return quat_log_big(q);
  // 2 atan2(s, w) / s = (2 / w) atan(t) / t, t = s / w <= 0.1
  double k = 2 * sim_atan_ratio(s2 / w2) / q.w;
  return vd_v3(q.x * k, q.y * k, q.z * k);
}
// q rotated by the world rotation vector v: exp(v) q, normalised
static inline vd_quat quat_rotate_by(vd_quat q, vd_vec3 v) { return q_normalize(q_mul(quat_exp(v), q)); }
static inline double quat_dot(vd_quat a, vd_quat b) { return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vd_vec3 quat_im(vd_quat q) { return vd_v3(q.x, q.y, q.z); }
// d3 (z axis) of a frame
static inline vd_vec3 quat_d3(vd_quat q) {
  return vd_v3(2 * (q.x * q.z + q.w * q.y), 2 * (q.y * q.z - q.w * q.x), 1 - 2 * (q.x * q.x + q.y * q.y));
}
// smallest rotation taking unit vector a to unit vector b
vd_quat quat_between(vd_vec3 a, vd_vec3 b);

#endif
