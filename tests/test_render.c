// SPDX-License-Identifier: MIT
// render: camera presets and intrinsics; with an OpenGL context (tests that need one print why
// and skip when none can be made here): masks agree with geometry (one leaf: its pixels carry its
// label and instance, the background 0), depth of planes against ray casting within 1 mm, point
// splats, a robot from MJCF, identical images for a seed, PNG round trips, bad input.
#include <stdlib.h>

#include "render_helpers.h"
#include "test.h"
#include "verdant/verdant.h"

// ---------------------------------------------------------------------------------------------
// helpers

// a camera at eye looking along +Y with Z up
static vd_camera cam_y(vd_vec3 eye, double fovy_deg) {
  vd_camera c;
  c.eye = eye;
  c.lookat = vd_add(eye, vd_v3(0, 1, 0));
  c.up = vd_v3(0, 0, 1);
  c.fovy = fovy_deg * VD_PI / 180;
  c.znear = 0.05;
  c.zfar = 50;
  return c;
}

// ---------------------------------------------------------------------------------------------
// cameras (no context needed)

TEST(render, camera_preset_fits_box) {
  vd_vec3 lo = vd_v3(-0.4, -0.3, 0), hi = vd_v3(0.5, 0.45, 1.4);
  vd_camera_kind kinds[] = {VD_CAMERA_FRONT, VD_CAMERA_SIDE, VD_CAMERA_TOP, VD_CAMERA_ORBIT};
  for (int k = 0; k < 4; k++) {
    vd_camera c = vd_camera_preset(kinds[k], 0.7, 0.4, lo, hi, 640, 480);
    vd_error err = {0};
    CHECK_STATUS(vd_camera_check(&c, &err), VD_OK, err);
    vd_intrinsics K = vd_camera_intrinsics(&c, 640, 480);
    // every corner projects inside the image and between the clip planes
    double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
    for (int i = 0; i < 8; i++) {
      vd_vec3 p = vd_v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
      double u, v, z;
      CHECK(vd_camera_project(&K, p, &u, &v, &z));
      CHECK(u >= -0.5 && u <= 639.5 && v >= -0.5 && v <= 479.5);
      CHECK(z > c.znear && z < c.zfar);
      umin = fmin(umin, u), umax = fmax(umax, u), vmin = fmin(vmin, v), vmax = fmax(vmax, v);
    }
    // and the box fills the image in one direction (a tight fit, within the 8% margin)
    CHECK(umax - umin > 0.8 * 640 || vmax - vmin > 0.8 * 480);
  }
}

TEST(render, camera_intrinsics) {
  vd_camera c = cam_y(vd_v3(0, -2, 0.5), 60);
  vd_intrinsics K = vd_camera_intrinsics(&c, 400, 300);
  CHECK_NEAR(K.fy, 150 / tan(VD_PI / 6), 1e-9);
  CHECK_NEAR(K.fx, K.fy, 1e-12);
  CHECK_NEAR(K.cx, 199.5, 1e-12);
  CHECK_NEAR(K.cy, 149.5, 1e-12);
  // the look-at point is the principal point; up in the world is up in the image (v smaller)
  double u, v, z;
  CHECK(vd_camera_project(&K, vd_v3(0, 0, 0.5), &u, &v, &z));
  CHECK_NEAR(u, 199.5, 1e-9);
  CHECK_NEAR(v, 149.5, 1e-9);
  CHECK_NEAR(z, 2, 1e-12);
  CHECK(vd_camera_project(&K, vd_v3(0.1, 0, 0.6), &u, &v, &z));
  CHECK(u > 199.5 && v < 149.5);
  CHECK(!vd_camera_project(&K, vd_v3(0, -3, 0.5), &u, &v, &z));
  // bad cameras
  vd_error err = {0};
  vd_camera b = c;
  b.fovy = 0;
  CHECK_STATUS(vd_camera_check(&b, &err), VD_ERR_VALUE, err);
  b = c, b.up = vd_v3(0, 1, 0);
  CHECK_STATUS(vd_camera_check(&b, &err), VD_ERR_VALUE, err);
  b = c, b.znear = 2, b.zfar = 1;
  CHECK_STATUS(vd_camera_check(&b, &err), VD_ERR_VALUE, err);
  b = c, b.eye.x = NAN;
  CHECK_STATUS(vd_camera_check(&b, &err), VD_ERR_VALUE, err);
  b = c, b.lookat = b.eye;
  CHECK_STATUS(vd_camera_check(&b, &err), VD_ERR_VALUE, err);
}

TEST(render, bad_settings) {
  vd_renderer* r = NULL;
  vd_error err = {0};
  vd_render_def d = vd_render_def_default();
  d.width = 0;
  CHECK_STATUS(vd_render_create(&d, &r, &err), VD_ERR_ARG, err);
  d = vd_render_def_default(), d.supersample = 5;
  CHECK_STATUS(vd_render_create(&d, &r, &err), VD_ERR_ARG, err);
  d = vd_render_def_default(), d.ambient = NAN;
  CHECK_STATUS(vd_render_create(&d, &r, &err), VD_ERR_ARG, err);
  CHECK(r == NULL);
}

