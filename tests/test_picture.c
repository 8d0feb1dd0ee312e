// SPDX-License-Identifier: MIT
// picture: what a person sees in the colour images, measured on the pixels (with an OpenGL
// context; skipped without one): the legend's decimal point is a point on the baseline, not a
// comma.
#include <stdlib.h>

#include "render_helpers.h"
#include "test.h"

// ---------------------------------------------------------------------------------------------
// helpers

// luminance of pixel (x, y) of an RGB frame
static double lum(const vd_frame* f, int x, int y) {
  const uint8_t* p = f->rgb + 3 * ((size_t)y * f->width + x);
  return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
}

// is pixel (x, y) ink of dark grey text (darker than the white panel, without colour)?
static int ink(const vd_frame* f, int x, int y) {
  const uint8_t* p = f->rgb + 3 * ((size_t)y * f->width + x);
  int mx = p[0] > p[1] ? p[0] : p[1], mn = p[0] < p[1] ? p[0] : p[1];
  mx = p[2] > mx ? p[2] : mx, mn = p[2] < mn ? p[2] : mn;
  return lum(f, x, y) < 215 && mx - mn < 40;
}

// CIE L*a*b* (D65) of an sRGB colour in [0, 1]
static void srgb_lab(const double c[3], double lab[3]) {
  double l[3];
  for (int k = 0; k < 3; k++)
    l[k] = c[k] <= 0.04045 ? c[k] / 12.92 : pow((c[k] + 0.055) / 1.055, 2.4);
  double X = (0.4124 * l[0] + 0.3576 * l[1] + 0.1805 * l[2]) / 0.95047;
  double Y = 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
  double Z = (0.0193 * l[0] + 0.1192 * l[1] + 0.9505 * l[2]) / 1.08883;
  double f[3] = {X, Y, Z};
  for (int k = 0; k < 3; k++)
    f[k] = f[k] > 0.008856 ? cbrt(f[k]) : 7.787 * f[k] + 16.0 / 116;
  lab[0] = 116 * f[1] - 16, lab[1] = 500 * (f[0] - f[1]), lab[2] = 200 * (f[1] - f[2]);
}

// CIE76 colour difference of two sRGB colours
static double delta_e(const double a[3], const double b[3]) {
  double x[3], y[3];
  srgb_lab(a, x);
  srgb_lab(b, y);
  return sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
              (x[2] - y[2]) * (x[2] - y[2]));
}

// smallest colour difference between two labels of a table in a palette
static double palette_min_delta(const char* const* names, int n, vd_palette p) {
  vd_label lab[16] = {{0}};
  float rgb[16][3];
  for (int i = 0; i < n; i++)
    vd_label_init(&lab[i], i + 1, names[i]);
  vd_render_label_colors(lab, n, p, rgb);
  double best = 1e9;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) {
      double a[3] = {rgb[i][0], rgb[i][1], rgb[i][2]}, b[3] = {rgb[j][0], rgb[j][1], rgb[j][2]};
      best = fmin(best, delta_e(a, b));
    }
  return best;
}

// ---------------------------------------------------------------------------------------------
// the legend

