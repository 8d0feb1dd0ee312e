// SPDX-License-Identifier: MIT
// Shared pieces of the verdant command: exit codes, error reports, plant options, loading a
// plant from an .lpy file or a plant file, the progress bar.
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"

int cli_exit_code(vd_status st) {
  switch (st) {
    case VD_OK: return EXIT_OK;
    case VD_ERR_NOMEM: return EXIT_FAIL;
    default: return EXIT_USAGE;  // syntax, unsupported, names, types, values, limits, formats, I/O on inputs
  }
}

int cli_report(const char* cmd, const vd_error* err, vd_status st) {
  char buf[1024];
  if (err && err->status != VD_OK)
    fprintf(stderr, "verdant %s: %s\n", cmd, vd_error_format(err, buf, sizeof buf));
  else
    fprintf(stderr, "verdant %s: %s\n", cmd, vd_status_str(st));
  return cli_exit_code(st);
}

void cli_blame_input(vd_error* err, const char* path) {
  if (err && err->status != VD_OK && !err->file[0] && path) snprintf(err->file, sizeof err->file, "%s", path);
}

int cli_usage_error(const char* cmd, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "verdant %s: ", cmd);
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\n(see 'verdant %s --help')\n", cmd);
  va_end(ap);
  return EXIT_USAGE;
}

// ---------------------------------------------------------------------------------------------
// interrupts: the output layer removes what the run wrote (only async-signal-safe calls there)

static void on_signal(int sig) {
  cli_out_rollback();  // temporary files and folders made; an earlier run is left as it was
  signal(sig, SIG_DFL);
  raise(sig);
}

void cli_signals_init(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGINT);
  sigaddset(&sa.sa_mask, SIGTERM);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

double cli_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cli_has_ext(const char* path, const char* ext) {
  size_t n = strlen(path), e = strlen(ext);
  return n >= e && strcasecmp(path + n - e, ext) == 0;
}

// the derived L-string as JSON (--lstring): module names and parameters (numbers or strings),
// written through the output layer (vd_outfile)
static vd_status write_lstring_json(const char* path, const vd_lsystem* ls, const vd_lstring* s, vd_error* err) {
  vd_outfile out;
  vd_status st = vd_outfile_open(&out, path, err);
  if (st) return st;
  FILE* f = out.fp;
  fprintf(f, "{\"format\": \"verdant-lstring\", \"version\": 1, \"modules\": [");
  for (int64_t i = 0; i < s->n; i++) {
    fputs(i ? ",\n[" : "\n[", f);
    const char* name = vd_lsys_symbol_name(ls, s->sym[i]);
    fputc('"', f);
    for (const char* c = name; *c; c++) {
      if (*c == '"' || *c == '\\') fputc('\\', f);
      fputc(*c, f);
    }
    fputc('"', f);
    for (int64_t k = s->par[i]; k < s->par[i + 1]; k++) {
      double v = s->val[k];
      const char* str = vd_lsys_value_str(ls, v);
      if (str) {
        fputs(", \"", f);
        for (const char* c = str; *c; c++) {
          if (*c == '"' || *c == '\\') fputc('\\', f);
          if ((unsigned char)*c < 32) fprintf(f, "\\u%04x", (unsigned char)*c);
          else fputc(*c, f);
        }
        fputc('"', f);
      } else if (isfinite(v)) {
        fprintf(f, ", %.17g", v);
      } else {
        fputs(", null", f);  // an object of the Python engine, or a non-finite number
      }
    }
    fputc(']', f);
  }
  fputs("\n]}\n", f);
  return vd_outfile_commit(&out, err);
}

// the files a --frames pattern writes, as an fnmatch pattern (the %d field any text); 0 when
// it does not fit
static int frames_glob(const char* name, char* buf, size_t cap) {
  size_t k = 0;
  for (const char* c = name; *c && k + 2 < cap; c++) {
    if (c[0] == '%' && c[1] == '%') {
      buf[k++] = '%', c++;
    } else if (c[0] == '%') {
      while (c[1] && c[1] != 'd') c++;
      buf[k++] = '*';
      if (c[1]) c++;
    } else {
      if (strchr("*?[\\", *c)) buf[k++] = '\\';
      buf[k++] = *c;
    }
  }
  buf[k] = 0;
  return k + 2 < cap;
}

