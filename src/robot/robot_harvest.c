// SPDX-License-Identifier: MIT
// Harvest episodes: the coupling loop of robot and plant, the grasp (touch, tie, slip, release),
// detachment and the other outcomes, observations and the summary.
//
// One robot step (the MJCF's timestep):
//   mj_step1 (positions, velocities, the servos' bias forces) -> gravity compensation of the arm
//   -> every robot collider's pose -> nsub plant steps, the collider poses (and the grasp tie's
//   target) interpolated from the previous robot step's poses to these -> the colliders' contact
//   forces, averaged over the substeps -> two-way: their reactions (and the held fruit's pull)
//   as xfrc_applied on the robot bodies -> mj_step2.
// The plant thus sees the robot one robot step late (2 ms with the bundled robots), and the
// robot feels the plant's reaction of the step before: the usual explicit co-simulation.
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "robot_internal.h"


#define KROT 2.0  // torsion spring of the grasp: k = KROT I / h^2 (explicit; stable below 4)
#define GRIP_SPEED 0.02  // finger target speed (m/s): closes 20 mm in a second

const char* vd_harvest_phase_name(vd_harvest_phase p) {
  static const char* n[VD_PHASE_COUNT] = {"external", "approach", "reach", "close",
                                          "detach",   "hold",     "done"};
  return p >= 0 && p < VD_PHASE_COUNT ? n[p] : "?";
}

const char* vd_harvest_site_name(vd_harvest_site s) {
  static const char* n[VD_SITE_COUNT] = {"none", "calyx", "abscission", "elsewhere"};
  return s >= 0 && s < VD_SITE_COUNT ? n[s] : "?";
}

const char* vd_harvest_event_name(vd_harvest_event_kind k) {
  static const char* n[VD_EV_KIND_COUNT] = {"phase",  "touch",  "grasp", "slip", "release",
                                            "fracture", "detach", "hit",  "drop", "ik"};
  return k >= 0 && k < VD_EV_KIND_COUNT ? n[k] : "?";
}

// ---------------------------------------------------------------------------------------------
// events and the end

vd_harvest_event* harvest_event(vd_harvest* h, vd_harvest_event_kind k, double value, int seg,
                                int instance) {
  // out of memory: this event and every later one dropped (the log stays a true prefix)
  if (h->ev_dropped || !vd_grow((void**)&h->ev, &h->cap_ev, h->nev + 1, sizeof *h->ev)) {
    h->ev_dropped++;
    return NULL;
  }
  vd_harvest_event* e = &h->ev[h->nev++];
  memset(e, 0, sizeof *e);
  e->time = h->sd->time;
  e->kind = k;
  e->value = value;
  e->seg = seg;
  e->instance = instance;
  e->cls = seg >= 0 ? h->sm->seg_class[seg] : -1;
  return e;
}

void vd_harvest_set_phase(vd_harvest* h, vd_harvest_phase p) {
  if (h->phase == p) return;
  h->phase = p;
  harvest_event(h, VD_EV_PHASE, p, -1, 0);
}

void harvest_finish(vd_harvest* h, const char* reason) {
  if (h->done) return;
  h->done = 1;
  if (reason != h->reason) snprintf(h->reason, sizeof h->reason, "%s", reason);
  if (h->phase != VD_PHASE_EXTERNAL) vd_harvest_set_phase(h, VD_PHASE_DONE);
}

void vd_harvest_end(vd_harvest* h, const char* reason) {
  harvest_finish(h, reason && *reason ? reason : "ended");
}

// remove the grasp tie (the last user tie of the state) and let the fingers touch the fruit again
static void tie_remove(vd_harvest* h) {
  if (h->tie >= 0 && h->tie < h->sd->ntie) {
    h->sd->tie[h->tie] = h->sd->tie[h->sd->ntie - 1];
    h->sd->ntie--;
  }
  h->tie = -1;
  for (int k = 0; k < h->ncol; k++) h->sd->collider_pass[h->col[k].sim] = -1;
  if (h->target >= 0) h->sd->seg_torque[h->fruit[h->target].seg] = vd_v3(0, 0, 0);
  h->held = 0;
}

void harvest_release(vd_harvest* h) {
  if (!h->held) return;
  tie_remove(h);
  harvest_event(h, VD_EV_RELEASE, 0, -1, h->target >= 0 ? h->fruit[h->target].instance : 0);
}

// ---------------------------------------------------------------------------------------------
// creation and reset

static void harvest_free_parts(vd_harvest* h) {
  robot_free(h);
  if (h->sm) vd_free(h->on, (size_t)h->sm->nseg + 1);
  vd_free(h->fwin, (size_t)h->fwin_cap * sizeof *h->fwin);
  vd_sim_data_destroy(h->sd);
  vd_sim_model_destroy(h->sm);
  vd_free(h->ev, (size_t)h->cap_ev * sizeof *h->ev);
  vd_scene_free(&h->scene);
  vd_robot_destroy(h->own_rb);
}

void vd_harvest_destroy(vd_harvest* h) {
  if (!h) return;
  harvest_free_parts(h);
  vd_free(h, sizeof *h);
}

// Before the first step: no robot geom may start inside the plant (its modelled shape) deeper
// than START_OVERLAP; the plant would be blown apart by the first contact projection. The error
// names the geom, the organ and the depth.
#define START_OVERLAP 1e-3  // (m)
static vd_status start_pose_check(const vd_harvest* h, vd_error* err) {
  const vd_sim_model* sm = h->sm;
  const vd_sim_data* sd = h->sd;
  for (int k = 0; k < h->ncol; k++) {
    const vd_collider* c = &h->col[k].shape;
    vd_vec3 lo, hi;
    vd_collider_bounds(c, &lo, &hi);
    double worst = -START_OVERLAP;
    int seg = -1, sphere = 0;
    for (int t = 0; t < sm->nseg; t++) {
      int a = sm->seg_node[2 * t], b = sm->seg_node[2 * t + 1];
      vd_vec3 pa = sd->node_pos[a], pb = sd->node_pos[b];
      double r = sm->seg_radius[t];
      if (fmin(pa.x, pb.x) - r > hi.x || fmax(pa.x, pb.x) + r < lo.x || fmin(pa.y, pb.y) - r > hi.y ||
          fmax(pa.y, pb.y) + r < lo.y || fmin(pa.z, pb.z) - r > hi.z || fmax(pa.z, pb.z) + r < lo.z)
        continue;
      double d = vd_collide_capsule(c, pa, pb, r, r).dist;
      if (d < worst) worst = d, seg = t, sphere = 0;
      double rs = sm->node_sphere[b];
      if (rs > 0 && (d = vd_collide_sphere(c, pb, rs).dist) < worst) worst = d, seg = t, sphere = 1;
    }
    if (seg < 0) continue;
    const mjModel* m = h->m;
    const char* gname = mj_id2name(m, mjOBJ_GEOM, h->col[k].geom);
    const char* bname = mj_id2name(m, mjOBJ_BODY, h->col[k].body);
    return vd_error_set(err, VD_ERR_VALUE, h->scene.path, 0, 0,
                        "the robot starts inside the plant: geom '%s' (body '%s') overlaps %s %d "
                        "(%s) by %.1f mm at q0; move robot.base (now %.3f, %.3f, %.3f m) or the plant",
                        gname ? gname : "(unnamed)", bname ? bname : "(unnamed)",
                        vd_sim_class_name((vd_sim_class)sm->seg_class[seg]), sm->seg_instance[seg],
                        sphere ? "its sphere" : "a segment", -worst * 1e3, h->scene.base_pos.x,
                        h->scene.base_pos.y, h->scene.base_pos.z);
  }
  return VD_OK;
}

