// SPDX-License-Identifier: MIT
// Plants: growing from an .lpy file or text, reading plant and curves JSON, the Plant type
// (numpy views of the compiled model, save, mesh, cloud) and the Mesh type (a tessellation).
#include "py_internal.h"

#include <math.h>
#include <stddef.h>
#include <strings.h>
#include <structmember.h>
#include <time.h>

#define PATH_CAP 4096

// Does path end with ext (case-insensitive, ext with the dot)?
static int has_ext(const char* path, const char* ext) {
  size_t n = strlen(path), e = strlen(ext);
  return n >= e && strcasecmp(path + n - e, ext) == 0;
}

// ---------------------------------------------------------------------------------------------
// growing

// What grow() was asked, converted while holding the GIL.
typedef struct grow_args {
  char path[PATH_CAP];   // file to read, or "" for text
  const char* text;      // source text (borrowed from a str) when path is ""
  Py_ssize_t text_len;
  vd_lsys_def def;
  int nset;
  char (*set_name)[128]; // --set names (nset)
  char** set_value;      // --set values (nset), UTF-8, owned by the Python objects below
  int nlabel;
  int* label_id;         // --label ids (nlabel)
  char (*label_name)[VD_LABEL_NAME_MAX];  // --label names
  double curve[3];       // curve step, connect, distance (m), < 0: file's or default
  vd_lsys_engine engine; // who runs the file's Python (--engine)
  int instances;         // instances=: a vd_instance_mode, or VD_INSTANCE_DEFAULT
} grow_args;

// the whole load, without the GIL: the library's one loader (vd_plant_load), as the command line
static vd_status grow_run(const grow_args* a, vd_plant_spec** out, vd_plant_load_info* info, vd_error* err) {
  const char** names = vd_calloc((size_t)a->nset + (size_t)a->nlabel + 1, sizeof *names);
  if (!names) return vd_error_set(err, VD_ERR_NOMEM, a->path, 0, 0, "out of memory");
  const char** labels = names + a->nset;
  for (int i = 0; i < a->nset; i++) names[i] = a->set_name[i];
  for (int i = 0; i < a->nlabel; i++) labels[i] = a->label_name[i];
  vd_plant_load_def d = vd_plant_load_def_default();
  d.lsys = a->def;
  d.engine = a->engine;
  d.set_name = names, d.set_value = (const char* const*)a->set_value, d.nset = a->nset;
  d.label_id = a->label_id, d.label_name = labels, d.nlabel = a->nlabel;
  d.curve_step = a->curve[0], d.curve_connect = a->curve[1], d.curve_distance = a->curve[2];
  d.instances = a->instances;
  vd_status st = a->path[0] ? vd_plant_load(a->path, &d, out, info, err)
                            : vd_plant_load_text(a->text, (size_t)a->text_len, NULL, &d, out, info, err);
  vd_free(names, ((size_t)a->nset + (size_t)a->nlabel + 1) * sizeof *names);
  return st;
}

vd_status vdpy_grow_file(const char* path, uint64_t seed, int steps, char* const* sets, int nset,
                         vd_plant_spec** out, vd_error* err) {
  grow_args a;
  memset(&a, 0, sizeof a);
  a.def = vd_lsys_def_default();
  a.def.max_modules = 50000000;
  a.def.seed = seed;
  a.def.steps = steps;
  a.curve[0] = a.curve[1] = a.curve[2] = -1;
  a.instances = VD_INSTANCE_DEFAULT;
  snprintf(a.path, sizeof a.path, "%s", path);
  // "NAME=VALUE" overrides, split into the arrays grow_run reads
  char(*names)[128] = nset ? vd_calloc((size_t)nset, sizeof *names) : NULL;
  char** values = nset ? vd_calloc((size_t)nset, sizeof *values) : NULL;
  if (nset && (!names || !values)) {
    vd_free(names, (size_t)nset * sizeof *names);
    vd_free(values, (size_t)nset * sizeof *values);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  }
  for (int i = 0; i < nset; i++) {
    const char* eq = strchr(sets[i], '=');
    size_t n = eq ? (size_t)(eq - sets[i]) : strlen(sets[i]);
    snprintf(names[i], sizeof names[i], "%.*s", (int)(n < 127 ? n : 127), sets[i]);
    values[i] = eq ? (char*)eq + 1 : (char*)"";
  }
  a.nset = nset, a.set_name = names, a.set_value = values;
  vd_status st = grow_run(&a, out, NULL, err);
  vd_free(names, (size_t)nset * sizeof *names);
  vd_free(values, (size_t)nset * sizeof *values);
  return st;
}

