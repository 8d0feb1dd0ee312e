// SPDX-License-Identifier: MIT
// Harvest episodes: the Harvest type over vd_harvest (robot.h), the engine of verdant.HarvestEnv,
// and the episode slots it shares with VectorHarvest (py_vector.c). A slot reads nothing from
// Python: it grows and places the episode's plant, builds the episode, and steps it one control
// step at a time under an action (end-effector velocity and gripper) with the environment's
// reward and ending rules, all without the GIL. Episode k of a seed gets the scene's
// randomisation (vd_scene_episode: plant seed, target, method parameters), the plant regrown only
// when its seed changes; a draw whose plant has no reachable fruit is drawn again (VDPY_DRAWS).
#include "py_internal.h"

#include <math.h>
#include <structmember.h>

#define PATH_CAP 4096

const char* const vdpy_term_names[VDPY_NTERMS] = {"detach", "grasp", "distance", "pull_force",
                                                  "fracture", "drop", "hit"};

struct vdpy_harvest {
  PyObject_HEAD
  vd_scene base;         // the scene as read (owned)
  vdpy_slot s;           // the episode
  int busy;
};

static int busy_check(vdpy_harvest* o) {
  if (o->busy) return (vdpy_busy("this Harvest"), 0);
  return 1;
}

// ---------------------------------------------------------------------------------------------
// slots

static void slot_free_episode(vdpy_slot* o) {
  vd_harvest_destroy(o->h);
  vd_data_destroy(o->pstate);
  vd_model_destroy(o->plant);
  vd_plant_spec_destroy(o->spec);
  o->h = NULL, o->pstate = NULL, o->plant = NULL, o->spec = NULL;
  o->ready = 0;
}

void vdpy_slot_free(vdpy_slot* o) {
  slot_free_episode(o);
  vd_scene_free(&o->scene);
}

// the method parameters an episode draws: a new episode needs a new vd_harvest when they change
static int same_method(const vd_method_def* a, const vd_method_def* b) {
  return a->method == b->method && a->approach_speed == b->approach_speed && a->pregrasp == b->pregrasp &&
         a->speed == b->speed && a->distance == b->distance && a->angle == b->angle &&
         a->angular_speed == b->angular_speed && a->grip_force == b->grip_force &&
         a->grip_friction == b->grip_friction && a->touch_force == b->touch_force && a->hold == b->hold;
}

// the episode has no target (no fruit, or none reachable): an outcome, not an error
static int no_target(const vd_harvest* h) {
  vd_harvest_obs b;
  vd_harvest_observe(h, &b);
  return vd_harvest_done(h) || b.target_reason != NULL;  // none chosen at the reset
}

// the episode of scene s (taken into o->scene): plant grown when its seed differs, episode built
// or reused, reset with target_seed; o->ready when a target was found
static vd_status episode(vdpy_slot* o, vd_scene* s, uint64_t target_seed, vd_error* err) {
  int regrow = !o->spec || s->plant_seed != o->plant_seed;
  int rebuild = regrow || !o->h || !same_method(&s->method, &o->scene.method) ||
                s->target_instance != o->scene.target_instance;
  vd_scene_free(&o->scene);
  o->scene = *s;
  memset(s, 0, sizeof *s);
  o->ready = 0;
  vd_status st = VD_OK;
  if (regrow) {
    slot_free_episode(o);
    st = vdpy_grow_file(o->scene.plant_path, o->scene.plant_seed, o->scene.plant_steps, o->scene.plant_set,
                        o->scene.nplant_set, &o->spec, err);
    if (st) {
      if (err && !err->file[0]) snprintf(err->file, sizeof err->file, "%.255s", o->scene.plant_path);
      return st;
    }
    o->plant_seed = o->scene.plant_seed;
    vd_scene_place_plant(&o->scene, o->spec);
    st = vd_plant_compile(o->spec, &o->plant, err);
    if (!st && !(o->pstate = vd_data_create(o->plant))) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    if (st) return st;
  }
  if (rebuild) {
    vd_harvest_destroy(o->h);
    o->h = NULL;
    st = vd_harvest_create(&o->scene, o->plant, &o->h, err);
    if (st) return st;
  }
  memset(err, 0, sizeof *err);
  st = vd_harvest_reset(o->h, target_seed, err);
  if (st == VD_ERR_VALUE && no_target(o->h)) st = VD_OK;  // no reachable fruit: done
  o->stepped = 0;
  o->ready = !st && !no_target(o->h);
  return st;
}

