// SPDX-License-Identifier: MIT
// Plant JSON (docs/formats.md): a columnar layout, one array per field, so big plants stay
// compact. Writing streams the file (shortest round-trip numbers, atomic rename); reading parses
// with cJSON and validates every field, naming it in the error.
#include <cjson/cJSON.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "plant_internal.h"

#define FORMAT_NAME "verdant-plant"

// element types a column can hold
typedef enum { COL_INT, COL_UINT, COL_I64, COL_DBL } col_type;

static size_t col_size(col_type t) {
  switch (t) {
  case COL_INT:
    return sizeof(int);
  case COL_UINT:
    return sizeof(unsigned);
  case COL_I64:
    return sizeof(int64_t);
  default:
    return sizeof(double);
  }
}

// address of element k of a column: record k/width of base, field at off, slot k%width
static void* col_at(const void* base, size_t stride, size_t off, int width, col_type t, size_t k) {
  return (char*)base + (k / (size_t)width) * stride + off + (k % (size_t)width) * col_size(t);
}

// ---------------------------------------------------------------------------------------------
// writing

typedef struct jw {
  FILE* fp;
  int nonfinite; // a NaN or infinity was met (the file is not written)
} jw;

// shortest of %.15g, %.16g, %.17g that reads back to the same double
static void fmt_double(char* buf, size_t cap, double v) {
  // integral values below 1e15 print the same digits as %.15g, without the search
  if (v == floor(v) && fabs(v) < 1e15 && !(v == 0 && signbit(v))) {
    snprintf(buf, cap, "%lld", (long long)v);
    return;
  }
  for (int prec = 15; prec <= 17; prec++) {
    snprintf(buf, cap, "%.*g", prec, v);
    if (prec == 17 || strtod(buf, NULL) == v) return;
  }
}

// shortest %.Ng (N = 6..9) that reads back to the same float
static void fmt_float(char* buf, size_t cap, float v) {
  for (int prec = 6; prec <= 9; prec++) {
    snprintf(buf, cap, "%.*g", prec, (double)v);
    if (prec == 9 || (float)strtod(buf, NULL) == v) return;
  }
}

static void w_double(jw* w, double v) {
  char buf[40];
  if (!isfinite(v)) {
    w->nonfinite = 1;
    v = 0;
  }
  fmt_double(buf, sizeof buf, v);
  fputs(buf, w->fp);
}

// JSON string with quotes, control characters escaped
static void w_string(jw* w, const char* s) {
  fputc('"', w->fp);
  for (const unsigned char* p = (const unsigned char*)s; *p; p++) {
    if (*p == '"' || *p == '\\')
      fprintf(w->fp, "\\%c", *p);
    else if (*p < 0x20)
      fprintf(w->fp, "\\u%04x", *p);
    else
      fputc(*p, w->fp);
  }
  fputc('"', w->fp);
}

// one column: "key": [v0, v1, ...] with n*width values
static void w_col(jw* w, const char* indent, const char* key, col_type t, const void* base,
                  size_t stride, size_t off, int n, int width, int last) {
  fprintf(w->fp, "%s\"%s\": [", indent, key);
  size_t total = (size_t)n * (size_t)width;
  for (size_t k = 0; k < total; k++) {
    if (k) fputc(',', w->fp);
    const void* p = col_at(base, stride, off, width, t, k);
    switch (t) {
    case COL_INT:
      fprintf(w->fp, "%d", *(const int*)p);
      break;
    case COL_UINT:
      fprintf(w->fp, "%u", *(const unsigned*)p);
      break;
    case COL_I64:
      fprintf(w->fp, "%lld", (long long)*(const int64_t*)p);
      break;
    case COL_DBL:
      w_double(w, *(const double*)p);
      break;
    }
  }
  fprintf(w->fp, "]%s\n", last ? "" : ",");
}

// a stress column: NaN (no stress there) is written as null
static void w_stress(jw* w, const char* key, const double* v, int n, int last) {
  fprintf(w->fp, "    \"%s\": [", key);
  for (int k = 0; k < n; k++) {
    if (k) fputc(',', w->fp);
    if (isnan(v[k])) fputs("null", w->fp);
    else w_double(w, v[k]);
  }
  fprintf(w->fp, "]%s\n", last ? "" : ",");
}

