// SPDX-License-Identifier: MIT
// Image files: PNG through libpng (colour RGB 8-bit, depth in millimetres and ids as 16-bit
// grey), a reader for checks, and the JSON sidecar with intrinsics, pose and legend.
#include <cjson/cJSON.h>
#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"

// ---------------------------------------------------------------------------------------------
// writing

// libpng errors jump back here; the message is kept for the caller
typedef struct png_err {
  jmp_buf jb;
  char msg[256];
} png_err;

static void on_png_error(png_structp png, png_const_charp msg) {
  png_err* e = png_get_error_ptr(png);
  snprintf(e->msg, sizeof e->msg, "%s", msg);
  longjmp(e->jb, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg) {
  (void)png;
  vd_log(1, "libpng: %s", msg);
}

// write rows (top first) of a w x h image; bits 8 or 16; channels 1 or 3; 16-bit samples are
// host-order uint16 and are written big-endian as PNG wants
static vd_status write_png(const char* path, int w, int h, int channels, int bits, const void* pix,
                           vd_error* err) {
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (st) return st;
  size_t row_bytes = (size_t)w * (size_t)channels * (size_t)(bits / 8);
  uint8_t* row = vd_malloc(row_bytes);
  if (!row) {
    vd_outfile_abort(&f);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  }
  png_err pe;
  pe.msg[0] = 0;
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &pe, on_png_error, on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    vd_free(row, row_bytes);
    vd_outfile_abort(&f);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory (libpng)");
  }
  if (setjmp(pe.jb)) {
    png_destroy_write_struct(&png, &info);
    vd_free(row, row_bytes);
    vd_outfile_abort(&f);
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot write PNG: %s", pe.msg);
  }
  png_init_io(png, f.fp);
  png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, bits,
               channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // a fixed compression level: same pixels, same bytes
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  for (int y = 0; y < h; y++) {
    if (bits == 8) {
      memcpy(row, (const uint8_t*)pix + (size_t)y * row_bytes, row_bytes);
    } else {
      const uint16_t* src = (const uint16_t*)pix + (size_t)y * w * channels;
      for (size_t i = 0; i < (size_t)w * channels; i++)
        row[2 * i] = (uint8_t)(src[i] >> 8), row[2 * i + 1] = (uint8_t)src[i];
    }
    png_write_row(png, row);
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  vd_free(row, row_bytes);
  return vd_outfile_commit(&f, err);
}

vd_status vd_render_write_png(const vd_frame* f, unsigned layer, const char* path, vd_error* err) {
  int w = f->width, h = f->height;
  size_t n = (size_t)w * (size_t)h;
  switch (layer) {
  case VD_LAYER_COLOR:
    if (!f->rgb) break;
    return write_png(path, w, h, 3, 8, f->rgb, err);
  case VD_LAYER_LABEL:
    if (!f->label) break;
    return write_png(path, w, h, 1, 16, f->label, err);
  case VD_LAYER_INSTANCE:
    if (!f->instance) break;
    return write_png(path, w, h, 1, 16, f->instance, err);
  case VD_LAYER_DEPTH: {
    if (!f->depth) break;
    // millimetres, rounded; 0 where nothing, 65535 for 65.535 m and beyond
    uint16_t* mm = vd_malloc(n * sizeof(uint16_t));
    if (!mm) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
    for (size_t i = 0; i < n; i++) {
      double v = f->depth[i] * 1000.0;
      mm[i] = !(v > 0) ? 0 : v >= 65535 ? 65535 : (uint16_t)fmax(1, floor(v + 0.5));
    }
    vd_status st = write_png(path, w, h, 1, 16, mm, err);
    vd_free(mm, n * sizeof(uint16_t));
    return st;
  }
  default:
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "write one layer at a time (got mask %u)",
                        layer);
  }
  return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "the frame was drawn without that layer");
}

// ---------------------------------------------------------------------------------------------
// reading

