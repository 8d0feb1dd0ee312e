// SPDX-License-Identifier: MIT
// sim: rod model built from plants (resampling, key nodes, leaves, fruits, abscission, clamp,
// bindings), settings checks, out of memory, determinism, loads (gravity, wind), solvers
// against each other, fracture events, contacts, the sag-free gate on the bundled tomato.
#include <stdlib.h>

#include "sim/sim_internal.h"
#include "test.h"
#include "verdant/verdant.h"

// grow a bundled plant (seed 0) and compile it
static vd_model* grow(const char* rel, vd_plant_spec** spec_out) {
  vd_error e = {0};
  vd_lsystem* ls = NULL;
  if (vd_lsys_load(vdt_path(rel), &ls, &e)) return NULL;
  vd_plant_spec* s = vd_plant_spec_create();
  vd_lsys_def def = vd_lsys_def_default();
  vd_model* m = NULL;
  if (s && !vd_lsys_grow(ls, &def, NULL, s, &e)) vd_plant_compile(s, &m, &e);
  vd_lsys_destroy(ls);
  if (spec_out)
    *spec_out = s;
  else
    vd_plant_spec_destroy(s);
  return m;
}

// a straight cantilever along +x: clamped piece of length l behind the origin, then L
static vd_model* cantilever(double len, double r, int with_fruit) {
  vd_plant_spec* s = vd_plant_spec_create();
  int a = vd_plant_add_node(s, vd_v3(-0.01, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(s, vd_v3(len, 0, 0));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = r, g.label = 1, g.instance = 1, g.up = vd_v3(0, 0, 1);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  int s1 = vd_plant_add_segment(s, &g);
  vd_plant_set_label(s, 1, "stem");
  if (with_fruit) {
    vd_sphere_spec f = vd_sphere_spec_default();
    f.center = vd_v3(len + 0.01, 0, 0), f.radius = 0.01, f.parent = s1, f.label = 2, f.instance = 3;
    vd_plant_add_sphere(s, &f);
    vd_plant_set_label(s, 2, "fruit");
  }
  vd_model* m = NULL;
  vd_error e = {0};
  vd_plant_compile(s, &m, &e);
  vd_plant_spec_destroy(s);
  return m;
}

static vd_sim_def cantilever_def(double sigma, double young, double rho) {
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = sigma;
  def.clamp_length = 0.01;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) def.material[k].young = young, def.material[k].density = rho;
  return def;
}

TEST(sim, build_tomato) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  vd_sim_model* m = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
  REQUIRE(m);
  int fixed = 0, leaf = 0, fruit = 0, absc = 0, flower = 0;
  for (int t = 0; t < m->nseg; t++) {
    unsigned f = m->seg_flags[t];
    fixed += !!(f & VD_SIM_FIXED), leaf += !!(f & VD_SIM_LEAFSEG), absc += !!(f & VD_SIM_ABSCISSION);
    if (f & VD_SIM_FRUITSEG) {
      if (m->seg_class[t] == VD_SIM_FRUIT)
        fruit++;
      else
        flower++;
    }
    // every rod segment is close to sigma unless a chain between key nodes is shorter
    if (!(f & (VD_SIM_FRUITSEG | VD_SIM_FIXED | VD_SIM_CONNECT))) CHECK(m->seg_len0[t] < 1.5 * def.segment_length + 1e-9);
    // the parent of a free segment owns its start node (the tree the direct solver needs)
    int p = m->seg_parent[t], a = m->seg_node[2 * t];
    if (!(f & VD_SIM_FIXED) && p >= 0 && m->node_owner[a] >= 0) CHECK_INT(m->node_owner[a], p);
  }
  // one clamped piece (the pot), leaves as graphs, 25 fruits and 11 buds on stalks, an
  // abscission joint on every one of the 36 pedicels (seed 0: docs/plants.md)
  CHECK_INT(fixed, 1);
  CHECK(leaf > 168 * 3);
  CHECK_INT(fruit, 25);
  CHECK_INT(flower, 11);
  CHECK_INT(absc, 36);
  // breakable: the 36 abscission joints and the 25 calyx joints
  CHECK_INT(m->nspare, 61);
  // every plant node, segment, sphere and leaf vertex follows the rods
  for (int i = 0; i < m->nbind_node; i++) CHECK(m->bind_node_ref[i] >= 0 || m->bind_node_seg[i] >= 0);
  for (int j = 0; j < m->nbind_seg; j++) CHECK(m->bind_seg_seg[j] >= 0);
  for (int k = 0; k < m->nbind_sphere; k++) CHECK(m->bind_sphere_node[k] >= 0);
  for (int v = 0; v < m->nbind_vert; v++) CHECK(m->bind_vert_seg[v] >= 0);
  CHECK(m->main_tip >= 0);
  CHECK(m->total_mass > 0.2 && m->total_mass < 1.0);
  // at rest the deformed plant is the plant
  vd_sim_data* d = vd_sim_data_create(m);
  vd_data* pd = vd_data_create(pm);
  REQUIRE(d && pd);
  vd_sim_to_plant(m, d, pm, pd);
  double worst = 0;
  for (int i = 0; i < 3 * pm->nnode; i++) worst = fmax(worst, fabs(pd->node_pos[i] - pm->node_pos0[i]));
  for (int i = 0; i < 3 * pm->nsphere; i++) worst = fmax(worst, fabs(pd->sphere_pos[i] - pm->sphere_pos0[i]));
  for (int i = 0; i < 3 * pm->nvert; i++) worst = fmax(worst, fabs(pd->vert_pos[i] - pm->vert_pos0[i]));
  CHECK(worst < 1e-12);
  vd_data_destroy(pd);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, segment_length) {
  // sigma changes the count, junctions stay where they are
  vd_model* pm = grow("data/tomato.lpy", NULL);
  REQUIRE(pm);
  int counts[2];
  double sig[2] = {0.02, 0.05};
  for (int k = 0; k < 2; k++) {
    vd_sim_def def = vd_sim_def_default();
    def.segment_length = sig[k];
    vd_sim_model* m = NULL;
    vd_error e = {0};
    CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
    REQUIRE(m);
    counts[k] = m->nseg;
    for (int i = 0; i < pm->nnode; i++) {
      int r = m->bind_node_ref[i];
      if (r < 0) continue;
      vd_vec3 p = vd_v3(pm->node_pos0[3 * i], pm->node_pos0[3 * i + 1], pm->node_pos0[3 * i + 2]);
      CHECK(vd_norm(vd_sub(m->node_pos0[r], p)) < 1e-12);
    }
    vd_sim_model_destroy(m);
  }
  CHECK(counts[1] < counts[0]);
  vd_model_destroy(pm);
}

