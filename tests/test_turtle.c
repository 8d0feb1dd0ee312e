// SPDX-License-Identifier: MIT
// turtle: L-Py turtle semantics against hand-derived goldens (frame, rotations and their signs,
// widths, colours and labels, instances, nodes, branching structure, primitives, polygons,
// scale, tropism, placement commands, errors, out of memory). Only plant.h's public API is used.
#include <stdlib.h>

#include "test.h"
#include "verdant/lsys.h"

// ---------------------------------------------------------------------------------------------
// building L-strings from text: predefined names by longest match, any other character is an
// organ module (id >= VD_SYM_PREDEFINED_COUNT), parameters are numbers in parentheses

static const char* const names[] = {
#define NAME(e, s) s,
    VD_SYM_LIST(NAME)
#undef NAME
};

// module and value capacities of a test string (kept beside it; freed by lfree)
typedef struct {
  vd_lstring s;
  int64_t scap; // capacity of src, 0 if none
} lbuf;

static void lpush(lbuf* b, int sym, const double* v, int nv) {
  vd_lstring* s = &b->s;
  if (s->n + 1 > s->cap) {
    int64_t nc = s->cap ? 2 * s->cap : 16;
    s->sym = vd_realloc(s->sym, (size_t)s->cap * sizeof *s->sym, (size_t)nc * sizeof *s->sym);
    s->par = vd_realloc(s->par, (size_t)(s->cap + 1) * sizeof *s->par,
                        (size_t)(nc + 1) * sizeof *s->par);
    s->cap = nc;
    if (!s->sym || !s->par) abort();
  }
  if (s->n == 0) s->par[0] = 0;
  int64_t nval = s->par[s->n];
  if (nval + nv > s->vcap) {
    int64_t nc = s->vcap ? 2 * s->vcap : 16;
    while (nc < nval + nv)
      nc *= 2;
    s->val = vd_realloc(s->val, (size_t)s->vcap * sizeof *s->val, (size_t)nc * sizeof *s->val);
    s->vcap = nc;
    if (!s->val) abort();
  }
  for (int k = 0; k < nv; k++)
    s->val[nval + k] = v[k];
  s->sym[s->n] = sym;
  s->par[s->n + 1] = nval + nv;
  s->n++;
}

// append the modules written in text ("F(1,0.2) [ +(30) ~l ] A")
static void ladd(lbuf* b, const char* text) {
  const char* c = text;
  while (*c) {
    if (*c == ' ') {
      c++;
      continue;
    }
    int best = -1;
    size_t blen = 0;
    for (int k = 0; k < VD_SYM_PREDEFINED_COUNT; k++) {
      size_t n = strlen(names[k]);
      if (n > blen && strncmp(c, names[k], n) == 0) {
        best = k;
        blen = n;
      }
    }
    int sym = best >= 0 ? best : VD_SYM_PREDEFINED_COUNT + (unsigned char)*c;
    c += best >= 0 ? blen : 1;
    double v[16];
    int nv = 0;
    if (*c == '(') {
      c++;
      while (*c && *c != ')') {
        char* end;
        v[nv++] = strtod(c, &end);
        c = end;
        while (*c == ' ' || *c == ',')
          c++;
      }
      if (*c == ')') c++;
    }
    lpush(b, sym, v, nv);
  }
}

static void lfree(lbuf* b) {
  vd_lstring* s = &b->s;
  vd_free(s->sym, (size_t)s->cap * sizeof *s->sym);
  vd_free(s->par, s->cap ? (size_t)(s->cap + 1) * sizeof *s->par : 0);
  vd_free(s->val, (size_t)s->vcap * sizeof *s->val);
  vd_free(s->src, (size_t)b->scap * sizeof *s->src);
  memset(b, 0, sizeof *b);
}

// give the string a src array (one entry per module)
static void lsrc(lbuf* b, const int64_t* src) {
  b->scap = b->s.n;
  b->s.src = vd_malloc((size_t)b->scap * sizeof *b->s.src);
  memcpy(b->s.src, src, (size_t)b->scap * sizeof *src);
}

// run the turtle on text with the default settings into a new spec
static vd_status run_def(const char* text, const vd_turtle_def* def, vd_plant_spec** out) {
  lbuf b = {0};
  ladd(&b, text);
  vd_error e = {0};
  *out = vd_plant_spec_create();
  vd_status st = vd_turtle_run(NULL, &b.s, def, *out, &e);
  lfree(&b);
  return st;
}

static vd_status run(const char* text, vd_plant_spec** out) {
  return run_def(text, NULL, out);
}

// status of a run whose plant is thrown away
static vd_status status_of(const char* text) {
  vd_plant_spec* P;
  vd_status st = run(text, &P);
  vd_plant_spec_destroy(P);
  return st;
}

#define TOL 1e-9
#define CHECK_V3(v, X, Y, Z)                                                                       \
  do {                                                                                             \
    vd_vec3 v_ = (v);                                                                              \
    CHECK_NEAR(v_.x, (X), TOL);                                                                    \
    CHECK_NEAR(v_.y, (Y), TOL);                                                                    \
    CHECK_NEAR(v_.z, (Z), TOL);                                                                    \
  } while (0)

static vd_vec3 seg_a(const vd_plant_spec* P, int k) {
  return P->node[P->seg[k].node0];
}
static vd_vec3 seg_b(const vd_plant_spec* P, int k) {
  return P->node[P->seg[k].node1];
}
static vd_vec3 mvert(const vd_plant_spec* P, int m, int j) {
  return P->vert[P->mesh[m].vert_start + j];
}
// unnormalised normal of triangle j of mesh m
static vd_vec3 mnormal(const vd_plant_spec* P, int m, int j) {
  const int* t = P->tri + 3 * (P->mesh[m].tri_start + j);
  vd_vec3 a = P->vert[t[0]], b = P->vert[t[1]], c = P->vert[t[2]];
  return vd_cross(vd_sub(b, a), vd_sub(c, a));
}

