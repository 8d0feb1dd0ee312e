// SPDX-License-Identifier: MIT
// Mesh readers: the OBJ and PLY meshes that vd_geom_write_obj / _ply make (label table in the
// header comments, a label and an instance per face), and triangle meshes from other tools (OBJ
// groups or materials as labels and objects as instances; PLY faces with or without label and
// instance properties). Polygons are cut into fans. Every fault names the file and the line
// (text) or the byte offset (binary PLY); counts are checked against the file's size before
// anything is allocated for them.
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "geom_internal.h"

// most vertices and triangles a mesh file may give (the mesh's int indices, with room)
#define MAX_ELEMS (1 << 28)

// what is read so far
typedef struct mreader {
  const char* path;
  vd_error* err;
  double* v; // positions (nv x 3)
  int nv, cap_v;
  double* vn; // normals of the file (nvn x 3)
  int nvn, cap_vn;
  int* f; // triangles: 3 vertices, 3 normals (-1: none), label, instance (nf x 8)
  int nf, cap_f;
  vd_label* lab; // label table (nlab)
  int nlab, cap_lab;
} mreader;

static vd_status fail(mreader* r, int line, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));
static vd_status fail(mreader* r, int line, const char* fmt, ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return vd_error_set(r->err, VD_ERR_FORMAT, r->path, line, 0, "%s", msg);
}

static vd_status nomem(mreader* r) {
  return vd_error_set(r->err, VD_ERR_NOMEM, r->path, 0, 0, "out of memory");
}

static void mreader_free(mreader* r) {
  vd_free(r->v, sizeof(double) * 3 * (size_t)r->cap_v);
  vd_free(r->vn, sizeof(double) * 3 * (size_t)r->cap_vn);
  vd_free(r->f, sizeof(int) * 8 * (size_t)r->cap_f);
  vd_free(r->lab, sizeof(vd_label) * (size_t)r->cap_lab);
}

static vd_status add_vec(mreader* r, double** a, int* n, int* cap, const double x[3], int line) {
  if (*n >= MAX_ELEMS) return fail(r, line, "more than %d vertices", MAX_ELEMS);
  if (!vd_grow((void**)a, cap, *n + 1, 3 * sizeof(double))) return nomem(r);
  memcpy(*a + 3 * *n, x, 3 * sizeof(double));
  (*n)++;
  return VD_OK;
}

static vd_status add_tri(mreader* r, const int v[3], const int n[3], int label, int inst,
                         int line) {
  if (r->nf >= MAX_ELEMS) return fail(r, line, "more than %d triangles", MAX_ELEMS);
  if (!vd_grow((void**)&r->f, &r->cap_f, r->nf + 1, 8 * sizeof(int))) return nomem(r);
  int* t = r->f + 8 * r->nf++;
  t[0] = v[0], t[1] = v[1], t[2] = v[2], t[3] = n[0], t[4] = n[1], t[5] = n[2];
  t[6] = label, t[7] = inst;
  return VD_OK;
}

// entry of the label table with id, or NULL
static vd_label* label_of(mreader* r, int id) {
  for (int i = 0; i < r->nlab; i++)
    if (r->lab[i].id == id) return &r->lab[i];
  return NULL;
}

// add label id with a name (the first name of an id stays)
static vd_status add_label(mreader* r, int id, const char* name) {
  if (label_of(r, id)) return VD_OK;
  if (!vd_grow((void**)&r->lab, &r->cap_lab, r->nlab + 1, sizeof(vd_label))) return nomem(r);
  vd_label_init(&r->lab[r->nlab++], id, name);
  return VD_OK;
}

// "label ID NAME" of a header comment (text after the comment marker); others are ignored
static vd_status comment_label(mreader* r, const char* s, size_t len, int line) {
  char buf[256];
  if (len >= sizeof buf) len = sizeof buf - 1;
  memcpy(buf, s, len);
  buf[len] = 0;
  char* p = buf;
  while (*p == ' ' || *p == '\t') p++;
  if (strncmp(p, "label ", 6) != 0) return VD_OK;
  char* end;
  errno = 0;
  long id = strtol(p + 6, &end, 10);
  if (errno || end == p + 6 || id < 0 || id > INT32_MAX || (*end != ' ' && *end != 0))
    return fail(r, line, "label comment: expected 'label ID NAME'");
  while (*end == ' ') end++;
  size_t n = strlen(end);
  while (n && (end[n - 1] == '\r' || end[n - 1] == ' ')) end[--n] = 0;
  return add_label(r, (int)id, end);
}

