// SPDX-License-Identifier: MIT
// verdant harvest: a MuJoCo robot picks a fruit off a simulated plant (a scene file says which
// plant, robot, fruit and method). One episode writes a run folder that `verdant render RUN/`
// draws (frames, colliders: the robot's geoms, rod.json, plant_initial.json) plus
// summary.json, events.csv and trajectory.csv; --episodes N runs a randomised batch, --jobs at a
// time, each episode a record in RUN/episodes/ (an interrupted batch resumes), then
// RUN/episodes.csv and RUN/summary.json with success rates and force statistics.
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const char* harvest_help =
    "usage: verdant harvest SCENE.json [-o RUN] [options]\n"
    "\n"
    "A robot (MuJoCo MJCF) harvests a fruit of a plant simulated as Cosserat rods: approach,\n"
    "grasp, then pull, bend or twist until the fruit comes off (docs/formats.md: scene files).\n"
    "\n"
    "  -o, --output RUN   write RUN/summary.json, RUN/events.csv, RUN/trajectory.csv and the\n"
    "                     frames that 'verdant render RUN/' draws (plant and robot)\n"
    "      --stats        print the summary (JSON) on stdout; the same bytes for the same\n"
    "                     inputs, as RUN/summary.json\n"
    "      --profile      the summaries add wall_seconds and real_time_factor (a batch:\n"
    "                     wall_seconds, episodes_per_minute): timings, which differ per run\n"
    "      --episodes N   a batch of N episodes, randomised as the scene's \"episodes\" says\n"
    "                     (plant seed, target, method parameters; one seed per episode):\n"
    "                     RUN/episodes/NNNNNN.json each, RUN/episodes.csv, RUN/summary.json\n"
    "                     (success rate per method, force distribution); complete episodes\n"
    "                     are skipped, so an interrupted batch resumes\n"
    "      --jobs J       episodes in parallel (default 1)\n"
    "      --seed S       seed of the batch (default 0)\n"
    "      --frames F     bin, jsonl or none (default: the scene's outputs.frames)\n"
    "      --duration T   longest episode (s), replaces the scene's\n"
    "      --two-way      the plant pushes the robot back; --one-way: it does not\n"
    "      --no-progress  no progress bar (it shows only when stderr is a terminal)\n";

typedef struct harvest_opts {
  const char* scene;
  const char* out;
  int stats, episodes, jobs, progress, two_way, profile;  // two_way: -1 the scene's
  uint64_t seed;
  const char* frames;
  double duration;  // < 0: the scene's
} harvest_opts;

static int parse_args(int argc, char** argv, harvest_opts* o) {
  const char* cmd = "harvest";
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    const char* val = NULL;
#define TAKE()                                                                                     \
  do {                                                                                             \
    if (i + 1 >= argc) return cli_usage_error(cmd, "%s needs a value", a);                         \
    val = argv[++i];                                                                               \
  } while (0)
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      TAKE();
      o->out = val;
    } else if (!strcmp(a, "--stats")) {
      o->stats = 1;
    } else if (!strcmp(a, "--profile")) {
      o->profile = 1;
    } else if (!strcmp(a, "--episodes")) {
      TAKE();
      int64_t n;
      if (!cli_parse_i64(val, 1, 10000000, &n))
        return cli_usage_error(cmd, "--episodes expects a count in 1..10000000, got '%s'", val);
      o->episodes = (int)n;
    } else if (!strcmp(a, "--jobs")) {
      TAKE();
      int64_t n;
      if (!cli_parse_i64(val, 1, 1024, &n))
        return cli_usage_error(cmd, "--jobs expects a count in 1..1024, got '%s'", val);
      o->jobs = (int)n;
    } else if (!strcmp(a, "--seed")) {
      TAKE();
      int64_t n;
      if (!cli_parse_i64(val, 0, INT64_MAX, &n))
        return cli_usage_error(cmd, "--seed expects a whole number >= 0, got '%s'", val);
      o->seed = (uint64_t)n;
    } else if (!strcmp(a, "--frames")) {
      TAKE();
      if (strcmp(val, "bin") != 0 && strcmp(val, "jsonl") != 0 && strcmp(val, "none") != 0)
        return cli_usage_error(cmd, "--frames expects bin, jsonl or none, got '%s'", val);
      o->frames = val;
    } else if (!strcmp(a, "--duration")) {
      TAKE();
      if (!cli_parse_num(val, &o->duration) || !(o->duration > 0) || o->duration > 3600)
        return cli_usage_error(cmd, "--duration expects a time in (0, 3600] (s), got '%s'", val);
    } else if (!strcmp(a, "--two-way")) {
      o->two_way = 1;
    } else if (!strcmp(a, "--one-way")) {
      o->two_way = 0;
    } else if (!strcmp(a, "--no-progress")) {
      o->progress = 0;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error(cmd, "unknown option '%s'", a);
    } else if (!o->scene) {
      o->scene = a;
    } else {
      return cli_usage_error(cmd, "unexpected argument '%s'", a);
    }
#undef TAKE
  }
  return EXIT_OK;
}

// ---------------------------------------------------------------------------------------------
// one episode

