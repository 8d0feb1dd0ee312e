// SPDX-License-Identifier: MIT
// Symbol table (predefined L-Py modules, declared and one-character modules), the string
// table behind NaN-boxed string parameters, global slots, and L-string storage.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lsys/lsys_internal.h"

static const char* predefined_names[] = {
#define VD_SYM_NAME(e, s) s,
    VD_SYM_LIST(VD_SYM_NAME)
#undef VD_SYM_NAME
};

const char* vd_sym_predefined_name(int sym) {
  if (sym < 0 || sym >= VD_SYM_PREDEFINED_COUNT) return NULL;
  return predefined_names[sym];
}

// FNV-1a over the name bytes
static uint32_t hash_name(const char* s, int len) {
  uint32_t h = 2166136261u;
  for (int i = 0; i < len; i++) h = (h ^ (unsigned char)s[i]) * 16777619u;
  return h;
}

static int sym_rehash(symtab* t, int hcap) {
  int* slots = vd_malloc((size_t)hcap * sizeof(int));
  if (!slots) return 0;
  for (int i = 0; i < hcap; i++) slots[i] = -1;
  for (int id = 0; id < t->n; id++) {
    uint32_t h = hash_name(t->name[id], (int)strlen(t->name[id])) & (uint32_t)(hcap - 1);
    while (slots[h] >= 0) h = (h + 1) & (uint32_t)(hcap - 1);
    slots[h] = id;
  }
  vd_free(t->hash_slot, (size_t)t->hcap * sizeof(int));
  t->hash_slot = slots;
  t->hcap = hcap;
  return 1;
}

int sym_find(const vd_lsystem* ls, const char* name, int len) {
  const symtab* t = &ls->syms;
  if (!t->hcap) return -1;
  uint32_t h = hash_name(name, len) & (uint32_t)(t->hcap - 1);
  while (t->hash_slot[h] >= 0) {
    int id = t->hash_slot[h];
    if ((int)strlen(t->name[id]) == len && memcmp(t->name[id], name, (size_t)len) == 0) return id;
    h = (h + 1) & (uint32_t)(t->hcap - 1);
  }
  return -1;
}

int sym_intern(vd_lsystem* ls, const char* name, int len, int declared) {
  symtab* t = &ls->syms;
  int id = sym_find(ls, name, len);
  if (id >= 0) {
    if (declared && !t->declared[id]) {
      t->declared[id] = 1;
      if (len > t->maxlen) t->maxlen = len;
    }
    return id;
  }
  if (!vd_grow((void**)&t->name, &t->cap, t->n + 1, sizeof(char*)) ||
      !vd_grow((void**)&t->declared, &t->cap_declared, t->n + 1, 1) ||
      !vd_grow((void**)&t->canon, &t->cap_canon, t->n + 1, sizeof(int)))
    return -1;
  char* s = vd_malloc((size_t)len + 1);
  if (!s) return -1;
  memcpy(s, name, (size_t)len);
  s[len] = 0;
  id = t->n++;
  t->name[id] = s;
  t->canon[id] = id;
  t->declared[id] = (unsigned char)(declared != 0);
  if (declared && len > t->maxlen) t->maxlen = len;
  if (t->n * 2 > t->hcap) {
    if (!sym_rehash(t, t->hcap ? t->hcap * 2 : 256)) return -1;
  } else {
    uint32_t h = hash_name(s, len) & (uint32_t)(t->hcap - 1);
    while (t->hash_slot[h] >= 0) h = (h + 1) & (uint32_t)(t->hcap - 1);
    t->hash_slot[h] = id;
  }
  return id;
}

int sym_alias(vd_lsystem* ls, const char* alias, int canon) {
  int id = sym_intern(ls, alias, (int)strlen(alias), 1);
  if (id < 0) return -1;
  ls->syms.canon[id] = canon;
  return id;
}

const char* vd_lsys_symbol_name(const vd_lsystem* ls, int sym) {
  if (!ls) {
    const char* p = vd_sym_predefined_name(sym);
    return p ? p : "?";
  }
  if (sym < 0 || sym >= ls->syms.n) return "?";
  return ls->syms.name[sym];
}

int vd_lsys_symbol_count(const vd_lsystem* ls) { return ls->syms.n; }

