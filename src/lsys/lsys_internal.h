// SPDX-License-Identifier: MIT
// Private structures of the lsys module: symbols, values, the parsed program (expressions,
// statements, successor templates, rule patterns) and the interpreter state.
#ifndef VERDANT_LSYS_INTERNAL_H
#define VERDANT_LSYS_INTERNAL_H

#include "verdant/lsys.h"

// ---------------------------------------------------------------------------------------------
// values of the Python subset

typedef enum vtype {
  V_NONE = 0,
  V_BOOL,
  V_INT,      // integral number (kept as a double, printed without ".0")
  V_FLOAT,
  V_STR,      // n = string id in the lsystem's string table
  V_FUNC,     // n = user function index
  V_BUILTIN,  // n = builtin id
  V_NS,       // n = namespace id (NS_MATH, NS_RANDOM)
  V_UNDEF,    // a global slot that has no value yet
  V_OBJ       // n = a boxed Python object handle (the Python engine's object table)
} vtype;

typedef struct value {
  int t;     // vtype
  double n;  // number, or an id for strings, functions, builtins, namespaces
} value;

enum { NS_MATH = 1, NS_RANDOM = 2 };

static inline value v_num(double x) {
  value v = {V_FLOAT, x};
  return v;
}
static inline value v_int(double x) {
  value v = {V_INT, x};
  return v;
}
static inline int v_isnum(value v) { return v.t == V_INT || v.t == V_FLOAT || v.t == V_BOOL; }

// ---------------------------------------------------------------------------------------------
// program: expressions and statements (allocated in the lsystem's arena)

typedef enum eop {
  E_CONST,     // value k
  E_LOCAL,     // frame slot
  E_GLOBAL,    // global slot
  E_NEG, E_POS, E_NOT,
  E_ADD, E_SUB, E_MUL, E_DIV, E_FLOORDIV, E_MOD, E_POW,
  E_AND, E_OR,
  E_CMP,       // chained comparison: args are operands, cmp[] the operators
  E_COND,      // a if b else c: a = then, b = cond, c = else
  E_CALL,      // fn(args): a = callee expression
  E_BUILTIN,   // direct builtin call: slot = builtin id
  E_ATTR,      // namespace attribute (math.pi): k holds the resolved value
  E_PYSRC      // Python engine: source text of an expression, k = its string id (V_STR)
} eop;

enum { CMP_LT, CMP_LE, CMP_GT, CMP_GE, CMP_EQ, CMP_NE };

typedef struct expr {
  int op;       // eop
  int line, col;
  int slot;     // local/global slot, builtin id
  value k;      // constant
  struct expr *a, *b, *c;
  int nargs;
  struct expr** args;
  int* cmp;     // comparison operators (nargs - 1)
} expr;

// A module of a successor template: symbol and parameter expressions.
typedef struct tmod {
  int32_t sym;
  int nparam;
  expr** param;
  int line, col;
} tmod;

// An L-string template (successor of a rule, argument of produce, the axiom).
typedef struct tmpl {
  int n;
  tmod* mod;
  int has_cut;  // contains %
} tmpl;

typedef enum sop {
  S_EXPR, S_ASSIGN, S_AUGASSIGN, S_IF, S_FOR, S_WHILE, S_PRODUCE, S_NPRODUCE, S_RETURN,
  S_PASS, S_BREAK, S_CONTINUE, S_PRINT, S_ASSERT, S_GLOBAL
} sop;

typedef struct stmt {
  int op;          // sop
  int line, col;
  int is_global;   // assignment target is a global slot
  int slot;        // assignment / loop variable slot
  int aug;         // augmented operator (eop)
  expr* e;         // value, condition, returned value, assert condition
  expr* e2;        // assert message; range stop
  expr* e3;        // range step
  tmpl* t;         // produce template
  struct stmt* body;   // then-block / loop body (linked list)
  struct stmt* orelse; // else-block (elif chains are nested ifs)
  int nargs;       // print arguments
  expr** args;
  struct stmt* next;
} stmt;

