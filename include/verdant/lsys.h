// SPDX-License-Identifier: MIT
// verdant lsys: L-systems in the L-Py file syntax, their derivation, and the turtle that turns
// an L-string into a labelled plant spec.
//
// A vd_lsystem is a parsed grammar (rules, globals, symbol table); it owns its interpreter
// state (globals, random generator), so one lsystem derives one plant at a time. A vd_lstring
// is a flat array of modules: symbol ids, and parameters as doubles stored contiguously.
//
// Usage:
//   vd_lsystem* ls; vd_error err = {0};
//   if (vd_lsys_load("data/tomato.lpy", &ls, &err)) { /* report err */ }
//   vd_lsys_def def = vd_lsys_def_default(); def.seed = 7;
//   vd_plant_spec* plant = vd_plant_spec_create();
//   vd_lsys_grow(ls, &def, NULL, plant, &err);    // derive, interpret, turtle
//   vd_lsys_destroy(ls);
#ifndef VERDANT_LSYS_H
#define VERDANT_LSYS_H

#include "verdant/core.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

// Predefined modules (L-Py's names, then verdant's): X(enum, name as written in L-strings).
// Symbols with ids below VD_SYM_PREDEFINED_COUNT are these; declared and one-character modules
// get later ids. L-Py's long names (Left, Sphere, MoveTo, StartGC, ...) are aliases: they read
// as the same symbol and print as the short name (vd_lsys_symbol_find resolves them too).
#define VD_SYM_LIST(X)                                                                             \
  X(VD_SYM_SB, "[")                                                                                \
  X(VD_SYM_EB, "]")                                                                                \
  X(VD_SYM_F, "F")                                                                                 \
  X(VD_SYM_f, "f")                                                                                 \
  X(VD_SYM_nF, "nF")                                                                               \
  X(VD_SYM_LEFT, "+")                                                                              \
  X(VD_SYM_RIGHT, "-")                                                                             \
  X(VD_SYM_UP, "^")                                                                                \
  X(VD_SYM_DOWN, "&")                                                                              \
  X(VD_SYM_ROLLL, "/")                                                                             \
  X(VD_SYM_ROLLR, "\\")                                                                            \
  X(VD_SYM_IROLLL, "iRollL")                                                                       \
  X(VD_SYM_IROLLR, "iRollR")                                                                       \
  X(VD_SYM_TURN, "|")                                                                              \
  X(VD_SYM_ROLLTOVERT, "@v")                                                                       \
  X(VD_SYM_ROLLTOHORIZ, "@h")                                                                      \
  X(VD_SYM_INCWIDTH, "_")                                                                          \
  X(VD_SYM_DECWIDTH, "!")                                                                          \
  X(VD_SYM_SETWIDTH, "SetWidth")                                                                   \
  X(VD_SYM_INCCOLOR, ";")                                                                          \
  X(VD_SYM_DECCOLOR, ",")                                                                          \
  X(VD_SYM_SETCOLOR, "SetColor")                                                                   \
  X(VD_SYM_INTERPCOLORS, "InterpolateColors")                                                      \
  X(VD_SYM_SPHERE, "@O")                                                                           \
  X(VD_SYM_CIRCLE, "@o")                                                                           \
  X(VD_SYM_BOX, "@B")                                                                              \
  X(VD_SYM_QUAD, "@b")                                                                             \
  X(VD_SYM_SURFACE, "~")                                                                           \
  X(VD_SYM_LEAF, "~l")                                                                             \
  X(VD_SYM_BP, "{")                                                                                \
  X(VD_SYM_PP, ".")                                                                                \
  X(VD_SYM_EP, "}")                                                                                \
  X(VD_SYM_STARTGC, "@Gc")                                                                         \
  X(VD_SYM_ENDGC, "@Ge")                                                                           \
  X(VD_SYM_TROPISM, "@Tp")                                                                         \
  X(VD_SYM_ELASTICITY, "@Ts")                                                                      \
  X(VD_SYM_MOVETO, "@M")                                                                           \
  X(VD_SYM_MOVEREL, "MoveRel")                                                                     \
  X(VD_SYM_SETHEAD, "@R")                                                                          \
  X(VD_SYM_PINPOINT, "Pinpoint")                                                                   \
  X(VD_SYM_PINPOINTREL, "PinpointRel")                                                             \
  X(VD_SYM_LINETO, "LineTo")                                                                       \
  X(VD_SYM_OLINETO, "OLineTo")                                                                     \
  X(VD_SYM_LINEREL, "LineRel")                                                                     \
  X(VD_SYM_OLINEREL, "OLineRel")                                                                   \
  X(VD_SYM_EULER, "EulerAngles")                                                                   \
  X(VD_SYM_SETSCALE, "@D")                                                                         \
  X(VD_SYM_MULTSCALE, "@Di")                                                                       \
  X(VD_SYM_DIVSCALE, "@Dd")                                                                        \
  X(VD_SYM_SECTIONRES, "SectionResolution")                                                        \
  X(VD_SYM_CUT, "%")                                                                               \
  X(VD_SYM_LABEL, "@L")                                                                            \
  X(VD_SYM_FRAME, "Frame")                                                                         \
  X(VD_SYM_ARROW, "Arrow")                                                                         \
  X(VD_SYM_PGLSHAPE, "@g")                                                                         \
  X(VD_SYM_2D, "@2D")                                                                              \
  X(VD_SYM_3D, "@3D")                                                                              \
  X(VD_SYM_SETGUIDE, "SetGuide")                                                                   \
  X(VD_SYM_ENDGUIDE, "EndGuide")                                                                   \
  X(VD_SYM_POSONGUIDE, "PositionOnGuide")                                                          \
  X(VD_SYM_SWEEP, "Sweep")                                                                         \
  X(VD_SYM_SETCONTOUR, "SetContour")                                                               \
  X(VD_SYM_TEXSCALE, "TextureScale")                                                               \
  X(VD_SYM_TEXUSCALE, "TextureUScale")                                                             \
  X(VD_SYM_TEXVSCALE, "TextureVScale")                                                             \
  X(VD_SYM_TEXTRANS, "TextureTranslation")                                                         \
  X(VD_SYM_TEXROT, "TextureRotation")                                                              \
  X(VD_SYM_GETPOS, "?P")                                                                           \
  X(VD_SYM_GETHEAD, "?H")                                                                          \
  X(VD_SYM_GETUP, "?U")                                                                            \
  X(VD_SYM_GETLEFT, "?L")                                                                          \
  X(VD_SYM_GETRIGHT, "?R")                                                                         \
  X(VD_SYM_GETFRAME, "?F")                                                                         \
  X(VD_SYM_SETAGE, "SetAge")                                                                       \
  X(VD_SYM_SURFACE_NAMED, "surface")                                                               \
  X(VD_SYM_TEXBASECOLOR, "TextureBaseColor")                                                       \
  X(VD_SYM_INTERPTEXCOLORS, "InterpolateTextureBaseColors")                                        \
  X(VD_SYM_TEXTRANSFORM, "TextureTransformation")                                                  \
  X(VD_SYM_LEFTREFLECTION, "LeftReflection")                                                       \
  X(VD_SYM_UPREFLECTION, "UpReflection")                                                           \
  X(VD_SYM_HEADINGREFLECTION, "HeadingReflection")                                                \
  X(VD_SYM_NEW, "new")

