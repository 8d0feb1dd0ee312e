// SPDX-License-Identifier: MIT
// lsys turtle: interprets an L-string with L-Py's 3D turtle (PlantGL semantics) and appends
// labelled geometry to a plant spec: frustum segments between shared nodes, spheres, and thin
// or closed triangle meshes (leaf, disc, quad, box, polygon).
//
// The frame follows PlantGL: heading H, left L, up U with H = L x U, starting at H = +Z,
// U = +X, L = -Y. Angles arrive in degrees and are turned into radians here. The colour
// (material) index is the semantic label; instance ids number the producing modules 1..K in
// order of first drawing. docs/turtle.md is the command table.
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <string.h>

#include "lsys/lsys_internal.h"  // object parameters (curves, functions, geometry) of the Python engine

#define EPS 1e-10                // lengths and radii below this draw nothing (m)
#define NF_MAX_STEPS 100000000.0 // nF refuses to draw more segments than this in one module
#define SLICES_MIN 3             // SectionResolution bounds
#define SLICES_MAX 1024
#define REORTHO_EVERY 64 // re-orthonormalise the frame after this many rotations

// predefined symbol names, for messages when no lsystem is at hand
static const char* const sym_names[] = {
#define SYM_NAME(e, s) s,
    VD_SYM_LIST(SYM_NAME)
#undef SYM_NAME
};

// What [ pushes and ] pops: the whole drawing state of one path.
typedef struct tstate {
  vd_vec3 pos;       // position (m)
  vd_vec3 h, l, u;   // heading, left, up: orthonormal, H = L x U
  double width;      // current radius before scaling (m)
  double scale;      // uniform turtle scale (@D, @Di, @Dd)
  double age;        // age written on segments (SetAge)
  vd_vec3 tropism;   // unit tropism direction, or 0 for none
  double elasticity; // tropism strength in [0, 1]
  int color;         // material index = semantic label
  int slices;        // section resolution of segments, spheres and discs
  int node;          // plant node at pos, -1 after a move without drawing
  int parent;        // last segment drawn on this path, -1 at the root
  int axis, order;   // axis id and branching order of the segments drawn next
  int pending;       // 1 inside a [ that has not drawn a segment yet (axis not created)
  int tail;          // last segment drawn on this state's own axis, -1 if none
  int gc;            // 1 between @Gc and @Ge
  int gc_prev;       // last segment of the current generalised cylinder, -1 if none
  int polygon;       // 1 between { and }
  int64_t open_at;   // module of the '[' that opened this state's branch
  // curve-fed geometry (docs/turtle.md, "Guides, contours, sweeps"): indices into the run's
  // tables, -1 for none
  int contour;       // cross section of F and generalised cylinders (a run curve), -1: circle
  int contour_ccw;   // the contour turns counter-clockwise (face orientation)
  int gc_contour, gc_ccw;  // the contour when @Gc started (the tube's section)
  int guide;         // the guide being followed (T->gst), -1 for none
  int gst_top;       // T->ngst to restore when this state is restored
  int gcp_start, gcp_n;    // the tube's recorded path (T->gcp) while @Gc is on with a contour
  int gcp_top;       // T->ngcp to restore when this state is restored
} tstate;

// Data of an object parameter, fetched from the Python engine once per run and parameter.
enum { CUR_POINTS = 1, CUR_GUIDE = 2, CUR_FUNC = 3 };
typedef struct tcurve {
  double key;        // the parameter it came from (a boxed object handle)
  int kind;          // CUR_*
  int dim, n;        // coordinates per point (2, 3), points or samples
  double* p;         // points (n x dim), or function values (n)
  double* tan;       // CUR_GUIDE: unit tangents (n x dim)
  double* nrm;       // CUR_GUIDE: unit normals (n x dim)
  double length;     // CUR_GUIDE: the curve's own length; CUR_FUNC: first x
  double lastx;      // CUR_FUNC: last x
  int closed;        // CUR_POINTS: first and last points coincide
} tcurve;

// A guide being followed (PlantGL's TurtlePath): its curve and where the turtle is on it.
typedef struct tguide {
  int curve;         // run curve (CUR_GUIDE)
  int yorient, ccw;  // 2D: the curve's y is the turtle's left (else up); the curve turns the other way
  double total;      // length the whole curve stands for (m, before the turtle scale)
  double scale;      // total / the curve's own length
  double t;          // position on the curve, normalised arc length in [0, 1]
  vd_vec3 pos;       // last position on the curve (curve space; 2D in x, y)
  vd_vec3 h, l, u;   // last heading on the curve; 3D: with the curve's left and up
} tguide;

// A point of a generalised cylinder's path (recorded while @Gc is on with a contour).
typedef struct tgcp {
  vd_vec3 p, l;      // position and turtle left (m)
  double r;          // radius (m)
} tgcp;

// One run of the turtle over one L-string.
typedef struct turtle {  // NOLINT(clang-analyzer-optin.performance.Padding): fields grouped by meaning; a few per derivation
  const vd_lsystem* ls; // Nullable: names and strings
  const vd_lstring* s;  // the string being read
  vd_turtle_def def;    // settings
  vd_plant_spec* plant; // output
  vd_error* err;        // Nullable: error record
  tstate t;             // current state
  tstate* stack;        // saved states ([ ... ]) (nstack)
  int nstack, cap_stack;
  int next_axis; // id of the next axis created
  int nrot;      // rotations since the frame was last re-orthonormalised
  // the module being interpreted
  int64_t i;       // index in s
  int sym;         // its symbol
  const double* p; // its parameters (np)
  int np;
  // instance numbering: module -> 1..K in order of first drawing
  int ninst;           // last instance id handed out
  int64_t last_module; // module of the last lookup
  int last_instance;   // its instance id
  int64_t max_module;  // largest module seen so far
  int hashed;          // 1 once modules stopped arriving in increasing order
  int64_t* hkey;       // open-addressing table: module, -1 = empty (hcap)
  int* hval;           // instance of each key (hcap)
  int64_t hcap, hcount;
  int seg0, sphere0, mesh0; // first elements of this run in the plant
  // polygon being recorded ({ . })
  vd_vec3* poly; // recorded points (m) (npoly)
  int npoly, cap_poly;
  int poly_label;      // label of the polygon (colour at {, or set inside)
  int64_t poly_module; // module of the {
  int poly_node, poly_parent;
  // scratch for meshes
  vd_vec3* vbuf; // vertices (cap_vbuf)
  int cap_vbuf;
  int* tbuf; // triangle indices (cap_tbuf ints)
  int cap_tbuf;
  int* ibuf; // ear-clipping index list (cap_ibuf)
  int cap_ibuf;
  // cached sine and cosine of the last angle (degrees)
  double c_deg, c_sin, c_cos;
  int warned_guide, warned_width, warned_color; // warnings already logged once
  // curve-fed geometry
  tcurve* cur;       // object parameters read so far (ncur)
  int ncur, cap_cur;
  tguide* gst;       // guide states, a stack that follows [ ] (ngst)
  int ngst, cap_gst;
  tgcp* gcp;         // recorded tube paths, a stack that follows [ ] (ngcp)
  int ngcp, cap_gcp;
  double* query; // Nullable: parameter values of the string (query run: ?P ?H ... are filled)
  lsys_qframes* qf;  // Nullable: frames of the query modules that take Vector3 objects
  // warnings, reported after the run with the file line of their first module
  struct twarn {
    int64_t i;     // first module it happened at
    int sym;       // its symbol
    int count;     // times
    char msg[160]; // what happened
  } warn[3];
} turtle;

enum { WARN_WIDTH, WARN_RADIUS, WARN_BRACKET };

// ---------------------------------------------------------------------------------------------
// defaults

vd_turtle_def vd_turtle_def_default(void) {
  vd_turtle_def d;
  d.angle = 60;
  d.step = 1;
  d.width = 0.1;
  d.width_inc = 1;
  d.scale_factor = 0.5;
  d.color = 1;
  d.slices = 8;
  d.tropism = vd_v3(0, 0, 1);
  d.elasticity = 0;
  return d;
}

// ---------------------------------------------------------------------------------------------
// errors and parameters

static const char* sym_name(const turtle* T, int sym) {
  if (T->ls) return vd_lsys_symbol_name(T->ls, sym);
  if (sym >= 0 && sym < VD_SYM_PREDEFINED_COUNT) return sym_names[sym];
  return "?";
}

