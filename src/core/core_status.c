// SPDX-License-Identifier: MIT
// Status codes, error records, the log hook and the assert handler.
#include "verdant/core.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* status_text[] = {
#define VD_STATUS_TEXT(name, text) text,
    VD_STATUS_LIST(VD_STATUS_TEXT)
#undef VD_STATUS_TEXT
};

const char* vd_status_str(vd_status s) {
  if ((int)s < 0 || s >= VD_STATUS_COUNT) return "unknown status";
  return status_text[s];
}

vd_status vd_error_set(vd_error* err, vd_status status, const char* file, int line, int col,
                       const char* fmt, ...) {
  if (!err) return status;
  // keep the first error: a later, derived failure must not overwrite the root cause
  if (err->status != VD_OK) return status;
  err->status = status;
  err->line = line;
  err->col = col;
  snprintf(err->file, sizeof err->file, "%s", file ? file : "");
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->msg, sizeof err->msg, fmt, ap);
  va_end(ap);
  return status;
}

const char* vd_error_format(const vd_error* err, char* buf, size_t cap) {
  if (!buf || cap == 0) return "";
  if (!err) {
    snprintf(buf, cap, "unknown error");
    return buf;
  }
  const char* msg = err->msg[0] ? err->msg : vd_status_str(err->status);
  if (err->file[0] && err->line > 0 && err->col > 0)
    snprintf(buf, cap, "%s:%d:%d: %s", err->file, err->line, err->col, msg);
  else if (err->file[0] && err->line > 0)
    snprintf(buf, cap, "%s:%d: %s", err->file, err->line, msg);
  else if (err->file[0])
    snprintf(buf, cap, "%s: %s", err->file, msg);
  else
    snprintf(buf, cap, "%s", msg);
  return buf;
}

// assert handler
static void default_assert(const char* expr, const char* file, int line) {
  fprintf(stderr, "verdant: assertion failed: %s (%s:%d)\n", expr, file, line);
  abort();
}

static vd_assert_fn assert_handler = default_assert;

void vd_set_assert_handler(vd_assert_fn fn) { assert_handler = fn ? fn : default_assert; }

void vd_assert_fail(const char* expr, const char* file, int line) {
  assert_handler(expr, file, line);
}

// log hook
static vd_log_fn log_fn;
static void* log_user;

void vd_set_log(vd_log_fn fn, void* user) {
  log_fn = fn;
  log_user = user;
}

void vd_log(int level, const char* fmt, ...) {
  if (!log_fn) return;
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  log_fn(log_user, level, buf);
}
