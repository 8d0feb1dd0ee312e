// SPDX-License-Identifier: MIT
// The Python engine: embedded CPython (Debian's libpython3.11) runs the Python of an .lpy file
// that goes beyond the native subset, as L-Py runs it through Boost.Python. The parser,
// derivation, matching, L-string layout and turtle are the native ones; CPython executes the
// file's top-level code, helper functions and classes, and every rule body and successor.
//
// Interpreter. One per process (CPython's rule). When verdant runs inside a Python process
// (the `verdant` package) the engine uses that interpreter; otherwise it starts one on first
// use with Debian's prefix (stdlib and dist-packages such as numpy), a fixed hash seed (set
// and dict order of strings is the same in every run) and no signal handlers.
//
// Threads. A process-wide mutex serialises the Python work of all lsystems: one lsystem holds
// it (and the GIL) for a whole derivation or interpretation, so Python code of two items of a
// dataset never interleaves. random (and numpy.random once imported) is CPython's global
// generator: seeded with --seed at the start of each derivation, and its state saved and
// restored per lsystem whenever another lsystem ran in between, so the same seed gives the
// same bytes whatever the thread count.
//
// Values. Module parameters stay doubles in the one L-string layout: numbers as numbers,
// strings as NaN-boxed string ids, any other Python object (list, tuple, dict, instance,
// vector, curve) as a NaN-boxed handle into the lsystem's object table. The table is swept
// after each step (objects no module refers to are released) and emptied when a derivation
// starts, so handles of an older derivation's string are stale (they read back as None).
#include "lsys/py/lsys_py.h"  // Python.h first: it sets the feature macros

#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lpyshim.h"  // generated from the package lpyshim: lpyshim_files[]

#ifndef VD_PYTHON_HOME
#define VD_PYTHON_HOME "/usr"
#endif

// new references to None and True (functions, not CPython's Py_RETURN_* statement macros, so the
// static analysers see the return)
static PyObject* py_none(void) {
  Py_INCREF(Py_None);
  return Py_None;
}

static PyObject* py_true(void) {
  Py_INCREF(Py_True);
  return Py_True;
}

// ---------------------------------------------------------------------------------------------
// process-wide state (CPython's interpreter is process-wide)

static pthread_once_t g_once = PTHREAD_ONCE_INIT;
static int g_state;              // 1 usable, -1 failed (g_why says why)
static char g_why[256];
static int g_hosted;             // 1 when verdant runs inside a Python process
static pthread_mutex_t g_mutex = PTHREAD_MUTEX_INITIALIZER;  // Python work of all lsystems
static PyObject* g_shim;         // the shim module's namespace (dict)
static PyObject* g_base;         // base namespace of every run (lpy and PlantGL names)
static vd_lsystem* g_cur;        // the lsystem running Python now (under g_mutex)
static vd_lsystem* g_last;       // the lsystem whose random state is in random now (not hosted)
static _Thread_local int tl_depth;           // nesting of lsys_py_enter on this thread
static _Thread_local PyGILState_STATE tl_gil;
static _Thread_local PyThreadState* tl_saved;  // the caller's thread state when it held the GIL
static _Thread_local PyObject* tl_host;        // hosted: the host's random state during a call

static PyObject* vd_module_create(void);

// ---------------------------------------------------------------------------------------------
// the watchdog. Counting the Python engine's operations (a trace function) would make it 2.4x
// slower, so its work limit is time without progress instead: when the thread running Python
// has not started a rule, produced or entered a hook for max_ops / 10^7 seconds (at least 1 s;
// 100 s by default), a TimeoutError is raised in it (PyThreadState_SetAsyncExc) and the run
// ends with VD_ERR_LIMIT. Only code that runs away is ever stopped.
static atomic_long g_progress;     // bumped at each rule call, produce and hook
static atomic_ulong g_busy;        // PyThread ident of the thread running the engine, 0 when idle
static atomic_llong g_limit_ms;    // the current run's limit
static atomic_int g_fired;         // the watchdog raised in the current run
static pthread_once_t g_wd_once = PTHREAD_ONCE_INIT;

static double mono_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void progress(void) { atomic_fetch_add_explicit(&g_progress, 1, memory_order_relaxed); }

static void* watchdog(void* arg) {
  (void)arg;
  long last = -1;
  unsigned long who = 0;
  double since = mono_now();
  for (;;) {
    struct timespec nap = {0, 50 * 1000 * 1000};
    nanosleep(&nap, NULL);
    unsigned long b = atomic_load(&g_busy);
    long p = atomic_load(&g_progress);
    double t = mono_now();
    if (!b || b != who || p != last) {
      who = b;
      last = p;
      since = t;
      continue;
    }
    if ((t - since) * 1000.0 < (double)atomic_load(&g_limit_ms)) continue;
    // the same Python work for the whole limit: stop it (the GIL makes the check and the raise
    // one step for the busy thread)
    PyGILState_STATE s = PyGILState_Ensure();
    if (atomic_load(&g_busy) == b && atomic_load(&g_progress) == p) {
      atomic_store(&g_fired, 1);
      PyThreadState_SetAsyncExc(b, PyExc_TimeoutError);
    }
    PyGILState_Release(s);
    since = t;
  }
  return NULL;
}

static void start_watchdog(void) {
  pthread_t th;
  pthread_attr_t a;
  pthread_attr_init(&a);
  pthread_attr_setdetachstate(&a, PTHREAD_CREATE_DETACHED);
  pthread_create(&th, &a, watchdog, NULL);
  pthread_attr_destroy(&a);
}

// The shim: the package lpyshim (embedded Python sources) as the private package
// _verdant_lpyshim. __init__ runs first; its __all__ lists the modules in the order they run,
// each registered in sys.modules so that their relative imports find each other; `_vd` (the C
// module) is there before them. The last, engine, holds what the C side calls.
#define SHIM_PKG "_verdant_lpyshim"

static const char* shim_source(const char* module) {
  for (int i = 0; i < lpyshim_files_count; i++)
    if (!strcmp(lpyshim_files[i].module, module)) return lpyshim_files[i].source;
  return NULL;
}

// run the shim's module `file` (a name of lpyshim_files) as the module `as`; a new reference
static PyObject* shim_module(const char* as, const char* file) {
  const char* src = shim_source(file);
  if (!src) return PyErr_Format(PyExc_ImportError, "the shim has no module %s", file);
  PyObject* m = PyModule_New(as);
  PyObject* d = m ? PyModule_GetDict(m) : NULL;  // borrowed
  PyObject* pkg = PyUnicode_FromString(SHIM_PKG);
  char fname[96];
  snprintf(fname, sizeof fname, "<verdant lpyshim/%s.py>", file);
  int bad = !d || !pkg || PyDict_SetItemString(d, "__builtins__", PyEval_GetBuiltins()) ||
            PyDict_SetItemString(d, "__package__", pkg) || PyDict_SetItemString(PyImport_GetModuleDict(), as, m);
  Py_XDECREF(pkg);
  if (bad) {
    Py_XDECREF(m);
    return NULL;
  }
  PyObject* code = Py_CompileString(src, fname, Py_file_input);
  PyObject* r = code ? PyEval_EvalCode(code, d, d) : NULL;
  Py_XDECREF(code);
  if (!r) {
    Py_DECREF(m);
    return NULL;
  }
  Py_DECREF(r);
  return m;
}

// load the shim's package and keep the engine module's namespace and its BASE namespace
static int load_shim(void) {
  PyObject* vd = vd_module_create();
  PyObject* pkg = vd ? shim_module(SHIM_PKG, "__init__") : NULL;
  PyObject* all = pkg ? PyObject_GetAttrString(pkg, "__all__") : NULL;
  PyObject* path = PyList_New(0);
  PyObject* eng = NULL;
  int ok = all && PyList_Check(all) && path && !PyObject_SetAttrString(pkg, "__path__", path) &&
           !PyDict_SetItemString(PyImport_GetModuleDict(), SHIM_PKG "._vd", vd) &&
           !PyObject_SetAttrString(pkg, "_vd", vd);
  Py_XDECREF(path);
  for (Py_ssize_t i = 0; ok && i < PyList_GET_SIZE(all); i++) {
    const char* name = PyUnicode_AsUTF8(PyList_GET_ITEM(all, i));
    char as[64];
    snprintf(as, sizeof as, SHIM_PKG ".%s", name ? name : "");
    PyObject* m = name ? shim_module(as, name) : NULL;
    ok = m && !PyObject_SetAttrString(pkg, name, m);
    Py_XDECREF(eng);
    eng = m;
  }
  PyObject* ns = ok && eng ? PyModule_GetDict(eng) : NULL;  // borrowed: the last module's
  PyObject* base = ns ? PyDict_GetItemString(ns, "BASE") : NULL;  // borrowed
  if (ok && (!base || !PyDict_Check(base))) PyErr_SetString(PyExc_RuntimeError, "the shim defines no BASE namespace");
  if (base && PyDict_Check(base)) {
    Py_INCREF(base);
    Py_INCREF(ns);
    g_base = base;
    g_shim = ns;
  }
  Py_XDECREF(eng);
  Py_XDECREF(all);
  Py_XDECREF(pkg);
  Py_XDECREF(vd);
  return g_shim != NULL;
}

static void shim_failed(void) {
  PyObject *t, *v, *tb;
  PyErr_Fetch(&t, &v, &tb);
  PyObject* s = v ? PyObject_Str(v) : NULL;
  const char* m = s ? PyUnicode_AsUTF8(s) : NULL;
  snprintf(g_why, sizeof g_why, "the engine's Python shim failed to load: %s", m ? m : "?");
  Py_XDECREF(s);
  Py_XDECREF(t);
  Py_XDECREF(v);
  Py_XDECREF(tb);
  PyErr_Clear();
  g_state = -1;
}

static void init_once(void) {
  if (Py_IsInitialized()) {
    // inside a Python process: its interpreter, its GIL
    g_hosted = 1;
    PyGILState_STATE s = PyGILState_Ensure();
    if (load_shim()) g_state = 1;
    else shim_failed();
    PyGILState_Release(s);
    return;
  }
  PyConfig c;
  PyConfig_InitPythonConfig(&c);
  c.install_signal_handlers = 0;  // Ctrl-C stays the program's
  c.parse_argv = 0;
  c.user_site_directory = 0;  // the same packages for every user
  c.use_hash_seed = 1;        // str hashes, hence set order, the same in every run
  c.hash_seed = 0;
  c.write_bytecode = 0;
  c.buffered_stdio = 0;
  PyStatus s = PyConfig_SetBytesString(&c, &c.home, VD_PYTHON_HOME);
  if (!PyStatus_Exception(s)) s = PyConfig_SetBytesString(&c, &c.program_name, VD_PYTHON_HOME "/bin/python3");
  if (!PyStatus_Exception(s)) s = Py_InitializeFromConfig(&c);
  PyConfig_Clear(&c);
  if (PyStatus_Exception(s)) {
    snprintf(g_why, sizeof g_why, "CPython did not start (%s%s%s)", s.func ? s.func : "",
             s.func ? ": " : "", s.err_msg ? s.err_msg : "?");
    g_state = -1;
    return;
  }
  if (load_shim()) g_state = 1;
  else shim_failed();
  PyEval_SaveThread();  // release the GIL: threads take it through PyGILState_Ensure
}

int vd_lsys_python_available(char* why, size_t cap) {
  pthread_once(&g_once, init_once);
  if (g_state != 1 && why && cap) snprintf(why, cap, "%s", g_why);
  return g_state == 1;
}

// call shim function name(arg) (a new reference, NULL on error); arg Nullable means None
static PyObject* shim_call(const char* name, PyObject* arg) {
  PyObject* f = PyDict_GetItemString(g_shim, name);  // borrowed
  if (!f) {
    PyErr_Format(PyExc_RuntimeError, "shim function %s missing", name);
    return NULL;
  }
  return PyObject_CallOneArg(f, arg ? arg : Py_None);
}

