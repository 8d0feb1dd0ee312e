// SPDX-License-Identifier: MIT
// One time step: loads, prediction, contact candidates, constraint projection (direct or
// Gauss-Seidel), velocities from the position change (implicit Euler, as XPBD), fracture
// checks. Settling runs steps until the plant is still, or solves statics directly.
#include "sim_internal.h"

const char* vd_sim_warning_name(vd_sim_warning w) {
  static const char* names[VD_SIM_WARN_COUNT] = {"nonfinite", "solver",    "strain", "substep",
                                                 "unstable",  "stretched", "arena"};
  return w >= 0 && w < VD_SIM_WARN_COUNT ? names[w] : "?";
}

// the per-element loops of a step, over ranges (sim_parallel runs them on opt.threads threads)
typedef struct loop_ctx {
  const vd_sim_model* m;
  vd_sim_data* d;
  sim_work* w;
  double h, fl, damp;
  int statics;
  double r[SIM_MAX_THREADS];  // per-chunk results (largest squared stretch, move, or 1 if not finite)
} loop_ctx;

// largest squared stretch |x_end - x_start|^2 / l0^2 of the free segments
static void stretch_range(void* p, int k, int t0, int t1) {
  loop_ctx* c = p;
  const vd_sim_model* m = c->m;
  const vd_sim_data* d = c->d;
  double r2 = 0;
  for (int t = t0; t < t1; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    vd_vec3 e = vd_sub(d->node_pos[m->seg_node[2 * t + 1]], d->node_pos[d->seg_start[t]]);
    double q = vd_dot(e, e) / (m->seg_len0[t] * m->seg_len0[t]);
    if (q > r2) r2 = q;
  }
  c->r[k] = r2;
}

// largest of the chunks' results
static double chunk_max(const loop_ctx* c, int nc) {
  double r = 0;
  for (int k = 0; k < nc; k++)
    if (c->r[k] > r) r = c->r[k];
  return r;
}

// largest stretch strain |x_end - x_start| / l0 - 1 of the free segments (-)
static double max_stretch(const vd_sim_model* m, vd_sim_data* d) {
  loop_ctx c = {m, d, (sim_work*)d->work, 0, 0, 0, 0, {0}};
  return sqrt(chunk_max(&c, sim_parallel(sim_threads(m), m->nseg, stretch_range, &c))) - 1;
}

// 1 in r[k] when a position or a frame in the range is not finite (nodes and segments both by t)
static void finite_range(void* p, int k, int i0, int i1) {
  loop_ctx* c = p;
  const vd_sim_model* m = c->m;
  const vd_sim_data* d = c->d;
  int bad = 0;
  for (int i = i0; i < i1; i++) {
    if (i < m->nnode_all) {
      vd_vec3 x = d->node_pos[i];
      bad |= !isfinite(x.x + x.y + x.z);
    }
    if (i < m->nseg) {
      vd_quat q = d->seg_quat[i];
      bad |= !isfinite(q.w + q.x + q.y + q.z);
    }
  }
  c->r[k] = bad;
}

// does the state hold only finite numbers?
static int finite_state(const vd_sim_model* m, vd_sim_data* d) {
  loop_ctx c = {m, d, (sim_work*)d->work, 0, 0, 0, 0, {0}};
  int n = m->nnode_all > m->nseg ? m->nnode_all : m->nseg;
  return chunk_max(&c, sim_parallel(sim_threads(m), n, finite_range, &c)) == 0;
}

// the step's start for nodes: keep the positions, predict them (x += h v), and the largest move
static void predict_nodes(void* p, int k, int i0, int i1) {
  loop_ctx* c = p;
  const vd_sim_model* m = c->m;
  vd_sim_data* d = c->d;
  sim_work* w = c->w;
  double h = c->h, fl = c->fl, mv = 0;
  for (int i = i0; i < i1; i++) {
    w->node_prev[i] = d->node_pos[i];
    if (c->statics) {
      d->node_vel[i] = vd_v3(0, 0, 0);
      continue;
    }
    if (!sim_node_moves(m, d, i)) continue;
    vd_vec3 v = d->node_vel[i];
    if (fl != 0) v = vd_madd(v, w->node_fext[i], fl / (d->node_mass[i] + h * w->node_drag[i]));
    vd_vec3 x = vd_madd(d->node_pos[i], v, h);
    vd_vec3 dx = vd_sub(x, w->node_prev[i]);
    double s = vd_dot(dx, dx);
    if (s > mv) mv = s;
    d->node_pos[i] = x;
  }
  c->r[k] = mv;
}

