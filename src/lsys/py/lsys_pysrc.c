// SPDX-License-Identifier: MIT
// The Python engine's source: the parser hands over the Python parts of an .lpy file (top-level
// statements, rule bodies and successors, the axiom, the derivation length, the editor
// trailer) and this file turns them into Python text for CPython, as L-Py's own translator
// does: `produce L-string` becomes `return __vd_p(id, (params of module 1), ...)`, `nproduce`
// the same call without the return, `makestring` a call that builds an Lstring object. The
// template `id` keeps the L-string's modules on the C side; the tuples carry the parameter
// values, so `*args` unpacks as in Python. Top-level code keeps its file lines; each function
// is compiled on its own with its first line at the file line it came from, so tracebacks and
// errors name the lines of the .lpy file.
#include "lsys/py/lsys_py.h"  // Python.h first: it sets the feature macros

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

// ---------------------------------------------------------------------------------------------
// text buffers

void sb_put(sbuf* b, const char* s, size_t n) {
  if (b->failed) return;
  if (b->n + n + 1 > b->cap) {
    size_t nc = b->cap ? b->cap : 256;
    while (nc < b->n + n + 1) nc *= 2;
    char* p = vd_realloc(b->s, b->cap, nc);
    if (!p) {
      b->failed = 1;
      return;
    }
    b->s = p;
    b->cap = nc;
  }
  memcpy(b->s + b->n, s, n);
  b->n += n;
  b->s[b->n] = 0;
}

void sb_puts(sbuf* b, const char* s) { sb_put(b, s, strlen(s)); }

void sb_printf(sbuf* b, const char* fmt, ...) {
  char tmp[512];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  if (n < 0) return;
  if ((size_t)n < sizeof tmp) {
    sb_put(b, tmp, (size_t)n);
    return;
  }
  char* big = vd_malloc((size_t)n + 1);
  if (!big) {
    b->failed = 1;
    return;
  }
  va_start(ap, fmt);
  vsnprintf(big, (size_t)n + 1, fmt, ap);
  va_end(ap);
  sb_put(b, big, (size_t)n);
  vd_free(big, (size_t)n + 1);
}

void sb_free(sbuf* b) {
  vd_free(b->s, b->cap);
  memset(b, 0, sizeof *b);
}

char* sb_take(sbuf* b, size_t* len) {
  if (b->failed || !b->s) {
    sb_free(b);
    sb_put(b, "", 0);
    if (b->failed) {
      sb_free(b);
      return NULL;
    }
  }
  // shrink to the exact size so the owner frees strlen + 1 bytes
  char* out = vd_malloc(b->n + 1);
  if (out) {
    memcpy(out, b->s, b->n + 1);
    if (len) *len = b->n;
  }
  sb_free(b);
  return out;
}

static void free_str(char* s) {
  if (s) vd_free(s, strlen(s) + 1);
}

static vd_status nomem(vd_lsystem* ls, int line) { return vm_error(ls, VD_ERR_NOMEM, line, 0, "out of memory"); }

// ---------------------------------------------------------------------------------------------
// parse begin / end

vd_status lsys_py_parse_begin(vd_lsystem* ls, const char* text, size_t len) {
  lsys_py* py = vd_calloc(1, sizeof(lsys_py));
  if (!py) return nomem(ls, 0);
  ls->py = py;
  py->text = text;
  py->len = len;
  py->fn_axiom = py->fn_dlen = -1;
  int n = 1;
  for (size_t i = 0; i < len; i++)
    if (text[i] == '\n') n++;
  py->nphys = n;
  py->phys_at = vd_malloc(sizeof(size_t) * (size_t)(n + 1));
  py->top = vd_calloc((size_t)n, sizeof(char*));
  py->top_name = vd_malloc(sizeof(int) * (size_t)n);
  py->top_last = vd_malloc(sizeof(int) * (size_t)n);
  if (!py->phys_at || !py->top || !py->top_name || !py->top_last) return nomem(ls, 0);
  int k = 0;
  py->phys_at[k++] = 0;
  for (size_t i = 0; i < len; i++)
    if (text[i] == '\n') py->phys_at[k++] = i + 1;
  py->phys_at[n] = len + 1;  // one past a virtual final newline
  for (int i = 0; i < n; i++) py->top_name[i] = -1;
  return VD_OK;
}

