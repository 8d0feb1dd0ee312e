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
  V_OBJ,      // n = a boxed Python object handle (the Python engine's object table)
  V_LIST,     // n = a list bound by the match of a rule (*args, x(...) variables): ls->mlist[n]
  V_DICT      // n = a dict bound by the match (**kwds): ls->mlist[n], keys and values alternate
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
  int drop;     // starts with `*`: L-Py discards the whole production (deletes the module)
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
  int discard_wrapped;  // decorated with @enable_string_discard (L-Py's __lpyfuture__)
  int nparam;
  int nlocal;
  stmt* body;
  int line;
} func;

// ---------------------------------------------------------------------------------------------
// rules

// Kinds of pattern elements (L-Py's pattern modules).
enum {
  PK_MOD = 0,  // a module: same symbol and parameter count (brackets included)
  PK_ANY,      // `*`: any module; `*(name, x, ...)` binds the name and the parameters
  PK_REP,      // `x(pattern [, min [, max]])`: repetition of a sub-pattern
  PK_OR,       // `or(pattern, pattern, ...)`: the first alternative that matches
  PK_NONE,     // `None` (inside or()): matches nothing
};

struct pstr;

// One element of a predecessor or context pattern.
typedef struct pmod {
  int32_t sym;     // PK_MOD: symbol (VD_SYM_SB / VD_SYM_EB for explicit brackets)
  int nparam;      // PK_MOD: parameters; PK_ANY: parameters after the name
  int* slot;       // binding slot per parameter, -1 when the parameter is a constant
  value* cval;     // constant value per parameter (when slot is -1)
  int kind;        // PK_*
  int exact;       // `=]`: the closing bracket must come next (no skip to the branch end)
  struct pext* x;  // PK_ANY with a name, PK_REP, PK_OR: the rest (NULL otherwise)
  int line, col;
} pmod;

// A condition on a pattern parameter (`*(n in 'AB', x > 0)`, L-Py's value constraints): a native
// expression over the rule's frame, or (Python engine) the index of a one-argument function.
typedef struct pcond {
  expr* e;   // native: the condition, its variable bound in the frame (NULL: no condition)
  int pyfn;  // Python engine: chunk index of `lambda name: condition`, -1 none
} pcond;

// What a few pattern elements need beyond a module.
typedef struct pext {
  int args_slot;   // PK_MOD / PK_ANY: slot of a trailing `*args` (a list), -1 none
  int kwds_slot;   // slot of a trailing `**kwds` (a dict of the declared parameter names), -1 none
  int has_name;    // PK_ANY: written with parameters, the first one is the module name
  int name_slot;   // PK_ANY: slot of the name, -1 when the name is a constant (name_val)
  value name_val;  // PK_ANY: constant name (a string)
  struct pstr* sub;  // PK_REP: the repeated pattern (sub[0]); PK_OR: the alternatives
  int nsub;
  int rmin, rmax;  // PK_REP: repetitions allowed
  pcond* cond;     // conditions per parameter (nparam), NULL when none has one
  pcond name_cond; // PK_ANY: condition on the name (meaningful only when cond is set)
} pext;

// A pattern: a string of pattern elements.
typedef struct pstr {
  int n;
  pmod* m;
} pstr;

enum { SEC_PRODUCTION = 0, SEC_DECOMPOSITION = 1, SEC_INTERPRETATION = 2, SEC_COUNT = 3 };

typedef struct rule {
  // what the rewriting loop reads first
  pstr pred;      // strict predecessor
  pstr left;      // left context `<`, in reading order
  pstr right;     // right context `>`
  int simple;     // only plain modules, no new contexts, no bracket outside the right context:
                  // the fast matcher applies (axial-tree matching, forward)
  int nlocal;     // frame size (pattern variables + body locals)
  tmpl* succ;     // one-line successor (NULL when the rule has a body)
  stmt* body;     // rule body
  int filter;     // consider/ignore filter in force where the rule was written (-1: none)
  // the rest
  pstr nleft;     // new left context `<<` (forward derivation only)
  pstr nright;    // new right context `>>` (backward derivation only)
  int section;    // SEC_*
  int group;      // rule group (0 = always active)
  int is_static;  // -static-> / @static: L-Py evaluates the successor once
  int incontext;  // its body calls InLeftContext / InRightContext (Python engine): general matcher
  int line;
  int pyfn;       // Python engine: index of the rule's function (lsys_py.c), -1 native
} rule;

