// SPDX-License-Identifier: MIT
// The verdant Python extension (verdant._verdant): shared declarations of its C files.
//
// The extension wraps the public C API (include/verdant/*.h) and nothing else. Objects own the
// library's memory (a spec and its compiled model, a cloud, a rod model and its state, a
// renderer); numpy arrays over that memory are views whose base is the owning object, so the
// memory lives as long as any array does. Library failures become verdant.Error subclasses
// carrying status, file, line, column and message; bad arguments raise before the library sees
// them. Long calls (growing, sampling, stepping, drawing) release the GIL; an object used by one
// thread while another calls it raises verdant.Error instead of racing.
#ifndef VERDANT_PY_INTERNAL_H
#define VERDANT_PY_INTERNAL_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#define PY_ARRAY_UNIQUE_SYMBOL vdpy_ARRAY_API
#ifndef VDPY_MODULE_C
#define NO_IMPORT_ARRAY
#endif
#include <numpy/arrayobject.h>

#include "verdant/verdant.h"

// ---------------------------------------------------------------------------------------------
// errors (py_module.c)

// Raise the verdant.Error subclass of st with err's file, line, column and message (err
// Nullable: the status text); returns NULL.
PyObject* vdpy_raise(vd_status st, const vd_error* err);
// Raise verdant.ArgumentError (a ValueError) with a printf-style message; returns NULL.
PyObject* vdpy_arg_error(const char* fmt, ...);
// Raise verdant.Error for an object already in use by another thread; returns NULL.
PyObject* vdpy_busy(const char* what);

// ---------------------------------------------------------------------------------------------
// argument conversion (py_args.c): each returns 1 on success, 0 with an exception set; None is
// never accepted here (callers skip None themselves)

// A whole number (int or anything with __index__, not bool) within [lo, hi].
int vdpy_i64(PyObject* o, const char* name, int64_t lo, int64_t hi, int64_t* out);
// A finite real number within [lo, hi].
int vdpy_f64(PyObject* o, const char* name, double lo, double hi, double* out);
// A real number within [lo, hi], or +inf when inf_ok (a threshold that never fires).
int vdpy_f64_inf(PyObject* o, const char* name, double lo, double hi, double* out);
// A sequence of n finite numbers.
int vdpy_vec(PyObject* o, const char* name, int n, double* out);
// Truth value (any object; bool(o)).
int vdpy_bool(PyObject* o, const char* name, int* out);
// A file-system path (str, bytes or os.PathLike) into buf (cap bytes), without NUL bytes.
int vdpy_path(PyObject* o, const char* name, char* buf, size_t cap);
// A str into buf (cap bytes, UTF-8), without NUL bytes.
int vdpy_str(PyObject* o, const char* name, char* buf, size_t cap);
// Keyword argument `name` of kw (Nullable) or NULL when absent or None (borrowed).
PyObject* vdpy_kw(PyObject* kw, const char* name);
// Fail with TypeError when kw holds a key not in the NULL-terminated list names.
int vdpy_kw_check(PyObject* kw, const char* func, const char* const* names);

// ---------------------------------------------------------------------------------------------
// arrays (py_module.c)

// A numpy array of nd dims over data owned by owner (a new reference to owner is kept as the
// base); writeable 0 makes it read-only. An empty array needs no data.
PyObject* vdpy_view(PyObject* owner, void* data, int nd, const npy_intp* dims, int typenum,
                    int writeable);
// A dict {id: name} of a label table.
PyObject* vdpy_label_dict(const vd_label* labels, int n);
// A list of dicts (id, name, organ, rgb) of a label table.
PyObject* vdpy_label_list(const vd_label* labels, int n);

// ---------------------------------------------------------------------------------------------
// types

// A plant: its editable spec and the compiled model (py_plant.c).
typedef struct vdpy_plant {
  PyObject_HEAD
  vd_plant_spec* spec;   // the plant as grown or read (owned)
  vd_model* model;       // compiled from spec (owned)
  uint64_t seed;         // growth seed: the default seed of its clouds (as the CLI does)
  PyObject* source;      // where it came from (str)
  PyObject* info;        // dict: modules and module_counts of the derivation (owned)
} vdpy_plant;

