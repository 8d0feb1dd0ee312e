// SPDX-License-Identifier: MIT
// The sampler: tessellate, build the alias table, solids and BVH, then make the points chunk by
// chunk, each chunk with its own random stream so the thread count never changes the result.
//
// Uniform points in a triangle: with r1, r2 uniform in [0, 1),
//   P = (1 - sqrt(r1)) A + sqrt(r1) (1 - r2) B + sqrt(r1) r2 C
// (Osada, Funkhouser, Chazelle & Dobkin 2002, "Shape distributions", eq. 1). sqrt(r1) is the
// distance fraction from A towards the opposite edge, whose density must grow linearly for equal
// area per step; r2 is then uniform along that segment. Drawing a1, a2 uniform and setting
// a3 = 1 - a1 - a2 leaves the triangle whenever a1 + a2 > 1 (half the draws), and normalising
// three uniforms by their sum (the paper's Algorithm 1) stays inside but crowds the centroid.
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "cloud_internal.h"

typedef struct view {
  vd_vec3 pos;          // scanner position (m)
  vd_vec3 f, r, u;      // scan frame: forward, right, up
  double dnear, dfar;   // nearest and farthest surface distance (m)
  double gmax;          // largest density over [dnear, dfar]
  int64_t start, count; // its points (surface modes) or rays (scan)
} view;

typedef struct counters {
  int64_t drawn, interior, density, backface, occluded, noise, missed;
} counters;

// a triangle packed for the sampler: one draw touches one record and one alias column
typedef struct stri {
  double v0[3], e1[3], e2[3]; // first vertex and edges (m)
  double n0[3], n1[3], n2[3]; // vertex normals
  int label, instance, kind, prim;
  int cand0, cand1;           // its interior candidates: cand[cand0 .. cand1)
  int one_sided;              // triangle of a closed primitive
  int pad;
} stri;

typedef struct acol {
  double prob; // probability of keeping the column's own triangle
  int alias;   // the other triangle of the column
  int pad;
} acol;

// uniforms drawn in blocks from a chunk's stream (the same sequence as one call at a time)
typedef struct ustream {
  vd_rng rng;
  double buf[64];
  int i;
  int has_gauss;
  double gauss_next;
} ustream;

static void us_init(ustream* u, uint64_t seed, uint64_t chunk) {
  vd_rng_stream(&u->rng, seed, chunk);
  u->i = 64;
  u->has_gauss = 0;
}
static inline double uni(ustream* u) {
  if (u->i == 64) {
    vd_rng_fill(&u->rng, u->buf, 64);
    u->i = 0;
  }
  return u->buf[u->i++];
}
// standard normal deviate, CPython's gauss() algorithm (Box-Muller, second value cached)
static double gauss(ustream* u) {
  if (u->has_gauss) {
    u->has_gauss = 0;
    return u->gauss_next;
  }
  double x2pi = uni(u) * (2.0 * VD_PI), g2rad = sqrt(-2.0 * log(1.0 - uni(u)));
  u->gauss_next = sin(x2pi) * g2rad;
  u->has_gauss = 1;
  return cos(x2pi) * g2rad;
}

typedef struct sampler {
  const vd_cloud_def* def;
  const vd_model* m;
  vd_mesh mesh;
  acol* col;                // alias table (ntri)
  stri* tri;                // packed triangles (ntri)
  unsigned char* one_sided; // 1 for triangles of closed primitives (ntri)
  double area;              // total area (m^2)
  vd_solids so;             // closed primitives (when interior removal is on)
  int* cand_start;          // candidate solids of triangle t: cand[cand_start[t] .. t + 1] (ntri + 1)
  int* cand;                // solids whose boxes meet the triangle's, own and tube neighbours
                            // left out (ncand)
  int ncand, cand_cap;
  vd_bvh bvh;               // triangles (occlusion, scan)
  view* views;              // nview >= 1; a single view without a scanner when there is none
  int nview;
  int scanners;             // 1 when views have scanner positions
  double eps;               // ray offset (m)
  vd_cloud* out;
  counters* per_chunk;      // (nchunk)
  int64_t nchunk;
  int failed;
} sampler;

static vd_vec3 mesh_vert(const vd_mesh* mesh, int v) {
  return vd_v3(mesh->pos[3 * (size_t)v], mesh->pos[3 * (size_t)v + 1], mesh->pos[3 * (size_t)v + 2]);
}

// ---------------------------------------------------------------------------------------------
// checks


