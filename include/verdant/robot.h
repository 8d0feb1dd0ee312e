// SPDX-License-Identifier: MIT
// verdant robot: a MuJoCo robot harvesting fruit from a simulated plant.
//
// A harvest episode (vd_harvest) couples a robot (any MuJoCo MJCF with a named end-effector site
// and two gripper actuators; data/robots/lite6.xml, gantry3.xml) with a plant simulated as
// Cosserat rods (verdant sim). Every robot step of the MJCF's timestep:
//   mj_step1 -> each robot geom becomes a collider of the plant at its pose (sphere, capsule and
//   box as themselves; cylinder, ellipsoid and mesh through a signed distance grid) -> the plant
//   takes its substeps (robot timestep / plant dt of them, the geoms' poses interpolated) ->
//   the contact forces on the colliders -> with two_way, their reactions go to the robot bodies
//   (xfrc_applied) -> mj_step2.
// One-way coupling (the plant cannot push the robot) is Gazebo Plants'; two-way lets a stiff
// branch stop the arm. A fruit is held when both fingers touch it with a normal force above a
// threshold: then a stiff tie holds its centre at the grasp point of the gripper and a torsion
// spring its orientation; it slips when the pull exceeds friction x grip force (both fingers),
// and is let go when the gripper opens. Detachment is the plant's fracture: the event that
// disconnects the fruit from the root names the site (calyx, abscission node, elsewhere).
//
// Three parts, as MuJoCo's mjModel, mjData and mjcb_control:
// * the robot description (vd_robot): the MJCF loaded once, its site, fingers, arm joints and
//   collision shapes; immutable, shared by every episode of a batch (any thread);
// * the episode (vd_harvest): robot state, plant, coupling, grasp, outcomes. It advances one
//   control step (scene control_dt) at a time under an action: an end-effector velocity (linear
//   and angular, world frame) and a gripper command (or a joint-space goal: vd_harvest_step_joints). The action moves a
//   commanded pose, which damped least-squares inverse kinematics on mj_jac turns into joint
//   targets for the robot's position servos (joint limits respected; gravity compensated);
// * a controller: anything that reads vd_harvest_observe and calls vd_harvest_step. The scripted
//   controller (vd_script: approach, pre-grasp, grasp, then pull, bend or twist) is one, written
//   against this header only; a learning agent (the Python HarvestEnv) is another.
// The episode never calls a controller. A controller may report its phase
// (vd_harvest_set_phase, logged as an event) and end the episode with a reason (vd_harvest_end).
//
// Ownership: a scene owns its strings; an episode copies the scene and borrows the plant
// (vd_model) and the robot description, which must outlive it. Nothing is global but MuJoCo's
// error hook (src/mjtrap/): MuJoCo errors come back as VD_ERR_VALUE, never an exit. One episode
// per thread; episodes on different threads are independent (same seed, same bytes).
//
// Statuses: VD_OK whenever the call did what it says, whatever the episode's outcome (no
// reachable fruit is an outcome: vd_harvest_observe's target_reason, the summary's reason);
// VD_ERR_ARG for a call the episode's state does not allow; VD_ERR_VALUE for bad input (an MJCF
// without the named site, q0 out of range) or a simulation that failed (the episode is then
// done); VD_ERR_IO / VD_ERR_FORMAT / VD_ERR_NOMEM as everywhere.
//
// Usage (compiled and run as written by tests/test_robot_example.c, from the source folder):
//   vd_error err = {0};
//   vd_scene sc;
//   vd_scene_read("data/scenes/tomato_pull.json", &sc, &err);
//   vd_lsystem* ls;                                        // the scene's plant, an .lpy here
//   vd_lsys_load(sc.plant_path, &ls, &err);                // (a plant JSON: vd_plant_read_json)
//   vd_lsys_def def = vd_lsys_def_default();
//   def.seed = sc.plant_seed;
//   vd_plant_spec* spec = vd_plant_spec_create();
//   vd_lsys_grow(ls, &def, NULL, spec, &err);
//   vd_plant_set_instances(spec, VD_INSTANCE_ORGANS);      // one instance per fruit
//   vd_scene_place_plant(&sc, spec);
//   vd_model* plant;
//   vd_plant_compile(spec, &plant, &err);
//   vd_robot* robot;                                       // once for a whole batch
//   vd_robot_load(&sc, &robot, &err);
//   vd_harvest* h;
//   vd_harvest_create_with(&sc, robot, plant, &h, &err);
//   vd_harvest_reset(h, 7, &err);
//   vd_harvest_action a = {{0, 0, -0.02}, {0, 0, 0}, 1.0};   // down at 2 cm/s, gripper closed
//   vd_harvest_obs obs;
//   for (int k = 0; k < 50 && !vd_harvest_done(h); k++) {  // an external controller
//     vd_harvest_step(h, &a, &err);
//     vd_harvest_observe(h, &obs);
//   }
//   vd_harvest_reset(h, 7, &err);                          // the scripted controller instead
//   vd_harvest_run(h, NULL, NULL, &err);
//   vd_harvest_summary sum;
//   vd_harvest_summarize(h, &sum);                         // sum.reason: "detached", ...
//   vd_harvest_destroy(h);
//   vd_robot_destroy(robot);
//   vd_model_destroy(plant);
//   vd_plant_spec_destroy(spec);
//   vd_lsys_destroy(ls);
//   vd_scene_free(&sc);
#ifndef VERDANT_ROBOT_H
#define VERDANT_ROBOT_H

