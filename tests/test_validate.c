// SPDX-License-Identifier: MIT
// validate: every analytic reference case at the quick sizes passes (the same cases as
// `verdant validate`), split in groups so a failure names its family.
#include "test.h"
#include "verdant/sim.h"

static void run(const char* filter, int min_results) {
  vd_validate_def def = {0};
  def.filter = filter;
  vd_validate_result* r = NULL;
  int n = 0;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_validate(&def, &r, &n, &e), VD_OK, e);
  CHECK(n >= min_results);
  for (int k = 0; k < n; k++) {
    if (!r[k].pass)
      vdt_fail(__FILE__, __LINE__, "%s (%s, %s): measured %.9g, reference %.9g, error %.3g > %.3g (%s)", r[k].name,
               r[k].form, r[k].quantity, r[k].measured, r[k].reference, r[k].error, r[k].tolerance, r[k].note);
    CHECK(isfinite(r[k].error));
  }
  vd_free(r, (size_t)n * sizeof *r);
}

TEST(validate, cantilever) { run("cantilever", 10); }
TEST(validate, shear_torsion) {
  run("timoshenko", 2);
  run("torsion", 3);
}
TEST(validate, large_deflection) { run("large_deflection", 12); }
TEST(validate, frequency) { run("frequency", 5); }
TEST(validate, buckling) { run("buckling", 4); }
TEST(validate, fracture) { run("fracture", 2); }
TEST(validate, contacts) { run("no_penetration", 6); }
TEST(validate, independence) {
  run("independence", 3);
  run("discretisation", 2);
}
TEST(validate, sag_free) { run("sag_free", 3); }
TEST(validate, filter_and_empty) {
  vd_validate_def def = {0};
  def.filter = "no case has this name";
  vd_validate_result* r = NULL;
  int n = -1;
  vd_error e = {0};
  CHECK_STATUS(vd_sim_validate(&def, &r, &n, &e), VD_OK, e);
  CHECK_INT(n, 0);
  CHECK(r == NULL);
}