// A user function (def).
typedef struct func {
  char name[64];
  int nparam;
  int nlocal;
  stmt* body;
  int line;
} func;

// ---------------------------------------------------------------------------------------------
// rules

// One module of a predecessor or context pattern. sym VD_SYM_SB/EB mark explicit brackets.
typedef struct pmod {
  int32_t sym;
  int nparam;
  int* slot;      // binding slot per parameter, -1 when the parameter is a constant
  value* cval;    // constant value per parameter (when slot is -1)
  int line, col;
} pmod;

enum { SEC_PRODUCTION = 0, SEC_DECOMPOSITION = 1, SEC_INTERPRETATION = 2, SEC_COUNT = 3 };

typedef struct rule {
  int section;    // SEC_*
  int group;      // rule group (0 = always active)
  int npred, nleft, nright;
  pmod* pred;     // strict predecessor (npred modules)
  pmod* left;     // left context in reading order (nleft)
  pmod* right;    // right context (nright)
  int nlocal;     // frame size (pattern variables + body locals)
  tmpl* succ;     // one-line successor (NULL when the rule has a body)
  stmt* body;     // rule body
  int line;
  int pyfn;       // Python engine: index of the rule's function (lsys_py.c), -1 native
} rule;

// ---------------------------------------------------------------------------------------------
// the lsystem

typedef struct symtab {
  int n, cap;         // count, capacity of name
  int cap_declared;   // capacity of declared (grown separately: one can fail after the other)
  char** name;        // symbol names (owned)
  int* hash_slot;     // open addressing table of symbol ids (hcap), -1 empty
  int hcap;
  int maxlen;         // longest predefined or declared name (for longest match)
  unsigned char* declared;  // 1 when the name takes part in longest-match tokenising (n)
} symtab;

typedef struct global_def {
  char* name;
  value init_override;  // value from --set
  int has_override;
} global_def;

// A logical line of the file: physical lines joined while brackets are open (parser, Python engine).
typedef struct lsys_line {
  const char* s;  // text without the indentation
  int len;
  int lineno;     // 1-based physical line where it starts
  int col0;       // 1-based column of s[0]
  int indent;     // indentation width (tabs to multiples of 8)
  int blank;      // only whitespace or a comment
  int lastline;   // physical line where it ends
} lsys_line;

// The engines that run a file's Python (vd_lsys_engine without AUTO).
typedef struct lsys_py lsys_py;

typedef struct toplevel {
  stmt* body;  // top-level statements in file order
} toplevel;

struct vd_lsystem {
  char file[256];
  lsys_py* py;             // Python engine state (NULL for the native engine)
  vd_arena arena;          // all parse structures
  symtab syms;
  // strings
  int nstr, capstr;
  char** str;
  int* str_slot;           // open addressing index of string ids (str_hcap), -1 empty
  int str_hcap;
  int64_t str_bytes;       // bytes of all strings (limit LSYS_MAX_STR_BYTES)
  // globals
  int nglobal, capglobal, capgval;  // count, capacities of gdef and gval
  global_def* gdef;        // names and overrides (nglobal)
  value* gval;             // current values (nglobal)
  // functions
  int nfunc, capfunc;
  func** funcs;
  // program
  stmt* top;               // top-level statements
  stmt* top_tail;
  tmpl* axiom;             // line axiom (or NULL)
  stmt* axiom_body;        // functional axiom (or NULL)
  int axiom_nlocal;
  int engine;              // VD_LSYS_NATIVE or VD_LSYS_PYTHON
  expr* derivation_length; // NULL = 1
  int max_depth[SEC_COUNT];  // maximum depth for decomposition / interpretation
  int nrule, caprule;
  rule** rules;
  // rules indexed by predecessor's first symbol, per section: ruleidx[sec][sym] -> list
  int* rule_first[SEC_COUNT];   // start index into rule_list (nsym + 1), built at derive time
  int* rule_list[SEC_COUNT];
  int rule_index_nsym;
  int has_context[SEC_COUNT];
  unsigned char* ignored;  // 1 for symbols skipped in context matching (nsym)
  int ignore_mode;         // 0 none, 1 ignore list, 2 consider list
  int32_t* ignore_syms;
  int nignore_syms;
  // labels declared by the file
  int nlabel;
  int* label_id;
  char** label_name;
  // scalars from the INITIALISATION block: global slot and value
  int nscalar;
  int* scalar_slot;
  value* scalar_val;
  // hooks (user function index or -1)
  int hook_start, hook_end, hook_starteach, hook_endeach;
  int has_cut;
  // runtime
  vd_rng rng;
  int current_group;
  int iteration;
  int stop_requested;
  int call_depth;
  int64_t max_ops;         // interpreter work allowed in this run (loop iterations + calls)
  int64_t ops_left;        // what is left of it
  vd_error* err;           // error sink during a run
};

