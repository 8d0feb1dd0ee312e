// SPDX-License-Identifier: MIT
// pieces: after a fracture the parts that broke off are separate pieces in every output: the
// deformed plant state (drawn, sampled), the plant spec written back (plant files), their
// meshes; labels and instances kept (issue 12, item 2).
#include <stdlib.h>

#include "test.h"
#include "verdant/verdant.h"

// a stem of two plant segments (0.12 m each, one class, so one rod chain whose joints fall
// inside them) with a fruit on top; rod segments of 2 cm
static vd_plant_spec* stem_spec(void) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0.12));
  int c = vd_plant_add_node(s, vd_v3(0, 0, 0.24));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = 0.004, g.r1 = 0.003, g.label = 1, g.instance = 1, g.up = vd_v3(1, 0, 0);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.r0 = 0.003, g.r1 = 0.002, g.parent = s0, g.instance = 2;
  int s1 = vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0, 0, 0.25), f.radius = 0.01, f.parent = s1, f.node = c, f.label = 2, f.instance = 3;
  vd_plant_add_sphere(s, &f);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 2, "fruit");
  return s;
}

// longest triangle edge of a plant's mesh in state d (NULL: rest shape)
static double longest_edge(const vd_model* m, const vd_data* d) {
  vd_mesh mesh;
  vd_error e = {0};
  if (vd_geom_tessellate(m, d, NULL, &mesh, &e)) return INFINITY;
  double best = 0;
  for (int t = 0; t < mesh.ntri; t++)
    for (int k = 0; k < 3; k++) {
      const double* p = mesh.pos + 3 * mesh.tri[3 * t + k];
      const double* q = mesh.pos + 3 * mesh.tri[3 * t + (k + 1) % 3];
      double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
      best = fmax(best, sqrt(dx * dx + dy * dy + dz * dz));
    }
  vd_mesh_free(&mesh);
  return best;
}

// pieces of a spec: segments without a parent
static int roots(const vd_plant_spec* s) {
  int n = 0;
  for (int j = 0; j < s->nseg; j++) n += s->seg[j].parent < 0;
  return n;
}

// does the spec hold the (label, instance) pair?
static int has_pair(const vd_plant_spec* s, int label, int instance) {
  for (int j = 0; j < s->nseg; j++)
    if (s->seg[j].label == label && s->seg[j].instance == instance) return 1;
  for (int k = 0; k < s->nsphere; k++)
    if (s->sphere[k].label == label && s->sphere[k].instance == instance) return 1;
  return 0;
}

// pull the top of the stem sideways until a stem joint breaks, then let the part fly 0.1 s;
// returns the models and state
typedef struct broken_run {
  vd_plant_spec* spec;
  vd_model* plant;
  vd_sim_model* m;
  vd_sim_data* d;
} broken_run;

// one break (a moment threshold: the joint at the base goes first) or many (a force threshold:
// every joint of the pulled chain carries the pull)
static int run_to_break(broken_run* r, int many) {
  memset(r, 0, sizeof *r);
  vd_error e = {0};
  r->spec = stem_spec();
  if (!r->spec || vd_plant_compile(r->spec, &r->plant, &e)) return 0;
  vd_sim_def def = vd_sim_def_default();
  if (many)
    def.material[VD_SIM_GREEN].break_force = 0.5;  // N, every stem joint may break
  else
    def.material[VD_SIM_GREEN].break_moment = 0.05;  // N m
  if (vd_sim_build(r->plant, &def, &r->m, &e)) return 0;
  r->m->opt.gravity = vd_v3(0, 0, 0);
  r->d = vd_sim_data_create(r->m);
  int tip = vd_sim_find_organ(r->m, r->plant, "fruit", 0);
  if (!r->d || tip < 0) return 0;
  int after = -1;
  for (int i = 0; i < 2000 && (after < 0 || i < after); i++) {
    // 20 N/s; after the first break only when many are wanted (the calyx would go next)
    r->d->node_force[tip] = after < 0 || many ? vd_v3(20.0 * r->d->time, 0, 0) : vd_v3(0, 0, 0);
    vd_sim_step(r->m, r->d);
    if (r->d->nevent && after < 0) after = i + 100;
  }
  return r->d->nevent > 0;
}

static void run_free(broken_run* r) {
  vd_sim_data_destroy(r->d);
  vd_sim_model_destroy(r->m);
  vd_model_destroy(r->plant);
  vd_plant_spec_destroy(r->spec);
}

TEST(pieces, state_drawn_apart) {
  broken_run r;
  int broke = run_to_break(&r, 0);
  REQUIRE(broke);
  // the break is inside a plant segment: both faces moved apart
  vd_data* pd = vd_data_create(r.plant);
  REQUIRE(pd);
  vd_sim_to_plant(r.m, r.d, r.plant, pd);
  int cut = -1;
  for (int j = 0; j < r.plant->nseg; j++)
    if (pd->seg_broken[j]) cut = j;
  REQUIRE(cut >= 0);
  const double* c = pd->seg_cut + 7 * cut;
  CHECK(c[0] > 0 && c[0] < 1);
  double gap = sqrt((c[4] - c[1]) * (c[4] - c[1]) + (c[5] - c[2]) * (c[5] - c[2]) + (c[6] - c[3]) * (c[6] - c[3]));
  CHECK(gap > 0.02);
  // no triangle spans the gap: every edge is shorter than a plant segment and its width
  double rest = longest_edge(r.plant, NULL), now = longest_edge(r.plant, pd);
  CHECK(rest < 0.13);
  CHECK(now < 0.13);
  // a state reset forgets the break
  vd_data_reset(r.plant, pd);
  CHECK(pd->seg_broken[cut] == 0 && pd->seg_cut[7 * cut] < 0);
  vd_data_destroy(pd);
  run_free(&r);
}

