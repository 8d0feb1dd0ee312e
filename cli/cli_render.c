// SPDX-License-Identifier: MIT
// verdant render: a plant (.lpy or plant file), a point cloud (.ply .pcd .xyz .csv .las) or a
// simulation run folder → PNG colour image, with depth (16-bit, mm) and label/instance masks
// (16-bit ids) and a JSON sidecar on request; every frame of a run into a folder or an MP4.
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

static const char* render_help =
    "usage: verdant render PLANT|MESH|CLOUD -o OUT.png [options]\n"
    "       verdant render RUN/ -o OUT.png [--time T] | -o DIR/ | --mp4 OUT.mp4 [options]\n"
    "\n"
    "Draw a plant (an .lpy file, derived on the fly, or a plant .json), a labelled mesh (.obj,\n"
    "or a .ply with faces, as 'verdant grow' writes them), a point cloud (.ply, .pcd, .xyz, .csv\n"
    "or .las, with optional label and instance) or a simulation run (a folder written by\n"
    "'verdant sim -o RUN/') headless with MuJoCo's renderer (EGL; software rendering\n"
    "when there is no GPU) and write a colour PNG with a legend.\n"
    "\n"
    "options:\n"
    "  -o, --output OUT.png  colour image; the other files take its name: OUT.depth.png,\n"
    "                        OUT.label.png, OUT.instance.png, OUT.png.json\n"
    "      --camera VIEW     front | side | top | orbit[:AZ[:EL]] (degrees, orbit alone is\n"
    "                        orbit:-60:20), fitted to the plant; default orbit\n"
    "      --eye X,Y,Z       explicit camera position (m); with --lookat, replaces --camera\n"
    "      --lookat X,Y,Z    point the camera looks at (m)\n"
    "      --up X,Y,Z        image up direction (default 0,0,1)\n"
    "      --fov DEG         vertical field of view (degrees, default 45)\n"
    "      --size WxH        image size in pixels (default 640x480)\n"
    "      --color-by WHAT   label | instance | stress | displacement (default label); stress\n"
    "                        needs a simulation run, a plant at rest has zero displacement\n"
    "      --palette P       label colours: distinct (default: every label its own colour, organ-\n"
    "                        like where it can) or natural (the label table's organ colours, in\n"
    "                        which labels of one organ look alike)\n"
    "      --range MIN,MAX   colour scale of stress (Pa) or displacement (m); default: the values\n"
    "                        of the plant still attached (a fallen fruit or broken branch lies\n"
    "                        beyond the scale, in its end colour); for a run: 0 to the largest\n"
    "                        such value of the whole run\n"
    "      --depth           also write OUT.depth.png (16-bit grey, millimetres along the optical\n"
    "                        axis, 0 = nothing) and OUT.png.json (intrinsics, pose)\n"
    "      --masks           also write OUT.label.png and OUT.instance.png (16-bit ids, 0 =\n"
    "                        background, exact: no anti-aliasing) and OUT.png.json\n"
    "      --supersample K   colour anti-aliasing, K x K samples per pixel (1..4, default 2)\n"
    "      --point-size M    splat half-size of cloud points (m, default 0.4% of the cloud)\n"
    "      --robot FILE.xml  draw a robot from its MJCF (with its own world) beside the plant\n"
    "      --no-floor, --no-shadows, --no-legend, --no-sky   leave those out\n"
    "      --light AZ,EL[,KEY[,HEAD[,AMBIENT]]]\n"
    "                        key light from azimuth AZ and elevation EL (degrees; default\n"
    "                        -114.6,57.3), its intensity, the headlight's and the ambient light\n"
    "                        (0..1; default 0.6, 0.35, 0.3)\n"
    "      --sky-rgb R,G,B[,R,G,B]   sky colours, zenith then horizon (0..1; with --no-sky the\n"
    "                        flat background)\n"
    "      --floor-rgb R,G,B[,R,G,B] the floor's two checker colours (0..1)\n"
    "      --info            print the OpenGL context used on stderr\n"
    ;
