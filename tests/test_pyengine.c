// SPDX-License-Identifier: MIT
// pyengine: the Python engine (embedded CPython) on small .lpy texts of our own: classes,
// lists and numpy values as module parameters, seeded random, hooks, errors at their lines,
// --set, the automatic engine choice, and the same strings as the native engine on the
// native subset.
#include <pthread.h>
#include <stdlib.h>

#include "test.h"
#include "verdant/lsys.h"

// derive src with an engine; the formatted string in buf
static vd_status derive_with(const char* src, vd_lsys_engine eng, int steps, uint64_t seed, char* buf, size_t cap,
                             vd_error* e) {
  vd_lsystem* ls;
  buf[0] = 0;
  vd_status st = vd_lsys_parse_engine(src, strlen(src), "py.lpy", eng, &ls, e);
  if (st) return st;
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = steps;
  d.seed = seed;
  d.max_ops = 100000000;  // runaway code stops after 10 s
  vd_lstring s = vd_lstring_empty();
  st = vd_lsys_derive(ls, &d, &s, e);
  if (!st) vd_lsys_format(ls, &s, buf, cap);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return st;
}

#define CHECK_PY(src, steps, expected)                                                            \
  do {                                                                                             \
    char b_[8192];                                                                                 \
    vd_error e_ = {0};                                                                             \
    CHECK_STATUS(derive_with(src, VD_LSYS_PYTHON, steps, 0, b_, sizeof b_, &e_), VD_OK, e_);       \
    CHECK_STR(b_, expected);                                                                       \
  } while (0)

static int python_here(void) {
  char why[256];
  if (vd_lsys_python_available(why, sizeof why)) return 1;
  fprintf(stderr, "  (no Python engine here: %s)\n", why);
  return 0;
}

TEST(pyengine, classes_and_lists_as_parameters) {
  if (!python_here()) return;
  const char* src =
      "class Bud:\n"
      "    def __init__(self, age):\n"
      "        self.age = age\n"
      "    def older(self):\n"
      "        return Bud(self.age + 1)\n"
      "    def __repr__(self):\n"
      "        return 'Bud(%d)' % self.age\n"
      "def grow(l):\n"
      "    return [x * 2 for x in l]\n"
      "Axiom: A(Bud(0), [1, 2])\n"
      "derivation length: 2\n"
      "production:\n"
      "A(b, l) :\n"
      "    if b.age < 1:\n"
      "        produce F(len(l)) [ +(30) A(b.older(), grow(l)) ] A(b.older(), l + [5])\n"
      "    else:\n"
      "        produce F(sum(l))\n"
      "endlsystem\n";
  CHECK_PY(src, -1, "F(2)[+(30)F(6)]F(8)");
  CHECK_PY(src, 1, "F(2)[+(30)A(Bud(1),[2, 4])]A(Bud(1),[1, 2, 5])");
}

TEST(pyengine, tuples_dicts_strings_big_ints) {
  if (!python_here()) return;
  const char* src =
      "Axiom: A((1, 'x'), {'k': 2.5}, 'leaf', 2**70, True)\n"
      "production:\n"
      "A(t, d, s, n, b) --> B(t[0] + d['k'], s.upper(), n % 1000, b, n // 2**69)\n";
  CHECK_PY(src, 1, "B(3.5,'LEAF',424,1,2)");
}

TEST(pyengine, numpy_copy_math) {
  if (!python_here()) return;
  const char* src =
      "import numpy as np\n"
      "from copy import deepcopy\n"
      "import math\n"
      "M = np.array([[1.0, 2.0], [3.0, 4.0]])\n"
      "Axiom: A(M, [[1], [2]])\n"
      "production:\n"
      "A(m, l) :\n"
      "    l2 = deepcopy(l)\n"
      "    l2[0].append(9)\n"
      "    produce B(float(np.linalg.det(m)), np.int64(7), len(l[0]), len(l2[0]), math.floor(m.sum()))\n";
  CHECK_PY(src, 1, "B(-2.0000000000000004,7,1,2,10)");
}

TEST(pyengine, seeded_random_is_cpython_and_repeats) {
  if (!python_here()) return;
  // CPython's random.seed(42); random() is 0.6394267984578837; the native engine agrees
  const char* src =
      "from random import *\n"
      "Axiom: A(random())\n"
      "production:\n"
      "A(x) --> A(x) B(uniform(0, 1), randint(1, 6), gauss(0, 1))\n";
  char a[4096], b[4096], c[4096], n[4096];
  vd_error e = {0};
  CHECK_STATUS(derive_with(src, VD_LSYS_PYTHON, 3, 42, a, sizeof a, &e), VD_OK, e);
  CHECK_STATUS(derive_with(src, VD_LSYS_PYTHON, 3, 42, b, sizeof b, &e), VD_OK, e);
  CHECK_STATUS(derive_with(src, VD_LSYS_PYTHON, 3, 43, c, sizeof c, &e), VD_OK, e);
  CHECK_STATUS(derive_with(src, VD_LSYS_NATIVE, 3, 42, n, sizeof n, &e), VD_OK, e);
  CHECK_STR(a, b);
  CHECK(strcmp(a, c) != 0);
  CHECK(strncmp(a, "A(0.6394267984578837)", 21) == 0);
  CHECK_STR(a, n);  // same generator, same algorithms: the two engines draw the same numbers
}

