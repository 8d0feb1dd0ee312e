// SPDX-License-Identifier: MIT
// Interpreter of the Python subset: expressions, statements, builtins (math, random with
// CPython's algorithms, L-Py's control functions) and emission of successor templates.
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lsys/lsys_internal.h"

#define MAX_CALL_DEPTH 200
#define MAX_LOOP_ITER 100000000LL
#define MAX_EXACT_INT 9007199254740992.0  // 2^53: integers beyond are not exact doubles

vd_status vm_error(vd_lsystem* ls, vd_status st, int line, int col, const char* fmt, ...) {
  if (ls->err && ls->err->status == VD_OK) {
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    vd_error_set(ls->err, st, ls->file, line, col, "%s", msg);
  }
  return st;
}

void vm_budget(vd_lsystem* ls, int64_t max_ops) {
  ls->max_ops = max_ops > 0 ? max_ops : LSYS_DEFAULT_MAX_OPS;
  ls->ops_left = ls->max_ops;
}

// take n operations (a loop iteration or a call is one) from the run's budget; non-zero when
// the budget is spent
static int spend_ops(vd_lsystem* ls, int64_t n, int line, int col) {
  ls->ops_left -= n;
  if (ls->ops_left >= 0) return 0;
  vm_error(ls, VD_ERR_LIMIT, line, col,
           "the run needs more than %lld interpreter operations (loop iterations, calls and modules "
           "rewritten)",
           (long long)ls->max_ops);
  return 1;
}

vd_status vm_spend(vd_lsystem* ls, int64_t n) {
  return spend_ops(ls, n, 0, 0) ? ls->err->status : VD_OK;
}

// ---------------------------------------------------------------------------------------------
// builtins

enum {
  B_ABS, B_MIN, B_MAX, B_INT, B_FLOAT, B_ROUND, B_BOOL, B_STR, B_POW, B_LEN_UNUSED,
  B_SQRT, B_SIN, B_COS, B_TAN, B_ASIN, B_ACOS, B_ATAN, B_ATAN2, B_SINH, B_COSH, B_TANH,
  B_EXP, B_LOG, B_LOG10, B_LOG2, B_FLOOR, B_CEIL, B_FABS, B_FMOD, B_HYPOT, B_DEGREES,
  B_RADIANS, B_TRUNC, B_COPYSIGN, B_ISNAN, B_ISINF,
  B_RANDOM, B_UNIFORM, B_GAUSS, B_NORMALVARIATE, B_RANDINT, B_RANDRANGE, B_SEED,
  B_TRIANGULAR, B_EXPOVARIATE,
  B_GETITERATIONNB, B_USEGROUP, B_GETGROUP, B_STOP, B_PRINT_UNUSED,
  B_BACKWARD, B_FORWARD, B_ISFORWARD, B_FRAMEDISPLAY, B_ISFRAMEDISPLAYED, B_ISANIMATIONENABLED,
  B_DISCARDNEWSTRING,
  B_COUNT
};

typedef struct builtin {
  const char* name;
  int minargs, maxargs;
  int ns;  // 0 plain builtin, NS_MATH, NS_RANDOM
} builtin;

static const builtin builtins[B_COUNT] = {
    [B_ABS] = {"abs", 1, 1, 0},
    [B_MIN] = {"min", 1, 64, 0},
    [B_MAX] = {"max", 1, 64, 0},
    [B_INT] = {"int", 0, 1, 0},
    [B_FLOAT] = {"float", 0, 1, 0},
    [B_ROUND] = {"round", 1, 2, 0},
    [B_BOOL] = {"bool", 0, 1, 0},
    [B_STR] = {"str", 0, 1, 0},
    [B_POW] = {"pow", 2, 2, NS_MATH},
    [B_LEN_UNUSED] = {"", 99, 99, -1},
    [B_SQRT] = {"sqrt", 1, 1, NS_MATH},
    [B_SIN] = {"sin", 1, 1, NS_MATH},
    [B_COS] = {"cos", 1, 1, NS_MATH},
    [B_TAN] = {"tan", 1, 1, NS_MATH},
    [B_ASIN] = {"asin", 1, 1, NS_MATH},
    [B_ACOS] = {"acos", 1, 1, NS_MATH},
    [B_ATAN] = {"atan", 1, 1, NS_MATH},
    [B_ATAN2] = {"atan2", 2, 2, NS_MATH},
    [B_SINH] = {"sinh", 1, 1, NS_MATH},
    [B_COSH] = {"cosh", 1, 1, NS_MATH},
    [B_TANH] = {"tanh", 1, 1, NS_MATH},
    [B_EXP] = {"exp", 1, 1, NS_MATH},
    [B_LOG] = {"log", 1, 2, NS_MATH},
    [B_LOG10] = {"log10", 1, 1, NS_MATH},
    [B_LOG2] = {"log2", 1, 1, NS_MATH},
    [B_FLOOR] = {"floor", 1, 1, NS_MATH},
    [B_CEIL] = {"ceil", 1, 1, NS_MATH},
    [B_FABS] = {"fabs", 1, 1, NS_MATH},
    [B_FMOD] = {"fmod", 2, 2, NS_MATH},
    [B_HYPOT] = {"hypot", 2, 2, NS_MATH},
    [B_DEGREES] = {"degrees", 1, 1, NS_MATH},
    [B_RADIANS] = {"radians", 1, 1, NS_MATH},
    [B_TRUNC] = {"trunc", 1, 1, NS_MATH},
    [B_COPYSIGN] = {"copysign", 2, 2, NS_MATH},
    [B_ISNAN] = {"isnan", 1, 1, NS_MATH},
    [B_ISINF] = {"isinf", 1, 1, NS_MATH},
    [B_RANDOM] = {"random", 0, 0, NS_RANDOM},
    [B_UNIFORM] = {"uniform", 2, 2, NS_RANDOM},
    [B_GAUSS] = {"gauss", 0, 2, NS_RANDOM},
    [B_NORMALVARIATE] = {"normalvariate", 0, 2, NS_RANDOM},
    [B_RANDINT] = {"randint", 2, 2, NS_RANDOM},
    [B_RANDRANGE] = {"randrange", 1, 3, NS_RANDOM},
    [B_SEED] = {"seed", 0, 1, NS_RANDOM},
    [B_TRIANGULAR] = {"triangular", 0, 3, NS_RANDOM},
    [B_EXPOVARIATE] = {"expovariate", 1, 1, NS_RANDOM},
    [B_GETITERATIONNB] = {"getIterationNb", 0, 0, 0},
    [B_USEGROUP] = {"useGroup", 1, 1, 0},
    [B_GETGROUP] = {"getGroup", 0, 0, 0},
    [B_STOP] = {"Stop", 0, 0, 0},
    [B_PRINT_UNUSED] = {"", 99, 99, -1},
    [B_BACKWARD] = {"backward", 0, 0, 0},
    [B_FORWARD] = {"forward", 0, 0, 0},
    [B_ISFORWARD] = {"isForward", 0, 0, 0},
    [B_FRAMEDISPLAY] = {"frameDisplay", 0, 1, 0},
    [B_ISFRAMEDISPLAYED] = {"isFrameDisplayed", 0, 0, 0},
    [B_ISANIMATIONENABLED] = {"isAnimationEnabled", 0, 0, 0},
    [B_DISCARDNEWSTRING] = {"DiscardNewString", 0, 0, 0},
};