TEST(sim, bad_settings) {
  vd_model* pm = cantilever(0.5, 0.005, 0);
  REQUIRE(pm);
  vd_error e = {0};
  vd_sim_model* m = NULL;
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_ERR_VALUE, e);
  def = vd_sim_def_default();
  def.material[VD_SIM_LEAF].young = -1;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_ERR_VALUE, e);
  def = vd_sim_def_default();
  def.material[VD_SIM_WOOD].poisson = 0.7;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_ERR_VALUE, e);
  def = vd_sim_def_default();
  def.gravity.z = NAN;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_ERR_VALUE, e);
  def = vd_sim_def_default();
  def.material[VD_SIM_FRUIT].break_force = 0;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_ERR_VALUE, e);
  CHECK(m == NULL);
  vd_model_destroy(pm);
}

TEST(sim, out_of_memory) {
  vd_model* pm = cantilever(0.3, 0.004, 1);
  REQUIRE(pm);
  int done = 0;
  for (int64_t b = 0; b < 400 && !done; b++) {
    vdt_oom_begin(b);
    vd_sim_def def = vd_sim_def_default();
    def.sag_free = 1;
    vd_sim_model* m = NULL;
    vd_sim_data* d = NULL;
    vd_error e = {0};
    vd_status st = vd_sim_build(pm, &def, &m, &e);
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    if (!st) d = vd_sim_data_create(m);
    if (d) {
      vd_sim_collider c = {VD_SIM_SPHERE, {0.05, 0, 0}, vd_v3(0.1, 0, 0.02), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
      vd_sim_add_collider(d, &c);
      for (int i = 0; i < 3; i++) vd_sim_step(m, d);
      done = vd_sim_add_tie(d, 2, vd_v3(0, 0, 0), 1e-4) >= 0;
    }
    vd_sim_data_destroy(d);
    vd_sim_model_destroy(m);
    vdt_oom_end();
  }
  CHECK(done);
  vd_model_destroy(pm);
}

// hash of a state's positions and frames
static uint64_t state_hash(const vd_sim_model* m, const vd_sim_data* d) {
  uint64_t h = 1469598103934665603ull;
  const unsigned char* p = (const unsigned char*)d->node_pos;
  for (size_t i = 0; i < (size_t)m->nnode_all * sizeof(vd_vec3); i++) h = (h ^ p[i]) * 1099511628211ull;
  p = (const unsigned char*)d->seg_quat;
  for (size_t i = 0; i < (size_t)m->nseg * sizeof(vd_quat); i++) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

TEST(sim, determinism) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  uint64_t h[2];
  for (int run = 0; run < 2; run++) {
    vd_sim_data* d = vd_sim_data_create(m);
    REQUIRE(d);
    vd_sim_collider c = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    vd_sim_add_collider(d, &c);
    for (int i = 0; i < 60; i++) CHECK(vd_sim_step(m, d) == VD_OK);
    h[run] = state_hash(m, d);
    CHECK_INT(d->nwarning, 0);
    vd_sim_data_destroy(d);
  }
  CHECK(h[0] == h[1]);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, wind_drag) {
  // steady wind across a cantilever: uniform load q = (rho_air / 2) C_d (2 r) v^2, so the tip
  // moves by q L^4 / 8 EI (small deflection) along the wind
  double len = 0.5, r = 0.004, e = 1e10, v = 10;
  vd_model* pm = cantilever(len, r, 0);
  REQUIRE(pm);
  vd_sim_def def = cantilever_def(0.0125, e, 1000);
  vd_sim_model* m = NULL;
  vd_error er = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &er) == VD_OK);
  m->opt.gravity = vd_v3(0, 0, 0);
  m->opt.wind = vd_v3(0, v, 0);
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.statics = 1;
  int ok = 0;
  vd_sim_settle(m, d, &s, &ok, NULL);
  CHECK(ok);
  double q = 0.5 * 1.226 * 1.2 * 2 * r * v * v, ei = e * 3.14159265358979 * pow(r, 4) / 4;
  double expect = q * pow(len, 4) / (8 * ei);
  double got = d->node_pos[m->main_tip].y;
  CHECK_NEAR(got / expect, 1.0, 0.01);
  // gusts and time series: the wind the solver sees
  vd_sim_opt o = m->opt;
  o.gust_amplitude = 0.5, o.gust_period = 2;
  CHECK_NEAR(sim_wind_at(&o, 0.5).y, 15.0, 1e-12);
  CHECK_NEAR(sim_wind_at(&o, 1.5).y, 5.0, 1e-12);
  double series[8] = {0, 0, 2, 0, 1, 0, 4, 0};
  o.wind_series = series, o.nwind = 2;
  CHECK_NEAR(sim_wind_at(&o, 0.25).y, 2.5, 1e-12);
  CHECK_NEAR(sim_wind_at(&o, 5).y, 4.0, 1e-12);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// settled tip sag of a soft cantilever under gravity with a given solver
