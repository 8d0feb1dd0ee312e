// SPDX-License-Identifier: MIT
// Tessellation of a compiled plant: frustums (rings at both ends, caps, rings shared along a
// generalised cylinder), UV spheres and copied meshes, into one labelled triangle mesh.
#include <limits.h>
#include <math.h>
#include <string.h>

#include "geom_internal.h"

vd_mesh_def vd_mesh_def_default(void) {
  vd_mesh_def def;
  memset(&def, 0, sizeof def);
  def.slices = 0;
  def.sphere_stacks = 0;
  def.caps = 1;
  return def;
}

// ---------------------------------------------------------------------------------------------
// the plan: per-segment ring sharing and vertex offsets, computed before any output

typedef struct plan {
  const vd_model* m;
  const double* node_pos;   // (nnode x 3)
  const double* seg_quat;   // (nseg x 4)
  const double* sphere_pos; // (nsphere x 3)
  const double* vert_pos;   // (nvert x 3)
  const vd_data* d;         // the state, or NULL for the rest shape
  vd_mesh_def def;
  int* cont;   // segment continuing this one through a shared ring, or -1 (nseg)
  int* joined; // 1 when the start ring is the parent's end ring (nseg)
  int* vbase;  // first vertex of each segment (nseg)
  int64_t nvert, ntri;
  int sphere_vbase, mesh_vbase; // first vertex of the spheres and of the meshes
} plan;

static int seg_slices(const plan* p, int i) { return geom_seg_slices(p->m, p->def.slices, i); }
static int sphere_slices(const plan* p, int i) {
  return p->def.slices > 0 ? p->def.slices : p->m->sphere_slices[i];
}
static int sphere_stacks(const plan* p, int i) {
  if (p->def.sphere_stacks > 0) return p->def.sphere_stacks;
  int st = sphere_slices(p, i) / 2;
  return st < 2 ? 2 : st;
}

// a child continues its parent when both are generalised-cylinder segments meeting at a node with
// the same section, the child is not broken off (seg_broken severs a segment from its parent),
// and no earlier child continues the parent already
int geom_seg_cut(const vd_data* d, int i, double* f) {
  *f = 0;
  if (!d || !d->seg_broken[i] || !(d->seg_cut[7 * i] >= 0)) return GEOM_WHOLE;
  double x = d->seg_cut[7 * i] > 1 ? 1 : d->seg_cut[7 * i];
  *f = x;
  // a break within 1e-9 of an end leaves no part on that side
  return (x < 1 - 1e-9 ? GEOM_PART_OFF : 0) | (x > 1e-9 ? GEOM_PART_STUB : 0);
}

void geom_joints(const vd_model* m, const vd_data* d, int slices, int* cont, int* joined) {
  for (int i = 0; i < m->nseg; i++)
    cont[i] = -1, joined[i] = 0;
  for (int i = 0; i < m->nseg; i++) {
    int q = m->seg_parent[i];
    double f;
    if (q < 0 || !(m->seg_flags[i] & VD_SEG_GC) || !(m->seg_flags[q] & VD_SEG_GC)) continue;
    if (m->seg_node[2 * i] != m->seg_node[2 * q + 1]) continue;
    if (geom_seg_slices(m, slices, i) != geom_seg_slices(m, slices, q) || cont[q] >= 0) continue;
    if (d && (d->seg_broken[i] || geom_seg_cut(d, q, &f) != GEOM_WHOLE)) continue;
    cont[q] = i;
    joined[i] = 1;
  }
}

static void plan_joints(plan* p) { geom_joints(p->m, p->d, p->def.slices, p->cont, p->joined); }

