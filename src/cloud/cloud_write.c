// SPDX-License-Identifier: MIT
// Cloud writers: PLY (binary little-endian or ASCII), PCD v0.7 (binary or ASCII), XYZ and CSV
// text, LAS 1.4 point data record format 6 (written here: Debian 12 packages no LAS library).
// Every file carries the label table (header comments, or LAS's classification lookup record)
// and is written under a temporary name, renamed when complete.
#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "cloud_internal.h"

vd_cloud_write_def vd_cloud_write_def_default(void) {
  vd_cloud_write_def def;
  memset(&def, 0, sizeof def);
  def.format = VD_CLOUD_AUTO;
  def.ascii = 0;
  def.ply_prefix = NULL;
  def.comment = NULL;
  def.threads = 0;
  return def;
}

static int has_ext(const char* path, const char* ext) {
  size_t n = strlen(path), e = strlen(ext);
  if (n < e) return 0;
  for (size_t i = 0; i < e; i++) {
    char c = path[n - e + i];
    if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
    if (c != ext[i]) return 0;
  }
  return 1;
}

vd_cloud_format vd_cloud_format_of(const char* path) {
  if (!path) return VD_CLOUD_AUTO;
  if (has_ext(path, ".ply")) return VD_CLOUD_PLY;
  if (has_ext(path, ".pcd")) return VD_CLOUD_PCD;
  if (has_ext(path, ".xyz")) return VD_CLOUD_XYZ;
  if (has_ext(path, ".csv")) return VD_CLOUD_CSV;
  if (has_ext(path, ".las")) return VD_CLOUD_LAS;
  return VD_CLOUD_AUTO;
}

// ---------------------------------------------------------------------------------------------
// helpers: little-endian fields, a write buffer, one-line names

typedef struct wbuf {
  FILE* fp;
  unsigned char data[1 << 19];
  size_t n;
} wbuf;

static void wb_flush(wbuf* b) {
  if (b->n) fwrite(b->data, 1, b->n, b->fp);
  b->n = 0;
}
static unsigned char* wb_take(wbuf* b, size_t n) {
  if (b->n + n > sizeof b->data) wb_flush(b);
  unsigned char* p = b->data + b->n;
  b->n += n;
  return p;
}

static void put_u16(unsigned char* p, unsigned v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }
static void put_u32(unsigned char* p, uint32_t v) {
  for (int k = 0; k < 4; k++)
    p[k] = (unsigned char)(v >> (8 * k));
}
static void put_u64(unsigned char* p, uint64_t v) {
  for (int k = 0; k < 8; k++)
    p[k] = (unsigned char)(v >> (8 * k));
}
static void put_f32(unsigned char* p, double v) {
  float f = (float)v;
  uint32_t u;
  memcpy(&u, &f, 4);
  put_u32(p, u);
}
static void put_f64(unsigned char* p, double v) {
  uint64_t u;
  memcpy(&u, &v, 8);
  put_u64(p, u);
}

// 1 on a little-endian host: records are then copied field by field with memcpy
static int host_le(void) {
  const uint32_t one = 1;
  unsigned char b;
  memcpy(&b, &one, 1);
  return b == 1;
}

// one PLY/PCD record: six float32, two int32 (+ int32 view, float32 range)
static void put_record(unsigned char* r, const vd_cloud* c, int64_t i, int views, int le) {
  if (le) {
    float f[6] = {(float)c->pos[3 * i], (float)c->pos[3 * i + 1], (float)c->pos[3 * i + 2],
                  (float)c->normal[3 * i], (float)c->normal[3 * i + 1], (float)c->normal[3 * i + 2]};
    int32_t id[2] = {c->label[i], c->instance[i]};
    memcpy(r, f, 24);
    memcpy(r + 24, id, 8);
    if (views) {
      int32_t v = c->view[i];
      float rg = (float)c->range[i];
      memcpy(r + 32, &v, 4);
      memcpy(r + 36, &rg, 4);
    }
    return;
  }
  for (int k = 0; k < 3; k++) {
    put_f32(r + 4 * k, c->pos[3 * i + k]);
    put_f32(r + 12 + 4 * k, c->normal[3 * i + k]);
  }
  put_u32(r + 24, (uint32_t)c->label[i]);
  put_u32(r + 28, (uint32_t)c->instance[i]);
  if (views) {
    put_u32(r + 32, (uint32_t)c->view[i]);
    put_f32(r + 36, c->range[i]);
  }
}

