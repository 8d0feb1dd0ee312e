// SPDX-License-Identifier: MIT
// Bounding volume hierarchy: a binned surface-area-heuristic build (Wald 2007, "On fast
// construction of SAH-based bounding volume hierarchies") into a flat node array, and ray casts
// on triangle BVHs (Möller & Trumbore 1997 ray-triangle test). The build is sequential and
// breaks every tie by position, so one input always gives one tree.
#include <math.h>
#include <string.h>

#include "geom_internal.h"

vd_bvh_def vd_bvh_def_default(void) {
  vd_bvh_def def;
  memset(&def, 0, sizeof def);
  def.leaf_size = 4;
  def.bins = 16;
  return def;
}

// ---------------------------------------------------------------------------------------------
// build

#define MAX_BINS 64

typedef struct bin {
  double lo[3], hi[3];
  int count;
} bin;

// an item being sorted into the tree: its box and centroid move with it, so every pass over a
// node's range reads memory in order
typedef struct bitem {
  double lo[3], hi[3], c[3];
  int id;
} bitem;

typedef struct builder {
  bitem* it;         // items, partitioned in place (n)
  vd_bvh_node* node; // output nodes
  int nnode;
  vd_bvh_def def;
} builder;

static void box_empty(double lo[3], double hi[3]) {
  for (int k = 0; k < 3; k++)
    lo[k] = INFINITY, hi[k] = -INFINITY;
}
// grow [lo, hi] by [a, b]; written as selects so the compiler emits minsd/maxsd, not branches
// (random boxes mispredict every other branch)
static inline void box_grow2(double lo[3], double hi[3], const double a[3], const double b[3]) {
  for (int k = 0; k < 3; k++) {
    lo[k] = a[k] < lo[k] ? a[k] : lo[k];
    hi[k] = b[k] > hi[k] ? b[k] : hi[k];
  }
}
// half the surface area of a box; 0 for an empty box
static double half_area(const double lo[3], const double hi[3]) {
  double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  if (!(dx >= 0) || !(dy >= 0) || !(dz >= 0)) return 0;
  return dx * dy + dy * dz + dz * dx;
}

static inline int bin_of(double c, double cmin, double scale, int nbin) {
  int b = (int)((c - cmin) * scale);
  return b < 0 ? 0 : b >= nbin ? nbin - 1 : b;
}

// best SAH plane of the range over all three axes, binned in one pass: sets *axis and *plane
// (items with bin < plane go left); returns 0 when every centroid is the same point
static int best_split(const builder* bd, int start, int count, const double cmin[3],
                      const double cmax[3], int* axis, int* plane) {
  int nbin = bd->def.bins;
  bin bins[3][MAX_BINS];
  double scale[3];
  int live[3];
  for (int a = 0; a < 3; a++) {
    double ext = cmax[a] - cmin[a];
    live[a] = ext > 0;
    scale[a] = live[a] ? nbin / ext : 0;
    for (int b = 0; b < nbin; b++) {
      box_empty(bins[a][b].lo, bins[a][b].hi);
      bins[a][b].count = 0;
    }
  }
  for (int i = start; i < start + count; i++) {
    const bitem* it = &bd->it[i];
    for (int a = 0; a < 3; a++) {
      if (!live[a]) continue;
      bin* b = &bins[a][bin_of(it->c[a], cmin[a], scale[a], nbin)];
      b->count++;  // NOLINT(clang-analyzer-core.uninitialized.Assign): nbin is in 2..MAX_BINS (vd_bvh_build checks)
      box_grow2(b->lo, b->hi, it->lo, it->hi);
    }
  }
  double best = INFINITY;
  int found = 0;
  for (int a = 0; a < 3; a++) {
    if (!live[a]) continue;
    // sweep from the right, then from the left, costing each plane
    double right_area[MAX_BINS];
    int right_count[MAX_BINS];
    double lo[3], hi[3];
    box_empty(lo, hi);
    int cnt = 0;
    for (int b = nbin - 1; b > 0; b--) {
      if (bins[a][b].count) box_grow2(lo, hi, bins[a][b].lo, bins[a][b].hi);  // NOLINT(clang-analyzer-core.uninitialized.Branch): nbin is in 2..MAX_BINS (vd_bvh_build checks)
      cnt += bins[a][b].count;
      right_area[b] = half_area(lo, hi);
      right_count[b] = cnt;
    }
    box_empty(lo, hi);
    cnt = 0;
    for (int b = 1; b < nbin; b++) {
      if (bins[a][b - 1].count) box_grow2(lo, hi, bins[a][b - 1].lo, bins[a][b - 1].hi);
      cnt += bins[a][b - 1].count;
      // cppcheck-suppress uninitvar ; right_count[1..nbin-1] is set by the sweep above
      if (cnt == 0 || right_count[b] == 0) continue;
      double cost = cnt * half_area(lo, hi) + right_count[b] * right_area[b];
      if (cost < best) {
        best = cost;
        *axis = a;
        *plane = b;
        found = 1;
      }
    }
  }
  return found;
}

