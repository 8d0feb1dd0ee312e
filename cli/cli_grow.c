// SPDX-License-Identifier: MIT
// verdant grow: L-system (or plant file) → plant JSON, OBJ or PLY, with --stats.
#include <cjson/cJSON.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* grow_help =
    "usage: verdant grow PLANT [-o OUT] [options]\n"
    "\n"
    "Grow a plant from an L-Py file (.lpy, derived on the fly), read a plant file (.json) or\n"
    "build one from hand-drawn branch curves (.json with \"format\": \"verdant-curves\"), and\n"
    "write it as plant JSON (.json) or a labelled mesh (.obj with .mtl, .ply).\n"
    "\n"
    "options:\n"
    "  -o, --output OUT      output file; the extension picks the format: .json .obj .ply\n"
    "      --ascii           write PLY as ASCII instead of binary little-endian\n"
    "      --stats           print a JSON summary on stdout (modules, module_counts, segments,\n"
    "                        spheres, leaves, labels (instances per label), organs (per label:\n"
    "                        count, length, area, volume, mean diameter), bbox_min, bbox_max (m),\n"
    "                        total_length (m)); the same bytes for the same inputs\n"
    "      --profile         --stats adds seconds (derive, turtle): timings, which differ per run\n"
    "      --traits FILE     per-instance traits as CSV: instance, label, label_name, organ,\n"
    "                        segments, spheres, meshes, length_m, area_m2, diameter_m, volume_m3,\n"
    "                        bbox (m)\n"
    "      --animate         .lpy files: interpret and draw after every derivation step, as\n"
    "                        L-Py's animate (its hooks and interpretation rules run per frame;\n"
    "                        every step runs; OUT is the last frame)\n"
    "      --frames PATTERN  write each frame of --animate (implied) as a plant file: PATTERN\n"
    "                        holds one %d, %4d or %04d for the frame number (0 = the axiom),\n"
    "                        its extension picks the format (.json .obj .ply), e.g. f%03d.obj\n"
    "      --call NAME       .lpy files: after the run, call the file's function NAME() (no\n"
    "                        arguments; repeatable): a failed assert in it fails the run\n";

static int cmp_u64(const void* a, const void* b) {
  uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
  return x < y ? -1 : x > y;
}

// number of distinct organ instances per label
static cJSON* label_counts(const vd_plant_spec* p) {
  size_t n = (size_t)p->nseg + (size_t)p->nsphere + (size_t)p->nmesh;
  uint64_t* key = n ? vd_malloc(n * sizeof(uint64_t)) : NULL;
  cJSON* obj = cJSON_CreateObject();
  if ((n && !key) || !obj) {
    vd_free(key, n * sizeof(uint64_t));
    cJSON_Delete(obj);
    return NULL;
  }
  size_t k = 0;
  for (int i = 0; i < p->nseg; i++) key[k++] = ((uint64_t)(uint32_t)p->seg[i].label << 32) | (uint32_t)p->seg[i].instance;  // NOLINT(clang-analyzer-core.NullDereference): key holds n entries whenever n > 0
  for (int i = 0; i < p->nsphere; i++)
    key[k++] = ((uint64_t)(uint32_t)p->sphere[i].label << 32) | (uint32_t)p->sphere[i].instance;  // NOLINT(clang-analyzer-core.NullDereference): key holds n entries whenever n > 0
  for (int i = 0; i < p->nmesh; i++) key[k++] = ((uint64_t)(uint32_t)p->mesh[i].label << 32) | (uint32_t)p->mesh[i].instance;  // NOLINT(clang-analyzer-core.NullDereference): key holds n entries whenever n > 0
  if (n) qsort(key, n, sizeof(uint64_t), cmp_u64);
  // every label of the table appears, with 0 when nothing carries it
  for (int l = 0; l < p->nlabel; l++) {
    int count = 0;
    for (size_t i = 0; i < n; i++)
      if ((int)(key[i] >> 32) == p->label[l].id && (i == 0 || key[i] != key[i - 1])) count++;
    cJSON_AddNumberToObject(obj, p->label[l].name, count);
  }
  vd_free(key, n * sizeof(uint64_t));
  return obj;
}

// per label: how many instances and their traits summed (the mean diameter)
static cJSON* organ_summary(const vd_plant_spec* p, const vd_organ_traits* t, int nt) {
  cJSON* obj = cJSON_CreateObject();
  if (!obj) return NULL;
  for (int l = 0; l < p->nlabel; l++) {
    int count = 0;
    double len = 0, area = 0, vol = 0, dia = 0;
    for (int i = 0; i < nt; i++) {
      if (t[i].label != p->label[l].id) continue;
      count++, len += t[i].length, area += t[i].area, vol += t[i].volume, dia += t[i].diameter;
    }
    if (!count) continue;
    cJSON* o = cJSON_AddObjectToObject(obj, p->label[l].name);
    cJSON_AddNumberToObject(o, "count", count);
    cJSON_AddNumberToObject(o, "length_m", len);
    cJSON_AddNumberToObject(o, "area_m2", area);
    cJSON_AddNumberToObject(o, "volume_m3", vol);
    cJSON_AddNumberToObject(o, "diameter_m_mean", dia / count);
  }
  return obj;
}

