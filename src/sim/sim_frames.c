// SPDX-License-Identifier: MIT
// Reading frames back: frames.bin (a header, then fixed-size little-endian records, read by
// seeking) and frames.jsonl (one JSON object per line, kept in memory and parsed per frame).
// Opening indexes every frame's time and checks every size against the file, so a frame load
// only fails on numbers that do not fit the model it is loaded into.
#include <cjson/cJSON.h>
#include <errno.h>
#include <stdio.h>

#include "sim_internal.h"

#define HEADER_BYTES 24

struct vd_sim_frames {
  char path[4096]; // file name, for errors
  int jsonl;       // 1: JSON Lines, 0: binary
  int nframe;      // frames
  int nnode, nseg; // sizes of every frame
  double* time;    // time of each frame (s) (nframe)
  // binary
  FILE* fp;           // open file
  size_t record;      // bytes of one record
  unsigned char* buf; // one record
  // JSON Lines
  char* text; // whole file (len + 1 bytes)
  size_t len;
  size_t* line_at; // offset of each frame's line (nframe)
  int* line_no;    // its line number (nframe)
};

static uint32_t get_u32(const unsigned char* b) {
  return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static double get_f64(const unsigned char* b) {
  uint64_t u = 0;
  for (int k = 7; k >= 0; k--)
    u = u << 8 | b[k];
  double d;
  memcpy(&d, &u, 8);
  return d;
}

static float get_f32(const unsigned char* b) {
  uint32_t u = get_u32(b);
  float f;
  memcpy(&f, &u, 4);
  return f;
}

// ---------------------------------------------------------------------------------------------
// opening

// the time of frame k is finite and not before the previous one
static vd_status check_time(vd_sim_frames* f, int k, int line, long long offset, vd_error* err) {
  double t = f->time[k];
  if (isfinite(t) && (!k || t >= f->time[k - 1])) return VD_OK;
  const char* what = isfinite(t) ? "before the previous frame's" : "not finite";
  if (line)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0, "frame %d: time %g is %s", k, t,
                        what);
  return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0, "frame %d at byte %lld: time %g is %s", k,
                      offset, t, what);
}

static vd_status open_bin(vd_sim_frames* f, vd_error* err) {
  f->fp = fopen(f->path, "rb");
  if (!f->fp)
    return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "cannot open: %s", strerror(errno));
  unsigned char h[HEADER_BYTES];
  if (fread(h, 1, sizeof h, f->fp) != sizeof h)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0, "shorter than the 24-byte header");
  if (memcmp(h, "VDSIMFRM", 8) != 0)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0,
                        "not a verdant frames file (no VDSIMFRM)");
  uint32_t ver = get_u32(h + 8), nn = get_u32(h + 12), ns = get_u32(h + 16);
  if (ver != VD_SIM_FRAMES_VERSION)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0,
                        "frames version %u (this verdant reads %d)", (unsigned)ver,
                        VD_SIM_FRAMES_VERSION);
  if (nn > 100000000u || ns > 100000000u)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0,
                        "header: %u nodes, %u segments: too many", (unsigned)nn, (unsigned)ns);
  f->nnode = (int)nn, f->nseg = (int)ns;
  f->record = 8 + 12 * (size_t)nn + 17 * (size_t)ns;
  if (fseek(f->fp, 0, SEEK_END) != 0)
    return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "cannot seek: %s", strerror(errno));
  long size = ftell(f->fp);
  if (size < HEADER_BYTES)
    return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "cannot tell its size");
  size_t body = (size_t)size - HEADER_BYTES;
  if (body % f->record)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0,
                        "%zu bytes after the header are not a whole number of %zu-byte frames "
                        "(%d nodes, %d segments): truncated?",
                        body, f->record, f->nnode, f->nseg);
  if (body / f->record > 100000000u)
    return vd_error_set(err, VD_ERR_LIMIT, f->path, 0, 0, "more than 1e8 frames");
  f->nframe = (int)(body / f->record);
  f->buf = vd_malloc(f->record);
  f->time = vd_malloc(sizeof(double) * (size_t)(f->nframe ? f->nframe : 1));
  if (!f->buf || !f->time) return vd_error_set(err, VD_ERR_NOMEM, f->path, 0, 0, "out of memory");
  // the time of every frame
  for (int k = 0; k < f->nframe; k++) {
    long long at = HEADER_BYTES + (long long)k * (long long)f->record;
    unsigned char b[8];
    if (fseek(f->fp, (long)at, SEEK_SET) != 0 || fread(b, 1, 8, f->fp) != 8)
      return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "cannot read frame %d at byte %lld", k,
                          at);
    f->time[k] = get_f64(b);
    vd_status st = check_time(f, k, 0, at, err);
    if (st) return st;
  }
  return VD_OK;
}