// the same lsystem text derived on several threads at once gives each thread the serial result
typedef struct job {
  const char* src;
  uint64_t seed;
  char out[4096];
  vd_status st;
} job;

static void* run_job(void* arg) {
  job* j = arg;
  vd_error e = {0};
  j->st = derive_with(j->src, VD_LSYS_PYTHON, 6, j->seed, j->out, sizeof j->out, &e);
  return NULL;
}

TEST(pyengine, threads_keep_their_random_streams) {
  if (!python_here()) return;
  const char* src =
      "import random\n"
      "Axiom: A(0)\n"
      "production:\n"
      "A(x) :\n"
      "    if random.random() < 0.7: produce A(x + 1) [ B(random.randint(0, 99)) ]\n"
      "    else: produce A(x)\n";
  job serial[4], par[4];
  for (int k = 0; k < 4; k++) {
    serial[k].src = par[k].src = src;
    serial[k].seed = par[k].seed = (uint64_t)k;
    run_job(&serial[k]);
  }
  pthread_t th[4];
  for (int k = 0; k < 4; k++) pthread_create(&th[k], NULL, run_job, &par[k]);
  for (int k = 0; k < 4; k++) pthread_join(th[k], NULL);
  for (int k = 0; k < 4; k++) {
    CHECK_INT(serial[k].st, VD_OK);
    CHECK_INT(par[k].st, VD_OK);
    CHECK_STR(par[k].out, serial[k].out);
  }
  CHECK(strcmp(serial[0].out, serial[1].out) != 0);
}

TEST(pyengine, same_strings_as_native_on_the_subset) {
  if (!python_here()) return;
  static const char* files[] = {"data/abop_1_9.lpy", "data/abop_fig1_24a.lpy", "data/signal.lpy", "data/tree.lpy",
                                "data/tomato.lpy", "data/lilac.lpy"};
  for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
    char* text;
    size_t len;
    vd_error e = {0};
    REQUIRE(vd_file_read(vdt_path(files[f]), &text, &len, &e) == VD_OK);
    vd_lsystem *ln, *lp;
    CHECK_STATUS(vd_lsys_parse_engine(text, len, files[f], VD_LSYS_NATIVE, &ln, &e), VD_OK, e);
    CHECK_STATUS(vd_lsys_parse_engine(text, len, files[f], VD_LSYS_PYTHON, &lp, &e), VD_OK, e);
    vd_free(text, len + 1);
    if (!ln || !lp) {
      vd_lsys_destroy(ln);
      vd_lsys_destroy(lp);
      continue;
    }
    CHECK_INT(vd_lsys_get_engine(ln), VD_LSYS_NATIVE);
    CHECK_INT(vd_lsys_get_engine(lp), VD_LSYS_PYTHON);
    vd_lsys_def d = vd_lsys_def_default();
    d.seed = 5;
    vd_lstring a = vd_lstring_empty(), b = vd_lstring_empty(), ga = vd_lstring_empty(), gb = vd_lstring_empty();
    CHECK_STATUS(vd_lsys_derive(ln, &d, &a, &e), VD_OK, e);
    CHECK_STATUS(vd_lsys_derive(lp, &d, &b, &e), VD_OK, e);
    CHECK_STATUS(vd_lsys_interpret(ln, &d, &a, &ga, &e), VD_OK, e);
    CHECK_STATUS(vd_lsys_interpret(lp, &d, &b, &gb, &e), VD_OK, e);
    // identical layout: symbols by name, parameter values bit for bit
    int same = a.n == b.n && ga.n == gb.n;
    for (int64_t i = 0; same && i < a.n; i++) {
      same = !strcmp(vd_lsys_symbol_name(ln, a.sym[i]), vd_lsys_symbol_name(lp, b.sym[i])) &&
             vd_lstring_nparam(&a, i) == vd_lstring_nparam(&b, i);
      for (int k = 0; same && k < vd_lstring_nparam(&a, i); k++) {
        double x = a.val[a.par[i] + k], y = b.val[b.par[i] + k];
        same = vd_lsys_value_is_str(x) ? !strcmp(vd_lsys_value_str(ln, x), vd_lsys_value_str(lp, y)) : x == y;
      }
    }
    if (!same) vdt_fail(__FILE__, __LINE__, "%s: the engines derive different strings", files[f]);
    vd_lstring_free(&a);
    vd_lstring_free(&b);
    vd_lstring_free(&ga);
    vd_lstring_free(&gb);
    vd_lsys_destroy(ln);
    vd_lsys_destroy(lp);
  }
}

