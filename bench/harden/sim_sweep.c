// SPDX-License-Identifier: MIT
// Numerical robustness sweep of the rod physics (docs/reliability.md): the bundled plants under
// gravity, wind with gusts and a ground plane, over Young's modulus 1e6..1e11 Pa, density
// 100..1500 kg/m^3, dt 1e-4..1e-2 s, iterations 1..100 and both solvers. Every step of every
// run is checked: positions, frames and velocities finite, and the library's warning counters.
// Usage: verdant_bench_sweep [--quick] [--steps N] [--csv FILE] [--plant NAME]
// Results (one row per run) go to bench/results/sweep-<machine>.csv.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "verdant/verdant.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static vd_model* grow(const char* path) {
  vd_error e = {0};
  vd_lsystem* ls = NULL;
  if (vd_lsys_load(path, &ls, &e)) {
    fprintf(stderr, "%s: %s\n", path, e.msg);
    return NULL;
  }
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def def = vd_lsys_def_default();
  vd_model* m = NULL;
  if (!vd_lsys_grow(ls, &def, NULL, s, &e)) vd_plant_compile(s, &m, &e);
  if (!m) fprintf(stderr, "%s: %s\n", path, e.msg);
  vd_plant_spec_destroy(s);
  vd_lsys_destroy(ls);
  return m;
}

// is every number of the state finite?
static int state_finite(const vd_sim_model* m, const vd_sim_data* d) {
  double s = 0;
  for (int i = 0; i < m->nnode_all; i++) {
    vd_vec3 p = d->node_pos[i], v = d->node_vel[i];
    s += p.x + p.y + p.z + v.x + v.y + v.z;
  }
  for (int t = 0; t < m->nseg; t++) {
    vd_quat q = d->seg_quat[t];
    vd_vec3 w = d->seg_omega[t];
    s += q.w + q.x + q.y + q.z + w.x + w.y + w.z;
  }
  return isfinite(s);
}

typedef struct run_result {
  int steps_done, nonfinite, failed;  // steps taken, non-finite states seen, 1 when a step failed
  int64_t warnings, retaken, stretched, unstable;
  double max_disp, ke, seconds;
} run_result;

// outcome of a run as `verdant sim` reports it
static const char* outcome(const run_result* r) {
  if (r->nonfinite) return "NONFINITE";
  if (r->failed) return "failed";
  if (r->stretched || r->unstable) return "stretched";
  if (r->retaken) return "retaken";
  return "clean";
}

// one run: gravity, ground, wind 5 m/s along x with 50 % gusts of 0.5 s, `steps` steps
static void run_one(const vd_model* pm, double sigma, double young, double rho, double dt, int iters,
                    vd_sim_solver solver, int steps, run_result* r) {
  memset(r, 0, sizeof *r);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = sigma;
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++) def.material[c].young = young, def.material[c].density = rho;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  if (vd_sim_build(pm, &def, &m, &e)) {
    fprintf(stderr, "build: %s\n", e.msg);
    r->failed = -1;
    return;
  }
  m->opt.dt = dt;
  m->opt.iterations = iters;
  m->opt.solver = solver;
  m->opt.wind = vd_v3(5, 0, 0);
  m->opt.gust_amplitude = 0.5;
  m->opt.gust_period = 0.5;
  vd_sim_data* d = vd_sim_data_create(m);
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  double t0 = now();
  // as the command does: stop at the first step that fails
  for (int k = 0; k < steps && !r->failed; k++) {
    r->failed = vd_sim_step(m, d) != VD_OK;
    if (!state_finite(m, d)) r->nonfinite++;
    r->steps_done += !r->failed;
  }
  r->seconds = now() - t0;
  r->warnings = d->nwarning;
  r->retaken = d->warning[VD_SIM_WARN_SUBSTEP];
  r->stretched = d->warning[VD_SIM_WARN_STRETCHED];
  r->unstable = d->warning[VD_SIM_WARN_UNSTABLE];
  r->max_disp = vd_sim_max_displacement(m, d, NULL);
  r->ke = vd_sim_kinetic_energy(m, d);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
}

