// SPDX-License-Identifier: MIT
// core: status/error formatting, allocator accounting, arena, rng (against CPython's random),
// vector and quaternion math, atomic files.
#include <stdlib.h>

#include "test.h"

TEST(core, error_format) {
  vd_error e = {0};
  char buf[256];
  CHECK_INT(vd_error_set(&e, VD_ERR_SYNTAX, "a.lpy", 3, 7, "expected %s", "':'"), VD_ERR_SYNTAX);
  CHECK_STR(vd_error_format(&e, buf, sizeof buf), "a.lpy:3:7: expected ':'");
  // the first error is kept
  vd_error_set(&e, VD_ERR_IO, "b", 1, 1, "later");
  CHECK_INT(e.status, VD_ERR_SYNTAX);
  CHECK_STR(vd_status_str(VD_ERR_LIMIT), "limit exceeded");
  CHECK_STR(vd_status_str((vd_status)999), "unknown status");
}

// a quoted line of a binary file must not put raw bytes on the user's terminal
TEST(core, error_message_printable) {
  vd_error e = {0};
  char buf[600];
  vd_error_set(&e, VD_ERR_FORMAT, "b.pcd", 1, 0, "unknown header line '%s'", "\xfa\x01ok \xc3\xa9t\xc3\xa9\x7f");
  CHECK_STR(vd_error_format(&e, buf, sizeof buf), "b.pcd:1: unknown header line '\\xfa\\x01ok \xc3\xa9t\xc3\xa9\\x7f'");
  // a long binary message is cut, never overflows
  char big[400];
  memset(big, 0xff, sizeof big - 1);
  big[sizeof big - 1] = 0;
  vd_error e2 = {0};
  vd_error_set(&e2, VD_ERR_FORMAT, "", 0, 0, "%s", big);
  CHECK(strlen(e2.msg) < sizeof e2.msg);
  CHECK(strncmp(e2.msg, "\\xff\\xff", 8) == 0);
}

TEST(core, alloc_counts_bytes) {
  int64_t b0 = vd_alloc_bytes();
  void* p = vd_malloc(100);
  CHECK_INT(vd_alloc_bytes() - b0, 100);
  p = vd_realloc(p, 100, 300);
  CHECK_INT(vd_alloc_bytes() - b0, 300);
  vd_free(p, 300);
  CHECK_INT(vd_alloc_bytes() - b0, 0);
  CHECK(vd_calloc((size_t)-1, 16) == NULL);
  int* arr = NULL;
  int cap = 0;
  REQUIRE(vd_grow((void**)&arr, &cap, 1000, sizeof(int)));
  CHECK(cap >= 1000);
  vd_free(arr, (size_t)cap * sizeof(int));
}

TEST(core, allocator_hook_out_of_memory) {
  vdt_oom_begin(1);
  void* a = vd_malloc(10);
  void* b = vd_malloc(10);
  vdt_oom_end();
  CHECK(a != NULL);
  CHECK(b == NULL);
  vd_free(a, 10);
}

TEST(core, arena) {
  vd_arena a;
  vd_arena_init(&a, 256);
  char* p = vd_arena_alloc(&a, 100);
  char* q = vd_arena_alloc(&a, 1000);  // larger than a block
  REQUIRE(p && q);
  CHECK(((uintptr_t)p & 15) == 0 && ((uintptr_t)q & 15) == 0);
  memset(q, 1, 1000);
  vd_arena_reset(&a);
  CHECK_INT(a.used, 0);
  CHECK(vd_arena_alloc(&a, 500) != NULL);
  vd_arena_free(&a);
}

TEST(core, rng_matches_cpython) {
  // reference values printed by CPython 3.11: random.seed(42); random.random() ...
  vd_rng r;
  vd_rng_seed(&r, 42);
  CHECK(vd_rng_random(&r) == 0.6394267984578837);
  CHECK(vd_rng_random(&r) == 0.025010755222666936);
  CHECK(vd_rng_random(&r) == 0.27502931836911926);
  vd_rng_seed(&r, 42);
  CHECK(vd_rng_uniform(&r, 2, 5) == 3.9182803953736514);
  CHECK(vd_rng_gauss(&r, 1, 2) == 2.5842894818995816);
  CHECK(vd_rng_gauss(&r, 1, 2) == 1.2510365514065214);
  CHECK_INT(vd_rng_randint(&r, 1, 6), 2);
  CHECK_INT(vd_rng_randint(&r, 0, 1000000), 146316);
  vd_rng_seed(&r, ((uint64_t)1 << 40) + 7);
  CHECK(vd_rng_random(&r) == 0.6137037779936511);
  vd_rng_seed(&r, 0);
  CHECK(vd_rng_random(&r) == 0.8444218515250481);
}

TEST(core, rng_streams_independent_and_reproducible) {
  vd_rng a, b, c;
  vd_rng_stream(&a, 7, 3);
  vd_rng_stream(&b, 7, 3);
  vd_rng_stream(&c, 7, 4);
  int same = 1, diff = 0;
  for (int i = 0; i < 100; i++) {
    uint32_t x = vd_rng_u32(&a), y = vd_rng_u32(&b), z = vd_rng_u32(&c);
    same &= x == y;
    diff += x != z;
  }
  CHECK(same);
  CHECK(diff > 90);
}