// ---------------------------------------------------------------------------------------------
// lines (vd_text_line) and numbers

// cut a line into blank-separated words in buf; -1 when it is too long or has too many
static int words(const char* ls, size_t ll, char* buf, size_t cap, char** w, int maxw) {
  if (ll >= cap) return -1;
  memcpy(buf, ls, ll);
  buf[ll] = 0;
  int n = 0;
  for (char* p = buf;;) {
    while (*p == ' ' || *p == '\t') p++;
    if (!*p) break;
    if (n == maxw) return -1;
    w[n++] = p;
    while (*p && *p != ' ' && *p != '\t') p++;
    if (*p) *p++ = 0;
  }
  return n;
}

// a finite number, the whole word
static int number(const char* s, double* x) {
  char* end;
  errno = 0;
  *x = strtod(s, &end);
  return end != s && !*end && errno != ERANGE && isfinite(*x);
}

// a whole number within [lo, hi], the whole word
static int whole(const char* s, long lo, long hi, long* x) {
  char* end;
  errno = 0;
  *x = strtol(s, &end, 10);
  return end != s && !*end && !errno && *x >= lo && *x <= hi;
}

// ---------------------------------------------------------------------------------------------
// OBJ

// the label named by a group or material: the table's entry whose OBJ name it is, else a new
// label (the next free id) of that name
static vd_status obj_label(mreader* r, const char* name, int* label) {
  int top = 0;
  char buf[VD_LABEL_NAME_MAX + 16];
  for (int i = 0; i < r->nlab; i++) {
    geom_obj_name(r->lab, r->nlab, r->lab[i].id, buf, sizeof buf);
    if (!strcmp(buf, name)) {
      *label = r->lab[i].id;
      return VD_OK;
    }
    if (r->lab[i].id >= top) top = r->lab[i].id + 1;
  }
  if (top == 0) top = 1; // a foreign file's groups are labels 1, 2, ...
  *label = top;
  return add_label(r, top, name);
}

// the instance of an object "<label name>_<instance>" (as written), else numbered in order of
// appearance; *label is set when the name gives it
typedef struct objnames {
  char (*name)[64]; // object names seen (n)
  int n, cap;
} objnames;

static vd_status obj_instance(mreader* r, objnames* on, const char* name, int* label, int* inst) {
  char buf[VD_LABEL_NAME_MAX + 16];
  for (int i = 0; i < r->nlab; i++) {
    geom_obj_name(r->lab, r->nlab, r->lab[i].id, buf, sizeof buf);
    size_t n = strlen(buf);
    long x;
    if (!strncmp(name, buf, n) && name[n] == '_' && whole(name + n + 1, 0, 65535, &x)) {
      *label = r->lab[i].id;
      *inst = (int)x;
      return VD_OK;
    }
  }
  for (int i = 0; i < on->n; i++)
    if (!strncmp(on->name[i], name, 63)) {
      *inst = i + 1;
      return VD_OK;
    }
  if (!vd_grow((void**)&on->name, &on->cap, on->n + 1, sizeof on->name[0])) return nomem(r);
  snprintf(on->name[on->n], sizeof on->name[0], "%s", name);
  *inst = ++on->n;
  return VD_OK;
}

// a face corner "v", "v/t", "v//n" or "v/t/n" (1-based, or negative from the end)
static int obj_corner(const char* s, int nv, int nvn, int* v, int* n) {
  char* end;
  errno = 0;
  long i = strtol(s, &end, 10);
  if (end == s || errno || i == 0 || i > nv || i < -(long)nv) return 0;
  *v = i > 0 ? (int)i - 1 : nv + (int)i;
  *n = -1;
  if (*end != '/') return *end == 0;
  const char* t = end + 1;
  if (*t != '/') { // texture index, not used
    long tex = strtol(t, &end, 10);
    if (end == t || tex == 0) return 0;
    t = end;
    if (*t != '/') return *t == 0;
  }
  t++;
  errno = 0;
  long k = strtol(t, &end, 10);
  if (end == t || *end || errno || k == 0 || k > nvn || k < -(long)nvn) return 0;
  *n = k > 0 ? (int)k - 1 : nvn + (int)k;
  return 1;
}

