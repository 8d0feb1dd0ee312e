// SPDX-License-Identifier: MIT
// verdant sim: a plant as Cosserat rods under gravity, wind, probes and pulls; frames, events,
// the final plant and a JSON summary.
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

static const char* sim_help =
    "usage: verdant sim PLANT [-o DIR] [options]\n"
    "\n"
    "Simulate a plant (.lpy or plant .json) as Cosserat rods (XPBD, direct tree solver) and\n"
    "write frames, fracture events and the final plant to DIR; --stats prints a JSON summary.\n"
    "With --grow the L-system grows the plant age step by age step with physics in between\n"
    "(mass-spring trees, with a rigid part, or rods): 'verdant sim --grow --help'.\n"
    "\n"
    "run:\n"
    "  -o, --output DIR        write DIR/frames.bin (or .jsonl), DIR/colliders.jsonl,\n"
    "                          DIR/rod.json, DIR/plant_initial.json, DIR/events.csv,\n"
    "                          DIR/plant.json (the final plant); 'verdant render DIR' draws it\n"
    "      --duration T        simulated time (s); default 1, or 0 after --settle/--statics\n"
    "      --dt H              time step (s), default 0.001\n"
    "      --iterations N      Newton iterations (direct) or sweeps (gs) per step, default 1\n"
    "      --threads N         threads for one plant's step (default 1): the direct solver's\n"
    "                          subtrees; the same bytes for any N\n"
    "      --solver S          direct (exact tree solve, default) or gs (XPBD Gauss-Seidel)\n"
    "      --settle            first run damped dynamics until the plant is still\n"
    "      --statics           first solve the static equilibrium directly\n"
    "      --ke-tol E          --settle stops when the kinetic energy stays below E (J), 1e-9\n"
    "      --sag-free          rest shape solved so that the modelled shape is the equilibrium\n"
    "      --stake S           tie the main stem to a fixed stake every S metres (greenhouse string)\n"
    "      --max-steps N       most time steps of a run, duration / dt (default 1000000000)\n"
    ;
static const char* sim_help_model =
    "model:\n"
    "      --segment-length [C=]S  rod segment length sigma_distance (m), default 0.02, or of\n"
    "                          class C only (e.g. wood=0.05; model reduction)\n"
    "      --active-radius R   region of interest (model reduction): only segments within R (m) of\n"
    "                          --active-center X,Y,Z, of --active-organ ORGAN[#I] or else of the\n"
    "                          first --probe's path are simulated; the rest is held as modelled\n"
    "      --leaves M          leaf blades as rod graphs (graph: midrib and two side veins,\n"
    "                          default), the midrib alone (midrib) or rigid on their node (rigid)\n"
    "      --leaf-segments K   segments per leaf vein (e.g. 2 or 3; default: by segment length)\n"
    "      --clamp L           the pot: the first L of the plant's base held fixed (m), default\n"
    "                          0.01; 0 holds only the base node and its frame (a clamped end)\n"
    "      --max-segments N    most rod segments of the model (default 1000000, about 2 kB each)\n"
    "      --bend-measure M    bend-twist strain: log (rotation vector, default) or quat\n"
    "                          (Kugelstadt & Schomer's Im(q), the model before 2026-11)\n"
    "      --young [C=]E       Young's modulus (Pa) of all classes, or of class C\n"
    "      --density [C=]RHO   density (kg/m^3); --poisson [C=]NU Poisson ratio\n"
    "                          classes: green wood pedicel leaf fruit flower root\n"
    "      --break-force [C=]F     joints break above this force (N); 'inf' disables\n"
    "      --break-moment [C=]M    ... or above this moment (N m)\n"
    "      --break-strain [C=]CS,CB  ... or when |C_s| > CS or |C_b| > CB (1/m), Gazebo Plants' form\n"
    "      --no-fracture       nothing breaks\n"
    ;
static const char* sim_help_loads =
    "loads:\n"
    "      --gravity X,Y,Z     gravity (m/s^2), default 0,0,-9.81\n"
    "      --wind X,Y,Z        mean wind (m/s); pressure 0.613 |v|^2 Pa on the drag areas\n"
    "      --gust A,P          gusts: wind * (1 + A sin(2 pi t / P)), P in s\n"
    "      --wind-file CSV     wind time series: rows t,vx,vy,vz (s, m/s), replaces --wind\n"
    "      --no-drag           no aerodynamic forces at all (no wind, no air drag)\n"
    "      --stokes ETA        extra Stokes drag 6 pi ETA r v (Pa s): numerical damping only\n"
    "      --damping TAU       material (stiffness-proportional) damping time (s), default 0\n"
    "      --mass-damping C    velocity damping rate (1/s), default 0\n"
    "contacts and probes:\n"
    "      --ground Z          ground plane at height Z (m), default 0; --no-ground for none\n"
    "      --collider-mesh FILE[:X,Y,Z]\n"
    "                          closed triangle mesh (.obj, counter-clockwise from outside) as a\n"
    "                          fixed collider, its origin placed at X,Y,Z (m); repeatable\n"
    "      --self-collision    capsules and fruits collide with each other (neighbours and parts\n"
    "                          touching in the modelled shape excluded); off by default\n"
    "                          (--no-self-collision)\n"
    "      --probe R:X0,Y0,Z0:X1,Y1,Z1[:T0:T1]\n"
    "                          kinematic sphere of radius R (m) moving from P0 to P1 (m) between\n"
    "                          T0 and T1 (s, default the whole run); repeatable\n"
    "      --pull ORGAN=FX,FY,FZ   force (N) on an organ (LABEL or LABEL#INSTANCE, e.g. fruit#12),\n"
    "                          ramped from 0 over --ramp seconds; repeatable\n"
    "      --move ORGAN=DX,DY,DZ   displace an organ (m) by a stiff tie, ramped over --ramp\n"
    "      --ramp T            ramp time of pulls and moves (s); default the run's duration\n"
    ;
// (in two parts: C99 compilers need only take string literals up to 4095 bytes)
static const char* sim_help_output =
    "soil:\n"
    "      --soil S            roots held by a soil (loam, sandy-loam, clay, singapore-residual;\n"
    "                          docs/physics.md) instead of clamped (no ground plane then);\n"
    "                          clamp (default) holds them\n"
    "output:\n"
    "      --frames F          bin (default), jsonl or none\n"
    "      --fps N             frames per simulated second, default 30\n"
    "      --final FILE        also write the final plant as .json, .obj or .ply\n"
    "      --stats             print a JSON summary on stdout: max_displacement (m, all nodes from\n"
    "                          their initial positions), tip_displacement (m, end of the main\n"
    "                          axis), kinetic_energy (J), events, ...; the same bytes for the\n"
    "                          same inputs\n"
    "      --batch N           run N plants side by side: item i grown with the seed drawn from\n"
    "                          (--seed, i) as dataset does (the same plant N times for a plant\n"
    "                          file); --stats prints one record per item, -o DIR writes\n"
    "                          DIR/item_NNNNNN/ (plant.json, events.csv); frames are not written\n"
    "      --jobs J            items run at once (threads), default 1\n"
    "      --profile           time each stage of the steps and the frame output; --stats then\n"
    "                          has wall_seconds, steps_per_second, real_time_factor and\n"
    "                          stage_seconds (forces, predict, contacts, eval, factor, solve,\n"
    "                          project, velocity, fracture, frames)\n";

