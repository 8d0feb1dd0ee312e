// SPDX-License-Identifier: MIT
// Inverse kinematics: damped least squares (Levenberg-Marquardt form, Wampler 1986; Buss 2004
// "Introduction to inverse kinematics with Jacobian transpose, pseudoinverse and damped least
// squares methods", eq. 11) on MuJoCo's site Jacobian: dq = J^T (J J^T + lambda^2 I)^-1 e with
// e the position error and, for arms that can turn the end-effector, the orientation error as
// a rotation vector weighted by rot_weight (m/rad). Each step is limited to 0.2 rad (or m) per
// joint and the joints are clamped to their ranges.
#include <string.h>

#include "robot_internal.h"

vd_ik_def vd_ik_def_default(void) {
  vd_ik_def d;
  d.max_iter = 200;
  d.damping = 0.01;
  d.tol_pos = 1e-4;
  d.tol_rot = 1e-3;
  d.rot_weight = 0.1;
  return d;
}

// solve the symmetric positive definite n x n system a y = e in place (Cholesky); 0 if singular
static int spd_solve(double* a, double* e, int n) {
  for (int j = 0; j < n; j++) {
    double s = a[j * n + j];
    for (int k = 0; k < j; k++) s -= a[j * n + k] * a[j * n + k];
    if (!(s > 0)) return 0;
    a[j * n + j] = sqrt(s);
    for (int i = j + 1; i < n; i++) {
      double t = a[i * n + j];
      for (int k = 0; k < j; k++) t -= a[i * n + k] * a[j * n + k];
      a[i * n + j] = t / a[j * n + j];
    }
  }
  for (int i = 0; i < n; i++) {
    for (int k = 0; k < i; k++) e[i] -= a[i * n + k] * e[k];
    e[i] /= a[i * n + i];
  }
  for (int i = n - 1; i >= 0; i--) {
    for (int k = i + 1; k < n; k++) e[i] -= a[k * n + i] * e[k];
    e[i] /= a[i * n + i];
  }
  return 1;
}

// site pose at arm joints q in the scratch data (kinematics and com positions for the Jacobian)
static void pose_at(vd_harvest* h, const double* q, vd_vec3* p, vd_quat* r) {
  for (int k = 0; k < h->rb->narm; k++) h->dk->qpos[h->rb->arm_qpos[k]] = q[k];
  mj_kinematics(h->m, h->dk);
  mj_comPos(h->m, h->dk);
  robot_site_pose(h, h->dk, p, r);
}

int robot_ik(vd_harvest* h, const vd_ik_def* def, vd_vec3 pos, const vd_quat* rot, double* q,
             double* pos_err, double* rot_err) {
  const mjModel* m = h->m;
  int n = h->rb->narm, use_rot = rot && h->orient, rows = use_rot ? 6 : 3, nv = m->nv;
  double w = def->rot_weight, lam2 = def->damping * def->damping;
  int mark = h->dk->pstack;
  mjtNum* jp = mj_stackAlloc(h->dk, 3 * nv);
  mjtNum* jr = mj_stackAlloc(h->dk, 3 * nv);
  double perr = INFINITY, rerr = use_rot ? INFINITY : 0;
  int ok = 0;
  for (int it = 0; it <= def->max_iter; it++) {
    vd_vec3 p;
    vd_quat r;
    pose_at(h, q, &p, &r);
    vd_vec3 ep = vd_sub(pos, p);
    vd_vec3 er = use_rot ? quat_log_v(vd_quat_mul(*rot, vd_quat_conj(r))) : vd_v3(0, 0, 0);
    perr = vd_norm(ep), rerr = use_rot ? vd_norm(er) : 0;
    if (perr <= def->tol_pos && rerr <= def->tol_rot) {
      ok = 1;
      break;
    }
    if (it == def->max_iter) break;
    mj_jacSite(m, h->dk, jp, jr, h->rb->ee_site);
    // J (rows x n) over the arm's dofs, e (rows)
    double J[6 * VD_ROBOT_MAX_JOINTS], e[6] = {ep.x, ep.y, ep.z, w * er.x, w * er.y, w * er.z};
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < n; k++) {
        J[i * n + k] = jp[i * nv + h->rb->arm_dof[k]];
        if (use_rot) J[(3 + i) * n + k] = w * jr[i * nv + h->rb->arm_dof[k]];
      }
    double a[36];
    for (int i = 0; i < rows; i++)
      for (int j = 0; j < rows; j++) {
        double s = i == j ? lam2 : 0;
        for (int k = 0; k < n; k++) s += J[i * n + k] * J[j * n + k];
        a[i * rows + j] = s;
      }
    if (!spd_solve(a, e, rows)) break;
    double big = 0, dq[VD_ROBOT_MAX_JOINTS];
    for (int k = 0; k < n; k++) {
      double s = 0;
      for (int i = 0; i < rows; i++) s += J[i * n + k] * e[i];
      dq[k] = s;
      if (fabs(s) > big) big = fabs(s);
    }
    double sc = big > 0.2 ? 0.2 / big : 1.0;
    for (int k = 0; k < n; k++) {
      double v = q[k] + sc * dq[k];
      q[k] = v < h->rb->arm_lo[k] ? h->rb->arm_lo[k] : v > h->rb->arm_hi[k] ? h->rb->arm_hi[k] : v;
    }
  }
  h->dk->pstack = mark;
  if (pos_err) *pos_err = perr;
  if (rot_err) *rot_err = rerr;
  return ok;
}

int vd_harvest_ik(vd_harvest* h, const vd_ik_def* def, vd_vec3 pos, const vd_quat* rot, double* q,
                  double* pos_err, double* rot_err) {
  vd_ik_def d = def ? *def : vd_ik_def_default();
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap)) {
    if (pos_err) *pos_err = INFINITY;
    if (rot_err) *rot_err = INFINITY;
    return 0;
  }
  int ok = robot_ik(h, &d, pos, rot, q, pos_err, rot_err);
  vd_mj_trap_end(&trap);
  return ok;
}

void vd_harvest_fk(vd_harvest* h, const double* q, vd_vec3* pos, vd_quat* rot) {
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap)) {
    *pos = vd_v3(NAN, NAN, NAN);
    if (rot) *rot = vd_quat_identity();
    return;
  }
  vd_quat r;
  pose_at(h, q, pos, &r);
  if (rot) *rot = r;
  vd_mj_trap_end(&trap);
}
