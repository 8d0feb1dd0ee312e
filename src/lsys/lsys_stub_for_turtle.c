// SPDX-License-Identifier: MIT
// TEMPORARY: replaced by the lead's lsys module at merge (delete this file then).
// The three lsys.h functions the turtle calls, so the `turtle` branch links on its own. The
// NaN-boxing test here only mimics "a NaN that is not the default quiet NaN"; the real scheme
// belongs to the lsys module.
#include <math.h>
#include <string.h>

#include "verdant/lsys.h"

int vd_lsys_value_is_str(double v) {
  if (!isnan(v)) return 0;
  uint64_t b;
  memcpy(&b, &v, sizeof b);
  b &= ~((uint64_t)1 << 63);
  return b != UINT64_C(0x7ff8000000000000);
}

const char* vd_lsys_value_str(const vd_lsystem* ls, double v) {
  (void)ls;
  (void)v;
  return NULL;
}

const char* vd_lsys_symbol_name(const vd_lsystem* ls, int sym) {
  (void)ls;
  (void)sym;
  return "?";
}
