// SPDX-License-Identifier: MIT
// verdant cloud: a plant (.lpy or plant file) → a labelled point cloud (.ply .pcd .xyz .csv
// .las), with scanner effects and --stats. The option parser and the load-sample-write pipeline
// are shared with verdant dataset.
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char* cli_cloud_help =
    "  -N, --points N        points of the surface sensors (default 100000)\n"
    "      --max-points N    most points, or rays of a scan, per cloud (default 50000000, about\n"
    "                        80 bytes each); more is an error before any memory is taken\n"
    "      --sensor S        uniform | distance | scan (default uniform): uniform on the\n"
    "                        surface; density falling with distance from the scanners; or\n"
    "                        rays on each scanner's grid, the hits being the points\n"
    "      --scanner X,Y,Z[,TX,TY,TZ]\n"
    "                        a scanner at X,Y,Z (m) looking at TX,TY,TZ (m; default the\n"
    "                        plant's bounding-box centre); repeatable, one view each\n"
    "      --scanners FILE   scanner preset (JSON, e.g. data/scanners/turntable8.json)\n"
    "      --density-law L   distance sensor: inverse-square (default) | linear | constant |\n"
    "                        table:D1:G1,D2:G2,... (density G at distance D m, linear between)\n"
    "      --noise S[,K]     Gaussian noise, sigma = S + K d (S in m, K in m per m of distance d\n"
    "                        to the scanner); isotropic on surfaces, along the ray in scans\n"
    "      --occlusion       keep only points a scanner sees (back faces culled, rays cast)\n"
    "      --no-interior     keep points inside other closed primitives\n"
    "      --pattern P       scan rays of --scanner scanners: angular (default) | pinhole\n"
    "      --fov H,V         their field of view, degrees (default 60,45)\n"
    "      --res W,H         their rays across and down (default 320,240)\n"
    "      --labels L        semantic (default) | instance: what the label field holds\n"
    "      --slices N        sides of every frustum and sphere (default: each primitive's own)\n"
    "      --cloud-seed S    seed of the sampling (default: the --seed of the plant)\n"
    "      --threads T       threads (default: all cores); the output does not depend on it\n"
    "      --ascii           PLY and PCD as text instead of binary\n"
    "      --ply-scalar-prefix\n"
    "                        PLY properties scalar_label, scalar_instance, ... (CloudCompare\n"
    "                        keeps only scalar_* properties)\n";

static const char* cloud_usage =
    "usage: verdant cloud PLANT -o OUT [options]\n"
    "\n"
    "Sample a labelled point cloud of a plant: an L-Py file (.lpy, derived on the fly) or a\n"
    "plant file (.json). OUT's extension picks the format: .ply .pcd .xyz .csv .las. Every\n"
    "point carries x y z, normal, label and instance (and view and range with scanners).\n"
    "\n"
    "options:\n"
    "  -o, --output OUT      the cloud file (written under a temporary name, then renamed)\n"
    "      --stats           print a JSON summary on stdout: points, labels (points per label),\n"
    "                        instances, bbox_min, bbox_max (m), area (m^2), rejected counts;\n"
    "                        the same bytes for the same inputs\n"
    "      --profile         --stats adds threads, seconds per stage and points_per_second:\n"
    "                        timings, which differ per run\n";

void cli_cloud_opts_init(cli_cloud_opts* o) {
  memset(o, 0, sizeof *o);
  o->def = vd_cloud_def_default();
  o->def.max_points = 50000000;
  o->wdef = vd_cloud_write_def_default();
  vd_scanner s = vd_scanner_default();
  o->pattern = s.pattern;
  o->fov_h = s.fov_h, o->fov_v = s.fov_v;
  o->res_h = s.res_h, o->res_v = s.res_v;
}