// end point of the last segment of text
static vd_vec3 end_of(const char* text) {
  vd_plant_spec* P;
  vd_status st = run(text, &P);
  vd_vec3 r = vd_v3(NAN, NAN, NAN);
  if (st == VD_OK && P->nseg > 0) r = seg_b(P, P->nseg - 1);
  vd_plant_spec_destroy(P);
  return r;
}

// ---------------------------------------------------------------------------------------------
// frame and rotations

TEST(turtle, defaults) {
  vd_turtle_def d = vd_turtle_def_default();
  CHECK(d.angle == 60 && d.step == 1 && d.width == 0.1 && d.width_inc == 1);
  CHECK(d.scale_factor == 0.5 && d.color == 1 && d.slices == 8 && d.elasticity == 0);
  CHECK_V3(d.tropism, 0, 0, 1);
}

TEST(turtle, single_F) {
  vd_plant_spec* P;
  REQUIRE(run("F", &P) == VD_OK);
  CHECK_INT(P->nseg, 1);
  CHECK_INT(P->nnode, 2);
  const vd_segment_spec* g = &P->seg[0];
  CHECK_V3(seg_a(P, 0), 0, 0, 0);
  CHECK_V3(seg_b(P, 0), 0, 0, 1); // heading +Z
  CHECK_V3(g->up, 1, 0, 0);       // up +X
  CHECK_NEAR(g->r0, 0.1, TOL);
  CHECK_NEAR(g->r1, 0.1, TOL);
  CHECK_INT(g->parent, -1);
  CHECK_INT(g->label, 1);
  CHECK_INT(g->instance, 1);
  CHECK_INT(g->module, 0);
  CHECK_INT(g->axis, 0);
  CHECK_INT(g->order, 0);
  CHECK_INT(g->flags, VD_SEG_TIP);
  CHECK_INT(g->slices, 8);
  CHECK_NEAR(g->age, 0, 0);
  CHECK_INT(P->ninstance, 1);
  vd_plant_spec_destroy(P);
}

TEST(turtle, turn_pitch_roll_signs) {
  // + turns H toward L = -Y, - toward +Y
  CHECK_V3(end_of("F +(90) F"), 0, -1, 1);
  CHECK_V3(end_of("F -(90) F"), 0, 1, 1);
  // & pitches H toward -U = -X, ^ toward +U
  CHECK_V3(end_of("&(90) F"), -1, 0, 0);
  CHECK_V3(end_of("^(90) F"), 1, 0, 0);
  // / rolls L toward U (so U goes to -L = +Y), then + turns toward the new L = +X
  CHECK_V3(end_of("/(90) +(90) F"), 1, 0, 0);
  CHECK_V3(end_of("\\(90) +(90) F"), -1, 0, 0);
  CHECK_V3(end_of("iRollL(90) +(90) F"), 1, 0, 0);
  CHECK_V3(end_of("iRollR(90) +(90) F"), -1, 0, 0);
  // | turns around, the default angle is 60 degrees
  CHECK_V3(end_of("| F"), 0, 0, -1);
  CHECK_V3(end_of("+ F"), 0, -sin(VD_PI / 3), cos(VD_PI / 3));
  CHECK_V3(end_of("& F"), -sin(VD_PI / 3), 0, cos(VD_PI / 3));
  vd_plant_spec* P;
  REQUIRE(run("/(90) F", &P) == VD_OK);
  CHECK_V3(P->seg[0].up, 0, 1, 0);
  vd_plant_spec_destroy(P);
}

TEST(turtle, rotations_match_rodrigues) {
  // an independent frame: rotate (H, L, U) about the current axes with vd_rotate
  vd_vec3 H = vd_v3(0, 0, 1), L = vd_v3(0, -1, 0), U = vd_v3(1, 0, 0), pos = vd_v3(0, 0, 0);
  double d = VD_PI / 180;
  H = vd_rotate(H, U, 30 * d), L = vd_rotate(L, U, 30 * d);           // +(30)
  pos = vd_add(pos, H);                                               // F
  vd_vec3 h2 = vd_rotate(H, L, 45 * d), u2 = vd_rotate(U, L, 45 * d); // &(45)
  H = h2, U = u2;
  vd_vec3 l3 = vd_rotate(L, H, 60 * d), u3 = vd_rotate(U, H, 60 * d); // /(60)
  L = l3, U = u3;
  H = vd_rotate(H, U, -20 * d), L = vd_rotate(L, U, -20 * d); // -(20)
  pos = vd_add(pos, vd_scale(H, 2));                          // F(2)
  vd_plant_spec* P;
  REQUIRE(run("+(30) F &(45) /(60) -(20) F(2)", &P) == VD_OK);
  CHECK_V3(seg_b(P, 1), pos.x, pos.y, pos.z);
  CHECK_V3(P->seg[1].up, U.x, U.y, U.z);
  vd_plant_spec_destroy(P);
}

TEST(turtle, frame_stays_orthonormal) {
  // 20000 small turns, pitches and rolls: the frame is re-orthonormalised as it goes
  lbuf b = {0};
  for (int k = 0; k < 5000; k++)
    ladd(&b, "+(7.3) &(3.1) /(11.7) F(0.01)");
  vd_plant_spec* P = vd_plant_spec_create();
  REQUIRE(vd_turtle_run(NULL, &b.s, NULL, P, NULL) == VD_OK);
  for (int k = 0; k < P->nseg; k += 499) {
    vd_vec3 dir = vd_sub(seg_b(P, k), seg_a(P, k));
    CHECK_NEAR(vd_norm(dir), 0.01, 1e-12);
    CHECK_NEAR(vd_norm(P->seg[k].up), 1, 1e-12);
    CHECK_NEAR(vd_dot(dir, P->seg[k].up), 0, 1e-12);
  }
  vd_plant_spec_destroy(P);
  lfree(&b);
}

