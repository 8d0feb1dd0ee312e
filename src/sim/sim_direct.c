// SPDX-License-Identifier: MIT
// Direct solver: each Newton iteration solves the XPBD system of the whole plant exactly,
//   [ M   -J^T ] [dy]   = - [ g ]     g = M (y - y_n - h v_n) - h^2 f - J^T lambda
//   [ J  alpha~] [dl]       [ c ]     c = C + alpha~ lambda (+ damping, Macklin et al. 2016)
// in time linear in the number of segments. Plants are trees, and so is the graph whose
// vertices are bodies and joints (Baraff 1996; Deul et al. 2018): a body is one segment's end
// node with its frame (6 dofs), a joint is that segment's stretch-shear and bend-twist rows
// (6), which touch only the body and its parent. Eliminating bodies and joints from the tips
// to the root (children first) leaves no fill-in: per segment one 6x6 Cholesky of the body and
// one of the joint's Schur complement. Unlike plain XPBD we keep the primal residual g, so the
// iteration converges to the implicit Euler step itself and static equilibria are exact.
#include "sim_internal.h"

// ---------------------------------------------------------------------------------------------
// 6x6 helpers, kept here so the compiler can unroll them in the hot loops

// inverse of a symmetric 3x3 matrix by cofactors (out may not alias a); 0 if singular
static inline int inv3_sym(const double* a, double* o) {
  double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[2] * a[7] - a[1] * a[8], c02 = a[1] * a[5] - a[2] * a[4];
  double c11 = a[0] * a[8] - a[2] * a[6], c12 = a[2] * a[3] - a[0] * a[5], c22 = a[0] * a[4] - a[1] * a[3];
  double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  if (!(det > 0)) return 0;
  double id = 1.0 / det;
  o[0] = c00 * id, o[1] = o[3] = c01 * id, o[2] = o[6] = c02 * id;
  o[4] = c11 * id, o[5] = o[7] = c12 * id, o[8] = c22 * id;
  return 1;
}

// inverse of a symmetric positive definite 6x6 matrix [[A, B], [B^T, D]] by its 3x3 blocks:
// X = A^-1 B, T = D - B^T X (the Schur complement, positive definite), then
// inv = [[A^-1 + X T^-1 X^T, -X T^-1], [-T^-1 X^T, T^-1]]; 0 if not positive definite
static int inv_spd(const double* m, double* inv) {
  double a[9], b[9], dd[9], ai[9], x[9], t[9], ti[9], y[9];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      a[3 * i + k] = m[6 * i + k];
      b[3 * i + k] = m[6 * i + 3 + k];
      dd[3 * i + k] = m[6 * (3 + i) + 3 + k];
    }
  if (!(a[0] > 0) || !inv3_sym(a, ai)) return 0;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) x[3 * i + k] = ai[3 * i] * b[k] + ai[3 * i + 1] * b[3 + k] + ai[3 * i + 2] * b[6 + k];
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++) {
      double v = dd[3 * i + k] - (b[i] * x[k] + b[3 + i] * x[3 + k] + b[6 + i] * x[6 + k]);
      t[3 * i + k] = t[3 * k + i] = v;
    }
  if (!(t[0] > 0) || !inv3_sym(t, ti)) return 0;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) y[3 * i + k] = x[3 * i] * ti[k] + x[3 * i + 1] * ti[3 + k] + x[3 * i + 2] * ti[6 + k];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      inv[6 * (3 + i) + 3 + k] = ti[3 * i + k];
      inv[6 * i + 3 + k] = inv[6 * (3 + k) + i] = -y[3 * i + k];
    }
  for (int i = 0; i < 3; i++)
    for (int k = i; k < 3; k++) {
      double v = ai[3 * i + k] + y[3 * i] * x[3 * k] + y[3 * i + 1] * x[3 * k + 1] + y[3 * i + 2] * x[3 * k + 2];
      inv[6 * i + k] = inv[6 * k + i] = v;
    }
  return 1;
}




#define SIM_MAX_TURN 1.0   // largest frame rotation of one Newton update (rad)
#define SIM_MAX_MOVE 10.0  // largest node move of one Newton update (rest lengths of its segment)