vd_status vd_render_read_png(const char* path, int* w, int* h, int* channels, int* bits,
                             uint16_t** pix, vd_error* err) {
  *pix = NULL;
  FILE* fp = fopen(path, "rb");
  if (!fp) return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot open");
  png_err pe;
  pe.msg[0] = 0;
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &pe, on_png_error, on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  uint8_t* row = NULL;
  size_t row_bytes = 0, total = 0;
  uint16_t* out = NULL;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, NULL);
    fclose(fp);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory (libpng)");
  }
  if (setjmp(pe.jb)) {
    png_destroy_read_struct(&png, &info, NULL);
    fclose(fp);
    vd_free(row, row_bytes);
    vd_free(out, total);
    return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "not a readable PNG: %s", pe.msg);
  }
  png_init_io(png, fp);
  png_read_info(png, info);
  // palettes to RGB, low bit depths to 8, alpha dropped
  png_set_expand(png);
  png_set_strip_alpha(png);
  png_read_update_info(png, info);
  int W = (int)png_get_image_width(png, info), H = (int)png_get_image_height(png, info);
  int C = png_get_channels(png, info), B = png_get_bit_depth(png, info);
  if (W <= 0 || H <= 0 || W > 65536 || H > 65536 || (C != 1 && C != 3) || (B != 8 && B != 16))
    png_error(png, "unsupported layout (grey or RGB, 8 or 16 bits)");
  row_bytes = png_get_rowbytes(png, info);
  total = (size_t)W * H * C * sizeof(uint16_t);
  row = vd_malloc(row_bytes);
  out = vd_malloc(total);
  if (!row || !out) png_error(png, "out of memory");
  for (int y = 0; y < H; y++) {
    png_read_row(png, row, NULL);
    for (size_t i = 0; i < (size_t)W * C; i++)
      out[(size_t)y * W * C + i] = B == 8 ? row[i] : (uint16_t)(row[2 * i] << 8 | row[2 * i + 1]);
  }
  png_read_end(png, NULL);
  png_destroy_read_struct(&png, &info, NULL);
  fclose(fp);
  vd_free(row, row_bytes);
  *w = W, *h = H, *channels = C, *bits = B, *pix = out;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// sidecar JSON

static const char* color_by_name(vd_color_by c) {
  switch (c) {
  case VD_COLOR_INSTANCE:
    return "instance";
  case VD_COLOR_STRESS:
    return "stress";
  case VD_COLOR_DISPLACEMENT:
    return "displacement";
  default:
    return "label";
  }
}