TEST(turtle, euler_and_sethead) {
  vd_plant_spec* P;
  // EulerAngles() is the initial frame; (0,0,0) is the world frame: H = X, U = Z
  CHECK_V3(end_of("+(40) EulerAngles F"), 0, 0, 1);
  REQUIRE(run("EulerAngles(0,0,0) F", &P) == VD_OK);
  CHECK_V3(seg_b(P, 0), 1, 0, 0);
  CHECK_V3(P->seg[0].up, 0, 0, 1);
  vd_plant_spec_destroy(P);
  CHECK_V3(end_of("EulerAngles(90,0,0) F"), 0, 1, 0);
  CHECK_V3(end_of("EulerAngles(0,30,0) F"), cos(VD_PI / 6), 0, sin(VD_PI / 6));
  // @R(h, u) sets both; @R(h) turns toward h
  REQUIRE(run("@R(1,0,0, 0,0,1) F", &P) == VD_OK);
  CHECK_V3(seg_b(P, 0), 1, 0, 0);
  CHECK_V3(P->seg[0].up, 0, 0, 1);
  vd_plant_spec_destroy(P);
  REQUIRE(run("@R(0,2,0, 1,1,1) F", &P) == VD_OK); // up re-orthogonalised against H
  CHECK_V3(seg_b(P, 0), 0, 1, 0);
  CHECK_V3(P->seg[0].up, sqrt(0.5), 0, sqrt(0.5));
  vd_plant_spec_destroy(P);
  CHECK_V3(end_of("@R(0,3,0) F"), 0, 1, 0);
  CHECK_V3(end_of("+(30) @R F"), 0, 0, 1);
}

TEST(turtle, roll_to_vert_and_horizontal) {
  vd_plant_spec* P;
  // after &(90) H = -X and U = +Z; a roll takes U off vertical, @v brings it back
  REQUIRE(run("&(90) /(30) @v F", &P) == VD_OK);
  CHECK_V3(seg_b(P, 0), -1, 0, 0);
  CHECK_V3(P->seg[0].up, 0, 0, 1);
  vd_plant_spec_destroy(P);
  // @h turns H into the horizontal plane
  CHECK_V3(end_of("&(30) @h F"), -1, 0, 0);
  CHECK_V3(end_of("&(30) @h(0.5) F"), -sin(VD_PI / 3), 0, cos(VD_PI / 3));
}

// ---------------------------------------------------------------------------------------------
// widths, colours, labels

TEST(turtle, frustum_top_radius) {
  vd_plant_spec* P;
  REQUIRE(run("F(2, 0.05) F F(1, 0) F F(1, -1)", &P) == VD_OK);
  CHECK_INT(P->nseg, 5);
  CHECK_NEAR(P->seg[0].r0, 0.1, TOL);
  CHECK_NEAR(P->seg[0].r1, 0.05, TOL);
  CHECK_V3(seg_b(P, 0), 0, 0, 2);
  CHECK_NEAR(P->seg[1].r0, 0.05, TOL); // width carried on
  CHECK_NEAR(P->seg[1].r1, 0.05, TOL);
  CHECK_NEAR(P->seg[2].r1, 0, TOL); // a cone
  CHECK_NEAR(P->seg[3].r0, 0, TOL);
  CHECK_NEAR(P->seg[4].r1, 0, TOL); // negative top radius = none
  vd_plant_spec_destroy(P);
}

TEST(turtle, width_commands) {
  vd_plant_spec* P;
  REQUIRE(run("F _ F ! F _(0.3) F !(0.2) F SetWidth(0.4) F ! F", &P) == VD_OK);
  static const double r[7] = {0.1, 1.1, 0.1, 0.3, 0.2, 0.4, 0.4}; // last ! would go negative
  REQUIRE(P->nseg == 7);
  for (int k = 0; k < 7; k++)
    CHECK_NEAR(P->seg[k].r0, r[k], TOL);
  vd_plant_spec_destroy(P);
  vd_turtle_def d = vd_turtle_def_default();
  d.width = 0.5;
  d.width_inc = 0.25;
  REQUIRE(run_def("F _ F", &d, &P) == VD_OK);
  CHECK_NEAR(P->seg[0].r0, 0.5, TOL);
  CHECK_NEAR(P->seg[1].r0, 0.75, TOL);
  vd_plant_spec_destroy(P);
}

TEST(turtle, colours_are_labels) {
  vd_plant_spec* P;
  REQUIRE(run("F ; F ;(5) F , F SetColor(2) F SetColor(10,20,30) F , , , F ;(3.9) F", &P) == VD_OK);
  static const int lab[8] = {1, 2, 5, 4, 2, 2, 0, 3};
  REQUIRE(P->nseg == 8);
  for (int k = 0; k < 8; k++)
    CHECK_INT(P->seg[k].label, lab[k]);
  vd_plant_spec_destroy(P);
  // the colour is part of the branch state
  REQUIRE(run("F [ ;(4) F ] F", &P) == VD_OK);
  CHECK_INT(P->seg[1].label, 4);
  CHECK_INT(P->seg[2].label, 1);
  vd_plant_spec_destroy(P);
}

