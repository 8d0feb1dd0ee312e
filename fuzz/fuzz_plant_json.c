// SPDX-License-Identifier: MIT
// libFuzzer target: plant JSON through parse, compile and tessellation. The mesh size is
// counted first; a plant whose mesh would exceed FUZZ_MAX_VERT vertices is tessellated with 3
// slices, and skipped if even that is too large, so a valid but huge plant cannot OOM.
#include "fuzz_common.h"
#include "verdant/geom.h"

#define FUZZ_MAX_VERT 200000  // largest mesh tessellated per input (vertices)

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

FUZZ_DEFAULT_INITIALIZE

// tessellate with def when the counted mesh is small enough; returns 1 when it was
static int tessellate_capped(const vd_model* m, const vd_data* d, const vd_mesh_def* def) {
  int nv = 0, nt = 0;
  vd_error err = {0};
  if (vd_geom_count(m, d, def, &nv, &nt, &err) != VD_OK) return 1;
  if (nv > FUZZ_MAX_VERT || nt > 2 * FUZZ_MAX_VERT) return 0;
  vd_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  if (vd_geom_tessellate(m, d, def, &mesh, &err) == VD_OK) {
    // the counts promised must be the counts delivered
    if (mesh.nvert != nv || mesh.ntri != nt) {
      fprintf(stderr, "fuzz: geom_count %d/%d but tessellate %d/%d\n", nv, nt, mesh.nvert,
              mesh.ntri);
      abort();
    }
    vd_mesh_free(&mesh);
  }
  return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_plant_spec* s = NULL;
  if (vd_plant_parse_json((const char*)data, size, "fuzz.json", &s, &err) == VD_OK) {
    vd_model* m = NULL;
    if (vd_plant_compile(s, &m, &err) == VD_OK) {
      // rest shape with each primitive's slices, or 3 slices when that is too large
      vd_mesh_def def = vd_mesh_def_default();
      if (!tessellate_capped(m, NULL, &def)) {
        def.slices = 3;
        def.sphere_stacks = 2;
        (void)tessellate_capped(m, NULL, &def);
      }
      // a state at the rest shape goes through the same path
      vd_data* d = vd_data_create(m);
      if (d) {
        def = vd_mesh_def_default();
        def.slices = 3;
        def.sphere_stacks = 2;
        (void)tessellate_capped(m, d, &def);
        vd_data_destroy(d);
      }
      vd_model_destroy(m);
    }
    vd_plant_spec_destroy(s);
  }
  fuzz_check_leak(before, "plant_json");
  return 0;
}