// the binary PLY/PCD records, a buffer at a time; large buffers are filled by several threads
// (each record is converted alone, so the bytes do not depend on the thread count)
static void write_records(FILE* fp, const vd_cloud* c, int views, wbuf* wb, int threads) {
  int64_t rec = views ? 40 : 32, per = (int64_t)sizeof wb->data / rec;
  int le = host_le();
#ifdef _OPENMP
  if (threads <= 0) threads = omp_get_max_threads();
#else
  (void)threads;
#endif
  for (int64_t a = 0; a < c->n; a += per) {
    int64_t b = a + per < c->n ? a + per : c->n;
    unsigned char* data = wb->data;
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1 && b - a >= 8192)
    for (int64_t i = a; i < b; i++)
      put_record(data + (i - a) * rec, c, i, views, le);
    fwrite(data, (size_t)rec, (size_t)(b - a), fp);
  }
}

// a string into a fixed field of cap bytes, cut, NUL-padded (the field is zeroed before)
static void put_str(unsigned char* p, const char* str, size_t cap) {
  size_t n = strlen(str);
  memcpy(p, str, n < cap ? n : cap);
}

// a label name on one line: control characters become spaces
static void one_line(const char* s, char* buf, size_t cap) {
  size_t n = 0;
  for (; s && *s && n + 1 < cap; s++, n++)
    buf[n] = (char)((unsigned char)*s < 0x20 ? ' ' : *s);
  buf[n] = 0;
}

// header comment lines shared by the text-headed formats: "<lead>verdant cloud ...", the user's
// comment, the views and the label table
static void comments(FILE* fp, const char* lead, const vd_cloud* c, const vd_cloud_write_def* def) {
  fprintf(fp, "%sverdant cloud, format version %d, units m\n", lead, VD_CLOUD_FORMAT_VERSION);
  if (def->comment && def->comment[0]) {
    char line[512];
    one_line(def->comment, line, sizeof line);
    fprintf(fp, "%s%s\n", lead, line);
  }
  fprintf(fp, "%sviews %d\n", lead, c->nview);
  for (int i = 0; i < c->nlabel; i++) {
    char name[VD_LABEL_NAME_MAX];
    one_line(c->labels[i].name, name, sizeof name);
    fprintf(fp, "%slabel %d %s\n", lead, c->labels[i].id, name);
  }
}

// ---------------------------------------------------------------------------------------------
// PLY

static void write_ply(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def, wbuf* wb) {
  const char* pre = def->ply_prefix ? def->ply_prefix : "";
  int views = c->nview > 0;
  fprintf(fp, "ply\nformat %s 1.0\n", def->ascii ? "ascii" : "binary_little_endian");
  comments(fp, "comment ", c, def);
  fprintf(fp,
          "element vertex %lld\nproperty float x\nproperty float y\nproperty float z\n"
          "property float nx\nproperty float ny\nproperty float nz\n"
          "property int %slabel\nproperty int %sinstance\n",
          (long long)c->n, pre, pre);
  if (views) fprintf(fp, "property int %sview\nproperty float %srange\n", pre, pre);
  fprintf(fp, "end_header\n");
  if (def->ascii) {
    for (int64_t i = 0; i < c->n; i++) {
      const double *p = c->pos + 3 * i, *n = c->normal + 3 * i;
      fprintf(fp, "%.9g %.9g %.9g %.9g %.9g %.9g %d %d", (double)(float)p[0], (double)(float)p[1],
              (double)(float)p[2], (double)(float)n[0], (double)(float)n[1], (double)(float)n[2],
              c->label[i], c->instance[i]);
      if (views) fprintf(fp, " %d %.9g", c->view[i], (double)(float)c->range[i]);
      fputc('\n', fp);
    }
    return;
  }
  write_records(fp, c, views, wb, def->threads);
}

