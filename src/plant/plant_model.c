// SPDX-License-Identifier: MIT
// Compile a spec into the flat, read-only vd_model (validated, one allocation), and the
// vd_data state that goes with it.
#include <math.h>
#include <string.h>

#include "plant_internal.h"

// ---------------------------------------------------------------------------------------------
// validation: every index in range, every number finite (coordinates and radii within
// VD_PLANT_MAX_COORD), parents without cycles

static int finite3(vd_vec3 v) {
  return fabs(v.x) <= VD_PLANT_MAX_COORD && fabs(v.y) <= VD_PLANT_MAX_COORD && fabs(v.z) <= VD_PLANT_MAX_COORD;
}

// a radius is valid when finite, not negative and not beyond VD_PLANT_MAX_COORD
static int radius_ok(double r) {
  return r >= 0 && r <= VD_PLANT_MAX_COORD;
}

// index i is valid in [lo, n)
static int in_range(int i, int lo, int n) {
  return i >= lo && i < n;
}

static vd_status validate_nodes_segments(const vd_plant_spec* s, vd_error* err) {
  for (int i = 0; i < s->nnode; i++)
    if (!finite3(s->node[i]))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "node %d: position is not finite or beyond +-%g m", i,
                          VD_PLANT_MAX_COORD);
  for (int i = 0; i < s->nseg; i++) {
    const vd_segment_spec* g = &s->seg[i];
    const char* bad = NULL;
    if (!in_range(g->node0, 0, s->nnode))
      bad = "node0 out of range";
    else if (!in_range(g->node1, 0, s->nnode))
      bad = "node1 out of range";
    else if (!radius_ok(g->r0))
      bad = "r0 is negative, not finite or beyond 1e9 m";
    else if (!radius_ok(g->r1))
      bad = "r1 is negative, not finite or beyond 1e9 m";
    else if (!finite3(g->up))
      bad = "up is not finite";
    else if (!in_range(g->parent, -1, s->nseg) || g->parent == i)
      bad = "parent out of range";
    else if (g->label < 0)
      bad = "label is negative";
    else if (g->instance < 0)
      bad = "instance is negative";
    else if (g->slices < 3)
      bad = "slices below 3";
    else if (!isfinite(g->age))
      bad = "age is not finite";
    if (bad) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "segment %d: %s", i, bad);
  }
  return VD_OK;
}

static vd_status validate_spheres(const vd_plant_spec* s, vd_error* err) {
  for (int i = 0; i < s->nsphere; i++) {
    const vd_sphere_spec* g = &s->sphere[i];
    const char* bad = NULL;
    if (!finite3(g->center))
      bad = "center is not finite or beyond +-1e9 m";
    else if (!radius_ok(g->radius))
      bad = "radius is negative, not finite or beyond 1e9 m";
    else if (!in_range(g->node, -1, s->nnode))
      bad = "node out of range";
    else if (!in_range(g->parent, -1, s->nseg))
      bad = "parent out of range";
    else if (g->label < 0)
      bad = "label is negative";
    else if (g->instance < 0)
      bad = "instance is negative";
    else if (g->slices < 3)
      bad = "slices below 3";
    if (bad) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "sphere %d: %s", i, bad);
  }
  return VD_OK;
}

static vd_status validate_meshes(const vd_plant_spec* s, vd_error* err) {
  for (int i = 0; i < s->nvert; i++)
    if (!finite3(s->vert[i]))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "vertex %d: position is not finite or beyond +-%g m", i,
                          VD_PLANT_MAX_COORD);
  for (int i = 0; i < s->nmesh; i++) {
    const vd_mesh_spec* g = &s->mesh[i];
    const char* bad = NULL;
    if (g->vert_start < 0 || g->nvert < 0 || g->vert_start > s->nvert - g->nvert)
      bad = "vertex range outside the vertex array";
    else if (g->tri_start < 0 || g->ntri < 0 || g->tri_start > s->ntri - g->ntri)
      bad = "triangle range outside the triangle array";
    else if (!in_range(g->node, -1, s->nnode))
      bad = "node out of range";
    else if (!in_range(g->parent, -1, s->nseg))
      bad = "parent out of range";
    else if (g->label < 0)
      bad = "label is negative";
    else if (g->instance < 0)
      bad = "instance is negative";
    if (bad) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "mesh %d: %s", i, bad);
    // triangles may only use the mesh's own vertices
    for (int t = g->tri_start; t < g->tri_start + g->ntri; t++)
      for (int k = 0; k < 3; k++)
        if (!in_range(s->tri[3 * t + k], g->vert_start, g->vert_start + g->nvert))
          return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                              "mesh %d: triangle %d: vertex %d out of range", i, t, k);
  }
  return VD_OK;
}

