// SPDX-License-Identifier: MIT
// data: the bundled plants grow for several seeds with every declared label present, and the
// deterministic ABOP examples match hand-derived counts and positions.
#include <math.h>
#include <stdlib.h>

#include "test.h"
#include "verdant/lsys.h"

static vd_plant_spec* grow_file(const char* rel, uint64_t seed, int steps, vd_error* e) {
  vd_lsystem* ls;
  if (vd_lsys_load(vdt_path(rel), &ls, e)) return NULL;
  vd_plant_spec* p = vd_plant_spec_create();
  vd_lsys_def d = vd_lsys_def_default();
  d.seed = seed;
  d.steps = steps;
  vd_status st = vd_lsys_grow(ls, &d, NULL, p, e);
  vd_lsys_destroy(ls);
  if (st) {
    vd_plant_spec_destroy(p);
    return NULL;
  }
  return p;
}

// number of primitives carrying label id
static int label_uses(const vd_plant_spec* p, int id) {
  int n = 0;
  for (int i = 0; i < p->nseg; i++) n += p->seg[i].label == id;
  for (int i = 0; i < p->nsphere; i++) n += p->sphere[i].label == id;
  for (int i = 0; i < p->nmesh; i++) n += p->mesh[i].label == id;
  return n;
}

static void check_all_labels_used(const char* rel, vd_plant_spec* p) {
  for (int l = 0; l < p->nlabel; l++)
    if (label_uses(p, p->label[l].id) == 0)
      vdt_fail(__FILE__, __LINE__, "%s: label %d (%s) has no organ", rel, p->label[l].id, p->label[l].name);
}

TEST(data, realistic_plants_grow_with_all_labels) {
  const char* files[] = {"data/tomato.lpy", "data/arabidopsis.lpy", "data/lilac.lpy", "data/tree.lpy"};
  for (int f = 0; f < 4; f++)
    for (uint64_t seed = 0; seed < 3; seed++) {
      vd_error e = {0};
      vd_plant_spec* p = grow_file(files[f], seed, -1, &e);
      if (!p) {
        char b[700];
        vdt_fail(__FILE__, __LINE__, "%s seed %llu: %s", files[f], (unsigned long long)seed,
                 vd_error_format(&e, b, sizeof b));
        continue;
      }
      CHECK(p->nseg > 50);
      CHECK(p->nlabel >= 3);
      check_all_labels_used(files[f], p);
      vd_plant_spec_destroy(p);
    }
}

TEST(data, tomato_fruits_are_instances_on_pedicels) {
  vd_error e = {0};
  vd_plant_spec* p = grow_file("data/tomato.lpy", 1, -1, &e);
  REQUIRE(p);
  int fruits = 0, ripe = 0;
  for (int i = 0; i < p->nsphere; i++) {
    const vd_sphere_spec* s = &p->sphere[i];
    if (vd_plant_find_label(p, s->label)->organ != VD_ORGAN_FRUIT) continue;
    fruits++;
    // growing fruits up to cherry size, hanging from a pedicel, each its own organ instance
    CHECK(s->radius > 0 && s->radius <= 0.016);
    ripe += s->radius >= 0.01;
    REQUIRE(s->parent >= 0);
    CHECK_INT(vd_plant_find_label(p, p->seg[s->parent].label)->organ, VD_ORGAN_PEDICEL);
    for (int j = 0; j < p->nsphere; j++)
      if (j != i) CHECK(p->sphere[j].instance != s->instance);
    for (int j = 0; j < p->nseg; j++) CHECK(p->seg[j].instance != s->instance);
  }
  CHECK(fruits >= 6);
  CHECK(ripe >= 3);
  vd_plant_stats st;
  vd_plant_spec_stats(p, &st);
  CHECK(st.bbox_max.z > 0.8 && st.bbox_max.z < 2.5);  // a tomato plant, in metres
  vd_plant_spec_destroy(p);
}

TEST(data, tree_roots_below_ground_and_ages) {
  vd_error e = {0};
  vd_plant_spec* p = grow_file("data/tree.lpy", 0, -1, &e);
  REQUIRE(p);
  int roots = 0, aged = 0;
  double oldest = 0;
  for (int i = 0; i < p->nseg; i++) {
    const vd_segment_spec* g = &p->seg[i];
    aged += g->age > 0;
    if (g->age > oldest) oldest = g->age;
    if (vd_plant_find_label(p, g->label)->organ != VD_ORGAN_ROOT) continue;
    roots++;
    CHECK(p->node[g->node0].z <= 1e-9 && p->node[g->node1].z <= 1e-9);
  }
  CHECK(roots > 10);
  CHECK(aged > 100);
  CHECK(oldest >= 5);  // the trunk's first internode is as old as the tree (8 years)
  vd_plant_spec_destroy(p);
}