// ---------------------------------------------------------------------------------------------
// masks and depth

TEST(render, one_leaf_mask) {
  vd_render_def d = vdt_small_def(200, 150);
  d.floor = 0;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  // a leaf 0.4 x 0.3 m facing the camera 2 m away, label 2, instance 5
  vd_vec3 v[4] = {{-0.2, 0, 0.35}, {0.2, 0, 0.35}, {0.2, 0, 0.65}, {-0.2, 0, 0.65}};
  vd_model* m = vdt_quad_plant(v, 2, 5);
  REQUIRE(m);
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
  vd_camera c = cam_y(vd_v3(0.03, -2, 0.52), 40);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_ALL, &f, &err), VD_OK, err);
  REQUIRE(f.label && f.instance && f.depth && f.rgb);
  // the leaf's rectangle in the image from the intrinsics
  double u0, v0, u1, v1, z;
  vd_camera_project(&f.K, v[3], &u0, &v0, &z);
  vd_camera_project(&f.K, v[1], &u1, &v1, &z);
  int inside = 0, wrong = 0, edge = 0, area = 0;
  for (int y = 0; y < f.height; y++)
    for (int x = 0; x < f.width; x++) {
      int l = f.label[y * f.width + x], in = f.instance[y * f.width + x];
      // pixel centres more than half a pixel inside or outside the rectangle are certain
      int in_rect = x > u0 + 0.5 && x < u1 - 0.5 && y > v0 + 0.5 && y < v1 - 0.5;
      int out_rect = x < u0 - 0.5 || x > u1 + 0.5 || y < v0 - 0.5 || y > v1 + 0.5;
      if (l) area++;
      if (in_rect)
        inside++, wrong += !(l == 2 && in == 5);
      else if (out_rect)
        wrong += l != 0 || in != 0;
      else
        edge += l != 0 && !(l == 2 && in == 5); // no mixed ids on the edge either
    }
  CHECK(inside > 1000);
  CHECK_INT(wrong, 0);
  CHECK_INT(edge, 0);
  // the labelled area is the projected area within a pixel's border
  double exact = (u1 - u0) * (v1 - v0);
  CHECK(fabs(area - exact) < (u1 - u0 + v1 - v0) + 4);
  // the sidecar legend names the leaf
  CHECK_INT(f.nlegend, 1);
  CHECK_INT(f.legend[0].id, 2);
  CHECK_STR(f.legend[0].name, "leaf");
  vd_render_destroy(r);
  vd_model_destroy(m);
}

// distance along the optical axis to plane (p0, n) through pixel (u, v) of K, or 0
static double ray_plane(const vd_intrinsics* K, double u, double v, vd_vec3 p0, vd_vec3 n) {
  double X = (u - K->cx) / K->fx, Y = (v - K->cy) / K->fy;
  vd_vec3 dir = vd_v3(K->R[0] * X + K->R[1] * Y + K->R[2], K->R[3] * X + K->R[4] * Y + K->R[5],
                      K->R[6] * X + K->R[7] * Y + K->R[8]);
  double den = vd_dot(dir, n);
  if (fabs(den) < 1e-12) return 0;
  return vd_dot(vd_sub(p0, K->t), n) / den; // dir has camera z = 1, so t is the depth
}