// vertex and triangle counts of every primitive, in output order
static void plan_counts(plan* p) {
  const vd_model* m = p->m;
  int64_t nv = 0, nt = 0;
  int caps = p->def.caps != 0;
  for (int i = 0; i < m->nseg; i++) {
    int64_t s = seg_slices(p, i);
    p->vbase[i] = nv > INT_MAX ? INT_MAX : (int)nv;
    double f;
    int parts = geom_seg_cut(p->d, i, &f);
    if (parts != GEOM_WHOLE) {
      // a broken segment: each part a closed frustum of its own
      int np = (parts & GEOM_PART_OFF ? 1 : 0) + (parts & GEOM_PART_STUB ? 1 : 0);
      nv += np * (2 * s + caps * 2 * (s + 1));
      nt += np * (2 * s + caps * 2 * s);
      continue;
    }
    int start_cap = caps && !p->joined[i], end_cap = caps && p->cont[i] < 0;
    nv += (p->joined[i] ? 0 : s) + s + (start_cap + end_cap) * (s + 1);
    nt += 2 * s + (start_cap + end_cap) * s;
  }
  p->sphere_vbase = nv > INT_MAX ? INT_MAX : (int)nv;
  for (int i = 0; i < m->nsphere; i++) {
    int64_t s = sphere_slices(p, i), st = sphere_stacks(p, i);
    nv += 2 + (st - 1) * s;
    nt += 2 * s * (st - 1);
  }
  p->mesh_vbase = nv > INT_MAX ? INT_MAX : (int)nv;
  for (int i = 0; i < m->nmesh; i++)
    nv += m->mesh_vert[2 * i + 1], nt += m->mesh_tri[2 * i + 1];
  p->nvert = nv;
  p->ntri = nt;
}

// check arguments and build the plan; scratch is freed by plan_free
static vd_status plan_make(plan* p, const vd_model* m, const vd_data* d, const vd_mesh_def* def,
                           vd_error* err) {
  memset(p, 0, sizeof *p);
  if (!m) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "tessellate: null model");
  p->m = m;
  p->def = def ? *def : vd_mesh_def_default();
  if (p->def.slices != 0 && p->def.slices < 3)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "mesh def: slices must be 0 or >= 3");
  if (p->def.sphere_stacks != 0 && p->def.sphere_stacks < 2)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "mesh def: sphere_stacks must be 0 or >= 2");
  if (d && (d->nnode != m->nnode || d->nseg != m->nseg || d->nsphere != m->nsphere ||
            d->nvert != m->nvert))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "tessellate: data does not match the model");
  // current state, or the rest shape without one
  p->node_pos = d ? d->node_pos : m->node_pos0;
  p->seg_quat = d ? d->seg_quat : m->seg_quat0;
  p->sphere_pos = d ? d->sphere_pos : m->sphere_pos0;
  p->vert_pos = d ? d->vert_pos : m->vert_pos0;
  p->d = d;
  if (m->nseg > 0) {
    p->cont = vd_malloc((size_t)m->nseg * 3 * sizeof(int));
    if (!p->cont) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory tessellating");
    p->joined = p->cont + m->nseg;
    p->vbase = p->joined + m->nseg;
  }
  plan_joints(p);
  plan_counts(p);
  // every index and the (ntri x 3) array must fit an int
  if (p->nvert > INT_MAX / 3 || p->ntri > INT_MAX / 3)
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                        "mesh too large: %lld vertices, %lld triangles", (long long)p->nvert,
                        (long long)p->ntri);
  return VD_OK;
}

static void plan_free(plan* p) {
  if (p->cont) vd_free(p->cont, (size_t)p->m->nseg * 3 * sizeof(int));
  p->cont = NULL;
}

vd_status vd_geom_count(const vd_model* m, const vd_data* d, const vd_mesh_def* def, int* nvert,
                        int* ntri, vd_error* err) {
  plan p;
  vd_status st = plan_make(&p, m, d, def, err);
  if (!st) {
    if (nvert) *nvert = (int)p.nvert;
    if (ntri) *ntri = (int)p.ntri;
  }
  plan_free(&p);
  return st;
}

// ---------------------------------------------------------------------------------------------
// output helpers

typedef struct out {
  vd_mesh* mesh;
  int nt; // triangles written so far
} out;

