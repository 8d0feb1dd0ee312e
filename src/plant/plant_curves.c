// SPDX-License-Identifier: MIT
// Hand-drawn plants: branch polylines in a curves JSON file (docs/formats.md) built into a plant
// spec the way Gazebo Plants does (Deng et al. 2024, sec. 3.5):
//
// 1. every polyline is sampled densely (sample_step), with radii interpolated along it;
// 2. branches are connected by a search over the curves from the root: the unconnected curve
//    nearest to the connected ones joins at the nearest sample, by whichever of its two ends is
//    nearer, while that gap is within sigma_connect, so the result is a tree (the paper's
//    breadth-first search, ordered by gap so that a branch drawn from another branch's tip is
//    not taken by an earlier curve passing near it);
// 3. the tree is simplified by a depth-first walk from the root: key nodes (the root, junctions,
//    tips, attachment points and the nodes leaves and fruits hang from) are kept, and a node is
//    kept when its path distance to the nearest kept ancestor reaches sigma_distance; a key node
//    closer than sigma_distance / 2 to a kept ancestor that is not a key node takes its place;
// 4. leaves are template meshes placed at their nodes, fruits are spheres hanging from theirs.
#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "plant_internal.h"

#define FORMAT_NAME "verdant-curves"
#define NAME_MAX_LEN 64
#define MERGE_EPS 1e-9 // an end this close to a sample is the same point (m)

vd_curves_def vd_curves_def_default(void) {
  vd_curves_def d;
  d.sample_step = 0.001;
  d.connect = 0.01;
  d.distance = 0.02;
  d.radius = 0.002;
  d.leaf_length = 0.05;
  d.fruit_radius = 0.01;
  d.slices = 8;
  d.max_samples = 10000000;
  return d;
}

// ---------------------------------------------------------------------------------------------
// the format name without a full parse