static void write_stress(jw* w, const vd_plant_spec* s) {
  if (!vd_plant_has_stress(s)) return;
  fprintf(w->fp, "  \"stress\": {\n    \"unit\": \"Pa\",\n");
  w_stress(w, "node", s->node_stress, s->nnode, 0);
  w_stress(w, "segment", s->seg_stress, s->nseg, 1);
  fprintf(w->fp, "  },\n");
}

static void write_labels(jw* w, const vd_plant_spec* s) {
  fprintf(w->fp, "  \"labels\": [");
  for (int i = 0; i < s->nlabel; i++) {
    const vd_label* l = &s->label[i];
    char c[3][24];
    for (int k = 0; k < 3; k++)
      fmt_float(c[k], sizeof c[k], isfinite(l->rgb[k]) ? l->rgb[k] : 0);
    fprintf(w->fp, "%s\n    {\"id\": %d, \"name\": ", i ? "," : "", l->id);
    w_string(w, l->name);
    fprintf(w->fp, ", \"organ\": \"%s\", \"rgb\": [%s, %s, %s]}", vd_organ_name(l->organ), c[0],
            c[1], c[2]);
  }
  fprintf(w->fp, "%s],\n", s->nlabel ? "\n  " : "");
}

static void write_segments(jw* w, const vd_plant_spec* s) {
  const char* in = "    ";
  size_t st = sizeof(vd_segment_spec);
  int n = s->nseg;
  fprintf(w->fp, "  \"segments\": {\n");
  w_col(w, in, "node0", COL_INT, s->seg, st, offsetof(vd_segment_spec, node0), n, 1, 0);
  w_col(w, in, "node1", COL_INT, s->seg, st, offsetof(vd_segment_spec, node1), n, 1, 0);
  w_col(w, in, "r0", COL_DBL, s->seg, st, offsetof(vd_segment_spec, r0), n, 1, 0);
  w_col(w, in, "r1", COL_DBL, s->seg, st, offsetof(vd_segment_spec, r1), n, 1, 0);
  w_col(w, in, "up", COL_DBL, s->seg, st, offsetof(vd_segment_spec, up), n, 3, 0);
  w_col(w, in, "parent", COL_INT, s->seg, st, offsetof(vd_segment_spec, parent), n, 1, 0);
  w_col(w, in, "label", COL_INT, s->seg, st, offsetof(vd_segment_spec, label), n, 1, 0);
  w_col(w, in, "instance", COL_INT, s->seg, st, offsetof(vd_segment_spec, instance), n, 1, 0);
  w_col(w, in, "axis", COL_INT, s->seg, st, offsetof(vd_segment_spec, axis), n, 1, 0);
  w_col(w, in, "order", COL_INT, s->seg, st, offsetof(vd_segment_spec, order), n, 1, 0);
  w_col(w, in, "flags", COL_UINT, s->seg, st, offsetof(vd_segment_spec, flags), n, 1, 0);
  w_col(w, in, "slices", COL_INT, s->seg, st, offsetof(vd_segment_spec, slices), n, 1, 0);
  w_col(w, in, "age", COL_DBL, s->seg, st, offsetof(vd_segment_spec, age), n, 1, 0);
  w_col(w, in, "module", COL_I64, s->seg, st, offsetof(vd_segment_spec, module), n, 1, 1);
  fprintf(w->fp, "  },\n");
}

