// SPDX-License-Identifier: MIT
// Simulation: the Sim type over a rod model and its state (vd_sim_build, vd_sim_step): the
// command line's build and run options, stepping and settling without the GIL, colliders, ties
// and forces between steps, state arrays as views, events, stress, the deformed plant.
#include "py_internal.h"

#include <math.h>
#include <stddef.h>
#include <structmember.h>

// ---------------------------------------------------------------------------------------------
// options

// a material field of every class (a number) or of some ({class: number}); ncomp 2 for strains;
// positive: every value > 0 (inf allowed where inf_ok: a threshold that never fires)
static int material_opt(PyObject* o, const char* name, vd_sim_def* def, size_t field, int ncomp,
                        int positive, int inf_ok) {
  int c0 = 0, c1 = VD_SIM_CLASS_COUNT;
  PyObject *key = NULL, *val = o;
  Py_ssize_t pos = 0;
  int dict = PyDict_Check(o);
  for (;;) {
    if (dict) {
      if (!PyDict_Next(o, &pos, &key, &val)) return 1;
      char cls[32];
      if (!vdpy_str(key, name, cls, sizeof cls)) return 0;
      vd_sim_class c = vd_sim_class_parse(cls);
      if (c == VD_SIM_CLASS_COUNT) {
        vdpy_arg_error("%s: unknown class '%s' (green, wood, pedicel, leaf, fruit, flower, root)", name, cls);
        return 0;
      }
      c0 = (int)c, c1 = (int)c + 1;
    }
    double v[2];
    PyObject* seq = ncomp == 2 && PySequence_Check(val) ? PySequence_Fast(val, name) : NULL;
    if (ncomp == 2 && (!seq || PySequence_Fast_GET_SIZE(seq) != 2)) {
      Py_XDECREF(seq);
      PyErr_Clear();
      PyErr_Format(PyExc_TypeError, "%s expects (cs, cb) or {class: (cs, cb)}", name);
      return 0;
    }
    for (int k = 0; k < ncomp; k++) {
      PyObject* x = ncomp == 2 ? PySequence_Fast_GET_ITEM(seq, k) : val;
      int ok = inf_ok ? vdpy_f64_inf(x, name, -HUGE_VAL, HUGE_VAL, &v[k]) : vdpy_f64(x, name, -1e300, 1e300, &v[k]);
      if (ok && positive && !(v[k] > 0)) ok = (vdpy_arg_error("%s expects numbers > 0", name), 0);
      if (!ok) {
        Py_XDECREF(seq);
        return 0;
      }
    }
    Py_XDECREF(seq);
    for (int c = c0; c < c1; c++) {
      double* dst = (double*)((char*)&def->material[c] + field);
      for (int k = 0; k < ncomp; k++) dst[k] = v[k];
    }
    if (!dict) return 1;
  }
}

static const char* const sim_kw[] = {
    "segment_length", "clamp_length", "clamp_roots", "leaf_graphs", "sag_free", "stake",
    "max_segments", "young", "density", "poisson", "break_force", "break_moment", "break_strain",
    "gravity", "dt", "iterations", "solver", "wind", "gust", "wind_series", "drag", "stokes",
    "damping", "mass_damping", "fracture", "contacts", "friction", "self_collision", "ground", NULL};

