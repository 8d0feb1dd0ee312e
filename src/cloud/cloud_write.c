// SPDX-License-Identifier: MIT
// Cloud writers: PLY (binary little-endian or ASCII), PCD v0.7 (binary or ASCII), XYZ and CSV
// text, LAS 1.4 point data record format 6 (written here: Debian 12 packages no LAS library).
// Every file carries the label table (header comments, or LAS's classification lookup and label
// table records)
// and is written under a temporary name, renamed when complete.
#include <math.h>
#include <stdlib.h>
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
// progress of the writing, every 64 Ki points and at the end
static void wrote(const vd_cloud_write_def* def, int64_t done, int64_t total) {
  if (def->progress && (done % 65536 == 0 || done == total)) def->progress(def->progress_user, done, total);
}

static void write_records(FILE* fp, const vd_cloud* c, int views, wbuf* wb, const vd_cloud_write_def* def) {
  int threads = def->threads;
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
    if (def->progress) def->progress(def->progress_user, b, c->n);
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
  for (int v = 0; c->view_pose && v < c->nview; v++) {
    const double* q = c->view_pose + 6 * v;
    fprintf(fp, "%sview %d position %.9g %.9g %.9g target %.9g %.9g %.9g\n", lead, v, q[0], q[1], q[2], q[3], q[4],
            q[5]);
  }
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
      wrote(def, i + 1, c->n);
    }
    return;
  }
  write_records(fp, c, views, wb, def);
}

// ---------------------------------------------------------------------------------------------
// PCD v0.7 (PCL): '#' lines are comments for PCL's header reader

// a scanner's pose as translation and unit quaternion w, x, y, z of its frame: z toward the
// target, x to the right, y down (the image convention), world up +z
static void view_quat(const double* pose, double out[7]) {
  double f[3] = {pose[3] - pose[0], pose[4] - pose[1], pose[5] - pose[2]};
  double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (int k = 0; k < 3; k++) f[k] = fl > 0 ? f[k] / fl : (k == 2);
  // right = f x up, or f x y when looking straight up or down
  double up[3] = {0, 0, 1};
  if (fabs(f[2]) > 0.999999) up[0] = 0, up[1] = 1, up[2] = 0;
  double r[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
  double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int k = 0; k < 3; k++) r[k] /= rl;
  double d[3] = {f[1] * r[2] - f[2] * r[1], f[2] * r[0] - f[0] * r[2], f[0] * r[1] - f[1] * r[0]};
  // rotation matrix with columns right, down, forward, to a quaternion (Shepperd)
  double m[3][3] = {{r[0], d[0], f[0]}, {r[1], d[1], f[1]}, {r[2], d[2], f[2]}};
  double w, x, y, z, tr = m[0][0] + m[1][1] + m[2][2];
  if (tr > 0) {
    double t = sqrt(tr + 1) * 2;
    w = t / 4, x = (m[2][1] - m[1][2]) / t, y = (m[0][2] - m[2][0]) / t, z = (m[1][0] - m[0][1]) / t;
  } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
    double t = sqrt(1 + m[0][0] - m[1][1] - m[2][2]) * 2;
    w = (m[2][1] - m[1][2]) / t, x = t / 4, y = (m[0][1] + m[1][0]) / t, z = (m[0][2] + m[2][0]) / t;
  } else if (m[1][1] > m[2][2]) {
    double t = sqrt(1 + m[1][1] - m[0][0] - m[2][2]) * 2;
    w = (m[0][2] - m[2][0]) / t, x = (m[0][1] + m[1][0]) / t, y = t / 4, z = (m[1][2] + m[2][1]) / t;
  } else {
    double t = sqrt(1 + m[2][2] - m[0][0] - m[1][1]) * 2;
    w = (m[1][0] - m[0][1]) / t, x = (m[0][2] + m[2][0]) / t, y = (m[1][2] + m[2][1]) / t, z = t / 4;
  }
  if (w < 0) w = -w, x = -x, y = -y, z = -z;
  double q[7] = {pose[0], pose[1], pose[2], w, x, y, z};
  memcpy(out, q, sizeof q);
}

