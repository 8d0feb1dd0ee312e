// SPDX-License-Identifier: MIT
// Private to the render module: the renderer's state, the OpenGL context and the MuJoCo guard.
#ifndef VERDANT_RENDER_INTERNAL_H
#define VERDANT_RENDER_INTERNAL_H

#include <mujoco/mujoco.h>
#include <setjmp.h>

#include "mjtrap/mjtrap.h"
#include "verdant/geom.h"
#include "verdant/render.h"

// ---------------------------------------------------------------------------------------------
// offscreen OpenGL context (render_gl.c): EGL loaded at run time, GL entry points by address

typedef struct gl_api gl_api; // loaded EGL and GL functions
typedef struct gl_ctx {
  void* lib;      // dlopen handle of libEGL
  gl_api* api;    // function table (owned)
  void* dpy;      // EGLDisplay
  void* ctx;      // EGLContext
  void* surf;     // EGLSurface (1x1 pbuffer) or NULL when surfaceless
  char info[256]; // "EGL 1.5 (surfaceless), GL 4.5 ..., llvmpipe ..."
  vd_render_gl id; // which OpenGL implementation this is (platform, vendor, renderer)
} gl_ctx;

// Create a compatibility-profile context with depth and stencil and make it current.
vd_status gl_create(gl_ctx* g, vd_error* err);
// Make the context current on this thread.
vd_status gl_current(gl_ctx* g, vd_error* err);
// Make no context current on this thread (another thread may take this one next).
void gl_release(gl_ctx* g);
// Release the context and the library.
void gl_destroy(gl_ctx* g);

// One triangle soup to compile into a display list: positions, normals, optional colours.
typedef struct gl_tris {
  int ntri;            // triangles
  const float* pos;    // vertex positions (ntri x 3 x 3)
  const float* normal; // vertex normals (ntri x 3 x 3)
  const float* rgb;    // Nullable: vertex colours (ntri x 3 x 3)
} gl_tris;

// Compile a display list of triangles; returns its name, 0 on failure.
unsigned gl_list(gl_ctx* g, const gl_tris* t);
// Offset the depth of filled polygons by factor x their depth slope + units x the depth
// resolution (glPolygonOffset); 0, 0 turns the offset off.
void gl_polygon_offset(gl_ctx* g, float factor, float units);
// Delete a display list (0 is fine).
void gl_list_free(gl_ctx* g, unsigned list);

// ---------------------------------------------------------------------------------------------
// the renderer

// item kinds
enum { ITEM_BACKGROUND = 0, ITEM_ROBOT = 1, ITEM_PLANT = 2, ITEM_POINTS = 3, ITEM_SHAPE = 4 };

// One scene geom we add: a (label, instance) group of a plant or cloud, or a solid.
typedef struct item {
  int kind;            // ITEM_*
  int label, instance; // ids written to the masks
  float rgba[4];       // flat colour (white when the list carries vertex colours)
  unsigned list;       // display list of the geometry (no colours)
  unsigned list_rgb;   // display list with vertex colours, 0 when flat
  int cloud;           // index of the cloud (ITEM_POINTS), -1 otherwise
  int start, count;    // ITEM_POINTS: range in the cloud's sorted point order
} item;

// A point cloud kept for splatting (its lists depend on the camera).
typedef struct cloud {
  int n;         // points
  double* xyz;   // positions (m) (n x 3), owned
  int* order;    // point indices sorted by (label, instance) (n)
  double radius; // splat half-size (m)
} cloud;

struct vd_renderer {
  vd_render_def def;
  char robot_path[4096]; // copy of def.robot_mjcf
  gl_ctx gl;
  int have_gl, have_mj; // what has been made (for destroy)
  mjModel* m;           // stage or robot model
  mjData* d;            // its state
  mjvScene scn;
  mjrContext con;
  mjvOption opt;
  mjvPerturb pert;
  mjvCamera mjcam;
  mjVFS* vfs;      // stage file system (owned)
  vd_render_look look;   // lights and stage colours of the next frames
  int tex_sky, tex_floor; // the stage's sky and floor textures, -1 with a robot's model
  uint8_t* tex0;         // the stage textures as made (ntexdata bytes), recoloured from
  int nmodel_geom; // geoms mjv_updateScene adds for the model
  int digit_base;  // font: lowest ink row of '0' above the bottom of its cell (pixels)
  int dot_size;    // font: side of the decimal point we draw (pixels)
  // what is drawn
  item* items; // scene items (nitem)
  int nitem, cap_item;
  cloud* clouds; // clouds (ncloud)
  int ncloud, cap_cloud;
  double cloud_eye[3], cloud_fwd[3], cloud_up[3]; // camera the cloud lists were built for
  int cloud_lists_valid;
  vd_legend_entry* legend; // labels in use, sorted by id (nlegend)
  int nlegend, cap_legend;
  vd_color_by color_by;        // colouring of the first plant or cloud
  vd_palette palette;          // its label colours
  int nadded;                  // plants and clouds added
  double range_min, range_max; // colour scale of the last value-coloured plant
  int log_scale;               // ... logarithmic
  vd_vec3 lo, hi;              // bounds of everything added
  int has_bounds;
  vd_vec3 lo_up, hi_up; // bounds of what is above the floor (z >= 0)
  int has_bounds_up;
  // images
  uint8_t* big;       // supersampled colour (kW x kH x 3), bottom row first
  uint8_t* rgb;       // colour (W x H x 3), top row first
  uint8_t* ids;       // id pass colours (W x H x 3), bottom row first
  float* zbuf;        // id pass depth buffer in [0, 1] (W x H), bottom row first
  double* depth;      // (W x H)
  uint16_t* label;    // (W x H)
  uint16_t* instance; // (W x H)
};

// Free every item's display lists and every cloud (render_scene.c).
void render_items_free(vd_renderer* r);
// Rebuild the splat lists of the clouds for a camera at eye looking along fwd with axes right/up.
vd_status render_clouds_update(vd_renderer* r, const double eye[3], const double fwd[3],
                               const double right[3], const double up[3], vd_error* err);
// Measure the font's digit baseline and stroke (once, after the MuJoCo context is made).
void render_measure_font(vd_renderer* r);
// Colour map from t in [0, 1] (viridis) into rgb.
void render_colormap(double t, float rgb[3]);

#endif