void lsys_py_enter(vd_lsystem* ls) {
  if (tl_depth++ > 0) return;
  pthread_once(&g_once, init_once);
  tl_saved = NULL;
  // a caller that holds the GIL (the verdant package) lets it go while waiting for the mutex,
  // or a thread holding the mutex could never take the GIL back
  if (g_hosted && PyGILState_Check()) tl_saved = PyEval_SaveThread();
  pthread_mutex_lock(&g_mutex);
  tl_gil = PyGILState_Ensure();
  g_cur = ls;
  if (g_state != 1 || !ls || !ls->py) return;
  pthread_once(&g_wd_once, start_watchdog);
  long long ms = ls->max_ops / 10000;
  atomic_store(&g_limit_ms, ms < 1000 ? 1000 : ms);
  atomic_store(&g_fired, 0);
  progress();
  atomic_store(&g_busy, PyThread_get_thread_ident());
  // random's state: this lsystem's
  if (g_hosted) {
    tl_host = shim_call("_vd_swap", ls->py->rstate);
    Py_CLEAR(ls->py->rstate);
    if (!tl_host) PyErr_Clear();
  } else if (g_last != ls) {
    if (g_last && g_last->py) {
      Py_XDECREF(g_last->py->rstate);
      g_last->py->rstate = shim_call("_vd_swap", ls->py->rstate);
      if (!g_last->py->rstate) PyErr_Clear();
    } else if (ls->py->rstate) {
      PyObject* r = shim_call("_vd_swap", ls->py->rstate);
      if (!r) PyErr_Clear();
      Py_XDECREF(r);
    }
    Py_CLEAR(ls->py->rstate);
    g_last = ls;
  }
}

void lsys_py_leave(vd_lsystem* ls) {
  if (--tl_depth > 0) return;
  if (atomic_load(&g_busy)) {
    unsigned long me = atomic_exchange(&g_busy, 0);
    if (atomic_load(&g_fired)) PyThreadState_SetAsyncExc(me, NULL);  // nothing left pending
  }
  if (g_state == 1 && ls && ls->py && g_hosted) {
    // give the host its random state back, keep this lsystem's
    Py_XDECREF(ls->py->rstate);
    ls->py->rstate = shim_call("_vd_swap", tl_host);
    if (!ls->py->rstate) PyErr_Clear();
    Py_CLEAR(tl_host);
  }
  g_cur = NULL;
  PyGILState_Release(tl_gil);
  pthread_mutex_unlock(&g_mutex);
  if (tl_saved) PyEval_RestoreThread(tl_saved);
  tl_saved = NULL;
}

// ---------------------------------------------------------------------------------------------
// errors: a Python exception becomes a vd_error at the file's line

static vd_status status_of(PyObject* type) {
  if (PyErr_GivenExceptionMatches(type, PyExc_SyntaxError)) return VD_ERR_SYNTAX;
  if (PyErr_GivenExceptionMatches(type, PyExc_NameError)) return VD_ERR_NAME;
  // a PlantGL / L-Py name the shim does not have (lpyshim/engine.py _NotInShim): a refusal
  PyObject* nis = g_shim ? PyDict_GetItemString(g_shim, "_NotInShim") : NULL;  // borrowed
  if (nis && PyErr_GivenExceptionMatches(type, nis)) return VD_ERR_UNSUPPORTED;
  if (PyErr_GivenExceptionMatches(type, PyExc_AttributeError)) return VD_ERR_NAME;
  if (PyErr_GivenExceptionMatches(type, PyExc_TypeError)) return VD_ERR_TYPE;
  if (PyErr_GivenExceptionMatches(type, PyExc_AssertionError)) return VD_ERR_ASSERT;
  if (PyErr_GivenExceptionMatches(type, PyExc_MemoryError)) return VD_ERR_NOMEM;
  if (PyErr_GivenExceptionMatches(type, PyExc_RecursionError)) return VD_ERR_LIMIT;
  if (PyErr_GivenExceptionMatches(type, PyExc_ImportError)) return VD_ERR_UNSUPPORTED;
  if (PyErr_GivenExceptionMatches(type, PyExc_NotImplementedError)) return VD_ERR_UNSUPPORTED;
  if (PyErr_GivenExceptionMatches(type, PyExc_OSError)) return VD_ERR_IO;
  return VD_ERR_VALUE;
}

// ---------------------------------------------------------------------------------------------
// error places: the Python engine compiles rule bodies and successors as translated text
// (`produce B(x)` becomes `return __vd_p(id, (x,))`), so a column in that text is found again in
// the file's line: the failing expression's text, its k-th occurrence in the translated line
// taken as its k-th occurrence in the file's line

// line `line` (1-based) of text into buf (without its newline); 0 when absent
static int text_line(const char* text, size_t len, int line, char* buf, size_t cap) {
  size_t at = 0;
  for (int l = 1; l < line && at < len; at++)
    if (text[at] == '\n') l++;
  if (at >= len && line > 1) return 0;
  size_t e = at;
  while (e < len && text[e] != '\n') e++;
  size_t n = e - at < cap - 1 ? e - at : cap - 1;
  memcpy(buf, text + at, n);
  buf[n] = 0;
  return 1;
}

// line `line` of the file `path` into buf; 0 when it cannot be read
static int file_line(const char* path, int line, char* buf, size_t cap) {
  FILE* f = path && *path ? fopen(path, "rb") : NULL;
  if (!f) return 0;
  int l = 1, ok = 0;
  while (fgets(buf, (int)cap, f)) {
    size_t n = strlen(buf);
    int whole = n > 0 && buf[n - 1] == '\n';
    if (l == line) {
      while (n > 0 && (buf[n - 1] == '\n' || buf[n - 1] == '\r')) buf[--n] = 0;
      ok = 1;
      break;
    }
    if (whole) l++;
  }
  fclose(f);
  return ok;
}

// the file column (1-based) of the expression at translated columns [c0, c1) of file line
// `line`; 0 when it cannot be told
static int file_col(const vd_lsystem* ls, int line, int c0, int c1) {
  static char gen[1024], orig[1024];
  const lsys_py* py = ls->py;
  int found = 0;
  for (int k = 0; py && k < py->nfn && !found; k++) {
    const pychunk* ch = &py->fn[k];
    if (ch->src && line >= ch->line) found = text_line(ch->src, ch->len, line - ch->line + 1, gen, sizeof gen);
  }
  if (!found || !file_line(ls->file, line, orig, sizeof orig)) return found ? 0 : c0 + 1;
  int glen = (int)strlen(gen);
  if (c0 < 0 || c1 <= c0 || c1 > glen) return 0;
  // the k-th occurrence of the expression's text in the translated line
  int tlen = c1 - c0, k = 0;
  for (int i = 0; i < c0; i++)
    if (!strncmp(gen + i, gen + c0, (size_t)tlen)) k++;
  for (const char* p = orig; *p; p++)
    if (!strncmp(p, gen + c0, (size_t)tlen) && k-- == 0) return (int)(p - orig) + 1;
  return 0;
}

// Is path a module beside the .lpy file (under its folder, not the file itself)?
static int beside_model(const vd_lsystem* ls, const char* path) {
  char dir[4096];
  if (!path || path[0] != '/' || !strcmp(path, ls->file) || !realpath(ls->file, dir)) return 0;
  char* slash = strrchr(dir, '/');
  if (!slash) return 0;
  slash[1] = 0;
  size_t n = strlen(dir);
  return !strncmp(path, dir, n) && !strstr(path + n, "/site-packages/") && !strstr(path + n, "/dist-packages/");
}

// path shown as the user named the model's folder (dir/helper.py for dir/model.lpy)
static void shown_path(const vd_lsystem* ls, const char* path, char* out, size_t cap) {
  char dir[4096];
  const char* slash = realpath(ls->file, dir) ? strrchr(dir, '/') : NULL;
  const char* given = strrchr(ls->file, '/');
  size_t n = slash ? (size_t)(slash - dir) + 1 : 0;
  if (slash && !strncmp(path, dir, n))
    snprintf(out, cap, "%.*s%s", given ? (int)(given - ls->file) + 1 : 0, ls->file, path + n);
  else
    snprintf(out, cap, "%s", path);
}

// one traceback frame: its file, line and (1-based, exact) column; 0 when not known
static const char* frame_place(PyObject* t, PyObject** fname, int* line, int* c0, int* c1) {
  PyObject* frame = PyObject_GetAttrString(t, "tb_frame");
  PyObject* lineno = PyObject_GetAttrString(t, "tb_lineno");
  PyObject* lasti = PyObject_GetAttrString(t, "tb_lasti");
  PyObject* code = frame ? PyObject_GetAttrString(frame, "f_code") : NULL;
  *fname = code ? PyObject_GetAttrString(code, "co_filename") : NULL;
  const char* fs = *fname && PyUnicode_Check(*fname) ? PyUnicode_AsUTF8(*fname) : NULL;
  *line = lineno && PyLong_Check(lineno) ? (int)PyLong_AsLong(lineno) : 0;
  *c0 = *c1 = -1;
  int l0, l1, a, b;
  if (lasti && PyLong_Check(lasti) && code && PyCode_Check(code) &&
      PyCode_Addr2Location((PyCodeObject*)code, (int)PyLong_AsLong(lasti), &l0, &a, &l1, &b) && l0 == *line && a >= 0) {
    *c0 = a;
    *c1 = l1 == l0 ? b : -1;
  }
  Py_XDECREF(frame);
  Py_XDECREF(lineno);
  Py_XDECREF(lasti);
  Py_XDECREF(code);
  PyErr_Clear();
  return fs;
}

// Turn the pending exception into ls->err: the innermost traceback frame in the .lpy file gives
// the line and column; the message is "Type: text". Returns the status.
static vd_status py_error(vd_lsystem* ls) {
  if (ls->err && ls->err->status) {
    // recorded on the C side (a limit, out of memory) and carried through Python
    PyErr_Clear();
    return ls->err->status;
  }
  PyObject *type, *val, *tb;
  PyErr_Fetch(&type, &val, &tb);
  if (!type) return vm_error(ls, VD_ERR_VALUE, 0, 0, "Python error without an exception");
  PyErr_NormalizeException(&type, &val, &tb);
  if (tb && val) PyException_SetTraceback(val, tb);
  vd_status st = status_of(type);
  if (PyErr_GivenExceptionMatches(type, PyExc_TimeoutError) && atomic_load(&g_fired)) st = VD_ERR_LIMIT;
  int line = 0, col = 0;
  if (PyErr_GivenExceptionMatches(type, PyExc_SyntaxError) && val) {
    PyObject* l = PyObject_GetAttrString(val, "lineno");
    PyObject* o = PyObject_GetAttrString(val, "offset");
    PyObject* f = PyObject_GetAttrString(val, "filename");
    if (l && PyLong_Check(l)) line = (int)PyLong_AsLong(l);
    if (o && PyLong_Check(o)) col = (int)PyLong_AsLong(o);
    const char* fs = f && PyUnicode_Check(f) ? PyUnicode_AsUTF8(f) : NULL;
    if (fs && strcmp(fs, ls->file) != 0) line = col = 0;  // in another module
    Py_XDECREF(l);
    Py_XDECREF(o);
    Py_XDECREF(f);
    PyErr_Clear();
  }
  // the innermost frame of the traceback in the .lpy file, and the innermost one after it in a
  // module beside the file (a helper the file imports), where the error is then reported
  char helper[512] = "";
  int hline = 0, hcol = 0;
  for (PyObject* t = tb; t && t != Py_None;) {
    PyObject* fname = NULL;
    int fl, c0, c1;
    const char* fs = frame_place(t, &fname, &fl, &c0, &c1);
    if (fs && !strcmp(fs, ls->file) && fl > 0) {
      line = fl;
      col = c0 >= 0 ? file_col(ls, fl, c0, c1) : 0;
      helper[0] = 0;
    } else if (fs && line && beside_model(ls, fs)) {
      shown_path(ls, fs, helper, sizeof helper);
      hline = fl;
      hcol = c0 >= 0 ? c0 + 1 : 0;
    }
    Py_XDECREF(fname);
    PyObject* next = PyObject_GetAttrString(t, "tb_next");
    if (t != tb) Py_DECREF(t);
    t = next;
    PyErr_Clear();
  }
  const char* tn = ((PyTypeObject*)type)->tp_name;
  PyObject* s = val ? PyObject_Str(val) : NULL;
  const char* msg = s ? PyUnicode_AsUTF8(s) : NULL;
  if (!msg) PyErr_Clear();
  // a limit or an unsupported feature keeps verdant's wording
  char text[512];
  if (st == VD_ERR_LIMIT && atomic_load(&g_fired))
    snprintf(text, sizeof text,
             "the Python code made no progress for %.0f s (a loop that never ends?); --max-ops %lld allows "
             "max_ops / 10^7 seconds",
             (double)atomic_load(&g_limit_ms) / 1000.0, (long long)ls->max_ops);
  else if (st == VD_ERR_UNSUPPORTED)
    snprintf(text, sizeof text, "unsupported: %s: %s", tn, msg ? msg : "");
  else if (!msg || !*msg)
    snprintf(text, sizeof text, "%s", PyErr_GivenExceptionMatches(type, PyExc_AssertionError) ? "assertion failed" : tn);
  else
    snprintf(text, sizeof text, "%s: %s", tn, msg);
  // failed in a module beside the file: its place, and the file's line that called it
  if (helper[0] && ls->err && ls->err->status == VD_OK)
    vd_error_set(ls->err, st, helper, hline, hcol, "%s (called from %s:%d:%d)", text, ls->file, line, col);
  else
    vm_error(ls, st, line, col, "%s", text);
  Py_XDECREF(s);
  Py_XDECREF(type);
  Py_XDECREF(val);
  Py_XDECREF(tb);
  return st;
}

