// SPDX-License-Identifier: MIT
// verdant cloud: labelled synthetic point clouds of a plant, with scanner effects, and their
// files (PLY, PCD, XYZ/CSV, LAS 1.4; layouts in docs/formats.md).
//
// vd_cloud_sample tessellates a model's state and returns a vd_cloud the caller owns (free it
// with vd_cloud_free). Surface modes (VD_SENSOR_UNIFORM, VD_SENSOR_DISTANCE) return exactly
// def.points points: triangles are drawn by area (alias table), points uniformly inside them
// (square-root barycentric map), and a point inside another closed primitive, rejected by the
// density law, hidden from its scanner, or pushed inside another primitive by noise is replaced
// by a new draw. VD_SENSOR_SCAN casts each scanner's ray grid instead and keeps the hits. Work is
// cut into chunks of VD_CLOUD_CHUNK points (or rays), each with its own random stream
// vd_rng_stream(def.seed, chunk), so any number of threads gives the same bytes.
//
// Usage:
//   vd_cloud_def def = vd_cloud_def_default(); def.points = 100000; def.seed = 7;
//   vd_cloud cloud; vd_error err = {0};
//   if (vd_cloud_sample(model, NULL, &def, &cloud, NULL, &err) == VD_OK) {
//     vd_cloud_write(&cloud, "plant.ply", NULL, &err);   // format from the extension
//     vd_cloud_free(&cloud);
//   }
#ifndef VERDANT_CLOUD_H
#define VERDANT_CLOUD_H

#include "verdant/core.h"
#include "verdant/geom.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VD_CLOUD_FORMAT_VERSION 1 // version of the point-cloud file conventions (docs/formats.md)
#define VD_CLOUD_CHUNK 4096       // points (or rays) per random stream; part of the output's identity
#define VD_CLOUD_TABLE_MAX 64     // most (distance, density) pairs of a table density law

// How points are made.
typedef enum vd_sensor {
  VD_SENSOR_UNIFORM = 0,  // uniform on the surface (scanners only give views, occlusion, noise)
  VD_SENSOR_DISTANCE = 1, // density falls with distance from each scanner by the density law
  VD_SENSOR_SCAN = 2,     // rays on each scanner's angular or pixel grid; the hits are the points
} vd_sensor;

// Relative point density gamma(d) at distance d from a scanner (distance sensor).
typedef enum vd_density_law {
  VD_DENSITY_CONSTANT = 0,       // gamma = 1
  VD_DENSITY_INVERSE_SQUARE = 1, // gamma = (d_near / d)^2
  VD_DENSITY_LINEAR = 2,         // gamma = 1 - (d - d_near) / (d_far - d_near)
  VD_DENSITY_TABLE = 3,          // piecewise linear through (table_d, table_g), flat outside
} vd_density_law;

// How a scanner lays out its rays in scan mode.
typedef enum vd_scan_pattern {
  VD_SCAN_ANGULAR = 0, // equal steps of azimuth and elevation (terrestrial LiDAR)
  VD_SCAN_PINHOLE = 1, // one ray through each pixel centre of a pinhole camera (depth camera)
} vd_scan_pattern;

// One scanner pose and its ray grid.
typedef struct vd_scanner {
  vd_vec3 pos;             // position (m)
  vd_vec3 target;          // point it looks at (m): centre of the ray grid
  vd_scan_pattern pattern; // ray layout in scan mode
  double fov_h, fov_v;     // field of view across and down (rad)
  int res_h, res_v;        // rays across and down
} vd_scanner;

// Scanner at (1, 0, 0.5) m looking at (0, 0, 0.5) m; angular grid, field of view 60 x 45 degrees,
// 320 x 240 rays.
vd_scanner vd_scanner_default(void);

