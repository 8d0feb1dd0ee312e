// SPDX-License-Identifier: MIT
// Mesh writers: OBJ with a sibling MTL (faces sorted and grouped by label and instance so every
// viewer shows the labels) and PLY (binary little-endian or ASCII) with per-face label and
// instance. Both are written atomically.
#include <stdlib.h>
#include <string.h>

#include "geom_internal.h"

// ---------------------------------------------------------------------------------------------
// label names as they appear in files

// table entry for id, or NULL (the table need not be sorted)
static const vd_label* find_label(const vd_label* labels, int nlabel, int id) {
  for (int i = 0; i < nlabel; i++)
    if (labels[i].id == id) return &labels[i];
  return NULL;
}

// an OBJ/MTL-safe form of a name: letters, digits, '_', '-', '.' kept, others become '_'
static void sanitize(const char* name, char* buf, size_t cap) {
  size_t n = 0;
  for (const char* c = name; *c && n + 1 < cap; c++, n++) {
    int ok = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
             *c == '_' || *c == '-' || *c == '.';
    buf[n] = (char)(ok ? *c : '_');
  }
  buf[n] = 0;
}

// the name of label id in OBJ/MTL files: its sanitised name; "label_<id>" when it has no entry
// or an empty name; "<name>_<id>" when an earlier entry sanitises to the same name
void geom_obj_name(const vd_label* labels, int nlabel, int id, char* buf, size_t cap) {
  const vd_label* l = find_label(labels, nlabel, id);
  if (!l || !l->name[0]) {
    snprintf(buf, cap, "label_%d", id);
    return;
  }
  char mine[VD_LABEL_NAME_MAX], other[VD_LABEL_NAME_MAX];
  sanitize(l->name, mine, sizeof mine);
  for (const vd_label* o = labels; o < l; o++) {
    sanitize(o->name, other, sizeof other);
    if (o->id != id && strcmp(other, mine) == 0) {
      snprintf(buf, cap, "%s_%d", mine, id);
      return;
    }
  }
  snprintf(buf, cap, "%s", mine);
}

// the label name on one line (for header comments): control characters become spaces
static void comment_name(const char* name, char* buf, size_t cap) {
  size_t n = 0;
  for (const char* c = name; *c && n + 1 < cap; c++, n++)
    buf[n] = (char)((unsigned char)*c < 0x20 ? ' ' : *c);
  buf[n] = 0;
}

static vd_status check_mesh(const vd_mesh* mesh, const char* path, vd_error* err) {
  if (!mesh || !path) return vd_error_set(err, VD_ERR_ARG, path ? path : "", 0, 0, "null argument");
  if (mesh->nvert < 0 || mesh->ntri < 0 || (mesh->nvert > 0 && !mesh->pos) ||
      (mesh->ntri > 0 && (!mesh->tri || !mesh->tri_label || !mesh->tri_instance)))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "mesh arrays missing");
  for (int k = 0; k < 3 * mesh->ntri; k++)
    if (mesh->tri[k] < 0 || mesh->tri[k] >= mesh->nvert)
      return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "triangle %d: vertex out of range", k / 3);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// OBJ + MTL

typedef struct face_key {
  int label, instance, index;
} face_key;

static int cmp_face(const void* a, const void* b) {
  const face_key *x = a, *y = b;
  if (x->label != y->label) return x->label < y->label ? -1 : 1;
  if (x->instance != y->instance) return x->instance < y->instance ? -1 : 1;
  return (x->index > y->index) - (x->index < y->index);
}

// path of the material library: the OBJ path with .obj replaced (or .mtl appended)
static void mtl_path(const char* path, char* buf, size_t cap) {
  size_t n = strlen(path);
  const char* ext = n >= 4 ? path + n - 4 : "";
  int is_obj =
      ext[0] == '.' && (ext[1] | 32) == 'o' && (ext[2] | 32) == 'b' && (ext[3] | 32) == 'j';
  snprintf(buf, cap, "%.*s.mtl", (int)(is_obj ? n - 4 : n), path);
}