int vd_lsys_symbol_find(const vd_lsystem* ls, const char* name) {
  int id = sym_find(ls, name, (int)strlen(name));
  return id < 0 ? id : sym_canon(ls, id);
}

// strings: interned, referenced from values and NaN-boxed inside L-strings
#define STR_TAG 0x7ffc5d0000000000ull
#define STR_MASK 0xffffff0000000000ull

double lsys_box_str(int id) {
  uint64_t bits = STR_TAG | (uint64_t)(uint32_t)id;
  double d;
  memcpy(&d, &bits, sizeof d);
  return d;
}

int lsys_unbox_str(double v) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  if ((bits & STR_MASK) != STR_TAG) return -1;
  return (int)(bits & 0xffffffffu);
}

// Python engine objects: tag, 8-bit epoch, 32-bit slot
#define OBJ_TAG 0x7ffc5e0000000000ull

double lsys_box_obj(uint32_t id, unsigned epoch) {
  uint64_t bits = OBJ_TAG | ((uint64_t)(epoch & 0xffu) << 32) | (uint64_t)id;
  double d;
  memcpy(&d, &bits, sizeof d);
  return d;
}

int lsys_unbox_obj(double v, uint32_t* id, unsigned* epoch) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  if ((bits & STR_MASK) != OBJ_TAG) return 0;
  *id = (uint32_t)(bits & 0xffffffffu);
  *epoch = (unsigned)((bits >> 32) & 0xffu);
  return 1;
}

int vd_lsys_value_is_obj(double v) {
  uint32_t id;
  unsigned e;
  return lsys_unbox_obj(v, &id, &e);
}

int vd_lsys_value_is_str(double v) { return lsys_unbox_str(v) >= 0; }

const char* vd_lsys_value_str(const vd_lsystem* ls, double v) {
  int id = lsys_unbox_str(v);
  if (!ls || id < 0 || id >= ls->nstr) return NULL;
  return ls->str[id];
}

// rebuild the string index with hcap slots (a power of two)
static int str_rehash(vd_lsystem* ls, int hcap) {
  int* slots = vd_malloc((size_t)hcap * sizeof(int));
  if (!slots) return 0;
  for (int i = 0; i < hcap; i++) slots[i] = -1;
  for (int id = 0; id < ls->nstr; id++) {
    uint32_t h = hash_name(ls->str[id], (int)strlen(ls->str[id])) & (uint32_t)(hcap - 1);
    while (slots[h] >= 0) h = (h + 1) & (uint32_t)(hcap - 1);
    slots[h] = id;
  }
  vd_free(ls->str_slot, (size_t)ls->str_hcap * sizeof(int));
  ls->str_slot = slots;
  ls->str_hcap = hcap;
  return 1;
}

// strings made at run time ('a' + s in a loop) would make a linear lookup quadratic and the
// table unbounded: they are indexed by hash and limited in total size
int str_intern(vd_lsystem* ls, const char* s, int len) {
  uint32_t h0 = hash_name(s, len);
  if (ls->str_hcap) {
    for (uint32_t h = h0 & (uint32_t)(ls->str_hcap - 1); ls->str_slot[h] >= 0;
         h = (h + 1) & (uint32_t)(ls->str_hcap - 1)) {
      const char* t = ls->str[ls->str_slot[h]];
      if ((int)strlen(t) == len && memcmp(t, s, (size_t)len) == 0) return ls->str_slot[h];
    }
  }
  if (ls->str_bytes + len + 1 > LSYS_MAX_STR_BYTES) return -2;
  if (!vd_grow((void**)&ls->str, &ls->capstr, ls->nstr + 1, sizeof(char*))) return -1;
  if ((ls->nstr + 1) * 2 > ls->str_hcap && !str_rehash(ls, ls->str_hcap ? ls->str_hcap * 2 : 64))
    return -1;
  char* c = vd_malloc((size_t)len + 1);
  if (!c) return -1;
  memcpy(c, s, (size_t)len);
  c[len] = 0;
  ls->str[ls->nstr] = c;
  ls->str_bytes += len + 1;
  uint32_t h = h0 & (uint32_t)(ls->str_hcap - 1);
  while (ls->str_slot[h] >= 0) h = (h + 1) & (uint32_t)(ls->str_hcap - 1);
  ls->str_slot[h] = ls->nstr;
  return ls->nstr++;
}