static vd_status read_obj(mreader* r, const char* s, size_t len) {
  vd_text t = {s, len, 0, 0};
  const char* ls;
  size_t ll;
  char buf[4096];
  char* w[256];
  int label = 0, inst = 0;
  objnames on = {NULL, 0, 0};
  vd_status st = VD_OK;
  while (!st && vd_text_line(&t, &ls, &ll)) {
    if (ll > 0 && ls[0] == '#') {
      if (ll > 1) st = comment_label(r, ls + 1, ll - 1, t.line);
      continue;
    }
    int n = words(ls, ll, buf, sizeof buf, w, 256);
    if (n < 0) {
      st = fail(r, t.line, "line too long (4096 characters or 256 words at most)");
      break;
    }
    if (n == 0) continue;
    if (!strcmp(w[0], "v") || !strcmp(w[0], "vn")) {
      double x[3];
      if (n < 4 || !number(w[1], &x[0]) || !number(w[2], &x[1]) || !number(w[3], &x[2])) {
        st = fail(r, t.line, "expected '%s X Y Z' with finite numbers", w[0]);
        break;
      }
      st = w[0][1] ? add_vec(r, &r->vn, &r->nvn, &r->cap_vn, x, t.line)
                   : add_vec(r, &r->v, &r->nv, &r->cap_v, x, t.line);
    } else if (!strcmp(w[0], "f")) {
      if (n < 4) {
        st = fail(r, t.line, "a face needs 3 vertices or more");
        break;
      }
      int v[3], nn[3];
      for (int k = 1; k < n && !st; k++) {
        int slot = k < 3 ? k - 1 : 2;
        if (!obj_corner(w[k], r->nv, r->nvn, &v[slot], &nn[slot])) {
          st = fail(r, t.line, "face corner %d '%s': expected V, V/T, V//N or V/T/N with V in "
                               "1..%d and N in 1..%d (or negative)", k, w[k], r->nv, r->nvn);
          break;
        }
        if (k < 3) continue;
        st = add_tri(r, v, nn, label, inst, t.line);
        // the fan: the first corner stays, the last becomes the second
        v[1] = v[2], nn[1] = nn[2];
      }
    } else if (!strcmp(w[0], "g") || !strcmp(w[0], "usemtl")) {
      if (n >= 2) st = obj_label(r, w[1], &label);
    } else if (!strcmp(w[0], "o")) {
      if (n >= 2) st = obj_instance(r, &on, w[1], &label, &inst);
    }
    // vt, s, mtllib, l, p and the rest do not change the triangles
  }
  vd_free(on.name, sizeof on.name[0] * (size_t)on.cap);
  if (!st && r->nf == 0) st = fail(r, 0, "no faces ('f' lines): not a triangle mesh");
  return st;
}

// ---------------------------------------------------------------------------------------------
// PLY

// what a property of the vertex or face element feeds
enum { P_NONE, P_X, P_Y, P_Z, P_NX, P_NY, P_NZ, P_INDICES, P_LABEL, P_INSTANCE };

#define PLY_MAX_ELEM 16
#define PLY_MAX_PROP 32
typedef struct pelem {
  char name[32];
  long count;
  int nprop;
  vd_scalar type[PLY_MAX_PROP];  // scalar type, or the item type of a list
  vd_scalar count_type[PLY_MAX_PROP]; // VD_SCALAR_BAD for scalars
  int feed[PLY_MAX_PROP];    // P_*
} pelem;

// what a property name feeds in the vertex or face element
static int ply_feed(const char* elem, const char* name, int list) {
  static const char* vert[] = {"x", "y", "z", "nx", "ny", "nz"};
  if (!strcmp(elem, "vertex") && !list)
    for (int k = 0; k < 6; k++)
      if (!strcmp(name, vert[k])) return P_X + k;
  if (!strcmp(elem, "face")) {
    if (list && (!strcmp(name, "vertex_indices") || !strcmp(name, "vertex_index")))
      return P_INDICES;
    if (!list && !strcmp(name, "label")) return P_LABEL;
    if (!list && !strcmp(name, "instance")) return P_INSTANCE;
  }
  return P_NONE;
}