// Record an error about the current module; returns st.
static vd_status fail(turtle* T, vd_status st, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static vd_status fail(turtle* T, vd_status st, const char* fmt, ...) {
  char msg[320];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return vd_error_set(T->err, st, "", 0, 0, "turtle: module %lld '%s': %s", (long long)T->i,
                      sym_name(T, T->sym), msg);
}

static vd_status nomem(turtle* T) {
  return fail(T, VD_ERR_NOMEM, "out of memory");
}

// a value L-Py accepts with a warning (it is ignored): kept for the report after the run
static void warn_module(turtle* T, int kind, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void warn_module(turtle* T, int kind, const char* fmt, ...) {
  struct twarn* w = &T->warn[kind];
  if (w->count++ == 0) {
    w->i = T->i;
    w->sym = T->sym;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->msg, sizeof w->msg, fmt, ap);
    va_end(ap);
  }
}

// a negative width or radius parameter k: L-Py warns and ignores it (1 when it was negative)
static int negative_ignored(turtle* T, int k, double v, int kind) {
  if (v >= 0) return 0;
  warn_module(T, kind, "negative %s %g (ignored, as in L-Py)", kind == WARN_WIDTH ? "width" : "radius", v);
  (void)k;
  return 1;
}

// parameter k of the current module as a finite number
static vd_status num(turtle* T, int k, double* out) {
  double v = T->p[k];
  *out = 0;
  if (!isfinite(v)) {
    if (vd_lsys_value_is_str(v))
      return fail(T, VD_ERR_TYPE, "parameter %d is a string, expected a number", k + 1);
    if (vd_lsys_value_is_obj(v)) {
      char r[120];
      lsys_py_repr(T->ls, v, r, sizeof r);
      return fail(T, VD_ERR_TYPE, "parameter %d is %s, expected a number", k + 1, r);
    }
    return fail(T, VD_ERR_VALUE, "parameter %d is not finite", k + 1);
  }
  *out = v;
  return VD_OK;
}

// parameter k, or dflt when the module has fewer parameters
static vd_status num_or(turtle* T, int k, double dflt, double* out) {
  if (k >= T->np) {
    *out = dflt;
    return VD_OK;
  }
  return num(T, k, out);
}

// parameter k as a non-negative length or radius, or dflt
static vd_status nonneg_or(turtle* T, int k, double dflt, const char* what, double* out) {
  vd_status st = num_or(T, k, dflt, out);
  if (st) return st;
  if (*out < 0) return fail(T, VD_ERR_VALUE, "negative %s %g", what, *out);
  return VD_OK;
}

// parameter k as a non-negative int index (colour, label), truncated like Python's int()
static vd_status index_at(turtle* T, int k, const char* what, int* out) {
  double v;
  *out = 0;
  vd_status st = num(T, k, &v);
  if (st) return st;
  if (v < 0 || v > (double)INT32_MAX) return fail(T, VD_ERR_VALUE, "bad %s %g", what, v);
  *out = (int)v;
  return VD_OK;
}

// refuse more than max parameters (max = L-Py's maximum + one trailing label)
static vd_status max_params(turtle* T, int max) {
  if (T->np > max)
    return fail(T, VD_ERR_ARG, "takes at most %d parameters (the last one a label), got %d", max,
                T->np);
  return VD_OK;
}

// label of a primitive: the explicit trailing parameter k when present, else the colour
static vd_status label_at(turtle* T, int k, int* label) {
  if (k < T->np) return index_at(T, k, "label", label);
  *label = T->t.color;
  return VD_OK;
}

// index of the derived-string module that produced module i
static int64_t module_of(const turtle* T, int64_t i) {
  return T->s->src ? T->s->src[i] : i;
}

// ---------------------------------------------------------------------------------------------
// instance ids: compact renumbering of producing modules, in order of first drawing

static uint64_t hash64(int64_t k) {
  uint64_t x = (uint64_t)k;
  x ^= x >> 33;
  x *= UINT64_C(0xff51afd7ed558ccd);
  x ^= x >> 33;
  return x;
}

// find the slot of key (or the empty slot where it belongs)
static int64_t hash_slot(const turtle* T, int64_t key) {
  int64_t mask = T->hcap - 1, j = (int64_t)(hash64(key) & (uint64_t)mask);
  while (T->hkey[j] != -1 && T->hkey[j] != key)
    j = (j + 1) & mask;
  return j;
}

// insert key -> val (key absent); grows the table at half load
static int hash_put(turtle* T, int64_t key, int val) {
  if (2 * (T->hcount + 1) > T->hcap) {
    int64_t ncap = T->hcap ? 2 * T->hcap : 1024;
    int64_t* nkey = vd_malloc((size_t)ncap * sizeof *nkey);
    int* nval = vd_malloc((size_t)ncap * sizeof *nval);
    if (!nkey || !nval) {
      vd_free(nkey, nkey ? (size_t)ncap * sizeof *nkey : 0);
      vd_free(nval, nval ? (size_t)ncap * sizeof *nval : 0);
      return 0;
    }
    memset(nkey, 0xff, (size_t)ncap * sizeof *nkey);
    int64_t* okey = T->hkey;
    int* oval = T->hval;
    int64_t ocap = T->hcap;
    T->hkey = nkey;
    T->hval = nval;
    T->hcap = ncap;
    for (int64_t j = 0; j < ocap; j++) {
      if (okey[j] == -1) continue;
      int64_t slot = hash_slot(T, okey[j]);
      T->hkey[slot] = okey[j];
      T->hval[slot] = oval[j];
    }
    vd_free(okey, (size_t)ocap * sizeof *okey);
    vd_free(oval, (size_t)ocap * sizeof *oval);
  }
  int64_t slot = hash_slot(T, key);
  T->hkey[slot] = key;
  T->hval[slot] = val;
  T->hcount++;
  return 1;
}

// add (module, instance) unless present
static int hash_note(turtle* T, int64_t module, int instance) {
  if (T->hcap && T->hkey[hash_slot(T, module)] == module) return 1;
  return hash_put(T, module, instance);
}

// Switch to the table: fill it from the elements this run has already added.
static int hash_start(turtle* T) {
  const vd_plant_spec* P = T->plant;
  for (int k = T->seg0; k < P->nseg; k++)
    if (!hash_note(T, P->seg[k].module, P->seg[k].instance)) return 0;
  for (int k = T->sphere0; k < P->nsphere; k++)
    if (!hash_note(T, P->sphere[k].module, P->sphere[k].instance)) return 0;
  for (int k = T->mesh0; k < P->nmesh; k++)
    if (!hash_note(T, P->mesh[k].module, P->mesh[k].instance)) return 0;
  T->hashed = 1;
  return 1;
}

// Instance id of a producing module, handing out the next id on its first drawing. While
// modules arrive in increasing order (the usual case) no table is needed.
static vd_status instance_of(turtle* T, int64_t module, int* out) {
  if (module == T->last_module) {
    *out = T->last_instance;
    return VD_OK;
  }
  int inst = 0;
  if (!T->hashed && module > T->max_module) {
    inst = ++T->ninst;
  } else {
    if (!T->hashed && !hash_start(T)) return nomem(T);
    int64_t slot = T->hcap ? hash_slot(T, module) : -1;
    if (slot >= 0 && T->hkey[slot] == module) {
      inst = T->hval[slot];
    } else {
      inst = ++T->ninst;
      if (!hash_put(T, module, inst)) return nomem(T);
    }
  }
  if (module > T->max_module) T->max_module = module;
  T->last_module = module;
  T->last_instance = inst;
  *out = inst;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// frame rotations

// make H, L, U orthonormal again (Gram-Schmidt from H, then L = U x H)
static void reorthonormalize(tstate* t) {
  t->h = vd_normalize(t->h);
  t->u = vd_normalize(vd_madd(t->u, t->h, -vd_dot(t->u, t->h)));
  t->l = vd_cross(t->u, t->h);
}

static void count_rotation(turtle* T) {
  if (++T->nrot >= REORTHO_EVERY) {
    reorthonormalize(&T->t);
    T->nrot = 0;
  }
}

// sine and cosine of an angle in degrees, cached for repeated angles
static void sincos_deg(turtle* T, double deg, double* s, double* c) {
  if (deg != T->c_deg) {
    double r = deg * (VD_PI / 180.0);
    T->c_deg = deg;
    T->c_sin = sin(r);
    T->c_cos = cos(r);
  }
  *s = T->c_sin;
  *c = T->c_cos;
}

// rotate the pair (a, b) in their plane so that a turns toward b
static void rot2(vd_vec3* a, vd_vec3* b, double s, double c) {
  vd_vec3 na = vd_add(vd_scale(*a, c), vd_scale(*b, s));
  vd_vec3 nb = vd_sub(vd_scale(*b, c), vd_scale(*a, s));
  *a = na;
  *b = nb;
}

// + : turn about U, H toward L (degrees)
static void turn_left(turtle* T, double deg) {
  double s, c;
  sincos_deg(T, deg, &s, &c);
  rot2(&T->t.h, &T->t.l, s, c);
  count_rotation(T);
}

// & : pitch about L, H toward -U (degrees)
static void pitch_down(turtle* T, double deg) {
  double s, c;
  sincos_deg(T, deg, &s, &c);
  rot2(&T->t.u, &T->t.h, s, c);
  count_rotation(T);
}

// / : roll about H, L toward U (degrees)
static void roll_left(turtle* T, double deg) {
  double s, c;
  sincos_deg(T, deg, &s, &c);
  rot2(&T->t.l, &T->t.u, s, c);
  count_rotation(T);
}

// | : half turn about U (exact)
static void turn_around(tstate* t) {
  t->h = vd_scale(t->h, -1);
  t->l = vd_scale(t->l, -1);
}

// rotate the whole frame about a unit axis (radians)
static void rotate_frame(turtle* T, vd_vec3 axis, double ang) {
  T->t.h = vd_rotate(T->t.h, axis, ang);
  T->t.l = vd_rotate(T->t.l, axis, ang);
  T->t.u = vd_rotate(T->t.u, axis, ang);
  count_rotation(T);
}

// Turn H toward the unit direction d by strength x the angle between them, about H x d
// (PlantGL's Turtle::_tendTo; a direction opposite to H turns about U).
static void tend_to(turtle* T, vd_vec3 d, double strength) {
  vd_vec3 cp = vd_cross(T->t.h, d);
  double s = vd_norm(cp), c = vd_dot(T->t.h, d);
  if (s > EPS)
    rotate_frame(T, vd_scale(cp, 1.0 / s), atan2(s, c) * strength);
  else if (c < EPS)
    rotate_frame(T, T->t.u, VD_PI * strength);
}

// L-Py's tropism before a move: H turns toward T by elasticity x angle(H, T)
static void apply_tropism(turtle* T) {
  if (T->t.elasticity > EPS && (T->t.tropism.x != 0 || T->t.tropism.y != 0 || T->t.tropism.z != 0))
    tend_to(T, T->t.tropism, T->t.elasticity);
}

// set H and U (normalised; U re-orthogonalised against H); L = U x H
static vd_status set_head(turtle* T, vd_vec3 h, vd_vec3 u) {
  h = vd_normalize(h);
  u = vd_normalize(u);
  vd_vec3 l = vd_cross(u, h);
  double n = vd_norm(l);
  if (n < 1e-9) return fail(T, VD_ERR_VALUE, "heading and up are colinear");
  T->t.h = h;
  T->t.l = vd_scale(l, 1.0 / n);
  T->t.u = vd_cross(T->t.h, T->t.l);
  T->nrot = 0;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// geometry output

// move to p; the next segment starts a new node unless p is where we were
static void move_to(tstate* t, vd_vec3 p) {
  if (p.x != t->pos.x || p.y != t->pos.y || p.z != t->pos.z) t->node = -1;
  t->pos = p;
}

// record the position as a polygon point
static vd_status poly_push(turtle* T) {
  if (!vd_grow((void**)&T->poly, &T->cap_poly, T->npoly + 1, sizeof *T->poly)) return nomem(T);
  T->poly[T->npoly++] = T->t.pos;
  return VD_OK;
}

// Draw a frustum from the position to end (radii already scaled) and move there.
static vd_status add_segment(turtle* T, vd_vec3 end, double r0, double r1, int label) {
  tstate* t = &T->t;
  vd_plant_spec* P = T->plant;
  // the start node is the current one, or a new node where a move left us
  int n0 = t->node;
  if (n0 < 0 && (n0 = vd_plant_add_node(P, t->pos)) < 0) return nomem(T);
  int n1 = vd_plant_add_node(P, end);
  if (n1 < 0) return nomem(T);
  // the first segment inside a [ creates the branch's axis
  if (t->pending) {
    t->axis = T->next_axis++;
    t->order++;
    t->pending = 0;
  }
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = n0;
  g.node1 = n1;
  g.r0 = r0;
  g.r1 = r1;
  g.up = t->u;
  g.parent = t->parent;
  g.label = label;
  g.module = module_of(T, T->i);
  vd_status st = instance_of(T, g.module, &g.instance);
  if (st) return st;
  g.axis = t->axis;
  g.order = t->order;
  g.slices = t->slices;
  g.age = t->age;
  // inside @Gc..@Ge a segment continuing the previous one of the tube joins it smoothly
  if (t->gc && t->gc_prev >= 0 && t->parent == t->gc_prev && n0 == P->seg[t->gc_prev].node1)
    g.flags |= VD_SEG_GC;
  int k = vd_plant_add_segment(P, &g);
  if (k < 0) return nomem(T);
  t->parent = k;
  t->tail = k;
  if (t->gc) t->gc_prev = k;
  t->node = n1;
  t->pos = end;
  return VD_OK;
}

// Append a mesh from the scratch buffers (nv vertices, nt triangles).
static vd_status add_mesh(turtle* T, int nv, int nt, int closed, int label, int64_t module,
                          int node, int parent) {
  vd_mesh_spec m;
  memset(&m, 0, sizeof m);
  m.closed = closed;
  m.node = node;
  m.parent = parent;
  m.label = label;
  m.module = module;
  vd_status st = instance_of(T, module, &m.instance);
  if (st) return st;
  if (vd_plant_add_mesh(T->plant, &m, T->vbuf, nv, T->tbuf, nt) < 0) return nomem(T);
  return VD_OK;
}

// make room for nv vertices and nt triangles in the scratch buffers
static vd_status scratch(turtle* T, int nv, int nt) {
  if (!vd_grow((void**)&T->vbuf, &T->cap_vbuf, nv, sizeof *T->vbuf) ||
      !vd_grow((void**)&T->tbuf, &T->cap_tbuf, 3 * nt, sizeof *T->tbuf))
    return nomem(T);
  return VD_OK;
}

static void tri(int* t, int k, int a, int b, int c) {
  t[3 * k] = a;
  t[3 * k + 1] = b;
  t[3 * k + 2] = c;
}

// ---------------------------------------------------------------------------------------------
// curve-fed geometry: guides, contours, sweeps, custom shapes (PlantGL's Turtle and
// PglTurtleDrawer semantics; the objects come from the Python engine, lsys_obj_*)

#define GUIDE_SAMPLES 512  // samples of a guide at equal steps of arc length (linear between)

// the run's data for object parameter k of the current module (fetched once); -1 on error
static int get_curve(turtle* T, int k, int kind, int* out) {
  double key = T->p[k];
  uint64_t kb, cb;
  memcpy(&kb, &key, sizeof kb);
  for (int c = 0; c < T->ncur; c++) {
    memcpy(&cb, &T->cur[c].key, sizeof cb);
    if (T->cur[c].kind == kind && cb == kb) {
      *out = c;
      return VD_OK;
    }
  }
  if (!vd_grow((void**)&T->cur, &T->cap_cur, T->ncur + 1, sizeof *T->cur)) return nomem(T);
  tcurve* c = &T->cur[T->ncur];
  memset(c, 0, sizeof *c);
  c->key = key;
  c->kind = kind;
  char why[256] = "";
  vd_status st;
  if (kind == CUR_POINTS) {
    st = lsys_obj_points(T->ls, key, &c->p, &c->n, &c->dim, why, sizeof why);
    if (!st) {
      double d = 0;
      for (int q = 0; q < c->dim; q++) d += fabs(c->p[q] - c->p[(c->n - 1) * c->dim + q]);
      c->closed = d < 1e-10;
    }
  } else if (kind == CUR_GUIDE) {
    c->n = GUIDE_SAMPLES + 1;
    st = lsys_obj_guide(T->ls, key, GUIDE_SAMPLES, &c->length, &c->p, &c->tan, &c->nrm, &c->dim, why, sizeof why);
  } else {
    st = lsys_obj_function(T->ls, key, &c->length, &c->lastx, &c->p, &c->n, why, sizeof why);
    c->dim = 1;
  }
  if (st)
    return fail(T, st, "parameter %d is not a %s (%s)", k + 1,
                kind == CUR_FUNC ? "function" : "curve", why);
  *out = T->ncur++;
  return VD_OK;
}

// point and unit tangent of a guide curve at normalised arc length s in [0, 1]
static void guide_at(const tcurve* c, double s, vd_vec3* p, vd_vec3* tan) {
  double x = fmin(fmax(s, 0), 1) * (c->n - 1);
  int i = (int)x;
  if (i >= c->n - 1) i = c->n - 2;
  double w = x - i;
  double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
  for (int q = 0; q < c->dim; q++) {
    a[q] = c->p[i * c->dim + q] * (1 - w) + c->p[(i + 1) * c->dim + q] * w;
    b[q] = c->tan[i * c->dim + q] * (1 - w) + c->tan[(i + 1) * c->dim + q] * w;
  }
  *p = vd_v3(a[0], a[1], a[2]);
  *tan = vd_v3(b[0], b[1], b[2]);
}

// the guide state of the current path, made its own (a branch copies its parent's)
static tguide* own_guide(turtle* T) {
  tstate* t = &T->t;
  if (t->guide < t->gst_top) {
    if (!vd_grow((void**)&T->gst, &T->cap_gst, T->ngst + 1, sizeof *T->gst)) return NULL;
    T->gst[T->ngst] = T->gst[t->guide];
    t->guide = T->ngst++;
  }
  return &T->gst[t->guide];
}

// SetGuide(curve, length[, yorientation, ccw]): follow curve over the next length (Turtle2DPath,
// Turtle3DPath: start at the curve's start, heading (1,0) or (0,1) in 2D, (0,0,1) in 3D)
static vd_status set_guide(turtle* T, int k, double length, int yorient, int ccw) {
  int c = -1;
  vd_status st = get_curve(T, k, CUR_GUIDE, &c);
  if (st) return st;
  if (!(length > 0) || !isfinite(length)) return fail(T, VD_ERR_VALUE, "guide length %g must be positive", length);
  if (!vd_grow((void**)&T->gst, &T->cap_gst, T->ngst + 1, sizeof *T->gst)) return nomem(T);
  tguide* g = &T->gst[T->ngst];
  memset(g, 0, sizeof *g);
  g->curve = c;
  g->yorient = yorient;
  g->ccw = ccw;
  g->total = length;
  g->scale = length / T->cur[c].length;
  vd_vec3 tan;
  guide_at(&T->cur[c], 0, &g->pos, &tan);
  if (T->cur[c].dim == 2) {
    g->h = yorient ? vd_v3(0, ccw ? -1 : 1, 0) : vd_v3(ccw ? -1 : 1, 0, 0);
  } else {
    g->h = vd_v3(0, 0, 1);
    g->u = vd_v3(1, 0, 0);
    g->l = vd_v3(0, -1, 0);
  }
  T->t.guide = T->ngst++;
  return VD_OK;
}

// PositionOnGuide(t): jump to length t along the guide (TurtlePath::setPosition)
static vd_status position_on_guide(turtle* T, double at) {
  if (T->t.guide < 0) {
    vd_log(1, "turtle: module %lld 'PositionOnGuide' without a guide; ignored", (long long)T->i);
    return VD_OK;
  }
  tguide* g = own_guide(T);
  if (!g) return nomem(T);
  const tcurve* c = &T->cur[g->curve];
  g->t = fmin(fmax(at / g->total, 0), 1);
  vd_vec3 tan;
  guide_at(c, g->t, &g->pos, &tan);
  g->h = vd_normalize(tan);
  if (c->dim == 3) {
    double x = g->t * (c->n - 1);
    int i = (int)fmin(x, c->n - 1);
    g->u = vd_normalize(vd_v3(c->nrm[3 * i], c->nrm[3 * i + 1], c->nrm[3 * i + 2]));
    g->l = vd_normalize(vd_cross(g->u, g->h));
  }
  return VD_OK;
}

// signed angle from a to b in the x, y plane
static double angle2(vd_vec3 a, vd_vec3 b) { return atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y); }

// Follow the guide over a move of *l (Turtle::_applyGuide): the heading turns toward the next
// point of the curve and *l becomes the chord to it; *l = 0 only turns to the local tangent.
static void apply_guide(turtle* T, double* l) {
  tstate* t = &T->t;
  if (t->guide < 0) return;
  int local = fabs(*l) < EPS;
  if (T->gst[t->guide].t >= 1.0 && !local) {
    t->guide = -1;  // the guide is used up
    return;
  }
  tguide* g = own_guide(T);
  if (!g) return;
  const tcurve* c = &T->cur[g->curve];
  double cur = g->t;
  vd_vec3 tangent, p;
  if (local) {
    guide_at(c, cur, &p, &tangent);
  } else {
    double next = cur + *l / g->total, rem = next - 1.0;
    if (rem > EPS) next = 1.0;
    vd_vec3 nextpos, endtan;
    guide_at(c, next, &nextpos, &endtan);
    vd_vec3 offset = vd_v3(0, 0, 0);
    if (rem > EPS) offset = vd_scale(vd_normalize(endtan), rem * c->length);
    tangent = vd_sub(vd_add(nextpos, offset), g->pos);
    double n = vd_norm(tangent);
    *l = n * g->scale;
    if (n > 0) tangent = vd_scale(tangent, 1.0 / n);
    g->pos = nextpos;
    g->t = next;
  }
  if (c->dim == 2) {
    double dev = angle2(g->h, tangent);
    if (g->ccw) dev = -dev;
    if (!g->yorient) {
      t->h = vd_rotate(t->h, t->l, -dev);
      t->u = vd_rotate(t->u, t->l, -dev);
    } else {
      t->h = vd_rotate(t->h, t->u, dev);
      t->l = vd_rotate(t->l, t->u, dev);
    }
    count_rotation(T);
    g->h = tangent;
    return;
  }
  // 3D: the tangent in the curve's last frame, turned into the turtle's frame
  vd_vec3 pt = vd_v3(vd_dot(tangent, g->h), vd_dot(tangent, g->l), vd_dot(tangent, g->u));
  vd_vec3 d = vd_normalize(vd_add(vd_add(vd_scale(t->h, pt.x), vd_scale(t->l, pt.y)), vd_scale(t->u, pt.z)));
  vd_vec3 cp = vd_cross(t->h, d), cp2 = vd_cross(g->h, tangent);
  double sn = vd_norm(cp);
  if (sn > EPS) {
    double ang = atan2(sn, vd_dot(t->h, d));
    rotate_frame(T, vd_scale(cp, 1.0 / sn), ang);
    if (vd_norm(cp2) > EPS) {
      vd_vec3 ax = vd_normalize(cp2);
      g->l = vd_normalize(vd_rotate(g->l, ax, ang));
      g->u = vd_normalize(vd_rotate(g->u, ax, ang));
    }
  }
  g->h = vd_norm(tangent) > 0 ? vd_normalize(tangent) : g->h;
}

// a contour's point k as (x along L, y along U)
static void contour_xy(const tcurve* c, int k, double* x, double* y) {
  *x = c->p[k * c->dim];
  *y = c->p[k * c->dim + 1];
}

// A tube through path points p[0..n) with frames (left l, radius r) and a contour: rings of the
// contour (x along the frame's left, y along tangent x left), joined by triangles; the face
// orientation follows ccw (PlantGL's Extrusion, with the rotation-minimising frame it builds
// from the first left). The contour's closing point is not repeated.
static vd_status sweep_mesh(turtle* T, const tgcp* path, int n, const tcurve* c, int ccw, int label) {
  int m = c->closed ? c->n - 1 : c->n;
  if (n < 2 || m < 2) return VD_OK;
  int nt = (n - 1) * (c->closed ? m : m - 1) * 2;
  vd_status st = scratch(T, n * m, nt);
  if (st) return st;
  vd_vec3 prev_t = vd_v3(0, 0, 0), nrm = path[0].l;
  int k = 0;
  for (int i = 0; i < n; i++) {
    // the tangent at a path point: the mean of its two chords (PlantGL's Polyline tangent)
    vd_vec3 a = i > 0 ? vd_normalize(vd_sub(path[i].p, path[i - 1].p)) : vd_v3(0, 0, 0);
    vd_vec3 b = i + 1 < n ? vd_normalize(vd_sub(path[i + 1].p, path[i].p)) : vd_v3(0, 0, 0);
    vd_vec3 tg = vd_add(a, b);
    tg = vd_norm(tg) > EPS ? vd_normalize(tg) : (i > 0 ? a : b);
    if (i == 0) {
      nrm = vd_sub(nrm, vd_scale(tg, vd_dot(nrm, tg)));
    } else {
      // carry the frame along: the rotation that takes the last tangent to this one
      vd_vec3 ax = vd_cross(prev_t, tg);
      double sn = vd_norm(ax);
      if (sn > EPS) nrm = vd_rotate(nrm, vd_scale(ax, 1.0 / sn), atan2(sn, vd_dot(prev_t, tg)));
      nrm = vd_sub(nrm, vd_scale(tg, vd_dot(nrm, tg)));
    }
    if (vd_norm(nrm) < EPS) nrm = fabs(tg.z) < 0.9 ? vd_cross(tg, vd_v3(0, 0, 1)) : vd_cross(tg, vd_v3(1, 0, 0));
    nrm = vd_normalize(nrm);
    vd_vec3 bin = vd_cross(tg, nrm);
    prev_t = tg;
    for (int j = 0; j < m; j++) {
      double x, y;
      contour_xy(c, j, &x, &y);
      T->vbuf[i * m + j] = vd_add(path[i].p, vd_add(vd_scale(nrm, x * path[i].r), vd_scale(bin, y * path[i].r)));
    }
  }
  for (int i = 0; i + 1 < n; i++)
    for (int j = 0; j < (c->closed ? m : m - 1); j++) {
      int j1 = (j + 1) % m;
      int a = i * m + j, b = i * m + j1, d = (i + 1) * m + j, e = (i + 1) * m + j1;
      if (ccw) {
        tri(T->tbuf, k++, a, b, e);
        tri(T->tbuf, k++, a, e, d);
      } else {
        tri(T->tbuf, k++, a, e, b);
        tri(T->tbuf, k++, a, d, e);
      }
    }
  // an open tube: a thin surface, as PlantGL draws it (no caps)
  return add_mesh(T, n * m, k, 0, label, module_of(T, T->i), T->t.node, T->t.parent);
}

// F with a contour (PglTurtleDrawer::smallSweep): the contour swept from the position to end
static vd_status contour_segment(turtle* T, vd_vec3 end, double r0, double r1, int label) {
  tstate* t = &T->t;
  tgcp path[2] = {{t->pos, t->l, r0}, {end, t->l, r1}};
  vd_status st = sweep_mesh(T, path, 2, &T->cur[t->contour], t->contour_ccw, label);
  if (st) return st;
  move_to(t, end);
  return VD_OK;
}

// record a point of the tube's path (TurtleParam::pushPosition)
static vd_status gc_record(turtle* T) {
  tstate* t = &T->t;
  if (t->gcp_start + t->gcp_n != T->ngcp) {
    // the path continues in a branch: copy it to the top of the stack first
    if (!vd_grow((void**)&T->gcp, &T->cap_gcp, T->ngcp + t->gcp_n + 1, sizeof *T->gcp)) return nomem(T);
    memmove(T->gcp + T->ngcp, T->gcp + t->gcp_start, sizeof *T->gcp * (size_t)t->gcp_n);
    t->gcp_start = T->ngcp;
    T->ngcp += t->gcp_n;
  }
  if (!vd_grow((void**)&T->gcp, &T->cap_gcp, T->ngcp + 1, sizeof *T->gcp)) return nomem(T);
  T->gcp[T->ngcp++] = (tgcp){t->pos, t->l, t->width * t->scale};
  t->gcp_n++;
  return VD_OK;
}

// the width changed inside a tube: its last point takes it (TurtleParam::pushRadius)
static void gc_width(turtle* T) {
  tstate* t = &T->t;
  if (t->gc && t->gc_contour >= 0 && t->gcp_n > 0) T->gcp[t->gcp_start + t->gcp_n - 1].r = t->width * t->scale;
}

// @Ge with a contour: the tube through the recorded path (Turtle::stopGC)
static vd_status gc_end(turtle* T) {
  tstate* t = &T->t;
  vd_status st = VD_OK;
  if (t->gc && t->gc_contour >= 0 && t->gcp_n > 1)
    st = sweep_mesh(T, T->gcp + t->gcp_start, t->gcp_n, &T->cur[t->gc_contour], t->gc_ccw, t->color);
  t->gcp_n = 0;
  return st;
}

// @g(geometry[, scale]) / PglShape: the object's mesh placed in the turtle's frame (local x along
// U, y along -L, z along H, PglTurtleDrawer::transform), scaled by scale x the turtle scale
static vd_status custom_geometry(turtle* T) {
  tstate* t = &T->t;
  double sc = 1, *xyz;
  int nv, nt, closed, *tr;
  vd_status st;
  if (T->np > 1 && (st = num(T, 1, &sc))) return st;
  if (!vd_lsys_value_is_obj(T->p[0])) {
    vd_log(1, "turtle: module %lld '@g' needs a geometry object; ignored", (long long)T->i);
    return VD_OK;
  }
  char why[256] = "";
  if (lsys_obj_mesh(T->ls, T->p[0], &xyz, &nv, &tr, &nt, &closed, why, sizeof why) != VD_OK) {
    // a material or an appearance only changes colours: nothing to draw
    vd_log(1, "turtle: module %lld '@g': %s; nothing drawn", (long long)T->i, why);
    return VD_OK;
  }
  st = scratch(T, nv, nt);
  if (!st) {
    double s = sc * t->scale;
    for (int i = 0; i < nv; i++) {
      vd_vec3 q = vd_add(vd_add(vd_scale(t->u, xyz[3 * i] * s), vd_scale(t->l, -xyz[3 * i + 1] * s)),
                         vd_scale(t->h, xyz[3 * i + 2] * s));
      T->vbuf[i] = vd_add(t->pos, q);
    }
    memcpy(T->tbuf, tr, sizeof(int) * 3 * (size_t)nt);
    st = add_mesh(T, nv, nt, closed, t->color, module_of(T, T->i), t->node, t->parent);
  }
  vd_free(xyz, sizeof(double) * 3 * (size_t)nv);
  vd_free(tr, sizeof(int) * 3 * (size_t)nt);
  return st;
}

// SetContour(curve[, ccw]): the cross section of the following F and tubes
static vd_status set_contour(turtle* T, int k, int ccw) {
  int c = -1;
  vd_status st = get_curve(T, k, CUR_POINTS, &c);
  if (st) return st;
  T->t.contour = c;
  T->t.contour_ccw = ccw;
  if (T->t.gc && T->t.gcp_n <= 1) {  // set while the tube starts: it is the tube's
    T->t.gc_contour = c;
    T->t.gc_ccw = ccw;
  }
  return VD_OK;
}

// the value of a function table at x (QuantisedFunction::getValue: x clamped, linear)
static double func_at(const tcurve* c, double x) {
  double fx = c->length, lx = c->lastx;
  x = fmin(fmax(x, fx), lx);
  double idx = (c->n - 1) * (x - fx) / (lx - fx);
  int i = (int)floor(idx);
  double d = idx - i;
  if (i >= c->n - 1 || fabs(d) < 1e-12) return c->p[i < c->n ? i : c->n - 1];
  return (1 - d) * c->p[i] + d * c->p[i + 1];
}

// ---------------------------------------------------------------------------------------------
// drawing commands

// F(len, top): tropism, frustum from width to top (top < 0: cylinder), move; width := top.
// A negative length turns around, draws, and turns back (PlantGL's Turtle::F).
static vd_status draw_F(turtle* T, double len, double top, int label) {
  tstate* t = &T->t;
  double zero = 0;
  if (len > 0) {
    if (t->guide >= 0) apply_guide(T, &len);  // the move becomes the chord along the guide
    apply_tropism(T);
    if (len > EPS) {
      double r1 = top > -EPS ? fmax(top, 0) : t->width;
      vd_vec3 end = vd_madd(t->pos, t->h, len * t->scale);
      vd_status st = VD_OK;
      if (t->gc && t->gc_contour >= 0)
        move_to(t, end);  // a tube with a contour: drawn from its recorded path at @Ge
      else if (t->contour >= 0)
        st = contour_segment(T, end, t->width * t->scale, r1 * t->scale, label);
      else
        st = add_segment(T, end, t->width * t->scale, r1 * t->scale, label);
      if (st) return st;
      if (t->guide >= 0) apply_guide(T, &zero);
      if (t->gc && t->gc_contour >= 0 && (st = gc_record(T))) return st;
      if (t->polygon && (st = poly_push(T))) return st;
    } else if (t->guide >= 0) {
      apply_guide(T, &zero);
    }
    if (top > -EPS) {
      t->width = fmax(top, 0);
      gc_width(T);
    }
  } else if (len < -EPS) {
    turn_around(t);
    vd_status st = draw_F(T, -len, top, label);
    turn_around(t);
    return st;
  }
  return VD_OK;
}

// f(len): tropism and move without drawing
static void move_f(turtle* T, double len) {
  int guided = len > 0 && T->t.guide >= 0;
  if (guided) apply_guide(T, &len);
  apply_tropism(T);
  move_to(&T->t, vd_madd(T->t.pos, T->t.h, len * T->t.scale));
  double zero = 0;
  if (guided && T->t.guide >= 0) apply_guide(T, &zero);
}

// LineTo family: orient H toward target, draw exactly to it, optionally restore the frame
static vd_status line_to(turtle* T, vd_vec3 target, double top, int keep_frame) {
  tstate* t = &T->t;
  vd_vec3 d = vd_sub(target, t->pos);
  double len = vd_norm(d);
  if (len <= EPS) return VD_OK;
  vd_vec3 h = t->h, l = t->l, u = t->u;
  tend_to(T, vd_scale(d, 1.0 / len), 1.0);
  double r1 = top > -EPS ? fmax(top, 0) : t->width;
  vd_status st = add_segment(T, target, t->width * t->scale, r1 * t->scale, t->color);
  if (st) return st;
  if (t->polygon && (st = poly_push(T))) return st;
  if (top > -EPS) t->width = fmax(top, 0);
  if (keep_frame) {
    t->h = h;
    t->l = l;
    t->u = u;
  }
  return VD_OK;
}

// nF(len, dl[, radius[, radius law]]): F(dl) repeated, plus the remainder; the radius goes
// linearly to radius, or follows radius x the law (a function over its x range, Turtle::nF)
static vd_status run_nF(turtle* T, double len, double dl, double radius, int law) {
  vd_status st;
  if (dl <= 0) return fail(T, VD_ERR_VALUE, "step %g must be positive", dl);
  double nsteps = floor(len / dl);
  if (nsteps > NF_MAX_STEPS) return fail(T, VD_ERR_LIMIT, "%g steps is too many", nsteps);
  double delta = len - nsteps * dl;
  int n = (int)nsteps, label = T->t.color;
  if (law >= 0 && len > 0) {
    const tcurve* f = &T->cur[law];
    double u = f->length, du = (dl / len) * (f->lastx - f->length);
    T->t.width = fmax(func_at(f, u) * radius, 0);
    gc_width(T);
    for (int k = 1; k <= n; k++) {
      u += du;
      if ((st = draw_F(T, dl, fmax(func_at(f, u) * radius, 0), label))) return st;
    }
    if (delta > EPS) return draw_F(T, delta, fmax(radius * func_at(f, f->lastx), 0), label);
    return VD_OK;
  }
  if (radius < 0) {
    for (int k = 0; k < n; k++)
      if ((st = draw_F(T, dl, -1, label))) return st;
    if (delta > EPS) return draw_F(T, delta, -1, label);
    return VD_OK;
  }
  double w = T->t.width, dw = len > 0 ? (radius - w) / len : 0;
  for (int k = 1; k <= n; k++)
    if ((st = draw_F(T, dl, w + dw * dl * k, label))) return st;
  if (delta > EPS) return draw_F(T, delta, radius, label);
  return VD_OK;
}

static vd_status draw_nF(turtle* T) {
  double len, dl, radius = -1;
  vd_status st;
  int law = -1;
  if (T->np < 2) {
    vd_log(1, "turtle: module %lld 'nF' needs length and step; ignored", (long long)T->i);
    return VD_OK;
  }
  if ((st = nonneg_or(T, 0, 0, "length", &len)) || (st = num(T, 1, &dl))) return st;
  if (T->np >= 3 && (st = nonneg_or(T, 2, 0, "radius", &radius))) return st;
  if (T->np >= 4 && vd_lsys_value_is_obj(T->p[3]) && (st = get_curve(T, 3, CUR_FUNC, &law))) return st;
  if (T->np >= 4 && law < 0) vd_log(1, "turtle: nF radius law is not a function (linear radius used)");
  return run_nF(T, len, dl, radius, law);
}

// @O(r): sphere at the position
static vd_status draw_sphere(turtle* T) {
  double r;
  int label;
  vd_status st;
  if ((st = max_params(T, 2)) || (st = num_or(T, 0, T->t.width, &r)) || (st = label_at(T, 1, &label)))
    return st;
  if (negative_ignored(T, 0, r, WARN_RADIUS) || r <= EPS) return VD_OK;
  vd_sphere_spec g = vd_sphere_spec_default();
  g.center = T->t.pos;
  g.radius = r * T->t.scale;
  g.node = T->t.node;
  g.parent = T->t.parent;
  g.label = label;
  g.slices = T->t.slices;
  g.module = module_of(T, T->i);
  if ((st = instance_of(T, g.module, &g.instance))) return st;
  if (vd_plant_add_sphere(T->plant, &g) < 0) return nomem(T);
  return VD_OK;
}

// @o(r): disc centred at the position in the plane of H and L (normal U, as PlantGL's Disc)
static vd_status draw_disc(turtle* T) {
  double r;
  int label;
  vd_status st;
  if ((st = max_params(T, 2)) || (st = num_or(T, 0, T->t.width, &r)) || (st = label_at(T, 1, &label)))
    return st;
  if (negative_ignored(T, 0, r, WARN_RADIUS) || r <= EPS) return VD_OK;
  const tstate* t = &T->t;
  int n = t->slices;
  if ((st = scratch(T, n + 1, n))) return st;
  // fan around the centre, counter-clockwise about U; rim point k at -cos(a) H - sin(a) L, where
  // PlantGL's Disc (x = cos, y = sin in its plane) lands after the turtle's orientation
  double rs = -r * t->scale;
  T->vbuf[0] = t->pos;
  for (int k = 0; k < n; k++) {
    double a = 2.0 * VD_PI * k / n;
    T->vbuf[1 + k] =
        vd_add(t->pos, vd_add(vd_scale(t->h, rs * cos(a)), vd_scale(t->l, rs * sin(a))));
    tri(T->tbuf, k, 0, 1 + k, 1 + (k + 1) % n);
  }
  return add_mesh(T, n + 1, n, 0, label, module_of(T, T->i), t->node, t->parent);
}

// @B(len, top) box / @b(len, top) quad: along H from the position, half-width = width at the
// base and top at the end; tropism first, then the turtle moves and width := top. A negative
// length turns around, draws, and turns back (PlantGL's Turtle::box and Turtle::quad).
static vd_status box_quad(turtle* T, double len, double top, int label, int box) {
  tstate* t = &T->t;
  if (len < -EPS) {
    turn_around(t);
    vd_status st = box_quad(T, -len, top, label, box);
    turn_around(t);
    return st;
  }
  if (len <= 0) return VD_OK;
  apply_tropism(T);
  double b = t->width * t->scale, e = top * t->scale, l = len * t->scale;
  vd_vec3 p0 = t->pos, p1 = vd_madd(t->pos, t->h, l);
  int nv = 0, nt = 0;
  vd_status st = scratch(T, 8, 12);
  if (st) return st;
  if (box && (b > EPS || e > EPS)) {
    // corners in (L, U): (-,-) (+,-) (+,+) (-,+), base then top; 12 outward triangles
    static const double cx[4] = {-1, 1, 1, -1}, cy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; k++) {
      T->vbuf[k] = vd_add(p0, vd_add(vd_scale(t->l, cx[k] * b), vd_scale(t->u, cy[k] * b)));
      T->vbuf[4 + k] = vd_add(p1, vd_add(vd_scale(t->l, cx[k] * e), vd_scale(t->u, cy[k] * e)));
    }
    tri(T->tbuf, 0, 0, 2, 1);
    tri(T->tbuf, 1, 0, 3, 2);
    tri(T->tbuf, 2, 4, 5, 6);
    tri(T->tbuf, 3, 4, 6, 7);
    for (int k = 0; k < 4; k++) {
      int j = (k + 1) % 4;
      tri(T->tbuf, 4 + 2 * k, k, j, j + 4);
      tri(T->tbuf, 5 + 2 * k, k, j + 4, k + 4);
    }
    nv = 8;
    nt = 12;
  } else if (!box && (b > EPS || e > EPS)) {
    // PlantGL's quad: base +L, base -L, top -L, top +L (one point where a radius is 0)
    if (b > EPS) {
      T->vbuf[nv++] = vd_madd(p0, t->l, b);
      T->vbuf[nv++] = vd_madd(p0, t->l, -b);
    } else {
      T->vbuf[nv++] = p0;
    }
    if (e > EPS) {
      T->vbuf[nv++] = vd_madd(p1, t->l, -e);
      T->vbuf[nv++] = vd_madd(p1, t->l, e);
    } else {
      T->vbuf[nv++] = p1;
    }
    tri(T->tbuf, nt++, 0, 1, 2);
    if (nv == 4) tri(T->tbuf, nt++, 0, 2, 3);
  }
  if (nv && l > EPS &&
      (st = add_mesh(T, nv, nt, box, label, module_of(T, T->i), t->node, t->parent)))
    return st;
  move_to(t, p1);
  t->width = top;
  return VD_OK;
}

// @B / @b parameters: length (step), top radius (width; negative = width), label
static vd_status draw_box_quad(turtle* T, int box) {
  double len, top;
  int label;
  vd_status st;
  if ((st = max_params(T, 3)) || (st = num_or(T, 0, T->def.step, &len)) ||
      (st = num_or(T, 1, T->t.width, &top)) || (st = label_at(T, 2, &label)))
    return st;
  if (T->np > 1 && negative_ignored(T, 1, top, WARN_RADIUS)) top = T->t.width;
  return box_quad(T, len, top, label, box);
}

// ~l(s): PlantGL's predefined leaf, a flat hexagon of length s along H, s/2 wide along L,
// six triangles around its centre (normal U). Parameters start at k0.
static vd_status draw_leaf(turtle* T, int k0) {
  double s;
  int label;
  vd_status st;
  if ((st = max_params(T, k0 + 2)) || (st = nonneg_or(T, k0, 1, "scale", &s)) ||
      (st = label_at(T, k0 + 1, &label)))
    return st;
  if (s <= EPS) return VD_OK;
  const tstate* t = &T->t;
  // points as (along H, along L): centre, base, three on each side, tip
  static const double ph[7] = {0.5, 0, 1.0 / 3, 2.0 / 3, 1, 2.0 / 3, 1.0 / 3};
  static const double pl[7] = {0, 0, 0.25, 0.25, 0, -0.25, -0.25};
  static const int tris[18] = {0, 2, 1, 0, 3, 2, 0, 4, 3, 0, 5, 4, 0, 6, 5, 0, 1, 6};
  if ((st = scratch(T, 7, 6))) return st;
  double k = s * t->scale;
  for (int j = 0; j < 7; j++)
    T->vbuf[j] = vd_add(t->pos, vd_add(vd_scale(t->h, ph[j] * k), vd_scale(t->l, pl[j] * k)));
  memcpy(T->tbuf, tris, sizeof tris);
  return add_mesh(T, 7, 6, 0, label, module_of(T, T->i), t->node, t->parent);
}

// ---------------------------------------------------------------------------------------------
// polygons

// twice the area of triangle abc (3D)
static double tri_area2(vd_vec3 a, vd_vec3 b, vd_vec3 c) {
  return vd_norm(vd_cross(vd_sub(b, a), vd_sub(c, a)));
}

// fan from point 0, skipping degenerate triangles; returns the triangle count
static int fan(const vd_vec3* p, int n, int* t) {
  int nt = 0;
  for (int k = 1; k + 1 < n; k++)
    if (tri_area2(p[0], p[k], p[k + 1]) > EPS * EPS) tri(t, nt++, 0, k, k + 1);
  return nt;
}

// Ear clipping in the polygon's best-fit plane (Newell normal); concave polygons come out
// right, self-intersecting ones fall back to a fan of what is left.
static int ear_clip(turtle* T, const vd_vec3* p, int n, int* t) {
  // plane basis with e1 x e2 = n, so the polygon runs counter-clockwise in (e1, e2)
  vd_vec3 nrm = vd_v3(0, 0, 0);
  for (int k = 0; k < n; k++) {
    vd_vec3 a = p[k], b = p[(k + 1) % n];
    nrm = vd_add(nrm, vd_v3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                            (a.x - b.x) * (a.y + b.y)));
  }
  if (vd_norm(nrm) < EPS * EPS) return fan(p, n, t);
  nrm = vd_normalize(nrm);
  vd_vec3 e1 = fabs(nrm.x) < 0.9 ? vd_v3(1, 0, 0) : vd_v3(0, 1, 0);
  e1 = vd_normalize(vd_sub(e1, vd_scale(nrm, vd_dot(e1, nrm))));
  vd_vec3 e2 = vd_cross(nrm, e1);
  int* v = T->ibuf;
  for (int k = 0; k < n; k++)
    v[k] = k;
  int m = n, nt = 0;
#define PX(k) vd_dot(p[k], e1)
#define PY(k) vd_dot(p[k], e2)
  while (m > 3) {
    int found = 0;
    for (int k = 0; k < m && !found; k++) {
      int a = v[(k + m - 1) % m], b = v[k], c = v[(k + 1) % m];
      double ax = PX(a), ay = PY(a), bx = PX(b), by = PY(b), cx = PX(c), cy = PY(c);
      double cr = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
      if (cr <= 0) continue; // reflex or flat corner
      // no other vertex inside or on the triangle
      int inside = 0;
      for (int j = 0; j < m && !inside; j++) {
        int q = v[j];
        if (q == a || q == b || q == c) continue;
        double qx = PX(q), qy = PY(q);
        double d1 = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax);
        double d2 = (cx - bx) * (qy - by) - (cy - by) * (qx - bx);
        double d3 = (ax - cx) * (qy - cy) - (ay - cy) * (qx - cx);
        inside = d1 >= 0 && d2 >= 0 && d3 >= 0;
      }
      if (inside) continue;
      tri(t, nt++, a, b, c);
      memmove(v + k, v + k + 1, (size_t)(m - k - 1) * sizeof *v);
      m--;
      found = 1;
    }
    if (!found) break;
  }
