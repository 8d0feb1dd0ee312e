// SPDX-License-Identifier: MIT
// verdant sim: plant physics with Cosserat rods (Kugelstadt & Schömer 2016) in XPBD form
// (Macklin et al. 2016), solved either by Gauss-Seidel iterations or exactly by a linear-time
// direct solver over the plant's tree (Deul et al. 2018; Baraff 1996). SI units throughout.
//
// A plant (vd_model) is turned into a rod model (vd_sim_model) by vd_sim_build: its axes are
// resampled to rod segments of about def.segment_length, keeping junctions, tips, organ changes,
// attachment points and abscission nodes as key nodes; positions live on nodes, one quaternion
// per segment; each segment carries a stretch-shear constraint and a bend-twist constraint with
// its parent segment. Leaves become small rod graphs (midrib and two side veins), fruits spheres
// on a stalk segment; the first def.clamp_length of every root segment is clamped. The rod
// model is const; a vd_sim_data holds the state (positions, frames, velocities, multipliers,
// colliders, ties, events), so one model drives many states.
//
// Ownership: the caller owns models and states; vd_sim_data borrows its model, which must
// outlive it. opt (inside the model) may be changed between steps; nothing else.
//
// Usage:
//   vd_sim_def def = vd_sim_def_default();           // materials, segment length, sag-free
//   vd_sim_model* sm; vd_sim_build(plant_model, &def, &sm, &err);
//   vd_sim_data* sd = vd_sim_data_create(sm);
//   for (int i = 0; i < 1000; i++) vd_sim_step(sm, sd);  // 1 s at opt.dt = 1 ms
//   vd_sim_to_plant(sm, sd, plant_model, plant_data);    // deformed plant for meshes/clouds
#ifndef VERDANT_SIM_H
#define VERDANT_SIM_H

#include "verdant/collide.h"
#include "verdant/core.h"
#include "verdant/geom.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_SIM_FRAMES_VERSION 1  // version of the binary and JSON Lines frame formats
#define VD_SIM_MAX_COLLIDERS 64  // most external colliders one state holds
#define VD_SIM_MAX_SUBSTEP 7     // a failed step is retaken in halves, down to dt / 2^7
#define VD_SIM_MAX_STRAIN 1.0    // a step that stretches a segment beyond (1 + this) l0, and to more
                                 // than twice the largest stretch at its start, fails (-)
#define VD_SIM_BLOWUP_STRAIN 10.0 // a step that stretches a segment beyond (1 + this) l0 fails (-)

// Kinds of numerical warnings, counted in vd_sim_data::warning (MuJoCo's mjData.warning).
typedef enum vd_sim_warning {
  VD_SIM_WARN_NONFINITE = 0,  // a step made a non-finite state: undone and retaken in halves
  VD_SIM_WARN_SOLVER,         // a factorisation of the direct solver failed: retaken in halves
  VD_SIM_WARN_STRAIN,         // a step stretched a segment beyond VD_SIM_MAX_STRAIN: retaken
  VD_SIM_WARN_SUBSTEP,        // steps retaken as two half steps (each failure above causes one)
  VD_SIM_WARN_UNSTABLE,       // substeps of dt / 2^VD_SIM_MAX_SUBSTEP that still failed (or were
                              // kept stretched beyond VD_SIM_MAX_STRAIN)
  VD_SIM_WARN_STRETCHED,      // steps that ended with a segment stretched beyond VD_SIM_MAX_STRAIN
  VD_SIM_WARN_ARENA,          // the per-step arena could not hold the contact candidates
  VD_SIM_WARN_COUNT
} vd_sim_warning;

// Lower-case name of a warning kind ("nonfinite", "solver", ...).
const char* vd_sim_warning_name(vd_sim_warning w);

// Stages of a step, timed into vd_sim_data::stage_seconds while vd_sim_data::profile is 1.
typedef enum vd_sim_stage {
  VD_SIM_STAGE_FORCES = 0,  // loads: gravity, the caller's forces, wind and air drag
  VD_SIM_STAGE_PREDICT,     // prediction of positions and frames (and the step's bookkeeping)
  VD_SIM_STAGE_CONTACTS,    // contact candidates near colliders, self-contact pairs
  VD_SIM_STAGE_EVAL,        // constraint evaluation: values, Jacobians, body residuals
  VD_SIM_STAGE_FACTOR,      // the direct solver's elimination from the tips (factorisation)
  VD_SIM_STAGE_SOLVE,       // back substitution and the update of the state (GS: the sweeps)
  VD_SIM_STAGE_PROJECT,     // contact projection and friction
  VD_SIM_STAGE_VELOCITY,    // velocities from the motion, the step's checks (finite, stretch)
  VD_SIM_STAGE_FRACTURE,    // fracture checks
  VD_SIM_STAGE_COUNT
} vd_sim_stage;

// Lower-case name of a stage ("forces", "predict", ...).
const char* vd_sim_stage_name(vd_sim_stage s);

// Material classes: each rod segment takes its material from one of these.
typedef enum vd_sim_class {
  VD_SIM_GREEN = 0,  // green (herbaceous) stem: organ stem, other
  VD_SIM_WOOD,       // lignified stem: organ stem whose label says trunk, branch, wood, twig, bole
  VD_SIM_PEDICEL,    // pedicels and peduncles (fruit stalks)
  VD_SIM_LEAF,       // petioles, rachises and leaf veins
  VD_SIM_FRUIT,      // fruit spheres and their calyx joint
  VD_SIM_FLOWER,     // flowers and buds
  VD_SIM_ROOT,       // roots (clamped in the soil unless def.clamp_roots is 0)
  VD_SIM_CLASS_COUNT
} vd_sim_class;

// Lower-case name of a material class ("green", "wood", "pedicel", ...).
const char* vd_sim_class_name(vd_sim_class c);
// Class for a name as written by vd_sim_class_name, or VD_SIM_CLASS_COUNT if none.
vd_sim_class vd_sim_class_parse(const char* name);

// Material of one class. INFINITY disables a fracture threshold.
typedef struct vd_sim_material {
  double young;         // Young's modulus E (Pa)
  double poisson;       // Poisson ratio nu (-); shear modulus G = E / (2 (1 + nu))
  double density;       // density rho (kg/m^3)
  double break_force;   // a joint breaks when its constraint force exceeds this (N)
  double break_moment;  // ... or its constraint moment exceeds this (N m)
  double break_cs;      // ... or |C_s| (stretch-shear strain, -) exceeds this (the paper's C_s^max)
  double break_cb;      // ... or |C_b| (Darboux vector change, 1/m) exceeds this (C_b^max)
  double drag_cd;       // drag coefficient of the segment (cylinder) or sphere (-)
} vd_sim_material;

// Bend-twist strain measure of the rod joints (docs/physics.md section 2).
typedef enum vd_sim_bend {
  VD_SIM_BEND_LOG = 0,  // rotation vector of the joint's turn away from rest, log(conj(q_rest) q_rel)
                        // / l-bar: the moment grows linearly with the angle up to 180 deg; a
                        // junction's parent segment lumps its upper half into its own joint
  VD_SIM_BEND_QUAT      // Kugelstadt & Schomer 2016 / Gazebo Plants: (2 / l-bar)(Im q_rel - Im q_rest),
                        // moment sin(angle) / flexibility (none left at 180 deg); junction joints
                        // each take half the parent segment (the model before 2026-11)
} vd_sim_bend;

// Name of a measure ("log", "quat") and back (-1 if none).
const char* vd_sim_bend_name(vd_sim_bend b);
int vd_sim_bend_parse(const char* name);