// a value source: the ASCII words of the body, or the binary bytes
typedef struct pbody {
  int binary;
  vd_text t;            // ASCII: the lines after end_header
  char buf[8192];       // ASCII: the current line's words
  char* w[1024];
  int nw, iw;
  const unsigned char* b; // binary: the body
  size_t nb, ib;
} pbody;

// next value of type ty; 0 with an error set at the end of the data or on a bad number
static int ply_next(mreader* r, pbody* pb, vd_scalar ty, double* x, vd_status* st) {
  if (pb->binary) {
    size_t k = (size_t)vd_scalar_size(ty);
    if (pb->nb - pb->ib < k) {
      *st = fail(r, 0, "the binary data end at byte %zu (of the body) inside a record", pb->ib);
      return 0;
    }
    *x = vd_scalar_get_le(pb->b + pb->ib, ty);
    pb->ib += k;
    if (!isfinite(*x)) {
      *st = fail(r, 0, "value at byte %zu of the body is not finite", pb->ib - k);
      return 0;
    }
    return 1;
  }
  while (pb->iw == pb->nw) {
    const char* ls;
    size_t ll;
    if (!vd_text_line(&pb->t, &ls, &ll)) {
      *st = fail(r, pb->t.line, "the file ends before every element was read");
      return 0;
    }
    pb->nw = words(ls, ll, pb->buf, sizeof pb->buf, pb->w, 1024);
    pb->iw = 0;
    if (pb->nw < 0) {
      *st = fail(r, pb->t.line, "line too long");
      return 0;
    }
  }
  if (!number(pb->w[pb->iw++], x)) {
    *st = fail(r, pb->t.line, "'%s' is not a finite number", pb->w[pb->iw - 1]);
    return 0;
  }
  return 1;
}