#undef PX
#undef PY
  // the last triangle, or a fan over a remainder with no ear
  for (int k = 1; k + 1 < m; k++)
    if (tri_area2(p[v[0]], p[v[k]], p[v[k + 1]]) > EPS * EPS) tri(t, nt++, v[0], v[k], v[k + 1]);
  return nt;
}

// }(concave): close the recorded polygon into a thin mesh (PlantGL drops a last point equal to
// the first; concave = 1 asks for ear clipping instead of a fan)
static vd_status end_polygon(turtle* T) {
  int concave = T->np > 0 && T->p[0] != 0 && !isnan(T->p[0]);
  int n = T->npoly;
  T->t.polygon = 0;
  T->npoly = 0;
  if (n > 1 && vd_norm(vd_sub(T->poly[n - 1], T->poly[0])) < EPS) n--;
  if (n < 3) return VD_OK;
  vd_status st = scratch(T, n, n - 2);
  if (st) return st;
  if (!vd_grow((void**)&T->ibuf, &T->cap_ibuf, n, sizeof *T->ibuf)) return nomem(T);
  memcpy(T->vbuf, T->poly, (size_t)n * sizeof *T->poly);
  int nt = concave ? ear_clip(T, T->vbuf, n, T->tbuf) : fan(T->vbuf, n, T->tbuf);
  if (nt == 0) return VD_OK;
  return add_mesh(T, n, nt, 0, T->poly_label, T->poly_module, T->poly_node, T->poly_parent);
}

