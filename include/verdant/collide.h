// SPDX-License-Identifier: MIT
// verdant collide: collision geometry shared by the plant simulation (sim) and the robot coupling.
//
// Geometry only, no response: the solver projects the contacts this module finds. Three parts:
//
// * Colliders: shapes outside the plant (ground plane, sphere, capsule, box, triangle mesh through
//   a signed distance grid) with a pose the caller may change before every query (robot links).
//   vd_collide_point and vd_collide_capsule give the signed distance, the outward normal and the
//   closest point from a point or a (tapered) capsule to one collider.
// * Signed distance grids (vd_sdf): built once per closed triangle mesh, in the mesh's own frame;
//   exact point-triangle distances in a band around the surface (sign from angle-weighted
//   pseudo-normals, Baerentzen & Aanaes 2005), the rest of the grid by closest-triangle sweeps or
//   clamped (narrow band); queried by trilinear interpolation with its gradient.
// * Contacts of the plant's primitives (capsules between nodes, spheres) with each other
//   (self-collision: sweep-and-prune broad phase, neighbour pairs excluded through an adjacency
//   the caller gives or builds with vd_collide_exclusion_build) and with colliders. Contact lists
//   live in a vd_arena the caller passes and resets (no heap allocation per step once the arena
//   has grown), sorted by (a, b) so the order never depends on the broad phase.
//
// Conventions: SI units (m). A pose maps local to world coordinates: x_w = pos + rot * x_l.
// Plane: the local xy plane, outward normal local +z. Capsule: local z axis from -half_length
// to +half_length. Box: centred, half sizes along local x, y, z. A plant capsule is tapered
// (radius r0 at node0, r1 at node1): the union of the spheres of radius r(t) = r0 + t (r1 - r0)
// centred on the axis. Distances are signed, negative when the shapes overlap. Normals point from
// the collider (or the second primitive) toward the plant primitive: moving the primitive along
// +normal separates them.
//
// Usage:
//   vd_collider ground = vd_collider_plane(vd_v3(0, 0, 0), vd_v3(0, 0, 1));
//   vd_collide_hit h = vd_collide_capsule(&ground, a, b, 0.004, 0.003);   // h.dist < 0:
//   penetration vd_collide_def def = vd_collide_def_default(); vd_contact_list self;
//   vd_collide_self(&prims, &def, &data->arena, &self, &err);     // self.c[0 .. self.n)
#ifndef VERDANT_COLLIDE_H
#define VERDANT_COLLIDE_H

#include "verdant/core.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---------------------------------------------------------------------------------------------
// signed distance grids

// Settings of a signed distance grid.
typedef struct vd_sdf_def {
  double cell;       // grid spacing (m); default 0.002
  double padding;    // grid margin around the mesh's bounding box (m); default 0.01
  double band;       // half-width of the band of exact distances around the surface (m), at
                     // least 1.5 cells; default 0.006
  int full;          // 1: distances everywhere in the grid (closest-triangle sweeps beyond the
                     // band); 0: narrow band, values beyond it clamped to +-band; default 1
  int64_t max_nodes; // largest grid accepted (nodes); VD_ERR_LIMIT beyond; default 16777216
                     // (128 MiB of doubles)
} vd_sdf_def;

// Defaults: cell 0.002 m, padding 0.01 m, band 0.006 m, full 1, max_nodes 16777216.
vd_sdf_def vd_sdf_def_default(void);

// A signed distance grid in the mesh's frame. One allocation (vd_sdf_destroy).
typedef struct vd_sdf {
  int nx, ny, nz;  // grid nodes along x, y, z
  vd_vec3 origin;  // position of node (0, 0, 0) (m)
  double cell;     // node spacing (m)
  double band;     // band half-width used at build time (m)
  int full;        // 1 when values beyond the band are distances, 0 when clamped
  int nvert, ntri; // size of the mesh after welding equal vertices
  double* value;   // signed distance at node (i, j, k), index i + nx (j + ny k) (m)
                   // (nx*ny*nz x 1)
  size_t nbytes;   // size of the allocation
} vd_sdf;

// Build the grid of a closed, consistently oriented triangle mesh (vert: nvert x 3 in m, tri:
// ntri x 3 vertex indices, counter-clockwise seen from outside; vertices at equal positions are
// welded). def Nullable: defaults. VD_ERR_VALUE names an open or badly oriented edge.
vd_status vd_sdf_build(const double* vert, int nvert, const int* tri, int ntri,
                       const vd_sdf_def* def, vd_sdf** out, vd_error* err);
// Free a grid (NULL is fine).
void vd_sdf_destroy(vd_sdf* sdf);
// Signed distance at local point p by trilinear interpolation; grad (Nullable) gets the
// interpolant's gradient. Outside the grid: distance to the grid box plus the value there.
double vd_sdf_eval(const vd_sdf* g, vd_vec3 p, vd_vec3* grad);

// ---------------------------------------------------------------------------------------------
// colliders and single queries