TEST(picture, legend_decimal_point) {
  // a white page, one leaf coloured by displacement over a fixed scale 0 .. 0.5 m: the legend
  // ends with the numbers "0" and "0.5"; at supersample 2 MuJoCo's font sits the full stop a
  // row below the digits and it reads as "0,5"
  vd_render_def d = vd_render_def_default();
  d.width = 320, d.height = 240, d.supersample = 2, d.shadows = 0, d.floor = 0, d.sky = 0;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_vec3 v[4] = {{-0.2, 0, 0}, {0.2, 0, 0}, {0.2, 0, 0.3}, {-0.2, 0, 0.3}};
  vd_model* m = vdt_quad_plant(v, 2, 1);
  REQUIRE(m);
  vd_render_style s = vd_render_style_default();
  s.color_by = VD_COLOR_DISPLACEMENT, s.range_min = 0, s.range_max = 0.5;
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, &s, &err), VD_OK, err);
  // the leaf low in the image, away from the legend in the top right corner
  vd_camera c = {{0, -2, 0.8}, {0, 0, 0.8}, {0, 0, 1}, 0.8, 0.1, 10};
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  REQUIRE(f.rgb);
  // the lowest band of text rows in the top right quarter: the numbers under the colour bar
  int x0 = f.width / 2, y1 = f.height / 2, bottom = -1, top = -1;
  for (int y = y1; y >= 0 && top < 0; y--) {
    int any = 0;
    for (int x = x0; x < f.width; x++)
      any |= ink(&f, x, y);
    if (any && bottom < 0) bottom = y;
    if (!any && bottom >= 0) top = y + 1;
  }
  REQUIRE(bottom > 0 && top > 0);
  // glyphs of the band as runs of columns with ink, the last three "0", ".", "5"
  int g0[8], g1[8], ng = 0;
  for (int x = x0, in = 0; x <= f.width; x++) {
    int any = 0;
    for (int y = top; x < f.width && y <= bottom; y++)
      any |= ink(&f, x, y);
    if (any && !in && ng < 8) g0[ng] = x;
    if (!any && in && ng < 8) g1[ng++] = x - 1;
    in = any;
  }
  REQUIRE(ng >= 3);
  // the last three: "0", ".", "5"; lowest and highest ink row of each
  int lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    int g = ng - 3 + k;
    lo[g] = -1, hi[g] = f.height;
    for (int y = top; y <= bottom; y++)
      for (int x = g0[g]; x <= g1[g]; x++)
        if (ink(&f, x, y)) lo[k] = y > lo[k] ? y : lo[k], hi[k] = y < hi[k] ? y : hi[k];
  }
  // the point stands on the digits' baseline, no lower, and is no taller than wide
  int dot = ng - 2;
  CHECK(lo[1] <= lo[0] && lo[1] <= lo[2]);
  CHECK(lo[1] - hi[1] <= g1[dot] - g0[dot]);
  // and it is small: its top lies in the lower third of the digits
  CHECK(hi[1] > hi[0] + 2 * (lo[0] - hi[0]) / 3);
  vd_render_destroy(r);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// shadows

// a plant of two parallel upright leaves facing -Y: a big one (1.2 x 0.8 m, label 2) in the
// plane y = 0 and a small one (0.12 x 0.12 m, label 3) gap metres in front of it, centred at
// (sx, -gap, sz)
static vd_model* leaf_and_blocker(double gap, double sx, double sz) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  // corners counter-clockwise seen from -Y: the surface faces the camera
  vd_vec3 big[4] = {{-0.6, 0, 0.2}, {0.6, 0, 0.2}, {0.6, 0, 1.0}, {-0.6, 0, 1.0}};
  vd_vec3 small[4] = {{sx - 0.06, -gap, sz - 0.06},
                      {sx + 0.06, -gap, sz - 0.06},
                      {sx + 0.06, -gap, sz + 0.06},
                      {sx - 0.06, -gap, sz + 0.06}};
  int t[6] = {0, 1, 2, 0, 2, 3};
  vd_mesh_spec m = {0};
  m.node = -1, m.parent = -1, m.module = -1;
  m.label = 2, m.instance = 1;
  vd_plant_add_mesh(s, &m, big, 4, t, 2);
  m.label = 3, m.instance = 2;
  vd_plant_add_mesh(s, &m, small, 4, t, 2);
  vd_plant_set_label(s, 2, "leaf");
  vd_plant_set_label(s, 3, "leaflet");
  return vdt_compile(s);
}