static vd_status not_available(vd_lsystem* ls) {
  return vm_error(ls, VD_ERR_UNSUPPORTED, 0, 0, "unsupported: the Python engine is not available (%s)", g_why);
}

// ---------------------------------------------------------------------------------------------
// objects in L-strings

// Python str of string id (borrowed from the cache; NULL with an exception on failure)
static PyObject* str_object(vd_lsystem* ls, int id) {
  lsys_py* py = ls->py;
  if (id >= py->capstrobj) {
    int old = py->capstrobj;
    if (!vd_grow((void**)&py->strobj, &py->capstrobj, id + 1, sizeof(PyObject*))) return PyErr_NoMemory();
    memset(py->strobj + old, 0, sizeof(PyObject*) * (size_t)(py->capstrobj - old));
  }
  if (!py->strobj[id]) py->strobj[id] = PyUnicode_FromString(ls->str[id]);
  return py->strobj[id];
}

// the Python value of a module parameter (new reference)
static PyObject* param_object(vd_lsystem* ls, double d) {
  int sid = lsys_unbox_str(d);
  if (sid >= 0) {
    PyObject* s = sid < ls->nstr ? str_object(ls, sid) : NULL;
    if (!s) {
      if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "bad string parameter");
      return NULL;
    }
    Py_INCREF(s);
    return s;
  }
  uint32_t id;
  unsigned ep;
  if (lsys_unbox_obj(d, &id, &ep)) {
    lsys_py* py = ls->py;
    if (ep == (py->epoch & 0xff) && (int)id < py->nobj && py->obj[id]) {
      Py_INCREF(py->obj[id]);
      return py->obj[id];
    }
    return py_none();  // a handle of an older derivation
  }
  if (d == floor(d) && fabs(d) < 9007199254740992.0) return PyLong_FromDouble(d);
  return PyFloat_FromDouble(d);
}

// the Python value of a frame value (new reference)
static PyObject* value_object(vd_lsystem* ls, value v) {
  switch (v.t) {
    case V_INT: return PyLong_FromDouble(v.n);
    case V_FLOAT: return PyFloat_FromDouble(v.n);
    case V_BOOL: return PyBool_FromLong(v.n != 0);
    case V_STR: {
      PyObject* s = str_object(ls, (int)v.n);
      Py_XINCREF(s);
      return s;
    }
    case V_OBJ: {
      uint32_t id = (uint32_t)v.n;
      lsys_py* py = ls->py;
      if ((int)id < py->nobj && py->obj[id]) {
        Py_INCREF(py->obj[id]);
        return py->obj[id];
      }
      return py_none();
    }
    case V_LIST:
    case V_DICT: {
      // *args, **kwds and x(...) variables bound by the rule's match (lsys_match.c)
      const struct mlist* l = &ls->mlist[(int)v.n];
      PyObject* o = v.t == V_LIST ? PyList_New(l->n) : PyDict_New();
      for (int k = 0; o && k < l->n; k += v.t == V_LIST ? 1 : 2) {
        PyObject* a = value_object(ls, ls->mval[l->at + k]);
        PyObject* b = v.t == V_DICT && a ? value_object(ls, ls->mval[l->at + k + 1]) : NULL;
        if (!a || (v.t == V_DICT && (!b || PyDict_SetItem(o, a, b) < 0))) {
          Py_XDECREF(a);
          Py_XDECREF(b);
          Py_CLEAR(o);
        } else if (v.t == V_LIST) {
          PyList_SET_ITEM(o, k, a);
        } else {
          Py_DECREF(a);
          Py_DECREF(b);
        }
      }
      return o;
    }
    default: return py_none();
  }
}

// keep o (borrowed) in the object table; its boxed handle in *out
static int keep_object(vd_lsystem* ls, PyObject* o, double* out) {
  lsys_py* py = ls->py;
  int id;
  if (py->nfree) {
    id = py->freel[--py->nfree];
  } else {
    if (py->nobj >= (1 << 30)) {
      PyErr_SetString(PyExc_MemoryError, "more than 2^30 object parameters");
      return 0;
    }
    if (!vd_grow((void**)&py->obj, &py->capobj, py->nobj + 1, sizeof(PyObject*))) {
      PyErr_NoMemory();
      return 0;
    }
    id = py->nobj++;
  }
  Py_INCREF(o);
  py->obj[id] = o;
  *out = lsys_box_obj((uint32_t)id, py->epoch & 0xff);
  return 1;
}

// a Python value as a module parameter: numbers stay numbers, str a string id, the rest a
// handle; 0 with an exception on failure
static int object_param(vd_lsystem* ls, PyObject* o, double* out) {
  if (PyFloat_Check(o)) {  // float and its subclasses (numpy.float64)
    *out = PyFloat_AS_DOUBLE(o);
    return 1;
  }
  if (PyLong_Check(o)) {  // int, bool
    int overflow = 0;
    long long v = PyLong_AsLongLongAndOverflow(o, &overflow);
    if (!overflow && v > -(1LL << 53) && v < (1LL << 53)) {
      *out = (double)v;
      return 1;
    }
    PyErr_Clear();
    return keep_object(ls, o, out);  // an int too large for a double stays an object
  }
  if (PyUnicode_Check(o)) {
    Py_ssize_t n;
    const char* s = PyUnicode_AsUTF8AndSize(o, &n);
    if (!s) return 0;
    if (n > (1 << 20)) {
      PyErr_SetString(PyExc_ValueError, "a string parameter longer than 1 MiB");
      return 0;
    }
    int id = str_intern(ls, s, (int)n);
    if (id < 0) {
      PyErr_SetString(PyExc_MemoryError, id == -2 ? "the strings of the model exceed 64 MiB" : "out of memory");
      return 0;
    }
    *out = lsys_box_str(id);
    return 1;
  }
  if (PyIndex_Check(o) && !PySequence_Check(o)) {  // numpy integer scalars
    PyObject* i = PyNumber_Index(o);
    if (!i) return 0;
    int ok = object_param(ls, i, out);
    Py_DECREF(i);
    return ok;
  }
  return keep_object(ls, o, out);
}

void lsys_py_gc(vd_lsystem* ls, const vd_lstring* s) {
  lsys_py* py = ls->py;
  if (!py || !py->nobj) return;
  // out of memory for the scratch: keep everything this time
  if (!vd_grow((void**)&py->mark, &py->capmark, py->nobj, 1) ||
      !vd_grow((void**)&py->freel, &py->capfree, py->nobj, sizeof(int)))
    return;
  memset(py->mark, 0, (size_t)py->nobj);
  int64_t nv = s->n ? s->par[s->n] : 0;
  unsigned ep = py->epoch & 0xff;
  for (int64_t k = 0; k < nv; k++) {
    uint32_t id;
    unsigned e;
    if (isnan(s->val[k]) && lsys_unbox_obj(s->val[k], &id, &e) && e == ep && (int)id < py->nobj) py->mark[id] = 1;
  }
  // release the unmarked; the table shrinks to its last marked slot, the rest is the free list
  int n = py->nobj;
  while (n > 0 && !py->mark[n - 1]) {
    Py_CLEAR(py->obj[n - 1]);
    n--;
  }
  py->nobj = n;
  py->nfree = 0;
  for (int i = n - 1; i >= 0; i--)
    if (!py->mark[i]) {
      Py_CLEAR(py->obj[i]);
      py->freel[py->nfree++] = i;
    }
}

void lsys_py_reset_objects(vd_lsystem* ls) {
  lsys_py* py = ls->py;
  if (!py) return;
  for (int i = 0; i < py->nobj; i++) Py_CLEAR(py->obj[i]);
  py->nobj = py->nfree = 0;
  py->epoch++;
}

// ---------------------------------------------------------------------------------------------
// the _vd module: what the translated code and the shim call back into

// the lsystem running Python now, or NULL with an exception
static vd_lsystem* current(void) {
  if (!g_cur || !g_cur->py) {
    PyErr_SetString(PyExc_RuntimeError, "no L-system is running");
    return NULL;
  }
  return g_cur;
}

// an error already recorded in ls->err travels through Python as this exception
static PyObject* vd_abort(void) {
  PyErr_SetString(PyExc_RuntimeError, "verdant: derivation stopped");
  return NULL;
}

// parameter values in s (an empty string may have no arrays yet)
static int64_t lstr_nval(const vd_lstring* s) { return s->par ? s->par[s->n] : 0; }

// append the template tid with parameter tuples args[0..nargs) to out
// newmodule('B', ...) (L-Py's `new`): the module named by the first parameter, which must be a
// string; *sym gets its symbol. Returns 1 (the parameters left start at 1), 0 with an exception.
static Py_ssize_t new_module(vd_lsystem* ls, PyObject* tup, int* sym) {
  PyObject* name = tup && PyTuple_GET_SIZE(tup) ? PyTuple_GET_ITEM(tup, 0) : NULL;
  Py_ssize_t len = 0;
  const char* s = name && PyUnicode_Check(name) ? PyUnicode_AsUTF8AndSize(name, &len) : NULL;
  if (!s || !len || len > INT_MAX) {
    if (!PyErr_Occurred())
      PyErr_SetString(PyExc_TypeError, "newmodule(name, ...): the first parameter is the new module's name (a string)");
    return 0;
  }
  int id = sym_intern(ls, s, (int)len, 0);
  if (id < 0) {
    PyErr_NoMemory();
    return 0;
  }
  *sym = id;
  return 1;
}