// the plant of a scene: grown (or read), placed, compiled
static vd_status scene_plant(const vd_scene* s, vd_plant_spec** spec, vd_model** plant, vd_error* err) {
  cli_plant_opts po;
  cli_plant_opts_init(&po);
  po.path = s->plant_path;
  po.seed = s->plant_seed;
  po.steps = s->plant_steps;
  po.progress = 0;
  for (int k = 0; k < s->nplant_set; k++) po.set[po.nset++] = s->plant_set[k];
  cli_grow_info info;
  *plant = NULL;
  vd_status st = cli_load_plant(&po, spec, &info, err);
  if (st) {
    cli_blame_input(err, s->plant_path);
    return st;
  }
  cli_grow_info_free(&info);
  vd_scene_place_plant(s, *spec);
  st = vd_plant_compile(*spec, plant, err);
  cli_blame_input(err, s->plant_path);
  return st;
}

// the keys every episode record begins with (NULL when out of memory)
static cJSON* record_begin(const vd_scene* s) {
  cJSON* o = cJSON_CreateObject();
  if (!o) return NULL;
  cJSON_AddStringToObject(o, "format", "verdant-harvest");
  cJSON_AddNumberToObject(o, "version", VD_HARVEST_FORMAT_VERSION);
  cJSON_AddStringToObject(o, "scene", s->path);
  cJSON_AddStringToObject(o, "method", vd_harvest_method_name(s->method.method));
  cJSON_AddBoolToObject(o, "two_way", s->two_way);
  cJSON_AddNumberToObject(o, "plant_seed", (double)s->plant_seed);
  return o;
}

// the summary of an episode as JSON (NULL when out of memory)
static cJSON* summary_json(const vd_harvest* h, double wall) {
  const vd_scene* s = vd_harvest_scene(h);
  vd_harvest_summary r;
  vd_harvest_summarize(h, &r);
  cJSON* o = record_begin(s);
  if (!o) return NULL;
  cJSON_AddNumberToObject(o, "target_instance", r.target_instance);
  cJSON_AddBoolToObject(o, "grasped", r.grasped);
  cJSON_AddBoolToObject(o, "detached", r.detached);
  cJSON_AddStringToObject(o, "site", vd_harvest_site_name(r.site));
  cJSON_AddNumberToObject(o, "detach_time", r.detached ? r.time : 0);
  cJSON_AddNumberToObject(o, "pedicel_force", r.detach_force);
  cJSON_AddNumberToObject(o, "pedicel_moment", r.detach_moment);
  // the target's break forces this episode (drawn per plant, or fixed); null: unbreakable, none
  cJSON_AddItemToObject(o, "calyx_threshold", isfinite(r.calyx_threshold) ? cJSON_CreateNumber(r.calyx_threshold)
                                                                           : cJSON_CreateNull());
  cJSON_AddItemToObject(o, "abscission_threshold", isfinite(r.abscission_threshold)
                                                       ? cJSON_CreateNumber(r.abscission_threshold)
                                                       : cJSON_CreateNull());
  cJSON_AddNumberToObject(o, "pull_force", r.pull_force);
  cJSON_AddNumberToObject(o, "max_pull_force", r.max_pull_force);
  cJSON_AddNumberToObject(o, "max_plant_displacement", r.max_displacement);
  cJSON_AddNumberToObject(o, "fruits_hit", r.fruits_hit);
  cJSON_AddNumberToObject(o, "fruits_dropped", r.fruits_dropped);
  cJSON_AddNumberToObject(o, "ik_error", r.ik_error);
  cJSON_AddNumberToObject(o, "track_error", r.track_error);
  cJSON_AddNumberToObject(o, "slip", r.slip);
  cJSON_AddNumberToObject(o, "grip_force_measured", r.grip_force);
  cJSON_AddNumberToObject(o, "speed", s->method.speed);
  cJSON_AddNumberToObject(o, "distance", s->method.distance);
  cJSON_AddNumberToObject(o, "angle_deg", s->method.angle * 180 / M_PI);
  cJSON_AddNumberToObject(o, "grip_force", s->method.grip_force);
  cJSON_AddNumberToObject(o, "duration", r.duration);
  cJSON_AddNumberToObject(o, "steps", (double)r.steps);
  cJSON_AddNumberToObject(o, "plant_warnings", (double)r.plant_warnings);
  cJSON_AddStringToObject(o, "reason", r.reason);
  if (r.detail[0]) cJSON_AddStringToObject(o, "detail", r.detail);
  if (wall >= 0) {
    cJSON_AddNumberToObject(o, "wall_seconds", wall);
    cJSON_AddNumberToObject(o, "real_time_factor", wall > 0 ? r.duration / wall : 0);
  }
  return o;
}

// write a JSON object to path (pretty) atomically; the object is deleted
static vd_status write_json(const char* path, cJSON* o, vd_error* err) {
  vd_status st = o ? cli_write_json(path, o, 1, err) : vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  cJSON_Delete(o);
  return st;
}