TEST(data, lilac_one_instance_per_flower) {
  vd_error e = {0};
  vd_plant_spec* p = grow_file("data/lilac.lpy", 0, -1, &e);
  REQUIRE(p);
  // all primitives of one flower instance carry the flower label, and flowers are many
  int flower = -1;
  for (int l = 0; l < p->nlabel; l++)
    if (p->label[l].organ == VD_ORGAN_FLOWER) flower = p->label[l].id;
  REQUIRE(flower >= 0);
  char* seen = calloc((size_t)p->ninstance + 1, 1);
  REQUIRE(seen);
  int nflowers = 0;
  for (int i = 0; i < p->nmesh; i++)
    if (p->mesh[i].label == flower && !seen[p->mesh[i].instance]) {
      seen[p->mesh[i].instance] = 1;
      nflowers++;
    }
  for (int i = 0; i < p->nseg; i++) CHECK(p->seg[i].label == flower || !seen[p->seg[i].instance]);
  free(seen);
  CHECK(nflowers > 50);
  vd_plant_spec_destroy(p);
}

TEST(data, abop_1_9_goldens) {
  vd_error e = {0};
  vd_plant_spec* p = grow_file("data/abop_1_9.lpy", 0, -1, &e);
  REQUIRE(p);
  CHECK_INT(p->nseg, 2047);
  // lengths S0 / R^k at depth k, 2^k segments per depth
  double S0 = 0.5, R = 1.456, total = 0;
  for (int k = 0; k <= 10; k++) total += pow(2, k) * S0 / pow(R, k);
  vd_plant_stats st;
  vd_plant_spec_stats(p, &st);
  CHECK_NEAR(st.total_length, total, 1e-9);
  // the first left branch: +(45) turns H = +Z toward L = -Y about U = +X
  double s1 = S0 / R, c = cos(VD_PI / 4), s = sin(VD_PI / 4);
  vd_vec3 want = vd_v3(0, -s1 * s, S0 + s1 * c);
  int found = 0;
  for (int i = 0; i < p->nnode; i++)
    if (vd_norm(vd_sub(p->node[i], want)) < 1e-9) found = 1;
  CHECK(found);
  // the tree is planar (Y-Z) and symmetric about the trunk
  CHECK_NEAR(st.bbox_max.y, -st.bbox_min.y, 1e-9);
  vd_plant_spec_destroy(p);
}

TEST(data, signal_counts) {
  // expected number of B after n steps, from the file's header: 1 2 3 5 8 11 11
  const int want[] = {1, 2, 3, 5, 8, 11, 11};
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_load(vdt_path("data/signal.lpy"), &ls, &e), VD_OK, e);
  if (!ls) return;
  int B = vd_lsys_symbol_find(ls, "B");
  for (int n = 0; n <= 6; n++) {
    vd_lsys_def d = vd_lsys_def_default();
    d.steps = n;
    vd_lstring s = vd_lstring_empty();
    CHECK_STATUS(vd_lsys_derive(ls, &d, &s, &e), VD_OK, e);
    int nb = 0;
    for (int64_t i = 0; i < s.n; i++) nb += s.sym[i] == B;
    CHECK_INT(nb, want[n]);
    vd_lstring_free(&s);
  }
  vd_lsys_destroy(ls);
}

TEST(data, classic_abop_plants_parse_and_grow) {
  const char* files[] = {"data/abop_fig1_24a.lpy", "data/abop_fig1_24b.lpy", "data/abop_fig1_24c.lpy",
                         "data/abop_fig1_24d.lpy", "data/abop_fig1_24e.lpy", "data/abop_fig1_24f.lpy",
                         "data/abop_3d_bush.lpy"};
  const int segs[] = {3125, 3125, 4096, 4118, 4118, 992, 3891};
  for (int f = 0; f < 7; f++) {
    vd_error e = {0};
    vd_plant_spec* p = grow_file(files[f], 0, -1, &e);
    if (!p) {
      char b[700];
      vdt_fail(__FILE__, __LINE__, "%s: %s", files[f], vd_error_format(&e, b, sizeof b));
      continue;
    }
    CHECK_INT(p->nseg, segs[f]);
    vd_plant_spec_destroy(p);
  }
}