// skip white space
static size_t skip_ws(const char* t, size_t n, size_t i) {
  while (i < n && (t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r'))
    i++;
  return i;
}

// index past a JSON string starting at its opening quote, or n when unterminated
static size_t skip_string(const char* t, size_t n, size_t i) {
  for (i++; i < n; i++) {
    if (t[i] == '\\')
      i++;
    else if (t[i] == '"')
      return i + 1;
  }
  return n;
}

// index past one JSON value (objects and arrays by bracket depth)
static size_t skip_value(const char* t, size_t n, size_t i) {
  if (i < n && t[i] == '"') return skip_string(t, n, i);
  int depth = 0;
  for (; i < n; i++) {
    char c = t[i];
    if (c == '"') {
      i = skip_string(t, n, i) - 1;
    } else if (c == '{' || c == '[') {
      depth++;
    } else if (c == '}' || c == ']') {
      if (depth == 0) return i;
      if (--depth == 0) return i + 1;
    } else if (depth == 0 && (c == ',' || c == ' ' || c == '\n' || c == '\r' || c == '\t')) {
      return i;
    }
  }
  return n;
}

const char* vd_plant_json_format(const char* t, size_t n, char* buf, size_t cap) {
  if (!buf || cap == 0) return "";
  buf[0] = 0;
  if (!t) return buf;
  size_t i = skip_ws(t, n, 0);
  if (i >= n || t[i] != '{') return buf;
  i++;
  // top-level members: "key": value, until the closing brace
  for (;;) {
    i = skip_ws(t, n, i);
    if (i >= n || t[i] != '"') return buf;
    size_t k0 = i + 1, k1 = skip_string(t, n, i);
    if (k1 >= n) return buf;
    i = skip_ws(t, n, k1);
    if (i >= n || t[i] != ':') return buf;
    i = skip_ws(t, n, i + 1);
    if (k1 - 1 - k0 == 6 && memcmp(t + k0, "format", 6) == 0) {
      if (i >= n || t[i] != '"') return buf;
      size_t v1 = skip_string(t, n, i);
      if (v1 >= n && t[n - 1] != '"') return buf; // unterminated
      size_t len = v1 - i - 2;
      if (len >= cap) len = cap - 1;
      memcpy(buf, t + i + 1, len);
      buf[len] = 0;
      return buf;
    }
    i = skip_ws(t, n, skip_value(t, n, i));
    if (i >= n || t[i] != ',') return buf;
    i++;
  }
}

// ---------------------------------------------------------------------------------------------
// the parsed file

typedef struct curve {
  int p0, np;              // first point in the point array, count
  int label;               // label id
  char name[NAME_MAX_LEN]; // optional name ("" when none)
} curve;

typedef enum { MARK_LEAF = 0, MARK_FRUIT = 1 } mark_kind;

typedef struct marker {
  mark_kind kind;
  int index;  // position in "leaves" or "fruits"
  vd_vec3 at; // marked point (m)
  int has_dir, has_normal;
  vd_vec3 dir, normal; // leaf axis / fruit direction, leaf surface normal (unit)
  double size;         // leaf length or fruit radius (m), < 0: the def's
  double width;        // leaf width (m), < 0: the length
  int tmpl;            // leaf template
  int label;
} marker;

typedef struct tmpl {
  char name[NAME_MAX_LEN];
  int v0, nv, t0, nt; // ranges in the template vertex and triangle arrays
} tmpl;

typedef struct label_entry {
  int id;
  char name[VD_LABEL_NAME_MAX];
} label_entry;

struct vd_curves {
  vd_curves_def def; // defaults with the file's settings
  char file[256];    // name used in errors
  int has_root;
  vd_vec3 root; // root point (m)
  curve* cv;
  int ncv, cap_cv;
  vd_vec3* pt; // polyline points of all curves (m)
  double* pr;  // radius at each point (m)
  int npt, cap_pt, cap_pr;
  marker* mk;
  int nmk, cap_mk;
  tmpl* tp;
  int ntp, cap_tp;
  vd_vec3* tv; // template vertices (units of leaf length and width)
  int ntv, cap_tv;
  int* tt;         // template triangles, local vertex indices (3 per triangle)
  int ntt, cap_tt; // ints used / capacity
  label_entry* lb;
  int nlb, cap_lb;
};

void vd_curves_destroy(vd_curves* c) {
  if (!c) return;
  vd_free(c->cv, (size_t)c->cap_cv * sizeof *c->cv);
  vd_free(c->pt, (size_t)c->cap_pt * sizeof *c->pt);
  vd_free(c->pr, (size_t)c->cap_pr * sizeof *c->pr);
  vd_free(c->mk, (size_t)c->cap_mk * sizeof *c->mk);
  vd_free(c->tp, (size_t)c->cap_tp * sizeof *c->tp);
  vd_free(c->tv, (size_t)c->cap_tv * sizeof *c->tv);
  vd_free(c->tt, (size_t)c->cap_tt * sizeof *c->tt);
  vd_free(c->lb, (size_t)c->cap_lb * sizeof *c->lb);
  vd_free(c, sizeof *c);
}

vd_curves_def vd_curves_file_def(const vd_curves* c) {
  return c ? c->def : vd_curves_def_default();
}

// ---------------------------------------------------------------------------------------------
// reading

typedef struct rd {
  vd_curves* c;
  const char* file;
  vd_error* err;
} rd;

static vd_status fail(rd* r, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static vd_status fail(rd* r, const char* fmt, ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return vd_error_set(r->err, VD_ERR_FORMAT, r->file, 0, 0, "%s", msg);
}

static vd_status nomem(rd* r) {
  return vd_error_set(r->err, VD_ERR_NOMEM, r->file, 0, 0, "out of memory reading curves");
}

// a finite number in [lo, hi]
static vd_status get_number(rd* r, const cJSON* v, const char* where, double lo, double hi,
                            double* out) {
  if (!cJSON_IsNumber(v)) return fail(r, "%s: expected a number", where);
  double x = v->valuedouble;
  if (!isfinite(x) || x < lo || x > hi)
    return fail(r, "%s: %.17g is not a number in [%g, %g]", where, x, lo, hi);
  *out = x;
  return VD_OK;
}

// [x, y, z] of finite numbers
static vd_status get_vec3(rd* r, const cJSON* v, const char* where, vd_vec3* out) {
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return fail(r, "%s: expected [x, y, z]", where);
  double x[3] = {0};
  int k = 0;
  for (const cJSON* e = v->child; e; e = e->next, k++) {
    char w[160];
    snprintf(w, sizeof w, "%s[%d]", where, k);
    vd_status st = get_number(r, e, w, -HUGE_VAL, HUGE_VAL, &x[k]);
    if (st) return st;
  }
  *out = vd_v3(x[0], x[1], x[2]);
  return VD_OK;
}

// a unit direction from a non-zero [x, y, z]
static vd_status get_dir(rd* r, const cJSON* v, const char* where, vd_vec3* out) {
  vd_status st = get_vec3(r, v, where, out);
  if (st) return st;
  if (!(vd_norm(*out) > 0)) return fail(r, "%s: expected a non-zero direction", where);
  *out = vd_normalize(*out);
  return VD_OK;
}

// reject keys outside `known` (a misspelt key would silently drop what it holds)
static vd_status known_keys(rd* r, const cJSON* obj, const char* where, const char* const* known,
                            int n) {
  for (const cJSON* e = obj->child; e; e = e->next) {
    int ok = 0;
    for (int k = 0; k < n; k++)
      ok |= e->string && strcmp(e->string, known[k]) == 0;
    if (!ok)
      return fail(r, "%s%s%s: unknown key", where, where[0] ? "." : "",
                  e->string ? e->string : "?");
  }
  return VD_OK;
}

static label_entry* find_label_name(vd_curves* c, const char* name) {
  for (int i = 0; i < c->nlb; i++)
    if (strcmp(c->lb[i].name, name) == 0) return &c->lb[i];
  return NULL;
}

static label_entry* find_label_id(vd_curves* c, int id) {
  for (int i = 0; i < c->nlb; i++)
    if (c->lb[i].id == id) return &c->lb[i];
  return NULL;
}

// add a named label; ids must be unique
static vd_status add_label(rd* r, int id, const char* name) {
  vd_curves* c = r->c;
  if (!vd_grow((void**)&c->lb, &c->cap_lb, c->nlb + 1, sizeof *c->lb)) return nomem(r);
  label_entry* e = &c->lb[c->nlb++];
  e->id = id;
  snprintf(e->name, sizeof e->name, "%s", name);
  return VD_OK;
}

// "label": a name (looked up, or given the next free id) or an id; absent: the default name
static vd_status get_label(rd* r, const cJSON* obj, const char* where, const char* dflt, int* out) {
  const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, "label");
  char w[160];
  snprintf(w, sizeof w, "%s.label", where);
  if (v && cJSON_IsNumber(v)) {
    double x = 0;
    vd_status st = get_number(r, v, w, 0, 2147483647.0, &x);
    if (st) return st;
    if (x != floor(x)) return fail(r, "%s: expected an integer id or a name", w);
    *out = (int)x;
    return VD_OK;
  }
  const char* name = dflt;
  if (v) {
    if (!cJSON_IsString(v) || !v->valuestring || !v->valuestring[0])
      return fail(r, "%s: expected a label name or an integer id", w);
    name = v->valuestring;
  }
  label_entry* e = find_label_name(r->c, name);
  if (e) {
    *out = e->id;
    return VD_OK;
  }
  int id = 1;
  for (int i = 0; i < r->c->nlb; i++)
    if (r->c->lb[i].id >= id) id = r->c->lb[i].id + 1;
  vd_status st = add_label(r, id, name);
  *out = id;
  return st;
}

static vd_status read_labels(rd* r, const cJSON* root) {
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(root, "labels");
  if (!a) return VD_OK;
  if (!cJSON_IsArray(a)) return fail(r, "labels: expected an array");
  int k = 0;
  for (const cJSON* e = a->child; e; e = e->next, k++) {
    char w[64];
    snprintf(w, sizeof w, "labels[%d]", k);
    if (!cJSON_IsObject(e)) return fail(r, "%s: expected an object", w);
    static const char* const known[] = {"id", "name"};
    vd_status st = known_keys(r, e, w, known, 2);
    if (st) return st;
    const cJSON* id = cJSON_GetObjectItemCaseSensitive(e, "id");
    const cJSON* name = cJSON_GetObjectItemCaseSensitive(e, "name");
    char wi[80];
    snprintf(wi, sizeof wi, "%s.id", w);
    if (!id) return fail(r, "%s: missing", wi);
    double x = 0;
    if ((st = get_number(r, id, wi, 0, 2147483647.0, &x))) return st;
    if (x != floor(x)) return fail(r, "%s: expected an integer", wi);
    if (!name) return fail(r, "%s.name: missing", w);
    if (!cJSON_IsString(name) || !name->valuestring || !name->valuestring[0])
      return fail(r, "%s.name: expected a non-empty string", w);
    if (find_label_id(r->c, (int)x)) return fail(r, "%s.id: duplicate id %d", w, (int)x);
    if (find_label_name(r->c, name->valuestring))
      return fail(r, "%s.name: duplicate name \"%s\"", w, name->valuestring);
    if ((st = add_label(r, (int)x, name->valuestring))) return st;
  }
  return VD_OK;
}

// "settings": overrides of the defaults, every key optional, unknown keys rejected
static vd_status read_settings(rd* r, const cJSON* root) {
  const cJSON* s = cJSON_GetObjectItemCaseSensitive(root, "settings");
  if (!s) return VD_OK;
  if (!cJSON_IsObject(s)) return fail(r, "settings: expected an object");
  vd_curves_def* d = &r->c->def;
  struct {
    const char* key;
    double* field;
    double lo;
  } keys[] = {{"sample_step", &d->sample_step, 1e-9}, {"connect", &d->connect, 0},
              {"distance", &d->distance, 0},          {"radius", &d->radius, 0},
              {"leaf_length", &d->leaf_length, 0},    {"fruit_radius", &d->fruit_radius, 0}};
  for (const cJSON* e = s->child; e; e = e->next) {
    char w[96];
    snprintf(w, sizeof w, "settings.%s", e->string ? e->string : "?");
    int found = 0;
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
      if (!e->string || strcmp(e->string, keys[k].key) != 0) continue;
      vd_status st = get_number(r, e, w, keys[k].lo, 1e6, keys[k].field);
      if (st) return st;
      found = 1;
    }
    if (!found && e->string && strcmp(e->string, "slices") == 0) {
      double x = 0;
      vd_status st = get_number(r, e, w, 3, 1024, &x);
      if (st) return st;
      if (x != floor(x)) return fail(r, "%s: expected an integer", w);
      d->slices = (int)x;
      found = 1;
    }
    if (!found)
      return fail(r,
                  "%s: unknown setting (expected sample_step, connect, distance, radius, "
                  "leaf_length, fruit_radius or slices)",
                  w);
  }
  return VD_OK;
}

static vd_status read_curves(rd* r, const cJSON* root) {
  vd_curves* c = r->c;
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(root, "curves");
  if (!a) return fail(r, "curves: missing");
  if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) == 0)
    return fail(r, "curves: expected a non-empty array");
  int k = 0;
  for (const cJSON* e = a->child; e; e = e->next, k++) {
    char w[64];
    snprintf(w, sizeof w, "curves[%d]", k);
    if (!cJSON_IsObject(e)) return fail(r, "%s: expected an object", w);
    static const char* const known[] = {"name", "label", "points", "radius"};
    vd_status st = known_keys(r, e, w, known, 4);
    if (st) return st;
    if (!vd_grow((void**)&c->cv, &c->cap_cv, c->ncv + 1, sizeof *c->cv)) return nomem(r);
    curve* cv = &c->cv[c->ncv];
    memset(cv, 0, sizeof *cv);
    // points: at least two
    const cJSON* pts = cJSON_GetObjectItemCaseSensitive(e, "points");
    if (!pts) return fail(r, "%s.points: missing", w);
    int np = cJSON_IsArray(pts) ? cJSON_GetArraySize(pts) : -1;
    if (np < 2) return fail(r, "%s.points: expected an array of at least 2 points [x, y, z]", w);
    if (!vd_grow((void**)&c->pt, &c->cap_pt, c->npt + np, sizeof *c->pt) ||
        !vd_grow((void**)&c->pr, &c->cap_pr, c->npt + np, sizeof *c->pr))
      return nomem(r);
    cv->p0 = c->npt, cv->np = np;
    int q = 0;
    for (const cJSON* p = pts->child; p; p = p->next, q++) {
      char wp[96];
      snprintf(wp, sizeof wp, "%s.points[%d]", w, q);
      if ((st = get_vec3(r, p, wp, &c->pt[c->npt + q]))) return st;
    }
    // radius: one number, or one per point; absent: the def's
    const cJSON* rad = cJSON_GetObjectItemCaseSensitive(e, "radius");
    char wr[96];
    snprintf(wr, sizeof wr, "%s.radius", w);
    for (q = 0; q < np; q++)
      c->pr[c->npt + q] = -1;
    if (rad && cJSON_IsArray(rad)) {
      if (cJSON_GetArraySize(rad) != np)
        return fail(r, "%s: %d values for %d points", wr, cJSON_GetArraySize(rad), np);
      q = 0;
      for (const cJSON* v = rad->child; v; v = v->next, q++) {
        char wq[112];
        snprintf(wq, sizeof wq, "%s[%d]", wr, q);
        if ((st = get_number(r, v, wq, 0, 1e3, &c->pr[c->npt + q]))) return st;
      }
    } else if (rad) {
      double x = 0;
      if ((st = get_number(r, rad, wr, 0, 1e3, &x))) return st;
      for (q = 0; q < np; q++)
        c->pr[c->npt + q] = x;
    }
    // the polyline must have a length
    double len = 0;
    for (q = 1; q < np; q++)
      len += vd_norm(vd_sub(c->pt[c->npt + q], c->pt[c->npt + q - 1]));
    if (!(len > 0)) return fail(r, "%s.points: the curve has zero length", w);
    c->npt += np;
    // name and label
    const cJSON* name = cJSON_GetObjectItemCaseSensitive(e, "name");
    if (name && !cJSON_IsString(name)) return fail(r, "%s.name: expected a string", w);
    if (name) snprintf(cv->name, sizeof cv->name, "%s", name->valuestring);
    if ((st = get_label(r, e, w, "stem", &cv->label))) return st;
    c->ncv++;
  }
  return VD_OK;
}