TEST(pyengine, automatic_choice) {
  if (!python_here()) return;
  vd_lsystem* ls;
  vd_error e = {0};
  const char* native = "Axiom: A\nproduction:\nA --> AB\n";
  CHECK_STATUS(vd_lsys_parse(native, strlen(native), "n.lpy", &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_get_engine(ls), VD_LSYS_NATIVE);
  vd_lsys_destroy(ls);
  const char* list = "x = [1, 2]\nAxiom: A(x[1])\n";
  CHECK_STATUS(vd_lsys_parse(list, strlen(list), "l.lpy", &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_get_engine(ls), VD_LSYS_PYTHON);
  vd_lsys_destroy(ls);
  // a name the file does not define (PlantGL's Vector3) goes to Python too
  const char* pgl = "from openalea.plantgl.all import *\nAxiom: A(Vector3(1, 2, 3).x)\n";
  CHECK_STATUS(vd_lsys_parse(pgl, strlen(pgl), "p.lpy", &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_get_engine(ls), VD_LSYS_PYTHON);
  vd_lsys_destroy(ls);
  CHECK_STR(vd_lsys_engine_name(VD_LSYS_PYTHON), "python");
  CHECK_STR(vd_lsys_engine_name(VD_LSYS_NATIVE), "native");
}

// what native refuses only when it runs ("a%d" % 3: native has no string formatting) runs in
// CPython after vd_lsys_fallback (issue 19); a file chosen explicitly keeps native's error
TEST(pyengine, automatic_choice_falls_back_at_run_time) {
  if (!python_here()) return;
  const char* src = "Axiom: A(1)\nderivation length: 1\nproduction:\nA(x):\n  s = 'a%d' % x\n  produce B(x + 1)\n";
  vd_lsystem* ls;
  vd_error e = {0};
  CHECK_STATUS(vd_lsys_parse(src, strlen(src), "f.lpy", &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_get_engine(ls), VD_LSYS_NATIVE);
  vd_lsys_def def = vd_lsys_def_default();
  def.steps = 1;
  vd_lstring out = vd_lstring_empty();
  vd_status st = vd_lsys_derive(ls, &def, &out, &e);
  CHECK(st == VD_ERR_TYPE || st == VD_ERR_UNSUPPORTED);
  CHECK_INT(vd_lsys_fallback(&ls, st), 1);
  CHECK_INT(vd_lsys_get_engine(ls), VD_LSYS_PYTHON);
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_derive(ls, &def, &out, &e2), VD_OK, e2);
  CHECK_INT((int)out.n, 1);
  CHECK_INT((int)out.val[0], 2);
  CHECK_INT(vd_lsys_fallback(&ls, VD_ERR_TYPE), 0);  // once only: it is Python now
  vd_lstring_free(&out);
  vd_lsys_destroy(ls);
  CHECK_STATUS(vd_lsys_parse_engine(src, strlen(src), "f.lpy", VD_LSYS_NATIVE, &ls, &e), VD_OK, e);
  CHECK_INT(vd_lsys_fallback(&ls, VD_ERR_TYPE), 0);
  vd_lsys_destroy(ls);
}

TEST(pyengine, hooks_with_the_lstring) {
  if (!python_here()) return;
  const char* src =
      "count = 0\n"
      "def StartEach():\n"
      "    global count\n"
      "    count += 1\n"
      "def EndEach(lstring):\n"
      "    assert len(lstring) == 2 ** (getIterationNb() + 1) * 2\n"
      "def End(lstring):\n"
      "    assert count == 3\n"
      "    assert lstring[0].name == 'A' and lstring[-1].name == 'B'\n"
      "    return lstring[:1] + lstring[-1:] + Lstring('C(1)') + [Module('D', count)]\n"
      "Axiom: A B\n"
      "derivation length: 3\n"
      "production:\n"
      "A --> A A\n"
      "B --> B B\n";
  CHECK_PY(src, -1, "ABC(1)D(3)");
}

TEST(pyengine, produce_forms) {
  if (!python_here()) return;
  const char* src =
      "def helper(n):\n"
      "    for i in range(n):\n"
      "        nproduce F(i)\n"
      "Axiom: A(3)\n"
      "production:\n"
      "A(n) :\n"
      "    helper(n)\n"
      "    s = makestring(B(n) C)\n"
      "    nsproduce(s)\n"
      "    produce(D(n, [n]))\n"
      "B --> *\n";
  CHECK_PY(src, 1, "F(0)F(1)F(2)B(3)CD(3,[3])");
}

TEST(pyengine, errors_name_the_file_line) {
  if (!python_here()) return;
  struct {
    const char* src;
    vd_status st;
    int line;
  } cases[] = {
      {"Axiom: A\nproduction:\nA :\n    x = undefined_thing + 1\n    produce B\n", VD_ERR_NAME, 4},
      {"Axiom: A\nproduction:\nA :\n    x = [1,\n    produce B\n", VD_ERR_SYNTAX, 4},
      {"class K:\n    def f(self):\n        return 1 / 0\nAxiom: A(K().f())\n", VD_ERR_VALUE, 3},
      {"Axiom: A\nproduction:\nA :\n    assert 1 == 2, 'no'\n", VD_ERR_ASSERT, 4},
      {"import no_such_module_here\nAxiom: A\n", VD_ERR_UNSUPPORTED, 1},
      {"x = [1]\nAxiom: A\nproduction:\nA :\n    while True:\n        x.append(1)\n        x.pop()\n",
       VD_ERR_LIMIT, 0},
      {"# nothing but a comment\n", VD_ERR_SYNTAX, 1},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    vd_lsystem* ls;
    vd_error e = {0};
    vd_status st = vd_lsys_parse_engine(cases[i].src, strlen(cases[i].src), "err.lpy", VD_LSYS_PYTHON, &ls, &e);
    if (st == VD_OK) {
      vd_lsys_def d = vd_lsys_def_default();
      d.steps = 1;
      d.max_ops = 1000;  // the runaway loop: 1 s without progress
      vd_lstring s = vd_lstring_empty();
      st = vd_lsys_derive(ls, &d, &s, &e);
      vd_lstring_free(&s);
      vd_lsys_destroy(ls);
    }
    if (st != cases[i].st || (cases[i].line && e.line != cases[i].line) || strcmp(e.file, "err.lpy") != 0) {
      char eb[700];
      vdt_fail(__FILE__, __LINE__, "case %d: %s line %d, expected %s line %d (%s)", (int)i, vd_status_str(st), e.line,
               vd_status_str(cases[i].st), cases[i].line, vd_error_format(&e, eb, sizeof eb));
    }
  }
}

TEST(pyengine, set_global) {
  if (!python_here()) return;
  const char* src =
      "N = [1, 2]\n"
      "K = len(N)\n"
      "Axiom: A(K, N)\n";
  vd_lsystem* ls;
  vd_error e = {0};
  REQUIRE(vd_lsys_parse_engine(src, strlen(src), "s.lpy", VD_LSYS_PYTHON, &ls, &e) == VD_OK);
  CHECK_STATUS(vd_lsys_set_global(ls, "N", "[1, 2, 3]", &e), VD_OK, e);
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_set_global(ls, "missing", "1", &e2), VD_ERR_NAME, e2);
  vd_lstring s = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, NULL, &s, &e), VD_OK, e);
  char buf[256] = "";
  vd_lsys_format(ls, &s, buf, sizeof buf);
  CHECK_STR(buf, "A(3,[1, 2, 3])");
  double k = 0;
  CHECK_INT(vd_lsys_get_global(ls, "K", &k), VD_OK);
  CHECK_NEAR(k, 3, 0);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
}