static int emit(vd_lsystem* ls, vm_out* out, int tid, PyObject* const* args, Py_ssize_t nargs) {
  lsys_py* py = ls->py;
  if (tid < 0 || tid >= py->ntp) {
    PyErr_SetString(PyExc_ValueError, "bad template id");
    return 0;
  }
  const tmpl* t = py->tp[tid];
  int nmod = t && !t->drop ? t->n : 0;  // `produce * ...` deletes the module (L-Py)
  vd_lstring* s = out->s;
  if (s->n + nmod > out->max_modules) {
    vm_error(ls, VD_ERR_LIMIT, nmod ? t->mod[0].line : 0, nmod ? t->mod[0].col : 0,
             "the L-string would exceed %lld modules (raise --max-modules)", (long long)out->max_modules);
    return 0;
  }
  if (!nmod) return 1;
  // count the parameters
  int64_t nval = 0;
  Py_ssize_t a = 0;
  for (int m = 0; m < nmod; m++) {
    if (!t->mod[m].nparam) continue;
    if (a >= nargs || !PyTuple_Check(args[a])) {
      PyErr_SetString(PyExc_TypeError, "bad produce arguments");
      return 0;
    }
    nval += PyTuple_GET_SIZE(args[a++]);
  }
  if (!lstr_reserve(s, s->n + nmod, lstr_nval(s) + nval)) {
    PyErr_NoMemory();
    return 0;
  }
  a = 0;
  for (int m = 0; m < nmod; m++) {
    int64_t n = s->n, v = s->par[n];
    s->sym[n] = t->mod[m].sym;
    if (s->src) s->src[n] = out->src;
    if (s->line) s->line[n] = t->mod[m].line;
    PyObject* tup = t->mod[m].nparam ? args[a++] : NULL;
    Py_ssize_t k0 = 0;
    if (sym_canon(ls, t->mod[m].sym) == VD_SYM_NEW && !(k0 = new_module(ls, tup, &s->sym[n]))) return 0;
    if (tup) {
      Py_ssize_t np = PyTuple_GET_SIZE(tup);
      for (Py_ssize_t k = k0; k < np; k++)
        if (!object_param(ls, PyTuple_GET_ITEM(tup, k), &s->val[v + k - k0])) return 0;
      v += np - k0;
    }
    s->par[n + 1] = v;
    s->n = n + 1;
  }
  return 1;
}

// _vd.p(tid, (params), ...): produce / nproduce into the current output; True
// produce A(a, **d): the values of dict d in the order module A(x, y) declares its parameter
// names, after the npos given by position (L-Py places keyword parameters by name); every name
// needs a value, every key a name not given already
static PyObject* vd_kw(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  if (nargs != 3 || !PyLong_Check(args[0]) || !PyLong_Check(args[1])) {
    PyErr_SetString(PyExc_TypeError, "bad produce call");
    return NULL;
  }
  int sym = (int)PyLong_AsLong(args[0]), npos = (int)PyLong_AsLong(args[1]);
  const char* mod = vd_lsys_symbol_name(ls, sym);
  PyObject* d = args[2];
  if (!PyDict_Check(d))
    return PyErr_Format(PyExc_TypeError, "produce %s(**...) needs a dict, got %s", mod, Py_TYPE(d)->tp_name);
  int nn;
  const int* names = lsys_declared_names(ls, sym, &nn);
  if (!nn)
    return PyErr_Format(PyExc_TypeError, "produce %s(**...): module %s declares no parameter names (module %s(x, y))",
                        mod, mod, mod);
  int rest = nn > npos ? nn - npos : 0;
  PyObject* t = PyTuple_New(rest);
  if (!t) return NULL;
  for (int k = 0; k < rest; k++) {
    PyObject* v = PyDict_GetItemString(d, ls->str[names[npos + k]]);  // borrowed
    if (!v) {
      Py_DECREF(t);
      return PyErr_Format(PyExc_TypeError, "produce %s(**...): no value for parameter '%s'", mod,
                          ls->str[names[npos + k]]);
    }
    Py_INCREF(v);
    PyTuple_SET_ITEM(t, k, v);
  }
  if (PyDict_Size(d) != rest) {
    // a key that is not a declared name, or names a parameter given by position
    PyObject *key, *val;
    Py_ssize_t pos = 0;
    while (PyDict_Next(d, &pos, &key, &val)) {
      const char* ks = PyUnicode_Check(key) ? PyUnicode_AsUTF8(key) : NULL;
      int at = -1;
      for (int k = 0; ks && at < 0 && k < nn; k++)
        if (!strcmp(ks, ls->str[names[k]])) at = k;
      if (at < npos) {
        Py_DECREF(t);
        PyErr_Clear();
        if (at >= 0) return PyErr_Format(PyExc_TypeError, "produce %s(**...): parameter %R given twice", mod, key);
        return PyErr_Format(PyExc_TypeError, "produce %s(**...): module %s has no parameter %R", mod, mod, key);
      }
    }
  }
  return t;
}

static PyObject* vd_p(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  if (!ls->py->out) {
    PyErr_SetString(PyExc_RuntimeError, "produce outside a rule or the axiom");
    return NULL;
  }
  if (nargs < 1 || !PyLong_Check(args[0])) {
    PyErr_SetString(PyExc_TypeError, "bad produce call");
    return NULL;
  }
  ls->py->out->nproduced = 1;
  progress();
  if (!emit(ls, ls->py->out, (int)PyLong_AsLong(args[0]), args + 1, nargs - 1))
    return ls->err && ls->err->status ? vd_abort() : NULL;
  return py_true();
}

// the modules of s[a..b) as a list of (name, (params...)) (new reference)
static PyObject* items_of(vd_lsystem* ls, const vd_lstring* s, int64_t a, int64_t b) {
  PyObject* list = PyList_New((Py_ssize_t)(b - a));
  if (!list) return NULL;
  for (int64_t i = a; i < b; i++) {
    int np = vd_lstring_nparam(s, i);
    PyObject* params = PyTuple_New(np);
    PyObject* name = params ? PyUnicode_FromString(vd_lsys_symbol_name(ls, s->sym[i])) : NULL;
    if (!name) {
      Py_XDECREF(params);
      Py_DECREF(list);
      return NULL;
    }
    for (int k = 0; k < np; k++) {
      PyObject* o = param_object(ls, s->val[s->par[i] + k]);
      if (!o) {
        Py_DECREF(name);
        Py_DECREF(params);
        Py_DECREF(list);
        return NULL;
      }
      PyTuple_SET_ITEM(params, k, o);
    }
    PyObject* it = PyTuple_Pack(2, name, params);
    Py_DECREF(name);
    Py_DECREF(params);
    if (!it) {
      Py_DECREF(list);
      return NULL;
    }
    PyList_SET_ITEM(list, (Py_ssize_t)(i - a), it);
  }
  return list;
}

// _vd.mk(tid, (params), ...): the modules of a template as items (makestring)
static PyObject* vd_mk(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  if (nargs < 1 || !PyLong_Check(args[0])) {
    PyErr_SetString(PyExc_TypeError, "bad makestring call");
    return NULL;
  }
  vd_lstring tmp = vd_lstring_empty();
  vm_out vo = {&tmp, 0, INT64_MAX, 0, 0};
  PyObject* r = NULL;
  if (lstr_reserve(&tmp, 16, 16) && emit(ls, &vo, (int)PyLong_AsLong(args[0]), args + 1, nargs - 1))
    r = items_of(ls, &tmp, 0, tmp.n);
  else if (!PyErr_Occurred())
    PyErr_NoMemory();
  vd_lstring_free(&tmp);
  return r;
}

// append items (a list of (name, params)) to s, modules recorded as coming from src
static int append_items(vd_lsystem* ls, vd_lstring* s, PyObject* items, int64_t src, int64_t max_modules) {
  PyObject* seq = PySequence_Fast(items, "a list of modules expected");
  if (!seq) return 0;
  Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
  int ok = 1;
  for (Py_ssize_t i = 0; i < n && ok; i++) {
    PyObject* it = PySequence_Fast_GET_ITEM(seq, i);
    PyObject *name, *params;
    if (!PyTuple_Check(it) || PyTuple_GET_SIZE(it) != 2 || !PyUnicode_Check(name = PyTuple_GET_ITEM(it, 0)) ||
        !PyTuple_Check(params = PyTuple_GET_ITEM(it, 1))) {
      PyErr_SetString(PyExc_TypeError, "a module must be (name, params)");
      ok = 0;
      break;
    }
    Py_ssize_t nl;
    const char* nm = PyUnicode_AsUTF8AndSize(name, &nl);
    int sym = nm && nl > 0 && nl < 256 ? sym_intern(ls, nm, (int)nl, 0) : -1;
    if (sym < 0) {
      if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "bad module name");
      ok = 0;
      break;
    }
    Py_ssize_t np = PyTuple_GET_SIZE(params);
    if (s->n + 1 > max_modules) {
      vm_error(ls, VD_ERR_LIMIT, 0, 0, "the L-string would exceed %lld modules (raise --max-modules)",
               (long long)max_modules);
      ok = 0;
      break;
    }
    if (!lstr_reserve(s, s->n + 1, lstr_nval(s) + np)) {
      PyErr_NoMemory();
      ok = 0;
      break;
    }
    int64_t m = s->n, v = s->par[m];
    s->sym[m] = sym;
    if (s->src) s->src[m] = src < 0 ? m : src;
    if (s->line) s->line[m] = 0;  // made by Python code: no line of the file
    for (Py_ssize_t k = 0; k < np && ok; k++) ok = object_param(ls, PyTuple_GET_ITEM(params, k), &s->val[v + k]);
    if (!ok) break;
    s->par[m + 1] = v + np;
    s->n = m + 1;
  }
  Py_DECREF(seq);
  return ok;
}

// _vd.parse(text): the modules of an L-string text as (name, [parameter sources])
static PyObject* vd_parse(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  Py_ssize_t n;
  const char* text = PyUnicode_AsUTF8AndSize(arg, &n);
  if (!text) return NULL;
  vd_error e = {0}, *saved = ls->err;
  ls->err = &e;
  tmpl* t = lsys_parse_tmpl_text(ls, text, (int)n, 1, 1);
  ls->err = saved;
  if (!t) {
    PyErr_Format(PyExc_ValueError, "bad L-string '%s': %s", text, e.msg);
    return NULL;
  }
  PyObject* list = PyList_New(t->n);
  for (int m = 0; list && m < t->n; m++) {
    PyObject* params = PyList_New(t->mod[m].nparam);
    for (int k = 0; params && k < t->mod[m].nparam; k++)
      PyList_SET_ITEM(params, k, PyUnicode_FromString(ls->str[(int)t->mod[m].param[k]->k.n]));
    PyObject* it = params ? Py_BuildValue("(sN)", vd_lsys_symbol_name(ls, t->mod[m].sym), params) : NULL;
    if (!it) {
      Py_DECREF(list);
      return NULL;
    }
    PyList_SET_ITEM(list, m, it);
  }
  return list;
}

// _vd.append(items): nsproduce of an L-string object into the current output
static PyObject* vd_append(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  vm_out* out = ls->py->out;
  if (!out) {
    PyErr_SetString(PyExc_RuntimeError, "nsproduce outside a rule or the axiom");
    return NULL;
  }
  out->nproduced = 1;
  if (!append_items(ls, out->s, arg, out->src, out->max_modules)) return ls->err && ls->err->status ? vd_abort() : NULL;
  return py_none();
}

static PyObject* vec_tuple(vd_vec3 v) { return Py_BuildValue("(ddd)", v.x, v.y, v.z); }

