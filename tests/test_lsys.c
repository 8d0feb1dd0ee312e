// SPDX-License-Identifier: MIT
// lsys: parsing of the L-Py file syntax, the Python subset, derivation and matching, checked
// against hand-derived strings.
#include <stdlib.h>

#include "test.h"
#include "verdant/lsys.h"

// derive `src` with the native engine, steps (-1 = file's) and seed; return the formatted string in buf
static vd_status derive_str(const char* src, int steps, uint64_t seed, char* buf, size_t cap, vd_error* e) {
  vd_lsystem* ls;
  buf[0] = 0;
  vd_status st = vd_lsys_parse_engine(src, strlen(src), "t.lpy", VD_LSYS_NATIVE, &ls, e);
  if (st) return st;
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = steps;
  d.seed = seed;
  d.max_ops = 10000000;  // runaway loops in the malformed cases stop fast
  vd_lstring s = vd_lstring_empty();
  st = vd_lsys_derive(ls, &d, &s, e);
  if (!st) vd_lsys_format(ls, &s, buf, cap);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return st;
}

#define CHECK_DERIVE(src, steps, expected)                                                         \
  do {                                                                                             \
    char b_[4096];                                                                                 \
    vd_error e_ = {0};                                                                             \
    CHECK_STATUS(derive_str(src, steps, 0, b_, sizeof b_, &e_), VD_OK, e_);                        \
    CHECK_STR(b_, expected);                                                                       \
  } while (0)

TEST(lsys, algae) {
  CHECK_DERIVE("Axiom: A\nderivation length: 4\nproduction:\nA --> AB\nB --> A\nendlsystem\n", -1, "ABAABABA");
  CHECK_DERIVE("Axiom: A\nproduction:\nA --> AB\nB --> A\n", 5, "ABAABABAABAAB");
}

TEST(lsys, parametric_branching_abop_1_9) {
  // ABOP fig 1.9 style: A(s) --> F(s)[+A(s/R)][-A(s/R)]
  const char* src =
      "R = 2.0\n"
      "Axiom: A(1)\n"
      "derivation length: 2\n"
      "production:\n"
      "A(s) --> F(s)[+A(s/R)][-A(s/R)]\n"
      "endlsystem\n";
  CHECK_DERIVE(src, -1,
               "F(1)[+F(0.5)[+A(0.25)][-A(0.25)]][-F(0.5)[+A(0.25)][-A(0.25)]]");
  // module counts after 11 steps: 2^11 A and 2047 F
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = 11;
  vd_lstring s = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, &d, &s, &e), VD_OK, e);
  int na = 0, nf = 0;
  int A = vd_lsys_symbol_find(ls, "A");
  double minA = 1;
  for (int64_t i = 0; i < s.n; i++) {
    if (s.sym[i] == A) {
      na++;
      if (s.val[s.par[i]] < minA) minA = s.val[s.par[i]];
    }
    if (s.sym[i] == VD_SYM_F) nf++;
  }
  CHECK_INT(na, 2048);
  CHECK_INT(nf, 2047);
  CHECK(minA == 1.0 / 2048);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
}

TEST(lsys, tokenisation_longest_match) {
  // Leaf undeclared is four modules; declared it is one
  CHECK_DERIVE("Axiom: Leaf(1)\n", 0, "Lea" "f(1)");
  CHECK_DERIVE("module Leaf\nAxiom: Leaf(1)\n", 0, "Leaf(1)");
  // predefined multi-character names and ~l
  CHECK_DERIVE("Axiom: @O(1)@Gc~l(2)SetWidth(3)@Di\n", 0, "@O(1)@Gc~l(2)SetWidth(3)@Di");
  // declared names win by length: Ab vs A b
  CHECK_DERIVE("module A, Ab\nAxiom: AbA b\n", 0, "AbAb");
  vd_lsystem* ls;
  vd_error e = {0};
  const char* src = "module A, Ab\nAxiom: AbA b\n";
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  vd_lstring s = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, NULL, &s, &e), VD_OK, e);
  CHECK_INT(s.n, 3);
  CHECK_INT(s.sym[0], vd_lsys_symbol_find(ls, "Ab"));
  CHECK_INT(s.sym[1], vd_lsys_symbol_find(ls, "A"));
  CHECK_INT(s.sym[2], vd_lsys_symbol_find(ls, "b"));
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
}