// physical line l (1-based) without its newline
static const char* phys_line(const lsys_py* py, int l, size_t* n) {
  size_t a = py->phys_at[l - 1], b = py->phys_at[l] - 1;
  if (b > py->len) b = py->len;
  if (b > a && py->text[b - 1] == '\r') b--;
  *n = b - a;
  return py->text + a;
}

// ---------------------------------------------------------------------------------------------
// template parameters: Python source between ',' and ')'

int lsys_py_params(vd_lsystem* ls, const char* s, int len, int* pos, int lineno, int col0, expr** params, int max) {
  int i = *pos + 1, np = 0, depth = 0, start = i;
  char q = 0;
  for (; i < len; i++) {
    char c = s[i];
    int k = lsys_quote_step(c, &q);
    if (k) {
      i += k - 1;
      continue;
    }
    if (c == '(' || c == '[' || c == '{') {
      depth++;
      continue;
    }
    if ((c == ')' || c == ']' || c == '}') && depth > 0) {
      depth--;
      continue;
    }
    if (depth == 0 && (c == ',' || c == ')')) {
      int a = start, b = i;
      while (a < b && isspace((unsigned char)s[a])) a++;
      while (b > a && isspace((unsigned char)s[b - 1])) b--;
      if (b > a) {
        if (np == max) {
          vm_error(ls, VD_ERR_LIMIT, lineno, col0 + a, "more than %d module parameters", max);
          return -1;
        }
        int id = str_intern(ls, s + a, b - a);
        if (id < 0) {
          str_intern_error(ls, id, lineno, col0 + a);
          return -1;
        }
        expr* e = vd_arena_alloc(&ls->arena, sizeof(expr));
        if (!e) {
          nomem(ls, lineno);
          return -1;
        }
        memset(e, 0, sizeof *e);
        e->op = E_PYSRC;
        e->line = lineno;
        e->col = col0 + a;
        e->k = (value){V_STR, id};
        params[np++] = e;
      } else if (c == ',') {
        vm_error(ls, VD_ERR_SYNTAX, lineno, col0 + i, "empty module parameter before ','");
        return -1;
      }
      start = i + 1;
      if (c == ')') {
        *pos = i + 1;
        return np;
      }
    }
  }
  vm_error(ls, VD_ERR_SYNTAX, lineno, col0 + *pos, "unclosed '(' in module parameters");
  return -1;
}

expr* lsys_py_expr(vd_lsystem* ls, const char* s, int len, int lineno, int col) {
  // the text up to a comment outside strings, trimmed
  char q = 0;
  int b = len;
  for (int i = 0; i < len; i++) {
    int k = lsys_quote_step(s[i], &q);
    if (k) {
      i += k - 1;
      continue;
    }
    if (s[i] == '#') {
      b = i;
      break;
    }
  }
  int a = 0;
  while (a < b && isspace((unsigned char)s[a])) a++;
  while (b > a && isspace((unsigned char)s[b - 1])) b--;
  if (a == b) {
    vm_error(ls, VD_ERR_SYNTAX, lineno, col, "expected an expression");
    return NULL;
  }
  int id = str_intern(ls, s + a, b - a);
  if (id < 0) {
    str_intern_error(ls, id, lineno, col + a);
    return NULL;
  }
  expr* e = vd_arena_alloc(&ls->arena, sizeof(expr));
  if (!e) {
    nomem(ls, lineno);
    return NULL;
  }
  memset(e, 0, sizeof *e);
  e->op = E_PYSRC;
  e->line = lineno;
  e->col = col + a;
  e->k = (value){V_STR, id};
  return e;
}

// ---------------------------------------------------------------------------------------------
// produce statements

static int is_ident(char c) { return isalnum((unsigned char)c) || c == '_'; }