// A consider:/ignore: filter: the symbols listed, and whether they are ignored or the only
// ones considered (brackets are always considered).
typedef struct cfilter {
  int mode;          // 1 ignore the listed symbols, 2 consider only them
  int32_t* syms;     // (nsyms)
  int nsyms;
  unsigned char* ignored;  // per symbol, built at derive time (rule_index_nsym)
} cfilter;

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
  int* canon;         // the symbol a name stands for: itself, or the short name of an alias (n)
  int cap_canon;      // capacity of canon
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

// Where the rule being applied matched (L-Py's LstringMatcher): InLeftContext / InRightContext
// in its body read on from there (Python engine).
typedef struct lsys_cur {
  const struct lsys_mctx* M;  // NULL outside a rule's body
  const rule* r;
  int64_t left;        // where the left context ended (the predecessor's start without one)
  int64_t right;       // where the right context ended (after the predecessor without one)
  int64_t rlast;       // last module matched on the right
} lsys_cur;

// A pattern of InLeftContext / InRightContext, parsed once: its text (string id), the pattern
// and its variables' names (string ids, in slot order).
typedef struct lsys_cpat {
  int sid;
  pstr p;
  int nvar;
  int* var;  // (nvar, arena)
} lsys_cpat;

struct vd_lsystem {  // NOLINT(clang-analyzer-optin.performance.Padding): fields grouped by meaning; one per model
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
  int axiom_line;          // line of the Axiom: keyword (0: the file has none)
  char* auto_text;         // the file's text when VD_LSYS_AUTO chose native (vd_lsys_fallback), else NULL
  size_t auto_len;
  expr* derivation_length; // NULL = 1
  expr* max_depth_expr[SEC_COUNT];  // `maximum depth:` of decomposition / interpretation (NULL = 1)
  int max_depth[SEC_COUNT];  // its value in this run
  int nrule, caprule;
  rule** rules;
  // the rules that apply, per section, indexed by the predecessor's first symbol (last symbol
  // when deriving backward): rule_list[rule_first[sym]] .. rule_list[rule_first[sym + 1] - 1],
  // rules of the active group first, then those of group 0, each in file order; `*` rules are
  // in every list. Rebuilt when the group, the direction or the symbol count changes.
  int* rule_first[SEC_COUNT];   // (rule_index_nsym + 1)
  int* rule_list[SEC_COUNT];    // (rule_list_cap[sec])
  int rule_list_cap[SEC_COUNT];
  int rule_index_nsym;
  int rule_index_group, rule_index_dir;  // what the index was built for
  int has_context[SEC_COUNT];   // some rule of the index reads a context (brackets matched)
  int has_generic[SEC_COUNT];   // some rule of the index needs the general matcher
  int has_query[SEC_COUNT];     // some rule of the index has a query module (?P ...) in a pattern
  int nfilter, capfilter;
  cfilter* filters;             // consider/ignore filters (nfilter)
  unsigned char* no_filter;     // all zero: what a rule without filter ignores (ign_nsym + 1)
  int ign_nsym;                 // symbols covered by the ignored tables
  int cur_filter;               // filter in force while parsing (-1 none)
  // L-Py options (INITIALISATION block or run time)
  int opt_string_matching;      // 0 as string, 1 as axial tree (default)
  int opt_early_return;         // 1: the derivation ends after a step where no rule matched
  int opt_module_matching;      // 0 simple, 1 with *args, 2 with value constraints (default)
  int opt_axiom_decomposition;  // 1: the axiom is decomposed before the first step
  int has_bases;                // a module declaration names base modules (inheritance)
  int opt_inherit;              // 'Module inheritance' on: a pattern module matches its subclasses
  // base modules declared with `module B : base = A` / `base = (A, C)`: (sym, base) pairs
  int nbase, capbase;
  struct mbase {
    int32_t sym, base;
  }* mbase;
  double turtle_angle;          // context.turtle.setAngleIncrement(a): the turtle's default angle (degrees)
  int has_turtle_angle;         // the file set it
  // parameter names declared with `module A(x, t)` (**kwds patterns): symbol, names (string ids)
  int npdecl, cappdecl;
  struct pdecl {
    int32_t sym;
    int n;
    int* name;  // string ids (arena)
  }* pdecl;
  // lists and dicts bound by one rule match (*args, **kwds, x(...) variables): valid while the
  // rule runs; mlist[i] = the values mval[at .. at + n)
  struct mlist {
    int at, n;
  }* mlist;
  int nmlist, capmlist;
  value* mval;
  int nmval, capmval;
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
  int backward;            // derive right to left (backward()); new right contexts apply
  int frame_displayed;     // the step is the last one, or any step of an animation (L-Py draws a
                           // frame then); frameDisplay(False) clears it
  int animating;           // vd_lsys_animate runs (isAnimationEnabled())
  int discard_requested;   // DiscardNewString(): the step's result is dropped
  lsys_cur cur;            // the rule being applied (Python engine: InLeftContext, InRightContext)
  lsys_cpat* cpat;         // InLeftContext / InRightContext patterns parsed so far (ncpat)
  int ncpat, capcpat;
  int call_depth;
  int steps_done;          // derivation steps taken since the axiom (vd_lsys_derive_step)
  int64_t max_ops;         // interpreter work allowed in this run (loop iterations + calls)
  int64_t ops_left;        // what is left of it
  vd_error* err;           // error sink during a run
  struct vm_out* cur_out;  // where produce writes in the rule body (or hook) being run, NULL outside
  // tracing a turtle error or warning back to the file (lsys_trace_lines)
  vd_lsys_def last_def;    // the settings of the last derivation
  int has_last_def;        // a derivation ran
  int track_lines;         // keep the file line of every module (vd_lstring.line)
  int quiet;               // print() says nothing (the run is a repeat)
};

