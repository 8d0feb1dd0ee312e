// SPDX-License-Identifier: MIT
// Pieces after fracture: which part of the plant each element belongs to once joints have
// broken, and the plant written back as separate pieces. A break at a rod joint splits the rod
// tree; a plant segment whose two ends lie on different pieces spans the gap, so it is cut at the
// joint: in a plant state (vd_sim_to_plant) by the break point of vd_data::seg_cut, in a spec
// (vd_sim_to_spec) into one segment per piece with new nodes at both faces of each break.
// Elements whose parent or attachment node lies on another piece lose that link, so every
// detached part is a tree of its own, with its labels and instances.
#include <string.h>

#include "sim_internal.h"

// piece of every rod segment and node: 0 for the rooted plant, t + 1 for the part hanging from
// segment t whose joint broke
typedef struct pieces {
  int* seg;   // (nseg)
  int* node;  // (nnode_all)
} pieces;

static int pieces_make(const vd_sim_model* m, const vd_sim_data* d, pieces* p) {
  p->seg = vd_malloc((size_t)(m->nseg ? m->nseg : 1) * sizeof(int));
  p->node = vd_malloc((size_t)(m->nnode_all ? m->nnode_all : 1) * sizeof(int));
  if (!p->seg || !p->node) return 0;
  // parents before children: seg_order lists children first
  for (int oi = m->nseg - 1; oi >= 0; oi--) {
    int t = m->seg_order[oi], par = m->seg_parent[t];
    p->seg[t] = d->seg_broken[t] ? t + 1 : par >= 0 ? p->seg[par] : 0;
  }
  for (int n = 0; n < m->nnode_all; n++) p->node[n] = 0;
  for (int n = 0; n < m->nnode; n++)
    if (m->node_owner[n] >= 0) p->node[n] = p->seg[m->node_owner[n]];
  for (int t = 0; t < m->nseg; t++)
    if (d->seg_broken[t] && d->seg_start[t] >= 0) p->node[d->seg_start[t]] = p->seg[t];
  return 1;
}

static void pieces_free(const vd_sim_model* m, pieces* p) {
  vd_free(p->seg, (size_t)(m->nseg ? m->nseg : 1) * sizeof(int));
  vd_free(p->node, (size_t)(m->nnode_all ? m->nnode_all : 1) * sizeof(int));
}

// piece of plant node i (through its binding; unbound nodes stay with the rooted plant)
static int node_piece(const vd_sim_model* m, const pieces* p, int i) {
  if (m->bind_node_ref[i] >= 0) return p->node[m->bind_node_ref[i]];
  if (m->bind_node_seg[i] >= 0) return p->seg[m->bind_node_seg[i]];
  return 0;
}

// modelled position of plant node i from the rod model's rest arrays (fallback: given)
static vd_vec3 node_rest(const vd_sim_model* m, int i, vd_vec3 fallback) {
  if (m->bind_node_ref[i] >= 0) return m->node_pos0[m->bind_node_ref[i]];
  int t = m->bind_node_seg[i];
  if (t >= 0) return vd_add(m->node_pos0[m->seg_node[2 * t]], vd_quat_rotate(m->seg_quat0[t], m->bind_node_local[i]));
  return fallback;
}

// one break on a plant segment: where along it (fraction of its length from node0), the end of
// the part on the node0 side and the start of the part beyond (m), the piece beyond
typedef struct cut {
  double f;
  vd_vec3 a, b;
  int piece;
} cut;

#define MAX_CUTS 64  // breaks followed along one plant segment

// The breaks on a plant segment from rest point n0 (piece p0) to n1 (piece p1), ordered from
// node0: the joints that made the pieces between p1 and p0. Returns the count.
static int segment_cuts(const vd_sim_model* m, const vd_sim_data* d, const pieces* p, int p0, int p1, vd_vec3 n0,
                        vd_vec3 n1, cut* c) {
  int n = 0;
  vd_vec3 axis = vd_sub(n1, n0);
  double l2 = vd_dot(axis, axis);
  // from the piece at node1 back toward node0: each piece's root joint, then its parent's piece
  for (int piece = p1; piece != p0 && piece > 0 && n < MAX_CUTS;) {
    int t = piece - 1, a = m->seg_node[2 * t];
    double f = l2 > 0 ? vd_dot(vd_sub(m->node_pos0[a], n0), axis) / l2 : 0;
    c[n].f = f < 0 ? 0 : f > 1 ? 1 : f;
    c[n].a = d->node_pos[a];
    c[n].b = d->node_pos[d->seg_start[t] >= 0 ? d->seg_start[t] : a];
    c[n].piece = piece;
    n++;
    piece = m->seg_parent[t] >= 0 ? p->seg[m->seg_parent[t]] : 0;
  }
  // node0 first
  for (int i = 0; i < n / 2; i++) {
    cut x = c[i];
    c[i] = c[n - 1 - i], c[n - 1 - i] = x;
  }
  return n;
}