// comma-separated numbers: exactly n of them (or n2 when n2 > 0), all finite
static int parse_list(const char* s, double* out, int n, int n2) {
  int k = 0;
  const char* p = s;
  while (*p) {
    if (k == (n2 > n ? n2 : n)) return 0;
    char* end;
    errno = 0;
    out[k] = strtod(p, &end);
    if (end == p || errno || !isfinite(out[k])) return 0;
    k++;
    if (*end == ',') {
      p = end + 1;
      if (!*p) return 0;
    } else if (*end) {
      return 0;
    } else {
      p = end;
    }
  }
  return k == n || (n2 > 0 && k == n2) ? k : 0;
}


// table:D1:G1,D2:G2,...
static int parse_table(const char* s, vd_cloud_def* def) {
  int n = 0;
  const char* p = s;
  while (*p) {
    if (n == VD_CLOUD_TABLE_MAX) return 0;
    char* end;
    errno = 0;
    double d = strtod(p, &end);
    if (end == p || *end != ':' || errno) return 0;
    p = end + 1;
    double g = strtod(p, &end);
    if (end == p || errno) return 0;
    def->table_d[n] = d, def->table_g[n] = g, n++;
    if (*end == ',') {
      p = end + 1;
      if (!*p) return 0;
    } else if (*end) {
      return 0;
    } else {
      p = end;
    }
  }
  def->ntable = n;
  return n >= 2;
}