// ---------------------------------------------------------------------------------------------
// internal functions

// symbol table
int sym_intern(vd_lsystem* ls, const char* name, int len, int declared);
int sym_find(const vd_lsystem* ls, const char* name, int len);
// Register `alias` (a long name such as "Left") as another spelling of symbol `canon`.
int sym_alias(vd_lsystem* ls, const char* alias, int canon);
// The symbol a name id stands for (aliases resolve to their short name).
static inline int sym_canon(const vd_lsystem* ls, int id) { return ls->syms.canon[id]; }

// Python quotes while scanning source one character c at a time (*q: the open quote, 0 outside a
// string): 0 when c is code, 1 when c opens, closes or is inside a string, 2 when c is a
// backslash inside one (the next character is escaped: skip it). Use:
//   int k = lsys_quote_step(c, &q); if (k) { i += k - 1; continue; }
static inline int lsys_quote_step(char c, char* q) {
  if (*q) {
    if (c == '\\') return 2;
    if (c == *q) *q = 0;
    return 1;
  }
  if (c == '\'' || c == '"') {
    *q = c;
    return 1;
  }
  return 0;
}
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
// Give s a line array (file line of the rule or axiom of each module); 0 out of memory.
int lstr_enable_line(vd_lstring* s);
// Copy src into dst (dst's arrays reused; src indices copied when src has them); 0 out of memory.
int lsys_lstring_copy(vd_lstring* dst, const vd_lstring* src);

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

// ---------------------------------------------------------------------------------------------
// rewriting (lsys_rewrite.c) and matching (lsys_match.c)