static const char* render_help_run =
    "simulation runs (RUN/ holds rod.json, plant_initial.json, frames, colliders.jsonl):\n"
    "  -o OUT.png            one frame: the one nearest --time T (s), default the last\n"
    "  -o DIR/               every frame (a name ending in /, a folder or without extension):\n"
    "                        DIR/frame_00000.png ... (and their depth, masks and\n"
    "                        sidecars), DIR/frames.json (index: frame times and files)\n"
    "      --time T          simulated time of the frame to draw (s), nearest frame; within\n"
    "                        the run's time range\n"
    "      --mp4 OUT.mp4     every frame as an H.264 video (needs Debian's ffmpeg; skipped\n"
    "                        with a message when it is not installed)\n"
    "      --fps N           frame rate of the video (default: the run's, from its frame times)\n"
    "      --displacement-from model|first\n"
    "                        displacement from the plant as modelled (default: a settled run\n"
    "                        shows its sag) or from the run's first frame (the timed motion)\n"
    "  Stress is the largest bending stress of each segment, 4 |M| / (pi r^3), from its\n"
    "  curvature (grey where there is none: leaf blades, fruits). The camera and the colour\n"
    "  scale stay fixed over the whole run, and probes and other colliders are drawn (label\n"
    "  65535 in the masks, as robots).\n";

int cli_parse_palette(const char* s, vd_palette* out) {
  if (!strcmp(s, "distinct"))
    *out = VD_PALETTE_DISTINCT;
  else if (!strcmp(s, "natural"))
    *out = VD_PALETTE_NATURAL;
  else
    return 0;
  return 1;
}

int cli_parse_nums(const char* s, double* x, int n) {
  if (!s) return 0;
  for (int k = 0; k < n; k++) {
    char* end;
    errno = 0;
    x[k] = strtod(s, &end);
    if (end == s || errno || !isfinite(x[k])) return 0;
    s = end;
    if (k < n - 1) {
      if (*s != ',') return 0;
      s++;
    }
  }
  return *s == 0;
}

int cli_look_opt(cli_render_opts* o, const char* cmd, int argc, char** argv, int* i) {
  const char* a = argv[*i];
  const char* val = NULL;
  if (strcmp(a, "--light") != 0 && strcmp(a, "--sky-rgb") != 0 && strcmp(a, "--floor-rgb") != 0)
    return 0;
  CLI_TAKE();
  double x[6];
  if (!strcmp(a, "--light")) {
    // AZ,EL in degrees, then the key light, headlight and ambient intensities
    int n = 0;
    for (int k = 2; k <= 5 && !n; k++)
      if (cli_parse_nums(val, x, k)) n = k;
    int ok = n >= 2 && x[0] >= -360 && x[0] <= 360 && x[1] > 0 && x[1] <= 90;
    for (int k = 2; ok && k < n; k++)
      ok = x[k] >= 0 && x[k] <= 1;
    if (!ok) {
      cli_usage_error(cmd, "--light expects AZ,EL[,KEY[,HEAD[,AMBIENT]]]: degrees (elevation in "
                           "(0, 90]), intensities in [0, 1]; got '%s'", val);
      return -1;
    }
    o->def.light_azimuth = x[0] * VD_PI / 180, o->def.light_elevation = x[1] * VD_PI / 180;
    if (n > 2) o->def.light = x[2];
    if (n > 3) o->def.headlight = x[3];
    if (n > 4) o->def.ambient = x[4];
    return 1;
  }
  // two colours (or one for both)
  int n = cli_parse_nums(val, x, 6) ? 6 : cli_parse_nums(val, x, 3) ? 3 : 0;
  for (int k = 0; k < n; k++)
    if (x[k] < 0 || x[k] > 1) n = 0;
  if (!n) {
    cli_usage_error(cmd, "%s expects R,G,B[,R,G,B] in [0, 1], got '%s'", a, val);
    return -1;
  }
  float(*c)[3] = !strcmp(a, "--sky-rgb") ? o->sky : o->floor;
  for (int k = 0; k < 6; k++)
    c[k / 3][k % 3] = (float)x[n == 6 ? k : k % 3];
  if (c == o->sky)
    o->has_sky = 1;
  else
    o->has_floor = 1;
  return 1;
}