// vd_rng_fill (pairs of words taken straight from the state) gives what vd_rng_random gives,
// whatever the state's position, odd ones and refills included
TEST(core, rng_fill_matches_random) {
  int same = 1;
  for (int skip = 0; skip < 5; skip++) {
    vd_rng a, b;
    vd_rng_stream(&a, 11, (uint64_t)skip);
    b = a;
    for (int k = 0; k < skip * 301; k++)
      (void)vd_rng_u32(&a), (void)vd_rng_u32(&b);
    if (skip % 2) (void)vd_rng_u32(&a), (void)vd_rng_u32(&b);
    double buf[1000];
    for (int round = 0; round < 3; round++) {
      int n = round == 0 ? 1 : round == 1 ? 333 : 1000;
      vd_rng_fill(&a, buf, n);
      for (int i = 0; i < n; i++)
        same &= buf[i] == vd_rng_random(&b);
    }
    same &= vd_rng_u32(&a) == vd_rng_u32(&b);
  }
  CHECK(same);
}

TEST(core, rotate_and_quat) {
  vd_vec3 v = vd_rotate(vd_v3(1, 0, 0), vd_v3(0, 0, 1), VD_PI / 2);
  CHECK_NEAR(v.x, 0, 1e-15);
  CHECK_NEAR(v.y, 1, 1e-15);
  vd_quat q = vd_quat_axis_angle(vd_v3(0, 0, 1), VD_PI / 2);
  vd_vec3 w = vd_quat_rotate(q, vd_v3(1, 0, 0));
  CHECK_NEAR(w.y, 1, 1e-15);
  vd_quat f = vd_quat_from_axes(vd_v3(0, 1, 0), vd_v3(-1, 0, 0), vd_v3(0, 0, 1));
  vd_vec3 u = vd_quat_rotate(f, vd_v3(1, 0, 0));
  CHECK_NEAR(u.y, 1, 1e-12);
  vd_quat id = vd_quat_mul(q, vd_quat_conj(q));
  CHECK_NEAR(id.w, 1, 1e-15);
}

// quartiles by linear interpolation (numpy.quantile's default): the values below are numpy's
TEST(core, quantiles_interpolate) {
  const double two[2] = {1, 3};  // the old rule gave q25 = median = q75 = 1
  CHECK_NEAR(vd_quantile_sorted(two, 2, 0.25), 1.5, 1e-15);
  CHECK_NEAR(vd_quantile_sorted(two, 2, 0.5), 2, 1e-15);
  CHECK_NEAR(vd_quantile_sorted(two, 2, 0.75), 2.5, 1e-15);
  const double four[4] = {1, 2, 3, 4};
  CHECK_NEAR(vd_quantile_sorted(four, 4, 0.25), 1.75, 1e-15);
  CHECK_NEAR(vd_quantile_sorted(four, 4, 0.75), 3.25, 1e-15);
  // six forces: the median is the mean of the middle two (1.51442, not the lower 1.49974)
  const double six[6] = {1.2, 1.41, 1.49974, 1.5291, 1.6, 1.75};
  CHECK_NEAR(vd_quantile_sorted(six, 6, 0.5), 1.51442, 1e-12);
  CHECK_NEAR(vd_quantile_sorted(six, 6, 0.25), 1.41 + 0.25 * (1.49974 - 1.41), 1e-12);
  const double one[1] = {7};
  CHECK_NEAR(vd_quantile_sorted(one, 1, 0.25), 7, 0);
  CHECK_NEAR(vd_quantile_sorted(one, 1, 1), 7, 0);
  CHECK_NEAR(vd_quantile_sorted(four, 4, 0), 1, 0);
  CHECK_NEAR(vd_quantile_sorted(four, 4, 1), 4, 0);
}

TEST(core, atomic_file) {
  char path[512];
  snprintf(path, sizeof path, "%s/atomic.txt", vdt_tmpdir());
  vd_error e = {0};
  vd_outfile f;
  CHECK_STATUS(vd_outfile_open(&f, path, &e), VD_OK, e);
  fputs("hello", f.fp);
  FILE* probe = fopen(path, "rb");
  CHECK(probe == NULL);  // nothing at the final name before commit
  if (probe) fclose(probe);
  CHECK_STATUS(vd_outfile_commit(&f, &e), VD_OK, e);
  char* text;
  size_t len;
  CHECK_STATUS(vd_file_read(path, &text, &len, &e), VD_OK, e);
  CHECK_INT(len, 5);
  CHECK_STR(text, "hello");
  vd_free(text, len + 1);
  // abort leaves nothing
  snprintf(path, sizeof path, "%s/aborted.txt", vdt_tmpdir());
  CHECK_STATUS(vd_outfile_open(&f, path, &e), VD_OK, e);
  vd_outfile_abort(&f);
  CHECK(fopen(path, "rb") == NULL);
  vd_error e2 = {0};
  CHECK_STATUS(vd_outfile_open(&f, "/nonexistent-dir/x.txt", &e2), VD_ERR_IO, e2);
  vd_error e3 = {0};
  CHECK_STATUS(vd_file_read("/nonexistent-file", &text, &len, &e3), VD_ERR_IO, e3);
}
