// SPDX-License-Identifier: MIT
// VectorHarvest: N harvest episodes (py_harvest.c's slots) stepped side by side in native threads
// inside one call, the engine of verdant.VectorHarvestEnv. A step takes the N actions as one
// (N, 7) array, releases the GIL, steps (or, after an episode ended, resets: Gymnasium's
// next-step autoreset) every slot on min(threads, N) threads with the environment's reward and
// ending rules, and returns batched observations (N, ...), rewards, terminations and
// truncations. No Python runs per environment per step. Slot i runs episodes 0, 1, 2, ... of its
// own seed. The threads are plain POSIX threads made for the call and joined before it returns
// (a few tens of microseconds against milliseconds of stepping): nothing spins between calls, as
// OpenMP's waiting workers would on a busy machine.
#include "py_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>

typedef struct vdpy_vector {
  PyObject_HEAD
  vd_scene base;         // the scene as read (owned)
  int n, threads;        // environments, threads that step them
  vdpy_slot* slot;       // the episodes (owned, n)
  vdpy_outcome* out;     // the last step's outcomes (owned, n)
  vd_status* st;         // the last call's status per slot (owned, n)
  vd_error* err;         // and its error (owned, n)
  int* reset_next;       // 1 when slot i's episode ended: the next step resets it (owned, n)
  int* was_reset;        // 1 when the last call reset slot i (owned, n)
  vdpy_rules rules;
  int nq;                // arm joints (the same robot in every slot)
  int ready;             // reset() succeeded and close() was not called
  int busy;
} vdpy_vector;

static void vector_free(vdpy_vector* o) {
  for (int i = 0; o->slot && i < o->n; i++) vdpy_slot_free(&o->slot[i]);
  PyMem_Free(o->slot), PyMem_Free(o->out), PyMem_Free(o->st), PyMem_Free(o->err);
  PyMem_Free(o->reset_next), PyMem_Free(o->was_reset);
  o->slot = NULL, o->out = NULL, o->st = NULL, o->err = NULL, o->reset_next = o->was_reset = NULL;
  o->ready = 0;
}

static void vector_dealloc(vdpy_vector* o) {
  vector_free(o);
  vd_scene_free(&o->base);
  Py_TYPE(o)->tp_free((PyObject*)o);
}

static PyObject* vector_new(PyTypeObject* type, PyObject* args, PyObject* kw) {
  static char* names[] = {"scene", "num_envs", "threads", "weights", "terminate_on_detach", "max_steps",
                          "randomize", NULL};
  PyObject *src, *no, *to, *wo, *mo = NULL;
  int tod = 1, randomize = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OOOO|pOp:VectorHarvest", names, &src, &no, &to, &wo, &tod, &mo,
                                   &randomize))
    return NULL;
  int64_t n, t;
  vdpy_rules rules;
  if (!vdpy_i64(no, "num_envs", 1, 65536, &n) || !vdpy_i64(to, "threads", 1, 64, &t) ||
      !vdpy_rules_parse(wo, tod, mo, &rules))
    return NULL;
  rules.randomize = randomize;
  vdpy_vector* o = (vdpy_vector*)type->tp_alloc(type, 0);
  if (!o) return NULL;
  vd_scene_default(&o->base);
  o->n = (int)n, o->threads = (int)t, o->rules = rules;
  o->slot = PyMem_Calloc((size_t)n, sizeof *o->slot);
  o->out = PyMem_Calloc((size_t)n, sizeof *o->out);
  o->st = PyMem_Calloc((size_t)n, sizeof *o->st);
  o->err = PyMem_Calloc((size_t)n, sizeof *o->err);
  o->reset_next = PyMem_Calloc((size_t)n, sizeof(int));
  o->was_reset = PyMem_Calloc((size_t)n, sizeof(int));
  if (!o->slot || !o->out || !o->st || !o->err || !o->reset_next || !o->was_reset) {
    PyErr_NoMemory();
    goto fail;
  }
  for (int i = 0; i < o->n; i++) vd_scene_default(&o->slot[i].scene);
  if (!vdpy_scene_read(src, &o->base)) goto fail;
  return (PyObject*)o;