int cli_cloud_opt(cli_cloud_opts* o, const char* cmd, int argc, char** argv, int* i) {
  const char* a = argv[*i];
  const char* val = NULL;
#define FAIL(...)                                                                                  \
  do {                                                                                             \
    cli_usage_error(cmd, __VA_ARGS__);                                                             \
    return -1;                                                                                     \
  } while (0)
  int64_t v;
  double x[6];
  if (!strcmp(a, "-N") || !strcmp(a, "--points")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 1, 2000000000, &v)) FAIL("%s expects an integer in 1..2000000000, got '%s'", a, val);
    o->def.points = v;
    o->points_given = 1;
  } else if (!strcmp(a, "--max-points")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 1, 2000000000, &v)) FAIL("--max-points expects an integer in 1..2000000000, got '%s'", val);
    o->def.max_points = v;
  } else if (!strcmp(a, "--sensor")) {
    CLI_TAKE();
    if (!strcmp(val, "uniform")) o->def.sensor = VD_SENSOR_UNIFORM;
    else if (!strcmp(val, "distance")) o->def.sensor = VD_SENSOR_DISTANCE;
    else if (!strcmp(val, "scan")) o->def.sensor = VD_SENSOR_SCAN;
    else FAIL("--sensor expects uniform, distance or scan, got '%s'", val);
  } else if (!strcmp(a, "--scanner")) {
    CLI_TAKE();
    int k = parse_list(val, x, 3, 6);
    if (!k) FAIL("--scanner expects X,Y,Z or X,Y,Z,TX,TY,TZ in metres, got '%s'", val);
    if (o->nscanner == CLI_MAX_SCANNERS) FAIL("too many --scanner options (%d at most)", CLI_MAX_SCANNERS);
    o->scanner_pos[o->nscanner] = vd_v3(x[0], x[1], x[2]);
    o->scanner_target[o->nscanner] = k == 6 ? vd_v3(x[3], x[4], x[5]) : vd_v3(0, 0, 0);
    o->scanner_has_target[o->nscanner] = k == 6;
    o->nscanner++;
  } else if (!strcmp(a, "--scanners")) {
    CLI_TAKE();
    o->scanners_file = val;
  } else if (!strcmp(a, "--density-law")) {
    CLI_TAKE();
    o->density_given = 1;
    if (!strcmp(val, "inverse-square")) o->def.density = VD_DENSITY_INVERSE_SQUARE;
    else if (!strcmp(val, "linear")) o->def.density = VD_DENSITY_LINEAR;
    else if (!strcmp(val, "constant")) o->def.density = VD_DENSITY_CONSTANT;
    else if (!strncmp(val, "table:", 6)) {
      o->def.density = VD_DENSITY_TABLE;
      if (!parse_table(val + 6, &o->def))
        FAIL("--density-law table expects table:D1:G1,D2:G2,... (2..%d pairs), got '%s'", VD_CLOUD_TABLE_MAX, val);
    } else {
      FAIL("--density-law expects inverse-square, linear, constant or table:D1:G1,..., got '%s'", val);
    }
  } else if (!strcmp(a, "--noise")) {
    CLI_TAKE();
    int k = parse_list(val, x, 1, 2);
    if (!k || x[0] < 0 || (k == 2 && x[1] < 0)) FAIL("--noise expects S or S,K with S, K >= 0, got '%s'", val);
    o->def.noise_sigma = x[0];
    o->def.noise_slope = k == 2 ? x[1] : 0;
  } else if (!strcmp(a, "--occlusion")) {
    o->def.occlusion = 1;
  } else if (!strcmp(a, "--no-interior")) {
    o->def.interior = 0;
  } else if (!strcmp(a, "--pattern")) {
    CLI_TAKE();
    o->scan_opts = 1;
    if (!strcmp(val, "angular")) o->pattern = VD_SCAN_ANGULAR;
    else if (!strcmp(val, "pinhole")) o->pattern = VD_SCAN_PINHOLE;
    else FAIL("--pattern expects angular or pinhole, got '%s'", val);
  } else if (!strcmp(a, "--fov")) {
    CLI_TAKE();
    o->scan_opts = 1;
    if (!parse_list(val, x, 2, 0) || !(x[0] > 0 && x[0] <= 360 && x[1] > 0 && x[1] <= 180))
      FAIL("--fov expects H,V in degrees, 0 < H <= 360, 0 < V <= 180, got '%s'", val);
    o->fov_h = x[0] * VD_PI / 180, o->fov_v = x[1] * VD_PI / 180;
  } else if (!strcmp(a, "--res")) {
    CLI_TAKE();
    o->scan_opts = 1;
    if (!parse_list(val, x, 2, 0) || x[0] != floor(x[0]) || x[1] != floor(x[1]) || x[0] < 1 ||
        x[1] < 1 || x[0] > 100000 || x[1] > 100000)
      FAIL("--res expects W,H integers in 1..100000, got '%s'", val);
    o->res_h = (int)x[0], o->res_v = (int)x[1];
  } else if (!strcmp(a, "--labels")) {
    CLI_TAKE();
    if (!strcmp(val, "semantic")) o->labels_instance = 0;
    else if (!strcmp(val, "instance")) o->labels_instance = 1;
    else FAIL("--labels expects semantic or instance, got '%s'", val);
  } else if (!strcmp(a, "--slices")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 3, 1024, &v)) FAIL("--slices expects an integer in 3..1024, got '%s'", val);
    o->def.mesh.slices = (int)v;
  } else if (!strcmp(a, "--cloud-seed")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 0, INT64_MAX, &v)) FAIL("--cloud-seed expects an integer >= 0, got '%s'", val);
    o->cloud_seed = (uint64_t)v;
    o->has_cloud_seed = 1;
  } else if (!strcmp(a, "--threads")) {
    CLI_TAKE();
    if (!cli_parse_i64(val, 1, 1024, &v)) FAIL("--threads expects an integer in 1..1024, got '%s'", val);
    o->def.threads = (int)v;
  } else if (!strcmp(a, "--ascii")) {
    o->wdef.ascii = 1;
  } else if (!strcmp(a, "--ply-scalar-prefix")) {
    o->wdef.ply_prefix = "scalar_";
  } else {
    return 0;
  }
#undef FAIL
  return 1;
}

int cli_cloud_check_output(const cli_cloud_opts* o, const char* cmd, const char* out) {
  int ply = out && (cli_has_ext(out, ".ply") || !strcmp(out, "ply"));
  int pcd = out && (cli_has_ext(out, ".pcd") || !strcmp(out, "pcd"));
  if (o->wdef.ascii && !ply && !pcd)
    return cli_usage_error(cmd, "--ascii applies to PLY and PCD clouds (XYZ and CSV are text, LAS is binary)%s",
                           out ? "" : "; there is no cloud output");
  if (o->wdef.ply_prefix && !ply)
    return cli_usage_error(cmd, "--ply-scalar-prefix applies to PLY clouds%s", out ? "" : "; there is no cloud output");
  return 0;
}