TEST(picture, no_shadow_acne) {
  // A big upright leaf lit by the key light at 60 degrees from its normal, with nothing between
  // them except a small leaf 3 cm in front. Every pixel of the big leaf outside the small leaf's
  // shadow must look exactly as it does with shadows off (before: stripes of self-shadow, "acne",
  // on most of it), and the pixels inside the shadow must be darker (the shadow is still there).
  const double gap = 0.03, sx = 0.1, sz = 0.7;
  vd_model* m = leaf_and_blocker(gap, sx, sz);
  REQUIRE(m);
  vd_render_def d = vdt_small_def(320, 240);
  d.floor = 0;
  d.light_azimuth = -2.0, d.light_elevation = 1.0; // the defaults, written out: the geometry
                                                   // below depends on them
  vd_vec3 from = vd_v3(cos(1.0) * cos(-2.0), cos(1.0) * sin(-2.0), sin(1.0));
  vd_camera c = {{0, -2.2, 0.6}, {0, 0, 0.6}, {0, 0, 1}, 0.45, 0.1, 20};
  uint8_t* img[2] = {NULL, NULL};
  uint16_t* label = NULL;
  vd_frame f;
  vd_error err = {0};
  for (int shadows = 0; shadows < 2; shadows++) {
    d.shadows = shadows;
    vd_renderer* r = vdt_renderer(&d);
    if (!r) break;
    CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
    CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR | VD_LAYER_LABEL, &f, &err), VD_OK, err);
    size_t n = (size_t)f.width * f.height;
    img[shadows] = malloc(3 * n);
    if (img[shadows] && f.rgb) memcpy(img[shadows], f.rgb, 3 * n);
    if (!label) label = malloc(n * sizeof *label);
    if (label && f.label) memcpy(label, f.label, n * sizeof *label);
    vd_render_destroy(r);
  }
  if (img[0] && img[1] && label) {
    // classify the big leaf's pixels: the ray through the pixel centre meets the plane y = 0 at
    // p; p + t from meets the small leaf's plane (y = -gap) at q; q inside the small leaf
    // shrunk by 1.5 cm: in its shadow; outside it grown by 1.5 cm: lit; between: the penumbra
    // of the shadow map's texels, not judged
    int lit = 0, lit_dark = 0, shade = 0, shade_dark = 0;
    for (int y = 2; y < f.height - 2; y++)
      for (int x = 2; x < f.width - 2; x++) {
        // only pixels whose 5 x 5 neighbourhood is big leaf (no edges)
        int inner = 1;
        for (int j = -2; j <= 2 && inner; j++)
          for (int i = -2; i <= 2; i++)
            inner &= label[(size_t)(y + j) * f.width + x + i] == 2;
        if (!inner) continue;
        const vd_intrinsics* K = &f.K;
        double cx = (x - K->cx) / K->fx, cy = (y - K->cy) / K->fy;
        vd_vec3 dir = vd_v3(K->R[0] * cx + K->R[1] * cy + K->R[2], K->R[3] * cx + K->R[4] * cy + K->R[5],
                            K->R[6] * cx + K->R[7] * cy + K->R[8]);
        vd_vec3 p = vd_madd(K->t, dir, -K->t.y / dir.y);
        vd_vec3 q = vd_madd(p, from, gap / -from.y);
        double ex = fabs(q.x - sx), ez = fabs(q.z - sz);
        size_t k = 3 * ((size_t)y * f.width + x);
        double l0 = 0.299 * img[0][k] + 0.587 * img[0][k + 1] + 0.114 * img[0][k + 2];
        double l1 = 0.299 * img[1][k] + 0.587 * img[1][k + 1] + 0.114 * img[1][k + 2];
        if (ex < 0.06 - 0.015 && ez < 0.06 - 0.015)
          shade++, shade_dark += l1 < l0 - 20;
        else if (ex > 0.06 + 0.015 || ez > 0.06 + 0.015)
          lit++, lit_dark += l1 < l0 - 6;
      }
    fprintf(stderr, "  lit %d (%d darker), in shadow %d (%d darker)\n", lit, lit_dark, shade,
            shade_dark);
    CHECK(lit > 20000 && shade > 100);
    CHECK(lit_dark <= lit / 1000);      // no acne
    CHECK(shade_dark >= shade * 95 / 100); // the shadow is cast
  }
  free(img[0]);
  free(img[1]);
  free(label);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// the sidecar