vd_status vd_harvest_create(const vd_scene* scene, const vd_model* plant, vd_harvest** out,
                            vd_error* err) {
  *out = NULL;
  vd_robot* rb;
  vd_status st = vd_robot_load(scene, &rb, err);
  if (st) return st;
  st = vd_harvest_create_with(scene, rb, plant, out, err);
  if (st || !*out) {
    vd_robot_destroy(rb);
    return st ? st : vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  (*out)->own_rb = rb;
  return VD_OK;
}

static int reachable(vd_harvest* h, int f, double* ik_err);

// move the robot's root body by d and bring the data and the collider shapes along
static vd_status move_base(vd_harvest* h, vd_vec3 d, vd_error* err) {
  int r = h->rb->root_body;
  double* bp = h->m->body_pos + 3 * r;
  bp[0] += d.x, bp[1] += d.y, bp[2] += d.z;
  h->scene.base_pos = vd_v3(bp[0], bp[1], bp[2]);
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap)) return vd_mj_trap_status(&trap, err);
  mj_forward(h->m, h->d);
  vd_mj_trap_end(&trap);
  for (int k = 0; k < h->ncol; k++)
    h->col[k].cur = h->col[k].prev = h->col[k].shape.pose = robot_geom_pose(h->m, h->d, h->col[k].geom);
  return VD_OK;
}

// robot.base.auto: the base slides along its row (the base frame's y axis) and lifts (z) so that
// the end effector at q0 is level with a fruit and in line with it along the row; its distance
// from the row (along the base's x) and its yaw stay the scene's, as a greenhouse pipe-rail
// trolley with a lift. The fruit: the scene's target; else the first, in order of their
// distance across the row from the end effector (the plant's side the robot faces), that the
// arm reaches from there without starting inside the plant. None such: the first (reset then
// says why no fruit is reachable).
static vd_status place_base(vd_harvest* h, vd_error* err) {
  if (!h->nfruit) return VD_OK;
  // the robot at q0, gripper open, as an episode starts
  for (int k = 0; k < h->rb->narm; k++) h->d->qpos[h->rb->arm_qpos[k]] = h->q0[k];
  for (int k = 0; k < 2; k++) h->d->qpos[h->rb->grip_qpos[k]] = h->scene.gripper_open;
  vd_status st = move_base(h, vd_v3(0, 0, 0), err);
  if (st) return st;
  vd_vec3 ee;
  robot_site_pose(h, h->d, &ee, NULL);
  double yaw = h->scene.base_yaw;
  vd_vec3 across = vd_v3(cos(yaw), sin(yaw), 0), row = vd_v3(-sin(yaw), cos(yaw), 0);
  int* order = vd_malloc((size_t)h->nfruit * sizeof(int));
  double* key = vd_malloc((size_t)h->nfruit * sizeof(double));
  if (!order || !key) {
    vd_free(order, (size_t)h->nfruit * sizeof(int));
    vd_free(key, (size_t)h->nfruit * sizeof(double));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  int n = 0;
  for (int f = 0; f < h->nfruit; f++) {
    if (h->scene.target_instance > 0 && h->fruit[f].instance != h->scene.target_instance) continue;
    vd_vec3 p = h->sd->node_pos[h->fruit[f].node];
    key[f] = fabs(vd_dot(vd_sub(p, ee), across)) + 1e-6 * p.z;
    int i = n++;
    for (; i > 0 && key[order[i - 1]] > key[f]; i--) order[i] = order[i - 1];
    order[i] = f;
  }
  vd_vec3 moved = vd_v3(0, 0, 0), first = moved;
  int placed = 0;
  for (int i = 0; !st && i < n && !placed; i++) {
    vd_vec3 p = h->sd->node_pos[h->fruit[order[i]].node];
    // ee: the end effector at the scene's base; want: the base's move that lines it up
    vd_vec3 want = vd_madd(vd_v3(0, 0, p.z - ee.z), row, vd_dot(vd_sub(p, ee), row));
    if (i == 0) first = want;
    st = move_base(h, vd_sub(want, moved), err);
    moved = want;
    double e;
    vd_error quiet = {0};
    placed = !st && reachable(h, order[i], &e) && start_pose_check(h, &quiet) == VD_OK;
  }
  if (!st && !placed && n) st = move_base(h, vd_sub(first, moved), err);
  vd_free(order, (size_t)h->nfruit * sizeof(int));
  vd_free(key, (size_t)h->nfruit * sizeof(double));
  return st;
}

vd_status vd_harvest_create_with(const vd_scene* scene, const vd_robot* robot, const vd_model* plant,
                                 vd_harvest** out, vd_error* err) {
  *out = NULL;
  if (!robot_matches(robot, scene))
    return vd_error_set(err, VD_ERR_ARG, scene->path, 0, 0,
                        "the robot was loaded for %s (site '%s', fingers '%s', '%s'), the scene names "
                        "%s (site '%s', fingers '%s', '%s')",
                        robot->path, robot->ee_site_name, robot->gripper_name[0], robot->gripper_name[1],
                        scene->robot_path, scene->ee_site, scene->gripper[0], scene->gripper[1]);
  vd_mj_trap_install();
  vd_harvest* h = vd_calloc(1, sizeof *h);
  if (!h) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  h->tie = -1;
  h->target = -1;
  h->rb = robot;
  vd_status st = vd_scene_copy(scene, &h->scene, err);
  if (st) {
    vd_free(h, sizeof *h);
    return st;
  }
  h->plant = plant;
  // the plant's rods, then the robot (its geoms become the plant's colliders)
  st = vd_sim_build(plant, &h->scene.sim_def, &h->sm, err);
  if (!st) {
    h->sm->opt = h->scene.sim_opt;
    h->sd = vd_sim_data_create(h->sm);
    h->on = vd_malloc((size_t)h->sm->nseg + 1);
    double steps = VD_HARVEST_FORCE_WINDOW / h->sm->opt.dt;
    h->fwin_cap = steps < 1e6 ? (int)ceil(steps) + 1 : 1000001;
    h->fwin = vd_malloc((size_t)h->fwin_cap * sizeof *h->fwin);
    if (!h->sd || !h->on || !h->fwin) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory (plant state)");
  }
  if (!st) st = robot_attach(h, err);
  if (!st && isfinite(h->scene.ground)) {
    vd_sim_collider g;
    memset(&g, 0, sizeof g);
    g.shape = VD_SIM_PLANE;
    g.pos = vd_v3(0, 0, h->scene.ground);
    g.quat = vd_quat_identity();
    if (vd_sim_add_collider(h->sd, &g) < 0)
      st = vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "no room for the ground collider");
  }
  if (!st) {
    vd_mj_trap trap;
    if (VD_MJ_TRY(&trap)) {
      mj_forward(h->m, h->d);
      vd_mj_trap_end(&trap);
    } else {
      st = vd_mj_trap_status(&trap, err);
    }
  }
  if (!st) st = robot_colliders(h, err);
  // (the colliders follow the moved base at the reset below)
  if (!st && h->scene.base_auto) st = place_base(h, err);
  if (st) {
    vd_harvest_destroy(h);
    return st;
  }
  st = vd_harvest_reset(h, 0, err);
  if (!st) st = start_pose_check(h, err);
  if (st) {
    vd_harvest_destroy(h);
    return st;
  }
  *out = h;
  return VD_OK;
}