// bounds of a range's boxes and centroids
static void range_bounds(const builder* bd, int start, int count, double lo[3], double hi[3],
                         double cmin[3], double cmax[3]) {
  box_empty(lo, hi);
  box_empty(cmin, cmax);
  for (int i = start; i < start + count; i++) {
    const bitem* it = &bd->it[i];
    box_grow2(lo, hi, it->lo, it->hi);
    box_grow2(cmin, cmax, it->c, it->c);
  }
}

// a pending node: its range and the bounds of its boxes and centroids
typedef struct task {
  int node, start, count;
  double lo[3], hi[3], cmin[3], cmax[3];
} task;

static void build_tree(builder* bd, int n) {
  // explicit stack; children are allocated in pairs and get their bounds while partitioning
  task stack[128];
  int sp = 0;
  bd->nnode = 1;
  task root = {0, 0, n, {0}, {0}, {0}, {0}};
  range_bounds(bd, 0, n, root.lo, root.hi, root.cmin, root.cmax);
  stack[sp++] = root;
  while (sp) {
    task tk = stack[--sp];
    vd_bvh_node* nd = &bd->node[tk.node];
    memcpy(nd->lo, tk.lo, sizeof nd->lo);
    memcpy(nd->hi, tk.hi, sizeof nd->hi);
    int start = tk.start, count = tk.count;
    // small ranges, and a stack about to overflow (never with sane input), become leaves
    if (count <= bd->def.leaf_size || sp >= 126) {
      nd->first = start;
      nd->count = count;
      continue;
    }
    // partition by the best plane, or halve the range when all centroids coincide; the two
    // sides' bounds are gathered on the way
    int axis = 0, plane = 0, mid;
    task l = {0, start, 0, {0}, {0}, {0}, {0}}, r = l;
    box_empty(l.lo, l.hi), box_empty(l.cmin, l.cmax), box_empty(r.lo, r.hi), box_empty(r.cmin, r.cmax);
    int split = best_split(bd, start, count, tk.cmin, tk.cmax, &axis, &plane);
    if (split) {
      double scale = bd->def.bins / (tk.cmax[axis] - tk.cmin[axis]);
      int i = start, j = start + count - 1;
      while (i <= j) {
        bitem* it = &bd->it[i];
        if (bin_of(it->c[axis], tk.cmin[axis], scale, bd->def.bins) < plane) {
          box_grow2(l.lo, l.hi, it->lo, it->hi);
          box_grow2(l.cmin, l.cmax, it->c, it->c);
          i++;
        } else {
          bitem t = *it;
          *it = bd->it[j];
          bd->it[j--] = t;
          box_grow2(r.lo, r.hi, t.lo, t.hi);
          box_grow2(r.cmin, r.cmax, t.c, t.c);
        }
      }
      mid = i;
      split = mid > start && mid < start + count;
    }
    if (!split) {
      mid = start + count / 2;
      range_bounds(bd, start, mid - start, l.lo, l.hi, l.cmin, l.cmax);
      range_bounds(bd, mid, start + count - mid, r.lo, r.hi, r.cmin, r.cmax);
    }
    int left = bd->nnode;
    bd->nnode += 2;
    nd->first = left;
    nd->count = 0;
    l.node = left, l.start = start, l.count = mid - start;
    r.node = left + 1, r.start = mid, r.count = start + count - mid;
    stack[sp++] = r;
    stack[sp++] = l;
  }
}

