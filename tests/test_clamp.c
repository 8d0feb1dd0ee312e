// SPDX-License-Identifier: MIT
// clamp: the pot clamp of a plant's base (vd_sim_def::clamp_length, `sim --clamp`); 0 holds only
// the base node and its frame, so a rod from the base is an exact cantilever (issue 12, item 22).
#include "test.h"
#include "verdant/verdant.h"

// a horizontal rod of length len and radius r from the origin along +x, its base the plant's root
static vd_model* rod_plant(double len, double r) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0)), b = vd_plant_add_node(s, vd_v3(len, 0, 0));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = r, g.label = 1, g.instance = 1, g.up = vd_v3(0, 0, 1);
  vd_plant_add_segment(s, &g);
  vd_plant_set_label(s, 1, "stem");
  return vdt_compile(s);
}

// static tip deflection under a tip load p (N) with the given clamp length (m); -1 on failure
static double tip_deflection(const vd_model* pm, double clamp, double p, double* mass) {
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.01;
  def.clamp_length = clamp;
  def.gravity = vd_v3(0, 0, 0);
  vd_sim_model* m = NULL;
  vd_error e = {0};
  if (vd_sim_build(pm, &def, &m, &e)) return -1;
  m->opt.gravity = vd_v3(0, 0, 0);
  vd_sim_data* d = vd_sim_data_create(m);
  double defl = -1;
  if (d && m->main_tip >= 0) {
    d->node_force[m->main_tip] = vd_v3(0, 0, -p);
    vd_sim_settle_def s = vd_sim_settle_def_default();
    s.statics = 1;
    int ok = 0;
    vd_sim_settle(m, d, &s, &ok, NULL);
    if (ok) defl = -d->node_pos[m->main_tip].z;
  }
  if (mass) *mass = m->total_mass;
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  return defl;
}

TEST(clamp, zero_is_an_exact_cantilever) {
  double len = 0.2, r = 0.002, p = 0.01, young = vd_sim_def_default().material[VD_SIM_GREEN].young;
  vd_model* pm = rod_plant(len, r);
  REQUIRE(pm);
  double inertia = VD_PI * r * r * r * r / 4;
  double m0 = 0, m1 = 0;
  double free_base = tip_deflection(pm, 0, p, &m0), potted = tip_deflection(pm, 0.01, p, &m1);
  // Euler-Bernoulli P L^3 / 3 E I for the whole length with clamp 0 (shear adds 0.3 %, the
  // discretisation less); with a 1 cm pot the free length is L - 1 cm
  CHECK_NEAR(free_base / (p * len * len * len / (3 * young * inertia)), 1.0, 0.01);
  double short_len = len - 0.01;
  CHECK_NEAR(potted / (p * short_len * short_len * short_len / (3 * young * inertia)), 1.0, 0.01);
  // the fixed segment behind the base adds no mass
  CHECK_NEAR(m0, m1, 1e-12 + 1e-9 * m1);
  vd_model_destroy(pm);
}

TEST(clamp, settings) {
  vd_model* pm = rod_plant(0.1, 0.002);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  vd_sim_model* m = NULL;
  vd_error e = {0};
  def.clamp_length = -0.01;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_ERR_VALUE, e);
  def.clamp_length = 0;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}
