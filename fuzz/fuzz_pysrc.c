// SPDX-License-Identifier: MIT
// libFuzzer target: an .lpy file read for the Python engine. The parser's rule structure, the
// translation of the file's Python (produce statements, templates, rule bodies, the trailer) and
// CPython's compile of it; nothing is run (fuzz input is never executed as Python). Every object
// is freed and the verdant allocator must be back where it started.
#include "fuzz_common.h"

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  fuzz_install_allocator();
  vd_set_assert_handler(fuzz_assert);
  char why[256];
  if (!vd_lsys_python_available(why, sizeof why)) {
    fprintf(stderr, "fuzz_pysrc: no Python engine here: %s\n", why);
    exit(2);
  }
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_lsystem* ls = NULL;
  if (vd_lsys_parse_engine((const char*)data, size, "fuzz.lpy", VD_LSYS_PYTHON, &ls, &err) == VD_OK) {
    (void)vd_lsys_symbol_count(ls);
    vd_lsys_destroy(ls);
  }
  fuzz_check_leak(before, "pysrc");
  return 0;
}
