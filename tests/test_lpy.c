// SPDX-License-Identifier: MIT
// lpy: compatibility with L-Py's semantics (openalea/lpy): results that used to be silently
// wrong, the grammar beyond the basics (contexts, patterns, hooks, the L-string object) and the
// refusals of what the native engine does not run. Every L-Py text here is our own.
#include <stdlib.h>

#include "test.h"
#include "verdant/lsys.h"

// parse and derive src (steps -1 = the file's), format the result into buf
static vd_status derive_text(const char* src, int steps, char* buf, size_t cap, vd_error* e) {
  vd_lsystem* ls;
  buf[0] = 0;
  vd_status st = vd_lsys_parse(src, strlen(src), "t.lpy", &ls, e);
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

#define DERIVES(src, steps, expected)                                                              \
  do {                                                                                             \
    char b_[4096];                                                                                 \
    vd_error e_ = {0};                                                                             \
    CHECK_STATUS(derive_text(src, steps, b_, sizeof b_, &e_), VD_OK, e_);                          \
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
