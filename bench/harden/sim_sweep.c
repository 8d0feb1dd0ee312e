// SPDX-License-Identifier: MIT
// Numerical robustness sweep of the rod physics (docs/reliability.md): the bundled plants under
// gravity, wind with gusts and a ground plane, over Young's modulus 1e6..1e11 Pa, density
// 100..1500 kg/m^3, dt 1e-4..1e-2 s, iterations 1..100 and both solvers. Every step of every
// run is checked: positions, frames and velocities finite, and the library's warning counters.
// Each run's CSV row is written and flushed as soon as the run ends, so a stopped sweep keeps
// what it did; --max-seconds caps a run's wall time (outcome "capped"); --append adds to a CSV
// so that bench/harden/sweep_2core.sh can build one table from several slices.
// Results (one row per run) go to bench/results/sweep-<machine>.csv.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "verdant/verdant.h"
#include "../bench_util.h"

#define MAXV 16 // most values of one swept parameter

static const char* usage =
    "usage: verdant_bench_sweep [options]\n"
    "  --quick              corners only: E 1e6,1e11 Pa; rho 100,1500 kg/m^3; dt 1e-4,1e-2 s; "
    "iterations 1,100\n"
    "  --plant LIST         plants, comma separated (arabidopsis,tomato,tree; default all)\n"
    "  --young LIST         Young's moduli (Pa), default 1e6,1e7,1e8,1e9,1e10,1e11\n"
    "  --density LIST       densities (kg/m^3), default 100,500,1000,1500\n"
    "  --dt LIST            time steps (s), default 1e-4,1e-3,1e-2\n"
    "  --iterations LIST    Newton iterations or Gauss-Seidel sweeps per step, default 1,10,100\n"
    "  --solver LIST        direct, gs or direct,gs (default)\n"
    "  --bend M             bend-twist measure: log (default) or quat\n"
    "  --steps N            steps per run (default 100)\n"
    "  --span T             at most T simulated seconds per run: steps = min(N, ceil(T / dt))\n"
    "  --max-seconds S      stop a run after S wall seconds, checked between steps (outcome "
    "capped)\n"
    "  --csv FILE           one row per run, flushed as each run ends\n"
    "  --append             add rows to FILE (header only when FILE is empty)\n";

// parse a comma-separated list of positive numbers into v; returns the count, 0 when malformed
static int parse_list(const char* s, double* v) {
  int n = 0;
  while (*s && n < MAXV) {
    char* end;
    double x = strtod(s, &end);
    if (end == s || !(x > 0) || !isfinite(x)) return 0;
    v[n++] = x;
    if (*end == ',')
      end++;
    else if (*end)
      return 0;
    s = end;
  }
  return *s ? 0 : n;
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
  int steps_done, nonfinite; // steps taken, non-finite states seen
  int failed, capped;        // 1 when a step failed; 1 when the wall-time cap stopped the run
  int64_t warning[VD_SIM_WARN_COUNT]; // the library's warning counters at the end
  int64_t warnings;                   // their sum
  double max_disp, ke, seconds;       // largest displacement (m), kinetic energy (J), wall (s)
} run_result;

// outcomes, worst first; a run is counted under the first that applies
enum { O_NONFINITE, O_FAILED, O_CAPPED, O_STRETCHED, O_RETAKEN, O_CLEAN, O_COUNT };
static const char* outcome_name[O_COUNT] = {"NONFINITE", "failed",  "capped",
                                            "stretched", "retaken", "clean"};

// outcome of a run as `verdant sim` reports it (capped: stopped by --max-seconds, incomplete)
static int outcome(const run_result* r) {
  if (r->nonfinite) return O_NONFINITE;
  if (r->failed) return O_FAILED;
  if (r->capped) return O_CAPPED;
  if (r->warning[VD_SIM_WARN_STRETCHED] || r->warning[VD_SIM_WARN_UNSTABLE]) return O_STRETCHED;
  if (r->warning[VD_SIM_WARN_SUBSTEP]) return O_RETAKEN;
  return O_CLEAN;
}

// one run: gravity, ground, wind 5 m/s along x with 50 % gusts of 0.5 s, `steps` steps, stopped
// after `max_seconds` of wall time (0: no cap)
static vd_sim_bend bend = VD_SIM_BEND_LOG;

