// SPDX-License-Identifier: MIT
// External colliders: analytic signed distances of a plane, sphere, capsule and box, closed
// triangle meshes through the collide module's signed distance grids, contact candidates (nodes
// against planes with the rod's flat-ended cross sections, fruit spheres, segment capsules), and
// their XPBD projection (compliance 0) with Coulomb friction; self-contacts come from
// vd_collide_self (sim_self.c) and are projected here too.
#include "sim_internal.h"

double sim_collider_distance(const vd_sim_collider* k, vd_vec3 p, vd_vec3* normal) {
  vd_vec3 v = vd_sub(p, k->pos);
  switch (k->shape) {
    case VD_SIM_PLANE: {
      vd_vec3 n = vd_quat_rotate(k->quat, vd_v3(0, 0, 1));
      *normal = n;
      return vd_dot(n, v);
    }
    case VD_SIM_SPHERE: {
      double r = vd_norm(v);
      *normal = r > 1e-15 ? vd_scale(v, 1.0 / r) : vd_v3(0, 0, 1);
      return r - k->size[0];
    }
    case VD_SIM_CAPSULE: {
      vd_vec3 a = vd_quat_rotate(k->quat, vd_v3(0, 0, 1));
      double s = vd_dot(v, a), hl = k->size[1];
      s = s < -hl ? -hl : s > hl ? hl : s;
      vd_vec3 w = vd_madd(v, a, -s);
      double r = vd_norm(w);
      *normal = r > 1e-15 ? vd_scale(w, 1.0 / r) : vd_quat_rotate(k->quat, vd_v3(1, 0, 0));
      return r - k->size[0];
    }
    case VD_SIM_BOX: {
      // box signed distance in the box frame, gradient back to world
      vd_vec3 l = vd_quat_rotate(vd_quat_conj(k->quat), v);
      double q[3] = {fabs(l.x) - k->size[0], fabs(l.y) - k->size[1], fabs(l.z) - k->size[2]};
      double sg[3] = {l.x < 0 ? -1.0 : 1.0, l.y < 0 ? -1.0 : 1.0, l.z < 0 ? -1.0 : 1.0};
      double out2 = 0, inside = q[0];
      int imax = 0;
      for (int i = 0; i < 3; i++) {
        if (q[i] > 0) out2 += q[i] * q[i];
        if (q[i] > inside) inside = q[i], imax = i;
      }
      vd_vec3 g;
      double dist;
      if (out2 > 0) {
        dist = sqrt(out2);
        g = vd_v3(q[0] > 0 ? sg[0] * q[0] / dist : 0, q[1] > 0 ? sg[1] * q[1] / dist : 0,
                  q[2] > 0 ? sg[2] * q[2] / dist : 0);
      } else {
        dist = inside;
        double e[3] = {0, 0, 0};
        e[imax] = sg[imax];
        g = vd_v3(e[0], e[1], e[2]);
      }
      *normal = vd_quat_rotate(k->quat, g);
      return dist;
    }
    case VD_SIM_MESH: {
      // the collide module's grid in the mesh frame: interpolated distance and its gradient
      if (!k->sdf) break;
      vd_vec3 g;
      double dist = vd_sdf_eval(k->sdf, vd_quat_rotate(vd_quat_conj(k->quat), v), &g);
      double gn = vd_norm(g);
      *normal = gn > 1e-15 ? vd_quat_rotate(k->quat, vd_scale(g, 1.0 / gn)) : vd_v3(0, 0, 1);
      return dist;
    }
  }
  *normal = vd_v3(0, 0, 1);
  return 1e300;
}

// closest parameter on segment a-b to point p
static double closest_t(vd_vec3 a, vd_vec3 b, vd_vec3 p) {
  vd_vec3 ab = vd_sub(b, a);
  double l2 = vd_dot(ab, ab);
  if (l2 <= 0) return 0;
  double t = vd_dot(vd_sub(p, a), ab) / l2;
  return t < 0 ? 0 : t > 1 ? 1 : t;
}