static vd_status read_ply(mreader* r, const char* s, size_t len) {
  vd_text t = {s, len, 0, 0};
  const char* ls;
  size_t ll;
  char buf[512];
  char* w[8];
  if (!vd_text_line(&t, &ls, &ll) || ll != 3 || memcmp(ls, "ply", 3) != 0)
    return fail(r, 1, "not a PLY file (expected 'ply')");
  int binary = -1, nelem = 0, ivert = -1, iface = -1;
  pelem* el = vd_calloc(PLY_MAX_ELEM, sizeof(pelem));
  if (!el) return nomem(r);
  vd_status st = VD_OK;
  for (;;) {
    if (!vd_text_line(&t, &ls, &ll)) {
      st = fail(r, t.line, "no end_header");
      break;
    }
    if (ll >= 7 && !memcmp(ls, "comment", 7)) {
      if ((st = comment_label(r, ls + 7, ll - 7, t.line))) break;
      continue;
    }
    if (ll >= 8 && !memcmp(ls, "obj_info", 8)) continue;
    int n = words(ls, ll, buf, sizeof buf, w, 8);
    if (n < 1) {
      st = fail(r, t.line, n < 0 ? "header line too long" : "empty header line");
      break;
    }
    if (!strcmp(w[0], "end_header")) break;
    if (!strcmp(w[0], "format")) {
      if (n != 3 || strcmp(w[2], "1.0") != 0) {
        st = fail(r, t.line, "expected 'format TYPE 1.0'");
        break;
      }
      if (!strcmp(w[1], "ascii")) {
        binary = 0;
      } else if (!strcmp(w[1], "binary_little_endian")) {
        binary = 1;
      } else {
        st = vd_error_set(r->err, VD_ERR_UNSUPPORTED, r->path, t.line, 0,
                          "PLY format '%s' is not supported (ascii, binary_little_endian)", w[1]);
        break;
      }
    } else if (!strcmp(w[0], "element")) {
      long c;
      if (n != 3 || !whole(w[2], 0, MAX_ELEMS, &c)) {
        st = fail(r, t.line, "expected 'element NAME COUNT' with COUNT in 0..%d", MAX_ELEMS);
        break;
      }
      if (nelem == PLY_MAX_ELEM) {
        st = fail(r, t.line, "more than %d elements", PLY_MAX_ELEM);
        break;
      }
      pelem* e = &el[nelem++];
      snprintf(e->name, sizeof e->name, "%s", w[1]);
      e->count = c;
      if (!strcmp(w[1], "vertex") && ivert < 0) ivert = nelem - 1;
      if (!strcmp(w[1], "face") && iface < 0) iface = nelem - 1;
    } else if (!strcmp(w[0], "property")) {
      if (!nelem) {
        st = fail(r, t.line, "property before any element");
        break;
      }
      pelem* e = &el[nelem - 1];
      int list = n >= 2 && !strcmp(w[1], "list");
      if ((list && n != 5) || (!list && n != 3)) {
        st = fail(r, t.line, "expected 'property TYPE NAME' or 'property list COUNT ITEM NAME'");
        break;
      }
      vd_scalar ct = list ? vd_scalar_ply(w[2]) : VD_SCALAR_BAD, it = vd_scalar_ply(w[list ? 3 : 1]);
      if (it == VD_SCALAR_BAD || (list && (ct == VD_SCALAR_BAD || ct == VD_SCALAR_F32 || ct == VD_SCALAR_F64))) {
        st = fail(r, t.line, "unknown property type");
        break;
      }
      if (e->nprop == PLY_MAX_PROP) {
        st = fail(r, t.line, "more than %d properties", PLY_MAX_PROP);
        break;
      }
      e->type[e->nprop] = it;
      e->count_type[e->nprop] = list ? ct : VD_SCALAR_BAD;
      e->feed[e->nprop] = ply_feed(e->name, w[list ? 4 : 2], list);
      e->nprop++;
    } else {
      st = fail(r, t.line, "unknown header line '%s'", w[0]);
      break;
    }
  }
  if (!st && binary < 0) st = fail(r, t.line, "no format line");
  if (!st && (ivert < 0 || iface < 0 || el[iface].count == 0))
    st = fail(r, t.line, "no face element: a point cloud, not a mesh");
  // the vertex element needs x, y, z; the face element its indices
  int has[P_INSTANCE + 1] = {0};
  for (int e = 0; !st && e < nelem; e++)
    for (int k = 0; k < el[e].nprop; k++)
      if ((e == ivert || e == iface) && has[el[e].feed[k]]++ && el[e].feed[k] != P_NONE)
        st = fail(r, t.line, "element '%s' names a property twice", el[e].name);
  if (!st && (!has[P_X] || !has[P_Y] || !has[P_Z]))
    st = fail(r, t.line, "the vertex element lacks x, y or z");
  if (!st && !has[P_INDICES]) st = fail(r, t.line, "the face element lacks vertex_indices");
  // a binary file holds at least a byte per scalar of its counted elements
  if (!st && binary) {
    size_t need = 0;
    for (int e = 0; e < nelem; e++)
      need += (size_t)el[e].count * (size_t)el[e].nprop;
    if (need > len - t.pos) st = fail(r, t.line, "the element counts do not fit in the file");
  }
  pbody* pb = NULL;
  if (!st) {
    pb = vd_calloc(1, sizeof(pbody));
    if (pb) {
      pb->binary = binary;
      pb->t = (vd_text){s + t.pos, len - t.pos, 0, t.line};
      pb->b = (const unsigned char*)s + t.pos, pb->nb = len - t.pos;
    } else {
      st = nomem(r);
    }
  }
  int nv_file = ivert >= 0 && !st ? (int)el[ivert].count : 0;
  for (int e = 0; !st && e < nelem; e++) {
    pelem* E = &el[e];
    for (long i = 0; !st && i < E->count; i++) {
      double pos[3] = {0, 0, 0}, nrm[3] = {0, 0, 0}, x;
      int label = 0, inst = 0, has_n = 0, f0 = r->nf;
      for (int k = 0; !st && k < E->nprop; k++) {
        int feed = E->feed[k];
        if (E->count_type[k] == VD_SCALAR_BAD) { // a scalar
          if (!ply_next(r, pb, E->type[k], &x, &st)) break;
          if (feed >= P_X && feed <= P_Z) pos[feed - P_X] = x;
          if (feed >= P_NX && feed <= P_NZ) nrm[feed - P_NX] = x, has_n = 1;
          if ((feed == P_LABEL || feed == P_INSTANCE) &&
              (x != floor(x) || x < 0 || x > (feed == P_LABEL ? 65534 : 65535))) {
            st = fail(r, binary ? 0 : pb->t.line, "face %ld: %s %g is not a whole number in 0..%d",
                      i, feed == P_LABEL ? "label" : "instance", x,
                      feed == P_LABEL ? 65534 : 65535);
            break;
          }
          if (feed == P_LABEL) label = (int)x;
          if (feed == P_INSTANCE) inst = (int)x;
          continue;
        }
        // a list: its count, then its items (the face's vertex indices: a fan)
        double c;
        if (!ply_next(r, pb, E->count_type[k], &c, &st)) break;
        if (c < 0 || c > 1024 || c != floor(c)) {
          st = fail(r, binary ? 0 : pb->t.line, "%s %ld: list of %g items", E->name, i, c);
          break;
        }
        if (feed == P_INDICES && c < 3) {
          st = fail(r, binary ? 0 : pb->t.line, "face %ld has %g vertices (3 or more)", i, c);
          break;
        }
        int v[3] = {0, 0, 0};
        for (int j = 0; j < (int)c && !st; j++) {
          if (!ply_next(r, pb, E->type[k], &x, &st)) break;
          if (feed != P_INDICES) continue;
          if (x != floor(x) || x < 0 || x >= nv_file) {
            st = fail(r, binary ? 0 : pb->t.line, "face %ld: vertex index %g not in 0..%d", i, x,
                      nv_file - 1);
            break;
          }
          v[j < 2 ? j : 2] = (int)x;
          if (j < 2) continue;
          // the fan's triangles (labelled once the whole record is read)
          int none[3] = {-1, -1, -1};
          st = add_tri(r, v, none, 0, 0, binary ? 0 : pb->t.line);
          v[1] = v[2];
        }
      }
      if (st) break;
      if (e == ivert) {
        st = add_vec(r, &r->v, &r->nv, &r->cap_v, pos, binary ? 0 : pb->t.line);
        if (!st && has_n) st = add_vec(r, &r->vn, &r->nvn, &r->cap_vn, nrm, 0);
      }
      for (int k = f0; e == iface && k < r->nf; k++)
        r->f[8 * k + 6] = label, r->f[8 * k + 7] = inst;
    }
  }
  // vertex normals from the file: every corner uses its vertex's
  for (int k = 0; !st && k < r->nf; k++)
    for (int c = 0; c < 3; c++)
      r->f[8 * k + 3 + c] = r->nvn == r->nv ? r->f[8 * k + c] : -1;
  if (pb) vd_free(pb, sizeof(pbody));
  vd_free(el, PLY_MAX_ELEM * sizeof(pelem));
  return st;
}