// allocate the block (nodes, items, triangles) and build from boxes
static vd_status build_common(const double* box, int n, const vd_bvh_def* def, int with_tri,
                              vd_bvh* out, vd_error* err) {
  memset(out, 0, sizeof *out);
  vd_bvh_def d = def ? *def : vd_bvh_def_default();
  if (d.leaf_size < 1 || d.leaf_size > 32)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bvh def: leaf_size must be in 1..32");
  if (d.bins < 2 || d.bins > MAX_BINS)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bvh def: bins must be in 2..%d", MAX_BINS);
  if (n < 0 || n > (1 << 28)) return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "bvh: %d items", n);
  if (n == 0) return VD_OK;
  size_t nnode_max = 2 * (size_t)n - 1;
  size_t nbytes = nnode_max * sizeof(vd_bvh_node) + (with_tri ? (size_t)n * sizeof(vd_bvh_tri) : 0) +
                  (size_t)n * sizeof(int);
  char* block = vd_malloc(nbytes);
  bitem* items = vd_malloc((size_t)n * sizeof(bitem));
  if (!block || !items) {
    vd_free(block, nbytes);
    vd_free(items, (size_t)n * sizeof(bitem));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building a BVH");
  }
  out->nbytes = nbytes;
  out->node = (vd_bvh_node*)block;
  char* p = block + nnode_max * sizeof(vd_bvh_node);
  if (with_tri) {
    out->tri = (vd_bvh_tri*)p;
    p += (size_t)n * sizeof(vd_bvh_tri);
  }
  out->item = (int*)p;
  out->nitem = n;
  for (int i = 0; i < n; i++) {
    bitem* it = &items[i];
    it->id = i;
    for (int k = 0; k < 3; k++) {
      it->lo[k] = box[6 * (size_t)i + k];
      it->hi[k] = box[6 * (size_t)i + 3 + k];
      it->c[k] = 0.5 * (it->lo[k] + it->hi[k]);
    }
  }
  builder bd = {items, out->node, 0, d};
  build_tree(&bd, n);
  out->nnode = bd.nnode;
  for (int i = 0; i < n; i++)
    out->item[i] = items[i].id;
  vd_free(items, (size_t)n * sizeof(bitem));
  return VD_OK;
}

vd_status vd_bvh_build(const double* box, int n, const vd_bvh_def* def, vd_bvh* out,
                       vd_error* err) {
  if (!out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bvh: null output");
  if (n > 0 && !box) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bvh: null boxes");
  return build_common(box, n, def, 0, out, err);
}

vd_status vd_bvh_build_mesh(const vd_mesh* mesh, const unsigned char* one_sided,
                            const vd_bvh_def* def, vd_bvh* out, vd_error* err) {
  if (!out || !mesh) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bvh: null argument");
  memset(out, 0, sizeof *out);
  int n = mesh->ntri;
  if (n <= 0) return VD_OK;
  // triangle boxes, then the tree, then the triangles copied in leaf order
  double* box = vd_malloc((size_t)n * 6 * sizeof(double));
  if (!box) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building a BVH");
  for (int t = 0; t < n; t++) {
    double* b = box + 6 * (size_t)t;
    for (int k = 0; k < 3; k++)
      b[k] = INFINITY, b[3 + k] = -INFINITY;
    for (int c = 0; c < 3; c++) {
      const double* v = mesh->pos + 3 * (size_t)mesh->tri[3 * t + c];
      for (int k = 0; k < 3; k++) {
        if (v[k] < b[k]) b[k] = v[k];
        if (v[k] > b[3 + k]) b[3 + k] = v[k];
      }
    }
  }
  vd_status st = build_common(box, n, def, 1, out, err);
  vd_free(box, (size_t)n * 6 * sizeof(double));
  if (st) return st;
  for (int i = 0; i < n; i++) {
    int t = out->item[i];
    vd_bvh_tri* bt = &out->tri[i];
    const double* a = mesh->pos + 3 * (size_t)mesh->tri[3 * t];
    const double* b = mesh->pos + 3 * (size_t)mesh->tri[3 * t + 1];
    const double* c = mesh->pos + 3 * (size_t)mesh->tri[3 * t + 2];
    for (int k = 0; k < 3; k++) {
      bt->v0[k] = a[k];
      bt->e1[k] = b[k] - a[k];
      bt->e2[k] = c[k] - a[k];
    }
    bt->tri = t;
    bt->label = mesh->tri_label ? mesh->tri_label[t] : 0;
    bt->instance = mesh->tri_instance ? mesh->tri_instance[t] : 0;
    bt->one_sided = one_sided ? one_sided[t] != 0 : 0;
  }
  return VD_OK;
}

void vd_bvh_free(vd_bvh* bvh) {
  if (!bvh) return;
  vd_free(bvh->node, bvh->nbytes);
  memset(bvh, 0, sizeof *bvh);
}

// ---------------------------------------------------------------------------------------------
// ray casting

typedef struct ray {
  double o[3], d[3], inv[3];
} ray;

static ray make_ray(vd_vec3 o, vd_vec3 d) {
  ray r = {{o.x, o.y, o.z}, {d.x, d.y, d.z}, {1.0 / d.x, 1.0 / d.y, 1.0 / d.z}};
  return r;
}

// entry distance of the ray into a node's box within (t0, t1), or -1 when it misses; a NaN from
// a ray starting on a slab plane parallel to it leaves that slab unconstrained
static double slab(const vd_bvh_node* n, const ray* r, double t0, double t1) {
  for (int k = 0; k < 3; k++) {
    double ta = (n->lo[k] - r->o[k]) * r->inv[k], tb = (n->hi[k] - r->o[k]) * r->inv[k];
    if (ta > tb) {
      double s = ta;
      ta = tb;
      tb = s;
    }
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
  }
  return t0 <= t1 ? t0 : -1;
}

// Möller-Trumbore: det > 0 when the ray meets the counter-clockwise side (the outward normal
// e1 x e2 points against the ray)
static int hit_tri(const vd_bvh_tri* tr, const ray* r, double tmin, double tmax, int cull,
                   double* t, double* u, double* v, int* front) {
  const double *d = r->d, *e1 = tr->e1, *e2 = tr->e2;
  double p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                 d[0] * e2[1] - d[1] * e2[0]};
  double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
  if (det == 0 || (cull && tr->one_sided && det < 0)) return 0;
  double inv = 1.0 / det;
  double s[3] = {r->o[0] - tr->v0[0], r->o[1] - tr->v0[1], r->o[2] - tr->v0[2]};
  double uu = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
  if (uu < 0 || uu > 1) return 0;
  double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                 s[0] * e1[1] - s[1] * e1[0]};
  double vv = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
  if (vv < 0 || uu + vv > 1) return 0;
  double tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
  if (!(tt > tmin && tt < tmax)) return 0;
  *t = tt, *u = uu, *v = vv, *front = det > 0;
  return 1;
}