// a template from "vertices" [[x, y, z], ...] and "triangles" [[i, j, k], ...]
static vd_status read_template(rd* r, const cJSON* t, const char* w, tmpl* out) {
  vd_curves* c = r->c;
  if (!cJSON_IsObject(t)) return fail(r, "%s: expected an object", w);
  static const char* const known[] = {"vertices", "triangles"};
  vd_status st0 = known_keys(r, t, w, known, 2);
  if (st0) return st0;
  const cJSON* v = cJSON_GetObjectItemCaseSensitive(t, "vertices");
  const cJSON* f = cJSON_GetObjectItemCaseSensitive(t, "triangles");
  int nv = v && cJSON_IsArray(v) ? cJSON_GetArraySize(v) : -1;
  int nt = f && cJSON_IsArray(f) ? cJSON_GetArraySize(f) : -1;
  if (nv < 3) return fail(r, "%s.vertices: expected an array of at least 3 points [x, y, z]", w);
  if (nt < 1) return fail(r, "%s.triangles: expected an array of triangles [i, j, k]", w);
  if (!vd_grow((void**)&c->tv, &c->cap_tv, c->ntv + nv, sizeof *c->tv) ||
      !vd_grow((void**)&c->tt, &c->cap_tt, c->ntt + 3 * nt, sizeof *c->tt))
    return nomem(r);
  out->v0 = c->ntv, out->nv = nv, out->t0 = c->ntt, out->nt = nt;
  int k = 0;
  for (const cJSON* e = v->child; e; e = e->next, k++) {
    char wv[160];
    snprintf(wv, sizeof wv, "%s.vertices[%d]", w, k);
    vd_status st = get_vec3(r, e, wv, &c->tv[c->ntv + k]);
    if (st) return st;
  }
  k = 0;
  for (const cJSON* e = f->child; e; e = e->next, k++) {
    char wt[160];
    snprintf(wt, sizeof wt, "%s.triangles[%d]", w, k);
    if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 3)
      return fail(r, "%s: expected [i, j, k]", wt);
    int q = 0;
    for (const cJSON* i = e->child; i; i = i->next, q++) {
      double x = 0;
      char wi[176];
      snprintf(wi, sizeof wi, "%s[%d]", wt, q);
      vd_status st = get_number(r, i, wi, 0, nv - 1, &x);
      if (st) return st;
      if (x != floor(x)) return fail(r, "%s: expected a vertex index", wi);
      c->tt[c->ntt + 3 * k + q] = (int)x;
    }
  }
  c->ntv += nv;
  c->ntt += 3 * nt;
  return VD_OK;
}