// the traits CSV, under a temporary name renamed when complete
static vd_status write_traits(const char* path, const vd_plant_spec* p, const vd_organ_traits* t, int nt,
                              vd_error* err) {
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (st) return st;
  fputs("instance,label,label_name,organ,segments,spheres,meshes,length_m,area_m2,diameter_m,volume_m3,"
        "xmin,ymin,zmin,xmax,ymax,zmax\n",
        f.fp);
  for (int i = 0; i < nt; i++) {
    const vd_organ_traits* o = &t[i];
    if (o->nseg + o->nsphere + o->nmesh == 0) continue;
    const vd_label* l = vd_plant_find_label(p, o->label);
    char name[VD_LABEL_NAME_MAX];
    size_t k = 0;
    for (const char* c = l ? l->name : ""; *c && k + 1 < sizeof name; c++)  // a CSV field: no commas, quotes or breaks
      name[k++] = (char)((*c == ',' || *c == '"' || (unsigned char)*c < 0x20) ? '_' : *c);
    name[k] = 0;
    fprintf(f.fp, "%d,%d,%s,%s,%d,%d,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", o->instance, o->label, name,
            vd_organ_name(o->organ), o->nseg, o->nsphere, o->nmesh, o->length, o->area, o->diameter, o->volume,
            o->bbox_min.x, o->bbox_min.y, o->bbox_min.z, o->bbox_max.x, o->bbox_max.y, o->bbox_max.z);
  }
  st = vd_outfile_commit(&f, err);
  vd_outfile_abort(&f);
  return st;
}

static cJSON* vec_json(vd_vec3 v) {
  double a[3] = {v.x, v.y, v.z};
  return cJSON_CreateDoubleArray(a, 3);
}

static int print_stats(const vd_plant_spec* p, const cli_grow_info* info, const vd_organ_traits* tr, int ntr,
                       int profile) {
  cJSON* root = cJSON_CreateObject();
  if (!root) return 0;
  vd_plant_stats ps;
  vd_plant_spec_stats(p, &ps);
  if (info->engine) cJSON_AddStringToObject(root, "engine", info->engine);
  cJSON_AddNumberToObject(root, "modules", (double)info->modules);
  cJSON* mc = cJSON_AddObjectToObject(root, "module_counts");
  for (int k = 0; k < info->nsym; k++)
    if (info->sym_count[k]) cJSON_AddNumberToObject(mc, info->sym_name[k], (double)info->sym_count[k]);
  cJSON_AddNumberToObject(root, "nodes", p->nnode);
  cJSON_AddNumberToObject(root, "segments", ps.nseg);
  cJSON_AddNumberToObject(root, "spheres", ps.nsphere);
  cJSON_AddNumberToObject(root, "leaves", ps.nleaf);
  cJSON_AddNumberToObject(root, "meshes", p->nmesh);
  cJSON_AddNumberToObject(root, "instances", p->ninstance);
  cJSON* labels = label_counts(p);
  if (labels) cJSON_AddItemToObject(root, "labels", labels);
  cJSON* organs = organ_summary(p, tr, ntr);
  if (organs) cJSON_AddItemToObject(root, "organs", organs);
  cJSON_AddItemToObject(root, "bbox_min", vec_json(ps.bbox_min));
  cJSON_AddItemToObject(root, "bbox_max", vec_json(ps.bbox_max));
  cJSON_AddNumberToObject(root, "total_length", ps.total_length);
  if (profile) {
    cJSON* t = cJSON_AddObjectToObject(root, "seconds");
    cJSON_AddNumberToObject(t, "derive", info->seconds_derive);
    cJSON_AddNumberToObject(t, "turtle", info->seconds_turtle);
  }
  char* text = cJSON_Print(root);
  int ok = text != NULL;
  if (text) {
    fputs(text, stdout);
    fputc('\n', stdout);
    cJSON_free(text);
  }
  cJSON_Delete(root);
  return ok;
}