static void write_pcd(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def, wbuf* wb) {
  int views = c->nview > 0;
  fprintf(fp, "# .PCD v0.7 - Point Cloud Data file format\n");
  comments(fp, "# ", c, def);
  fprintf(fp, "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z label instance%s\n",
          views ? " view range" : "");
  fprintf(fp, "SIZE 4 4 4 4 4 4 4 4%s\nTYPE F F F F F F U U%s\nCOUNT 1 1 1 1 1 1 1 1%s\n",
          views ? " 4 4" : "", views ? " U F" : "", views ? " 1 1" : "");
  // one scanner: its pose is the viewpoint (several: identity, the views are in the comments)
  double vp[7] = {0, 0, 0, 1, 0, 0, 0};
  if (c->nview == 1 && c->view_pose) view_quat(c->view_pose, vp);
  fprintf(fp, "WIDTH %lld\nHEIGHT 1\nVIEWPOINT %.9g %.9g %.9g %.9g %.9g %.9g %.9g\nPOINTS %lld\nDATA %s\n",
          (long long)c->n, vp[0], vp[1], vp[2], vp[3], vp[4], vp[5], vp[6], (long long)c->n,
          def->ascii ? "ascii" : "binary");
  if (def->ascii) {
    for (int64_t i = 0; i < c->n; i++) {
      const double *p = c->pos + 3 * i, *n = c->normal + 3 * i;
      fprintf(fp, "%.9g %.9g %.9g %.9g %.9g %.9g %u %u", (double)(float)p[0], (double)(float)p[1],
              (double)(float)p[2], (double)(float)n[0], (double)(float)n[1], (double)(float)n[2],
              (unsigned)c->label[i], (unsigned)c->instance[i]);
      if (views) fprintf(fp, " %u %.9g", (unsigned)c->view[i], (double)(float)c->range[i]);
      fputc('\n', fp);
      wrote(def, i + 1, c->n);
    }
    return;
  }
  write_records(fp, c, views, wb, def);
}

// ---------------------------------------------------------------------------------------------
// XYZ and CSV

// The column names come first, so numpy's genfromtxt(names=True) (and pandas with comment='#')
// names the columns; XYZ's names line is a comment, which Open3D's XYZ reader skips with the
// others. Then the comments: format, seed, views and their poses, label table.
static void write_text(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def, int csv) {
  int views = c->nview > 0;
  char sep = csv ? ',' : ' ';
  fprintf(fp, "%sx%cy%cz%cnx%cny%cnz%clabel%cinstance", csv ? "" : "# ", sep, sep, sep, sep, sep,
          sep, sep);
  if (views) fprintf(fp, "%cview%crange", sep, sep);
  fputc('\n', fp);
  comments(fp, "# ", c, def);
  for (int64_t i = 0; i < c->n; i++) {
    const double *p = c->pos + 3 * i, *n = c->normal + 3 * i;
    fprintf(fp, "%.9g%c%.9g%c%.9g%c%.7g%c%.7g%c%.7g%c%d%c%d", p[0], sep, p[1], sep, p[2], sep, n[0],
            sep, n[1], sep, n[2], sep, c->label[i], sep, c->instance[i]);
    if (views) fprintf(fp, "%c%d%c%.9g", sep, c->view[i], sep, c->range[i]);
    fputc('\n', fp);
    wrote(def, i + 1, c->n);
  }
}

// ---------------------------------------------------------------------------------------------
// LAS 1.4, point data record format 6, with extra bytes (label, instance, view, range, normal)
//
// Classification follows the ASPRS codes where they fit and keeps the label otherwise: label 0
// (no organ) is 1 "unclassified", a label named ground or soil is 2 "ground", label id L is the
// user-definable class 64 + L (L <= 191), and larger ids are 1; the classification lookup VLR
// names the classes used. The exact label id (any int32) is in the "label" extra bytes, and a
// verdant VLR (user id "verdant", record 1) holds the label table: id, class, name.

#define LAS_HEADER 375
#define LAS_VLR_HEADER 54
#define LAS_EXTRA_DESC 192
#define LAS_PF6 30
#define LAS_EXTRA 28  // label i32, instance i32, view i32, range f32, normal 3 x f32
#define LAS_LABEL_ENTRY 56  // verdant label table entry: id i32, class u8, 3 reserved, name 48

// the extra-bytes descriptors (LAS 1.4 R15, table 24): name and data type
static const struct {
  const char* name;
  int type;  // 6 = int32, 9 = float
  const char* desc;
} las_extra[] = {
    {"label", 6, "semantic label id (the label table)"},
    {"instance", 6, "organ instance id"},
    {"view", 6, "scanner view (also point source id)"},
    {"range", 9, "distance to the scanner (m)"},
    {"NormalX", 9, "surface normal x"},
    {"NormalY", 9, "surface normal y"},
    {"NormalZ", 9, "surface normal z"},
};