// a primitive of the hook's scene: (kind, module, parent, ...) as _vd_build_scene reads it
static PyObject* scene_prims(const vd_plant_spec* p) {
  PyObject* list = PyList_New(0);
  for (int i = 0; list && i < p->nseg; i++) {
    const vd_segment_spec* g = &p->seg[i];
    PyObject* it = Py_BuildValue("(sLiNNddN)", "seg", (long long)g->module, g->parent, vec_tuple(p->node[g->node0]),
                                 vec_tuple(p->node[g->node1]), g->r0, g->r1, vec_tuple(g->up));
    if (!it || PyList_Append(list, it)) Py_CLEAR(list);
    Py_XDECREF(it);
  }
  for (int i = 0; list && i < p->nsphere; i++) {
    const vd_sphere_spec* g = &p->sphere[i];
    PyObject* it =
        Py_BuildValue("(sLiNd)", "sph", (long long)g->module, g->parent, vec_tuple(g->center), g->radius);
    if (!it || PyList_Append(list, it)) Py_CLEAR(list);
    Py_XDECREF(it);
  }
  for (int i = 0; list && i < p->nmesh; i++) {
    const vd_mesh_spec* m = &p->mesh[i];
    PyObject* v = PyList_New(m->nvert);
    PyObject* t = PyList_New(m->ntri);
    for (int k = 0; v && k < m->nvert; k++) PyList_SET_ITEM(v, k, vec_tuple(p->vert[m->vert_start + k]));
    for (int k = 0; t && k < m->ntri; k++) {
      const int* q = &p->tri[3 * (m->tri_start + k)];
      PyList_SET_ITEM(t, k, Py_BuildValue("(iii)", q[0], q[1], q[2]));
    }
    PyObject* it = v && t ? Py_BuildValue("(sLiNNi)", "mesh", (long long)m->module, m->parent, v, t, m->closed) : NULL;
    if (!it) {
      Py_XDECREF(v);
      Py_XDECREF(t);
    }
    if (!it || PyList_Append(list, it)) Py_CLEAR(list);
    Py_XDECREF(it);
  }
  return list;
}

// _vd.scene(): the primitives the hook's string draws
static PyObject* vd_scene(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  if (!ls->py->hook_s) {
    PyErr_SetString(PyExc_RuntimeError, "the scene is only known inside a hook");
    return NULL;
  }
  // an animation drew the frame's scene before the hook: the same primitives, not drawn again
  if (ls->py->hook_plant) return scene_prims(ls->py->hook_plant);
  vd_plant_spec* p = vd_plant_spec_create();
  if (!p) return PyErr_NoMemory();
  vm_out* saved = ls->py->out;
  vd_status st = lsys_scene(ls, ls->py->hook_s, p);
  ls->py->out = saved;
  PyObject* r = st ? NULL : scene_prims(p);
  vd_plant_spec_destroy(p);
  if (st) return vd_abort();
  return r;
}

static PyObject* vd_use_group(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  long g = PyLong_AsLong(arg);
  if (g == -1 && PyErr_Occurred()) return NULL;
  ls->current_group = (int)g;
  return py_none();
}

static PyObject* vd_get_group(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  return ls ? PyLong_FromLong(ls->current_group) : NULL;
}

static PyObject* vd_iteration(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  return ls ? PyLong_FromLong(ls->iteration) : NULL;
}

static PyObject* vd_stop(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  ls->stop_requested = 1;
  return py_none();
}

// backward() / forward(): the direction of the next steps (the derivation loop reads it)
static PyObject* vd_set_backward(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  int b = PyObject_IsTrue(arg);
  if (b < 0) return NULL;
  ls->backward = b;
  return py_none();
}

static PyObject* vd_is_backward(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  return ls ? PyBool_FromLong(ls->backward) : NULL;
}

// isFrameDisplayed(): the step is the last one, or any step of an animation
static PyObject* vd_frame_displayed(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  return ls ? PyBool_FromLong(ls->frame_displayed) : NULL;
}

// the (name, params) items of a native lsystem's string: numbers and strings
static PyObject* native_items(const vd_lsystem* ls, const vd_lstring* s) {
  PyObject* list = PyList_New((Py_ssize_t)s->n);
  for (int64_t i = 0; list && i < s->n; i++) {
    int np = vd_lstring_nparam(s, i);
    PyObject* params = PyTuple_New(np);
    for (int k = 0; params && k < np; k++) {
      double v = s->val[s->par[i] + k];
      const char* str = vd_lsys_value_str(ls, v);
      PyObject* o = str ? PyUnicode_FromString(str)
                    : v == floor(v) && fabs(v) < 9007199254740992.0 ? PyLong_FromDouble(v)
                                                                    : PyFloat_FromDouble(v);
      if (!o) Py_CLEAR(params);
      else PyTuple_SET_ITEM(params, k, o);
    }
    PyObject* it = params ? Py_BuildValue("(sN)", vd_lsys_symbol_name(ls, s->sym[i]), params) : NULL;
    if (!it) Py_CLEAR(list);
    else PyList_SET_ITEM(list, (Py_ssize_t)i, it);
  }
  return list;
}

// Lsystem().set(code); iterate(n) inside a file: a nested L-system of the native subset derived
// n steps (-1: its derivation length), seeded 0; its string as items
static PyObject* vd_nested(PyObject* self, PyObject* args) {
  (void)self;
  vd_lsystem* outer = current();
  const char* code;
  Py_ssize_t len;
  int steps;
  if (!outer || !PyArg_ParseTuple(args, "s#i", &code, &len, &steps)) return NULL;
  vd_lsystem* ls;
  vd_error e = {0};
  vd_status st = vd_lsys_parse_engine(code, (size_t)len, "Lsystem", VD_LSYS_NATIVE, &ls, &e);
  if (st == VD_ERR_UNSUPPORTED)
    return PyErr_Format(PyExc_NotImplementedError,
                        "an Lsystem inside a file runs L-Py's simple Python subset only (%s)", e.msg);
  if (st) return PyErr_Format(PyExc_ValueError, "Lsystem: line %d: %s", e.line, e.msg);
  vd_lsys_def d = vd_lsys_def_default();
  d.steps = steps;
  d.max_ops = outer->max_ops;
  vd_lstring s = vd_lstring_empty();
  st = vd_lsys_derive(ls, &d, &s, &e);
  PyObject* r = st ? PyErr_Format(PyExc_ValueError, "Lsystem: line %d: %s", e.line, e.msg) : native_items(ls, &s);
  vd_lstring_free(&s);
  vd_lsys_destroy(ls);
  return r;
}

// ModuleClass.issubclass: is module a (a name) module b or a subclass of it?
static PyObject* vd_isa(PyObject* self, PyObject* args) {
  (void)self;
  vd_lsystem* ls = current();
  const char *a, *b;
  if (!ls || !PyArg_ParseTuple(args, "ss", &a, &b)) return NULL;
  int sa = vd_lsys_symbol_find(ls, a), sb = vd_lsys_symbol_find(ls, b);
  return PyBool_FromLong(sa >= 0 && sb >= 0 && lsys_isa(ls, sa, sb));
}

// frameDisplay(enabled): whether the step's frame is drawn
// the short name of a predefined module named `name` (its own name or one of L-Py's long names),
// or None: openalea.lpy's predefined module classes
static PyObject* vd_predefined(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  const char* name = PyUnicode_Check(arg) ? PyUnicode_AsUTF8(arg) : NULL;
  if (!ls || !name) return name ? py_none() : NULL;
  int sym = vd_lsys_symbol_find(ls, name);
  if (sym < 0 || sym >= VD_SYM_PREDEFINED_COUNT) return py_none();
  return PyUnicode_FromString(vd_lsys_symbol_name(ls, sym));
}

static PyObject* vd_set_frame_displayed(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  int t = PyObject_IsTrue(arg);
  if (t < 0) return NULL;
  ls->frame_displayed = t;
  return py_none();
}

// isAnimationEnabled(): vd_lsys_animate runs
static PyObject* vd_animating(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  return ls ? PyBool_FromLong(ls->animating) : NULL;
}

// context().options.setSelection(name, value) at run time: the options that change results
static PyObject* vd_set_option(PyObject* self, PyObject* args) {
  (void)self;
  vd_lsystem* ls = current();
  const char* name;
  long v;
  if (!ls || !PyArg_ParseTuple(args, "sl", &name, &v)) return NULL;
  if (lsys_set_option(ls, name, (int)strlen(name), v, 0)) return vd_abort();
  return py_none();
}

// context().turtle.setAngleIncrement(a): the turtle's default angle for this file
static PyObject* vd_set_turtle_angle(PyObject* self, PyObject* arg) {
  (void)self;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  double a = PyFloat_AsDouble(arg);
  if (a == -1.0 && PyErr_Occurred()) return NULL;
  ls->turtle_angle = a;
  ls->has_turtle_angle = 1;
  return py_none();
}

// the 'Module matching' option (PatternModule.matchingMethod)
static PyObject* vd_module_matching(PyObject* self, PyObject* noarg) {
  (void)self, (void)noarg;
  vd_lsystem* ls = current();
  return ls ? PyLong_FromLong(ls->opt_module_matching) : NULL;
}

static PyObject* vd_log_text(PyObject* self, PyObject* arg) {
  (void)self;
  const char* s = PyUnicode_AsUTF8(arg);
  if (!s) return NULL;
  vd_lsystem* ls = current();
  if (ls && ls->quiet) return py_none();  // a repeat run (tracing an error back to the file)
  vd_log(0, "%s", s);
  return py_none();
}

// inLeftContext(pattern, params) / inRightContext: match the pattern on from where the
// rule's contexts ended (L-Py's LstringMatcher); its variables go into params (a dict)
static PyObject* vd_in_context(PyObject* self, PyObject* args) {
  (void)self;
  int right;
  const char* pat;
  Py_ssize_t plen;
  PyObject* params;
  if (!PyArg_ParseTuple(args, "is#O", &right, &pat, &plen, &params)) return NULL;
  vd_lsystem* ls = current();
  if (!ls) return NULL;
  if (!ls->cur.M) {
    PyErr_Format(PyExc_RuntimeError, "in%sContext outside the body of a rule", right ? "Right" : "Left");
    return NULL;
  }
  if (plen > INT_MAX / 2) {
    PyErr_SetString(PyExc_ValueError, "pattern too long");
    return NULL;
  }
  const lsys_cpat* cp = lsys_context_pattern(ls, pat, (int)plen, ls->cur.r->line);
  if (!cp) return vd_abort();
  value frame[64];
  for (int i = 0; i < 64; i++) frame[i] = (value){V_NONE, 0};
  int ok = lsys_context_match(ls, right, &cp->p, frame);
  if (ok < 0) return vd_abort();
  for (int i = 0; ok && params != Py_None && i < cp->nvar; i++) {
    PyObject* v = value_object(ls, frame[i]);
    PyObject* k = v ? str_object(ls, cp->var[i]) : NULL;  // borrowed
    int r = k ? PyObject_SetItem(params, k, v) : -1;
    Py_XDECREF(v);
    if (r < 0) return NULL;
  }
  return PyBool_FromLong(ok);
}

