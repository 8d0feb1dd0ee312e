// SPDX-License-Identifier: MIT
// verdant geom: tessellation of a compiled plant into a labelled triangle mesh, mesh export
// (OBJ + MTL, PLY; conventions in docs/formats.md), a bounding volume hierarchy with ray casting,
// and point-inside tests for the plant's closed primitives.
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
//
// Rays and solids (the caller owns both and frees them; neither keeps a pointer to its inputs):
//   vd_bvh bvh; vd_bvh_build_mesh(&mesh, NULL, NULL, &bvh, &err);
//   vd_hit hit; if (vd_bvh_raycast(&bvh, origin, dir, 0, INFINITY, 0, -1, &hit)) ... hit.label
//   vd_solids so; vd_solids_build(model, data, &def, &so, &err);
//   if (vd_solids_inside(&so, p, VD_PRIM_MESH, leaf) >= 0) ... p is inside another organ
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
// Tessellate state d (Nullable: the rest shape) of model m into mesh (def Nullable: defaults).
vd_status vd_geom_tessellate(const vd_model* m, const vd_data* d, const vd_mesh_def* def,
                             vd_mesh* mesh, vd_error* err);
// Free a mesh's arrays and zero it (NULL and empty meshes are fine).
void vd_mesh_free(vd_mesh* mesh);

// Read a triangle mesh from an .obj or .ply file: the files vd_geom_write_obj / _ply write (label
// table from the header comments, label and instance per face from the OBJ objects and groups or
// the PLY face properties) and meshes from other tools (OBJ groups or materials become labels 1,
// 2, ... named after them and objects instances 1, 2, ...; faces before any group have label 0;
// PLY faces without label or instance properties have 0). Polygons become fans of triangles;
// normals are the file's (per vertex) or else summed from the faces around a vertex; tri_kind is
// VD_PRIM_MESH and tri_prim 0. labels (Nullable) receives the label table sorted by id (nlabel
// entries; free with vd_free(*labels, max(nlabel, 1) * sizeof(vd_label))). Errors name the file
// and the line (or the byte for binary PLY); VD_ERR_FORMAT for a PLY without faces.
vd_status vd_geom_read_mesh(const char* path, vd_mesh* mesh, vd_label** labels, int* nlabel,
                            vd_error* err);
// The same from memory: obj 1 for OBJ text, 0 for PLY; name (Nullable) is used in errors.
vd_status vd_geom_parse_mesh(const char* data, size_t len, int obj, const char* name,
                             vd_mesh* mesh, vd_label** labels, int* nlabel, vd_error* err);
// 1 when path names a mesh: an .obj, or a .ply whose header has a face element with faces (a
// .ply without one is a point cloud).
int vd_geom_is_mesh_file(const char* path);

// ---------------------------------------------------------------------------------------------
// robot-simulator formats

#define VD_EXPORT_FORMAT_VERSION 1 // version of the URDF/SDF/MJCF conventions (docs/formats.md)

// File formats of vd_geom_export.
typedef enum vd_export_format {
  VD_EXPORT_URDF = 0, // URDF: one link per organ on fixed joints, meshes as OBJ files
  VD_EXPORT_SDF,      // SDF 1.7: a static model, one link per organ, meshes as OBJ files
  VD_EXPORT_MJCF,     // MuJoCo MJCF: one body per organ (no joints), meshes inline
} vd_export_format;

// A plant's rods for a flexible (articulated) export: the rod segments of the physics model
// with their joints, stiffness and lumped masses (vd_sim_export_rods fills it from a rod model).
// Arrays are the caller's; a segment's mass sits at its end point, as the rods lump it.
typedef struct vd_export_rods {
  int nseg;                  // rod segments
  const double* seg_ends;    // start and end point (m) (nseg x 6)
  const double* seg_radius;  // radius (m) (nseg)
  const double* seg_quat;    // rest frame w,x,y,z: d3 (z) along the segment (nseg x 4)
  const int* seg_parent;     // parent segment of its joint, -1: on the base (nseg)
  const int* seg_fixed;      // 1: held, part of the base (nseg)
  const int* seg_drawn;      // 1: a capsule, 0: a connector with no shape (fruit stalk) (nseg)
  const int* seg_label;      // semantic label id (nseg)
  const int* seg_instance;   // organ instance id (nseg)
  const double* seg_stiff;   // its joint with the parent: bending about d1, d2 and twist about
                             // d3 stiffness (N m/rad) (nseg x 3)
  const double* seg_mass;    // mass lumped at its end point (kg) (nseg)
  const double* seg_inertia; // rotary inertia of its own about d1/d2 and about d3 (kg m^2) (nseg x 2)
  const double* seg_sphere;  // radius of a sphere (fruit) centred at its end point, 0: none (m) (nseg)
  const double* seg_break;   // its joint's break force (N) and moment (N m), INFINITY: never
                             // (Nullable) (nseg x 2)
  const int* mesh_seg;       // rod segment each plant mesh rides on, -1: the base (plant nmesh)
  void* block;               // the memory behind the arrays when a library function filled them
  size_t nbytes;             // (vd_sim_export_rods), else NULL and 0
} vd_export_rods;

