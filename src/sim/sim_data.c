// SPDX-License-Identifier: MIT
// The state of a rod model: creation in one block plus the solver's work block, reset,
// colliders and ties, organ lookup, energies, and writing the deformed plant back.
#include <strings.h>

#include "sim_internal.h"

static size_t take(size_t* top, size_t bytes) {
  size_t o = (*top + 15) & ~(size_t)15;
  *top = o + bytes;
  return o;
}

sim_work* sim_work_create(const vd_sim_model* m, size_t* bytes) {
  size_t na = (size_t)m->nnode_all, ns = (size_t)m->nseg;
  size_t nsp = m->nspare ? (size_t)m->nspare : 1, ntl = (size_t)m->ntie + 16;
  size_t D = sizeof(double), top = 0;
  size_t o_w = take(&top, sizeof(sim_work));
  size_t o_np = take(&top, na * sizeof(vd_vec3)), o_sp = take(&top, ns * sizeof(vd_quat));
  size_t o_fe = take(&top, na * sizeof(vd_vec3)), o_te = take(&top, ns * sizeof(vd_vec3)), o_dr = take(&top, na * D);
  size_t o_sdr = take(&top, ns * 5 * D);
  size_t o_cp = take(&top, ns * 6 * D), o_so = take(&top, nsp * sizeof(int)), o_ls = take(&top, ns * 6 * D);

  char* blk = vd_calloc(1, top);
  if (!blk) return NULL;
  sim_work* w = (sim_work*)(blk + o_w);
  w->node_prev = (vd_vec3*)(blk + o_np), w->seg_prev = (vd_quat*)(blk + o_sp);
  w->node_fext = (vd_vec3*)(blk + o_fe), w->seg_text = (vd_vec3*)(blk + o_te), w->node_drag = (double*)(blk + o_dr);
  w->seg_drag = (double*)(blk + o_sdr);
  w->c_prev = (double*)(blk + o_cp), w->spare_of = (int*)(blk + o_so), w->lambda_save = (double*)(blk + o_ls);

  w->tie_lambda = vd_calloc(ntl, 3 * D);
  if (!w->tie_lambda || sim_plan_build(m, 1, &w->plan)) {
    vd_free(w->tie_lambda, ntl * 3 * D);
    vd_free(blk, top);
    return NULL;
  }
  w->cap_tie_lambda = (int)ntl;
  w->model_ties = m->ntie;
  // self-collision primitives and their exclusion, from the modelled shape
  vd_error err;
  if (sim_self_init(m, &w->self, &err)) {
    sim_plan_free(&w->plan);
    vd_free(w->tie_lambda, ntl * 3 * D);
    vd_free(blk, top);
    return NULL;
  }
  for (int t = 0; t < m->nseg; t++)
    if (m->seg_spare[t] >= 0) w->spare_of[m->seg_spare[t] - m->nnode] = t;
  *bytes = top;
  return w;
}

static void work_free(sim_work* w, size_t bytes) {
  if (!w) return;
  sim_self_free(&w->self);
  sim_plan_free(&w->plan);
  vd_free(w->tie_lambda, (size_t)w->cap_tie_lambda * 3 * sizeof(double));
  vd_free(w, bytes);
}

vd_sim_data* vd_sim_data_create(const vd_sim_model* m) {
  size_t na = (size_t)m->nnode_all, ns = (size_t)m->nseg, top = 0;
  size_t V = sizeof(vd_vec3), Q = sizeof(vd_quat), D = sizeof(double), I = sizeof(int);
  size_t o_d = take(&top, sizeof(vd_sim_data));
  size_t o_p = take(&top, na * V), o_v = take(&top, na * V), o_f = take(&top, na * V), o_m = take(&top, na * D);
  size_t o_q = take(&top, ns * Q), o_o = take(&top, ns * V), o_t = take(&top, ns * V);
  size_t o_l = take(&top, ns * 6 * D), o_b = take(&top, ns * I), o_s = take(&top, ns * I);
  size_t o_e = take(&top, (ns ? ns : 1) * sizeof(vd_sim_event));
  char* blk = vd_calloc(1, top);
  if (!blk) return NULL;
  vd_sim_data* d = (vd_sim_data*)(blk + o_d);
  d->nbytes = top;
  d->nnode_all = m->nnode_all, d->nseg = m->nseg;
  d->node_pos = (vd_vec3*)(blk + o_p), d->node_vel = (vd_vec3*)(blk + o_v);
  d->node_force = (vd_vec3*)(blk + o_f), d->node_mass = (double*)(blk + o_m);
  d->seg_quat = (vd_quat*)(blk + o_q), d->seg_omega = (vd_vec3*)(blk + o_o);
  d->seg_torque = (vd_vec3*)(blk + o_t), d->seg_lambda = (double*)(blk + o_l);
  d->seg_broken = (int*)(blk + o_b), d->seg_start = (int*)(blk + o_s);
  d->event = (vd_sim_event*)(blk + o_e);
  d->work = sim_work_create(m, &d->work_bytes);
  if (!d->work) {
    vd_free(blk, top);
    return NULL;
  }
  vd_arena_init(&d->arena, 0);
  vd_sim_data_reset(m, d);
  return d;
}