// ---------------------------------------------------------------------------------------------
// state commands

// set the colour (label); inside a polygon it is also the polygon's label (PlantGL)
static void set_color(turtle* T, int c) {
  T->t.color = c;
  if (T->t.polygon) T->poly_label = c;
}

// ] : an axis ends; mark its last segment as a tip and restore the saved state
static void end_axis(turtle* T, const tstate* t) {
  if (!t->pending && t->tail >= 0) T->plant->seg[t->tail].flags |= VD_SEG_TIP;
}

// the angle parameter in degrees (default: the def's angle)
static vd_status angle_arg(turtle* T, double* deg) {
  return num_or(T, 0, T->def.angle, deg);
}

// a vector from parameter *k on: one vector object (Vector3 or a 3-tuple of the Python engine,
// as L-Py's turtle takes) or up to three numbers (missing ones from dflt); *k moves past them
static vd_status vec_at(turtle* T, int* k, vd_vec3 dflt, vd_vec3* out) {
  vd_status st;
  if (*k < T->np && vd_lsys_value_is_obj(T->p[*k])) {
    char why[200];
    double c[3];
    if (lsys_obj_vec3(T->ls, T->p[*k], c, why, sizeof why) != VD_OK)
      return fail(T, VD_ERR_TYPE, "parameter %d: expected a number or a 3D vector, got %s", *k + 1, why);
    *out = vd_v3(c[0], c[1], c[2]);
    (*k)++;
    return VD_OK;
  }
  if ((st = num_or(T, *k, dflt.x, &out->x)) || (st = num_or(T, *k + 1, dflt.y, &out->y)) ||
      (st = num_or(T, *k + 2, dflt.z, &out->z)))
    return st;
  *k += 3;
  return VD_OK;
}