TEST(picture, sidecar_names_opengl) {
  // which OpenGL drew an image: a GPU and Mesa's llvmpipe differ in the last bits of a picture
  vd_render_def d = vdt_small_def(32, 24);
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  const vd_render_gl* gl = vd_render_gl_info(r);
  CHECK(gl->vendor[0] && gl->renderer[0] && gl->version[0]);
  CHECK(strstr(vd_render_info(r), gl->renderer) != NULL);
  CHECK(gl->software == (strstr(gl->renderer, "llvmpipe") || strstr(gl->renderer, "softpipe") ||
                         strstr(gl->renderer, "swrast") || strstr(gl->renderer, "Software")));
  vd_camera c = {{0, -2, 0.5}, {0, 0, 0.5}, {0, 0, 1}, 0.8, 0.1, 10};
  vd_frame f;
  vd_error err = {0};
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK(f.gl == gl);
  char path[512];
  snprintf(path, sizeof path, "%s/gl.json", vdt_tmpdir());
  CHECK_STATUS(vd_render_write_json(&f, NULL, path, &err), VD_OK, err);
  char* text = NULL;
  size_t len = 0;
  CHECK_STATUS(vd_file_read(path, &text, &len, &err), VD_OK, err);
  if (text) {
    char want[300];
    snprintf(want, sizeof want, "\"renderer\":\t\"%s\"", gl->renderer);
    CHECK(strstr(text, "\"opengl\":") != NULL);
    CHECK(strstr(text, want) != NULL);
    CHECK(strstr(text, gl->software ? "\"software\":\ttrue" : "\"software\":\tfalse") != NULL);
    vd_free(text, len + 1);
  }
  vd_render_destroy(r);
}

// ---------------------------------------------------------------------------------------------
// label colours

TEST(picture, palette_tells_classes_apart) {
  // the bundled plants' label tables: labels of one organ kind (trunk and branch; leaf,
  // peduncle and pedicel) had near-identical colours (CIE76 5.2 for trunk/branch, 11.6 for
  // leaf/peduncle); the default palette keeps every pair at least 25 apart
  static const char* tomato[] = {"stem", "leaf", "peduncle", "pedicel", "fruit", "flower"};
  static const char* tree[] = {"trunk", "branch", "leaf", "root"};
  static const char* arabidopsis[] = {"internode", "leaf", "flower", "silique"};
  static const char* many[] = {"stem", "branch", "twig", "leaf", "leaflet", "petiole", "flower",
                               "petal", "fruit", "berry", "pedicel", "peduncle", "root", "a",
                               "b"};
  CHECK(palette_min_delta(tomato, 6, VD_PALETTE_DISTINCT) >= 25);
  CHECK(palette_min_delta(tree, 4, VD_PALETTE_DISTINCT) >= 25);
  CHECK(palette_min_delta(arabidopsis, 4, VD_PALETTE_DISTINCT) >= 25);
  CHECK(palette_min_delta(many, 15, VD_PALETTE_DISTINCT) >= 25);
  // the natural palette is the label table's (organ colours), kept as an option
  CHECK(palette_min_delta(tree, 4, VD_PALETTE_NATURAL) < 10);
  // organ-like where it can: leaf green, fruit red (green and red channels dominate)
  vd_label lab[6];
  float rgb[6][3];
  for (int i = 0; i < 6; i++)
    vd_label_init(&lab[i], i + 1, tomato[i]);
  vd_render_label_colors(lab, 6, VD_PALETTE_DISTINCT, rgb);
  CHECK(rgb[1][1] > rgb[1][0] && rgb[1][1] > rgb[1][2]);
  CHECK(rgb[4][0] > rgb[4][1] && rgb[4][0] > rgb[4][2]);

  // in a picture of the tomato, the mean colours of the labels' pixels stay apart too
  vd_render_def d = vdt_small_def(480, 360);
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_model* m = vdt_tomato(2);
  REQUIRE(m);
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
  vd_vec3 lo, hi;
  vd_render_bounds(r, &lo, &hi);
  vd_camera c = vd_camera_preset(VD_CAMERA_FRONT, 0, 0, lo, hi, d.width, d.height);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR | VD_LAYER_LABEL, &f, &err), VD_OK, err);
  CHECK(f.palette == VD_PALETTE_DISTINCT);
  double sum[8][3] = {{0}};
  int count[8] = {0};
  for (int i = 0; f.label && i < f.width * f.height; i++) {
    int l = f.label[i];
    if (l < 1 || l > 6) continue;
    count[l]++;
    for (int k = 0; k < 3; k++)
      sum[l][k] += f.rgb[3 * i + k] / 255.0;
  }
  int pairs = 0;
  for (int a = 1; a <= 6; a++)
    for (int b = a + 1; b <= 6; b++) {
      if (count[a] < 20 || count[b] < 20) continue;
      double ca[3], cb[3];
      for (int k = 0; k < 3; k++)
        ca[k] = sum[a][k] / count[a], cb[k] = sum[b][k] / count[b];
      double de = delta_e(ca, cb);
      if (de < 15) fprintf(stderr, "  labels %d and %d: colour difference %.1f\n", a, b, de);
      CHECK(de >= 15);
      pairs++;
    }
  CHECK(pairs >= 6);
  vd_render_destroy(r);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// colour scales