TEST(pyengine, objects_are_released_after_each_step) {
  if (!python_here()) return;
  // 200 steps, each replacing a growing list: the table holds only the live ones
  const char* src =
      "import sys\n"
      "Axiom: A([0])\n"
      "production:\n"
      "A(l) --> A(l + [len(l)])\n"
      "interpretation:\n"
      "A(l) --> F(len(l))\n";
  char buf[256];
  vd_error e = {0};
  CHECK_STATUS(derive_with(src, VD_LSYS_PYTHON, 200, 0, buf, sizeof buf, &e), VD_OK, e);
  CHECK(strncmp(buf, "A([0, 1, 2,", 11) == 0);
  vd_lsystem* ls;
  REQUIRE(vd_lsys_parse_engine(src, strlen(src), "g.lpy", VD_LSYS_PYTHON, &ls, &e) == VD_OK);
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = 200;
  vd_lstring s = vd_lstring_empty(), g = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, &d, &s, &e), VD_OK, e);
  CHECK_STATUS(vd_lsys_interpret(ls, &d, &s, &g, &e), VD_OK, e);
  REQUIRE(g.n == 1);
  CHECK_NEAR(g.val[0], 201, 0);
  vd_lstring_free(&s);
  vd_lstring_free(&g);
  vd_lsys_destroy(ls);
}

// ---------------------------------------------------------------------------------------------
// the turtle fed by PlantGL objects

static vd_plant_spec* grow_py(const char* src, vd_error* e) {
  vd_lsystem* ls;
  if (vd_lsys_parse_engine(src, strlen(src), "turtle.lpy", VD_LSYS_PYTHON, &ls, e)) return NULL;
  vd_plant_spec* p = vd_plant_spec_create();
  vd_lsys_def d = vd_lsys_def_default();
  if (vd_lsys_grow(ls, &d, NULL, p, e)) {
    vd_plant_spec_destroy(p);
    p = NULL;
  }
  vd_lsys_destroy(ls);
  return p;
}

