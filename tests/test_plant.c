// SPDX-License-Identifier: MIT
// plant: spec building, label table, organ names, statistics, compile (validation, model and
// data arrays), plant JSON (byte-identical round trip, malformed input, out of memory).
#include <stdlib.h>

#include "test.h"
#include "verdant/plant.h"

// a small plant: two stem segments (a generalised cylinder), a leaf quad, a fruit sphere
static vd_plant_spec* make_plant(void) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int b = vd_plant_add_node(s, vd_v3(0, 0, 1));
  int c = vd_plant_add_node(s, vd_v3(0, 0.5, 1.5));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = 0.1, g.r1 = 0.08, g.label = 1, g.instance = 1;
  g.flags = VD_SEG_GC, g.module = 3, g.age = 1.25;
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.r0 = 0.08, g.r1 = 0.05, g.parent = s0,
  g.flags = VD_SEG_GC | VD_SEG_TIP;
  g.up = vd_v3(0.1, 0.2, 0.3), g.module = 4, g.slices = 6, g.age = 0.1;
  int s1 = vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0, 0.5, 1.7), f.radius = 0.2, f.node = c, f.parent = s1, f.label = 3;
  f.instance = 7, f.module = 9;
  vd_plant_add_sphere(s, &f);
  vd_mesh_spec m = {0};
  m.node = b, m.parent = s0, m.label = 2, m.instance = 4, m.module = -1;
  vd_vec3 v[4] = {{0, 0, 1}, {0.3, 0, 1}, {0.3, 0.1, 1.1}, {0, 0.1, 1.1}};
  int t[6] = {0, 1, 2, 0, 2, 3};
  vd_plant_add_mesh(s, &m, v, 4, t, 2);
  vd_plant_set_label(s, 1, "stem");
  vd_plant_set_label(s, 2, "leaf");
  return s;
}

TEST(plant, spec_build) {
  vd_plant_spec* s = make_plant();
  REQUIRE(s);
  CHECK_INT(s->nnode, 3);
  CHECK_INT(s->nseg, 2);
  CHECK_INT(s->nsphere, 1);
  CHECK_INT(s->nmesh, 1);
  CHECK_INT(s->nvert, 4);
  CHECK_INT(s->ntri, 2);
  CHECK_INT(s->ninstance, 7);
  // a second mesh: its local triangle indices become global ones
  vd_mesh_spec m = {0};
  vd_vec3 v[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  int t[3] = {0, 1, 2};
  CHECK_INT(vd_plant_add_mesh(s, &m, v, 3, t, 1), 1);
  CHECK_INT(s->mesh[1].vert_start, 4);
  CHECK_INT(s->mesh[1].tri_start, 2);
  CHECK_INT(s->tri[6], 4);
  CHECK_INT(s->tri[8], 6);
  // many nodes grow the arrays
  for (int i = 0; i < 1000; i++)
    REQUIRE(vd_plant_add_node(s, vd_v3(i, 0, 0)) == 3 + i);
  // defaults
  vd_segment_spec g = vd_segment_spec_default();
  CHECK(g.node0 == -1 && g.node1 == -1 && g.r0 == 0.1 && g.r1 == 0.1 && g.up.x == 1);
  CHECK(g.parent == -1 && g.slices == 8 && g.module == -1 && g.flags == 0 && g.instance == 0);
  vd_sphere_spec f = vd_sphere_spec_default();
  CHECK(f.radius == 0.1 && f.node == -1 && f.parent == -1 && f.slices == 8 && f.module == -1);
  // clear keeps the memory
  int cap = s->cap_node;
  vd_plant_spec_clear(s);
  CHECK_INT(s->nnode + s->nseg + s->nsphere + s->nmesh + s->nvert + s->ntri + s->nlabel, 0);
  CHECK_INT(s->cap_node, cap);
  CHECK_INT(vd_plant_add_node(s, vd_v3(0, 0, 0)), 0);
  vd_plant_spec_destroy(s);
  vd_plant_spec_destroy(NULL);
  CHECK_INT(vd_plant_add_node(NULL, vd_v3(0, 0, 0)), -1);
}

TEST(plant, labels) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  CHECK_INT(vd_plant_set_label(s, 5, "Fruit"), VD_OK);
  CHECK_INT(vd_plant_set_label(s, 1, "stem"), VD_OK);
  CHECK_INT(vd_plant_set_label(s, 3, "leaf"), VD_OK);
  CHECK_INT(vd_plant_set_label(s, -1, "bad"), VD_ERR_ARG);
  // sorted by id
  REQUIRE(s->nlabel == 3);
  CHECK(s->label[0].id == 1 && s->label[1].id == 3 && s->label[2].id == 5);
  CHECK_INT(s->label[2].organ, VD_ORGAN_FRUIT);
  // rename keeps the colour, updates the organ
  float rgb[3];
  memcpy(rgb, s->label[1].rgb, sizeof rgb);
  CHECK_INT(vd_plant_set_label(s, 3, "petiole stalk"), VD_OK);
  CHECK_INT(s->nlabel, 3);
  CHECK_STR(vd_plant_find_label(s, 3)->name, "petiole stalk");
  CHECK_INT(vd_plant_find_label(s, 3)->organ, VD_ORGAN_LEAF);
  CHECK(memcmp(rgb, vd_plant_find_label(s, 3)->rgb, sizeof rgb) == 0);
  CHECK(vd_plant_find_label(s, 4) == NULL);
  // long names are cut to VD_LABEL_NAME_MAX - 1 bytes
  char longname[200];
  memset(longname, 'x', sizeof longname - 1);
  longname[199] = 0;
  vd_plant_set_label(s, 9, longname);
  CHECK_INT(strlen(vd_plant_find_label(s, 9)->name), VD_LABEL_NAME_MAX - 1);
  // default palette: 2 green, 3 red; later ids are distinct and deterministic
  float c2[3], c3[3], c40[3], c40b[3], c41[3];
  vd_plant_default_rgb(2, c2);
  vd_plant_default_rgb(3, c3);
  vd_plant_default_rgb(40, c40);
  vd_plant_default_rgb(40, c40b);
  vd_plant_default_rgb(41, c41);
  CHECK(c2[1] > c2[0] && c2[1] > c2[2]);
  CHECK(c3[0] > c3[1] && c3[0] > c3[2]);
  CHECK(memcmp(c40, c40b, sizeof c40) == 0 && memcmp(c40, c41, sizeof c40) != 0);
  for (int k = 0; k < 3; k++)
    CHECK(c40[k] >= 0 && c40[k] <= 1);
  // complete_labels names every id used
  vd_plant_spec_clear(s);
  vd_plant_set_label(s, 1, "stem");
  vd_segment_spec g = vd_segment_spec_default();
  g.label = 1;
  vd_plant_add_segment(s, &g);
  g.label = 12;
  vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.label = 0;
  vd_plant_add_sphere(s, &f);
  CHECK_INT(vd_plant_complete_labels(s), VD_OK);
  CHECK_INT(s->nlabel, 3);
  CHECK_STR(vd_plant_find_label(s, 12)->name, "label_12");
  CHECK_STR(vd_plant_find_label(s, 0)->name, "label_0");
  CHECK_STR(vd_plant_find_label(s, 1)->name, "stem");
  vd_plant_spec_destroy(s);
}