void vd_sim_data_reset(const vd_sim_model* m, vd_sim_data* d) {
  // modelled shape at rest; spare nodes unused (no mass) until their joint breaks
  int na = m->nnode_all, ns = m->nseg;
  for (int i = 0; i < na; i++) {
    d->node_pos[i] = i < m->nnode ? m->node_pos0[i] : vd_v3(0, 0, 0);
    d->node_mass[i] = i < m->nnode ? m->node_mass[i] : 0.0;
  }
  memset(d->node_vel, 0, (size_t)na * sizeof(vd_vec3));
  memset(d->node_force, 0, (size_t)na * sizeof(vd_vec3));
  memcpy(d->seg_quat, m->seg_quat0, (size_t)ns * sizeof(vd_quat));
  memset(d->seg_omega, 0, (size_t)ns * sizeof(vd_vec3));
  memset(d->seg_torque, 0, (size_t)ns * sizeof(vd_vec3));
  memset(d->seg_lambda, 0, (size_t)ns * 6 * sizeof(double));
  memset(d->seg_broken, 0, (size_t)ns * sizeof(int));
  for (int t = 0; t < ns; t++) d->seg_start[t] = m->seg_node[2 * t];
  sim_work* w = (sim_work*)d->work;
  memset(w->tie_lambda, 0, (size_t)w->cap_tie_lambda * 3 * sizeof(double));
  w->self.have_pairs = 0;
  d->time = 0;
  d->nstep = 0;
  d->nevent = 0;
  d->ncontact = 0;
  d->max_penetration = 0;
  d->nwarning = 0;
  memset(d->warning, 0, sizeof d->warning);
  memset(d->stage_seconds, 0, sizeof d->stage_seconds);
}

void vd_sim_data_destroy(vd_sim_data* d) {
  if (!d) return;
  work_free((sim_work*)d->work, d->work_bytes);
  vd_free(d->tie, (size_t)d->cap_tie * sizeof(vd_sim_tie));
  vd_arena_free(&d->arena);
  vd_free(d, d->nbytes);
}

// ---------------------------------------------------------------------------------------------
// colliders and ties

int vd_sim_add_collider(vd_sim_data* d, const vd_sim_collider* c) {
  if (d->ncollider >= VD_SIM_MAX_COLLIDERS) return -1;
  d->collider[d->ncollider] = *c;
  d->collider[d->ncollider].quat = q_normalize(c->quat);
  d->collider_force[d->ncollider] = d->collider_torque[d->ncollider] = vd_v3(0, 0, 0);
  d->collider_pass[d->ncollider] = -1;
  return d->ncollider++;
}

void vd_sim_set_collider_pose(const vd_sim_model* m, vd_sim_data* d, int i, vd_vec3 pos, vd_quat q) {
  VD_ASSERT(i >= 0 && i < d->ncollider);
  vd_sim_collider* c = &d->collider[i];
  c->vel = vd_scale(vd_sub(pos, c->pos), 1.0 / m->opt.dt);
  c->pos = pos;
  c->quat = q_normalize(q);
}

int vd_sim_add_tie(vd_sim_data* d, int node, vd_vec3 target, double compliance) {
  VD_ASSERT(node >= 0 && node < d->nnode_all && compliance > 0);
  sim_work* w = (sim_work*)d->work;
  if (!vd_grow((void**)&d->tie, &d->cap_tie, d->ntie + 1, sizeof(vd_sim_tie))) return -1;
  // one multiplier row per tie in the work block (model ties first)
  int rows = w->model_ties + d->ntie + 1;
  if (rows > w->cap_tie_lambda) {
    int cap = 2 * rows;
    double* nl = vd_realloc(w->tie_lambda, (size_t)w->cap_tie_lambda * 3 * sizeof(double),
                            (size_t)cap * 3 * sizeof(double));
    if (!nl) return -1;
    memset(nl + 3 * (size_t)w->cap_tie_lambda, 0, (size_t)(cap - w->cap_tie_lambda) * 3 * sizeof(double));
    w->tie_lambda = nl;
    w->cap_tie_lambda = cap;
  }
  vd_sim_tie* t = &d->tie[d->ntie];
  memset(t, 0, sizeof *t);
  t->node = node, t->target = target, t->compliance = compliance;
  return d->ntie++;
}