// Rod-model settings for vd_sim_build.
typedef struct vd_sim_def {
  double segment_length;          // target rod segment length sigma_distance (m)
  double clamp_length;            // length of each root segment held fixed, like a pot (m); 0: only
                                  // the root node and its frame held (an exact clamped end)
  int clamp_roots;                // 1: segments of organ root are fixed (0: a soil may hold them,
                                  // vd_sim_soil_attach; the stem's collar stays held)
  vd_sim_material material[VD_SIM_CLASS_COUNT];  // per class; see vd_sim_def_default
  double leaf_areal_density;      // mass of leaf lamina per area (kg/m^2)
  double leaf_vein_ratio;         // midrib radius at the leaf base / blade length (-)
  double leaf_plate_cd;           // drag coefficient of the lamina, normal flow (-)
  int leaf_graphs;                // leaf meshes: 1 rod graphs (midrib and two side veins), 2 the midrib
                                  // alone, 0 rigid on their node (model reduction)
  int leaf_segments;              // segments per leaf vein (e.g. 2 or 3), 0: by the segment length
  double class_segment_length[VD_SIM_CLASS_COUNT];  // segment length per class (m), 0: segment_length
                                  // (model reduction: wood coarser than green stems)
  int sag_free;                   // 1: rest shape solved so the modelled shape is in equilibrium
  vd_vec3 gravity;                // gravity used by sag_free and copied to opt.gravity (m/s^2)
  double stake_spacing;           // tie the main stem to a fixed stake every this length (m), 0 off
  double stake_stiffness;         // stiffness of each stake tie (N/m)
  int max_segments;               // most rod segments the model may have; larger is VD_ERR_LIMIT
  vd_sim_bend bend_measure;       // bend-twist strain measure
  double active_radius;           // region of interest (model reduction), 0 off: segments with no node
                                  // within this distance (m) of the segment active_a - active_b are
                                  // held at the modelled shape (not simulated); a held segment's
                                  // joint with a simulated parent still holds that parent (m)
  vd_vec3 active_a, active_b;     // the region's axis: a point when equal, or a collider's path (m)
} vd_sim_def;

// Defaults (sources in docs/physics.md):
//   segment_length 0.02 m, clamp_length 0.01 m, clamp_roots 1, leaf_graphs 1, sag_free 0,
//   gravity (0, 0, -9.81) m/s^2, stake_spacing 0 m (off), stake_stiffness 1e4 N/m,
//   max_segments 1000000 (a model and one state take about 2 kB per segment),
//   bend_measure VD_SIM_BEND_LOG, leaf_segments 0, class_segment_length 0 (all: segment_length),
//   active_radius 0 (off), active_a = active_b = (0, 0, 0),
//   leaf_areal_density 0.22 kg/m^2, leaf_vein_ratio 0.015, leaf_plate_cd 1.17;
//   materials            E (Pa)   nu    rho (kg/m^3)  drag cd   fracture
//     green stem         1e9      0.3   1000          1.2       never
//     wood               1e10     0.3   900           1.2       never
//     pedicel            5e8      0.3   1000          1.2       abscission joint: 6.5 N, 1e-2 N m
//     leaf               5e8      0.3   900           1.2       never
//     fruit              5e6      0.3   800           0.47      calyx joint: 1.5 N
//     flower             1e8      0.3   500           0.47      never
//     root               1e10     0.3   900           1.2       never
//   break_cs and break_cb are INFINITY (off) for every class.
vd_sim_def vd_sim_def_default(void);

// Solver for the constraint projection.
typedef enum vd_sim_solver {
  VD_SIM_DIRECT = 0,  // exact linear-time tree solve per Newton iteration (Deul et al. 2018)
  VD_SIM_GS           // XPBD Gauss-Seidel sweeps (Macklin et al. 2016), multipliers accumulated
} vd_sim_solver;

// Run settings: stored in the model, may be changed between steps.
typedef struct vd_sim_opt {
  double dt;                  // time step h (s)
  int iterations;             // Newton iterations (direct) or sweeps (gs) per step
  vd_sim_solver solver;       // constraint solver
  vd_vec3 gravity;            // gravitational acceleration (m/s^2)
  double air_density;         // rho_air (kg/m^3); wind pressure P = rho_air |v|^2 / 2 = 0.613 |v|^2
  vd_vec3 wind;               // mean wind velocity (m/s)
  double gust_amplitude;      // gusts: wind * (1 + a sin(2 pi t / gust_period)), a (-)
  double gust_period;         // gust period (s)
  const double* wind_series;  // Nullable: time series rows (t s, vx, vy, vz m/s), linear in t,
                              // replaces wind and gusts; owned by the caller (nwind rows x 4)
  int nwind;                  // rows of wind_series
  int drag;                   // 1: aerodynamic forces (wind and quadratic air drag) on
                              // segments, spheres and leaf laminae; 0: none
  double stokes_viscosity;    // Stokes drag 6 pi eta r v (Pa s); numerical damping only, 0 off
  double damping;             // stiffness-proportional (Rayleigh) damping time tau (s)
  double mass_damping;        // velocity damping rate c: v /= 1 + c h (1/s)
  int fracture;               // 1: joints break at their thresholds
  int contacts;               // 1: colliders are projected
  double friction;            // Coulomb friction coefficient of contacts (-)
  int threads;                // threads one state's step uses (the direct solver's subtrees, per-segment
                              // loops); the bytes do not depend on it; changing it rebuilds the
                              // solver's schedule at the next step (one allocation)
  int self_collision;         // 1: the plant's capsules and fruit spheres collide with each other
                              // (vd_collide_self; topological neighbours and pairs touching in
                              // the modelled shape excluded)
} vd_sim_opt;

// Defaults: dt 1e-3 s, iterations 1, solver direct, gravity (0, 0, -9.81) m/s^2,
// air_density 1.226 kg/m^3, wind 0 m/s, gust_amplitude 0, gust_period 2 s, no wind series,
// drag 1, stokes_viscosity 0 Pa s, damping 0 s, mass_damping 0 1/s, fracture 1, contacts 1,
// friction 0.5, threads 1, self_collision 0 (off: it costs ~30 % on the tomato with a probe,
// docs/physics.md).
vd_sim_opt vd_sim_opt_default(void);

// rod segment flags
#define VD_SIM_FIXED 1u      // kinematic: clamped (position and frame)
#define VD_SIM_FRUITSEG 2u   // stalk from a pedicel tip to a fruit (or bud) centre
#define VD_SIM_LEAFSEG 4u    // part of a leaf rod graph
#define VD_SIM_CONNECT 8u    // connector bridging a gap between a parent and its child
#define VD_SIM_ABSCISSION 16u  // its joint with the parent is a pedicel abscission node
#define VD_SIM_HELD 32u      // outside the region of interest: held (also VD_SIM_FIXED)