TEST(render, depth_of_planes) {
  vd_render_def d = vdt_small_def(160, 120);
  d.floor = 0;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_error err = {0};
  // a plane facing the camera at 1.2345 m, and a plane tilted by 50 degrees
  double dist = 1.2345;
  vd_vec3 a[4] = {{-3, dist, -3}, {3, dist, -3}, {3, dist, 3}, {-3, dist, 3}};
  double s = sin(50 * VD_PI / 180), co = cos(50 * VD_PI / 180);
  vd_vec3 b[4] = {{-3, 2.5 - 3 * s, -3 * co},
                  {3, 2.5 - 3 * s, -3 * co},
                  {3, 2.5 + 3 * s, 3 * co},
                  {-3, 2.5 + 3 * s, 3 * co}};
  vd_vec3 nb = vd_normalize(vd_cross(vd_sub(b[1], b[0]), vd_sub(b[3], b[0])));
  for (int k = 0; k < 2; k++) {
    vd_render_clear(r);
    vd_model* m = vdt_quad_plant(k ? b : a, 1, 1);
    REQUIRE(m);
    CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
    vd_camera c = cam_y(vd_v3(0, 0, 0), 50);
    c.znear = 0.01;
    c.zfar = 100;
    vd_frame f;
    CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_DEPTH | VD_LAYER_LABEL, &f, &err), VD_OK, err);
    REQUIRE(f.depth && !f.rgb);
    double worst = 0;
    int n = 0;
    for (int y = 0; y < f.height; y++)
      for (int x = 0; x < f.width; x++) {
        double want = ray_plane(&f.K, x, y, k ? b[0] : a[0], k ? nb : vd_v3(0, -1, 0));
        double got = f.depth[y * f.width + x];
        if (f.label[y * f.width + x] != 1) continue;
        worst = fmax(worst, fabs(got - want));
        n++;
      }
    CHECK(n > f.width * f.height * 9 / 10); // the planes (nearly) fill the view
    CHECK(worst < 1e-3);
    if (k == 0) {
      // the 16-bit PNG holds millimetres
      char path[512];
      snprintf(path, sizeof path, "%s/depth.png", vdt_tmpdir());
      CHECK_STATUS(vd_render_write_png(&f, VD_LAYER_DEPTH, path, &err), VD_OK, err);
      int w, h, ch, bits;
      uint16_t* pix;
      CHECK_STATUS(vd_render_read_png(path, &w, &h, &ch, &bits, &pix, &err), VD_OK, err);
      if (pix) {
        CHECK_INT(w * h, f.width * f.height);
        CHECK_INT(ch, 1);
        CHECK_INT(bits, 16);
        CHECK(abs((int)pix[0] - 1235) <= 1); // 1234.5 mm, rounded
        CHECK(abs((int)pix[w * h / 2 + w / 2] - 1235) <= 1);
        vd_free(pix, (size_t)w * h * ch * sizeof(uint16_t));
      }
    }
    vd_model_destroy(m);
  }
  vd_render_destroy(r);
}

TEST(render, tomato_masks_consistent) {
  vd_render_def d = vdt_small_def(320, 240);
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_model* m = vdt_tomato(4);
  REQUIRE(m);
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
  vd_vec3 lo, hi;
  CHECK(vd_render_bounds(r, &lo, &hi));
  vd_camera c = vd_camera_preset(VD_CAMERA_ORBIT, -1, 0.3, lo, hi, 320, 240);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_ALL, &f, &err), VD_OK, err);
  // every instance in the mask has one label, the one the model gives it; floor pixels are 0
  // but have depth; sky pixels have no depth
  int* inst_label = calloc((size_t)m->ninstance + 1, sizeof(int));
  REQUIRE(inst_label);
  for (int i = 0; i < m->nseg; i++)
    inst_label[m->seg_instance[i]] = m->seg_label[i];
  for (int i = 0; i < m->nsphere; i++)
    inst_label[m->sphere_instance[i]] = m->sphere_label[i];
  for (int i = 0; i < m->nmesh; i++)
    inst_label[m->mesh_instance[i]] = m->mesh_label[i];
  int plant = 0, bad = 0, floor_px = 0, sky = 0, labels_seen = 0;
  for (int i = 0; i < f.width * f.height; i++) {
    int in = f.instance[i], l = f.label[i];
    if (in) {
      plant++;
      bad += in > m->ninstance || inst_label[in] != l;
      labels_seen |= 1 << (l & 31);
    } else {
      bad += l != 0;
      if (f.depth[i] > 0)
        floor_px++;
      else
        sky++;
    }
  }
  free(inst_label);
  CHECK_INT(bad, 0);
  CHECK(plant > 1000);
  CHECK(floor_px > 1000 && sky > 1000);
  CHECK(labels_seen & (1 << 2)); // leaves
  CHECK(labels_seen & (1 << 1)); // stem
  vd_render_destroy(r);
  vd_model_destroy(m);
}

TEST(render, deterministic) {
  // the same seed twice, from fresh renderers: identical colour and masks; another seed differs
  uint8_t* rgb[3] = {NULL, NULL, NULL};
  uint16_t* lab[3] = {NULL, NULL, NULL};
  size_t n = 240 * 180;
  uint64_t seeds[3] = {7, 7, 8};
  int ran = 0;
  for (int k = 0; k < 3; k++) {
    vd_render_def d = vd_render_def_default();
    d.width = 240, d.height = 180;
    vd_renderer* r = vdt_renderer(&d);
    if (!r) break;
    vd_model* m = vdt_tomato(seeds[k]);
    vd_error err = {0};
    if (m) CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
    vd_vec3 lo, hi;
    vd_render_bounds(r, &lo, &hi);
    vd_camera c = vd_camera_preset(VD_CAMERA_FRONT, 0, 0, lo, hi, 240, 180);
    vd_frame f;
    CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR | VD_LAYER_LABEL, &f, &err), VD_OK, err);
    rgb[k] = malloc(3 * n);
    lab[k] = malloc(2 * n);
    if (rgb[k] && lab[k] && f.rgb && f.label)
      memcpy(rgb[k], f.rgb, 3 * n), memcpy(lab[k], f.label, 2 * n);
    vd_render_destroy(r);
    vd_model_destroy(m);
    ran++;
  }
  if (ran == 3) {
    CHECK(memcmp(rgb[0], rgb[1], 3 * n) == 0);
    CHECK(memcmp(lab[0], lab[1], 2 * n) == 0);
    CHECK(memcmp(lab[0], lab[2], 2 * n) != 0);
  }
  for (int k = 0; k < 3; k++)
    free(rgb[k]), free(lab[k]);
}

