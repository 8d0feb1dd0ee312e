// SPDX-License-Identifier: MIT
// Building the rod model of a plant (Gazebo Plants section 3.5, with verdant's plants as the
// input instead of hand-drawn curves): axes are cut at key nodes (junctions, tips, organ
// changes, attachment points of leaves and fruits, pedicel abscission nodes) into chains, and
// each chain is resampled to rod segments of about sigma_distance with nodes on the plant's
// polyline. Leaves become small rod graphs, spheres hang from a stalk segment, the first
// clamp_length of every root segment is held fixed (0: the root node and its frame only). Then masses, rest frames (parallel
// transport), compliances, fracture thresholds and the elimination order are set, and every
// plant element is bound to the rod it follows.
#include <stdlib.h>

#include "sim_internal.h"

// ---------------------------------------------------------------------------------------------
// defaults

static const char* class_names[VD_SIM_CLASS_COUNT] = {"green", "wood", "pedicel", "leaf",
                                                       "fruit", "flower", "root"};

const char* vd_sim_class_name(vd_sim_class c) {
  return c >= 0 && c < VD_SIM_CLASS_COUNT ? class_names[c] : "?";
}

vd_sim_class vd_sim_class_parse(const char* name) {
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++)
    if (name && strcmp(name, class_names[c]) == 0) return (vd_sim_class)c;
  return VD_SIM_CLASS_COUNT;
}

static const char* bend_names[2] = {"log", "quat"};

const char* vd_sim_bend_name(vd_sim_bend b) { return b >= 0 && b < 2 ? bend_names[b] : "?"; }

int vd_sim_bend_parse(const char* name) {
  for (int k = 0; k < 2; k++)
    if (name && strcmp(name, bend_names[k]) == 0) return k;
  return -1;
}

static vd_sim_material material(double e, double rho, double cd) {
  vd_sim_material mt = {e, 0.3, rho, INFINITY, INFINITY, INFINITY, INFINITY, cd};
  return mt;
}

vd_sim_def vd_sim_def_default(void) {
  vd_sim_def d;
  memset(&d, 0, sizeof d);
  d.segment_length = 0.02;
  d.clamp_length = 0.01;
  d.clamp_roots = 1;
  // E, rho, cd per class: anchors-physics.md 5.1, facts-robot-trees.md 5.2, docs/physics.md
  d.material[VD_SIM_GREEN] = material(1e9, 1000, 1.2);
  d.material[VD_SIM_WOOD] = material(1e10, 900, 1.2);
  d.material[VD_SIM_PEDICEL] = material(5e8, 1000, 1.2);
  d.material[VD_SIM_LEAF] = material(5e8, 900, 1.2);
  d.material[VD_SIM_FRUIT] = material(5e6, 800, 0.47);
  d.material[VD_SIM_FLOWER] = material(1e8, 500, 0.47);
  d.material[VD_SIM_ROOT] = material(1e10, 900, 1.2);
  // abscission knuckle of a cherry-tomato pedicel: 5-8 N in tension; bending moment assumed
  // (no source reached): 5x the weight moment of a fruit on a horizontal pedicel; calyx pull
  // 0.58-2.46 N (docs/physics.md)
  d.material[VD_SIM_PEDICEL].break_force = 6.5;
  d.material[VD_SIM_PEDICEL].break_moment = 1e-2;
  d.material[VD_SIM_FRUIT].break_force = 1.5;
  d.leaf_areal_density = 0.22;
  d.leaf_vein_ratio = 0.015;
  d.leaf_plate_cd = 1.17;
  d.leaf_graphs = 1;
  d.sag_free = 0;
  d.gravity = vd_v3(0, 0, -9.81);
  d.max_segments = 1000000;
  d.bend_measure = VD_SIM_BEND_LOG;
  d.stake_spacing = 0;
  d.stake_stiffness = 1e4;
  return d;
}

vd_sim_opt vd_sim_opt_default(void) {
  vd_sim_opt o;
  memset(&o, 0, sizeof o);
  o.dt = 1e-3;
  o.iterations = 1;
  o.solver = VD_SIM_DIRECT;
  o.gravity = vd_v3(0, 0, -9.81);
  o.air_density = 1.226;
  o.gust_period = 2.0;
  o.drag = 1;
  o.fracture = 1;
  o.contacts = 1;
  o.friction = 0.5;
  o.self_collision = 0;
  o.threads = 1;
  return o;
}

// ---------------------------------------------------------------------------------------------
// builder state: growable arrays

typedef struct bnode {
  vd_vec3 pos;
  double mass, radius, sphere;
  int owner, fixed, root_seg;
} bnode;

typedef struct bseg {
  int n0, n1, parent, cls, label, instance, plant;
  unsigned flags;
  double radius, mass, ib, it;
  vd_vec3 leafn;  // lamina area times normal, world frame while building
  int ghost;      // the fixed segment behind a root held without a pot (clamp_length 0): no mass
} bseg;

typedef struct pend {
  int item, seg;  // plant item bound to a rod segment
} pend;

typedef struct bld {
  const vd_model* p;
  const vd_sim_def* def;
  vd_error* err;
  bnode* node;
  int nnode, cap_node;
  bseg* seg;
  int nseg, cap_seg;
  pend* pnode;  // plant nodes bound to a rod segment
  int npnode, cap_pnode;
  int* rod_of;        // plant node -> rod node (plant nnode)
  int* pseg_rod;      // plant segment -> rod segment (plant nseg)
  int* sph_node;      // plant sphere -> rod node
  int* sph_seg;       // plant sphere -> rod segment
  int* vert_seg;      // plant vertex -> rod segment
  int* pclass;        // plant segment -> class
  int* out_seg;       // plant node -> a segment starting there
  int* in_seg;        // plant node -> a segment ending there
  int* nout;          // plant node -> segments starting there
  int* nin;           // plant node -> segments ending there
  unsigned char* key; // plant node is a key node
  unsigned char* absc;// plant node is an abscission node
  int ntie;
  int* tie_node;
  int cap_tie;
  int over;  // 1 when the model would pass def->max_segments
} bld;

// the error of a failed addition: the segment limit, or out of memory
static vd_status oom(bld* b) {
  if (b->over)
    return vd_error_set(b->err, VD_ERR_LIMIT, "", 0, 0,
                        "sim: the rod model needs more than %d segments (segment length %g m); use a longer "
                        "segment length or raise the segment limit",
                        b->def->max_segments, b->def->segment_length);
  return vd_error_set(b->err, VD_ERR_NOMEM, "", 0, 0, "sim: out of memory building the rod model");
}

static int add_node(bld* b, vd_vec3 pos, int fixed) {
  if (!vd_grow((void**)&b->node, &b->cap_node, b->nnode + 1, sizeof(bnode))) return -1;
  bnode* n = &b->node[b->nnode];
  memset(n, 0, sizeof *n);
  n->pos = pos;
  n->owner = -1;
  n->root_seg = -1;
  n->fixed = fixed;
  return b->nnode++;
}

// bend parent for a segment starting at rod node n: the segment ending there, else a fixed
// segment starting there (root nodes), else none
static int parent_at(const bld* b, int n) {
  return b->node[n].owner >= 0 ? b->node[n].owner : b->node[n].root_seg;
}

static int add_seg(bld* b, int n0, int n1, int cls, int label, int instance, int plant,
                   double radius, unsigned flags) {
  if (b->nseg >= b->def->max_segments) {
    b->over = 1;
    return -1;
  }
  if (!vd_grow((void**)&b->seg, &b->cap_seg, b->nseg + 1, sizeof(bseg))) return -1;
  int t = b->nseg;
  bseg* s = &b->seg[t];
  memset(s, 0, sizeof *s);
  s->n0 = n0, s->n1 = n1, s->cls = cls, s->label = label, s->instance = instance;
  s->plant = plant, s->radius = radius > 1e-5 ? radius : 1e-5, s->flags = flags;
  s->parent = parent_at(b, n0);
  b->node[n1].owner = t;
  if ((flags & VD_SIM_FIXED) && b->node[n0].owner < 0 && b->node[n0].root_seg < 0) b->node[n0].root_seg = t;
  return b->nseg++;
}

