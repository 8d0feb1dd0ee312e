// SPDX-License-Identifier: MIT
// verdant render: pictures of plants, point clouds and robots as colour, metric depth and exact
// label masks (semantic and instance), headless.
//
// A vd_renderer owns an offscreen OpenGL context (EGL, the Mesa surfaceless platform first, so no
// display is needed; a GPU's EGL device where there is one) and MuJoCo's scene and renderer on it:
// a stage (floor, sky, lights) or a robot loaded from its MJCF, to which each frame adds what you
// give it: plants (a vd_model in one of its states, tessellated by vd_geom_tessellate, one scene
// geom per organ instance) and point clouds (arrays of points splatted as small camera-facing
// squares). vd_render_draw renders the colour image (anti-aliased by supersampling, with a legend)
// and, when asked, a second exact pass without lighting or anti-aliasing that gives per pixel the
// depth (m, along the optical axis) and the label and instance of the front surface. Images are
// owned by the renderer and stay valid until its next draw. No global state except the MuJoCo
// error hook (installed once; errors come back as a status on the calling thread). A renderer is
// used by one thread at a time: vd_render_release hands it from one thread to the next.
//
// Pixels: row 0 is the top row; camera intrinsics follow OpenCV (u right, v down, pixel centres
// at integers): u = fx X/Z + cx, v = fy Y/Z + cy in the camera frame (X right, Y down, Z forward).
// Masks: 0 is background (sky, floor); a primitive with label 0 shows as 0 in the label mask.
//
// Usage:
//   vd_renderer* r; vd_error err = {0};
//   vd_render_def def = vd_render_def_default();
//   if (vd_render_create(&def, &r, &err)) { /* VD_ERR_UNSUPPORTED: no OpenGL context here */ }
//   vd_render_add_plant(r, model, data, NULL, &err);
//   vd_camera cam = vd_camera_preset(VD_CAMERA_FRONT, 0, 0, lo, hi, def.width, def.height);
//   vd_frame f; vd_render_draw(r, &cam, VD_LAYER_ALL, &f, &err);
//   vd_render_write_png(&f, VD_LAYER_COLOR, "plant.png", &err); vd_render_destroy(r);
#ifndef VERDANT_RENDER_H
#define VERDANT_RENDER_H

#include "verdant/core.h"
#include "verdant/geom.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_RENDER_FORMAT_VERSION 1  // version of the image sidecar JSON (docs/formats.md)
#define VD_RENDER_ROBOT_LABEL 65535 // label id of robot and collider pixels in masks

// ---------------------------------------------------------------------------------------------
// cameras

// Camera presets, each fitted to a box so that all of it is in view.
typedef enum vd_camera_kind {
  VD_CAMERA_FRONT = 0, // from -Y looking toward +Y, Z up
  VD_CAMERA_SIDE,      // from +X looking toward -X, Z up
  VD_CAMERA_TOP,       // from +Z looking down, Y up in the image
  VD_CAMERA_ORBIT,     // from azimuth/elevation around the box centre, Z up
} vd_camera_kind;

// A pinhole camera.
typedef struct vd_camera {
  vd_vec3 eye;    // optical centre (m)
  vd_vec3 lookat; // a point on the optical axis in front of the camera (m)
  vd_vec3 up;     // image up direction (need not be orthogonal to the axis, not parallel to it)
  double fovy;    // vertical field of view (rad), in (0, pi)
  double znear;   // near clip distance (m), > 0
  double zfar;    // far clip distance (m), > znear
} vd_camera;

// Camera intrinsics (OpenCV convention, pixels) and pose.
typedef struct vd_intrinsics {
  int width, height; // image size (pixels)
  double fx, fy;     // focal lengths (pixels)
  double cx, cy;     // principal point (pixels, pixel centres at integers)
  double R[9];       // rotation camera → world, row-major; columns are the camera X, Y, Z axes
  vd_vec3 t;         // camera centre in the world (m)
} vd_intrinsics;