vd_status cli_apply_look(const cli_render_opts* o, vd_renderer* r, vd_error* err) {
  if (!o->has_sky && !o->has_floor) return VD_OK;
  vd_render_look look = vd_render_get_look(r);
  if (o->has_sky) memcpy(look.sky, o->sky, sizeof look.sky);
  if (o->has_floor) memcpy(look.floor, o->floor, sizeof look.floor);
  return vd_render_set_look(r, &look, err);
}

int cli_parse_vec3(const char* s, vd_vec3* v) {
  double x[3];
  if (!cli_parse_nums(s, x, 3)) return 0;
  *v = vd_v3(x[0], x[1], x[2]);
  return 1;
}

// a number, the whole text

// --camera VIEW
static int parse_camera(const char* s, vd_camera_kind* kind, double* az, double* el) {
  *az = -60, *el = 20;
  if (!strcmp(s, "front"))
    *kind = VD_CAMERA_FRONT;
  else if (!strcmp(s, "side"))
    *kind = VD_CAMERA_SIDE;
  else if (!strcmp(s, "top"))
    *kind = VD_CAMERA_TOP;
  else if (!strncmp(s, "orbit", 5) && (s[5] == 0 || s[5] == ':')) {
    *kind = VD_CAMERA_ORBIT;
    if (s[5] == ':') {
      char buf[64];
      snprintf(buf, sizeof buf, "%s", s + 6);
      char* colon = strchr(buf, ':');
      if (colon) *colon = 0;
      if (!cli_parse_num(buf, az)) return 0;
      if (colon && !cli_parse_num(colon + 1, el)) return 0;
      if (*el < -90 || *el > 90) return 0;
    }
  } else {
    return 0;
  }
  return 1;
}

// OUT.png → OUT.<what>.<ext>
static void sibling(const char* out, const char* what, char* buf, size_t cap) {
  size_t n = strlen(out);
  if (cli_has_ext(out, ".png")) n -= 4;
  snprintf(buf, cap, "%.*s.%s", (int)n, out, what);
}

