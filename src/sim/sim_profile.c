// SPDX-License-Identifier: MIT
// The clock of the stage profile and the stages' names.
#define _POSIX_C_SOURCE 199309L
#include <time.h>

#include "sim_internal.h"

double sim_clock(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char* vd_sim_stage_name(vd_sim_stage s) {
  static const char* names[VD_SIM_STAGE_COUNT] = {"forces", "predict", "contacts", "eval",    "factor",
                                                  "solve",  "project", "velocity", "fracture"};
  return s >= 0 && s < VD_SIM_STAGE_COUNT ? names[s] : "?";
}