// A rigid placement: world = pos + rot * local.
typedef struct vd_pose {
  vd_vec3 pos; // origin of the local frame in world (m)
  vd_quat rot; // orientation of the local frame (unit quaternion)
} vd_pose;

// Identity pose.
vd_pose vd_pose_identity(void);

// Collider shapes.
typedef enum vd_shape {
  VD_SHAPE_PLANE = 0, // half-space below the local xy plane
  VD_SHAPE_SPHERE,    // sphere of radius at the origin
  VD_SHAPE_CAPSULE,   // segment -half_length..+half_length on local z, swept by radius
  VD_SHAPE_BOX,       // box of half sizes half_size
  VD_SHAPE_SDF,       // closed triangle mesh through a signed distance grid
  VD_SHAPE_COUNT
} vd_shape;

// A shape outside the plant with a pose the caller may change before every query.
typedef struct vd_collider {
  vd_shape shape;     // which shape
  vd_pose pose;       // local frame in world (m)
  double radius;      // sphere and capsule radius (m)
  double half_length; // capsule half length along local z (m)
  vd_vec3 half_size;  // box half sizes along local x, y, z (m)
  const vd_sdf* sdf;  // grid in the local frame for VD_SHAPE_SDF (not owned)
  int id;             // caller's tag (a robot geom id), not used here
} vd_collider;

// Plane through point with outward unit normal n (the free side).
vd_collider vd_collider_plane(vd_vec3 point, vd_vec3 n);
// Sphere of radius r at center.
vd_collider vd_collider_sphere(vd_vec3 center, double r);
// Capsule around the segment a-b with radius r.
vd_collider vd_collider_capsule(vd_vec3 a, vd_vec3 b, double r);
// Box with the given pose and half sizes.
vd_collider vd_collider_box(vd_pose pose, vd_vec3 half_size);
// Mesh through its distance grid sdf, placed at pose.
vd_collider vd_collider_sdf(vd_pose pose, const vd_sdf* sdf);
// Replace a collider's pose (the robot coupling calls this every step).
void vd_collider_set_pose(vd_collider* c, vd_pose pose);

// Result of a single query.
typedef struct vd_collide_hit {
  double dist;    // signed distance between the surfaces (m), negative when overlapping
  vd_vec3 normal; // unit outward normal of the collider at point (world)
  vd_vec3 point;  // closest point on the collider's surface (world, m)
  double t;       // capsule queries: axis parameter in [0, 1] of the deepest point; else 0
} vd_collide_hit;

// Signed distance from world point p to the collider's surface.
vd_collide_hit vd_collide_point(const vd_collider* c, vd_vec3 p);
// Sphere (centre p, radius r) against a collider: vd_collide_point with dist reduced by r.
vd_collide_hit vd_collide_sphere(const vd_collider* c, vd_vec3 p, double r);
// Tapered capsule a-b (radius ra at a, rb at b) against a collider: the deepest axis point t
// and the separation there (exact to round-off for the convex shapes; SDF colliders sample the
// axis every half cell, then refine around the best sample).
vd_collide_hit vd_collide_capsule(const vd_collider* c, vd_vec3 a, vd_vec3 b, double ra, double rb);
// World-space bounding box of a collider (planes are unbounded: +-HUGE_VAL across).
void vd_collider_bounds(const vd_collider* c, vd_vec3* lo, vd_vec3* hi);

// ---------------------------------------------------------------------------------------------
// plant primitives, neighbour exclusion and contact lists

// The plant's primitives for one query. Primitive index: capsules 0..ncapsule-1, then spheres
// ncapsule..ncapsule+nsphere-1. Arrays are the caller's (a vd_data's state arrays fit).
typedef struct vd_collide_prims {
  int nnode, ncapsule, nsphere; // sizes
  const double* node_pos;       // node positions (m) (nnode x 3)
  const int* capsule_node;      // end nodes of each capsule (ncapsule x 2)
  const double* capsule_radius; // radius at node0 and node1 (m) (ncapsule x 2)
  const double* sphere_pos;     // sphere centres (m) (nsphere x 3)
  const double* sphere_radius;  // sphere radii (m) (nsphere x 1)
  const int* skip;              // Nullable: non-zero leaves a primitive out (a broken segment)
                                // ((ncapsule + nsphere) x 1)
  const double* margin;         // Nullable: extra margin of each primitive (m): pair i, j is
                                // reported closer than def.margin + margin[i] + margin[j], a
                                // collider contact closer than def.margin + margin[i]; boxes grow
                                // by it (a fast primitive's own reach, not everyone's)
                                // ((ncapsule + nsphere) x 1)
  const int* exclude_start;     // Nullable: row starts of the excluded-pair adjacency (CSR):
                                // primitive i never meets exclude[exclude_start[i] ..
                                // exclude_start[i+1]) ((ncapsule + nsphere + 1) x 1)
  const int* exclude;           // excluded partners, ascending within each row (nexclude x 1)
  int exclude_rows;             // rows of the adjacency: ncapsule + nsphere when one is given
} vd_collide_prims;

