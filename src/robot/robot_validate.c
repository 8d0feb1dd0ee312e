// SPDX-License-Identifier: MIT
// Harvest validation (docs/validation.md "Harvesting"): detachment forces against the tomato
// literature, bending against pulling, the Gazebo Plants bending run (C_b^max = 0.31) and its
// C_s^max sweep (Fig. 9), two-way coupling against the rod's own force, and inverse kinematics.
// The cases run on a small truss (robot_truss) picked by a six-axis gantry written here (three
// slides, three wrist hinges, verdant's gripper), so they take seconds.
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "robot_internal.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif



vd_model* robot_truss(double r) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  vd_vec3 p[6] = {{0, 0, -0.01}, {0, 0, 0}, {0, 0, 0.5}, {0.1, 0, 0.5}, {0.11, 0, 0.485}, {0.12, 0, 0.47}};
  for (int k = 0; k < 6; k++) vd_plant_add_node(s, p[k]);
  int lab[5] = {1, 1, 3, 4, 4};
  double rad[5] = {0.006, 0.006, 0.0025, 0.0012, 0.0012};
  int parent = -1;
  for (int k = 0; k < 5; k++) {
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = k, g.node1 = k + 1, g.r0 = g.r1 = rad[k], g.label = lab[k];
    g.instance = 1 + (k >= 2) + (k >= 3);
    g.up = vd_v3(0, 1, 0), g.parent = parent;
    parent = vd_plant_add_segment(s, &g);
  }
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0.12 + 0.4 * r, 0, 0.47 - 0.9 * r), f.radius = r, f.parent = parent;
  f.label = 5, f.instance = 9;
  vd_plant_add_sphere(s, &f);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 3, "peduncle");
  vd_plant_set_label(s, 4, "pedicel");
  vd_plant_set_label(s, 5, "fruit");
  vd_model* m = NULL;
  vd_error e = {0};
  vd_plant_compile(s, &m, &e);
  vd_plant_spec_destroy(s);
  return m;
}