static vd_status vec_args(turtle* T, int k, vd_vec3 dflt, vd_vec3* out) {
  return vec_at(T, &k, dflt, out);
}

// @v(alpha): roll about H so that U comes closest to vertical (PlantGL rollToVert)
static void roll_to_vert(turtle* T, double alpha) {
  tstate* t = &T->t;
  if (alpha <= 0) return;
  vd_vec3 nl = vd_cross(vd_v3(0, 0, 1), t->h);
  double n = vd_norm(nl);
  if (alpha >= 1) {
    t->l = n < EPS ? vd_v3(0, -1, 0) : vd_scale(nl, 1.0 / n);
    t->u = vd_cross(t->h, t->l);
    return;
  }
  if (n < EPS) return;
  // part of the way: roll by alpha x the signed angle from L to the target left
  nl = vd_scale(nl, 1.0 / n);
  double ang = atan2(vd_dot(vd_cross(t->l, nl), t->h), vd_dot(t->l, nl));
  roll_left(T, alpha * ang * (180.0 / VD_PI));
}

// @h(alpha): turn the frame so that H comes into the horizontal plane (PlantGL
// rollToHorizontal)
static void roll_to_horizontal(turtle* T, double alpha) {
  tstate* t = &T->t;
  if (alpha <= 0) return;
  if (alpha > 1) alpha = 1;
  double z = t->h.z;
  if (fabs(z) <= EPS) return;
  vd_vec3 target = vd_v3(t->h.x, t->h.y, 0);
  if (vd_norm(target) < EPS) target = vd_v3(1, 0, 0);
  target = vd_normalize(target);
  vd_vec3 axis = vd_cross(t->h, target);
  double s = vd_norm(axis);
  if (s < EPS) {
    // H vertical and the fallback target opposite: turn about any horizontal axis
    axis = t->u;
    s = 1;
  }
  axis = vd_scale(axis, 1.0 / s);
  rotate_frame(T, axis, atan2(s, vd_dot(t->h, target)) * alpha);
}

