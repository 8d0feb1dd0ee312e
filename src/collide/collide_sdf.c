// SPDX-License-Identifier: MIT
// Signed distance grids of closed triangle meshes, built once per mesh: exact point-triangle
// distances in a band around the surface with the sign from angle-weighted pseudo-normals
// (Baerentzen & Aanaes 2005, "Signed distance computation using the angle weighted
// pseudonormal"), closest-triangle sweeps for the rest of the grid, and the sign of every node
// outside the band carried over from the band by a flood fill (nodes more than a cell away from
// the surface cannot change sign between neighbours).
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "collide_internal.h"

vd_sdf_def vd_sdf_def_default(void) {
  vd_sdf_def d;
  d.cell = 0.002;
  d.padding = 0.01;
  d.band = 0.006;
  d.full = 1;
  d.max_nodes = (int64_t)1 << 24;
  return d;
}

// ---------------------------------------------------------------------------------------------
// mesh preparation: welding, edges, pseudo-normals

typedef struct mesh {
  int nv, nt;  // welded vertices, kept triangles
  vd_vec3* v;  // welded positions (nv)
  int* t;      // triangles in welded indices (nt x 3)
  vd_vec3* fn; // unit face normal (nt), zero for degenerate triangles
  vd_vec3* vn; // vertex pseudo-normal (nv)
  int* te;     // edge id of edge k (t[k] -> t[k+1]) of each triangle (nt x 3)
  vd_vec3* en; // edge pseudo-normal (ne)
  int ne;
} mesh;

static void mesh_free(mesh* m, int nv_in, int nt_in) {
  vd_free(m->v, (size_t)nv_in * sizeof(vd_vec3));
  vd_free(m->t, (size_t)nt_in * 3 * sizeof(int));
  vd_free(m->fn, (size_t)nt_in * sizeof(vd_vec3));
  vd_free(m->vn, (size_t)nv_in * sizeof(vd_vec3));
  vd_free(m->te, (size_t)nt_in * 3 * sizeof(int));
  vd_free(m->en, (size_t)nt_in * 3 * sizeof(vd_vec3));
  memset(m, 0, sizeof *m);
}

// order of vertices by position, ties by index (qsort with a context through a file-local
// pointer is not allowed: no global state, so the keys carry the position)
typedef struct vkey {
  double x, y, z;
  int i;
} vkey;

static int cmp_vkey(const void* pa, const void* pb) {
  const vkey *a = pa, *b = pb;
  if (a->x != b->x) return a->x < b->x ? -1 : 1;
  if (a->y != b->y) return a->y < b->y ? -1 : 1;
  if (a->z != b->z) return a->z < b->z ? -1 : 1;
  return (a->i > b->i) - (a->i < b->i);
}

// one directed edge of a triangle, keyed by its undirected vertex pair
typedef struct ekey {
  int lo, hi; // vertex pair, lo < hi
  int tri, k; // triangle and edge slot
  int fwd;    // 1 when the triangle runs lo -> hi
} ekey;

static int cmp_ekey(const void* pa, const void* pb) {
  const ekey *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  if (a->tri != b->tri) return a->tri < b->tri ? -1 : 1;
  return (a->k > b->k) - (a->k < b->k);
}

static double angle_between(vd_vec3 a, vd_vec3 b) {
  double na = vd_norm(a), nb = vd_norm(b);
  if (!(na > 0) || !(nb > 0)) return 0;
  double c = vd_dot(a, b) / (na * nb);
  return acos(c < -1 ? -1 : (c > 1 ? 1 : c));
}

