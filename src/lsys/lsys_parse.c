// SPDX-License-Identifier: MIT
// Parser for the L-Py file syntax and its small Python subset.
//
// The file is cut into logical lines (brackets and backslashes join physical lines), each with
// its indentation. Keyword lines (Axiom:, production:, module, ...) drive a small state machine;
// rule headers and successors are read character by character (module names by longest match
// against predefined and declared names, else one character), and Python expressions and
// statements by a token-level recursive descent parser. Everything is allocated in the
// lsystem's arena; errors carry the file, line and column.
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lsys/lsys_internal.h"

// ---------------------------------------------------------------------------------------------
// logical lines

typedef lsys_line pline;  // lsys_internal.h: the Python engine reads them too

typedef struct parser {
  vd_lsystem* ls;
  pline* lines;
  int nline, capline;
  char* joined;       // storage for joined logical lines (arena)
  int failed;
  int discard_decorator;  // the next def is decorated with @enable_string_discard
} parser;

// parse errors are recorded like run-time errors: the first one wins
#define perr vm_error

static void* aalloc(vd_lsystem* ls, size_t n) {
  void* p = vd_arena_alloc(&ls->arena, n);
  if (p) memset(p, 0, n);
  return p;
}

// does the line text (after indentation) hold only a comment or nothing?
static int is_blank(const char* s, int len) {
  for (int i = 0; i < len; i++) {
    if (s[i] == '#') return 1;
    if (!isspace((unsigned char)s[i])) return 0;
  }
  return 1;
}

static int is_space_c(char c) { return c == ' ' || c == '\t'; }

static int word_at(const char* s, int len, int i, const char* w) {
  int n = (int)strlen(w);
  if (i + n > len || memcmp(s + i, w, (size_t)n) != 0) return 0;
  if (i > 0 && (isalnum((unsigned char)s[i - 1]) || s[i - 1] == '_')) return 0;
  return i + n == len || !(isalnum((unsigned char)s[i + n]) || s[i + n] == '_');
}

// the end of a triple-quoted string closed by three q from s[i]: the index after it, or -1
static int triple_end(const char* s, int len, int i, char q) {
  for (; i + 2 < len; i++) {
    if (s[i] == '\\') {
      i++;
      continue;
    }
    if (s[i] == q && s[i + 1] == q && s[i + 2] == q) return i + 3;
  }
  return -1;
}

// bracket balance change of a physical line, ignoring strings and comments. In L-strings
// (after produce/nproduce, after -->, on Axiom:/ignore:/consider: lines) only parentheses
// count: [ ] { } are modules there, and a trailing \ is the RollR module, not a continuation.
// *tq: the quote of a triple-quoted string open at the start of the line (0 if none), and at
// its end (Python docstrings span lines).
static int bracket_delta(const char* s, int len, int* backslash, int header, char* tq) {
  int d = 0;
  char q = 0;
  int lstr = header;  // a rule header: brackets are modules in its patterns
  *backslash = 0;
  int start = 0;
  if (*tq) {
    start = triple_end(s, len, 0, *tq);
    if (start < 0) return 0;  // the whole line is inside the string
    *tq = 0;
  }
  static const char* lstr_lines[] = {"Axiom:", "axiom:", "ignore:", "consider:"};
  for (size_t k = 0; k < sizeof lstr_lines / sizeof lstr_lines[0]; k++)
    if (len >= (int)strlen(lstr_lines[k]) && memcmp(s, lstr_lines[k], strlen(lstr_lines[k])) == 0) lstr = 1;
  for (int i = start; i < len; i++) {
    char c = s[i];
    if (q) {
      if (c == '\\') i++;
      else if (c == q) q = 0;
      continue;
    }
    if (c == '#') break;
    if (!lstr && (word_at(s, len, i, "produce") || word_at(s, len, i, "nproduce") ||
                  (i + 3 <= len && memcmp(s + i, "-->", 3) == 0)))
      lstr = 1;
    if ((c == '\'' || c == '"') && i + 2 < len && s[i + 1] == c && s[i + 2] == c) {
      int e = triple_end(s, len, i + 3, c);
      if (e < 0) {
        *tq = c;
        return d;
      }
      i = e - 1;
      continue;
    }
    if (c == '\'' || c == '"') q = c;
    else if (c == '(' || (!lstr && (c == '[' || c == '{'))) d++;
    else if (c == ')' || (!lstr && (c == ']' || c == '}'))) d--;
  }
  int e = len;
  while (e > 0 && isspace((unsigned char)s[e - 1])) e--;
  if (e > 0 && s[e - 1] == '\\' && !q && !lstr) *backslash = 1;
  return d;
}

static int is_init_marker(const char* s, int len) {
  // "###### INITIALISATION ######" written by the L-Py editor
  if (len < 8 || s[0] != '#') return 0;
  for (int i = 0; i + 14 <= len; i++)
    if (memcmp(s + i, "INITIALISATION", 14) == 0 || memcmp(s + i, "INITIALIZATION", 14) == 0)
      return 1;
  return 0;
}

