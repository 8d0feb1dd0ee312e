// SPDX-License-Identifier: MIT
// Direct solver: each Newton iteration solves the XPBD system of the whole plant exactly,
//   [ M   -J^T ] [dy]   = - [ g ]     g = M (y - y_n - h v_n) - h^2 f - J^T lambda
//   [ J  alpha~] [dl]       [ c ]     c = C + alpha~ lambda (+ damping, Macklin et al. 2016)
// in time linear in the number of segments. Plants are trees, and so is the graph whose
// vertices are bodies and joints (Baraff 1996; Deul et al. 2018): a body is one segment's end
// node with its frame (6 dofs), a joint is that segment's stretch-shear and bend-twist rows
// (6), which touch only the body and its parent. Eliminating bodies and joints from the tips
// to the root (children first) leaves no fill-in. Unlike plain XPBD we keep the primal residual
// g, so the iteration converges to the implicit Euler step itself and static equilibria are
// exact.
//
// How it is computed (issue 13):
// * The stretch-shear rows are taken in world axes: rows premultiplied by T = l0 R, which
//   leaves the solution unchanged (dl = T^T dl^) and turns their Jacobian into [I, [E]x] on the
//   body and [-I, 0] on the parent (E = x_end - x_start), with compliance
//   alpha^ = l0^2 R diag(alpha~) R^T: cross products instead of 3x3 products.
// * Bodies are eliminated SIM_W (8) at a time (sim_plan.c): every quantity of a block is stored
//   lane by lane (sim_blk), and the block arithmetic of a step runs as one loop over the lanes,
//   which the compiler vectorises (each lane's arithmetic is the scalar one: same bytes with any
//   vector width, no fused multiply-adds, -ffp-contract=off).
// * A body sums its children's contributions J_p^T S^-1 J_p and their residual terms itself,
//   in the fixed order of its children, so the bytes do not depend on the schedule or threads.
// * Tips (a third of the tomato) have a diagonal body matrix: their inverse is written down.
// * 6x6 inverses by 3x3 Schur blocks (two divisions each), used through products.
#include <stddef.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "sim_internal.h"

// a profiling build (-DVD_PROF_NOINLINE) keeps the stages apart for callgrind
#ifdef VD_PROF_NOINLINE
#define PROF_NOINLINE __attribute__((noinline))
#define SIM_INLINE_PROF static
#else
#define PROF_NOINLINE
#define SIM_INLINE_PROF static inline __attribute__((always_inline))
#endif

// Every kernel is inlined into the block loops, which are compiled three times (x86-64 with gcc
// or clang; -DVD_SIM_PORTABLE for one baseline build): for AVX-512 (eight lanes in one
// instruction), AVX2 (four) and the baseline (SSE2, two), picked at load time by the CPU. All
// give the same bytes: each lane's arithmetic is the scalar IEEE arithmetic in the same order,
// with no fused multiply-adds (-ffp-contract=off); the tomato's frames were compared byte for
// byte between the three and between blocks of four and eight lanes.
// Sanitizer builds (gcc defines __SANITIZE_ADDRESS__, clang has the feature) take one plain copy
// with the compiler's own inlining: clang 14 at -O1 with ASan and UBSan needed more than ten
// minutes for the three clones of the forced-inline kernels, and 25 s for one.
#if defined(__SANITIZE_ADDRESS__)
#define SIM_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SIM_SANITIZED 1
#endif
#endif
#ifdef SIM_SANITIZED
#define SIM_INLINE static inline
#else
#define SIM_INLINE static inline __attribute__((always_inline))
#endif
#if defined(__x86_64__) && defined(__has_attribute) && !defined(VD_PROF_NOINLINE) && !defined(SIM_SANITIZED) && \
    !defined(VD_SIM_PORTABLE)
#if __has_attribute(target_clones)
#define SIM_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
#endif
#ifndef SIM_CLONES
#define SIM_CLONES
#endif

#define SIM_MAX_TURN 1.0   // largest frame rotation of one Newton update (rad)
#define SIM_MAX_MOVE 10.0  // largest node move of one Newton update (rest lengths of its segment)

// packed upper 3x3: 00 01 02 11 12 22
#define S00 0
#define S01 1
#define S02 2
#define S11 3
#define S12 4
#define S22 5

// ---------------------------------------------------------------------------------------------
// lane kernels: every statement is a loop over the SIM_W lanes of contiguous arrays, which the
// compiler turns into vector instructions (each lane's arithmetic is the scalar one)

typedef double lane[SIM_W];
#define L _Pragma("omp simd") for (int l = 0; l < SIM_W; l++)

// index of element (i, j) of a packed symmetric 3x3
static const int SYM[3][3] = {{S00, S01, S02}, {S01, S11, S12}, {S02, S12, S22}};

// inverse of symmetric 3x3 matrices (packed) by cofactors; ok *= 1 where positive definite
SIM_INLINE void inv3s(lane* restrict a, lane* restrict o, lane ok) {
  lane c00, c01, c02, c11, c12, c22, id;
  L c00[l] = a[S11][l] * a[S22][l] - a[S12][l] * a[S12][l];
  L c01[l] = a[S02][l] * a[S12][l] - a[S01][l] * a[S22][l];
  L c02[l] = a[S01][l] * a[S12][l] - a[S02][l] * a[S11][l];
  L c11[l] = a[S00][l] * a[S22][l] - a[S02][l] * a[S02][l];
  L c12[l] = a[S02][l] * a[S01][l] - a[S00][l] * a[S12][l];
  L c22[l] = a[S00][l] * a[S11][l] - a[S01][l] * a[S01][l];
  L {
    double det = a[S00][l] * c00[l] + a[S01][l] * c01[l] + a[S02][l] * c02[l];
    id[l] = 1.0 / det;
    ok[l] = a[S00][l] > 0 && det > 0 ? ok[l] : 0.0;
  }
  L o[S00][l] = c00[l] * id[l];
  L o[S01][l] = c01[l] * id[l];
  L o[S02][l] = c02[l] * id[l];
  L o[S11][l] = c11[l] * id[l];
  L o[S12][l] = c12[l] * id[l];
  L o[S22][l] = c22[l] * id[l];
}

// inverse of symmetric positive definite 6x6 matrices [A | B | D] by their 3x3 blocks:
// X = A^-1 B, T = D - B^T X (the Schur complement), inverse [[A^-1 + X T^-1 X^T, -X T^-1],
// [., T^-1]]; ok *= 1 where both pivots were positive definite
SIM_INLINE void inv6s(lane* restrict m, lane* restrict o, lane ok) {
  lane *a = m, *b = m + 6, *dd = m + 15;
  lane ai[6], x[9], t[6], y[9];
  inv3s(a, ai, ok);
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      L x[3 * i + k][l] = ai[SYM[i][0]][l] * b[k][l] + ai[SYM[i][1]][l] * b[3 + k][l] + ai[SYM[i][2]][l] * b[6 + k][l];
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++)
      L t[SYM[i][k]][l] = dd[SYM[i][k]][l] - (b[i][l] * x[k][l] + b[3 + i][l] * x[3 + k][l] + b[6 + i][l] * x[6 + k][l]);
  inv3s(t, o + 15, ok);
  lane* ti = o + 15;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      L y[3 * i + k][l] = x[3 * i][l] * ti[SYM[0][k]][l] + x[3 * i + 1][l] * ti[SYM[1][k]][l] + x[3 * i + 2][l] * ti[SYM[2][k]][l];
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++)
      L o[SYM[i][k]][l] = ai[SYM[i][k]][l] + y[3 * i][l] * x[3 * k][l] + y[3 * i + 1][l] * x[3 * k + 1][l] +
                          y[3 * i + 2][l] * x[3 * k + 2][l];
  for (int k = 0; k < 9; k++) L o[6 + k][l] = -y[k][l];
}

// y = M v for symmetric 6x6 matrices [A | B | D] and 6-vectors
SIM_INLINE void mul6s(lane* restrict m, lane* restrict v, lane* restrict y) {
  lane *a = m, *b = m + 6, *dd = m + 15;
  for (int i = 0; i < 3; i++) {
    L y[i][l] = a[SYM[i][0]][l] * v[0][l] + a[SYM[i][1]][l] * v[1][l] + a[SYM[i][2]][l] * v[2][l] + b[3 * i][l] * v[3][l] +
                b[3 * i + 1][l] * v[4][l] + b[3 * i + 2][l] * v[5][l];
    L y[3 + i][l] = b[i][l] * v[0][l] + b[3 + i][l] * v[1][l] + b[6 + i][l] * v[2][l] + dd[SYM[i][0]][l] * v[3][l] +
                    dd[SYM[i][1]][l] * v[4][l] + dd[SYM[i][2]][l] * v[5][l];
  }
}

