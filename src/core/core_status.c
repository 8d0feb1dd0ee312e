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

// length of the valid UTF-8 sequence at s (1..4), 0 when it is not one
static int utf8_len(const unsigned char* s) {
  if (s[0] < 0x80) return 1;
  int n = s[0] >= 0xf0 && s[0] <= 0xf4 ? 4 : s[0] >= 0xe0 ? 3 : s[0] >= 0xc2 && s[0] < 0xe0 ? 2 : 0;
  for (int k = 1; k < n; k++)
    if ((s[k] & 0xc0) != 0x80) return 0;
  return n;
}

// copy a message for a terminal: control bytes and bytes that are not UTF-8 (a quoted line of a
// binary file) become \xNN; tabs and newlines stay
static void printable(const char* in, char* out, size_t cap) {
  const unsigned char* s = (const unsigned char*)in;
  size_t o = 0;
  while (*s && o + 1 < cap) {
    int n = utf8_len(s);
    if (n == 1 && (*s >= 0x20 || *s == '\t' || *s == '\n') && *s != 0x7f) {
      out[o++] = (char)*s++;
    } else if (n > 1) {
      if (o + (size_t)n >= cap) break;
      for (int k = 0; k < n; k++) out[o++] = (char)*s++;
    } else {
      if (o + 4 >= cap) break;
      snprintf(out + o, 5, "\\x%02x", *s++);
      o += 4;
    }
  }
  out[o] = 0;
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
  char raw[sizeof err->msg];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(raw, sizeof raw, fmt, ap);
  va_end(ap);
  printable(raw, err->msg, sizeof err->msg);
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