static vd_status check_def(const vd_cloud_def* def, vd_error* err) {
#define BAD(...) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, __VA_ARGS__)
  if (def->sensor < VD_SENSOR_UNIFORM || def->sensor > VD_SENSOR_SCAN) BAD("cloud def: unknown sensor");
  if (def->sensor != VD_SENSOR_SCAN && (def->points < 1 || def->points > VD_CLOUD_MAX_POINTS))
    BAD("cloud def: points must be in 1..%lld, got %lld", (long long)VD_CLOUD_MAX_POINTS,
        (long long)def->points);
  if (def->max_points < 1) BAD("cloud def: max_points must be >= 1");
  if (def->sensor != VD_SENSOR_SCAN && def->points > def->max_points)
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                        "a cloud of %lld points is more than the limit of %lld (max_points; it would take about "
                        "%.3g GB)",
                        (long long)def->points, (long long)def->max_points, 80e-9 * (double)def->points);
  if (def->density < VD_DENSITY_CONSTANT || def->density > VD_DENSITY_TABLE)
    BAD("cloud def: unknown density law");
  if (!(def->noise_sigma >= 0) || !isfinite(def->noise_sigma))
    BAD("cloud def: noise sigma must be a finite number >= 0 m");
  if (!(def->noise_slope >= 0) || !isfinite(def->noise_slope))
    BAD("cloud def: noise slope must be a finite number >= 0 m/m");
  if (def->nscanner < 0 || def->nscanner > 65535 || (def->nscanner > 0 && !def->scanner))
    BAD("cloud def: nscanner must be in 0..65535 with a scanner array");
  if (def->threads < 0) BAD("cloud def: threads must be >= 0");
  if (def->max_attempts < 1) BAD("cloud def: max_attempts must be >= 1");
  if (def->nscanner == 0) {
    if (def->sensor == VD_SENSOR_DISTANCE) BAD("the distance sensor needs at least one scanner");
    if (def->sensor == VD_SENSOR_SCAN) BAD("the scan sensor needs at least one scanner");
    if (def->occlusion) BAD("occlusion needs at least one scanner");
    if (def->noise_slope > 0) BAD("noise growing with distance needs at least one scanner");
  }
  if (def->sensor == VD_SENSOR_DISTANCE && def->density == VD_DENSITY_TABLE) {
    if (def->ntable < 2 || def->ntable > VD_CLOUD_TABLE_MAX)
      BAD("density table: 2..%d (distance, density) pairs, got %d", VD_CLOUD_TABLE_MAX, def->ntable);
    int positive = 0;
    for (int i = 0; i < def->ntable; i++) {
      if (!isfinite(def->table_d[i]) || def->table_d[i] < 0)
        BAD("density table: distance %d must be a finite number >= 0 m", i + 1);
      if (i > 0 && !(def->table_d[i] > def->table_d[i - 1]))
        BAD("density table: distances must increase (pair %d)", i + 1);
      if (!isfinite(def->table_g[i]) || def->table_g[i] < 0)
        BAD("density table: density %d must be a finite number >= 0", i + 1);
      positive |= def->table_g[i] > 0;
    }
    if (!positive) BAD("density table: every density is 0");
  }
  int64_t rays = 0;
  for (int v = 0; v < def->nscanner; v++) {
    const vd_scanner* s = &def->scanner[v];
    if (!vd_v3_finite(s->pos) || !vd_v3_finite(s->target)) BAD("scanner %d: position and target must be finite", v);
    if (vd_norm(vd_sub(s->target, s->pos)) == 0) BAD("scanner %d: target equals the position", v);
    if (def->sensor != VD_SENSOR_SCAN) continue;
    if (s->pattern != VD_SCAN_ANGULAR && s->pattern != VD_SCAN_PINHOLE) BAD("scanner %d: unknown pattern", v);
    double hmax = s->pattern == VD_SCAN_PINHOLE ? VD_PI : 2 * VD_PI, vmax = VD_PI;
    if (!(s->fov_h > 0 && s->fov_h <= hmax) || (s->pattern == VD_SCAN_PINHOLE && s->fov_h >= VD_PI))
      BAD("scanner %d: horizontal field of view must be in (0, %g) degrees", v, hmax * 180 / VD_PI);
    if (!(s->fov_v > 0 && s->fov_v <= vmax) || (s->pattern == VD_SCAN_PINHOLE && s->fov_v >= VD_PI))
      BAD("scanner %d: vertical field of view must be in (0, 180) degrees", v);
    if (s->res_h < 1 || s->res_v < 1 || s->res_h > 100000 || s->res_v > 100000)
      BAD("scanner %d: resolution must be 1..100000 rays each way", v);
    rays += (int64_t)s->res_h * s->res_v;
  }
  if (rays > VD_CLOUD_MAX_RAYS)
    BAD("scan: %lld rays in all (at most %lld)", (long long)rays, (long long)VD_CLOUD_MAX_RAYS);
  if (rays > def->max_points)
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                        "a scan of %lld rays is more than the limit of %lld (max_points; it would take about "
                        "%.3g GB)",
                        (long long)rays, (long long)def->max_points, 80e-9 * (double)rays);
#undef BAD
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// alias table (Vose 1991): O(n) build, O(1) draw