// the validation robot: slides x, y, z, then wrist hinges about z, y, x, the gripper's +z along
// world -x at rest; only the gripper collides with the plant
static const char* gantry6_xml =
    "<mujoco model=\"validate_gantry6\">\n"
    " <compiler angle=\"radian\" autolimits=\"true\"/>\n"
    " <option timestep=\"0.002\" gravity=\"0 0 -9.81\" integrator=\"Euler\"/>\n"
    " <default><geom contype=\"0\" conaffinity=\"0\"/>\n"
    "  <position ctrllimited=\"true\" forcelimited=\"true\"/></default>\n"
    " <worldbody><body name=\"base\">\n"
    "  <body name=\"cx\"><joint name=\"x\" type=\"slide\" axis=\"1 0 0\" range=\"-1 1\" damping=\"300\"/>\n"
    "   <inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1e-2 1e-2 1e-2\"/>\n"
    "   <body name=\"cy\"><joint name=\"y\" type=\"slide\" axis=\"0 1 0\" range=\"-1 1\" damping=\"300\"/>\n"
    "    <inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1e-2 1e-2 1e-2\"/>\n"
    "    <body name=\"cz\"><joint name=\"z\" type=\"slide\" axis=\"0 0 1\" range=\"-1 1\" damping=\"300\"/>\n"
    "     <inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1e-2 1e-2 1e-2\"/>\n"
    "     <body name=\"rz\"><joint name=\"rz\" axis=\"0 0 1\" range=\"-6.3 6.3\" damping=\"3\" armature=\"0.02\"/>\n"
    "      <inertial pos=\"0 0 0\" mass=\"0.2\" diaginertia=\"1e-4 1e-4 1e-4\"/>\n"
    "      <body name=\"ry\"><joint name=\"ry\" axis=\"0 1 0\" range=\"-3 3\" damping=\"3\" armature=\"0.02\"/>\n"
    "       <inertial pos=\"0 0 0\" mass=\"0.2\" diaginertia=\"1e-4 1e-4 1e-4\"/>\n"
    "       <body name=\"rx\"><joint name=\"rx\" axis=\"1 0 0\" range=\"-6.3 6.3\" damping=\"3\" armature=\"0.02\"/>\n"
    "        <inertial pos=\"0 0 0\" mass=\"0.2\" diaginertia=\"1e-4 1e-4 1e-4\"/>\n"
    "        <body name=\"tool\" euler=\"0 -1.5707963 0\">\n"
    "         <inertial pos=\"0 0 0.02\" mass=\"0.2\" diaginertia=\"1.2e-4 1e-4 6e-5\"/>\n"
    "         <geom name=\"palm\" type=\"box\" pos=\"0 0 0.024\" size=\"0.014 0.034 0.010\" contype=\"1\"/>\n"
    "         <site name=\"tcp\" pos=\"0 0 0.069\"/>\n"
    "         <body name=\"finger_l\" pos=\"0 0 0.034\">\n"
    "          <inertial pos=\"0 0.004 0.03\" mass=\"0.02\" diaginertia=\"6e-6 6e-6 1e-6\"/>\n"
    "          <joint name=\"finger_l\" type=\"slide\" axis=\"0 1 0\" range=\"0 0.025\" damping=\"2\" armature=\"0.01\"/>\n"
    "          <geom name=\"finger_l\" type=\"box\" pos=\"0 0.004 0.03\" size=\"0.009 0.004 0.03\" contype=\"1\"/>\n"
    "         </body>\n"
    "         <body name=\"finger_r\" pos=\"0 0 0.034\">\n"
    "          <inertial pos=\"0 -0.004 0.03\" mass=\"0.02\" diaginertia=\"6e-6 6e-6 1e-6\"/>\n"
    "          <joint name=\"finger_r\" type=\"slide\" axis=\"0 -1 0\" range=\"0 0.025\" damping=\"2\" armature=\"0.01\"/>\n"
    "          <geom name=\"finger_r\" type=\"box\" pos=\"0 -0.004 0.03\" size=\"0.009 0.004 0.03\" contype=\"1\"/>\n"
    "         </body>\n"
    "        </body></body></body></body></body></body></body></body>\n"
    " </worldbody>\n"
    " <actuator>\n"
    "  <position joint=\"x\" kp=\"5000\" ctrlrange=\"-1 1\" forcerange=\"-200 200\"/>\n"
    "  <position joint=\"y\" kp=\"5000\" ctrlrange=\"-1 1\" forcerange=\"-200 200\"/>\n"
    "  <position joint=\"z\" kp=\"5000\" ctrlrange=\"-1 1\" forcerange=\"-200 200\"/>\n"
    "  <position joint=\"rz\" kp=\"50\" ctrlrange=\"-6.3 6.3\" forcerange=\"-10 10\"/>\n"
    "  <position joint=\"ry\" kp=\"50\" ctrlrange=\"-3 3\" forcerange=\"-10 10\"/>\n"
    "  <position joint=\"rx\" kp=\"50\" ctrlrange=\"-6.3 6.3\" forcerange=\"-10 10\"/>\n"
    "  <position name=\"finger_l\" joint=\"finger_l\" kp=\"1000\" ctrlrange=\"0 0.025\" forcerange=\"-3 3\"/>\n"
    "  <position name=\"finger_r\" joint=\"finger_r\" kp=\"1000\" ctrlrange=\"0 0.025\" forcerange=\"-3 3\"/>\n"
    " </actuator>\n"
    "</mujoco>\n";

