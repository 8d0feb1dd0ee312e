// SPDX-License-Identifier: MIT
// Life cycle of an lsystem, globals and overrides, and derivation: parallel rewriting with
// rules tried in order, axial-tree context matching, cut, decomposition and interpretation.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lsys/lsys_internal.h"

// ---------------------------------------------------------------------------------------------
// create / destroy

static vd_lsystem* lsys_new(const char* name, vd_error* err) {
  vd_lsystem* ls = vd_calloc(1, sizeof(vd_lsystem));
  if (!ls) {
    vd_error_set(err, VD_ERR_NOMEM, name ? name : "", 0, 0, "out of memory");
    return NULL;
  }
  snprintf(ls->file, sizeof ls->file, "%s", name ? name : "");
  ls->engine = VD_LSYS_NATIVE;
  vd_arena_init(&ls->arena, 1 << 16);
  vm_budget(ls, 0);
  ls->max_depth[SEC_DECOMPOSITION] = 1;
  ls->max_depth[SEC_INTERPRETATION] = 1;
  ls->opt_string_matching = 1;
  ls->opt_early_return = 1;
  ls->opt_module_matching = 2;
  // predefined modules take the first ids, in VD_SYM_LIST order
  for (int i = 0; i < VD_SYM_PREDEFINED_COUNT; i++) {
    const char* n = vd_sym_predefined_name(i);
    if (sym_intern(ls, n, (int)strlen(n), 1) != i) {
      vd_lsys_destroy(ls);
      vd_error_set(err, VD_ERR_NOMEM, name ? name : "", 0, 0, "out of memory");
      return NULL;
    }
  }
  // L-Py's long names of the predefined modules (its predefined module table)
  static const struct {
    const char* name;
    int sym;
  } aliases[] = {
      {"SB", VD_SYM_SB},           {"EB", VD_SYM_EB},
      {"Cut", VD_SYM_CUT},         {"GetPos", VD_SYM_GETPOS},
      {"GetHead", VD_SYM_GETHEAD}, {"GetUp", VD_SYM_GETUP},
      {"GetLeft", VD_SYM_GETLEFT}, {"GetRight", VD_SYM_GETRIGHT},
      {"GetFrame", VD_SYM_GETFRAME}, {"StartGC", VD_SYM_STARTGC},
      {"EndGC", VD_SYM_ENDGC},     {"BP", VD_SYM_BP},
      {"EP", VD_SYM_EP},           {"PP", VD_SYM_PP},
      {"MoveTo", VD_SYM_MOVETO},   {"SetHead", VD_SYM_SETHEAD},
      {"Left", VD_SYM_LEFT},       {"Right", VD_SYM_RIGHT},
      {"Up", VD_SYM_UP},           {"Down", VD_SYM_DOWN},
      {"RollL", VD_SYM_ROLLL},     {"RollR", VD_SYM_ROLLR},
      {"TurnAround", VD_SYM_TURN}, {"RollToVert", VD_SYM_ROLLTOVERT},
      {"RollToHorizontal", VD_SYM_ROLLTOHORIZ}, {"Sphere", VD_SYM_SPHERE},
      {"Box", VD_SYM_BOX},         {"Quad", VD_SYM_QUAD},
      {"Circle", VD_SYM_CIRCLE},   {"Label", VD_SYM_LABEL},
      {"IncWidth", VD_SYM_INCWIDTH}, {"DecWidth", VD_SYM_DECWIDTH},
      {"IncColor", VD_SYM_INCCOLOR}, {"DecColor", VD_SYM_DECCOLOR},
      {"DivScale", VD_SYM_DIVSCALE}, {"MultScale", VD_SYM_MULTSCALE},
      {"SetScale", VD_SYM_SETSCALE}, {"PglShape", VD_SYM_PGLSHAPE},
      {"Elasticity", VD_SYM_ELASTICITY}, {"Tropism", VD_SYM_TROPISM},
      {"TextureVCoeff", VD_SYM_TEXVSCALE}, {"StartScreenProjection", VD_SYM_2D},
      {"EndScreenProjection", VD_SYM_3D}, {"newmodule", VD_SYM_NEW},
  };
  for (size_t i = 0; i < sizeof aliases / sizeof aliases[0]; i++) {
    if (sym_alias(ls, aliases[i].name, aliases[i].sym) < 0) {
      vd_lsys_destroy(ls);
      vd_error_set(err, VD_ERR_NOMEM, name ? name : "", 0, 0, "out of memory");
      return NULL;
    }
  }
  return ls;
}