// ... for frames: keep them, predict them (q = exp(h omega) q)
static void predict_segs(void* p, int k, int t0, int t1) {
  loop_ctx* c = p;
  const vd_sim_model* m = c->m;
  vd_sim_data* d = c->d;
  sim_work* w = c->w;
  double h = c->h, fl = c->fl;
  (void)k;
  if (!c->statics && fl == 0) {
    sim_frame_predict(m, d, w, h, t0, t1);
    return;
  }
  for (int t = t0; t < t1; t++) {
    w->seg_prev[t] = d->seg_quat[t];
    if (c->statics) {
      d->seg_omega[t] = vd_v3(0, 0, 0);
      continue;
    }
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    vd_vec3 op = d->seg_omega[t];
    if (fl != 0) {
      // omega + h I^-1 (tau - omega x I omega), I = ib + (it - ib) d3 d3^T in world axes
      vd_vec3 d3 = quat_d3(d->seg_quat[t]);
      double ib = m->seg_inertia[2 * t], it = m->seg_inertia[2 * t + 1];
      vd_vec3 io = vd_madd(vd_scale(op, ib), d3, (it - ib) * vd_dot(d3, op));
      vd_vec3 tq = vd_sub(w->seg_text[t], vd_cross(op, io));
      vd_vec3 it_tq = vd_madd(vd_scale(tq, 1.0 / ib), d3, (1.0 / it - 1.0 / ib) * vd_dot(d3, tq));
      op = vd_madd(op, it_tq, fl);
    }
    d->seg_quat[t] = quat_rotate_by(d->seg_quat[t], vd_scale(op, h));
  }
}

// velocities from the step's motion (nodes and segments both by index)
static void velocity_range(void* p, int k, int i0, int i1) {
  loop_ctx* c = p;
  const vd_sim_model* m = c->m;
  vd_sim_data* d = c->d;
  const sim_work* w = c->w;
  double s = c->damp / c->h;
  (void)k;
  for (int i = i0; i < i1 && i < m->nnode_all; i++)
    d->node_vel[i] = !sim_node_moves(m, d, i) || c->statics ? vd_v3(0, 0, 0)
                                                            : vd_scale(vd_sub(d->node_pos[i], w->node_prev[i]), s);
  int t1 = i1 < m->nseg ? i1 : m->nseg;
  if (c->statics)
    for (int t = i0; t < t1; t++) d->seg_omega[t] = vd_v3(0, 0, 0);
  else if (i0 < t1)
    sim_frame_velocities(m, d, w, s, i0, t1);
}

void sim_detach(const vd_sim_model* m, vd_sim_data* d, int t) {
  int a = d->seg_start[t], k = m->seg_spare[t];
  double share = 0.5 * m->seg_mass[t];
  if (share < 1e-6) share = 1e-6;
  if (d->node_mass[a] > 2 * share) d->node_mass[a] -= share;
  d->node_mass[k] = share;
  d->node_pos[k] = d->node_pos[a];
  d->node_vel[k] = sim_node_moves(m, d, a) ? d->node_vel[a] : vd_v3(0, 0, 0);
  d->node_force[k] = vd_v3(0, 0, 0);
  d->seg_start[t] = k;
  d->seg_broken[t] = 1;
}

// detach segment t from its parent and record the event
static void break_joint(const vd_sim_model* m, vd_sim_data* d, int t, double force, double moment,
                        double cs, double cb, int cause) {
  int a = d->seg_start[t];
  sim_detach(m, d, t);
  double* lam = d->seg_lambda + 6 * t;
  lam[3] = lam[4] = lam[5] = 0;
  vd_sim_event* e = &d->event[d->nevent++];
  e->time = d->time;
  e->seg = t;
  e->node = a;
  e->label = m->seg_label[t];
  e->instance = m->seg_instance[t];
  e->cls = m->seg_class[t];
  e->force = force;
  e->moment = moment;
  e->cs = cs;
  e->cb = cb;
  e->cause = cause;
}