static void write_spheres(jw* w, const vd_plant_spec* s) {
  const char* in = "    ";
  size_t st = sizeof(vd_sphere_spec);
  int n = s->nsphere;
  fprintf(w->fp, "  \"spheres\": {\n");
  w_col(w, in, "center", COL_DBL, s->sphere, st, offsetof(vd_sphere_spec, center), n, 3, 0);
  w_col(w, in, "radius", COL_DBL, s->sphere, st, offsetof(vd_sphere_spec, radius), n, 1, 0);
  w_col(w, in, "node", COL_INT, s->sphere, st, offsetof(vd_sphere_spec, node), n, 1, 0);
  w_col(w, in, "parent", COL_INT, s->sphere, st, offsetof(vd_sphere_spec, parent), n, 1, 0);
  w_col(w, in, "label", COL_INT, s->sphere, st, offsetof(vd_sphere_spec, label), n, 1, 0);
  w_col(w, in, "instance", COL_INT, s->sphere, st, offsetof(vd_sphere_spec, instance), n, 1, 0);
  w_col(w, in, "slices", COL_INT, s->sphere, st, offsetof(vd_sphere_spec, slices), n, 1, 0);
  w_col(w, in, "module", COL_I64, s->sphere, st, offsetof(vd_sphere_spec, module), n, 1, 1);
  fprintf(w->fp, "  },\n");
}

static void write_meshes(jw* w, const vd_plant_spec* s) {
  const char* in = "    ";
  size_t st = sizeof(vd_mesh_spec);
  int n = s->nmesh;
  fprintf(w->fp, "  \"meshes\": {\n");
  w_col(w, in, "vert_start", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, vert_start), n, 1, 0);
  w_col(w, in, "nvert", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, nvert), n, 1, 0);
  w_col(w, in, "tri_start", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, tri_start), n, 1, 0);
  w_col(w, in, "ntri", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, ntri), n, 1, 0);
  // closed is written as 0 or 1 whatever non-zero value the spec holds
  fprintf(w->fp, "%s\"closed\": [", in);
  for (int i = 0; i < n; i++)
    fprintf(w->fp, "%s%d", i ? "," : "", s->mesh[i].closed ? 1 : 0);
  fprintf(w->fp, "],\n");
  w_col(w, in, "node", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, node), n, 1, 0);
  w_col(w, in, "parent", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, parent), n, 1, 0);
  w_col(w, in, "label", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, label), n, 1, 0);
  w_col(w, in, "instance", COL_INT, s->mesh, st, offsetof(vd_mesh_spec, instance), n, 1, 0);
  w_col(w, in, "module", COL_I64, s->mesh, st, offsetof(vd_mesh_spec, module), n, 1, 1);
  fprintf(w->fp, "  },\n");
}

vd_status vd_plant_write_json(const vd_plant_spec* s, const char* path, vd_error* err) {
  if (!s || !path) return vd_error_set(err, VD_ERR_ARG, path ? path : "", 0, 0, "null argument");
  // a spec that does not compile would not read back either
  vd_status st = vd_plant_validate(s, err);
  if (st) {
    if (err && !err->file[0]) snprintf(err->file, sizeof err->file, "%s", path);
    return st;
  }
  vd_outfile f;
  st = vd_outfile_open(&f, path, err);
  if (st) return st;
  jw w = {f.fp, 0};
  // header, labels, then one object of columns per element kind
  fprintf(f.fp, "{\n  \"format\": \"%s\",\n  \"version\": %d,\n  \"units\": \"m\",\n", FORMAT_NAME,
          VD_PLANT_FORMAT_VERSION);
  write_labels(&w, s);
  w_col(&w, "  ", "nodes", COL_DBL, s->node, sizeof(vd_vec3), 0, s->nnode, 3, 0);
  write_segments(&w, s);
  write_spheres(&w, s);
  write_meshes(&w, s);
  write_stress(&w, s);
  w_col(&w, "  ", "vertices", COL_DBL, s->vert, sizeof(vd_vec3), 0, s->nvert, 3, 0);
  w_col(&w, "  ", "triangles", COL_INT, s->tri, 3 * sizeof(int), 0, s->ntri, 3, 1);
  fprintf(f.fp, "}\n");
  if (w.nonfinite) {
    vd_outfile_abort(&f);
    return vd_error_set(err, VD_ERR_VALUE, path, 0, 0, "a value is not finite");
  }
  st = vd_outfile_commit(&f, err);
  if (st) vd_outfile_abort(&f);
  return st;
}

// ---------------------------------------------------------------------------------------------
// reading

typedef struct rd {
  const char* file; // name used in errors
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

// field of an object: NULL when absent (optional) or an error when required
static const cJSON* field(rd* r, const cJSON* obj, const char* prefix, const char* key,
                          int required, vd_status* st) {
  const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, key);
  if (!v && required) *st = fail(r, "%s%s: missing", prefix, key);
  return v;
}