// The rod model: compiled once, read-only. Arrays live in one block.
typedef struct vd_sim_model {
  int nnode;              // rod nodes
  int nseg;               // rod segments (each with a stretch-shear and a bend-twist constraint)
  int nspare;             // spare nodes, one per breakable joint, used when it breaks
  int nnode_all;          // nnode + nspare
  int ntie;               // stake ties
  int nbind_node, nbind_seg, nbind_sphere, nbind_vert;  // plant elements bound to the rods
  vd_sim_opt opt;         // run settings (may be changed between steps)
  // nodes (nnode_all; spare nodes after the first nnode)
  vd_vec3* node_pos0;     // modelled position (m)
  double* node_mass;      // lumped mass (kg)
  double* node_radius;    // largest radius of its segments or its sphere (m), Stokes drag
  int* node_owner;        // segment that ends at the node, -1 for fixed root nodes and spares
  int* node_fixed;        // 1 when the node is kinematic
  double* node_sphere;    // drag sphere radius at the node, 0 if none (m)
  // segments (nseg)
  int* seg_node;          // start and end node (nseg x 2)
  int* seg_parent;        // parent segment of the bend-twist constraint, -1 if none
  unsigned* seg_flags;    // VD_SIM_* flags
  int* seg_class;         // vd_sim_class
  int* seg_label;         // semantic label id of the plant element it came from
  int* seg_instance;      // organ instance id
  int* seg_plant;         // plant segment it resamples, -1 for leaves, fruits, connectors
  int* seg_spare;         // spare node used if its joint breaks, -1 if unbreakable
  int* seg_order;         // post-order index: children before parents (nseg)
  double* seg_len0;       // rest length l0 (m)
  double* seg_radius;     // radius (m)
  double* seg_mass;       // mass of the segment's own material, lumped half on each node (kg)
  vd_quat* seg_quat0;     // modelled frame: d3 (z) along the segment (initial state)
  vd_quat* seg_rest;      // rest relative rotation conj(q_parent) q (bend-twist rest, augmented)
  double* seg_lbar;       // Darboux length l-bar = (l_parent + l) / 2 of the joint (m)
  double* seg_cs;         // stretch-shear compliance of C_s (shear, shear, stretch) (nseg x 3)
  double* seg_cb;         // bend-twist compliance of C_b (bend, bend, twist) (nseg x 3)
  double* seg_inertia;    // rotary inertia about d1/d2 and about d3 (kg m^2) (nseg x 2)
  double* seg_break;      // thresholds: force N, moment N m, C_s, C_b 1/m (nseg x 4)
  double* seg_cd;         // drag coefficient (-)
  double* seg_leaf_normal;// lamina normal in the segment frame, area-weighted (nseg x 3)
  // stake ties (ntie)
  int* tie_node;          // tied node
  vd_vec3* tie_anchor;    // fixed anchor point (m)
  double* tie_compliance; // compliance (m/N)
  // bindings: where each plant element sits on the rods (for vd_sim_to_plant)
  int* bind_node_seg;     // plant node -> rod segment (-1: rod node bind_node_ref) (nbind_node)
  int* bind_node_ref;     // rod node when bound to a node, else unused (nbind_node)
  vd_vec3* bind_node_local;  // offset in the segment's modelled frame from its start node (m)
  int* bind_seg_seg;      // plant segment -> rod segment whose rotation it follows (nbind_seg)
  vd_quat* bind_seg_local;   // conj(rod modelled frame) * plant frame (nbind_seg)
  int* bind_sphere_node;  // plant sphere -> rod node at its centre (nbind_sphere)
  int* bind_sphere_seg;   // ... and the segment whose frame it follows (-1 none)
  int* bind_vert_seg;     // mesh vertex -> rod segment (nbind_vert)
  vd_vec3* bind_vert_local;  // offset in that segment's modelled frame from its start node (m)
  int main_tip;           // node at the end of the main axis (for tip_displacement), -1 if none
  double leaf_cd;         // drag coefficient of leaf laminae, normal flow (-)
  int nsagfree_clamped;   // joints whose sag-free rest curvature was out of reach (too heavy)
  int nheld;              // segments held outside the region of interest
  vd_sim_bend bend_measure;  // bend-twist strain measure (from the def)
  double total_mass;      // sum of node masses (kg)
  size_t nbytes;          // size of the single allocation
} vd_sim_model;

// An external collider, moved by the caller (one-way coupling: the plant does not push it).
typedef enum vd_sim_shape {
  VD_SIM_PLANE = 0,  // half-space below the plane through pos with normal +z of quat
  VD_SIM_SPHERE,     // sphere of radius size[0] at pos
  VD_SIM_CAPSULE,    // capsule of radius size[0], half-length size[1] along z of quat
  VD_SIM_BOX,        // box of half-extents size[0..2] in the frame of quat
  VD_SIM_MESH        // closed triangle mesh through its signed distance grid sdf, placed at
                     // pos / quat (the grid's local frame)
} vd_sim_shape;

typedef struct vd_sim_collider {
  vd_sim_shape shape;  // shape kind
  double size[3];      // shape sizes (m), see vd_sim_shape
  vd_vec3 pos;         // position (m)
  vd_quat quat;        // orientation
  vd_vec3 vel;         // velocity (m/s), set by vd_sim_set_collider_pose from pose changes
  const vd_sdf* sdf;   // VD_SIM_MESH: the mesh's distance grid (not owned; outlives the state)
} vd_sim_collider;

// One fracture: the joint of segment seg with its parent broke at time t.
typedef struct vd_sim_event {
  double time;        // simulation time (s)
  int seg;            // rod segment detached from its parent
  int node;           // node where it broke
  int label;          // label id of the segment
  int instance;       // organ instance id of the segment
  int cls;            // vd_sim_class of the segment
  double force;       // constraint force at breaking (N)
  double moment;      // constraint moment at breaking (N m)
  double cs, cb;      // |C_s| (-) and |C_b| (1/m) at breaking
  int cause;          // 0 force, 1 moment, 2 C_s, 3 C_b
} vd_sim_event;

// A user tie: a node pulled toward a target point by a spring (a displacement pull).
typedef struct vd_sim_tie {
  int node;           // rod node
  vd_vec3 target;     // target point (m), may move each step
  double compliance;  // 1 / stiffness (m/N), > 0
} vd_sim_tie;

// The state of one rod model.
typedef struct vd_sim_data {
  int nnode_all, nseg;     // sizes copied from the model
  double time;             // simulation time (s)
  int64_t nstep;           // steps taken
  vd_vec3* node_pos;       // position (m) (nnode_all)
  vd_vec3* node_vel;       // velocity (m/s) (nnode_all)
  vd_vec3* node_force;     // external force set by the caller, kept across steps (N) (nnode_all)
  double* node_mass;       // current lumped mass, changes when a joint breaks (kg) (nnode_all)
  vd_quat* seg_quat;       // frame (nseg)
  vd_vec3* seg_omega;      // angular velocity, world frame (rad/s) (nseg)
  vd_vec3* seg_torque;     // external torque set by the caller (N m) (nseg)
  double* seg_lambda;      // accumulated multipliers: stretch-shear 3, bend-twist 3 (nseg x 6)
  int* seg_broken;         // 1 when the joint with the parent has broken (nseg)
  int* seg_start;          // current start node: seg_node[2s] or its spare after breaking (nseg)
  vd_sim_collider collider[VD_SIM_MAX_COLLIDERS];  // external colliders
  int ncollider;           // colliders in use
  // what the plant did to each collider in the last vd_sim_step: minus the momentum its contacts
  // (normal pushes and friction) gave the plant, per second of the step (the reaction a robot
  // link feels; two-way coupling)
  vd_vec3 collider_force[VD_SIM_MAX_COLLIDERS];   // force on collider k (N)
  vd_vec3 collider_torque[VD_SIM_MAX_COLLIDERS];  // its moment about collider k's pos (N m)
  int collider_pass[VD_SIM_MAX_COLLIDERS];  // a node collider k does not touch, -1 none (a fruit
                                            // held between a gripper's fingers); set to -1 by
                                            // vd_sim_add_collider
  vd_sim_tie* tie;         // user ties (ntie, capacity cap_tie)
  int ntie, cap_tie;
  vd_sim_event* event;     // fracture events since the last reset (nevent, at most nseg)
  int nevent;
  int ncontact;            // contacts found in the last step
  double max_penetration;  // deepest penetration left after the last step (m)
  int64_t nwarning;        // numerical warnings of every kind (the sum of warning[])
  int64_t warning[VD_SIM_WARN_COUNT];  // numerical warnings by kind (vd_sim_warning)
  int profile;             // 1: time each stage of every step into stage_seconds (0 by default)
  double stage_seconds[VD_SIM_STAGE_COUNT];  // time spent per stage while profiling, wall clock (s)
  void* work;              // solver scratch (private)
  size_t work_bytes;       // size of work
  vd_arena arena;          // per-step scratch (contacts)
  size_t nbytes;           // size of the state block
} vd_sim_data;