static int add_pend(bld* b, int item, int seg) {
  if (!vd_grow((void**)&b->pnode, &b->cap_pnode, b->npnode + 1, sizeof(pend))) return 0;
  b->pnode[b->npnode].item = item;
  b->pnode[b->npnode].seg = seg;
  b->npnode++;
  return 1;
}

static vd_vec3 pnode(const vd_model* p, int i) {
  return vd_v3(p->node_pos0[3 * i], p->node_pos0[3 * i + 1], p->node_pos0[3 * i + 2]);
}

static vd_organ label_organ(const vd_model* p, int label) {
  const vd_label* l = vd_model_find_label(p, label);
  return l ? l->organ : VD_ORGAN_OTHER;
}

// material class of a plant segment: organ kind, with wood told apart by the label's name
static int class_of(const vd_model* p, int label) {
  const vd_label* l = vd_model_find_label(p, label);
  vd_organ o = l ? l->organ : VD_ORGAN_OTHER;
  switch (o) {
    case VD_ORGAN_PEDICEL: return VD_SIM_PEDICEL;
    case VD_ORGAN_LEAF: return VD_SIM_LEAF;
    case VD_ORGAN_FRUIT: return VD_SIM_FRUIT;
    case VD_ORGAN_FLOWER: return VD_SIM_FLOWER;
    case VD_ORGAN_ROOT: return VD_SIM_ROOT;
    case VD_ORGAN_STEM: {
      static const char* wood[] = {"trunk", "branch", "wood", "twig", "bole", "limb"};
      for (size_t k = 0; k < sizeof wood / sizeof wood[0]; k++)
        if (strstr(l->name, wood[k])) return VD_SIM_WOOD;
      return VD_SIM_GREEN;
    }
    default: return VD_SIM_GREEN;
  }
}

// ---------------------------------------------------------------------------------------------
// validation of the settings

static vd_status check_def(const vd_sim_def* d, vd_error* err) {
#define BAD(...) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, __VA_ARGS__)
  if (!(isfinite(d->segment_length) && d->segment_length > 0))
    BAD("sim: segment length must be a number > 0 (m), got %g", d->segment_length);
  if (!(isfinite(d->clamp_length) && d->clamp_length >= 0))
    BAD("sim: clamp length must be a number >= 0 (m), got %g", d->clamp_length);
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++) {
    const vd_sim_material* mt = &d->material[c];
    const char* n = class_names[c];
    if (!(isfinite(mt->young) && mt->young > 0)) BAD("sim: Young's modulus of '%s' must be > 0 (Pa), got %g", n, mt->young);
    if (!(isfinite(mt->poisson) && mt->poisson > -1 && mt->poisson <= 0.5))
      BAD("sim: Poisson ratio of '%s' must be in (-1, 0.5], got %g", n, mt->poisson);
    if (!(isfinite(mt->density) && mt->density > 0)) BAD("sim: density of '%s' must be > 0 (kg/m^3), got %g", n, mt->density);
    if (!(mt->break_force > 0) || !(mt->break_moment > 0) || !(mt->break_cs > 0) || !(mt->break_cb > 0))
      BAD("sim: fracture thresholds of '%s' must be > 0 (or infinite)", n);
    if (!(isfinite(mt->drag_cd) && mt->drag_cd >= 0)) BAD("sim: drag coefficient of '%s' must be >= 0, got %g", n, mt->drag_cd);
  }
  if (!(isfinite(d->leaf_areal_density) && d->leaf_areal_density >= 0))
    BAD("sim: leaf areal density must be >= 0 (kg/m^2), got %g", d->leaf_areal_density);
  if (!(isfinite(d->leaf_vein_ratio) && d->leaf_vein_ratio > 0)) BAD("sim: leaf vein ratio must be > 0, got %g", d->leaf_vein_ratio);
  if (!(isfinite(d->leaf_plate_cd) && d->leaf_plate_cd >= 0)) BAD("sim: leaf drag coefficient must be >= 0");
  if (!(isfinite(d->gravity.x) && isfinite(d->gravity.y) && isfinite(d->gravity.z))) BAD("sim: gravity is not finite");
  if (!(isfinite(d->stake_spacing) && d->stake_spacing >= 0)) BAD("sim: stake spacing must be >= 0 (m), got %g", d->stake_spacing);
  if (!(isfinite(d->stake_stiffness) && d->stake_stiffness > 0)) BAD("sim: stake stiffness must be > 0 (N/m), got %g", d->stake_stiffness);
  if (d->max_segments < 1) BAD("sim: max_segments must be >= 1, got %d", d->max_segments);
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++)
    if (!(isfinite(d->class_segment_length[c]) && d->class_segment_length[c] >= 0))
      BAD("sim: segment length of '%s' must be >= 0 (m; 0: the segment length), got %g", class_names[c],
          d->class_segment_length[c]);
  if (d->leaf_graphs < 0 || d->leaf_graphs > 2) BAD("sim: leaf mode must be 0 (rigid), 1 (graphs) or 2 (midrib)");
  if (!(isfinite(d->active_radius) && d->active_radius >= 0)) BAD("sim: active radius must be >= 0 (m), got %g", d->active_radius);
  if (!(isfinite(d->active_a.x + d->active_a.y + d->active_a.z + d->active_b.x + d->active_b.y + d->active_b.z)))
    BAD("sim: the region of interest is not finite");
  if (d->leaf_segments < 0 || d->leaf_segments > 1000) BAD("sim: leaf segments must be in 0..1000, got %d", d->leaf_segments);
  if (d->bend_measure != VD_SIM_BEND_LOG && d->bend_measure != VD_SIM_BEND_QUAT)
    BAD("sim: unknown bend-twist measure %d", (int)d->bend_measure);
#undef BAD
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// plant analysis: degrees, key nodes, abscission nodes

// plant node a sphere hangs from: its own node, else the end of its parent segment
static int sphere_attach(const vd_model* p, int k) {
  if (p->sphere_node[k] >= 0) return p->sphere_node[k];
  return p->sphere_parent[k] >= 0 ? p->seg_node[2 * p->sphere_parent[k] + 1] : -1;
}

static void find_abscission(bld* b) {
  const vd_model* p = b->p;
  // every terminal pedicel branch: walk up from its tip while the label stays the same and
  // the axis does not branch; the abscission node is the branch's node nearest its middle
  for (int t = 0; t < p->nseg; t++) {
    if (b->pclass[t] != VD_SIM_PEDICEL || b->nout[p->seg_node[2 * t + 1]] != 0) continue;
    int chain[64], k = 0, cur = t;
    while (k < 64) {
      chain[k++] = cur;
      int par = p->seg_parent[cur];
      if (par < 0 || p->seg_label[par] != p->seg_label[t] || p->seg_node[2 * par + 1] != p->seg_node[2 * cur] ||
          b->nout[p->seg_node[2 * cur]] != 1)
        break;
      cur = par;
    }
    // chain[k-1] is the base piece; arc lengths from the base
    double total = 0;
    for (int i = 0; i < k; i++) total += p->seg_len0[chain[i]];
    if (k == 1) {
      b->absc[p->seg_node[2 * chain[0]]] = 1;
      continue;
    }
    double best = 1e300, s = 0;
    int bn = -1;
    for (int i = k - 1; i >= 1; i--) {
      s += p->seg_len0[chain[i]];
      double dd = fabs(s - 0.5 * total);
      if (dd < best - 1e-12) best = dd, bn = p->seg_node[2 * chain[i] + 1];
    }
    if (bn >= 0) b->absc[bn] = 1;
  }
}

