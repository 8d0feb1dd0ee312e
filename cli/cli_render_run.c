// SPDX-License-Identifier: MIT
// verdant render RUN/: pictures of a simulation run. The run is read back (cli_run.c), a first
// pass over every frame finds the box the plant and the colliders sweep and the colour scale of
// the whole run, so the camera and the colours stay fixed; the second pass draws the frames
// asked for: one (--time), all into a folder, and/or all into an MP4 through Debian's ffmpeg
// (fed raw RGB on a pipe, written under a temporary name and renamed when it succeeds).
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"

extern char** environ;

// ---------------------------------------------------------------------------------------------
// the box of the run and its colour scale

typedef struct box {
  vd_vec3 lo, hi;
  int any, floor;
} box;

// with a floor, what lies under it is hidden and left out (as vd_render_bounds does)
static void box_add(box* b, vd_vec3 p, double r) {
  vd_vec3 lo = vd_v3(p.x - r, p.y - r, p.z - r), hi = vd_v3(p.x + r, p.y + r, p.z + r);
  if (b->floor && hi.z < 0) return;
  if (b->floor && lo.z < 0) lo.z = 0;
  b->lo = b->any ? vd_vmin(b->lo, lo) : lo;
  b->hi = b->any ? vd_vmax(b->hi, hi) : hi;
  b->any = 1;
}

// the plant state's points and the colliders drawn (planes are not)
static void box_frame(box* b, const vd_model* m, const vd_data* d, const vd_sim_collider* col,
                      int ncol) {
  for (int i = 0; i < m->nnode; i++)
    box_add(b, vd_v3(d->node_pos[3 * i], d->node_pos[3 * i + 1], d->node_pos[3 * i + 2]), 0);
  for (int i = 0; i < m->nsphere; i++)
    box_add(b, vd_v3(d->sphere_pos[3 * i], d->sphere_pos[3 * i + 1], d->sphere_pos[3 * i + 2]),
            m->sphere_radius[i]);
  for (int i = 0; i < m->nvert; i++)
    box_add(b, vd_v3(d->vert_pos[3 * i], d->vert_pos[3 * i + 1], d->vert_pos[3 * i + 2]), 0);
  for (int c = 0; c < ncol; c++) {
    const vd_sim_collider* k = &col[c];
    double r =
        k->shape == VD_SIM_SPHERE    ? k->size[0]
        : k->shape == VD_SIM_CAPSULE ? k->size[0] + k->size[1]
        : k->shape == VD_SIM_BOX
            ? sqrt(k->size[0] * k->size[0] + k->size[1] * k->size[1] + k->size[2] * k->size[2])
            : -1;
    if (r >= 0) box_add(b, k->pos, r);
  }
}

// copy a plant state (same model)
static void copy_state(const vd_model* m, const vd_data* src, vd_data* dst) {
  memcpy(dst->node_pos, src->node_pos, sizeof(double) * 3 * (size_t)m->nnode);
  memcpy(dst->seg_quat, src->seg_quat, sizeof(double) * 4 * (size_t)m->nseg);
  memcpy(dst->sphere_pos, src->sphere_pos, sizeof(double) * 3 * (size_t)m->nsphere);
  memcpy(dst->vert_pos, src->vert_pos, sizeof(double) * 3 * (size_t)m->nvert);
  memcpy(dst->seg_broken, src->seg_broken, sizeof(int) * (size_t)m->nseg);
  memcpy(dst->seg_cut, src->seg_cut, sizeof(double) * 7 * (size_t)m->nseg);
}

// ---------------------------------------------------------------------------------------------
// ffmpeg

// is there an executable named name on PATH?
static int on_path(const char* name) {
  const char* path = getenv("PATH");
  if (!path || !*path) return 0;
  char buf[4096];
  for (const char* p = path; *p;) {
    const char* e = strchr(p, ':');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    snprintf(buf, sizeof buf, "%.*s/%s", (int)n, n ? p : ".", name);
    if (access(buf, X_OK) == 0) return 1;
    p += n + (e ? 1 : 0);
  }
  return 0;
}

typedef struct video {
  pid_t pid;
  FILE* pipe;
  vd_outfile of;  // the video through the output layer: ffmpeg writes its temporary name
  int of_open;
} video;