// Build the rod model of a compiled plant. Errors name the offending element.
vd_status vd_sim_build(const vd_model* plant, const vd_sim_def* def, vd_sim_model** out,
                       vd_error* err);
// Free a rod model (NULL is fine).
void vd_sim_model_destroy(vd_sim_model* m);
// The rods of m for a flexible export (vd_export_def.rods of vd_geom_export): every rod segment
// with its rest shape, the stiffness of its joint with the parent (bending and twist, k = 1 /
// (C_b compliance l-bar^2): the series half-segments' EI/l, GJ/l), the mass the rods lump at its
// end node, its rotary inertia, the fruit sphere on that node and its break force and moment;
// plant (the model m was built from) gives each mesh the rod segment most of its vertices ride
// on. Free with vd_sim_export_rods_free. docs/formats.md, "Flexible exports".
vd_status vd_sim_export_rods(const vd_sim_model* m, const vd_model* plant, vd_export_rods* out,
                             vd_error* err);
// Free what vd_sim_export_rods filled (a zeroed struct is fine).
void vd_sim_export_rods_free(vd_export_rods* r);
// New state at the modelled shape, at rest; NULL when out of memory.
vd_sim_data* vd_sim_data_create(const vd_sim_model* m);
// Put a state back at the modelled shape (colliders and ties are kept, events cleared).
void vd_sim_data_reset(const vd_sim_model* m, vd_sim_data* d);
// Free a state (NULL is fine).
void vd_sim_data_destroy(vd_sim_data* d);

// Advance one time step of m->opt.dt. A step that fails (non-finite state, failed
// factorisation, a segment stretched beyond VD_SIM_MAX_STRAIN and to more than twice the
// largest stretch at the start of the step, or beyond VD_SIM_BLOWUP_STRAIN) is undone and
// retaken as two half steps, recursively down to dt / 2^VD_SIM_MAX_SUBSTEP; each failure is
// counted in d->warning. At the smallest substep a stretched state below VD_SIM_BLOWUP_STRAIN
// is kept (counted as VD_SIM_WARN_UNSTABLE); a non-finite one, a failed factorisation or a
// larger stretch is put back to the start of that substep (time says where) and VD_ERR_VALUE
// is returned; else VD_OK. A step that ends stretched beyond VD_SIM_MAX_STRAIN is counted as
// VD_SIM_WARN_STRETCHED. The state never holds a non-finite number.
vd_status vd_sim_step(const vd_sim_model* m, vd_sim_data* d);

// Step n states of one model (many episodes, parameter sweeps, batch learning): each state
// d[i] takes nsteps steps as vd_sim_step would, the states split among `threads` threads
// (OpenMP; each state on one thread, opt.threads is not used inside); the results are the same
// bytes as stepping each state alone. st (Nullable, n) gets each state's status of its first
// failing step (VD_OK when none); a failed state stops there. Returns VD_ERR_VALUE when any
// state failed, else VD_OK. The caller may change colliders, forces and ties of each state
// between calls.
vd_status vd_sim_step_batch(const vd_sim_model* m, vd_sim_data** d, int n, int nsteps, int threads,
                            vd_status* st);

// Settling: what to run and when to stop.
typedef struct vd_sim_settle_def {
  int statics;           // 1: solve the static equilibrium directly (quasi-static Newton steps)
  double ke_tol;         // dynamics: stop when kinetic energy stays < ke_tol for 0.25 s (J) ...
  double disp_tol;       // ... or statics: when the largest node move of a step < disp_tol (m)
  double max_time;       // dynamics: give up after this much simulated time (s)
  int max_steps;         // statics: give up after this many steps
  double extra_damping;  // dynamics: mass damping rate added while settling (1/s)
  void (*progress)(void* user, double frac, int steps);  // Nullable: called after each step with
                         // the share of the budget used (max_time or max_steps) and the steps
  void* user;            // passed to progress
} vd_sim_settle_def;

// Defaults: statics 0, ke_tol 1e-9 J, disp_tol 1e-9 m, max_time 10 s, max_steps 400,
// extra_damping 5 1/s, no progress.
vd_sim_settle_def vd_sim_settle_def_default(void);
// Settle the state under the current loads. *converged (Nullable) tells whether the tolerance
// was met; *steps (Nullable) the steps taken. Fractures may happen on the way.
vd_status vd_sim_settle(const vd_sim_model* m, vd_sim_data* d, const vd_sim_settle_def* s,
                        int* converged, int* steps);

// Add an external collider; returns its index or -1 when VD_SIM_MAX_COLLIDERS are in use.
int vd_sim_add_collider(vd_sim_data* d, const vd_sim_collider* c);
// Move collider i to a new pose for the next step; its velocity becomes (pos - old) / dt.
void vd_sim_set_collider_pose(const vd_sim_model* m, vd_sim_data* d, int i, vd_vec3 pos, vd_quat q);
// Add a user tie (compliance > 0); returns its index or -1 when out of memory.
int vd_sim_add_tie(vd_sim_data* d, int node, vd_vec3 target, double compliance);

// Largest wind velocity component of a time series (m/s) and most rows.
#define VD_SIM_MAX_WIND 1000.0
#define VD_SIM_MAX_WIND_ROWS 10000000
// Parse a wind time series (CSV rows t,vx,vy,vz in s and m/s, times not decreasing; a first
// line that is not numeric is a header; '#' starts a comment) for opt.wind_series; name
// (Nullable) is used in errors, which give line and column. *rows (nrows x 4) is allocated:
// free it with vd_free(*rows, *n * 4 * sizeof(double)).
vd_status vd_sim_parse_wind(const char* text, size_t len, const char* name, double** rows, int* n,
                            vd_error* err);
// Read and parse a wind time series file (see vd_sim_parse_wind).
vd_status vd_sim_read_wind(const char* path, double** rows, int* n, vd_error* err);

// Node that represents an organ: the sphere centre of a fruit, else the node of the organ
// farthest from the root. label may be a label name or an organ name; instance 0 picks the
// first instance carrying it. Returns -1 when nothing matches.
int vd_sim_find_organ(const vd_sim_model* m, const vd_model* plant, const char* label, int instance);
// Kinetic energy of the state (J).
double vd_sim_kinetic_energy(const vd_sim_model* m, const vd_sim_data* d);
// Largest distance of any node from its modelled position (m); *node (Nullable) gets the node.
double vd_sim_max_displacement(const vd_sim_model* m, const vd_sim_data* d, int* node);

// Write the deformed plant into a plant state (node, segment frames, spheres, mesh vertices,
// broken segments: a segment spanning a broken joint is marked in seg_broken with where it broke
// in seg_cut, so it is drawn as two parts); plant must be the model m was built from.
void vd_sim_to_plant(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant,
                     vd_data* out);
// Same into an editable spec (positions, sphere centres, mesh vertices, segment up vectors);
// spec must be the one plant was compiled from. Parts that broke off become separate pieces: a
// segment spanning a broken joint is split there (new nodes at both faces of the break, the
// stump marked VD_SEG_TIP), and parents and attachment nodes across a break are removed (-1);
// labels and instances are kept. VD_ERR_NOMEM when the new elements do not fit (the spec then
// holds the positions, pieces partly cut).
vd_status vd_sim_to_spec(const vd_sim_model* m, const vd_sim_data* d, vd_plant_spec* spec);

// ---------------------------------------------------------------------------------------------
// stress from a state (geometry only: works on any state, frames read back included)