#include "verdant/core.h"
#include "verdant/plant.h"
#include "verdant/sim.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_SCENE_VERSION 1         // version of the scene JSON (docs/formats.md)
#define VD_HARVEST_FORMAT_VERSION 1 // version of summary.json, events.csv, trajectory.csv
#define VD_ROBOT_MAX_JOINTS 16     // most arm joints a robot may have
#define VD_SCENE_MAX_SET 64        // most plant globals a scene may set

// ---------------------------------------------------------------------------------------------
// scenes

// Detachment methods.
typedef enum vd_harvest_method {
  VD_HARVEST_PULL = 0, // retreat along the pedicel axis (Gazebo Plants' stretching)
  VD_HARVEST_BEND,     // rotate the gripper about an axis normal to the pedicel through the
                       // pedicel's abscission node (else the calyx), swinging the fruit up
                       // toward the robot (the paper's bending)
  VD_HARVEST_TWIST,    // rotate the gripper about the pedicel axis through the fruit centre
  VD_HARVEST_METHOD_COUNT
} vd_harvest_method;

// Lower-case name of a method ("pull", "bend", "twist").
const char* vd_harvest_method_name(vd_harvest_method m);

// The scripted controller's parameters (scene "method").
typedef struct vd_method_def {
  vd_harvest_method method; // detachment method
  double approach_speed;    // end-effector speed while approaching (m/s)
  double pregrasp;          // pre-grasp point: this far from the fruit along the approach (m)
  double speed;             // pull: retreat speed (m/s)
  double distance;          // pull: retreat distance (m)
  double angle;             // bend and twist: rotation (rad)
  double angular_speed;     // bend and twist: rotation speed (rad/s)
  double grip_force;        // squeeze of each finger (N): the finger actuators' force limit
  double grip_friction;     // friction coefficient between fingers and fruit (-)
  double touch_force;       // a finger touches the fruit above this normal force (N)
  double hold;              // time kept after detachment before the episode ends (s)
} vd_method_def;

// Defaults: pull, approach_speed 0.1 m/s, pregrasp 0.06 m, speed 0.02 m/s, distance 0.08 m,
// angle 1.5708 rad (90 deg), angular_speed 0.7854 rad/s (45 deg/s), grip_force 3 N (below the
// 4.5-9 N that bursts a ripe tomato's skin, docs/physics.md), grip_friction 0.8, touch_force
// 0.02 N, hold 0.3 s.
vd_method_def vd_method_def_default(void);

// What an episode randomises (scene "episodes"): per episode, uniform in each [lo, hi] range
// whose hi > lo, from the episode's seed.
typedef struct vd_episode_def {
  int plant_seed;          // 1: a new plant seed per episode (the caller regrows the plant)
  int random_target;       // 1: a random reachable fruit instead of the scene's target
  double speed[2];         // pull speed range (m/s)
  double distance[2];      // pull distance range (m)
  double angle[2];         // bend/twist angle range (rad)
  double grip_force[2];    // grip force range (N)
} vd_episode_def;

