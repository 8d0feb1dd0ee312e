// SPDX-License-Identifier: MIT
// The renderer's lifetime: defaults, the OpenGL context, the stage model (floor, sky) written as
// MJCF into MuJoCo's in-memory file system or a robot's MJCF, MuJoCo's scene and context, image
// buffers.
#define _DEFAULT_SOURCE
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "render_internal.h"

vd_render_def vd_render_def_default(void) {
  vd_render_def d;
  memset(&d, 0, sizeof d);
  d.width = 640;
  d.height = 480;
  d.supersample = 2;
  d.shadows = 1;
  d.floor = 1;
  d.sky = 1;
  d.background[0] = d.background[1] = d.background[2] = 1.0f;
  d.light_azimuth = -2.0;
  d.light_elevation = 1.0;
  d.light = 0.6;
  d.headlight = 0.35;
  d.ambient = 0.3;
  d.legend = 1;
  d.max_geoms = 20000;
  d.robot_mjcf = NULL;
  return d;
}

vd_render_style vd_render_style_default(void) {
  vd_render_style s;
  memset(&s, 0, sizeof s);
  s.color_by = VD_COLOR_LABEL;
  return s;
}

// is x a finite number in [lo, hi]?
static int in_range(double x, double lo, double hi) {
  return isfinite(x) && x >= lo && x <= hi;
}

// the first light setting out of range (its name and range), NULL when all are fine
static const char* check_lights(double az, double el, double light, double head, double amb) {
  if (!in_range(az, -1e3, 1e3)) return "light_azimuth (finite, rad)";
  if (!in_range(el, 1e-3, VD_PI / 2 + 1e-9)) return "light_elevation (0..pi/2 rad)";
  if (!in_range(light, 0, 1)) return "light (0..1)";
  if (!in_range(head, 0, 1)) return "headlight (0..1)";
  if (!in_range(amb, 0, 1)) return "ambient (0..1)";
  return NULL;
}

// check the settings, naming the first bad field
static vd_status check_def(const vd_render_def* d, vd_error* err) {
  const char* bad = NULL;
  if (d->width < 1 || d->width > 8192)
    bad = "width (1..8192 pixels)";
  else if (d->height < 1 || d->height > 8192)
    bad = "height (1..8192 pixels)";
  else if (d->supersample < 1 || d->supersample > 4)
    bad = "supersample (1..4)";
  else if ((long)d->width * d->supersample > 16384 || (long)d->height * d->supersample > 16384)
    bad = "width or height x supersample (at most 16384 pixels)";
  else if (d->max_geoms < 1 || d->max_geoms > 10000000)
    bad = "max_geoms (1..10000000)";
  if (!bad) bad = check_lights(d->light_azimuth, d->light_elevation, d->light, d->headlight, d->ambient);
  for (int k = 0; !bad && k < 3; k++)
    if (!in_range(d->background[k], 0, 1)) bad = "background (each in 0..1)";
  if (bad) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bad render setting: %s", bad);
  return VD_OK;
}

// the stage's colours as made: sky zenith and horizon, floor checker
static const float sky_rgb[2][3] = {{0.92f, 0.95f, 1.0f}, {0.55f, 0.68f, 0.85f}};
static const float floor_rgb[2][3] = {{0.62f, 0.57f, 0.50f}, {0.55f, 0.50f, 0.43f}};