TEST(plant, organ_names) {
  CHECK_INT(vd_organ_from_name("Internode"), VD_ORGAN_STEM);
  CHECK_INT(vd_organ_from_name("trunk"), VD_ORGAN_STEM);
  CHECK_INT(vd_organ_from_name("side_BRANCH"), VD_ORGAN_STEM);
  CHECK_INT(vd_organ_from_name("leaflet"), VD_ORGAN_LEAF);
  CHECK_INT(vd_organ_from_name("Cotyledon"), VD_ORGAN_LEAF);
  CHECK_INT(vd_organ_from_name("pine needle"), VD_ORGAN_LEAF);
  CHECK_INT(vd_organ_from_name("petal"), VD_ORGAN_FLOWER);
  CHECK_INT(vd_organ_from_name("Inflorescence"), VD_ORGAN_FLOWER);
  CHECK_INT(vd_organ_from_name("tomato"), VD_ORGAN_FRUIT);
  CHECK_INT(vd_organ_from_name("Berry"), VD_ORGAN_FRUIT);
  CHECK_INT(vd_organ_from_name("pedicel"), VD_ORGAN_PEDICEL);
  CHECK_INT(vd_organ_from_name("peduncle_stem"), VD_ORGAN_PEDICEL);
  CHECK_INT(vd_organ_from_name("taproot"), VD_ORGAN_ROOT);
  CHECK_INT(vd_organ_from_name("label_7"), VD_ORGAN_OTHER);
  CHECK_INT(vd_organ_from_name(""), VD_ORGAN_OTHER);
  CHECK_INT(vd_organ_from_name(NULL), VD_ORGAN_OTHER);
  CHECK_STR(vd_organ_name(VD_ORGAN_PEDICEL), "pedicel");
  CHECK_STR(vd_organ_name(VD_ORGAN_OTHER), "other");
  CHECK_STR(vd_organ_name((vd_organ)99), "other");
  for (int o = 0; o < VD_ORGAN_COUNT; o++)
    CHECK_INT(vd_organ_from_name(vd_organ_name((vd_organ)o)), o);
}

