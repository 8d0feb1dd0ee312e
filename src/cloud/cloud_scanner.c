// SPDX-License-Identifier: MIT
// Scanner presets: a JSON file of scanner poses and ray grids (docs/formats.md), in metres or
// relative to the plant's bounding box so one preset fits a rosette and a tree.
#include <cjson/cJSON.h>
#include <math.h>
#include <string.h>

#include "cloud_internal.h"

#define FORMAT_NAME "verdant-scanners"

// 1-based line and column of byte pos
static void line_col(const char* text, size_t len, size_t pos, int* line, int* col) {
  *line = 1, *col = 1;
  for (size_t i = 0; i < pos && i < len; i++) {
    if (text[i] == '\n')
      (*line)++, *col = 1;
    else
      (*col)++;
  }
}

// n numbers of array field key of obj into out; 0 when absent (out untouched), -1 when malformed
static int numbers(const cJSON* obj, const char* key, double* out, int n) {
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(obj, key);
  if (!a) return 0;
  if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return -1;
  int i = 0;
  for (const cJSON* e = a->child; e; e = e->next, i++) {
    if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) return -1;
    out[i] = e->valuedouble;
  }
  return 1;
}

static vd_status parse(const cJSON* root, const char* path, vd_vec3 lo, vd_vec3 hi,
                       vd_scanner** out, int* nout, vd_error* err) {
#define BAD(...) return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, __VA_ARGS__)
  if (!cJSON_IsObject(root)) BAD("expected a JSON object");
  const cJSON* f = cJSON_GetObjectItemCaseSensitive(root, "format");
  if (!cJSON_IsString(f) || strcmp(f->valuestring, FORMAT_NAME) != 0)
    BAD("field 'format': expected \"%s\"", FORMAT_NAME);
  const cJSON* v = cJSON_GetObjectItemCaseSensitive(root, "version");
  if (!cJSON_IsNumber(v) || v->valuedouble != 1) BAD("field 'version': expected 1");
  // frame: world metres, or the bounding box (origin at its centre, unit its largest side)
  const cJSON* fr = cJSON_GetObjectItemCaseSensitive(root, "frame");
  int bbox = 0;
  if (fr) {
    if (!cJSON_IsString(fr) || (strcmp(fr->valuestring, "world") != 0 && strcmp(fr->valuestring, "bbox") != 0))
      BAD("field 'frame': expected \"world\" or \"bbox\"");
    bbox = !strcmp(fr->valuestring, "bbox");
  }
  vd_vec3 centre = vd_scale(vd_add(lo, hi), 0.5);
  double size = fmax(hi.x - lo.x, fmax(hi.y - lo.y, hi.z - lo.z));
  if (!(size > 0)) size = 1;
  const cJSON* arr = cJSON_GetObjectItemCaseSensitive(root, "scanners");
  if (!cJSON_IsArray(arr)) BAD("field 'scanners': expected an array");
  int n = cJSON_GetArraySize(arr);
  if (n < 1 || n > 65535) BAD("field 'scanners': expected 1..65535 scanners, got %d", n);
  vd_scanner* sc = vd_malloc((size_t)n * sizeof *sc);
  if (!sc) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  int i = 0;
  for (const cJSON* e = arr->child; e; e = e->next, i++) {
    vd_scanner s = vd_scanner_default();
    double p[3] = {0}, t[3] = {0, 0, 0}, fov[2] = {0}, res[2] = {0};
    const char* what = NULL;
    if (!cJSON_IsObject(e)) what = "expected an object";
    if (!what && numbers(e, "position", p, 3) != 1) what = "'position': expected 3 numbers";
    int ht = what ? 0 : numbers(e, "target", t, 3);
    if (ht < 0) what = "'target': expected 3 numbers";
    int hf = what ? 0 : numbers(e, "fov", fov, 2);
    if (hf < 0 || (hf && !(fov[0] > 0 && fov[0] <= 360 && fov[1] > 0 && fov[1] <= 180)))
      what = "'fov': expected [horizontal, vertical] degrees in (0, 360] x (0, 180]";
    int hr = what ? 0 : numbers(e, "resolution", res, 2);
    if (hr < 0 || (hr && !(res[0] >= 1 && res[0] <= 100000 && res[1] >= 1 && res[1] <= 100000 &&
                          res[0] == floor(res[0]) && res[1] == floor(res[1]))))
      what = "'resolution': expected [across, down] integers in 1..100000";
    const cJSON* pat = what ? NULL : cJSON_GetObjectItemCaseSensitive(e, "pattern");
    if (pat && (!cJSON_IsString(pat) ||
                (strcmp(pat->valuestring, "angular") != 0 && strcmp(pat->valuestring, "pinhole") != 0)))
      what = "'pattern': expected \"angular\" or \"pinhole\"";
    if (what) {
      vd_free(sc, (size_t)n * sizeof *sc);
      BAD("scanners[%d]: %s", i, what);
    }
    // place in the world; the target defaults to the frame's origin
    vd_vec3 pv = vd_v3(p[0], p[1], p[2]), tv = vd_v3(t[0], t[1], t[2]);
    if (bbox) {
      pv = vd_madd(centre, pv, size);
      tv = vd_madd(centre, tv, size);
    }
    s.pos = pv;
    s.target = tv;
    if (hf) s.fov_h = fov[0] * VD_PI / 180.0, s.fov_v = fov[1] * VD_PI / 180.0;
    if (hr) s.res_h = (int)res[0], s.res_v = (int)res[1];
    if (pat) s.pattern = strcmp(pat->valuestring, "pinhole") ? VD_SCAN_ANGULAR : VD_SCAN_PINHOLE;
    if (vd_norm(vd_sub(s.target, s.pos)) == 0) {
      vd_free(sc, (size_t)n * sizeof *sc);
      BAD("scanners[%d]: target equals the position", i);
    }
    sc[i] = s;
  }
#undef BAD
  *out = sc;
  *nout = n;
  return VD_OK;
}

vd_status vd_cloud_parse_scanners(const char* text, size_t len, const char* name, vd_vec3 lo,
                                  vd_vec3 hi, vd_scanner** out, int* n, vd_error* err) {
  if (!name) name = "";
  if (!out || !n || (!text && len)) return vd_error_set(err, VD_ERR_ARG, name, 0, 0, "null argument");
  *out = NULL;
  *n = 0;
  const char* end = NULL;
  cJSON* root = cJSON_ParseWithLengthOpts(text ? text : "", len, &end, 0);
  if (!root) {
    int line, col;
    line_col(text ? text : "", len, end && text && end >= text ? (size_t)(end - text) : 0, &line, &col);
    return vd_error_set(err, VD_ERR_SYNTAX, name, line, col, "invalid JSON");
  }
  vd_status st = parse(root, name, lo, hi, out, n, err);
  cJSON_Delete(root);
  return st;
}

vd_status vd_cloud_read_scanners(const char* path, vd_vec3 lo, vd_vec3 hi, vd_scanner** out,
                                 int* n, vd_error* err) {
  if (!path || !out || !n) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "null argument");
  *out = NULL;
  *n = 0;
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  st = vd_cloud_parse_scanners(text, len, path, lo, hi, out, n, err);
  vd_free(text, len + 1);
  return st;
}