vd_status vdpy_slot_reset(vdpy_slot* o, const vd_scene* base, uint64_t seed, int64_t k, int randomize,
                          vd_error* err) {
  o->seed = seed, o->episode = k, o->draws = 0;
  o->nevents = 0, o->was_detached = o->was_held = 0, o->steps = 0;
  // only a new plant can make an impossible draw possible: one draw when the plant is fixed
  int ndraw = randomize && base->episodes.plant_seed ? VDPY_DRAWS : 1;
  for (int t = 0; t < ndraw; t++) {
    // draw t of episode k is the episode stream k + t 2^40 (episode indices stay below 2^40)
    vd_scene s;
    uint64_t tseed = seed;
    int64_t kt = k + ((int64_t)t << 40);
    vd_status st = randomize ? vd_scene_episode(base, seed, kt, &s, &tseed, err) : vd_scene_copy(base, &s, err);
    if (!st) st = episode(o, &s, tseed, err);
    vd_scene_free(&s);
    if (st) return st;
    o->draws = t + 1;
    if (o->ready) {
      if (o->h) o->nevents = vd_harvest_events(o->h, &(const vd_harvest_event*){NULL});
      return VD_OK;
    }
  }
  vd_harvest_summary sum;
  vd_harvest_summarize(o->h, &sum);
  memset(err, 0, sizeof *err);  // the last draw's reason is in the message
  return vd_error_set(err, VD_ERR_VALUE, base->path, 0, 0,
                      "%s%d draw%s of episode %lld (seed %llu) found no reachable target fruit (%s)%s",
                      base->path[0] ? "" : "scene (JSON text): ", ndraw, ndraw > 1 ? "s" : "", (long long)k,
                      (unsigned long long)seed, sum.reason[0] ? sum.reason : "no target",
                      ndraw > 1 ? "" : "; the scene draws no new plant per episode (episodes.plant_seed)");
}

