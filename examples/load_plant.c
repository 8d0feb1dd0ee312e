// SPDX-License-Identifier: MIT
// Example: make a plant from any file verdant accepts (an .lpy file, a plant file, a curves
// file) with the library's one loader, and write it as a plant file.
//   build/example_load data/tomato.lpy tomato.json [modules|organs]
#include <stdio.h>
#include <string.h>

#include "verdant/verdant.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: %s PLANT OUT.json [modules|organs]\n", argv[0]);
    return 2;
  }
  vd_plant_load_def def = vd_plant_load_def_default();
  if (argc > 3) def.instances = strcmp(argv[3], "modules") ? VD_INSTANCE_ORGANS : VD_INSTANCE_MODULES;
  vd_error err = {0};
  char msg[1024];
  vd_plant_spec* plant = NULL;
  vd_status st = vd_plant_load(argv[1], &def, &plant, NULL, &err);
  if (!st) st = vd_plant_write_json(plant, argv[2], &err);
  vd_plant_spec_destroy(plant);
  if (st) {
    fprintf(stderr, "%s\n", vd_error_format(&err, msg, sizeof msg));
    return 2;
  }
  return 0;
}
