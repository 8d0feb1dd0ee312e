// SPDX-License-Identifier: MIT
// Cloud readers for the files vd_cloud_write makes: PLY (ASCII, binary little-endian), PCD
// (ASCII, binary), XYZ, CSV and LAS 1.4 format 6. Columns are found by name, so files from
// other tools with the same fields read too. Every fault names the file and the line (text) or
// the byte offset (binary); nothing is trusted: counts are checked against the file's size.
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "cloud_internal.h"

// the cloud fields a column can feed
enum { F_X, F_Y, F_Z, F_NX, F_NY, F_NZ, F_LABEL, F_INSTANCE, F_VIEW, F_RANGE, F_COUNT };
static const char* field_names[F_COUNT] = {"x", "y", "z", "nx", "ny", "nz",
                                           "label", "instance", "view", "range"};

// which field a column name feeds (-1: none); "scalar_" and PCD/LAS spellings accepted
static int field_of(const char* name) {
  if (!strncmp(name, "scalar_", 7)) name += 7;
  for (int f = 0; f < F_COUNT; f++)
    if (!strcmp(name, field_names[f])) return f;
  if (!strcmp(name, "normal_x") || !strcmp(name, "NormalX")) return F_NX;
  if (!strcmp(name, "normal_y") || !strcmp(name, "NormalY")) return F_NY;
  if (!strcmp(name, "normal_z") || !strcmp(name, "NormalZ")) return F_NZ;
  return -1;
}

// a table of columns: name, type, byte offset in a binary record, field fed
typedef struct cols {
  int n;
  char name[64][64];
  vd_scalar type[64];
  int offset[64];
  int field[64];
  int record;  // bytes per binary record
} cols;

// ---------------------------------------------------------------------------------------------
// building the cloud

typedef struct reader {
  const char* path;
  vd_error* err;
  vd_label* labels;  // from header comments (growing)
  int nlabel, cap_label;
  int nview;         // from "views N", -1 when not given
} reader;

