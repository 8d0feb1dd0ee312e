// SPDX-License-Identifier: MIT
// lpy: compatibility with L-Py's semantics (openalea/lpy): results that used to be silently
// wrong, the grammar beyond the basics (contexts, patterns, hooks, the L-string object) and the
// refusals of what the native engine does not run. Every L-Py text here is our own.
#include <stdlib.h>

#include "test.h"
#include "verdant/lsys.h"

// parse with an engine and derive src (steps -1 = the file's), format the result into buf
static vd_status derive_engine(const char* src, vd_lsys_engine engine, int steps, char* buf, size_t cap,
                               vd_error* e) {
  vd_lsystem* ls;
  buf[0] = 0;
  vd_status st = vd_lsys_parse_engine(src, strlen(src), "t.lpy", engine, &ls, e);
  if (st) return st;
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = steps;
  d.max_ops = 10000000;
  vd_lstring s = vd_lstring_empty();
  st = vd_lsys_derive(ls, &d, &s, e);
  if (!st) vd_lsys_format(ls, &s, buf, cap);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return st;
}

// the same with the native engine
static vd_status derive_text(const char* src, int steps, char* buf, size_t cap, vd_error* e) {
  return derive_engine(src, VD_LSYS_NATIVE, steps, buf, cap, e);
}

#define DERIVES(src, steps, expected)                                                              \
  do {                                                                                             \
    char b_[4096];                                                                                 \
    vd_error e_ = {0};                                                                             \
    CHECK_STATUS(derive_text(src, steps, b_, sizeof b_, &e_), VD_OK, e_);                          \
    CHECK_STR(b_, expected);                                                                       \
  } while (0)

#define PY_DERIVES(src, steps, expected)                                                           \
  do {                                                                                             \
    char b_[4096];                                                                                 \
    vd_error e_ = {0};                                                                             \
    CHECK_STATUS(derive_engine(src, VD_LSYS_PYTHON, steps, b_, sizeof b_, &e_), VD_OK, e_);        \
    CHECK_STR(b_, expected);                                                                       \
  } while (0)

// the status of parsing and deriving src; the message is left in *e
static vd_status run_status(const char* src, vd_error* e) {
  char b[256];
  memset(e, 0, sizeof *e);
  return derive_text(src, -1, b, sizeof b, e);
}

#define REFUSED(src, what)                                                                         \
  do {                                                                                             \
    vd_error e_;                                                                                   \
    CHECK_STATUS(run_status(src, &e_), VD_ERR_UNSUPPORTED, e_);                                    \
    if (!strstr(e_.msg, what)) vdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e_.msg, what); \
  } while (0)

TEST(lpy, star_successor_deletes) {
  // `--> *` and `produce *` delete the module as in L-Py (a successor that starts with `*`
  // produces nothing); before, a literal `*` module was left in the string
  DERIVES("Axiom: A B A\nproduction:\nB --> *\n", 1, "AA");
  DERIVES("Axiom: A(1) A(2) A(3)\nproduction:\nA(x) :\n  if x == 2: produce *\n  else: produce B(x)\n",
          1, "B(1)B(3)");
  DERIVES("Axiom: A\nproduction:\nA --> * B\n", 1, "");
  REFUSED("Axiom: A\nproduction:\nA --> B *\n", "'*' module inside a successor");
}

TEST(lpy, predefined_long_names) {
  // L-Py's long names are the same modules as the short ones: Left(30) is +(30), not the five
  // modules L e f t(30) (the last one a hidden move)
  DERIVES("Axiom: Left(30) Right RollL(2) SetHead(0,0,1,1,0,0) Sphere(1) StartGC EndGC BP PP EP IncColor "
          "DecColor(2) MoveTo(1,2,3) Label('x') IncWidth DecWidth SB EB\n",
          0, "+(30)-/(2)@R(0,0,1,1,0,0)@O(1)@Gc@Ge{.};,(2)@M(1,2,3)@L('x')_![]");
  // a rule written with the short name matches modules written with the long one, and back
  DERIVES("Axiom: Left(30) +(10)\nproduction:\n+(a) --> Right(a)\n", 1, "-(30)-(10)");
  DERIVES("Axiom: Tropism(0,0,1) @Ts(0.5) Elasticity(0.2)\nproduction:\nElasticity(e) --> @Ts(e * 2)\n", 1,
          "@Tp(0,0,1)@Ts(1)@Ts(0.4)");
  vd_lsystem* ls;
  vd_error e = {0};
  const char* src = "Axiom: Sphere\n";
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t", &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_symbol_find(ls, "Sphere"), VD_SYM_SPHERE);
  CHECK_INT(vd_lsys_symbol_find(ls, "GetPos"), VD_SYM_GETPOS);
  CHECK_INT(vd_lsys_symbol_find(ls, "surface"), VD_SYM_SURFACE_NAMED);
  vd_lsys_destroy(ls);
}

TEST(lpy, new_left_context) {
  // `<<` reads the string already written by the forward pass: the first A follows the Y that
  // X just became, the second follows Z
  DERIVES("Axiom: X A A\nproduction:\nY << A --> Z\nA --> Y\nX --> Y\n", 1, "YZY");
  // a left context `<` reads the old string instead
  DERIVES("Axiom: X A A\nproduction:\nY < A --> Z\nA --> Y\nX --> Y\n", 1, "YYY");
}

