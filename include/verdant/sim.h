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
#include "verdant/phys.h"

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

// A user tie: a node pulled toward a target point by a spring (a displacement pull). A tie with
// max_force > 0 is a friction-limited hold (a grasp): the part of its pull across axis may not
// exceed max_force; at every solver iteration, before the tie enters the solve, a target farther
// than that lets its target slide toward the node (slip grows by the distance), so the limit
// holds inside the solve, not after it. Along axis (the fingers' closing direction) it holds.
typedef struct vd_sim_tie {
  int node;           // rod node
  vd_vec3 target;     // target point (m), may move each step
  double compliance;  // 1 / stiffness (m/N), > 0
  double max_force;   // largest pull across axis (N); 0: unlimited (vd_sim_add_tie's default)
  vd_vec3 axis;       // unit direction left unlimited; zero: the whole pull limited
  double slip;        // how far the target has slid so far (m)
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
// The constraint force (N) and moment (N m) that the joint of segment seg with its parent
// carried in the last step, as the fracture test measures them (the multipliers' generalised
// forces J^T lambda / h^2); 0 for a broken joint, a segment without a parent and before a step.
void vd_sim_joint_load(const vd_sim_model* m, const vd_sim_data* d, int seg, double* force, double* moment);
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


// Run the validation cases; *out (free with vd_free(*out, *n * sizeof **out)) gets the results.
vd_status vd_sim_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                          vd_error* err);


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

#ifdef __cplusplus
}
#endif
#endif
