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
#include "../bench_util.h"

typedef struct bench_case {
  const char* name;
  int robot;       // draw data/robots/arm6.xml
  int supersample; // colour anti-aliasing
  unsigned layers; // what is drawn per frame
} bench_case;

// a renderer for a case, with the tomato (plant 1) or without it (the peer); NULL on failure
static vd_renderer* make(const bench_case* c, const vd_model* m, int plant, double* setup_s) {
  vd_render_def def = vd_render_def_default();
  def.supersample = c->supersample;
  char robot[4200];
  snprintf(robot, sizeof robot, "%s/data/robots/arm6.xml", VD_SOURCE_DIR);
  if (c->robot) def.robot_mjcf = robot;
  vd_renderer* r;
  vd_error err = {0};
  if (vd_render_create(&def, &r, &err)) {
    fprintf(stderr, "%s: %s\n", c->name, err.msg);
    return NULL;
  }
  double t = bench_wall();
  if (plant && vd_render_add_plant(r, m, NULL, NULL, &err)) {
    fprintf(stderr, "%s: %s\n", c->name, err.msg);
    vd_render_destroy(r);
    return NULL;
  }
  *setup_s = bench_wall() - t;
  return r;
}

// frame times of a case and its peer, frames interleaved so that load from elsewhere on the
// machine hits both alike: mean and fastest frame of each; 0 on failure
static int run_case(const bench_case* c, const vd_model* m, int frames, double* mean, double* best,
                    double* peer_mean, double* peer_best, double* setup_s, char* info, size_t cap) {
  double ignore;
  vd_renderer* r = make(c, m, 1, setup_s);
  vd_renderer* p = r ? make(c, m, 0, &ignore) : NULL;
  if (!r || !p) {
    vd_render_destroy(r);
    return 0;
  }
  snprintf(info, cap, "%s", vd_render_info(r));
  // the tomato's box frames both alike; the camera turns a little every frame
  vd_vec3 lo = vd_v3(-0.45, -0.45, 0), hi = vd_v3(0.48, 0.48, 1.39);
  vd_frame f;
  vd_error err = {0};
  double sum[2] = {0, 0}, fast[2] = {1e30, 1e30};
  int ok = 1;
  for (int i = 0; i <= frames && ok; i++) {
    vd_camera cam = vd_camera_preset(VD_CAMERA_ORBIT, -1.0 + 0.02 * i, 0.35, lo, hi, 640, 480);
    for (int k = 0; k < 2 && ok; k++) {
      double a = bench_wall();
      if (vd_render_draw(k ? p : r, &cam, c->layers, &f, &err)) {
        fprintf(stderr, "%s: %s\n", c->name, err.msg);
        ok = 0;
      }
      double t = bench_wall() - a;
      if (i > 0) sum[k] += t, fast[k] = t < fast[k] ? t : fast[k]; // frame 0 warms up
    }
  }
  vd_render_destroy(r);
  vd_render_destroy(p);
  *mean = sum[0] / frames, *best = fast[0], *peer_mean = sum[1] / frames, *peer_best = fast[1];
  return ok;
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
      {"tomato", 0, 1, C},
      {"tomato supersample 2", 0, 2, C},
      {"tomato + depth + masks", 0, 1, ALL},
      {"tomato + arm", 1, 1, C},
      {"tomato + arm + depth + masks", 1, 1, ALL},
  };
  fprintf(csv,
          "bench,case,width,height,supersample,layers,plant_triangles,frames,ms_per_frame,"
          "frames_per_s,best_ms,peer_ms_per_frame,peer_best_ms,ratio_vs_peer,best_ratio_vs_peer,"
          "setup_s\n");
  printf(
      "tomato seed 1: %d triangles, 640 x 480, %d frames per case; peer: the same scene without\n"
      "the plant (MuJoCo's stage, or the arm), frames interleaved with the case's\n",
      ntri, frames);
  printf("%-30s %9s %7s %8s %9s %9s %7s %7s\n", "case", "ms/frame", "fps", "best_ms", "peer_ms",
         "peer_best", "x peer", "best x");
  char info[256] = "";
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    const bench_case* c = &cases[k];
    double t, best, pt, pbest, setup = 0;
    if (!run_case(c, m, frames, &t, &best, &pt, &pbest, &setup, info, sizeof info)) return 1;
    printf("%-30s %9.1f %7.1f %8.1f %9.1f %9.1f %7.2f %7.2f\n", c->name, 1e3 * t, 1 / t, 1e3 * best,
           1e3 * pt, 1e3 * pbest, t / pt, best / pbest);
    fprintf(csv, "render,%s,640,480,%d,%u,%d,%d,%.2f,%.2f,%.2f,%.2f,%.2f,%.3f,%.3f,%.4f\n", c->name,
            c->supersample, c->layers, ntri, frames, 1e3 * t, 1 / t, 1e3 * best, 1e3 * pt,
            1e3 * pbest, t / pt, best / pbest, setup);
    fflush(stdout);
  }
  printf("context: %s\nresults: %s\n", info, csv_path);
  fclose(csv);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
  vd_lsys_destroy(ls);
  return 0;
}
