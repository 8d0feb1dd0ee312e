// SPDX-License-Identifier: MIT
// Cameras (presets fitted to a box, intrinsics, projection) and drawing a frame: MuJoCo's scene
// gets the stage or robot geoms, our lights and camera, and one mesh geom per item whose display
// list is ours; a colour pass (supersampled, shadows, legend) and an exact id pass (no lighting,
// no anti-aliasing, each geom in the colour of its segmentation id) that gives depth and masks.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render_internal.h"

// ---------------------------------------------------------------------------------------------
// cameras

// camera axes: forward, right, image up (orthonormal)
static void cam_axes(const vd_camera* c, vd_vec3* f, vd_vec3* rt, vd_vec3* up) {
  *f = vd_normalize(vd_sub(c->lookat, c->eye));
  *rt = vd_normalize(vd_cross(*f, c->up));
  *up = vd_cross(*rt, *f);
}

vd_status vd_camera_check(const vd_camera* c, vd_error* err) {
  const double v[] = {c->eye.x, c->eye.y, c->eye.z, c->lookat.x, c->lookat.y, c->lookat.z,
                      c->up.x,  c->up.y,  c->up.z,  c->fovy,     c->znear,    c->zfar};
  for (size_t i = 0; i < sizeof v / sizeof v[0]; i++)
    if (!isfinite(v[i]))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "camera has a value that is not finite");
  if (!(c->fovy > 0 && c->fovy < VD_PI))
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                        "camera field of view must be in (0, 180) degrees");
  if (!(c->znear > 0 && c->zfar > c->znear))
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "camera clip distances need 0 < near < far");
  vd_vec3 f = vd_sub(c->lookat, c->eye);
  if (vd_norm(f) < 1e-9)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "camera eye and look-at point coincide");
  if (vd_norm(vd_cross(vd_normalize(f), vd_normalize(c->up))) < 1e-6)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                        "camera up direction is along the viewing direction");
  return VD_OK;
}

vd_camera vd_camera_preset(vd_camera_kind kind, double azimuth, double elevation, vd_vec3 lo,
                           vd_vec3 hi, int width, int height) {
  vd_camera c;
  c.fovy = 45.0 * VD_PI / 180.0;
  vd_vec3 f, up = vd_v3(0, 0, 1);
  switch (kind) {
  case VD_CAMERA_SIDE:
    f = vd_v3(-1, 0, 0);
    break;
  case VD_CAMERA_TOP:
    f = vd_v3(0, 0, -1), up = vd_v3(0, 1, 0);
    break;
  case VD_CAMERA_ORBIT:
    f = vd_v3(-cos(elevation) * cos(azimuth), -cos(elevation) * sin(azimuth), -sin(elevation));
    if (fabs(sin(elevation)) > 0.999) up = vd_v3(-cos(azimuth), -sin(azimuth), 0);
    break;
  default:
    f = vd_v3(0, 1, 0);
    break;
  }
  // a tiny box still gets a picture
  vd_vec3 ctr = vd_scale(vd_add(lo, hi), 0.5);
  vd_vec3 half = vd_scale(vd_sub(hi, lo), 0.5);
  double hmin = 0.05;
  half = vd_v3(fmax(half.x, hmin), fmax(half.y, hmin), fmax(half.z, hmin));
  vd_vec3 rt = vd_normalize(vd_cross(f, up)), u = vd_cross(rt, f);
  double ty = tan(c.fovy / 2), tx = ty * (double)width / (double)(height > 0 ? height : 1);
  // distance from the centre so that every corner is inside the frustum, plus a margin
  double dist = 0, reach = 0;
  for (int k = 0; k < 8; k++) {
    vd_vec3 p = vd_v3(k & 1 ? half.x : -half.x, k & 2 ? half.y : -half.y, k & 4 ? half.z : -half.z);
    double z = vd_dot(p, f), x = fabs(vd_dot(p, rt)), y = fabs(vd_dot(p, u));
    dist = fmax(dist, fmax(x / tx, y / ty) - z);
    reach = fmax(reach, vd_norm(p));
  }
  dist *= 1.08;
  c.eye = vd_madd(ctr, f, -dist);
  c.lookat = ctr;
  c.up = up;
  // clip distances: the box, and the floor to the horizon
  c.znear = fmax(1e-3, 0.05 * (dist - reach));
  if (c.znear > 0.5 * (dist - reach) && dist > reach) c.znear = 0.5 * (dist - reach);
  c.zfar = dist + reach + 60.0;
  return c;
}