TEST(plant, stats) {
  vd_plant_stats st;
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  vd_plant_spec_stats(s, &st);
  CHECK(st.bbox_min.x == 0 && st.bbox_max.z == 0 && st.total_length == 0);
  vd_plant_spec_destroy(s);
  s = make_plant();
  REQUIRE(s);
  vd_plant_spec_stats(s, &st);
  // x: segment radii 0.1 at the base and the sphere (0.2) at x = 0; leaf reaches x = 0.3
  CHECK_NEAR(st.bbox_min.x, -0.2, 1e-15);
  CHECK_NEAR(st.bbox_max.x, 0.3, 1e-15);
  // y: base radius -0.1, sphere at y 0.5 + 0.2
  CHECK_NEAR(st.bbox_min.y, -0.1, 1e-15);
  CHECK_NEAR(st.bbox_max.y, 0.7, 1e-15);
  // z: base node -0.1, sphere top 1.9
  CHECK_NEAR(st.bbox_min.z, -0.1, 1e-15);
  CHECK_NEAR(st.bbox_max.z, 1.9, 1e-15);
  CHECK_NEAR(st.total_length, 1 + sqrt(0.5), 1e-15);
  CHECK_INT(st.nseg, 2);
  CHECK_INT(st.nsphere, 1);
  CHECK_INT(st.nleaf, 1);
  vd_plant_spec_destroy(s);
}

// compile a copy of the plant after edit() and return the status
static vd_status compile_edited(void (*edit)(vd_plant_spec*)) {
  vd_plant_spec* s = make_plant();
  if (!s) return VD_ERR_NOMEM;
  edit(s);
  vd_error err = {0};
  vd_model* m = (vd_model*)1;
  vd_status st = vd_plant_compile(s, &m, &err);
  if (st != VD_OK && m != NULL) st = VD_ERR_ASSERT; // a failed compile leaves no model
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
  return st;
}
static void e_node0(vd_plant_spec* s) {
  s->seg[1].node0 = 3;
}
static void e_node1(vd_plant_spec* s) {
  s->seg[0].node1 = -1;
}
static void e_radius(vd_plant_spec* s) {
  s->seg[0].r1 = -0.1;
}
static void e_radius_nan(vd_plant_spec* s) {
  s->seg[0].r0 = NAN;
}
static void e_parent(vd_plant_spec* s) {
  s->seg[0].parent = 2;
}
static void e_cycle(vd_plant_spec* s) {
  s->seg[0].parent = 1;
}
static void e_self(vd_plant_spec* s) {
  s->seg[1].parent = 1;
}
static void e_pos(vd_plant_spec* s) {
  s->node[2].y = INFINITY;
}
static void e_slices(vd_plant_spec* s) {
  s->seg[0].slices = 2;
}
static void e_sphere_r(vd_plant_spec* s) {
  s->sphere[0].radius = -1;
}
static void e_sphere_node(vd_plant_spec* s) {
  s->sphere[0].node = 3;
}
static void e_tri(vd_plant_spec* s) {
  s->tri[4] = 4;
}
static void e_mesh_range(vd_plant_spec* s) {
  s->mesh[0].nvert = 5;
}
static void e_label(vd_plant_spec* s) {
  s->seg[1].label = -2;
}
static void e_vert(vd_plant_spec* s) {
  s->vert[1].z = NAN;
}
static void e_none(vd_plant_spec* s) {
  (void)s;
}

TEST(plant, compile_validation) {
  CHECK_INT(compile_edited(e_none), VD_OK);
  CHECK_INT(compile_edited(e_node0), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_node1), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_radius), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_radius_nan), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_parent), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_cycle), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_self), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_pos), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_slices), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_sphere_r), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_sphere_node), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_tri), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_mesh_range), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_label), VD_ERR_VALUE);
  CHECK_INT(compile_edited(e_vert), VD_ERR_VALUE);
  // a bad local triangle index in add_mesh is caught by compile
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  vd_mesh_spec m = {0};
  vd_vec3 v[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  int t[3] = {0, 1, 3};
  vd_plant_add_mesh(s, &m, v, 3, t, 1);
  vd_model* model = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_plant_compile(s, &model, &err), VD_ERR_VALUE, err);
  CHECK(model == NULL);
  vd_plant_spec_destroy(s);
}

// rotate the frame's axis a by the quaternion stored at q (w, x, y, z)
static vd_vec3 frame_axis(const double* q, vd_vec3 a) {
  vd_quat r = {q[0], q[1], q[2], q[3]};
  return vd_quat_rotate(r, a);
}