// ---------------------------------------------------------------------------------------------
// the mesh

// build the vd_mesh: shared vertices when every corner's normal is its vertex's (or none is
// given; normals then from the faces around each vertex), else three vertices per triangle
static vd_status build(mreader* r, vd_mesh* mesh) {
  int shared = 1;
  for (int k = 0; k < r->nf && shared; k++)
    for (int c = 0; c < 3; c++) {
      int n = r->f[8 * k + 3 + c];
      if (n >= 0 && n != r->f[8 * k + c]) shared = 0;
      if (n >= 0 && r->nvn <= r->f[8 * k + c]) shared = 0;
    }
  size_t nt = (size_t)r->nf, nv = shared ? (size_t)r->nv : 3 * nt;
  if (!geom_mesh_alloc(mesh, (int)nv, (int)nt)) return nomem(r);
  if (shared) memcpy(mesh->pos, r->v, sizeof(double) * 3 * nv);
  for (size_t k = 0; k < nt; k++) {
    const int* f = r->f + 8 * k;
    vd_vec3 p[3];
    for (int c = 0; c < 3; c++)
      p[c] = vd_v3(r->v[3 * f[c]], r->v[3 * f[c] + 1], r->v[3 * f[c] + 2]);
    // the face's normal weighted by its area, for vertices without one of their own
    vd_vec3 fn = vd_cross(vd_sub(p[1], p[0]), vd_sub(p[2], p[0]));
    for (int c = 0; c < 3; c++) {
      int vi = shared ? f[c] : (int)(3 * k) + c;
      mesh->tri[3 * k + c] = vi;
      if (!shared) memcpy(mesh->pos + 3 * vi, r->v + 3 * f[c], sizeof(double) * 3);
      vd_vec3 n = f[3 + c] >= 0 ? vd_v3(r->vn[3 * f[3 + c]], r->vn[3 * f[3 + c] + 1],
                                        r->vn[3 * f[3 + c] + 2])
                                : fn;
      // shared: file normals are set once, face normals add up
      if (shared && f[3 + c] >= 0) {
        mesh->normal[3 * vi] = n.x, mesh->normal[3 * vi + 1] = n.y, mesh->normal[3 * vi + 2] = n.z;
      } else {
        mesh->normal[3 * vi] += n.x, mesh->normal[3 * vi + 1] += n.y;
        mesh->normal[3 * vi + 2] += n.z;
      }
    }
    mesh->tri_label[k] = f[6];
    mesh->tri_instance[k] = f[7];
    mesh->tri_prim[k] = 0;
    mesh->tri_kind[k] = VD_PRIM_MESH;
  }
  for (size_t i = 0; i < nv; i++) {
    vd_vec3 n = vd_v3(mesh->normal[3 * i], mesh->normal[3 * i + 1], mesh->normal[3 * i + 2]);
    double l = vd_norm(n);
    n = l > 0 && isfinite(l) ? vd_scale(n, 1 / l) : vd_v3(0, 0, 0);
    mesh->normal[3 * i] = n.x, mesh->normal[3 * i + 1] = n.y, mesh->normal[3 * i + 2] = n.z;
  }
  return VD_OK;
}