// What one rule match reads: the string rewritten, its bracket match, the string being written
// (for new contexts), the direction and the per-filter tables of ignored symbols.
typedef struct lsys_mctx {
  vd_lsystem* ls;
  const vd_lstring* src;        // the string read
  const int64_t* match;         // Nullable: bracket match of src
  const vd_lstring* dest;       // the string written so far (back to front when backward)
  int backward;                 // right-to-left pass: predecessors are matched ending at i
  int string_mode;              // L-Py's "String matching: As String" option
  unsigned char* const* ignored;  // [filter + 1]: ignored symbols of each filter ([0]: none)
  int nsym;                     // size of each ignored table
} lsys_mctx;

// Scratch of the recursive rewriting, one per depth.
typedef struct lsys_level {
  vd_lstring buf;      // what the rule at this depth produced
  int64_t* match;      // bracket match of the string read at this depth
  int64_t match_cap;
} lsys_level;

// Scratch of the passes of one run.
typedef struct lsys_pass {
  int64_t* match;         // bracket match of the string read by a step
  int64_t match_cap;
  int64_t max_modules;    // largest string allowed
  lsys_level* lvl;        // recursion scratch (nlvl)
  int nlvl, caplvl;
  unsigned char** ignored;  // per-filter tables handed to the matcher (cap_ignored)
  int cap_ignored;
  vd_lstring saved;       // the string at the end of the previous step (DiscardNewString)
  int64_t identity_bit;   // LSYS_SRC_IDENTITY in a query pass: marks modules copied unchanged
  vd_lstring geo;         // the interpreted string of a query pass (with source indices)
} lsys_pass;

// (Re)build the rule index for a group and a direction (no-op when up to date).
vd_status lsys_build_index(vd_lsystem* ls, int group, int backward);
// 1 when the section has no rule in the current index.
int lsys_section_empty(const vd_lsystem* ls, int sec);
// Bracket match of s: for each '[' its ']' (s->n when unclosed), for each ']' its '[' (-1).
vd_status lsys_bracket_match(const vd_lstring* s, int64_t** out, int64_t* cap);
// Append module i of in to out with source index src.
vd_status lsys_copy_module(vd_lsystem* ls, const vd_lstring* in, int64_t i, vd_lstring* out, int64_t src,
                           int64_t max_modules);
// Reverse the order of the modules [a, s->n) of s.
void lsys_reverse_tail(vd_lstring* s, int64_t a);
// One parallel step of a section over in, into out (cleared first); *matched = a rule applied.
vd_status lsys_step(vd_lsystem* ls, int sec, const vd_lstring* in, vd_lstring* out, lsys_pass* P, int* matched);
// L-Py's recursive rewriting (decomposition, interpretation) of in, appended to out: each
// production is rewritten again on its own, up to depth levels.
vd_status lsys_recursive(vd_lsystem* ls, int sec, const vd_lstring* in, vd_lstring* out, lsys_pass* P, int depth,
                         int level, int* matched);
// Free a run's scratch.
void lsys_pass_free(lsys_pass* P);
// A new list (or dict) of n values for the match being made: its id, -1 out of memory; its
// values at ls->mval[ls->mlist[id].at] (to be filled).
int lsys_mlist_new(vd_lsystem* ls, int n);
// Run the turtle over s without keeping geometry, writing the turtle's position and frame into
// the parameters of the query modules ?P ?H ?U ?L ?R of s.
// Frames of the query modules that take Vector3 objects (Python engine: ?F, ?P ... without
// parameters or with an object): 13 values per module, its index in the string then the
// turtle's position, heading, up and left.
typedef struct lsys_qframes {
  double* v;
  int n, cap;  // modules recorded, capacity (modules)
} lsys_qframes;
// qf Nullable: without it such modules are refused
vd_status lsys_turtle_query(const vd_lsystem* ls, vd_lstring* s, vd_error* err, lsys_qframes* qf);
#define LSYS_SRC_IDENTITY (INT64_C(1) << 62)  // on a source index: the module was copied unchanged
// File lines of the modules idx[0..n) of s, a string the last derivation made (interpreted or
// not): the derivation runs again keeping lines; 1 when s is that string (lines[k] is 0 where
// unknown), 0 otherwise.
int lsys_trace_lines(vd_lsystem* ls, const vd_lstring* s, const int64_t* idx, int n, int* lines);
// Apply an L-Py option by name (Early return when no matching, String matching, Module matching,
// Module inheritance, Axiom decomposition); refuses what the engines cannot honour.
vd_status lsys_set_option(vd_lsystem* ls, const char* name, int nlen, long v, int line);
// The turtle's default angle set by the file (context.turtle.setAngleIncrement); 0 when not set.
int lsys_turtle_angle(const vd_lsystem* ls, double* angle);
// The file name of an lsystem ("" when parsed from text without one).
const char* lsys_file(const vd_lsystem* ls);
// Match rule r at module i (general matcher); *first, *end = the predecessor's modules.
// With cur (nullable), where the contexts ended (InLeftContext / InRightContext go on from there).
int lsys_rule_match(const lsys_mctx* M, const rule* r, int64_t i, value* frame, int64_t* first, int64_t* end,
                    lsys_cur* cur);