void sim_tie_limit(const vd_sim_model* m, vd_sim_data* d, int k) {
  if (k < m->ntie) return;
  vd_sim_tie* t = &d->tie[k - m->ntie];
  if (!(t->max_force > 0)) return;
  vd_vec3 c = vd_sub(d->node_pos[t->node], t->target);
  vd_vec3 ct = vd_sub(c, vd_scale(t->axis, vd_dot(c, t->axis)));  // across the axis
  double n = vd_norm(ct), lim = t->max_force * t->compliance;
  if (n <= lim) return;
  vd_vec3 shift = vd_scale(ct, 1 - lim / n);
  t->target = vd_add(t->target, shift);
  t->slip += vd_norm(shift);
}

int sim_tie_count(const vd_sim_model* m, const vd_sim_data* d) {
  const sim_work* w = (const sim_work*)d->work;
  int n = m->ntie + d->ntie;
  return n < w->cap_tie_lambda ? n : w->cap_tie_lambda;  // equal unless out of memory
}

void sim_tie_get(const vd_sim_model* m, const vd_sim_data* d, int k, int* node, vd_vec3* target,
                 double* compliance) {
  if (k < m->ntie) {
    *node = m->tie_node[k], *target = m->tie_anchor[k], *compliance = m->tie_compliance[k];
  } else {
    const vd_sim_tie* t = &d->tie[k - m->ntie];
    *node = t->node, *target = t->target, *compliance = t->compliance;
  }
}

// ---------------------------------------------------------------------------------------------
// queries

int vd_sim_find_organ(const vd_sim_model* m, const vd_model* plant, const char* label, int instance) {
  // label ids whose name (or organ name) matches
  int ids[256], nid = 0;
  for (int i = 0; i < plant->nlabel && nid < 256; i++)
    if (!strcasecmp(plant->labels[i].name, label) || !strcasecmp(vd_organ_name(plant->labels[i].organ), label))
      ids[nid++] = plant->labels[i].id;
  if (!nid) return -1;
  // spheres first: a fruit's centre
  int best = -1, best_inst = 0;
  for (int k = 0; k < plant->nsphere; k++) {
    int l = plant->sphere_label[k], in = plant->sphere_instance[k];
    int ok = 0;
    for (int i = 0; i < nid; i++) ok |= ids[i] == l;
    if (!ok || m->bind_sphere_node[k] < 0) continue;
    if (instance ? in == instance : (best < 0 || in < best_inst)) best = m->bind_sphere_node[k], best_inst = in;
    if (instance && in == instance) return best;
  }
  if (best >= 0) return best;
  // segments: the end node farthest from the root along the organ (largest index = latest)
  int pick_inst = instance;
  if (!pick_inst) {
    for (int t = 0; t < m->nseg; t++) {
      int ok = 0;
      for (int i = 0; i < nid; i++) ok |= ids[i] == m->seg_label[t];
      if (ok && (!pick_inst || m->seg_instance[t] < pick_inst)) pick_inst = m->seg_instance[t];
    }
  }
  int node = -1;
  for (int oi = m->nseg - 1; oi >= 0; oi--) {
    int t = m->seg_order[oi];
    int ok = 0;
    for (int i = 0; i < nid; i++) ok |= ids[i] == m->seg_label[t];
    if (ok && m->seg_instance[t] == pick_inst && !(m->seg_flags[t] & VD_SIM_FIXED)) node = m->seg_node[2 * t + 1];
  }
  return node;
}

double vd_sim_kinetic_energy(const vd_sim_model* m, const vd_sim_data* d) {
  double e = 0;
  for (int i = 0; i < m->nnode_all; i++)
    if (sim_node_moves(m, d, i)) e += 0.5 * d->node_mass[i] * vd_dot(d->node_vel[i], d->node_vel[i]);
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    vd_vec3 w = q_rotate(q_conj(d->seg_quat[t]), d->seg_omega[t]);
    double ib = m->seg_inertia[2 * t], it = m->seg_inertia[2 * t + 1];
    e += 0.5 * (ib * (w.x * w.x + w.y * w.y) + it * w.z * w.z);
  }
  return e;
}

double vd_sim_max_displacement(const vd_sim_model* m, const vd_sim_data* d, int* node) {
  double best = 0;
  int bi = -1;
  for (int i = 0; i < m->nnode; i++) {
    double l = v_norm(vd_sub(d->node_pos[i], m->node_pos0[i]));
    if (l > best) best = l, bi = i;
  }
  if (node) *node = bi;
  return best;
}

