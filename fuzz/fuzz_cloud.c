// SPDX-License-Identifier: MIT
// libFuzzer target: the point-cloud readers (PLY, PCD, XYZ, CSV, LAS) and scanner presets. The
// first byte picks the parser, the rest is the file; a cloud that parses is relabelled by
// instance, which walks every point again.
#include "fuzz_common.h"
#include "verdant/cloud.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

FUZZ_DEFAULT_INITIALIZE

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  int kind = data[0] % 6;
  const char* text = (const char*)data + 1;
  size_t len = size - 1;
  if (kind < 5) {
    static const vd_cloud_format fmt[5] = {VD_CLOUD_PLY, VD_CLOUD_PCD, VD_CLOUD_XYZ, VD_CLOUD_CSV,
                                           VD_CLOUD_LAS};
    vd_cloud c;
    if (vd_cloud_parse(text, len, fmt[kind], "fuzz", &c, &err) == VD_OK) {
      // a read cloud is consistent: n points, every array there
      if (c.n > 0 && (!c.pos || !c.normal || !c.label || !c.instance || !c.view || !c.range)) abort();
      vd_error e2 = {0};
      (void)vd_cloud_relabel(&c, &e2);
      vd_cloud_free(&c);
    }
  } else {
    vd_scanner* sc = NULL;
    int n = 0;
    if (vd_cloud_parse_scanners(text, len, "fuzz.json", vd_v3(-1, -1, 0), vd_v3(1, 1, 2), &sc, &n,
                                &err) == VD_OK) {
      if (n < 1 || !sc) abort();
      vd_free(sc, (size_t)n * sizeof *sc);
    }
  }
  fuzz_check_leak(before, "cloud");
  return 0;
}