static void write_obj_header(FILE* fp, const vd_mesh* mesh, const vd_label* labels, int nlabel,
                             const char* mtl_name) {
  fprintf(fp, "# verdant mesh, format version %d\n", VD_MESH_FORMAT_VERSION);
  fprintf(fp, "# vertices %d, triangles %d, units m\n", mesh->nvert, mesh->ntri);
  for (int i = 0; i < nlabel; i++) {
    char name[VD_LABEL_NAME_MAX];
    comment_name(labels[i].name, name, sizeof name);
    fprintf(fp, "# label %d %s\n", labels[i].id, name);
  }
  fprintf(fp, "mtllib %s\n", mtl_name);
}

static void write_mtl_entry(FILE* fp, const vd_label* labels, int nlabel, int id) {
  char name[VD_LABEL_NAME_MAX + 16];
  geom_obj_name(labels, nlabel, id, name, sizeof name);
  const vd_label* l = find_label(labels, nlabel, id);
  float rgb[3];
  if (l)
    memcpy(rgb, l->rgb, sizeof rgb);
  else
    vd_plant_default_rgb(id, rgb);
  fprintf(fp, "newmtl %s\nKa 0 0 0\nKd %.6g %.6g %.6g\nKs 0 0 0\nd 1\nillum 1\n\n", name,
          (double)rgb[0], (double)rgb[1], (double)rgb[2]);
}

vd_status vd_geom_write_obj(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                            const char* path, vd_error* err) {
  vd_status st = check_mesh(mesh, path, err);
  if (st) return st;
  if (nlabel < 0 || (nlabel > 0 && !labels)) nlabel = 0;
  // faces sorted by (label, instance), stable by index
  face_key* keys = NULL;
  size_t nkey = (size_t)mesh->ntri;
  if (nkey > 0) {
    keys = vd_malloc(nkey * sizeof *keys);
    if (!keys) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory writing OBJ");
    for (size_t t = 0; t < nkey; t++)
      keys[t] = (face_key){mesh->tri_label[t], mesh->tri_instance[t], (int)t};
    qsort(keys, nkey, sizeof *keys, cmp_face);
  }
  // both files under temporary names
  char mpath[4200];
  mtl_path(path, mpath, sizeof mpath);
  const char* slash = strrchr(mpath, '/');
  const char* mname = slash ? slash + 1 : mpath;
  vd_outfile fo, fm;
  st = vd_outfile_open(&fm, mpath, err);
  if (!st) {
    st = vd_outfile_open(&fo, path, err);
    if (st) vd_outfile_abort(&fm);
  }
  if (st) {
    vd_free(keys, nkey * sizeof *keys);
    return st;
  }
  // materials: one per label used, in label order
  fprintf(fm.fp, "# verdant mesh materials, format version %d\n\n", VD_MESH_FORMAT_VERSION);
  for (size_t t = 0; t < nkey; t++)
    if (t == 0 || keys[t].label != keys[t - 1].label)
      write_mtl_entry(fm.fp, labels, nlabel, keys[t].label);
  // vertices and normals
  FILE* fp = fo.fp;
  write_obj_header(fp, mesh, labels, nlabel, mname);
  for (int v = 0; v < mesh->nvert; v++)
    fprintf(fp, "v %.9g %.9g %.9g\n", mesh->pos[3 * v], mesh->pos[3 * v + 1], mesh->pos[3 * v + 2]);
  if (mesh->normal)
    for (int v = 0; v < mesh->nvert; v++)
      fprintf(fp, "vn %.7g %.7g %.7g\n", mesh->normal[3 * v], mesh->normal[3 * v + 1],
              mesh->normal[3 * v + 2]);
  // faces: a new object, group and material at each change of (label, instance)
  char name[VD_LABEL_NAME_MAX + 16];
  for (size_t t = 0; t < nkey; t++) {
    const face_key* k = &keys[t];
    if (t == 0 || k->label != keys[t - 1].label || k->instance != keys[t - 1].instance) {
      geom_obj_name(labels, nlabel, k->label, name, sizeof name);
      fprintf(fp, "o %s_%d\ng %s\nusemtl %s\n", name, k->instance, name, name);
    }
    const int* f = mesh->tri + 3 * k->index;
    if (mesh->normal)
      fprintf(fp, "f %d//%d %d//%d %d//%d\n", f[0] + 1, f[0] + 1, f[1] + 1, f[1] + 1, f[2] + 1,
              f[2] + 1);
    else
      fprintf(fp, "f %d %d %d\n", f[0] + 1, f[1] + 1, f[2] + 1);
  }
  vd_free(keys, nkey * sizeof *keys);
  // the material library first, so the OBJ never names a missing one
  st = vd_outfile_commit(&fm, err);
  if (!st) st = vd_outfile_commit(&fo, err);
  vd_outfile_abort(&fm);
  vd_outfile_abort(&fo);
  return st;
}

