// SPDX-License-Identifier: MIT
// Rewriting passes: the rule index, one parallel production step (forward or backward) and the
// recursive rewriting of decomposition and interpretation, as openalea/lpy does them
// (src/cpp/lsystem.cpp: __step, __recursiveSteps, __gRecursiveInterpretation).
//
// Rules are tried in order at each position; the first whose pattern matches and whose body
// produces wins; a module no rule rewrites is copied. A cut `%` is applied when the string is
// read: the module and the rest of its branch are skipped. Simple rules (plain modules, axial
// contexts, forward) take the fast matcher below; the others lsys_rule_match (lsys_match.c).
#include <string.h>

#include "lsys/lsys_internal.h"

// ---------------------------------------------------------------------------------------------
// rule index

// symbol a rule is indexed by: its first predecessor module (its last one backward); -1 for `*`
static int key_symbol(const rule* r, int backward) {
  const pmod* m = &r->pred.m[backward ? r->pred.n - 1 : 0];
  return m->kind == PK_MOD ? m->sym : -1;
}

// a rule the fast matcher takes: plain modules only, no new context, brackets only in the
// right context, no `=]`
static int rule_is_simple(const rule* r) {
  const pstr* parts[3] = {&r->pred, &r->left, &r->right};
  if (r->nleft.n || r->nright.n || r->incontext) return 0;
  for (int p = 0; p < 3; p++)
    for (int k = 0; k < parts[p]->n; k++) {
      const pmod* m = &parts[p]->m[k];
      if (m->kind != PK_MOD || m->exact || m->x) return 0;
      if (p < 2 && (m->sym == VD_SYM_SB || m->sym == VD_SYM_EB)) return 0;
    }
  return 1;
}

// does the pattern hold a query module (?P ?H ?U ?L ?R ?F)?
static int has_query_module(const pstr* p) {
  for (int k = 0; k < p->n; k++) {
    const pmod* m = &p->m[k];
    if (m->kind == PK_MOD && m->sym >= VD_SYM_GETPOS && m->sym <= VD_SYM_GETFRAME) return 1;
    if (m->x)
      for (int a = 0; a < m->x->nsub; a++)
        if (has_query_module(&m->x->sub[a])) return 1;
  }
  return 0;
}

static int rule_applies(const rule* r, int sec, int group, int backward) {
  if (r->section != sec || r->group != group) return 0;
  // a new right context needs backward derivation, a new left one forward (L-Py)
  return backward ? r->nleft.n == 0 : r->nright.n == 0;
}