TEST(lsys, rule_fall_through_and_identity) {
  const char* src =
      "Axiom: A(1)A(2)A(3)B\n"
      "production:\n"
      "A(x) :\n"
      "  if x == 1: produce X\n"
      "A(x) :\n"
      "  if x == 2:\n"
      "    produce Y\n"
      "endlsystem\n";
  // A(1) -> X by the first rule, A(2) falls through to the second, A(3) has no rule that
  // produces: identity; B has no rule: identity
  CHECK_DERIVE(src, 1, "XYA(3)B");
}

TEST(lsys, deletion_and_empty_produce) {
  CHECK_DERIVE("Axiom: ABA\nproduction:\nB -->\n", 1, "AA");
  CHECK_DERIVE("Axiom: ABA\nproduction:\nB :\n  produce\n", 1, "AA");
}

TEST(lsys, python_subset_expressions) {
  const char* src =
      "from math import *\n"
      "import random\n"
      "N = 7\n"
      "def sq(x): return x * x\n"
      "def f(x):\n"
      "  if x > 2:\n"
      "    return x - 1\n"
      "  return 0\n"
      "Axiom: A(N // 2, N % 3, -7 % 3, 2 ** 3 ** 2, -2 ** 2, 7 / 2, 1 < 2 < 3, 3 < 2 < 4)"
      "B(abs(-3), min(4, 2, 9), max(1, 5), int(-2.7), round(2.5), round(3.5), sqrt(16), sq(3), f(5))"
      "C(1 if N > 5 else 2, not 0, 0 or 3, 2 and 0, floor(2.5), math.pi > 3.14, radians(180) == pi)\n";
  CHECK_DERIVE(src, 0,
               "A(3,1,2,512,-4,3.5,1,0)B(3,2,5,-2,2,4,4,9,4)C(1,1,3,0,2,1,1)");
}

TEST(lsys, statements_loops_globals) {
  const char* src =
      "count = 0\n"
      "Axiom:\n"
      "  nproduce A\n"
      "  for i in range(3):\n"
      "    nproduce B(i)\n"
      "  for i in range(10, 4, -3):\n"
      "    if i == 7: continue\n"
      "    nproduce C(i)\n"
      "production:\n"
      "B(i) :\n"
      "  global count\n"
      "  count += 1\n"
      "  k = i * 10\n"
      "  k = k + count\n"
      "  produce B(k)\n"
      "endlsystem\n";
  CHECK_DERIVE(src, 0, "AB(0)B(1)B(2)C(10)");
  CHECK_DERIVE(src, 1, "AB(1)B(12)B(23)C(10)");
}