static vd_status build_alias(sampler* s, vd_error* err) {
  const vd_mesh* mesh = &s->mesh;
  int n = mesh->ntri;
  double* a = vd_malloc((size_t)n * sizeof(double));
  int* small = vd_malloc((size_t)n * 2 * sizeof(int));
  if (!a || !small) {
    vd_free(a, (size_t)n * sizeof(double));
    vd_free(small, (size_t)n * 2 * sizeof(int));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory for the alias table");
  }
  int* large = small + n;
  double total = 0;
  for (int t = 0; t < n; t++) {
    const double* p0 = mesh->pos + 3 * (size_t)mesh->tri[3 * t];
    const double* p1 = mesh->pos + 3 * (size_t)mesh->tri[3 * t + 1];
    const double* p2 = mesh->pos + 3 * (size_t)mesh->tri[3 * t + 2];
    vd_vec3 e1 = vd_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
    vd_vec3 e2 = vd_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
    a[t] = 0.5 * vd_norm(vd_cross(e1, e2));
    if (!isfinite(a[t])) a[t] = 0;
    total += a[t];
  }
  s->area = total;
  vd_status st = VD_OK;
  if (!(total > 0)) {
    st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "the plant has no surface to sample");
  } else {
    // columns of height 1: a small one is topped up from a large one, which shrinks
    int ns = 0, nl = 0;
    for (int t = 0; t < n; t++) {
      a[t] = a[t] * n / total;
      if (a[t] < 1)
        small[ns++] = t;
      else
        large[nl++] = t;
    }
    while (ns && nl) {
      int sm = small[--ns], lg = large[--nl];
      s->col[sm].prob = a[sm];
      s->col[sm].alias = lg;
      a[lg] = (a[lg] + a[sm]) - 1.0;
      if (a[lg] < 1)
        small[ns++] = lg;
      else
        large[nl++] = lg;
    }
    // what is left is 1 up to rounding
    while (nl) {
      int lg = large[--nl];
      s->col[lg].prob = 1, s->col[lg].alias = lg;
    }
    while (ns) {
      int sm = small[--ns];
      s->col[sm].prob = 1, s->col[sm].alias = sm;
    }
  }
  vd_free(a, (size_t)n * sizeof(double));
  vd_free(small, (size_t)n * 2 * sizeof(int));
  return st;
}

static inline int draw_tri(const sampler* s, ustream* u) {
  int n = s->mesh.ntri;
  double x = uni(u) * n;
  int i = (int)x;
  if (i >= n) i = n - 1;
  return x - i < s->col[i].prob ? i : s->col[i].alias;
}

// pack every triangle (after the candidates are known)
static void pack_tris(sampler* s) {
  const vd_mesh* mesh = &s->mesh;
  for (int t = 0; t < mesh->ntri; t++) {
    stri* r = &s->tri[t];
    const int* tv = mesh->tri + 3 * (size_t)t;
    for (int k = 0; k < 3; k++) {
      double a = mesh->pos[3 * (size_t)tv[0] + k];
      r->v0[k] = a;
      r->e1[k] = mesh->pos[3 * (size_t)tv[1] + k] - a;
      r->e2[k] = mesh->pos[3 * (size_t)tv[2] + k] - a;
      r->n0[k] = mesh->normal[3 * (size_t)tv[0] + k];
      r->n1[k] = mesh->normal[3 * (size_t)tv[1] + k];
      r->n2[k] = mesh->normal[3 * (size_t)tv[2] + k];
    }
    r->label = mesh->tri_label[t], r->instance = mesh->tri_instance[t];
    r->kind = mesh->tri_kind[t], r->prim = mesh->tri_prim[t];
    r->cand0 = s->cand_start ? s->cand_start[t] : 0;
    r->cand1 = s->cand_start ? s->cand_start[t + 1] : 0;
    r->one_sided = s->one_sided[t];
    r->pad = 0;
  }
}

// ---------------------------------------------------------------------------------------------
// interior candidates: most triangles meet no other solid's box, and their points need no test

