// SPDX-License-Identifier: MIT
// The general rule matcher: L-Py's matching of a rule at a position of an L-string, for rules
// the fast path of lsys_derive.c does not take (any-module `*`, brackets in a predecessor or a
// left context, `=]`, x(...) repetitions, or(...) alternatives, new contexts `<<` / `>>`,
// backward derivation, the "As String" string matching option).
//
// It follows openalea/lpy's algorithms (src/cpp/matching_tmpl.h, lsysrule.cpp): the strict
// predecessor is a run of consecutive modules; a left context walks up the axial tree (the
// father of a module: the previous module on its axis, lateral branches and ignored modules
// skipped; an explicit `[` in the pattern steps to the previous module instead); a right
// context walks forward on the axis, skipping lateral branches unless the pattern opens one,
// never leaving the branch it is in. New contexts are matched in the string being written: `<<`
// against what the forward pass has produced so far, `>>` against what the backward pass has
// produced after the position. Positions are module indices; NONE (-1) stands for L-Py's
// string end iterator.
#include <string.h>

#include "lsys/lsys_internal.h"

#define NONE (-1)

// an L-string read in forward order; `rev` when its modules are stored back to front (the
// output of a backward pass)
typedef struct view {
  const vd_lstring* s;
  int64_t n;
  int rev;
  const int64_t* match;        // Nullable: bracket match (forward strings only)
  const unsigned char* ign;    // modules ignored by the rule's filter (indexed by symbol)
  int nsym;                    // size of ign
} view;

static inline int64_t at(const view* v, int64_t k) { return v->rev ? v->n - 1 - k : k; }
static inline int32_t vsym(const view* v, int64_t k) { return v->s->sym[at(v, k)]; }
static inline int is_sb(const view* v, int64_t k) { return vsym(v, k) == VD_SYM_SB; }
static inline int is_eb(const view* v, int64_t k) { return vsym(v, k) == VD_SYM_EB; }
static inline int is_br(const view* v, int64_t k) { return is_sb(v, k) || is_eb(v, k); }
static inline int ignored(const view* v, int64_t k) {
  int32_t s = vsym(v, k);
  return s < v->nsym && v->ign[s];
}

// ---------------------------------------------------------------------------------------------
// moving in the tree (openalea/lpy axialtree_manip.h)

// the ']' closing the branch that starts at pos (or, starting_before, the branch pos is in);
// v->n when the string ends first
static int64_t end_bracket(const view* v, int64_t pos, int starting_before) {
  if (pos >= v->n) return v->n;
  if (!starting_before && is_sb(v, pos)) {
    if (v->match) return v->match[pos];
    pos++;
  }
  int depth = 0;
  while (pos < v->n && (depth > 0 || !is_eb(v, pos))) {
    if (v->match && !v->rev && is_sb(v, pos)) {
      pos = v->match[pos] + 1;
      continue;
    }
    if (is_sb(v, pos)) depth++;
    else if (is_eb(v, pos)) depth--;
    pos++;
  }
  return pos;
}

// the '[' opening the branch closed by the ']' at pos; NONE when there is none
static int64_t begin_bracket(const view* v, int64_t pos) {
  if (is_sb(v, pos)) return pos;
  if (pos == 0) return NONE;
  if (v->match && !v->rev && is_eb(v, pos)) return v->match[pos];
  if (is_eb(v, pos)) pos--;
  int depth = 0;
  while (pos != 0 && (depth > 0 || !is_sb(v, pos))) {
    if (is_eb(v, pos)) depth++;
    else if (is_sb(v, pos)) depth--;
    pos--;
  }
  if (pos == 0) return depth == 0 && is_sb(v, 0) ? 0 : NONE;
  return pos;
}

// the father of pos: the previous module on its axis (NONE at the root)
static int64_t parent(const view* v, int64_t pos) {
  if (pos == 0) return NONE;
  pos--;
  while (pos != NONE && pos != 0 && (is_br(v, pos) || ignored(v, pos))) {
    while (pos != 0 && (is_sb(v, pos) || ignored(v, pos))) pos--;
    while (pos != NONE && pos != 0 && is_eb(v, pos)) {
      pos = begin_bracket(v, pos);
      if (pos != NONE) pos = pos == 0 ? NONE : pos - 1;
    }
  }
  if (pos == NONE) return NONE;
  if (pos == 0 && (is_sb(v, 0) || ignored(v, 0))) return NONE;
  return pos;
}