// ---------------------------------------------------------------------------------------------
// PCD v0.7 (PCL): '#' lines are comments for PCL's header reader

static void write_pcd(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def, wbuf* wb) {
  int views = c->nview > 0;
  fprintf(fp, "# .PCD v0.7 - Point Cloud Data file format\n");
  comments(fp, "# ", c, def);
  fprintf(fp, "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z label instance%s\n",
          views ? " view range" : "");
  fprintf(fp, "SIZE 4 4 4 4 4 4 4 4%s\nTYPE F F F F F F U U%s\nCOUNT 1 1 1 1 1 1 1 1%s\n",
          views ? " 4 4" : "", views ? " U F" : "", views ? " 1 1" : "");
  fprintf(fp, "WIDTH %lld\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %lld\nDATA %s\n",
          (long long)c->n, (long long)c->n, def->ascii ? "ascii" : "binary");
  if (def->ascii) {
    for (int64_t i = 0; i < c->n; i++) {
      const double *p = c->pos + 3 * i, *n = c->normal + 3 * i;
      fprintf(fp, "%.9g %.9g %.9g %.9g %.9g %.9g %u %u", (double)(float)p[0], (double)(float)p[1],
              (double)(float)p[2], (double)(float)n[0], (double)(float)n[1], (double)(float)n[2],
              (unsigned)c->label[i], (unsigned)c->instance[i]);
      if (views) fprintf(fp, " %u %.9g", (unsigned)c->view[i], (double)(float)c->range[i]);
      fputc('\n', fp);
    }
    return;
  }
  write_records(fp, c, views, wb, def->threads);
}

// ---------------------------------------------------------------------------------------------
// XYZ and CSV

static void write_text(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def, int csv) {
  int views = c->nview > 0;
  char sep = csv ? ',' : ' ';
  comments(fp, "# ", c, def);
  fprintf(fp, "%sx%cy%cz%cnx%cny%cnz%clabel%cinstance", csv ? "" : "# ", sep, sep, sep, sep, sep,
          sep, sep);
  if (views) fprintf(fp, "%cview%crange", sep, sep);
  fputc('\n', fp);
  for (int64_t i = 0; i < c->n; i++) {
    const double *p = c->pos + 3 * i, *n = c->normal + 3 * i;
    fprintf(fp, "%.9g%c%.9g%c%.9g%c%.7g%c%.7g%c%.7g%c%d%c%d", p[0], sep, p[1], sep, p[2], sep, n[0],
            sep, n[1], sep, n[2], sep, c->label[i], sep, c->instance[i]);
    if (views) fprintf(fp, "%c%d%c%.9g", sep, c->view[i], sep, c->range[i]);
    fputc('\n', fp);
  }
}

// ---------------------------------------------------------------------------------------------
// LAS 1.4, point data record format 6, with extra bytes (instance, range, normal)

#define LAS_HEADER 375
#define LAS_VLR_HEADER 54
#define LAS_EXTRA_DESC 192
#define LAS_PF6 30
#define LAS_EXTRA 20  // instance i32, range f32, normal 3 x f32

// the extra-bytes descriptors (LAS 1.4 R15, table 24): name and data type
static const struct {
  const char* name;
  int type;  // 6 = int32, 9 = float
  const char* desc;
} las_extra[] = {
    {"instance", 6, "organ instance id"},
    {"range", 9, "distance to the scanner (m)"},
    {"NormalX", 9, "surface normal x"},
    {"NormalY", 9, "surface normal y"},
    {"NormalZ", 9, "surface normal z"},
};

static void vlr_header(unsigned char* p, int record, unsigned len, const char* desc) {
  memset(p, 0, LAS_VLR_HEADER);
  memcpy(p + 2, "LASF_Spec", 9);  // NOLINT(bugprone-not-null-terminated-result): a fixed-width LAS field, no NUL
  put_u16(p + 18, (unsigned)record);
  put_u16(p + 20, len);
  put_str(p + 22, desc, 31);
}

