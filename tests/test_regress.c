// SPDX-License-Identifier: MIT
// regress: inputs found by the fuzz targets (fuzz/), minimised, fed through the same path as
// the target that found them. Each asserts the status code; before its fix each one crashed,
// hung, leaked or tripped a sanitizer. docs/reliability.md lists them with their root causes.
#include <stdlib.h>

#include "test.h"
#include "verdant/verdant.h"

// stop a derivation after 3 steps (fuzz_lsys derives min(3, the file's length) steps)
static int stop_after_3(void* user, int step, int steps, int64_t modules) {
  (void)user;
  (void)steps;
  (void)modules;
  return step >= 3;
}

// fuzz_lsys's path: parse, derive, interpret, turtle, compile; the first failing status
static vd_status lsys_path(const char* src, size_t len) {
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  vd_status st = vd_lsys_parse(src, len, "regress.lpy", &ls, &err);
  if (st) return st;
  vd_lsys_def def = vd_lsys_def_default();
  def.progress = stop_after_3;
  def.max_modules = 20000;
  def.max_ops = 100000;
  vd_lstring derived = vd_lstring_empty(), interp = vd_lstring_empty();
  st = vd_lsys_derive(ls, &def, &derived, &err);
  if (!st) st = vd_lsys_interpret(ls, &def, &derived, &interp, &err);
  if (!st) {
    vd_plant_spec* plant = vd_plant_spec_create();
    vd_turtle_def tdef = vd_turtle_def_default();
    st = plant ? vd_turtle_run(ls, &interp, &tdef, plant, &err) : VD_ERR_NOMEM;
    vd_model* m = NULL;
    if (!st) st = vd_plant_compile(plant, &m, &err);
    vd_model_destroy(m);
    vd_plant_spec_destroy(plant);
  }
  (void)vd_lsys_derivation_length(ls);
  vd_lstring_free(&interp);
  vd_lstring_free(&derived);
  vd_lsys_destroy(ls);
  return st;
}

// fuzz_expr's path: `Axiom: A(<expr>)` derived one step
static vd_status expr_path(const char* e) {
  char src[4200];
  snprintf(src, sizeof src, "Axiom: A(%s)\n", e);
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  vd_status st = vd_lsys_parse(src, strlen(src), "expr.lpy", &ls, &err);
  if (st) return st;
  vd_lsys_def def = vd_lsys_def_default();
  def.steps = 1;
  def.max_modules = 20000;
  def.max_ops = 100000;
  vd_lstring s = vd_lstring_empty();
  st = vd_lsys_derive(ls, &def, &s, &err);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return st;
}

#define LSYS(src) lsys_path(src, strlen(src))

// ---------------------------------------------------------------------------------------------
// interpreter work limit (vd_lsys_def.max_ops)

TEST(regress, while_true_stops_at_work_limit) {
  // took the whole 1e8-iteration loop limit (~10 s under ASan): a fuzzer timeout
  CHECK_INT(LSYS("Axiom: A\nproduction:\nA :\n  while True:\n    pass\n"), VD_ERR_LIMIT);
}

TEST(regress, nested_loops_stop_at_work_limit) {
  // the per-loop limit did not bound nested loops (1e16 iterations)
  CHECK_INT(LSYS("Axiom:\n  for i in range(100000000):\n    for j in range(100000000):\n      pass\n"),
            VD_ERR_LIMIT);
}

TEST(regress, recursive_fanout_stops_at_work_limit) {
  // depth 60 is under the recursion limit, but two calls per level are 2^60 calls
  CHECK_INT(LSYS("def f(n):\n  if n == 0: return 0\n  return f(n - 1) + f(n - 1)\nAxiom: A(f(60))\n"),
            VD_ERR_LIMIT);
}

TEST(regress, range_with_huge_start_terminates) {
  // i += 1 rounds back to i above 2^53: the loop never ended; now iterations are counted
  CHECK_INT(LSYS("Axiom:\n  for i in range(100000000000000000, 100000000000000010):\n    pass\n  produce A\n"), VD_OK);
  CHECK_INT(LSYS("Axiom:\n  for i in range(100000000000000000, 100000000000000010):\n    nproduce B\n"), VD_OK);
  CHECK_INT(expr_path("1"), VD_OK);
}