// the previous module, ignored ones skipped (NONE before the start)
static int64_t previous_module(const view* v, int64_t pos) {
  if (pos == 0) return NONE;
  pos--;
  while (pos != 0 && ignored(v, pos)) pos--;
  return pos;
}

// the next module (from pos itself when from_here), ignored ones skipped; v->n at the end
static int64_t next_module(const view* v, int64_t pos, int from_here) {
  if (pos < v->n && !from_here) pos++;
  while (pos < v->n && ignored(v, pos)) pos++;
  return pos;
}

// ---------------------------------------------------------------------------------------------
// one module against one pattern element

typedef struct mstate {
  vd_lsystem* ls;
  value* frame;
} mstate;

static int bind_params(const pmod* p, const double* val, int np, value* frame) {
  if (np != p->nparam) return 0;
  for (int k = 0; k < np; k++) {
    if (p->slot[k] >= 0) {
      frame[p->slot[k]] = param_to_value(val[k]);
    } else {
      value c = p->cval[k];
      if (c.t == V_STR) {
        if (lsys_unbox_str(val[k]) != (int)c.n) return 0;
      } else if (!(v_isnum(c) && val[k] == c.n)) {
        return 0;
      }
    }
  }
  return 1;
}

// a list of module parameters (prepended with a name when name >= 0); -1 out of memory
static value param_list(vd_lsystem* ls, int name, const double* val, int n) {
  int id = lsys_mlist_new(ls, n + (name >= 0));
  if (id < 0) return (value){V_UNDEF, 0};
  value* o = ls->mval + ls->mlist[id].at;
  if (name >= 0) *o++ = (value){V_STR, name};
  for (int k = 0; k < n; k++) o[k] = param_to_value(val[k]);
  return (value){V_LIST, id};
}

// depth-first over the declared bases; a cycle (module A : base = B, B : base = A) ends at depth 32
static int isa_depth(const vd_lsystem* ls, int32_t sym, int32_t anc, int depth) {
  if (sym == anc) return 1;
  if (depth >= 32) return 0;
  for (int i = 0; i < ls->nbase; i++)
    if (ls->mbase[i].sym == sym && isa_depth(ls, ls->mbase[i].base, anc, depth + 1)) return 1;
  return 0;
}

int lsys_isa(const vd_lsystem* ls, int32_t sym, int32_t anc) { return isa_depth(ls, sym, anc, 0); }

const int* lsys_declared_names(const vd_lsystem* ls, int32_t sym, int* n) {
  for (int i = 0; i < ls->npdecl; i++)
    if (ls->pdecl[i].sym == sym) {
      *n = ls->pdecl[i].n;
      return ls->pdecl[i].name;
    }
  *n = 0;
  return NULL;
}

// L-Py's named parameters from index start: name i is the parameter max(0, np - nnamed) + i;
// with name >= 0 the dict also holds 'name'
static value named_dict(vd_lsystem* ls, int32_t sym, int name, const double* val, int np, int start) {
  int nn;
  const int* names = lsys_declared_names(ls, sym, &nn);
  int first = np - nn > 0 ? np - nn : 0, count = 0;
  for (int i = start; i < nn; i++) count += first + i < np;
  int key_name = -1;
  if (name >= 0 && (key_name = str_intern(ls, "name", 4)) < 0) return (value){V_UNDEF, 0};
  int id = lsys_mlist_new(ls, 2 * (count + (name >= 0)));
  if (id < 0) return (value){V_UNDEF, 0};
  value* o = ls->mval + ls->mlist[id].at;
  if (name >= 0) {
    *o++ = (value){V_STR, key_name};
    *o++ = (value){V_STR, name};
  }
  for (int i = start; i < nn; i++)
    if (first + i < np) {
      *o++ = (value){V_STR, names[i]};
      *o++ = param_to_value(val[first + i]);
    }
  return (value){V_DICT, id};
}

