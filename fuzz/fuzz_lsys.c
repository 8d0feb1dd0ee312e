// SPDX-License-Identifier: MIT
// libFuzzer target: an .lpy file through the whole L-system path. Parse, derive a few steps
// under a small module limit, interpret, run the turtle into a plant spec and compile it; every
// object is freed and the verdant allocator must be back where it started. The native engine only:
// fuzz input is never run as Python.
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

// progress hook: stop after 3 steps, so a derivation runs min(3, the file's length) steps
static int stop_after_3(void* user, int step, int steps, int64_t modules) {
  (void)user;
  (void)steps;
  (void)modules;
  return step >= 3;
}

FUZZ_DEFAULT_INITIALIZE

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_lsystem* ls = NULL;
  // parse: any status is fine, only a crash or a leak is a finding
  if (vd_lsys_parse_engine((const char*)data, size, "fuzz.lpy", VD_LSYS_NATIVE, &ls, &err) == VD_OK) {
    // derive the file's derivation length, stopped after 3 steps, under small work limits
    vd_lsys_def def = vd_lsys_def_default();
    def.steps = -1;
    def.progress = stop_after_3;
    def.max_modules = 20000;
    def.max_ops = 100000;
    vd_lstring derived = vd_lstring_empty(), interp = vd_lstring_empty();
    vd_status st = vd_lsys_derive(ls, &def, &derived, &err);
    if (!st) st = vd_lsys_interpret(ls, &def, &derived, &interp, &err);
    // turtle into a plant spec, then compile it
    if (!st) {
      vd_plant_spec* plant = vd_plant_spec_create();
      vd_turtle_def tdef = vd_turtle_def_default();
      if (plant && vd_turtle_run(ls, &interp, &tdef, plant, &err) == VD_OK) {
        vd_model* m = NULL;
        if (vd_plant_compile(plant, &m, &err) == VD_OK) vd_model_destroy(m);
      }
      vd_plant_spec_destroy(plant);
    }
    (void)vd_lsys_derivation_length(ls);
    vd_lstring_free(&interp);
    vd_lstring_free(&derived);
    vd_lsys_destroy(ls);
  }
  fuzz_check_leak(before, "lsys");
  return 0;
}
