// SPDX-License-Identifier: MIT
// Growth runs (issue 11 item 10; docs/benchmarks.md, "Growth"): the seed's tree, Hopea odorata
// 25 years (data/hopea.lpy, one internode a year), 50 substeps of h = 10 ms per age step, roots
// in Singapore's residual soil, gravity and 15 m/s wind, grown by the mass-spring tree (mss,
// ML-Tree), the mass-spring tree with a rigid part (mrl, MRL-Tree) and the rods; then the rods
// on the same final tree (the MRL run's last plant) for 50 substeps. Per run: wall and CPU
// time, node-substeps (the sum over substeps of the physics nodes) and their rate.
// Usage: verdant_bench_growth [--csv FILE] [--ages N] [--no-rods]
#include <stdlib.h>
#include <string.h>

#include "../bench_util.h"

typedef struct run {
  double wall, cpu, node_substeps, last_cpu, last_node_substeps;  // last_*: the last age step
  vd_growth_stats s;
} run;

static vd_growth_def bench_def(vd_growth_model model, int ages) {
  vd_growth_def d = vd_growth_def_default();
  d.model = model;
  d.ages = ages;
  d.substeps = 50;
  vd_wood w;
  if (vd_wood_species("hopea-odorata", &w) == VD_OK)
    d.mss.young_wood = w.young, d.mss.density_wood = w.density, d.mss.mor = w.mor;
  vd_soil_preset("singapore-residual", &d.mss.soil);
  d.opt.wind = d.rod_opt.wind = vd_v3(15, 0, 0);
  return d;
}

// grow; *final (Nullable) gets the last plant
static int grow(vd_lsystem* ls, const vd_growth_def* def, run* r, vd_plant_spec** final) {
  memset(r, 0, sizeof *r);
  vd_growth* g = NULL;
  vd_error e = {0};
  double w0 = bench_wall(), c0 = bench_cpu();
  vd_status st = vd_growth_create(ls, def, &g, &e);
  for (int k = 0; k < def->ages && !st; k++) {
    double lc = bench_cpu();
    st = vd_growth_step(g, &e);
    vd_growth_stats s;
    vd_growth_get_stats(g, &s);
    double ns = (double)s.nphys * def->substeps;  // nodes after the step: those that were stepped
    r->node_substeps += ns;
    r->last_cpu = bench_cpu() - lc, r->last_node_substeps = ns;
  }
  r->wall = bench_wall() - w0, r->cpu = bench_cpu() - c0;
  if (!st) vd_growth_get_stats(g, &r->s);
  if (!st && final) st = vd_growth_plant(g, final, &e);
  vd_growth_destroy(g);
  if (st) {
    char buf[1200];
    fprintf(stderr, "bench_growth: %s\n", vd_error_format(&e, buf, sizeof buf));
    return 0;
  }
  return 1;
}

// the rods on a plant for n substeps of the growth run's rod settings, roots in the soil
static int rods_on(const vd_plant_spec* spec, const vd_growth_def* def, int n, run* r) {
  memset(r, 0, sizeof *r);
  vd_error e = {0};
  vd_model* pm = NULL;
  vd_sim_model* m = NULL;
  vd_sim_data* d = NULL;
  vd_sim_soil* soil = NULL;
  vd_sim_def rdef = def->rods;
  rdef.clamp_roots = 0;
  int ok = !vd_plant_compile(spec, &pm, &e) && !vd_sim_build(pm, &rdef, &m, &e);
  if (ok) {
    vd_vec3 gr = m->opt.gravity;
    m->opt = def->rod_opt;
    m->opt.gravity = gr;
    d = vd_sim_data_create(m);
    ok = d && !vd_sim_soil_attach(m, d, &def->mss.soil, &soil, &e);
  }
  if (ok) {
    double w0 = bench_wall(), c0 = bench_cpu();
    for (int k = 0; k < n; k++) {
      vd_sim_step(m, d);
      vd_sim_soil_update(m, d, soil);
    }
    r->wall = bench_wall() - w0, r->cpu = bench_cpu() - c0;
    r->node_substeps = r->last_node_substeps = (double)m->nnode * n;
    r->last_cpu = r->cpu;
    r->s.nphys = m->nnode;
    r->s.max_displacement = vd_sim_max_displacement(m, d, NULL);
  } else {
    char buf[1200];
    fprintf(stderr, "bench_growth: rods: %s\n", vd_error_format(&e, buf, sizeof buf));
  }
  vd_sim_soil_destroy(soil);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
  return ok;
}

