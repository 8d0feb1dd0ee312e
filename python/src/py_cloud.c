// SPDX-License-Identifier: MIT
// Point clouds: Plant.cloud's options (the command line's cloud options, checked the same way),
// sampling without the GIL, the Cloud type (numpy views of the library's point block), files.
#include "py_internal.h"

#include <math.h>
#include <strings.h>

#define PATH_CAP 4096
#define MAX_SCANNERS 65535

static const char* sensor_name(int s) {
  return s == VD_SENSOR_UNIFORM ? "uniform" : s == VD_SENSOR_DISTANCE ? "distance" : "scan";
}

// a str option among choices; *out gets its index
static int choice(PyObject* o, const char* name, const char* const* choices, int* out) {
  char buf[64];
  if (!vdpy_str(o, name, buf, sizeof buf)) return 0;
  for (int k = 0; choices[k]; k++)
    if (!strcmp(buf, choices[k])) {
      *out = k;
      return 1;
    }
  char list[256] = "";
  for (int k = 0; choices[k]; k++)
    snprintf(list + strlen(list), sizeof list - strlen(list), "%s'%s'", k ? ", " : "", choices[k]);
  vdpy_arg_error("%s expects one of %s, got '%s'", name, list, buf);
  return 0;
}

// scanners: a preset path, or a list of (x, y, z) / (x, y, z, tx, ty, tz) positions and preset
// paths, expanded in order; positions look at the plant's bounding-box centre unless given
static int scanners(PyObject* o, const vd_plant_spec* spec, const vd_scanner* proto,
                    vd_scanner** out, int* n) {
  *out = NULL;
  *n = 0;
  PyObject* seq = NULL;
  if (PyUnicode_Check(o) || PyBytes_Check(o) || PyObject_HasAttrString(o, "__fspath__")) {
    seq = PyTuple_Pack(1, o);
  } else if (PyList_Check(o) || PyTuple_Check(o) || PyArray_Check(o)) {
    seq = PySequence_Fast(o, "scanners");  // a numpy array (k, 3) or (k, 6) too
  } else {
    PyErr_Format(PyExc_TypeError, "scanners expects a preset path or a list of positions, got %s",
                 Py_TYPE(o)->tp_name);
    return 0;
  }
  if (!seq) return 0;
  vd_plant_stats ps;
  vd_plant_spec_stats(spec, &ps);
  vd_vec3 centre = vd_scale(vd_add(ps.bbox_min, ps.bbox_max), 0.5);
  int cap = 0, ok = 1;
  vd_scanner* sc = NULL;
  for (Py_ssize_t i = 0; ok && i < PySequence_Fast_GET_SIZE(seq); i++) {
    PyObject* item = PySequence_Fast_GET_ITEM(seq, i);
    vd_scanner* add = NULL;
    int nadd = 0;
    vd_scanner one;
    if (PyUnicode_Check(item) || PyBytes_Check(item) || PyObject_HasAttrString(item, "__fspath__")) {
      char path[PATH_CAP];
      vd_error err = {0};
      vd_status st;
      ok = vdpy_path(item, "scanners", path, sizeof path);
      if (ok) {
        Py_BEGIN_ALLOW_THREADS
        st = vd_cloud_read_scanners(path, ps.bbox_min, ps.bbox_max, &add, &nadd, &err);
        Py_END_ALLOW_THREADS
        if (st) ok = (vdpy_raise(st, &err), 0);
      }
    } else {
      double x[6];
      Py_ssize_t len = PySequence_Check(item) ? PySequence_Size(item) : -1;
      if (len != 3 && len != 6) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "scanners[%zd] expects (x, y, z) or (x, y, z, tx, ty, tz) in "
                                      "metres, or a preset path", i);
        ok = 0;
      } else {
        ok = vdpy_vec(item, "scanners", (int)len, x);
      }
      if (ok) {
        one = *proto;
        one.pos = vd_v3(x[0], x[1], x[2]);
        one.target = len == 6 ? vd_v3(x[3], x[4], x[5]) : centre;
        if (vd_norm(vd_sub(one.target, one.pos)) == 0)
          ok = (vdpy_arg_error("scanners[%zd]: the scanner sits on its target; give a target", i), 0);
        add = &one, nadd = 1;
      }
    }
    if (ok && *n + nadd > MAX_SCANNERS) ok = (vdpy_arg_error("more than %d scanners", MAX_SCANNERS), 0);
    if (ok && !vd_grow((void**)&sc, &cap, *n + nadd, sizeof *sc)) ok = (PyErr_NoMemory(), 0);
    if (ok) memcpy(sc + *n, add, (size_t)nadd * sizeof *sc), *n += nadd;
    if (add && add != &one) vd_free(add, (size_t)nadd * sizeof *add);
  }
  Py_DECREF(seq);
  if (!ok) {
    vd_free(sc, (size_t)cap * sizeof *sc);
    *n = 0;
    return 0;
  }
  // exact size, so the caller frees n entries
  if (cap > *n) {
    vd_scanner* s2 = *n ? vd_malloc((size_t)*n * sizeof *s2) : NULL;
    if (*n && !s2) {
      vd_free(sc, (size_t)cap * sizeof *sc);
      *n = 0;
      PyErr_NoMemory();
      return 0;
    }
    if (*n) memcpy(s2, sc, (size_t)*n * sizeof *s2);
    vd_free(sc, (size_t)cap * sizeof *sc);
    sc = s2;
  }
  *out = sc;
  return 1;
}