// Camera of a preset fitted to the box lo..hi (m) for a width x height image, fovy 45 degrees.
// azimuth and elevation (rad) are used by VD_CAMERA_ORBIT only (azimuth 0 looks from +X, pi/2
// from +Y; elevation above the horizon). Clip distances enclose the box and a floor around it.
vd_camera vd_camera_preset(vd_camera_kind kind, double azimuth, double elevation, vd_vec3 lo,
                           vd_vec3 hi, int width, int height);
// Intrinsics and pose of camera c for a width x height image.
vd_intrinsics vd_camera_intrinsics(const vd_camera* c, int width, int height);
// Project world point p to pixel (u, v) and depth z along the optical axis (m); 0 if behind.
int vd_camera_project(const vd_intrinsics* k, vd_vec3 p, double* u, double* v, double* z);
// Check a camera: finite, fovy in (0, pi), 0 < znear < zfar, eye != lookat, up not along the axis.
vd_status vd_camera_check(const vd_camera* c, vd_error* err);

// ---------------------------------------------------------------------------------------------
// the renderer

// Settings of a renderer (fixed for its lifetime).
typedef struct vd_render_def {
  int width, height;      // image size (pixels), 1..8192; default 640 x 480
  int supersample;        // colour anti-aliasing: k x k samples per pixel, 1..4; default 2
  int shadows;            // 1: the key light casts shadows; default 1
  int floor;              // 1: a checkered ground plane at z = 0 (in colour and depth, 0 in
                          // masks); default 1
  int sky;                // 1: a gradient sky, 0: a flat background colour; default 1
  float background[3];    // background colour with sky 0, in [0, 1]; default white (1, 1, 1)
  double light_azimuth;   // key light direction: azimuth it comes from, from +X toward +Y (rad);
                          // default -2.0 (front left)
  double light_elevation; // key light elevation above the horizon (rad), (0, pi/2]; default 1.0
  double light;           // key light diffuse intensity in [0, 1]; default 0.6
  double headlight;       // light at the camera, diffuse intensity in [0, 1]; default 0.35
  double ambient;         // ambient intensity in [0, 1]; default 0.3
  int legend;             // 1: draw the legend into the colour image; default 1
  int max_geoms;          // most scene geoms we add (organ instances, cloud groups);
                          // default 20000
  const char* robot_mjcf; // Nullable: MJCF file of a robot (with its own world) drawn with the
                          // plants at its reference pose; default NULL
} vd_render_def;

// Defaults: 640 x 480, supersample 2, shadows 1, floor 1, sky 1, background (1, 1, 1), key light
// from azimuth -2.0 rad at elevation 1.0 rad with intensity 0.6, headlight 0.35, ambient 0.3,
// legend 1, max_geoms 20000, robot_mjcf NULL.
vd_render_def vd_render_def_default(void);

// An offscreen renderer: OpenGL context, MuJoCo scene and context, image buffers.
typedef struct vd_renderer vd_renderer;

// Create a renderer. VD_ERR_UNSUPPORTED with a message naming the step when no OpenGL context can
// be made here (no EGL, no Mesa driver); VD_ERR_FORMAT when the robot MJCF does not load.
vd_status vd_render_create(const vd_render_def* def, vd_renderer** out, vd_error* err);
// Release the renderer, its context and images (NULL is fine).
void vd_render_destroy(vd_renderer* r);
// Let go of the renderer's OpenGL context on this thread, so that another thread may use the
// renderer next (a pool of renderers shared by worker threads, one thread at a time).
void vd_render_release(vd_renderer* r);
// The OpenGL implementation a renderer draws with: pictures from a GPU and from Mesa's software
// rasteriser can differ in their last bits, so sidecars record it.
typedef struct vd_render_gl {
  char platform[32];  // EGL display used: "surfaceless" (Mesa), "device" (a GPU driver's EGL)
                      // or "default display"
  char vendor[128];   // GL_VENDOR: "Mesa", "NVIDIA Corporation", ...
  char renderer[128]; // GL_RENDERER: "llvmpipe (LLVM 15.0.6, 256 bits)", a GPU's name, ...
  char version[128];  // GL_VERSION
  int software;       // 1: a software rasteriser (llvmpipe, softpipe, swrast), 0: hardware
} vd_render_gl;