// the ASPRS class of a label (see above)
static int las_class(int id, const char* name) {
  if (id == 0) return 1;
  if (name && (vd_organ_from_name(name) == VD_ORGAN_OTHER) &&
      (strstr(name, "ground") || strstr(name, "Ground") || strstr(name, "soil") || strstr(name, "Soil")))
    return 2;
  return id > 0 && id <= 191 ? 64 + id : 1;
}

typedef struct las_id_class {
  int id, cls;
} las_id_class;

static int cmp_id_class(const void* a, const void* b) {
  int x = ((const las_id_class*)a)->id, y = ((const las_id_class*)b)->id;
  return (x > y) - (x < y);
}

// the verdant label table record: per label its id (int32), class (uint8), 3 reserved bytes and
// its name (48 bytes, NUL-padded)
static void las_label_table(FILE* fp, const vd_cloud* c) {
  for (int i = 0; i < c->nlabel; i++) {
    unsigned char e[LAS_LABEL_ENTRY];
    memset(e, 0, sizeof e);
    put_u32(e, (uint32_t)c->labels[i].id);
    e[4] = (unsigned char)las_class(c->labels[i].id, c->labels[i].name);
    char name[VD_LABEL_NAME_MAX];
    one_line(c->labels[i].name, name, sizeof name);
    put_str(e + 8, name, 47);
    fwrite(e, 1, sizeof e, fp);
  }
}

static void vlr_header(unsigned char* p, const char* user, int record, unsigned len, const char* desc) {
  memset(p, 0, LAS_VLR_HEADER);
  put_str(p + 2, user, 16);
  put_u16(p + 18, (unsigned)record);
  put_u16(p + 20, len);
  put_str(p + 22, desc, 31);
}