void cli_out_plant_opts(const cli_plant_opts* o) {
  cli_out_input("PLANT", o->path);
  if (o->lstring_out) cli_out_file("--lstring", o->lstring_out);
  if (o->frames) {
    // the frames' folder, every name the pattern makes (and their .mtl for OBJ)
    const char* slash = strrchr(o->frames, '/');
    char dir[4200], glob[2][4200];
    if (!slash)
      snprintf(dir, sizeof dir, ".");
    else
      snprintf(dir, sizeof dir, "%.*s", slash == o->frames ? 1 : (int)(slash - o->frames), o->frames);
    int n = frames_glob(slash ? slash + 1 : o->frames, glob[0], sizeof glob[0]) ? 1 : 0;
    if (n && cli_has_ext(glob[0], ".obj")) {
      size_t len = strlen(glob[0]);
      memcpy(glob[1], glob[0], len - 4);
      memcpy(glob[1] + len - 4, ".mtl", 5);
      n = 2;
    }
    const char* members[2] = {glob[0], glob[1]};
    cli_out_pattern("--frames", o->frames, dir, members, n, 0);
  }
}

const char* cli_plant_help =
    "  -n, --steps N         derivation steps (default: the file's `derivation length`)\n"
    "      --seed S          random seed, as random.seed(S) before the axiom (default 0)\n"
    "      --set NAME=VALUE  replace a global of the .lpy file (repeatable)\n"
    "      --label ID=NAME   name a label id (repeatable; the file's LABELS come first)\n"
    "      --max-modules N   largest L-string allowed (default 50000000)\n"
    "      --max-ops N       interpreter work allowed: loop iterations + calls (default 1e9)\n"
    "      --engine E        who runs the file's Python: auto (default: native when the file\n"
    "                        stays in the native subset, else python), native, python\n"
    "      --lstring FILE    .lpy files: also write the derived L-string (before interpretation)\n"
    "                        as JSON: {\"modules\": [[\"A\", 1, 2], [\"[\"], ...]}\n"
    "      --curve-step M    curves files: dense sampling step (m; default 0.001)\n"
    "      --curve-connect M curves files: largest branch gap, sigma_connect (m; default 0.01)\n"
    "      --curve-distance M\n"
    "                        curves files: segment length, sigma_distance (m; default 0.02);\n"
    "                        the file's \"settings\" replace the defaults, these flags the file's\n"
    "      --instances MODE  what an instance is: organs (default for .lpy files: one per organ\n"
    "                        as a botanist names it, a pedicel with its knuckle is one) or\n"
    "                        modules (one per L-string module); plant files keep theirs unless given\n"
    "      --no-progress     no progress bar (it shows only when stderr is a terminal)\n";

void cli_plant_opts_init(cli_plant_opts* o) {
  memset(o, 0, sizeof *o);
  o->steps = -1;
  o->seed = 0;
  o->max_modules = 50000000;
  o->progress = isatty(2);
  o->curve_step = o->curve_connect = o->curve_distance = -1;
  o->instances = -1;
}

int cli_parse_num(const char* s, double* out) {
  if (!s || !*s) return 0;
  char* end;
  errno = 0;
  double x = strtod(s, &end);
  if (end == s || *end || errno || !isfinite(x)) return 0;
  *out = x;
  return 1;
}