// ---------------------------------------------------------------------------------------------
// a plant state: break points

void sim_plant_cuts(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant, vd_data* out) {
  for (int j = 0; j < plant->nseg; j++) {
    out->seg_broken[j] = 0;
    out->seg_cut[7 * j] = -1;
  }
  int any = 0;
  for (int t = 0; t < m->nseg; t++) any |= d->seg_broken[t];
  pieces p;
  if (!any || !pieces_make(m, d, &p)) {
    // out of memory: the segments of the broken rod segments are severed from their parents
    for (int t = 0; any && t < m->nseg; t++)
      if (d->seg_broken[t] && m->seg_plant[t] >= 0) out->seg_broken[m->seg_plant[t]] = 1;
    if (any) pieces_free(m, &p);
    return;
  }
  for (int j = 0; j < plant->nseg; j++) {
    int i0 = plant->seg_node[2 * j], i1 = plant->seg_node[2 * j + 1];
    int p0 = node_piece(m, &p, i0), p1 = node_piece(m, &p, i1);
    if (p0 == p1) continue;
    cut c[MAX_CUTS];
    vd_vec3 r0 = node_rest(m, i0, vd_v3(plant->node_pos0[3 * i0], plant->node_pos0[3 * i0 + 1], plant->node_pos0[3 * i0 + 2]));
    vd_vec3 r1 = node_rest(m, i1, vd_v3(plant->node_pos0[3 * i1], plant->node_pos0[3 * i1 + 1], plant->node_pos0[3 * i1 + 2]));
    int n = segment_cuts(m, d, &p, p0, p1, r0, r1, c);
    if (!n) continue;
    // the first break and the far side of the last one (a state draws one cut per segment)
    double* o = out->seg_cut + 7 * j;
    o[0] = c[0].f;
    o[1] = c[0].a.x, o[2] = c[0].a.y, o[3] = c[0].a.z;
    o[4] = c[n - 1].b.x, o[5] = c[n - 1].b.y, o[6] = c[n - 1].b.z;
    out->seg_broken[j] = 1;
  }
  pieces_free(m, &p);
}

// ---------------------------------------------------------------------------------------------
// a spec: separate pieces

// the piece of an element: its rod node, else its rod segment, else its attachment node
static int element_piece(const pieces* p, const int* npiece, int rod_node, int rod_seg, int node) {
  if (rod_node >= 0) return p->node[rod_node];
  if (rod_seg >= 0) return p->seg[rod_seg];
  return node >= 0 ? npiece[node] : 0;
}