static double solver_sag(vd_sim_solver solver, int iterations, double h) {
  vd_model* pm = cantilever(0.5, 0.004, 0);
  vd_sim_def def = cantilever_def(0.05, 2e7, 600);
  vd_sim_model* m = NULL;
  vd_error e = {0};
  if (!pm || vd_sim_build(pm, &def, &m, &e)) return NAN;
  m->opt.solver = solver, m->opt.iterations = iterations, m->opt.dt = h, m->opt.drag = 0;
  vd_sim_data* d = vd_sim_data_create(m);
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.extra_damping = 20, s.ke_tol = 1e-12, s.max_time = 10;
  vd_sim_settle(m, d, &s, NULL, NULL);
  double sag = -d->node_pos[m->main_tip].z;
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
  return sag;
}

TEST(sim, solvers_agree) {
  // the direct solver is exact after one iteration; Gauss-Seidel converges to the same
  // stiffness with enough sweeps (XPBD: the material, not the iteration count, sets it)
  double direct = solver_sag(VD_SIM_DIRECT, 1, 1e-3);
  double gs = solver_sag(VD_SIM_GS, 100, 1e-3);
  CHECK(direct > 0.05 && direct < 0.5);
  CHECK_NEAR(gs / direct, 1.0, 0.02);
}