// Text describing the OpenGL context ("EGL 1.5 surfaceless, Mesa llvmpipe ..."), for logs.
const char* vd_render_info(const vd_renderer* r);
// The OpenGL implementation of the renderer (valid while it lives).
const vd_render_gl* vd_render_gl_info(const vd_renderer* r);
// Lighting and stage colours, changeable between frames (a dataset varies them per view).
typedef struct vd_render_look {
  double light_azimuth;   // key light: azimuth it comes from, from +X toward +Y (rad)
  double light_elevation; // key light elevation above the horizon (rad), (0, pi/2]
  double light;           // key light diffuse intensity in [0, 1]
  double headlight;       // light at the camera, diffuse intensity in [0, 1]
  double ambient;         // ambient intensity in [0, 1]
  float sky[2][3];        // sky gradient colours, zenith then horizon, in [0, 1] (with sky 0 in
                          // the settings: the flat background, sky[0] used for both)
  float floor[2][3];      // the floor's two checker colours in [0, 1]
} vd_render_look;

// The renderer's look: at creation the settings' lights, the sky (0.92, 0.95, 1) to (0.55, 0.68,
// 0.85) or the flat background, the floor (0.62, 0.57, 0.50) and (0.55, 0.50, 0.43).
vd_render_look vd_render_get_look(const vd_renderer* r);
// Change the lights and the stage's sky and floor colours for the next frames (a robot's MJCF
// keeps its own sky and floor: only the lights change). VD_ERR_ARG names a value out of range.
vd_status vd_render_set_look(vd_renderer* r, const vd_render_look* look, vd_error* err);
// Set the robot's joint positions (MuJoCo qpos, nq values) for the next frames.
vd_status vd_render_set_robot_qpos(vd_renderer* r, const double* qpos, int nq, vd_error* err);

// What MuJoCo makes of an MJCF file (a robot, a plant from vd_geom_export, a scene including
// both), loaded as the renderer loads a robot and brought to its first state (mj_forward); no
// OpenGL context is needed.
typedef struct vd_mjcf_info {
  int nbody, ngeom, nmesh, njoint; // sizes of the model (the world body counted)
  int nbody_prefix;                // bodies whose names start with the prefix
  int ngeom_prefix;                // geoms of those bodies
  int ncontact;                    // contacts of the first state
  int ncontact_prefix;             // of them, between a geom of a prefix body and one of a body
                                   // that is neither a prefix body nor the world (a robot's)
} vd_mjcf_info;

// Load MJCF files with MuJoCo and count what they hold (prefix Nullable: no prefix counts): one
// file as it is; several (a robot and a plant from vd_geom_export) in a scene that includes each,
// made in memory with the files of their folders (MuJoCo 2.2.2 resolves every include against
// the top file's folder, so a robot that includes its gripper would not load from a scene file
// elsewhere). VD_ERR_IO when a file cannot be opened, VD_ERR_FORMAT with MuJoCo's message when it
// does not load, VD_ERR_VALUE for a MuJoCo error after loading.
vd_status vd_render_mjcf_info(const char* const* files, int nfiles, const char* prefix,
                              vd_mjcf_info* info, vd_error* err);

// ---------------------------------------------------------------------------------------------
// what is drawn

// How plants and clouds are coloured.
typedef enum vd_color_by {
  VD_COLOR_LABEL = 0,    // the label table's colour (fruit red, leaf green, ...)
  VD_COLOR_INSTANCE,     // a distinct colour per organ instance
  VD_COLOR_STRESS,       // a colour scale of a per-segment stress given by the caller (Pa)
  VD_COLOR_DISPLACEMENT, // a colour scale of the distance from the rest shape (m)
} vd_color_by;

// Colours of labels (colour by label, and the legend).
typedef enum vd_palette {
  VD_PALETTE_DISTINCT = 0, // every label its own colour, at least 29 CIE76 units apart in L*a*b*
                           // for 15 labels, organ-like where it can (leaf green, fruit red, stem
                           // brown, flower yellow; a second stem or leaf label gets another)
  VD_PALETTE_NATURAL,      // the label table's colours (by organ kind: labels of one organ, such
                           // as trunk and branch or peduncle and pedicel, look alike)
} vd_palette;