// is fruit f still on the plant? else *seg gets the broken joint nearest the fruit
static int fruit_attached(const vd_harvest* h, int f, int* seg) {
  const vd_sim_model* m = h->sm;
  for (int t = h->fruit[f].seg; t >= 0; t = m->seg_parent[t])
    if (h->sd->seg_broken[t]) {
      if (seg) *seg = t;
      return 0;
    }
  return 1;
}

// base of the robot (for "nearest")
static vd_vec3 base_pos(const vd_harvest* h) {
  int r = h->rb->root_body;
  return vd_v3(h->d->xpos[3 * r], h->d->xpos[3 * r + 1], h->d->xpos[3 * r + 2]);
}

static vd_vec3 unit_or(vd_vec3 v, vd_vec3 fallback) {
  double n = vd_norm(v);
  return n > 1e-9 ? vd_scale(v, 1.0 / n) : fallback;
}

// Grasp geometry: the pedicel axis p runs from the calyx (the fruit stalk's start) to the
// fruit's centre; the approach a is the horizontal direction from the robot's base to the fruit
// (made normal to p when the calyx would otherwise lie toward the palm); the gripper's z axis is
// a and its fingers close along p x a, so they meet the fruit's sides and the pedicel stays
// between them at the top. A robot that cannot turn its end-effector (a gantry) approaches along
// its tool axis.
void harvest_grasp_pose(vd_harvest* h, int f, vd_vec3* pos, vd_quat* rot, vd_vec3* approach,
                        vd_vec3* pedicel) {
  const vd_sim_data* sd = h->sd;
  const robot_fruit* fr = &h->fruit[f];
  vd_vec3 c = sd->node_pos[fr->node], calyx = sd->node_pos[sd->seg_start[fr->seg]];
  vd_vec3 p = unit_or(vd_sub(c, calyx), vd_v3(0, 0, -1));
  vd_vec3 ah = vd_sub(c, base_pos(h));
  ah.z = 0;
  ah = unit_or(ah, vd_v3(1, 0, 0));
  // horizontal, unless the calyx would then lie toward the palm: a . p <= 0 keeps the pedicel
  // ahead of the fingers
  double ap = vd_dot(ah, p);
  vd_vec3 a = ap > 0 ? vd_madd(ah, p, -ap) : ah;
  a = vd_norm(a) > 0.2 ? unit_or(a, ah) : ah;
  if (h->orient) {
    vd_vec3 y = unit_or(vd_cross(p, a), vd_v3(0, 0, 1));
    vd_vec3 x = vd_cross(y, a);
    *rot = vd_quat_from_axes(x, y, a);
  } else {
    vd_vec3 tmp;
    vd_harvest_fk(h, h->q0, &tmp, rot);
    a = vd_quat_rotate(*rot, vd_v3(0, 0, 1));
  }
  *pos = c;
  *approach = a;
  *pedicel = p;
}

int vd_harvest_grasp_pose(vd_harvest* h, vd_vec3* pos, vd_quat* rot, vd_vec3* approach,
                          vd_vec3* pedicel) {
  if (h->target < 0) return 0;
  harvest_grasp_pose(h, h->target, pos, rot, approach, pedicel);
  return 1;
}

// the grasp pose of fruit f is reachable from q0 through its pre-grasp pose; *ik_err gets the
// distance the arm stays short of the grasp point (m)
static int reachable(vd_harvest* h, int f, double* ik_err) {
  vd_vec3 pos, a, p;
  vd_quat rot;
  harvest_grasp_pose(h, f, &pos, &rot, &a, &p);
  double q[VD_ROBOT_MAX_JOINTS], e1, r1, e2, r2;
  memcpy(q, h->q0, sizeof q);
  vd_ik_def def = vd_ik_def_default();
  def.max_iter = 400;
  vd_vec3 pre = vd_madd(pos, a, -h->scene.method.pregrasp);
  robot_ik(h, &def, pre, &rot, q, &e1, &r1);
  robot_ik(h, &def, pos, &rot, q, &e2, &r2);
  if (ik_err) *ik_err = e2;
  return e1 < 1e-3 && e2 < 1e-3 && r1 < 1e-2 && r2 < 1e-2;
}

// no target: the reason (a key) and what to tell a user
static void no_target(vd_harvest* h, const char* reason, const char* fmt, ...) {
  snprintf(h->target_reason, sizeof h->target_reason, "%s", reason);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(h->target_detail, sizeof h->target_detail, fmt, ap);
  va_end(ap);
}

// the plant's fruit instances as "3, 7, 12" (the first ones, when many) into buf
static void fruit_list(const vd_harvest* h, char* buf, size_t cap) {
  size_t n = 0;
  buf[0] = 0;
  for (int f = 0; f < h->nfruit && n + 16 < cap; f++)
    n += (size_t)snprintf(buf + n, cap - n, "%s%d", f ? ", " : "", h->fruit[f].instance);
  if (n + 16 >= cap && cap > 4) snprintf(buf + cap - 5, 5, "...");
}

