// SPDX-License-Identifier: MIT
// Scene files (docs/formats.md "Harvest scenes"): JSON read into a vd_scene, every field checked
// with an error that names it, unknown keys rejected (a misspelt "grip_fource" would otherwise
// be ignored in silence); relative paths resolved against the scene's folder. Also the per-
// episode scene of a batch and the plant's placement.
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "robot_internal.h"

const char* vd_harvest_method_name(vd_harvest_method m) {
  static const char* n[VD_HARVEST_METHOD_COUNT] = {"pull", "bend", "twist"};
  return m >= 0 && m < VD_HARVEST_METHOD_COUNT ? n[m] : "?";
}

vd_method_def vd_method_def_default(void) {
  vd_method_def d;
  d.method = VD_HARVEST_PULL;
  d.approach_speed = 0.1;
  d.pregrasp = 0.06;
  d.speed = 0.02;
  d.distance = 0.08;
  d.angle = 0.5 * M_PI;
  d.angular_speed = 0.25 * M_PI;
  d.grip_force = 3.0;
  d.grip_friction = 0.8;
  d.touch_force = 0.02;
  d.hold = 0.3;
  return d;
}

void vd_scene_default(vd_scene* s) {
  memset(s, 0, sizeof *s);
  s->plant_steps = -1;
  s->plant_pos = vd_v3(0, 0, 0);
  snprintf(s->ee_site, sizeof s->ee_site, "tcp");
  snprintf(s->gripper[0], sizeof s->gripper[0], "finger_l");
  snprintf(s->gripper[1], sizeof s->gripper[1], "finger_r");
  s->gripper_open = 0.02;
  s->gripper_closed = 0.0;
  s->method = vd_method_def_default();
  s->sim_def = vd_sim_def_default();
  s->sim_def.sag_free = 1;
  s->draw_calyx[0] = 0.58, s->draw_calyx[1] = 2.46;
  s->draw_abscission[0] = 5.0, s->draw_abscission[1] = 8.0;
  s->sim_opt = vd_sim_opt_default();
  s->ground = 0.0;
  s->two_way = 0;
  s->duration = 10.0;
  s->control_dt = 0.01;
  s->fps = 30;
  s->frames = 1;
}

void vd_scene_free(vd_scene* s) {
  if (!s) return;
  for (int k = 0; k < s->nplant_set; k++) vd_free(s->plant_set[k], strlen(s->plant_set[k]) + 1);
  s->nplant_set = 0;
}

vd_status vd_scene_copy(const vd_scene* s, vd_scene* out, vd_error* err) {
  *out = *s;
  out->nplant_set = 0;
  for (int k = 0; k < s->nplant_set; k++) {
    char* p = vd_strdup(s->plant_set[k]);
    if (!p) {
      vd_scene_free(out);
      return vd_error_set(err, VD_ERR_NOMEM, s->path, 0, 0, "out of memory");
    }
    out->plant_set[out->nplant_set++] = p;
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// reading fields

typedef struct rd {
  const char* file; // for errors
  char dir[4096];   // the scene's folder ("" when none)
  vd_error* err;
} rd;

static vd_status bad(rd* r, const char* where, const char* key, const char* what) {
  return vd_error_set(r->err, VD_ERR_FORMAT, r->file, 0, 0, "%s%s%s: expected %s", where,
                      *where ? "." : "", key, what);
}

// every key of object o must be one of keys (NULL-terminated)
static vd_status known_keys(rd* r, const cJSON* o, const char* where, const char* const* keys) {
  for (const cJSON* c = o ? o->child : NULL; c; c = c->next) {
    int ok = 0;
    for (int k = 0; keys[k] && !ok; k++) ok = c->string && !strcmp(c->string, keys[k]);
    if (!ok)
      return vd_error_set(r->err, VD_ERR_FORMAT, r->file, 0, 0, "%s%s%s: unknown key", where,
                          *where ? "." : "", c->string ? c->string : "?");
  }
  return VD_OK;
}

// number key of o in [lo, hi] into *v when present (absent: *v unchanged)
static vd_status num(rd* r, const cJSON* o, const char* where, const char* key, double lo,
                     double hi, const char* what, double* v) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!x) return VD_OK;
  if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble) || x->valuedouble < lo || x->valuedouble > hi)
    return bad(r, where, key, what);
  *v = x->valuedouble;
  return VD_OK;
}