static vd_status mesh_make(mesh* m, const double* vert, int nvert, const int* tri, int ntri,
                           vd_error* err) {
  memset(m, 0, sizeof *m);
  const char* oom = "out of memory building a distance grid";
  // check the input
  for (int i = 0; i < nvert; i++)
    for (int k = 0; k < 3; k++)
      if (!isfinite(vert[3 * i + k]))
        return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "sdf: vertex %d is not finite", i);
  for (int i = 0; i < 3 * ntri; i++)
    if (tri[i] < 0 || tri[i] >= nvert)
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                          "sdf: triangle %d: vertex index %d out of range", i / 3, tri[i]);
  m->v = vd_malloc((size_t)nvert * sizeof(vd_vec3));
  m->t = vd_malloc((size_t)ntri * 3 * sizeof(int));
  m->fn = vd_malloc((size_t)ntri * sizeof(vd_vec3));
  m->vn = vd_calloc((size_t)nvert, sizeof(vd_vec3));
  m->te = vd_malloc((size_t)ntri * 3 * sizeof(int));
  m->en = vd_calloc((size_t)ntri * 3, sizeof(vd_vec3));
  vkey* vk = vd_malloc((size_t)nvert * sizeof(vkey));
  int* remap = vd_malloc((size_t)nvert * sizeof(int));
  ekey* ek = vd_malloc((size_t)ntri * 3 * sizeof(ekey));
  vd_status st = VD_OK;
  if (!m->v || !m->t || !m->fn || !m->vn || !m->te || !m->en || !vk || !remap || !ek) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "%s", oom);
    goto done;
  }
  // weld vertices at equal positions: sort by position, one id per run of equal keys
  for (int i = 0; i < nvert; i++)
    vk[i] = (vkey){vert[3 * i], vert[3 * i + 1], vert[3 * i + 2], i};
  qsort(vk, (size_t)nvert, sizeof *vk, cmp_vkey);
  for (int i = 0; i < nvert; i++) {
    if (i == 0 || vk[i].x != vk[i - 1].x || vk[i].y != vk[i - 1].y || vk[i].z != vk[i - 1].z)
      m->v[m->nv++] = vd_v3(vk[i].x, vk[i].y, vk[i].z);
    remap[vk[i].i] = m->nv - 1;
  }
  // triangles in welded ids, collapsed ones dropped (they bound nothing)
  for (int t = 0; t < ntri; t++) {
    int a = remap[tri[3 * t]], b = remap[tri[3 * t + 1]], c = remap[tri[3 * t + 2]];
    if (a == b || b == c || c == a) continue;
    int* o = m->t + 3 * m->nt++;
    o[0] = a, o[1] = b, o[2] = c;
  }
  if (m->nt == 0) {
    st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "sdf: the mesh has no triangles of area > 0");
    goto done;
  }
  // face normals and angle-weighted vertex normals
  for (int t = 0; t < m->nt; t++) {
    const int* o = m->t + 3 * t;
    vd_vec3 p[3] = {m->v[o[0]], m->v[o[1]], m->v[o[2]]};
    vd_vec3 n = vd_cross(vd_sub(p[1], p[0]), vd_sub(p[2], p[0]));
    double len = vd_norm(n);
    m->fn[t] = len > 0 ? vd_scale(n, 1.0 / len) : vd_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
      double w = angle_between(vd_sub(p[(k + 1) % 3], p[k]), vd_sub(p[(k + 2) % 3], p[k]));
      m->vn[o[k]] = vd_madd(m->vn[o[k]], m->fn[t], w);
    }
  }
  // edges: every undirected edge must be used by exactly two triangles in opposite directions
  int nk = 0;
  for (int t = 0; t < m->nt; t++)
    for (int k = 0; k < 3; k++) {
      int a = m->t[3 * t + k], b = m->t[3 * t + (k + 1) % 3];
      ek[nk++] = (ekey){a < b ? a : b, a < b ? b : a, t, k, a < b};
    }
  qsort(ek, (size_t)nk, sizeof *ek, cmp_ekey);
  for (int i = 0; i < nk;) {
    int j = i;
    while (j < nk && ek[j].lo == ek[i].lo && ek[j].hi == ek[i].hi)
      j++;
    if (j - i != 2) {
      st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                        "sdf: the mesh is not closed: the edge between welded vertices %d and %d "
                        "belongs to %d triangle(s), expected 2",
                        ek[i].lo, ek[i].hi, j - i);
      goto done;
    }
    if (ek[i].fwd == ek[i + 1].fwd) {
      st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                        "sdf: triangles %d and %d are not consistently oriented", ek[i].tri,
                        ek[i + 1].tri);
      goto done;
    }
    vd_vec3 n = vd_add(m->fn[ek[i].tri], m->fn[ek[i + 1].tri]);
    m->en[m->ne] = n;
    m->te[3 * ek[i].tri + ek[i].k] = m->ne;
    m->te[3 * ek[i + 1].tri + ek[i + 1].k] = m->ne;
    m->ne++;
    i = j;
  }