// start ffmpeg reading w x h RGB frames at fps from a pipe into a temporary file beside path
static vd_status video_start(video* v, const char* path, int w, int h, double fps, vd_error* err) {
  vd_status st = vd_outfile_open(&v->of, path, err);
  if (st) return st;
  v->of_open = 1;
  int fd[2];
  if (pipe(fd) != 0)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot make a pipe: %s", strerror(errno));
  char size[64], rate[64];
  snprintf(size, sizeof size, "%dx%d", w, h);
  snprintf(rate, sizeof rate, "%.6g", fps);
  // H.264 needs even sizes: pad by a pixel where the image is odd
  char* argv[] = {"ffmpeg",
                  "-hide_banner",
                  "-loglevel",
                  "error",
                  "-nostdin",
                  "-y",
                  "-f",
                  "rawvideo",
                  "-pix_fmt",
                  "rgb24",
                  "-s",
                  size,
                  "-framerate",
                  rate,
                  "-i",
                  "pipe:0",
                  "-an",
                  "-vf",
                  "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                  "-c:v",
                  "libx264",
                  "-pix_fmt",
                  "yuv420p",
                  "-movflags",
                  "+faststart",
                  "-f",
                  "mp4",
                  v->of.tmp,
                  NULL};
  // -nostdin only stops ffmpeg reading keys from the terminal; the frames come through pipe:0
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fd[0], 0);
  posix_spawn_file_actions_addclose(&fa, fd[1]);
  int rc = posix_spawnp(&v->pid, "ffmpeg", &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fd[0]);
  if (rc != 0) {
    close(fd[1]);
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot start ffmpeg: %s", strerror(rc));
  }
  v->pipe = fdopen(fd[1], "wb");
  if (!v->pipe) {
    close(fd[1]);
    waitpid(v->pid, NULL, 0);
    v->pid = 0;
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot open the pipe to ffmpeg");
  }
  return VD_OK;
}