// the stage: a floor plane and a sky, as MJCF text (lights are set per frame)
static int stage_xml(const vd_render_def* d, char* buf, size_t cap) {
  const float* bg = d->background;
  const float* s0 = d->sky ? sky_rgb[0] : bg;
  const float* s1 = d->sky ? sky_rgb[1] : bg;
  return snprintf(
      buf, cap,
      "<mujoco model=\"verdant_stage\">\n"
      "  <visual>\n"
      "    <global offwidth=\"%d\" offheight=\"%d\"/>\n"
      "    <quality shadowsize=\"2048\" offsamples=\"0\"/>\n"
      "  </visual>\n"
      "  <asset>\n"
      "    <texture name=\"sky\" type=\"skybox\" builtin=\"gradient\" rgb1=\"%g %g %g\" rgb2=\"%g "
      "%g %g\" "
      "width=\"256\" height=\"1536\"/>\n"
      "    <texture name=\"ground\" type=\"2d\" builtin=\"checker\" rgb1=\"%g %g %g\" "
      "rgb2=\"%g %g %g\" width=\"256\" height=\"256\"/>\n"
      "    <material name=\"ground\" texture=\"ground\" texrepeat=\"2 2\" texuniform=\"true\"/>\n"
      "  </asset>\n"
      "  <worldbody>\n"
      "%s"
      "  </worldbody>\n"
      "</mujoco>\n",
      d->width * d->supersample, d->height * d->supersample, s0[0], s0[1], s0[2], s1[0], s1[1],
      s1[2], floor_rgb[0][0], floor_rgb[0][1], floor_rgb[0][2], floor_rgb[1][0], floor_rgb[1][1],
      floor_rgb[1][2],
      d->floor ? "    <geom name=\"floor\" type=\"plane\" size=\"30 30 3\" material=\"ground\"/>\n"
               : "");
}

// load the stage from memory, or the robot from its file; NULL with *st and err set on failure
static mjModel* load_model(vd_renderer* r, vd_status* st, vd_error* err) {
  char msg[1000] = "";
  mjModel* m = NULL;
  if (r->def.robot_mjcf) {
    *st = vd_mj_load_xml(r->robot_path, "robot MJCF", &m, err);
    return m;
  }
  char xml[4096];
  int len = stage_xml(&r->def, xml, sizeof xml);
  r->vfs = vd_malloc(sizeof *r->vfs);
  if (!r->vfs) {
    *st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    return NULL;
  }
  mj_defaultVFS(r->vfs);
  if (mj_makeEmptyFileVFS(r->vfs, "stage.xml", len) != 0) {
    mj_deleteVFS(r->vfs);
    *st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "MuJoCo's file system refused the stage");
    return NULL;
  }
  int i = mj_findFileVFS(r->vfs, "stage.xml");
  memcpy(r->vfs->filedata[i], xml, (size_t)len);
  m = mj_loadXML("stage.xml", r->vfs, msg, sizeof msg);
  if (!m) *st = vd_error_set(err, VD_ERR_FORMAT, "", 0, 0, "stage model: %s", msg);
  // the file system is needed for loading only
  mj_deleteVFS(r->vfs);
  vd_free(r->vfs, sizeof *r->vfs);
  r->vfs = NULL;
  return m;
}

// MuJoCo part of create, under the error guard
static vd_status make_mujoco(vd_renderer* r, vd_error* err) {
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap))
    return vd_error_set(err, VD_ERR_FORMAT, r->def.robot_mjcf ? r->robot_path : "", 0, 0,
                        "MuJoCo: %s", trap.error);
  vd_status st = VD_OK;
  r->m = load_model(r, &st, err);
  if (r->m) {
    // offscreen buffer for the supersampled colour pass; no multisampling (exact id pass)
    r->m->vis.global.offwidth = r->def.width * r->def.supersample;
    r->m->vis.global.offheight = r->def.height * r->def.supersample;
    r->m->vis.quality.offsamples = 0;
    r->m->vis.quality.shadowsize = 2048;
    r->d = mj_makeData(r->m);
    // the look as made; the stage's textures kept for recolouring (vd_render_set_look)
    r->look.light_azimuth = r->def.light_azimuth, r->look.light_elevation = r->def.light_elevation;
    r->look.light = r->def.light, r->look.headlight = r->def.headlight;
    r->look.ambient = r->def.ambient;
    for (int k = 0; k < 3; k++) {
      r->look.sky[0][k] = r->def.sky ? sky_rgb[0][k] : r->def.background[k];
      r->look.sky[1][k] = r->def.sky ? sky_rgb[1][k] : r->def.background[k];
      r->look.floor[0][k] = floor_rgb[0][k], r->look.floor[1][k] = floor_rgb[1][k];
    }
    r->tex_sky = r->tex_floor = -1;
    if (!r->def.robot_mjcf) {
      r->tex_sky = mj_name2id(r->m, mjOBJ_TEXTURE, "sky");
      r->tex_floor = mj_name2id(r->m, mjOBJ_TEXTURE, "ground");
      r->tex0 = vd_malloc((size_t)r->m->ntexdata + 1);
      if (!r->tex0) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      else memcpy(r->tex0, r->m->tex_rgb, (size_t)r->m->ntexdata);
    }
    mj_forward(r->m, r->d);
    mjv_defaultOption(&r->opt);
    mjv_defaultPerturb(&r->pert);
    mjv_defaultCamera(&r->mjcam);
    mjv_defaultScene(&r->scn);
    mjv_makeScene(r->m, &r->scn, r->m->ngeom + 16 + r->def.max_geoms);
    mjr_defaultContext(&r->con);
    int k = r->def.supersample;
    mjr_makeContext(r->m, &r->con,
                    k >= 3   ? mjFONTSCALE_300
                    : k == 2 ? mjFONTSCALE_200
                             : mjFONTSCALE_100);
    r->have_mj = 1;
    mjr_setBuffer(mjFB_OFFSCREEN, &r->con);
    if (r->con.currentBuffer != mjFB_OFFSCREEN)
      st = vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: MuJoCo has no offscreen buffer");
    else
      render_measure_font(r);
  }
  vd_mj_trap_end(&trap);
  return st;
}