// the run options of kw into opt (those Sim() and Sim.set() share); 0 with an exception
static int run_opts(PyObject* kw, vd_sim_opt* opt, double** wind, int* nwind) {
  PyObject* o;
  int64_t v;
  double x[3];
  if ((o = vdpy_kw(kw, "dt")) && !vdpy_f64(o, "dt", 1e-9, 1.0, &opt->dt)) return 0;
  if ((o = vdpy_kw(kw, "iterations"))) {
    if (!vdpy_i64(o, "iterations", 1, 1000, &v)) return 0;
    opt->iterations = (int)v;
  }
  if ((o = vdpy_kw(kw, "solver"))) {
    char s[16];
    if (!vdpy_str(o, "solver", s, sizeof s)) return 0;
    if (!strcmp(s, "direct")) opt->solver = VD_SIM_DIRECT;
    else if (!strcmp(s, "gs")) opt->solver = VD_SIM_GS;
    else return (vdpy_arg_error("solver expects 'direct' or 'gs', got '%s'", s), 0);
  }
  if ((o = vdpy_kw(kw, "gravity"))) {
    if (!vdpy_vec(o, "gravity", 3, x)) return 0;
    for (int k = 0; k < 3; k++)
      if (fabs(x[k]) > 1e4) return (vdpy_arg_error("gravity components within +-1e4 m/s^2"), 0);
    opt->gravity = vd_v3(x[0], x[1], x[2]);
  }
  if ((o = vdpy_kw(kw, "wind"))) {
    if (!vdpy_vec(o, "wind", 3, x)) return 0;
    for (int k = 0; k < 3; k++)
      if (fabs(x[k]) > VD_SIM_MAX_WIND) return (vdpy_arg_error("wind components within +-%g m/s", VD_SIM_MAX_WIND), 0);
    opt->wind = vd_v3(x[0], x[1], x[2]);
  }
  if ((o = vdpy_kw(kw, "gust"))) {
    if (!vdpy_vec(o, "gust", 2, x)) return 0;
    if (!(x[1] > 0)) return (vdpy_arg_error("gust expects (amplitude, period s > 0)"), 0);
    opt->gust_amplitude = x[0], opt->gust_period = x[1];
  }
  if ((o = vdpy_kw(kw, "wind_series"))) {
    // rows (t s, vx, vy, vz m/s), times not decreasing: checked here, then owned by the Sim
    PyArrayObject* a = (PyArrayObject*)PyArray_FROMANY(o, NPY_DOUBLE, 2, 2, NPY_ARRAY_CARRAY_RO);
    if (!a) return 0;
    npy_intp n = PyArray_DIM(a, 0);
    const double* r = PyArray_DATA(a);
    int ok = PyArray_DIM(a, 1) == 4 && n >= 1 && n <= VD_SIM_MAX_WIND_ROWS;
    for (npy_intp i = 0; ok && i < n; i++)
      for (int k = 0; ok && k < 4; k++)
        ok = isfinite(r[4 * i + k]) && (k == 0 ? (i == 0 || r[4 * i] >= r[4 * (i - 1)]) : fabs(r[4 * i + k]) <= VD_SIM_MAX_WIND);
    double* w = ok ? vd_malloc((size_t)n * 4 * sizeof(double)) : NULL;
    if (w) memcpy(w, r, (size_t)n * 4 * sizeof(double));
    Py_DECREF(a);
    if (!ok) return (vdpy_arg_error("wind_series expects rows (t, vx, vy, vz), finite, times not decreasing, "
                                    "|v| <= %g m/s", VD_SIM_MAX_WIND), 0);
    if (!w) return (PyErr_NoMemory(), 0);
    vd_free(*wind, (size_t)*nwind * 4 * sizeof(double));
    *wind = w, *nwind = (int)n;
    opt->wind_series = w, opt->nwind = (int)n;
  }
  struct {
    const char* name;
    int* dst;
  } flags[] = {{"drag", &opt->drag}, {"fracture", &opt->fracture}, {"contacts", &opt->contacts},
               {"self_collision", &opt->self_collision}};
  for (int k = 0; k < 4; k++)
    if ((o = vdpy_kw(kw, flags[k].name)) && !vdpy_bool(o, flags[k].name, flags[k].dst)) return 0;
  struct {
    const char* name;
    double* dst;
  } nums[] = {{"stokes", &opt->stokes_viscosity}, {"damping", &opt->damping},
              {"mass_damping", &opt->mass_damping}, {"friction", &opt->friction}};
  for (int k = 0; k < 4; k++)
    if ((o = vdpy_kw(kw, nums[k].name)) && !vdpy_f64(o, nums[k].name, 0, 1e12, nums[k].dst)) return 0;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// Sim

// steps between two checks for signals (Ctrl-C) in step(n): a few ms of the tomato's steps
#define SIGNAL_CHUNK 16

static int busy_check(vdpy_sim* s) {
  if (s->busy) return (vdpy_busy("this Sim"), 0);
  return 1;
}

static void sim_dealloc(vdpy_sim* s) {
  vd_sim_data_destroy(s->data);
  vd_sim_model_destroy(s->model);
  vd_data_destroy(s->pstate);
  for (int k = 0; k < VD_SIM_MAX_COLLIDERS; k++) vd_sdf_destroy(s->sdf[k]);
  vd_free(s->wind, (size_t)s->nwind * 4 * sizeof(double));
  Py_XDECREF(s->plant);
  Py_TYPE(s)->tp_free((PyObject*)s);
}

static PyObject* sim_new(PyTypeObject* type, PyObject* args, PyObject* kw) {
  PyObject* plant;
  if (!PyArg_ParseTuple(args, "O!:Sim", &vdpy_plant_type, &plant) || !vdpy_kw_check(kw, "Sim", sim_kw))
    return NULL;
  vdpy_sim* s = (vdpy_sim*)type->tp_alloc(type, 0);
  if (!s) return NULL;
  s->plant = Py_NewRef(plant);
  const vd_model* pm = ((vdpy_plant*)plant)->model;
  vd_sim_def def = vd_sim_def_default();
  vd_sim_opt opt = vd_sim_opt_default();
  PyObject* o;
  int64_t v;
  double ground = 0;
  int has_ground = 1;
  // build options
  if ((o = vdpy_kw(kw, "segment_length")) && !vdpy_f64(o, "segment_length", 1e-5, 10, &def.segment_length)) goto fail;
  if ((o = vdpy_kw(kw, "clamp_length")) && !vdpy_f64(o, "clamp_length", 0, 10, &def.clamp_length)) goto fail;
  if ((o = vdpy_kw(kw, "clamp_roots")) && !vdpy_bool(o, "clamp_roots", &def.clamp_roots)) goto fail;
  if ((o = vdpy_kw(kw, "leaf_graphs")) && !vdpy_bool(o, "leaf_graphs", &def.leaf_graphs)) goto fail;
  if ((o = vdpy_kw(kw, "sag_free")) && !vdpy_bool(o, "sag_free", &def.sag_free)) goto fail;
  if ((o = vdpy_kw(kw, "stake")) && !vdpy_f64(o, "stake", 0, 100, &def.stake_spacing)) goto fail;
  if ((o = vdpy_kw(kw, "max_segments"))) {
    if (!vdpy_i64(o, "max_segments", 1, 100000000, &v)) goto fail;
    def.max_segments = (int)v;
  }
  struct {
    const char* name;
    size_t field;
    int ncomp, positive, inf_ok;
  } mats[] = {{"young", offsetof(vd_sim_material, young), 1, 1, 0},
              {"density", offsetof(vd_sim_material, density), 1, 1, 0},
              {"poisson", offsetof(vd_sim_material, poisson), 1, 0, 0},
              {"break_force", offsetof(vd_sim_material, break_force), 1, 1, 1},
              {"break_moment", offsetof(vd_sim_material, break_moment), 1, 1, 1},
              {"break_strain", offsetof(vd_sim_material, break_cs), 2, 1, 1}};
  for (int k = 0; k < 6; k++)
    if ((o = vdpy_kw(kw, mats[k].name)) &&
        !material_opt(o, mats[k].name, &def, mats[k].field, mats[k].ncomp, mats[k].positive, mats[k].inf_ok))
      goto fail;
  if (!run_opts(kw, &opt, &s->wind, &s->nwind)) goto fail;
  def.gravity = opt.gravity;
  if (kw && PyDict_GetItemString(kw, "ground")) {
    o = PyDict_GetItemString(kw, "ground");
    if (o == Py_None) has_ground = 0;
    else if (!vdpy_f64(o, "ground", -1e6, 1e6, &ground)) goto fail;
  }
  // build the rod model and its state
  {
    vd_error err = {0};
    vd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = vd_sim_build(pm, &def, &s->model, &err);
    Py_END_ALLOW_THREADS
    if (st) {
      if (!err.file[0] && err.status) {
        PyObject* src = ((vdpy_plant*)plant)->source;
        snprintf(err.file, sizeof err.file, "%.255s", PyUnicode_AsUTF8(src) ? PyUnicode_AsUTF8(src) : "");
        PyErr_Clear();
      }
      vdpy_raise(st, &err);
      goto fail;
    }
  }
  s->model->opt = opt;
  s->data = vd_sim_data_create(s->model);
  s->pstate = vd_data_create(pm);
  if (!s->data || !s->pstate) {
    PyErr_NoMemory();
    goto fail;
  }
  if (has_ground) {
    vd_sim_collider c = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, ground), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    vd_sim_add_collider(s->data, &c);
  }
  return (PyObject*)s;
fail:
  Py_DECREF(s);
  return NULL;
}

// steps and settling: without the GIL, one thread at a time
static PyObject* step_failed(vdpy_sim* s, vd_status st) {
  vd_error err = {0};
  vd_error_set(&err, st, "", 0, 0,
               "the simulation became unstable at t = %.4f s: even steps of dt / %d made a non-finite "
               "state, a singular system or a stretch beyond %g%% (%lld numerical warnings); try a "
               "smaller dt or more iterations",
               s->data->time, 1 << VD_SIM_MAX_SUBSTEP, 100 * VD_SIM_BLOWUP_STRAIN,
               (long long)s->data->nwarning);
  return vdpy_raise(st, &err);
}