done:
  vd_free(vk, (size_t)nvert * sizeof(vkey));
  vd_free(remap, (size_t)nvert * sizeof(int));
  vd_free(ek, (size_t)ntri * 3 * sizeof(ekey));
  if (st) mesh_free(m, nvert, ntri);
  return st;
}

// ---------------------------------------------------------------------------------------------
// point-triangle distance with the feature of the closest point

// features: 0 face, 1..3 vertex k-1, 4..6 edge k-4 (from vertex k-4 to the next)
typedef struct closest {
  vd_vec3 q;   // closest point
  int feature; // which feature holds q
} closest;

// closest point of triangle abc to p, by Voronoi regions (Ericson, Real-Time Collision
// Detection, 5.1.5)
static closest closest_on_triangle(vd_vec3 p, vd_vec3 a, vd_vec3 b, vd_vec3 c) {
  closest r;
  vd_vec3 ab = vd_sub(b, a), ac = vd_sub(c, a), ap = vd_sub(p, a);
  double d1 = vd_dot(ab, ap), d2 = vd_dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return (closest){a, 1};
  vd_vec3 bp = vd_sub(p, b);
  double d3 = vd_dot(ab, bp), d4 = vd_dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return (closest){b, 2};
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    return (closest){vd_madd(a, ab, v), 4};
  }
  vd_vec3 cp = vd_sub(p, c);
  double d5 = vd_dot(ab, cp), d6 = vd_dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return (closest){c, 3};
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double w = d2 / (d2 - d6);
    return (closest){vd_madd(a, ac, w), 6};
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (closest){vd_madd(b, vd_sub(c, b), w), 5};
  }
  double den = va + vb + vc;
  if (!(den > 0)) {
    // degenerate (collinear) triangle: the nearest of its three edges
    r.q = a, r.feature = 1;
    return r;
  }
  double v = vb / den, w = vc / den;
  r.q = vd_add(a, vd_add(vd_scale(ab, v), vd_scale(ac, w)));
  r.feature = 0;
  return r;
}

static double tri_dist2(const mesh* m, int t, vd_vec3 p) {
  const int* o = m->t + 3 * t;
  closest c = closest_on_triangle(p, m->v[o[0]], m->v[o[1]], m->v[o[2]]);
  vd_vec3 d = vd_sub(p, c.q);
  return vd_dot(d, d);
}

// +1 outside, -1 inside, from the pseudo-normal of the closest feature of triangle t
static double tri_sign(const mesh* m, int t, vd_vec3 p) {
  const int* o = m->t + 3 * t;
  closest c = closest_on_triangle(p, m->v[o[0]], m->v[o[1]], m->v[o[2]]);
  vd_vec3 n;
  if (c.feature == 0)
    n = m->fn[t];
  else if (c.feature <= 3)
    n = m->vn[o[c.feature - 1]];
  else
    n = m->en[m->te[3 * t + c.feature - 4]];
  return vd_dot(vd_sub(p, c.q), n) < 0 ? -1.0 : 1.0;
}

// ---------------------------------------------------------------------------------------------
// the grid

static vd_vec3 node_pos(const vd_sdf* g, int i, int j, int k) {
  return vd_v3(g->origin.x + i * g->cell, g->origin.y + j * g->cell, g->origin.z + k * g->cell);
}

// node index o of face neighbour q (0..5: -x, +x, -y, +y, -z, +z) of node id; 0 off the grid
static int neighbour(const vd_sdf* g, size_t id, int q, size_t* o) {
  size_t sy = (size_t)g->nx, sz = sy * (size_t)g->ny;
  int c[3] = {(int)(id % sy), (int)((id / sy) % (size_t)g->ny), (int)(id / sz)};
  int n[3] = {g->nx, g->ny, g->nz};
  int a = q / 2, s = (q & 1) ? 1 : -1;
  c[a] += s;
  if (c[a] < 0 || c[a] >= n[a]) return 0;
  *o = (size_t)c[0] + sy * (size_t)c[1] + sz * (size_t)c[2];
  return 1;
}