vd_status sim_spec_pieces(const vd_sim_model* m, const vd_sim_data* d, vd_plant_spec* spec) {
  int any = 0;
  for (int t = 0; t < m->nseg; t++) any |= d->seg_broken[t];
  if (!any) return VD_OK;
  pieces p;
  int nn0 = spec->nnode, ns0 = spec->nseg;
  // pieces of nodes and segments, grown as cuts add them
  int capn = nn0 + 16, caps = ns0 + 16;
  int* npiece = vd_malloc((size_t)capn * sizeof(int));
  int* spiece = vd_malloc((size_t)caps * sizeof(int));
  vd_vec3* rest = vd_malloc((size_t)(nn0 ? nn0 : 1) * sizeof(vd_vec3));
  vd_status st = VD_OK;
  if (!pieces_make(m, d, &p) || !npiece || !spiece || !rest) {
    st = VD_ERR_NOMEM;
    goto done;
  }
  // modelled node positions (the spec already holds the deformed ones)
  for (int i = 0; i < nn0; i++) {
    rest[i] = node_rest(m, i, spec->node[i]);
    npiece[i] = node_piece(m, &p, i);
  }
  for (int j = 0; j < ns0; j++) spiece[j] = npiece[spec->seg[j].node1];
  // cut every segment whose ends lie on different pieces
  for (int j = 0; j < ns0 && !st; j++) {
    vd_segment_spec g = spec->seg[j];
    int p0 = npiece[g.node0], p1 = npiece[g.node1];
    if (p0 == p1) continue;
    cut c[MAX_CUTS];
    int n = segment_cuts(m, d, &p, p0, p1, rest[g.node0], rest[g.node1], c);
    if (!n) continue;
    // parts k = 0..n: from node0 (or the far face of break k - 1) to the near face of break k
    // (or node1); a part of no length is left out. The last part stays segment j (its children
    // hang from it); the others are new segments.
    int last = n;
    while (last > 0 && !(c[last - 1].f < 1 - 1e-9)) last--;
    for (int k = 0; k <= last && !st; k++) {
      double f0 = k ? c[k - 1].f : 0, f1 = k < n ? c[k].f : 1;
      if (k > 0 && k < last && !(f1 > f0 + 1e-12)) continue;  // two breaks at one point
      if (k == 0 && last > 0 && !(f1 > 1e-9)) continue;        // a break at node0
      vd_segment_spec part = g;
      part.r0 = g.r0 + f0 * (g.r1 - g.r0);
      part.r1 = g.r0 + f1 * (g.r1 - g.r0);
      part.parent = k == 0 ? g.parent : -1;
      int piece = k == 0 ? p0 : c[k - 1].piece;
      // its ends: node0 and node1 where they lie, new nodes at the faces of the breaks
      part.node0 = k == 0 ? g.node0 : vd_plant_add_node(spec, c[k - 1].b);
      part.node1 = k == n ? g.node1 : vd_plant_add_node(spec, c[k].a);
      if (k < n) part.flags |= VD_SEG_TIP;  // nothing continues past a break
      if (part.node0 < 0 || part.node1 < 0) {
        st = VD_ERR_NOMEM;
        break;
      }
      int at = k == last ? j : vd_plant_add_segment(spec, &part);
      if (at < 0) {
        st = VD_ERR_NOMEM;
        break;
      }
      if (k == last) spec->seg[j] = part;
      // pieces of the new nodes and segments
      if (!vd_grow((void**)&npiece, &capn, spec->nnode, sizeof(int)) ||
          !vd_grow((void**)&spiece, &caps, spec->nseg, sizeof(int))) {
        st = VD_ERR_NOMEM;
        break;
      }
      if (part.node0 >= nn0) npiece[part.node0] = piece;
      if (part.node1 >= nn0) npiece[part.node1] = piece;
      spiece[at] = piece;
    }
  }
  if (st) goto done;
  // links across pieces are cut: parents, attachment nodes
  for (int j = 0; j < spec->nseg; j++) {
    vd_segment_spec* g = &spec->seg[j];
    if (g->parent >= 0 && spiece[g->parent] != spiece[j]) g->parent = -1;
  }
  for (int k = 0; k < spec->nsphere; k++) {
    vd_sphere_spec* s = &spec->sphere[k];
    int piece = element_piece(&p, npiece, m->bind_sphere_node[k], -1, s->node);
    if (s->parent >= 0 && spiece[s->parent] != piece) s->parent = -1;
    if (s->node >= 0 && npiece[s->node] != piece) s->node = -1;
  }
  for (int k = 0; k < spec->nmesh; k++) {
    vd_mesh_spec* s = &spec->mesh[k];
    int rs = s->nvert > 0 ? m->bind_vert_seg[s->vert_start] : -1;
    int piece = element_piece(&p, npiece, -1, rs, s->node);
    if (s->parent >= 0 && spiece[s->parent] != piece) s->parent = -1;
    if (s->node >= 0 && npiece[s->node] != piece) s->node = -1;
  }
done:
  pieces_free(m, &p);
  vd_free(npiece, (size_t)capn * sizeof(int));
  vd_free(spiece, (size_t)caps * sizeof(int));
  vd_free(rest, (size_t)(nn0 ? nn0 : 1) * sizeof(vd_vec3));
  return st;
}