static vd_vec3 get3(const double* a, int i) {
  return vd_v3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);  // NOLINT(clang-analyzer-core.NullDereference): arrays sized by the counts vd_geom_count gave
}
static vd_quat getq(const double* a, int i) {
  vd_quat q = {a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]};
  return q;
}

static void put_vert(vd_mesh* mesh, int v, vd_vec3 p) {
  mesh->pos[3 * v] = p.x, mesh->pos[3 * v + 1] = p.y, mesh->pos[3 * v + 2] = p.z;
}
// normals are accumulated, then normalised once at the end
static void add_normal(vd_mesh* mesh, int v, vd_vec3 n) {
  mesh->normal[3 * v] += n.x, mesh->normal[3 * v + 1] += n.y, mesh->normal[3 * v + 2] += n.z;
}

static void put_tri(out* o, int a, int b, int c, int label, int instance, int prim,
                    vd_prim_kind kind) {
  vd_mesh* mesh = o->mesh;
  int t = o->nt++;
  mesh->tri[3 * t] = a, mesh->tri[3 * t + 1] = b, mesh->tri[3 * t + 2] = c;
  mesh->tri_label[t] = label;
  mesh->tri_instance[t] = instance;
  mesh->tri_prim[t] = prim;
  mesh->tri_kind[t] = (int)kind;
}

// ---------------------------------------------------------------------------------------------
// frustums

// halfway frame between a and b (normalised sum, taking the shorter way)
static vd_quat quat_mid(vd_quat a, vd_quat b) {
  double dot = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  double s = dot < 0 ? -1 : 1;
  vd_quat q = {a.w + s * b.w, a.x + s * b.x, a.y + s * b.y, a.z + s * b.z};
  return vd_quat_normalize(q);
}

// ring k of n at angle 2 pi k / n: x axis of the frame is angle 0
static vd_vec3 ring_dir(vd_quat q, int k, int n) {
  double a = 2.0 * VD_PI * (double)k / (double)n;
  return vd_quat_rotate(q, vd_v3(cos(a), sin(a), 0));
}

// write the ring of n vertices at v0: centre c, radius r, frame q
static void put_ring(vd_mesh* mesh, int v0, vd_vec3 c, double r, vd_quat q, int n) {
  for (int k = 0; k < n; k++)
    put_vert(mesh, v0 + k, vd_madd(c, ring_dir(q, k, n), r));
}

// side normal of a frustum at ring direction u: radial, tilted by the taper (r0 - r1) / len
static vd_vec3 side_normal(vd_vec3 u, vd_vec3 axis, double len, double r0, double r1) {
  if (!(len > 0)) return u;
  return vd_normalize(vd_add(vd_scale(u, len), vd_scale(axis, r0 - r1)));
}

// a flat cap: centre vertex at vc, ring copied from the side ring at ring0, fan facing normal n
static void put_cap(out* o, int vc, int ring0, int n, vd_vec3 c, vd_vec3 normal, int outward_ccw,
                    int label, int inst, int prim) {
  vd_mesh* mesh = o->mesh;
  put_vert(mesh, vc, c);
  add_normal(mesh, vc, normal);
  for (int k = 0; k < n; k++) {
    memcpy(mesh->pos + 3 * (vc + 1 + k), mesh->pos + 3 * (ring0 + k), 3 * sizeof(double));
    add_normal(mesh, vc + 1 + k, normal);
  }
  // end cap: (c, k, k+1) faces +z; start cap: (c, k+1, k) faces -z
  for (int k = 0; k < n; k++) {
    int a = vc + 1 + k, b = vc + 1 + (k + 1) % n;
    if (outward_ccw)
      put_tri(o, vc, a, b, label, inst, prim, VD_PRIM_SEGMENT);
    else
      put_tri(o, vc, b, a, label, inst, prim, VD_PRIM_SEGMENT);
  }
}

