// SPDX-License-Identifier: MIT
// verdant geom: tessellation of a compiled plant into a labelled triangle mesh, and mesh export
// (OBJ + MTL, PLY; conventions in docs/formats.md).
//
// vd_geom_tessellate reads a model and one of its states (or the rest shape) and fills a
// vd_mesh that the caller owns and frees with vd_mesh_free; every triangle carries the label,
// organ instance and primitive it came from. Closed primitives (frustums with caps, spheres,
// closed meshes) come out watertight and counter-clockwise seen from outside. Frustum side and
// cap vertices are separate (sharp normals); segments of one generalised cylinder (VD_SEG_GC)
// share the ring at their joint, so the tube is smooth and closed as a whole; a segment marked
// broken in the state (seg_broken) is cut from its parent there and both pieces get caps.
//
// Usage:
//   vd_mesh mesh; vd_error err = {0};
//   vd_mesh_def def = vd_mesh_def_default(); def.slices = 12;
//   if (vd_geom_tessellate(model, data, &def, &mesh, &err) == VD_OK) {
//     vd_geom_write_obj(&mesh, model->labels, model->nlabel, "plant.obj", &err);
//     vd_mesh_free(&mesh);
//   }
#ifndef VERDANT_GEOM_H
#define VERDANT_GEOM_H

#include "verdant/core.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_MESH_FORMAT_VERSION 1 // version of the OBJ/PLY mesh conventions (docs/formats.md)

// Which kind of plant primitive a triangle was made from.
typedef enum vd_prim_kind {
  VD_PRIM_SEGMENT = 0, // frustum between two nodes
  VD_PRIM_SPHERE = 1,  // sphere
  VD_PRIM_MESH = 2,    // triangle mesh of the spec
} vd_prim_kind;

// Tessellation settings.
typedef struct vd_mesh_def {
  int slices;        // sides of every frustum and longitudes of every sphere (>= 3), or 0 to use
                     // each primitive's own slices; default 0
  int sphere_stacks; // latitude bands of spheres (>= 2), or 0 for max(2, slices / 2); default 0
  int caps;          // 1 closes frustum ends with flat caps (watertight), 0 leaves them open;
                     // default 1
} vd_mesh_def;

// Defaults: slices 0 (per primitive), sphere_stacks 0 (slices / 2), caps 1.
vd_mesh_def vd_mesh_def_default(void);

// A labelled triangle mesh. Arrays live in one block owned by the mesh (vd_mesh_free).
typedef struct vd_mesh {
  int nvert, ntri;   // sizes
  double* pos;       // vertex position (m) (nvert x 3)
  double* normal;    // unit vertex normal, outward (nvert x 3)
  int* tri;          // vertex indices, counter-clockwise seen from outside (ntri x 3)
  int* tri_label;    // semantic label id (ntri x 1)
  int* tri_instance; // organ instance id (ntri x 1)
  int* tri_prim;     // index of the primitive within its kind (segment, sphere or mesh) (ntri x 1)
  int* tri_kind;     // vd_prim_kind of that primitive (ntri x 1)
  size_t nbytes;     // size of the single allocation (0 when empty)
} vd_mesh;

// Exact vertex and triangle counts vd_geom_tessellate would produce (def Nullable: defaults).
vd_status vd_geom_count(const vd_model* m, const vd_data* d, const vd_mesh_def* def, int* nvert,
                        int* ntri, vd_error* err);
// Tessellate state d (Nullable: the rest shape) of model m into out (def Nullable: defaults).
vd_status vd_geom_tessellate(const vd_model* m, const vd_data* d, const vd_mesh_def* def,
                             vd_mesh* out, vd_error* err);
// Free a mesh's arrays and zero it (NULL and empty meshes are fine).
void vd_mesh_free(vd_mesh* mesh);

// Write OBJ with normals plus a sibling .mtl (same base name), faces grouped by label/instance.
vd_status vd_geom_write_obj(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                            const char* path, vd_error* err);
// Write PLY (binary little-endian when binary is 1, else ASCII) with face label and instance.
vd_status vd_geom_write_ply(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                            const char* path, int binary, vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