// ---------------------------------------------------------------------------------------------
// internal functions

// symbol table
int sym_intern(vd_lsystem* ls, const char* name, int len, int declared);
int sym_find(const vd_lsystem* ls, const char* name, int len);
#define LSYS_MAX_STR_BYTES (64 << 20)  // all strings of an lsystem together (bytes)
// Id of a string, added when new; -1 out of memory, -2 over LSYS_MAX_STR_BYTES.
int str_intern(vd_lsystem* ls, const char* s, int len);
// Report a failed str_intern (its negative result) as out of memory or limit; returns the status.
vd_status str_intern_error(vd_lsystem* ls, int id, int line, int col);
double lsys_box_str(int id);
int lsys_unbox_str(double v);
// Python engine objects in L-strings: NaN-boxed handles (slot id and epoch) into lsys_py's table.
double lsys_box_obj(uint32_t id, unsigned epoch);
int lsys_unbox_obj(double v, uint32_t* id, unsigned* epoch);
int global_slot(vd_lsystem* ls, const char* name, int len, int create);

// lstring building (int64 capacities, max_modules limit)
int lstr_reserve(vd_lstring* s, int64_t nmod, int64_t nval);
void lstr_clear(vd_lstring* s);
int lstr_enable_src(vd_lstring* s);

// parser
vd_status lsys_parse_file(vd_lsystem* ls, const char* text, size_t len);
// parse text with one engine (VD_LSYS_NATIVE or VD_LSYS_PYTHON) into a new lsystem
vd_status lsys_parse_with(const char* text, size_t len, const char* name, int engine, vd_lsystem** out,
                          vd_error* err);
expr* lsys_parse_expr_text(vd_lsystem* ls, const char* text, int len, int line, int col);
tmpl* lsys_parse_tmpl_text(vd_lsystem* ls, const char* text, int len, int line, int col);

// interpreter
#define LSYS_DEFAULT_MAX_OPS 1000000000LL  // vd_lsys_def.max_ops when unset
// Start a run with a budget of max_ops interpreter operations (<= 0: the default).
void vm_budget(vd_lsystem* ls, int64_t max_ops);
// Take n operations from the run's budget (a rewriting pass costs one per module it reads);
// sets the error and returns its status when the budget is spent, else VD_OK.
vd_status vm_spend(vd_lsystem* ls, int64_t n);
typedef struct vm_out {
  vd_lstring* s;       // where produce writes
  int64_t src;         // source index recorded on produced modules (when s->src)
  int64_t max_modules;
  int produced;        // a produce ran (body finished)
  int nproduced;       // an nproduce ran
} vm_out;

vd_status vm_exec_block(vd_lsystem* ls, stmt* s, value* frame, vm_out* out, int* returned,
                        value* retval);