static void run_one(const vd_model* pm, double sigma, double young, double rho, double dt,
                    int iters, vd_sim_solver solver, int steps, double max_seconds, run_result* r) {
  memset(r, 0, sizeof *r);
  vd_sim_def def = vd_sim_def_default();
  def.bend_measure = bend;
  def.segment_length = sigma;
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++)
    def.material[c].young = young, def.material[c].density = rho;
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
  vd_sim_collider g = {VD_SIM_PLANE,       {0, 0, 0},      vd_v3(0, 0, 0),
                       vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  double t0 = bench_wall();
  // as the command does: stop at the first step that fails; the cap is checked between steps
  for (int k = 0; k < steps && !r->failed; k++) {
    if (max_seconds > 0 && bench_wall() - t0 > max_seconds) {
      r->capped = 1;
      break;
    }
    r->failed = vd_sim_step(m, d) != VD_OK;
    if (!state_finite(m, d)) r->nonfinite++;
    r->steps_done += !r->failed;
  }
  r->seconds = bench_wall() - t0;
  r->warnings = d->nwarning;
  memcpy(r->warning, d->warning, sizeof r->warning);
  r->max_disp = vd_sim_max_displacement(m, d, NULL);
  r->ke = vd_sim_kinetic_energy(m, d);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
}