TEST(lpy, backward_and_new_right_context) {
  // backward(): right to left; `>>` reads what the pass has already written to the right
  const char* src =
      "def Start():\n  backward()\n"
      "Axiom: A A X\nproduction:\nA >> Z --> Z\nA --> B\nX --> Z\n";
  DERIVES(src, 1, "ZZZ");
  // forward, a rule with `>>` does not apply (L-Py)
  DERIVES("Axiom: A A X\nproduction:\nA >> Z --> Z\nA --> B\nX --> Z\n", 1, "BBZ");
  // backward() at the top level, multi-module predecessors read right to left
  DERIVES("backward()\nAxiom: A B A B\nproduction:\nA B --> C\n", 1, "CC");
  // isForward() follows the direction
  DERIVES("def Start():\n  backward()\nAxiom: A\nproduction:\nA :\n  produce B(isForward())\n", 1, "B(0)");
}

TEST(lpy, any_module_patterns) {
  DERIVES("Axiom: A B(1) C\nproduction:\n* < B(x) --> D(x)\n", 1, "AD(1)C");
  DERIVES("Axiom: A B\nproduction:\n* --> C\n", 1, "CC");
  // *(name, x): the module name and its parameters
  DERIVES("Axiom: B(2) C\nproduction:\n*(n, x) --> E(n, x)\n", 1, "E('B',2)C");
  // a `*` rule is tried in file order among the others
  DERIVES("Axiom: A B\nproduction:\nA --> X\n* --> Y\nB --> Z\n", 1, "XY");
}

TEST(lpy, brackets_in_patterns) {
  // a bracket in a strict predecessor matches itself
  DERIVES("Axiom: A[B]C\nproduction:\nA [ --> D [\n", 1, "D[B]C");
  // `[` in a left context is the module just before (the branch start), then up the tree
  DERIVES("Axiom: X [ Y ] Z\nproduction:\nX [ < Y --> W\n", 1, "X[W]Z");
  DERIVES("Axiom: X Y [ Z ]\nproduction:\nX [ < Z --> W\n", 1, "XY[Z]");
  // `]` skips the rest of the branch the pattern opened; `=]` wants it at once
  DERIVES("Axiom: A [ B C ] E\nproduction:\nA > [ B ] E --> X\n", 1, "X[BC]E");
  DERIVES("Axiom: A [ B C ] E\nproduction:\nA > [ B =] E --> X\n", 1, "A[BC]E");
}

TEST(lpy, repetition_and_alternatives) {
  DERIVES("Axiom: I I I A\nproduction:\nx(I) < A --> B\n", 1, "IIIB");
  DERIVES("Axiom: I I I A\nproduction:\nx(I, 4) < A --> B\n", 1, "IIIA");
  DERIVES("Axiom: I I I A\nproduction:\nx(I, 1, 3) < A --> B\n", 1, "IIIB");
  DERIVES("Axiom: C A D A E A\nproduction:\nor(C, D) < A --> B\n", 1, "CBDBEA");
  // the variables of the alternatives that did not match are None
  DERIVES("Axiom: C(1) A D(2) A\nproduction:\nor(C(x), D(y)) < A :\n  if x == None: produce B(y)\n"
          "  else: produce E(x)\n",
          1, "C(1)E(1)D(2)B(2)");
  DERIVES("Axiom: A C A\nproduction:\nA > or(C, None) --> B\n", 1, "BCB");
}

TEST(lpy, filters_per_rule_and_group_order) {
  // each rule reads its contexts with the consider/ignore written last before it
  DERIVES("Axiom: A + B - C\nproduction:\nignore: +\nA > B --> X\nignore: -\nB > C --> Y\n", 1, "X+Y-C");
  // with a group active its rules come before those of group 0 (L-Py), not in file order
  DERIVES("def Start():\n  useGroup(1)\nAxiom: A\nproduction:\nA --> B\ngroup 1:\nA --> C\nendgroup\n", 1, "C");
  DERIVES("Axiom: A\nproduction:\nA --> B\ngroup 1:\nA --> C\nendgroup\n", 1, "B");
}

TEST(lpy, early_return_and_stop) {
  // "Early return when no matching" (L-Py's default): a step where no rule applies ends the
  // derivation, and End() is not called
  const char* src =
      "def End():\n  assert False\n"
      "Axiom: A\nderivation length: 3\nproduction:\nB --> C\n";
  vd_error e;
  CHECK_STATUS(run_status(src, &e), VD_OK, e);
  char with_option[512];
  snprintf(with_option, sizeof with_option,
           "%s###### INITIALISATION ######\ndef __initialiseContext__(context):\n"
           "\tcontext.options.setSelection('Early return when no matching',0)\n",
           src);
  CHECK_STATUS(run_status(with_option, &e), VD_ERR_ASSERT, e);
  // Stop() ends after the step, without End()
  CHECK_STATUS(run_status("def End():\n  assert False\nAxiom: A(0)\nderivation length: 5\nproduction:\n"
                          "A(x) :\n  if x == 1: Stop()\n  produce A(x + 1)\n",
                          &e),
               VD_OK, e);
  DERIVES("Axiom: A(0)\nderivation length: 5\nproduction:\nA(x) :\n  if x == 1: Stop()\n  produce A(x + 1)\n", -1,
          "A(2)");
  // no rule at all: the axiom, and no hook runs
  CHECK_STATUS(run_status("def Start():\n  assert False\nAxiom: A\n", &e), VD_OK, e);
}