// a closed triangle mesh from a Wavefront OBJ file: "v x y z" and "f i j k ..." lines (1-based
// or negative indices, "i/t/n" forms, polygons split in fans); other lines are skipped
static vd_status read_obj(const char* path, double** vert, int* nvert, int** tri, int* ntri, vd_error* err) {
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  int capv = 0, nv = 0, capt = 0, nt = 0, line = 0;
  double* v = NULL;
  int* t = NULL;
  char* p = text;
  while (*p && !st) {
    line++;
    char* e = strchr(p, '\n');
    if (e) *e = 0;
    char* s = p;
    while (*s == ' ' || *s == '\t') s++;
    if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
      double x[3];
      char* q = s + 1;
      for (int k = 0; k < 3 && !st; k++) {
        char* end;
        x[k] = strtod(q, &end);
        if (end == q || !isfinite(x[k]))
          st = vd_error_set(err, VD_ERR_FORMAT, path, line, (int)(q - p) + 1, "expected a vertex coordinate (m)");
        q = end;
      }
      if (!st && !vd_grow((void**)&v, &capv, nv + 1, 3 * sizeof(double)))
        st = vd_error_set(err, VD_ERR_NOMEM, path, line, 0, "out of memory");
      if (!st) memcpy(v + 3 * nv++, x, sizeof x);
    } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
      int idx[3], k = 0;
      char* q = s + 1;
      for (;;) {
        while (*q == ' ' || *q == '\t' || *q == '\r') q++;
        if (!*q) break;
        char* end;
        long i = strtol(q, &end, 10);
        if (end == q || i == 0 || (i > 0 && i > nv) || (i < 0 && -i > nv)) {
          st = vd_error_set(err, VD_ERR_FORMAT, path, line, (int)(q - p) + 1,
                            "expected a vertex index in 1..%d or -%d..-1", nv, nv);
          break;
        }
        int vi = i > 0 ? (int)i - 1 : nv + (int)i;
        while (*end && *end != ' ' && *end != '\t' && *end != '\r') end++;  // skip "/t/n"
        q = end;
        if (k < 2) {
          idx[k++] = vi;
          continue;
        }
        idx[2] = vi;
        if (!vd_grow((void**)&t, &capt, nt + 1, 3 * sizeof(int))) {
          st = vd_error_set(err, VD_ERR_NOMEM, path, line, 0, "out of memory");
          break;
        }
        memcpy(t + 3 * nt++, idx, sizeof idx);
        idx[1] = vi;  // fan
        k = 3;
      }
      if (!st && k < 3) st = vd_error_set(err, VD_ERR_FORMAT, path, line, 1, "a face needs at least 3 vertices");
    }
    p = e ? e + 1 : p + strlen(p);
  }
  vd_free(text, len + 1);
  if (!st && !nt) st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "no faces ('f' lines) in the mesh");
  if (st) {
    vd_free(v, (size_t)capv * 3 * sizeof(double));
    vd_free(t, (size_t)capt * 3 * sizeof(int));
    return st;
  }
  *vert = v, *nvert = nv, *tri = t, *ntri = nt;
  // shrink to the exact sizes so the caller frees nv and nt rows
  double* v2 = vd_realloc(v, (size_t)capv * 3 * sizeof(double), (size_t)nv * 3 * sizeof(double));
  if (v2) *vert = v2;
  int* t2 = vd_realloc(t, (size_t)capt * 3 * sizeof(int), (size_t)nt * 3 * sizeof(int));
  if (t2) *tri = t2;
  if (!v2 || !t2) {
    vd_free(v2 ? v2 : v, v2 ? (size_t)nv * 3 * sizeof(double) : (size_t)capv * 3 * sizeof(double));
    vd_free(t2 ? t2 : t, t2 ? (size_t)nt * 3 * sizeof(int) : (size_t)capt * 3 * sizeof(int));
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  }
  return VD_OK;
}

// the distance grid of a mesh file; errors name the file
static vd_status load_mesh_sdf(const char* path, vd_sdf** out, vd_error* err) {
  if (!cli_has_ext(path, ".obj"))
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "--collider-mesh reads Wavefront .obj files");
  double* v = NULL;
  int* t = NULL;
  int nv = 0, nt = 0;
  vd_status st = read_obj(path, &v, &nv, &t, &nt, err);
  if (st) return st;
  // grid spacing 2 mm, coarser for meshes over 0.256 m so the grid stays near 128 cells across
  vd_sdf_def def = vd_sdf_def_default();
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, ext = 0;
  for (int i = 0; i < nv; i++)
    for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], v[3 * i + k]), hi[k] = fmax(hi[k], v[3 * i + k]);
  for (int k = 0; k < 3; k++) ext = fmax(ext, hi[k] - lo[k]);
  if (ext / 128 > def.cell) def.cell = ext / 128, def.band = 3 * def.cell, def.padding = 5 * def.cell;
  st = vd_sdf_build(v, nv, t, nt, &def, out, err);
  if (st && !err->file[0]) snprintf(err->file, sizeof err->file, "%s", path);
  vd_free(v, (size_t)nv * 3 * sizeof(double));
  vd_free(t, (size_t)nt * 3 * sizeof(int));
  return st;
}

// ---------------------------------------------------------------------------------------------
// option values

// a finite number, or inf (a threshold that never fires)
static int parse_num(const char* s, double* out) {
  if (s && (!strcmp(s, "inf") || !strcmp(s, "INF"))) {
    *out = INFINITY;
    return 1;
  }
  return cli_parse_num(s, out);
}

// "a,b,c" -> n numbers
static int parse_list(const char* s, double* out, int n) {
  char buf[256];
  if (!s || strlen(s) >= sizeof buf) return 0;
  strcpy(buf, s);
  char* p = buf;
  for (int i = 0; i < n; i++) {
    char* c = i < n - 1 ? strchr(p, ',') : NULL;
    if (i < n - 1 && !c) return 0;
    if (c) *c = 0;
    if (!parse_num(p, &out[i]) || !isfinite(out[i])) return 0;
    p = c ? c + 1 : p + strlen(p);
  }
  return 1;
}

typedef struct probe {
  double r;
  vd_vec3 p0, p1;
  double t0, t1;  // t1 < 0: the whole run
  int id;
} probe;

typedef struct pull {
  vd_vec3 v;
  char organ[64];
  int instance;
  int move;  // 0 force, 1 displacement
  int node, tie;
} pull;

typedef struct sim_opts {
  cli_plant_opts po;
  const char* out;
  double duration;
  int duration_set;
  int settle, statics, stats, profile;
  int batch, jobs;
  int active_center_set;  // --active-center given
  pull active_organ;      // --active-organ (organ[0] == 0: none)
  double ke_tol;
  const char* frames;
  double fps;
  const char* final;
  double ground;
  int no_ground;
  probe probe[16];
  int nprobe;
  pull pull[16];
  int npull;
  double ramp;
  int ramp_set;
  const char* wind_file;
  const char* soil;        // --soil PRESET: roots held by the soil instead of clamped
  char mesh_path[8][512];  // --collider-mesh files
  vd_vec3 mesh_pos[8];     // ... and their placements (m)
  int nmesh;
  double max_steps;
  int ke_tol_set, gust_set, fps_set;  // given on the command line (checked against what they need)
  vd_sim_def def;
  vd_sim_opt opt;
} sim_opts;

// class-prefixed value: "C=V" sets class C, "V" sets every class; returns 0 on a bad value
static int class_value(const char* cmd, const char* opt, const char* val, vd_sim_def* def, size_t field, int ncomp,
                       int positive) {
  const char* eq = strchr(val, '=');
  int c0 = 0, c1 = VD_SIM_CLASS_COUNT;
  const char* num = val;
  if (eq) {
    char name[32];
    size_t n = (size_t)(eq - val);
    if (n >= sizeof name) n = sizeof name - 1;
    memcpy(name, val, n);
    name[n] = 0;
    vd_sim_class c = vd_sim_class_parse(name);
    if (c == VD_SIM_CLASS_COUNT) {
      cli_usage_error(cmd, "%s: unknown class '%s' (green, wood, pedicel, leaf, fruit, flower, root)", opt, name);
      return 0;
    }
    c0 = (int)c, c1 = (int)c + 1;
    num = eq + 1;
  }
  double v[2];
  int ok = ncomp == 1 ? parse_num(num, &v[0]) : parse_list(num, v, ncomp);
  for (int k = 0; ok && k < ncomp; k++) ok = positive ? v[k] > 0 : 1;
  if (!ok) {
    cli_usage_error(cmd, "%s expects %s[CLASS=]%s, got '%s'", opt, "", ncomp == 1 ? "NUMBER" : "NUMBER,NUMBER", val);
    return 0;
  }
  for (int c = c0; c < c1; c++) {
    double* dst = (double*)((char*)&def->material[c] + field);
    for (int k = 0; k < ncomp; k++) dst[k] = v[k];
  }
  return 1;
}

