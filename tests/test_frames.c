// SPDX-License-Identifier: MIT
// frames: reading the frames `verdant sim` writes (binary and JSON Lines, written here by hand
// from the layout in docs/formats.md) back into a rod state, broken joints included; errors
// that name the file and the line; the moment and bending stress from a state against the
// cantilever's M(x) = F (L - x) and sigma = 4 M / (pi r^3).
#include <stdlib.h>

#include "test.h"
#include "verdant/verdant.h"

// ---------------------------------------------------------------------------------------------
// helpers

// a straight cantilever along +x: a clamped piece of 1 cm behind the origin, then len, and a
// fruit on its tip when asked
static vd_model* cantilever(double len, double r, int with_fruit) {
  vd_beam_def d = vd_beam_def_default();
  d.length = len, d.radius = r, d.fruit_radius = with_fruit ? 0.01 : 0, d.fruit_offset = 0.01;
  vd_model* m;
  vd_error e = {0};
  vd_plant_beam_model(&d, &m, &e);
  return m;
}

static vd_sim_def rod_def(double sigma, double young) {
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = sigma;
  def.clamp_length = 0.01;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++)
    def.material[k].young = young, def.material[k].density = 1000;
  return def;
}

static void put_u32(FILE* f, uint32_t v) {
  unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                        (unsigned char)(v >> 24)};
  fwrite(b, 1, 4, f);
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

// append a frame record of state d (docs/formats.md, frames.bin)
static void bin_record(FILE* f, const vd_sim_model* m, const vd_sim_data* d) {
  put_f64(f, d->time);
  for (int i = 0; i < m->nnode_all; i++)
    put_f32(f, d->node_pos[i].x), put_f32(f, d->node_pos[i].y), put_f32(f, d->node_pos[i].z);
  for (int t = 0; t < m->nseg; t++)
    put_f32(f, d->seg_quat[t].w), put_f32(f, d->seg_quat[t].x), put_f32(f, d->seg_quat[t].y),
        put_f32(f, d->seg_quat[t].z);
  for (int t = 0; t < m->nseg; t++)
    fputc(d->seg_broken[t] ? 1 : 0, f);
}

static void bin_header(FILE* f, const vd_sim_model* m) {
  fwrite("VDSIMFRM", 1, 8, f);
  put_u32(f, 1);
  put_u32(f, (uint32_t)m->nnode_all);
  put_u32(f, (uint32_t)m->nseg);
  put_u32(f, 0);
}

// append a frame line of state d (docs/formats.md, frames.jsonl)
static void jsonl_record(FILE* f, const vd_sim_model* m, const vd_sim_data* d) {
  fprintf(f, "{\"t\":%.9g,\"pos\":[", d->time);
  for (int i = 0; i < m->nnode_all; i++)
    fprintf(f, "%s%.9g,%.9g,%.9g", i ? "," : "", d->node_pos[i].x, d->node_pos[i].y,
            d->node_pos[i].z);
  fputs("],\"quat\":[", f);
  for (int t = 0; t < m->nseg; t++)
    fprintf(f, "%s%.9g,%.9g,%.9g,%.9g", t ? "," : "", d->seg_quat[t].w, d->seg_quat[t].x,
            d->seg_quat[t].y, d->seg_quat[t].z);
  fputs("],\"broken\":[", f);
  for (int t = 0, first = 1; t < m->nseg; t++)
    if (d->seg_broken[t]) fprintf(f, "%s%d", first ? "" : ",", t), first = 0;
  fputs("]}\n", f);
}

// three states of a cantilever with a fruit pulled off: at rest, bent, the fruit broken away
typedef struct run3 {
  vd_model* plant;
  vd_sim_model* m;
  vd_sim_data* s[3];
} run3;