static double norm3(vd_vec3 v) { return sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

// the reward terms of the step that led to observation b, with the events since the last step
static void slot_reward(vdpy_slot* o, const vd_harvest_obs* b, const vdpy_rules* r, vdpy_outcome* out) {
  const vd_harvest_event* ev;
  int n = vd_harvest_events(o->h, &ev), count[VD_EV_KIND_COUNT] = {0};
  for (int k = o->nevents; k < n; k++) count[ev[k].kind]++;
  o->nevents = n;
  double dt = o->scene.control_dt;
  double dist = norm3(vd_sub(b->ee_pos, b->fruit_pos));
  double pull = b->held ? norm3(b->pull_force) : 0.0;
  int detached_now = b->detached && !o->was_detached, held_now = b->held && !o->was_held;
  o->was_detached |= b->detached != 0;
  o->was_held |= b->held != 0;
  int others = count[VD_EV_FRACTURE] - count[VD_EV_DETACH];  // the target's own is "detach"
  double raw[VDPY_NTERMS] = {detached_now, held_now, -dist * dt, -pull * dt, -(others > 0 ? others : 0),
                             -count[VD_EV_DROP], -count[VD_EV_HIT]};
  out->reward = 0;
  for (int k = 0; k < VDPY_NTERMS; k++) out->reward += out->terms[k] = r->w[k] * raw[k];
}

vd_status vdpy_slot_step(vdpy_slot* o, const vd_harvest_action* a, const vdpy_rules* r, vdpy_outcome* out,
                         vd_error* err) {
  memset(out, 0, sizeof *out);
  if (!o->h || !o->ready)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        o->h && o->steps ? "the episode is over (terminated or truncated): reset() first"
                                         : "no episode: reset() first (the last reset failed or none was made)");
  o->stepped = 1;
  vd_status st = vd_harvest_step(o->h, a, err);
  if (st && !(st == VD_ERR_VALUE && vd_harvest_done(o->h))) return st;
  out->ok = !st;  // MuJoCo or the plant failed: an outcome, the episode is over
  o->steps++;
  vd_harvest_obs b;
  vd_harvest_observe(o->h, &b);
  slot_reward(o, &b, r, out);
  // the ending: the scene's (its reason), the target's detachment, or the step limit
  int over = vd_harvest_done(o->h), done = over || (r->terminate_on_detach && b.detached);
  if (done) {
    vd_harvest_summary sum;
    vd_harvest_summarize(o->h, &sum);
    snprintf(out->reason, sizeof out->reason, "%s", over ? sum.reason : "detached");
  }
  out->truncated = (done && !strcmp(out->reason, "time")) || (!done && r->max_steps > 0 && o->steps >= r->max_steps);
  out->terminated = done && !out->truncated;
  if (out->truncated && !done) snprintf(out->reason, sizeof out->reason, "max_episode_steps");
  if (out->terminated || out->truncated) o->ready = 0;
  memset(err, 0, sizeof *err);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// Harvest

static void harvest_dealloc(vdpy_harvest* o) {
  vdpy_slot_free(&o->s);
  vd_scene_free(&o->base);
  Py_TYPE(o)->tp_free((PyObject*)o);
}

int vdpy_scene_read(PyObject* src, vd_scene* out) {
  vd_error err = {0};
  vd_status st;
  // a scene file, or its JSON text: a str with a newline or whose first character (past blanks)
  // is '{'
  const char* text = NULL;
  Py_ssize_t len = 0;
  char path[PATH_CAP] = "";
  int is_text = 0;
  if (PyUnicode_Check(src)) {
    Py_ssize_t n = PyUnicode_GET_LENGTH(src), i = 0;
    while (i < n && Py_UNICODE_ISSPACE(PyUnicode_READ_CHAR(src, i))) i++;
    is_text = PyUnicode_FindChar(src, '\n', 0, n, 1) >= 0 || (i < n && PyUnicode_READ_CHAR(src, i) == '{');
  }
  if (is_text) {
    text = PyUnicode_AsUTF8AndSize(src, &len);
    if (!text) return 0;
  } else if (!vdpy_path(src, "scene", path, sizeof path)) {
    return 0;
  }
  Py_BEGIN_ALLOW_THREADS
  st = text ? vd_scene_parse(text, (size_t)len, NULL, out, &err) : vd_scene_read(path, out, &err);
  Py_END_ALLOW_THREADS
  if (st) return (vdpy_raise(st, &err), 0);
  return 1;
}

static PyObject* harvest_new(PyTypeObject* type, PyObject* args, PyObject* kw) {
  static char* names[] = {"scene", NULL};
  PyObject* src;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O:Harvest", names, &src)) return NULL;
  vdpy_harvest* o = (vdpy_harvest*)type->tp_alloc(type, 0);
  if (!o) return NULL;
  vd_scene_default(&o->base);
  vd_scene_default(&o->s.scene);
  if (!vdpy_scene_read(src, &o->base)) goto fail;
  // the scene as written, its first draw (the episode stays not ready when no fruit is reachable)
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  vd_scene s;
  st = vd_scene_copy(&o->base, &s, &err);
  if (!st) st = episode(&o->s, &s, 0, &err);
  vd_scene_free(&s);
  o->s.ready = 0;
  Py_END_ALLOW_THREADS
  if (st) {
    vdpy_raise(st, &err);
    goto fail;
  }
  return (PyObject*)o;
fail:
  Py_DECREF(o);
  return NULL;
}

// reset(seed, episode): episode k of the scene's randomisation under seed -> plant draws taken
static PyObject* harvest_reset(vdpy_harvest* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"seed", "episode", "randomize", NULL};
  PyObject *so, *ko = NULL;
  int randomize = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|O$p:reset", names, &so, &ko, &randomize)) return NULL;
  int64_t seed, k = 0;
  if (!vdpy_i64(so, "seed", 0, INT64_MAX, &seed)) return NULL;
  if (ko && !vdpy_i64(ko, "episode", 0, ((int64_t)1 << 40) - 1, &k)) return NULL;
  if (!busy_check(o)) return NULL;
  o->busy = 1;
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vdpy_slot_reset(&o->s, &o->base, (uint64_t)seed, k, randomize, &err);
  Py_END_ALLOW_THREADS
  o->busy = 0;
  if (st) return vdpy_raise(st, &err);
  return PyLong_FromLong(o->s.draws);
}

static int have_episode(vdpy_harvest* o) {
  if (!o->s.h) return (vdpy_raise(VD_ERR_VALUE, NULL), 0);  // a failed reset left none
  return 1;
}

// an action: end-effector velocity (m/s, rad/s) and gripper, checked
static int parse_action(PyObject* lo, PyObject* ao, PyObject* go, vd_harvest_action* a) {
  double l[3], w[3], g;
  if (!vdpy_vec(lo, "lin_vel", 3, l) || !vdpy_vec(ao, "ang_vel", 3, w) || !vdpy_f64(go, "gripper", 0, 1, &g))
    return 0;
  for (int k = 0; k < 3; k++)
    if (fabs(l[k]) > 10 || fabs(w[k]) > 100)
      return (vdpy_arg_error("lin_vel within +-10 m/s and ang_vel within +-100 rad/s"), 0);
  *a = (vd_harvest_action){vd_v3(l[0], l[1], l[2]), vd_v3(w[0], w[1], w[2]), g};
  return 1;
}