TEST(turtle, explicit_trailing_label) {
  vd_plant_spec* P;
  REQUIRE(run("F(1, 0.2, 7) F @O(0.3, 3) ~l(1, 4) @o(0.1, 5) @B(1, 0.1, 6) @b(1, 0.1, 8)", &P) ==
          VD_OK);
  CHECK_INT(P->seg[0].label, 7);
  CHECK_NEAR(P->seg[0].r1, 0.2, TOL);
  CHECK_INT(P->seg[1].label, 1); // only for that primitive
  CHECK_NEAR(P->seg[1].r0, 0.2, TOL);
  CHECK_INT(P->sphere[0].label, 3);
  CHECK_NEAR(P->sphere[0].radius, 0.3, TOL);
  REQUIRE(P->nmesh == 4);
  CHECK_INT(P->mesh[0].label, 4);
  CHECK_INT(P->mesh[1].label, 5);
  CHECK_INT(P->mesh[2].label, 6);
  CHECK_INT(P->mesh[3].label, 8);
  vd_plant_spec_destroy(P);
  CHECK_INT(status_of("F(1, 0.1, 7, 8)"), VD_ERR_ARG);
  CHECK_INT(status_of("@O(1, 2, 3)"), VD_ERR_ARG);
  CHECK_INT(status_of("~l(1, 2, 3)"), VD_ERR_ARG);
  CHECK_INT(status_of("@B(1, 0.1, 2, 3)"), VD_ERR_ARG);
  CHECK_INT(status_of("F(1, 0.1, -2)"), VD_ERR_VALUE);
}

// ---------------------------------------------------------------------------------------------
// instances and structure

TEST(turtle, instances_from_src) {
  lbuf b = {0};
  ladd(&b, "F F A F @O F f F");
  static const int64_t src[8] = {3, 3, 4, 7, 7, 5, 6, 3};
  lsrc(&b, src);
  vd_plant_spec* P = vd_plant_spec_create();
  REQUIRE(vd_turtle_run(NULL, &b.s, NULL, P, NULL) == VD_OK);
  // modules 3, 7, 5 draw, in that order: instances 1, 2, 3; module 3 again is instance 1
  REQUIRE(P->nseg == 5);
  static const int inst[5] = {1, 1, 2, 3, 1};
  static const int64_t mod[5] = {3, 3, 7, 5, 3};
  for (int k = 0; k < 5; k++) {
    CHECK_INT(P->seg[k].instance, inst[k]);
    CHECK_INT(P->seg[k].module, mod[k]);
  }
  CHECK_INT(P->sphere[0].instance, 2);
  CHECK_INT(P->sphere[0].module, 7);
  // a second run appends after the instances already in the plant
  REQUIRE(vd_turtle_run(NULL, &b.s, NULL, P, NULL) == VD_OK);
  CHECK_INT(P->seg[5].instance, 4);
  CHECK_INT(P->ninstance, 6);
  vd_plant_spec_destroy(P);
  lfree(&b);
}

TEST(turtle, instances_many_unordered) {
  // 3000 modules whose src visits 0..999 in a scrambled order, each three times
  lbuf b = {0};
  int n = 3000;
  int64_t* src = vd_malloc((size_t)n * sizeof *src);
  for (int k = 0; k < n; k++) {
    ladd(&b, "F");
    src[k] = (int64_t)((k % 1000) * 7919 % 1000);
  }
  lsrc(&b, src);
  vd_plant_spec* P = vd_plant_spec_create();
  REQUIRE(vd_turtle_run(NULL, &b.s, NULL, P, NULL) == VD_OK);
  REQUIRE(P->nseg == n);
  for (int k = 0; k < n; k++)
    CHECK_INT(P->seg[k].instance, k % 1000 + 1);
  CHECK_INT(P->ninstance, 1000);
  vd_plant_spec_destroy(P);
  vd_free(src, (size_t)n * sizeof *src);
  lfree(&b);
}

TEST(turtle, instances_without_src) {
  vd_plant_spec* P;
  REQUIRE(run("F + f F @O B [ F ]", &P) == VD_OK);
  CHECK_INT(P->seg[0].instance, 1);
  CHECK_INT(P->seg[1].instance, 2);
  CHECK_INT(P->seg[1].module, 3);
  CHECK_INT(P->sphere[0].instance, 3);
  CHECK_INT(P->seg[2].instance, 4);
  CHECK_INT(P->seg[2].module, 7);
  vd_plant_spec_destroy(P);
}

TEST(turtle, nodes_shared_along_axis) {
  vd_plant_spec* P;
  REQUIRE(run("F F F", &P) == VD_OK);
  CHECK_INT(P->nnode, 4);
  CHECK_INT(P->seg[0].node1, P->seg[1].node0);
  CHECK_INT(P->seg[1].node1, P->seg[2].node0);
  vd_plant_spec_destroy(P);
  // a branch starts at the current node, and so does the axis after it
  REQUIRE(run("F [ +F ] F", &P) == VD_OK);
  CHECK_INT(P->nnode, 4);
  CHECK_INT(P->seg[1].node0, P->seg[0].node1);
  CHECK_INT(P->seg[2].node0, P->seg[0].node1);
  vd_plant_spec_destroy(P);
  // a move without drawing starts a new node; the parent stays the last segment
  REQUIRE(run("F f F +(90) F", &P) == VD_OK);
  CHECK_INT(P->nnode, 5);
  CHECK(P->seg[1].node0 != P->seg[0].node1);
  CHECK_V3(seg_a(P, 1), 0, 0, 2);
  CHECK_INT(P->seg[1].parent, 0);
  CHECK_INT(P->seg[2].node0, P->seg[1].node1); // rotations keep the node
  vd_plant_spec_destroy(P);
  REQUIRE(run("F MoveRel(0,3,0) F", &P) == VD_OK);
  CHECK_INT(P->nnode, 4);
  CHECK_V3(seg_a(P, 1), 0, 3, 1);
  vd_plant_spec_destroy(P);
}