// body numbering: segment t is body t; spare node k (k = node - nnode) is body nseg + k
static int node_body(const vd_sim_model* m, const vd_sim_data* d, int n) {
  if (n >= m->nnode) return d->node_mass[n] > 0 ? m->nseg + (n - m->nnode) : -1;
  if (m->node_fixed[n]) return -1;
  int o = m->node_owner[n];
  return o >= 0 && !(m->seg_flags[o] & VD_SIM_FIXED) ? o : -1;
}



// y = J x (6x6 times 6)
static void mv6(const double* jm, const double* x, double* y) {
  for (int i = 0; i < 6; i++) {
    double s = 0;
    for (int k = 0; k < 6; k++) s += jm[6 * i + k] * x[k];
    y[i] = s;
  }
}


// mass matrix and inertial residual of every body; returns 0 if a body has no mass
static void init_bodies(const vd_sim_model* m, vd_sim_data* d, sim_work* w, double h) {
  double h2 = h * h;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    double* hb = w->h + 36 * t;
    double* g = w->gb + 6 * t;
    memset(hb, 0, 36 * sizeof(double));
    int n = m->seg_node[2 * t + 1];
    // the node's mass plus h times its air drag damping (drag linearised at v_n, implicit)
    double mass = d->node_mass[n] + h * w->node_drag[n];
    hb[0] = hb[7] = hb[14] = mass;
    // rotational inertia in world axes
    double r[9], iw[9];
    m3_from_quat(r, d->seg_quat[t]);
    double ib = m->seg_inertia[2 * t], it = m->seg_inertia[2 * t + 1];
    double a = ib, c = it - ib, d3[3] = {r[2], r[5], r[8]};
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) iw[3 * i + k] = (i == k ? a : 0.0) + c * d3[i] * d3[k];
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) hb[6 * (3 + i) + 3 + k] = iw[3 * i + k];
    // g = M (y - y_n - h v_n) - h^2 f
    vd_vec3 dx = vd_sub(vd_sub(d->node_pos[n], w->node_prev[n]), vd_scale(d->node_vel[n], h));
    vd_vec3 f = w->node_fext[n];
    g[0] = mass * dx.x - h2 * f.x, g[1] = mass * dx.y - h2 * f.y, g[2] = mass * dx.z - h2 * f.z;
    vd_vec3 om = d->seg_omega[t];
    vd_vec3 dth = vd_sub(quat_log(q_mul(d->seg_quat[t], q_conj(w->seg_prev[t]))),
                         vd_scale(om, h));
    vd_vec3 io = m3_mul_v(iw, om);
    vd_vec3 tq = vd_sub(w->seg_text[t], vd_cross(om, io));
    vd_vec3 idth = m3_mul_v(iw, dth);
    g[3] = idth.x - h2 * tq.x, g[4] = idth.y - h2 * tq.y, g[5] = idth.z - h2 * tq.z;
  }
  for (int k = 0; k < m->nspare; k++) {
    int n = m->nnode + k, b = m->nseg + k;
    double* hb = w->h + 36 * b;
    double* g = w->gb + 6 * b;
    memset(hb, 0, 36 * sizeof(double));
    memset(g, 0, 6 * sizeof(double));
    if (d->node_mass[n] <= 0) continue;
    double mass = d->node_mass[n] + h * w->node_drag[n];
    hb[0] = hb[7] = hb[14] = mass;
    hb[21] = hb[28] = hb[35] = 1.0;  // the spare has no frame: a decoupled unit block
    vd_vec3 dx = vd_sub(vd_sub(d->node_pos[n], w->node_prev[n]), vd_scale(d->node_vel[n], h));
    vd_vec3 f = w->node_fext[n];
    g[0] = mass * dx.x - h2 * f.x, g[1] = mass * dx.y - h2 * f.y, g[2] = mass * dx.z - h2 * f.z;
  }
}