TEST(sim, fracture_events) {
  vd_model* pm = cantilever(0.1, 0.001, 1);
  REQUIRE(pm);
  vd_sim_def def = cantilever_def(0.01, 5e8, 1000);
  def.material[VD_SIM_FRUIT].break_force = 0.5;
  def.material[VD_SIM_FRUIT].density = 800;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  m->opt.gravity = vd_v3(0, 0, 0);
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  int fruit = vd_sim_find_organ(m, pm, "fruit", 0);
  CHECK(fruit >= 0);
  CHECK_INT(vd_sim_find_organ(m, pm, "no such organ", 0), -1);
  for (int i = 0; i < 400; i++) {
    d->node_force[fruit] = vd_v3(2.0 * d->time, 0, 0);  // ramp 2 N/s along the rod
    vd_sim_step(m, d);
  }
  REQUIRE(d->nevent == 1);
  const vd_sim_event* ev = &d->event[0];
  CHECK_NEAR(ev->time, 0.25, 2.5e-3);
  CHECK(ev->force >= 0.5);
  CHECK_INT(ev->cls, VD_SIM_FRUIT);
  CHECK_INT(ev->cause, 0);
  CHECK(d->seg_broken[ev->seg]);
  // the fruit flew off, pulled by its force; the rod stayed
  CHECK(d->node_pos[fruit].x > 0.2);
  CHECK(fabs(d->node_pos[m->main_tip].x - 0.1) < 0.01);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, contacts) {
  vd_model* pm = cantilever(0.4, 0.003, 1);
  REQUIRE(pm);
  vd_sim_def def = cantilever_def(0.02, 5e7, 1000);
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, -0.02), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  CHECK_INT(vd_sim_add_collider(d, &g), 0);
  // an upright capsule sweeps sideways through the rod (one-way coupling cannot resolve a
  // rod pinched between two colliders, so the sweep keeps clear of the ground)
  vd_sim_collider p = {VD_SIM_CAPSULE, {0.02, 0.05, 0}, vd_v3(0.25, 0.1, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  int id = vd_sim_add_collider(d, &p);
  double worst = 0;
  int touched = 0;
  for (int i = 0; i < 500; i++) {
    vd_sim_set_collider_pose(m, d, id, vd_v3(0.25, 0.1 - 0.3 * i / 500.0, 0), vd_quat_identity());
    touched |= d->ncontact > 0;
    vd_sim_step(m, d);
    worst = fmax(worst, d->max_penetration);
  }
  CHECK(touched);
  CHECK(worst < 1e-4);
  CHECK(d->node_pos[m->main_tip].z > -0.02 - 1e-4);
  for (int k = d->ncollider; k < VD_SIM_MAX_COLLIDERS; k++) vd_sim_add_collider(d, &g);
  CHECK_INT(vd_sim_add_collider(d, &g), -1);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// a thick upright stem standing in the ground (as the bundled tree's trunk, r = 8 cm, at
// sigma 2 cm): its first free nodes sit 2-6 cm above the plane, within their radius of it. As
// node spheres the plane pushed them up by the radius and the first segment stayed stretched
// by 260 % every step (tree: 100 of 100 steps stretched, 7 retaken); the rod's flat cross
// sections reach nothing below an upright node, so it stands as modelled
TEST(sim, ground_upright_trunk) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  int a = vd_plant_add_node(s, vd_v3(0, 0, -0.01)), b = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(s, vd_v3(0.01, 0, 1.0));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.08, g.label = 1, g.instance = 1, g.up = vd_v3(1, 0, 0);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  vd_plant_add_segment(s, &g);
  vd_plant_set_label(s, 1, "trunk");
  vd_model* pm = NULL;
  vd_error e = {0};
  REQUIRE(vd_plant_compile(s, &pm, &e) == VD_OK);
  vd_plant_spec_destroy(s);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.02;
  def.sag_free = 1;
  vd_sim_model* m = NULL;
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  vd_sim_collider ground = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &ground);
  for (int k = 0; k < 10; k++) CHECK(vd_sim_step(m, d) == VD_OK);
  CHECK_INT(d->nwarning, 0);
  CHECK(vd_sim_max_displacement(m, d, NULL) < 1e-6);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
  // a rod lying along the plane still touches it with its full radius: a plane 1 mm inside a
  // 3 mm cantilever lifts every free node to 3 mm above it
  pm = cantilever(0.2, 0.003, 0);
  REQUIRE(pm);
  def = cantilever_def(0.02, 1e9, 1000);
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  d = vd_sim_data_create(m);
  REQUIRE(d);
  ground.pos = vd_v3(0, 0, -0.002);
  vd_sim_add_collider(d, &ground);
  CHECK(vd_sim_step(m, d) == VD_OK);
  double low = 1;
  for (int i = 0; i < m->nnode; i++)
    if (!m->node_fixed[i]) low = fmin(low, d->node_pos[i].z);
  CHECK(fabs(low - 0.001) < 1e-9);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, sag_free_tomato) {
  // the gate of the issue: with sag-free initialisation the bundled tomato moves less than
  // 1 mm; without it, it visibly sags
  vd_model* pm = grow("data/tomato.lpy", NULL);
  REQUIRE(pm);
  for (int on = 1; on >= 0; on--) {
    vd_sim_def def = vd_sim_def_default();
    def.sag_free = on;
    vd_sim_model* m = NULL;
    vd_error e = {0};
    REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
    CHECK_INT(m->nsagfree_clamped, 0);
    vd_sim_data* d = vd_sim_data_create(m);
    REQUIRE(d);
    for (int i = 0; i < (on ? 500 : 300); i++) vd_sim_step(m, d);
    double md = vd_sim_max_displacement(m, d, NULL);
    if (on)
      CHECK(md < 1e-3);
    else
      CHECK(md > 1e-2);
    vd_sim_data_destroy(d);
    vd_sim_model_destroy(m);
  }
  vd_model_destroy(pm);
}

