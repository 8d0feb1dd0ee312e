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
// start ring is its parent's end ring) for every segment; broken (Nullable) severs segments.
void geom_joints(const vd_model* m, const int* broken, int slices, int* cont, int* joined);

#endif