// c = e x u for 3-vectors
#define CROSS(c, e, u)                                         \
  do {                                                         \
    L(c)[0][l] = (e)[1][l] * (u)[2][l] - (e)[2][l] * (u)[1][l]; \
    L(c)[1][l] = (e)[2][l] * (u)[0][l] - (e)[0][l] * (u)[2][l]; \
    L(c)[2][l] = (e)[0][l] * (u)[1][l] - (e)[1][l] * (u)[0][l]; \
  } while (0)

// ---------------------------------------------------------------------------------------------
// body numbering

// slot of the body that owns node n for a tie: its segment's slot, nslot + k for spare k, -1
static int tie_slot(const vd_sim_model* m, const vd_sim_data* d, const sim_plan* p, int n) {
  if (n >= m->nnode) return d->node_mass[n] > 0 ? p->nslot + (n - m->nnode) : -1;
  if (m->node_fixed[n]) return -1;
  int o = m->node_owner[n];
  return o >= 0 ? p->seg_slot[o] : -1;
}

// ---------------------------------------------------------------------------------------------
// quaternion maps on lanes

// rotation matrices of unit quaternions (w, x, y, z)
SIM_INLINE void rot_lanes(lane* restrict q, lane* restrict r) {
  L {
    double w = q[0][l], x = q[1][l], y = q[2][l], z = q[3][l];
    r[0][l] = 1 - 2 * (y * y + z * z), r[1][l] = 2 * (x * y - w * z), r[2][l] = 2 * (x * z + w * y);
    r[3][l] = 2 * (x * y + w * z), r[4][l] = 1 - 2 * (x * x + z * z), r[5][l] = 2 * (y * z - w * x);
    r[6][l] = 2 * (x * z - w * y), r[7][l] = 2 * (y * z + w * x), r[8][l] = 1 - 2 * (x * x + y * y);
  }
}

// c = a b (sa, sb = +1 or -1 conjugate a or b)
SIM_INLINE void qmul_lanes(lane* restrict a, lane* restrict b, lane* restrict c, double sa, double sb) {
  L {
    double aw = a[0][l], ax = sa * a[1][l], ay = sa * a[2][l], az = sa * a[3][l];
    double bw = b[0][l], bx = sb * b[1][l], by = sb * b[2][l], bz = sb * b[3][l];
    c[0][l] = aw * bw - ax * bx - ay * by - az * bz;
    c[1][l] = aw * bx + ax * bw + ay * bz - az * by;
    c[2][l] = aw * by - ax * bz + ay * bw + az * bx;
    c[3][l] = aw * bz + ax * by - ay * bx + az * bw;
  }
}

// rotation vector of q (the shorter way: q and -q alike) as quat_log does it where
// t = |Im q| / Re q <= 0.1 (its series); elsewhere need[l] = 1 and the caller calls quat_log
SIM_INLINE void qlog_lanes(lane* restrict q, lane* restrict v, lane need) {
  L {
    // (-0: sg = -1, w = +0 instead of 1 and -0: not ok either way; copysign keeps the loop
    // free of branches, a comparison was threaded into them once inlined)
    double sg = copysign(1.0, q[0][l]);
    double w = sg * q[0][l], x = sg * q[1][l], y = sg * q[2][l], z = sg * q[3][l];
    double s2 = x * x + y * y + z * z, w2 = w * w;
    // operands picked, not operations, all in doubles: a conditional division, or an int
    // flag, keeps the loop scalar
    double ok = w > 0 ? 1.0 : 0.0;
    ok = s2 <= 0.01 * w2 ? ok : 0.0;
    double k = 2 * sim_atan_ratio((ok > 0 ? s2 : 0.0) / (ok > 0 ? w2 : 1.0)) / (ok > 0 ? w : 1.0);
    v[0][l] = k * x, v[1][l] = k * y, v[2][l] = k * z;
    need[l] = 1.0 - ok;
  }
}

// q = exp(v) q, normalised, as quat_rotate_by does it where |v| <= 0.1 rad (its series);
// elsewhere need[l] = 1 and the caller calls quat_rotate_by
SIM_INLINE void qrot_lanes(lane* restrict q, lane* restrict v, lane need) {
  L {
    double a2 = v[0][l] * v[0][l] + v[1][l] * v[1][l] + v[2][l] * v[2][l], c, k;
    sim_exp_series(a2 <= 0.01 ? a2 : 0.0, &c, &k);
    double ex = v[0][l] * k, ey = v[1][l] * k, ez = v[2][l] * k;
    double aw = c, bw = q[0][l], bx = q[1][l], by = q[2][l], bz = q[3][l];
    double rw = aw * bw - ex * bx - ey * by - ez * bz;
    double rx = aw * bx + ex * bw + ey * bz - ez * by;
    double ry = aw * by - ex * bz + ey * bw + ez * bx;
    double rz = aw * bz + ex * by - ey * bx + ez * bw;
    double n = sqrt(rw * rw + rx * rx + ry * ry + rz * rz), in = 1.0 / n;
    q[0][l] = rw * in, q[1][l] = rx * in, q[2][l] = ry * in, q[3][l] = rz * in;
    need[l] = a2 <= 0.01 ? 0.0 : 1.0;
  }
}

// ---------------------------------------------------------------------------------------------
// the frames' prediction and velocities, SIM_W segments at a time (the maps' series vectorise).
// Whole groups move between the segments' quaternions and the lanes by interleaved loads and
// stores in lane loops (vector permutes): lanes filled or read one scalar at a time made the
// vector code wait on store forwarding.

// lanes of SIM_W consecutive quaternions (n < SIM_W: the rest repeat the first)
SIM_INLINE void quat_lanes(const vd_quat* restrict src, int n, lane* restrict q) {
  if (n == SIM_W) {
    const double* restrict a = (const double*)src;
    L q[0][l] = a[4 * l], q[1][l] = a[4 * l + 1], q[2][l] = a[4 * l + 2], q[3][l] = a[4 * l + 3];
    return;
  }
  for (int l = 0; l < SIM_W; l++) {
    vd_quat c = src[l < n ? l : 0];
    q[0][l] = c.w, q[1][l] = c.x, q[2][l] = c.y, q[3][l] = c.z;
  }
}

// segments [t0, t1) of a dynamic step with the loads kept in the residual (the direct solver):
// seg_prev = the frame, the frame turned by h omega (fixed ones kept): quat_rotate_by's bytes
SIM_CLONES void sim_frame_predict(const vd_sim_model* m, vd_sim_data* d, sim_work* w, double h, int t0, int t1) {
  memcpy(w->seg_prev + t0, d->seg_quat + t0, (size_t)(t1 - t0) * sizeof(vd_quat));
  for (int b = t0; b < t1; b += SIM_W) {
    int n = t1 - b < SIM_W ? t1 - b : SIM_W;
    // a last short group goes through a padded copy (the lane loops stay free of branches)
    vd_quat qb[SIM_W];
    vd_vec3 ob[SIM_W];
    const double *qs = (const double*)(d->seg_quat + b), *os = (const double*)(d->seg_omega + b);
    double* qo = (double*)(d->seg_quat + b);
    if (n < SIM_W) {
      for (int l = 0; l < SIM_W; l++) qb[l] = d->seg_quat[b + (l < n ? l : 0)], ob[l] = d->seg_omega[b + (l < n ? l : 0)];
      qs = (const double*)qb, os = (const double*)ob, qo = (double*)qb;
    }
    lane q[4], v[3], need;
    L q[0][l] = qs[4 * l], q[1][l] = qs[4 * l + 1], q[2][l] = qs[4 * l + 2], q[3][l] = qs[4 * l + 3];
    L v[0][l] = os[3 * l] * h, v[1][l] = os[3 * l + 1] * h, v[2][l] = os[3 * l + 2] * h;
    qrot_lanes(q, v, need);
    L qo[4 * l] = q[0][l], qo[4 * l + 1] = q[1][l], qo[4 * l + 2] = q[2][l], qo[4 * l + 3] = q[3][l];
    if (n < SIM_W) memcpy(d->seg_quat + b, qb, (size_t)n * sizeof(vd_quat));
    // fixed frames stay; turns beyond the series' range take the scalar map
    for (int l = 0; l < n; l++) {
      int t = b + l;
      if (m->seg_flags[t] & VD_SIM_FIXED) d->seg_quat[t] = w->seg_prev[t];
      else if (need[l] > 0) d->seg_quat[t] = quat_rotate_by(w->seg_prev[t], vd_scale(d->seg_omega[t], h));
    }
  }
}