int builtin_find(const char* name, int len) {
  for (int i = 0; i < B_COUNT; i++)
    if (builtins[i].ns >= 0 && (int)strlen(builtins[i].name) == len &&
        memcmp(builtins[i].name, name, (size_t)len) == 0)
      return i;
  return -1;
}

int builtin_in_ns(int ns, const char* name, int len) {
  int b = builtin_find(name, len);
  if (b < 0) return -1;
  if (builtins[b].ns == ns) return b;
  return -1;
}

value ns_constant(int ns, const char* name, int len, int* found) {
  *found = 1;
  if (ns == NS_MATH) {
    if (len == 2 && memcmp(name, "pi", 2) == 0) return v_num(VD_PI);
    if (len == 1 && name[0] == 'e') return v_num(2.718281828459045);
    if (len == 3 && memcmp(name, "tau", 3) == 0) return v_num(2 * VD_PI);
    if (len == 3 && memcmp(name, "inf", 3) == 0) return v_num(INFINITY);
  }
  *found = 0;
  return (value){V_NONE, 0};
}

static const char* type_name(value v) {
  switch (v.t) {
    case V_NONE: return "None";
    case V_BOOL: return "bool";
    case V_INT: return "int";
    case V_FLOAT: return "float";
    case V_STR: return "str";
    case V_FUNC: return "function";
    case V_BUILTIN: return "builtin function";
    case V_NS: return "module";
    case V_OBJ: return "object";
    default: return "undefined";
  }
}

void value_repr(const vd_lsystem* ls, value v, char* buf, size_t cap) {
  switch (v.t) {
    case V_NONE: snprintf(buf, cap, "None"); break;
    case V_BOOL: snprintf(buf, cap, "%s", v.n != 0 ? "True" : "False"); break;
    case V_INT: snprintf(buf, cap, "%.0f", v.n); break;
    case V_FLOAT:
      if (isnan(v.n)) snprintf(buf, cap, "nan");
      else if (isinf(v.n)) snprintf(buf, cap, v.n > 0 ? "inf" : "-inf");
      else if (v.n == floor(v.n) && fabs(v.n) < 1e16) snprintf(buf, cap, "%.1f", v.n);
      else {
        for (int p = 1; p <= 17; p++) {
          snprintf(buf, cap, "%.*g", p, v.n);
          if (strtod(buf, NULL) == v.n) break;
        }
      }
      break;
    case V_STR:
      snprintf(buf, cap, "%s", (int)v.n >= 0 && (int)v.n < ls->nstr ? ls->str[(int)v.n] : "");
      break;
    case V_FUNC: snprintf(buf, cap, "<function %s>", ls->funcs[(int)v.n]->name); break;
    case V_BUILTIN: snprintf(buf, cap, "<built-in function %s>", builtins[(int)v.n].name); break;
    case V_NS: snprintf(buf, cap, "<module '%s'>", v.n == NS_MATH ? "math" : "random"); break;
    default: snprintf(buf, cap, "<undefined>"); break;
  }
}

int value_truthy(value v) {
  switch (v.t) {
    case V_NONE: return 0;
    case V_BOOL:
    case V_INT:
    case V_FLOAT: return v.n != 0;
    default: return 1;
  }
}

vd_status value_to_param(vd_lsystem* ls, value v, double* out, int line, int col) {
  if (v_isnum(v)) {
    *out = v.n;
    return VD_OK;
  }
  if (v.t == V_STR) {
    *out = lsys_box_str((int)v.n);
    return VD_OK;
  }
  return vm_error(ls, VD_ERR_TYPE, line, col, "a module parameter must be a number or a string, not %s",
                  type_name(v));
}

value param_to_value(double d) {
  int sid = lsys_unbox_str(d);
  if (sid >= 0) return (value){V_STR, sid};
  uint32_t oid;
  unsigned epoch;
  if (isnan(d) && lsys_unbox_obj(d, &oid, &epoch)) return (value){V_OBJ, oid};
  if (d == floor(d) && fabs(d) < 9007199254740992.0) return v_int(d);
  return v_num(d);
}