fail:
  Py_DECREF(o);
  return NULL;
}

// ---------------------------------------------------------------------------------------------
// running one function over every slot on the threads

typedef struct pool_job {
  vdpy_vector* o;
  void (*fn)(vdpy_vector* o, int i, const void* arg);
  const void* arg;
  atomic_int next;  // the next slot to take
} pool_job;

static void* pool_worker(void* p) {
  pool_job* j = p;
  for (int i; (i = atomic_fetch_add(&j->next, 1)) < j->o->n;) j->fn(j->o, i, j->arg);
  return NULL;
}

// fn(o, i, arg) for every slot i, slots taken in turn by min(threads, n) threads (the caller is
// one of them); a thread that cannot be made leaves its share to the others. Without the GIL.
static void pool_run(vdpy_vector* o, void (*fn)(vdpy_vector*, int, const void*), const void* arg) {
  pool_job j = {o, fn, arg, 0};
  int nt = o->threads < o->n ? o->threads : o->n, made = 0;
  pthread_t th[63];
  if (nt > 64) nt = 64;
  for (; made < nt - 1; made++)
    if (pthread_create(&th[made], NULL, pool_worker, &j)) break;
  pool_worker(&j);
  for (int k = 0; k < made; k++) pthread_join(th[k], NULL);
}

static int busy_check(vdpy_vector* o) {
  if (o->busy) return (vdpy_busy("this VectorHarvest"), 0);
  if (!o->slot) return (vdpy_arg_error("the VectorHarvest is closed"), 0);
  return 1;
}

// raise the first slot failure of the last call; 1 when there was none
static int slot_failures(vdpy_vector* o) {
  for (int i = 0; i < o->n; i++)
    if (o->st[i]) {
      o->ready = 0;
      if (o->st[i] == VD_ERR_ARG) return (vdpy_arg_error("environment %d: %s", i, o->err[i].msg), 0);
      return (vdpy_raise(o->st[i], &o->err[i]), 0);
    }
  return 1;
}

// a new (n, cols...) array of type t (cols 0: a vector (n))
static PyObject* batch(int n, int cols, int t) {
  npy_intp d[2] = {n, cols};
  return PyArray_ZEROS(cols ? 2 : 1, d, t, 0);
}

#define ROW(a, i, T) ((T*)PyArray_GETPTR1((PyArrayObject*)(a), (i)))

static void put3(double* r, vd_vec3 v) { r[0] = v.x, r[1] = v.y, r[2] = v.z; }

// the batched observation of every slot: the keys and dtypes of HarvestEnv's state observation
static PyObject* observations(vdpy_vector* o) {
  int n = o->n, nq = o->nq;
  static const char* keys[] = {"q", "qd", "gripper", "ee_pos", "ee_quat", "fruit_pos", "fruit_vel",
                               "held", "touching", "finger_force", "pull_force", "detached"};
  const int cols[] = {nq, nq, 1, 3, 4, 3, 3, 1, 2, 2, 3, 1};
  const int types[] = {NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE,
                       NPY_DOUBLE, NPY_INT8,   NPY_INT8,   NPY_DOUBLE, NPY_DOUBLE, NPY_INT8};
  enum { NK = 12 };
  PyObject* a[NK] = {NULL};
  PyObject* d = PyDict_New();
  for (int k = 0; d && k < NK; k++)
    if (!(a[k] = batch(n, cols[k], types[k])) || PyDict_SetItemString(d, keys[k], a[k]) < 0) Py_CLEAR(d);
  if (d) {
    for (int i = 0; i < n; i++) {
      vd_harvest_obs b;
      vd_harvest_observe(o->slot[i].h, &b);
      memcpy(ROW(a[0], i, double), b.q, (size_t)nq * sizeof(double));
      memcpy(ROW(a[1], i, double), b.qd, (size_t)nq * sizeof(double));
      *ROW(a[2], i, double) = b.gripper_opening;
      put3(ROW(a[3], i, double), b.ee_pos);
      double* q = ROW(a[4], i, double);
      q[0] = b.ee_quat.w, q[1] = b.ee_quat.x, q[2] = b.ee_quat.y, q[3] = b.ee_quat.z;
      put3(ROW(a[5], i, double), b.fruit_pos);
      put3(ROW(a[6], i, double), b.fruit_vel);
      *ROW(a[7], i, npy_int8) = (npy_int8)(b.held != 0);
      ROW(a[8], i, npy_int8)[0] = (npy_int8)(b.touching[0] != 0);
      ROW(a[8], i, npy_int8)[1] = (npy_int8)(b.touching[1] != 0);
      memcpy(ROW(a[9], i, double), b.finger_force, 2 * sizeof(double));
      put3(ROW(a[10], i, double), b.pull_force);
      *ROW(a[11], i, npy_int8) = (npy_int8)(b.detached != 0);
    }
  }
  for (int k = 0; k < NK; k++) Py_XDECREF(a[k]);
  return d;
}