static int run3_make(run3* r) {
  memset(r, 0, sizeof *r);
  r->plant = cantilever(0.1, 0.001, 1);
  if (!r->plant) return 0;
  vd_sim_def def = rod_def(0.01, 5e8);
  def.material[VD_SIM_FRUIT].break_force = 0.5;
  vd_error e = {0};
  if (vd_sim_build(r->plant, &def, &r->m, &e)) return 0;
  r->m->opt.gravity = vd_v3(0, 0, 0);
  vd_sim_data* d = vd_sim_data_create(r->m);
  if (!d) return 0;
  int fruit = vd_sim_find_organ(r->m, r->plant, "fruit", 0);
  for (int k = 0; k < 3; k++) {
    r->s[k] = vd_sim_data_create(r->m);
    if (!r->s[k]) return 0;
  }
  // a copy of the state at three times: 0, 0.1 s (bent), 0.4 s (broken)
  size_t V = sizeof(vd_vec3);
  for (int step = 0, k = 0; step <= 400 && k < 3; step++) {
    if (step == 0 || step == 100 || step == 400) {
      vd_sim_data* c = r->s[k++];
      memcpy(c->node_pos, d->node_pos, (size_t)r->m->nnode_all * V);
      memcpy(c->seg_quat, d->seg_quat, (size_t)r->m->nseg * sizeof(vd_quat));
      memcpy(c->seg_broken, d->seg_broken, (size_t)r->m->nseg * sizeof(int));
      memcpy(c->seg_start, d->seg_start, (size_t)r->m->nseg * sizeof(int));
      c->time = d->time;
    }
    d->node_force[fruit] = vd_v3(2.0 * d->time, 0, -1.0 * d->time);
    vd_sim_step(r->m, d);
  }
  vd_sim_data_destroy(d);
  return 1;
}

static void run3_free(run3* r) {
  for (int k = 0; k < 3; k++)
    vd_sim_data_destroy(r->s[k]);
  vd_sim_model_destroy(r->m);
  vd_model_destroy(r->plant);
}

static const char* tmp_path(const char* name) {
  static char buf[4][512];
  static int next;
  char* b = buf[next++ & 3];
  snprintf(b, 512, "%s/%s", vdt_tmpdir(), name);
  return b;
}

// the loaded state has the frame's positions, frames, broken joints; the deformed plant agrees
static void check_loaded(const run3* r, const vd_sim_data* want, const vd_sim_data* got,
                         double tol) {
  const vd_sim_model* m = r->m;
  CHECK_NEAR(got->time, want->time, 1e-12);
  double dp = 0, dq = 0;
  for (int i = 0; i < m->nnode_all; i++)
    dp = fmax(dp, vd_norm(vd_sub(got->node_pos[i], want->node_pos[i])));
  for (int t = 0; t < m->nseg; t++) {
    vd_quat a = got->seg_quat[t], b = want->seg_quat[t];
    dq = fmax(dq, fabs(a.w - b.w) + fabs(a.x - b.x) + fabs(a.y - b.y) + fabs(a.z - b.z));
    CHECK_INT(got->seg_broken[t], want->seg_broken[t]);
    CHECK_INT(got->seg_start[t], want->seg_start[t]);
  }
  CHECK(dp < tol);
  CHECK(dq < 4 * tol);
  // the deformed plant drawn from the loaded state matches the original state's
  vd_data* pa = vd_data_create(r->plant);
  vd_data* pb = vd_data_create(r->plant);
  REQUIRE(pa && pb);
  vd_sim_to_plant(m, want, r->plant, pa);
  vd_sim_to_plant(m, got, r->plant, pb);
  double d = 0;
  for (int i = 0; i < 3 * r->plant->nsphere; i++)
    d = fmax(d, fabs(pa->sphere_pos[i] - pb->sphere_pos[i]));
  for (int i = 0; i < 3 * r->plant->nnode; i++)
    d = fmax(d, fabs(pa->node_pos[i] - pb->node_pos[i]));
  CHECK(d < 10 * tol);
  vd_data_destroy(pa);
  vd_data_destroy(pb);
}

// ---------------------------------------------------------------------------------------------
// reading frames