TEST(lsys, context_axial_tree) {
  // left context skips lateral branches and ignored symbols
  const char* src =
      "Axiom: B A [ + A ] - A C\n"
      "ignore: + -\n"
      "production:\n"
      "B < A --> X\n"
      "A > C --> Y\n"
      "endlsystem\n";
  // A after B -> X; A inside the branch has left context B (the branch's parent is A... no:
  // the module before '[' is the first A, whose name is A, so B < A does not match);
  // the last A: left context skipping '-' and the branch is the first A -> no match for B<A,
  // right context C -> Y
  CHECK_DERIVE(src, 1, "BX[+A]-YC");
  // right context skips a lateral branch; explicit lateral branch in the pattern
  CHECK_DERIVE("Axiom: A[B]C\nproduction:\nA > C --> X\n", 1, "X[B]C");
  CHECK_DERIVE("Axiom: A[B]C\nproduction:\nA > [B]C --> X\n", 1, "X[B]C");
  CHECK_DERIVE("Axiom: A[D]C\nproduction:\nA > [B]C --> X\n", 1, "A[D]C");
  // inside a branch, the left context is the module before the branch
  CHECK_DERIVE("Axiom: A[B][C]\nproduction:\nA < C --> Z\n", 1, "A[B][Z]");
  // a right context stops at the end of the branch
  CHECK_DERIVE("Axiom: [A]B\nproduction:\nA > B --> X\n", 1, "[A]B");
  // signal propagation (acropetal): B travels up the main axis over branches
  const char* sig =
      "Axiom: B A [ A ] A A\n"
      "production:\n"
      "B < A --> B\n"
      "endlsystem\n";
  CHECK_DERIVE(sig, 1, "BB[A]AA");
  CHECK_DERIVE(sig, 2, "BB[B]BA");
}

TEST(lsys, context_consider) {
  CHECK_DERIVE("Axiom: A x y B\nconsider: AB\nproduction:\nA > B --> X\n", 1, "Xx" "yB");
}

TEST(lsys, constants_in_patterns) {
  CHECK_DERIVE("Axiom: A(1)A(2)A(-1)\nproduction:\nA(2) --> B\nA(-1) --> C\n", 1, "A(1)BC");
}

TEST(lsys, multi_module_predecessor) {
  CHECK_DERIVE("Axiom: ABAB\nproduction:\nAB --> C\n", 1, "CC");
}

TEST(lsys, cut) {
  // as in L-Py, % stays in the string until the string is read again (the next step,
  // decomposition or interpretation), which drops it and the rest of its branch
  CHECK_DERIVE("Axiom: A[BC[D]E]F\nproduction:\nC --> %\n", 1, "A[B%[D]E]F");
  CHECK_DERIVE("Axiom: A[BC[D]E]F\nproduction:\nC --> %\n", 2, "A[B]F");
  CHECK_DERIVE("Axiom: AB%CD\nproduction:\nX --> X\n", 1, "AB");
}

TEST(lsys, decomposition_and_depth) {
  const char* src =
      "Axiom: A\n"
      "production:\n"
      "A --> AB\n"
      "decomposition:\n"
      "maximum depth: 3\n"
      "B --> CC\n"
      "C --> D\n"
      "endlsystem\n";
  // step 1: AB -> decompose B -> CC -> DD (depth 2)
  CHECK_DERIVE(src, 1, "ADD");
}

TEST(lsys, interpretation_keeps_string_and_tracks_source) {
  const char* src =
      "Axiom: A(2)B\n"
      "interpretation:\n"
      "maximum depth: 2\n"
      "A(x) --> F(x) G\n"
      "G --> @O(0.5)\n"
      "endlsystem\n";
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  vd_lstring d = vd_lstring_empty(), g = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, NULL, &d, &e), VD_OK, e);
  CHECK_STATUS(vd_lsys_interpret(ls, NULL, &d, &g, &e), VD_OK, e);
  char buf[256] = "";
  CHECK_STR(vd_lsys_format(ls, &d, buf, sizeof buf), "A(2)B");
  buf[0] = 0;
  CHECK_STR(vd_lsys_format(ls, &g, buf, sizeof buf), "F(2)@O(0.5)B");
  REQUIRE(g.src != NULL);
  CHECK_INT(g.src[0], 0);
  CHECK_INT(g.src[1], 0);
  CHECK_INT(g.src[2], 1);
  vd_lstring_free(&d);
  vd_lstring_free(&g);
  vd_lsys_destroy(ls);
}

TEST(lsys, groups) {
  const char* src =
      "def EndEach():\n"
      "  useGroup(1)\n"
      "Axiom: A\n"
      "production:\n"
      "A --> AB\n"
      "group 1:\n"
      "B --> C\n"
      "endgroup\n"
      "endlsystem\n";
  // step 1: group 0 only -> AB; then group 1 active: A->AB (group 0 always), B->C
  CHECK_DERIVE(src, 2, "ABC");
}