void vd_lsys_destroy(vd_lsystem* ls) {
  if (!ls) return;
  lsys_py_free(ls);
  vd_free(ls->auto_text, ls->auto_text ? ls->auto_len + 1 : 0);
  for (int i = 0; i < ls->syms.n; i++) vd_free(ls->syms.name[i], strlen(ls->syms.name[i]) + 1);
  vd_free(ls->syms.name, (size_t)ls->syms.cap * sizeof(char*));
  vd_free(ls->syms.declared, (size_t)ls->syms.cap_declared);
  vd_free(ls->syms.canon, (size_t)ls->syms.cap_canon * sizeof(int));
  vd_free(ls->syms.hash_slot, (size_t)ls->syms.hcap * sizeof(int));
  for (int i = 0; i < ls->nstr; i++) vd_free(ls->str[i], strlen(ls->str[i]) + 1);
  vd_free(ls->str, (size_t)ls->capstr * sizeof(char*));
  vd_free(ls->str_slot, (size_t)ls->str_hcap * sizeof(int));
  for (int i = 0; i < ls->nglobal; i++) vd_free(ls->gdef[i].name, strlen(ls->gdef[i].name) + 1);
  vd_free(ls->gdef, (size_t)ls->capglobal * sizeof(global_def));
  vd_free(ls->gval, (size_t)ls->capgval * sizeof(value));
  vd_free(ls->funcs, (size_t)ls->capfunc * sizeof(func*));
  vd_free(ls->rules, (size_t)ls->caprule * sizeof(rule*));
  for (int s = 0; s < SEC_COUNT; s++) {
    vd_free(ls->rule_first[s], ls->rule_first[s] ? (size_t)(ls->rule_index_nsym + 2) * sizeof(int) : 0);
    vd_free(ls->rule_list[s], (size_t)ls->rule_list_cap[s] * sizeof(int));
  }
  vd_free(ls->no_filter, ls->no_filter ? (size_t)ls->ign_nsym + 1 : 0);
  for (int f = 0; f < ls->nfilter; f++) {
    vd_free(ls->filters[f].syms, sizeof(int32_t) * (size_t)ls->filters[f].nsyms);
    vd_free(ls->filters[f].ignored, ls->filters[f].ignored ? (size_t)ls->ign_nsym + 1 : 0);
  }
  vd_free(ls->filters, sizeof(cfilter) * (size_t)ls->capfilter);
  vd_free(ls->label_id, sizeof(int) * (size_t)ls->nlabel);
  vd_free(ls->label_name, sizeof(char*) * (size_t)ls->nlabel);
  vd_free(ls->scalar_slot, sizeof(int) * (size_t)ls->nscalar);
  vd_free(ls->scalar_val, sizeof(value) * (size_t)ls->nscalar);
  vd_free(ls->pdecl, sizeof(struct pdecl) * (size_t)ls->cappdecl);
  vd_free(ls->mbase, sizeof(struct mbase) * (size_t)ls->capbase);
  vd_free(ls->mlist, sizeof(struct mlist) * (size_t)ls->capmlist);
  vd_free(ls->mval, sizeof(value) * (size_t)ls->capmval);
  vd_free(ls->cpat, sizeof(lsys_cpat) * (size_t)ls->capcpat);
  vd_arena_free(&ls->arena);
  vd_free(ls, sizeof *ls);
}

// parse with one engine (VD_LSYS_NATIVE or VD_LSYS_PYTHON); lsys_engine.c chooses
vd_status lsys_parse_with(const char* text, size_t len, const char* name, int engine, vd_lsystem** out,
                          vd_error* err) {
  *out = NULL;
  vd_error local = {0};
  if (!err) err = &local;
  vd_lsystem* ls = lsys_new(name, err);
  if (!ls) return VD_ERR_NOMEM;
  ls->engine = engine;
  // a NUL byte inside the text is a binary file, not L-Py
  const char* nul = memchr(text, 0, len);
  if (nul) {
    int line = 1, col = 1;
    for (const char* p = text; p < nul; p++) {
      if (*p == '\n') line++, col = 1;
      else col++;
    }
    vd_error_set(err, VD_ERR_SYNTAX, ls->file, line, col, "NUL byte in the file (binary data, not L-Py text)");
    vd_lsys_destroy(ls);
    return VD_ERR_SYNTAX;
  }
  ls->err = err;
  vd_status st = lsys_parse_file(ls, text, len);
  ls->err = NULL;
  if (st) {
    if (err->status == VD_OK) vd_error_set(err, st, ls->file, 0, 0, "%s", vd_status_str(st));
    vd_lsys_destroy(ls);
    return st;
  }
  *out = ls;
  return VD_OK;
}


vd_lsys_def vd_lsys_def_default(void) {
  vd_lsys_def d;
  memset(&d, 0, sizeof d);
  d.steps = -1;
  d.seed = 0;
  d.max_modules = 50000000;
  d.max_ops = LSYS_DEFAULT_MAX_OPS;
  return d;
}

// ---------------------------------------------------------------------------------------------
// globals

static void reset_globals(vd_lsystem* ls) {
  for (int i = 0; i < ls->nglobal; i++) {
    const char* n = ls->gdef[i].name;
    int len = (int)strlen(n);
    value v = {V_UNDEF, 0};
    int found;
    value c = ns_constant(NS_MATH, n, len, &found);
    if (found) v = c;
    else if (strcmp(n, "math") == 0) v = (value){V_NS, NS_MATH};
    else if (strcmp(n, "random") == 0) v = (value){V_NS, NS_RANDOM};
    else {
      int b = builtin_find(n, len);
      if (b >= 0) v = (value){V_BUILTIN, b};
    }
    ls->gval[i] = v;
  }
}

static int assigned_at_top(const vd_lsystem* ls, int slot) {
  for (const stmt* s = ls->top; s; s = s->next)
    if ((s->op == S_ASSIGN || s->op == S_AUGASSIGN) && s->is_global && s->slot == slot) return 1;
  for (int i = 0; i < ls->nscalar; i++)
    if (ls->scalar_slot[i] == slot) return 1;
  return 0;
}