static vd_status fail(reader* r, int line, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
static vd_status fail(reader* r, int line, const char* fmt, ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return vd_error_set(r->err, VD_ERR_FORMAT, r->path, line, 0, "%s", msg);
}

// "label ID NAME" or "views N" comment text (after the comment marker and spaces)
static vd_status comment_line(reader* r, const char* s, size_t len, int line) {
  char buf[256];
  if (len >= sizeof buf) len = sizeof buf - 1;
  memcpy(buf, s, len);
  buf[len] = 0;
  char* p = buf;
  while (*p == ' ' || *p == '\t') p++;
  if (!strncmp(p, "views ", 6)) {
    char* end;
    errno = 0;
    long v = strtol(p + 6, &end, 10);
    if (!errno && v >= 0 && v <= 65535 && (*end == 0 || *end == '\r')) r->nview = (int)v;
    return VD_OK;
  }
  if (strncmp(p, "label ", 6) != 0) return VD_OK;
  char* end;
  errno = 0;
  long id = strtol(p + 6, &end, 10);
  if (errno || end == p + 6 || id < 0 || id > INT32_MAX || (*end != ' ' && *end != 0))
    return fail(r, line, "label comment: expected 'label ID NAME'");
  while (*end == ' ') end++;
  size_t n = strlen(end);
  while (n && (end[n - 1] == '\r' || end[n - 1] == ' ')) end[--n] = 0;
  if (!vd_grow((void**)&r->labels, &r->cap_label, r->nlabel + 1, sizeof(vd_label)))
    return vd_error_set(r->err, VD_ERR_NOMEM, r->path, 0, 0, "out of memory");
  vd_label_init(&r->labels[r->nlabel++], (int)id, end);
  return VD_OK;
}

// store value v of field f at point i, checking integers
static int put_field(vd_cloud* c, int64_t i, int f, double v) {
  if (!isfinite(v)) return 0;
  switch (f) {
    case F_X: case F_Y: case F_Z: c->pos[3 * i + f - F_X] = v; return 1;
    case F_NX: case F_NY: case F_NZ: c->normal[3 * i + f - F_NX] = v; return 1;
    case F_RANGE: c->range[i] = v; return 1;
    default: break;
  }
  if (v != floor(v) || v < INT32_MIN || v > INT32_MAX) return 0;
  if (f == F_LABEL) c->label[i] = (int)v;
  if (f == F_INSTANCE) c->instance[i] = (int)v;
  if (f == F_VIEW) {
    if (v < 0 || v > 65535) return 0;  // scanner indices
    c->view[i] = (int)v;
  }
  return 1;
}

// map columns to fields; x, y and z are required, a field named twice is an error
static vd_status map_fields(reader* r, cols* cs, int* has) {
  for (int f = 0; f < F_COUNT; f++)
    has[f] = 0;
  for (int k = 0; k < cs->n; k++) {
    cs->field[k] = field_of(cs->name[k]);
    if (cs->field[k] < 0) continue;
    if (has[cs->field[k]]++) return fail(r, 0, "column '%s' appears twice", cs->name[k]);
  }
  if (!has[F_X] || !has[F_Y] || !has[F_Z]) return fail(r, 0, "no x, y and z columns");
  return VD_OK;
}

// allocate the cloud with the table read so far; views from the header or the view column
static vd_status start_cloud(reader* r, vd_cloud* out, int64_t n) {
  if (n < 0 || n > VD_CLOUD_MAX_POINTS) return fail(r, 0, "point count %lld out of range", (long long)n);
  return cloud_alloc(out, n, r->labels, r->nlabel, 1, r->err);
}

static void finish_views(reader* r, vd_cloud* c, int has_view) {
  if (r->nview >= 0) {
    c->nview = r->nview;
    return;
  }
  int mx = -1;
  for (int64_t i = 0; has_view && i < c->n; i++)
    if (c->view[i] > mx) mx = c->view[i];
  c->nview = has_view ? mx + 1 : 0;
}

// ---------------------------------------------------------------------------------------------
// line reading over the whole file (vd_text_line)

// split a line into at most cap tokens on sep (' ' means any run of blanks), NUL-terminated in buf
static int split(const char* ls, size_t ll, char sep, char* buf, size_t bcap, char** tok, int cap) {
  if (ll >= bcap) return -1;
  memcpy(buf, ls, ll);
  buf[ll] = 0;
  int n = 0;
  char* p = buf;
  if (sep == ' ') {
    for (;;) {
      while (*p == ' ' || *p == '\t') p++;
      if (!*p) break;
      if (n == cap) return -1;
      tok[n++] = p;
      while (*p && *p != ' ' && *p != '\t') p++;
      if (*p) *p++ = 0;
    }
  } else {
    for (;;) {
      if (n == cap) return -1;
      tok[n++] = p;
      char* q = strchr(p, sep);
      if (!q) break;
      *q = 0;
      p = q + 1;
    }
  }
  return n;
}

// ASCII records: one per line, one value per column
static vd_status read_ascii_rows(reader* r, vd_text* t, const cols* cs, char sep, vd_cloud* c) {
  char buf[4096];
  char* tok[64];
  for (int64_t i = 0; i < c->n; i++) {
    const char* ls;
    size_t ll;
    do {
      if (!vd_text_line(t, &ls, &ll)) return fail(r, t->line, "expected %lld points, the file ends", (long long)c->n);
    } while (ll == 0 || ls[0] == '#');
    int n = split(ls, ll, sep, buf, sizeof buf, tok, 64);
    if (n != cs->n) return fail(r, t->line, "expected %lld values", (long long)cs->n);
    for (int k = 0; k < n; k++) {
      char* end;
      errno = 0;
      double v = strtod(tok[k], &end);
      while (*end == ' ' || *end == '\t') end++;
      if (end == tok[k] || *end || errno == EINVAL)
        return fail(r, t->line, "column '%s': not a number", cs->name[k]);
      if (cs->field[k] >= 0 && !put_field(c, i, cs->field[k], v))
        return fail(r, t->line, "column '%s': value out of range", cs->name[k]);
    }
  }
  return VD_OK;
}

// binary little-endian records
static vd_status read_binary_rows(reader* r, const unsigned char* data, size_t avail, const cols* cs,
                                  vd_cloud* c, size_t base) {
  if (cs->record <= 0) return fail(r, 0, "empty record");
  if ((uint64_t)c->n > avail / (uint64_t)cs->record)
    return fail(r, 0, "%lld points do not fit in the file", (long long)c->n);
  for (int64_t i = 0; i < c->n; i++) {
    const unsigned char* rec = data + (size_t)i * (size_t)cs->record;
    for (int k = 0; k < cs->n; k++) {
      if (cs->field[k] < 0) continue;
      if (!put_field(c, i, cs->field[k], vd_scalar_get_le(rec + cs->offset[k], cs->type[k]))) {
        return fail(r, 0, "column '%s' of point %lld (byte %llu): bad value", cs->name[k], (long long)i,
                    (unsigned long long)base + (unsigned long long)i * (unsigned long long)cs->record + (unsigned long long)cs->offset[k]);
      }
    }
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// PLY

static vd_status read_ply(reader* r, const char* s, size_t len, vd_cloud* out) {
  vd_text t = {s, len, 0, 0};
  const char* ls;
  size_t ll;
  if (!vd_text_line(&t, &ls, &ll) || ll != 3 || memcmp(ls, "ply", 3) != 0)
    return fail(r, 1, "not a PLY file (expected 'ply')");
  int binary = -1, in_vertex = 0, seen_vertex = 0;
  int64_t n = -1;
  cols cs;
  memset(&cs, 0, sizeof cs);
  char buf[512];
  char* tok[8];
  for (;;) {
    if (!vd_text_line(&t, &ls, &ll)) return fail(r, t.line, "no end_header");
    if (ll >= 8 && !memcmp(ls, "comment ", 8)) {
      vd_status st = comment_line(r, ls + 8, ll - 8, t.line);
      if (st) return st;
      continue;
    }
    if (ll >= 8 && !memcmp(ls, "obj_info", 8)) continue;
    int k = split(ls, ll, ' ', buf, sizeof buf, tok, 8);
    if (k < 1) return fail(r, t.line, "header line too long");
    if (!strcmp(tok[0], "end_header")) break;
    if (!strcmp(tok[0], "format")) {
      if (k != 3 || strcmp(tok[2], "1.0") != 0) return fail(r, t.line, "expected 'format TYPE 1.0'");
      if (!strcmp(tok[1], "ascii")) binary = 0;
      else if (!strcmp(tok[1], "binary_little_endian")) binary = 1;
      else return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, t.line, 0, "PLY format '%s' is not supported", tok[1]);
    } else if (!strcmp(tok[0], "element")) {
      if (k != 3) return fail(r, t.line, "expected 'element NAME COUNT'");
      // elements after the vertex block (PCL writes face and camera) are not read
      if (seen_vertex) {
        in_vertex = 0;
        continue;
      }
      if (strcmp(tok[1], "vertex") != 0)
        return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, t.line, 0,
                            "element '%s' before the vertex element is not supported", tok[1]);
      char* end;
      errno = 0;
      long long v = strtoll(tok[2], &end, 10);
      if (errno || *end || v < 0) return fail(r, t.line, "bad vertex count '%s'", tok[2]);
      n = v;
      in_vertex = seen_vertex = 1;
    } else if (!strcmp(tok[0], "property")) {
      if (!seen_vertex) return fail(r, t.line, "property before element");
      if (!in_vertex) continue;
      if (k >= 2 && !strcmp(tok[1], "list"))
        return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, t.line, 0, "list properties are not supported in clouds");
      if (k != 3) return fail(r, t.line, "expected 'property TYPE NAME'");
      vd_scalar ty = vd_scalar_ply(tok[1]);
      if (ty == VD_SCALAR_BAD) return fail(r, t.line, "unknown property type '%s'", tok[1]);
      if (cs.n == 64) return fail(r, t.line, "more than 64 properties");
      if (strlen(tok[2]) >= sizeof cs.name[0]) return fail(r, t.line, "property name too long");
      strcpy(cs.name[cs.n], tok[2]);
      cs.type[cs.n] = ty;
      cs.offset[cs.n] = cs.record;
      cs.record += vd_scalar_size(ty);
      cs.n++;
    } else {
      return fail(r, t.line, "unknown header line '%.40s'", tok[0]);
    }
  }
  if (binary < 0) return fail(r, t.line, "no format line");
  if (n < 0) return fail(r, t.line, "no vertex element");
  int has[F_COUNT];
  vd_status st = map_fields(r, &cs, has);
  // every point takes at least its record (binary) or a digit and a separator per value (text)
  uint64_t least = binary ? (uint64_t)cs.record : 2 * (uint64_t)cs.n;
  if (!st && (uint64_t)n > (len - t.pos) / least)
    st = fail(r, t.line, "%lld points do not fit in the file", (long long)n);
  if (!st) st = start_cloud(r, out, n);
  if (st) return st;
  if (binary)
    st = read_binary_rows(r, (const unsigned char*)s + t.pos, len - t.pos, &cs, out, t.pos);
  else
    st = read_ascii_rows(r, &t, &cs, ' ', out);
  if (!st) finish_views(r, out, has[F_VIEW]);
  return st;
}