// the same with a value > lo strictly
static vd_status num_pos(rd* r, const cJSON* o, const char* where, const char* key, double hi,
                         const char* what, double* v) {
  double x = *v;
  vd_status st = num(r, o, where, key, 0, hi, what, &x);
  if (st) return st;
  if (cJSON_GetObjectItemCaseSensitive(o, key) && !(x > 0)) return bad(r, where, key, what);
  *v = x;
  return VD_OK;
}

// a boolean key into *v when present
static vd_status flag(rd* r, const cJSON* o, const char* where, const char* key, int* v) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!x) return VD_OK;
  if (!cJSON_IsBool(x)) return bad(r, where, key, "true or false");
  *v = cJSON_IsTrue(x);
  return VD_OK;
}

// an array of n numbers into v when present
static vd_status vec(rd* r, const cJSON* o, const char* where, const char* key, int n, double lim,
                     const char* what, double* v) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!x) return VD_OK;
  if (!cJSON_IsArray(x) || cJSON_GetArraySize(x) != n) return bad(r, where, key, what);
  for (int k = 0; k < n; k++) {
    const cJSON* e = cJSON_GetArrayItem(x, k);
    if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > lim)
      return bad(r, where, key, what);
    v[k] = e->valuedouble;
  }
  return VD_OK;
}

// a path key (non-empty string) resolved against the scene's folder
static vd_status path_of(rd* r, const cJSON* o, const char* where, const char* key, char* out,
                         size_t cap, int required) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!x) return required ? bad(r, where, key, "a file path (string)") : VD_OK;
  if (!cJSON_IsString(x) || !x->valuestring[0]) return bad(r, where, key, "a file path (string)");
  const char* p = x->valuestring;
  int n = (p[0] == '/' || !r->dir[0]) ? snprintf(out, cap, "%s", p)
                                      : snprintf(out, cap, "%s/%s", r->dir, p);
  if (n < 0 || (size_t)n >= cap) return bad(r, where, key, "a shorter path");
  return VD_OK;
}

// a name key (string shorter than cap) into out when present
static vd_status name_of(rd* r, const cJSON* o, const char* where, const char* key, char* out,
                         size_t cap) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!x) return VD_OK;
  if (!cJSON_IsString(x) || !x->valuestring[0] || strlen(x->valuestring) >= cap)
    return bad(r, where, key, "a name (string of 1..63 characters)");
  snprintf(out, cap, "%s", x->valuestring);
  return VD_OK;
}

// an object key (absent: NULL and VD_OK)
static vd_status obj(rd* r, const cJSON* o, const char* where, const char* key, const cJSON** out) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  *out = NULL;
  if (!x) return VD_OK;
  if (!cJSON_IsObject(x)) return bad(r, where, key, "an object");
  *out = x;
  return VD_OK;
}