SIM_CLONES void sim_frame_velocities(const vd_sim_model* m, vd_sim_data* d, const sim_work* w, double s, int t0, int t1) {
  for (int b = t0; b < t1; b += SIM_W) {
    int n = t1 - b < SIM_W ? t1 - b : SIM_W;
    lane q[4], qp[4], dq[4], v[3], need;
    quat_lanes(d->seg_quat + b, n, q);
    quat_lanes(w->seg_prev + b, n, qp);
    qmul_lanes(q, qp, dq, 1, -1);
    qlog_lanes(dq, v, need);
    if (n == SIM_W) {
      double* restrict o = (double*)(d->seg_omega + b);
      L o[3 * l] = v[0][l] * s, o[3 * l + 1] = v[1][l] * s, o[3 * l + 2] = v[2][l] * s;
    } else {
      for (int l = 0; l < n; l++) d->seg_omega[b + l] = vd_v3(v[0][l] * s, v[1][l] * s, v[2][l] * s);
    }
    for (int l = 0; l < n; l++) {
      int t = b + l;
      if (m->seg_flags[t] & VD_SIM_FIXED) d->seg_omega[t] = vd_v3(0, 0, 0);
      else if (need[l] > 0) d->seg_omega[t] = vd_scale(quat_log((vd_quat){dq[0][l], dq[1][l], dq[2][l], dq[3][l]}), s);
    }
  }
}

// each segment's air drag (sim_forces.c's seg_drag, the same operations lane by lane): groups
// of SIM_W segments from t0 while whole groups fit; returns where it stopped (the caller takes
// the rest). Lanes that take no drag or have no lamina compute it anyway and drop it.
SIM_CLONES int sim_seg_drag_lanes(const vd_sim_model* m, const vd_sim_data* d, sim_work* w, vd_vec3 wind, double q, int t0,
                                  int t1) {
  const double* restrict vel = (const double*)d->node_vel;
  const double* restrict mass = d->node_mass;
  const int* restrict fixed = m->node_fixed;
  const int* restrict start = d->seg_start;
  const int* restrict snode = m->seg_node;
  const unsigned* restrict flags = m->seg_flags;
  const double* restrict ln = m->seg_leaf_normal;
  const double *restrict rad = m->seg_radius, *restrict len0 = m->seg_len0, *restrict cd = m->seg_cd;
  const double lcd = m->leaf_cd;
  int b = t0;
  for (; b + SIM_W <= t1; b += SIM_W) {
    const double* restrict qs = (const double*)(d->seg_quat + b);
    double* restrict sd = w->seg_drag + 5 * (size_t)b;
    lane ma, mb, u[3], d3[3], up[3], kq, f[3], cc, nw[3], leaf;
    L {
      int na = start[b + l], nb = snode[2 * (b + l) + 1];
      ma[l] = !fixed[na] && mass[na] > 0 ? 1.0 : 0.0;
      mb[l] = !fixed[nb] && mass[nb] > 0 ? 1.0 : 0.0;
      double vax = ma[l] > 0 ? vel[3 * na] : 0.0, vay = ma[l] > 0 ? vel[3 * na + 1] : 0.0, vaz = ma[l] > 0 ? vel[3 * na + 2] : 0.0;
      double vbx = mb[l] > 0 ? vel[3 * nb] : 0.0, vby = mb[l] > 0 ? vel[3 * nb + 1] : 0.0, vbz = mb[l] > 0 ? vel[3 * nb + 2] : 0.0;
      u[0][l] = wind.x - (vax + vbx) * 0.5, u[1][l] = wind.y - (vay + vby) * 0.5, u[2][l] = wind.z - (vaz + vbz) * 0.5;
    }
    L {
      double qw = qs[4 * l], qx = qs[4 * l + 1], qy = qs[4 * l + 2], qz = qs[4 * l + 3];
      d3[0][l] = 2 * (qx * qz + qw * qy), d3[1][l] = 2 * (qy * qz - qw * qx), d3[2][l] = 1 - 2 * (qx * qx + qy * qy);
      // the lamina normal rotated into the world: q_rotate's operations
      double vx = ln[3 * (b + l)], vy = ln[3 * (b + l) + 1], vz = ln[3 * (b + l) + 2];
      leaf[l] = vx != 0 || vy != 0 || vz != 0 ? 1.0 : 0.0;
      double tx = (qy * vz - qz * vy) * 2.0, ty = (qz * vx - qx * vz) * 2.0, tz = (qx * vy - qy * vx) * 2.0;
      nw[0][l] = (vx + tx * qw) + (qy * tz - qz * ty);
      nw[1][l] = (vy + ty * qw) + (qz * tx - qx * tz);
      nw[2][l] = (vz + tz * qw) + (qx * ty - qy * tx);
    }
    L {
      double dot = u[0][l] * d3[0][l] + u[1][l] * d3[1][l] + u[2][l] * d3[2][l];
      up[0][l] = u[0][l] + d3[0][l] * -dot, up[1][l] = u[1][l] + d3[1][l] * -dot, up[2][l] = u[2][l] + d3[2][l] * -dot;
      double area = 2 * rad[b + l] * len0[b + l];
      kq[l] = q * cd[b + l] * area * sqrt(up[0][l] * up[0][l] + up[1][l] * up[1][l] + up[2][l] * up[2][l]);
      f[0][l] = up[0][l] * kq[l], f[1][l] = up[1][l] * kq[l], f[2][l] = up[2][l] * kq[l];
      cc[l] = 2 * kq[l];
    }
    L {
      double a = sqrt(nw[0][l] * nw[0][l] + nw[1][l] * nw[1][l] + nw[2][l] * nw[2][l]);
      double un = (u[0][l] * nw[0][l] + u[1][l] * nw[1][l] + u[2][l] * nw[2][l]) / (leaf[l] > 0 ? a : 1.0);
      double s = q * lcd * fabs(un) * un;
      double fx = f[0][l] + nw[0][l] * s, fy = f[1][l] + nw[1][l] * s, fz = f[2][l] + nw[2][l] * s;
      double c2 = cc[l] + 2 * q * lcd * a * fabs(un);
      int on = !(flags[b + l] & (VD_SIM_FIXED | VD_SIM_FRUITSEG)) && (ma[l] > 0 || mb[l] > 0);
      sd[5 * l] = leaf[l] > 0 ? fx : f[0][l];
      sd[5 * l + 1] = leaf[l] > 0 ? fy : f[1][l];
      sd[5 * l + 2] = leaf[l] > 0 ? fz : f[2][l];
      sd[5 * l + 3] = leaf[l] > 0 ? c2 : cc[l];
      sd[5 * l + 4] = on ? (ma[l] > 0 ? (mb[l] > 0 ? 0.5 : 1.0) : 0.0) : -1.0;
    }
  }
  return b;
}

// ---------------------------------------------------------------------------------------------
// linearisation of the bodies and joints of a block

// a block's inputs, gathered lane by lane (the model's part is in the plan's sim_stat)
typedef struct sim_in {
  lane qt[4], qp[4], qv[4];   // frame, parent frame (identity: no bend rows), frame at the step's start
  lane e[3];                  // x_end - x_start (m)
  lane dx[3];                 // x_end - x_start_of_step - h v (m)
  lane fe[3], om[3], te[3];   // external force (N), angular velocity (rad/s), external torque (N m)
  lane lam[6], cp[6];         // multipliers, constraint values at the step's start (0 without damping)
  lane mass, tieh, tieg[3];   // mass with drag (kg), ties on the node
  lane bend;                  // 1 when the bend rows are active
  sim_stat* st;               // the block's model data
} sim_in;

