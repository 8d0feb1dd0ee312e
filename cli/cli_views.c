// SPDX-License-Identifier: MIT
// The views of `verdant dataset --images N`: render options (shadows, floor, sky, palette,
// supersampling) and what varies from view to view, drawn from the item's view stream: the
// camera's elevation, distance and an offset of the plant in the picture, the lights, the sky and
// floor colours. A view is made again by `verdant render` with the options its record gives.
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char* cli_view_help =
    "pictures (with --images N; each view drawn from the item's seed):\n"
    "      --no-shadows, --no-floor, --no-sky   leave those out of the pictures\n"
    "      --palette P       label colours: distinct (default) or natural (the label table's)\n"
    "      --supersample K   colour anti-aliasing, K x K samples per pixel (1..4, default 2)\n"
    "      --view-elevation A:B   camera elevation drawn in [A, B] degrees (default 10:40)\n"
    "      --view-distance A:B    camera distance drawn in [A, B] times the distance that fits the\n"
    "                        plant (0.2..10; default 1:1)\n"
    "      --view-jitter F   the point looked at moves by up to F times the plant's half-size\n"
    "                        along each axis (0..2, default 0): the plant off centre\n"
    "      --vary-light      key light from azimuth -180..180 and elevation 15..75 degrees,\n"
    "                        intensity 0.35..0.8, headlight 0.15..0.45, ambient 0.15..0.4\n"
    "      --vary-background sky and floor colours drawn per view (muted, random hues)\n";

void cli_view_opts_init(cli_view_opts* v) {
  memset(v, 0, sizeof *v);
  v->shadows = v->floor = v->sky = 1;
  v->supersample = 2;
  v->palette = VD_PALETTE_DISTINCT;
  v->el[0] = 10, v->el[1] = 40;
  v->dist[0] = v->dist[1] = 1;
}

// A:B with lo <= A <= B <= hi
static int parse_range(const char* s, double lo, double hi, double ab[2]) {
  char buf[128];
  snprintf(buf, sizeof buf, "%s", s ? s : "");
  char* colon = strchr(buf, ':');
  if (!colon) return 0;
  *colon = 0;
  return cli_parse_num(buf, &ab[0]) && cli_parse_num(colon + 1, &ab[1]) && ab[0] >= lo &&
         ab[0] <= ab[1] && ab[1] <= hi;
}

int cli_view_opt(cli_view_opts* v, const char* cmd, int argc, char** argv, int* i) {
  const char* a = argv[*i];
  const char* val = NULL;
  static const char* flags[] = {"--no-shadows", "--no-floor", "--no-sky", "--vary-light",
                                "--vary-background"};
  for (int k = 0; k < 5; k++)
    if (!strcmp(a, flags[k])) {
      int* f[5] = {&v->shadows, &v->floor, &v->sky, &v->vary_light, &v->vary_background};
      *f[k] = k >= 3;
      v->given = 1;
      return 1;
    }
  if (!strcmp(a, "--palette")) {
    CLI_TAKE();
    if (!cli_parse_palette(val, &v->palette)) {
      cli_usage_error(cmd, "--palette expects distinct or natural, got '%s'", val);
      return -1;
    }
  } else if (!strcmp(a, "--supersample")) {
    CLI_TAKE();
    double k;
    if (!cli_parse_num(val, &k) || k != floor(k) || k < 1 || k > 4) {
      cli_usage_error(cmd, "--supersample expects 1, 2, 3 or 4, got '%s'", val);
      return -1;
    }
    v->supersample = (int)k;
  } else if (!strcmp(a, "--view-elevation")) {
    CLI_TAKE();
    if (!parse_range(val, -89, 89, v->el)) {
      cli_usage_error(cmd, "--view-elevation expects A:B degrees, -89 <= A <= B <= 89, got '%s'", val);
      return -1;
    }
  } else if (!strcmp(a, "--view-distance")) {
    CLI_TAKE();
    if (!parse_range(val, 0.2, 10, v->dist)) {
      cli_usage_error(cmd, "--view-distance expects A:B, 0.2 <= A <= B <= 10, got '%s'", val);
      return -1;
    }
  } else if (!strcmp(a, "--view-jitter")) {
    CLI_TAKE();
    if (!cli_parse_num(val, &v->jitter) || v->jitter < 0 || v->jitter > 2) {
      cli_usage_error(cmd, "--view-jitter expects a fraction in [0, 2], got '%s'", val);
      return -1;
    }
  } else {
    return 0;
  }
  v->given = 1;
  return 1;
}