vd_status vd_lsys_set_global(vd_lsystem* ls, const char* name, const char* text, vd_error* err) {
  if (ls->py) {
    vd_error local = {0};
    ls->err = err ? err : &local;
    vd_status st = lsys_py_set_global(ls, name, text);
    ls->err = NULL;
    return st;
  }
  int slot = global_slot(ls, name, (int)strlen(name), 0);
  if (slot < 0 || !assigned_at_top(ls, slot))
    return vd_error_set(err, VD_ERR_NAME, ls->file, 0, 0, "--set %s: the file defines no global '%s'", name, name);
  // evaluate the value as an expression with only builtins available
  vd_error local = {0};
  ls->err = err ? err : &local;
  int before = ls->nglobal;
  expr* e = lsys_parse_expr_text(ls, text, (int)strlen(text), 0, 1);
  vd_status st = VD_OK;
  value v = {0};
  if (!e) {
    st = ls->err->status ? ls->err->status : VD_ERR_SYNTAX;
  } else {
    // globals created by the expression (builtin names) need values
    value* saved = vd_malloc(sizeof(value) * (size_t)ls->nglobal);
    if (!saved) {
      st = vd_error_set(ls->err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    } else {
      memcpy(saved, ls->gval, sizeof(value) * (size_t)ls->nglobal);
      reset_globals(ls);
      st = vm_eval(ls, e, NULL, &v);
      memcpy(ls->gval, saved, sizeof(value) * (size_t)before);
      vd_free(saved, sizeof(value) * (size_t)ls->nglobal);
    }
  }
  if (st == VD_OK) {
    ls->gdef[slot].init_override = v;
    ls->gdef[slot].has_override = 1;
  } else if (ls->err->status) {
    // name the option in the message
    char msg[sizeof ls->err->msg];
    snprintf(msg, sizeof msg, "%s", ls->err->msg);
    snprintf(ls->err->msg, sizeof ls->err->msg, "--set %.40s=%.60s: %.380s", name, text, msg);
    ls->err->file[0] = 0;
    ls->err->line = ls->err->col = 0;
  }
  ls->err = NULL;
  return st;
}

vd_status vd_lsys_get_global(const vd_lsystem* ls, const char* name, double* value_out) {
  if (ls->py) return lsys_py_get_global((vd_lsystem*)ls, name, value_out);
  int slot = global_slot((vd_lsystem*)ls, name, (int)strlen(name), 0);
  if (slot < 0) return VD_ERR_NAME;
  value v = ls->gval[slot];
  if (v.t == V_UNDEF) return VD_ERR_NAME;
  if (!v_isnum(v)) return VD_ERR_TYPE;
  *value_out = v.n;
  return VD_OK;
}

// run the top-level code: scalars first, then statements in file order; --set values replace
// the assignments to their names
static vd_status run_toplevel(vd_lsystem* ls, uint64_t seed) {
  reset_globals(ls);
  vd_rng_seed(&ls->rng, seed);
  ls->current_group = 0;
  ls->iteration = 0;
  ls->stop_requested = 0;
  ls->call_depth = 0;
  ls->backward = 0;
  ls->discard_requested = 0;
  ls->frame_displayed = 0;
  if (ls->py) return lsys_py_run_toplevel(ls, seed);
  for (int i = 0; i < ls->nscalar; i++) ls->gval[ls->scalar_slot[i]] = ls->scalar_val[i];
  for (stmt* s = ls->top; s; s = s->next) {
    if (s->op == S_ASSIGN && s->is_global && ls->gdef[s->slot].has_override) {
      ls->gval[s->slot] = ls->gdef[s->slot].init_override;
      continue;
    }
    stmt* next = s->next;
    s->next = NULL;
    vd_status st = vm_exec_block(ls, s, NULL, NULL, NULL, NULL);
    s->next = next;
    if (st) return st;
  }
  for (int i = 0; i < ls->nglobal; i++)
    if (ls->gdef[i].has_override) ls->gval[i] = ls->gdef[i].init_override;
  return VD_OK;
}

int vd_lsys_derivation_length(const vd_lsystem* ls) {
  if (ls->py) {
    vd_lsystem* mls = (vd_lsystem*)ls;
    vd_error local = {0};
    mls->err = &local;
    int n = 1;
    lsys_py_enter(mls);
    if (run_toplevel(mls, 0) != VD_OK || lsys_py_dlength_eval(mls, &n) != VD_OK) n = 1;
    lsys_py_leave(mls);
    mls->err = NULL;
    return n;
  }
  if (!ls->derivation_length) return 1;
  value v;
  vd_lsystem* mls = (vd_lsystem*)ls;
  vd_error local = {0};
  mls->err = &local;
  vm_budget(mls, mls->max_ops);  // the work limit of the last run
  // the expression may use globals: run the top-level code first (derive runs it again)
  if (run_toplevel(mls, 0) != VD_OK) {
    mls->err = NULL;
    return 1;
  }
  int n = 1;
  // the same range vd_lsys_derive accepts; anything else (NaN, 1e300) stays 1
  if (vm_eval(mls, ls->derivation_length, NULL, &v) == VD_OK && v_isnum(v) && v.n == floor(v.n) &&
      v.n >= 0 && v.n <= 1e9)
    n = (int)v.n;
  mls->err = NULL;
  return n;
}

// ---------------------------------------------------------------------------------------------
// hooks

static int find_hook(vd_lsystem* ls, const char* name) {
  int slot = global_slot(ls, name, (int)strlen(name), 0);
  if (slot < 0 || ls->gval[slot].t != V_FUNC) return -1;
  return (int)ls->gval[slot].n;
}

static vd_status call_hook(vd_lsystem* ls, int fi) {
  if (ls->py) return VD_OK;  // the Python engine calls its hooks by name (lsys_py_hook)
  if (fi < 0) return VD_OK;
  func* f = ls->funcs[fi];
  if (f->nparam != 0)
    return vm_error(ls, VD_ERR_UNSUPPORTED, f->line, 1,
                    "unsupported: hook %s() with parameters (the L-string is not a Python object here)", f->name);
  value r;
  return vm_call_func(ls, fi, 0, NULL, &r, f->line, 1);
}

// release a run's scratch, make sure a failure has a message, detach the error sink
static vd_status end_run(vd_lsystem* ls, vd_status st, vd_lstring* tmp, lsys_pass* P) {
  if (ls->py) lsys_py_leave(ls);
  vd_lstring_free(tmp);
  lsys_pass_free(P);
  if (st && ls->err->status == VD_OK) vd_error_set(ls->err, st, ls->file, 0, 0, "%s", vd_status_str(st));
  ls->err = NULL;
  return st;
}

static void lstr_swap(vd_lstring* a, vd_lstring* b) {
  vd_lstring t = *a;
  *a = *b;
  *b = t;
}

// `maximum depth:` of a section, evaluated after the top-level code (default 1)
static vd_status eval_max_depth(vd_lsystem* ls, int sec) {
  ls->max_depth[sec] = 1;
  const expr* e = ls->max_depth_expr[sec];
  if (!e) return VD_OK;
  value v;
  vd_status st = vm_eval(ls, e, NULL, &v);
  if (st) return st;
  if (!v_isnum(v) || !(v.n >= 1 && v.n <= 1000))
    return vm_error(ls, VD_ERR_VALUE, e->line, e->col, "maximum depth must be a number in 1..1000");
  ls->max_depth[sec] = (int)v.n;  // L-Py rounds a float down
  return VD_OK;
}

// the whole string through a section's recursive rewriting (also applies the cuts)
static vd_status rewrite_section(vd_lsystem* ls, int sec, vd_lstring* cur, vd_lstring* tmp, lsys_pass* P,
                                 int* matched) {
  lstr_clear(tmp);
  if (!lstr_reserve(tmp, cur->n + 16, (cur->par ? cur->par[cur->n] : 0) + 16) || (cur->src && !lstr_enable_src(tmp)) ||
      (cur->line && !lstr_enable_line(tmp)))
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory growing the L-string");
  vd_status st = lsys_recursive(ls, sec, cur, tmp, P, ls->max_depth[sec], 0, matched);
  if (st) return st;
  lstr_swap(cur, tmp);
  return VD_OK;
}

static int has_rules(const vd_lsystem* ls) { return ls->nrule > 0; }

// StartInterpretation / EndInterpretation: what they produce is drawn before / after the string
// (with source index src)
static vd_status interpretation_hook(vd_lsystem* ls, const char* name, vd_lstring* out, int64_t src,
                                     int64_t max_modules) {
  if (ls->py) return lsys_py_produce_hook(ls, name, out, src, max_modules);
  int fi = find_hook(ls, name);
  if (fi < 0) return VD_OK;
  func* f = ls->funcs[fi];
  if (f->nparam != 0)
    return vm_error(ls, VD_ERR_UNSUPPORTED, f->line, 1, "unsupported: hook %s(turtle) (the turtle object)", f->name);
  vm_out vo = {out, src, max_modules, 0, 0};
  vm_out* outer = ls->cur_out;
  ls->cur_out = &vo;
  value r;
  vd_status st = vm_call_func(ls, fi, 0, NULL, &r, f->line, 1);
  ls->cur_out = outer;
  return st;
}

// the string through the interpretation rules, the hooks' modules around it; out->src maps
// each module to the module of in it came from (in->n and in->n + 1 for the hooks)
static vd_status interpret_into(vd_lsystem* ls, const vd_lstring* in, vd_lstring* out, lsys_pass* P) {
  vd_status st = lsys_build_index(ls, ls->current_group, 0);  // interpretation reads forward
  if (st) return vm_error(ls, st, 0, 0, "out of memory");
  lstr_clear(out);
  if (!lstr_enable_src(out) || !lstr_reserve(out, in->n + 16, (in->par ? in->par[in->n] : 0) + 16) ||
      (in->line && !lstr_enable_line(out)))
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  if ((st = interpretation_hook(ls, "StartInterpretation", out, in->n, P->max_modules))) return st;
  int m = 0;
  if ((st = lsys_recursive(ls, SEC_INTERPRETATION, in, out, P, ls->max_depth[SEC_INTERPRETATION], 0, &m))) return st;
  return interpretation_hook(ls, "EndInterpretation", out, in->n + 1, P->max_modules);
}

// the query modules that take Vector3 objects (Python engine), as L-Py's turtle fills them: ?F
// its first four parameters (position, heading, up, left; appended when missing), ?P ?H ?U ?L
// ?R without parameters one appended vector, with one object parameter a new vector; s is
// rebuilt with the new parameter counts
static vd_status query_objects(vd_lsystem* ls, vd_lstring* s, const vd_lstring* geo, const lsys_qframes* qf,
                               int64_t max_modules) {
  vd_lstring t = vd_lstring_empty();
  if ((s->src && !lstr_enable_src(&t)) || (s->line && !lstr_enable_line(&t)) ||
      !lstr_reserve(&t, s->n, s->par[s->n] + 4 * (int64_t)qf->n)) {
    vd_lstring_free(&t);
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  }
  (void)max_modules;
  vd_status st = VD_OK;
  int r = 0;  // next record (in string order, as the turtle met them)
  t.par[0] = 0;
  for (int64_t j = 0; j < s->n && !st; j++) {
    // the record of module j, if any (records of modules that are not copies are skipped)
    const double* rec = NULL;
    while (r < qf->n) {
      int64_t k = (int64_t)qf->v[13 * r];
      if (!(geo->src[k] & LSYS_SRC_IDENTITY)) {
        r++;
        continue;
      }
      int64_t sj = geo->src[k] & ~LSYS_SRC_IDENTITY;
      if (sj < j) {
        r++;
        continue;
      }
      if (sj == j) rec = qf->v + 13 * r++;
      break;
    }
    int64_t a = s->par[j], np = s->par[j + 1] - a;
    double nv[64];
    int64_t nn = np;
    if (rec) {
      int frame = s->sym[j] == VD_SYM_GETFRAME;
      int vecs = frame ? 4 : 1;
      nn = np > vecs ? np : vecs;
      if (nn > 64) nn = 64;
      for (int64_t k = 0; k < nn; k++) nv[k] = k < np ? s->val[a + k] : 0;
      int32_t sym = s->sym[j];
      for (int k = 0; k < vecs && !st; k++) {
        // ?P: position; ?H heading; ?U up; ?L left; ?R right; ?F all four
        int f = frame ? k : sym == VD_SYM_GETPOS ? 0 : sym == VD_SYM_GETHEAD ? 1 : sym == VD_SYM_GETUP ? 2 : 3;
        double sg = sym == VD_SYM_GETRIGHT ? -1 : 1;
        st = lsys_py_vec3(ls, sg * rec[1 + 3 * f], sg * rec[2 + 3 * f], sg * rec[3 + 3 * f], &nv[k]);
      }
    }
    if (!lstr_reserve(&t, t.n + 1, t.par[t.n] + nn)) st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    if (st) break;
    t.sym[t.n] = s->sym[j];
    memcpy(t.val + t.par[t.n], rec ? nv : s->val + a, sizeof(double) * (size_t)nn);
    if (t.src && s->src) t.src[t.n] = s->src[j];
    if (t.line && s->line) t.line[t.n] = s->line[j];
    t.par[t.n + 1] = t.par[t.n] + nn;
    t.n++;
  }
  if (st) {
    vd_lstring_free(&t);
    return st;
  }
  vd_lstring_free(s);
  *s = t;
  return VD_OK;
}

vd_status lsys_scene(vd_lsystem* ls, const vd_lstring* s, vd_plant_spec* plant) {
  lsys_pass P;
  memset(&P, 0, sizeof P);
  P.max_modules = INT64_MAX / 64;
  vd_lstring geo = vd_lstring_empty();
  vd_status st = interpret_into(ls, s, &geo, &P);
  if (!st) {
    vd_turtle_def td = vd_turtle_def_default();
    st = vd_turtle_run(ls, &geo, &td, plant, ls->err);
  }
  vd_lstring_free(&geo);
  lsys_pass_free(&P);
  return st;
}

// an animation frame: plant (cleared) drawn from s, the file's labels named
vd_status lsys_draw(vd_lsystem* ls, const vd_lstring* s, vd_plant_spec* plant) {
  vd_plant_spec_clear(plant);
  if (!ls->max_depth[SEC_INTERPRETATION]) ls->max_depth[SEC_INTERPRETATION] = 1;
  vd_status st = lsys_scene(ls, s, plant);
  for (int i = 0; !st && i < ls->nlabel; i++) st = vd_plant_set_label(plant, ls->label_id[i], ls->label_name[i]);
  if (!st) st = vd_plant_complete_labels(plant);
  if (st && ls->err->status == VD_OK) vm_error(ls, st, 0, 0, "out of memory");
  return st;
}

// L-Py's environmental programs: before a step whose rules read query modules, the turtle
// interprets the string and fills ?P ?H ?U ?L ?R with its position and frame (in the modules
// the interpretation rules leave as they are)
static vd_status query_pass(vd_lsystem* ls, vd_lstring* s, lsys_pass* P) {
  vd_lstring* geo = &P->geo;
  P->identity_bit = LSYS_SRC_IDENTITY;
  vd_status st = interpret_into(ls, s, geo, P);
  P->identity_bit = 0;
  if (st) return st;
  lsys_qframes qf = {NULL, 0, 0};
  if ((st = lsys_turtle_query(ls, geo, ls->err, ls->py ? &qf : NULL))) {
    vd_free(qf.v, sizeof(double) * (size_t)qf.cap);
    return st;
  }
  for (int64_t k = 0; k < geo->n; k++) {
    int32_t sym = geo->sym[k];
    if (sym < VD_SYM_GETPOS || sym > VD_SYM_GETRIGHT || !(geo->src[k] & LSYS_SRC_IDENTITY)) continue;
    int64_t j = geo->src[k] & ~LSYS_SRC_IDENTITY;
    int64_t np = geo->par[k + 1] - geo->par[k];
    memcpy(s->val + s->par[j], geo->val + geo->par[k], sizeof(double) * (size_t)np);
  }
  if (qf.n) st = query_objects(ls, s, geo, &qf, P->max_modules);
  vd_free(qf.v, sizeof(double) * (size_t)qf.cap);
  return st;
}

// the run's settings with defaults filled in; the interpreter budget starts
static vd_lsys_def run_def(vd_lsystem* ls, const vd_lsys_def* def, lsys_pass* P) {
  vd_lsys_def d = def ? *def : vd_lsys_def_default();
  if (d.max_modules <= 0) d.max_modules = 50000000;
  vm_budget(ls, d.max_ops);
  memset(P, 0, sizeof *P);
  P->max_modules = d.max_modules;
  return d;
}

// the start of a run: top-level code, derivation length (steps Nullable), maximum depths, rule
// index, hooks, axiom, Start hook and the axiom's decomposition; *early is set when L-Py returns
// at once (no rule or no axiom)
static vd_status run_setup(vd_lsystem* ls, const vd_lsys_def* d, vd_lstring* out, vd_lstring* tmp, lsys_pass* P,
                           int* steps, int* early, vd_plant_spec* anim, int* stop) {
  vd_status st = VD_OK;
  *early = 0;
  if (ls->py) {
    lsys_py_enter(ls);
    lsys_py_reset_objects(ls);
  }
  if (out->src) {
    vd_free(out->src, sizeof(int64_t) * (size_t)out->cap);
    out->src = NULL;
  }
  if ((st = run_toplevel(ls, d->seed))) return st;
  if (steps) {
    *steps = d->steps;
    if (*steps < 0 && ls->py) {
      if ((st = lsys_py_dlength_eval(ls, steps))) return st;
    } else if (*steps < 0) {
      *steps = 1;
      if (ls->derivation_length) {
        value v;
        if ((st = vm_eval(ls, ls->derivation_length, NULL, &v))) return st;
        if (!v_isnum(v) || v.n != floor(v.n) || v.n < 0 || v.n > 1e9)
          return vm_error(ls, VD_ERR_VALUE, ls->derivation_length->line, ls->derivation_length->col,
                          "derivation length must be a non-negative integer");
        *steps = (int)v.n;
      }
    }
  }
  if ((st = eval_max_depth(ls, SEC_DECOMPOSITION)) || (st = eval_max_depth(ls, SEC_INTERPRETATION))) return st;
  if ((st = lsys_build_index(ls, 0, ls->backward))) return vm_error(ls, st, 0, 0, "out of memory");
  ls->hook_start = find_hook(ls, "Start");
  ls->hook_end = find_hook(ls, "End");
  ls->hook_starteach = find_hook(ls, "StartEach");
  ls->hook_endeach = find_hook(ls, "EndEach");
  ls->steps_done = 0;
  // axiom
  lstr_clear(out);
  if (!lstr_reserve(out, 64, 64)) return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  if (ls->track_lines && (!lstr_enable_line(out) || !lstr_enable_line(tmp)))
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  vm_out vo = {out, 0, d->max_modules, 0, 0};
  if (ls->py) {
    st = lsys_py_emit_axiom(ls, &vo);
  } else if (ls->axiom) {
    st = vm_emit_tmpl(ls, ls->axiom, NULL, &vo);
  } else if (ls->axiom_body) {
    int nl = ls->axiom_nlocal > 0 ? ls->axiom_nlocal : 1;
    value* frame = vd_malloc(sizeof(value) * (size_t)nl);
    if (!frame) return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    for (int i = 0; i < nl; i++) frame[i] = (value){V_UNDEF, 0};
    st = vm_exec_block(ls, ls->axiom_body, frame, &vo, NULL, NULL);
    vd_free(frame, sizeof(value) * (size_t)nl);
  }
  if (st) return st;
  // an animation shows the axiom first, before the Start hook (L-Py's animate)
  if (anim) {
    if ((st = lsys_draw(ls, out, anim))) return st;
    if (d->frame && d->frame(d->frame_user, 0, out, anim)) *stop = 1;
    if ((st = lsys_build_index(ls, 0, ls->backward))) return vm_error(ls, st, 0, 0, "out of memory");
  }
  // L-Py returns at once, without calling any hook, when there is no rule or no axiom (and
  // "Early return when no matching" is on, its default)
  if ((!has_rules(ls) || out->n == 0) && ls->opt_early_return) {
    *early = 1;
    return VD_OK;
  }
  ls->iteration = 0;
  if (*stop) return VD_OK;
  if ((st = call_hook(ls, ls->hook_start))) return st;
  if (ls->py && (st = lsys_py_hook(ls, "Start", out, tmp, d->max_modules, NULL, NULL))) return st;
  if (ls->opt_axiom_decomposition && !lsys_section_empty(ls, SEC_DECOMPOSITION)) {
    int dm = 0;
    if ((st = rewrite_section(ls, SEC_DECOMPOSITION, out, tmp, P, &dm))) return st;
  }
  return VD_OK;
}

// one derivation step up to EndEach (excluded): StartEach, the query pass, productions,
// decomposition; *matching tells whether a rule matched
static vd_status run_step(vd_lsystem* ls, int step, int last, vd_lstring* out, vd_lstring* tmp, lsys_pass* P,
                          int* matching) {
  ls->iteration = step;
  ls->steps_done = step + 1;
  ls->frame_displayed = last;
  vd_status st = call_hook(ls, ls->hook_starteach);
  if (st) return st;
  if (ls->py && (st = lsys_py_hook(ls, "StartEach", out, tmp, P->max_modules, NULL, NULL))) return st;
  // useGroup() and backward() take effect at the next step
  if ((st = lsys_build_index(ls, ls->current_group, ls->backward))) return vm_error(ls, st, 0, 0, "out of memory");
  if (!lsys_section_empty(ls, SEC_PRODUCTION)) {
    if (ls->has_query[SEC_PRODUCTION]) {
      if ((st = query_pass(ls, out, P))) return st;
      if ((st = lsys_build_index(ls, ls->current_group, ls->backward)))
        return vm_error(ls, st, 0, 0, "out of memory");
    }
    if ((st = lsys_step(ls, SEC_PRODUCTION, out, tmp, P, matching))) return st;
    lstr_swap(out, tmp);
  }
  if (!lsys_section_empty(ls, SEC_DECOMPOSITION)) {
    int dm = 0;
    if ((st = rewrite_section(ls, SEC_DECOMPOSITION, out, tmp, P, &dm))) return st;
    if (dm) *matching = 1;
  }
  return VD_OK;
}

// the End hooks of an animation: *have tells whether anim holds the string's scene
static vd_status end_hooks(vd_lsystem* ls, vd_lstring* out, vd_lstring* tmp, int64_t max_modules, vd_plant_spec* anim,
                           int* have) {
  if (ls->hook_end >= 0) *have = 0;  // a native End returns nothing: the frame draws the string
  vd_status st = call_hook(ls, ls->hook_end);
  if (!st && ls->py) st = lsys_py_hook(ls, "End", out, tmp, max_modules, anim, have);
  return st;
}

// vd_lsys_derive, and vd_lsys_animate when anim (its plant) is given
static vd_status derive_run(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_plant_spec* anim,
                            vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  lsys_pass P;
  vd_lsys_def d = run_def(ls, def, &P);
  ls->last_def = d;
  ls->has_last_def = 1;
  ls->animating = anim != NULL;
  vd_lstring tmp = vd_lstring_empty();
  int steps = 0, early = 0, stop = 0;
  // anim holds the plant of the current string (frames: the string after a step is drawn, or
  // the scene an EndEach or End returned is kept)
  int have = 0;
  vd_status st = run_setup(ls, &d, out, &tmp, &P, &steps, &early, anim, &stop);
  if (st) goto done;
  have = early || stop;
  if (early || stop) goto done;
  int matching = 1, step = 0, ended = 0;
  // DiscardNewString() (L-Py's __lpyfuture__) drops a step's result for the string at the end
  // of the step before; it works through the EndEach that module provides (or decorates)
  int discard = global_slot(ls, "DiscardNewString", 16, 0) >= 0 &&
                (ls->hook_endeach < 0 || ls->funcs[ls->hook_endeach]->discard_wrapped);
  int has_saved = 0;
  // an animation derives one step at a time, as L-Py's: no early return when nothing matched
  for (; (matching || !ls->opt_early_return || anim) && step < steps; step++) {
    have = 0;
    if ((st = run_step(ls, step, anim || step == steps - 1, out, &tmp, &P, &matching))) goto done;
    if (!(discard && ls->discard_requested) && (st = call_hook(ls, ls->hook_endeach))) goto done;
    if (ls->py && (st = lsys_py_hook(ls, "EndEach", out, &tmp, d.max_modules, anim, &have))) goto done;
    if (discard) {
      if (ls->discard_requested) {
        ls->discard_requested = 0;
        have = 0;
        if (has_saved) lstr_swap(out, &P.saved);
      } else {
        if (!lsys_lstring_copy(&P.saved, out)) {
          st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
          goto done;
        }
        has_saved = 1;
      }
    }
    // the Python engine's objects no module refers to any more (a saved string keeps its own)
    if (ls->py && !has_saved) lsys_py_gc(ls, out);
    if (d.progress && d.progress(d.progress_user, step + 1, steps, out->n)) stop = 1;
    if (anim) {
      // L-Py's animate: End runs inside the last step, before its frame
      if (step + 1 == steps && !ls->stop_requested) {
        ended = 1;
        if ((st = end_hooks(ls, out, &tmp, d.max_modules, anim, &have))) goto done;
      }
      if (ls->frame_displayed) {
        if (!have && (st = lsys_draw(ls, out, anim))) goto done;
        have = 1;
        if (d.frame && d.frame(d.frame_user, step + 1, out, anim)) stop = 1;
      }
    }
    if (stop || ls->stop_requested) break;  // Stop(): L-Py ends here, without End()
  }
  if (step == steps && !ended) {
    if (anim) {
      st = end_hooks(ls, out, &tmp, d.max_modules, anim, &have);
    } else {
      st = call_hook(ls, ls->hook_end);
      if (!st && ls->py) st = lsys_py_hook(ls, "End", out, &tmp, d.max_modules, NULL, NULL);
    }
  }
done:
  // the plant of the final string, when the last frame did not show it
  if (!st && anim && !have) st = lsys_draw(ls, out, anim);
  ls->animating = 0;
  return end_run(ls, st, &tmp, &P);
}

vd_status vd_lsys_derive(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_error* err) {
  return derive_run(ls, def, out, NULL, err);
}

vd_status vd_lsys_animate(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_plant_spec* plant,
                          vd_error* err) {
  vd_plant_spec_clear(plant);
  return derive_run(ls, def, out, plant, err);
}

vd_status vd_lsys_call(vd_lsystem* ls, const char* name, vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  lsys_pass P;
  run_def(ls, ls->has_last_def ? &ls->last_def : NULL, &P);  // the run's interpreter budget
  vd_lstring tmp = vd_lstring_empty();
  vd_status st = VD_OK;
  if (ls->py) lsys_py_enter(ls);  // end_run leaves
  if (!ls->has_last_def) {
    st = vm_error(ls, VD_ERR_ARG, 0, 0, "%s(): call it after a derivation", name);
  } else if (ls->py) {
    st = lsys_py_call(ls, name);
  } else {
    int fi = find_hook(ls, name);
    if (fi < 0) {
      st = vm_error(ls, VD_ERR_NAME, 0, 0, "the file defines no function '%s'", name);
    } else if (ls->funcs[fi]->nparam != 0) {
      st = vm_error(ls, VD_ERR_ARG, ls->funcs[fi]->line, 1, "%s() takes parameters: only a function without any can be called",
                    name);
    } else {
      value r;
      st = vm_call_func(ls, fi, 0, NULL, &r, ls->funcs[fi]->line, 1);
    }
  }
  return end_run(ls, st, &tmp, &P);
}

vd_status vd_lsys_derive_begin(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  lsys_pass P;
  vd_lsys_def d = run_def(ls, def, &P);
  ls->last_def = d;
  ls->has_last_def = 1;
  vd_lstring tmp = vd_lstring_empty();
  int early = 0;
  int stop = 0;
  vd_status st = run_setup(ls, &d, out, &tmp, &P, NULL, &early, NULL, &stop);
  return end_run(ls, st, &tmp, &P);
}

vd_status vd_lsys_derive_step(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* s, vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  lsys_pass P;
  vd_lsys_def d = run_def(ls, def, &P);
  vd_lstring tmp = vd_lstring_empty();
  vd_status st = VD_OK;
  int matching = 1;
  if (ls->py) lsys_py_enter(ls);
  if (global_slot(ls, "DiscardNewString", 16, 0) >= 0)
    st = vm_error(ls, VD_ERR_UNSUPPORTED, 0, 0, "unsupported: DiscardNewString() in a step-by-step derivation");
  else if (ls->stop_requested)
    st = vm_error(ls, VD_ERR_VALUE, 0, 0, "the L-system has stopped (Stop() was called): no more steps");
  // every module names itself as its source; the passes carry that to what it becomes
  if (!st && (!lstr_enable_src(s) || !lstr_enable_src(&tmp))) st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  for (int64_t i = 0; !st && s->src && i < s->n; i++) s->src[i] = i;
  if (!st) st = run_step(ls, ls->steps_done, 0, s, &tmp, &P, &matching);
  if (!st) st = call_hook(ls, ls->hook_endeach);
  if (!st && ls->py) st = lsys_py_hook(ls, "EndEach", s, &tmp, d.max_modules, NULL, NULL);
  if (!st && d.progress) d.progress(d.progress_user, ls->steps_done, ls->steps_done, s->n);
  return end_run(ls, st, &tmp, &P);
}

vd_status vd_lsys_interpret(vd_lsystem* ls, const vd_lsys_def* def, const vd_lstring* in, vd_lstring* out,
                            vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  lsys_pass P;
  run_def(ls, def, &P);
  vd_lstring tmp = vd_lstring_empty();
  if (ls->py) lsys_py_enter(ls);
  // interpretation rules of the group in use at the end of the derivation, read forward
  if (!ls->max_depth[SEC_INTERPRETATION]) ls->max_depth[SEC_INTERPRETATION] = 1;
  vd_status st = interpret_into(ls, in, out, &P);
  return end_run(ls, st, &tmp, &P);
}

const char* lsys_file(const vd_lsystem* ls) { return ls->file; }


int lsys_turtle_angle(const vd_lsystem* ls, double* angle) {
  if (ls->has_turtle_angle) *angle = ls->turtle_angle;
  return ls->has_turtle_angle;
}

int lsys_trace_lines(vd_lsystem* ls, const vd_lstring* s, const int64_t* idx, int n, int* lines) {
  for (int k = 0; k < n; k++) lines[k] = 0;
  if (!ls->has_last_def || ls->track_lines) return 0;
  // the same derivation (same settings, as many steps as were made), quiet, keeping lines
  vd_lsys_def d = ls->last_def;
  d.steps = ls->steps_done;
  d.progress = NULL;
  vd_error e = {0};
  vd_lstring der = vd_lstring_empty(), geo = vd_lstring_empty();
  ls->track_lines = 1;
  ls->quiet = 1;
  vd_status st = vd_lsys_derive(ls, &d, &der, &e);
  if (!st) st = vd_lsys_interpret(ls, &d, &der, &geo, &e);
  ls->track_lines = 0;
  ls->quiet = 0;
  // s is the interpreted string, or the derived one, when modules and symbols agree
  const vd_lstring* same = NULL;
  if (!st && geo.line && geo.n == s->n && (!s->n || !memcmp(geo.sym, s->sym, sizeof(int32_t) * (size_t)s->n)))
    same = &geo;
  else if (!st && der.line && der.n == s->n && (!s->n || !memcmp(der.sym, s->sym, sizeof(int32_t) * (size_t)s->n)))
    same = &der;
  for (int k = 0; same && k < n; k++)
    if (idx[k] >= 0 && idx[k] < same->n) lines[k] = same->line[idx[k]];
  vd_lstring_free(&der);
  vd_lstring_free(&geo);
  return same != NULL;
}

vd_status vd_lsys_parse_lstring(vd_lsystem* ls, const char* text, vd_lstring* out, vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  vd_status st = VD_OK;
  tmpl* t = lsys_parse_tmpl_text(ls, text, (int)strlen(text), 1, 1);
  if (!t) {
    st = ls->err->status ? ls->err->status : VD_ERR_NOMEM;
  } else {
    lstr_clear(out);
    if (!lstr_reserve(out, t->n + 1, 16)) {
      st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    } else {
      reset_globals(ls);
      vm_out vo = {out, 0, INT64_MAX, 0, 0};
      st = vm_emit_tmpl(ls, t, NULL, &vo);
    }
  }
  ls->err = NULL;
  return st;
}

vd_status vd_lsys_grow(vd_lsystem* ls, const vd_lsys_def* def, const vd_turtle_def* tdef, vd_plant_spec* plant,
                       vd_error* err) {
  vd_lstring derived = vd_lstring_empty(), geo = vd_lstring_empty();
  vd_status st = vd_lsys_derive(ls, def, &derived, err);
  if (!st) st = vd_lsys_interpret(ls, def, &derived, &geo, err);
  if (!st) {
    vd_turtle_def td = tdef ? *tdef : vd_turtle_def_default();
    st = vd_turtle_run(ls, &geo, &td, plant, err);
  }
  for (int i = 0; !st && i < ls->nlabel; i++) st = vd_plant_set_label(plant, ls->label_id[i], ls->label_name[i]);
  if (!st) st = vd_plant_complete_labels(plant);
  if (st && err && err->status == VD_OK) vd_error_set(err, st, ls->file, 0, 0, "%s", vd_status_str(st));
  vd_lstring_free(&derived);
  vd_lstring_free(&geo);
  return st;
}