TEST(frames, binary_round_trip) {
  run3 r;
  REQUIRE(run3_make(&r));
  REQUIRE(r.s[2]->time > 0.39);
  int nbroken = 0;
  for (int t = 0; t < r.m->nseg; t++)
    nbroken += r.s[2]->seg_broken[t];
  CHECK_INT(nbroken, 1); // the fruit came off in the last frame
  const char* path = tmp_path("frames.bin");
  FILE* f = fopen(path, "wb");
  REQUIRE(f);
  bin_header(f, r.m);
  for (int k = 0; k < 3; k++)
    bin_record(f, r.m, r.s[k]);
  fclose(f);
  vd_sim_frames* fr = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_frames_open(path, &fr, &e), VD_OK, e);
  REQUIRE(fr);
  CHECK_INT(vd_sim_frames_count(fr), 3);
  int nn, ns;
  vd_sim_frames_size(fr, &nn, &ns);
  CHECK_INT(nn, r.m->nnode_all);
  CHECK_INT(ns, r.m->nseg);
  CHECK_NEAR(vd_sim_frames_time(fr, 1), r.s[1]->time, 1e-12);
  // nearest frame: ties go to the earlier one, outside the run to the ends
  CHECK_INT(vd_sim_frames_nearest(fr, -5), 0);
  CHECK_INT(vd_sim_frames_nearest(fr, 0.04), 0);
  CHECK_INT(vd_sim_frames_nearest(fr, 0.2), 1);
  CHECK_INT(vd_sim_frames_nearest(fr, 0.5 * (r.s[1]->time + r.s[2]->time)), 1);
  CHECK_INT(vd_sim_frames_nearest(fr, 99), 2);
  vd_sim_data* d = vd_sim_data_create(r.m);
  REQUIRE(d);
  for (int k = 0; k < 3; k++) {
    CHECK_STATUS(vd_sim_frames_load(fr, k, r.m, d, &e), VD_OK, e);
    check_loaded(&r, r.s[k], d, 2e-7);
  }
  // frames of another model do not load
  vd_model* p2 = cantilever(0.2, 0.001, 0);
  vd_sim_def def = rod_def(0.01, 5e8);
  vd_sim_model* m2 = NULL;
  REQUIRE(p2 && !vd_sim_build(p2, &def, &m2, &e));
  vd_sim_data* d2 = vd_sim_data_create(m2);
  REQUIRE(d2);
  CHECK_STATUS(vd_sim_frames_load(fr, 0, m2, d2, &e), VD_ERR_FORMAT, e);
  vd_sim_data_destroy(d2);
  vd_sim_model_destroy(m2);
  vd_model_destroy(p2);
  vd_sim_frames_close(fr);
  vd_sim_data_destroy(d);
  run3_free(&r);
}

TEST(frames, jsonl_round_trip) {
  run3 r;
  REQUIRE(run3_make(&r));
  const char* path = tmp_path("frames.jsonl");
  FILE* f = fopen(path, "wb");
  REQUIRE(f);
  for (int k = 0; k < 3; k++) {
    jsonl_record(f, r.m, r.s[k]);
    if (k == 0) fputs("   \n", f); // blank lines are skipped
  }
  fclose(f);
  vd_sim_frames* fr = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_frames_open(path, &fr, &e), VD_OK, e);
  REQUIRE(fr);
  CHECK_INT(vd_sim_frames_count(fr), 3);
  vd_sim_data* d = vd_sim_data_create(r.m);
  REQUIRE(d);
  for (int k = 0; k < 3; k++) {
    CHECK_STATUS(vd_sim_frames_load(fr, k, r.m, d, &e), VD_OK, e);
    check_loaded(&r, r.s[k], d, 1e-7);
  }
  vd_sim_frames_close(fr);
  vd_sim_data_destroy(d);
  run3_free(&r);
}

// write bytes to a file
static const char* put_file(const char* name, const void* data, size_t n) {
  const char* path = tmp_path(name);
  FILE* f = fopen(path, "wb");
  if (!f) return path;
  fwrite(data, 1, n, f);
  fclose(f);
  return path;
}