// gather the lanes of block bi from their slots (padding: a unit body and joint)
PROF_NOINLINE static void gather_in(const vd_sim_model* m, const vd_sim_data* d, const sim_work* w, const sim_step_ctx* ctx,
                                    sim_in* restrict in, int bi) {
  const sim_plan* p = &w->plan;
  const double h = ctx->h;
  const int damped = ctx->gamma > 0;
  if (!damped)
    for (int k = 0; k < 6; k++) L in->cp[k][l] = 0;
  for (int l = 0; l < SIM_W; l++) {
    int s = bi * SIM_W + l, t = p->slot_seg[s];
    if (t < 0) {
      double* f = &in->qt[0][0];
      for (size_t k = 0; k < offsetof(sim_in, st) / sizeof(lane); k++) f[SIM_W * k + l] = 0;
      in->qt[0][l] = in->qp[0][l] = in->qv[0][l] = 1;
      in->mass[l] = 1;
      continue;
    }
    int nb = m->seg_node[2 * t + 1], na = d->seg_start[t], par = m->seg_parent[t];
    int bend = !d->seg_broken[t] && par >= 0;
    vd_quat q = d->seg_quat[t], qp = bend ? d->seg_quat[par] : vd_quat_identity(), qv = w->seg_prev[t];
    in->qt[0][l] = q.w, in->qt[1][l] = q.x, in->qt[2][l] = q.y, in->qt[3][l] = q.z;
    in->qp[0][l] = qp.w, in->qp[1][l] = qp.x, in->qp[2][l] = qp.y, in->qp[3][l] = qp.z;
    in->qv[0][l] = qv.w, in->qv[1][l] = qv.x, in->qv[2][l] = qv.y, in->qv[3][l] = qv.z;
    vd_vec3 xb = d->node_pos[nb], xa = d->node_pos[na], xv = w->node_prev[nb], v = d->node_vel[nb];
    vd_vec3 fe = w->node_fext[nb], om = d->seg_omega[t], te = w->seg_text[t];
    in->e[0][l] = xb.x - xa.x, in->e[1][l] = xb.y - xa.y, in->e[2][l] = xb.z - xa.z;
    in->dx[0][l] = xb.x - xv.x - v.x * h, in->dx[1][l] = xb.y - xv.y - v.y * h, in->dx[2][l] = xb.z - xv.z - v.z * h;
    in->fe[0][l] = fe.x, in->fe[1][l] = fe.y, in->fe[2][l] = fe.z;
    in->om[0][l] = om.x, in->om[1][l] = om.y, in->om[2][l] = om.z;
    in->te[0][l] = te.x, in->te[1][l] = te.y, in->te[2][l] = te.z;
    const double* lam = d->seg_lambda + 6 * t;
    for (int k = 0; k < 6; k++) in->lam[k][l] = lam[k];
    if (damped) {
      const double* cp = w->c_prev + 6 * t;
      for (int k = 0; k < 6; k++) in->cp[k][l] = cp[k];
    }
    for (int k = 0; k < 3; k++) in->tieg[k][l] = p->tie_g[3 * s + k];
    in->mass[l] = d->node_mass[nb] + h * w->node_drag[nb];
    in->tieh[l] = p->tie_h[s];
    in->bend[l] = bend;
  }
}

// what the linearisation of a block passes to its elimination alone (on the stack)
typedef struct sim_fw {
  lane c[6];    // damped constraint values c': stretch rows in world axes (m), bend (1/m)
  lane al[9];   // damped compliances alpha~': stretch (upper 3x3, world), bend (diagonal)
  lane lf[6];   // the joint's multipliers: stretch as R lambda_s / l0 (world), bend
  lane mi[3];   // tips: 1 / (mass + ties), 1 / ib, 1 / it - 1 / ib
  lane d3[3];   // the frame's d3
  lane ok;      // 1 while both factorisations of the lane held
} sim_fw;

// bend-twist strain and its Jacobian dC/dpsi of the lanes (sim_bend_strain, lane-parallel);
// lanes whose log needs libm are recomputed by sim_bend_strain itself
SIM_INLINE void bend_lanes(vd_sim_bend kind, sim_in* in, lane* restrict cb, lane* restrict dc) {
  lane qr[4];
  qmul_lanes(in->qp, in->qt, qr, -1, 1);
  // the sign that puts q_rel on the rest rotation's side
  L {
    double dot = qr[0][l] * in->st->q0[0][l] + qr[1][l] * in->st->q0[1][l] + qr[2][l] * in->st->q0[2][l] + qr[3][l] * in->st->q0[3][l];
    double sg = dot < 0 ? -1.0 : 1.0;
    qr[0][l] *= sg, qr[1][l] *= sg, qr[2][l] *= sg, qr[3][l] *= sg;
  }
  if (kind == VD_SIM_BEND_QUAT) {
    L {
      double f = 1.0 / in->st->lbar[l], k2 = 2.0 * f;
      cb[0][l] = k2 * (qr[1][l] - in->st->q0[1][l]);
      cb[1][l] = k2 * (qr[2][l] - in->st->q0[2][l]);
      cb[2][l] = k2 * (qr[3][l] - in->st->q0[3][l]);
      dc[0][l] = f * qr[0][l], dc[1][l] = f * qr[3][l], dc[2][l] = -f * qr[2][l];
      dc[3][l] = -f * qr[3][l], dc[4][l] = f * qr[0][l], dc[5][l] = f * qr[1][l];
      dc[6][l] = f * qr[2][l], dc[7][l] = -f * qr[1][l], dc[8][l] = f * qr[0][l];
    }
    return;
  }
  // log measure: the turn qd = conj(q0) q (w >= 0), ph = log(qd), C = ph / l-bar,
  // dC/dpsi = J_l^-1(ph) R0^T / l-bar, J_l^-1 = I - [ph]x / 2 + beta [ph]x^2
  lane qd[4], ph[3], need, r0[9], beta, f, dd, jl[9];
  qmul_lanes(in->st->q0, qr, qd, -1, 1);
  qlog_lanes(qd, ph, need);
  for (int l = 0; l < SIM_W; l++)
    if (need[l] > 0) {
      vd_vec3 v = quat_log((vd_quat){qd[0][l], qd[1][l], qd[2][l], qd[3][l]});
      ph[0][l] = v.x, ph[1][l] = v.y, ph[2][l] = v.z;
    }
  // beta = (1 - (a / 2) cot(a / 2)) / a^2, cot(a / 2) = w / s; its series below a = 0.1 (to 1e-17)
  L {
    double a2 = ph[0][l] * ph[0][l] + ph[1][l] * ph[1][l] + ph[2][l] * ph[2][l];
    double s = sqrt(qd[1][l] * qd[1][l] + qd[2][l] * qd[2][l] + qd[3][l] * qd[3][l]);
    double ser = 1.0 / 12 + a2 * (1.0 / 720 + a2 * (1.0 / 30240 + a2 * (1.0 / 1209600 + a2 * (1.0 / 47900160))));
    double a = sqrt(a2);
    int big = a2 > 0.01;
    double frm = (1 - 0.5 * a * qd[0][l] / (big ? s : 1.0)) / (big ? a2 : 1.0);
    beta[l] = big ? frm : ser;
    dd[l] = 1 - beta[l] * a2;
    f[l] = 1.0 / in->st->lbar[l];
  }
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) L jl[3 * i + k][l] = beta[l] * ph[i][l] * ph[k][l] + (i == k ? dd[l] : 0.0);
  L jl[1][l] += 0.5 * ph[2][l], jl[2][l] -= 0.5 * ph[1][l], jl[5][l] += 0.5 * ph[0][l];
  L jl[3][l] -= 0.5 * ph[2][l], jl[6][l] += 0.5 * ph[1][l], jl[7][l] -= 0.5 * ph[0][l];
  rot_lanes(in->st->q0, r0);
  for (int k = 0; k < 3; k++) L cb[k][l] = f[l] * ph[k][l];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      L dc[3 * i + k][l] = f[l] * (jl[3 * i][l] * r0[3 * k][l] + jl[3 * i + 1][l] * r0[3 * k + 1][l] + jl[3 * i + 2][l] * r0[3 * k + 2][l]);
}

