// SPDX-License-Identifier: MIT
// verdant._verdant: the module, its exception classes, numpy views over library memory, label
// tables, and the registration of the Python classes that extend the C types.
#define VDPY_MODULE_C
#include "py_internal.h"

#include <errno.h>
#include <stdarg.h>
#include <sys/stat.h>
#include <unistd.h>

// ---------------------------------------------------------------------------------------------
// exceptions: verdant.Error and one subclass per status code

static PyObject* error_base;                      // verdant.Error
static PyObject* error_class[VD_STATUS_COUNT];    // by vd_status (VD_OK unused)

// class name, extra builtin base (Nullable), status and docstring of each subclass
static const struct {
  vd_status st;
  const char* name;
  const char* doc;
} error_kinds[] = {
    {VD_ERR_SYNTAX, "ParseError", "The input does not parse (L-Py syntax, JSON, a number)."},
    {VD_ERR_UNSUPPORTED, "UnsupportedError", "The input uses a construct verdant does not support."},
    {VD_ERR_NAME, "UndefinedNameError", "A name (global, module, label, organ) is not defined."},
    {VD_ERR_TYPE, "WrongTypeError", "A value has the wrong type (also a TypeError)."},
    {VD_ERR_VALUE, "BadValueError", "A value is out of range or not finite (also a ValueError)."},
    {VD_ERR_ASSERT, "ModelAssertionError", "An assertion in the model failed."},
    {VD_ERR_LIMIT, "LimitError", "A size or work limit was exceeded (modules, points, segments)."},
    {VD_ERR_IO, "FileError", "A file could not be read or written (also an OSError)."},
    {VD_ERR_FORMAT, "FormatError", "A file is not in the expected format."},
    {VD_ERR_NOMEM, "OutOfMemoryError", "Out of memory (also a MemoryError)."},
    {VD_ERR_ARG, "ArgumentError", "A bad argument (also a ValueError)."},
};

// short lower-case name of a status ("syntax"), the `status` attribute of errors
static const char* status_key(vd_status st) {
  static const char* keys[VD_STATUS_COUNT] = {"ok",     "syntax", "unsupported", "name",
                                              "type",   "value",  "assert",      "limit",
                                              "io",     "format", "nomem",       "arg"};
  return (int)st >= 0 && st < VD_STATUS_COUNT ? keys[st] : "error";
}

// the errno of a file that could not be read or written, found again from the file system (the
// library's status does not carry it): ENOENT where it (or its folder) is missing, EISDIR for a
// folder, EACCES without permission, else EIO
static int file_errno(const char* file) {
  struct stat sb;
  if (!file[0]) return EIO;
  if (stat(file, &sb) < 0) return errno == ENOENT || errno == ENOTDIR ? ENOENT : errno;
  if (S_ISDIR(sb.st_mode)) return EISDIR;
  if (access(file, R_OK) < 0) return EACCES;
  return EIO;
}

// FileError's OSError attributes: errno, strerror (the library's message), filename
static int set_errno(PyObject* e, const char* file, PyObject* f, PyObject* m) {
  PyObject* no = PyLong_FromLong(file_errno(file));
  int bad = !no || PyObject_SetAttrString(e, "errno", no) < 0 || PyObject_SetAttrString(e, "strerror", m) < 0 ||
            PyObject_SetAttrString(e, "filename", file[0] ? f : Py_None) < 0;
  Py_XDECREF(no);
  return bad;
}

// raise class cls with message text and the location attributes
static PyObject* raise_with(PyObject* cls, const char* status, const char* file, int line,
                            int col, const char* msg, const char* text) {
  PyObject* e = PyObject_CallFunction(cls, "s", text);
  if (!e) return NULL;
  PyObject* f = PyUnicode_DecodeFSDefault(file);
  PyObject* m = PyUnicode_DecodeUTF8(msg, (Py_ssize_t)strlen(msg), "replace");
  PyObject* s = PyUnicode_FromString(status);
  int bad = !f || !m || !s || PyObject_SetAttrString(e, "status", s) < 0;
  if (!bad) {
    PyObject* ln = PyLong_FromLong(line);
    PyObject* cn = PyLong_FromLong(col);
    bad = !ln || !cn || PyObject_SetAttrString(e, "file", f) < 0 ||
          PyObject_SetAttrString(e, "line", ln) < 0 || PyObject_SetAttrString(e, "column", cn) < 0 ||
          PyObject_SetAttrString(e, "message", m) < 0;
    Py_XDECREF(ln);
    Py_XDECREF(cn);
  }
  if (!bad && !strcmp(status, "io")) bad = set_errno(e, file, f, m);
  Py_XDECREF(f);
  Py_XDECREF(m);
  Py_XDECREF(s);
  if (!bad) PyErr_SetObject(cls, e);
  Py_DECREF(e);
  return NULL;
}