// a pattern module with *args and/or **kwds (the Python engine): L-Py's module matching with
// the any-module and argument lists (openalea/lpy matching.cpp, with value constraints)
static int bind_lists(const mstate* S, const pmod* p, int32_t sym, int name, const double* val, int np) {
  vd_lsystem* ls = S->ls;
  const pext* x = p->x;
  int hasA = x->args_slot >= 0, hasK = x->kwds_slot >= 0, star = p->kind == PK_ANY;
  int hasN = star && x->has_name;
  int P = hasN + p->nparam + hasA + hasK;
  int nn;
  lsys_declared_names(ls, sym, &nn);
  value A = {V_UNDEF, 0}, K = {V_UNDEF, 0};
  if (!star && np + 2 < P) return 0;
  if (star && np + 3 < P) return 0;
  if (P == 1) {
    if (hasA) A = param_list(ls, star ? name : -1, val, np);
    else if (nn != np) return 0;
    else K = named_dict(ls, sym, star ? name : -1, val, np, 0);
  } else if (P == 2 && hasA && hasK && !hasN) {
    if (nn > np) return 0;
    A = param_list(ls, -1, val, np - nn);
    K = named_dict(ls, sym, star ? name : -1, val, np, 0);
  } else {
    int normal = p->nparam;
    if (normal > np) return 0;
    if (hasN) {
      if (x->name_slot >= 0) S->frame[x->name_slot] = (value){V_STR, name};
      else if ((int)x->name_val.n != name) return 0;
    }
    for (int k = 0; k < normal; k++) {
      if (p->slot[k] >= 0) {
        S->frame[p->slot[k]] = param_to_value(val[k]);
      } else {
        value c = p->cval[k];
        if (c.t == V_STR ? lsys_unbox_str(val[k]) != (int)c.n : !(v_isnum(c) && val[k] == c.n)) return 0;
      }
    }
    if (hasA) {
      if (star && normal == 0 && !hasK) {
        A = param_list(ls, -1, val, np);
      } else {
        int last = np;
        if (hasK) last = normal > np - nn ? normal : np - nn;
        A = param_list(ls, -1, val + normal, last > normal ? last - normal : 0);
      }
    }
    if (hasK) {
      if (!hasA && nn + normal < np) return 0;
      int unnamed = np - nn > 0 ? np - nn : 0;
      int start = normal - unnamed > 0 ? normal - unnamed : 0;
      K = named_dict(ls, sym, -1, val, np, start);
    }
  }
  if ((hasA && A.t == V_UNDEF) || (hasK && K.t == V_UNDEF)) return 0;  // out of memory: no match
  if (hasA) S->frame[x->args_slot] = A;
  if (hasK) S->frame[x->kwds_slot] = K;
  return 1;
}

// the conditions of a pattern module on what it bound (L-Py's value constraints); an error
// (set in ls->err) is no match
static int conds_hold(const mstate* S, const pmod* p) {
  const pext* x = p->x;
  if (!x || !x->cond) return 1;  // no condition (name_cond is set only with cond)
  if (p->kind == PK_ANY && x->has_name && x->name_slot >= 0 &&
      lsys_cond_holds(S->ls, &x->name_cond, S->frame[x->name_slot], S->frame) != 1)
    return 0;
  for (int k = 0; x->cond && k < p->nparam; k++)
    if (p->slot[k] >= 0 && lsys_cond_holds(S->ls, &x->cond[k], S->frame[p->slot[k]], S->frame) != 1) return 0;
  return 1;
}

static int module_match(const mstate* S, const pmod* p, const view* v, int64_t k) {
  int64_t j = at(v, k);
  const vd_lstring* s = v->s;
  int np = (int)(s->par[j + 1] - s->par[j]);
  const double* val = s->val + s->par[j];
  int lists = p->x && (p->x->args_slot >= 0 || p->x->kwds_slot >= 0);
  if (p->kind == PK_MOD) {
    if (s->sym[j] != p->sym && !(S->ls->opt_inherit && lsys_isa(S->ls, s->sym[j], p->sym))) return 0;
    if (!(lists ? bind_lists(S, p, s->sym[j], -1, val, np) : bind_params(p, val, np, S->frame))) return 0;
    return conds_hold(S, p);
  }
  if (p->kind != PK_ANY) return 0;
  if (!p->x) return 1;
  // *(name, x, ...): the name is a string value
  const char* name = vd_lsys_symbol_name(S->ls, s->sym[j]);
  int id = str_intern(S->ls, name, (int)strlen(name));
  if (id < 0) return 0;
  if (lists) return bind_lists(S, p, s->sym[j], id, val, np) && conds_hold(S, p);
  if (p->x->name_slot >= 0) S->frame[p->x->name_slot] = (value){V_STR, id};
  else if ((int)p->x->name_val.n != id) return 0;
  return bind_params(p, val, np, S->frame) && conds_hold(S, p);
}