int cli_cloud_check(const cli_cloud_opts* o, const char* cmd) {
  if (o->density_given && o->def.sensor != VD_SENSOR_DISTANCE)
    return cli_usage_error(cmd, "--density-law applies to --sensor distance");
  if (o->scan_opts && o->def.sensor != VD_SENSOR_SCAN)
    return cli_usage_error(cmd, "--pattern, --fov and --res apply to --sensor scan");
  if (o->points_given && o->def.sensor == VD_SENSOR_SCAN)
    return cli_usage_error(cmd, "--points does not apply to --sensor scan (the ray grid sets the count)");
  int any = o->nscanner > 0 || o->scanners_file;
  if (!any && o->def.sensor != VD_SENSOR_UNIFORM)
    return cli_usage_error(cmd, "--sensor %s needs --scanner or --scanners",
                           o->def.sensor == VD_SENSOR_SCAN ? "scan" : "distance");
  if (!any && o->def.occlusion) return cli_usage_error(cmd, "--occlusion needs --scanner or --scanners");
  if (!any && o->def.noise_slope > 0)
    return cli_usage_error(cmd, "--noise S,K with K > 0 needs --scanner or --scanners");
  return 0;
}

// ---------------------------------------------------------------------------------------------
// the pipeline: load, compile, scanners, sample, relabel, write

// progress bars of the sampling (chunks) and the writing (points)
typedef struct cloud_bar {
  cli_progress bar;
  const char* what;
  int64_t best;  // chunks may finish out of order: the bar never goes back
} cloud_bar;

static void cloud_progress(void* user, int64_t done, int64_t total) {
  cloud_bar* b = user;
  if (!b->bar.on) return;
  if (done > b->best) b->best = done;
  if (!cli_progress_due(&b->bar) && b->best < total) return;
  char text[64];
  snprintf(text, sizeof text, "%3d%%", total > 0 ? (int)(100.0 * (double)b->best / (double)total) : 100);
  cli_progress_bar(b->what, total > 0 ? (double)b->best / (double)total : 1, text);
  b->bar.shown = 1;
}