static vd_status build_candidates(sampler* s, vd_error* err) {
  const vd_mesh* mesh = &s->mesh;
  const vd_solids* so = &s->so;
  int n = mesh->ntri, buf_cap = 64;
  s->cand_start = vd_malloc(((size_t)n + 1) * sizeof(int));
  int* buf = vd_malloc((size_t)buf_cap * sizeof(int));
  if (!s->cand_start || !buf) {
    vd_free(buf, (size_t)buf_cap * sizeof(int));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory for interior candidates");
  }
  s->ncand = 0;
  for (int t = 0; t < n; t++) {
    s->cand_start[t] = s->ncand;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 3; c++)
      for (int k = 0; k < 3; k++) {
        double v = mesh->pos[3 * (size_t)mesh->tri[3 * t + c] + k];
        lo[k] = fmin(lo[k], v), hi[k] = fmax(hi[k], v);
      }
    int m = vd_bvh_overlap(&so->bvh, lo, hi, buf, buf_cap);
    if (m > buf_cap) {
      vd_free(buf, (size_t)buf_cap * sizeof(int));
      buf_cap = m;
      buf = vd_malloc((size_t)buf_cap * sizeof(int));
      if (!buf) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory for interior candidates");
      m = vd_bvh_overlap(&so->bvh, lo, hi, buf, buf_cap);
    }
    int own = vd_solids_own(so, mesh->tri_kind[t], mesh->tri_prim[t]);
    int j0 = own >= 0 ? so->solid[own].joined[0] : -1, j1 = own >= 0 ? so->solid[own].joined[1] : -1;
    // the triangle's bounding sphere: centroid and farthest vertex
    vd_vec3 tv[3], cen = vd_v3(0, 0, 0);
    for (int c = 0; c < 3; c++) {
      tv[c] = mesh_vert(mesh, mesh->tri[3 * t + c]);
      cen = vd_madd(cen, tv[c], 1.0 / 3.0);
    }
    double rad = 0;
    for (int c = 0; c < 3; c++)
      rad = fmax(rad, vd_norm(vd_sub(tv[c], cen)));
    for (int i = 0; i < m; i++) {
      const vd_solid* sd = &so->solid[buf[i]];
      if (buf[i] == own || buf[i] == j0 || buf[i] == j1) continue;
      if (lo[0] > sd->hi[0] || hi[0] < sd->lo[0] || lo[1] > sd->hi[1] || hi[1] < sd->lo[1] ||
          lo[2] > sd->hi[2] || hi[2] < sd->lo[2])
        continue;
      // boxes of slanted frustums are loose: drop solids whose bounding capsule or sphere the
      // triangle's bounding sphere misses
      if (sd->kind == VD_PRIM_SPHERE && vd_norm(vd_sub(cen, sd->c)) > sd->r0 + rad + 2 * so->eps) continue;
      if (sd->kind == VD_PRIM_SEGMENT) {
        vd_vec3 ax = vd_v3(sd->rot[6], sd->rot[7], sd->rot[8]), d = vd_sub(cen, sd->c);
        double z = vd_dot(d, ax), zc = z < 0 ? 0 : z > sd->len ? sd->len : z;
        if (vd_norm(vd_sub(d, vd_scale(ax, zc))) > fmax(sd->r0, sd->r1) + rad + 2 * so->eps) continue;
      }
      if (!vd_grow((void**)&s->cand, &s->cand_cap, s->ncand + 1, sizeof(int))) {
        vd_free(buf, (size_t)buf_cap * sizeof(int));
        return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory for interior candidates");
      }
      s->cand[s->ncand++] = buf[i];
    }
  }
  s->cand_start[n] = s->ncand;
  vd_free(buf, (size_t)buf_cap * sizeof(int));
  return VD_OK;
}