static PyMethodDef vd_methods[] = {
    {"p", (PyCFunction)(void (*)(void))vd_p, METH_FASTCALL, "produce a template"},
    {"kw", (PyCFunction)(void (*)(void))vd_kw, METH_FASTCALL, "produce A(**d): d's values in declared order"},
    {"mk", (PyCFunction)(void (*)(void))vd_mk, METH_FASTCALL, "the items of a template"},
    {"parse", vd_parse, METH_O, "modules of an L-string text"},
    {"append", vd_append, METH_O, "append (name, params) items to the production"},
    {"scene", vd_scene, METH_NOARGS, "the primitives the hook's string draws"},
    {"use_group", vd_use_group, METH_O, "useGroup"},
    {"get_group", vd_get_group, METH_NOARGS, "getGroup"},
    {"iteration", vd_iteration, METH_NOARGS, "getIterationNb"},
    {"stop", vd_stop, METH_NOARGS, "Stop"},
    {"log", vd_log_text, METH_O, "a line to verdant's log"},
    {"set_backward", vd_set_backward, METH_O, "backward() / forward()"},
    {"is_backward", vd_is_backward, METH_NOARGS, "not isForward()"},
    {"frame_displayed", vd_frame_displayed, METH_NOARGS, "isFrameDisplayed"},
    {"set_frame_displayed", vd_set_frame_displayed, METH_O, "frameDisplay"},
    {"animating", vd_animating, METH_NOARGS, "isAnimationEnabled"},
    {"isa", vd_isa, METH_VARARGS, "ModuleClass.issubclass"},
    {"predefined", vd_predefined, METH_O, "a predefined module's short name, or None"},
    {"nested", vd_nested, METH_VARARGS, "an Lsystem inside a file"},
    {"module_matching", vd_module_matching, METH_NOARGS, "the 'Module matching' option"},
    {"set_option", vd_set_option, METH_VARARGS, "context().options.setSelection"},
    {"set_turtle_angle", vd_set_turtle_angle, METH_O, "context().turtle.setAngleIncrement"},
    {"in_context", vd_in_context, METH_VARARGS, "inLeftContext / inRightContext"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef vd_module_def = {PyModuleDef_HEAD_INIT, "_verdant_lsys", "verdant's L-system engine", -1,
                                           vd_methods, NULL, NULL, NULL, NULL};

static PyObject* vd_module_create(void) { return PyModule_Create(&vd_module_def); }

// ---------------------------------------------------------------------------------------------
// compile and run

// compile text whose first line is file line `line` (newlines before it keep the numbering)
static PyObject* compile_at(vd_lsystem* ls, const char* src, size_t len, int line) {
  size_t pad = line > 1 ? (size_t)(line - 1) : 0;
  char* buf = vd_malloc(pad + len + 1);
  if (!buf) return PyErr_NoMemory();
  memset(buf, '\n', pad);
  memcpy(buf + pad, src, len);
  buf[pad + len] = 0;
  PyObject* code = Py_CompileStringExFlags(buf, ls->file, Py_file_input, NULL, -1);
  vd_free(buf, pad + len + 1);
  return code;
}

// the top-level code, line for line
static vd_status compile_top(vd_lsystem* ls) {
  lsys_py* py = ls->py;
  sbuf b = {0};
  for (int i = 0; i < py->nphys; i++) {
    if (py->top[i]) sb_puts(&b, py->top[i]);
    sb_put(&b, "\n", 1);
  }
  if (b.failed) {
    sb_free(&b);
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  }
  Py_CLEAR(py->code_top);
  py->code_top = Py_CompileStringExFlags(b.s ? b.s : "", ls->file, Py_file_input, NULL, -1);
  sb_free(&b);
  return py->code_top ? VD_OK : py_error(ls);
}

vd_status lsys_py_compile(vd_lsystem* ls) {
  lsys_py* py = ls->py;
  lsys_py_enter(ls);
  vd_status st = VD_OK;
  if (g_state != 1) {
    st = not_available(ls);
    goto done;
  }
  if ((st = compile_top(ls))) goto done;
  if (py->trailer) {
    py->code_trailer = compile_at(ls, py->trailer, strlen(py->trailer), py->trailer_line);
    if (!py->code_trailer) {
      st = py_error(ls);
      goto done;
    }
  }
  for (int k = 0; k < py->nfn; k++) {
    py->fn[k].code = compile_at(ls, py->fn[k].src, py->fn[k].len, py->fn[k].line);
    if (!py->fn[k].code) {
      st = py_error(ls);
      goto done;
    }
  }
  py->fobj = vd_calloc((size_t)(py->nfn ? py->nfn : 1), sizeof(PyObject*));
  if (!py->fobj) st = vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
done:
  lsys_py_leave(ls);
  return st;
}

static vd_status exec_code(vd_lsystem* ls, PyObject* code) {
  PyObject* r = PyEval_EvalCode(code, ls->py->ns, ls->py->ns);
  if (!r) return py_error(ls);
  Py_DECREF(r);
  return VD_OK;
}

vd_status lsys_py_run_toplevel(vd_lsystem* ls, uint64_t seed) {
  lsys_py* py = ls->py;
  if (g_state != 1) return not_available(ls);
  for (int k = 0; k < py->nfn; k++) Py_CLEAR(py->fobj[k]);
  Py_CLEAR(py->ns);
  py->ns = PyDict_Copy(g_base);
  if (!py->ns) return py_error(ls);
  // the --set values, the file name
  PyObject* set = PyDict_New();
  if (!set) return py_error(ls);
  for (int i = 0; i < py->nset; i++) PyDict_SetItemString(set, py->set[i].name, py->set[i].value);
  PyDict_SetItemString(py->ns, "__vd_set", set);
  Py_DECREF(set);
  PyObject* file = PyUnicode_FromString(ls->file);
  if (!file) return py_error(ls);
  PyDict_SetItemString(py->ns, "__file__", file);
  Py_DECREF(file);
  // random.seed(seed) (and numpy's generator once numpy is loaded), for this lsystem
  PyObject* s = PyLong_FromUnsignedLongLong(seed);
  PyObject* r = s ? shim_call("_vd_seed", s) : NULL;
  Py_XDECREF(s);
  if (!r) return py_error(ls);
  Py_DECREF(r);
  if (!g_hosted) g_last = ls;
  // the editor's trailer (__initialiseContext__, scalars, curves), then the file's code
  vd_status st;
  if (py->code_trailer && (st = exec_code(ls, py->code_trailer))) return st;
  r = shim_call("_vd_init_context", py->ns);
  if (!r) return py_error(ls);
  Py_DECREF(r);
  if ((st = exec_code(ls, py->code_top))) return st;
  for (int k = 0; k < py->nfn; k++) {
    if ((st = exec_code(ls, py->fn[k].code))) return st;
    PyObject* f = PyDict_GetItemString(py->ns, py->fn[k].name);  // borrowed
    if (!f) return vm_error(ls, VD_ERR_NAME, py->fn[k].line, 0, "function %s missing", py->fn[k].name);
    Py_INCREF(f);
    py->fobj[k] = f;
  }
  return VD_OK;
}

// make sure a run's namespace exists (interpretation without a derivation)
static vd_status need_ns(vd_lsystem* ls) {
  if (ls->py->ns) return VD_OK;
  return lsys_py_run_toplevel(ls, 0);
}

vd_status lsys_py_dlength_eval(vd_lsystem* ls, int* steps) {
  lsys_py* py = ls->py;
  *steps = 1;
  if (py->fn_dlen < 0) return VD_OK;
  vd_status st = need_ns(ls);
  if (st) return st;
  PyObject* r = PyObject_CallNoArgs(py->fobj[py->fn_dlen]);
  if (!r) return py_error(ls);
  long long n = -1;
  if (PyLong_Check(r)) n = PyLong_AsLongLong(r);
  else if (PyFloat_Check(r) && PyFloat_AS_DOUBLE(r) == floor(PyFloat_AS_DOUBLE(r))) n = (long long)PyFloat_AS_DOUBLE(r);
  Py_DECREF(r);
  PyErr_Clear();
  if (n < 0 || n > 1000000000LL)
    return vm_error(ls, VD_ERR_VALUE, py->fn[py->fn_dlen].line + 1, 1, "derivation length must be a non-negative integer");
  *steps = (int)n;
  return VD_OK;
}

// call f(args) with produce writing to out; the result's meaning as a rule body
static vd_status call_rule(vd_lsystem* ls, PyObject* f, PyObject* const* args, Py_ssize_t nargs, vm_out* out) {
  lsys_py* py = ls->py;
  progress();
  vm_out* saved = py->out;
  py->out = out;
  PyObject* r = PyObject_Vectorcall(f, args, (size_t)nargs, NULL);
  py->out = saved;
  if (!r) return py_error(ls);
  vd_status st = VD_OK;
  if (r == Py_True) {
    out->produced = 1;
  } else if (r != Py_None) {
    // a body that returns an L-string (or a list of modules) produces it
    PyObject* items = shim_call("_vd_items", r);
    if (!items || !append_items(ls, out->s, items, out->src, out->max_modules)) st = py_error(ls);
    Py_XDECREF(items);
    out->produced = 1;
  }
  Py_DECREF(r);
  return st;
}

vd_status lsys_py_emit_axiom(vd_lsystem* ls, vm_out* out) {
  lsys_py* py = ls->py;
  if (py->fn_axiom < 0) return VD_OK;
  vd_status st = need_ns(ls);
  return st ? st : call_rule(ls, py->fobj[py->fn_axiom], NULL, 0, out);
}

vd_status lsys_py_apply_rule(vd_lsystem* ls, const rule* r, const value* frame, vm_out* out) {
  lsys_py* py = ls->py;
  vd_status st = need_ns(ls);
  if (st) return st;
  PyObject* args[64];
  int n = r->nlocal;
  if (n > 64) return vm_error(ls, VD_ERR_LIMIT, r->line, 0, "more than 64 pattern variables");
  for (int i = 0; i < n; i++) {
    args[i] = value_object(ls, frame[i]);
    if (!args[i]) {
      for (int k = 0; k < i; k++) Py_DECREF(args[k]);
      return py_error(ls);
    }
  }
  st = call_rule(ls, py->fobj[r->pyfn], args, n, out);
  for (int i = 0; i < n; i++) Py_DECREF(args[i]);
  return st;
}

vd_status lsys_py_eval(vd_lsystem* ls, const expr* e, value* out) {
  vd_status st = need_ns(ls);
  if (st) return st;
  PyObject* code = Py_CompileStringExFlags(ls->str[(int)e->k.n], ls->file, Py_eval_input, NULL, -1);
  PyObject* r = code ? PyEval_EvalCode(code, ls->py->ns, ls->py->ns) : NULL;
  Py_XDECREF(code);
  if (!r) return py_error(ls);
  if (PyBool_Check(r)) {
    *out = (value){V_BOOL, r == Py_True};
  } else if (PyLong_Check(r) || PyFloat_Check(r)) {
    double d = PyFloat_Check(r) ? PyFloat_AS_DOUBLE(r) : PyLong_AsDouble(r);
    *out = PyFloat_Check(r) ? v_num(d) : v_int(d);
  } else if (PyUnicode_Check(r)) {
    const char* t = PyUnicode_AsUTF8(r);
    int id = t ? str_intern(ls, t, (int)strlen(t)) : -1;
    if (id < 0) {
      Py_DECREF(r);
      PyErr_Clear();
      return vm_error(ls, VD_ERR_NOMEM, e->line, e->col, "out of memory");
    }
    *out = (value){V_STR, id};
  } else {
    Py_DECREF(r);
    return vm_error(ls, VD_ERR_TYPE, e->line, e->col, "expected a number or a string");
  }
  Py_DECREF(r);
  if (PyErr_Occurred()) return py_error(ls);
  return VD_OK;
}

vd_status lsys_py_test(vd_lsystem* ls, int fn, value v, int* holds) {
  lsys_py* py = ls->py;
  vd_status st = need_ns(ls);
  if (st) return st;
  PyObject* a = value_object(ls, v);
  if (!a) return py_error(ls);
  PyObject* r = PyObject_CallOneArg(py->fobj[fn], a);
  Py_DECREF(a);
  int t = r ? PyObject_IsTrue(r) : -1;
  Py_XDECREF(r);
  if (t < 0) return py_error(ls);
  *holds = t;
  return VD_OK;
}

// number of positional parameters a hook declares (0 when unknown)
static int arity(PyObject* f) {
  PyObject* code = PyObject_GetAttrString(f, "__code__");
  if (!code) {
    PyErr_Clear();
    return 0;
  }
  PyObject* n = PyObject_GetAttrString(code, "co_argcount");
  Py_DECREF(code);
  int k = n && PyLong_Check(n) ? (int)PyLong_AsLong(n) : 0;
  Py_XDECREF(n);
  PyErr_Clear();
  return k;
}

vd_status lsys_py_produce_hook(vd_lsystem* ls, const char* name, vd_lstring* out, int64_t src, int64_t max_modules) {
  lsys_py* py = ls->py;
  if (!py->ns) return VD_OK;
  PyObject* f = PyDict_GetItemString(py->ns, name);  // borrowed
  if (!f || !PyCallable_Check(f)) return VD_OK;
  PyObject* args[1] = {Py_None};
  vm_out vo = {out, src, max_modules, 0, 0};
  Py_INCREF(f);
  vd_status st = call_rule(ls, f, args, arity(f) >= 1 ? 1 : 0, &vo);
  Py_DECREF(f);
  return st;
}

vd_status lsys_py_hook(vd_lsystem* ls, const char* name, vd_lstring* s, vd_lstring* scratch, int64_t max_modules,
                       vd_plant_spec* scene, int* kept) {
  lsys_py* py = ls->py;
  if (!py->ns) return VD_OK;
  PyObject* f = PyDict_GetItemString(py->ns, name);  // borrowed
  if (!f || !PyCallable_Check(f)) return VD_OK;
  if (kept) *kept = 0;
  int want = arity(f);
  PyObject* args[2] = {NULL, NULL};
  int n = 0, drawn = 0;
  if (want >= 1) {
    PyObject* items = items_of(ls, s, 0, s->n);
    args[0] = items ? shim_call("_vd_lstring", items) : NULL;
    Py_XDECREF(items);
    if (!args[0]) return py_error(ls);
    n = 1;
  }
  if (want >= 2) {
    // an animation's frame: L-Py draws the scene before the hook (and shows it when kept)
    vd_status st = VD_OK;
    if (scene && ls->frame_displayed) {
      vm_out* saved = py->out;
      st = lsys_draw(ls, s, scene);
      py->out = saved;
      drawn = !st;
    }
    args[1] = st ? NULL : shim_call("_vd_lazy_scene", NULL);  // made from s when the hook reads it
    if (!args[1]) {
      Py_DECREF(args[0]);
      return st ? st : py_error(ls);
    }
    n = 2;
  }
  Py_INCREF(f);
  progress();
  vm_out vo = {scratch, 0, max_modules, 0, 0};
  if (!lstr_reserve(scratch, 16, 16)) {
    Py_DECREF(f);
    for (int i = 0; i < n; i++) Py_DECREF(args[i]);
    return vm_error(ls, VD_ERR_NOMEM, 0, 0, "out of memory");
  }
  lstr_clear(scratch);
  vm_out* saved = py->out;
  const vd_lstring* saved_s = py->hook_s;
  const vd_plant_spec* saved_plant = py->hook_plant;
  py->out = &vo;  // an nproduce in a hook has nowhere to go but is not an error
  py->hook_s = s;
  py->hook_plant = drawn ? scene : NULL;
  PyObject* r = PyObject_Vectorcall(f, args, (size_t)n, NULL);
  py->out = saved;
  py->hook_s = saved_s;
  py->hook_plant = saved_plant;
  Py_DECREF(f);
  PyObject* scene_type = PyDict_GetItemString(g_shim, "Scene");  // borrowed
  // which scene the frame shows (L-Py's __apply_post_process): the given one when the hook
  // returns nothing, the scene, or (lstring, scene); none (the string is drawn) otherwise; a
  // scene the hook made itself cannot be drawn here
  PyObject* rs = r && PyTuple_Check(r) && PyTuple_GET_SIZE(r) == 2 ? PyTuple_GET_ITEM(r, 1)
                 : r && scene_type && PyObject_IsInstance(r, scene_type) == 1 ? r
                                                                               : NULL;
  if (kept) *kept = drawn && r && (r == Py_None || (rs && rs == args[1]));
  if (r && drawn && rs && rs != args[1] && rs != Py_None) {
    for (int i = 0; i < n; i++) Py_DECREF(args[i]);
    Py_DECREF(r);
    return vm_error(ls, VD_ERR_UNSUPPORTED, 0, 0,
                    "unsupported: %s returned a scene of its own in an animation (verdant draws the frames from the "
                    "L-string; return the scene it was given, the L-string or nothing)",
                    name);
  }
  // a hook that changed the L-string it was given in place (lstring[0][0] = 2) and returned
  // nothing: the changed string is the result, as the hook saw L-Py's own string
  if (r == Py_None && n >= 1) {
    Py_DECREF(r);
    Py_INCREF(args[0]);
    r = args[0];
  }
  for (int i = 0; i < n; i++) Py_DECREF(args[i]);
  if (!r) return py_error(ls);
  vd_status st = VD_OK;
  // a hook may return (lstring, scene): the string counts
  if (PyTuple_Check(r) && PyTuple_GET_SIZE(r) == 2) {
    PyObject* first = PyTuple_GET_ITEM(r, 0);
    Py_INCREF(first);
    Py_DECREF(r);
    r = first;
  }
  if (r != Py_None && r != Py_True && r != Py_False && !(scene_type && PyObject_IsInstance(r, scene_type) == 1)) {
    // the hook returned a new string: it replaces the current one
    PyObject* items = shim_call("_vd_items", r);
    lstr_clear(scratch);
    if (!items || !append_items(ls, scratch, items, -1, max_modules)) {
      st = py_error(ls);
    } else {
      vd_lstring t = *s;
      *s = *scratch;
      *scratch = t;
    }
    Py_XDECREF(items);
  }
  Py_DECREF(r);
  return st;
}

vd_status lsys_py_call(vd_lsystem* ls, const char* name) {
  lsys_py* py = ls->py;
  PyObject* f = py->ns ? PyDict_GetItemString(py->ns, name) : NULL;  // borrowed
  if (!f || !PyCallable_Check(f))
    return vm_error(ls, VD_ERR_NAME, 0, 0, "the file defines no function '%s'", name);
  Py_INCREF(f);
  vm_out* saved = py->out;
  py->out = NULL;
  PyObject* r = PyObject_CallNoArgs(f);
  py->out = saved;
  Py_DECREF(f);
  if (!r) return py_error(ls);
  Py_DECREF(r);
  return VD_OK;
}

vd_status lsys_py_vec3(vd_lsystem* ls, double x, double y, double z, double* out) {
  PyObject* c = Py_BuildValue("(ddd)", x, y, z);
  PyObject* v = c ? shim_call("_vd_make_vec3", c) : NULL;
  Py_XDECREF(c);
  int ok = v && keep_object(ls, v, out);
  Py_XDECREF(v);
  return ok ? VD_OK : py_error(ls);
}

// ---------------------------------------------------------------------------------------------
// globals: --set and reading back

// does the file give name a value that --set may replace: a top-level `name = ...`, an
// extern(name = ...) or a scalar of the editor trailer?
static int settable(const lsys_py* py, const vd_lsystem* ls, const char* name) {
  size_t n = strlen(name);
  for (int i = 0; i < py->nphys; i++) {
    if (py->top_name[i] >= 0 && !strcmp(ls->str[py->top_name[i]], name)) return 1;
    const char* t = py->top[i];
    if (t && strstr(t, "extern") && strstr(t, name)) return 1;
  }
  if (py->trailer) {
    for (const char* p = py->trailer; (p = strstr(p, name)); p += n)
      if (p > py->trailer && (p[-1] == '\'' || p[-1] == '"') && (p[n] == '\'' || p[n] == '"')) return 1;
  }
  return 0;
}

vd_status lsys_py_set_global(vd_lsystem* ls, const char* name, const char* text) {
  lsys_py* py = ls->py;
  if (!settable(py, ls, name))
    return vd_error_set(ls->err, VD_ERR_NAME, ls->file, 0, 0, "--set %s: the file defines no global '%s'", name, name);
  lsys_py_enter(ls);
  vd_status st = VD_OK;
  if (g_state != 1) {
    st = not_available(ls);
    goto done;
  }
  // the value: a Python expression with only the builtins
  PyObject* g = PyDict_New();
  PyObject* v = NULL;
  if (g) {
    PyDict_SetItemString(g, "__builtins__", PyEval_GetBuiltins());
    v = PyRun_String(text, Py_eval_input, g, g);
    Py_DECREF(g);
  }
  if (!v) {
    PyObject *t, *e, *tb;
    PyErr_Fetch(&t, &e, &tb);
    PyObject* s = e ? PyObject_Str(e) : NULL;
    const char* m = s ? PyUnicode_AsUTF8(s) : NULL;
    st = vd_error_set(ls->err, t && PyErr_GivenExceptionMatches(t, PyExc_SyntaxError) ? VD_ERR_SYNTAX : VD_ERR_VALUE,
                      "", 0, 0, "--set %.40s=%.60s: %s: %s", name, text, t ? ((PyTypeObject*)t)->tp_name : "error",
                      m ? m : "");
    Py_XDECREF(s);
    Py_XDECREF(t);
    Py_XDECREF(e);
    Py_XDECREF(tb);
    PyErr_Clear();
    goto done;
  }
  int k = 0;
  while (k < py->nset && strcmp(py->set[k].name, name) != 0) k++;
  if (k == py->nset) {
    char* nm = vd_strdup(name);
    if (!nm || !vd_grow((void**)&py->set, &py->capset, py->nset + 1, sizeof(pyset))) {
      if (nm) vd_free(nm, strlen(nm) + 1);
      Py_DECREF(v);
      st = vd_error_set(ls->err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      goto done;
    }
    py->set[py->nset++] = (pyset){nm, NULL};
  }
  Py_XDECREF(py->set[k].value);
  py->set[k].value = v;
  // its assignments at top level take the value instead
  for (int i = 0; i < py->nphys; i++) {
    if (py->top_name[i] < 0 || strcmp(ls->str[py->top_name[i]], name) != 0) continue;
    sbuf b = {0};
    sb_printf(&b, "%s = __vd_set['%s']", name, name);
    char* line = sb_take(&b, NULL);
    if (!line) {
      st = vd_error_set(ls->err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      goto done;
    }
    vd_free(py->top[i], strlen(py->top[i]) + 1);
    py->top[i] = line;
    for (int l = i + 1; l < py->top_last[i] && l < py->nphys; l++)
      if (py->top[l]) py->top[l][0] = 0;
  }
  st = compile_top(ls);
done:
  lsys_py_leave(ls);
  return st;
}

vd_status lsys_py_get_global(vd_lsystem* ls, const char* name, double* out) {
  lsys_py* py = ls->py;
  if (!py->ns) return VD_ERR_NAME;
  lsys_py_enter(ls);
  vd_status st = VD_ERR_NAME;
  PyObject* v = PyDict_GetItemString(py->ns, name);  // borrowed
  if (v) {
    st = VD_ERR_TYPE;
    if (PyFloat_Check(v) || PyLong_Check(v)) {
      *out = PyFloat_Check(v) ? PyFloat_AS_DOUBLE(v) : PyLong_AsDouble(v);
      st = PyErr_Occurred() ? VD_ERR_TYPE : VD_OK;
      PyErr_Clear();
    }
  }
  lsys_py_leave(ls);
  return st;
}

// ---------------------------------------------------------------------------------------------
// free

void lsys_py_free(vd_lsystem* ls) {
  lsys_py* py = ls->py;
  if (!py) return;
  if (g_state == 1) {
    lsys_py_enter(NULL);  // the lock and the GIL only: no random state to swap in or keep
    lsys_py_reset_objects(ls);
    for (int k = 0; k < py->nfn; k++) {
      Py_CLEAR(py->fn[k].code);
      if (py->fobj) Py_CLEAR(py->fobj[k]);
    }
    for (int i = 0; i < py->capstrobj; i++) Py_CLEAR(py->strobj[i]);
    for (int i = 0; i < py->nset; i++) Py_CLEAR(py->set[i].value);
    Py_CLEAR(py->code_top);
    Py_CLEAR(py->code_trailer);
    Py_CLEAR(py->ns);
    Py_CLEAR(py->rstate);
    Py_CLEAR(py->npstate);
    if (g_last == ls) g_last = NULL;
    lsys_py_leave(NULL);
  }
  for (int k = 0; k < py->nfn; k++) vd_free(py->fn[k].src, py->fn[k].len + 1);
  vd_free(py->fn, sizeof(pychunk) * (size_t)py->capfn);
  vd_free(py->fobj, sizeof(PyObject*) * (size_t)(py->nfn ? py->nfn : 1));
  for (int i = 0; i < py->nphys; i++)
    if (py->top && py->top[i]) vd_free(py->top[i], strlen(py->top[i]) + 1);
  vd_free(py->top, sizeof(char*) * (size_t)py->nphys);
  vd_free(py->top_name, sizeof(int) * (size_t)py->nphys);
  vd_free(py->top_last, sizeof(int) * (size_t)py->nphys);
  vd_free(py->phys_at, sizeof(size_t) * (size_t)(py->nphys + 1));
  if (py->trailer) vd_free(py->trailer, strlen(py->trailer) + 1);
  vd_free(py->tp, sizeof(tmpl*) * (size_t)py->captp);
  for (int i = 0; i < py->nset; i++) vd_free(py->set[i].name, strlen(py->set[i].name) + 1);
  vd_free(py->set, sizeof(pyset) * (size_t)py->capset);
  vd_free(py->obj, sizeof(PyObject*) * (size_t)py->capobj);
  vd_free(py->freel, sizeof(int) * (size_t)py->capfree);
  vd_free(py->mark, (size_t)py->capmark);
  vd_free(py->strobj, sizeof(PyObject*) * (size_t)py->capstrobj);
  vd_free(py, sizeof *py);
  ls->py = NULL;
}

void lsys_py_repr(const vd_lsystem* ls, double v, char* buf, size_t cap) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  snprintf(buf, cap, "None");
  lsys_py_enter(mls);
  if (g_state == 1) {
    PyObject* o = param_object(mls, v);
    PyObject* r = o ? PyObject_Repr(o) : NULL;
    const char* s = r ? PyUnicode_AsUTF8(r) : NULL;
    if (s) snprintf(buf, cap, "%s", s);
    Py_XDECREF(r);
    Py_XDECREF(o);
    PyErr_Clear();
  }
  lsys_py_leave(mls);
}

// ---------------------------------------------------------------------------------------------
// objects for the turtle

// the object behind v and the shim's answer fn(obj, extra...) (new reference), or NULL with why
static PyObject* obj_query(vd_lsystem* ls, double v, const char* fn, PyObject* extra, char* why, size_t cap) {
  uint32_t id;
  unsigned ep;
  if (!ls || !ls->py || g_state != 1 || !lsys_unbox_obj(v, &id, &ep)) {
    snprintf(why, cap, "%s", vd_lsys_value_is_str(v) ? "a string" : "a number");
    return NULL;
  }
  PyObject* o = param_object(ls, v);
  PyObject* f = o ? PyDict_GetItemString(g_shim, fn) : NULL;  // borrowed
  PyObject* r = f ? (extra ? PyObject_CallFunctionObjArgs(f, o, extra, NULL) : PyObject_CallOneArg(f, o)) : NULL;
  if (!r) {
    PyObject *t, *e, *tb;
    PyErr_Fetch(&t, &e, &tb);
    PyObject* s = e ? PyObject_Str(e) : NULL;
    const char* m = s ? PyUnicode_AsUTF8(s) : NULL;
    snprintf(why, cap, "%s: %s", t ? ((PyTypeObject*)t)->tp_name : "error", m ? m : "");
    Py_XDECREF(s);
    Py_XDECREF(t);
    Py_XDECREF(e);
    Py_XDECREF(tb);
    PyErr_Clear();
  } else if (r == Py_None) {
    PyObject* tr = PyObject_Repr(o);
    const char* m = tr ? PyUnicode_AsUTF8(tr) : NULL;
    snprintf(why, cap, "%.200s", m ? m : "an object");
    Py_XDECREF(tr);
    PyErr_Clear();
    Py_CLEAR(r);
  }
  Py_XDECREF(o);
  return r;
}

// a Python sequence of numbers into a new array of n doubles (n from the sequence), or NULL
static double* doubles(PyObject* seq, int* n) {
  PyObject* f = PySequence_Fast(seq, "numbers expected");
  if (!f) return NULL;
  Py_ssize_t k = PySequence_Fast_GET_SIZE(f);
  double* a = vd_malloc(sizeof(double) * (size_t)(k ? k : 1));
  for (Py_ssize_t i = 0; a && i < k; i++) {
    a[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(f, i));
    if (PyErr_Occurred() || !isfinite(a[i])) {
      vd_free(a, sizeof(double) * (size_t)(k ? k : 1));
      a = NULL;
    }
  }
  Py_DECREF(f);
  PyErr_Clear();
  if (a) *n = (int)k;
  return a;
}

static void free_doubles(double* a, int n) { vd_free(a, sizeof(double) * (size_t)(n ? n : 1)); }

vd_status lsys_obj_vec3(const vd_lsystem* ls, double v, double c[3], char* why, size_t cap) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  lsys_py_enter(mls);
  vd_status st = VD_ERR_TYPE;
  PyObject* r = obj_query(mls, v, "_vd_vec3", NULL, why, cap);
  int k = 0;
  double* p = r ? doubles(r, &k) : NULL;
  if (p && k == 3 && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])) {
    memcpy(c, p, sizeof(double) * 3);
    st = VD_OK;
  } else if (r) {
    snprintf(why, cap, "a vector that is not three finite numbers");
  }
  if (p) free_doubles(p, k);
  Py_XDECREF(r);
  PyErr_Clear();
  lsys_py_leave(mls);
  return st;
}