// can joint t not break? Bounds of what check_fracture computes, from the multipliers and the
// segment alone: force = |R lambda_s| / (h^2 l0) = |lambda_s| / (h^2 l0); moment = |G^T lambda_b|
// / h^2 with |G| = |J_l^-1(phi)| / l-bar <= (pi / 2) / l-bar for |phi| <= pi (log measure) and
// 1 / l-bar (quat measure); |C_s| <= |E| / l0 + 1; |C_b| <= pi / l-bar (log) or 4 / l-bar (quat).
// Each bound has a factor of 2 or 1 + 1e-9 to spare for rounding, so a joint they clear gives
// the same decision as the full evaluation (most joints, most steps: no joint evaluation)
static int cannot_break(const vd_sim_model* m, const vd_sim_data* d, int t, double h2) {
  const double* thr = m->seg_break + 4 * t;
  const double* lam = d->seg_lambda + 6 * t;
  const double slack = 1 + 1e-9;
  double l0 = m->seg_len0[t], lbar = m->seg_lbar[t];
  double fs = sqrt(lam[0] * lam[0] + lam[1] * lam[1] + lam[2] * lam[2]) / (h2 * l0) * slack;
  double mb = 2 * sqrt(lam[3] * lam[3] + lam[4] * lam[4] + lam[5] * lam[5]) / (h2 * lbar) * slack;
  if (!(fs <= thr[0]) || !(mb <= thr[1])) return 0;
  if (isfinite(thr[2])) {
    vd_vec3 e = vd_sub(d->node_pos[m->seg_node[2 * t + 1]], d->node_pos[d->seg_start[t]]);
    if (!((vd_norm(e) / l0 + 1) * slack <= thr[2])) return 0;
  }
  return !isfinite(thr[3]) || 4 / lbar * slack <= thr[3];
}

// the constraint force and moment of joint t in a step of h (h2 = h^2): the generalised forces
// J^T lambda / h^2 of its stretch-shear and bend-twist multipliers; j gets the joint's values
static void joint_load(const vd_sim_model* m, const vd_sim_data* d, int t, double h2, sim_joint* j, double* force,
                       double* moment) {
  const double* lam = d->seg_lambda + 6 * t;
  sim_joint_eval(m, d, t, j);
  vd_vec3 ms = vd_v3(lam[0] / h2, lam[1] / h2, lam[2] / h2);
  vd_vec3 mb = vd_v3(lam[3] / h2, lam[4] / h2, lam[5] / h2);
  *force = vd_norm(m3_tmul_v(j->a, ms));
  *moment = j->bend ? vd_norm(m3_tmul_v(j->g, mb)) : 0.0;
}

// joints whose force, moment or strain passed their threshold break (each once)
static void check_fracture(const vd_sim_model* m, vd_sim_data* d, double h) {
  double h2 = h * h;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_spare[t] < 0 || d->seg_broken[t] || (m->seg_flags[t] & VD_SIM_FIXED)) continue;
    if (cannot_break(m, d, t, h2)) continue;
    const double* thr = m->seg_break + 4 * t;
    sim_joint j;
    double force, moment;
    joint_load(m, d, t, h2, &j, &force, &moment);
    double cs = sqrt(j.c[0] * j.c[0] + j.c[1] * j.c[1] + j.c[2] * j.c[2]);
    double cb = sqrt(j.c[3] * j.c[3] + j.c[4] * j.c[4] + j.c[5] * j.c[5]);
    int cause = force > thr[0] ? 0 : moment > thr[1] ? 1 : cs > thr[2] ? 2 : cb > thr[3] ? 3 : -1;
    if (cause >= 0) break_joint(m, d, t, force, moment, cs, cb, cause);
  }
}