// closest-triangle sweeps in the 8 diagonal orders: each node outside the band tries the
// triangles of its three upwind neighbours
static void sweep(const mesh* m, const vd_sdf* g, double* d2, int* tri, const unsigned char* band) {
  int n[3] = {g->nx, g->ny, g->nz};
  ptrdiff_t stride[3] = {1, g->nx, (ptrdiff_t)g->nx * g->ny};
  for (int dir = 0; dir < 8; dir++) {
    int s[3] = {(dir & 1) ? -1 : 1, (dir & 2) ? -1 : 1, (dir & 4) ? -1 : 1};
    int c[3];
    for (int kk = 0; kk < n[2]; kk++) {
      c[2] = s[2] > 0 ? kk : n[2] - 1 - kk;
      for (int jj = 0; jj < n[1]; jj++) {
        c[1] = s[1] > 0 ? jj : n[1] - 1 - jj;
        for (int ii = 0; ii < n[0]; ii++) {
          c[0] = s[0] > 0 ? ii : n[0] - 1 - ii;
          ptrdiff_t id = c[0] + stride[1] * c[1] + stride[2] * c[2];
          if (band[id]) continue;
          vd_vec3 p = node_pos(g, c[0], c[1], c[2]);
          for (int a = 1; a < 8; a++) {
            ptrdiff_t off = 0;
            int ok = 1;
            for (int b = 0; b < 3; b++) {
              if (!(a & (1 << b))) continue;
              int up = c[b] - s[b];
              if (up < 0 || up >= n[b]) ok = 0;
              off += s[b] * stride[b];
            }
            if (!ok) continue;
            int t = tri[id - off];
            if (t < 0 || t == tri[id]) continue;
            double e = tri_dist2(m, t, p);
            if (e < d2[id] || (e == d2[id] && t < tri[id])) d2[id] = e, tri[id] = t;
          }
        }
      }
    }
  }
}