PyObject* vdpy_raise(vd_status st, const vd_error* err) {
  if (st == VD_ERR_NOMEM && (!err || err->status == VD_OK)) return PyErr_NoMemory();
  PyObject* cls = (int)st > 0 && st < VD_STATUS_COUNT ? error_class[st] : error_base;
  char text[1024];
  const char* msg = vd_status_str(st);
  if (err && err->status != VD_OK) {
    vd_error_format(err, text, sizeof text);
    msg = err->msg[0] ? err->msg : msg;
  } else {
    snprintf(text, sizeof text, "%s", msg);
  }
  return raise_with(cls, status_key(st), err && err->status ? err->file : "",
                    err && err->status ? err->line : 0, err && err->status ? err->col : 0, msg, text);
}

PyObject* vdpy_arg_error(const char* fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return raise_with(error_class[VD_ERR_ARG], "arg", "", 0, 0, msg, msg);
}

PyObject* vdpy_busy(const char* what) {
  char msg[256];
  snprintf(msg, sizeof msg, "%s is in use by another thread (one thread at a time per object)", what);
  return raise_with(error_base, "busy", "", 0, 0, msg, msg);
}

static int make_errors(PyObject* mod) {
  error_base = PyErr_NewExceptionWithDoc(
      "verdant.Error",
      "Base class of verdant's errors. Attributes: status (short code: 'syntax', 'value', ...),\n"
      "file, line and column (1-based; '' and 0 when unknown) and message; str(e) is\n"
      "'file:line:column: message' like the command line's errors.",
      NULL, NULL);
  if (!error_base || PyModule_AddObjectRef(mod, "Error", error_base) < 0) return -1;
  for (size_t k = 0; k < sizeof error_kinds / sizeof error_kinds[0]; k++) {
    PyObject* extra = NULL;
    switch (error_kinds[k].st) {
    case VD_ERR_TYPE: extra = PyExc_TypeError; break;
    case VD_ERR_VALUE:
    case VD_ERR_ARG: extra = PyExc_ValueError; break;
    case VD_ERR_IO: extra = PyExc_OSError; break;
    case VD_ERR_NOMEM: extra = PyExc_MemoryError; break;
    default: break;
    }
    PyObject* bases = extra ? PyTuple_Pack(2, error_base, extra) : PyTuple_Pack(1, error_base);
    if (!bases) return -1;
    char full[64];
    snprintf(full, sizeof full, "verdant.%s", error_kinds[k].name);
    PyObject* cls = PyErr_NewExceptionWithDoc(full, error_kinds[k].doc, bases, NULL);
    Py_DECREF(bases);
    if (!cls || PyModule_AddObjectRef(mod, error_kinds[k].name, cls) < 0) return -1;
    error_class[error_kinds[k].st] = cls;
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// arrays and label tables

PyObject* vdpy_view(PyObject* owner, void* data, int nd, const npy_intp* dims, int typenum,
                    int writeable) {
  npy_intp count = 1;
  for (int k = 0; k < nd; k++) count *= dims[k];
  if (count == 0 || !data) {  // nothing to view: an empty array, read-only like a view would be
    PyObject* e = PyArray_ZEROS(nd, (npy_intp*)dims, typenum, 0);
    if (e && !writeable) PyArray_CLEARFLAGS((PyArrayObject*)e, NPY_ARRAY_WRITEABLE);
    return e;
  }
  PyObject* a = PyArray_SimpleNewFromData(nd, (npy_intp*)dims, typenum, data);
  if (!a) return NULL;
  Py_INCREF(owner);
  if (PyArray_SetBaseObject((PyArrayObject*)a, owner) < 0) {  // steals owner
    Py_DECREF(a);
    return NULL;
  }
  if (!writeable) PyArray_CLEARFLAGS((PyArrayObject*)a, NPY_ARRAY_WRITEABLE);
  return a;
}

PyObject* vdpy_label_dict(const vd_label* labels, int n) {
  PyObject* d = PyDict_New();
  for (int k = 0; d && k < n; k++) {
    PyObject* id = PyLong_FromLong(labels[k].id);
    PyObject* name = PyUnicode_DecodeUTF8(labels[k].name, (Py_ssize_t)strlen(labels[k].name), "replace");
    if (!id || !name || PyDict_SetItem(d, id, name) < 0) Py_CLEAR(d);
    Py_XDECREF(id);
    Py_XDECREF(name);
  }
  return d;
}

PyObject* vdpy_label_list(const vd_label* labels, int n) {
  PyObject* list = PyList_New(n);
  for (int k = 0; list && k < n; k++) {
    const vd_label* l = &labels[k];
    PyObject* e = Py_BuildValue("{s:i,s:s,s:s,s:(fff)}", "id", l->id, "name", l->name, "organ",
                                vd_organ_name(l->organ), "rgb", (double)l->rgb[0],
                                (double)l->rgb[1], (double)l->rgb[2]);
    if (!e) Py_CLEAR(list);
    else PyList_SET_ITEM(list, k, e);
  }
  return list;
}

// ---------------------------------------------------------------------------------------------
// module functions

PyTypeObject* vdpy_plant_class = &vdpy_plant_type;
PyTypeObject* vdpy_mesh_class = &vdpy_mesh_type;
PyTypeObject* vdpy_cloud_class = &vdpy_cloud_type;

// _register(plant=, mesh=, cloud=): the Python subclasses the C code instantiates
static PyObject* mod_register(PyObject* self, PyObject* args, PyObject* kw) {
  static char* names[] = {"plant", "mesh", "cloud", NULL};
  PyObject *p = NULL, *m = NULL, *c = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|$O!O!O!", names, &PyType_Type, &p, &PyType_Type, &m,
                                   &PyType_Type, &c))
    return NULL;
  struct {
    PyObject* cls;
    PyTypeObject* base;
    PyTypeObject** slot;
  } r[3] = {{p, &vdpy_plant_type, &vdpy_plant_class},
            {m, &vdpy_mesh_type, &vdpy_mesh_class},
            {c, &vdpy_cloud_type, &vdpy_cloud_class}};
  for (int k = 0; k < 3; k++) {
    if (!r[k].cls) continue;
    if (!PyType_IsSubtype((PyTypeObject*)r[k].cls, r[k].base))
      return vdpy_arg_error("_register: %s is not a subclass of %s",
                            ((PyTypeObject*)r[k].cls)->tp_name, r[k].base->tp_name);
    Py_INCREF(r[k].cls);
    if (*r[k].slot != r[k].base) Py_DECREF((PyObject*)*r[k].slot);
    *r[k].slot = (PyTypeObject*)r[k].cls;
  }
  Py_RETURN_NONE;
}