static PyObject* sim_step(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"n", NULL};
  PyObject* no = NULL;
  int64_t n = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|O:step", names, &no)) return NULL;
  if (no && !vdpy_i64(no, "n", 0, INT64_MAX, &n)) return NULL;
  if (!busy_check(s)) return NULL;
  s->busy = 1;
  vd_status st = VD_OK;
  // in chunks, the signals checked between them (Ctrl-C stops a long call within a chunk; the
  // steps taken stay taken)
  for (int64_t k = 0; k < n && !st;) {
    int64_t end = k + SIGNAL_CHUNK < n ? k + SIGNAL_CHUNK : n;
    Py_BEGIN_ALLOW_THREADS
    for (; k < end && !st; k++) st = vd_sim_step(s->model, s->data);
    Py_END_ALLOW_THREADS
    if (!st && k < n && PyErr_CheckSignals() < 0) {
      s->busy = 0;
      return NULL;
    }
  }
  s->busy = 0;
  if (st) return step_failed(s, st);
  Py_RETURN_NONE;
}

// ---------------------------------------------------------------------------------------------
// the state as bytes: a header of sizes, then every array of vd_sim_data that a step reads, in a
// fixed order, native byte order (the same machine kind and verdant version read it back)

#define STATE_MAGIC "VDSIMST1"

typedef struct state_head {
  char magic[8];
  int32_t nnode, nseg, ncollider, ntie, nevent, ncontact;
  int32_t sizes[4];  // sizeof of vd_vec3, vd_quat, vd_sim_collider, vd_sim_event: a layout check
  double time, max_penetration;
  int64_t nstep, nwarning, warning[VD_SIM_WARN_COUNT];
} state_head;

// one walk over the arrays, copying into buf (save) or out of it (load); returns bytes walked
static size_t state_walk(vd_sim_data* d, const state_head* h, char* buf, int save) {
  size_t at = sizeof *h;
  const size_t nn = (size_t)h->nnode, ns = (size_t)h->nseg;
  struct {
    void* p;
    size_t n;
  } part[] = {
      {d->node_pos, nn * sizeof(vd_vec3)},     {d->node_vel, nn * sizeof(vd_vec3)},
      {d->node_force, nn * sizeof(vd_vec3)},   {d->node_mass, nn * sizeof(double)},
      {d->seg_quat, ns * sizeof(vd_quat)},     {d->seg_omega, ns * sizeof(vd_vec3)},
      {d->seg_torque, ns * sizeof(vd_vec3)},   {d->seg_lambda, ns * 6 * sizeof(double)},
      {d->seg_broken, ns * sizeof(int)},       {d->seg_start, ns * sizeof(int)},
      {d->collider_force, sizeof d->collider_force}, {d->collider_torque, sizeof d->collider_torque},
      {d->collider_pass, sizeof d->collider_pass},   {d->event, (size_t)h->nevent * sizeof(vd_sim_event)},
  };
  for (size_t k = 0; k < sizeof part / sizeof part[0]; k++) {
    if (buf && part[k].n) {
      if (save) memcpy(buf + at, part[k].p, part[k].n);
      else memcpy(part[k].p, buf + at, part[k].n);
    }
    at += part[k].n;
  }
  // colliders (their distance grids stay the Sim's own) and ties
  for (int k = 0; k < h->ncollider; k++, at += sizeof(vd_sim_collider))
    if (buf && save) {
      vd_sim_collider c = d->collider[k];
      c.sdf = NULL;
      memcpy(buf + at, &c, sizeof c);
    } else if (buf) {
      const vd_sdf* keep = d->collider[k].sdf;
      memcpy(&d->collider[k], buf + at, sizeof(vd_sim_collider));
      d->collider[k].sdf = keep;
    }
  for (int k = 0; k < h->ntie; k++, at += sizeof(vd_sim_tie))
    if (buf) {
      if (save) memcpy(buf + at, &d->tie[k], sizeof(vd_sim_tie));
      else memcpy(&d->tie[k], buf + at, sizeof(vd_sim_tie));
    }
  return at;
}

static void state_sizes(int32_t* sz) {
  sz[0] = (int32_t)sizeof(vd_vec3), sz[1] = (int32_t)sizeof(vd_quat);
  sz[2] = (int32_t)sizeof(vd_sim_collider), sz[3] = (int32_t)sizeof(vd_sim_event);
}

// get_state() -> bytes
static PyObject* sim_get_state(vdpy_sim* s, PyObject* unused) {
  if (!busy_check(s)) return NULL;
  vd_sim_data* d = s->data;
  state_head h;
  memset(&h, 0, sizeof h);
  memcpy(h.magic, STATE_MAGIC, 8);
  h.nnode = d->nnode_all, h.nseg = d->nseg, h.ncollider = d->ncollider, h.ntie = d->ntie;
  h.nevent = d->nevent, h.ncontact = d->ncontact;
  state_sizes(h.sizes);
  h.time = d->time, h.max_penetration = d->max_penetration;
  h.nstep = d->nstep, h.nwarning = d->nwarning;
  memcpy(h.warning, d->warning, sizeof h.warning);
  size_t n = state_walk(d, &h, NULL, 1);
  PyObject* b = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)n);
  if (!b) return NULL;
  char* buf = PyBytes_AS_STRING(b);
  memcpy(buf, &h, sizeof h);
  state_walk(d, &h, buf, 1);
  return b;
}

// set_state(bytes): the state get_state returned, of a Sim of the same plant and options
static PyObject* sim_set_state(vdpy_sim* s, PyObject* arg) {
  Py_buffer view;
  if (PyObject_GetBuffer(arg, &view, PyBUF_SIMPLE) < 0) return NULL;
  vd_sim_data* d = s->data;
  state_head h;
  int32_t sz[4];
  state_sizes(sz);
  const char* why = NULL;
  if ((size_t)view.len < sizeof h) why = "too short";
  if (!why) {
    memcpy(&h, view.buf, sizeof h);
    if (memcmp(h.magic, STATE_MAGIC, 8) || memcmp(h.sizes, sz, sizeof sz)) why = "not a Sim state of this build";
    else if (h.nnode != d->nnode_all || h.nseg != d->nseg) why = "of another rod model (node or segment counts differ)";
    else if (h.ncollider < 0 || h.ncollider > VD_SIM_MAX_COLLIDERS || h.ntie < 0 || h.nevent < 0 ||
             h.nevent > d->nseg)
      why = "corrupt (counts out of range)";
    else if (state_walk(d, &h, NULL, 0) != (size_t)view.len) why = "of the wrong length";
  }
  // mesh colliders keep this Sim's distance grids: the same meshes must be here
  const char* buf = view.buf;
  for (int k = 0; !why && k < h.ncollider; k++) {
    vd_sim_collider c;
    size_t at = state_walk(d, &(state_head){.nnode = h.nnode, .nseg = h.nseg, .nevent = h.nevent}, NULL, 0);
    memcpy(&c, buf + at + (size_t)k * sizeof c, sizeof c);
    if (c.shape == VD_SIM_MESH && (k >= d->ncollider || !d->collider[k].sdf)) why = "with a mesh collider this Sim lacks";
  }
  if (!why && busy_check(s)) {
    while (d->ntie < h.ntie)  // room for the ties (their values come next)
      if (vd_sim_add_tie(d, 0, vd_v3(0, 0, 0), 1) < 0) {
        PyBuffer_Release(&view);
        return PyErr_NoMemory();
      }
    d->ntie = h.ntie, d->ncollider = h.ncollider, d->nevent = h.nevent, d->ncontact = h.ncontact;
    d->time = h.time, d->max_penetration = h.max_penetration;
    d->nstep = h.nstep, d->nwarning = h.nwarning;
    memcpy(d->warning, h.warning, sizeof h.warning);
    state_walk(d, &h, (char*)view.buf, 0);
  }
  PyBuffer_Release(&view);
  if (why) return vdpy_arg_error("set_state: the state is %s", why);
  if (PyErr_Occurred()) return NULL;
  Py_RETURN_NONE;
}