// closest parameter on segment a-b to the segment c-d (Ericson 2004, 5.1.9)
static double closest_t_seg(vd_vec3 a, vd_vec3 b, vd_vec3 c, vd_vec3 dd) {
  vd_vec3 d1 = vd_sub(b, a), d2 = vd_sub(dd, c), r = vd_sub(a, c);
  double aa = vd_dot(d1, d1), e = vd_dot(d2, d2), f = vd_dot(d2, r);
  if (aa <= 1e-30) return 0;
  double cc = vd_dot(d1, r), s, t;
  if (e <= 1e-30) {
    s = -cc / aa;
  } else {
    double bb = vd_dot(d1, d2), den = aa * e - bb * bb;
    s = den > 1e-30 ? (bb * f - cc * e) / den : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    t = (bb * s + f) / e;
    if (t < 0)
      s = -cc / aa;
    else if (t > 1)
      s = (bb - cc) / aa;
  }
  return s < 0 ? 0 : s > 1 ? 1 : s;
}

// best parameter along the segment for a collider: exact for spheres and capsules, the
// deepest of 9 equidistant samples for boxes (as Gazebo Plants samples capsules), the collide
// module's search along the axis for meshes
static double seg_param(const vd_sim_collider* k, vd_vec3 a, vd_vec3 b) {
  switch (k->shape) {
    case VD_SIM_SPHERE: return closest_t(a, b, k->pos);
    case VD_SIM_CAPSULE: {
      vd_vec3 ax = vd_quat_rotate(k->quat, vd_v3(0, 0, k->size[1]));
      return closest_t_seg(a, b, vd_sub(k->pos, ax), vd_add(k->pos, ax));
    }
    case VD_SIM_MESH: {
      // the collide module's axis search: samples every half cell, then a golden-section refine
      if (!k->sdf) return 0;
      vd_pose pose = {k->pos, k->quat};
      vd_collider c = vd_collider_sdf(pose, k->sdf);
      return vd_collide_capsule(&c, a, b, 0, 0).t;
    }
    default: {
      double best = 1e300, bt = 0;
      for (int i = 0; i <= 8; i++) {
        double t = i / 8.0;
        vd_vec3 nrm;
        double s = sim_collider_distance(k, vd_add(a, vd_scale(vd_sub(b, a), t)), &nrm);
        if (s < best) best = s, bt = t;
      }
      return bt;
    }
  }
}

// radius of a ball around the collider's pos holding the whole shape (m); planes: infinite
static double collider_reach(const vd_sim_collider* k) {
  switch (k->shape) {
    case VD_SIM_SPHERE: return k->size[0];
    case VD_SIM_CAPSULE: return k->size[0] + k->size[1];
    case VD_SIM_BOX: return sqrt(k->size[0] * k->size[0] + k->size[1] * k->size[1] + k->size[2] * k->size[2]);
    case VD_SIM_MESH: {
      // the grid's box around the mesh frame's origin: its farthest corner
      if (!k->sdf) return 0;
      const vd_sdf* g = k->sdf;
      double r2 = 0;
      for (int c = 0; c < 8; c++) {
        vd_vec3 p = vd_v3(g->origin.x + ((c & 1) ? (g->nx - 1) * g->cell : 0),
                          g->origin.y + ((c & 2) ? (g->ny - 1) * g->cell : 0),
                          g->origin.z + ((c & 4) ? (g->nz - 1) * g->cell : 0));
        double q = vd_dot(p, p);
        if (q > r2) r2 = q;
      }
      return sqrt(r2);
    }
    default: return INFINITY;
  }
}

// squared distance from point p to segment a-b
static double seg_dist2(vd_vec3 a, vd_vec3 b, vd_vec3 p) {
  vd_vec3 q = vd_sub(vd_add(a, vd_scale(vd_sub(b, a), closest_t(a, b, p))), p);
  return vd_dot(q, q);
}