// parents must form a forest: walk up from each segment, marking the path
static vd_status validate_parents(const vd_plant_spec* s, vd_error* err) {
  if (s->nseg == 0) return VD_OK;
  // state: 0 unvisited, 1 on the current path, 2 known to reach a root
  char* state = vd_calloc((size_t)s->nseg, 1);
  if (!state) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory validating parents");
  vd_status st = VD_OK;
  for (int i = 0; i < s->nseg && !st; i++) {
    int j = i;
    while (j >= 0 && state[j] == 0)
      state[j] = 1, j = s->seg[j].parent;
    if (j >= 0 && state[j] == 1)
      st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "segment %d: parent chain has a cycle", i);
    for (j = i; j >= 0 && state[j] == 1; j = s->seg[j].parent)
      state[j] = 2;
  }
  vd_free(state, (size_t)s->nseg);
  return st;
}

vd_status vd_plant_validate(const vd_plant_spec* s, vd_error* err) {
  vd_status st = validate_nodes_segments(s, err);
  if (!st) st = validate_spheres(s, err);
  if (!st) st = validate_meshes(s, err);
  if (!st) st = validate_parents(s, err);
  return st;
}

// ---------------------------------------------------------------------------------------------
// segment frames

// unit vector orthogonal to unit v, from the world axis least aligned with it
static vd_vec3 any_perp(vd_vec3 v) {
  double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
  vd_vec3 a =
      (ax <= ay && ax <= az) ? vd_v3(1, 0, 0) : (ay <= az ? vd_v3(0, 1, 0) : vd_v3(0, 0, 1));
  return vd_normalize(vd_madd(a, v, -vd_dot(a, v)));
}

// part of v orthogonal to unit n, normalised; fallback when v is (nearly) along n
static vd_vec3 ortho_dir(vd_vec3 v, vd_vec3 n) {
  vd_vec3 o = vd_madd(v, n, -vd_dot(v, n));
  double len = vd_norm(o), vlen = vd_norm(v);
  if (!(len > 1e-9 * vlen) || !(vlen > 0)) return any_perp(n);
  return vd_scale(o, 1.0 / len);
}

// frame of a segment: z along dir, x toward up; a zero-length segment takes x from up and z from
// the hint direction (its parent's axis, else world z)
static vd_quat segment_frame(vd_vec3 dir, vd_vec3 up, vd_vec3 hint) {
  vd_vec3 x, z;
  if (vd_norm(dir) > 0) {
    z = vd_normalize(dir);
    x = ortho_dir(up, z);
  } else {
    x = vd_norm(up) > 0 ? vd_normalize(up) : vd_v3(1, 0, 0);
    z = ortho_dir(hint, x);
  }
  vd_vec3 y = vd_cross(z, x);
  return vd_quat_normalize(vd_quat_from_axes(x, y, z));
}

// ---------------------------------------------------------------------------------------------
// the model block

// place an array of bytes at the next 16-byte aligned offset
static size_t take(size_t* top, size_t bytes) {
  size_t off = *top;
  *top += (bytes + 15) & ~(size_t)15;
  return off;
}