// a closed frustum of segment i on its own (a part of a broken segment): two rings from vertex v,
// then the caps; returns the next free vertex
static int tess_part(const plan* p, out* o, int i, int v, vd_vec3 c0, vd_vec3 c1, double r0, double r1) {
  const vd_model* m = p->m;
  vd_mesh* mesh = o->mesh;
  int n = seg_slices(p, i), label = m->seg_label[i], inst = m->seg_instance[i];
  vd_quat q = getq(p->seg_quat, i);
  vd_vec3 axis = vd_quat_rotate(q, vd_v3(0, 0, 1));
  double len = vd_norm(vd_sub(c1, c0));
  int start = v, end = v + n;
  put_ring(mesh, start, c0, r0, q, n);
  put_ring(mesh, end, c1, r1, q, n);
  for (int k = 0; k < n; k++) {
    add_normal(mesh, start + k, side_normal(ring_dir(q, k, n), axis, len, r0, r1));
    add_normal(mesh, end + k, side_normal(ring_dir(q, k, n), axis, len, r0, r1));
  }
  for (int k = 0; k < n; k++) {
    int a0 = start + k, b0 = start + (k + 1) % n, a1 = end + k, b1 = end + (k + 1) % n;
    put_tri(o, a0, b0, b1, label, inst, i, VD_PRIM_SEGMENT);
    put_tri(o, a0, b1, a1, label, inst, i, VD_PRIM_SEGMENT);
  }
  v += 2 * n;
  if (p->def.caps) {
    put_cap(o, v, start, n, c0, vd_scale(axis, -1), 0, label, inst, i);
    put_cap(o, v + n + 1, end, n, c1, axis, 1, label, inst, i);
    v += 2 * (n + 1);
  }
  return v;
}

static void tess_segment(const plan* p, out* o, int i) {
  const vd_model* m = p->m;
  vd_mesh* mesh = o->mesh;
  int n = seg_slices(p, i), caps = p->def.caps != 0;
  int label = m->seg_label[i], inst = m->seg_instance[i];
  int n0 = m->seg_node[2 * i], n1 = m->seg_node[2 * i + 1];
  vd_vec3 c0 = get3(p->node_pos, n0), c1 = get3(p->node_pos, n1);
  double r0 = m->seg_radius[2 * i], r1 = m->seg_radius[2 * i + 1];
  double f;
  int parts = geom_seg_cut(p->d, i, &f);
  if (parts != GEOM_WHOLE) {
    // broken at a known point: the part that came off (B -> node1), then the stump (node0 -> A)
    const double* cut = p->d->seg_cut + 7 * i;
    double rf = r0 + f * (r1 - r0);
    int v = p->vbase[i];  // NOLINT(clang-analyzer-core.NullDereference): arrays sized by the counts vd_geom_count gave
    if (parts & GEOM_PART_OFF) v = tess_part(p, o, i, v, vd_v3(cut[4], cut[5], cut[6]), c1, rf, r1);
    if (parts & GEOM_PART_STUB) tess_part(p, o, i, v, c0, vd_v3(cut[1], cut[2], cut[3]), r0, rf);
    return;
  }
  vd_quat q = getq(p->seg_quat, i);
  vd_vec3 axis = vd_quat_rotate(q, vd_v3(0, 0, 1));
  double len = vd_norm(vd_sub(c1, c0));

  // start ring: the parent's end ring when joined, else our own
  int v = p->vbase[i], start, end;  // NOLINT(clang-analyzer-core.NullDereference): arrays sized by the counts vd_geom_count gave
  vd_quat q0 = q, q1 = q;
  if (p->joined[i]) {
    int par = m->seg_parent[i];
    start = p->vbase[par] + (p->joined[par] ? 0 : seg_slices(p, par));
    q0 = quat_mid(getq(p->seg_quat, par), q);
    r0 = m->seg_radius[2 * par + 1];
  } else {
    start = v;
    v += n;
    put_ring(mesh, start, c0, r0, q, n);
  }
  // end ring: ours, in the halfway frame when a child continues the tube
  end = v;
  v += n;
  if (p->cont[i] >= 0) q1 = quat_mid(q, getq(p->seg_quat, p->cont[i]));
  put_ring(mesh, end, c1, r1, q1, n);

  // side: each ring vertex gets this frustum's normal (joint rings get both, averaged)
  for (int k = 0; k < n; k++) {
    add_normal(mesh, start + k, side_normal(ring_dir(q0, k, n), axis, len, r0, r1));
    add_normal(mesh, end + k, side_normal(ring_dir(q1, k, n), axis, len, r0, r1));
  }
  for (int k = 0; k < n; k++) {
    int a0 = start + k, b0 = start + (k + 1) % n, a1 = end + k, b1 = end + (k + 1) % n;
    put_tri(o, a0, b0, b1, label, inst, i, VD_PRIM_SEGMENT);
    put_tri(o, a0, b1, a1, label, inst, i, VD_PRIM_SEGMENT);
  }
  // caps on the ends that are not joints, with separate vertices for sharp normals
  if (caps && !p->joined[i]) {
    put_cap(o, v, start, n, c0, vd_scale(axis, -1), 0, label, inst, i);
    v += n + 1;
  }
  if (caps && p->cont[i] < 0) put_cap(o, v, end, n, c1, axis, 1, label, inst, i);
}