// info: episode, seed and target of every slot, the reset mask, and per-slot reasons where an
// episode ended (Gymnasium's vector info: an array per key and a "_key" mask)
static PyObject* infos(vdpy_vector* o) {
  int n = o->n;
  PyObject *ep = batch(n, 0, NPY_INT64), *seed = batch(n, 0, NPY_UINT64), *tgt = batch(n, 0, NPY_INT32);
  PyObject *draws = batch(n, 0, NPY_INT32), *time = batch(n, 0, NPY_DOUBLE), *rs = batch(n, 0, NPY_BOOL);
  PyObject *reason = batch(n, 0, NPY_OBJECT), *mask = batch(n, 0, NPY_BOOL), *terms = batch(n, VDPY_NTERMS, NPY_DOUBLE);
  PyObject* d = NULL;
  if (ep && seed && tgt && draws && time && rs && reason && mask && terms) {
    for (int i = 0; i < n; i++) {
      vd_harvest_obs b;
      vd_harvest_observe(o->slot[i].h, &b);
      *ROW(ep, i, npy_int64) = o->slot[i].episode;
      *ROW(seed, i, npy_uint64) = o->slot[i].seed;
      *ROW(tgt, i, npy_int32) = b.target_instance;
      *ROW(draws, i, npy_int32) = o->slot[i].draws;
      *ROW(time, i, double) = b.time;
      *ROW(rs, i, npy_bool) = (npy_bool)o->was_reset[i];
      *ROW(mask, i, npy_bool) = (npy_bool)(o->out[i].reason[0] != 0);
      memcpy(ROW(terms, i, double), o->out[i].terms, sizeof o->out[i].terms);
      PyObject* s = PyUnicode_FromString(o->out[i].reason);
      if (!s) goto done;
      PyObject** at = ROW(reason, i, PyObject*);
      PyObject* old = *at;  // a zeroed object array holds references to the int 0
      *at = s;
      Py_XDECREF(old);
    }
    d = Py_BuildValue("{s:O,s:O,s:O,s:O,s:O,s:O,s:O,s:O,s:O}", "episode", ep, "seed", seed, "target_instance",
                      tgt, "draws", draws, "time", time, "autoreset", rs, "reason", reason, "_reason", mask,
                      "reward_terms", terms);
  }
done:
  Py_XDECREF(ep), Py_XDECREF(seed), Py_XDECREF(tgt), Py_XDECREF(draws), Py_XDECREF(time);
  Py_XDECREF(rs), Py_XDECREF(reason), Py_XDECREF(mask), Py_XDECREF(terms);
  return d;
}

// slot i to episode 0 of seeds[i]
static void reset_one(vdpy_vector* o, int i, const void* arg) {
  const uint64_t* seeds = arg;
  memset(&o->err[i], 0, sizeof o->err[i]);
  memset(&o->out[i], 0, sizeof o->out[i]);
  o->st[i] = vdpy_slot_reset(&o->slot[i], &o->base, seeds[i], 0, o->rules.randomize, &o->err[i]);
  o->reset_next[i] = 0, o->was_reset[i] = 1;
}