// built-in leaf blades, x from base (0) to tip (1), y across, normal +z: a midrib of n intervals
// with edge points at half-width w(x) = h * sin(pi x)^0.7 (widest a little before the middle)
static vd_status builtin_template(rd* r, const char* name, double h) {
  vd_curves* c = r->c;
  const int n = 8;
  int nv = 2 + 3 * (n - 1), nt = 4 * (n - 1) + 2 * 1;
  if (!vd_grow((void**)&c->tp, &c->cap_tp, c->ntp + 1, sizeof *c->tp) ||
      !vd_grow((void**)&c->tv, &c->cap_tv, c->ntv + nv, sizeof *c->tv) ||
      !vd_grow((void**)&c->tt, &c->cap_tt, c->ntt + 3 * nt, sizeof *c->tt))
    return nomem(r);
  tmpl* t = &c->tp[c->ntp++];
  snprintf(t->name, sizeof t->name, "%s", name);
  t->v0 = c->ntv, t->nv = nv, t->t0 = c->ntt, t->nt = 0;
  // vertices: midrib m_0..m_n (0, then 1..n-1 with left and right edges, then the tip)
  vd_vec3* v = c->tv + c->ntv;
  int mid[9], left[9], right[9], nvv = 0;
  for (int i = 0; i <= n; i++) {
    double x = (double)i / n;
    mid[i] = nvv;
    v[nvv++] = vd_v3(x, 0, 0);
    if (i == 0 || i == n) {
      left[i] = right[i] = mid[i];
      continue;
    }
    double w = h * pow(sin(VD_PI * x), 0.7);
    left[i] = nvv;
    v[nvv++] = vd_v3(x, w, 0);
    right[i] = nvv;
    v[nvv++] = vd_v3(x, -w, 0);
  }
  // strips on both sides of the midrib, counter-clockwise seen from +z
  int* tt = c->tt + c->ntt;
  int ntt = 0;
  for (int i = 0; i < n; i++) {
    int tri[4][3] = {{mid[i], mid[i + 1], left[i + 1]},
                     {mid[i], left[i + 1], left[i]},
                     {mid[i], right[i], right[i + 1]},
                     {mid[i], right[i + 1], mid[i + 1]}};
    for (int k = 0; k < 4; k++) {
      if (tri[k][0] == tri[k][1] || tri[k][1] == tri[k][2] || tri[k][2] == tri[k][0]) continue;
      memcpy(tt + 3 * ntt++, tri[k], sizeof tri[k]);
    }
  }
  t->nt = ntt;
  c->ntv += nvv;
  c->ntt += 3 * ntt;
  return VD_OK;
}

static vd_status read_templates(rd* r, const cJSON* root) {
  vd_status st;
  if ((st = builtin_template(r, "blade", 0.25)) || (st = builtin_template(r, "narrow", 0.08)))
    return st;
  const cJSON* o = cJSON_GetObjectItemCaseSensitive(root, "templates");
  if (!o) return VD_OK;
  if (!cJSON_IsObject(o)) return fail(r, "templates: expected an object of named templates");
  for (const cJSON* e = o->child; e; e = e->next) {
    char w[96];
    snprintf(w, sizeof w, "templates.%s", e->string);
    for (int i = 0; i < r->c->ntp; i++)
      if (strcmp(r->c->tp[i].name, e->string) == 0)
        return fail(r, "%s: a template of this name exists already", w);
    if (strlen(e->string) >= NAME_MAX_LEN || !e->string[0])
      return fail(r, "%s: a name of 1 to %d characters expected", w, NAME_MAX_LEN - 1);
    if (!vd_grow((void**)&r->c->tp, &r->c->cap_tp, r->c->ntp + 1, sizeof *r->c->tp))
      return nomem(r);
    tmpl t;
    memset(&t, 0, sizeof t);
    snprintf(t.name, sizeof t.name, "%s", e->string);
    if ((st = read_template(r, e, w, &t))) return st;
    r->c->tp[r->c->ntp++] = t;
  }
  return VD_OK;
}

// "leaves" and "fruits": markers at points of the curves
static vd_status read_markers(rd* r, const cJSON* root, mark_kind kind) {
  vd_curves* c = r->c;
  const char* key = kind == MARK_LEAF ? "leaves" : "fruits";
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(root, key);
  if (!a) return VD_OK;
  if (!cJSON_IsArray(a)) return fail(r, "%s: expected an array", key);
  int k = 0;
  for (const cJSON* e = a->child; e; e = e->next, k++) {
    char w[64], wf[96];
    snprintf(w, sizeof w, "%s[%d]", key, k);
    if (!cJSON_IsObject(e)) return fail(r, "%s: expected an object", w);
    static const char* const kleaf[] = {"at",     "label", "direction", "normal",
                                        "length", "width", "template"};
    static const char* const kfruit[] = {"at", "label", "direction", "radius"};
    vd_status st =
        kind == MARK_LEAF ? known_keys(r, e, w, kleaf, 7) : known_keys(r, e, w, kfruit, 4);
    if (st) return st;
    if (!vd_grow((void**)&c->mk, &c->cap_mk, c->nmk + 1, sizeof *c->mk)) return nomem(r);
    marker m;
    memset(&m, 0, sizeof m);
    m.kind = kind, m.index = k, m.size = -1, m.width = -1;
    const cJSON* at = cJSON_GetObjectItemCaseSensitive(e, "at");
    snprintf(wf, sizeof wf, "%s.at", w);
    if (!at) return fail(r, "%s: missing", wf);
    if ((st = get_vec3(r, at, wf, &m.at))) return st;
    const cJSON* d = cJSON_GetObjectItemCaseSensitive(e, "direction");
    snprintf(wf, sizeof wf, "%s.direction", w);
    if (d && (st = get_dir(r, d, wf, &m.dir))) return st;
    m.has_dir = d != NULL;
    const char* size_key = kind == MARK_LEAF ? "length" : "radius";
    const cJSON* sz = cJSON_GetObjectItemCaseSensitive(e, size_key);
    snprintf(wf, sizeof wf, "%s.%s", w, size_key);
    if (sz && (st = get_number(r, sz, wf, 1e-9, 1e3, &m.size))) return st;
    if (kind == MARK_LEAF) {
      const cJSON* n = cJSON_GetObjectItemCaseSensitive(e, "normal");
      snprintf(wf, sizeof wf, "%s.normal", w);
      if (n && (st = get_dir(r, n, wf, &m.normal))) return st;
      m.has_normal = n != NULL;
      const cJSON* wd = cJSON_GetObjectItemCaseSensitive(e, "width");
      snprintf(wf, sizeof wf, "%s.width", w);
      if (wd && (st = get_number(r, wd, wf, 1e-9, 1e3, &m.width))) return st;
      const cJSON* t = cJSON_GetObjectItemCaseSensitive(e, "template");
      snprintf(wf, sizeof wf, "%s.template", w);
      m.tmpl = 0;
      if (t) {
        if (!cJSON_IsString(t)) return fail(r, "%s: expected a template name", wf);
        m.tmpl = -1;
        for (int i = 0; i < c->ntp; i++)
          if (strcmp(c->tp[i].name, t->valuestring) == 0) m.tmpl = i;
        if (m.tmpl < 0)
          return fail(r, "%s: unknown template \"%s\" (built in: blade, narrow)", wf,
                      t->valuestring);
      }
    }
    if ((st = get_label(r, e, w, kind == MARK_LEAF ? "leaf" : "fruit", &m.label))) return st;
    c->mk[c->nmk++] = m;
  }
  return VD_OK;
}