// ---------------------------------------------------------------------------------------------
// spheres and meshes

// UV sphere: top pole, stacks-1 rings from top to bottom, bottom pole; axes are the world's
static void tess_sphere(const plan* p, out* o, int i, int v0) {
  const vd_model* m = p->m;
  vd_mesh* mesh = o->mesh;
  int n = sphere_slices(p, i), st = sphere_stacks(p, i);
  int label = m->sphere_label[i], inst = m->sphere_instance[i];
  vd_vec3 c = get3(p->sphere_pos, i);
  double r = m->sphere_radius[i];
  int top = v0, bot = v0 + 1 + (st - 1) * n;
  put_vert(mesh, top, vd_madd(c, vd_v3(0, 0, 1), r));
  add_normal(mesh, top, vd_v3(0, 0, 1));
  for (int j = 1; j < st; j++) {
    double phi = VD_PI * (double)j / (double)st;
    for (int k = 0; k < n; k++) {
      double th = 2.0 * VD_PI * (double)k / (double)n;
      vd_vec3 u = vd_v3(sin(phi) * cos(th), sin(phi) * sin(th), cos(phi));
      int vi = v0 + 1 + (j - 1) * n + k;
      put_vert(mesh, vi, vd_madd(c, u, r));
      add_normal(mesh, vi, u);
    }
  }
  put_vert(mesh, bot, vd_madd(c, vd_v3(0, 0, -1), r));
  add_normal(mesh, bot, vd_v3(0, 0, -1));
  // pole fans and the quads between rings, counter-clockwise from outside
  for (int k = 0; k < n; k++) {
    int k1 = (k + 1) % n;
    put_tri(o, top, v0 + 1 + k, v0 + 1 + k1, label, inst, i, VD_PRIM_SPHERE);
    for (int j = 1; j < st - 1; j++) {
      int u0 = v0 + 1 + (j - 1) * n, l0 = u0 + n;
      put_tri(o, u0 + k, l0 + k, l0 + k1, label, inst, i, VD_PRIM_SPHERE);
      put_tri(o, u0 + k, l0 + k1, u0 + k1, label, inst, i, VD_PRIM_SPHERE);
    }
    int last = v0 + 1 + (st - 2) * n;
    put_tri(o, bot, last + k1, last + k, label, inst, i, VD_PRIM_SPHERE);
  }
}