vd_status vd_plant_compile(const vd_plant_spec* s, vd_model** out, vd_error* err) {
  if (out) *out = NULL;
  if (!s || !out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "compile: null argument");
  // validate everything before allocating
  vd_status st = vd_plant_validate(s, err);
  if (st) return st;

  // labels completed in a copy of the table
  vd_plant_spec tmp;
  memset(&tmp, 0, sizeof tmp);
  tmp.nseg = s->nseg, tmp.seg = s->seg;
  tmp.nsphere = s->nsphere, tmp.sphere = s->sphere;
  tmp.nmesh = s->nmesh, tmp.mesh = s->mesh;
  if (s->nlabel > 0) {
    if (!vd_grow((void**)&tmp.label, &tmp.cap_label, s->nlabel, sizeof *tmp.label))
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory compiling labels");
    memcpy(tmp.label, s->label, (size_t)s->nlabel * sizeof *s->label);
    tmp.nlabel = s->nlabel;
  }
  if (vd_plant_complete_labels(&tmp) != VD_OK) {
    vd_free(tmp.label, (size_t)tmp.cap_label * sizeof *tmp.label);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory compiling labels");
  }

  // sizes first: offsets of every array in one block
  size_t nn = (size_t)s->nnode, ns = (size_t)s->nseg, nsp = (size_t)s->nsphere;
  size_t nm = (size_t)s->nmesh, nv = (size_t)s->nvert, nt = (size_t)s->ntri;
  size_t D = sizeof(double), I = sizeof(int), top = 0;
  size_t o_model = take(&top, sizeof(vd_model));
  size_t o_node_pos0 = take(&top, nn * 3 * D);
  size_t o_seg_node = take(&top, ns * 2 * I), o_seg_radius = take(&top, ns * 2 * D);
  size_t o_seg_len0 = take(&top, ns * D), o_seg_quat0 = take(&top, ns * 4 * D);
  size_t o_seg_parent = take(&top, ns * I), o_seg_label = take(&top, ns * I);
  size_t o_seg_instance = take(&top, ns * I), o_seg_axis = take(&top, ns * I);
  size_t o_seg_order = take(&top, ns * I), o_seg_flags = take(&top, ns * I);
  size_t o_seg_slices = take(&top, ns * I), o_seg_age = take(&top, ns * D);
  size_t o_sphere_pos0 = take(&top, nsp * 3 * D), o_sphere_radius = take(&top, nsp * D);
  size_t o_sphere_node = take(&top, nsp * I), o_sphere_parent = take(&top, nsp * I);
  size_t o_sphere_label = take(&top, nsp * I), o_sphere_instance = take(&top, nsp * I);
  size_t o_sphere_slices = take(&top, nsp * I);
  size_t o_mesh_vert = take(&top, nm * 2 * I), o_mesh_tri = take(&top, nm * 2 * I);
  size_t o_mesh_closed = take(&top, nm * I), o_mesh_node = take(&top, nm * I);
  size_t o_mesh_parent = take(&top, nm * I), o_mesh_label = take(&top, nm * I);
  size_t o_mesh_instance = take(&top, nm * I);
  size_t o_vert_pos0 = take(&top, nv * 3 * D), o_tri_vert = take(&top, nt * 3 * I);
  size_t o_labels = take(&top, (size_t)tmp.nlabel * sizeof(vd_label));

  // then one allocation
  char* block = vd_malloc(top);
  if (!block) {
    vd_free(tmp.label, (size_t)tmp.cap_label * sizeof *tmp.label);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory compiling the model");
  }
  memset(block, 0, top);
  vd_model* m = (vd_model*)(block + o_model);
  m->nnode = s->nnode, m->nseg = s->nseg, m->nsphere = s->nsphere, m->nmesh = s->nmesh;
  m->nvert = s->nvert, m->ntri = s->ntri, m->nlabel = tmp.nlabel, m->ninstance = 0;
  m->nbytes = top;
  m->node_pos0 = (double*)(block + o_node_pos0);
  m->seg_node = (int*)(block + o_seg_node);
  m->seg_radius = (double*)(block + o_seg_radius);
  m->seg_len0 = (double*)(block + o_seg_len0);
  m->seg_quat0 = (double*)(block + o_seg_quat0);
  m->seg_parent = (int*)(block + o_seg_parent);
  m->seg_label = (int*)(block + o_seg_label);
  m->seg_instance = (int*)(block + o_seg_instance);
  m->seg_axis = (int*)(block + o_seg_axis);
  m->seg_order = (int*)(block + o_seg_order);
  m->seg_flags = (int*)(block + o_seg_flags);
  m->seg_slices = (int*)(block + o_seg_slices);
  m->seg_age = (double*)(block + o_seg_age);
  m->sphere_pos0 = (double*)(block + o_sphere_pos0);
  m->sphere_radius = (double*)(block + o_sphere_radius);
  m->sphere_node = (int*)(block + o_sphere_node);
  m->sphere_parent = (int*)(block + o_sphere_parent);
  m->sphere_label = (int*)(block + o_sphere_label);
  m->sphere_instance = (int*)(block + o_sphere_instance);
  m->sphere_slices = (int*)(block + o_sphere_slices);
  m->mesh_vert = (int*)(block + o_mesh_vert);
  m->mesh_tri = (int*)(block + o_mesh_tri);
  m->mesh_closed = (int*)(block + o_mesh_closed);
  m->mesh_node = (int*)(block + o_mesh_node);
  m->mesh_parent = (int*)(block + o_mesh_parent);
  m->mesh_label = (int*)(block + o_mesh_label);
  m->mesh_instance = (int*)(block + o_mesh_instance);
  m->vert_pos0 = (double*)(block + o_vert_pos0);
  m->tri_vert = (int*)(block + o_tri_vert);
  m->labels = (vd_label*)(block + o_labels);

  // nodes
  for (int i = 0; i < s->nnode; i++) {
    m->node_pos0[3 * i + 0] = s->node[i].x;
    m->node_pos0[3 * i + 1] = s->node[i].y;
    m->node_pos0[3 * i + 2] = s->node[i].z;
  }
  // segments: topology, radii, rest length and rest frame
  for (int i = 0; i < s->nseg; i++) {
    const vd_segment_spec* g = &s->seg[i];
    m->seg_node[2 * i] = g->node0, m->seg_node[2 * i + 1] = g->node1;
    m->seg_radius[2 * i] = g->r0, m->seg_radius[2 * i + 1] = g->r1;
    m->seg_parent[i] = g->parent;
    m->seg_label[i] = g->label;
    m->seg_instance[i] = g->instance;
    m->seg_axis[i] = g->axis;
    m->seg_order[i] = g->order;
    m->seg_flags[i] = (int)g->flags;
    m->seg_slices[i] = g->slices;
    m->seg_age[i] = g->age;
    if (g->instance > m->ninstance) m->ninstance = g->instance;
    vd_vec3 dir = vd_sub(s->node[g->node1], s->node[g->node0]);
    m->seg_len0[i] = vd_norm(dir);
    vd_vec3 hint = vd_v3(0, 0, 1);
    if (g->parent >= 0) {
      const vd_segment_spec* p = &s->seg[g->parent];
      vd_vec3 pdir = vd_sub(s->node[p->node1], s->node[p->node0]);
      if (vd_norm(pdir) > 0) hint = pdir;
    }
    vd_quat q = segment_frame(dir, g->up, hint);
    m->seg_quat0[4 * i + 0] = q.w, m->seg_quat0[4 * i + 1] = q.x;
    m->seg_quat0[4 * i + 2] = q.y, m->seg_quat0[4 * i + 3] = q.z;
  }
  // spheres
  for (int i = 0; i < s->nsphere; i++) {
    const vd_sphere_spec* g = &s->sphere[i];
    m->sphere_pos0[3 * i + 0] = g->center.x;
    m->sphere_pos0[3 * i + 1] = g->center.y;
    m->sphere_pos0[3 * i + 2] = g->center.z;
    m->sphere_radius[i] = g->radius;
    m->sphere_node[i] = g->node;
    m->sphere_parent[i] = g->parent;
    m->sphere_label[i] = g->label;
    m->sphere_instance[i] = g->instance;
    m->sphere_slices[i] = g->slices;
    if (g->instance > m->ninstance) m->ninstance = g->instance;
  }
  // meshes, their vertices and triangles
  for (int i = 0; i < s->nmesh; i++) {
    const vd_mesh_spec* g = &s->mesh[i];
    m->mesh_vert[2 * i] = g->vert_start, m->mesh_vert[2 * i + 1] = g->nvert;
    m->mesh_tri[2 * i] = g->tri_start, m->mesh_tri[2 * i + 1] = g->ntri;
    m->mesh_closed[i] = g->closed ? 1 : 0;
    m->mesh_node[i] = g->node;
    m->mesh_parent[i] = g->parent;
    m->mesh_label[i] = g->label;
    m->mesh_instance[i] = g->instance;
    if (g->instance > m->ninstance) m->ninstance = g->instance;
  }
  for (int i = 0; i < s->nvert; i++) {
    m->vert_pos0[3 * i + 0] = s->vert[i].x;
    m->vert_pos0[3 * i + 1] = s->vert[i].y;
    m->vert_pos0[3 * i + 2] = s->vert[i].z;
  }
  if (nt > 0) memcpy(m->tri_vert, s->tri, nt * 3 * I);
  // labels
  if (tmp.nlabel > 0) memcpy(m->labels, tmp.label, (size_t)tmp.nlabel * sizeof(vd_label));
  vd_free(tmp.label, (size_t)tmp.cap_label * sizeof *tmp.label);
  *out = m;
  return VD_OK;
}