static vd_status read_root(rd* r, const cJSON* root) {
  if (!cJSON_IsObject(root)) return fail(r, "expected a JSON object at the top level");
  const cJSON* fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
  if (!fmt) return fail(r, "format: missing");
  if (!cJSON_IsString(fmt) || strcmp(fmt->valuestring, FORMAT_NAME) != 0)
    return fail(r, "format: expected \"%s\"", FORMAT_NAME);
  const cJSON* ver = cJSON_GetObjectItemCaseSensitive(root, "version");
  if (!ver) return fail(r, "version: missing");
  if (!cJSON_IsNumber(ver)) return fail(r, "version: expected a number");
  if (ver->valuedouble != VD_CURVES_FORMAT_VERSION)
    return fail(r, "version: %.17g is not supported (this reader knows version %d)",
                ver->valuedouble, VD_CURVES_FORMAT_VERSION);
  const cJSON* units = cJSON_GetObjectItemCaseSensitive(root, "units");
  if (units && (!cJSON_IsString(units) || strcmp(units->valuestring, "m") != 0))
    return fail(r, "units: expected \"m\"");
  static const char* const known[] = {"format", "version", "units",  "labels", "settings",
                                      "root",   "curves",  "leaves", "fruits", "templates"};
  vd_status st = known_keys(r, root, "", known, 10);
  if (st) return st;
  if ((st = read_labels(r, root)) || (st = read_settings(r, root))) return st;
  const cJSON* rt = cJSON_GetObjectItemCaseSensitive(root, "root");
  if (rt) {
    if ((st = get_vec3(r, rt, "root", &r->c->root))) return st;
    r->c->has_root = 1;
  }
  if ((st = read_curves(r, root)) || (st = read_templates(r, root)) ||
      (st = read_markers(r, root, MARK_LEAF)) || (st = read_markers(r, root, MARK_FRUIT)))
    return st;
  return VD_OK;
}

// 1-based line and column (bytes) of offset pos in text
static void line_col(const char* text, size_t len, size_t pos, int* line, int* col) {
  int ln = 1, c = 1;
  for (size_t i = 0; i < pos && i < len; i++) {
    if (text[i] == '\n')
      ln++, c = 1;
    else
      c++;
  }
  *line = ln;
  *col = c;
}

vd_status vd_curves_parse(const char* text, size_t len, const char* name, vd_curves** out,
                          vd_error* err) {
  const char* file = name ? name : "";
  if (out) *out = NULL;
  if (!out || (!text && len)) return vd_error_set(err, VD_ERR_ARG, file, 0, 0, "null argument");
  if (len > VD_FILE_MAX)
    return vd_error_set(err, VD_ERR_LIMIT, file, 0, 0, "input larger than %zu bytes",
                        (size_t)VD_FILE_MAX);
  if (len == 0)
    return vd_error_set(err, VD_ERR_FORMAT, file, 0, 0, "empty input: expected a curves object");
  // parse; on failure report where cJSON stopped, and nothing but white space after the value
  const char* end = NULL;
  cJSON* root = cJSON_ParseWithLengthOpts(text, len, &end, 0);
  size_t pos = (end && end >= text) ? (size_t)(end - text) : 0;
  if (root) pos = skip_ws(text, len, pos);
  if (!root || pos < len) {
    int line, col;
    line_col(text, len, pos, &line, &col);
    cJSON_Delete(root);
    return vd_error_set(err, VD_ERR_FORMAT, file, line, col,
                        root ? "text after the JSON value" : "invalid JSON");
  }
  vd_curves* c = vd_calloc(1, sizeof *c);
  if (!c) {
    cJSON_Delete(root);
    return vd_error_set(err, VD_ERR_NOMEM, file, 0, 0, "out of memory reading curves");
  }
  c->def = vd_curves_def_default();
  snprintf(c->file, sizeof c->file, "%s", file);
  rd r = {c, file, err};
  vd_status st = read_root(&r, root);
  cJSON_Delete(root);
  if (st) {
    vd_curves_destroy(c);
    return st;
  }
  *out = c;
  return VD_OK;
}

vd_status vd_curves_read(const char* path, vd_curves** out, vd_error* err) {
  if (out) *out = NULL;
  if (!path || !out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "null argument");
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  st = vd_curves_parse(text, len, path, out, err);
  vd_free(text, len + 1);
  return st;
}

// ---------------------------------------------------------------------------------------------
// building

typedef struct build {
  const vd_curves* c;
  vd_curves_def def;
  vd_error* err;
  int64_t ns;          // dense samples
  int* base;           // first sample of each curve (ncv + 1)
  vd_vec3* pos;        // sample positions (ns)
  double* rad;         // sample radii (ns)
  int* cof;            // curve of each sample (ns)
  int* parent;         // tree parent sample, -1 for the root and merged samples (ns)
  unsigned char* flag; // bit 0 alive, bit 1 key, bit 2 kept (ns)
  int* anchor;         // nearest kept ancestor (ns)
  double* dist;        // path distance from the anchor (m) (ns)
  int* cstart;         // children CSR: row starts (ns + 1)
  int* child;          // children, ascending (ns)
  int* order;          // preorder of the live samples (ns)
  int* mark_node;      // sample of each marker (nmk)
  int* depth;          // BFS layer of each curve (ncv)
  double* start_rad;   // radius at each curve's attaching end (ncv)
  int root;            // root sample
} build;

#define ALIVE 1u
#define KEY 2u
#define KEPT 4u

static void build_free(build* b) {
  size_t ns = (size_t)b->ns, nc = (size_t)b->c->ncv;
  vd_free(b->base, (nc + 1) * sizeof(int));
  vd_free(b->pos, ns * sizeof(vd_vec3));
  vd_free(b->rad, ns * sizeof(double));
  vd_free(b->cof, ns * sizeof(int));
  vd_free(b->parent, ns * sizeof(int));
  vd_free(b->flag, ns);
  vd_free(b->anchor, ns * sizeof(int));
  vd_free(b->dist, ns * sizeof(double));
  vd_free(b->cstart, (ns + 1) * sizeof(int));
  vd_free(b->child, ns * sizeof(int));
  vd_free(b->order, ns * sizeof(int));
  vd_free(b->mark_node, ((size_t)b->c->nmk + 1) * sizeof(int));
  vd_free(b->depth, nc * sizeof(int));
  vd_free(b->start_rad, nc * sizeof(double));
}

static vd_status bnomem(build* b) {
  return vd_error_set(b->err, VD_ERR_NOMEM, b->c->file, 0, 0, "out of memory building curves");
}