// strict integer parsing: the whole text, within [lo, hi]
int cli_parse_i64(const char* s, int64_t lo, int64_t hi, int64_t* out) {
  if (!s || !*s) return 0;
  char* end;
  errno = 0;
  long long v = strtoll(s, &end, 10);
  if (errno || *end || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

int cli_parse_i64_pair(const char* s, char sep, int64_t lo, int64_t hi, int64_t* a, int64_t* b) {
  const char* at = s ? strchr(s, sep) : NULL;
  char head[32];
  size_t n = at ? (size_t)(at - s) : 0;
  if (!at || n >= sizeof head) return 0;
  memcpy(head, s, n);
  head[n] = 0;
  return cli_parse_i64(head, lo, hi, a) && cli_parse_i64(at + 1, lo, hi, b);
}

int cli_plant_opt(cli_plant_opts* o, const char* cmd, int argc, char** argv, int* i) {
  const char* a = argv[*i];
  const char* val = NULL;
  int64_t v;
  if (!strcmp(a, "-n") || !strcmp(a, "--steps")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 0, 1000000000, &v)) {
      cli_usage_error(cmd, "%s expects an integer >= 0, got '%s'", a, val);
      return -1;
    }
    o->steps = (int)v;
    return 1;
  }
  if (!strcmp(a, "--seed")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 0, INT64_MAX, &v)) {
      cli_usage_error(cmd, "--seed expects an integer >= 0, got '%s'", val);
      return -1;
    }
    o->seed = (uint64_t)v;
    return 1;
  }
  if (!strcmp(a, "--max-modules")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 1, INT64_MAX / 64, &v)) {
      cli_usage_error(cmd, "--max-modules expects an integer >= 1, got '%s'", val);
      return -1;
    }
    o->max_modules = v;
    return 1;
  }
  if (!strcmp(a, "--lstring")) {
    CLI_TAKE();
    o->lstring_out = val;
    return 1;
  }
  if (!strcmp(a, "--engine")) {
    CLI_TAKE();
    if (!strcmp(val, "auto")) o->engine = VD_LSYS_AUTO;
    else if (!strcmp(val, "native")) o->engine = VD_LSYS_NATIVE;
    else if (!strcmp(val, "python")) o->engine = VD_LSYS_PYTHON;
    else {
      cli_usage_error(cmd, "--engine expects auto, native or python, got '%s'", val);
      return -1;
    }
    return 1;
  }
  if (!strcmp(a, "--max-ops")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 1, INT64_MAX, &v)) {
      cli_usage_error(cmd, "--max-ops expects an integer >= 1, got '%s'", val);
      return -1;
    }
    o->max_ops = v;
    return 1;
  }
  if (!strcmp(a, "--set") || !strcmp(a, "--label")) {
    CLI_TAKE();
    const char* eq = strchr(val, '=');
    if (!eq || eq == val || !eq[1]) {
      cli_usage_error(cmd, "%s expects %s, got '%s'", a, a[2] == 's' ? "NAME=VALUE" : "ID=NAME", val);
      return -1;
    }
    if (a[2] == 's') {
      if (o->nset == 64) {
        cli_usage_error(cmd, "too many --set options (64 at most)");
        return -1;
      }
      o->set[o->nset++] = val;
    } else {
      char idbuf[32];
      size_t n = (size_t)(eq - val);
      if (n >= sizeof idbuf || !cli_parse_i64((memcpy(idbuf, val, n), idbuf[n] = 0, idbuf), 0, 65535, &v)) {
        cli_usage_error(cmd, "--label expects ID=NAME with an integer ID in 0..65535, got '%s'", val);
        return -1;
      }
      if (o->nlabel == 64) {
        cli_usage_error(cmd, "too many --label options (64 at most)");
        return -1;
      }
      o->label[o->nlabel++] = val;
    }
    return 1;
  }
  if (!strcmp(a, "--curve-step") || !strcmp(a, "--curve-connect") || !strcmp(a, "--curve-distance")) {
    CLI_TAKE();
    char* end;
    errno = 0;
    double x = strtod(val, &end);
    int step = a[8] == 's';
    if (errno || *end || !(x >= (step ? 1e-6 : 0)) || !(x <= 1e3)) {
      cli_usage_error(cmd, "%s expects a length in metres%s, got '%s'", a, step ? " >= 1e-6" : " >= 0", val);
      return -1;
    }
    *(step ? &o->curve_step : a[8] == 'c' ? &o->curve_connect : &o->curve_distance) = x;
    return 1;
  }
  if (!strcmp(a, "--no-progress")) {
    o->progress = 0;
    return 1;
  }
  if (!strcmp(a, "--instances")) {
    CLI_TAKE();
    if (!strcmp(val, "organs")) o->instances = VD_INSTANCE_ORGANS;
    else if (!strcmp(val, "modules")) o->instances = VD_INSTANCE_MODULES;
    else {
      cli_usage_error(cmd, "--instances expects organs or modules, got '%s'", val);
      return -1;
    }
    return 1;
  }
  return 0;
}

