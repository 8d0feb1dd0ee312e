// SPDX-License-Identifier: MIT
// Example: grow an .lpy plant with the library, compile it, and list its organs by label.
//   build/example_grow data/tomato.lpy 3
#include <stdio.h>
#include <stdlib.h>

#include "verdant/verdant.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s PLANT.lpy [SEED]\n", argv[0]);
    return 2;
  }
  vd_error err = {0};
  char msg[1024];
  vd_lsystem* ls;
  if (vd_lsys_load(argv[1], &ls, &err)) {
    fprintf(stderr, "%s\n", vd_error_format(&err, msg, sizeof msg));
    return 2;
  }
  // derive with a seed, interpret and run the turtle in one call
  vd_lsys_def def = vd_lsys_def_default();
  def.seed = argc > 2 ? strtoull(argv[2], NULL, 10) : 0;
  vd_plant_spec* plant = vd_plant_spec_create();
  vd_status st = vd_lsys_grow(ls, &def, NULL, plant, &err);
  vd_lsys_destroy(ls);
  // compile: a const model and a state that starts at the rest shape
  vd_model* m = NULL;
  if (!st) st = vd_plant_compile(plant, &m, &err);
  vd_plant_spec_destroy(plant);
  if (st) {
    fprintf(stderr, "%s\n", vd_error_format(&err, msg, sizeof msg));
    return 2;
  }
  vd_data* d = vd_data_create(m);
  printf("%d nodes, %d segments, %d spheres, %d meshes, %d organ instances\n", m->nnode, m->nseg,
         m->nsphere, m->nmesh, m->ninstance);
  for (int l = 0; l < m->nlabel; l++) {
    int nseg = 0, nsph = 0, nmesh = 0;
    for (int i = 0; i < m->nseg; i++) nseg += m->seg_label[i] == m->labels[l].id;
    for (int i = 0; i < m->nsphere; i++) nsph += m->sphere_label[i] == m->labels[l].id;
    for (int i = 0; i < m->nmesh; i++) nmesh += m->mesh_label[i] == m->labels[l].id;
    printf("  label %d %-10s (%s): %d segments, %d spheres, %d meshes\n", m->labels[l].id, m->labels[l].name,
           vd_organ_name(m->labels[l].organ), nseg, nsph, nmesh);
  }
  vd_data_destroy(d);
  vd_model_destroy(m);
  return 0;
}