vd_status str_intern_error(vd_lsystem* ls, int id, int line, int col) {
  if (id == -2)
    return vm_error(ls, VD_ERR_LIMIT, line, col, "the strings of the model exceed %d bytes",
                    LSYS_MAX_STR_BYTES);
  return vm_error(ls, VD_ERR_NOMEM, line, col, "out of memory");
}

// globals: a slot per name, values reset at the start of each derivation
int global_slot(vd_lsystem* ls, const char* name, int len, int create) {
  for (int i = 0; i < ls->nglobal; i++)
    if ((int)strlen(ls->gdef[i].name) == len && memcmp(ls->gdef[i].name, name, (size_t)len) == 0)
      return i;
  if (!create) return -1;
  if (!vd_grow((void**)&ls->gdef, &ls->capglobal, ls->nglobal + 1, sizeof(global_def)) ||
      !vd_grow((void**)&ls->gval, &ls->capgval, ls->nglobal + 1, sizeof(value)))
    return -1;
  global_def* g = &ls->gdef[ls->nglobal];
  memset(g, 0, sizeof *g);
  g->name = vd_malloc((size_t)len + 1);
  if (!g->name) return -1;
  memcpy(g->name, name, (size_t)len);
  g->name[len] = 0;
  ls->gval[ls->nglobal].t = V_UNDEF;
  ls->gval[ls->nglobal].n = 0;
  return ls->nglobal++;
}

// ---------------------------------------------------------------------------------------------
// L-string storage

int lstr_reserve(vd_lstring* s, int64_t nmod, int64_t nval) {
  if (nmod > s->cap) {
    // grow sym, par (cap + 1 entries) and src together; on failure nothing changes
    int64_t nc = s->cap < 64 ? 64 : s->cap;
    while (nc < nmod) nc += nc / 2;
    if ((uint64_t)nc > SIZE_MAX / 16) return 0;
    int32_t* sym = vd_malloc((size_t)nc * sizeof(int32_t));
    int64_t* par = vd_malloc((size_t)(nc + 1) * sizeof(int64_t));
    int64_t* src = s->src ? vd_malloc((size_t)nc * sizeof(int64_t)) : NULL;
    int32_t* line = s->line ? vd_malloc((size_t)nc * sizeof(int32_t)) : NULL;
    if (!sym || !par || (s->src && !src) || (s->line && !line)) {
      vd_free(sym, (size_t)nc * sizeof(int32_t));
      vd_free(par, (size_t)(nc + 1) * sizeof(int64_t));
      vd_free(src, (size_t)nc * sizeof(int64_t));
      vd_free(line, (size_t)nc * sizeof(int32_t));
      return 0;
    }
    if (s->n) memcpy(sym, s->sym, (size_t)s->n * sizeof(int32_t));
    memcpy(par, s->par ? s->par : (int64_t[]){0}, (size_t)(s->n + 1) * sizeof(int64_t));
    if (src && s->n) memcpy(src, s->src, (size_t)s->n * sizeof(int64_t));
    if (line && s->n) memcpy(line, s->line, (size_t)s->n * sizeof(int32_t));
    vd_free(s->sym, (size_t)s->cap * sizeof(int32_t));
    vd_free(s->par, s->cap ? (size_t)(s->cap + 1) * sizeof(int64_t) : 0);
    if (s->src) vd_free(s->src, (size_t)s->cap * sizeof(int64_t));
    if (s->line) vd_free(s->line, (size_t)s->cap * sizeof(int32_t));
    s->sym = sym;
    s->par = par;
    if (s->src) s->src = src;
    if (s->line) s->line = line;
    s->cap = nc;
  }
  if (nval > s->vcap) {
    int64_t nc = s->vcap < 64 ? 64 : s->vcap;
    while (nc < nval) nc += nc / 2;
    if ((uint64_t)nc > SIZE_MAX / 16) return 0;
    double* v = vd_realloc(s->val, (size_t)s->vcap * sizeof(double), (size_t)nc * sizeof(double));
    if (!v) return 0;
    s->val = v;
    s->vcap = nc;
  }
  if (!s->par) return 0;
  return 1;
}

