// SPDX-License-Identifier: MIT
// verdant render benchmark: frames per second at 640 x 480 for the bundled tomato (seed 1), with
// and without the arm of data/robots/arm6.xml, colour only and colour + depth + masks, beside
// the peer measured in the same run: MuJoCo drawing the same stage (floor, sky, lights, shadows)
// or the arm alone, without the plant. Software rendering (Mesa llvmpipe) on machines without a
// GPU. Results go to bench/results/render-2core.csv.
#define _POSIX_C_SOURCE 200809L
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

typedef struct bench_case {
  const char* name;
  int robot;       // draw data/robots/arm6.xml
  int plant;       // draw the tomato (0: the peer, MuJoCo's stage or robot alone)
  int supersample; // colour anti-aliasing
  unsigned layers; // what is drawn per frame
} bench_case;

// seconds per frame of a case, mean over frames after one warm-up frame; -1 on failure
static double run_case(const bench_case* c, const vd_model* m, int frames, double* setup_s,
                       const char** info) {
  vd_render_def def = vd_render_def_default();
  def.supersample = c->supersample;
  char robot[4200];
  snprintf(robot, sizeof robot, "%s/data/robots/arm6.xml", VD_SOURCE_DIR);
  if (c->robot) def.robot_mjcf = robot;
  vd_renderer* r;
  vd_error err = {0};
  double t0 = now();
  if (vd_render_create(&def, &r, &err)) {
    fprintf(stderr, "%s: %s\n", c->name, err.msg);
    return -1;
  }
  double t1 = now();
  if (c->plant && vd_render_add_plant(r, m, NULL, NULL, &err)) {
    fprintf(stderr, "%s: %s\n", c->name, err.msg);
    vd_render_destroy(r);
    return -1;
  }
  double t2 = now();
  *setup_s = t2 - t1;
  (void)t0;
  static char info_buf[256];
  snprintf(info_buf, sizeof info_buf, "%s", vd_render_info(r));
  *info = info_buf;
  // the tomato's box frames every case alike (the peer draws the same view)
  vd_vec3 lo = vd_v3(-0.45, -0.45, 0), hi = vd_v3(0.48, 0.48, 1.39);
  vd_frame f;
  double total = 0;
  for (int i = 0; i <= frames; i++) {
    vd_camera cam =
        vd_camera_preset(VD_CAMERA_ORBIT, -1.0 + 0.02 * i, 0.35, lo, hi, def.width, def.height);
    double a = now();
    if (vd_render_draw(r, &cam, c->layers, &f, &err)) {
      fprintf(stderr, "%s: %s\n", c->name, err.msg);
      vd_render_destroy(r);
      return -1;
    }
    if (i > 0) total += now() - a;
  }
  vd_render_destroy(r);
  return total / frames;
}

int main(int argc, char** argv) {
  int frames = 20;
  const char* csv_path = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      frames = 5;
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
  }
  char defpath[512];
  if (!csv_path) {
    snprintf(defpath, sizeof defpath, "%s/bench/results/render-2core.csv", VD_SOURCE_DIR);
    csv_path = defpath;
  }
  // the tomato, seed 1
  vd_lsystem* ls;
  vd_error err = {0};
  char lpy[4200];
  snprintf(lpy, sizeof lpy, "%s/data/tomato.lpy", VD_SOURCE_DIR);
  if (vd_lsys_load(lpy, &ls, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def ld = vd_lsys_def_default();
  ld.seed = 1;
  vd_model* m = NULL;
  if (vd_lsys_grow(ls, &ld, NULL, s, &err) || vd_plant_compile(s, &m, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  vd_mesh mesh;
  vd_geom_tessellate(m, NULL, NULL, &mesh, &err);
  int ntri = mesh.ntri;
  vd_mesh_free(&mesh);
  FILE* csv = fopen(csv_path, "w");
  if (!csv) {
    fprintf(stderr, "cannot write %s\n", csv_path);
    return 1;
  }
  const unsigned C = VD_LAYER_COLOR, ALL = VD_LAYER_ALL;
  const bench_case cases[] = {
      {"stage alone (peer)", 0, 0, 1, C},
      {"tomato", 0, 1, 1, C},
      {"tomato, supersample 2", 0, 1, 2, C},
      {"tomato + depth + masks", 0, 1, 1, ALL},
      {"arm alone (peer)", 1, 0, 1, C},
      {"tomato + arm", 1, 1, 1, C},
      {"tomato + arm + depth + masks", 1, 1, 1, ALL},
  };
  fprintf(
      csv,
      "bench,case,width,height,supersample,layers,plant_triangles,frames,ms_per_frame,frames_per_s,"
      "setup_s,ratio_vs_peer\n");
  printf("tomato seed 1: %d triangles, 640 x 480, %d frames per case\n", ntri, frames);
  printf("%-32s %10s %8s %10s %8s\n", "case", "ms/frame", "fps", "setup_s", "x peer");
  double peer = 0;
  const char* info = "";
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    const bench_case* c = &cases[k];
    double setup = 0, t = run_case(c, m, frames, &setup, &info);
    if (t < 0) return 1;
    if (!c->plant) peer = t;
    printf("%-32s %10.1f %8.1f %10.3f %8.2f\n", c->name, 1e3 * t, 1 / t, setup, t / peer);
    fprintf(csv, "render,%s,640,480,%d,%u,%d,%d,%.2f,%.2f,%.4f,%.3f\n", c->name, c->supersample,
            c->layers, c->plant ? ntri : 0, frames, 1e3 * t, 1 / t, setup, t / peer);
    fflush(stdout);
  }
  printf("context: %s\nresults: %s\n", info, csv_path);
  fclose(csv);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
  vd_lsys_destroy(ls);
  return 0;
}