// a range [lo, hi] with lo <= hi within [a, b]
static vd_status range(rd* r, const cJSON* o, const char* where, const char* key, double a,
                       double b, double scale, const char* what, double* v) {
  if (!cJSON_GetObjectItemCaseSensitive(o, key)) return VD_OK;
  double x[2] = {v[0] / scale, v[1] / scale};
  vd_status st = vec(r, o, where, key, 2, 1e300, what, x);
  if (st) return st;
  if (!(x[0] >= a && x[1] >= x[0] && x[1] <= b)) return bad(r, where, key, what);
  v[0] = x[0] * scale, v[1] = x[1] * scale;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// sections

static vd_status read_plant(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"file", "seed", "steps", "set", "pos", "yaw_deg", NULL};
  const char* w = "plant";
  if (!o) return bad(r, "", "plant", "an object with \"file\"");
  vd_status st = known_keys(r, o, w, keys);
  if (!st) st = path_of(r, o, w, "file", s->plant_path, sizeof s->plant_path, 1);
  double seed = (double)s->plant_seed, steps = s->plant_steps, pos[3] = {0, 0, 0}, yaw = 0;
  if (!st) st = num(r, o, w, "seed", 0, 9007199254740991.0, "a whole number >= 0", &seed);
  if (!st && seed != floor(seed)) st = bad(r, w, "seed", "a whole number >= 0");
  if (!st) st = num(r, o, w, "steps", -1, 1e6, "a whole number of derivation steps", &steps);
  if (!st && steps != floor(steps)) st = bad(r, w, "steps", "a whole number of derivation steps");
  if (!st) st = vec(r, o, w, "pos", 3, 1e4, "[x, y, z] (m)", pos);
  if (!st) st = num(r, o, w, "yaw_deg", -360, 360, "an angle in -360..360 (deg)", &yaw);
  if (st) return st;
  s->plant_seed = (uint64_t)seed;
  s->plant_steps = (int)steps;
  s->plant_pos = vd_v3(pos[0], pos[1], pos[2]);
  s->plant_yaw = yaw * M_PI / 180;
  const cJSON* set = cJSON_GetObjectItemCaseSensitive(o, "set");
  if (set) {
    if (!cJSON_IsObject(set)) return bad(r, w, "set", "an object of NAME: number");
    for (const cJSON* c = set->child; c; c = c->next) {
      if (!cJSON_IsNumber(c) || !isfinite(c->valuedouble) || !c->string[0] ||
          strlen(c->string) > 200)
        return vd_error_set(r->err, VD_ERR_FORMAT, r->file, 0, 0,
                            "plant.set.%s: expected a number", c->string);
      if (s->nplant_set == VD_SCENE_MAX_SET)
        return bad(r, w, "set", "at most 64 globals");
      char buf[256];
      snprintf(buf, sizeof buf, "%s=%.17g", c->string, c->valuedouble);
      char* p = vd_strdup(buf);
      if (!p) return vd_error_set(r->err, VD_ERR_NOMEM, r->file, 0, 0, "out of memory");
      s->plant_set[s->nplant_set++] = p;
    }
  }
  return VD_OK;
}

static vd_status read_robot(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"mjcf",    "base",         "q0",           "ee_site",
                               "gripper", "gripper_open", "gripper_closed", NULL};
  static const char* bkeys[] = {"pos", "yaw_deg", "auto", NULL};
  const char* w = "robot";
  if (!o) return bad(r, "", "robot", "an object with \"mjcf\"");
  vd_status st = known_keys(r, o, w, keys);
  if (!st) st = path_of(r, o, w, "mjcf", s->robot_path, sizeof s->robot_path, 1);
  const cJSON* base = NULL;
  if (!st) st = obj(r, o, w, "base", &base);
  if (!st && base) st = known_keys(r, base, "robot.base", bkeys);
  double pos[3] = {s->base_pos.x, s->base_pos.y, s->base_pos.z}, yaw = s->base_yaw * 180 / M_PI;
  if (!st && base) st = vec(r, base, "robot.base", "pos", 3, 1e4, "[x, y, z] (m)", pos);
  if (!st && base)
    st = num(r, base, "robot.base", "yaw_deg", -360, 360, "an angle in -360..360 (deg)", &yaw);
  if (!st && base) st = flag(r, base, "robot.base", "auto", &s->base_auto);
  if (st) return st;
  s->base_pos = vd_v3(pos[0], pos[1], pos[2]);
  s->base_yaw = yaw * M_PI / 180;
  const cJSON* q0 = cJSON_GetObjectItemCaseSensitive(o, "q0");
  if (q0) {
    int n = cJSON_IsArray(q0) ? cJSON_GetArraySize(q0) : -1;
    if (n < 1 || n > VD_ROBOT_MAX_JOINTS)
      return bad(r, w, "q0", "an array of 1..16 joint positions (rad or m)");
    if ((st = vec(r, o, w, "q0", n, 100, "an array of 1..16 joint positions (rad or m)", s->q0)))
      return st;
    s->nq0 = n;
  }
  if ((st = name_of(r, o, w, "ee_site", s->ee_site, sizeof s->ee_site))) return st;
  const cJSON* g = cJSON_GetObjectItemCaseSensitive(o, "gripper");
  if (g) {
    if (!cJSON_IsArray(g) || cJSON_GetArraySize(g) != 2)
      return bad(r, w, "gripper", "the names of the two finger actuators");
    for (int k = 0; k < 2; k++) {
      const cJSON* e = cJSON_GetArrayItem(g, k);
      if (!cJSON_IsString(e) || !e->valuestring[0] || strlen(e->valuestring) >= sizeof s->gripper[k])
        return bad(r, w, "gripper", "the names of the two finger actuators");
      snprintf(s->gripper[k], sizeof s->gripper[k], "%s", e->valuestring);
    }
  }
  if ((st = num(r, o, w, "gripper_open", -10, 10, "a finger actuator target (m)", &s->gripper_open)))
    return st;
  return num(r, o, w, "gripper_closed", -10, 10, "a finger actuator target (m)", &s->gripper_closed);
}