// Elastic moment of each segment's joint with its parent from the change of curvature and twist,
// M = C_b / (compliance l-bar) (N m), in the parent's material frame: bending about d1 and d2,
// twisting about d3 (nseg x 3); 0 for broken joints and segments without a parent.
void vd_sim_joint_moment(const vd_sim_model* m, const vd_sim_data* d, double* out);
// Largest bending stress of each rod segment (Pa): 4 |M_bend| / (pi r^3) of the joints at its
// two ends, with its parent and with its children (nseg).
void vd_sim_seg_stress(const vd_sim_model* m, const vd_sim_data* d, double* out);
// The same per plant segment: the largest over the rod segments that resample it, NaN where no
// rod segment does; plant must be the model m was built from (plant->nseg).
void vd_sim_plant_stress(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant,
                         double* out);

// ---------------------------------------------------------------------------------------------
// reading the frames `verdant sim -o DIR` writes (frames.bin, frames.jsonl; docs/formats.md)

// An open frames file.
typedef struct vd_sim_frames vd_sim_frames;

// Open a frames file and index it: sizes checked against the file, times finite and never
// decreasing; errors name the file and the byte offset (binary) or the line (JSON Lines).
vd_status vd_sim_frames_open(const char* path, vd_sim_frames** out, vd_error* err);
// Close a frames file (NULL is fine).
void vd_sim_frames_close(vd_sim_frames* f);
// Number of frames.
int vd_sim_frames_count(const vd_sim_frames* f);
// Node count (spares included) and segment count of every frame.
void vd_sim_frames_size(const vd_sim_frames* f, int* nnode_all, int* nseg);
// Time of frame k (s).
double vd_sim_frames_time(const vd_sim_frames* f, int k);
// Frame nearest to time t (s), the earlier one on a tie; -1 when there are no frames.
int vd_sim_frames_nearest(const vd_sim_frames* f, double t);
// Put frame k into state d of rod model m: time, node positions, segment frames and broken
// joints (whose spare nodes take their share of mass, as in a fracture); velocities, multipliers
// and events cleared. VD_ERR_FORMAT when the frame does not fit m or holds non-finite numbers.
vd_status vd_sim_frames_load(vd_sim_frames* f, int k, const vd_sim_model* m, vd_sim_data* d,
                             vd_error* err);

// ---------------------------------------------------------------------------------------------
// validation against analytic references (docs/validation.md)

// One checked quantity.
typedef struct vd_validate_result {
  char name[64];     // case name ("cantilever_tip_load")
  char form[16];     // "discrete" (the discrete model's exact value) or "continuum"
  char quantity[48]; // what is compared ("tip deflection (m)")
  double measured;   // simulated value
  double reference;  // reference value
  double error;      // relative error |measured - reference| / |reference| (or absolute, see note)
  double tolerance;  // allowed error
  int pass;          // 1 when error <= tolerance
  char note[160];    // sizes and the reference's source
} vd_validate_result;

// Validation settings.
typedef struct vd_validate_def {
  int full;            // 1: the full sweep (finer rods, more cases), else the quick sizes
  const char* filter;  // Nullable: run only cases whose name contains this text
  void (*progress)(void* user, const char* name);  // Nullable: called before each case
  void* user;          // passed to progress
  const vd_model* plant;  // Nullable: also run the sag-free gate on this plant (e.g. the tomato)
} vd_validate_def;

// A growing list of validation results (for the modules' own cases).
typedef struct vd_validate_list {
  vd_validate_result* r;  // results (n, capacity cap)
  int n, cap;
} vd_validate_list;

// Append a checked quantity: error relative to the reference (absolute when abs_err is set or
// the reference is 0); pass when finite and within tol. note is printf-style. 0 when out of
// memory.
int vd_validate_add(vd_validate_list* l, const char* name, const char* form, const char* quantity,
                    double measured, double reference, double tol, int abs_err, const char* note,
                    ...) __attribute__((format(printf, 9, 10)));
// Hand the list's results to a caller as vd_sim_validate does (*out exactly n entries, or NULL).
vd_status vd_validate_finish(vd_validate_list* l, vd_validate_result** out, int* n, vd_error* err);

// Run the validation cases; *out (free with vd_free(*out, *n * sizeof **out)) gets the results.
vd_status vd_sim_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                          vd_error* err);

// =============================================================================================
// mass-spring trees with a rigid part: ML-Tree and MRL-Tree (Lim & Gobeawan 2024, seed 001)
//
// A plant becomes point masses on its stem and root nodes, joined by one spring per internode and
// by angle springs; leaves, petioles, fruits and flowers add their mass and their drag area to
// the stem node they hang from. Springs follow the paper (k = k0 d / l, k0 larger for woody
// internodes, distance springs between alternate nodes) or the wood's elasticity (k = E A / l and
// hinge springs of stiffness E I / l-bar, which resist bending to first order where alternate
// springs resist it only to second order, docs/physics.md). Damping is eq. 5,
// c sqrt(k (m1 + m2)) (v_j - v_i). A substep advances by the approximate implicit Euler of Kang et
// al. 2001 (eq. 3) or 2000 (eq. 4), or by a linearised backward Euler solved by preconditioned
// conjugate gradients (Baraff & Witkin 1998), which couples the whole tree in every substep.
// MRL-Tree: nodes at least def.rigid_age old form one rigid body (quaternion, RK4; eqs. 6-8 as
// they join), stepped before the springs. Below-ground nodes hold while the net force on them is
// below their maximum soil resistance (Pang et al. 2023 eq. 12 or an Imhoff et al. 2016 eqs.
// 13-14 pedotransfer function).
//
// Usage:
//   vd_mss_def def = vd_mss_def_default();                 // material springs, no rigid part
//   vd_mss_model* m; vd_mss_build(plant_model, &def, NULL, &m, &err);
//   vd_mss_data* d = vd_mss_data_create(m);
//   for (int i = 0; i < 50; i++) vd_mss_step(m, d);        // 50 substeps of m->opt.dt
//   vd_mss_stress(m, d);                                   // d->node_stress, d->spring_stress

// Integrators of a substep.
typedef enum vd_mss_integrator {
  VD_MSS_EQ3 = 0,     // approximate implicit Euler, Kang et al. 2001 (the paper's eq. 3)
  VD_MSS_EQ4,         // approximate implicit Euler, Kang et al. 2000 (the paper's eq. 4)
  VD_MSS_IMPLICIT     // linearised backward Euler over the whole tree, conjugate gradients
} vd_mss_integrator;

// Spring laws.
typedef enum vd_mss_springs {
  VD_MSS_PAPER = 0,   // k = k0 d / l (eq. 2) for internodes and alternate-node distance springs
  VD_MSS_MATERIAL     // internodes k = E pi r^2 / l, hinges E pi r^4 / (4 l-bar) at every node
} vd_mss_springs;

// Air drag on the moving tree.
typedef enum vd_mss_drag {
  VD_MSS_DRAG_NONE = 0,   // none
  VD_MSS_DRAG_STOKES,     // 6 pi eta R v on each node (eq. 11; valid only for Re < 1)
  VD_MSS_DRAG_QUADRATIC   // 0.5 rho C_d A |u| u on the relative air velocity (the default)
} vd_mss_drag;

// Wind load.
typedef enum vd_mss_wind {
  VD_MSS_WIND_PAPER = 0,  // eqs. 9-10: P = 0.613 |v_wind|^2 on the node's cross-section pi r^2
  VD_MSS_WIND_AREA        // the rods' load: the normal component of the relative air velocity
                          // on each internode's projected area 2 r l and on the leaf area
} vd_mss_wind;