// density_law: a name or a table [(d, g), ...]
static int density_law(PyObject* o, vd_cloud_def* def) {
  if (PyUnicode_Check(o)) {
    static const char* const laws[] = {"inverse-square", "linear", "constant", NULL};
    static const vd_density_law ids[] = {VD_DENSITY_INVERSE_SQUARE, VD_DENSITY_LINEAR, VD_DENSITY_CONSTANT};
    int k;
    if (!choice(o, "density_law", laws, &k)) return 0;
    def->density = ids[k];
    return 1;
  }
  PyObject* seq = PyList_Check(o) || PyTuple_Check(o) ? PySequence_Fast(o, "density_law") : NULL;
  if (!seq) {
    PyErr_Format(PyExc_TypeError, "density_law expects a name or a list of (distance m, density) pairs");
    return 0;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
  int ok = n >= 2 && n <= VD_CLOUD_TABLE_MAX;
  if (!ok) vdpy_arg_error("density_law table expects 2..%d pairs, got %zd", VD_CLOUD_TABLE_MAX, n);
  for (Py_ssize_t i = 0; ok && i < n; i++) {
    double dg[2];
    ok = vdpy_vec(PySequence_Fast_GET_ITEM(seq, i), "density_law pairs", 2, dg);
    if (ok) def->table_d[i] = dg[0], def->table_g[i] = dg[1];
  }
  Py_DECREF(seq);
  if (!ok) return 0;
  def->density = VD_DENSITY_TABLE;
  def->ntable = (int)n;
  return 1;
}

static PyObject* cloud_stats_dict(const vd_cloud_stats* s) {
  return Py_BuildValue("{s:i,s:i,s:d,s:L,s:{s:L,s:L,s:L,s:L,s:L},s:L,s:{s:d,s:d,s:d},s:i}",
                       "triangles", s->ntri, "solids", s->nsolid, "area", s->area, "drawn",
                       (long long)s->drawn, "rejected", "interior", (long long)s->rejected_interior,
                       "density", (long long)s->rejected_density, "backface",
                       (long long)s->rejected_backface, "occluded", (long long)s->rejected_occluded,
                       "noise", (long long)s->rejected_noise, "missed", (long long)s->missed,
                       "seconds", "tessellate", s->seconds_tessellate, "build", s->seconds_build,
                       "sample", s->seconds_sample, "threads", s->threads);
}

// a Cloud object owning c (taken)
static PyObject* cloud_new(vd_cloud* c, uint64_t seed, int sensor, int instance_labels,
                           PyObject* stats) {
  vdpy_cloud* o = (vdpy_cloud*)vdpy_cloud_class->tp_alloc(vdpy_cloud_class, 0);
  if (!o) {
    vd_cloud_free(c);
    return NULL;
  }
  o->cloud = *c;
  memset(c, 0, sizeof *c);
  o->seed = seed;
  o->sensor = sensor;
  o->instance_labels = instance_labels;
  o->stats = stats ? Py_NewRef(stats) : PyDict_New();
  if (!o->stats) Py_CLEAR(o);
  return (PyObject*)o;
}

PyObject* vdpy_cloud_make(const vd_plant_spec* spec, const vd_model* m, const vd_data* d,
                          uint64_t default_seed, PyObject* kw) {
  static const char* const names[] = {"points", "sensor", "scanners", "noise", "occlusion",
                                      "interior", "density_law", "pattern", "fov", "res",
                                      "labels", "slices", "seed", "threads", "max_points", NULL};
  if (!vdpy_kw_check(kw, "cloud", names)) return NULL;
  vd_cloud_def def = vd_cloud_def_default();
  def.max_points = 50000000;  // the command line's default
  def.seed = default_seed;
  vd_scanner proto = vd_scanner_default();
  PyObject* o;
  int64_t v;
  int k, instance_labels = 0, points_given = 0, scan_opts = 0;
  double x[2];
  if ((o = vdpy_kw(kw, "points"))) {
    if (!vdpy_i64(o, "points", 1, 2000000000, &v)) return NULL;
    def.points = v, points_given = 1;
  }
  if ((o = vdpy_kw(kw, "max_points"))) {
    if (!vdpy_i64(o, "max_points", 1, 2000000000, &v)) return NULL;
    def.max_points = v;
  }
  if ((o = vdpy_kw(kw, "sensor"))) {
    static const char* const sensors[] = {"uniform", "distance", "scan", NULL};
    if (!choice(o, "sensor", sensors, &k)) return NULL;
    def.sensor = (vd_sensor)k;
  }
  if ((o = vdpy_kw(kw, "density_law")) && !density_law(o, &def)) return NULL;
  if ((o = vdpy_kw(kw, "noise"))) {
    if (PySequence_Check(o)) {
      if (!vdpy_vec(o, "noise", 2, x)) return NULL;
      if (x[0] < 0 || x[1] < 0) return vdpy_arg_error("noise expects (sigma m, slope m/m) >= 0");
      def.noise_sigma = x[0], def.noise_slope = x[1];
    } else if (!vdpy_f64(o, "noise", 0, 1e3, &def.noise_sigma)) {
      return NULL;
    }
  }
  if ((o = vdpy_kw(kw, "occlusion")) && !vdpy_bool(o, "occlusion", &def.occlusion)) return NULL;
  if ((o = vdpy_kw(kw, "interior")) && !vdpy_bool(o, "interior", &def.interior)) return NULL;
  if ((o = vdpy_kw(kw, "pattern"))) {
    static const char* const patterns[] = {"angular", "pinhole", NULL};
    if (!choice(o, "pattern", patterns, &k)) return NULL;
    proto.pattern = (vd_scan_pattern)k, scan_opts = 1;
  }
  if ((o = vdpy_kw(kw, "fov"))) {
    if (!vdpy_vec(o, "fov", 2, x)) return NULL;
    if (!(x[0] > 0 && x[0] <= 360 && x[1] > 0 && x[1] <= 180))
      return vdpy_arg_error("fov expects (h, v) in degrees, 0 < h <= 360, 0 < v <= 180");
    proto.fov_h = x[0] * VD_PI / 180, proto.fov_v = x[1] * VD_PI / 180, scan_opts = 1;
  }
  if ((o = vdpy_kw(kw, "res"))) {
    if (!vdpy_vec(o, "res", 2, x)) return NULL;
    if (x[0] != floor(x[0]) || x[1] != floor(x[1]) || x[0] < 1 || x[1] < 1 || x[0] > 100000 || x[1] > 100000)
      return vdpy_arg_error("res expects (w, h), integers in 1..100000");
    proto.res_h = (int)x[0], proto.res_v = (int)x[1], scan_opts = 1;
  }
  if ((o = vdpy_kw(kw, "labels"))) {
    static const char* const kinds[] = {"semantic", "instance", NULL};
    if (!choice(o, "labels", kinds, &instance_labels)) return NULL;
  }
  if ((o = vdpy_kw(kw, "slices"))) {
    if (!vdpy_i64(o, "slices", 3, 1024, &v)) return NULL;
    def.mesh.slices = (int)v;
  }
  if ((o = vdpy_kw(kw, "seed"))) {
    if (!vdpy_i64(o, "seed", 0, INT64_MAX, &v)) return NULL;
    def.seed = (uint64_t)v;
  }
  if ((o = vdpy_kw(kw, "threads"))) {
    if (!vdpy_i64(o, "threads", 1, 1024, &v)) return NULL;
    def.threads = (int)v;
  }
  // the command line's consistency checks
  PyObject* sc_arg = vdpy_kw(kw, "scanners");
  if (vdpy_kw(kw, "density_law") && def.sensor != VD_SENSOR_DISTANCE)
    return vdpy_arg_error("density_law applies to sensor='distance'");
  if (scan_opts && def.sensor != VD_SENSOR_SCAN)
    return vdpy_arg_error("pattern, fov and res apply to sensor='scan'");
  if (points_given && def.sensor == VD_SENSOR_SCAN)
    return vdpy_arg_error("points does not apply to sensor='scan' (the ray grid sets the count)");
  vd_scanner* sc = NULL;
  int nsc = 0;
  if (sc_arg && !scanners(sc_arg, spec, &proto, &sc, &nsc)) return NULL;
  const char* fault = NULL;
  if (!nsc && def.sensor != VD_SENSOR_UNIFORM) fault = "sensor='distance' and 'scan' need scanners";
  else if (!nsc && def.occlusion) fault = "occlusion needs scanners";
  else if (!nsc && def.noise_slope > 0) fault = "noise (sigma, slope) with slope > 0 needs scanners";
  if (fault) {
    vd_free(sc, (size_t)nsc * sizeof *sc);
    return vdpy_arg_error("%s", fault);
  }
  def.nscanner = nsc;
  def.scanner = sc;
  // sample (and relabel) without the GIL
  vd_cloud cloud;
  memset(&cloud, 0, sizeof cloud);
  vd_cloud_stats stats;
  memset(&stats, 0, sizeof stats);
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_cloud_sample(m, d, &def, &cloud, &stats, &err);
  if (!st && instance_labels) st = vd_cloud_relabel(&cloud, &err);
  Py_END_ALLOW_THREADS
  vd_free(sc, (size_t)nsc * sizeof *sc);
  if (st) {
    vd_cloud_free(&cloud);
    return vdpy_raise(st, &err);
  }
  PyObject* sd = cloud_stats_dict(&stats);
  if (!sd) {
    vd_cloud_free(&cloud);
    return NULL;
  }
  PyObject* r = cloud_new(&cloud, def.seed, def.sensor, instance_labels, sd);
  Py_DECREF(sd);
  return r;
}

PyObject* vdpy_read_cloud(PyObject* self, PyObject* args, PyObject* kw) {
  static char* names[] = {"path", NULL};
  PyObject* path;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O:read_cloud", names, &path)) return NULL;
  char p[PATH_CAP];
  if (!vdpy_path(path, "path", p, sizeof p)) return NULL;
  vd_cloud c;
  memset(&c, 0, sizeof c);
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_cloud_read(p, &c, &err);
  Py_END_ALLOW_THREADS
  if (st) return vdpy_raise(st, &err);
  return cloud_new(&c, 0, -1, 0, NULL);
}

// ---------------------------------------------------------------------------------------------
// Cloud

static void cloud_dealloc(vdpy_cloud* c) {
  vd_cloud_free(&c->cloud);
  Py_XDECREF(c->xyz);
  Py_XDECREF(c->stats);
  Py_TYPE(c)->tp_free((PyObject*)c);
}

#define CLOUD_ARRAY(getter, field, cols, type)                                                     \
  static PyObject* getter(vdpy_cloud* c, void* unused) {                                           \
    npy_intp dims[2] = {(npy_intp)c->cloud.n, cols};                                               \
    return vdpy_view((PyObject*)c, c->cloud.field, (cols) > 1 ? 2 : 1, dims, type, 0);             \
  }
CLOUD_ARRAY(cloud_pos, pos, 3, NPY_DOUBLE)
CLOUD_ARRAY(cloud_normals, normal, 3, NPY_DOUBLE)
CLOUD_ARRAY(cloud_label, label, 1, NPY_INT32)
CLOUD_ARRAY(cloud_instance, instance, 1, NPY_INT32)
CLOUD_ARRAY(cloud_view, view, 1, NPY_INT32)
CLOUD_ARRAY(cloud_range, range, 1, NPY_DOUBLE)
#undef CLOUD_ARRAY

// float32 positions: converted once (the library keeps doubles), read-only like the views
static PyObject* cloud_xyz(vdpy_cloud* c, void* unused) {
  if (!c->xyz) {
    npy_intp dims[2] = {(npy_intp)c->cloud.n, 3};
    PyObject* a = PyArray_EMPTY(2, dims, NPY_FLOAT32, 0);
    if (!a) return NULL;
    float* dst = PyArray_DATA((PyArrayObject*)a);
    const double* src = c->cloud.pos;
    size_t n = 3 * (size_t)c->cloud.n;
    Py_BEGIN_ALLOW_THREADS
    for (size_t i = 0; i < n; i++) dst[i] = (float)src[i];
    Py_END_ALLOW_THREADS
    PyArray_CLEARFLAGS((PyArrayObject*)a, NPY_ARRAY_WRITEABLE);
    // another thread may have made it while this one converted without the GIL: keep the first
    if (c->xyz) Py_DECREF(a);
    else c->xyz = a;
  }
  return Py_NewRef(c->xyz);
}

static PyObject* cloud_labels(vdpy_cloud* c, void* unused) {
  return vdpy_label_dict(c->cloud.labels, c->cloud.nlabel);
}
static PyObject* cloud_label_table(vdpy_cloud* c, void* unused) {
  return vdpy_label_list(c->cloud.labels, c->cloud.nlabel);
}
static PyObject* cloud_stats(vdpy_cloud* c, void* unused) { return PyDict_Copy(c->stats); }
static PyObject* cloud_seed(vdpy_cloud* c, void* unused) {
  return PyLong_FromUnsignedLongLong(c->seed);
}
static PyObject* cloud_nview(vdpy_cloud* c, void* unused) { return PyLong_FromLong(c->cloud.nview); }

static PyGetSetDef cloud_getset[] = {
    {"xyz", (getter)cloud_xyz, NULL, "positions (m), float32 (n x 3): a copy of pos made once", NULL},
    {"pos", (getter)cloud_pos, NULL, "positions (m), float64 (n x 3): the library's array, no copy", NULL},
    {"normals", (getter)cloud_normals, NULL, "unit surface normals, float64 (n x 3)", NULL},
    {"label", (getter)cloud_label, NULL, "semantic label id (or instance id with labels='instance'), int32 (n)", NULL},
    {"instance", (getter)cloud_instance, NULL, "organ instance id, int32 (n)", NULL},
    {"view", (getter)cloud_view, NULL, "index of the scanner that made the point (0 without scanners), int32 (n)", NULL},
    {"range", (getter)cloud_range, NULL, "distance from that scanner (m; 0 without scanners), float64 (n)", NULL},
    {"labels", (getter)cloud_labels, NULL, "label table as a dict {id: name}", NULL},
    {"label_table", (getter)cloud_label_table, NULL, "label table: dicts of id, name, organ, rgb", NULL},
    {"stats", (getter)cloud_stats, NULL, "the sampling's counters and stage timings (s)", NULL},
    {"seed", (getter)cloud_seed, NULL, "sampling seed", NULL},
    {"nview", (getter)cloud_nview, NULL, "scanners behind the cloud (0: view and range carry nothing)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static Py_ssize_t cloud_len(vdpy_cloud* c) { return (Py_ssize_t)c->cloud.n; }

static PySequenceMethods cloud_seq = {.sq_length = (lenfunc)cloud_len};

// write the cloud; the header comment is the command line's unless one is given
static PyObject* cloud_save(vdpy_cloud* c, PyObject* args, PyObject* kw) {
  static char* names[] = {"path", "ascii", "ply_prefix", "comment", "threads", NULL};
  PyObject *path, *prefix = Py_None, *comment = Py_None, *threads = Py_None;
  int ascii = 0;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$pOOO:save", names, &path, &ascii, &prefix, &comment, &threads))
    return NULL;
  char out[PATH_CAP], pre[64], com[256];
  if (!vdpy_path(path, "path", out, sizeof out)) return NULL;
  if (vd_cloud_format_of(out) == VD_CLOUD_AUTO)
    return vdpy_arg_error("save: '%s': unknown format (use .ply, .pcd, .xyz, .csv or .las)", out);
  vd_cloud_write_def wd = vd_cloud_write_def_default();
  wd.ascii = ascii;
  if (prefix != Py_None) {
    if (!vdpy_str(prefix, "ply_prefix", pre, sizeof pre)) return NULL;
    wd.ply_prefix = pre;
  }
  if (comment != Py_None) {
    if (!vdpy_str(comment, "comment", com, sizeof com)) return NULL;
    if (strchr(com, '\n') || strchr(com, '\r')) return vdpy_arg_error("comment is one line");
    wd.comment = com;
  } else if (c->sensor >= 0) {
    snprintf(com, sizeof com, "seed %llu, sensor %s, labels %s", (unsigned long long)c->seed,
             sensor_name(c->sensor), c->instance_labels ? "instance" : "semantic");
    wd.comment = com;
  }
  if (threads != Py_None) {
    int64_t v;
    if (!vdpy_i64(threads, "threads", 1, 1024, &v)) return NULL;
    wd.threads = (int)v;
  }
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_cloud_write(&c->cloud, out, &wd, &err);
  Py_END_ALLOW_THREADS
  if (st) return vdpy_raise(st, &err);
  Py_RETURN_NONE;
}

// pickling: the cloud's arrays and tables as bytes (native byte order), exact
#define CLOUD_MAGIC "VDCLOUD1"

typedef struct cloud_head {
  char magic[8];
  int64_t n;
  int32_t nview, nlabel, sensor, instance_labels, has_pose, label_size;
  uint64_t seed;
} cloud_head;

// one walk over the parts, into buf (save) or out of it (load); returns bytes walked
static size_t cloud_walk(vd_cloud* c, const cloud_head* h, char* buf, int save) {
  size_t n = (size_t)h->n, at = sizeof *h;
  struct {
    void* p;
    size_t n;
  } part[] = {
      {c->pos, 3 * n * sizeof(double)}, {c->normal, 3 * n * sizeof(double)}, {c->label, n * sizeof(int)},
      {c->instance, n * sizeof(int)},   {c->view, n * sizeof(int)},          {c->range, n * sizeof(double)},
      {c->view_pose, h->has_pose ? (size_t)h->nview * 6 * sizeof(double) : 0},
      {c->labels, (size_t)h->nlabel * sizeof(vd_label)},
  };
  for (size_t k = 0; k < sizeof part / sizeof part[0]; k++) {
    if (buf && part[k].n) {
      if (save) memcpy(buf + at, part[k].p, part[k].n);
      else memcpy(part[k].p, buf + at, part[k].n);
    }
    at += part[k].n;
  }
  return at;
}

static PyObject* cloud_reduce(vdpy_cloud* c, PyObject* unused) {
  cloud_head h;
  memset(&h, 0, sizeof h);
  memcpy(h.magic, CLOUD_MAGIC, 8);
  h.n = c->cloud.n, h.nview = c->cloud.nview, h.nlabel = c->cloud.nlabel, h.sensor = c->sensor;
  h.instance_labels = c->instance_labels, h.has_pose = c->cloud.view_pose != NULL;
  h.label_size = (int32_t)sizeof(vd_label), h.seed = c->seed;
  size_t n = cloud_walk(&c->cloud, &h, NULL, 1);
  PyObject* b = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)n);
  if (!b) return NULL;
  memcpy(PyBytes_AS_STRING(b), &h, sizeof h);
  cloud_walk(&c->cloud, &h, PyBytes_AS_STRING(b), 1);
  PyObject* f = PyObject_GetAttrString(PyImport_AddModule("verdant._verdant"), "_cloud_unpickle");
  if (!f) {
    Py_DECREF(b);
    return NULL;
  }
  return Py_BuildValue("(N(NO))", f, b, c->stats);
}

PyObject* vdpy_cloud_unpickle(PyObject* self, PyObject* args) {
  Py_buffer v;
  PyObject* stats;
  if (!PyArg_ParseTuple(args, "y*O!:_cloud_unpickle", &v, &PyDict_Type, &stats)) return NULL;
  cloud_head h;
  vd_cloud c;
  memset(&c, 0, sizeof c);
  vd_error err = {0};
  const char* why = NULL;
  if ((size_t)v.len < sizeof h) why = "too short";
  if (!why) {
    memcpy(&h, v.buf, sizeof h);
    if (memcmp(h.magic, CLOUD_MAGIC, 8) || h.label_size != (int32_t)sizeof(vd_label)) why = "not a Cloud of this build";
    else if (h.n < 0 || h.nview < 0 || h.nlabel < 0 || cloud_walk(&c, &h, NULL, 0) != (size_t)v.len) why = "corrupt";
  }
  vd_status st = VD_OK;
  if (!why) st = vd_cloud_alloc(&c, h.n, NULL, 0, &err);
  if (!why && !st) {
    c.nlabel = h.nlabel, c.nview = h.nview;
    c.labels = h.nlabel ? vd_malloc((size_t)h.nlabel * sizeof(vd_label)) : NULL;
    c.view_pose = h.has_pose && h.nview ? vd_malloc((size_t)h.nview * 6 * sizeof(double)) : NULL;
    if ((h.nlabel && !c.labels) || (h.has_pose && h.nview && !c.view_pose)) st = VD_ERR_NOMEM;
    else cloud_walk(&c, &h, v.buf, 0);
  }
  PyBuffer_Release(&v);
  if (why) return vdpy_arg_error("_cloud_unpickle: the data is %s", why);
  if (st) {
    vd_cloud_free(&c);
    return vdpy_raise(st, &err);
  }
  return cloud_new(&c, h.seed, h.sensor, h.instance_labels, stats);
}

static PyMethodDef cloud_methods[] = {
    {"save", (PyCFunction)(void (*)(void))cloud_save, METH_VARARGS | METH_KEYWORDS,
     "save($self, /, path, *, ascii=False, ply_prefix=None, comment=None, threads=None)\n--\n\n"
     "save(path, *, ascii=False, ply_prefix=None, comment=None, threads=None): write the cloud;\n"
     "the extension picks the format (.ply .pcd .xyz .csv .las). The same bytes as\n"
     "`verdant cloud` with the same options (the header comment records seed, sensor, labels)."},
    {"__reduce__", (PyCFunction)cloud_reduce, METH_NOARGS, NULL},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_cloud_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.Cloud",
    .tp_basicsize = sizeof(vdpy_cloud),
    .tp_dealloc = (destructor)cloud_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "A labelled point cloud (Plant.cloud, verdant.read_cloud).",
    .tp_as_sequence = &cloud_seq,
    .tp_methods = cloud_methods,
    .tp_getset = cloud_getset,
};