// the keyword kw at t[i] as a whole word (not an attribute: no '.' before it)
static int keyword_at(const char* t, size_t n, size_t i, const char* kw) {
  size_t k = strlen(kw);
  if (i + k > n || memcmp(t + i, kw, k) != 0) return 0;
  if (i > 0 && (is_ident(t[i - 1]) || t[i - 1] == '.')) return 0;
  return i + k == n || !is_ident(t[i + k]);
}

// register a produce template; its id
static int add_template(vd_lsystem* ls, const tmpl* t) {
  lsys_py* py = ls->py;
  if (!vd_grow((void**)&py->tp, &py->captp, py->ntp + 1, sizeof(tmpl*))) return -1;
  py->tp[py->ntp] = t;
  return py->ntp++;
}

// `fn(id, (p, q), (r,))` for a template: one tuple per module written with parameters
static void put_call(sbuf* b, const vd_lsystem* ls, const char* fn, int id, const tmpl* t) {
  sb_printf(b, "%s(%d", fn, id);
  for (int m = 0; t && m < t->n; m++) {
    const tmod* tm = &t->mod[m];
    if (!tm->nparam) continue;
    sb_puts(b, ", (");
    for (int k = 0; k < tm->nparam; k++) {
      const char* p = ls->str[(int)tm->param[k]->k.n];
      // A(a, **d): d's values in the order module A declares its parameter names, after the k
      // given by position
      if (p[0] == '*' && p[1] == '*') sb_printf(b, "*__vd_kw(%d, %d, %s), ", (int)tm->sym, k, p + 2);
      else sb_printf(b, "%s, ", p);
    }
    sb_puts(b, ")");
  }
  sb_puts(b, ")");
}

// the L-string after a produce keyword: t[a..) up to the end of the line (or to the ')' that
// closes `produce(`), continued over newlines while its parentheses are open. Sets *end.
static size_t lstring_end(const char* t, size_t n, size_t a, int paren) {
  int depth = paren ? 1 : 0;
  char q = 0;
  size_t i = a;
  for (; i < n; i++) {
    char c = t[i];
    int k = lsys_quote_step(c, &q);
    if (k) {
      i += (size_t)k - 1;
      continue;
    }
    if (c == '(') depth++;
    else if (c == ')') {
      depth--;
      if (paren && depth == 0) return i;
    } else if (c == '#' && depth == (paren ? 1 : 0)) {
      // a comment: the L-string ends here (the rest of the line is kept as the comment)
      if (!paren) return i;
    } else if (c == '\n' && depth <= (paren ? 1 : 0) && !paren) {
      return i;
    }
  }
  return i;
}

// Translate Python source t[0..n) starting at file line `line`: produce, nproduce and
// makestring statements become calls; the line count stays the same.
// InLeftContext(A(x) B, params) at t[*i] (L-Py's pattern written as modules): made
// inLeftContext('A(x) B', params), the pattern a string; *i and *copied move after it
static vd_status translate_incontext(vd_lsystem* ls, const char* t, size_t n, size_t* i, size_t* copied, int ln,
                                     int col, sbuf* out) {
  int right = t[*i + 2] == 'R';
  size_t a = *i + (right ? 14 : 13);
  while (a < n && (t[a] == ' ' || t[a] == '\t')) a++;
  if (a >= n || t[a] != '(') return vm_error(ls, VD_ERR_SYNTAX, ln, col, "expected '(' after In%sContext", right ? "Right" : "Left");
  // the closing parenthesis and the last top-level comma before it (the parameters' dict)
  size_t comma = 0, e = a + 1;
  int depth = 0;
  char q = 0;
  for (; e < n; e++) {
    char c = t[e];
    int k = lsys_quote_step(c, &q);
    if (k) {
      e += (size_t)k - 1;
      continue;
    }
    if (c == '(' || c == '[' || c == '{') {
      depth++;
    } else if (c == ']' || c == '}') {
      depth--;
    } else if (c == ')') {
      if (depth-- == 0) break;
    } else if (c == ',' && depth == 0) {
      comma = e;
    }
  }
  if (e >= n) return vm_error(ls, VD_ERR_SYNTAX, ln, col, "unclosed '(' after In%sContext", right ? "Right" : "Left");
  size_t pe = comma ? comma : e;
  sb_put(out, t + *copied, *i - *copied);
  sb_puts(out, right ? "inRightContext('" : "inLeftContext('");
  for (size_t k = a + 1; k < pe; k++) {
    char c = t[k];
    if (c == '\n' || c == '\r') c = ' ';
    if (c == '\'' || c == '\\') sb_put(out, "\\", 1);
    sb_put(out, &c, 1);
  }
  sb_puts(out, "'");
  // ", params)" or ")" as written (newlines kept: the lines stay the file's)
  size_t nl = 0;
  for (size_t k = a + 1; k < pe; k++) nl += t[k] == '\n';
  for (size_t k = 0; k < nl; k++) sb_puts(out, "\n");
  *copied = pe;
  *i = pe;
  return VD_OK;
}

