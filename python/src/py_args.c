// SPDX-License-Identifier: MIT
// Argument conversion: strict checks of numbers, vectors, paths and keyword sets, each failure a
// TypeError or verdant.ArgumentError naming the argument, before the library sees a value.
#include "py_internal.h"

#include <math.h>

int vdpy_i64(PyObject* o, const char* name, int64_t lo, int64_t hi, int64_t* out) {
  if (PyBool_Check(o) || PyFloat_Check(o)) {
    PyErr_Format(PyExc_TypeError, "%s expects an integer, got %s", name, Py_TYPE(o)->tp_name);
    return 0;
  }
  PyObject* i = PyNumber_Index(o);
  if (!i) {
    PyErr_Clear();
    PyErr_Format(PyExc_TypeError, "%s expects an integer, got %s", name, Py_TYPE(o)->tp_name);
    return 0;
  }
  int overflow = 0;
  long long v = PyLong_AsLongLongAndOverflow(i, &overflow);
  Py_DECREF(i);
  if (v == -1 && PyErr_Occurred()) return 0;
  if (overflow || v < lo || v > hi) {
    vdpy_arg_error("%s expects an integer in %lld..%lld", name, (long long)lo, (long long)hi);
    return 0;
  }
  *out = (int64_t)v;
  return 1;
}

static int real(PyObject* o, const char* name, double* out) {
  if (PyBool_Check(o) || !PyNumber_Check(o) || PyComplex_Check(o)) {
    PyErr_Format(PyExc_TypeError, "%s expects a number, got %s", name, Py_TYPE(o)->tp_name);
    return 0;
  }
  double v = PyFloat_AsDouble(o);
  if (v == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    PyErr_Format(PyExc_TypeError, "%s expects a number, got %s", name, Py_TYPE(o)->tp_name);
    return 0;
  }
  *out = v;
  return 1;
}

int vdpy_f64(PyObject* o, const char* name, double lo, double hi, double* out) {
  double v;
  if (!real(o, name, &v)) return 0;
  if (!isfinite(v) || v < lo || v > hi) {
    vdpy_arg_error("%s expects a finite number in [%g, %g], got %g", name, lo, hi, v);
    return 0;
  }
  *out = v;
  return 1;
}

int vdpy_f64_inf(PyObject* o, const char* name, double lo, double hi, double* out) {
  double v;
  if (!real(o, name, &v)) return 0;
  if (v == INFINITY) {
    *out = v;
    return 1;
  }
  return vdpy_f64(o, name, lo, hi, out);
}

int vdpy_vec(PyObject* o, const char* name, int n, double* out) {
  PyObject* seq = PySequence_Check(o) && !PyUnicode_Check(o) && !PyBytes_Check(o)
                      ? PySequence_Fast(o, name)
                      : NULL;
  if (!seq || PySequence_Fast_GET_SIZE(seq) != n) {
    Py_XDECREF(seq);
    PyErr_Clear();
    PyErr_Format(PyExc_TypeError, "%s expects a sequence of %d numbers", name, n);
    return 0;
  }
  int ok = 1;
  for (int k = 0; ok && k < n; k++)
    ok = vdpy_f64(PySequence_Fast_GET_ITEM(seq, k), name, -HUGE_VAL, HUGE_VAL, &out[k]);
  Py_DECREF(seq);
  return ok;
}

int vdpy_bool(PyObject* o, const char* name, int* out) {
  int v = PyObject_IsTrue(o);
  if (v < 0) return 0;
  *out = v;
  return 1;
}

// copy bytes into buf: not too long, no NUL inside
static int copy_text(const char* s, Py_ssize_t n, const char* name, char* buf, size_t cap) {
  if ((size_t)n >= cap) {
    vdpy_arg_error("%s is too long (%zd bytes, %zu at most)", name, n, cap - 1);
    return 0;
  }
  if (memchr(s, 0, (size_t)n)) {
    vdpy_arg_error("%s holds a NUL character", name);
    return 0;
  }
  memcpy(buf, s, (size_t)n);
  buf[n] = 0;
  return 1;
}

int vdpy_path(PyObject* o, const char* name, char* buf, size_t cap) {
  PyObject* b = NULL;
  if (!PyUnicode_Check(o) && !PyBytes_Check(o) && !PyObject_HasAttrString(o, "__fspath__")) {
    PyErr_Format(PyExc_TypeError, "%s expects a path (str or os.PathLike), got %s", name,
                 Py_TYPE(o)->tp_name);
    return 0;
  }
  if (!PyUnicode_FSConverter(o, &b)) {
    if (PyErr_ExceptionMatches(PyExc_ValueError)) {  // a NUL inside
      PyErr_Clear();
      vdpy_arg_error("%s holds a NUL character", name);
    }
    return 0;
  }
  int ok = copy_text(PyBytes_AS_STRING(b), PyBytes_GET_SIZE(b), name, buf, cap);
  Py_DECREF(b);
  return ok;
}

int vdpy_str(PyObject* o, const char* name, char* buf, size_t cap) {
  if (!PyUnicode_Check(o)) {
    PyErr_Format(PyExc_TypeError, "%s expects a str, got %s", name, Py_TYPE(o)->tp_name);
    return 0;
  }
  Py_ssize_t n;
  const char* s = PyUnicode_AsUTF8AndSize(o, &n);
  return s && copy_text(s, n, name, buf, cap);
}

PyObject* vdpy_kw(PyObject* kw, const char* name) {
  if (!kw) return NULL;
  PyObject* v = PyDict_GetItemString(kw, name);
  return v == Py_None ? NULL : v;
}

int vdpy_kw_check(PyObject* kw, const char* func, const char* const* names) {
  if (!kw) return 1;
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(kw, &pos, &key, &value)) {
    const char* k = PyUnicode_Check(key) ? PyUnicode_AsUTF8(key) : NULL;
    int known = 0;
    for (int i = 0; k && names[i] && !known; i++) known = !strcmp(k, names[i]);
    if (!known) {
      PyErr_Format(PyExc_TypeError, "%s() got an unexpected keyword argument %R", func, key);
      return 0;
    }
  }
  return 1;
}
