// SPDX-License-Identifier: MIT
// Self-collision of the rod model through the collide module: the plant's primitives (one
// capsule per segment, one sphere per fruit node), the excluded-pair adjacency built once per
// state from the modelled shape, and per step the contacts of vd_collide_self turned into
// sim_contact records (collider -1) for the projection in sim_contact_basic.c.
#include "sim_internal.h"

// topological neighbours excluded: primitives whose nodes are at most this many capsules apart
#define SIM_SELF_HOPS 1
// pairs closer than this in the modelled shape touch by design and are excluded too (m)
#define SIM_SELF_REST_MARGIN 0.001
// boxes of the broad phase grow by the contact margin plus this, so its pairs last several steps (m)
#define SIM_SELF_GROW 0.01

// segments that take part: everything but the stalks inside fruit spheres
static int seg_collides(const vd_sim_model* m, int t) { return !(m->seg_flags[t] & VD_SIM_FRUITSEG); }

void sim_self_free(sim_self* s) {
  if (!s) return;
  vd_collide_exclusion_free(&s->ex);
  vd_arena_free(&s->pair_arena);
  vd_free(s->block, s->nbytes);
  memset(s, 0, sizeof *s);
}

// fill the primitive arrays from positions pos (capsule ends from the current start nodes)
static void self_fill(const vd_sim_model* m, const int* seg_start, const vd_vec3* pos, sim_self* s) {
  for (int k = 0; k < s->ncap; k++) {
    int t = s->cap_seg[k];
    s->cap_node[2 * k] = seg_start ? seg_start[t] : m->seg_node[2 * t];
    s->cap_node[2 * k + 1] = m->seg_node[2 * t + 1];
  }
  for (int k = 0; k < s->nsph; k++) {
    vd_vec3 p = pos[s->sph_node[k]];
    s->sph_pos[3 * k] = p.x, s->sph_pos[3 * k + 1] = p.y, s->sph_pos[3 * k + 2] = p.z;
  }
}

// primitives view over the node positions pos
static vd_collide_prims self_prims(const vd_sim_model* m, const vd_vec3* pos, const sim_self* s) {
  vd_collide_prims p;
  memset(&p, 0, sizeof p);
  p.nnode = m->nnode_all, p.ncapsule = s->ncap, p.nsphere = s->nsph;
  p.node_pos = &pos[0].x;
  p.capsule_node = s->cap_node, p.capsule_radius = s->cap_radius;
  p.sphere_pos = s->sph_pos, p.sphere_radius = s->sph_radius;
  p.margin = s->margin;
  return p;
}

vd_status sim_self_init(const vd_sim_model* m, sim_self* s, vd_error* err) {
  memset(s, 0, sizeof *s);
  int nc = 0, nsp = 0;
  for (int t = 0; t < m->nseg; t++) nc += seg_collides(m, t);
  for (int i = 0; i < m->nnode; i++) nsp += m->node_sphere[i] > 0 && m->node_owner[i] >= 0;
  size_t I = sizeof(int), D = sizeof(double);
  size_t nca = nc ? (size_t)nc : 1, nsa = nsp ? (size_t)nsp : 1;
  size_t npa = nca + nsa;
  s->nbytes = (size_t)m->nnode_all * sizeof(vd_vec3) + nca * 3 * I + nca * 2 * D + nsa * I + nsa * 4 * D +
              npa * 2 * D;
  s->block = vd_malloc(s->nbytes);
  if (!s->block) {
    s->nbytes = 0;
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "sim: out of memory (self-collision)");
  }
  // layout: doubles first (alignment), then ints
  s->pos_built = (vd_vec3*)s->block;
  double* dp = (double*)(s->pos_built + m->nnode_all);
  s->cap_radius = dp, dp += nca * 2;
  s->sph_pos = dp, dp += nsa * 3;
  s->sph_radius = dp, dp += nsa;
  s->margin = dp, dp += npa;
  s->margin_built = dp, dp += npa;
  int* ip = (int*)dp;
  s->cap_node = ip, ip += nca * 2;
  s->cap_seg = ip, ip += nca;
  s->sph_node = ip;
  s->ncap = nc, s->nsph = nsp;
  for (int t = 0, k = 0; t < m->nseg; t++)
    if (seg_collides(m, t)) {
      s->cap_seg[k] = t;
      s->cap_radius[2 * k] = s->cap_radius[2 * k + 1] = m->seg_radius[t];
      k++;
    }
  for (int i = 0, k = 0; i < m->nnode; i++)
    if (m->node_sphere[i] > 0 && m->node_owner[i] >= 0) {
      s->sph_node[k] = i;
      s->sph_radius[k] = m->node_sphere[i];
      k++;
    }
  // exclusion: neighbours along the rods, then whatever touches in the modelled shape (at rest:
  // no margins of their own)
  self_fill(m, NULL, m->node_pos0, s);
  memset(s->margin, 0, npa * D);
  vd_status st = vd_collide_exclusion_build(m->nnode_all, nc, s->cap_node, nsp, s->sph_node, SIM_SELF_HOPS,
                                            &s->ex, err);
  if (!st) {
    vd_collide_prims rest = self_prims(m, m->node_pos0, s);
    vd_collide_prims_set_exclusion(&rest, &s->ex);
    st = vd_collide_exclusion_add_touching(&s->ex, &rest, SIM_SELF_REST_MARGIN, err);
  }
  vd_arena_init(&s->pair_arena, 0);
  if (st) sim_self_free(s);
  return st;
}