// ---------------------------------------------------------------------------------------------
// the deformed plant

// position of a point bound to segment t with a local offset from its modelled start node
static vd_vec3 bound_point(const vd_sim_model* m, const vd_sim_data* d, int t, vd_vec3 local) {
  int a = m->seg_node[2 * t];
  // after a break the segment hangs from its spare; the offset stays relative to the frame
  vd_vec3 base = d->node_pos[d->seg_start[t] >= 0 ? d->seg_start[t] : a];
  return vd_add(base, q_rotate(d->seg_quat[t], local));
}

static vd_vec3 plant_node_pos(const vd_sim_model* m, const vd_sim_data* d, int i, vd_vec3 rest) {
  if (m->bind_node_ref[i] >= 0) return d->node_pos[m->bind_node_ref[i]];
  if (m->bind_node_seg[i] >= 0) return bound_point(m, d, m->bind_node_seg[i], m->bind_node_local[i]);
  return rest;
}

static vd_quat plant_seg_quat(const vd_sim_model* m, const vd_sim_data* d, int j, vd_quat rest) {
  int t = m->bind_seg_seg[j];
  return t >= 0 ? q_normalize(q_mul(d->seg_quat[t], m->bind_seg_local[j])) : rest;
}

void vd_sim_to_plant(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant, vd_data* out) {
  VD_ASSERT(plant->nnode == m->nbind_node && plant->nseg == m->nbind_seg);
  for (int i = 0; i < plant->nnode; i++) {
    vd_vec3 r = vd_v3(plant->node_pos0[3 * i], plant->node_pos0[3 * i + 1], plant->node_pos0[3 * i + 2]);
    vd_vec3 p = plant_node_pos(m, d, i, r);
    out->node_pos[3 * i] = p.x, out->node_pos[3 * i + 1] = p.y, out->node_pos[3 * i + 2] = p.z;
  }
  for (int j = 0; j < plant->nseg; j++) {
    const double* q0 = plant->seg_quat0 + 4 * j;
    vd_quat q = plant_seg_quat(m, d, j, (vd_quat){q0[0], q0[1], q0[2], q0[3]});
    out->seg_quat[4 * j] = q.w, out->seg_quat[4 * j + 1] = q.x, out->seg_quat[4 * j + 2] = q.y;
    out->seg_quat[4 * j + 3] = q.z;
  }
  for (int k = 0; k < plant->nsphere; k++) {
    int n = m->bind_sphere_node[k];
    if (n < 0) continue;
    vd_vec3 p = d->node_pos[n];
    out->sphere_pos[3 * k] = p.x, out->sphere_pos[3 * k + 1] = p.y, out->sphere_pos[3 * k + 2] = p.z;
  }
  for (int v = 0; v < plant->nvert; v++) {
    int t = m->bind_vert_seg[v];
    if (t < 0) continue;
    vd_vec3 p = bound_point(m, d, t, m->bind_vert_local[v]);
    out->vert_pos[3 * v] = p.x, out->vert_pos[3 * v + 1] = p.y, out->vert_pos[3 * v + 2] = p.z;
  }
  sim_plant_cuts(m, d, plant, out);  // broken segments and where they broke (sim_pieces.c)
}

vd_status vd_sim_to_spec(const vd_sim_model* m, const vd_sim_data* d, vd_plant_spec* spec) {
  VD_ASSERT(spec->nnode == m->nbind_node && spec->nseg == m->nbind_seg);
  for (int i = 0; i < spec->nnode; i++) spec->node[i] = plant_node_pos(m, d, i, spec->node[i]);
  for (int j = 0; j < spec->nseg; j++) {
    int t = m->bind_seg_seg[j];
    if (t < 0) continue;
    // the section's up vector turns with the rod segment
    vd_quat rot = q_mul(d->seg_quat[t], q_conj(m->seg_quat0[t]));
    spec->seg[j].up = q_rotate(rot, spec->seg[j].up);
  }
  for (int k = 0; k < spec->nsphere; k++)
    if (m->bind_sphere_node[k] >= 0) spec->sphere[k].center = d->node_pos[m->bind_sphere_node[k]];
  for (int v = 0; v < spec->nvert; v++)
    if (m->bind_vert_seg[v] >= 0) spec->vert[v] = bound_point(m, d, m->bind_vert_seg[v], m->bind_vert_local[v]);
  return sim_spec_pieces(m, d, spec);  // parts that broke off become pieces of their own
}
