// SPDX-License-Identifier: MIT
// verdant render benchmark for simulation runs: what one frame of `verdant render RUN/` costs at
// 640 x 480 for the bundled tomato (seed 1, sag-free) pushed by a probe, step by step: reading
// the frame back (vd_sim_frames_load), the deformed plant (vd_sim_to_plant), the stress
// (vd_sim_plant_stress), rebuilding the scene (clear, tessellate, display lists, the probe) and
// drawing. The peer, measured in the same run with its frames interleaved, is the same scene
// drawn again without rebuilding (what a still plant costs). Also the cost of making a renderer.
// Results go to bench/results/render-run-2core.csv.
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "verdant/verdant.h"
#include "../bench_util.h"

// little-endian writers for frames.bin (docs/formats.md)
static void put_u32(FILE* f, uint32_t v) {
  for (int k = 0; k < 4; k++)
    fputc((int)(v >> (8 * k)) & 255, f);
}
static void put_f32(FILE* f, double d) {
  float x = (float)d;
  uint32_t u;
  memcpy(&u, &x, 4);
  put_u32(f, u);
}
static void put_f64(FILE* f, double d) {
  uint64_t u;
  memcpy(&u, &d, 8);
  for (int k = 0; k < 8; k++)
    fputc((int)(u >> (8 * k)) & 255, f);
}

static void record(FILE* f, const vd_sim_model* m, const vd_sim_data* d) {
  put_f64(f, d->time);
  for (int i = 0; i < m->nnode_all; i++)
    put_f32(f, d->node_pos[i].x), put_f32(f, d->node_pos[i].y), put_f32(f, d->node_pos[i].z);
  for (int t = 0; t < m->nseg; t++)
    put_f32(f, d->seg_quat[t].w), put_f32(f, d->seg_quat[t].x), put_f32(f, d->seg_quat[t].y),
        put_f32(f, d->seg_quat[t].z);
  for (int t = 0; t < m->nseg; t++)
    fputc(d->seg_broken[t] ? 1 : 0, f);
}

typedef struct bench_case {
  const char* name;
  int supersample;
  unsigned layers;
  vd_color_by color_by;
} bench_case;

typedef struct timing {
  double load, plant, stress, scene, draw, peer; // seconds per frame
  double best_total, best_peer;
} timing;

static int fail(const char* what, const vd_error* e) {
  fprintf(stderr, "%s: %s\n", what, e->msg);
  return 1;
}