static vd_status need_num(vd_lsystem* ls, value v, const char* fn, int line, int col) {
  if (v_isnum(v)) return VD_OK;
  return vm_error(ls, VD_ERR_TYPE, line, col, "%s: expected a number, got %s", fn, type_name(v));
}

static value num_result(double x, int is_int) { return is_int ? v_int(x) : v_num(x); }

static vd_status call_builtin(vd_lsystem* ls, int b, int n, const value* a, value* out, int line, int col) {
  const builtin* B = &builtins[b];
  if (n < B->minargs || n > B->maxargs) {
    if (B->minargs == B->maxargs)
      return vm_error(ls, VD_ERR_TYPE, line, col, "%s() takes %d argument%s (%d given)", B->name, B->minargs,
                      B->minargs == 1 ? "" : "s", n);
    return vm_error(ls, VD_ERR_TYPE, line, col, "%s() takes %d to %d arguments (%d given)", B->name,
                    B->minargs, B->maxargs, n);
  }
  // arguments of numeric functions must be numbers
  if (b != B_STR && b != B_BOOL)
    for (int i = 0; i < n; i++)
      if (need_num(ls, a[i], B->name, line, col)) return ls->err->status;
  double x = n > 0 ? a[0].n : 0, y = n > 1 ? a[1].n : 0;
  vd_rng* r = &ls->rng;
  switch (b) {
    case B_ABS: *out = num_result(fabs(x), a[0].t != V_FLOAT); break;
    case B_MIN:
    case B_MAX: {
      if (n == 1)
        return vm_error(ls, VD_ERR_UNSUPPORTED, line, col, "unsupported: %s() of an iterable", B->name);
      int k = 0;
      for (int i = 1; i < n; i++)
        if (b == B_MIN ? a[i].n < a[k].n : a[i].n > a[k].n) k = i;
      *out = a[k];
      break;
    }
    case B_INT:
      if (n && !isfinite(x)) return vm_error(ls, VD_ERR_VALUE, line, col, "int() of a non-finite number");
      *out = v_int(n ? trunc(x) : 0);
      break;
    case B_FLOAT: *out = v_num(n ? x : 0); break;
    case B_ROUND:
      if (n == 1) {
        if (!isfinite(x)) return vm_error(ls, VD_ERR_VALUE, line, col, "round() of a non-finite number");
        // Python 3 rounds half to even
        double f = floor(x), d = x - f;
        double rr = d > 0.5 ? f + 1 : d < 0.5 ? f : (fmod(f, 2) == 0 ? f : f + 1);
        *out = v_int(rr);
      } else {
        double p = pow(10.0, y);
        double s = x * p, f = floor(s), d = s - f;
        double rr = d > 0.5 ? f + 1 : d < 0.5 ? f : (fmod(f, 2) == 0 ? f : f + 1);
        *out = num_result(rr / p, a[0].t != V_FLOAT);
      }
      break;
    case B_BOOL: *out = (value){V_BOOL, n ? value_truthy(a[0]) : 0}; break;
    case B_STR: {
      char buf[128];
      if (n) value_repr(ls, a[0], buf, sizeof buf);
      else buf[0] = 0;
      int id = str_intern(ls, buf, (int)strlen(buf));
      if (id < 0) return str_intern_error(ls, id, line, col);
      *out = (value){V_STR, id};
      break;
    }
    case B_POW: *out = v_num(pow(x, y)); break;
    case B_SQRT:
      if (x < 0) return vm_error(ls, VD_ERR_VALUE, line, col, "math domain error: sqrt of a negative number");
      *out = v_num(sqrt(x));
      break;
    case B_SIN: *out = v_num(sin(x)); break;
    case B_COS: *out = v_num(cos(x)); break;
    case B_TAN: *out = v_num(tan(x)); break;
    case B_ASIN:
    case B_ACOS:
      if (x < -1 || x > 1) return vm_error(ls, VD_ERR_VALUE, line, col, "math domain error in %s", B->name);
      *out = v_num(b == B_ASIN ? asin(x) : acos(x));
      break;
    case B_ATAN: *out = v_num(atan(x)); break;
    case B_ATAN2: *out = v_num(atan2(x, y)); break;
    case B_SINH: *out = v_num(sinh(x)); break;
    case B_COSH: *out = v_num(cosh(x)); break;
    case B_TANH: *out = v_num(tanh(x)); break;
    case B_EXP: *out = v_num(exp(x)); break;
    case B_LOG:
    case B_LOG10:
    case B_LOG2:
      if (x <= 0 || (n == 2 && (y <= 0 || y == 1)))
        return vm_error(ls, VD_ERR_VALUE, line, col, "math domain error in %s", B->name);
      *out = v_num(b == B_LOG10 ? log10(x) : b == B_LOG2 ? log2(x) : n == 2 ? log(x) / log(y) : log(x));
      break;
    case B_FLOOR: *out = v_int(floor(x)); break;
    case B_CEIL: *out = v_int(ceil(x)); break;
    case B_FABS: *out = v_num(fabs(x)); break;
    case B_FMOD:
      if (y == 0) return vm_error(ls, VD_ERR_VALUE, line, col, "math domain error in fmod");
      *out = v_num(fmod(x, y));
      break;
    case B_HYPOT: *out = v_num(hypot(x, y)); break;
    case B_DEGREES: *out = v_num(x * (180.0 / VD_PI)); break;
    case B_RADIANS: *out = v_num(x * (VD_PI / 180.0)); break;
    case B_TRUNC: *out = v_int(trunc(x)); break;
    case B_COPYSIGN: *out = v_num(copysign(x, y)); break;
    case B_ISNAN: *out = (value){V_BOOL, isnan(x) ? 1 : 0}; break;
    case B_ISINF: *out = (value){V_BOOL, isinf(x) ? 1 : 0}; break;
    case B_RANDOM: *out = v_num(vd_rng_random(r)); break;
    case B_UNIFORM: *out = v_num(vd_rng_uniform(r, x, y)); break;
    case B_GAUSS: *out = v_num(vd_rng_gauss(r, n > 0 ? x : 0.0, n > 1 ? y : 1.0)); break;
    case B_NORMALVARIATE: {
      // CPython's Kinderman-Monahan ratio method
      const double NV = 4 * exp(-0.5) / sqrt(2.0);
      double z;
      for (;;) {
        double u1 = vd_rng_random(r), u2 = 1.0 - vd_rng_random(r);
        z = NV * (u1 - 0.5) / u2;
        if (z * z / 4.0 <= -log(u2)) break;
      }
      *out = v_num((n > 0 ? x : 0.0) + z * (n > 1 ? y : 1.0));
      break;
    }
    case B_RANDINT:
      if (x != floor(x) || y != floor(y)) return vm_error(ls, VD_ERR_VALUE, line, col, "randint() needs integers");
      if (fabs(x) > MAX_EXACT_INT || fabs(y) > MAX_EXACT_INT)
        return vm_error(ls, VD_ERR_VALUE, line, col, "randint() arguments beyond +-2^53");
      if (y < x) return vm_error(ls, VD_ERR_VALUE, line, col, "empty range for randint(%g, %g)", x, y);
      *out = v_int((double)vd_rng_randint(r, (int64_t)x, (int64_t)y));
      break;
    case B_RANDRANGE: {
      double start = n == 1 ? 0 : x, stop = n == 1 ? x : y, step = n == 3 ? a[2].n : 1;
      if (start != floor(start) || stop != floor(stop) || step != floor(step) || step == 0)
        return vm_error(ls, VD_ERR_VALUE, line, col, "randrange() needs integers and a non-zero step");
      if (fabs(start) > MAX_EXACT_INT || fabs(stop) > MAX_EXACT_INT || fabs(step) > MAX_EXACT_INT)
        return vm_error(ls, VD_ERR_VALUE, line, col, "randrange() arguments beyond +-2^53");
      double cnt = step > 0 ? floor((stop - start + step - 1) / step) : floor((stop - start + step + 1) / step);
      if (cnt <= 0) return vm_error(ls, VD_ERR_VALUE, line, col, "empty range for randrange()");
      *out = v_int(start + step * (double)vd_rng_randint(r, 0, (int64_t)cnt - 1));
      break;
    }
    case B_SEED:
      if (n && (x != floor(x) || !isfinite(x)))
        return vm_error(ls, VD_ERR_UNSUPPORTED, line, col, "unsupported: seed() with a non-integer");
      if (n && fabs(x) >= 18446744073709551616.0)
        return vm_error(ls, VD_ERR_UNSUPPORTED, line, col, "unsupported: seed() beyond 2^64");
      vd_rng_seed(r, n ? (uint64_t)fabs(x) : 0);
      *out = (value){V_NONE, 0};
      break;
    case B_TRIANGULAR: {
      double lo = n > 0 ? x : 0, hi = n > 1 ? y : 1, mode = n > 2 ? a[2].n : (lo + hi) / 2;
      double u = vd_rng_random(r);
      double c = hi == lo ? 0.5 : (mode - lo) / (hi - lo);
      if (u > c) {
        u = 1 - u;
        c = 1 - c;
        double t = lo;
        lo = hi;
        hi = t;
      }
      *out = v_num(lo + (hi - lo) * sqrt(u * c));
      break;
    }
    case B_EXPOVARIATE:
      if (x == 0) return vm_error(ls, VD_ERR_VALUE, line, col, "expovariate() with rate 0");
      *out = v_num(-log(1.0 - vd_rng_random(r)) / x);
      break;
    case B_GETITERATIONNB: *out = v_int(ls->iteration); break;
    case B_USEGROUP:
      if (x != floor(x) || x < 0 || x > 1000000)
        return vm_error(ls, VD_ERR_VALUE, line, col, "useGroup() needs a group number in 0..1000000");
      ls->current_group = (int)x;
      *out = (value){V_NONE, 0};
      break;
    case B_GETGROUP: *out = v_int(ls->current_group); break;
    case B_STOP:
      ls->stop_requested = 1;
      *out = (value){V_NONE, 0};
      break;
    // derivation direction: backward() takes effect at the next step (L-Py)
    case B_BACKWARD:
    case B_FORWARD:
      ls->backward = b == B_BACKWARD;
      *out = (value){V_NONE, 0};
      break;
    case B_ISFORWARD: *out = (value){V_BOOL, !ls->backward}; break;
    // frameDisplay(False): an animation skips the step's frame
    case B_FRAMEDISPLAY:
      ls->frame_displayed = n == 0 || x != 0;
      *out = (value){V_NONE, 0};
      break;
    case B_ISFRAMEDISPLAYED: *out = (value){V_BOOL, ls->frame_displayed}; break;
    case B_ISANIMATIONENABLED: *out = (value){V_BOOL, ls->animating}; break;
    case B_DISCARDNEWSTRING:
      ls->discard_requested = 1;
      *out = (value){V_NONE, 0};
      break;
    default: return vm_error(ls, VD_ERR_UNSUPPORTED, line, col, "unsupported builtin");
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// expressions

static vd_status arith(vd_lsystem* ls, int op, value a, value b, value* out, int line, int col) {
  if (op == E_ADD && a.t == V_STR && b.t == V_STR) {
    char buf[2048];
    snprintf(buf, sizeof buf, "%s%s", ls->str[(int)a.n], ls->str[(int)b.n]);
    // a concatenation costs one operation per 64 bytes it makes
    if (spend_ops(ls, (int64_t)strlen(buf) / 64, line, col)) return ls->err->status;
    int id = str_intern(ls, buf, (int)strlen(buf));
    if (id < 0) return str_intern_error(ls, id, line, col);
    *out = (value){V_STR, id};
    return VD_OK;
  }
  if (!v_isnum(a) || !v_isnum(b)) {
    static const char* sym[] = {[E_ADD] = "+", [E_SUB] = "-", [E_MUL] = "*", [E_DIV] = "/",
                                [E_FLOORDIV] = "//", [E_MOD] = "%", [E_POW] = "**"};
    return vm_error(ls, VD_ERR_TYPE, line, col, "unsupported operand types for %s: %s and %s", sym[op],
                    type_name(a), type_name(b));
  }
  int ints = a.t != V_FLOAT && b.t != V_FLOAT;
  double x = a.n, y = b.n;
  switch (op) {
    case E_ADD: *out = num_result(x + y, ints); break;
    case E_SUB: *out = num_result(x - y, ints); break;
    case E_MUL: *out = num_result(x * y, ints); break;
    case E_DIV:
      if (y == 0) return vm_error(ls, VD_ERR_VALUE, line, col, "division by zero");
      *out = v_num(x / y);
      break;
    case E_FLOORDIV:
      if (y == 0) return vm_error(ls, VD_ERR_VALUE, line, col, "integer division or modulo by zero");
      *out = num_result(floor(x / y), ints);
      break;
    case E_MOD: {
      if (y == 0) return vm_error(ls, VD_ERR_VALUE, line, col, "modulo by zero");
      double m = fmod(x, y);
      if (m != 0 && ((m < 0) != (y < 0))) m += y;  // Python: sign of the divisor
      *out = num_result(m, ints);
      break;
    }
    case E_POW:
      if (x == 0 && y < 0) return vm_error(ls, VD_ERR_VALUE, line, col, "0.0 cannot be raised to a negative power");
      if (x < 0 && y != floor(y))
        return vm_error(ls, VD_ERR_UNSUPPORTED, line, col, "unsupported: negative number to a fractional power");
      *out = num_result(pow(x, y), ints && y >= 0);
      break;
    default: return vm_error(ls, VD_ERR_SYNTAX, line, col, "bad operator");
  }
  return VD_OK;
}

static int compare(vd_lsystem* ls, int op, value a, value b, int* res, int line, int col) {
  if (v_isnum(a) && v_isnum(b)) {
    double x = a.n, y = b.n;
    switch (op) {
      case CMP_LT: *res = x < y; break;
      case CMP_LE: *res = x <= y; break;
      case CMP_GT: *res = x > y; break;
      case CMP_GE: *res = x >= y; break;
      case CMP_EQ: *res = x == y; break;
      default: *res = x != y; break;
    }
    return 0;
  }
  if (op == CMP_EQ || op == CMP_NE) {
    int eq = a.t == b.t && a.n == b.n;
    *res = op == CMP_EQ ? eq : !eq;
    return 0;
  }
  if (a.t == V_STR && b.t == V_STR) {
    int c = strcmp(ls->str[(int)a.n], ls->str[(int)b.n]);
    *res = op == CMP_LT ? c < 0 : op == CMP_LE ? c <= 0 : op == CMP_GT ? c > 0 : c >= 0;
    return 0;
  }
  vm_error(ls, VD_ERR_TYPE, line, col, "cannot compare %s and %s", type_name(a), type_name(b));
  return 1;
}

static vd_status eval_call(vd_lsystem* ls, const expr* e, value* frame, value* out) {
  value callee;
  // namespace functions: random.uniform(...), math.sqrt(...)
  if (e->a->op == E_ATTR) {
    value base;
    if (vm_eval(ls, e->a->a, frame, &base)) return ls->err->status;
    const char* attr = ls->str[e->a->slot];
    if (base.t != V_NS)  // NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult): vm_eval fills its value when it returns VD_OK; the analyzer does not follow the variadic vm_error
      return vm_error(ls, VD_ERR_UNSUPPORTED, e->line, e->col, "unsupported: attribute '%s' of %s", attr,
                      type_name(base));
    int b = builtin_in_ns((int)base.n, attr, (int)strlen(attr));
    if (b < 0)
      return vm_error(ls, VD_ERR_NAME, e->a->line, e->a->col, "module '%s' has no function '%s'",
                      base.n == NS_MATH ? "math" : "random", attr);
    callee = (value){V_BUILTIN, b};
  } else if (vm_eval(ls, e->a, frame, &callee)) {
    return ls->err->status;
  }
  value args[64];
  for (int i = 0; i < e->nargs; i++)
    if (vm_eval(ls, e->args[i], frame, &args[i])) return ls->err->status;
  if (callee.t == V_BUILTIN) return call_builtin(ls, (int)callee.n, e->nargs, args, out, e->line, e->col);  // NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult): vm_eval fills its value when it returns VD_OK; the analyzer does not follow the variadic vm_error
  if (callee.t == V_NS && callee.n == NS_RANDOM)  // `random` after `from random import *` is random()
    return call_builtin(ls, B_RANDOM, e->nargs, args, out, e->line, e->col);
  if (callee.t == V_FUNC) return vm_call_func(ls, (int)callee.n, e->nargs, args, out, e->line, e->col);
  return vm_error(ls, VD_ERR_TYPE, e->line, e->col, "'%s' object is not callable", type_name(callee));
}

vd_status vm_eval(vd_lsystem* ls, const expr* e, value* frame, value* out) {
  value a = {0}, b = {0};
  switch (e->op) {
    case E_CONST: *out = e->k; return VD_OK;
    case E_LOCAL:
      *out = frame[e->slot];
      if (out->t == V_UNDEF)
        return vm_error(ls, VD_ERR_NAME, e->line, e->col, "local variable used before assignment");
      return VD_OK;
    case E_GLOBAL:
      *out = ls->gval[e->slot];
      if (out->t == V_UNDEF)
        return vm_error(ls, VD_ERR_NAME, e->line, e->col, "name '%s' is not defined", ls->gdef[e->slot].name);
      return VD_OK;
    case E_NEG:
    case E_POS:
      if (vm_eval(ls, e->a, frame, &a)) return ls->err->status;
      if (!v_isnum(a))
        return vm_error(ls, VD_ERR_TYPE, e->line, e->col, "bad operand type for unary %s: %s",
                        e->op == E_NEG ? "-" : "+", type_name(a));
      *out = num_result(e->op == E_NEG ? -a.n : a.n, a.t != V_FLOAT);
      return VD_OK;
    case E_NOT:
      if (vm_eval(ls, e->a, frame, &a)) return ls->err->status;
      *out = (value){V_BOOL, !value_truthy(a)};
      return VD_OK;
    case E_ADD:
    case E_SUB:
    case E_MUL:
    case E_DIV:
    case E_FLOORDIV:
    case E_MOD:
    case E_POW:
      if (vm_eval(ls, e->a, frame, &a) || vm_eval(ls, e->b, frame, &b)) return ls->err->status;
      // fast path for floats
      if (a.t == V_FLOAT && b.t == V_FLOAT) {
        if (e->op == E_ADD) { *out = v_num(a.n + b.n); return VD_OK; }
        if (e->op == E_SUB) { *out = v_num(a.n - b.n); return VD_OK; }
        if (e->op == E_MUL) { *out = v_num(a.n * b.n); return VD_OK; }
        if (e->op == E_DIV && b.n != 0) { *out = v_num(a.n / b.n); return VD_OK; }
      }
      return arith(ls, e->op, a, b, out, e->line, e->col);
    case E_AND:
      if (vm_eval(ls, e->a, frame, &a)) return ls->err->status;
      if (!value_truthy(a)) {
        *out = a;
        return VD_OK;
      }
      return vm_eval(ls, e->b, frame, out);
    case E_OR:
      if (vm_eval(ls, e->a, frame, &a)) return ls->err->status;
      if (value_truthy(a)) {
        *out = a;
        return VD_OK;
      }
      return vm_eval(ls, e->b, frame, out);
    case E_CMP: {
      if (vm_eval(ls, e->args[0], frame, &a)) return ls->err->status;
      for (int i = 0; i < e->nargs - 1; i++) {
        if (vm_eval(ls, e->args[i + 1], frame, &b)) return ls->err->status;
        int r;
        if (compare(ls, e->cmp[i], a, b, &r, e->line, e->col)) return ls->err->status;
        if (!r) {
          *out = (value){V_BOOL, 0};
          return VD_OK;
        }
        a = b;
      }
      *out = (value){V_BOOL, 1};
      return VD_OK;
    }
    case E_COND:
      if (vm_eval(ls, e->b, frame, &a)) return ls->err->status;
      return vm_eval(ls, value_truthy(a) ? e->a : e->c, frame, out);
    case E_CALL: return eval_call(ls, e, frame, out);
    case E_PYSRC:
      if (ls->py) return lsys_py_eval(ls, e, out);
      return vm_error(ls, VD_ERR_UNSUPPORTED, e->line, e->col, "unsupported: Python source outside the Python engine");
    case E_ATTR: {
      if (vm_eval(ls, e->a, frame, &a)) return ls->err->status;
      const char* attr = ls->str[e->slot];
      int alen = (int)strlen(attr);
      if (a.t != V_NS)
        return vm_error(ls, VD_ERR_UNSUPPORTED, e->line, e->col, "unsupported: attribute '%s' of %s", attr,
                        type_name(a));
      int found;
      value c = ns_constant((int)a.n, attr, alen, &found);
      if (found) {
        *out = c;
        return VD_OK;
      }
      int bi = builtin_in_ns((int)a.n, attr, alen);
      if (bi < 0)
        return vm_error(ls, VD_ERR_NAME, e->line, e->col, "module '%s' has no attribute '%s'",
                        a.n == NS_MATH ? "math" : "random", attr);
      *out = (value){V_BUILTIN, bi};
      return VD_OK;
    }
    default: return vm_error(ls, VD_ERR_SYNTAX, e->line, e->col, "bad expression");
  }
}

// ---------------------------------------------------------------------------------------------
// statements

enum { FLOW_NONE = 0, FLOW_BREAK, FLOW_CONTINUE, FLOW_RETURN };

typedef struct exec_state {
  vm_out* out;
  int in_func;   // a def's body: produce emits and returns from the def (L-Py's pproduce)
  int flow;
  value ret;
} exec_state;

static vd_status exec_list(vd_lsystem* ls, stmt* s, value* frame, exec_state* X);

static vd_status assign(vd_lsystem* ls, const stmt* s, value* frame, value v) {
  if (s->is_global) ls->gval[s->slot] = v;
  else frame[s->slot] = v;
  return VD_OK;
}

vd_status vm_emit_tmpl(vd_lsystem* ls, const tmpl* t, value* frame, vm_out* out) {
  vd_lstring* s = out->s;
  int64_t nparam = 0;
  for (int i = 0; i < t->n; i++) nparam += t->mod[i].nparam;
  if (s->n + t->n > out->max_modules)
    return vm_error(ls, VD_ERR_LIMIT, t->n ? t->mod[0].line : 0, t->n ? t->mod[0].col : 0,
                    "the L-string would exceed %lld modules (raise --max-modules)", (long long)out->max_modules);
  if (!lstr_reserve(s, s->n + t->n, s->par[s->n] + nparam))
    return vm_error(ls, VD_ERR_NOMEM, t->n ? t->mod[0].line : 0, 0, "out of memory growing the L-string");
  int64_t n = s->n, v = s->par[n];
  if (__builtin_expect(((uintptr_t)s->src | (uintptr_t)s->line) != 0, 0)) {
    // source indices (interpretation) and file lines (tracing an error): rare
    for (int i = 0; s->src && i < t->n; i++) s->src[n + i] = out->src;
    for (int i = 0; s->line && i < t->n; i++) s->line[n + i] = t->mod[i].line;
  }
  for (int i = 0; i < t->n; i++) {
    const tmod* m = &t->mod[i];
    s->sym[n] = m->sym;
    for (int k = 0; k < m->nparam; k++) {
      const expr* e = m->param[k];
      value x;
      if (e->op == E_LOCAL && frame[e->slot].t != V_UNDEF && frame[e->slot].t <= V_FLOAT && frame[e->slot].t >= V_BOOL) {
        s->val[v++] = frame[e->slot].n;
        continue;
      }
      if (vm_eval(ls, e, frame, &x)) return ls->err->status;
      if (value_to_param(ls, x, &s->val[v], e->line, e->col)) return ls->err->status;
      v++;
    }
    n++;
    s->par[n] = v;
  }
  s->n = n;
  return VD_OK;
}

// one pass through a loop body (it costs one operation): 1 when the loop ends here (break, or
// return with X->flow left at FLOW_RETURN), 0 to go on, -1 on error
static int loop_iteration(vd_lsystem* ls, const stmt* s, value* frame, exec_state* X) {
  if (spend_ops(ls, 1, s->line, s->col) || exec_list(ls, s->body, frame, X)) return -1;
  if (X->flow == FLOW_CONTINUE) X->flow = FLOW_NONE;
  if (X->flow == FLOW_BREAK) {
    X->flow = FLOW_NONE;
    return 1;
  }
  return X->flow == FLOW_RETURN;
}

static vd_status exec_list(vd_lsystem* ls, stmt* s, value* frame, exec_state* X) {
  for (; s; s = s->next) {
    value v;
    switch (s->op) {
      case S_EXPR:
        if (vm_eval(ls, s->e, frame, &v)) return ls->err->status;
        break;
      case S_ASSIGN:
        if (vm_eval(ls, s->e, frame, &v)) return ls->err->status;
        assign(ls, s, frame, v);
        break;
      case S_AUGASSIGN: {
        value cur = s->is_global ? ls->gval[s->slot] : frame[s->slot];
        if (cur.t == V_UNDEF)
          return vm_error(ls, VD_ERR_NAME, s->line, s->col, "name '%s' is not defined before '%s='",
                          s->is_global ? ls->gdef[s->slot].name : "local", "op");
        if (vm_eval(ls, s->e, frame, &v)) return ls->err->status;
        value r;
        if (arith(ls, s->aug, cur, v, &r, s->line, s->col)) return ls->err->status;
        assign(ls, s, frame, r);
        break;
      }
      case S_IF:
        if (vm_eval(ls, s->e, frame, &v)) return ls->err->status;
        if (value_truthy(v)) {
          if (exec_list(ls, s->body, frame, X)) return ls->err->status;
        } else if (s->orelse) {
          if (exec_list(ls, s->orelse, frame, X)) return ls->err->status;
        }
        if (X->flow) return VD_OK;
        break;
      case S_WHILE: {
        for (;;) {
          if (vm_eval(ls, s->e, frame, &v)) return ls->err->status;
          if (!value_truthy(v)) break;
          int r = loop_iteration(ls, s, frame, X);
          if (r < 0) return ls->err->status;
          if (r > 0) break;
        }
        if (X->flow == FLOW_RETURN) return VD_OK;
        break;
      }
      case S_FOR: {
        value a = v_int(0), b, c = v_int(1);
        if (s->e && vm_eval(ls, s->e, frame, &a)) return ls->err->status;
        if (vm_eval(ls, s->e2, frame, &b)) return ls->err->status;
        if (s->e3 && vm_eval(ls, s->e3, frame, &c)) return ls->err->status;
        if (!v_isnum(a) || !v_isnum(b) || !v_isnum(c) || a.n != floor(a.n) || b.n != floor(b.n) ||
            c.n != floor(c.n))
          return vm_error(ls, VD_ERR_TYPE, s->line, s->col, "range() arguments must be integers");
        if (c.n == 0) return vm_error(ls, VD_ERR_VALUE, s->line, s->col, "range() step must not be zero");
        double cnt = c.n > 0 ? ceil((b.n - a.n) / c.n) : ceil((a.n - b.n) / -c.n);
        if (cnt > (double)MAX_LOOP_ITER)
          return vm_error(ls, VD_ERR_LIMIT, s->line, s->col, "range() of more than %lld items", MAX_LOOP_ITER);
        // count iterations rather than adding the step: a + step can round back to a
        int64_t nit = cnt > 0 ? (int64_t)cnt : 0;
        for (int64_t k = 0; k < nit; k++) {
          assign(ls, s, frame, v_int(a.n + (double)k * c.n));
          int r = loop_iteration(ls, s, frame, X);
          if (r < 0) return ls->err->status;
          if (r > 0) break;
        }
        if (X->flow == FLOW_RETURN) return VD_OK;
        break;
      }
      case S_PRODUCE:
      case S_NPRODUCE:
        if (!X->out)
          return vm_error(ls, VD_ERR_SYNTAX, s->line, s->col,
                          "'%s' called where no L-string is being written (outside a rule, the axiom or a hook "
                          "that produces)",
                          s->op == S_PRODUCE ? "produce" : "nproduce");
        if (vm_emit_tmpl(ls, s->t, frame, X->out)) return ls->err->status;
        if (s->op == S_PRODUCE && X->in_func) {
          // in a def, produce adds to what the rule produces and returns from the def
          X->out->nproduced = 1;
          X->flow = FLOW_RETURN;
          X->ret = (value){V_NONE, 0};
          return VD_OK;
        }
        if (s->op == S_PRODUCE) {
          X->out->produced = 1;
          X->flow = FLOW_RETURN;
          return VD_OK;
        }
        X->out->nproduced = 1;
        break;
      case S_RETURN:
        X->ret = (value){V_NONE, 0};
        if (s->e && vm_eval(ls, s->e, frame, &X->ret)) return ls->err->status;
        X->flow = FLOW_RETURN;
        return VD_OK;
      case S_PASS:
      case S_GLOBAL: break;
      case S_BREAK: X->flow = FLOW_BREAK; return VD_OK;
      case S_CONTINUE: X->flow = FLOW_CONTINUE; return VD_OK;
      case S_PRINT: {
        if (ls->quiet) break;  // a repeat run (tracing an error back to the file)
        char line[1024] = "";
        size_t n = 0;
        for (int i = 0; i < s->nargs; i++) {
          if (vm_eval(ls, s->args[i], frame, &v)) return ls->err->status;
          char buf[256];
          value_repr(ls, v, buf, sizeof buf);
          n += (size_t)snprintf(line + n, n < sizeof line ? sizeof line - n : 0, "%s%s", i ? " " : "", buf);
          if (n >= sizeof line) n = sizeof line - 1;
        }
        vd_log(0, "%s", line);
        break;
      }
      case S_ASSERT:
        if (vm_eval(ls, s->e, frame, &v)) return ls->err->status;
        if (!value_truthy(v)) {
          char msg[256] = "";
          if (s->e2) {
            value m;
            if (vm_eval(ls, s->e2, frame, &m)) return ls->err->status;
            value_repr(ls, m, msg, sizeof msg);
          }
          return vm_error(ls, VD_ERR_ASSERT, s->line, s->col, "assertion failed%s%s", msg[0] ? ": " : "", msg);
        }
        break;
      default: return vm_error(ls, VD_ERR_SYNTAX, s->line, s->col, "bad statement");
    }
  }
  return VD_OK;
}

vd_status vm_exec_block(vd_lsystem* ls, stmt* s, value* frame, vm_out* out, int* returned, value* retval) {
  exec_state X = {out, 0, FLOW_NONE, {V_NONE, 0}};
  // defs called from here (nproduce in a helper) write where this block writes
  vm_out* outer = ls->cur_out;
  ls->cur_out = out;
  vd_status st = exec_list(ls, s, frame, &X);
  ls->cur_out = outer;
  if (returned) *returned = X.flow == FLOW_RETURN;
  if (retval) *retval = X.ret;
  return st;
}

vd_status vm_call_func(vd_lsystem* ls, int fi, int nargs, const value* args, value* ret, int line, int col) {
  func* f = ls->funcs[fi];
  if (nargs != f->nparam)
    return vm_error(ls, VD_ERR_TYPE, line, col, "%s() takes %d argument%s (%d given)", f->name, f->nparam,
                    f->nparam == 1 ? "" : "s", nargs);
  if (ls->call_depth >= MAX_CALL_DEPTH)
    return vm_error(ls, VD_ERR_LIMIT, line, col, "maximum recursion depth (%d) exceeded in %s()",
                    MAX_CALL_DEPTH, f->name);
  if (spend_ops(ls, 1, line, col)) return ls->err->status;
  value small[32];
  value* frame = small;
  int nl = f->nlocal > 0 ? f->nlocal : 1;
  if (nl > 32) {
    frame = vd_malloc(sizeof(value) * (size_t)nl);
    if (!frame) return vm_error(ls, VD_ERR_NOMEM, line, col, "out of memory");
  }
  for (int i = 0; i < nl; i++) frame[i] = (value){V_UNDEF, 0};
  for (int i = 0; i < nargs; i++) frame[i] = args[i];
  ls->call_depth++;
  // produce / nproduce inside a def write to the string of the rule (or hook) that called it
  exec_state X = {ls->cur_out, 1, FLOW_NONE, {V_NONE, 0}};
  vd_status st = exec_list(ls, f->body, frame, &X);
  ls->call_depth--;
  *ret = X.ret;
  if (frame != small) vd_free(frame, sizeof(value) * (size_t)nl);
  return st;
}

int lsys_cond_holds(vd_lsystem* ls, const pcond* c, value v, value* frame) {
  int h = 1;
  if (c->pyfn >= 0) {
    if (lsys_py_test(ls, c->pyfn, v, &h)) return -1;
  } else if (c->e) {
    value r;
    if (vm_eval(ls, c->e, frame, &r)) return -1;
    h = value_truthy(r);
  }
  return h != 0;
}
