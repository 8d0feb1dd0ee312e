// SPDX-License-Identifier: MIT
// temporary: replaced by the real plant module at merge
#include <string.h>
#include "verdant/plant.h"
vd_status vd_plant_set_label(vd_plant_spec* s, int id, const char* name) { (void)s; (void)id; (void)name; return VD_OK; }
vd_status vd_plant_complete_labels(vd_plant_spec* s) { (void)s; return VD_OK; }
vd_plant_spec* vd_plant_spec_create(void) { return vd_calloc(1, sizeof(vd_plant_spec)); }
void vd_plant_spec_destroy(vd_plant_spec* s) { vd_free(s, sizeof *s); }
void vd_plant_spec_stats(const vd_plant_spec* s, vd_plant_stats* out) { (void)s; memset(out, 0, sizeof *out); }
vd_status vd_plant_write_json(const vd_plant_spec* s, const char* path, vd_error* err) { (void)s; return vd_error_set(err, VD_ERR_IO, path, 0, 0, "stub"); }
vd_status vd_plant_read_json(const char* path, vd_plant_spec** out, vd_error* err) { (void)out; return vd_error_set(err, VD_ERR_IO, path, 0, 0, "stub"); }