// dense samples of every polyline: n intervals of at most sample_step, both ends included
static vd_status sample(build* b) {
  const vd_curves* c = b->c;
  int nc = c->ncv;
  b->base = vd_malloc(((size_t)nc + 1) * sizeof(int));
  if (!b->base) return bnomem(b);
  int64_t ns = 0;
  for (int k = 0; k < nc; k++) {
    const curve* cv = &c->cv[k];
    double len = 0;
    for (int q = 1; q < cv->np; q++)
      len += vd_norm(vd_sub(c->pt[cv->p0 + q], c->pt[cv->p0 + q - 1]));
    double n = ceil(len / b->def.sample_step - 1e-9);
    if (n < 1) n = 1;
    if ((double)ns + n + 1 > (double)b->def.max_samples || (double)ns + n + 1 > 0x7fffffff)
      return vd_error_set(b->err, VD_ERR_LIMIT, c->file, 0, 0,
                          "curves: more than %lld samples at sample_step %g m; use a larger step",
                          (long long)b->def.max_samples, b->def.sample_step);
    b->base[k] = (int)ns;
    ns += (int64_t)n + 1;
  }
  b->base[nc] = (int)ns;
  b->ns = ns;
  size_t s = (size_t)ns;
  b->pos = vd_malloc(s * sizeof(vd_vec3));
  b->rad = vd_malloc(s * sizeof(double));
  b->cof = vd_malloc(s * sizeof(int));
  b->parent = vd_malloc(s * sizeof(int));
  b->flag = vd_calloc(s, 1);
  b->anchor = vd_malloc(s * sizeof(int));
  b->dist = vd_malloc(s * sizeof(double));
  b->cstart = vd_calloc(s + 1, sizeof(int));
  b->child = vd_malloc(s * sizeof(int));
  b->order = vd_malloc(s * sizeof(int));
  b->mark_node = vd_malloc(((size_t)c->nmk + 1) * sizeof(int));
  b->depth = vd_malloc((size_t)nc * sizeof(int));
  b->start_rad = vd_malloc((size_t)nc * sizeof(double));
  if (!b->pos || !b->rad || !b->cof || !b->parent || !b->flag || !b->anchor || !b->dist ||
      !b->cstart || !b->child || !b->order || !b->mark_node || !b->depth || !b->start_rad)
    return bnomem(b);
  // walk each polyline at equal arc-length steps, radii linear along it
  for (int k = 0; k < nc; k++) {
    const curve* cv = &c->cv[k];
    const vd_vec3* p = c->pt + cv->p0;
    const double* pr = c->pr + cv->p0;
    int n = b->base[k + 1] - b->base[k] - 1;
    double len = 0;
    for (int q = 1; q < cv->np; q++)
      len += vd_norm(vd_sub(p[q], p[q - 1]));
    int q = 0;
    double s0 = 0; // arc length at p[q]
    for (int i = 0; i <= n; i++) {
      double arc = i == n ? len : len * i / n;
      double l = vd_norm(vd_sub(p[q + 1], p[q]));
      while (q + 2 < cv->np && arc > s0 + l)
        s0 += l, q++, l = vd_norm(vd_sub(p[q + 1], p[q]));
      double f = l > 0 ? (arc - s0) / l : 0;
      f = f < 0 ? 0 : (f > 1 ? 1 : f);
      int id = b->base[k] + i;
      b->pos[id] =
          i == n ? p[cv->np - 1] : (i == 0 ? p[0] : vd_madd(p[q], vd_sub(p[q + 1], p[q]), f));
      double r0 = pr[q] >= 0 ? pr[q] : b->def.radius,
             r1 = pr[q + 1] >= 0 ? pr[q + 1] : b->def.radius;
      b->rad[id] = i == n ? r1 : r0 + f * (r1 - r0);
      b->cof[id] = k;
      b->flag[id] = ALIVE;
      b->parent[id] = -1;
    }
  }
  return VD_OK;
}

// nearest sample of curve k to point x (the lowest index on ties)
static int nearest_on_curve(const build* b, int k, vd_vec3 x, double* d) {
  int best = -1;
  double bd = HUGE_VAL;
  for (int i = b->base[k]; i < b->base[k + 1]; i++) {
    if (!(b->flag[i] & ALIVE)) continue;  // NOLINT(clang-analyzer-core.NullDereference): arrays sized by the sample count, > 0 here
    double e = vd_norm(vd_sub(b->pos[i], x));
    if (e < bd) bd = e, best = i;
  }
  *d = bd;
  return best;
}

// link the samples of curve k to the tree, walking away from its end `end` (0 first, 1 last)
// attached to sample u; an end on u itself is merged into u
static void link_curve(build* b, int k, int end, int u, double gap) {
  int n = b->base[k + 1] - b->base[k];
  int prev = u;
  for (int j = 0; j < n; j++) {
    int id = end == 0 ? b->base[k] + j : b->base[k + 1] - 1 - j;
    if (j == 0 && gap <= MERGE_EPS) {
      b->flag[id] &= (unsigned char)~ALIVE;
      continue;
    }
    b->parent[id] = prev;
    prev = id;
  }
  b->start_rad[k] = b->rad[end == 0 ? b->base[k] : b->base[k + 1] - 1];
}

// the gap of every end of every unconnected curve to the samples of curve p, kept when smaller
// than the best so far (ties keep the earlier connected curve)
static void update_gaps(build* b, int p, double* gap, int* at, int* end) {
  const vd_curves* c = b->c;
  for (int k = 0; k < c->ncv; k++) {
    if (b->depth[k] >= 0) continue;
    for (int e = 0; e < 2; e++) {
      vd_vec3 x = c->pt[e == 0 ? c->cv[k].p0 : c->cv[k].p0 + c->cv[k].np - 1];
      double d;
      int u = nearest_on_curve(b, p, x, &d);
      if (u >= 0 && d < gap[k]) gap[k] = d, at[k] = u, end[k] = e;
    }
  }
}

// grow the tree over the curves from the root curve: repeatedly the unconnected curve with the
// smallest gap to the connected ones joins there (ties: the lower curve index), by whichever end
// is nearer, while the gap is within sigma_connect. A best-first search from the root: a
// pedicel drawn from a peduncle's tip joins the peduncle even when the stem passes nearby.
static vd_status connect(build* b, vd_curves_stats* stats) {
  const vd_curves* c = b->c;
  int nc = c->ncv;
  // the root: the given point's nearest sample, or the first point of the first curve
  int rc = 0;
  b->root = b->base[0];
  if (c->has_root) {
    double bd = HUGE_VAL;
    for (int k = 0; k < nc; k++) {
      double d;
      int i = nearest_on_curve(b, k, c->root, &d);
      if (d < bd) bd = d, b->root = i, rc = k;
    }
    if (bd > b->def.connect)
      return vd_error_set(b->err, VD_ERR_VALUE, c->file, 0, 0,
                          "root: no curve within connect = %g m (the nearest is %g m away)",
                          b->def.connect, bd);
  }
  // the root curve runs both ways from the root sample
  for (int i = b->base[rc]; i < b->base[rc + 1]; i++)
    b->parent[i] = i < b->root ? i + 1 : (i > b->root ? i - 1 : -1);  // NOLINT(clang-analyzer-core.NullDereference): arrays sized by the sample count, > 0 here
  b->start_rad[rc] = b->rad[b->root];  // NOLINT(clang-analyzer-core.NullDereference): arrays sized by the sample count, > 0 here
  b->flag[b->root] |= KEY;
  for (int k = 0; k < nc; k++)
    b->depth[k] = -1;
  b->depth[rc] = 0;
  double* gap = vd_malloc((size_t)nc * sizeof(double));
  int* at = vd_malloc((size_t)nc * sizeof(int));
  int* end = vd_malloc((size_t)nc * sizeof(int));
  if (!gap || !at || !end) {
    vd_free(gap, (size_t)nc * sizeof(double));
    vd_free(at, (size_t)nc * sizeof(int));
    vd_free(end, (size_t)nc * sizeof(int));
    return bnomem(b);
  }
  for (int k = 0; k < nc; k++)
    gap[k] = HUGE_VAL, at[k] = -1, end[k] = 0;
  update_gaps(b, rc, gap, at, end);
  for (;;) {
    int k = -1;
    for (int q = 0; q < nc; q++)
      if (b->depth[q] < 0 && (k < 0 || gap[q] < gap[k])) k = q;
    if (k < 0 || !(gap[k] <= b->def.connect)) break;
    // curve k joins at sample at[k]: a key node between two curves
    b->depth[k] = b->depth[b->cof[at[k]]] + 1;
    link_curve(b, k, end[k], at[k], gap[k]);
    b->flag[at[k]] |= KEY;
    stats->nconnect++;
    if (gap[k] > MERGE_EPS) stats->ngap++;
    update_gaps(b, k, gap, at, end);
  }
  // every curve must have joined
  vd_status st = VD_OK;
  for (int k = 0; k < nc && !st; k++)
    if (b->depth[k] < 0)
      st = vd_error_set(b->err, VD_ERR_VALUE, c->file, 0, 0,
                        "curves[%d]%s%s%s: not connected to the plant: its ends are %g m from the "
                        "nearest connected curve, more than connect = %g m",
                        k, c->cv[k].name[0] ? " (" : "", c->cv[k].name, c->cv[k].name[0] ? ")" : "",
                        gap[k], b->def.connect);
  vd_free(gap, (size_t)nc * sizeof(double));
  vd_free(at, (size_t)nc * sizeof(int));
  vd_free(end, (size_t)nc * sizeof(int));
  return st;
}