// label table order
static int cmp_label(const void* a, const void* b) {
  const vd_label *x = a, *y = b;
  return (x->id > y->id) - (x->id < y->id);
}

vd_status vd_geom_parse_mesh(const char* data, size_t len, int obj, const char* name,
                             vd_mesh* mesh, vd_label** labels, int* nlabel, vd_error* err) {
  memset(mesh, 0, sizeof *mesh);
  if (labels) *labels = NULL;
  if (nlabel) *nlabel = 0;
  mreader r;
  memset(&r, 0, sizeof r);
  r.path = name ? name : "";
  r.err = err;
  vd_status st = obj ? read_obj(&r, data, len) : read_ply(&r, data, len);
  if (!st) st = build(&r, mesh);
  if (!st && labels && nlabel) {
    // the table, sorted by id, exactly as long as it is
    if (r.nlab) qsort(r.lab, (size_t)r.nlab, sizeof(vd_label), cmp_label);
    *labels = vd_malloc(sizeof(vd_label) * (size_t)(r.nlab ? r.nlab : 1));
    if (!*labels) {
      vd_mesh_free(mesh);
      st = nomem(&r);
    } else {
      if (r.nlab) memcpy(*labels, r.lab, sizeof(vd_label) * (size_t)r.nlab);
      *nlabel = r.nlab;
    }
  }
  mreader_free(&r);
  return st;
}

vd_status vd_geom_read_mesh(const char* path, vd_mesh* mesh, vd_label** labels, int* nlabel,
                            vd_error* err) {
  memset(mesh, 0, sizeof *mesh);
  if (labels) *labels = NULL;
  if (nlabel) *nlabel = 0;
  size_t n = strlen(path);
  int obj = n >= 4 && (!strcmp(path + n - 4, ".obj") || !strcmp(path + n - 4, ".OBJ"));
  int ply = n >= 4 && (!strcmp(path + n - 4, ".ply") || !strcmp(path + n - 4, ".PLY"));
  if (!obj && !ply)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "a mesh is read from .obj or .ply");
  char* data;
  size_t len;
  vd_status st = vd_file_read(path, &data, &len, err);
  if (st) return st;
  st = vd_geom_parse_mesh(data, len, obj, path, mesh, labels, nlabel, err);
  vd_free(data, len + 1);
  return st;
}

int vd_geom_is_mesh_file(const char* path) {
  size_t n = strlen(path);
  if (n < 4) return 0;
  const char* ext = path + n - 4;
  if (!strcmp(ext, ".obj") || !strcmp(ext, ".OBJ")) return 1;
  if (strcmp(ext, ".ply") != 0 && strcmp(ext, ".PLY") != 0) return 0;
  // a PLY with a face element of at least one face, read from its header
  FILE* f = fopen(path, "rb");
  if (!f) return 0;
  char line[512];
  int mesh = 0;
  for (int k = 0; k < 10000 && fgets(line, sizeof line, f); k++) {
    if (!strncmp(line, "end_header", 10)) break;
    char* end;
    if (!strncmp(line, "element face ", 13) && strtol(line + 13, &end, 10) > 0 && end != line + 13)
      mesh = 1;
  }
  fclose(f);
  return mesh;
}