// ---------------------------------------------------------------------------------------------
// PLY

static void put_u32le(unsigned char* p, uint32_t u) {
  p[0] = (unsigned char)u, p[1] = (unsigned char)(u >> 8);
  p[2] = (unsigned char)(u >> 16), p[3] = (unsigned char)(u >> 24);
}
static void put_f32le(unsigned char* p, double v) {
  float f = (float)v;
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  put_u32le(p, u);
}

vd_status vd_geom_write_ply(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                            const char* path, int binary, vd_error* err) {
  return vd_geom_write_ply_values(mesh, labels, nlabel, NULL, NULL, path, binary, err);
}

vd_status vd_geom_write_ply_values(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                                   const double* value, const char* value_name, const char* path, int binary,
                                   vd_error* err) {
  vd_status st = check_mesh(mesh, path, err);
  if (st) return st;
  if (nlabel < 0 || (nlabel > 0 && !labels)) nlabel = 0;
  vd_outfile f;
  st = vd_outfile_open(&f, path, err);
  if (st) return st;
  FILE* fp = f.fp;
  // header: format, version and label table as comments, then the two elements
  fprintf(fp, "ply\nformat %s 1.0\n", binary ? "binary_little_endian" : "ascii");
  fprintf(fp, "comment verdant mesh, format version %d, units m\n", VD_MESH_FORMAT_VERSION);
  for (int i = 0; i < nlabel; i++) {
    char name[VD_LABEL_NAME_MAX];
    comment_name(labels[i].name, name, sizeof name);
    fprintf(fp, "comment label %d %s\n", labels[i].id, name);
  }
  fprintf(fp,
          "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
          "property float nx\nproperty float ny\nproperty float nz\n",
          mesh->nvert);
  // a per-vertex value (a simulation's stress): one more float property, NaN where none
  if (value) fprintf(fp, "property float %s\n", value_name && *value_name ? value_name : "value");
  fprintf(fp,
          "element face %d\nproperty list uchar int vertex_indices\nproperty int label\n"
          "property int instance\nend_header\n",
          mesh->ntri);
  // vertices: position and normal (zero normal when the mesh has none)
  for (int v = 0; v < mesh->nvert; v++) {
    double val[6] = {mesh->pos[3 * v], mesh->pos[3 * v + 1], mesh->pos[3 * v + 2], 0, 0, 0};
    if (mesh->normal) memcpy(val + 3, mesh->normal + 3 * v, 3 * sizeof(double));
    if (binary) {
      unsigned char rec[28];
      for (int k = 0; k < 6; k++)
        put_f32le(rec + 4 * k, val[k]);
      if (value) put_f32le(rec + 24, value[v]);
      fwrite(rec, 1, value ? 28 : 24, fp);
    } else {
      fprintf(fp, "%.9g %.9g %.9g %.7g %.7g %.7g", val[0], val[1], val[2], val[3], val[4], val[5]);
      if (value) fprintf(fp, " %.7g", value[v]);
      fputc('\n', fp);
    }
  }
  // faces: count, three indices, label, instance
  for (int t = 0; t < mesh->ntri; t++) {
    const int* tri = mesh->tri + 3 * t;
    if (binary) {
      unsigned char rec[21];
      rec[0] = 3;
      for (int k = 0; k < 3; k++)
        put_u32le(rec + 1 + 4 * k, (uint32_t)tri[k]);
      put_u32le(rec + 13, (uint32_t)mesh->tri_label[t]);
      put_u32le(rec + 17, (uint32_t)mesh->tri_instance[t]);
      fwrite(rec, 1, sizeof rec, fp);
    } else {
      fprintf(fp, "3 %d %d %d %d %d\n", tri[0], tri[1], tri[2], mesh->tri_label[t],
              mesh->tri_instance[t]);
    }
  }
  st = vd_outfile_commit(&f, err);
  vd_outfile_abort(&f);
  return st;
}
