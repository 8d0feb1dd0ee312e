// SPDX-License-Identifier: MIT
// Writes the plant JSON seeds of fuzz/corpus/fuzz_plant_json/ with the library's own writer,
// so the seeds follow the current schema. Build and run by hand:
//   cc -Iinclude fuzz/make_seeds.c src/*/*.c $(pkg-config --cflags --libs libcjson) -lm -o /tmp/s
//   /tmp/s fuzz/corpus/fuzz_plant_json
#include <stdio.h>

#include "verdant/verdant.h"

// the plant of tests/test_plant.c: a two-segment generalised cylinder, a sphere and a leaf
static vd_plant_spec* small_plant(void) {
  vd_plant_spec* s = vd_plant_spec_create();
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int b = vd_plant_add_node(s, vd_v3(0, 0, 1));
  int c = vd_plant_add_node(s, vd_v3(0, 0.5, 1.5));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = 0.1, g.r1 = 0.08, g.label = 1, g.instance = 1;
  g.flags = VD_SEG_GC, g.module = 3, g.age = 1.25;
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.r0 = 0.08, g.r1 = 0.05, g.parent = s0;
  g.flags = VD_SEG_GC | VD_SEG_TIP, g.up = vd_v3(0.1, 0.2, 0.3), g.module = 4, g.slices = 6;
  int s1 = vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0, 0.5, 1.7), f.radius = 0.2, f.node = c, f.parent = s1, f.label = 3;
  f.instance = 7, f.module = 9;
  vd_plant_add_sphere(s, &f);
  vd_mesh_spec m = {0};
  m.node = b, m.parent = s0, m.label = 2, m.instance = 4, m.module = -1;
  vd_vec3 v[4] = {{0, 0, 1}, {0.3, 0, 1}, {0.3, 0.1, 1.1}, {0, 0.1, 1.1}};
  int t[6] = {0, 1, 2, 0, 2, 3};
  vd_plant_add_mesh(s, &m, v, 4, t, 2);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 2, "leaf");
  return s;
}

// a branching tree: a main axis of n segments with a lateral and a closed box on each node
static vd_plant_spec* tree(int n) {
  vd_plant_spec* s = vd_plant_spec_create();
  int prev = vd_plant_add_node(s, vd_v3(0, 0, 0)), pseg = -1;
  for (int i = 0; i < n; i++) {
    int nx = vd_plant_add_node(s, vd_v3(0, 0, 0.1 * (i + 1)));
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = prev, g.node1 = nx, g.parent = pseg, g.label = 1, g.instance = 1, g.slices = 5;
    g.flags = VD_SEG_GC | (i == n - 1 ? VD_SEG_TIP : 0);
    int sg = vd_plant_add_segment(s, &g);
    int lat = vd_plant_add_node(s, vd_v3(0.05, 0, 0.1 * (i + 1) + 0.03));
    g.node0 = nx, g.node1 = lat, g.parent = sg, g.order = 1, g.axis = i + 1, g.flags = VD_SEG_TIP;
    g.instance = i + 2, g.r0 = 0.02, g.r1 = 0.01;
    vd_plant_add_segment(s, &g);
    if (i % 2 == 0) {
      vd_mesh_spec m = {0};
      m.closed = 1, m.node = nx, m.parent = sg, m.label = 4, m.instance = 100 + i, m.module = i;
      vd_vec3 v[4] = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, 0.01}};
      int t[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
      vd_plant_add_mesh(s, &m, v, 4, t, 4);
    }
    prev = nx, pseg = sg;
  }
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 4, "fruit");
  return s;
}

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  char path[4096];
  vd_error err = {0};
  vd_plant_spec* plants[4] = {small_plant(), tree(3), tree(12), vd_plant_spec_create()};
  const char* names[4] = {"small", "tree3", "tree12", "empty"};
  int rc = 0;
  for (int i = 0; i < 4; i++) {
    snprintf(path, sizeof path, "%s/%s.json", argv[1], names[i]);
    if (vd_plant_write_json(plants[i], path, &err) != VD_OK) rc = 1;
    vd_plant_spec_destroy(plants[i]);
  }
  return rc;
}
