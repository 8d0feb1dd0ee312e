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
