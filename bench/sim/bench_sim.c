// SPDX-License-Identifier: MIT
// verdant sim benchmarks: steps per second of the bundled tomato and tree at dt = 1 ms (direct
// solver, the default; Gauss-Seidel for comparison), and the solver choice: the error of the
// settled sag and the cost per step of direct vs Gauss-Seidel on a wood and a green cantilever.
// Results go to bench/results/sim-<machine>.csv. The MuJoCo capsule-chain peer lives in the
// collide engineer's bench (bench_mujoco_chain.c) and is compared in docs/benchmarks.md.
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "verdant/verdant.h"
#include "../bench_util.h"

// a plant run's settings
typedef struct run_def {
  const char* name;      // case name in the CSV
  vd_sim_solver solver;  // solver
  int iters, threads;    // Newton iterations (or sweeps), threads of the step
  int self;              // self-collision
  double secs;           // simulated time (s)
  double active;         // region of interest radius around the first fruit (m), 0 off
  int leaves, leaf_segments;  // def.leaf_graphs, def.leaf_segments
  double leaf_sigma;     // segment length of the leaf class (m), 0: default
  int profile;           // stage rows too
  int bare;              // no sag-free, no probe (the tree: a kinematic probe cannot push its trunk)
} run_def;

// the model of a run: sag-free, with its reductions
static vd_sim_model* run_model(const vd_model* pm, const run_def* r) {
  vd_sim_def def = vd_sim_def_default();
  def.sag_free = !r->bare;
  def.leaf_graphs = r->leaves;
  def.leaf_segments = r->leaf_segments;
  def.class_segment_length[VD_SIM_LEAF] = r->leaf_sigma;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  if (vd_sim_build(pm, &def, &m, &e)) {
    fprintf(stderr, "%s: %s\n", r->name, e.msg);
    return NULL;
  }
  if (r->active > 0) {
    int f = vd_sim_find_organ(m, pm, "fruit", 0);
    def.active_radius = r->active;
    def.active_a = def.active_b = m->node_pos0[f >= 0 ? f : 0];
    vd_sim_model_destroy(m);
    if (vd_sim_build(pm, &def, &m, &e)) return NULL;
  }
  m->opt.solver = r->solver;
  m->opt.iterations = r->iters;
  m->opt.self_collision = r->self;
  m->opt.threads = r->threads;
  return m;
}

