// SPDX-License-Identifier: MIT
// Shared by the benchmark programs: the two clocks they time with and a bundled plant grown
// and compiled. Header-only (each benchmark is its own program).
#ifndef VD_BENCH_UTIL_H
#define VD_BENCH_UTIL_H

#include <stdio.h>
#include <time.h>

#include "verdant/verdant.h"

// wall-clock seconds (monotonic)
static inline double bench_wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// the machine's 1-minute load average (/proc/loadavg; -1 when unknown), written beside timings
static inline double bench_load1(void) {
  double l = -1;
  FILE* f = fopen("/proc/loadavg", "r");
  if (f) {
    if (fscanf(f, "%lf", &l) != 1) l = -1;
    fclose(f);
  }
  return l;
}

// CPU seconds of the whole process (all threads)
static inline double bench_cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// the .lpy file at path grown with seed 0 for the file's derivation length and compiled; NULL
// with the error on stderr
static inline vd_model* bench_grow(const char* path) {
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  vd_plant_spec* s = vd_plant_spec_create();
  vd_model* m = NULL;
  vd_lsys_def def = vd_lsys_def_default();
  if (!s) {
    vd_error_set(&err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  } else if (!vd_lsys_load(path, &ls, &err) && !vd_lsys_grow(ls, &def, NULL, s, &err)) {
    vd_plant_compile(s, &m, &err);
  }
  if (!m) {
    char buf[1200];
    fprintf(stderr, "%s\n", vd_error_format(&err, buf, sizeof buf));
  }
  vd_lsys_destroy(ls);
  vd_plant_spec_destroy(s);
  return m;
}

#endif