// choose the target fruit; -1 with the reason in target_reason when there is none
static vd_status choose_target(vd_harvest* h, uint64_t seed, vd_error* err) {
  const vd_scene* s = &h->scene;
  h->target = -1;
  h->target_reason[0] = h->target_detail[0] = 0;
  if (!h->nfruit) {
    no_target(h, "no fruit", "the plant has no fruit");
    return VD_OK;
  }
  int random = s->target_instance < 0;
  vd_vec3 b = base_pos(h);
  if (s->target_instance > 0) {
    for (int f = 0; f < h->nfruit; f++)
      if (h->fruit[f].instance == s->target_instance) h->target = f;
    if (h->target < 0) {
      char ids[160];
      fruit_list(h, ids, sizeof ids);
      no_target(h, "no such fruit", "target.fruit: the plant has no fruit with instance %d (its fruits: %s)",
                s->target_instance, ids);
      return VD_OK;
    }
    if (!reachable(h, h->target, &h->grasp_ik_err)) {
      const robot_fruit* f = &h->fruit[h->target];
      no_target(h, "unreachable",
                "fruit %d is out of reach: %.3f m from the robot's base, the arm stays %.3f m short "
                "of its grasp pose",
                f->instance, vd_norm(vd_sub(h->sd->node_pos[f->node], b)), h->grasp_ik_err);
      h->target = -1;
    }
    return VD_OK;
  }
  // fruits by distance from the robot's base (instance breaks ties), the reachable ones
  int* order = vd_malloc((size_t)h->nfruit * sizeof(int));
  if (!order) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int f = 0; f < h->nfruit; f++) order[f] = f;
  for (int i = 1; i < h->nfruit; i++)
    for (int k = i; k > 0; k--) {
      int x = order[k - 1], y = order[k];
      double dx = vd_norm(vd_sub(h->sd->node_pos[h->fruit[x].node], b));
      double dy = vd_norm(vd_sub(h->sd->node_pos[h->fruit[y].node], b));
      if (dx < dy || (dx == dy && h->fruit[x].instance < h->fruit[y].instance)) break;
      order[k - 1] = y, order[k] = x;
    }
  int nok = 0, nearest = order[0];
  double nearest_short = 0;
  for (int i = 0; i < h->nfruit; i++) {
    double e;
    if (!reachable(h, order[i], &e)) {
      if (i == 0) nearest_short = e;
      continue;
    }
    order[nok++] = order[i];
    if (!random) break;
  }
  if (nok) {
    int pick = 0;
    if (random) {
      vd_rng* g = vd_malloc(sizeof *g);
      if (g) {
        vd_rng_seed(g, seed);
        pick = (int)vd_rng_randint(g, 0, nok - 1);
        vd_free(g, sizeof *g);
      }
    }
    h->target = order[pick];
    reachable(h, h->target, &h->grasp_ik_err);
  }
  vd_free(order, (size_t)h->nfruit * sizeof(int));
  if (h->target < 0) {
    const robot_fruit* f = &h->fruit[nearest];
    no_target(h, "no reachable fruit",
              "none of the plant's %d fruits is in reach: the nearest, fruit %d, is %.3f m from the "
              "robot's base and the arm stays %.3f m short of its grasp pose",
              h->nfruit, f->instance, vd_norm(vd_sub(h->sd->node_pos[f->node], b)), nearest_short);
  }
  return VD_OK;
}

// each fruit's calyx and abscission break forces for this plant: drawn in the scene's ranges
// from the plant seed and the fruit's instance (the same plant, the same thresholds), or the
// materials' fixed values; written into the rod model's thresholds
static void draw_thresholds(vd_harvest* h) {
  vd_sim_model* sm = h->sm;
  const double* range[2] = {h->scene.draw_calyx, h->scene.draw_abscission};
  for (int f = 0; f < h->nfruit; f++) {
    robot_fruit* fr = &h->fruit[f];
    int seg[2] = {fr->seg, -1};
    for (int s = fr->seg, n = 0; s >= 0 && n < 8; s = sm->seg_parent[s], n++)
      if (sm->seg_flags[s] & VD_SIM_ABSCISSION) {
        seg[1] = s;
        break;
      }
    fr->absc = seg[1];
    vd_rng rng;
    vd_rng_stream(&rng, h->scene.plant_seed, (uint64_t)(uint32_t)fr->instance);
    for (int k = 0; k < 2; k++) {
      double u = vd_rng_random(&rng);  // drawn either way: one stream per fruit whatever is fixed
      fr->thr[k] = seg[k] >= 0 ? sm->seg_break[4 * seg[k]] : INFINITY;
      if (seg[k] < 0 || !(range[k][0] <= range[k][1])) continue;
      fr->thr[k] = range[k][0] + (range[k][1] - range[k][0]) * u;
      sm->seg_break[4 * seg[k]] = fr->thr[k];
    }
  }
}

vd_status vd_harvest_reset(vd_harvest* h, uint64_t seed, vd_error* err) {
  mjModel* m = h->m;
  mjData* d = h->d;
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap)) {
    h->done = 1;
    return vd_mj_trap_status(&trap, err);
  }
  // robot at q0, gripper open
  mj_resetData(m, d);
  for (int k = 0; k < h->rb->narm; k++) {
    d->qpos[h->rb->arm_qpos[k]] = h->q0[k];
    d->ctrl[h->rb->arm_act[k]] = h->q0[k];
    h->qcmd[k] = h->q0[k];
  }
  for (int k = 0; k < 2; k++) {
    d->qpos[h->rb->grip_qpos[k]] = h->scene.gripper_open;
    d->ctrl[h->rb->grip_act[k]] = h->scene.gripper_open;
  }
  mj_forward(m, d);
  vd_mj_trap_end(&trap);
  // plant at its modelled shape, colliders at the robot's pose
  vd_sim_data_reset(h->sm, h->sd);
  h->sd->ntie = 0;
  for (int k = 0; k < h->ncol; k++) {
    robot_collider* c = &h->col[k];
    c->cur = c->prev = c->shape.pose = robot_geom_pose(m, d, c->geom);
    vd_sim_collider* sc = &h->sd->collider[c->sim];
    sc->pos = c->cur.pos, sc->quat = c->cur.rot, sc->vel = vd_v3(0, 0, 0);
    h->sd->collider_pass[c->sim] = -1;
  }
  // episode state
  robot_site_pose(h, d, &h->ee_pos, &h->ee_quat);
  h->xcmd = h->ee_pos, h->rcmd = h->ee_quat;
  h->grip_cmd = 0;
  h->ik_err = 0;
  h->cmd_scale = 1;
  h->held = h->ever_held = 0, h->tie = -1;
  h->slip = h->tie_slip0 = 0;
  h->grip_n[0] = h->grip_n[1] = h->grip_at_detach = 0;
  h->pull_force = h->pull_torque = h->robot_force = vd_v3(0, 0, 0);
  h->touching[0] = h->touching[1] = h->touched[0] = h->touched[1] = 0;
  h->finger_force[0] = h->finger_force[1] = 0;
  h->detached = 0, h->site = VD_SITE_NONE;
  h->detach_time = h->detach_force = h->detach_moment = h->detach_pull = 0;
  h->max_pull = h->max_disp = h->grasp_ik_err = h->grasp_track_err = h->pull_at_break = 0;
  h->done = 0, h->reason[0] = 0;
  h->nevent_seen = 0, h->nev = 0, h->ev_dropped = 0, h->step = 0;
  h->watch_seg[0] = -2, h->watch_seg[1] = -1;
  h->fwin_n = h->fwin_head = h->fwin_frozen = 0;
  for (int f = 0; f < h->nfruit; f++) h->fruit[f].hit = h->fruit[f].dropped = 0;
  h->phase = VD_PHASE_EXTERNAL;
  draw_thresholds(h);
  // without a target the episode can still be driven from outside; target_reason says why
  return choose_target(h, seed, err);
}

// ---------------------------------------------------------------------------------------------
// one robot step with its plant substeps

static vd_pose pose_lerp(vd_pose a, vd_pose b, double t) {
  vd_pose p;
  p.pos = vd_add(vd_scale(a.pos, 1 - t), vd_scale(b.pos, t));
  p.rot = vd_quat_mul(quat_exp_v(vd_scale(quat_log_v(vd_quat_mul(b.rot, vd_quat_conj(a.rot))), t)), a.rot);
  return p;
}