// Colours of a label table (sorted by id, as a model's) in a palette into rgb (nlabel x 3): the
// distinct palette hands its colours out in id order, each label taking the first free colour its
// organ prefers, then the first free one; beyond 15 labels, hues by the golden ratio.
void vd_render_label_colors(const vd_label* labels, int nlabel, vd_palette palette,
                            float (*rgb)[3]);

// Look of one plant or cloud.
typedef struct vd_render_style {
  vd_color_by color_by;     // default VD_COLOR_LABEL
  vd_palette palette;       // label colours; default VD_PALETTE_DISTINCT
  const double* seg_stress; // Nullable: stress per segment (Pa) (nseg), needed by VD_COLOR_STRESS;
                            // NaN: no value (drawn grey), infinite: refused
  double range_min;         // colour scale minimum (Pa or m); with range_max <= range_min the
  double range_max;         // scale spans the attached plant's values (vd_render_value_range);
                            // default 0, 0
  int slices;               // tessellation sides (>= 3), or 0 for each primitive's own; default 0
  const vd_data* ref;       // Nullable: state displacement is measured from (a run's first
                            // frame); NULL: the model's rest shape; default NULL
  int log_scale;            // 1: the colour scale is logarithmic (values <= 0 at its bottom;
                            // an automatic range spans the positive values, four decades at
                            // most); default 0
} vd_render_style;

// Defaults: colour by label in the distinct palette, no stress, automatic range, slices 0,
// displacement from the rest shape (ref NULL).
vd_render_style vd_render_style_default(void);

// Remove every plant and cloud added since the last clear.
void vd_render_clear(vd_renderer* r);
// Add plant model m in state d (Nullable: its rest shape) with style s (Nullable: defaults).
vd_status vd_render_add_plant(vd_renderer* r, const vd_model* m, const vd_data* d,
                              const vd_render_style* s, vd_error* err);

// Add a labelled triangle mesh (vd_geom_read_mesh: an OBJ or PLY that verdant grow wrote) coloured
// by label or instance (style Nullable: by label); labels (Nullable, nlabel entries, any order)
// names them. Every triangle is drawn from both sides (which surfaces are open is not known).
vd_status vd_render_add_mesh(vd_renderer* r, const vd_mesh* mesh, const vd_label* labels,
                             int nlabel, const vd_render_style* style, vd_error* err);

// The colour scale vd_render_add_plant gives plant m in state d (Nullable: at rest) under style
// (Nullable: defaults) when the style fixes none: the smallest and largest stress (Pa) or
// displacement (m) of the primitives still joined to the root (a segment that broke and what
// lies beyond it, a fruit that left its attachment node are left out and drawn in the end
// colour; all primitives when none is left); 0, 0 for other colourings or no values. A caller
// drawing many states (the frames of a run) takes the union for one scale.
vd_status vd_render_value_range(const vd_model* m, const vd_data* d, const vd_render_style* style,
                                double* lo, double* hi, vd_error* err);

// A point cloud to splat: arrays owned by the caller.
typedef struct vd_points {
  int n;                  // number of points
  const double* xyz;      // positions (m) (n x 3)
  const int* label;       // Nullable: semantic label per point (n); NULL: all label 0
  const int* instance;    // Nullable: instance per point (n); NULL: all instance 0
  double radius;          // splat half-size (m), > 0, or 0 for 0.4% of the cloud's extent
  const vd_label* labels; // Nullable: label names and colours (nlabel), for colours and legend
  int nlabel;             // entries in labels
} vd_points;

// Add a point cloud coloured by label or instance (style Nullable: by label).
vd_status vd_render_add_points(vd_renderer* r, const vd_points* p, const vd_render_style* s,
                               vd_error* err);
// Shapes of solids drawn beside plants and clouds (the colliders of a simulation run).
typedef enum vd_render_shape_kind {
  VD_RENDER_SPHERE = 0, // sphere of radius size[0]
  VD_RENDER_CAPSULE,    // capsule of radius size[0] and half-length size[1] along its z axis
  VD_RENDER_BOX,        // box of half-extents size[0..2] along its axes
} vd_render_shape_kind;

