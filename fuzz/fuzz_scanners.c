// SPDX-License-Identifier: MIT
// libFuzzer target: scanner presets (--scanners FILE). A preset that parses scans a small
// plant (a stem and a sphere) with the scan sensor, and again with the distance sensor,
// occlusion and noise, limited to FUZZ_MAX_POINTS points or rays (larger presets must fail
// with VD_ERR_LIMIT, not allocate).
#include "fuzz_common.h"
#include "verdant/cloud.h"

#define FUZZ_MAX_POINTS 20000

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static vd_model* plant;

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  fuzz_install_allocator();
  vd_set_assert_handler(fuzz_assert);
  vd_plant_spec* s = vd_plant_spec_create();
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0.3));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = 0.01, g.r1 = 0.005, g.label = 1, g.instance = 1;
  int t = vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0, 0, 0.32), f.radius = 0.03, f.parent = t, f.label = 2, f.instance = 2;
  vd_plant_add_sphere(s, &f);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 2, "fruit");
  vd_error e = {0};
  if (vd_plant_compile(s, &plant, &e) != VD_OK) abort();
  vd_plant_spec_destroy(s);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_scanner* sc = NULL;
  int n = 0;
  if (vd_cloud_parse_scanners((const char*)data, size, "fuzz.json", vd_v3(-0.03, -0.03, 0), vd_v3(0.03, 0.03, 0.35),
                              &sc, &n, &err) == VD_OK) {
    if (n < 1 || !sc) abort();
    for (int mode = 0; mode < 2; mode++) {
      vd_cloud_def def = vd_cloud_def_default();
      def.max_points = FUZZ_MAX_POINTS;
      def.threads = 1;
      def.nscanner = n;
      def.scanner = sc;
      def.max_attempts = 1000;
      if (mode == 0) {
        def.sensor = VD_SENSOR_SCAN;
      } else {
        def.sensor = VD_SENSOR_DISTANCE;
        def.points = 2000;
        def.occlusion = 1;
        def.noise_sigma = 0.001, def.noise_slope = 0.001;
      }
      vd_cloud c;
      vd_error e2 = {0};
      if (vd_cloud_sample(plant, NULL, &def, &c, NULL, &e2) == VD_OK) {
        if (c.n > FUZZ_MAX_POINTS) abort();
        vd_cloud_free(&c);
      }
    }
    vd_free(sc, (size_t)n * sizeof *sc);
  } else if (sc || n) {
    abort();
  }
  fuzz_check_leak(before, "scanners");
  return 0;
}