// Settings of vd_cloud_sample.
typedef struct vd_cloud_def {
  int64_t points;            // points returned by the surface modes (>= 1); default 100000
  uint64_t seed;             // master seed of the chunks' random streams; default 0
  vd_sensor sensor;          // default VD_SENSOR_UNIFORM
  vd_density_law density;    // distance sensor's law; default VD_DENSITY_INVERSE_SQUARE
  int ntable;                // pairs of the table law (2..VD_CLOUD_TABLE_MAX); default 0
  double table_d[VD_CLOUD_TABLE_MAX]; // table distances, increasing (m)
  double table_g[VD_CLOUD_TABLE_MAX]; // table densities (>= 0, one > 0)
  double noise_sigma;        // Gaussian noise sigma(d) = noise_sigma + noise_slope d: at d = 0
                             // (m); default 0 (no noise)
  double noise_slope;        // growth of sigma with distance to the scanner (m per m); default 0
  int occlusion;             // 1 keeps only points a scanner sees (back faces of closed
                             // primitives culled, rays cast through the BVH); default 0
  int interior;              // 1 removes points inside other closed primitives; default 1
  int nscanner;              // scanners (0..65535); each is one view; default 0
  const vd_scanner* scanner; // the scanners (borrowed, nscanner) (Nullable when nscanner is 0)
  vd_mesh_def mesh;          // tessellation (caps are always closed); default vd_mesh_def_default()
  int threads;               // OpenMP threads, 0 = OpenMP's default; the output never depends
                             // on it; default 0
  int64_t max_points;        // most points (surface modes) or rays (scan), about 80 bytes each;
                             // beyond is VD_ERR_LIMIT before anything is allocated; default 2e9
  int64_t max_attempts;      // most draws for one point, and a hundredth of it per point on
                             // average over a chunk, before giving up (>= 1); default 100000
  void (*progress)(void* user, int64_t done, int64_t total);  // Nullable: called as chunks of
                             // points are made (done of total chunks), from one thread at a time;
                             // default NULL
  void* progress_user;       // passed to progress; default NULL
} vd_cloud_def;

// Defaults: points 100000, seed 0, uniform sensor, inverse-square law, no table, no noise
// (sigma 0 m, slope 0 m/m), occlusion off, interior removal on, no scanners, default
// tessellation, threads 0 (OpenMP's choice), max_points 2000000000, max_attempts 100000.
vd_cloud_def vd_cloud_def_default(void);

// A labelled point cloud. Point arrays live in one block; the label table in another.
typedef struct vd_cloud {
  int64_t n;         // points
  double* pos;       // position (m) (n x 3)
  double* normal;    // unit surface normal; thin surfaces seen by a scanner face it (n x 3)
  int* label;        // semantic label id, or the instance id after vd_cloud_relabel (n x 1)
  int* instance;     // organ instance id (n x 1)
  int* view;         // index of the scanner that made the point, 0 without scanners (n x 1)
  double* range;     // distance from that scanner (m), 0 without scanners (n x 1)
  int nview;         // scanners behind the cloud; 0: view and range carry nothing
  double* view_pose; // each scanner's position and the point it looks at (m) (nview x 6);
                     // Nullable: not known (a cloud read from a file); owned, vd_cloud_free
  int nlabel;        // entries of the label table
  vd_label* labels;  // label table: id -> name, organ kind, colour (nlabel)
  size_t nbytes;     // size of the point block
} vd_cloud;

// Counters and timings of one vd_cloud_sample call (stages in seconds, wall clock).
typedef struct vd_cloud_stats {
  int ntri;                  // triangles of the tessellation
  int nsolid;                // closed primitives tested for interior points
  double area;               // surface area of the tessellation (m^2)
  int64_t drawn;             // candidate points drawn (surface modes) or rays cast (scan)
  int64_t rejected_interior; // candidates inside another closed primitive
  int64_t rejected_density;  // candidates the density law turned down
  int64_t rejected_backface; // candidates on back faces of closed primitives
  int64_t rejected_occluded; // candidates hidden from their scanner by other surfaces
  int64_t rejected_noise;    // candidates pushed inside another closed primitive by noise
  int64_t missed;            // scan rays that hit nothing
  double seconds_tessellate; // tessellation
  double seconds_build;      // alias table, solids and BVHs
  double seconds_sample;     // drawing, testing and storing the points
  int threads;               // threads used
} vd_cloud_stats;