// split text into logical lines; returns the offset where the INITIALISATION block starts
static vd_status split_lines(parser* P, const char* text, size_t len, size_t* init_at) {
  vd_lsystem* ls = P->ls;
  *init_at = len;
  size_t pos = 0;
  int lineno = 0;
  int in_rules = 0, rule_indent = -1;  // inside a rule section; indentation of its rules
  while (pos < len) {
    // one physical line
    size_t start = pos;
    while (pos < len && text[pos] != '\n') pos++;
    size_t end = pos;
    if (pos < len) pos++;
    lineno++;
    if (end > start && text[end - 1] == '\r') end--;
    const char* s = text + start;
    int n = (int)(end - start);
    // indentation
    int ind = 0, k = 0;
    while (k < n && (s[k] == ' ' || s[k] == '\t')) {
      ind = s[k] == '\t' ? (ind / 8 + 1) * 8 : ind + 1;
      k++;
    }
    if (ind == 0 && is_init_marker(s, n)) {
      *init_at = start;
      break;
    }
    pline L = {s + k, n - k, lineno, k + 1, ind, is_blank(s + k, n - k), lineno};
    // rule sections: their header lines (at the section's rule indentation) hold patterns,
    // where [ ] { } are modules; the indented bodies are Python
    int header = 0;
    if (!L.blank) {
      static const char* secs[] = {"production", "interpretation", "homomorphism", "decomposition"};
      int is_sec = 0;
      for (size_t q = 0; q < sizeof secs / sizeof secs[0]; q++) {
        int kl = (int)strlen(secs[q]), p = kl;
        if (ind == 0 && L.len >= kl && memcmp(L.s, secs[q], (size_t)kl) == 0) {
          while (p < L.len && is_space_c(L.s[p])) p++;
          if (p < L.len && L.s[p] == ':') is_sec = 1;
        }
      }
      if (is_sec) {
        in_rules = 1;
        rule_indent = -1;
      } else if (ind == 0 && (word_at(L.s, L.len, 0, "endlsystem") || word_at(L.s, L.len, 0, "def") ||
                              word_at(L.s, L.len, 0, "class") || word_at(L.s, L.len, 0, "Axiom"))) {
        in_rules = 0;
      } else if (in_rules) {
        if (rule_indent < 0) rule_indent = ind;
        header = ind <= rule_indent;
      }
    }
    // join continuation lines while brackets are open, the line ends with a backslash or a
    // triple-quoted string goes on
    int bs = 0;
    char tq = 0;
    int depth = L.blank ? 0 : bracket_delta(L.s, L.len, &bs, header, &tq);
    if (depth > 0 || bs || tq) {
      // copy into the arena, joining with spaces
      size_t cap = (size_t)L.len + 1;
      char* buf = NULL;
      size_t blen = 0;
      buf = vd_arena_alloc(&ls->arena, cap + 1);
      if (!buf) return perr(ls, VD_ERR_NOMEM, lineno, 1, "out of memory");
      memcpy(buf, L.s, (size_t)L.len);
      blen = (size_t)L.len;
      if (bs) {
        while (blen > 0 && isspace((unsigned char)buf[blen - 1])) blen--;
        blen--;  // drop the backslash
      }
      while ((depth > 0 || bs || tq) && pos < len) {
        size_t s2 = pos;
        while (pos < len && text[pos] != '\n') pos++;
        size_t e2 = pos;
        if (pos < len) pos++;
        lineno++;
        if (e2 > s2 && text[e2 - 1] == '\r') e2--;
        int d2 = bracket_delta(text + s2, (int)(e2 - s2), &bs, header, &tq);
        depth += d2;
        // strip a trailing comment from the piece before joining
        size_t piece = e2 - s2;
        {
          char q = 0;
          for (size_t i = 0; i < piece; i++) {
            char c = text[s2 + i];
            if (q) {
              if (c == '\\') i++;
              else if (c == q) q = 0;
            } else if (c == '\'' || c == '"') {
              q = c;
            } else if (c == '#') {
              piece = i;
              break;
            }
          }
        }
        char* nb = vd_arena_alloc(&ls->arena, blen + 1 + piece + 1);
        if (!nb) return perr(ls, VD_ERR_NOMEM, lineno, 1, "out of memory");
        memcpy(nb, buf, blen);
        nb[blen++] = ' ';
        memcpy(nb + blen, text + s2, piece);
        blen += piece;
        if (bs) {
          while (blen > 0 && isspace((unsigned char)nb[blen - 1])) blen--;
          if (blen > 0) blen--;
        }
        buf = nb;
      }
      if (tq)
        return perr(ls, VD_ERR_SYNTAX, L.lineno, L.col0, "unterminated triple-quoted string");
      if (depth > 0)
        return perr(ls, VD_ERR_SYNTAX, L.lineno, L.col0, "unclosed bracket at end of file");
      L.s = buf;
      L.len = (int)blen;
    }
    L.lastline = lineno;
    if (!vd_grow((void**)&P->lines, &P->capline, P->nline + 1, sizeof(pline)))
      return perr(ls, VD_ERR_NOMEM, lineno, 1, "out of memory");
    P->lines[P->nline++] = L;
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// tokens

enum {
  T_EOF = 0, T_NUM, T_STR, T_NAME, T_OP
};

// two- and three-character operators are encoded as small integers above 255
enum {
  OP_EQ = 256, OP_NE, OP_LE, OP_GE, OP_POW, OP_FLOORDIV, OP_ARROW, OP_SHL, OP_SHR,
  OP_ADDEQ, OP_SUBEQ, OP_MULEQ, OP_DIVEQ, OP_MODEQ, OP_POWEQ, OP_FLOORDIVEQ, OP_WALRUS
};

typedef struct lexer {
  vd_lsystem* ls;
  const char* s;  // text of the logical line
  int len;
  int pos;
  int lineno, col0;
  // current token
  int t;          // T_*
  int op;         // operator code when t == T_OP
  int start;      // token start offset
  int tlen;
  double num;
  int is_int;
  int sid;        // string id when t == T_STR
} lexer;

typedef struct scope {
  // names of locals: slot i has name names[i]
  int n, cap, caplen;     // count, capacities of names and lens (grown one after the other)
  const char** names;
  int* lens;
  const char** globals;  // names declared global
  int* glens;
  int ng, capg, capglen;  // count, capacities of globals and glens
  int is_function;       // 0 at top level (all names are globals)
} scope;

static int lx_col(const lexer* L) { return L->col0 + L->start; }

static vd_status lx_next(lexer* L) {
  const char* s = L->s;
  while (L->pos < L->len && (s[L->pos] == ' ' || s[L->pos] == '\t')) L->pos++;
  L->start = L->pos;
  if (L->pos >= L->len || s[L->pos] == '#') {
    L->t = T_EOF;
    L->tlen = 0;
    return VD_OK;
  }
  char c = s[L->pos];
  // numbers: 12, 1.5, .5, 1e-3, 0x1F, with _ separators
  if (isdigit((unsigned char)c) || (c == '.' && L->pos + 1 < L->len && isdigit((unsigned char)s[L->pos + 1]))) {
    char buf[128];
    int n = 0, isint = 1;
    int p = L->pos;
    if (c == '0' && p + 1 < L->len && (s[p + 1] == 'x' || s[p + 1] == 'X')) {
      p += 2;
      while (p < L->len && (isxdigit((unsigned char)s[p]) || s[p] == '_')) {
        if (s[p] != '_' && n < 120) buf[n++] = s[p];
        p++;
      }
      buf[n] = 0;
      L->num = (double)strtoull(buf, NULL, 16);
    } else {
      while (p < L->len) {
        char d = s[p];
        if (isdigit((unsigned char)d) || d == '_') {
        } else if (d == '.') {
          isint = 0;
        } else if ((d == 'e' || d == 'E') && p + 1 < L->len &&
                   (isdigit((unsigned char)s[p + 1]) ||
                    ((s[p + 1] == '+' || s[p + 1] == '-') && p + 2 < L->len && isdigit((unsigned char)s[p + 2])))) {
          isint = 0;
          if (n < 120) buf[n++] = d;
          p++;
          d = s[p];
        } else {
          break;
        }
        if (d != '_' && n < 120) buf[n++] = d;
        p++;
      }
      buf[n] = 0;
      L->num = strtod(buf, NULL);
    }
    if (p < L->len && (isalpha((unsigned char)s[p]) || s[p] == '_'))
      return perr(L->ls, VD_ERR_SYNTAX, L->lineno, L->col0 + p, "invalid number literal");
    L->is_int = isint;
    L->t = T_NUM;
    L->tlen = p - L->pos;
    L->pos = p;
    return VD_OK;
  }
  // names
  if (isalpha((unsigned char)c) || c == '_') {
    int p = L->pos;
    while (p < L->len && (isalnum((unsigned char)s[p]) || s[p] == '_')) p++;
    // string prefixes r'', b'', f'' are not supported (u'' is a plain string in Python 3)
    if (p == L->pos + 1 && (c == 'u' || c == 'U') && p < L->len && (s[p] == '\'' || s[p] == '"')) {
      L->pos = p;
      return lx_next(L);
    }
    if (p < L->len && (s[p] == '\'' || s[p] == '"') && p - L->pos <= 2)
      return perr(L->ls, VD_ERR_UNSUPPORTED, L->lineno, L->col0 + L->pos,
                  "unsupported: prefixed string literal");
    L->t = T_NAME;
    L->tlen = p - L->pos;
    L->pos = p;
    return VD_OK;
  }
  // strings
  if (c == '\'' || c == '"') {
    char q = c;
    int p = L->pos + 1;
    if (p + 1 < L->len && s[p] == q && s[p + 1] == q)
      return perr(L->ls, VD_ERR_UNSUPPORTED, L->lineno, L->col0 + L->pos,
                  "unsupported: triple-quoted string");
    char buf[1024];
    int n = 0;
    while (p < L->len && s[p] != q) {
      char d = s[p];
      if (d == '\\' && p + 1 < L->len) {
        p++;
        d = s[p];
        if (d == 'n') d = '\n';
        else if (d == 't') d = '\t';
      }
      if (n < 1023) buf[n++] = d;
      p++;
    }
    if (p >= L->len)
      return perr(L->ls, VD_ERR_SYNTAX, L->lineno, L->col0 + L->pos, "unterminated string");
    L->sid = str_intern(L->ls, buf, n);
    if (L->sid < 0) return str_intern_error(L->ls, L->sid, L->lineno, L->col0 + L->pos);
    L->t = T_STR;
    L->tlen = p + 1 - L->pos;
    L->pos = p + 1;
    return VD_OK;
  }
  // operators
  static const struct {
    const char* s;
    int code;
  } ops[] = {{"**=", OP_POWEQ}, {"//=", OP_FLOORDIVEQ}, {"**", OP_POW}, {"//", OP_FLOORDIV},
             {"==", OP_EQ},     {"!=", OP_NE},          {"<=", OP_LE},  {">=", OP_GE},
             {"->", OP_ARROW},  {"<<", OP_SHL},         {">>", OP_SHR}, {"+=", OP_ADDEQ},
             {"-=", OP_SUBEQ},  {"*=", OP_MULEQ},       {"/=", OP_DIVEQ}, {"%=", OP_MODEQ},
             {":=", OP_WALRUS}};
  for (size_t i = 0; i < sizeof ops / sizeof ops[0]; i++) {
    int n = (int)strlen(ops[i].s);
    if (L->pos + n <= L->len && memcmp(s + L->pos, ops[i].s, (size_t)n) == 0) {
      L->t = T_OP;
      L->op = ops[i].code;
      L->tlen = n;
      L->pos += n;
      return VD_OK;
    }
  }
  if (strchr("()[]{},:.;=<>+-*/%~&|^@", c)) {
    L->t = T_OP;
    L->op = (unsigned char)c;
    L->tlen = 1;
    L->pos++;
    return VD_OK;
  }
  return perr(L->ls, VD_ERR_SYNTAX, L->lineno, L->col0 + L->pos, "unexpected character '%c'", c);
}

static int tok_is(const lexer* L, int op) { return L->t == T_OP && L->op == op; }
static int tok_name(const lexer* L, const char* kw) {
  return L->t == T_NAME && L->tlen == (int)strlen(kw) && memcmp(L->s + L->start, kw, (size_t)L->tlen) == 0;
}

static void lx_init(lexer* L, vd_lsystem* ls, const char* s, int len, int lineno, int col0, int pos) {
  memset(L, 0, sizeof *L);
  L->ls = ls;
  L->s = s;
  L->len = len;
  L->lineno = lineno;
  L->col0 = col0;
  L->pos = pos;
}

static const char* tok_desc(const lexer* L, char* buf, size_t cap) {
  if (L->t == T_EOF) return "end of line";
  snprintf(buf, cap, "'%.*s'", L->tlen > 40 ? 40 : L->tlen, L->s + L->start);
  return buf;
}

static vd_status expect(lexer* L, int op, const char* what) {
  if (!tok_is(L, op)) {
    char b[64];
    return perr(L->ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected %s, found %s", what,
                tok_desc(L, b, sizeof b));
  }
  return lx_next(L);
}

// ---------------------------------------------------------------------------------------------
// scopes

static int scope_find(const scope* sc, const char* name, int len) {
  for (int i = 0; i < sc->n; i++)
    if (sc->lens[i] == len && memcmp(sc->names[i], name, (size_t)len) == 0) return i;
  return -1;
}

static int scope_add(vd_lsystem* ls, scope* sc, const char* name, int len) {
  int i = scope_find(sc, name, len);
  if (i >= 0) return i;
  if (!vd_grow((void**)&sc->names, &sc->cap, sc->n + 1, sizeof(char*)) ||
      !vd_grow((void**)&sc->lens, &sc->caplen, sc->n + 1, sizeof(int)))
    return -1;
  (void)ls;
  sc->names[sc->n] = name;
  sc->lens[sc->n] = len;
  return sc->n++;
}

static int scope_is_global(const scope* sc, const char* name, int len) {
  for (int i = 0; i < sc->ng; i++)
    if (sc->glens[i] == len && memcmp(sc->globals[i], name, (size_t)len) == 0) return 1;
  return 0;
}

static int scope_add_global(scope* sc, const char* name, int len) {
  if (scope_is_global(sc, name, len)) return 1;
  if (!vd_grow((void**)&sc->globals, &sc->capg, sc->ng + 1, sizeof(char*)) ||
      !vd_grow((void**)&sc->glens, &sc->capglen, sc->ng + 1, sizeof(int)))
    return 0;
  sc->globals[sc->ng] = name;
  sc->glens[sc->ng] = len;
  sc->ng++;
  return 1;
}

static void scope_free(scope* sc) {
  vd_free(sc->names, (size_t)sc->cap * sizeof(char*));
  vd_free(sc->lens, (size_t)sc->caplen * sizeof(int));
  vd_free(sc->globals, (size_t)sc->capg * sizeof(char*));
  vd_free(sc->glens, (size_t)sc->capglen * sizeof(int));
  memset(sc, 0, sizeof *sc);
}

// ---------------------------------------------------------------------------------------------
// expressions

typedef struct pctx {
  vd_lsystem* ls;
  lexer* L;
  scope* sc;
} pctx;

static expr* new_expr(pctx* C, int op, int col) {
  expr* e = aalloc(C->ls, sizeof(expr));
  if (!e) {
    perr(C->ls, VD_ERR_NOMEM, C->L->lineno, col, "out of memory");
    return NULL;
  }
  e->op = op;
  e->line = C->L->lineno;
  e->col = col;
  return e;
}

static expr* parse_expr(pctx* C);

static const char* unsupported_kw[] = {"lambda", "yield", "await", "class", "try", "except",
                                       "finally", "with", "raise", "del", "async", "nonlocal",
                                       "is", "in", "from", "import", NULL};

static expr* parse_call_args(pctx* C, expr* e) {
  // after '(' : positional arguments only
  lexer* L = C->L;
  expr* args[64];
  int n = 0;
  if (lx_next(L)) return NULL;
  while (!tok_is(L, ')')) {
    if (n == 64) {
      perr(C->ls, VD_ERR_LIMIT, L->lineno, lx_col(L), "more than 64 call arguments");
      return NULL;
    }
    if (L->t == T_NAME) {
      // keyword arguments are not part of the subset
      lexer save = *L;
      if (lx_next(L)) return NULL;
      if (tok_is(L, '=')) {
        perr(C->ls, VD_ERR_UNSUPPORTED, save.lineno, lx_col(&save),
             "unsupported: keyword argument '%.*s='", save.tlen, save.s + save.start);
        return NULL;
      }
      *L = save;
    }
    if (tok_is(L, '*') || tok_is(L, OP_POW)) {
      perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: argument unpacking");
      return NULL;
    }
    expr* a = parse_expr(C);
    if (!a) return NULL;
    args[n++] = a;
    if (tok_is(L, ',')) {
      if (lx_next(L)) return NULL;
    } else if (!tok_is(L, ')')) {
      char b[64];
      perr(C->ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected ',' or ')' in call, found %s",
           tok_desc(L, b, sizeof b));
      return NULL;
    }
  }
  if (lx_next(L)) return NULL;
  e->nargs = n;
  if (n) {
    e->args = aalloc(C->ls, sizeof(expr*) * (size_t)n);
    if (!e->args) return NULL;
    memcpy(e->args, args, sizeof(expr*) * (size_t)n);
  }
  return e;
}

// a name in an expression: local slot, global slot, or namespace attribute
static expr* parse_name(pctx* C) {
  lexer* L = C->L;
  const char* name = L->s + L->start;
  int len = L->tlen, col = lx_col(L);
  for (int i = 0; unsupported_kw[i]; i++)
    if ((int)strlen(unsupported_kw[i]) == len && memcmp(unsupported_kw[i], name, (size_t)len) == 0) {
      perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, col, "unsupported: '%s'", unsupported_kw[i]);
      return NULL;
    }
  if (lx_next(L)) return NULL;
  expr* e;
  if (len == 4 && memcmp(name, "True", 4) == 0) {
    e = new_expr(C, E_CONST, col);
    if (e) e->k = (value){V_BOOL, 1};
    return e;
  }
  if (len == 5 && memcmp(name, "False", 5) == 0) {
    e = new_expr(C, E_CONST, col);
    if (e) e->k = (value){V_BOOL, 0};
    return e;
  }
  if (len == 4 && memcmp(name, "None", 4) == 0) {
    e = new_expr(C, E_CONST, col);
    if (e) e->k = (value){V_NONE, 0};
    return e;
  }
  int slot = (C->sc && C->sc->is_function && !scope_is_global(C->sc, name, len))
                 ? scope_find(C->sc, name, len)
                 : -1;
  if (slot >= 0) {
    e = new_expr(C, E_LOCAL, col);
    if (e) e->slot = slot;
  } else {
    int g = global_slot(C->ls, name, len, 1);
    if (g < 0) {
      perr(C->ls, VD_ERR_NOMEM, L->lineno, col, "out of memory");
      return NULL;
    }
    e = new_expr(C, E_GLOBAL, col);
    if (e) e->slot = g;
  }
  return e;
}

static expr* parse_atom(pctx* C) {
  lexer* L = C->L;
  int col = lx_col(L);
  expr* e = NULL;
  if (L->t == T_NUM) {
    e = new_expr(C, E_CONST, col);
    if (!e) return NULL;
    e->k = L->is_int ? v_int(L->num) : v_num(L->num);
    if (lx_next(L)) return NULL;
  } else if (L->t == T_STR) {
    e = new_expr(C, E_CONST, col);
    if (!e) return NULL;
    e->k = (value){V_STR, L->sid};
    if (lx_next(L)) return NULL;
    // implicit concatenation of adjacent literals
    while (L->t == T_STR) {
      char buf[2048];
      snprintf(buf, sizeof buf, "%s%s", C->ls->str[(int)e->k.n], C->ls->str[L->sid]);
      int id = str_intern(C->ls, buf, (int)strlen(buf));
      if (id < 0) {
        str_intern_error(C->ls, id, L->lineno, lx_col(L));
        return NULL;
      }
      e->k.n = id;
      if (lx_next(L)) return NULL;
    }
  } else if (L->t == T_NAME) {
    e = parse_name(C);
    if (!e) return NULL;
  } else if (tok_is(L, '(')) {
    if (lx_next(L)) return NULL;
    if (tok_is(L, ')')) {
      perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, col, "unsupported: tuple");
      return NULL;
    }
    e = parse_expr(C);
    if (!e) return NULL;
    if (tok_is(L, ',')) {
      perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: tuple");
      return NULL;
    }
    if (expect(L, ')', "')'")) return NULL;
  } else if (tok_is(L, '[') || tok_is(L, '{')) {
    perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, col, "unsupported: %s literal",
         tok_is(L, '[') ? "list" : "dict or set");
    return NULL;
  } else {
    char b[64];
    perr(C->ls, VD_ERR_SYNTAX, L->lineno, col, "expected an expression, found %s",
         tok_desc(L, b, sizeof b));
    return NULL;
  }
  // trailers: calls and attributes
  for (;;) {
    if (tok_is(L, '(')) {
      expr* c = new_expr(C, E_CALL, lx_col(L));
      if (!c) return NULL;
      c->a = e;
      e = parse_call_args(C, c);
      if (!e) return NULL;
    } else if (tok_is(L, '.')) {
      if (lx_next(L)) return NULL;
      if (L->t != T_NAME) {
        perr(C->ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected an attribute name after '.'");
        return NULL;
      }
      expr* a = new_expr(C, E_ATTR, lx_col(L));
      if (!a) return NULL;
      a->a = e;
      a->slot = str_intern(C->ls, L->s + L->start, L->tlen);
      if (a->slot < 0) {
        str_intern_error(C->ls, a->slot, L->lineno, lx_col(L));
        return NULL;
      }
      if (lx_next(L)) return NULL;
      e = a;
    } else if (tok_is(L, '[')) {
      perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: subscript");
      return NULL;
    } else {
      break;
    }
  }
  return e;
}

static expr* binop(pctx* C, int op, expr* a, expr* b, int col) {
  expr* e = new_expr(C, op, col);
  if (!e) return NULL;
  e->a = a;
  e->b = b;
  return e;
}

static expr* parse_unary(pctx* C);

static expr* parse_power(pctx* C) {
  expr* a = parse_atom(C);
  if (!a) return NULL;
  if (tok_is(C->L, OP_POW)) {
    int col = lx_col(C->L);
    if (lx_next(C->L)) return NULL;
    expr* b = parse_unary(C);  // right associative, binds a unary minus on its right
    if (!b) return NULL;
    return binop(C, E_POW, a, b, col);
  }
  return a;
}

static expr* parse_unary(pctx* C) {
  lexer* L = C->L;
  if (tok_is(L, '-') || tok_is(L, '+')) {
    int neg = tok_is(L, '-'), col = lx_col(L);
    if (lx_next(L)) return NULL;
    expr* a = parse_unary(C);
    if (!a) return NULL;
    // fold constants so that patterns like A(-1) stay constants
    if (a->op == E_CONST && (a->k.t == V_INT || a->k.t == V_FLOAT)) {
      if (neg) a->k.n = -a->k.n;
      return a;
    }
    return binop(C, neg ? E_NEG : E_POS, a, NULL, col);
  }
  if (tok_is(L, '~')) {
    perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: bitwise operator '~'");
    return NULL;
  }
  return parse_power(C);
}

static expr* parse_term(pctx* C) {
  expr* a = parse_unary(C);
  while (a) {
    lexer* L = C->L;
    int op;
    if (tok_is(L, '*')) op = E_MUL;
    else if (tok_is(L, '/')) op = E_DIV;
    else if (tok_is(L, OP_FLOORDIV)) op = E_FLOORDIV;
    else if (tok_is(L, '%')) op = E_MOD;
    else if (tok_is(L, '@')) {
      perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: operator '@'");
      return NULL;
    } else break;
    int col = lx_col(L);
    if (lx_next(L)) return NULL;
    expr* b = parse_unary(C);
    if (!b) return NULL;
    a = binop(C, op, a, b, col);
  }
  return a;
}

static expr* parse_arith(pctx* C) {
  expr* a = parse_term(C);
  while (a) {
    lexer* L = C->L;
    int op;
    if (tok_is(L, '+')) op = E_ADD;
    else if (tok_is(L, '-')) op = E_SUB;
    else break;
    int col = lx_col(L);
    if (lx_next(L)) return NULL;
    expr* b = parse_term(C);
    if (!b) return NULL;
    a = binop(C, op, a, b, col);
  }
  if (a && (tok_is(C->L, '&') || tok_is(C->L, '|') || tok_is(C->L, '^') || tok_is(C->L, OP_SHL) ||
            tok_is(C->L, OP_SHR))) {
    perr(C->ls, VD_ERR_UNSUPPORTED, C->L->lineno, lx_col(C->L), "unsupported: bitwise operator");
    return NULL;
  }
  return a;
}

static int cmp_op(const lexer* L) {
  if (tok_is(L, '<')) return CMP_LT;
  if (tok_is(L, OP_LE)) return CMP_LE;
  if (tok_is(L, '>')) return CMP_GT;
  if (tok_is(L, OP_GE)) return CMP_GE;
  if (tok_is(L, OP_EQ)) return CMP_EQ;
  if (tok_is(L, OP_NE)) return CMP_NE;
  return -1;
}

