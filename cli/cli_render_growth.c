// SPDX-License-Identifier: MIT
// verdant render RUN/ of a growth run ('verdant sim --grow -o RUN/'): the plant at each age step
// (age_NNN.json, with stress), drawn with one camera fitted to the largest age and, coloured by
// stress, one logarithmic scale over the whole run (the paper's Figure 7).
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

typedef struct snap {
  char file[4200];
  double time;
  int age;
} snap;

// the index's snapshots; *n gets their count
static vd_status read_index(const char* dir, snap** out, int* n, vd_error* err) {
  char path[4200];
  snprintf(path, sizeof path, "%s/growth.json", dir);
  char* text;
  size_t len;
  *out = NULL;
  *n = 0;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  cJSON* root = cJSON_ParseWithLength(text, len);
  vd_free(text, len + 1);
  const cJSON* fmt = root ? cJSON_GetObjectItemCaseSensitive(root, "format") : NULL;
  const cJSON* ver = root ? cJSON_GetObjectItemCaseSensitive(root, "version") : NULL;
  const cJSON* list = root ? cJSON_GetObjectItemCaseSensitive(root, "snapshots") : NULL;
  if (!root || !cJSON_IsString(fmt) || strcmp(fmt->valuestring, "verdant-growth") != 0)
    st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "not a growth run index (format \"verdant-growth\")");
  else if (!cJSON_IsNumber(ver) || ver->valuedouble != VD_GROWTH_FORMAT_VERSION)
    st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "version: expected %d", VD_GROWTH_FORMAT_VERSION);
  else if (!cJSON_IsArray(list) || cJSON_GetArraySize(list) < 1)
    st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "snapshots: expected a non-empty array");
  int cnt = st ? 0 : cJSON_GetArraySize(list);
  snap* s = cnt ? vd_calloc((size_t)cnt, sizeof(snap)) : NULL;
  if (!st && !s) st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  int k = 0;
  for (const cJSON* e = st || !list || !s ? NULL : list->child; e && s && !st && k < cnt; e = e->next, k++) {
    const cJSON* f = cJSON_GetObjectItemCaseSensitive(e, "file");
    const cJSON* t = cJSON_GetObjectItemCaseSensitive(e, "time");
    const cJSON* a = cJSON_GetObjectItemCaseSensitive(e, "age");
    if (!cJSON_IsString(f) || strchr(f->valuestring, '/') || !cJSON_IsNumber(t) || !isfinite(t->valuedouble) ||
        !cJSON_IsNumber(a))
      st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "snapshots[%d]: expected {age, time, file} with a file name", k);
    else {
      snprintf(s[k].file, sizeof s[k].file, "%s/%s", dir, f->valuestring);
      s[k].time = t->valuedouble;
      s[k].age = (int)a->valuedouble;
    }
  }
  cJSON_Delete(root);
  if (st) {
    vd_free(s, sizeof(snap) * (size_t)(cnt ? cnt : 1));
    return st;
  }
  *out = s;
  *n = cnt;
  return VD_OK;
}

// read and compile snapshot k
static vd_status load(const snap* s, vd_plant_spec** spec, vd_model** model, vd_error* err) {
  *spec = NULL, *model = NULL;
  vd_status st = vd_plant_read_json(s->file, spec, err);
  if (!st) st = vd_plant_compile(*spec, model, err);
  return st;
}

