// SPDX-License-Identifier: MIT
// verdant growth: a plant grown by its L-system with physics between the growth steps
// (Lim & Gobeawan 2024, Algorithms 1 and 2). Each age step is one derivation step of the
// L-system (a unit of age: the file records internode ages with SetAge), the turtle's plant, and
// def.substeps physics substeps of a mass-spring tree (mss), a mass-spring tree with a rigid
// part (mrl) or Cosserat rods (rods).
//
// State carries over by stable ids: every module of the L-string keeps an id while it is
// rewritten into its own kind (I -> I), so each plant node is known from one step to the next.
// A node that existed keeps its rest position (the shape it grew into, changed by gravitropism),
// its deformed position, velocity and mass; a new node is placed on its nearest old ancestor as
// the turtle drew it, turned with that ancestor's rest frame and deformation, and enters with the
// momentum rule of eq. 1: the ancestor's momentum m_i v_i is shared by it and its new nodes,
// v = m_i v_i / (m_i + sum m_j), m_j the smallest mass. At the end of each age step masses are
// recomputed from internode volume x density and velocities from the conserved momentum. An
// internode that breaks is cut from the L-string with everything that grows from it.
//
// Ownership: the grower borrows the lsystem (not freed, and not used by anyone else meanwhile).
//
// Usage:
//   vd_growth_def def = vd_growth_def_default();
//   def.model = VD_GROWTH_MRL; def.ages = 8;
//   vd_growth* g; vd_growth_create(ls, &def, &g, &err);       // the axiom's plant, age 0
//   while (vd_growth_age(g) < def.ages) vd_growth_step(g, &err);
//   vd_plant_spec* p; vd_growth_plant(g, &p, &err);          // deformed, with stress
#ifndef VERDANT_GROWTH_H
#define VERDANT_GROWTH_H

#include "verdant/core.h"
#include "verdant/lsys.h"
#include "verdant/mss.h"
#include "verdant/plant.h"
#include "verdant/sim.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_GROWTH_FORMAT_VERSION 1  // version of the growth run index (growth.json, docs/formats.md)

// Physics between growth steps.
typedef enum vd_growth_model {
  VD_GROWTH_MSS = 0,  // mass-spring tree (ML-Tree)
  VD_GROWTH_MRL,      // mass-spring tree with a rigid part (MRL-Tree)
  VD_GROWTH_RODS      // Cosserat rods (verdant's validated rod engine)
} vd_growth_model;

// Lower-case name of a model ("mss", "mrl", "rods").
const char* vd_growth_model_name(vd_growth_model m);

// Settings of a growth run.
typedef struct vd_growth_def {
  vd_growth_model model;  // physics between growth steps
  int ages;               // age steps the caller means to take (for progress and checks)
  int substeps;           // physics substeps per age step (>= 1)
  vd_lsys_def lsys;       // derivation settings (seed, limits; steps is not read)
  vd_turtle_def turtle;   // turtle settings
  vd_mss_def mss;         // mss / mrl: model settings (mss.rigid_age is set to INFINITY for mss)
  vd_mss_opt opt;         // mss / mrl: run settings and forces (opt.dt is the substep)
  vd_sim_def rods;        // rods: model settings; the green, wood and root materials' E, density
                          // and C_d are replaced by mss.young_*, mss.density_* and opt.drag_cd (one
                          // wood for every model); opt.breaking and mss.mor, mor_green also apply
  vd_sim_opt rod_opt;     // rods: run settings (rod_opt.dt is the substep)
  int paper_eq8;          // mrl: 1 joins nodes by eq. 8 as printed, 0 with the corrected term
  int bastien_substeps;   // explicit substeps of the AC model per age step (>= 1)
  int stress_free;        // 1: new wood is laid down without stress on the deformed tree (the
                          // rest shape follows the deformation by the new share of stiffness)
  double uproot_tilt;     // a base tilted this far after its roots gave way is uprooted (rad)
  int paper_masses;       // mss / mrl: 1 as the seed: new nodes keep the smallest mass (eq. 1)
                          // and every mass its last year's value for the whole age step, updated
                          // at its end; 0 (default): each node takes its mass now (its internode,
                          // leaves and organs this year) before the first substep, momentum kept
  int paper_rigid;        // mrl: 1 as the seed: every node old enough joins the rigid body, roots
                          // and clamped nodes too, so the body is held in place while its soil
                          // or clamp holds; 0 (default): the wood above the ground joins and the
                          // body turns about the clamped or held node it grows from
} vd_growth_def;

// Defaults: model mrl, ages 0 (the file's derivation length is the caller's to read), substeps
// 50 (the seed's), lsys and turtle defaults, mss defaults with rigid_age 3 (the seed's), opt
// defaults, rods defaults, rod_opt defaults with dt 0.01 s, paper_eq8 0, bastien_substeps 20,
// uproot_tilt 10 degrees.
vd_growth_def vd_growth_def_default(void);