static vd_status analyse(bld* b) {
  const vd_model* p = b->p;
  int nn = p->nnode, ns = p->nseg;
  for (int i = 0; i < nn; i++) b->out_seg[i] = b->in_seg[i] = -1;
  for (int t = 0; t < ns; t++) {
    int a = p->seg_node[2 * t], e = p->seg_node[2 * t + 1];
    b->nout[a]++, b->out_seg[a] = t;
    b->nin[e]++, b->in_seg[e] = t;
    b->pclass[t] = class_of(p, p->seg_label[t]);
  }
  find_abscission(b);
  // attachment points of spheres and meshes must be rod nodes
  for (int k = 0; k < p->nsphere; k++) {
    int n = sphere_attach(p, k);
    if (n >= 0) b->key[n] = 1;
  }
  for (int k = 0; k < p->nmesh; k++)
    if (p->mesh_node[k] >= 0) b->key[p->mesh_node[k]] = 1;
  for (int i = 0; i < nn; i++) {
    if (b->absc[i] || b->nin[i] != 1 || b->nout[i] != 1) {
      b->key[i] = 1;
      continue;
    }
    int s = b->in_seg[i], t = b->out_seg[i];
    if (p->seg_parent[t] != s || b->pclass[s] != b->pclass[t]) b->key[i] = 1;
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// chains: resampling between key nodes

// point at arc length a along a polyline (pts, cumulative arc cum), and the index of the piece
static vd_vec3 at_arc(const vd_vec3* pts, const double* cum, int k, double a, int* piece) {
  int i = 0;
  while (i < k - 1 && a > cum[i + 1]) i++;
  double len = cum[i + 1] - cum[i];
  double f = len > 0 ? (a - cum[i]) / len : 0;
  if (f < 0) f = 0;
  if (f > 1) f = 1;
  if (piece) *piece = i;
  return vd_add(pts[i], vd_scale(vd_sub(pts[i + 1], pts[i]), f));
}

// resample arc range [a0, a1] of a chain into rod segments starting at rod node start;
// returns the last rod node (or -1 on failure). The chain's plant segments are segs[0..k-1].
// segment length of material class c (m)
static double sigma_of(const vd_sim_def* d, int c) {
  return c >= 0 && c < VD_SIM_CLASS_COUNT && d->class_segment_length[c] > 0 ? d->class_segment_length[c]
                                                                             : d->segment_length;
}

static int resample(bld* b, const int* segs, const vd_vec3* pts, const double* cum, int k, double a0,
                    double a1, int start, int fixed, int first_flags, int end_node_plant) {
  const vd_model* p = b->p;
  double len = a1 - a0;
  int nrod = (int)floor(len / sigma_of(b->def, b->pclass[segs[0]]) + 0.5);
  if (nrod < 1) nrod = 1;
  if (fixed) nrod = 1;
  int prev = start;
  for (int j = 1; j <= nrod; j++) {
    double aj = j == nrod ? a1 : a0 + len * j / nrod;
    int n;
    if (j == nrod && end_node_plant >= 0 && b->rod_of[end_node_plant] >= 0) {
      n = b->rod_of[end_node_plant];
    } else {
      n = add_node(b, j == nrod && end_node_plant >= 0 ? pnode(p, end_node_plant) : at_arc(pts, cum, k, aj, NULL), fixed);
      if (n < 0) return -1;
    }
    // properties from the plant segment at the middle of the rod segment
    double am = a0 + len * (j - 0.5) / nrod;
    int piece;
    at_arc(pts, cum, k, am, &piece);
    int ps = segs[piece];
    double pl = cum[piece + 1] - cum[piece], f = pl > 0 ? (am - cum[piece]) / pl : 0;
    double r = p->seg_radius[2 * ps] + f * (p->seg_radius[2 * ps + 1] - p->seg_radius[2 * ps]);
    unsigned fl = (fixed ? VD_SIM_FIXED : 0) | (j == 1 ? (unsigned)first_flags : 0);
    int t = add_seg(b, prev, n, b->pclass[ps], p->seg_label[ps], p->seg_instance[ps], ps, r, fl);
    if (t < 0) return -1;
    if (j == nrod && end_node_plant >= 0) b->rod_of[end_node_plant] = n;
    // plant nodes inside this rod segment's arc range and plant segments whose middle it holds
    double lo = a0 + len * (j - 1) / nrod;
    for (int i = 1; i < k; i++)
      if (cum[i] >= lo && (cum[i] < aj || (j == nrod && cum[i] <= aj)) && b->rod_of[p->seg_node[2 * segs[i]]] < 0)
        if (!add_pend(b, p->seg_node[2 * segs[i]], t)) return -1;
    for (int i = 0; i < k; i++) {
      double mid = 0.5 * (cum[i] + cum[i + 1]);
      if (mid >= lo && (mid < aj || j == nrod) && mid >= a0 && mid <= a1 && b->pseg_rod[segs[i]] < 0)
        b->pseg_rod[segs[i]] = t;
    }
    prev = n;
  }
  return prev;
}

static vd_status build_chains(bld* b) {
  const vd_model* p = b->p;
  int ns = p->nseg;
  // breadth-first over the plant's parent forest: parents before children
  int* order = vd_malloc((size_t)(ns ? ns : 1) * sizeof(int));
  int* segs = vd_malloc((size_t)(ns ? ns : 1) * sizeof(int));
  vd_vec3* pts = vd_malloc((size_t)(ns + 1) * sizeof(vd_vec3));
  double* cum = vd_malloc((size_t)(ns + 1) * sizeof(double));
  int* head = vd_malloc((size_t)(ns ? ns : 1) * sizeof(int));
  int* next = vd_malloc((size_t)(ns ? ns : 1) * sizeof(int));
  vd_status st = VD_OK;
  if (!order || !segs || !pts || !cum || !head || !next) {
    st = oom(b);
    goto done;
  }
  {
    for (int t = 0; t < ns; t++) head[t] = -1;
    for (int t = ns - 1; t >= 0; t--) {
      int par = p->seg_parent[t];
      if (par >= 0) next[t] = head[par], head[par] = t;
    }
    int no = 0;
    for (int t = 0; t < ns; t++)
      if (p->seg_parent[t] < 0) order[no++] = t;
    for (int i = 0; i < no; i++)
      for (int c = head[order[i]]; c >= 0; c = next[c]) order[no++] = c;
  }
  for (int oi = 0; oi < ns; oi++) {
    int first = order[oi];
    int n0 = p->seg_node[2 * first], par = p->seg_parent[first];
    // a continuation of its parent's chain is built with that chain
    if (par >= 0 && p->seg_node[2 * par + 1] == n0 && !b->key[n0]) continue;
    // collect the chain up to the next key node
    int k = 0, cur = first;
    pts[0] = pnode(p, n0);
    cum[0] = 0;
    for (;;) {
      segs[k] = cur;
      pts[k + 1] = pnode(p, p->seg_node[2 * cur + 1]);
      cum[k + 1] = cum[k] + vd_norm(vd_sub(pts[k + 1], pts[k]));
      k++;
      int e = p->seg_node[2 * cur + 1];
      if (b->key[e] || k >= ns) break;
      cur = b->out_seg[e];
    }
    int end_plant = p->seg_node[2 * segs[k - 1] + 1];
    double total = cum[k];
    // start rod node: existing, a connector from the parent's end, or a new fixed root node
    int start = b->rod_of[n0];
    int is_root = 0;
    if (start < 0) {
      if (par >= 0 && b->rod_of[p->seg_node[2 * par + 1]] >= 0) {
        int pe = b->rod_of[p->seg_node[2 * par + 1]];
        vd_vec3 x = pnode(p, n0);
        if (vd_norm(vd_sub(x, b->node[pe].pos)) < 1e-9) {
          start = pe;
        } else {
          start = add_node(b, x, 0);
          if (start < 0 || add_seg(b, pe, start, b->pclass[first], p->seg_label[first], p->seg_instance[first], -1,
                                   p->seg_radius[2 * first], VD_SIM_CONNECT) < 0) {
            st = oom(b);
            goto done;
          }
        }
      } else {
        start = add_node(b, pnode(p, n0), 1);
        if (start < 0) {
          st = oom(b);
          goto done;
        }
      }
      b->rod_of[n0] = start;
    }
    is_root = par < 0 && b->node[start].fixed;
    // degenerate chain: its end is its start
    if (total < 1e-9) {
      if (b->rod_of[end_plant] < 0) b->rod_of[end_plant] = start;
      for (int i = 0; i < k; i++) b->pseg_rod[segs[i]] = b->node[start].owner;
      continue;
    }
    int cls = b->pclass[first];
    unsigned first_flags = b->absc[n0] && cls == VD_SIM_PEDICEL ? VD_SIM_ABSCISSION : 0;
    int last;
    if (cls == VD_SIM_ROOT && b->def->clamp_roots && b->node[start].fixed) {
      // roots stay in the soil: every rod segment fixed, for roots at the plant's base and
      // roots branching from a held node (the trunk's pot, another root)
      int nrod = (int)floor(total / sigma_of(b->def, cls) + 0.5);
      if (nrod < 1) nrod = 1;
      last = start;
      for (int j = 0; j < nrod && last >= 0; j++) {
        double a0 = total * j / nrod, a1 = total * (j + 1) / nrod;
        last = resample(b, segs, pts, cum, k, a0, a1, last, 1, 0, j == nrod - 1 ? end_plant : -1);
      }
      b->node[start].fixed = 1;
    } else if (is_root) {
      // the pot: the first clamp_length held, the rest free
      double c = b->def->clamp_length < total ? b->def->clamp_length : total;
      if (c > 0) {
        last = resample(b, segs, pts, cum, k, 0, c, start, 1, 0, c >= total ? end_plant : -1);
        if (last >= 0 && c < total) last = resample(b, segs, pts, cum, k, c, total, last, 0, 0, end_plant);
      } else {
        // no pot: only the root node and its frame held, by a massless fixed segment behind the
        // root along the first one and as long (the mirror image of a clamped end)
        double nrod = floor(total / b->def->segment_length + 0.5), l1 = total / (nrod < 1 ? 1 : nrod);
        int j = 1;
        while (j < k && !(cum[j] > 1e-12)) j++;
        vd_vec3 dir = vd_scale(vd_sub(pts[j], pts[0]), 1.0 / cum[j]);
        int g = add_node(b, vd_sub(b->node[start].pos, vd_scale(dir, l1)), 1);
        int t = g < 0 ? -1 : add_seg(b, g, start, cls, p->seg_label[first], p->seg_instance[first], -1,
                                      p->seg_radius[2 * first], VD_SIM_FIXED);
        if (t >= 0) b->seg[t].ghost = 1;
        last = t < 0 ? -1 : resample(b, segs, pts, cum, k, 0, total, start, 0, 0, end_plant);
      }
    } else {
      last = resample(b, segs, pts, cum, k, 0, total, start, 0, (int)first_flags, end_plant);
    }
    if (last < 0) {
      st = oom(b);
      goto done;
    }
  }
done:
  vd_free(order, (size_t)(ns ? ns : 1) * sizeof(int));
  vd_free(segs, (size_t)(ns ? ns : 1) * sizeof(int));
  vd_free(pts, (size_t)(ns + 1) * sizeof(vd_vec3));
  vd_free(cum, (size_t)(ns + 1) * sizeof(double));
  vd_free(head, (size_t)(ns ? ns : 1) * sizeof(int));
  vd_free(next, (size_t)(ns ? ns : 1) * sizeof(int));
  return st;
}

// ---------------------------------------------------------------------------------------------
// spheres and meshes

static vd_status build_spheres(bld* b) {
  const vd_model* p = b->p;
  for (int k = 0; k < p->nsphere; k++) {
    b->sph_node[k] = b->sph_seg[k] = -1;
    int pn = sphere_attach(p, k);
    if (pn < 0 || b->rod_of[pn] < 0) continue;
    int a = b->rod_of[pn];
    vd_organ o = label_organ(p, p->sphere_label[k]);
    int cls = o == VD_ORGAN_FLOWER ? VD_SIM_FLOWER : VD_SIM_FRUIT;
    double r = p->sphere_radius[k];
    vd_vec3 c = vd_v3(p->sphere_pos0[3 * k], p->sphere_pos0[3 * k + 1], p->sphere_pos0[3 * k + 2]);
    double mass = b->def->material[cls].density * 4.0 / 3.0 * VD_PI * r * r * r;
    if (vd_norm(vd_sub(c, b->node[a].pos)) < 1e-7) {
      // centred on the node: the node carries the sphere
      b->node[a].mass += mass;
      if (r > b->node[a].sphere) b->node[a].sphere = r;
      b->sph_node[k] = a;
      b->sph_seg[k] = b->node[a].owner;
      continue;
    }
    int n = add_node(b, c, 0);
    if (n < 0) return oom(b);
    b->node[n].mass = mass;
    b->node[n].sphere = r;
    int t = add_seg(b, a, n, cls, p->sphere_label[k], p->sphere_instance[k], -1, r, VD_SIM_FRUITSEG);
    if (t < 0) return oom(b);
    b->seg[t].ib = b->seg[t].it = 0.4 * mass * r * r;
    b->sph_node[k] = n;
    b->sph_seg[k] = t;
  }
  return VD_OK;
}

// distance from p to segment a-b and the parameter of the closest point
static double seg_dist(vd_vec3 a, vd_vec3 b, vd_vec3 p, double* u) {
  vd_vec3 ab = vd_sub(b, a);
  double l2 = vd_dot(ab, ab), t = l2 > 0 ? vd_dot(vd_sub(p, a), ab) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  *u = t;
  return vd_norm(vd_sub(p, vd_add(a, vd_scale(ab, t))));
}

// a chain of nseg rod segments from rod node a straight to point e; returns the end node
static int straight(bld* b, int a, vd_vec3 e, int nrod, double r0, double r1, int label, int inst, int* first) {
  vd_vec3 s = b->node[a].pos;
  int prev = a;
  for (int j = 1; j <= nrod; j++) {
    int n = add_node(b, vd_add(s, vd_scale(vd_sub(e, s), (double)j / nrod)), 0);
    if (n < 0) return -1;
    double r = r0 + (r1 - r0) * (j - 0.5) / nrod;
    int t = add_seg(b, prev, n, VD_SIM_LEAF, label, inst, -1, r, VD_SIM_LEAFSEG);
    if (t < 0) return -1;
    if (j == 1 && first) *first = t;
    prev = n;
  }
  return prev;
}

// segments of a leaf vein of length len
static int nsteps(const bld* b, double len) {
  if (b->def->leaf_segments > 0) return b->def->leaf_segments;
  int k = (int)floor(len / sigma_of(b->def, VD_SIM_LEAF) + 0.5);
  return k < 1 ? 1 : k;
}

// leaf mesh -> midrib from the attachment node to the farthest vertex, plus a side vein to the
// widest vertex on each side; lamina mass and area go to the nearest vein segment
static vd_status leaf_graph(bld* b, int k, int* done) {
  const vd_model* p = b->p;
  *done = 0;
  int a = b->rod_of[p->mesh_node[k]];
  int v0 = p->mesh_vert[2 * k], nv = p->mesh_vert[2 * k + 1];
  int t0 = p->mesh_tri[2 * k], nt = p->mesh_tri[2 * k + 1];
  if (nv < 3 || nt < 1) return VD_OK;
  vd_vec3 xa = b->node[a].pos;
#define VP(i) vd_v3(p->vert_pos0[3 * (i)], p->vert_pos0[3 * (i) + 1], p->vert_pos0[3 * (i) + 2])
  int tip = -1;
  double len = 0;
  for (int i = 0; i < nv; i++) {
    double l = vd_norm(vd_sub(VP(v0 + i), xa));
    if (l > len) len = l, tip = v0 + i;
  }
  if (len < 1e-6) return VD_OK;
  vd_vec3 nrm = vd_v3(0, 0, 0);
  for (int i = 0; i < nt; i++) {
    const int* tv = p->tri_vert + 3 * (t0 + i);
    nrm = vd_add(nrm, vd_cross(vd_sub(VP(tv[1]), VP(tv[0])), vd_sub(VP(tv[2]), VP(tv[0]))));
  }
  nrm = vd_normalize(nrm);
  vd_vec3 u = vd_scale(vd_sub(VP(tip), xa), 1.0 / len);
  // midrib radius from the blade length, never thicker than the stalk it grows on
  int par = parent_at(b, a);
  double r0 = b->def->leaf_vein_ratio * len;
  if (par >= 0 && r0 > b->seg[par].radius) r0 = b->seg[par].radius;
  if (r0 < 1e-4) r0 = 1e-4;
  int label = p->mesh_label[k], inst = p->mesh_instance[k];
  int first_seg = b->nseg;
  int km = nsteps(b, len), first;
  int mid0 = b->nnode;  // midrib nodes are mid0 .. mid0 + km - 1 (node j = mid0 + j - 1)
  if (straight(b, a, VP(tip), km, r0, 0.7 * r0, label, inst, &first) < 0) return oom(b);
  // side veins to the widest vertex on each side (not for the midrib alone)
  for (int side = -1; side <= 1 && b->def->leaf_graphs == 1; side += 2) {
    int best = -1;
    double bd = 0.1 * len, btau = 0;
    for (int i = 0; i < nv; i++) {
      vd_vec3 w = vd_sub(VP(v0 + i), xa);
      double tau = vd_dot(w, u);
      vd_vec3 lat = vd_madd(w, u, -tau);
      double dist = vd_norm(lat);
      double sg = vd_dot(vd_cross(u, lat), nrm);
      if ((sg > 0 ? 1 : -1) == side && dist > bd) bd = dist, best = v0 + i, btau = tau / len;
    }
    if (best < 0) continue;
    int j = (int)floor(btau * km + 0.5);
    if (j > km - 1) j = km - 1;
    if (j < 0) j = 0;
    int sn = j == 0 ? a : mid0 + j - 1;
    double rv = 0.7 * r0 * (1 - 0.3 * btau);
    double lv = vd_norm(vd_sub(VP(best), b->node[sn].pos));
    if (lv < 1e-6) continue;
    if (straight(b, sn, VP(best), nsteps(b, lv), rv, 0.7 * rv, label, inst, NULL) < 0) return oom(b);
  }
  // bind vertices to the nearest leaf segment; lamina mass to its nodes, area to the segment
  int last_seg = b->nseg;
  for (int i = 0; i < nv; i++) {
    vd_vec3 x = VP(v0 + i);
    double bdist = 1e300;
    int bs = first_seg;
    for (int t = first_seg; t < last_seg; t++) {
      double uu;
      double dd = seg_dist(b->node[b->seg[t].n0].pos, b->node[b->seg[t].n1].pos, x, &uu);
      if (dd < bdist) bdist = dd, bs = t;
    }
    b->vert_seg[v0 + i] = bs;
  }
  double rho_a = b->def->leaf_areal_density;
  for (int i = 0; i < nt; i++) {
    const int* tv = p->tri_vert + 3 * (t0 + i);
    vd_vec3 cr = vd_cross(vd_sub(VP(tv[1]), VP(tv[0])), vd_sub(VP(tv[2]), VP(tv[0])));
    double area = 0.5 * vd_norm(cr);
    for (int c = 0; c < 3; c++) {
      int t = b->vert_seg[tv[c]];
      double uu;
      seg_dist(b->node[b->seg[t].n0].pos, b->node[b->seg[t].n1].pos, VP(tv[c]), &uu);
      b->node[b->seg[t].n0].mass += rho_a * area / 3 * (1 - uu);
      b->node[b->seg[t].n1].mass += rho_a * area / 3 * uu;
    }
    // the plate's area and normal go to the segment nearest the triangle's centre
    vd_vec3 cen = vd_scale(vd_add(vd_add(VP(tv[0]), VP(tv[1])), VP(tv[2])), 1.0 / 3);
    double bdist = 1e300;
    int bs = first_seg;
    for (int t = first_seg; t < last_seg; t++) {
      double uu;
      double dd = seg_dist(b->node[b->seg[t].n0].pos, b->node[b->seg[t].n1].pos, cen, &uu);
      if (dd < bdist) bdist = dd, bs = t;
    }
    vd_vec3 n = vd_dot(cr, nrm) < 0 ? vd_scale(cr, -0.5) : vd_scale(cr, 0.5);
    b->seg[bs].leafn = vd_add(b->seg[bs].leafn, n);
  }
#undef VP
  (void)first;
  *done = 1;
  return VD_OK;
}

static vd_status build_meshes(bld* b) {
  const vd_model* p = b->p;
  for (int k = 0; k < p->nmesh; k++) {
    int v0 = p->mesh_vert[2 * k], nv = p->mesh_vert[2 * k + 1];
    for (int i = 0; i < nv; i++) b->vert_seg[v0 + i] = -1;
    int pn = p->mesh_node[k];
    int a = pn >= 0 ? b->rod_of[pn] : -1;
    if (a >= 0 && b->def->leaf_graphs && label_organ(p, p->mesh_label[k]) == VD_ORGAN_LEAF) {
      int done;
      vd_status st = leaf_graph(b, k, &done);
      if (st) return st;
      if (done) continue;
    }
    // rigid: the mesh follows the segment ending at its node (or its parent's rod segment)
    int t = a >= 0 ? parent_at(b, a) : (p->mesh_parent[k] >= 0 ? b->pseg_rod[p->mesh_parent[k]] : -1);
    for (int i = 0; i < nv; i++) b->vert_seg[v0 + i] = t;
    if (t < 0) continue;
    double area = 0;
    int t0 = p->mesh_tri[2 * k], nt = p->mesh_tri[2 * k + 1];
    for (int i = 0; i < nt; i++) {
      const int* tv = p->tri_vert + 3 * (t0 + i);
      vd_vec3 q0 = vd_v3(p->vert_pos0[3 * tv[0]], p->vert_pos0[3 * tv[0] + 1], p->vert_pos0[3 * tv[0] + 2]);
      vd_vec3 q1 = vd_v3(p->vert_pos0[3 * tv[1]], p->vert_pos0[3 * tv[1] + 1], p->vert_pos0[3 * tv[1] + 2]);
      vd_vec3 q2 = vd_v3(p->vert_pos0[3 * tv[2]], p->vert_pos0[3 * tv[2] + 1], p->vert_pos0[3 * tv[2] + 2]);
      area += 0.5 * vd_norm(vd_cross(vd_sub(q1, q0), vd_sub(q2, q0)));
    }
    b->node[a >= 0 ? a : b->seg[t].n1].mass += b->def->leaf_areal_density * area;
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// main axis and stake ties

static int main_axis_tip(const bld* b) {
  const vd_model* p = b->p;
  int root = -1;
  for (int t = 0; t < p->nseg && root < 0; t++)
    if (p->seg_parent[t] < 0 && b->pclass[t] != VD_SIM_ROOT) root = t;
  if (root < 0) return -1;
  int cur = root, axis = p->seg_axis[root];
  for (;;) {
    int nxt = -1;
    for (int t = cur + 1; t < p->nseg && nxt < 0; t++)
      if (p->seg_parent[t] == cur && p->seg_axis[t] == axis) nxt = t;
    if (nxt < 0) break;
    cur = nxt;
  }
  return b->rod_of[p->seg_node[2 * cur + 1]];
}

static vd_status stake_ties(bld* b, int tip) {
  double sp = b->def->stake_spacing;
  if (sp <= 0 || tip < 0) return VD_OK;
  // nodes from the tip down to a fixed node
  int* path = vd_malloc((size_t)b->nnode * sizeof(int));
  if (!path) return oom(b);
  int np = 0, n = tip;
  while (n >= 0 && !b->node[n].fixed && np < b->nnode) {
    path[np++] = n;
    int o = b->node[n].owner;
    n = o >= 0 ? b->seg[o].n0 : -1;
  }
  vd_status st = VD_OK;
  if (n < 0) np = 0;
  // arc length from the base, tie the first node past every multiple of the spacing
  double arc = 0, next = sp;
  vd_vec3 prev = np ? b->node[n].pos : vd_v3(0, 0, 0);
  for (int i = np - 1; i >= 0; i--) {
    int k = path[i];
    arc += vd_norm(vd_sub(b->node[k].pos, prev));
    prev = b->node[k].pos;
    if (arc + 1e-12 >= next) {
      if (!vd_grow((void**)&b->tie_node, &b->cap_tie, b->ntie + 1, sizeof(int))) {
        st = oom(b);
        break;
      }
      b->tie_node[b->ntie++] = k;
      while (next <= arc + 1e-12) next += sp;
    }
  }
  vd_free(path, (size_t)b->nnode * sizeof(int));
  return st;
}

// ---------------------------------------------------------------------------------------------
// packing into the single-block model

static size_t take(size_t* top, size_t bytes) {
  size_t o = (*top + 15) & ~(size_t)15;
  *top = o + bytes;
  return o;
}

static vd_status pack(bld* b, vd_sim_model** out) {
  const vd_model* p = b->p;
  const vd_sim_def* def = b->def;
  int nn = b->nnode, ns = b->nseg;
  // spares: one per breakable, movable segment
  int nspare = 0;
  double (*brk)[4] = vd_malloc((size_t)(ns ? ns : 1) * sizeof *brk);
  if (!brk) return oom(b);
  for (int t = 0; t < ns; t++) {
    const bseg* s = &b->seg[t];
    const vd_sim_material* mt = &def->material[s->cls];
    int on = !(s->flags & VD_SIM_FIXED) && (s->cls != VD_SIM_PEDICEL || (s->flags & VD_SIM_ABSCISSION));
    brk[t][0] = on ? mt->break_force : INFINITY;
    brk[t][1] = on ? mt->break_moment : INFINITY;
    brk[t][2] = on ? mt->break_cs : INFINITY;
    brk[t][3] = on ? mt->break_cb : INFINITY;
    if (isfinite(brk[t][0]) || isfinite(brk[t][1]) || isfinite(brk[t][2]) || isfinite(brk[t][3])) nspare++;
  }
  int na = nn + nspare, nt = b->ntie;
  size_t D = sizeof(double), I = sizeof(int), V = sizeof(vd_vec3), Q = sizeof(vd_quat);
  size_t top = 0;
  size_t o_m = take(&top, sizeof(vd_sim_model));
  size_t o_np = take(&top, na * V), o_nm = take(&top, na * D), o_nr = take(&top, na * D);
  size_t o_no = take(&top, na * I), o_nf = take(&top, na * I), o_nsph = take(&top, na * D);
  size_t o_sn = take(&top, ns * 2 * I), o_sp = take(&top, ns * I), o_sf = take(&top, ns * sizeof(unsigned));
  size_t o_sc = take(&top, ns * I), o_sl = take(&top, ns * I), o_si = take(&top, ns * I);
  size_t o_spl = take(&top, ns * I), o_ssp = take(&top, ns * I), o_so = take(&top, ns * I);
  size_t o_len = take(&top, ns * D), o_rad = take(&top, ns * D), o_mass = take(&top, ns * D);
  size_t o_q0 = take(&top, ns * Q), o_rest = take(&top, ns * Q), o_lbar = take(&top, ns * D);
  size_t o_cs = take(&top, ns * 3 * D), o_cb = take(&top, ns * 3 * D), o_in = take(&top, ns * 2 * D);
  size_t o_brk = take(&top, ns * 4 * D), o_cd = take(&top, ns * D), o_ln = take(&top, ns * 3 * D);
  size_t o_tn = take(&top, nt * I), o_ta = take(&top, nt * V), o_tc = take(&top, nt * D);
  size_t o_bns = take(&top, p->nnode * I), o_bnr = take(&top, p->nnode * I), o_bnl = take(&top, p->nnode * V);
  size_t o_bss = take(&top, p->nseg * I), o_bsl = take(&top, p->nseg * Q);
  size_t o_bpn = take(&top, p->nsphere * I), o_bps = take(&top, p->nsphere * I);
  size_t o_bvs = take(&top, p->nvert * I), o_bvl = take(&top, p->nvert * V);
  char* block = vd_calloc(1, top);
  if (!block) {
    vd_free(brk, (size_t)(ns ? ns : 1) * sizeof *brk);
    return oom(b);
  }
  vd_sim_model* m = (vd_sim_model*)(block + o_m);
  m->nbytes = top;
  m->nnode = nn, m->nseg = ns, m->nspare = nspare, m->nnode_all = na, m->ntie = nt;
  m->nbind_node = p->nnode, m->nbind_seg = p->nseg, m->nbind_sphere = p->nsphere, m->nbind_vert = p->nvert;
  m->opt = vd_sim_opt_default();
  m->opt.gravity = def->gravity;
  m->leaf_cd = def->leaf_plate_cd;
#define P(f, o) m->f = (void*)(block + (o))
  P(node_pos0, o_np), P(node_mass, o_nm), P(node_radius, o_nr), P(node_owner, o_no), P(node_fixed, o_nf);
  P(node_sphere, o_nsph), P(seg_node, o_sn), P(seg_parent, o_sp), P(seg_flags, o_sf), P(seg_class, o_sc);
  P(seg_label, o_sl), P(seg_instance, o_si), P(seg_plant, o_spl), P(seg_spare, o_ssp), P(seg_order, o_so);
  P(seg_len0, o_len), P(seg_radius, o_rad), P(seg_mass, o_mass), P(seg_quat0, o_q0), P(seg_rest, o_rest);
  P(seg_lbar, o_lbar), P(seg_cs, o_cs), P(seg_cb, o_cb), P(seg_inertia, o_in), P(seg_break, o_brk);
  P(seg_cd, o_cd), P(seg_leaf_normal, o_ln), P(tie_node, o_tn), P(tie_anchor, o_ta), P(tie_compliance, o_tc);
  P(bind_node_seg, o_bns), P(bind_node_ref, o_bnr), P(bind_node_local, o_bnl), P(bind_seg_seg, o_bss);
  P(bind_seg_local, o_bsl), P(bind_sphere_node, o_bpn), P(bind_sphere_seg, o_bps), P(bind_vert_seg, o_bvs);
  P(bind_vert_local, o_bvl);
#undef P
  // nodes
  for (int i = 0; i < nn; i++) {
    m->node_pos0[i] = b->node[i].pos;
    m->node_owner[i] = b->node[i].owner;
    m->node_fixed[i] = b->node[i].fixed;
    m->node_sphere[i] = b->node[i].sphere;
    m->node_mass[i] = b->node[i].mass;
    m->node_radius[i] = b->node[i].sphere;
  }
  for (int i = nn; i < na; i++) m->node_owner[i] = -1;
  // segments: geometry, materials, lumped masses
  for (int t = 0; t < ns; t++) {
    const bseg* s = &b->seg[t];
    const vd_sim_material* mt = &def->material[s->cls];
    m->seg_node[2 * t] = s->n0, m->seg_node[2 * t + 1] = s->n1;
    m->seg_parent[t] = s->parent, m->seg_flags[t] = s->flags, m->seg_class[t] = s->cls;
    m->seg_label[t] = s->label, m->seg_instance[t] = s->instance, m->seg_plant[t] = s->plant;
    m->seg_radius[t] = s->radius, m->seg_cd[t] = mt->drag_cd;
    double l = vd_norm(vd_sub(b->node[s->n1].pos, b->node[s->n0].pos));
    m->seg_len0[t] = l > 1e-12 ? l : 1e-12;
    double r = s->radius, area = VD_PI * r * r;
    double mass = (s->flags & VD_SIM_FRUITSEG) || s->ghost ? 0.0 : mt->density * area * m->seg_len0[t];
    m->seg_mass[t] = mass;
    m->node_mass[s->n0] += 0.5 * mass;
    m->node_mass[s->n1] += 0.5 * mass;
    double ib = (s->flags & VD_SIM_FRUITSEG) ? s->ib : 0.25 * mass * r * r;
    double it = (s->flags & VD_SIM_FRUITSEG) ? s->it : 0.5 * mass * r * r;
    m->seg_inertia[2 * t] = ib > 1e-16 ? ib : 1e-16;
    m->seg_inertia[2 * t + 1] = it > 1e-16 ? it : 1e-16;
    if (!(s->flags & VD_SIM_FRUITSEG)) {
      if (r > m->node_radius[s->n0]) m->node_radius[s->n0] = r;
      if (r > m->node_radius[s->n1]) m->node_radius[s->n1] = r;
    }
    memcpy(m->seg_break + 4 * t, brk[t], sizeof brk[t]);
  }
  for (int i = 0; i < nn; i++) {
    if (!m->node_fixed[i] && m->node_mass[i] < 1e-9) m->node_mass[i] = 1e-9;
    m->total_mass += m->node_mass[i];
  }
  vd_free(brk, (size_t)(ns ? ns : 1) * sizeof *brk);
  // spares
  int ks = 0;
  for (int t = 0; t < ns; t++) {
    const double* bk = m->seg_break + 4 * t;
    m->seg_spare[t] = isfinite(bk[0]) || isfinite(bk[1]) || isfinite(bk[2]) || isfinite(bk[3]) ? nn + ks++ : -1;
  }
  // order: breadth-first from the roots over bend parents, then reversed (children first)
  {
    int* head = vd_malloc((size_t)(ns ? ns : 1) * sizeof(int));
    int* nxt = vd_malloc((size_t)(ns ? ns : 1) * sizeof(int));
    if (!head || !nxt) {
      vd_free(head, (size_t)(ns ? ns : 1) * sizeof(int));
      vd_free(nxt, (size_t)(ns ? ns : 1) * sizeof(int));
      vd_free(block, top);
      return oom(b);
    }
    for (int t = 0; t < ns; t++) head[t] = -1;
    for (int t = ns - 1; t >= 0; t--)
      if (m->seg_parent[t] >= 0) nxt[t] = head[m->seg_parent[t]], head[m->seg_parent[t]] = t;
    int no = 0;
    for (int t = 0; t < ns; t++)
      if (m->seg_parent[t] < 0) m->seg_order[no++] = t;
    for (int i = 0; i < no; i++)
      for (int c = head[m->seg_order[i]]; c >= 0; c = nxt[c]) m->seg_order[no++] = c;
    vd_free(head, (size_t)(ns ? ns : 1) * sizeof(int));
    vd_free(nxt, (size_t)(ns ? ns : 1) * sizeof(int));
    // rest frames by parallel transport from the parent (parents come first in this order)
    for (int i = 0; i < ns; i++) {
      int t = m->seg_order[i];
      vd_vec3 d3 = vd_normalize(vd_sub(m->node_pos0[m->seg_node[2 * t + 1]], m->node_pos0[m->seg_node[2 * t]]));
      int par = m->seg_parent[t];
      vd_quat q;
      if (par >= 0) {
        q = vd_quat_mul(quat_between(quat_d3(m->seg_quat0[par]), d3), m->seg_quat0[par]);
      } else if (m->seg_plant[t] >= 0) {
        const double* pq = p->seg_quat0 + 4 * m->seg_plant[t];
        vd_quat qp = {pq[0], pq[1], pq[2], pq[3]};
        q = vd_quat_mul(quat_between(quat_d3(qp), d3), qp);
      } else {
        q = quat_between(vd_v3(0, 0, 1), d3);
      }
      m->seg_quat0[t] = q_normalize(q);
    }
    // reverse: children before parents
    for (int i = 0, j = ns - 1; i < j; i++, j--) {
      int tmp = m->seg_order[i];
      m->seg_order[i] = m->seg_order[j];
      m->seg_order[j] = tmp;
    }
  }
  // compliances: stretch-shear of the segment, bend-twist of the joint with its parent; the
  // joint's flexibility is that of the two half segments beside it (a fixed half is rigid).
  // With the log measure a junction (a segment with two or more children) lumps its upper half
  // into its own lower joint instead of into each child's: the upper half carries the sum of
  // its children's moments, so giving each child joint that half leaves out the others' moments
  // (an error of first order in sigma); the moment along the segment changes by O(l), so moving
  // the half down one joint is second order (docs/validation.md, discretisation)
  m->bend_measure = def->bend_measure;
  int* nkid = vd_calloc((size_t)ns + 1, sizeof(int));  // bend children of each segment
  if (!nkid) {
    vd_free(block, top);
    return oom(b);
  }
  for (int t = 0; t < ns; t++)
    if (m->seg_parent[t] >= 0) nkid[m->seg_parent[t]]++;
  // junction_down[t]: segment t's upper half goes into its own lower joint
#define JUNCTION_DOWN(t) (def->bend_measure == VD_SIM_BEND_LOG && nkid[t] >= 2 && m->seg_parent[t] >= 0)
  for (int t = 0; t < ns; t++) {
    const vd_sim_material* mt = &def->material[m->seg_class[t]];
    double e = mt->young, nu = mt->poisson, g = e / (2 * (1 + nu)), r = m->seg_radius[t];
    double a = VD_PI * r * r, in = 0.25 * VD_PI * r * r * r * r, kap = 6 * (1 + nu) / (7 + 6 * nu);
    double l = m->seg_len0[t];
    m->seg_cs[3 * t] = m->seg_cs[3 * t + 1] = 1.0 / (l * kap * g * a);
    m->seg_cs[3 * t + 2] = 1.0 / (l * e * a);
    int par = m->seg_parent[t];
    double fb = 0.5 * l / (e * in), ft = 0.5 * l / (g * 2 * in), lbar = l;
    if (JUNCTION_DOWN(t)) fb *= 2, ft *= 2;
    if (par >= 0) {
      const vd_sim_material* mp = &def->material[m->seg_class[par]];
      double ep = mp->young, gp = ep / (2 * (1 + mp->poisson)), rp = m->seg_radius[par];
      double ip = 0.25 * VD_PI * rp * rp * rp * rp, lp = m->seg_len0[par];
      if (!(m->seg_flags[par] & VD_SIM_FIXED) && !JUNCTION_DOWN(par))
        fb += 0.5 * lp / (ep * ip), ft += 0.5 * lp / (gp * 2 * ip);
      lbar = 0.5 * (l + lp);
      vd_quat qr = vd_quat_mul(vd_quat_conj(m->seg_quat0[par]), m->seg_quat0[t]);
      if (qr.w < 0) qr.w = -qr.w, qr.x = -qr.x, qr.y = -qr.y, qr.z = -qr.z;
      m->seg_rest[t] = q_normalize(qr);
    } else {
      m->seg_rest[t] = vd_quat_identity();
    }
    m->seg_lbar[t] = lbar;
    m->seg_cb[3 * t] = m->seg_cb[3 * t + 1] = fb / (lbar * lbar);
    m->seg_cb[3 * t + 2] = ft / (lbar * lbar);
    // lamina normal into the segment frame
    vd_vec3 ln = vd_quat_rotate(vd_quat_conj(m->seg_quat0[t]), b->seg[t].leafn);
    m->seg_leaf_normal[3 * t] = ln.x, m->seg_leaf_normal[3 * t + 1] = ln.y, m->seg_leaf_normal[3 * t + 2] = ln.z;
  }
#undef JUNCTION_DOWN
  vd_free(nkid, ((size_t)ns + 1) * sizeof(int));
  // ties
  for (int k = 0; k < nt; k++) {
    m->tie_node[k] = b->tie_node[k];
    m->tie_anchor[k] = m->node_pos0[b->tie_node[k]];
    m->tie_compliance[k] = 1.0 / def->stake_stiffness;
  }
  // bindings
  for (int i = 0; i < p->nnode; i++) {
    m->bind_node_seg[i] = -1;
    m->bind_node_ref[i] = b->rod_of[i];
  }
  for (int k = 0; k < b->npnode; k++) {
    int i = b->pnode[k].item, t = b->pnode[k].seg;
    if (b->rod_of[i] >= 0) continue;
    m->bind_node_seg[i] = t;
    vd_vec3 off = vd_sub(pnode(p, i), m->node_pos0[m->seg_node[2 * t]]);
    m->bind_node_local[i] = vd_quat_rotate(vd_quat_conj(m->seg_quat0[t]), off);
  }
  for (int j = 0; j < p->nseg; j++) {
    int t = b->pseg_rod[j];
    m->bind_seg_seg[j] = t;
    if (t < 0) continue;
    const double* pq = p->seg_quat0 + 4 * j;
    vd_quat qp = {pq[0], pq[1], pq[2], pq[3]};
    m->bind_seg_local[j] = vd_quat_mul(vd_quat_conj(m->seg_quat0[t]), qp);
  }
  for (int k = 0; k < p->nsphere; k++) m->bind_sphere_node[k] = b->sph_node[k], m->bind_sphere_seg[k] = b->sph_seg[k];
  for (int v = 0; v < p->nvert; v++) {
    int t = b->vert_seg[v];
    m->bind_vert_seg[v] = t;
    if (t < 0) continue;
    vd_vec3 x = vd_v3(p->vert_pos0[3 * v], p->vert_pos0[3 * v + 1], p->vert_pos0[3 * v + 2]);
    m->bind_vert_local[v] = vd_quat_rotate(vd_quat_conj(m->seg_quat0[t]), vd_sub(x, m->node_pos0[m->seg_node[2 * t]]));
  }
  *out = m;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------

static void bld_free(bld* b) {
  const vd_model* p = b->p;
  vd_free(b->node, (size_t)b->cap_node * sizeof(bnode));
  vd_free(b->seg, (size_t)b->cap_seg * sizeof(bseg));
  vd_free(b->pnode, (size_t)b->cap_pnode * sizeof(pend));
  vd_free(b->tie_node, (size_t)b->cap_tie * sizeof(int));
  size_t nn = (size_t)p->nnode + 1, ns = (size_t)p->nseg + 1;
  vd_free(b->rod_of, nn * sizeof(int));
  vd_free(b->out_seg, nn * sizeof(int));
  vd_free(b->in_seg, nn * sizeof(int));
  vd_free(b->nout, nn * sizeof(int));
  vd_free(b->nin, nn * sizeof(int));
  vd_free(b->key, nn);
  vd_free(b->absc, nn);
  vd_free(b->pseg_rod, ns * sizeof(int));
  vd_free(b->pclass, ns * sizeof(int));
  vd_free(b->sph_node, ((size_t)p->nsphere + 1) * sizeof(int));
  vd_free(b->sph_seg, ((size_t)p->nsphere + 1) * sizeof(int));
  vd_free(b->vert_seg, ((size_t)p->nvert + 1) * sizeof(int));
}

// region of interest: segments with no node within active_radius of the region's axis are held
// (fixed) with their end nodes, after everything else is built (sag-free and the compliances
// are those of the whole plant: a simulated segment next to a held one keeps the joint's full
// flexibility, and the held part is where the whole plant's equilibrium puts it)
static void hold_outside(vd_sim_model* m, const vd_sim_def* def) {
  vd_vec3 a = def->active_a, ab = vd_sub(def->active_b, def->active_a);
  double l2 = vd_dot(ab, ab), r = def->active_radius;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    int inside = 0;
    for (int e = 0; e < 2; e++) {
      vd_vec3 x = m->node_pos0[m->seg_node[2 * t + e]];
      double u = l2 > 0 ? vd_dot(vd_sub(x, a), ab) / l2 : 0;
      u = u < 0 ? 0 : u > 1 ? 1 : u;
      inside |= vd_norm(vd_sub(x, vd_madd(a, ab, u))) <= r;
    }
    if (inside) continue;
    m->seg_flags[t] |= VD_SIM_FIXED | VD_SIM_HELD;
    m->node_fixed[m->seg_node[2 * t + 1]] = 1;
    m->nheld++;
  }
}

vd_status vd_sim_build(const vd_model* plant, const vd_sim_def* def, vd_sim_model** out, vd_error* err) {
  *out = NULL;
  VD_ASSERT(plant && def);
  vd_status st = check_def(def, err);
  if (st) return st;
  // the axes alone, resampled, must fit the segment limit: say so before building anything
  double axes = 0;
  for (int t = 0; t < plant->nseg; t++) axes += plant->seg_len0[t];
  double smin = def->segment_length;
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++)
    if (def->class_segment_length[c] > 0 && def->class_segment_length[c] < smin) smin = def->class_segment_length[c];
  if (axes / smin > def->max_segments)
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                        "sim: %.4g m of axes at a segment length of %g m make about %.3g rod segments, more than "
                        "the limit of %d; use a longer segment length or raise the segment limit",
                        axes, smin, axes / smin, def->max_segments);
  bld b;
  memset(&b, 0, sizeof b);
  b.p = plant, b.def = def, b.err = err;
  size_t nn = (size_t)plant->nnode + 1, ns = (size_t)plant->nseg + 1;
  b.rod_of = vd_malloc(nn * sizeof(int));
  b.out_seg = vd_malloc(nn * sizeof(int));
  b.in_seg = vd_malloc(nn * sizeof(int));
  b.nout = vd_calloc(nn, sizeof(int));
  b.nin = vd_calloc(nn, sizeof(int));
  b.key = vd_calloc(nn, 1);
  b.absc = vd_calloc(nn, 1);
  b.pseg_rod = vd_malloc(ns * sizeof(int));
  b.pclass = vd_malloc(ns * sizeof(int));
  b.sph_node = vd_malloc(((size_t)plant->nsphere + 1) * sizeof(int));
  b.sph_seg = vd_malloc(((size_t)plant->nsphere + 1) * sizeof(int));
  b.vert_seg = vd_malloc(((size_t)plant->nvert + 1) * sizeof(int));
  if (!b.rod_of || !b.out_seg || !b.in_seg || !b.nout || !b.nin || !b.key || !b.absc || !b.pseg_rod || !b.pclass ||
      !b.sph_node || !b.sph_seg || !b.vert_seg) {
    st = oom(&b);
    goto done;
  }
  for (int i = 0; i < plant->nnode; i++) b.rod_of[i] = -1;
  for (int i = 0; i < plant->nseg; i++) b.pseg_rod[i] = -1;
  for (int i = 0; i < plant->nvert; i++) b.vert_seg[i] = -1;
  if ((st = analyse(&b)) || (st = build_chains(&b)) || (st = build_spheres(&b)) || (st = build_meshes(&b))) goto done;
  if (b.nseg == 0) {
    st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "sim: the plant has no segments to simulate");
    goto done;
  }
  int tip = main_axis_tip(&b);
  if ((st = stake_ties(&b, tip))) goto done;
  vd_sim_model* m = NULL;
  if ((st = pack(&b, &m))) goto done;
  m->main_tip = tip;
  if (def->sag_free) m->nsagfree_clamped = sim_sagfree(m, def->gravity);
  if (m->nsagfree_clamped < 0) {
    vd_sim_model_destroy(m);
    st = oom(&b);
    goto done;
  }
  if (def->active_radius > 0) hold_outside(m, def);
  *out = m;
done:
  bld_free(&b);
  return st;
}

void vd_sim_model_destroy(vd_sim_model* m) {
  if (m) vd_free(m, m->nbytes);
}