TEST(render, colour_modes_and_legend) {
  vd_render_def d = vdt_small_def(160, 120);
  d.legend = 1;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_model* m = vdt_tomato(1);
  REQUIRE(m);
  vd_data* st = vd_data_create(m);
  REQUIRE(st);
  vd_error err = {0};
  // displacement: move the whole plant by 3 cm, every primitive has moved 3 cm
  for (int i = 0; i < 3 * m->nnode; i += 3)
    st->node_pos[i] += 0.03;
  for (int i = 0; i < 3 * m->nsphere; i += 3)
    st->sphere_pos[i] += 0.03;
  for (int i = 0; i < 3 * m->nvert; i += 3)
    st->vert_pos[i] += 0.03;
  vd_render_style s = vd_render_style_default();
  s.color_by = VD_COLOR_DISPLACEMENT;
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_OK, err);
  vd_vec3 lo, hi;
  vd_render_bounds(r, &lo, &hi);
  vd_camera c = vd_camera_preset(VD_CAMERA_FRONT, 0, 0, lo, hi, 160, 120);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK_NEAR(f.range_min, 0.03, 1e-9);
  CHECK_NEAR(f.range_max, 0.03, 1e-9);
  CHECK(f.color_by == VD_COLOR_DISPLACEMENT);
  CHECK(f.nlegend >= 4); // the key of the label mask, whatever the colouring
  // stress needs values; with them, the range is theirs
  vd_render_clear(r);
  s.color_by = VD_COLOR_STRESS;
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_ERR_ARG, err);
  double* stress = malloc(sizeof(double) * (size_t)m->nseg);
  REQUIRE(stress);
  for (int i = 0; i < m->nseg; i++)
    stress[i] = 1e5 * i;
  s.seg_stress = stress;
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_ALL, &f, &err), VD_OK, err);
  CHECK_NEAR(f.range_max, 1e5 * (m->nseg - 1), 1e-6);
  // NaN is "no value" (grey, left out of the range); infinity is refused
  stress[3] = NAN;
  vd_render_clear(r);
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK_NEAR(f.range_max, 1e5 * (m->nseg - 1), 1e-6);
  stress[3] = INFINITY;
  vd_render_clear(r);
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_ERR_VALUE, err);
  free(stress);
  // by label: the legend lists the plant's labels in id order with their names
  vd_render_clear(r);
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, NULL, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK(f.nlegend >= 4);
  for (int i = 1; i < f.nlegend; i++)
    CHECK(f.legend[i].id > f.legend[i - 1].id);
  CHECK(vd_model_find_label(m, f.legend[0].id) != NULL);
  if (f.nlegend) CHECK_STR(f.legend[0].name, vd_model_find_label(m, f.legend[0].id)->name);
  // a layer that was not drawn cannot be written; a bad layer mask is refused
  CHECK_STATUS(vd_render_draw(r, &c, 0, &f, &err), VD_ERR_ARG, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  char path[512];
  snprintf(path, sizeof path, "%s/none.png", vdt_tmpdir());
  CHECK_STATUS(vd_render_write_png(&f, VD_LAYER_LABEL, path, &err), VD_ERR_ARG, err);
  vd_data_destroy(st);
  vd_render_destroy(r);
  vd_model_destroy(m);
}