typedef enum vd_sym {
#define VD_SYM_ENUM(e, s) e,
  VD_SYM_LIST(VD_SYM_ENUM)
#undef VD_SYM_ENUM
      VD_SYM_PREDEFINED_COUNT
} vd_sym;

// Name of a predefined symbol ("@O"), or NULL for ids outside the predefined range.
const char* vd_sym_predefined_name(int sym);

// A flat L-string: module i has symbol sym[i] and the parameters val[par[i]] .. val[par[i+1]-1].
typedef struct vd_lstring {
  int64_t n;      // number of modules
  int32_t* sym;   // symbol id of each module (n)
  int64_t* par;   // first-parameter offset of each module, and the total at par[n] (n + 1)
  double* val;    // parameter values (par[n]); strings are NaN-boxed ids (vd_lsys_value_str)
  int64_t* src;   // Nullable: index of the derived-string module each module came from (n)
  int64_t cap, vcap;  // capacities of the module and value arrays
  int32_t* line;  // Nullable: file line of the rule or axiom that wrote each module (n); kept
                  // only when an error or warning is traced back to the file
} vd_lstring;

// Empty L-string (no allocation).
static inline vd_lstring vd_lstring_empty(void) {
  vd_lstring s = {0, 0, 0, 0, 0, 0, 0, 0};
  return s;
}
// Free an L-string's arrays and make it empty.
void vd_lstring_free(vd_lstring* s);
// Number of parameters of module i.
static inline int vd_lstring_nparam(const vd_lstring* s, int64_t i) {
  return (int)(s->par[i + 1] - s->par[i]);
}