// An excluded-pair adjacency built from the plant's topology (one allocation).
typedef struct vd_collide_exclusion {
  int nprim;     // ncapsule + nsphere
  int nexclude;  // entries in exclude
  int* start;    // row starts (nprim + 1 x 1)
  int* exclude;  // excluded partners, ascending per row, symmetric (nexclude x 1)
  size_t nbytes; // size of the allocation
} vd_collide_exclusion;

// Exclude every pair of primitives whose nodes are at most `hops` capsule edges apart (0: they
// share a node; 1: also the next capsule along, ...). sph_node (Nullable: none attached) gives
// each sphere's attachment node or -1. Build once per model; free with
// vd_collide_exclusion_free.
vd_status vd_collide_exclusion_build(int nnode, int ncapsule, const int* cap_node, int nsphere,
                                     const int* sph_node, int hops, vd_collide_exclusion* out,
                                     vd_error* err);
// Also exclude every pair closer than margin (m) in the state rest (the modelled shape, with ex
// set in it or not): organs that touch by design, a fruit against the pedicel segments around
// its node, are not collisions. ex is rebuilt in place (one allocation).
vd_status vd_collide_exclusion_add_touching(vd_collide_exclusion* ex, const vd_collide_prims* rest,
                                            double margin, vd_error* err);
// Free an exclusion's arrays and zero it.
void vd_collide_exclusion_free(vd_collide_exclusion* ex);
// Point prims' exclude_start / exclude / exclude_rows at an exclusion's arrays.
void vd_collide_prims_set_exclusion(vd_collide_prims* prims, const vd_collide_exclusion* ex);

// Contact queries' settings.
typedef struct vd_collide_def {
  double margin;    // pairs whose surfaces are closer than this are reported (m); default 0.001
  int max_contacts; // longest list (the rest are counted in ndropped); default 1000000
} vd_collide_def;

// Defaults: margin 0.001 m, max_contacts 1000000.
vd_collide_def vd_collide_def_default(void);

// One contact: primitive a against primitive b (self) or against collider b.
typedef struct vd_contact {
  int a;          // plant primitive (capsules first, then spheres)
  int b;          // second plant primitive (a < b), or collider index when collider is 1
  int collider;   // 1 when b indexes the collider array
  double ta, tb;  // axis parameters in [0, 1] of the closest points on a and on b (capsules);
                  // 0 for spheres and for colliders
  double dist;    // signed separation of the surfaces (m), negative when overlapping
  vd_vec3 normal; // unit normal from b toward a: moving a along +normal separates the pair
  vd_vec3 pa, pb; // closest surface points on a and on b (world, m)
} vd_contact;

// A contact list in the caller's arena.
typedef struct vd_contact_list {
  int n;            // contacts
  vd_contact* c;    // contacts sorted by (a, b) (n x 1), in the arena
  int64_t ntested;  // candidate pairs the narrow phase examined
  int64_t ndropped; // contacts beyond def.max_contacts, not stored
} vd_contact_list;

// Contacts between the plant's own primitives (capsule-capsule, capsule-sphere, sphere-sphere),
// excluded pairs and skipped primitives left out. Scratch and the list come from arena.
vd_status vd_collide_self(const vd_collide_prims* prims, const vd_collide_def* def, vd_arena* arena,
                          vd_contact_list* out, vd_error* err);
// Contacts between the plant's primitives and ncol colliders.
vd_status vd_collide_colliders(const vd_collide_prims* prims, const vd_collider* col, int ncol,
                               const vd_collide_def* def, vd_arena* arena, vd_contact_list* out,
                               vd_error* err);
// The contact of one pair of plant primitives i, j (the narrow phase): 1 and *out filled when
// their surfaces are closer than margin, else 0.
int vd_collide_pair(const vd_collide_prims* prims, int i, int j, double margin, vd_contact* out);

// Candidate pairs of the broad phase, to reuse over several steps (a Verlet list).
typedef struct vd_pair_list {
  int n;     // pairs
  int* pair; // primitive pairs (a < b), ascending by (a, b) (n x 2), in an arena
} vd_pair_list;

// The broad phase alone: pairs (not excluded, not skipped) whose boxes, grown by grow / 2 +
// prims->margin[i] each (m), overlap. While no primitive moves more than (grow - margin) / 2 plus
// the drop of its own margin since the build, every contact within margin is among them: build
// them every few steps into an arena kept until the next build. The list takes 8 bytes a pair.
vd_status vd_collide_self_pairs(const vd_collide_prims* prims, double grow, vd_arena* arena,
                                vd_pair_list* out, vd_error* err);
// The narrow phase over given pairs: their contacts within def.margin, sorted by (a, b).
vd_status vd_collide_pairs(const vd_collide_prims* prims, const vd_pair_list* pairs,
                           const vd_collide_def* def, vd_arena* arena, vd_contact_list* out,
                           vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