static int parse_probe(const char* s, probe* p) {
  char buf[256];
  if (strlen(s) >= sizeof buf) return 0;
  strcpy(buf, s);
  char* part[5];
  int n = 0;
  for (char* q = strtok(buf, ":"); q && n < 5; q = strtok(NULL, ":")) part[n++] = q;
  if (n != 3 && n != 5) return 0;
  double a[3], b[3];
  if (!parse_num(part[0], &p->r) || !(p->r > 0) || !parse_list(part[1], a, 3) || !parse_list(part[2], b, 3)) return 0;
  p->p0 = vd_v3(a[0], a[1], a[2]), p->p1 = vd_v3(b[0], b[1], b[2]);
  p->t0 = 0, p->t1 = -1;
  if (n == 5 && (!parse_num(part[3], &p->t0) || !parse_num(part[4], &p->t1) || !(p->t1 > p->t0) || p->t0 < 0)) return 0;
  return 1;
}

static int parse_pull(const char* s, pull* p, int move) {
  const char* eq = strchr(s, '=');
  if (!eq || eq == s || (size_t)(eq - s) >= sizeof p->organ) return 0;
  memcpy(p->organ, s, (size_t)(eq - s));
  p->organ[eq - s] = 0;
  p->instance = 0;
  char* hash = strchr(p->organ, '#');
  if (hash) {
    char* end;
    long v = strtol(hash + 1, &end, 10);
    if (*end || v < 1) return 0;
    p->instance = (int)v;
    *hash = 0;
  }
  double v[3];
  if (!parse_list(eq + 1, v, 3)) return 0;
  p->v = vd_v3(v[0], v[1], v[2]);
  p->move = move;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// outputs

static const char* label_name(const vd_model* plant, int id) {
  const vd_label* l = vd_model_find_label(plant, id);
  return l ? l->name : "";
}

static const char* cause_name(int c) {
  static const char* n[4] = {"force", "moment", "strain_cs", "strain_cb"};
  return c >= 0 && c < 4 ? n[c] : "?";
}

static vd_status write_events(const vd_sim_data* d, const vd_model* plant, const char* dir, vd_error* err) {
  char path[4096];
  snprintf(path, sizeof path, "%s/events.csv", dir);
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (st) return st;
  fputs("time_s,segment,node,label,label_name,instance,class,force_N,moment_Nm,cs,cb_per_m,cause\n", f.fp);
  for (int k = 0; k < d->nevent; k++) {
    const vd_sim_event* e = &d->event[k];
    fprintf(f.fp, "%.6f,%d,%d,%d,%s,%d,%s,%.6g,%.6g,%.6g,%.6g,%s\n", e->time, e->seg, e->node, e->label,
            label_name(plant, e->label), e->instance, vd_sim_class_name(e->cls), e->force, e->moment, e->cs, e->cb,
            cause_name(e->cause));
  }
  return vd_outfile_commit(&f, err);
}

// ---------------------------------------------------------------------------------------------
// the summary

static int print_stats(const vd_sim_model* m, const vd_sim_data* d, const vd_model* plant, double wall, int64_t steps,
                       int settled, int settle_steps, double frames_s) {
  cJSON* root = cJSON_CreateObject();
  if (!root) return 0;
  int node;
  double md = vd_sim_max_displacement(m, d, &node);
  double tip = m->main_tip >= 0 ? vd_norm(vd_sub(d->node_pos[m->main_tip], m->node_pos0[m->main_tip])) : 0;
  cJSON_AddNumberToObject(root, "max_displacement", md);
  cJSON_AddNumberToObject(root, "max_displacement_node", node);
  cJSON_AddNumberToObject(root, "tip_displacement", tip);
  cJSON_AddNumberToObject(root, "kinetic_energy", vd_sim_kinetic_energy(m, d));
  cJSON* ev = cJSON_AddArrayToObject(root, "events");
  for (int k = 0; k < d->nevent; k++) {
    const vd_sim_event* e = &d->event[k];
    cJSON* o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "time", e->time);
    cJSON_AddNumberToObject(o, "segment", e->seg);
    cJSON_AddStringToObject(o, "label", label_name(plant, e->label));
    cJSON_AddNumberToObject(o, "instance", e->instance);
    cJSON_AddStringToObject(o, "class", vd_sim_class_name(e->cls));
    cJSON_AddNumberToObject(o, "force", e->force);
    cJSON_AddNumberToObject(o, "moment", e->moment);
    cJSON_AddStringToObject(o, "cause", cause_name(e->cause));
    cJSON_AddItemToArray(ev, o);
  }
  cJSON_AddNumberToObject(root, "nevents", d->nevent);
  cJSON_AddNumberToObject(root, "steps", (double)steps);
  cJSON_AddNumberToObject(root, "time", d->time);
  if (d->profile) {  // timings: only when asked, so that the same inputs print the same bytes
    cJSON_AddNumberToObject(root, "wall_seconds", wall);
    cJSON_AddNumberToObject(root, "steps_per_second", wall > 0 ? (double)steps / wall : 0);
    cJSON_AddNumberToObject(root, "real_time_factor", wall > 0 ? (double)steps * m->opt.dt / wall : 0);
  }
  if (settle_steps >= 0) {
    cJSON_AddBoolToObject(root, "settled", settled);
    cJSON_AddNumberToObject(root, "settle_steps", settle_steps);
  }
  cJSON_AddNumberToObject(root, "nodes", m->nnode);
  cJSON_AddNumberToObject(root, "segments", m->nseg);
  cJSON_AddNumberToObject(root, "total_mass", m->total_mass);
  cJSON_AddNumberToObject(root, "max_penetration", d->max_penetration);
  cJSON_AddNumberToObject(root, "contacts", d->ncontact);
  cJSON_AddNumberToObject(root, "sag_free_out_of_reach", m->nsagfree_clamped);
  cJSON_AddNumberToObject(root, "warnings", (double)d->nwarning);
  cJSON* wk = cJSON_AddObjectToObject(root, "warning_counts");
  for (int k = 0; k < VD_SIM_WARN_COUNT; k++)
    cJSON_AddNumberToObject(wk, vd_sim_warning_name((vd_sim_warning)k), (double)d->warning[k]);
  if (d->profile) {
    cJSON* sg = cJSON_AddObjectToObject(root, "stage_seconds");
    for (int k = 0; k < VD_SIM_STAGE_COUNT; k++)
      cJSON_AddNumberToObject(sg, vd_sim_stage_name((vd_sim_stage)k), d->stage_seconds[k]);
    cJSON_AddNumberToObject(sg, "frames", frames_s);
  }
  char* text = cJSON_Print(root);
  cJSON_Delete(root);
  if (!text) return 0;
  fputs(text, stdout);
  fputc('\n', stdout);
  cJSON_free(text);
  return 1;
}

static void progress_bar(double t, double total, int64_t steps, double wall) {
  char text[128];
  snprintf(text, sizeof text, "%.3f / %.3f s simulated, step %lld, %.1f s", t, total, (long long)steps, wall);
  cli_progress_bar("simulating", total > 0 ? t / total : 1, text);
}

// settling: the share of its budget (10 s simulated or 400 static steps) used so far
typedef struct settle_bar {
  cli_progress bar;
  double t0;
} settle_bar;

static void settle_progress(void* user, double frac, int steps) {
  settle_bar* b = user;
  if (!cli_progress_due(&b->bar)) return;
  char text[96];
  snprintf(text, sizeof text, "step %d, %.1f s (stops when still)", steps, cli_now() - b->t0);
  cli_progress_bar("settling", frac, text);
}

