// SPDX-License-Identifier: MIT
// The flexible export checked in MuJoCo: a horizontal cantilever's rods exported as MJCF
// (vd_sim_export_rods + vd_geom_export), loaded alone in MuJoCo and settled under its own weight
// and under a tip load, against the rods' own statics and Euler-Bernoulli (docs/validation.md,
// "Exports").
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <mujoco/mujoco.h>

#include "mjtrap/mjtrap.h"
#include "robot_internal.h"

// the test beam: clamped 1 cm behind the origin, then L along +x at 0.3 m height
typedef struct beam {
  double len, r, e, rho;  // m, m, Pa, kg/m^3
  int nseg;               // rod segments of the free part
} beam;

static vd_status beam_rods(const beam* b, vd_model** pm, vd_sim_model** sm, vd_error* err) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  double l = b->len / b->nseg;
  vd_plant_add_node(s, vd_v3(-l, 0, 0.3));
  vd_plant_add_node(s, vd_v3(0, 0, 0.3));
  vd_plant_add_node(s, vd_v3(b->len, 0, 0.3));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = 0, g.node1 = 1, g.r0 = g.r1 = b->r, g.label = 1, g.instance = 1, g.up = vd_v3(0, 0, 1);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = 1, g.node1 = 2, g.parent = s0, g.instance = 2;
  vd_plant_add_segment(s, &g);
  vd_status st = vd_plant_set_label(s, 1, "stem");
  if (!st) st = vd_plant_compile(s, pm, err);
  vd_plant_spec_destroy(s);
  if (st) return st;
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = l, def.clamp_length = l;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) {
    def.material[k].young = b->e, def.material[k].density = b->rho;
    def.material[k].break_force = def.material[k].break_moment = INFINITY;
  }
  st = vd_sim_build(*pm, &def, sm, err);
  if (st) vd_model_destroy(*pm), *pm = NULL;
  return st;
}

// the rods' tip (main axis end) settled under gravity (on/off) and a tip force; deflection in z
static double rods_sag(const vd_sim_model* sm, int gravity, double tip_force, int* ok) {
  vd_sim_data* d = sm ? vd_sim_data_create(sm) : NULL;
  if (!d) return NAN;
  vd_sim_model* m = (vd_sim_model*)sm;  // the run settings are the caller's to change
  vd_vec3 g0 = m->opt.gravity;
  m->opt.gravity = gravity ? g0 : vd_v3(0, 0, 0);
  m->opt.drag = 0;
  int tip = sm->main_tip;
  d->node_force[tip] = vd_v3(0, 0, -tip_force);
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.statics = 1, s.disp_tol = 1e-12, s.max_steps = 3000;
  vd_sim_settle(sm, d, &s, ok, NULL);
  double dz = d->node_pos[tip].z - sm->node_pos0[tip].z;
  m->opt.gravity = g0;
  vd_sim_data_destroy(d);
  return dz;
}