// A parsed scene file. Paths are resolved against the scene file's folder.
typedef struct vd_scene {
  char path[4096];                 // the scene file ("" when parsed from text without a name)
  // plant
  char plant_path[4096];           // .lpy, plant .json or curves .json
  uint64_t plant_seed;             // derivation seed
  int plant_steps;                 // derivation steps, -1: the file's
  char* plant_set[VD_SCENE_MAX_SET]; // "NAME=VALUE" overrides of the .lpy's globals (owned)
  int nplant_set;
  vd_vec3 plant_pos;               // where the plant's origin goes (m)
  double plant_yaw;                // rotation of the plant about +z (rad)
  // robot
  char robot_path[4096];           // the MJCF
  vd_vec3 base_pos;                // pose of the robot's root body (m) (replaces the MJCF's)
  double base_yaw;                 // ... rotation about +z (rad)
  double q0[VD_ROBOT_MAX_JOINTS];  // initial arm joint positions (rad or m), in MJCF order
  int nq0;                         // how many (0: the MJCF's qpos0)
  char ee_site[64];                // end-effector site: +z the approach, fingers close along y
  char gripper[2][64];             // the two finger actuators (position servos)
  double gripper_open;             // finger actuator target when open (m)
  double gripper_closed;           // ... when closed (m)
  // target and method
  int target_instance;             // fruit organ instance; 0: the nearest reachable fruit; -1: a
                                   // random reachable one (vd_harvest_reset's seed picks it)
  vd_method_def method;            // the scripted controller
  vd_episode_def episodes;         // what --episodes randomises
  // physics
  vd_sim_def sim_def;              // rod model: materials and fracture thresholds, sag-free ...
  // each fruit's break forces, drawn uniformly in [lo, hi] from the plant seed and the fruit's
  // instance (the same plant, the same thresholds); lo > hi (NaN): the materials' fixed value.
  // Defaults: calyx 0.58-2.46 N (Xie et al. 2021, cherry-tomato pulling), abscission 5-8 N
  // (cherry-tomato cluster abscission zone in tension); "thresholds" in the scene file; a scene
  // that sets materials.fruit.break_force (pedicel) fixes the calyx (abscission) threshold.
  double draw_calyx[2], draw_abscission[2];
  vd_sim_opt sim_opt;              // plant run settings (dt, friction, ...)
  double ground;                   // height of the plant's ground plane (m); NAN: none
  int two_way;                     // 1: the plant pushes the robot back
  int base_auto;                   // 1: the base slides along its row (its y) and lifts (z) to a
                                   // fruit before the episode, as a rail trolley with a lift
  double duration;                 // longest episode (s)
  double control_dt;               // control step (s): a multiple of the MJCF's timestep
  // outputs
  double fps;                      // frames per simulated second of the run folder
  int frames;                      // 0 none, 1 binary frames.bin, 2 frames.jsonl
} vd_scene;

// Defaults of every field (no plant, no robot; lite6's site and fingers; method defaults;
// sag_free 1; ground 0 m; one-way; duration 10 s; control_dt 0.01 s; fps 30, binary frames).
void vd_scene_default(vd_scene* s);
// Parse scene JSON text; name (Nullable) is the file it came from, used in errors and to
// resolve relative paths. Malformed input: VD_ERR_FORMAT naming the field ("method.speed:
// expected a number > 0 (m/s)"), or the line and column of a JSON syntax error.
vd_status vd_scene_parse(const char* text, size_t len, const char* name, vd_scene* out,
                         vd_error* err);
// Read and parse a scene file.
vd_status vd_scene_read(const char* path, vd_scene* out, vd_error* err);
// Free what a scene owns (a zeroed or default scene is fine).
void vd_scene_free(vd_scene* s);
// Copy a scene (the copy owns its own strings); VD_ERR_NOMEM on failure.
vd_status vd_scene_copy(const vd_scene* s, vd_scene* out, vd_error* err);
// Move and turn an editable plant to the scene's plant pose (nodes, spheres, mesh vertices).
void vd_scene_place_plant(const vd_scene* s, vd_plant_spec* plant);
// The scene of episode k of a batch seeded with seed: method parameters drawn in the episode
// ranges, the plant's seed drawn when episodes.plant_seed, target_instance -1 when
// episodes.random_target; *target_seed is the seed for vd_harvest_reset (it picks the random
// target). out must be freed (vd_scene_free).
vd_status vd_scene_episode(const vd_scene* s, uint64_t seed, int64_t k, vd_scene* out,
                           uint64_t* target_seed, vd_error* err);

// ---------------------------------------------------------------------------------------------
// robot descriptions