int main(int argc, char** argv) {
  int quick = 0, steps = 100, append = 0;
  double span = 0, max_seconds = 0;
  const char* csv_path = NULL;
  const char* plants = NULL;
  const char* lists[5] = {NULL, NULL, NULL, NULL, NULL}; // young, density, dt, iterations, solver
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    int more = i + 1 < argc;
    if (!strcmp(a, "--quick"))
      quick = 1;
    else if (!strcmp(a, "--append"))
      append = 1;
    else if (!strcmp(a, "--bend") && more) {
      int b = vd_sim_bend_parse(argv[++i]);
      if (b < 0) {
        fprintf(stderr, "--bend: expected log or quat, got '%s'\n", argv[i]);
        return 2;
      }
      bend = (vd_sim_bend)b;
    } else if (!strcmp(a, "--steps") && more)
      steps = atoi(argv[++i]);
    else if (!strcmp(a, "--span") && more)
      span = atof(argv[++i]);
    else if (!strcmp(a, "--max-seconds") && more)
      max_seconds = atof(argv[++i]);
    else if (!strcmp(a, "--csv") && more)
      csv_path = argv[++i];
    else if (!strcmp(a, "--plant") && more)
      plants = argv[++i];
    else if (!strcmp(a, "--young") && more)
      lists[0] = argv[++i];
    else if (!strcmp(a, "--density") && more)
      lists[1] = argv[++i];
    else if (!strcmp(a, "--dt") && more)
      lists[2] = argv[++i];
    else if (!strcmp(a, "--iterations") && more)
      lists[3] = argv[++i];
    else if (!strcmp(a, "--solver") && more)
      lists[4] = argv[++i];
    else {
      fputs(usage, stderr);
      return 2;
    }
  }
  if (steps < 1 || span < 0 || max_seconds < 0) {
    fputs(usage, stderr);
    return 2;
  }
  // plants and their rod segment length (the tree at a coarse sigma)
  static const char* names[] = {"arabidopsis", "tomato", "tree"};
  static const double sigma[] = {0.02, 0.02, 0.1};
  // swept values: defaults (full grid or --quick corners), replaced by the lists given
  double val[4][MAXV];
  int nval[4];
  static const double full[4][6] = {
      {1e6, 1e7, 1e8, 1e9, 1e10, 1e11}, {100, 500, 1000, 1500}, {1e-4, 1e-3, 1e-2}, {1, 10, 100}};
  static const int nfull[4] = {6, 4, 3, 3};
  static const double corner[4][2] = {{1e6, 1e11}, {100, 1500}, {1e-4, 1e-2}, {1, 100}};
  static const char* what[4] = {"--young", "--density", "--dt", "--iterations"};
  for (int p = 0; p < 4; p++) {
    if (lists[p]) {
      nval[p] = parse_list(lists[p], val[p]);
      if (!nval[p]) {
        fprintf(stderr, "%s: expected up to %d positive numbers separated by commas, got '%s'\n",
                what[p], MAXV, lists[p]);
        return 2;
      }
    } else {
      nval[p] = quick ? 2 : nfull[p];
      for (int k = 0; k < nval[p]; k++)
        val[p][k] = quick ? corner[p][k] : full[p][k];
    }
  }
  int use_solver[2] = {1, 1};
  if (lists[4]) {
    use_solver[0] = strstr(lists[4], "direct") != NULL;
    use_solver[1] = strstr(lists[4], "gs") != NULL;
    if (!use_solver[0] && !use_solver[1]) {
      fprintf(stderr, "--solver: expected direct, gs or direct,gs, got '%s'\n", lists[4]);
      return 2;
    }
  }
  int use_plant[3] = {1, 1, 1};
  if (plants) {
    int any = 0;
    for (int p = 0; p < 3; p++)
      any += use_plant[p] = strstr(plants, names[p]) != NULL;
    if (!any) {
      fprintf(stderr, "--plant: expected arabidopsis, tomato or tree (comma separated), got '%s'\n",
              plants);
      return 2;
    }
  }
  FILE* csv = csv_path ? fopen(csv_path, append ? "a" : "w") : NULL;
  if (csv_path && !csv) {
    perror(csv_path);
    return 1;
  }
  // header: run settings, outcome, one column per warning kind, then measures
  if (csv && ftell(csv) == 0) {
    fprintf(csv, "plant,sigma_m,young_pa,density,dt_s,iterations,solver,steps_asked,steps,outcome,"
                 "nonfinite_states");
    for (int w = 0; w < VD_SIM_WARN_COUNT; w++)
      fprintf(csv, ",warn_%s", vd_sim_warning_name((vd_sim_warning)w));
    fprintf(csv, ",warnings,max_displacement_m,kinetic_energy_j,seconds\n");
    fflush(csv);
  }
  int64_t runs = 0, nonfinite = 0, steps_all = 0, count[O_COUNT] = {0},
          by_solver[2][O_COUNT] = {{0}};
  int64_t warn_all[VD_SIM_WARN_COUNT] = {0};
  double t_all = bench_wall();
  for (int p = 0; p < 3; p++) {
    if (!use_plant[p]) continue;
    char path[4096];
    snprintf(path, sizeof path, "%s/data/%s.lpy", VD_SOURCE_DIR, names[p]);
    vd_model* pm = bench_grow(path);
    if (!pm) return 1;
    for (int a = 0; a < nval[0]; a++)
      for (int b = 0; b < nval[1]; b++)
        for (int c = 0; c < nval[2]; c++)
          for (int k = 0; k < nval[3]; k++)
            for (int s = 0; s < 2; s++) {
              if (!use_solver[s]) continue;
              double young = val[0][a], rho = val[1][b], dt = val[2][c];
              int iters = (int)val[3][k];
              int n = steps;
              if (span > 0 && ceil(span / dt - 1e-9) < n) n = (int)ceil(span / dt - 1e-9);
              run_result r;
              vd_sim_solver solver = s ? VD_SIM_GS : VD_SIM_DIRECT;
              run_one(pm, sigma[p], young, rho, dt, iters, solver, n, max_seconds, &r);
              int o = outcome(&r);
              runs++;
              nonfinite += r.nonfinite;
              steps_all += r.steps_done;
              count[o]++, by_solver[s][o]++;
              for (int w = 0; w < VD_SIM_WARN_COUNT; w++)
                warn_all[w] += r.warning[w];
              printf("%-12s E %-6.0e rho %-5.0f dt %-6.0e it %-3d %-6s  steps %3d/%-3d  %-9s  "
                     "nonfinite %d  "
                     "retaken %4lld  stretched %3lld  max disp %.4g m  KE %.3g J  %.2f s\n",
                     names[p], young, rho, dt, iters, s ? "gs" : "direct", r.steps_done, n,
                     outcome_name[o], r.nonfinite, (long long)r.warning[VD_SIM_WARN_SUBSTEP],
                     (long long)r.warning[VD_SIM_WARN_STRETCHED], r.max_disp, r.ke, r.seconds);
              fflush(stdout);
              if (csv) {
                fprintf(csv, "%s,%g,%g,%g,%g,%d,%s,%d,%d,%s,%d", names[p], sigma[p], young, rho, dt,
                        iters, s ? "gs" : "direct", n, r.steps_done, outcome_name[o], r.nonfinite);
                for (int w = 0; w < VD_SIM_WARN_COUNT; w++)
                  fprintf(csv, ",%lld", (long long)r.warning[w]);
                fprintf(csv, ",%lld,%.6g,%.6g,%.3f\n", (long long)r.warnings, r.max_disp, r.ke,
                        r.seconds);
                fflush(csv);
              }
            }
    vd_model_destroy(pm);
  }
  printf("%lld runs, %lld steps in %.0f s: %lld non-finite states\n  outcomes:", (long long)runs,
         (long long)steps_all, bench_wall() - t_all, (long long)nonfinite);
  for (int o = 0; o < O_COUNT; o++)
    printf(" %s %lld", outcome_name[o], (long long)count[o]);
  printf("\n  warnings:");
  for (int w = 0; w < VD_SIM_WARN_COUNT; w++)
    printf(" %s %lld", vd_sim_warning_name((vd_sim_warning)w), (long long)warn_all[w]);
  printf("\n");
  for (int s = 0; s < 2; s++) {
    if (!use_solver[s]) continue;
    printf("  %-6s", s ? "gs" : "direct");
    for (int o = 0; o < O_COUNT; o++)
      printf(" %s %lld", outcome_name[o], (long long)by_solver[s][o]);
    printf("\n");
  }
  if (csv) fclose(csv);
  return nonfinite ? 1 : 0;
}
