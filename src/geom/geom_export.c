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
  d.damping_ratio = 0.1;
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

// an MJCF mesh asset of shape s, inline, its vertices less offset (the frame of its body)
static void mjcf_mesh(FILE* fp, const char* name, const tmesh* s, vd_vec3 o) {
  fprintf(fp, "    <mesh name=\"%s\" vertex=\"", name);
  for (int v = 0; v < s->nv; v++)
    fprintf(fp, "%s%.9g %.9g %.9g", v ? " " : "", s->v[3 * v] - o.x, s->v[3 * v + 1] - o.y,
            s->v[3 * v + 2] - o.z);
  fprintf(fp, "\" face=\"");
  for (int t = 0; t < s->nt; t++)
    fprintf(fp, "%s%d %d %d", t ? " " : "", s->t[3 * t], s->t[3 * t + 1], s->t[3 * t + 2]);
  fprintf(fp, "\"/>\n");
}

// one MJCF material per label (its colour), named prefix + the label's name
static void mjcf_materials(FILE* fp, const vd_model* m, const char* pre) {
  for (int i = 0; i < m->nlabel; i++) {
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, m->labels[i].id, lname, sizeof lname);
    fprintf(fp, "    <material name=\"%s%s\" rgba=\"%.4g %.4g %.4g 1\"/>\n", pre, lname,
            m->labels[i].rgb[0], m->labels[i].rgb[1], m->labels[i].rgb[2]);
  }
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
  mjcf_materials(fp, m, pre);
  // the meshes, inline, in the plant's frame
  vd_status st = VD_OK;
  for (int o = 0; !st && o < p->norg; o++) {
    int n = organ_prims(p, o, pr, cap), kmesh = 0;
    for (int j = 0; !st && j < n && j < cap; j++) {
      if (pr[j].kind != 2) continue;
      tmesh s;
      if ((st = mesh_shape(p, pr[j].i, d->leaf_thickness, &s, err))) break;
      char name[VD_LABEL_NAME_MAX + 128];
      snprintf(name, sizeof name, "%s%s_m%d", pre, p->org[o].name, kmesh++);
      mjcf_mesh(fp, name, &s, vd_v3(0, 0, 0));
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
// flexible plants: the rods as links joined by spring joints

// one link: rod segments of one organ, rigid among themselves
typedef struct xlink {
  int root;        // rod segment whose joint joins the xlink to its parent link
  int parent;      // parent link, -1: the base
  int label, instance;
  vd_vec3 origin;  // the joint point: the root segment's start (m)
  double mass;     // (kg)
  vd_vec3 com;     // centre of mass (m)
  double in[6];    // inertia about com, world axes: xx yy zz xy xz yz (kg m^2)
  double k[3];     // joint stiffness, bend d1, bend d2, twist d3: its segments' in series (N m/rad)
  double c[3];     // joint damping (N m s/rad)
  vd_vec3 axis[3]; // the root segment's rest d1, d2, d3
  char name[VD_LABEL_NAME_MAX + 40];
} xlink;

typedef struct flex {
  const vd_export_rods* r;
  int nlink;
  xlink* lk;       // (nlink)
  int* seg_link;  // xlink of each rod segment, -1: the base (nseg)
  int* order;     // segments, parents before children (nseg)
  int* mesh_link; // xlink of each plant mesh, -1: the base (plant nmesh)
  int* kid0;      // first child xlink of each link; [nlink]: of the base; -1 none (nlink + 1)
  int* next;      // next sibling link, -1 none (nlink)
} flex;

static vd_vec3 rod_end(const vd_export_rods* r, int t, int end) {
  const double* e = r->seg_ends + 6 * t + 3 * end;
  return vd_v3(e[0], e[1], e[2]);
}

static vd_quat rod_quat(const vd_export_rods* r, int t) {
  const double* q = r->seg_quat + 4 * t;
  return vd_quat_normalize((vd_quat){q[0], q[1], q[2], q[3]});
}

static int rod_parent(const vd_export_rods* r, int t) {
  int p = r->seg_parent[t];
  return p >= 0 && p < r->nseg ? p : -1;
}

static void flex_free(flex* f, int nseg, int nmesh) {
  vd_free(f->lk, sizeof(xlink) * ((size_t)nseg + 1));
  vd_free(f->seg_link, sizeof(int) * ((size_t)nseg + 1));
  vd_free(f->order, sizeof(int) * ((size_t)nseg + 1));
  vd_free(f->mesh_link, sizeof(int) * ((size_t)nmesh + 1));
  vd_free(f->kid0, sizeof(int) * ((size_t)nseg + 2));
  vd_free(f->next, sizeof(int) * ((size_t)nseg + 1));
  memset(f, 0, sizeof *f);
}

// segments with every parent before its children, by depth (a cycle's segments count as roots)
static vd_status flex_order(flex* f, int* depth, vd_error* err) {
  const vd_export_rods* r = f->r;
  int n = r->nseg, maxd = 0;
  for (int t = 0; t < n; t++)
    depth[t] = -1;
  int* stack = f->order; // scratch until the sort below
  for (int t = 0; t < n; t++) {
    int j = t, up = 0;
    while (j >= 0 && depth[j] < 0 && up < n)
      stack[up++] = j, j = rod_parent(r, j);
    int d = j >= 0 && depth[j] >= 0 ? depth[j] + 1 : 0;
    while (up > 0)
      depth[stack[--up]] = d++;
    if (d - 1 > maxd) maxd = d - 1;
  }
  int* start = vd_calloc((size_t)maxd + 2, sizeof(int));
  if (!start) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int t = 0; t < n; t++)
    start[depth[t] + 1]++;
  for (int d = 0; d <= maxd; d++)
    start[d + 1] += start[d];
  for (int t = 0; t < n; t++)
    f->order[start[depth[t]]++] = t;
  vd_free(start, sizeof(int) * ((size_t)maxd + 2));
  return VD_OK;
}

// inertia of xlink l about the axis a through its joint point (kg m^2)
static double axis_inertia(const xlink* l, vd_vec3 a) {
  double j = a.x * a.x * l->in[0] + a.y * a.y * l->in[1] + a.z * a.z * l->in[2] +
             2 * (a.x * a.y * l->in[3] + a.x * a.z * l->in[4] + a.y * a.z * l->in[5]);
  vd_vec3 d = vd_sub(l->com, l->origin);
  double ar = vd_dot(a, d);
  return j + l->mass * (vd_dot(d, d) - ar * ar);
}

// the links: a new one at an organ's first rod and every `chunk` rods along it; masses lumped
// at the segments' end points plus their rotary inertia; joint compliances in series
static void flex_links(flex* f, const vd_export_def* def, int* size, double* acc, double* comp,
                       int* pos) {
  const vd_export_rods* r = f->r;
  int n = r->nseg, nl = 0;
  // each organ's rod count, summed from the tips to the organ's first rod
  for (int t = 0; t < n; t++)
    size[t] = 1;
  for (int q = n - 1; q >= 0; q--) {
    int t = f->order[q], p = rod_parent(r, t);
    if (p >= 0 && !r->seg_fixed[p] && !r->seg_fixed[t] && r->seg_instance[p] == r->seg_instance[t])
      size[p] += size[t];
  }
  for (int q = 0; q < n; q++) {
    int t = f->order[q], p = rod_parent(r, t);
    if (r->seg_fixed[t]) {
      f->seg_link[t] = -1;
      continue;
    }
    int first = p < 0 || r->seg_fixed[p] || r->seg_instance[p] != r->seg_instance[t];
    int nper = def->links_per_organ;
    // size[] of an organ's first rod becomes the organ's chunk, handed down to its rods
    if (first) size[t] = nper < 0 ? INT32_MAX : nper == 0 ? 1 : (size[t] + nper - 1) / nper;
    else size[t] = size[p];
    double kk[3];
    for (int k = 0; k < 3; k++) {
      double s = r->seg_stiff[3 * t + k];
      kk[k] = s > 0 && isfinite(s) ? 1.0 / s : 0.0;
    }
    if (first || pos[p] >= size[t]) {
      xlink* l = &f->lk[nl];
      memset(l, 0, sizeof *l);
      l->root = t;
      l->parent = p >= 0 ? f->seg_link[p] : -1;
      l->label = r->seg_label[t], l->instance = r->seg_instance[t];
      l->origin = rod_end(r, t, 0);
      vd_quat qt = rod_quat(r, t);
      l->axis[0] = vd_quat_rotate(qt, vd_v3(1, 0, 0));
      l->axis[1] = vd_quat_rotate(qt, vd_v3(0, 1, 0));
      l->axis[2] = vd_quat_rotate(qt, vd_v3(0, 0, 1));
      f->seg_link[t] = nl++;
      pos[t] = 1;
      for (int k = 0; k < 3; k++)
        comp[3 * t + k] = kk[k];
    } else {
      f->seg_link[t] = f->seg_link[p];
      pos[t] = pos[p] + 1;
      for (int k = 0; k < 3; k++)
        comp[3 * t + k] = comp[3 * p + k] + kk[k];
    }
    // the link's compliance: its longest path's; its moments: m, m x, m x x^T, rotary
    int li = f->seg_link[t];
    xlink* l = &f->lk[li];
    for (int k = 0; k < 3; k++)
      if (comp[3 * t + k] > l->k[k]) l->k[k] = comp[3 * t + k];
    double m = r->seg_mass[t] > 0 && isfinite(r->seg_mass[t]) ? r->seg_mass[t] : 0;
    vd_vec3 x = rod_end(r, t, 1);
    double* a = acc + 10 * li;
    a[0] += m, a[1] += m * x.x, a[2] += m * x.y, a[3] += m * x.z;
    a[4] += m * x.x * x.x, a[5] += m * x.y * x.y, a[6] += m * x.z * x.z;
    a[7] += m * x.x * x.y, a[8] += m * x.x * x.z, a[9] += m * x.y * x.z;
    // rotary inertia ib (1 - d3 d3^T) + it d3 d3^T, world axes
    double ib = r->seg_inertia[2 * t], it = r->seg_inertia[2 * t + 1];
    vd_vec3 d3 = vd_quat_rotate(rod_quat(r, t), vd_v3(0, 0, 1));
    double dd[6] = {d3.x * d3.x, d3.y * d3.y, d3.z * d3.z, d3.x * d3.y, d3.x * d3.z, d3.y * d3.z};
    for (int k = 0; k < 6; k++)
      l->in[k] += (k < 3 ? ib : 0) + (it - ib) * dd[k];
  }
  f->nlink = nl;
  // mass, centre and inertia about it (floored so that every xlink is a valid rigid body), the
  // springs, and damping at damping_ratio of critical for the xlink on its spring
  for (int i = 0; i < nl; i++) {
    xlink* l = &f->lk[i];
    const double* a = acc + 10 * i;
    double m = a[0] > 1e-9 ? a[0] : 1e-9;
    vd_vec3 c = a[0] > 0 ? vd_v3(a[1] / a[0], a[2] / a[0], a[3] / a[0]) : l->origin;
    // sum m (|x|^2 1 - x x^T) about the origin, moved to c
    double sxx = a[4] - a[0] * c.x * c.x, syy = a[5] - a[0] * c.y * c.y, szz = a[6] - a[0] * c.z * c.z;
    double sxy = a[7] - a[0] * c.x * c.y, sxz = a[8] - a[0] * c.x * c.z, syz = a[9] - a[0] * c.y * c.z;
    l->in[0] += syy + szz, l->in[1] += sxx + szz, l->in[2] += sxx + syy;
    l->in[3] -= sxy, l->in[4] -= sxz, l->in[5] -= syz;
    double floor = 1e-12 + 1e-6 * (fabs(l->in[0]) + fabs(l->in[1]) + fabs(l->in[2]));
    for (int k = 0; k < 3; k++)
      l->in[k] += floor;
    l->mass = m, l->com = c;
    for (int k = 0; k < 3; k++) {
      l->k[k] = l->k[k] > 0 ? 1.0 / l->k[k] : 0.0;
      double j = axis_inertia(l, l->axis[k]);
      l->c[k] = 2 * def->damping_ratio * sqrt(l->k[k] * (j > 0 ? j : 0));
    }
  }
  // the tree of links
  for (int i = 0; i <= nl; i++)
    f->kid0[i] = -1;
  for (int i = nl - 1; i >= 0; i--) {
    int p = f->lk[i].parent < 0 ? nl : f->lk[i].parent;
    f->next[i] = f->kid0[p];
    f->kid0[p] = i;
  }
}

// links by label, instance, then index (qsort has no user pointer: the links are set before)
static _Thread_local const xlink* sort_links;
static int cmp_link(const void* a, const void* b) {
  int i = *(const int*)a, j = *(const int*)b;
  const xlink *x = &sort_links[i], *y = &sort_links[j];
  if (x->label != y->label) return x->label < y->label ? -1 : 1;
  if (x->instance != y->instance) return x->instance < y->instance ? -1 : 1;
  return (i > j) - (i < j);
}

static vd_status flex_make(flex* f, const vd_model* m, const vd_export_def* def, vd_error* err) {
  const vd_export_rods* r = def->rods;
  int n = r->nseg;
  memset(f, 0, sizeof *f);
  f->r = r;
  f->lk = vd_malloc(sizeof(xlink) * ((size_t)n + 1));
  f->seg_link = vd_malloc(sizeof(int) * ((size_t)n + 1));
  f->order = vd_malloc(sizeof(int) * ((size_t)n + 1));
  f->mesh_link = vd_malloc(sizeof(int) * ((size_t)m->nmesh + 1));
  f->kid0 = vd_malloc(sizeof(int) * ((size_t)n + 2));
  f->next = vd_malloc(sizeof(int) * ((size_t)n + 1));
  int* size = vd_malloc(sizeof(int) * ((size_t)n + 1));
  int* pos = vd_malloc(sizeof(int) * ((size_t)n + 1));
  double* acc = vd_calloc((size_t)n + 1, 10 * sizeof(double));
  double* comp = vd_malloc(sizeof(double) * 3 * ((size_t)n + 1));
  vd_status st = VD_OK;
  if (!f->lk || !f->seg_link || !f->order || !f->mesh_link || !f->kid0 || !f->next || !size ||
      !pos || !acc || !comp) {
    vd_free(size, sizeof(int) * ((size_t)n + 1));
    vd_free(pos, sizeof(int) * ((size_t)n + 1));
    vd_free(acc, 10 * sizeof(double) * ((size_t)n + 1));
    vd_free(comp, sizeof(double) * 3 * ((size_t)n + 1));
    flex_free(f, n, m->nmesh);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  st = flex_order(f, size, err);
  if (!st) {
    flex_links(f, def, size, acc, comp, pos);
    for (int i = 0; i < m->nmesh; i++) {
      int t = r->mesh_seg ? r->mesh_seg[i] : -1;
      f->mesh_link[i] = t >= 0 && t < n ? f->seg_link[t] : -1;
    }
    // names: <label>_<instance>_<k>, k counting the organ's links in the order they come
    // (links sorted by label, instance and index; size[] is free again)
    for (int i = 0; i < f->nlink; i++)
      size[i] = i;
    sort_links = f->lk;
    if (f->nlink) qsort(size, (size_t)f->nlink, sizeof(int), cmp_link);
    for (int j = 0, k = 0; j < f->nlink; j++) {
      xlink* l = &f->lk[size[j]];
      const xlink* prev = j ? &f->lk[size[j - 1]] : NULL;
      k = prev && prev->label == l->label && prev->instance == l->instance ? k + 1 : 0;
      char lab[VD_LABEL_NAME_MAX + 16];
      geom_obj_name(m->labels, m->nlabel, l->label, lab, sizeof lab);
      snprintf(l->name, sizeof l->name, "%s_%d_%d", lab, l->instance, k);
    }
  }
  vd_free(size, sizeof(int) * ((size_t)n + 1));
  vd_free(pos, sizeof(int) * ((size_t)n + 1));
  vd_free(acc, 10 * sizeof(double) * ((size_t)n + 1));
  vd_free(comp, sizeof(double) * 3 * ((size_t)n + 1));
  if (st) flex_free(f, n, m->nmesh);
  return st;
}

// items of each xlink in a list: segments and plant meshes, grouped by xlink (the base last)
typedef struct members {
  int* seg_start; // (nlink + 2): the segments of xlink i are seg[seg_start[i] .. seg_start[i + 1])
  int* seg;       // (nseg)
  int* mesh_start; // (nlink + 2)
  int* mesh;      // (nmesh)
  int nlink, nseg, nmesh;
} members;

static void members_free(members* g) {
  vd_free(g->seg_start, sizeof(int) * ((size_t)g->nlink + 2));
  vd_free(g->seg, sizeof(int) * ((size_t)g->nseg + 1));
  vd_free(g->mesh_start, sizeof(int) * ((size_t)g->nlink + 2));
  vd_free(g->mesh, sizeof(int) * ((size_t)g->nmesh + 1));
}

static void group(const int* of, int n, int nl, int* start, int* item) {
  for (int i = 0; i <= nl + 1; i++)
    start[i] = 0;
  for (int i = 0; i < n; i++)
    start[(of[i] < 0 ? nl : of[i]) + 1]++;
  for (int i = 0; i <= nl; i++)
    start[i + 1] += start[i];
  for (int i = 0; i < n; i++)
    item[start[of[i] < 0 ? nl : of[i]]++] = i;
  for (int i = nl; i > 0; i--)
    start[i] = start[i - 1];
  start[0] = 0;
}

static vd_status members_make(members* g, const flex* f, int nmesh, vd_error* err) {
  g->nlink = f->nlink, g->nseg = f->r->nseg, g->nmesh = nmesh;
  g->seg_start = vd_malloc(sizeof(int) * ((size_t)g->nlink + 2));
  g->seg = vd_malloc(sizeof(int) * ((size_t)g->nseg + 1));
  g->mesh_start = vd_malloc(sizeof(int) * ((size_t)g->nlink + 2));
  g->mesh = vd_malloc(sizeof(int) * ((size_t)nmesh + 1));
  if (!g->seg_start || !g->seg || !g->mesh_start || !g->mesh) {
    members_free(g);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  group(f->seg_link, g->nseg, g->nlink, g->seg_start, g->seg);
  group(f->mesh_link, nmesh, g->nlink, g->mesh_start, g->mesh);
  return VD_OK;
}

// the frame origin of xlink li, -1 the base (the plant's origin) (m)
static vd_vec3 link_origin(const flex* f, int li) {
  return li >= 0 && f->lk ? f->lk[li].origin : vd_v3(0, 0, 0);
}

// a drawn rod segment's capsule: 0 when it has no shape
static int rod_shape(const vd_export_rods* r, int t, vd_vec3* a, vd_vec3* b, double* rad) {
  *a = rod_end(r, t, 0), *b = rod_end(r, t, 1), *rad = r->seg_radius[t];
  return r->seg_drawn[t] && vd_norm(vd_sub(*b, *a)) > 1e-9 && *rad > 0;
}

static double rod_sphere(const vd_export_rods* r, int t) {
  return r->seg_sphere && r->seg_sphere[t] > 0 ? r->seg_sphere[t] : 0;
}

// MJCF: the geoms of xlink li (-1 the base) in its frame
static void mjcf_flex_geoms(out* w, const plan* p, const flex* f, const members* g, int li) {
  FILE* fp = w->fp;
  const vd_export_rods* r = f->r;
  const vd_model* m = p->m;
  const char* pre = w->prefix;
  vd_vec3 o = link_origin(f, li);
  int gi = li < 0 ? g->nlink : li, ng = 0;
  const char* lname_link = li >= 0 ? f->lk[li].name : "base";
  for (int j = g->seg_start[gi]; j < g->seg_start[gi + 1]; j++) {
    int t = g->seg[j];
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, r->seg_label[t], lname, sizeof lname);
    vd_vec3 a, b;
    double rad;
    if (rod_shape(r, t, &a, &b, &rad)) {
      a = vd_sub(a, o), b = vd_sub(b, o);
      fprintf(fp, "<geom name=\"%s%s_%d\" material=\"%s%s\" contype=\"2\" conaffinity=\"1\" "
                  "type=\"capsule\" size=\"%.9g\" fromto=\"%.9g %.9g %.9g %.9g %.9g %.9g\"/>\n",
              pre, lname_link, ng++, pre, lname, rad, a.x, a.y, a.z, b.x, b.y, b.z);
    }
    double sr = rod_sphere(r, t);
    if (sr > 0) {
      vd_vec3 c = vd_sub(rod_end(r, t, 1), o);
      fprintf(fp, "<geom name=\"%s%s_%d\" material=\"%s%s\" contype=\"2\" conaffinity=\"1\" "
                  "type=\"sphere\" size=\"%.9g\" pos=\"%.9g %.9g %.9g\"/>\n",
              pre, lname_link, ng++, pre, lname, sr, c.x, c.y, c.z);
    }
  }
  for (int j = g->mesh_start[gi]; j < g->mesh_start[gi + 1]; j++) {
    int i = g->mesh[j];
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, m->mesh_label[i], lname, sizeof lname);
    fprintf(fp, "<geom name=\"%s%s_%d\" material=\"%s%s\" contype=\"2\" conaffinity=\"1\" "
                "type=\"mesh\" mesh=\"%smesh_%d\"/>\n",
            pre, lname_link, ng++, pre, lname, pre, i);
  }
}

// MJCF: body li with its inertial, joints, geoms and the bodies on it (depth-first)
static void mjcf_flex_body(out* w, const plan* p, const flex* f, const members* g, int li) {
  FILE* fp = w->fp;
  const xlink* l = &f->lk[li];
  const char* pre = w->prefix;
  vd_vec3 d = vd_sub(l->origin, link_origin(f, l->parent)), c = vd_sub(l->com, l->origin);
  fprintf(fp, "<body name=\"%s%s\" pos=\"%.9g %.9g %.9g\">\n", pre, l->name, d.x, d.y, d.z);
  fprintf(fp, "<inertial pos=\"%.9g %.9g %.9g\" mass=\"%.9g\" fullinertia=\"%.9g %.9g %.9g %.9g %.9g %.9g\"/>\n",
          c.x, c.y, c.z, l->mass, l->in[0], l->in[1], l->in[2], l->in[3], l->in[4], l->in[5]);
  static const char* jn[3] = {"jb1", "jb2", "jt"};
  for (int k = 0; k < 3 && w->def->links_per_organ >= 0; k++)
    fprintf(fp, "<joint name=\"%s%s_%s\" type=\"hinge\" pos=\"0 0 0\" axis=\"%.9g %.9g %.9g\" "
                "stiffness=\"%.9g\" damping=\"%.9g\" springref=\"0\"/>\n",
            pre, l->name, jn[k], l->axis[k].x, l->axis[k].y, l->axis[k].z, l->k[k], l->c[k]);
  mjcf_flex_geoms(w, p, f, g, li);
  for (int k = f->kid0[li]; k >= 0; k = f->next[k])
    mjcf_flex_body(w, p, f, g, k);
  fprintf(fp, "</body>\n");
}

static vd_status write_mjcf_flex(out* w, const plan* p, const flex* f, vd_error* err) {
  FILE* fp = w->fp;
  const vd_model* m = p->m;
  const vd_export_def* d = w->def;
  const vd_export_rods* r = f->r;
  const char* pre = w->prefix;
  members g;
  vd_status st = members_make(&g, f, m->nmesh, err);
  if (st) return st;
  fprintf(fp, "<!-- verdant export, format version %d: a %s plant for MuJoCo from its rods, one body "
              "per %s (%slabel_instance_k), three hinge springs per joint (bend d1, bend d2, "
              "twist: EI/l, GJ/l of the rods), masses and inertias of the rods; plant geoms "
              "contype 2, conaffinity 1 (they touch everything of contype 1, not each other); "
              "units m, kg, N m/rad; include it beside a robot: <include file=\"...\"/> -->\n",
          VD_EXPORT_FORMAT_VERSION, d->links_per_organ >= 0 ? "flexible" : "rigid",
          d->links_per_organ >= 0 ? "link" : "organ", pre);
  fprintf(fp, "<mujoco model=\"%s\">\n  <asset>\n", d->name);
  mjcf_materials(fp, m, pre);
  // the meshes in the frame of the body they ride on
  for (int i = 0; !st && i < m->nmesh; i++) {
    tmesh s;
    if ((st = mesh_shape(p, i, d->leaf_thickness, &s, err))) break;
    vd_vec3 o = link_origin(f, f->mesh_link[i]);
    char name[128];
    snprintf(name, sizeof name, "%smesh_%d", pre, i);
    mjcf_mesh(fp, name, &s, o);
    tmesh_free(&s);
  }
  fprintf(fp, "  </asset>\n");
  // break thresholds of the joints that can break: (force N, moment N m) per link
  int nbrk = 0;
  for (int i = 0; r->seg_break && i < f->nlink; i++) {
    const double* b = r->seg_break + 2 * f->lk[i].root;
    if (!isfinite(b[0]) && !isfinite(b[1])) continue;
    if (!nbrk++) fprintf(fp, "  <custom>\n");
    fprintf(fp, "    <numeric name=\"%sbreak/%s\" size=\"2\" data=\"%.9g %.9g\"/>\n", pre,
            f->lk[i].name, isfinite(b[0]) ? b[0] : -1.0, isfinite(b[1]) ? b[1] : -1.0);
  }
  if (nbrk) fprintf(fp, "  </custom>\n");
  fprintf(fp, "  <worldbody>\n<body name=\"%s\" pos=\"%.9g %.9g %.9g\">\n", d->name, d->pos.x,
          d->pos.y, d->pos.z);
  // the base (held rods) as a body of its own, so that every plant geom has a prefixed body
  fprintf(fp, "<body name=\"%sbase\">\n", pre);
  if (!st) {
    mjcf_flex_geoms(w, p, f, &g, -1);
    for (int k = f->kid0[f->nlink]; k >= 0; k = f->next[k])
      mjcf_flex_body(w, p, f, &g, k);
  }
  fprintf(fp, "</body>\n</body>\n  </worldbody>\n</mujoco>\n");
  members_free(&g);
  return st;
}

// URDF and SDF: the OBJ file of each plant mesh, as the static export names them
static vd_status mesh_files(const plan* p, prim_ref* pr, int cap, int** org, int** k, vd_error* err) {
  const vd_model* m = p->m;
  *org = vd_malloc(sizeof(int) * ((size_t)m->nmesh + 1));
  *k = vd_malloc(sizeof(int) * ((size_t)m->nmesh + 1));
  if (!*org || !*k) {
    vd_free(*org, sizeof(int) * ((size_t)m->nmesh + 1));
    vd_free(*k, sizeof(int) * ((size_t)m->nmesh + 1));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  for (int o = 0; o < p->norg; o++) {
    int n = organ_prims(p, o, pr, cap), kmesh = 0;
    for (int j = 0; j < n && j < cap; j++)
      if (pr[j].kind == 2) (*org)[pr[j].i] = o, (*k)[pr[j].i] = kmesh++;
  }
  return VD_OK;
}

// URDF <inertial> or SDF <inertial> of a link: mass at com (relative to its frame at o)
static void inertial_xml(FILE* fp, int sdf, double mass, vd_vec3 c, const double* in, const char* ind) {
  if (sdf)
    fprintf(fp, "%s<inertial><pose>%.9g %.9g %.9g 0 0 0</pose><mass>%.9g</mass><inertia><ixx>%.9g</ixx>"
                "<iyy>%.9g</iyy><izz>%.9g</izz><ixy>%.9g</ixy><ixz>%.9g</ixz><iyz>%.9g</iyz></inertia></inertial>\n",
            ind, c.x, c.y, c.z, mass, in[0], in[1], in[2], in[3], in[4], in[5]);
  else
    fprintf(fp, "%s<inertial><origin xyz=\"%.9g %.9g %.9g\" rpy=\"0 0 0\"/><mass value=\"%.9g\"/>"
                "<inertia ixx=\"%.9g\" iyy=\"%.9g\" izz=\"%.9g\" ixy=\"%.9g\" ixz=\"%.9g\" iyz=\"%.9g\"/></inertial>\n",
            ind, c.x, c.y, c.z, mass, in[0], in[1], in[2], in[3], in[4], in[5]);
}

// URDF/SDF: the visuals and collisions of xlink li (-1 the base) in its frame
static void xml_flex_shapes(out* w, const plan* p, const flex* f, const members* g, int li,
                            const char* dir_rel, const int* morg, const int* mk) {
  FILE* fp = w->fp;
  int sdf = w->def->format == VD_EXPORT_SDF;
  const vd_export_rods* r = f->r;
  const vd_model* m = p->m;
  vd_vec3 o = link_origin(f, li);
  int gi = li < 0 ? g->nlink : li, ns = 0;
  char base[VD_LABEL_NAME_MAX + 48];
  snprintf(base, sizeof base, "%s_base", w->def->name);
  const char* ln = li >= 0 ? f->lk[li].name : base;
  const char* ind = sdf ? "        " : "      ";
  int nseg = g->seg_start[gi + 1] - g->seg_start[gi], nmesh = g->mesh_start[gi + 1] - g->mesh_start[gi];
  for (int j = 0; j < 2 * nseg + nmesh; j++) {
    int is_mesh = j >= 2 * nseg, t = -1, i = -1, label;
    double xyz[3] = {0, 0, 0}, rpy[3] = {0, 0, 0}, rad = 0, len = 0;
    if (is_mesh) {
      i = g->mesh[g->mesh_start[gi] + j - 2 * nseg];
      label = m->mesh_label[i];
      xyz[0] = -o.x, xyz[1] = -o.y, xyz[2] = -o.z;
    } else {
      t = g->seg[g->seg_start[gi] + j / 2];
      label = r->seg_label[t];
      vd_vec3 a, b;
      if (j % 2 == 0) { // the capsule, as a cylinder
        if (!rod_shape(r, t, &a, &b, &rad)) continue;
        axis_pose(vd_sub(a, o), vd_sub(b, o), xyz, rpy);
        len = vd_norm(vd_sub(b, a));
      } else { // the sphere at its end
        if (!(rad = rod_sphere(r, t))) continue;
        vd_vec3 c = vd_sub(rod_end(r, t, 1), o);
        xyz[0] = c.x, xyz[1] = c.y, xyz[2] = c.z;
      }
    }
    char lname[VD_LABEL_NAME_MAX + 16];
    geom_obj_name(m->labels, m->nlabel, label, lname, sizeof lname);
    float rgb[3];
    label_rgb(m, label, rgb);
    char uri[4400] = "";
    if (is_mesh) snprintf(uri, sizeof uri, "%s/%s_m%d.obj", dir_rel, p->org[morg[i]].name, mk[i]);
    for (int role = 0; role < 2; role++) {
      const char* el = role ? "collision" : "visual";
      fprintf(fp, "%s<%s name=\"%s_%s%d\">\n", sdf ? "      " : "    ", el, ln, role ? "c" : "v", ns);
      if (sdf)
        fprintf(fp, "%s<pose>%.9g %.9g %.9g %.9g %.9g %.9g</pose>\n", ind, xyz[0], xyz[1], xyz[2],
                rpy[0], rpy[1], rpy[2]);
      else
        fprintf(fp, "%s<origin xyz=\"%.9g %.9g %.9g\" rpy=\"%.9g %.9g %.9g\"/>\n", ind, xyz[0], xyz[1],
                xyz[2], rpy[0], rpy[1], rpy[2]);
      if (is_mesh && sdf)
        fprintf(fp, "%s<geometry><mesh><uri>%s</uri></mesh></geometry>\n", ind, uri);
      else if (is_mesh)
        fprintf(fp, "%s<geometry><mesh filename=\"%s\"/></geometry>\n", ind, uri);
      else if (len > 0 && sdf)
        fprintf(fp, "%s<geometry><cylinder><radius>%.9g</radius><length>%.9g</length></cylinder></geometry>\n",
                ind, rad, len);
      else if (len > 0)
        fprintf(fp, "%s<geometry><cylinder radius=\"%.9g\" length=\"%.9g\"/></geometry>\n", ind, rad, len);
      else if (sdf)
        fprintf(fp, "%s<geometry><sphere><radius>%.9g</radius></sphere></geometry>\n", ind, rad);
      else
        fprintf(fp, "%s<geometry><sphere radius=\"%.9g\"/></geometry>\n", ind, rad);
      if (!role && sdf)
        fprintf(fp, "%s<material><diffuse>%.4g %.4g %.4g 1</diffuse><ambient>%.4g %.4g %.4g 1</ambient></material>\n",
                ind, rgb[0], rgb[1], rgb[2], rgb[0], rgb[1], rgb[2]);
      if (!role && !sdf) fprintf(fp, "%s<material name=\"%s\"/>\n", ind, lname);
      fprintf(fp, "%s</%s>\n", sdf ? "      " : "    ", el);
    }
    ns++;
  }
}

#define XML_MIN_MASS 1.5e-6 // least mass of a URDF/SDF link (kg)

// URDF/SDF: one link; in a flexible export also its two helper links for the bending hinges
static void xml_flex_links(out* w, const plan* p, const flex* f, const members* g, int li,
                           const char* dir_rel, const int* morg, const int* mk) {
  FILE* fp = w->fp;
  int sdf = w->def->format == VD_EXPORT_SDF, flexible = w->def->links_per_organ >= 0;
  const xlink* l = li >= 0 ? &f->lk[li] : NULL;
  char base[VD_LABEL_NAME_MAX + 48];
  snprintf(base, sizeof base, "%s_base", w->def->name);
  const char* ln = l ? l->name : base;
  vd_vec3 o = link_origin(f, li);
  const char* ind = sdf ? "      " : "    ";
  // the helper links: a thousandth of the link's mass and inertia, at the joint point, taken
  // from the link (the total stays the rods'); every mass at least XML_MIN_MASS, since sdformat
  // reads a URDF link under 1e-6 kg as massless and drops it with everything hanging from it
  double hm = l ? fmax(1e-3 * l->mass, XML_MIN_MASS) : 0;
  for (int k = 0; l && flexible && k < 2; k++) {
    double tr = 1e-3 * (l->in[0] + l->in[1] + l->in[2]) / 3;
    double hin[6] = {tr, tr, tr, 0, 0, 0};
    fprintf(fp, "  %s<link name=\"%s_b%d\">\n", sdf ? "  " : "", ln, k + 1);
    if (sdf) fprintf(fp, "%s<pose>%.9g %.9g %.9g 0 0 0</pose>\n", ind, o.x, o.y, o.z);
    inertial_xml(fp, sdf, hm, vd_v3(0, 0, 0), hin, ind);
    fprintf(fp, "  %s</link>\n", sdf ? "  " : "");
  }
  fprintf(fp, "  %s<link name=\"%s\">\n", sdf ? "  " : "", ln);
  if (sdf) fprintf(fp, "%s<pose>%.9g %.9g %.9g 0 0 0</pose>\n", ind, o.x, o.y, o.z);
  if (l) {
    double lm = flexible ? fmax(l->mass - 2 * hm, XML_MIN_MASS) : fmax(l->mass, XML_MIN_MASS);
    inertial_xml(fp, sdf, lm, vd_sub(l->com, l->origin), l->in, ind);
  } else {
    static const double bin[6] = {1e-6, 1e-6, 1e-6, 0, 0, 0};
    inertial_xml(fp, sdf, 1e-3, vd_v3(0, 0, 0), bin, ind);
  }
  xml_flex_shapes(w, p, f, g, li, dir_rel, morg, mk);
  fprintf(fp, "  %s</link>\n", sdf ? "  " : "");
}

// URDF/SDF: the joints of xlink li to its parent
static void xml_flex_joints(out* w, const flex* f, int li) {
  FILE* fp = w->fp;
  int sdf = w->def->format == VD_EXPORT_SDF, flexible = w->def->links_per_organ >= 0;
  const xlink* l = &f->lk[li];
  char par[VD_LABEL_NAME_MAX + 48];
  if (l->parent >= 0)
    snprintf(par, sizeof par, "%s", f->lk[l->parent].name);
  else
    snprintf(par, sizeof par, "%s_base", w->def->name);
  vd_vec3 d = vd_sub(l->origin, link_origin(f, l->parent));
  const double* brk = f->r->seg_break ? f->r->seg_break + 2 * l->root : NULL;
  double bf = brk && isfinite(brk[0]) ? brk[0] : -1, bm = brk && isfinite(brk[1]) ? brk[1] : -1;
  static const char* jn[3] = {"jb1", "jb2", "jt"};
  for (int k = 0; k < (flexible ? 3 : 1); k++) {
    char from[VD_LABEL_NAME_MAX + 52], to[VD_LABEL_NAME_MAX + 52], name[VD_LABEL_NAME_MAX + 52];
    snprintf(from, sizeof from, k == 0 ? "%s" : "%s_b%d", k == 0 ? par : l->name, k);
    snprintf(to, sizeof to, !flexible || k == 2 ? "%s" : "%s_b%d", l->name, k + 1);
    snprintf(name, sizeof name, flexible ? "%s_%s" : "%s_joint", l->name, jn[k]);
    vd_vec3 a = l->axis[k];
    if (sdf) {
      fprintf(fp, "    <joint name=\"%s\" type=\"%s\">\n      <parent>%s</parent><child>%s</child>\n",
              name, flexible ? "revolute" : "fixed", from, to);
      if (flexible)
        fprintf(fp, "      <axis><xyz>%.9g %.9g %.9g</xyz><limit><lower>-1e16</lower><upper>1e16</upper></limit>"
                    "<dynamics><damping>%.9g</damping><friction>0</friction><spring_reference>0</spring_reference>"
                    "<spring_stiffness>%.9g</spring_stiffness></dynamics></axis>\n",
                a.x, a.y, a.z, l->c[k], l->k[k]);
      if (k == 0 && (bf >= 0 || bm >= 0))
        fprintf(fp, "      <verdant:break_force>%.9g</verdant:break_force><verdant:break_moment>%.9g</verdant:break_moment>\n",
                bf, bm);
      fprintf(fp, "    </joint>\n");
    } else {
      fprintf(fp, "  <joint name=\"%s\" type=\"%s\"", name, flexible ? "continuous" : "fixed");
      if (k == 0 && (bf >= 0 || bm >= 0))
        fprintf(fp, " verdant_break_force=\"%.9g\" verdant_break_moment=\"%.9g\"", bf, bm);
      fprintf(fp, "><parent link=\"%s\"/><child link=\"%s\"/><origin xyz=\"%.9g %.9g %.9g\" rpy=\"0 0 0\"/>",
              from, to, k == 0 ? d.x : 0.0, k == 0 ? d.y : 0.0, k == 0 ? d.z : 0.0);
      if (flexible)
        fprintf(fp, "<axis xyz=\"%.9g %.9g %.9g\"/><dynamics damping=\"%.9g\" friction=\"0\"/>", a.x, a.y,
                a.z, l->c[k]);
      fprintf(fp, "</joint>\n");
      if (flexible)
        fprintf(fp, "  <gazebo reference=\"%s\"><springStiffness>%.9g</springStiffness>"
                    "<springReference>0</springReference></gazebo>\n", name, l->k[k]);
      else
        fprintf(fp, "  <gazebo reference=\"%s\"><preserveFixedJoint>true</preserveFixedJoint></gazebo>\n", name);
    }
  }
}

static vd_status write_xml_flex(out* w, const plan* p, const flex* f, const char* dir_rel,
                                prim_ref* pr, int cap, vd_error* err) {
  FILE* fp = w->fp;
  const vd_model* m = p->m;
  const vd_export_def* d = w->def;
  int sdf = d->format == VD_EXPORT_SDF;
  members g;
  vd_status st = members_make(&g, f, m->nmesh, err);
  if (st) return st;
  int *morg = NULL, *mk = NULL;
  if ((st = mesh_files(p, pr, cap, &morg, &mk, err))) {
    members_free(&g);
    return st;
  }
  const char* kind = d->links_per_organ >= 0 ? "flexible" : "rigid";
  fprintf(fp, "<?xml version=\"1.0\"?>\n");
  fprintf(fp, "<!-- verdant export, format version %d: a %s plant from its rods, one link per %s "
              "(label_instance_k)%s, masses and inertias of the rods, units m, kg, N m/rad -->\n",
          VD_EXPORT_FORMAT_VERSION, kind, d->links_per_organ >= 0 ? "link" : "organ",
          d->links_per_organ >= 0 ? ", three revolute springs per joint (bend d1, bend d2, twist: "
                                    "EI/l, GJ/l of the rods) through two helper links" : "");
  if (sdf) {
    fprintf(fp, "<sdf version=\"1.7\" xmlns:verdant=\"urn:verdant\">\n  <model name=\"%s\">\n", d->name);
    fprintf(fp, "    <pose>%.9g %.9g %.9g 0 0 0</pose>\n", d->pos.x, d->pos.y, d->pos.z);
  } else {
    fprintf(fp, "<robot name=\"%s\">\n", d->name);
    for (int i = 0; i < m->nlabel; i++) {
      char lname[VD_LABEL_NAME_MAX + 16];
      geom_obj_name(m->labels, m->nlabel, m->labels[i].id, lname, sizeof lname);
      fprintf(fp, "  <material name=\"%s\"><color rgba=\"%.4g %.4g %.4g 1\"/></material>\n", lname,
              m->labels[i].rgb[0], m->labels[i].rgb[1], m->labels[i].rgb[2]);
    }
    fprintf(fp, "  <link name=\"world\"/>\n");
  }
  xml_flex_links(w, p, f, &g, -1, dir_rel, morg, mk);
  for (int i = 0; i < f->nlink; i++)
    xml_flex_links(w, p, f, &g, i, dir_rel, morg, mk);
  // the base held in the world
  if (sdf)
    fprintf(fp, "    <joint name=\"%s_fixed\" type=\"fixed\"><parent>world</parent><child>%s_base</child></joint>\n",
            d->name, d->name);
  else
    fprintf(fp, "  <joint name=\"%s_fixed\" type=\"fixed\"><parent link=\"world\"/><child link=\"%s_base\"/>"
                "<origin xyz=\"%.9g %.9g %.9g\" rpy=\"0 0 0\"/></joint>\n",
            d->name, d->name, d->pos.x, d->pos.y, d->pos.z);
  for (int i = 0; i < f->nlink; i++)
    xml_flex_joints(w, f, i);
  fprintf(fp, sdf ? "  </model>\n</sdf>\n" : "</robot>\n");
  vd_free(morg, sizeof(int) * ((size_t)m->nmesh + 1));
  vd_free(mk, sizeof(int) * ((size_t)m->nmesh + 1));
  members_free(&g);
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
  if (ed.rods && (ed.rods->nseg < 0 || (ed.rods->nseg > 0 && (!ed.rods->seg_ends || !ed.rods->seg_radius ||
                   !ed.rods->seg_quat || !ed.rods->seg_parent || !ed.rods->seg_fixed ||
                   !ed.rods->seg_drawn || !ed.rods->seg_label || !ed.rods->seg_instance ||
                   !ed.rods->seg_stiff || !ed.rods->seg_mass || !ed.rods->seg_inertia))))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "the rods lack an array");
  if (ed.links_per_organ < -1)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "links per organ must be -1, 0 or more");
  if (!(ed.damping_ratio >= 0 && isfinite(ed.damping_ratio)))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "the damping ratio must be finite and >= 0");
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
      flex fx;
      if (ed.rods && !(st = flex_make(&fx, m, &ed, err))) {
        st = ed.format == VD_EXPORT_MJCF ? write_mjcf_flex(&w, &p, &fx, err)
                                         : write_xml_flex(&w, &p, &fx, rel, pr, cap, err);
        flex_free(&fx, ed.rods->nseg, m->nmesh);
      } else if (!ed.rods) {
        st = ed.format == VD_EXPORT_URDF  ? write_urdf(&w, &p, rel, pr, cap)
             : ed.format == VD_EXPORT_SDF ? write_sdf(&w, &p, rel, pr, cap)
                                          : write_mjcf(&w, &p, pr, cap, err);
      }
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
