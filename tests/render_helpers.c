// SPDX-License-Identifier: MIT
// Helpers shared by the render tests (render_helpers.h).
#include "render_helpers.h"

#include "test.h"

vd_renderer* vdt_renderer(vd_render_def* def) {
  vd_renderer* r = NULL;
  vd_error err = {0};
  vd_status st = vd_render_create(def, &r, &err);
  if (st == VD_ERR_UNSUPPORTED) {
    char buf[1024];
    fprintf(stderr, "  skip: %s\n", vd_error_format(&err, buf, sizeof buf));
    return NULL;
  }
  CHECK_STATUS(st, VD_OK, err);
  return r;
}

vd_render_def vdt_small_def(int w, int h) {
  vd_render_def d = vd_render_def_default();
  d.width = w, d.height = h, d.supersample = 1, d.shadows = 0, d.legend = 0;
  return d;
}

vd_model* vdt_quad_plant(const vd_vec3 v[4], int label, int instance) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  vd_mesh_spec m = {0};
  m.label = label, m.instance = instance, m.node = -1, m.parent = -1, m.module = -1;
  int t[6] = {0, 1, 2, 0, 2, 3};
  vd_plant_add_mesh(s, &m, v, 4, t, 2);
  vd_plant_set_label(s, label, "leaf");
  return vdt_compile(s);
}

vd_model* vdt_tomato(uint64_t seed) {
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  if (vd_lsys_load(vdt_path("data/tomato.lpy"), &ls, &err)) return NULL;
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def def = vd_lsys_def_default();
  def.seed = seed;
  vd_model* m = NULL;
  if (s && !vd_lsys_grow(ls, &def, NULL, s, &err)) vd_plant_compile(s, &m, &err);
  vd_plant_spec_destroy(s);
  vd_lsys_destroy(ls);
  return m;
}