// A robot loaded from its MJCF (immutable; share it between episodes and threads).
typedef struct vd_robot vd_robot;

// Load the scene's robot: the MJCF scene->robot_path (VD_ERR_IO / VD_ERR_FORMAT naming the file,
// line where MuJoCo gives one), its end-effector site scene->ee_site, fingers scene->gripper and
// the arm joints between them and the root (VD_ERR_VALUE naming what is missing), the collision
// shapes of its collidable geoms. Every scene with the same robot_path, ee_site and gripper may
// use it (vd_harvest_create_with).
vd_status vd_robot_load(const vd_scene* scene, vd_robot** out, vd_error* err);
// Free a robot description (NULL is fine); after every episode that uses it.
void vd_robot_destroy(vd_robot* r);

// ---------------------------------------------------------------------------------------------
// episodes

// One harvest episode: robot state, plant and their coupling.
typedef struct vd_harvest vd_harvest;

// Control action of one step.
typedef struct vd_harvest_action {
  vd_vec3 lin_vel;  // commanded end-effector velocity, world frame (m/s)
  vd_vec3 ang_vel;  // commanded end-effector angular velocity, world frame (rad/s)
  double gripper;   // gripper command in [0, 1]: 0 open, 1 closed
} vd_harvest_action;

// Phases of a controller (VD_PHASE_EXTERNAL until a controller reports one).
typedef enum vd_harvest_phase {
  VD_PHASE_EXTERNAL = 0, // no phase reported
  VD_PHASE_APPROACH,     // to the pre-grasp pose, gripper open
  VD_PHASE_REACH,        // straight in to the grasp pose
  VD_PHASE_CLOSE,        // closing until both fingers touch
  VD_PHASE_DETACH,       // the method's motion
  VD_PHASE_HOLD,         // holding the detached fruit
  VD_PHASE_DONE,         // the episode is over
  VD_PHASE_COUNT
} vd_harvest_phase;

// Lower-case name of a phase.
const char* vd_harvest_phase_name(vd_harvest_phase p);

// Where the target fruit came off.
typedef enum vd_harvest_site {
  VD_SITE_NONE = 0,   // not detached
  VD_SITE_CALYX,      // the fruit's own joint (fruit class): the calyx stays on the plant
  VD_SITE_ABSCISSION, // the pedicel's abscission node (knuckle)
  VD_SITE_ELSEWHERE,  // another joint between the fruit and the root
  VD_SITE_COUNT
} vd_harvest_site;

// Lower-case name of a site ("none", "calyx", "abscission", "elsewhere").
const char* vd_harvest_site_name(vd_harvest_site s);

// What an episode reports, kept up to date after every step.
typedef struct vd_harvest_obs {
  double time;              // simulated time (s)
  int64_t step;             // control steps taken
  vd_harvest_phase phase;   // the scripted controller's phase
  int nq;                   // arm joints
  const double* q;          // arm joint positions (rad or m) (nq), valid until the next step
  const double* qd;         // arm joint velocities (nq)
  double gripper_opening;   // distance between the finger pads (m)
  vd_vec3 ee_pos;           // end-effector site position (m)
  vd_quat ee_quat;          // end-effector site orientation
  vd_vec3 cmd_pos;          // commanded end-effector position (m)
  vd_quat cmd_quat;         // ... orientation
  const double* q_cmd;      // the servos' joint targets (nq), valid until the next step
  const double* q0;         // initial arm joints (nq)
  double cmd_scale;         // fraction of the last action's motion the command took (joint speed
                            // limits scale a step down; 0 when out of reach)
  int orient;               // 1 when the arm can turn the end-effector (a gantry cannot)
  vd_vec3 base_pos;         // the robot's root body (m)
  int target_instance;      // the target fruit's organ instance; 0: none
  const char* target_reason; // why there is none ("no fruit", "no such fruit", "unreachable",
                            // "no reachable fruit"), else NULL
  vd_vec3 fruit_pos;        // the target fruit's centre (m)
  vd_vec3 fruit_vel;        // its velocity (m/s)
  int held;                 // 1 while the fruit is held
  int touching[2];          // finger l / r touches the target fruit
  double finger_force[2];   // normal force of each finger on the fruit (N)
  double grip_force;        // squeeze on the held fruit: the finger actuators' mean force (N)
  vd_vec3 pull_force;       // force of the held fruit on the gripper (N)
  double pull_torque;       // torque of the held fruit on the gripper (N m)
  double slip;              // slip of the held fruit in the grip so far (m)
  vd_vec3 robot_force;      // total contact force of the plant on the robot (N)
  int detached;             // 1 once the target fruit is off the plant
  vd_harvest_site site;     // where it came off
  double ik_error;          // distance of the joint targets' pose from the commanded pose (m)
} vd_harvest_obs;