// MJCF of a one-axis pusher: a sphere of radius 1 cm on a slide along y with a position servo
// (gain kp N/m, limit fmax N) and two dummy fingers
static void pusher_mjcf(const char* path, double kp, double fmax) {
  FILE* f = fopen(path, "w");
  if (!f) return;
  fprintf(f,
          "<mujoco><compiler autolimits=\"true\"/><option timestep=\"0.002\" gravity=\"0 0 0\"/>\n"
          "<worldbody><body name=\"base\" pos=\"0 0 0\">\n"
          " <body name=\"slider\"><joint name=\"y\" type=\"slide\" axis=\"0 1 0\" range=\"-1 1\" damping=\"%g\"/>\n"
          "  <inertial pos=\"0 0 0\" mass=\"0.5\" diaginertia=\"1e-3 1e-3 1e-3\"/>\n"
          "  <geom name=\"ball\" type=\"sphere\" size=\"0.01\" contype=\"1\" conaffinity=\"0\"/>\n"
          "  <site name=\"tcp\"/>\n"
          "  <body name=\"fl\" pos=\"0 0 0.2\"><joint name=\"fl\" type=\"slide\" axis=\"1 0 0\" range=\"0 0.02\"/>"
          "<geom size=\"0.002\" contype=\"0\" conaffinity=\"0\" mass=\"0.01\"/></body>\n"
          "  <body name=\"fr\" pos=\"0 0 0.2\"><joint name=\"fr\" type=\"slide\" axis=\"-1 0 0\" range=\"0 0.02\"/>"
          "<geom size=\"0.002\" contype=\"0\" conaffinity=\"0\" mass=\"0.01\"/></body>\n"
          " </body></body></worldbody>\n"
          "<actuator><position name=\"y\" joint=\"y\" kp=\"%g\" forcelimited=\"true\" forcerange=\"%g %g\"/>\n"
          " <position name=\"finger_l\" joint=\"fl\" kp=\"100\"/><position name=\"finger_r\" joint=\"fr\" kp=\"100\"/>\n"
          "</actuator></mujoco>\n",
          2 * sqrt(kp * 0.5), kp, -fmax, fmax);
  fclose(f);
}

// a horizontal cantilever along +x from the origin, length L, radius r, no gravity
static vd_model* rod_plant(double len, double r) {
  vd_beam_def d = vd_beam_def_default();
  d.origin = vd_v3(0, 0, 0.3), d.length = len, d.radius = r, d.one_instance = 1, d.label = "branch";
  vd_model* m;
  vd_error e = {0};
  vd_plant_beam_model(&d, &m, &e);
  return m;
}

// push the rod's tip sideways with the pusher for T seconds; returns the tip's displacement (m)
// and the pusher's lag behind its command (m), the plant's reaction (N) and the servo force (N)
void robot_push_rod(int two_way, double kp, double fmax, double young, const char* dir, double* tip,
                    double* lag, double* reaction, double* servo, double* clamp, double* tip_mass) {
  char path[4200];
  snprintf(path, sizeof path, "%s/pusher.xml", dir);
  pusher_mjcf(path, kp, fmax);
  char text[8192];
  snprintf(text, sizeof text,
           "{\"format\": \"verdant-scene\", \"version\": 1, \"plant\": {\"file\": \"x.lpy\"},"
           " \"robot\": {\"mjcf\": \"%s\", \"base\": {\"pos\": [0.2, -0.015, 0.3]}},"
           " \"sim\": {\"gravity\": [0, 0, 0], \"ground\": null, \"segment_length\": 0.02, \"drag\": false,"
           " \"mass_damping\": 20, \"sag_free\": false},"
           " \"materials\": {\"wood\": {\"young\": %g}}, \"target\": {\"fruit\": 1},"
           " \"two_way\": %s, \"duration\": 30}",
           path, young, two_way ? "true" : "false");
  vd_error e = {0};
  vd_scene s;
  vd_scene_parse(text, strlen(text), NULL, &s, &e);
  vd_model* pm = rod_plant(0.2, 0.004);
  vd_harvest* h = NULL;
  vd_harvest_create(&s, pm, &h, &e);  // no fruit: the episode has no target (an outcome)
  unlink(path);
  *tip = *lag = *reaction = *servo = *clamp = *tip_mass = NAN;
  if (!h) {
    vd_model_destroy(pm);
    vd_scene_free(&s);
    return;
  }
  // no fruit to harvest: the pusher is driven by hand
  const vd_sim_model* sm = vd_harvest_sim_model(h);
  int tipn = sm->seg_node[2 * (sm->nseg - 1) + 1];
  // 2 cm/s along +y for 1.5 s (3 cm), then hold for 1.5 s
  for (int k = 0; k < 300 && !vd_harvest_done(h); k++) {
    vd_harvest_action a = {{0, k < 150 ? 0.02 : 0, 0}, {0, 0, 0}, 0};
    if (vd_harvest_step(h, &a, &e)) break;
  }
  vd_harvest_obs o;
  vd_harvest_observe(h, &o);
  *tip = vd_norm(vd_sub(vd_harvest_sim_data(h)->node_pos[tipn], sm->node_pos0[tipn]));
  *lag = o.cmd_pos.y - o.ee_pos.y;
  *reaction = o.robot_force.y;
  *servo = h->d->actuator_force[h->rb->arm_act[0]];
  // the rod's force on its clamp: the stretch-shear multiplier of the first free segment
  const vd_sim_data* sd = vd_harvest_sim_data(h);
  for (int t = 0; t < sm->nseg; t++) {
    if ((sm->seg_flags[t] & VD_SIM_FIXED) || !sm->node_fixed[sm->seg_node[2 * t]]) continue;
    double h2 = sm->opt.dt * sm->opt.dt;
    const double* l = sd->seg_lambda + 6 * t;
    vd_vec3 f = vd_quat_rotate(sd->seg_quat[t], vd_v3(l[0] / h2, l[1] / h2, l[2] / h2));
    *clamp = f.y / sm->seg_len0[t];
  }
  *tip_mass = sd->node_mass[tipn];
  vd_harvest_destroy(h);
  vd_model_destroy(pm);
  vd_scene_free(&s);
}