// one number checked to be finite, integral when asked, and inside [lo, hi]
static vd_status number(rd* r, const cJSON* v, const char* where, size_t k, int integer, double lo,
                        double hi, double* out) {
  if (!cJSON_IsNumber(v)) return fail(r, "%s[%zu]: expected a number", where, k);
  double x = v->valuedouble;
  if (!isfinite(x)) return fail(r, "%s[%zu]: number is not finite", where, k);
  if (integer && x != floor(x)) return fail(r, "%s[%zu]: expected an integer", where, k);
  if (x < lo || x > hi)
    return fail(r, "%s[%zu]: %.17g out of range [%.17g, %.17g]", where, k, x, lo, hi);
  *out = x;
  return VD_OK;
}

// a column of n*width values stored into records; *n < 0 means "this column sets n"
static vd_status column(rd* r, const cJSON* sec, const char* sname, const char* key, int* n,
                        int width, col_type t, double lo, double hi, void* base, size_t stride,
                        size_t off) {
  char where[96];
  snprintf(where, sizeof where, "%s%s%s", sname, sname[0] ? "." : "", key);
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(sec, key);
  if (!a) return fail(r, "%s: missing", where);
  if (!cJSON_IsArray(a)) return fail(r, "%s: expected an array", where);
  int size = cJSON_GetArraySize(a);
  if (*n < 0) {
    if (size % width) return fail(r, "%s: %d values is not a multiple of %d", where, size, width);
    *n = size / width;
    return VD_OK; // the caller allocates, then reads the column again with n set
  }
  if ((int64_t)size != (int64_t)*n * width)
    return fail(r, "%s: %d values, expected %lld", where, size, (long long)*n * width);
  size_t k = 0;
  for (const cJSON* v = a->child; v; v = v->next, k++) {
    double x = 0;
    vd_status st = number(r, v, where, k, t != COL_DBL, lo, hi, &x);
    if (st) return st;
    void* p = col_at(base, stride, off, width, t, k);
    switch (t) {
    case COL_INT:
      *(int*)p = (int)x;
      break;
    case COL_UINT:
      *(unsigned*)p = (unsigned)x;
      break;
    case COL_I64:
      *(int64_t*)p = (int64_t)x;
      break;
    case COL_DBL:
      *(double*)p = x;
      break;
    }
  }
  return VD_OK;
}

// count of records of a section from its first column (0 when the section is absent)
static vd_status section_count(rd* r, const cJSON* sec, const char* sname, const char* first,
                               int width, int* n) {
  *n = 0;
  if (!sec) return VD_OK;
  if (!cJSON_IsObject(sec)) return fail(r, "%s: expected an object", sname);
  *n = -1;
  return column(r, sec, sname, first, n, width, COL_DBL, 0, 0, NULL, 0, 0);
}

// a top-level flat array of n*width values ("nodes", "vertices", "triangles")
static vd_status flat_count(rd* r, const cJSON* root, const char* key, int width, int* n) {
  *n = 0;
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(root, key);
  if (!a) return VD_OK;
  *n = -1;
  return column(r, root, "", key, n, width, COL_DBL, 0, 0, NULL, 0, 0);
}

// read one column of a section into field f of the records g (inside read_segments etc.)
#define COLUMN(key, width, type, lo, hi, f)                                                        \
  if (!e) e = column(r, sec, S, key, &n, width, type, lo, hi, g, sizeof *g, offsetof(T, f))

#define I32 2147483647.0
#define I53 9007199254740992.0