// EulerAngles(azimuth, elevation, roll) in degrees: PlantGL's eulerRotationZYX(az, -el, roll),
// H = M x, U = M z, L = U x H
static void euler_angles(turtle* T, double az, double el, double roll) {
  double a = az * (VD_PI / 180), b = -el * (VD_PI / 180), c = roll * (VD_PI / 180);
  double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
  tstate* t = &T->t;
  t->h = vd_v3(ca * cb, sa * cb, -sb);
  t->u = vd_v3(ca * sb * cc + sa * sc, sa * sb * cc - ca * sc, cb * cc);
  t->l = vd_cross(t->u, t->h);
  T->nrot = 0;
}

// ?P ?H ?U ?L ?R in a query run: the position or a frame vector into the module's parameters
// (L-Py: 3 parameters take x, y, z; fewer take the first coordinates; none would append a
// Vector3 object, which the native engine does not have)
static vd_status query_fill(turtle* T) {
  if (!T->query) return VD_OK;
  const tstate* t = &T->t;
  double* p = T->query + T->s->par[T->i];
  int objects = T->sym == VD_SYM_GETFRAME || T->np == 0 || (T->np == 1 && lsys_unbox_str(p[0]) < 0 && isnan(p[0]));
  if (objects && T->qf) {
    // the Python engine makes the Vector3 objects (lsys_py_query_objects)
    lsys_qframes* q = T->qf;
    if (!vd_grow((void**)&q->v, &q->cap, 13 * (q->n + 1), sizeof(double)))
      return fail(T, VD_ERR_NOMEM, "out of memory");
    double* r = q->v + 13 * q->n++;
    vd_vec3 f[4] = {t->pos, t->h, t->u, t->l};
    r[0] = (double)T->i;
    for (int k = 0; k < 4; k++) {
      r[1 + 3 * k] = f[k].x;
      r[2 + 3 * k] = f[k].y;
      r[3 + 3 * k] = f[k].z;
    }
    return VD_OK;
  }
  if (T->sym == VD_SYM_GETFRAME)
    return fail(T, VD_ERR_UNSUPPORTED, "unsupported: ?F (GetFrame fills Vector3 objects)");
  if (T->np == 0)
    return fail(T, VD_ERR_UNSUPPORTED, "unsupported: %s without parameters (L-Py appends a Vector3 object)",
                sym_name(T, T->sym));
  vd_vec3 v = T->sym == VD_SYM_GETPOS    ? t->pos
              : T->sym == VD_SYM_GETHEAD ? t->h
              : T->sym == VD_SYM_GETUP   ? t->u
              : T->sym == VD_SYM_GETLEFT ? t->l
                                         : vd_sub(vd_v3(0, 0, 0), t->l);
  double c[3] = {v.x, v.y, v.z};
  for (int k = 0; k < T->np && k < 3; k++) {
    if (isnan(p[k]))  // a string or an object (NaN-boxed)
      return fail(T, VD_ERR_UNSUPPORTED, "unsupported: %s with a non-number parameter", sym_name(T, T->sym));
    p[k] = c[k];
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// one module

static vd_status step(turtle* T) {
  tstate* t = &T->t;
  double a, b;
  vd_vec3 v;
  int c;
  vd_status st = VD_OK;
  switch ((vd_sym)T->sym) {
  // structure
  case VD_SYM_SB:
    if (!vd_grow((void**)&T->stack, &T->cap_stack, T->nstack + 1, sizeof *T->stack))
      return nomem(T);
    // guide states and tube paths of the branch go above the parent's (dropped at ])
    t->gst_top = T->ngst;
    t->gcp_top = T->ngcp;
    T->stack[T->nstack++] = *t;
    t->open_at = T->i;
    // a tube continues into the branch from its last point only (Turtle::push)
    if (t->gc && t->gc_contour >= 0 && t->gcp_n > 0) {
      if (!vd_grow((void**)&T->gcp, &T->cap_gcp, T->ngcp + 1, sizeof *T->gcp)) return nomem(T);
      T->gcp[T->ngcp] = T->gcp[t->gcp_start + t->gcp_n - 1];
      t->gcp_start = T->ngcp++;
      t->gcp_n = 1;
    }
    t->pending = 1;
    t->tail = -1;
    return VD_OK;
  case VD_SYM_EB:
    if (T->nstack == 0) return fail(T, VD_ERR_SYNTAX, "']' without a matching '['");
    end_axis(T, t);
    if ((st = gc_end(T))) return st;  // a branch's tube ends with it (Turtle::pop)
    *t = T->stack[--T->nstack];
    T->ngst = t->gst_top;
    T->ngcp = t->gcp_top;
    return VD_OK;

  // moves and drawing
  case VD_SYM_F: {
    int label;
    if ((st = max_params(T, 3)) || (st = num_or(T, 0, T->def.step, &a)) ||
        (st = num_or(T, 1, -1, &b)) || (st = label_at(T, 2, &label)))
      return st;
    if (T->np > 1 && negative_ignored(T, 1, b, WARN_RADIUS)) b = -1;  // a cylinder
    return draw_F(T, a, b, label);
  }
  case VD_SYM_f:
    if ((st = num_or(T, 0, T->def.step, &a))) return st;
    move_f(T, a);
    return VD_OK;
  case VD_SYM_nF:
    return draw_nF(T);

  // rotations
  case VD_SYM_LEFT:
  case VD_SYM_RIGHT:
    if ((st = angle_arg(T, &a))) return st;
    turn_left(T, T->sym == VD_SYM_LEFT ? a : -a);
    return VD_OK;
  case VD_SYM_DOWN:
  case VD_SYM_UP:
    if ((st = angle_arg(T, &a))) return st;
    pitch_down(T, T->sym == VD_SYM_DOWN ? a : -a);
    return VD_OK;
  case VD_SYM_ROLLL:
  case VD_SYM_ROLLR:
  case VD_SYM_IROLLL:
  case VD_SYM_IROLLR:
    // without a guide the intrinsic rolls are the plain rolls (PlantGL)
    if ((st = angle_arg(T, &a))) return st;
    roll_left(T, T->sym == VD_SYM_ROLLL || T->sym == VD_SYM_IROLLL ? a : -a);
    return VD_OK;
  case VD_SYM_TURN:
    turn_around(t);
    return VD_OK;
  case VD_SYM_ROLLTOVERT:
    if ((st = num_or(T, 0, 1, &a))) return st;
    roll_to_vert(T, a);
    return VD_OK;
  case VD_SYM_ROLLTOHORIZ:
    if ((st = num_or(T, 0, 1, &a))) return st;
    roll_to_horizontal(T, a);
    return VD_OK;

  // width: no parameter = +-width_inc, a parameter sets it
  case VD_SYM_INCWIDTH:
  case VD_SYM_DECWIDTH:
  case VD_SYM_SETWIDTH:
    if (T->np > 0) {
      if ((st = num(T, 0, &a))) return st;
      if (!negative_ignored(T, 0, a, WARN_WIDTH)) t->width = a;
    } else if (T->sym == VD_SYM_INCWIDTH) {
      t->width += T->def.width_inc;
    } else if (T->sym == VD_SYM_DECWIDTH && t->width - T->def.width_inc > -EPS) {
      t->width = fmax(t->width - T->def.width_inc, 0);
    } else if (!T->warned_width) {
      // L-Py warns and keeps the width (negative widths, SetWidth without value)
      vd_log(1,
             "turtle: module %lld '%s' would make the width negative or has no value; "
             "width kept",
             (long long)T->i, sym_name(T, T->sym));
      T->warned_width = 1;
    }
    gc_width(T);
    return VD_OK;

  // colour = label
  case VD_SYM_INCCOLOR:
  case VD_SYM_DECCOLOR:
    if (T->np > 0) {
      if ((st = index_at(T, 0, "colour index", &c))) return st;
      set_color(T, c);
    } else if (T->sym == VD_SYM_INCCOLOR) {
      set_color(T, t->color + 1);
    } else if (t->color > 0) {
      set_color(T, t->color - 1);
    } else if (!T->warned_color) {
      vd_log(1, "turtle: module %lld ',' below colour 0; colour kept", (long long)T->i);
      T->warned_color = 1;
    }
    return VD_OK;
  case VD_SYM_SETCOLOR:
    // SetColor(i) sets the index; SetColor(r,g,b[,a]) is a custom material: label unchanged
    if (T->np == 1) {
      if ((st = index_at(T, 0, "colour index", &c))) return st;
      set_color(T, c);
    }
    return VD_OK;

  // primitives
  case VD_SYM_SPHERE:
    return draw_sphere(T);
  case VD_SYM_CIRCLE:
    return draw_disc(T);
  case VD_SYM_BOX:
  case VD_SYM_QUAD:
    return draw_box_quad(T, T->sym == VD_SYM_BOX);
  case VD_SYM_LEAF:
    return draw_leaf(T, 0);
  case VD_SYM_SURFACE:
  case VD_SYM_SURFACE_NAMED: {
    const char* name = NULL;
    if (T->np > 0 && T->ls && vd_lsys_value_is_str(T->p[0]))
      name = vd_lsys_value_str(T->ls, T->p[0]);
    if (name && strcmp(name, "l") == 0) return draw_leaf(T, 1);
    return fail(T, VD_ERR_UNSUPPORTED, "unknown surface '%s' (only 'l' is predefined)",
                name ? name : "?");
  }

  // polygons
  case VD_SYM_BP:
    t->polygon = 1;
    T->npoly = 0;
    T->poly_label = t->color;
    T->poly_module = module_of(T, T->i);
    T->poly_node = t->node;
    T->poly_parent = t->parent;
    return VD_OK;
  case VD_SYM_PP:
    return t->polygon ? poly_push(T) : VD_OK;
  case VD_SYM_EP:
    return t->polygon ? end_polygon(T) : VD_OK;

  // generalised cylinders
  case VD_SYM_STARTGC:
    t->gc = 1;
    t->gc_prev = -1;
    // a contour makes the tube a swept mesh (its path recorded from here)
    t->gc_contour = t->contour;
    t->gc_ccw = t->contour_ccw;
    t->gcp_n = 0;
    t->gcp_start = T->ngcp;
    if (t->gc_contour >= 0 && (st = gc_record(T))) return st;
    return VD_OK;
  case VD_SYM_ENDGC:
    if ((st = gc_end(T))) return st;
    t->gc = 0;
    t->gc_prev = -1;
    return VD_OK;

  // tropism: Tropism() = (0,0,1); one or two values fill x, y with z = 1 (PlantGL defaults)
  case VD_SYM_TROPISM:
    if ((st = vec_args(T, 0, vd_v3(0, 0, 1), &v))) return st;
    t->tropism = vd_norm(v) > 0 ? vd_normalize(v) : vd_v3(0, 0, 0);
    return VD_OK;
  case VD_SYM_ELASTICITY:
    // exactly one value sets it; otherwise L-Py resets it to 0
    a = 0;
    if (T->np == 1 && (st = num(T, 0, &a))) return st;
    if (a < 0 || a > 1) return fail(T, VD_ERR_VALUE, "elasticity %g outside [0, 1]", a);
    t->elasticity = a;
    return VD_OK;

  // absolute placement and orientation
  case VD_SYM_MOVETO:
    if ((st = vec_args(T, 0, T->np == 0 ? vd_v3(0, 0, 0) : t->pos, &v))) return st;
    move_to(t, v);
    return VD_OK;
  case VD_SYM_MOVEREL:
    if ((st = vec_args(T, 0, vd_v3(0, 0, 0), &v))) return st;
    move_to(t, vd_add(t->pos, v));
    return VD_OK;
  case VD_SYM_SETHEAD: {
    vd_vec3 u;
    if (T->np == 0) return set_head(T, vd_v3(0, 0, 1), vd_v3(1, 0, 0));
    int k = 0;
    if ((st = vec_at(T, &k, vd_v3(0, 0, 0), &v))) return st;
    int has_up = k < T->np;
    if ((st = vec_at(T, &k, vd_v3(0, 0, 0), &u))) return st;
    if (vd_norm(v) < EPS) return fail(T, VD_ERR_VALUE, "zero heading");
    if (!has_up || vd_norm(u) < EPS) {
      // no usable up: turn toward the heading like PinpointRel
      tend_to(T, vd_normalize(v), 1);
      return VD_OK;
    }
    return set_head(T, v, u);
  }
  case VD_SYM_PINPOINT:
  case VD_SYM_PINPOINTREL:
    if (T->np == 0) return VD_OK;
    if ((st = vec_args(T, 0, vd_v3(0, 0, 0), &v))) return st;
    if (T->sym == VD_SYM_PINPOINT) v = vd_sub(v, t->pos);
    if (vd_norm(v) > EPS) tend_to(T, vd_normalize(v), 1);
    return VD_OK;
  case VD_SYM_LINETO:
  case VD_SYM_OLINETO:
  case VD_SYM_LINEREL:
  case VD_SYM_OLINEREL: {
    int rel = T->sym == VD_SYM_LINEREL || T->sym == VD_SYM_OLINEREL;
    int keep = T->sym == VD_SYM_LINETO || T->sym == VD_SYM_LINEREL;
    if (T->np == 0) return VD_OK;
    int k = 0;
    if ((st = vec_at(T, &k, vd_v3(0, 0, 0), &v)) || (st = num_or(T, k, -1, &b))) return st;
    return line_to(T, rel ? vd_add(t->pos, v) : v, b, keep);
  }
  case VD_SYM_EULER:
    if ((st = vec_args(T, 0, vd_v3(180, 90, 0), &v))) return st;
    euler_angles(T, v.x, v.y, v.z);
    return VD_OK;

  // scale
  case VD_SYM_SETSCALE:
  case VD_SYM_MULTSCALE:
  case VD_SYM_DIVSCALE:
    if ((st = num_or(T, 0, T->sym == VD_SYM_SETSCALE ? 1 : T->def.scale_factor, &a))) return st;
    if (a <= 0) return fail(T, VD_ERR_VALUE, "scale %g must be positive", a);
    t->scale = T->sym == VD_SYM_SETSCALE    ? a
               : T->sym == VD_SYM_MULTSCALE ? t->scale * a
                                            : t->scale / a;
    if (!isfinite(t->scale) || t->scale <= 0) return fail(T, VD_ERR_VALUE, "scale overflow");
    return VD_OK;
  case VD_SYM_SECTIONRES:
    if (T->np == 0) return VD_OK;
    if ((st = num(T, 0, &a))) return st;
    if (a < SLICES_MIN || a >= SLICES_MAX + 1)
      return fail(T, VD_ERR_VALUE, "section resolution %g outside [%d, %d]", a, SLICES_MIN,
                  SLICES_MAX);
    t->slices = (int)a;
    return VD_OK;

  // verdant extension: age written on the following segments
  case VD_SYM_SETAGE:
    if ((st = num_or(T, 0, 0, &a))) return st;
    t->age = a;
    return VD_OK;

  // query modules: filled in a query run (before a derivation step), nothing drawn
  case VD_SYM_GETPOS:
  case VD_SYM_GETHEAD:
  case VD_SYM_GETUP:
  case VD_SYM_GETLEFT:
  case VD_SYM_GETRIGHT:
  case VD_SYM_GETFRAME:
    return query_fill(T);

  // PlantGL mirrors the shapes drawn after a reflection (not the frame): not supported
  case VD_SYM_LEFTREFLECTION:
  case VD_SYM_UPREFLECTION:
  case VD_SYM_HEADINGREFLECTION:
    return fail(T, VD_ERR_UNSUPPORTED, "unsupported: reflections of the drawn shapes");

  // curve-fed geometry (object parameters of the Python engine)
  case VD_SYM_SETGUIDE:
    if (T->np == 0) {
      t->guide = -1;
      return VD_OK;
    }
    if (T->np >= 2 && vd_lsys_value_is_obj(T->p[0])) {
      double yo = 0, cw = 0;
      if ((st = num(T, 1, &a)) || (st = num_or(T, 2, 0, &yo)) || (st = num_or(T, 3, 0, &cw))) return st;
      return set_guide(T, 0, a, yo != 0, cw != 0);
    }
    goto no_curve;
  case VD_SYM_SETCONTOUR:
    if (T->np >= 1 && vd_lsys_value_is_obj(T->p[0])) {
      double cw = 0;
      if ((st = num_or(T, 1, 0, &cw))) return st;
      return set_contour(T, 0, cw != 0);
    }
    goto no_curve;
  case VD_SYM_SWEEP:
    // Sweep(path, section, length, dl[, radius, radius law]) = SetGuide(path, length),
    // SetContour(section), nF(length, dl, radius, radius law) (Turtle::sweep)
    if (T->np >= 4 && vd_lsys_value_is_obj(T->p[0])) {
      double dl, radius = 1;
      int law = -1;
      if ((st = nonneg_or(T, 2, 0, "length", &a)) || (st = num(T, 3, &dl)) || (st = nonneg_or(T, 4, 1, "radius", &radius)))
        return st;
      if (T->np >= 6 && vd_lsys_value_is_obj(T->p[5]) && (st = get_curve(T, 5, CUR_FUNC, &law))) return st;
      if ((st = set_guide(T, 0, a, 0, 0)) || (st = set_contour(T, 1, 0))) return st;
      return run_nF(T, a, dl, radius, law);
    }
    goto no_curve;
  case VD_SYM_ENDGUIDE:
    t->guide = -1;
    return VD_OK;
  case VD_SYM_POSONGUIDE:
    if ((st = num_or(T, 0, 0, &a))) return st;
    return position_on_guide(T, a);
  case VD_SYM_PGLSHAPE:
    if (T->np == 0) return VD_OK;
    return custom_geometry(T);
  no_curve:
    if (!T->warned_guide) {
      vd_log(1, "turtle: module %lld '%s' needs curve objects; ignored", (long long)T->i,
             sym_name(T, T->sym));
      T->warned_guide = 1;
    }
    return VD_OK;

  // display-only and query modules; % is applied by the derivation
  case VD_SYM_INTERPCOLORS:
  case VD_SYM_CUT:
  case VD_SYM_LABEL:
  case VD_SYM_FRAME:
  case VD_SYM_ARROW:
  case VD_SYM_2D:
  case VD_SYM_3D:
  case VD_SYM_TEXSCALE:
  case VD_SYM_TEXUSCALE:
  case VD_SYM_TEXVSCALE:
  case VD_SYM_TEXTRANS:
  case VD_SYM_TEXROT:
  case VD_SYM_TEXBASECOLOR:
  case VD_SYM_INTERPTEXCOLORS:
  case VD_SYM_TEXTRANSFORM:
  case VD_SYM_NEW:  // newmodule(...) becomes the module it names when produced
  case VD_SYM_PREDEFINED_COUNT:
    return VD_OK;
  }
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// the run

// settings that would make the turtle draw nonsense
static vd_status check_def(const vd_turtle_def* d, vd_error* err) {
  const char* bad = NULL;
  if (!isfinite(d->angle))
    bad = "angle";
  else if (!isfinite(d->step))
    bad = "step";
  else if (!(d->width >= 0) || !isfinite(d->width))
    bad = "width";
  else if (!(d->width_inc >= 0) || !isfinite(d->width_inc))
    bad = "width_inc";
  else if (!(d->scale_factor > 0) || !isfinite(d->scale_factor))
    bad = "scale_factor";
  else if (d->color < 0)
    bad = "color";
  else if (d->slices < SLICES_MIN || d->slices > SLICES_MAX)
    bad = "slices";
  else if (!isfinite(d->tropism.x) || !isfinite(d->tropism.y) || !isfinite(d->tropism.z))
    bad = "tropism";
  else if (!(d->elasticity >= 0 && d->elasticity <= 1))
    bad = "elasticity";
  if (bad) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "turtle: bad setting '%s'", bad);
  return VD_OK;
}

static void release(turtle* T) {
  for (int k = 0; k < T->ncur; k++) {
    tcurve* c = &T->cur[k];
    size_t n = (size_t)(c->kind == CUR_FUNC ? c->n : c->n * c->dim);
    vd_free(c->p, sizeof(double) * n);
    vd_free(c->tan, c->tan ? sizeof(double) * n : 0);
    vd_free(c->nrm, c->nrm ? sizeof(double) * n : 0);
  }
  vd_free(T->cur, (size_t)T->cap_cur * sizeof *T->cur);
  vd_free(T->gst, (size_t)T->cap_gst * sizeof *T->gst);
  vd_free(T->gcp, (size_t)T->cap_gcp * sizeof *T->gcp);
  vd_free(T->stack, (size_t)T->cap_stack * sizeof *T->stack);
  vd_free(T->hkey, (size_t)T->hcap * sizeof *T->hkey);
  vd_free(T->hval, (size_t)T->hcap * sizeof *T->hval);
  vd_free(T->poly, (size_t)T->cap_poly * sizeof *T->poly);
  vd_free(T->vbuf, (size_t)T->cap_vbuf * sizeof *T->vbuf);
  vd_free(T->tbuf, (size_t)T->cap_tbuf * sizeof *T->tbuf);
  vd_free(T->ibuf, (size_t)T->cap_ibuf * sizeof *T->ibuf);
}

// Name the file line of the rule or axiom behind a failed module and behind each warning
// (the derivation runs again keeping lines: nothing is paid for them while all goes well).
static void report(turtle* T, vd_status st, vd_error* err) {
  int64_t idx[4];
  int line[4] = {0, 0, 0, 0}, n = 0;
  if (st && err) idx[n++] = T->i;
  for (int k = 0; k < 3; k++)
    if (T->warn[k].count) idx[n++] = T->warn[k].i;
  if (!n) return;
  int found = T->ls && !T->query && lsys_trace_lines((vd_lsystem*)T->ls, T->s, idx, n, line);
  const char* file = T->ls ? lsys_file(T->ls) : "";
  int j = 0;
  if (st && err) {
    if (found && line[0] > 0 && err->line == 0) {
      snprintf(err->file, sizeof err->file, "%s", file);
      err->line = line[0];
    }
    j = 1;
  }
  for (int k = 0; k < 3; k++) {
    const struct twarn* w = &T->warn[k];
    if (!w->count) continue;
    char where[300] = "";
    if (found && line[j] > 0) snprintf(where, sizeof where, "%s:%d: ", file, line[j]);
    vd_log(1, "%sturtle: module %lld '%s': %s%s", where, (long long)w->i, sym_name(T, w->sym), w->msg,
           w->count > 1 ? " (and more like it)" : "");
    j++;
  }
}

static vd_status turtle_run(const vd_lsystem* ls, const vd_lstring* s, const vd_turtle_def* def,
                            vd_plant_spec* plant, vd_error* err, double* query, lsys_qframes* qf) {
  VD_ASSERT(s && plant);
  turtle T;
  memset(&T, 0, sizeof T);
  T.query = query;
  T.qf = qf;
  T.def = def ? *def : vd_turtle_def_default();
  // the file's own default angle (context.turtle.setAngleIncrement, as L-Py's turtle takes it)
  double fa;
  if (ls && lsys_turtle_angle(ls, &fa)) T.def.angle = fa;
  // the Python engine's other settings of the file (setWidthIncrement, setScaleMultiplier, ...)
  if (ls && ls->py) lsys_py_turtle_def(ls, &T.def);
  vd_status st = check_def(&T.def, err);
  if (st) return st;
  T.ls = ls;
  T.s = s;
  T.plant = plant;
  T.err = err;
  T.last_module = -1;
  T.max_module = -1;
  T.ninst = plant->ninstance;
  T.seg0 = plant->nseg;
  T.sphere0 = plant->nsphere;
  T.mesh0 = plant->nmesh;
  T.c_deg = 0;
  T.c_sin = 0;
  T.c_cos = 1;

  // the initial state: PlantGL's frame and L-Py's defaults
  tstate* t = &T.t;
  t->pos = vd_v3(0, 0, 0);
  t->h = vd_v3(0, 0, 1);
  t->l = vd_v3(0, -1, 0);
  t->u = vd_v3(1, 0, 0);
  t->width = T.def.width;
  t->scale = 1;
  t->tropism = vd_norm(T.def.tropism) > 0 ? vd_normalize(T.def.tropism) : vd_v3(0, 0, 0);
  t->elasticity = T.def.elasticity;
  t->color = T.def.color;
  t->slices = T.def.slices;
  t->node = -1;
  t->parent = -1;
  t->tail = -1;
  t->gc_prev = -1;
  t->contour = t->gc_contour = t->guide = -1;
  t->contour_ccw = t->gc_ccw = 1;
  T.next_axis = 1;

  // interpret every predefined module; organ modules have no geometry
  for (int64_t i = 0; i < s->n && st == VD_OK; i++) {
    int sym = s->sym[i];
    if (sym == VD_SYM_CUT) {
      // % drops the rest of its branch (the derivation leaves it until the string is read)
      int depth = 0;
      while (i + 1 < s->n && !(s->sym[i + 1] == VD_SYM_EB && depth == 0)) {
        depth += s->sym[i + 1] == VD_SYM_SB ? 1 : s->sym[i + 1] == VD_SYM_EB ? -1 : 0;
        i++;
      }
      continue;
    }
    if (sym < 0 || sym >= VD_SYM_PREDEFINED_COUNT) {
      // `~x` surfaces other than the predefined leaf `~l` need PlantGL objects
      const char* name = ls ? vd_lsys_symbol_name(ls, sym) : "";
      if (name[0] == '~' && name[1])
        st = vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                          "turtle: module %lld '%s': unsupported surface (only ~l is predefined)", (long long)i,
                          name);
      continue;
    }
    T.i = i;
    T.sym = sym;
    T.np = (int)(s->par[i + 1] - s->par[i]);
    T.p = T.np ? s->val + s->par[i] : NULL;
    st = step(&T);
  }

  // the string ends every open axis (unclosed [ are tolerated, as in L-Py) and the current tube
  if (st == VD_OK) st = gc_end(&T);
  if (st == VD_OK) {
    end_axis(&T, &T.t);
    for (int k = T.nstack - 1; k >= 0; k--)
      end_axis(&T, &T.stack[k]);
    if (T.t.polygon && T.npoly > 0)
      vd_log(1, "turtle: polygon not closed with '}' at the end of the string; dropped");
    if (T.nstack > 0) {
      // L-Py accepts the string (each open branch ends there); the innermost '[' is named
      T.i = T.t.open_at;
      T.sym = VD_SYM_SB;
      warn_module(&T, WARN_BRACKET, "%d '[' not closed at the end of the string", T.nstack);
    }
  }
  report(&T, st, err);
  // the largest instance id in use, whether or not the plant's add functions track it
  if (T.ninst > plant->ninstance) plant->ninstance = T.ninst;
  release(&T);
  return st;
}

vd_status vd_turtle_run(const vd_lsystem* ls, const vd_lstring* s, const vd_turtle_def* def,
                        vd_plant_spec* plant, vd_error* err) {
  return turtle_run(ls, s, def, plant, err, NULL, NULL);
}

vd_status lsys_turtle_query(const vd_lsystem* ls, vd_lstring* s, vd_error* err, lsys_qframes* qf) {
  vd_plant_spec* scratch = vd_plant_spec_create();
  if (!scratch) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  vd_turtle_def d = vd_turtle_def_default();
  vd_status st = turtle_run(ls, s, &d, scratch, err, s->val, qf);
  vd_plant_spec_destroy(scratch);
  return st;
}