// ---------------------------------------------------------------------------------------------

static int parse_args(int argc, char** argv, sim_opts* o) {
  const char* cmd = "sim";
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    int r = cli_plant_opt(&o->po, cmd, argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    const char* val = NULL;
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      CLI_VAL();
      o->out = val;
    } else if (!strcmp(a, "--duration")) {
      CLI_NUM(o->duration, x_ >= 0, "a time >= 0 (s)");
      o->duration_set = 1;
    } else if (!strcmp(a, "--dt")) {
      CLI_NUM(o->opt.dt, x_ > 0 && x_ <= 1, "a time step in (0, 1] (s)");
    } else if (!strcmp(a, "--iterations")) {
      CLI_NUM(o->opt.iterations, x_ >= 1 && x_ <= 10000 && x_ == floor(x_),
              "an integer in 1..10000");
    } else if (!strcmp(a, "--threads")) {
      CLI_NUM(o->opt.threads, x_ >= 1 && x_ <= 64 && x_ == floor(x_), "an integer in 1..64");
    } else if (!strcmp(a, "--solver")) {
      CLI_VAL();
      if (!strcmp(val, "direct")) o->opt.solver = VD_SIM_DIRECT;
      else if (!strcmp(val, "gs")) o->opt.solver = VD_SIM_GS;
      else return cli_usage_error(cmd, "--solver expects direct or gs, got '%s'", val);
    } else if (!strcmp(a, "--settle")) {
      o->settle = 1;
    } else if (!strcmp(a, "--statics")) {
      o->statics = 1;
    } else if (!strcmp(a, "--ke-tol")) {
      CLI_NUM(o->ke_tol, x_ > 0, "an energy > 0 (J)");
      o->ke_tol_set = 1;
    } else if (!strcmp(a, "--sag-free")) {
      o->def.sag_free = 1;
    } else if (!strcmp(a, "--stake")) {
      CLI_NUM(o->def.stake_spacing, x_ > 0, "a spacing > 0 (m)");
    } else if (!strcmp(a, "--segment-length")) {
      // S for every class, or C=S for class C (model reduction: wood coarser than green stems)
      CLI_VAL();
      const char* eq = strchr(val, '=');
      double x_;
      char name[32];
      size_t nl = eq ? (size_t)(eq - val) : 0;
      if (nl >= sizeof name) nl = sizeof name - 1;
      memcpy(name, val, nl);
      name[nl] = 0;
      vd_sim_class cls = eq ? vd_sim_class_parse(name) : VD_SIM_CLASS_COUNT;
      if (eq && cls == VD_SIM_CLASS_COUNT) return cli_usage_error(cmd, "%s: unknown class '%s'", a, name);
      if (!parse_num(eq ? eq + 1 : val, &x_) || !isfinite(x_) || !(x_ > 0))
        return cli_usage_error(cmd, "%s expects a length > 0 (m) or CLASS=LENGTH, got '%s'", a, val);
      if (eq)
        o->def.class_segment_length[cls] = x_;
      else
        o->def.segment_length = x_;
    } else if (!strcmp(a, "--active-radius")) {
      CLI_NUM(o->def.active_radius, x_ > 0, "a distance > 0 (m)");
    } else if (!strcmp(a, "--active-center")) {
      CLI_VAL();
      double v[3];
      if (!parse_list(val, v, 3)) return cli_usage_error(cmd, "--active-center expects X,Y,Z (m), got '%s'", val);
      o->def.active_a = o->def.active_b = vd_v3(v[0], v[1], v[2]);
      o->active_center_set = 1;
    } else if (!strcmp(a, "--active-organ")) {
      CLI_VAL();
      char spec[80];
      snprintf(spec, sizeof spec, "%s=0,0,0", val);
      if (strlen(val) > 60 || !parse_pull(spec, &o->active_organ, 0))
        return cli_usage_error(cmd, "--active-organ expects ORGAN or ORGAN#INSTANCE, got '%s'", val);
    } else if (!strcmp(a, "--leaves")) {
      CLI_VAL();
      if (!strcmp(val, "graph")) o->def.leaf_graphs = 1;
      else if (!strcmp(val, "midrib")) o->def.leaf_graphs = 2;
      else if (!strcmp(val, "rigid")) o->def.leaf_graphs = 0;
      else return cli_usage_error(cmd, "--leaves expects graph, midrib or rigid, got '%s'", val);
    } else if (!strcmp(a, "--leaf-segments")) {
      CLI_NUM(o->def.leaf_segments, x_ >= 1 && x_ <= 1000 && x_ == floor(x_),
              "an integer in 1..1000");
    } else if (!strcmp(a, "--clamp")) {
      CLI_NUM(o->def.clamp_length, x_ >= 0 && x_ <= 1e3, "a length >= 0 (m)");
    } else if (!strcmp(a, "--max-segments")) {
      CLI_NUM(o->def.max_segments, x_ >= 1 && x_ <= 2e9 && x_ == floor(x_),
              "an integer in 1..2000000000");
    } else if (!strcmp(a, "--bend-measure")) {
      CLI_VAL();
      int b = vd_sim_bend_parse(val);
      if (b < 0) return cli_usage_error(cmd, "--bend-measure expects log or quat, got '%s'", val);
      o->def.bend_measure = (vd_sim_bend)b;
    } else if (!strcmp(a, "--max-steps")) {
      CLI_NUM(o->max_steps, x_ >= 1 && x_ <= 1e15 && x_ == floor(x_), "an integer in 1..1e15");
    } else if (!strcmp(a, "--young")) {
      CLI_VAL();
      if (!class_value(cmd, a, val, &o->def, offsetof(vd_sim_material, young), 1, 1)) return EXIT_USAGE;
    } else if (!strcmp(a, "--density")) {
      CLI_VAL();
      if (!class_value(cmd, a, val, &o->def, offsetof(vd_sim_material, density), 1, 1)) return EXIT_USAGE;
    } else if (!strcmp(a, "--poisson")) {
      CLI_VAL();
      if (!class_value(cmd, a, val, &o->def, offsetof(vd_sim_material, poisson), 1, 0)) return EXIT_USAGE;
    } else if (!strcmp(a, "--break-force")) {
      CLI_VAL();
      if (!class_value(cmd, a, val, &o->def, offsetof(vd_sim_material, break_force), 1, 1)) return EXIT_USAGE;
    } else if (!strcmp(a, "--break-moment")) {
      CLI_VAL();
      if (!class_value(cmd, a, val, &o->def, offsetof(vd_sim_material, break_moment), 1, 1)) return EXIT_USAGE;
    } else if (!strcmp(a, "--break-strain")) {
      CLI_VAL();
      if (!class_value(cmd, a, val, &o->def, offsetof(vd_sim_material, break_cs), 2, 1)) return EXIT_USAGE;
    } else if (!strcmp(a, "--no-fracture")) {
      o->opt.fracture = 0;
    } else if (!strcmp(a, "--gravity") || !strcmp(a, "--wind")) {
      CLI_VAL();
      double v[3];
      if (!parse_list(val, v, 3)) return cli_usage_error(cmd, "%s expects X,Y,Z (%s), got '%s'", a, a[2] == 'g' ? "m/s^2" : "m/s", val);
      for (int k = 0; k < 3; k++)
        if (fabs(v[k]) > (a[2] == 'g' ? 1e4 : VD_SIM_MAX_WIND))
          return cli_usage_error(cmd, "%s expects components within +-%g %s, got '%s'", a,
                                 a[2] == 'g' ? 1e4 : VD_SIM_MAX_WIND, a[2] == 'g' ? "m/s^2" : "m/s", val);
      if (a[2] == 'g') o->opt.gravity = o->def.gravity = vd_v3(v[0], v[1], v[2]);
      else o->opt.wind = vd_v3(v[0], v[1], v[2]);
    } else if (!strcmp(a, "--gust")) {
      CLI_VAL();
      double v[2];
      if (!parse_list(val, v, 2) || !(v[1] > 0)) return cli_usage_error(cmd, "--gust expects AMPLITUDE,PERIOD (-, s > 0), got '%s'", val);
      o->opt.gust_amplitude = v[0], o->opt.gust_period = v[1];
      o->gust_set = 1;
    } else if (!strcmp(a, "--wind-file")) {
      CLI_VAL();
      o->wind_file = val;
    } else if (!strcmp(a, "--no-drag")) {
      o->opt.drag = 0;
    } else if (!strcmp(a, "--stokes")) {
      CLI_NUM(o->opt.stokes_viscosity, x_ >= 0, "a viscosity >= 0 (Pa s)");
    } else if (!strcmp(a, "--damping")) {
      CLI_NUM(o->opt.damping, x_ >= 0, "a time >= 0 (s)");
    } else if (!strcmp(a, "--mass-damping")) {
      CLI_NUM(o->opt.mass_damping, x_ >= 0, "a rate >= 0 (1/s)");
    } else if (!strcmp(a, "--ground")) {
      CLI_NUM(o->ground, 1, "a height (m)");
      o->no_ground = 0;
    } else if (!strcmp(a, "--no-ground")) {
      o->no_ground = 1;
    } else if (!strcmp(a, "--collider-mesh")) {
      CLI_VAL();
      if (o->nmesh == 8) return cli_usage_error(cmd, "too many --collider-mesh options (8 at most)");
      char* m = o->mesh_path[o->nmesh];
      if (strlen(val) >= sizeof o->mesh_path[0]) return cli_usage_error(cmd, "--collider-mesh: path too long");
      strcpy(m, val);
      vd_vec3 at = vd_v3(0, 0, 0);
      char* colon = strrchr(m, ':');
      double x[3];
      if (colon && parse_list(colon + 1, x, 3)) *colon = 0, at = vd_v3(x[0], x[1], x[2]);
      o->mesh_pos[o->nmesh++] = at;
    } else if (!strcmp(a, "--soil")) {
      CLI_VAL();
      vd_soil tmp;
      if (vd_soil_preset(val, &tmp) != VD_OK)
        return cli_usage_error(cmd, "--soil expects clamp, loam, sandy-loam, clay or singapore-residual, got '%s'", val);
      o->soil = val;
    } else if (!strcmp(a, "--self-collision")) {
      o->opt.self_collision = 1;
    } else if (!strcmp(a, "--no-self-collision")) {
      o->opt.self_collision = 0;
    } else if (!strcmp(a, "--probe")) {
      CLI_VAL();
      if (o->nprobe == 16) return cli_usage_error(cmd, "too many --probe options (16 at most)");
      if (!parse_probe(val, &o->probe[o->nprobe]))
        return cli_usage_error(cmd, "--probe expects R:X0,Y0,Z0:X1,Y1,Z1[:T0:T1] (m, s; R > 0, T1 > T0), got '%s'", val);
      o->nprobe++;
    } else if (!strcmp(a, "--pull") || !strcmp(a, "--move")) {
      CLI_VAL();
      if (o->npull == 16) return cli_usage_error(cmd, "too many --pull/--move options (16 at most)");
      if (!parse_pull(val, &o->pull[o->npull], a[2] == 'm'))
        return cli_usage_error(cmd, "%s expects ORGAN[#INSTANCE]=X,Y,Z (%s), got '%s'", a, a[2] == 'm' ? "m" : "N", val);
      o->npull++;
    } else if (!strcmp(a, "--ramp")) {
      CLI_NUM(o->ramp, x_ >= 0, "a time >= 0 (s)");
      o->ramp_set = 1;
    } else if (!strcmp(a, "--frames")) {
      CLI_VAL();
      if (strcmp(val, "bin") != 0 && strcmp(val, "jsonl") != 0 && strcmp(val, "none") != 0)
        return cli_usage_error(cmd, "--frames expects bin, jsonl or none, got '%s'", val);
      o->frames = val;
    } else if (!strcmp(a, "--fps")) {
      CLI_NUM(o->fps, x_ > 0 && x_ <= 100000, "a rate in (0, 100000] (1/s)");
      o->fps_set = 1;
    } else if (!strcmp(a, "--final")) {
      CLI_VAL();
      if (!cli_has_ext(val, ".json") && !cli_has_ext(val, ".obj") && !cli_has_ext(val, ".ply"))
        return cli_usage_error(cmd, "--final '%s': unknown format (use .json, .obj or .ply)", val);
      o->final = val;
    } else if (!strcmp(a, "--stats")) {
      o->stats = 1;
    } else if (!strcmp(a, "--batch")) {
      CLI_NUM(o->batch, x_ >= 1 && x_ <= 1e6 && x_ == floor(x_), "an integer in 1..1000000");
    } else if (!strcmp(a, "--jobs")) {
      CLI_NUM(o->jobs, x_ >= 1 && x_ <= 1024 && x_ == floor(x_), "an integer in 1..1024");
    } else if (!strcmp(a, "--profile")) {
      o->profile = 1;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error(cmd, "unknown option '%s'", a);
    } else if (!o->po.path) {
      o->po.path = a;
    } else {
      return cli_usage_error(cmd, "unexpected argument '%s'", a);
    }
  }
  return EXIT_OK;
}