// the derivation's summary: modules, module_counts (by symbol, in symbol order), seconds
static PyObject* grow_info(const vd_plant_load_info* o, int lsys) {
  if (!lsys) return PyDict_New();
  PyObject* counts = PyDict_New();
  for (int k = 0; counts && k < o->nsym; k++) {
    if (!o->sym_count[k]) continue;
    PyObject* v = PyLong_FromLongLong((long long)o->sym_count[k]);
    if (!v || PyDict_SetItemString(counts, o->sym_name[k], v) < 0) Py_CLEAR(counts);
    Py_XDECREF(v);
  }
  if (!counts) return NULL;
  return Py_BuildValue("{s:s,s:L,s:N,s:{s:d,s:d}}", "engine", o->engine ? o->engine : "native", "modules",
                       (long long)o->modules, "module_counts", counts, "seconds", "derive", o->seconds_derive,
                       "turtle", o->seconds_turtle);
}

// set= values: str as written, numbers, booleans, lists and tuples by their repr
static PyObject* set_text(PyObject* v, const char* name) {
  if (PyUnicode_Check(v)) return Py_NewRef(v);
  if (PyNumber_Check(v) || PyList_Check(v) || PyTuple_Check(v)) return PyObject_Repr(v);
  return PyErr_Format(PyExc_TypeError, "set[%s] expects a str (a Python expression), a number, "
                                       "a bool, a list or a tuple, got %s",
                      name, Py_TYPE(v)->tp_name);
}