// The seed's own choices, for reproducing it: paper springs (k0 d / l, alternate-node springs),
// eq. 3, the paper's wind load (eqs. 9-10 on node cross-sections, C_d 1) with Stokes drag (eq. 11),
// eq. 8 as printed, no strain limiting, a rigid part stepped by RK4 even when nothing holds it, no
// stress-free growth, masses updated at the end of each age step, the seed's rigid part (the rest
// of def is left as it is).
void vd_growth_def_paper(vd_growth_def* def);

// A tree whose height falls below this share of its drawn height has collapsed (fallen over or
// bent down): a standing tree under gravity and a storm keeps most of its height.
#define VD_GROWTH_COLLAPSE 0.5

// One event of a growth run.
typedef struct vd_growth_event {
  int kind;            // VD_MSS_BREAK, VD_MSS_UPROOT or VD_MSS_ANCHOR (rods: fractures are
                       // VD_MSS_BREAK)
  int age;             // age step in which it happened
  double time;         // simulation time (s)
  int node;            // plant node at the base of the broken internode (uproot: the base)
  int segment;         // plant segment that broke, -1 for uprooting
  double stress;       // stress at breaking (Pa); uproot: the tilt (rad); anchor: share of the
                       // anchorage (-)
  double limit;        // modulus of rupture (Pa); uproot: the tilt limit (rad); anchor: the
                       // crown's moment (N m)
  int removed;         // plant nodes removed with the broken branch
  char label[VD_LABEL_NAME_MAX];  // label name of the broken segment
} vd_growth_event;

// Summary of a growth run so far.
typedef struct vd_growth_stats {
  int age;                  // age steps taken
  double time;              // simulated time (s)
  int nnode, nseg;          // plant size now
  int nphys;                // physics nodes now (mass-spring nodes or rod nodes)
  int nrigid;               // nodes in the rigid body (mrl)
  double height;            // height of the highest stem node above the base (m)
  double height0;           // the same in the rest shape (m): the shape the physics returns to,
                            // which follows a lasting lean (stress-free growth)
  double drawn_height;      // the same as the turtle draws the L-string: unloaded, as grown,
                            // without physics; the largest at any age, so branches broken off
                            // the string do not lower it (m)
  double max_displacement;  // largest distance of a node from its rest position (m)
  double tip_displacement;  // ... of the end of the main stem (m)
  double max_stress;        // largest internode stress (Pa)
  double total_mass;        // mass of the plant (kg)
  double kinetic_energy;    // (J)
  int nbroken;              // branches broken so far
  int uprooted;             // 1 after uprooting
  int anchor_failed;        // 1 once the root crown's anchorage gave way (soil, mss/mrl)
  double anchor_load;       // largest share of the crown's anchorage used, |M| / M_a or |F| / F_a
                            // (-; 0 without a soil)
  int collapsed;            // 1 when the height fell below VD_GROWTH_COLLAPSE x the drawn height,
                            // or diverged
  int diverged;             // 1 when the state is not finite or the tree left its size (higher
                            // than 1.5 x its drawn height, or a node moved more than twice it)
  double momentum_error;    // largest |change of total momentum| at a growth event (eq. 1, the
                            // mass update, eqs. 6-7), relative to sum m |v| (-)
  double angular_error;     // mrl: largest |L eq. 8 - L true| at a join, relative (-)
  int64_t substeps;         // physics substeps taken
  int64_t cg_iterations;    // conjugate-gradient iterations (implicit integrator)
  int64_t unstable;         // substeps undone as non-finite (mss) or failed (rods)
} vd_growth_stats;

// An ongoing growth run (opaque).
typedef struct vd_growth vd_growth;

// Start a run: derive the axiom, build the plant and its physics at age 0 (no substeps yet).
// Bad settings are VD_ERR_VALUE with the field named (zero substeps, negative density, a light
// inside the plant, ...).
vd_status vd_growth_create(vd_lsystem* ls, const vd_growth_def* def, vd_growth** out, vd_error* err);
// Free a run (NULL is fine).
void vd_growth_destroy(vd_growth* g);
// One age step: a derivation step, the new plant with the carried state, def.substeps substeps,
// the mass update, gravitropism of the rest shape, and the pruning of broken branches.
vd_status vd_growth_step(vd_growth* g, vd_error* err);
// Age steps taken.
int vd_growth_age(const vd_growth* g);
// Summary so far.
void vd_growth_get_stats(const vd_growth* g, vd_growth_stats* out);
// Events so far (valid until the next step); *n gets their count.
const vd_growth_event* vd_growth_events(const vd_growth* g, int* n);
// The plant now, deformed, with its stress (vd_plant_set_stress): a new spec for the caller.
vd_status vd_growth_plant(const vd_growth* g, vd_plant_spec** out, vd_error* err);
// The mass-spring model and state now (mss, mrl; NULL for rods), for inspection.
const vd_mss_model* vd_growth_mss(const vd_growth* g, const vd_mss_data** data);
// Validation cases of growth runs (paper findings as numbers; docs/validation.md): *out gets
// them (free with vd_free(*out, *n * sizeof **out)); def as for vd_sim_validate.
vd_status vd_growth_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                             vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