vd_intrinsics vd_camera_intrinsics(const vd_camera* c, int width, int height) {
  vd_intrinsics k;
  memset(&k, 0, sizeof k);
  vd_vec3 f, rt, up;
  cam_axes(c, &f, &rt, &up);
  k.width = width;
  k.height = height;
  k.fy = 0.5 * height / tan(0.5 * c->fovy);
  k.fx = k.fy; // square pixels: OpenGL's frustum keeps the aspect ratio of the image
  k.cx = 0.5 * width - 0.5;
  k.cy = 0.5 * height - 0.5;
  // camera X right, Y down, Z forward as columns of R
  vd_vec3 col[3] = {rt, vd_scale(up, -1), f};
  for (int i = 0; i < 3; i++) {
    k.R[3 * 0 + i] = col[i].x;
    k.R[3 * 1 + i] = col[i].y;
    k.R[3 * 2 + i] = col[i].z;
  }
  k.t = c->eye;
  return k;
}

int vd_camera_project(const vd_intrinsics* k, vd_vec3 p, double* u, double* v, double* z) {
  vd_vec3 q = vd_sub(p, k->t);
  // camera coordinates: R transposed times q
  double X = k->R[0] * q.x + k->R[3] * q.y + k->R[6] * q.z;
  double Y = k->R[1] * q.x + k->R[4] * q.y + k->R[7] * q.z;
  double Z = k->R[2] * q.x + k->R[5] * q.y + k->R[8] * q.z;
  *z = Z;
  if (Z <= 0) return 0;
  *u = k->fx * X / Z + k->cx;
  *v = k->fy * Y / Z + k->cy;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// legend

// width in pixels of text in MuJoCo's normal font
static int text_width(const mjrContext* con, const char* s) {
  int w = 0;
  for (; *s; s++)
    w += con->charWidth[(unsigned char)*s & 127];
  return w;
}

// text starting at pixel x, centred vertically on a row of height lh from y (a label exactly as
// wide as the text, on a transparent background)
static void text_at(const mjrContext* con, const char* s, int x, int y, int lh) {
  mjrRect rect = {x, y, text_width(con, s), lh};
  mjr_label(rect, mjFONT_NORMAL, s, 1, 1, 1, 0, 0.1f, 0.1f, 0.1f, con);
}

void render_measure_font(vd_renderer* r) {
  // draw '0' black on white in a cell at the corner of the offscreen buffer and read it back
  const mjrContext* con = &r->con;
  int w = con->charWidth['0'], h = con->charHeight;
  r->digit_base = 0, r->dot_size = 2;
  if (w <= 0 || h <= 0) return;
  uint8_t* px = vd_malloc((size_t)w * (size_t)h * 3);
  if (!px) return;
  mjrRect cell = {0, 0, w, h};
  mjr_label(cell, mjFONT_NORMAL, "0", 1, 1, 1, 1, 0, 0, 0, con);
  mjr_readPixels(px, NULL, cell, con);
  // rows come bottom first: the first with ink is the baseline; the stroke is the run of ink
  // at mid-height from the left edge of the glyph
  int base = -1, stroke = 0;
  for (int y = 0; y < h && base < 0; y++)
    for (int x = 0; x < w; x++)
      if (px[3 * ((size_t)y * w + x)] < 128) base = y;
  if (base >= 0) {
    int y = base + (h - base) / 4, x = 0;
    while (x < w && px[3 * ((size_t)y * w + x)] >= 128) x++;
    while (x < w && px[3 * ((size_t)y * w + x)] < 128) x++, stroke++;
  }
  vd_free(px, (size_t)w * (size_t)h * 3);
  r->digit_base = base > 0 ? base : 0;
  r->dot_size = stroke > 0 ? (3 * stroke + 1) / 2 : 2;
}

// a number at pixel x, on a row of height lh from y. MuJoCo's bitmap fonts at 150-250 % put
// the full stop a row below the digits' baseline and make it taller than wide, which reads as
// a decimal comma once the image is averaged down; we draw it as a square on the baseline.
static void number_at(const vd_renderer* r, const char* s, int x, int y, int lh) {
  const mjrContext* con = &r->con;
  const char* dot = strchr(s, '.');
  if (!dot) {
    text_at(con, s, x, y, lh);
    return;
  }
  char head[48];
  size_t n = (size_t)(dot - s) < sizeof head - 1 ? (size_t)(dot - s) : sizeof head - 1;
  memcpy(head, s, n);
  head[n] = 0;
  text_at(con, head, x, y, lh);
  int xd = x + text_width(con, head), adv = con->charWidth['.'];
  // the glyph cell sits (lh - charHeight) / 2 above y (mjr_label centres it)
  int yb = y + (lh - con->charHeight) / 2 + r->digit_base;
  mjrRect sq = {xd + (adv - r->dot_size + 1) / 2, yb, r->dot_size, r->dot_size};
  mjr_rectangle(sq, 0.1f, 0.1f, 0.1f, 1);
  text_at(con, dot + 1, xd + adv, y, lh);
}

// a legend panel in the top right corner of the w x h viewport (pixel scale k)
static void draw_legend(vd_renderer* r, int w, int h, int k) {
  const mjrContext* con = &r->con;
  int lh = con->charHeight + 4 * k, pad = 6 * k, sw = con->charHeight;
  char title[96], lo_txt[48], hi_txt[48];
  int rows = 0, width = 0;
  const char* unit = r->color_by == VD_COLOR_STRESS ? "Pa" : "m";
  if (r->color_by == VD_COLOR_LABEL) {
    rows = r->nlegend;
    for (int i = 0; i < r->nlegend; i++) {
      int tw = sw + pad + text_width(con, r->legend[i].name);
      if (tw > width) width = tw;
    }
    if (!rows) return;
  } else if (r->color_by == VD_COLOR_INSTANCE) {
    int n = 0;
    for (int i = 0; i < r->nitem; i++)
      n += r->items[i].kind == ITEM_PLANT || r->items[i].kind == ITEM_POINTS;
    snprintf(title, sizeof title, "colour: organ instance (%d)", n);
    rows = 1;
    width = text_width(con, title);
  } else {
    snprintf(title, sizeof title, "%s (%s%s)",
             r->color_by == VD_COLOR_STRESS ? "stress" : "displacement", unit, r->log_scale ? ", log" : "");
    snprintf(lo_txt, sizeof lo_txt, "%.3g", r->range_min);
    snprintf(hi_txt, sizeof hi_txt, "%.3g", r->range_max);
    rows = 3;
    width = text_width(con, title);
    int bw = 10 * sw;
    if (bw > width) width = bw;
  }
  int pw = width + 2 * pad, ph = rows * lh + 2 * pad;
  int x0 = w - pw - pad, y0 = h - ph - pad;
  if (x0 < 0) x0 = 0;
  if (y0 < 0) y0 = 0;
  mjrRect panel = {x0, y0, pw, ph};
  mjr_rectangle(panel, 1, 1, 1, 0.8f);
  if (r->color_by == VD_COLOR_LABEL) {
    for (int i = 0; i < r->nlegend; i++) {
      int y = y0 + ph - pad - (i + 1) * lh + (lh - sw) / 2;
      mjrRect sq = {x0 + pad, y, sw, sw};
      const float* c = r->legend[i].rgb;
      mjr_rectangle(sq, c[0], c[1], c[2], 1);
      text_at(con, r->legend[i].name, x0 + 2 * pad + sw, y0 + ph - pad - (i + 1) * lh, lh);
    }
  } else if (r->color_by == VD_COLOR_INSTANCE) {
    text_at(con, title, x0 + pad, y0 + pad, lh);
  } else {
    text_at(con, title, x0 + pad, y0 + ph - pad - lh, lh);
    // the colour bar, low values on the left
    int bw = pw - 2 * pad, bh = lh, yb = y0 + pad + lh;
    for (int i = 0; i < 64; i++) {
      float c[3];
      render_colormap((i + 0.5) / 64.0, c);
      mjrRect seg = {x0 + pad + i * bw / 64, yb, (i + 1) * bw / 64 - i * bw / 64, bh};
      mjr_rectangle(seg, c[0], c[1], c[2], 1);
    }
    number_at(r, lo_txt, x0 + pad, y0 + pad, lh);
    number_at(r, hi_txt, x0 + pw - pad - text_width(con, hi_txt), y0 + pad, lh);
  }
}

// ---------------------------------------------------------------------------------------------
// drawing

// shadow map: the half-width of the key light's view, a multiple of the bounding sphere's radius;
// the depth offset, in depth slopes per texel and in steps of the depth buffer. A texel's depth
// varies by tan(angle of incidence) texels across it and a fragment sits up to sqrt(2)/2 of a
// texel from the texel centre, so a slope factor of 2 keeps a lit face clear of its own shadow
// up to the incidence where the light grazes it (docs/render.md)
#define SHADOW_CLIP 1.02
#define SHADOW_SLOPE_BIAS 2.0f
#define SHADOW_UNIT_BIAS 4.0f

// set every light: a light at the camera (with the ambient term) and the key light
static void set_lights(vd_renderer* r, const vd_camera* c, vd_vec3 ctr, double reach) {
  mjvScene* scn = &r->scn;
  vd_vec3 f = vd_normalize(vd_sub(c->lookat, c->eye));
  double az = r->look.light_azimuth, el = r->look.light_elevation;
  vd_vec3 from = vd_v3(cos(el) * cos(az), cos(el) * sin(az), sin(el));
  scn->nlight = 2;
  for (int i = 0; i < 2; i++) {
    mjvLight* l = &scn->lights[i];
    memset(l, 0, sizeof *l);
    vd_vec3 pos = i == 0 ? c->eye : vd_madd(ctr, from, 4 * reach);
    vd_vec3 dir = i == 0 ? f : vd_scale(from, -1);
    float amb = i == 0 ? (float)r->look.ambient : 0.f;
    float dif = (float)(i == 0 ? r->look.headlight : r->look.light);
    float spec = i == 0 ? 0.1f : 0.25f;
    l->pos[0] = (float)pos.x, l->pos[1] = (float)pos.y, l->pos[2] = (float)pos.z;
    l->dir[0] = (float)dir.x, l->dir[1] = (float)dir.y, l->dir[2] = (float)dir.z;
    l->attenuation[0] = 1;
    l->cutoff = 180;
    l->directional = 1;
    l->castshadow = i == 1 && r->def.shadows;
    for (int k = 0; k < 3; k++)
      l->ambient[k] = amb, l->diffuse[k] = dif, l->specular[k] = spec;
  }
}

// the OpenGL camera of both eyes
static void set_camera(vd_renderer* r, const vd_camera* c) {
  vd_vec3 f, rt, up;
  cam_axes(c, &f, &rt, &up);
  for (int i = 0; i < 2; i++) {
    mjvGLCamera* g = &r->scn.camera[i];
    g->pos[0] = (float)c->eye.x, g->pos[1] = (float)c->eye.y, g->pos[2] = (float)c->eye.z;
    g->forward[0] = (float)f.x, g->forward[1] = (float)f.y, g->forward[2] = (float)f.z;
    g->up[0] = (float)up.x, g->up[1] = (float)up.y, g->up[2] = (float)up.z;
    g->frustum_near = (float)c->znear;
    g->frustum_far = (float)c->zfar;
    g->frustum_center = 0;
    g->frustum_top = (float)(c->znear * tan(0.5 * c->fovy));
    g->frustum_bottom = -g->frustum_top;
  }
}

// point the item geoms at their lists for a pass (rgb: the vertex-coloured lists)
static void set_lists(vd_renderer* r, int rgb) {
  for (int i = 0; i < r->nitem; i++) {
    const item* it = &r->items[i];
    unsigned list = rgb && it->list_rgb ? it->list_rgb : it->list;
    r->scn.geoms[r->nmodel_geom + i].dataid = (int)(list - r->con.baseMesh);
  }
}

// scene geoms: the model's (floor, robot), then one per item
static vd_status fill_scene(vd_renderer* r, vd_error* err) {
  mjvScene* scn = &r->scn;
  mjv_updateScene(r->m, r->d, &r->opt, &r->pert, &r->mjcam, mjCAT_ALL, scn);
  // segmentation ids: 0 background (floor, world geoms), 1 robot, 2 + i item i
  for (int i = 0; i < scn->ngeom; i++) {
    mjvGeom* g = &scn->geoms[i];
    int robot = r->def.robot_mjcf && g->objtype == mjOBJ_GEOM && g->objid >= 0 &&
                r->m->geom_bodyid[g->objid] > 0;
    g->segid = robot ? 1 : 0;
  }
  r->nmodel_geom = scn->ngeom;
  if (scn->ngeom + r->nitem > scn->maxgeom)
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                        "the scene holds %d geoms; %d organ instances and cloud groups "
                        "need more (raise max_geoms)",
                        scn->maxgeom - scn->ngeom, r->nitem);
  const mjtNum zero[3] = {0, 0, 0}, eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int i = 0; i < r->nitem; i++) {
    const item* it = &r->items[i];
    if (it->list < r->con.baseMesh)
      return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                          "OpenGL display list %u below MuJoCo's mesh lists", it->list);
    mjvGeom* g = &scn->geoms[scn->ngeom++];
    mjv_initGeom(g, mjGEOM_MESH, NULL, zero, eye, it->rgba);
    g->category = mjCAT_DYNAMIC;
    g->objtype = mjOBJ_UNKNOWN;
    g->objid = -1;
    g->segid = 2 + i;
    g->specular = 0.15f;
    g->shininess = 0.25f;
    g->reflectance = 0;
    g->emission = 0;
  }
  return VD_OK;
}

