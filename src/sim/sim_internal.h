// SPDX-License-Identifier: MIT
// Private pieces of the sim module (the rods engine): the constraint evaluation shared by both
// solvers, the solvers, contacts, forces, sag-free (small dense math: phys/phys_internal.h).
#ifndef VERDANT_SIM_INTERNAL_H
#define VERDANT_SIM_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "phys/phys_internal.h"
#include "verdant/sim.h"

// ---------------------------------------------------------------------------------------------
// constraint evaluation (both solvers use these; sim_constraint.c)

// One joint linearised at the current state: segment t's stretch-shear rows (0..2, material
// frame) and the bend-twist rows with its parent (3..5, parent's frame).
typedef struct sim_joint {
  double c[6];       // constraint values
  double alpha[6];   // compliance (before dividing by h^2)
  double a[9];       // d C_s / d x_end = R^T / l0 (also -d C_s / d x_start)
  double b[9];       // d C_s / d theta_t = R^T [e / l0]x
  double g[9];       // d C_b / d theta_t (d C_b / d theta_parent = -g)
  int bend;          // 1 when the bend-twist rows are active
  int parent_body;   // parent body: segment, nseg + spare index, or -1 when kinematic
} sim_joint;

// Evaluate joint t (segment t must not be fixed).
void sim_joint_eval(const vd_sim_model* m, const vd_sim_data* d, int t, sim_joint* j);
// Constraint values only (for damping and fracture checks).
void sim_joint_values(const vd_sim_model* m, const vd_sim_data* d, int t, double c[6]);
// Bend-twist strain C_b (3, 1/m) of a joint of measure kind with relative rotation qr =
// conj(q_parent) q_t, rest rotation q0 and Darboux length lbar; dc (Nullable) gets dC_b/dpsi
// (3x3) for a rotation psi of qr on the left, in the parent's frame (dC_b/dtheta_t = dc R_p^T).
void sim_bend_strain(vd_sim_bend kind, vd_quat qr, vd_quat q0, double lbar, double* c, double* dc);
// Inverse left Jacobian of SO(3) at the rotation vector v (3x3): log(exp(u) exp(v)) = v + J u + O(u^2).
void sim_jl_inv(vd_vec3 v, double* o);
// Detach segment t from its parent (a fracture): its start moves to its spare node, which takes
// half the segment's mass; the joint is marked broken (sim_step.c).
void sim_detach(const vd_sim_model* m, vd_sim_data* d, int t);
// Pieces after fracture (sim_pieces.c): mark the plant segments of state out that span a broken
// joint, with where they broke (vd_data::seg_cut).
void sim_plant_cuts(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant, vd_data* out);
// Cut the spec (positions already written back) into separate pieces at the broken joints:
// segments spanning a break split with new nodes at its faces, links across pieces removed.
vd_status sim_spec_pieces(const vd_sim_model* m, const vd_sim_data* d, vd_plant_spec* spec);

// ---------------------------------------------------------------------------------------------
// self-collision primitives (sim_self.c): capsule k is segment cap_seg[k], sphere k is the
// fruit node sph_node[k]; built once per state, refreshed from the positions every step

typedef struct sim_self {
  int ncap, nsph;            // capsules (segments but fruit stalks) and spheres (fruit nodes)
  int* cap_seg;              // segment of each capsule (ncap)
  int* cap_node;             // current end nodes of each capsule (ncap x 2)
  double* cap_radius;        // radius at both ends (m) (ncap x 2)
  int* sph_node;             // node of each sphere (nsph)
  double* sph_pos;           // sphere centres, refreshed each step (m) (nsph x 3)
  double* sph_radius;        // sphere radii (m) (nsph)
  vd_collide_exclusion ex;   // neighbours and pairs touching in the modelled shape
  // each primitive's own margin: twice the step's largest displacement of its nodes, so one fast
  // node widens its own search, not the whole plant's (a global margin made the pairs O(n^2))
  double* margin;            // this step's (m) (ncap + nsph)
  double* margin_built;      // at the last build (m) (ncap + nsph)
  // candidate pairs reused over steps (a Verlet list): valid while no primitive has moved more
  // than (grow - margin) / 2 + margin_built - margin from pos_built and no joint has broken since
  vd_arena pair_arena;       // holds pairs
  vd_pair_list pairs;        // broad-phase pairs of the last build
  vd_vec3* pos_built;        // node positions at that build (m) (nnode_all)
  double grow;               // box growth used at that build (m)
  int have_pairs;            // 0: build at the next step
  int nevent_built;          // fracture events at that build
  void* block;               // the arrays above but ex and pairs (one allocation)
  size_t nbytes;             // its size
} sim_self;