vd_status lsys_build_index(vd_lsystem* ls, int group, int backward) {
  int nsym = ls->syms.n;
  if (ls->rule_first[0] && nsym == ls->rule_index_nsym && group == ls->rule_index_group &&
      backward == ls->rule_index_dir)
    return VD_OK;
  // the per-filter tables of ignored symbols (nsym + 1 bytes each)
  if (nsym != ls->ign_nsym || !ls->no_filter) {
    vd_free(ls->no_filter, ls->no_filter ? (size_t)ls->ign_nsym + 1 : 0);
    for (int f = 0; f < ls->nfilter; f++) {
      vd_free(ls->filters[f].ignored, ls->filters[f].ignored ? (size_t)ls->ign_nsym + 1 : 0);
      ls->filters[f].ignored = NULL;
    }
    ls->ign_nsym = nsym;
    ls->no_filter = vd_calloc((size_t)nsym + 1, 1);
    if (!ls->no_filter) return VD_ERR_NOMEM;
    for (int f = 0; f < ls->nfilter; f++) {
      cfilter* F = &ls->filters[f];
      F->ignored = vd_calloc((size_t)nsym + 1, 1);
      if (!F->ignored) return VD_ERR_NOMEM;
      if (F->mode == 2) memset(F->ignored, 1, (size_t)nsym);
      for (int k = 0; k < F->nsyms; k++) F->ignored[F->syms[k]] = F->mode == 1;
      // brackets are always considered
      F->ignored[VD_SYM_SB] = F->ignored[VD_SYM_EB] = 0;
    }
  }
  for (int s = 0; s < SEC_COUNT; s++) {
    vd_free(ls->rule_first[s], ls->rule_first[s] ? (size_t)(ls->rule_index_nsym + 2) * sizeof(int) : 0);
    ls->rule_first[s] = NULL;
  }
  ls->rule_index_nsym = nsym;
  ls->rule_index_group = group;
  ls->rule_index_dir = backward;
  int groups[2] = {group, 0};
  int ngroups = group != 0 ? 2 : 1;
  for (int s = 0; s < SEC_COUNT; s++) {
    // bucket nsym holds the `*` rules alone: symbols made after the index was built
    int* first = vd_calloc((size_t)nsym + 2, sizeof(int));
    if (!first) return VD_ERR_NOMEM;
    ls->rule_first[s] = first;
    ls->has_context[s] = 0;
    ls->has_generic[s] = 0;
    ls->has_query[s] = 0;
    int64_t nstar = 0;
    for (int g = 0; g < ngroups; g++)
      for (int r = 0; r < ls->nrule; r++) {
        rule* R = ls->rules[r];
        if (!rule_applies(R, s, groups[g], backward)) continue;
        R->simple = rule_is_simple(R) && !backward && ls->opt_string_matching && !(ls->opt_inherit && ls->has_bases);
        if (R->left.n || R->right.n || R->nleft.n || R->nright.n) ls->has_context[s] = 1;
        if (!R->simple) ls->has_generic[s] = 1;
        if (has_query_module(&R->pred) || has_query_module(&R->left) || has_query_module(&R->right) ||
            has_query_module(&R->nleft) || has_query_module(&R->nright))
          ls->has_query[s] = 1;
        int k = key_symbol(R, backward);
        if (k < 0) nstar++;
        else if (ls->opt_inherit && ls->has_bases) {
          // 'Module inheritance': the rule serves its module's subclasses too
          for (int q = 0; q < nsym; q++) first[q + 1] += lsys_isa(ls, q, k);
        } else first[k + 1]++;
      }
    for (int k = 0; k <= nsym; k++) first[k + 1] += first[k] + (int)nstar;
    int64_t total = first[nsym + 1];
    if (total > ls->rule_list_cap[s]) {
      int* nl = vd_realloc(ls->rule_list[s], sizeof(int) * (size_t)ls->rule_list_cap[s], sizeof(int) * (size_t)total);
      if (!nl) return VD_ERR_NOMEM;
      ls->rule_list[s] = nl;
      ls->rule_list_cap[s] = (int)total;
    }
    int* fill = vd_malloc(sizeof(int) * (size_t)(nsym + 1));
    if (!fill) return VD_ERR_NOMEM;
    memcpy(fill, first, sizeof(int) * (size_t)(nsym + 1));
    // rules of the active group first, then group 0, in file order; `*` rules in every bucket
    for (int g = 0; g < ngroups; g++)
      for (int r = 0; r < ls->nrule; r++) {
        const rule* R = ls->rules[r];
        if (!rule_applies(R, s, groups[g], backward)) continue;
        int k = key_symbol(R, backward);
        if (k >= 0 && ls->opt_inherit && ls->has_bases) {
          for (int q = 0; q < nsym; q++)
            if (lsys_isa(ls, q, k)) ls->rule_list[s][fill[q]++] = r;
        } else if (k >= 0) {
          ls->rule_list[s][fill[k]++] = r;
        } else {
          for (int q = 0; q <= nsym; q++) ls->rule_list[s][fill[q]++] = r;
        }
      }
    vd_free(fill, sizeof(int) * (size_t)(nsym + 1));
  }
  return VD_OK;
}

int lsys_section_empty(const vd_lsystem* ls, int sec) {
  return ls->rule_first[sec][ls->rule_index_nsym + 1] == 0;
}

// ---------------------------------------------------------------------------------------------
// brackets

