// SPDX-License-Identifier: MIT
// One way in: a plant from any input verdant accepts (vd_plant_load). The table `formats` says
// which inputs there are and how each is read; everything after (the caller's label names, the
// instance numbering) is the same for all. The command line, the Python package, growth and
// harvest scenes all load plants here.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "lsys_internal.h"

vd_plant_load_def vd_plant_load_def_default(void) {
  vd_plant_load_def d;
  memset(&d, 0, sizeof d);
  d.lsys = vd_lsys_def_default();
  d.turtle = vd_turtle_def_default();
  d.engine = VD_LSYS_AUTO;
  d.curve_step = d.curve_connect = d.curve_distance = -1;
  d.instances = VD_INSTANCE_DEFAULT;
  return d;
}

const char* vd_plant_format_name(vd_plant_format f) {
  static const char* names[VD_PLANT_FORMAT_COUNT] = {"lpy", "plant", "curves"};
  return f >= 0 && f < VD_PLANT_FORMAT_COUNT ? names[f] : "?";
}

void vd_plant_load_info_free(vd_plant_load_info* info) {
  if (!info) return;
  if (info->sym_name)
    for (int k = 0; k < info->nsym; k++)
      if (info->sym_name[k]) vd_free(info->sym_name[k], strlen(info->sym_name[k]) + 1);
  vd_free(info->sym_name, sizeof(char*) * (size_t)info->nsym);
  vd_free(info->sym_count, sizeof(int64_t) * (size_t)info->nsym);
  memset(info, 0, sizeof *info);
}