static vd_status translate(vd_lsystem* ls, const char* t, size_t n, int line, int col0, sbuf* out) {
  size_t i = 0, copied = 0;
  char q = 0;
  int tq = 0;  // inside a triple-quoted string
  int ln = line;
  size_t line_start = 0;
  while (i < n) {
    char c = t[i];
    if (c == '\n') {
      ln++;
      line_start = i + 1;
    }
    if (tq) {
      if (c == '\\') {
        i += 2;
        continue;
      }
      if (c == q && i + 2 < n && t[i + 1] == q && t[i + 2] == q) {
        tq = 0;
        q = 0;
        i += 3;
        continue;
      }
      i++;
      continue;
    }
    if (q) {
      if (c == '\\') i++;
      else if (c == q || c == '\n') q = 0;
      i++;
      continue;
    }
    if (c == '#') {
      while (i < n && t[i] != '\n') i++;
      continue;
    }
    if (c == '\'' || c == '"') {
      if (i + 2 < n && t[i + 1] == c && t[i + 2] == c) {
        tq = 1;
        q = c;
        i += 3;
      } else {
        q = c;
        i++;
      }
      continue;
    }
    if (c == 'I' && (keyword_at(t, n, i, "InLeftContext") || keyword_at(t, n, i, "InRightContext"))) {
      vd_status st = translate_incontext(ls, t, n, &i, &copied, ln, col0 + (int)(i - line_start), out);
      if (st) return st;
      continue;
    }
    const char* kw = NULL;
    if (c == 'p' && keyword_at(t, n, i, "produce")) kw = "produce";
    else if (c == 'n' && keyword_at(t, n, i, "nproduce")) kw = "nproduce";
    else if (c == 'm' && keyword_at(t, n, i, "makestring")) kw = "makestring";
    if (!kw) {
      i++;
      continue;
    }
    // copy what precedes the keyword
    sb_put(out, t + copied, i - copied);
    size_t a = i + strlen(kw);
    while (a < n && (t[a] == ' ' || t[a] == '\t')) a++;
    int paren = a < n && t[a] == '(';
    if (paren) a++;
    size_t e = lstring_end(t, n, a, paren);
    if (paren && e >= n)
      return vm_error(ls, VD_ERR_SYNTAX, ln, col0 + (int)(i - line_start), "unclosed '(' after %s", kw);
    // the L-string, newlines made spaces, a lone '*' is the empty string
    size_t len = e - a;
    char* lstr = vd_malloc(len + 1);
    if (!lstr) return nomem(ls, ln);
    int extra_lines = 0;
    for (size_t k = 0; k < len; k++) {
      char ch = t[a + k];
      lstr[k] = ch;
      if (ch == '\n' || ch == '\r') lstr[k] = ' ';
      if (t[a + k] == '\n') extra_lines++;
    }
    lstr[len] = 0;
    size_t s0 = 0, s1 = len;
    while (s0 < s1 && isspace((unsigned char)lstr[s0])) s0++;
    while (s1 > s0 && isspace((unsigned char)lstr[s1 - 1])) s1--;
    const tmpl* tp = NULL;
    if (!(s1 - s0 == 1 && lstr[s0] == '*')) {
      tp = lsys_parse_tmpl_text(ls, lstr, (int)len, ln, col0 + (int)(a - line_start));
      if (!tp) {
        vd_free(lstr, len + 1);
        return ls->err && ls->err->status ? ls->err->status : nomem(ls, ln);
      }
    }
    vd_free(lstr, len + 1);
    int id = add_template(ls, tp);
    if (id < 0) return nomem(ls, ln);
    if (!strcmp(kw, "produce")) {
      sb_puts(out, "return ");
      put_call(out, ls, "__vd_p", id, tp);
    } else if (!strcmp(kw, "nproduce")) {
      put_call(out, ls, "__vd_p", id, tp);
    } else {
      put_call(out, ls, "__vd_mk", id, tp);
    }
    for (int k = 0; k < extra_lines; k++) sb_put(out, "\n", 1);
    ln += extra_lines;
    i = paren ? e + 1 : e;
    copied = i;
  }
  sb_put(out, t + copied, n - copied);
  return out->failed ? nomem(ls, line) : VD_OK;
}