// the exported MJCF settled in MuJoCo (implicit damping, 0.2 ms steps, up to 8 s): deflection
// in z of the rest tip point carried by the body nearest to it
static double mujoco_sag(const char* path, vd_vec3 tip_rest, int gravity, double tip_force, int* ok,
                         vd_status* st, vd_error* err) {
  mjModel* mm = NULL;
  *ok = 0;
  if ((*st = vd_mj_load_xml(path, "exported plant MJCF", &mm, err))) return NAN;
  mjData* md = mj_makeData(mm);
  volatile double dz = NAN;
  vd_mj_trap trap;
  vd_mj_trap_install();
  if (md && VD_MJ_TRY(&trap)) {
    mm->opt.timestep = 2e-4;
    mm->opt.integrator = mjINT_IMPLICIT;
    if (!gravity) mm->opt.gravity[2] = 0;
    mj_forward(mm, md);
    // the body whose frame origin is nearest the tip (the last link) and the tip in its frame
    int tb = 1;
    double best = INFINITY, tip_body[3];
    for (int b = 1; b < mm->nbody; b++) {
      const double* x = md->xpos + 3 * b;
      double dd = hypot(hypot(x[0] - tip_rest.x, x[1] - tip_rest.y), x[2] - tip_rest.z);
      if (dd < best) best = dd, tb = b;
    }
    double offset[3] = {tip_rest.x - md->xpos[3 * tb], tip_rest.y - md->xpos[3 * tb + 1],
                        tip_rest.z - md->xpos[3 * tb + 2]};
    mju_mulMatTVec(tip_body, md->xmat + 9 * tb, offset, 3, 3);
    double last = INFINITY, z = 0;
    for (int k = 0; k < 40000; k++) {
      // the tip force at the tip point: force at the body's centre of mass plus its moment
      double p[3], arm[3], f[3] = {0, 0, -tip_force}, tq[3];
      mju_mulMatVec(p, md->xmat + 9 * tb, tip_body, 3, 3);
      mju_addTo3(p, md->xpos + 3 * tb);
      mju_sub3(arm, p, md->xipos + 3 * tb);
      mju_cross(tq, arm, f);
      mju_copy3(md->xfrc_applied + 6 * tb, f);
      mju_copy3(md->xfrc_applied + 6 * tb + 3, tq);
      mj_step(mm, md);
      z = p[2];
      if (k % 1000 == 999) {
        if (fabs(z - last) < 1e-9) {
          *ok = 1;
          break;
        }
        last = z;
      }
    }
    dz = z - tip_rest.z;
    vd_mj_trap_end(&trap);
  } else if (md) {
    *st = vd_mj_trap_status(&trap, err);
  } else {
    *st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
  mj_deleteData(md);
  mj_deleteModel(mm);
  return dz;
}

vd_status vd_robot_validate_export(const vd_validate_def* def, vd_validate_result** out, int* n,
                                   vd_error* err) {
  *out = NULL, *n = 0;
  vd_validate_list list = {NULL, 0, 0};
  int sag = !def->filter || strstr("export_flex_self_weight", def->filter);
  int load = !def->filter || strstr("export_flex_tip_load", def->filter);
  if (!sag && !load) return VD_OK;
  // a green stem 0.5 m long, 3 mm radius, E 1 GPa, 1000 kg/m^3, in 2 cm rods (25 links)
  beam b = {0.5, 0.003, 1e9, 1000, def->full ? 50 : 25};
  vd_model* pm = NULL;
  vd_sim_model* sm = NULL;
  vd_status st = beam_rods(&b, &pm, &sm, err);
  if (st) return st;
  const char* tmp = getenv("TMPDIR");
  char dir[3800], path[4096];
  snprintf(dir, sizeof dir, "%s/verdant-export-XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
  if (!mkdtemp(dir)) st = vd_error_set(err, VD_ERR_IO, dir, 0, 0, "cannot make a scratch folder");
  snprintf(path, sizeof path, "%s/beam.xml", dir);
  vd_export_rods rods;
  memset(&rods, 0, sizeof rods);
  if (!st) st = vd_sim_export_rods(sm, pm, &rods, err);
  if (!st) {
    vd_export_def ed = vd_export_def_default();
    ed.rods = &rods;
    ed.damping_ratio = 150;  // overdamped links: the first mode settles in about a second
    st = vd_geom_export(pm, NULL, &ed, path, err);
  }
  double ei = b.e * VD_PI * pow(b.r, 4) / 4, q = b.rho * VD_PI * b.r * b.r * 9.81;
  double p = 0.05;  // N
  vd_vec3 tip = vd_v3(b.len, 0, 0.3);
  for (int c = 0; c < 2 && !st; c++) {
    if (!(c ? load : sag)) continue;
    const char* nm = c ? "export_flex_tip_load" : "export_flex_self_weight";
    if (def->progress) def->progress(def->user, nm);
    int ok_r = 0, ok_m = 0;
    double rz = rods_sag(sm, !c, c ? p : 0, &ok_r);
    double mz = mujoco_sag(path, tip, !c, c ? p : 0, &ok_m, &st, err);
    if (st) break;
    double eb = c ? p * pow(b.len, 3) / (3 * ei) : q * pow(b.len, 4) / (8 * ei);
    if (!vd_validate_add(&list, nm, "rods", "tip deflection (m)", -mz, -rz, 0.05, 0,
                         "MJCF of %d links in MuJoCo vs the rods%s; Euler-Bernoulli %.4g m (%s)",
                         b.nseg, ok_r && ok_m ? "" : " [not settled]", eb,
                         c ? "PL^3/3EI, P 0.05 N" : "qL^4/8EI"))
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
  vd_sim_export_rods_free(&rods);
  unlink(path);
  rmdir(dir);
  vd_sim_model_destroy(sm);
  vd_model_destroy(pm);
  if (st) {
    vd_free(list.r, sizeof *list.r * (size_t)list.cap);
    return st;
  }
  return vd_validate_finish(&list, out, n, err);
}