static PyObject* mod_alloc_bytes(PyObject* self, PyObject* unused) {
  return PyLong_FromLongLong((long long)vd_alloc_bytes());
}

static PyMethodDef methods[] = {
    {"grow", (PyCFunction)(void (*)(void))vdpy_grow, METH_VARARGS | METH_KEYWORDS,
     "grow($module, /, source, *, seed=0, steps=None, set=None, labels=None, max_modules=50000000, max_ops=0, curve_step=None, curve_connect=None, curve_distance=None)\n--\n\n"
     "grow(source, *, seed=0, steps=None, set=None, labels=None, max_modules=50000000,\n"
     "     max_ops=0, curve_step=None, curve_connect=None, curve_distance=None) -> Plant\n"
     "Low-level grow; see verdant.grow."},
    {"load", (PyCFunction)(void (*)(void))vdpy_load, METH_VARARGS | METH_KEYWORDS,
     "load($module, /, path, *, labels=None, seed=0)\n--\n\n"
     "load(path, *, labels=None, seed=0) -> Plant: read a plant JSON file."},
    {"read_cloud", (PyCFunction)(void (*)(void))vdpy_read_cloud, METH_VARARGS | METH_KEYWORDS,
     "read_cloud($module, /, path)\n--\n\n"
     "read_cloud(path) -> Cloud: read a cloud file written by verdant (.ply .pcd .xyz .csv .las)."},
    {"read_png", (PyCFunction)(void (*)(void))vdpy_read_png, METH_VARARGS | METH_KEYWORDS,
     "read_png($module, /, path)\n--\n\n"
     "read_png(path) -> numpy array: a PNG as written by verdant render (H x W x 3 uint8 colour,\n"
     "H x W uint16 depth in mm or label/instance ids)."},
    {"_register", (PyCFunction)(void (*)(void))mod_register, METH_VARARGS | METH_KEYWORDS,
     "_register($module, /, plant=None, mesh=None, cloud=None)\n--\n\n"
     "_register(plant=, mesh=, cloud=): Python subclasses the extension returns."},
    {"_cloud_unpickle", vdpy_cloud_unpickle, METH_VARARGS,
     "_cloud_unpickle($module, data, stats, /)\n--\n\nA Cloud from the bytes of Cloud.__reduce__ (pickling)."},
    {"alloc_bytes", mod_alloc_bytes, METH_NOARGS,
     "alloc_bytes($module, /)\n--\n\n"
     "alloc_bytes() -> int: bytes currently allocated by the C library (for leak checks)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "verdant._verdant",
    "verdant's C extension: the library's plants, clouds, simulation and renderer. Use the\n"
    "verdant package, which wraps it.",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__verdant(void);
PyMODINIT_FUNC PyInit__verdant(void) {
  import_array();
  PyObject* mod = PyModule_Create(&module);
  if (!mod) return NULL;
  PyTypeObject* types[] = {&vdpy_plant_type,    &vdpy_mesh_type,    &vdpy_cloud_type,  &vdpy_sim_type,
                           &vdpy_renderer_type, &vdpy_harvest_type, &vdpy_vector_type};
  const char* names[] = {"Plant", "Mesh", "Cloud", "Sim", "Renderer", "Harvest", "VectorHarvest"};
  for (int k = 0; k < (int)(sizeof types / sizeof types[0]); k++)
    if (PyType_Ready(types[k]) < 0 || PyModule_AddObjectRef(mod, names[k], (PyObject*)types[k]) < 0)
      goto fail;
  if (make_errors(mod) < 0) goto fail;
  if (PyModule_AddStringConstant(mod, "version", VD_VERSION_STRING) < 0) goto fail;
  return mod;
fail:
  Py_DECREF(mod);
  return NULL;
}