vd_status cli_cloud_make(const cli_plant_opts* po, const cli_cloud_opts* co, const char* out,
                         cli_cloud_result* res, vd_error* err) {
  memset(res, 0, sizeof *res);
  double t0 = cli_now();
  vd_plant_spec* plant = NULL;
  cli_grow_info info;
  vd_status st = cli_load_plant(po, &plant, &info, err);
  if (st) return st;
  cli_grow_info_free(&info);
  double t1 = cli_now();
  vd_model* m = NULL;
  st = vd_plant_compile(plant, &m, err);
  cli_blame_input(err, po->path);
  vd_plant_stats ps;
  vd_plant_spec_stats(plant, &ps);
  vd_plant_spec_destroy(plant);
  if (st) return st;
  double t2 = cli_now();
  // scanners: --scanner ones (target: the plant's centre unless given), then the preset's
  vd_scanner* sc = NULL;
  int nfile = 0, n = co->nscanner;
  vd_scanner* fsc = NULL;
  if (co->scanners_file) st = vd_cloud_read_scanners(co->scanners_file, ps.bbox_min, ps.bbox_max, &fsc, &nfile, err);
  if (!st && n + nfile > 0) {
    sc = vd_malloc((size_t)(n + nfile) * sizeof *sc);
    if (!sc) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  if (!st) {
    vd_vec3 centre = vd_scale(vd_add(ps.bbox_min, ps.bbox_max), 0.5);
    for (int i = 0; i < n; i++) {
      vd_scanner s = vd_scanner_default();
      s.pos = co->scanner_pos[i];
      s.target = co->scanner_has_target[i] ? co->scanner_target[i] : centre;
      s.pattern = co->pattern;
      s.fov_h = co->fov_h, s.fov_v = co->fov_v, s.res_h = co->res_h, s.res_v = co->res_v;
      if (vd_norm(vd_sub(s.target, s.pos)) == 0)
        st = vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                          "--scanner %d: the scanner sits on its target; give a target", i + 1);
      sc[i] = s;  // NOLINT(clang-analyzer-core.NullDereference): sc is allocated whenever n + nfile > 0
    }
    for (int i = 0; i < nfile; i++)
      sc[n + i] = fsc[i];  // NOLINT(clang-analyzer-core.NullDereference): sc is allocated whenever n + nfile > 0
  }
  vd_free(fsc, (size_t)nfile * sizeof *fsc);
  // sample
  vd_cloud cloud;
  memset(&cloud, 0, sizeof cloud);
  if (!st) {
    vd_cloud_def def = co->def;
    def.seed = co->has_cloud_seed ? co->cloud_seed : po->seed;
    def.nscanner = n + nfile;
    def.scanner = sc;
    cloud_bar bar = {{po->progress, 0, 0}, "sampling", 0};
    def.progress = cloud_progress;
    def.progress_user = &bar;
    st = vd_cloud_sample(m, NULL, &def, &cloud, &res->stats, err);
    cli_progress_end(&bar.bar);
  }
  vd_free(sc, (size_t)(n + nfile) * sizeof *sc);
  vd_model_destroy(m);
  if (!st && co->labels_instance) st = vd_cloud_relabel(&cloud, err);
  double t3 = cli_now();
  // write
  if (!st && out) {
    vd_cloud_write_def wd = co->wdef;
    char comment[256];
    snprintf(comment, sizeof comment, "seed %llu, sensor %s, labels %s", (unsigned long long)(co->has_cloud_seed ? co->cloud_seed : po->seed),
             co->def.sensor == VD_SENSOR_UNIFORM ? "uniform" : co->def.sensor == VD_SENSOR_DISTANCE ? "distance" : "scan",
             co->labels_instance ? "instance" : "semantic");
    wd.comment = comment;
    wd.threads = co->def.threads;
    cloud_bar bar = {{po->progress, 0, 0}, "writing ", 0};
    wd.progress = cloud_progress;
    wd.progress_user = &bar;
    st = vd_cloud_write(&cloud, out, &wd, err);
    cli_progress_end(&bar.bar);
    if (st) res->write_failed = 1;
  }
  double t4 = cli_now();
  res->seconds_load = t1 - t0;
  res->seconds_compile = t2 - t1;
  res->seconds_write = t4 - t3;
  res->seconds_total = t4 - t0;
  if (!st) {
    res->cloud = cloud;
  } else {
    vd_cloud_free(&cloud);
  }
  return st;
}

// ---------------------------------------------------------------------------------------------
// --stats

static cJSON* vec_json(const double* v) { return cJSON_CreateDoubleArray(v, 3); }

typedef struct id_index {
  int id, index;
} id_index;

static int cmp_id(const void* a, const void* b) {
  int x = ((const id_index*)a)->id, y = ((const id_index*)b)->id;
  return (x > y) - (x < y);
}