// set every variable of a pattern to None (the alternatives of or(...) that did not match)
static void set_none(const pstr* p, value* frame) {
  for (int i = 0; i < p->n; i++) {
    const pmod* m = &p->m[i];
    for (int k = 0; k < m->nparam; k++)
      if (m->slot && m->slot[k] >= 0) frame[m->slot[k]] = (value){V_NONE, 0};
    if (!m->x) continue;
    if (m->kind == PK_ANY && m->x->name_slot >= 0) frame[m->x->name_slot] = (value){V_NONE, 0};
    for (int a = 0; a < m->x->nsub; a++) set_none(&m->x->sub[a], frame);
  }
}

static int is_re(const pmod* m) { return m->kind == PK_REP || m->kind == PK_OR; }

// the variable slots of a pattern, in order (at most cap); their count
static int pattern_vars(const pstr* p, int* slots, int n, int cap) {
  for (int i = 0; i < p->n; i++) {
    const pmod* m = &p->m[i];
    if (m->x && m->x->has_name && m->x->name_slot >= 0 && n < cap) slots[n++] = m->x->name_slot;
    for (int k = 0; k < m->nparam; k++)
      if (m->slot && m->slot[k] >= 0 && n < cap) slots[n++] = m->slot[k];
    if (m->x && m->x->args_slot >= 0 && n < cap) slots[n++] = m->x->args_slot;
    if (m->x && m->x->kwds_slot >= 0 && n < cap) slots[n++] = m->x->kwds_slot;
    for (int a = 0; m->x && a < m->x->nsub; a++) n = pattern_vars(&m->x->sub[a], slots, n, cap);
  }
  return n;
}

// what the variables of a repetition took at each iteration (L-Py binds each to a list)
typedef struct rep_acc {
  int slots[32];
  int nv;           // variables
  value* v;         // nv values per iteration (cap values)
  int n, cap;       // values stored, capacity
} rep_acc;

static int rep_take(rep_acc* A, const value* frame) {
  if (!A->nv) return 1;
  if (!vd_grow((void**)&A->v, &A->cap, A->n + A->nv, sizeof(value))) return 0;
  for (int k = 0; k < A->nv; k++) A->v[A->n++] = frame[A->slots[k]];
  return 1;
}

// bind each variable to the list of its values (in string order: reversed when the
// repetition walked to the left); frees the accumulator; 0 out of memory
static int rep_bind(vd_lsystem* ls, rep_acc* A, value* frame, int reversed) {
  int ok = 1;
  int iters = A->nv ? A->n / A->nv : 0;
  for (int k = 0; k < A->nv && ok; k++) {
    int id = lsys_mlist_new(ls, iters);
    if (id < 0) {
      ok = 0;
      break;
    }
    value* o = ls->mval + ls->mlist[id].at;
    for (int it = 0; it < iters; it++) o[it] = A->v[(reversed ? iters - 1 - it : it) * A->nv + k];
    frame[A->slots[k]] = (value){V_LIST, id};
  }
  vd_free(A->v, sizeof(value) * (size_t)A->cap);
  return ok;
}

// ---------------------------------------------------------------------------------------------
// left contexts: L-Py's TreeLeftMatcher (and its string form)

static int left_match(const mstate* S, const view* v, int64_t start, const pstr* p, int from, int64_t* end,
                      int string_mode);

