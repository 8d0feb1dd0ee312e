// SPDX-License-Identifier: MIT
// libFuzzer target: the expression evaluator through the public API. The input becomes the
// parameter list of the axiom, `Axiom: A(<input>)` on one line (newlines removed), and is
// derived one step, so the expression parser and the evaluator see it.
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

FUZZ_DEFAULT_INITIALIZE

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // wrap the input (the buffer is plain malloc: not counted by the verdant allocator)
  static const char head[] = "Axiom: A(", tail[] = ")\n";
  char* text = malloc(sizeof head + size + sizeof tail);
  if (!text) return 0;
  size_t len = 0;
  memcpy(text, head, sizeof head - 1);
  len = sizeof head - 1;
  for (size_t i = 0; i < size; i++)
    if (data[i] != '\n' && data[i] != '\r') text[len++] = (char)data[i];
  memcpy(text + len, tail, sizeof tail - 1);
  len += sizeof tail - 1;

  int64_t before = vd_alloc_bytes();
  vd_error err = {0};
  vd_lsystem* ls = NULL;
  if (vd_lsys_parse_engine(text, len, "expr.lpy", VD_LSYS_NATIVE, &ls, &err) == VD_OK) {
    vd_lsys_def def = vd_lsys_def_default();
    def.steps = 1;
    def.max_modules = 20000;
    def.max_ops = 100000;
    vd_lstring s = vd_lstring_empty();
    (void)vd_lsys_derive(ls, &def, &s, &err);
    vd_lstring_free(&s);
    vd_lsys_destroy(ls);
  }
  fuzz_check_leak(before, "expr");
  free(text);
  return 0;
}