TEST(pyengine, guide_turns_the_turtle_along_the_curve) {
  if (!python_here()) return;
  // an L-shaped guide of length 2 drawn by two F(1): the first goes straight, the second turns
  // 90 degrees toward U (the curve's y), and the path ends at H0 + U0 = (1, 0, 1)
  vd_error e = {0};
  vd_plant_spec* p = grow_py("g = Polyline2D([(0, 0), (1, 0), (1, 1)])\nAxiom: SetGuide(g, 2) F(1) F(1)\n", &e);
  if (!p) {
    char b[600];
    vdt_fail(__FILE__, __LINE__, "%s", vd_error_format(&e, b, sizeof b));
    return;
  }
  REQUIRE(p->nseg == 2);
  vd_vec3 end = p->node[p->seg[1].node1], mid = p->node[p->seg[0].node1];
  CHECK_NEAR(mid.x, 0, 1e-3);
  CHECK_NEAR(mid.z, 1, 1e-3);
  CHECK_NEAR(end.x, 1, 1e-3);
  CHECK_NEAR(end.y, 0, 1e-3);
  CHECK_NEAR(end.z, 1, 1e-3);
  vd_plant_spec_destroy(p);
  // a guide twice as long as its curve stretches the moves; after the guide the turtle goes on
  // straight; EndGuide stops following
  p = grow_py("g = Polyline2D([(0, 0), (0.5, 0)])\nAxiom: SetGuide(g, 1) F(0.5) F(0.5) F(1) EndGuide F(1)\n", &e);
  REQUIRE(p && p->nseg == 4);
  CHECK_NEAR(p->node[p->seg[3].node1].z, 3, 1e-9);
  vd_plant_spec_destroy(p);
}

TEST(pyengine, contour_sweeps_and_tubes) {
  if (!python_here()) return;
  vd_error e = {0};
  // a square contour: F draws a swept mesh (8 vertices, 8 triangles, open), not a segment
  const char* sq = "sq = Polyline2D([(1, 1), (-1, 1), (-1, -1), (1, -1), (1, 1)])\n";
  char src[512];
  snprintf(src, sizeof src, "%sAxiom: _(0.5) SetContour(sq, True) F(2)\n", sq);
  vd_plant_spec* p = grow_py(src, &e);
  REQUIRE(p);
  CHECK_INT(p->nseg, 0);
  REQUIRE(p->nmesh == 1);
  CHECK_INT(p->mesh[0].nvert, 8);
  CHECK_INT(p->mesh[0].ntri, 8);
  CHECK_INT(p->mesh[0].closed, 0);
  vd_plant_stats ps;
  vd_plant_spec_stats(p, &ps);
  CHECK_NEAR(ps.bbox_max.z, 2, 1e-12);
  CHECK_NEAR(ps.bbox_max.x, 0.5, 1e-12);  // x of the contour along L (= -Y), y along U (= X)
  CHECK_NEAR(ps.bbox_max.y, 0.5, 1e-12);
  vd_plant_spec_destroy(p);
  // a tube with the contour: one mesh through its path, a branch is its own tube
  snprintf(src, sizeof src, "%sAxiom: SetContour(sq) @Gc F(1) [ +(30) F(1) ] F(1) F(1) @Ge F(1)\n", sq);
  p = grow_py(src, &e);
  REQUIRE(p);
  CHECK_INT(p->nmesh, 3);  // the tube, its branch, the F after @Ge (a small sweep)
  REQUIRE(p->nmesh == 3);
  CHECK_INT(p->mesh[0].nvert, 2 * 4);  // the branch: its start and end rings
  CHECK_INT(p->mesh[1].nvert, 4 * 4);  // the main tube: 4 rings
  vd_plant_spec_destroy(p);
}

TEST(pyengine, sweep_and_radius_law) {
  if (!python_here()) return;
  vd_error e = {0};
  // Sweep(path, section, length, dl, radius, law): 10 swept steps along the path, radius from
  // the law (a line from 1 to 0: the last ring has radius 0)
  vd_plant_spec* p = grow_py("path = Polyline2D([(0, 0), (1, 0)])\n"
                             "sec = Polyline2D.Circle(1, 6)\n"
                             "law = QuantisedFunction(Polyline2D([(0, 1), (1, 0)]))\n"
                             "Axiom: Sweep(path, sec, 1, 0.1, 0.2, law)\n",
                             &e);
  REQUIRE(p);
  CHECK_INT(p->nmesh, 10);
  vd_plant_stats ps;
  vd_plant_spec_stats(p, &ps);
  CHECK_NEAR(ps.bbox_max.z, 1, 1e-9);
  CHECK_NEAR(ps.bbox_max.y, 0.2, 1e-9);  // the hexagon's x = -1 corner along L = -Y
  vd_plant_spec_destroy(p);
  // nF with a law and a default section: segments, radius following the law
  p = grow_py("law = QuantisedFunction(Polyline2D([(0, 1), (1, 0.5)]))\nAxiom: nF(1, 0.5, 0.1, law)\n", &e);
  REQUIRE(p && p->nseg == 2);
  CHECK_NEAR(p->seg[0].r0, 0.1, 1e-9);
  CHECK_NEAR(p->seg[0].r1, 0.075, 1e-9);
  CHECK_NEAR(p->seg[1].r1, 0.05, 1e-9);
  vd_plant_spec_destroy(p);
}