// InLeftContext (right = 0) / InRightContext (right = 1) in the body of the rule being applied
// (ls->cur): match p from where the last context ended, binding its variables into frame; on a
// match the position moves on. 1 or 0; -1 on an error (ls->err set).
int lsys_context_match(vd_lsystem* ls, int right, const pstr* p, value* frame);
// the pattern text s[0..len) of InLeftContext / InRightContext, parsed once per lsystem; NULL
// with the error set (line: the rule's)
const lsys_cpat* lsys_context_pattern(vd_lsystem* ls, const char* s, int len, int line);

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
// does the pattern condition c hold on v (bound in frame)? 1 or 0; -1 on an error (ls->err set)
int lsys_cond_holds(vd_lsystem* ls, const pcond* c, value v, value* frame);
vd_status value_to_param(vd_lsystem* ls, value v, double* out, int line, int col);
value param_to_value(double d);

// ---------------------------------------------------------------------------------------------
// the Python engine (py/lsys_py.c: CPython bridge and run time; py/lsys_pysrc.c: the file's Python
// source). Only these two files include Python.h. Every function below is a no-op or an
// error for the native engine (ls->py == NULL).

// parse time: the parser hands over the Python parts of the file
vd_status lsys_py_parse_begin(vd_lsystem* ls, const char* text, size_t len);
vd_status lsys_py_parse_end(vd_lsystem* ls, size_t init_at);
// the parameters of a template module, s[*pos] = '(': each an E_PYSRC expression (at most
// max) into params; *pos moves after the ')'. Returns the count, or -1 with the error set.
int lsys_py_params(vd_lsystem* ls, const char* s, int len, int* pos, int lineno, int col0,
                   expr** params, int max);
// an expression as Python source (E_PYSRC), a trailing comment dropped; NULL with the error set
expr* lsys_py_expr(vd_lsystem* ls, const char* s, int len, int lineno, int col);
// evaluate an E_PYSRC expression in the current run's namespace (a number, bool or str)
vd_status lsys_py_eval(vd_lsystem* ls, const expr* e, value* out);
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
// a condition on the pattern parameter name (`name in 'AB'`): the chunk index of a function of
// name that returns its truth, or -1 with the error set
int lsys_py_cond(vd_lsystem* ls, const char* name, int nlen, const char* s, int len, int lineno);

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
// call the condition function fn (lsys_py_cond) on v: *holds its truth
vd_status lsys_py_test(vd_lsystem* ls, int fn, value v, int* holds);
// call hook name (Start, End, StartEach, EndEach, ...) with the arguments it declares; s is
// the current string (an End hook may return a new one). Missing hooks are fine.
// scene (Nullable: an animation's frame): a hook that declares a second parameter, in a step
// whose frame is displayed, gets the scene drawn into it first; *kept (Nullable) is then set to
// whether the hook kept that scene (returned it, alone or second of a pair, or nothing) and to
// 0 when the hook ran without keeping one (left as is when there is no such hook)
vd_status lsys_py_hook(vd_lsystem* ls, const char* name, vd_lstring* s, vd_lstring* scratch, int64_t max_modules,
                       vd_plant_spec* scene, int* kept);