TEST(lsys, stochastic_seeds) {
  const char* src =
      "from random import *\n"
      "Axiom: A(0)\n"
      "production:\n"
      "A(x) --> A(random()) B(uniform(1, 2)) C(randint(1, 6)) D(gauss(0, 1))\n";
  char a[1024], b[1024], c[1024];
  vd_error e = {0};
  CHECK_STATUS(derive_str(src, 3, 5, a, sizeof a, &e), VD_OK, e);
  CHECK_STATUS(derive_str(src, 3, 5, b, sizeof b, &e), VD_OK, e);
  CHECK_STATUS(derive_str(src, 3, 6, c, sizeof c, &e), VD_OK, e);
  CHECK_STR(a, b);
  CHECK(strcmp(a, c) != 0);
  // seed(n) inside the file behaves like CPython's random.seed(n)
  CHECK_DERIVE("import random\nrandom.seed(42)\nAxiom: A(random.random())\n", 0, "A(0.6394267984578837)");
}

TEST(lsys, set_global_override) {
  const char* src = "R = 2\nS = R * 10\nAxiom: A(R, S)\n";
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  CHECK_STATUS(vd_lsys_set_global(ls, "R", "3", &e), VD_OK, e);
  vd_lstring s = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, NULL, &s, &e), VD_OK, e);
  char buf[128] = "";
  CHECK_STR(vd_lsys_format(ls, &s, buf, sizeof buf), "A(3,30)");
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_set_global(ls, "nope", "1", &e2), VD_ERR_NAME, e2);
  vd_error e3 = {0};
  CHECK_STATUS(vd_lsys_set_global(ls, "R", "1 +", &e3), VD_ERR_SYNTAX, e3);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
}

TEST(lsys, initialisation_scalars_and_labels) {
  const char* src =
      "LABELS = {1: 'stem', 2: \"leaf\"}\n"
      "Axiom: A(tropism, n)\n"
      "###### INITIALISATION ######\n"
      "__lpy_code_version__ = 1.1\n"
      "def __initialiseContext__(context):\n"
      "\tscalars = [('tropism', 'Float', 0.25, 0.0, 1.0, 2), ('n', 'Integer', 8, 0, 20)]\n"
      "\tcontext[\"__scalars__\"] = scalars\n";
  CHECK_DERIVE(src, 0, "A(0.25,8)");
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_label_count(ls), 2);
  int id;
  const char* name;
  vd_lsys_label_get(ls, 1, &id, &name);
  CHECK_INT(id, 2);
  CHECK_STR(name, "leaf");
  vd_lsys_destroy(ls);
}

TEST(lsys, derivation_length_expression_and_stop) {
  CHECK_DERIVE("N = 2\nAxiom: A\nderivation length: N + 1\nproduction:\nA --> AA\n", -1, "AAAAAAAA");
  CHECK_DERIVE("def EndEach():\n  if getIterationNb() == 1: Stop()\nAxiom: A\nproduction:\nA --> AA\n", 5, "AAAA");
}

TEST(lsys, limit_max_modules) {
  const char* src = "Axiom: A\nproduction:\nA --> AA\n";
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = 30;
  d.max_modules = 1000;
  vd_lstring s = vd_lstring_empty();
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_derive(ls, &d, &s, &e2), VD_ERR_LIMIT, e2);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
}

// ---------------------------------------------------------------------------------------------
// malformed inputs: status code and reported line

typedef struct bad_case {
  const char* src;
  vd_status status;
  int line;
} bad_case;