TEST(pyengine, pglshape_places_the_geometry) {
  if (!python_here()) return;
  vd_error e = {0};
  // a box of half-size (1, 2, 3) after a move: z along H, x along U, y along -L; scale 0.5
  vd_plant_spec* p = grow_py("Axiom: f(10) @g(Box(Vector3(1, 2, 3)), 0.5) @g(Material('m')) @g(NurbsPatch([[(0,0,0,1),(1,0,0,1)],[(0,1,0,1),(1,1,0,1)]], udegree=1, vdegree=1))\n", &e);
  if (!p) {
    char b[600];
    vdt_fail(__FILE__, __LINE__, "%s", vd_error_format(&e, b, sizeof b));
    return;
  }
  REQUIRE(p->nmesh == 2);
  CHECK_INT(p->mesh[0].closed, 1);
  CHECK_INT(p->mesh[0].nvert, 8);
  CHECK_INT(p->mesh[1].closed, 0);  // the patch: a thin surface
  double zmin = 1e9, zmax = -1e9, xmax = -1e9, ymax = -1e9;
  for (int i = 0; i < p->mesh[0].nvert; i++) {
    vd_vec3 v = p->vert[p->mesh[0].vert_start + i];
    zmin = fmin(zmin, v.z), zmax = fmax(zmax, v.z), xmax = fmax(xmax, v.x), ymax = fmax(ymax, v.y);
  }
  CHECK_NEAR(zmin, 10 - 1.5, 1e-12);
  CHECK_NEAR(zmax, 10 + 1.5, 1e-12);
  CHECK_NEAR(xmax, 0.5, 1e-12);
  CHECK_NEAR(ymax, 1.0, 1e-12);
  vd_plant_spec_destroy(p);
}

TEST(pyengine, interpretation_hooks_produce_around_the_string) {
  if (!python_here()) return;
  vd_error e = {0};
  // StartInterpretation's modules come first (a sphere, a turn), EndInterpretation's last
  vd_plant_spec* p = grow_py("def StartInterpretation():\n  produce @O(0.2) +(90)\n"
                             "def EndInterpretation(turtle):\n  produce @O(0.3)\nAxiom: F(1)\n",
                             &e);
  REQUIRE(p && p->nsphere == 2 && p->nseg == 1);
  CHECK_NEAR(p->sphere[0].radius, 0.2, 1e-12);
  CHECK_NEAR(p->sphere[1].radius, 0.3, 1e-12);
  CHECK_NEAR(p->sphere[1].center.y, -1, 1e-12);  // after F(1) turned toward L = -Y
  vd_plant_spec_destroy(p);
}

TEST(pyengine, hooks_get_the_scene) {
  if (!python_here()) return;
  // End(lstring, lscene): one Shape per primitive, id = the drawing module's index, PlantGL's
  // geometry (a cone when the top radius is 0, a polyline for a zero radius, a placed cylinder)
  const char* src =
      "def End(lstring, lscene):\n"
      "    assert type(lscene) == Scene\n"
      "    ids = sorted(lscene.todict().keys())\n"
      "    assert ids == [0, 2, 3, 4], ids\n"
      "    assert type(lscene[0].geometry) == Cone\n"
      "    assert type(lscene[1].geometry) == Polyline\n"
      "    g = lscene[2].geometry\n"
      "    assert type(g) == Translated and type(g.geometry) == Cylinder and abs(g.translation.z - 2) < 1e-9\n"
      "    assert type(lscene[3].geometry.geometry) == Sphere\n"
      "    return lstring, lscene\n"
      "Axiom: F(1, 0) ; F(1) _(0.5) F(1) @O(1)\n";
  CHECK_PY(src, 1, "F(1,0);F(1)_(0.5)F(1)@O(1)");
}

TEST(pyengine, context_turtle_settings_apply) {
  if (!python_here()) return;
  vd_error e = {0};
  // execContext().turtle.setAngleIncrement(90): + turns 90 degrees, so F + F ends at (0, -1, 1)
  vd_plant_spec* p = grow_py("execContext().turtle.setAngleIncrement(90)\nAxiom: F(1) + F(1)\n", &e);
  REQUIRE(p && p->nseg == 2);
  vd_vec3 end = p->node[p->seg[1].node1];
  CHECK_NEAR(end.x, 0, 1e-12);
  CHECK_NEAR(end.y, -1, 1e-12);
  CHECK_NEAR(end.z, 1, 1e-12);
  vd_plant_spec_destroy(p);
}