vd_status lsys_bracket_match(const vd_lstring* s, int64_t** out, int64_t* cap) {
  if (s->n > *cap) {
    int64_t* m = vd_realloc(*out, sizeof(int64_t) * (size_t)*cap, sizeof(int64_t) * (size_t)s->n);
    if (!m) return VD_ERR_NOMEM;
    *out = m;
    *cap = s->n;
  }
  int64_t* m = *out;
  // the match array itself is the stack of open brackets: m[open] links to the previous open
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

// the ']' that ends the branch a cut at i is in (s->n when the string ends first)
static int64_t cut_end(const vd_lstring* s, const int64_t* m, int64_t i) {
  int64_t j = i + 1;
  while (j < s->n && s->sym[j] != VD_SYM_EB) {
    if (s->sym[j] == VD_SYM_SB) {
      if (m) {
        j = m[j] + 1;
        continue;
      }
      int depth = 1;
      for (j++; j < s->n && depth; j++) depth += s->sym[j] == VD_SYM_SB ? 1 : s->sym[j] == VD_SYM_EB ? -1 : 0;
      continue;
    }
    j++;
  }
  return j;
}

// ---------------------------------------------------------------------------------------------
// the fast matcher: plain modules, axial-tree contexts, forward

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
static int64_t prev_axial(const unsigned char* ign, const vd_lstring* s, const int64_t* m, int64_t j) {
  while (j >= 0) {
    int32_t sym = s->sym[j];
    if (sym == VD_SYM_EB) {
      j = m[j] - 1;  // NOLINT(clang-analyzer-core.NullDereference): contexts are read with the brackets matched
      continue;
    }
    if (sym == VD_SYM_SB || ign[sym]) {
      j--;
      continue;
    }
    return j;
  }
  return -1;
}

// next module on the same axis: skips lateral branches and ignored modules; -1 at the axis end
static int64_t next_axial(const unsigned char* ign, const vd_lstring* s, const int64_t* m, int64_t j) {
  while (j < s->n) {
    int32_t sym = s->sym[j];
    if (sym == VD_SYM_SB) {
      j = m[j] + 1;  // NOLINT(clang-analyzer-core.NullDereference): contexts are read with the brackets matched
      continue;
    }
    if (sym == VD_SYM_EB) return -1;
    if (ign[sym]) {
      j++;
      continue;
    }
    return j;
  }
  return -1;
}

static int fast_left(const unsigned char* ign, const rule* r, const vd_lstring* s, const int64_t* m, int64_t i,
                     value* frame) {
  int64_t j = i - 1;
  for (int p = r->left.n - 1; p >= 0; p--) {
    j = prev_axial(ign, s, m, j);
    if (j < 0 || !match_module(&r->left.m[p], s, j, frame)) return 0;
    j--;
  }
  return 1;
}

static int fast_right(const unsigned char* ign, const rule* r, const vd_lstring* s, const int64_t* m, int64_t j,
                      value* frame) {
  int64_t open[64];
  int depth = 0;
  for (int p = 0; p < r->right.n; p++) {
    const pmod* pm = &r->right.m[p];
    if (pm->sym == VD_SYM_SB) {
      // an explicit lateral branch: the next non-ignored module must open one
      while (j < s->n && s->sym[j] != VD_SYM_SB && s->sym[j] != VD_SYM_EB && ign[s->sym[j]]) j++;
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
    j = next_axial(ign, s, m, j);
    if (j < 0 || !match_module(pm, s, j, frame)) return 0;
    j++;
  }
  return 1;
}

// a simple rule whose predecessor would cover [i, e): the modules, then the contexts
static int fast_match(const lsys_mctx* M, const rule* r, int64_t i, int64_t e, value* frame) {
  const vd_lstring* in = M->src;
  if (e > in->n) return 0;
  for (int q = 0; q < r->pred.n; q++)
    if (!match_module(&r->pred.m[q], in, i + q, frame)) return 0;
  if (r->left.n && !fast_left(M->ignored[r->filter + 1], r, in, M->match, i, frame)) return 0;
  if (r->right.n && !fast_right(M->ignored[r->filter + 1], r, in, M->match, e, frame)) return 0;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// applying the rules at one position

static inline vd_status copy_module(vd_lsystem* ls, const vd_lstring* in, int64_t i, vd_lstring* out, int64_t src,
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
  if (out->line) out->line[n] = in->line ? in->line[i] : 0;
  int64_t v = out->par[n];
  for (int64_t k = 0; k < np; k++) out->val[v + k] = in->val[a + k];
  out->par[n + 1] = v + np;
  out->n = n + 1;
  return VD_OK;
}

vd_status lsys_copy_module(vd_lsystem* ls, const vd_lstring* in, int64_t i, vd_lstring* out, int64_t src,
                           int64_t max_modules) {
  return copy_module(ls, in, i, out, src, max_modules);
}

// reverse the order of modules [a, s->n) of s (each keeps its parameters in order)
void lsys_reverse_tail(vd_lstring* s, int64_t a) {
  int64_t b = s->n;
  if (b - a < 2) return;
  int64_t v0 = s->par[a], v1 = s->par[b];
  // all the values reversed at once (each module's values then read backward)
  for (int64_t x = v0, y = v1 - 1; x < y; x++, y--) {
    double t = s->val[x];
    s->val[x] = s->val[y];
    s->val[y] = t;
  }
  // offsets -> counts, modules (symbol, source, count) reversed, counts -> offsets
  for (int64_t k = a; k < b; k++) s->par[k] = s->par[k + 1] - s->par[k];
  for (int64_t x = a, y = b - 1; x < y; x++, y--) {
    int32_t t = s->sym[x];
    s->sym[x] = s->sym[y];
    s->sym[y] = t;
    int64_t c = s->par[x];
    s->par[x] = s->par[y];
    s->par[y] = c;
    if (s->src) {
      int64_t u = s->src[x];
      s->src[x] = s->src[y];
      s->src[y] = u;
    }
    if (s->line) {
      int32_t u = s->line[x];
      s->line[x] = s->line[y];
      s->line[y] = u;
    }
  }
  int64_t off = v0;
  for (int64_t k = a; k < b; k++) {
    int64_t c = s->par[k];
    s->par[k] = off;
    // this module's values are in reverse: put them back in order
    for (int64_t x = off, y = off + c - 1; x < y; x++, y--) {
      double t = s->val[x];
      s->val[x] = s->val[y];
      s->val[y] = t;
    }
    off += c;
  }
}


// Try the rules of section sec at module i of M->src (the last module of the predecessor when
// the pass runs backward); on success the production is appended to out (reversed when
// backward) and [*b, *e) is the predecessor. Returns 1 when a rule applied, 0 when none, -1 on
// error (*st set).
static inline __attribute__((always_inline)) int apply_try(vd_lsystem* ls, const lsys_mctx* M,
                                                           int64_t max_modules, int sec, int64_t i,
                                                           vd_lstring* out, int64_t* consumed_first,
                                                           int64_t* consumed_end, vd_status* st,
                                                           const int backward) {
  const vd_lstring* in = M->src;
  int32_t sym = in->sym[i];
  int nsym = ls->rule_index_nsym;
  int bucket = sym < nsym ? sym : nsym;
  const int* first = ls->rule_first[sec];
  const int* list = ls->rule_list[sec];
  value small[64];
  for (int k = first[bucket]; k < first[bucket + 1]; k++) {
    const rule* r = ls->rules[list[k]];
    value* frame = small;
    int nl = r->nlocal;
    if (nl > 64) {
      frame = vd_malloc(sizeof(value) * (size_t)nl);
      if (!frame) {
        *st = vm_error(ls, VD_ERR_NOMEM, r->line, 0, "out of memory");
        return -1;
      }
    }
    for (int q = 0; q < nl; q++) frame[q] = (value){V_UNDEF, 0};
    int ok;
    int64_t b = i, e;
    if (!backward && r->simple) {
      e = i + r->pred.n;
      ok = fast_match(M, r, i, e, frame);
    } else {
      ok = lsys_rule_match(M, r, i, frame, &b, &e, r->incontext ? &ls->cur : NULL);
      if (!ok && ls->err && ls->err->status) {
        // a pattern condition failed to evaluate
        *st = ls->err->status;
        if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
        return -1;
      }
    }
    int applied = 0;
    if (ok) {
      int64_t mark = out->n;
      vm_out vo = {out, in->src ? in->src[b] : b, max_modules, 0, 0};
      if (ls->py) {
        lsys_cur saved = ls->cur;  // a rule body may run rules (an interpretation inside it)
        if (!r->incontext) ls->cur.M = NULL;
        *st = lsys_py_apply_rule(ls, r, frame, &vo);
        ls->cur = saved;
      } else if (r->succ) {
        *st = vm_emit_tmpl(ls, r->succ, frame, &vo);
        vo.produced = 1;
      } else {
        *st = vm_exec_block(ls, r->body, frame, &vo, NULL, NULL);
      }
      if (*st) {
        if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
        return -1;
      }
      // a body that produced nothing (not even with nproduce) fails: the next rule is tried
      applied = vo.produced || out->n > mark;
      if (!applied) out->n = mark;
      else if (backward) lsys_reverse_tail(out, mark);
    }
    if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
    if (applied) {
      *consumed_first = b;
      *consumed_end = e;
      return 1;
    }
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// lists bound by a match

int lsys_mlist_new(vd_lsystem* ls, int n) {
  if (!vd_grow((void**)&ls->mlist, &ls->capmlist, ls->nmlist + 1, sizeof(struct mlist)) ||
      !vd_grow((void**)&ls->mval, &ls->capmval, ls->nmval + n, sizeof(value)))
    return -1;
  ls->mlist[ls->nmlist].at = ls->nmval;
  ls->mlist[ls->nmlist].n = n;
  ls->nmval += n;
  return ls->nmlist++;
}

// ---------------------------------------------------------------------------------------------
// passes

void lsys_pass_free(lsys_pass* P) {
  vd_free(P->match, sizeof(int64_t) * (size_t)P->match_cap);
  for (int k = 0; k < P->nlvl; k++) {
    vd_lstring_free(&P->lvl[k].buf);
    vd_free(P->lvl[k].match, sizeof(int64_t) * (size_t)P->lvl[k].match_cap);
  }
  vd_free(P->lvl, sizeof(lsys_level) * (size_t)P->caplvl);
  vd_free(P->ignored, sizeof(unsigned char*) * (size_t)P->cap_ignored);
  vd_lstring_free(&P->saved);
  vd_lstring_free(&P->geo);
  memset(P, 0, sizeof *P);
}

// the matching context of a pass over in, writing to out
static vd_status pass_context(vd_lsystem* ls, lsys_pass* P, int sec, const vd_lstring* in, const vd_lstring* out,
                              int64_t** match, int64_t* match_cap, lsys_mctx* M) {
  memset(M, 0, sizeof *M);
  if (!vd_grow((void**)&P->ignored, &P->cap_ignored, ls->nfilter + 1, sizeof(unsigned char*))) {
    vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    return VD_ERR_NOMEM;
  }
  P->ignored[0] = ls->no_filter;
  for (int f = 0; f < ls->nfilter; f++) P->ignored[f + 1] = ls->filters[f].ignored;
  M->ls = ls;
  M->src = in;
  M->dest = out;
  M->backward = sec == SEC_PRODUCTION && ls->backward;
  M->string_mode = !ls->opt_string_matching;
  M->ignored = P->ignored;
  M->nsym = ls->rule_index_nsym;
  if ((ls->has_context[sec] || ls->has_generic[sec]) && in->n) {
    if (lsys_bracket_match(in, match, match_cap)) {
      vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
      return VD_ERR_NOMEM;
    }
    M->match = *match;
  }
  return VD_OK;
}

// the forward step when every rule is simple: the fast path, all in one loop
static vd_status step_simple(vd_lsystem* ls, int sec, const lsys_mctx* M, vd_lstring* out, int64_t max_modules,
                             int* matched) {
  const vd_lstring* in = M->src;
  const int* first = ls->rule_first[sec];
  const int* list = ls->rule_list[sec];
  int nsym = ls->rule_index_nsym;
  const int py = ls->py != NULL;  // the engine does not change during a step
  value small[64];
  vm_out vo = {out, 0, max_modules, 0, 0};
  for (int64_t i = 0; i < in->n;) {
    int32_t sym = in->sym[i];
    int64_t src = in->src ? in->src[i] : i;
    int done = 0;
    if (sym == VD_SYM_CUT) {
      i = cut_end(in, M->match, i);
      continue;
    }
    if (sym < nsym && first[sym] != first[sym + 1]) {
      for (int k = first[sym]; k < first[sym + 1] && !done; k++) {
        const rule* r = ls->rules[list[k]];
        const pmod* pm = r->pred.m;
        int np = r->pred.n;
        if (i + np > in->n) continue;
        value* frame = small;
        int nl = r->nlocal;
        if (nl > 64) {
          frame = vd_malloc(sizeof(value) * (size_t)nl);
          if (!frame) return vm_error(ls, VD_ERR_NOMEM, r->line, 0, "out of memory");
        }
        for (int q = 0; q < nl; q++) frame[q] = (value){V_UNDEF, 0};
        int ok = match_module(pm, in, i, frame);
        for (int q = 1; ok && q < np; q++) ok = match_module(pm + q, in, i + q, frame);
        if (ok && r->left.n) ok = fast_left(M->ignored[r->filter + 1], r, in, M->match, i, frame);
        if (ok && r->right.n) ok = fast_right(M->ignored[r->filter + 1], r, in, M->match, i + r->pred.n, frame);
        if (ok) {
          int64_t mark = out->n;
          vo.src = src;
          vo.produced = vo.nproduced = 0;
          vd_status st;
          if (py) {
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
          if (vo.produced || out->n > mark) {
            done = 1;
            *matched = 1;
            i += r->pred.n;
          } else {
            out->n = mark;  // the body produced nothing: the rule fails, try the next one
          }
        }
        if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
      }
    }
    if (!done) {
      vd_status st = copy_module(ls, in, i, out, src, max_modules);
      if (st) return st;
      i++;
    }
  }
  return VD_OK;
}

vd_status lsys_step(vd_lsystem* ls, int sec, const vd_lstring* in, vd_lstring* out, lsys_pass* P, int* matched) {
  // a pass reads every module once: it costs that many operations, so a derivation of many
  // steps over a long string is bounded by max_ops like a runaway loop
  vd_status st = vm_spend(ls, in->n);
  if (st) return st;
  lstr_clear(out);
  if (!lstr_reserve(out, in->n + 16, in->par[in->n] + 16))
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory growing the L-string");
  *matched = 0;
  lsys_mctx M = {0};
  if ((st = pass_context(ls, P, sec, in, out, &P->match, &P->match_cap, &M))) return st;
  int64_t b, e;
  const int* first = ls->rule_first[sec];
  int nsym = ls->rule_index_nsym;
  if (!M.backward && !ls->has_generic[sec]) return step_simple(ls, sec, &M, out, P->max_modules, matched);
  if (!M.backward) {
    for (int64_t i = 0; i < in->n;) {
      int32_t sym = in->sym[i];
      if (sym == VD_SYM_CUT) {
        i = cut_end(in, M.match, i);
        continue;
      }
      int bucket = sym < nsym ? sym : nsym;
      if (first[bucket] != first[bucket + 1]) {
        int r = apply_try(ls, &M, P->max_modules, sec, i, out, &b, &e, &st, 0);
        if (r < 0) return st;
        if (r) {
          *matched = 1;
          i = e;
          continue;
        }
      }
      if ((st = copy_module(ls, in, i, out, in->src ? in->src[i] : i, P->max_modules))) return st;
      i++;
    }
    return VD_OK;
  }
  // backward: right to left, the productions written back to front, the whole reversed at the end
  for (int64_t i = in->n - 1; i >= 0;) {
    int r = apply_try(ls, &M, P->max_modules, sec, i, out, &b, &e, &st, 1);
    if (r < 0) return st;
    if (r) {
      *matched = 1;
      i = b - 1;
    } else {
      if ((st = copy_module(ls, in, i, out, in->src ? in->src[i] : i, P->max_modules))) return st;
      i--;
    }
  }
  lsys_reverse_tail(out, 0);
  return VD_OK;
}

vd_status lsys_recursive(vd_lsystem* ls, int sec, const vd_lstring* in, vd_lstring* out, lsys_pass* P, int depth,
                         int level, int* matched) {
  vd_status st = vm_spend(ls, in->n);
  if (st) return st;
  if (level + depth > P->nlvl) {
    // every level's scratch exists before the recursion starts: a deeper level reads the
    // buffer of the one above, which must not move
    if (!vd_grow((void**)&P->lvl, &P->caplvl, level + depth, sizeof(lsys_level)))
      return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
    for (int k = P->nlvl; k < level + depth; k++) memset(&P->lvl[k], 0, sizeof P->lvl[k]);
    P->nlvl = level + depth;
  }
  lsys_mctx M = {0};
  if ((st = pass_context(ls, P, sec, in, out, &P->lvl[level].match, &P->lvl[level].match_cap, &M))) return st;
  M.backward = 0;
  int64_t b, e;
  for (int64_t i = 0; i < in->n;) {
    if (in->sym[i] == VD_SYM_CUT) {
      i = cut_end(in, M.match, i);
      continue;
    }
    int r;
    if (depth > 1) {
      // the production is rewritten again, on its own, one level deeper
      vd_lstring* buf = &P->lvl[level].buf;
      lstr_clear(buf);
      if (!lstr_reserve(buf, 16, 16) || (out->src && !lstr_enable_src(buf)) || (out->line && !lstr_enable_line(buf)))
        return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
      r = apply_try(ls, &M, P->max_modules, sec, i, buf, &b, &e, &st, 0);
      if (r < 0) return st;
      if (r) {
        int sub = 0;
        *matched = 1;
        if ((st = lsys_recursive(ls, sec, buf, out, P, depth - 1, level + 1, &sub))) return st;
      }
    } else {
      r = apply_try(ls, &M, P->max_modules, sec, i, out, &b, &e, &st, 0);
      if (r < 0) return st;
      if (r) *matched = 1;
    }
    if (r) {
      i = e;
    } else {
      // a query pass marks (at the top level) the modules it copies unchanged
      int64_t src = (in->src ? in->src[i] : i) | (level == 0 ? P->identity_bit : 0);
      if ((st = copy_module(ls, in, i, out, src, P->max_modules))) return st;
      i++;
    }
  }
  return VD_OK;
}