static const bad_case bad_cases[] = {
    {"Axiom: A(\n", VD_ERR_SYNTAX, 1},                                   // unclosed bracket
    {"# only a comment\n\n", VD_ERR_SYNTAX, 1},                          // nothing in the file
    {"Axiom: A\nproduction:\nA -> B\n", VD_ERR_SYNTAX, 3},               // wrong arrow
    {"Axiom: A\nproduction:\nA(x) :\nproduce B\n", VD_ERR_SYNTAX, 3},    // body not indented
    {"Axiom: A\nproduction:\nA :\n  if x\n    produce B\n", VD_ERR_SYNTAX, 4},  // missing ':'
    {"import numpy\nAxiom: A\n", VD_ERR_UNSUPPORTED, 1},                 // unsupported import
    {"class X:\n  pass\nAxiom: A\n", VD_ERR_UNSUPPORTED, 1},             // class
    {"x = [1, 2]\nAxiom: A\n", VD_ERR_UNSUPPORTED, 1},                   // list literal
    {"x = lambda y: y\nAxiom: A\n", VD_ERR_UNSUPPORTED, 1},              // lambda
    {"Axiom: A(undefined_name)\n", VD_ERR_NAME, 1},                      // runtime NameError
    {"Axiom: A(1 / 0)\n", VD_ERR_VALUE, 1},                              // division by zero
    {"Axiom: A\nproduction:\nA :\n  assert 1 == 2\n", VD_ERR_ASSERT, 4}, // assert
    {"Axiom: A\nproduction:\nA(x) --> B(x +)\n", VD_ERR_SYNTAX, 3},      // bad expression
    {"Axiom: A\nproduction:\nA(*p) --> B\n", VD_ERR_UNSUPPORTED, 3},     // *args pattern
    {"Axiom: A\nproduction:\nx(A(y)) < B --> C\n", VD_ERR_UNSUPPORTED, 3},  // list binding
    {"x = 1\n  y = 2\nAxiom: A\n", VD_ERR_SYNTAX, 2},                    // bad indentation
    {"Axiom: A\nderivation length: 'x'\n", VD_ERR_VALUE, 2},             // bad derivation length
    {"Axiom: A\ndecomposition:\nmaximum depth: 0\n", VD_ERR_VALUE, 3},   // bad maximum depth
    {"Axiom: B\nproduction:\nB --> C(\"a\" - 1)\n", VD_ERR_TYPE, 3},    // str minus int
    {"def f(x): return f(x)\nAxiom: A(f(1))\n", VD_ERR_LIMIT, 1},        // runaway recursion
    {"x = 1\nx.y = 2\nAxiom: A\n", VD_ERR_SYNTAX, 2},                    // attribute assignment
    {"Axiom: A('abc' * 2)\n", VD_ERR_TYPE, 1},                           // type error
    {"Axiom: A\nproduction:\nA :\n  while True:\n    pass\n", VD_ERR_LIMIT, 4},  // endless loop
    {"Axiom: A\nproduction:\nA :\n  else:\n    produce B\n", VD_ERR_SYNTAX, 4},  // else without if
    {"Axiom: A\nproduce B\n", VD_ERR_SYNTAX, 2},                         // produce outside a rule
    {"Axiom: A$\x01\n", VD_ERR_SYNTAX, 1},                               // control character
    {"LABELS = {'a': 1}\nAxiom: A\n", VD_ERR_VALUE, 1},                  // bad LABELS
    {"Axiom: A\nproduction:\nA :\n  for i in [1,2]:\n    produce B\n", VD_ERR_UNSUPPORTED, 4},
    {"Axiom: A(sqrt(-1))\n", VD_ERR_VALUE, 1},                           // math domain
    {"Axiom: A\nproduction:\nA(x) --> B(y)\n", VD_OK, 0},                // A has no parameter: no match
};