// x(...) / or(...) walking backward from pos; *end = the last module matched (pos if none)
static int left_re(const mstate* S, const view* v, int64_t pos, const pmod* m, int64_t* end, int string_mode) {
  const pext* x = m->x;
  int64_t it = pos;
  if (m->kind == PK_REP) {
    int num = 0;
    rep_acc A = {{0}, 0, NULL, 0, 0};
    A.nv = pattern_vars(&x->sub[0], A.slots, 0, 32);
    while (num < x->rmax) {
      int64_t e;
      if (!left_match(S, v, it, &x->sub[0], x->sub[0].n - 1, &e, string_mode)) break;
      if (!rep_take(&A, S->frame)) break;
      it = e;
      num++;
    }
    if (!rep_bind(S->ls, &A, S->frame, 1) || num < x->rmin) return 0;
  } else {
    int matched = -1;
    for (int a = 0; a < x->nsub && matched < 0; a++) {
      int64_t e;
      if (x->sub[a].n == 1 && x->sub[a].m[0].kind == PK_NONE) {
        matched = a;
      } else if (left_match(S, v, it, &x->sub[a], x->sub[a].n - 1, &e, string_mode)) {
        matched = a;
        it = e;
      }
    }
    if (matched < 0) return 0;
    for (int a = 0; a < x->nsub; a++)
      if (a != matched) set_none(&x->sub[a], S->frame);
  }
  *end = it;
  return 1;
}