// Sample a cloud of state d (Nullable: rest shape) of m into out (stats Nullable).
vd_status vd_cloud_sample(const vd_model* m, const vd_data* d, const vd_cloud_def* def,
                          vd_cloud* out, vd_cloud_stats* stats, vd_error* err);
// Allocate an empty cloud of n points and a copy of a label table (labels Nullable if nlabel 0).
vd_status vd_cloud_alloc(vd_cloud* c, int64_t n, const vd_label* labels, int nlabel,
                         vd_error* err);
// Free a cloud's arrays and zero it (NULL and empty clouds are fine).
void vd_cloud_free(vd_cloud* c);
// Make the label of every point its instance id; the table becomes one entry per instance,
// named "<semantic name>_<instance>" (for instance segmentation).
vd_status vd_cloud_relabel(vd_cloud* c, vd_error* err);

// ---------------------------------------------------------------------------------------------
// scanner presets (JSON, docs/formats.md)

// Read scanners from a preset file; positions in a "bbox" frame are placed around the box
// [lo, hi] (m). *out is allocated (free with vd_free(*out, *n * sizeof(vd_scanner))).
vd_status vd_cloud_read_scanners(const char* path, vd_vec3 lo, vd_vec3 hi, vd_scanner** out,
                                 int* n, vd_error* err);
// The same from JSON text in memory (name Nullable, used in errors).
vd_status vd_cloud_parse_scanners(const char* text, size_t len, const char* name, vd_vec3 lo,
                                  vd_vec3 hi, vd_scanner** out, int* n, vd_error* err);

// ---------------------------------------------------------------------------------------------
// files

// File format of a cloud.
typedef enum vd_cloud_format {
  VD_CLOUD_AUTO = 0, // from the extension: .ply .pcd .xyz .csv .las
  VD_CLOUD_PLY,      // Stanford PLY
  VD_CLOUD_PCD,      // PCL's PCD v0.7
  VD_CLOUD_XYZ,      // text, space-separated, '#' header
  VD_CLOUD_CSV,      // text, comma-separated, header line
  VD_CLOUD_LAS,      // ASPRS LAS 1.4, point data record format 6
} vd_cloud_format;

// Settings of vd_cloud_write.
typedef struct vd_cloud_write_def {
  vd_cloud_format format; // default VD_CLOUD_AUTO
  int ascii;              // PLY and PCD as text instead of binary; default 0
  const char* ply_prefix; // prefix of PLY's label, instance, view and range properties
                          // ("scalar_" for CloudCompare) (Nullable: none); default NULL
  const char* comment;    // one line recorded in the header where the format allows it
                          // (Nullable); default NULL
  int threads;            // threads converting binary records, 0 = all cores; the bytes do not
                          // depend on it; default 0
  void (*progress)(void* user, int64_t done, int64_t total);  // Nullable: called as points are
                          // written (done of total); default NULL
  void* progress_user;    // passed to progress; default NULL
} vd_cloud_write_def;

// Defaults: format from the extension, binary, no property prefix, no comment, all cores.
vd_cloud_write_def vd_cloud_write_def_default(void);
// Format for a path's extension (VD_CLOUD_AUTO when unknown).
vd_cloud_format vd_cloud_format_of(const char* path);
// Write a cloud atomically (temporary file renamed when complete) (def Nullable: defaults).
vd_status vd_cloud_write(const vd_cloud* c, const char* path, const vd_cloud_write_def* def,
                         vd_error* err);
// Read a cloud written by vd_cloud_write (format from the extension) into out.
vd_status vd_cloud_read(const char* path, vd_cloud* out, vd_error* err);
// Parse a cloud file's bytes in memory (fmt VD_CLOUD_AUTO: from name's extension; name Nullable,
// used in errors).
vd_status vd_cloud_parse(const char* data, size_t len, vd_cloud_format fmt, const char* name,
                         vd_cloud* out, vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
