// SPDX-License-Identifier: MIT
// A plant for robot simulators: URDF, SDF and MuJoCo MJCF. Every organ instance is one link
// (URDF, SDF) or body (MJCF) named "<label name>_<instance>", with a visual and a collision shape
// per primitive: a cylinder (URDF, SDF) or capsule (MJCF) per segment of its mean radius, a
// sphere per sphere, a mesh per spec mesh; open meshes (leaves) are given a thickness, since
// collision engines want volumes (and MuJoCo 2.2.2 refuses flat meshes). URDF and SDF take
// meshes from OBJ files in a folder beside the file; MJCF holds them inline. The plant is
// static: URDF links hang on fixed joints (each organ on the organ its root primitive hangs
// from), SDF models are <static>, MJCF bodies have no joints. Conventions in docs/formats.md.
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "geom_internal.h"

vd_export_def vd_export_def_default(void) {
  vd_export_def d;
  memset(&d, 0, sizeof d);
  d.format = VD_EXPORT_MJCF;
  d.name = "plant";
  d.pos = vd_v3(0, 0, 0);
  d.leaf_thickness = 2e-4;
  return d;
}

const char* vd_export_format_name(vd_export_format f) {
  return f == VD_EXPORT_URDF ? "urdf" : f == VD_EXPORT_SDF ? "sdf" : "mjcf";
}

// ---------------------------------------------------------------------------------------------
// organs: the (label, instance) groups and the tree they form

typedef struct organ {
  int label, instance;
  int parent; // organ its root primitive hangs from, -1: the plant's base
  int depth;  // depth of its root primitive
  char name[VD_LABEL_NAME_MAX + 24];
  int nmesh;  // mesh primitives so far (naming)
} organ;

typedef struct plan {
  const vd_model* m;
  const double* node;   // node positions of the state (nnode x 3)
  const double* sphere; // sphere centres (nsphere x 3)
  const double* vert;   // mesh vertices (nvert x 3)
  organ* org;           // (norg)
  int norg;
  int* prim_org;  // organ of each primitive: segments, spheres, meshes (nseg + nsphere + nmesh)
  int* seg_depth; // (nseg)
} plan;

static int cmp_org(const void* a, const void* b) {
  const organ *x = a, *y = b;
  if (x->label != y->label) return x->label < y->label ? -1 : 1;
  return (x->instance > y->instance) - (x->instance < y->instance);
}