// write text to dir/name; 0 on failure
static int write_file(const char* dir, const char* name, const char* text, char* path, size_t cap) {
  snprintf(path, cap, "%s/%s", dir, name);
  FILE* f = fopen(path, "w");
  if (!f) return 0;
  int ok = fputs(text, f) >= 0;
  return fclose(f) == 0 && ok;
}

// a scene for the truss and the validation gantry at path
static void truss_scene(vd_scene* s, const char* robot) {
  vd_scene_default(s);
  snprintf(s->robot_path, sizeof s->robot_path, "%s", robot);
  s->base_pos = vd_v3(0.45, 0, 0.46);
  s->duration = 8;
  s->sim_def.segment_length = 0.02;
  // the materials' thresholds, fixed: each case states its own
  s->draw_calyx[0] = s->draw_calyx[1] = s->draw_abscission[0] = s->draw_abscission[1] = NAN;
}

typedef struct outcome {
  vd_harvest_summary sum;
  double stretch;  // end-effector travel from the grasp to the detachment (m)
  vd_status st;
} outcome;

static vd_status stretch_step(void* user, const vd_harvest* h) {
  double* grasp = user;  // [held-from x, y, z, set?, travel]
  vd_harvest_obs o;
  vd_harvest_observe(h, &o);
  if (o.held && !grasp[3]) grasp[0] = o.ee_pos.x, grasp[1] = o.ee_pos.y, grasp[2] = o.ee_pos.z, grasp[3] = 1;
  if (grasp[3] && !o.detached) grasp[4] = vd_norm(vd_sub(o.ee_pos, vd_v3(grasp[0], grasp[1], grasp[2])));
  return VD_OK;
}

// run the scripted method of scene s on the truss
static outcome harvest(const vd_scene* s, vd_error* err) {
  outcome out;
  memset(&out, 0, sizeof out);
  vd_model* pm = robot_truss(0.012);
  vd_harvest* h = NULL;
  double track[5] = {0, 0, 0, 0, 0};
  out.st = pm ? vd_harvest_create(s, pm, &h, err) : VD_ERR_NOMEM;
  if (!out.st) out.st = vd_harvest_run(h, stretch_step, track, err);
  if (h) vd_harvest_summarize(h, &out.sum);
  out.stretch = track[4];
  vd_harvest_destroy(h);
  vd_model_destroy(pm);
  return out;
}