// ---------------------------------------------------------------------------------------------
// PCD

static vd_status read_pcd(reader* r, const char* s, size_t len, vd_cloud* out) {
  vd_text t = {s, len, 0, 0};
  const char* ls;
  size_t ll;
  cols cs;
  memset(&cs, 0, sizeof cs);
  int sizes[64] = {0}, counts[64] = {0}, nsize = -1, ntype = -1, ncount = -1, binary = -1;
  char types[64];
  int64_t points = -1;
  char buf[4096];
  char* tok[66];
  while (binary < 0) {
    if (!vd_text_line(&t, &ls, &ll)) return fail(r, t.line, "no DATA line");
    if (ll == 0) continue;
    if (ls[0] == '#') {
      vd_status st = comment_line(r, ls + 1, ll - 1, t.line);
      if (st) return st;
      continue;
    }
    int k = split(ls, ll, ' ', buf, sizeof buf, tok, 66);
    if (k < 1 || k > 65) return fail(r, t.line, "header line too long");
    const char* key = tok[0];
    if (!strcmp(key, "FIELDS")) {
      cs.n = k - 1;
      for (int i = 1; i < k; i++) {
        if (strlen(tok[i]) >= sizeof cs.name[0]) return fail(r, t.line, "field name too long");
        strcpy(cs.name[i - 1], tok[i]);
      }
    } else if (!strcmp(key, "SIZE") || !strcmp(key, "COUNT")) {
      int* dst = key[0] == 'S' ? sizes : counts;
      for (int i = 1; i < k; i++) {
        char* end;
        long v = strtol(tok[i], &end, 10);
        if (*end || v < 1 || v > 8) return fail(r, t.line, "bad %s value", key);
        dst[i - 1] = (int)v;
      }
      if (key[0] == 'S') nsize = k - 1;
      else ncount = k - 1;
    } else if (!strcmp(key, "TYPE")) {
      for (int i = 1; i < k; i++) {
        if (strlen(tok[i]) != 1 || !strchr("FUI", tok[i][0])) return fail(r, t.line, "bad TYPE '%s'", tok[i]);
        types[i - 1] = tok[i][0];
      }
      ntype = k - 1;
    } else if (!strcmp(key, "POINTS")) {
      char* end;
      errno = 0;
      long long v = k == 2 ? strtoll(tok[1], &end, 10) : -1;
      if (k != 2 || errno || *end || v < 0) return fail(r, t.line, "bad POINTS");
      points = v;
    } else if (!strcmp(key, "DATA")) {
      if (k == 2 && !strcmp(tok[1], "ascii")) binary = 0;
      else if (k == 2 && !strcmp(tok[1], "binary")) binary = 1;
      else return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, t.line, 0, "PCD DATA '%s' is not supported (ascii or binary)", k > 1 ? tok[1] : "");
    } else if (strcmp(key, "VERSION") != 0 && strcmp(key, "WIDTH") != 0 && strcmp(key, "HEIGHT") != 0 && strcmp(key, "VIEWPOINT") != 0) {
      return fail(r, t.line, "unknown header line '%.40s'", key);
    }
  }
  if (cs.n < 1 || nsize != cs.n || ntype != cs.n || (ncount >= 0 && ncount != cs.n))
    return fail(r, t.line, "FIELDS, SIZE, TYPE and COUNT differ in length");
  if (points < 0) return fail(r, t.line, "no POINTS line");
  for (int i = 0; i < cs.n; i++) {
    if (ncount >= 0 && counts[i] != 1)
      return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, 0, 0, "field '%s': COUNT %d is not supported", cs.name[i], counts[i]);
    vd_scalar ty = VD_SCALAR_BAD;
    int sz = sizes[i];
    if (types[i] == 'F') ty = sz == 4 ? VD_SCALAR_F32 : sz == 8 ? VD_SCALAR_F64 : VD_SCALAR_BAD;
    if (types[i] == 'U') ty = sz == 1 ? VD_SCALAR_U8 : sz == 2 ? VD_SCALAR_U16 : sz == 4 ? VD_SCALAR_U32 : sz == 8 ? VD_SCALAR_U64 : VD_SCALAR_BAD;
    if (types[i] == 'I') ty = sz == 1 ? VD_SCALAR_I8 : sz == 2 ? VD_SCALAR_I16 : sz == 4 ? VD_SCALAR_I32 : sz == 8 ? VD_SCALAR_I64 : VD_SCALAR_BAD;
    if (ty == VD_SCALAR_BAD) return fail(r, 0, "field '%s': bad SIZE/TYPE", cs.name[i]);
    cs.type[i] = ty;
    cs.offset[i] = cs.record;
    cs.record += sz;
  }
  int has[F_COUNT];
  vd_status st = map_fields(r, &cs, has);
  uint64_t least = binary ? (uint64_t)cs.record : 2 * (uint64_t)cs.n;
  if (!st && (uint64_t)points > (len - t.pos) / least)
    st = fail(r, t.line, "%lld points do not fit in the file", (long long)points);
  if (!st) st = start_cloud(r, out, points);
  if (st) return st;
  if (binary)
    st = read_binary_rows(r, (const unsigned char*)s + t.pos, len - t.pos, &cs, out, t.pos);
  else
    st = read_ascii_rows(r, &t, &cs, ' ', out);
  if (!st) finish_views(r, out, has[F_VIEW]);
  return st;
}