static expr* parse_comparison(pctx* C) {
  expr* a = parse_arith(C);
  if (!a) return NULL;
  lexer* L = C->L;
  if (tok_name(L, "in") || tok_name(L, "is") || (tok_name(L, "not"))) {
    perr(C->ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: '%.*s' operator", L->tlen,
         L->s + L->start);
    return NULL;
  }
  if (cmp_op(L) < 0) return a;
  expr* ops[16];
  int cmps[16];
  int n = 0;
  ops[n] = a;
  int col = lx_col(L);
  while (cmp_op(L) >= 0) {
    if (n == 15) {
      perr(C->ls, VD_ERR_LIMIT, L->lineno, lx_col(L), "comparison chain too long");
      return NULL;
    }
    cmps[n] = cmp_op(L);
    if (lx_next(L)) return NULL;
    expr* b = parse_arith(C);
    if (!b) return NULL;
    ops[++n] = b;
  }
  expr* e = new_expr(C, E_CMP, col);
  if (!e) return NULL;
  e->nargs = n + 1;
  e->args = aalloc(C->ls, sizeof(expr*) * (size_t)(n + 1));
  e->cmp = aalloc(C->ls, sizeof(int) * (size_t)n);
  if (!e->args || !e->cmp) return NULL;
  memcpy(e->args, ops, sizeof(expr*) * (size_t)(n + 1));
  memcpy(e->cmp, cmps, sizeof(int) * (size_t)n);
  return e;
}

static expr* parse_not(pctx* C) {
  if (tok_name(C->L, "not")) {
    int col = lx_col(C->L);
    if (lx_next(C->L)) return NULL;
    expr* a = parse_not(C);
    if (!a) return NULL;
    return binop(C, E_NOT, a, NULL, col);
  }
  return parse_comparison(C);
}

// a left-associative chain `sub (kw sub)*` joined by op
static expr* parse_kw_chain(pctx* C, const char* kw, int op, expr* (*sub)(pctx*)) {
  expr* a = sub(C);
  while (a && tok_name(C->L, kw)) {
    int col = lx_col(C->L);
    if (lx_next(C->L)) return NULL;
    expr* b = sub(C);
    if (!b) return NULL;
    a = binop(C, op, a, b, col);
  }
  return a;
}

static expr* parse_and(pctx* C) { return parse_kw_chain(C, "and", E_AND, parse_not); }
static expr* parse_or(pctx* C) { return parse_kw_chain(C, "or", E_OR, parse_and); }

static expr* parse_expr(pctx* C) {
  if (tok_name(C->L, "lambda")) {
    perr(C->ls, VD_ERR_UNSUPPORTED, C->L->lineno, lx_col(C->L), "unsupported: 'lambda'");
    return NULL;
  }
  expr* a = parse_or(C);
  if (a && tok_name(C->L, "if")) {
    int col = lx_col(C->L);
    if (lx_next(C->L)) return NULL;
    expr* cond = parse_or(C);
    if (!cond) return NULL;
    if (!tok_name(C->L, "else")) {
      perr(C->ls, VD_ERR_SYNTAX, C->L->lineno, lx_col(C->L), "expected 'else' in conditional expression");
      return NULL;
    }
    if (lx_next(C->L)) return NULL;
    expr* b = parse_expr(C);
    if (!b) return NULL;
    expr* e = new_expr(C, E_COND, col);
    if (!e) return NULL;
    e->a = a;
    e->b = cond;
    e->c = b;
    return e;
  }
  return a;
}

// ---------------------------------------------------------------------------------------------
// L-string templates and patterns (character level)

static int is_space(char c) { return c == ' ' || c == '\t'; }

// read one module name at s[*pos]; returns the symbol id or -1 (error set)
static int read_module_name(vd_lsystem* ls, const char* s, int len, int* pos, int lineno, int col0) {
  int p = *pos;
  char c = s[p];
  // ~ followed by a surface name (one character) when not followed by '('
  if (c == '~' && p + 1 < len && s[p + 1] != '(' && !is_space(s[p + 1])) {
    int id = sym_intern(ls, s + p, 2, 0);
    *pos = p + 2;
    if (id < 0) perr(ls, VD_ERR_NOMEM, lineno, col0 + p, "out of memory");
    return id;
  }
  // longest match against predefined and declared names
  int maxl = ls->syms.maxlen;
  if (maxl > len - p) maxl = len - p;
  for (int l = maxl; l >= 2; l--) {
    int id = sym_find(ls, s + p, l);
    if (id >= 0 && ls->syms.declared[id]) {
      *pos = p + l;
      return sym_canon(ls, id);
    }
  }
  if (c == '(' || c == ')' || c == '\'' || c == '"') {
    perr(ls, VD_ERR_SYNTAX, lineno, col0 + p, "unexpected '%c' where a module name was expected", c);
    return -1;
  }
  // a non-ASCII character (UTF-8, as Python 3 reads the file) is one module, like an ASCII one
  int clen = 1;
  unsigned char u = (unsigned char)c;
  if (u >= 0xC2 && u <= 0xF4) {
    clen = u >= 0xF0 ? 4 : u >= 0xE0 ? 3 : 2;
    for (int k = 1; k < clen; k++)
      if (p + k >= len || ((unsigned char)s[p + k] & 0xC0) != 0x80) clen = 0;
  } else if (u < 32 || u >= 127) {
    clen = 0;
  }
  if (!clen) {
    perr(ls, VD_ERR_SYNTAX, lineno, col0 + p, "unexpected character (byte 0x%02x) in an L-string", u);
    return -1;
  }
  int id = sym_intern(ls, s + p, clen, 0);
  *pos = p + clen;
  if (id < 0) perr(ls, VD_ERR_NOMEM, lineno, col0 + p, "out of memory");
  return id;
}

// parse an L-string template from s[pos..len); stops at end or a comment
static tmpl* parse_tmpl(vd_lsystem* ls, scope* sc, const char* s, int len, int pos, int lineno, int col0) {
  tmpl* t = aalloc(ls, sizeof(tmpl));
  if (!t) return NULL;
  int cap = 0;
  tmod* mods = NULL;
  for (;;) {
    while (pos < len && is_space(s[pos])) pos++;
    if (pos >= len || s[pos] == '#') break;
    int mcol = col0 + pos;
    if (s[pos] == '*') {
      // `produce *`, `--> *`: a successor that starts with the any-module `*` produces
      // nothing (L-Py drops the whole production); a `*` further on has no meaning there
      if (t->n > 0) {
        perr(ls, VD_ERR_UNSUPPORTED, lineno, mcol, "unsupported: '*' module inside a successor");
        goto fail;
      }
      t->drop = 1;
    }
    int sym = read_module_name(ls, s, len, &pos, lineno, col0);
    if (sym < 0) goto fail;
    if (sym_canon(ls, sym) == VD_SYM_NEW && ls->engine == VD_LSYS_NATIVE) {
      // newmodule('B', x) is the module B(x): its name is a value, made by the Python engine
      perr(ls, VD_ERR_UNSUPPORTED, lineno, mcol, "unsupported: 'newmodule' module (a module named by a value)");
      goto fail;
    }
    if (t->n == cap) {
      int ncap = cap ? cap * 2 : 16;
      tmod* nm = aalloc(ls, sizeof(tmod) * (size_t)ncap);
      if (!nm) goto fail;
      if (cap) memcpy(nm, mods, sizeof(tmod) * (size_t)cap);
      mods = nm;
      cap = ncap;
    }
    tmod* m = &mods[t->n++];
    m->sym = sym;  // NOLINT(clang-analyzer-core.NullDereference): mods grown above before t->n grows
    m->line = lineno;
    m->col = mcol;
    if (sym == VD_SYM_CUT) t->has_cut = 1;
    {
      // L-Py allows spaces between a module's name and its parameters: `MyGC (a, b)`
      int q = pos;
      while (q < len && is_space(s[q])) q++;
      if (q < len && s[q] == '(') pos = q;
    }
    if (pos < len && s[pos] == '(' && ls->engine == VD_LSYS_PYTHON) {
      // the Python engine: parameters stay Python source for CPython
      expr* params[64];
      int np = lsys_py_params(ls, s, len, &pos, lineno, col0, params, 64);
      if (np < 0) goto fail;
      m->nparam = np;
      if (np) {
        m->param = aalloc(ls, sizeof(expr*) * (size_t)np);
        if (!m->param) goto fail;
        memcpy(m->param, params, sizeof(expr*) * (size_t)np);
      }
    } else if (pos < len && s[pos] == '(') {
      lexer L;
      lx_init(&L, ls, s, len, lineno, col0, pos + 1);
      if (lx_next(&L)) goto fail;
      pctx C = {ls, &L, sc};
      expr* params[64];
      int np = 0;
      while (!tok_is(&L, ')')) {
        if (np == 64) {
          perr(ls, VD_ERR_LIMIT, lineno, lx_col(&L), "more than 64 module parameters");
          goto fail;
        }
        if (tok_is(&L, '*')) {
          perr(ls, VD_ERR_UNSUPPORTED, lineno, lx_col(&L), "unsupported: parameter unpacking");
          goto fail;
        }
        expr* e = parse_expr(&C);
        if (!e) goto fail;
        params[np++] = e;
        if (tok_is(&L, ',')) {
          if (lx_next(&L)) goto fail;
          if (tok_is(&L, ')')) break;
        } else if (!tok_is(&L, ')')) {
          char b[64];
          perr(ls, VD_ERR_SYNTAX, lineno, lx_col(&L),
               "expected ',' or ')' in the parameters of '%s', found %s", vd_lsys_symbol_name(ls, sym),
               tok_desc(&L, b, sizeof b));
          goto fail;
        }
      }
      pos = L.start + 1;  // after ')'
      m->nparam = np;
      if (np) {
        m->param = aalloc(ls, sizeof(expr*) * (size_t)np);
        if (!m->param) goto fail;
        memcpy(m->param, params, sizeof(expr*) * (size_t)np);
      }
    }
  }
  t->mod = mods;
  if (t->drop) t->n = 0;  // `*` first: nothing is emitted (the modules were read for their syntax)
  return t;
fail:
  if (ls->err && ls->err->status == VD_OK) perr(ls, VD_ERR_NOMEM, lineno, col0, "out of memory");
  return NULL;
}

tmpl* lsys_parse_tmpl_text(vd_lsystem* ls, const char* text, int len, int line, int col) {
  return parse_tmpl(ls, NULL, text, len, 0, line, col);
}

expr* lsys_parse_expr_text(vd_lsystem* ls, const char* text, int len, int line, int col) {
  lexer L;
  lx_init(&L, ls, text, len, line, col, 0);
  if (lx_next(&L)) return NULL;
  pctx C = {ls, &L, NULL};
  expr* e = parse_expr(&C);
  if (!e) return NULL;
  if (L.t != T_EOF) {
    char b[64];
    perr(ls, VD_ERR_SYNTAX, line, lx_col(&L), "unexpected %s after expression", tok_desc(&L, b, sizeof b));
    return NULL;
  }
  return e;
}

// end of the parenthesised text that starts at s[p] == '(' (index of its ')'), or -1; only
// parentheses nest: brackets are modules in patterns
static int close_paren(const char* s, int p, int b) {
  int depth = 0;
  char q = 0;
  for (int i = p; i < b; i++) {
    char c = s[i];
    int k = lsys_quote_step(c, &q);
    if (k) {
      i += k - 1;
      continue;
    }
    if (c == '(') {
      depth++;
    } else if (c == ')' && --depth == 0) {
      return i;
    }
  }
  return -1;
}

// next top-level comma in s[p..b) (outside parentheses and strings), or b
static int next_comma(const char* s, int p, int b) {
  int depth = 0;
  char q = 0;
  for (int i = p; i < b; i++) {
    char c = s[i];
    int k = lsys_quote_step(c, &q);
    if (k) {
      i += k - 1;
      continue;
    }
    if (c == '(') {
      depth++;
    } else if (c == ')') {
      depth--;
    } else if (c == ',' && depth == 0) {
      return i;
    }
  }
  return b;
}

// does s[p..b) start with the word w followed (after spaces) by '('? returns the index of '('
static int call_word_at(const char* s, int p, int b, const char* w) {
  int n = (int)strlen(w);
  if (p + n > b || memcmp(s + p, w, (size_t)n) != 0) return -1;
  int q = p + n;
  while (q < b && is_space(s[q])) q++;
  return q < b && s[q] == '(' ? q : -1;
}

static int parse_pstr(vd_lsystem* ls, scope* sc, const char* s, int a, int b, int lineno, int col0, int depth,
                      pstr* out);

// a constant integer argument of x(...): min or max repetitions
static int rep_bound(vd_lsystem* ls, const char* s, int a, int b, int lineno, int col0, int* out) {
  expr* e = lsys_parse_expr_text(ls, s + a, b - a, lineno, col0 + a);
  if (!e) return 0;
  if (e->op != E_CONST || e->k.t != V_INT || e->k.n < 0 || e->k.n > 1e9) {
    perr(ls, VD_ERR_SYNTAX, lineno, col0 + a, "x(...) bounds must be non-negative integers");
    return 0;
  }
  *out = (int)e->k.n;
  return 1;
}