// Gravitropism.
typedef enum vd_mss_gravitropism {
  VD_MSS_GRAVI_NONE = 0,  // none
  VD_MSS_GRAVI_SINE,      // the paper: an upward force k sin A across each internode (not buds)
  VD_MSS_GRAVI_BASTIEN    // Bastien et al. 2013 AC model: the rest curvature of growing
                          // internodes changes by dC/dt = -beta sin A - gamma C (hinge springs)
} vd_mss_gravitropism;

// How below-ground nodes are held.
typedef enum vd_soil_method {
  VD_SOIL_CLAMP = 0,      // fixed (a pot; no soil model)
  VD_SOIL_PANG2023,       // method 1: Pang et al. 2023 eq. 12 (cone penetration, depth h)
  VD_SOIL_IMHOFF2016      // method 2: ln SR pedotransfer function, F = 1e6 SR A (eqs. 13-14)
} vd_soil_method;

// Soil: composition, the resistance law and its coefficients (sources in docs/physics.md).
typedef struct vd_soil {
  vd_soil_method method;  // resistance law
  double ground;          // ground height z (m): nodes of roots below it are in the soil
  double clay;            // clay content (% by mass)
  double organic;         // organic matter content (% by mass)
  double water;           // volumetric water content theta (m^3/m^3), > 0
  double bulk_density;    // dry bulk density BD (Mg/m^3 = g/cm^3); gamma = 1000 BD kg/m^3
  double poisson;         // Poisson ratio mu of the soil, method 1 (-), < 0.5
  double residual_pressure; // P_a of method 1 (Pa)
  double cone_radius;     // r of method 1 (m); 0: the root's radius at the node
  double ptf[8];          // method 2: ln SR = c0 + c1 clay + c2 OM + (d0 + d1 clay + d2 OM) ln theta
                          //                   + (e0 + e1 clay) ln BD; order c0 c1 c2 d0 d1 d2 e0 e1
  double sr_max;          // method 2: SR is clamped to this (MPa)
  double stiffness;       // rods engine: stiffness of each node's hold in the soil (N/m)
} vd_soil;

// Soil presets: "clamp", "loam", "sandy-loam", "clay", "singapore-residual" (the composition of
// each and its source in docs/physics.md; method 2 with the da Silva & Kay 1997 coefficients,
// since Imhoff et al. 2016's could not be read). VD_ERR_NAME for an unknown name.
vd_status vd_soil_preset(const char* name, vd_soil* out);
// Maximum resistance of a soil node (N): depth below ground (m), root radius (m) and the lateral
// surface area the node holds by (m^2, method 2). 0 above ground; INFINITY for VD_SOIL_CLAMP.
double vd_soil_max_force(const vd_soil* s, double depth, double radius, double area);
// Check a soil's numbers (water > 0, density > 0, Poisson below 0.5, ...); errors name the field.
vd_status vd_soil_check(const vd_soil* s, vd_error* err);

// Soil for the rods engine, instead of clamped roots: every root node below the ground is held by
// a tie to the point where it grew, of stiffness soil->stiffness; after each step a tie that pulls
// harder than the node's maximum resistance (vd_soil_max_force) slips so that it pulls exactly
// that much (the node has yielded). Build the rod model with def.clamp_roots = 0; the stem's
// collar (the pot length of its first segment) stays held: rods join the stem and its roots at
// the base without a bending joint (no parent between them), so the roots cannot hold it upright.
typedef struct vd_sim_soil {
  int n;              // held nodes
  int* node;          // rod node (n)
  int* tie;           // its tie in the state (n)
  double* fmax;       // its maximum resistance (N) (n)
  unsigned char* yielded;  // 1 once its tie has slipped (n)
  int nyielded;       // nodes that have slipped
  double ground;      // ground height (m)
  size_t nbytes;      // size of the block
} vd_sim_soil;

// Tie the root nodes of a rod state into the soil (a clamp soil holds them with stiff ties that
// never slip). VD_ERR_NOMEM, or VD_ERR_VALUE for a bad soil.
vd_status vd_sim_soil_attach(const vd_sim_model* m, vd_sim_data* d, const vd_soil* soil,
                             vd_sim_soil** out, vd_error* err);
// After a step: ties beyond their node's resistance slip.
void vd_sim_soil_update(const vd_sim_model* m, vd_sim_data* d, vd_sim_soil* s);
// Free (NULL is fine).
void vd_sim_soil_destroy(vd_sim_soil* s);

// Wood of a species: stiffness, density and strength for mass-spring trees (docs/physics.md).
typedef struct vd_wood {
  const char* name;    // species name ("hopea-odorata")
  double young;        // modulus of elasticity along the grain (Pa)
  double density;      // density of the wood (kg/m^3)
  double mor;          // modulus of rupture, static bending strength (Pa)
  const char* source;  // where the numbers come from
} vd_wood;

// Wood of a species by name: "generic-broadleaf" (green hardwood), "hopea-odorata" (merawan,
// the seed's species). VD_ERR_NAME for an unknown name; vd_wood_count/vd_wood_get list them.
vd_status vd_wood_species(const char* name, vd_wood* out);
// Number of species in the table.
int vd_wood_count(void);
// Species i of the table (0 <= i < vd_wood_count()).
const vd_wood* vd_wood_get(int i);

// A rigid body in the MRL manner: state for RK4 with a quaternion.
typedef struct vd_rigid {
  int n;              // member nodes
  double mass;        // M (kg)
  vd_vec3 x;          // centre of mass (m)
  vd_quat q;          // orientation: body frame to world
  vd_vec3 p;          // linear momentum (kg m/s)
  vd_vec3 L;          // angular momentum about x (kg m^2/s)
  double ibody[9];    // inertia about x in the body frame (kg m^2), row-major 3 x 3
  double ibody_inv[9];// its inverse (1 / (kg m^2))
} vd_rigid;

// Angular velocity of a rigid body (rad/s, world frame).
vd_vec3 vd_rigid_omega(const vd_rigid* b);
// Kinetic energy of a rigid body (J).
double vd_rigid_energy(const vd_rigid* b);
// Advance a rigid body by h (s) under a constant force (N) and torque about x (N m), classical
// fourth-order Runge-Kutta on x, q, p, L; q renormalised after the step.
void vd_rigid_step(vd_rigid* b, vd_vec3 force, vd_vec3 torque, double h);

// Mass-spring settings for vd_mss_build.
typedef struct vd_mss_def {
  vd_mss_springs springs;   // spring law
  double k0_green;          // paper: k0 of eq. 2 for green internodes (N/m)
  double k0_wood;           // paper: k0 once the internode is woody (N/m)
  double woody_age;         // internodes at least this old are woody (model time unit, years)
  double rigid_age;         // MRL: nodes at least this old join the rigid body; INFINITY: ML only
  double young_green;       // material: Young's modulus of green internodes (Pa)
  double young_wood;        // material: Young's modulus of woody internodes and roots (Pa)
  double density_green;     // density of green internodes (kg/m^3)
  double density_wood;      // density of woody internodes and roots (kg/m^3)
  double mor;               // modulus of rupture of the wood (Pa); INFINITY: nothing breaks
  double mor_green;         // ... of green internodes (Pa)
  double leaf_areal_density;// leaf lamina mass per area (kg/m^2)
  double min_mass;          // the smallest node mass, given to new nodes (eq. 1) and bases (kg)
  double damping;           // c of eq. 5 (-)
  double fix_height;        // stem nodes at most this far above the ground are clamped when the
                            // plant has no roots (m)
  vd_soil soil;             // how below-ground root nodes are held
  int max_nodes;            // most nodes; more is VD_ERR_LIMIT
} vd_mss_def;

