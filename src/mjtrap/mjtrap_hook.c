// SPDX-License-Identifier: MIT
// MuJoCo error trap (mjtrap.h): hooks that longjmp to the innermost open trap of the thread.
#include "mjtrap.h"

#include <errno.h>
#include <mujoco/mujoco.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>

// open traps of this thread, innermost first (MuJoCo's hooks take no user pointer)
static _Thread_local vd_mj_trap* open_trap;
static once_flag install_once = ONCE_FLAG_INIT;

static void on_error(const char* msg) {
  vd_mj_trap* t = open_trap;
  if (!t) {
    // a MuJoCo call outside any trap: a programmer error, never a return into MuJoCo
    vd_assert_fail("MuJoCo error outside a vd_mj_trap", __FILE__, __LINE__);
    abort();
  }
  snprintf(t->error, sizeof t->error, "%s", msg ? msg : "unknown MuJoCo error");
  open_trap = t->outer; // closed: an error in the caller's recovery goes to the outer trap
  longjmp(t->env, 1);
}

static void on_warning(const char* msg) {
  vd_log(1, "MuJoCo: %s", msg ? msg : "warning");
  vd_mj_trap* t = open_trap;
  if (!t) return; // outside a trap a warning is only logged (mjData counts it in d->warning)
  t->nwarning++;
  snprintf(t->warning, sizeof t->warning, "%s", msg ? msg : "");
}

static void install(void) {
  mju_user_error = on_error;
  mju_user_warning = on_warning;
}

void vd_mj_trap_install(void) {
  call_once(&install_once, install);
}

void vd_mj_trap_begin(vd_mj_trap* t) {
  t->error[0] = t->warning[0] = 0;
  t->nwarning = 0;
  t->outer = open_trap;
  open_trap = t;
}

void vd_mj_trap_end(vd_mj_trap* t) {
  VD_ASSERT(open_trap == t);
  open_trap = t->outer;
}

vd_status vd_mj_trap_status(const vd_mj_trap* t, vd_error* err) {
  return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "MuJoCo: %s", t->error[0] ? t->error : "error");
}

vd_mj_trap* vd_mj_trap_current(void) {
  return open_trap;
}

vd_status vd_mj_load_xml(const char* path, const char* what, mjModel** out, vd_error* err) {
  *out = NULL;
  FILE* f = fopen(path, "rb");
  if (!f) return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot open: %s", strerror(errno));
  fclose(f);
  vd_mj_trap_install();
  char msg[1000] = "";
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap)) return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "%s: MuJoCo: %s", what, trap.error);
  mjModel* m = mj_loadXML(path, NULL, msg, sizeof msg);
  vd_mj_trap_end(&trap);
  if (m) {
    *out = m;
    return VD_OK;
  }
  // MuJoCo's message spans lines ("XML parse error 7:\nError=... Line number=5: ..."): one line,
  // with the line number where the parser gives one
  long line = 0;
  const char* ln = strstr(msg, "Line number=");
  if (!ln) ln = strstr(msg, "line ");
  if (ln) line = strtol(ln + (ln[0] == 'L' ? 12 : 5), NULL, 10);
  for (char* c = msg; *c; c++)
    if (*c == '\n' || *c == '\r') *c = ' ';
  size_t n = strlen(msg);
  while (n && msg[n - 1] == ' ') msg[--n] = 0;
  return vd_error_set(err, VD_ERR_FORMAT, path, line > 0 && line < 1000000000 ? (int)line : 0, 0,
                      "%s: %s", what, msg[0] ? msg : "MuJoCo could not load it");
}