// linearise a block from its gathered inputs: body matrix (mass + ties) I and the inertia, the
// residual g with -J^T lambda, the joint's values, compliances and Jacobians (world stretch rows)
PROF_NOINLINE SIM_INLINE_PROF void eval_block(sim_blk* restrict b, sim_fw* restrict fw, sim_in* in, double h, double gam,
                                               vd_sim_bend kind) {
  double h2 = h * h, ig = 1.0 / (1 + gam);
  lane rt[9], rp[9], dq[4], dth[3], need, cb[3], dc[9];
  rot_lanes(in->qt, rt);
  for (int k = 0; k < 4; k++) L b->qt[k][l] = in->qt[k][l];
  L b->l0[l] = in->st->l0[l];
  rot_lanes(in->qp, rp);
  // the frame's turn since the step's start
  qmul_lanes(in->qt, in->qv, dq, 1, -1);
  qlog_lanes(dq, dth, need);
  for (int l = 0; l < SIM_W; l++)
    if (need[l] > 0) {
      vd_vec3 v = quat_log((vd_quat){dq[0][l], dq[1][l], dq[2][l], dq[3][l]});
      dth[0][l] = v.x, dth[1][l] = v.y, dth[2][l] = v.z;
    }
  bend_lanes(kind, in, cb, dc);
  // compliances / h^2 (inactive bend rows: unit compliance)
  lane acs[3], acb[3];
  for (int k = 0; k < 3; k++) {
    L acs[k][l] = in->st->cs[k][l] / h2;
    L acb[k][l] = (in->bend[l] > 0 ? in->st->cb[k][l] : 1.0) / h2;
  }
  // body: world inertia ib I + (it - ib) d3 d3^T; g_t = I (dth - h om) - h^2 (tau - om x I om)
  lane ci, iw[6], dt[3], io[3], tq[3], il0;
  L ci[l] = in->st->it[l] - in->st->ib[l], il0[l] = 1.0 / in->st->l0[l];
  L fw->d3[0][l] = rt[2][l], fw->d3[1][l] = rt[5][l], fw->d3[2][l] = rt[8][l];
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++) L iw[SYM[i][k]][l] = (i == k ? in->st->ib[l] : 0.0) + ci[l] * fw->d3[i][l] * fw->d3[k][l];
  for (int k = 0; k < 3; k++) L dt[k][l] = dth[k][l] - h * in->om[k][l];
  for (int i = 0; i < 3; i++) {
    L io[i][l] = iw[SYM[i][0]][l] * in->om[0][l] + iw[SYM[i][1]][l] * in->om[1][l] + iw[SYM[i][2]][l] * in->om[2][l];
    L b->g[3 + i][l] = iw[SYM[i][0]][l] * dt[0][l] + iw[SYM[i][1]][l] * dt[1][l] + iw[SYM[i][2]][l] * dt[2][l];
  }
  lane oxi[3];
  CROSS(oxi, in->om, io);
  for (int k = 0; k < 3; k++) L tq[k][l] = in->te[k][l] - oxi[k][l];
  // stretch-shear: C_s = R^T E / l0 - e3, damped value v (material); the world rows take
  // f = R lambda_s / l0, c^ = l0 R v and alpha^ = l0^2 R diag(alpha~) R^T / (1 + gamma)
  lane v[3];
  for (int k = 0; k < 3; k++)
    L {
      double cs = (rt[k][l] * in->e[0][l] + rt[3 + k][l] * in->e[1][l] + rt[6 + k][l] * in->e[2][l]) * il0[l] - (k == 2 ? 1.0 : 0.0);
      v[k][l] = (cs + acs[k][l] * in->lam[k][l] + gam * (cs - in->cp[k][l])) * ig;
    }
  for (int i = 0; i < 3; i++) {
    L fw->lf[i][l] = (rt[3 * i][l] * in->lam[0][l] + rt[3 * i + 1][l] * in->lam[1][l] + rt[3 * i + 2][l] * in->lam[2][l]) * il0[l];
    L fw->c[i][l] = in->st->l0[l] * (rt[3 * i][l] * v[0][l] + rt[3 * i + 1][l] * v[1][l] + rt[3 * i + 2][l] * v[2][l]);
  }
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++)
      L fw->al[SYM[i][k]][l] = in->st->l0[l] * in->st->l0[l] * ig *
                              (rt[3 * i][l] * acs[0][l] * rt[3 * k][l] + rt[3 * i + 1][l] * acs[1][l] * rt[3 * k + 1][l] +
                               rt[3 * i + 2][l] * acs[2][l] * rt[3 * k + 2][l]);
  // bend-twist: G = dC/dpsi R_p^T (zero when inactive)
  lane* gm = b->gm;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      L gm[3 * i + k][l] = in->bend[l] * (dc[3 * i][l] * rp[3 * k][l] + dc[3 * i + 1][l] * rp[3 * k + 1][l] + dc[3 * i + 2][l] * rp[3 * k + 2][l]);
  for (int k = 0; k < 3; k++)
    L {
      double c = in->bend[l] * cb[k][l];
      fw->c[3 + k][l] = (c + acb[k][l] * in->lam[3 + k][l] + gam * (c - in->cp[3 + k][l])) * ig;
      fw->al[6 + k][l] = acb[k][l] * ig;
      fw->lf[3 + k][l] = in->lam[3 + k][l];
    }
  // g = M (y - y_n - h v_n) - h^2 f - J^T lambda, J^T lambda = [f; f x E + G^T lambda_b]
  lane fxe[3];
  CROSS(fxe, fw->lf, in->e);
  for (int k = 0; k < 3; k++) {
    L b->g[k][l] = in->mass[l] * in->dx[k][l] - h2 * in->fe[k][l] - fw->lf[k][l] + in->tieg[k][l];
    L b->g[3 + k][l] = b->g[3 + k][l] - h2 * tq[k][l] - fxe[k][l] -
                       (gm[k][l] * in->lam[3][l] + gm[3 + k][l] * in->lam[4][l] + gm[6 + k][l] * in->lam[5][l]);
    L b->e[k][l] = in->e[k][l];
  }
  // body matrix: (mass + ties) I and the inertia
  for (int k = 0; k < 15; k++) L b->h[k][l] = 0;
  L {
    double mt = in->mass[l] + in->tieh[l];
    b->h[S00][l] = mt, b->h[S11][l] = mt, b->h[S22][l] = mt;
    fw->mi[0][l] = 1.0 / mt, fw->mi[1][l] = 1.0 / in->st->ib[l], fw->mi[2][l] = 1.0 / in->st->it[l] - 1.0 / in->st->ib[l];
  }
  for (int k = 0; k < 6; k++) L b->h[15 + k][l] = iw[k][l];
}

// region of interest: the joints of held children still hold slot s's body (lane l), as leaf
// joints with a kinematic child: H += J_p^T alpha~'^-1 J_p, g += J_p^T alpha~'^-1 c' - J_p^T lambda
// with J_p = -[[a, 0], [0, G]] (material rows); the linearisation is kept for the multipliers
static void held_terms(const vd_sim_model* m, const vd_sim_data* d, const sim_work* w, const sim_step_ctx* ctx,
                       sim_blk* b, int l, int s) {
  const sim_plan* p = &w->plan;
  double h2 = ctx->h * ctx->h, gam = ctx->gamma;
  for (int k = p->held_start[s]; k < p->held_start[s + 1]; k++) {
    int c = p->held_seg[k];
    sim_joint j;
    sim_joint_eval(m, d, c, &j);
    const double* lam = d->seg_lambda + 6 * c;
    const double* cp = w->c_prev + 6 * c;
    double* lin = p->held_lin + 30 * k;  // a (9), G (9), c' (6), alpha~' (6)
    double cv[6], ap[6];
    for (int i = 0; i < 6; i++) {
      double at = j.alpha[i] / h2;
      ap[i] = at / (1 + gam);
      cv[i] = (j.c[i] + at * lam[i] + gam * (j.c[i] - (gam > 0 ? cp[i] : 0.0))) / (1 + gam);
      if (i >= 3 && !j.bend) ap[i] = 1, cv[i] = 0;
    }
    memcpy(lin, j.a, 9 * sizeof(double));
    memcpy(lin + 9, j.g, 9 * sizeof(double));
    memcpy(lin + 18, cv, 6 * sizeof(double));
    memcpy(lin + 24, ap, 6 * sizeof(double));
    for (int i = 0; i < 3; i++)
      for (int q = i; q < 3; q++) {
        double sa = 0, sg = 0;
        for (int r = 0; r < 3; r++) {
          sa += j.a[3 * r + i] * j.a[3 * r + q] / ap[r];
          sg += j.g[3 * r + i] * j.g[3 * r + q] / ap[3 + r];
        }
        b->h[SYM[i][q]][l] += sa;
        b->h[15 + SYM[i][q]][l] += sg;
      }
    for (int i = 0; i < 3; i++) {
      double ga = 0, gg = 0;
      for (int r = 0; r < 3; r++) {
        ga += j.a[3 * r + i] * (lam[r] - cv[r] / ap[r]);
        gg += j.g[3 * r + i] * (lam[3 + r] - cv[3 + r] / ap[3 + r]);
      }
      b->g[i][l] += ga;
      b->g[3 + i][l] += gg;
    }
  }
}

