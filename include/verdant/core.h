// SPDX-License-Identifier: MIT
// verdant core: math by value, allocation hook with byte count, arena, seeded RNG,
// status codes and the error struct every other module reports through.
//
// Ownership: nothing here owns global state except the allocator hook and the assert
// handler, both set once by the application before any other call.
//
// Usage:
//   vd_rng rng; vd_rng_seed(&rng, 42);            // same stream as CPython random.seed(42)
//   double u = vd_rng_random(&rng);               // [0, 1)
//   vd_error err = {0};
//   vd_status st = vd_some_call(..., &err);       // err.file, err.line, err.col, err.msg
//   if (st != VD_OK) fprintf(stderr, "%s\n", vd_error_format(&err, buf, sizeof buf));
#ifndef VERDANT_CORE_H
#define VERDANT_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#define VD_VERSION_MAJOR 0
#define VD_VERSION_MINOR 1
#define VD_VERSION_PATCH 0
#define VD_VERSION_STRING "0.1.0"

// ---------------------------------------------------------------------------------------------
// status codes: one X-macro list gives the enum and vd_status_str()

#define VD_STATUS_LIST(X)                                                                          \
  X(VD_OK, "ok")                                                                                   \
  X(VD_ERR_SYNTAX, "syntax error")                                                                 \
  X(VD_ERR_UNSUPPORTED, "unsupported construct")                                                   \
  X(VD_ERR_NAME, "undefined name")                                                                 \
  X(VD_ERR_TYPE, "wrong type")                                                                     \
  X(VD_ERR_VALUE, "bad value")                                                                     \
  X(VD_ERR_ASSERT, "assertion failed")                                                             \
  X(VD_ERR_LIMIT, "limit exceeded")                                                                \
  X(VD_ERR_IO, "input/output error")                                                               \
  X(VD_ERR_FORMAT, "bad file format")                                                              \
  X(VD_ERR_NOMEM, "out of memory")                                                                 \
  X(VD_ERR_ARG, "bad argument")

typedef enum vd_status {
#define VD_STATUS_ENUM(name, text) name,
  VD_STATUS_LIST(VD_STATUS_ENUM)
#undef VD_STATUS_ENUM
      VD_STATUS_COUNT
} vd_status;

// Short English text of a status code ("syntax error").
const char* vd_status_str(vd_status s);

// Where and why an expected failure happened. line and col are 1-based; 0 means unknown.
typedef struct vd_error {
  vd_status status;  // the code also returned by the call
  char file[256];    // input file name, or "" when the input was not a file
  int line;          // 1-based line of the fault, 0 if none
  int col;           // 1-based column of the fault, 0 if none
  char msg[512];     // what was expected / what went wrong
} vd_error;

// Fill err (Nullable: err) with status, location and a printf-style message; returns status.
// The first failure wins: a record that already holds one is left as it is, so a root cause is
// never overwritten by its consequences. Zero a record (vd_error e = {0}) before reusing it.
vd_status vd_error_set(vd_error* err, vd_status status, const char* file, int line, int col,
                       const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;

// Format "file:line:col: message" (parts that are unknown are left out) into buf.
const char* vd_error_format(const vd_error* err, char* buf, size_t cap);

// ---------------------------------------------------------------------------------------------
// binary scalars of PLY, PCD and LAS files (the mesh and cloud readers share them)

typedef enum vd_scalar {
  VD_SCALAR_I8 = 0, VD_SCALAR_U8, VD_SCALAR_I16, VD_SCALAR_U16, VD_SCALAR_I32, VD_SCALAR_U32,
  VD_SCALAR_I64, VD_SCALAR_U64, VD_SCALAR_F32, VD_SCALAR_F64, VD_SCALAR_BAD
} vd_scalar;

// Bytes of a scalar (0 for VD_SCALAR_BAD).
static inline int vd_scalar_size(vd_scalar t) {
  static const int size[] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8, 0};
  return t >= 0 && t <= VD_SCALAR_BAD ? size[t] : 0;
}
// The scalar a PLY property type names ("char" or "int8" ... "double" or "float64");
// VD_SCALAR_BAD for any other name.
vd_scalar vd_scalar_ply(const char* name);
// The little-endian scalar of type t at p, as a double.
double vd_scalar_get_le(const unsigned char* p, vd_scalar t);

// ---------------------------------------------------------------------------------------------
// allocation: all heap traffic goes through one hook that sees sizes

// Allocator hook: realloc semantics (ptr NULL = malloc, size 0 = free). user is passed back.
typedef void* (*vd_realloc_fn)(void* user, void* ptr, size_t old_size, size_t new_size);

