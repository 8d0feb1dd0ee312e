// SPDX-License-Identifier: MIT
// verdant: virtual plants. L-systems in L-Py syntax → labelled plant → physics, robots,
// labelled point clouds. This umbrella header includes every public module header.
//
// Usage:
//   #include <verdant/verdant.h>
//   vd_lsystem* ls; vd_error err = {0};
//   vd_lsys_load("tomato.lpy", &ls, &err);
//   vd_plant_spec* plant = vd_plant_spec_create();
//   vd_lsys_def def = vd_lsys_def_default();
//   vd_lsys_grow(ls, &def, NULL, plant, &err);
//   vd_model* m; vd_plant_compile(plant, &m, &err);
#ifndef VERDANT_H
#define VERDANT_H

#include "verdant/core.h"
#include "verdant/plant.h"
#include "verdant/lsys.h"
#include "verdant/geom.h"
#include "verdant/cloud.h"
#include "verdant/render.h"
#include "verdant/phys.h"
#include "verdant/sim.h"
#include "verdant/mss.h"
#include "verdant/collide.h"
#include "verdant/growth.h"
#include "verdant/robot.h"

#endif