static PyObject* sim_settle(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"statics", "ke_tol", "disp_tol", "max_time", "max_steps", "extra_damping", NULL};
  vd_sim_settle_def sd = vd_sim_settle_def_default();
  PyObject *ke = NULL, *disp = NULL, *tmax = NULL, *smax = NULL, *damp = NULL;
  int statics = 0;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|$pOOOOO:settle", names, &statics, &ke, &disp, &tmax, &smax, &damp))
    return NULL;
  int64_t v;
  sd.statics = statics;
  if (ke && !vdpy_f64(ke, "ke_tol", 0, 1e12, &sd.ke_tol)) return NULL;
  if (disp && !vdpy_f64(disp, "disp_tol", 0, 1e6, &sd.disp_tol)) return NULL;
  if (tmax && !vdpy_f64(tmax, "max_time", 0, 1e9, &sd.max_time)) return NULL;
  if (damp && !vdpy_f64(damp, "extra_damping", 0, 1e9, &sd.extra_damping)) return NULL;
  if (smax) {
    if (!vdpy_i64(smax, "max_steps", 0, 1000000000, &v)) return NULL;
    sd.max_steps = (int)v;
  }
  if (!busy_check(s)) return NULL;
  s->busy = 1;
  int converged = 0, steps = 0;
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_sim_settle(s->model, s->data, &sd, &converged, &steps);
  Py_END_ALLOW_THREADS
  s->busy = 0;
  if (st) return step_failed(s, st);
  return Py_BuildValue("(Oi)", converged ? Py_True : Py_False, steps);
}

static PyObject* sim_reset(vdpy_sim* s, PyObject* unused) {
  if (!busy_check(s)) return NULL;
  vd_sim_data_reset(s->model, s->data);
  Py_RETURN_NONE;
}

// set(**run options): change dt, wind, gravity, damping, ... between steps
static PyObject* sim_set(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static const char* const names[] = {"dt", "iterations", "solver", "gravity", "wind", "gust",
                                      "wind_series", "drag", "stokes", "damping", "mass_damping",
                                      "fracture", "contacts", "friction", "self_collision", NULL};
  if (PyTuple_GET_SIZE(args)) return PyErr_Format(PyExc_TypeError, "set() takes keyword arguments only");
  if (!vdpy_kw_check(kw, "set", names) || !busy_check(s)) return NULL;
  vd_sim_opt opt = s->model->opt;
  if (!run_opts(kw, &opt, &s->wind, &s->nwind)) return NULL;
  s->model->opt = opt;
  Py_RETURN_NONE;
}

static PyObject* sim_options(vdpy_sim* s, void* c) {
  const vd_sim_opt* o = &s->model->opt;
  return Py_BuildValue("{s:d,s:i,s:s,s:(ddd),s:(ddd),s:(dd),s:i,s:O,s:d,s:d,s:d,s:O,s:O,s:d,s:O}", "dt", o->dt,
                       "iterations", o->iterations, "solver", o->solver == VD_SIM_GS ? "gs" : "direct",
                       "gravity", o->gravity.x, o->gravity.y, o->gravity.z, "wind", o->wind.x, o->wind.y,
                       o->wind.z, "gust", o->gust_amplitude, o->gust_period, "wind_series_rows", o->nwind,
                       "drag", o->drag ? Py_True : Py_False, "stokes", o->stokes_viscosity, "damping",
                       o->damping, "mass_damping", o->mass_damping, "fracture",
                       o->fracture ? Py_True : Py_False, "contacts", o->contacts ? Py_True : Py_False,
                       "friction", o->friction, "self_collision", o->self_collision ? Py_True : Py_False);
}

// colliders

static const char* const shape_names[] = {"plane", "sphere", "capsule", "box", "mesh", NULL};

static int quat_arg(PyObject* o, vd_quat* q) {
  double x[4];
  if (!vdpy_vec(o, "quat", 4, x)) return 0;
  double n = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
  if (!(n > 1e-12)) return (vdpy_arg_error("quat expects a non-zero quaternion (w, x, y, z)"), 0);
  q->w = x[0] / n, q->x = x[1] / n, q->y = x[2] / n, q->z = x[3] / n;
  return 1;
}

static int add_collider(vdpy_sim* s, const vd_sim_collider* c, vd_sdf* sdf) {
  int i = vd_sim_add_collider(s->data, c);
  if (i < 0) {
    vd_sdf_destroy(sdf);
    vdpy_arg_error("a Sim holds at most %d colliders", VD_SIM_MAX_COLLIDERS);
    return -1;
  }
  s->sdf[i] = sdf;
  return i;
}

