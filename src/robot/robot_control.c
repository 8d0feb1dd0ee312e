// SPDX-License-Identifier: MIT
// The scripted harvest (vd_script), a controller written against verdant/robot.h alone, as a
// learned policy would be: approach in joint space to a pre-grasp pose in front of the fruit
// (gripper open), straight in until the fruit sits between the fingers, close until both
// fingers touch it, then the method's motion, pull (retreat along the pedicel axis), bend (swing
// the fruit about the calyx, about an axis normal to the pedicel) or twist (turn about the
// pedicel axis), and hold the detached fruit. Every phase is a stream of actions given to
// vd_harvest_step; the controller reads vd_harvest_observe, reports its phases and ends the
// episode on its timeouts.
//
// Bend turns the end-effector, and the fruit with it, about the axis a x p through the pedicel's
// abscission node (the knuckle; the calyx when the pedicel has none), swinging the fruit up
// toward the robot. The grasp geometry is the episode's (vd_harvest_grasp_pose), the one its
// choice of a reachable target used.
#include <math.h>
#include <string.h>

#include "verdant/robot.h"

#define APPROACH_TURN 1.0  // angular speed of the approach (rad/s)
#define PHASE_TIMEOUT 10.0 // approach / reach give up after this (s)
#define CLOSE_TIMEOUT 3.0  // closing gives up after this (s)
#define DETACH_WAIT 1.0    // after the method's motion, wait this long for a late break (s)

struct vd_script {
  vd_harvest* h;
  vd_method_def md;           // the scene's method
  double dt;                  // control step (s)
  vd_harvest_phase phase;
  double phase_t0;            // time the phase began (s)
  int joint_move;             // 1: the approach in joint space to qgoal
  double qgoal[VD_ROBOT_MAX_JOINTS]; // the IK solution of the pre-grasp pose from q0
  int nq;
  vd_vec3 grasp_pos;          // grasp point (m)
  vd_quat grasp_rot;          // grasp orientation
  vd_vec3 approach;           // approach direction (unit)
  vd_vec3 pedicel;            // pedicel axis at the fruit, calyx to fruit (unit)
  vd_vec3 pivot;              // bend pivot (m)
  vd_vec3 axis;               // bend / twist axis (unit)
  double progress;            // method motion done (m or rad): what the command achieved
  double progress_step;       // the method motion the last action asked for (m or rad)
  double settle_t;            // time the command has been at its target (s)
};

// the rotation vector of unit quaternion q (shortest)
static vd_vec3 rot_log(vd_quat q) {
  if (q.w < 0) q.w = -q.w, q.x = -q.x, q.y = -q.y, q.z = -q.z;
  double s = sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  if (s < 1e-12) return vd_v3(2 * q.x, 2 * q.y, 2 * q.z);
  double a = 2 * atan2(s, q.w) / s;
  return vd_v3(a * q.x, a * q.y, a * q.z);
}

static vd_vec3 unit_or(vd_vec3 v, vd_vec3 fallback) {
  double n = vd_norm(v);
  return n > 1e-9 ? vd_scale(v, 1.0 / n) : fallback;
}

static void set_phase(vd_script* c, vd_harvest_phase p, double t) {
  if (c->phase == p) return;
  c->phase = p;
  c->phase_t0 = t;
  c->settle_t = 0;
  vd_harvest_set_phase(c->h, p);
}

vd_status vd_script_create(vd_harvest* h, vd_script** out, vd_error* err) {
  vd_script* c = vd_calloc(1, sizeof *c);
  *out = c;
  if (!c) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  const vd_scene* s = vd_harvest_scene(h);
  c->h = h;
  c->md = s->method;
  c->dt = s->control_dt;
  vd_harvest_obs o;
  vd_harvest_observe(h, &o);
  c->nq = o.nq;
  c->phase = o.phase;
  if (!o.target_instance) {
    vd_harvest_end(h, o.target_reason);  // nothing to pick: over at once
    return VD_OK;
  }
  set_phase(c, VD_PHASE_APPROACH, o.time);
  vd_vec3 pre;
  vd_harvest_grasp_pose(h, &c->grasp_pos, &c->grasp_rot, &c->approach, &c->pedicel);
  pre = vd_madd(c->grasp_pos, c->approach, -c->md.pregrasp);
  // to the pre-grasp pose in joint space (no singularity on the way, no wrist flips)
  vd_ik_def def = vd_ik_def_default();
  def.max_iter = 400;
  memcpy(c->qgoal, o.q0, sizeof(double) * (size_t)o.nq);
  vd_harvest_ik(h, &def, pre, &c->grasp_rot, c->qgoal, NULL, NULL);
  c->joint_move = 1;
  return VD_OK;
}

