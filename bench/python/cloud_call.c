// SPDX-License-Identifier: MIT
// The C side of bench/python/cloud_bench.py: vd_cloud_sample called in a loop in one process,
// as the Python binding calls it (same plant, seed, points and threads), each call timed in wall
// and process CPU seconds. The first call warms the allocator and is left out.
// usage: verdant_bench_cloud_call PLANT.lpy SEED POINTS THREADS REPS
// prints one JSON line: {"wall": best s, "cpu": best s, "points": n}
#include <stdlib.h>

#include "../bench_util.h"

int main(int argc, char** argv) {
  if (argc != 6) {
    fprintf(stderr, "usage: %s PLANT.lpy SEED POINTS THREADS REPS\n", argv[0]);
    return 2;
  }
  uint64_t seed = strtoull(argv[2], NULL, 10);
  int64_t points = strtoll(argv[3], NULL, 10);
  int threads = atoi(argv[4]), reps = atoi(argv[5]);
  // the plant as verdant.grow(PLANT, seed=SEED) makes it
  vd_error err = {0};
  vd_lsystem* ls = NULL;
  vd_plant_spec* s = vd_plant_spec_create();
  vd_model* m = NULL;
  vd_lsys_def ldef = vd_lsys_def_default();
  ldef.seed = seed;
  if (!s || vd_lsys_load(argv[1], &ls, &err) || vd_lsys_grow(ls, &ldef, NULL, s, &err) ||
      vd_plant_compile(s, &m, &err)) {
    char buf[1200];
    fprintf(stderr, "%s\n", vd_error_format(&err, buf, sizeof buf));
    return 1;
  }
  vd_lsys_destroy(ls);
  vd_plant_spec_destroy(s);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = points;
  def.seed = seed;
  def.threads = threads;
  def.max_points = 50000000;
  double best_wall = 1e30, best_cpu = 1e30;
  for (int r = 0; r <= reps; r++) {
    vd_cloud c;
    double w0 = bench_wall(), c0 = bench_cpu();
    vd_status st = vd_cloud_sample(m, NULL, &def, &c, NULL, &err);
    double w = bench_wall() - w0, cpu = bench_cpu() - c0;
    if (st) return 1;
    vd_cloud_free(&c);
    if (r > 0 && w < best_wall) best_wall = w;
    if (r > 0 && cpu < best_cpu) best_cpu = cpu;
  }
  vd_model_destroy(m);
  printf("{\"wall\": %.9f, \"cpu\": %.9f, \"points\": %lld}\n", best_wall, best_cpu, (long long)points);
  return 0;
}
