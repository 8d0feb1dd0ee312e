// SPDX-License-Identifier: MIT
// Private parts of the robot module: the robot description (vd_robot, immutable once loaded) and
// the episode's state (vd_harvest), shared by robot_model.c (MJCF, description, colliders),
// robot_ik.c (inverse kinematics) and robot_harvest.c (coupling, grasp, episode). The scripted
// controller (robot_control.c) does not include this header: it is a client of robot.h only.
// Never installed.
#ifndef VERDANT_ROBOT_INTERNAL_H
#define VERDANT_ROBOT_INTERNAL_H

#include <math.h>
#include <mujoco/mujoco.h>

#include "mjtrap/mjtrap.h"
#include "verdant/collide.h"
#include "verdant/robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define ROBOT_MAX_COLLIDERS (VD_SIM_MAX_COLLIDERS - 1) // robot geoms (one collider is the ground)
#define ROBOT_TIE_COMPLIANCE 1e-5  // the grasp tie: 1e5 N/m (m/N)
#define ROBOT_TOUCH_GAP 5e-4       // a finger touches the fruit within this gap (m)

// One collidable robot geom of the description: its shape in its own frame (distance grid for
// cylinders, ellipsoids and meshes, owned by the description and read only by episodes).
typedef struct robot_geom {
  int geom;           // MuJoCo geom
  int body;           // its body
  int finger;         // 0 / 1 for a geom of finger l / r, else -1
  vd_sdf* sdf;        // owned distance grid (cylinder, ellipsoid, mesh), else NULL
  vd_sim_collider sc; // the plant collider (pose identity; sdf borrowed)
  vd_collider shape;  // the same shape for queries of the collide module (pose identity)
} robot_geom;

// The robot description: the MJCF as loaded (its own base pose), what the episodes need to know
// about it, the collision shapes. Never changed after vd_robot_load; episodes of any thread
// read it.
struct vd_robot {
  char path[4096];            // the MJCF
  char ee_site_name[64];      // scene robot.ee_site it was described with
  char gripper_name[2][64];   // scene robot.gripper
  mjModel* m;                 // as loaded
  int root_body;              // the robot's root (a child of the world)
  int ee_site;                // end-effector site
  int narm;                   // arm joints (those between the root and the site, with servos)
  int arm_jnt[VD_ROBOT_MAX_JOINTS], arm_qpos[VD_ROBOT_MAX_JOINTS], arm_dof[VD_ROBOT_MAX_JOINTS],
      arm_act[VD_ROBOT_MAX_JOINTS];
  double arm_lo[VD_ROBOT_MAX_JOINTS], arm_hi[VD_ROBOT_MAX_JOINTS];  // joint limits
  double qd_max[VD_ROBOT_MAX_JOINTS]; // joint speed limit of the command (rad/s or m/s)
  int grip_act[2], grip_qpos[2], grip_dof[2], finger_body[2];
  robot_geom geom[ROBOT_MAX_COLLIDERS];
  int ngeom;
};

// One robot geom as a collider of the plant in an episode.
typedef struct robot_collider {
  int geom;           // MuJoCo geom
  int body;           // its body
  int sim;            // its index in the plant state's colliders
  int finger;         // 0 / 1 for a geom of finger l / r, else -1
  vd_pose prev;       // pose at the previous robot step
  vd_pose cur;        // pose at this robot step
  vd_collider shape;  // the same shape for queries of the collide module (pose cur)
} robot_collider;

// One fruit of the plant.
typedef struct robot_fruit {
  int node;       // rod node at its centre
  int seg;        // its stalk segment (VD_SIM_FRUITSEG, class fruit)
  int instance;   // organ instance
  double radius;  // sphere radius (m)
  int absc;       // its pedicel's abscission joint within 8 segments, -1 none
  double thr[2];  // its calyx and abscission break forces this episode (N; INFINITY: none)
  int hit;        // the robot has touched it
  int dropped;    // it came off the plant
} robot_fruit;