TEST(frames, bad_files) {
  run3 r;
  REQUIRE(run3_make(&r));
  vd_sim_frames* fr = NULL;
  vd_error e = {0};
  // a whole binary file in memory, then damaged copies
  const char* good = tmp_path("good.bin");
  FILE* f = fopen(good, "wb");
  REQUIRE(f);
  bin_header(f, r.m);
  for (int k = 0; k < 3; k++)
    bin_record(f, r.m, r.s[k]);
  fclose(f);
  char* bytes;
  size_t len;
  REQUIRE(!vd_file_read(good, &bytes, &len, &e));
  size_t rec = 8 + 12 * (size_t)r.m->nnode_all + 17 * (size_t)r.m->nseg;
  REQUIRE(len == 24 + 3 * rec);
  CHECK_STATUS(vd_sim_frames_open(tmp_path("missing.bin"), &fr, &e), VD_ERR_IO, e);
  CHECK(fr == NULL);
  CHECK_STATUS(vd_sim_frames_open(put_file("short.bin", bytes, 10), &fr, &e), VD_ERR_FORMAT, e);
  e = (vd_error){0}; // (an error record keeps its first error)
  CHECK_STATUS(vd_sim_frames_open(put_file("cut.bin", bytes, len - 5), &fr, &e), VD_ERR_FORMAT, e);
  CHECK(strstr(e.msg, "truncated") != NULL);
  char* copy = malloc(len);
  REQUIRE(copy);
  memcpy(copy, bytes, len), copy[0] = 'X';
  CHECK_STATUS(vd_sim_frames_open(put_file("magic.bin", copy, len), &fr, &e), VD_ERR_FORMAT, e);
  memcpy(copy, bytes, len), copy[8] = 7; // version 7
  CHECK_STATUS(vd_sim_frames_open(put_file("version.bin", copy, len), &fr, &e), VD_ERR_FORMAT, e);
  // time going backwards: frame 2 at t = 0
  memcpy(copy, bytes, len), memset(copy + 24 + 2 * rec, 0, 8);
  CHECK_STATUS(vd_sim_frames_open(put_file("back.bin", copy, len), &fr, &e), VD_ERR_FORMAT, e);
  // a broken flag on a joint that cannot break opens, but does not load
  memcpy(copy, bytes, len);
  int t0 = -1;
  for (int t = 0; t < r.m->nseg && t0 < 0; t++)
    if (r.m->seg_spare[t] < 0) t0 = t;
  REQUIRE(t0 >= 0);
  copy[24 + rec + 8 + 12 * (size_t)r.m->nnode_all + 16 * (size_t)r.m->nseg + (size_t)t0] = 1;
  CHECK_STATUS(vd_sim_frames_open(put_file("flag.bin", copy, len), &fr, &e), VD_OK, e);
  vd_sim_data* d = vd_sim_data_create(r.m);
  REQUIRE(fr && d);
  CHECK_STATUS(vd_sim_frames_load(fr, 0, r.m, d, &e), VD_OK, e);
  CHECK_STATUS(vd_sim_frames_load(fr, 1, r.m, d, &e), VD_ERR_FORMAT, e);
  vd_sim_frames_close(fr);
  // a non-finite position: frame 0, node 0
  memcpy(copy, bytes, len);
  float nan = NAN;
  memcpy(copy + 24 + 8, &nan, 4);
  CHECK_STATUS(vd_sim_frames_open(put_file("nan.bin", copy, len), &fr, &e), VD_OK, e);
  CHECK_STATUS(vd_sim_frames_load(fr, 0, r.m, d, &e), VD_ERR_FORMAT, e);
  vd_sim_frames_close(fr);
  // JSON Lines: the error names the line
  const char* bad =
      "{\"t\":0,\"pos\":[0,0,0],\"quat\":[1,0,0,0],\"broken\":[]}\n{\"t\":1,\"pos\":[0,0]}\n";
  e = (vd_error){0};
  CHECK_STATUS(vd_sim_frames_open(put_file("bad.jsonl", bad, strlen(bad)), &fr, &e), VD_ERR_FORMAT,
               e);
  CHECK_INT(e.line, 2);
  // a time going backwards in JSON Lines (fuzz finding: the parsed line leaked)
  const char* back = "{\"t\":1,\"pos\":[0,0,0],\"quat\":[1,0,0,0],\"broken\":[]}\n"
                     "{\"t\":0,\"pos\":[0,0,0],\"quat\":[1,0,0,0],\"broken\":[]}\n";
  e = (vd_error){0};
  CHECK_STATUS(vd_sim_frames_open(put_file("back.jsonl", back, strlen(back)), &fr, &e),
               VD_ERR_FORMAT, e);
  CHECK_INT(e.line, 2);
  const char* junk = "{\"t\":0,\"pos\":[0,0,0],\"quat\":[1,0,0,0],\"broken\":[]}\n\nnot json\n";
  e = (vd_error){0};
  CHECK_STATUS(vd_sim_frames_open(put_file("junk.jsonl", junk, strlen(junk)), &fr, &e),
               VD_ERR_FORMAT, e);
  CHECK_INT(e.line, 3);
  // a broken segment id out of every range (fuzz finding: 1e999 cast to int)
  const char* huge = tmp_path("huge.jsonl");
  f = fopen(huge, "wb");
  REQUIRE(f);
  jsonl_record(f, r.m, r.s[0]);
  fclose(f);
  char* text;
  size_t tl;
  REQUIRE(!vd_file_read(huge, &text, &tl, &e));
  char* br = strstr(text, "\"broken\":[]");
  REQUIRE(br);
  char* edited = malloc(tl + 16);
  REQUIRE(edited);
  snprintf(edited, tl + 16, "%.*s\"broken\":[1e999]}\n", (int)(br - text), text);
  vd_free(text, tl + 1);
  e = (vd_error){0};
  CHECK_STATUS(vd_sim_frames_open(put_file("huge.jsonl", edited, strlen(edited)), &fr, &e), VD_OK,
               e);
  REQUIRE(fr);
  CHECK_STATUS(vd_sim_frames_load(fr, 0, r.m, d, &e), VD_ERR_FORMAT, e);
  vd_sim_frames_close(fr);
  free(edited);
  free(copy);
  vd_free(bytes, len + 1);
  vd_sim_data_destroy(d);
  run3_free(&r);
}