void cli_progress_bar(const char* what, double frac, const char* text) {
  int w = 30, fill = (int)(frac * w + 1e-6);
  if (!(fill >= 0)) fill = 0;
  if (fill > w) fill = w;
  char bar[64];
  for (int k = 0; k < w; k++) bar[k] = k < fill ? '#' : ' ';
  bar[w] = 0;
  fprintf(stderr, "\r%s [%s] %s", what, bar, text);
  fflush(stderr);
}

int cli_progress_due(cli_progress* p) {
  if (!p->on) return 0;
  double now = cli_now();
  if (p->shown && now - p->last < 0.1) return 0;
  p->shown = 1, p->last = now;
  return 1;
}

void cli_progress_clear(void) {
  fputs("\r\033[K", stderr);
  fflush(stderr);
}

void cli_progress_end(cli_progress* p) {
  if (p->shown) cli_progress_clear();
  p->shown = 0;
}

// progress bar on stderr: only when it is a terminal
static int progress_cb(void* user, int step, int steps, int64_t modules) {
  (void)user;
  int w = 30, fill = steps > 0 ? (int)((double)step / steps * w) : w;
  char bar[64];
  for (int k = 0; k < w; k++) bar[k] = k < fill ? '#' : ' ';
  bar[w] = 0;
  fprintf(stderr, "\rderiving [%s] step %d/%d, %lld modules", bar, step, steps, (long long)modules);
  if (step == steps) cli_progress_clear();
  fflush(stderr);
  return 0;
}

int cli_frame_name(const char* pattern, int frame, char* buf, size_t cap) {
  size_t n = 0;
  int fields = 0;
  for (const char* p = pattern; *p; p++) {
    char piece[32];
    const char* text = piece;
    if (*p != '%') {
      piece[0] = *p, piece[1] = 0;
    } else if (p[1] == '%') {
      piece[0] = '%', piece[1] = 0;
      p++;
    } else {
      // %d, %Nd or %0Nd with N < 10
      const char* q = p + 1;
      int zero = *q == '0';
      if (zero) q++;
      int width = 0;
      if (*q >= '1' && *q <= '9') width = *q++ - '0';
      if (*q != 'd' || fields++) return 0;
      snprintf(piece, sizeof piece, zero ? "%0*d" : "%*d", width, frame);
      p = q;
    }
    size_t k = strlen(text);
    if (n + k >= cap) return 0;
    memcpy(buf + n, text, k + 1);
    n += k;
  }
  return fields == 1;
}

// the plant options as the library's settings (vd_plant_load_def); the strings point into o and b
typedef struct load_bufs {
  char set_name[64][128];
  const char* set_name_p[64];
  const char* set_value[64];
  int label_id[64];
  const char* label_name[64];
} load_bufs;