void vd_script_destroy(vd_script* c) {
  vd_free(c, sizeof *c);
}

// velocities that bring the commanded pose to (x, r) at speed (m/s) and turn (rad/s)
static void track(const vd_script* c, const vd_harvest_obs* o, vd_vec3 x, vd_quat r, double speed,
                  double turn, vd_harvest_action* a) {
  double dt = c->dt;
  vd_vec3 e = vd_sub(x, o->cmd_pos);
  double n = vd_norm(e);
  a->lin_vel = n <= speed * dt ? vd_scale(e, 1.0 / dt) : vd_scale(e, speed / n);
  vd_vec3 w = o->orient ? rot_log(vd_quat_mul(r, vd_quat_conj(o->cmd_quat))) : vd_v3(0, 0, 0);
  double m = vd_norm(w);
  a->ang_vel = m <= turn * dt ? vd_scale(w, 1.0 / dt) : vd_scale(w, turn / m);
}

// has the joint command arrived at its goal, and the end-effector within tol (m) of it?
static int joints_arrived(const vd_script* c, const vd_harvest_obs* o, double tol) {
  for (int k = 0; k < c->nq; k++)
    if (fabs(o->q_cmd[k] - c->qgoal[k]) > 1e-9) return 0;
  return vd_norm(vd_sub(o->ee_pos, o->cmd_pos)) < tol;
}

// has the command arrived at (x, r), and the arm caught up within tol (m)?
static int arrived(const vd_harvest_obs* o, vd_vec3 x, vd_quat r, double tol) {
  double e = vd_norm(vd_sub(x, o->cmd_pos));
  double w = o->orient ? vd_norm(rot_log(vd_quat_mul(r, vd_quat_conj(o->cmd_quat)))) : 0;
  return e < 1e-6 && w < 1e-5 && vd_norm(vd_sub(o->ee_pos, o->cmd_pos)) < tol;
}

void vd_script_action(vd_script* c, vd_harvest_action* a, int* joints, double* q) {
  memset(a, 0, sizeof *a);
  int jm = c->phase == VD_PHASE_APPROACH && c->joint_move;
  if (joints) *joints = jm;
  if (jm && q) memcpy(q, c->qgoal, sizeof(double) * (size_t)c->nq);
  const vd_method_def* md = &c->md;
  vd_harvest_obs o;
  vd_harvest_observe(c->h, &o);
  switch (c->phase) {
    case VD_PHASE_APPROACH:  // joint space (vd_script_step): toward qgoal
      break;
    case VD_PHASE_REACH:
      // in to the fruit where it is now (the plant sways: the gripper follows it)
      c->grasp_pos = o.fruit_pos;
      track(c, &o, c->grasp_pos, c->grasp_rot, 0.5 * md->approach_speed, APPROACH_TURN, a);
      break;
    case VD_PHASE_CLOSE:
      // the fingers close around the fruit, still followed
      c->grasp_pos = o.fruit_pos;
      track(c, &o, c->grasp_pos, c->grasp_rot, 0.5 * md->approach_speed, APPROACH_TURN, a);
      a->gripper = 1;
      break;
    case VD_PHASE_DETACH: {
      a->gripper = 1;
      double goal = md->method == VD_HARVEST_PULL ? md->distance : fabs(md->angle);
      double rate = md->method == VD_HARVEST_PULL ? md->speed : md->angular_speed;
      double step = rate * c->dt;
      if (c->progress + step > goal) step = goal - c->progress;
      if (step <= 0) break;
      c->progress_step = step;  // counted after the step as far as the command went
      if (md->method == VD_HARVEST_PULL) {
        a->lin_vel = vd_scale(c->pedicel, step / c->dt);
      } else {
        // a rigid turn of the end-effector about the axis through the pivot
        double sgn = md->angle < 0 ? -1 : 1;
        vd_vec3 w = vd_scale(c->axis, sgn * step / c->dt);
        a->ang_vel = w;
        a->lin_vel = vd_cross(w, vd_sub(o.cmd_pos, c->pivot));
      }
      break;
    }
    case VD_PHASE_HOLD:
      a->gripper = 1;
      break;
    default:
      break;
  }
}