void vd_sim_joint_load(const vd_sim_model* m, const vd_sim_data* d, int seg, double* force, double* moment) {
  const sim_work* w = (const sim_work*)d->work;
  *force = *moment = 0;
  if (seg < 0 || seg >= m->nseg || d->seg_broken[seg] || m->seg_parent[seg] < 0 || !(w->h_last > 0)) return;
  sim_joint j;
  joint_load(m, d, seg, w->h_last * w->h_last, &j, force, moment);
}

// potential energy of the current state under the loads in w (J): elastic energy of every
// constraint and tie, minus the work of the external forces (torques: see torque_work, their
// potential is not single-valued once a segment turns past pi)
static double potential_energy(const vd_sim_model* m, const vd_sim_data* d, const sim_work* w) {
  double e = 0;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_flags[t] & VD_SIM_FIXED) continue;
    double c[6];
    sim_joint_values(m, d, t, c);
    for (int k = 0; k < 3; k++) e += 0.5 * c[k] * c[k] / m->seg_cs[3 * t + k];
    if (!d->seg_broken[t] && m->seg_parent[t] >= 0)
      for (int k = 0; k < 3; k++) e += 0.5 * c[3 + k] * c[3 + k] / m->seg_cb[3 * t + k];
  }
  int ntie = sim_tie_count(m, d);
  for (int k = 0; k < ntie; k++) {
    int n;
    vd_vec3 target;
    double comp;
    sim_tie_get(m, d, k, &n, &target, &comp);
    if (!sim_node_moves(m, d, n)) continue;
    vd_vec3 cc = vd_sub(d->node_pos[n], target);
    e += 0.5 * vd_dot(cc, cc) / comp;
  }
  for (int i = 0; i < m->nnode_all; i++)
    if (sim_node_moves(m, d, i)) e -= vd_dot(w->node_fext[i], d->node_pos[i]);
  return e;
}

// work of the external torques over the last step (rotations since the step's start)
static double torque_work(const vd_sim_model* m, const vd_sim_data* d, const sim_work* w) {
  double e = 0;
  for (int t = 0; t < m->nseg; t++)
    if (!(m->seg_flags[t] & VD_SIM_FIXED))
      e += vd_dot(w->seg_text[t], quat_log(vd_quat_mul(d->seg_quat[t], vd_quat_conj(w->seg_prev[t]))));
  return e;
}