// ---------------------------------------------------------------------------------------------
// the direct solver's schedule and blocks (sim_plan.c, sim_direct.c)

#define SIM_W 8             // bodies eliminated side by side in one block (lanes: one AVX-512 vector)
#define SIM_MAX_THREADS 64  // most threads one state's step may use

// One block of SIM_W bodies, each field an array over the lanes (structure of arrays), so
// the elimination's 6x6 and 3x3 block arithmetic runs lane-parallel (vectorised). A body is
// one free segment: its end node and its frame (6 dofs); its joint is the segment's
// stretch-shear rows (in world axes here) and its bend-twist rows with the parent. Symmetric
// 6x6 matrices are stored as [A (3x3 upper: 00 01 02 11 12 22) | B (3x3 row-major) | D (upper)].
// It holds what the back substitution and the update read (the forward elimination's other
// quantities live on its stack, the contributions to the parents in sim_kid): the blocks of a
// plant stream through the caches three times an iteration.
typedef struct sim_blk {
  double h[21][SIM_W];   // body matrix H, then its inverse
  double s[21][SIM_W];   // joint Schur matrix S = J H^-1 J^T + alpha~', then its inverse
  double g[6][SIM_W];    // body residual (position rows N s^2, rotation rows N m s^2)
  double r[6][SIM_W];    // joint right-hand side
  double e[3][SIM_W];    // segment vector x_end - x_start (m)
  double gm[9][SIM_W];   // bend-twist Jacobian G (1/m, row-major)
  double dy[6][SIM_W];   // body update (m, rad)
  double dl[6][SIM_W];   // multiplier update (world stretch rows, bend rows)
  double qt[4][SIM_W];   // the frame at the linearisation
  double l0[SIM_W];      // rest length (m)
} sim_blk;

// A block's contributions to its bodies' parents, apart from the blocks (fewer cache lines
// between a child's elimination and its parent's).
typedef struct sim_kid {
  double dh[21][SIM_W];  // contribution J_p^T S^-1 J_p to the parent's H
  double dg[6][SIM_W];   // contribution to the parent's g
} sim_kid;

// What a block's bodies and joints keep from the model (lane by lane), so that a step gathers
// only the state. Padding lanes hold a unit body and joint.
typedef struct sim_stat {
  double q0[4][SIM_W];   // rest relative rotation of the bend-twist constraint
  double cs[3][SIM_W];   // stretch-shear compliances
  double cb[3][SIM_W];   // bend-twist compliances
  double l0[SIM_W];      // rest length (m)
  double lbar[SIM_W];    // Darboux length (m)
  double ib[SIM_W];      // rotary inertia about d1, d2 (kg m^2)
  double it[SIM_W];      // ... about d3
} sim_stat;