void vd_model_destroy(vd_model* m) {
  if (m) vd_free(m, m->nbytes);
}

const vd_label* vd_model_find_label(const vd_model* m, int id) {
  if (!m) return NULL;
  // binary search in the sorted table
  int lo = 0, hi = m->nlabel;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (m->labels[mid].id < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (lo < m->nlabel && m->labels[lo].id == id) ? &m->labels[lo] : NULL;
}

// ---------------------------------------------------------------------------------------------
// state

vd_data* vd_data_create(const vd_model* m) {
  if (!m) return NULL;
  // sizes first, then one allocation
  size_t D = sizeof(double), top = 0;
  size_t o_data = take(&top, sizeof(vd_data));
  size_t o_node_pos = take(&top, (size_t)m->nnode * 3 * D);
  size_t o_seg_quat = take(&top, (size_t)m->nseg * 4 * D);
  size_t o_sphere_pos = take(&top, (size_t)m->nsphere * 3 * D);
  size_t o_vert_pos = take(&top, (size_t)m->nvert * 3 * D);
  size_t o_seg_broken = take(&top, (size_t)m->nseg * sizeof(int));
  size_t o_seg_cut = take(&top, (size_t)m->nseg * 7 * D);
  char* block = vd_malloc(top);
  if (!block) return NULL;
  memset(block, 0, top);
  vd_data* d = (vd_data*)(block + o_data);
  d->nnode = m->nnode, d->nseg = m->nseg, d->nsphere = m->nsphere, d->nvert = m->nvert;
  d->node_pos = (double*)(block + o_node_pos);
  d->seg_quat = (double*)(block + o_seg_quat);
  d->sphere_pos = (double*)(block + o_sphere_pos);
  d->vert_pos = (double*)(block + o_vert_pos);
  d->seg_broken = (int*)(block + o_seg_broken);
  d->seg_cut = (double*)(block + o_seg_cut);
  d->nbytes = top;
  vd_arena_init(&d->arena, 0);
  vd_data_reset(m, d);
  return d;
}

void vd_data_reset(const vd_model* m, vd_data* d) {
  if (!m || !d) return;
  VD_ASSERT(d->nnode == m->nnode && d->nseg == m->nseg && d->nsphere == m->nsphere &&
            d->nvert == m->nvert);
  // rest shape, nothing broken, no warnings, empty scratch
  size_t D = sizeof(double);
  memcpy(d->node_pos, m->node_pos0, (size_t)m->nnode * 3 * D);
  memcpy(d->seg_quat, m->seg_quat0, (size_t)m->nseg * 4 * D);
  memcpy(d->sphere_pos, m->sphere_pos0, (size_t)m->nsphere * 3 * D);
  memcpy(d->vert_pos, m->vert_pos0, (size_t)m->nvert * 3 * D);
  memset(d->seg_broken, 0, (size_t)m->nseg * sizeof(int));
  for (int i = 0; i < m->nseg; i++) {
    double* c = d->seg_cut + 7 * i;
    c[0] = -1;  // no known break point
    for (int k = 0; k < 3; k++) c[1 + k] = c[4 + k] = m->node_pos0[3 * m->seg_node[2 * i] + k];
  }
  d->nwarning = 0;
  vd_arena_reset(&d->arena);
}

void vd_data_destroy(vd_data* d) {
  if (!d) return;
  vd_arena_free(&d->arena);
  vd_free(d, d->nbytes);
}