static vd_status read_target(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"fruit", NULL};
  if (!o) return VD_OK;
  vd_status st = known_keys(r, o, "target", keys);
  if (st) return st;
  const cJSON* f = cJSON_GetObjectItemCaseSensitive(o, "fruit");
  if (!f) return VD_OK;
  if (cJSON_IsString(f) && !strcmp(f->valuestring, "nearest_reachable")) {
    s->target_instance = 0;
    return VD_OK;
  }
  if (cJSON_IsNumber(f) && f->valuedouble >= 1 && f->valuedouble <= 2147483647.0 &&
      f->valuedouble == floor(f->valuedouble)) {
    s->target_instance = (int)f->valuedouble;
    return VD_OK;
  }
  return bad(r, "target", "fruit", "\"nearest_reachable\" or a fruit's instance id (>= 1)");
}

static vd_status read_method(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"name",           "approach_speed", "pregrasp",    "speed",
                               "distance",       "angle_deg",      "angular_speed_deg",
                               "grip_force",     "grip_friction",  "touch_force", "hold", NULL};
  const char* w = "method";
  if (!o) return VD_OK;
  vd_method_def* m = &s->method;
  vd_status st = known_keys(r, o, w, keys);
  if (st) return st;
  const cJSON* name = cJSON_GetObjectItemCaseSensitive(o, "name");
  if (name) {
    int k = VD_HARVEST_METHOD_COUNT;
    for (int i = 0; cJSON_IsString(name) && i < VD_HARVEST_METHOD_COUNT; i++)
      if (!strcmp(name->valuestring, vd_harvest_method_name((vd_harvest_method)i))) k = i;
    if (k == VD_HARVEST_METHOD_COUNT) return bad(r, w, "name", "\"pull\", \"bend\" or \"twist\"");
    m->method = (vd_harvest_method)k;
  }
  double ang = m->angle * 180 / M_PI, angv = m->angular_speed * 180 / M_PI;
  if (!st) st = num_pos(r, o, w, "approach_speed", 2, "a speed in (0, 2] (m/s)", &m->approach_speed);
  if (!st) st = num_pos(r, o, w, "pregrasp", 1, "a distance in (0, 1] (m)", &m->pregrasp);
  if (!st) st = num_pos(r, o, w, "speed", 2, "a speed in (0, 2] (m/s)", &m->speed);
  if (!st) st = num_pos(r, o, w, "distance", 2, "a distance in (0, 2] (m)", &m->distance);
  if (!st) st = num(r, o, w, "angle_deg", -720, 720, "an angle in -720..720 (deg)", &ang);
  if (!st) st = num_pos(r, o, w, "angular_speed_deg", 720, "a speed in (0, 720] (deg/s)", &angv);
  if (!st) st = num_pos(r, o, w, "grip_force", 1000, "a force in (0, 1000] (N)", &m->grip_force);
  if (!st) st = num(r, o, w, "grip_friction", 0, 10, "a coefficient in 0..10", &m->grip_friction);
  if (!st) st = num(r, o, w, "touch_force", 0, 100, "a force in 0..100 (N)", &m->touch_force);
  if (!st) st = num(r, o, w, "hold", 0, 100, "a time in 0..100 (s)", &m->hold);
  if (st) return st;
  m->angle = ang * M_PI / 180;
  m->angular_speed = angv * M_PI / 180;
  return VD_OK;
}