// a JSON array of numbers of the expected length n (n < 0: any), or NULL
static const cJSON* number_array(const cJSON* o, const char* key, int n) {
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!cJSON_IsArray(a) || (n >= 0 && cJSON_GetArraySize(a) != n)) return NULL;
  return a;
}

// parse line k of a JSON Lines file; checks the sizes (f->nnode < 0 on the first line: take them)
static vd_status parse_line(vd_sim_frames* f, int k, cJSON** out, vd_error* err) {
  const char* s = f->text + f->line_at[k];
  const char* e = strchr(s, '\n');
  size_t n = e ? (size_t)(e - s) : strlen(s);
  int line = f->line_no[k];
  cJSON* o = cJSON_ParseWithLength(s, n);
  if (!o || !cJSON_IsObject(o)) {
    cJSON_Delete(o);
    return vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0, "not a JSON object");
  }
  const cJSON* t = cJSON_GetObjectItemCaseSensitive(o, "t");
  const cJSON* pos = number_array(o, "pos", -1);
  const cJSON* quat = number_array(o, "quat", -1);
  const cJSON* br = number_array(o, "broken", -1);
  const char* bad = !cJSON_IsNumber(t) ? "\"t\" (a number, s)"
                    : !pos             ? "\"pos\" (an array of x, y, z per node)"
                    : !quat            ? "\"quat\" (an array of w, x, y, z per segment)"
                    : !br              ? "\"broken\" (an array of segment ids)"
                                       : NULL;
  if (bad) {
    cJSON_Delete(o);
    return vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0, "missing or bad %s", bad);
  }
  int np = cJSON_GetArraySize(pos), nq = cJSON_GetArraySize(quat);
  if (f->nnode < 0) {
    if (np % 3 || nq % 4) {
      cJSON_Delete(o);
      return vd_error_set(
          err, VD_ERR_FORMAT, f->path, line, 0,
          "\"pos\" has %d numbers and \"quat\" %d: not 3 per node and 4 per segment", np, nq);
    }
    f->nnode = np / 3, f->nseg = nq / 4;
  }
  if (np != 3 * f->nnode || nq != 4 * f->nseg) {
    cJSON_Delete(o);
    return vd_error_set(
        err, VD_ERR_FORMAT, f->path, line, 0,
        "%d node and %d segment values where the first frame has %d nodes and %d segments", np / 3,
        nq / 4, f->nnode, f->nseg);
  }
  f->time[k] = t->valuedouble;
  vd_status st = check_time(f, k, line, 0, err);
  if (st) {
    cJSON_Delete(o);
    return st;
  }
  *out = o;
  return VD_OK;
}