vd_status vd_render_create(const vd_render_def* def, vd_renderer** out, vd_error* err) {
  *out = NULL;
  vd_render_def d = def ? *def : vd_render_def_default();
  vd_status st = check_def(&d, err);
  if (st) return st;
  if (d.robot_mjcf && strlen(d.robot_mjcf) >= 4096)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "robot MJCF path too long");
  vd_renderer* r = vd_calloc(1, sizeof *r);
  if (!r) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  r->def = d;
  if (d.robot_mjcf) {
    snprintf(r->robot_path, sizeof r->robot_path, "%s", d.robot_mjcf);
    r->def.robot_mjcf = r->robot_path;
  }
  vd_mj_trap_install();
  // the context first: without one nothing else can be made
  st = gl_create(&r->gl, err);
  r->have_gl = r->gl.api != NULL;
  if (!st) st = make_mujoco(r, err);
  // image buffers
  if (!st) {
    size_t n = (size_t)d.width * (size_t)d.height,
           k2 = (size_t)d.supersample * (size_t)d.supersample;
    r->big = vd_malloc(3 * n * k2);
    r->rgb = vd_malloc(3 * n);
    r->ids = vd_malloc(3 * n);
    r->zbuf = vd_malloc(n * sizeof(float));
    r->depth = vd_malloc(n * sizeof(double));
    r->label = vd_malloc(n * sizeof(uint16_t));
    r->instance = vd_malloc(n * sizeof(uint16_t));
    if (!r->big || !r->rgb || !r->ids || !r->zbuf || !r->depth || !r->label || !r->instance)
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  if (st) {
    vd_render_destroy(r);
    return st;
  }
  *out = r;
  return VD_OK;
}

void vd_render_release(vd_renderer* r) {
  if (r && r->have_gl && r->gl.ctx) gl_release(&r->gl);
}

void vd_render_destroy(vd_renderer* r) {
  if (!r) return;
  vd_error ignore;
  if (r->have_gl && r->gl.ctx) gl_current(&r->gl, &ignore);
  render_items_free(r);
  vd_free(r->items, sizeof(item) * (size_t)r->cap_item);
  vd_free(r->clouds, sizeof(cloud) * (size_t)r->cap_cloud);
  vd_free(r->legend, sizeof(vd_legend_entry) * (size_t)r->cap_legend);
  if (r->have_mj) {
    mjr_freeContext(&r->con);
    mjv_freeScene(&r->scn);
  }
  if (r->d) mj_deleteData(r->d);
  if (r->m) vd_free(r->tex0, (size_t)r->m->ntexdata + 1);
  if (r->m) mj_deleteModel(r->m);
  if (r->vfs) mj_deleteVFS(r->vfs);
  vd_free(r->vfs, sizeof *r->vfs);
  if (r->have_gl) gl_destroy(&r->gl);
  size_t n = (size_t)r->def.width * (size_t)r->def.height;
  size_t k2 = (size_t)r->def.supersample * (size_t)r->def.supersample;
  vd_free(r->big, 3 * n * k2);
  vd_free(r->rgb, 3 * n);
  vd_free(r->ids, 3 * n);
  vd_free(r->zbuf, n * sizeof(float));
  vd_free(r->depth, n * sizeof(double));
  vd_free(r->label, n * sizeof(uint16_t));
  vd_free(r->instance, n * sizeof(uint16_t));
  vd_free(r, sizeof *r);
}