int main(int argc, char** argv) {
  int nframe = 30;
  const char* csv_path = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      nframe = 8;
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
  }
  char defpath[512];
  if (!csv_path) {
    snprintf(defpath, sizeof defpath, "%s/bench/results/render-run-2core.csv", VD_SOURCE_DIR);
    csv_path = defpath;
  }
  // the tomato, seed 1, sag-free, a 4 cm probe moving through it at 0.8 m height over 1 s
  vd_lsystem* ls;
  vd_error err = {0};
  char lpy[4200];
  snprintf(lpy, sizeof lpy, "%s/data/tomato.lpy", VD_SOURCE_DIR);
  if (vd_lsys_load(lpy, &ls, &err)) return fail("tomato", &err);
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def ld = vd_lsys_def_default();
  ld.seed = 1;
  vd_model* pm = NULL;
  if (vd_lsys_grow(ls, &ld, NULL, s, &err) || vd_plant_compile(s, &pm, &err))
    return fail("tomato", &err);
  vd_sim_def def = vd_sim_def_default();
  def.sag_free = 1;
  vd_sim_model* sm = NULL;
  if (vd_sim_build(pm, &def, &sm, &err)) return fail("sim", &err);
  vd_sim_data* sd = vd_sim_data_create(sm);
  vd_data* pd = vd_data_create(pm);
  double* stress = malloc(sizeof(double) * (size_t)pm->nseg);
  if (!sd || !pd || !stress) return 1;
  vd_sim_collider probe = {
      VD_SIM_SPHERE, {0.04, 0, 0}, vd_v3(0.4, 0, 0.8), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  int pid = vd_sim_add_collider(sd, &probe);
  // the run: a frame every 1/30 s, written as frames.bin; the probe's positions kept
  char path[4200];
  snprintf(path, sizeof path, "/tmp/verdant_bench_render_run.%ld.bin", (long)getpid());
  FILE* f = fopen(path, "wb");
  if (!f) return 1;
  fwrite("VDSIMFRM", 1, 8, f);
  put_u32(f, 1), put_u32(f, (uint32_t)sm->nnode_all), put_u32(f, (uint32_t)sm->nseg), put_u32(f, 0);
  vd_vec3* probe_at = malloc(sizeof(vd_vec3) * (size_t)nframe);
  int steps_per_frame = 33;
  for (int k = 0; k < nframe; k++) {
    probe_at[k] = sd->collider[pid].pos;
    record(f, sm, sd);
    for (int i = 0; i < steps_per_frame; i++) {
      double x = 0.4 - 0.8 * (sd->time + sm->opt.dt) / (nframe * steps_per_frame * sm->opt.dt);
      vd_sim_set_collider_pose(sm, sd, pid, vd_v3(x, 0, 0.8), vd_quat_identity());
      vd_sim_step(sm, sd);
    }
  }
  fclose(f);
  vd_sim_frames* fr = NULL;
  if (vd_sim_frames_open(path, &fr, &err)) return fail("frames", &err);
  // renderer creation, three times
  double create = 0;
  for (int k = 0; k < 3; k++) {
    vd_render_def d = vd_render_def_default();
    vd_renderer* r;
    double t = bench_wall();
    if (vd_render_create(&d, &r, &err)) return fail("renderer", &err);
    create += (bench_wall() - t) / 3;
    vd_render_destroy(r);
  }
  FILE* csv = fopen(csv_path, "w");
  if (!csv) {
    fprintf(stderr, "cannot write %s\n", csv_path);
    return 1;
  }
  fprintf(csv, "bench,case,width,height,supersample,layers,frames,rod_nodes,rod_segments,load_ms,"
               "plant_ms,stress_ms,"
               "scene_ms,draw_ms,total_ms,frames_per_s,best_total_ms,peer_ms,peer_best_ms,ratio_vs_"
               "peer,renderer_create_s\n");
  printf(
      "tomato seed 1 sag-free: %d rod nodes, %d segments; a probe pushing it; %d frames of 640 x "
      "480\n"
      "per case; peer: the same scene drawn again without rebuilding (a still plant), interleaved\n"
      "making a renderer: %.3f s\n",
      sm->nnode_all, sm->nseg, nframe, create);
  printf("%-34s %7s %7s %7s %7s %7s %8s %6s %8s %7s %6s\n", "case", "load", "plant", "stress",
         "scene", "draw", "total", "fps", "best", "peer", "x peer");
  const bench_case cases[] = {
      {"colour; supersample 2 (CLI default)", 2, VD_LAYER_COLOR, VD_COLOR_LABEL},
      {"colour by stress; supersample 2", 2, VD_LAYER_COLOR, VD_COLOR_STRESS},
      {"colour + depth + masks", 1, VD_LAYER_ALL, VD_COLOR_LABEL},
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    const bench_case* bc = &cases[c];
    vd_render_def d = vd_render_def_default();
    d.supersample = bc->supersample;
    vd_renderer *r, *p;
    if (vd_render_create(&d, &r, &err) || vd_render_create(&d, &p, &err))
      return fail(bc->name, &err);
    // the peer: frame 0, built once
    vd_render_style st = vd_render_style_default();
    st.color_by = bc->color_by;
    st.seg_stress = stress;
    if (vd_sim_frames_load(fr, 0, sm, sd, &err)) return fail("load", &err);
    vd_sim_to_plant(sm, sd, pm, pd);
    vd_sim_plant_stress(sm, sd, pm, stress);
    if (vd_render_add_plant(p, pm, pd, &st, &err)) return fail("peer", &err);
    vd_vec3 lo = vd_v3(-0.9, -0.5, 0), hi = vd_v3(0.6, 0.5, 1.4);
    vd_camera cam = vd_camera_preset(VD_CAMERA_ORBIT, -1.0, 0.35, lo, hi, d.width, d.height);
    timing tm;
    memset(&tm, 0, sizeof tm);
    tm.best_total = tm.best_peer = 1e30;
    vd_frame out;
    for (int k = 0; k <= nframe; k++) {
      int fk = k == 0 ? 0 : k - 1; // a warm-up frame first
      double t0 = bench_wall();
      if (vd_sim_frames_load(fr, fk, sm, sd, &err)) return fail("load", &err);
      double t1 = bench_wall();
      vd_sim_to_plant(sm, sd, pm, pd);
      double t2 = bench_wall();
      if (bc->color_by == VD_COLOR_STRESS) vd_sim_plant_stress(sm, sd, pm, stress);
      double t3 = bench_wall();
      vd_render_clear(r);
      vd_render_shape sh = {
          VD_RENDER_SPHERE, {0.04, 0, 0}, probe_at[fk], vd_quat_identity(), {0.55f, 0.62f, 0.75f}};
      if (vd_render_add_plant(r, pm, pd, &st, &err) || vd_render_add_shape(r, &sh, &err))
        return fail("scene", &err);
      double t4 = bench_wall();
      if (vd_render_draw(r, &cam, bc->layers, &out, &err)) return fail("draw", &err);
      double t5 = bench_wall();
      if (vd_render_draw(p, &cam, bc->layers, &out, &err)) return fail("peer", &err);
      double t6 = bench_wall();
      if (k == 0) continue;
      tm.load += (t1 - t0) / nframe, tm.plant += (t2 - t1) / nframe,
          tm.stress += (t3 - t2) / nframe;
      tm.scene += (t4 - t3) / nframe, tm.draw += (t5 - t4) / nframe, tm.peer += (t6 - t5) / nframe;
      if (t5 - t0 < tm.best_total) tm.best_total = t5 - t0;
      if (t6 - t5 < tm.best_peer) tm.best_peer = t6 - t5;
    }
    double total = tm.load + tm.plant + tm.stress + tm.scene + tm.draw;
    printf("%-34s %7.2f %7.2f %7.2f %7.1f %7.1f %8.1f %6.1f %8.1f %7.1f %6.2f\n", bc->name,
           1e3 * tm.load, 1e3 * tm.plant, 1e3 * tm.stress, 1e3 * tm.scene, 1e3 * tm.draw,
           1e3 * total, 1 / total, 1e3 * tm.best_total, 1e3 * tm.peer, total / tm.peer);
    fprintf(csv,
            "render_run,%s,%d,%d,%d,%u,%d,%d,%d,%.3f,%.3f,%.3f,%.2f,%.2f,%.2f,%.3f,%.2f,%.2f,%.2f,%"
            ".3f,%.3f\n",
            bc->name, d.width, d.height, d.supersample, bc->layers, nframe, sm->nnode_all, sm->nseg,
            1e3 * tm.load, 1e3 * tm.plant, 1e3 * tm.stress, 1e3 * tm.scene, 1e3 * tm.draw,
            1e3 * total, 1 / total, 1e3 * tm.best_total, 1e3 * tm.peer, 1e3 * tm.best_peer,
            total / tm.peer, create);
    vd_render_destroy(r);
    vd_render_destroy(p);
  }
  fclose(csv);
  printf("results: %s\n", csv_path);
  remove(path);
  vd_sim_frames_close(fr);
  free(probe_at);
  free(stress);
  vd_data_destroy(pd);
  vd_sim_data_destroy(sd);
  vd_sim_model_destroy(sm);
  vd_model_destroy(pm);
  vd_plant_spec_destroy(s);
  vd_lsys_destroy(ls);
  return 0;
}