static vd_status write_events(const vd_harvest* h, const char* dir, vd_error* err) {
  char path[4200];
  snprintf(path, sizeof path, "%s/events.csv", dir);
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (st) {
    return st;
  }
  fputs("time_s,event,value,segment,instance,class,force_N,moment_Nm,site\n", f.fp);
  const vd_harvest_event* ev;
  int n = vd_harvest_events(h, &ev);
  for (int k = 0; k < n; k++) {
    const vd_harvest_event* e = &ev[k];
    const char* value = e->kind == VD_EV_PHASE ? vd_harvest_phase_name((vd_harvest_phase)(int)e->value) : NULL;
    fprintf(f.fp, "%.6f,%s,", e->time, vd_harvest_event_name(e->kind));
    if (value) fputs(value, f.fp);
    else fprintf(f.fp, "%.6g", e->value);
    fprintf(f.fp, ",%d,%d,%s,%.6g,%.6g,%s\n", e->seg, e->instance,
            e->cls >= 0 ? vd_sim_class_name((vd_sim_class)e->cls) : "", e->force, e->moment,
            e->kind == VD_EV_DETACH ? vd_harvest_site_name(e->site) : "");
  }
  st = vd_outfile_commit(&f, err);
  return st;
}

// RUN/forces.csv: the target's joint loads at every plant step over the last 0.5 s before it
// came off (docs/formats.md)
static vd_status write_forces(const vd_harvest* h, const char* dir, vd_error* err) {
  char path[4200];
  snprintf(path, sizeof path, "%s/forces.csv", dir);
  int n = vd_harvest_forces(h, NULL, 0);
  vd_harvest_force* x = vd_malloc(sizeof *x * (size_t)(n ? n : 1));
  if (!x) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  vd_harvest_forces(h, x, n);
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (!st) {
    fputs("time_s,calyx_force_N,calyx_moment_Nm,abscission_force_N,abscission_moment_Nm,pull_force_N,broke\n", f.fp);
    for (int k = 0; k < n; k++)
      fprintf(f.fp, "%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n", x[k].time, x[k].calyx_force, x[k].calyx_moment,
              x[k].abscission_force, x[k].abscission_moment, x[k].pull_force, x[k].broke);
    st = vd_outfile_commit(&f, err);
  }
  vd_free(x, sizeof *x * (size_t)(n ? n : 1));
  return st;
}

// what an episode run writes as it goes
typedef struct episode_out {
  const harvest_opts* o;
  cli_frames frames;
  vd_outfile traj;
  int traj_open, progress;
  double next_frame, fps;
  int write_failed;
} episode_out;

static void traj_header(FILE* f, int nq) {
  fputs("time_s,phase", f);
  for (int k = 0; k < nq; k++) fprintf(f, ",q%d", k);
  fputs(",ee_x,ee_y,ee_z,ee_qw,ee_qx,ee_qy,ee_qz,cmd_x,cmd_y,cmd_z,fruit_x,fruit_y,fruit_z,"
        "gripper_opening_m,held,grip_force_N,pull_x_N,pull_y_N,pull_z_N,pull_N,robot_force_N,"
        "ik_error_m\n",
        f);
}

static void progress_bar(double t, double total) {
  char text[64];
  snprintf(text, sizeof text, "%.2f / %.2f s", t, total);
  cli_progress_bar("harvesting", total > 0 ? t / total : 1, text);
}

static vd_status on_step(void* user, const vd_harvest* h) {
  episode_out* eo = user;
  vd_harvest_obs ob;
  vd_harvest_observe(h, &ob);
  if (eo->traj_open) {
    FILE* f = eo->traj.fp;
    fprintf(f, "%.6f,%s", ob.time, vd_harvest_phase_name(ob.phase));
    for (int k = 0; k < ob.nq; k++) fprintf(f, ",%.9g", ob.q[k]);
    fprintf(f, ",%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%.6g,%.6g,%.6g,"
               "%.6g,%.6g,%.6g,%.6g\n",
            ob.ee_pos.x, ob.ee_pos.y, ob.ee_pos.z, ob.ee_quat.w, ob.ee_quat.x, ob.ee_quat.y, ob.ee_quat.z,
            ob.cmd_pos.x, ob.cmd_pos.y, ob.cmd_pos.z, ob.fruit_pos.x, ob.fruit_pos.y, ob.fruit_pos.z,
            ob.gripper_opening, ob.held, ob.grip_force, ob.pull_force.x, ob.pull_force.y, ob.pull_force.z,
            vd_norm(ob.pull_force), vd_norm(ob.robot_force), ob.ik_error);
    if (ferror(f)) eo->write_failed = 1;
  }
  if (eo->frames.frames_open && (ob.time >= eo->next_frame - 1e-9 || vd_harvest_done(h))) {
    if (cli_frames_write(&eo->frames, vd_harvest_sim_model(h), vd_harvest_sim_data(h))) eo->write_failed = 1;
    while (eo->next_frame <= ob.time + 1e-9) eo->next_frame += 1.0 / eo->fps;
  }
  if (eo->write_failed) return VD_ERR_IO;  // the commit below says which file
  if (eo->progress && ob.step % 10 == 0) progress_bar(ob.time, vd_harvest_scene(h)->duration);
  return VD_OK;
}

// apply the command-line overrides to a scene
static void override(const harvest_opts* o, vd_scene* s) {
  if (o->two_way >= 0) s->two_way = o->two_way;
  if (o->duration > 0) s->duration = o->duration;
  if (o->frames) s->frames = !strcmp(o->frames, "none") ? 0 : !strcmp(o->frames, "bin") ? 1 : 2;
}