TEST(pyengine, point_grids_query_like_brute_force) {
  if (!python_here()) return;
  // Point3Grid's ball and cone queries give the enabled points a search over all of them gives;
  // disabled points are no longer found; each constructor form files every point
  const char* src =
      "import random\n"
      "random.seed(1)\n"
      "P = [Vector3(random.uniform(-5, 5), random.uniform(-5, 5), random.uniform(0, 5)) for i in range(400)]\n"
      "def ball(c, r, on):\n"
      "    return [i for i, p in enumerate(P) if on(i) and norm(p - c) <= r]\n"
      "def cone(o, d, r, a):\n"
      "    d = d.normed()\n"
      "    return [i for i, p in enumerate(P) if norm(p - o) <= r + 1e-5 and norm(p - o) > 0 and\n"
      "            dot((p - o) / norm(p - o), d) > math.cos(a / 2) - 1e-5]\n"
      "import math\n"
      "ok = []\n"
      "for G in (Point3Grid(P, 7), Point3Grid(Vector3(1, 1, 1), P), Point3Grid((0.5, 2, 3), Vector3(-5, -5, 0), Vector3(5, 5, 5), P)):\n"
      "    q = [(Vector3(0, 0, 2), 1.5), (Vector3(4, 4, 4), 3), (Vector3(-9, 0, 0), 2), (Vector3(0, 0, 0), 100)]\n"
      "    ok.append(all(sorted(G.query_ball_point(c, r)) == ball(c, r, lambda i: True) for c, r in q))\n"
      "    ok.append(sorted(G.query_points_in_cone(Vector3(0, 0, 0), Vector3(1, 1, 1), 4, math.radians(60))) ==\n"
      "              cone(Vector3(0, 0, 0), Vector3(1, 1, 1), 4, math.radians(60)))\n"
      "    gone = G.query_ball_point(Vector3(0, 0, 2), 2)\n"
      "    G.disable_points(gone)\n"
      "    ok.append(sorted(G.query_ball_point(Vector3(0, 0, 2), 3)) == ball(Vector3(0, 0, 2), 3, lambda i: i not in gone))\n"
      "    ok.append(len(G.get_enabled_points()) == 400 - len(gone) and not G.is_point_enabled(gone[0]))\n"
      "    G.enable_point(gone[0])\n"
      "    ok.append(G.is_point_enabled(gone[0]) and G.closest_point(P[gone[0]]) == gone[0])\n"
      "Axiom: R(ok.count(True), len(ok), len(gone) > 3)\n";
  CHECK_PY(src, 0, "R(15,15,1)");
}

TEST(pyengine, discretizer_gives_what_the_turtle_draws) {
  if (!python_here()) return;
  vd_error e = {0};
  // a curve discretises to its stride + 1 points, a sphere to the mesh @g draws: the same mesh
  // drawn from the TriangleSet as from the sphere
  const char* src =
      "d = Discretizer()\n"
      "c = NurbsCurve2D([(0, 0, 1), (1, 1, 1), (2, 0, 1)])\n"
      "c.stride = 4\n"
      "ok1 = c.apply(d) and len(d.result.pointList) == 5 and d.result.pointList[4] == Vector2(2, 0)\n"
      "s = Sphere(1, 6, 4)\n"
      "ok2 = s.apply(d) and isinstance(d.result, TriangleSet)\n"
      "Axiom: R(ok1, ok2) @g(s) f(3) @g(d.result)\n";
  char lstr[4096];
  CHECK_STATUS(derive_with(src, VD_LSYS_PYTHON, 0, 0, lstr, sizeof lstr, &e), VD_OK, e);
  CHECK(strncmp(lstr, "R(1,1)@g(", 9) == 0);
  vd_plant_spec* p = grow_py(src, &e);
  REQUIRE(p && p->nmesh == 2);
  CHECK_INT(p->mesh[0].nvert, p->mesh[1].nvert);
  CHECK_INT(p->mesh[0].ntri, p->mesh[1].ntri);
  for (int i = 0; i < p->mesh[0].nvert; i++) {
    vd_vec3 a = p->vert[p->mesh[0].vert_start + i], b = p->vert[p->mesh[1].vert_start + i];
    CHECK_NEAR(b.z - a.z, 3, 1e-12);
    CHECK_NEAR(b.x, a.x, 1e-12);
  }
  vd_plant_spec_destroy(p);
}

TEST(pyengine, table_parameter_sets_and_reload) {
  if (!python_here()) return;
  // openalea.lpy.tableparameterset: the values live in the module's table; reload (imp's and
  // importlib's) gives verdant's openalea modules back
  const char* src =
      "import openalea.lpy.tableparameterset as tp\n"
      "from imp import reload\n"
      "reload(tp)\n"
      "import importlib, openalea.lpy.__lpyfuture__\n"
      "importlib.reload(openalea.lpy.__lpyfuture__)\n"
      "from openalea.lpy.tableparameterset import TableParameterSet as PS\n"
      "from openalea.lpy.parameterset import ParameterSet\n"
      "tp.init_dict_table()\n"
      "def End():\n"
      "    assert len(tp.get_table()) == 1 and not PS(x=1).hasattr('t')\n"
      "Axiom: A(PS(t=0, l=0.5)) B(ParameterSet(n=2))\n"
      "derivation length: 3\n"
      "production:\n"
      "A(p):\n"
      "    p.t += 1\n"
      "    p.l *= 2\n"
      "    produce A(p)\n";
  CHECK_PY(src, -1, "A(TableParameterSet(0,t=3,l=4.0))B(ParameterSet(n=2))");
}

TEST(pyengine, pylab_without_matplotlib_draws_nothing) {
  if (!python_here()) return;
  // a model that plots its data as it grows: the plot shows nothing on the command line
  // (matplotlib's own when installed), numpy's names are pylab's
  CHECK_PY("import pylab as plt\nimport matplotlib.pyplot as p2\n"
           "def StartEach():\n    plt.close()\n    p2.plot([1, 2], [3, 4], '-', linewidth=2)\n    plt.show()\n"
           "Axiom: F(float(plt.sqrt(4)))\nderivation length: 1\nproduction:\nF(x) --> F(x + 1)\n",
           -1, "F(3)");
}