static PyObject* sim_add_collider(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"shape", "size", "pos", "quat", NULL};
  PyObject *shape, *size = Py_None, *pos = Py_None, *quat = Py_None;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|OOO:add_collider", names, &shape, &size, &pos, &quat))
    return NULL;
  char sh[16];
  if (!vdpy_str(shape, "shape", sh, sizeof sh)) return NULL;
  int kind = -1;
  for (int k = 0; k < 4; k++)
    if (!strcmp(sh, shape_names[k])) kind = k;
  if (kind < 0) return vdpy_arg_error("shape expects 'plane', 'sphere', 'capsule' or 'box' (meshes: add_mesh_collider), got '%s'", sh);
  vd_sim_collider c = {(vd_sim_shape)kind, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  int nsize = kind == VD_SIM_SPHERE ? 1 : kind == VD_SIM_CAPSULE ? 2 : kind == VD_SIM_BOX ? 3 : 0;
  if (nsize && size == Py_None) return vdpy_arg_error("a %s needs size=", sh);
  if (nsize == 1 && !PySequence_Check(size)) {
    if (!vdpy_f64(size, "size", 1e-9, 1e6, &c.size[0])) return NULL;
  } else if (nsize) {
    if (!vdpy_vec(size, "size", nsize, c.size)) return NULL;
    for (int k = 0; k < nsize; k++)
      if (!(c.size[k] > 0 || (kind == VD_SIM_CAPSULE && k == 1 && c.size[k] >= 0)) || c.size[k] > 1e6)
        return vdpy_arg_error("size expects positive lengths (m)");
  }
  double x[3];
  if (pos != Py_None) {
    if (!vdpy_vec(pos, "pos", 3, x)) return NULL;
    c.pos = vd_v3(x[0], x[1], x[2]);
  }
  if (quat != Py_None && !quat_arg(quat, &c.quat)) return NULL;
  if (!busy_check(s)) return NULL;
  int i = add_collider(s, &c, NULL);
  return i < 0 ? NULL : PyLong_FromLong(i);
}

static PyObject* sim_add_mesh_collider(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"vertices", "triangles", "pos", "quat", "cell", NULL};
  PyObject *vo, *to, *pos = Py_None, *quat = Py_None, *cell = Py_None;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|OOO:add_mesh_collider", names, &vo, &to, &pos, &quat, &cell))
    return NULL;
  PyArrayObject* va = (PyArrayObject*)PyArray_FROMANY(vo, NPY_DOUBLE, 2, 2, NPY_ARRAY_CARRAY_RO);
  PyArrayObject* ta = va ? (PyArrayObject*)PyArray_FROMANY(to, NPY_INT32, 2, 2, NPY_ARRAY_CARRAY_RO | NPY_ARRAY_FORCECAST) : NULL;
  PyObject* r = NULL;
  vd_sim_collider c = {VD_SIM_MESH, {0, 0, 0}, vd_v3(0, 0, 0), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
  vd_sdf_def def = vd_sdf_def_default();
  double x[3];
  if (!va || !ta) goto done;
  npy_intp nv = PyArray_DIM(va, 0), nt = PyArray_DIM(ta, 0);
  if (PyArray_DIM(va, 1) != 3 || PyArray_DIM(ta, 1) != 3 || nv < 4 || nt < 4 || nv > 10000000 || nt > 10000000) {
    vdpy_arg_error("add_mesh_collider expects vertices (n x 3, m) and triangles (k x 3) of a closed mesh");
    goto done;
  }
  const double* vp = PyArray_DATA(va);
  const int* tp = PyArray_DATA(ta);
  for (npy_intp i = 0; i < 3 * nv; i++)
    if (!isfinite(vp[i]) || fabs(vp[i]) > 1e6) {
      vdpy_arg_error("vertices must be finite (m)");
      goto done;
    }
  for (npy_intp i = 0; i < 3 * nt; i++)
    if (tp[i] < 0 || tp[i] >= nv) {
      vdpy_arg_error("triangles index vertices 0..%zd", (Py_ssize_t)nv - 1);
      goto done;
    }
  if (pos != Py_None) {
    if (!vdpy_vec(pos, "pos", 3, x)) goto done;
    c.pos = vd_v3(x[0], x[1], x[2]);
  }
  if (quat != Py_None && !quat_arg(quat, &c.quat)) goto done;
  // grid spacing 2 mm, coarser for meshes over 0.256 m so the grid stays near 128 cells across
  // (the command line's --collider-mesh), or the cell given
  if (cell != Py_None) {
    if (!vdpy_f64(cell, "cell", 1e-5, 10, &def.cell)) goto done;
    def.band = 3 * def.cell, def.padding = 5 * def.cell;
  } else {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, ext = 0;
    for (npy_intp i = 0; i < nv; i++)
      for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], vp[3 * i + k]), hi[k] = fmax(hi[k], vp[3 * i + k]);
    for (int k = 0; k < 3; k++) ext = fmax(ext, hi[k] - lo[k]);
    if (ext / 128 > def.cell) def.cell = ext / 128, def.band = 3 * def.cell, def.padding = 5 * def.cell;
  }
  if (!busy_check(s)) goto done;
  if (s->data->ncollider >= VD_SIM_MAX_COLLIDERS) {
    vdpy_arg_error("a Sim holds at most %d colliders", VD_SIM_MAX_COLLIDERS);
    goto done;
  }
  {
    vd_sdf* sdf = NULL;
    vd_error err = {0};
    vd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = vd_sdf_build(vp, (int)nv, tp, (int)nt, &def, &sdf, &err);
    Py_END_ALLOW_THREADS
    if (st) {
      vdpy_raise(st, &err);
      goto done;
    }
    c.sdf = sdf;
    int i = add_collider(s, &c, sdf);
    if (i >= 0) r = PyLong_FromLong(i);
  }
done:
  Py_XDECREF(va);
  Py_XDECREF(ta);
  return r;
}

static int collider_index(vdpy_sim* s, PyObject* o, int* i) {
  int64_t v;
  if (!vdpy_i64(o, "collider", 0, VD_SIM_MAX_COLLIDERS - 1, &v)) return 0;
  if (v >= s->data->ncollider) return (vdpy_arg_error("no collider %lld (the Sim has %d)", (long long)v, s->data->ncollider), 0);
  *i = (int)v;
  return 1;
}

static PyObject* sim_move_collider(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"index", "pos", "quat", NULL};
  PyObject *io, *pos, *quat = Py_None;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|O:move_collider", names, &io, &pos, &quat)) return NULL;
  int i;
  double x[3];
  if (!collider_index(s, io, &i) || !vdpy_vec(pos, "pos", 3, x)) return NULL;
  vd_quat q = s->data->collider[i].quat;
  if (quat != Py_None && !quat_arg(quat, &q)) return NULL;
  if (!busy_check(s)) return NULL;
  vd_sim_set_collider_pose(s->model, s->data, i, vd_v3(x[0], x[1], x[2]), q);
  Py_RETURN_NONE;
}

static PyObject* sim_colliders(vdpy_sim* s, void* c) {
  PyObject* list = PyList_New(s->data->ncollider);
  for (int i = 0; list && i < s->data->ncollider; i++) {
    const vd_sim_collider* k = &s->data->collider[i];
    PyObject* e = Py_BuildValue("{s:s,s:(ddd),s:(ddd),s:(dddd),s:(ddd)}", "shape", shape_names[k->shape],
                                "size", k->size[0], k->size[1], k->size[2], "pos", k->pos.x, k->pos.y, k->pos.z,
                                "quat", k->quat.w, k->quat.x, k->quat.y, k->quat.z, "vel", k->vel.x, k->vel.y,
                                k->vel.z);
    if (!e) Py_CLEAR(list);
    else PyList_SET_ITEM(list, i, e);
  }
  return list;
}