// ---------------------------------------------------------------------------------------------
// parser

TEST(regress, group_number_at_end_of_text) {
  // strtol read past the end of a text whose last line is `group N` (heap-buffer-overflow)
  const char src[] = {'A', 'x', 'i', 'o', 'm', ':', ' ', 'A', '\n', 'g', 'r', 'o', 'u', 'p', ' ', '1', '2'};
  char* exact = malloc(sizeof src);  // exactly sized, as the fuzzer's buffer
  REQUIRE(exact);
  memcpy(exact, src, sizeof src);
  CHECK_INT(lsys_path(exact, sizeof src), VD_ERR_SYNTAX);
  free(exact);
  CHECK_INT(LSYS("Axiom: A\nproduction:\ngroup :\nA --> B\n"), VD_ERR_SYNTAX);
  CHECK_INT(LSYS("Axiom: A\nproduction:\ngroup   2 :\nA --> B\nendgroup\n"), VD_OK);
}

// ---------------------------------------------------------------------------------------------
// numbers converted to integers (UBSan: value outside the range of the integer type)

TEST(regress, random_builtins_with_huge_arguments) {
  CHECK_INT(expr_path("randint(1e300, 1e301)"), VD_ERR_VALUE);
  CHECK_INT(expr_path("randint(-9e18, 9e18)"), VD_ERR_VALUE);
  CHECK_INT(expr_path("randrange(1e300)"), VD_ERR_VALUE);
  CHECK_INT(expr_path("randrange(0, 1e300, 3)"), VD_ERR_VALUE);
  CHECK_INT(expr_path("seed(1e300)"), VD_ERR_UNSUPPORTED);
  CHECK_INT(expr_path("randint(-2**53, 2**53), randrange(-2**53, 2**53), seed(2**63) or 1"), VD_OK);
  // the generator itself over the whole int64 range
  vd_rng r;
  vd_rng_seed(&r, 1);
  int64_t v = vd_rng_randint(&r, INT64_MIN, INT64_MAX);
  (void)v;
  CHECK(vd_rng_randint(&r, -5, -5) == -5);
}

TEST(regress, use_group_with_huge_number) {
  CHECK_INT(expr_path("useGroup(1e300)"), VD_ERR_VALUE);
  CHECK_INT(expr_path("useGroup(2) or 1"), VD_OK);
}

TEST(regress, derivation_length_out_of_int_range) {
  CHECK_INT(LSYS("Axiom: A\nderivation length: 1e300\n"), VD_ERR_VALUE);
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  const char* src = "Axiom: A\nderivation length: 1e300\n";
  REQUIRE(vd_lsys_parse(src, strlen(src), "t", &ls, &err) == VD_OK);
  CHECK_INT(vd_lsys_derivation_length(ls), 1);
  vd_lsys_destroy(ls);
}

// ---------------------------------------------------------------------------------------------
// out of memory at every allocation of the lsys path (the fuzz targets never fail an allocation)

// an allocator that fails once a budget of allocations is spent
static int64_t oom_budget;
static void* oom_realloc(void* user, void* ptr, size_t old_size, size_t new_size) {
  (void)user;
  (void)old_size;
  if (new_size == 0) {
    free(ptr);
    return NULL;
  }
  if (oom_budget-- <= 0) return NULL;
  return realloc(ptr, new_size);
}

