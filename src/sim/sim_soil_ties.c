// SPDX-License-Identifier: MIT
// The rods engine in the soil: root nodes held by ties that slip beyond the soil's resistance
// (vd_soil_max_force, phys_soil.c; docs/physics.md, "Soil").
#include "sim_internal.h"

vd_status vd_sim_soil_attach(const vd_sim_model* m, vd_sim_data* d, const vd_soil* soil, vd_sim_soil** out,
                             vd_error* err) {
  *out = NULL;
  vd_status st = vd_soil_check(soil, err);
  if (st) return st;
  int nn = m->nnode;
  // nodes of root segments below the ground, and root starts at the ground
  unsigned char* pick = vd_calloc((size_t)(nn ? nn : 1), 1);
  if (!pick) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  int n = 0;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_class[t] != VD_SIM_ROOT) continue;
    for (int e = 0; e < 2; e++) {
      int k = m->seg_node[2 * t + e];
      if (m->node_fixed[k] || pick[k]) continue;
      if (m->node_pos0[k].z < soil->ground + 0.01) pick[k] = 1, n++;
    }
  }
  size_t nb = sizeof(vd_sim_soil) + (size_t)n * (2 * sizeof(int) + sizeof(double) + 1) + 16;
  char* blk = vd_calloc(1, nb);
  if (!blk) {
    vd_free(pick, (size_t)(nn ? nn : 1));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  vd_sim_soil* s = (vd_sim_soil*)blk;
  s->nbytes = nb;
  s->ground = soil->ground;
  s->fmax = (double*)(blk + sizeof(vd_sim_soil));
  s->node = (int*)(s->fmax + n);
  s->tie = s->node + n;
  s->yielded = (unsigned char*)(s->tie + n);
  double comp = 1.0 / soil->stiffness;
  for (int k = 0; k < nn && !st; k++) {
    if (!pick[k]) continue;
    // the area the node holds by: the side of the segment that ends at it
    int o = m->node_owner[k];
    double area = o >= 0 ? 2 * VD_PI * m->seg_radius[o] * m->seg_len0[o] : 0;
    double depth = soil->ground - m->node_pos0[k].z;
    double f = soil->method == VD_SOIL_CLAMP ? INFINITY : vd_soil_max_force(soil, depth, m->node_radius[k], area);
    int tie = vd_sim_add_tie(d, k, d->node_pos[k], soil->method == VD_SOIL_CLAMP ? 1e-9 : comp);
    if (tie < 0) {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      break;
    }
    s->node[s->n] = k, s->tie[s->n] = tie, s->fmax[s->n] = f;
    s->n++;
  }
  vd_free(pick, (size_t)(nn ? nn : 1));
  if (st) {
    vd_free(blk, nb);
    return st;
  }
  *out = s;
  return VD_OK;
}

void vd_sim_soil_update(const vd_sim_model* m, vd_sim_data* d, vd_sim_soil* s) {
  (void)m;
  if (!s) return;
  for (int k = 0; k < s->n; k++) {
    vd_sim_tie* t = &d->tie[s->tie[k]];
    vd_vec3 x = d->node_pos[t->node], e = vd_sub(x, t->target);
    double f = v_norm(e) / t->compliance;
    if (!(f > s->fmax[k])) continue;
    // slip: the anchor follows the node until the tie pulls with the node's resistance
    t->target = vd_sub(x, vd_scale(e, s->fmax[k] / f));
    if (!s->yielded[k]) s->yielded[k] = 1, s->nyielded++;
  }
}

void vd_sim_soil_destroy(vd_sim_soil* s) {
  if (s) vd_free(s, s->nbytes);
}
