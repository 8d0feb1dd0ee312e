// SPDX-License-Identifier: MIT
// harden: resource limits (derivation work, file size, rod segments), the physics under extreme
// settings (a short version of bench/harden/sim_sweep.c: never a non-finite state, failures
// counted), roots held in the soil, and determinism: hashes of grown plants, clouds and
// simulations compared across runs and across 1 and 2 threads (docs/reliability.md).
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "test.h"
#include "verdant/verdant.h"

// grow a bundled plant (seed, the file's derivation length) and compile it
static vd_model* grow_seed(const char* rel, uint64_t seed) {
  vd_error e = {0};
  vd_lsystem* ls = NULL;
  if (vd_lsys_load(vdt_path(rel), &ls, &e)) return NULL;
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def def = vd_lsys_def_default();
  def.seed = seed;
  vd_model* m = NULL;
  if (s && !vd_lsys_grow(ls, &def, NULL, s, &e)) vd_plant_compile(s, &m, &e);
  vd_lsys_destroy(ls);
  vd_plant_spec_destroy(s);
  return m;
}

// FNV-1a over bytes
static uint64_t fnv(uint64_t h, const void* p, size_t n) {
  const unsigned char* b = p;
  for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ull;
  return h;
}
#define FNV0 1469598103934665603ull

// every number of a rod state finite: positions, velocities, frames, angular velocities
static int sim_finite(const vd_sim_model* m, const vd_sim_data* d) {
  for (int i = 0; i < m->nnode_all; i++) {
    vd_vec3 p = d->node_pos[i], v = d->node_vel[i];
    if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z) || !isfinite(v.x) || !isfinite(v.y) || !isfinite(v.z))
      return 0;
  }
  for (int t = 0; t < m->nseg; t++) {
    vd_quat q = d->seg_quat[t];
    vd_vec3 w = d->seg_omega[t];
    if (!isfinite(q.w + q.x + q.y + q.z) || !isfinite(w.x) || !isfinite(w.y) || !isfinite(w.z)) return 0;
  }
  return 1;
}

// ---------------------------------------------------------------------------------------------
// limits

// a derivation that only lengthens its string: each step reads every module, so many steps
// stop at the work limit instead of running for hours (before: -n 1e9 on the tomato never ended)
TEST(harden, long_derivation_stops_at_work_limit) {
  const char* src = "Axiom: A\nproduction:\nA --> AB\n";
  vd_lsystem* ls = NULL;
  vd_error e = {0};
  REQUIRE(vd_lsys_parse(src, strlen(src), "grow.lpy", &ls, &e) == VD_OK);
  vd_lsys_def def = vd_lsys_def_default();
  def.steps = 1000000000;
  def.max_ops = 1000000;
  vd_lstring out = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, &def, &out, &e), VD_ERR_LIMIT, e);
  CHECK(strstr(e.msg, "modules rewritten") != NULL);
  vd_lstring_free(&out);
  vd_lsys_destroy(ls);
}

// a file larger than VD_FILE_MAX is refused from its size, before anything is read
TEST(harden, huge_file_refused_before_reading) {
  char path[512];
  snprintf(path, sizeof path, "%s/huge.lpy", vdt_tmpdir());
  int fd = open(path, O_CREAT | O_WRONLY | O_TRUNC, 0600);
  REQUIRE(fd >= 0);
  int ok = ftruncate(fd, (off_t)VD_FILE_MAX + 4096) == 0;  // sparse: no disk used
  close(fd);
  REQUIRE(ok);
  char* text = NULL;
  size_t len = 0;
  vd_error e = {0};
  int64_t before = vd_alloc_bytes();
  CHECK_STATUS(vd_file_read(path, &text, &len, &e), VD_ERR_LIMIT, e);
  CHECK(text == NULL && vd_alloc_bytes() == before);
  vd_lsystem* ls = NULL;
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_load(path, &ls, &e2), VD_ERR_LIMIT, e2);
  unlink(path);
}