// the outcome of an episode as one line on stderr (without --stats: the run folder alone would
// say nothing, terminal or not)
static void outcome_line(const vd_harvest* h, const char* out) {
  vd_harvest_summary r;
  vd_harvest_summarize(h, &r);
  char detail[160] = "";
  if (r.detached)
    snprintf(detail, sizeof detail, ", detached at %.3f s (site %s, pull force %.3g N)", r.time,
             vd_harvest_site_name(r.site), r.pull_force);
  fprintf(stderr, "verdant harvest: %s: fruit %d %s%s; %s\n", r.reason, r.target_instance,
          r.grasped ? "grasped" : "not grasped", detail, out);
}

// the files a scene names are there; else exit 2 naming the key, the path and the folder a
// relative path is read from (a broken "../tomato.lpy" said only that a file was missing)
static int scene_files_exist(const vd_scene* s) {
  const char* key[2] = {"plant.file", "robot.mjcf"};
  const char* path[2] = {s->plant_path, s->robot_path};
  for (int k = 0; k < 2; k++)
    if (path[k][0] && access(path[k], F_OK) != 0) {
      fprintf(stderr, "verdant harvest: %s: %s: '%s' does not exist (%s; a relative path is read from the scene's folder)\n",
              s->path, key[k], path[k], strerror(errno));
      return 0;
    }
  return 1;
}

static int run_one(const harvest_opts* o, vd_scene* s) {
  vd_error err = {0};
  vd_plant_spec* spec = NULL;
  vd_model* plant = NULL;
  vd_harvest* h = NULL;
  int code = EXIT_OK;
  episode_out eo;
  memset(&eo, 0, sizeof eo);
  eo.o = o;
  eo.fps = s->fps;
  eo.progress = o->progress;
  vd_status st = scene_plant(s, &spec, &plant, &err);
  if (st) {
    code = cli_report("harvest", &err, st);
    goto done;
  }
  st = vd_harvest_create(s, plant, &h, &err);
  if (st) {
    code = cli_report("harvest", &err, st);
    goto done;
  }
  vd_harvest_obs ob0;
  vd_harvest_observe(h, &ob0);
  if (ob0.target_reason) {
    // a fruit the plant does not have is bad input; no reachable fruit is a clean outcome
    vd_harvest_end(h, ob0.target_reason);
    vd_harvest_summary r0;
    vd_harvest_summarize(h, &r0);
    if (!strcmp(ob0.target_reason, "no such fruit")) {
      vd_error_set(&err, VD_ERR_VALUE, s->path, 0, 0, "%s", r0.detail);
      code = cli_report("harvest", &err, VD_ERR_VALUE);
      goto done;
    }
    fprintf(stderr, "verdant harvest: %s\n", r0.detail[0] ? r0.detail : r0.reason);
  }
  // the run folder: a simulation run (for 'verdant render RUN/') plus the harvest's files
  if (o->out) {
    st = vd_outdir_make(o->out, &err);
    if (!st) st = cli_rod_json_write(vd_harvest_sim_model(h), plant, &s->sim_def, o->out, &err);
    char path[4200];
    if (!st) {
      snprintf(path, sizeof path, "%s/plant_initial.json", o->out);
      st = vd_plant_write_json(spec, path, &err);
    }
    if (!st && s->frames) st = cli_frames_begin(&eo.frames, vd_harvest_sim_model(h), o->out, s->frames == 2, &err);
    if (!st) {
      snprintf(path, sizeof path, "%s/trajectory.csv", o->out);
      st = vd_outfile_open(&eo.traj, path, &err);
      if (!st) {
        eo.traj_open = 1;
        int nq;
        vd_harvest_obs ob;
        vd_harvest_observe(h, &ob);
        nq = ob.nq;
        traj_header(eo.traj.fp, nq);
      }
    }
    if (st) {
      cli_report("harvest", &err, st);
      code = EXIT_FAIL;
      goto done;
    }
  }
  double t0 = cli_now();
  st = vd_harvest_run(h, on_step, &eo, &err);
  double wall = cli_now() - t0;
  if (eo.progress) cli_progress_clear();
  if (st && !eo.write_failed) {
    cli_report("harvest", &err, st);
    code = EXIT_FAIL;
    goto done;
  }
  st = VD_OK;
  if (o->out) {
    if (eo.traj_open) {
      st = vd_outfile_commit(&eo.traj, &err);
      eo.traj_open = 0;
    }
    vd_status s2 = cli_frames_end(&eo.frames, &err);
    st = st ? st : s2;
    if (!st) st = write_events(h, o->out, &err);
    if (!st) st = write_forces(h, o->out, &err);
    char path[4200];
    snprintf(path, sizeof path, "%s/summary.json", o->out);
    if (!st) st = write_json(path, summary_json(h, o->profile ? wall : -1), &err);
    if (st) {
      cli_report("harvest", &err, st);
      code = EXIT_FAIL;
      goto done;
    }
  }
  if (!o->stats) outcome_line(h, o->out);
  if (o->stats) {
    cJSON* j = summary_json(h, o->profile ? wall : -1);
    char* text = j ? cJSON_Print(j) : NULL;
    cJSON_Delete(j);
    if (!text) {
      code = EXIT_FAIL;
      goto done;
    }
    puts(text);
    cJSON_free(text);
  }
done:
  if (eo.traj_open) vd_outfile_abort(&eo.traj);
  cli_frames_abort(&eo.frames);
  vd_harvest_destroy(h);
  vd_model_destroy(plant);
  vd_plant_spec_destroy(spec);
  return code;
}

