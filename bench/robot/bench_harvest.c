// SPDX-License-Identifier: MIT
// verdant harvest benchmark (issue 10, item 10): the real-time factor of a 10 s pull episode of
// data/scenes/tomato_pull.json (the Lite 6 and the full bundled tomato, one-way, one thread:
// approach, grasp, pull, then holding the fruit to t = 10 s) beside MuJoCo stepping the arm
// alone through the same joint motion in the same run (the peer: what the robot costs without
// the plant); then episodes per minute of `verdant harvest --episodes N` on 1 and on 2 jobs.
// Real-time factors are simulated seconds per CPU second of the thread (per wall second for the
// batches); the machine's load average is written beside each row (docs/benchmarks.md).
// Usage: verdant_bench_harvest [--quick] [--csv PATH] [--episodes N]
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "verdant/verdant.h"
#include "mjtrap/mjtrap.h"
#include "../bench_util.h"

// CPU seconds of this thread
static double thread_cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// CPU seconds of the finished child processes
static double children_cpu(void) {
  struct rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
         1e-6 * (double)ru.ru_stime.tv_usec;
}


// the scene's plant grown (seed and derivation steps of the scene), placed and compiled
static vd_model* scene_plant(const vd_scene* s) {
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  vd_plant_spec* spec = vd_plant_spec_create();
  vd_model* m = NULL;
  vd_plant_load_def def = vd_plant_load_def_default();
  def.lsys.seed = s->plant_seed;
  def.lsys.steps = s->plant_steps;
  vd_plant_spec_destroy(spec);
  spec = NULL;
  if (s->nplant_set) {
    fprintf(stderr, "bench: the scene sets plant globals; this bench grows the file as it is\n");
  } else if (!vd_plant_load(s->plant_path, &def, &spec, NULL, &err)) {
    vd_scene_place_plant(s, spec);
    vd_plant_compile(spec, &m, &err);
  }
  if (!m && err.msg[0]) {
    char buf[1200];
    fprintf(stderr, "%s\n", vd_error_format(&err, buf, sizeof buf));
  }
  vd_lsys_destroy(ls);
  vd_plant_spec_destroy(spec);
  return m;
}

typedef struct episode_out {
  double cpu, sim;          // CPU seconds of the thread, simulated seconds
  int detached, nq;
  char site[16];
  double force;             // pedicel force at detachment (N)
  int64_t steps;            // control steps
  double control_dt, robot_dt, plant_dt;
  int nseg;                 // rod segments of the plant
  double* q;                // arm joints per control step (steps x nq), for the peer
} episode_out;

// after each control step: the arm's joints recorded (the peer's targets)
typedef struct recorder {
  episode_out* o;
  int64_t n, cap;
} recorder;

static vd_status record(void* user, const vd_harvest* h) {
  recorder* r = user;
  vd_harvest_obs obs;
  vd_harvest_observe(h, &obs);
  if (r->n < r->cap) memcpy(r->o->q + r->n++ * r->o->nq, obs.q, sizeof(double) * (size_t)obs.nq);
  return VD_OK;
}

// one pull episode of the scene lasting duration, timed on this thread
static int run_episode(const vd_scene* s0, const vd_model* plant, double duration, episode_out* o) {
  vd_scene s;
  vd_error err = {0};
  memset(o, 0, sizeof *o);
  if (vd_scene_copy(s0, &s, &err)) return 0;
  s.duration = duration;
  s.method.hold = duration;  // hold the detached fruit to the end: a full-length episode
  vd_harvest* h = NULL;
  int ok = 0;
  if (!vd_harvest_create(&s, plant, &h, &err) && !vd_harvest_reset(h, 0, &err)) {
    vd_harvest_obs obs;
    vd_harvest_observe(h, &obs);
    o->nq = obs.nq;
    recorder r = {o, 0, (int64_t)(duration / s.control_dt + 4)};
    o->q = calloc((size_t)r.cap * (size_t)o->nq, sizeof(double));
    if (o->q) {
      double t0 = thread_cpu();
      ok = vd_harvest_run(h, record, &r, &err) == VD_OK;
      o->cpu = thread_cpu() - t0;
      vd_harvest_summary sum;
      vd_harvest_summarize(h, &sum);
      o->sim = sum.duration;
      o->steps = r.n;
      o->detached = sum.detached;
      o->force = sum.detach_force;
      snprintf(o->site, sizeof o->site, "%s", vd_harvest_site_name(sum.site));
      const vd_sim_model* sm = vd_harvest_sim_model(h);
      o->plant_dt = sm->opt.dt;
      o->nseg = sm->nseg;
      o->control_dt = s.control_dt;
    }
  }
  if (!ok && err.msg[0]) {
    char buf[1200];
    fprintf(stderr, "episode: %s\n", vd_error_format(&err, buf, sizeof buf));
  }
  vd_harvest_destroy(h);
  vd_scene_free(&s);
  return ok;
}

