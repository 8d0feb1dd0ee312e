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
  // predefined modules take the first ids, in VD_SYM_LIST order
  for (int i = 0; i < VD_SYM_PREDEFINED_COUNT; i++) {
    const char* n = vd_sym_predefined_name(i);
    if (sym_intern(ls, n, (int)strlen(n), 1) != i) {
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
  for (int i = 0; i < ls->syms.n; i++) vd_free(ls->syms.name[i], strlen(ls->syms.name[i]) + 1);
  vd_free(ls->syms.name, (size_t)ls->syms.cap * sizeof(char*));
  vd_free(ls->syms.declared, (size_t)ls->syms.cap_declared);
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
    vd_free(ls->rule_first[s], (size_t)(ls->rule_index_nsym + 1) * sizeof(int));
    vd_free(ls->rule_list[s], (size_t)ls->nrule * sizeof(int));
  }
  vd_free(ls->ignored, (size_t)ls->rule_index_nsym);
  vd_free(ls->ignore_syms, sizeof(int32_t) * (size_t)ls->nignore_syms);
  vd_free(ls->label_id, sizeof(int) * (size_t)ls->nlabel);
  vd_free(ls->label_name, sizeof(char*) * (size_t)ls->nlabel);
  vd_free(ls->scalar_slot, sizeof(int) * (size_t)ls->nscalar);
  vd_free(ls->scalar_val, sizeof(value) * (size_t)ls->nscalar);
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
// rule index

static vd_status build_index(vd_lsystem* ls) {
  int nsym = ls->syms.n;
  for (int s = 0; s < SEC_COUNT; s++) {
    vd_free(ls->rule_first[s], (size_t)(ls->rule_index_nsym + 1) * sizeof(int));
    vd_free(ls->rule_list[s], (size_t)ls->nrule * sizeof(int));
    ls->rule_first[s] = NULL;
    ls->rule_list[s] = NULL;
  }
  vd_free(ls->ignored, (size_t)ls->rule_index_nsym);
  ls->ignored = NULL;
  ls->rule_index_nsym = nsym;
  for (int s = 0; s < SEC_COUNT; s++) {
    int* first = vd_calloc((size_t)nsym + 1, sizeof(int));
    int* list = ls->nrule ? vd_malloc(sizeof(int) * (size_t)ls->nrule) : NULL;
    if (!first || (ls->nrule && !list)) {
      vd_free(first, ((size_t)nsym + 1) * sizeof(int));
      vd_free(list, sizeof(int) * (size_t)ls->nrule);
      return VD_ERR_NOMEM;
    }
    ls->rule_first[s] = first;
    ls->rule_list[s] = list;
    ls->has_context[s] = 0;
    // counting sort by first predecessor symbol, keeping declaration order
    for (int r = 0; r < ls->nrule; r++)
      if (ls->rules[r]->section == s) first[ls->rules[r]->pred[0].sym + 1]++;
    for (int k = 0; k < nsym; k++) first[k + 1] += first[k];
    int* fill = vd_malloc(sizeof(int) * (size_t)(nsym + 1));
    if (!fill) return VD_ERR_NOMEM;
    memcpy(fill, first, sizeof(int) * (size_t)(nsym + 1));
    for (int r = 0; r < ls->nrule; r++) {
      const rule* R = ls->rules[r];
      if (R->section != s) continue;
      list[fill[R->pred[0].sym]++] = r;
      if (R->nleft || R->nright) ls->has_context[s] = 1;
    }
    vd_free(fill, sizeof(int) * (size_t)(nsym + 1));
  }
  ls->ignored = vd_calloc((size_t)nsym, 1);
  if (!ls->ignored && nsym) return VD_ERR_NOMEM;
  if (ls->ignore_mode == 1) {
    for (int k = 0; k < ls->nignore_syms; k++) ls->ignored[ls->ignore_syms[k]] = 1;
  } else if (ls->ignore_mode == 2) {
    memset(ls->ignored, 1, (size_t)nsym);
    for (int k = 0; k < ls->nignore_syms; k++) ls->ignored[ls->ignore_syms[k]] = 0;
  }
  // brackets are never ignored
  ls->ignored[VD_SYM_SB] = ls->ignored[VD_SYM_EB] = 0;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// matching

// matching bracket of every '[' and ']' (others untouched)
static vd_status bracket_match(const vd_lstring* s, int64_t** out, int64_t* cap) {
  if (s->n > *cap) {
    int64_t* m = vd_realloc(*out, sizeof(int64_t) * (size_t)*cap, sizeof(int64_t) * (size_t)s->n);
    if (!m) return VD_ERR_NOMEM;
    *out = m;
    *cap = s->n;
  }
  int64_t* m = *out;
  // use the match array itself as the stack of open brackets: m[open] links to the previous open
  int64_t top = -1;
  for (int64_t i = 0; i < s->n; i++) {
    if (s->sym[i] == VD_SYM_SB) {
      m[i] = top;
      top = i;
    } else if (s->sym[i] == VD_SYM_EB) {
      if (top < 0) {
        m[i] = -1;  // unbalanced: acts as the start of the string
      } else {
        int64_t open = top;
        top = m[open];
        m[open] = i;
        m[i] = open;
      }
    }
  }
  while (top >= 0) {  // unclosed: the branch runs to the end
    int64_t prev = m[top];
    m[top] = s->n;
    top = prev;
  }
  return VD_OK;
}

static int match_module(const pmod* p, const vd_lstring* s, int64_t i, value* frame) {
  if (s->sym[i] != p->sym) return 0;
  int64_t a = s->par[i];
  if (s->par[i + 1] - a != p->nparam) return 0;
  for (int k = 0; k < p->nparam; k++) {
    double v = s->val[a + k];
    if (p->slot[k] >= 0) {
      frame[p->slot[k]] = param_to_value(v);
    } else {
      value c = p->cval[k];
      if (c.t == V_STR) {
        if (lsys_unbox_str(v) != (int)c.n) return 0;
      } else if (!(v_isnum(c) && v == c.n)) {
        return 0;
      }
    }
  }
  return 1;
}

// previous module on the same axis: skips lateral branches and ignored modules
static int64_t prev_axial(const vd_lsystem* ls, const vd_lstring* s, const int64_t* m, int64_t j) {
  while (j >= 0) {
    int32_t sym = s->sym[j];
    if (sym == VD_SYM_EB) {
      j = m[j] - 1;
      continue;
    }
    if (sym == VD_SYM_SB || ls->ignored[sym]) {
      j--;
      continue;
    }
    return j;
  }
  return -1;
}

// next module on the same axis: skips lateral branches and ignored modules; -1 at the axis end
static int64_t next_axial(const vd_lsystem* ls, const vd_lstring* s, const int64_t* m, int64_t j) {
  while (j < s->n) {
    int32_t sym = s->sym[j];
    if (sym == VD_SYM_SB) {
      j = m[j] + 1;  // NOLINT(clang-analyzer-core.NullDereference): m holds every module of a non-empty L-string
      continue;
    }
    if (sym == VD_SYM_EB) return -1;
    if (ls->ignored[sym]) {
      j++;
      continue;
    }
    return j;
  }
  return -1;
}

static int match_left(const vd_lsystem* ls, const rule* r, const vd_lstring* s, const int64_t* m, int64_t i,
                      value* frame) {
  int64_t j = i - 1;
  for (int p = r->nleft - 1; p >= 0; p--) {
    j = prev_axial(ls, s, m, j);
    if (j < 0 || !match_module(&r->left[p], s, j, frame)) return 0;
    j--;
  }
  return 1;
}

static int match_right(const vd_lsystem* ls, const rule* r, const vd_lstring* s, const int64_t* m, int64_t j,
                       value* frame) {
  int64_t open[64];
  int depth = 0;
  for (int p = 0; p < r->nright; p++) {
    const pmod* pm = &r->right[p];
    if (pm->sym == VD_SYM_SB) {
      // an explicit lateral branch: the next non-ignored module must open one
      while (j < s->n && s->sym[j] != VD_SYM_SB && s->sym[j] != VD_SYM_EB && ls->ignored[s->sym[j]]) j++;
      if (j >= s->n || s->sym[j] != VD_SYM_SB || depth == 64) return 0;
      open[depth++] = j;
      j++;
      continue;
    }
    if (pm->sym == VD_SYM_EB) {
      // the pattern leaves the branch: skip the rest of it
      if (depth == 0) return 0;
      int64_t o = open[--depth];
      j = m[o] + 1;  // NOLINT(clang-analyzer-core.NullDereference): m holds every module of a non-empty L-string
      continue;
    }
    j = next_axial(ls, s, m, j);
    if (j < 0 || !match_module(pm, s, j, frame)) return 0;
    j++;
  }
  return 1;
}

// ---------------------------------------------------------------------------------------------
// one rewriting pass

typedef struct pass_ctx {
  int64_t* match;
  int64_t match_cap;
  int64_t max_modules;
} pass_ctx;

static vd_status copy_module(vd_lsystem* ls, const vd_lstring* in, int64_t i, vd_lstring* out, int64_t src,
                             int64_t max_modules) {
  int64_t a = in->par[i], np = in->par[i + 1] - a;
  if (out->n + 1 > out->cap || out->par[out->n] + np > out->vcap) {
    if (out->n + 1 > max_modules)
      return vm_error(ls, VD_ERR_LIMIT, 0, 0, "the L-string would exceed %lld modules (raise --max-modules)",
                      (long long)max_modules);
    if (!lstr_reserve(out, out->n + 1, out->par[out->n] + np))
      return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory growing the L-string");
  }
  int64_t n = out->n;
  out->sym[n] = in->sym[i];
  if (out->src) out->src[n] = src;
  int64_t v = out->par[n];
  for (int64_t k = 0; k < np; k++) out->val[v + k] = in->val[a + k];
  out->par[n + 1] = v + np;
  out->n = n + 1;
  return VD_OK;
}

static vd_status apply_rules(vd_lsystem* ls, int sec, const vd_lstring* in, vd_lstring* out, pass_ctx* P,
                             int* fired) {
  // a pass reads every module once: it costs that many operations, so a derivation of many
  // steps over a long string is bounded by max_ops like a runaway loop
  vd_status sp = vm_spend(ls, in->n);
  if (sp) return sp;
  lstr_clear(out);
  if (!lstr_reserve(out, in->n + 16, in->par[in->n] + 16))
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory growing the L-string");
  *fired = 0;
  if (ls->has_context[sec] && bracket_match(in, &P->match, &P->match_cap))
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  const int* first = ls->rule_first[sec];
  const int* list = ls->rule_list[sec];
  int nsym = ls->rule_index_nsym;
  value small[64];
  vm_out vo = {out, 0, P->max_modules, 0, 0};
  for (int64_t i = 0; i < in->n;) {
    int32_t sym = in->sym[i];
    int64_t src = in->src ? in->src[i] : i;
    int done = 0;
    if (sym < nsym && first[sym] != first[sym + 1]) {
      for (int k = first[sym]; k < first[sym + 1] && !done; k++) {
        const rule* r = ls->rules[list[k]];
        if (r->group != 0 && r->group != ls->current_group) continue;
        if (i + r->npred > in->n) continue;
        value* frame = small;
        int nl = r->nlocal;
        if (nl > 64) {
          frame = vd_malloc(sizeof(value) * (size_t)nl);
          if (!frame) return vm_error(ls, VD_ERR_NOMEM, r->line, 0, "out of memory");
        }
        for (int q = 0; q < nl; q++) frame[q] = (value){V_UNDEF, 0};
        int ok = 1;
        for (int q = 0; q < r->npred && ok; q++) ok = match_module(&r->pred[q], in, i + q, frame);
        if (ok && r->nleft) ok = match_left(ls, r, in, P->match, i, frame);
        if (ok && r->nright) ok = match_right(ls, r, in, P->match, i + r->npred, frame);
        if (ok) {
          int64_t mark = out->n;
          vo.src = src;
          vo.produced = vo.nproduced = 0;
          vd_status st;
          if (ls->py) {
            st = lsys_py_apply_rule(ls, r, frame, &vo);
          } else if (r->succ) {
            st = vm_emit_tmpl(ls, r->succ, frame, &vo);
            vo.produced = 1;
          } else {
            st = vm_exec_block(ls, r->body, frame, &vo, NULL, NULL);
          }
          if (st) {
            if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
            return st;
          }
          if (vo.produced || vo.nproduced) {
            done = 1;
            *fired = 1;
            i += r->npred;
          } else {
            out->n = mark;  // the body produced nothing: the rule fails, try the next one
          }
        }
        if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
      }
    }
    if (!done) {
      vd_status st = copy_module(ls, in, i, out, src, P->max_modules);
      if (st) return st;
      i++;
    }
  }
  return VD_OK;
}

// % removes itself and the rest of its branch (up to, not including, the closing ']')
static void apply_cut(vd_lstring* s) {
  int64_t w = 0, wv = 0;
  for (int64_t i = 0; i < s->n;) {
    if (s->sym[i] == VD_SYM_CUT) {
      int depth = 0;
      int64_t j = i + 1;
      for (; j < s->n; j++) {
        if (s->sym[j] == VD_SYM_SB) depth++;
        else if (s->sym[j] == VD_SYM_EB && depth-- == 0) break;
      }
      i = j;
      continue;
    }
    int64_t a = s->par[i], np = s->par[i + 1] - a;
    s->sym[w] = s->sym[i];
    if (s->src) s->src[w] = s->src[i];
    memmove(s->val + wv, s->val + a, sizeof(double) * (size_t)np);
    s->par[w] = wv;
    wv += np;
    w++;
    i++;
  }
  s->n = w;
  s->par[w] = wv;
}

static int has_cut(const vd_lstring* s) {
  for (int64_t i = 0; i < s->n; i++)
    if (s->sym[i] == VD_SYM_CUT) return 1;
  return 0;
}

static void lstr_swap(vd_lstring* a, vd_lstring* b) {
  vd_lstring t = *a;
  *a = *b;
  *b = t;
}

// repeated passes of a section's rules (decomposition, interpretation) up to its maximum depth
static vd_status apply_section(vd_lsystem* ls, int sec, vd_lstring* cur, vd_lstring* tmp, pass_ctx* P) {
  if (ls->rule_first[sec][ls->rule_index_nsym] == 0) return VD_OK;
  for (int d = 0; d < ls->max_depth[sec]; d++) {
    int fired = 0;
    vd_status st = apply_rules(ls, sec, cur, tmp, P, &fired);
    if (st) return st;
    lstr_swap(cur, tmp);
    if (!fired) break;
  }
  if (has_cut(cur)) apply_cut(cur);
  return VD_OK;
}

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
static vd_status end_run(vd_lsystem* ls, vd_status st, vd_lstring* tmp, pass_ctx* P) {
  if (ls->py) lsys_py_leave(ls);
  vd_lstring_free(tmp);
  vd_free(P->match, sizeof(int64_t) * (size_t)P->match_cap);
  if (st && ls->err->status == VD_OK) vd_error_set(ls->err, st, ls->file, 0, 0, "%s", vd_status_str(st));
  ls->err = NULL;
  return st;
}

vd_status vd_lsys_derive(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  vd_lsys_def d = def ? *def : vd_lsys_def_default();
  if (d.max_modules <= 0) d.max_modules = 50000000;
  vm_budget(ls, d.max_ops);
  vd_lstring tmp = vd_lstring_empty();
  pass_ctx P = {NULL, 0, d.max_modules};
  if (ls->py) {
    lsys_py_enter(ls);
    lsys_py_reset_objects(ls);
  }
  vd_status st = build_index(ls);
  if (st) {
    vm_error(ls, st, 0, 0, "out of memory");
    goto done;
  }
  if (out->src) {
    vd_free(out->src, sizeof(int64_t) * (size_t)out->cap);
    out->src = NULL;
  }
  if ((st = run_toplevel(ls, d.seed))) goto done;
  int steps = d.steps;
  if (steps < 0 && ls->py) {
    if ((st = lsys_py_dlength_eval(ls, &steps))) goto done;
  } else if (steps < 0) {
    steps = 1;
    if (ls->derivation_length) {
      value v;
      if ((st = vm_eval(ls, ls->derivation_length, NULL, &v))) goto done;
      if (!v_isnum(v) || v.n != floor(v.n) || v.n < 0 || v.n > 1e9) {
        st = vm_error(ls, VD_ERR_VALUE, ls->derivation_length->line, ls->derivation_length->col,
                      "derivation length must be a non-negative integer");
        goto done;
      }
      steps = (int)v.n;
    }
  }
  ls->hook_start = find_hook(ls, "Start");
  ls->hook_end = find_hook(ls, "End");
  ls->hook_starteach = find_hook(ls, "StartEach");
  ls->hook_endeach = find_hook(ls, "EndEach");
  if ((st = call_hook(ls, ls->hook_start))) goto done;
  // axiom
  lstr_clear(out);
  if (!lstr_reserve(out, 64, 64)) {
    st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    goto done;
  }
  if (ls->py && (st = lsys_py_hook(ls, "Start", out, &tmp, d.max_modules))) goto done;
  {
    vm_out vo = {out, 0, d.max_modules, 0, 0};
    if (ls->py) {
      st = lsys_py_emit_axiom(ls, &vo);
    } else if (ls->axiom) {
      st = vm_emit_tmpl(ls, ls->axiom, NULL, &vo);
    } else {
      int nl = ls->axiom_nlocal > 0 ? ls->axiom_nlocal : 1;
      value* frame = vd_malloc(sizeof(value) * (size_t)nl);
      if (!frame) {
        st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
        goto done;
      }
      for (int i = 0; i < nl; i++) frame[i] = (value){V_UNDEF, 0};
      st = vm_exec_block(ls, ls->axiom_body, frame, &vo, NULL, NULL);
      vd_free(frame, sizeof(value) * (size_t)nl);
    }
    if (st) goto done;
  }
  if (has_cut(out)) apply_cut(out);
  for (int step = 0; step < steps && !ls->stop_requested; step++) {
    ls->iteration = step;
    if ((st = call_hook(ls, ls->hook_starteach))) goto done;
    if (ls->py && (st = lsys_py_hook(ls, "StartEach", out, &tmp, d.max_modules))) goto done;
    int fired = 0;
    if ((st = apply_rules(ls, SEC_PRODUCTION, out, &tmp, &P, &fired))) goto done;
    lstr_swap(out, &tmp);
    if (has_cut(out)) apply_cut(out);
    if ((st = apply_section(ls, SEC_DECOMPOSITION, out, &tmp, &P))) goto done;
    if ((st = call_hook(ls, ls->hook_endeach))) goto done;
    if (ls->py) {
      if ((st = lsys_py_hook(ls, "EndEach", out, &tmp, d.max_modules))) goto done;
      lsys_py_gc(ls, out);
    }
    if (d.progress && d.progress(d.progress_user, step + 1, steps, out->n)) break;
  }
  if ((st = call_hook(ls, ls->hook_end))) goto done;
  if (ls->py && (st = lsys_py_hook(ls, "End", out, &tmp, d.max_modules))) goto done;
done:
  return end_run(ls, st, &tmp, &P);
}

vd_status vd_lsys_interpret(vd_lsystem* ls, const vd_lsys_def* def, const vd_lstring* in, vd_lstring* out,
                            vd_error* err) {
  vd_error local = {0};
  ls->err = err ? err : &local;
  vd_lsys_def d = def ? *def : vd_lsys_def_default();
  if (d.max_modules <= 0) d.max_modules = 50000000;
  vm_budget(ls, d.max_ops);
  pass_ctx P = {NULL, 0, d.max_modules};
  vd_lstring tmp = vd_lstring_empty();
  vd_status st = VD_OK;
  if (ls->py) lsys_py_enter(ls);
  if (ls->rule_index_nsym != ls->syms.n && (st = build_index(ls))) {
    vm_error(ls, st, 0, 0, "out of memory");
    goto done;
  }
  // copy the input with its source indices
  lstr_clear(out);
  if (!lstr_enable_src(out) || !lstr_reserve(out, in->n + 1, in->par[in->n] + 1) || !lstr_enable_src(&tmp)) {
    st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    goto done;
  }
  memcpy(out->sym, in->sym, sizeof(int32_t) * (size_t)in->n);
  memcpy(out->par, in->par, sizeof(int64_t) * (size_t)(in->n + 1));
  memcpy(out->val, in->val, sizeof(double) * (size_t)in->par[in->n]);
  for (int64_t i = 0; i < in->n; i++) out->src[i] = in->src ? in->src[i] : i;
  out->n = in->n;
  st = apply_section(ls, SEC_INTERPRETATION, out, &tmp, &P);
done:
  return end_run(ls, st, &tmp, &P);
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