// how far the plant reaches beyond each node towards a plane of normal n (m), -1 where nothing
// is attached. A rod segment is a cylinder with flat ends: its deepest point towards the
// plane lies on the rim of an end disk, r sqrt(1 - (n.u)^2) beyond the axis (u its direction),
// so a chain of them touches a plane first at a node with this reach; a fruit sphere reaches
// its radius. (Node spheres of the segment radius reach r along the axis as well: they pushed
// the first free node of the tree's upright trunk, r = 8.2 cm, from 3 cm above the ground to
// 8.2 cm, stretching the 2 cm segment below it by 260 %.)
// Only segments with an end in near[] (a node whose height above the plane, less its largest
// radius, is below the margin) are looked at: the others cannot make a candidate.
static void plane_reach(const vd_sim_model* m, const vd_sim_data* d, vd_vec3 n, const unsigned char* near,
                        double* reach) {
  for (int i = 0; i < m->nnode_all; i++)
    reach[i] = m->node_sphere[i] > 0 ? m->node_sphere[i] : -1;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FRUITSEG) continue;
    int a = d->seg_start[t], b = m->seg_node[2 * t + 1];
    if (!near[a] && !near[b]) continue;
    vd_vec3 e = vd_sub(d->node_pos[b], d->node_pos[a]);
    double l2 = vd_dot(e, e), en = vd_dot(e, n);
    double s2 = l2 > 0 ? 1 - en * en / l2 : 1;
    double r = m->seg_radius[t] * sqrt(s2 > 0 ? s2 : 0);
    if (r > reach[a]) reach[a] = r;
    if (r > reach[b]) reach[b] = r;
  }
}

int sim_contacts_find(const vd_sim_model* m, vd_sim_data* d, double margin, sim_contact** out) {
  *out = NULL;
  if (!d->ncollider) return 0;
  size_t cap = (size_t)d->ncollider * (size_t)(m->nseg + m->nnode_all);
  sim_contact* c = vd_arena_alloc(&d->arena, cap * sizeof(sim_contact));
  double* reach = vd_arena_alloc(&d->arena, (size_t)m->nnode_all * sizeof(double));
  unsigned char* near = vd_arena_alloc(&d->arena, (size_t)m->nnode_all);
  if (!c || !reach || !near) {
    sim_warn(d, VD_SIM_WARN_ARENA);
    return 0;
  }
  int n = 0;
  for (int k = 0; k < d->ncollider; k++) {
    const vd_sim_collider* col = &d->collider[k];
    vd_vec3 nrm;
    if (col->shape == VD_SIM_PLANE) {
      // every moving node with the rod's reach towards the plane; a node higher than its
      // largest radius plus the margin cannot touch, and needs no reach
      vd_vec3 pn = vd_quat_rotate(col->quat, vd_v3(0, 0, 1));
      const sim_work* w = (const sim_work*)d->work;
      int any = 0;
      for (int i = 0; i < m->nnode_all; i++) {
        // a spare node carries the segment that broke onto it
        double rmax = i < m->nnode ? m->node_radius[i] : m->seg_radius[w->spare_of[i - m->nnode]];
        near[i] = sim_node_moves(m, d, i) && i != d->collider_pass[k] &&
                  vd_dot(pn, vd_sub(d->node_pos[i], col->pos)) - rmax < margin;
        any |= near[i];
      }
      if (!any) continue;
      plane_reach(m, d, pn, near, reach);
      for (int i = 0; i < m->nnode_all; i++) {
        if (!near[i] || reach[i] < 0) continue;
        if (sim_collider_distance(col, d->node_pos[i], &nrm) - reach[i] < margin)
          c[n++] = (sim_contact){i, -1, 0, reach[i], k, 0, -1, -1, 0, 0};
      }
      continue;
    }
    // fruit spheres, then segment capsules; a ball around the shape: elements beyond it (plus
    // their radius) are skipped at once
    double far = collider_reach(col) + margin;
    for (int i = 0; i < m->nnode_all; i++) {
      double r = m->node_sphere[i];
      if (!(r > 0) || !sim_node_moves(m, d, i) || i == d->collider_pass[k]) continue;
      vd_vec3 dp = vd_sub(d->node_pos[i], col->pos);
      if (vd_dot(dp, dp) > (far + r) * (far + r)) continue;
      if (sim_collider_distance(col, d->node_pos[i], &nrm) - r < margin)
        c[n++] = (sim_contact){i, -1, 0, r, k, 0, -1, -1, 0, 0};
    }
    for (int t = 0; t < m->nseg; t++) {
      if (m->seg_flags[t] & (VD_SIM_FIXED | VD_SIM_FRUITSEG)) continue;
      int na = d->seg_start[t], nb = m->seg_node[2 * t + 1];
      vd_vec3 a = d->node_pos[na], b = d->node_pos[nb];
      double r = m->seg_radius[t];
      if (seg_dist2(a, b, col->pos) > (far + r) * (far + r)) continue;
      double u = seg_param(col, a, b);
      if (sim_collider_distance(col, vd_add(a, vd_scale(vd_sub(b, a), u)), &nrm) - r < margin)
        c[n++] = (sim_contact){-1, t, u, r, k, 0, -1, -1, 0, 0};
    }
  }
  *out = c;
  return n;
}