// ---------------------------------------------------------------------------------------------
// batches

// FNV-1a of the scene file's bytes and the batch seed: a record made with other inputs is not
// this batch's
static uint64_t batch_key(const char* text, size_t len, uint64_t seed) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < len; i++) h = (h ^ (unsigned char)text[i]) * 1099511628211ull;
  for (int k = 0; k < 8; k++) h = (h ^ ((seed >> (8 * k)) & 255)) * 1099511628211ull;
  return h;
}

typedef struct batch {
  const harvest_opts* o;
  const vd_scene* scene;
  const vd_robot* robot;  // loaded once, shared by every episode
  char key[32];
  char dir[4200];
} batch;

static void record_path(const batch* b, int k, char* path, size_t cap) {
  snprintf(path, cap, "%s/episodes/%06d.json", b->dir, k);
}

// the record of episode k when complete (made by this batch); else NULL (*mismatch when made by
// another)
static cJSON* complete_record(const batch* b, int k, int* mismatch) {
  char path[4300];
  record_path(b, k, path, sizeof path);
  if (access(path, F_OK)) return NULL;
  char* text;
  size_t len;
  vd_error e = {0};
  if (vd_file_read(path, &text, &len, &e)) return NULL;
  cJSON* r = cJSON_ParseWithLength(text, len);
  vd_free(text, len + 1);
  const cJSON* key = cJSON_GetObjectItemCaseSensitive(r, "batch");
  const cJSON* ep = cJSON_GetObjectItemCaseSensitive(r, "episode");
  if (!cJSON_IsString(key) || !cJSON_IsNumber(ep) || ep->valuedouble != k) {
    cJSON_Delete(r);
    return NULL;
  }
  if (strcmp(key->valuestring, b->key) != 0) {
    *mismatch = 1;
    cJSON_Delete(r);
    return NULL;
  }
  return r;
}

// the record of an episode that failed (its plant did not load, its simulation failed): an
// outcome with reason "failed" and the error, so that the batch goes on
static cJSON* failure_json(const vd_scene* s, const vd_error* e, vd_status st) {
  char buf[1024];
  cJSON* o = record_begin(s);
  if (!o) return NULL;
  cJSON_AddNumberToObject(o, "target_instance", 0);
  cJSON_AddBoolToObject(o, "grasped", 0);
  cJSON_AddBoolToObject(o, "detached", 0);
  cJSON_AddStringToObject(o, "site", vd_harvest_site_name(VD_SITE_NONE));
  cJSON_AddNumberToObject(o, "speed", s->method.speed);
  cJSON_AddNumberToObject(o, "distance", s->method.distance);
  cJSON_AddNumberToObject(o, "angle_deg", s->method.angle * 180 / M_PI);
  cJSON_AddNumberToObject(o, "grip_force", s->method.grip_force);
  cJSON_AddStringToObject(o, "reason", "failed");
  cJSON_AddStringToObject(o, "detail", e->status ? vd_error_format(e, buf, sizeof buf) : vd_status_str(st));
  return o;
}

// which of episodes 0..n-1 have a record file in the folder sub (calloc'd flags; NULL out of
// memory): one listing of the folder, not a look-up per episode, so that a batch of millions
// starts at once
static unsigned char* recorded_episodes(const char* sub, int n) {
  unsigned char* has = vd_calloc((size_t)n, 1);
  DIR* d = has ? opendir(sub) : NULL;
  if (!d) return has;
  const struct dirent* e;
  while ((e = readdir(d))) {
    char* end;
    long k = strtol(e->d_name, &end, 10);
    if (end != e->d_name && !strcmp(end, ".json") && k >= 0 && k < n) has[k] = 1;
  }
  closedir(d);
  return has;
}

// run episode k and write its record; an episode that fails is recorded as such (the batch
// goes on); only a record that cannot be written is an error
static vd_status make_episode(const batch* b, int k, vd_error* err) {
  vd_scene s;
  uint64_t tseed;
  vd_status st = vd_scene_episode(b->scene, b->o->seed, k, &s, &tseed, err);
  if (st) return st;
  vd_plant_spec* spec = NULL;
  vd_model* plant = NULL;
  vd_harvest* h = NULL;
  vd_error e = {0};
  st = scene_plant(&s, &spec, &plant, &e);
  if (!st) st = vd_harvest_create_with(&s, b->robot, plant, &h, &e);
  if (!st) st = vd_harvest_reset(h, tseed, &e);
  if (!st) st = vd_harvest_run(h, NULL, NULL, &e);
  cJSON* r = st ? failure_json(&s, &e, st) : summary_json(h, -1);
  if (r) {
    cJSON_AddNumberToObject(r, "episode", k);
    cJSON_AddStringToObject(r, "batch", b->key);
  }
  char path[4300];
  record_path(b, k, path, sizeof path);
  st = write_json(path, r, err);
  // a complete episode is kept even when the batch stops later (it resumes from there)
  const char* done[1] = {path};
  if (!st && cli_out_publish(done, 1, 1)) st = vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot put the record in place");
  vd_harvest_destroy(h);
  vd_model_destroy(plant);
  vd_plant_spec_destroy(spec);
  vd_scene_free(&s);
  return st;
}

