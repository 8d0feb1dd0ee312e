// SPDX-License-Identifier: MIT
// verdant plant: the labelled plant every other module reads.
//
// A vd_plant_spec is the editable form (the turtle and the plant-file reader write it): nodes,
// frustum segments between nodes, spheres and thin or closed triangle meshes, each with a
// semantic label, an organ instance id, a parent segment and the index of the L-string module
// that produced it. vd_plant_compile turns a spec into a flat, read-only vd_model (one
// allocation, MuJoCo style); a vd_data holds the state that changes (node positions, segment
// frames, sphere centres, mesh vertices), so one model can drive many states.
//
// Units: metres. Labels: any non-negative int id with a name; instance ids start at 1 (0 is
// "no instance", the background in masks).
//
// Usage:
//   vd_plant_spec* s = vd_plant_spec_create();
//   int a = vd_plant_add_node(s, vd_v3(0,0,0)), b = vd_plant_add_node(s, vd_v3(0,0,0.1));
//   vd_segment_spec g = vd_segment_spec_default(); g.node0 = a; g.node1 = b; g.label = 1;
//   vd_plant_add_segment(s, &g);
//   vd_model* m; vd_plant_compile(s, &m, &err); vd_data* d = vd_data_create(m);
#ifndef VERDANT_PLANT_H
#define VERDANT_PLANT_H

#include "verdant/core.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_PLANT_FORMAT_VERSION 1  // version of the plant JSON schema (docs/formats.md)
#define VD_LABEL_NAME_MAX 48       // longest label name including the NUL
#define VD_PLANT_MAX_COORD 1e9     // largest |coordinate| and radius a plant may have (m): beyond
                                   // it meshes and clouds written as float32 would hold inf

// What the physics and robot modules treat specially; derived from the label's name.
typedef enum vd_organ {
  VD_ORGAN_OTHER = 0,  // unknown organ
  VD_ORGAN_STEM,       // stem, internode, trunk, branch, shoot, peduncle-free axes
  VD_ORGAN_LEAF,       // leaf, leaflet, petiole, cotyledon
  VD_ORGAN_FLOWER,     // flower, petal, bud, inflorescence
  VD_ORGAN_FRUIT,      // fruit, berry, silique, pod, seed
  VD_ORGAN_PEDICEL,    // pedicel, peduncle (fruit stalks, with an abscission zone)
  VD_ORGAN_ROOT,       // root
  VD_ORGAN_COUNT
} vd_organ;

// Organ kind for a label name (case-insensitive keywords above; VD_ORGAN_OTHER if none).
vd_organ vd_organ_from_name(const char* name);
// Lower-case name of an organ kind ("stem").
const char* vd_organ_name(vd_organ o);

// One entry of the label table.
typedef struct vd_label {
  int id;                        // semantic label id (material index or explicit label)
  char name[VD_LABEL_NAME_MAX];  // name shown in every output ("leaf")
  vd_organ organ;                // organ kind derived from the name
  float rgb[3];                  // display colour in [0, 1]
} vd_label;

// Fill a label entry: id, name (truncated), organ kind from the name, colour by organ kind
// (fruit red, leaf green, ...) or from the palette by id when the organ is unknown.
void vd_label_init(vd_label* l, int id, const char* name);

// segment flags
#define VD_SEG_GC 1u    // part of a generalised cylinder: joins its parent's end ring smoothly
#define VD_SEG_TIP 2u   // nothing continues from node1 on the same axis (an axis tip)

// A frustum between two nodes.
typedef struct vd_segment_spec {
  int node0, node1;  // start and end node
  double r0, r1;     // radius at node0 and node1 (m)
  vd_vec3 up;        // unit vector normal to the axis: angular origin of the section (turtle up)
  int parent;        // parent segment, -1 for a root segment
  int label;         // semantic label id
  int instance;      // organ instance id (>= 1)
  int axis;          // axis id: segments of one branch axis share it
  int order;         // branching order (0 main axis, +1 per lateral branch)
  unsigned flags;    // VD_SEG_*
  int slices;        // sides of the section when tessellated (>= 3)
  double age;        // organ age in the model's time unit (SetAge), 0 if unset
  int64_t module;    // index of the producing module in the derived L-string, -1 if none
} vd_segment_spec;