static vd_status read_labels(rd* r, const cJSON* root, vd_plant_spec* s) {
  vd_status st = VD_OK;
  const cJSON* labels = field(r, root, "", "labels", 0, &st);
  if (!labels) return st;
  if (!cJSON_IsArray(labels)) return fail(r, "labels: expected an array");
  size_t k = 0;
  for (const cJSON* e = labels->child; e; e = e->next, k++) {
    char where[64];
    snprintf(where, sizeof where, "labels[%zu]", k);
    if (!cJSON_IsObject(e)) return fail(r, "%s: expected an object", where);
    // id and name are required; organ and rgb default from the name and the id
    const cJSON* id = cJSON_GetObjectItemCaseSensitive(e, "id");
    const cJSON* name = cJSON_GetObjectItemCaseSensitive(e, "name");
    const cJSON* organ = cJSON_GetObjectItemCaseSensitive(e, "organ");
    const cJSON* rgb = cJSON_GetObjectItemCaseSensitive(e, "rgb");
    double x = 0;
    if (!id) return fail(r, "%s.id: missing", where);
    if (!cJSON_IsNumber(id)) return fail(r, "%s.id: expected a number", where);
    x = id->valuedouble;
    if (!isfinite(x) || x != floor(x) || x < 0 || x > I32)
      return fail(r, "%s.id: expected an integer in [0, 2147483647]", where);
    if (!name) return fail(r, "%s.name: missing", where);
    if (!cJSON_IsString(name) || !name->valuestring)
      return fail(r, "%s.name: expected a string", where);
    if (vd_plant_find_label(s, (int)x)) return fail(r, "%s.id: duplicate id %d", where, (int)x);
    if (vd_plant_set_label(s, (int)x, name->valuestring))
      return vd_error_set(r->err, VD_ERR_NOMEM, r->file, 0, 0, "out of memory reading labels");
    vd_label* l = (vd_label*)vd_plant_find_label(s, (int)x);
    if (organ) {
      vd_organ o = cJSON_IsString(organ) ? vd_organ_parse(organ->valuestring) : VD_ORGAN_COUNT;
      if (o == VD_ORGAN_COUNT) return fail(r, "%s.organ: expected an organ name", where);
      l->organ = o;
    }
    if (rgb) {
      if (!cJSON_IsArray(rgb) || cJSON_GetArraySize(rgb) != 3)
        return fail(r, "%s.rgb: expected 3 numbers", where);
      char w2[80];
      snprintf(w2, sizeof w2, "%s.rgb", where);
      size_t c = 0;
      for (const cJSON* v = rgb->child; v; v = v->next, c++) {
        if ((st = number(r, v, w2, c, 0, 0, 1, &x))) return st;
        l->rgb[c] = (float)x;
      }
    }
  }
  return VD_OK;
}

static vd_status read_segments(rd* r, const cJSON* sec, vd_plant_spec* s, int n) {
  typedef vd_segment_spec T;
  const char* S = "segments";
  double nn = s->nnode - 1, ns = n - 1;
  vd_segment_spec* g = s->seg;
  vd_status e = VD_OK;
  // every column is required; indices are checked against the node and segment counts
  COLUMN("node0", 1, COL_INT, 0, nn, node0);
  COLUMN("node1", 1, COL_INT, 0, nn, node1);
  COLUMN("r0", 1, COL_DBL, 0, HUGE_VAL, r0);
  COLUMN("r1", 1, COL_DBL, 0, HUGE_VAL, r1);
  COLUMN("up", 3, COL_DBL, -HUGE_VAL, HUGE_VAL, up);
  COLUMN("parent", 1, COL_INT, -1, ns, parent);
  COLUMN("label", 1, COL_INT, 0, I32, label);
  COLUMN("instance", 1, COL_INT, 0, I32, instance);
  COLUMN("axis", 1, COL_INT, -I32 - 1, I32, axis);
  COLUMN("order", 1, COL_INT, -I32 - 1, I32, order);
  COLUMN("flags", 1, COL_UINT, 0, 4294967295.0, flags);
  COLUMN("slices", 1, COL_INT, 3, I32, slices);
  COLUMN("age", 1, COL_DBL, -HUGE_VAL, HUGE_VAL, age);
  COLUMN("module", 1, COL_I64, -1, I53, module);
  return e;
}