static double load_now(void) {
  struct timespec ts;
  timespec_get(&ts, TIME_UTC);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// the caller's label names (after the file's), the instances as def says (lsys: 1 when ls drew it)
static vd_status name_plant(const vd_plant_load_def* def, int lsys, vd_plant_spec* plant) {
  vd_status st = VD_OK;
  for (int i = 0; !st && i < def->nlabel; i++) st = vd_plant_set_label(plant, def->label_id[i], def->label_name[i]);
  if (!st && lsys) st = vd_plant_complete_labels(plant);
  int mode = def->instances != VD_INSTANCE_DEFAULT ? def->instances : lsys ? VD_INSTANCE_ORGANS : -1;
  if (!st && mode >= 0) st = vd_plant_set_instances(plant, (vd_instance_mode)mode);
  return st;
}

vd_status vd_plant_load_name(const vd_lsystem* ls, const vd_plant_load_def* def, vd_plant_spec* plant) {
  vd_status st = VD_OK;
  for (int i = 0; !st && i < vd_lsys_label_count(ls); i++) {
    int id;
    const char* name;
    vd_lsys_label_get(ls, i, &id, &name);
    st = vd_plant_set_label(plant, id, name);
  }
  return st ? st : name_plant(def, 1, plant);
}

// ---------------------------------------------------------------------------------------------
// the formats

// One kind of input: the settings that apply only to it are refused for the others.
typedef struct load_input {
  const char* name;     // for errors
  const char* text;     // the whole input
  size_t len;
  const char* path;     // the file (Nullable: text in memory)
} load_input;

static int curve_set(const vd_plant_load_def* d) {
  return d->curve_step >= 0 || d->curve_connect >= 0 || d->curve_distance >= 0;
}

static vd_status not_lsys(const load_input* in, const vd_plant_load_def* d, vd_error* err) {
  if (d->nset) return vd_error_set(err, VD_ERR_ARG, in->name, 0, 0, "overriding globals (--set, set=) applies to .lpy files only");
  if (d->animate || d->ncall || d->lsys.frame)
    return vd_error_set(err, VD_ERR_ARG, in->name, 0, 0, "%s applies to .lpy files only",
                        d->ncall ? "calling the file's functions (--call)" : d->lsys.frame ? "writing frames (--frames)"
                                                                                           : "animating (--animate)");
  return VD_OK;
}

static vd_status load_json(const load_input* in, const vd_plant_load_def* d, vd_plant_spec** out, vd_error* err) {
  vd_status st = not_lsys(in, d, err);
  if (st) return st;
  if (curve_set(d))
    return vd_error_set(err, VD_ERR_ARG, in->name, 0, 0, "curve settings (--curve-*, curve_*) apply to curves files only");
  return vd_plant_parse_json(in->text, in->len, in->name, out, err);
}

static vd_status load_curves(const load_input* in, const vd_plant_load_def* d, vd_plant_spec** out, vd_error* err) {
  vd_status st = not_lsys(in, d, err);
  if (st) return st;
  vd_curves* c;
  if ((st = vd_curves_parse(in->text, in->len, in->name, &c, err))) return st;
  vd_curves_def cd = vd_curves_file_def(c);
  if (d->curve_step >= 0) cd.sample_step = d->curve_step;
  if (d->curve_connect >= 0) cd.connect = d->curve_connect;
  if (d->curve_distance >= 0) cd.distance = d->curve_distance;
  *out = vd_plant_spec_create();
  st = *out ? vd_curves_build(c, &cd, *out, NULL, err) : vd_error_set(err, VD_ERR_NOMEM, in->name, 0, 0, "out of memory");
  vd_curves_destroy(c);
  return st;
}

// module counts by symbol, for the caller's summary
static vd_status count_symbols(const vd_lsystem* ls, const vd_lstring* s, vd_plant_load_info* info) {
  info->modules = s->n;
  info->nsym = vd_lsys_symbol_count(ls);
  info->sym_count = vd_calloc((size_t)info->nsym, sizeof(int64_t));
  info->sym_name = vd_calloc((size_t)info->nsym, sizeof(char*));
  if (!info->sym_count || !info->sym_name) return VD_ERR_NOMEM;
  for (int64_t i = 0; i < s->n; i++) info->sym_count[s->sym[i]]++;
  for (int k = 0; k < info->nsym; k++)
    if (!(info->sym_name[k] = vd_strdup(vd_lsys_symbol_name(ls, k)))) return VD_ERR_NOMEM;
  return VD_OK;
}

// the frames of an animation handed to the caller named as the plant is (labels, instances)
typedef struct named_frames {
  const vd_lsystem* ls;
  const vd_plant_load_def* d;
  vd_status st;
} named_frames;

static int name_frame(void* user, int frame, const vd_lstring* s, const vd_plant_spec* plant) {
  named_frames* f = user;
  vd_plant_spec* p = vd_plant_spec_copy(plant);
  f->st = p ? vd_plant_load_name(f->ls, f->d, p) : VD_ERR_NOMEM;
  int stop = f->st ? 1 : f->d->lsys.frame(f->d->lsys.frame_user, frame, s, p);
  vd_plant_spec_destroy(p);
  return stop;
}

// derive (or animate), interpret, draw, call, name
static vd_status grow_lsys(vd_lsystem* ls, const char* name, const vd_plant_load_def* d, vd_plant_spec** out,
                           vd_plant_load_info* info, vd_error* err) {
  vd_status st = VD_OK;
  info->engine = vd_lsys_engine_name(vd_lsys_get_engine(ls));
  vd_plant_spec* plant = vd_plant_spec_create();
  if (!plant) st = vd_error_set(err, VD_ERR_NOMEM, name, 0, 0, "out of memory");
  vd_lstring derived = vd_lstring_empty(), geo = vd_lstring_empty();
  vd_lsys_def ld = d->lsys;
  named_frames nf = {ls, d, VD_OK};
  if (ld.frame) ld.frame = name_frame, ld.frame_user = &nf;
  double t0 = load_now();
  // an animation draws every frame and ends with the plant of the last
  if (!st) st = d->animate ? vd_lsys_animate(ls, &ld, &derived, plant, err) : vd_lsys_derive(ls, &ld, &derived, err);
  double t1 = load_now();
  if (!st && nf.st) st = vd_error_set(err, nf.st, name, 0, 0, "out of memory");
  if (!st && d->derived) st = d->derived(d->user, ls, &derived, err);
  if (!st && !d->animate) st = vd_lsys_interpret(ls, &ld, &derived, &geo, err);
  if (!st && !d->animate) st = vd_turtle_run(ls, &geo, &d->turtle, plant, err);
  double t2 = load_now();
  for (int i = 0; !st && i < d->ncall; i++) st = vd_lsys_call(ls, d->call[i], err);
  if (!st && (st = vd_plant_load_name(ls, d, plant))) vd_error_set(err, st, name, 0, 0, "out of memory");
  if (!st && (st = count_symbols(ls, &derived, info))) vd_error_set(err, st, name, 0, 0, "out of memory");
  info->seconds_derive = t1 - t0;
  info->seconds_turtle = t2 - t1;
  info->axiom_line = vd_lsys_axiom_line(ls);
  vd_lstring_free(&derived);
  vd_lstring_free(&geo);
  if (st) {
    vd_plant_spec_destroy(plant);
    return st;
  }
  *out = plant;
  return VD_OK;
}

// the L-system of an input with def's engine and overrides of its globals
static vd_status open_lsys(const load_input* in, const vd_plant_load_def* d, vd_lsystem** out, vd_error* err) {
  vd_lsystem* ls;
  vd_status st = in->path ? vd_lsys_load_engine(in->path, d->engine, &ls, err)
                          : vd_lsys_parse_engine(in->text, in->len, in->name, d->engine, &ls, err);
  if (st) return st;
  for (int i = 0; !st && i < d->nset; i++) st = vd_lsys_set_global(ls, d->set_name[i], d->set_value[i], err);
  if (st) {
    vd_lsys_destroy(ls);
    return st;
  }
  *out = ls;
  return VD_OK;
}

vd_status vd_plant_load_lsystem(const char* path, const vd_plant_load_def* def, vd_lsystem** out, vd_error* err) {
  vd_plant_load_def d0 = vd_plant_load_def_default();
  load_input in = {path, NULL, 0, path};
  *out = NULL;
  return open_lsys(&in, def ? def : &d0, out, err);
}

static vd_status load_lpy(const load_input* in, const vd_plant_load_def* d, vd_plant_spec** out,
                          vd_plant_load_info* info, vd_error* err) {
  if (curve_set(d))
    return vd_error_set(err, VD_ERR_ARG, in->name, 0, 0, "curve settings (--curve-*, curve_*) apply to curves files only");
  vd_lsystem* ls;
  vd_status st = open_lsys(in, d, &ls, err);
  if (st) return st;
  st = grow_lsys(ls, in->name, d, out, info, err);
  // what the native engine refuses only when it runs: the automatic choice runs it in CPython,
  // with the same overrides
  if (st && vd_lsys_fallback(&ls, st)) {
    if (err) memset(err, 0, sizeof *err);
    vd_plant_load_info_free(info);
    info->format = VD_PLANT_FORMAT_LPY;
    st = VD_OK;
    for (int i = 0; !st && i < d->nset; i++) st = vd_lsys_set_global(ls, d->set_name[i], d->set_value[i], err);
    if (!st) st = grow_lsys(ls, in->name, d, out, info, err);
  }
  vd_lsys_destroy(ls);
  return st;
}

// JSON inputs: which format by the text's "format" (a plant file when it names none)
static vd_plant_format json_format(const char* text, size_t len) {
  char fmt[32];
  return !strcmp(vd_plant_json_format(text, len, fmt, sizeof fmt), "verdant-curves") ? VD_PLANT_FORMAT_CURVES
                                                                                      : VD_PLANT_FORMAT_JSON;
}

static int has_ext(const char* path, const char* ext) {
  size_t n = strlen(path), e = strlen(ext);
  return n >= e && !strcasecmp(path + n - e, ext);
}

// the formats: how the input is told (by the file name, then the text) and read. A new input
// format is one row here and one reader above.
typedef struct load_format {
  vd_plant_format id;
  const char* ext;  // file name ending (NULL: the default, L-Py)
  int json;         // JSON text: the "format" field tells the row (json_format)
} load_format;

static const load_format formats[] = {
    {VD_PLANT_FORMAT_JSON, ".json", 1},
    {VD_PLANT_FORMAT_LPY, NULL, 0},
};

static vd_status load_any(const load_input* in0, const vd_plant_load_def* def, vd_plant_spec** out,
                          vd_plant_load_info* info, vd_error* err) {
  vd_plant_load_def d0 = vd_plant_load_def_default();
  const vd_plant_load_def* d = def ? def : &d0;
  load_input in = *in0;
  // which row: by the name's ending, or for text by its first character
  const load_format* f = &formats[sizeof formats / sizeof *formats - 1];
  for (size_t k = 0; k + 1 < sizeof formats / sizeof *formats; k++) {
    const char* p = in.text;
    while (!in.path && p < in.text + in.len && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) p++;
    if (in.path ? has_ext(in.path, formats[k].ext) : formats[k].json && p < in.text + in.len && *p == '{') {
      f = &formats[k];
      break;
    }
  }
  vd_status st = VD_OK;
  char* text = NULL;
  size_t len = 0;
  info->format = f->id;
  if (f->id != VD_PLANT_FORMAT_LPY && in.path) {
    if ((st = vd_file_read(in.path, &text, &len, err))) return st;
    in.text = text, in.len = len;
  }
  if (f->json) info->format = json_format(in.text, in.len);
  switch (info->format) {
    case VD_PLANT_FORMAT_LPY: st = load_lpy(&in, d, out, info, err); break;
    case VD_PLANT_FORMAT_JSON: st = load_json(&in, d, out, err); break;
    case VD_PLANT_FORMAT_CURVES: st = load_curves(&in, d, out, err); break;
    default: st = vd_error_set(err, VD_ERR_FORMAT, in.name, 0, 0, "unknown plant format"); break;
  }
  if (text) vd_free(text, len + 1);
  if (!st && info->format != VD_PLANT_FORMAT_LPY && (st = name_plant(d, 0, *out)))
    vd_error_set(err, st, in.name, 0, 0, "out of memory");
  return st;
}

static vd_status load_done(vd_status st, vd_plant_spec** out, vd_plant_load_info* mine, vd_plant_load_info* info) {
  if (st) {
    vd_plant_spec_destroy(*out);
    *out = NULL;
    vd_plant_load_info_free(mine);
  }
  if (info) *info = *mine;
  else vd_plant_load_info_free(mine);
  return st;
}

vd_status vd_plant_load(const char* path, const vd_plant_load_def* def, vd_plant_spec** out,
                        vd_plant_load_info* info, vd_error* err) {
  *out = NULL;
  vd_plant_load_info mine;
  memset(&mine, 0, sizeof mine);
  load_input in = {path, NULL, 0, path};
  return load_done(load_any(&in, def, out, &mine, err), out, &mine, info);
}

vd_status vd_plant_load_text(const char* text, size_t len, const char* name, const vd_plant_load_def* def,
                             vd_plant_spec** out, vd_plant_load_info* info, vd_error* err) {
  *out = NULL;
  vd_plant_load_info mine;
  memset(&mine, 0, sizeof mine);
  load_input in = {name ? name : "<string>", text, len, NULL};
  return load_done(load_any(&in, def, out, &mine, err), out, &mine, info);
}