static int find_org(const plan* p, int label, int instance) {
  int lo = 0, hi = p->norg;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    const organ* o = &p->org[mid];
    if (o->label < label || (o->label == label && o->instance < instance))
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

static void plan_free(plan* p) {
  const vd_model* m = p->m;
  size_t nprim = (size_t)m->nseg + (size_t)m->nsphere + (size_t)m->nmesh + 1;
  vd_free(p->org, sizeof(organ) * nprim);
  vd_free(p->prim_org, sizeof(int) * nprim);
  vd_free(p->seg_depth, sizeof(int) * ((size_t)m->nseg + 1));
}

static vd_status plan_make(plan* p, const vd_model* m, const vd_data* d, vd_error* err) {
  memset(p, 0, sizeof *p);
  p->m = m;
  p->node = d ? d->node_pos : m->node_pos0;
  p->sphere = d ? d->sphere_pos : m->sphere_pos0;
  p->vert = d ? d->vert_pos : m->vert_pos0;
  size_t nprim = (size_t)m->nseg + (size_t)m->nsphere + (size_t)m->nmesh + 1;
  p->org = vd_malloc(sizeof(organ) * nprim);
  p->prim_org = vd_malloc(sizeof(int) * nprim);
  p->seg_depth = vd_malloc(sizeof(int) * ((size_t)m->nseg + 1));
  if (!p->org || !p->prim_org || !p->seg_depth) {
    plan_free(p);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  // every primitive's (label, instance), sorted and made unique
  int n = 0;
  for (int i = 0; i < m->nseg; i++)
    p->org[n++] = (organ){.label = m->seg_label[i], .instance = m->seg_instance[i]};
  for (int i = 0; i < m->nsphere; i++)
    p->org[n++] = (organ){.label = m->sphere_label[i], .instance = m->sphere_instance[i]};
  for (int i = 0; i < m->nmesh; i++)
    p->org[n++] = (organ){.label = m->mesh_label[i], .instance = m->mesh_instance[i]};
  if (n) qsort(p->org, (size_t)n, sizeof(organ), cmp_org);
  int k = 0;
  for (int i = 0; i < n; i++)
    if (!k || cmp_org(&p->org[k - 1], &p->org[i]) != 0) p->org[k++] = p->org[i];
  p->norg = k;
  for (int i = 0; i < k; i++) {
    organ* o = &p->org[i];
    char lab[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, o->label, lab, sizeof lab);
    snprintf(o->name, sizeof o->name, "%s_%d", lab, o->instance);
    o->parent = -1;
    o->depth = INT32_MAX;
  }
  // the depth of every segment along its parents: walk up to a known one (or the root) keeping
  // the path, then set it from the top down (prim_org serves as the stack here)
  for (int i = 0; i < m->nseg; i++)
    p->seg_depth[i] = -1;
  int* stack = p->prim_org;
  for (int i = 0; i < m->nseg; i++) {
    int j = i, up = 0;
    while (j >= 0 && p->seg_depth[j] < 0 && up < m->nseg)
      stack[up++] = j, j = m->seg_parent[j];
    int depth = j >= 0 && p->seg_depth[j] >= 0 ? p->seg_depth[j] + 1 : 0;
    while (up > 0)
      p->seg_depth[stack[--up]] = depth++;
  }
  // each primitive's organ; each organ's root primitive (the shallowest) and its parent organ
  for (int kind = 0, q = 0; kind < 3; kind++) {
    int cnt = kind == 0 ? m->nseg : kind == 1 ? m->nsphere : m->nmesh;
    for (int i = 0; i < cnt; i++, q++) {
      int label = kind == 0 ? m->seg_label[i] : kind == 1 ? m->sphere_label[i] : m->mesh_label[i];
      int inst = kind == 0 ? m->seg_instance[i] : kind == 1 ? m->sphere_instance[i] : m->mesh_instance[i];
      int par = kind == 0 ? m->seg_parent[i] : kind == 1 ? m->sphere_parent[i] : m->mesh_parent[i];
      int o = find_org(p, label, inst);
      p->prim_org[q] = o;
      int depth = kind == 0 ? p->seg_depth[i] : par >= 0 ? p->seg_depth[par] + 1 : 0;
      if (depth < p->org[o].depth) {
        p->org[o].depth = depth;
        p->org[o].parent = par >= 0 ? par : -1; // a segment index for now
      }
    }
  }
  for (int i = 0; i < k; i++) {
    int par = p->org[i].parent;
    p->org[i].parent = par >= 0 ? p->prim_org[par] : -1;
    if (p->org[i].parent == i) p->org[i].parent = -1;
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// shapes

// a segment as an axis from a to b with radius r; 0 when it has no length
static int seg_shape(const plan* p, int i, vd_vec3* a, vd_vec3* b, double* r) {
  const vd_model* m = p->m;
  int n0 = m->seg_node[2 * i], n1 = m->seg_node[2 * i + 1];
  *a = vd_v3(p->node[3 * n0], p->node[3 * n0 + 1], p->node[3 * n0 + 2]);
  *b = vd_v3(p->node[3 * n1], p->node[3 * n1 + 1], p->node[3 * n1 + 2]);
  *r = 0.5 * (m->seg_radius[2 * i] + m->seg_radius[2 * i + 1]);
  return vd_norm(vd_sub(*b, *a)) > 1e-9 && *r > 0;
}

// roll, pitch, yaw (fixed axes X, Y, Z: R = Rz(yaw) Ry(pitch) Rx(roll)) that turn +Z onto u
static void rpy_of_z(vd_vec3 u, double rpy[3]) {
  u = vd_normalize(u);
  rpy[0] = 0;
  rpy[1] = acos(u.z < -1 ? -1 : u.z > 1 ? 1 : u.z);
  rpy[2] = atan2(u.y, u.x);
}

// a closed triangle mesh of mesh primitive i: as it is when closed, else a slab of thickness h
// (both faces along the vertex normals and walls on the boundary edges), outward
typedef struct tmesh {
  int nv, nt;       // vertices and triangles
  int cap_v, cap_t; // their room
  double* v;        // (nv x 3)
  int* t;           // (nt x 3)
} tmesh;

static void tmesh_free(tmesh* s) {
  vd_free(s->v, sizeof(double) * 3 * (size_t)s->cap_v);
  vd_free(s->t, sizeof(int) * 3 * (size_t)s->cap_t);
  memset(s, 0, sizeof *s);
}

typedef struct edge {
  int a, b; // directed, as in its triangle
  int lo, hi;
} edge;
static int cmp_edge(const void* x, const void* y) {
  const edge *e = x, *f = y;
  if (e->lo != f->lo) return e->lo < f->lo ? -1 : 1;
  return (e->hi > f->hi) - (e->hi < f->hi);
}

static vd_status mesh_shape(const plan* p, int i, double h, tmesh* s, vd_error* err) {
  const vd_model* m = p->m;
  memset(s, 0, sizeof *s);
  int v0 = m->mesh_vert[2 * i], nv = m->mesh_vert[2 * i + 1];
  int t0 = m->mesh_tri[2 * i], nt = m->mesh_tri[2 * i + 1];
  int closed = m->mesh_closed[i];
  size_t nedge = closed ? 0 : 3 * (size_t)nt;
  s->nv = closed ? nv : 2 * nv;
  s->cap_v = s->nv + 1;
  s->cap_t = (closed ? nt : 2 * nt + 2 * (int)nedge) + 1; // at most: walls on every edge
  s->v = vd_malloc(sizeof(double) * 3 * (size_t)s->cap_v);
  s->t = vd_malloc(sizeof(int) * 3 * (size_t)s->cap_t);
  edge* e = nedge ? vd_malloc(sizeof(edge) * nedge) : NULL;
  double* nrm = closed ? NULL : vd_calloc((size_t)nv + 1, 3 * sizeof(double));
  if (!s->v || !s->t || (nedge && !e) || (!closed && !nrm)) {
    vd_free(e, sizeof(edge) * nedge);
    vd_free(nrm, 3 * sizeof(double) * ((size_t)nv + 1));
    tmesh_free(s);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  // vertex normals (area-weighted) for the slab
  for (int t = 0; t < nt && !closed; t++) {
    const int* tv = m->tri_vert + 3 * (t0 + t);
    vd_vec3 a = vd_v3(p->vert[3 * tv[0]], p->vert[3 * tv[0] + 1], p->vert[3 * tv[0] + 2]);
    vd_vec3 b = vd_v3(p->vert[3 * tv[1]], p->vert[3 * tv[1] + 1], p->vert[3 * tv[1] + 2]);
    vd_vec3 c = vd_v3(p->vert[3 * tv[2]], p->vert[3 * tv[2] + 1], p->vert[3 * tv[2] + 2]);
    vd_vec3 fn = vd_cross(vd_sub(b, a), vd_sub(c, a));
    for (int k = 0; k < 3; k++) {
      double* q = nrm + 3 * (tv[k] - v0);
      q[0] += fn.x, q[1] += fn.y, q[2] += fn.z;
    }
  }
  for (int k = 0; k < nv; k++) {
    const double* x = p->vert + 3 * (v0 + k);
    vd_vec3 n = closed ? vd_v3(0, 0, 0) : vd_normalize(vd_v3(nrm[3 * k], nrm[3 * k + 1], nrm[3 * k + 2]));
    if (!isfinite(n.x + n.y + n.z)) n = vd_v3(0, 0, 0);
    for (int side = 0; side < (closed ? 1 : 2); side++) {
      double f = closed ? 0 : side ? -0.5 * h : 0.5 * h;
      double* o = s->v + 3 * (k + side * nv);
      o[0] = x[0] + f * n.x, o[1] = x[1] + f * n.y, o[2] = x[2] + f * n.z;
    }
  }
  int k = 0;
  for (int t = 0; t < nt; t++) {
    const int* tv = m->tri_vert + 3 * (t0 + t);
    int a = tv[0] - v0, b = tv[1] - v0, c = tv[2] - v0;
    s->t[3 * k] = a, s->t[3 * k + 1] = b, s->t[3 * k + 2] = c, k++;
    if (closed) continue;
    s->t[3 * k] = a + nv, s->t[3 * k + 1] = c + nv, s->t[3 * k + 2] = b + nv, k++;
    int q[3] = {a, b, c};
    for (int j = 0; j < 3; j++) {
      edge* ed = &e[3 * t + j];
      ed->a = q[j], ed->b = q[(j + 1) % 3];
      ed->lo = ed->a < ed->b ? ed->a : ed->b, ed->hi = ed->a < ed->b ? ed->b : ed->a;
    }
  }
  // walls on the boundary edges (those of one triangle), facing out of the slab
  if (nedge) qsort(e, nedge, sizeof(edge), cmp_edge);
  for (size_t j = 0; j < nedge;) {
    size_t r = j + 1;
    while (r < nedge && e[r].lo == e[j].lo && e[r].hi == e[j].hi)
      r++;
    if (r - j == 1) {
      int at = e[j].a, bt = e[j].b, ab = at + nv, bb = bt + nv;
      s->t[3 * k] = at, s->t[3 * k + 1] = ab, s->t[3 * k + 2] = bb, k++;
      s->t[3 * k] = at, s->t[3 * k + 1] = bb, s->t[3 * k + 2] = bt, k++;
    }
    j = r;
  }
  vd_free(e, sizeof(edge) * nedge);
  vd_free(nrm, 3 * sizeof(double) * ((size_t)nv + 1));
  // outward: a positive signed volume (flip every triangle otherwise)
  double vol = 0;
  for (int t = 0; t < k; t++) {
    const double* a = s->v + 3 * s->t[3 * t];
    const double* b = s->v + 3 * s->t[3 * t + 1];
    const double* c = s->v + 3 * s->t[3 * t + 2];
    vol += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (vol < 0)
    for (int t = 0; t < k; t++) {
      int x = s->t[3 * t + 1];
      s->t[3 * t + 1] = s->t[3 * t + 2], s->t[3 * t + 2] = x;
    }
  s->nt = k;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// writing

typedef struct out {
  FILE* fp;
  const vd_export_def* def;
  char prefix[64]; // "<name>/" in MJCF names
} out;

// an OBJ file of a shape
static vd_status write_obj(const char* path, const tmesh* s, const char* what, vd_error* err) {
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (st) return st;
  fprintf(f.fp, "# verdant export, format version %d: %s, units m\n", VD_EXPORT_FORMAT_VERSION,
          what);
  for (int v = 0; v < s->nv; v++)
    fprintf(f.fp, "v %.9g %.9g %.9g\n", s->v[3 * v], s->v[3 * v + 1], s->v[3 * v + 2]);
  for (int t = 0; t < s->nt; t++)
    fprintf(f.fp, "f %d %d %d\n", s->t[3 * t] + 1, s->t[3 * t + 1] + 1, s->t[3 * t + 2] + 1);
  return vd_outfile_commit(&f, err);
}

// material colour of a label
static void label_rgb(const vd_model* m, int label, float rgb[3]) {
  const vd_label* l = vd_model_find_label(m, label);
  if (l)
    memcpy(rgb, l->rgb, sizeof l->rgb);
  else
    vd_plant_default_rgb(label, rgb);
}

// a URDF or SDF origin/pose of a cylinder from a to b
static void axis_pose(vd_vec3 a, vd_vec3 b, double xyz[3], double rpy[3]) {
  vd_vec3 c = vd_scale(vd_add(a, b), 0.5);
  xyz[0] = c.x, xyz[1] = c.y, xyz[2] = c.z;
  rpy_of_z(vd_sub(b, a), rpy);
}

// the geometry element of primitive (kind, i) in URDF or SDF; mesh_uri for meshes
static void geometry_xml(FILE* fp, int sdf, const plan* p, int kind, int i, const char* mesh_uri,
                         const char* ind) {
  if (kind == 0) {
    vd_vec3 a, b;
    double r;
    seg_shape(p, i, &a, &b, &r);
    double l = vd_norm(vd_sub(b, a));
    if (sdf)
      fprintf(fp, "%s<geometry><cylinder><radius>%.9g</radius><length>%.9g</length></cylinder></geometry>\n",
              ind, r, l);
    else
      fprintf(fp, "%s<geometry><cylinder radius=\"%.9g\" length=\"%.9g\"/></geometry>\n", ind, r, l);
  } else if (kind == 1) {
    if (sdf)
      fprintf(fp, "%s<geometry><sphere><radius>%.9g</radius></sphere></geometry>\n", ind,
              p->m->sphere_radius[i]);
    else
      fprintf(fp, "%s<geometry><sphere radius=\"%.9g\"/></geometry>\n", ind, p->m->sphere_radius[i]);
  } else {
    if (sdf)
      fprintf(fp, "%s<geometry><mesh><uri>%s</uri></mesh></geometry>\n", ind, mesh_uri);
    else
      fprintf(fp, "%s<geometry><mesh filename=\"%s\"/></geometry>\n", ind, mesh_uri);
  }
}

// the pose of primitive (kind, i) in URDF (<origin>) or SDF (<pose>)
static void pose_xml(FILE* fp, int sdf, const plan* p, int kind, int i, const char* ind) {
  double xyz[3] = {0, 0, 0}, rpy[3] = {0, 0, 0};
  if (kind == 0) {
    vd_vec3 a, b;
    double r;
    seg_shape(p, i, &a, &b, &r);
    axis_pose(a, b, xyz, rpy);
  } else if (kind == 1) {
    for (int k = 0; k < 3; k++)
      xyz[k] = p->sphere[3 * i + k];
  }
  if (sdf)
    fprintf(fp, "%s<pose>%.9g %.9g %.9g %.9g %.9g %.9g</pose>\n", ind, xyz[0], xyz[1], xyz[2],
            rpy[0], rpy[1], rpy[2]);
  else
    fprintf(fp, "%s<origin xyz=\"%.9g %.9g %.9g\" rpy=\"%.9g %.9g %.9g\"/>\n", ind, xyz[0], xyz[1],
            xyz[2], rpy[0], rpy[1], rpy[2]);
}

// primitives of organ o, in kind order (segments, spheres, meshes), through a callback
typedef struct prim_ref {
  int kind, i;
} prim_ref;

static int organ_prims(const plan* p, int o, prim_ref* refs, int cap) {
  const vd_model* m = p->m;
  int n = 0, q = 0;
  for (int kind = 0; kind < 3; kind++) {
    int cnt = kind == 0 ? m->nseg : kind == 1 ? m->nsphere : m->nmesh;
    for (int i = 0; i < cnt; i++, q++) {
      if (p->prim_org[q] != o) continue;
      if (kind == 0) {
        vd_vec3 a, b;
        double r;
        if (!seg_shape(p, i, &a, &b, &r)) continue;
      }
      if (n < cap) refs[n] = (prim_ref){kind, i};
      n++;
    }
  }
  return n;
}

// the mesh file of mesh primitive i of organ o (relative to the main file's folder)
static void mesh_file(const char* dir_rel, const organ* o, int k, char* buf, size_t cap) {
  snprintf(buf, cap, "%s/%s_m%d.obj", dir_rel, o->name, k);
}

static vd_status write_links(out* w, const plan* p, const char* dir_rel, int sdf, prim_ref* pr,
                             int cap) {
  FILE* fp = w->fp;
  const vd_model* m = p->m;
  for (int o = 0; o < p->norg; o++) {
    const organ* og = &p->org[o];
    int n = organ_prims(p, o, pr, cap);
    float rgb[3];
    label_rgb(m, og->label, rgb);
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, og->label, lname, sizeof lname);
    fprintf(fp, "  %s<link name=\"%s\">\n", sdf ? "  " : "", og->name);
    if (sdf) fprintf(fp, "      <!-- label %d %s, instance %d -->\n", og->label, lname, og->instance);
    else fprintf(fp, "    <!-- label %d %s, instance %d -->\n", og->label, lname, og->instance);
    int kmesh = 0;
    for (int j = 0; j < n && j < cap; j++) {
      char uri[4400] = "";
      if (pr[j].kind == 2) mesh_file(dir_rel, og, kmesh++, uri, sizeof uri);
      for (int role = 0; role < 2; role++) {
        const char* el = role ? "collision" : "visual";
        const char* ind = sdf ? "        " : "      ";
        fprintf(fp, "%s<%s name=\"%s_%s%d\">\n", sdf ? "      " : "    ", el, og->name,
                role ? "c" : "v", j);
        pose_xml(fp, sdf, p, pr[j].kind, pr[j].i, ind);
        geometry_xml(fp, sdf, p, pr[j].kind, pr[j].i, uri, ind);
        if (!role && sdf)
          fprintf(fp, "%s<material><diffuse>%.4g %.4g %.4g 1</diffuse><ambient>%.4g %.4g %.4g 1</ambient></material>\n",
                  ind, rgb[0], rgb[1], rgb[2], rgb[0], rgb[1], rgb[2]);
        if (!role && !sdf) fprintf(fp, "%s<material name=\"%s\"/>\n", ind, lname);
        fprintf(fp, "%s</%s>\n", sdf ? "      " : "    ", el);
      }
    }
    fprintf(fp, "  %s</link>\n", sdf ? "  " : "");
  }
  return VD_OK;
}

static vd_status write_urdf(out* w, const plan* p, const char* dir_rel, prim_ref* pr, int cap) {
  FILE* fp = w->fp;
  const vd_model* m = p->m;
  fprintf(fp, "<?xml version=\"1.0\"?>\n");
  fprintf(fp, "<!-- verdant export, format version %d: a static plant, one link per organ "
              "(label_instance), units m -->\n", VD_EXPORT_FORMAT_VERSION);
  fprintf(fp, "<robot name=\"%s\">\n", w->def->name);
  // one material per label
  for (int i = 0; i < m->nlabel; i++) {
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, m->labels[i].id, lname, sizeof lname);
    fprintf(fp, "  <material name=\"%s\"><color rgba=\"%.4g %.4g %.4g 1\"/></material>\n", lname,
            m->labels[i].rgb[0], m->labels[i].rgb[1], m->labels[i].rgb[2]);
  }
  fprintf(fp, "  <link name=\"%s_base\"/>\n", w->def->name);
  vd_status st = write_links(w, p, dir_rel, 0, pr, cap);
  // each organ on a fixed joint to the organ it hangs from (the base for the first)
  for (int o = 0; !st && o < p->norg; o++) {
    const organ* og = &p->org[o];
    char parent[VD_LABEL_NAME_MAX + 32];
    if (og->parent >= 0)
      snprintf(parent, sizeof parent, "%s", p->org[og->parent].name);
    else
      snprintf(parent, sizeof parent, "%s_base", w->def->name);
    fprintf(fp, "  <joint name=\"%s_joint\" type=\"fixed\"><parent link=\"%s\"/><child link=\"%s\"/>"
                "<origin xyz=\"0 0 0\" rpy=\"0 0 0\"/></joint>\n",
            og->name, parent, og->name);
  }
  fprintf(fp, "</robot>\n");
  return st;
}

static vd_status write_sdf(out* w, const plan* p, const char* dir_rel, prim_ref* pr, int cap) {
  FILE* fp = w->fp;
  const vd_export_def* d = w->def;
  fprintf(fp, "<?xml version=\"1.0\"?>\n");
  fprintf(fp, "<!-- verdant export, format version %d: a static plant, one link per organ "
              "(label_instance), units m -->\n", VD_EXPORT_FORMAT_VERSION);
  fprintf(fp, "<sdf version=\"1.7\">\n  <model name=\"%s\">\n    <static>true</static>\n", d->name);
  fprintf(fp, "    <pose>%.9g %.9g %.9g 0 0 0</pose>\n", d->pos.x, d->pos.y, d->pos.z);
  // SDF writes links at the model's depth: indent them by two more
  vd_status st = write_links(w, p, dir_rel, 1, pr, cap);
  fprintf(fp, "  </model>\n</sdf>\n");
  return st;
}

static vd_status write_mjcf(out* w, const plan* p, prim_ref* pr, int cap, vd_error* err) {
  FILE* fp = w->fp;
  const vd_model* m = p->m;
  const vd_export_def* d = w->def;
  const char* pre = w->prefix;
  fprintf(fp, "<!-- verdant export, format version %d: a static plant for MuJoCo, one body per organ "
              "(%slabel_instance), units m; include it beside a robot: <include file=\"...\"/> -->\n",
          VD_EXPORT_FORMAT_VERSION, pre);
  fprintf(fp, "<mujoco model=\"%s\">\n  <asset>\n", d->name);
  for (int i = 0; i < m->nlabel; i++) {
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, m->labels[i].id, lname, sizeof lname);
    fprintf(fp, "    <material name=\"%s%s\" rgba=\"%.4g %.4g %.4g 1\"/>\n", pre, lname,
            m->labels[i].rgb[0], m->labels[i].rgb[1], m->labels[i].rgb[2]);
  }
  // the meshes, inline, in the plant's frame
  vd_status st = VD_OK;
  for (int o = 0; !st && o < p->norg; o++) {
    int n = organ_prims(p, o, pr, cap), kmesh = 0;
    for (int j = 0; !st && j < n && j < cap; j++) {
      if (pr[j].kind != 2) continue;
      tmesh s;
      if ((st = mesh_shape(p, pr[j].i, d->leaf_thickness, &s, err))) break;
      fprintf(fp, "    <mesh name=\"%s%s_m%d\" vertex=\"", pre, p->org[o].name, kmesh++);
      for (int v = 0; v < s.nv; v++)
        fprintf(fp, "%s%.9g %.9g %.9g", v ? " " : "", s.v[3 * v], s.v[3 * v + 1], s.v[3 * v + 2]);
      fprintf(fp, "\" face=\"");
      for (int t = 0; t < s.nt; t++)
        fprintf(fp, "%s%d %d %d", t ? " " : "", s.t[3 * t], s.t[3 * t + 1], s.t[3 * t + 2]);
      fprintf(fp, "\"/>\n");
      tmesh_free(&s);
    }
  }
  fprintf(fp, "  </asset>\n  <worldbody>\n");
  fprintf(fp, "    <body name=\"%s\" pos=\"%.9g %.9g %.9g\">\n", d->name, d->pos.x, d->pos.y, d->pos.z);
  for (int o = 0; !st && o < p->norg; o++) {
    const organ* og = &p->org[o];
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, og->label, lname, sizeof lname);
    fprintf(fp, "      <body name=\"%s%s\">\n", pre, og->name);
    int n = organ_prims(p, o, pr, cap), kmesh = 0;
    for (int j = 0; j < n && j < cap; j++) {
      int i = pr[j].i;
      fprintf(fp, "        <geom name=\"%s%s_%d\" material=\"%s%s\" ", pre, og->name, j, pre, lname);
      if (pr[j].kind == 0) {
        vd_vec3 a, b;
        double r;
        seg_shape(p, i, &a, &b, &r);
        fprintf(fp, "type=\"capsule\" size=\"%.9g\" fromto=\"%.9g %.9g %.9g %.9g %.9g %.9g\"/>\n", r,
                a.x, a.y, a.z, b.x, b.y, b.z);
      } else if (pr[j].kind == 1) {
        fprintf(fp, "type=\"sphere\" size=\"%.9g\" pos=\"%.9g %.9g %.9g\"/>\n", m->sphere_radius[i],
                p->sphere[3 * i], p->sphere[3 * i + 1], p->sphere[3 * i + 2]);
      } else {
        fprintf(fp, "type=\"mesh\" mesh=\"%s%s_m%d\"/>\n", pre, og->name, kmesh++);
      }
    }
    fprintf(fp, "      </body>\n");
  }
  fprintf(fp, "    </body>\n  </worldbody>\n</mujoco>\n");
  return st;
}

// ---------------------------------------------------------------------------------------------
// the files

// folder of path's meshes: "<path without extension>_meshes" and its name relative to path's
// folder
static void mesh_dirs(const char* path, char* dir, size_t cap, char* rel, size_t rcap) {
  const char* slash = strrchr(path, '/');
  const char* dot = strrchr(path, '.');
  size_t n = dot && (!slash || dot > slash) ? (size_t)(dot - path) : strlen(path);
  snprintf(dir, cap, "%.*s_meshes", (int)n, path);
  const char* base = slash ? slash + 1 : path;
  snprintf(rel, rcap, "%s", dir + (base - path));
}

vd_status vd_geom_export(const vd_model* m, const vd_data* d, const vd_export_def* def,
                         const char* path, vd_error* err) {
  vd_export_def ed = def ? *def : vd_export_def_default();
  if ((int)ed.format < VD_EXPORT_URDF || ed.format > VD_EXPORT_MJCF)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "unknown export format %d", (int)ed.format);
  if (!ed.name || !ed.name[0] || strlen(ed.name) > 48)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "the model name must have 1..48 characters");
  for (const char* c = ed.name; *c; c++)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
          *c == '_' || *c == '-'))
      return vd_error_set(err, VD_ERR_ARG, path, 0, 0,
                          "the model name '%s' may hold letters, digits, '_' and '-' only", ed.name);
  if (!(ed.leaf_thickness > 0 && ed.leaf_thickness < 0.1))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "leaf thickness must be in (0, 0.1) m");
  if (!isfinite(ed.pos.x + ed.pos.y + ed.pos.z))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "the plant's position is not finite");
  if (d && (d->nnode != m->nnode || d->nseg != m->nseg || d->nsphere != m->nsphere ||
            d->nvert != m->nvert))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "the state does not belong to this model");
  plan p;
  vd_status st = plan_make(&p, m, d, err);
  if (st) return st;
  // one scratch list of an organ's primitives, as long as the longest organ's
  int cap = 1;
  {
    int* cnt = vd_calloc((size_t)p.norg + 1, sizeof(int));
    if (!cnt) {
      plan_free(&p);
      return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
    }
    int total = m->nseg + m->nsphere + m->nmesh;
    for (int q = 0; q < total; q++)
      if (++cnt[p.prim_org[q]] > cap) cap = cnt[p.prim_org[q]];
    vd_free(cnt, sizeof(int) * ((size_t)p.norg + 1));
  }
  prim_ref* pr = vd_malloc(sizeof(prim_ref) * (size_t)cap);
  if (!pr) {
    plan_free(&p);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  }
  // URDF and SDF: the meshes' OBJ files first, in their folder (removed again on failure)
  char dir[4200], rel[4200];
  mesh_dirs(path, dir, sizeof dir, rel, sizeof rel);
  int made_dir = 0, nfile = 0;
  if (ed.format != VD_EXPORT_MJCF && m->nmesh > 0) {
    struct stat sb;
    made_dir = stat(dir, &sb) != 0;
    st = vd_outdir_make(dir, err);
    for (int o = 0; !st && o < p.norg; o++) {
      int n = organ_prims(&p, o, pr, cap), kmesh = 0;
      for (int j = 0; !st && j < n && j < cap; j++) {
        if (pr[j].kind != 2) continue;
        char file[4800], what[200];
        snprintf(file, sizeof file, "%s/%s_m%d.obj", dir, p.org[o].name, kmesh);
        snprintf(what, sizeof what, "mesh %d of organ %s", kmesh, p.org[o].name);
        kmesh++;
        tmesh s;
        if (!(st = mesh_shape(&p, pr[j].i, ed.leaf_thickness, &s, err))) {
          st = write_obj(file, &s, what, err);
          tmesh_free(&s);
          nfile += !st;
        }
      }
    }
  }
  // the main file
  if (!st) {
    vd_outfile f;
    st = vd_outfile_open(&f, path, err);
    if (!st) {
      out w = {f.fp, &ed, ""};
      snprintf(w.prefix, sizeof w.prefix, "%s/", ed.name);
      st = ed.format == VD_EXPORT_URDF  ? write_urdf(&w, &p, rel, pr, cap)
           : ed.format == VD_EXPORT_SDF ? write_sdf(&w, &p, rel, pr, cap)
                                        : write_mjcf(&w, &p, pr, cap, err);
      if (st)
        vd_outfile_abort(&f);
      else
        st = vd_outfile_commit(&f, err);
    }
  }
  // a failure leaves nothing: the mesh files written and a folder made are removed
  if (st && nfile) {
    for (int o = 0; o < p.norg; o++) {
      int n = organ_prims(&p, o, pr, cap), kmesh = 0;
      for (int j = 0; j < n && j < cap; j++) {
        if (pr[j].kind != 2) continue;
        char file[4800];
        snprintf(file, sizeof file, "%s/%s_m%d.obj", dir, p.org[o].name, kmesh++);
        vd_outfile_remove(file);
      }
    }
  }
  if (st && made_dir) vd_outdir_remove(dir);
  vd_free(pr, sizeof(prim_ref) * (size_t)cap);
  plan_free(&p);
  return st;
}