const char* vd_render_info(const vd_renderer* r) {
  return r->gl.info;
}

vd_render_look vd_render_get_look(const vd_renderer* r) {
  return r->look;
}

// recolour texture id from the colours it was made with (a0 -> a1 texel by texel, each texel's
// place between them kept) to b0 -> b1, and upload it
static void recolour(vd_renderer* r, int id, const float a[2][3], const float b[2][3]) {
  if (id < 0) return;
  const mjModel* m = r->m;
  size_t n = (size_t)m->tex_width[id] * (size_t)m->tex_height[id], adr = (size_t)m->tex_adr[id];
  int same = 1;
  for (int k = 0; k < 6; k++)
    same &= a[k / 3][k % 3] == b[k / 3][k % 3];
  if (same) { // back to the colours it was made with: the texels as made
    memcpy(m->tex_rgb + adr, r->tex0 + adr, 3 * n);
    mjr_uploadTexture(m, &r->con, id);
    return;
  }
  double d[3], dd = 0;
  for (int k = 0; k < 3; k++)
    d[k] = 255.0 * (a[1][k] - a[0][k]), dd += d[k] * d[k];
  for (size_t i = 0; i < n; i++) {
    const uint8_t* src = r->tex0 + adr + 3 * i;
    double t = 0;
    for (int k = 0; dd > 1e-9 && k < 3; k++)
      t += (src[k] - 255.0 * a[0][k]) * d[k] / dd;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    for (int k = 0; k < 3; k++) {
      double v = 255.0 * (b[0][k] + t * (b[1][k] - b[0][k]));
      m->tex_rgb[adr + 3 * i + k] = (mjtByte)(v < 0 ? 0 : v > 255 ? 255 : floor(v + 0.5));
    }
  }
  mjr_uploadTexture(m, &r->con, id);
}

vd_status vd_render_set_look(vd_renderer* r, const vd_render_look* look, vd_error* err) {
  const char* bad = check_lights(look->light_azimuth, look->light_elevation, look->light,
                                 look->headlight, look->ambient);
  for (int j = 0; !bad && j < 2; j++)
    for (int k = 0; k < 3; k++) {
      if (!in_range(look->sky[j][k], 0, 1)) bad = "sky colour (each in 0..1)";
      if (!in_range(look->floor[j][k], 0, 1)) bad = "floor colour (each in 0..1)";
    }
  if (bad) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bad look: %s", bad);
  vd_render_look want = *look;
  if (!r->def.sky) memcpy(want.sky[1], want.sky[0], sizeof want.sky[0]);
  int sky = 0, floor_changed = 0;
  for (int j = 0; j < 2; j++)
    for (int k = 0; k < 3; k++) {
      sky |= want.sky[j][k] != r->look.sky[j][k];
      floor_changed |= want.floor[j][k] != r->look.floor[j][k];
    }
  if (r->tex0 && (sky || floor_changed)) {
    vd_status st = gl_current(&r->gl, err);
    if (st) return st;
    vd_mj_trap trap;
    if (!VD_MJ_TRY(&trap)) return vd_mj_trap_status(&trap, err);
    // the stage as made: recolour from its own colours
    float s0[2][3], f0[2][3];
    for (int k = 0; k < 3; k++) {
      s0[0][k] = r->def.sky ? sky_rgb[0][k] : r->def.background[k];
      s0[1][k] = r->def.sky ? sky_rgb[1][k] : r->def.background[k];
      f0[0][k] = floor_rgb[0][k], f0[1][k] = floor_rgb[1][k];
    }
    if (sky) recolour(r, r->tex_sky, (const float(*)[3])s0, (const float(*)[3])want.sky);
    if (floor_changed) recolour(r, r->tex_floor, (const float(*)[3])f0, (const float(*)[3])want.floor);
    vd_mj_trap_end(&trap);
  }
  r->look = want;
  return VD_OK;
}