// A sphere (fruit, bud, flower centre).
typedef struct vd_sphere_spec {
  vd_vec3 center;   // centre (m)
  double radius;    // radius (m)
  int node;         // attachment node (the end of the segment it hangs from), -1 if none
  int parent;       // parent segment, -1 if none
  int label;        // semantic label id
  int instance;     // organ instance id (>= 1)
  int slices;       // tessellation resolution (>= 3)
  int64_t module;   // producing module, -1 if none
} vd_sphere_spec;

// A triangle mesh: thin surface (leaf, polygon, disc, quad) or closed volume (box).
typedef struct vd_mesh_spec {
  int vert_start, nvert;  // range in the spec's vertex array
  int tri_start, ntri;    // range in the spec's triangle array
  int closed;             // 1 if the mesh bounds a volume (outward-facing triangles)
  int node;               // attachment node, -1 if none
  int parent;             // parent segment, -1 if none
  int label;              // semantic label id
  int instance;           // organ instance id (>= 1)
  int64_t module;         // producing module, -1 if none
} vd_mesh_spec;

// The editable plant. Arrays are owned by the spec; use the add functions to append.
typedef struct vd_plant_spec {
  int nnode, nseg, nsphere, nmesh, nvert, ntri, nlabel;  // counts
  int ninstance;            // largest instance id in use
  vd_vec3* node;            // node positions (m) (nnode)
  vd_segment_spec* seg;     // segments (nseg)
  vd_sphere_spec* sphere;   // spheres (nsphere)
  vd_mesh_spec* mesh;       // meshes (nmesh)
  vd_vec3* vert;            // mesh vertices (m) (nvert)
  int* tri;                 // mesh triangles, indices into vert, counter-clockwise (ntri x 3)
  vd_label* label;          // label table sorted by id (nlabel)
  int cap_node, cap_seg, cap_sphere, cap_mesh, cap_vert, cap_tri, cap_label;  // capacities
  double* node_stress;      // Nullable: stress at each node's section (Pa), NaN where none, set by
                            // vd_plant_set_stress (nstress_node); stale once nodes are added
  double* seg_stress;       // Nullable: largest stress of each segment (Pa), NaN where none
                            // (nstress_seg)
  int nstress_node, nstress_seg;  // lengths of the stress arrays
} vd_plant_spec;

// Create an empty spec; NULL when out of memory.
vd_plant_spec* vd_plant_spec_create(void);
// Free a spec (NULL is fine).
void vd_plant_spec_destroy(vd_plant_spec* s);
// Deep copy of a spec (every element, the label table and the stress); NULL when out of memory.
vd_plant_spec* vd_plant_spec_copy(const vd_plant_spec* s);
// Remove every element, keeping the memory.
void vd_plant_spec_clear(vd_plant_spec* s);
// Segment with defaults: nodes -1, radii 0.1 m, up +X, parent -1, label 0, instance 0,
// axis 0, order 0, flags 0, slices 8, age 0, module -1.
vd_segment_spec vd_segment_spec_default(void);
// Sphere with defaults: centre 0, radius 0.1 m, node -1, parent -1, label 0, instance 0,
// slices 8, module -1.
vd_sphere_spec vd_sphere_spec_default(void);
// Append a node; returns its index or -1 when out of memory.
int vd_plant_add_node(vd_plant_spec* s, vd_vec3 p);
// Append a segment; returns its index or -1 when out of memory.
int vd_plant_add_segment(vd_plant_spec* s, const vd_segment_spec* g);
// Append a sphere; returns its index or -1 when out of memory.
int vd_plant_add_sphere(vd_plant_spec* s, const vd_sphere_spec* g);
// Append a mesh with its vertices and triangles (indices local to verts); m's vert/tri ranges
// are filled in. Returns the mesh index or -1 when out of memory.
int vd_plant_add_mesh(vd_plant_spec* s, const vd_mesh_spec* m, const vd_vec3* verts, int nvert,
                      const int* tris, int ntri);
// Name label id (adds it or renames it); name is truncated to VD_LABEL_NAME_MAX-1 characters.
vd_status vd_plant_set_label(vd_plant_spec* s, int id, const char* name);
// Label entry for id, or NULL when the id has no entry.
const vd_label* vd_plant_find_label(const vd_plant_spec* s, int id);
// Make sure every label id used by an element has a table entry (default name "label_<id>").
vd_status vd_plant_complete_labels(vd_plant_spec* s);
// Default display colour of a label id: a fixed palette for 0..6 (grey, brown, green, red,
// yellow, blue, purple), then a colour hashed from the id.
void vd_plant_default_rgb(int id, float rgb[3]);

