// SPDX-License-Identifier: MIT
// The list every module's validation cases report through (vd_validate_add, vd_validate_finish).
#include <stdarg.h>
#include <stdio.h>

#include "phys_internal.h"

int vd_validate_add(vd_validate_list* l, const char* name, const char* form, const char* quantity, double measured,
                    double reference, double tol, int abs_err, const char* note, ...) {
  va_list ap;
  va_start(ap, note);
  int ok = vd_validate_addv(l, name, form, quantity, measured, reference, tol, abs_err, note, ap);
  va_end(ap);
  return ok;
}

int vd_validate_addv(vd_validate_list* l, const char* name, const char* form, const char* quantity, double measured,
                     double reference, double tol, int abs_err, const char* note, va_list ap) {
  if (!vd_grow((void**)&l->r, &l->cap, l->n + 1, sizeof(vd_validate_result))) return 0;
  vd_validate_result* r = &l->r[l->n++];
  memset(r, 0, sizeof *r);
  snprintf(r->name, sizeof r->name, "%s", name);
  snprintf(r->form, sizeof r->form, "%s", form);
  snprintf(r->quantity, sizeof r->quantity, "%s", quantity);
  r->measured = measured;
  r->reference = reference;
  r->error = abs_err || reference == 0 ? fabs(measured - reference) : fabs(measured - reference) / fabs(reference);
  r->tolerance = tol;
  r->pass = isfinite(measured) && r->error <= tol;
  vsnprintf(r->note, sizeof r->note, note, ap);
  return 1;
}

vd_status vd_validate_finish(vd_validate_list* l, vd_validate_result** out, int* n, vd_error* err) {
  *out = NULL;
  *n = 0;
  if (!l->n) {
    vd_free(l->r, (size_t)l->cap * sizeof(vd_validate_result));
    return VD_OK;
  }
  vd_validate_result* r = l->r;
  if (l->cap != l->n) {
    r = vd_realloc(l->r, (size_t)l->cap * sizeof *r, (size_t)l->n * sizeof *r);
    if (!r) {
      vd_free(l->r, (size_t)l->cap * sizeof(vd_validate_result));
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    }
  }
  *out = r;
  *n = l->n;
  return VD_OK;
}