TEST(plant, model_and_data) {
  vd_plant_spec* s = make_plant();
  REQUIRE(s);
  // a zero-length segment gets a frame from its up vector
  int n = vd_plant_add_node(s, vd_v3(0, 0.5, 1.5));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = 2, g.node1 = n, g.parent = 1, g.up = vd_v3(0, 0, 2);
  vd_plant_add_segment(s, &g);
  vd_model* m = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_plant_compile(s, &m, &err), VD_OK, err);
  REQUIRE(m);
  CHECK(m->nnode == 4 && m->nseg == 3 && m->nsphere == 1 && m->nmesh == 1);
  CHECK(m->nvert == 4 && m->ntri == 2 && m->ninstance == 7);
  CHECK(m->nbytes > sizeof(vd_model));
  CHECK_NEAR(m->seg_len0[0], 1, 0);
  CHECK_NEAR(m->seg_len0[1], sqrt(0.5), 1e-15);
  CHECK_NEAR(m->seg_len0[2], 0, 0);
  CHECK(m->seg_node[2] == 1 && m->seg_node[3] == 2 && m->seg_parent[1] == 0);
  CHECK(m->seg_radius[0] == 0.1 && m->seg_radius[3] == 0.05 && m->seg_slices[1] == 6);
  CHECK(m->seg_flags[1] == (VD_SEG_GC | VD_SEG_TIP) && m->seg_age[0] == 1.25);
  // frames: z along the segment, x toward up, right-handed
  for (int i = 0; i < 2; i++) {
    const double* q = m->seg_quat0 + 4 * i;
    vd_vec3 p0 = s->node[s->seg[i].node0], p1 = s->node[s->seg[i].node1];
    vd_vec3 z = frame_axis(q, vd_v3(0, 0, 1)), x = frame_axis(q, vd_v3(1, 0, 0));
    vd_vec3 dir = vd_normalize(vd_sub(p1, p0));
    CHECK_NEAR(vd_dot(z, dir), 1, 1e-12);
    CHECK_NEAR(vd_dot(x, z), 0, 1e-12);
    vd_vec3 up = vd_normalize(s->seg[i].up);
    vd_vec3 upo = vd_normalize(vd_madd(up, dir, -vd_dot(up, dir)));
    CHECK_NEAR(vd_dot(x, upo), 1, 1e-12);
  }
  vd_vec3 x2 = frame_axis(m->seg_quat0 + 8, vd_v3(1, 0, 0));
  CHECK_NEAR(x2.z, 1, 1e-12);
  // labels completed in the model (3 and 0 added), the spec left alone
  CHECK_INT(s->nlabel, 2);
  CHECK_INT(m->nlabel, 4);
  REQUIRE(vd_model_find_label(m, 3));
  CHECK_STR(vd_model_find_label(m, 3)->name, "label_3");
  CHECK_STR(vd_model_find_label(m, 2)->name, "leaf");
  CHECK(vd_model_find_label(m, 5) == NULL);
  CHECK(m->sphere_radius[0] == 0.2 && m->sphere_node[0] == 2 && m->sphere_instance[0] == 7);
  CHECK(m->mesh_vert[0] == 0 && m->mesh_vert[1] == 4 && m->mesh_tri[1] == 2 && m->tri_vert[5] == 3);
  CHECK(m->vert_pos0[3] == 0.3);
  // data starts at rest and resets to it
  vd_data* d = vd_data_create(m);
  REQUIRE(d);
  CHECK(d->nnode == 4 && d->nseg == 3 && d->nbytes > sizeof(vd_data));
  CHECK(memcmp(d->node_pos, m->node_pos0, 12 * sizeof(double)) == 0);
  CHECK(memcmp(d->seg_quat, m->seg_quat0, 12 * sizeof(double)) == 0);
  d->node_pos[5] = 7;
  d->seg_broken[1] = 1;
  d->nwarning = 3;
  d->sphere_pos[0] = 1;
  d->vert_pos[2] = 9;
  REQUIRE(vd_arena_alloc(&d->arena, 1000));
  vd_data_reset(m, d);
  CHECK(d->node_pos[5] == 1 && d->seg_broken[1] == 0 && d->nwarning == 0);
  CHECK(d->sphere_pos[0] == 0 && d->vert_pos[2] == 1);
  vd_data_destroy(d);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
  vd_data_destroy(NULL);
  vd_model_destroy(NULL);
}

TEST(plant, compile_empty) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  vd_model* m = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_plant_compile(s, &m, &err), VD_OK, err);
  REQUIRE(m);
  CHECK_INT(m->nlabel, 0);
  vd_data* d = vd_data_create(m);
  CHECK(d != NULL);
  vd_data_destroy(d);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

// whole file as a vd_malloc'd string (free with len + 1)
static char* slurp(const char* path, size_t* len) {
  char* t = NULL;
  vd_error err = {0};
  if (vd_file_read(path, &t, len, &err) != VD_OK) return NULL;
  return t;
}