// A parsed L-system (opaque).
typedef struct vd_lsystem vd_lsystem;

// Settings of one derivation; defaults from vd_lsys_def_default().
typedef struct vd_lsys_def {
  int steps;            // derivation steps; -1 = the file's `derivation length` (default -1)
  uint64_t seed;        // random seed, as if random.seed(seed) ran before the axiom (default 0)
  int64_t max_modules;  // largest L-string allowed, error VD_ERR_LIMIT beyond (default 50e6)
  int64_t max_ops;      // interpreter work allowed per call: loop iterations, function calls
                        // and modules read by each rewriting pass, error VD_ERR_LIMIT
                        // beyond; 0 or less = default (1e9)
  // Nullable: called after each step with (step, steps, modules); return non-zero to stop.
  int (*progress)(void* user, int step, int steps, int64_t modules);
  void* progress_user;  // passed to progress
  // Nullable: vd_lsys_animate calls it with every frame it shows: the frame number (0: the
  // axiom, k: the string after step k), the derived string and the plant it draws; return
  // non-zero to stop the animation there.
  int (*frame)(void* user, int frame, const vd_lstring* s, const vd_plant_spec* plant);
  void* frame_user;     // passed to frame
} vd_lsys_def;

// Default derivation settings (see vd_lsys_def).
vd_lsys_def vd_lsys_def_default(void);

// Parse L-Py text; name is the file name used in errors (Nullable). The engine is chosen
// automatically (VD_LSYS_AUTO).
vd_status vd_lsys_parse(const char* text, size_t len, const char* name, vd_lsystem** out,
                        vd_error* err);
// Read and parse an .lpy file (engine chosen automatically).
vd_status vd_lsys_load(const char* path, vd_lsystem** out, vd_error* err);

// Which engine runs a file's Python: the native subset interpreter (fast) or embedded CPython
// (any Python, PlantGL-like objects). Both share the parser's rules, the derivation, the
// L-string layout and the turtle.
typedef enum vd_lsys_engine {
  VD_LSYS_AUTO = 0,  // native when the whole file is in the native subset, else Python
  VD_LSYS_NATIVE,    // the native subset only (unsupported constructs are errors)
  VD_LSYS_PYTHON     // embedded CPython for all of the file's Python
} vd_lsys_engine;
// Parse with a given engine (VD_LSYS_AUTO: native, then Python when the native parse stops at
// a construct beyond its subset).
vd_status vd_lsys_parse_engine(const char* text, size_t len, const char* name,
                               vd_lsys_engine engine, vd_lsystem** out, vd_error* err);
// Read and parse an .lpy file with a given engine.
vd_status vd_lsys_load_engine(const char* path, vd_lsys_engine engine, vd_lsystem** out,
                              vd_error* err);