// Settings of an export.
typedef struct vd_export_def {
  vd_export_format format; // default VD_EXPORT_MJCF
  const char* name;        // model name and (MJCF) name prefix "<name>/": letters, digits, '_',
                           // '-', 1..48 characters; default "plant"
  vd_vec3 pos;             // where the plant's origin goes (m): the MJCF root body's and the SDF
                           // model's pose; default 0, 0, 0
  double leaf_thickness;   // thickness given to open meshes (leaves) so that they have a volume
                           // (m), in (0, 0.1); default 2e-4
  const vd_export_rods* rods; // Nullable: the plant's rods. NULL: a static plant, one rigid link
                           // per organ with no masses. Given: masses and inertias from the rods on
                           // every link, and (links_per_organ >= 0) a flexible plant
  int links_per_organ;     // with rods: -1 one rigid link per organ on fixed joints (masses only);
                           // 0 one link per rod segment; N > 0 each organ's rods in N links;
                           // links are joined by spring joints (bend, bend, twist); default 0
  double damping_ratio;    // joint damping as a fraction of critical for the link on its spring
                           // (-), >= 0; default 0.1
} vd_export_def;

// Defaults: MJCF, name "plant", at the origin, leaves 0.2 mm thick, no rods (static), one link
// per rod segment and damping ratio 0.1 when rods are given.
vd_export_def vd_export_def_default(void);
// "urdf", "sdf" or "mjcf".
const char* vd_export_format_name(vd_export_format f);
// Write plant m in state d (Nullable: its rest shape) for a robot simulator: every organ instance
// (label, instance) a link or body named "<label>_<instance>" with a visual and a collision
// shape per primitive (segment: cylinder of the mean radius in URDF/SDF, capsule in MJCF; sphere;
// mesh: closed, open ones as slabs of leaf_thickness). URDF and SDF write the meshes as OBJ files
// into "<path without extension>_meshes/" first (referred to relative to path); every file is
// atomic and a failure leaves none of them. docs/formats.md has the conventions.
vd_status vd_geom_export(const vd_model* m, const vd_data* d, const vd_export_def* def,
                         const char* path, vd_error* err);

// Write OBJ with normals plus a sibling .mtl (same base name), faces grouped by label/instance.
vd_status vd_geom_write_obj(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                            const char* path, vd_error* err);
// Write PLY (binary little-endian when binary is 1, else ASCII) with face label and instance.
vd_status vd_geom_write_ply(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                            const char* path, int binary, vd_error* err);
// Write PLY with one more per-vertex float property value_name (Nullable: "value") from value
// (Nullable: none, as vd_geom_write_ply) (nvert), NaN where there is none.
vd_status vd_geom_write_ply_values(const vd_mesh* mesh, const vd_label* labels, int nlabel,
                                   const double* value, const char* value_name, const char* path,
                                   int binary, vd_error* err);
// Per-vertex values of a tessellated plant (vd_geom_tessellate of m in state d, Nullable: rest)
// from values at the plant's nodes and segments (Nullable each; NaN: none): a segment's vertex
// takes the value of the node at its nearer end (the segment's value where the node has none);
// spheres and meshes have none (NaN). out: mesh->nvert values.
void vd_geom_vertex_values(const vd_model* m, const vd_data* d, const vd_mesh* mesh,
                           const double* node_value, const double* seg_value, double* out);

// ---------------------------------------------------------------------------------------------
// bounding volume hierarchy: binned SAH build over boxes, flat node array, built sequentially so
// the same input always gives the same tree

// BVH build settings.
typedef struct vd_bvh_def {
  int leaf_size; // most items in a leaf (1..32); default 4
  int bins;      // SAH bins per axis and node (2..64); default 16
} vd_bvh_def;

// Defaults: leaf_size 4 items, bins 16.
vd_bvh_def vd_bvh_def_default(void);

// One node: a box and either two children (first, first + 1) or a run of items.
typedef struct vd_bvh_node {
  double lo[3], hi[3]; // box (m)
  int first;           // interior: index of the left child, the right child is first + 1;
                       // leaf: first position in the item array
  int count;           // items of a leaf, 0 for an interior node
} vd_bvh_node;

// Triangle of a mesh BVH, stored in leaf order for ray casting.
typedef struct vd_bvh_tri {
  double v0[3], e1[3], e2[3]; // first vertex and the edges v1 - v0, v2 - v0 (m)
  int tri;                    // index of the triangle in the mesh
  int label, instance;        // copied from the mesh
  int one_sided;              // 1: back faces are culled when a ray asks for culling
} vd_bvh_tri;

// A BVH. Arrays live in one block owned by the BVH (vd_bvh_free); the root is node 0.
typedef struct vd_bvh {
  int nnode, nitem;  // sizes
  vd_bvh_node* node; // nodes (nnode)
  int* item;         // item indices in leaf order (nitem)
  vd_bvh_tri* tri;   // triangles in leaf order for a mesh BVH, NULL for a box BVH (nitem)
  size_t nbytes;     // size of the block
} vd_bvh;