// The elimination schedule of a model for nthread threads: blocks in an order where every
// body's children come in earlier blocks; thread k eliminates its subtrees' blocks
// [part[k], part[k+1]), then one thread the top part [part[nthread], nblock). Each body sums
// its children's contributions in the fixed order of kid_slot, so any schedule and any thread
// count give the same bytes.
typedef struct sim_plan {
  int nbody, nblock, nslot;  // free segments, blocks, nblock * SIM_W
  int nthread;               // threads the blocks are cut for
  int part[SIM_MAX_THREADS + 2];
  int* slot_seg;             // segment of each slot, -1 for padding (nslot)
  int* seg_slot;             // slot of each segment, -1 when fixed (nseg)
  int* par_slot;             // slot of the parent body, -1 when kinematic or padding (nslot)
  ptrdiff_t* poff;           // where the parent's update dy of slot s starts, in doubles from blk (0 without)
  double* puse;              // 1 where slot s has a parent body, else 0 (nslot, nslot)
  int* kid_start;            // children of slot s: kid_slot[kid_start[s] .. kid_start[s + 1]) (nslot + 1)
  int* kid_slot;             // (nbody)
  int* kround;               // block b adds its children in rounds kround[b] .. kround[b + 1]: round r adds
  ptrdiff_t* koff;           // each lane's j-th child, at koff[SIM_W r + l] in sim_kid's doubles (0 and
  double* kuse;              // kuse 0 where none) (nblock + 1, nround x SIM_W, nround x SIM_W)
  unsigned char* tip_block;  // 1 when block b holds tips (no children) only (nblock)
  double* tie_h;             // ties on each slot's node, then on each spare: sum of h^2 / compliance (nslot + nspare)
  double* tie_g;             // ... and their residual sum c h^2 / compliance ((nslot + nspare) x 3)
  double* spare_dy;          // update of each spare node this iteration (nspare x 3)
  int* held_start;           // held children of slot s (region of interest): held_seg[held_start[s] ..
  int* held_seg;             // held_start[s + 1]), their joints hold the body (nslot + 1, nheld)
  double* held_lin;          // their linearisation this iteration: a, G, c', alpha~' (nheld x 30)
  sim_blk* blk;              // the blocks (nblock, 64-byte aligned inside mem)
  sim_kid* kid;              // their contributions to the parents (nblock, 64-byte aligned)
  sim_stat* stat;            // their model data (nblock, 64-byte aligned)
  void* mem;                 // one allocation for all of the above
  size_t nbytes;             // its size
} sim_plan;

// Build the schedule of model m for nthread threads (1..SIM_MAX_THREADS) into p (freed and
// replaced); VD_ERR_NOMEM when out of memory (p then empty).
vd_status sim_plan_build(const vd_sim_model* m, int nthread, sim_plan* p);
// Free a plan (an empty one is fine).
void sim_plan_free(sim_plan* p);

// ---------------------------------------------------------------------------------------------
// solver scratch kept in vd_sim_data::work

typedef struct sim_work {
  vd_vec3* node_prev;   // positions at the start of the step (nnode_all)
  vd_quat* seg_prev;    // frames at the start of the step (nseg)
  vd_vec3* node_fext;   // total external force this step (N) (nnode_all)
  vd_vec3* seg_text;    // total external torque this step (N m) (nseg)
  double* node_drag;    // air drag damping -dF/dv of each node, taken implicitly (kg/s) (nnode_all)
  double* seg_drag;     // each segment's drag force (N), damping (kg/s) and start node's share (nseg x 5)
  double* c_prev;       // constraint values at the start of the step (nseg x 6)
  double* lambda_save;  // multipliers before a statics step, to undo it (nseg x 6)
  int* spare_of;        // spare index -> segment (nspare)
  // direct solver
  sim_plan plan;        // its schedule and blocks

  double* tie_lambda;   // multipliers of model and user ties (ntie_all x 3)
  int cap_tie_lambda;   // capacity of tie_lambda (rows)
  int model_ties;       // stake ties of the model (the first rows)
  int gravity_only;     // scratch flag
  sim_self self;        // self-collision primitives and exclusion
  vd_vec3 col_imp[VD_SIM_MAX_COLLIDERS];  // impulse of this step's contacts on each collider (N s)
  vd_vec3 col_ang[VD_SIM_MAX_COLLIDERS];  // its moment about the collider's pos (N m s)
  double strain;        // largest stretch strain at the end of the last step (-)
  double h_last;        // size of the last dynamic step kept (s; the multipliers' step), 0 before
} sim_work;

// Allocate the work block for a model; NULL when out of memory. *bytes gets its size.
sim_work* sim_work_create(const vd_sim_model* m, size_t* bytes);

struct sim_contact;

// Per-step context shared by the solvers.
typedef struct sim_step_ctx {
  double h;                      // time step (s)
  double gamma;                  // damping factor tau / h
  int statics;                   // 1: quasi-static step (no inertia carried)
  double extra_damping;          // mass damping added by settling (1/s)
  struct sim_contact* contacts;  // contact candidates of this step
  int ncontact;                  // their count
  int last;                      // 1: the smallest substep, an overstretched state is kept
  double* tstage;                // running timestamp of the stage profile (sim_stage)
} sim_step_ctx;

