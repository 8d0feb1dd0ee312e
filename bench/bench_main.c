// SPDX-License-Identifier: MIT
// verdant benchmarks: derivation (modules/s) and turtle (segments/s) on derivations of 10^5 to
// 10^7 modules, each printed beside memcpy of the same bytes in the same run (the peer: the
// fastest any string rewriter can move its output). The same rules run again through the Python
// engine (embedded CPython) up to 10^6 modules, so the cost of the Python path is measured on the
// same work. Results go to bench/results/<host>.csv.
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "verdant/verdant.h"
#include "bench_util.h"

typedef struct case_def {
  const char* name;
  const char* src;
  int steps[3];  // steps giving ~1e5, ~1e6, ~1e7 modules
} case_def;

static const case_def cases[] = {
    {"parametric_binary_tree", "R = 2.0\nAxiom: A(1)\nproduction:\nA(s) --> F(s)[+A(s/R)][-A(s/R)]\n",
     {14, 17, 20}},
    {"algae_copy_heavy", "Axiom: A\nproduction:\nA --> AB\nB --> A\n", {24, 29, 34}},
    {"stochastic_bush",
     "from random import *\nAxiom: A(1)\nproduction:\n"
     "A(s) :\n  if random() < 0.5:\n    produce F(s)[+(uniform(20,40))A(s*0.7)]A(s*0.9)\n"
     "  else:\n    produce F(s)[-(uniform(20,40))A(s*0.7)]/(137.5)A(s*0.9)\n",
     {14, 17, 20}},
    // every module rewritten by a rule with a body: the rule calls dominate (the Python engine's
    // worst case)
    {"body_every_module",
     "Axiom: A(0)\nproduction:\nA(x) :\n  if x % 2 == 0:\n    produce A(x + 1) A(x + 3)\n"
     "  else:\n    produce A(x + 1)\n",
     {34, 40, 46}},
};

typedef struct acc {
  int64_t total;  // modules written over all steps
} acc;

static int count_cb(void* user, int step, int steps, int64_t modules) {
  (void)step;
  (void)steps;
  ((acc*)user)->total += modules;
  return 0;
}

// best of `reps` memcpy passes moving `bytes` bytes through a buffer of `chunk` bytes
static double memcpy_seconds(size_t bytes, size_t chunk) {
  char* a = malloc(chunk);
  char* b = malloc(chunk);
  if (!a || !b) {
    free(a);
    free(b);
    return -1;
  }
  memset(a, 1, chunk);
  memset(b, 2, chunk);
  double best = 1e30;
  for (int r = 0; r < 3; r++) {
    double t0 = bench_wall();
    size_t left = bytes;
    while (left) {
      size_t n = left < chunk ? left : chunk;
      memcpy(b, a, n);
      a[n / 2] ^= b[n / 3];  // keep the copies observable
      left -= n;
    }
    double t = bench_wall() - t0;
    if (t < best) best = t;
  }
  free(a);
  free(b);
  return best;
}

int main(int argc, char** argv) {
  int max_size = 3;  // 1: 1e5 only, 2: up to 1e6, 3: up to 1e7
  const char* csv_path = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) max_size = 2;
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
  }
  char host[128] = "unknown";
  gethostname(host, sizeof host);
  char defpath[512];
  if (!csv_path) {
    snprintf(defpath, sizeof defpath, "%s/bench/results/lsys-%s.csv", VD_SOURCE_DIR, "2core");
    csv_path = defpath;
  }
  FILE* csv = fopen(csv_path, "w");
  if (!csv) {
    fprintf(stderr, "cannot write %s\n", csv_path);
    return 1;
  }
  fprintf(csv, "bench,case,modules_final,modules_total,seconds,modules_per_s,memcpy_seconds,ratio_vs_memcpy,"
               "segments,turtle_seconds,segments_per_s,engine\n");
  printf("%-24s %-7s %12s %12s %9s %14s %10s %9s %12s\n", "case", "engine", "final", "written", "derive_s",
         "modules/s", "memcpy_s", "x memcpy", "segments/s");
  char why[256];
  int python = vd_lsys_python_available(why, sizeof why);
  if (!python) printf("(no Python engine here: %s)\n", why);
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    for (int run = 0; run < 2 * max_size; run++) {
      // native at every size, then the Python engine on the same rules up to ~1e6 modules
      int k = run % max_size;
      vd_lsys_engine eng = run < max_size ? VD_LSYS_NATIVE : VD_LSYS_PYTHON;
      if (eng == VD_LSYS_PYTHON && (!python || k > 1)) continue;
      vd_lsystem* ls;
      vd_error err = {0};
      if (vd_lsys_parse_engine(cases[c].src, strlen(cases[c].src), cases[c].name, eng, &ls, &err)) {
        fprintf(stderr, "%s: %s\n", cases[c].name, err.msg);
        return 1;
      }
      vd_lsys_def def = vd_lsys_def_default();
      def.steps = cases[c].steps[k];
      def.seed = 1;
      acc a = {0};
      def.progress = count_cb;
      def.progress_user = &a;
      vd_lstring s = vd_lstring_empty();
      double t0 = bench_wall();
      vd_status st = vd_lsys_derive(ls, &def, &s, &err);
      double td = bench_wall() - t0;
      if (st) {
        fprintf(stderr, "%s: %s\n", cases[c].name, err.msg);
        return 1;
      }
      // the bytes the derivation wrote: symbols, parameter offsets and values of every step
      double bytes_per_module = (double)(s.n * (4 + 8) + s.par[s.n] * 8) / (double)s.n;
      size_t bytes = (size_t)(bytes_per_module * (double)a.total);
      size_t chunk = (size_t)(s.n * 12 + s.par[s.n] * 8);
      double tm = memcpy_seconds(bytes, chunk);
      // turtle on the final string
      vd_plant_spec* plant = vd_plant_spec_create();
      vd_turtle_def td_def = vd_turtle_def_default();
      double t1 = bench_wall();
      st = vd_turtle_run(ls, &s, &td_def, plant, &err);
      double tt = bench_wall() - t1;
      int nseg = plant ? plant->nseg : 0;
      double mps = (double)a.total / td;
      const char* en = vd_lsys_engine_name(eng);
      printf("%-24s %-7s %12lld %12lld %9.4f %14.0f %10.4f %9.2f %12.0f\n", cases[c].name, en, (long long)s.n,
             (long long)a.total, td, mps, tm, td / tm, tt > 0 ? nseg / tt : 0);
      fprintf(csv, "derive,%s,%lld,%lld,%.6f,%.0f,%.6f,%.3f,%d,%.6f,%.0f,%s\n", cases[c].name, (long long)s.n,
              (long long)a.total, td, mps, tm, td / tm, nseg, tt, tt > 0 ? nseg / tt : 0, en);
      fflush(stdout);
      vd_plant_spec_destroy(plant);
      vd_lstring_free(&s);
      vd_lsys_destroy(ls);
    }
  }
  fclose(csv);
  printf("results: %s\n", csv_path);
  return 0;
}