// results under construction
typedef struct results {
  vd_validate_result* r;
  int n, cap;
  const vd_validate_def* def;
} results;

static int wanted(const results* rs, const char* name) {
  if (rs->def->filter && !strstr(name, rs->def->filter)) return 0;
  if (rs->def->progress) rs->def->progress(rs->def->user, name);
  return 1;
}

// add a result: pass when |measured - reference| <= tolerance (absolute) unless the case says
// otherwise through pass_override (>= 0)
static void add(results* rs, const char* name, const char* quantity, double measured,
                double reference, double error, double tolerance, int pass, const char* note) {
  if (!vd_grow((void**)&rs->r, &rs->cap, rs->n + 1, sizeof *rs->r)) return;
  vd_validate_result* v = &rs->r[rs->n++];
  memset(v, 0, sizeof *v);
  snprintf(v->name, sizeof v->name, "%s", name);
  snprintf(v->form, sizeof v->form, "published");
  snprintf(v->quantity, sizeof v->quantity, "%s", quantity);
  v->measured = measured;
  v->reference = reference;
  v->error = error;
  v->tolerance = tolerance;
  v->pass = pass;
  snprintf(v->note, sizeof v->note, "%s", note);
}

// a range check lo..hi as a result: reference the middle, tolerance the half width
static void add_range(results* rs, const char* name, const char* quantity, double x, double lo,
                      double hi, const char* note) {
  double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  add(rs, name, quantity, x, mid, fabs(x - mid), half, isfinite(x) && fabs(x - mid) <= half, note);
}