TEST(frames, out_of_memory) {
  run3 r;
  REQUIRE(run3_make(&r));
  const char* paths[2] = {tmp_path("oom.bin"), tmp_path("oom.jsonl")};
  FILE* f = fopen(paths[0], "wb");
  REQUIRE(f);
  bin_header(f, r.m);
  for (int k = 0; k < 3; k++)
    bin_record(f, r.m, r.s[k]);
  fclose(f);
  f = fopen(paths[1], "wb");
  REQUIRE(f);
  for (int k = 0; k < 3; k++)
    jsonl_record(f, r.m, r.s[k]);
  fclose(f);
  vd_sim_data* d = vd_sim_data_create(r.m);
  REQUIRE(d);
  for (int p = 0; p < 2; p++) {
    int done = 0;
    for (int64_t budget = 0; budget < 200 && !done; budget++) {
      vd_sim_frames* fr = NULL;
      vd_error e = {0};
      vdt_oom_begin(budget);
      vd_status st = vd_sim_frames_open(paths[p], &fr, &e);
      if (!st) st = vd_sim_frames_load(fr, 2, r.m, d, &e);
      vdt_oom_end();
      CHECK(st == VD_OK || st == VD_ERR_NOMEM);
      done = st == VD_OK;
      vd_sim_frames_close(fr);
    }
    CHECK(done);
  }
  vd_sim_data_destroy(d);
  run3_free(&r);
}

// ---------------------------------------------------------------------------------------------
// moments and stress from a state