vd_status vd_sdf_build(const double* vert, int nvert, const int* tri, int ntri,
                       const vd_sdf_def* def_in, vd_sdf** out, vd_error* err) {
  if (out) *out = NULL;
  if (!out || (nvert > 0 && !vert) || (ntri > 0 && !tri) || nvert < 0 || ntri < 0)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "sdf: null or negative argument");
  vd_sdf_def def = def_in ? *def_in : vd_sdf_def_default();
  if (!(def.cell > 0) || !isfinite(def.cell))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "sdf: cell must be > 0 m");
  if (!(def.padding >= 0) || !isfinite(def.padding))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "sdf: padding must be >= 0 m");
  if (!(def.band >= 1.5 * def.cell) || !isfinite(def.band))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        "sdf: band (%g m) must be at least 1.5 cells (%g m)", def.band,
                        1.5 * def.cell);
  if (ntri == 0) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "sdf: the mesh has no triangles");

  mesh m;
  vd_status st = mesh_make(&m, vert, nvert, tri, ntri, err);
  if (st) return st;

  // grid box: the mesh bounds plus padding, at least two nodes along each axis
  vd_vec3 lo = m.v[0], hi = m.v[0];  // NOLINT(clang-analyzer-core.NullDereference): ntri > 0 with indices below nvert: m.v has vertices
  for (int i = 1; i < m.nv; i++)
    lo = vd_vmin(lo, m.v[i]), hi = vd_vmax(hi, m.v[i]);
  lo = vd_sub(lo, vd_v3(def.padding, def.padding, def.padding));
  hi = vd_add(hi, vd_v3(def.padding, def.padding, def.padding));
  double ext[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
  int64_t n[3];
  for (int a = 0; a < 3; a++) {
    double c = ceil(ext[a] / def.cell - 1e-9) + 1;
    if (!(c < 1e9)) c = 1e9;
    n[a] = c < 2 ? 2 : (int64_t)c;
  }
  if (n[0] * n[1] > def.max_nodes || n[0] * n[1] * n[2] > def.max_nodes) {
    mesh_free(&m, nvert, ntri);
    return vd_error_set(
        err, VD_ERR_LIMIT, "", 0, 0,
        "sdf: a %lld x %lld x %lld grid exceeds max_nodes (%lld); use a larger cell",
        (long long)n[0], (long long)n[1], (long long)n[2], (long long)def.max_nodes);
  }
  size_t nn = (size_t)(n[0] * n[1] * n[2]);

  // one allocation for the result; scratch for the build
  size_t head = (sizeof(vd_sdf) + 15) & ~(size_t)15;
  size_t nbytes = head + nn * sizeof(double);
  vd_sdf* g = vd_malloc(nbytes);
  double* d2 = vd_malloc(nn * sizeof(double));
  int* tr = vd_malloc(nn * sizeof(int));
  unsigned char* band = vd_calloc(nn, 1);
  int* queue = vd_malloc(nn * sizeof(int));
  if (!g || !d2 || !tr || !band || !queue) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building a distance grid");
    vd_free(g, nbytes);
    g = NULL;
    goto done;
  }
  memset(g, 0, sizeof *g);
  g->nx = (int)n[0], g->ny = (int)n[1], g->nz = (int)n[2];
  g->origin = lo;
  g->cell = def.cell;
  g->band = def.band;
  g->full = def.full != 0;
  g->nvert = m.nv, g->ntri = m.nt;
  g->value = (double*)((char*)g + head);
  g->nbytes = nbytes;
  for (size_t i = 0; i < nn; i++)
    d2[i] = HUGE_VAL, tr[i] = -1;

  // band: every triangle visits the nodes within `band` of its bounding box
  double b2 = def.band * def.band;
  size_t sx = 1, sy = (size_t)g->nx, sz = (size_t)g->nx * (size_t)g->ny;
  for (int t = 0; t < m.nt; t++) {
    const int* o = m.t + 3 * t;
    vd_vec3 tlo = vd_vmin(m.v[o[0]], vd_vmin(m.v[o[1]], m.v[o[2]]));
    vd_vec3 thi = vd_vmax(m.v[o[0]], vd_vmax(m.v[o[1]], m.v[o[2]]));
    double l[3] = {tlo.x - def.band, tlo.y - def.band, tlo.z - def.band};
    double h[3] = {thi.x + def.band, thi.y + def.band, thi.z + def.band};
    double org[3] = {lo.x, lo.y, lo.z};
    int i0[3], i1[3];
    for (int a = 0; a < 3; a++) {
      double u0 = ceil((l[a] - org[a]) / def.cell), u1 = floor((h[a] - org[a]) / def.cell);
      i0[a] = u0 < 0 ? 0 : (int)u0;
      i1[a] = u1 > (double)(n[a] - 1) ? (int)(n[a] - 1) : (int)u1;
    }
    for (int k = i0[2]; k <= i1[2]; k++)
      for (int j = i0[1]; j <= i1[1]; j++)
        for (int i = i0[0]; i <= i1[0]; i++) {
          size_t id = (size_t)i * sx + (size_t)j * sy + (size_t)k * sz;
          double e = tri_dist2(&m, t, node_pos(g, i, j, k));
          if (e <= b2 && e < d2[id]) d2[id] = e, tr[id] = t;
        }
  }
  for (size_t i = 0; i < nn; i++)
    band[i] = tr[i] >= 0;

  // beyond the band: closest triangles carried over by sweeps (full grids only)
  if (g->full) sweep(&m, g, d2, tr, band);

  // signs: pseudo-normals in the band, then a flood fill through the nodes beyond it
  for (size_t id = 0; id < nn; id++) {
    if (!band[id]) continue;
    int i = (int)(id % sy), j = (int)((id / sy) % (size_t)g->ny), k = (int)(id / sz);
    g->value[id] = tri_sign(&m, tr[id], node_pos(g, i, j, k)) * sqrt(d2[id]);
  }
  // 2: beyond the band, sign not yet known; 3: known
  for (size_t id = 0; id < nn; id++)
    if (!band[id]) band[id] = 2;
  size_t qh = 0, qt = 0;
  for (size_t id = 0; id < nn; id++) {
    if (band[id] != 2) continue;
    // a node beside the band takes the band node's sign
    for (int q = 0; q < 6; q++) {
      size_t o;
      if (!neighbour(g, id, q, &o)) continue;
      if (band[o] == 1) {
        g->value[id] = g->value[o] < 0 ? -1.0 : 1.0;
        band[id] = 3;
        queue[qt++] = (int)id;
        break;
      }
    }
  }
  for (;;) {
    while (qh < qt) {
      size_t id = (size_t)queue[qh++];
      for (int q = 0; q < 6; q++) {
        size_t o;
        if (!neighbour(g, id, q, &o) || band[o] != 2) continue;
        g->value[o] = g->value[id];
        band[o] = 3;
        queue[qt++] = (int)o;
      }
    }
    // a region that touches no band node (no surface near it) is outside
    size_t id = 0;
    while (id < nn && band[id] != 2)
      id++;
    if (id == nn) break;
    g->value[id] = 1.0;
    band[id] = 3;
    queue[qt++] = (int)id;
  }
  // magnitudes beyond the band: swept distances, or the band width
  for (size_t id = 0; id < nn; id++) {
    if (band[id] != 3) continue;
    double mag = (g->full && tr[id] >= 0) ? sqrt(d2[id]) : def.band;
    g->value[id] *= mag;
  }