TEST(plant, json_round_trip) {
  vd_plant_spec* s = make_plant();
  REQUIRE(s);
  // awkward values: shortest round trip, negative zero, tiny and large magnitudes, odd names
  s->node[1].x = 0.1 + 0.2;
  s->node[1].y = -0.0;
  s->seg[0].age = 1e-300;
  s->vert[0].x = 123456789.123456789;
  s->seg[1].module = 9007199254740992LL;
  vd_plant_set_label(s, 4, "odd \"name\"\\\ttab");
  char p1[300], p2[300];
  snprintf(p1, sizeof p1, "%s/rt1.json", vdt_tmpdir());
  snprintf(p2, sizeof p2, "%s/rt2.json", vdt_tmpdir());
  vd_error err = {0};
  CHECK_STATUS(vd_plant_write_json(s, p1, &err), VD_OK, err);
  vd_plant_spec* r = NULL;
  CHECK_STATUS(vd_plant_read_json(p1, &r, &err), VD_OK, err);
  REQUIRE(r);
  CHECK_STATUS(vd_plant_write_json(r, p2, &err), VD_OK, err);
  // the spec is the same field by field
  CHECK(r->nnode == s->nnode && r->nseg == s->nseg && r->nsphere == s->nsphere);
  CHECK(r->nmesh == s->nmesh && r->nvert == s->nvert && r->ntri == s->ntri);
  CHECK(r->nlabel == s->nlabel && r->ninstance == s->ninstance);
  CHECK(memcmp(r->node, s->node, (size_t)s->nnode * sizeof *s->node) == 0);
  CHECK(memcmp(r->vert, s->vert, (size_t)s->nvert * sizeof *s->vert) == 0);
  CHECK(memcmp(r->tri, s->tri, (size_t)s->ntri * 3 * sizeof *s->tri) == 0);
  CHECK(signbit(r->node[1].y));
  for (int i = 0; i < s->nseg; i++) {
    const vd_segment_spec *a = &s->seg[i], *b = &r->seg[i];
    CHECK(a->node0 == b->node0 && a->node1 == b->node1 && a->r0 == b->r0 && a->r1 == b->r1);
    CHECK(a->up.x == b->up.x && a->up.y == b->up.y && a->up.z == b->up.z);
    CHECK(a->parent == b->parent && a->label == b->label && a->instance == b->instance);
    CHECK(a->axis == b->axis && a->order == b->order && a->flags == b->flags);
    CHECK(a->slices == b->slices && a->age == b->age && a->module == b->module);
  }
  CHECK(memcmp(&r->sphere[0], &s->sphere[0], sizeof s->sphere[0]) == 0);
  CHECK(memcmp(&r->mesh[0], &s->mesh[0], sizeof s->mesh[0]) == 0);
  for (int i = 0; i < s->nlabel; i++) {
    CHECK_STR(r->label[i].name, s->label[i].name);
    CHECK(r->label[i].id == s->label[i].id && r->label[i].organ == s->label[i].organ);
    CHECK(memcmp(r->label[i].rgb, s->label[i].rgb, sizeof r->label[i].rgb) == 0);
  }
  // and the files are byte-identical
  size_t n1 = 0, n2 = 0;
  char* t1 = slurp(p1, &n1);
  char* t2 = slurp(p2, &n2);
  REQUIRE(t1 && t2);
  CHECK(n1 == n2 && memcmp(t1, t2, n1) == 0);
  CHECK(strstr(t1, "\"version\": 1") != NULL);
  CHECK(strstr(t1, "0.30000000000000004") != NULL);
  vd_free(t1, n1 + 1);
  vd_free(t2, n2 + 1);
  // an empty plant round-trips too
  vd_plant_spec* e = vd_plant_spec_create();
  REQUIRE(e);
  CHECK_STATUS(vd_plant_write_json(e, p1, &err), VD_OK, err);
  vd_plant_spec* e2 = NULL;
  CHECK_STATUS(vd_plant_read_json(p1, &e2, &err), VD_OK, err);
  CHECK(e2 && e2->nnode == 0 && e2->nseg == 0);
  vd_plant_spec_destroy(e2);
  vd_plant_spec_destroy(e);
  // a non-finite value is refused and leaves no file
  s->node[0].x = NAN;
  char p3[300];
  snprintf(p3, sizeof p3, "%s/nan.json", vdt_tmpdir());
  vd_error err2 = {0};
  CHECK_STATUS(vd_plant_write_json(s, p3, &err2), VD_ERR_VALUE, err2);
  FILE* fp = fopen(p3, "rb");
  CHECK(fp == NULL);
  if (fp) fclose(fp);
  vd_plant_spec_destroy(r);
  vd_plant_spec_destroy(s);
}