static vd_status read_spheres(rd* r, const cJSON* sec, vd_plant_spec* s, int n) {
  typedef vd_sphere_spec T;
  const char* S = "spheres";
  double nn = s->nnode - 1, ns = s->nseg - 1;
  vd_sphere_spec* g = s->sphere;
  vd_status e = VD_OK;
  COLUMN("center", 3, COL_DBL, -HUGE_VAL, HUGE_VAL, center);
  COLUMN("radius", 1, COL_DBL, 0, HUGE_VAL, radius);
  COLUMN("node", 1, COL_INT, -1, nn, node);
  COLUMN("parent", 1, COL_INT, -1, ns, parent);
  COLUMN("label", 1, COL_INT, 0, I32, label);
  COLUMN("instance", 1, COL_INT, 0, I32, instance);
  COLUMN("slices", 1, COL_INT, 3, I32, slices);
  COLUMN("module", 1, COL_I64, -1, I53, module);
  return e;
}

static vd_status read_meshes(rd* r, const cJSON* sec, vd_plant_spec* s, int n) {
  typedef vd_mesh_spec T;
  const char* S = "meshes";
  double nn = s->nnode - 1, ns = s->nseg - 1;
  vd_mesh_spec* g = s->mesh;
  vd_status e = VD_OK;
  COLUMN("vert_start", 1, COL_INT, 0, s->nvert, vert_start);
  COLUMN("nvert", 1, COL_INT, 0, s->nvert, nvert);
  COLUMN("tri_start", 1, COL_INT, 0, s->ntri, tri_start);
  COLUMN("ntri", 1, COL_INT, 0, s->ntri, ntri);
  COLUMN("closed", 1, COL_INT, 0, 1, closed);
  COLUMN("node", 1, COL_INT, -1, nn, node);
  COLUMN("parent", 1, COL_INT, -1, ns, parent);
  COLUMN("label", 1, COL_INT, 0, I32, label);
  COLUMN("instance", 1, COL_INT, 0, I32, instance);
  COLUMN("module", 1, COL_I64, -1, I53, module);
  if (e) return e;
  // ranges inside the arrays, triangles inside their mesh's vertices
  for (int i = 0; i < n; i++) {
    if (g[i].nvert > s->nvert - g[i].vert_start)
      return fail(r, "meshes.nvert[%d]: range [%d, +%d) outside the %d vertices", i,
                  g[i].vert_start, g[i].nvert, s->nvert);
    if (g[i].ntri > s->ntri - g[i].tri_start)
      return fail(r, "meshes.ntri[%d]: range [%d, +%d) outside the %d triangles", i, g[i].tri_start,
                  g[i].ntri, s->ntri);
    for (int t = g[i].tri_start; t < g[i].tri_start + g[i].ntri; t++)
      for (int k = 0; k < 3; k++) {
        int v = s->tri[3 * t + k];
        if (v < g[i].vert_start || v >= g[i].vert_start + g[i].nvert)
          return fail(r, "triangles[%d]: vertex %d is not one of mesh %d's vertices", 3 * t + k, v,
                      i);
      }
  }
  return VD_OK;
}

// grow a spec array to exactly n elements of size esz (n may be 0)
static int alloc_exact(void** p, int* cap, int n, size_t esz) {
  if (n <= 0) return 1;
  void* q = vd_malloc((size_t)n * esz);
  if (!q) return 0;
  memset(q, 0, (size_t)n * esz);
  *p = q;
  *cap = n;
  return 1;
}

