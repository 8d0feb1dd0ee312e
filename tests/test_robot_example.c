// SPDX-License-Identifier: MIT
// robot.h's usage example as written in the header (cut out by the build into
// robot_example.inc): it compiles against the public headers alone and runs from the source
// folder, an external controller's steps and then the scripted method on the bundled tomato.
#include <string.h>
#include <unistd.h>

#include "test.h"
#include "verdant/verdant.h"

// the example, its checks on what it left behind
static void run_example(vd_status* st, char* reason, size_t cap, int64_t* steps) {
#include "robot_example.inc"
  *st = err.status;
  snprintf(reason, cap, "%s", sum.reason);
  *steps = sum.steps;
}

TEST(robot_example, header_example_runs) {
  char cwd[4096];
  REQUIRE(getcwd(cwd, sizeof cwd));
  REQUIRE(chdir(VD_SOURCE_DIR) == 0);
  vd_status st;
  char reason[128];
  int64_t steps;
  run_example(&st, reason, sizeof reason, &steps);
  REQUIRE(chdir(cwd) == 0);
  CHECK_INT(st, VD_OK);
  CHECK(steps > 0);
  CHECK_STR(reason, "detached");
}