// The automatic choice's second chance: when *ls was parsed with VD_LSYS_AUTO, which chose the
// native engine, and a run of it failed with st = VD_ERR_UNSUPPORTED or VD_ERR_TYPE (something
// the native subset refuses only when it runs, such as "a%d" % 3), *ls is replaced by the same
// text parsed for the Python engine and 1 is returned: the caller runs again from the start
// (its --set overrides, derivation...). Else 0 and *ls is unchanged (the error stands).
int vd_lsys_fallback(vd_lsystem** ls, vd_status st);
// The line of the file's Axiom: keyword; 0 when it has none (its string then starts empty, as
// in L-Py).
int vd_lsys_axiom_line(const vd_lsystem* ls);
// The engine that runs ls (VD_LSYS_NATIVE or VD_LSYS_PYTHON).
vd_lsys_engine vd_lsys_get_engine(const vd_lsystem* ls);
// "auto", "native" or "python".
const char* vd_lsys_engine_name(vd_lsys_engine e);
// 1 when the embedded CPython engine can start in this process (its standard library found),
// else 0 with the reason in why (Nullable, cap bytes).
int vd_lsys_python_available(char* why, size_t cap);
// Free an lsystem (NULL is fine).
void vd_lsys_destroy(vd_lsystem* ls);
// Replace global `name` by the value of the Python expression `text` (--set NAME=TEXT).
// The global must exist in the file (VD_ERR_NAME otherwise).
vd_status vd_lsys_set_global(vd_lsystem* ls, const char* name, const char* text, vd_error* err);
// Current numeric value of a global; VD_ERR_NAME if absent, VD_ERR_TYPE if not a number.
vd_status vd_lsys_get_global(const vd_lsystem* ls, const char* name, double* value);
// The file's derivation length (after globals are set).
int vd_lsys_derivation_length(const vd_lsystem* ls);

// Derive: reset globals to their initial values (with --set overrides), run the axiom and
// `derivation length` (or def->steps) production steps with decomposition; the result is the
// derived string (before interpretation) in *out, which is overwritten.
vd_status vd_lsys_derive(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_error* err);
// Animate, as L-Py's Lsystem.animate(): derive as vd_lsys_derive does and interpret after
// every step. A frame is drawn (interpretation rules, StartInterpretation/EndInterpretation,
// then the turtle with default settings, the file's labels named) from the axiom before the
// Start hook, then from the string after each step whose frame is displayed (frameDisplay(False)
// during a step skips its frame); def->frame sees each. A Python EndEach(lstring, lscene) or
// End(lstring, lscene) gets the frame's scene, drawn before the call, and the frame reuses it
// when the hook returns it (alone or as (lstring, lscene)) or returns nothing; any other
// result draws the string again. Every step runs, a step where no rule matches included
// (L-Py's animate derives one step at a time). *out is the final string and *plant (cleared
// first) its plant, as the last frame showed it (drawn once more when the last step's frame
// was skipped). isAnimationEnabled() is true meanwhile.
vd_status vd_lsys_animate(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_plant_spec* plant,
                          vd_error* err);
// Call the function `name` of the file's global namespace without arguments, after a run (it
// sees the globals as the run left them): a check() of the file's own asserts. VD_ERR_NAME when
// the file has no such function; a failed assert or any exception is an error with its line.
vd_status vd_lsys_call(vd_lsystem* ls, const char* name, vd_error* err);
// Derive step by step (growth loops): begin resets the globals (with --set overrides), runs the
// Start hook and puts the axiom into *out; each vd_lsys_derive_step then applies one production
// step with decomposition (StartEach/EndEach hooks) to s in place and sets s->src[j] to the
// index, in the string before the step, of the module that module j came from, so a caller can
// follow each module through the steps. def->steps is not read; the same seed gives the same
// strings as vd_lsys_derive. VD_ERR_VALUE after Stop() was called.
vd_status vd_lsys_derive_begin(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* out, vd_error* err);
// One derivation step of a run started by vd_lsys_derive_begin (see there).
vd_status vd_lsys_derive_step(vd_lsystem* ls, const vd_lsys_def* def, vd_lstring* s, vd_error* err);
// Apply interpretation (homomorphism) rules to a derived string; out->src maps each module back
// to its module in `in`.
vd_status vd_lsys_interpret(vd_lsystem* ls, const vd_lsys_def* def, const vd_lstring* in,
                            vd_lstring* out, vd_error* err);