static int cmp_double(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : x > y;
}

// statistics of n values (sorted in place): count, mean, sd, min, quartiles (linear
// interpolation: vd_quantile_sorted), max
static cJSON* stats_json(double* v, int n) {
  cJSON* o = cJSON_CreateObject();
  cJSON_AddNumberToObject(o, "n", n);
  if (!n) return o;
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  double s = 0, s2 = 0;
  for (int i = 0; i < n; i++) s += v[i];
  double mean = s / n;
  for (int i = 0; i < n; i++) s2 += (v[i] - mean) * (v[i] - mean);
  cJSON_AddNumberToObject(o, "mean", mean);
  cJSON_AddNumberToObject(o, "sd", n > 1 ? sqrt(s2 / (n - 1)) : 0);
  cJSON_AddNumberToObject(o, "min", v[0]);
  cJSON_AddNumberToObject(o, "q25", vd_quantile_sorted(v, n, 0.25));
  cJSON_AddNumberToObject(o, "median", vd_quantile_sorted(v, n, 0.5));
  cJSON_AddNumberToObject(o, "q75", vd_quantile_sorted(v, n, 0.75));
  cJSON_AddNumberToObject(o, "max", v[n - 1]);
  return o;
}

static double num_of(const cJSON* r, const char* key) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(r, key);
  return cJSON_IsNumber(x) ? x->valuedouble : 0;
}

static const char* str_of(const cJSON* r, const char* key) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(r, key);
  return cJSON_IsString(x) ? x->valuestring : "";
}