TEST(sim, stake_and_ties) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  def.stake_spacing = 0.25;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  CHECK(m->ntie >= 4 && m->ntie <= 6);  // a 1.4 m stem tied every 25 cm
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  // a user tie pulls a fruit 2 cm sideways
  int fruit = vd_sim_find_organ(m, pm, "fruit", 0);
  REQUIRE(fruit >= 0);
  vd_vec3 target = vd_add(m->node_pos0[fruit], vd_v3(0.02, 0, 0));
  CHECK(vd_sim_add_tie(d, fruit, target, 1e-4) >= 0);
  m->opt.fracture = 0;
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.statics = 1;
  vd_sim_settle(m, d, &s, NULL, NULL);
  CHECK(vd_norm(vd_sub(d->node_pos[fruit], target)) < 5e-3);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, tree_builds_and_steps) {
  vd_model* pm = grow("data/tree.lpy", NULL);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  def.sag_free = 1;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
  REQUIRE(m);
  int roots = 0;
  for (int t = 0; t < m->nseg; t++) roots += m->seg_class[t] == VD_SIM_ROOT && (m->seg_flags[t] & VD_SIM_FIXED);
  CHECK(roots > 100);  // roots stay in the soil
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  for (int i = 0; i < 5; i++) CHECK(vd_sim_step(m, d) == VD_OK);
  CHECK(vd_sim_max_displacement(m, d, NULL) < 1e-3);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, self_contact_projection) {
  // the projection the collide module's self-contacts will go through: two overlapping
  // capsules of one rod are pushed apart to touching, by inverse mass, momentum kept
  vd_model* pm = cantilever(0.4, 0.003, 0);
  REQUIRE(pm);
  vd_sim_def def = cantilever_def(0.02, 5e7, 1000);
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  vd_sim_data* d = vd_sim_data_create(m);
  REQUIRE(d);
  int s1 = 3, s2 = 12;
  int a = m->seg_node[2 * s2], b = m->seg_node[2 * s2 + 1];
  // fold segment s2 back over s1, 2 mm above its axis (radii 3 mm: 4 mm of overlap)
  vd_vec3 p1 = d->node_pos[m->seg_node[2 * s1]], p2 = d->node_pos[m->seg_node[2 * s1 + 1]];
  d->node_pos[a] = vd_add(p2, vd_v3(0, 0, 0.002));
  d->node_pos[b] = vd_add(p1, vd_v3(0, 0, 0.002));
  vd_vec3 mom0 = vd_v3(0, 0, 0);
  int nodes[4] = {m->seg_node[2 * s1], m->seg_node[2 * s1 + 1], a, b};
  for (int k = 0; k < 4; k++) mom0 = vd_madd(mom0, d->node_pos[nodes[k]], d->node_mass[nodes[k]]);
  sim_contact c = {-1, s1, 0.5, m->seg_radius[s1], -1, 0, -1, s2, 0.5, m->seg_radius[s2]};
  CHECK(sim_contact_gap(m, d, &c) < -0.003);
  for (int it = 0; it < 5; it++) sim_contacts_project(m, d, &c, 1, m->opt.dt);
  CHECK(sim_contact_gap(m, d, &c) > -1e-9);
  vd_vec3 mom1 = vd_v3(0, 0, 0);
  for (int k = 0; k < 4; k++) mom1 = vd_madd(mom1, d->node_pos[nodes[k]], d->node_mass[nodes[k]]);
  CHECK(v_norm(vd_sub(mom1, mom0)) < 1e-12);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

TEST(sim, self_collision_rest) {
  // neighbours are excluded: a sagging straight rod, with or without a fruit on its tip, has
  // no self-contact candidates; turned off, no self-contacts are looked for at all
  for (int fruit = 0; fruit < 2; fruit++) {
    vd_model* pm = cantilever(0.4, 0.003, fruit);
    REQUIRE(pm);
    vd_sim_def def = cantilever_def(0.02, 5e7, 1000);
    vd_sim_model* m = NULL;
    vd_error e = {0};
    REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
    CHECK_INT(m->opt.self_collision, 0);
    m->opt.self_collision = 1;
    m->opt.contacts = 1;
    vd_sim_data* d = vd_sim_data_create(m);
    REQUIRE(d);
    const sim_work* w = (const sim_work*)d->work;
    CHECK(w->self.ncap > 0);
    CHECK_INT(w->self.nsph, fruit);
    CHECK(w->self.ex.nexclude > 0);
    int most = 0;
    for (int k = 0; k < 200; k++) {
      CHECK_INT(vd_sim_step(m, d), VD_OK);
      if (d->ncontact > most) most = d->ncontact;
    }
    CHECK_INT(most, 0);
    CHECK(vd_sim_max_displacement(m, d, NULL) > 1e-3);  // it did move
    vd_sim_data_destroy(d);
    vd_sim_model_destroy(m);
    vd_model_destroy(pm);
  }
}

TEST(sim, self_collision_fold) {
  // a rod folded back over itself by hand: the step's self-contacts push the overlap out
  vd_model* pm = cantilever(0.4, 0.003, 0);
  REQUIRE(pm);
  vd_sim_def def = cantilever_def(0.02, 5e7, 1000);
  vd_sim_model* m = NULL;
  vd_error e = {0};
  REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
  m->opt.gravity = vd_v3(0, 0, 0);
  m->opt.contacts = 1;
  for (int on = 0; on < 2; on++) {
    m->opt.self_collision = on;
    vd_sim_data* d = vd_sim_data_create(m);
    REQUIRE(d);
    int s1 = 3, s2 = 12;
    int a = m->seg_node[2 * s2], b = m->seg_node[2 * s2 + 1];
    vd_vec3 p1 = d->node_pos[m->seg_node[2 * s1]], p2 = d->node_pos[m->seg_node[2 * s1 + 1]];
    d->node_pos[a] = vd_add(p2, vd_v3(0, 0, 0.002));
    d->node_pos[b] = vd_add(p1, vd_v3(0, 0, 0.002));
    sim_contact c = {-1, s1, 0.5, m->seg_radius[s1], -1, 0, -1, s2, 0.5, m->seg_radius[s2]};
    CHECK(sim_contact_gap(m, d, &c) < -0.003);
    CHECK_INT(vd_sim_step(m, d), VD_OK);
    if (on) {
      CHECK(d->ncontact > 0);
      CHECK(d->max_penetration < 1e-6);
      CHECK(sim_contact_gap(m, d, &c) > -1e-6);
    } else {
      CHECK_INT(d->ncontact, 0);
    }
    vd_sim_data_destroy(d);
  }
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// a dense canopy: k x k parallel rods of length len along x, spacing apart in y and z
static vd_model* comb(int k, double len, double apart, double r) {
  vd_plant_spec* s = vd_plant_spec_create();
  vd_segment_spec g = vd_segment_spec_default();
  g.r0 = g.r1 = r, g.label = 1, g.up = vd_v3(0, 0, 1);
  for (int i = 0; i < k * k; i++) {
    double y = apart * (i % k), z = apart * (i / k);
    int a = vd_plant_add_node(s, vd_v3(-0.01, y, z)), b = vd_plant_add_node(s, vd_v3(0, y, z));
    int c = vd_plant_add_node(s, vd_v3(len, y, z));
    g.node0 = a, g.node1 = b, g.parent = -1, g.instance = 2 * i + 1;
    int s0 = vd_plant_add_segment(s, &g);
    g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2 * i + 2;
    vd_plant_add_segment(s, &g);
  }
  vd_plant_set_label(s, 1, "stem");
  vd_model* m = NULL;
  vd_error e = {0};
  vd_plant_compile(s, &m, &e);
  vd_plant_spec_destroy(s);
  return m;
}

TEST(sim, self_collision_pairs_linear) {
  // one node flung fast in a dense canopy widens its own search only: the broad phase's pairs
  // per primitive stay bounded (a margin set by the fastest node for every primitive made the
  // pairs, contacts and the memory holding them grow as the square of the plant)
  int most[2] = {0, 0}, nprim[2] = {0, 0};
  for (int size = 0; size < 2; size++) {
    vd_model* pm = comb(size ? 8 : 4, 0.4, 0.012, 0.003);
    REQUIRE(pm);
    vd_sim_def def = cantilever_def(0.02, 5e7, 1000);
    vd_sim_model* m = NULL;
    vd_error e = {0};
    REQUIRE(vd_sim_build(pm, &def, &m, &e) == VD_OK);
    m->opt.self_collision = 1;
    m->opt.contacts = 1;
    vd_sim_data* d = vd_sim_data_create(m);
    REQUIRE(d);
    const sim_work* w = (const sim_work*)d->work;
    nprim[size] = w->self.ncap + w->self.nsph;
    for (int k = 0; k < 5; k++) {
      // the last rod's tip at 40 m/s: 4 cm a step
      d->node_vel[m->nnode - 1] = vd_v3(0, 0, 40);
      vd_sim_step(m, d);
      if (w->self.pairs.n > most[size]) most[size] = w->self.pairs.n;
    }
    CHECK_INT(d->warning[VD_SIM_WARN_ARENA], 0);
    vd_sim_data_destroy(d);
    vd_sim_model_destroy(m);
    vd_model_destroy(pm);
  }
  // measured: 2811 pairs for 336 primitives, 13233 for 1344 (a global margin: 38824, 629920)
  CHECK(nprim[1] >= 4 * nprim[0] - 8);
  CHECK(most[1] < 12 * nprim[1]);               // pairs per primitive bounded
  CHECK(most[1] < 6 * (most[0] > 0 ? most[0] : 1)); // 4x the rods, not 16x the pairs
}

// the bend-twist Jacobian of both measures against central differences of the constraint values,
// for a joint on the tomato turned well away from rest (both sides, the parent's block is -G)
TEST(sim, bend_jacobian) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  CHECK(pm != NULL);
  if (!pm) return;
  for (int kind = 0; kind < 2; kind++) {
    vd_sim_def def = vd_sim_def_default();
    def.bend_measure = (vd_sim_bend)kind;
    def.sag_free = 1;
    vd_sim_model* m = NULL;
    vd_error e = {0};
    CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
    vd_sim_data* d = vd_sim_data_create(m);
    // turn every frame by a different rotation (up to ~100 degrees away from rest)
    for (int t = 0; t < m->nseg; t++)
      d->seg_quat[t] = quat_rotate_by(d->seg_quat[t], vd_v3(0.9 * sin(t), 1.3 * cos(3.0 * t), 0.7 * sin(7.0 * t)));
    double worst = 0;
    int tested = 0;
    for (int t = 1; t < m->nseg && tested < 40; t += 37) {
      int p = m->seg_parent[t];
      if (p < 0 || (m->seg_flags[t] & VD_SIM_FIXED) || (m->seg_flags[p] & VD_SIM_FIXED)) continue;
      tested++;
      sim_joint j;
      sim_joint_eval(m, d, t, &j);
      for (int side = 0; side < 2; side++) {
        int s = side ? p : t;
        vd_quat q0 = d->seg_quat[s];
        for (int k = 0; k < 3; k++) {
          double h = 1e-6, cp[6], cm[6];
          vd_vec3 dv = vd_v3(k == 0 ? h : 0, k == 1 ? h : 0, k == 2 ? h : 0);
          d->seg_quat[s] = quat_rotate_by(q0, dv);
          sim_joint_values(m, d, t, cp);
          d->seg_quat[s] = quat_rotate_by(q0, vd_scale(dv, -1));
          sim_joint_values(m, d, t, cm);
          d->seg_quat[s] = q0;
          for (int i = 0; i < 3; i++) {
            double fd = (cp[3 + i] - cm[3 + i]) / (2 * h), an = (side ? -1 : 1) * j.g[3 * i + k];
            double err = fabs(fd - an) / (1 + fabs(an));
            if (err > worst) worst = err;
          }
        }
      }
    }
    CHECK(tested >= 20);
    CHECK(worst < 1e-6);
    vd_sim_data_destroy(d);
    vd_sim_model_destroy(m);
  }
  vd_model_destroy(pm);
}

// a tomato state with a probe through its crown at height z (m)
static vd_sim_data* probed_state(vd_sim_model* m, double z) {
  vd_sim_data* d = vd_sim_data_create(m);
  vd_sim_collider g = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &g);
  vd_sim_collider p = {VD_SIM_SPHERE, {0.04, 0, 0}, vd_v3(0.3, 0, z), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sim_add_collider(d, &p);
  return d;
}

// move every state's probe and step them: one state at a time, or as a batch on 2 threads
static void probe_steps(vd_sim_model* m, vd_sim_data** d, int n, int steps, int batch) {
  for (int k = 0; k < steps; k++) {
    for (int i = 0; i < n; i++)
      vd_sim_set_collider_pose(m, d[i], 1, vd_v3(0.3 - 0.6 * k / steps, 0, 0.3 + 0.1 * i), vd_quat_identity());
    if (batch)
      CHECK(vd_sim_step_batch(m, d, n, 1, 2, NULL) == VD_OK);
    else
      for (int i = 0; i < n; i++) CHECK(vd_sim_step(m, d[i]) == VD_OK);
  }
}

static int same_state(const vd_sim_model* m, const vd_sim_data* a, const vd_sim_data* b) {
  return !memcmp(a->node_pos, b->node_pos, (size_t)m->nnode_all * sizeof(vd_vec3)) &&
         !memcmp(a->seg_quat, b->seg_quat, (size_t)m->nseg * sizeof(vd_quat)) &&
         !memcmp(a->seg_lambda, b->seg_lambda, (size_t)m->nseg * 6 * sizeof(double)) && a->nevent == b->nevent;
}

// the same bytes with 1, 2 and 3 threads for one state, and a batch of states on 2 threads
// equal to the states stepped alone
TEST(sim, threads_and_batch_same_bytes) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  CHECK(pm != NULL);
  if (!pm) return;
  vd_sim_def def = vd_sim_def_default();
  def.sag_free = 1;
  vd_sim_model* m = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
  m->opt.wind = vd_v3(3, 0, 0);
  vd_sim_data *d1 = probed_state(m, 0.35), *dt[2] = {probed_state(m, 0.35), probed_state(m, 0.35)};
  probe_steps(m, &d1, 1, 30, 0);
  for (int k = 0; k < 2; k++) {
    m->opt.threads = 2 + k;
    probe_steps(m, &dt[k], 1, 30, 0);
    CHECK(same_state(m, d1, dt[k]));
  }
  m->opt.threads = 1;
  vd_sim_data *solo[3], *batch[3];
  for (int i = 0; i < 3; i++) solo[i] = probed_state(m, 0.3), batch[i] = probed_state(m, 0.3);
  probe_steps(m, solo, 3, 20, 0);
  probe_steps(m, batch, 3, 20, 1);
  for (int i = 0; i < 3; i++) CHECK(same_state(m, solo[i], batch[i]));
  CHECK(!same_state(m, solo[0], solo[2]));  // the probes differ: so do the states
  for (int i = 0; i < 3; i++) vd_sim_data_destroy(solo[i]), vd_sim_data_destroy(batch[i]);
  vd_sim_data_destroy(d1), vd_sim_data_destroy(dt[0]), vd_sim_data_destroy(dt[1]);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}