TEST(lpy, decomposition_recursive_and_depth_expression) {
  // decomposition rewrites each production again on its own, up to `maximum depth` (an
  // expression)
  DERIVES("N = 3\nAxiom: A(0)\nproduction:\nX --> X\ndecomposition:\nmaximum depth: N\nA(x) --> B(x) A(x + 1)\n", 1,
          "B(0)B(1)B(2)A(3)");
  // contexts inside the recursion see only the production being rewritten
  DERIVES("Axiom: C A\nproduction:\nX --> X\ndecomposition:\nmaximum depth: 2\nA --> D E\nC < E --> F\nD < E --> G\n", 1,
          "CDG");
}

TEST(lpy, string_matching_option) {
  const char* trailer =
      "###### INITIALISATION ######\ndef __initialiseContext__(context):\n"
      "\tcontext.options.setSelection('String matching',%d)\n";
  char src[512], t[256];
  // as an axial tree (default) the left context of C is A; as a string it is ']'
  snprintf(t, sizeof t, trailer, 1);
  snprintf(src, sizeof src, "Axiom: A [ B ] C\nproduction:\nA < C --> D\n%s", t);
  DERIVES(src, 1, "A[B]D");
  snprintf(t, sizeof t, trailer, 0);
  snprintf(src, sizeof src, "Axiom: A [ B ] C\nproduction:\nA < C --> D\n] < C --> E\n%s", t);
  DERIVES(src, 1, "A[B]E");
  // multiscale matching is refused, never silently ignored
  snprintf(t, sizeof t, trailer, 3);
  snprintf(src, sizeof src, "module U : scale = 1\nAxiom: U\nproduction:\nU --> U\n%s", t);
  REFUSED(src, "String matching");
}

TEST(lpy, refusals_name_the_construct) {
  REFUSED("Axiom: A\nproduction:\n$A(a) --> B\n", "'$' pattern module");
  REFUSED("Axiom: A\nproduction:\nA > ?I(it) --> B\n", "'?I' pattern module");
  REFUSED("Axiom: A\nproduction:\nA(*p) --> B\n", "'*args' pattern parameter");
  REFUSED("Axiom: A\nproduction:\nA(**p) --> B\n", "'**kwds' pattern parameter");
  REFUSED("Axiom: A\nproduction:\n*(n in 'AB') --> B\n", "'in' operator");  // native: the Python engine takes it
  REFUSED("Axiom: A\nproduction:\nx(A) --> B\n", "x(...) or or(...) in a strict predecessor");
  REFUSED("@decorate\ndef f(): pass\nAxiom: A\n", "decorator");
}

TEST(lpy, conditions_on_pattern_parameters) {
  // L-Py's value constraints: a parameter written `x > 1` matches when the condition holds on it
  const char* src = "Axiom: A(1) B(2) A(3) B(4)\nproduction:\nA(x) < B(y > 2) --> Y(x, y)\n"
                    "A(x == 1) > B(y) --> X(y)\n";
  DERIVES(src, 1, "X(2)B(2)A(3)Y(3,4)");
  PY_DERIVES(src, 1, "X(2)B(2)A(3)Y(3,4)");
  // on the name of `*(...)` and any parameter; `in` is Python (the Python engine)
  PY_DERIVES("Axiom: A(1) B(2) S(3) U(4)\nproduction:\n*(n in 'SU', x) --> X(x)\nB(x > 1) --> Y(x)\n", 1,
             "A(1)Y(2)X(3)X(4)");
  // in a repetition (its variables bind lists: the Python engine): only the modules that pass count
  PY_DERIVES("Axiom: I(1) I(2) I(0) A\nproduction:\nx(I(l > 0), 2) < A --> B\n", 1, "I(1)I(2)I(0)A");
  PY_DERIVES("Axiom: I(0) I(1) I(2) A\nproduction:\nx(I(l > 0), 2) < A --> B\n", 1, "I(0)I(1)I(2)B");
  // a condition that fails to evaluate is an error with its line, not a silent mismatch
  vd_error e;
  CHECK_STATUS(run_status("Axiom: A(1)\nproduction:\nA(x > zz) --> B\n", &e), VD_ERR_NAME, e);
  CHECK(e.line == 3);
}

TEST(lpy, in_left_and_right_context) {
  // InLeftContext / InRightContext in a rule's body read on from where the rule's contexts
  // ended, bind the pattern's variables into the dict, and move on when they match
  const char* src = "Axiom: C B B B A(2) D E(5)\nproduction:\nA(x) :\n  n = 0\n  while InLeftContext(B): n += 1\n"
                    "  p = {}\n  if InRightContext(D E(y), p): produce X(n, p['y'])\n";
  PY_DERIVES(src, 1, "CBBBX(3,5)DE(5)");
  // after the rule's own left context; the string form, a failed match leaves the dict alone
  PY_DERIVES("Axiom: B B B A(2) D\nproduction:\nB < A(x) :\n  n = 0\n  while inLeftContext('B'): n += 1\n"
             "  p = {}\n  assert not inRightContext('E(y)', p) and p == {}\n  produce X(n)\n",
             1, "BBBX(2)D");
  // "As String" matching: each InRightContext goes on after the module it matched (it matched
  // the same B for ever), after the rule's own right context too; options.find() reads the option
  const char* str = "Axiom: A B B B A B B\nproduction:\nA > B:\n  n, m = 1, 0\n"
                    "  while InRightContext(B): n += 1\n  while InLeftContext(B): m += 1\n"
                    "  assert context().options.find('String matching').currentValue() == 'As String'\n"
                    "  produce X(n, m)\n"
                    "###### INITIALISATION ######\ndef __initialiseContext__(context):\n"
                    "\tcontext.options.setSelection('String matching', 0)\n";
  PY_DERIVES(str, 1, "X(3,0)BBBX(2,3)BB");
}