// Event kinds in an episode's log.
typedef enum vd_harvest_event_kind {
  VD_EV_PHASE = 0,  // the scripted controller entered a phase (value: the phase)
  VD_EV_TOUCH,      // a finger first touched the target (value: finger 0/1)
  VD_EV_GRASP,      // the fruit is held (value: finger normal force, N)
  VD_EV_SLIP,       // the fruit slipped out of the grip (value: pull force, N)
  VD_EV_RELEASE,    // the gripper opened and let go (value: 0)
  VD_EV_FRACTURE,   // a plant joint broke (value: its force, N; seg, instance, cls set)
  VD_EV_DETACH,     // the target fruit came off (value: gripper pull force, N; site set)
  VD_EV_HIT,        // the robot first touched another fruit (instance set)
  VD_EV_DROP,       // another fruit came off the plant (instance set)
  VD_EV_IK,         // the commanded pose is out of reach (value: distance, m)
  VD_EV_KIND_COUNT
} vd_harvest_event_kind;

// Lower-case name of an event kind.
const char* vd_harvest_event_name(vd_harvest_event_kind k);

// One event.
typedef struct vd_harvest_event {
  double time;              // simulated time (s)
  vd_harvest_event_kind kind;
  double value;             // see the kind
  int seg;                  // rod segment (fracture), else -1
  int instance;             // organ instance involved, else 0
  int cls;                  // vd_sim_class of the segment (fracture), else -1
  double force, moment;     // joint force (N) and moment (N m) of a fracture or detachment
  vd_harvest_site site;     // detachment site
} vd_harvest_event;

// The outcome of an episode (summary.json).
typedef struct vd_harvest_summary {
  int detached;                // 1 when the target fruit came off
  int grasped;                 // 1 when it was ever held
  vd_harvest_site site;        // where it came off
  double time;                 // time of detachment (s), else the episode's end
  double detach_force;         // force of the broken joint at detachment (N)
  double detach_moment;        // its moment (N m)
  double calyx_threshold;      // the target's calyx break force this episode (N; drawn or fixed,
                               // INFINITY: unbreakable; NAN: no target)
  double abscission_threshold; // ... its abscission joint's (INFINITY also: none)
  double pull_force;           // gripper pull force at detachment (N), the force sensor's view
  double max_pull_force;       // largest gripper pull force before detachment (N)
  double max_displacement;     // largest displacement of a node still on the plant (m)
  int fruits_hit;              // other fruits the robot touched
  int fruits_dropped;          // other fruits that came off
  double ik_error;             // inverse kinematics residual at the grasp pose (m)
  double track_error;          // end-effector distance from the commanded pose at grasp (m)
  double slip;                 // slip in the grip (m)
  double grip_force;           // the fingers' measured mean squeeze when the fruit came off (or
                               // when last held) (N)
  double duration;             // simulated time of the episode (s)
  int64_t steps;               // control steps
  int64_t plant_warnings;      // numerical warnings of the plant simulation
  int target_instance;         // the target fruit
  int events_dropped;          // events the log had no memory for (none is logged after one)
  char reason[128];            // why it ended ("detached", "not grasped", "time", ...)
  char detail[256];            // the reason in words where there is more to say (which fruit,
                               // how far), else ""
} vd_harvest_summary;

// A fruit of the plant as an episode sees it now.
typedef struct vd_harvest_fruit {
  int instance;     // organ instance
  vd_vec3 pos;      // centre (m)
  vd_vec3 calyx;    // the calyx: where the fruit's stalk starts (m)
  vd_vec3 knuckle;  // the pedicel's abscission node within 8 segments of the fruit, else the calyx
  double radius;    // (m)
  int attached;     // 1 while on the plant
} vd_harvest_fruit;

// Build an episode from a scene, a robot description loaded for a scene with the same robot
// (VD_ERR_ARG when the scene names another MJCF, site or fingers) and the plant (placed already:
// vd_scene_place_plant): the robot's model copied (no parsing) with the scene's base pose and
// grip force, q0 and time steps checked (VD_ERR_VALUE), the rod model built, then reset with
// seed 0. The plant and the robot must outlive the episode.
vd_status vd_harvest_create_with(const vd_scene* scene, const vd_robot* robot, const vd_model* plant,
                                 vd_harvest** out, vd_error* err);