done:
  vd_free(d2, nn * sizeof(double));
  vd_free(tr, nn * sizeof(int));
  vd_free(band, nn);
  vd_free(queue, nn * sizeof(int));
  mesh_free(&m, nvert, ntri);
  if (st) return st;
  *out = g;
  return VD_OK;
}

void vd_sdf_destroy(vd_sdf* sdf) {
  if (sdf) vd_free(sdf, sdf->nbytes);
}

// trilinear value and gradient at a point inside the grid box
static double trilinear(const vd_sdf* g, double u, double v, double w, vd_vec3* grad) {
  int i = (int)floor(u), j = (int)floor(v), k = (int)floor(w);
  if (i > g->nx - 2) i = g->nx - 2;
  if (j > g->ny - 2) j = g->ny - 2;
  if (k > g->nz - 2) k = g->nz - 2;
  if (i < 0) i = 0;
  if (j < 0) j = 0;
  if (k < 0) k = 0;
  double fx = u - i, fy = v - j, fz = w - k;
  size_t sy = (size_t)g->nx, sz = (size_t)g->nx * (size_t)g->ny;
  const double* c = g->value + (size_t)i + sy * (size_t)j + sz * (size_t)k;
  double c000 = c[0], c100 = c[1], c010 = c[sy], c110 = c[sy + 1];
  double c001 = c[sz], c101 = c[sz + 1], c011 = c[sz + sy], c111 = c[sz + sy + 1];
  // along x, then y, then z
  double c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
  double c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
  double c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
  double val = c0 + fz * (c1 - c0);
  if (grad) {
    double gx = ((c100 - c000) * (1 - fy) + (c110 - c010) * fy) * (1 - fz) +
                ((c101 - c001) * (1 - fy) + (c111 - c011) * fy) * fz;
    double gy = (c10 - c00) * (1 - fz) + (c11 - c01) * fz;
    double gz = c1 - c0;
    *grad = vd_scale(vd_v3(gx, gy, gz), 1.0 / g->cell);
  }
  return val;
}

double vd_sdf_eval(const vd_sdf* g, vd_vec3 p, vd_vec3* grad) {
  VD_ASSERT(g);
  // grid coordinates, clamped to the box
  double u[3] = {(p.x - g->origin.x) / g->cell, (p.y - g->origin.y) / g->cell,
                 (p.z - g->origin.z) / g->cell};
  int n[3] = {g->nx, g->ny, g->nz};
  double c[3];
  int clamped[3];
  for (int a = 0; a < 3; a++) {
    c[a] = u[a] < 0 ? 0 : (u[a] > n[a] - 1 ? n[a] - 1 : u[a]);
    clamped[a] = c[a] != u[a];
  }
  vd_vec3 gi;
  double val = trilinear(g, c[0], c[1], c[2], &gi);
  if (!clamped[0] && !clamped[1] && !clamped[2]) {
    if (grad) *grad = gi;
    return val;
  }
  // outside: value at the box plus the distance to it; the gradient follows the same split
  vd_vec3 off = vd_scale(vd_v3(u[0] - c[0], u[1] - c[1], u[2] - c[2]), g->cell);
  double dist = vd_norm(off);
  if (grad) {
    double gg[3] = {gi.x, gi.y, gi.z}, o[3] = {off.x, off.y, off.z};
    for (int a = 0; a < 3; a++)
      if (clamped[a]) gg[a] = dist > 0 ? o[a] / dist : 0;
    *grad = vd_v3(gg[0], gg[1], gg[2]);
  }
  return val + dist;
}