// inside a candidate solid of a triangle. Nine tests in ten end at the solid's box: that test is
// made here, inline, and the full one (which repeats it) only for points inside the box.
static inline int inside_cand(const sampler* s, const stri* r, vd_vec3 p) {
  for (int i = r->cand0; i < r->cand1; i++) {
    const vd_solid* sd = &s->so.solid[s->cand[i]];
    if (p.x < sd->lo[0] || p.x > sd->hi[0] || p.y < sd->lo[1] || p.y > sd->hi[1] || p.z < sd->lo[2] ||
        p.z > sd->hi[2])
      continue;
    if (vd_solid_contains(&s->so, s->cand[i], p)) return 1;
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// views: scanner frames, surface distance range, density peak

// distance from p to the triangle abc (Ericson, Real-Time Collision Detection, 5.1.5)
static double dist_tri(vd_vec3 p, vd_vec3 a, vd_vec3 b, vd_vec3 c) {
  vd_vec3 ab = vd_sub(b, a), ac = vd_sub(c, a), ap = vd_sub(p, a);
  double d1 = vd_dot(ab, ap), d2 = vd_dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return vd_norm(ap);
  vd_vec3 bp = vd_sub(p, b);
  double d3 = vd_dot(ab, bp), d4 = vd_dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return vd_norm(bp);
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return vd_norm(vd_sub(p, vd_madd(a, ab, d1 / (d1 - d3))));
  vd_vec3 cp = vd_sub(p, c);
  double d5 = vd_dot(ab, cp), d6 = vd_dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return vd_norm(cp);
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return vd_norm(vd_sub(p, vd_madd(a, ac, d2 / (d2 - d6))));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return vd_norm(vd_sub(p, vd_madd(b, vd_sub(c, b), w)));
  }
  double den = 1.0 / (va + vb + vc);
  vd_vec3 q = vd_add(a, vd_add(vd_scale(ab, vb * den), vd_scale(ac, vc * den)));
  return vd_norm(vd_sub(p, q));
}

static double table_gamma(const vd_cloud_def* def, double d) {
  int n = def->ntable;
  if (d <= def->table_d[0]) return def->table_g[0];
  if (d >= def->table_d[n - 1]) return def->table_g[n - 1];
  int i = 1;
  while (def->table_d[i] < d) i++;
  double f = (d - def->table_d[i - 1]) / (def->table_d[i] - def->table_d[i - 1]);
  return def->table_g[i - 1] + f * (def->table_g[i] - def->table_g[i - 1]);
}

// relative density at distance d from the view's scanner
static double gamma_of(const vd_cloud_def* def, const view* w, double d) {
  switch (def->density) {
    case VD_DENSITY_CONSTANT: return 1;
    case VD_DENSITY_INVERSE_SQUARE: {
      double dn = w->dnear > 1e-6 ? w->dnear : 1e-6;
      return d <= dn ? 1 : (dn / d) * (dn / d);
    }
    case VD_DENSITY_LINEAR: {
      double span = w->dfar - w->dnear;
      if (!(span > 0)) return 1;
      double g = 1 - (d - w->dnear) / span;
      return g < 0 ? 0 : g > 1 ? 1 : g;
    }
    default: return table_gamma(def, d);
  }
}

// a right-handed scan frame looking from pos at target, up as close to +z as possible
static void view_frame(view* w, vd_vec3 target) {
  w->f = vd_normalize(vd_sub(target, w->pos));
  vd_vec3 hint = fabs(w->f.z) > 0.999999 ? vd_v3(0, 1, 0) : vd_v3(0, 0, 1);
  w->r = vd_normalize(vd_cross(w->f, hint));
  w->u = vd_cross(w->r, w->f);
}

static vd_status make_views(sampler* s, vd_error* err) {
  const vd_cloud_def* def = s->def;
  s->scanners = def->nscanner > 0;
  s->nview = s->scanners ? def->nscanner : 1;
  s->views = vd_calloc((size_t)s->nview, sizeof(view));
  if (!s->views) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory for views");
  int64_t start = 0;
  for (int v = 0; v < s->nview; v++) {
    view* w = &s->views[v];
    if (def->sensor == VD_SENSOR_SCAN) {
      w->count = (int64_t)def->scanner[v].res_h * def->scanner[v].res_v;
    } else {
      // points split evenly, the first views taking the remainder
      w->count = def->points / s->nview + (v < def->points % s->nview);
    }
    w->start = start;
    start += w->count;
    w->gmax = 1;
    if (!s->scanners) continue;
    w->pos = def->scanner[v].pos;
    view_frame(w, def->scanner[v].target);
    // nearest and farthest surface distances, the density's peak between them
    const vd_mesh* mesh = &s->mesh;
    w->dnear = INFINITY, w->dfar = 0;
    for (int i = 0; i < mesh->nvert; i++)
      w->dfar = fmax(w->dfar, vd_norm(vd_sub(mesh_vert(mesh, i), w->pos)));
    for (int t = 0; t < mesh->ntri; t++) {
      double d = dist_tri(w->pos, mesh_vert(mesh, mesh->tri[3 * t]), mesh_vert(mesh, mesh->tri[3 * t + 1]),
                          mesh_vert(mesh, mesh->tri[3 * t + 2]));
      w->dnear = fmin(w->dnear, d);
    }
    if (def->sensor == VD_SENSOR_DISTANCE && def->density == VD_DENSITY_TABLE) {
      double g = fmax(table_gamma(def, w->dnear), table_gamma(def, w->dfar));
      for (int i = 0; i < def->ntable; i++)
        if (def->table_d[i] > w->dnear && def->table_d[i] < w->dfar) g = fmax(g, def->table_g[i]);
      if (!(g > 0))
        return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                            "density table is 0 over scanner %d's distances %g..%g m", v, w->dnear,
                            w->dfar);
      w->gmax = g;
    }
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// points

static inline vd_vec3 tri_normal(const stri* r, double wa, double wb, double wc) {
  const double *na = r->n0, *nb = r->n1, *nc = r->n2;
  vd_vec3 n = vd_v3(wa * na[0] + wb * nb[0] + wc * nc[0], wa * na[1] + wb * nb[1] + wc * nc[1],
                    wa * na[2] + wb * nb[2] + wc * nc[2]);
  double len2 = vd_dot(n, n);
  if (len2 > 1e-24) return vd_scale(n, 1.0 / sqrt(len2));
  // vertex normals cancel (a fold): the face normal
  vd_vec3 e1 = vd_v3(r->e1[0], r->e1[1], r->e1[2]), e2 = vd_v3(r->e2[0], r->e2[1], r->e2[2]);
  return vd_normalize(vd_cross(e1, e2));
}

// point i; view and range only with scanners (without, the block was allocated zeroed, and those
// pages are never touched)
static void store(vd_cloud* c, int64_t i, vd_vec3 p, vd_vec3 n, int label, int instance, int scanners,
                  int vi, double range) {
  c->pos[3 * i] = p.x, c->pos[3 * i + 1] = p.y, c->pos[3 * i + 2] = p.z;
  c->normal[3 * i] = n.x, c->normal[3 * i + 1] = n.y, c->normal[3 * i + 2] = n.z;
  c->label[i] = label, c->instance[i] = instance;
  if (scanners) c->view[i] = vi, c->range[i] = range;
}

static vd_vec3 gauss3(ustream* u) {
  double x = gauss(u), y = gauss(u), z = gauss(u);
  return vd_v3(x, y, z);
}

// surface modes: every point of the chunk, each drawn until a candidate survives; 0 when one
// point ran out of attempts
static int sample_chunk(const sampler* s, int64_t c, counters* k) {
  const vd_cloud_def* def = s->def;
  ustream u;
  us_init(&u, def->seed, (uint64_t)c);
  int64_t a = c * VD_CLOUD_CHUNK, b = a + VD_CLOUD_CHUNK;
  if (b > def->points) b = def->points;
  int v = 0;
  // a budget for the chunk: max_attempts for one point, and max_attempts / 100 per point on
  // average, so a tiny acceptance rate fails soon instead of running for hours
  int64_t budget = def->max_attempts + def->max_attempts / 100 * (b - a), used = 0;
  for (int64_t i = a; i < b; i++) {
    while (v + 1 < s->nview && i >= s->views[v + 1].start) v++;
    const view* w = &s->views[v];
    for (int64_t tries = 0;; tries++) {
      if (tries >= def->max_attempts || used++ >= budget) return 0;
      k->drawn++;
      // a triangle by area, a uniform point in it
      const stri* r = &s->tri[draw_tri(s, &u)];
      double r1 = uni(&u), r2 = uni(&u);
#if defined(__GNUC__)
      // the next draw's triangle is most likely this one: start loading it, and the alias
      // column of the draw after (three uniforms a draw), which picks that one's triangle
      if (u.i + 3 < 64) {
        int nn = (int)(u.buf[u.i + 3] * s->mesh.ntri);
        if (nn < s->mesh.ntri) __builtin_prefetch(&s->col[nn]);
      }
      if (u.i < 64) {
        double x = u.buf[u.i] * s->mesh.ntri;
        int nx = (int)x;
        if (nx < s->mesh.ntri) {
          if (!(x - nx < s->col[nx].prob)) nx = s->col[nx].alias;
          // a record spans three or four lines (176 bytes, 16-byte aligned)
          const char* rp = (const char*)&s->tri[nx];
          __builtin_prefetch(rp);
          __builtin_prefetch(rp + 64);
          __builtin_prefetch(rp + 128);
          __builtin_prefetch(rp + sizeof(stri) - 1);
        }
      }
#endif
      double sq = sqrt(r1), wa = 1 - sq, wb = sq * (1 - r2), wc = sq * r2;
      vd_vec3 p = vd_v3(r->v0[0] + wb * r->e1[0] + wc * r->e2[0], r->v0[1] + wb * r->e1[1] + wc * r->e2[1],
                        r->v0[2] + wb * r->e1[2] + wc * r->e2[2]);
      // inside another closed primitive
      if (def->interior && inside_cand(s, r, p)) {
        k->interior++;
        continue;
      }
      vd_vec3 n = tri_normal(r, wa, wb, wc);
      double d = 0;
      if (s->scanners) {
        vd_vec3 to = vd_sub(w->pos, p);
        d = vd_norm(to);
        // the density law, as an acceptance probability gamma(d) / gamma_max
        if (def->sensor == VD_SENSOR_DISTANCE && def->density != VD_DENSITY_CONSTANT &&
            uni(&u) * w->gmax >= gamma_of(def, w, d)) {
          k->density++;
          continue;
        }
        double facing = vd_dot(n, to);
        if (def->occlusion) {
          // back faces by the flat face normal (the smooth normal may lean past the silhouette)
          vd_vec3 fn = vd_cross(vd_v3(r->e1[0], r->e1[1], r->e1[2]), vd_v3(r->e2[0], r->e2[1], r->e2[2]));
          if (r->one_sided && vd_dot(fn, to) <= 0) {
            k->backface++;
            continue;
          }
          if (d > 2 * s->eps &&
              vd_bvh_occluded(&s->bvh, p, vd_scale(to, 1.0 / d), s->eps, d - s->eps, (int)(r - s->tri))) {
            k->occluded++;
            continue;
          }
        }
        // thin surfaces are seen from either side: their normal faces the scanner
        if (!r->one_sided && facing < 0) n = vd_scale(n, -1);
      }
      // noise, and the noisy point must not enter another closed primitive either
      double sigma = def->noise_sigma + def->noise_slope * d;
      if (sigma > 0) {
        p = vd_madd(p, gauss3(&u), sigma);
        if (def->interior && vd_solids_inside(&s->so, p, r->kind, r->prim) >= 0) {
          k->noise++;
          continue;
        }
      }
      double range = s->scanners ? vd_norm(vd_sub(p, w->pos)) : 0;
      store(s->out, i, p, n, r->label, r->instance, s->scanners, v, range);
      break;
    }
  }
  return 1;
}

// scan mode: ray g of the views' grids
static vd_vec3 ray_dir(const vd_scanner* sc, const view* w, int64_t l) {
  int ix = (int)(l % sc->res_h), iy = (int)(l / sc->res_h);
  double fx = ((double)ix + 0.5) / sc->res_h, fy = ((double)iy + 0.5) / sc->res_v;
  if (sc->pattern == VD_SCAN_PINHOLE) {
    double x = (2 * fx - 1) * tan(0.5 * sc->fov_h), y = (1 - 2 * fy) * tan(0.5 * sc->fov_v);
    return vd_normalize(vd_add(w->f, vd_add(vd_scale(w->r, x), vd_scale(w->u, y))));
  }
  double az = (fx - 0.5) * sc->fov_h, el = (0.5 - fy) * sc->fov_v;
  vd_vec3 h = vd_add(vd_scale(w->f, cos(az)), vd_scale(w->r, sin(az)));
  return vd_add(vd_scale(h, cos(el)), vd_scale(w->u, sin(el)));
}

static void scan_chunk(const sampler* s, int64_t c, counters* k, unsigned char* keep) {
  const vd_cloud_def* def = s->def;
  ustream u;
  us_init(&u, def->seed, (uint64_t)c);
  int64_t total = s->views[s->nview - 1].start + s->views[s->nview - 1].count;
  int64_t a = c * VD_CLOUD_CHUNK, b = a + VD_CLOUD_CHUNK;
  if (b > total) b = total;
  int v = 0;
  for (int64_t g = a; g < b; g++) {
    while (v + 1 < s->nview && g >= s->views[v + 1].start) v++;
    const view* w = &s->views[v];
    vd_vec3 dir = ray_dir(&def->scanner[v], w, g - w->start);
    vd_hit h;
    k->drawn++;
    keep[g] = 0;
    // the nearest surface, back faces of closed primitives culled
    if (!vd_bvh_raycast(&s->bvh, w->pos, dir, 0, INFINITY, 1, -1, &h)) {
      k->missed++;
      continue;
    }
    const stri* r = &s->tri[h.tri];
    vd_vec3 n = tri_normal(r, 1 - h.u - h.v, h.u, h.v);
    if (!r->one_sided && vd_dot(n, dir) > 0) n = vd_scale(n, -1);
    // range noise along the ray
    double range = h.t, sigma = def->noise_sigma + def->noise_slope * h.t;
    if (sigma > 0) {
      range += sigma * gauss(&u);
      if (range < 0) range = 0;
    }
    vd_vec3 p = vd_madd(w->pos, dir, range);
    if (def->interior && vd_solids_inside(&s->so, p, r->kind, r->prim) >= 0) {
      if (sigma > 0)
        k->noise++;
      else
        k->interior++;
      continue;
    }
    store(s->out, g, p, n, r->label, r->instance, 1, v, range);
    keep[g] = 1;
  }
}

// ---------------------------------------------------------------------------------------------
// the whole call

static void sampler_free(sampler* s) {
  int n = s->mesh.ntri;
  vd_free(s->col, (size_t)n * sizeof(acol));
  vd_free(s->tri, (size_t)n * sizeof(stri));
  vd_free(s->one_sided, (size_t)n);
  vd_free(s->views, (size_t)s->nview * sizeof(view));
  vd_free(s->per_chunk, (size_t)s->nchunk * sizeof(counters));
  if (s->cand_start) vd_free(s->cand_start, ((size_t)n + 1) * sizeof(int));
  vd_free(s->cand, (size_t)s->cand_cap * sizeof(int));
  vd_solids_free(&s->so);
  vd_bvh_free(&s->bvh);
  vd_mesh_free(&s->mesh);
}

// keep the scan hits in ray order, in a cloud of their exact size
static vd_status compact(vd_cloud* big, const unsigned char* keep, vd_cloud* out, vd_error* err) {
  int64_t n = 0;
  for (int64_t i = 0; i < big->n; i++)
    n += keep[i];
  vd_status st = vd_cloud_alloc(out, n, big->labels, big->nlabel, err);
  if (st) return st;
  out->nview = big->nview;
  int64_t j = 0;
  for (int64_t i = 0; i < big->n; i++) {
    if (!keep[i]) continue;
    memcpy(out->pos + 3 * j, big->pos + 3 * i, 3 * sizeof(double));
    memcpy(out->normal + 3 * j, big->normal + 3 * i, 3 * sizeof(double));
    out->label[j] = big->label[i], out->instance[j] = big->instance[i];
    out->view[j] = big->view[i], out->range[j] = big->range[i];
    j++;
  }
  return VD_OK;
}

vd_status vd_cloud_sample(const vd_model* m, const vd_data* d, const vd_cloud_def* def_in,
                          vd_cloud* out, vd_cloud_stats* stats, vd_error* err) {
  if (!out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "cloud: null output");
  memset(out, 0, sizeof *out);
  if (!m) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "cloud: null model");
  vd_cloud_def def = def_in ? *def_in : vd_cloud_def_default();
  vd_cloud_stats st_local;
  if (!stats) stats = &st_local;
  memset(stats, 0, sizeof *stats);
  vd_status st = check_def(&def, err);
  if (st) return st;
  sampler s;
  memset(&s, 0, sizeof s);
  s.def = &def;
  s.m = m;

  // tessellation (closed caps: the solids must be closed)
  double t0 = cloud_now();
  def.mesh.caps = 1;
  st = vd_geom_tessellate(m, d, &def.mesh, &s.mesh, err);
  if (st) return st;
  double t1 = cloud_now();
  stats->ntri = s.mesh.ntri;
  if (s.mesh.ntri == 0) {
    sampler_free(&s);
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "the plant has no surface to sample");
  }

  // alias table, sidedness, views, solids, BVH
  int n = s.mesh.ntri;
  s.col = vd_malloc((size_t)n * sizeof(acol));
  s.tri = vd_malloc((size_t)n * sizeof(stri));
  s.one_sided = vd_malloc((size_t)n);
  if (!s.col || !s.tri || !s.one_sided) {
    sampler_free(&s);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory sampling");
  }
  double scale = 1;
  for (int i = 0; i < 3 * s.mesh.nvert; i++)
    scale = fmax(scale, fabs(s.mesh.pos[i]));
  s.eps = 1e-9 * scale;
  for (int t = 0; t < n; t++)
    s.one_sided[t] = s.mesh.tri_kind[t] != VD_PRIM_MESH || m->mesh_closed[s.mesh.tri_prim[t]];
  st = build_alias(&s, err);
  if (!st) st = make_views(&s, err);
  if (!st && def.interior) st = vd_solids_build(m, d, &def.mesh, &s.so, err);
  if (!st && def.interior) st = build_candidates(&s, err);
  if (!st) pack_tris(&s);
  if (!st && (def.occlusion || def.sensor == VD_SENSOR_SCAN))
    st = vd_bvh_build_mesh(&s.mesh, s.one_sided, NULL, &s.bvh, err);
  int64_t total = st ? 0 : s.views[s.nview - 1].start + s.views[s.nview - 1].count;
  s.nchunk = (total + VD_CLOUD_CHUNK - 1) / VD_CLOUD_CHUNK;
  if (!st) {
    s.per_chunk = vd_calloc((size_t)s.nchunk, sizeof(counters));
    if (!s.per_chunk) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory sampling");
  }
  vd_cloud big;
  memset(&big, 0, sizeof big);
  unsigned char* keep = NULL;
  if (!st) st = cloud_alloc(&big, total, m->labels, m->nlabel, !s.scanners, err);
  if (!st && def.sensor == VD_SENSOR_SCAN) {
    keep = vd_malloc((size_t)total);
    if (!keep) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory scanning");
  }
  if (st) {
    vd_cloud_free(&big);
    sampler_free(&s);
    return st;
  }
  big.nview = def.nscanner;
  s.out = &big;
  stats->area = s.area;
  stats->nsolid = s.so.nsolid;
  double t2 = cloud_now();

  // the chunks, in any order on any number of threads
  int threads = 1;
#ifdef _OPENMP
  threads = def.threads > 0 ? def.threads : omp_get_max_threads();
#endif
  stats->threads = threads;
  int failed = 0;
  int64_t nchunk = s.nchunk, ndone = 0;
  const sampler* cs = &s;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int64_t c = 0; c < nchunk; c++) {
    int stop;
#pragma omp atomic read
    stop = failed;
    if (stop) continue;
    if (def.sensor == VD_SENSOR_SCAN) {
      scan_chunk(cs, c, &s.per_chunk[c], keep);
    } else if (!sample_chunk(cs, c, &s.per_chunk[c])) {
#pragma omp atomic write
      failed = 1;
    }
    // progress: chunks done, reported by one thread at a time (it never changes the points)
    if (def.progress) {
      int64_t done;
#pragma omp atomic capture
      done = ++ndone;
#pragma omp critical(vd_cloud_progress)
      def.progress(def.progress_user, done, nchunk);
    }
  }
  double t3 = cloud_now();
  for (int64_t c = 0; c < nchunk; c++) {
    const counters* k = &s.per_chunk[c];
    stats->drawn += k->drawn, stats->rejected_interior += k->interior;
    stats->rejected_density += k->density, stats->rejected_backface += k->backface;
    stats->rejected_occluded += k->occluded, stats->rejected_noise += k->noise;
    stats->missed += k->missed;
  }
  stats->seconds_tessellate = t1 - t0;
  stats->seconds_build = t2 - t1;
  stats->seconds_sample = t3 - t2;
  if (failed) {
    vd_cloud_free(&big);
    sampler_free(&s);
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                        "candidates rarely survive (a point needed more than %lld draws, or more "
                        "than %lld per point on average): interior removal, the density law or "
                        "occlusion leave (almost) nothing to sample",
                        (long long)def.max_attempts, (long long)(def.max_attempts / 100));
  }
  if (def.sensor == VD_SENSOR_SCAN) {
    st = compact(&big, keep, out, err);
    vd_cloud_free(&big);
    vd_free(keep, (size_t)total);
  } else {
    *out = big;
  }
  sampler_free(&s);
  // the scanners' poses, for the files (PCD VIEWPOINT, the views of the headers)
  if (!st && out->nview > 0) {
    out->view_pose = vd_malloc((size_t)out->nview * 6 * sizeof(double));
    if (!out->view_pose) {
      vd_cloud_free(out);
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
    for (int v = 0; v < out->nview; v++) {
      const vd_scanner* sc = &def.scanner[v];
      double pose[6] = {sc->pos.x, sc->pos.y, sc->pos.z, sc->target.x, sc->target.y, sc->target.z};
      memcpy(out->view_pose + 6 * v, pose, sizeof pose);
    }
  }
  return st;
}