TEST(turtle, parent_axis_order_tips) {
  vd_plant_spec* P;
  REQUIRE(run("F [ +F [ -F ] F ] F [ F ]", &P) == VD_OK);
  REQUIRE(P->nseg == 6);
  static const int parent[6] = {-1, 0, 1, 1, 0, 4};
  static const int axis[6] = {0, 1, 2, 1, 0, 3};
  static const int order[6] = {0, 1, 2, 1, 0, 1};
  static const unsigned flags[6] = {0, 0, VD_SEG_TIP, VD_SEG_TIP, VD_SEG_TIP, VD_SEG_TIP};
  for (int k = 0; k < 6; k++) {
    CHECK_INT(P->seg[k].parent, parent[k]);
    CHECK_INT(P->seg[k].axis, axis[k]);
    CHECK_INT(P->seg[k].order, order[k]);
    CHECK_INT(P->seg[k].flags, flags[k]);
  }
  vd_plant_spec_destroy(P);
  // nested brackets before drawing make one lateral axis; a bracket that draws nothing makes none
  REQUIRE(run("F [ ] [[ F ]] F", &P) == VD_OK);
  CHECK_INT(P->seg[1].axis, 1);
  CHECK_INT(P->seg[1].order, 1);
  CHECK_INT(P->seg[2].axis, 0);
  CHECK_INT(P->seg[0].flags, 0);
  CHECK_INT(P->seg[1].flags, VD_SEG_TIP);
  CHECK_INT(P->seg[2].flags, VD_SEG_TIP);
  vd_plant_spec_destroy(P);
  // unclosed brackets are tolerated and end their axes at the end of the string
  REQUIRE(run("F [ F f F [ F", &P) == VD_OK);
  CHECK_INT(P->seg[0].flags, VD_SEG_TIP);
  CHECK_INT(P->seg[1].flags, 0);
  CHECK_INT(P->seg[2].flags, VD_SEG_TIP);
  CHECK_INT(P->seg[3].flags, VD_SEG_TIP);
  CHECK_INT(P->seg[3].order, 2);
  vd_plant_spec_destroy(P);
}

TEST(turtle, set_age_and_resolution) {
  vd_plant_spec* P;
  REQUIRE(run("SetAge(3) F [ SetAge(5) F ] SectionResolution(5) F @O", &P) == VD_OK);
  CHECK_NEAR(P->seg[0].age, 3, 0);
  CHECK_NEAR(P->seg[1].age, 5, 0);
  CHECK_NEAR(P->seg[2].age, 3, 0);
  CHECK_INT(P->seg[1].slices, 8);
  CHECK_INT(P->seg[2].slices, 5);
  CHECK_INT(P->sphere[0].slices, 5);
  vd_plant_spec_destroy(P);
}

// ---------------------------------------------------------------------------------------------
// primitives

TEST(turtle, sphere) {
  vd_plant_spec* P;
  REQUIRE(run("@O(0.5) F @O @O(0)", &P) == VD_OK);
  REQUIRE(P->nsphere == 2);
  CHECK_V3(P->sphere[0].center, 0, 0, 0);
  CHECK_NEAR(P->sphere[0].radius, 0.5, TOL);
  CHECK_INT(P->sphere[0].node, -1);
  CHECK_INT(P->sphere[0].parent, -1);
  CHECK_V3(P->sphere[1].center, 0, 0, 1);
  CHECK_NEAR(P->sphere[1].radius, 0.1, TOL); // default: the width
  CHECK_INT(P->sphere[1].node, P->seg[0].node1);
  CHECK_INT(P->sphere[1].parent, 0);
  CHECK_INT(P->sphere[1].label, 1);
  CHECK_INT(P->sphere[1].instance, 3);
  CHECK_INT(P->sphere[1].module, 2);
  CHECK_INT(P->sphere[1].slices, 8);
  vd_plant_spec_destroy(P);
  // a negative radius is ignored with a warning, as L-Py does (issue 12 item 8)
  REQUIRE(run("@O(-1) @O(0.5)", &P) == VD_OK);
  CHECK_INT(P->nsphere, 1);
  vd_plant_spec_destroy(P);
}

TEST(turtle, disc) {
  vd_plant_spec* P;
  REQUIRE(run("F @o(0.5)", &P) == VD_OK);
  REQUIRE(P->nmesh == 1);
  const vd_mesh_spec* m = &P->mesh[0];
  CHECK_INT(m->nvert, 9);
  CHECK_INT(m->ntri, 8);
  CHECK_INT(m->closed, 0);
  CHECK_INT(m->node, P->seg[0].node1);
  CHECK_INT(m->parent, 0);
  CHECK_V3(mvert(P, 0, 0), 0, 0, 1);
  CHECK_V3(mvert(P, 0, 1), 0, 0, 0.5); // PlantGL's first rim point: -H
  CHECK_V3(mvert(P, 0, 3), 0, 0.5, 1); // a quarter turn on: -L
  // the rim lies in the plane of H and L (normal U = +X), faces point along U
  double area = 0;
  for (int j = 1; j < 9; j++) {
    vd_vec3 q = vd_sub(mvert(P, 0, j), vd_v3(0, 0, 1));
    CHECK_NEAR(q.x, 0, TOL);
    CHECK_NEAR(vd_norm(q), 0.5, TOL);
  }
  for (int j = 0; j < 8; j++) {
    vd_vec3 nrm = mnormal(P, 0, j);
    CHECK(nrm.x > 0);
    area += 0.5 * vd_norm(nrm);
  }
  CHECK_NEAR(area, 8 * 0.5 * 0.25 * sin(VD_PI / 4), TOL);
  vd_plant_spec_destroy(P);
}