// Build a BVH over n boxes (n x 6: lo x y z, hi x y z) (def Nullable: defaults).
vd_status vd_bvh_build(const double* box, int n, const vd_bvh_def* def, vd_bvh* out,
                       vd_error* err);
// Build a BVH over a mesh's triangles; one_sided (Nullable: none) marks triangles whose back
// faces rays may cull (ntri x 1, nonzero = one-sided).
vd_status vd_bvh_build_mesh(const vd_mesh* mesh, const unsigned char* one_sided,
                            const vd_bvh_def* def, vd_bvh* out, vd_error* err);
// Free a BVH's block and zero it (NULL and empty are fine).
void vd_bvh_free(vd_bvh* bvh);

// A ray hit on a mesh BVH.
typedef struct vd_hit {
  double t;            // distance along the ray (m, for a unit direction)
  double u, v;         // barycentric weights of the triangle's second and third vertices
  int tri;             // triangle index in the mesh
  int label, instance; // the triangle's semantic label and organ instance
  int front;           // 1 when the ray met the counter-clockwise (outward) side
} vd_hit;

// Nearest hit of the ray o + t dir, tmin < t < tmax, on a mesh BVH; cull skips back faces of
// one-sided triangles; skip is a mesh triangle to ignore (-1: none). 1 on a hit, else 0.
int vd_bvh_raycast(const vd_bvh* bvh, vd_vec3 o, vd_vec3 dir, double tmin, double tmax, int cull,
                   int skip, vd_hit* hit);
// 1 when any triangle (both sides, except skip) meets the ray o + t dir for tmin < t < tmax.
int vd_bvh_occluded(const vd_bvh* bvh, vd_vec3 o, vd_vec3 dir, double tmin, double tmax, int skip);
// Items of the leaves whose boxes overlap the box [lo, hi] (a superset of the items that do),
// written to items up to cap; returns how many there are (which may exceed cap).
int vd_bvh_overlap(const vd_bvh* bvh, const double lo[3], const double hi[3], int* items, int cap);

// ---------------------------------------------------------------------------------------------
// solids: the closed primitives of a plant (frustums with caps, spheres, closed meshes) as the
// polyhedra the tessellation makes of them, with exact point-inside tests

// One closed primitive.
typedef struct vd_solid {
  int kind;            // vd_prim_kind
  int prim;            // index of the primitive within its kind
  int label, instance; // semantic label and organ instance
  int slices, stacks;  // polygon sides (frustum, sphere longitudes) and sphere latitude bands
  double cos_half;     // cos(pi / slices): inscribed over circumscribed radius of the polygon
  double cos_stack;    // sphere: cos(pi / (2 stacks)), the latitude chords' inner reach
  int joined[2];       // solids of a generalised-cylinder tube sharing a ring with this one
                       // (parent side, child side), -1 when none
  vd_vec3 c;           // frustum start centre or sphere centre (m)
  vd_quat q;           // frustum frame: z along the axis, x toward ring vertex 0
  double rot[9];       // the same frame as a world-to-frame rotation, rows x, y, z
  double len;          // frustum length (m)
  double r0, r1;       // frustum circumradius at start and end, sphere radius in r0 (m)
  int tri_start, ntri; // closed mesh: range in the solids' triangle array
  double lo[3], hi[3]; // bounding box (m)
} vd_solid;

// The closed primitives of one plant state with a BVH over their boxes.
typedef struct vd_solids {
  int nsolid;          // solids
  vd_solid* solid;     // (nsolid)
  int ntri;            // triangles of closed meshes
  double* tri;         // their vertices (ntri x 9) (m)
  int nseg, nsphere, nmesh; // sizes of the lookups below
  int* seg_solid;      // solid of each segment (nseg)
  int* sphere_solid;   // solid of each sphere (nsphere)
  int* mesh_solid;     // solid of each mesh, -1 for open (thin) meshes (nmesh)
  double eps;          // boundary tolerance (m): points within it of a surface count as inside
  vd_bvh bvh;          // over the solids' boxes
  size_t nbytes;       // size of the block holding the arrays above (not the BVH)
} vd_solids;

// Build the solids of state d (Nullable: rest shape) of m, tessellated as def (Nullable:
// defaults; caps are always closed) would do it.
vd_status vd_solids_build(const vd_model* m, const vd_data* d, const vd_mesh_def* def,
                          vd_solids* out, vd_error* err);
// The solid of primitive (kind, prim), or -1 when it has none (thin meshes, bad indices).
int vd_solids_own(const vd_solids* so, int kind, int prim);
// 1 when p is inside solid i or on its boundary (within eps).
int vd_solid_contains(const vd_solids* so, int i, vd_vec3 p);
// A solid containing p other than the primitive (kind, prim) and the tube neighbours it is
// joined to, or -1 when none (kind -1: exclude nothing).
int vd_solids_inside(const vd_solids* so, vd_vec3 p, int kind, int prim);
// Free the solids and zero the struct (NULL and empty are fine).
void vd_solids_free(vd_solids* so);

#ifdef __cplusplus
}
#endif
#endif