// Segments without a parent that start at one point (the turtle starts a node per branch of an
// axiom: roots and trunk) are made to start at one node; returns the nodes no longer used.
int vd_plant_join_bases(vd_plant_spec* s);
// Attach stress (a simulation's result) to a spec: node (Nullable, nnode values) and seg
// (Nullable, nseg values) in Pa, NaN where there is none; copied. Both NULL removes it.
vd_status vd_plant_set_stress(vd_plant_spec* s, const double* node, const double* seg);
// 1 when the spec carries stress for its current nodes and segments.
int vd_plant_has_stress(const vd_plant_spec* s);

// Summary of a plant for --stats.
typedef struct vd_plant_stats {
  vd_vec3 bbox_min, bbox_max;  // bounds of all geometry including radii (m)
  double total_length;         // sum of segment lengths (m)
  int nseg, nsphere, nleaf;    // counts; nleaf counts meshes that are not closed
} vd_plant_stats;

// Compute the summary of a spec (an empty plant has a zero box).
void vd_plant_spec_stats(const vd_plant_spec* s, vd_plant_stats* out);

// ---------------------------------------------------------------------------------------------
// organ instances and traits

// What an instance id names.
typedef enum vd_instance_mode {
  VD_INSTANCE_MODULES = 0,  // one per producing L-string module (the turtle's numbering; elements
                            // without a module keep their instance)
  VD_INSTANCE_ORGANS = 1,   // one per organ as a botanist names it: the module pieces of one
                            // label joined with their parent segment's organ when it has the same
                            // label (a pedicel drawn as pedicel, knuckle, pedicel is one pedicel,
                            // a truss rachis one peduncle, a compound leaf one leaf), except that
                            // a stem or root segment on another axis than its parent's (a lateral
                            // branch or root) starts its own
} vd_instance_mode;

// Renumber the instances of s as mode says, 1..K in the order the elements come (segments,
// spheres, meshes); sets ninstance = K. VD_ERR_NOMEM leaves s unchanged.
vd_status vd_plant_set_instances(vd_plant_spec* s, vd_instance_mode mode);

// What a phenotyper measures on one instance (at the spec's shape).
typedef struct vd_organ_traits {
  int instance;                // instance id (1..)
  int label;                   // label of its first element, -1 when it has none
  vd_organ organ;              // organ kind of that label
  int nseg, nsphere, nmesh;    // its elements
  double length;               // segments' lengths summed (m)
  double area;                 // one-sided area of its thin meshes (leaf blades, petals) (m^2)
  double diameter;             // the largest sphere's diameter or closed mesh's largest extent (a
                               // fruit), else its thickest segment's diameter (m)
  double volume;               // frustums, spheres and closed meshes (m^3)
  vd_vec3 bbox_min, bbox_max;  // bounds including radii (m); 0 when it has no geometry
} vd_organ_traits;

// Traits of every instance 1..s->ninstance: *out (vd_free with *n * sizeof **out) holds
// instance i at index i - 1 (*out NULL and *n 0 when the plant has none).
vd_status vd_plant_traits(const vd_plant_spec* s, vd_organ_traits** out, int* n);

// ---------------------------------------------------------------------------------------------
// compiled model and state

