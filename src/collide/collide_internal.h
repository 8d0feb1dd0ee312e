// SPDX-License-Identifier: MIT
// Private helpers of the collide module (collide_contact.c, collide_sdf.c); never installed.
#ifndef VERDANT_COLLIDE_INTERNAL_H
#define VERDANT_COLLIDE_INTERNAL_H

#include <math.h>

#include "verdant/collide.h"

// Euclidean length (inline: the queries are the inner loop of every step)
static inline double len3(vd_vec3 a) {
  return sqrt(vd_dot(a, a));
}

#endif