// rules from keywords: weights (7 numbers, vdpy_term_names' order), terminate_on_detach,
// max_steps (None or 0: none)
int vdpy_rules_parse(PyObject* weights, int terminate_on_detach, PyObject* max_steps, vdpy_rules* r) {
  memset(r, 0, sizeof *r);
  if (!vdpy_vec(weights, "weights", VDPY_NTERMS, r->w)) return 0;
  r->terminate_on_detach = terminate_on_detach;
  r->randomize = 1;
  if (max_steps && max_steps != Py_None && !vdpy_i64(max_steps, "max_steps", 0, INT64_MAX, &r->max_steps))
    return 0;
  return 1;
}

PyObject* vdpy_outcome_tuple(const vdpy_outcome* out) {
  PyObject* terms = PyDict_New();
  for (int k = 0; terms && k < VDPY_NTERMS; k++) {
    PyObject* v = PyFloat_FromDouble(out->terms[k]);
    if (!v || PyDict_SetItemString(terms, vdpy_term_names[k], v) < 0) Py_CLEAR(terms);
    Py_XDECREF(v);
  }
  if (!terms) return NULL;
  return Py_BuildValue("(OdNOOs)", out->ok ? Py_True : Py_False, out->reward, terms,
                       out->terminated ? Py_True : Py_False, out->truncated ? Py_True : Py_False, out->reason);
}

static PyObject* events_list(const vd_harvest* h, int since);

// act(lin_vel, ang_vel, gripper, weights, terminate_on_detach, max_steps) -> (ok, reward, terms,
// terminated, truncated, reason, events): one environment step, with the events it made
static PyObject* harvest_act(vdpy_harvest* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"lin_vel", "ang_vel", "gripper", "weights", "terminate_on_detach", "max_steps", NULL};
  PyObject *lo, *ao, *go, *wo, *mo = NULL;
  int tod = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OOOO|pO:act", names, &lo, &ao, &go, &wo, &tod, &mo)) return NULL;
  vd_harvest_action a;
  vdpy_rules r;
  if (!parse_action(lo, ao, go, &a) || !vdpy_rules_parse(wo, tod, mo, &r) || !busy_check(o)) return NULL;
  o->busy = 1;
  vd_error err = {0};
  vdpy_outcome out;
  vd_status st;
  int since = o->s.nevents;
  Py_BEGIN_ALLOW_THREADS
  st = vdpy_slot_step(&o->s, &a, &r, &out, &err);
  Py_END_ALLOW_THREADS
  o->busy = 0;
  if (st == VD_ERR_ARG) return vdpy_arg_error("%s", err.msg);
  if (st) return vdpy_raise(st, &err);
  PyObject* t = vdpy_outcome_tuple(&out);
  PyObject* ev = t ? events_list(o->s.h, since) : NULL;
  PyObject* one = ev ? PyTuple_Pack(1, ev) : NULL;
  PyObject* all = one ? PySequence_Concat(t, one) : NULL;
  Py_XDECREF(t);
  Py_XDECREF(ev);
  Py_XDECREF(one);
  return all;
}

// step(lin_vel, ang_vel, gripper) -> ok: False when the episode failed (then done)
static PyObject* harvest_step(vdpy_harvest* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"lin_vel", "ang_vel", "gripper", NULL};
  PyObject *lo, *ao, *go;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OOO:step", names, &lo, &ao, &go)) return NULL;
  vd_harvest_action a;
  if (!parse_action(lo, ao, go, &a)) return NULL;
  if (!have_episode(o) || !busy_check(o)) return NULL;
  if (vd_harvest_done(o->s.h)) return vdpy_arg_error("the episode is over: reset() first");
  o->busy = 1;
  o->s.stepped = 1;
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_harvest_step(o->s.h, &a, &err);
  Py_END_ALLOW_THREADS
  o->busy = 0;
  if (st == VD_ERR_VALUE && vd_harvest_done(o->s.h)) Py_RETURN_FALSE;  // MuJoCo or the plant failed
  if (st) return vdpy_raise(st, &err);
  Py_RETURN_TRUE;
}