// The flat, read-only plant. Arrays live in one block; shapes are given as (rows x cols).
typedef struct vd_model {
  int nnode, nseg, nsphere, nmesh, nvert, ntri, nlabel, ninstance;  // sizes
  // nodes
  double* node_pos0;   // rest position (m) (nnode x 3)
  // segments
  int* seg_node;       // start and end node (nseg x 2)
  double* seg_radius;  // radius at start and end (m) (nseg x 2)
  double* seg_len0;    // rest length (m) (nseg x 1)
  double* seg_quat0;   // rest frame w,x,y,z: z along the segment, x toward up (nseg x 4)
  int* seg_parent;     // parent segment or -1 (nseg x 1)
  int* seg_label;      // semantic label id (nseg x 1)
  int* seg_instance;   // organ instance id (nseg x 1)
  int* seg_axis;       // axis id (nseg x 1)
  int* seg_order;      // branching order (nseg x 1)
  int* seg_flags;      // VD_SEG_* flags (nseg x 1)
  int* seg_slices;     // tessellation sides (nseg x 1)
  double* seg_age;     // organ age (model time unit) (nseg x 1)
  // spheres
  double* sphere_pos0;    // rest centre (m) (nsphere x 3)
  double* sphere_radius;  // radius (m) (nsphere x 1)
  int* sphere_node;       // attachment node or -1 (nsphere x 1)
  int* sphere_parent;     // parent segment or -1 (nsphere x 1)
  int* sphere_label;      // semantic label id (nsphere x 1)
  int* sphere_instance;   // organ instance id (nsphere x 1)
  int* sphere_slices;     // tessellation resolution (nsphere x 1)
  // meshes
  int* mesh_vert;      // first vertex and vertex count (nmesh x 2)
  int* mesh_tri;       // first triangle and triangle count (nmesh x 2)
  int* mesh_closed;    // 1 if closed volume (nmesh x 1)
  int* mesh_node;      // attachment node or -1 (nmesh x 1)
  int* mesh_parent;    // parent segment or -1 (nmesh x 1)
  int* mesh_label;     // semantic label id (nmesh x 1)
  int* mesh_instance;  // organ instance id (nmesh x 1)
  double* vert_pos0;   // rest vertex position (m) (nvert x 3)
  int* tri_vert;       // triangle vertex indices into vert (ntri x 3)
  // labels
  vd_label* labels;    // label table sorted by id (nlabel)
  size_t nbytes;       // size of the single allocation
} vd_model;

// The state that changes. Created from a model, starts at the rest shape.
typedef struct vd_data {
  int nnode, nseg, nsphere, nvert;  // sizes copied from the model
  double* node_pos;    // position (m) (nnode x 3)
  double* seg_quat;    // frame w,x,y,z (nseg x 4)
  double* sphere_pos;  // centre (m) (nsphere x 3)
  double* vert_pos;    // mesh vertex position (m) (nvert x 3)
  int* seg_broken;     // 1 when the segment has fractured (nseg x 1)
  double* seg_cut;     // where a broken segment broke (nseg x 7): the fraction f of its length
                       // from node0 (0: at node0, 1: at node1; < 0: not known, the segment is
                       // only severed from its parent), the end A of the part still attached
                       // and the start B of the part that came off (m); drawn as node0 -> A
                       // (when f > 0) and B -> node1 (when f < 1). Read where seg_broken is 1.
  int64_t nwarning;    // count of numerical warnings raised by steps
  vd_arena arena;      // scratch memory, reset by each step
  size_t nbytes;       // size of the single allocation
} vd_data;

// Compile a spec into a model (labels completed, sizes checked).
vd_status vd_plant_compile(const vd_plant_spec* s, vd_model** out, vd_error* err);

// A straight beam, the cantilever of the validation cases, tests and benchmarks: a clamped
// piece from origin - clamp * dir to origin (segment 0, instance 1), then length along dir (segment
// 1, instance 2 or 1 with one_instance), both of radius r and label 1; with fruit_radius > 0 a
// sphere on segment 1 (label 2 "fruit", instance 3) centred fruit_offset beyond the tip, hung on
// the tip node when fruit_on_node. Segments' up: +z, or +x for a dir within 26 degrees of z.
typedef struct vd_beam_def {
  vd_vec3 origin;       // the clamped end of the free length (m, 0)
  vd_vec3 dir;          // unit direction (+x)
  double length;        // free length (m, 0.1)
  double radius;        // radius (m, 0.001)
  double clamp;         // length of the clamped piece behind the origin (m, 0.01)
  double fruit_radius;  // m; 0: no fruit (0)
  double fruit_offset;  // the fruit's centre beyond the tip along dir (m, 0)
  int fruit_on_node;    // 1: the sphere's node is the tip (1)
  int one_instance;     // 1: both segments are instance 1 (0)
  const char* label;    // label 1's name ("stem")
} vd_beam_def;
vd_beam_def vd_beam_def_default(void);
// The beam of d as a spec (*out new) or compiled (vd_plant_beam_model; the spec is not kept).
vd_status vd_plant_beam(const vd_beam_def* d, vd_plant_spec** out, vd_error* err);
vd_status vd_plant_beam_model(const vd_beam_def* d, vd_model** out, vd_error* err);
// Free a model (NULL is fine).
void vd_model_destroy(vd_model* m);
// Label entry for id in a model, or NULL.
const vd_label* vd_model_find_label(const vd_model* m, int id);
// New state at the model's rest shape; NULL when out of memory.
vd_data* vd_data_create(const vd_model* m);
// Put a state back at the rest shape.
void vd_data_reset(const vd_model* m, vd_data* d);
// Free a state (NULL is fine).
void vd_data_destroy(vd_data* d);

