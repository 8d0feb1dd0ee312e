// SPDX-License-Identifier: MIT
// A tiny test harness: TEST(group, name) registers a test at load time; CHECK records a failure
// and goes on, REQUIRE returns from the test. Every test must give back all the memory it took
// through the verdant allocator.
#ifndef VERDANT_TEST_H
#define VERDANT_TEST_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "verdant/core.h"

typedef void (*vdt_fn)(void);
void vdt_register(const char* group, const char* name, vdt_fn fn);
void vdt_fail(const char* file, int line, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));
// Path of a file under the source tree (static buffer rotation of 8).
const char* vdt_path(const char* rel);
// Scratch directory for this test run (created once).
const char* vdt_tmpdir(void);
// Install an allocator that lets `budget` more allocations succeed, then fails every one.
void vdt_oom_begin(int64_t budget);
// Restore the libc allocator after vdt_oom_begin.
void vdt_oom_end(void);
// Compile the spec s and free it; the model, or NULL when it does not compile.
struct vd_plant_spec;
struct vd_model;
struct vd_model* vdt_compile(struct vd_plant_spec* s);

#define TEST(group, name)                                                                          \
  static void test_##group##_##name(void);                                                         \
  __attribute__((constructor)) static void reg_##group##_##name(void) {                            \
    vdt_register(#group, #name, test_##group##_##name);                                            \
  }                                                                                                \
  static void test_##group##_##name(void)

#define CHECK(c)                                                                                   \
  do {                                                                                             \
    if (!(c)) vdt_fail(__FILE__, __LINE__, "CHECK(%s)", #c);                                       \
  } while (0)
#define REQUIRE(c)                                                                                 \
  do {                                                                                             \
    if (!(c)) {                                                                                    \
      vdt_fail(__FILE__, __LINE__, "REQUIRE(%s)", #c);                                             \
      return;                                                                                      \
    }                                                                                              \
  } while (0)
#define CHECK_INT(a, b)                                                                            \
  do {                                                                                             \
    long long va_ = (long long)(a), vb_ = (long long)(b);                                          \
    if (va_ != vb_) vdt_fail(__FILE__, __LINE__, "%s == %lld, expected %lld", #a, va_, vb_);       \
  } while (0)
#define CHECK_NEAR(a, b, tol)                                                                      \
  do {                                                                                             \
    double va_ = (double)(a), vb_ = (double)(b);                                                   \
    if (!(fabs(va_ - vb_) <= (tol)))                                                               \
      vdt_fail(__FILE__, __LINE__, "%s == %.17g, expected %.17g (tol %g)", #a, va_, vb_,           \
               (double)(tol));                                                                     \
  } while (0)
#define CHECK_STR(a, b)                                                                            \
  do {                                                                                             \
    const char *va_ = (a), *vb_ = (b);                                                             \
    if (!va_ || strcmp(va_, vb_) != 0)                                                             \
      vdt_fail(__FILE__, __LINE__, "%s == \"%s\", expected \"%s\"", #a, va_ ? va_ : "(null)", vb_); \
  } while (0)
// Check a call's status; on mismatch print the error record e (a vd_error).
#define CHECK_STATUS(call, expected, e)                                                            \
  do {                                                                                             \
    vd_status st_ = (call);                                                                        \
    if (st_ != (expected)) {                                                                       \
      char eb_[1024];                                                                              \
      vdt_fail(__FILE__, __LINE__, "%s -> %s, expected %s (%s)", #call, vd_status_str(st_),         \
               vd_status_str(expected), vd_error_format(&(e), eb_, sizeof eb_));                   \
    }                                                                                              \
  } while (0)

#endif