TEST(turtle, box) {
  vd_plant_spec* P;
  REQUIRE(run("@B(2, 0.3) F", &P) == VD_OK);
  REQUIRE(P->nmesh == 1);
  const vd_mesh_spec* m = &P->mesh[0];
  CHECK_INT(m->nvert, 8);
  CHECK_INT(m->ntri, 12);
  CHECK_INT(m->closed, 1);
  for (int j = 0; j < 4; j++) {
    vd_vec3 a = mvert(P, 0, j), b = mvert(P, 0, 4 + j);
    CHECK_NEAR(a.z, 0, TOL);
    CHECK_NEAR(fabs(a.x), 0.1, TOL);
    CHECK_NEAR(fabs(a.y), 0.1, TOL);
    CHECK_NEAR(b.z, 2, TOL);
    CHECK_NEAR(fabs(b.x), 0.3, TOL);
    CHECK_NEAR(fabs(b.y), 0.3, TOL);
  }
  // outward triangles: the divergence theorem gives the frustum volume h/3 (A1 + A2 + sqrt(A1 A2))
  double vol = 0;
  for (int j = 0; j < 12; j++) {
    const int* t = P->tri + 3 * (m->tri_start + j);
    vol += vd_dot(P->vert[t[0]], vd_cross(P->vert[t[1]], P->vert[t[2]])) / 6;
  }
  CHECK_NEAR(vol, 2.0 / 3 * (0.04 + 0.36 + 0.12), TOL);
  // the turtle moved along H and the width became the top radius
  CHECK_V3(seg_a(P, 0), 0, 0, 2);
  CHECK_NEAR(P->seg[0].r0, 0.3, TOL);
  vd_plant_spec_destroy(P);
}

TEST(turtle, quad) {
  vd_plant_spec* P;
  REQUIRE(run("@b(1)", &P) == VD_OK);
  REQUIRE(P->nmesh == 1);
  CHECK_INT(P->mesh[0].nvert, 4);
  CHECK_INT(P->mesh[0].ntri, 2);
  CHECK_V3(mvert(P, 0, 0), 0, -0.1, 0); // base + width L
  CHECK_V3(mvert(P, 0, 1), 0, 0.1, 0);
  CHECK_V3(mvert(P, 0, 2), 0, 0.1, 1);
  CHECK_V3(mvert(P, 0, 3), 0, -0.1, 1);
  CHECK(mnormal(P, 0, 0).x > 0 && mnormal(P, 0, 1).x > 0);
  vd_plant_spec_destroy(P);
  REQUIRE(run("@b(1, 0)", &P) == VD_OK); // a triangle when the top radius is 0
  CHECK_INT(P->mesh[0].nvert, 3);
  CHECK_INT(P->mesh[0].ntri, 1);
  vd_plant_spec_destroy(P);
}

TEST(turtle, leaf_hexagon) {
  vd_plant_spec* P;
  REQUIRE(run("~l F @D(2) ~l(0.5) /(90) ~l", &P) == VD_OK);
  REQUIRE(P->nmesh == 3);
  static const double v[7][3] = {{0, 0, 0.5},         {0, 0, 0}, {0, -0.25, 1.0 / 3},
                                 {0, -0.25, 2.0 / 3}, {0, 0, 1}, {0, 0.25, 2.0 / 3},
                                 {0, 0.25, 1.0 / 3}};
  static const int t[18] = {0, 2, 1, 0, 3, 2, 0, 4, 3, 0, 5, 4, 0, 6, 5, 0, 1, 6};
  CHECK_INT(P->mesh[0].nvert, 7);
  CHECK_INT(P->mesh[0].ntri, 6);
  CHECK_INT(P->mesh[0].closed, 0);
  for (int j = 0; j < 7; j++)
    CHECK_V3(mvert(P, 0, j), v[j][0], v[j][1], v[j][2]);
  for (int j = 0; j < 18; j++)
    CHECK_INT(P->tri[3 * P->mesh[0].tri_start + j] - P->mesh[0].vert_start, t[j]);
  for (int j = 0; j < 6; j++)
    CHECK(mnormal(P, 0, j).x > 0); // faces along U
  // scale x parameter: the same leaf, at the top of the F
  for (int j = 0; j < 7; j++)
    CHECK_V3(mvert(P, 1, j), v[j][0], v[j][1], v[j][2] + 1);
  // after a roll L = +X (scale 2)
  CHECK_V3(mvert(P, 2, 2), 0.5, 0, 1 + 2.0 / 3);
  CHECK_INT(P->mesh[1].parent, 0);
  vd_plant_spec_destroy(P);
  CHECK_INT(status_of("~"), VD_ERR_UNSUPPORTED);
  CHECK_INT(status_of("~l(-1)"), VD_ERR_VALUE);
}

// ---------------------------------------------------------------------------------------------
// polygons and generalised cylinders

TEST(turtle, polygon_points) {
  vd_plant_spec* P;
  REQUIRE(run("{ . f . +(90) f . +(90) f . }", &P) == VD_OK);
  CHECK_INT(P->nseg, 0);
  REQUIRE(P->nmesh == 1);
  CHECK_INT(P->mesh[0].nvert, 4);
  CHECK_INT(P->mesh[0].ntri, 2);
  CHECK_V3(mvert(P, 0, 0), 0, 0, 0);
  CHECK_V3(mvert(P, 0, 1), 0, 0, 1);
  CHECK_V3(mvert(P, 0, 2), 0, -1, 1);
  CHECK_V3(mvert(P, 0, 3), 0, -1, 0);
  CHECK_INT(P->mesh[0].label, 1);
  CHECK_INT(P->mesh[0].instance, 1);
  CHECK_INT(P->mesh[0].module, 0);
  vd_plant_spec_destroy(P);
  // F inside a polygon draws its segment and records its end; a last point equal to the
  // first is dropped; the colour set inside labels the polygon
  REQUIRE(run("{ . ;(3) F +(90) F +(90) F +(90) F }", &P) == VD_OK);
  CHECK_INT(P->nseg, 4);
  REQUIRE(P->nmesh == 1);
  CHECK_INT(P->mesh[0].nvert, 4);
  CHECK_INT(P->mesh[0].label, 3);
  CHECK_INT(P->seg[0].instance, 1);
  CHECK_INT(P->mesh[0].instance, 5); // module 0 (the {) drew last
  vd_plant_spec_destroy(P);
  // fewer than three points: nothing
  REQUIRE(run("{ . f . } { f f }", &P) == VD_OK);
  CHECK_INT(P->nmesh, 0);
  vd_plant_spec_destroy(P);
}

