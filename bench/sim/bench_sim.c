// SPDX-License-Identifier: MIT
// verdant sim benchmarks: steps per second of the bundled tomato and tree at dt = 1 ms (direct
// solver, the default; Gauss-Seidel for comparison), and the solver choice: the error of the
// settled sag and the cost per step of direct vs Gauss-Seidel on a wood and a green cantilever.
// Results go to bench/results/sim-<machine>.csv. The MuJoCo capsule-chain peer lives in the
// collide engineer's bench (bench_mujoco_chain.c) and is compared in docs/benchmarks.md.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "verdant/verdant.h"
#include "../bench_util.h"

// a plant run: sag-free plant, ground, a probe sweeping through the crown; self: self-collision
static void plant_run(FILE* csv, const char* name, const vd_model* pm, vd_sim_solver solver, int iters, double secs,
                      int self) {
  vd_sim_def def = vd_sim_def_default();
  def.sag_free = 1;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  if (vd_sim_build(pm, &def, &m, &e)) {
    fprintf(stderr, "%s: %s\n", name, e.msg);
    return;
  }
  m->opt.solver = solver;
  m->opt.iterations = iters;
  m->opt.self_collision = self;
  vd_sim_data* d = vd_sim_data_create(m);
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  // the probe crosses the plant at 60 % of its height
  double top = 0;
  for (int i = 0; i < m->nnode; i++) top = fmax(top, m->node_pos0[i].z);
  vd_sim_collider p = {VD_SIM_SPHERE, {0.04, 0, 0}, vd_v3(0.5, 0, 0.6 * top), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  int id = vd_sim_add_collider(d, &p);
  int steps = (int)(secs / m->opt.dt + 0.5);
  double w0 = bench_wall(), c0 = bench_cpu();
  for (int k = 0; k < steps; k++) {
    vd_sim_set_collider_pose(m, d, id, vd_v3(0.5 - 1.0 * k / steps, 0, 0.6 * top), vd_quat_identity());
    vd_sim_step(m, d);
  }
  double wall = bench_wall() - w0, ct = bench_cpu() - c0;
  int dyn = 0;
  for (int t = 0; t < m->nseg; t++) dyn += !(m->seg_flags[t] & VD_SIM_FIXED);
  double sps = steps / ct;
  printf("%-8s %-6s %4d it  %6d seg  %8.0f steps/s  %6.2fx real time  %6.2f us/seg-step  (wall %.2f s, %lld warnings)%s\n",
         name, solver == VD_SIM_GS ? "gs" : "direct", iters, dyn, sps, sps * m->opt.dt, 1e6 * ct / steps / dyn, wall,
         (long long)d->nwarning, self ? "" : "  no self-collision");
  fprintf(csv, "plant,%s%s,%s,%d,%d,%d,%.6f,%.6f,%.1f,%.3f,%.4f,,\n", name, self ? "" : "_noself", solver == VD_SIM_GS ? "gs" : "direct", iters,
          dyn, steps, ct, wall, sps, sps * m->opt.dt, 1e6 * ct / steps / dyn);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
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
               "us_per_segment_step,settled_sag_m,sag_error_rel\n");
  char path[1024];
  snprintf(path, sizeof path, "%s/data/tomato.lpy", VD_SOURCE_DIR);
  vd_model* tomato = bench_grow(path);
  snprintf(path, sizeof path, "%s/data/tree.lpy", VD_SOURCE_DIR);
  vd_model* tree = bench_grow(path);
  if (!tomato || !tree) return 1;
  double cal = calibration_ns();
  printf("== machine: %.3f ns per dependent floating-point add (compare runs with it)\n", cal);
  fprintf(csv, "calibration,ns_per_dependent_add,,,,,,,,,%.5f,,\n", cal);
  printf("== cantilevers at dt = 1 ms (direct solver, 1 iteration); CPU time\n");
  // reference: the same model at N = 1280 (second-order convergence: within 3e-7 of the limit)
  double ref = cantilever_tip(1280);
  printf("   0.5 N tip load, converged tip deflection %.9f m (PL^3/3EI = %.9f m, linear)\n", ref,
         0.5 / (3 * 1e10 * 3.14159265358979 * pow(0.005, 4) / 4));
  static const int ns[5] = {5, 10, 20, 40, 80};
  for (int k = 0; k < 5; k++) cantilever_run(csv, ns[k], ref);
  printf("== plants at dt = 1 ms (sag-free, ground, a probe through the crown); CPU time\n");
  plant_run(csv, "tomato", tomato, VD_SIM_DIRECT, 1, quick ? 0.3 : 2.0, 1);
  plant_run(csv, "tomato", tomato, VD_SIM_DIRECT, 1, quick ? 0.3 : 2.0, 0);
  plant_run(csv, "tomato", tomato, VD_SIM_DIRECT, 2, quick ? 0.3 : 1.0, 1);
  plant_run(csv, "tomato", tomato, VD_SIM_GS, 10, quick ? 0.2 : 1.0, 1);
  plant_run(csv, "tree", tree, VD_SIM_DIRECT, 1, quick ? 0.05 : 0.3, 1);
  plant_run(csv, "tree", tree, VD_SIM_DIRECT, 1, quick ? 0.05 : 0.3, 0);
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