// A labelled triangle mesh of a plant (py_plant.c).
typedef struct vdpy_mesh {
  PyObject_HEAD
  vd_mesh mesh;        // owned
  PyObject* plant;     // the plant it was made from (its label table)
} vdpy_mesh;

// A labelled point cloud (py_cloud.c).
typedef struct vdpy_cloud {
  PyObject_HEAD
  vd_cloud cloud;      // owned
  uint64_t seed;       // sampling seed (recorded in file headers)
  int sensor;          // vd_sensor, for the header comment
  int instance_labels; // 1 after relabelling by instance
  PyObject* xyz;       // float32 copy of pos, made on first use (owned, Nullable)
  PyObject* stats;     // dict of the sampling's counters and timings (owned)
} vdpy_cloud;

// A rod simulation of a plant (py_sim.c).
typedef struct vdpy_sim {
  PyObject_HEAD
  PyObject* plant;       // the vdpy_plant simulated (its model is borrowed by the rod model)
  vd_sim_model* model;   // owned
  vd_sim_data* data;     // owned
  vd_data* pstate;       // plant state for pictures and clouds (owned)
  vd_sdf* sdf[VD_SIM_MAX_COLLIDERS];  // distance grids of mesh colliders (owned)
  double* wind;          // wind series rows (owned, nwind x 4)
  int nwind;
  int busy;              // a thread is stepping it
} vdpy_sim;

// An offscreen renderer (py_render.c).
typedef struct vdpy_renderer {
  PyObject_HEAD
  vd_renderer* r;        // owned
  vd_render_def def;
  char robot[4096];      // robot MJCF path ("" none)
  int busy;
} vdpy_renderer;

extern PyTypeObject vdpy_plant_type, vdpy_mesh_type, vdpy_cloud_type, vdpy_sim_type,
    vdpy_renderer_type;
// The classes to instantiate (Python subclasses registered by verdant/__init__.py, else the
// base types above).
extern PyTypeObject* vdpy_plant_class;
extern PyTypeObject* vdpy_mesh_class;
extern PyTypeObject* vdpy_cloud_class;

// The plant model of a Sim and its plant state at the Sim's current rod state (the Sim's own
// buffer, valid until the next call).
const vd_data* vdpy_sim_plant_state(PyObject* sim, const vd_model** plant);

// Harvest episode slots (py_harvest.c): what a Harvest holds once and a VectorHarvest
// (py_vector.c) N times: the episode's scene, its plant (grown for the draw) and the episode
// over it, with the environment's bookkeeping (reward state, step count). No Python calls in
// the slot functions: run them without the GIL, one slot per thread at a time.
#include "verdant/robot.h"

#define VDPY_DRAWS 32        // plant draws of one episode before reset gives up (docs/python.md)
#define VDPY_NTERMS 7        // reward terms: detach, grasp, distance, pull_force, fracture, drop, hit

typedef struct vdpy_slot {
  vd_scene scene;        // the current episode's scene (owned)
  vd_plant_spec* spec;   // the episode's plant, placed (owned)
  vd_model* plant;       // compiled (owned; the episode borrows it)
  uint64_t plant_seed;   // the seed spec was grown with
  vd_harvest* h;         // the episode (owned; Nullable before the first draw)
  vd_data* pstate;       // the plant state of the current step (owned)
  int stepped;           // step() was called in this episode (the scripted controller is off)
  int ready;             // the last reset found a reachable target and the episode is not over
  uint64_t seed;         // the episode's seed
  int64_t episode;       // its index under the seed
  int draws;             // plant draws the last reset took (1 when the first was possible)
  int nevents;           // events already seen by the reward
  int was_detached, was_held;
  int64_t steps;         // control steps of the episode
} vdpy_slot;

// The reward weights and ending rules of an environment (docs/python.md).
typedef struct vdpy_rules {
  double w[VDPY_NTERMS];   // weight of each term, in the order of VDPY_NTERMS
  int terminate_on_detach; // the episode ends when the target comes off
  int64_t max_steps;       // truncation after this many steps (0: the scene's duration only)
  int randomize;           // draw each episode from the scene's "episodes" ranges
} vdpy_rules;

