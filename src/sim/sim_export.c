// SPDX-License-Identifier: MIT
// The rods of a rod model as vd_geom_export wants them for a flexible plant: per rod segment its
// rest shape, its joint's stiffness, the mass lumped on its end node and its rotary inertia
// (docs/formats.md, "Flexible exports"; the derivation in docs/physics.md).
#include <math.h>
#include <string.h>

#include "sim_internal.h"

static size_t take(size_t* top, size_t bytes) {
  size_t at = *top;
  *top += (bytes + 15) & ~(size_t)15;
  return at;
}

// the rod segment most of plant mesh i's vertices ride on, -1 none
static int mesh_rod(const vd_sim_model* m, const vd_model* p, int i) {
  int v0 = p->mesh_vert[2 * i], nv = p->mesh_vert[2 * i + 1], best = -1, nbest = 0;
  if (v0 < 0 || v0 + nv > m->nbind_vert) return -1;
  // Boyer-Moore majority vote, then the candidate's count: vertices of a leaf ride on a few
  // neighbouring vein segments, and the vote picks the one most of them share when there is one
  int cand = -1, cnt = 0;
  for (int k = 0; k < nv; k++) {
    int t = m->bind_vert_seg[v0 + k];
    if (!cnt) cand = t, cnt = 1;
    else cnt += t == cand ? 1 : -1;
  }
  for (int k = 0; k < nv; k++)
    nbest += m->bind_vert_seg[v0 + k] == cand;
  if (nbest > 0) best = cand;
  else if (nv > 0) best = m->bind_vert_seg[v0];
  return best >= 0 && best < m->nseg ? best : -1;
}

vd_status vd_sim_export_rods(const vd_sim_model* m, const vd_model* plant, vd_export_rods* out,
                             vd_error* err) {
  memset(out, 0, sizeof *out);
  size_t ns = (size_t)m->nseg, nm = plant ? (size_t)plant->nmesh : 0, top = 0;
  size_t o_ends = take(&top, sizeof(double) * 6 * ns), o_rad = take(&top, sizeof(double) * ns);
  size_t o_quat = take(&top, sizeof(double) * 4 * ns), o_par = take(&top, sizeof(int) * ns);
  size_t o_fix = take(&top, sizeof(int) * ns), o_drawn = take(&top, sizeof(int) * ns);
  size_t o_lab = take(&top, sizeof(int) * ns), o_inst = take(&top, sizeof(int) * ns);
  size_t o_k = take(&top, sizeof(double) * 3 * ns), o_mass = take(&top, sizeof(double) * ns);
  size_t o_in = take(&top, sizeof(double) * 2 * ns), o_sph = take(&top, sizeof(double) * ns);
  size_t o_brk = take(&top, sizeof(double) * 2 * ns), o_mesh = take(&top, sizeof(int) * (nm + 1));
  char* b = vd_calloc(1, top);
  if (!b) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  double *ends = (double*)(b + o_ends), *rad = (double*)(b + o_rad), *quat = (double*)(b + o_quat);
  int *par = (int*)(b + o_par), *fix = (int*)(b + o_fix), *drawn = (int*)(b + o_drawn);
  int *lab = (int*)(b + o_lab), *inst = (int*)(b + o_inst), *mesh = (int*)(b + o_mesh);
  double *k = (double*)(b + o_k), *mass = (double*)(b + o_mass), *in = (double*)(b + o_in);
  double *sph = (double*)(b + o_sph), *brk = (double*)(b + o_brk);
  for (int t = 0; t < m->nseg; t++) {
    int n0 = m->seg_node[2 * t], n1 = m->seg_node[2 * t + 1];
    vd_vec3 a = m->node_pos0[n0], e = m->node_pos0[n1];
    double* x = ends + 6 * t;
    x[0] = a.x, x[1] = a.y, x[2] = a.z, x[3] = e.x, x[4] = e.y, x[5] = e.z;
    rad[t] = m->seg_radius[t];
    vd_quat q = m->seg_quat0[t];
    quat[4 * t] = q.w, quat[4 * t + 1] = q.x, quat[4 * t + 2] = q.y, quat[4 * t + 3] = q.z;
    par[t] = m->seg_parent[t];
    fix[t] = (m->seg_flags[t] & VD_SIM_FIXED) != 0;
    drawn[t] = !(m->seg_flags[t] & VD_SIM_FRUITSEG);
    lab[t] = m->seg_label[t], inst[t] = m->seg_instance[t];
    // the joint's energy is |C_b|^2 / (2 cb) with C_b = angle / l-bar: k = 1 / (cb l-bar^2)
    double lb = m->seg_lbar[t];
    for (int c = 0; c < 3; c++) {
      double cb = m->seg_cb[3 * t + c];
      k[3 * t + c] = cb > 0 && lb > 0 ? 1.0 / (cb * lb * lb) : 0.0;
    }
    int owns = n1 >= 0 && n1 < m->nnode && m->node_owner[n1] == t;
    mass[t] = owns ? m->node_mass[n1] : 0.0;
    sph[t] = owns && m->node_sphere ? m->node_sphere[n1] : 0.0;
    in[2 * t] = m->seg_inertia[2 * t], in[2 * t + 1] = m->seg_inertia[2 * t + 1];
    brk[2 * t] = m->seg_spare[t] >= 0 ? m->seg_break[4 * t] : INFINITY;
    brk[2 * t + 1] = m->seg_spare[t] >= 0 ? m->seg_break[4 * t + 1] : INFINITY;
  }
  for (size_t i = 0; i < nm; i++)
    mesh[i] = mesh_rod(m, plant, (int)i);
  *out = (vd_export_rods){.nseg = m->nseg, .seg_ends = ends, .seg_radius = rad, .seg_quat = quat,
                          .seg_parent = par, .seg_fixed = fix, .seg_drawn = drawn, .seg_label = lab,
                          .seg_instance = inst, .seg_stiff = k, .seg_mass = mass,
                          .seg_inertia = in, .seg_sphere = sph, .seg_break = brk,
                          .mesh_seg = mesh, .block = b, .nbytes = top};
  return VD_OK;
}

void vd_sim_export_rods_free(vd_export_rods* r) {
  if (r->block) vd_free(r->block, r->nbytes);
  memset(r, 0, sizeof *r);
}