// close(): free the episode and its plant now (the scene stays for info)
static PyObject* harvest_close(vdpy_harvest* o, PyObject* unused) {
  if (!busy_check(o)) return NULL;
  vdpy_slot_free(&o->s);
  Py_RETURN_NONE;
}

// run(): the scene's scripted controller to the end of the episode (as `verdant harvest`)
// run(until=): stop when the scripted controller enters a phase (its on_step hook)
typedef struct run_until {
  int phase;    // the phase to stop at; VD_PHASE_COUNT: none
  int reached;  // 1 when it was entered
} run_until;

static vd_status stop_at_phase(void* user, const vd_harvest* h) {
  run_until* u = user;
  vd_harvest_obs b;
  vd_harvest_observe((vd_harvest*)h, &b);
  if ((int)b.phase != u->phase) return VD_OK;
  u->reached = 1;
  return VD_ERR_LIMIT;  // stops vd_harvest_run (u->reached tells it from an error)
}

static PyObject* harvest_run(vdpy_harvest* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"until", NULL};
  const char* until = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|z:run", names, &until)) return NULL;
  run_until u = {VD_PHASE_COUNT, 0};
  if (until) {
    for (int p = VD_PHASE_APPROACH; p < VD_PHASE_COUNT; p++)
      if (!strcmp(until, vd_harvest_phase_name((vd_harvest_phase)p))) u.phase = p;
    if (u.phase == VD_PHASE_COUNT)
      return vdpy_arg_error("until: a phase (approach, reach, close, detach, hold, done), not '%s'", until);
  }
  if (!have_episode(o) || !busy_check(o)) return NULL;
  if (o->s.stepped) return vdpy_arg_error("run() drives an episode from its start: reset() first");
  o->busy = 1;
  vd_error err = {0};
  vd_status st = VD_OK;
  Py_BEGIN_ALLOW_THREADS
  if (!vd_harvest_done(o->s.h)) st = vd_harvest_run(o->s.h, until ? stop_at_phase : NULL, &u, &err);
  Py_END_ALLOW_THREADS
  o->busy = 0;
  if (u.reached) {
    o->s.stepped = 1;  // the episode goes on from here under step() or act()
    Py_RETURN_TRUE;
  }
  if (st == VD_ERR_VALUE && vd_harvest_done(o->s.h)) Py_RETURN_FALSE;
  if (st) return vdpy_raise(st, &err);
  Py_RETURN_TRUE;
}

static PyObject* vec(const double* v, npy_intp n) {
  npy_intp d[1] = {n};
  PyObject* a = PyArray_EMPTY(1, d, NPY_DOUBLE, 0);
  if (a && n) memcpy(PyArray_DATA((PyArrayObject*)a), v, (size_t)n * sizeof(double));
  return a;
}

static PyObject* harvest_observe(vdpy_harvest* o, PyObject* unused) {
  if (!have_episode(o) || !busy_check(o)) return NULL;
  vd_harvest_obs b;
  vd_harvest_observe(o->s.h, &b);
  double ee[3] = {b.ee_pos.x, b.ee_pos.y, b.ee_pos.z}, eq[4] = {b.ee_quat.w, b.ee_quat.x, b.ee_quat.y, b.ee_quat.z};
  double fp[3] = {b.fruit_pos.x, b.fruit_pos.y, b.fruit_pos.z}, fv[3] = {b.fruit_vel.x, b.fruit_vel.y, b.fruit_vel.z};
  double cp[3] = {b.cmd_pos.x, b.cmd_pos.y, b.cmd_pos.z}, pf[3] = {b.pull_force.x, b.pull_force.y, b.pull_force.z};
  double rf[3] = {b.robot_force.x, b.robot_force.y, b.robot_force.z};
  double touch[2] = {b.touching[0], b.touching[1]};
  return Py_BuildValue(
      "{s:d,s:L,s:s,s:N,s:N,s:d,s:N,s:N,s:N,s:i,s:N,s:N,s:O,s:N,s:N,s:d,s:N,s:d,s:d,s:N,s:O,s:s,s:d}", "time",
      b.time, "step", (long long)b.step, "phase", vd_harvest_phase_name(b.phase), "q", vec(b.q, b.nq), "qd",
      vec(b.qd, b.nq), "gripper_opening", b.gripper_opening, "ee_pos", vec(ee, 3), "ee_quat", vec(eq, 4),
      "cmd_pos", vec(cp, 3), "target_instance", b.target_instance, "fruit_pos", vec(fp, 3), "fruit_vel",
      vec(fv, 3), "held", b.held ? Py_True : Py_False, "touching", vec(touch, 2), "finger_force",
      vec(b.finger_force, 2), "grip_force", b.grip_force, "pull_force", vec(pf, 3), "pull_torque",
      b.pull_torque, "slip", b.slip, "robot_force", vec(rf, 3), "detached", b.detached ? Py_True : Py_False,
      "site", vd_harvest_site_name(b.site), "ik_error", b.ik_error);
}