static void row(FILE* csv, const char* kase, const char* model, int ages, int substeps, const run* r, double load) {
  double rate = r->cpu > 0 ? r->node_substeps / r->cpu : 0, last = r->last_cpu > 0 ? r->last_node_substeps / r->last_cpu : 0;
  printf("%-10s %-4s %2d ages x %2d  nodes %6d  wall %7.2f s  cpu %7.2f s  %9.3g node-substeps/s, last age %9.3g (cpu)  "
         "largest move %.3f m\n",
         kase, model, ages, substeps, r->s.nphys, r->wall, r->cpu, rate, last, r->s.max_displacement);
  fprintf(csv, "%s,%s,%d,%d,%d,%d,%.0f,%.3f,%.3f,%.4g,%.4g,%.3f,%.4g,%.3f,%.3f,%.4f,%.4g,%d,%.2f\n", kase, model, ages,
          substeps, r->s.nphys, r->s.nrigid, r->node_substeps, r->wall, r->cpu, rate,
          r->wall > 0 ? r->node_substeps / r->wall : 0, r->last_cpu, last, r->s.height, r->s.height0, r->s.max_displacement,
          r->s.max_stress, r->s.collapsed, load);
  fflush(csv);
}

int main(int argc, char** argv) {
  const char* csv_path = NULL;
  int ages = 25, rods = 1;
  static const char* usage =
      "usage: verdant_bench_growth [--csv FILE] [--ages N] [--quick] [--no-rods]\n"
      "Grow data/hopea.lpy with each model and time it; rows into FILE (default\n"
      "bench/results/growth-2core.csv, replaced). --quick: 10 ages; --no-rods: skip the rods.\n";
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
      fputs(usage, stdout);
      return 0;
    }
    if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else if (!strcmp(argv[i], "--ages") && i + 1 < argc) ages = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--no-rods")) rods = 0;
    else if (!strcmp(argv[i], "--quick")) ages = 10;
    else {
      fprintf(stderr, "verdant_bench_growth: unknown argument '%s'\n%s", argv[i], usage);
      return 2;
    }
  }
  if (ages < 1) ages = 1;
  char defpath[1024], lpy[1024];
  if (!csv_path) {
    snprintf(defpath, sizeof defpath, "%s/bench/results/growth-2core.csv", VD_SOURCE_DIR);
    csv_path = defpath;
  }
  snprintf(lpy, sizeof lpy, "%s/data/hopea.lpy", VD_SOURCE_DIR);
  vd_lsystem* ls = NULL;
  vd_error e = {0};
  if (vd_lsys_load(lpy, &ls, &e)) {
    char buf[1200];
    fprintf(stderr, "bench_growth: %s\n", vd_error_format(&e, buf, sizeof buf));
    return 1;
  }
  FILE* csv = fopen(csv_path, "w");
  if (!csv) {
    fprintf(stderr, "cannot write %s\n", csv_path);
    vd_lsys_destroy(ls);
    return 1;
  }
  fprintf(csv, "case,model,ages,substeps,final_nodes,rigid_nodes,node_substeps,wall_s,cpu_s,node_substeps_per_cpu_s,"
               "node_substeps_per_wall_s,last_age_cpu_s,last_age_node_substeps_per_cpu_s,height_m,rest_height_m,max_displacement_m,"
               "max_stress_pa,collapsed,load1\n");
  run r;
  vd_plant_spec* final = NULL;
  vd_growth_def d = bench_def(VD_GROWTH_MSS, ages);
  if (grow(ls, &d, &r, NULL)) row(csv, "grow", "mss", ages, d.substeps, &r, bench_load1());
  d = bench_def(VD_GROWTH_MRL, ages);
  if (grow(ls, &d, &r, &final)) row(csv, "grow", "mrl", ages, d.substeps, &r, bench_load1());
  if (rods) {
    if (final && rods_on(final, &d, d.substeps, &r)) row(csv, "final_tree", "rods", ages, d.substeps, &r, bench_load1());
    d = bench_def(VD_GROWTH_RODS, ages);
    if (grow(ls, &d, &r, NULL)) row(csv, "grow", "rods", ages, d.substeps, &r, bench_load1());
  }
  vd_plant_spec_destroy(final);
  fclose(csv);
  vd_lsys_destroy(ls);
  printf("wrote %s\n", csv_path);
  return 0;
}