// is module sym the module anc or a subclass of it (its declared bases, transitively)?
int lsys_isa(const vd_lsystem* ls, int32_t sym, int32_t anc);
// the parameter names a symbol declares (module A(x, t)), string ids; count in *n (0: none)
const int* lsys_declared_names(const vd_lsystem* ls, int32_t sym, int* n);
// call the file's global function name without arguments (vd_lsys_call)
vd_status lsys_py_call(vd_lsystem* ls, const char* name);
// call hook name (StartInterpretation, EndInterpretation) with what it produces appended to out,
// recorded as coming from module src; a hook that declares a parameter gets the turtle (None)
vd_status lsys_py_produce_hook(vd_lsystem* ls, const char* name, vd_lstring* out, int64_t src, int64_t max_modules);
// the plant the string s draws (interpretation with its hooks, then the turtle), for the scene
// a Python hook receives (EndEach(lstring, lscene))
vd_status lsys_scene(vd_lsystem* ls, const vd_lstring* s, vd_plant_spec* plant);
// an animation frame: plant (cleared) drawn from s as lsys_scene does, the file's labels named
vd_status lsys_draw(vd_lsystem* ls, const vd_lstring* s, vd_plant_spec* plant);
// drop objects that no module of s refers to any more (after a step)
void lsys_py_gc(vd_lsystem* ls, const vd_lstring* s);
// release every object (a new derivation starts)
void lsys_py_reset_objects(vd_lsystem* ls);
vd_status lsys_py_set_global(vd_lsystem* ls, const char* name, const char* text);
// a Vector3(x, y, z) object as a parameter (a handle) in *out
vd_status lsys_py_vec3(vd_lsystem* ls, double x, double y, double z, double* out);
vd_status lsys_py_get_global(vd_lsystem* ls, const char* name, double* out);
// What the turtle reads from object parameters (the Python engine's curves, functions and
// geometry). Arrays are vd_malloc'd, the caller frees them (sizes from the counts). Each returns
// VD_ERR_TYPE with a message in why (cap bytes) when v is not such an object (or no object at all).
// A curve as points at equal steps of its parameter (its stride): n points of dim (2 or 3) coordinates.
vd_status lsys_obj_points(const vd_lsystem* ls, double v, double** p, int* n, int* dim, char* why, size_t cap);
// A guide: the curve's length, m + 1 points, unit tangents and unit normals at equal steps of
// normalised arc length, and the dimension.
vd_status lsys_obj_guide(const vd_lsystem* ls, double v, int m, double* length, double** p, double** tan,
                         double** nrm, int* dim, char* why, size_t cap);
// A function of x: its range and its n samples at equal steps (QuantisedFunction).
vd_status lsys_obj_function(const vd_lsystem* ls, double v, double* fx, double* lx, double** val, int* n, char* why,
                            size_t cap);
// A 3D vector (Vector3, a sequence of three numbers) as c[0..2].
vd_status lsys_obj_vec3(const vd_lsystem* ls, double v, double c[3], char* why, size_t cap);
// A geometry as a triangle mesh: nv vertices (x, y, z), nt triangles, closed when it bounds a volume.
vd_status lsys_obj_mesh(const vd_lsystem* ls, double v, double** xyz, int* nv, int** tri, int* nt, int* closed,
                        char* why, size_t cap);
// The turtle settings the file made through context().turtle (setAngleIncrement,
// setWidthIncrement, setScaleMultiplier, setElasticity) applied over td (Python engine).
void lsys_py_turtle_def(const vd_lsystem* ls, vd_turtle_def* td);
// repr() of an object parameter into buf (cap bytes); "None" for a stale handle
void lsys_py_repr(const vd_lsystem* ls, double v, char* buf, size_t cap);

#endif