int cli_grow(int argc, char** argv) {
  cli_plant_opts po;
  cli_plant_opts_init(&po);
  const char* out = NULL;
  const char* traits = NULL;
  int stats = 0, ascii = 0, profile = 0;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      fputs(grow_help, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
    int r = cli_plant_opt(&po, "grow", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (i + 1 >= argc) return cli_usage_error("grow", "%s needs a file name", a);
      out = argv[++i];
    } else if (!strcmp(a, "--stats")) {
      stats = 1;
    } else if (!strcmp(a, "--profile")) {
      profile = 1;
    } else if (!strcmp(a, "--traits")) {
      if (i + 1 >= argc) return cli_usage_error("grow", "%s needs a file name", a);
      if (traits) return cli_usage_error("grow", "--traits given 2 times");
      traits = argv[++i];
    } else if (!strcmp(a, "--ascii")) {
      ascii = 1;
    } else if (!strcmp(a, "--animate")) {
      po.animate = 1;
    } else if (!strcmp(a, "--frames")) {
      if (i + 1 >= argc) return cli_usage_error("grow", "%s needs a file name pattern", a);
      if (po.frames) return cli_usage_error("grow", "--frames given 2 times");
      po.frames = argv[++i];
      po.animate = 1;
      char name[4200];
      if (!cli_frame_name(po.frames, 0, name, sizeof name))
        return cli_usage_error("grow", "--frames '%s': give one %%d, %%Nd or %%0Nd (N < 10) for the frame number "
                               "(%%%% for a %%)", po.frames);
      if (!cli_has_ext(name, ".json") && !cli_has_ext(name, ".obj") && !cli_has_ext(name, ".ply"))
        return cli_usage_error("grow", "--frames '%s': unknown format (use .json, .obj or .ply)", po.frames);
    } else if (!strcmp(a, "--call")) {
      if (i + 1 >= argc) return cli_usage_error("grow", "%s needs a function name", a);
      const char* f = argv[++i];
      int ok = f[0] == '_' || ((f[0] | 32) >= 'a' && (f[0] | 32) <= 'z');
      for (const char* c = f; ok && *c; c++) ok = *c == '_' || (*c >= '0' && *c <= '9') || ((*c | 32) >= 'a' && (*c | 32) <= 'z');
      if (!ok) return cli_usage_error("grow", "--call expects a Python function name, got '%s'", f);
      if (po.ncall == 8) return cli_usage_error("grow", "too many --call options (8 at most)");
      po.call[po.ncall++] = f;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error("grow", "unknown option '%s'", a);
    } else if (!po.path) {
      po.path = a;
    } else {
      return cli_usage_error("grow", "unexpected argument '%s'", a);
    }
  }
  if (!po.path) return cli_usage_error("grow", "missing PLANT (an .lpy or plant .json file)");
  if (!out && !stats && !traits && !po.frames && !po.ncall)
    return cli_usage_error("grow", "nothing to do: give -o OUT, --frames PATTERN, --traits FILE, --call NAME and/or --stats");
  if (out && !cli_has_ext(out, ".json") && !cli_has_ext(out, ".obj") && !cli_has_ext(out, ".ply"))
    return cli_usage_error("grow", "output '%s': unknown format (use .json, .obj or .ply)", out);
  if (profile && !stats) return cli_usage_error("grow", "--profile adds timings to --stats; give --stats");
  if (ascii && !(out && cli_has_ext(out, ".ply")))
    return cli_usage_error("grow", "--ascii applies to a .ply output (plant JSON and OBJ are text already)");
  // the files: declared and checked before anything runs
  cli_out_plant_opts(&po);
  if (out) cli_out_plant("-o", out);
  if (traits) cli_out_file("--traits", traits);
  if (cli_out_check("grow")) return EXIT_USAGE;
  vd_error err = {0};
  vd_plant_spec* plant;
  cli_grow_info info;
  vd_status st = cli_load_plant(&po, &plant, &info, &err);
  if (st) return cli_report("grow", &err, st);
  // per-instance traits (--stats, --traits)
  vd_organ_traits* tr = NULL;
  int ntr = 0;
  if ((stats || traits) && (st = vd_plant_traits(plant, &tr, &ntr))) {
    vd_plant_spec_destroy(plant);
    cli_grow_info_free(&info);
    vd_error_set(&err, st, "", 0, 0, "out of memory");
    return cli_report("grow", &err, st);
  }
  // the file, its material library and the traits: in place together when the command ends
  if (out) st = cli_write_plant(plant, out, ascii, &err);
  if (!st && traits) st = write_traits(traits, plant, tr, ntr, &err);
  cli_blame_input(&err, po.path);  // a plant that does not compile (output errors name the output)
  if (!st && stats && !print_stats(plant, &info, tr, ntr, profile)) st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  vd_free(tr, (size_t)ntr * sizeof *tr);
  vd_plant_spec_destroy(plant);
  cli_grow_info_free(&info);
  if (st) {
    int code = cli_report("grow", &err, st);
    return st == VD_ERR_IO ? EXIT_FAIL : code;  // failing to write the output is a failed run
  }
  return EXIT_OK;
}