int cli_view_explicit(const cli_view_opts* v) {
  return v->dist[0] != 1 || v->dist[1] != 1 || v->jitter > 0;
}

void cli_view_def(const cli_view_opts* v, vd_render_def* def) {
  def->shadows = v->shadows, def->floor = v->floor, def->sky = v->sky;
  def->supersample = v->supersample;
}

// a muted colour of a random hue: saturation and value within the ranges
static void random_rgb(vd_rng* g, double s0, double s1, double v0, double v1, float rgb[3]) {
  double h = vd_rng_uniform(g, 0, 6), s = vd_rng_uniform(g, s0, s1), v = vd_rng_uniform(g, v0, v1);
  int i = (int)h % 6;
  double f = h - floor(h), p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double c[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  for (int k = 0; k < 3; k++)
    rgb[k] = (float)c[i][k];
}

void cli_view_draw(const cli_view_opts* v, vd_rng* g, double az, vd_vec3 lo, vd_vec3 hi, int w,
                   int h, vd_render_look look, cli_view* out) {
  memset(out, 0, sizeof *out);
  out->az = az;
  // the elevation first: the draw every view made before these options existed
  out->el = vd_rng_uniform(g, v->el[0], v->el[1]);
  out->dist = v->dist[0] < v->dist[1] ? vd_rng_uniform(g, v->dist[0], v->dist[1]) : v->dist[0];
  vd_vec3 shift = vd_v3(0, 0, 0);
  if (v->jitter > 0) {
    vd_vec3 half = vd_scale(vd_sub(hi, lo), 0.5);
    shift.x = v->jitter * half.x * vd_rng_uniform(g, -1, 1);
    shift.y = v->jitter * half.y * vd_rng_uniform(g, -1, 1);
    shift.z = v->jitter * half.z * vd_rng_uniform(g, -1, 1);
  }
  // the lights in the units of render --light (degrees), so that the record makes it again
  out->light[0] = look.light_azimuth * 180 / VD_PI, out->light[1] = look.light_elevation * 180 / VD_PI;
  out->light[2] = look.light, out->light[3] = look.headlight, out->light[4] = look.ambient;
  if (v->vary_light) {
    out->light[0] = vd_rng_uniform(g, -180, 180), out->light[1] = vd_rng_uniform(g, 15, 75);
    out->light[2] = vd_rng_uniform(g, 0.35, 0.8), out->light[3] = vd_rng_uniform(g, 0.15, 0.45);
    out->light[4] = vd_rng_uniform(g, 0.15, 0.4);
    look.light_azimuth = out->light[0] * VD_PI / 180;
    look.light_elevation = out->light[1] * VD_PI / 180;
    look.light = out->light[2], look.headlight = out->light[3], look.ambient = out->light[4];
  }
  if (v->vary_background) {
    // sky: a light zenith and a paler horizon; floor: a muted colour and a darker second
    random_rgb(g, 0.05, 0.45, 0.75, 1.0, look.sky[0]);
    random_rgb(g, 0.05, 0.35, 0.55, 0.9, look.sky[1]);
    random_rgb(g, 0.1, 0.6, 0.3, 0.8, look.floor[0]);
    for (int k = 0; k < 3; k++)
      look.floor[1][k] = 0.88f * look.floor[0][k];
  }
  out->look = look;
  // the camera: the orbit preset, moved back or in by the distance factor and shifted; with
  // either, the pose is explicit and its clip planes those `render --eye --lookat` gives
  vd_camera c = vd_camera_preset(VD_CAMERA_ORBIT, az * VD_PI / 180, out->el * VD_PI / 180, lo, hi,
                                 w, h);
  if (cli_view_explicit(v)) {
    cli_render_opts o;
    memset(&o, 0, sizeof o);
    o.has_eye = 1, o.fov = 45, o.up = c.up;
    o.lookat = vd_add(c.lookat, shift);
    o.eye = vd_add(vd_madd(c.lookat, vd_sub(c.eye, c.lookat), out->dist), shift);
    c = cli_render_camera(&o, lo, hi);
  }
  out->cam = c;
}

void cli_view_record(const cli_view_opts* v, const cli_view* view, cJSON* e) {
  cJSON_AddNumberToObject(e, "azimuth", view->az);
  cJSON_AddNumberToObject(e, "elevation", view->el);
  if (cli_view_explicit(v)) {
    double eye[3] = {view->cam.eye.x, view->cam.eye.y, view->cam.eye.z};
    double at[3] = {view->cam.lookat.x, view->cam.lookat.y, view->cam.lookat.z};
    double up[3] = {view->cam.up.x, view->cam.up.y, view->cam.up.z};
    cJSON_AddNumberToObject(e, "distance", view->dist);
    cJSON_AddItemToObject(e, "eye", cJSON_CreateDoubleArray(eye, 3));
    cJSON_AddItemToObject(e, "lookat", cJSON_CreateDoubleArray(at, 3));
    cJSON_AddItemToObject(e, "up", cJSON_CreateDoubleArray(up, 3));
  }
  if (v->vary_light) cJSON_AddItemToObject(e, "light", cJSON_CreateDoubleArray(view->light, 5));
  if (v->vary_background) {
    double sky[6], fl[6];
    for (int k = 0; k < 6; k++)
      sky[k] = view->look.sky[k / 3][k % 3], fl[k] = view->look.floor[k / 3][k % 3];
    cJSON_AddItemToObject(e, "sky", cJSON_CreateDoubleArray(sky, 6));
    cJSON_AddItemToObject(e, "floor", cJSON_CreateDoubleArray(fl, 6));
  }
}

void cli_view_recipe(const cli_view_opts* v, cJSON* a) {
  static const char* flag[3] = {"--no-shadows", "--no-floor", "--no-sky"};
  const int on[3] = {v->shadows, v->floor, v->sky};
  for (int k = 0; k < 3; k++)
    if (!on[k]) cJSON_AddItemToArray(a, cJSON_CreateString(flag[k]));
  if (v->palette != VD_PALETTE_DISTINCT) {
    cJSON_AddItemToArray(a, cJSON_CreateString("--palette"));
    cJSON_AddItemToArray(a, cJSON_CreateString("natural"));
  }
  if (v->supersample != 2) {
    char k[8];
    snprintf(k, sizeof k, "%d", v->supersample);
    cJSON_AddItemToArray(a, cJSON_CreateString("--supersample"));
    cJSON_AddItemToArray(a, cJSON_CreateString(k));
  }
  // the view's fields, each "A,B,..." from its array in the record
  const char* pairs[4][2] = {{"--eye", "{eye}"}, {"--lookat", "{lookat}"}, {"--up", "{up}"},
                             {"--light", "{light}"}};
  int first = cli_view_explicit(v) ? 0 : 3, last = v->vary_light ? 4 : 3;
  for (int k = first; k < last; k++) {
    cJSON_AddItemToArray(a, cJSON_CreateString(pairs[k][0]));
    cJSON_AddItemToArray(a, cJSON_CreateString(pairs[k][1]));
  }
  if (v->vary_background) {
    cJSON_AddItemToArray(a, cJSON_CreateString("--sky-rgb"));
    cJSON_AddItemToArray(a, cJSON_CreateString("{sky}"));
    cJSON_AddItemToArray(a, cJSON_CreateString("--floor-rgb"));
    cJSON_AddItemToArray(a, cJSON_CreateString("{floor}"));
  }
  if (!cli_view_explicit(v)) {
    cJSON_AddItemToArray(a, cJSON_CreateString("--camera"));
    cJSON_AddItemToArray(a, cJSON_CreateString("orbit:{azimuth}:{elevation}"));
  }
}
