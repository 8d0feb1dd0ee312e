// SPDX-License-Identifier: MIT
// Private to geom: the rule that joins generalised-cylinder segments through a shared ring, used
// by the tessellation (to share the ring) and by the solids (to exclude a tube's neighbours).
#ifndef VERDANT_GEOM_INTERNAL_H
#define VERDANT_GEOM_INTERNAL_H

#include "verdant/geom.h"

// Sides of segment i under the tessellation settings (slices > 0 overrides the model's).
static inline int geom_seg_slices(const vd_model* m, int slices, int i) {
  return slices > 0 ? slices : m->seg_slices[i];
}

// Fill cont[i] (the segment continuing i through a shared ring, or -1) and joined[i] (1 when i's
// start ring is its parent's end ring) for every segment; the broken segments of d (Nullable)
// are severed from their parents, and a segment cut at a known point (geom_seg_cut) from its
// children too.
void geom_joints(const vd_model* m, const vd_data* d, int slices, int* cont, int* joined);

// The parts of segment i drawn in state d (Nullable): GEOM_WHOLE for a segment that is not cut
// at a known point; else GEOM_PART_OFF (B -> node1, when f < 1) and GEOM_PART_STUB (node0 -> A,
// when f > 0) of a broken segment, *f the fraction where it broke (vd_data::seg_cut).
enum { GEOM_WHOLE = 0, GEOM_PART_OFF = 1, GEOM_PART_STUB = 2 };
int geom_seg_cut(const vd_data* d, int i, double* f);

// The name of label id in OBJ/MTL files (groups, objects, materials): its name with characters
// other than letters, digits, '_', '-', '.' made '_'; "label_<id>" without an entry or a name;
// "<name>_<id>" when an earlier entry of the table gives the same name.
void geom_obj_name(const vd_label* labels, int nlabel, int id, char* buf, size_t cap);

// Allocate a mesh of nvert vertices and ntri triangles in one zeroed block (vd_mesh_free frees
// it); 0 when out of memory (the mesh is then empty).
int geom_mesh_alloc(vd_mesh* mesh, int nvert, int ntri);

#endif
