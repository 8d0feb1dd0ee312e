// SPDX-License-Identifier: MIT
// XPBD Gauss-Seidel solver (Macklin, Muller, Chentanez 2016): each sweep projects every
// segment's stretch-shear constraint and its bend-twist constraint with the parent, from the
// root to the tips, with compliance alpha / h^2 and multipliers accumulated over the sweeps
// of one step (without accumulation the result ignores the material, newton issue #2933).
// Each constraint is a 3x3 solve: the generalised inverse mass of its nodes and frames plus
// alpha~. Unlike the direct solver this drops the primal residual (the usual XPBD choice),
// so it converges to the implicit step only approximately and slowly for stiff rods.
#include "sim_internal.h"

// world inverse inertia of segment t (zero when fixed)
static void inv_inertia(const vd_sim_model* m, const vd_sim_data* d, int t, double* out) {
  if (t < 0 || (m->seg_flags[t] & VD_SIM_FIXED)) {
    m3_zero(out);
    return;
  }
  // Gauss-Seidel needs the frames to be not much lighter than the nodes they are tied to:
  // the inertia is floored at that of the segment as a rigid bar, m l^2 / 12 (a small change
  // of the rotary inertia; the direct solver uses the exact one)
  double r[9], l = m->seg_len0[t], bar = m->seg_mass[t] * l * l / 12;
  double ib = m->seg_inertia[2 * t], it = m->seg_inertia[2 * t + 1];
  m3_from_quat(r, d->seg_quat[t]);
  m3_inv_inertia(out, r, ib > bar ? ib : bar, it > bar ? it : bar);
}

// A = B W B^T for 3x3 matrices (W symmetric)
static void bwbt(const double* b, const double* wm, double* a) {
  double t1[9], bt[9];
  m3_mul(t1, b, wm);
  m3_transpose(bt, b);
  m3_mul(a, t1, bt);
}

static void project_stretch(const vd_sim_model* m, vd_sim_data* d, int t, const sim_step_ctx* c,
                            const double* cp) {
  sim_joint j;
  sim_joint_eval(m, d, t, &j);
  int na = d->seg_start[t], nb = m->seg_node[2 * t + 1];
  double wa = sim_node_w(m, d, na), wb = sim_node_w(m, d, nb);
  double iinv[9], a[9];
  inv_inertia(m, d, t, iinv);
  bwbt(j.b, iinv, a);
  double l0 = m->seg_len0[t], wsum = (wa + wb) / (l0 * l0);
  a[0] += wsum, a[4] += wsum, a[8] += wsum;
  double h2 = c->h * c->h, gam = c->gamma;
  double* lam = d->seg_lambda + 6 * t;
  double rhs[3];
  for (int i = 0; i < 3; i++) {
    double at = j.alpha[i] / h2;
    a[4 * i] += at / (1 + gam);
    rhs[i] = -(j.c[i] + at * lam[i] + gam * (j.c[i] - cp[i])) / (1 + gam);
  }
  vd_vec3 dl;
  if (!m3_solve_spd(a, vd_v3(rhs[0], rhs[1], rhs[2]), &dl)) return;
  lam[0] += dl.x, lam[1] += dl.y, lam[2] += dl.z;
  // dx_end = w_b a^T dl, dx_start = -w_a a^T dl, dtheta = I^-1 b^T dl
  vd_vec3 f = m3_tmul_v(j.a, dl);
  d->node_pos[nb] = vd_madd(d->node_pos[nb], f, wb);
  d->node_pos[na] = vd_madd(d->node_pos[na], f, -wa);
  if (!(m->seg_flags[t] & VD_SIM_FIXED))
    d->seg_quat[t] = quat_rotate_by(d->seg_quat[t], m3_mul_v(iinv, m3_tmul_v(j.b, dl)));
}

static void project_bend(const vd_sim_model* m, vd_sim_data* d, int t, const sim_step_ctx* c,
                         const double* cp) {
  sim_joint j;
  sim_joint_eval(m, d, t, &j);
  if (!j.bend) return;
  int p = m->seg_parent[t];
  double it[9], ip[9], isum[9], a[9];
  inv_inertia(m, d, t, it);
  inv_inertia(m, d, p, ip);
  for (int i = 0; i < 9; i++) isum[i] = it[i] + ip[i];
  bwbt(j.g, isum, a);
  double h2 = c->h * c->h, gam = c->gamma;
  double* lam = d->seg_lambda + 6 * t + 3;
  double rhs[3];
  for (int i = 0; i < 3; i++) {
    double at = j.alpha[3 + i] / h2;
    a[4 * i] += at / (1 + gam);
    rhs[i] = -(j.c[3 + i] + at * lam[i] + gam * (j.c[3 + i] - cp[3 + i])) / (1 + gam);
  }
  vd_vec3 dl;
  if (!m3_solve_spd(a, vd_v3(rhs[0], rhs[1], rhs[2]), &dl)) return;
  lam[0] += dl.x, lam[1] += dl.y, lam[2] += dl.z;
  vd_vec3 tq = m3_tmul_v(j.g, dl);
  d->seg_quat[t] = quat_rotate_by(d->seg_quat[t], m3_mul_v(it, tq));
  if (!(m->seg_flags[p] & VD_SIM_FIXED))
    d->seg_quat[p] = quat_rotate_by(d->seg_quat[p], vd_scale(m3_mul_v(ip, tq), -1.0));
}

// ties: a node pulled toward its target with compliance
static void project_ties(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* c) {
  sim_work* w = (sim_work*)d->work;
  int ntie = sim_tie_count(m, d);
  for (int k = 0; k < ntie; k++) {
    int n;
    vd_vec3 target;
    double comp;
    sim_tie_limit(m, d, k);
    sim_tie_get(m, d, k, &n, &target, &comp);
    double wn = sim_node_w(m, d, n);
    if (wn <= 0) continue;
    double at = comp / (c->h * c->h);
    double* lam = w->tie_lambda + 3 * k;
    vd_vec3 cc = vd_sub(d->node_pos[n], target);
    double den = wn + at;
    vd_vec3 dl = vd_v3(-(cc.x + at * lam[0]) / den, -(cc.y + at * lam[1]) / den, -(cc.z + at * lam[2]) / den);
    lam[0] += dl.x, lam[1] += dl.y, lam[2] += dl.z;
    d->node_pos[n] = vd_madd(d->node_pos[n], dl, wn);
  }
}

void sim_solve_gs(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* c) {
  sim_work* w = (sim_work*)d->work;
  for (int it = 0; it < m->opt.iterations; it++) {
    // root to tips: reverse of the children-first order
    for (int oi = m->nseg - 1; oi >= 0; oi--) {
      int t = m->seg_order[oi];
      if (m->seg_flags[t] & VD_SIM_FIXED) continue;
      const double* cp = w->c_prev + 6 * t;
      project_stretch(m, d, t, c, cp);
      project_bend(m, d, t, c, cp);
    }
    project_ties(m, d, c);
    if (c->contacts && c->ncontact) sim_contacts_project(m, d, c->contacts, c->ncontact, c->h);
  }
}