int cli_label_counts(const vd_cloud* c, int64_t* count) {
  for (int l = 0; l < c->nlabel; l++)
    count[l] = 0;
  if (c->nlabel == 0) return 1;
  // the table sorted by id, then one binary search per point
  id_index* ix = vd_malloc((size_t)c->nlabel * sizeof *ix);
  if (!ix) return 0;
  for (int l = 0; l < c->nlabel; l++)
    ix[l] = (id_index){c->labels[l].id, l};
  qsort(ix, (size_t)c->nlabel, sizeof *ix, cmp_id);
  // distinct ids over a short range: a direct table instead of a search per point
  int lo = ix[0].id, span = ix[c->nlabel - 1].id - lo, distinct = 1;
  for (int l = 1; l < c->nlabel; l++)
    distinct &= ix[l].id != ix[l - 1].id;
  int* at_id = distinct && span >= 0 && span < 1 << 16 ? vd_malloc(((size_t)span + 1) * sizeof(int)) : NULL;
  if (at_id) {
    for (int k = 0; k <= span; k++)
      at_id[k] = -1;
    for (int l = 0; l < c->nlabel; l++)
      at_id[ix[l].id - lo] = ix[l].index;
    for (int64_t i = 0; i < c->n; i++) {
      int64_t k = (int64_t)c->label[i] - lo;
      if (k >= 0 && k <= span && at_id[k] >= 0) count[at_id[k]]++;
    }
    vd_free(at_id, ((size_t)span + 1) * sizeof(int));
    vd_free(ix, (size_t)c->nlabel * sizeof *ix);
    return 1;
  }
  for (int64_t i = 0; i < c->n; i++) {
    id_index key = {c->label[i], 0};
    const id_index* at = bsearch(&key, ix, (size_t)c->nlabel, sizeof *ix, cmp_id);
    if (at) count[at->index]++;
  }
  vd_free(ix, (size_t)c->nlabel * sizeof *ix);
  return 1;
}

cJSON* cli_cloud_stats_json(const cli_cloud_result* r, double seconds_total, int profile) {
  const vd_cloud* c = &r->cloud;
  const vd_cloud_stats* s = &r->stats;
  cJSON* root = cJSON_CreateObject();
  if (!root) return NULL;
  cJSON_AddNumberToObject(root, "points", (double)c->n);
  // points per label name, in table order; and the distinct instances
  cJSON* labels = cJSON_AddObjectToObject(root, "labels");
  int64_t* count = c->nlabel ? vd_calloc((size_t)c->nlabel, sizeof(int64_t)) : NULL;
  int ninst = 0;
  if (count && cli_label_counts(c, count)) {
    for (int l = 0; l < c->nlabel; l++)
      cJSON_AddNumberToObject(labels, c->labels[l].name, (double)count[l]);
  }
  vd_free(count, (size_t)c->nlabel * sizeof(int64_t));
  int maxi = 0;
  for (int64_t i = 0; i < c->n; i++)
    if (c->instance[i] > maxi) maxi = c->instance[i];
  unsigned char* seen = vd_calloc((size_t)maxi + 1, 1);
  if (seen) {
    for (int64_t i = 0; i < c->n; i++)
      if (c->instance[i] >= 0 && !seen[c->instance[i]]) seen[c->instance[i]] = 1, ninst++;
    vd_free(seen, (size_t)maxi + 1);
  }
  cJSON_AddNumberToObject(root, "instances", ninst);
  cJSON_AddNumberToObject(root, "views", c->nview);
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  if (c->n)
    for (int k = 0; k < 3; k++)
      lo[k] = INFINITY, hi[k] = -INFINITY;
  // one pass; for finite bounds the same as fmin and fmax (ties and NaN keep the bound)
  for (int64_t i = 0; i < c->n; i++)
    for (int k = 0; k < 3; k++) {
      double x = c->pos[3 * i + k];
      lo[k] = x < lo[k] ? x : lo[k];
      hi[k] = x > hi[k] ? x : hi[k];
    }
  cJSON_AddItemToObject(root, "bbox_min", vec_json(lo));
  cJSON_AddItemToObject(root, "bbox_max", vec_json(hi));
  cJSON_AddNumberToObject(root, "area", s->area);
  cJSON_AddNumberToObject(root, "triangles", s->ntri);
  cJSON_AddNumberToObject(root, "solids", s->nsolid);
  cJSON_AddNumberToObject(root, "drawn", (double)s->drawn);
  cJSON* rej = cJSON_AddObjectToObject(root, "rejected");
  cJSON_AddNumberToObject(rej, "interior", (double)s->rejected_interior);
  cJSON_AddNumberToObject(rej, "density", (double)s->rejected_density);
  cJSON_AddNumberToObject(rej, "backface", (double)s->rejected_backface);
  cJSON_AddNumberToObject(rej, "occluded", (double)s->rejected_occluded);
  cJSON_AddNumberToObject(rej, "noise", (double)s->rejected_noise);
  cJSON_AddNumberToObject(root, "missed_rays", (double)s->missed);
  if (!profile) return root;
  cJSON_AddNumberToObject(root, "threads", s->threads);
  cJSON* t = cJSON_AddObjectToObject(root, "seconds");
  cJSON_AddNumberToObject(t, "load", r->seconds_load);
  cJSON_AddNumberToObject(t, "compile", r->seconds_compile);
  cJSON_AddNumberToObject(t, "tessellate", s->seconds_tessellate);
  cJSON_AddNumberToObject(t, "build", s->seconds_build);
  cJSON_AddNumberToObject(t, "sample", s->seconds_sample);
  cJSON_AddNumberToObject(t, "write", r->seconds_write);
  cJSON_AddNumberToObject(t, "total", seconds_total);
  cJSON* pps = cJSON_AddObjectToObject(root, "points_per_second");
  cJSON_AddNumberToObject(pps, "sample", s->seconds_sample > 0 ? (double)c->n / s->seconds_sample : 0);
  cJSON_AddNumberToObject(pps, "write", r->seconds_write > 0 ? (double)c->n / r->seconds_write : 0);
  cJSON_AddNumberToObject(pps, "total", seconds_total > 0 ? (double)c->n / seconds_total : 0);
  return root;
}