// leaf and fruit markers: the nearest live sample, which becomes a key node
static vd_status place_markers(build* b) {
  const vd_curves* c = b->c;
  for (int m = 0; m < c->nmk; m++) {
    double bd = HUGE_VAL;
    int bi = -1;
    for (int k = 0; k < c->ncv; k++) {
      double d;
      int i = nearest_on_curve(b, k, c->mk[m].at, &d);
      if (d < bd) bd = d, bi = i;
    }
    if (bd > b->def.connect)
      return vd_error_set(b->err, VD_ERR_VALUE, c->file, 0, 0,
                          "%s[%d].at: no curve within connect = %g m (the nearest is %g m away)",
                          c->mk[m].kind == MARK_LEAF ? "leaves" : "fruits", c->mk[m].index,
                          b->def.connect, bd);
    b->mark_node[m] = bi;
    b->flag[bi] |= KEY;
  }
  return VD_OK;
}

// children lists (ascending), degrees to key nodes, and the preorder of the tree
static void tree(build* b) {
  int ns = (int)b->ns;
  for (int i = 0; i < ns; i++)
    if ((b->flag[i] & ALIVE) && b->parent[i] >= 0) b->cstart[b->parent[i] + 1]++;
  for (int i = 0; i < ns; i++)
    b->cstart[i + 1] += b->cstart[i];
  int* fill = b->order; // borrowed before the preorder is written
  for (int i = 0; i < ns; i++)
    fill[i] = b->cstart[i];
  for (int i = 0; i < ns; i++)
    if ((b->flag[i] & ALIVE) && b->parent[i] >= 0) b->child[fill[b->parent[i]]++] = i;
  // key nodes: the root, tips and junctions (degree not 2)
  for (int i = 0; i < ns; i++) {
    if (!(b->flag[i] & ALIVE)) continue;
    int deg = (b->parent[i] >= 0) + (b->cstart[i + 1] - b->cstart[i]);
    if (deg != 2 || i == b->root) b->flag[i] |= KEY;
  }
  // preorder by an explicit stack; children pushed in reverse so the lowest comes first
  int top = 0, n = 0;
  int* stack = b->anchor; // borrowed: anchors are written after the walk
  stack[top++] = b->root;
  while (top) {
    int u = stack[--top];
    b->order[n++] = u;
    for (int e = b->cstart[u + 1] - 1; e >= b->cstart[u]; e--)
      stack[top++] = b->child[e];
  }
}

// depth-first simplification (the preorder is a depth-first walk)
static void simplify(build* b) {
  double sig = b->def.distance;
  int ns = (int)b->ns;
  for (int i = 0; i < ns; i++)
    b->anchor[i] = -1, b->dist[i] = 0;
  // live samples are exactly those in the preorder
  int nlive = 0;
  for (int i = 0; i < ns; i++)
    nlive += (b->flag[i] & ALIVE) != 0;
  for (int q = 0; q < nlive; q++) {
    int u = b->order[q];
    if (u == b->root) {
      b->flag[u] |= KEPT;
      continue;
    }
    int p = b->parent[u];
    int a = (b->flag[p] & KEPT) ? p : b->anchor[p];
    double d = ((b->flag[p] & KEPT) ? 0 : b->dist[p]) + vd_norm(vd_sub(b->pos[u], b->pos[p]));
    b->anchor[u] = a;
    b->dist[u] = d;
    if (b->flag[u] & KEY) {
      // a key node too close to a plain kept ancestor replaces it
      if (d < 0.5 * sig * (1 - 1e-9) && !(b->flag[a] & KEY)) {
        b->flag[a] &= (unsigned char)~KEPT;
        d += b->dist[a];
        b->anchor[u] = b->anchor[a];
        b->dist[u] = d;
      }
      b->flag[u] |= KEPT;
    } else if (d >= sig * (1 - 1e-9)) {
      b->flag[u] |= KEPT;
    }
  }
}

// unit vector orthogonal to unit v (from the world axis least aligned with it)
static vd_vec3 any_perp(vd_vec3 v) {
  double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
  vd_vec3 a =
      (ax <= ay && ax <= az) ? vd_v3(1, 0, 0) : (ay <= az ? vd_v3(0, 1, 0) : vd_v3(0, 0, 1));
  return vd_normalize(vd_madd(a, v, -vd_dot(a, v)));
}

// part of v orthogonal to unit n, normalised, or any perpendicular when v is along n
static vd_vec3 ortho(vd_vec3 v, vd_vec3 n) {
  vd_vec3 o = vd_madd(v, n, -vd_dot(v, n));
  double l = vd_norm(o);
  return l > 1e-9 ? vd_scale(o, 1.0 / l) : any_perp(n);
}

// direction of the plant at sample u: from its parent, else toward its first child
static vd_vec3 tangent(const build* b, int u) {
  int p = b->parent[u];
  if (p >= 0) return vd_normalize(vd_sub(b->pos[u], b->pos[p]));
  if (b->cstart[u + 1] > b->cstart[u])
    return vd_normalize(vd_sub(b->pos[b->child[b->cstart[u]]], b->pos[u]));
  return vd_v3(0, 0, 1);
}

// is u the end of its curve (no live child on the same curve)?
static int curve_tip(const build* b, int u) {
  for (int e = b->cstart[u]; e < b->cstart[u + 1]; e++)
    if (b->cof[b->child[e]] == b->cof[u]) return 0;
  return 1;
}

