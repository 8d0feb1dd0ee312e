// SPDX-License-Identifier: MIT
// Vector and quaternion helpers that are too long to inline.
#include "verdant/core.h"

#include <math.h>

double vd_norm(vd_vec3 a) { return sqrt(vd_dot(a, a)); }

vd_vec3 vd_normalize(vd_vec3 a) {
  double n = vd_norm(a);
  return n > 0 ? vd_scale(a, 1.0 / n) : a;
}

vd_vec3 vd_rotate(vd_vec3 v, vd_vec3 axis, double angle) {
  // Rodrigues: v cos + (k x v) sin + k (k.v)(1 - cos)
  double c = cos(angle), s = sin(angle);
  vd_vec3 kxv = vd_cross(axis, v);
  double kv = vd_dot(axis, v);
  return vd_v3(v.x * c + kxv.x * s + axis.x * kv * (1 - c), v.y * c + kxv.y * s + axis.y * kv * (1 - c),
               v.z * c + kxv.z * s + axis.z * kv * (1 - c));
}

vd_quat vd_quat_axis_angle(vd_vec3 axis, double angle) {
  double s = sin(0.5 * angle);
  vd_quat q = {cos(0.5 * angle), axis.x * s, axis.y * s, axis.z * s};
  return q;
}

vd_quat vd_quat_mul(vd_quat a, vd_quat b) {
  vd_quat q = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
               a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
  return q;
}

vd_quat vd_quat_conj(vd_quat q) {
  vd_quat c = {q.w, -q.x, -q.y, -q.z};
  return c;
}

vd_quat vd_quat_normalize(vd_quat q) {
  double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (n <= 0) return vd_quat_identity();
  vd_quat r = {q.w / n, q.x / n, q.y / n, q.z / n};
  return r;
}

vd_vec3 vd_quat_rotate(vd_quat q, vd_vec3 v) {
  // v + 2w (u x v) + 2 u x (u x v), u = vector part
  vd_vec3 u = vd_v3(q.x, q.y, q.z);
  vd_vec3 t = vd_scale(vd_cross(u, v), 2.0);
  return vd_add(vd_add(v, vd_scale(t, q.w)), vd_cross(u, t));
}

vd_quat vd_quat_from_axes(vd_vec3 x, vd_vec3 y, vd_vec3 z) {
  // Shepperd's method on the rotation matrix with columns x, y, z
  double m00 = x.x, m10 = x.y, m20 = x.z;
  double m01 = y.x, m11 = y.y, m21 = y.z;
  double m02 = z.x, m12 = z.y, m22 = z.z;
  double tr = m00 + m11 + m22;
  vd_quat q;
  if (tr > 0) {
    double s = sqrt(tr + 1.0) * 2;
    q.w = 0.25 * s;
    q.x = (m21 - m12) / s;
    q.y = (m02 - m20) / s;
    q.z = (m10 - m01) / s;
  } else if (m00 > m11 && m00 > m22) {
    double s = sqrt(1.0 + m00 - m11 - m22) * 2;
    q.w = (m21 - m12) / s;
    q.x = 0.25 * s;
    q.y = (m01 + m10) / s;
    q.z = (m02 + m20) / s;
  } else if (m11 > m22) {
    double s = sqrt(1.0 + m11 - m00 - m22) * 2;
    q.w = (m02 - m20) / s;
    q.x = (m01 + m10) / s;
    q.y = 0.25 * s;
    q.z = (m12 + m21) / s;
  } else {
    double s = sqrt(1.0 + m22 - m00 - m11) * 2;
    q.w = (m10 - m01) / s;
    q.x = (m02 + m20) / s;
    q.y = (m12 + m21) / s;
    q.z = 0.25 * s;
  }
  return vd_quat_normalize(q);
}

double vd_quantile_sorted(const double* x, int n, double q) {
  double h = (n - 1) * q;
  int i = (int)floor(h);
  if (i < 0) return x[0];
  if (i >= n - 1) return x[n - 1];
  return x[i] + (h - i) * (x[i + 1] - x[i]);
}