TEST(lsys, malformed_inputs) {
  int n = (int)(sizeof bad_cases / sizeof bad_cases[0]);
  int checked = 0;
  for (int i = 0; i < n; i++) {
    const bad_case* c = &bad_cases[i];
    char buf[512];
    vd_error e = {0};
    vd_status st = derive_str(c->src, strstr(c->src, "derivation length") ? -1 : 1, 0, buf, sizeof buf, &e);
    if (st != c->status || (c->line && e.line != c->line)) {
      char eb[700];
      vdt_fail(__FILE__, __LINE__, "case %d: status %s line %d, expected %s line %d (%s)", i, vd_status_str(st),
               e.line, vd_status_str(c->status), c->line, vd_error_format(&e, eb, sizeof eb));
    }
    if (st != VD_OK) CHECK(e.msg[0] != 0);
    if (c->line) CHECK(e.col > 0);
    checked++;
  }
  CHECK(checked >= 25);
}

TEST(lsys, binary_and_empty_input) {
  vd_lsystem* ls = NULL;
  vd_error e = {0};
  const char bin[] = "Axiom: A\0\x01\x02";
  CHECK_STATUS(vd_lsys_parse(bin, sizeof bin, "b", &ls, &e), VD_ERR_SYNTAX, e);
  CHECK(ls == NULL);
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_parse_engine("", 0, "empty", VD_LSYS_NATIVE, &ls, &e2), VD_ERR_SYNTAX, e2);
  vd_error e3 = {0};
  CHECK_STATUS(vd_lsys_load("/nonexistent.lpy", &ls, &e3), VD_ERR_IO, e3);
}

// ---------------------------------------------------------------------------------------------
// grow: derivation + interpretation + turtle, labels and instances end to end

static vd_status grow_str(const char* src, vd_plant_spec** out, vd_error* e) {
  vd_lsystem* ls;
  *out = NULL;
  vd_status st = vd_lsys_parse(src, strlen(src), "g.lpy", &ls, e);
  if (st) return st;
  vd_plant_spec* p = vd_plant_spec_create();
  st = vd_lsys_grow(ls, NULL, NULL, p, e);
  vd_lsys_destroy(ls);
  if (st) {
    vd_plant_spec_destroy(p);
    return st;
  }
  *out = p;
  return VD_OK;
}

TEST(lsys, grow_labels_and_instances) {
  const char* src =
      "LABELS = {1: 'stem', 2: 'leaf', 3: 'fruit'}\n"
      "module I, Leaf, Fruit\n"
      "Axiom: SetWidth(0.005) A(3)\n"
      "derivation length: 4\n"
      "production:\n"
      "A(n) :\n"
      "    if n > 0: produce I(0.05) [ +(50) Leaf(0.06) ] /(137.5) A(n - 1)\n"
      "    else: produce Fruit(0.012)\n"
      "interpretation:\n"
      "I(l) --> ;(1) F(l, 0.004)\n"
      "Leaf(s) --> ;(2) ~l(s) ~l(s * 0.5)\n"
      "Fruit(r) --> ;(3) @O(r)\n"
      "endlsystem\n";
  vd_plant_spec* p;
  vd_error e = {0};
  CHECK_STATUS(grow_str(src, &p, &e), VD_OK, e);
  REQUIRE(p);
  CHECK_INT(p->nseg, 3);
  CHECK_INT(p->nmesh, 6);
  CHECK_INT(p->nsphere, 1);
  // 3 internodes + 3 leaves (two surfaces each, one module) + 1 fruit
  CHECK_INT(p->ninstance, 7);
  CHECK_INT(p->mesh[0].instance, p->mesh[1].instance);
  CHECK(p->mesh[2].instance != p->mesh[1].instance);
  CHECK_INT(p->sphere[0].label, 3);
  CHECK_STR(vd_plant_find_label(p, 3)->name, "fruit");
  CHECK_INT(vd_plant_find_label(p, 3)->organ, VD_ORGAN_FRUIT);
  // the stem: 3 segments of 0.05 m stacked on +Z, sharing nodes
  CHECK_NEAR(p->node[p->seg[2].node1].z, 0.15, 1e-12);
  CHECK_INT(p->seg[1].node0, p->seg[0].node1);
  CHECK_INT(p->seg[1].parent, 0);
  CHECK_NEAR(p->seg[0].r0, 0.005, 1e-15);
  CHECK_NEAR(p->seg[0].r1, 0.004, 1e-15);
  // the fruit sits at the stem's tip
  CHECK_NEAR(p->sphere[0].center.z, 0.15, 1e-12);
  vd_plant_spec_destroy(p);
}