int main(int argc, char** argv) {
  int quick = 0, steps = 100;
  const char* csv_path = NULL;
  const char* only = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else if (!strcmp(argv[i], "--plant") && i + 1 < argc) only = argv[++i];
    else {
      fprintf(stderr, "usage: %s [--quick] [--steps N] [--csv FILE] [--plant NAME]\n", argv[0]);
      return 2;
    }
  }
  // plants and their rod segment length (the tree at a coarse sigma)
  static const char* names[] = {"arabidopsis", "tomato", "tree"};
  static const double sigma[] = {0.02, 0.02, 0.1};
  static const double young_all[] = {1e6, 1e7, 1e8, 1e9, 1e10, 1e11};
  static const double rho_all[] = {100, 500, 1000, 1500};
  static const double dt_all[] = {1e-4, 1e-3, 1e-2};
  static const int iters_all[] = {1, 10, 100};
  static const double young_q[] = {1e6, 1e11};
  static const double rho_q[] = {100, 1500};
  static const double dt_q[] = {1e-4, 1e-2};
  static const int iters_q[] = {1, 100};
  const double* young = quick ? young_q : young_all;
  const double* rho = quick ? rho_q : rho_all;
  const double* dt = quick ? dt_q : dt_all;
  const int* iters = quick ? iters_q : iters_all;
  int ny = quick ? 2 : 6, nr = quick ? 2 : 4, nd = quick ? 2 : 3, ni = quick ? 2 : 3;
  FILE* csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) {
    perror(csv_path);
    return 1;
  }
  if (csv)
    fprintf(csv, "plant,sigma_m,young_pa,density,dt_s,iterations,solver,steps,outcome,nonfinite_states,"
                 "retaken,stretched,unstable,warnings,max_displacement_m,kinetic_energy_j,seconds\n");
  int64_t runs = 0, nonfinite = 0, count[4] = {0, 0, 0, 0};
  int64_t by_solver[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  static const char* kinds[4] = {"clean", "retaken", "stretched", "failed"};
  double t_all = now();
  for (int p = 0; p < 3; p++) {
    if (only && strcmp(only, names[p])) continue;
    char path[4096];
    snprintf(path, sizeof path, "%s/data/%s.lpy", VD_SOURCE_DIR, names[p]);
    vd_model* pm = grow(path);
    if (!pm) return 1;
    for (int a = 0; a < ny; a++)
      for (int b = 0; b < nr; b++)
        for (int c = 0; c < nd; c++)
          for (int k = 0; k < ni; k++)
            for (int s = 0; s < 2; s++) {
              run_result r;
              vd_sim_solver solver = s ? VD_SIM_GS : VD_SIM_DIRECT;
              run_one(pm, sigma[p], young[a], rho[b], dt[c], iters[k], solver, steps, &r);
              runs++;
              nonfinite += r.nonfinite;
              const char* o = outcome(&r);
              for (int q = 0; q < 4; q++)
                if (!strcmp(o, kinds[q])) count[q]++, by_solver[s][q]++;
              printf("%-12s E %-6.0e rho %-5.0f dt %-6.0e it %-3d %-6s  steps %3d  %-9s  nonfinite %d  retaken %4lld  "
                     "stretched %3lld  max disp %.4g m  KE %.3g J  %.2f s\n",
                     names[p], young[a], rho[b], dt[c], iters[k], s ? "gs" : "direct", r.steps_done, o, r.nonfinite,
                     (long long)r.retaken, (long long)r.stretched, r.max_disp, r.ke, r.seconds);
              fflush(stdout);
              if (csv)
                fprintf(csv, "%s,%g,%g,%g,%g,%d,%s,%d,%s,%d,%lld,%lld,%lld,%lld,%.6g,%.6g,%.3f\n", names[p], sigma[p],
                        young[a], rho[b], dt[c], iters[k], s ? "gs" : "direct", r.steps_done, o, r.nonfinite,
                        (long long)r.retaken, (long long)r.stretched, (long long)r.unstable, (long long)r.warnings,
                        r.max_disp, r.ke, r.seconds);
            }
    vd_model_destroy(pm);
  }
  printf("%lld runs of %d steps in %.0f s: %lld non-finite states; clean %lld, retaken %lld, stretched %lld, failed %lld\n",
         (long long)runs, steps, now() - t_all, (long long)nonfinite, (long long)count[0], (long long)count[1],
         (long long)count[2], (long long)count[3]);
  for (int s = 0; s < 2; s++)
    printf("  %-6s clean %lld, retaken %lld, stretched %lld, failed %lld\n", s ? "gs" : "direct",
           (long long)by_solver[s][0], (long long)by_solver[s][1], (long long)by_solver[s][2], (long long)by_solver[s][3]);
  if (csv) fclose(csv);
  return nonfinite ? 1 : 0;
}
