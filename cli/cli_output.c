// SPDX-License-Identifier: MIT
// Writing a plant by the output file's extension: plant JSON, OBJ (+MTL) or PLY mesh.
#include <string.h>

#include "cli.h"

static vd_status write_plant(const vd_plant_spec* plant, const char* path, int ascii, vd_error* err) {
  if (cli_has_ext(path, ".json")) return vd_plant_write_json(plant, path, err);
  // meshes: compile, tessellate the rest shape, write with the label table
  vd_model* m = NULL;
  vd_status st = vd_plant_compile(plant, &m, err);
  if (st) return st;
  vd_mesh mesh;
  st = vd_geom_tessellate(m, NULL, NULL, &mesh, err);
  if (!st) {
    if (cli_has_ext(path, ".obj")) {
      st = vd_geom_write_obj(&mesh, m->labels, m->nlabel, path, err);
    } else if (vd_plant_has_stress(plant)) {
      // a simulated plant's stress (Pa) on every vertex
      double* val = vd_malloc(sizeof(double) * (size_t)(mesh.nvert ? mesh.nvert : 1));
      if (!val) {
        st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
      } else {
        vd_geom_vertex_values(m, NULL, &mesh, plant->node_stress, plant->seg_stress, val);
        st = vd_geom_write_ply_values(&mesh, m->labels, m->nlabel, val, "stress", path, !ascii, err);
        vd_free(val, sizeof(double) * (size_t)(mesh.nvert ? mesh.nvert : 1));
      }
    } else {
      st = vd_geom_write_ply(&mesh, m->labels, m->nlabel, path, !ascii, err);
    }
    vd_mesh_free(&mesh);
  }
  vd_model_destroy(m);
  return st;
}

int cli_plant_files(const char* path, char files[2][4200]) {
  size_t n = strlen(path);
  snprintf(files[0], 4200, "%s", path);
  if (!cli_has_ext(path, ".obj")) return 1;
  snprintf(files[1], 4200, "%.*s.mtl", (int)(n - 4), path);
  return 2;
}

void cli_out_plant(const char* what, const char* path) {
  char files[2][4200];
  int nf = cli_plant_files(path, files);
  for (int k = 0; k < nf; k++) cli_out_file(what, files[k]);
}

vd_status cli_write_plant(const vd_plant_spec* plant, const char* path, int ascii, vd_error* err) {
  return write_plant(plant, path, ascii, err);
}