TEST(render, point_splats) {
  vd_render_def d = vdt_small_def(200, 150);
  d.floor = 0;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  // two clusters of points: label 3 instance 7 on the left, label 4 instance 9 on the right
  enum { N = 200 };
  double xyz[3 * N];
  int lab[N], inst[N];
  for (int i = 0; i < N; i++) {
    int right = i >= N / 2;
    xyz[3 * i] = (right ? 0.3 : -0.3) + 0.002 * (i % 10);
    xyz[3 * i + 1] = 0.01 * (i % 7);
    xyz[3 * i + 2] = 0.5 + 0.002 * ((i / 10) % 10);
    lab[i] = right ? 4 : 3;
    inst[i] = right ? 9 : 7;
  }
  vd_label names[2] = {{3, "fruit", VD_ORGAN_FRUIT, {1, 0, 0}},
                       {4, "leaf", VD_ORGAN_LEAF, {0, 1, 0}}};
  vd_points p = {N, xyz, lab, inst, 0.01, names, 2};
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_points(r, &p, NULL, &err), VD_OK, err);
  vd_camera c = cam_y(vd_v3(0, -2, 0.51), 40);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_ALL, &f, &err), VD_OK, err);
  // the pixel at each cluster's first point carries its ids; the corners are background
  double u, v, z;
  vd_camera_project(&f.K, vd_v3(xyz[0], xyz[1], xyz[2]), &u, &v, &z);
  int at = (int)lround(v) * f.width + (int)lround(u);
  CHECK_INT(f.label[at], 3);
  CHECK_INT(f.instance[at], 7);
  vd_camera_project(&f.K, vd_v3(xyz[3 * N - 3], xyz[3 * N - 2], xyz[3 * N - 1]), &u, &v, &z);
  at = (int)lround(v) * f.width + (int)lround(u);
  CHECK_INT(f.label[at], 4);
  CHECK_INT(f.instance[at], 9);
  CHECK_INT(f.label[0], 0);
  CHECK_INT(f.nlegend, 2);
  CHECK_STR(f.legend[1].name, "leaf");
  // a second camera rebuilds the splats to face it
  vd_camera c2 = c;
  c2.eye = vd_v3(-2, 0.03, 0.51), c2.lookat = vd_v3(0, 0.03, 0.51); // label 3 in front
  CHECK_STATUS(vd_render_draw(r, &c2, VD_LAYER_LABEL, &f, &err), VD_OK, err);
  int n3 = 0;
  for (int i = 0; i < f.width * f.height; i++)
    n3 += f.label[i] == 3;
  CHECK(n3 > 20);
  // bad points
  xyz[5] = NAN;
  CHECK_STATUS(vd_render_add_points(r, &p, NULL, &err), VD_ERR_VALUE, err);
  xyz[5] = 0;
  lab[0] = 70000;
  CHECK_STATUS(vd_render_add_points(r, &p, NULL, &err), VD_ERR_LIMIT, err);
  lab[0] = 3;
  vd_render_style s = vd_render_style_default();
  s.color_by = VD_COLOR_DISPLACEMENT;
  CHECK_STATUS(vd_render_add_points(r, &p, &s, &err), VD_ERR_ARG, err);
  vd_render_destroy(r);
}

// a robot in MJCF: a red capsule standing in front of the plant
static const char* robot_xml =
    "<mujoco model=\"post\">\n"
    "  <worldbody>\n"
    "    <body name=\"post\" pos=\"0 -1 0.5\">\n"
    "      <joint name=\"slide\" type=\"slide\" axis=\"1 0 0\"/>\n"
    "      <geom type=\"capsule\" size=\"0.05 0.3\" rgba=\"0.8 0.2 0.2 1\"/>\n"
    "    </body>\n"
    "  </worldbody>\n"
    "</mujoco>\n";

TEST(render, robot_from_mjcf) {
  char path[512];
  snprintf(path, sizeof path, "%s/post.xml", vdt_tmpdir());
  FILE* fp = fopen(path, "w");
  REQUIRE(fp);
  fputs(robot_xml, fp);
  fclose(fp);
  vd_render_def d = vdt_small_def(160, 120);
  d.robot_mjcf = path;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_camera c = cam_y(vd_v3(0, -3, 0.5), 40);
  vd_frame f;
  vd_error err = {0};
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_LABEL | VD_LAYER_DEPTH, &f, &err), VD_OK, err);
  int mid = 60 * 160 + 80;
  CHECK_INT(f.label[mid], VD_RENDER_ROBOT_LABEL);
  CHECK_NEAR(f.depth[mid], 2 - 0.05, 2e-3);
  // moving the joint moves the robot out of the centre
  double q = 0.5;
  CHECK_STATUS(vd_render_set_robot_qpos(r, &q, 1, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_LABEL, &f, &err), VD_OK, err);
  CHECK_INT(f.label[mid], 0);
  CHECK_STATUS(vd_render_set_robot_qpos(r, &q, 2, &err), VD_ERR_ARG, err);
  vd_render_destroy(r);
  // a broken MJCF is a format error naming the file
  fp = fopen(path, "w");
  REQUIRE(fp);
  fputs("<mujoco><worldbody><geom type=\"capsule\"", fp);
  fclose(fp);
  vd_renderer* bad = NULL;
  vd_status st = vd_render_create(&d, &bad, &err);
  if (st != VD_ERR_UNSUPPORTED) CHECK_STATUS(st, VD_ERR_FORMAT, err);
  CHECK(bad == NULL);
  // a missing one cannot be opened (before MuJoCo is asked)
  snprintf(path, sizeof path, "%s/missing.xml", vdt_tmpdir());
  vd_error err2 = {0};
  st = vd_render_create(&d, &bad, &err2);
  if (st != VD_ERR_UNSUPPORTED) CHECK_STATUS(st, VD_ERR_IO, err2);
}