int cli_cloud(int argc, char** argv) {
  double start = cli_now();
  cli_plant_opts po;
  cli_plant_opts_init(&po);
  cli_cloud_opts co;
  cli_cloud_opts_init(&co);
  const char* out = NULL;
  int stats = 0, profile = 0;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      fputs(cloud_usage, stdout);
      fputs(cli_cloud_help, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
    int r = cli_plant_opt(&po, "cloud", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    r = cli_cloud_opt(&co, "cloud", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (i + 1 >= argc) return cli_usage_error("cloud", "%s needs a file name", a);
      out = argv[++i];
    } else if (!strcmp(a, "--stats")) {
      stats = 1;
    } else if (!strcmp(a, "--profile")) {
      profile = 1;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error("cloud", "unknown option '%s'", a);
    } else if (!po.path) {
      po.path = a;
    } else {
      return cli_usage_error("cloud", "unexpected argument '%s'", a);
    }
  }
  if (!po.path) return cli_usage_error("cloud", "missing PLANT (an .lpy or plant .json file)");
  if (!out && !stats) return cli_usage_error("cloud", "nothing to do: give -o OUT and/or --stats");
  if (profile && !stats) return cli_usage_error("cloud", "--profile adds timings to --stats; give --stats");
  if (out && vd_cloud_format_of(out) == VD_CLOUD_AUTO)
    return cli_usage_error("cloud", "output '%s': unknown format (use .ply, .pcd, .xyz, .csv or .las)", out);
  if (cli_cloud_check(&co, "cloud") || cli_cloud_check_output(&co, "cloud", out)) return EXIT_USAGE;
  // the files: the plant and the scanners read, the cloud written
  cli_out_plant_opts(&po);
  cli_out_input("--scanners", co.scanners_file);
  cli_out_file("-o", out);
  if (cli_out_check("cloud")) return EXIT_USAGE;
  vd_error err = {0};
  cli_cloud_result res;
  vd_status st = cli_cloud_make(&po, &co, out, &res, &err);
  if (st) {
    int code = cli_report("cloud", &err, st);
    return res.write_failed && st == VD_ERR_IO ? EXIT_FAIL : code;
  }
  if (stats) {
    cJSON* root = cli_cloud_stats_json(&res, cli_now() - start, profile);
    char* text = root ? cJSON_Print(root) : NULL;
    if (text) {
      fputs(text, stdout);
      fputc('\n', stdout);
      cJSON_free(text);
    }
    cJSON_Delete(root);
    if (!text) {
      vd_cloud_free(&res.cloud);
      fprintf(stderr, "verdant cloud: out of memory\n");
      return EXIT_FAIL;
    }
  }
  vd_cloud_free(&res.cloud);
  return EXIT_OK;
}