TEST(turtle, polygon_concave) {
  // an L-shape of area 3, started at a corner that does not see the whole polygon
  const char* pts = "{ @M(0,2,1) . @M(0,2,0) . @M(0,0,0) . @M(0,0,2) . @M(0,1,2) . @M(0,1,1) . }";
  char text[256];
  for (int concave = 0; concave < 2; concave++) {
    snprintf(text, sizeof text, "%s%s", pts, concave ? "(1)" : "");
    vd_plant_spec* P;
    REQUIRE(run(text, &P) == VD_OK);
    REQUIRE(P->nmesh == 1);
    CHECK_INT(P->mesh[0].ntri, 4);
    double area = 0, signed_area = 0;
    for (int j = 0; j < 4; j++) {
      vd_vec3 nrm = mnormal(P, 0, j);
      area += 0.5 * vd_norm(nrm);
      signed_area += 0.5 * nrm.x;
    }
    CHECK_NEAR(fabs(signed_area), 3, TOL);
    if (concave)
      CHECK_NEAR(area, 3, TOL); // ear clipping: no overlap
    else
      CHECK(area > 3 + 0.1); // the plain fan overlaps (as PlantGL's default)
    vd_plant_spec_destroy(P);
  }
}

TEST(turtle, generalized_cylinder_flags) {
  vd_plant_spec* P;
  REQUIRE(run("F @Gc F F [ F ] F @Ge F", &P) == VD_OK);
  REQUIRE(P->nseg == 6);
  static const unsigned gc[6] = {0, 0, VD_SEG_GC, VD_SEG_GC, VD_SEG_GC, 0};
  for (int k = 0; k < 6; k++)
    CHECK_INT(P->seg[k].flags & VD_SEG_GC, gc[k]);
  vd_plant_spec_destroy(P);
}

// ---------------------------------------------------------------------------------------------
// scale, tropism, placement, nF

TEST(turtle, scale) {
  vd_plant_spec* P;
  REQUIRE(run("@D(2) F f F @Di F @Dd @Dd F @Di(0.25) F @O", &P) == VD_OK);
  CHECK_V3(seg_b(P, 0), 0, 0, 2);
  CHECK_NEAR(P->seg[0].r0, 0.2, TOL);
  CHECK_V3(seg_a(P, 1), 0, 0, 4); // f scaled too
  CHECK_V3(seg_b(P, 1), 0, 0, 6);
  CHECK_V3(seg_b(P, 2), 0, 0, 7);  // x 0.5
  CHECK_V3(seg_b(P, 3), 0, 0, 11); // / 0.5 / 0.5
  CHECK_V3(seg_b(P, 4), 0, 0, 12); // x 0.25
  CHECK_NEAR(P->seg[4].r0, 0.1, TOL);
  CHECK_NEAR(P->sphere[0].radius, 0.1, TOL);
  vd_plant_spec_destroy(P);
  CHECK_INT(status_of("@Dd(0)"), VD_ERR_VALUE);
  CHECK_INT(status_of("@D(-1)"), VD_ERR_VALUE);
}

TEST(turtle, tropism_rule) {
  // H horizontal along -Y, T = +Z, elasticity 0.5: each F first turns H halfway toward T
  vd_plant_spec* P;
  REQUIRE(run("@Tp(0,0,1) @Ts(0.5) +(90) F F", &P) == VD_OK);
  double c45 = cos(VD_PI / 4), c675 = cos(3 * VD_PI / 8), s675 = sin(3 * VD_PI / 8);
  CHECK_V3(seg_b(P, 0), 0, -c45, c45);
  CHECK_V3(seg_b(P, 1), 0, -c45 - c675, c45 + s675);
  CHECK_NEAR(vd_dot(P->seg[1].up, vd_sub(seg_b(P, 1), seg_a(P, 1))), 0, TOL);
  vd_plant_spec_destroy(P);
  // full elasticity aligns H with T (normalised); f bends too
  CHECK_V3(end_of("@Tp(2,0,0) @Ts(1) F"), 1, 0, 0);
  REQUIRE(run("@Tp(1,0,0) @Ts(1) f F", &P) == VD_OK);
  CHECK_V3(seg_a(P, 0), 1, 0, 0);
  CHECK_V3(seg_b(P, 0), 2, 0, 0);
  vd_plant_spec_destroy(P);
  // settings from the def; @Ts() turns it off
  vd_turtle_def d = vd_turtle_def_default();
  d.tropism = vd_v3(0, 1, 0);
  d.elasticity = 1;
  REQUIRE(run_def("F @Ts F", &d, &P) == VD_OK);
  CHECK_V3(seg_b(P, 0), 0, 1, 0);
  CHECK_V3(seg_b(P, 1), 0, 2, 0);
  vd_plant_spec_destroy(P);
  CHECK_INT(status_of("@Ts(1.5)"), VD_ERR_VALUE);
}

TEST(turtle, move_pinpoint_lineto) {
  CHECK_V3(end_of("@M(1,2,3) F"), 1, 2, 4);
  CHECK_V3(end_of("F @M(5) F"), 5, 0, 2); // missing coordinates keep their value
  CHECK_V3(end_of("Pinpoint(0,3,4) F"), 0, 0.6, 0.8);
  CHECK_V3(end_of("@M(0,0,1) PinpointRel(1,0,0) F"), 1, 0, 1);
  vd_plant_spec* P;
  // LineTo draws exactly to the point and keeps the orientation; OLineTo keeps the new one
  REQUIRE(run("LineTo(0,3,4) F OLineTo(0,6,9) F", &P) == VD_OK);
  CHECK_V3(seg_a(P, 0), 0, 0, 0);
  CHECK_V3(seg_b(P, 0), 0, 3, 4);
  CHECK_NEAR(vd_dot(P->seg[0].up, vd_v3(0, 0.6, 0.8)), 0, TOL);
  CHECK_V3(seg_b(P, 1), 0, 3, 5);
  CHECK_V3(seg_b(P, 2), 0, 6, 9);
  CHECK_V3(seg_b(P, 3), 0, 6.6, 9.8);
  CHECK_INT(P->seg[1].node0, P->seg[0].node1);
  vd_plant_spec_destroy(P);
  REQUIRE(run("F LineRel(1,0,0, 0.3)", &P) == VD_OK);
  CHECK_V3(seg_b(P, 1), 1, 0, 1);
  CHECK_NEAR(P->seg[1].r1, 0.3, TOL);
  vd_plant_spec_destroy(P);
}