TEST(lpy, scene_argument_of_the_hooks) {
  // EndEach(lstring, scene) / End(lstring, scene): the string interpreted and drawn, one shape per
  // primitive, its id the module that drew it (L-Py's shape ids); (lstring, scene) or the scene
  // returned keep the string
  PY_DERIVES("def EndEach(lstring, scene):\n  assert len(scene) == 3, len(scene)\n"
             "  assert sorted(scene.todict().keys()) == [0, 2] and len(scene.todict()[2]) == 2\n"
             "  return lstring, scene\n"
             "def End(lstring, scene):\n  return scene\n"
             "Axiom: A\nproduction:\nA --> B [ C ]\ninterpretation:\nB --> F\nC --> F @O(0.1)\n",
             1, "B[C]");
  // a hook that returns nothing keeps what it changed in place (L-Py hands it the string itself)
  PY_DERIVES("def EndEach(lstring):\n  lstring[0][0] = 2\nAxiom: A(1)\nproduction:\nA(x) --> A(x)\n", 1, "A(2)");
}

TEST(lpy, vector_query_modules_python_engine) {
  // ?P without parameters gets a Vector3 appended, ?F the four vectors of the frame (position,
  // heading, up, left), as L-Py's turtle fills them (the native engine has no vectors: refused)
  const char* src = "Axiom: F(2) ?P ?F\nderivation length: 2\nproduction:\n"
                    "?P(v) > ?F(p, h, u, l) :\n  assert v == p and abs(v.z - 2) < 1e-12 and abs(h.z - 1) < 1e-12\n"
                    "  assert abs(u.x - 1) < 1e-12 and abs(l.y + 1) < 1e-12\n  produce ?P(v) X\n";
  char b[256];
  vd_error e = {0};
  CHECK_STATUS(derive_engine(src, VD_LSYS_PYTHON, -1, b, sizeof b, &e), VD_OK, e);
  CHECK(strncmp(b, "F(2)?P(Vector3(0,0,2))X?F(", 26) == 0);
  REFUSED(src, "?P without parameters");
}

TEST(lpy, discard_new_string) {
  // DiscardNewString() (L-Py's __lpyfuture__) drops the result of the step it is called in
  const char* src =
      "from openalea.lpy.__lpyfuture__ import *\n"
      "Axiom: A\nderivation length: 3\nproduction:\nA :\n  if getIterationNb() == 1: DiscardNewString()\n"
      "  produce A B\n";
  DERIVES(src, -1, "ABB");
  // the same in the Python engine, whose __lpyfuture__ provides the EndEach that discards
  PY_DERIVES(src, -1, "ABB");
  // importlib.reload of it (L-Py's own tests do) gives the run's module back
  PY_DERIVES("import importlib\nimport openalea.lpy.__lpyfuture__\nimportlib.reload(openalea.lpy.__lpyfuture__)\n"
             "from openalea.lpy.__lpyfuture__ import *\n"
             "Axiom: A\nderivation length: 3\nproduction:\nA :\n  if getIterationNb() == 1: DiscardNewString()\n"
             "  produce A B\n",
             -1, "ABB");
}

TEST(lpy, query_modules_filled_before_each_step) {
  // the turtle fills ?P before the step (L-Py's environmental programs)
  DERIVES("Axiom: ?P(0,0,0) F(2) ?P(0,0,0) +(90) F(1) ?P(0,0,0)\nproduction:\n?P(x, y, z) --> B(x, y, z)\n", 1,
          "B(0,0,0)F(2)B(0,0,2)+(90)F(1)B(0,-1,2)");
  // a model that prunes what grows above z = 3 stops; unfilled, it grew without bound
  DERIVES("Axiom: A ?P(0,0,0)\nderivation length: 6\nproduction:\nA ?P(x, y, z) :\n  if z > 3: produce\n"
          "  produce F(1) A ?P(0,0,0)\n",
          -1, "F(1)F(1)F(1)F(1)");
  // a module an interpretation rule rewrites keeps its values (L-Py fills the rewritten copy)
  DERIVES("Axiom: F(1) ?H(0,0,0) ?U(0,0,0) ?L(0,0,0) ?R(0,0,0) ?P(7,7,7)\nproduction:\n"
          "?H(a,b,c) ?U(d,e,f) ?L(g,h,i) ?R(j,k,l) ?P(x,y,z) --> H(a,b,c) U(d,e,f) L(g,h,i) R(j,k,l) P(x,y,z)\n"
          "interpretation:\n?P(x,y,z) --> ?P(x,y,z)\n",
          1, "F(1)H(0,0,1)U(1,0,0)L(0,-1,0)R(0,1,0)P(7,7,7)");
  REFUSED("Axiom: ?P\nproduction:\n?P --> A\n", "?P without parameters");
  REFUSED("Axiom: ?F(0,0,0,0)\nproduction:\n?F(p,h,u,l) --> A\n", "?F");
}