// the rod model's size: a clear limit from the axes' length before building, and while
// building (leaves and fruits add segments the estimate does not count)
TEST(harden, sim_segment_limit) {
  vd_model* pm = grow_seed("data/arabidopsis.lpy", 0);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  int nseg = m->nseg;
  vd_sim_model_destroy(m);
  // the estimate: absurdly short segments
  def.segment_length = 1e-9;
  vd_error e1 = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e1), VD_ERR_LIMIT, e1);
  CHECK(m == NULL);
  // while building: one segment fewer than the model needs
  double axes = 0;
  for (int t = 0; t < pm->nseg; t++) axes += pm->seg_len0[t];
  def = vd_sim_def_default();
  def.max_segments = nseg - 1;
  CHECK(axes / def.segment_length < def.max_segments);  // the estimate lets it through
  vd_error e2 = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e2), VD_ERR_LIMIT, e2);
  CHECK(m == NULL);
  def.max_segments = 0;
  vd_error e3 = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e3), VD_ERR_VALUE, e3);
  vd_model_destroy(pm);
}

// point and ray counts beyond max_points: a clear limit before the cloud is allocated
TEST(harden, cloud_point_limit) {
  vd_model* pm = grow_seed("data/arabidopsis.lpy", 0);
  REQUIRE(pm);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 2000000000;  // 160 GB
  def.max_points = 50000000;
  vd_cloud c;
  vd_error e = {0};
  int64_t before = vd_alloc_bytes();
  CHECK_STATUS(vd_cloud_sample(pm, NULL, &def, &c, NULL, &e), VD_ERR_LIMIT, e);
  CHECK(vd_alloc_bytes() == before && c.n == 0);
  vd_scanner sc = vd_scanner_default();
  sc.pos = vd_v3(1, 0, 0.2), sc.target = vd_v3(0, 0, 0.1);
  sc.res_h = sc.res_v = 10000;  // 1e8 rays
  def = vd_cloud_def_default();
  def.max_points = 50000000;
  def.sensor = VD_SENSOR_SCAN, def.nscanner = 1, def.scanner = &sc;
  vd_error e2 = {0};
  CHECK_STATUS(vd_cloud_sample(pm, NULL, &def, &c, NULL, &e2), VD_ERR_LIMIT, e2);
  def.max_points = 0;
  vd_error e3 = {0};
  CHECK_STATUS(vd_cloud_sample(pm, NULL, &def, &c, NULL, &e3), VD_ERR_ARG, e3);
  vd_model_destroy(pm);
}

// ---------------------------------------------------------------------------------------------
// physics under extreme settings

