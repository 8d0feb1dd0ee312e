// SPDX-License-Identifier: MIT
// libFuzzer target: curves JSON through parse, build (sampling, connection, simplification,
// leaves and fruits) and compile. The dense sampling is capped so that a valid file with a tiny
// sample_step or huge curves cannot take seconds per input.
#include "fuzz_common.h"

#define FUZZ_MAX_SAMPLES 200000  // most dense samples per input

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

FUZZ_DEFAULT_INITIALIZE

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_curves* c = NULL;
  if (vd_curves_parse((const char*)data, size, "fuzz.json", &c, &err) == VD_OK) {
    vd_curves_def def = vd_curves_file_def(c);
    def.max_samples = FUZZ_MAX_SAMPLES;
    vd_plant_spec* s = vd_plant_spec_create();
    vd_curves_stats st;
    if (s && vd_curves_build(c, &def, s, &st, &err) == VD_OK) {
      // what the build reports is what it made, and the plant is valid
      if (st.nseg != s->nseg || st.nnode != s->nnode || st.nconnect != st.ncurve - 1) {
        fprintf(stderr, "fuzz: curves stats %d/%d/%d disagree with the spec %d/%d\n", st.nseg,
                st.nnode, st.nconnect, s->nseg, s->nnode);
        abort();
      }
      vd_model* m = NULL;
      vd_error e2 = {0};
      if (vd_plant_compile(s, &m, &e2) != VD_OK) {
        fprintf(stderr, "fuzz: a built curves plant does not compile: %s\n", e2.msg);
        abort();
      }
      vd_model_destroy(m);
    }
    vd_plant_spec_destroy(s);
    vd_curves_destroy(c);
  }
  fuzz_check_leak(before, "curves");
  return 0;
}