// average k x k blocks of the bottom-up big image into the top-down rgb image
static void downsample(const uint8_t* big, uint8_t* rgb, int w, int h, int k) {
  int bw = w * k;
  for (int y = 0; y < h; y++) {
    uint8_t* out = rgb + (size_t)(h - 1 - y) * w * 3;
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 3; c++) {
        unsigned sum = 0;
        for (int j = 0; j < k; j++)
          for (int i = 0; i < k; i++)
            sum += big[((size_t)(y * k + j) * bw + (x * k + i)) * 3 + c];
        out[3 * x + c] = (uint8_t)((sum + (unsigned)(k * k) / 2) / (unsigned)(k * k));
      }
  }
}

// decode the id pass into depth and masks (top row first)
static void decode_ids(vd_renderer* r, const vd_camera* c) {
  int w = r->def.width, h = r->def.height;
  double n = (float)c->znear, f = (float)c->zfar;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      size_t src = (size_t)y * w + x, dst = (size_t)(h - 1 - y) * w + x;
      const uint8_t* p = r->ids + 3 * src;
      int v = p[0] | p[1] << 8 | p[2] << 16;
      int lab = 0, inst = 0;
      double z = 0;
      if (v > 0) {
        // window depth in [0, 1] back to the distance along the optical axis
        double d = r->zbuf[src];
        z = n * f / (f - d * (f - n));
        int seg = v - 1;
        if (seg == 1)
          lab = VD_RENDER_ROBOT_LABEL;
        else if (seg >= 2 && seg - 2 < r->nitem)
          lab = r->items[seg - 2].label, inst = r->items[seg - 2].instance;
      }
      r->depth[dst] = z;
      r->label[dst] = (uint16_t)lab;
      r->instance[dst] = (uint16_t)inst;
    }
}