// parameters of a pattern module, s[p] == '(': names are bound into scope, constants compared
static int parse_pattern_params(vd_lsystem* ls, scope* sc, const char* s, int p, int b, int lineno, int col0,
                                pmod* m, int* after) {
  lexer L;
  lx_init(&L, ls, s, b, lineno, col0, p + 1);
  if (lx_next(&L)) return 0;
  int slots[64];
  value cv[64];
  pcond cd[64];
  int np = 0, ncond = 0;
  while (!tok_is(&L, ')')) {
    if (np == 64) {
      perr(ls, VD_ERR_LIMIT, lineno, lx_col(&L), "more than 64 pattern parameters");
      return 0;
    }
    if (tok_is(&L, '*') || tok_is(&L, OP_POW)) {
      int kw = tok_is(&L, OP_POW), scol = lx_col(&L);
      if (ls->engine != VD_LSYS_PYTHON) {
        perr(ls, VD_ERR_UNSUPPORTED, lineno, scol, "unsupported: '%s' pattern parameter (binds a %s)",
             kw ? "**kwds" : "*args", kw ? "dict" : "list");
        return 0;
      }
      // the Python engine: *args (a list) then **kwds (a dict), at the end
      if (lx_next(&L)) return 0;
      if (L.t != T_NAME) {
        perr(ls, VD_ERR_SYNTAX, lineno, lx_col(&L), "expected a name after '%s'", kw ? "**" : "*");
        return 0;
      }
      if (!m->x) {
        if (!(m->x = aalloc(ls, sizeof(pext)))) {
          perr(ls, VD_ERR_NOMEM, lineno, scol, "out of memory");
          return 0;
        }
        m->x->args_slot = m->x->kwds_slot = -1;
      }
      if (m->x->kwds_slot >= 0 || (!kw && m->x->args_slot >= 0)) {
        perr(ls, VD_ERR_SYNTAX, lineno, scol, "'*args' and '**kwds' come last, in this order");
        return 0;
      }
      int sl = scope_add(ls, sc, L.s + L.start, L.tlen);
      if (sl < 0) {
        perr(ls, VD_ERR_NOMEM, lineno, scol, "out of memory");
        return 0;
      }
      if (kw) m->x->kwds_slot = sl;
      else m->x->args_slot = sl;
      if (lx_next(&L)) return 0;
      if (tok_is(&L, ',')) {
        if (lx_next(&L)) return 0;
      } else if (!tok_is(&L, ')')) {
        char bb[64];
        perr(ls, VD_ERR_SYNTAX, lineno, lx_col(&L), "expected ',' or ')' in a pattern, found %s",
             tok_desc(&L, bb, sizeof bb));
        return 0;
      }
      continue;
    }
    if (m->x && (m->x->args_slot >= 0 || m->x->kwds_slot >= 0)) {
      perr(ls, VD_ERR_SYNTAX, lineno, lx_col(&L), "'*args' and '**kwds' come last, in this order");
      return 0;
    }
    if (L.t == T_NAME && !tok_name(&L, "True") && !tok_name(&L, "False") && !tok_name(&L, "None")) {
      lexer name = L;
      if (lx_next(&L)) return 0;
      int sl = scope_add(ls, sc, name.s + name.start, name.tlen);
      if (sl < 0) {
        perr(ls, VD_ERR_NOMEM, lineno, lx_col(&name), "out of memory");
        return 0;
      }
      cd[np] = (pcond){NULL, -1};
      if (!tok_is(&L, ',') && !tok_is(&L, ')')) {
        // a condition (L-Py's value constraint): `n in 'AB'` is `lambda n: n in 'AB'`
        int close = close_paren(s, p, b);
        if (close < 0) {
          perr(ls, VD_ERR_SYNTAX, lineno, col0 + p, "unclosed '(' in a pattern");
          return 0;
        }
        int end = next_comma(s, name.start, close);
        if (ls->engine == VD_LSYS_PYTHON) {
          cd[np].pyfn = lsys_py_cond(ls, name.s + name.start, name.tlen, s + name.start, end - name.start, lineno);
          if (cd[np].pyfn < 0) return 0;
        } else {
          lexer E;
          lx_init(&E, ls, s, end, lineno, col0, name.start);
          if (lx_next(&E)) return 0;
          pctx C = {ls, &E, sc};
          if (!(cd[np].e = parse_expr(&C))) return 0;
          if (E.t != T_EOF) {
            char bb[64];
            perr(ls, VD_ERR_SYNTAX, lineno, lx_col(&E), "unexpected %s in the condition on '%.*s'",
                 tok_desc(&E, bb, sizeof bb), name.tlen, name.s + name.start);
            return 0;
          }
        }
        ncond++;
        lx_init(&L, ls, s, b, lineno, col0, end);
        if (lx_next(&L)) return 0;
      }
      slots[np] = sl;
      cv[np] = (value){V_NONE, 0};
    } else {
      pctx C = {ls, &L, NULL};
      int ccol = lx_col(&L);
      expr* e = parse_expr(&C);
      if (!e) return 0;
      if (e->op != E_CONST) {
        perr(ls, VD_ERR_SYNTAX, lineno, ccol, "a pattern parameter must be a name or a constant");
        return 0;
      }
      slots[np] = -1;
      cv[np] = e->k;
      cd[np] = (pcond){NULL, -1};
    }
    np++;
    if (tok_is(&L, ',')) {
      if (lx_next(&L)) return 0;
    } else if (!tok_is(&L, ')')) {
      char bb[64];
      perr(ls, VD_ERR_SYNTAX, lineno, lx_col(&L), "expected ',' or ')' in a pattern, found %s",
           tok_desc(&L, bb, sizeof bb));
      return 0;
    }
  }
  *after = L.start + 1;
  m->nparam = np;
  if (np) {
    m->slot = aalloc(ls, sizeof(int) * (size_t)np);
    m->cval = aalloc(ls, sizeof(value) * (size_t)np);
    if (!m->slot || !m->cval) {
      perr(ls, VD_ERR_NOMEM, lineno, m->col, "out of memory");
      return 0;
    }
    memcpy(m->slot, slots, sizeof(int) * (size_t)np);
    memcpy(m->cval, cv, sizeof(value) * (size_t)np);
  }
  if (ncond) {
    // conditions take the general matcher (m->x set)
    if (!m->x) {
      if (!(m->x = aalloc(ls, sizeof(pext)))) {
        perr(ls, VD_ERR_NOMEM, lineno, m->col, "out of memory");
        return 0;
      }
      m->x->args_slot = m->x->kwds_slot = -1;
    }
    m->x->name_cond = (pcond){NULL, -1};
    if (!(m->x->cond = aalloc(ls, sizeof(pcond) * (size_t)np))) {
      perr(ls, VD_ERR_NOMEM, lineno, m->col, "out of memory");
      return 0;
    }
    memcpy(m->x->cond, cd, sizeof(pcond) * (size_t)np);
  }
  return 1;
}

// x(...) and or(...): sub-patterns separated by top-level commas in s[p+1 .. close)
static int parse_pattern_re(vd_lsystem* ls, scope* sc, const char* s, int p, int close, int lineno, int col0,
                            int depth, pmod* m) {
  pext* x = m->x = aalloc(ls, sizeof(pext));
  if (!x) {
    perr(ls, VD_ERR_NOMEM, lineno, col0 + p, "out of memory");
    return 0;
  }
  x->args_slot = x->kwds_slot = -1;
  int nargs = 0, starts[64] = {0}, ends[64] = {0};
  for (int q = p + 1; q <= close && nargs < 64;) {
    int c = next_comma(s, q, close);
    starts[nargs] = q;
    ends[nargs] = c;
    nargs++;
    q = c + 1;
  }
  if (m->kind == PK_REP) {
    if (nargs > 3) {
      perr(ls, VD_ERR_SYNTAX, lineno, col0 + p, "x(...) takes a pattern and at most two bounds");
      return 0;
    }
    x->nsub = 1;
    x->rmin = 0;
    x->rmax = 1000;  // L-Py's default
    if (nargs >= 2 && !rep_bound(ls, s, starts[1], ends[1], lineno, col0, &x->rmin)) return 0;
    if (nargs == 2) x->rmax = x->rmin;
    if (nargs == 3 && !rep_bound(ls, s, starts[2], ends[2], lineno, col0, &x->rmax)) return 0;
  } else {
    x->nsub = nargs;
  }
  x->sub = aalloc(ls, sizeof(pstr) * (size_t)x->nsub);
  if (!x->sub) {
    perr(ls, VD_ERR_NOMEM, lineno, col0 + p, "out of memory");
    return 0;
  }
  for (int k = 0; k < x->nsub; k++) {
    int before = sc->n;
    if (!parse_pstr(ls, sc, s, starts[k], ends[k], lineno, col0, depth + 1, &x->sub[k])) return 0;
    if (x->sub[k].n == 0) {
      perr(ls, VD_ERR_SYNTAX, lineno, col0 + starts[k], "empty pattern in %s(...)", m->kind == PK_REP ? "x" : "or");
      return 0;
    }
    if (m->kind == PK_REP && sc->n > before && ls->engine != VD_LSYS_PYTHON) {
      perr(ls, VD_ERR_UNSUPPORTED, lineno, col0 + starts[k],
           "unsupported: variables inside x(...) (they bind lists)");
      return 0;
    }
  }
  return 1;
}