// Defaults (sources in docs/physics.md): springs material, k0_green 1e4 N/m, k0_wood 1e5 N/m,
// woody_age 1, rigid_age INFINITY (ML-Tree), young_green 1e9 Pa, young_wood 1e10 Pa,
// density_green 1000 kg/m^3, density_wood 900 kg/m^3, mor 5.5e7 Pa, mor_green 1.5e7 Pa,
// leaf_areal_density 0.22 kg/m^2, min_mass 1e-4 kg, damping 1 (critical for equal masses),
// fix_height 0.01 m, soil clamp at ground 0, max_nodes 1000000.
vd_mss_def vd_mss_def_default(void);

// Run settings, stored in the model; may be changed between substeps.
typedef struct vd_mss_opt {
  double dt;                    // substep h (s)
  vd_mss_integrator integrator; // substep integrator
  int cg_iterations;            // implicit: most conjugate-gradient iterations per substep
  double cg_tolerance;          // implicit: relative residual that ends the iterations (-)
  vd_vec3 gravity;              // gravitational acceleration (m/s^2)
  vd_vec3 wind;                 // mean wind velocity (m/s)
  double gust_amplitude;        // gusts wind * (1 + a sin(2 pi t / gust_period)) (-), as the rods
  double gust_period;           // (s)
  const double* wind_series;    // Nullable: rows (t s, vx, vy, vz m/s) replacing wind and gusts;
                                // owned by the caller (nwind x 4)
  int nwind;                    // rows of wind_series
  vd_mss_wind wind_model;       // wind load
  double air_density;           // rho_air (kg/m^3); P = rho |v|^2 / 2 = 0.613 |v|^2 at 1.226
  double drag_cd;               // drag coefficient of internodes and nodes (-)
  double leaf_cd;               // drag coefficient of leaf laminae (-)
  vd_mss_drag drag;             // air drag on the moving tree
  double viscosity;             // eta of Stokes drag (Pa s)
  int light;                    // 1: phototropism toward light_pos
  vd_vec3 light_pos;            // light point (m)
  double light_k;               // phototropism F = light_k / d^2 toward the light on buds (N m^2)
  vd_mss_gravitropism gravitropism; // gravitropism model
  double gravi_k;               // sine law: F = gravi_k sin A across each internode (N)
  double bastien_beta;          // AC model: graviceptive sensitivity beta (1/(m time unit))
  double bastien_gamma;         // AC model: proprioceptive sensitivity gamma (1/time unit)
  double growth_zone_age;       // AC model: internodes younger than this curve (time unit)
  int soil;                     // 1: below-ground nodes hold only up to their soil resistance
  int breaking;                 // 1: an internode breaks when its stress exceeds its MOR
  double strain_limit;          // internodes stretched or shortened by more than this after a
                                // substep are put back to it, parents first (Provot 1995); 0 off
  int rigid_release;            // 1: a rigid part nothing holds (its soil gave way) is released into
                                // the springs; 0: stepped by RK4 against them (the paper's; unstable)
} vd_mss_opt;

// Defaults: dt 0.01 s, integrator implicit, cg_iterations 500, cg_tolerance 1e-8, gravity
// (0, 0, -9.81) m/s^2, no wind, gust_period 2 s, wind_model area, air_density 1.226 kg/m^3,
// drag_cd 1.2, leaf_cd 0.1, drag quadratic, viscosity 1.81e-5 Pa s, no light, light_k 1 N m^2,
// no gravitropism, gravi_k 0.1 N, bastien_beta 0.5 1/(m year), bastien_gamma 1 1/year,
// growth_zone_age 2 years, soil 1, breaking 1, strain_limit 1e-4, rigid_release 1.
vd_mss_opt vd_mss_opt_default(void);

// node flags
#define VD_MSS_FIXED 1u   // clamped: never moves
#define VD_MSS_SOIL 2u    // in the soil: held up to node_soil (N)
#define VD_MSS_TIP 4u     // a bud: nothing grows from it (phototropism acts here)
#define VD_MSS_ROOT 8u    // on a root
#define VD_MSS_CROWN 16u  // the root crown of a plant rooted in a soil: held, with its rotation
                          // resisted, while the stem's wrench is within the anchorage

// The mass-spring model of one plant: read-only between age steps. Arrays live in one block.
typedef struct vd_mss_model {
  int nnode;              // point masses (stem and root nodes of the plant)
  int ninter;             // internode springs: springs 0 .. ninter-1, one per stem/root segment
  int nspring;            // all springs: internodes, then alternate-node springs
  int nhinge;             // hinge (bending) springs
  int nplant;             // nodes of the plant it was built from
  vd_mss_opt opt;         // run settings
  vd_mss_springs springs; // spring law it was built with
  double rigid_age;       // nodes at least this old join the rigid body (time unit)
  double damping;         // c of eq. 5 (-)
  // nodes (nnode)
  int* node_plant;        // plant node
  int* plant_node;        // mass-spring node of each plant node, -1 if none (nplant); the bases
                          // of axes that start at one point (roots and trunk from the axiom) share
                          // one node
  int* node_parent;       // node at the other end of its owner internode, -1 for bases
  int* node_owner;        // its owner internode (the spring ending at it), -1 for bases
  unsigned* node_flags;   // VD_MSS_* flags
  vd_vec3* node_rest;     // rest position (m)
  double* node_mass;      // mass: owner internode volume x density + attached organs (kg)
  double* node_radius;    // radius of the owner internode at the node (m)
  double* node_age;       // age of the owner internode (time unit)
  double* node_leaf_area; // leaf lamina area hanging from the node (m^2)
  double* node_soil;      // maximum soil resistance (N): 0 above ground
  int* node_axis;         // branch axis of its owner internode (plant seg_axis), -1 for bases
  // springs (nspring)
  int* spring_node;       // end nodes (nspring x 2); an internode runs from node 0 to node 1
  int* spring_plant;      // plant segment of an internode, -1 for angle springs
  double* spring_k;       // stiffness (N/m)
  double* spring_l0;      // rest length (m)
  double* spring_radius;  // internode radius at node 0 and node 1 (m) (nspring x 2)
  double* spring_mor;     // modulus of rupture of an internode (Pa)
  // hinges (nhinge): a hinge at node b keeps arm b->c at its rest angle to arm b->a
  int* hinge_node;        // a, b, c (nhinge x 3); a = -1: a fixed arm along hinge_p0
  double* hinge_k;        // rotational stiffness E I / l-bar (N m/rad)
  vd_vec3* hinge_p0;      // rest direction of arm b->a (unit)
  vd_vec3* hinge_q0;      // rest direction of arm b->c (unit)
  int* node_pre;          // position of each node in node_order (nnode)
  int* node_order;        // nodes in pre-order: every node before its subtree (nnode)
  int* node_last;         // position in node_order of the last node of each node's subtree (nnode)
  int main_tip;           // node at the top of the main stem, -1 if none
  int base;               // the base node of the stem (where the roots meet it), -1 if none
  double height0;         // rest height of the highest node above the base (m)
  double total_mass;      // sum of node masses (kg)
  int crown;              // the root crown node (VD_MSS_CROWN), -1 if none
  double anchor_force;    // anchorage of the crown: sum of its root nodes' resistances (N)
  double anchor_moment;   // ... and the moment they can give about it, sum F_max,i |x_i - x_c| (N m)
  double ground;          // with a crown: the ground (z, m) that stem nodes rest on, not pass
  size_t nbytes;          // size of the single allocation
} vd_mss_model;

// One event of a mass-spring run.
typedef enum vd_mss_event_kind {
  VD_MSS_BREAK = 0,   // an internode broke: the subtree beyond it is removed
  VD_MSS_UPROOT,      // the base tilted beyond the uprooting angle after its roots gave way
  VD_MSS_ANCHOR       // the stem's wrench on the root crown exceeded the soil's anchorage: the
                      // root plate gave way (the crown turns freely from then on)
} vd_mss_event_kind;