TEST(lsys, grow_explicit_label_argument) {
  // seed 003 style: the label travels as the last parameter
  const char* src =
      "module I\n"
      "Axiom: I(0.1, 0.01, 8) F(0.1, 0.01, 9)\n"
      "interpretation:\n"
      "I(h, r, lab) --> F(h, r, lab)\n"
      "endlsystem\n";
  vd_plant_spec* p;
  vd_error e = {0};
  CHECK_STATUS(grow_str(src, &p, &e), VD_OK, e);
  REQUIRE(p && p->nseg == 2);
  CHECK_INT(p->seg[0].label, 8);
  CHECK_INT(p->seg[1].label, 9);
  CHECK_STR(vd_plant_find_label(p, 8)->name, "label_8");
  vd_plant_spec_destroy(p);
}

TEST(lsys, grow_unknown_surface_rejected) {
  vd_plant_spec* p;
  vd_error e = {0};
  CHECK_STATUS(grow_str("Axiom: ~q(1)\n", &p, &e), VD_ERR_UNSUPPORTED, e);
  CHECK(p == NULL);
}

TEST(lsys, grow_same_seed_same_plant) {
  const char* src =
      "from random import *\n"
      "Axiom: A(1)\n"
      "derivation length: 6\n"
      "production:\n"
      "A(s) --> F(s * uniform(0.5, 1)) [ +(uniform(10, 60)) A(s * 0.7) ] /(gauss(137, 10)) A(s * 0.8)\n";
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "s", &ls, &e), VD_OK, e);
  vd_plant_spec *a = vd_plant_spec_create(), *b = vd_plant_spec_create(), *c = vd_plant_spec_create();
  vd_lsys_def d = vd_lsys_def_default();
  d.seed = 11;
  CHECK_STATUS(vd_lsys_grow(ls, &d, NULL, a, &e), VD_OK, e);
  CHECK_STATUS(vd_lsys_grow(ls, &d, NULL, b, &e), VD_OK, e);
  d.seed = 12;
  CHECK_STATUS(vd_lsys_grow(ls, &d, NULL, c, &e), VD_OK, e);
  REQUIRE(a->nnode == b->nnode && a->nnode > 10);
  CHECK(memcmp(a->node, b->node, sizeof(vd_vec3) * (size_t)a->nnode) == 0);
  CHECK(c->nnode != a->nnode || memcmp(a->node, c->node, sizeof(vd_vec3) * (size_t)a->nnode) != 0);
  vd_plant_spec_destroy(a);
  vd_plant_spec_destroy(b);
  vd_plant_spec_destroy(c);
  vd_lsys_destroy(ls);
}

TEST(lsys, lstring_lines_do_not_join_on_brackets) {
  // an nproduce line may open a branch that a later line closes (L-Py accepts it)
  const char* src =
      "module A, B\n"
      "Axiom: A\n"
      "production:\n"
      "A :\n"
      "    nproduce [\n"
      "    t = 2\n"
      "    nproduce B(t) ]\n"
      "    produce B\n"
      "endlsystem\n";
  CHECK_DERIVE(src, 1, "[B(2)]B");
  // a trailing backslash in an L-string is RollR, not a line continuation
  CHECK_DERIVE("Axiom: F \\\nproduction:\nF --> F \\\n", 1, "F\\\\");
  // an axiom line with an unclosed branch stays one line
  CHECK_DERIVE("Axiom: A [ B\nproduction:\nB --> C\n", 1, "A[C");
  // parentheses still join lines (Python's implicit continuation)
  CHECK_DERIVE("Axiom: A(1,\n  2)\n", 0, "A(1,2)");
}