// the body of parse: root object to spec
// "stress": {"unit": "Pa", "node": [...], "segment": [...]}, numbers >= 0 or null (none)
static vd_status read_stress(rd* r, const cJSON* root, vd_plant_spec* s) {
  const cJSON* sec = cJSON_GetObjectItemCaseSensitive(root, "stress");
  if (!sec) return VD_OK;
  if (!cJSON_IsObject(sec)) return fail(r, "stress: expected an object of columns");
  const cJSON* unit = cJSON_GetObjectItemCaseSensitive(sec, "unit");
  if (unit && (!cJSON_IsString(unit) || strcmp(unit->valuestring, "Pa") != 0)) return fail(r, "stress.unit: expected \"Pa\"");
  const char* keys[2] = {"node", "segment"};
  int want[2] = {s->nnode, s->nseg};
  double* col[2] = {NULL, NULL};
  vd_status st = VD_OK;
  for (int k = 0; k < 2 && !st; k++) {
    const cJSON* a = cJSON_GetObjectItemCaseSensitive(sec, keys[k]);
    if (!a || !cJSON_IsArray(a)) {
      st = fail(r, "stress.%s: expected an array", keys[k]);
      break;
    }
    if (cJSON_GetArraySize(a) != want[k]) {
      st = fail(r, "stress.%s: expected %d values (one per %s), got %d", keys[k], want[k], keys[k], cJSON_GetArraySize(a));
      break;
    }
    col[k] = vd_malloc(sizeof(double) * (size_t)(want[k] ? want[k] : 1));
    if (!col[k]) {
      st = vd_error_set(r->err, VD_ERR_NOMEM, r->file, 0, 0, "out of memory reading plant");
      break;
    }
    int i = 0;
    for (const cJSON* v = a->child; v; v = v->next, i++) {
      if (cJSON_IsNull(v)) {
        col[k][i] = NAN;
      } else if (cJSON_IsNumber(v) && v->valuedouble >= 0 && isfinite(v->valuedouble)) {
        col[k][i] = v->valuedouble;
      } else {
        st = fail(r, "stress.%s[%d]: expected a stress >= 0 (Pa) or null", keys[k], i);
        break;
      }
    }
  }
  if (!st && vd_plant_set_stress(s, col[0], col[1]))
    st = vd_error_set(r->err, VD_ERR_NOMEM, r->file, 0, 0, "out of memory reading plant");
  for (int k = 0; k < 2; k++) vd_free(col[k], sizeof(double) * (size_t)(want[k] ? want[k] : 1));
  return st;
}

static vd_status read_root(rd* r, const cJSON* root, vd_plant_spec* s) {
  vd_status st = VD_OK;
  if (!cJSON_IsObject(root)) return fail(r, "expected a JSON object at the top level");
  // format, version, units
  const cJSON* fmt = field(r, root, "", "format", 1, &st);
  if (!fmt) return st;
  if (!cJSON_IsString(fmt) || strcmp(fmt->valuestring, FORMAT_NAME) != 0)
    return fail(r, "format: expected \"%s\"", FORMAT_NAME);
  const cJSON* ver = field(r, root, "", "version", 1, &st);
  if (!ver) return st;
  if (!cJSON_IsNumber(ver)) return fail(r, "version: expected a number");
  if (ver->valuedouble != VD_PLANT_FORMAT_VERSION)
    return fail(r, "version: %.17g is not supported (this reader knows version %d)",
                ver->valuedouble, VD_PLANT_FORMAT_VERSION);
  const cJSON* units = cJSON_GetObjectItemCaseSensitive(root, "units");
  if (units && (!cJSON_IsString(units) || strcmp(units->valuestring, "m") != 0))
    return fail(r, "units: expected \"m\"");
  if ((st = read_labels(r, root, s))) return st;

  // counts of every element kind, then exact allocations
  const cJSON* segs = cJSON_GetObjectItemCaseSensitive(root, "segments");
  const cJSON* sphs = cJSON_GetObjectItemCaseSensitive(root, "spheres");
  const cJSON* mshs = cJSON_GetObjectItemCaseSensitive(root, "meshes");
  int nnode, nseg, nsph, nmesh, nvert, ntri;
  if ((st = flat_count(r, root, "nodes", 3, &nnode))) return st;
  if ((st = flat_count(r, root, "vertices", 3, &nvert))) return st;
  if ((st = flat_count(r, root, "triangles", 3, &ntri))) return st;
  if ((st = section_count(r, segs, "segments", "node0", 1, &nseg))) return st;
  if ((st = section_count(r, sphs, "spheres", "radius", 1, &nsph))) return st;
  if ((st = section_count(r, mshs, "meshes", "vert_start", 1, &nmesh))) return st;
  if (!alloc_exact((void**)&s->node, &s->cap_node, nnode, sizeof *s->node) ||
      !alloc_exact((void**)&s->seg, &s->cap_seg, nseg, sizeof *s->seg) ||
      !alloc_exact((void**)&s->sphere, &s->cap_sphere, nsph, sizeof *s->sphere) ||
      !alloc_exact((void**)&s->mesh, &s->cap_mesh, nmesh, sizeof *s->mesh) ||
      !alloc_exact((void**)&s->vert, &s->cap_vert, nvert, sizeof *s->vert) ||
      !alloc_exact((void**)&s->tri, &s->cap_tri, ntri, 3 * sizeof *s->tri))
    return vd_error_set(r->err, VD_ERR_NOMEM, r->file, 0, 0, "out of memory reading plant");
  // counts are set first so that range checks see them
  s->nnode = nnode, s->nseg = nseg, s->nsphere = nsph, s->nmesh = nmesh;
  s->nvert = nvert, s->ntri = ntri;

  // flat arrays, then the element sections
  double big = HUGE_VAL;
  if (nnode && (st = column(r, root, "", "nodes", &nnode, 3, COL_DBL, -big, big, s->node,
                            sizeof(vd_vec3), 0)))
    return st;
  if (nvert && (st = column(r, root, "", "vertices", &nvert, 3, COL_DBL, -big, big, s->vert,
                            sizeof(vd_vec3), 0)))
    return st;
  if (ntri && (st = column(r, root, "", "triangles", &ntri, 3, COL_INT, 0, nvert - 1, s->tri,
                           3 * sizeof(int), 0)))
    return st;
  if (segs && (st = read_segments(r, segs, s, nseg))) return st;
  if (sphs && (st = read_spheres(r, sphs, s, nsph))) return st;
  if (mshs && (st = read_meshes(r, mshs, s, nmesh))) return st;

  if ((st = read_stress(r, root, s))) return st;

  // largest instance id in use
  for (int i = 0; i < nseg; i++)
    s->ninstance = s->seg[i].instance > s->ninstance ? s->seg[i].instance : s->ninstance;
  for (int i = 0; i < nsph; i++)
    s->ninstance = s->sphere[i].instance > s->ninstance ? s->sphere[i].instance : s->ninstance;
  for (int i = 0; i < nmesh; i++)
    s->ninstance = s->mesh[i].instance > s->ninstance ? s->mesh[i].instance : s->ninstance;
  return VD_OK;
}