// add the children's contributions to the bodies of block bi, each body's in their fixed order:
// round j adds every lane's j-th child, loaded lane-parallel (gathers) from the child's block,
// whose stores are long done; adding lane by lane with scalar loads of the lanes the block's
// linearisation had just written as vectors stalled on store forwarding (a fifth of the step)
SIM_INLINE void gather_kids(const vd_sim_data* d, const sim_plan* p, sim_blk* restrict b, int bi) {
  const double* restrict dh = &p->kid[0].dh[0][0];
  const double* restrict dg = &p->kid[0].dg[0][0];
  // the rounds and the lanes' children come from the plan (indices computed here and stored a
  // scalar at a time would make the vector loads below wait for them), unless a child broke
  int broken = 0;
  for (int k = p->kid_start[bi * SIM_W]; k < p->kid_start[bi * SIM_W + SIM_W]; k++) broken |= d->seg_broken[p->slot_seg[p->kid_slot[k]]];
  ptrdiff_t dyn_off[SIM_W];
  lane dyn_use;
  for (int r = p->kround[bi]; r < p->kround[bi + 1]; r++) {
    const ptrdiff_t* restrict off = p->koff + (size_t)SIM_W * r;
    const double* restrict use = p->kuse + (size_t)SIM_W * r;
    if (broken) {
      int j = r - p->kround[bi];
      for (int l = 0; l < SIM_W; l++) {
        int s = bi * SIM_W + l;
        int c = j < p->kid_start[s + 1] - p->kid_start[s] ? p->kid_slot[p->kid_start[s] + j] : -1;
        int on = c >= 0 && !d->seg_broken[p->slot_seg[c]];  // a broken child hangs from its spare now
        dyn_use[l] = on ? 1.0 : 0.0;
        dyn_off[l] = on ? off[l] : 0;
      }
      off = dyn_off, use = dyn_use;
    }
    for (int i = 0; i < 21; i++)
      L {
        double v = dh[off[l] + SIM_W * i];
        b->h[i][l] = use[l] > 0 ? b->h[i][l] + v : b->h[i][l];
      }
    for (int i = 0; i < 6; i++)
      L {
        double v = dg[off[l] + SIM_W * i];
        b->g[i][l] = use[l] > 0 ? b->g[i][l] + v : b->g[i][l];
      }
  }
}

// ---------------------------------------------------------------------------------------------
// the block kernels (lane-parallel)

// forward elimination of a block: H^-1, S = J H^-1 J^T + alpha^, r, S^-1 and the contribution
// to the parent; tip: the body matrix is (mass) I and the inertia, its inverse written down
SIM_INLINE void forward_kernel(sim_blk* restrict b, sim_fw* restrict fw, sim_kid* restrict kc, const int tip) {
  // H^-1 and S^-1 are written where the block keeps them (a tip's straight into b->h)
  lane hl[21], sm[21], ok, *hi = tip ? b->h : hl, *si = b->s;
  L ok[l] = 1.0;
  if (tip) {
    // (m I)^-1 and R diag(1/ib, 1/ib, 1/it) R^T = (1/ib) I + (1/it - 1/ib) d3 d3^T
    for (int k = 0; k < 15; k++) L hi[k][l] = 0;
    L hi[S00][l] = fw->mi[0][l];
    L hi[S11][l] = fw->mi[0][l];
    L hi[S22][l] = fw->mi[0][l];
    for (int i = 0; i < 3; i++)
      for (int k = i; k < 3; k++)
        L hi[15 + SYM[i][k]][l] = (i == k ? fw->mi[1][l] : 0.0) + fw->mi[2][l] * fw->d3[i][l] * fw->d3[k][l];
  } else {
    inv6s(b->h, hi, ok);
  }
  lane *ha = hi, *hb = hi + 6, *hd = hi + 15, *e = b->e, *g = b->gm;
  // Q = [E]x Hb^T (column j: E x row j of Hb), Z = [E]x Hd (column j: E x column j of Hd)
  lane q[9], z[9], zx[9], u[3], w[3];
  for (int j = 0; j < 3; j++) {
    L u[0][l] = hb[3 * j][l], u[1][l] = hb[3 * j + 1][l], u[2][l] = hb[3 * j + 2][l];
    L w[0][l] = hd[SYM[0][j]][l], w[1][l] = hd[SYM[1][j]][l], w[2][l] = hd[SYM[2][j]][l];
    L {
      q[j][l] = e[1][l] * u[2][l] - e[2][l] * u[1][l];
      q[3 + j][l] = e[2][l] * u[0][l] - e[0][l] * u[2][l];
      q[6 + j][l] = e[0][l] * u[1][l] - e[1][l] * u[0][l];
      z[j][l] = e[1][l] * w[2][l] - e[2][l] * w[1][l];
      z[3 + j][l] = e[2][l] * w[0][l] - e[0][l] * w[2][l];
      z[6 + j][l] = e[0][l] * w[1][l] - e[1][l] * w[0][l];
    }
  }
  // Z [E]x^T: row i is E x row i of Z
  for (int i = 0; i < 3; i++)
    L {
      zx[3 * i][l] = e[1][l] * z[3 * i + 2][l] - e[2][l] * z[3 * i + 1][l];
      zx[3 * i + 1][l] = e[2][l] * z[3 * i][l] - e[0][l] * z[3 * i + 2][l];
      zx[3 * i + 2][l] = e[0][l] * z[3 * i + 1][l] - e[1][l] * z[3 * i][l];
    }
  // S_ss = Ha + Q + Q^T + Z [E]x^T + alpha^_s; S_sb = (Hb + Z) G^T; S_bb = G Hd G^T + alpha^_b
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++)
      L sm[SYM[i][k]][l] = ha[SYM[i][k]][l] + q[3 * i + k][l] + q[3 * k + i][l] + zx[3 * i + k][l] + fw->al[SYM[i][k]][l];
  lane bz[9], vg[9];
  for (int k = 0; k < 9; k++) L bz[k][l] = hb[k][l] + z[k][l];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      L sm[6 + 3 * i + k][l] = bz[3 * i][l] * g[3 * k][l] + bz[3 * i + 1][l] * g[3 * k + 1][l] + bz[3 * i + 2][l] * g[3 * k + 2][l];
      L vg[3 * i + k][l] = g[3 * i][l] * hd[SYM[0][k]][l] + g[3 * i + 1][l] * hd[SYM[1][k]][l] + g[3 * i + 2][l] * hd[SYM[2][k]][l];
    }
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++)
      L sm[15 + SYM[i][k]][l] = vg[3 * i][l] * g[3 * k][l] + vg[3 * i + 1][l] * g[3 * k + 1][l] + vg[3 * i + 2][l] * g[3 * k + 2][l];
  L sm[15 + S00][l] += fw->al[6][l];
  L sm[15 + S11][l] += fw->al[7][l];
  L sm[15 + S22][l] += fw->al[8][l];
  // r = -c' + J H^-1 g: hg = H^-1 g = (u, w); r_s = -c_s + u + E x w, r_b = -c_b + G w
  lane hg[6], ew[3], r[6];
  mul6s(hi, b->g, hg);
  CROSS(ew, e, hg + 3);
  for (int i = 0; i < 3; i++) {
    L r[i][l] = -fw->c[i][l] + hg[i][l] + ew[i][l];
    L r[3 + i][l] = -fw->c[3 + i][l] + g[3 * i][l] * hg[3][l] + g[3 * i + 1][l] * hg[4][l] + g[3 * i + 2][l] * hg[5][l];
  }
  inv6s(sm, si, ok);
  // contribution J_p^T S^-1 J_p = [[S^-1_A, S^-1_B G], [., G^T S^-1_D G]] and to g_p:
  // [(S^-1 r)_s + f; G^T ((S^-1 r)_b + lambda_b)]
  lane *sa = si, *sb = si + 6, *sd = si + 15;
  lane ug[9], sr[6], pb[3];
  for (int k = 0; k < 6; k++) L kc->dh[k][l] = sa[k][l];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      L kc->dh[6 + 3 * i + k][l] = sb[3 * i][l] * g[k][l] + sb[3 * i + 1][l] * g[3 + k][l] + sb[3 * i + 2][l] * g[6 + k][l];
      L ug[3 * i + k][l] = sd[SYM[i][0]][l] * g[k][l] + sd[SYM[i][1]][l] * g[3 + k][l] + sd[SYM[i][2]][l] * g[6 + k][l];
    }
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++)
      L kc->dh[15 + SYM[i][k]][l] = g[i][l] * ug[k][l] + g[3 + i][l] * ug[3 + k][l] + g[6 + i][l] * ug[6 + k][l];
  mul6s(si, r, sr);
  for (int k = 0; k < 3; k++) {
    L kc->dg[k][l] = sr[k][l] + fw->lf[k][l];
    L pb[k][l] = sr[3 + k][l] + fw->lf[3 + k][l];
  }
  for (int k = 0; k < 3; k++) L kc->dg[3 + k][l] = g[k][l] * pb[0][l] + g[3 + k][l] * pb[1][l] + g[6 + k][l] * pb[2][l];
  if (!tip)
    for (int k = 0; k < 21; k++) L b->h[k][l] = hi[k][l];
  for (int k = 0; k < 6; k++) L b->r[k][l] = r[k][l];
  L fw->ok[l] = ok[l];
}