// the written text of the test plant, as a vd_malloc'd string
static char* plant_text(size_t* len) {
  vd_plant_spec* s = make_plant();
  if (!s) return NULL;
  char p[300];
  snprintf(p, sizeof p, "%s/base.json", vdt_tmpdir());
  vd_error err = {0};
  vd_status st = vd_plant_write_json(s, p, &err);
  vd_plant_spec_destroy(s);
  return st == VD_OK ? slurp(p, len) : NULL;
}

// parse text with the first occurrence of from replaced by to
static vd_status parse_edited(const char* text, const char* from, const char* to, vd_error* err) {
  const char* at = strstr(text, from);
  if (!at) return VD_ERR_ASSERT;
  size_t n = strlen(text), nf = strlen(from), nt = strlen(to);
  size_t len = n - nf + nt;
  char* buf = vd_malloc(len + 1);
  if (!buf) return VD_ERR_NOMEM;
  size_t pre = (size_t)(at - text);
  memcpy(buf, text, pre);
  memcpy(buf + pre, to, nt);
  memcpy(buf + pre + nt, at + nf, n - pre - nf + 1);
  memset(err, 0, sizeof *err);
  vd_plant_spec* s = NULL;
  vd_status st = vd_plant_parse_json(buf, len, "edited.json", &s, err);
  if (st != VD_OK && s) st = VD_ERR_ASSERT;
  vd_plant_spec_destroy(s);
  vd_free(buf, len + 1);
  return st;
}

TEST(plant, json_malformed) {
  size_t len = 0;
  char* t = plant_text(&len);
  REQUIRE(t);
  vd_error e;
  // the unedited text parses
  CHECK_STATUS(parse_edited(t, "{", "{", &e), VD_OK, e);
  struct {
    const char *from, *to;
  } cases[] = {
      {"{", "x{"},                                        // not JSON
      {"\"verdant-plant\"", "\"other-format\""},          // wrong format
      {"\"format\"", "\"fmt\""},                          // missing format
      {"\"version\": 1", "\"version\": 2"},               // unsupported version
      {"\"version\": 1", "\"version\": \"1\""},           // version not a number
      {"\"units\": \"m\"", "\"units\": \"mm\""},          // other units
      {"\"r0\"", "\"rr0\""},                              // missing column
      {"\"r1\": [0.08,", "\"r1\": ["},                    // unequal columns
      {"\"r1\": [", "\"r1\": [\"a\","},                   // string in a number column
      {"\"node1\": [1,2]", "\"node1\": [1,3]"},           // node index out of range
      {"\"parent\": [-1,0]", "\"parent\": [-1,2]"},       // parent out of range
      {"\"slices\": [8,6]", "\"slices\": [8,2]"},         // too few slices
      {"\"label\": [1,1]", "\"label\": [1,1.5]"},         // non-integer index
      {"\"nodes\": [0,", "\"nodes\": [1e999,"},           // infinite value
      {"\"radius\": [0.2]", "\"radius\": [-1]"},          // negative radius
      {"\"nodes\": [0,0,0,", "\"nodes\": [0,0,"},         // nodes not a multiple of 3
      {"\"triangles\": [0,1,2", "\"triangles\": [0,1,9"}, // vertex out of range
      {"\"ntri\": [2]", "\"ntri\": [3]"},                 // triangle range outside
      {"\"segments\": {", "\"segments\": ["},             // section of the wrong type
      {"\"labels\": [", "\"labels\": [{\"id\": 1, \"name\": \"dup\"},"}, // duplicate label
      {"\"organ\": \"stem\"", "\"organ\": \"trunkish\""},                // unknown organ
      {"\"module\": [3,4]", "\"module\": [3,-7]"},                       // module out of range
      {"}\n", "}\n}"},                                                   // text after the value
      {"\"nodes\": [", "\"nodes\": [nan,"},                              // NaN is not JSON
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    vd_status st = parse_edited(t, cases[i].from, cases[i].to, &e);
    if (st != VD_ERR_FORMAT) fprintf(stderr, "  case %zu: %s -> %s\n", i, cases[i].to, e.msg);
    CHECK_INT(st, VD_ERR_FORMAT);
    if (st == VD_ERR_FORMAT) CHECK_STR(e.file, "edited.json");
  }
  // a syntax error reports line and column
  CHECK_STATUS(parse_edited(t, "\"units\": \"m\",", "\"units\": \"m\" ,,", &e), VD_ERR_FORMAT, e);
  CHECK_INT(e.line, 4);
  CHECK(e.col >= 16 && e.col <= 18); // cJSON stops at or just after the second comma
  vd_free(t, len + 1);
  // empty input, bare values, deep nesting, a lone string
  const char* bad[] = {"",
                       "   ",
                       "null",
                       "[]",
                       "42",
                       "\"verdant-plant\"",
                       "{\"format\": 1}",
                       "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    vd_plant_spec* s = NULL;
    memset(&e, 0, sizeof e);
    CHECK_STATUS(vd_plant_parse_json(bad[i], strlen(bad[i]), NULL, &s, &e), VD_ERR_FORMAT, e);
    CHECK(s == NULL);
  }
  // a missing file is an I/O error naming the file; an empty file is a format error
  vd_plant_spec* s = NULL;
  memset(&e, 0, sizeof e);
  char p[300];
  snprintf(p, sizeof p, "%s/missing.json", vdt_tmpdir());
  CHECK_STATUS(vd_plant_read_json(p, &s, &e), VD_ERR_IO, e);
  CHECK_STR(e.file, p);
  snprintf(p, sizeof p, "%s/empty.json", vdt_tmpdir());
  FILE* fp = fopen(p, "wb");
  REQUIRE(fp);
  fclose(fp);
  memset(&e, 0, sizeof e);
  CHECK_STATUS(vd_plant_read_json(p, &s, &e), VD_ERR_FORMAT, e);
  CHECK_STR(e.file, p);
}