vd_status vd_plant_parse_json(const char* text, size_t len, const char* name, vd_plant_spec** out,
                              vd_error* err) {
  rd r = {name ? name : "", err};
  if (out) *out = NULL;
  if (!out || (!text && len)) return vd_error_set(err, VD_ERR_ARG, r.file, 0, 0, "null argument");
  if (len > VD_FILE_MAX)
    return vd_error_set(err, VD_ERR_LIMIT, r.file, 0, 0, "input larger than %zu bytes",
                        (size_t)VD_FILE_MAX);
  if (len == 0) return fail(&r, "empty input: expected a plant JSON object");
  // parse; on failure report where cJSON stopped
  const char* end = NULL;
  cJSON* root = cJSON_ParseWithLengthOpts(text, len, &end, 0);
  if (!root) {
    int line, col;
    size_t pos = (end && end >= text) ? (size_t)(end - text) : 0;
    line_col(text, len, pos, &line, &col);
    return vd_error_set(err, VD_ERR_FORMAT, r.file, line, col, "invalid JSON");
  }
  // nothing but white space may follow the value
  size_t pos = (size_t)(end - text);
  while (pos < len &&
         (text[pos] == ' ' || text[pos] == '\t' || text[pos] == '\n' || text[pos] == '\r'))
    pos++;
  if (pos < len) {
    cJSON_Delete(root);
    int line, col;
    line_col(text, len, pos, &line, &col);
    return vd_error_set(err, VD_ERR_FORMAT, r.file, line, col, "text after the JSON value");
  }
  // fill a new spec; any failure frees it
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) {
    cJSON_Delete(root);
    return vd_error_set(err, VD_ERR_NOMEM, r.file, 0, 0, "out of memory reading plant");
  }
  vd_status st = read_root(&r, root, s);
  cJSON_Delete(root);
  if (st) {
    vd_plant_spec_destroy(s);
    return st;
  }
  *out = s;
  return VD_OK;
}

vd_status vd_plant_read_json(const char* path, vd_plant_spec** out, vd_error* err) {
  if (out) *out = NULL;
  if (!path || !out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "null argument");
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  st = vd_plant_parse_json(text, len, path, out, err);
  vd_free(text, len + 1);
  return st;
}