static vd_status write_las(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def,
                           wbuf* wb, const char* path, vd_error* err) {
  (void)def;
  for (int i = 0; i < c->nlabel; i++)
    if (c->labels[i].id < 0 || c->labels[i].id > 255)
      return vd_error_set(err, VD_ERR_VALUE, path, 0, 0,
                          "LAS classification holds labels 0..255, the table has %d",
                          c->labels[i].id);
  for (int64_t i = 0; i < c->n; i++)
    if (c->label[i] < 0 || c->label[i] > 255)
      return vd_error_set(err, VD_ERR_VALUE, path, 0, 0,
                          "LAS classification holds labels 0..255, point %lld has %d",
                          (long long)i, c->label[i]);
  if (c->nview > 65535)
    return vd_error_set(err, VD_ERR_VALUE, path, 0, 0, "LAS point source id holds 65536 views");
  // bounds, offset (the centre in whole metres) and a power-of-ten scale from 1 um up that keeps
  // every coordinate in int32
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, off[3], scale = 1e-6;
  for (int k = 0; k < 3; k++) {
    lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int64_t i = 0; i < c->n; i++) {
      double v = c->pos[3 * i + k];
      if (!isfinite(v)) return vd_error_set(err, VD_ERR_VALUE, path, 0, 0, "point %lld is not finite", (long long)i);
      lo[k] = fmin(lo[k], v), hi[k] = fmax(hi[k], v);
    }
    if (c->n == 0) lo[k] = hi[k] = 0;
    off[k] = floor(0.5 * (lo[k] + hi[k]) + 0.5);
    while (fmax(fabs(hi[k] - off[k]), fabs(lo[k] - off[k])) / scale > 2.0e9 && scale < 1e6) scale *= 10;
  }
  int nclass = c->nlabel;
  int nextra = (int)(sizeof las_extra / sizeof las_extra[0]);
  unsigned class_len = (unsigned)nclass * 16, extra_len = (unsigned)nextra * LAS_EXTRA_DESC;
  int nvlr = (nclass > 0) + 1;
  uint32_t offset = LAS_HEADER + (uint32_t)(nclass > 0) * (LAS_VLR_HEADER + class_len) + LAS_VLR_HEADER + extra_len;
  // the public header block
  unsigned char h[LAS_HEADER];
  memset(h, 0, sizeof h);
  memcpy(h, "LASF", 4);  // NOLINT(bugprone-not-null-terminated-result): a fixed-width LAS field, no NUL
  put_u16(h + 6, 1u << 4);  // global encoding: WKT coordinate system bit (required for PDRF 6+)
  h[24] = 1, h[25] = 4;
  put_str(h + 26, "verdant synthetic cloud", 31);
  put_str(h + 58, "verdant " VD_VERSION_STRING, 31);
  put_u16(h + 90, 0), put_u16(h + 92, 0);  // creation day and year: 0, so a seed gives one file
  put_u16(h + 94, LAS_HEADER);
  put_u32(h + 96, offset);
  put_u32(h + 100, (uint32_t)nvlr);
  h[104] = 6;
  put_u16(h + 105, LAS_PF6 + LAS_EXTRA);
  for (int k = 0; k < 3; k++) {
    put_f64(h + 131 + 8 * k, scale);
    put_f64(h + 155 + 8 * k, off[k]);
    // stored extremes: what the scaled integers give back
    double mx = off[k] + scale * (double)llround((hi[k] - off[k]) / scale);
    double mn = off[k] + scale * (double)llround((lo[k] - off[k]) / scale);
    put_f64(h + 179 + 16 * k, mx);
    put_f64(h + 187 + 16 * k, mn);
  }
  put_u64(h + 247, (uint64_t)c->n);
  put_u64(h + 255, (uint64_t)c->n);  // every point is a first (and only) return
  fwrite(h, 1, sizeof h, fp);
  // classification lookup: label names, 15 characters each
  unsigned char vh[LAS_VLR_HEADER];
  if (nclass > 0) {
    vlr_header(vh, 0, class_len, "Classification lookup");
    fwrite(vh, 1, sizeof vh, fp);
    for (int i = 0; i < nclass; i++) {
      unsigned char e[16];
      memset(e, 0, sizeof e);
      e[0] = (unsigned char)c->labels[i].id;
      char name[VD_LABEL_NAME_MAX];
      one_line(c->labels[i].name, name, sizeof name);
      put_str(e + 1, name, 15);
      fwrite(e, 1, sizeof e, fp);
    }
  }
  // extra bytes descriptors
  vlr_header(vh, 4, extra_len, "Extra bytes");
  fwrite(vh, 1, sizeof vh, fp);
  for (int i = 0; i < nextra; i++) {
    unsigned char d[LAS_EXTRA_DESC];
    memset(d, 0, sizeof d);
    d[2] = (unsigned char)las_extra[i].type;
    put_str(d + 4, las_extra[i].name, 31);
    put_str(d + 160, las_extra[i].desc, 31);
    fwrite(d, 1, sizeof d, fp);
  }
  // points
  wb->fp = fp, wb->n = 0;
  for (int64_t i = 0; i < c->n; i++) {
    unsigned char* r = wb_take(wb, LAS_PF6 + LAS_EXTRA);
    memset(r, 0, LAS_PF6 + LAS_EXTRA);
    for (int k = 0; k < 3; k++)
      put_u32(r + 4 * k, (uint32_t)(int32_t)llround((c->pos[3 * i + k] - off[k]) / scale));
    r[14] = 0x11;  // return 1 of 1
    r[16] = (unsigned char)c->label[i];
    put_u16(r + 20, (unsigned)c->view[i]);
    put_u32(r + 30, (uint32_t)c->instance[i]);
    put_f32(r + 34, c->range[i]);
    for (int k = 0; k < 3; k++)
      put_f32(r + 38 + 4 * k, c->normal[3 * i + k]);
  }
  wb_flush(wb);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// dispatch