// the method's frame at the grasp: pedicel axis, bend axis and pivot, twist centre
static void detach_frame(vd_script* c, const vd_harvest_obs* o) {
  vd_harvest_fruit f;
  if (vd_harvest_find_fruit(c->h, o->target_instance, &f, NULL)) return;
  c->pedicel = unit_or(vd_sub(f.pos, f.calyx), c->pedicel);
  if (c->md.method == VD_HARVEST_BEND) {
    // about the pedicel's abscission node (the knuckle) when the fruit has one, else about the
    // calyx: the picker's snap
    c->axis = unit_or(vd_cross(c->approach, c->pedicel), vd_v3(0, 0, 1));
    c->pivot = f.knuckle;
  } else {
    c->axis = c->pedicel;
    c->pivot = f.pos;
  }
}

// the phase bookkeeping after a control step
static void after_step(vd_script* c) {
  vd_harvest* h = c->h;
  if (vd_harvest_done(h)) {
    c->phase = VD_PHASE_DONE;
    return;
  }
  vd_harvest_obs o;
  vd_harvest_observe(h, &o);
  double t = o.time - c->phase_t0;
  const vd_method_def* md = &c->md;
  if (o.detached && c->phase != VD_PHASE_HOLD) {
    set_phase(c, VD_PHASE_HOLD, o.time);
    return;
  }
  switch (c->phase) {
    case VD_PHASE_APPROACH:
      if (joints_arrived(c, &o, 2e-3)) {
        c->joint_move = 0;
        // aim at where the fruit is now (the plant may have moved)
        vd_vec3 a, p;
        vd_harvest_grasp_pose(h, &c->grasp_pos, &c->grasp_rot, &a, &p);
        if (o.orient) c->approach = a;
        c->pedicel = p;
        set_phase(c, VD_PHASE_REACH, o.time);
      } else if (t > PHASE_TIMEOUT) {
        vd_harvest_end(h, "approach timeout");
      }
      break;
    case VD_PHASE_REACH:
      if (arrived(&o, c->grasp_pos, c->grasp_rot, 2e-3)) set_phase(c, VD_PHASE_CLOSE, o.time);
      else if (t > PHASE_TIMEOUT) vd_harvest_end(h, "reach timeout");
      break;
    case VD_PHASE_CLOSE:
      if (o.held) {
        detach_frame(c, &o);
        c->progress = 0, c->progress_step = 0;
        set_phase(c, VD_PHASE_DETACH, o.time);
      } else if (t > CLOSE_TIMEOUT) {
        vd_harvest_end(h, "not grasped");
      }
      break;
    case VD_PHASE_DETACH: {
      double goal = md->method == VD_HARVEST_PULL ? md->distance : fabs(md->angle);
      // the motion the command made: near a wrist singularity the joints' speed limits slow it
      // down, and the method ends only once the whole distance or angle is done
      c->progress += o.cmd_scale * c->progress_step;
      c->progress_step = 0;
      if (!o.held) {
        vd_harvest_end(h, "slipped");
      } else if (c->progress >= goal - 1e-12) {
        c->settle_t += c->dt;
        if (c->settle_t >= DETACH_WAIT) vd_harvest_end(h, "not detached");
      }
      break;
    }
    case VD_PHASE_HOLD:
      if (t >= md->hold - 1e-9) vd_harvest_end(h, "detached");
      break;
    default:
      break;
  }
}

vd_status vd_script_step(vd_script* c, vd_error* err) {
  if (vd_harvest_done(c->h)) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "the episode is over (reset it)");
  vd_harvest_action a;
  int joints;
  double q[VD_ROBOT_MAX_JOINTS];
  vd_script_action(c, &a, &joints, q);
  vd_status st = joints ? vd_harvest_step_joints(c->h, q, a.gripper, err) : vd_harvest_step(c->h, &a, err);
  if (!st) after_step(c);
  return st;
}

vd_status vd_harvest_run(vd_harvest* h, vd_status (*on_step)(void* user, const vd_harvest* h),
                         void* user, vd_error* err) {
  vd_script* c;
  vd_status st = vd_script_create(h, &c, err);
  if (!st && on_step) st = on_step(user, h);
  while (!st && !vd_harvest_done(h)) {
    st = vd_script_step(c, err);
    if (!st && on_step) st = on_step(user, h);
  }
  vd_script_destroy(c);
  return st;
}