// episodes.csv and summary.json from every record
static int batch_summary(const batch* b, int n, double wall, int made, int skipped) {
  vd_error err = {0};
  char path[4300];
  snprintf(path, sizeof path, "%s/episodes.csv", b->dir);
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, &err);
  double* force = vd_malloc(sizeof(double) * (size_t)n * 2);
  double* pforce = force ? force + n : NULL;
  int nf = 0, ndet[VD_HARVEST_METHOD_COUNT] = {0}, nep[VD_HARVEST_METHOD_COUNT] = {0};
  int nsite[VD_SITE_COUNT] = {0}, ndetached = 0, ngrasp = 0, nharvest = 0;
  if (!st && !force) st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  if (!st) {
    fputs("episode,plant_seed,target_instance,method,speed,distance,angle_deg,grip_force,grasped,detached,site,"
          "detach_time,pull_force,pedicel_force,pedicel_moment,calyx_threshold,abscission_threshold,"
          "max_plant_displacement,fruits_hit,fruits_dropped,reason\n",
          f.fp);
    for (int k = 0; k < n && !st; k++) {
      int mm = 0;
      cJSON* r = complete_record(b, k, &mm);
      if (!r) {
        st = vd_error_set(&err, VD_ERR_IO, b->dir, 0, 0, "episode %d has no record", k);
        break;
      }
      const char* method = str_of(r, "method");
      int mi = 0;
      for (int i = 0; i < VD_HARVEST_METHOD_COUNT; i++)
        if (!strcmp(method, vd_harvest_method_name((vd_harvest_method)i))) mi = i;
      int det = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(r, "detached"));
      int gr = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(r, "grasped"));
      const char* site = str_of(r, "site");
      nep[mi]++;
      // a success is a harvest: the fruit came off while the gripper held it (a fruit knocked
      // off without a grasp counts as detached, not as harvested)
      ndet[mi] += det && gr;
      nharvest += det && gr;
      ndetached += det;
      ngrasp += gr;
      for (int i = 0; i < VD_SITE_COUNT; i++)
        if (!strcmp(site, vd_harvest_site_name((vd_harvest_site)i))) nsite[i]++;
      if (det && gr) force[nf] = num_of(r, "pull_force"), pforce[nf] = num_of(r, "pedicel_force"), nf++;
      // thresholds: empty where unbreakable or none (null in the record)
      char thr[2][32];
      const char* tk[2] = {"calyx_threshold", "abscission_threshold"};
      for (int i = 0; i < 2; i++) {
        const cJSON* x = cJSON_GetObjectItemCaseSensitive(r, tk[i]);
        if (cJSON_IsNumber(x)) snprintf(thr[i], sizeof thr[i], "%.6g", x->valuedouble);
        else thr[i][0] = 0;
      }
      fprintf(f.fp, "%d,%.0f,%.0f,%s,%.6g,%.6g,%.6g,%.6g,%d,%d,%s,%.6f,%.6g,%.6g,%.6g,%s,%s,%.6g,%.0f,%.0f,%s\n", k,
              num_of(r, "plant_seed"), num_of(r, "target_instance"), method, num_of(r, "speed"),
              num_of(r, "distance"), num_of(r, "angle_deg"), num_of(r, "grip_force"), gr, det, site,
              num_of(r, "detach_time"), num_of(r, "pull_force"), num_of(r, "pedicel_force"),
              num_of(r, "pedicel_moment"), thr[0], thr[1], num_of(r, "max_plant_displacement"),
              num_of(r, "fruits_hit"), num_of(r, "fruits_dropped"), str_of(r, "reason"));
      cJSON_Delete(r);
    }
    if (st) vd_outfile_abort(&f);
    else st = vd_outfile_commit(&f, &err);
  }
  cJSON* o = st ? NULL : cJSON_CreateObject();
  if (o) {
    cJSON_AddStringToObject(o, "format", "verdant-harvest-batch");
    cJSON_AddNumberToObject(o, "version", VD_HARVEST_FORMAT_VERSION);
    cJSON_AddStringToObject(o, "scene", b->scene->path);
    cJSON_AddNumberToObject(o, "seed", (double)b->o->seed);
    cJSON_AddNumberToObject(o, "episodes", n);
    cJSON_AddNumberToObject(o, "grasped", ngrasp);
    cJSON_AddNumberToObject(o, "detached", ndetached);
    cJSON_AddNumberToObject(o, "harvested", nharvest);
    cJSON_AddNumberToObject(o, "success_rate", n ? (double)nharvest / n : 0);
    cJSON* pm = cJSON_AddObjectToObject(o, "per_method");
    for (int i = 0; i < VD_HARVEST_METHOD_COUNT; i++) {
      if (!nep[i]) continue;
      cJSON* e = cJSON_AddObjectToObject(pm, vd_harvest_method_name((vd_harvest_method)i));
      cJSON_AddNumberToObject(e, "episodes", nep[i]);
      cJSON_AddNumberToObject(e, "harvested", ndet[i]);
      cJSON_AddNumberToObject(e, "success_rate", (double)ndet[i] / nep[i]);
    }
    cJSON* ps = cJSON_AddObjectToObject(o, "sites");
    for (int i = 1; i < VD_SITE_COUNT; i++) cJSON_AddNumberToObject(ps, vd_harvest_site_name((vd_harvest_site)i), nsite[i]);
    cJSON_AddItemToObject(o, "pull_force", stats_json(force, nf));
    cJSON_AddItemToObject(o, "pedicel_force", stats_json(pforce, nf));
    cJSON_AddNumberToObject(o, "made", made);
    cJSON_AddNumberToObject(o, "skipped", skipped);
    if (b->o->profile) {  // timings: only when asked (the same inputs write the same bytes)
      cJSON_AddNumberToObject(o, "wall_seconds", wall);
      cJSON_AddNumberToObject(o, "episodes_per_minute", wall > 0 ? 60.0 * made / wall : 0);
    }
  }
  vd_free(force, sizeof(double) * (size_t)n * 2);
  if (!st && !o) st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  char* text = NULL;
  if (!st && b->o->stats) text = cJSON_Print(o);
  snprintf(path, sizeof path, "%s/summary.json", b->dir);
  if (!st) st = write_json(path, o, &err);
  if (st) {
    free(text);
    cli_report("harvest", &err, st);
    return EXIT_FAIL;
  }
  if (text) puts(text);
  else
    fprintf(stderr, "verdant harvest: %d episode%s: success rate %.3f (%d harvested, %d detached, %d grasped); %s\n",
            n, n == 1 ? "" : "s", n ? (double)nharvest / n : 0, nharvest, ndetached, ngrasp, path);
  free(text);
  return EXIT_OK;
}