vd_status vd_render_draw(vd_renderer* r, const vd_camera* cam, unsigned layers, vd_frame* out,
                         vd_error* err) {
  memset(out, 0, sizeof *out);
  vd_status st = vd_camera_check(cam, err);
  if (st) return st;
  if (!layers || (layers & ~VD_LAYER_ALL))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bad layer mask %u", layers);
  if ((st = gl_current(&r->gl, err))) return st;
  // splats face this camera
  vd_vec3 f, rt, up;
  cam_axes(cam, &f, &rt, &up);
  {
    double e[3] = {cam->eye.x, cam->eye.y, cam->eye.z}, fw[3] = {f.x, f.y, f.z},
           ri[3] = {rt.x, rt.y, rt.z}, u[3] = {up.x, up.y, up.z};
    if ((st = render_clouds_update(r, e, fw, ri, u, err))) return st;
  }
  int w = r->def.width, h = r->def.height, k = r->def.supersample;
  vd_vec3 lo, hi;
  if (!vd_render_bounds(r, &lo, &hi)) lo = hi = cam->lookat;
  vd_vec3 ctr = vd_scale(vd_add(lo, hi), 0.5);
  double reach = fmax(0.5 * vd_norm(vd_sub(hi, lo)), 0.05);
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap))
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0, "MuJoCo: %s", trap.error);
  st = fill_scene(r, err);
  if (!st) {
    mjvScene* scn = &r->scn;
    set_lights(r, cam, ctr, reach);
    set_camera(r, cam);
    // the key light's shadow map covers the bounding sphere of what is drawn (the light looks at
    // its centre), no more: every texel spent where shadows can fall
    r->con.shadowClip = (float)(SHADOW_CLIP * reach);
    scn->flags[mjRND_CULL_FACE] = 1;
    scn->flags[mjRND_REFLECTION] = 0;
    mjr_setBuffer(mjFB_OFFSCREEN, &r->con);
    // colour: supersampled, lit, shadows, legend
    if (layers & VD_LAYER_COLOR) {
      scn->flags[mjRND_SEGMENT] = scn->flags[mjRND_IDCOLOR] = 0;
      scn->flags[mjRND_SHADOW] = (mjtByte)r->def.shadows;
      scn->flags[mjRND_SKYBOX] = 1;
      set_lists(r, 1);
      mjrRect vp = {0, 0, w * k, h * k};
      // depth bias of the shadow map (shadow acne, docs/render.md): MuJoCo 2.2.2 keeps the
      // back faces (as seen from the light) and compares without a bias, so a lit face
      // shadows itself wherever a texel's depth slope exceeds the thickness behind it; the
      // offset applies to every pass of this draw alike, so the lit and the shadow passes
      // still meet depth for depth
      gl_polygon_offset(&r->gl, SHADOW_SLOPE_BIAS, SHADOW_UNIT_BIAS);
      mjr_render(vp, scn, &r->con);
      gl_polygon_offset(&r->gl, 0, 0);
      if (r->def.legend && r->nadded) draw_legend(r, w * k, h * k, k);
      mjr_readPixels(r->big, NULL, vp, &r->con);
      downsample(r->big, r->rgb, w, h, k);
    }
    // ids: one flat colour per geom, no lighting, no anti-aliasing; depth from the same pass
    if (layers & (VD_LAYER_DEPTH | VD_LAYER_LABEL | VD_LAYER_INSTANCE)) {
      scn->flags[mjRND_SEGMENT] = scn->flags[mjRND_IDCOLOR] = 1;
      scn->flags[mjRND_SHADOW] = 0;
      scn->flags[mjRND_SKYBOX] = 0;
      set_lists(r, 0);
      mjrRect vp = {0, 0, w, h};
      mjr_render(vp, scn, &r->con);
      mjr_readPixels(r->ids, r->zbuf, vp, &r->con);
      decode_ids(r, cam);
    }
    mjr_finish();
  }
  vd_mj_trap_end(&trap);
  if (st) return st;
  out->width = w;
  out->height = h;
  out->layers = layers;
  out->rgb = layers & VD_LAYER_COLOR ? r->rgb : NULL;
  out->depth = layers & VD_LAYER_DEPTH ? r->depth : NULL;
  out->label = layers & VD_LAYER_LABEL ? r->label : NULL;
  out->instance = layers & VD_LAYER_INSTANCE ? r->instance : NULL;
  out->K = vd_camera_intrinsics(cam, w, h);
  out->camera = *cam;
  out->color_by = r->color_by;
  out->palette = r->palette;
  out->nlegend = r->nlegend;
  out->legend = r->legend;
  out->range_min = r->range_min;
  out->range_max = r->range_max;
  out->gl = &r->gl.id;
  return VD_OK;
}