// a pattern s[a..b): modules (parameters are names bound into scope, or constants), `*`,
// brackets, `=]`, x(...) repetitions, or(...) alternatives, None
static int parse_pstr(vd_lsystem* ls, scope* sc, const char* s, int a, int b, int lineno, int col0, int depth,
                      pstr* out) {
  pmod* mods = NULL;
  int n = 0, cap = 0;
  int pos = a;
  memset(out, 0, sizeof *out);
  if (depth > 32) {
    perr(ls, VD_ERR_LIMIT, lineno, col0 + a, "patterns nested more than 32 deep");
    return 0;
  }
  for (;;) {
    while (pos < b && is_space(s[pos])) pos++;
    if (pos >= b) break;
    if (n == cap) {
      int ncap = cap ? cap * 2 : 8;
      pmod* nm = aalloc(ls, sizeof(pmod) * (size_t)ncap);
      if (!nm) {
        perr(ls, VD_ERR_NOMEM, lineno, col0 + pos, "out of memory");
        return 0;
      }
      if (cap) memcpy(nm, mods, sizeof(pmod) * (size_t)cap);
      mods = nm;
      cap = ncap;
    }
    pmod* m = &mods[n++];
    m->line = lineno;
    m->col = col0 + pos;
    int par;
    if (s[pos] == '$' || (s[pos] == '?' && pos + 1 < b && s[pos + 1] == 'I')) {
      perr(ls, VD_ERR_UNSUPPORTED, lineno, col0 + pos, "unsupported: '%s' pattern module (it binds a %s)",
           s[pos] == '$' ? "$" : "?I", s[pos] == '$' ? "module object" : "string iterator");
      return 0;
    }
    if (s[pos] == '=' && pos + 1 < b && s[pos + 1] == ']') {
      m->kind = PK_MOD;
      m->sym = VD_SYM_EB;
      m->exact = 1;
      pos += 2;
      continue;
    }
    if (s[pos] == '*') {
      m->kind = PK_ANY;
      pos++;
      while (pos < b && is_space(s[pos])) pos++;
      if (pos < b && s[pos] == '(') {
        // *(name, x, y): the name first, then the parameters
        int after;
        if (!parse_pattern_params(ls, sc, s, pos, b, lineno, col0, m, &after)) return 0;
        if (m->x && m->nparam == 0) {
          pos = after;  // *(*args), *(**kwds), *(*args, **kwds): the name goes in the list / dict
          continue;
        }
        if (m->nparam == 0) {
          perr(ls, VD_ERR_SYNTAX, lineno, m->col, "'*()' needs at least the module name");
          return 0;
        }
        if (!m->x) {
          m->x = aalloc(ls, sizeof(pext));
          if (!m->x) {
            perr(ls, VD_ERR_NOMEM, lineno, m->col, "out of memory");
            return 0;
          }
          m->x->args_slot = m->x->kwds_slot = -1;
        }
        m->x->has_name = 1;
        m->x->name_slot = m->slot[0];
        m->x->name_val = m->cval[0];
        if (m->x->name_slot < 0 && m->x->name_val.t != V_STR) {
          perr(ls, VD_ERR_SYNTAX, lineno, m->col, "the first parameter of '*(...)' is the module name");
          return 0;
        }
        m->slot++;
        m->cval++;
        if (m->x->cond) m->x->name_cond = *m->x->cond++;
        m->nparam--;
        pos = after;
      }
      continue;
    }
    if (s[pos] == 'N' && b - pos >= 4 && memcmp(s + pos, "None", 4) == 0 &&
        (pos + 4 == b || !(isalnum((unsigned char)s[pos + 4]) || s[pos + 4] == '_'))) {
      m->kind = PK_NONE;
      pos += 4;
      continue;
    }
    int sympos = pos;
    int sym = read_module_name(ls, s, b, &pos, lineno, col0);
    if (sym < 0) return 0;
    // x(...) repetition and or(...) alternatives (L-Py's RepExp and Or pattern modules)
    // (x, all and repexp are the names of the repetition; a longer declared name wins)
    int op = -1, kind = -1;
    static const char* const re_names[] = {"x", "all", "repexp", "or"};
    for (int k = 0; k < 4 && kind < 0; k++)
      if (pos - sympos <= (k == 3 ? 2 : 1) && (op = call_word_at(s, sympos, b, re_names[k])) >= 0)
        kind = k == 3 ? PK_OR : PK_REP;
    if (kind >= 0) {
      int close = close_paren(s, op, b);
      if (close < 0) {
        perr(ls, VD_ERR_SYNTAX, lineno, col0 + op, "unclosed '(' in a pattern");
        return 0;
      }
      m->kind = kind;
      if (!parse_pattern_re(ls, sc, s, op, close, lineno, col0, depth, m)) return 0;
      pos = close + 1;
      continue;
    }
    m->kind = PK_MOD;
    m->sym = sym;
    {
      int q = pos;  // `A (x)`: spaces before the parameters, as in L-Py
      while (q < b && is_space(s[q])) q++;
      if (q < b && s[q] == '(') pos = q;
    }
    if (pos < b && s[pos] == '(') {
      if (!parse_pattern_params(ls, sc, s, pos, b, lineno, col0, m, &par)) return 0;
      pos = par;
    }
  }
  out->n = n;
  out->m = mods;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// statements

typedef struct sparse {
  parser* P;
  vd_lsystem* ls;
  scope* sc;
  int in_loop;
  int in_func;   // return allowed
  int allow_produce;
} sparse;

static stmt* new_stmt(vd_lsystem* ls, int op, int lineno, int col) {
  stmt* s = aalloc(ls, sizeof(stmt));
  if (!s) {
    perr(ls, VD_ERR_NOMEM, lineno, col, "out of memory");
    return NULL;
  }
  s->op = op;
  s->line = lineno;
  s->col = col;
  return s;
}

static stmt* parse_block(sparse* S, int* li, int indent);

// the body of a compound statement: inline after ':' or the indented block that follows
static stmt* parse_suite(sparse* S, lexer* L, int* li, int header_indent) {
  if (!tok_is(L, ':')) {
    char b[64];
    perr(S->ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected ':', found %s", tok_desc(L, b, sizeof b));
    return NULL;
  }
  int after = L->pos;
  if (lx_next(L)) return NULL;
  if (L->t != T_EOF) {
    // inline body: the rest of the line is a simple statement
    pline* ln = &S->P->lines[*li];
    pline sub = *ln;
    sub.s = ln->s + after;
    sub.len = ln->len - after;
    sub.col0 = ln->col0 + after;
    pline* saved = S->P->lines;
    int saved_n = S->P->nline;
    // parse the sub-line as a one-line block
    S->P->lines = &sub;
    S->P->nline = 1;
    int k = 0;
    sub.indent = 0;
    stmt* body = parse_block(S, &k, 0);
    S->P->lines = saved;
    S->P->nline = saved_n;
    (*li)++;
    return body;
  }
  (*li)++;
  // skip blank lines to find the block's indentation
  int j = *li;
  while (j < S->P->nline && S->P->lines[j].blank) j++;
  if (j >= S->P->nline || S->P->lines[j].indent <= header_indent) {
    perr(S->ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected an indented block");
    return NULL;
  }
  *li = j;
  return parse_block(S, li, S->P->lines[j].indent);
}

static int name_is(const char* s, int len, const char* kw) {
  return len == (int)strlen(kw) && memcmp(s, kw, (size_t)len) == 0;
}

// assignment target: a local (in functions) or a global
static int target_slot(sparse* S, const char* name, int len, int* is_global) {
  if (S->sc && S->sc->is_function && !scope_is_global(S->sc, name, len)) {
    *is_global = 0;
    return scope_add(S->ls, S->sc, name, len);
  }
  *is_global = 1;
  return global_slot(S->ls, name, len, 1);
}

static stmt* parse_simple(sparse* S, lexer* L, int* li, int indent);

static stmt* parse_statement(sparse* S, int* li, int indent) {
  pline* ln = &S->P->lines[*li];
  lexer L;
  lx_init(&L, S->ls, ln->s, ln->len, ln->lineno, ln->col0, 0);
  if (lx_next(&L)) return NULL;
  int col = lx_col(&L);
  pctx C = {S->ls, &L, S->sc};
  if (tok_name(&L, "if") || tok_name(&L, "while")) {
    int is_while = tok_name(&L, "while");
    stmt* s = new_stmt(S->ls, is_while ? S_WHILE : S_IF, ln->lineno, col);
    if (!s || lx_next(&L)) return NULL;
    s->e = parse_expr(&C);
    if (!s->e) return NULL;
    if (is_while) S->in_loop++;
    s->body = parse_suite(S, &L, li, indent);
    if (is_while) S->in_loop--;
    if (!s->body) return NULL;
    // elif / else chains
    stmt* cur = s;
    while (!is_while && *li < S->P->nline) {
      int j = *li;
      while (j < S->P->nline && S->P->lines[j].blank) j++;
      if (j >= S->P->nline || S->P->lines[j].indent != indent) break;
      pline* nl = &S->P->lines[j];
      lexer L2;
      lx_init(&L2, S->ls, nl->s, nl->len, nl->lineno, nl->col0, 0);
      if (lx_next(&L2)) return NULL;
      if (tok_name(&L2, "elif")) {
        *li = j;
        stmt* e = new_stmt(S->ls, S_IF, nl->lineno, lx_col(&L2));
        if (!e || lx_next(&L2)) return NULL;
        pctx C2 = {S->ls, &L2, S->sc};
        e->e = parse_expr(&C2);
        if (!e->e) return NULL;
        e->body = parse_suite(S, &L2, li, indent);
        if (!e->body) return NULL;
        cur->orelse = e;
        cur = e;
      } else if (tok_name(&L2, "else")) {
        *li = j;
        if (lx_next(&L2)) return NULL;
        cur->orelse = parse_suite(S, &L2, li, indent);
        if (!cur->orelse) return NULL;
        break;
      } else {
        break;
      }
    }
    return s;
  }
  if (tok_name(&L, "for")) {
    stmt* s = new_stmt(S->ls, S_FOR, ln->lineno, col);
    if (!s || lx_next(&L)) return NULL;
    if (L.t != T_NAME) {
      perr(S->ls, VD_ERR_SYNTAX, L.lineno, lx_col(&L), "expected a loop variable after 'for'");
      return NULL;
    }
    s->slot = target_slot(S, L.s + L.start, L.tlen, &s->is_global);
    if (s->slot < 0 || lx_next(&L)) return NULL;
    if (tok_is(&L, ',')) {
      perr(S->ls, VD_ERR_UNSUPPORTED, L.lineno, lx_col(&L), "unsupported: tuple unpacking in 'for'");
      return NULL;
    }
    if (!tok_name(&L, "in")) {
      perr(S->ls, VD_ERR_SYNTAX, L.lineno, lx_col(&L), "expected 'in' in for statement");
      return NULL;
    }
    if (lx_next(&L)) return NULL;
    if (!tok_name(&L, "range")) {
      perr(S->ls, VD_ERR_UNSUPPORTED, L.lineno, lx_col(&L),
           "unsupported: 'for' over anything but range(...)");
      return NULL;
    }
    if (lx_next(&L) || expect(&L, '(', "'(' after range")) return NULL;
    expr* a[3];
    int n = 0;
    while (!tok_is(&L, ')')) {
      if (n == 3) {
        perr(S->ls, VD_ERR_SYNTAX, L.lineno, lx_col(&L), "range() takes at most 3 arguments");
        return NULL;
      }
      a[n] = parse_expr(&C);
      if (!a[n]) return NULL;
      n++;
      if (tok_is(&L, ',')) {
        if (lx_next(&L)) return NULL;
      } else if (!tok_is(&L, ')')) {
        perr(S->ls, VD_ERR_SYNTAX, L.lineno, lx_col(&L), "expected ',' or ')' in range()");
        return NULL;
      }
    }
    if (n == 0) {
      perr(S->ls, VD_ERR_SYNTAX, L.lineno, lx_col(&L), "range() needs at least 1 argument");
      return NULL;
    }
    if (lx_next(&L)) return NULL;
    if (n == 1) {
      s->e = NULL;
      s->e2 = a[0];
    } else {
      s->e = a[0];
      s->e2 = a[1];
      s->e3 = n == 3 ? a[2] : NULL;
    }
    S->in_loop++;
    s->body = parse_suite(S, &L, li, indent);
    S->in_loop--;
    if (!s->body) return NULL;
    return s;
  }
  if (tok_name(&L, "elif") || tok_name(&L, "else")) {
    perr(S->ls, VD_ERR_SYNTAX, L.lineno, col, "'%.*s' without a matching 'if'", L.tlen, L.s + L.start);
    return NULL;
  }
  if (tok_name(&L, "def")) {
    perr(S->ls, VD_ERR_UNSUPPORTED, L.lineno, col, "unsupported: nested 'def'");
    return NULL;
  }
  stmt* s = parse_simple(S, &L, li, indent);
  if (!s) return NULL;
  (*li)++;
  return s;
}

// simple statements; several may follow each other separated by ';'
static stmt* parse_simple(sparse* S, lexer* L, int* li, int indent) {
  (void)li;
  (void)indent;
  vd_lsystem* ls = S->ls;
  pctx C = {ls, L, S->sc};
  int col = lx_col(L);
  stmt* s = NULL;
  if (tok_name(L, "produce") || tok_name(L, "nproduce")) {
    int n = tok_name(L, "nproduce");
    if (!S->allow_produce) {
      perr(ls, VD_ERR_SYNTAX, L->lineno, col, "'%s' outside a rule or the axiom", n ? "nproduce" : "produce");
      return NULL;
    }
    s = new_stmt(ls, n ? S_NPRODUCE : S_PRODUCE, L->lineno, col);
    if (!s) return NULL;
    // the rest of the line is an L-string
    s->t = parse_tmpl(ls, S->sc, L->s, L->len, L->pos, L->lineno, L->col0);
    if (!s->t) return NULL;
    return s;
  }
  if (tok_name(L, "pass") || tok_name(L, "break") || tok_name(L, "continue")) {
    int op = tok_name(L, "pass") ? S_PASS : tok_name(L, "break") ? S_BREAK : S_CONTINUE;
    if (op != S_PASS && !S->in_loop) {
      perr(ls, VD_ERR_SYNTAX, L->lineno, col, "'%.*s' outside a loop", L->tlen, L->s + L->start);
      return NULL;
    }
    s = new_stmt(ls, op, L->lineno, col);
    if (!s || lx_next(L)) return NULL;
  } else if (tok_name(L, "return")) {
    if (!S->in_func) {
      perr(ls, VD_ERR_SYNTAX, L->lineno, col, "'return' outside a function");
      return NULL;
    }
    s = new_stmt(ls, S_RETURN, L->lineno, col);
    if (!s || lx_next(L)) return NULL;
    if (L->t != T_EOF && !tok_is(L, ';')) {
      s->e = parse_expr(&C);
      if (!s->e) return NULL;
      if (tok_is(L, ',')) {
        perr(ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: returning a tuple");
        return NULL;
      }
    }
  } else if (tok_name(L, "global")) {
    s = new_stmt(ls, S_GLOBAL, L->lineno, col);
    if (!s || lx_next(L)) return NULL;
    for (;;) {
      if (L->t != T_NAME) {
        perr(ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected a name after 'global'");
        return NULL;
      }
      if (S->sc && !scope_add_global(S->sc, L->s + L->start, L->tlen)) return NULL;
      if (global_slot(ls, L->s + L->start, L->tlen, 1) < 0) return NULL;
      if (lx_next(L)) return NULL;
      if (!tok_is(L, ',')) break;
      if (lx_next(L)) return NULL;
    }
  } else if (tok_name(L, "print")) {
    s = new_stmt(ls, S_PRINT, L->lineno, col);
    if (!s || lx_next(L)) return NULL;
    if (!tok_is(L, '(')) {
      perr(ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "expected '(' after print");
      return NULL;
    }
    expr tmp;
    memset(&tmp, 0, sizeof tmp);
    if (!parse_call_args(&C, &tmp)) return NULL;
    s->nargs = tmp.nargs;
    s->args = tmp.args;
  } else if (tok_name(L, "assert")) {
    s = new_stmt(ls, S_ASSERT, L->lineno, col);
    if (!s || lx_next(L)) return NULL;
    s->e = parse_expr(&C);
    if (!s->e) return NULL;
    if (tok_is(L, ',')) {
      if (lx_next(L)) return NULL;
      s->e2 = parse_expr(&C);
      if (!s->e2) return NULL;
    }
  } else if (tok_name(L, "import") || tok_name(L, "from")) {
    perr(ls, VD_ERR_UNSUPPORTED, L->lineno, col, "unsupported: import inside a block");
    return NULL;
  } else if (L->t == T_NAME) {
    // assignment or expression statement
    lexer save = *L;
    const char* name = L->s + L->start;
    int len = L->tlen;
    if (lx_next(L)) return NULL;
    int aug = -1;
    if (tok_is(L, OP_ADDEQ)) aug = E_ADD;
    else if (tok_is(L, OP_SUBEQ)) aug = E_SUB;
    else if (tok_is(L, OP_MULEQ)) aug = E_MUL;
    else if (tok_is(L, OP_DIVEQ)) aug = E_DIV;
    else if (tok_is(L, OP_MODEQ)) aug = E_MOD;
    else if (tok_is(L, OP_POWEQ)) aug = E_POW;
    else if (tok_is(L, OP_FLOORDIVEQ)) aug = E_FLOORDIV;
    if (tok_is(L, ',')) {
      perr(ls, VD_ERR_UNSUPPORTED, L->lineno, col, "unsupported: tuple assignment");
      return NULL;
    }
    if (tok_is(L, '=') || aug >= 0) {
      for (int i = 0; unsupported_kw[i]; i++)
        if (name_is(name, len, unsupported_kw[i])) {
          perr(ls, VD_ERR_SYNTAX, L->lineno, col, "cannot assign to '%s'", unsupported_kw[i]);
          return NULL;
        }
      if (name_is(name, len, "True") || name_is(name, len, "False") || name_is(name, len, "None")) {
        perr(ls, VD_ERR_SYNTAX, L->lineno, col, "cannot assign to '%.*s'", len, name);
        return NULL;
      }
      s = new_stmt(ls, aug >= 0 ? S_AUGASSIGN : S_ASSIGN, L->lineno, col);
      if (!s) return NULL;
      s->aug = aug;
      s->slot = target_slot(S, name, len, &s->is_global);
      if (s->slot < 0) return NULL;
      if (lx_next(L)) return NULL;
      s->e = parse_expr(&C);
      if (!s->e) return NULL;
      if (tok_is(L, '=')) {
        perr(ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: chained assignment");
        return NULL;
      }
      if (tok_is(L, ',')) {
        perr(ls, VD_ERR_UNSUPPORTED, L->lineno, lx_col(L), "unsupported: tuple");
        return NULL;
      }
    } else {
      *L = save;
      s = new_stmt(ls, S_EXPR, L->lineno, col);
      if (!s) return NULL;
      s->e = parse_expr(&C);
      if (!s->e) return NULL;
    }
  } else {
    s = new_stmt(ls, S_EXPR, L->lineno, col);
    if (!s) return NULL;
    s->e = parse_expr(&C);
    if (!s->e) return NULL;
  }
  if (tok_is(L, ';')) {
    if (lx_next(L)) return NULL;
    if (L->t == T_EOF) return s;
    s->next = parse_simple(S, L, li, indent);
    return s->next ? s : NULL;
  }
  if (L->t != T_EOF) {
    char b[64];
    perr(ls, VD_ERR_SYNTAX, L->lineno, lx_col(L), "unexpected %s", tok_desc(L, b, sizeof b));
    return NULL;
  }
  return s;
}

static stmt* parse_block(sparse* S, int* li, int indent) {
  stmt *head = NULL, *tail = NULL;
  while (*li < S->P->nline) {
    pline* ln = &S->P->lines[*li];
    if (ln->blank) {
      (*li)++;
      continue;
    }
    if (ln->indent < indent) break;
    if (ln->indent > indent) {
      perr(S->ls, VD_ERR_SYNTAX, ln->lineno, ln->col0, "unexpected indentation");
      return NULL;
    }
    stmt* s = parse_statement(S, li, indent);
    if (!s) return NULL;
    if (!head) head = s;
    else tail->next = s;
    tail = s;
    while (tail->next) tail = tail->next;
  }
  if (!head) {
    stmt* p = new_stmt(S->ls, S_PASS, 0, 0);
    return p;
  }
  return head;
}

// names assigned in a block of lines (Python makes them locals of the function)
static int prescan_locals(sparse* S, int from, int indent, scope* sc) {
  for (int j = from; j < S->P->nline; j++) {
    pline* ln = &S->P->lines[j];
    if (ln->blank) continue;
    if (ln->indent < indent) break;
    lexer L;
    lx_init(&L, S->ls, ln->s, ln->len, ln->lineno, ln->col0, 0);
    // a failed token read is reported later by the real parse
    vd_error* keep = S->ls->err;
    vd_error scratch = {0};
    S->ls->err = &scratch;
    int bad = lx_next(&L) != VD_OK;
    if (!bad && tok_name(&L, "global")) {
      while (!lx_next(&L) && L.t == T_NAME) {
        scope_add_global(sc, L.s + L.start, L.tlen);
        if (lx_next(&L) || !tok_is(&L, ',')) break;
      }
    } else if (!bad && tok_name(&L, "for")) {
      if (!lx_next(&L) && L.t == T_NAME) scope_add(S->ls, sc, L.s + L.start, L.tlen);
    } else if (!bad && L.t == T_NAME) {
      const char* name = L.s + L.start;
      int len = L.tlen;
      if (!lx_next(&L) && L.t == T_OP &&
          (L.op == '=' || L.op == OP_ADDEQ || L.op == OP_SUBEQ || L.op == OP_MULEQ || L.op == OP_DIVEQ ||
           L.op == OP_MODEQ || L.op == OP_POWEQ || L.op == OP_FLOORDIVEQ))
        scope_add(S->ls, sc, name, len);
    }
    S->ls->err = keep;
  }
  // names declared global are not locals
  for (int g = 0; g < sc->ng; g++) {
    int i = scope_find(sc, sc->globals[g], sc->glens[g]);
    if (i >= 0) sc->lens[i] = -1;  // hide it
  }
  return 1;
}

// ---------------------------------------------------------------------------------------------
// file structure

static int starts_kw(const pline* ln, const char* kw, int* after) {
  int n = (int)strlen(kw);
  if (ln->len < n || memcmp(ln->s, kw, (size_t)n) != 0) return 0;
  *after = n;
  return 1;
}

// "derivation length" and similar keywords followed by ':' (spaces allowed before it)
static int starts_kw_colon(const pline* ln, const char* kw, int* after) {
  int a;
  if (!starts_kw(ln, kw, &a)) return 0;
  while (a < ln->len && is_space(ln->s[a])) a++;
  if (a >= ln->len || ln->s[a] != ':') return 0;
  *after = a + 1;
  return 1;
}

static int rest_blank(const pline* ln, int from) { return is_blank(ln->s + from, ln->len - from); }

static vd_status parse_import(parser* P, const pline* ln) {
  vd_lsystem* ls = P->ls;
  // import random | import math | from random import * | from math import ... |
  // from openalea.plantgl.all import * (PlantGL objects are not used by the subset: ignored)
  lexer L;
  lx_init(&L, ls, ln->s, ln->len, ln->lineno, ln->col0, 0);
  if (lx_next(&L)) return ls->err->status;
  int is_from = tok_name(&L, "from");
  if (lx_next(&L)) return ls->err->status;
  for (;;) {
    if (L.t != T_NAME)
      return perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "expected a module name");
    const char* m = L.s + L.start;
    int mcol = lx_col(&L);
    // dotted name
    int p = L.pos;
    while (p < L.len && (isalnum((unsigned char)L.s[p]) || L.s[p] == '_' || L.s[p] == '.')) p++;
    int mlen = p - L.start;
    L.pos = p;
    if (lx_next(&L)) return ls->err->status;
    int ok = name_is(m, mlen, "random") || name_is(m, mlen, "math") ||
             (mlen >= 8 && memcmp(m, "openalea", 8) == 0);
    if (!ok)
      return perr(ls, VD_ERR_UNSUPPORTED, ln->lineno, mcol,
                  "unsupported: import of module '%.*s' (only random, math and openalea are accepted)",
                  mlen, m);
    if (tok_name(&L, "as"))
      return perr(ls, VD_ERR_UNSUPPORTED, ln->lineno, lx_col(&L), "unsupported: 'import ... as'");
    if (is_from) return VD_OK;  // names of random/math are always available
    if (!tok_is(&L, ',')) break;
    if (lx_next(&L)) return ls->err->status;
  }
  if (L.t != T_EOF && !is_from)
    return perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "unexpected text after import");
  return VD_OK;
}

// LABELS = {1: "stem", 2: "leaf"}: label names declared in the file (also valid Python)
static vd_status parse_labels_dict(parser* P, const pline* ln, int from) {
  vd_lsystem* ls = P->ls;
  lexer L;
  lx_init(&L, ls, ln->s, ln->len, ln->lineno, ln->col0, from);
  if (lx_next(&L)) return ls->err->status;
  if (!tok_is(&L, '{'))
    return perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "LABELS must be a dict {id: 'name', ...}");
  if (lx_next(&L)) return ls->err->status;
  while (!tok_is(&L, '}')) {
    if (L.t != T_NUM || !L.is_int || L.num < 0 || L.num > 65535)
      return perr(ls, VD_ERR_VALUE, ln->lineno, lx_col(&L), "LABELS key must be an integer label id in 0..65535");
    int id = (int)L.num;
    if (lx_next(&L)) return ls->err->status;
    if (expect(&L, ':', "':' in LABELS")) return ls->err->status;
    if (L.t != T_STR) return perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "LABELS value must be a string");
    // the arrays stay exactly nlabel long, so they are freed by count (labels are few): copy
    // into new arrays of k + 1, and change nothing when either allocation fails
    int k = ls->nlabel;
    int* ids = vd_malloc(sizeof(int) * (size_t)(k + 1));
    char** names = vd_malloc(sizeof(char*) * (size_t)(k + 1));
    if (!ids || !names) {
      vd_free(ids, sizeof(int) * (size_t)(k + 1));
      vd_free(names, sizeof(char*) * (size_t)(k + 1));
      return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
    }
    if (k) {
      memcpy(ids, ls->label_id, sizeof(int) * (size_t)k);
      memcpy(names, ls->label_name, sizeof(char*) * (size_t)k);
    }
    vd_free(ls->label_id, sizeof(int) * (size_t)k);
    vd_free(ls->label_name, sizeof(char*) * (size_t)k);
    ids[k] = id;
    names[k] = ls->str[L.sid];
    ls->label_id = ids;
    ls->label_name = names;
    ls->nlabel = k + 1;
    if (lx_next(&L)) return ls->err->status;
    if (tok_is(&L, ',')) {
      if (lx_next(&L)) return ls->err->status;
    } else if (!tok_is(&L, '}')) {
      return perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "expected ',' or '}' in LABELS");
    }
  }
  return VD_OK;
}

// module A, B(x, t), Leaf : scale = 2
static vd_status parse_module_decl(parser* P, const pline* ln, int from) {
  vd_lsystem* ls = P->ls;
  int p = from;
  const char* s = ln->s;
  int decl[64], ndecl = 0;  // the modules the line declares
  for (;;) {
    while (p < ln->len && is_space(s[p])) p++;
    if (p < ln->len && s[p] == ':') {
      // `: scale = n` (multiscale, read by the options) and `: base = A` or `base = (A, C)`
      // (inheritance): the bases of every module of the line
      for (int k = p + 1; k + 4 <= ln->len; k++) {
        if (memcmp(s + k, "base", 4) != 0 || isalnum((unsigned char)s[k - 1]) || s[k - 1] == '_' ||
            (k + 4 < ln->len && (isalnum((unsigned char)s[k + 4]) || s[k + 4] == '_')))
          continue;
        int q = k + 4;
        while (q < ln->len && is_space(s[q])) q++;
        if (q >= ln->len || s[q] != '=') continue;
        q++;
        while (q < ln->len && is_space(s[q])) q++;
        int group = q < ln->len && (s[q] == '(' || s[q] == '[');
        if (group) q++;
        for (;;) {
          while (q < ln->len && (is_space(s[q]) || s[q] == ',')) q++;
          int a = q;
          while (q < ln->len && !is_space(s[q]) && s[q] != ',' && s[q] != ')' && s[q] != ']' && s[q] != '#') q++;
          if (q == a) break;
          int b = sym_intern(ls, s + a, q - a, 1);
          if (b < 0) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
          for (int d = 0; d < ndecl; d++) {
            if (!vd_grow((void**)&ls->mbase, &ls->capbase, ls->nbase + 1, sizeof(struct mbase)))
              return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
            ls->mbase[ls->nbase++] = (struct mbase){decl[d], b};
          }
          ls->has_bases = 1;
          if (!group) break;
        }
        break;
      }
      break;
    }
    if (p >= ln->len || s[p] == '#') break;
    int a = p;
    while (p < ln->len && !is_space(s[p]) && s[p] != ',' && s[p] != '(' && s[p] != ':' && s[p] != '#') p++;
    if (p == a) return perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + p, "expected a module name");
    int sym = sym_intern(ls, s + a, p - a, 1);
    if (sym < 0) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
    if (ndecl < 64) decl[ndecl++] = sym;
    while (p < ln->len && is_space(s[p]) && p + 1 < ln->len && (is_space(s[p + 1]) || s[p + 1] == '(')) p++;
    if (p < ln->len && is_space(s[p]) && p + 1 < ln->len && s[p + 1] == '(') p++;
    if (p < ln->len && s[p] == '(') {
      // parameter names (for **kwds patterns): names separated by commas
      int names[64], nn = 0, open = p;
      int depth = 0;
      while (p < ln->len) {
        if (s[p] == '(') depth++;
        if (s[p] == ')' && --depth == 0) break;
        p++;
      }
      if (p >= ln->len) return perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + a, "unclosed '(' in module declaration");
      for (int q = open + 1; q < p && nn < 64;) {
        while (q < p && (is_space(s[q]) || s[q] == ',')) q++;
        int n0 = q;
        while (q < p && (isalnum((unsigned char)s[q]) || s[q] == '_')) q++;
        if (q == n0) break;
        int id = str_intern(ls, s + n0, q - n0);
        if (id < 0) return str_intern_error(ls, id, ln->lineno, ln->col0 + n0);
        names[nn++] = id;
        while (q < p && s[q] != ',') q++;
      }
      if (nn) {
        if (!vd_grow((void**)&ls->pdecl, &ls->cappdecl, ls->npdecl + 1, sizeof(struct pdecl)))
          return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
        struct pdecl* d = &ls->pdecl[ls->npdecl++];
        d->sym = sym;
        d->n = nn;
        d->name = aalloc(ls, sizeof(int) * (size_t)nn);
        if (!d->name) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
        memcpy(d->name, names, sizeof(int) * (size_t)nn);
      }
      p++;
    }
    while (p < ln->len && is_space(s[p])) p++;
    if (p < ln->len && s[p] == ',') p++;
  }
  return VD_OK;
}