// Monotonic clock (s) for the stage profile.
double sim_clock(void);
// While d->profile is on: add the time since *t to stage s and set *t to now.
static inline void sim_stage(vd_sim_data* d, vd_sim_stage s, double* t) {
  if (!d->profile) return;
  double now = sim_clock();
  d->stage_seconds[s] += now - *t;
  *t = now;
}
// The start of a timed span (0 when not profiling).
static inline double sim_stage_start(const vd_sim_data* d) { return d->profile ? sim_clock() : 0.0; }

// Threads of a state's step (opt.threads, at least 1), and a parallel loop over independent
// elements with them: each element's arithmetic is the same on any thread, so the bytes do not
// depend on the count (reductions are max or logical, which do not depend on the order).
static inline int sim_threads(const vd_sim_model* m) {
  return m->opt.threads < 1 ? 1 : m->opt.threads > SIM_MAX_THREADS ? SIM_MAX_THREADS : m->opt.threads;
}
// fn(ctx, chunk, i0, i1) over [0, n) cut into nchunk = min(nt, n / 256, SIM_MAX_THREADS)
// contiguous chunks run by nt threads (at least one chunk; one chunk runs on the caller without
// OpenMP); returns nchunk. Per-chunk results go to arrays indexed by chunk.
typedef void (*sim_range_fn)(void* ctx, int chunk, int i0, int i1);
int sim_parallel(int nt, int n, sim_range_fn fn, void* ctx);

// Count one numerical warning of kind k (vd_sim_warning) in d->warning and d->nwarning.
static inline void sim_warn(vd_sim_data* d, int k) {
  d->warning[k]++;
  d->nwarning++;
}

// Both solvers: project all constraints for one step (positions and frames in d are moved).
// sim_solve_direct returns 0 when a factorisation failed (the step must be retaken), else 1.
int sim_solve_direct(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* c);
// The frames' velocities at the end of a step, lane-parallel (sim_direct.c; the same bytes as
// the scalar log map): segments [t0, t1) get omega = s log(q conj(q_prev)) (fixed ones 0).
void sim_frame_velocities(const vd_sim_model* m, vd_sim_data* d, const sim_work* w, double s, int t0, int t1);
// The frames' prediction of a dynamic step without the loads (the direct solver's): segments
// [t0, t1) keep their frame in seg_prev and turn by h omega (fixed ones stay), lane-parallel
// with the same bytes as quat_rotate_by.
void sim_frame_predict(const vd_sim_model* m, vd_sim_data* d, sim_work* w, double h, int t0, int t1);
// Segment t's air drag (cylinder in cross flow, leaf lamina as a plate) in the relative wind
// (wind (m/s), q = rho_air / 2): its force (N), damping (kg/s) and its start node's share (-1:
// none) into w->seg_drag (nseg x 5) (sim_forces.c).
void sim_seg_drag_one(const vd_sim_model* m, const vd_sim_data* d, sim_work* w, vd_vec3 wind, double q, int t);
// The same for whole groups of SIM_W segments from t0, lane-parallel with the same bytes
// (sim_direct.c); returns the first segment not done.
int sim_seg_drag_lanes(const vd_sim_model* m, const vd_sim_data* d, sim_work* w, vd_vec3 wind, double q, int t0, int t1);
void sim_solve_gs(const vd_sim_model* m, vd_sim_data* d, const sim_step_ctx* c);

// 1 when node n moves (not kinematic and with mass): sim_node_w > 0 without the division
static inline int sim_node_moves(const vd_sim_model* m, const vd_sim_data* d, int n) {
  return !m->node_fixed[n] && d->node_mass[n] > 0;
}
// inverse mass of a node (0 when kinematic)
static inline double sim_node_w(const vd_sim_model* m, const vd_sim_data* d, int n) {
  return m->node_fixed[n] || d->node_mass[n] <= 0 ? 0.0 : 1.0 / d->node_mass[n];
}
// Ties (stake ties of the model, then user ties): node, target, compliance of tie k.
int sim_tie_count(const vd_sim_model* m, const vd_sim_data* d);
void sim_tie_get(const vd_sim_model* m, const vd_sim_data* d, int k, int* node, vd_vec3* target,
                 double* compliance);