// the step itself; statics: start from the current state, no inertia carried over. Returns -1,
// or the vd_sim_warning kind of a failure, with positions and frames put back (not counted)
static int step_core(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* cin) {
  sim_work* w = (sim_work*)d->work;
  sim_step_ctx c = *cin;
  double h = c.h;
  int na = m->nnode_all, ns = m->nseg, nt = sim_threads(m);
  double tp = sim_stage_start(d);
  c.tstage = &tp;
  vd_arena_reset(&d->arena);
  memset(w->col_imp, 0, sizeof w->col_imp);
  memset(w->col_ang, 0, sizeof w->col_ang);
  // the stretch at the start: a step may not double it beyond VD_SIM_MAX_STRAIN (a stretch the
  // state already had, e.g. from a contact holding a node, is not a new failure)
  double strain0 = c.statics ? 0 : max_stretch(m, d);
  sim_stage(d, VD_SIM_STAGE_VELOCITY, &tp);
  // loads at the start of the step
  sim_forces(m, d, w);
  sim_stage(d, VD_SIM_STAGE_FORCES, &tp);
  if (c.gamma > 0)
    for (int t = 0; t < ns; t++)
      if (!(m->seg_flags[t] & VD_SIM_FIXED) || (m->seg_flags[t] & VD_SIM_HELD)) sim_joint_values(m, d, t, w->c_prev + 6 * t);
  if (!c.statics) {
    // prediction: semi-implicit Euler on velocities, then positions and frames; air drag is
    // linearly implicit, m (v - v_n) = h (f_n - c (v - v_n)) with c = -dF/dv (w->node_drag):
    // explicit drag diverges once h c / m > 2, which light organs in wind reach at 1 ms.
    // The direct solver keeps the loads in its residual g and starts its Newton iterations
    // from the inertial motion alone (fl = 0): a node of 1e-8 kg carries no weight against its
    // rod, and starting it where wind and gravity alone would put it (centimetres off at 10 ms)
    // linearises its segment's rotation far from the solution
    memset(d->seg_lambda, 0, (size_t)ns * 6 * sizeof(double));
    memset(w->tie_lambda, 0, (size_t)w->cap_tie_lambda * 3 * sizeof(double));
  }
  // keep the state and predict it (statics: velocities zeroed)
  loop_ctx lc = {m, d, w, h, m->opt.solver == VD_SIM_GS ? h : 0.0, 0, c.statics, {0}};
  double vmax = sqrt(chunk_max(&lc, sim_parallel(nt, na, predict_nodes, &lc)));
  sim_parallel(nt, ns, predict_segs, &lc);
  sim_stage(d, VD_SIM_STAGE_PREDICT, &tp);
  // contact candidates near the predicted state
  c.contacts = NULL;
  c.ncontact = 0;
  if (m->opt.contacts && (d->ncollider || m->opt.self_collision)) {
    if (d->ncollider) c.ncontact = sim_contacts_find(m, d, 2 * vmax + 0.005, &c.contacts);
    // self-contacts: each primitive reaches twice its own nodes' displacement (sim_self.c)
    if (m->opt.self_collision) c.ncontact = sim_self_find(m, d, 0.002, c.contacts, c.ncontact, &c.contacts);
  }
  sim_stage(d, VD_SIM_STAGE_CONTACTS, &tp);
  // constraints
  // statics needs the primal residual that only the direct solver keeps
  int solved = 1;
  if (m->opt.solver == VD_SIM_GS && !c.statics) {
    sim_solve_gs(m, d, &c);
    sim_stage(d, VD_SIM_STAGE_SOLVE, &tp);
  } else {
    solved = sim_solve_direct(m, d, &c);
  }
  // contacts have the last word (no penetration), then friction
  d->ncontact = c.ncontact;
  d->max_penetration = 0;
  if (c.ncontact) {
    sim_contacts_project(m, d, c.contacts, c.ncontact, h);
    sim_contacts_friction(m, d, c.contacts, c.ncontact, h);
    for (int k = 0; k < c.ncontact; k++) {
      double s = sim_contact_gap(m, d, &c.contacts[k]);
      if (-s > d->max_penetration) d->max_penetration = -s;
    }
  }
  sim_stage(d, VD_SIM_STAGE_PROJECT, &tp);
  // a failed step: put the previous state back and say why; at the smallest substep a state
  // stretched up to VD_SIM_BLOWUP_STRAIN is kept (counted), beyond it the step fails
  int fail = !finite_state(m, d) ? VD_SIM_WARN_NONFINITE : !solved ? VD_SIM_WARN_SOLVER : -1;
  double strain = fail < 0 && !c.statics ? max_stretch(m, d) : 0;
  if (strain > VD_SIM_BLOWUP_STRAIN || (strain > VD_SIM_MAX_STRAIN && strain > 2 * strain0)) {
    if (!c.last || strain > VD_SIM_BLOWUP_STRAIN) fail = VD_SIM_WARN_STRAIN;
    else sim_warn(d, VD_SIM_WARN_STRAIN), sim_warn(d, VD_SIM_WARN_UNSTABLE);
  }
  w->strain = strain;
  if (fail >= 0) {
    memcpy(d->node_pos, w->node_prev, (size_t)na * sizeof(vd_vec3));
    memcpy(d->seg_quat, w->seg_prev, (size_t)ns * sizeof(vd_quat));
    return fail;
  }
  // velocities from the step's motion
  lc.damp = 1.0 / (1.0 + (m->opt.mass_damping + c.extra_damping) * h);
  sim_parallel(nt, na > ns ? na : ns, velocity_range, &lc);
  sim_stage(d, VD_SIM_STAGE_VELOCITY, &tp);
  if (!c.statics) w->h_last = h;
  if (m->opt.fracture && !c.statics) check_fracture(m, d, h);
  // the step's reactions on the colliders (impulses; vd_sim_step makes them forces)
  for (int k = 0; k < d->ncollider; k++) {
    d->collider_force[k] = vd_add(d->collider_force[k], w->col_imp[k]);
    d->collider_torque[k] = vd_add(d->collider_torque[k], w->col_ang[k]);
  }
  sim_stage(d, VD_SIM_STAGE_FRACTURE, &tp);
  for (int k = 0; k < d->ncollider; k++) d->collider[k].vel = vd_v3(0, 0, 0);
  d->time += c.statics ? 0.0 : h;
  return -1;
}