// the grasp tie's target and the torsion spring on the held fruit at end-effector pose e
static void grasp_drive(vd_harvest* h, vd_pose e, vd_vec3* torque) {
  const robot_fruit* f = &h->fruit[h->target];
  vd_sim_data* sd = h->sd;
  sd->tie[h->tie].target = vd_add(e.pos, vd_quat_rotate(e.rot, h->hold_local));
  // orientation: a spring on the fruit's stalk frame, explicit (k h^2 / I = KROT)
  int t = f->seg;
  double ib = h->sm->seg_inertia[2 * t], it = h->sm->seg_inertia[2 * t + 1], dt = h->sm->opt.dt;
  double inr = ib < it ? ib : it, k = KROT * inr / (dt * dt), c = sqrt(k * inr);
  vd_quat want = vd_quat_mul(e.rot, h->hold_rot);
  vd_vec3 tau = vd_sub(vd_scale(quat_log_v(vd_quat_mul(want, vd_quat_conj(sd->seg_quat[t]))), k),
                       vd_scale(sd->seg_omega[t], c));
  // the grip's friction torque bounds it: mu (N_l + N_r) r, the fingers' measured squeeze
  const vd_method_def* md = &h->scene.method;
  double lim = md->grip_friction * (h->grip_n[0] + h->grip_n[1]) * f->radius, n = vd_norm(tau);
  if (n > lim && n > 0) tau = vd_scale(tau, lim / n);
  sd->seg_torque[t] = tau;
  *torque = tau;
  // the hold's friction limit inside the plant solve: mu (N_l + N_r) across the closing axis
  vd_sim_tie* tie = &sd->tie[h->tie];
  tie->max_force = md->grip_friction * (h->grip_n[0] + h->grip_n[1]);
  if (!(tie->max_force > 0)) tie->max_force = 1e-9;  // no squeeze: nothing holds
  tie->axis = vd_quat_rotate(e.rot, vd_v3(0, 1, 0));
}

// after a plant substep: the tie's force on the gripper and the slip the solve let happen (the
// tie's target slid inside the solver's iterations where the pull across the closing axis
// reached mu (N_l + N_r)); the grasp point in the gripper moves with it
static void grasp_slip(vd_harvest* h, vd_pose e, vd_vec3* force) {
  const robot_fruit* f = &h->fruit[h->target];
  const vd_sim_tie* t = &h->sd->tie[h->tie];
  *force = vd_scale(vd_sub(h->sd->node_pos[f->node], t->target), 1.0 / ROBOT_TIE_COMPLIANCE);
  h->slip = h->tie_slip0 + t->slip;
  h->hold_local = vd_quat_rotate(vd_quat_conj(e.rot), vd_sub(t->target, e.pos));
}

// the squeeze finger k's actuator exerts held at position q with target ctrl, at rest (N): its
// gain and bias (MuJoCo's affine actuator: gain0 ctrl + bias0 + bias1 q) within its force range
static double finger_squeeze(const mjModel* m, int a, double ctrl, double q) {
  const mjtNum* g = m->actuator_gainprm + mjNGAIN * a;
  const mjtNum* b = m->actuator_biasprm + mjNBIAS * a;
  double f = g[0] * ctrl + b[0] + b[1] * q;
  if (m->actuator_forcelimited[a]) {
    const mjtNum* r = m->actuator_forcerange + 2 * a;
    f = f < r[0] ? r[0] : f > r[1] ? r[1] : f;
  }
  return fabs(f);
}

// the finger touches and forces on the target fruit, from the last robot step
static void finger_contacts(vd_harvest* h, const vd_vec3* force) {
  h->touching[0] = h->touching[1] = 0;
  h->finger_force[0] = h->finger_force[1] = 0;
  if (h->target < 0) return;
  const robot_fruit* f = &h->fruit[h->target];
  vd_vec3 p = h->sd->node_pos[f->node];
  vd_vec3 fs[2] = {{0, 0, 0}, {0, 0, 0}};
  for (int k = 0; k < h->ncol; k++) {
    const robot_collider* c = &h->col[k];
    if (c->finger < 0) continue;
    if (vd_collide_sphere(&c->shape, p, f->radius).dist < ROBOT_TOUCH_GAP) h->touching[c->finger] = 1;
    fs[c->finger] = vd_add(fs[c->finger], force[k]);
  }
  for (int k = 0; k < 2; k++) h->finger_force[k] = vd_norm(fs[k]);
}

// grasp the target when both fingers touch it hard enough while closing
static void grasp_check(vd_harvest* h) {
  if (h->held || h->target < 0 || h->grip_cmd < 0.5 || h->detached) return;
  const robot_fruit* f = &h->fruit[h->target];
  for (int k = 0; k < 2; k++)
    if (h->touching[k] && !h->touched[k]) {
      h->touched[k] = 1;
      harvest_event(h, VD_EV_TOUCH, k, -1, f->instance);
    }
  double tf = h->scene.method.touch_force;
  if (!(h->touching[0] && h->touching[1] && h->finger_force[0] >= tf && h->finger_force[1] >= tf))
    return;
  vd_sim_data* sd = h->sd;
  vd_vec3 p = sd->node_pos[f->node];
  h->tie = vd_sim_add_tie(sd, f->node, p, ROBOT_TIE_COMPLIANCE);
  if (h->tie < 0) return;  // out of memory: try again next step
  h->held = h->ever_held = 1;
  h->slip = 0, h->tie_slip0 = 0;
  h->hold_local = vd_quat_rotate(vd_quat_conj(h->ee_quat), vd_sub(p, h->ee_pos));
  h->hold_rot = vd_quat_mul(vd_quat_conj(h->ee_quat), sd->seg_quat[f->seg]);
  // the fingers stay where they met the fruit, their servos commanded closed: each squeezes
  // with its actuator's force there (the grip force limit, unless the fruit holds them early)
  for (int k = 0; k < 2; k++) {
    h->finger_q[k] = h->d->qpos[h->rb->grip_qpos[k]];
    h->grip_n[k] = finger_squeeze(h->m, h->rb->grip_act[k], h->scene.gripper_closed, h->finger_q[k]);
  }
  h->grip_at_detach = 0.5 * (h->grip_n[0] + h->grip_n[1]);
  // the fingers hold the fruit through the tie now: they no longer push it
  for (int k = 0; k < h->ncol; k++)
    if (h->col[k].finger >= 0) sd->collider_pass[h->col[k].sim] = f->node;
  h->grasp_track_err = vd_norm(vd_sub(h->ee_pos, h->xcmd));
  harvest_event(h, VD_EV_GRASP, 0.5 * (h->finger_force[0] + h->finger_force[1]), -1, f->instance);
}

// the target's stalk and abscission joints (the abscission within 8 segments of the fruit)
static void watch_target(vd_harvest* h) {
  h->watch_seg[0] = h->watch_seg[1] = -1;
  if (h->target < 0) return;
  const vd_sim_model* sm = h->sm;
  int s0 = h->fruit[h->target].seg;
  h->watch_seg[0] = s0;
  for (int s = s0, n = 0; s >= 0 && n < 8; s = sm->seg_parent[s], n++)
    if (sm->seg_flags[s] & VD_SIM_ABSCISSION) {
      h->watch_seg[1] = s;
      break;
    }
}