TEST(pyengine, vectors_as_turtle_parameters) {
  if (!python_here()) return;
  vd_error e = {0};
  // @M(Vector3), SetHead(Vector3, Vector3), LineTo((x, y, z), r), @Tp(Vector3): a vector
  // object stands for three numbers, as in L-Py's turtle
  vd_plant_spec* p = grow_py("Axiom: @M(Vector3(1, 2, 3)) SetHead(Vector3(1, 0, 0), Vector3(0, 0, 1)) F(1) "
                             "LineTo((2, 2, 5), 0.2)\n",
                             &e);
  if (!p) {
    char b[600];
    vdt_fail(__FILE__, __LINE__, "%s", vd_error_format(&e, b, sizeof b));
    return;
  }
  REQUIRE(p->nseg == 2);
  vd_vec3 a = p->node[p->seg[0].node0], b = p->node[p->seg[0].node1], c = p->node[p->seg[1].node1];
  CHECK_NEAR(a.x, 1, 1e-12);
  CHECK_NEAR(a.y, 2, 1e-12);
  CHECK_NEAR(a.z, 3, 1e-12);
  CHECK_NEAR(b.x, 2, 1e-12);
  CHECK_NEAR(b.z, 3, 1e-12);
  CHECK_NEAR(c.z, 5, 1e-12);
  CHECK_NEAR(p->seg[1].r1, 0.2, 1e-12);
  vd_plant_spec_destroy(p);
  // a vector that is not three numbers is an error naming the parameter
  p = grow_py("Axiom: @M(Vector2(1, 2)) F(1)\n", &e);
  CHECK(p == NULL);
  CHECK(strstr(e.msg, "parameter 1") != NULL);
  vd_plant_spec_destroy(p);
}

TEST(pyengine, nurbs_volume_maps_the_cube) {
  if (!python_here()) return;
  // control points evenly spaced over a box: the cubic (Bezier) volume is the affine map of the
  // unit cube onto the box (B-splines reproduce linear functions); a lattice moved at one corner
  // moves the points near it
  const char* src =
      "import openalea.plantgl.scenegraph.nurbspatch_nd as nd\n"
      "V = nd.NurbsPatch3D([[[Vector4(2 * i / 3., j / 3., 3 * k / 3., 1) for k in range(4)] for j in range(4)] for i in range(4)])\n"
      "p = V.getPointAt(0.25, 0.5, 0.8)\n"
      "L = nd.NurbsPatch3D([[[(i, j, k + (0.5 if (i, j, k) == (1, 1, 1) else 0)) for k in range(2)] for j in range(2)] for i in range(2)])\n"
      "q = L.getPointAt(1, 1, 0.5)\n"
      "Axiom: R(round(p.x, 12), round(p.y, 12), round(p.z, 12), q.z)\n";
  CHECK_PY(src, 0, "R(0.5,0.5,2.4,0.75)");
}

TEST(pyengine, point_set_directions) {
  if (!python_here()) return;
  // pointset_mean_direction: the normed mean of the unit directions (not of the offsets: a far
  // point counts as much as a near one); findClosestFromSubset among a group or all points
  const char* src =
      "P = [Vector3(10, 0, 0), Vector3(0, 1, 0), Vector3(0, 0, 5), Vector3(1, 1, 0)]\n"
      "d = pointset_mean_direction(Vector3(0, 0, 0), P, [0, 1])\n"
      "a = pointset_mean_direction((0, 0, 0), P)\n"
      "c = findClosestFromSubset(Vector3(0.9, 0.9, 0), P, [0, 2])\n"
      "Axiom: R(round(d.x, 12), round(d.y, 12), round(norm(a), 12), c[0], findClosestFromSubset((1, 1, 0.1), P)[0])\n";
  CHECK_PY(src, 0, "R(0.707106781187,0.707106781187,1,2,3)");
}

TEST(pyengine, plantgl_names_the_shim_lacks_are_refused) {
  if (!python_here()) return;
  char b[256];
  vd_error e = {0};
  // hasattr sees an AttributeError; using the name refuses the file, naming it
  CHECK_PY("import openalea.plantgl.all as pgl\nAxiom: R(hasattr(pgl, 'Grid3Indexing'), hasattr(pgl, 'Box'))\n", 0,
           "R(0,1)");
  CHECK_STATUS(derive_with("import openalea.plantgl.all as pgl\ng = pgl.Grid3Indexing((1, 1, 1))\nAxiom: A\n",
                           VD_LSYS_PYTHON, 0, 0, b, sizeof b, &e),
               VD_ERR_UNSUPPORTED, e);
  CHECK(strstr(e.msg, "openalea.plantgl.all.Grid3Indexing") != NULL);
  CHECK_INT(e.line, 2);
}
