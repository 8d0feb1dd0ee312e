// SPDX-License-Identifier: MIT
// Private to lsys_py.c and lsys_pysrc.c: the state of the Python engine of one lsystem. The
// only header of verdant that includes Python.h (with lsys_py.c and lsys_pysrc.c, DESIGN's rule:
// only lsys includes Python headers).
#ifndef VERDANT_LSYS_PY_H
#define VERDANT_LSYS_PY_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "lsys/lsys_internal.h"

// A piece of the file's Python compiled on its own: a rule's function, the axiom, the
// derivation length. Its source starts at physical line `line` (tracebacks name file lines).
typedef struct pychunk {
  char name[24];   // the function's name in the namespace (__vd_r3, __vd_axiom, __vd_dlen)
  int line;        // physical line of the source's first line (>= 1)
  char* src;       // source text (owned, NUL-terminated)
  size_t len;      // strlen(src)
  PyObject* code;  // compiled code object (after lsys_py_parse_end)
} pychunk;

// A --set NAME=VALUE override: the value, evaluated when set.
typedef struct pyset {
  char* name;       // owned
  PyObject* value;  // new reference
} pyset;

struct lsys_py {
  // parse time only: the file's text and its physical lines
  const char* text;
  size_t len;
  int nphys;        // physical lines before the editor trailer
  size_t* phys_at;  // offset of each physical line, and of the end (nphys + 1)
  // the top-level code line for line (tracebacks give file lines); NULL where the file has
  // no top-level Python
  char** top;       // owned line texts (nphys)
  int* top_name;    // string id of NAME for a `NAME = ...` statement starting here at column 0, else -1 (nphys)
  int* top_last;    // last physical line of the statement starting here (nphys)
  PyObject* code_top;
  // functions of the rules (index = rule->pyfn), the axiom and the derivation length
  pychunk* fn;
  int nfn, capfn;
  int fn_axiom, fn_dlen;  // indices into fn, -1 when absent
  int has_axiom;          // the file has an Axiom: line (perhaps empty)
  // the L-Py editor's trailer (###### INITIALISATION ######): Python run before the file
  char* trailer;
  int trailer_line;
  PyObject* code_trailer;
  // produce templates: id -> template (in the lsystem's arena)
  const tmpl** tp;
  int ntp, captp;
  // --set overrides
  pyset* set;
  int nset, capset;
  // run time
  PyObject* ns;       // namespace of the current run (a dict)
  PyObject** fobj;    // the functions of the current run (nfn)
  PyObject* rstate;   // random's state between two entries (NULL before the first run)
  PyObject* npstate;  // numpy.random's state, when numpy is loaded
  vm_out* out;        // where produce writes now (NULL outside rules and the axiom)
  const vd_lstring* hook_s;  // the string a hook receives (its scene is made from it on demand)
  const vd_plant_spec* hook_plant;  // its scene, drawn already (an animation frame), or NULL
  // objects referenced by L-strings (handles: slot and epoch, lsys_box_obj)
  PyObject** obj;     // new references; NULL = free slot (capobj)
  int nobj, capobj;   // slots in use up to nobj
  int* freel;         // free slots below nobj (nfree)
  int nfree, capfree;
  unsigned char* mark;  // scratch of the collector (capmark)
  int capmark;
  unsigned epoch;       // 8-bit derivation counter carried by handles
  PyObject** strobj;  // Python str of each string id, made on first use (capstrobj)
  int capstrobj;
};

// compile every chunk (lsys_py.c); errors name the file's line
vd_status lsys_py_compile(vd_lsystem* ls);
// a growable text buffer
typedef struct sbuf {
  char* s;
  size_t n, cap;
  int failed;  // out of memory happened
} sbuf;
void sb_put(sbuf* b, const char* s, size_t n);
void sb_puts(sbuf* b, const char* s);
void sb_printf(sbuf* b, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void sb_free(sbuf* b);
// is l->s[from..] blank (spaces or a comment)?
int lsys_line_rest_blank(const lsys_line* l, int from);
// the text of a buffer as an owned NUL-terminated string (the buffer is emptied); NULL on failure
char* sb_take(sbuf* b, size_t* len);

#endif