static void load_def(const cli_plant_opts* o, load_bufs* b, vd_plant_load_def* d) {
  *d = vd_plant_load_def_default();
  d->lsys.steps = o->steps;
  d->lsys.seed = o->seed;
  d->lsys.max_modules = o->max_modules;
  d->lsys.max_ops = o->max_ops;
  if (o->progress) d->lsys.progress = progress_cb;
  d->engine = (vd_lsys_engine)o->engine;
  for (int i = 0; i < o->nset; i++) {  // NAME=VALUE, checked by cli_plant_opt
    const char* eq = strchr(o->set[i], '=');
    size_t n = (size_t)(eq - o->set[i]);
    if (n >= sizeof b->set_name[i]) n = sizeof b->set_name[i] - 1;
    memcpy(b->set_name[i], o->set[i], n);
    b->set_name[i][n] = 0;
    b->set_name_p[i] = b->set_name[i];
    b->set_value[i] = eq + 1;
  }
  d->set_name = b->set_name_p, d->set_value = b->set_value, d->nset = o->nset;
  for (int i = 0; i < o->nlabel; i++) {  // ID=NAME, checked by cli_plant_opt
    b->label_id[i] = (int)strtol(o->label[i], NULL, 10);
    b->label_name[i] = strchr(o->label[i], '=') + 1;
  }
  d->label_id = b->label_id, d->label_name = b->label_name, d->nlabel = o->nlabel;
  d->curve_step = o->curve_step, d->curve_connect = o->curve_connect, d->curve_distance = o->curve_distance;
  d->instances = o->instances < 0 ? VD_INSTANCE_DEFAULT : o->instances;
  d->animate = o->animate;
  d->call = o->call, d->ncall = o->ncall;
}

// an animation's frames written as they come (--frames); the loader names them as the plant
typedef struct frame_writer {
  const cli_plant_opts* o;
  vd_error* err;
  vd_status st;
  int last;  // frames written: 0..last-1
} frame_writer;

static int write_frame(void* user, int frame, const vd_lstring* s, const vd_plant_spec* plant) {
  (void)s;
  frame_writer* w = user;
  char path[4200];
  if (!cli_frame_name(w->o->frames, frame, path, sizeof path)) {
    w->st = vd_error_set(w->err, VD_ERR_ARG, w->o->frames, 0, 0, "frame %d: the file name is too long", frame);
    return 1;
  }
  w->st = cli_write_plant(plant, path, 0, w->err);
  if (!w->st) w->last = frame + 1;
  return w->st != VD_OK;
}

// --lstring: the derived string, unless a frame failed
static vd_status write_derived(void* user, const vd_lsystem* ls, const vd_lstring* s, vd_error* err) {
  const frame_writer* w = user;
  return w->st ? w->st : write_lstring_json(w->o->lstring_out, ls, s, err);
}

vd_status cli_load_lsystem(const cli_plant_opts* o, vd_lsystem** out, vd_error* err) {
  load_bufs b;
  vd_plant_load_def d;
  load_def(o, &b, &d);
  return vd_plant_load_lsystem(o->path, &d, out, err);
}

vd_status cli_load_plant(const cli_plant_opts* o, vd_plant_spec** out, cli_grow_info* info, vd_error* err) {
  memset(info, 0, sizeof *info);
  *out = NULL;
  // a file of another kind says what it is (not an L-Py syntax error in a mesh)
  char kind_buf[160];
  const char* kind = cli_not_a_plant(o->path, kind_buf, sizeof kind_buf);
  if (kind)
    return vd_error_set(err, VD_ERR_FORMAT, o->path, 0, 0, "%s, not a plant: verdant takes an .lpy file or a plant .json",
                        kind);
  load_bufs b;
  vd_plant_load_def d;
  load_def(o, &b, &d);
  frame_writer fw = {o, err, VD_OK, 0};
  if (o->frames) d.lsys.frame = write_frame, d.lsys.frame_user = &fw;
  if (o->lstring_out) d.derived = write_derived, d.user = &fw;
  vd_status st = vd_plant_load(o->path, &d, out, info, err);
  if (fw.st && !st) {
    st = fw.st;
    vd_plant_spec_destroy(*out);
    *out = NULL;
    vd_plant_load_info_free(info);
  }
  if (!st && info->format == VD_PLANT_FORMAT_LPY && !info->modules && !info->axiom_line)
    fprintf(stderr, "verdant: %s:1:1: warning: the file has no Axiom: line, so its L-string starts empty and the "
            "plant is empty\n", o->path);
  return st;
}