const vd_render_gl* vd_render_gl_info(const vd_renderer* r) {
  return &r->gl.id;
}

vd_status vd_render_set_robot_qpos(vd_renderer* r, const double* qpos, int nq, vd_error* err) {
  if (!r->def.robot_mjcf)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "the renderer has no robot");
  if (nq != r->m->nq)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "robot qpos has %d values, the model needs %d",
                        nq, r->m->nq);
  for (int i = 0; i < nq; i++)
    if (!isfinite(qpos[i]))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "robot qpos[%d] is not finite", i);
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap))
    return vd_error_set(err, VD_ERR_VALUE, r->robot_path, 0, 0, "MuJoCo: %s", trap.error);
  memcpy(r->d->qpos, qpos, sizeof(double) * (size_t)nq);
  mj_forward(r->m, r->d);
  vd_mj_trap_end(&trap);
  return VD_OK;
}

// is name a file MJCF models refer to (an include, a mesh, a texture)?
static int mjcf_part(const char* name) {
  static const char* ext[] = {".xml", ".stl", ".obj", ".msh", ".png", ".skn"};
  size_t n = strlen(name);
  for (size_t k = 0; k < sizeof ext / sizeof ext[0]; k++)
    if (n > 4 && !strcasecmp(name + n - 4, ext[k])) return 1;
  return 0;
}

// add the files of folder dir (and of its folders, one level down) that MJCF refers to
static void vfs_add_folder(mjVFS* vfs, const char* dir, int depth) {
  DIR* d = opendir(dir);
  if (!d) return;
  for (struct dirent* e; (e = readdir(d)) && vfs->nfile < mjMAXVFS - 8;) {
    if (e->d_name[0] == '.') continue;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    struct stat sb;
    if (stat(path, &sb) != 0) continue;
    if (S_ISDIR(sb.st_mode) && depth == 0) vfs_add_folder(vfs, path, 1);
    // 2.2.2 reads the file by the name given (the folder argument is not used for reading)
    if (S_ISREG(sb.st_mode) && mjcf_part(e->d_name)) mj_addFileVFS(vfs, NULL, path);
  }
  closedir(d);
}

// a scene including the files, in a VFS: their folders' files by name (MuJoCo 2.2.2 resolves
// every include, nested ones too, against the top file's folder; in a VFS, by file name), each
// part under a name of its own; NULL with *st set on failure
static mjVFS* scene_vfs(const char* const* files, int nfiles, vd_status* st, vd_error* err) {
  mjVFS* vfs = vd_malloc(sizeof *vfs);
  if (!vfs) {
    *st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    return NULL;
  }
  mj_defaultVFS(vfs);
  char scene[16384];
  size_t n = (size_t)snprintf(scene, sizeof scene, "<mujoco model=\"verdant_scene\">\n");
  for (int k = 0; k < nfiles && !*st; k++) {
    char dir[4200], part[64];
    FILE* f = fopen(files[k], "rb");
    if (!f) {
      *st = vd_error_set(err, VD_ERR_IO, files[k], 0, 0, "cannot open: %s", strerror(errno));
      break;
    }
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (len > 0 && fseek(f, 0, SEEK_SET) != 0) len = -1;
    snprintf(part, sizeof part, "verdant_part%d.xml", k);
    if (len <= 0 || mj_makeEmptyFileVFS(vfs, part, (int)len) != 0 ||
        fread(vfs->filedata[mj_findFileVFS(vfs, part)], 1, (size_t)len, f) != (size_t)len)
      *st = vd_error_set(err, VD_ERR_IO, files[k], 0, 0, "cannot read it");
    fclose(f);
    snprintf(dir, sizeof dir, "%s", files[k]);
    char* slash = strrchr(dir, '/');
    if (slash) *slash = 0;
    vfs_add_folder(vfs, slash ? dir : ".", 0);
    n += (size_t)snprintf(scene + n, n < sizeof scene ? sizeof scene - n : 0,
                          "  <include file=\"%s\"/>\n", part);
  }
  n += (size_t)snprintf(scene + n, n < sizeof scene ? sizeof scene - n : 0, "</mujoco>\n");
  if (!*st && (n >= sizeof scene || mj_makeEmptyFileVFS(vfs, "verdant_scene.xml", (int)n) != 0))
    *st = vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "too many files for one MuJoCo scene");
  if (!*st) memcpy(vfs->filedata[mj_findFileVFS(vfs, "verdant_scene.xml")], scene, n);
  if (*st) {
    mj_deleteVFS(vfs);
    vd_free(vfs, sizeof *vfs);
    return NULL;
  }
  return vfs;
}