// ---------------------------------------------------------------------------------------------
// XYZ and CSV: '#' comment lines; the column names are the last '#' line before the data (XYZ)
// or the first line that is not a comment (CSV)

static vd_status read_text(reader* r, const char* s, size_t len, int csv, vd_cloud* out) {
  vd_text t = {s, len, 0, 0};
  const char* ls;
  size_t ll;
  cols cs;
  memset(&cs, 0, sizeof cs);
  char buf[4096], hdr[4096];
  char* tok[64];
  size_t hl = 0;
  int have_hdr = 0;
  // header: comments and (CSV) the names line, in any order
  size_t data_pos = 0;
  int data_line = 0;
  for (;;) {
    size_t before = t.pos;
    int line_before = t.line;
    if (!vd_text_line(&t, &ls, &ll)) {
      data_pos = t.pos, data_line = t.line;
      break;
    }
    if (ll && ls[0] == '#') {
      vd_status st = comment_line(r, ls + 1, ll - 1, t.line);
      if (st) return st;
      // an XYZ names line: "# x y z ..."
      const char* p = ls + 1;
      while (p < ls + ll && *p == ' ') p++;
      if (!csv && ls + ll - p >= 2 && p[0] == 'x' && (p[1] == ' ' || p[1] == '\t')) {
        hl = (size_t)(ls + ll - p);
        if (hl >= sizeof hdr) return fail(r, t.line, "names line too long");
        memcpy(hdr, p, hl);
        have_hdr = 1;
      }
      continue;
    }
    if (ll == 0) continue;
    if (csv && !have_hdr) {
      // the names line; comments may follow it (verdant writes them there for numpy)
      if (ll >= sizeof hdr) return fail(r, t.line, "names line too long");
      memcpy(hdr, ls, ll);
      hl = ll;
      have_hdr = 1;
      continue;
    }
    data_pos = before, data_line = line_before;
    break;
  }
  if (!have_hdr) return fail(r, t.line, "no column names line");
  int k = split(hdr, hl, csv ? ',' : ' ', buf, sizeof buf, tok, 64);
  if (k < 1) return fail(r, data_line, "too many columns");
  cs.n = k;
  for (int i = 0; i < k; i++) {
    char* nm = tok[i];
    while (*nm == ' ') nm++;
    size_t nl = strlen(nm);
    while (nl && nm[nl - 1] == ' ') nm[--nl] = 0;
    if (nl >= sizeof cs.name[0]) return fail(r, data_line, "column name too long");
    strcpy(cs.name[i], nm);
  }
  int has[F_COUNT];
  vd_status st = map_fields(r, &cs, has);
  if (st) return st;
  // count the data lines, then read them
  int64_t n = 0;
  vd_text c = {s, len, data_pos, data_line};
  while (vd_text_line(&c, &ls, &ll))
    if (ll && ls[0] != '#') n++;
  st = start_cloud(r, out, n);
  if (st) return st;
  t.pos = data_pos, t.line = data_line;
  st = read_ascii_rows(r, &t, &cs, csv ? ',' : ' ', out);
  if (!st) finish_views(r, out, has[F_VIEW]);
  return st;
}