// ---------------------------------------------------------------------------------------------
// top-level statements

// `NAME = ...` (not ==, not NAME.x = ...): the length of NAME, else 0
static int assigned_name(const char* s, int len) {
  int i = 0;
  if (i >= len || !(isalpha((unsigned char)s[i]) || s[i] == '_')) return 0;
  while (i < len && is_ident(s[i])) i++;
  int nl = i;
  while (i < len && (s[i] == ' ' || s[i] == '\t')) i++;
  if (i < len && s[i] == '=' && (i + 1 >= len || s[i + 1] != '=')) return nl;
  return 0;
}

// physical lines first..last of the file as one text (with newlines)
static void raw_lines(const lsys_py* py, int first, int last, sbuf* b) {
  for (int l = first; l <= last && l <= py->nphys; l++) {
    size_t n;
    const char* s = phys_line(py, l, &n);
    sb_put(b, s, n);
    if (l < last) sb_put(b, "\n", 1);
  }
}

vd_status lsys_py_toplevel(vd_lsystem* ls, const lsys_line* lines, int nline, int* li) {
  lsys_py* py = ls->py;
  const lsys_line* first = &lines[*li];
  int j = *li + 1;
  while (j < nline && (lines[j].blank || lines[j].indent > first->indent)) j++;
  // trailing blank lines belong to what follows
  int k = j;
  while (k > *li + 1 && lines[k - 1].blank) k--;
  int a = first->lineno, b = lines[k - 1].lastline;
  sbuf raw = {0}, out = {0};
  raw_lines(py, a, b, &raw);
  if (raw.failed) {
    sb_free(&raw);
    return nomem(ls, a);
  }
  vd_status st = translate(ls, raw.s ? raw.s : "", raw.n, a, 1, &out);
  sb_free(&raw);
  if (st) {
    sb_free(&out);
    return st;
  }
  // split back into lines
  size_t len;
  char* text = sb_take(&out, &len);
  if (!text) return nomem(ls, a);
  const char* p = text;
  for (int l = a; l <= b; l++) {
    const char* e = strchr(p, '\n');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    char* s = vd_malloc(n + 1);
    if (!s) {
      vd_free(text, len + 1);
      return nomem(ls, l);
    }
    memcpy(s, p, n);
    s[n] = 0;
    free_str(py->top[l - 1]);
    py->top[l - 1] = s;
    p = e ? e + 1 : p + n;
  }
  vd_free(text, len + 1);
  // a global assignment at column 0 can be replaced by --set
  int nl = first->indent == 0 ? assigned_name(first->s, first->len) : 0;
  if (nl) {
    int id = str_intern(ls, first->s, nl);
    if (id < 0) return str_intern_error(ls, id, a, 1);
    py->top_name[a - 1] = id;
    py->top_last[a - 1] = first->lastline;
  }
  *li = j;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// functions: rules, axiom, derivation length

static int add_chunk(vd_lsystem* ls, int line, char* src, size_t len) {
  lsys_py* py = ls->py;
  if (!vd_grow((void**)&py->fn, &py->capfn, py->nfn + 1, sizeof(pychunk))) return -1;
  pychunk* c = &py->fn[py->nfn];
  memset(c, 0, sizeof *c);
  // the name after "def " in the source
  const char* n = src + 4;
  size_t k = 0;
  while (k + 1 < sizeof c->name && n[k] && n[k] != '(') {
    c->name[k] = n[k];
    k++;
  }
  c->line = line < 1 ? 1 : line;
  c->src = src;
  c->len = len;
  return py->nfn++;
}

// finish a function's text into a chunk; its index or -1 (error set)
static int finish_chunk(vd_lsystem* ls, sbuf* b, int line) {
  size_t len;
  char* src = sb_take(b, &len);
  if (!src) {
    nomem(ls, line);
    return -1;
  }
  int k = add_chunk(ls, line, src, len);
  if (k < 0) {
    vd_free(src, len + 1);
    nomem(ls, line);
  }
  return k;
}

// the indented block below lines[h] (the header): its logical line range [*from, *to)
static int block_below(const lsys_line* lines, int nline, int h, int* from, int* to) {
  int j = h + 1;
  while (j < nline && lines[j].blank) j++;
  if (j >= nline || lines[j].indent <= lines[h].indent) return 0;
  int k = j;
  while (k < nline && (lines[k].blank || lines[k].indent > lines[h].indent)) k++;
  while (k > j + 1 && lines[k - 1].blank) k--;
  *from = j;
  *to = k;
  return 1;
}

// `def name(args):` followed by the block below lines[h], translated; the chunk index
static int block_function(vd_lsystem* ls, const char* header, const lsys_line* lines, int nline, int h, int* next) {
  int from, to;
  if (!block_below(lines, nline, h, &from, &to)) return -2;
  lsys_py* py = ls->py;
  int a = lines[from].lineno, b = lines[to - 1].lastline;
  sbuf raw = {0}, out = {0};
  raw_lines(py, a, b, &raw);
  sb_puts(&out, header);
  sb_puts(&out, "\n");
  vd_status st = raw.failed ? nomem(ls, a) : translate(ls, raw.s ? raw.s : "", raw.n, a, 1, &out);
  sb_free(&raw);
  if (st) {
    sb_free(&out);
    return -1;
  }
  *next = to;
  return finish_chunk(ls, &out, a - 1);
}

static void put_args(sbuf* b, const char* const* names, const int* lens, int n) {
  for (int i = 0; i < n; i++) {
    if (i) sb_puts(b, ", ");
    sb_put(b, names[i], (size_t)lens[i]);
  }
}

vd_status lsys_py_rule(vd_lsystem* ls, rule* r, const char* const* names, const int* lens, int nnames,
                       const lsys_line* lines, int nline, int* li, int body_at) {
  const lsys_line* h = &lines[*li];
  sbuf b = {0};
  char fname[32];
  snprintf(fname, sizeof fname, "__vd_r%d", ls->py->nfn);
  sb_printf(&b, "def %s(", fname);
  put_args(&b, names, lens, nnames);
  sb_puts(&b, "):");
  int k;
  if (body_at < 0) {
    // pred --> successor: one line
    int id = add_template(ls, r->succ);
    if (id < 0) {
      sb_free(&b);
      return nomem(ls, h->lineno);
    }
    sb_puts(&b, " return ");
    put_call(&b, ls, "__vd_p", id, r->succ);
    k = finish_chunk(ls, &b, h->lineno);
    (*li)++;
  } else if (body_at < h->len && !lsys_line_rest_blank(h, body_at)) {
    // pred : statement on the same line
    sb_puts(&b, "\n ");
    vd_status st = translate(ls, h->s + body_at, (size_t)(h->len - body_at), h->lineno, h->col0 + body_at, &b);
    if (st) {
      sb_free(&b);
      return st;
    }
    k = finish_chunk(ls, &b, h->lineno - 1);
    (*li)++;
  } else {
    size_t len;
    char* header = sb_take(&b, &len);
    if (!header) return nomem(ls, h->lineno);
    int next = *li + 1;
    k = block_function(ls, header, lines, nline, *li, &next);
    vd_free(header, len + 1);
    if (k == -2)
      return vm_error(ls, VD_ERR_SYNTAX, h->lineno, h->col0 + body_at - 1, "expected an indented rule body after ':'");
    *li = next;
  }
  if (k < 0) return ls->err->status ? ls->err->status : nomem(ls, h->lineno);
  r->pyfn = k;
  // InLeftContext / InRightContext (translated to inLeftContext / inRightContext) read where the
  // rule's contexts ended: the general matcher records it
  r->incontext = strstr(ls->py->fn[k].src, "nLeftContext(") || strstr(ls->py->fn[k].src, "nRightContext(");
  return VD_OK;
}

vd_status lsys_py_axiom(vd_lsystem* ls, const tmpl* t, const lsys_line* lines, int nline, int* li) {
  lsys_py* py = ls->py;
  py->has_axiom = 1;
  const lsys_line* h = &lines[*li];
  int k;
  if (t) {
    int id = add_template(ls, t);
    if (id < 0) return nomem(ls, h->lineno);
    sbuf b = {0};
    sb_puts(&b, "def __vd_axiom(): return ");
    put_call(&b, ls, "__vd_p", id, t);
    k = finish_chunk(ls, &b, h->lineno);
    (*li)++;
  } else {
    int next = *li + 1;
    k = block_function(ls, "def __vd_axiom():", lines, nline, *li, &next);
    if (k == -2) {
      // an empty axiom: the derivation starts from the empty string
      (*li)++;
      return VD_OK;
    }
    *li = next;
  }
  if (k < 0) return ls->err->status ? ls->err->status : nomem(ls, h->lineno);
  py->fn_axiom = k;
  return VD_OK;
}

vd_status lsys_py_dlength(vd_lsystem* ls, const char* s, int len, int lineno) {
  sbuf b = {0};
  sb_puts(&b, "def __vd_dlen(): return (\n");
  sb_put(&b, s, (size_t)len);
  sb_puts(&b, "\n)");
  int k = finish_chunk(ls, &b, lineno - 1);
  if (k < 0) return ls->err->status;
  ls->py->fn_dlen = k;
  return VD_OK;
}

int lsys_py_cond(vd_lsystem* ls, const char* name, int nlen, const char* s, int len, int lineno) {
  if (!ls->py->text) {
    // a pattern read at run time (InLeftContext): its functions are compiled already
    vm_error(ls, VD_ERR_UNSUPPORTED, lineno, 0, "unsupported: a condition on '%.*s' in an InLeftContext / InRightContext pattern",
             nlen, name);
    return -1;
  }
  sbuf b = {0};
  sb_printf(&b, "def __vd_c%d(", ls->py->nfn);
  sb_put(&b, name, (size_t)nlen);
  sb_puts(&b, "): return (\n");
  sb_put(&b, s, (size_t)len);
  sb_puts(&b, "\n)");
  return finish_chunk(ls, &b, lineno - 1);
}

vd_status lsys_py_parse_end(vd_lsystem* ls, size_t init_at) {
  lsys_py* py = ls->py;
  // no Axiom: the string is empty (L-Py: a rule set, or Python code alone); the derivation then
  // returns at once
  if (init_at < py->len) {
    // the trailer, from the marker line on
    int line = 1;
    for (size_t i = 0; i < init_at; i++)
      if (py->text[i] == '\n') line++;
    size_t n = py->len - init_at;
    py->trailer = vd_malloc(n + 1);
    if (!py->trailer) return nomem(ls, line);
    memcpy(py->trailer, py->text + init_at, n);
    py->trailer[n] = 0;
    py->trailer_line = line;
  }
  vd_status st = lsys_py_compile(ls);
  // the text belongs to the caller: forget it
  py->text = NULL;
  py->len = 0;
  return st;
}

// is lines->s[from..] blank (only spaces or a comment)?
int lsys_line_rest_blank(const lsys_line* l, int from) {
  for (int i = from; i < l->len; i++) {
    if (l->s[i] == '#') return 1;
    if (!isspace((unsigned char)l->s[i])) return 0;
  }
  return 1;
}