// one plant step's sample of the target's joint loads into the window; events from nev0 on are
// this step's fractures (a watched joint that broke carries the fracture's load, and the window
// stops there)
static void record_forces(vd_harvest* h, int nev0, double pull) {
  if (h->fwin_frozen) return;
  if (h->watch_seg[0] == -2) watch_target(h);
  if (h->watch_seg[0] < 0) return;
  const vd_sim_data* sd = h->sd;
  vd_harvest_force* x = &h->fwin[h->fwin_head];
  memset(x, 0, sizeof *x);
  x->time = sd->time;
  x->pull_force = pull;
  double* f[2] = {&x->calyx_force, &x->abscission_force};
  double* mo[2] = {&x->calyx_moment, &x->abscission_moment};
  for (int k = 0; k < 2; k++) {
    int s = h->watch_seg[k];
    if (s < 0) continue;
    vd_sim_joint_load(h->sm, sd, s, f[k], mo[k]);
    for (int e = nev0; e < sd->nevent; e++)
      if (sd->event[e].seg == s) *f[k] = sd->event[e].force, *mo[k] = sd->event[e].moment, x->broke = 1;
  }
  h->fwin_head = (h->fwin_head + 1) % h->fwin_cap;
  if (h->fwin_n < h->fwin_cap) h->fwin_n++;
  if (x->broke) h->fwin_frozen = 1;
}

int vd_harvest_forces(const vd_harvest* h, vd_harvest_force* out, int cap) {
  int first = (h->fwin_head - h->fwin_n + h->fwin_cap) % h->fwin_cap;
  for (int k = 0; out && k < h->fwin_n && k < cap; k++) out[k] = h->fwin[(first + k) % h->fwin_cap];
  return h->fwin_n;
}

static vd_status robot_step(vd_harvest* h, vd_error* err) {
  mjModel* m = h->m;
  mjData* d = h->d;
  vd_sim_data* sd = h->sd;
  vd_mj_trap trap;
  if (h->held)
    for (int k = 0; k < 2; k++) {
      // a held finger stays against the fruit (the fruit is in the plant solve, not in MuJoCo)
      d->qpos[h->rb->grip_qpos[k]] = h->finger_q[k];
      d->qvel[h->rb->grip_dof[k]] = 0;
    }
  if (!VD_MJ_TRY(&trap)) return vd_mj_trap_status(&trap, err);
  mj_step1(m, d);
  // the arm's controller compensates gravity and the velocity-dependent forces
  for (int k = 0; k < h->rb->narm; k++) d->qfrc_applied[h->rb->arm_dof[k]] = d->qfrc_bias[h->rb->arm_dof[k]];
  vd_mj_trap_end(&trap);
  // poses at this robot step
  for (int k = 0; k < h->ncol; k++) {
    robot_collider* c = &h->col[k];
    c->prev = c->cur;
    c->cur = c->shape.pose = robot_geom_pose(m, d, c->geom);
  }
  vd_pose e0 = {h->ee_pos, h->ee_quat}, e1;
  robot_site_pose(h, d, &e1.pos, &e1.rot);
  // the plant's substeps
  vd_vec3 force[ROBOT_MAX_COLLIDERS], torque[ROBOT_MAX_COLLIDERS];
  vd_vec3 pull = {0, 0, 0}, twist = {0, 0, 0};
  memset(force, 0, sizeof force);
  memset(torque, 0, sizeof torque);
  int held0 = h->held, broke = 0;
  for (int s = 0; s < h->nsub; s++) {
    double a = (double)(s + 1) / h->nsub;
    for (int k = 0; k < h->ncol; k++) {
      robot_collider* c = &h->col[k];
      vd_pose p = pose_lerp(c->prev, c->cur, a);
      vd_sim_set_collider_pose(h->sm, sd, c->sim, p.pos, p.rot);
    }
    vd_pose e = pose_lerp(e0, e1, a);
    vd_vec3 tau = {0, 0, 0};
    if (h->held) grasp_drive(h, e, &tau);
    int nev = sd->nevent;
    if (vd_sim_step(h->sm, sd))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                          "the plant simulation failed at t = %.4f s (non-finite or torn apart)", sd->time);
    for (int k = 0; k < h->ncol; k++) {
      force[k] = vd_add(force[k], sd->collider_force[h->col[k].sim]);
      torque[k] = vd_add(torque[k], sd->collider_torque[h->col[k].sim]);
    }
    double fsensor = 0;
    if (h->held) {
      vd_vec3 fg;
      grasp_slip(h, e, &fg);
      pull = vd_add(pull, fg);
      // the force sensor: its largest value up to and with the break, and its value at the break
      double fn = fsensor = vd_norm(fg);
      if (!h->detached && !broke && fn > h->max_pull) h->max_pull = fn;
      if (sd->nevent > nev) h->pull_at_break = fn, broke = 1;
      twist = vd_sub(twist, tau);
      if (h->slip > h->fruit[h->target].radius) {
        harvest_event(h, VD_EV_SLIP, vd_norm(fg), -1, h->fruit[h->target].instance);
        tie_remove(h);
      }
    }
    record_forces(h, nev, fsensor);
  }
  double inv = 1.0 / h->nsub;
  h->robot_force = vd_v3(0, 0, 0);
  for (int k = 0; k < h->ncol; k++) {
    force[k] = vd_scale(force[k], inv), torque[k] = vd_scale(torque[k], inv);
    h->robot_force = vd_add(h->robot_force, force[k]);
  }
  h->pull_force = held0 ? vd_scale(pull, inv) : vd_v3(0, 0, 0);
  h->pull_torque = held0 ? vd_scale(twist, inv) : vd_v3(0, 0, 0);
  h->ee_pos = e1.pos, h->ee_quat = e1.rot;
  // two-way: the plant's reactions on the robot bodies, as forces at their centres of mass
  if (h->scene.two_way) {
    for (int k = 0; k < h->ncol; k++) {
      int b = h->col[k].body;
      mjtNum* x = d->xfrc_applied + 6 * b;
      memset(x, 0, 6 * sizeof(mjtNum));
    }
    int gb = m->site_bodyid[h->rb->ee_site];
    memset(d->xfrc_applied + 6 * gb, 0, 6 * sizeof(mjtNum));
    for (int k = 0; k <= h->ncol; k++) {
      int b;
      vd_vec3 f, t, at;
      if (k < h->ncol) {
        b = h->col[k].body, f = force[k], t = torque[k], at = h->col[k].cur.pos;
      } else {
        b = gb, f = h->pull_force, t = h->pull_torque, at = e1.pos;
        if (!held0) continue;
      }
      vd_vec3 com = vd_v3(d->xipos[3 * b], d->xipos[3 * b + 1], d->xipos[3 * b + 2]);
      t = vd_add(t, vd_cross(vd_sub(at, com), f));
      mjtNum* x = d->xfrc_applied + 6 * b;
      x[0] += f.x, x[1] += f.y, x[2] += f.z, x[3] += t.x, x[4] += t.y, x[5] += t.z;
    }
  }
  if (!VD_MJ_TRY(&trap)) return vd_mj_trap_status(&trap, err);
  mj_step2(m, d);
  vd_mj_trap_end(&trap);
  if (h->held) {
    // the squeeze measured: the finger actuators' force in this step
    for (int k = 0; k < 2; k++) h->grip_n[k] = fabs(d->actuator_force[h->rb->grip_act[k]]);
    if (!h->detached) h->grip_at_detach = 0.5 * (h->grip_n[0] + h->grip_n[1]);
  }
  finger_contacts(h, force);
  grasp_check(h);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// outcomes after each control step