vd_status lsys_obj_points(const vd_lsystem* ls, double v, double** p, int* n, int* dim, char* why, size_t cap) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  *p = NULL;
  lsys_py_enter(mls);
  vd_status st = VD_ERR_TYPE;
  PyObject* zero = PyLong_FromLong(0);
  PyObject* r = zero ? obj_query(mls, v, "_vd_curve", zero, why, cap) : NULL;
  Py_XDECREF(zero);
  int k = 0;
  if (r && PyTuple_Check(r) && PyTuple_GET_SIZE(r) == 2) {
    *dim = (int)PyLong_AsLong(PyTuple_GET_ITEM(r, 1));
    *p = doubles(PyTuple_GET_ITEM(r, 0), &k);
    if (*p && (*dim == 2 || *dim == 3) && k % *dim == 0 && k >= 2 * *dim) {
      *n = k / *dim;
      st = VD_OK;
    } else if (*p) {
      free_doubles(*p, k);
      *p = NULL;
      snprintf(why, cap, "a curve with too few points");
    }
  }
  Py_XDECREF(r);
  PyErr_Clear();
  lsys_py_leave(mls);
  return st;
}

vd_status lsys_obj_guide(const vd_lsystem* ls, double v, int m, double* length, double** p, double** tan,
                         double** nrm, int* dim, char* why, size_t cap) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  *p = *tan = *nrm = NULL;
  lsys_py_enter(mls);
  vd_status st = VD_ERR_TYPE;
  PyObject* pm = PyLong_FromLong(m);
  PyObject* r = pm ? obj_query(mls, v, "_vd_guide", pm, why, cap) : NULL;
  Py_XDECREF(pm);
  if (r && PyTuple_Check(r) && PyTuple_GET_SIZE(r) == 5) {
    int a = 0, b = 0, c = 0;
    *length = PyFloat_AsDouble(PyTuple_GET_ITEM(r, 0));
    *dim = (int)PyLong_AsLong(PyTuple_GET_ITEM(r, 4));
    *p = doubles(PyTuple_GET_ITEM(r, 1), &a);
    *tan = doubles(PyTuple_GET_ITEM(r, 2), &b);
    *nrm = doubles(PyTuple_GET_ITEM(r, 3), &c);
    int want = (m + 1) * *dim;
    if (*p && *tan && *nrm && (*dim == 2 || *dim == 3) && a == want && b == want && c == want && isfinite(*length) &&
        *length > 0) {
      st = VD_OK;
    } else {
      if (*p) free_doubles(*p, a);
      if (*tan) free_doubles(*tan, b);
      if (*nrm) free_doubles(*nrm, c);
      *p = *tan = *nrm = NULL;
      snprintf(why, cap, "a curve without length");
    }
  }
  Py_XDECREF(r);
  PyErr_Clear();
  lsys_py_leave(mls);
  return st;
}