// region of interest: the tomato around one fruit, the rest held; at rest the simulated part
// stays where sag-free put it (the held parts' joints hold it), and a pull on the fruit breaks
// its calyx as in the whole plant
TEST(sim, region_of_interest) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  CHECK(pm != NULL);
  if (!pm) return;
  vd_sim_def def = vd_sim_def_default();
  def.sag_free = 1;
  vd_sim_model* whole = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &whole, &e), VD_OK, e);
  int fruit = vd_sim_find_organ(whole, pm, "fruit", 0);
  CHECK(fruit >= 0);
  def.active_radius = 0.15;
  def.active_a = def.active_b = whole->node_pos0[fruit];
  vd_sim_model* m = NULL;
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
  CHECK(m->nheld > whole->nseg / 3 && m->nheld < whole->nseg);
  double tbreak[2] = {-1, -1};
  for (int k = 0; k < 2; k++) {
    vd_sim_model* mm = k ? m : whole;
    vd_sim_data* d = vd_sim_data_create(mm);
    for (int s = 0; s < 50; s++) CHECK(vd_sim_step(mm, d) == VD_OK);
    CHECK(vd_sim_max_displacement(mm, d, NULL) < 1e-9);
    for (int s = 0; s < 600 && !d->nevent; s++) {
      d->node_force[fruit] = vd_v3(0, 0, -5.0 * s / 600);  // 0 -> 5 N over 0.6 s
      CHECK(vd_sim_step(mm, d) == VD_OK);
    }
    CHECK(d->nevent >= 1);
    tbreak[k] = d->time;
    vd_sim_data_destroy(d);
  }
  CHECK(fabs(tbreak[1] - tbreak[0]) < 0.1 * tbreak[0]);
  vd_sim_model_destroy(m);
  vd_sim_model_destroy(whole);
  vd_model_destroy(pm);
}