struct vd_harvest {
  vd_scene scene;             // own copy
  const vd_model* plant;      // borrowed
  const vd_robot* rb;         // the robot description (borrowed, or own_rb)
  vd_robot* own_rb;           // the description vd_harvest_create loaded for this episode alone
  vd_sim_model* sm;           // rod model
  vd_sim_data* sd;            // rod state
  // MuJoCo
  mjModel* m;                 // the description's model copied, with the scene's base pose and
                              // grip force limit (no parsing: mj_copyModel)
  mjData* d;                  // the episode
  mjData* dk;                 // scratch for inverse kinematics
  int orient;                 // 1 when the arm can turn the end-effector (IK on orientation)
  int nrobot;                 // robot steps per control step
  int nsub;                   // plant steps per robot step
  robot_collider col[ROBOT_MAX_COLLIDERS];
  int ncol;
  // fruits
  robot_fruit* fruit;
  int nfruit;
  // command
  double qcmd[VD_ROBOT_MAX_JOINTS];  // joint targets
  vd_vec3 xcmd;               // commanded end-effector position (m)
  vd_quat rcmd;               // ... orientation
  double grip_cmd;            // gripper command in [0, 1]
  double ik_err;              // residual of the last IK (m)
  double q0[VD_ROBOT_MAX_JOINTS];  // initial arm joints
  double cmd_scale;           // fraction of the last action's motion the command took (joint
                              // speed limits scale a step down; 0 when out of reach)
  // target and grasp
  int target;                 // index into fruit, -1 none
  int held, ever_held, tie;   // holding; tie index in sd->tie
  vd_vec3 hold_local;         // fruit centre in the end-effector frame (m)
  vd_quat hold_rot;           // conj(ee) * fruit stalk frame
  double finger_q[2];         // finger positions held at the grasp (m)
  double grip_n[2];           // each finger's squeeze while held: its actuator's force (N)
  double grip_at_detach;      // the mean squeeze when the fruit came off, else while last held (N)
  double slip;                // slip so far (m)
  double tie_slip0;           // slip before the present grasp (m)
  vd_vec3 pull_force;         // held fruit on the gripper (N), last robot step
  vd_vec3 pull_torque;        // ... its torque (N m)
  double pull_at_break;       // its size at the end of the plant step of the last fracture (N)
  int touching[2];
  double finger_force[2];
  int touched[2];             // a touch event was logged
  vd_vec3 robot_force;        // plant on robot, last robot step (N)
  vd_vec3 ee_pos;             // site pose at the last robot step
  vd_quat ee_quat;
  // the controller's phase (vd_harvest_set_phase), for observations and the event log
  vd_harvest_phase phase;
  // outcome
  int detached;
  vd_harvest_site site;
  double detach_time, detach_force, detach_moment, detach_pull, max_pull, max_disp;
  double grasp_ik_err, grasp_track_err;
  int done;
  char reason[128];           // why it ended (once done)
  char target_reason[128];    // why there is no target ("" when there is one)
  char target_detail[256];    // ... in words, with the fruit and distance
  int nevent_seen;            // plant fracture events already logged
  vd_harvest_event* ev;       // log (nev, capacity cap_ev)
  int nev, cap_ev;
  int ev_dropped;             // events not logged (out of memory): none is logged after one
  int64_t step;
  signed char* on;            // scratch: segment still on the plant (nseg + 1)
  // the target's joint loads at every plant step, the last VD_HARVEST_FORCE_WINDOW s (a ring)
  int watch_seg[2];           // the target's stalk (calyx) and abscission joints, -1 none; [0] -2:
                              // not looked up yet
  vd_harvest_force* fwin;     // the ring (fwin_cap samples)
  int fwin_cap, fwin_n, fwin_head;  // capacity, samples held, next to write
  int fwin_frozen;            // a watched joint broke: the window before it is kept
  double qbuf[VD_ROBOT_MAX_JOINTS], qdbuf[VD_ROBOT_MAX_JOINTS];  // observation copies
};

// robot_model.c: the episode's copy of the robot (base pose, grip force, data, time steps), its
// colliders in the plant state and the fruits.
vd_status robot_attach(vd_harvest* h, vd_error* err);
// 1 when scene s names robot r (same MJCF, site and fingers)
int robot_matches(const vd_robot* r, const vd_scene* s);
vd_status robot_colliders(vd_harvest* h, vd_error* err);
void robot_free(vd_harvest* h);
// Pose of geom g (after kinematics) as a vd_pose.
vd_pose robot_geom_pose(const mjModel* m, const mjData* d, int g);
// Site pose of the end-effector in data d.
void robot_site_pose(const vd_harvest* h, const mjData* d, vd_vec3* pos, vd_quat* rot);
// Arm joint positions of data d into q.
void robot_get_q(const vd_harvest* h, const mjData* d, double* q);

// robot_ik.c: damped least squares on mj_jacSite in the scratch data.
int robot_ik(vd_harvest* h, const vd_ik_def* def, vd_vec3 pos, const vd_quat* rot, double* q,
             double* pos_err, double* rot_err);

// robot_harvest.c: grasp geometry of fruit f (vd_harvest_grasp_pose's)
void harvest_grasp_pose(vd_harvest* h, int f, vd_vec3* pos, vd_quat* rot, vd_vec3* approach,
                        vd_vec3* pedicel);

// robot_validate.c: the validation's small truss (fruit radius r) and the two-way pusher (a
// sphere on a slide pushing a cantilever's tip 3 cm; dir holds its MJCF for a moment)
vd_model* robot_truss(double r);
void robot_push_rod(int two_way, double kp, double fmax, double young, const char* dir, double* tip,
                    double* lag, double* reaction, double* servo, double* clamp, double* tip_mass);

// robot_harvest.c: log an event; NULL when it was dropped (out of memory, or one was before)
vd_harvest_event* harvest_event(vd_harvest* h, vd_harvest_event_kind k, double value, int seg,
                                int instance);
void harvest_finish(vd_harvest* h, const char* reason);
void harvest_release(vd_harvest* h);

// small rotation helpers
vd_vec3 quat_log_v(vd_quat q);          // rotation vector of q (shortest)
vd_quat quat_exp_v(vd_vec3 v);          // rotation of rotation vector v
vd_quat quat_from_mat(const double* r); // from a row-major 3x3 rotation

#endif