// consider: / ignore: followed by module names: a filter for the rules that follow (L-Py
// applies the last one written before a rule to its contexts); an empty list ends filtering
static vd_status parse_symbol_list(parser* P, const pline* ln, int from, int mode) {
  vd_lsystem* ls = P->ls;
  if (is_blank(ln->s + from, ln->len - from)) {
    ls->cur_filter = -1;
    return VD_OK;
  }
  if (!vd_grow((void**)&ls->filters, &ls->capfilter, ls->nfilter + 1, sizeof(cfilter)))
    return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
  cfilter* f = &ls->filters[ls->nfilter++];
  memset(f, 0, sizeof *f);
  f->mode = mode;
  int p = from;
  while (p < ln->len) {
    while (p < ln->len && is_space(ln->s[p])) p++;
    if (p >= ln->len || ln->s[p] == '#') break;
    int sym = read_module_name(ls, ln->s, ln->len, &p, ln->lineno, ln->col0);
    if (sym < 0) return ls->err->status;
    int32_t* ns = vd_realloc(f->syms, sizeof(int32_t) * (size_t)f->nsyms, sizeof(int32_t) * (size_t)(f->nsyms + 1));
    if (!ns) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
    f->syms = ns;
    f->syms[f->nsyms++] = sym;
  }
  ls->cur_filter = ls->nfilter - 1;
  return VD_OK;
}

static vd_status add_rule(vd_lsystem* ls, rule* r) {
  if (!vd_grow((void**)&ls->rules, &ls->caprule, ls->nrule + 1, sizeof(rule*)))
    return perr(ls, VD_ERR_NOMEM, r->line, 1, "out of memory");
  ls->rules[ls->nrule++] = r;
  return VD_OK;
}

// find a top-level (outside brackets and strings) occurrence of a string in s[a..b)
static int find_top(const char* s, int a, int b, const char* what) {
  int n = (int)strlen(what), depth = 0;
  char q = 0;
  for (int i = a; i + n <= b; i++) {
    char c = s[i];
    int k = lsys_quote_step(c, &q);
    if (k) {
      i += k - 1;
      continue;
    }
    if (c == '#') return -1;
    if (c == '(') depth++;
    else if (c == ')') depth--;
    else if (depth == 0 && memcmp(s + i, what, (size_t)n) == 0) return i;
  }
  return -1;
}