// nodes, organs, forces, ties

static int node_arg(vdpy_sim* s, PyObject* o, int instance, int* node) {
  if (PyUnicode_Check(o)) {
    char label[VD_LABEL_NAME_MAX];
    if (!vdpy_str(o, "organ", label, sizeof label)) return 0;
    *node = vd_sim_find_organ(s->model, ((vdpy_plant*)s->plant)->model, label, instance);
    if (*node < 0) {
      vd_error err = {0};
      vd_error_set(&err, VD_ERR_NAME, "", 0, 0, "no organ '%s'%s%.0d in the plant (labels or organ names)",
                   label, instance ? "#" : "", instance);
      vdpy_raise(VD_ERR_NAME, &err);
      return 0;
    }
    return 1;
  }
  int64_t v;
  if (!vdpy_i64(o, "node", 0, s->model->nnode_all - 1, &v)) return 0;
  *node = (int)v;
  return 1;
}

static PyObject* sim_find_organ(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"organ", "instance", NULL};
  PyObject *organ, *inst = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|O:find_organ", names, &organ, &inst)) return NULL;
  int64_t v = 0;
  int node;
  if (!PyUnicode_Check(organ)) return PyErr_Format(PyExc_TypeError, "organ expects a label or organ name (str)");
  if (inst && !vdpy_i64(inst, "instance", 0, INT32_MAX, &v)) return NULL;
  if (!node_arg(s, organ, (int)v, &node)) return NULL;
  return PyLong_FromLong(node);
}

static PyObject* sim_apply_force(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"node", "force", "instance", NULL};
  PyObject *no, *fo, *inst = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|O:apply_force", names, &no, &fo, &inst)) return NULL;
  int64_t v = 0;
  int node;
  double f[3];
  if (inst && !vdpy_i64(inst, "instance", 0, INT32_MAX, &v)) return NULL;
  if (!node_arg(s, no, (int)v, &node) || !vdpy_vec(fo, "force", 3, f)) return NULL;
  if (!busy_check(s)) return NULL;
  s->data->node_force[node] = vd_v3(f[0], f[1], f[2]);
  return PyLong_FromLong(node);
}

static PyObject* sim_add_tie(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"node", "target", "compliance", "instance", NULL};
  PyObject *no, *to = Py_None, *co = NULL, *inst = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|OOO:add_tie", names, &no, &to, &co, &inst)) return NULL;
  int64_t v = 0;
  int node;
  double t[3], compliance = 1e-5;
  if (inst && !vdpy_i64(inst, "instance", 0, INT32_MAX, &v)) return NULL;
  if (!node_arg(s, no, (int)v, &node)) return NULL;
  if (co && !vdpy_f64(co, "compliance", 1e-15, 1e6, &compliance)) return NULL;
  if (to != Py_None && !vdpy_vec(to, "target", 3, t)) return NULL;
  if (!busy_check(s)) return NULL;
  vd_vec3 target = to != Py_None ? vd_v3(t[0], t[1], t[2]) : s->data->node_pos[node];
  int i = vd_sim_add_tie(s->data, node, target, compliance);
  if (i < 0) return PyErr_NoMemory();
  return PyLong_FromLong(i);
}

static PyObject* sim_move_tie(vdpy_sim* s, PyObject* args, PyObject* kw) {
  static char* names[] = {"index", "target", NULL};
  PyObject *io, *to;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OO:move_tie", names, &io, &to)) return NULL;
  int64_t i;
  double t[3];
  if (!vdpy_i64(io, "index", 0, INT32_MAX, &i) || !vdpy_vec(to, "target", 3, t)) return NULL;
  if (i >= s->data->ntie) return vdpy_arg_error("no tie %lld (the Sim has %d)", (long long)i, s->data->ntie);
  if (!busy_check(s)) return NULL;
  s->data->tie[i].target = vd_v3(t[0], t[1], t[2]);
  Py_RETURN_NONE;
}

// state arrays: views of the state, valid (and changing) until the Sim is gone

#define SIM_ARRAY(getter, base, field, rows, cols, type, writeable)                                \
  static PyObject* getter(vdpy_sim* s, void* c) {                                                  \
    npy_intp dims[2] = {s->model->rows, cols};                                                     \
    return vdpy_view((PyObject*)s, (void*)s->base->field, (cols) > 1 ? 2 : 1, dims, type, writeable); \
  }
SIM_ARRAY(sim_node_pos, data, node_pos, nnode_all, 3, NPY_DOUBLE, 0)
SIM_ARRAY(sim_node_vel, data, node_vel, nnode_all, 3, NPY_DOUBLE, 0)
SIM_ARRAY(sim_node_force, data, node_force, nnode_all, 3, NPY_DOUBLE, 1)
SIM_ARRAY(sim_node_mass, data, node_mass, nnode_all, 1, NPY_DOUBLE, 0)
SIM_ARRAY(sim_seg_quat, data, seg_quat, nseg, 4, NPY_DOUBLE, 0)
SIM_ARRAY(sim_seg_omega, data, seg_omega, nseg, 3, NPY_DOUBLE, 0)
SIM_ARRAY(sim_seg_torque, data, seg_torque, nseg, 3, NPY_DOUBLE, 1)
SIM_ARRAY(sim_seg_broken, data, seg_broken, nseg, 1, NPY_INT32, 0)
SIM_ARRAY(sim_node_pos0, model, node_pos0, nnode_all, 3, NPY_DOUBLE, 0)
SIM_ARRAY(sim_seg_node, model, seg_node, nseg, 2, NPY_INT32, 0)
SIM_ARRAY(sim_seg_label, model, seg_label, nseg, 1, NPY_INT32, 0)
SIM_ARRAY(sim_seg_instance, model, seg_instance, nseg, 1, NPY_INT32, 0)
SIM_ARRAY(sim_seg_class, model, seg_class, nseg, 1, NPY_INT32, 0)
SIM_ARRAY(sim_seg_radius, model, seg_radius, nseg, 1, NPY_DOUBLE, 0)
SIM_ARRAY(sim_seg_len0, model, seg_len0, nseg, 1, NPY_DOUBLE, 0)
#undef SIM_ARRAY

// bending stress of each rod segment (Pa): a new array each read (an earlier one keeps its values)
static PyObject* sim_stress(vdpy_sim* s, void* c) {
  if (!busy_check(s)) return NULL;
  npy_intp dims[1] = {s->model->nseg};
  PyObject* a = PyArray_ZEROS(1, dims, NPY_DOUBLE, 0);
  if (a && s->model->nseg) vd_sim_seg_stress(s->model, s->data, PyArray_DATA((PyArrayObject*)a));
  return a;
}