// events from index `since` on
static PyObject* harvest_events(vdpy_harvest* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"since", NULL};
  PyObject* so = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|O:events", names, &so)) return NULL;
  int64_t since = 0;
  if (so && !vdpy_i64(so, "since", 0, INT32_MAX, &since)) return NULL;
  if (!have_episode(o) || !busy_check(o)) return NULL;
  return events_list(o->s.h, (int)since);
}

// the events of episode h from index since on, as dicts
static PyObject* events_list(const vd_harvest* h, int since) {
  const vd_harvest_event* ev;
  int n = vd_harvest_events(h, &ev);
  PyObject* list = PyList_New(0);
  for (int k = since; list && k < n; k++) {
    const vd_harvest_event* e = &ev[k];
    PyObject* d = Py_BuildValue("{s:d,s:s,s:d,s:i,s:i,s:s,s:d,s:d,s:s}", "time", e->time, "kind",
                                vd_harvest_event_name(e->kind), "value", e->value, "segment", e->seg, "instance",
                                e->instance, "class", e->cls >= 0 ? vd_sim_class_name((vd_sim_class)e->cls) : "",
                                "force", e->force, "moment", e->moment, "site", vd_harvest_site_name(e->site));
    if (!d || PyList_Append(list, d) < 0) Py_CLEAR(list);
    Py_XDECREF(d);
  }
  return list;
}

// the target's joint loads at every plant step of the last 0.5 s before its detachment
static PyObject* harvest_forces(vdpy_harvest* o, PyObject* unused) {
  if (!have_episode(o) || !busy_check(o)) return NULL;
  int n = vd_harvest_forces(o->s.h, NULL, 0);
  vd_harvest_force* x = PyMem_Malloc(sizeof *x * (size_t)(n ? n : 1));
  double* col = PyMem_Malloc(sizeof(double) * 7 * (size_t)(n ? n : 1));
  if (!x || !col) {
    PyMem_Free(x), PyMem_Free(col);
    return PyErr_NoMemory();
  }
  vd_harvest_forces(o->s.h, x, n);
  for (int k = 0; k < n; k++) {
    double v[7] = {x[k].time, x[k].calyx_force, x[k].calyx_moment, x[k].abscission_force,
                   x[k].abscission_moment, x[k].pull_force, x[k].broke};
    for (int c = 0; c < 7; c++) col[(size_t)c * (size_t)n + (size_t)k] = v[c];
  }
  static const char* keys[7] = {"time", "calyx_force", "calyx_moment", "abscission_force", "abscission_moment",
                                "pull_force", "broke"};
  PyObject* d = PyDict_New();
  for (int c = 0; d && c < 7; c++) {
    PyObject* a = vec(col + (size_t)c * (size_t)n, n);
    if (!a || PyDict_SetItemString(d, keys[c], a) < 0) Py_CLEAR(d);
    Py_XDECREF(a);
  }
  PyMem_Free(x), PyMem_Free(col);
  return d;
}

static PyObject* harvest_summary(vdpy_harvest* o, PyObject* unused) {
  if (!have_episode(o) || !busy_check(o)) return NULL;
  vd_harvest_summary s;
  vd_harvest_summarize(o->s.h, &s);
  return Py_BuildValue("{s:O,s:O,s:s,s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:i,s:i,s:d,s:d,s:d,s:d,s:L,s:L,s:i,s:s,s:K}",
                       "detached", s.detached ? Py_True : Py_False, "grasped", s.grasped ? Py_True : Py_False,
                       "site", vd_harvest_site_name(s.site), "time", s.time, "detach_force", s.detach_force,
                       "detach_moment", s.detach_moment, "calyx_threshold", s.calyx_threshold,
                       "abscission_threshold", s.abscission_threshold, "pull_force", s.pull_force, "max_pull_force",
                       s.max_pull_force, "max_displacement", s.max_displacement, "fruits_hit", s.fruits_hit,
                       "fruits_dropped", s.fruits_dropped, "ik_error", s.ik_error, "track_error", s.track_error,
                       "slip", s.slip, "duration", s.duration, "steps", (long long)s.steps, "plant_warnings",
                       (long long)s.plant_warnings, "target_instance", s.target_instance, "reason", s.reason,
                       "plant_seed", (unsigned long long)o->s.plant_seed);
}