static vd_status parse_rule(parser* P, int* li, int section, int group) {
  vd_lsystem* ls = P->ls;
  pline* ln = &P->lines[*li];
  const char* s = ln->s;
  int len = ln->len;
  // strip a trailing comment
  {
    char q = 0;
    int depth = 0;
    for (int i = 0; i < len; i++) {
      char c = s[i];
      int k = lsys_quote_step(c, &q);
      if (k) {
        i += k - 1;
        continue;
      }
      if (c == '(') {
        depth++;
      } else if (c == ')') {
        depth--;
      } else if (c == '#') {
        len = i;
        break;
      }
    }
  }
  rule* r = aalloc(ls, sizeof(rule));
  if (!r) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
  r->section = section;
  r->group = group;
  r->line = ln->lineno;
  scope sc;
  memset(&sc, 0, sizeof sc);
  sc.is_function = 1;
  vd_status st = VD_OK;
  // the header ends at the first '-->' (or '-static->') or ':' (L-Py's rule)
  int arrow = find_top(s, 0, len, "-->"), sarrow = find_top(s, 0, len, "-static->");
  int colon = find_top(s, 0, len, ":");
  int arrow_len = 3;
  if (sarrow >= 0 && (arrow < 0 || sarrow < arrow)) {
    arrow = sarrow;
    arrow_len = 9;
    r->is_static = 1;
  }
  if (colon >= 0 && arrow >= 0 && colon < arrow) arrow = -1;
  if (arrow >= 0) colon = -1;
  int hend = arrow >= 0 ? arrow : colon;
  if (hend < 0) {
    if (find_top(s, 0, len, "->") >= 0)
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + find_top(s, 0, len, "->"),
                "'->' is not a rule arrow: write '-->'");
    else
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + len, "expected '-->' or ':' after the rule's predecessor");
    goto done;
  }
  // header: newleft << left < pred >> newright > right (L-Py's order), outside parentheses
  int cut[5] = {-1, -1, -1, -1, -1};  // ends of: newleft, left, pred, newright; right runs to hend
  {
    int begs = 0, depth = 0, in_nright = 0, pred_end = -1;
    int nl_end = -1, l_end = -1, nr_end = -1;
    char q = 0;
    for (int i = 0; i < hend; i++) {
      char c = s[i];
      int k = lsys_quote_step(c, &q);
      if (k) {
        i += k - 1;
        continue;
      }
      if (c == '(') depth++;
      else if (c == ')') depth--;
      else if (depth == 0 && c == '<') {
        int two = i + 1 < hend && s[i + 1] == '<';
        if (pred_end >= 0 || (two ? nl_end >= 0 : l_end >= 0)) {
          st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + i, "ill-formed rule header: misplaced '%s'", two ? "<<" : "<");
          goto done;
        }
        if (two) nl_end = i, i++;
        else l_end = i;
        begs = i + 1;
      } else if (depth == 0 && c == '>') {
        int two = i + 1 < hend && s[i + 1] == '>';
        if (two) {
          if (in_nright || nr_end >= 0 || pred_end >= 0) {
            st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + i, "ill-formed rule header: misplaced '>>'");
            goto done;
          }
          pred_end = i;
          in_nright = 1;
          i++;
        } else if (in_nright) {
          nr_end = i;
          in_nright = 0;
        } else if (pred_end < 0) {
          pred_end = i;
        } else {
          st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + i, "ill-formed rule header: two right contexts");
          goto done;
        }
        begs = i + 1;
      }
    }
    (void)begs;
    cut[0] = nl_end;
    cut[1] = l_end;
    cut[2] = pred_end;
    cut[3] = in_nright ? hend : nr_end;
    cut[4] = in_nright;
  }
  {
    int nl_end = cut[0], l_end = cut[1], pred_end = cut[2], nr_end = cut[3];
    int pa = (nl_end > l_end ? nl_end + 2 : l_end >= 0 ? l_end + 1 : 0);
    int pb = pred_end >= 0 ? pred_end : hend;
    int lo = 0;
    // the contexts before the predecessor, in written order
    if (nl_end >= 0 && (l_end < 0 || nl_end < l_end)) {
      if (!parse_pstr(ls, &sc, s, 0, nl_end, ln->lineno, ln->col0, 0, &r->nleft)) goto fail;
      lo = nl_end + 2;
      if (l_end >= 0 && !parse_pstr(ls, &sc, s, lo, l_end, ln->lineno, ln->col0, 0, &r->left)) goto fail;
    } else if (l_end >= 0) {
      if (!parse_pstr(ls, &sc, s, 0, l_end, ln->lineno, ln->col0, 0, &r->left)) goto fail;
      lo = l_end + 1;
      if (nl_end >= 0 && !parse_pstr(ls, &sc, s, lo, nl_end, ln->lineno, ln->col0, 0, &r->nleft)) goto fail;
    }
    if (!parse_pstr(ls, &sc, s, pa, pb, ln->lineno, ln->col0, 0, &r->pred)) goto fail;
    if (r->pred.n == 0) {
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + pa, "rule without a predecessor");
      goto done;
    }
    for (int k = 0; k < r->pred.n; k++)
      if (r->pred.m[k].kind == PK_REP || r->pred.m[k].kind == PK_OR) {
        st = perr(ls, VD_ERR_UNSUPPORTED, ln->lineno, r->pred.m[k].col,
                  "unsupported: x(...) or or(...) in a strict predecessor");
        goto done;
      }
    if (pred_end >= 0) {
      if (cut[4] || nr_end >= 0) {
        // pred >> newright [> right]
        int ne = nr_end >= 0 ? nr_end : hend;
        if (!parse_pstr(ls, &sc, s, pred_end + 2, ne, ln->lineno, ln->col0, 0, &r->nright)) goto fail;
        if (nr_end >= 0 && nr_end < hend &&
            !parse_pstr(ls, &sc, s, nr_end + 1, hend, ln->lineno, ln->col0, 0, &r->right))
          goto fail;
      } else if (!parse_pstr(ls, &sc, s, pred_end + 1, hend, ln->lineno, ln->col0, 0, &r->right)) {
        goto fail;
      }
    }
    if (r->nleft.n && r->nright.n) {
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0, "ill-formed rule header: new left and new right contexts");
      goto done;
    }
  }
  r->filter = ls->cur_filter;
  // @static after ':' (L-Py's marker for a static rule body)
  if (colon >= 0) {
    int m = colon + 1;
    while (m < len && is_space(s[m])) m++;
    if (len - m >= 7 && memcmp(s + m, "@static", 7) == 0) {
      r->is_static = 1;
      colon = m + 6;
    }
  }
  if (ls->engine == VD_LSYS_PYTHON) {
    // the Python engine: the successor or the body becomes a Python function of the pattern
    // variables
    if (arrow >= 0) {
      r->succ = parse_tmpl(ls, &sc, s, len, arrow + arrow_len, ln->lineno, ln->col0);
      if (!r->succ) goto fail;
    }
    st = lsys_py_rule(ls, r, sc.names, sc.lens, sc.n, P->lines, P->nline, li, arrow >= 0 ? -1 : colon + 1);
    if (st) goto done;
    r->nlocal = sc.n;
    st = add_rule(ls, r);
    goto done;
  }
  if (arrow >= 0) {
    r->succ = parse_tmpl(ls, &sc, s, len, arrow + arrow_len, ln->lineno, ln->col0);
    if (!r->succ) goto fail;
    (*li)++;
  } else {
    // body: inline after ':' or the indented lines that follow
    sparse S = {P, ls, &sc, 0, 0, 1};
    int rest = colon + 1;
    if (!is_blank(s + rest, len - rest)) {
      pline sub = *ln;
      sub.s = s + rest;
      sub.len = len - rest;
      sub.col0 = ln->col0 + rest;
      sub.indent = 0;
      pline* saved = P->lines;
      int saved_n = P->nline;
      P->lines = &sub;
      P->nline = 1;
      int k = 0;
      r->body = parse_block(&S, &k, 0);
      P->lines = saved;
      P->nline = saved_n;
      if (!r->body) goto fail;
      (*li)++;
    } else {
      int j = *li + 1;
      while (j < P->nline && P->lines[j].blank) j++;
      if (j >= P->nline || P->lines[j].indent <= ln->indent) {
        st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + colon, "expected an indented rule body after ':'");
        goto done;
      }
      prescan_locals(&S, j, P->lines[j].indent, &sc);
      *li = j;
      r->body = parse_block(&S, li, P->lines[j].indent);
      if (!r->body) goto fail;
    }
  }
  r->nlocal = sc.n;
  st = add_rule(ls, r);
  goto done;
fail:
  st = ls->err && ls->err->status ? ls->err->status : VD_ERR_NOMEM;
done:
  scope_free(&sc);
  return st;
}

// append statements (a list linked by next) to the top-level code
static void append_top(vd_lsystem* ls, stmt* s) {
  if (ls->top_tail) ls->top_tail->next = s;
  else ls->top = s;
  ls->top_tail = s;
  while (ls->top_tail->next) ls->top_tail = ls->top_tail->next;
}

static vd_status parse_def(parser* P, int* li) {
  vd_lsystem* ls = P->ls;
  pline* ln = &P->lines[*li];
  lexer L;
  lx_init(&L, ls, ln->s, ln->len, ln->lineno, ln->col0, 0);
  if (lx_next(&L) || lx_next(&L)) return ls->err->status;  // NOLINT(misc-redundant-expression): lx_next advances: skip 'def', then read the name
  if (L.t != T_NAME) return perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "expected a function name after 'def'");
  func* f = aalloc(ls, sizeof(func));
  if (!f) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
  snprintf(f->name, sizeof f->name, "%.*s", L.tlen, L.s + L.start);
  f->line = ln->lineno;
  f->discard_wrapped = P->discard_decorator;
  P->discard_decorator = 0;
  int g = global_slot(ls, L.s + L.start, L.tlen, 1);
  if (g < 0) return perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
  if (lx_next(&L) || expect(&L, '(', "'(' after the function name")) return ls->err->status;
  scope sc;
  memset(&sc, 0, sizeof sc);
  sc.is_function = 1;
  vd_status st = VD_OK;
  while (!tok_is(&L, ')')) {
    if (L.t != T_NAME) {
      st = perr(ls, tok_is(&L, '*') || tok_is(&L, OP_POW) ? VD_ERR_UNSUPPORTED : VD_ERR_SYNTAX, ln->lineno,
                lx_col(&L), "expected a parameter name");
      goto done;
    }
    if (scope_add(ls, &sc, L.s + L.start, L.tlen) < 0) {
      st = VD_ERR_NOMEM;
      goto done;
    }
    if (lx_next(&L)) goto fail;
    if (tok_is(&L, '=')) {
      st = perr(ls, VD_ERR_UNSUPPORTED, ln->lineno, lx_col(&L), "unsupported: default parameter values");
      goto done;
    }
    if (tok_is(&L, ',')) {
      if (lx_next(&L)) goto fail;
    } else if (!tok_is(&L, ')')) {
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, lx_col(&L), "expected ',' or ')' in parameters");
      goto done;
    }
  }
  f->nparam = sc.n;
  if (lx_next(&L)) goto fail;
  sparse S = {P, ls, &sc, 0, 1, 1};
  {
    // locals: prescan the body
    int j = *li + 1;
    while (j < P->nline && P->lines[j].blank) j++;
    if (j < P->nline && P->lines[j].indent > ln->indent) prescan_locals(&S, j, P->lines[j].indent, &sc);
  }
  f->body = parse_suite(&S, &L, li, ln->indent);
  if (!f->body) goto fail;
  f->nlocal = sc.n;
  if (!vd_grow((void**)&ls->funcs, &ls->capfunc, ls->nfunc + 1, sizeof(func*))) {
    st = perr(ls, VD_ERR_NOMEM, ln->lineno, 1, "out of memory");
    goto done;
  }
  ls->funcs[ls->nfunc] = f;
  // the function is bound to its global name when the top-level code runs
  {
    stmt* s = new_stmt(ls, S_ASSIGN, ln->lineno, ln->col0);
    expr* e = aalloc(ls, sizeof(expr));
    if (!s || !e) goto fail;
    e->op = E_CONST;
    e->k = (value){V_FUNC, ls->nfunc};
    s->is_global = 1;
    s->slot = g;
    s->e = e;
    append_top(ls, s);
  }
  ls->nfunc++;
  goto done;
fail:
  st = ls->err && ls->err->status ? ls->err->status : VD_ERR_NOMEM;
done:
  scope_free(&sc);
  return st;
}

static vd_status parse_toplevel_stmt(parser* P, int* li) {
  vd_lsystem* ls = P->ls;
  pline* ln = &P->lines[*li];
  int a;
  if (ls->engine == VD_LSYS_PYTHON) {
    // the Python engine: CPython runs the statement; a literal LABELS dict is read here too
    if (starts_kw(ln, "LABELS", &a)) {
      int p = a;
      while (p < ln->len && is_space(ln->s[p])) p++;
      if (p < ln->len && ln->s[p] == '=' && (p + 1 >= ln->len || ln->s[p + 1] != '=')) {
        vd_error keep = *ls->err;
        if (parse_labels_dict(P, ln, p + 1)) *ls->err = keep;  // not a literal dict: Python's
      }
    }
    return lsys_py_toplevel(ls, P->lines, P->nline, li);
  }
  if (starts_kw(ln, "import ", &a) || starts_kw(ln, "from ", &a)) {
    vd_status st = parse_import(P, ln);
    (*li)++;
    return st;
  }
  if (ln->len > 1 && ln->s[0] == '@') {
    // decorators: only L-Py's @enable_string_discard (DiscardNewString through EndEach)
    if (starts_kw(ln, "@enable_string_discard", &a) && rest_blank(ln, a)) {
      P->discard_decorator = 1;
      (*li)++;
      return VD_OK;
    }
    return perr(ls, VD_ERR_UNSUPPORTED, ln->lineno, ln->col0, "unsupported: decorator '%.*s'", ln->len, ln->s);
  }
  if (starts_kw(ln, "def ", &a)) return parse_def(P, li);
  if (starts_kw(ln, "class ", &a))
    return perr(ls, VD_ERR_UNSUPPORTED, ln->lineno, ln->col0, "unsupported: 'class'");
  // LABELS = {...}
  if (starts_kw(ln, "LABELS", &a)) {
    int p = a;
    while (p < ln->len && is_space(ln->s[p])) p++;
    if (p < ln->len && ln->s[p] == '=' && (p + 1 >= ln->len || ln->s[p + 1] != '=')) {
      (*li)++;
      return parse_labels_dict(P, ln, p + 1);
    }
  }
  // extern(NAME = value): an L-Py global that can be set from outside
  if (starts_kw(ln, "extern", &a)) {
    int p = a;
    while (p < ln->len && is_space(ln->s[p])) p++;
    if (p < ln->len && ln->s[p] == '(') {
      int close = ln->len - 1;
      while (close > p && ln->s[close] != ')') close--;
      pline sub = *ln;
      sub.s = ln->s + p + 1;
      sub.len = close - p - 1;
      sub.col0 = ln->col0 + p + 1;
      sub.indent = 0;
      pline* saved = P->lines;
      int saved_n = P->nline;
      P->lines = &sub;
      P->nline = 1;
      int k = 0;
      sparse S = {P, ls, NULL, 0, 0, 0};
      stmt* s = parse_block(&S, &k, 0);
      P->lines = saved;
      P->nline = saved_n;
      if (!s) return ls->err->status;
      if (s->op != S_ASSIGN)
        return perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0, "extern() expects NAME = value");
      append_top(ls, s);
      (*li)++;
      return VD_OK;
    }
  }
  sparse S = {P, ls, NULL, 0, 0, 0};
  stmt* s = parse_statement(&S, li, ln->indent);
  if (!s) return ls->err->status ? ls->err->status : VD_ERR_NOMEM;
  append_top(ls, s);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// the INITIALISATION trailer: scalar defaults and material names

static void add_scalar(vd_lsystem* ls, const char* name, int nlen, value v) {
  int g = global_slot(ls, name, nlen, 1);
  if (g < 0) return;
  int n = ls->nscalar;
  int* slots = vd_malloc(sizeof(int) * (size_t)(n + 1));
  value* vals = vd_malloc(sizeof(value) * (size_t)(n + 1));
  if (!slots || !vals) {
    vd_free(slots, sizeof(int) * (size_t)(n + 1));
    vd_free(vals, sizeof(value) * (size_t)(n + 1));
    return;
  }
  if (n) {
    memcpy(slots, ls->scalar_slot, sizeof(int) * (size_t)n);
    memcpy(vals, ls->scalar_val, sizeof(value) * (size_t)n);
  }
  vd_free(ls->scalar_slot, sizeof(int) * (size_t)n);
  vd_free(ls->scalar_val, sizeof(value) * (size_t)n);
  slots[n] = g;
  vals[n] = v;
  ls->scalar_slot = slots;
  ls->scalar_val = vals;
  ls->nscalar = n + 1;
}

static int parse_scalar_value(const char* s, int len, value* v) {
  while (len > 0 && is_space(*s)) s++, len--;
  while (len > 0 && is_space(s[len - 1])) len--;
  if (len == 4 && memcmp(s, "True", 4) == 0) {
    *v = (value){V_BOOL, 1};
    return 1;
  }
  if (len == 5 && memcmp(s, "False", 5) == 0) {
    *v = (value){V_BOOL, 0};
    return 1;
  }
  char buf[64];
  if (len <= 0 || len >= 63) return 0;
  memcpy(buf, s, (size_t)len);
  buf[len] = 0;
  char* end;
  double d = strtod(buf, &end);
  if (*end) return 0;
  int isint = strchr(buf, '.') == NULL && strchr(buf, 'e') == NULL && strchr(buf, 'E') == NULL;
  *v = isint ? v_int(d) : v_num(d);
  return 1;
}

// Apply one L-Py option (the trailer's or a run-time context.options.setSelection): the options
// that change results; those the engines cannot honour are refused (line for the message)
vd_status lsys_set_option(vd_lsystem* ls, const char* name, int nlen, long v, int line) {
  if (name_is(name, nlen, "Early return when no matching")) {
    ls->opt_early_return = v != 0;
  } else if (name_is(name, nlen, "Axiom decomposition")) {
    ls->opt_axiom_decomposition = v != 0;
  } else if (name_is(name, nlen, "Module matching")) {
    ls->opt_module_matching = (int)v;
  } else if (name_is(name, nlen, "String matching")) {
    if (v == 2 || v == 3)
      return perr(ls, VD_ERR_UNSUPPORTED, line, 1,
                  "unsupported: option 'String matching' = %s (multi-level and multiscale matching)",
                  v == 2 ? "As Multi-level AxialTree" : "As Multiscale AxialTree");
    ls->opt_string_matching = v != 0;
    ls->rule_index_group = -1;  // the rule index (which rules take the fast matcher) is rebuilt
  } else if (name_is(name, nlen, "Module inheritance")) {
    ls->opt_inherit = v != 0;
    ls->rule_index_group = -1;  // and its buckets (a rule serves the subclasses)
  }
  return VD_OK;
}