// the same per plant segment (NaN where no rod segment resamples it): a new array
static PyObject* sim_plant_stress(vdpy_sim* s, void* c) {
  if (!busy_check(s)) return NULL;
  const vd_model* pm = ((vdpy_plant*)s->plant)->model;
  npy_intp dims[1] = {pm->nseg};
  PyObject* a = PyArray_ZEROS(1, dims, NPY_DOUBLE, 0);
  if (a && pm->nseg) vd_sim_plant_stress(s->model, s->data, pm, PyArray_DATA((PyArrayObject*)a));
  return a;
}

static const char* cause_name(int c) {
  static const char* n[4] = {"force", "moment", "strain_cs", "strain_cb"};
  return c >= 0 && c < 4 ? n[c] : "?";
}

static PyObject* sim_events(vdpy_sim* s, void* c) {
  const vd_model* pm = ((vdpy_plant*)s->plant)->model;
  PyObject* list = PyList_New(s->data->nevent);
  for (int k = 0; list && k < s->data->nevent; k++) {
    const vd_sim_event* e = &s->data->event[k];
    const vd_label* l = vd_model_find_label(pm, e->label);
    PyObject* d = Py_BuildValue("{s:d,s:i,s:i,s:i,s:s,s:i,s:s,s:d,s:d,s:d,s:d,s:s}", "time", e->time,
                                "segment", e->seg, "node", e->node, "label", e->label, "label_name",
                                l ? l->name : "", "instance", e->instance, "class",
                                vd_sim_class_name((vd_sim_class)e->cls), "force", e->force, "moment",
                                e->moment, "cs", e->cs, "cb", e->cb, "cause", cause_name(e->cause));
    if (!d) Py_CLEAR(list);
    else PyList_SET_ITEM(list, k, d);
  }
  return list;
}

static PyObject* sim_stats(vdpy_sim* s, void* c) {
  if (!busy_check(s)) return NULL;
  const vd_sim_model* m = s->model;
  const vd_sim_data* d = s->data;
  int node;
  double md = vd_sim_max_displacement(m, d, &node);
  double tip = m->main_tip >= 0 ? vd_norm(vd_sub(d->node_pos[m->main_tip], m->node_pos0[m->main_tip])) : 0;
  PyObject* wc = PyDict_New();
  for (int k = 0; wc && k < VD_SIM_WARN_COUNT; k++) {
    PyObject* v = PyLong_FromLongLong((long long)d->warning[k]);
    if (!v || PyDict_SetItemString(wc, vd_sim_warning_name((vd_sim_warning)k), v) < 0) Py_CLEAR(wc);
    Py_XDECREF(v);
  }
  PyObject* ev = wc ? sim_events(s, NULL) : NULL;
  if (!ev) {
    Py_XDECREF(wc);
    return NULL;
  }
  return Py_BuildValue("{s:d,s:i,s:d,s:d,s:N,s:i,s:L,s:d,s:i,s:i,s:d,s:d,s:i,s:i,s:L,s:N}", "max_displacement", md,
                       "max_displacement_node", node, "tip_displacement", tip, "kinetic_energy",
                       vd_sim_kinetic_energy(m, d), "events", ev, "nevents", d->nevent, "steps",
                       (long long)d->nstep, "time", d->time, "nodes", m->nnode, "segments", m->nseg,
                       "total_mass", m->total_mass, "max_penetration", d->max_penetration, "contacts",
                       d->ncontact, "sag_free_out_of_reach", m->nsagfree_clamped, "warnings",
                       (long long)d->nwarning, "warning_counts", wc);
}

static PyObject* sim_time(vdpy_sim* s, void* c) { return PyFloat_FromDouble(s->data->time); }
static PyObject* sim_nstep(vdpy_sim* s, void* c) { return PyLong_FromLongLong((long long)s->data->nstep); }

// the deformed plant: a copy of the plant's spec moved to the state (as `verdant sim --final`)
static PyObject* sim_plant(vdpy_sim* s, PyObject* unused) {
  if (!busy_check(s)) return NULL;
  vdpy_plant* p = (vdpy_plant*)s->plant;
  vd_plant_spec* spec = vd_plant_spec_copy(p->spec);
  if (!spec) return PyErr_NoMemory();
  vd_sim_to_spec(s->model, s->data, spec);
  const char* src = PyUnicode_AsUTF8(p->source);
  return src ? vdpy_plant_new(spec, p->seed, src, p->info) : (vd_plant_spec_destroy(spec), NULL);
}

// the plant state of the current rod state (for pictures), in the Sim's own buffer
const vd_data* vdpy_sim_plant_state(PyObject* sim, const vd_model** plant) {
  vdpy_sim* s = (vdpy_sim*)sim;
  *plant = ((vdpy_plant*)s->plant)->model;
  vd_sim_to_plant(s->model, s->data, *plant, s->pstate);
  return s->pstate;
}

