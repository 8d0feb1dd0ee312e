// SPDX-License-Identifier: MIT
// Private to cloud: limits and small helpers shared by the sampler, the writers and the readers.
#ifndef VERDANT_CLOUD_INTERNAL_H
#define VERDANT_CLOUD_INTERNAL_H

#include <time.h>

#include "verdant/cloud.h"

// Most points a cloud holds (files and arrays index them with 32-bit counts in places).
#define VD_CLOUD_MAX_POINTS ((int64_t)2000000000)
// Most rays of one scan (all scanners together).
#define VD_CLOUD_MAX_RAYS ((int64_t)500000000)

// vd_cloud_alloc, with the point arrays zeroed only when zero is 1.
vd_status cloud_alloc(vd_cloud* c, int64_t n, const vd_label* labels, int nlabel, int zero,
                      vd_error* err);

// Wall-clock seconds (C11 timespec_get).
static inline double cloud_now(void) {
  struct timespec ts;
  timespec_get(&ts, TIME_UTC);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