// A friction-limited user tie (max_force > 0): its target slides toward the node until the pull
// across its axis is max_force (vd_sim_tie); called at every solver iteration.
void sim_tie_limit(const vd_sim_model* m, vd_sim_data* d, int k);

// ---------------------------------------------------------------------------------------------
// contacts (sim_contact_basic.c until the collide module takes over)

// One contact candidate, found once per step and re-evaluated at every projection: a rod
// element (node sphere or segment capsule) against a collider, or against a second rod element
// (self-contact: collider -1, the second element in node2 / seg2 / t2 / radius2).
typedef struct sim_contact {
  int node;        // rod node whose sphere touches, or -1
  int seg;         // rod segment whose capsule touches, or -1 (then t is the parameter)
  double t;        // parameter along seg (0 at its start node)
  double radius;   // radius of the rod element (m)
  int collider;    // collider index, -1 for a self-contact
  double lambda;   // accumulated normal correction this step (m)
  int node2, seg2; // second rod element of a self-contact (as node / seg), else -1
  double t2;       // parameter along seg2
  double radius2;  // radius of the second element (m)
} sim_contact;

// Find contact candidates at the current (predicted) state, within margin (m); results go to
// the arena. Returns the count (0 when none or the arena fails; failures counted as warnings).
int sim_contacts_find(const vd_sim_model* m, vd_sim_data* d, double margin, sim_contact** out);
// Build the self-collision primitives and exclusion of a model (zeroed on failure).
vd_status sim_self_init(const vd_sim_model* m, sim_self* s, vd_error* err);
// Free them (a zeroed one is fine).
void sim_self_free(sim_self* s);
// Append the self-contacts at the current state to the nprev contacts in prev: pairs closer than
// margin (m) plus twice the step's displacement (from node_prev) of each one's nodes; *out gets
// the joined list (in the arena). Returns the new count.
int sim_self_find(const vd_sim_model* m, vd_sim_data* d, double margin, sim_contact* prev, int nprev,
                  sim_contact** out);
// Project contacts: push penetrating rod elements out of the colliders (compliance 0); the
// reactions on the colliders of a step of h (s) go to the work block's col_imp / col_ang.
void sim_contacts_project(const vd_sim_model* m, vd_sim_data* d, sim_contact* c, int n, double h);
// Coulomb friction on the step's tangential motion at each active contact.
void sim_contacts_friction(const vd_sim_model* m, vd_sim_data* d, sim_contact* c, int n, double h);
// Signed gap of contact c at the current state (m, negative when penetrating).
double sim_contact_gap(const vd_sim_model* m, const vd_sim_data* d, sim_contact* c);
// Signed distance from point p to collider k's surface (m) and the outward normal there.
double sim_collider_distance(const vd_sim_collider* k, vd_vec3 p, vd_vec3* normal);

// ---------------------------------------------------------------------------------------------
// forces (sim_forces.c)

// Wind velocity at time t (m/s).
vd_vec3 sim_wind_at(const vd_sim_opt* o, double t);
// Accumulate external forces and torques of this step into w->node_fext and w->seg_text, and
// the air drag's damping coefficient of each node (kg/s) into w->node_drag.
void sim_forces(const vd_sim_model* m, vd_sim_data* d, sim_work* w);

// ---------------------------------------------------------------------------------------------
// building helpers

// Sag-free rest state: given the modelled shape in m, adjust rest lengths, frames and rest
// relative rotations so it is the static equilibrium under gravity (sim_sagfree.c). Returns
// the number of joints where the required rest curvature was out of reach (clamped).
int sim_sagfree(vd_sim_model* m, vd_vec3 gravity);

// segment start node at the current state
static inline int sim_seg_start(const vd_sim_data* d, const vd_sim_model* m, int t) {
  (void)m;
  return d->seg_start[t];
}

#endif