PyObject* vdpy_grow(PyObject* self, PyObject* args, PyObject* kw) {
  static const char* const names[] = {"seed", "steps", "set", "labels", "max_modules", "max_ops",
                                      "curve_step", "curve_connect", "curve_distance", "engine", "instances", NULL};
  PyObject* source;
  if (!PyArg_ParseTuple(args, "O:grow", &source) || !vdpy_kw_check(kw, "grow", names)) return NULL;
  grow_args a;
  memset(&a, 0, sizeof a);
  a.def = vd_lsys_def_default();
  a.def.max_modules = 50000000;  // the command line's default
  a.curve[0] = a.curve[1] = a.curve[2] = -1;
  a.instances = VD_INSTANCE_DEFAULT;
  PyObject* values = NULL;  // keeps set= texts alive
  PyObject* result = NULL;
  PyObject* o;
  int64_t v;
  // the source: a path (os.PathLike, bytes, or a str without a newline) or the text itself
  char label[PATH_CAP + 16];
  if (PyUnicode_Check(source) && PyUnicode_FindChar(source, '\n', 0, PyUnicode_GET_LENGTH(source), 1) >= 0) {
    a.text = PyUnicode_AsUTF8AndSize(source, &a.text_len);
    if (!a.text) return NULL;
    if (memchr(a.text, 0, (size_t)a.text_len)) return vdpy_arg_error("source text holds a NUL character");
    snprintf(label, sizeof label, "<string>");
  } else {
    if (!vdpy_path(source, "source", a.path, sizeof a.path)) return NULL;
    if (!a.path[0]) return vdpy_arg_error("source is an empty path");
    snprintf(label, sizeof label, "%s", a.path);
  }
  if ((o = vdpy_kw(kw, "seed"))) {
    if (!vdpy_i64(o, "seed", 0, INT64_MAX, &v)) return NULL;
    a.def.seed = (uint64_t)v;
  }
  if ((o = vdpy_kw(kw, "steps"))) {
    if (!vdpy_i64(o, "steps", 0, 1000000000, &v)) return NULL;
    a.def.steps = (int)v;
  }
  if ((o = vdpy_kw(kw, "max_modules"))) {
    if (!vdpy_i64(o, "max_modules", 1, INT64_MAX / 64, &v)) return NULL;
    a.def.max_modules = v;
  }
  if ((o = vdpy_kw(kw, "max_ops"))) {
    if (!vdpy_i64(o, "max_ops", 0, INT64_MAX, &v)) return NULL;
    a.def.max_ops = v;
  }
  if ((o = vdpy_kw(kw, "engine"))) {
    char e[16];
    if (!vdpy_str(o, "engine", e, sizeof e)) return NULL;
    if (!strcmp(e, "auto")) a.engine = VD_LSYS_AUTO;
    else if (!strcmp(e, "native")) a.engine = VD_LSYS_NATIVE;
    else if (!strcmp(e, "python")) a.engine = VD_LSYS_PYTHON;
    else return vdpy_arg_error("engine expects 'auto', 'native' or 'python', got '%s'", e);
  }
  if ((o = vdpy_kw(kw, "instances"))) {
    char e[16];
    if (!vdpy_str(o, "instances", e, sizeof e)) return NULL;
    if (!strcmp(e, "modules")) a.instances = VD_INSTANCE_MODULES;
    else if (!strcmp(e, "organs")) a.instances = VD_INSTANCE_ORGANS;
    else return vdpy_arg_error("instances expects 'organs' or 'modules', got '%s'", e);
  }
  const char* curve_names[3] = {"curve_step", "curve_connect", "curve_distance"};
  for (int k = 0; k < 3; k++)
    if ((o = vdpy_kw(kw, curve_names[k])) && !vdpy_f64(o, curve_names[k], k ? 0 : 1e-6, 1e3, &a.curve[k]))
      return NULL;
  // set= and labels=: dicts, converted into arrays the library reads without the GIL
  PyObject* set = vdpy_kw(kw, "set");
  PyObject* labels = vdpy_kw(kw, "labels");
  if (set && !PyDict_Check(set)) return PyErr_Format(PyExc_TypeError, "set expects a dict {name: value}");
  if (labels && !PyDict_Check(labels)) return PyErr_Format(PyExc_TypeError, "labels expects a dict {id: name}");
  Py_ssize_t nset = set ? PyDict_Size(set) : 0, nlab = labels ? PyDict_Size(labels) : 0;
  if (nset > 4096 || nlab > 65536) return vdpy_arg_error("too many set= or labels= entries");
  a.nset = (int)nset, a.nlabel = (int)nlab;
  values = PyList_New(0);
  a.set_name = PyMem_Calloc((size_t)nset + 1, sizeof *a.set_name);
  a.set_value = PyMem_Calloc((size_t)nset + 1, sizeof *a.set_value);
  a.label_id = PyMem_Calloc((size_t)nlab + 1, sizeof *a.label_id);
  a.label_name = PyMem_Calloc((size_t)nlab + 1, sizeof *a.label_name);
  if (!values || !a.set_name || !a.set_value || !a.label_id || !a.label_name) {
    PyErr_NoMemory();
    goto done;
  }
  {
    PyObject *key, *val;
    Py_ssize_t pos = 0;
    int i = 0;
    while (set && PyDict_Next(set, &pos, &key, &val)) {
      if (!vdpy_str(key, "set names", a.set_name[i], sizeof a.set_name[i])) goto done;
      PyObject* t = set_text(val, a.set_name[i]);
      if (!t || PyList_Append(values, t) < 0) {
        Py_XDECREF(t);
        goto done;
      }
      Py_DECREF(t);
      a.set_value[i] = (char*)PyUnicode_AsUTF8(t);
      if (!a.set_value[i]) goto done;
      i++;
    }
    pos = 0, i = 0;
    while (labels && PyDict_Next(labels, &pos, &key, &val)) {
      if (!vdpy_i64(key, "label ids", 0, 65535, &v)) goto done;
      a.label_id[i] = (int)v;
      if (!vdpy_str(val, "label names", a.label_name[i], sizeof a.label_name[i])) goto done;
      if (!a.label_name[i][0]) {
        vdpy_arg_error("label %d: empty name", a.label_id[i]);
        goto done;
      }
      i++;
    }
  }
  {
    vd_plant_spec* spec = NULL;
    vd_plant_load_info out;
    memset(&out, 0, sizeof out);
    vd_error err = {0};
    vd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = grow_run(&a, &spec, &out, &err);
    Py_END_ALLOW_THREADS
    if (st) {
      if (!err.file[0] && err.status) snprintf(err.file, sizeof err.file, "%.255s", label);
      vdpy_raise(st, &err);
    } else {
      PyObject* info = grow_info(&out, out.format == VD_PLANT_FORMAT_LPY);
      if (info) {
        result = vdpy_plant_new(spec, a.def.seed, label, info);
        spec = NULL;  // taken
        Py_DECREF(info);
      }
    }
    vd_plant_spec_destroy(spec);
    vd_plant_load_info_free(&out);
  }
done:
  Py_XDECREF(values);
  PyMem_Free(a.set_name);
  PyMem_Free(a.set_value);
  PyMem_Free(a.label_id);
  PyMem_Free(a.label_name);
  return result;
}