// close the pipe, wait for ffmpeg; on success (ok) hand the video to the output layer, else
// remove it
static vd_status video_finish(video* v, const char* path, int ok, vd_error* err) {
  if (!v->pid) {
    if (v->of_open) vd_outfile_abort(&v->of);
    v->of_open = 0;
    return VD_OK;
  }
  int bad = v->pipe ? fclose(v->pipe) != 0 : 0;
  v->pipe = NULL;
  int status = 0;
  while (waitpid(v->pid, &status, 0) < 0 && errno == EINTR) {
  }
  v->pid = 0;
  vd_status st = VD_OK;
  if (ok && (bad || !WIFEXITED(status) || WEXITSTATUS(status) != 0))
    st = vd_error_set(err, VD_ERR_IO, path, 0, 0, "ffmpeg failed (%s %d)",
                      WIFEXITED(status) ? "exit status" : "signal",
                      WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
  if (ok && !st) st = vd_outfile_commit(&v->of, err);
  else vd_outfile_abort(&v->of);
  v->of_open = 0;
  return st;
}

// ---------------------------------------------------------------------------------------------
// the index of a folder of frames

static vd_status write_index(const cli_render_opts* o, const cli_run* run, const char* dir,
                             const vd_frame* f, vd_error* err) {
  cJSON* root = cJSON_CreateObject();
  if (!root) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  static const char* by[4] = {"label", "instance", "stress", "displacement"};
  cJSON_AddStringToObject(root, "format", "verdant-render-run");
  cJSON_AddNumberToObject(root, "version", 1);
  cJSON_AddStringToObject(root, "run", run->dir);
  cJSON_AddNumberToObject(root, "width", f->width);
  cJSON_AddNumberToObject(root, "height", f->height);
  cJSON_AddStringToObject(root, "color_by", by[o->style.color_by]);
  if (o->style.color_by == VD_COLOR_STRESS || o->style.color_by == VD_COLOR_DISPLACEMENT) {
    double range[2] = {f->range_min, f->range_max};
    cJSON_AddItemToObject(root, "range", cJSON_CreateDoubleArray(range, 2));
    cJSON_AddStringToObject(root, "unit", o->style.color_by == VD_COLOR_STRESS ? "Pa" : "m");
  }
  cJSON* frames = cJSON_AddArrayToObject(root, "frames");
  for (int k = 0; k < run->nframe; k++) {
    cJSON* e = cJSON_CreateObject();
    char name[64];
    cJSON_AddNumberToObject(e, "index", k);
    cJSON_AddNumberToObject(e, "time", vd_sim_frames_time(run->frames, k));
    snprintf(name, sizeof name, "frame_%05d.png", k);
    cJSON_AddStringToObject(e, "color", name);
    if (o->depth)
      snprintf(name, sizeof name, "frame_%05d.depth.png", k),
          cJSON_AddStringToObject(e, "depth", name);
    if (o->masks) {
      snprintf(name, sizeof name, "frame_%05d.label.png", k);
      cJSON_AddStringToObject(e, "label", name);
      snprintf(name, sizeof name, "frame_%05d.instance.png", k);
      cJSON_AddStringToObject(e, "instance", name);
    }
    if (o->depth || o->masks)
      snprintf(name, sizeof name, "frame_%05d.png.json", k), cJSON_AddStringToObject(e, "camera", name);
    cJSON_AddItemToArray(frames, e);
  }
  char* text = cJSON_Print(root);
  cJSON_Delete(root);
  if (!text) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  char path[4200];
  snprintf(path, sizeof path, "%s/frames.json", dir);
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

// ---------------------------------------------------------------------------------------------
// the command

// the colliders of a frame as solids (planes are the floor's business, meshes are not drawn)
static vd_status add_colliders(vd_renderer* r, const vd_sim_collider* col, int ncol,
                               vd_error* err) {
  vd_status st = VD_OK;
  for (int c = 0; c < ncol && !st; c++) {
    const vd_sim_collider* k = &col[c];
    // a mesh collider's distance grid is not in the run (and its size is 0): not drawn
    if (k->shape == VD_SIM_PLANE || k->shape == VD_SIM_MESH) continue;
    vd_render_shape s = {k->shape == VD_SIM_SPHERE    ? VD_RENDER_SPHERE
                         : k->shape == VD_SIM_CAPSULE ? VD_RENDER_CAPSULE
                                                      : VD_RENDER_BOX,
                         {k->size[0], k->size[1], k->size[2]},
                         k->pos,
                         k->quat,
                         {0.55f, 0.62f, 0.75f}};
    st = vd_render_add_shape(r, &s, err);
  }
  return st;
}

// -o names a folder for every frame: DIR/, an existing folder or a name without an extension
// (g.jpg is a mistyped picture, not a folder to fill with frames)
static int folder_name(const char* out) {
  size_t n = strlen(out);
  struct stat sb;
  if ((n && out[n - 1] == '/') || (!stat(out, &sb) && S_ISDIR(sb.st_mode))) return 1;
  const char* base = strrchr(out, '/');
  return strchr(base ? base + 1 : out, '.') == NULL;
}

int cli_render_run(const cli_render_opts* o) {
  const char* cmd = "render";
  // what to write
  int single = o->out && cli_has_ext(o->out, ".png");
  const char* folder = o->out && !single ? o->out : NULL;
  if (!o->out && !o->mp4)
    return cli_usage_error(cmd, "missing -o OUT.png, -o DIR/ or --mp4 OUT.mp4 for the run");
  if (folder && !folder_name(folder))
    return cli_usage_error(cmd,
                           "-o %s: a run is drawn as PNG: -o OUT.png for one frame, -o DIR/ (a folder) for "
                           "every frame",
                           folder);
  if (o->has_time && !single) return cli_usage_error(cmd, "--time picks the frame of -o OUT.png");
  if (o->po.steps >= 0 || o->po.seed || o->po.nset || o->po.nlabel)
    return cli_usage_error(
        cmd, "-n, --seed, --set and --label apply to .lpy plants; a run holds its plant");
  {
    // the files: the run's files and the robot read; one picture (and its layers), or a folder
    // of frames (an earlier render's frames there that this one does not draw go), the video
    static const char* const frame_files[] = {"frames.json", "frame_*.png", "frame_*.png.json"};
    cli_out_input("RUN", o->po.path);
    for (int k = 0; k < cli_run_nmember; k++) {
      char p[4200];
      snprintf(p, sizeof p, "%s/%s", o->po.path, cli_run_members[k]);
      if (!strchr(p, '*')) cli_out_input("RUN", p);
    }
    cli_out_input("--robot", o->def.robot_mjcf);
    if (single) {
      char opath[5][4200];
      int nout = cli_frame_files(o->out, o->depth, o->masks, opath);
      for (int k = 0; k < nout; k++) cli_out_file("-o", opath[k]);
    }
    if (folder) cli_out_folder("-o", folder, frame_files, 3, 1);
    cli_out_file("--mp4", o->mp4);
    if (cli_out_check(cmd)) return EXIT_USAGE;
  }
  const char* mp4 = o->mp4;
  if (mp4 && !on_path("ffmpeg")) {
    fprintf(stderr,
            "verdant render: --mp4 %s skipped: ffmpeg is not installed (Debian: apt-get install "
            "ffmpeg)\n",
            mp4);
    if (!o->out) return EXIT_FAIL;
    mp4 = NULL;
  }
  vd_error err = {0};
  vd_status st;
  int code = EXIT_OK;
  cli_run run;
  vd_renderer* r = NULL;
  vd_data* ref = NULL;
  double* stress = NULL;
  video vid;
  memset(&vid, 0, sizeof vid);
  int progress = o->po.progress;
  int writing = 0; // the failure, if any, is in writing the outputs
  if ((st = cli_run_open(o->po.path, &run, &err))) return cli_report(cmd, &err, st);
  const vd_model* pm = run.plant;
  if (o->has_time) {
    // --time picks a frame of the run: a time outside it is a mistake, not the nearest end
    double t0 = vd_sim_frames_time(run.frames, 0), t1 = vd_sim_frames_time(run.frames, run.nframe - 1);
    double tol = run.nframe > 1 ? (t1 - t0) / (run.nframe - 1) : 0;  // half a frame either side
    if (!(o->time >= t0 - 0.5 * tol - 1e-9 && o->time <= t1 + 0.5 * tol + 1e-9)) {
      cli_run_close(&run);
      return cli_usage_error(cmd, "--time %g: the run %s has frames from %g to %g s", o->time, o->po.path, t0, t1);
    }
  }
  int want = o->has_time ? vd_sim_frames_nearest(run.frames, o->time) : run.nframe - 1;
  int all = folder || mp4;
  // first pass: the box swept by the plant and the colliders; the colour scale of the whole run
  vd_render_style style = o->style;
  int value = style.color_by == VD_COLOR_STRESS || style.color_by == VD_COLOR_DISPLACEMENT;
  ref = vd_data_create(pm);
  stress = vd_malloc(sizeof(double) * (size_t)(pm->nseg ? pm->nseg : 1));
  if (!ref || !stress) {
    st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    goto fail;
  }
  box bx = {vd_v3(0, 0, 0), vd_v3(0, 0, 0), 0, o->def.floor};
  // displacement from the plant as modelled (its rest shape: a settled run shows its sag), or
  // from the first frame (--displacement-from first: the motion of the timed run only)
  style.ref = o->disp_from_first ? ref : NULL;
  style.seg_stress = stress;
  double vmax = 0;
  for (int k = 0; k < run.nframe; k++) {
    if ((st = cli_run_load(&run, k, &err))) goto fail;
    if (k == 0) copy_state(pm, run.pstate, ref);
    const vd_sim_collider* col;
    int ncol = cli_run_colliders(&run, k, &col);
    box_frame(&bx, pm, run.pstate, col, ncol);
    // the scale of the plant still attached in this frame (a fallen fruit lies beyond it)
    if (value) {
      double lo, hi;
      if (style.color_by == VD_COLOR_STRESS) vd_sim_plant_stress(run.sim, run.state, pm, stress);
      if ((st = vd_render_value_range(pm, run.pstate, &style, &lo, &hi, &err))) goto fail;
      vmax = fmax(vmax, hi);
    }
  }
  if (value && !(style.range_max > style.range_min) && vmax > 0)
    style.range_min = 0, style.range_max = vmax;
  // the renderer, with room for every organ instance and collider
  vd_render_def def = o->def;
  if (pm->ninstance + VD_SIM_MAX_COLLIDERS + 16 > def.max_geoms)
    def.max_geoms = pm->ninstance + VD_SIM_MAX_COLLIDERS + 16;
  if ((st = vd_render_create(&def, &r, &err))) {
    code = st == VD_ERR_UNSUPPORTED || st == VD_ERR_NOMEM ? EXIT_FAIL : cli_exit_code(st);
    cli_report(cmd, &err, st);
    goto done;
  }
  if (o->info) fprintf(stderr, "verdant render: %s\n", vd_render_info(r));
  if ((st = cli_apply_look(o, r, &err))) goto fail;
  // the camera: fitted to the run's box and what the renderer holds (a robot)
  vd_camera cam;
  {
    if ((st = cli_run_load(&run, 0, &err)) ||
        (st = vd_render_add_plant(r, pm, run.pstate, &style, &err)))
      goto fail;
    vd_vec3 lo, hi;
    vd_render_bounds(r, &lo, &hi);
    if (bx.any) lo = vd_vmin(lo, bx.lo), hi = vd_vmax(hi, bx.hi);
    cam = cli_render_camera(o, lo, hi);
  }
  writing = 1;
  if (folder && (st = vd_outdir_make(folder, &err))) goto fail;
  // frames: one, or every one into the folder and the video
  unsigned layers = VD_LAYER_COLOR | (o->depth ? VD_LAYER_DEPTH : 0) |
                    (o->masks ? VD_LAYER_LABEL | VD_LAYER_INSTANCE : 0);
  if (mp4) {
    double fps = o->fps;
    if (!(fps > 0)) {
      double span =
          vd_sim_frames_time(run.frames, run.nframe - 1) - vd_sim_frames_time(run.frames, 0);
      fps = run.nframe > 1 && span > 0 ? (run.nframe - 1) / span : 30;
    }
    signal(SIGPIPE, SIG_IGN); // a failing ffmpeg shows as a write error, not a dead verdant
    if ((st = video_start(&vid, mp4, def.width, def.height, fps, &err))) goto fail;
  }
  vd_frame f;
  memset(&f, 0, sizeof f);
  int k0 = all ? 0 : want, k1 = all ? run.nframe : want + 1;
  for (int k = k0; k < k1; k++) {
    if (progress) fprintf(stderr, "\rrendering frame %d / %d", k + 1, run.nframe), fflush(stderr);
    writing = 0;
    if ((st = cli_run_load(&run, k, &err))) goto fail;
    if (style.color_by == VD_COLOR_STRESS) vd_sim_plant_stress(run.sim, run.state, pm, stress);
    const vd_sim_collider* col;
    int ncol = cli_run_colliders(&run, k, &col);
    vd_render_clear(r);
    if ((st = vd_render_add_plant(r, pm, run.pstate, &style, &err))) goto fail;
    if ((st = add_colliders(r, col, ncol, &err))) goto fail;
    if ((st = vd_render_draw(r, &cam, layers, &f, &err))) goto fail;
    writing = 1;
    if (folder) {
      char path[4200];
      snprintf(path, sizeof path, "%s/frame_%05d.png", folder, k);
      if ((st = cli_frame_write(&f, path, o->depth, o->masks, &err))) goto fail;
    }
    if (single && k == want && (st = cli_frame_write(&f, o->out, o->depth, o->masks, &err)))
      goto fail;
    if (vid.pipe &&
        fwrite(f.rgb, 3, (size_t)f.width * f.height, vid.pipe) != (size_t)f.width * f.height) {
      st = vd_error_set(&err, VD_ERR_IO, mp4, 0, 0, "ffmpeg stopped reading frames");
      goto fail;
    }
  }
  if (progress) cli_progress_clear();
  if (folder && (st = write_index(o, &run, folder, &f, &err))) goto fail;
  if (mp4 && (st = video_finish(&vid, mp4, 1, &err))) goto fail;
  goto done;
fail:
  if (progress) cli_progress_clear();
  // bad run files are bad input (2); a failure to write or to encode is a failed run (1)
  code = cli_report(cmd, &err, st);
  if (writing) code = EXIT_FAIL;
done:
  if (vid.pid) video_finish(&vid, mp4, 0, NULL);
  vd_render_destroy(r);
  vd_free(stress, sizeof(double) * (size_t)(pm->nseg ? pm->nseg : 1));
  vd_data_destroy(ref);
  cli_run_close(&run);
  return code;
}