static vd_status read_episodes(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"plant_seed", "target", "speed", "distance", "angle_deg", "grip_force",
                               NULL};
  const char* w = "episodes";
  if (!o) return VD_OK;
  vd_episode_def* e = &s->episodes;
  vd_status st = known_keys(r, o, w, keys);
  if (!st) st = flag(r, o, w, "plant_seed", &e->plant_seed);
  const cJSON* t = cJSON_GetObjectItemCaseSensitive(o, "target");
  if (!st && t) {
    if (cJSON_IsString(t) && !strcmp(t->valuestring, "random_reachable")) e->random_target = 1;
    else if (cJSON_IsString(t) && !strcmp(t->valuestring, "scene")) e->random_target = 0;
    else st = bad(r, w, "target", "\"random_reachable\" or \"scene\"");
  }
  if (!st) st = range(r, o, w, "speed", 1e-6, 2, 1, "[lo, hi] speeds in (0, 2] (m/s)", e->speed);
  if (!st) st = range(r, o, w, "distance", 1e-6, 2, 1, "[lo, hi] distances in (0, 2] (m)", e->distance);
  if (!st)
    st = range(r, o, w, "angle_deg", -720, 720, M_PI / 180, "[lo, hi] angles in -720..720 (deg)",
               e->angle);
  if (!st)
    st = range(r, o, w, "grip_force", 1e-6, 1000, 1, "[lo, hi] forces in (0, 1000] (N)", e->grip_force);
  return st;
}

static vd_status read_materials(rd* r, const cJSON* o, vd_scene* s) {
  if (!o) return VD_OK;
  static const char* keys[] = {"young", "poisson", "density", "break_force", "break_moment",
                               "break_cs", "break_cb", "drag_cd", NULL};
  static const size_t off[] = {offsetof(vd_sim_material, young),
                               offsetof(vd_sim_material, poisson),
                               offsetof(vd_sim_material, density),
                               offsetof(vd_sim_material, break_force),
                               offsetof(vd_sim_material, break_moment),
                               offsetof(vd_sim_material, break_cs),
                               offsetof(vd_sim_material, break_cb),
                               offsetof(vd_sim_material, drag_cd)};
  for (const cJSON* c = o->child; c; c = c->next) {
    vd_sim_class k = vd_sim_class_parse(c->string ? c->string : "");
    if (k == VD_SIM_CLASS_COUNT)
      return vd_error_set(r->err, VD_ERR_FORMAT, r->file, 0, 0,
                          "materials.%s: unknown class (green, wood, pedicel, leaf, fruit, flower, "
                          "root)",
                          c->string ? c->string : "?");
    char where[64];
    snprintf(where, sizeof where, "materials.%s", c->string);
    if (!cJSON_IsObject(c)) return bad(r, "materials", c->string, "an object");
    vd_status st = known_keys(r, c, where, keys);
    if (st) return st;
    for (int i = 0; keys[i]; i++) {
      const cJSON* x = cJSON_GetObjectItemCaseSensitive(c, keys[i]);
      if (!x) continue;
      double* v = (double*)((char*)&s->sim_def.material[k] + off[i]);
      int brk = i >= 3 && i <= 6;
      // a fixed break force (or none): no draw for that joint
      if (i == 3 && k == VD_SIM_FRUIT) s->draw_calyx[0] = s->draw_calyx[1] = NAN;
      if (i == 3 && k == VD_SIM_PEDICEL) s->draw_abscission[0] = s->draw_abscission[1] = NAN;
      if (brk && cJSON_IsNull(x)) {
        *v = INFINITY;
        continue;
      }
      double lo = i == 1 ? -0.99 : 0, hi = i == 1 ? 0.5 : 1e15;
      if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble) || x->valuedouble < lo ||
          x->valuedouble > hi || (!brk && i != 1 && !(x->valuedouble > 0)))
        return bad(r, where, keys[i],
                   brk ? "a threshold >= 0, or null for none"
                       : i == 1 ? "a Poisson ratio in -0.99..0.5" : "a number > 0");
      *v = x->valuedouble;
    }
  }
  return VD_OK;
}