TEST(lpy, start_end_interpretation_produce) {
  // what StartInterpretation / EndInterpretation produce is drawn before / after the string
  const char* src =
      "def StartInterpretation():\n  produce @O(0.2) +(90)\n"
      "def EndInterpretation():\n  nproduce @O(0.3)\n"
      "Axiom: F(1)\n";
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "t.lpy", &ls, &e), VD_OK, e);
  vd_plant_spec* P = vd_plant_spec_create();
  CHECK_STATUS(vd_lsys_grow(ls, NULL, NULL, P, &e), VD_OK, e);
  CHECK_INT(P->nsphere, 2);
  CHECK_INT(P->nseg, 1);
  if (P->nseg == 1) {
    vd_vec3 b = P->node[P->seg[0].node1];
    CHECK_NEAR(b.y, -1, 1e-12);
    CHECK_NEAR(b.z, 0, 1e-12);
  }
  vd_plant_spec_destroy(P);
  vd_lsys_destroy(ls);
}

TEST(lpy, nproduce_in_a_def) {
  // nproduce in a helper adds to the production of the rule that calls it; produce in a def
  // adds and returns from the def
  DERIVES("def two(x):\n  nproduce B(x) B(x + 1)\ndef one():\n  produce C\n  nproduce D\n"
          "Axiom: A(1)\nproduction:\nA(x) :\n  two(x)\n  one()\n",
          1, "B(1)B(2)C");
}

TEST(lpy, absent_or_empty_axiom_and_spacing) {
  // no Axiom: (a rule set) and an empty Axiom: give an empty string, as in L-Py
  DERIVES("production:\nA --> B\n", 1, "");
  DERIVES("Axiom:\nproduction:\nA --> B\n", 1, "");
  // spaces between a module name and its parameters, in successors, patterns and declarations
  DERIVES("module Leaf (a, b)\nAxiom: Leaf (1, 2) F (3)\nproduction:\nLeaf (a, b) --> Leaf (b, a)\n", 1,
          "Leaf(2,1)F(3)");
  // a non-ASCII character is one module; u'' strings are plain strings
  DERIVES("Axiom: A(u'\xc3\xa9') \xc3\xa9\nproduction:\n\xc3\xa9 --> B\n", 1, "A('\xc3\xa9')B");
}


TEST(lpy, argument_lists_in_patterns_python_engine) {
  // *args, **kwds (the names of `module A(x, t)`, the last parameters) and x(...) variables
  // bind lists and dicts, as L-Py's matching does; the native engine refuses them
  PY_DERIVES("module A(x, t)\nAxiom: A(1, 2, 3) B\nproduction:\nA(*args, **kw) :\n"
             "  assert args == [1] and kw == {'x': 2, 't': 3}\n  produce C(len(args))\n",
             1, "C(1)B");
  PY_DERIVES("module A(x, t)\nAxiom: A(1, 2)\nproduction:\n*(**kw) :\n  assert kw == {'name': 'A', 'x': 1, 't': 2}\n"
             "  produce D\n",
             1, "D");
  PY_DERIVES("Axiom: A(5, 6)\nproduction:\n*(n, x, *rest) :\n  assert n == 'A' and x == 5 and rest == [6]\n"
             "  produce E\n",
             1, "E");
  PY_DERIVES("Axiom: I(0) I(1) A\nproduction:\nx(I(t)) < A :\n  assert t == [0, 1]\n  produce B\n", 1, "I(0)I(1)B");
  PY_DERIVES("Axiom: A I(0) I(1)\nproduction:\nA > x(I(t)) :\n  assert t == [0, 1]\n  produce B\n", 1, "BI(0)I(1)");
}

// ---------------------------------------------------------------------------------------------
// turtle errors and warnings name the file line of the rule or axiom (issue 12 items 7 and 8)

static char logged[2048];

static void keep_log(void* user, int level, const char* msg) {
  (void)user;
  (void)level;
  size_t n = strlen(logged);
  snprintf(logged + n, sizeof logged - n, "%s\n", msg);
}

// grow src (with --set-like overrides name=value), status and error in *e
static vd_status grow_status(const char* src, const char* name, const char* value, vd_error* e) {
  vd_lsystem* ls;
  memset(e, 0, sizeof *e);
  vd_status st = vd_lsys_parse(src, strlen(src), "t.lpy", &ls, e);
  if (st) return st;
  if (name) st = vd_lsys_set_global(ls, name, value, e);
  vd_plant_spec* P = vd_plant_spec_create();
  if (!st) st = vd_lsys_grow(ls, NULL, NULL, P, e);
  vd_plant_spec_destroy(P);
  vd_lsys_destroy(ls);
  return st;
}

TEST(lpy, turtle_errors_name_the_file_line) {
  const char* src =
      "PHYLLO = 137.5\n"
      "Axiom: A\n"
      "derivation length: 2\n"
      "production:\n"
      "A --> F(1) /(PHYLLO) B\n"
      "B --> F(1e308 * 10)\n";
  vd_error e;
  CHECK_STATUS(grow_status(src, NULL, NULL, &e), VD_ERR_VALUE, e);
  CHECK_INT(e.line, 6);
  CHECK_STR(e.file, "t.lpy");
  CHECK_STATUS(grow_status(src, "PHYLLO", "1e400", &e), VD_ERR_VALUE, e);
  CHECK_INT(e.line, 5);
  CHECK_STATUS(grow_status("Axiom: F\nproduction:\nF --> F ] F\n", NULL, NULL, &e), VD_ERR_SYNTAX, e);
  CHECK_INT(e.line, 3);
  // the axiom's line when the module comes from the axiom
  CHECK_STATUS(grow_status("x = 1\nAxiom: F ] F\n", NULL, NULL, &e), VD_ERR_SYNTAX, e);
  CHECK_INT(e.line, 2);
}