static vd_status emit(build* b, vd_plant_spec* s, vd_curves_stats* stats) {
  const vd_curves* c = b->c;
  int ns = (int)b->ns, nlive = 0;
  for (int i = 0; i < ns; i++)
    nlive += (b->flag[i] & ALIVE) != 0;
  // spec node and segment of every kept sample
  int* nid = vd_malloc((size_t)ns * sizeof(int));
  int* sid = vd_malloc((size_t)ns * sizeof(int));
  vd_vec3* up = vd_malloc((size_t)ns * sizeof(vd_vec3));
  unsigned char* cont = vd_calloc((size_t)ns, 1); // a kept node continued on its own curve
  vd_status st = VD_OK;
  if (!nid || !sid || !up || !cont) {
    st = bnomem(b);
    goto done;
  }
  int inst0 = s->ninstance;
  for (int q = 0; q < nlive; q++) {
    int u = b->order[q];
    if ((b->flag[u] & KEPT) && u != b->root && b->cof[b->anchor[u]] == b->cof[u])
      cont[b->anchor[u]] = 1;
  }
  for (int q = 0; q < nlive; q++) {
    int u = b->order[q];
    if (!(b->flag[u] & KEPT)) continue;
    nid[u] = vd_plant_add_node(s, b->pos[u]);
    sid[u] = -1;
    if (nid[u] < 0) {
      st = bnomem(b);
      goto done;
    }
    stats->nnode++;
    if (u == b->root) continue;
    // the segment from the nearest kept ancestor
    int a = b->anchor[u], k = b->cof[u];
    vd_vec3 dir = vd_sub(b->pos[u], b->pos[a]);
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = nid[a], g.node1 = nid[u];
    g.r0 = b->cof[a] == k ? b->rad[a] : b->start_rad[k];
    g.r1 = b->rad[u];
    g.parent = sid[a];
    g.label = c->cv[k].label;
    g.instance = inst0 + k + 1;
    g.axis = k;
    g.order = b->depth[k];
    g.slices = b->def.slices;
    // smooth joints along a curve, and where a curve goes on from another's end
    int same = b->cof[a] == k;
    g.flags = (same || !cont[a]) ? VD_SEG_GC : 0;
    if (curve_tip(b, u)) g.flags |= VD_SEG_TIP;
    // up: carried along from the parent segment (parallel transport), else any perpendicular
    vd_vec3 t = vd_norm(dir) > 0 ? vd_normalize(dir) : tangent(b, u);
    up[u] = sid[a] >= 0 ? ortho(up[a], t) : any_perp(t);
    g.up = up[u];
    sid[u] = vd_plant_add_segment(s, &g);
    if (sid[u] < 0) {
      st = bnomem(b);
      goto done;
    }
    stats->nseg++;
  }
  // leaves and fruits at their nodes
  for (int m = 0; m < c->nmk; m++) {
    const marker* mk = &c->mk[m];
    int u = b->mark_node[m];
    vd_vec3 t = tangent(b, u);
    int tip = b->cstart[u + 1] == b->cstart[u];
    vd_vec3 pos = b->pos[u];
    int inst = inst0 + c->ncv + m + 1;
    if (mk->kind == MARK_FRUIT) {
      // hanging (or continuing a pedicel's tip), touching its node
      double r = mk->size > 0 ? mk->size : b->def.fruit_radius;
      vd_vec3 d = mk->has_dir ? mk->dir : (tip ? t : vd_v3(0, 0, -1));
      vd_sphere_spec f = vd_sphere_spec_default();
      f.center = vd_madd(pos, d, r);
      f.radius = r;
      f.node = nid[u];
      f.parent = sid[u];
      f.label = mk->label;
      f.instance = inst;
      f.slices = b->def.slices;
      if (vd_plant_add_sphere(s, &f) < 0) {
        st = bnomem(b);
        goto done;
      }
      stats->nfruit++;
      continue;
    }
    // leaf frame: x along the leaf, z its normal, y = z x x
    vd_vec3 dx = mk->has_dir ? mk->dir : (tip ? t : vd_cross(t, vd_v3(0, 0, 1)));
    if (!(vd_norm(dx) > 1e-9)) dx = vd_v3(1, 0, 0);
    dx = vd_normalize(dx);
    vd_vec3 dz = ortho(mk->has_normal ? mk->normal : vd_v3(0, 0, 1), dx);
    vd_vec3 dy = vd_cross(dz, dx);
    double len = mk->size > 0 ? mk->size : b->def.leaf_length;
    double wid = mk->width > 0 ? mk->width : len;
    const tmpl* tp = &c->tp[mk->tmpl];
    vd_vec3* v = vd_malloc((size_t)tp->nv * sizeof *v);
    if (!v) {
      st = bnomem(b);
      goto done;
    }
    for (int i = 0; i < tp->nv; i++) {
      vd_vec3 l = c->tv[tp->v0 + i];
      v[i] = vd_add(pos, vd_add(vd_scale(dx, l.x * len),
                                vd_add(vd_scale(dy, l.y * wid), vd_scale(dz, l.z * len))));
    }
    vd_mesh_spec ms;
    memset(&ms, 0, sizeof ms);
    ms.closed = 0;
    ms.node = nid[u];
    ms.parent = sid[u];
    ms.label = mk->label;
    ms.instance = inst;
    ms.module = -1;
    int mi = vd_plant_add_mesh(s, &ms, v, tp->nv, c->tt + tp->t0, tp->nt);
    vd_free(v, (size_t)tp->nv * sizeof *v);
    if (mi < 0) {
      st = bnomem(b);
      goto done;
    }
    stats->nleaf++;
  }
  // label names of the labels in use
  for (int i = 0; i < c->nlb; i++) {
    int used = 0;
    for (int k = 0; k < c->ncv; k++)
      used |= c->cv[k].label == c->lb[i].id;
    for (int m = 0; m < c->nmk; m++)
      used |= c->mk[m].label == c->lb[i].id;
    if (used && vd_plant_set_label(s, c->lb[i].id, c->lb[i].name)) {
      st = bnomem(b);
      goto done;
    }
  }
done:
  vd_free(nid, (size_t)ns * sizeof(int));
  vd_free(sid, (size_t)ns * sizeof(int));
  vd_free(up, (size_t)ns * sizeof(vd_vec3));
  vd_free(cont, (size_t)ns);
  return st;
}

vd_status vd_curves_build(const vd_curves* c, const vd_curves_def* def, vd_plant_spec* spec,
                          vd_curves_stats* stats_out, vd_error* err) {
  if (!c || !spec) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "curves: null argument");
  build b;
  memset(&b, 0, sizeof b);
  b.c = c;
  b.def = def ? *def : c->def;
  b.err = err;
  // settings in range
  const vd_curves_def* d = &b.def;
  if (!(d->sample_step > 0) || !(d->connect >= 0) || !(d->distance >= 0) || !(d->radius >= 0) ||
      !(d->leaf_length > 0) || !(d->fruit_radius > 0) || !isfinite(d->sample_step) ||
      !isfinite(d->connect) || !isfinite(d->distance) || !isfinite(d->radius) || d->slices < 3 ||
      d->max_samples < 1)
    return vd_error_set(err, VD_ERR_ARG, c->file, 0, 0,
                        "curves: settings out of range (sample_step > 0, connect, distance and "
                        "radius >= 0, leaf_length and fruit_radius > 0, slices >= 3)");
  vd_curves_stats stats;
  memset(&stats, 0, sizeof stats);
  stats.ncurve = c->ncv;
  vd_status st = sample(&b);
  if (!st) stats.nsample = b.ns;
  if (!st) st = connect(&b, &stats);
  if (!st) st = place_markers(&b);
  if (!st) {
    tree(&b);
    simplify(&b);
    st = emit(&b, spec, &stats);
  }
  build_free(&b);
  if (stats_out) *stats_out = stats;
  return st;
}