vd_status vd_render_write_json(const vd_frame* f, const char* const* files, const char* path,
                               vd_error* err) {
  cJSON* root = cJSON_CreateObject();
  if (!root) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  const vd_intrinsics* k = &f->K;
  cJSON_AddStringToObject(root, "format", "verdant-image");
  cJSON_AddNumberToObject(root, "version", VD_RENDER_FORMAT_VERSION);
  cJSON_AddNumberToObject(root, "width", k->width);
  cJSON_AddNumberToObject(root, "height", k->height);
  cJSON* in = cJSON_AddObjectToObject(root, "intrinsics");
  cJSON_AddNumberToObject(in, "fx", k->fx);
  cJSON_AddNumberToObject(in, "fy", k->fy);
  cJSON_AddNumberToObject(in, "cx", k->cx);
  cJSON_AddNumberToObject(in, "cy", k->cy);
  double K[9] = {k->fx, 0, k->cx, 0, k->fy, k->cy, 0, 0, 1};
  cJSON_AddItemToObject(in, "K", cJSON_CreateDoubleArray(K, 9));
  cJSON* pose = cJSON_AddObjectToObject(root, "pose");
  cJSON_AddItemToObject(pose, "R", cJSON_CreateDoubleArray(k->R, 9));
  double t[3] = {k->t.x, k->t.y, k->t.z};
  cJSON_AddItemToObject(pose, "t", cJSON_CreateDoubleArray(t, 3));
  cJSON_AddStringToObject(pose, "convention",
                          "x_world = R x_camera + t; camera x right, y down, z forward");
  cJSON* cam = cJSON_AddObjectToObject(root, "camera");
  double eye[3] = {f->camera.eye.x, f->camera.eye.y, f->camera.eye.z};
  double at[3] = {f->camera.lookat.x, f->camera.lookat.y, f->camera.lookat.z};
  double up[3] = {f->camera.up.x, f->camera.up.y, f->camera.up.z};
  cJSON_AddItemToObject(cam, "eye", cJSON_CreateDoubleArray(eye, 3));
  cJSON_AddItemToObject(cam, "lookat", cJSON_CreateDoubleArray(at, 3));
  cJSON_AddItemToObject(cam, "up", cJSON_CreateDoubleArray(up, 3));
  cJSON_AddNumberToObject(cam, "fovy_deg", f->camera.fovy * 180.0 / VD_PI);
  cJSON_AddNumberToObject(cam, "znear", f->camera.znear);
  cJSON_AddNumberToObject(cam, "zfar", f->camera.zfar);
  cJSON_AddNumberToObject(root, "depth_scale", 0.001);
  cJSON_AddStringToObject(root, "depth_unit", "mm, 0 = no surface");
  cJSON_AddStringToObject(root, "color_by", color_by_name(f->color_by));
  cJSON_AddStringToObject(root, "palette", f->palette == VD_PALETTE_NATURAL ? "natural" : "distinct");
  if (f->color_by == VD_COLOR_STRESS || f->color_by == VD_COLOR_DISPLACEMENT) {
    double rg[2] = {f->range_min, f->range_max};
    cJSON_AddItemToObject(root, "range", cJSON_CreateDoubleArray(rg, 2));
    cJSON_AddStringToObject(root, "range_unit", f->color_by == VD_COLOR_STRESS ? "Pa" : "m");
  }
  cJSON* leg = cJSON_AddArrayToObject(root, "labels");
  for (int i = 0; leg && i < f->nlegend; i++) {
    cJSON* e = cJSON_CreateObject();
    cJSON_AddNumberToObject(e, "id", f->legend[i].id);
    cJSON_AddStringToObject(e, "name", f->legend[i].name);
    double c[3] = {f->legend[i].rgb[0], f->legend[i].rgb[1], f->legend[i].rgb[2]};
    cJSON_AddItemToObject(e, "rgb", cJSON_CreateDoubleArray(c, 3));
    cJSON_AddItemToArray(leg, e);
  }
  cJSON_AddNumberToObject(root, "robot_label", VD_RENDER_ROBOT_LABEL);
  if (f->gl) {
    // which OpenGL drew it: a GPU's and Mesa's software pictures differ in their last bits
    cJSON* gl = cJSON_AddObjectToObject(root, "opengl");
    cJSON_AddStringToObject(gl, "vendor", f->gl->vendor);
    cJSON_AddStringToObject(gl, "renderer", f->gl->renderer);
    cJSON_AddStringToObject(gl, "version", f->gl->version);
    cJSON_AddStringToObject(gl, "egl_platform", f->gl->platform);
    cJSON_AddBoolToObject(gl, "software", f->gl->software);
  }
  cJSON* fl = cJSON_AddObjectToObject(root, "files");
  for (int i = 0; files && files[i] && files[i + 1]; i += 2)
    cJSON_AddStringToObject(fl, files[i], files[i + 1]);
  char* text = cJSON_Print(root);
  cJSON_Delete(root);
  if (!text) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  vd_outfile of;
  vd_status st = vd_outfile_open(&of, path, err);
  if (!st) {
    fputs(text, of.fp);
    fputc('\n', of.fp);
    st = vd_outfile_commit(&of, err);
  }
  cJSON_free(text);
  return st;
}