typedef struct vd_mss_event {
  vd_mss_event_kind kind; // what happened
  double time;            // simulation time (s)
  int node;               // break: the node at the base of the broken internode; uproot: base
  int spring;             // break: the internode; uproot: -1
  double stress;          // break: its stress (Pa); uproot: tilt (rad); anchor: the larger of
                          // moment / anchor_moment and force / anchor_force (-)
  double limit;           // break: its modulus of rupture (Pa); uproot: the tilt limit (rad);
                          // anchor: the crown's moment (N m)
  int removed;            // break: nodes removed with the subtree
} vd_mss_event;

// The state of a mass-spring model.
typedef struct vd_mss_data {
  int nnode, nspring;     // sizes copied from the model
  double time;            // simulation time (s)
  int64_t nstep;          // substeps taken
  vd_vec3* pos;           // position (m) (nnode)
  vd_vec3* vel;           // velocity (m/s) (nnode)
  vd_vec3* force;         // external force set by the caller, kept across steps (N) (nnode)
  double* mass;           // current mass (kg) (nnode); the growth loop changes it (eq. 1)
  vd_vec3* fext;          // external load of the last substep: gravity, wind, drag, tropisms,
                          // soil reaction, caller's force (N) (nnode)
  vd_vec3* acc;           // acceleration over the last substep (m/s^2) (nnode)
  vd_vec3* dv;            // velocity change of the last substep (m/s) (eq. 4 reads it) (nnode)
  unsigned char* held;    // 1 when the soil held the node in the last substep (nnode)
  unsigned char* yielded; // 1 once the net force on it has exceeded its soil resistance (nnode)
  unsigned char* removed; // 1 once it fell with a broken branch (nnode)
  unsigned char* rigid;   // 1 when it belongs to the rigid body (nnode)
  vd_vec3* body;          // position in the rigid body's frame when rigid (m) (nnode)
  unsigned char* spring_broken; // 1 when the spring is gone (nspring)
  double* node_stress;    // stress of the section at each node, on its owner internode (Pa)
  double* spring_stress;  // largest stress of each internode: axial + bending (Pa) (nspring)
  vd_rigid rb;            // the rigid part (rb.n = 0: none)
  double uproot_tilt;     // tilt of the base that counts as uprooting (rad)
  int uprooted;           // 1 after the uprooting event
  int anchor_failed;      // 1 once the root crown's anchorage gave way (VD_MSS_ANCHOR)
  double anchor_load;     // largest share of the anchorage the stem has used: max over substeps
                          // of |M| / anchor_moment and |F| / anchor_force (-)
  vd_mss_event* event;    // events (nevent, capacity cap_event)
  int nevent, cap_event;
  int64_t cg_iterations;  // conjugate-gradient iterations over all substeps
  int64_t cg_unconverged; // substeps whose iterations ended above the tolerance
  int64_t nonfinite;      // substeps that made a non-finite state (undone, velocities zeroed)
  void* work;             // scratch (private)
  size_t work_bytes;      // its size
  size_t nbytes;          // size of the state block
} vd_mss_data;

// Build the mass-spring model of a compiled plant. rest (Nullable, plant->nnode x 3) replaces the
// plant's node positions as the rest shape. Errors name the offending element; VD_ERR_VALUE for
// bad settings (negative density, zero time step, ...), VD_ERR_LIMIT beyond def->max_nodes.
vd_status vd_mss_build(const vd_model* plant, const vd_mss_def* def, const double* rest,
                       vd_mss_model** out, vd_error* err);
// Check run settings (time step > 0, finite vectors, ...); errors name the field.
vd_status vd_mss_opt_check(const vd_mss_opt* o, vd_error* err);
// Free a model (NULL is fine).
void vd_mss_model_destroy(vd_mss_model* m);
// New state at the rest shape, at rest, no rigid part; NULL when out of memory.
vd_mss_data* vd_mss_data_create(const vd_mss_model* m);
// Free a state (NULL is fine).
void vd_mss_data_destroy(vd_mss_data* d);
// Advance one substep of m->opt.dt (Algorithm 1; Algorithm 2 when the state has a rigid part).
void vd_mss_step(const vd_mss_model* m, vd_mss_data* d);
// Join the flagged nodes (join[i] != 0, nnode) to the rigid body by eqs. 6-8; paper_eq8 1 adds
// the old body's angular momentum as eq. 8 is written, 0 the corrected term (docs/physics.md).
// lcheck (Nullable, 2 x 3) gets the angular momentum about the new centre of mass the joined
// nodes and the old body really have, and the one eq. 8 gives.
void vd_mss_rigid_join(const vd_mss_model* m, vd_mss_data* d, const unsigned char* join,
                       int paper_eq8, double* lcheck);
// Recompute the rigid body's mass, centre and inertia from its members' current masses and
// positions, keeping p and the angular momentum (docs/physics.md); members flagged removed leave
// with their momentum.
void vd_mss_rigid_update(const vd_mss_model* m, vd_mss_data* d);
// Rebuild the rigid body from the members it has now, which move rigidly (v = V + omega x r) at
// angular velocity omega (rad/s): p and the angular momentum are theirs (members that are gone
// took theirs away).
void vd_mss_rigid_refit(const vd_mss_model* m, vd_mss_data* d, vd_vec3 omega);
// Stress of every internode and node section (d->spring_stress, d->node_stress) from the loads of
// the last substep: the subtree beyond each section is in equilibrium with the section's force N
// and moment M, sigma = |N| / (pi r^2) + 4 |M| / (pi r^3).
void vd_mss_stress(const vd_mss_model* m, vd_mss_data* d);
// The same with the external loads recomputed at the present state (positions, velocities,
// time): for a model just built or after branches were removed, whose last substep's loads are
// gone (its accelerations are those of the last substep, zero on a new model: quasi-static).
void vd_mss_stress_now(const vd_mss_model* m, vd_mss_data* d);
// Total linear momentum of the free nodes and the rigid body (kg m/s).
vd_vec3 vd_mss_momentum(const vd_mss_model* m, const vd_mss_data* d);
// Kinetic energy (J).
double vd_mss_kinetic_energy(const vd_mss_model* m, const vd_mss_data* d);
// Largest distance of a node from its rest position (m); *node (Nullable) gets it.
double vd_mss_max_displacement(const vd_mss_model* m, const vd_mss_data* d, int* node);
// Height of the highest node that is not removed, above the base's rest height (m).
double vd_mss_height(const vd_mss_model* m, const vd_mss_data* d);
// Gravitropism by the AC model of Bastien et al. 2013 over a time t (time unit) in nsub explicit
// substeps: the rest bend of every hinge whose child internode is younger than
// opt.growth_zone_age changes by dC/dt = -beta sin A - gamma C (A the internode's angle to the
// vertical in the rest shape, C = bend / l-bar); rest (nnode) starts as the model's rest shape
// and gets the new one (the subtree beyond each bent hinge turns with it).
void vd_mss_bastien(const vd_mss_model* m, const vd_mss_data* d, double t, int nsub, vd_vec3* rest);
// Validation cases of the mass-spring and rigid-body models (docs/validation.md): *out gets them
// (free with vd_free(*out, *n * sizeof **out)); def as for vd_sim_validate.
vd_status vd_mss_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                          vd_error* err);
// Wind velocity at time t (m/s): a series (linear between rows, held at the ends) when given,
// else mean * (1 + gust_amplitude sin(2 pi t / gust_period)); the rods use the same function.
vd_vec3 vd_wind_at(vd_vec3 mean, double gust_amplitude, double gust_period, const double* series,
                   int nseries, double t);

#ifdef __cplusplus
}
#endif
#endif