// Replace the allocator (NULL restores libc). Call before any other verdant call.
void vd_set_allocator(vd_realloc_fn fn, void* user);
// Bytes currently allocated through verdant (tests check it returns to zero).
int64_t vd_alloc_bytes(void);
// Allocate size bytes (uninitialised); NULL on failure or size 0.
void* vd_malloc(size_t size);
// Allocate n*size zeroed bytes; NULL on failure or overflow.
void* vd_calloc(size_t n, size_t size);
// Resize a block allocated by vd_malloc; old_size must be its current size.
void* vd_realloc(void* ptr, size_t old_size, size_t new_size);
// Free a block of the given size (NULL is fine).
void vd_free(void* ptr, size_t size);
// Grow a dynamic array so that it holds at least need elements; returns 0 on failure.
int vd_grow(void** ptr, int* cap, int need, size_t elem_size);
// Copy a NUL-terminated string with vd_malloc; free with vd_free(s, strlen(s) + 1).
char* vd_strdup(const char* s);

// Arena: bump allocator for scratch memory, reset as a whole.
typedef struct vd_arena {
  struct vd_arena_block* head;  // most recent block
  size_t block_size;            // default block size (bytes)
  size_t used;                  // bytes handed out since the last reset
} vd_arena;

// Initialise an empty arena with the given default block size (bytes, 0 = 64 KiB).
void vd_arena_init(vd_arena* a, size_t block_size);
// Allocate size bytes aligned to 16; NULL on failure.
void* vd_arena_alloc(vd_arena* a, size_t size);
// Forget everything allocated; keeps the largest block for reuse.
void vd_arena_reset(vd_arena* a);
// Release all blocks.
void vd_arena_free(vd_arena* a);


// ---------------------------------------------------------------------------------------------
// files: whole-file reads and atomic writes (temp name, renamed when complete)

// An output file being written under a temporary name next to its final path.
typedef struct vd_outfile {
  FILE* fp;          // open stream to write to
  char path[4096];   // final path
  char tmp[4200];    // temporary path, removed on abort
} vd_outfile;

// Open path for writing (binary) under a temporary name in the same directory.
vd_status vd_outfile_open(vd_outfile* f, const char* path, vd_error* err);
// The temporary name vd_outfile_open uses for path in this process ("<path>.tmp.<pid>").
void vd_outfile_tmp_path(const char* path, char* buf, size_t cap);
// Flush, check for write errors, close and rename to the final path; on failure nothing is left.
vd_status vd_outfile_commit(vd_outfile* f, vd_error* err);
// Close and remove the temporary file (safe after a failed commit, and twice).
void vd_outfile_abort(vd_outfile* f);
// Make the folder path for outputs (an existing folder is fine); through the guard when one is set.
vd_status vd_outdir_make(const char* path, vd_error* err);
// Take back an output this call committed (a failure after it): removed, or with a guard set, its
// temporary file dropped.
void vd_outfile_remove(const char* path);
// Remove a folder vd_outdir_make made, when empty (with a guard set the guard does, at the end).
void vd_outdir_remove(const char* path);

// An output guard: a program's one output layer (the verdant command's, cli/cli_paths.c), told
// of every output before its first byte. With a guard set, vd_outfile_open asks open() (which
// may refuse a path that was not declared, or make its folder), vd_outfile_commit hands the
// complete temporary file to commit() instead of renaming it (the guard renames every output
// into place when the whole program succeeded), vd_outfile_abort tells abort(), and
// vd_outdir_make calls mkdir(). Without one (the default, the Python package) each file is
// renamed into place when complete and folders are made directly.
typedef struct vd_outfile_guard {
  vd_status (*open)(void* user, const char* path, const char* tmp, vd_error* err);
  vd_status (*commit)(void* user, const char* path, const char* tmp, vd_error* err);
  void (*abort)(void* user, const char* path, const char* tmp);
  vd_status (*mkdir)(void* user, const char* path, vd_error* err);
  void* user;
} vd_outfile_guard;
// Set the process's output guard (Nullable: none); the struct is copied. Not thread-safe: set it
// before any output is open.
void vd_outfile_set_guard(const vd_outfile_guard* g);
// Read a whole file; *text is NUL-terminated, free it with vd_free(*text, *len + 1).
vd_status vd_file_read(const char* path, char** text, size_t* len, vd_error* err);
// Largest file vd_file_read accepts (bytes).
#define VD_FILE_MAX ((size_t)1 << 30)

// Lines of a text in memory, read one at a time by vd_text_line: { text, length, offset of the
// next line, number of the last line read (1-based; 0 before the first) }.
typedef struct vd_text {
  const char* s;
  size_t len, pos;
  int line;
} vd_text;
// The next line of t, without its newline (or the carriage return before it), into *ls and *ll;
// 0 at the end of the text.
int vd_text_line(vd_text* t, const char** ls, size_t* ll);

// ---------------------------------------------------------------------------------------------
// assertions for programmer errors

// Handler called when VD_ASSERT fails; the default prints and aborts.
typedef void (*vd_assert_fn)(const char* expr, const char* file, int line);
// Replace the assert handler (NULL restores the default).
void vd_set_assert_handler(vd_assert_fn fn);
// Called by VD_ASSERT on failure.
void vd_assert_fail(const char* expr, const char* file, int line);
#define VD_ASSERT(c) ((c) ? (void)0 : vd_assert_fail(#c, __FILE__, __LINE__))

