// SPDX-License-Identifier: MIT
// A small reader of point clouds in PLY (ASCII or binary little/big-endian): the vertex element's
// x, y, z and, when present, label and instance. It lets `verdant render` show the clouds that
// verdant and other tools write until the cloud module's readers take over.
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

// PLY scalar types and their sizes
static int type_size(const char* t) {
  static const char* names[][2] = {
      {"char", "1"},  {"int8", "1"},    {"uchar", "1"},  {"uint8", "1"},
      {"short", "2"}, {"int16", "2"},   {"ushort", "2"}, {"uint16", "2"},
      {"int", "4"},   {"int32", "4"},   {"uint", "4"},   {"uint32", "4"},
      {"float", "4"}, {"float32", "4"}, {"double", "8"}, {"float64", "8"}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (!strcmp(t, names[i][0])) return names[i][1][0] - '0';
  return 0;
}

typedef struct prop {
  char type[16];
  int size; // bytes in binary files
  int is_float, is_signed;
  int role; // 0 x, 1 y, 2 z, 3 label, 4 instance, -1 other
} prop;

// one binary scalar as a double
static double get_bin(const unsigned char* p, const prop* q, int big) {
  unsigned char b[8];
  for (int i = 0; i < q->size; i++)
    b[i] = big ? p[q->size - 1 - i] : p[i];
  if (q->is_float) {
    if (q->size == 4) {
      float f;
      memcpy(&f, b, 4);
      return f;
    }
    double d;
    memcpy(&d, b, 8);
    return d;
  }
  uint64_t u = 0;
  for (int i = q->size - 1; i >= 0; i--)
    u = u << 8 | b[i];
  if (q->is_signed && (u >> (8 * q->size - 1)) & 1)
    return (double)(int64_t)(u | (~(uint64_t)0 << (8 * q->size - 1)));
  return (double)u;
}

// arrays are allocated one byte larger so that an empty cloud still has them
void cli_ply_cloud_free(cli_ply_cloud* c) {
  vd_free(c->xyz, sizeof(double) * 3 * (size_t)c->n + 1);
  vd_free(c->label, sizeof(int) * (size_t)c->n + 1);
  vd_free(c->instance, sizeof(int) * (size_t)c->n + 1);
  vd_free(c->labels, sizeof(vd_label) * (size_t)c->nlabel);
  memset(c, 0, sizeof *c);
}

vd_status cli_read_ply_cloud(const char* path, cli_ply_cloud* out, vd_error* err) {
  memset(out, 0, sizeof *out);
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  // label names go through a plant spec, which gives them their organ colours
  vd_plant_spec* names = vd_plant_spec_create();
  if (!names) {
    vd_free(text, len + 1);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  }
  // header, line by line
  prop props[64];
  int nprop = 0, fmt = -1, line = 0, in_vertex = 0, seen_vertex = 0, have[5] = {0};
  long long n = -1;
  size_t pos = 0;
  if (len < 4 || strncmp(text, "ply", 3) || (text[3] != '\n' && text[3] != '\r')) {
    st = vd_error_set(err, VD_ERR_FORMAT, path, 1, 1,
                      "not a PLY file (expected 'ply' on the first line)");
    goto done;
  }
  for (;;) {
    line++;
    size_t e = pos;
    while (e < len && text[e] != '\n')
      e++;
    if (e >= len) {
      st = vd_error_set(err, VD_ERR_FORMAT, path, line, 1, "header without end_header");
      goto done;
    }
    char buf[256];
    size_t l = e - pos < sizeof buf - 1 ? e - pos : sizeof buf - 1;
    memcpy(buf, text + pos, l);
    buf[l] = 0;
    if (l && buf[l - 1] == '\r') buf[--l] = 0;
    pos = e + 1;
    char w0[32] = "", w1[32] = "", w2[32] = "", w3[32] = "";
    int nw = sscanf(buf, "%31s %31s %31s %31s", w0, w1, w2, w3);
    int id, at = 0;
    if (!strcmp(w0, "comment") && sscanf(buf, "comment label %d %n", &id, &at) == 1 && at > 0 &&
        buf[at] && id >= 0 && id <= 65535) {
      if (vd_plant_set_label(names, id, buf + at)) {
        st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
        goto done;
      }
      continue;
    }
    if (line == 1 || nw <= 0 || !strcmp(w0, "comment") || !strcmp(w0, "obj_info")) continue;
    if (!strcmp(w0, "end_header")) break;
    if (!strcmp(w0, "format")) {
      fmt = !strcmp(w1, "ascii")                  ? 0
            : !strcmp(w1, "binary_little_endian") ? 1
            : !strcmp(w1, "binary_big_endian")    ? 2
                                                  : -2;
      if (fmt == -2) {
        st = vd_error_set(err, VD_ERR_FORMAT, path, line, 8, "unknown PLY format '%s'", w1);
        goto done;
      }
    } else if (!strcmp(w0, "element")) {
      if (seen_vertex) { // elements after the vertices are not read
        in_vertex = 0;
        continue;
      }
      in_vertex = !strcmp(w1, "vertex");
      if (!in_vertex) {
        st = vd_error_set(err, VD_ERR_UNSUPPORTED, path, line, 9,
                          "the vertex element must come first (found '%s')", w1);
        goto done;
      }
      seen_vertex = 1;
      char* end;
      errno = 0;
      n = strtoll(w2, &end, 10);
      if (errno || *end || n < 0 || n > 200000000) {
        st = vd_error_set(err, VD_ERR_FORMAT, path, line, 16, "bad vertex count '%s'", w2);
        goto done;
      }
      in_vertex = 1;
    } else if (!strcmp(w0, "property")) {
      if (!in_vertex) continue; // properties of later elements: not read
      if (!strcmp(w1, "list")) {
        st = vd_error_set(err, VD_ERR_UNSUPPORTED, path, line, 10,
                          "list properties of vertices are not supported");
        goto done;
      }
      if (nprop == 64 || !type_size(w1) || nw < 3) {
        st = vd_error_set(err, VD_ERR_FORMAT, path, line, 10, "bad property '%s'", buf);
        goto done;
      }
      prop* q = &props[nprop++];
      snprintf(q->type, sizeof q->type, "%s", w1);
      q->size = type_size(w1);
      q->is_float = strstr(w1, "float") || !strcmp(w1, "double");
      q->is_signed = !q->is_float && w1[0] != 'u';
      const char* roles[] = {"x", "y", "z", "label", "instance"};
      q->role = -1;
      for (int k = 0; k < 5; k++)
        if (!strcmp(w2, roles[k])) q->role = k, have[k]++;
    } else {
      st = vd_error_set(err, VD_ERR_FORMAT, path, line, 1, "unexpected header line '%s'", buf);
      goto done;
    }
  }
  if (fmt < 0 || n < 0 || !have[0] || !have[1] || !have[2]) {
    st = vd_error_set(err, VD_ERR_FORMAT, path, line, 1,
                      "PLY header needs a format and a vertex element with x, y, z");
    goto done;
  }
  out->n = (int)n;
  out->xyz = vd_malloc(sizeof(double) * 3 * (size_t)n + 1);
  out->label = have[3] ? vd_malloc(sizeof(int) * (size_t)n + 1) : NULL;
  out->instance = have[4] ? vd_malloc(sizeof(int) * (size_t)n + 1) : NULL;
  if (!out->xyz || (have[3] && !out->label) || (have[4] && !out->instance)) {
    st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
    goto done;
  }
  // the vertices
  size_t stride = 0;
  for (int k = 0; k < nprop; k++)
    stride += (size_t)props[k].size;
  char* p = text + pos;
  for (long long i = 0; i < n; i++) {
    double v[5] = {0};
    if (fmt == 0) {
      for (int k = 0; k < nprop; k++) {
        char* end;
        double x = strtod(p, &end);
        if (end == p) {
          st = vd_error_set(err, VD_ERR_FORMAT, path, line + 1 + (int)i, 0,
                            "vertex %lld: expected %d numbers", i, nprop);
          goto done;
        }
        p = end;
        if (props[k].role >= 0) v[props[k].role] = x;
      }
    } else {
      if ((size_t)(text + len - p) < stride) {
        st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "file ends at vertex %lld of %lld", i, n);
        goto done;
      }
      for (int k = 0, off = 0; k < nprop; off += props[k].size, k++)
        if (props[k].role >= 0)
          v[props[k].role] = get_bin((unsigned char*)p + off, &props[k], fmt == 2);
      p += stride;
    }
    for (int k = 0; k < 3; k++) {
      if (!isfinite(v[k])) {
        st =
            vd_error_set(err, VD_ERR_VALUE, path, 0, 0, "vertex %lld: coordinate is not finite", i);
        goto done;
      }
      out->xyz[3 * i + k] = v[k];
    }
    for (int k = 3; k < 5; k++) {
      int* dst = k == 3 ? out->label : out->instance;
      if (!dst) continue;
      if (!(v[k] >= 0 && v[k] <= 65535) || v[k] != floor(v[k])) {
        st = vd_error_set(err, VD_ERR_VALUE, path, 0, 0,
                          "vertex %lld: %s %g is not an integer in 0..65535", i,
                          k == 3 ? "label" : "instance", v[k]);
        goto done;
      }
      dst[i] = (int)v[k];
    }
  }
  if (names->nlabel) {
    out->labels = vd_malloc(sizeof(vd_label) * (size_t)names->nlabel);
    if (!out->labels) {
      st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
      goto done;
    }
    memcpy(out->labels, names->label, sizeof(vd_label) * (size_t)names->nlabel);
    out->nlabel = names->nlabel;
  }
done:
  vd_plant_spec_destroy(names);
  vd_free(text, len + 1);
  if (st) cli_ply_cloud_free(out);
  return st;
}