// slot i one step under its row of the (n, 7) actions, or its next episode when the last ended
static void step_one(vdpy_vector* o, int i, const void* arg) {
  const double* r = (const double*)arg + 7 * i;
  vdpy_slot* s = &o->slot[i];
  memset(&o->err[i], 0, sizeof o->err[i]);
  o->was_reset[i] = o->reset_next[i];
  if (o->reset_next[i]) {  // the episode ended at the last step: the next one, zero reward
    memset(&o->out[i], 0, sizeof o->out[i]);
    o->st[i] = vdpy_slot_reset(s, &o->base, s->seed, s->episode + 1, o->rules.randomize, &o->err[i]);
    o->reset_next[i] = 0;
    return;
  }
  double g = r[6] < 0 ? 0 : r[6] > 1 ? 1 : r[6];
  vd_harvest_action act = {vd_v3(r[0], r[1], r[2]), vd_v3(r[3], r[4], r[5]), g};
  o->st[i] = vdpy_slot_step(s, &act, &o->rules, &o->out[i], &o->err[i]);
  o->reset_next[i] = !o->st[i] && (o->out[i].terminated || o->out[i].truncated);
}

// reset(seeds) -> (observations, info): episode 0 of seeds[i] in slot i
static PyObject* vector_reset(vdpy_vector* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"seeds", NULL};
  PyObject* so;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O:reset", names, &so)) return NULL;
  if (!busy_check(o)) return NULL;
  PyObject* seq = PySequence_Fast(so, "seeds: a sequence of num_envs whole numbers");
  if (!seq) return NULL;
  if (PySequence_Fast_GET_SIZE(seq) != o->n) {
    Py_DECREF(seq);
    return vdpy_arg_error("seeds: %d numbers (num_envs), got %zd", o->n, PySequence_Fast_GET_SIZE(seq));
  }
  uint64_t* seeds = PyMem_Malloc((size_t)o->n * sizeof *seeds);
  if (!seeds) {
    Py_DECREF(seq);
    return PyErr_NoMemory();
  }
  for (int i = 0; i < o->n; i++) {
    int64_t s;
    if (!vdpy_i64(PySequence_Fast_GET_ITEM(seq, i), "seeds[i]", 0, INT64_MAX, &s)) {
      Py_DECREF(seq);
      PyMem_Free(seeds);
      return NULL;
    }
    seeds[i] = (uint64_t)s;
  }
  Py_DECREF(seq);
  o->busy = 1;
  Py_BEGIN_ALLOW_THREADS
  pool_run(o, reset_one, seeds);
  Py_END_ALLOW_THREADS
  o->busy = 0;
  PyMem_Free(seeds);
  if (!slot_failures(o)) return NULL;
  vd_harvest_obs b;
  vd_harvest_observe(o->slot[0].h, &b);
  o->nq = b.nq;
  o->ready = 1;
  return Py_BuildValue("(NN)", observations(o), infos(o));
}

// step(actions) -> (observations, rewards, terminated, truncated, info)
static PyObject* vector_step(vdpy_vector* o, PyObject* args, PyObject* kw) {
  static char* names[] = {"actions", NULL};
  PyObject* ao;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O:step", names, &ao)) return NULL;
  if (!busy_check(o)) return NULL;
  if (!o->ready) return vdpy_arg_error("step() before a successful reset(): call reset() first");
  PyArrayObject* a = (PyArrayObject*)PyArray_FROMANY(ao, NPY_DOUBLE, 2, 2, NPY_ARRAY_IN_ARRAY);
  if (!a) return NULL;
  if (PyArray_DIM(a, 0) != o->n || PyArray_DIM(a, 1) != 7) {
    Py_DECREF(a);
    return vdpy_arg_error("actions: shape (%d, 7), got (%zd, %zd)", o->n, (Py_ssize_t)PyArray_DIM(a, 0),
                          (Py_ssize_t)PyArray_DIM(a, 1));
  }
  const double* x = PyArray_DATA(a);
  for (npy_intp k = 0; k < 7 * (npy_intp)o->n; k++)
    if (!isfinite(x[k])) {
      Py_DECREF(a);
      return vdpy_arg_error("actions: finite numbers (row %d)", (int)(k / 7));
    }
  o->busy = 1;
  int n = o->n;
  Py_BEGIN_ALLOW_THREADS
  pool_run(o, step_one, x);
  Py_END_ALLOW_THREADS
  o->busy = 0;
  Py_DECREF(a);
  if (!slot_failures(o)) return NULL;
  PyObject *rew = batch(n, 0, NPY_DOUBLE), *term = batch(n, 0, NPY_BOOL), *trunc = batch(n, 0, NPY_BOOL);
  if (rew && term && trunc)
    for (int i = 0; i < n; i++) {
      *ROW(rew, i, double) = o->out[i].reward;
      *ROW(term, i, npy_bool) = (npy_bool)o->out[i].terminated;
      *ROW(trunc, i, npy_bool) = (npy_bool)o->out[i].truncated;
    }
  if (!rew || !term || !trunc) {
    Py_XDECREF(rew), Py_XDECREF(term), Py_XDECREF(trunc);
    return NULL;
  }
  return Py_BuildValue("(NNNNN)", observations(o), rew, term, trunc, infos(o));
}