// the tree's roots branch from the trunk's pot: every root segment is held (before, the free
// roots sat below the ground plane and the first step threw them out at 1000 m/s)
TEST(harden, sim_tree_roots_held) {
  vd_model* pm = grow_seed("data/tree.lpy", 0);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.1;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  int roots = 0, free_roots = 0;
  for (int t = 0; t < m->nseg; t++)
    if (m->seg_class[t] == VD_SIM_ROOT) roots++, free_roots += !(m->seg_flags[t] & VD_SIM_FIXED);
  CHECK(roots > 10);
  CHECK_INT(free_roots, 0);
  // a few steps on the ground: nothing is thrown about
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  for (int k = 0; k < 5; k++) CHECK(vd_sim_step(m, d) == VD_OK);
  CHECK(vd_sim_max_displacement(m, d, NULL) < 0.01);
  CHECK_INT(d->nwarning, 0);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// the corners of the robustness sweep on the arabidopsis (E 1e6 and 1e11 Pa, density 100 and
// 1500 kg/m^3, dt 1e-4 and 1e-2 s, 1 and 10 iterations, both solvers) under gravity, gusty
// wind and a ground: no step leaves a non-finite number; a step that fails is counted
TEST(harden, sim_sweep_corners_stay_finite) {
  vd_model* pm = grow_seed("data/arabidopsis.lpy", 0);
  REQUIRE(pm);
  static const double young[] = {1e6, 1e11}, rho[] = {100, 1500}, dt[] = {1e-4, 1e-2};
  static const int iters[] = {1, 10};
  int runs = 0, warned = 0;
  for (int a = 0; a < 2; a++)
    for (int b = 0; b < 2; b++)
      for (int c = 0; c < 2; c++)
        for (int k = 0; k < 2; k++)
          for (int s = 0; s < 2; s++) {
            if (s && k) continue;  // Gauss-Seidel with one sweep only (10 sweeps: the benchmark's sweep)
            vd_sim_def def = vd_sim_def_default();
            for (int q = 0; q < VD_SIM_CLASS_COUNT; q++) def.material[q].young = young[a], def.material[q].density = rho[b];
            vd_sim_model* m = NULL;
            vd_error e = {0};
            REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
            m->opt.dt = dt[c];
            m->opt.iterations = iters[k];
            m->opt.solver = s ? VD_SIM_GS : VD_SIM_DIRECT;
            m->opt.wind = vd_v3(5, 0, 0);
            m->opt.gust_amplitude = 0.5, m->opt.gust_period = 0.5;
            vd_sim_data* d = vd_sim_data_create(m);
            REQUIRE(d);
            vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
            vd_sim_add_collider(d, &g);
            int failed = 0, finite = 1;
            for (int n = 0; n < 6; n++) {
              failed += vd_sim_step(m, d) != VD_OK;
              finite &= sim_finite(m, d);
            }
            CHECK(finite);
            CHECK(isfinite(vd_sim_kinetic_energy(m, d)));
            // a failed step is always counted as unstable; the total is the sum of the kinds
            if (failed) CHECK(d->warning[VD_SIM_WARN_UNSTABLE] > 0);
            int64_t sum = 0;
            for (int w = 0; w < VD_SIM_WARN_COUNT; w++) sum += d->warning[w];
            CHECK_INT(sum, d->nwarning);
            runs++;
            warned += d->nwarning > 0;
            vd_sim_data_destroy(d);
            vd_sim_model_destroy(m);
          }
  CHECK_INT(runs, 24);
  CHECK(warned > 0);  // the sweep does reach the settings that need retaking
  vd_model_destroy(pm);
}

// a step that exploded before (soft, light plant at dt 1e-2 s, one Newton iteration): retaken
// in halves it stays on the plant's scale (before: 1e125 m after 48 steps)
TEST(harden, sim_retake_keeps_soft_plant_bounded) {
  vd_model* pm = grow_seed("data/arabidopsis.lpy", 0);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  for (int q = 0; q < VD_SIM_CLASS_COUNT; q++) def.material[q].young = 1e6, def.material[q].density = 100;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  m->opt.dt = 1e-2;
  m->opt.wind = vd_v3(5, 0, 0);
  m->opt.gust_amplitude = 0.5, m->opt.gust_period = 0.5;
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  for (int n = 0; n < 50; n++) vd_sim_step(m, d);
  CHECK(sim_finite(m, d));
  CHECK(vd_sim_max_displacement(m, d, NULL) < 1.0);  // the plant is 0.3 m tall
  CHECK(d->nwarning > 0);  // the trouble is counted (stretched steps, retakes)
  CHECK(d->time > 0.25);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// ---------------------------------------------------------------------------------------------
// determinism: the same seed gives the same bytes, across runs and thread counts

// hash of a plant written as plant JSON (the bytes a user gets from `verdant grow -o x.json`)
static uint64_t plant_hash(const char* rel, uint64_t seed) {
  vd_error e = {0};
  vd_lsystem* ls = NULL;
  if (vd_lsys_load(vdt_path(rel), &ls, &e)) return 0;
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def def = vd_lsys_def_default();
  def.seed = seed;
  uint64_t h = 0;
  char path[512];
  snprintf(path, sizeof path, "%s/det_%llu.json", vdt_tmpdir(), (unsigned long long)seed);
  if (s && !vd_lsys_grow(ls, &def, NULL, s, &e) && !vd_plant_write_json(s, path, &e)) {
    char* text;
    size_t len;
    if (!vd_file_read(path, &text, &len, &e)) {
      h = fnv(FNV0, text, len);
      vd_free(text, len + 1);
    }
  }
  unlink(path);
  vd_lsys_destroy(ls);
  vd_plant_spec_destroy(s);
  return h;
}

TEST(harden, determinism_grown_plants) {
  // stochastic plants: the same seed twice gives the same file, another seed another one
  static const char* plants[] = {"data/tomato.lpy", "data/arabidopsis.lpy", "data/lilac.lpy"};
  for (int p = 0; p < 3; p++) {
    uint64_t a = plant_hash(plants[p], 7), b = plant_hash(plants[p], 7), c = plant_hash(plants[p], 8);
    CHECK(a != 0);
    CHECK(a == b);
    CHECK(a != c);
  }
}

// hash of every array of a cloud
static uint64_t cloud_hash(const vd_cloud* c) {
  uint64_t h = fnv(FNV0, &c->n, sizeof c->n);
  h = fnv(h, c->pos, 3 * sizeof(double) * (size_t)c->n);
  h = fnv(h, c->normal, 3 * sizeof(double) * (size_t)c->n);
  h = fnv(h, c->label, sizeof(int) * (size_t)c->n);
  h = fnv(h, c->instance, sizeof(int) * (size_t)c->n);
  h = fnv(h, c->view, sizeof(int) * (size_t)c->n);
  return fnv(h, c->range, sizeof(double) * (size_t)c->n);
}

TEST(harden, determinism_clouds_across_threads) {
  vd_model* pm = grow_seed("data/tomato.lpy", 3);
  REQUIRE(pm);
  // a surface cloud with noise and a scan with occlusion, each on 1 and 2 threads, twice
  vd_scanner sc = vd_scanner_default();
  sc.pos = vd_v3(1.5, -1.0, 0.8), sc.target = vd_v3(0, 0, 0.6);
  sc.res_h = 320, sc.res_v = 240;  // 19 chunks of rays
  for (int mode = 0; mode < 2; mode++) {
    uint64_t h[3];
    for (int r = 0; r < 3; r++) {
      vd_cloud_def def = vd_cloud_def_default();
      def.seed = 11;
      def.points = 20000;  // 5 chunks: the threads share them
      def.noise_sigma = 0.001;
      if (mode) def.sensor = VD_SENSOR_SCAN, def.occlusion = 1, def.nscanner = 1, def.scanner = &sc;
      def.threads = r == 1 ? 2 : 1;
      vd_cloud c;
      vd_error e = {0};
      REQUIRE(vd_cloud_sample(pm, NULL, &def, &c, NULL, &e) == VD_OK);
      CHECK(c.n > 1000);
      h[r] = cloud_hash(&c);
      vd_cloud_free(&c);
    }
    CHECK(h[0] == h[1]);
    CHECK(h[0] == h[2]);
  }
  vd_model_destroy(pm);
}

// hash of a rod state's positions and frames
static uint64_t sim_hash(const vd_sim_model* m, const vd_sim_data* d) {
  uint64_t h = fnv(FNV0, d->node_pos, sizeof(vd_vec3) * (size_t)m->nnode_all);
  h = fnv(h, d->seg_quat, sizeof(vd_quat) * (size_t)m->nseg);
  return fnv(h, &d->nevent, sizeof d->nevent);
}

TEST(harden, determinism_simulations_across_threads) {
  vd_model* pm = grow_seed("data/tomato.lpy", 0);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  m->opt.wind = vd_v3(4, 1, 0);
  m->opt.gust_amplitude = 0.3;
  // four states of one model: two stepped one after the other, two at once on two threads
  // (one model drives many states; nothing is shared between them)
  uint64_t h[4] = {0, 0, 0, 0};
#ifdef _OPENMP
#pragma omp parallel for num_threads(2) schedule(static, 1)
#endif
  for (int k = 0; k < 4; k++) {
    vd_sim_data* d = vd_sim_data_create(m);
    if (!d) continue;
    vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    vd_sim_add_collider(d, &g);
    for (int n = 0; n < 60; n++) vd_sim_step(m, d);
    h[k] = sim_hash(m, d);
    vd_sim_data_destroy(d);
  }
  CHECK(h[0] != 0);
  CHECK(h[0] == h[1] && h[0] == h[2] && h[0] == h[3]);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// ---------------------------------------------------------------------------------------------
// wind time series files (vd_sim_parse_wind; also the fuzz_wind target)

TEST(harden, wind_series_parse) {
  const char* ok = "t,vx,vy,vz\r\n# gusts\n0,1,0,0\n  0.5 , 2,0,0\r\n\n1,3,-1,0.5\n";
  double* rows = NULL;
  int n = 0;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_parse_wind(ok, strlen(ok), "w.csv", &rows, &n, &e), VD_OK, e);
  CHECK_INT(n, 3);
  if (n == 3) CHECK(rows[4] == 0.5 && rows[5] == 2 && rows[10] == -1 && rows[11] == 0.5);
  vd_free(rows, (size_t)n * 4 * sizeof(double));
  // each bad row names its line and column
  static const struct {
    const char* text;
    vd_status st;
    int line, col;
  } bad[] = {
      {"0,1,0,0\n1,2,0\n", VD_ERR_FORMAT, 2, 6},           // a component missing
      {"0,1,0,0\n1,2,0,0,5\n", VD_ERR_FORMAT, 2, 8},       // one too many
      {"0,1,0,0\n1,nan,0,0\n", VD_ERR_FORMAT, 2, 3},       // not finite
      {"0,1,0,0\n1,inf,0,0\n", VD_ERR_FORMAT, 2, 3},
      {"0,1e300,0,0\n", VD_ERR_FORMAT, 1, 3},              // beyond +-1000 m/s
      {"0,1,0,0\n2,1,0,0\n1,1,0,0\n", VD_ERR_FORMAT, 3, 1}, // time backwards
      {"0,1,0,0\n1,x,0,0\n", VD_ERR_FORMAT, 2, 3},         // not a number
      {"t,vx,vy,vz\n", VD_ERR_FORMAT, 0, 0},               // no rows
      {"", VD_ERR_FORMAT, 0, 0},                           // empty
      {"0,1,0\0,0\n", VD_ERR_FORMAT, 1, 6},                // binary
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    vd_error eb = {0};
    size_t len = k == 9 ? 10 : strlen(bad[k].text);
    CHECK_STATUS(vd_sim_parse_wind(bad[k].text, len, "w.csv", &rows, &n, &eb), bad[k].st, eb);
    CHECK_INT(eb.line, bad[k].line);
    CHECK_INT(eb.col, bad[k].col);
    CHECK(rows == NULL && n == 0);
  }
  // out of memory at every allocation: a status, nothing kept
  const char* many = "0,1,0,0\n1,1,0,0\n2,1,0,0\n3,1,0,0\n4,1,0,0\n5,1,0,0\n6,1,0,0\n7,1,0,0\n8,1,0,0\n9,1,0,0\n";
  for (int budget = 0; budget < 12; budget++) {
    vd_error eo = {0};
    vdt_oom_begin(budget);
    vd_status st = vd_sim_parse_wind(many, strlen(many), "w.csv", &rows, &n, &eo);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    if (!st) vd_free(rows, (size_t)n * 4 * sizeof(double));
  }
}