vd_status lsys_obj_function(const vd_lsystem* ls, double v, double* fx, double* lx, double** val, int* n, char* why,
                            size_t cap) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  *val = NULL;
  lsys_py_enter(mls);
  vd_status st = VD_ERR_TYPE;
  PyObject* r = obj_query(mls, v, "_vd_function", NULL, why, cap);
  if (r && PyTuple_Check(r) && PyTuple_GET_SIZE(r) == 3) {
    *fx = PyFloat_AsDouble(PyTuple_GET_ITEM(r, 0));
    *lx = PyFloat_AsDouble(PyTuple_GET_ITEM(r, 1));
    *val = doubles(PyTuple_GET_ITEM(r, 2), n);
    if (*val && *n >= 2 && isfinite(*fx) && isfinite(*lx) && *lx > *fx) {
      st = VD_OK;
    } else {
      if (*val) free_doubles(*val, *n);
      *val = NULL;
      snprintf(why, cap, "a function without a range");
    }
  }
  Py_XDECREF(r);
  PyErr_Clear();
  lsys_py_leave(mls);
  return st;
}

vd_status lsys_obj_mesh(const vd_lsystem* ls, double v, double** xyz, int* nv, int** tri, int* nt, int* closed,
                        char* why, size_t cap) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  *xyz = NULL;
  *tri = NULL;
  lsys_py_enter(mls);
  vd_status st = VD_ERR_TYPE;
  PyObject* r = obj_query(mls, v, "_vd_mesh", NULL, why, cap);
  if (r && PyTuple_Check(r) && PyTuple_GET_SIZE(r) == 3) {
    int a = 0, b = 0;
    double* p = doubles(PyTuple_GET_ITEM(r, 0), &a);
    double* t = doubles(PyTuple_GET_ITEM(r, 1), &b);
    *closed = PyObject_IsTrue(PyTuple_GET_ITEM(r, 2)) == 1;
    int ok = p && t && a % 3 == 0 && b % 3 == 0 && a > 0 && b > 0;
    int* ti = ok ? vd_malloc(sizeof(int) * (size_t)b) : NULL;
    double nvert = (double)(a - a % 3) / 3.0;  // vertices (a is a multiple of 3 here)
    int bad = 0;
    for (int i = 0; ti && i < b && !bad; i++) {
      bad = !(t[i] >= 0 && t[i] < nvert);
      if (!bad) ti[i] = (int)t[i];
    }
    if (ti && bad) {
      vd_free(ti, sizeof(int) * (size_t)b);
      ti = NULL;
    }
    if (t) free_doubles(t, b);
    if (ti) {
      *xyz = p;
      *nv = a / 3;
      *tri = ti;
      *nt = b / 3;
      st = VD_OK;
    } else {
      if (p) free_doubles(p, a);
      snprintf(why, cap, "a geometry whose mesh is not valid");
    }
  }
  Py_XDECREF(r);
  PyErr_Clear();
  lsys_py_leave(mls);
  return st;
}

void lsys_py_turtle_def(const vd_lsystem* ls, vd_turtle_def* td) {
  vd_lsystem* mls = (vd_lsystem*)ls;
  if (!ls || !ls->py || !ls->py->ns || g_state != 1) return;
  lsys_py_enter(mls);
  PyObject* d = shim_call("_vd_turtle_settings", ls->py->ns);
  static const char* names[] = {"setAngleIncrement", "setWidthIncrement", "setScaleMultiplier", "setElasticity"};
  double* fields[] = {&td->angle, &td->width_inc, &td->scale_factor, &td->elasticity};
  for (int k = 0; d && PyDict_Check(d) && k < 4; k++) {
    PyObject* a = PyDict_GetItemString(d, names[k]);  // borrowed: the arguments' tuple
    if (!a || !PyTuple_Check(a) || PyTuple_GET_SIZE(a) < 1) continue;
    double v = PyFloat_AsDouble(PyTuple_GET_ITEM(a, 0));
    if (!PyErr_Occurred() && isfinite(v)) *fields[k] = v;
    PyErr_Clear();
  }
  Py_XDECREF(d);
  PyErr_Clear();
  lsys_py_leave(mls);
}