// The same with a robot description of its own, loaded from the scene (vd_robot_load's errors).
vd_status vd_harvest_create(const vd_scene* scene, const vd_model* plant, vd_harvest** out,
                            vd_error* err);
// Free an episode (NULL is fine).
void vd_harvest_destroy(vd_harvest* h);
// Start again: robot at q0, plant at its modelled (sag-free) shape, events cleared, phase
// external, the target chosen (a random reachable fruit from seed when target_instance is -1).
// Without a target (none reachable, no fruit, an instance the plant does not have) the episode
// still runs under an external controller; observations say why (target_reason), and the
// scripted controller ends it at once with that reason. VD_OK unless MuJoCo failed.
vd_status vd_harvest_reset(vd_harvest* h, uint64_t seed, vd_error* err);
// Advance one control step under action a. VD_ERR_ARG when the episode is over or the action is
// not finite; VD_ERR_VALUE when MuJoCo or the plant failed (the episode is then done).
vd_status vd_harvest_step(vd_harvest* h, const vd_harvest_action* a, vd_error* err);
// Advance one control step in joint space: the joint targets move straight toward q (the nq arm
// joints, MJCF order; rad or m; clamped to the joints' ranges), every joint arriving together
// under the joints' speed limits; gripper as in an action. Errors as vd_harvest_step's.
vd_status vd_harvest_step_joints(vd_harvest* h, const double* q, double gripper, vd_error* err);
// A controller's phase, for observations; a change is logged as a VD_EV_PHASE event.
void vd_harvest_set_phase(vd_harvest* h, vd_harvest_phase p);
// End the episode with a reason (a controller gave up, "approach timeout"); nothing when over.
void vd_harvest_end(vd_harvest* h, const char* reason);
// The grasp geometry of the target fruit where it is now: the grasp point (its centre), the
// gripper's orientation (z along the approach, fingers closing across the pedicel), the
// approach direction and the pedicel axis (calyx to centre). 0 when there is no target.
int vd_harvest_grasp_pose(vd_harvest* h, vd_vec3* pos, vd_quat* rot, vd_vec3* approach,
                          vd_vec3* pedicel);
// The target fruit's joint loads at one plant step (RUN/forces.csv).
typedef struct vd_harvest_force {
  double time;                                 // s
  double calyx_force, calyx_moment;            // its stalk's joint (N, N m)
  double abscission_force, abscission_moment;  // its pedicel's abscission joint (N, N m); 0: none
  double pull_force;                           // the gripper's force sensor (N); 0 when not held
  int broke;                                   // 1 at the step a watched joint broke (its load:
                                               // the fracture's)
} vd_harvest_force;
#define VD_HARVEST_FORCE_WINDOW 0.5  // seconds of plant steps kept before the detachment
// The target's joint loads at every plant step over the last VD_HARVEST_FORCE_WINDOW s up to
// the step its calyx or abscission joint broke (or up to now, when none broke), oldest first:
// how many there are; the first cap of them into out (Nullable).
int vd_harvest_forces(const vd_harvest* h, vd_harvest_force* out, int cap);

// The plant's fruits now: how many there are; the first cap of them into out (Nullable).
int vd_harvest_fruits(const vd_harvest* h, vd_harvest_fruit* out, int cap);
// The fruit with organ instance id; VD_ERR_ARG when the plant has none.
vd_status vd_harvest_find_fruit(const vd_harvest* h, int instance, vd_harvest_fruit* out, vd_error* err);

// ---------------------------------------------------------------------------------------------
// the scripted controller (a client of the functions above; src/robot/robot_control.c)

// The scene's scripted method driving one episode: approach in joint space to the pre-grasp pose,
// reach in along the approach, close until the fingers hold, then pull, bend or twist, hold the
// detached fruit. It reports its phases and ends the episode on its timeouts.
typedef struct vd_script vd_script;

