// SPDX-License-Identifier: MIT
// TEMPORARY: replaced by the real plant module at merge (delete this file then).
// A minimal, correct implementation of the plant-spec functions the turtle and its tests use,
// so the `turtle` branch links on its own: create/destroy/clear, element defaults, add
// node/segment/sphere/mesh, and the label table. Nothing here is part of the plant design.
#include <string.h>

#include "verdant/plant.h"

vd_plant_spec* vd_plant_spec_create(void) {
  return vd_calloc(1, sizeof(vd_plant_spec));
}

void vd_plant_spec_destroy(vd_plant_spec* s) {
  if (!s) return;
  vd_free(s->node, (size_t)s->cap_node * sizeof *s->node);
  vd_free(s->seg, (size_t)s->cap_seg * sizeof *s->seg);
  vd_free(s->sphere, (size_t)s->cap_sphere * sizeof *s->sphere);
  vd_free(s->mesh, (size_t)s->cap_mesh * sizeof *s->mesh);
  vd_free(s->vert, (size_t)s->cap_vert * sizeof *s->vert);
  vd_free(s->tri, (size_t)s->cap_tri * 3 * sizeof *s->tri);
  vd_free(s->label, (size_t)s->cap_label * sizeof *s->label);
  vd_free(s, sizeof *s);
}

void vd_plant_spec_clear(vd_plant_spec* s) {
  s->nnode = s->nseg = s->nsphere = s->nmesh = s->nvert = s->ntri = s->nlabel = 0;
  s->ninstance = 0;
}

vd_segment_spec vd_segment_spec_default(void) {
  vd_segment_spec g;
  memset(&g, 0, sizeof g);
  g.node0 = g.node1 = -1;
  g.r0 = g.r1 = 0.1;
  g.up = vd_v3(1, 0, 0);
  g.parent = -1;
  g.slices = 8;
  g.module = -1;
  return g;
}

vd_sphere_spec vd_sphere_spec_default(void) {
  vd_sphere_spec g;
  memset(&g, 0, sizeof g);
  g.radius = 0.1;
  g.node = g.parent = -1;
  g.slices = 8;
  g.module = -1;
  return g;
}

// keep ninstance the largest instance id in use
static void note_instance(vd_plant_spec* s, int instance) {
  if (instance > s->ninstance) s->ninstance = instance;
}

int vd_plant_add_node(vd_plant_spec* s, vd_vec3 p) {
  if (!vd_grow((void**)&s->node, &s->cap_node, s->nnode + 1, sizeof *s->node)) return -1;
  s->node[s->nnode] = p;
  return s->nnode++;
}

int vd_plant_add_segment(vd_plant_spec* s, const vd_segment_spec* g) {
  if (!vd_grow((void**)&s->seg, &s->cap_seg, s->nseg + 1, sizeof *s->seg)) return -1;
  s->seg[s->nseg] = *g;
  note_instance(s, g->instance);
  return s->nseg++;
}

int vd_plant_add_sphere(vd_plant_spec* s, const vd_sphere_spec* g) {
  if (!vd_grow((void**)&s->sphere, &s->cap_sphere, s->nsphere + 1, sizeof *s->sphere)) return -1;
  s->sphere[s->nsphere] = *g;
  note_instance(s, g->instance);
  return s->nsphere++;
}

int vd_plant_add_mesh(vd_plant_spec* s, const vd_mesh_spec* m, const vd_vec3* verts, int nvert,
                      const int* tris, int ntri) {
  // grow the triangle array in units of 3 ints, the others by element
  int tcap = s->cap_tri;
  if (!vd_grow((void**)&s->mesh, &s->cap_mesh, s->nmesh + 1, sizeof *s->mesh) ||
      !vd_grow((void**)&s->vert, &s->cap_vert, s->nvert + nvert, sizeof *s->vert) ||
      !vd_grow((void**)&s->tri, &tcap, s->ntri + ntri, 3 * sizeof *s->tri))
    return -1;
  s->cap_tri = tcap;
  vd_mesh_spec* d = &s->mesh[s->nmesh];
  *d = *m;
  d->vert_start = s->nvert;
  d->nvert = nvert;
  d->tri_start = s->ntri;
  d->ntri = ntri;
  memcpy(s->vert + s->nvert, verts, (size_t)nvert * sizeof *verts);
  for (int k = 0; k < 3 * ntri; k++)
    s->tri[3 * s->ntri + k] = tris[k] + s->nvert;
  s->nvert += nvert;
  s->ntri += ntri;
  note_instance(s, m->instance);
  return s->nmesh++;
}

vd_status vd_plant_set_label(vd_plant_spec* s, int id, const char* name) {
  // find the slot (sorted by id), insert when absent
  int k = 0;
  while (k < s->nlabel && s->label[k].id < id)
    k++;
  if (k == s->nlabel || s->label[k].id != id) {
    if (!vd_grow((void**)&s->label, &s->cap_label, s->nlabel + 1, sizeof *s->label))
      return VD_ERR_NOMEM;
    memmove(s->label + k + 1, s->label + k, (size_t)(s->nlabel - k) * sizeof *s->label);
    memset(&s->label[k], 0, sizeof s->label[k]);
    s->label[k].id = id;
    s->nlabel++;
  }
  snprintf(s->label[k].name, sizeof s->label[k].name, "%s", name);
  return VD_OK;
}

const vd_label* vd_plant_find_label(const vd_plant_spec* s, int id) {
  for (int k = 0; k < s->nlabel; k++)
    if (s->label[k].id == id) return &s->label[k];
  return NULL;
}