// ---------------------------------------------------------------------------------------------
// LAS 1.4, point data record format 6

static uint64_t le(const unsigned char* p, int n) {
  uint64_t u = 0;
  for (int k = n - 1; k >= 0; k--)
    u = (u << 8) | p[k];
  return u;
}
static double le_f64(const unsigned char* p) {
  uint64_t u = le(p, 8);
  double d;
  memcpy(&d, &u, 8);
  return d;
}

// verdant's label table (a VLR or an extended VLR): per label id (int32), class (uint8), 3
// reserved bytes, name (48 bytes)
static vd_status las_label_table(reader* r, const unsigned char* p, unsigned len) {
  r->nlabel = 0;
  for (unsigned e = 0; e + 56 <= len; e += 56) {
    if (!vd_grow((void**)&r->labels, &r->cap_label, r->nlabel + 1, sizeof(vd_label)))
      return vd_error_set(r->err, VD_ERR_NOMEM, r->path, 0, 0, "out of memory");
    char name[49];
    memcpy(name, p + e + 8, 48);
    name[48] = 0;
    vd_label_init(&r->labels[r->nlabel++], (int)(int32_t)le(p + e, 4), name);
  }
  return VD_OK;
}

static vd_status read_las(reader* r, const char* s, size_t len, vd_cloud* out) {
  const unsigned char* b = (const unsigned char*)s;
  if (len < 375 || memcmp(b, "LASF", 4) != 0) return fail(r, 0, "not a LAS file (expected 'LASF')");
  if (b[24] != 1 || b[25] != 4)
    return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, 0, 0, "LAS %d.%d: only 1.4 is read", b[24], b[25]);
  unsigned hsize = (unsigned)le(b + 94, 2);
  uint64_t offset = le(b + 96, 4), nvlr = le(b + 100, 4);
  int pf = b[104];
  unsigned rlen = (unsigned)le(b + 105, 2);
  uint64_t n = le(b + 247, 8);
  if (pf != 6) return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, 0, 0, "LAS point format %d: only 6 is read", pf);
  if (hsize < 375 || hsize > len || rlen < 30 || offset > len || offset < hsize)
    return fail(r, 0, "inconsistent LAS header (byte 94..107)");
  double scale[3], off[3];
  for (int k = 0; k < 3; k++) {
    scale[k] = le_f64(b + 131 + 8 * k), off[k] = le_f64(b + 155 + 8 * k);
    if (!isfinite(scale[k]) || scale[k] == 0 || !isfinite(off[k])) return fail(r, 131, "bad LAS scale or offset");
  }
  // VLRs: classification lookup (label names), extra bytes (label, instance, view, range,
  // normals), verdant's label table (ids and names)
  int table = 0;
  cols cs;
  memset(&cs, 0, sizeof cs);
  size_t pos = hsize;
  int extra_bytes = (int)rlen - 30;
  for (uint64_t v = 0; v < nvlr; v++) {
    if (pos + 54 > offset) return fail(r, 0, "VLR %lld runs past the point data", (long long)v);
    const unsigned char* h = b + pos;
    unsigned rec = (unsigned)le(h + 18, 2), vlen = (unsigned)le(h + 20, 2);
    int spec = !memcmp(h + 2, "LASF_Spec", 9) && h[11] == 0;
    pos += 54;
    if (pos + vlen > offset) return fail(r, 0, "VLR %lld runs past the point data", (long long)v);
    if (!memcmp(h + 2, "verdant", 8) && rec == 1) {
      // verdant's label table: it replaces the classification lookup's names
      vd_status st = las_label_table(r, b + pos, vlen);
      if (st) return st;
      table = 1;
    } else if (spec && rec == 0 && !table) {
      for (unsigned e = 0; e + 16 <= vlen; e += 16) {
        if (!vd_grow((void**)&r->labels, &r->cap_label, r->nlabel + 1, sizeof(vd_label)))
          return vd_error_set(r->err, VD_ERR_NOMEM, r->path, 0, 0, "out of memory");
        char name[16];
        memcpy(name, b + pos + e + 1, 15);
        name[15] = 0;
        vd_label_init(&r->labels[r->nlabel++], b[pos + e], name);
      }
    } else if (spec && rec == 4) {
      int at = 0;
      for (unsigned e = 0; e + 192 <= vlen; e += 192) {
        const unsigned char* d = b + pos + e;
        int dt = d[2];
        static const vd_scalar map[] = {VD_SCALAR_BAD, VD_SCALAR_U8, VD_SCALAR_I8, VD_SCALAR_U16, VD_SCALAR_I16, VD_SCALAR_U32, VD_SCALAR_I32, VD_SCALAR_U64, VD_SCALAR_I64, VD_SCALAR_F32, VD_SCALAR_F64};
        if (dt < 1 || dt > 10)
          return vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, 0, 0, "extra bytes data type %d is not supported", dt);
        if (cs.n == 64) return fail(r, 0, "more than 64 extra dimensions");
        memcpy(cs.name[cs.n], d + 4, 32);
        cs.name[cs.n][32] = 0;
        cs.type[cs.n] = map[dt];
        cs.offset[cs.n] = 30 + at;
        at += vd_scalar_size(map[dt]);
        cs.n++;
      }
      if (at > extra_bytes) return fail(r, 0, "extra bytes descriptors exceed the record length");
    }
    pos += vlen;
  }
  int has[F_COUNT] = {0};
  for (int k = 0; k < cs.n; k++) {
    cs.field[k] = field_of(cs.name[k]);
    if (cs.field[k] >= 0 && (cs.field[k] <= F_Z || has[cs.field[k]]++)) cs.field[k] = -1;
  }
  // extended VLRs after the points: verdant's label table when it was too long for a VLR
  uint64_t evlr = le(b + 235, 8), nevlr = le(b + 243, 4);
  for (uint64_t v = 0; v < nevlr && evlr >= offset && evlr <= len && len - evlr >= 60; v++) {
    const unsigned char* h = b + evlr;
    uint64_t elen = le(h + 20, 8);
    if (elen > len - evlr - 60) return fail(r, 0, "extended VLR %lld runs past the end of the file", (long long)v);
    if (!memcmp(h + 2, "verdant", 8) && le(h + 18, 2) == 1) {
      if (elen > 65535ull * 1024) return fail(r, 0, "label table of %llu bytes", (unsigned long long)elen);
      r->nlabel = 0;
      vd_status st = las_label_table(r, h + 60, (unsigned)elen);
      if (st) return st;
    }
    evlr += 60 + elen;
  }
  if (n > (uint64_t)VD_CLOUD_MAX_POINTS || n > (len - offset) / rlen)
    return fail(r, 0, "%lld points do not fit in the file", (long long)n);
  vd_status st = start_cloud(r, out, (int64_t)n);
  if (st) return st;
  for (uint64_t i = 0; i < n; i++) {
    const unsigned char* p = b + offset + i * rlen;
    for (int k = 0; k < 3; k++)
      out->pos[3 * i + k] = off[k] + scale[k] * (double)(int32_t)le(p + 4 * k, 4);
    out->label[i] = p[16];
    out->view[i] = (int)le(p + 20, 2);
    for (int k = 0; k < cs.n; k++)
      if (cs.field[k] >= 0 && !put_field(out, (int64_t)i, cs.field[k], vd_scalar_get_le(p + cs.offset[k], cs.type[k])))
        return fail(r, 0, "extra dimension '%s' of point %lld: bad value", cs.name[k], (long long)i);
  }
  r->nview = -1;
  finish_views(r, out, has[F_RANGE] > 0);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// dispatch