TEST(frames, cantilever_moment_and_stress) {
  // a 20 cm rod of radius 2 mm, clamped at x = 0, a 0.01 N tip load down, no gravity: the
  // static moment is M(x) = F (L - x) at every joint, the base stress 4 F L / (pi r^3)
  double L = 0.2, r = 0.002, F = 0.01;
  vd_model* p = cantilever(L, r, 0);
  REQUIRE(p);
  vd_sim_def def = rod_def(0.01, 1e9);
  def.gravity = vd_v3(0, 0, 0);
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(!vd_sim_build(p, &def, &m, &e));
  m->opt.gravity = vd_v3(0, 0, 0);
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  double* mo = malloc(sizeof(double) * 3 * (size_t)m->nseg);
  double* sg = malloc(sizeof(double) * (size_t)m->nseg);
  double* ps = malloc(sizeof(double) * (size_t)p->nseg);
  REQUIRE(mo && sg && ps);
  // at rest: no moment anywhere
  vd_sim_joint_moment(m, d, mo);
  vd_sim_seg_stress(m, d, sg);
  double mx = 0;
  for (int t = 0; t < m->nseg; t++)
    mx = fmax(mx, fabs(mo[3 * t]) + fabs(mo[3 * t + 1]) + fabs(mo[3 * t + 2]) + sg[t]);
  CHECK(mx < 1e-9);
  // loaded: statics
  REQUIRE(m->main_tip >= 0);
  d->node_force[m->main_tip] = vd_v3(0, 0, -F);
  vd_sim_settle_def sd = vd_sim_settle_def_default();
  sd.statics = 1;
  sd.disp_tol = 1e-12;
  int conv = 0;
  vd_sim_settle(m, d, &sd, &conv, NULL);
  CHECK(conv);
  vd_sim_joint_moment(m, d, mo);
  vd_sim_seg_stress(m, d, sg);
  int checked = 0, base = -1;
  double worst = 0;
  for (int t = 0; t < m->nseg; t++) {
    if (m->seg_parent[t] < 0 || (m->seg_flags[t] & VD_SIM_FIXED)) continue;
    double x = m->node_pos0[m->seg_node[2 * t]].x, want = F * (L - x);
    double bend = sqrt(mo[3 * t] * mo[3 * t] + mo[3 * t + 1] * mo[3 * t + 1]);
    worst = fmax(worst, fabs(bend - want) / (F * L));
    CHECK(fabs(mo[3 * t + 2]) < 1e-6 * F * L); // no twist
    if (fabs(x) < 1e-9) base = t;
    checked++;
  }
  CHECK(checked >= 15);
  CHECK(worst < 0.01); // within 1 % of F L at every joint
  REQUIRE(base >= 0);
  double sigma = 4 * F * L / (VD_PI * r * r * r);
  CHECK_NEAR(sg[base], sigma, 0.01 * sigma);
  // per plant segment: the largest of its rod segments; the clamp piece carries the base moment
  vd_sim_plant_stress(m, d, p, ps);
  CHECK_NEAR(ps[1], sigma, 0.01 * sigma);
  CHECK_NEAR(ps[0], sigma, 0.01 * sigma);
  free(mo);
  free(sg);
  free(ps);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(p);
}

TEST(frames, stress_of_broken_and_unbound) {
  // after the fruit breaks off, its joint carries nothing; fruits have no plant segment (NaN)
  run3 r;
  REQUIRE(run3_make(&r));
  double* ps = malloc(sizeof(double) * (size_t)r.plant->nseg);
  double* mo = malloc(sizeof(double) * 3 * (size_t)r.m->nseg);
  REQUIRE(ps && mo);
  vd_sim_joint_moment(r.m, r.s[2], mo);
  for (int t = 0; t < r.m->nseg; t++)
    if (r.s[2]->seg_broken[t]) CHECK(mo[3 * t] == 0 && mo[3 * t + 1] == 0 && mo[3 * t + 2] == 0);
  vd_sim_plant_stress(r.m, r.s[1], r.plant, ps);
  for (int j = 0; j < r.plant->nseg; j++)
    CHECK(isfinite(ps[j]) && ps[j] >= 0);
  CHECK(ps[1] > 0); // the bent rod is stressed
  free(ps);
  free(mo);
  run3_free(&r);
}