TEST(lpy, turtle_warnings_name_the_file_line) {
  // an unclosed '[' and negative widths and radii are accepted (as L-Py does) with a warning
  logged[0] = 0;
  vd_set_log(keep_log, NULL);
  vd_error e;
  vd_status st = grow_status("Axiom: F\nderivation length: 1\nproduction:\nF --> F [ F _(-0.1) F(1, -0.2)\n", NULL,
                             NULL, &e);
  vd_set_log(NULL, NULL);
  CHECK_STATUS(st, VD_OK, e);
  CHECK(strstr(logged, "t.lpy:4: turtle: module 3 '_': negative width") != NULL);
  CHECK(strstr(logged, "t.lpy:4: turtle: module 4 'F': negative radius") != NULL);
  CHECK(strstr(logged, "t.lpy:4: turtle: module 1 '[': 1 '[' not closed") != NULL);
}

// grow src with an engine; the end of the last segment in *end
static vd_status grow_end(const char* src, vd_lsys_engine engine, vd_vec3* end, vd_error* e) {
  vd_lsystem* ls;
  memset(e, 0, sizeof *e);
  vd_status st = vd_lsys_parse_engine(src, strlen(src), "t.lpy", engine, &ls, e);
  if (st) return st;
  vd_plant_spec* P = vd_plant_spec_create();
  st = vd_lsys_grow(ls, NULL, NULL, P, e);
  if (!st && P->nseg) *end = P->node[P->seg[P->nseg - 1].node1];
  vd_plant_spec_destroy(P);
  vd_lsys_destroy(ls);
  return st;
}

TEST(lpy, turtle_angle_increment_of_the_file) {
  // context.turtle.setAngleIncrement(90) makes + turn 90 degrees (it was ignored: 60)
  vd_vec3 b = {0, 0, 0};
  vd_error e;
  CHECK_STATUS(grow_end("Axiom: F(1) + F(1)\n###### INITIALISATION ######\ndef __initialiseContext__(context):\n"
                        "\tcontext.turtle.setAngleIncrement(90)\n",
                        VD_LSYS_NATIVE, &b, &e),
               VD_OK, e);
  CHECK_NEAR(b.y, -1, 1e-9);
  CHECK_NEAR(b.z, 1, 1e-9);
  CHECK_STATUS(grow_end("context().turtle.setAngleIncrement(90)\nAxiom: F(1) + F(1)\n", VD_LSYS_PYTHON, &b, &e), VD_OK,
               e);
  CHECK_NEAR(b.y, -1, 1e-9);
  CHECK_NEAR(b.z, 1, 1e-9);
}

TEST(lpy, turtle_takes_vectors_python_engine) {
  // @M(v), @R(h, u) with vector objects or tuples, as L-Py's turtle takes them
  vd_vec3 b = {0, 0, 0};
  vd_error e;
  CHECK_STATUS(grow_end("Axiom: @M(Vector3(1, 2, 3)) F(1)\n", VD_LSYS_PYTHON, &b, &e), VD_OK, e);
  CHECK_NEAR(b.x, 1, 1e-9);
  CHECK_NEAR(b.y, 2, 1e-9);
  CHECK_NEAR(b.z, 4, 1e-9);
  CHECK_STATUS(grow_end("Axiom: @R((1, 0, 0), Vector3(0, 0, 1)) F(2)\n", VD_LSYS_PYTHON, &b, &e), VD_OK, e);
  CHECK_NEAR(b.x, 2, 1e-9);
  CHECK_NEAR(b.z, 0, 1e-9);
  // an object that is no vector is an error naming it
  CHECK_STATUS(grow_end("Axiom: @M([1]) F(1)\n", VD_LSYS_PYTHON, &b, &e), VD_ERR_TYPE, e);
}

// ---------------------------------------------------------------------------------------------
// animation (vd_lsys_animate, L-Py's Lsystem.animate) and calling the file's functions

typedef struct frames_seen {
  int n, frame[16], nseg[16];
} frames_seen;

static int see_frame(void* user, int frame, const vd_lstring* s, const vd_plant_spec* plant) {
  (void)s;
  frames_seen* f = user;
  if (f->n < 16) f->frame[f->n] = frame, f->nseg[f->n] = plant->nseg, f->n++;
  return 0;
}

// animate src with an engine: the frames seen, the final plant's segments and global `n`
static vd_status animate_text(const char* src, vd_lsys_engine engine, frames_seen* f, int* nseg, double* n,
                              vd_error* e) {
  vd_lsystem* ls;
  memset(f, 0, sizeof *f);
  vd_status st = vd_lsys_parse_engine(src, strlen(src), "anim.lpy", engine, &ls, e);
  if (st) return st;
  vd_lsys_def d = vd_lsys_def_default();
  d.max_ops = 10000000;
  d.frame = see_frame;
  d.frame_user = f;
  vd_lstring s = vd_lstring_empty();
  vd_plant_spec* p = vd_plant_spec_create();
  st = vd_lsys_animate(ls, &d, &s, p, e);
  *nseg = p->nseg;
  if (!st && vd_lsys_get_global(ls, "n", n)) *n = -1;
  if (!st) st = vd_lsys_call(ls, "check", e);
  vd_plant_spec_destroy(p);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return st;
}