// a dynamic step of h; a failed one is retaken as two steps of h / 2, down to
// dt / 2^VD_SIM_MAX_SUBSTEP (smaller steps make the mass term M / h^2 dominate: the Newton
// iterations start closer to the solution and the matrices are better conditioned)
static vd_status step_retake(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* base, double h, int depth) {
  sim_step_ctx c = *base;
  c.h = h;
  c.gamma = m->opt.damping / h;
  c.last = depth == VD_SIM_MAX_SUBSTEP;
  int fail = step_core(m, d, &c);
  if (fail < 0) return VD_OK;
  sim_warn(d, fail);
  if (c.last) {
    sim_warn(d, VD_SIM_WARN_UNSTABLE);
    return VD_ERR_VALUE;
  }
  sim_warn(d, VD_SIM_WARN_SUBSTEP);
  vd_status st = step_retake(m, d, base, 0.5 * h, depth + 1);
  return st ? st : step_retake(m, d, base, 0.5 * h, depth + 1);
}

// collider reactions of the step(s) to come: impulses summed from zero (step_core)
static void reactions_begin(vd_sim_data* d) {
  memset(d->collider_force, 0, sizeof d->collider_force);
  memset(d->collider_torque, 0, sizeof d->collider_torque);
}

// ... divided by the time they span: mean forces and moments (N, N m)
static void reactions_end(vd_sim_data* d, double h) {
  for (int k = 0; k < d->ncollider; k++) {
    d->collider_force[k] = vd_scale(d->collider_force[k], 1.0 / h);
    d->collider_torque[k] = vd_scale(d->collider_torque[k], 1.0 / h);
  }
}

vd_status vd_sim_step(const vd_sim_model* m, vd_sim_data* d) {
  sim_step_ctx c;
  memset(&c, 0, sizeof c);
  reactions_begin(d);
  vd_status st = step_retake(m, d, &c, m->opt.dt, 0);
  reactions_end(d, m->opt.dt);
  if (!st) d->nstep++;
  if (!st && ((sim_work*)d->work)->strain > VD_SIM_MAX_STRAIN) sim_warn(d, VD_SIM_WARN_STRETCHED);
  return st;
}

vd_status vd_sim_step_batch(const vd_sim_model* m, vd_sim_data** d, int n, int nsteps, int threads,
                            vd_status* st) {
  int failed = 0;
  if (threads < 1) threads = 1;
  // one state per thread at a time; inner loops run on the calling thread (nested regions are
  // serial), so each state's arithmetic is that of vd_sim_step alone
#pragma omp parallel for num_threads(threads) if(threads > 1 && n > 1) schedule(dynamic, 1) reduction(| : failed)
  for (int i = 0; i < n; i++) {
    vd_status s = VD_OK;
    for (int k = 0; k < nsteps && !s; k++) s = vd_sim_step(m, d[i]);
    if (st) st[i] = s;
    failed |= s != VD_OK;
  }
  return failed ? VD_ERR_VALUE : VD_OK;
}

vd_sim_settle_def vd_sim_settle_def_default(void) {
  vd_sim_settle_def s;
  s.statics = 0;
  s.ke_tol = 1e-9;
  s.disp_tol = 1e-9;
  s.max_time = 10;
  s.max_steps = 400;
  s.extra_damping = 5;
  s.progress = NULL;
  s.user = NULL;
  return s;
}

