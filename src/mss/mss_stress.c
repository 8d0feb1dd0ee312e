// SPDX-License-Identifier: MIT
// Stress, branch breaking and the AC model of gravitropism on mass-spring trees.
//
// Stress by sections. Cut an internode b -> c just above b: the section carries the force N and
// moment M that the rest of the tree exerts on the subtree beyond the cut (c and everything that
// grows from it). Where the springs model the wood, these are the elastic forces that cross the
// cut (the sum of the springs' and hinges' forces on the subtree: forces inside it cancel), which
// keeps the stress elastic: the artificial damping of stiff modes by the implicit step would show
// as inertia. Inside the rigid part of an MRL-Tree there are no elastic forces, so the subtree's
// loads give them instead (dynamic equilibrium: N = sum (f_ext,k + f_branches,k - m_k a_k), the
// rigid body's accelerations being smooth): the rigid nodes, which the paper could not stress
// individually (its sec. 4.4), have stress too. The section of radius r then carries
// sigma = |N . e| / (pi r^2) + 4 |M_perp| / (pi r^3): axial plus the largest bending stress
// (M r / I, I = pi r^4 / 4). The same cut just below c gives the stress at node c.
//
// Bastien et al. 2013 (PNAS 110(2):755-760), the AC model: in the growth zone the curvature C of
// an axis changes by dC/dt = -beta sin A - gamma C, A the local angle to the vertical. On a hinge
// between two internodes of one axis, C = theta / l-bar with theta the rest bend, so the rest bend
// vector omega (from the straight continuation of the lower internode to the upper one) changes by
// d omega / dt = beta l-bar (q x up) - gamma omega, |q x up| = sin A. Its steady shape has
// dA/ds = -sin A / L_c with L_c = gamma / beta: A(s) = 2 atan(tan(A0 / 2) exp(-s / L_c)), and the
// bending number B = beta L / gamma fixes the tip angle (facts-robot-trees.md section 7).
// Roots are left as they grew: held by the soil, a root cannot turn up its rest shape without
// loading itself against its hold (their gravitropism, downward, is the turtle's as they grow).
#include "mss_internal.h"

void mss_subtrees(const vd_mss_model* m, const vd_mss_data* d, mss_work* w) {
  int nn = m->nnode;
  // per node: the elastic forces on it (fsub, msub) and, on rigid members, their loads with the
  // forces of the springs that hold the mass-spring branches (ftot, dvs as the moment)
  for (int i = 0; i < nn; i++) {
    int live = !d->removed[i];
    w->fsub[i] = live ? w->fint[i] : vd_v3(0, 0, 0);
    w->msub[i] = vd_v3(0, 0, 0);
    w->ftot[i] = live && d->rigid[i] ? vd_add(vd_madd(d->fext[i], d->acc[i], -d->mass[i]), w->fint[i]) : vd_v3(0, 0, 0);
    w->dvs[i] = vd_v3(0, 0, 0);
  }
  // children after their parents in pre-order: a reverse pass sums every subtree
  for (int k = nn - 1; k >= 0; k--) {
    int n = m->node_order[k], par = m->node_parent[n];
    if (par < 0 || d->removed[n]) continue;
    vd_vec3 arm = vd_sub(d->pos[n], d->pos[par]);
    w->fsub[par] = vd_add(w->fsub[par], w->fsub[n]);
    w->msub[par] = vd_add(w->msub[par], vd_add(w->msub[n], vd_cross(arm, w->fsub[n])));
    w->ftot[par] = vd_add(w->ftot[par], w->ftot[n]);
    w->dvs[par] = vd_add(w->dvs[par], vd_add(w->dvs[n], vd_cross(arm, w->ftot[n])));
  }
}

// stress of a section of radius r along e under force f and moment mo
static double section_stress(vd_vec3 f, vd_vec3 mo, vd_vec3 e, double r) {
  r = fmax(r, 1e-6);
  double n = fabs(vd_dot(f, e));
  vd_vec3 mp = vd_madd(mo, e, -vd_dot(mo, e));
  return n / (VD_PI * r * r) + 4 * v_norm(mp) / (VD_PI * r * r * r);
}

