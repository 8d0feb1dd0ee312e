// SPDX-License-Identifier: MIT
// Writing a plant by the output file's extension: plant JSON, OBJ (+MTL) or PLY mesh.
#include "cli.h"

vd_status cli_write_plant(const vd_plant_spec* plant, const char* path, int ascii, vd_error* err) {
  (void)ascii;
  if (cli_has_ext(path, ".json")) return vd_plant_write_json(plant, path, err);
  return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "mesh output is not available in this build");
}