int sim_self_find(const vd_sim_model* m, vd_sim_data* d, double margin, sim_contact* prev, int nprev,
                  sim_contact** out) {
  sim_work* w = (sim_work*)d->work;
  sim_self* s = &w->self;
  *out = prev;
  if (!s->block || s->ncap + s->nsph < 2) return nprev;
  self_fill(m, d->seg_start, d->node_pos, s);
  vd_collide_prims p = self_prims(m, d->node_pos, s);
  vd_collide_prims_set_exclusion(&p, &s->ex);
  vd_collide_def def = vd_collide_def_default();
  def.margin = margin;
  // each primitive's own margin: twice the step's largest displacement of its nodes (two
  // elements closing at once each bring their own); and how far it moved since the build
  int np = s->ncap + s->nsph;
  const vd_vec3* start = w->node_prev;
  double* moved = vd_arena_alloc(&d->arena, (size_t)np * sizeof *moved);
  if (!moved) {
    sim_warn(d, VD_SIM_WARN_ARENA);
    return nprev;
  }
  for (int k = 0; k < np; k++) {
    int nd[2];
    if (k < s->ncap)
      nd[0] = s->cap_node[2 * k], nd[1] = s->cap_node[2 * k + 1];
    else
      nd[0] = nd[1] = s->sph_node[k - s->ncap];
    double step2 = 0, built2 = 0;
    for (int e = 0; e < 2; e++) {
      vd_vec3 u = vd_sub(d->node_pos[nd[e]], start[nd[e]]), b = vd_sub(d->node_pos[nd[e]], s->pos_built[nd[e]]);
      step2 = fmax(step2, vd_dot(u, u)), built2 = fmax(built2, vd_dot(b, b));
    }
    s->margin[k] = 2 * sqrt(step2);
    moved[k] = sqrt(built2);
  }
  // broad phase again when a primitive may have moved past the growth of its box (its margin's
  // drop since the build counts in its favour), or after a fracture
  double lim = 0.5 * (s->grow - margin);
  int rebuild = !s->have_pairs || lim <= 0 || s->nevent_built != d->nevent;
  for (int k = 0; k < np && !rebuild; k++)
    rebuild = moved[k] + s->margin[k] > lim + s->margin_built[k];
  vd_error err;
  if (rebuild) {
    vd_arena_reset(&s->pair_arena);
    s->grow = margin + SIM_SELF_GROW;
    s->have_pairs = 0;
    if (vd_collide_self_pairs(&p, s->grow, &s->pair_arena, &s->pairs, &err)) {
      sim_warn(d, VD_SIM_WARN_ARENA);
      return nprev;
    }
    memcpy(s->pos_built, d->node_pos, (size_t)m->nnode_all * sizeof(vd_vec3));
    memcpy(s->margin_built, s->margin, (size_t)np * sizeof *s->margin);
    s->have_pairs = 1;
    s->nevent_built = d->nevent;
  }
  // narrow phase over the kept pairs
  vd_contact_list L;
  if (vd_collide_pairs(&p, &s->pairs, &def, &d->arena, &L, &err)) {
    sim_warn(d, VD_SIM_WARN_ARENA);
    return nprev;
  }
  // contacts beyond the list's cap are a counted warning, never a silent drop
  if (L.ndropped) sim_warn(d, VD_SIM_WARN_ARENA);
  if (!L.n) return nprev;
  sim_contact* c = vd_arena_alloc(&d->arena, (size_t)(nprev + L.n) * sizeof(sim_contact));
  if (!c) {
    sim_warn(d, VD_SIM_WARN_ARENA);
    return nprev;
  }
  if (nprev) memcpy(c, prev, (size_t)nprev * sizeof(sim_contact));
  int n = nprev;
  for (int k = 0; k < L.n; k++) {
    const vd_contact* q = &L.c[k];
    // primitive a (capsule or sphere) as the first element, b as the second
    sim_contact r = {-1, -1, 0, 0, -1, 0, -1, -1, 0, 0};
    if (q->a < s->ncap) {
      r.seg = s->cap_seg[q->a], r.t = q->ta, r.radius = s->cap_radius[2 * q->a];
    } else {
      r.node = s->sph_node[q->a - s->ncap], r.radius = s->sph_radius[q->a - s->ncap];
    }
    if (q->b < s->ncap) {
      r.seg2 = s->cap_seg[q->b], r.t2 = q->tb, r.radius2 = s->cap_radius[2 * q->b];
    } else {
      r.node2 = s->sph_node[q->b - s->ncap], r.radius2 = s->sph_radius[q->b - s->ncap];
    }
    // two kinematic elements cannot be moved apart
    int wa = r.node >= 0 ? sim_node_w(m, d, r.node) > 0
                         : sim_node_w(m, d, d->seg_start[r.seg]) > 0 || sim_node_w(m, d, m->seg_node[2 * r.seg + 1]) > 0;
    int wb = r.node2 >= 0 ? sim_node_w(m, d, r.node2) > 0
                          : sim_node_w(m, d, d->seg_start[r.seg2]) > 0 || sim_node_w(m, d, m->seg_node[2 * r.seg2 + 1]) > 0;
    if (wa || wb) c[n++] = r;
  }
  *out = c;
  return n;
}