PyObject* vdpy_load(PyObject* self, PyObject* args, PyObject* kw) {
  static char* names[] = {"path", "labels", "seed", NULL};
  PyObject *path, *labels = Py_None, *seed = Py_None;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$OO:load", names, &path, &labels, &seed)) return NULL;
  char p[PATH_CAP];
  if (!vdpy_path(path, "path", p, sizeof p)) return NULL;
  if (!has_ext(p, ".json")) return vdpy_arg_error("load reads plant JSON files (.json); grow() takes .lpy files");
  PyObject* a = Py_BuildValue("(O)", path);
  PyObject* k = a ? Py_BuildValue("{s:O,s:O}", "labels", labels, "seed", seed) : NULL;
  PyObject* r = k ? vdpy_grow(self, a, k) : NULL;
  Py_XDECREF(a);
  Py_XDECREF(k);
  return r;
}

// ---------------------------------------------------------------------------------------------
// Plant

PyObject* vdpy_plant_new(vd_plant_spec* spec, uint64_t seed, const char* source, PyObject* info) {
  vd_model* m = NULL;
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_plant_compile(spec, &m, &err);
  Py_END_ALLOW_THREADS
  if (st) {
    vd_plant_spec_destroy(spec);
    if (!err.file[0] && err.status) snprintf(err.file, sizeof err.file, "%.255s", source);
    return vdpy_raise(st, &err);
  }
  vdpy_plant* p = (vdpy_plant*)vdpy_plant_class->tp_alloc(vdpy_plant_class, 0);
  if (!p) {
    vd_model_destroy(m);
    vd_plant_spec_destroy(spec);
    return NULL;
  }
  p->spec = spec;
  p->model = m;
  p->seed = seed;
  p->source = PyUnicode_DecodeFSDefault(source);
  p->info = info ? Py_NewRef(info) : PyDict_New();
  if (!p->source || !p->info) Py_CLEAR(p);
  return (PyObject*)p;
}

static void plant_dealloc(vdpy_plant* p) {
  vd_model_destroy(p->model);
  vd_plant_spec_destroy(p->spec);
  Py_XDECREF(p->source);
  Py_XDECREF(p->info);
  Py_TYPE(p)->tp_free((PyObject*)p);
}

// one getter per model array: (name, field, rows, cols, numpy type)
#define PLANT_ARRAY(getter, field, rows, cols, type)                                               \
  static PyObject* getter(vdpy_plant* p, void* c) {                                                \
    npy_intp dims[2] = {p->model->rows, cols};                                                     \
    return vdpy_view((PyObject*)p, p->model->field, (cols) > 1 ? 2 : 1, dims, type, 0);            \
  }