TEST(picture, scale_follows_the_attached_plant) {
  // the tomato moved 3 cm, one fruit fallen 1 m below its calyx and a branch broken off and
  // dropped 0.5 m: the automatic scale is the plant's 3 cm (was 1 m), and the parts that came off
  // are drawn in the scale's end colour
  vd_model* m = vdt_tomato(1);
  REQUIRE(m);
  vd_data* d = vd_data_create(m);
  REQUIRE(d);
  for (int i = 0; i < 3 * m->nnode; i += 3)
    d->node_pos[i] += 0.03;
  for (int i = 0; i < 3 * m->nsphere; i += 3)
    d->sphere_pos[i] += 0.03;
  for (int i = 0; i < 3 * m->nvert; i += 3)
    d->vert_pos[i] += 0.03;
  vd_render_style s = vd_render_style_default();
  s.color_by = VD_COLOR_DISPLACEMENT;
  double lo, hi;
  vd_error err = {0};
  CHECK_STATUS(vd_render_value_range(m, d, &s, &lo, &hi, &err), VD_OK, err);
  CHECK_NEAR(lo, 0.03, 1e-9);
  CHECK_NEAR(hi, 0.03, 1e-9);
  // a fruit falls: its sphere leaves its attachment node
  int fruit = -1;
  for (int k = 0; k < m->nsphere && fruit < 0; k++)
    if (m->sphere_node[k] >= 0 || m->sphere_parent[k] >= 0) fruit = k;
  REQUIRE(fruit >= 0);
  d->sphere_pos[3 * fruit + 2] -= 1.0;
  CHECK_STATUS(vd_render_value_range(m, d, &s, &lo, &hi, &err), VD_OK, err);
  CHECK_NEAR(hi, 0.03, 1e-9);
  // a branch breaks off: a segment with children, marked broken, its subtree dropped 0.5 m
  int cut = -1;
  for (int j = 0; j < m->nseg && cut < 0; j++)
    if (m->seg_parent[j] >= 0 && m->seg_parent[m->seg_parent[j]] >= 0)
      for (int c = 0; c < m->nseg; c++)
        if (m->seg_parent[c] == j) cut = j;
  REQUIRE(cut >= 0);
  d->seg_broken[cut] = 1;
  for (int j = 0; j < m->nseg; j++) {
    int a = j;
    while (a >= 0 && a != cut)
      a = m->seg_parent[a];
    if (a == cut) d->node_pos[3 * m->seg_node[2 * j + 1] + 2] -= 0.5;
  }
  CHECK_STATUS(vd_render_value_range(m, d, &s, &lo, &hi, &err), VD_OK, err);
  CHECK_NEAR(hi, 0.03, 1e-9);
  // a fixed range is the caller's; the plant renderer takes the attached scale too
  vd_render_def def = vdt_small_def(64, 48);
  vd_renderer* r = vdt_renderer(&def);
  if (r) {
    CHECK_STATUS(vd_render_add_plant(r, m, d, &s, &err), VD_OK, err);
    vd_vec3 blo, bhi;
    vd_render_bounds(r, &blo, &bhi);
    vd_camera c = vd_camera_preset(VD_CAMERA_FRONT, 0, 0, blo, bhi, 64, 48);
    vd_frame f;
    CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
    CHECK_NEAR(f.range_max, 0.03, 1e-9);
    vd_render_destroy(r);
  }
  // stress: the same rule
  s.color_by = VD_COLOR_STRESS;
  double* stress = malloc(sizeof(double) * (size_t)m->nseg);
  REQUIRE(stress);
  for (int j = 0; j < m->nseg; j++)
    stress[j] = j == cut ? 1e9 : 1e6;
  s.seg_stress = stress;
  CHECK_STATUS(vd_render_value_range(m, d, &s, &lo, &hi, &err), VD_OK, err);
  CHECK_NEAR(hi, 1e6, 1e-3);
  free(stress);
  vd_data_destroy(d);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// the look: lights, sky and floor colours between frames

TEST(picture, look_changes_between_frames) {
  vd_render_def d = vdt_small_def(160, 120);
  d.shadows = 1;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_vec3 v[4] = {{-0.2, 0, 0.1}, {0.2, 0, 0.1}, {0.2, 0, 0.5}, {-0.2, 0, 0.5}};
  vd_model* m = vdt_quad_plant(v, 2, 1);
  REQUIRE(m);
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
  // a camera that sees the floor in the lower half and the sky in the upper
  vd_camera c = {{0, -3, 0.6}, {0, 0, 0.3}, {0, 0, 1}, 0.9, 0.05, 60};
  size_t n = 3 * 160 * 120;
  uint8_t* img0 = malloc(n);
  REQUIRE(img0);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR | VD_LAYER_LABEL, &f, &err), VD_OK, err);
  memcpy(img0, f.rgb, n);
  vd_render_look def = vd_render_get_look(r);
  CHECK_NEAR(def.light, d.light, 0);
  CHECK_NEAR(def.floor[0][0], 0.62f, 0);
  // a red floor, a dark blue sky, light from the other side
  vd_render_look look = def;
  look.light_azimuth = 1.0, look.light_elevation = 0.5, look.ambient = 0.2;
  const float red[2][3] = {{0.9f, 0.1f, 0.1f}, {0.7f, 0.05f, 0.05f}};
  const float blue[2][3] = {{0.05f, 0.1f, 0.5f}, {0.1f, 0.2f, 0.6f}};
  memcpy(look.floor, red, sizeof red);
  memcpy(look.sky, blue, sizeof blue);
  CHECK_STATUS(vd_render_set_look(r, &look, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR | VD_LAYER_LABEL, &f, &err), VD_OK, err);
  // floor pixels (bottom rows, background in the mask) are red, sky pixels (top rows) blue
  int floor_red = 0, floor_n = 0, sky_blue = 0, sky_n = 0;
  for (int y = 0; y < 120; y++)
    for (int x = 0; x < 160; x++) {
      if (f.label[y * 160 + x]) continue;
      const uint8_t* p = f.rgb + 3 * (y * 160 + x);
      if (y >= 110) floor_n++, floor_red += p[0] > 2 * p[1] && p[0] > 2 * p[2];
      if (y < 10) sky_n++, sky_blue += p[2] > p[0] + 40 && p[2] > p[1];
    }
  CHECK(floor_n > 1000 && floor_red == floor_n);
  CHECK(sky_n > 1000 && sky_blue == sky_n);
  // back to the look it was made with: the same bytes again
  CHECK_STATUS(vd_render_set_look(r, &def, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK(!memcmp(img0, f.rgb, n));
  // out of range
  look = def, look.floor[1][2] = 1.5f;
  CHECK_STATUS(vd_render_set_look(r, &look, &err), VD_ERR_ARG, err);
  look = def, look.light_elevation = 0;
  CHECK_STATUS(vd_render_set_look(r, &look, &err), VD_ERR_ARG, err);
  free(img0);
  vd_render_destroy(r);
  vd_model_destroy(m);
}