// options that do nothing without another one are refused, not ignored
static int check_applies(const sim_opts* o) {
  const char* cmd = "sim";
  if (o->frames && !o->out) return cli_usage_error(cmd, "--frames applies to a run folder (-o DIR)");
  if (o->fps_set && (!o->out || (o->frames && !strcmp(o->frames, "none"))))
    return cli_usage_error(cmd, "--fps sets the frame rate of DIR/frames: give -o DIR (and frames other than none)");
  if (o->ramp_set && !o->npull) return cli_usage_error(cmd, "--ramp applies to --pull and --move");
  if (o->ke_tol_set && !o->settle) return cli_usage_error(cmd, "--ke-tol applies to --settle");
  if (o->gust_set && o->wind_file)
    return cli_usage_error(cmd, "--gust does not apply with --wind-file (the series replaces the wind and its gusts)");
  if (o->gust_set && o->opt.wind.x == 0 && o->opt.wind.y == 0 && o->opt.wind.z == 0)
    return cli_usage_error(cmd, "--gust modulates the mean wind: give --wind X,Y,Z");
  return 0;
}

// the files of a run, declared to the output layer and checked: the plant, the wind series and
// collider meshes read; the run folder (an earlier run's files there that this one does not
// write go when it completes) and --final written
static int check_clash(const sim_opts* o) {
  cli_out_plant_opts(&o->po);
  cli_out_input("--wind-file", o->wind_file);
  for (int k = 0; k < o->nmesh; k++) cli_out_input("--collider-mesh", o->mesh_path[k]);
  if (o->out) cli_out_folder("-o", o->out, cli_run_members, cli_run_nmember, 1);
  if (o->final) cli_out_plant("--final", o->final);
  return cli_out_check("sim");
}

// ---------------------------------------------------------------------------------------------
// batches: N items side by side (--batch N --jobs J)

// one item's result
typedef struct batch_item {
  uint64_t seed;
  vd_status st;
  vd_error err;
  int64_t steps;
  double time, wall, max_disp, ke;
  int nevent, nseg;
  int64_t nwarning;
} batch_item;

// item i's seed from (master, i), as `verdant dataset` draws it: the same plant for the same item
static uint64_t batch_seed(uint64_t master, int i) {
  vd_rng r;
  vd_rng_stream(&r, master, (uint64_t)i);
  uint64_t hi = vd_rng_u32(&r), lo = vd_rng_u32(&r);
  return ((hi << 32) | lo) & ((1ull << 53) - 1);
}

