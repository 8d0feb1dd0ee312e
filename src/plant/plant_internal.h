// SPDX-License-Identifier: MIT
// Helpers shared by the plant module's files (private, never installed).
#ifndef VERDANT_PLANT_INTERNAL_H
#define VERDANT_PLANT_INTERNAL_H

#include "verdant/plant.h"

// Organ kind for its exact lower-case name ("stem"); VD_ORGAN_COUNT when it is none.
vd_organ vd_organ_parse(const char* name);

// Check a spec as compile does (indices, finite numbers, parent forest); VD_ERR_VALUE names the
// element.
vd_status vd_plant_validate(const vd_plant_spec* s, vd_error* err);

#endif