// match p.m[from], p.m[from - 1], ... going up the tree from start (the module the context is
// to the left of); *end = the last module matched
static int left_match(const mstate* S, const view* v, int64_t start, const pstr* p, int from, int64_t* end,
                      int string_mode) {
  int64_t it = start;
  if (string_mode) {
    // "As String": previous modules in the string, brackets included
    it = it <= 0 ? NONE : it - 1;
    for (int i = from; i >= 0; i--) {
      const pmod* m = &p->m[i];
      if (it == NONE) {
        // nothing left: only None and repetitions that may match nothing (L-Py)
        if (m->kind == PK_NONE) continue;
        if (is_re(m)) {
          int64_t e;
          if (!left_re(S, v, 0, m, &e, string_mode)) return 0;
          continue;
        }
        return 0;
      }
      if (is_re(m)) {
        int64_t e;
        if (!left_re(S, v, it + 1, m, &e, string_mode)) return 0;
        it = e - 1 < 0 ? NONE : e - 1;
        continue;
      }
      if (!module_match(S, m, v, it)) return 0;
      it = it == 0 ? NONE : it - 1;
    }
    *end = it == NONE ? 0 : it + 1;
    return 1;
  }
  if (it == 0 || v->n == 0) {
    // nothing to the left: only repetitions that may match nothing (and None) succeed
    int i = from;
    while (i >= 0 && p->m[i].kind == PK_NONE) i--;
    while (i >= 0 && is_re(&p->m[i])) {
      int64_t e;
      if (!left_re(S, v, it, &p->m[i], &e, string_mode)) return 0;
      i--;
      while (i >= 0 && p->m[i].kind == PK_NONE) i--;
    }
    if (i >= 0) return 0;
    *end = it;
    return 1;
  }
  for (int i = from; i >= 0; i--) {
    const pmod* m = &p->m[i];
    if (is_re(m)) {
      int64_t e;
      if (!left_re(S, v, it, m, &e, string_mode)) return 0;
      it = e;
      continue;
    }
    it = (m->kind == PK_MOD && m->sym == VD_SYM_SB) ? previous_module(v, it) : parent(v, it);
    if (it == NONE) return 0;
    if (!module_match(S, m, v, it)) return 0;
  }
  *end = it;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// right contexts: L-Py's TreeRightMatcher (and its string form)

static int right_match(const mstate* S, const view* v, int64_t start, int64_t* last, const pstr* p, int from,
                       int to, int64_t* end, int string_mode);

// x(...) / or(...) at pos going forward; *end = the position after the last iteration
static int right_re(const mstate* S, const view* v, int64_t pos, int64_t* last, const pmod* m, int64_t* end,
                    int string_mode) {
  const pext* x = m->x;
  int64_t it = pos, lm = *last;
  if (m->kind == PK_REP) {
    int num = 0;
    rep_acc A = {{0}, 0, NULL, 0, 0};
    A.nv = pattern_vars(&x->sub[0], A.slots, 0, 32);
    while (num < x->rmax) {
      int64_t e, l2 = lm;
      if (!right_match(S, v, it, &l2, &x->sub[0], 0, x->sub[0].n, &e, string_mode)) break;
      if (!rep_take(&A, S->frame)) break;
      // the sub-match ends on its last matched module: continue after it
      lm = e;
      it = e + 1;
      num++;
    }
    if (!rep_bind(S->ls, &A, S->frame, 0) || num < x->rmin) return 0;
  } else {
    int matched = -1;
    for (int a = 0; a < x->nsub && matched < 0; a++) {
      int64_t e, l2 = lm;
      if (x->sub[a].n == 1 && x->sub[a].m[0].kind == PK_NONE) {
        matched = a;
      } else if (right_match(S, v, it, &l2, &x->sub[a], 0, x->sub[a].n, &e, string_mode)) {
        // L-Py leaves the position on the alternative's last module (a repetition moves past)
        matched = a;
        lm = e;
        it = e;
      }
    }
    if (matched < 0) return 0;
    for (int a = 0; a < x->nsub; a++)
      if (a != matched) set_none(&x->sub[a], S->frame);
  }
  *last = lm;
  *end = it;
  return 1;
}

// match p.m[from..to) going forward from start; *last is the module matched just before
// (updated); *end = the last module matched
static int right_match(const mstate* S, const view* v, int64_t start, int64_t* last, const pstr* p, int from,
                       int to, int64_t* end, int string_mode) {
  int64_t it = start, lm = *last;
  int i = from;
  if (from >= to) {
    *end = start;
    return 1;
  }
  if (it >= v->n) {
    // nothing to the right: only None and repetitions that may match nothing succeed
    if (to - from == 1 && p->m[from].kind == PK_NONE) {
      *end = it;
      return 1;
    }
    while (i < to && is_re(&p->m[i])) {
      int64_t e;
      if (!right_re(S, v, v->n, &lm, &p->m[i], &e, string_mode)) return 0;
      i++;
    }
    if (i < to) return 0;
    *last = lm;
    *end = it;
    return 1;
  }
  if (string_mode) {
    // "As String" (L-Py's StringMatcher<GetNext>): from start itself, then the next modules with
    // ignored ones skipped, brackets included; after x(...)/or(...) one module is stepped over
    // as L-Py does
    for (; i < to; i++) {
      const pmod* m = &p->m[i];
      if (it >= v->n) return 0;
      if (is_re(m)) {
        int64_t e;
        if (!right_re(S, v, it, &lm, m, &e, string_mode)) return 0;
        lm = e;
        it = next_module(v, e, 0);
        continue;
      }
      if (!module_match(S, m, v, it)) return 0;
      lm = it;
      it = next_module(v, it, 0);
    }
    *last = lm;
    *end = lm;
    return 1;
  }
  it = it == lm ? next_module(v, it, 0) : next_module(v, it, 1);
  int64_t stack[64];
  int depth = 0;
  while (it < v->n && i < to) {
    const pmod* m = &p->m[i];
    int next_pattern = 1, next_src = 1;
    if (m->kind == PK_ANY) {
      if (!module_match(S, m, v, it)) return 0;
    } else if (m->kind == PK_NONE) {
      next_src = 0;
    } else if (is_re(m)) {
      int64_t e;
      if (!right_re(S, v, it, &lm, m, &e, string_mode)) return 0;
      it = e;
      next_src = 0;
    } else if (m->sym != VD_SYM_SB && m->sym != VD_SYM_EB) {
      if (!is_br(v, it)) {
        if (!module_match(S, m, v, it)) return 0;
      } else if (is_eb(v, it)) {
        return 0;  // the context does not leave the branch
      } else {
        it = end_bracket(v, it, 0);  // a lateral branch the pattern does not name
        next_pattern = 0;
      }
    } else if (m->sym == VD_SYM_EB) {
      if (!is_eb(v, it)) {
        if (m->exact) return 0;
        if (depth == 0) return 0;
        depth--;
        it = end_bracket(v, it, 1);  // the rest of the branch the pattern opened
      } else if (depth > 0) {
        depth--;
      }
    } else {
      if (!is_sb(v, it) || depth == 64) return 0;
      stack[depth++] = it;
    }
    if (next_pattern) i++;
    if (next_src) {
      lm = it;
      if (it < v->n && i < to) it = next_module(v, it, 0);
    }
  }
  (void)stack;
  if (i < to) return 0;
  *last = lm;
  *end = it;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// the strict predecessor: consecutive modules

static int pred_forward(const mstate* S, const view* v, int64_t i, const pstr* p, int64_t* end) {
  if (i + p->n > v->n) return 0;
  for (int k = 0; k < p->n; k++)
    if (!module_match(S, &p->m[k], v, i + k)) return 0;
  *end = i + p->n;
  return 1;
}

// backward: the predecessor ends at i; *first = its first module
static int pred_backward(const mstate* S, const view* v, int64_t i, const pstr* p, int64_t* first) {
  if (i + 1 < p->n) return 0;
  for (int k = 0; k < p->n; k++)
    if (!module_match(S, &p->m[p->n - 1 - k], v, i - k)) return 0;
  *first = i + 1 - p->n;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// a rule

int lsys_rule_match(const lsys_mctx* M, const rule* r, int64_t i, value* frame, int64_t* first, int64_t* end,
                    lsys_cur* cur) {
  mstate S = {M->ls, frame};
  M->ls->nmlist = M->ls->nmval = 0;  // lists bound by an earlier attempt are no longer referenced
  const unsigned char* ign = M->ignored[r->filter + 1];
  view src = {M->src, M->src->n, 0, M->match, ign, M->nsym};
  int64_t b, e;
  if (!M->backward) {
    b = i;
    if (!pred_forward(&S, &src, i, &r->pred, &e)) return 0;
  } else {
    e = i + 1;
    if (!pred_backward(&S, &src, i, &r->pred, &b)) return 0;
  }
  int64_t tmp, lend = b;
  if (r->left.n && !left_match(&S, &src, b, &r->left, r->left.n - 1, &lend, M->string_mode)) return 0;
  if (r->nleft.n) {
    // the string written so far, read up the tree from its end
    view dst = {M->dest, M->dest->n, 0, NULL, ign, M->nsym};
    if (!left_match(&S, &dst, dst.n, &r->nleft, r->nleft.n - 1, &tmp, M->string_mode)) return 0;
  }
  if (r->nright.n) {
    // the string written so far by the backward pass starts after the predecessor
    view dst = {M->dest, M->dest->n, 1, NULL, ign, M->nsym};
    int64_t lm = NONE;
    if (!right_match(&S, &dst, 0, &lm, &r->nright, 0, r->nright.n, &tmp, M->string_mode)) return 0;
  }
  int64_t rend = e, rlast = e - 1;
  if (r->right.n && !right_match(&S, &src, e, &rlast, &r->right, 0, r->right.n, &rend, M->string_mode)) return 0;
  // "As String": an InRightContext goes on after the last module matched, not at it
  if (r->right.n && M->string_mode) rend = next_module(&src, rend, 0);
  *first = b;
  *end = e;
  if (cur) *cur = (lsys_cur){M, r, lend, rend, rlast};
  return 1;
}

int lsys_context_match(vd_lsystem* ls, int right, const pstr* p, value* frame) {
  lsys_cur* c = &ls->cur;
  const lsys_mctx* M = c->M;
  if (!M) return 0;
  if (!p->n) return 1;
  mstate S = {ls, frame};
  const unsigned char* ign = M->ignored[c->r->filter + 1];
  view src = {M->src, M->src->n, 0, M->match, ign, M->nsym};
  int64_t end, lm = c->rlast;
  int ok = right ? right_match(&S, &src, c->right, &lm, p, 0, p->n, &end, M->string_mode)
                 : left_match(&S, &src, c->left, p, p->n - 1, &end, M->string_mode);
  if (ls->err && ls->err->status) return -1;
  if (!ok) return 0;
  if (right) {
    c->right = M->string_mode ? next_module(&src, end, 0) : end;  // as in lsys_rule_match
    c->rlast = lm;
  } else {
    c->left = end;
  }
  return 1;
}