// grow, build and run item i; its outputs go to DIR/item_NNNNNN/ with -o DIR
static void batch_run(const sim_opts* o, int i, double nsteps, const double* wind, int nwind, vd_sdf* const* sdf,
                      batch_item* r) {
  cli_plant_opts po = o->po;
  po.seed = r->seed;
  po.progress = 0;
  vd_plant_spec* spec = NULL;
  vd_model* plant = NULL;
  vd_sim_model* m = NULL;
  vd_sim_data* d = NULL;
  cli_grow_info info;
  vd_error* err = &r->err;
  vd_status st = cli_load_plant(&po, &spec, &info, err);
  if (!st) cli_grow_info_free(&info);
  if (!st) st = vd_plant_compile(spec, &plant, err);
  if (!st) st = vd_sim_build(plant, &o->def, &m, err);
  if (!st) {
    vd_vec3 g = m->opt.gravity;
    m->opt = o->opt;
    m->opt.gravity = g;
    m->opt.wind_series = wind;
    m->opt.nwind = nwind;
    m->opt.threads = 1;  // one item, one thread
    d = vd_sim_data_create(m);
    if (!d) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  pull pl[16];
  memcpy(pl, o->pull, sizeof pl);
  for (int k = 0; !st && k < o->npull; k++) {
    pl[k].node = vd_sim_find_organ(m, plant, pl[k].organ, pl[k].instance);
    if (pl[k].node < 0)
      st = vd_error_set(err, VD_ERR_VALUE, o->po.path, 0, 0, "item %d: no organ '%s' in the plant", i, pl[k].organ);
    else if (pl[k].move && (pl[k].tie = vd_sim_add_tie(d, pl[k].node, d->node_pos[pl[k].node], 1e-5)) < 0)  // NOLINT(clang-analyzer-core.NullDereference): d exists whenever st is VD_OK
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  int probe_id[16];
  if (!st) {
    if (!o->no_ground) {
      vd_sim_collider c = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, o->ground), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
      vd_sim_add_collider(d, &c);
    }
    for (int k = 0; k < o->nmesh; k++) {
      vd_sim_collider c = {VD_SIM_MESH, {0, 0, 0}, o->mesh_pos[k], vd_quat_identity(), vd_v3(0, 0, 0), sdf[k]};
      vd_sim_add_collider(d, &c);
    }
    for (int k = 0; k < o->nprobe; k++) {
      vd_sim_collider c = {VD_SIM_SPHERE, {o->probe[k].r, 0, 0}, o->probe[k].p0, vd_quat_identity(), vd_v3(0, 0, 0), NULL};
      probe_id[k] = vd_sim_add_collider(d, &c);
    }
  }
  double t0 = cli_now();
  if (!st && (o->settle || o->statics)) {
    vd_sim_settle_def sd = vd_sim_settle_def_default();
    sd.statics = o->statics;
    sd.ke_tol = o->ke_tol;
    st = vd_sim_settle(m, d, &sd, NULL, NULL);
  }
  // the run with probes and pulls, as a single run drives them
  double start = d ? d->time : 0, total = o->duration, ramp = o->ramp_set ? o->ramp : total;
  int64_t steps0 = d ? d->nstep : 0;
  for (int64_t step = 0; !st && d && step < (int64_t)nsteps; step++) {
    double t = d->time - start, f = ramp > 0 ? fmin(1.0, t / ramp) : 1.0;
    for (int k = 0; k < o->npull; k++) {
      if (pl[k].move)
        d->tie[pl[k].tie].target = vd_madd(m->node_pos0[pl[k].node], pl[k].v, f);
      else
        d->node_force[pl[k].node] = vd_scale(pl[k].v, f);
    }
    for (int k = 0; k < o->nprobe; k++) {
      const probe* pr = &o->probe[k];
      double t1 = pr->t1 < 0 ? total : pr->t1, s = (t + m->opt.dt - pr->t0) / (t1 - pr->t0);
      s = s < 0 ? 0 : s > 1 ? 1 : s;
      vd_sim_set_collider_pose(m, d, probe_id[k], vd_add(pr->p0, vd_scale(vd_sub(pr->p1, pr->p0), s)), vd_quat_identity());
    }
    st = vd_sim_step(m, d);
    if (st) vd_error_set(err, st, "", 0, 0, "item %d became unstable at t = %.4f s", i, d->time);
  }
  r->wall = cli_now() - t0;
  if (d) {
    r->steps = d->nstep - steps0, r->time = d->time, r->nevent = d->nevent, r->nwarning = d->nwarning;
    r->max_disp = vd_sim_max_displacement(m, d, NULL), r->ke = vd_sim_kinetic_energy(m, d), r->nseg = m->nseg;
  }
  // the item's folder: the final plant and its events
  if (!st && o->out) {
    char dir[4200], path[4300];
    snprintf(dir, sizeof dir, "%s/item_%06d", o->out, i);
    st = vd_outdir_make(dir, err);
    if (!st) st = write_events(d, plant, dir, err);
    if (!st && (st = vd_sim_to_spec(m, d, spec))) vd_error_set(err, st, "", 0, 0, "out of memory writing the final plant");
    snprintf(path, sizeof path, "%s/plant.json", dir);
    if (!st) st = cli_write_plant(spec, path, 0, err);
  }
  r->st = st;
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(plant);
  vd_plant_spec_destroy(spec);
}

// --batch: the items on --jobs threads, then one record each (item order) with --stats
static int sim_batch(const sim_opts* o, double nsteps) {
  vd_error err = {0};
  double* wind = NULL;
  int nwind = 0, code = EXIT_OK, n = o->batch, jobs = o->jobs > 0 ? o->jobs : 1;
  vd_sdf* sdf[8] = {NULL};
  vd_status st = o->wind_file ? vd_sim_read_wind(o->wind_file, &wind, &nwind, &err) : VD_OK;
  for (int k = 0; !st && k < o->nmesh; k++) st = load_mesh_sdf(o->mesh_path[k], &sdf[k], &err);
  if (!st && o->out) st = vd_outdir_make(o->out, &err);
  batch_item* r = st ? NULL : vd_calloc((size_t)n, sizeof *r);
  if (!st && !r) st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  if (st || !r) {
    code = cli_report("sim", &err, st);
    goto done;
  }
  for (int i = 0; i < n; i++) r[i].seed = batch_seed(o->po.seed, i);
  double t0 = cli_now();
#pragma omp parallel for num_threads(jobs) schedule(dynamic, 1)
  for (int i = 0; i < n; i++) batch_run(o, i, nsteps, wind, nwind, sdf, &r[i]);
  double wall = cli_now() - t0;
  // bad input (the first item's) is exit 2, a failed item exit 1
  for (int i = 0; i < n && code == EXIT_OK; i++)
    if (r[i].st) code = cli_report("sim", &r[i].err, r[i].st) == EXIT_USAGE ? EXIT_USAGE : EXIT_FAIL;
  if (o->stats) {
    cJSON* root = cJSON_CreateObject();
    cJSON* items = cJSON_AddArrayToObject(root, "items");
    int64_t steps = 0;
    for (int i = 0; i < n; i++) {
      cJSON* it = cJSON_CreateObject();
      char num[32];
      snprintf(num, sizeof num, "%llu", (unsigned long long)r[i].seed);
      cJSON_AddNumberToObject(it, "item", i);
      cJSON_AddRawToObject(it, "seed", num);
      cJSON_AddBoolToObject(it, "ok", r[i].st == VD_OK);
      cJSON_AddNumberToObject(it, "segments", r[i].nseg);
      cJSON_AddNumberToObject(it, "steps", (double)r[i].steps);
      cJSON_AddNumberToObject(it, "time", r[i].time);
      cJSON_AddNumberToObject(it, "max_displacement", r[i].max_disp);
      cJSON_AddNumberToObject(it, "kinetic_energy", r[i].ke);
      cJSON_AddNumberToObject(it, "nevents", r[i].nevent);
      cJSON_AddNumberToObject(it, "warnings", (double)r[i].nwarning);
      if (o->profile) cJSON_AddNumberToObject(it, "wall_seconds", r[i].wall);
      cJSON_AddItemToArray(items, it);
      steps += r[i].steps;
    }
    cJSON_AddNumberToObject(root, "jobs", jobs);
    if (o->profile) {
      cJSON_AddNumberToObject(root, "wall_seconds", wall);
      cJSON_AddNumberToObject(root, "steps_per_second", wall > 0 ? (double)steps / wall : 0);
      cJSON_AddNumberToObject(root, "real_time_factor", wall > 0 ? (double)steps * o->opt.dt / wall : 0);
    }
    char* text = cJSON_Print(root);
    cJSON_Delete(root);
    if (text) fputs(text, stdout), fputc('\n', stdout), cJSON_free(text);
    else code = EXIT_FAIL;
  }
done:
  vd_free(r, (size_t)n * sizeof *r);
  vd_free(wind, (size_t)nwind * 4 * sizeof(double));
  for (int k = 0; k < 8; k++) vd_sdf_destroy(sdf[k]);
  return code;
}

int cli_sim(int argc, char** argv) {
  // growth with physics between the age steps has its own options (cli_sim_grow.c)
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "--grow")) return cli_sim_grow(argc, argv);
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
      fputs(sim_help, stdout);
      fputs(sim_help_model, stdout);
      fputs(sim_help_loads, stdout);
      fputs(sim_help_output, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
  sim_opts o;
  memset(&o, 0, sizeof o);
  cli_plant_opts_init(&o.po);
  o.def = vd_sim_def_default();
  o.opt = vd_sim_opt_default();
  o.duration = 1.0;
  o.max_steps = 1e9;
  o.ke_tol = 1e-9;
  o.fps = 30;
  int rc = parse_args(argc, argv, &o);
  if (rc) return rc;
  if (!o.po.path) return cli_usage_error("sim", "missing PLANT (an .lpy or plant .json file)");
  if (!o.out && !o.stats && !o.final) return cli_usage_error("sim", "nothing to do: give -o DIR, --final FILE and/or --stats");
  if (check_clash(&o) || check_applies(&o)) return EXIT_USAGE;
  if ((o.settle || o.statics) && !o.duration_set) o.duration = 0;
  if (!o.frames) o.frames = "bin";
  // the run's steps, counted (a time sum stalls once time + dt == time): at most --max-steps
  double nsteps = floor(o.duration / o.opt.dt + 0.5);
  if (nsteps > o.max_steps)
    return cli_usage_error("sim", "--duration %g s at --dt %g s is %.4g steps, more than --max-steps %.0f", o.duration,
                           o.opt.dt, nsteps, o.max_steps);
  if (o.def.active_radius > 0 && !o.active_center_set && !o.active_organ.organ[0]) {
    if (!o.nprobe)
      return cli_usage_error("sim", "--active-radius needs --active-center, --active-organ or a --probe");
    o.def.active_a = o.probe[0].p0, o.def.active_b = o.probe[0].p1;
  }
  if (o.batch) {
    if (o.final) return cli_usage_error("sim", "--final writes one plant: with --batch use -o DIR");
    return sim_batch(&o, nsteps);
  }
  if (o.jobs) return cli_usage_error("sim", "--jobs needs --batch N (one plant's step: --threads)");
  // load, compile, build
  vd_error err = {0};
  vd_plant_spec* spec = NULL;
  vd_model* plant = NULL;
  vd_sim_model* m = NULL;
  vd_sim_data* d = NULL;
  double* wind = NULL;
  int nwind = 0;
  vd_sdf* sdf[8] = {NULL};
  cli_frames out;
  memset(&out, 0, sizeof out);
  cli_grow_info info;
  int code = EXIT_OK;
  vd_status st = cli_load_plant(&o.po, &spec, &info, &err);
  if (!st) cli_grow_info_free(&info);
  if (!st && o.wind_file) st = vd_sim_read_wind(o.wind_file, &wind, &nwind, &err);
  // a soil holds the roots: the axiom's roots and trunk share their base, nothing is clamped
  vd_soil soil;
  vd_sim_soil* held = NULL;
  int use_soil = o.soil && vd_soil_preset(o.soil, &soil) == VD_OK && soil.method != VD_SOIL_CLAMP;
  if (!st && use_soil) {
    vd_plant_join_bases(spec);
    o.def.clamp_roots = 0;
  }
  if (!st) st = vd_plant_compile(spec, &plant, &err);
  if (!st && o.def.active_radius > 0 && o.active_organ.organ[0]) {
    // the region around an organ: where the whole plant's model puts it
    vd_sim_def whole = o.def;
    whole.active_radius = 0;
    st = vd_sim_build(plant, &whole, &m, &err);
    int n = st ? -1 : vd_sim_find_organ(m, plant, o.active_organ.organ, o.active_organ.instance);
    if (!st && n < 0)
      st = vd_error_set(&err, VD_ERR_VALUE, o.po.path, 0, 0, "--active-organ: no organ '%s' in the plant",
                        o.active_organ.organ);
    if (!st) o.def.active_a = o.def.active_b = m->node_pos0[n];
    vd_sim_model_destroy(m);
    m = NULL;
  }
  if (!st) st = vd_sim_build(plant, &o.def, &m, &err);
  cli_blame_input(&err, o.po.path);
  if (!st) {
    vd_vec3 g = m->opt.gravity;
    m->opt = o.opt;
    m->opt.gravity = g;
    m->opt.wind_series = wind;
    m->opt.nwind = nwind;
    d = vd_sim_data_create(m);
    if (!d)
      st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    else
      d->profile = o.profile;
  }
  // organs to pull, colliders
  for (int k = 0; !st && k < o.npull; k++) {
    pull* p = &o.pull[k];
    p->node = vd_sim_find_organ(m, plant, p->organ, p->instance);
    if (p->node < 0)
      st = vd_error_set(&err, VD_ERR_VALUE, o.po.path, 0, 0, "no organ '%s'%s%.0d in the plant (labels or organ names)",
                        p->organ, p->instance ? "#" : "", p->instance);
    else if (p->move && (p->tie = vd_sim_add_tie(d, p->node, d->node_pos[p->node], 1e-5)) < 0)  // NOLINT(clang-analyzer-core.NullDereference): d exists whenever st is VD_OK
      st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  if (!st && use_soil) st = vd_sim_soil_attach(m, d, &soil, &held, &err);
  // the ground plane would push the roots out of the soil: with a soil there is none
  if (!st && !o.no_ground && !use_soil) {
    vd_sim_collider c = {VD_SIM_PLANE, {0, 0, 0}, vd_v3(0, 0, o.ground), vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    vd_sim_add_collider(d, &c);
  }
  for (int k = 0; !st && k < o.nmesh; k++) {
    st = load_mesh_sdf(o.mesh_path[k], &sdf[k], &err);
    if (!st) {
      vd_sim_collider c = {VD_SIM_MESH, {0, 0, 0}, o.mesh_pos[k], vd_quat_identity(), vd_v3(0, 0, 0), sdf[k]};
      vd_sim_add_collider(d, &c);
    }
  }
  for (int k = 0; !st && k < o.nprobe; k++) {
    vd_sim_collider c = {VD_SIM_SPHERE, {o.probe[k].r, 0, 0}, o.probe[k].p0, vd_quat_identity(), vd_v3(0, 0, 0), NULL};
    o.probe[k].id = vd_sim_add_collider(d, &c);
  }
  if (st) {
    code = cli_report("sim", &err, st);
    goto done;
  }
  // output folder: failing to write is a failed run (exit 1), not bad input; the run's files
  // appear together when the command succeeds (the output layer), a folder made for a failed run
  // goes
  if (o.out) st = vd_outdir_make(o.out, &err);
  if (st) {
    cli_report("sim", &err, st);
    code = EXIT_FAIL;
    goto done;
  }
  if (o.out) {
    st = cli_rod_json_write(m, plant, &o.def, o.out, &err);
    if (!st) {
      char path[4096];
      snprintf(path, sizeof path, "%s/plant_initial.json", o.out);
      st = vd_plant_write_json(spec, path, &err);
    }
    if (!st && strcmp(o.frames, "none") != 0) st = cli_frames_begin(&out, m, o.out, !strcmp(o.frames, "jsonl"), &err);
    if (st) {
      cli_report("sim", &err, st);
      code = EXIT_FAIL;
      goto done;
    }
  }
  {
    double t0 = cli_now();
    int settled = 0, settle_steps = -1;
    int64_t steps0 = d->nstep;
    // settling first
    if (o.settle || o.statics) {
      vd_sim_settle_def sd = vd_sim_settle_def_default();
      sd.statics = o.statics;
      sd.ke_tol = o.ke_tol;
      settle_bar sb = {{o.po.progress, 0, 0}, cli_now()};
      sd.progress = settle_progress;
      sd.user = &sb;
      st = vd_sim_settle(m, d, &sd, &settled, &settle_steps);
      if (sb.bar.shown) {
        char text[96];
        snprintf(text, sizeof text, "%d steps, %.1f s, %s", settle_steps, cli_now() - sb.t0, settled ? "still" : "not still");
        cli_progress_bar("settling", 1, text);
        cli_progress_end(&sb.bar);
      }
    }
    // the timed run with probes and pulls
    double start = d->time, total = o.duration, next_frame = start;
    double ramp = o.ramp_set ? o.ramp : total;
    cli_progress bar = {o.po.progress, 0, 0};
    double frames_s = 0;
    if (out.frames_open) cli_frames_write(&out, m, d), next_frame += 1.0 / o.fps;
    for (int64_t step = 0; !st && step < (int64_t)nsteps; step++) {
      double t = d->time - start, f = ramp > 0 ? fmin(1.0, t / ramp) : 1.0;
      for (int k = 0; k < o.npull; k++) {
        pull* p = &o.pull[k];
        if (p->move)
          d->tie[p->tie].target = vd_madd(m->node_pos0[p->node], p->v, f);
        else
          d->node_force[p->node] = vd_scale(p->v, f);
      }
      for (int k = 0; k < o.nprobe; k++) {
        const probe* pr = &o.probe[k];
        double t1 = pr->t1 < 0 ? total : pr->t1, s = (t + m->opt.dt - pr->t0) / (t1 - pr->t0);
        s = s < 0 ? 0 : s > 1 ? 1 : s;
        vd_sim_set_collider_pose(m, d, pr->id, vd_add(pr->p0, vd_scale(vd_sub(pr->p1, pr->p0), s)), vd_quat_identity());
      }
      st = vd_sim_step(m, d);
      vd_sim_soil_update(m, d, held);
      if (out.frames_open && d->time >= next_frame - 1e-12) {
        double tf = o.profile ? cli_now() : 0;
        if (cli_frames_write(&out, m, d)) break;  // reported by the commit below
        if (o.profile) frames_s += cli_now() - tf;
        next_frame += 1.0 / o.fps;
      }
      if (cli_progress_due(&bar)) progress_bar(d->time - start, total, d->nstep, cli_now() - t0);
    }
    if (bar.shown) progress_bar(d->time - start, total, d->nstep, cli_now() - t0), cli_progress_end(&bar);
    double wall = cli_now() - t0;
    if (st) {
      vd_error_set(&err, st, "", 0, 0,
                   "the simulation became unstable at t = %.4f s: even steps of dt / %d made a non-finite state, "
                   "a singular system or a stretch beyond %g%% (%lld numerical warnings); try a smaller --dt or "
                   "more --iterations%s",
                   d->time, 1 << VD_SIM_MAX_SUBSTEP, 100 * VD_SIM_BLOWUP_STRAIN, (long long)d->nwarning,
                   m->opt.solver == VD_SIM_GS ? " (Gauss-Seidel needs many on stiff material), or --solver direct" : "");
      cli_report("sim", &err, st);
      code = EXIT_FAIL;
      goto done;
    }
    // numerical trouble that the run survived: say so (the counts are in --stats too)
    if (d->nwarning) {
      const char* sep = "verdant sim: warning: ";
      if (d->warning[VD_SIM_WARN_SUBSTEP]) {
        fprintf(stderr, "%s%lld steps were retaken in halves (non-finite %lld, singular %lld, overstretched %lld)", sep,
                (long long)d->warning[VD_SIM_WARN_SUBSTEP], (long long)d->warning[VD_SIM_WARN_NONFINITE],
                (long long)d->warning[VD_SIM_WARN_SOLVER], (long long)d->warning[VD_SIM_WARN_STRAIN]);
        sep = "; ";
      }
      if (d->warning[VD_SIM_WARN_UNSTABLE]) {
        fprintf(stderr, "%s%lld substeps of dt / %d stayed stretched beyond %g%%: the result is not trustworthy "
                        "(a contact or tie holding part of the plant, or too large a time step: try a smaller --dt "
                        "or more --iterations)",
                sep, (long long)d->warning[VD_SIM_WARN_UNSTABLE], 1 << VD_SIM_MAX_SUBSTEP, 100 * VD_SIM_MAX_STRAIN);
        sep = "; ";
      }
      if (d->warning[VD_SIM_WARN_STRETCHED] && !d->warning[VD_SIM_WARN_UNSTABLE]) {
        fprintf(stderr, "%s%lld steps ended with a segment stretched beyond %g%%: the result is not trustworthy "
                        "(a contact or tie holding part of the plant, a material too soft, or too large a time "
                        "step: try a smaller --dt or more --iterations)",
                sep, (long long)d->warning[VD_SIM_WARN_STRETCHED], 100 * VD_SIM_MAX_STRAIN);
        sep = "; ";
      }
      if (d->warning[VD_SIM_WARN_ARENA])
        fprintf(stderr, "%scontacts were dropped in %lld steps (out of memory)", sep,
                (long long)d->warning[VD_SIM_WARN_ARENA]);
      fputc('\n', stderr);
    }
    // outputs
    if (out.frames_open) {
      st = vd_outfile_commit(&out.frames, &err);
      out.frames_open = 0;
    }
    if (out.colliders_open) {  // kept only beside complete frames
      vd_status s2 = VD_OK;
      if (st) vd_outfile_abort(&out.colliders);
      else s2 = vd_outfile_commit(&out.colliders, &err);
      st = st ? st : s2;
      out.colliders_open = 0;
    }
    if (!st && o.out) st = write_events(d, plant, o.out, &err);
    if (!st && (o.out || o.final)) {
      st = vd_sim_to_spec(m, d, spec);
      if (st) vd_error_set(&err, st, "", 0, 0, "out of memory writing the final plant");
      if (!st && o.out) {
        char path[4096];
        snprintf(path, sizeof path, "%s/plant.json", o.out);
        st = cli_write_plant(spec, path, 0, &err);
      }
      if (!st && o.final) st = cli_write_plant(spec, o.final, 0, &err);
    }
    if (st) {
      cli_report("sim", &err, st);
      code = EXIT_FAIL;
      goto done;
    }
    if (o.stats && !print_stats(m, d, plant, wall, d->nstep - steps0, settled, settle_steps, frames_s)) code = EXIT_FAIL;
  }
done:
  if (out.frames_open) vd_outfile_abort(&out.frames);
  if (out.colliders_open) vd_outfile_abort(&out.colliders);
  vd_free(out.bbuf, out.fbuf_n);
  vd_sim_soil_destroy(held);
  vd_sim_data_destroy(d);
  vd_sim_model_destroy(m);
  vd_model_destroy(plant);
  vd_plant_spec_destroy(spec);
  vd_free(wind, (size_t)nwind * 4 * sizeof(double));
  for (int k = 0; k < 8; k++) vd_sdf_destroy(sdf[k]);
  return code;
}