// Name of a symbol id ("Leaf", "@O"), or "?" if out of range.
const char* vd_lsys_symbol_name(const vd_lsystem* ls, int sym);
// Number of symbols (predefined + declared + seen).
int vd_lsys_symbol_count(const vd_lsystem* ls);
// Symbol id of a name, or -1.
int vd_lsys_symbol_find(const vd_lsystem* ls, const char* name);
// Append a textual form of s ("F(1)[+(30)A]") to buf (cap bytes, truncated); returns buf.
char* vd_lsys_format(const vd_lsystem* ls, const vd_lstring* s, char* buf, size_t cap);
// Parse an L-string written in the file's module names, with constant parameters.
vd_status vd_lsys_parse_lstring(vd_lsystem* ls, const char* text, vd_lstring* out, vd_error* err);

// Python objects inside L-strings (the Python engine's lists, vectors, curves...) are NaN-boxed
// handles: 1 when v is one.
int vd_lsys_value_is_obj(double v);
// Strings inside L-strings are NaN-boxed: test and extract the string id of a value.
int vd_lsys_value_is_str(double v);
// String text of a NaN-boxed value, or NULL when it is not a string of this lsystem.
const char* vd_lsys_value_str(const vd_lsystem* ls, double v);

// Label names declared by the file (LABELS = {id: "name", ...} or material names); count.
int vd_lsys_label_count(const vd_lsystem* ls);
// Label i declared by the file: its id and name.
void vd_lsys_label_get(const vd_lsystem* ls, int i, int* id, const char** name);

// ---------------------------------------------------------------------------------------------
// turtle

// Turtle settings; defaults from vd_turtle_def_default() are L-Py's.
typedef struct vd_turtle_def {
  double angle;          // default turn angle (degrees), 60
  double step;           // default F/f length (m), 1
  double width;          // initial width, a radius (m), 0.1
  double width_inc;      // _ and ! without argument add/subtract this (m), 1
  double scale_factor;   // @Di / @Dd without argument multiply/divide the scale by this, 0.5
  int color;             // initial colour (material) index = label, 1
  int slices;            // sections of cylinders and spheres, 8
  vd_vec3 tropism;       // tropism direction, (0, 0, 1)
  double elasticity;     // tropism strength in [0, 1], 0 (off)
} vd_turtle_def;

// L-Py's turtle defaults (see vd_turtle_def).
vd_turtle_def vd_turtle_def_default(void);

// Interpret an L-string with the turtle and append the geometry to plant. Instance ids come
// from s->src when present (one per derived module), else from the module index.
vd_status vd_turtle_run(const vd_lsystem* ls, const vd_lstring* s, const vd_turtle_def* def,
                        vd_plant_spec* plant, vd_error* err);

// Derive, interpret and run the turtle (tdef Nullable: defaults); labels declared by the file
// are named in plant.
vd_status vd_lsys_grow(vd_lsystem* ls, const vd_lsys_def* def, const vd_turtle_def* tdef,
                       vd_plant_spec* plant, vd_error* err);

// ---------------------------------------------------------------------------------------------
// Loading a plant from any file verdant accepts (lsys_load.c): the one entry the command line,
// the Python package, growth, harvest scenes and export all go through, so that the same file
// with the same settings makes the same plant (ids and bytes) everywhere. A new input format is
// one entry in the table of lsys_load.c.

// The kinds of plant input.
typedef enum vd_plant_format {
  VD_PLANT_FORMAT_LPY = 0,  // an L-Py file: derived, interpreted, drawn by the turtle
  VD_PLANT_FORMAT_JSON,     // a plant file (JSON, format "verdant-plant")
  VD_PLANT_FORMAT_CURVES,   // a curves file (JSON, format "verdant-curves")
  VD_PLANT_FORMAT_COUNT
} vd_plant_format;

// Name of a format ("lpy", "plant", "curves").
const char* vd_plant_format_name(vd_plant_format f);

// vd_plant_load_def::instances: organs for a plant drawn from an L-system, a file's own numbering.
#define VD_INSTANCE_DEFAULT (-1)