// spec mesh: vertices copied, triangles re-indexed, normals from area-weighted face normals
static void tess_mesh(const plan* p, out* o, int i, int v0) {
  const vd_model* m = p->m;
  vd_mesh* mesh = o->mesh;
  int vs = m->mesh_vert[2 * i], nv = m->mesh_vert[2 * i + 1];
  int ts = m->mesh_tri[2 * i], nt = m->mesh_tri[2 * i + 1];
  memcpy(mesh->pos + 3 * v0, p->vert_pos + 3 * vs, (size_t)nv * 3 * sizeof(double));  // NOLINT(clang-analyzer-core.NullDereference,clang-analyzer-core.NonNullParamChecker): arrays sized by the counts vd_geom_count gave
  for (int t = ts; t < ts + nt; t++) {
    int a = v0 + m->tri_vert[3 * t] - vs, b = v0 + m->tri_vert[3 * t + 1] - vs;
    int c = v0 + m->tri_vert[3 * t + 2] - vs;
    vd_vec3 pa = get3(mesh->pos, a), pb = get3(mesh->pos, b), pc = get3(mesh->pos, c);
    vd_vec3 fn = vd_cross(vd_sub(pb, pa), vd_sub(pc, pa));
    add_normal(mesh, a, fn), add_normal(mesh, b, fn), add_normal(mesh, c, fn);
    put_tri(o, a, b, c, m->mesh_label[i], m->mesh_instance[i], i, VD_PRIM_MESH);
  }
}

// ---------------------------------------------------------------------------------------------
// the whole plant

vd_status vd_geom_tessellate(const vd_model* m, const vd_data* d, const vd_mesh_def* def,
                             vd_mesh* mesh, vd_error* err) {
  if (!mesh) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "tessellate: null output");
  memset(mesh, 0, sizeof *mesh);
  plan p;
  vd_status st = plan_make(&p, m, d, def, err);
  if (st) {
    plan_free(&p);
    return st;
  }
  size_t nv = (size_t)p.nvert;
  if (!geom_mesh_alloc(mesh, (int)p.nvert, (int)p.ntri)) {
    plan_free(&p);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory tessellating");
  }
  // segments, spheres, meshes in index order
  out o = {mesh, 0};
  for (int i = 0; i < m->nseg; i++)
    tess_segment(&p, &o, i);
  int v = p.sphere_vbase;
  for (int i = 0; i < m->nsphere; i++) {
    tess_sphere(&p, &o, i, v);
    v += 2 + (sphere_stacks(&p, i) - 1) * sphere_slices(&p, i);
  }
  v = p.mesh_vbase;
  for (int i = 0; i < m->nmesh; i++) {
    tess_mesh(&p, &o, i, v);
    v += m->mesh_vert[2 * i + 1];
  }
  VD_ASSERT(o.nt == mesh->ntri && v == mesh->nvert);
  // unit normals (a vertex of only degenerate triangles keeps a zero normal)
  for (size_t k = 0; k < nv; k++) {
    vd_vec3 n = vd_normalize(get3(mesh->normal, (int)k));
    mesh->normal[3 * k] = n.x, mesh->normal[3 * k + 1] = n.y, mesh->normal[3 * k + 2] = n.z;
  }
  plan_free(&p);
  return VD_OK;
}

int geom_mesh_alloc(vd_mesh* mesh, int nvert, int ntri) {
  // sizes first, then one block: doubles, then ints
  memset(mesh, 0, sizeof *mesh);
  size_t nv = (size_t)nvert, nt = (size_t)ntri;
  size_t nbytes = nv * 6 * sizeof(double) + nt * 7 * sizeof(int);
  mesh->nvert = nvert;
  mesh->ntri = ntri;
  if (nbytes == 0) return 1;
  char* block = vd_calloc(1, nbytes);
  if (!block) {
    memset(mesh, 0, sizeof *mesh);
    return 0;
  }
  mesh->nbytes = nbytes;
  mesh->pos = (double*)block;
  mesh->normal = mesh->pos + 3 * nv;
  mesh->tri = (int*)(mesh->normal + 3 * nv);
  mesh->tri_label = mesh->tri + 3 * nt;
  mesh->tri_instance = mesh->tri_label + nt;
  mesh->tri_prim = mesh->tri_instance + nt;
  mesh->tri_kind = mesh->tri_prim + nt;
  return 1;
}

void vd_mesh_free(vd_mesh* mesh) {
  if (!mesh) return;
  vd_free(mesh->pos, mesh->nbytes);
  memset(mesh, 0, sizeof *mesh);
}
