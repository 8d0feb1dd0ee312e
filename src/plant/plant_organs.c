// SPDX-License-Identifier: MIT
// Organ instances and traits. The turtle numbers instances by producing module: a tomato
// pedicel drawn as pedicel, knuckle, pedicel is three instances, a truss rachis one per piece.
// A phenotyper counts organs as a botanist names them; vd_plant_set_instances joins the module
// pieces into organs (or puts the module numbering back), vd_plant_traits measures each one.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "plant_internal.h"

// union-find over the elements: segments, then spheres, then meshes
static int find(int* up, int i) {
  while (up[i] != i) {
    up[i] = up[up[i]];
    i = up[i];
  }
  return i;
}

static void join(int* up, int a, int b) {
  a = find(up, a), b = find(up, b);
  if (a == b) return;
  if (a < b) up[b] = a;
  else up[a] = b;
}

// what groups the elements of one module: the module, or the instance where no module is known
typedef struct elem_key {
  int64_t group;  // module index, or -(instance + 1) without a module
  int label;      // organs: a module's pieces of other labels are other organs
  int elem;
} elem_key;

static int cmp_key(const void* a, const void* b) {
  const elem_key *x = a, *y = b;
  if (x->group != y->group) return x->group < y->group ? -1 : 1;
  if (x->label != y->label) return x->label < y->label ? -1 : 1;
  return (x->elem > y->elem) - (x->elem < y->elem);
}

static vd_organ organ_of(const vd_plant_spec* s, int label) {
  const vd_label* l = vd_plant_find_label(s, label);
  return l ? l->organ : VD_ORGAN_OTHER;
}

vd_status vd_plant_set_instances(vd_plant_spec* s, vd_instance_mode mode) {
  if (!s) return VD_ERR_ARG;
  int ns = s->nseg, nsp = s->nsphere, n = ns + s->nsphere + s->nmesh;
  if (n == 0) {
    s->ninstance = 0;
    return VD_OK;
  }
  int* up = vd_malloc((size_t)n * sizeof(int));
  int* id = vd_calloc((size_t)n, sizeof(int));
  elem_key* key = vd_malloc((size_t)n * sizeof(elem_key));
  if (!up || !id || !key) {
    vd_free(up, (size_t)n * sizeof(int));
    vd_free(id, (size_t)n * sizeof(int));
    vd_free(key, (size_t)n * sizeof(elem_key));
    return VD_ERR_NOMEM;
  }
  int organs = mode == VD_INSTANCE_ORGANS;
  for (int e = 0; e < n; e++) {
    int64_t module;
    int inst, label;
    if (e < ns) module = s->seg[e].module, inst = s->seg[e].instance, label = s->seg[e].label;
    else if (e < ns + nsp) module = s->sphere[e - ns].module, inst = s->sphere[e - ns].instance, label = s->sphere[e - ns].label;
    else module = s->mesh[e - ns - nsp].module, inst = s->mesh[e - ns - nsp].instance, label = s->mesh[e - ns - nsp].label;
    up[e] = e;
    key[e].group = module >= 0 ? module : -(int64_t)inst - 1;
    key[e].label = organs ? label : 0;
    key[e].elem = e;
  }
  // the pieces of one module (of one label)
  qsort(key, (size_t)n, sizeof *key, cmp_key);
  for (int k = 1; k < n; k++)
    if (key[k].group == key[k - 1].group && key[k].label == key[k - 1].label) join(up, key[k].elem, key[k - 1].elem);
  if (organs) {
    // an element continues its parent segment's organ when it has the same label; a stem or
    // root segment on another axis than its parent's is a lateral branch or root: its own organ
    for (int e = 0; e < ns; e++) {
      const vd_segment_spec* g = &s->seg[e];
      if (g->parent < 0 || g->parent >= ns || s->seg[g->parent].label != g->label) continue;
      vd_organ o = organ_of(s, g->label);
      if ((o == VD_ORGAN_STEM || o == VD_ORGAN_ROOT) && g->axis != s->seg[g->parent].axis) continue;
      join(up, e, g->parent);
    }
    for (int e = 0; e < nsp; e++) {
      int p = s->sphere[e].parent;
      if (p >= 0 && p < ns && s->seg[p].label == s->sphere[e].label) join(up, ns + e, p);
    }
    for (int e = 0; e < s->nmesh; e++) {
      int p = s->mesh[e].parent;
      if (p >= 0 && p < ns && s->seg[p].label == s->mesh[e].label) join(up, ns + nsp + e, p);
    }
  }
  // 1..K in the order the elements come
  int k = 0;
  for (int e = 0; e < n; e++) {
    int r = find(up, e);
    if (!id[r]) id[r] = ++k;
    int v = id[r];
    if (e < ns) s->seg[e].instance = v;
    else if (e < ns + nsp) s->sphere[e - ns].instance = v;
    else s->mesh[e - ns - nsp].instance = v;
  }
  s->ninstance = k;
  vd_free(up, (size_t)n * sizeof(int));
  vd_free(id, (size_t)n * sizeof(int));
  vd_free(key, (size_t)n * sizeof(elem_key));
  return VD_OK;
}