TEST(lpy, animate_draws_every_step) {
  // the interpretation rule counts its calls: the axiom's frame, then one per step; check()
  // reads the count as the run left it
  const char* src =
      "n = 0\n"
      "def check():\n  assert n == 4 and not isAnimationEnabled()\n"
      "def StartEach():\n  assert isAnimationEnabled() and isFrameDisplayed()\n"
      "Axiom: A\nderivation length: 3\nproduction:\nA --> F(1) A\n"
      "interpretation:\nA:\n  global n\n  n += 1\n  produce\nendlsystem\n";
  for (int engine = VD_LSYS_NATIVE; engine <= VD_LSYS_PYTHON; engine++) {
    if (engine == VD_LSYS_PYTHON && !vd_lsys_python_available(NULL, 0)) break;
    frames_seen f;
    int nseg;
    double n;
    vd_error e = {0};
    CHECK_STATUS(animate_text(src, (vd_lsys_engine)engine, &f, &nseg, &n, &e), VD_OK, e);
    CHECK_INT(f.n, 4);
    for (int k = 0; k < f.n; k++) {
      CHECK_INT(f.frame[k], k);
      CHECK_INT(f.nseg[k], k);  // frame k: the string after k steps
    }
    CHECK_INT(nseg, 3);
    CHECK_NEAR(n, 4, 0);
  }
  // frameDisplay(False) during a step skips its frame; the final plant is drawn all the same;
  // a step where no rule matches still runs (and has its frame)
  const char* skip =
      "n = 0\ndef check():\n  assert n == 4, n\n"
      "def StartEach():\n  frameDisplay(getIterationNb() != 2)\n"
      "Axiom: A(0)\nderivation length: 3\nproduction:\nA(x) :\n  if x < 1:\n    produce F(1) A(x + 1)\n"
      "interpretation:\nA(x):\n  global n\n  n += 1\n  produce\nendlsystem\n";
  frames_seen f;
  int nseg;
  double n;
  vd_error e = {0};
  CHECK_STATUS(animate_text(skip, VD_LSYS_NATIVE, &f, &nseg, &n, &e), VD_OK, e);
  CHECK_INT(f.n, 3);
  CHECK_INT(f.frame[2], 2);  // frames 0, 1, 2; 3 skipped
  CHECK_INT(nseg, 1);
  CHECK_NEAR(n, 4, 0);  // frames 0, 1, 2 and the final string, drawn for *plant
}

TEST(lpy, animate_reuses_the_scene_a_hook_returns) {
  if (!vd_lsys_python_available(NULL, 0)) return;
  // EndEach(lstring, lscene) in an animation: the scene is drawn before the call; the frame
  // keeps it when the hook returns it (alone or with the string) or nothing, else draws again
  static const struct {
    const char* ret;
    int draws;
  } cases[] = {
      {"return lstring, lscene", 2}, {"return lscene", 2},          {"pass", 2},
      {"return lstring", 3},         {"return lstring, None", 3},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char src[1024];
    snprintf(src, sizeof src,
             "n = 0\ndef check():\n  pass\n"
             "def EndEach(lstring, lscene):\n  %s\n"
             "Axiom: B C\nderivation length: 1\nproduction:\nC --> C\n"
             "interpretation:\nB:\n  global n\n  n += 1\n  produce F(1)\nendlsystem\n",
             cases[k].ret);
    frames_seen f;
    int nseg;
    double n;
    vd_error e = {0};
    CHECK_STATUS(animate_text(src, VD_LSYS_PYTHON, &f, &nseg, &n, &e), VD_OK, e);
    CHECK_INT(f.n, 2);
    CHECK_INT(nseg, 1);
    if (n != cases[k].draws) vdt_fail(__FILE__, __LINE__, "'%s': %g draws, expected %d", cases[k].ret, n, cases[k].draws);
  }
  // a scene the hook made itself cannot be a frame: refused, not ignored
  frames_seen f;
  int nseg;
  double n;
  vd_error e = {0};
  CHECK_STATUS(animate_text("def EndEach(lstring, lscene):\n  return Scene()\nAxiom: A\nproduction:\nA --> A\n",
                            VD_LSYS_PYTHON, &f, &nseg, &n, &e),
               VD_ERR_UNSUPPORTED, e);
  if (!strstr(e.msg, "scene of its own")) vdt_fail(__FILE__, __LINE__, "message '%s'", e.msg);
}