static PyGetSetDef sim_getset[] = {
    {"node_pos", (getter)sim_node_pos, NULL, "node positions (m), float64 (nnode_all x 3), a view of the state", NULL},
    {"node_vel", (getter)sim_node_vel, NULL, "node velocities (m/s), float64 (nnode_all x 3)", NULL},
    {"node_force", (getter)sim_node_force, NULL, "external forces set by you, kept across steps (N), writable (nnode_all x 3)", NULL},
    {"node_mass", (getter)sim_node_mass, NULL, "lumped node masses (kg) (nnode_all)", NULL},
    {"seg_quat", (getter)sim_seg_quat, NULL, "segment frames w,x,y,z, float64 (nseg x 4)", NULL},
    {"seg_omega", (getter)sim_seg_omega, NULL, "segment angular velocities (rad/s) (nseg x 3)", NULL},
    {"seg_torque", (getter)sim_seg_torque, NULL, "external torques set by you (N m), writable (nseg x 3)", NULL},
    {"seg_broken", (getter)sim_seg_broken, NULL, "1 where the joint with the parent broke, int32 (nseg)", NULL},
    {"node_pos0", (getter)sim_node_pos0, NULL, "modelled node positions (m) (nnode_all x 3)", NULL},
    {"seg_node", (getter)sim_seg_node, NULL, "start and end node of each rod segment, int32 (nseg x 2)", NULL},
    {"seg_label", (getter)sim_seg_label, NULL, "label id of each rod segment, int32 (nseg)", NULL},
    {"seg_instance", (getter)sim_seg_instance, NULL, "organ instance of each rod segment, int32 (nseg)", NULL},
    {"seg_class", (getter)sim_seg_class, NULL, "material class of each rod segment (green 0 ... root 6), int32 (nseg)", NULL},
    {"seg_radius", (getter)sim_seg_radius, NULL, "rod segment radii (m) (nseg)", NULL},
    {"seg_len0", (getter)sim_seg_len0, NULL, "rod segment rest lengths (m) (nseg)", NULL},
    {"stress", (getter)sim_stress, NULL, "largest bending stress of each rod segment (Pa) (nseg): computed on access, a new array", NULL},
    {"plant_stress", (getter)sim_plant_stress, NULL, "the same per plant segment (NaN where none), a new array", NULL},
    {"events", (getter)sim_events, NULL, "fractures so far: a list of dicts (time, segment, node, label, label_name, instance, class, force, moment, cs, cb, cause)", NULL},
    {"stats", (getter)sim_stats, NULL, "the summary of `verdant sim --stats` (without wall-clock timings)", NULL},
    {"colliders", (getter)sim_colliders, NULL, "the colliders: dicts of shape, size, pos, quat, vel", NULL},
    {"options", (getter)sim_options, NULL, "the run options (change them with set())", NULL},
    {"time", (getter)sim_time, NULL, "simulated time (s)", NULL},
    {"nstep", (getter)sim_nstep, NULL, "steps taken", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMemberDef sim_members[] = {
    {"initial_plant", T_OBJECT_EX, offsetof(vdpy_sim, plant), READONLY, "the plant simulated (as grown)"},
    {NULL, 0, 0, 0, NULL},
};

static PyMethodDef sim_methods[] = {
    {"step", (PyCFunction)(void (*)(void))sim_step, METH_VARARGS | METH_KEYWORDS,
     "step($self, /, n=1)\n--\n\n"
     "step(n=1): advance n time steps of dt without the GIL; raises BadValueError if the state\n"
     "becomes unstable even at dt / 128 (the state is left at the last good substep)."},
    {"settle", (PyCFunction)(void (*)(void))sim_settle, METH_VARARGS | METH_KEYWORDS,
     "settle($self, /, *, statics=False, ke_tol=1e-9, disp_tol=1e-9, max_time=10, max_steps=400, extra_damping=5)\n--\n\n"
     "settle(*, statics=False, ke_tol=1e-9, disp_tol=1e-9, max_time=10, max_steps=400,\n"
     "extra_damping=5) -> (converged, steps): damped dynamics (or static Newton steps) until still."},
    {"get_state", (PyCFunction)sim_get_state, METH_NOARGS,
     "get_state($self, /)\n--\n\n"
     "get_state() -> bytes: the whole rod state (positions, velocities, frames, multipliers,\n"
     "fractures, colliders, ties, forces, time); set_state() on a Sim of the same plant and options\n"
     "resumes it exactly (the same future as not stopping). Native byte order."},
    {"set_state", (PyCFunction)sim_set_state, METH_O,
     "set_state($self, state, /)\n--\n\n"
     "set_state(state): restore a state of get_state() (ArgumentError naming what does not match)."},
    {"reset", (PyCFunction)sim_reset, METH_NOARGS,
     "reset($self, /)\n--\n\n"
     "reset(): back to the modelled shape (colliders and ties kept)."},
    {"set", (PyCFunction)(void (*)(void))sim_set, METH_VARARGS | METH_KEYWORDS,
     "set($self, /, **options)\n--\n\n"
     "set(**options): change run options between steps (dt, iterations, solver, gravity, wind,\n"
     "gust, wind_series, drag, stokes, damping, mass_damping, fracture, contacts, friction,\n"
     "self_collision)."},
    {"add_collider", (PyCFunction)(void (*)(void))sim_add_collider, METH_VARARGS | METH_KEYWORDS,
     "add_collider($self, /, shape, size=None, pos=(0,0,0), quat=(1,0,0,0))\n--\n\n"
     "add_collider(shape, size=None, pos=(0,0,0), quat=(1,0,0,0)) -> index: 'plane' (the half-space\n"
     "below z of quat through pos), 'sphere' (size r), 'capsule' (r, half length), 'box' (half sizes)."},
    {"add_mesh_collider", (PyCFunction)(void (*)(void))sim_add_mesh_collider, METH_VARARGS | METH_KEYWORDS,
     "add_mesh_collider($self, /, vertices, triangles, pos=(0,0,0), quat=(1,0,0,0), cell=None)\n--\n\n"
     "add_mesh_collider(vertices, triangles, pos=(0,0,0), quat=(1,0,0,0), cell=None) -> index: a\n"
     "closed, counter-clockwise triangle mesh through its signed distance grid (cell m)."},
    {"move_collider", (PyCFunction)(void (*)(void))sim_move_collider, METH_VARARGS | METH_KEYWORDS,
     "move_collider($self, /, index, pos, quat=None)\n--\n\n"
     "move_collider(index, pos, quat=None): a new pose for the next step; its velocity becomes the\n"
     "move over dt (a kinematic probe)."},
    {"find_organ", (PyCFunction)(void (*)(void))sim_find_organ, METH_VARARGS | METH_KEYWORDS,
     "find_organ($self, /, organ, instance=0)\n--\n\n"
     "find_organ(organ, instance=0) -> node: the rod node of an organ (label or organ name; a\n"
     "fruit's centre; instance 0: the first)."},
    {"apply_force", (PyCFunction)(void (*)(void))sim_apply_force, METH_VARARGS | METH_KEYWORDS,
     "apply_force($self, /, node_or_organ, force, instance=0)\n--\n\n"
     "apply_force(node_or_organ, force, instance=0) -> node: set the external force (N) on a node\n"
     "(kept until changed)."},
    {"add_tie", (PyCFunction)(void (*)(void))sim_add_tie, METH_VARARGS | METH_KEYWORDS,
     "add_tie($self, /, node_or_organ, target=None, compliance=1e-5, instance=0)\n--\n\n"
     "add_tie(node_or_organ, target=None, compliance=1e-5, instance=0) -> index: a spring (m/N)\n"
     "pulling a node toward target (default: where it is)."},
    {"move_tie", (PyCFunction)(void (*)(void))sim_move_tie, METH_VARARGS | METH_KEYWORDS,
     "move_tie($self, /, index, target)\n--\n\n"
     "move_tie(index, target): move a tie's target (m)."},
    {"plant", (PyCFunction)sim_plant, METH_NOARGS,
     "plant($self, /)\n--\n\n"
     "plant() -> Plant: the deformed plant (the same as `verdant sim --final`)."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_sim_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.Sim",
    .tp_basicsize = sizeof(vdpy_sim),
    .tp_dealloc = (destructor)sim_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "Sim(plant, **options)\n--\n\nSim(plant, **options): a plant as Cosserat rods (see verdant.Sim).",
    .tp_methods = sim_methods,
    .tp_members = sim_members,
    .tp_getset = sim_getset,
    .tp_new = sim_new,
};