// the file name of a path
static const char* base_name(const char* path) {
  const char* slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

// the whole command line, checked before any work
static int parse_args(int argc, char** argv, cli_render_opts* o) {
  const char* camera_text = "orbit";
  int has_lookat = 0;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    int r = cli_plant_opt(&o->po, "render", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    r = cli_look_opt(o, "render", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    // options with a value
    const char* val = NULL;
    static const char* with_value[] = {"-o",         "--output",      "--camera",     "--eye",
                                       "--lookat",   "--up",          "--fov",        "--size",
                                       "--color-by", "--supersample", "--point-size", "--robot",
                                       "--time",     "--mp4",         "--fps",        "--range",
                                       "--palette",  "--displacement-from"};
    for (size_t k = 0; k < sizeof with_value / sizeof with_value[0]; k++)
      if (!strcmp(a, with_value[k])) {
        if (i + 1 >= argc) return cli_usage_error("render", "%s needs a value", a);
        val = argv[++i];
      }
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      o->out = val;
    } else if (!strcmp(a, "--camera")) {
      camera_text = val;
    } else if (!strcmp(a, "--eye")) {
      if (!cli_parse_vec3(val, &o->eye))
        return cli_usage_error("render", "--eye expects X,Y,Z in metres, got '%s'", val);
      o->has_eye = 1;
    } else if (!strcmp(a, "--lookat")) {
      if (!cli_parse_vec3(val, &o->lookat))
        return cli_usage_error("render", "--lookat expects X,Y,Z in metres, got '%s'", val);
      has_lookat = 1;
    } else if (!strcmp(a, "--up")) {
      if (!cli_parse_vec3(val, &o->up))
        return cli_usage_error("render", "--up expects X,Y,Z, got '%s'", val);
    } else if (!strcmp(a, "--fov")) {
      if (!cli_parse_num(val, &o->fov) || o->fov <= 0 || o->fov >= 180)
        return cli_usage_error("render", "--fov expects degrees in (0, 180), got '%s'", val);
    } else if (!strcmp(a, "--size")) {
      int64_t w, h;
      if (!cli_parse_i64_pair(val, 'x', 1, 8192, &w, &h))
        return cli_usage_error("render", "--size expects WxH with 1..8192 pixels each, got '%s'",
                               val);
      o->def.width = (int)w, o->def.height = (int)h;
    } else if (!strcmp(a, "--color-by")) {
      if (!strcmp(val, "label"))
        o->style.color_by = VD_COLOR_LABEL;
      else if (!strcmp(val, "instance"))
        o->style.color_by = VD_COLOR_INSTANCE;
      else if (!strcmp(val, "stress"))
        o->style.color_by = VD_COLOR_STRESS;
      else if (!strcmp(val, "displacement"))
        o->style.color_by = VD_COLOR_DISPLACEMENT;
      else
        return cli_usage_error(
            "render", "--color-by expects label, instance, stress or displacement, got '%s'", val);
    } else if (!strcmp(a, "--displacement-from")) {
      if (strcmp(val, "model") != 0 && strcmp(val, "first") != 0)
        return cli_usage_error("render", "--displacement-from expects model or first, got '%s'",
                               val);
      o->disp_from_first = !strcmp(val, "first");
    } else if (!strcmp(a, "--palette")) {
      if (!cli_parse_palette(val, &o->style.palette))
        return cli_usage_error("render", "--palette expects distinct or natural, got '%s'", val);
    } else if (!strcmp(a, "--range")) {
      char* end;
      errno = 0;
      double lo = strtod(val, &end), hi = 0;
      int ok = end != val && *end == ',' && !errno && isfinite(lo);
      if (ok) ok = cli_parse_num(end + 1, &hi) && hi > lo;
      if (!ok)
        return cli_usage_error("render",
                               "--range expects MIN,MAX with MIN < MAX (Pa or m), got '%s'", val);
      o->style.range_min = lo, o->style.range_max = hi;
    } else if (!strcmp(a, "--supersample")) {
      double k;
      if (!cli_parse_num(val, &k) || k != floor(k) || k < 1 || k > 4)
        return cli_usage_error("render", "--supersample expects 1, 2, 3 or 4, got '%s'", val);
      o->def.supersample = (int)k;
    } else if (!strcmp(a, "--point-size")) {
      if (!cli_parse_num(val, &o->point_size) || o->point_size <= 0)
        return cli_usage_error("render", "--point-size expects a size > 0 in metres, got '%s'",
                               val);
    } else if (!strcmp(a, "--robot")) {
      o->def.robot_mjcf = val;
    } else if (!strcmp(a, "--time")) {
      if (!cli_parse_num(val, &o->time))
        return cli_usage_error("render", "--time expects a time in seconds, got '%s'", val);
      o->has_time = 1;
    } else if (!strcmp(a, "--mp4")) {
      if (!cli_has_ext(val, ".mp4"))
        return cli_usage_error("render", "--mp4 '%s' must end in .mp4", val);
      o->mp4 = val;
    } else if (!strcmp(a, "--fps")) {
      if (!cli_parse_num(val, &o->fps) || o->fps <= 0 || o->fps > 1000)
        return cli_usage_error("render", "--fps expects a frame rate in (0, 1000] (1/s), got '%s'",
                               val);
    } else if (!strcmp(a, "--depth")) {
      o->depth = 1;
    } else if (!strcmp(a, "--masks")) {
      o->masks = 1;
    } else if (!strcmp(a, "--no-floor")) {
      o->def.floor = 0;
    } else if (!strcmp(a, "--no-shadows")) {
      o->def.shadows = 0;
    } else if (!strcmp(a, "--no-legend")) {
      o->def.legend = 0;
    } else if (!strcmp(a, "--no-sky")) {
      o->def.sky = 0;
    } else if (!strcmp(a, "--info")) {
      o->info = 1;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error("render", "unknown option '%s'", a);
    } else if (!o->po.path) {
      o->po.path = a;
    } else {
      return cli_usage_error("render", "unexpected argument '%s'", a);
    }
  }
  if (!parse_camera(camera_text, &o->kind, &o->az, &o->el))
    return cli_usage_error(
        "render", "--camera expects front, side, top or orbit[:AZ[:EL]] (degrees), got '%s'",
        camera_text);
  if (o->has_eye != has_lookat) return cli_usage_error("render", "--eye and --lookat go together");
  return EXIT_OK;
}

vd_camera cli_render_camera(const cli_render_opts* o, vd_vec3 lo, vd_vec3 hi) {
  vd_camera cam;
  if (o->has_eye) {
    cam.eye = o->eye, cam.lookat = o->lookat, cam.up = o->up;
    cam.fovy = o->fov * VD_PI / 180;
    double dist = vd_norm(vd_sub(o->lookat, o->eye));
    cam.znear = fmax(1e-3, 0.01 * dist);
    cam.zfar = 100 * dist + 60;
    return cam;
  }
  cam = vd_camera_preset(o->kind, o->az * VD_PI / 180, o->el * VD_PI / 180, lo, hi, o->def.width,
                         o->def.height);
  if (o->fov != 45) {
    // keep the fitted view, narrow or widen the lens: move along the axis to keep the framing
    double d = vd_norm(vd_sub(cam.lookat, cam.eye)), f0 = tan(cam.fovy / 2),
           f1 = tan(o->fov * VD_PI / 360);
    vd_vec3 dir = vd_normalize(vd_sub(cam.eye, cam.lookat));
    cam.eye = vd_madd(cam.lookat, dir, d * f0 / f1);
    cam.fovy = o->fov * VD_PI / 180;
    cam.zfar += d * f0 / f1;
  }
  return cam;
}

int cli_frame_files(const char* out, int depth, int masks, char path[5][4200]) {
  int n = 0;
  snprintf(path[n++], 4200, "%s", out);
  if (depth) sibling(out, "depth.png", path[n++], 4200);
  if (masks) sibling(out, "label.png", path[n++], 4200), sibling(out, "instance.png", path[n++], 4200);
  if (depth || masks) snprintf(path[n++], 4200, "%s.json", out);
  return n;
}

vd_status cli_frame_write(const vd_frame* f, const char* out, int depth, int masks, vd_error* err) {
  char p_depth[4200], p_label[4200], p_inst[4200], p_json[4200];
  sibling(out, "depth.png", p_depth, sizeof p_depth);
  sibling(out, "label.png", p_label, sizeof p_label);
  sibling(out, "instance.png", p_inst, sizeof p_inst);
  snprintf(p_json, sizeof p_json, "%s.json", out);
  // colour, then depth and masks, then the sidecar naming them (the output layer puts them in
  // place together)
  vd_status st = vd_render_write_png(f, VD_LAYER_COLOR, out, err);
  if (!st && depth) st = vd_render_write_png(f, VD_LAYER_DEPTH, p_depth, err);
  if (!st && masks) st = vd_render_write_png(f, VD_LAYER_LABEL, p_label, err);
  if (!st && masks) st = vd_render_write_png(f, VD_LAYER_INSTANCE, p_inst, err);
  if (!st && (depth || masks)) {
    // the sidecar names its siblings by file name, so the folder can move
    const char* files[12];
    int nf = 0;
    files[nf++] = "color", files[nf++] = base_name(out);
    if (depth) files[nf++] = "depth", files[nf++] = base_name(p_depth);
    if (masks)
      files[nf++] = "label", files[nf++] = base_name(p_label), files[nf++] = "instance",
      files[nf++] = base_name(p_inst);
    files[nf] = NULL;
    st = vd_render_write_json(f, files, p_json, err);
  }
  return st;
}

int cli_render(int argc, char** argv) {
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
      fputs(render_help, stdout);
      fputs(render_help_run, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
  cli_render_opts o;
  memset(&o, 0, sizeof o);
  cli_plant_opts_init(&o.po);
  o.def = vd_render_def_default();
  o.style = vd_render_style_default();
  o.up = vd_v3(0, 0, 1);
  o.fov = 45;
  int rc = parse_args(argc, argv, &o);
  if (rc) return rc;
  if (!o.po.path)
    return cli_usage_error(
        "render", "missing PLANT, CLOUD or RUN/ (.lpy, plant .json, a .ply/.pcd/.xyz/.csv/.las "
                  "cloud, or a folder of 'verdant sim -o')");
  // a simulation run
  struct stat sb;
  if (stat(o.po.path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
    // a growth run ('verdant sim --grow -o RUN/') has its own index of ages
    char idx[4200];
    snprintf(idx, sizeof idx, "%s/growth.json", o.po.path);
    if (stat(idx, &sb) == 0) return cli_render_growth(&o);
    return cli_render_run(&o);
  }
  if (!o.out) return cli_usage_error("render", "missing -o OUT.png");
  if (!cli_has_ext(o.out, ".png"))
    return cli_usage_error("render", "output '%s' must end in .png", o.out);
  if (o.has_time || o.mp4 || o.fps > 0 || o.disp_from_first)
    return cli_usage_error("render", "--time, --mp4, --fps and --displacement-from first apply to "
                                     "simulation runs (a folder of 'verdant sim -o')");
  {
    // the files: the plant (or cloud) and the robot read, the picture and its layers written
    char files[5][4200];
    int nout = cli_frame_files(o.out, o.depth, o.masks, files);
    cli_out_plant_opts(&o.po);
    cli_out_input("--robot", o.def.robot_mjcf);
    for (int k = 0; k < nout; k++) cli_out_file("-o", files[k]);
    if (cli_out_check("render")) return EXIT_USAGE;
  }
  // meshes (.obj, a .ply with faces: what 'verdant grow' writes), point clouds in any format the
  // cloud module reads; everything else is a plant
  int is_mesh = vd_geom_is_mesh_file(o.po.path);
  int is_cloud = !is_mesh && (cli_has_ext(o.po.path, ".ply") || cli_has_ext(o.po.path, ".pcd") ||
                              cli_has_ext(o.po.path, ".xyz") || cli_has_ext(o.po.path, ".csv") ||
                              cli_has_ext(o.po.path, ".las"));
  vd_render_style style = o.style;
  if ((is_cloud || is_mesh) && style.color_by != VD_COLOR_LABEL &&
      style.color_by != VD_COLOR_INSTANCE)
    return cli_usage_error("render", "a point cloud or a mesh is coloured by label or instance");
  // stress: a plant file that carries it (a growth run's snapshot), else a run folder
  int want_stress = !is_cloud && style.color_by == VD_COLOR_STRESS;
  vd_render_def def = o.def;
  // load what is drawn
  vd_error err = {0};
  vd_status st;
  vd_plant_spec* plant = NULL;
  vd_model* model = NULL;
  cli_grow_info ginfo;
  memset(&ginfo, 0, sizeof ginfo);
  vd_cloud cl;
  memset(&cl, 0, sizeof cl);
  vd_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  vd_label* mlabels = NULL;
  int nmlabel = 0;
  vd_renderer* r = NULL;
  int code = EXIT_OK;
  if (is_mesh) {
    st = vd_geom_read_mesh(o.po.path, &mesh, &mlabels, &nmlabel, &err);
  } else if (is_cloud) {
    st = vd_cloud_read(o.po.path, &cl, &err);
    if (!st && cl.n > INT32_MAX)
      st = vd_error_set(&err, VD_ERR_LIMIT, o.po.path, 0, 0, "more than 2^31 points");
  } else {
    st = cli_load_plant(&o.po, &plant, &ginfo, &err);
    if (!st && want_stress && !vd_plant_has_stress(plant)) {
      code = cli_usage_error("render",
                             "--color-by stress needs a simulation state (a run folder of 'verdant sim -o RUN/', "
                             "or a plant file with stress from 'verdant sim --grow'); a plant at rest carries no stress");
      goto done;
    }
    if (!st) st = vd_plant_compile(plant, &model, &err);
    cli_blame_input(&err, o.po.path);
    // a simulated plant's stress, on the paper's logarithmic scale (its Figure 7)
    if (!st && want_stress) style.seg_stress = plant->seg_stress, style.log_scale = 1;
  }
  if (st) {
    code = cli_report("render", &err, st);
    goto done;
  }
  // room in the scene for every organ instance (or cloud group) whatever the plant's size
  {
    long need = is_mesh ? mesh.ntri : is_cloud ? cl.n : model->ninstance;
    if (need + 16 > def.max_geoms) def.max_geoms = need + 16 > 10000000 ? 10000000 : (int)need + 16;
  }
  // the renderer: a missing OpenGL context is a failed run, not bad input
  st = vd_render_create(&def, &r, &err);
  if (st) {
    code = cli_report("render", &err, st);
    if (st == VD_ERR_UNSUPPORTED || st == VD_ERR_NOMEM) code = EXIT_FAIL;
    goto done;
  }
  if (o.info) fprintf(stderr, "verdant render: %s\n", vd_render_info(r));
  if ((st = cli_apply_look(&o, r, &err))) {
    code = cli_report("render", &err, st);
    goto done;
  }
  if (is_mesh) {
    st = vd_render_add_mesh(r, &mesh, mlabels, nmlabel, &style, &err);
  } else if (is_cloud) {
    vd_points pts = {(int)cl.n, cl.pos, cl.label, cl.instance, o.point_size, cl.labels, cl.nlabel};
    st = vd_render_add_points(r, &pts, &style, &err);
  } else {
    st = vd_render_add_plant(r, model, NULL, &style, &err);
  }
  if (st) {
    code = cli_report("render", &err, st);
    goto done;
  }
  // the camera, the frame, the files
  vd_vec3 lo, hi;
  vd_render_bounds(r, &lo, &hi);
  vd_camera cam = cli_render_camera(&o, lo, hi);
  unsigned layers = VD_LAYER_COLOR | (o.depth ? VD_LAYER_DEPTH : 0) |
                    (o.masks ? VD_LAYER_LABEL | VD_LAYER_INSTANCE : 0);
  vd_frame f;
  st = vd_render_draw(r, &cam, layers, &f, &err);
  if (st) {
    code = cli_report("render", &err, st);
    goto done;
  }
  st = cli_frame_write(&f, o.out, o.depth, o.masks, &err);
  if (st)
    code = st == VD_ERR_IO ? (cli_report("render", &err, st), EXIT_FAIL)
                           : cli_report("render", &err, st);
done:
  vd_render_destroy(r);
  vd_model_destroy(model);
  vd_plant_spec_destroy(plant);
  cli_grow_info_free(&ginfo);
  vd_cloud_free(&cl);
  vd_mesh_free(&mesh);
  vd_free(mlabels, sizeof(vd_label) * (size_t)(nmlabel ? nmlabel : 1));
  return code;
}