TEST(lpy, call_a_function_of_the_file) {
  for (int engine = VD_LSYS_NATIVE; engine <= VD_LSYS_PYTHON; engine++) {
    if (engine == VD_LSYS_PYTHON && !vd_lsys_python_available(NULL, 0)) break;
    vd_lsystem* ls;
    vd_error e = {0};
    const char* src = "k = 0\ndef ok():\n  assert k == 2\ndef bad():\n  assert k == 3\n"
                      "def EndEach():\n  global k\n  k += 1\nAxiom: A\nderivation length: 2\nproduction:\nA --> A\n";
    CHECK_STATUS(vd_lsys_parse_engine(src, strlen(src), "call.lpy", (vd_lsys_engine)engine, &ls, &e), VD_OK, e);
    CHECK_INT(vd_lsys_call(ls, "ok", &e), VD_ERR_ARG);  // before any run
    vd_lsys_def d = vd_lsys_def_default();
    vd_lstring s = vd_lstring_empty();
    CHECK_STATUS(vd_lsys_derive(ls, &d, &s, &e), VD_OK, e);
    CHECK_STATUS(vd_lsys_call(ls, "ok", &e), VD_OK, e);
    memset(&e, 0, sizeof e);
    CHECK(vd_lsys_call(ls, "bad", &e) != VD_OK && e.line == 5);  // the failed assert's line
    memset(&e, 0, sizeof e);
    CHECK_INT(vd_lsys_call(ls, "missing", &e), VD_ERR_NAME);
    if (!strstr(e.msg, "no function 'missing'")) vdt_fail(__FILE__, __LINE__, "message '%s'", e.msg);
    vd_lstring_free(&s);
    vd_lsys_destroy(ls);
  }
}

TEST(lpy, produce_with_keyword_parameters_python_engine) {
  if (!vd_lsys_python_available(NULL, 0)) return;
  // produce A(**d) places d's values by the names `module A(x, y)` declares; A(a, **d) after
  // the ones given by position
  PY_DERIVES("module A(x, y)\nAxiom: A(0, 0)\nproduction:\nA(**p):\n  p['y'] += 1\n  produce A(**p) B\n", 2,
             "A(0,2)BB");
  PY_DERIVES("module A(x, y)\nAxiom: A(0, 0)\nproduction:\nA(x, y):\n  produce A(5, **{'y': y + 1})\n", 1, "A(5,1)");
  // a key that names no parameter, or a parameter without a value: errors at the produce
  static const char* bad[][2] = {
      {"A(**p):\n  p['z'] = 1\n  produce A(**p)\n", "no parameter 'z'"},
      {"A(**p):\n  del p['x']\n  produce A(**p)\n", "no value for parameter 'x'"},
      {"A(**p):\n  produce B(**p)\n", "module B declares no parameter names"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    char src[512], b[256];
    snprintf(src, sizeof src, "module A(x, y)\nAxiom: A(0, 0)\nproduction:\n%s", bad[k][0]);
    vd_error e = {0};
    CHECK(derive_engine(src, VD_LSYS_PYTHON, 1, b, sizeof b, &e) != VD_OK);
    if (!strstr(e.msg, bad[k][1]) || e.line < 5) vdt_fail(__FILE__, __LINE__, "'%s' at line %d", e.msg, e.line);
  }
}

TEST(lpy, module_inheritance) {
  // `module B : base = A` with the 'Module inheritance' option: a rule (or context) of A applies
  // to B too, in file order; without the option B is a module of its own
  const char* head = "module A(x)\nmodule B(x) : base = A\nmodule E, F : base = (Q, B)\n";
  const char* body = "Axiom: B(1) A(2) C E(3) F\nderivation length: 1\nproduction:\n"
                     "A(x) < C --> G(x)\nA(x) --> D(x)\n";
  const char* opt = "###### INITIALISATION ######\ndef __initialiseContext__(context):\n"
                    "\tcontext.options.setSelection('Module inheritance', 1)\n";
  char src[1024];
  snprintf(src, sizeof src, "%s%s%s", head, body, opt);
  DERIVES(src, -1, "D(1)D(2)G(2)D(3)F");  // F has no parameter: A(x) does not match it
  snprintf(src, sizeof src, "%s%s", head, body);
  DERIVES(src, -1, "B(1)D(2)G(2)E(3)F");
  if (vd_lsys_python_available(NULL, 0)) {
    snprintf(src, sizeof src,
             "%sassert ModuleClass.get('E').issubclass(ModuleClass.get('A'))\n"
             "assert not ModuleClass.get('A').issubclass(ModuleClass.get('B'))\n%s%s",
             head, body, opt);
    PY_DERIVES(src, -1, "D(1)D(2)G(2)D(3)F");
  }
}

TEST(lpy, lsystem_inside_a_file_python_engine) {
  if (!vd_lsys_python_available(NULL, 0)) return;
  // Lsystem().set(code).iterate(): a nested L-system (the native subset) derived by verdant,
  // its string an Lstring the rule reads
  const char* src = "inner = '''\nAxiom: A(1)\nderivation length: 2\nproduction:\nA(x) --> A(x + 1) B('s')\n'''\n"
                    "Axiom: E\nproduction:\nE:\n  l = Lsystem()\n  l.set(inner)\n  s = l.iterate()\n"
                    "  assert s[2].name == 'B' and s[2][0] == 's'\n  produce X(len(s), s[0][0], len(l.iterate(1)))\n";
  PY_DERIVES(src, 1, "X(3,3,2)");
  // beyond the native subset: refused, at the line of the call
  vd_error e = {0};
  char b[256];
  CHECK_STATUS(derive_engine("Axiom: E\nproduction:\nE:\n  l = Lsystem()\n  l.set('class A: pass\\nAxiom: A')\n"
                             "  l.iterate()\n  produce X\n",
                             VD_LSYS_PYTHON, 1, b, sizeof b, &e),
               VD_ERR_UNSUPPORTED, e);
  if (!strstr(e.msg, "Lsystem inside a file") || e.line != 6) vdt_fail(__FILE__, __LINE__, "'%s' line %d", e.msg, e.line);
}