// current point, its generalised inverse mass, and the two nodes with their weights
typedef struct cpoint {
  vd_vec3 p;
  int na, nb;
  double ca, cb, wa, wb, w;
} cpoint;

// a rod element (node, or segment at parameter t) as a contact point
static cpoint element_point(const vd_sim_model* m, const vd_sim_data* d, int node, int seg, double t) {
  cpoint q;
  if (node >= 0) {
    q.na = q.nb = node;
    q.ca = 1, q.cb = 0;
    q.wa = q.wb = sim_node_w(m, d, node);
    q.p = d->node_pos[node];
    q.w = q.wa;
    return q;
  }
  q.na = d->seg_start[seg], q.nb = m->seg_node[2 * seg + 1];
  q.ca = 1 - t, q.cb = t;
  q.wa = sim_node_w(m, d, q.na), q.wb = sim_node_w(m, d, q.nb);
  q.p = vd_add(vd_scale(d->node_pos[q.na], q.ca), vd_scale(d->node_pos[q.nb], q.cb));
  q.w = q.ca * q.ca * q.wa + q.cb * q.cb * q.wb;
  return q;
}

static cpoint contact_point(const vd_sim_model* m, const vd_sim_data* d, sim_contact* c) {
  if (c->node < 0 && c->collider >= 0) {
    // follow the closest point on the axis for round colliders
    const vd_sim_collider* col = &d->collider[c->collider];
    vd_vec3 a = d->node_pos[d->seg_start[c->seg]], b = d->node_pos[m->seg_node[2 * c->seg + 1]];
    if (col->shape == VD_SIM_SPHERE || col->shape == VD_SIM_CAPSULE) c->t = seg_param(col, a, b);
  }
  if (c->collider < 0 && c->seg >= 0 && c->seg2 >= 0) {
    // two capsules: the closest points of their axes
    vd_vec3 a = d->node_pos[d->seg_start[c->seg]], b = d->node_pos[m->seg_node[2 * c->seg + 1]];
    vd_vec3 e = d->node_pos[d->seg_start[c->seg2]], f = d->node_pos[m->seg_node[2 * c->seg2 + 1]];
    c->t = closest_t_seg(a, b, e, f);
    c->t2 = closest_t(e, f, vd_add(a, vd_scale(vd_sub(b, a), c->t)));
  }
  return element_point(m, d, c->node, c->seg, c->t);
}

double sim_contact_gap(const vd_sim_model* m, const vd_sim_data* d, sim_contact* c) {
  cpoint q = contact_point(m, d, c);
  vd_vec3 nrm;
  if (c->collider >= 0) return sim_collider_distance(&d->collider[c->collider], q.p, &nrm) - c->radius;
  cpoint q2 = element_point(m, d, c->node2, c->seg2, c->t2);
  return vd_norm(vd_sub(q.p, q2.p)) - c->radius - c->radius2;
}