static PyObject* harvest_done(vdpy_harvest* o, void* c) {
  return PyBool_FromLong(o->s.h ? vd_harvest_done(o->s.h) : 1);
}

static PyObject* harvest_info(vdpy_harvest* o, void* c) {
  const vd_scene* s = &o->s.scene;
  vd_harvest_obs b;
  memset(&b, 0, sizeof b);
  if (o->s.h) vd_harvest_observe(o->s.h, &b);
  return Py_BuildValue("{s:s,s:s,s:s,s:d,s:d,s:i,s:d,s:d,s:s,s:K,s:O}", "scene", s->path, "plant", s->plant_path,
                       "robot", s->robot_path, "control_dt", s->control_dt, "duration", s->duration, "nq", b.nq,
                       "gripper_open", s->gripper_open, "gripper_closed", s->gripper_closed, "method",
                       vd_harvest_method_name(s->method.method), "plant_seed", (unsigned long long)o->s.plant_seed,
                       "two_way", s->two_way ? Py_True : Py_False);
}

// the robot's full joint positions (pictures with the robot's MJCF)
static PyObject* harvest_qpos(vdpy_harvest* o, void* c) {
  if (!have_episode(o)) return NULL;
  int nq = 0;
  const double* q = vd_harvest_qpos(o->s.h, &nq);
  return vec(q, nq);
}

// the plant state of the current step, and the colliders the robot's geoms are to the plant
const vd_data* vdpy_harvest_plant_state(PyObject* obj, const vd_model** plant, const vd_sim_collider** col,
                                        int* ncol) {
  vdpy_harvest* o = (vdpy_harvest*)obj;
  if (!o->s.h) return NULL;
  const vd_sim_model* sm = vd_harvest_sim_model(o->s.h);
  const vd_sim_data* sd = vd_harvest_sim_data(o->s.h);
  vd_sim_to_plant(sm, sd, o->s.plant, o->s.pstate);
  *plant = o->s.plant;
  *col = sd->collider, *ncol = sd->ncollider;
  return o->s.pstate;
}

int vdpy_harvest_busy(PyObject* obj, int set) {
  vdpy_harvest* o = (vdpy_harvest*)obj;
  int was = o->busy;
  if (set >= 0) o->busy = set;
  return was;
}

// a labelled cloud of the plant in its current state (Plant.cloud's keywords)
static PyObject* harvest_cloud(vdpy_harvest* o, PyObject* args, PyObject* kw) {
  if (PyTuple_GET_SIZE(args)) return PyErr_Format(PyExc_TypeError, "cloud() takes keyword arguments only");
  if (!have_episode(o) || !busy_check(o)) return NULL;
  const vd_model* m;
  const vd_sim_collider* col;
  int ncol;
  const vd_data* d = vdpy_harvest_plant_state((PyObject*)o, &m, &col, &ncol);
  o->busy = 1;
  PyObject* r = vdpy_cloud_make(o->s.spec, m, d, o->s.plant_seed, kw);
  o->busy = 0;
  return r;
}

static PyObject* harvest_plant(vdpy_harvest* o, PyObject* unused) {
  if (!have_episode(o) || !busy_check(o)) return NULL;
  vd_plant_spec* spec = vd_plant_spec_copy(o->s.spec);
  if (!spec) return PyErr_NoMemory();
  vd_sim_to_spec(vd_harvest_sim_model(o->s.h), vd_harvest_sim_data(o->s.h), spec);
  return vdpy_plant_new(spec, o->s.plant_seed, o->s.scene.plant_path, NULL);
}