TEST(render, png_round_trip) {
  // 16-bit masks and 8-bit colour come back unchanged; a file that is not a PNG is refused
  enum { W = 37, H = 23 };
  uint16_t lab[W * H], inst[W * H];
  uint8_t rgb[W * H * 3];
  for (int i = 0; i < W * H; i++)
    lab[i] = (uint16_t)(i * 97), inst[i] = (uint16_t)(65535 - i), rgb[3 * i] = (uint8_t)i,
    rgb[3 * i + 1] = (uint8_t)(i >> 3), rgb[3 * i + 2] = 7;
  vd_frame f;
  memset(&f, 0, sizeof f);
  f.width = W, f.height = H, f.rgb = rgb, f.label = lab, f.instance = inst;
  char path[512];
  snprintf(path, sizeof path, "%s/rt.png", vdt_tmpdir());
  vd_error err = {0};
  int w, h, ch, bits;
  uint16_t* pix;
  CHECK_STATUS(vd_render_write_png(&f, VD_LAYER_INSTANCE, path, &err), VD_OK, err);
  CHECK_STATUS(vd_render_read_png(path, &w, &h, &ch, &bits, &pix, &err), VD_OK, err);
  if (pix) {
    CHECK(w == W && h == H && ch == 1 && bits == 16);
    CHECK(memcmp(pix, inst, sizeof inst) == 0);
    vd_free(pix, (size_t)w * h * ch * 2);
  }
  CHECK_STATUS(vd_render_write_png(&f, VD_LAYER_COLOR, path, &err), VD_OK, err);
  CHECK_STATUS(vd_render_read_png(path, &w, &h, &ch, &bits, &pix, &err), VD_OK, err);
  if (pix) {
    CHECK(ch == 3 && bits == 8);
    int same = 1;
    for (int i = 0; i < W * H * 3; i++)
      same &= pix[i] == rgb[i];
    CHECK(same);
    vd_free(pix, (size_t)w * h * ch * 2);
  }
  // an unwritable path fails with nothing left behind; garbage is not a PNG
  CHECK_STATUS(vd_render_write_png(&f, VD_LAYER_LABEL, "/nonexistent-dir/x.png", &err), VD_ERR_IO,
               err);
  snprintf(path, sizeof path, "%s/garbage.png", vdt_tmpdir());
  FILE* fp = fopen(path, "w");
  REQUIRE(fp);
  fputs("not a png at all", fp);
  fclose(fp);
  CHECK_STATUS(vd_render_read_png(path, &w, &h, &ch, &bits, &pix, &err), VD_ERR_FORMAT, err);
  CHECK(pix == NULL);
}