vd_status vd_render_mjcf_info(const char* const* files, int nfiles, const char* prefix,
                              vd_mjcf_info* info, vd_error* err) {
  memset(info, 0, sizeof *info);
  if (nfiles < 1) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "no MJCF file");
  vd_mj_trap_install();
  vd_mj_trap trap;
  mjModel* volatile m = NULL;
  mjData* volatile d = NULL;
  mjVFS* volatile vfs = NULL;
  vd_status st = VD_OK;
  if (VD_MJ_TRY(&trap)) {
    mjModel* loaded = NULL;
    if (nfiles == 1) {
      st = vd_mj_load_xml(files[0], "MJCF", &loaded, err);
    } else {
      // several: a scene that includes them, in memory
      vfs = scene_vfs(files, nfiles, &st, err);
      char msg[1000] = "";
      if (vfs) loaded = mj_loadXML("verdant_scene.xml", vfs, msg, sizeof msg);
      if (vfs && !loaded) {
        for (char* c = msg; *c; c++)
          if (*c == '\n' || *c == '\r') *c = ' ';
        st = vd_error_set(err, VD_ERR_FORMAT, files[0], 0, 0, "MJCF scene of %d files: %s", nfiles,
                          msg);
      }
    }
    m = loaded;
    if (m) {      d = mj_makeData(m);
      mj_forward(m, d);
      info->nbody = m->nbody, info->ngeom = m->ngeom, info->nmesh = m->nmesh;
      info->njoint = m->njnt, info->ncontact = d->ncon;
      size_t np = prefix ? strlen(prefix) : 0;
      // bodies named with the prefix, their geoms, and their contacts with other moving parts
      for (int b = 1; b < m->nbody; b++) {
        const char* name = mj_id2name(m, mjOBJ_BODY, b);
        info->nbody_prefix += np && name && !strncmp(name, prefix, np);
      }
      for (int g = 0; g < m->ngeom; g++) {
        const char* name = mj_id2name(m, mjOBJ_BODY, m->geom_bodyid[g]);
        info->ngeom_prefix += np && name && !strncmp(name, prefix, np);
      }
      for (int c = 0; c < d->ncon; c++) {
        int b1 = m->geom_bodyid[d->contact[c].geom1], b2 = m->geom_bodyid[d->contact[c].geom2];
        const char* n1 = mj_id2name(m, mjOBJ_BODY, b1);
        const char* n2 = mj_id2name(m, mjOBJ_BODY, b2);
        int p1 = np && n1 && !strncmp(n1, prefix, np), p2 = np && n2 && !strncmp(n2, prefix, np);
        info->ncontact_prefix += (p1 && !p2 && b2 > 0) || (p2 && !p1 && b1 > 0);
      }
    }
    vd_mj_trap_end(&trap);
  } else {
    st = vd_mj_trap_status(&trap, err);
  }
  if (d) mj_deleteData(d);
  if (m) mj_deleteModel(m);
  if (vfs) {
    mj_deleteVFS(vfs);
    vd_free(vfs, sizeof *vfs);
  }
  return st;
}