vd_status vd_sim_settle(const vd_sim_model* m, vd_sim_data* d, const vd_sim_settle_def* s, int* converged,
                        int* steps) {
  sim_work* w = (sim_work*)d->work;
  int ok = 0, n = 0;
  vd_status st = VD_OK;
  if (!s->statics) {
    // dynamics with extra damping until the kinetic energy is small
    sim_step_ctx c;
    memset(&c, 0, sizeof c);
    c.extra_damping = s->extra_damping;
    // still means below the tolerance for a quarter second in a row (not one turning point)
    double t0 = d->time, calm = 0;
    while (d->time - t0 < s->max_time) {
      reactions_begin(d);
      st = step_retake(m, d, &c, m->opt.dt, 0);
      reactions_end(d, m->opt.dt);
      if (st) break;
      d->nstep++;
      if (w->strain > VD_SIM_MAX_STRAIN) sim_warn(d, VD_SIM_WARN_STRETCHED);
      n++;
      if (s->progress) s->progress(s->user, (d->time - t0) / s->max_time, n);
      calm = vd_sim_kinetic_energy(m, d) < s->ke_tol ? calm + m->opt.dt : 0;
      if (calm >= 0.25) {
        ok = 1;
        break;
      }
    }
  } else {
    // quasi-static steps (proximal Newton): a step that lowers the potential energy is kept
    // and h grows four-fold, one that raises it is undone and h shrinks; with h large the
    // inertial term M / h^2 vanishes and each step is a Newton step on the statics
    sim_step_ctx c;
    memset(&c, 0, sizeof c);
    c.statics = 1;
    c.h = 1.0;
    memset(d->seg_lambda, 0, (size_t)m->nseg * 6 * sizeof(double));
    memset(w->tie_lambda, 0, (size_t)w->cap_tie_lambda * 3 * sizeof(double));
    sim_forces(m, d, w);
    double e0 = potential_energy(m, d, w), hcap = 1e4;
    while (n < s->max_steps) {
      memcpy(w->lambda_save, d->seg_lambda, (size_t)m->nseg * 6 * sizeof(double));
      // a failed step (non-finite, failed factorisation) is undone like one that raises the
      // energy: h shrinks
      int kind = step_core(m, d, &c), fail = kind >= 0;
      if (fail) sim_warn(d, kind);
      else d->nstep++;
      n++;
      if (s->progress) s->progress(s->user, (double)n / s->max_steps, n);
      double e1 = fail ? INFINITY : potential_energy(m, d, w) - torque_work(m, d, w);
      // largest move of a node, or of a segment end by its rotation
      double mv = fail ? INFINITY : 0;
      for (int i = 0; !fail && i < m->nnode_all; i++) {
        double l = vd_norm(vd_sub(d->node_pos[i], w->node_prev[i]));
        if (l > mv) mv = l;
      }
      for (int t = 0; !fail && t < m->nseg; t++) {
        double l = vd_norm(quat_log(vd_quat_mul(d->seg_quat[t], vd_quat_conj(w->seg_prev[t])))) * m->seg_len0[t];
        if (l > mv) mv = l;
      }
      double hp = c.h, hn;
      if (e1 > e0 + 1e-12 * (fabs(e0) + 1e-12) && mv > s->disp_tol) {
        memcpy(d->node_pos, w->node_prev, (size_t)m->nnode_all * sizeof(vd_vec3));
        memcpy(d->seg_quat, w->seg_prev, (size_t)m->nseg * sizeof(vd_quat));
        memcpy(d->seg_lambda, w->lambda_save, (size_t)m->nseg * 6 * sizeof(double));
        hn = hp * 0.25;
        hcap = hp * 0.5;  // the trust region remembers the failure
        if (hn < 1e-5) {
          if (fail) st = VD_ERR_VALUE, sim_warn(d, VD_SIM_WARN_UNSTABLE);
          break;
        }
      } else {
        e0 = e1 + torque_work(m, d, w);
        if (mv < s->disp_tol) {
          ok = 1;
          break;
        }
        hn = hp * 4 > hcap ? hcap : hp * 4;
        if (hn < hp) hn = hp;
      }
      // multipliers are forces times h^2: keep the forces across the change of h
      double sc = (hn / hp) * (hn / hp);
      for (int k = 0; k < 6 * m->nseg; k++) d->seg_lambda[k] *= sc;
      for (int k = 0; k < 3 * w->cap_tie_lambda; k++) w->tie_lambda[k] *= sc;
      c.h = hn;
    }
    if (m->opt.fracture) check_fracture(m, d, c.h);
  }
  if (converged) *converged = ok;
  if (steps) *steps = n;
  return st;
}