TEST(pieces, spec_split) {
  broken_run r;
  int broke = run_to_break(&r, 0);
  REQUIRE(broke);
  int nseg0 = r.spec->nseg, nnode0 = r.spec->nnode;
  CHECK_INT(roots(r.spec), 1);
  CHECK_STATUS(vd_sim_to_spec(r.m, r.d, r.spec), VD_OK, (vd_error){0});
  // one more piece: the segment holding the break became two, with two new nodes
  CHECK_INT(roots(r.spec), 2);
  CHECK_INT(r.spec->nseg, nseg0 + 1);
  CHECK_INT(r.spec->nnode, nnode0 + 2);
  // labels and instances kept; the fruit hangs from the part that came off
  CHECK(has_pair(r.spec, 1, 1) && has_pair(r.spec, 1, 2) && has_pair(r.spec, 2, 3));
  const vd_sphere_spec* fruit = &r.spec->sphere[0];
  REQUIRE(fruit->parent >= 0);
  int top = fruit->parent;
  while (r.spec->seg[top].parent >= 0) top = r.spec->seg[top].parent;
  CHECK(r.spec->seg[top].node0 >= nnode0);  // the piece starts at a new node, not at the root
  // the stump ends in a tip; the spec compiles and its mesh spans no gap
  int tips = 0;
  for (int j = 0; j < r.spec->nseg; j++)
    tips += r.spec->seg[j].node1 >= nnode0 && (r.spec->seg[j].flags & VD_SEG_TIP);
  CHECK_INT(tips, 1);
  vd_model* cm = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_plant_compile(r.spec, &cm, &e), VD_OK, e);
  if (cm) CHECK(longest_edge(cm, NULL) < 0.13);
  vd_model_destroy(cm);
  run_free(&r);
}

TEST(pieces, many_breaks) {
  // pulled on after the first break, the stem breaks at many joints, several inside one plant
  // segment: one more piece per break in the spec, no mesh spanning a gap in the spec or state
  broken_run r;
  int broke = run_to_break(&r, 1);
  REQUIRE(broke);
  REQUIRE(r.d->nevent >= 3);
  vd_data* pd = vd_data_create(r.plant);
  REQUIRE(pd);
  vd_sim_to_plant(r.m, r.d, r.plant, pd);
  CHECK(longest_edge(r.plant, pd) < 0.13);
  vd_data_destroy(pd);
  CHECK_STATUS(vd_sim_to_spec(r.m, r.d, r.spec), VD_OK, (vd_error){0});
  CHECK_INT(roots(r.spec), 1 + r.d->nevent);
  vd_model* cm = NULL;
  vd_error e = {0};
  CHECK_STATUS(vd_plant_compile(r.spec, &cm, &e), VD_OK, e);
  if (cm) CHECK(longest_edge(cm, NULL) < 0.13);
  vd_model_destroy(cm);
  run_free(&r);
}

TEST(pieces, spec_out_of_memory) {
  // every allocation of the split may fail: an error, never a crash or a leak
  for (int64_t budget = 0; budget < 12; budget++) {
    broken_run r;
    int broke = run_to_break(&r, 0);
    REQUIRE(broke);
    vdt_oom_begin(budget);
    vd_status st = vd_sim_to_spec(r.m, r.d, r.spec);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    run_free(&r);
  }
}

TEST(pieces, calyx_break_frees_the_fruit) {
  // a fruit pulled off its stalk: the fruit sphere loses its parent and attachment node
  broken_run r;
  memset(&r, 0, sizeof r);
  vd_error e = {0};
  r.spec = stem_spec();
  REQUIRE(r.spec && vd_plant_compile(r.spec, &r.plant, &e) == VD_OK);
  vd_sim_def def = vd_sim_def_default();
  def.material[VD_SIM_FRUIT].break_force = 0.5;
  REQUIRE(vd_sim_build(r.plant, &def, &r.m, &e) == VD_OK);
  r.m->opt.gravity = vd_v3(0, 0, 0);
  r.d = vd_sim_data_create(r.m);
  REQUIRE(r.d);
  int fruit = vd_sim_find_organ(r.m, r.plant, "fruit", 0);
  for (int i = 0; i < 400; i++) {
    r.d->node_force[fruit] = vd_v3(0, 0, 4.0 * r.d->time);
    vd_sim_step(r.m, r.d);
  }
  REQUIRE(r.d->nevent == 1);
  CHECK_STATUS(vd_sim_to_spec(r.m, r.d, r.spec), VD_OK, e);
  CHECK_INT(r.spec->sphere[0].parent, -1);
  CHECK_INT(r.spec->sphere[0].node, -1);
  CHECK_INT(roots(r.spec), 1);  // the stem stays whole
  CHECK(has_pair(r.spec, 2, 3));
  run_free(&r);
}