// a plant run: sag-free plant, ground, a probe sweeping through the crown at 60 % of the
// height; steps/s from the process CPU time on one thread, from the wall time on several
static double plant_run(FILE* csv, const vd_model* pm, const run_def* r) {
  vd_sim_model* m = run_model(pm, r);
  if (!m) return 0;
  vd_sim_data* d = vd_sim_data_create(m);
  d->profile = r->profile;
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  double top = 0;
  for (int i = 0; i < m->nnode; i++) top = fmax(top, m->node_pos0[i].z);
  vd_sim_collider p = {VD_SIM_SPHERE, {0.04, 0, 0}, vd_v3(0.5, 0, 0.6 * top), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  int id = r->bare ? -1 : vd_sim_add_collider(d, &p);
  int steps = (int)(r->secs / m->opt.dt + 0.5);
  double l0 = bench_load1(), w0 = bench_wall(), c0 = bench_cpu();
  for (int k = 0; k < steps; k++) {
    if (id >= 0) vd_sim_set_collider_pose(m, d, id, vd_v3(0.5 - 1.0 * k / steps, 0, 0.6 * top), vd_quat_identity());
    vd_sim_step(m, d);
  }
  double wall = bench_wall() - w0, ct = bench_cpu() - c0;
  int dyn = 0;
  for (int t = 0; t < m->nseg; t++) dyn += !(m->seg_flags[t] & VD_SIM_FIXED);
  double sps = steps / (r->threads > 1 ? wall : ct), load = 0.5 * (l0 + bench_load1());
  printf("%-22s %-6s %2d it %2d thr  %6d seg  %8.0f steps/s  %6.2fx real time  %6.3f us/seg-step  (cpu %.2f s, wall %.2f s, "
         "load %.1f, %lld warnings)\n",
         r->name, r->solver == VD_SIM_GS ? "gs" : "direct", r->iters, r->threads, dyn, sps, sps * m->opt.dt,
         1e6 / sps / dyn, ct, wall, load, (long long)d->nwarning);
  fprintf(csv, "plant,%s,%s,%d,%d,%d,%.6f,%.6f,%.1f,%.3f,%.4f,,,%d,%.2f,%s\n", r->name, r->solver == VD_SIM_GS ? "gs" : "direct",
          r->iters, dyn, steps, ct, wall, sps, sps * m->opt.dt, 1e6 / sps / dyn, r->threads, load,
          r->threads > 1 ? "steps/s from wall time" : "steps/s from CPU time");
  if (r->profile) {
    // where the time goes: each stage per segment and step, and its share
    double tot = 0;
    for (int k = 0; k < VD_SIM_STAGE_COUNT; k++) tot += d->stage_seconds[k];
    printf("   stages (us per segment-step, share):");
    for (int k = 0; k < VD_SIM_STAGE_COUNT; k++) {
      double v = d->stage_seconds[k] / steps / dyn * 1e6;
      printf(" %s %.4f (%.1f%%)", vd_sim_stage_name((vd_sim_stage)k), v, 100 * d->stage_seconds[k] / tot);
      fprintf(csv, "stage,%s_%s,,,%d,%d,,%.6f,,,%.5f,,,%d,%.2f,share %.4f of the step's wall time\n", r->name,
              vd_sim_stage_name((vd_sim_stage)k), dyn, steps, d->stage_seconds[k], v, r->threads, load,
              d->stage_seconds[k] / tot);
    }
    printf("\n");
  }
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  return sps;
}

// what a model reduction changes: the first fruit pulled down by 0.5 N for 0.3 s (its
// displacement), then pulled by a force ramped from 0 to 5 N over 0.6 s until its calyx breaks
// (the force then); steps/s of the plain sag-free plant
static void reduction_run(FILE* csv, const vd_model* pm, const run_def* r, double* base) {
  vd_sim_model* m = run_model(pm, r);
  if (!m) return;
  int f = vd_sim_find_organ(m, pm, "fruit", 0);
  vd_sim_data* d = vd_sim_data_create(m);
  double c0 = bench_cpu();
  int steps = 0;
  for (; steps < 300; steps++) {
    d->node_force[f] = vd_v3(0, 0, -0.5);
    vd_sim_step(m, d);
  }
  double disp = vd_norm(vd_sub(d->node_pos[f], m->node_pos0[f]));
  vd_sim_data_reset(m, d);
  double fbreak = -1;
  for (int k = 0; k < 600 && !d->nevent; k++, steps++) {
    d->node_force[f] = vd_v3(0, 0, -5.0 * k / 600);
    vd_sim_step(m, d);
    if (d->nevent) fbreak = 5.0 * k / 600;
  }
  double ct = bench_cpu() - c0, sps = steps / ct;
  int dyn = 0;
  for (int t = 0; t < m->nseg; t++) dyn += !(m->seg_flags[t] & VD_SIM_FIXED);
  if (base[0] == 0) base[0] = disp, base[1] = fbreak, base[2] = sps;
  printf("%-22s %6d seg  %8.0f steps/s (x %.2f)  fruit under 0.5 N: %.4f mm (%+.1f %%)  calyx breaks at %.3f N (%+.1f %%)\n",
         r->name, dyn, sps, sps / base[2], 1e3 * disp, 100 * (disp - base[0]) / base[0], fbreak,
         100 * (fbreak - base[1]) / base[1]);
  fprintf(csv, "reduction,%s,direct,1,%d,%d,%.6f,,%.1f,%.3f,%.4f,%.6g,%.6g,1,%.2f,fruit displacement under 0.5 N (m) / "
               "relative change; speed-up %.2f; calyx breaks at %.4f N (full %.4f N)\n",
          r->name, dyn, steps, ct, sps, sps * m->opt.dt, 1e6 / sps / dyn, disp, (disp - base[0]) / base[0], bench_load1(),
          sps / base[2], fbreak, base[1]);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
}

// a batch of n tomatoes (one model, n states, probes at different heights) on `threads` threads
// through vd_sim_step_batch: steps/s of all states together, from the wall time
static double batch_run(FILE* csv, const vd_model* pm, int n, int threads, double secs) {
  run_def r = {"batch", VD_SIM_DIRECT, 1, 1, 0, secs, 0, 1, 0, 0, 0, 0};
  vd_sim_model* m = run_model(pm, &r);
  if (!m) return 0;
  vd_sim_data* d[64];
  double top = 0;
  for (int i = 0; i < m->nnode; i++) top = fmax(top, m->node_pos0[i].z);
  for (int i = 0; i < n; i++) {
    d[i] = vd_sim_data_create(m);
    vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    vd_sim_add_collider(d[i], &g);
    vd_sim_collider p = {VD_SIM_SPHERE, {0.04, 0, 0}, vd_v3(0.5, 0.01 * i, 0.6 * top), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    vd_sim_add_collider(d[i], &p);
  }
  int steps = (int)(secs / m->opt.dt + 0.5);
  double l0 = bench_load1(), w0 = bench_wall(), c0 = bench_cpu();
  for (int k = 0; k < steps; k++) {
    for (int i = 0; i < n; i++)
      vd_sim_set_collider_pose(m, d[i], 1, vd_v3(0.5 - 1.0 * k / steps, 0.01 * i, 0.6 * top), vd_quat_identity());
    vd_sim_step_batch(m, d, n, 1, threads, NULL);
  }
  double wall = bench_wall() - w0, ct = bench_cpu() - c0, sps = (double)steps * n / wall, load = 0.5 * (l0 + bench_load1());
  printf("batch of %d tomatoes, %d threads: %8.0f steps/s in all from wall (%.2fx real time each; %.2f plant-seconds per wall "
         "second, %.2f per CPU second; CPU %.2f s, wall %.2f s, load %.1f)\n",
         n, threads, sps, sps * m->opt.dt / n, sps * m->opt.dt, (double)steps * n * m->opt.dt / ct, ct, wall, load);
  fprintf(csv, "batch,tomato_x%d,direct,1,%d,%d,%.6f,%.6f,%.1f,%.3f,,,,%d,%.2f,steps/s of all states from wall time\n", n,
          m->nseg, steps * n, ct, wall, sps, sps * m->opt.dt, threads, load);
  for (int i = 0; i < n; i++) vd_sim_data_destroy(d[i]);
  vd_sim_model_destroy(m);
  return sps;
}

// the MuJoCo body tree of the tomato, measured by verdant_bench_mujoco (beside this program) in
// this run: its steps/s, or 0 when it cannot be run
static double mujoco_tomato(const char* argv0) {
  char cmd[2048], out[1024];
  const char* slash = strrchr(argv0, '/');
  int dir = slash ? (int)(slash - argv0) : 1;
  snprintf(out, sizeof out, "/tmp/verdant_bench_mujoco_%d.csv", (int)getpid());
  snprintf(cmd, sizeof cmd, "%.*s/verdant_bench_mujoco --quick --plants tomato --csv %s > /dev/null", dir,
           slash ? argv0 : ".", out);
  if (system(cmd) != 0) return 0;
  FILE* f = fopen(out, "r");
  double sps = 0;
  char line[1024];
  while (f && fgets(line, sizeof line, f)) {
    if (strncmp(line, "plant_tomato,", 13) != 0) continue;
    // steps_per_s is the 13th column
    char* c = line;
    for (int k = 0; k < 12 && c; k++) c = strchr(c + 1, ',');
    if (c) sps = atof(c + 1);
  }
  if (f) fclose(f);
  remove(out);
  return sps;
}

// a cantilever (clamped piece + L along x)
static vd_model* cantilever(double len, double r) {
  vd_plant_spec* s = vd_plant_spec_create();
  int a = vd_plant_add_node(s, vd_v3(-0.01, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(s, vd_v3(len, 0, 0));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = r, g.label = 1, g.instance = 1, g.up = vd_v3(0, 0, 1);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  vd_plant_add_segment(s, &g);
  vd_plant_set_label(s, 1, "stem");
  vd_model* m = NULL;
  vd_error e = {0};
  vd_plant_compile(s, &m, &e);
  vd_plant_spec_destroy(s);
  return m;
}

// settled sag with a solver setup against the static solution: error and cost per step
static void solver_run(FILE* csv, const char* name, double young, double rho, vd_sim_solver solver, int iters) {
  vd_model* pm = cantilever(1.0, 0.005);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.025;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) def.material[k].young = young, def.material[k].density = rho;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  vd_sim_build(pm, &def, &m, &e);
  m->opt.drag = 0;
  // reference: statics with the direct solver
  vd_sim_data* d = vd_sim_data_create(m);
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.statics = 1;
  s.disp_tol = 1e-13;
  vd_sim_settle(m, d, &s, NULL, NULL);
  double ref = -d->node_pos[m->main_tip].z;
  vd_sim_data_reset(m, d);
  m->opt.solver = solver;
  m->opt.iterations = iters;
  // damped dynamics for 3 s
  double c0 = bench_cpu();
  int steps = 3000;
  s = vd_sim_settle_def_default();
  s.extra_damping = 10;
  s.max_time = 3.0;
  s.ke_tol = 0;  // run the whole 3 s
  int n = 0;
  vd_sim_settle(m, d, &s, NULL, &n);
  steps = n;
  double ct = bench_cpu() - c0;
  double sag = -d->node_pos[m->main_tip].z, err = (sag - ref) / ref;
  printf("%-22s %-6s %4d it  sag %.5f m (static %.5f m, error %+8.3f %%)  %7.2f us/step\n", name,
         solver == VD_SIM_GS ? "gs" : "direct", iters, sag, ref, 100 * err, 1e6 * ct / steps);
  fprintf(csv, "solver,%s,%s,%d,%d,%d,%.6f,,,,,%.6g,%.6g\n", name, solver == VD_SIM_GS ? "gs" : "direct", iters, m->nseg - 1,
          steps, ct, sag, err);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// machine-speed reference measured in the same run (the machine is shared), as the MuJoCo
// chain bench does: nanoseconds per step of a dependent chain of floating-point adds, best of 5
static double calibration_ns(void) {
  volatile double x = 0;
  double best = HUGE_VAL;
  for (int b = 0; b < 5; b++) {
    double t0 = bench_wall();
    for (int k = 0; k < 10000000; k++) x += 1e-9;
    best = fmin(best, bench_wall() - t0);
  }
  return best / 1e7 * 1e9;
}

// the cantilever of anchors-physics.md 3.1 (L = 1 m, r = 5 mm, rho = 1000, E = 10 GPa) with N
// segments under gravity at h = 1 ms: steps/s and the tip-load accuracy, for the comparison
// with MuJoCo capsule chains of N bodies at equal accuracy (same discretisation error)
// settled tip deflection of the test cantilever with n segments under a 0.5 N tip load
static double cantilever_tip(int n) {
  vd_model* pm = cantilever(1.0, 0.005);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 1.0 / n;
  def.clamp_length = 0.01;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) def.material[k].young = 1e10, def.material[k].density = 1000;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  vd_sim_build(pm, &def, &m, &e);
  m->opt.drag = 0;
  m->opt.gravity = vd_v3(0, 0, 0);
  vd_sim_data* d = vd_sim_data_create(m);
  d->node_force[m->main_tip] = vd_v3(0, 0, -0.5);
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.statics = 1;
  s.disp_tol = 1e-14;
  vd_sim_settle(m, d, &s, NULL, NULL);
  double tip = -d->node_pos[m->main_tip].z;
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
  return tip;
}

static void cantilever_run(FILE* csv, int n, double ref) {
  vd_model* pm = cantilever(1.0, 0.005);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 1.0 / n;
  def.clamp_length = 0.01;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) def.material[k].young = 1e10, def.material[k].density = 1000;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  vd_sim_build(pm, &def, &m, &e);
  m->opt.drag = 0;
  // accuracy: 0.5 N tip load against the converged (nonlinear) solution
  double err = (cantilever_tip(n) - ref) / ref;
  // speed: released under gravity, 2000 steps
  vd_sim_data* d = vd_sim_data_create(m);
  m->opt.gravity = vd_v3(0, 0, -9.81);
  int steps = 2000;
  double c0 = bench_cpu();
  for (int k = 0; k < steps; k++) vd_sim_step(m, d);
  double ct = bench_cpu() - c0;
  printf("cantilever N = %3d  %9.0f steps/s  %7.2f x real time  tip-load error %+.2e\n", n, steps / ct,
         steps / ct * m->opt.dt, err);
  fprintf(csv, "cantilever,N%d,direct,1,%d,%d,%.6f,,%.1f,%.3f,%.4f,,%.6g\n", n, n, steps, ct, steps / ct,
          steps / ct * m->opt.dt, 1e6 * ct / steps / n, err);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

int main(int argc, char** argv) {
  const char* csv_path = NULL;
  int quick = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    if (!strcmp(argv[i], "--quick")) quick = 1;
  }
  char defpath[1024];
  if (!csv_path) {
    snprintf(defpath, sizeof defpath, "%s/bench/results/sim-2core.csv", VD_SOURCE_DIR);
    csv_path = defpath;
  }
  FILE* csv = fopen(csv_path, "w");
  if (!csv) {
    fprintf(stderr, "cannot write %s\n", csv_path);
    return 1;
  }
  fprintf(csv, "bench,case,solver,iterations,segments,steps,cpu_seconds,wall_seconds,steps_per_s,real_time_factor,"
               "us_per_segment_step,settled_sag_m,sag_error_rel,threads,load_1min,note\n");
  char path[1024];
  snprintf(path, sizeof path, "%s/data/tomato.lpy", VD_SOURCE_DIR);
  vd_model* tomato = bench_grow(path);
  snprintf(path, sizeof path, "%s/data/tree.lpy", VD_SOURCE_DIR);
  vd_model* tree = bench_grow(path);
  if (!tomato || !tree) return 1;
  // the machine: its name, its load, a speed reference measured now
  char cpu[256] = "?";
  FILE* ci = fopen("/proc/cpuinfo", "r");
  char line[512];
  while (ci && fgets(line, sizeof line, ci))
    if (!strncmp(line, "model name", 10) && strchr(line, ':')) {
      snprintf(cpu, sizeof cpu, "%s", strchr(line, ':') + 2);
      cpu[strcspn(cpu, "\n,")] = 0;
      break;
    }
  if (ci) fclose(ci);
  double cal = calibration_ns();
  printf("== machine: %s, %ld cores online, load %.2f; %.3f ns per dependent floating-point add (compare runs with it)\n",
         cpu, sysconf(_SC_NPROCESSORS_ONLN), bench_load1(), cal);
  fprintf(csv, "calibration,ns_per_dependent_add,,,,,,,,,%.5f,,,,%.2f,%s\n", cal, bench_load1(), cpu);
  printf("== cantilevers at dt = 1 ms (direct solver, 1 iteration); CPU time\n");
  // reference: the same model at N = 1280 (second-order convergence: within 3e-7 of the limit)
  double ref = cantilever_tip(1280);
  printf("   0.5 N tip load, converged tip deflection %.9f m (PL^3/3EI = %.9f m, linear)\n", ref,
         0.5 / (3 * 1e10 * 3.14159265358979 * pow(0.005, 4) / 4));
  static const int ns[5] = {5, 10, 20, 40, 80};
  for (int k = 0; k < 5; k++) cantilever_run(csv, ns[k], ref);
  printf("== plants at dt = 1 ms (sag-free, ground, a probe through the crown)\n");
  double sec = quick ? 0.3 : 2.0;
  run_def tom = {"tomato", VD_SIM_DIRECT, 1, 1, 0, sec, 0, 1, 0, 0, 1, 0};
  double tom_sps = plant_run(csv, tomato, &tom);
  run_def tself = tom;
  tself.name = "tomato_self", tself.self = 1, tself.profile = 0;
  plant_run(csv, tomato, &tself);
  run_def t2 = tom;
  t2.name = "tomato_2it", t2.iters = 2, t2.profile = 0, t2.secs = quick ? 0.2 : 1.0;
  plant_run(csv, tomato, &t2);
  run_def roi = tom;
  roi.name = "tomato_roi_15cm", roi.active = 0.15, roi.profile = 0;
  plant_run(csv, tomato, &roi);
  run_def tgs = tom;
  tgs.name = "tomato_gs10", tgs.solver = VD_SIM_GS, tgs.iters = 10, tgs.profile = 0, tgs.secs = quick ? 0.1 : 0.5;
  plant_run(csv, tomato, &tgs);
  run_def tr1 = {"tree", VD_SIM_DIRECT, 1, 1, 0, quick ? 0.03 : 0.2, 0, 1, 0, 0, 1, 1};
  double tr1_sps = plant_run(csv, tree, &tr1);
  run_def tr1w = tr1;
  tr1w.name = "tree_1thread_wall", tr1w.profile = 0;
  // the same one-thread run timed by the wall clock, to compare with two threads
  tr1w.threads = 1;
  double w1 = 0;
  {
    double w0 = bench_wall();
    plant_run(csv, tree, &tr1w);
    w1 = bench_wall() - w0;
  }
  run_def tr2 = tr1;
  tr2.name = "tree_2threads", tr2.threads = 2, tr2.profile = 0;
  double w2 = 0;
  {
    double w0 = bench_wall();
    plant_run(csv, tree, &tr2);
    w2 = bench_wall() - w0;
  }
  printf("   tree: 2 threads %.2fx one thread (wall, load %.1f)\n", w1 / w2, bench_load1());
  fprintf(csv, "ratio,tree_2threads_over_1,direct,1,,,,,%.4f,,,,,2,%.2f,wall time of the same run on 1 and 2 threads\n",
          w1 / w2, bench_load1());
  (void)tr1_sps;
  printf("== batches: one model, states stepped by vd_sim_step_batch\n");
  double b1 = batch_run(csv, tomato, 8, 1, quick ? 0.1 : 0.5);
  double b2 = batch_run(csv, tomato, 8, 2, quick ? 0.1 : 0.5);
  printf("   batch of 8 tomatoes: 2 threads %.2fx one thread\n", b2 / b1);
  fprintf(csv, "ratio,batch8_2threads_over_1,direct,1,,,,,%.4f,,,,,2,%.2f,steps/s of all states (wall)\n", b2 / b1,
          bench_load1());
  // the learning case (issue 24): 64 tomatoes on two threads, plant-seconds per wall second
  // (goal >= 40); real_time_factor of its row is that number
  double b64 = batch_run(csv, tomato, 64, 2, quick ? 0.02 : 0.25);
  printf("   batch of 64 tomatoes on 2 threads: %.2f plant-seconds per wall second (goal >= 40)\n", b64 * 1e-3);
  printf("== model reductions of the tomato (sag-free): what they change and what they save\n");
  double base[3] = {0, 0, 0};
  run_def red[6] = {{"full", VD_SIM_DIRECT, 1, 1, 0, 0, 0, 1, 0, 0, 0, 0},
                    {"leaf_sigma_0.05", VD_SIM_DIRECT, 1, 1, 0, 0, 0, 1, 0, 0.05, 0, 0},
                    {"leaves_midrib_3", VD_SIM_DIRECT, 1, 1, 0, 0, 0, 2, 3, 0, 0, 0},
                    {"leaves_midrib_2", VD_SIM_DIRECT, 1, 1, 0, 0, 0, 2, 2, 0, 0, 0},
                    {"leaves_rigid", VD_SIM_DIRECT, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0},
                    {"roi_15cm_fruit", VD_SIM_DIRECT, 1, 1, 0, 0, 0.15, 1, 0, 0, 0, 0}};
  for (int k = 0; k < 6; k++) reduction_run(csv, tomato, &red[k], base);
  printf("== the MuJoCo body tree of the tomato in this run (verdant_bench_mujoco --quick --plants tomato)\n");
  double mj = mujoco_tomato(argv[0]);
  if (mj > 0) {
    printf("   MuJoCo %.1f steps/s; the rod solver %.0f steps/s: %.1fx faster\n", mj, tom_sps, tom_sps / mj);
    fprintf(csv, "ratio,rods_over_mujoco_tomato,direct,1,,,,,%.4f,,,,,1,%.2f,MuJoCo %.2f steps/s (its CPU time)\n",
            tom_sps / mj, bench_load1(), mj);
  }
  printf("== solver choice: settled sag of a 1 m cantilever (40 segments) after 3 s of damped dynamics\n");
  static const int gs_it[5] = {5, 20, 50, 200, 1000};
  for (int k = 0; k < 2; k++) {
    const char* name = k ? "green E=5e7" : "wood E=1e10";
    double e = k ? 5e7 : 1e10, rho = k ? 1000 : 900;
    solver_run(csv, name, e, rho, VD_SIM_DIRECT, 1);
    for (int i = 0; i < (quick ? 3 : 5); i++) solver_run(csv, name, e, rho, VD_SIM_GS, gs_it[i]);
  }
  fclose(csv);
  vd_model_destroy(tomato);
  vd_model_destroy(tree);
  printf("results: %s\n", csv_path);
  return 0;
}