vd_status vd_robot_validate(const vd_validate_def* def, vd_validate_result** out, int* n,
                            vd_error* err) {
  *out = NULL;
  *n = 0;
  results rs = {NULL, 0, 0, def};
  // the validation robot in a scratch folder
  const char* tmp = getenv("TMPDIR");
  char dir[3800], robot[4096];
  snprintf(dir, sizeof dir, "%s/verdant-validate-XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
  if (!mkdtemp(dir)) return vd_error_set(err, VD_ERR_IO, dir, 0, 0, "cannot make a scratch folder");
  if (!write_file(dir, "gantry6.xml", gantry6_xml, robot, sizeof robot)) {
    rmdir(dir);
    return vd_error_set(err, VD_ERR_IO, dir, 0, 0, "cannot write the validation robot");
  }
  vd_scene s;
  vd_status st = VD_OK;
  double pull_calyx = NAN;
  // pull: the calyx (fruit joint, 1.5 N by default) breaks within Xie et al. 2021's range
  if (wanted(&rs, "harvest_pull_calyx") || wanted(&rs, "harvest_bend_vs_pull")) {
    truss_scene(&s, robot);
    s.method.method = VD_HARVEST_PULL, s.method.speed = 0.04, s.method.distance = 0.1;
    outcome o = harvest(&s, err);
    if (o.st) st = o.st;
    pull_calyx = o.sum.pull_force;
    if (!def->filter || strstr("harvest_pull_calyx", def->filter))
      add_range(&rs, "harvest_pull_calyx", "gripper force at detachment (N)",
                o.sum.site == VD_SITE_CALYX ? o.sum.pull_force : NAN, 0.58, 2.46,
                "default materials, site calyx; range: Xie et al. 2021 (cherry tomato pulling)");
    vd_scene_free(&s);
  }
  // pull with the calyx made unbreakable: the abscission node (6.5 N) within 5-8 N
  if (!st && wanted(&rs, "harvest_pull_abscission")) {
    truss_scene(&s, robot);
    s.method.method = VD_HARVEST_PULL, s.method.speed = 0.01, s.method.distance = 0.1;
    s.duration = 15;
    s.method.grip_force = 6;  // friction 2 x 0.8 x 6 = 9.6 N holds it
    s.sim_def.material[VD_SIM_FRUIT].break_force = INFINITY;
    // a tensile test: the knuckle's bending threshold off
    s.sim_def.material[VD_SIM_PEDICEL].break_moment = INFINITY;
    outcome o = harvest(&s, err);
    if (o.st) st = o.st;
    add_range(&rs, "harvest_pull_abscission", "gripper force at detachment (N)",
              o.sum.site == VD_SITE_ABSCISSION ? o.sum.pull_force : NAN, 5, 8,
              "tension only (calyx and knuckle moment off), site abscission; range: abscission zone "
              "5-8 N in tension (facts 5.2)");
    vd_scene_free(&s);
  }
  // a quasi-static pull (1 cm/s): the force the gripper's sensor reads at the break is the calyx
  // joint's threshold (the fruit's weight and inertia are small beside it); the forces logged at
  // every plant step (vd_harvest_forces) end at the joint's fracture load
  if (!st && wanted(&rs, "harvest_pull_quasistatic")) {
    truss_scene(&s, robot);
    s.method.method = VD_HARVEST_PULL, s.method.speed = 0.01, s.method.distance = 0.1;
    s.duration = 12;
    double thr = s.sim_def.material[VD_SIM_FRUIT].break_force;
    outcome o = harvest(&s, err);
    if (o.st) st = o.st;
    double f = o.sum.site == VD_SITE_CALYX ? o.sum.pull_force : NAN;
    add(&rs, "harvest_pull_quasistatic", "gripper force at the break / calyx threshold (-)", f / thr, 1,
        fabs(f / thr - 1), 0.05, isfinite(f) && fabs(f / thr - 1) <= 0.05,
        "pull at 0.01 m/s, site calyx: within 5 % of the joint's break force (issue 20 item 2)");
    vd_scene_free(&s);
  }
  // bend: detaches with less force than pull (tomato peduncle tests, Trans. CSAE 2008)
  if (!st && (!def->filter || strstr("harvest_bend_vs_pull", def->filter))) {
    truss_scene(&s, robot);
    s.method.method = VD_HARVEST_BEND, s.method.angle = 0.5 * M_PI, s.method.angular_speed = M_PI / 3;
    outcome o = harvest(&s, err);
    if (o.st) st = o.st;
    double ratio = o.sum.detached ? o.sum.pull_force / pull_calyx : NAN;
    add(&rs, "harvest_bend_vs_pull", "bend / pull detachment force (-)", ratio, 1, ratio, 1,
        isfinite(ratio) && ratio < 1,
        "passes below 1: bending detaches with less force (Trans. CSAE 2008; facts 5.2)");
    vd_scene_free(&s);
  }
  // Gazebo Plants' bending run: C_b^max = 0.31 on the fruit's joints (other thresholds off)
  if (!st && wanted(&rs, "harvest_bend_cb031")) {
    truss_scene(&s, robot);
    s.method.method = VD_HARVEST_BEND, s.method.angle = 0.5 * M_PI, s.method.angular_speed = M_PI / 3;
    for (int c = 0; c < VD_SIM_CLASS_COUNT; c++) {
      vd_sim_material* mt = &s.sim_def.material[c];
      mt->break_force = mt->break_moment = mt->break_cs = mt->break_cb = INFINITY;
    }
    s.sim_def.material[VD_SIM_FRUIT].break_cb = 0.31;
    s.sim_def.material[VD_SIM_PEDICEL].break_cb = 0.31;
    outcome o = harvest(&s, err);
    if (o.st) st = o.st;
    add(&rs, "harvest_bend_cb031", "detached (1) or not (0)", o.sum.detached, 1,
        fabs(o.sum.detached - 1.0), 0, o.sum.detached == 1,
        "bending with C_b^max = 0.31 1/m on the fruit's joints (Deng et al., Gazebo Plants 4.3)");
    vd_scene_free(&s);
  }
  // the C_s^max sweep of Gazebo Plants' Fig. 9: more stretch before detachment as it rises
  if (!st && wanted(&rs, "harvest_cs_sweep")) {
    static const double cs[4] = {0.05, 0.1, 0.2, 0.35};
    double travel[4], worst = INFINITY;
    for (int k = 0; k < 4 && !st; k++) {
      truss_scene(&s, robot);
      s.method.method = VD_HARVEST_PULL, s.method.speed = 0.04, s.method.distance = 0.25;
      s.duration = 12;
      for (int c = 0; c < VD_SIM_CLASS_COUNT; c++) {
        vd_sim_material* mt = &s.sim_def.material[c];
        mt->break_force = mt->break_moment = mt->break_cs = mt->break_cb = INFINITY;
      }
      // a herbaceous pedicel (E 1e8 Pa; the paper sets 1e6-1e7 Pa for herbaceous plants, 2e7 in
      // its Figs. 6-7: the trend holds there too, with a smaller last step) with the threshold on
      // it and on the fruit's joint; a grip that does not slip (friction 1)
      s.sim_def.material[VD_SIM_PEDICEL].young = 1e8;
      s.sim_def.material[VD_SIM_PEDICEL].break_cs = cs[k];
      s.sim_def.material[VD_SIM_FRUIT].break_cs = cs[k];
      s.method.grip_force = 3;
      s.method.grip_friction = 1;
      outcome o = harvest(&s, err);
      if (o.st) st = o.st;
      travel[k] = o.sum.detached ? o.stretch : NAN;
      if (k) worst = fmin(worst, travel[k] / travel[k - 1]);
      vd_scene_free(&s);
    }
    char note[160];
    snprintf(note, sizeof note,
             "pull travel to detachment at C_s^max 0.05/0.1/0.2/0.35: %.1f/%.1f/%.1f/%.1f mm; "
             "passes when each exceeds the last (Gazebo Plants Fig. 9)",
             1e3 * travel[0], 1e3 * travel[1], 1e3 * travel[2], 1e3 * travel[3]);
    add(&rs, "harvest_cs_sweep", "smallest travel ratio of successive C_s^max (-)", worst, 1,
        worst, 1, isfinite(worst) && worst > 1, note);
  }
  // two-way: a stiff branch (E 1e10 Pa, r 4 mm, L 0.2 m: 3EI/L^3 = 754 N/m) stops a pusher
  // limited to 2 N; the reaction it feels equals the rod's force on its clamp and its servo's
  if (!st && wanted(&rs, "two_way_stiff_branch")) {
    double tip, lag, r, f, clamp, m;
    robot_push_rod(1, 5000, 2, 1e10, dir, &tip, &lag, &r, &f, &clamp, &m);
    double k = 3 * 1e10 * (M_PI * pow(0.004, 4) / 4) / pow(0.2, 3), mh = m / 1e-6;
    char note[160];
    snprintf(note, sizeof note, "pusher stopped %.1f mm short of its 30 mm command at its 2 N limit; "
             "servo %.4f N", 1e3 * lag, fabs(f));
    double e1 = fabs(-r - (-clamp)) / fabs(clamp);
    add(&rs, "two_way_stiff_branch", "reaction on the arm vs the rod's clamp force (N)", -r, -clamp, e1,
        0.01, lag > 0.01 && e1 <= 0.01 && fabs(-r - f) <= 0.01 * fabs(f), note);
    double want = k * tip * mh / (mh + k), e2 = fabs(fabs(r) - want) / want;
    add(&rs, "two_way_contact_factor", "reaction vs k tip m/h^2 / (m/h^2 + k) (N)", fabs(r), want, e2,
        0.03, e2 <= 0.03,
        "position-projected contacts pass on m/h^2/(m/h^2+k) of the static force (docs/physics.md 9)");
  }
  // exactly n results (the caller frees n of them)
  if (rs.n && rs.cap > rs.n) {
    vd_validate_result* r = vd_realloc(rs.r, (size_t)rs.cap * sizeof *rs.r, (size_t)rs.n * sizeof *rs.r);
    if (r) rs.r = r, rs.cap = rs.n;
  }
  if (rs.cap != rs.n) {
    vd_free(rs.r, (size_t)rs.cap * sizeof *rs.r);
    rs.r = NULL, rs.n = 0;
    if (!st) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  *out = rs.r;
  *n = rs.n;
  unlink(robot);
  rmdir(dir);
  return st;
}