// One control step's outcome.
typedef struct vdpy_outcome {
  double reward, terms[VDPY_NTERMS];
  int ok;                  // 0 when MuJoCo or the plant failed (the episode is then over)
  int terminated, truncated;
  char reason[128];        // why it ended ("" while it goes on)
} vdpy_outcome;

// Names of the reward terms, in order.
extern const char* const vdpy_term_names[VDPY_NTERMS];
// Free a slot's episode, plant and scene (a zeroed slot is fine).
void vdpy_slot_free(vdpy_slot* o);
// Episode k of seed (base's randomisation when rules->randomize), the plant redrawn up to
// VDPY_DRAWS times until a fruit is reachable; VD_ERR_VALUE naming the scene, the draws and the
// reason when none is.
vd_status vdpy_slot_reset(vdpy_slot* o, const vd_scene* base, uint64_t seed, int64_t k, int randomize,
                          vd_error* err);
// One control step under a with rules' reward and ending; VD_ERR_ARG when the slot is not
// ready (no successful reset, or the episode is over).
vd_status vdpy_slot_step(vdpy_slot* o, const vd_harvest_action* a, const vdpy_rules* rules, vdpy_outcome* out,
                         vd_error* err);
// Rules from Python values: weights (VDPY_NTERMS numbers, vdpy_term_names' order),
// terminate_on_detach, max_steps (Nullable or None: none); randomize on. 0 with an exception set.
int vdpy_rules_parse(PyObject* weights, int terminate_on_detach, PyObject* max_steps, vdpy_rules* r);
// (ok, reward, {term: value}, terminated, truncated, reason) of an outcome.
PyObject* vdpy_outcome_tuple(const vdpy_outcome* out);
// Read a scene file or its JSON text (src: str, bytes or path) into *out; NULL with an
// exception set. Holds the GIL only for the conversion.
int vdpy_scene_read(PyObject* src, vd_scene* out);

// Harvest episodes (py_harvest.c): the type, the plant state of the current step with the
// colliders the robot's geoms are to the plant, and its busy flag (set >= 0 sets it; returns the
// old value).
typedef struct vdpy_harvest vdpy_harvest;
extern PyTypeObject vdpy_harvest_type;
// N harvest episodes stepped in native threads (py_vector.c).
extern PyTypeObject vdpy_vector_type;
const vd_data* vdpy_harvest_plant_state(PyObject* harvest, const vd_model** plant,
                                        const vd_sim_collider** col, int* ncol);
int vdpy_harvest_busy(PyObject* harvest, int set);

// Module functions.
PyObject* vdpy_grow(PyObject* self, PyObject* args, PyObject* kw);
PyObject* vdpy_load(PyObject* self, PyObject* args, PyObject* kw);
PyObject* vdpy_read_cloud(PyObject* self, PyObject* args, PyObject* kw);
PyObject* vdpy_read_png(PyObject* self, PyObject* args, PyObject* kw);
// _cloud_unpickle(data, stats): a Cloud from Cloud.__reduce__'s bytes (py_cloud.c).
PyObject* vdpy_cloud_unpickle(PyObject* self, PyObject* args);

// Grow (or read) the plant file path as grow() does with seed, steps (-1: the file's) and
// "NAME=VALUE" overrides; *out is a new spec. No Python calls: run it without the GIL.
vd_status vdpy_grow_file(const char* path, uint64_t seed, int steps, char* const* sets, int nset,
                         vd_plant_spec** out, vd_error* err);
// A new Plant owning spec (taken) with its model compiled; NULL with an exception set (spec
// freed).
PyObject* vdpy_plant_new(vd_plant_spec* spec, uint64_t seed, const char* source, PyObject* info);
// Sample a cloud of plant model m in state d (Nullable: rest) with the keyword options of
// Plant.cloud; spec gives the bounding box that places scanners.
PyObject* vdpy_cloud_make(const vd_plant_spec* spec, const vd_model* m, const vd_data* d,
                          uint64_t default_seed, PyObject* kw);

#endif