// back substitution of a block, the parents' updates in dyp: dl = S^-1 (r + [dx_p; G dth_p]),
// dy = H^-1 (-g + [dl_s; dl_s x E + G^T dl_b])
PROF_NOINLINE SIM_INLINE_PROF void back_kernel(sim_blk* restrict b, lane* restrict dyp) {
  lane *g = b->gm, *e = b->e;
  lane v[6], tv[6], lxe[3];
  for (int i = 0; i < 3; i++) {
    L v[i][l] = b->r[i][l] + dyp[i][l];
    L v[3 + i][l] = b->r[3 + i][l] + g[3 * i][l] * dyp[3][l] + g[3 * i + 1][l] * dyp[4][l] + g[3 * i + 2][l] * dyp[5][l];
  }
  mul6s(b->s, v, b->dl);
  lane* dl = b->dl;
  L {
    lxe[0][l] = dl[1][l] * e[2][l] - dl[2][l] * e[1][l];
    lxe[1][l] = dl[2][l] * e[0][l] - dl[0][l] * e[2][l];
    lxe[2][l] = dl[0][l] * e[1][l] - dl[1][l] * e[0][l];
  }
  for (int k = 0; k < 3; k++) {
    L tv[k][l] = -b->g[k][l] + dl[k][l];
    L tv[3 + k][l] = -b->g[3 + k][l] + lxe[k][l] + g[k][l] * dl[3][l] + g[3 + k][l] * dl[4][l] + g[6 + k][l] * dl[5][l];
  }
  mul6s(b->h, tv, b->dy);
}

// ---------------------------------------------------------------------------------------------
// one Newton iteration

// a spare node hangs only from the joint that broke onto it (lane l of block b): solve it now,
// H = (m + ties) I + S^-1_A, dx = -H^-1 g; 0 when singular
static int solve_spare(const vd_sim_model* m, const vd_sim_data* d, const sim_work* w, const sim_step_ctx* ctx,
                       const sim_kid* b, int l, int t) {
  const sim_plan* p = &w->plan;
  int k = m->seg_spare[t] - m->nnode, n = m->nnode + k;
  double h = ctx->h, h2 = h * h;
  double mass = d->node_mass[n] + h * w->node_drag[n] + p->tie_h[p->nslot + k];
  double a[9] = {b->dh[S00][l] + mass, b->dh[S01][l],        b->dh[S02][l],
                 b->dh[S01][l],        b->dh[S11][l] + mass, b->dh[S12][l],
                 b->dh[S02][l],        b->dh[S12][l],        b->dh[S22][l] + mass};
  double ms = d->node_mass[n] + h * w->node_drag[n];
  vd_vec3 dx = vd_sub(vd_sub(d->node_pos[n], w->node_prev[n]), vd_scale(d->node_vel[n], h));
  vd_vec3 f = w->node_fext[n];
  const double* tg = p->tie_g + 3 * (p->nslot + k);
  vd_vec3 g = vd_v3(ms * dx.x - h2 * f.x + tg[0] + b->dg[0][l], ms * dx.y - h2 * f.y + tg[1] + b->dg[1][l],
                    ms * dx.z - h2 * f.z + tg[2] + b->dg[2][l]);
  vd_vec3 x;
  if (!m3_solve_spd(a, vd_scale(g, -1), &x)) return 0;
  double* o = p->spare_dy + 3 * k;
  o[0] = x.x, o[1] = x.y, o[2] = x.z;
  return 1;
}

// forward elimination of blocks [b0, b1); 0 when a factorisation failed
SIM_CLONES static int forward_range(const vd_sim_model* m, vd_sim_data* d, sim_work* w, const sim_step_ctx* ctx, int b0, int b1) {
  sim_plan* p = &w->plan;
  for (int bi = b0; bi < b1; bi++) {
    sim_blk* b = &p->blk[bi];
    sim_kid* kc = &p->kid[bi];
    sim_in in;
    sim_fw fw;
    in.st = &p->stat[bi];
    gather_in(m, d, w, ctx, &in, bi);
    eval_block(b, &fw, &in, ctx->h, ctx->gamma, m->bend_measure);
    for (int l = 0; l < SIM_W; l++) {
      int s = bi * SIM_W + l;
      if (p->slot_seg[s] >= 0 && p->held_start[s + 1] > p->held_start[s]) held_terms(m, d, w, ctx, b, l, s);
    }
    gather_kids(d, p, b, bi);
    if (p->tip_block[bi])
      forward_kernel(b, &fw, kc, 1);
    else
      forward_kernel(b, &fw, kc, 0);
    for (int l = 0; l < SIM_W; l++) {
      int t = p->slot_seg[bi * SIM_W + l];
      if (t < 0) continue;
      if (!(fw.ok[l] > 0)) return 0;
      if (d->seg_broken[t] && !solve_spare(m, d, w, ctx, kc, l, t)) return 0;
    }
  }
  return 1;
}

// back substitution of blocks [b0, b1) in reverse
SIM_CLONES static void back_range(const vd_sim_model* m, const vd_sim_data* d, sim_work* w, int b0, int b1) {
  sim_plan* p = &w->plan;
  lane dyp[6];
  const double* restrict base = (const double*)p->blk;
  for (int bi = b1 - 1; bi >= b0; bi--) {
    sim_blk* b = &p->blk[bi];
    // the parents' updates, lane-parallel from the plan's offsets (as gather_kids), unless a
    // joint of the block broke: its lane takes its spare node's update
    int broken = 0;
    for (int l = 0; l < SIM_W; l++) {
      int t = p->slot_seg[bi * SIM_W + l];
      broken |= t >= 0 && d->seg_broken[t];
    }
    if (!broken) {
      const ptrdiff_t* restrict off = p->poff + bi * SIM_W;
      const double* restrict use = p->puse + bi * SIM_W;
      for (int k = 0; k < 6; k++)
        L {
          double v = base[off[l] + SIM_W * k];
          dyp[k][l] = use[l] > 0 ? v : 0.0;
        }
      back_kernel(b, dyp);
      continue;
    }
    for (int l = 0; l < SIM_W; l++) {
      int s = bi * SIM_W + l, t = p->slot_seg[s], ps = p->par_slot[s];
      for (int k = 0; k < 6; k++) dyp[k][l] = 0;
      if (t < 0) continue;
      if (d->seg_broken[t]) {
        const double* o = p->spare_dy + 3 * (m->seg_spare[t] - m->nnode);
        dyp[0][l] = o[0], dyp[1][l] = o[1], dyp[2][l] = o[2];
      } else if (ps >= 0) {
        const sim_blk* pb = &p->blk[ps / SIM_W];
        for (int k = 0; k < 6; k++) dyp[k][l] = pb->dy[k][ps % SIM_W];
      }
    }
    back_kernel(b, dyp);
  }
}

// trust region: a Newton update that turns a frame by more than SIM_MAX_TURN or moves a
// node by more than SIM_MAX_MOVE rest lengths of its segment is scaled down as a whole (the
// linearisation means nothing that far out; from there a full update diverges). Corrections
// of a light node's prediction reach a few rest lengths in normal runs; these do not.
SIM_CLONES static double trust_scale(const sim_plan* p) {
  double turn2 = 0, move2 = 0;  // largest squared turn and squared move in rest lengths
  for (int bi = 0; bi < p->nblock; bi++) {
    const sim_blk* b = &p->blk[bi];
    lane tu, mo;
    L tu[l] = b->dy[3][l] * b->dy[3][l] + b->dy[4][l] * b->dy[4][l] + b->dy[5][l] * b->dy[5][l];
    L mo[l] = (b->dy[0][l] * b->dy[0][l] + b->dy[1][l] * b->dy[1][l] + b->dy[2][l] * b->dy[2][l]) / (b->l0[l] * b->l0[l]);
    for (int l = 0; l < SIM_W; l++) {
      if (p->slot_seg[bi * SIM_W + l] < 0) continue;
      if (tu[l] > turn2) turn2 = tu[l];
      if (mo[l] > move2) move2 = mo[l];
    }
  }
  double scale = 1, turn = sqrt(turn2), move = sqrt(move2);
  if (turn > SIM_MAX_TURN) scale = SIM_MAX_TURN / turn;
  if (move * scale > SIM_MAX_MOVE) scale = SIM_MAX_MOVE / move;
  return scale;
}