int lstr_enable_src(vd_lstring* s) {
  if (s->src) return 1;
  int64_t c = s->cap ? s->cap : 64;
  if (!s->cap && !lstr_reserve(s, 64, 0)) return 0;
  s->src = vd_malloc((size_t)c * sizeof(int64_t));
  return s->src != NULL;
}

int lstr_enable_line(vd_lstring* s) {
  if (s->line) return 1;
  if (!s->cap && !lstr_reserve(s, 64, 0)) return 0;
  s->line = vd_calloc((size_t)s->cap, sizeof(int32_t));
  return s->line != NULL;
}

int lsys_lstring_copy(vd_lstring* dst, const vd_lstring* src) {
  lstr_clear(dst);
  if (!lstr_reserve(dst, src->n + 1, src->par[src->n] + 1)) return 0;
  if (src->src && !lstr_enable_src(dst)) return 0;
  if (src->line && !lstr_enable_line(dst)) return 0;
  if (src->line) memcpy(dst->line, src->line, sizeof(int32_t) * (size_t)src->n);
  memcpy(dst->sym, src->sym, sizeof(int32_t) * (size_t)src->n);
  memcpy(dst->par, src->par, sizeof(int64_t) * (size_t)(src->n + 1));
  memcpy(dst->val, src->val, sizeof(double) * (size_t)src->par[src->n]);
  if (src->src) memcpy(dst->src, src->src, sizeof(int64_t) * (size_t)src->n);
  dst->n = src->n;
  return 1;
}

void lstr_clear(vd_lstring* s) {
  s->n = 0;
  if (s->par) s->par[0] = 0;
}

void vd_lstring_free(vd_lstring* s) {
  if (!s) return;
  vd_free(s->sym, (size_t)s->cap * sizeof(int32_t));
  vd_free(s->par, s->cap ? (size_t)(s->cap + 1) * sizeof(int64_t) : 0);
  vd_free(s->src, (size_t)s->cap * sizeof(int64_t));
  vd_free(s->line, (size_t)s->cap * sizeof(int32_t));
  vd_free(s->val, (size_t)s->vcap * sizeof(double));
  *s = vd_lstring_empty();
}

// ---------------------------------------------------------------------------------------------
// textual form of an L-string

static void fmt_num(double v, char* b, size_t cap) {
  // shortest representation that reads back exactly, as Python's repr
  if (v == floor(v) && fabs(v) < 1e15) {
    snprintf(b, cap, "%.0f", v);
    return;
  }
  for (int p = 1; p <= 17; p++) {
    snprintf(b, cap, "%.*g", p, v);
    if (strtod(b, NULL) == v) return;
  }
}

char* vd_lsys_format(const vd_lsystem* ls, const vd_lstring* s, char* buf, size_t cap) {
  if (!buf || cap == 0) return buf;
  size_t n = strlen(buf);
  for (int64_t i = 0; i < s->n && n + 1 < cap; i++) {
    const char* name = vd_lsys_symbol_name(ls, s->sym[i]);
    n += (size_t)snprintf(buf + n, cap - n, "%s", name);
    if (n >= cap) break;
    int np = vd_lstring_nparam(s, i);
    for (int k = 0; k < np && n < cap; k++) {
      double v = s->val[s->par[i] + k];
      char num[256];
      const char* str = vd_lsys_value_str(ls, v);
      if (str)
        snprintf(num, sizeof num, "'%s'", str);
      else if (ls && ls->py && vd_lsys_value_is_obj(v))
        lsys_py_repr(ls, v, num, sizeof num);
      else
        fmt_num(v, num, sizeof num);
      n += (size_t)snprintf(buf + n, cap - n, "%s%s%s", k == 0 ? "(" : ",", num, k == np - 1 ? ")" : "");
    }
  }
  if (n >= cap) buf[cap - 1] = 0;
  return buf;
}

// label names declared by the file
int vd_lsys_label_count(const vd_lsystem* ls) { return ls->nlabel; }

void vd_lsys_label_get(const vd_lsystem* ls, int i, int* id, const char** name) {
  *id = ls->label_id[i];
  *name = ls->label_name[i];
}