static void grow_box(vd_organ_traits* t, vd_vec3 p, double r) {
  t->bbox_min = vd_v3(fmin(t->bbox_min.x, p.x - r), fmin(t->bbox_min.y, p.y - r), fmin(t->bbox_min.z, p.z - r));
  t->bbox_max = vd_v3(fmax(t->bbox_max.x, p.x + r), fmax(t->bbox_max.y, p.y + r), fmax(t->bbox_max.z, p.z + r));
}

vd_status vd_plant_traits(const vd_plant_spec* s, vd_organ_traits** out, int* nout) {
  if (!s || !out || !nout) return VD_ERR_ARG;
  *out = NULL, *nout = 0;
  int ni = s->ninstance > 0 ? s->ninstance : 0;
  if (ni == 0) return VD_OK;
  vd_organ_traits* t = vd_calloc((size_t)ni, sizeof *t);
  // a sphere or a closed mesh gives the diameter (a fruit); else the thickest segment (a stem)
  double* round = vd_calloc((size_t)ni, sizeof(double));
  double* thick = vd_calloc((size_t)ni, sizeof(double));
  if (!t || !round || !thick) {
    vd_free(t, (size_t)ni * sizeof *t);
    vd_free(round, (size_t)ni * sizeof(double));
    vd_free(thick, (size_t)ni * sizeof(double));
    return VD_ERR_NOMEM;
  }
  for (int i = 0; i < ni; i++) {
    t[i].instance = i + 1, t[i].label = -1;
    t[i].bbox_min = vd_v3(INFINITY, INFINITY, INFINITY);
    t[i].bbox_max = vd_v3(-INFINITY, -INFINITY, -INFINITY);
  }
  for (int e = 0; e < s->nseg; e++) {
    const vd_segment_spec* g = &s->seg[e];
    if (g->instance < 1 || g->instance > ni || g->node0 < 0 || g->node0 >= s->nnode || g->node1 < 0 || g->node1 >= s->nnode)
      continue;
    vd_organ_traits* o = &t[g->instance - 1];
    if (o->label < 0) o->label = g->label;
    o->nseg++;
    vd_vec3 a = s->node[g->node0], b = s->node[g->node1];
    double l = vd_norm(vd_sub(b, a));
    o->length += l;
    o->volume += VD_PI * l * (g->r0 * g->r0 + g->r0 * g->r1 + g->r1 * g->r1) / 3;
    thick[g->instance - 1] = fmax(thick[g->instance - 1], 2 * fmax(g->r0, g->r1));
    grow_box(o, a, g->r0);
    grow_box(o, b, g->r1);
  }
  for (int e = 0; e < s->nsphere; e++) {
    const vd_sphere_spec* g = &s->sphere[e];
    if (g->instance < 1 || g->instance > ni) continue;
    vd_organ_traits* o = &t[g->instance - 1];
    if (o->label < 0) o->label = g->label;
    o->nsphere++;
    o->volume += 4.0 / 3.0 * VD_PI * g->radius * g->radius * g->radius;
    round[g->instance - 1] = fmax(round[g->instance - 1], 2 * g->radius);
    grow_box(o, g->center, g->radius);
  }
  for (int e = 0; e < s->nmesh; e++) {
    const vd_mesh_spec* g = &s->mesh[e];
    if (g->instance < 1 || g->instance > ni) continue;
    vd_organ_traits* o = &t[g->instance - 1];
    if (o->label < 0) o->label = g->label;
    o->nmesh++;
    double area = 0, vol = 0;
    vd_vec3 lo = vd_v3(INFINITY, INFINITY, INFINITY), hi = vd_v3(-INFINITY, -INFINITY, -INFINITY);
    for (int k = g->tri_start; k < g->tri_start + g->ntri && k < s->ntri; k++) {
      const int* tv = s->tri + 3 * k;
      int i0 = tv[0], i1 = tv[1], i2 = tv[2];  // indices into the spec's vertices
      if (i0 < 0 || i1 < 0 || i2 < 0 || i0 >= s->nvert || i1 >= s->nvert || i2 >= s->nvert) continue;
      vd_vec3 a = s->vert[i0], b = s->vert[i1], c = s->vert[i2];
      area += 0.5 * vd_norm(vd_cross(vd_sub(b, a), vd_sub(c, a)));
      vol += vd_dot(a, vd_cross(b, c)) / 6;
    }
    for (int k = g->vert_start; k < g->vert_start + g->nvert && k < s->nvert; k++) {
      vd_vec3 p = s->vert[k];
      lo = vd_v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
      hi = vd_v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
      grow_box(o, p, 0);
    }
    if (g->closed) {
      o->volume += fabs(vol);
      if (g->nvert > 0) round[g->instance - 1] = fmax(round[g->instance - 1], fmax(hi.x - lo.x, fmax(hi.y - lo.y, hi.z - lo.z)));
    } else {
      o->area += area;
    }
  }
  for (int i = 0; i < ni; i++) {
    vd_organ_traits* o = &t[i];
    o->organ = o->label >= 0 ? organ_of(s, o->label) : VD_ORGAN_OTHER;
    o->diameter = round[i] > 0 ? round[i] : thick[i];
    if (!(o->bbox_min.x <= o->bbox_max.x)) o->bbox_min = o->bbox_max = vd_v3(0, 0, 0);  // nothing measurable
  }
  vd_free(round, (size_t)ni * sizeof(double));
  vd_free(thick, (size_t)ni * sizeof(double));
  *out = t, *nout = ni;
  return VD_OK;
}