// move the contact point by dp, sharing the motion by inverse mass; returns the mass-weighted
// displacement sum m_i dx_i (the momentum given to the plant, times h) (kg m)
static vd_vec3 move_point(vd_sim_data* d, const cpoint* q, vd_vec3 dp) {
  if (q->w <= 0) return vd_v3(0, 0, 0);
  vd_vec3 k = vd_scale(dp, 1.0 / q->w);
  if (q->na == q->nb) {
    d->node_pos[q->na] = vd_add(d->node_pos[q->na], dp);
    return vd_scale(dp, d->node_mass[q->na]);
  }
  d->node_pos[q->na] = vd_madd(d->node_pos[q->na], k, q->ca * q->wa);
  d->node_pos[q->nb] = vd_madd(d->node_pos[q->nb], k, q->cb * q->wb);
  return vd_scale(k, (q->wa > 0 ? q->ca : 0) + (q->wb > 0 ? q->cb : 0));
}

// the reaction of a collider contact at point p: the collider receives minus the momentum mdx / h
// it gave the plant (accumulated per step in the work block)
static void collider_reaction(const vd_sim_data* d, int k, vd_vec3 p, vd_vec3 mdx, double h) {
  sim_work* w = (sim_work*)d->work;
  vd_vec3 j = vd_scale(mdx, -1.0 / h);
  w->col_imp[k] = vd_add(w->col_imp[k], j);
  w->col_ang[k] = vd_add(w->col_ang[k], vd_cross(vd_sub(p, d->collider[k].pos), j));
}

void sim_contacts_project(const vd_sim_model* m, vd_sim_data* d, sim_contact* c, int n, double h) {
  for (int i = 0; i < n; i++) {
    cpoint q = contact_point(m, d, &c[i]);
    vd_vec3 nrm;
    if (c[i].collider >= 0) {
      if (q.w <= 0) continue;
      double s = sim_collider_distance(&d->collider[c[i].collider], q.p, &nrm) - c[i].radius;
      if (s >= 0) continue;
      collider_reaction(d, c[i].collider, q.p, move_point(d, &q, vd_scale(nrm, -s)), h);
      c[i].lambda += -s;
      continue;
    }
    // self-contact: push the two elements apart along the line between them, by inverse mass
    cpoint q2 = element_point(m, d, c[i].node2, c[i].seg2, c[i].t2);
    vd_vec3 dp = vd_sub(q.p, q2.p);
    double dist = vd_norm(dp), s = dist - c[i].radius - c[i].radius2, w = q.w + q2.w;
    if (s >= 0 || w <= 0 || dist < 1e-15) continue;
    nrm = vd_scale(dp, 1.0 / dist);
    move_point(d, &q, vd_scale(nrm, -s * q.w / w));
    move_point(d, &q2, vd_scale(nrm, s * q2.w / w));
    c[i].lambda += -s;
  }
}

void sim_contacts_friction(const vd_sim_model* m, vd_sim_data* d, sim_contact* c, int n, double h) {
  const sim_work* w = (const sim_work*)d->work;
  double mu = m->opt.friction;
  for (int i = 0; i < n; i++) {
    if (c[i].lambda <= 0 || mu <= 0 || c[i].collider < 0) continue;  // self-contacts: no friction yet
    cpoint q = contact_point(m, d, &c[i]);
    if (q.w <= 0) continue;
    const vd_sim_collider* col = &d->collider[c[i].collider];
    vd_vec3 nrm;
    sim_collider_distance(col, q.p, &nrm);
    // tangential motion of the contact point over the step, relative to the collider
    vd_vec3 p0 = vd_add(vd_scale(w->node_prev[q.na], q.ca), vd_scale(w->node_prev[q.nb], q.cb));
    vd_vec3 dp = vd_sub(vd_sub(q.p, p0), vd_scale(col->vel, h));
    vd_vec3 dt = vd_madd(dp, nrm, -vd_dot(dp, nrm));
    double lt = vd_norm(dt), lim = mu * c[i].lambda;
    if (lt <= 0) continue;
    // static friction cancels the slip; kinetic friction removes mu times the normal push
    double k = lt <= lim ? 1.0 : lim / lt;
    collider_reaction(d, c[i].collider, q.p, move_point(d, &q, vd_scale(dt, -k)), h);
  }
}