// A solid: a probe, a tool, an obstacle.
typedef struct vd_render_shape {
  vd_render_shape_kind kind; // shape
  double size[3];     // sizes (m), see vd_render_shape_kind
  vd_vec3 pos;        // centre (m)
  vd_quat quat;       // orientation (normalised here)
  float rgb[3];       // colour in [0, 1]
} vd_render_shape;

// Add a solid; its pixels carry label VD_RENDER_ROBOT_LABEL and instance 0 in the masks, like a
// robot's. VD_ERR_VALUE for sizes that are not finite and > 0 (a capsule's half-length >= 0).
vd_status vd_render_add_shape(vd_renderer* r, const vd_render_shape* s, vd_error* err);
// Bounds of everything added and of the robot's geoms (m); with the floor on, of what is above
// it (z >= 0) when anything is. Returns 0 when there is nothing.
int vd_render_bounds(const vd_renderer* r, vd_vec3* lo, vd_vec3* hi);

// ---------------------------------------------------------------------------------------------
// frames

// layers of a frame
#define VD_LAYER_COLOR 1u    // colour image (RGB, 8 bits)
#define VD_LAYER_DEPTH 2u    // depth along the optical axis (m)
#define VD_LAYER_LABEL 4u    // semantic label of the front surface
#define VD_LAYER_INSTANCE 8u // organ instance of the front surface
#define VD_LAYER_ALL 15u

// One entry of a frame's legend.
typedef struct vd_legend_entry {
  int id;                       // label id (by label) or 0
  char name[VD_LABEL_NAME_MAX]; // what it names
  float rgb[3];                 // its colour in [0, 1]
} vd_legend_entry;

// A rendered frame; arrays belong to the renderer and stay valid until its next draw.
typedef struct vd_frame {
  int width, height;        // size (pixels)
  unsigned layers;          // VD_LAYER_* present
  const uint8_t* rgb;       // colour, top row first (height x width x 3)
  const double* depth;      // depth along the optical axis (m), 0 where nothing (height x width)
  const uint16_t* label;    // label id, 0 background (height x width)
  const uint16_t* instance; // instance id, 0 background (height x width)
  vd_intrinsics K;          // camera intrinsics and pose
  vd_camera camera;         // the camera drawn from
  vd_color_by color_by;     // colouring of the first plant or cloud
  vd_palette palette;       // its label colours
  int nlegend;              // labels present, by id, with names and label colours (the mask key)
  const vd_legend_entry* legend; // (nlegend)
  double range_min, range_max;   // colour scale of stress (Pa) or displacement (m)
  const vd_render_gl* gl;        // Nullable: the OpenGL implementation that drew it
} vd_frame;

// Render the scene from camera c; layers is a mask of VD_LAYER_*.
vd_status vd_render_draw(vd_renderer* r, const vd_camera* c, unsigned layers, vd_frame* out,
                         vd_error* err);

// ---------------------------------------------------------------------------------------------
// files (atomic: temporary name, renamed when complete)

// Write one layer as PNG: colour RGB 8-bit; depth 16-bit grey in millimetres (0 = nothing,
// saturating at 65535); label or instance 16-bit grey ids.
vd_status vd_render_write_png(const vd_frame* f, unsigned layer, const char* path, vd_error* err);
// Write the sidecar JSON: format version, intrinsics, pose, depth scale, legend, the OpenGL
// implementation that drew it, files named in files (Nullable; NULL-terminated pairs "role",
// "path").
vd_status vd_render_write_json(const vd_frame* f, const char* const* files, const char* path,
                               vd_error* err);
// Read a PNG (grey or RGB, 8 or 16 bits; alpha dropped) into *pix (w x h x channels values, row 0
// at the top), free with vd_free(*pix, w * h * channels * sizeof(uint16_t)).
vd_status vd_render_read_png(const char* path, int* w, int* h, int* channels, int* bits,
                             uint16_t** pix, vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