static vd_status write_las(FILE* fp, const vd_cloud* c, const vd_cloud_write_def* def,
                           wbuf* wb, const char* path, vd_error* err) {
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
  // the classes of the label table: one lookup entry per class used (the first label naming it)
  unsigned char cls[256] = {0};  // class -> 1 when in the lookup
  int nlookup = 0;
  for (int i = 0; i < c->nlabel; i++) {
    int k = las_class(c->labels[i].id, c->labels[i].name);
    if (!cls[k]) cls[k] = 1, nlookup++;
  }
  int nextra = (int)(sizeof las_extra / sizeof las_extra[0]);
  unsigned class_len = (unsigned)nlookup * 16, extra_len = (unsigned)nextra * LAS_EXTRA_DESC;
  // the label table in a VLR, or after the points in an extended VLR when it is too long for one
  // (more than 1170 labels: instance labels)
  uint64_t label_len = (uint64_t)c->nlabel * LAS_LABEL_ENTRY;
  int table_vlr = c->nlabel > 0 && label_len <= 65535, table_evlr = c->nlabel > 0 && !table_vlr;
  // the scanners' poses: position and target, 6 doubles each (a VLR while they fit)
  unsigned views_len = c->view_pose && c->nview <= 1365 ? (unsigned)c->nview * 48 : 0;
  int nvlr = (nlookup > 0) + 1 + table_vlr + (views_len > 0);
  uint32_t offset = LAS_HEADER + (uint32_t)(nlookup > 0) * (LAS_VLR_HEADER + class_len) + LAS_VLR_HEADER + extra_len +
                    (uint32_t)table_vlr * (LAS_VLR_HEADER + (uint32_t)label_len) +
                    (views_len ? LAS_VLR_HEADER + views_len : 0);
  // the class of each label id, sorted by id for the points
  las_id_class* ids = vd_malloc((size_t)(c->nlabel ? c->nlabel : 1) * sizeof *ids);
  if (!ids) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory writing a cloud");
  for (int i = 0; i < c->nlabel; i++) ids[i].id = c->labels[i].id, ids[i].cls = las_class(c->labels[i].id, c->labels[i].name);
  qsort(ids, (size_t)c->nlabel, sizeof *ids, cmp_id_class);
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
  if (table_evlr) {
    put_u64(h + 235, (uint64_t)offset + (uint64_t)c->n * (LAS_PF6 + LAS_EXTRA));
    put_u32(h + 243, 1);
  }
  put_u64(h + 247, (uint64_t)c->n);
  put_u64(h + 255, (uint64_t)c->n);  // every point is a first (and only) return
  fwrite(h, 1, sizeof h, fp);
  // classification lookup: the classes used, named by their labels (15 characters each)
  unsigned char vh[LAS_VLR_HEADER];
  if (nlookup > 0) {
    vlr_header(vh, "LASF_Spec", 0, class_len, "Classification lookup");
    fwrite(vh, 1, sizeof vh, fp);
    unsigned char done[256] = {0};
    for (int i = 0; i < c->nlabel; i++) {
      int k = las_class(c->labels[i].id, c->labels[i].name);
      if (done[k]) continue;
      done[k] = 1;
      unsigned char e[16];
      memset(e, 0, sizeof e);
      e[0] = (unsigned char)k;
      char name[VD_LABEL_NAME_MAX];
      one_line(k == 1 ? "unclassified" : c->labels[i].name, name, sizeof name);
      put_str(e + 1, name, 15);
      fwrite(e, 1, sizeof e, fp);
    }
  }
  // extra bytes descriptors
  vlr_header(vh, "LASF_Spec", 4, extra_len, "Extra bytes");
  fwrite(vh, 1, sizeof vh, fp);
  for (int i = 0; i < nextra; i++) {
    unsigned char d[LAS_EXTRA_DESC];
    memset(d, 0, sizeof d);
    d[2] = (unsigned char)las_extra[i].type;
    put_str(d + 4, las_extra[i].name, 31);
    put_str(d + 160, las_extra[i].desc, 31);
    fwrite(d, 1, sizeof d, fp);
  }
  if (table_vlr) {
    vlr_header(vh, "verdant", 1, (unsigned)label_len, "Label table: id, class, name");
    fwrite(vh, 1, sizeof vh, fp);
    las_label_table(fp, c);
  }
  if (views_len) {
    vlr_header(vh, "verdant", 2, views_len, "Views: position, target (m)");
    fwrite(vh, 1, sizeof vh, fp);
    for (int v = 0; v < 6 * c->nview; v++) {
      unsigned char e[8];
      put_f64(e, c->view_pose[v]);
      fwrite(e, 1, sizeof e, fp);
    }
  }
  // points: the class of a label of the table from the table, any other from its id
  wb->fp = fp, wb->n = 0;
  int last = -1, last_class = 1;
  for (int64_t i = 0; i < c->n; i++) {
    unsigned char* r = wb_take(wb, LAS_PF6 + LAS_EXTRA);
    memset(r, 0, LAS_PF6 + LAS_EXTRA);
    for (int k = 0; k < 3; k++)
      put_u32(r + 4 * k, (uint32_t)(int32_t)llround((c->pos[3 * i + k] - off[k]) / scale));
    r[14] = 0x11;  // return 1 of 1
    r[15] = 0x01;  // classification flag: synthetic (made by a sensor model, not a LiDAR)
    int l = c->label[i];
    if (l != last || i == 0) {
      las_id_class key = {l, 0};
      const las_id_class* at = bsearch(&key, ids, (size_t)c->nlabel, sizeof *ids, cmp_id_class);
      last = l, last_class = at ? at->cls : las_class(l, NULL);
    }
    r[16] = (unsigned char)last_class;
    put_u16(r + 20, (unsigned)c->view[i]);
    put_u32(r + 30, (uint32_t)l);
    put_u32(r + 34, (uint32_t)c->instance[i]);
    put_u32(r + 38, (uint32_t)c->view[i]);
    put_f32(r + 42, c->range[i]);
    for (int k = 0; k < 3; k++)
      put_f32(r + 46 + 4 * k, c->normal[3 * i + k]);
    wrote(def, i + 1, c->n);
  }
  wb_flush(wb);
  vd_free(ids, (size_t)(c->nlabel ? c->nlabel : 1) * sizeof *ids);
  if (table_evlr) {
    // extended VLR header (LAS 1.4 R15, table 14): 60 bytes, an 8-byte length
    unsigned char eh[60];
    memset(eh, 0, sizeof eh);
    put_str(eh + 2, "verdant", 16);
    put_u16(eh + 18, 1);
    put_u64(eh + 20, label_len);
    put_str(eh + 28, "Label table: id, class, name", 31);
    fwrite(eh, 1, sizeof eh, fp);
    las_label_table(fp, c);
  }
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