TEST(render, out_of_memory) {
  // every allocation failing in turn: NOMEM (or success), never a crash, nothing leaked; first
  // while creating a renderer, then while adding a plant and drawing with one
  vd_vec3 v[4] = {{-0.2, 0, 0.35}, {0.2, 0, 0.35}, {0.2, 0, 0.65}, {-0.2, 0, 0.65}};
  vd_model* m = vdt_quad_plant(v, 2, 5);
  REQUIRE(m);
  vd_render_def d = vdt_small_def(32, 24);
  vd_renderer* r = vdt_renderer(&d);
  if (!r) {
    vd_model_destroy(m);
    return;
  }
  vd_render_destroy(r);
  r = NULL;
  vd_error err = {0};
  for (int budget = 0; budget < 100 && !r; budget++) {
    vdt_oom_begin(budget);
    vd_status st = vd_render_create(&d, &r, &err);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    CHECK(st == VD_OK || r == NULL);
  }
  REQUIRE(r);
  int done = 0;
  vd_camera c = cam_y(vd_v3(0, -2, 0.5), 40);
  for (int budget = 0; budget < 200 && !done; budget++) {
    vd_render_clear(r);
    vd_frame f;
    vdt_oom_begin(budget);
    vd_status st = vd_render_add_plant(r, m, NULL, NULL, &err);
    if (!st) st = vd_render_draw(r, &c, VD_LAYER_ALL, &f, &err);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    if (st == VD_OK) {
      done = 1;
      CHECK_INT(f.label[12 * 32 + 16], 2);
    }
  }
  CHECK(done);
  vd_render_destroy(r);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// solids, displacement from a reference state, a simulation state

TEST(render, shapes) {
  vd_render_def d = vdt_small_def(200, 150);
  d.floor = 0;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_error err = {0};
  // a sphere of 10 cm, 2 m in front of the camera: robot label, instance 0, its disc's area
  vd_render_shape s = {
      VD_RENDER_SPHERE, {0.1, 0, 0}, vd_v3(0, 0, 0.5), vd_quat_identity(), {0.5f, 0.6f, 0.7f}};
  CHECK_STATUS(vd_render_add_shape(r, &s, &err), VD_OK, err);
  vd_camera c = cam_y(vd_v3(0, -2, 0.5), 40);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_ALL, &f, &err), VD_OK, err);
  double u, v, z;
  REQUIRE(vd_camera_project(&f.K, s.pos, &u, &v, &z));
  int cu = (int)lround(u), cv = (int)lround(v);
  CHECK_INT(f.label[cv * f.width + cu], VD_RENDER_ROBOT_LABEL);
  CHECK_INT(f.instance[cv * f.width + cu], 0);
  CHECK_NEAR(f.depth[cv * f.width + cu], 2 - 0.1, 2e-3);
  int area = 0;
  for (int i = 0; i < f.width * f.height; i++)
    area += f.label[i] == VD_RENDER_ROBOT_LABEL;
  // the silhouette of a sphere seen from distance D: radius f r / sqrt(D^2 - r^2) pixels
  double rad = f.K.fy * 0.1 / sqrt(4 - 0.01), disc = VD_PI * rad * rad;
  CHECK(fabs(area - disc) < 0.05 * disc);
  // a capsule along x and a box: both drawn, both in the bounds
  vd_render_clear(r);
  vd_render_shape cap = {VD_RENDER_CAPSULE,
                         {0.05, 0.3, 0},
                         vd_v3(0, 0, 0.5),
                         vd_quat_axis_angle(vd_v3(0, 1, 0), VD_PI / 2),
                         {1, 0, 0}};
  CHECK_STATUS(vd_render_add_shape(r, &cap, &err), VD_OK, err);
  vd_vec3 lo, hi;
  CHECK(vd_render_bounds(r, &lo, &hi));
  CHECK_NEAR(hi.x, 0.35, 1e-3);
  CHECK_NEAR(lo.x, -0.35, 1e-3);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_LABEL, &f, &err), VD_OK, err);
  REQUIRE(vd_camera_project(&f.K, vd_v3(0.3, 0, 0.5), &u, &v, &z));
  CHECK_INT(f.label[(int)lround(v) * f.width + (int)lround(u)], VD_RENDER_ROBOT_LABEL);
  REQUIRE(vd_camera_project(&f.K, vd_v3(0, 0, 0.62), &u, &v, &z));
  CHECK_INT(f.label[(int)lround(v) * f.width + (int)lround(u)], 0); // above the capsule
  vd_render_clear(r);
  vd_render_shape box = {
      VD_RENDER_BOX, {0.1, 0.1, 0.2}, vd_v3(0, 0, 0.5), vd_quat_identity(), {0, 1, 0}};
  CHECK_STATUS(vd_render_add_shape(r, &box, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_LABEL | VD_LAYER_DEPTH, &f, &err), VD_OK, err);
  // the box's front face (y = -0.1) fills a 0.2 x 0.4 m rectangle 1.9 m away
  area = 0;
  for (int i = 0; i < f.width * f.height; i++)
    area += f.label[i] == VD_RENDER_ROBOT_LABEL;
  double face = (f.K.fx * 0.2 / 1.9) * (f.K.fy * 0.4 / 1.9);
  CHECK(fabs(area - face) < 0.05 * face);
  REQUIRE(vd_camera_project(&f.K, box.pos, &u, &v, &z));
  CHECK_NEAR(f.depth[(int)lround(v) * f.width + (int)lround(u)], 1.9, 2e-3);
  // bad sizes and poses
  vd_render_shape bad = s;
  bad.size[0] = 0;
  CHECK_STATUS(vd_render_add_shape(r, &bad, &err), VD_ERR_VALUE, err);
  bad = s, bad.pos.x = NAN;
  CHECK_STATUS(vd_render_add_shape(r, &bad, &err), VD_ERR_VALUE, err);
  bad = cap, bad.size[1] = -1;
  CHECK_STATUS(vd_render_add_shape(r, &bad, &err), VD_ERR_VALUE, err);
  bad = s, bad.kind = (vd_render_shape_kind)9;
  CHECK_STATUS(vd_render_add_shape(r, &bad, &err), VD_ERR_ARG, err);
  vd_render_destroy(r);
}

