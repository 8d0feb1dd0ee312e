// SPDX-License-Identifier: MIT
// The scripted harvest: approach to a pre-grasp pose in front of the fruit (gripper open),
// straight in until the fruit sits between the fingers, close until both fingers touch it,
// then the method's motion, pull (retreat along the pedicel axis), bend (swing the fruit about
// the calyx, about an axis normal to the pedicel) or twist (turn about the pedicel axis), and
// hold the detached fruit. Every phase is a stream of end-effector velocities given to the same
// control step an external controller uses.
//
// Bend turns the end-effector, and the fruit with it, about the axis a x p through the pedicel's
// abscission node (the knuckle; the calyx when the pedicel has none), swinging the fruit up
// toward the robot.
//
// Grasp geometry: the pedicel axis p runs from the calyx (the fruit stalk's start) to the
// fruit's centre; the approach a is the horizontal direction from the robot's base to the fruit
// (made normal to p when the calyx would otherwise lie toward the palm); the gripper's z axis is
// a and its fingers close along p x a, so they meet
// the fruit's sides and the pedicel stays between them at the top. A robot that cannot turn its
// end-effector (a gantry) approaches along its tool axis.
#include <string.h>

#include "robot_internal.h"

#define APPROACH_TURN 1.0  // angular speed of the approach (rad/s)
#define PHASE_TIMEOUT 10.0 // approach / reach give up after this (s)
#define CLOSE_TIMEOUT 3.0  // closing gives up after this (s)
#define DETACH_WAIT 1.0    // after the method's motion, wait this long for a late break (s)

void control_set_phase(vd_harvest* h, vd_harvest_phase p) {
  if (h->phase == p) return;
  h->phase = p;
  h->phase_t0 = h->sd->time;
  h->settle_t = 0;
  harvest_event(h, VD_EV_PHASE, p, -1, 0);
}

static vd_vec3 unit_or(vd_vec3 v, vd_vec3 fallback) {
  double n = vd_norm(v);
  return n > 1e-9 ? vd_scale(v, 1.0 / n) : fallback;
}

void control_grasp_pose(vd_harvest* h, int f, vd_vec3* pos, vd_quat* rot, vd_vec3* approach,
                        vd_vec3* pedicel) {
  const vd_sim_data* sd = h->sd;
  const robot_fruit* fr = &h->fruit[f];
  vd_vec3 c = sd->node_pos[fr->node], calyx = sd->node_pos[sd->seg_start[fr->seg]];
  vd_vec3 p = unit_or(vd_sub(c, calyx), vd_v3(0, 0, -1));
  int r = h->root_body;
  vd_vec3 base = vd_v3(h->d->xpos[3 * r], h->d->xpos[3 * r + 1], h->d->xpos[3 * r + 2]);
  vd_vec3 ah = vd_sub(c, base);
  ah.z = 0;
  ah = unit_or(ah, vd_v3(1, 0, 0));
  // horizontal, unless the calyx would then lie toward the palm: a . p <= 0 keeps the pedicel
  // ahead of the fingers
  double ap = vd_dot(ah, p);
  vd_vec3 a = ap > 0 ? vd_madd(ah, p, -ap) : ah;
  a = vd_norm(a) > 0.2 ? unit_or(a, ah) : ah;
  if (h->orient) {
    vd_vec3 y = unit_or(vd_cross(p, a), vd_v3(0, 0, 1));
    vd_vec3 x = vd_cross(y, a);
    *rot = vd_quat_from_axes(x, y, a);
  } else {
    vd_vec3 tmp;
    vd_harvest_fk(h, h->q0, &tmp, rot);
    a = vd_quat_rotate(*rot, vd_v3(0, 0, 1));
  }
  *pos = c;
  *approach = a;
  *pedicel = p;
}

void control_begin(vd_harvest* h) {
  h->phase = VD_PHASE_EXTERNAL;  // so that the first phase is logged
  control_set_phase(h, VD_PHASE_APPROACH);
  control_grasp_pose(h, h->target, &h->grasp_pos, &h->grasp_rot, &h->approach, &h->pedicel);
  h->pre_pos = vd_madd(h->grasp_pos, h->approach, -h->scene.method.pregrasp);
  h->progress = 0, h->progress_step = 0;
  // to the pre-grasp pose in joint space (no singularity on the way, no wrist flips)
  h->joint_move = 1;
  memcpy(h->qgoal, h->qpre, sizeof h->qgoal);
}

// velocities that bring the commanded pose to (x, r) at speed (m/s) and turn (rad/s)
static void track(const vd_harvest* h, vd_vec3 x, vd_quat r, double speed, double turn,
                  vd_harvest_action* a) {
  double dt = h->scene.control_dt;
  vd_vec3 e = vd_sub(x, h->xcmd);
  double n = vd_norm(e);
  a->lin_vel = n <= speed * dt ? vd_scale(e, 1.0 / dt) : vd_scale(e, speed / n);
  vd_vec3 w = h->orient ? quat_log_v(vd_quat_mul(r, vd_quat_conj(h->rcmd))) : vd_v3(0, 0, 0);
  double m = vd_norm(w);
  a->ang_vel = m <= turn * dt ? vd_scale(w, 1.0 / dt) : vd_scale(w, turn / m);
}

// has the joint command arrived at its goal, and the end-effector within tol (m) of it?
static int joints_arrived(const vd_harvest* h, double tol) {
  for (int k = 0; k < h->narm; k++)
    if (fabs(h->qcmd[k] - h->qgoal[k]) > 1e-9) return 0;
  return vd_norm(vd_sub(h->ee_pos, h->xcmd)) < tol;
}