// ---------------------------------------------------------------------------------------------
// plant files (JSON, schema VD_PLANT_FORMAT_VERSION, docs/formats.md)

// Write the spec as plant JSON to path, atomically (temp file + rename).
vd_status vd_plant_write_json(const vd_plant_spec* s, const char* path, vd_error* err);
// Read plant JSON from path into a new spec; errors name the file and the field.
vd_status vd_plant_read_json(const char* path, vd_plant_spec** out, vd_error* err);
// Parse plant JSON from memory (name is used in errors, Nullable).
vd_status vd_plant_parse_json(const char* text, size_t len, const char* name, vd_plant_spec** out,
                              vd_error* err);
// The top-level "format" string of a JSON text ("verdant-plant", "verdant-curves") copied into
// buf, found without parsing the whole text; "" when there is none.
const char* vd_plant_json_format(const char* text, size_t len, char* buf, size_t cap);

// ---------------------------------------------------------------------------------------------
// hand-drawn plants: branch polylines (curves JSON, docs/formats.md) to a plant spec, as Gazebo
// Plants (Deng et al. 2024, sec. 3.5) builds them: dense sampling of every polyline, branch
// connections within sigma_connect by a search from the root (nearest gap first), simplification
// to segments of about sigma_distance keeping junctions, tips, curve joins and marked nodes,
// leaves from templates and fruits as spheres at marked nodes.
//
//   vd_curves* c; vd_curves_read("data/curves_tomato.json", &c, &err);
//   vd_curves_def def = vd_curves_file_def(c);   // defaults with the file's "settings"
//   def.distance = 0.03;
//   vd_curves_build(c, &def, spec, NULL, &err); vd_curves_destroy(c);

#define VD_CURVES_FORMAT_VERSION 1  // version of the curves JSON schema (docs/formats.md)

// Settings of the curve import.
typedef struct vd_curves_def {
  double sample_step;   // dense sampling step along every polyline (m); default 0.001
  double connect;       // sigma_connect: largest gap between a branch end and the plant (m);
                        // default 0.01
  double distance;      // sigma_distance: segment length after simplification (m); default 0.02
  double radius;        // radius of curves that give none (m); default 0.002
  double leaf_length;   // leaf length when a leaf gives none (m); default 0.05
  double fruit_radius;  // fruit radius when a fruit gives none (m); default 0.01
  int slices;           // tessellation sides of segments and fruits (>= 3); default 8
  int64_t max_samples;  // most dense samples over all curves; VD_ERR_LIMIT beyond; default 1e7
} vd_curves_def;

// Defaults: sample_step 0.001 m, connect 0.01 m, distance 0.02 m, radius 0.002 m, leaf_length
// 0.05 m, fruit_radius 0.01 m, slices 8, max_samples 10000000.
vd_curves_def vd_curves_def_default(void);

// A parsed curves file (opaque).
typedef struct vd_curves vd_curves;

// Counts of a build, for tests and --stats.
typedef struct vd_curves_stats {
  int ncurve;     // polylines in the file
  int64_t nsample;  // dense samples over all curves
  int nconnect;   // branch connections made (one per curve but the root's)
  int ngap;       // connections bridged by a segment (the rest joined at a shared point)
  int nnode;      // nodes kept after simplification
  int nseg;       // segments made
  int nleaf, nfruit;  // leaves and fruits placed
} vd_curves_stats;

// Read a curves file (format "verdant-curves"); errors name the file and the field.
vd_status vd_curves_read(const char* path, vd_curves** out, vd_error* err);
// Parse curves JSON from memory (name is used in errors, Nullable).
vd_status vd_curves_parse(const char* text, size_t len, const char* name, vd_curves** out,
                          vd_error* err);
// Free parsed curves (NULL is fine).
void vd_curves_destroy(vd_curves* c);
// The defaults with the file's "settings" applied.
vd_curves_def vd_curves_file_def(const vd_curves* c);
// Build the plant into spec (appended; def Nullable: vd_curves_file_def; stats Nullable).
// VD_ERR_VALUE names a curve that does not connect or a marker far from every curve.
vd_status vd_curves_build(const vd_curves* c, const vd_curves_def* def, vd_plant_spec* spec,
                          vd_curves_stats* stats, vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
