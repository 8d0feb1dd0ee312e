// SPDX-License-Identifier: MIT
// verdant mss: mass-spring trees with a rigid part, ML-Tree and MRL-Tree (Lim & Gobeawan 2024,
// seed 001).
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
#ifndef VERDANT_MSS_H
#define VERDANT_MSS_H

#include "verdant/core.h"
#include "verdant/phys.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

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

// Kinds of numerical warnings, counted in vd_mss_data::warning (as the rods' vd_sim_warning).
typedef enum vd_mss_warning {
  VD_MSS_WARN_NONFINITE = 0,  // a substep made a non-finite state: undone, the motion stopped
  VD_MSS_WARN_CG,             // conjugate gradients ended above their tolerance (substep kept)
  VD_MSS_WARN_COUNT
} vd_mss_warning;

// Lower-case name of a warning kind ("nonfinite", "cg").
const char* vd_mss_warning_name(vd_mss_warning w);

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
  int64_t nwarning;       // numerical warnings of every kind (the sum of warning[])
  int64_t warning[VD_MSS_WARN_COUNT];  // numerical warnings by kind (vd_mss_warning)
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
// The step contract of both engines (vd_sim_step): a substep that makes a non-finite state is
// put back to its start with the motion stopped, counted as VD_MSS_WARN_NONFINITE, and
// VD_ERR_VALUE is returned; else VD_OK (conjugate gradients that end above their tolerance are
// counted as VD_MSS_WARN_CG, the substep kept). The state never holds a non-finite number.
vd_status vd_mss_step(const vd_mss_model* m, vd_mss_data* d);
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
// and gets the new one (the subtree beyond each bent hinge turns with it). Root internodes keep
// their rest shape (the soil holds them as they grew).
void vd_mss_bastien(const vd_mss_model* m, const vd_mss_data* d, double t, int nsub, vd_vec3* rest);
// Validation cases of the mass-spring and rigid-body models (docs/validation.md): *out gets them
// (free with vd_free(*out, *n * sizeof **out)); def as for vd_sim_validate.
vd_status vd_mss_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                          vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