vd_status vd_cloud_parse(const char* data, size_t len, vd_cloud_format fmt, const char* name,
                         vd_cloud* out, vd_error* err) {
  if (!out) return vd_error_set(err, VD_ERR_ARG, name ? name : "", 0, 0, "null argument");
  memset(out, 0, sizeof *out);
  if (!data && len) return vd_error_set(err, VD_ERR_ARG, name ? name : "", 0, 0, "null data");
  if (fmt == VD_CLOUD_AUTO) fmt = vd_cloud_format_of(name);
  if (fmt < VD_CLOUD_PLY || fmt > VD_CLOUD_LAS)
    return vd_error_set(err, VD_ERR_ARG, name ? name : "", 0, 0,
                        "unknown point cloud format (use .ply, .pcd, .xyz, .csv or .las)");
  // the text parsers need a NUL after the data
  char* s = vd_malloc(len + 1);
  if (!s) return vd_error_set(err, VD_ERR_NOMEM, name ? name : "", 0, 0, "out of memory");
  if (len) memcpy(s, data, len);
  s[len] = 0;
  reader r = {name ? name : "", err, NULL, 0, 0, -1};
  vd_status st;
  switch (fmt) {
    case VD_CLOUD_PLY: st = read_ply(&r, s, len, out); break;
    case VD_CLOUD_PCD: st = read_pcd(&r, s, len, out); break;
    case VD_CLOUD_XYZ: st = read_text(&r, s, len, 0, out); break;
    case VD_CLOUD_CSV: st = read_text(&r, s, len, 1, out); break;
    default: st = read_las(&r, s, len, out); break;
  }
  vd_free(s, len + 1);
  vd_free(r.labels, (size_t)r.cap_label * sizeof(vd_label));
  if (st) vd_cloud_free(out);
  return st;
}

vd_status vd_cloud_read(const char* path, vd_cloud* out, vd_error* err) {
  if (!path || !out) return vd_error_set(err, VD_ERR_ARG, path ? path : "", 0, 0, "null argument");
  memset(out, 0, sizeof *out);
  vd_cloud_format fmt = vd_cloud_format_of(path);
  if (fmt == VD_CLOUD_AUTO)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "unknown point cloud format (use .ply, .pcd, .xyz, .csv or .las)");
  char* s;
  size_t len;
  vd_status st = vd_file_read(path, &s, &len, err);
  if (st) return st;
  st = vd_cloud_parse(s, len, fmt, path, out, err);
  vd_free(s, len + 1);
  return st;
}