// Settings of vd_plant_load: one struct for every format (what does not apply to the input is an
// error when set: VD_ERR_ARG naming the setting).
typedef struct vd_plant_load_def {
  vd_lsys_def lsys;             // L-systems: steps, seed, limits, progress and frame callbacks
  vd_turtle_def turtle;         // L-systems: the turtle
  vd_lsys_engine engine;        // L-systems: who runs the file's Python (VD_LSYS_AUTO)
  const char* const* set_name;  // L-systems: globals to override before the run (nset), and
  const char* const* set_value; // their values as Python expressions
  int nset;
  const int* label_id;          // label names given after the file's own (nlabel): ids 0..65535
  const char* const* label_name;
  int nlabel;
  double curve_step;            // curves files: dense sampling step (m); < 0: the file's or default
  double curve_connect;         // curves files: largest branch gap (m); < 0: the file's or default
  double curve_distance;        // curves files: segment length (m); < 0: the file's or default
  int instances;                // a vd_instance_mode, or VD_INSTANCE_DEFAULT: organs for what an
                                // L-system draws, a plant or curves file keeps its own numbering
  int animate;                  // L-systems: draw after every step (vd_lsys_animate); the plant is
                                // the last frame's
  const char* const* call;      // L-systems: the file's functions called after the run (ncall)
  int ncall;
  // Nullable, L-systems: called with the derived string before it is drawn; a status other than
  // VD_OK stops the load with it (the command line's --lstring writes the string here).
  vd_status (*derived)(void* user, const vd_lsystem* ls, const vd_lstring* s, vd_error* err);
  void* user;                   // passed to derived
} vd_plant_load_def;

// Defaults: vd_lsys_def_default, vd_turtle_def_default, VD_LSYS_AUTO, no overrides, curve
// settings -1, instances VD_INSTANCE_DEFAULT.
vd_plant_load_def vd_plant_load_def_default(void);

// What a load did (vd_plant_load_info_free frees the arrays).
typedef struct vd_plant_load_info {
  vd_plant_format format;       // what the input was
  const char* engine;           // L-systems: the engine that ran it ("native", "python"), else NULL
  int64_t modules;              // L-systems: modules of the derived string, else 0
  int nsym;                     // L-systems: symbols of the file
  int64_t* sym_count;           // modules of each symbol in the derived string (nsym)
  char** sym_name;              // each symbol's name (nsym)
  double seconds_derive;        // L-systems: wall time of the derivation (s)
  double seconds_turtle;        // ... and of the interpretation and the turtle (s)
  int axiom_line;               // L-systems: the line of the file's Axiom:, 0 when it has none
} vd_plant_load_info;

// Make a plant from the file at path: an .lpy file, a plant file or a curves file (.json, told
// apart by their "format"). *out gets a new spec; info (Nullable) what was done. Errors name the
// file, line and column (VD_ERR_ARG for a setting that does not apply to the input).
vd_status vd_plant_load(const char* path, const vd_plant_load_def* def, vd_plant_spec** out,
                        vd_plant_load_info* info, vd_error* err);
// The same from text in memory: JSON when it starts with '{', else L-Py; name (Nullable) is
// used in errors.
vd_status vd_plant_load_text(const char* text, size_t len, const char* name, const vd_plant_load_def* def,
                             vd_plant_spec** out, vd_plant_load_info* info, vd_error* err);
// The L-system of an .lpy file as vd_plant_load opens it (def's engine and overrides of its
// globals; def Nullable): for callers that derive it themselves (growth).
vd_status vd_plant_load_lsystem(const char* path, const vd_plant_load_def* def, vd_lsystem** out, vd_error* err);
// Name the labels and instances of a plant that ls drew, as vd_plant_load does (the file's
// labels, def's, then the instances): for frames drawn outside it. VD_ERR_NOMEM.
vd_status vd_plant_load_name(const vd_lsystem* ls, const vd_plant_load_def* def, vd_plant_spec* plant);
// Free the arrays of info (a zeroed one is fine).
void vd_plant_load_info_free(vd_plant_load_info* info);

#ifdef __cplusplus
}
#endif
#endif