// largest displacement of the nodes still on the plant
static double attached_displacement(const vd_harvest* h) {
  const vd_sim_model* m = h->sm;
  const vd_sim_data* d = h->sd;
  double best = 0;
  // a segment is on the plant when no joint between it and its root has broken (memo in h->on:
  // -1 unknown, 0 off, 1 on)
  signed char* on = h->on;
  memset(on, -1, (size_t)m->nseg);
  for (int t = 0; t < m->nseg; t++) {
    int u = t;
    while (u >= 0 && on[u] < 0 && !d->seg_broken[u]) u = m->seg_parent[u];
    signed char v = (signed char)(u < 0 ? 1 : on[u] >= 0 ? on[u] : 0);
    for (int x = t; x != u; x = m->seg_parent[x]) on[x] = v;
    if (u >= 0 && on[u] < 0) on[u] = 0;
    if (!on[t]) continue;
    int n = m->seg_node[2 * t + 1];
    double s = vd_norm(vd_sub(d->node_pos[n], m->node_pos0[n]));
    if (s > best) best = s;
  }
  return best;
}

static void outcomes(vd_harvest* h) {
  vd_sim_data* sd = h->sd;
  // fractures
  for (; h->nevent_seen < sd->nevent; h->nevent_seen++) {
    const vd_sim_event* e = &sd->event[h->nevent_seen];
    vd_harvest_event* x = harvest_event(h, VD_EV_FRACTURE, e->force, e->seg, e->instance);
    if (x) x->force = e->force, x->moment = e->moment;
  }
  // the target
  int seg;
  if (h->target >= 0 && !h->detached && !fruit_attached(h, h->target, &seg)) {
    h->detached = 1;
    h->detach_time = sd->time;
    int cls = h->sm->seg_class[seg];
    h->site = cls == VD_SIM_FRUIT ? VD_SITE_CALYX
              : (cls == VD_SIM_PEDICEL && (h->sm->seg_flags[seg] & VD_SIM_ABSCISSION)) ? VD_SITE_ABSCISSION
                                                                                        : VD_SITE_ELSEWHERE;
    for (int k = sd->nevent - 1; k >= 0; k--)
      if (sd->event[k].seg == seg) {
        h->detach_force = sd->event[k].force;
        h->detach_moment = sd->event[k].moment;
        break;
      }
    h->detach_pull = h->held ? h->pull_at_break : 0;
    vd_harvest_event* e = harvest_event(h, VD_EV_DETACH, h->detach_pull, seg, h->fruit[h->target].instance);
    if (e) e->site = h->site, e->force = h->detach_force, e->moment = h->detach_moment;
  }
  // other fruits: touched by the robot, come off
  for (int f = 0; f < h->nfruit; f++) {
    robot_fruit* fr = &h->fruit[f];
    if (f == h->target) continue;
    if (!fr->dropped && !fruit_attached(h, f, NULL)) {
      fr->dropped = 1;
      harvest_event(h, VD_EV_DROP, 0, -1, fr->instance);
    }
    if (fr->hit) continue;
    vd_vec3 p = sd->node_pos[fr->node];
    for (int k = 0; k < h->ncol && !fr->hit; k++)
      if (vd_collide_sphere(&h->col[k].shape, p, fr->radius).dist < ROBOT_TOUCH_GAP) {
        fr->hit = 1;
        harvest_event(h, VD_EV_HIT, 0, -1, fr->instance);
      }
  }
  double md = attached_displacement(h);
  if (md > h->max_disp) h->max_disp = md;
}

// ---------------------------------------------------------------------------------------------
// control steps

// one control step: under action a, or toward the joint goal qgoal (Nullable; a's velocities ignored)
static vd_status control_step(vd_harvest* h, const vd_harvest_action* a, const double* qgoal,
                              vd_error* err) {
  if (h->done) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "the episode is over (reset it)");
  const vd_scene* s = &h->scene;
  double dt = s->control_dt;
  // the commanded pose moves with the action; IK turns it into joint targets
  h->grip_cmd = a->gripper < 0 ? 0 : a->gripper > 1 ? 1 : a->gripper;
  vd_vec3 v = a->lin_vel, w = a->ang_vel;
  if (!isfinite(v.x + v.y + v.z + w.x + w.y + w.z + h->grip_cmd))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "action: velocities must be finite");
  double q[VD_ROBOT_MAX_JOINTS], re = 0;
  memcpy(q, h->qcmd, sizeof q);
  int joint_move = qgoal != NULL;
  if (joint_move) {
    // joint space: straight to the goal, every joint arriving together
    const vd_robot* rb = h->rb;
    for (int k = 0; k < rb->narm; k++) {
      if (!isfinite(qgoal[k])) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "q[%d] must be finite", k);
      q[k] = qgoal[k] < rb->arm_lo[k] ? rb->arm_lo[k] : qgoal[k] > rb->arm_hi[k] ? rb->arm_hi[k] : qgoal[k];
    }
  } else {
    h->xcmd = vd_madd(h->xcmd, v, dt);
    if (h->orient) h->rcmd = vd_quat_normalize(vd_quat_mul(quat_exp_v(vd_scale(w, dt)), h->rcmd));
    vd_ik_def def = vd_ik_def_default();
    def.max_iter = 30;
    def.tol_pos = 1e-5;
    def.tol_rot = 1e-4;
    vd_mj_trap trap;
    if (!VD_MJ_TRY(&trap)) {
      harvest_finish(h, "MuJoCo error");
      return vd_mj_trap_status(&trap, err);
    }
    robot_ik(h, &def, h->xcmd, &h->rcmd, q, &h->ik_err, &re);
    vd_mj_trap_end(&trap);
  }
  // the joints' speed limits: the whole step scaled down so that the path stays the same
  double sc = 1;
  for (int k = 0; k < h->rb->narm; k++) {
    double dq = fabs(q[k] - h->qcmd[k]), lim = h->rb->qd_max[k] * dt;
    if (dq > lim && lim / dq < sc) sc = lim / dq;
  }
  for (int k = 0; k < h->rb->narm; k++) h->qcmd[k] += sc * (q[k] - h->qcmd[k]);
  h->cmd_scale = joint_move ? 1 : sc;
  if (joint_move || sc < 1) {
    vd_quat r;
    vd_vec3 x;
    vd_harvest_fk(h, h->qcmd, &x, &r);
    if (!joint_move) h->ik_err = vd_norm(vd_sub(x, h->xcmd));
    h->xcmd = x;
    if (h->orient) h->rcmd = r;
  }
  if (!joint_move && (h->ik_err > 5e-3 || re > 5e-2)) {
    // out of reach: the command stops where the arm can be (no wind-up)
    harvest_event(h, VD_EV_IK, h->ik_err, -1, 0);
    h->cmd_scale = 0;
    vd_quat r;
    vd_harvest_fk(h, h->qcmd, &h->xcmd, &r);
    if (h->orient) h->rcmd = r;
  }
  mjData* d = h->d;
  for (int k = 0; k < h->rb->narm; k++) d->ctrl[h->rb->arm_act[k]] = h->qcmd[k];
  if (h->held && h->grip_cmd < 0.5) harvest_release(h);
  for (int r = 0; r < h->nrobot; r++) {
    // fingers: frozen on a held fruit, else their targets move toward the command
    for (int k = 0; k < 2; k++) {
      int act = h->rb->grip_act[k];
      if (h->held) {
        d->ctrl[act] = s->gripper_closed;  // squeezing; the fruit holds the finger (robot_step)
        continue;
      }
      double want = s->gripper_open + h->grip_cmd * (s->gripper_closed - s->gripper_open);
      double step = GRIP_SPEED * h->m->opt.timestep, cur = d->ctrl[act];
      d->ctrl[act] = cur + (want > cur + step ? step : want < cur - step ? -step : want - cur);
    }
    vd_status st = robot_step(h, err);
    if (st) {
      harvest_finish(h, "simulation failed");
      return st;
    }
  }
  h->step++;
  outcomes(h);
  if (h->sd->time >= s->duration - 1e-9) harvest_finish(h, h->detached ? "detached" : "time");
  return VD_OK;
}