static vd_status open_jsonl(vd_sim_frames* f, vd_error* err) {
  vd_status st = vd_file_read(f->path, &f->text, &f->len, err);
  if (st) return st;
  // one frame per non-blank line
  int n = 0;
  for (size_t i = 0; i < f->len;) {
    const char* e = memchr(f->text + i, '\n', f->len - i);
    size_t end = e ? (size_t)(e - f->text) : f->len;
    size_t j = i;
    while (j < end && (f->text[j] == ' ' || f->text[j] == '\t' || f->text[j] == '\r'))
      j++;
    n += j < end;
    i = end + 1;
  }
  f->nframe = n;
  size_t cap = (size_t)(n ? n : 1);
  f->line_at = vd_malloc(cap * sizeof(size_t));
  f->line_no = vd_malloc(cap * sizeof(int));
  f->time = vd_malloc(cap * sizeof(double));
  if (!f->line_at || !f->line_no || !f->time)
    return vd_error_set(err, VD_ERR_NOMEM, f->path, 0, 0, "out of memory");
  n = 0;
  int line = 0;
  for (size_t i = 0; i < f->len;) {
    line++;
    const char* e = memchr(f->text + i, '\n', f->len - i);
    size_t end = e ? (size_t)(e - f->text) : f->len;
    size_t j = i;
    while (j < end && (f->text[j] == ' ' || f->text[j] == '\t' || f->text[j] == '\r'))
      j++;
    if (j < end) f->line_at[n] = i, f->line_no[n++] = line;
    i = end + 1;
  }
  // every line parsed once: sizes and times
  f->nnode = f->nseg = -1;
  for (int k = 0; k < f->nframe; k++) {
    cJSON* o = NULL;
    if ((st = parse_line(f, k, &o, err))) return st;
    cJSON_Delete(o);
  }
  if (f->nnode < 0) f->nnode = f->nseg = 0;
  return VD_OK;
}

vd_status vd_sim_frames_open(const char* path, vd_sim_frames** out, vd_error* err) {
  *out = NULL;
  vd_sim_frames* f = vd_calloc(1, sizeof *f);
  if (!f) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  snprintf(f->path, sizeof f->path, "%s", path);
  size_t n = strlen(path);
  f->jsonl = n >= 6 && !strcmp(path + n - 6, ".jsonl");
  vd_status st = f->jsonl ? open_jsonl(f, err) : open_bin(f, err);
  if (st) {
    vd_sim_frames_close(f);
    return st;
  }
  *out = f;
  return VD_OK;
}

void vd_sim_frames_close(vd_sim_frames* f) {
  if (!f) return;
  size_t cap = (size_t)(f->nframe ? f->nframe : 1);
  if (f->fp) fclose(f->fp);
  vd_free(f->buf, f->record);
  vd_free(f->time, cap * sizeof(double));
  if (f->text) vd_free(f->text, f->len + 1);
  vd_free(f->line_at, cap * sizeof(size_t));
  vd_free(f->line_no, cap * sizeof(int));
  vd_free(f, sizeof *f);
}

int vd_sim_frames_count(const vd_sim_frames* f) {
  return f->nframe;
}

void vd_sim_frames_size(const vd_sim_frames* f, int* nnode_all, int* nseg) {
  *nnode_all = f->nnode;
  *nseg = f->nseg;
}

double vd_sim_frames_time(const vd_sim_frames* f, int k) {
  VD_ASSERT(k >= 0 && k < f->nframe);
  return f->time[k];
}

int vd_sim_frames_nearest(const vd_sim_frames* f, double t) {
  if (!f->nframe) return -1;
  // first frame at or after t, by bisection (times never decrease)
  int lo = 0, hi = f->nframe;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (f->time[mid] < t)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (lo == f->nframe) return f->nframe - 1;
  if (lo > 0 && t - f->time[lo - 1] <= f->time[lo] - t) return lo - 1;
  return lo;
}

// ---------------------------------------------------------------------------------------------
// loading a frame

// joint t of frame k is broken: the segment hangs from its spare node, at the frame's position
static vd_status detach(const vd_sim_frames* f, const vd_sim_model* m, vd_sim_data* d, int k, int t,
                        int line, vd_error* err) {
  int spare = m->seg_spare[t];
  if (spare < 0)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0,
                        "frame %d: segment %d is marked broken but its joint cannot break", k, t);
  vd_vec3 p = d->node_pos[spare];
  sim_detach(m, d, t);
  d->node_pos[spare] = p;
  d->node_vel[spare] = vd_v3(0, 0, 0);
  return VD_OK;
}

