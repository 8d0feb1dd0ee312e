// SPDX-License-Identifier: MIT
// Private pieces of the mass-spring trees (mss_*.c): the scratch of a state and the functions the
// files share.
#ifndef VERDANT_MSS_INTERNAL_H
#define VERDANT_MSS_INTERNAL_H

#include "phys/phys_internal.h"
#include "verdant/mss.h"

// Scratch of one state, one block (vd_mss_data::work).
typedef struct mss_work {
  vd_vec3* fint;   // internal forces: springs, hinges, damping (N) (nnode)
  vd_vec3* ftot;   // all forces on a node (N) (nnode)
  vd_vec3* cg_r;   // conjugate gradients: residual, preconditioned residual, direction, A p,
  vd_vec3* cg_z;   // solution and right-hand side (nnode each)
  vd_vec3* cg_p;
  vd_vec3* cg_ap;
  vd_vec3* cg_x;
  vd_vec3* cg_b;
  vd_vec3* dvs;    // eq. 3: predicted velocity changes of the neighbours; eq. 4: their sum (nnode)
  vd_vec3* pos0;   // state at the start of the substep (undo after a non-finite result) (nnode)
  vd_vec3* vel0;
  vd_vec3* fsub;   // stress: force and moment of each subtree (nnode)
  vd_vec3* msub;
  double* pre;     // block-Jacobi preconditioner, inverted diagonal blocks (nnode x 9)
  double* cdrag;   // derivative of the air drag with respect to the node's velocity (N s/m) (nnode)
  double* ksum;    // eqs. 3-4: sum of the spring constants at each node (N/m) (nnode)
  double* spring_c;// damping coefficient of each spring this substep, eq. 5 (N s/m) (nspring)
  unsigned char* con;  // 1: the node's velocity change is fixed at 0 in this substep (nnode)
  // the direct solver: block LDL^T in an elimination order where the couplings of a tree of
  // springs and hinges (parent, grandparent, sibling arm) make little fill
  int direct;      // 1 when the structure fits MSS_LINKS links per node (else conjugate gradients)
  int* elim;       // elimination order: children before parents (nnode)
  int* epos;       // position of each node in it (nnode)
  int* nlink;      // links of each node to nodes eliminated after it (nnode)
  int* link;       // their targets (nnode x MSS_LINKS)
  double* lblk;    // block A[target][node] of each link (nnode x MSS_LINKS x 9)
  double* diag;    // diagonal blocks, inverted during the factorisation (nnode x 9)
  int* anchor_spring;  // a rigid body's couplings (nspring) and (nhinge)
  int* anchor_hinge;
} mss_work;

#define MSS_LINKS 8  // most links (couplings to later nodes, fill included) per node

// The ground a rigid body turns about (issue 26 defect 2): the node its hardened wood grows from
// (a clamped base or a held root crown), and the springs and hinges that join the body to nodes
// outside it, evaluated at every stage of the body's RK4 (the outside nodes held where they are
// for the substep, Algorithm 2).
typedef struct mss_anchor {
  int node;            // the pivot node (not a member)
  vd_vec3 pivot;       // its position (m)
  vd_vec3 pivot_body;  // ... in the body frame (m)
  vd_vec3 axis_body;   // direction from the pivot to the body's first member, body frame (unit)
  int nspring, nhinge; // couplings to nodes outside the body
  int* spring;         // (nspring) into the model's springs
  int* hinge;          // (nhinge) into its hinges
  double stiffness;    // rotational stiffness of the couplings about the pivot, sum of the hinges'
                       // k and the springs' k r^2 (N m/rad): sets the RK4's substeps
  double hinge_k;      // ... of the hinges at the pivot alone (N m/rad): the anchor's damping
  double damping;      // set by the step: c sqrt(hinge_k I) (N m s)
  double omega;        // set by the step: sqrt(stiffness / I) (rad/s)
} mss_anchor;

// One substep h of a rigid body pinned at an->pivot under the loads' torque about it (N m) and its
// couplings: classical RK4 on the orientation quaternion and the angular momentum about the
// pivot, split so h omega / n < 0.5; then x, p and L from the turn.
void mss_rigid_pinned_step(const vd_mss_model* m, vd_mss_data* d, mss_anchor* an, vd_vec3 torque, double h);
// Hinge h's forces on its nodes at positions xa (unused for a fixed arm), xb, xc.
void mss_hinge_force_at(const vd_mss_model* m, int h, vd_vec3 xa, vd_vec3 xb, vd_vec3 xc, vd_vec3* fa, vd_vec3* fb,
                        vd_vec3* fc);

// Put the rigid body's members at the body's pose and velocity.
void mss_rigid_sync(const vd_mss_model* m, vd_mss_data* d);
// External loads of a substep into d->fext (gravity, caller's force, wind, drag, tropisms) and
// each node's drag derivative into w->cdrag.
void mss_external(const vd_mss_model* m, vd_mss_data* d, mss_work* w);
// Internal forces of springs and hinges (and damping) at the current state into w->fint; rigid
// pairs are skipped.
void mss_internal(const vd_mss_model* m, const vd_mss_data* d, mss_work* w);
// Subtree equilibrium: force and moment of the loads beyond every node (w->fsub, w->msub).
void mss_subtrees(const vd_mss_model* m, const vd_mss_data* d, mss_work* w);
// Remove the subtree beyond spring s (a break); returns the nodes removed.
int mss_remove_subtree(const vd_mss_model* m, vd_mss_data* d, int s);
// Add an event; 0 when out of memory.
int mss_event(vd_mss_data* d, const vd_mss_event* e);

// Count one numerical warning of kind k (vd_mss_warning) in d->warning and d->nwarning.
static inline void mss_warn(vd_mss_data* d, int k) {
  d->warning[k]++;
  d->nwarning++;
}

// whether a node moves with the springs (not fixed, not rigid, not removed)
static inline int mss_free(const vd_mss_model* m, const vd_mss_data* d, int i) {
  return !(m->node_flags[i] & VD_MSS_FIXED) && !d->rigid[i] && !d->removed[i];
}

// whether the soil holds the root crown now (its anchorage has not given way)
static inline int mss_crown_held(const vd_mss_model* m, const vd_mss_data* d) {
  return m->crown >= 0 && !d->anchor_failed && !d->removed[m->crown];
}

// whether hinge h acts: a stiffness, and not a fixed arm of a crown whose anchorage gave way
static inline int mss_hinge_on(const vd_mss_model* m, const vd_mss_data* d, int h) {
  const int* hn = m->hinge_node + 3 * h;
  if (!(m->hinge_k[h] > 0)) return 0;
  return !(hn[0] < 0 && (m->node_flags[hn[1]] & VD_MSS_CROWN) && d->anchor_failed);
}

#endif
