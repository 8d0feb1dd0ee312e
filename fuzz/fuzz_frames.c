// SPDX-License-Identifier: MIT
// libFuzzer target: the simulation frames reader (frames.bin, frames.jsonl). The first byte
// picks the format, the rest is the file (written to a scratch file: the reader seeks in it);
// every frame that indexes is loaded into the state of a small rod model (a stem with a
// breakable fruit), the nearest-frame search runs, and nothing may leak.
// Seeds for that model: FUZZ_FRAMES_SEEDS=fuzz/corpus/fuzz_frames build-fuzz/fuzz_frames -runs=0
#define _POSIX_C_SOURCE 200809L
#include <unistd.h>

#include "fuzz_common.h"

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static vd_model* plant;
static vd_sim_model* model;
static vd_sim_data* state;
static char scratch[2][256];

// a stem of 12 cm with a fruit on a pedicel: a few rod segments, one breakable joint
static void build(void) {
  vd_plant_spec* s = vd_plant_spec_create();
  int a = vd_plant_add_node(s, vd_v3(0, 0, -0.01)), b = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(s, vd_v3(0, 0, 0.12)), e = vd_plant_add_node(s, vd_v3(0.03, 0, 0.12));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.003, g.label = 1, g.instance = 1;
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  int s1 = vd_plant_add_segment(s, &g);
  g.node0 = c, g.node1 = e, g.parent = s1, g.r0 = g.r1 = 0.001, g.label = 3, g.instance = 3;
  int s2 = vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0.03, 0, 0.105), f.radius = 0.01, f.node = e, f.parent = s2, f.label = 4;
  f.instance = 4;
  vd_plant_add_sphere(s, &f);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 3, "pedicel");
  vd_plant_set_label(s, 4, "fruit");
  vd_error err = {0};
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.04;
  if (vd_plant_compile(s, &plant, &err) || vd_sim_build(plant, &def, &model, &err)) abort();
  vd_plant_spec_destroy(s);
  state = vd_sim_data_create(model);
  if (!state) abort();
}

static void put_u32(FILE* f, uint32_t v) {
  for (int k = 0; k < 4; k++) fputc((int)(v >> (8 * k)) & 255, f);
}
static void put_f32(FILE* f, double d) {
  float x = (float)d;
  uint32_t u;
  memcpy(&u, &x, 4);
  put_u32(f, u);
}

// two seeds for the model: binary and JSON Lines, two frames, the second with the fruit broken
static void write_seeds(const char* dir) {
  char path[512];
  for (int jsonl = 0; jsonl < 2; jsonl++) {
    snprintf(path, sizeof path, "%s/seed_%s", dir, jsonl ? "jsonl" : "bin");
    FILE* f = fopen(path, "wb");
    if (!f) abort();
    fputc(jsonl, f);
    if (!jsonl) {
      fwrite("VDSIMFRM", 1, 8, f);
      put_u32(f, 1), put_u32(f, (uint32_t)model->nnode_all), put_u32(f, (uint32_t)model->nseg);
      put_u32(f, 0);
    }
    for (int k = 0; k < 2; k++) {
      double t = 0.05 * k;
      if (jsonl) {
        fprintf(f, "{\"t\":%g,\"pos\":[", t);
        for (int i = 0; i < model->nnode_all; i++)
          fprintf(f, "%s%g,%g,%g", i ? "," : "", model->node_pos0[i].x, model->node_pos0[i].y,
                  model->node_pos0[i].z);
        fputs("],\"quat\":[", f);
        for (int s = 0; s < model->nseg; s++)
          fprintf(f, "%s%g,%g,%g,%g", s ? "," : "", model->seg_quat0[s].w, model->seg_quat0[s].x,
                  model->seg_quat0[s].y, model->seg_quat0[s].z);
        fputs("],\"broken\":[", f);
        for (int s = 0, first = 1; s < model->nseg && k; s++)
          if (model->seg_spare[s] >= 0) fprintf(f, "%s%d", first ? "" : ",", s), first = 0;
        fputs("]}\n", f);
      } else {
        uint64_t u;
        memcpy(&u, &t, 8);
        for (int b = 0; b < 8; b++) fputc((int)(u >> (8 * b)) & 255, f);
        for (int i = 0; i < model->nnode_all; i++)
          put_f32(f, model->node_pos0[i].x), put_f32(f, model->node_pos0[i].y),
              put_f32(f, model->node_pos0[i].z);
        for (int s = 0; s < model->nseg; s++)
          put_f32(f, model->seg_quat0[s].w), put_f32(f, model->seg_quat0[s].x),
              put_f32(f, model->seg_quat0[s].y), put_f32(f, model->seg_quat0[s].z);
        for (int s = 0; s < model->nseg; s++) fputc(k && model->seg_spare[s] >= 0, f);
      }
    }
    fclose(f);
  }
}

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  fuzz_install_allocator();
  vd_set_assert_handler(fuzz_assert);
  build();
  for (int k = 0; k < 2; k++)
    snprintf(scratch[k], sizeof scratch[k], "/tmp/verdant_fuzz_frames.%ld.%s", (long)getpid(),
             k ? "jsonl" : "bin");
  const char* seeds = getenv("FUZZ_FRAMES_SEEDS");
  if (seeds) write_seeds(seeds);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  int jsonl = data[0] & 1;
  FILE* f = fopen(scratch[jsonl], "wb");
  if (!f) return 0;
  fwrite(data + 1, 1, size - 1, f);
  fclose(f);
  int64_t before = vd_alloc_bytes();
  vd_sim_frames* fr = NULL;
  vd_error err = {0};
  if (vd_sim_frames_open(scratch[jsonl], &fr, &err) == VD_OK) {
    int n = vd_sim_frames_count(fr);
    for (int k = 0; k < n && k < 8; k++) {
      vd_error e2 = {0};
      if (vd_sim_frames_load(fr, k, model, state, &e2) == VD_OK) {
        // a loaded state is finite and its broken joints hang from their spares
        for (int t = 0; t < model->nseg; t++)
          if (state->seg_broken[t] && state->seg_start[t] != model->seg_spare[t]) abort();
      }
    }
    if (n) {
      int k = vd_sim_frames_nearest(fr, vd_sim_frames_time(fr, n / 2));
      if (k < 0 || k >= n) abort();
    }
    vd_sim_frames_close(fr);
  }
  fuzz_check_leak(before, "frames");
  return 0;
}