// has the command arrived at (x, r), and the arm caught up within tol (m)?
static int arrived(const vd_harvest* h, vd_vec3 x, vd_quat r, double tol) {
  double e = vd_norm(vd_sub(x, h->xcmd));
  double w = h->orient ? vd_norm(quat_log_v(vd_quat_mul(r, vd_quat_conj(h->rcmd)))) : 0;
  return e < 1e-6 && w < 1e-5 && vd_norm(vd_sub(h->ee_pos, h->xcmd)) < tol;
}

void control_action(vd_harvest* h, vd_harvest_action* a) {
  memset(a, 0, sizeof *a);
  const vd_method_def* md = &h->scene.method;
  double dt = h->scene.control_dt;
  switch (h->phase) {
    case VD_PHASE_APPROACH:  // joint space: see control_begin
      break;
    case VD_PHASE_REACH:
      // in to the fruit where it is now (the plant sways: the gripper follows it)
      h->grasp_pos = h->sd->node_pos[h->fruit[h->target].node];
      track(h, h->grasp_pos, h->grasp_rot, 0.5 * md->approach_speed, APPROACH_TURN, a);
      break;
    case VD_PHASE_CLOSE:
      // the fingers close around the fruit, still followed
      h->grasp_pos = h->sd->node_pos[h->fruit[h->target].node];
      track(h, h->grasp_pos, h->grasp_rot, 0.5 * md->approach_speed, APPROACH_TURN, a);
      a->gripper = 1;
      break;
    case VD_PHASE_DETACH: {
      a->gripper = 1;
      double goal = md->method == VD_HARVEST_PULL ? md->distance : fabs(md->angle);
      double rate = md->method == VD_HARVEST_PULL ? md->speed : md->angular_speed;
      double step = rate * dt;
      if (h->progress + step > goal) step = goal - h->progress;
      if (step <= 0) break;
      h->progress_step = step;  // counted by control_after_step as far as the command went
      if (md->method == VD_HARVEST_PULL) {
        a->lin_vel = vd_scale(h->pedicel, step / dt);
      } else {
        // a rigid turn of the end-effector about the axis through the pivot
        double sgn = md->angle < 0 ? -1 : 1;
        vd_vec3 w = vd_scale(h->axis, sgn * step / dt);
        a->ang_vel = w;
        a->lin_vel = vd_cross(w, vd_sub(h->xcmd, h->pivot));
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

void control_after_step(vd_harvest* h) {
  if (h->done || !h->scripted) return;
  double t = h->sd->time - h->phase_t0;
  const vd_method_def* md = &h->scene.method;
  if (h->detached && h->phase != VD_PHASE_HOLD) {
    control_set_phase(h, VD_PHASE_HOLD);
    return;
  }
  switch (h->phase) {
    case VD_PHASE_APPROACH:
      if (joints_arrived(h, 2e-3)) {
        h->joint_move = 0;
        // aim at where the fruit is now (the plant may have moved)
        vd_vec3 a, p;
        control_grasp_pose(h, h->target, &h->grasp_pos, &h->grasp_rot, &a, &p);
        if (h->orient) h->approach = a, h->pedicel = p;
        else h->pedicel = p;
        control_set_phase(h, VD_PHASE_REACH);
      } else if (t > PHASE_TIMEOUT) {
        harvest_finish(h, "approach timeout");
      }
      break;
    case VD_PHASE_REACH:
      if (arrived(h, h->grasp_pos, h->grasp_rot, 2e-3)) control_set_phase(h, VD_PHASE_CLOSE);
      else if (t > PHASE_TIMEOUT) harvest_finish(h, "reach timeout");
      break;
    case VD_PHASE_CLOSE:
      if (h->held) {
        // the method's frame at the grasp: pedicel axis, bend axis and pivot, twist centre
        const robot_fruit* f = &h->fruit[h->target];
        vd_vec3 c = h->sd->node_pos[f->node], calyx = h->sd->node_pos[h->sd->seg_start[f->seg]];
        h->pedicel = unit_or(vd_sub(c, calyx), h->pedicel);
        if (md->method == VD_HARVEST_BEND) {
          // about the pedicel's abscission node (the knuckle) when the fruit has one, else
          // about the calyx: the picker's snap
          h->axis = unit_or(vd_cross(h->approach, h->pedicel), vd_v3(0, 0, 1));
          h->pivot = calyx;
          const vd_sim_model* sm = h->sm;
          for (int s = f->seg, n = 0; s >= 0 && n < 8; s = sm->seg_parent[s], n++)
            if (sm->seg_flags[s] & VD_SIM_ABSCISSION) {
              h->pivot = h->sd->node_pos[h->sd->seg_start[s]];
              break;
            }
        } else {
          h->axis = h->pedicel;
          h->pivot = c;
        }
        h->progress = 0, h->progress_step = 0;
        control_set_phase(h, VD_PHASE_DETACH);
      } else if (t > CLOSE_TIMEOUT) {
        harvest_finish(h, "not grasped");
      }
      break;
    case VD_PHASE_DETACH: {
      double goal = md->method == VD_HARVEST_PULL ? md->distance : fabs(md->angle);
      // the motion the command made: near a wrist singularity the joints' speed limits slow it
      // down, and the method ends only once the whole distance or angle is done
      h->progress += h->cmd_scale * h->progress_step;
      h->progress_step = 0;
      if (!h->held) {
        harvest_finish(h, "slipped");
      } else if (h->progress >= goal - 1e-12) {
        h->settle_t += h->scene.control_dt;
        if (h->settle_t >= DETACH_WAIT) harvest_finish(h, "not detached");
      }
      break;
    }
    case VD_PHASE_HOLD:
      if (t >= md->hold - 1e-9) harvest_finish(h, "detached");
      break;
    default:
      break;
  }
}
