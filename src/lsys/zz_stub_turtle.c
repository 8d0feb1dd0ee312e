// SPDX-License-Identifier: MIT
// temporary: replaced by the real turtle at merge
#include "verdant/lsys.h"
vd_turtle_def vd_turtle_def_default(void) { vd_turtle_def d = {60, 1, 0.1, 1, 0.5, 1, 8, {0, 0, 1}, 0}; return d; }
vd_status vd_turtle_run(const vd_lsystem* ls, const vd_lstring* s, const vd_turtle_def* def, vd_plant_spec* plant, vd_error* err) { (void)ls; (void)s; (void)def; (void)plant; (void)err; return VD_OK; }