static int run_batch(const harvest_opts* o, const vd_scene* s) {
  if (!o->out) return cli_usage_error("harvest", "--episodes needs -o RUN (the batch's folder)");
  batch b;
  memset(&b, 0, sizeof b);
  b.o = o;
  b.scene = s;
  snprintf(b.dir, sizeof b.dir, "%s", o->out);
  for (size_t l = strlen(b.dir); l > 1 && b.dir[l - 1] == '/'; l--) b.dir[l - 1] = 0;  // RUN/ -> RUN/summary.json
  char* text;
  size_t len;
  vd_error err = {0};
  vd_status st = vd_file_read(s->path, &text, &len, &err);
  if (st) return cli_report("harvest", &err, st);
  char opts[96];
  snprintf(opts, sizeof opts, "%d %.17g %s", o->two_way, o->duration, o->frames ? o->frames : "");
  uint64_t key = batch_key(text, len, o->seed) ^ batch_key(opts, strlen(opts), 0);
  vd_free(text, len + 1);
  snprintf(b.key, sizeof b.key, "%016llx", (unsigned long long)key);
  char sub[4300];
  snprintf(sub, sizeof sub, "%s/episodes", b.dir);
  if ((st = vd_outdir_make(b.dir, &err)) || (st = vd_outdir_make(sub, &err))) {
    cli_report("harvest", &err, st);
    return EXIT_FAIL;
  }
  int n = o->episodes;
  int* todo = vd_malloc(sizeof(int) * (size_t)n);
  unsigned char* has = recorded_episodes(sub, n);
  if (!todo || !has) {
    vd_free(todo, sizeof(int) * (size_t)n);
    vd_free(has, (size_t)n);
    return cli_report("harvest", NULL, VD_ERR_NOMEM);
  }
  int ntodo = 0, skipped = 0, mismatch_at = -1;
  for (int k = 0; k < n; k++) {
    int mm = 0;
    cJSON* r = has[k] ? complete_record(&b, k, &mm) : NULL;
    if (mm && mismatch_at < 0) mismatch_at = k;
    if (r) skipped++;
    else todo[ntodo++] = k;
    cJSON_Delete(r);
  }
  vd_free(has, (size_t)n);
  if (mismatch_at >= 0) {
    vd_free(todo, sizeof(int) * (size_t)n);
    fprintf(stderr,
            "verdant harvest: %s: episode %d was made with another scene, seed or options; use another "
            "folder\n",
            b.dir, mismatch_at);
    return EXIT_USAGE;
  }
  vd_robot* robot = NULL;
  vd_status rst = vd_robot_load(s, &robot, &err);
  if (rst) {
    vd_free(todo, sizeof(int) * (size_t)n);
    return cli_report("harvest", &err, rst);
  }
  b.robot = robot;
  double t0 = cli_now();
  int done = 0, failed = -1;
  vd_error first = {0};
  vd_status first_st = VD_OK;
  if (o->progress) fprintf(stderr, "harvest: %d episode%s (%d complete already)\n", n, n == 1 ? "" : "s", skipped);
#pragma omp parallel for schedule(dynamic, 1) num_threads(o->jobs)
  for (int i = 0; i < ntodo; i++) {
    int stop;
#pragma omp atomic read
    stop = failed;
    if (stop >= 0) continue;
    vd_error e = {0};
    vd_status es = make_episode(&b, todo[i], &e);
#pragma omp critical(harvest_progress)
    {
      if (es && (failed < 0 || todo[i] < failed)) failed = todo[i], first = e, first_st = es;
      if (!es) done++;
      if (o->progress) {
        double el = cli_now() - t0;
        char line[96];
        snprintf(line, sizeof line, "%d/%d episodes, %.1f episodes/min   ", done, ntodo,
                 el > 0 ? 60 * done / el : 0.0);
        cli_progress_bar("harvest", ntodo ? (double)done / ntodo : 1, line);
      }
    }
  }
  if (o->progress) cli_progress_clear();
  vd_free(todo, sizeof(int) * (size_t)n);
  vd_robot_destroy(robot);
  if (failed >= 0) {
    char buf[1024];
    fprintf(stderr, "verdant harvest: episode %d: %s\n", failed,
            first.status ? vd_error_format(&first, buf, sizeof buf) : vd_status_str(first_st));
    return first_st == VD_ERR_IO || first_st == VD_ERR_NOMEM ? EXIT_FAIL : cli_exit_code(first_st);
  }
  return batch_summary(&b, n, cli_now() - t0, done, skipped);
}

int cli_harvest(int argc, char** argv) {
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
      fputs(harvest_help, stdout);
      return EXIT_OK;
    }
  harvest_opts o;
  memset(&o, 0, sizeof o);
  o.jobs = 1;
  o.two_way = -1;
  o.duration = -1;
  o.progress = isatty(2);
  int rc = parse_args(argc, argv, &o);
  if (rc) return rc;
  if (!o.scene) return cli_usage_error("harvest", "missing SCENE (a scene .json file)");
  // a scene that cannot be read says so before "nothing to do"
  vd_scene s;
  vd_error err = {0};
  vd_status st = vd_scene_read(o.scene, &s, &err);
  if (st) return cli_report("harvest", &err, st);
  if (!scene_files_exist(&s)) {
    vd_scene_free(&s);
    return EXIT_USAGE;
  }
  if (!o.out && !o.stats) {
    vd_scene_free(&s);
    return cli_usage_error("harvest", "nothing to do: give -o RUN and/or --stats");
  }
  override(&o, &s);
  // the files: the scene and what it names read; the run folder written (a single run replaces
  // an earlier one's files; a batch keeps its complete episodes and resumes)
  static const char* const run_files[] = {"summary.json", "events.csv", "trajectory.csv", "forces.csv"};
  static const char* const batch_files[] = {"summary.json", "episodes.csv", "episodes/*.json"};
  const char* members[32];
  int nm = 0;
  for (int k = 0; !o.episodes && k < cli_run_nmember && nm < 28; k++) members[nm++] = cli_run_members[k];
  if (o.episodes)
    for (int k = 0; k < 3; k++) members[nm++] = batch_files[k];
  else
    for (int k = 0; k < 4; k++) members[nm++] = run_files[k];
  cli_out_input("SCENE", o.scene);
  cli_out_input("the scene's plant", s.plant_path);
  cli_out_input("the scene's robot", s.robot_path);
  if (o.out) cli_out_folder("-o", o.out, members, nm, !o.episodes);
  if (cli_out_check("harvest")) {
    vd_scene_free(&s);
    return EXIT_USAGE;
  }
  rc = o.episodes ? run_batch(&o, &s) : run_one(&o, &s);
  vd_scene_free(&s);
  return rc;
}
