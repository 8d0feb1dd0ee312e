// SPDX-License-Identifier: MIT
// MuJoCo error trap, the one process-wide MuJoCo error hook of verdant (private: never
// installed). MuJoCo reports fatal errors through the global hook mju_user_error, and without
// one it prints and exits. vd_mj_trap_install points MuJoCo's error and warning hooks at
// handlers that longjmp back to the innermost open trap of the calling thread, so a MuJoCo error
// becomes a vd_status of the verdant call that made it, never an exit (DESIGN.md). Warnings are
// counted in the open trap and passed to the log hook (vd_log), never printed.
//
// Shared by every piece of verdant that calls MuJoCo: render, robot and the benchmarks (the
// dependency table in docs/architecture.md lets render and robot include it; it includes core
// and MuJoCo only). MuJoCo's hooks take no user pointer, so the open traps are kept per thread
// (thread-local) and the hooks are set once per process (call_once).
//
// Usage (locals changed inside the trap and read after an error must be volatile):
//   vd_mj_trap trap;
//   vd_mj_trap_install();
//   if (VD_MJ_TRY(&trap)) {
//     mj_step(m, d);                  // an mju_error inside jumps to the else branch
//     vd_mj_trap_end(&trap);
//   } else {
//     st = vd_mj_trap_status(&trap, err);   // VD_ERR_VALUE, "MuJoCo: <message>"; trap closed
//   }
// After an error the mjData is in an unknown state: reset it (mj_resetData) or delete it.
#ifndef VERDANT_MJTRAP_H
#define VERDANT_MJTRAP_H

#include <setjmp.h>

#include "verdant/core.h"

// One open trap: where to jump on an error and what MuJoCo said.
typedef struct vd_mj_trap {
  jmp_buf env;              // the VD_MJ_TRY point
  char error[512];          // MuJoCo's error message ("" when none)
  char warning[512];        // the last warning message ("" when none)
  int nwarning;             // warnings raised while the trap was open
  struct vd_mj_trap* outer; // the trap that was open before this one
} vd_mj_trap;

// Point MuJoCo's error and warning hooks at the trap handlers (once per process, thread-safe).
void vd_mj_trap_install(void);
// Open trap t on this thread (use VD_MJ_TRY, which also sets the jump point).
void vd_mj_trap_begin(vd_mj_trap* t);
// Close trap t (the innermost open one) after the guarded calls succeeded.
void vd_mj_trap_end(vd_mj_trap* t);
// After a jump: the error as a status (VD_ERR_VALUE) with the message in err (Nullable).
vd_status vd_mj_trap_status(const vd_mj_trap* t, vd_error* err);
// Innermost open trap of this thread, NULL when none.
vd_mj_trap* vd_mj_trap_current(void);

struct mjModel_;
// Load an MJCF file (MuJoCo's mj_loadXML under a trap): VD_ERR_IO when it cannot be opened,
// VD_ERR_FORMAT with MuJoCo's message on one line, the file and the line where MuJoCo names one,
// prefixed by what ("robot MJCF").
vd_status vd_mj_load_xml(const char* path, const char* what, struct mjModel_** out, vd_error* err);

// Open a trap and set its jump point: true on entry, false when a MuJoCo error jumped back
// (the trap is closed by then).
#define VD_MJ_TRY(t) (vd_mj_trap_begin(t), setjmp((t)->env) == 0)

#endif