vd_status vd_harvest_step(vd_harvest* h, const vd_harvest_action* a, vd_error* err) {
  return control_step(h, a, NULL, err);
}

vd_status vd_harvest_step_joints(vd_harvest* h, const double* q, double gripper, vd_error* err) {
  vd_harvest_action a = {{0, 0, 0}, {0, 0, 0}, gripper};
  return control_step(h, &a, q, err);
}

// ---------------------------------------------------------------------------------------------
// reading an episode

int vd_harvest_done(const vd_harvest* h) {
  return h->done;
}

void vd_harvest_observe(const vd_harvest* h, vd_harvest_obs* o) {
  vd_harvest* w = (vd_harvest*)h;  // observation copies live in the episode
  memset(o, 0, sizeof *o);
  o->time = h->sd->time;
  o->step = h->step;
  o->phase = h->phase;
  o->nq = h->rb->narm;
  for (int k = 0; k < h->rb->narm; k++) {
    w->qbuf[k] = h->d->qpos[h->rb->arm_qpos[k]];
    w->qdbuf[k] = h->d->qvel[h->rb->arm_dof[k]];
  }
  o->q = w->qbuf;
  o->qd = w->qdbuf;
  o->gripper_opening = h->d->qpos[h->rb->grip_qpos[0]] + h->d->qpos[h->rb->grip_qpos[1]];
  o->ee_pos = h->ee_pos;
  o->ee_quat = h->ee_quat;
  o->cmd_pos = h->xcmd;
  o->cmd_quat = h->rcmd;
  o->q_cmd = h->qcmd;
  o->q0 = h->q0;
  o->cmd_scale = h->cmd_scale;
  o->orient = h->orient;
  o->base_pos = base_pos(h);
  o->target_reason = h->target < 0 ? h->target_reason : NULL;
  if (h->target >= 0) {
    const robot_fruit* f = &h->fruit[h->target];
    o->target_instance = f->instance;
    o->fruit_pos = h->sd->node_pos[f->node];
    o->fruit_vel = h->sd->node_vel[f->node];
  }
  o->held = h->held;
  o->touching[0] = h->touching[0], o->touching[1] = h->touching[1];
  o->finger_force[0] = h->finger_force[0], o->finger_force[1] = h->finger_force[1];
  o->grip_force = h->held ? 0.5 * (h->grip_n[0] + h->grip_n[1]) : 0;
  o->pull_force = h->pull_force;
  o->pull_torque = vd_norm(h->pull_torque);
  o->slip = h->slip;
  o->robot_force = h->robot_force;
  o->detached = h->detached;
  o->site = h->site;
  o->ik_error = h->ik_err;
}

int vd_harvest_events(const vd_harvest* h, const vd_harvest_event** out) {
  *out = h->ev;
  return h->nev;
}

void vd_harvest_summarize(const vd_harvest* h, vd_harvest_summary* o) {
  memset(o, 0, sizeof *o);
  o->detached = h->detached;
  o->grasped = h->ever_held;
  o->site = h->site;
  o->time = h->detached ? h->detach_time : h->sd->time;
  o->detach_force = h->detach_force;
  o->detach_moment = h->detach_moment;
  o->calyx_threshold = h->target >= 0 ? h->fruit[h->target].thr[0] : NAN;
  o->abscission_threshold = h->target >= 0 ? h->fruit[h->target].thr[1] : NAN;
  o->pull_force = h->detach_pull;
  o->max_pull_force = h->max_pull;
  o->max_displacement = h->max_disp;
  for (int f = 0; f < h->nfruit; f++) {
    o->fruits_hit += h->fruit[f].hit;
    o->fruits_dropped += h->fruit[f].dropped;
  }
  o->ik_error = h->grasp_ik_err;
  o->track_error = h->grasp_track_err;
  o->slip = h->slip;
  o->grip_force = h->grip_at_detach;
  o->duration = h->sd->time;
  o->steps = h->step;
  o->plant_warnings = h->sd->nwarning;
  o->target_instance = h->target >= 0 ? h->fruit[h->target].instance : 0;
  o->events_dropped = h->ev_dropped;
  snprintf(o->reason, sizeof o->reason, "%s", h->done ? h->reason : "running");
  if (h->done && h->target < 0 && !strcmp(h->reason, h->target_reason))
    snprintf(o->detail, sizeof o->detail, "%s", h->target_detail);
}

// fruit f as the public record
static void fruit_info(const vd_harvest* h, int f, vd_harvest_fruit* o) {
  const robot_fruit* fr = &h->fruit[f];
  const vd_sim_model* sm = h->sm;
  const vd_sim_data* sd = h->sd;
  memset(o, 0, sizeof *o);
  o->instance = fr->instance;
  o->pos = sd->node_pos[fr->node];
  o->calyx = o->knuckle = sd->node_pos[sd->seg_start[fr->seg]];
  for (int s = fr->seg, n = 0; s >= 0 && n < 8; s = sm->seg_parent[s], n++)
    if (sm->seg_flags[s] & VD_SIM_ABSCISSION) {
      o->knuckle = sd->node_pos[sd->seg_start[s]];
      break;
    }
  o->radius = fr->radius;
  o->attached = fruit_attached(h, f, NULL);
}

int vd_harvest_fruits(const vd_harvest* h, vd_harvest_fruit* out, int cap) {
  for (int f = 0; out && f < h->nfruit && f < cap; f++) fruit_info(h, f, &out[f]);
  return h->nfruit;
}

vd_status vd_harvest_find_fruit(const vd_harvest* h, int instance, vd_harvest_fruit* out, vd_error* err) {
  for (int f = 0; f < h->nfruit; f++)
    if (h->fruit[f].instance == instance) {
      fruit_info(h, f, out);
      return VD_OK;
    }
  return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "the plant has no fruit with instance %d", instance);
}

const vd_sim_model* vd_harvest_sim_model(const vd_harvest* h) {
  return h->sm;
}

const vd_sim_data* vd_harvest_sim_data(const vd_harvest* h) {
  return h->sd;
}

const double* vd_harvest_qpos(const vd_harvest* h, int* nq) {
  *nq = h->m->nq;
  return h->d->qpos;
}

const vd_scene* vd_harvest_scene(const vd_harvest* h) {
  return &h->scene;
}