// Log hook: the library never prints; messages go here (default: dropped).
typedef void (*vd_log_fn)(void* user, int level, const char* msg);
// Install a log hook (NULL drops messages).
void vd_set_log(vd_log_fn fn, void* user);
// Send a printf-style message to the log hook (level 0 info, 1 warning).
void vd_log(int level, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

// ---------------------------------------------------------------------------------------------
// random numbers: MT19937 with CPython's seeding and float algorithms, so a model that calls
// seed(n) draws the same numbers as under L-Py / CPython's random module. No global state.

typedef struct vd_rng {
  uint32_t mt[624];   // Mersenne Twister state
  int mti;            // index into mt
  int has_gauss;      // 1 when gauss_next holds a cached normal deviate (CPython behaviour)
  double gauss_next;  // cached second Box-Muller deviate
} vd_rng;

// Seed like CPython random.seed(n) for an integer n (sign ignored, as CPython does).
void vd_rng_seed(vd_rng* r, uint64_t n);
// Seed from an array of 32-bit words (MT19937 init_by_array).
void vd_rng_seed_array(vd_rng* r, const uint32_t* key, int len);
// Independent stream for item `index` of a run seeded with `master`: item i is reproducible alone.
void vd_rng_stream(vd_rng* r, uint64_t master, uint64_t index);
// Next raw 32-bit output.
uint32_t vd_rng_u32(vd_rng* r);
// Uniform double in [0, 1) with 53 random bits (CPython random()).
double vd_rng_random(vd_rng* r);
// Fill out with n uniform doubles in [0, 1): the same numbers as n calls of vd_rng_random.
void vd_rng_fill(vd_rng* r, double* out, int n);
// a + (b - a) * random() (CPython uniform()).
double vd_rng_uniform(vd_rng* r, double a, double b);
// Normal deviate by CPython's gauss(mu, sigma) (Box-Muller with a cached pair).
double vd_rng_gauss(vd_rng* r, double mu, double sigma);
// Uniform integer in [a, b] inclusive (CPython randint); requires a <= b.
int64_t vd_rng_randint(vd_rng* r, int64_t a, int64_t b);

// ---------------------------------------------------------------------------------------------
// math by value

typedef struct vd_vec3 {
  double x, y, z;
} vd_vec3;

typedef struct vd_quat {
  double w, x, y, z;  // unit quaternion, w scalar part
} vd_quat;

#define VD_PI 3.14159265358979323846

// The q-quantile (0 <= q <= 1) of n >= 1 values sorted ascending, by linear interpolation between
// order statistics (Hyndman & Fan 1996, type 7; numpy's and R's default): h = (n - 1) q,
// Q = x[floor h] + (h - floor h)(x[floor h + 1] - x[floor h]). The median of an even count is
// the mean of the middle two.
double vd_quantile_sorted(const double* x, int n, double q);

static inline vd_vec3 vd_v3(double x, double y, double z) {
  vd_vec3 r = {x, y, z};
  return r;
}
static inline vd_vec3 vd_add(vd_vec3 a, vd_vec3 b) { return vd_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vd_vec3 vd_sub(vd_vec3 a, vd_vec3 b) { return vd_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vd_vec3 vd_scale(vd_vec3 a, double s) { return vd_v3(a.x * s, a.y * s, a.z * s); }
static inline vd_vec3 vd_madd(vd_vec3 a, vd_vec3 b, double s) {
  return vd_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static inline double vd_dot(vd_vec3 a, vd_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vd_vec3 vd_cross(vd_vec3 a, vd_vec3 b) {
  return vd_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline vd_vec3 vd_vmin(vd_vec3 a, vd_vec3 b) {
  return vd_v3(a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z);
}
static inline vd_vec3 vd_vmax(vd_vec3 a, vd_vec3 b) {
  return vd_v3(a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z);
}
// Euclidean length.
double vd_norm(vd_vec3 a);
// a / |a|, or a unchanged when |a| is 0.
vd_vec3 vd_normalize(vd_vec3 a);
// Rotate v about the unit axis by angle (radians), right-handed (Rodrigues).
vd_vec3 vd_rotate(vd_vec3 v, vd_vec3 axis, double angle);

// Identity quaternion.
static inline vd_quat vd_quat_identity(void) {
  vd_quat q = {1, 0, 0, 0};
  return q;
}
// Quaternion for a rotation of angle (radians) about the unit axis.
vd_quat vd_quat_axis_angle(vd_vec3 axis, double angle);
// Product a * b (apply b first, then a).
vd_quat vd_quat_mul(vd_quat a, vd_quat b);
// Conjugate (inverse for unit quaternions).
vd_quat vd_quat_conj(vd_quat q);
// q normalised to unit length.
vd_quat vd_quat_normalize(vd_quat q);
// Rotate v by the unit quaternion q.
vd_vec3 vd_quat_rotate(vd_quat q, vd_vec3 v);
// Quaternion of the rotation whose columns are the orthonormal axes x, y, z.
vd_quat vd_quat_from_axes(vd_vec3 x, vd_vec3 y, vd_vec3 z);

#ifdef __cplusplus
}
#endif
#endif