PLANT_ARRAY(plant_nodes, node_pos0, nnode, 3, NPY_DOUBLE)
PLANT_ARRAY(plant_segments, seg_node, nseg, 2, NPY_INT32)
PLANT_ARRAY(plant_radii, seg_radius, nseg, 2, NPY_DOUBLE)
PLANT_ARRAY(plant_labels, seg_label, nseg, 1, NPY_INT32)
PLANT_ARRAY(plant_instances, seg_instance, nseg, 1, NPY_INT32)
PLANT_ARRAY(plant_parents, seg_parent, nseg, 1, NPY_INT32)
PLANT_ARRAY(plant_axes, seg_axis, nseg, 1, NPY_INT32)
PLANT_ARRAY(plant_orders, seg_order, nseg, 1, NPY_INT32)
PLANT_ARRAY(plant_frames, seg_quat0, nseg, 4, NPY_DOUBLE)
PLANT_ARRAY(plant_spheres, sphere_pos0, nsphere, 3, NPY_DOUBLE)
PLANT_ARRAY(plant_sphere_radii, sphere_radius, nsphere, 1, NPY_DOUBLE)
PLANT_ARRAY(plant_sphere_labels, sphere_label, nsphere, 1, NPY_INT32)
PLANT_ARRAY(plant_sphere_instances, sphere_instance, nsphere, 1, NPY_INT32)
PLANT_ARRAY(plant_sphere_nodes, sphere_node, nsphere, 1, NPY_INT32)
PLANT_ARRAY(plant_vertices, vert_pos0, nvert, 3, NPY_DOUBLE)
PLANT_ARRAY(plant_triangles, tri_vert, ntri, 3, NPY_INT32)
PLANT_ARRAY(plant_mesh_vert, mesh_vert, nmesh, 2, NPY_INT32)
PLANT_ARRAY(plant_mesh_tri, mesh_tri, nmesh, 2, NPY_INT32)
PLANT_ARRAY(plant_mesh_labels, mesh_label, nmesh, 1, NPY_INT32)
PLANT_ARRAY(plant_mesh_instances, mesh_instance, nmesh, 1, NPY_INT32)
PLANT_ARRAY(plant_mesh_closed, mesh_closed, nmesh, 1, NPY_INT32)
#undef PLANT_ARRAY

static PyObject* plant_label_names(vdpy_plant* p, void* c) {
  return vdpy_label_dict(p->model->labels, p->model->nlabel);
}
static PyObject* plant_label_table(vdpy_plant* p, void* c) {
  return vdpy_label_list(p->model->labels, p->model->nlabel);
}
static PyObject* plant_seed(vdpy_plant* p, void* c) {
  return PyLong_FromUnsignedLongLong(p->seed);
}
static PyObject* plant_source(vdpy_plant* p, void* c) { return Py_NewRef(p->source); }
static PyObject* plant_info(vdpy_plant* p, void* c) { return PyDict_Copy(p->info); }
// per-instance traits (vd_plant_traits), as `verdant grow --traits` writes them
static PyObject* plant_traits(vdpy_plant* p, void* c) {
  vd_organ_traits* t;
  int n;
  if (vd_plant_traits(p->spec, &t, &n)) return PyErr_NoMemory();
  PyObject* list = PyList_New(0);
  for (int i = 0; list && i < n; i++) {
    const vd_organ_traits* o = &t[i];
    if (o->nseg + o->nsphere + o->nmesh == 0) continue;
    PyObject* d = Py_BuildValue("{s:i,s:i,s:s,s:i,s:i,s:i,s:d,s:d,s:d,s:d,s:(ddd),s:(ddd)}", "instance", o->instance,
                                "label", o->label, "organ", vd_organ_name(o->organ), "segments", o->nseg, "spheres",
                                o->nsphere, "meshes", o->nmesh, "length_m", o->length, "area_m2", o->area, "diameter_m",
                                o->diameter, "volume_m3", o->volume, "bbox_min", o->bbox_min.x, o->bbox_min.y,
                                o->bbox_min.z, "bbox_max", o->bbox_max.x, o->bbox_max.y, o->bbox_max.z);
    if (!d || PyList_Append(list, d) < 0) Py_CLEAR(list);
    Py_XDECREF(d);
  }
  vd_free(t, (size_t)n * sizeof *t);
  return list;
}
static PyObject* plant_geometry(vdpy_plant* p, void* c) {
  vd_plant_stats s;
  vd_plant_spec_stats(p->spec, &s);
  return Py_BuildValue("{s:i,s:i,s:i,s:i,s:i,s:i,s:(ddd),s:(ddd),s:d}", "nodes", p->spec->nnode,
                       "segments", s.nseg, "spheres", s.nsphere, "leaves", s.nleaf, "meshes",
                       p->spec->nmesh, "instances", p->spec->ninstance, "bbox_min", s.bbox_min.x,
                       s.bbox_min.y, s.bbox_min.z, "bbox_max", s.bbox_max.x, s.bbox_max.y,
                       s.bbox_max.z, "total_length", s.total_length);
}

