// SPDX-License-Identifier: MIT
// MuJoCo error guard. MuJoCo reports errors through one process-wide hook that must not return
// (its default prints and exits). Ours jumps back to the innermost guard pushed on the calling
// thread, so a MuJoCo error becomes a status of the verdant call that made it; warnings go to the
// verdant log hook instead of MuJoCo's log file.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>

#include "render_internal.h"

// the jump target and message of this thread (the only per-thread state of the module)
static _Thread_local jmp_buf* guard_target;
static _Thread_local char guard_msg[512];
static once_flag guard_once = ONCE_FLAG_INIT;

static void on_error(const char* msg) {
  snprintf(guard_msg, sizeof guard_msg, "%s", msg ? msg : "MuJoCo error");
  if (guard_target) longjmp(*guard_target, 1);
  // a MuJoCo error outside every guard is a verdant bug: stop loudly rather than go on
  vd_assert_fail("MuJoCo error outside a guard", __FILE__, __LINE__);
  abort();
}

static void on_warning(const char* msg) {
  vd_log(1, "MuJoCo: %s", msg ? msg : "warning");
}

static void install(void) {
  mju_user_error = on_error;
  mju_user_warning = on_warning;
}

void mjguard_install(void) {
  call_once(&guard_once, install);
}

jmp_buf* mjguard_push(jmp_buf* jb) {
  jmp_buf* prev = guard_target;
  guard_target = jb;
  guard_msg[0] = 0;
  return prev;
}

void mjguard_pop(jmp_buf* prev) {
  guard_target = prev;
}

const char* mjguard_message(void) {
  return guard_msg;
}