// context.options.setSelection('NAME', VALUE) lines of the trailer: the L-Py options that change
// results are applied; those the native engine cannot honour are refused
static vd_status parse_options(vd_lsystem* ls, const char* s, size_t len, int line0) {
  vd_status st;
  static const char key[] = "options.setSelection(";
  size_t kl = strlen(key);
  for (size_t i = 0; i + kl <= len; i++) {
    if (memcmp(s + i, key, kl) != 0) continue;
    int line = line0;
    for (size_t k = 0; k < i; k++) line += s[k] == '\n';
    size_t p = i + kl;
    while (p < len && is_space(s[p])) p++;
    if (p >= len || (s[p] != '\'' && s[p] != '"')) continue;
    char q = s[p++];
    size_t n0 = p;
    while (p < len && s[p] != q && s[p] != '\n') p++;
    if (p >= len || s[p] != q) continue;
    int nlen = (int)(p - n0);
    const char* name = s + n0;
    p++;
    while (p < len && (is_space(s[p]) || s[p] == ',')) p++;
    char* end;
    char buf[24];
    size_t bl = 0;
    while (p < len && bl < sizeof buf - 1 && s[p] != ')' && s[p] != '\n') buf[bl++] = s[p++];
    buf[bl] = 0;
    long v = strtol(buf, &end, 10);
    while (*end && isspace((unsigned char)*end)) end++;
    if (end == buf || *end) continue;  // a value computed at run time: not an option we read
    if ((st = lsys_set_option(ls, name, nlen, v, line))) return st;
  }
  // context.turtle.setAngleIncrement(a): the turtle's default angle for this file
  {
    static const char tkey[] = "turtle.setAngleIncrement(";
    size_t tl = strlen(tkey);
    for (size_t i = 0; i + tl <= len; i++) {
      if (memcmp(s + i, tkey, tl) != 0) continue;
      char buf[32];
      size_t bl = 0, p = i + tl;
      while (p < len && bl < sizeof buf - 1 && s[p] != ')' && s[p] != '\n') buf[bl++] = s[p++];
      buf[bl] = 0;
      char* end;
      double a = strtod(buf, &end);
      while (*end && isspace((unsigned char)*end)) end++;
      if (end != buf && !*end && isfinite(a)) {
        ls->turtle_angle = a;
        ls->has_turtle_angle = 1;
      }
    }
  }
  return VD_OK;
}

static void parse_trailer(vd_lsystem* ls, const char* s, size_t len) {
  // scalars = [('name', 'Float', 0.1, 0.0, 1.0, 2), ('n', 8, 0, 20)]
  const char* keys[] = {"scalars = [", "scalars=[", "__scalars__ = [", "__scalars__=["};
  for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
    size_t kl = strlen(keys[k]);
    for (size_t i = 0; i + kl <= len; i++) {
      if (memcmp(s + i, keys[k], kl) != 0) continue;
      size_t p = i + kl;
      // tuples until the closing ']'
      while (p < len && s[p] != ']') {
        if (s[p] != '(') {
          p++;
          continue;
        }
        size_t q = p + 1;
        const char* fields[8];
        int flen[8];
        int nf = 0;
        size_t fs = q;
        char quote = 0;
        int depth = 0;
        for (; q < len; q++) {
          char c = s[q];
          if (quote) {
            if (c == quote) quote = 0;
            continue;
          }
          if (c == '\'' || c == '"') quote = c;
          else if (c == '(' || c == '[') depth++;
          else if ((c == ')' || c == ']') && depth > 0) depth--;
          else if ((c == ',' || c == ')') && depth == 0) {
            if (nf < 8) {
              fields[nf] = s + fs;
              flen[nf] = (int)(q - fs);
              nf++;
            }
            fs = q + 1;
            if (c == ')') break;
          }
        }
        p = q + 1;
        if (nf < 2) continue;
        // name in quotes
        const char* nm = fields[0];
        int nl = flen[0];
        while (nl > 0 && is_space(*nm)) nm++, nl--;
        while (nl > 0 && is_space(nm[nl - 1])) nl--;
        if (nl < 2 || (nm[0] != '\'' && nm[0] != '"')) continue;
        nm++;
        nl -= 2;
        // typed form ('name', 'Float', value, ...) or plain ('name', value, min, max)
        const char* f1 = fields[1];
        int l1 = flen[1];
        while (l1 > 0 && is_space(*f1)) f1++, l1--;
        value v;
        if (l1 > 0 && (f1[0] == '\'' || f1[0] == '"')) {
          if (nf >= 3 && parse_scalar_value(fields[2], flen[2], &v)) add_scalar(ls, nm, nl, v);
        } else if (parse_scalar_value(fields[1], flen[1], &v)) {
          add_scalar(ls, nm, nl, v);
        }
      }
      break;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// entry point

static const char* section_kw[][2] = {{"production", "0"},     {"interpretation", "2"},
                                      {"homomorphism", "2"},   {"decomposition", "1"}};

vd_status lsys_parse_file(vd_lsystem* ls, const char* text, size_t len) {
  parser P;
  memset(&P, 0, sizeof P);
  P.ls = ls;
  ls->cur_filter = -1;
  if (len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3)) text += 3, len -= 3;  // a UTF-8 byte-order mark
  size_t init_at;
  vd_status st = split_lines(&P, text, len, &init_at);
  if (st) goto done;
  if (ls->engine == VD_LSYS_PYTHON && (st = lsys_py_parse_begin(ls, text, len))) goto done;
  int section = -1, group = 0, rule_indent = -1;
  int li = 0;
  while (li < P.nline) {
    pline* ln = &P.lines[li];
    if (ln->blank) {
      li++;
      continue;
    }
    int a;
    // keyword lines
    if (starts_kw_colon(ln, "Axiom", &a) || starts_kw_colon(ln, "axiom", &a)) {
      ls->axiom_line = ln->lineno;
      if (ls->engine == VD_LSYS_PYTHON) {
        tmpl* t = NULL;
        if (!rest_blank(ln, a) && !(t = parse_tmpl(ls, NULL, ln->s, ln->len, a, ln->lineno, ln->col0))) goto fail;
        if ((st = lsys_py_axiom(ls, t, P.lines, P.nline, &li))) goto done;
      } else if (!rest_blank(ln, a)) {
        ls->axiom = parse_tmpl(ls, NULL, ln->s, ln->len, a, ln->lineno, ln->col0);
        if (!ls->axiom) goto fail;
        li++;
      } else {
        // functional axiom: an indented block with nproduce
        int j = li + 1;
        while (j < P.nline && P.lines[j].blank) j++;
        if (j >= P.nline || P.lines[j].indent <= ln->indent) {
          // an empty axiom (L-Py accepts it: the derivation has nothing to rewrite)
          ls->axiom = lsys_parse_tmpl_text(ls, "", 0, ln->lineno, ln->col0 + a);
          if (!ls->axiom) goto fail;
          li++;
          section = -1;
          continue;
        }
        scope sc;
        memset(&sc, 0, sizeof sc);
        sc.is_function = 1;
        sparse S = {&P, ls, &sc, 0, 0, 1};
        prescan_locals(&S, j, P.lines[j].indent, &sc);
        li = j;
        ls->axiom_body = parse_block(&S, &li, P.lines[j].indent);
        ls->axiom_nlocal = sc.n;
        scope_free(&sc);
        if (!ls->axiom_body) goto fail;
      }
      section = -1;
      continue;
    }
    if (starts_kw_colon(ln, "derivation length", &a) && ls->engine == VD_LSYS_PYTHON) {
      if ((st = lsys_py_dlength(ls, ln->s + a, ln->len - a, ln->lineno))) goto done;
      li++;
      continue;
    }
    if (starts_kw_colon(ln, "derivation length", &a)) {
      ls->derivation_length = lsys_parse_expr_text(ls, ln->s + a, ln->len - a, ln->lineno, ln->col0 + a);
      if (!ls->derivation_length) goto fail;
      li++;
      continue;
    }
    int sec = -1;
    for (size_t k = 0; k < sizeof section_kw / sizeof section_kw[0]; k++)
      if (starts_kw_colon(ln, section_kw[k][0], &a)) sec = section_kw[k][1][0] - '0';
    if (sec >= 0) {
      section = sec;
      rule_indent = -1;
      li++;
      continue;
    }
    if (starts_kw_colon(ln, "maximum depth", &a)) {
      if (section != SEC_DECOMPOSITION && section != SEC_INTERPRETATION) {
        st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0,
                  "'maximum depth:' must follow 'decomposition:' or 'interpretation:'");
        goto done;
      }
      // an expression (L-Py evaluates it after the top-level code): `maximum depth: N`
      ls->max_depth_expr[section] = ls->engine == VD_LSYS_PYTHON
                                        ? lsys_py_expr(ls, ln->s + a, ln->len - a, ln->lineno, ln->col0 + a)
                                        : lsys_parse_expr_text(ls, ln->s + a, ln->len - a, ln->lineno, ln->col0 + a);
      if (!ls->max_depth_expr[section]) goto fail;
      li++;
      continue;
    }
    if (starts_kw(ln, "group", &a) && a < ln->len && is_space(ln->s[a])) {
      // the number goes through a NUL-terminated copy: the last line of the text has no end
      while (a < ln->len && is_space(ln->s[a])) a++;
      char buf[32];
      int n = ln->len - a < 31 ? ln->len - a : 31;
      memcpy(buf, ln->s + a, (size_t)n);
      buf[n] = 0;
      char* bend;
      long g = strtol(buf, &bend, 10);
      const char* end = ln->s + a + (bend - buf);
      while (end < ln->s + ln->len && is_space(*end)) end++;
      if (bend == buf || end >= ln->s + ln->len || *end != ':' || g < 0 || g > 1000000) {
        st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0 + a, "expected 'group N:' with an integer N");
        goto done;
      }
      group = (int)g;
      li++;
      continue;
    }
    if (starts_kw(ln, "endgroup", &a) && rest_blank(ln, a)) {
      group = 0;
      li++;
      continue;
    }
    if (starts_kw_colon(ln, "ignore", &a) || starts_kw_colon(ln, "consider", &a)) {
      int mode = ln->s[0] == 'i' ? 1 : 2;
      if ((st = parse_symbol_list(&P, ln, a, mode))) goto done;
      li++;
      continue;
    }
    if (starts_kw(ln, "module", &a) && a < ln->len && is_space(ln->s[a])) {
      if ((st = parse_module_decl(&P, ln, a))) goto done;
      li++;
      continue;
    }
    if (starts_kw(ln, "endlsystem", &a) && rest_blank(ln, a)) {
      section = -1;
      li++;
      continue;
    }
    if (starts_kw(ln, "nproduce", &a) || starts_kw(ln, "produce", &a)) {
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0, "'produce' outside a rule or the axiom");
      goto done;
    }
    // a def in a rule section ends the section (L-Py switches to Python code there)
    if (section >= 0 && ln->indent == 0 && starts_kw(ln, "def ", &a)) section = -1;
    // rules inside a section
    if (section >= 0 && (rule_indent < 0 || ln->indent <= rule_indent)) {
      if (rule_indent < 0) rule_indent = ln->indent;
      if ((st = parse_rule(&P, &li, section, group))) goto done;
      continue;
    }
    if (section >= 0) {
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0, "unexpected indentation in a rule section");
      goto done;
    }
    if (ln->indent > 0) {
      st = perr(ls, VD_ERR_SYNTAX, ln->lineno, ln->col0, "unexpected indentation");
      goto done;
    }
    if ((st = parse_toplevel_stmt(&P, &li))) goto done;
  }
  {
    // a file with nothing in it is not an L-system (without an Axiom:, a file of rules or of
    // Python code is: its string is empty, as in L-Py)
    int content = 0;
    for (int k = 0; k < P.nline && !content; k++) content = !P.lines[k].blank;
    if (!content) {
      st = perr(ls, VD_ERR_SYNTAX, 1, 1, "the file is empty (no Axiom:, no rules, no code)");
      goto done;
    }
  }
  if (ls->engine == VD_LSYS_PYTHON) {
    // the trailer runs as Python; its L-system options (matching, early return) apply here too
    if (init_at < len) {
      int line0 = 1;
      for (size_t k = 0; k < init_at; k++) line0 += text[k] == '\n';
      if ((st = parse_options(ls, text + init_at, len - init_at, line0))) goto done;
    }
    st = lsys_py_parse_end(ls, init_at);
    goto done;
  }
  if (!ls->axiom && !ls->axiom_body) {
    // no Axiom: an empty string (L-Py's default: a rule set for composition, or Python code alone)
    ls->axiom = lsys_parse_tmpl_text(ls, "", 0, 1, 1);
    if (!ls->axiom) goto fail;
  }
  if (init_at < len) {
    int line0 = 1;
    for (size_t k = 0; k < init_at; k++) line0 += text[k] == '\n';
    parse_trailer(ls, text + init_at, len - init_at);
    if ((st = parse_options(ls, text + init_at, len - init_at, line0))) goto done;
  }
  goto done;
fail:
  st = ls->err && ls->err->status ? ls->err->status : VD_ERR_NOMEM;
  if (ls->err && ls->err->status == VD_OK) perr(ls, st, 0, 0, "out of memory");
done:
  vd_free(P.lines, (size_t)P.capline * sizeof(pline));
  return st;
}

// ---------------------------------------------------------------------------------------------
// patterns of InLeftContext / InRightContext (Python engine, at run time)

const lsys_cpat* lsys_context_pattern(vd_lsystem* ls, const char* s, int len, int line) {
  int sid = str_intern(ls, s, len);
  if (sid < 0) {
    str_intern_error(ls, sid, line, 0);
    return NULL;
  }
  for (int i = 0; i < ls->ncpat; i++)
    if (ls->cpat[i].sid == sid) return &ls->cpat[i];
  if (!vd_grow((void**)&ls->cpat, &ls->capcpat, ls->ncpat + 1, sizeof(lsys_cpat))) {
    perr(ls, VD_ERR_NOMEM, line, 0, "out of memory");
    return NULL;
  }
  lsys_cpat* c = &ls->cpat[ls->ncpat];
  memset(c, 0, sizeof *c);
  c->sid = sid;
  const char* t = ls->str[sid];  // lives as long as the lsystem (names point into it)
  scope sc = {0};
  sc.is_function = 1;
  int ok = parse_pstr(ls, &sc, t, 0, len, line, 1, 0, &c->p);
  if (ok && sc.n > 64) ok = !perr(ls, VD_ERR_LIMIT, line, 0, "more than 64 variables in a context pattern");
  if (ok && sc.n && !(c->var = aalloc(ls, sizeof(int) * (size_t)sc.n)))
    ok = !perr(ls, VD_ERR_NOMEM, line, 0, "out of memory");
  for (int i = 0; ok && i < sc.n; i++)
    if ((c->var[i] = str_intern(ls, sc.names[i], sc.lens[i])) < 0) ok = !str_intern_error(ls, c->var[i], line, 0);
  c->nvar = sc.n;
  scope_free(&sc);
  if (!ok) return NULL;
  ls->ncpat++;
  return c;
}