vd_status vd_sim_frames_load(vd_sim_frames* f, int k, const vd_sim_model* m, vd_sim_data* d,
                             vd_error* err) {
  VD_ASSERT(k >= 0 && k < f->nframe);
  if (f->nnode != m->nnode_all || f->nseg != m->nseg)
    return vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0,
                        "frames have %d nodes and %d segments, the rod model %d and %d", f->nnode,
                        f->nseg, m->nnode_all, m->nseg);
  // start from the modelled shape: masses, no motion, no broken joints
  vd_sim_data_reset(m, d);
  int line = f->jsonl ? f->line_no[k] : 0;
  long long at = HEADER_BYTES + (long long)k * (long long)f->record;
  vd_status st = VD_OK;
  cJSON* o = NULL;
  if (f->jsonl) {
    if ((st = parse_line(f, k, &o, err))) return st;
    const cJSON* pos = cJSON_GetObjectItemCaseSensitive(o, "pos");
    const cJSON* quat = cJSON_GetObjectItemCaseSensitive(o, "quat");
    const cJSON* v = pos->child;
    for (int i = 0; i < m->nnode_all; i++) {
      double x[3];
      for (int c = 0; c < 3; c++, v = v->next)
        x[c] = cJSON_IsNumber(v) ? v->valuedouble : NAN;
      d->node_pos[i] = vd_v3(x[0], x[1], x[2]);
    }
    v = quat->child;
    for (int t = 0; t < m->nseg; t++) {
      double q[4];
      for (int c = 0; c < 4; c++, v = v->next)
        q[c] = cJSON_IsNumber(v) ? v->valuedouble : NAN;
      d->seg_quat[t] = (vd_quat){q[0], q[1], q[2], q[3]};
    }
  } else {
    if (fseek(f->fp, (long)at, SEEK_SET) != 0 || fread(f->buf, 1, f->record, f->fp) != f->record)
      return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "cannot read frame %d at byte %lld", k,
                          at);
    const unsigned char* b = f->buf + 8;
    for (int i = 0; i < m->nnode_all; i++, b += 12)
      d->node_pos[i] = vd_v3(get_f32(b), get_f32(b + 4), get_f32(b + 8));
    for (int t = 0; t < m->nseg; t++, b += 16)
      d->seg_quat[t] = (vd_quat){get_f32(b), get_f32(b + 4), get_f32(b + 8), get_f32(b + 12)};
  }
  d->time = f->time[k];
  // finite numbers; frames stored as floats are normalised again
  for (int i = 0; i < m->nnode_all && !st; i++) {
    vd_vec3 p = d->node_pos[i];
    if (!isfinite(p.x + p.y + p.z))
      st = vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0, "frame %d: node %d is not finite", k,
                        i);
  }
  for (int t = 0; t < m->nseg && !st; t++) {
    vd_quat q = d->seg_quat[t];
    double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!isfinite(n) || n < 0.5 || n > 1.5)
      st = vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0,
                        "frame %d: segment %d's quaternion is not a rotation", k, t);
    else
      d->seg_quat[t] = q_normalize(q);
  }
  // broken joints detach as a fracture does, keeping the frame's spare positions
  for (int t = 0; t < m->nseg && !st; t++) {
    int broken;
    if (f->jsonl) {
      broken = 0;
    } else {
      unsigned char flag = f->buf[8 + 12 * (size_t)m->nnode_all + 16 * (size_t)m->nseg + (size_t)t];
      if (flag > 1) {
        st = vd_error_set(err, VD_ERR_FORMAT, f->path, 0, 0,
                          "frame %d: segment %d has flag %u (0 or 1)", k, t, (unsigned)flag);
        break;
      }
      broken = flag;
    }
    if (broken) st = detach(f, m, d, k, t, line, err);
  }
  if (f->jsonl && !st) {
    const cJSON* b;
    cJSON_ArrayForEach(b, cJSON_GetObjectItemCaseSensitive(o, "broken")) {
      // range first: casting an out-of-range double to int is undefined (fuzz finding: inf)
      if (!cJSON_IsNumber(b) || !(b->valuedouble >= 0 && b->valuedouble < m->nseg) ||
          b->valuedouble != floor(b->valuedouble)) {
        st = vd_error_set(err, VD_ERR_FORMAT, f->path, line, 0,
                          "frame %d: \"broken\" holds %g, not a segment id (0..%d)", k,
                          cJSON_IsNumber(b) ? b->valuedouble : NAN, m->nseg - 1);
        break;
      }
      int t = (int)b->valuedouble;
      if (!d->seg_broken[t] && (st = detach(f, m, d, k, t, line, err))) break;
    }
  }
  cJSON_Delete(o);
  return st;
}
