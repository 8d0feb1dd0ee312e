// SPDX-License-Identifier: MIT
// Values carried from a plant's nodes and segments to the vertices of its tessellation (a
// simulation's stress, written as a per-vertex PLY property).
#include <math.h>
#include <string.h>

#include "verdant/geom.h"

void vd_geom_vertex_values(const vd_model* m, const vd_data* d, const vd_mesh* mesh,
                           const double* node_value, const double* seg_value, double* out) {
  for (int v = 0; v < mesh->nvert; v++) out[v] = NAN;
  const double* node = d ? d->node_pos : m->node_pos0;
  for (int t = 0; t < mesh->ntri; t++) {
    if (mesh->tri_kind[t] != VD_PRIM_SEGMENT) continue;
    int j = mesh->tri_prim[t];
    if (j < 0 || j >= m->nseg) continue;
    int a = m->seg_node[2 * j], b = m->seg_node[2 * j + 1];
    const double* pa = node + 3 * a;
    const double* pb = node + 3 * b;
    double ax[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    double l2 = ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2];
    double vs = seg_value ? seg_value[j] : NAN;
    for (int k = 0; k < 3; k++) {
      int v = mesh->tri[3 * t + k];
      const double* p = mesh->pos + 3 * v;
      // the ring the vertex belongs to: its position along the axis
      double u = l2 > 0 ? ((p[0] - pa[0]) * ax[0] + (p[1] - pa[1]) * ax[1] + (p[2] - pa[2]) * ax[2]) / l2 : 0;
      double vn = node_value ? node_value[u < 0.5 ? a : b] : NAN;
      out[v] = isnan(vn) ? vs : vn;
    }
  }
}