// uniform in [-0.5, 0.5) from a linear congruential state
static double half_rand(unsigned* r) {
  *r = *r * 1103515245u + 12345u;
  return *r / 4294967296.0 - 0.5;
}

// the segments' air drag eight at a time (sim_seg_drag_lanes) gives the bytes of the one-by-one
// loop (sim_seg_drag_one) on every segment: leaf laminae, fruit stalks, fixed and free ends,
// random velocities and frames turned away from the modelled ones, in wind
TEST(sim, drag_lanes_same_bytes) {
  vd_model* pm = grow("data/tomato.lpy", NULL);
  CHECK(pm != NULL);
  if (!pm) return;
  vd_sim_def def = vd_sim_def_default();
  vd_sim_model* m = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_build(pm, &def, &m, &e), VD_OK, e);
  vd_sim_data* d = vd_sim_data_create(m);
  CHECK(d != NULL);
  sim_work* w = (sim_work*)d->work;
  unsigned r = 12345u;
  int leaves = 0;
  for (int i = 0; i < m->nnode_all; i++) d->node_vel[i] = vd_v3(half_rand(&r), half_rand(&r), 3 * half_rand(&r));
  for (int t = 0; t < m->nseg; t++) {
    d->seg_quat[t] = q_normalize(q_mul(d->seg_quat[t], (vd_quat){1, 0.3 * half_rand(&r), 0.3 * half_rand(&r), 0.3 * half_rand(&r)}));
    const double* ln = m->seg_leaf_normal + 3 * t;
    leaves += ln[0] != 0 || ln[1] != 0 || ln[2] != 0;
  }
  d->node_mass[m->seg_node[2 * (m->nseg / 2) + 1]] = 0;  // a massless end: no share to it
  CHECK(leaves > 0);
  size_t n = (size_t)m->nseg * 5;
  double* one = malloc(n * sizeof(double));
  CHECK(one != NULL);
  vd_vec3 wind = vd_v3(7, -2, 0.5);
  for (int t = 0; t < m->nseg; t++) sim_seg_drag_one(m, d, w, wind, 0.613, t);
  memcpy(one, w->seg_drag, n * sizeof(double));
  memset(w->seg_drag, 0, n * sizeof(double));
  int t = sim_seg_drag_lanes(m, d, w, wind, 0.613, 0, m->nseg);
  CHECK(t > m->nseg - SIM_W && t <= m->nseg);
  for (; t < m->nseg; t++) sim_seg_drag_one(m, d, w, wind, 0.613, t);
  int same = 1;
  for (int k = 0; k < m->nseg; k++) {
    const double *a = one + 5 * k, *b = w->seg_drag + 5 * k;
    // a segment without drag (a[4] < 0) leaves the rest of its row unread
    same &= a[4] < 0 ? b[4] == a[4] : !memcmp(a, b, 5 * sizeof(double));
  }
  CHECK(same);
  free(one);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(pm);
}