// "thresholds": {"calyx": [lo, hi] or null, "abscission": [lo, hi] or null} (N): each fruit's
// break forces drawn in [lo, hi]; null: the materials' fixed value
static vd_status read_thresholds(rd* r, const cJSON* o, vd_scene* s) {
  if (!o) return VD_OK;
  static const char* keys[] = {"calyx", "abscission", NULL};
  vd_status st = known_keys(r, o, "thresholds", keys);
  double* dst[2] = {s->draw_calyx, s->draw_abscission};
  for (int k = 0; !st && k < 2; k++) {
    const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, keys[k]);
    if (!x) continue;
    if (cJSON_IsNull(x)) {
      dst[k][0] = dst[k][1] = NAN;
      continue;
    }
    const cJSON* a = cJSON_IsArray(x) && cJSON_GetArraySize(x) == 2 ? x->child : NULL;
    const cJSON* b = a ? a->next : NULL;
    if (!a || !cJSON_IsNumber(a) || !cJSON_IsNumber(b) || !isfinite(a->valuedouble) || !isfinite(b->valuedouble) ||
        !(a->valuedouble > 0) || !(b->valuedouble >= a->valuedouble) || b->valuedouble > 1e6)
      return bad(r, "thresholds", keys[k], "[lo, hi] break forces with 0 < lo <= hi <= 1e6 (N), or null");
    dst[k][0] = a->valuedouble, dst[k][1] = b->valuedouble;
  }
  return st;
}

static vd_status read_sim(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"dt",       "iterations",     "solver",  "segment_length",
                               "sag_free", "friction",       "ground",  "self_collision",
                               "drag",     "damping",        "mass_damping", "gravity",
                               "stake",    NULL};
  const char* w = "sim";
  if (!o) return VD_OK;
  vd_status st = known_keys(r, o, w, keys);
  double it = s->sim_opt.iterations, g[3] = {s->sim_opt.gravity.x, s->sim_opt.gravity.y,
                                              s->sim_opt.gravity.z};
  if (!st) st = num_pos(r, o, w, "dt", 0.1, "a time step in (0, 0.1] (s)", &s->sim_opt.dt);
  if (!st) st = num(r, o, w, "iterations", 1, 100, "a whole number 1..100", &it);
  if (!st && it != floor(it)) st = bad(r, w, "iterations", "a whole number 1..100");
  const cJSON* sv = cJSON_GetObjectItemCaseSensitive(o, "solver");
  if (!st && sv) {
    if (cJSON_IsString(sv) && !strcmp(sv->valuestring, "direct")) s->sim_opt.solver = VD_SIM_DIRECT;
    else if (cJSON_IsString(sv) && !strcmp(sv->valuestring, "gs")) s->sim_opt.solver = VD_SIM_GS;
    else st = bad(r, w, "solver", "\"direct\" or \"gs\"");
  }
  if (!st)
    st = num_pos(r, o, w, "segment_length", 1, "a length in (0, 1] (m)", &s->sim_def.segment_length);
  if (!st) st = flag(r, o, w, "sag_free", &s->sim_def.sag_free);
  if (!st) st = num(r, o, w, "friction", 0, 10, "a coefficient in 0..10", &s->sim_opt.friction);
  const cJSON* gr = cJSON_GetObjectItemCaseSensitive(o, "ground");
  if (!st && gr) {
    if (cJSON_IsNull(gr)) s->ground = NAN;
    else st = num(r, o, w, "ground", -1e4, 1e4, "a height (m) or null for none", &s->ground);
  }
  if (!st) st = flag(r, o, w, "self_collision", &s->sim_opt.self_collision);
  if (!st) st = flag(r, o, w, "drag", &s->sim_opt.drag);
  if (!st) st = num(r, o, w, "damping", 0, 10, "a time in 0..10 (s)", &s->sim_opt.damping);
  if (!st) st = num(r, o, w, "mass_damping", 0, 1e4, "a rate in 0..1e4 (1/s)", &s->sim_opt.mass_damping);
  if (!st) st = vec(r, o, w, "gravity", 3, 1e4, "[x, y, z] (m/s^2)", g);
  if (!st)
    st = num(r, o, w, "stake", 0, 100, "a spacing >= 0 (m; 0: no stake)", &s->sim_def.stake_spacing);
  if (st) return st;
  s->sim_opt.iterations = (int)it;
  s->sim_opt.gravity = s->sim_def.gravity = vd_v3(g[0], g[1], g[2]);
  return VD_OK;
}