int cli_render_growth(const cli_render_opts* o) {
  const char* cmd = "render";
  if (!o->out) return cli_usage_error(cmd, "missing -o OUT.png (the last age) or -o DIR/ (every age)");
  size_t ol = strlen(o->out);
  int folder = ol > 0 && o->out[ol - 1] == '/';
  if (!folder && !cli_has_ext(o->out, ".png")) return cli_usage_error(cmd, "output '%s' must end in .png or /", o->out);
  if (o->mp4 || o->disp_from_first)
    return cli_usage_error(cmd, "--mp4 and --displacement-from apply to runs of 'verdant sim -o', not growth runs");
  vd_error err = {0};
  snap* s = NULL;
  int n = 0, code = EXIT_OK;
  vd_renderer* r = NULL;
  vd_plant_spec* spec = NULL;
  vd_model* model = NULL;
  vd_status st = read_index(o->po.path, &s, &n, &err);
  if (st) return cli_report(cmd, &err, st);
  // the files: the run's index and ages and the robot read; a picture (and its layers) or a
  // folder of one per age written (an earlier render's ages there that this one does not draw go)
  static const char* const age_files[] = {"age_*.png", "age_*.png.json"};
  char idx[4300];
  snprintf(idx, sizeof idx, "%s/growth.json", o->po.path);
  cli_out_input("RUN", o->po.path);
  cli_out_input("RUN", idx);
  for (int k = 0; k < n; k++) cli_out_input("RUN", s[k].file);
  cli_out_input("--robot", o->def.robot_mjcf);
  if (folder) {
    cli_out_folder("-o", o->out, age_files, 2, 1);
  } else {
    char files[5][4200];
    int nf = cli_frame_files(o->out, o->depth, o->masks, files);
    for (int k = 0; k < nf; k++) cli_out_file("-o", files[k]);
  }
  if (cli_out_check(cmd)) {
    vd_free(s, sizeof(snap) * (size_t)(n ? n : 1));
    return EXIT_USAGE;
  }
  // which ages: the one nearest --time (default the last), or all into a folder
  int want = n - 1;
  if (o->has_time)
    for (int k = 0; k < n; k++)
      if (fabs(s[k].time - o->time) < fabs(s[want].time - o->time)) want = k;
  vd_render_style style = o->style;
  int stress = style.color_by == VD_COLOR_STRESS;
  if (style.color_by == VD_COLOR_DISPLACEMENT)
    return vd_free(s, sizeof(snap) * (size_t)n), cli_usage_error(cmd, "a growth run is coloured by label, instance or stress");
  // one stress scale for the run: the smallest positive and the largest value of every age
  if (stress && !(style.range_max > style.range_min)) {
    double lo = INFINITY, hi = 0;
    for (int k = 0; k < n && !st; k++) {
      vd_plant_spec* p = NULL;
      st = vd_plant_read_json(s[k].file, &p, &err);
      if (!st && vd_plant_has_stress(p))
        for (int j = 0; j < p->nseg; j++)
          if (isfinite(p->seg_stress[j]) && p->seg_stress[j] > 0) lo = fmin(lo, p->seg_stress[j]), hi = fmax(hi, p->seg_stress[j]);
      vd_plant_spec_destroy(p);
    }
    // four decades at most: round-off leaves stresses near zero that would stretch the scale
    if (!st && hi > lo) style.range_min = fmax(lo, hi * 1e-4), style.range_max = hi;
  }
  style.log_scale = stress;
  // the camera: fitted to the largest plant (the last age) so every picture has the same view
  if (!st) st = load(&s[n - 1], &spec, &model, &err);
  vd_render_def def = o->def;
  if (!st && model->ninstance + 16 > def.max_geoms) def.max_geoms = model->ninstance + 16;
  if (!st) {
    st = vd_render_create(&def, &r, &err);
    if (st) {
      code = st == VD_ERR_UNSUPPORTED || st == VD_ERR_NOMEM ? EXIT_FAIL : cli_exit_code(st);
      cli_report(cmd, &err, st);
      goto done;
    }
  }
  if (!st && o->info) fprintf(stderr, "verdant render: %s\n", vd_render_info(r));
  if (!st) st = cli_apply_look(o, r, &err);
  vd_camera cam;
  memset(&cam, 0, sizeof cam);
  if (!st) {
    vd_render_style st0 = style;
    if (stress) st0.seg_stress = vd_plant_has_stress(spec) ? spec->seg_stress : NULL;
    if (stress && !st0.seg_stress) st0.color_by = VD_COLOR_LABEL;
    st = vd_render_add_plant(r, model, NULL, &st0, &err);
  }
  if (!st) {
    vd_vec3 lo, hi;
    vd_render_bounds(r, &lo, &hi);
    cam = cli_render_camera(o, lo, hi);
  }
  if (st) goto fail;
  if (folder && (st = vd_outdir_make(o->out, &err))) goto fail;
  unsigned layers = VD_LAYER_COLOR | (o->depth ? VD_LAYER_DEPTH : 0) | (o->masks ? VD_LAYER_LABEL | VD_LAYER_INSTANCE : 0);
  for (int k = folder ? 0 : want; k <= (folder ? n - 1 : want); k++) {
    vd_plant_spec_destroy(spec);
    vd_model_destroy(model);
    if ((st = load(&s[k], &spec, &model, &err))) goto fail;
    vd_render_clear(r);
    vd_render_style sk = style;
    if (stress) sk.seg_stress = vd_plant_has_stress(spec) ? spec->seg_stress : NULL;
    if (stress && (!sk.seg_stress || !spec->nseg)) sk.color_by = VD_COLOR_LABEL;  // an empty axiom
    if (spec->nseg + spec->nsphere + spec->nmesh == 0) continue;
    if ((st = vd_render_add_plant(r, model, NULL, &sk, &err))) goto fail;
    vd_frame f;
    if ((st = vd_render_draw(r, &cam, layers, &f, &err))) goto fail;
    char path[4300];
    if (folder) snprintf(path, sizeof path, "%sage_%03d.png", o->out, s[k].age);
    else snprintf(path, sizeof path, "%s", o->out);
    if ((st = cli_frame_write(&f, path, o->depth, o->masks, &err))) goto fail;
  }
  goto done;
fail:
  cli_report(cmd, &err, st);
  code = st == VD_ERR_IO ? EXIT_FAIL : cli_exit_code(st);
done:
  vd_render_destroy(r);
  vd_plant_spec_destroy(spec);
  vd_model_destroy(model);
  vd_free(s, sizeof(snap) * (size_t)(n ? n : 1));
  return code;
}