static PyGetSetDef harvest_getset[] = {
    {"done", (getter)harvest_done, NULL, "True when the episode is over", NULL},
    {"info", (getter)harvest_info, NULL, "the episode's scene: files, control_dt (s), duration (s), nq, gripper, method, plant seed", NULL},
    {"qpos", (getter)harvest_qpos, NULL, "the robot's MuJoCo joint positions (a copy)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMethodDef harvest_methods[] = {
    {"reset", (PyCFunction)(void (*)(void))harvest_reset, METH_VARARGS | METH_KEYWORDS,
     "reset($self, /, seed, episode=0, *, randomize=True)\n--\n\n"
     "reset(seed, episode=0, *, randomize=True): start episode `episode` of the scene's\n"
     "randomisation under seed (plant seed, target, method parameters); the plant is regrown\n"
     "when its seed changes, and drawn again (up to 32 draws) while no fruit is reachable.\n"
     "Returns the draws taken; BadValueError naming the scene when none was possible. Without\n"
     "the GIL."},
    {"step", (PyCFunction)(void (*)(void))harvest_step, METH_VARARGS | METH_KEYWORDS,
     "step($self, /, lin_vel, ang_vel, gripper)\n--\n\n"
     "step(lin_vel, ang_vel, gripper) -> bool: one control step under an end-effector velocity\n"
     "(m/s, rad/s, world frame) and a gripper command in [0, 1] (0 open, 1 closed), without the\n"
     "GIL; False when MuJoCo or the plant failed (the episode is then done)."},
    {"act", (PyCFunction)(void (*)(void))harvest_act, METH_VARARGS | METH_KEYWORDS,
     "act($self, /, lin_vel, ang_vel, gripper, weights, terminate_on_detach=True, max_steps=None)\n"
     "--\n\n"
     "One environment step (HarvestEnv.step) without the GIL: the action, then the reward of\n"
     "weights (7 numbers: detach, grasp, distance, pull_force, fracture, drop, hit) and the\n"
     "ending. Returns (ok, reward, terms, terminated, truncated, reason, events). ArgumentError\n"
     "before a successful reset and after the episode ended."},
    {"close", (PyCFunction)harvest_close, METH_NOARGS,
     "close($self, /)\n--\n\nFree the episode and its plant now; later calls that need them raise."},
    {"run", (PyCFunction)(void (*)(void))harvest_run, METH_VARARGS | METH_KEYWORDS,
     "run($self, /, until=None)\n--\n\n"
     "run(until=None) -> bool: the scene's scripted controller (approach, grasp, then pull, bend or\n"
     "twist) to the end of the episode, without the GIL, as `verdant harvest` runs it; False when\n"
     "MuJoCo or the plant failed. until: a phase name (e.g. \"reach\": the arm at its pre-grasp\n"
     "pose); the run stops as the controller enters it (True) and the episode goes on under\n"
     "step() or act(). Only before the first step() of an episode."},
    {"observe", (PyCFunction)harvest_observe, METH_NOARGS,
     "observe($self, /)\n--\n\n"
     "observe() -> dict: time, phase, joint state q and qd, end-effector pose, target fruit, grasp\n"
     "forces, detachment."},
    {"events", (PyCFunction)(void (*)(void))harvest_events, METH_VARARGS | METH_KEYWORDS,
     "events($self, /, since=0)\n--\n\n"
     "events(since=0) -> list of dicts: phase, touch, grasp, slip, release, fracture, detach, hit,\n"
     "drop and ik events from index since on."},
    {"forces", (PyCFunction)harvest_forces, METH_NOARGS,
     "forces($self, /)\n--\n\n"
     "forces() -> dict of arrays: the target fruit's joint loads at every plant step over the last\n"
     "0.5 s before its calyx or abscission joint broke (or before now): time (s), calyx_force (N),\n"
     "calyx_moment (N m), abscission_force, abscission_moment, pull_force (the gripper's sensor,\n"
     "N), broke (1 at the fracture's step, which carries the fracture's load); RUN/forces.csv."},
    {"summary", (PyCFunction)harvest_summary, METH_NOARGS,
     "summary($self, /)\n--\n\n"
     "summary() -> dict: the outcome so far (summary.json)."},
    {"cloud", (PyCFunction)(void (*)(void))harvest_cloud, METH_VARARGS | METH_KEYWORDS,
     "cloud($self, /, **options)\n--\n\n"
     "cloud(**options) -> Cloud: the plant in its current state (Plant.cloud's keywords)."},
    {"plant", (PyCFunction)harvest_plant, METH_NOARGS,
     "plant($self, /)\n--\n\n"
     "plant() -> Plant: the plant in its current state."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_harvest_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.Harvest",
    .tp_basicsize = sizeof(vdpy_harvest),
    .tp_dealloc = (destructor)harvest_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "Harvest(scene)\n--\n\nHarvest(scene): a harvest episode stepped from Python (see verdant.HarvestEnv).",
    .tp_methods = harvest_methods,
    .tp_getset = harvest_getset,
    .tp_new = harvest_new,
};