static PyGetSetDef plant_getset[] = {
    {"nodes", (getter)plant_nodes, NULL, "node positions (m), float64 (nnode x 3)", NULL},
    {"segments", (getter)plant_segments, NULL, "start and end node of each segment, int32 (nseg x 2)", NULL},
    {"radii", (getter)plant_radii, NULL, "segment radius at start and end (m), float64 (nseg x 2)", NULL},
    {"labels", (getter)plant_labels, NULL, "semantic label id of each segment, int32 (nseg)", NULL},
    {"instances", (getter)plant_instances, NULL, "organ instance id of each segment, int32 (nseg)", NULL},
    {"parents", (getter)plant_parents, NULL, "parent segment or -1, int32 (nseg)", NULL},
    {"axes", (getter)plant_axes, NULL, "branch axis id of each segment, int32 (nseg)", NULL},
    {"orders", (getter)plant_orders, NULL, "branching order of each segment, int32 (nseg)", NULL},
    {"frames", (getter)plant_frames, NULL, "segment frames w,x,y,z (z along the segment), float64 (nseg x 4)", NULL},
    {"spheres", (getter)plant_spheres, NULL, "sphere centres (m), float64 (nsphere x 3)", NULL},
    {"sphere_radii", (getter)plant_sphere_radii, NULL, "sphere radii (m), float64 (nsphere)", NULL},
    {"sphere_labels", (getter)plant_sphere_labels, NULL, "sphere label ids, int32 (nsphere)", NULL},
    {"sphere_instances", (getter)plant_sphere_instances, NULL, "sphere instance ids, int32 (nsphere)", NULL},
    {"sphere_nodes", (getter)plant_sphere_nodes, NULL, "sphere attachment node or -1, int32 (nsphere)", NULL},
    {"vertices", (getter)plant_vertices, NULL, "vertices of the leaf/organ meshes (m), float64 (nvert x 3)", NULL},
    {"triangles", (getter)plant_triangles, NULL, "their triangles, indices into vertices, int32 (ntri x 3)", NULL},
    {"mesh_vertex_range", (getter)plant_mesh_vert, NULL, "first vertex and count of each mesh, int32 (nmesh x 2)", NULL},
    {"mesh_triangle_range", (getter)plant_mesh_tri, NULL, "first triangle and count of each mesh, int32 (nmesh x 2)", NULL},
    {"mesh_labels", (getter)plant_mesh_labels, NULL, "mesh label ids, int32 (nmesh)", NULL},
    {"mesh_instances", (getter)plant_mesh_instances, NULL, "mesh instance ids, int32 (nmesh)", NULL},
    {"mesh_closed", (getter)plant_mesh_closed, NULL, "1 for closed meshes (volumes), int32 (nmesh)", NULL},
    {"label_names", (getter)plant_label_names, NULL, "label table as a dict {id: name}", NULL},
    {"label_table", (getter)plant_label_table, NULL, "label table: dicts of id, name, organ, rgb", NULL},
    {"seed", (getter)plant_seed, NULL, "growth seed (also the default seed of its clouds)", NULL},
    {"source", (getter)plant_source, NULL, "the file it came from, or '<string>'", NULL},
    {"_info", (getter)plant_info, NULL, "derivation summary: modules, module_counts, seconds", NULL},
    {"traits", (getter)plant_traits, NULL,
     "per-instance traits (one dict per instance: instance, label, organ, segments, spheres, meshes, length_m, "
     "area_m2, diameter_m, volume_m3, bbox_min, bbox_max), as `verdant grow --traits`",
     NULL},
    {"_geometry", (getter)plant_geometry, NULL, "counts, bounding box (m), total length (m)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

// a mesh with the plant's label table as OBJ (with its MTL) or PLY (binary unless ascii)
static vd_status write_mesh(const vd_mesh* mesh, const vd_model* m, const char* out, int obj, int ascii,
                            vd_error* err) {
  return obj ? vd_geom_write_obj(mesh, m->labels, m->nlabel, out, err)
             : vd_geom_write_ply(mesh, m->labels, m->nlabel, out, !ascii, err);
}

// write the spec (JSON) or the rest shape's tessellation (OBJ with MTL, PLY), as `verdant grow -o`
static PyObject* plant_save(vdpy_plant* p, PyObject* args, PyObject* kw) {
  static char* names[] = {"path", "ascii", NULL};
  PyObject* path;
  int ascii = 0;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$p:save", names, &path, &ascii)) return NULL;
  char out[PATH_CAP];
  if (!vdpy_path(path, "path", out, sizeof out)) return NULL;
  int json = has_ext(out, ".json"), obj = has_ext(out, ".obj"), ply = has_ext(out, ".ply");
  if (!json && !obj && !ply) return vdpy_arg_error("save: '%s': unknown format (use .json, .obj or .ply)", out);
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  if (json) {
    st = vd_plant_write_json(p->spec, out, &err);
  } else {
    vd_mesh mesh;
    st = vd_geom_tessellate(p->model, NULL, NULL, &mesh, &err);
    if (!st) {
      st = write_mesh(&mesh, p->model, out, obj, ascii, &err);
      vd_mesh_free(&mesh);
    }
  }
  Py_END_ALLOW_THREADS
  if (st) return vdpy_raise(st, &err);
  Py_RETURN_NONE;
}

static PyObject* plant_mesh(vdpy_plant* p, PyObject* args, PyObject* kw) {
  static char* names[] = {"slices", "stacks", "caps", NULL};
  PyObject *slices = Py_None, *stacks = Py_None;
  int caps = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|$OOp:mesh", names, &slices, &stacks, &caps)) return NULL;
  vd_mesh_def def = vd_mesh_def_default();
  int64_t v;
  if (slices != Py_None) {
    if (!vdpy_i64(slices, "slices", 3, 1024, &v)) return NULL;
    def.slices = (int)v;
  }
  if (stacks != Py_None) {
    if (!vdpy_i64(stacks, "stacks", 2, 1024, &v)) return NULL;
    def.sphere_stacks = (int)v;
  }
  def.caps = caps;
  vdpy_mesh* m = (vdpy_mesh*)vdpy_mesh_class->tp_alloc(vdpy_mesh_class, 0);
  if (!m) return NULL;
  m->plant = Py_NewRef((PyObject*)p);
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_geom_tessellate(p->model, NULL, &def, &m->mesh, &err);
  Py_END_ALLOW_THREADS
  if (st) {
    Py_DECREF(m);
    return vdpy_raise(st, &err);
  }
  return (PyObject*)m;
}

static PyObject* plant_cloud(vdpy_plant* p, PyObject* args, PyObject* kw) {
  if (PyTuple_GET_SIZE(args)) return PyErr_Format(PyExc_TypeError, "cloud() takes keyword arguments only");
  return vdpy_cloud_make(p->spec, p->model, NULL, p->seed, kw);
}

static PyObject* plant_reduce(vdpy_plant* p, PyObject* unused) {
  return PyErr_Format(PyExc_TypeError, "a Plant cannot be pickled; save() it or pass its source and seed");
}

static PyMethodDef plant_methods[] = {
    {"save", (PyCFunction)(void (*)(void))plant_save, METH_VARARGS | METH_KEYWORDS,
     "save($self, /, path, *, ascii=False)\n--\n\n"
     "save(path, *, ascii=False): write the plant as plant JSON (.json), a labelled OBJ mesh with\n"
     "its MTL (.obj) or a PLY mesh with face label and instance (.ply, binary unless ascii).\n"
     "The same bytes as `verdant grow PLANT -o path`."},
    {"mesh", (PyCFunction)(void (*)(void))plant_mesh, METH_VARARGS | METH_KEYWORDS,
     "mesh($self, /, *, slices=None, stacks=None, caps=True)\n--\n\n"
     "mesh(*, slices=None, stacks=None, caps=True) -> Mesh: the labelled triangle mesh of the\n"
     "plant (slices: sides of every frustum and sphere, default each primitive's own)."},
    {"_cloud", (PyCFunction)(void (*)(void))plant_cloud, METH_VARARGS | METH_KEYWORDS,
     "_cloud($self, /, **options)\n--\n\nLow-level cloud sampler; see Plant.cloud."},
    {"__reduce__", (PyCFunction)plant_reduce, METH_NOARGS, NULL},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_plant_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.Plant",
    .tp_basicsize = sizeof(vdpy_plant),
    .tp_dealloc = (destructor)plant_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "A labelled plant (made by verdant.grow or verdant.load).",
    .tp_methods = plant_methods,
    .tp_getset = plant_getset,
};

// ---------------------------------------------------------------------------------------------
// Mesh

static void mesh_dealloc(vdpy_mesh* m) {
  vd_mesh_free(&m->mesh);
  Py_XDECREF(m->plant);
  Py_TYPE(m)->tp_free((PyObject*)m);
}

#define MESH_ARRAY(getter, field, rows, cols, type)                                                \
  static PyObject* getter(vdpy_mesh* m, void* c) {                                                 \
    npy_intp dims[2] = {m->mesh.rows, cols};                                                       \
    return vdpy_view((PyObject*)m, m->mesh.field, (cols) > 1 ? 2 : 1, dims, type, 0);              \
  }
MESH_ARRAY(mesh_vertices, pos, nvert, 3, NPY_DOUBLE)
MESH_ARRAY(mesh_normals, normal, nvert, 3, NPY_DOUBLE)
MESH_ARRAY(mesh_triangles, tri, ntri, 3, NPY_INT32)
MESH_ARRAY(mesh_label, tri_label, ntri, 1, NPY_INT32)
MESH_ARRAY(mesh_instance, tri_instance, ntri, 1, NPY_INT32)
MESH_ARRAY(mesh_prim, tri_prim, ntri, 1, NPY_INT32)
MESH_ARRAY(mesh_kind, tri_kind, ntri, 1, NPY_INT32)
#undef MESH_ARRAY

static PyObject* mesh_labels(vdpy_mesh* m, void* c) {
  const vd_model* pm = ((vdpy_plant*)m->plant)->model;
  return vdpy_label_dict(pm->labels, pm->nlabel);
}

static PyGetSetDef mesh_getset[] = {
    {"vertices", (getter)mesh_vertices, NULL, "vertex positions (m), float64 (nvert x 3)", NULL},
    {"normals", (getter)mesh_normals, NULL, "unit outward vertex normals, float64 (nvert x 3)", NULL},
    {"triangles", (getter)mesh_triangles, NULL, "vertex indices, counter-clockwise from outside, int32 (ntri x 3)", NULL},
    {"label", (getter)mesh_label, NULL, "semantic label id per triangle, int32 (ntri)", NULL},
    {"instance", (getter)mesh_instance, NULL, "organ instance id per triangle, int32 (ntri)", NULL},
    {"prim", (getter)mesh_prim, NULL, "primitive index within its kind per triangle, int32 (ntri)", NULL},
    {"kind", (getter)mesh_kind, NULL, "primitive kind per triangle: 0 segment, 1 sphere, 2 mesh, int32 (ntri)", NULL},
    {"labels", (getter)mesh_labels, NULL, "label table as a dict {id: name}", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMemberDef mesh_members[] = {
    {"plant", T_OBJECT_EX, offsetof(vdpy_mesh, plant), READONLY, "the plant it was made from"},
    {NULL, 0, 0, 0, NULL},
};

static PyObject* mesh_save(vdpy_mesh* m, PyObject* args, PyObject* kw) {
  static char* names[] = {"path", "ascii", NULL};
  PyObject* path;
  int ascii = 0;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$p:save", names, &path, &ascii)) return NULL;
  char out[PATH_CAP];
  if (!vdpy_path(path, "path", out, sizeof out)) return NULL;
  int obj = has_ext(out, ".obj"), ply = has_ext(out, ".ply");
  if (!obj && !ply) return vdpy_arg_error("save: '%s': unknown format (use .obj or .ply)", out);
  const vd_model* pm = ((vdpy_plant*)m->plant)->model;
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = write_mesh(&m->mesh, pm, out, obj, ascii, &err);
  Py_END_ALLOW_THREADS
  if (st) return vdpy_raise(st, &err);
  Py_RETURN_NONE;
}

static PyMethodDef mesh_methods[] = {
    {"save", (PyCFunction)(void (*)(void))mesh_save, METH_VARARGS | METH_KEYWORDS,
     "save($self, /, path, *, ascii=False)\n--\n\n"
     "save(path, *, ascii=False): write OBJ (+MTL, faces grouped by label/instance) or PLY (face\n"
     "label and instance; binary unless ascii)."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_mesh_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.Mesh",
    .tp_basicsize = sizeof(vdpy_mesh),
    .tp_dealloc = (destructor)mesh_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "A labelled triangle mesh of a plant (Plant.mesh()).",
    .tp_methods = mesh_methods,
    .tp_members = mesh_members,
    .tp_getset = mesh_getset,
};