// apply the update scaled by scale: positions, frames, multipliers (stretch rows back to the
// material frame: dlambda_s = l0 R^T dl^)
SIM_CLONES static void apply_blocks(const vd_sim_model* m, vd_sim_data* d, sim_plan* p, double scale, int b0, int b1) {
  for (int bi = b0; bi < b1; bi++) {
    sim_blk* b = &p->blk[bi];
    lane v[3], need, ls[3], rt[9];
    rot_lanes(b->qt, rt);  // the frame's rotation at the linearisation, as eval_block had it
    for (int k = 0; k < 3; k++) L v[k][l] = scale * b->dy[3 + k][l];
    qrot_lanes(b->qt, v, need);
    for (int k = 0; k < 3; k++)
      L ls[k][l] = scale * (b->l0[l] * (rt[k][l] * b->dl[0][l] + rt[3 + k][l] * b->dl[1][l] + rt[6 + k][l] * b->dl[2][l]));
    for (int l = 0; l < SIM_W; l++) {
      int t = p->slot_seg[bi * SIM_W + l];
      if (t < 0) continue;
      int n = m->seg_node[2 * t + 1];
      vd_vec3* x = &d->node_pos[n];
      x->x += scale * b->dy[0][l], x->y += scale * b->dy[1][l], x->z += scale * b->dy[2][l];
      d->seg_quat[t] = need[l] > 0 ? quat_rotate_by(d->seg_quat[t], vd_v3(v[0][l], v[1][l], v[2][l]))
                                   : (vd_quat){b->qt[0][l], b->qt[1][l], b->qt[2][l], b->qt[3][l]};
      double* lam = d->seg_lambda + 6 * t;
      for (int k = 0; k < 3; k++) lam[k] += ls[k][l];
      if (!d->seg_broken[t] && m->seg_parent[t] >= 0)
        for (int k = 0; k < 3; k++) lam[3 + k] += scale * b->dl[3 + k][l];
      else
        lam[3] = lam[4] = lam[5] = 0;
    }
  }
}

// one Newton iteration; returns 0 when a factorisation failed (state left unchanged)
static int iterate(const vd_sim_model* m, vd_sim_data* d, sim_work* w, const sim_step_ctx* ctx) {
  sim_plan* p = &w->plan;
  double h2 = ctx->h * ctx->h;
  int nseg = m->nseg;
  // ties are leaf joints of the body that owns their node: H += I / alpha~, g += c / alpha~
  int nts = p->nslot + m->nspare;
  memset(p->tie_h, 0, (size_t)nts * sizeof(double));
  memset(p->tie_g, 0, (size_t)nts * 3 * sizeof(double));
  int ntie = sim_tie_count(m, d);
  for (int k = 0; k < ntie; k++) {
    int n;
    vd_vec3 target;
    double comp;
    sim_tie_limit(m, d, k);
    sim_tie_get(m, d, k, &n, &target, &comp);
    int s = tie_slot(m, d, p, n);
    if (s < 0) continue;
    double at = comp / h2;
    vd_vec3 cc = vd_sub(d->node_pos[n], target);
    p->tie_h[s] += 1 / at;
    p->tie_g[3 * s] += cc.x / at, p->tie_g[3 * s + 1] += cc.y / at, p->tie_g[3 * s + 2] += cc.z / at;
  }
  sim_stage(d, VD_SIM_STAGE_EVAL, ctx->tstage);
  // forward elimination (with each block's linearisation), then back substitution
  double scale = 1;
  if (p->nthread <= 1) {
    if (!forward_range(m, d, w, ctx, 0, p->nblock)) return 0;
    sim_stage(d, VD_SIM_STAGE_FACTOR, ctx->tstage);
    back_range(m, d, w, 0, p->nblock);
    scale = trust_scale(p);
    apply_blocks(m, d, p, scale, 0, p->nblock);
  } else {
    // each thread its subtrees, then one thread the top part; back substitution the other way
    // round; the update by blocks
    int nt = p->nthread, ok = 1;
#pragma omp parallel num_threads(nt)
    {
#ifdef _OPENMP
      int team = omp_get_num_threads(), me = omp_get_thread_num(), mine = 1;
#else
      int team = 1, me = 0, mine = 1;
#endif
      for (int k = me; k < nt; k += team) mine &= forward_range(m, d, w, ctx, p->part[k], p->part[k + 1]);
      if (!mine) {
#pragma omp atomic write
        ok = 0;
      }
#pragma omp barrier
#pragma omp single
      {
        if (ok && !forward_range(m, d, w, ctx, p->part[nt], p->nblock)) ok = 0;
        if (ok) back_range(m, d, w, p->part[nt], p->nblock);
      }
      if (ok) {
        for (int k = me; k < nt; k += team) back_range(m, d, w, p->part[k], p->part[k + 1]);
#pragma omp barrier
#pragma omp single
        scale = trust_scale(p);
        int per = (p->nblock + team - 1) / team, b0 = me * per, b1 = b0 + per < p->nblock ? b0 + per : p->nblock;
        if (b0 < b1) apply_blocks(m, d, p, scale, b0, b1);
      }
    }
    if (!ok) return 0;
    sim_stage(d, VD_SIM_STAGE_FACTOR, ctx->tstage);
  }
  // held children's multipliers: dl = -(c' + J_p dy_p) / alpha~', J_p dy_p = -[a dx_p; G dth_p]
  for (int s = 0; s < p->nslot && p->held_start[p->nslot] > 0; s++)
    for (int k = p->held_start[s]; k < p->held_start[s + 1]; k++) {
      const sim_blk* b = &p->blk[s / SIM_W];
      const double* lin = p->held_lin + 30 * k;
      double* lam = d->seg_lambda + 6 * p->held_seg[k];
      int l = s % SIM_W;
      for (int i = 0; i < 3; i++) {
        double ax = 0, gt = 0;
        for (int r = 0; r < 3; r++) ax += lin[3 * i + r] * b->dy[r][l], gt += lin[9 + 3 * i + r] * b->dy[3 + r][l];
        lam[i] -= scale * (lin[18 + i] - ax) / lin[24 + i];
        lam[3 + i] -= scale * (lin[21 + i] - gt) / lin[27 + i];
      }
    }
  for (int t = 0; t < nseg; t++) {
    if (!d->seg_broken[t] || (m->seg_flags[t] & VD_SIM_FIXED)) continue;
    int k = m->seg_spare[t] - m->nnode, n = m->nnode + k;
    const double* o = p->spare_dy + 3 * k;
    d->node_pos[n] = vd_add(d->node_pos[n], vd_v3(scale * o[0], scale * o[1], scale * o[2]));
  }
  // tie multipliers: the node has moved already, the new constraint value is c + dx (a
  // friction-limited tie slides first: its multiplier stays inside its limit)
  for (int k = 0; k < ntie; k++) {
    int n;
    vd_vec3 target;
    double comp;
    sim_tie_limit(m, d, k);
    sim_tie_get(m, d, k, &n, &target, &comp);
    if (tie_slot(m, d, p, n) < 0) continue;
    vd_vec3 cc = vd_sub(d->node_pos[n], target);
    double at = comp / h2;
    double* lam = w->tie_lambda + 3 * k;
    lam[0] = -cc.x / at, lam[1] = -cc.y / at, lam[2] = -cc.z / at;
  }
  sim_stage(d, VD_SIM_STAGE_SOLVE, ctx->tstage);
  return 1;
}

int sim_solve_direct(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* c) {
  sim_work* w = (sim_work*)d->work;
  // the schedule is cut for opt.threads (rebuilt when that changes)
  int nt = m->opt.threads < 1 ? 1 : m->opt.threads > SIM_MAX_THREADS ? SIM_MAX_THREADS : m->opt.threads;
  if (w->plan.nthread != nt && sim_plan_build(m, nt, &w->plan)) {
    sim_warn(d, VD_SIM_WARN_ARENA);
    sim_plan_build(m, 1, &w->plan);  // fall back to one thread
    if (!w->plan.mem) return 0;
  }
  int iters = c->statics && m->opt.iterations < 4 ? 4 : m->opt.iterations;
  for (int it = 0; it < iters; it++) {
    if (!iterate(m, d, w, c)) return 0;
    if (c->contacts && c->ncontact) sim_contacts_project(m, d, c->contacts, c->ncontact, c->h);
    sim_stage(d, VD_SIM_STAGE_PROJECT, c->tstage);
  }
  return 1;
}