// the peer: MuJoCo stepping the arm alone (the same MJCF, timestep and servos, gravity
// compensated as in an episode) through the episode's joint motion; CPU seconds of the thread
static double arm_alone(const char* mjcf, const episode_out* e, double* robot_dt) {
  mjModel* m = NULL;
  vd_error err = {0};
  if (vd_mj_load_xml(mjcf, "robot", &m, &err)) {
    char buf[1200];
    fprintf(stderr, "%s\n", vd_error_format(&err, buf, sizeof buf));
    return -1;
  }
  mjData* d = mj_makeData(m);
  double cpu = -1;
  vd_mj_trap trap;
  if (d && VD_MJ_TRY(&trap)) {
    *robot_dt = m->opt.timestep;
    int per = (int)(e->control_dt / m->opt.timestep + 0.5);
    int narm = e->nq < m->nu ? e->nq : m->nu;
    double t0 = thread_cpu();
    for (int64_t k = 0; k < e->steps; k++) {
      for (int j = 0; j < narm; j++) d->ctrl[j] = e->q[k * e->nq + j];
      for (int r = 0; r < per; r++) {
        mj_step1(m, d);
        for (int j = 0; j < m->nv; j++) d->qfrc_applied[j] = d->qfrc_bias[j];
        mj_step2(m, d);
      }
    }
    cpu = thread_cpu() - t0;
    vd_mj_trap_end(&trap);
  } else if (d) {
    fprintf(stderr, "MuJoCo: %s\n", trap.error);
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return cpu;
}

// `verdant harvest SCENE --episodes n --jobs j` into a scratch folder: episodes per minute (wall)
// and CPU seconds per episode; -1 on failure
static double batch(const char* verdant, const char* scene, int n, int jobs, double* cpu_per) {
  char dir[] = "/tmp/verdant_bench_harvest.XXXXXX";
  if (!mkdtemp(dir)) return -1;
  char cmd[8192];
  snprintf(cmd, sizeof cmd, "'%s' harvest '%s' --episodes %d --jobs %d --frames none --no-progress -o '%s/b' 2>/dev/null",
           verdant, scene, n, jobs, dir);
  double c0 = children_cpu(), w0 = bench_wall();
  int rc = system(cmd);
  double wall = bench_wall() - w0, cpu = children_cpu() - c0;
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0) fprintf(stderr, "bench: could not remove %s\n", dir);
  if (rc != 0) {
    fprintf(stderr, "bench: verdant harvest --episodes failed (%d)\n", rc);
    return -1;
  }
  *cpu_per = cpu / n;
  return 60.0 * n / wall;
}

int main(int argc, char** argv) {
  int quick = 0, n = 8;
  const char* csv_path = VD_SOURCE_DIR "/bench/results/harvest-2core.csv";
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1, n = 4;
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else if (!strcmp(argv[i], "--episodes") && i + 1 < argc) n = atoi(argv[++i]);
    else {
      fprintf(stderr, "usage: verdant_bench_harvest [--quick] [--csv PATH] [--episodes N]\n");
      return 2;
    }
  }
  if (n < 1) n = 1;
  vd_mj_trap_install();
  const char* scene_path = VD_SOURCE_DIR "/data/scenes/tomato_pull.json";
  vd_scene s;
  vd_error err = {0};
  if (vd_scene_read(scene_path, &s, &err)) {
    char buf[1200];
    fprintf(stderr, "%s\n", vd_error_format(&err, buf, sizeof buf));
    return 1;
  }
  vd_model* plant = scene_plant(&s);
  if (!plant) return 1;
  FILE* csv = fopen(csv_path, "w");
  if (!csv) {
    perror(csv_path);
    return 1;
  }
  fprintf(csv, "case,what,sim_s,cpu_s,realtime,episodes,jobs,episodes_per_min,cpu_s_per_episode,segments,"
               "plant_dt_s,robot_dt_s,control_dt_s,detached,site,pedicel_force_N,load1\n");
  double duration = quick ? 6 : 10;
  episode_out e;
  if (!run_episode(&s, plant, duration, &e)) return 1;
  double robot_dt = 0, l = bench_load1();
  printf("pull episode, full tomato (%d segments, plant dt %.4g s): %.2f s simulated in %.2f CPU s: %.2fx real "
         "time; detached %d at the %s (%.2f N)\n",
         e.nseg, e.plant_dt, e.sim, e.cpu, e.sim / e.cpu, e.detached, e.site, e.force);
  double acpu = arm_alone(s.robot_path, &e, &robot_dt);
  fprintf(csv, "episode_pull,lite6+tomato one-way,%.3f,%.4f,%.3f,1,1,,,%d,%.6g,%.6g,%.6g,%d,%s,%.4f,%.2f\n", e.sim, e.cpu,
          e.sim / e.cpu, e.nseg, e.plant_dt, robot_dt, e.control_dt, e.detached, e.site, e.force, l);
  if (acpu > 0) {
    printf("peer: MuJoCo stepping the arm alone through the same motion: %.4f CPU s: %.1fx real time "
           "(the plant costs %.1fx the arm)\n",
           acpu, e.sim / acpu, e.cpu / acpu);
    fprintf(csv, "arm_alone,lite6 MuJoCo only,%.3f,%.5f,%.2f,1,1,,,0,,%.6g,%.6g,,,,%.2f\n", e.sim, acpu, e.sim / acpu,
            robot_dt, e.control_dt, bench_load1());
  }
  free(e.q);
  // batches through the CLI beside this program (build/verdant)
  char verdant[4096];
  snprintf(verdant, sizeof verdant, "%s", argv[0]);
  char* slash = strrchr(verdant, '/');
  snprintf(slash ? slash + 1 : verdant, sizeof verdant - (size_t)(slash ? slash + 1 - verdant : 0), "verdant");
  for (int jobs = 1; jobs <= 2; jobs++) {
    double cpe = 0, l0 = bench_load1();
    double epm = batch(verdant, scene_path, n, jobs, &cpe);
    if (epm < 0) continue;
    printf("batch of %d episodes on %d job%s: %.1f episodes/min (%.2f CPU s per episode; load %.1f)\n", n, jobs,
           jobs > 1 ? "s" : "", epm, cpe, l0);
    fprintf(csv, "batch,verdant harvest --episodes,,,,%d,%d,%.2f,%.3f,,,,,,,,%.2f\n", n, jobs, epm, cpe, l0);
  }
  fclose(csv);
  printf("wrote %s\n", csv_path);
  vd_model_destroy(plant);
  vd_scene_free(&s);
  return 0;
}