// walk the tree: nearer child first; any = 1 returns at the first hit
static int traverse(const vd_bvh* bvh, const ray* r, double tmin, double tmax, int cull, int skip,
                    int any, vd_hit* hit) {
  if (!bvh || bvh->nnode == 0 || !bvh->tri) return 0;
  int stack[256];
  int sp = 0, found = 0, node = 0;
  double best = tmax;
  if (slab(&bvh->node[0], r, tmin, best) < 0) return 0;
  for (;;) {
    const vd_bvh_node* nd = &bvh->node[node];
    if (nd->count) {
      for (int i = nd->first; i < nd->first + nd->count; i++) {
        const vd_bvh_tri* tr = &bvh->tri[i];
        double t, u, v;
        int front;
        if (tr->tri == skip || !hit_tri(tr, r, tmin, best, cull, &t, &u, &v, &front)) continue;
        found = 1;
        best = t;
        if (hit) {
          hit->t = t, hit->u = u, hit->v = v, hit->front = front;
          hit->tri = tr->tri, hit->label = tr->label, hit->instance = tr->instance;
        }
        if (any) return 1;
      }
    } else {
      int a = nd->first, b = nd->first + 1;
      double ta = slab(&bvh->node[a], r, tmin, best), tb = slab(&bvh->node[b], r, tmin, best);
      if (ta >= 0 && tb >= 0) {
        if (tb < ta) {
          int s = a;
          a = b;
          b = s;
        }
        if (sp < 256) stack[sp++] = b;  // depth is at most ~130 (build_tree)
        node = a;
        continue;
      }
      if (ta >= 0) {
        node = a;
        continue;
      }
      if (tb >= 0) {
        node = b;
        continue;
      }
    }
    // next pending node that can still hold something nearer
    for (;;) {
      if (sp == 0) return found;
      node = stack[--sp];
      if (slab(&bvh->node[node], r, tmin, best) >= 0) break;
    }
  }
}

int vd_bvh_raycast(const vd_bvh* bvh, vd_vec3 o, vd_vec3 dir, double tmin, double tmax, int cull,
                   int skip, vd_hit* hit) {
  ray r = make_ray(o, dir);
  return traverse(bvh, &r, tmin, tmax, cull, skip, 0, hit);
}

int vd_bvh_occluded(const vd_bvh* bvh, vd_vec3 o, vd_vec3 dir, double tmin, double tmax,
                    int skip) {
  ray r = make_ray(o, dir);
  return traverse(bvh, &r, tmin, tmax, 0, skip, 1, NULL);
}

int vd_bvh_overlap(const vd_bvh* bvh, const double lo[3], const double hi[3], int* items, int cap) {
  if (!bvh || bvh->nnode == 0) return 0;
  int stack[256];
  int sp = 0, n = 0;
  stack[sp++] = 0;
  while (sp) {
    const vd_bvh_node* nd = &bvh->node[stack[--sp]];
    if (lo[0] > nd->hi[0] || hi[0] < nd->lo[0] || lo[1] > nd->hi[1] || hi[1] < nd->lo[1] ||
        lo[2] > nd->hi[2] || hi[2] < nd->lo[2])
      continue;
    if (nd->count) {
      for (int i = nd->first; i < nd->first + nd->count; i++, n++)
        if (n < cap) items[n] = bvh->item[i];
    } else if (sp + 2 <= 256) {
      stack[sp++] = nd->first + 1;
      stack[sp++] = nd->first;
    }
  }
  return n;
}