TEST(render, displacement_from_reference) {
  vd_render_def d = vdt_small_def(120, 90);
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_model* m = vdt_tomato(1);
  REQUIRE(m);
  vd_data* st = vd_data_create(m);
  vd_data* ref = vd_data_create(m);
  REQUIRE(st && ref);
  // the state and the reference both moved 3 cm: no displacement between them; 3 cm from rest
  for (int i = 0; i < 3 * m->nnode; i += 3)
    st->node_pos[i] += 0.03, ref->node_pos[i] += 0.03;
  for (int i = 0; i < 3 * m->nsphere; i += 3)
    st->sphere_pos[i] += 0.03, ref->sphere_pos[i] += 0.03;
  for (int i = 0; i < 3 * m->nvert; i += 3)
    st->vert_pos[i] += 0.03, ref->vert_pos[i] += 0.03;
  vd_render_style s = vd_render_style_default();
  s.color_by = VD_COLOR_DISPLACEMENT;
  s.ref = ref;
  vd_error err = {0};
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_OK, err);
  vd_vec3 lo, hi;
  vd_render_bounds(r, &lo, &hi);
  vd_camera c = vd_camera_preset(VD_CAMERA_FRONT, 0, 0, lo, hi, 120, 90);
  vd_frame f;
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK_NEAR(f.range_max, 0, 1e-12);
  // against the rest shape: 3 cm; the plant drawn at rest against the reference: 3 cm too
  vd_render_clear(r);
  s.ref = NULL;
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK_NEAR(f.range_max, 0.03, 1e-9);
  vd_render_clear(r);
  s.ref = ref;
  CHECK_STATUS(vd_render_add_plant(r, m, NULL, &s, &err), VD_OK, err);
  CHECK_STATUS(vd_render_draw(r, &c, VD_LAYER_COLOR, &f, &err), VD_OK, err);
  CHECK_NEAR(f.range_min, 0.03, 1e-9);
  // a reference of another model is refused
  vd_model* q = vdt_quad_plant((vd_vec3[4]){{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}, 2, 1);
  vd_data* qd = q ? vd_data_create(q) : NULL;
  REQUIRE(qd);
  s.ref = qd;
  CHECK_STATUS(vd_render_add_plant(r, m, st, &s, &err), VD_ERR_ARG, err);
  vd_data_destroy(qd);
  vd_model_destroy(q);
  vd_data_destroy(st);
  vd_data_destroy(ref);
  vd_render_destroy(r);
  vd_model_destroy(m);
}

TEST(render, masks_follow_the_simulated_state) {
  // a stem with a fruit pushed sideways by a growing force (statics): in every state drawn, the
  // pixel of the fruit's centre carries the fruit's label and instance, and the fruit moves
  vd_render_def d = vdt_small_def(240, 180);
  d.floor = 0;
  vd_renderer* r = vdt_renderer(&d);
  if (!r) return;
  vd_plant_spec* sp = vd_plant_spec_create();
  REQUIRE(sp);
  int a = vd_plant_add_node(sp, vd_v3(0, 0, -0.01)), b = vd_plant_add_node(sp, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(sp, vd_v3(0, 0, 0.3));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.002, g.label = 1, g.instance = 1;
  int s0 = vd_plant_add_segment(sp, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  int s1 = vd_plant_add_segment(sp, &g);
  vd_sphere_spec fr = vd_sphere_spec_default();
  fr.center = vd_v3(0, 0, 0.32), fr.radius = 0.02, fr.parent = s1, fr.node = c, fr.label = 5,
  fr.instance = 3;
  vd_plant_add_sphere(sp, &fr);
  vd_plant_set_label(sp, 1, "stem");
  vd_plant_set_label(sp, 5, "fruit");
  vd_model* pm = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_plant_compile(sp, &pm, &err), VD_OK, err);
  vd_plant_spec_destroy(sp);
  REQUIRE(pm);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.03;
  vd_sim_model* sm = NULL;
  CHECK_STATUS(vd_sim_build(pm, &def, &sm, &err), VD_OK, err);
  REQUIRE(sm);
  sm->opt.gravity = vd_v3(0, 0, 0);
  vd_sim_data* sd = vd_sim_data_create(sm);
  vd_data* pd = vd_data_create(pm);
  REQUIRE(sd && pd);
  int fruit = vd_sim_find_organ(sm, pm, "fruit", 0);
  REQUIRE(fruit >= 0);
  vd_camera cam = cam_y(vd_v3(0, -1.2, 0.2), 40);
  double u0 = 0;
  for (int k = 0; k < 4; k++) {
    vd_sim_to_plant(sm, sd, pm, pd);
    vd_render_clear(r);
    CHECK_STATUS(vd_render_add_plant(r, pm, pd, NULL, &err), VD_OK, err);
    vd_frame f;
    CHECK_STATUS(vd_render_draw(r, &cam, VD_LAYER_LABEL | VD_LAYER_INSTANCE, &f, &err), VD_OK, err);
    double u, v, z;
    vd_vec3 p = vd_v3(pd->sphere_pos[0], pd->sphere_pos[1], pd->sphere_pos[2]);
    REQUIRE(vd_camera_project(&f.K, p, &u, &v, &z));
    int px = (int)lround(v) * f.width + (int)lround(u);
    CHECK_INT(f.label[px], 5);
    CHECK_INT(f.instance[px], 3);
    if (k == 0) u0 = u;
    if (k == 3) CHECK(u - u0 > 20); // pushed along +x: 20 pixels or more to the right
    sd->node_force[fruit] = vd_v3(0.07 * (k + 1), 0, 0);
    vd_sim_settle_def sdef = vd_sim_settle_def_default();
    sdef.statics = 1;
    vd_sim_settle(sm, sd, &sdef, NULL, NULL);
  }
  vd_data_destroy(pd);
  vd_sim_data_destroy(sd);
  vd_sim_model_destroy(sm);
  vd_model_destroy(pm);
  vd_render_destroy(r);
}