vd_status vm_eval(vd_lsystem* ls, const expr* e, value* frame, value* out);
vd_status vm_emit_tmpl(vd_lsystem* ls, const tmpl* t, value* frame, vm_out* out);
vd_status vm_call_func(vd_lsystem* ls, int fi, int nargs, const value* args, value* ret, int line,
                       int col);
vd_status vm_error(vd_lsystem* ls, vd_status st, int line, int col, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
void value_repr(const vd_lsystem* ls, value v, char* buf, size_t cap);
int builtin_find(const char* name, int len);
int builtin_in_ns(int ns, const char* name, int len);
value ns_constant(int ns, const char* name, int len, int* found);
int value_truthy(value v);
vd_status value_to_param(vd_lsystem* ls, value v, double* out, int line, int col);
value param_to_value(double d);

// ---------------------------------------------------------------------------------------------
// the Python engine (lsys_py.c: CPython bridge and run time; lsys_pysrc.c: the file's Python
// source). Only these two files include Python.h. Every function below is a no-op or an
// error for the native engine (ls->py == NULL).

// parse time: the parser hands over the Python parts of the file
vd_status lsys_py_parse_begin(vd_lsystem* ls, const char* text, size_t len);
vd_status lsys_py_parse_end(vd_lsystem* ls, size_t init_at);
// the parameters of a template module, s[*pos] = '(': each an E_PYSRC expression (at most
// max) into params; *pos moves after the ')'. Returns the count, or -1 with the error set.
int lsys_py_params(vd_lsystem* ls, const char* s, int len, int* pos, int lineno, int col0,
                   expr** params, int max);
// a top-level statement (with its indented block) starting at lines[*li]; advances *li
vd_status lsys_py_toplevel(vd_lsystem* ls, const lsys_line* lines, int nline, int* li);
// the body of rule r whose header is lines[*li]: successor r->succ, or the Python after the
// header's ':' (body_at) and the indented lines below; names: the pattern variables in slot order
vd_status lsys_py_rule(vd_lsystem* ls, rule* r, const char* const* names, const int* lens,
                       int nnames, const lsys_line* lines, int nline, int* li, int body_at);
// the axiom: a template, or the indented block below lines[*li] (advances *li)
vd_status lsys_py_axiom(vd_lsystem* ls, const tmpl* t, const lsys_line* lines, int nline, int* li);
// `derivation length:` text
vd_status lsys_py_dlength(vd_lsystem* ls, const char* s, int len, int lineno);

// run time
void lsys_py_free(vd_lsystem* ls);
// take the engine (process-wide lock and the GIL) for ls; lsys_py_leave gives it back
void lsys_py_enter(vd_lsystem* ls);
void lsys_py_leave(vd_lsystem* ls);
// run the prologue (trailer, top-level code) in a fresh namespace, random seeded with seed
vd_status lsys_py_run_toplevel(vd_lsystem* ls, uint64_t seed);
vd_status lsys_py_dlength_eval(vd_lsystem* ls, int* steps);
vd_status lsys_py_emit_axiom(vd_lsystem* ls, vm_out* out);
vd_status lsys_py_apply_rule(vd_lsystem* ls, const rule* r, const value* frame, vm_out* out);
// call hook name (Start, End, StartEach, EndEach, ...) with the arguments it declares; s is
// the current string (an End hook may return a new one). Missing hooks are fine.
vd_status lsys_py_hook(vd_lsystem* ls, const char* name, vd_lstring* s, vd_lstring* scratch, int64_t max_modules);
// drop objects that no module of s refers to any more (after a step)
void lsys_py_gc(vd_lsystem* ls, const vd_lstring* s);
// release every object (a new derivation starts)
void lsys_py_reset_objects(vd_lsystem* ls);
vd_status lsys_py_set_global(vd_lsystem* ls, const char* name, const char* text);
vd_status lsys_py_get_global(vd_lsystem* ls, const char* name, double* out);
// repr() of an object parameter into buf (cap bytes); "None" for a stale handle
void lsys_py_repr(const vd_lsystem* ls, double v, char* buf, size_t cap);

#endif