TEST(turtle, nF_chain) {
  vd_plant_spec* P;
  REQUIRE(run("nF(2.5, 1)", &P) == VD_OK);
  REQUIRE(P->nseg == 3);
  CHECK_V3(seg_b(P, 0), 0, 0, 1);
  CHECK_V3(seg_b(P, 2), 0, 0, 2.5);
  CHECK_INT(P->seg[1].node0, P->seg[0].node1);
  CHECK_INT(P->seg[2].instance, 1);
  vd_plant_spec_destroy(P);
  REQUIRE(run("nF(2, 1, 0.3)", &P) == VD_OK); // radius 0.1 -> 0.3 linearly
  REQUIRE(P->nseg == 2);
  CHECK_NEAR(P->seg[0].r0, 0.1, TOL);
  CHECK_NEAR(P->seg[0].r1, 0.2, TOL);
  CHECK_NEAR(P->seg[1].r1, 0.3, TOL);
  vd_plant_spec_destroy(P);
  CHECK_INT(status_of("nF(1, 0)"), VD_ERR_VALUE);
  CHECK_INT(status_of("nF(1e12, 1e-3)"), VD_ERR_LIMIT);
}

TEST(turtle, negative_length) {
  vd_plant_spec* P;
  REQUIRE(run("F(-1) F", &P) == VD_OK);
  CHECK_V3(seg_b(P, 0), 0, 0, -1);
  CHECK_V3(P->seg[0].up, 1, 0, 0);
  CHECK_V3(seg_b(P, 1), 0, 0, 0); // the frame is restored after drawing
  vd_plant_spec_destroy(P);
  CHECK_V3(end_of("f(-2) F"), 0, 0, -1);
}

// ---------------------------------------------------------------------------------------------
// errors and resources

TEST(turtle, errors) {
  CHECK_INT(status_of("F(nan)"), VD_ERR_VALUE);
  CHECK_INT(status_of("F(inf)"), VD_ERR_VALUE);
  CHECK_INT(status_of("+(nan)"), VD_ERR_VALUE);
  CHECK_INT(status_of(";(-1)"), VD_ERR_VALUE);
  CHECK_INT(status_of("SectionResolution(2)"), VD_ERR_VALUE);
  CHECK_INT(status_of("SectionResolution(2000)"), VD_ERR_VALUE);
  CHECK_INT(status_of("@R(0,0,0)"), VD_ERR_VALUE);
  CHECK_INT(status_of("@R(0,0,1, 0,0,2)"), VD_ERR_VALUE);
  CHECK_INT(status_of("F ] F"), VD_ERR_SYNTAX);
  // organ modules are ignored; display-only modules are accepted
  vd_plant_spec* P;
  REQUIRE(run("A B F @L(1) Frame SetGuide(1, 2) ?P InterpolateColors(1,2) F", &P) == VD_OK);
  CHECK_INT(P->nseg, 2);
  CHECK_INT(P->seg[0].module, 2);
  vd_plant_spec_destroy(P);
  // % drops the rest of its branch
  REQUIRE(run("F [ F % F [ F ] F ] F", &P) == VD_OK);
  CHECK_INT(P->nseg, 3);
  vd_plant_spec_destroy(P);
  // the error names the module and its index
  lbuf b = {0};
  ladd(&b, "F F(nan)");
  vd_error e = {0};
  P = vd_plant_spec_create();
  CHECK_INT(vd_turtle_run(NULL, &b.s, NULL, P, &e), VD_ERR_VALUE);
  CHECK_INT(e.status, VD_ERR_VALUE);
  CHECK(strstr(e.msg, "module 1 'F'") != NULL);
  vd_plant_spec_destroy(P);
  lfree(&b);
  // bad settings
  vd_turtle_def d = vd_turtle_def_default();
  d.slices = 2;
  CHECK_INT(run_def("F", &d, &P), VD_ERR_ARG);
  vd_plant_spec_destroy(P);
}

TEST(turtle, out_of_memory) {
  // every failure point returns VD_ERR_NOMEM and leaks nothing; the last budget succeeds
  lbuf b = {0};
  for (int k = 0; k < 40; k++)
    ladd(&b, "F [ +F @O ~l ] { . f . +(90) f . } @B(0.1) [ [ F ] ");
  int64_t* src = vd_malloc((size_t)b.s.n * sizeof *src);
  for (int64_t k = 0; k < b.s.n; k++)
    src[k] = (k * 37) % b.s.n;
  lsrc(&b, src);
  vd_free(src, (size_t)b.s.n * sizeof *src);
  int ok = 0;
  for (int64_t n = 0; n < 2000 && !ok; n++) {
    vd_plant_spec* P = vd_plant_spec_create();
    REQUIRE(P);
    vdt_oom_begin(n);
    vd_status st = vd_turtle_run(NULL, &b.s, NULL, P, NULL);
    vdt_oom_end();
    if (st == VD_OK)
      ok = 1;
    else
      CHECK_INT(st, VD_ERR_NOMEM);
    vd_plant_spec_destroy(P);
  }
  CHECK(ok);
  lfree(&b);
}
