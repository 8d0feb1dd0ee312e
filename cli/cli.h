// SPDX-License-Identifier: MIT
// Shared pieces of the verdant command: option parsing, loading a plant, errors, progress.
#ifndef VERDANT_CLI_H
#define VERDANT_CLI_H

#include <stdio.h>

#include "verdant/verdant.h"

// exit codes (DESIGN.md): 0 success, 1 failed run, 2 bad usage or bad input
enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_USAGE = 2 };

// Exit code for a library status: input faults are 2, resource and I/O faults of a run are 1.
int cli_exit_code(vd_status st);
// Print "verdant <cmd>: file:line:col: message" to stderr and return the exit code.
int cli_report(const char* cmd, const vd_error* err, vd_status st);
// An error without a file (a plant that does not compile, a rod model that cannot be built)
// is about the input plant: name it.
void cli_blame_input(vd_error* err, const char* path);
// Print a usage error and return EXIT_USAGE.
int cli_usage_error(const char* cmd, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

// Options every command that takes a plant understands.
typedef struct cli_plant_opts {
  const char* path;        // .lpy or plant .json
  int steps;               // -n/--steps, -1 = file's derivation length
  uint64_t seed;           // --seed
  int64_t max_modules;     // --max-modules
  int64_t max_ops;         // --max-ops (0 = library default)
  const char* set[64];     // --set NAME=VALUE
  int nset;
  const char* label[64];   // --label ID=NAME
  int nlabel;
  int progress;            // show a progress bar (stderr is a terminal)
  double curve_step;       // --curve-step (m) for curves files, < 0: the file's or the default
  double curve_connect;    // --curve-connect (m), < 0: the file's or the default
  double curve_distance;   // --curve-distance (m), < 0: the file's or the default
  int engine;              // --engine auto|native|python (vd_lsys_engine), VD_LSYS_AUTO by default
  const char* lstring_out; // --lstring FILE: the derived L-string as JSON (.lpy files), NULL: none
  int instances;           // --instances: a vd_instance_mode, or -1 (default): organs for .lpy
                           // files, a plant file's own numbering
  int animate;             // grow --animate: draw after every step (vd_lsys_animate), .lpy files
  const char* frames;      // grow --frames PATTERN: write each frame there (a %d field), or NULL
  const char* call[8];     // grow --call NAME: the file's functions called after the run
  int ncall;
} cli_plant_opts;

// The file of animation frame `frame` from a --frames pattern: the pattern with its one integer
// field (%d, %4d, %04d) filled and %% as %; 0 when the pattern has no such field, more than
// one, another conversion, or the name does not fit cap.
int cli_frame_name(const char* pattern, int frame, char* buf, size_t cap);

// Defaults: steps -1, seed 0, max_modules 50e6, progress if stderr is a TTY.
void cli_plant_opts_init(cli_plant_opts* o);
// Consume a plant option at argv[*i] (advancing *i past its value); 1 if consumed, 0 if not
// a plant option, -1 on a bad value (message printed).
int cli_plant_opt(cli_plant_opts* o, const char* cmd, int argc, char** argv, int* i);
// Help text lines for the plant options.
extern const char* cli_plant_help;
// Declare the plant options' files to the output layer: PLANT read, --lstring and --frames written.
void cli_out_plant_opts(const cli_plant_opts* o);

// Load the plant: derive an .lpy (and keep its derived string's module counts in stats), read
// a plant file, or build a plant from a curves file. On success *out is a new spec.
typedef vd_plant_load_info cli_grow_info;  // what the load did (module counts for --stats)
vd_status cli_load_plant(const cli_plant_opts* o, vd_plant_spec** out, cli_grow_info* info, vd_error* err);
// The L-system of an .lpy file with the options' engine and --set overrides (sim --grow).
vd_status cli_load_lsystem(const cli_plant_opts* o, vd_lsystem** out, vd_error* err);
// What the file at path is when it is not a plant ("a mesh (PLY)", "a point cloud (LAS)", "a
// simulation run", JSON of another format), told from its first bytes and its name; NULL when it
// may be one (L-Py text, plant or curves JSON). buf holds the text for some kinds (cli_kind.c).
const char* cli_not_a_plant(const char* path, char* buf, size_t cap);
// Free what cli_load_plant put in info.
#define cli_grow_info_free vd_plant_load_info_free

// Parse a whole decimal integer within [lo, hi]; 1 on success.
int cli_parse_i64(const char* s, int64_t lo, int64_t hi, int64_t* out);
// Parse two whole decimal integers A<sep>B, each within [lo, hi] ("640x480", "2/8"); 1 on success.
int cli_parse_i64_pair(const char* s, char sep, int64_t lo, int64_t hi, int64_t* a, int64_t* b);
// Parse n comma-separated finite numbers, the whole text ("1,2.5,3"); 1 on success.
int cli_parse_nums(const char* s, double* x, int n);
// Parse X,Y,Z (three finite numbers, the whole text); 1 on success.
int cli_parse_vec3(const char* s, vd_vec3* v);
// Parse a whole finite number; 1 on success.
int cli_parse_num(const char* s, double* out);
// Inside an option parser with locals a (the option), val, i, argc, argv and cmd: take the
// option's value into val, or report that it is missing and return -1.
#define CLI_TAKE()                                                                                 \
  do {                                                                                             \
    if (*i + 1 >= argc) {                                                                          \
      cli_usage_error(cmd, "%s needs a value", a);                                                 \
      return -1;                                                                                   \
    }                                                                                              \
    val = argv[++*i];                                                                              \
  } while (0)
// Inside a command's own argument loop (locals a, val, i, argc, argv and cmd, in a function that
// returns the exit status): take the option's value into val, or return the usage error (2).
#define CLI_VAL()                                                                                  \
  do {                                                                                             \
    if (i + 1 >= argc) return cli_usage_error(cmd, "%s needs a value", a);                         \
    val = argv[++i];                                                                               \
  } while (0)
// ... and the value as a finite number (cli_parse_num) for which cond holds (cond reads x_) into
// dst, or the usage error "OPTION expects WHAT, got 'VALUE'".
#define CLI_NUM(dst, cond, what)                                                                   \
  do {                                                                                             \
    CLI_VAL();                                                                                     \
    double x_;                                                                                     \
    if (!cli_parse_num(val, &x_) || !(cond))                                                       \
      return cli_usage_error(cmd, "%s expects %s, got '%s'", a, what, val);                        \
    (dst) = x_;                                                                                    \
  } while (0)
// Interrupts: SIGINT and SIGTERM remove every output of the run (cli_out_rollback), then end the
// process by the same signal. Call once from main.
void cli_signals_init(void);

// Monotonic seconds.
double cli_now(void);
// A progress bar on stderr: "\rWHAT [####    ] TEXT" (frac in [0, 1]); the caller ends it with
// a newline. Callers show it only when stderr is a terminal (cli_plant_opts.progress).
void cli_progress_bar(const char* what, double frac, const char* text);
// the end of a bar: its line cleared, nothing left on screen
void cli_progress_clear(void);
// When to redraw a bar: at the first call, then at most ten times a second; off when on is 0.
typedef struct cli_progress {
  int on, shown;
  double last;  // cli_now() of the last redraw
} cli_progress;
int cli_progress_due(cli_progress* p);
// End a bar that was shown (a newline).
void cli_progress_end(cli_progress* p);
// Does path end with ext (case-insensitive, ext with the dot)?
int cli_has_ext(const char* path, const char* ext);

// The output layer (cli_paths.c): every file a command writes goes through it. A command
// declares what it reads and writes before the first byte (what: the option or role, named in
// messages), then cli_out_check refuses (exit 2, naming both) an output that is an input (same
// inode: another spelling, a hard or symbolic link), an input inside an output folder under a
// name written there, two outputs that are one file, and an output that cannot be written. The
// library's writers (vd_outfile, vd_outdir_make) refuse any other path and keep each file under a
// temporary name beside its target; main() calls cli_out_finish, which puts them all in place
// when the command succeeded, else removes them (as the SIGINT/SIGTERM handler does).
// Is a the same file as b (both exist, same device and inode)?
int cli_same_file(const char* a, const char* b);
// Install the layer as the library's output guard (main, before any command runs).
void cli_out_init(void);
// A file the command reads (missing files are compared by name).
void cli_out_input(const char* what, const char* path);
// A file the command writes.
void cli_out_file(const char* what, const char* path);
// A folder the command writes into: members are fnmatch patterns (relative, '/' matched only by
// '/') of the files written there, made with their folders as needed; replace: files matching
// them that an earlier run left and this run does not write are removed when the command succeeds.
void cli_out_folder(const char* what, const char* dir, const char* const* members, int nmember, int replace);
// The same, named in messages as shown (a --frames pattern) rather than as the folder.
void cli_out_pattern(const char* what, const char* shown, const char* dir, const char* const* members, int nmember,
                     int replace);
// Compare every declared output with every input and output, check each can be written: 0, or
// EXIT_USAGE after printing why (nothing touched).
int cli_out_check(const char* cmd);
// The name that holds the file written to path now: its temporary name until the command ends.
const char* cli_out_current(const char* path, char* buf, size_t cap);
// Put these complete outputs in place now (ok), or drop them: an item of a batch that resumes.
// Nonzero when one could not be put in place.
int cli_out_publish(const char* const* paths, int n, int ok);
// The end of the command with exit code rc: 0 puts every output in place (EXIT_FAIL when one
// cannot be), else every output and folder made goes. Returns the exit code.
int cli_out_finish(const char* cmd, int rc);
// For the signal handler: remove every temporary file and folder made (async-signal-safe).
void cli_out_rollback(void);
// Remove path when it is a temporary file of this layer left by a process that is gone (killed
// by SIGKILL, power loss): "<name>.tmp.<pid>" or ".bak.<pid>"; 1 when removed.
int cli_out_drop_orphan(const char* path);

// The files of a plant output: path, and for .obj its material library (.mtl); returns the count.
int cli_plant_files(const char* path, char files[2][4200]);
// Declare a plant output (the file, and for .obj its .mtl).
void cli_out_plant(const char* what, const char* path);

// Write a plant by the extension of path (.json, .obj, .ply; ascii: PLY as text).
vd_status cli_write_plant(const vd_plant_spec* plant, const char* path, int ascii, vd_error* err);

// Options of the commands that make point clouds (cloud, dataset).
#define CLI_MAX_SCANNERS 64
typedef struct cli_cloud_opts {
  vd_cloud_def def;                          // sampler settings (scanners filled in later)
  vd_cloud_write_def wdef;                   // --ascii, --ply-scalar-prefix
  int nscanner;                              // --scanner count
  vd_vec3 scanner_pos[CLI_MAX_SCANNERS];     // --scanner positions (m)
  vd_vec3 scanner_target[CLI_MAX_SCANNERS];  // --scanner targets (m)
  int scanner_has_target[CLI_MAX_SCANNERS];  // 0: the plant's bounding-box centre
  const char* scanners_file;                 // --scanners preset
  vd_scan_pattern pattern;                   // --pattern of --scanner scanners
  double fov_h, fov_v;                       // --fov (rad)
  int res_h, res_v;                          // --res
  int labels_instance;                       // --labels instance
  int has_cloud_seed;                        // --cloud-seed given
  uint64_t cloud_seed;                       // --cloud-seed
  int density_given, scan_opts, points_given; // for consistency checks
} cli_cloud_opts;

// Defaults of every cloud option (vd_cloud_def_default, the default scanner grid).
void cli_cloud_opts_init(cli_cloud_opts* o);
// Consume a cloud option at argv[*i]; 1 consumed, 0 not a cloud option, -1 bad value (printed).
int cli_cloud_opt(cli_cloud_opts* o, const char* cmd, int argc, char** argv, int* i);
// Check option combinations after parsing; prints and returns EXIT_USAGE, or 0 when fine.
int cli_cloud_check(const cli_cloud_opts* o, const char* cmd);
// Check the writer options against the output (a file name, a format name "ply", or NULL when
// nothing is written): --ascii needs PLY or PCD, --ply-scalar-prefix PLY. Prints, EXIT_USAGE.
int cli_cloud_check_output(const cli_cloud_opts* o, const char* cmd, const char* out);
// Help text lines for the cloud options.
extern const char* cli_cloud_help;

// What cli_cloud_make produced: the cloud (owned, vd_cloud_free) and timings.
typedef struct cli_cloud_result {
  vd_cloud cloud;
  vd_cloud_stats stats;
  double seconds_load, seconds_compile, seconds_write, seconds_total;
  int write_failed;  // the failure was writing the output
} cli_cloud_result;

// Load the plant, sample its cloud, relabel if asked, write it to out (Nullable: no file).
vd_status cli_cloud_make(const cli_plant_opts* po, const cli_cloud_opts* co, const char* out,
                         cli_cloud_result* res, vd_error* err);
// Points per label table entry (count has c->nlabel slots); 0 when out of memory.
int cli_label_counts(const vd_cloud* c, int64_t* count);
// The --stats JSON of a result (caller deletes it), NULL when out of memory.
// profile: also the threads, the seconds per stage and the rates (timings: not the same bytes twice)
struct cJSON* cli_cloud_stats_json(const cli_cloud_result* r, double seconds_total, int profile);

// Simulation runs on disk (cli_run.c): the rod build settings of rod.json, the colliders of
// colliders.jsonl, and a run read back frame by frame.
struct cJSON* cli_sim_def_json(const vd_sim_def* def);
// Read the build settings written by cli_sim_def_json (errors name path and the field).
vd_status cli_sim_def_parse(const struct cJSON* o, const char* path, vd_sim_def* def, vd_error* err);
// Write one line of colliders.jsonl: the state's time and colliders.
void cli_colliders_write(FILE* fp, const vd_sim_data* d);
// The rod topology of a run (DIR/rod.json: what frames refer to, and how to rebuild the model).
vd_status cli_rod_json_write(const vd_sim_model* m, const vd_model* plant, const vd_sim_def* def,
                             const char* dir, vd_error* err);
// A run's frames being written: DIR/frames.bin (or .jsonl) and DIR/colliders.jsonl.
typedef struct cli_frames {
  vd_outfile frames, colliders;
  int frames_open, colliders_open, jsonl;  // zero the struct
  size_t fbuf_n;
  unsigned char* bbuf;
} cli_frames;
// The files a simulation run folder holds (sim -o DIR, its --batch items): fnmatch patterns for
// cli_out_folder.
extern const char* const cli_run_members[];
extern const int cli_run_nmember;
// Open the frames files of a run folder (temporary names until cli_frames_end).
vd_status cli_frames_begin(cli_frames* o, const vd_sim_model* m, const char* dir, int jsonl,
                           vd_error* err);
// Append one frame of state d; nonzero when a write has failed (the commit reports it).
int cli_frames_write(cli_frames* o, const vd_sim_model* m, const vd_sim_data* d);
// Commit both files (colliders only beside complete frames) and release the writer.
vd_status cli_frames_end(cli_frames* o, vd_error* err);
// Remove the temporary files and release the writer (after cli_frames_end: only releases).
void cli_frames_abort(cli_frames* o);

// A run folder opened for reading.
typedef struct cli_run {
  char dir[4096];          // the folder
  vd_plant_spec* spec;     // the initial plant (plant_initial.json)
  vd_model* plant;         // compiled
  vd_sim_model* sim;       // rod model rebuilt with the run's build settings
  vd_sim_data* state;      // rod state of the loaded frame
  vd_data* pstate;         // plant state of the loaded frame
  vd_sim_frames* frames;   // frames.bin or frames.jsonl
  int nframe;              // frames (>= 1)
  int* col_start;          // colliders of frame k: col[col_start[k] .. col_start[k + 1]) (nframe + 1)
  vd_sim_collider* col;    // every frame's colliders (ncol); NULL without colliders.jsonl
  int ncol, cap_col;
} cli_run;

// Open a run folder: rod.json, plant_initial.json, frames, colliders.jsonl when there.
vd_status cli_run_open(const char* dir, cli_run* run, vd_error* err);
// Load frame k into run->state and run->pstate.
vd_status cli_run_load(cli_run* run, int k, vd_error* err);
// Colliders of frame k (count returned; *out points into the run).
int cli_run_colliders(const cli_run* run, int k, const vd_sim_collider** out);
// Release everything the run holds.
void cli_run_close(cli_run* run);

// Options of `verdant render` (cli_render.c), shared with the run renderer (cli_render_run.c).
typedef struct cli_render_opts {
  cli_plant_opts po;        // the input (po.path) and the plant options
  const char* out;          // -o: OUT.png, or a folder for every frame of a run
  const char* mp4;          // --mp4 (runs)
  vd_render_def def;        // --size, --supersample, --robot, --no-floor ...
  vd_render_style style;    // --color-by, --range
  vd_camera_kind kind;      // --camera
  double az, el;            // --camera orbit angles (degrees)
  int has_eye;              // --eye/--lookat given
  vd_vec3 eye, lookat, up;  // explicit pose (m), --up
  double fov;               // --fov (degrees)
  int depth, masks, info;   // --depth, --masks, --info
  double point_size;        // --point-size (m), 0 automatic
  int has_time;             // --time given
  double time;              // --time (s)
  double fps;               // --fps of the MP4 (0: the run's frame rate)
  int disp_from_first;      // --displacement-from first (runs): from frame 0, not the model
  int has_sky, has_floor;   // --sky-rgb, --floor-rgb given
  float sky[2][3];          // --sky-rgb: zenith and horizon colours in [0, 1]
  float floor[2][3];        // --floor-rgb: checker colours in [0, 1]
} cli_render_opts;

// Parse an option of the look of pictures (--light AZ,EL[,KEY[,HEAD[,AMBIENT]]] into def,
// --sky-rgb, --floor-rgb into o) at argv[*i]: 1 consumed, 0 not one, -1 bad value (printed).
int cli_look_opt(cli_render_opts* o, const char* cmd, int argc, char** argv, int* i);
// Apply --sky-rgb and --floor-rgb to a renderer made from o->def.
vd_status cli_apply_look(const cli_render_opts* o, vd_renderer* r, vd_error* err);

// --palette NAME (distinct, natural); 1 on success.
int cli_parse_palette(const char* s, vd_palette* out);
// The camera of the options: the explicit pose, or the preset fitted to the box lo..hi.
vd_camera cli_render_camera(const cli_render_opts* o, vd_vec3 lo, vd_vec3 hi);
// The files of a frame: OUT.png, and with depth or masks OUT.depth.png, OUT.label.png,
// OUT.instance.png and the sidecar OUT.png.json naming them (named after the whole image name, so
// it never takes the name of a plant file OUT.json). Fills path[0..n) and returns n.
int cli_frame_files(const char* out, int depth, int masks, char path[5][4200]);
// Write a frame's files (cli_frame_files; every file atomic).
vd_status cli_frame_write(const vd_frame* f, const char* out, int depth, int masks, vd_error* err);
// Render a simulation run folder (cli_render_run.c); returns the exit code.
int cli_render_run(const cli_render_opts* o);
// Render a growth run folder (growth.json, age_NNN.json; cli_render_growth.c): the last age, the
// one nearest --time, or every age into a folder; returns the exit code.
int cli_render_growth(const cli_render_opts* o);

// The pictures of `verdant dataset --images N` (cli_views.c): render options and what varies
// from view to view.
typedef struct cli_view_opts {
  int shadows, floor, sky;  // 0 with --no-shadows, --no-floor, --no-sky
  int supersample;          // --supersample K
  vd_palette palette;       // --palette
  double el[2];             // --view-elevation A:B (degrees)
  double dist[2];           // --view-distance A:B (times the fitted distance)
  double jitter;            // --view-jitter F (fraction of the plant's half-size)
  int vary_light;           // --vary-light
  int vary_background;      // --vary-background
  int given;                // any of these given (they need --images)
} cli_view_opts;

// One view: its angles (degrees), distance factor, camera, look, lights as render --light takes.
typedef struct cli_view {
  double az, el, dist;
  vd_camera cam;
  vd_render_look look;
  double light[5];  // azimuth, elevation (degrees), key, headlight, ambient
} cli_view;

// Help lines of the view options.
extern const char* cli_view_help;
// Defaults: shadows, floor, sky, supersample 2, distinct palette, elevation 10:40, distance 1:1,
// no jitter, lights and background fixed.
void cli_view_opts_init(cli_view_opts* v);
// Consume a view option at argv[*i]: 1 consumed, 0 not one, -1 bad value (printed).
int cli_view_opt(cli_view_opts* v, const char* cmd, int argc, char** argv, int* i);
// 1 when views need an explicit pose (a distance other than 1 or jitter).
int cli_view_explicit(const cli_view_opts* v);
// The render settings the options set (shadows, floor, sky, supersample).
void cli_view_def(const cli_view_opts* v, vd_render_def* def);
// Draw one view at azimuth az (degrees) of the box lo..hi for a w x h picture from g, starting
// from the renderer's look.
void cli_view_draw(const cli_view_opts* v, vd_rng* g, double az, vd_vec3 lo, vd_vec3 hi, int w,
                   int h, vd_render_look look, cli_view* out);
// The view's fields in its record (azimuth, elevation; eye, lookat, up, distance; light; sky,
// floor: as the options make them vary).
void cli_view_record(const cli_view_opts* v, const cli_view* view, struct cJSON* e);
// Append the render options that make a view again to a recipe (fields in braces: {azimuth},
// {elevation}, {eye}, {lookat}, {up}, {light}, {sky}, {floor}, arrays written A,B,...).
void cli_view_recipe(const cli_view_opts* v, struct cJSON* a);

// Rewrite the command line before dispatch (cli_args.c): --opt=value into --opt value, operands
// after -- that start with '-' as ./-name, 'help CMD' as 'CMD --help'; a repeated -o/--output is
// an error. Returns 0, or the exit code after printing why.
int cli_args_normalize(int* argc, char*** argv);

// Subcommands.
int cli_harvest(int argc, char** argv);
// verdant sim PLANT --grow (cli_sim_grow.c): growth with physics between the age steps.
int cli_sim_grow(int argc, char** argv);
int cli_grow(int argc, char** argv);
int cli_cloud(int argc, char** argv);
int cli_dataset(int argc, char** argv);
int cli_render(int argc, char** argv);
int cli_sim(int argc, char** argv);
int cli_validate(int argc, char** argv);
int cli_export(int argc, char** argv);

#endif