TEST(regress, lsys_out_of_memory_sweep) {
  const char* src =
      "LABELS = {1: 'stem', 2: 'leaf', 3: 'fruit'}\n"
      "module Apex, Leaf\n"
      "def f(x):\n"
      "  return x * 2\n"
      "Axiom: Apex(1) A('s')\n"
      "derivation length: 2\n"
      "ignore: +\n"
      "production:\n"
      "Apex(x) --> F(f(x)) [ +(30) Leaf(x) ] Apex(x + 1)\n"
      "F(x) < Leaf(y) :\n"
      "  for i in range(2):\n"
      "    nproduce Leaf(y + i)\n"
      "A(s) --> A(s + 't')\n"
      "group 1:\n"
      "Leaf(y) --> %\n"
      "endgroup\n"
      "decomposition:\n"
      "Leaf(y) --> ~l(y)\n"
      "interpretation:\n"
      "Apex(x) --> @O(x)\n"
      "endlsystem\n"
      "###### INITIALISATION ######\n"
      "def __initialiseContext__(context):\n"
      "\tscalars = [('n', 'Integer', 8, 0, 20)]\n"
      "\tcontext[\"__scalars__\"] = scalars\n";
  int64_t start = vd_alloc_bytes();
  int done = 0;
  for (int64_t b = 0; b < 5000 && !done; b++) {
    oom_budget = b;
    vd_set_allocator(oom_realloc, NULL);
    vd_status st = LSYS(src);
    vd_set_allocator(NULL, NULL);
    done = st == VD_OK;
    if (st != VD_OK && st != VD_ERR_NOMEM) {
      vdt_fail(__FILE__, __LINE__, "budget %lld: %s", (long long)b, vd_status_str(st));
      break;
    }
    if (vd_alloc_bytes() != start) {
      vdt_fail(__FILE__, __LINE__, "budget %lld: %lld bytes not given back", (long long)b,
               (long long)(vd_alloc_bytes() - start));
      break;
    }
  }
  CHECK(done);
}

// ---------------------------------------------------------------------------------------------
// strings made at run time

// derive with the default settings (work limit 1e10); the status
static vd_status derive_default(const char* src) {
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  vd_status st = vd_lsys_parse(src, strlen(src), "regress.lpy", &ls, &err);
  if (st) return st;
  vd_lstring s = vd_lstring_empty();
  st = vd_lsys_derive(ls, NULL, &s, &err);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return st;
}

TEST(regress, strings_built_in_a_loop) {
  // every s + str(i) interned its result after a linear search of all strings (each up to 2 KiB):
  // minutes for this loop, and the table grew without bound. Now strings are hashed, a
  // concatenation costs one operation per 64 bytes, and all strings are limited to 64 MiB.
  CHECK_INT(LSYS("s = 'ab'\nAxiom:\n  global s\n  for i in range(50000):\n    s = s + str(i)\n  produce A(s)\n"),
            VD_ERR_LIMIT);
  // 40000 distinct strings of ~1.9 KiB pass the 64 MiB limit (under the default work limit)
  CHECK_INT(derive_default("Axiom:\n  a = 'abcdefghij'\n  for k in range(6):\n    a = a + a\n  b = a + a + a\n"
                           "  for i in range(40000):\n    c = b + str(i)\n  produce A(c)\n"),
            VD_ERR_LIMIT);
  // the same string again is found, not added
  CHECK_INT(LSYS("Axiom:\n  for i in range(5000):\n    nproduce A('x' + 'y', str(i % 7))\n"), VD_OK);
}

// ---------------------------------------------------------------------------------------------
// cloud readers

// F10 (fuzz_cloud, UBSan signed overflow): an XYZ cloud naming a label with a large id gave the
// label its organ colour through id * 37 in int arithmetic
TEST(regress, large_label_id_colour) {
  static const char xyz[] = "# 2 : leaf\n# label 63661737 flower\n0 0 0 63661737 1\n";
  vd_cloud c;
  vd_error err = {0};
  vd_status st = vd_cloud_parse(xyz, sizeof xyz - 1, VD_CLOUD_XYZ, "regress.xyz", &c, &err);
  if (st == VD_OK) vd_cloud_free(&c);
  // every id a label can have gets a colour (the sanitizer build checks the arithmetic)
  static const int ids[] = {0, 6, 7, 65535, 63661737, 2147483647};
  for (int k = 0; k < 6; k++) {
    vd_label l;
    vd_label_init(&l, ids[k], "flower");
    for (int j = 0; j < 3; j++) CHECK(l.rgb[j] >= 0 && l.rgb[j] <= 1);
  }
}
