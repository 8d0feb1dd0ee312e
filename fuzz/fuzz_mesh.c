// SPDX-License-Identifier: MIT
// libFuzzer target: the mesh readers (OBJ, PLY ASCII and binary). The first byte picks the
// parser, the rest is the file; a mesh that parses is checked for consistency (indices in range,
// finite positions, unit or zero normals) and its label table for sorted ids.
#include <math.h>

#include "fuzz_common.h"
#include "verdant/geom.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

FUZZ_DEFAULT_INITIALIZE

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_mesh m;
  vd_label* lab = NULL;
  int nlab = 0;
  if (vd_geom_parse_mesh((const char*)data + 1, size - 1, data[0] & 1, "fuzz", &m, &lab, &nlab,
                         &err) == VD_OK) {
    if (m.ntri < 1 || m.nvert < 1) abort();
    for (int t = 0; t < 3 * m.ntri; t++)
      if (m.tri[t] < 0 || m.tri[t] >= m.nvert) abort();
    for (int i = 0; i < m.nvert; i++) {
      double l = 0;
      for (int k = 0; k < 3; k++) {
        if (!isfinite(m.pos[3 * i + k])) abort();
        l += m.normal[3 * i + k] * m.normal[3 * i + k];
      }
      if (l != 0 && fabs(l - 1) > 1e-6) abort();
    }
    for (int i = 1; i < nlab; i++)
      if (lab[i].id <= lab[i - 1].id) abort();
    vd_mesh_free(&m);
    vd_free(lab, sizeof(vd_label) * (size_t)(nlab ? nlab : 1));
  }
  fuzz_check_leak(before, "mesh");
  return 0;
}