// one Newton iteration; returns 0 when a factorisation failed (state left unchanged)
static int iterate(const vd_sim_model* m, vd_sim_data* d, sim_work* w, const sim_step_ctx* ctx) {
  double h = ctx->h, h2 = h * h, gam = ctx->gamma;
  int nseg = m->nseg;
  // linearise every joint at the current state
  for (int t = 0; t < nseg; t++)
    if (!(m->seg_flags[t] & VD_SIM_FIXED)) sim_joint_eval(m, d, t, &w->joint[t]);
  init_bodies(m, d, w, h);
  // g -= J^T lambda for every joint, on its own body and its parent body
  for (int t = 0; t < nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    const sim_joint* j = &w->joint[t];
    const double* lam = d->seg_lambda + 6 * t;
    vd_vec3 ls = vd_v3(lam[0], lam[1], lam[2]), lb = vd_v3(lam[3], lam[4], lam[5]);
    vd_vec3 ta = m3_tmul_v(j->a, ls), tb = vd_add(m3_tmul_v(j->b, ls), m3_tmul_v(j->g, lb));
    double* g = w->gb + 6 * t;
    g[0] -= ta.x, g[1] -= ta.y, g[2] -= ta.z, g[3] -= tb.x, g[4] -= tb.y, g[5] -= tb.z;
    if (j->parent_body >= 0) {
      double* gp = w->gb + 6 * j->parent_body;
      vd_vec3 tg = m3_tmul_v(j->g, lb);
      gp[0] += ta.x, gp[1] += ta.y, gp[2] += ta.z;
      if (j->parent_body < nseg) gp[3] += tg.x, gp[4] += tg.y, gp[5] += tg.z;
    }
  }
  // ties are leaf joints of the body that owns their node: H += I / alpha~, g += (c + alpha~ l) / alpha~ - l
  int ntie = sim_tie_count(m, d);
  for (int k = 0; k < ntie; k++) {
    int n;
    vd_vec3 target;
    double comp;
    sim_tie_get(m, d, k, &n, &target, &comp);
    int b = node_body(m, d, n);
    if (b < 0) continue;
    double at = comp / h2;
    double* lam = w->tie_lambda + 3 * k;
    vd_vec3 cc = vd_sub(d->node_pos[n], target);
    double* hb = w->h + 36 * b;
    double* g = w->gb + 6 * b;
    hb[0] += 1 / at, hb[7] += 1 / at, hb[14] += 1 / at;
    // g_body -= lambda (J = I), then g' = g + (c + alpha~ lambda) / alpha~ = g + c / alpha~ + lambda
    g[0] += cc.x / at, g[1] += cc.y / at, g[2] += cc.z / at;
    (void)lam;
  }
  // forward elimination: children before parents; h and s end up holding inverses. The
  // Jacobians are used block by block: J_c = [[a, b], [0, g]], J_p = [[-a, 0], [0, -g]].
  for (int oi = 0; oi < nseg; oi++) {
    int t = m->seg_order[oi];
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    const sim_joint* j = &w->joint[t];
    const double *ja = j->a, *jb = j->b, *jg = j->g;
    double* hb = w->h + 36 * t;
    double* g = w->gb + 6 * t;
    double hi[36];
    if (!inv_spd(hb, hi)) return 0;
    memcpy(hb, hi, sizeof hi);
    // P = J_c H^-1, then S = P J_c^T
    double pm[36], sm[36];
    for (int i = 0; i < 3; i++)
      for (int c = 0; c < 6; c++) {
        double u0 = 0, u1 = 0;
        for (int k = 0; k < 3; k++) {
          u0 += ja[3 * i + k] * hi[6 * k + c] + jb[3 * i + k] * hi[6 * (3 + k) + c];
          u1 += jg[3 * i + k] * hi[6 * (3 + k) + c];
        }
        pm[6 * i + c] = u0;
        pm[6 * (3 + i) + c] = u1;
      }
    for (int i = 0; i < 6; i++) {
      const double* pr = pm + 6 * i;
      for (int c = 0; c < 3; c++) {
        sm[6 * i + c] = pr[0] * ja[3 * c] + pr[1] * ja[3 * c + 1] + pr[2] * ja[3 * c + 2] + pr[3] * jb[3 * c] +
                        pr[4] * jb[3 * c + 1] + pr[5] * jb[3 * c + 2];
        sm[6 * i + 3 + c] = pr[3] * jg[3 * c] + pr[4] * jg[3 * c + 1] + pr[5] * jg[3 * c + 2];
      }
    }
    // r = -c' + J_c H^-1 g = -c' + P g, with c' and alpha~' divided by 1 + gamma (damping)
    const double* lam = d->seg_lambda + 6 * t;
    const double* cp = w->c_prev + 6 * t;
    double* r = w->r + 6 * t;
    for (int i = 0; i < 6; i++) {
      double at = j->alpha[i] / h2;
      double cv = j->c[i] + at * lam[i] + gam * (j->c[i] - cp[i]);
      double pg = 0;
      for (int k = 0; k < 6; k++) pg += pm[6 * i + k] * g[k];
      sm[6 * i + i] += at / (1 + gam);
      r[i] = -cv / (1 + gam) + pg;
    }
    double* s = w->s + 36 * t;
    if (!inv_spd(sm, s)) return 0;
    // parent body: H_p += J_p^T S^-1 J_p, g_p -= J_p^T S^-1 r
    int pb = j->parent_body;
    if (pb < 0) continue;
    int spare = pb >= nseg;
    double* hp = w->h + 36 * pb;
    double* gp = w->gb + 6 * pb;
    double sa[9], blk[9];
    // block (0,0): a^T S00 a
    for (int i = 0; i < 3; i++)
      for (int c = 0; c < 3; c++)
        sa[3 * i + c] = s[6 * i] * ja[c] + s[6 * i + 1] * ja[3 + c] + s[6 * i + 2] * ja[6 + c];
    for (int i = 0; i < 3; i++)
      for (int c = 0; c < 3; c++) {
        blk[3 * i + c] = ja[i] * sa[c] + ja[3 + i] * sa[3 + c] + ja[6 + i] * sa[6 + c];
        hp[6 * i + c] += blk[3 * i + c];
      }
    double sr[6];
    for (int i = 0; i < 6; i++) {
      double v = 0;
      for (int k = 0; k < 6; k++) v += s[6 * i + k] * r[k];
      sr[i] = v;
    }
    for (int i = 0; i < 3; i++) gp[i] += ja[i] * sr[0] + ja[3 + i] * sr[1] + ja[6 + i] * sr[2];
    if (!spare) {
      // blocks (0,1) = a^T S01 g and (1,1) = g^T S11 g
      double sg[9];
      for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++)
          sg[3 * i + c] = s[6 * i + 3] * jg[c] + s[6 * i + 4] * jg[3 + c] + s[6 * i + 5] * jg[6 + c];
      for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) {
          double v = ja[i] * sg[c] + ja[3 + i] * sg[3 + c] + ja[6 + i] * sg[6 + c];
          hp[6 * i + 3 + c] += v;
          hp[6 * (3 + c) + i] += v;
        }
      for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++)
          sg[3 * i + c] = s[6 * (3 + i) + 3] * jg[c] + s[6 * (3 + i) + 4] * jg[3 + c] + s[6 * (3 + i) + 5] * jg[6 + c];
      for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++)
          hp[6 * (3 + i) + 3 + c] += jg[i] * sg[c] + jg[3 + i] * sg[3 + c] + jg[6 + i] * sg[6 + c];
      for (int i = 0; i < 3; i++) gp[3 + i] += jg[i] * sr[3] + jg[3 + i] * sr[4] + jg[6 + i] * sr[5];
    } else {
      // a spare body hangs only from this joint: solve it now as a root
      double hs[36];
      if (!inv_spd(hp, hs)) return 0;
      memcpy(hp, hs, sizeof hs);
      double ng[6];
      for (int i = 0; i < 6; i++) ng[i] = -gp[i];
      mv6(hs, ng, w->dy + 6 * pb);
    }
  }
  // back substitution: parents before children
  for (int oi = nseg - 1; oi >= 0; oi--) {
    int t = m->seg_order[oi];
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    const sim_joint* j = &w->joint[t];
    const double *ja = j->a, *jb = j->b, *jg = j->g;
    double* dl = w->dl + 6 * t;
    double* dy = w->dy + 6 * t;
    double rr[6];
    memcpy(rr, w->r + 6 * t, sizeof rr);
    int pb = j->parent_body;
    if (pb >= 0) {
      // rr = r - J_p dy_p = r + [a dy_p0; g dy_p1]
      const double* dp = w->dy + 6 * pb;
      for (int i = 0; i < 3; i++) {
        rr[i] += ja[3 * i] * dp[0] + ja[3 * i + 1] * dp[1] + ja[3 * i + 2] * dp[2];
        if (pb < nseg) rr[3 + i] += jg[3 * i] * dp[3] + jg[3 * i + 1] * dp[4] + jg[3 * i + 2] * dp[5];
      }
    }
    mv6(w->s + 36 * t, rr, dl);
    // dy = H^-1 (-g + J_c^T dl), J_c^T dl = [a^T dl0; b^T dl0 + g^T dl1]
    const double* g = w->gb + 6 * t;
    double v[6];
    for (int i = 0; i < 3; i++) {
      v[i] = -g[i] + ja[i] * dl[0] + ja[3 + i] * dl[1] + ja[6 + i] * dl[2];
      v[3 + i] = -g[3 + i] + jb[i] * dl[0] + jb[3 + i] * dl[1] + jb[6 + i] * dl[2] + jg[i] * dl[3] +
                 jg[3 + i] * dl[4] + jg[6 + i] * dl[5];
    }
    mv6(w->h + 36 * t, v, dy);
  }
  // trust region: a Newton update that turns a frame by more than SIM_MAX_TURN or moves a
  // node by more than SIM_MAX_MOVE rest lengths of its segment is scaled down as a whole (the
  // linearisation means nothing that far out; from there a full update diverges). Corrections
  // of a light node's prediction reach a few rest lengths in normal runs; these do not.
  double scale = 1;
  for (int t = 0; t < nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    const double* dy = w->dy + 6 * t;
    double turn = sqrt(dy[3] * dy[3] + dy[4] * dy[4] + dy[5] * dy[5]);
    double move = sqrt(dy[0] * dy[0] + dy[1] * dy[1] + dy[2] * dy[2]) / m->seg_len0[t];
    if (turn * scale > SIM_MAX_TURN) scale = SIM_MAX_TURN / turn;
    if (move * scale > SIM_MAX_MOVE) scale = SIM_MAX_MOVE / move;
  }
  if (scale < 1) {
    for (int k = 0; k < 6 * (nseg + m->nspare); k++) w->dy[k] *= scale;
    for (int k = 0; k < 6 * nseg; k++) w->dl[k] *= scale;
  }
  // apply: positions, frames, multipliers
  for (int t = 0; t < nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    const double* dy = w->dy + 6 * t;
    int n = m->seg_node[2 * t + 1];
    d->node_pos[n] = vd_add(d->node_pos[n], vd_v3(dy[0], dy[1], dy[2]));
    d->seg_quat[t] = quat_rotate_by(d->seg_quat[t], vd_v3(dy[3], dy[4], dy[5]));
    double* lam = d->seg_lambda + 6 * t;
    const double* dl = w->dl + 6 * t;
    for (int i = 0; i < 6; i++) lam[i] += dl[i];
    if (!w->joint[t].bend) lam[3] = lam[4] = lam[5] = 0;
  }
  for (int k = 0; k < m->nspare; k++) {
    int n = m->nnode + k;
    if (d->node_mass[n] <= 0) continue;
    const double* dy = w->dy + 6 * (m->nseg + k);
    d->node_pos[n] = vd_add(d->node_pos[n], vd_v3(dy[0], dy[1], dy[2]));
  }
  // tie multipliers: dl = -(c + alpha~ l + dx) / alpha~
  for (int k = 0; k < ntie; k++) {
    int n;
    vd_vec3 target;
    double comp;
    sim_tie_get(m, d, k, &n, &target, &comp);
    int b = node_body(m, d, n);
    if (b < 0) continue;
    // the node has moved already: the new constraint value is c + dx
    vd_vec3 cc = vd_sub(d->node_pos[n], target);
    double at = comp / h2;
    double* lam = w->tie_lambda + 3 * k;
    lam[0] = -cc.x / at, lam[1] = -cc.y / at, lam[2] = -cc.z / at;
  }
  return 1;
}

int sim_solve_direct(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* c) {
  sim_work* w = (sim_work*)d->work;
  int iters = c->statics && m->opt.iterations < 4 ? 4 : m->opt.iterations;
  for (int it = 0; it < iters; it++) {
    if (!iterate(m, d, w, c)) return 0;
    if (c->contacts && c->ncontact) sim_contacts_project(m, d, c->contacts, c->ncontact, c->h);
  }
  return 1;
}