static vd_status read_outputs(rd* r, const cJSON* o, vd_scene* s) {
  static const char* keys[] = {"fps", "frames", NULL};
  if (!o) return VD_OK;
  vd_status st = known_keys(r, o, "outputs", keys);
  if (!st) st = num_pos(r, o, "outputs", "fps", 10000, "frames per second in (0, 10000]", &s->fps);
  const cJSON* f = cJSON_GetObjectItemCaseSensitive(o, "frames");
  if (!st && f) {
    const char* v = cJSON_IsString(f) ? f->valuestring : "";
    s->frames = !strcmp(v, "none") ? 0 : !strcmp(v, "bin") ? 1 : !strcmp(v, "jsonl") ? 2 : -1;
    if (s->frames < 0) st = bad(r, "outputs", "frames", "\"bin\", \"jsonl\" or \"none\"");
  }
  return st;
}

// ---------------------------------------------------------------------------------------------
// the whole file

static size_t skip_ws(const char* t, size_t len, size_t i) {
  while (i < len && (t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r')) i++;
  return i;
}

static vd_status read_root(rd* r, const cJSON* root, vd_scene* s) {
  static const char* keys[] = {"format",   "version",    "plant",   "robot",      "target",
                               "method",   "episodes",   "materials", "sim",      "two_way",
                               "duration", "control_dt", "outputs", "thresholds", NULL};
  if (!cJSON_IsObject(root)) return bad(r, "", "scene", "a JSON object");
  vd_status st = known_keys(r, root, "", keys);
  if (st) return st;
  const cJSON* fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
  if (!cJSON_IsString(fmt) || strcmp(fmt->valuestring, "verdant-scene") != 0)
    return bad(r, "", "format", "\"verdant-scene\"");
  const cJSON* ver = cJSON_GetObjectItemCaseSensitive(root, "version");
  if (!cJSON_IsNumber(ver) || ver->valuedouble != VD_SCENE_VERSION)
    return bad(r, "", "version", "1 (this verdant reads scene version 1)");
  const cJSON* sec[10];
  static const char* names[10] = {"plant", "robot",   "target",     "method", "episodes",
                                  "materials", "sim", "outputs", "thresholds", NULL};
  for (int k = 0; names[k]; k++)
    if ((st = obj(r, root, "", names[k], &sec[k]))) return st;
  if (!st) st = read_plant(r, sec[0], s);
  if (!st) st = read_robot(r, sec[1], s);
  if (!st) st = read_target(r, sec[2], s);
  if (!st) st = read_method(r, sec[3], s);
  if (!st) st = read_episodes(r, sec[4], s);
  if (!st) st = read_materials(r, sec[5], s);
  if (!st) st = read_sim(r, sec[6], s);
  if (!st) st = read_outputs(r, sec[7], s);
  if (!st) st = read_thresholds(r, sec[8], s);
  if (!st) st = flag(r, root, "", "two_way", &s->two_way);
  if (!st) st = num_pos(r, root, "", "duration", 3600, "a time in (0, 3600] (s)", &s->duration);
  if (!st)
    st = num_pos(r, root, "", "control_dt", 1, "a time step in (0, 1] (s)", &s->control_dt);
  return st;
}

vd_status vd_scene_parse(const char* text, size_t len, const char* name, vd_scene* out,
                         vd_error* err) {
  const char* file = name ? name : "";
  vd_scene_default(out);
  if (!text && len) return vd_error_set(err, VD_ERR_ARG, file, 0, 0, "null argument");
  if (len > VD_FILE_MAX)
    return vd_error_set(err, VD_ERR_LIMIT, file, 0, 0, "input larger than %zu bytes",
                        (size_t)VD_FILE_MAX);
  rd r;
  memset(&r, 0, sizeof r);
  r.file = file;
  r.err = err;
  snprintf(out->path, sizeof out->path, "%s", file);
  const char* slash = strrchr(file, '/');
  if (slash && (size_t)(slash - file) < sizeof r.dir) {
    memcpy(r.dir, file, (size_t)(slash - file));
    r.dir[slash - file] = 0;
    if (!r.dir[0]) snprintf(r.dir, sizeof r.dir, "/");
  }
  // JSON syntax: where cJSON stopped, and nothing but white space after the value
  const char* end = NULL;
  cJSON* root = len ? cJSON_ParseWithLengthOpts(text, len, &end, 0) : NULL;
  size_t pos = (end && end >= text) ? (size_t)(end - text) : 0;
  if (root) pos = skip_ws(text, len, pos);
  if (!root || pos < len) {
    int line = 1, col = 1;
    for (size_t i = 0; i < pos && i < len; i++) text[i] == '\n' ? (line++, col = 1) : col++;
    cJSON_Delete(root);
    return vd_error_set(err, VD_ERR_FORMAT, file, line, col,
                        !len ? "empty input: expected a scene object"
                        : root ? "text after the JSON value"
                               : "invalid JSON");
  }
  vd_status st = read_root(&r, root, out);
  cJSON_Delete(root);
  if (st) vd_scene_free(out);
  return st;
}

vd_status vd_scene_read(const char* path, vd_scene* out, vd_error* err) {
  vd_scene_default(out);
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  st = vd_scene_parse(text, len, path, out, err);
  vd_free(text, len + 1);
  return st;
}

// ---------------------------------------------------------------------------------------------
// placement and episodes

void vd_scene_place_plant(const vd_scene* s, vd_plant_spec* p) {
  vd_quat q = vd_quat_axis_angle(vd_v3(0, 0, 1), s->plant_yaw);
  for (int i = 0; i < p->nnode; i++) p->node[i] = vd_add(vd_quat_rotate(q, p->node[i]), s->plant_pos);
  for (int i = 0; i < p->nvert; i++) p->vert[i] = vd_add(vd_quat_rotate(q, p->vert[i]), s->plant_pos);
  for (int i = 0; i < p->nsphere; i++)
    p->sphere[i].center = vd_add(vd_quat_rotate(q, p->sphere[i].center), s->plant_pos);
  for (int i = 0; i < p->nseg; i++) p->seg[i].up = vd_quat_rotate(q, p->seg[i].up);
}

// uniform in [r0, r1] when the range is open, else keep v
static double draw(vd_rng* g, const double* r, double v) {
  double u = vd_rng_random(g);  // drawn always: the stream does not depend on which ranges are set
  return r[1] > r[0] ? r[0] + (r[1] - r[0]) * u : v;
}

vd_status vd_scene_episode(const vd_scene* s, uint64_t seed, int64_t k, vd_scene* out,
                           uint64_t* target_seed, vd_error* err) {
  vd_status st = vd_scene_copy(s, out, err);
  if (st) return st;
  vd_rng* g = vd_malloc(sizeof *g);
  if (!g) {
    vd_scene_free(out);
    return vd_error_set(err, VD_ERR_NOMEM, s->path, 0, 0, "out of memory");
  }
  vd_rng_stream(g, seed, (uint64_t)k);
  uint64_t ps = ((uint64_t)vd_rng_u32(g) << 21) ^ vd_rng_u32(g);  // 53 bits at most
  if (s->episodes.plant_seed) out->plant_seed = ps;
  if (s->episodes.random_target) out->target_instance = -1;
  *target_seed = ((uint64_t)vd_rng_u32(g) << 32) | vd_rng_u32(g);
  const vd_episode_def* e = &s->episodes;
  out->method.speed = draw(g, e->speed, s->method.speed);
  out->method.distance = draw(g, e->distance, s->method.distance);
  out->method.angle = draw(g, e->angle, s->method.angle);
  out->method.grip_force = draw(g, e->grip_force, s->method.grip_force);
  vd_free(g, sizeof *g);
  return VD_OK;
}