static PyObject* vector_close(vdpy_vector* o, PyObject* unused) {
  if (o->busy) return vdpy_busy("this VectorHarvest");
  vector_free(o);
  Py_RETURN_NONE;
}

static PyObject* vector_get_n(vdpy_vector* o, void* c) { return PyLong_FromLong(o->n); }
static PyObject* vector_get_threads(vdpy_vector* o, void* c) { return PyLong_FromLong(o->threads); }

static PyObject* vector_get_nq(vdpy_vector* o, void* c) {
  if (!o->nq && o->slot) {  // before the first reset: the scene's robot, from one episode
    vd_error err = {0};
    vd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = vdpy_slot_reset(&o->slot[0], &o->base, 0, 0, o->rules.randomize, &err);
    Py_END_ALLOW_THREADS
    if (st) return vdpy_raise(st, &err);
    vd_harvest_obs b;
    vd_harvest_observe(o->slot[0].h, &b);
    o->nq = b.nq;
  }
  return PyLong_FromLong(o->nq);
}

static PyObject* vector_get_control_dt(vdpy_vector* o, void* c) { return PyFloat_FromDouble(o->base.control_dt); }

static PyGetSetDef vector_getset[] = {
    {"num_envs", (getter)vector_get_n, NULL, "environments", NULL},
    {"threads", (getter)vector_get_threads, NULL, "threads that step them", NULL},
    {"nq", (getter)vector_get_nq, NULL, "arm joints (the first call makes a reset of environment 0)", NULL},
    {"control_dt", (getter)vector_get_control_dt, NULL, "one step (s)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMethodDef vector_methods[] = {
    {"reset", (PyCFunction)(void (*)(void))vector_reset, METH_VARARGS | METH_KEYWORDS,
     "reset($self, /, seeds)\n--\n\n"
     "Episode 0 of seeds[i] in environment i, on the threads without the GIL. Returns\n"
     "(observations, info): arrays (num_envs, ...)."},
    {"step", (PyCFunction)(void (*)(void))vector_step, METH_VARARGS | METH_KEYWORDS,
     "step($self, /, actions)\n--\n\n"
     "One control step of every environment under actions (num_envs, 7), on the threads without\n"
     "the GIL; an environment whose episode ended at the last step starts its next episode\n"
     "instead (zero reward). Returns (observations, rewards, terminated, truncated, info)."},
    {"close", (PyCFunction)vector_close, METH_NOARGS, "close($self, /)\n--\n\nFree every episode now."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_vector_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.VectorHarvest",
    .tp_basicsize = sizeof(vdpy_vector),
    .tp_dealloc = (destructor)vector_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "VectorHarvest(scene, num_envs, threads, weights, terminate_on_detach=True, max_steps=None, "
              "randomize=True)\n--\n\n"
              "num_envs harvest episodes stepped in native threads (see verdant.VectorHarvestEnv).",
    .tp_methods = vector_methods,
    .tp_getset = vector_getset,
    .tp_new = vector_new,
};