vd_status vd_cloud_write(const vd_cloud* c, const char* path, const vd_cloud_write_def* def_in,
                         vd_error* err) {
  if (!c || !path) return vd_error_set(err, VD_ERR_ARG, path ? path : "", 0, 0, "null argument");
  if (c->n < 0 || (c->n > 0 && (!c->pos || !c->normal || !c->label || !c->instance || !c->view ||
                                !c->range)))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "cloud arrays missing");
  vd_cloud_write_def def = def_in ? *def_in : vd_cloud_write_def_default();
  vd_cloud_format fmt = def.format == VD_CLOUD_AUTO ? vd_cloud_format_of(path) : def.format;
  if (fmt == VD_CLOUD_AUTO)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0,
                        "unknown point cloud format (use .ply, .pcd, .xyz, .csv or .las)");
  if (def.ply_prefix) {
    for (const char* p = def.ply_prefix; *p; p++)
      if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '_'))
        return vd_error_set(err, VD_ERR_ARG, path, 0, 0,
                            "PLY property prefix '%s': letters, digits and '_' only", def.ply_prefix);
    if (strlen(def.ply_prefix) > 32) return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "PLY property prefix too long");
  }
  // a 512 KiB record buffer for the binary formats, then the file under a temporary name
  wbuf* wb = vd_malloc(sizeof *wb);
  if (!wb) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory writing a cloud");
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (!st) {
    switch (fmt) {
      case VD_CLOUD_PLY: write_ply(f.fp, c, &def, wb); break;
      case VD_CLOUD_PCD: write_pcd(f.fp, c, &def, wb); break;
      case VD_CLOUD_XYZ: write_text(f.fp, c, &def, 0); break;
      case VD_CLOUD_CSV: write_text(f.fp, c, &def, 1); break;
      default: st = write_las(f.fp, c, &def, wb, path, err); break;
    }
    if (!st) st = vd_outfile_commit(&f, err);
    vd_outfile_abort(&f);
  }
  vd_free(wb, sizeof *wb);
  return st;
}