void vd_mss_stress(const vd_mss_model* m, vd_mss_data* d) {
  mss_work* w = d->work;
  mss_internal(m, d, w);
  mss_subtrees(m, d, w);
  for (int i = 0; i < m->nnode; i++) d->node_stress[i] = 0;
  for (int s = 0; s < m->nspring; s++) d->spring_stress[s] = 0;
  for (int s = 0; s < m->ninter; s++) {
    int b = m->spring_node[2 * s], c = m->spring_node[2 * s + 1];
    if (d->spring_broken[s] || d->removed[c] || m->node_owner[c] != s) continue;
    vd_vec3 ev = vd_sub(d->pos[c], d->pos[b]);
    double l = v_norm(ev);
    vd_vec3 e = l > 0 ? vd_scale(ev, 1.0 / l) : vd_v3(0, 0, 1);
    // a cut through the rigid part: the loads beyond it; elsewhere the elastic forces across it
    int rigid = d->rigid[b] && d->rigid[c];
    vd_vec3 f = rigid ? w->ftot[c] : vd_scale(w->fsub[c], -1);
    vd_vec3 mc = rigid ? w->dvs[c] : vd_scale(w->msub[c], -1);
    vd_vec3 mb = vd_add(mc, vd_cross(ev, f));
    double top = section_stress(f, mc, e, m->spring_radius[2 * s + 1]);
    double base = section_stress(f, mb, e, m->spring_radius[2 * s]);
    d->node_stress[c] = top;
    d->spring_stress[s] = fmax(top, base);
    // a base node shows the largest stress of the internodes that start at it
    if (m->node_owner[b] < 0) d->node_stress[b] = fmax(d->node_stress[b], base);
  }
}

int mss_remove_subtree(const vd_mss_model* m, vd_mss_data* d, int s) {
  int c = m->spring_node[2 * s + 1];
  d->spring_broken[s] = 1;
  if (m->node_owner[c] != s) return 0;
  int n = 0;
  for (int k = m->node_pre[c]; k <= m->node_last[c]; k++) {
    int i = m->node_order[k];
    if (d->removed[i]) continue;
    d->removed[i] = 1;
    n++;
  }
  for (int t = 0; t < m->nspring; t++)
    if (d->removed[m->spring_node[2 * t]] || d->removed[m->spring_node[2 * t + 1]]) d->spring_broken[t] = 1;
  return n;
}

void vd_mss_bastien(const vd_mss_model* m, const vd_mss_data* d, double t, int nsub, vd_vec3* rest) {
  int nn = m->nnode;
  for (int i = 0; i < nn; i++) rest[i] = m->node_rest[i];
  if (nsub < 1 || !(t > 0)) return;
  double g = v_norm(m->opt.gravity), beta = m->opt.bastien_beta, gamma = m->opt.bastien_gamma;
  vd_vec3 up = g > 0 ? vd_scale(m->opt.gravity, -1.0 / g) : vd_v3(0, 0, 1);
  double dt = t / nsub;
  for (int step = 0; step < nsub; step++) {
    // deepest hinges first: a turn about b carries the already turned subtrees beyond it
    for (int k = nn - 1; k >= 0; k--) {
      int c = m->node_order[k], b = m->node_parent[c];
      // roots: the soil holds them where they grew (their own gravitropism is the turtle's
      // tropism as they grow), so their rest shape does not bend (issue 26 defect 3)
      if (b < 0 || (d && d->removed[c]) || (m->node_flags[c] & VD_MSS_ROOT)) continue;
      int a = m->node_parent[b];
      if (a < 0 || m->node_axis[c] != m->node_axis[b] || m->node_age[c] >= m->opt.growth_zone_age) continue;
      vd_vec3 qv = vd_sub(rest[c], rest[b]), pv = vd_sub(rest[a], rest[b]);
      double lq = v_norm(qv), lp = v_norm(pv);
      if (!(lq > 0) || !(lp > 0)) continue;
      vd_vec3 q = vd_scale(qv, 1.0 / lq), cont = vd_scale(pv, -1.0 / lp);
      // the rest bend: rotation from the continuation of the lower internode to the upper one
      vd_vec3 ax = vd_cross(cont, q);
      double sn = v_norm(ax), th = atan2(sn, vd_dot(cont, q));
      vd_vec3 omega = sn > 1e-15 ? vd_scale(ax, th / sn) : vd_v3(0, 0, 0);
      double lbar = 0.5 * (lq + lp);
      vd_vec3 domega = vd_scale(vd_madd(vd_scale(vd_cross(q, up), beta * lbar), omega, -gamma), dt);
      double ang = v_norm(domega);
      if (!(ang > 0)) continue;
      vd_quat r = vd_quat_axis_angle(vd_scale(domega, 1.0 / ang), ang);
      vd_vec3 pivot = rest[b];
      for (int j = m->node_pre[c]; j <= m->node_last[c]; j++) {
        int i = m->node_order[j];
        rest[i] = vd_add(pivot, q_rotate(r, vd_sub(rest[i], pivot)));
      }
    }
  }
}

void vd_mss_stress_now(const vd_mss_model* m, vd_mss_data* d) {
  mss_external(m, d, d->work);
  vd_mss_stress(m, d);
}
