// SPDX-License-Identifier: MIT
// libFuzzer target: sim inputs read from files, the wind time series (--wind-file). A series
// that parses drives 4 steps of a small plant (a stem with a fruit on a pedicel and a leaf
// blade) with drag on: every state must stay finite, a failed step must be counted.
#include <math.h>

#include "fuzz_common.h"
#include "verdant/sim.h"

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static vd_model* plant;
static vd_sim_model* model;

// the plant: stem, pedicel, fruit sphere, a triangle leaf blade on a petiole (built once)
static void build_plant(void) {
  vd_plant_spec* s = vd_plant_spec_create();
  int n0 = vd_plant_add_node(s, vd_v3(0, 0, 0)), n1 = vd_plant_add_node(s, vd_v3(0, 0, 0.2));
  int n2 = vd_plant_add_node(s, vd_v3(0.03, 0, 0.18)), n3 = vd_plant_add_node(s, vd_v3(-0.04, 0, 0.22));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = n0, g.node1 = n1, g.r0 = 0.004, g.r1 = 0.003, g.label = 1, g.instance = 1;
  int stem = vd_plant_add_segment(s, &g);
  g.node0 = n1, g.node1 = n2, g.r0 = g.r1 = 0.001, g.label = 2, g.instance = 2, g.parent = stem;
  int ped = vd_plant_add_segment(s, &g);
  g.node0 = n1, g.node1 = n3, g.r0 = g.r1 = 0.0008, g.label = 4, g.instance = 4, g.parent = stem;
  vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0.03, 0, 0.165), f.radius = 0.012, f.parent = ped, f.label = 3, f.instance = 3;
  vd_plant_add_sphere(s, &f);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 2, "pedicel");
  vd_plant_set_label(s, 3, "fruit");
  vd_plant_set_label(s, 4, "leaf");
  vd_error e = {0};
  if (vd_plant_compile(s, &plant, &e) != VD_OK) abort();
  vd_plant_spec_destroy(s);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.05;
  if (vd_sim_build(plant, &def, &model, &e) != VD_OK) abort();
}

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  fuzz_install_allocator();
  vd_set_assert_handler(fuzz_assert);
  build_plant();
  return 0;
}

static int finite_state(const vd_sim_model* m, const vd_sim_data* d) {
  for (int i = 0; i < m->nnode_all; i++) {
    vd_vec3 p = d->node_pos[i], v = d->node_vel[i];
    if (!isfinite(p.x + p.y + p.z) || !isfinite(v.x + v.y + v.z)) return 0;
  }
  for (int t = 0; t < m->nseg; t++) {
    vd_quat q = d->seg_quat[t];
    if (!isfinite(q.w + q.x + q.y + q.z)) return 0;
  }
  return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  double* rows = NULL;
  int n = 0;
  if (vd_sim_parse_wind((const char*)data, size, "fuzz.csv", &rows, &n, &err) == VD_OK) {
    if (n < 1 || !rows) abort();
    for (int k = 0; k < n; k++)
      if (!isfinite(rows[4 * k]) || !isfinite(rows[4 * k + 1]) || fabs(rows[4 * k + 1]) > VD_SIM_MAX_WIND ||
          (k && rows[4 * k] < rows[4 * (k - 1)]))
        abort();
    // 4 steps of 5 ms with the series, starting at its first time
    model->opt.wind_series = rows;
    model->opt.nwind = n;
    model->opt.dt = 0.005;
    vd_sim_data* d = vd_sim_data_create(model);
    if (d) {
      d->time = rows[0];
      for (int k = 0; k < 4; k++) {
        vd_status st = vd_sim_step(model, d);
        if (!finite_state(model, d)) {
          fprintf(stderr, "fuzz: non-finite state after step %d\n", k);
          abort();
        }
        if (st != VD_OK && d->warning[VD_SIM_WARN_UNSTABLE] == 0) {
          fprintf(stderr, "fuzz: a step failed without a counted warning\n");
          abort();
        }
      }
      vd_sim_data_destroy(d);
    }
    model->opt.wind_series = NULL;
    model->opt.nwind = 0;
    vd_free(rows, (size_t)n * 4 * sizeof(double));
  } else if (rows || n) {
    abort();
  }
  fuzz_check_leak(before, "wind");
  return 0;
}
