// SPDX-License-Identifier: MIT
// harden: resource limits (derivation work, file size).
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "test.h"
#include "verdant/verdant.h"

// ---------------------------------------------------------------------------------------------
// limits

// a derivation that only lengthens its string: each step reads every module, so many steps
// stop at the work limit instead of running for hours (before: -n 1e9 on the tomato never ended)
TEST(harden, long_derivation_stops_at_work_limit) {
  const char* src = "Axiom: A\nproduction:\nA --> AB\n";
  vd_lsystem* ls = NULL;
  vd_error e = {0};
  REQUIRE(vd_lsys_parse(src, strlen(src), "grow.lpy", &ls, &e) == VD_OK);
  vd_lsys_def def = vd_lsys_def_default();
  def.steps = 1000000000;
  def.max_ops = 1000000;
  vd_lstring out = vd_lstring_empty();
  CHECK_STATUS(vd_lsys_derive(ls, &def, &out, &e), VD_ERR_LIMIT, e);
  CHECK(strstr(e.msg, "modules rewritten") != NULL);
  vd_lstring_free(&out);
  vd_lsys_destroy(ls);
}

// a file larger than VD_FILE_MAX is refused from its size, before anything is read
TEST(harden, huge_file_refused_before_reading) {
  char path[512];
  snprintf(path, sizeof path, "%s/huge.lpy", vdt_tmpdir());
  int fd = open(path, O_CREAT | O_WRONLY | O_TRUNC, 0600);
  REQUIRE(fd >= 0);
  int ok = ftruncate(fd, (off_t)VD_FILE_MAX + 4096) == 0;  // sparse: no disk used
  close(fd);
  REQUIRE(ok);
  char* text = NULL;
  size_t len = 0;
  vd_error e = {0};
  int64_t before = vd_alloc_bytes();
  CHECK_STATUS(vd_file_read(path, &text, &len, &e), VD_ERR_LIMIT, e);
  CHECK(text == NULL && vd_alloc_bytes() == before);
  vd_lsystem* ls = NULL;
  vd_error e2 = {0};
  CHECK_STATUS(vd_lsys_load(path, &ls, &e2), VD_ERR_LIMIT, e2);
  unlink(path);
}