// A scripted controller for episode h, beginning at h's current state (after vd_harvest_reset;
// an episode without a target is ended at once with its target_reason). VD_ERR_NOMEM only.
vd_status vd_script_create(vd_harvest* h, vd_script** out, vd_error* err);
// Free it (NULL is fine).
void vd_script_destroy(vd_script* c);
// The action for the current state (also advances the controller's own plan; call once per step).
// During the approach the script moves in joint space: the action is then zero and *joints
// (Nullable) gets 1 with the goal in q (nq values; vd_script_step steps with
// vd_harvest_step_joints); else *joints gets 0.
void vd_script_action(vd_script* c, vd_harvest_action* a, int* joints, double* q);
// One control step: the action, vd_harvest_step, the phase bookkeeping. VD_ERR_ARG when the
// episode is over; vd_harvest_step's errors.
vd_status vd_script_step(vd_script* c, vd_error* err);
// Run the scene's scripted method from the current state (just reset) to the end (detached and
// held, failed, or duration). on_step (Nullable) is called once before the first control step
// and after every one (for outputs and progress); a status it returns stops the run and is
// returned.
vd_status vd_harvest_run(vd_harvest* h, vd_status (*on_step)(void* user, const vd_harvest* h),
                         void* user, vd_error* err);
// 1 when the episode is over.
int vd_harvest_done(const vd_harvest* h);
// The current observation.
void vd_harvest_observe(const vd_harvest* h, vd_harvest_obs* out);
// The events so far (*out points into the episode, valid until the next step).
int vd_harvest_events(const vd_harvest* h, const vd_harvest_event** out);
// The outcome so far.
void vd_harvest_summarize(const vd_harvest* h, vd_harvest_summary* out);
// The plant's rod model and state (for frames, pictures, extra queries).
const vd_sim_model* vd_harvest_sim_model(const vd_harvest* h);
const vd_sim_data* vd_harvest_sim_data(const vd_harvest* h);
// The robot's full MuJoCo joint positions (nq values, *nq set), for pictures.
const double* vd_harvest_qpos(const vd_harvest* h, int* nq);
// The scene the episode runs (its own copy).
const vd_scene* vd_harvest_scene(const vd_harvest* h);

// ---------------------------------------------------------------------------------------------
// validation (docs/validation.md "Harvesting")

// Run the harvest validation cases (detachment forces per site against the tomato literature,
// bend against pull, Gazebo Plants' C_b^max = 0.31 bending run and C_s^max sweep, two-way
// coupling against the rod's own force) on a small truss picked by a six-axis gantry written to
// a scratch folder under $TMPDIR. def->filter, progress and user are used; *out (free with
// vd_free(*out, *n * sizeof **out)) gets the results.
vd_status vd_robot_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                            vd_error* err);

// The flexible export in MuJoCo against the rods it came from (docs/validation.md "Exports"): a
// horizontal cantilever exported as MJCF (vd_sim_export_rods, vd_geom_export) and loaded alone
// in MuJoCo sags under its own weight and deflects under a tip load as the rods do, within 5 %;
// both beside Euler-Bernoulli. def->filter, progress and user are used; *out as above.
vd_status vd_robot_validate_export(const vd_validate_def* def, vd_validate_result** out, int* n,
                                   vd_error* err);

// ---------------------------------------------------------------------------------------------
// inverse kinematics of a loaded robot (also used by tests and tools)

// Inverse kinematics settings.
typedef struct vd_ik_def {
  int max_iter;       // most iterations; default 200
  double damping;     // damped least squares lambda (m); default 0.01
  double tol_pos;     // position tolerance (m); default 1e-4
  double tol_rot;     // orientation tolerance (rad); default 1e-3
  double rot_weight;  // weight of orientation error against position error (m/rad); default 0.1
} vd_ik_def;

// Defaults: max_iter 200, damping 0.01 m, tol_pos 1e-4 m, tol_rot 1e-3 rad, rot_weight 0.1 m/rad.
vd_ik_def vd_ik_def_default(void);
// Solve the episode robot's arm joints for an end-effector pose (position, and orientation when
// rot is not NULL and the robot can turn), starting from q (nq arm joints, updated in place);
// joint limits respected. *pos_err and *rot_err (Nullable) get the residuals (m, rad).
// Returns 1 when within tolerance.
int vd_harvest_ik(vd_harvest* h, const vd_ik_def* def, vd_vec3 pos, const vd_quat* rot, double* q,
                  double* pos_err, double* rot_err);
// Forward kinematics: the end-effector pose at arm joints q.
void vd_harvest_fk(vd_harvest* h, const double* q, vd_vec3* pos, vd_quat* rot);

#ifdef __cplusplus
}
#endif
#endif