TEST(plant, json_every_prefix) {
  // every truncation of a valid file is rejected cleanly (a poor man's fuzz)
  size_t len = 0;
  char* t = plant_text(&len);
  REQUIRE(t);
  int ok = 0;
  for (size_t n = 0; n < len; n++) {
    vd_plant_spec* s = NULL;
    vd_error e = {0};
    vd_status st = vd_plant_parse_json(t, n, "cut", &s, &e);
    if (st == VD_OK) ok++;
    vd_plant_spec_destroy(s);
  }
  // only the prefixes that drop nothing but the final newline parse
  CHECK_INT(ok, 1);
  vd_free(t, len + 1);
}

TEST(plant, out_of_memory) {
  size_t len = 0;
  char* t = plant_text(&len);
  REQUIRE(t);
  // parse and compile under every allocation budget until one succeeds
  int done = 0;
  for (int64_t b = 0; b < 200 && !done; b++) {
    vdt_oom_begin(b);
    vd_plant_spec* s = NULL;
    vd_model* m = NULL;
    vd_data* d = NULL;
    vd_error e = {0};
    vd_status st = vd_plant_parse_json(t, len, "oom", &s, &e);
    if (st == VD_OK) st = vd_plant_compile(s, &m, &e);
    if (st == VD_OK) d = vd_data_create(m);
    done = d != NULL;
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    vd_data_destroy(d);
    vd_model_destroy(m);
    vd_plant_spec_destroy(s);
    vdt_oom_end();
  }
  CHECK(done);
  vd_free(t, len + 1);
}

TEST(plant, spec_copy) {
  vd_plant_spec* s = make_plant();
  REQUIRE(s);
  vd_plant_set_label(s, 4, "odd name");
  vd_plant_spec* c = vd_plant_spec_copy(s);
  REQUIRE(c);
  // the same plant: equal files
  char p1[300], p2[300];
  snprintf(p1, sizeof p1, "%s/copy1.json", vdt_tmpdir());
  snprintf(p2, sizeof p2, "%s/copy2.json", vdt_tmpdir());
  vd_error err = {0};
  CHECK_STATUS(vd_plant_write_json(s, p1, &err), VD_OK, err);
  CHECK_STATUS(vd_plant_write_json(c, p2, &err), VD_OK, err);
  size_t n1 = 0, n2 = 0;
  char* t1 = slurp(p1, &n1);
  char* t2 = slurp(p2, &n2);
  REQUIRE(t1 && t2);
  CHECK(n1 == n2 && memcmp(t1, t2, n1) == 0);
  vd_free(t1, n1 + 1);
  vd_free(t2, n2 + 1);
  CHECK(c->ninstance == s->ninstance && c->nlabel == s->nlabel);
  // independent: editing and growing the copy leaves the original as it was
  c->node[0].x = 5;
  CHECK(s->node[0].x == 0);
  int k = vd_plant_add_node(c, vd_v3(1, 2, 3));
  CHECK(k == s->nnode && c->nnode == s->nnode + 1);
  vd_plant_spec_destroy(c);
  // an empty spec copies to an empty spec
  vd_plant_spec* e = vd_plant_spec_create();
  vd_plant_spec* ec = vd_plant_spec_copy(e);
  CHECK(ec && ec->nnode == 0 && ec->nlabel == 0);
  vd_plant_spec_destroy(ec);
  vd_plant_spec_destroy(e);
  CHECK(vd_plant_spec_copy(NULL) == NULL);
  // out of memory at every allocation: NULL, nothing leaked (the harness checks the count)
  for (int64_t budget = 0; budget < 9; budget++) {
    vdt_oom_begin(budget);
    vd_plant_spec* o = vd_plant_spec_copy(s);
    vdt_oom_end();
    CHECK((o == NULL) == (budget < 8));
    vd_plant_spec_destroy(o);
  }
  vd_plant_spec_destroy(s);
}

