// SPDX-License-Identifier: MIT
// Which engine runs a file: the native Python subset when the whole file stays inside it (the
// fast path), else embedded CPython (py/lsys_py.c). Both share the parser's rule structure, the
// derivation, the L-string layout and the turtle; only the Python parts differ.
#include <string.h>

#include "lsys/lsys_internal.h"

const char* vd_lsys_engine_name(vd_lsys_engine e) {
  switch (e) {
    case VD_LSYS_NATIVE: return "native";
    case VD_LSYS_PYTHON: return "python";
    default: return "auto";
  }
}

vd_lsys_engine vd_lsys_get_engine(const vd_lsystem* ls) {
  return ls->engine == VD_LSYS_PYTHON ? VD_LSYS_PYTHON : VD_LSYS_NATIVE;
}

// does a statement list assign global slot g (at any depth, in any function or rule)?
static int assigns_global(const stmt* s, int g) {
  for (; s; s = s->next) {
    if ((s->op == S_ASSIGN || s->op == S_AUGASSIGN || s->op == S_FOR) && s->is_global && s->slot == g)
      return 1;
    if (assigns_global(s->body, g) || assigns_global(s->orelse, g)) return 1;
  }
  return 0;
}

// A name the native engine knows without the file defining it: math constants and functions,
// the random functions, the builtins and L-Py's control functions.
static int predefined_name(const char* n) {
  int len = (int)strlen(n), found;
  ns_constant(NS_MATH, n, len, &found);
  return found || !strcmp(n, "math") || !strcmp(n, "random") || builtin_find(n, len) >= 0;
}

// Every global the file reads is defined somewhere the native engine sees: assigned by the
// file's code (top level, functions, rules, the axiom), a scalar of the editor trailer or a
// predefined name. A name defined elsewhere (a PlantGL import, the trailer's curves and
// functions) is for the Python engine.
static int native_names_resolved(const vd_lsystem* ls, const char** missing) {
  for (int g = 0; g < ls->nglobal; g++) {
    const char* n = ls->gdef[g].name;
    if (predefined_name(n) || assigns_global(ls->top, g) || assigns_global(ls->axiom_body, g)) continue;
    int ok = 0;
    for (int i = 0; i < ls->nscalar && !ok; i++) ok = ls->scalar_slot[i] == g;
    for (int f = 0; f < ls->nfunc && !ok; f++) ok = assigns_global(ls->funcs[f]->body, g);
    for (int r = 0; r < ls->nrule && !ok; r++) ok = assigns_global(ls->rules[r]->body, g);
    if (!ok) {
      *missing = n;
      return 0;
    }
  }
  return 1;
}

// hooks that take the L-string (End(lstring)) are for the Python engine: the native one calls
// hooks without arguments
static int native_hooks(const vd_lsystem* ls, const char** which) {
  static const char* hooks[] = {"Start", "End", "StartEach", "EndEach", "StartInterpretation", "EndInterpretation"};
  for (int f = 0; f < ls->nfunc; f++)
    for (size_t h = 0; h < sizeof hooks / sizeof hooks[0]; h++)
      if (!strcmp(ls->funcs[f]->name, hooks[h]) && ls->funcs[f]->nparam > 0) {
        *which = hooks[h];
        return 0;
      }
  return 1;
}

vd_status vd_lsys_parse_engine(const char* text, size_t len, const char* name, vd_lsys_engine engine,
                               vd_lsystem** out, vd_error* err) {
  if (engine == VD_LSYS_NATIVE || engine == VD_LSYS_PYTHON) return lsys_parse_with(text, len, name, (int)engine, out, err);
  // auto: the native engine when it takes the whole file
  vd_error nerr = {0};
  vd_status st = lsys_parse_with(text, len, name, VD_LSYS_NATIVE, out, &nerr);
  const char* missing = NULL;
  if (st == VD_OK && native_names_resolved(*out, &missing) && native_hooks(*out, &missing)) {
    // kept for vd_lsys_fallback: what native refuses only when it runs goes to CPython
    (*out)->auto_text = vd_malloc(len + 1);
    if ((*out)->auto_text) memcpy((*out)->auto_text, text, len), (*out)->auto_text[len] = 0, (*out)->auto_len = len;
    return VD_OK;
  }
  if (st == VD_OK) {
    vd_lsys_destroy(*out);
    *out = NULL;
  } else if (st != VD_ERR_UNSUPPORTED && st != VD_ERR_SYNTAX) {
    // out of memory, a limit, a binary file: the same for both engines
    if (err) *err = nerr;
    return st;
  }
  char why[200];
  if (!vd_lsys_python_available(why, sizeof why)) {
    // no CPython here: the native engine's verdict stands
    if (st == VD_OK)
      return vd_error_set(err, VD_ERR_UNSUPPORTED, name ? name : "", 0, 0,
                          "unsupported: '%s' needs the Python engine (a name the file does not define, or a "
                          "hook with parameters), which is not available (%s)",
                          missing, why);
    if (err) *err = nerr;
    return st;
  }
  return lsys_parse_with(text, len, name, VD_LSYS_PYTHON, out, err);
}

int vd_lsys_axiom_line(const vd_lsystem* ls) {
  return ls->axiom_line;
}

int vd_lsys_fallback(vd_lsystem** ls, vd_status st) {
  vd_lsystem* old = *ls;
  if (!old || !old->auto_text || (st != VD_ERR_UNSUPPORTED && st != VD_ERR_TYPE)) return 0;
  char why[200];
  if (!vd_lsys_python_available(why, sizeof why)) return 0;
  vd_lsystem* py = NULL;
  vd_error e = {0};
  if (lsys_parse_with(old->auto_text, old->auto_len, old->file, VD_LSYS_PYTHON, &py, &e)) return 0;
  vd_lsys_destroy(old);
  *ls = py;
  return 1;
}

vd_status vd_lsys_parse(const char* text, size_t len, const char* name, vd_lsystem** out, vd_error* err) {
  return vd_lsys_parse_engine(text, len, name, VD_LSYS_AUTO, out, err);
}

vd_status vd_lsys_load_engine(const char* path, vd_lsys_engine engine, vd_lsystem** out, vd_error* err) {
  char* text;
  size_t len;
  *out = NULL;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  st = vd_lsys_parse_engine(text, len, path, engine, out, err);
  vd_free(text, len + 1);
  return st;
}

vd_status vd_lsys_load(const char* path, vd_lsystem** out, vd_error* err) {
  return vd_lsys_load_engine(path, VD_LSYS_AUTO, out, err);
}