// Organ instances (issue 12, item 20): a stem of two internodes with a lateral branch, a pedicel
// drawn as pedicel + knuckle + pedicel (three modules), its fruit, and a leaf of two modules
// (petiole, blade)
TEST(plant, organ_instances_and_traits) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  CHECK_STATUS(vd_plant_set_label(s, 1, "stem"), VD_OK, (vd_error){0});
  vd_plant_set_label(s, 2, "pedicel");
  vd_plant_set_label(s, 3, "fruit");
  vd_plant_set_label(s, 4, "leaf");
  vd_vec3 p[7] = {vd_v3(0, 0, 0), vd_v3(0, 0, 0.1), vd_v3(0, 0, 0.2), vd_v3(0.1, 0, 0.2), vd_v3(0, 0.02, 0.1),
                  vd_v3(0, 0.03, 0.1), vd_v3(0, 0.05, 0.1)};
  for (int i = 0; i < 7; i++) vd_plant_add_node(s, p[i]);
  // segment: nodes, parent, label, axis, module
  int seg[7][6] = {{0, 1, -1, 1, 0, 10}, {1, 2, 0, 1, 0, 11}, {2, 3, 1, 1, 1, 12},  // stem, stem, branch
                   {1, 4, 0, 2, 2, 13},  {4, 5, 3, 2, 2, 14},  {5, 6, 4, 2, 2, 15},   // pedicel, knuckle, pedicel
                   {1, 4, 0, 4, 3, 16}};                                           // petiole
  for (int i = 0; i < 7; i++) {
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = seg[i][0], g.node1 = seg[i][1], g.parent = seg[i][2], g.label = seg[i][3], g.axis = seg[i][4];
    g.module = seg[i][5], g.instance = i + 1, g.r0 = g.r1 = 0.01;
    vd_plant_add_segment(s, &g);
  }
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(0, 0.05, 0.09), f.radius = 0.01, f.parent = 5, f.node = 6, f.label = 3, f.module = 17, f.instance = 8;
  vd_plant_add_sphere(s, &f);
  // the blade: a unit-area square from another module, hung from the petiole
  vd_mesh_spec m = {0};
  m.node = 4, m.parent = 6, m.label = 4, m.module = 18, m.instance = 9;
  vd_vec3 v[4] = {vd_v3(0, 0, 0), vd_v3(1, 0, 0), vd_v3(1, 1, 0), vd_v3(0, 1, 0)};
  int tri[6] = {0, 1, 2, 0, 2, 3};
  vd_plant_add_mesh(s, &m, v, 4, tri, 2);
  s->ninstance = 9;
  CHECK_INT(vd_plant_set_instances(s, VD_INSTANCE_ORGANS), VD_OK);
  // stem 1 (both internodes), branch 2, pedicel 3 (three pieces), leaf 4 (petiole and blade),
  // fruit 5
  int want[7] = {1, 1, 2, 3, 3, 3, 4};
  for (int i = 0; i < 7; i++) CHECK_INT(s->seg[i].instance, want[i]);
  CHECK_INT(s->sphere[0].instance, 5);
  CHECK_INT(s->mesh[0].instance, 4);
  CHECK_INT(s->ninstance, 5);
  vd_organ_traits* t;
  int n;
  CHECK_INT(vd_plant_traits(s, &t, &n), VD_OK);
  CHECK_INT(n, 5);
  if (n == 5) {
    CHECK_NEAR(t[0].length, 0.2, 1e-12);
    CHECK_NEAR(t[0].volume, VD_PI * 0.01 * 0.01 * 0.2, 1e-12);
    CHECK_NEAR(t[0].diameter, 0.02, 1e-12);
    CHECK_INT(t[2].nseg, 3);
    CHECK_NEAR(t[2].length, 0.05, 1e-12);
    CHECK_NEAR(t[3].area, 1.0, 1e-12);
    CHECK_INT(t[3].organ, VD_ORGAN_LEAF);
    CHECK_NEAR(t[4].diameter, 0.02, 1e-12);
    CHECK_NEAR(t[4].volume, 4.0 / 3.0 * VD_PI * 1e-6, 1e-15);
  }
  vd_free(t, (size_t)n * sizeof *t);
  // modules: one per producing module again
  CHECK_INT(vd_plant_set_instances(s, VD_INSTANCE_MODULES), VD_OK);
  for (int i = 0; i < 7; i++) CHECK_INT(s->seg[i].instance, i + 1);
  CHECK_INT(s->sphere[0].instance, 8);
  CHECK_INT(s->mesh[0].instance, 9);
  CHECK_INT(s->ninstance, 9);
  vd_plant_spec_destroy(s);
}
