// SPDX-License-Identifier: MIT
// verdant dataset: K plants of one model, each with its labelled cloud, item i seeded from
// (master seed, i) so any item can be remade alone. Items run in parallel (--jobs) and split
// across machines (--shard i/N); a run skips complete items, so an interrupted dataset resumes.
// Every file is written under a temporary name and renamed when complete; an item is complete
// when its record (written after its cloud and images) names a cloud file of the recorded size
// and the images it lists exist. With --images N each item also gets N rendered views of the
// same plant (colour, depth, label and instance masks, camera sidecar).
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <nettle/sha2.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "cli.h"

#define DATASET_FORMAT "verdant-dataset"
#define DATASET_VERSION 1
#define MAX_VARY 16

static const char* dataset_usage =
    "usage: verdant dataset PLANT --count K -o DIR [options]\n"
    "\n"
    "Make K plants of one model (an .lpy file) and a labelled point cloud of each in DIR:\n"
    "item_000000.ply ... with a record item_000000.json each, and manifest.json (label table,\n"
    "per-item seed, parameters, point counts, SHA-256 checksums) once every item is there.\n"
    "Item i uses the seed printed in its record: 'verdant cloud PLANT --seed SEED' with the same\n"
    "options (and --set NAME=VALUE for each --vary) makes it again. Complete items are skipped,\n"
    "so an interrupted run resumes where it stopped.\n"
    "\n"
    "options:\n"
    "  -K, --count K         items in the dataset (>= 1)\n"
    "  -o, --output DIR      the dataset folder (created if missing)\n"
    "      --seed S          master seed (default 0); item i is seeded from (S, i)\n"
    "      --format F        cloud files: ply (default) | pcd | xyz | csv | las\n"
    "      --jobs J          items made at once on this machine (default 1)\n"
    "      --shard I/N       make only items i with i mod N = I (0 <= I < N): one shard of a\n"
    "                        Slurm job array or of mpirun ranks (examples/dataset_*.sh)\n"
    "      --vary NAME=A:B   set the .lpy global NAME to a value drawn uniformly in [A, B] for\n"
    "                        each item (repeatable); integer bounds (8:24) draw integers, write\n"
    "                        8.0:24 for real values; the value is in the item's record\n"
    "      --images N        also N pictures of each plant from around it (colour, depth and label\n"
    "                        and instance masks, camera JSON: item_000000_view0.png, ...), seeded\n"
    "                        by the item; needs an OpenGL context (EGL, software without a GPU)\n"
    "      --image-size WxH  size of those pictures in pixels (default 640x480)\n"
    "      --force           remake complete items too\n"
    "      --stats           print a JSON summary on stdout (made, skipped, points, manifest)\n"
    "      --profile         --stats adds seconds and items_per_second (timings)\n";

typedef struct vary {
  char name[64];
  double a, b;
  int integer;  // both bounds written as integers: draw integers in [a, b]
} vary;

typedef struct dataset {
  const char* dir;
  const char* ext;  // "ply", ...
  int count, jobs, shard, nshard, force, progress, width;
  uint64_t master;
  vary vary[MAX_VARY];
  int nvary;
  int instance_labels; // --labels instance: every item has its own label table
  char params[17];     // hex FNV-1a of the arguments that shape the output
  cJSON* arguments;    // those arguments
  int argc;            // the command line (for the regenerate recipes)
  char** argv;
  int images;          // --images: views per item
  int img_w, img_h;    // --image-size (pixels)
  cli_view_opts view;  // the pictures' options (cli_views.c)
} dataset;

// Renderers shared by the worker threads, one thread at a time (an OpenGL context is current on
// one thread; vd_render_release hands it over).
#define POOL_MAX 1024
typedef struct render_pool {
  vd_renderer* r[POOL_MAX]; // renderers (n), NULL until first needed
  int geoms[POOL_MAX];      // their max_geoms
  int busy[POOL_MAX];       // 1 while a thread holds it
  vd_render_look look0[POOL_MAX]; // their look as made (views vary from it)
  int n;
} render_pool;

// ---------------------------------------------------------------------------------------------
// small helpers

static uint64_t fnv1a(uint64_t h, const char* s, size_t n) {
  for (size_t i = 0; i < n; i++) {
    h ^= (unsigned char)s[i];
    h *= 1099511628211ull;
  }
  return h;
}

// item seed and --vary values from the stream (master, i): reproducible for one item alone
static uint64_t item_seed(const dataset* ds, int i, double* values) {
  vd_rng r;
  vd_rng_stream(&r, ds->master, (uint64_t)i);
  uint64_t hi = vd_rng_u32(&r), lo = vd_rng_u32(&r);
  for (int k = 0; k < ds->nvary; k++) {
    const vary* v = &ds->vary[k];
    if (v->integer) {
      // one draw either way, so the stream stays the same for the other values
      double x = v->a + floor(vd_rng_uniform(&r, 0, 1) * (v->b - v->a + 1));
      values[k] = x > v->b ? v->b : x;
    } else {
      values[k] = vd_rng_uniform(&r, v->a, v->b);
    }
  }
  return ((hi << 32) | lo) & ((1ull << 53) - 1);  // below 2^53: exact as a JSON number
}

static void item_path(const dataset* ds, int i, const char* ext, char* buf, size_t cap) {
  snprintf(buf, cap, "%s/item_%0*d.%s", ds->dir, ds->width, i, ext);
}

// SHA-256 of a file as 64 hex digits; 0 on a read error
static int sha256_file(const char* path, char hex[65], int64_t* bytes) {
  FILE* f = fopen(path, "rb");
  if (!f) return 0;
  struct sha256_ctx ctx;
  sha256_init(&ctx);
  unsigned char buf[1 << 16];
  size_t n;
  *bytes = 0;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
    sha256_update(&ctx, n, buf);
    *bytes += (int64_t)n;
  }
  int ok = !ferror(f);
  fclose(f);
  unsigned char d[SHA256_DIGEST_SIZE];
  sha256_digest(&ctx, SHA256_DIGEST_SIZE, d);
  for (int k = 0; k < SHA256_DIGEST_SIZE; k++)
    snprintf(hex + 2 * k, 3, "%02x", d[k]);
  return ok;
}

// write JSON atomically
static vd_status write_json(const char* path, const cJSON* root, int pretty, vd_error* err) {
  char* text = pretty ? cJSON_Print(root) : cJSON_PrintUnformatted(root);
  if (!text) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (!st) {
    fputs(text, f.fp);
    fputc('\n', f.fp);
    st = vd_outfile_commit(&f, err);
    vd_outfile_abort(&f);
  }
  cJSON_free(text);
  return st;
}

// the record of item i if it is complete (parsed, matching parameters, cloud file of its size);
// *mismatch is set when a record exists but was made with other parameters
static cJSON* complete_record(const dataset* ds, int i, int* mismatch) {
  char path[4200];
  item_path(ds, i, "json", path, sizeof path);
  char* text;
  size_t len;
  vd_error e = {0};
  if (access(path, F_OK) != 0 || vd_file_read(path, &text, &len, &e)) return NULL;
  cJSON* rec = cJSON_ParseWithLength(text, len);
  vd_free(text, len + 1);
  if (!rec) return NULL;
  const cJSON* params = cJSON_GetObjectItemCaseSensitive(rec, "parameters");
  const cJSON* file = cJSON_GetObjectItemCaseSensitive(rec, "file");
  const cJSON* bytes = cJSON_GetObjectItemCaseSensitive(rec, "bytes");
  const cJSON* index = cJSON_GetObjectItemCaseSensitive(rec, "index");
  if (!cJSON_IsString(params) || !cJSON_IsString(file) || !cJSON_IsNumber(bytes) ||
      !cJSON_IsNumber(index) || index->valuedouble != i) {
    cJSON_Delete(rec);
    return NULL;
  }
  if (strcmp(params->valuestring, ds->params) != 0) {
    *mismatch = 1;
    cJSON_Delete(rec);
    return NULL;
  }
  char cpath[4200];
  snprintf(cpath, sizeof cpath, "%s/%s", ds->dir, file->valuestring);
  struct stat sb;
  if (strchr(file->valuestring, '/') || stat(cpath, &sb) != 0 || (double)sb.st_size != bytes->valuedouble) {
    cJSON_Delete(rec);
    return NULL;
  }
  // the pictures: as many views as asked, every file there
  if (ds->images) {
    const cJSON* views = cJSON_GetObjectItemCaseSensitive(rec, "images");
    int ok = cJSON_IsArray(views) && cJSON_GetArraySize(views) == ds->images;
    static const char* roles[5] = {"color", "depth", "label", "instance", "camera"};
    const cJSON* v;
    cJSON_ArrayForEach(v, views) {
      for (int k = 0; k < 5 && ok; k++) {
        const cJSON* f = cJSON_GetObjectItemCaseSensitive(v, roles[k]);
        ok = cJSON_IsString(f) && !strchr(f->valuestring, '/');
        if (ok) {
          snprintf(cpath, sizeof cpath, "%s/%s", ds->dir, f->valuestring);
          ok = access(cpath, F_OK) == 0;
        }
      }
    }
    if (!ok) {
      cJSON_Delete(rec);
      return NULL;
    }
  }
  return rec;
}

// temporary files left by a run of this shard that was killed (SIGKILL, power loss): a name
// "<item or manifest>.tmp.<pid>" (or ".bak.<pid>", an old file kept aside) whose process is gone
// is removed; returns how many
static int remove_stale(const dataset* ds) {
  DIR* dir = opendir(ds->dir);
  if (!dir) return 0;
  int removed = 0;
  struct dirent* e;
  while ((e = readdir(dir)) != NULL) {
    const char* tmp = strstr(e->d_name, ".tmp.");
    if (!tmp) tmp = strstr(e->d_name, ".bak.");  // a file kept aside while an item was remade
    if (!tmp) continue;
    char* end;
    long pid = strtol(tmp + 5, &end, 10);
    if (*end || pid <= 0 || pid == (long)getpid()) continue;
    int mine = !strncmp(e->d_name, "manifest.json.tmp.", 18);
    if (!mine && !strncmp(e->d_name, "item_", 5)) {
      char* iend;
      long index = strtol(e->d_name + 5, &iend, 10);
      mine = iend != e->d_name + 5 && index >= 0 && index % ds->nshard == ds->shard;
    }
    if (!mine) continue;
    // only when no process of that id runs here (another machine's run keeps its files)
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", ds->dir, e->d_name);
    removed += cli_out_drop_orphan(path);
  }
  closedir(dir);
  return removed;
}

// ---------------------------------------------------------------------------------------------
// pictures of an item

// a renderer of the pool for this thread (made on first use, remade when too small)
static vd_status pool_take(render_pool* p, const dataset* ds, int geoms, int* slot, vd_error* err) {
  int s = -1;
#pragma omp critical(dataset_pool)
  {
    for (int k = 0; k < p->n && s < 0; k++)
      if (!p->busy[k]) s = k;
    if (s < 0 && p->n < POOL_MAX) s = p->n++;
    if (s >= 0) p->busy[s] = 1;
  }
  if (s < 0) return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "more than %d renderers", POOL_MAX);
  *slot = s;
  if (p->r[s] && p->geoms[s] >= geoms) return VD_OK;
  vd_render_destroy(p->r[s]);
  p->r[s] = NULL;
  vd_render_def def = vd_render_def_default();
  def.width = ds->img_w, def.height = ds->img_h;
  def.legend = 0;  // training images: nothing drawn over the scene
  cli_view_def(&ds->view, &def);
  if (geoms > def.max_geoms) def.max_geoms = geoms;
  p->geoms[s] = def.max_geoms;
  vd_status st = vd_render_create(&def, &p->r[s], err);
  if (st) p->busy[s] = 0;
  if (!st) p->look0[s] = vd_render_get_look(p->r[s]);
  return st;
}

// give the renderer back, its context free for the next thread
static void pool_put(render_pool* p, int slot) {
  vd_render_release(p->r[slot]);
#pragma omp critical(dataset_pool)
  p->busy[slot] = 0;
}

static void pool_free(render_pool* p) {
  for (int k = 0; k < p->n; k++)
    vd_render_destroy(p->r[k]);
  p->n = 0;
}

// ds->images views of item i's plant (loaded with the item's options): the camera orbits the
// plant at azimuths evenly spaced from an offset, at elevations in [10, 40] degrees, all drawn
// from the stream (item seed, VIEW_STREAM); the files and the cameras go into the record
#define VIEW_STREAM 0x76696577u  // "view"
static vd_status make_images(const dataset* ds, render_pool* pool, const cli_plant_opts* po, int i, uint64_t seed,
                             cJSON* rec, vd_error* err) {
  vd_plant_spec* spec = NULL;
  vd_model* m = NULL;
  cli_grow_info info;
  memset(&info, 0, sizeof info);
  vd_status st = cli_load_plant(po, &spec, &info, err);
  if (!st) st = vd_plant_compile(spec, &m, err);
  cli_grow_info_free(&info);
  vd_plant_spec_destroy(spec);
  int slot = -1;
  if (!st) st = pool_take(pool, ds, m->ninstance + 16, &slot, err);
  vd_renderer* r = slot >= 0 ? pool->r[slot] : NULL;
  vd_render_look look0 = {0};
  if (!st) {
    vd_render_style style = vd_render_style_default();
    style.palette = ds->view.palette;
    vd_render_clear(r);
    look0 = pool->look0[slot];
    st = vd_render_add_plant(r, m, NULL, &style, err);
  }
  cJSON* views = cJSON_AddArrayToObject(rec, "images");
  if (!st && !views) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  vd_rng g;
  vd_rng_stream(&g, seed, VIEW_STREAM);
  double az0 = vd_rng_uniform(&g, -180, 180);
  for (int v = 0; !st && v < ds->images; v++) {
    // the view: elevation, distance, offset, lights and colours drawn from the stream
    double az = fmod(az0 + 360.0 * v / ds->images + 180, 360) - 180;
    vd_vec3 lo, hi;
    vd_render_bounds(r, &lo, &hi);
    cli_view view;
    cli_view_draw(&ds->view, &g, az, lo, hi, ds->img_w, ds->img_h, look0, &view);
    if (ds->view.vary_light || ds->view.vary_background) st = vd_render_set_look(r, &view.look, err);
    vd_frame f;
    char base[64], path[4200];
    snprintf(base, sizeof base, "item_%0*d_view%d", ds->width, i, v);
    snprintf(path, sizeof path, "%s/%s.png", ds->dir, base);
    if (!st) st = vd_render_draw(r, &view.cam, VD_LAYER_ALL, &f, err);
    if (!st) st = cli_frame_write(&f, path, 1, 1, err);
    if (st) break;
    cJSON* e = cJSON_CreateObject();
    cJSON_AddNumberToObject(e, "view", v);
    cli_view_record(&ds->view, &view, e);
    static const char* roles[5][2] = {{"color", "png"}, {"depth", "depth.png"}, {"label", "label.png"},
                                      {"instance", "instance.png"}, {"camera", "png.json"}};
    for (int k = 0; k < 5; k++) {
      snprintf(path, sizeof path, "%s.%s", base, roles[k][1]);
      cJSON_AddStringToObject(e, roles[k][0], path);
    }
    cJSON_AddItemToArray(views, e);
  }
  if (slot >= 0) pool_put(pool, slot);
  vd_model_destroy(m);
  return st;
}

// ---------------------------------------------------------------------------------------------
// one item

// *out_failed is set when the failure was writing or reading back the item's files, or drawing
// its pictures (a failed run, exit 1) rather than bad input (exit 2)
static vd_status make_item_files(const dataset* ds, render_pool* pool, const cli_plant_opts* po0, const cli_cloud_opts* co,
                           int i, int64_t* points, int* out_failed, vd_error* err) {
  *out_failed = 0;
  double values[MAX_VARY] = {0};
  uint64_t seed = item_seed(ds, i, values);
  // the item's plant options: its seed, the --vary values as --set
  cli_plant_opts po = *po0;
  po.seed = seed;
  po.progress = 0;
  char setbuf[MAX_VARY][96];
  for (int k = 0; k < ds->nvary; k++) {
    if (po.nset == 64) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "too many --set and --vary options");
    snprintf(setbuf[k], sizeof setbuf[k], "%s=%.17g", ds->vary[k].name, values[k]);
    po.set[po.nset++] = setbuf[k];
  }
  cli_cloud_opts cco = *co;
  cco.has_cloud_seed = 0;  // the cloud is seeded by the item seed as well
  if (ds->jobs > 1 && cco.def.threads == 0) cco.def.threads = 1;
  char cpath[4200], rpath[4200];
  item_path(ds, i, ds->ext, cpath, sizeof cpath);
  item_path(ds, i, "json", rpath, sizeof rpath);
  cli_cloud_result res;
  vd_status st = cli_cloud_make(&po, &cco, cpath, &res, err);
  if (st) {
    *out_failed = res.write_failed;
    return st;
  }
  // the record: seed, values, counts, the file's size and checksum
  char hex[65], now[4300];
  int64_t bytes;
  if (!sha256_file(cli_out_current(cpath, now, sizeof now), hex, &bytes)) {
    *out_failed = 1;
    vd_cloud_free(&res.cloud);
    return vd_error_set(err, VD_ERR_IO, cpath, 0, 0, "cannot read back the cloud: %s", strerror(errno));
  }
  cJSON* rec = cJSON_CreateObject();
  if (!rec) {
    vd_cloud_free(&res.cloud);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  const char* slash = strrchr(cpath, '/');
  cJSON_AddNumberToObject(rec, "index", i);
  // seeds and drawn values exactly (cJSON prints 15 digits when they nearly round-trip, and
  // an item seed near 2^53 printed that way regenerated another item)
  char num[40];
  snprintf(num, sizeof num, "%llu", (unsigned long long)seed);
  cJSON_AddRawToObject(rec, "seed", num);
  cJSON* vv = cJSON_AddObjectToObject(rec, "vary");
  for (int k = 0; k < ds->nvary; k++)
    snprintf(num, sizeof num, "%.17g", values[k]), cJSON_AddRawToObject(vv, ds->vary[k].name, num);
  cJSON_AddStringToObject(rec, "file", slash ? slash + 1 : cpath);
  cJSON_AddNumberToObject(rec, "points", (double)res.cloud.n);
  cJSON* lc = cJSON_AddObjectToObject(rec, "label_points");
  cJSON* lt = cJSON_AddArrayToObject(rec, "labels");
  int64_t* count = res.cloud.nlabel ? vd_calloc((size_t)res.cloud.nlabel, sizeof(int64_t)) : NULL;
  if (res.cloud.nlabel && (!count || !cli_label_counts(&res.cloud, count))) {
    vd_free(count, (size_t)res.cloud.nlabel * sizeof(int64_t));
    vd_cloud_free(&res.cloud);
    cJSON_Delete(rec);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  for (int l = 0; l < res.cloud.nlabel; l++) {
    cJSON_AddNumberToObject(lc, res.cloud.labels[l].name, (double)count[l]);
    cJSON* e = cJSON_CreateObject();
    cJSON_AddNumberToObject(e, "id", res.cloud.labels[l].id);
    cJSON_AddStringToObject(e, "name", res.cloud.labels[l].name);
    cJSON_AddItemToArray(lt, e);
  }
  vd_free(count, (size_t)res.cloud.nlabel * sizeof(int64_t));
  cJSON_AddNumberToObject(rec, "bytes", (double)bytes);
  cJSON_AddStringToObject(rec, "sha256", hex);
  cJSON_AddStringToObject(rec, "parameters", ds->params);
  *points = res.cloud.n;
  vd_cloud_free(&res.cloud);
  // the pictures, then the record that makes the item complete
  if (ds->images) st = make_images(ds, pool, &po, i, seed, rec, err);
  if (!st) st = write_json(rpath, rec, 0, err);
  *out_failed = st != VD_OK;
  cJSON_Delete(rec);
  return st;
}

// ---------------------------------------------------------------------------------------------
// progress and the manifest

static void progress(const dataset* ds, int done, int total, double t0) {
  if (!ds->progress) return;
  double el = cli_now() - t0, rate = el > 0 ? done / el : 0;
  double eta = rate > 0 ? (total - done) / rate : 0;
  int w = 30, fill = total > 0 ? (int)((double)done / total * w) : w;
  char bar[64];
  for (int k = 0; k < w; k++)
    bar[k] = k < fill ? '#' : ' ';
  bar[w] = 0;
  fprintf(stderr, "\rdataset [%s] %d/%d items, %.1f items/s, ETA %.0f s   ", bar, done, total, rate, eta);
  if (done == total) cli_progress_clear();
  fflush(stderr);
}

// a record read back prints its seed and vary values exactly again (as written by make_item)
static void exact_numbers(cJSON* rec) {
  char num[40];
  cJSON* seed = cJSON_GetObjectItemCaseSensitive(rec, "seed");
  if (cJSON_IsNumber(seed) && seed->valuedouble >= 0 && seed->valuedouble < 9007199254740992.0) {
    snprintf(num, sizeof num, "%.0f", seed->valuedouble);
    cJSON_ReplaceItemInObjectCaseSensitive(rec, "seed", cJSON_CreateRaw(num));
  }
  cJSON* v;
  cJSON_ArrayForEach(v, cJSON_GetObjectItemCaseSensitive(rec, "vary")) {
    if (!cJSON_IsNumber(v)) continue;
    snprintf(num, sizeof num, "%.17g", v->valuedouble);
    char* raw = cJSON_malloc(strlen(num) + 1);
    if (!raw) continue;
    strcpy(raw, num);
    v->type = cJSON_Raw;
    v->valuestring = raw;
  }
}

// The command that makes one item's cloud again, as an argument list with the item's fields in
// braces ({seed}, {vary.NAME}): `verdant cloud` with the plant, the item's seed and --vary
// values, and every plant and cloud option of the dataset's command line (found with the same
// parsers) but those the dataset sets itself (--seed) or that do not change the bytes
// (--threads, --no-progress); images: the `verdant render` command of one view.
static cJSON* recipe(const dataset* ds, const char* plant, int images) {
  cJSON* a = cJSON_CreateArray();
  if (!a) return NULL;
  const char* head[] = {"verdant", images ? "render" : "cloud", plant, "--seed", "{seed}"};
  for (size_t k = 0; k < sizeof head / sizeof *head; k++) cJSON_AddItemToArray(a, cJSON_CreateString(head[k]));
  for (int k = 0; k < ds->nvary; k++) {
    char buf[96];
    snprintf(buf, sizeof buf, "%s={vary.%s}", ds->vary[k].name, ds->vary[k].name);
    cJSON_AddItemToArray(a, cJSON_CreateString("--set"));
    cJSON_AddItemToArray(a, cJSON_CreateString(buf));
  }
  cli_plant_opts po;
  cli_cloud_opts co;
  cli_plant_opts_init(&po);
  cli_cloud_opts_init(&co);
  for (int i = 1; i < ds->argc; i++) {
    int i0 = i, r = cli_plant_opt(&po, "dataset", ds->argc, ds->argv, &i), cloud = 0;
    if (r == 0) r = cli_cloud_opt(&co, "dataset", ds->argc, ds->argv, &i), cloud = 1;
    if (r <= 0) {
      // the dataset's own options: skip their values
      int takes = 0;
      const char* o = ds->argv[i];
      static const char* with_value[] = {"-K", "--count", "-o", "--output", "--format", "--jobs", "--shard",
                                         "--vary", "--images", "--image-size", "--palette", "--supersample",
                                         "--view-elevation", "--view-distance", "--view-jitter"};
      for (size_t k = 0; k < sizeof with_value / sizeof *with_value; k++) takes |= !strcmp(o, with_value[k]);
      i += takes;
      continue;
    }
    const char* o = ds->argv[i0];
    if (!strcmp(o, "--seed") || !strcmp(o, "--no-progress") || !strcmp(o, "--threads")) continue;
    // pictures take the plant options; clouds the cloud options too
    if (images && cloud) continue;
    for (int k = i0; k <= i; k++) cJSON_AddItemToArray(a, cJSON_CreateString(ds->argv[k]));
  }
  if (images) {
    char size[32];
    snprintf(size, sizeof size, "%dx%d", ds->img_w, ds->img_h);
    cli_view_recipe(&ds->view, a);
    const char* tail[] = {"--size", size, "--no-legend", "--depth", "--masks", "-o", "view.png"};
    for (size_t k = 0; k < sizeof tail / sizeof *tail; k++) cJSON_AddItemToArray(a, cJSON_CreateString(tail[k]));
  } else {
    char out[32];
    snprintf(out, sizeof out, "item.%s", ds->ext);
    cJSON_AddItemToArray(a, cJSON_CreateString("-o"));
    cJSON_AddItemToArray(a, cJSON_CreateString(out));
  }
  return a;
}

// the recipe as one shell line (arguments quoted where they need it)
static cJSON* recipe_line(const cJSON* a) {
  size_t cap = 64, n = 0;
  const cJSON* e;
  cJSON_ArrayForEach(e, a) cap += 3 * strlen(e->valuestring) + 3;
  char* buf = vd_malloc(cap);
  if (!buf) return NULL;
  buf[0] = 0;
  cJSON_ArrayForEach(e, a) {
    const char* v = e->valuestring;
    int plain = *v != 0;
    for (const char* c = v; *c; c++)
      plain &= !!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=.,:/{}@%", *c);
    n += (size_t)snprintf(buf + n, cap - n, "%s%s", n ? " " : "", plain ? "" : "'");
    for (const char* c = v; *c && n + 5 < cap; c++) {
      if (*c == '\'' && !plain)
        n += (size_t)snprintf(buf + n, cap - n, "'\\''");
      else
        buf[n++] = *c, buf[n] = 0;
    }
    if (!plain) n += (size_t)snprintf(buf + n, cap - n, "'");
  }
  cJSON* s = cJSON_CreateString(buf);
  vd_free(buf, cap);
  return s;
}

// put ",\n\t\"key\":\t<value>" on f (value printed compactly, then deleted)
static int put_field(FILE* f, int* first, const char* key, cJSON* value) {
  char* text = value ? cJSON_PrintUnformatted(value) : NULL;
  cJSON_Delete(value);
  if (!text) return 0;
  fprintf(f, "%s\n\t\"%s\":\t%s", *first ? "" : ",", key, text);
  *first = 0;
  cJSON_free(text);
  return 1;
}

// manifest.json when every item of the dataset is complete; 0 written, 1 not yet, -1 error.
// Written as a stream, one item at a time: its memory does not grow with the item count.
static int write_manifest(const dataset* ds, const cli_plant_opts* po, vd_error* err) {
  // first pass: every item complete? the label table (every id once, in order of first
  // appearance; with instance labels each item keeps its own table) and the total points
  int64_t total = 0;
  cJSON* labels = cJSON_CreateArray();
  if (!labels) {
    vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    return -1;
  }
  for (int i = 0; i < ds->count; i++) {
    int mismatch = 0;
    cJSON* rec = complete_record(ds, i, &mismatch);
    if (!rec) {
      cJSON_Delete(labels);
      return 1;
    }
    const cJSON* e;
    if (!ds->instance_labels) {
      cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(rec, "labels")) {
        const cJSON* id = cJSON_GetObjectItemCaseSensitive(e, "id");
        int seen = 0;
        const cJSON* o;
        cJSON_ArrayForEach(o, labels) {
          const cJSON* oid = cJSON_GetObjectItemCaseSensitive(o, "id");
          seen |= cJSON_IsNumber(oid) && cJSON_IsNumber(id) && oid->valuedouble == id->valuedouble;
        }
        if (!seen) cJSON_AddItemToArray(labels, cJSON_Duplicate(e, 1));
      }
    }
    const cJSON* pts = cJSON_GetObjectItemCaseSensitive(rec, "points");
    total += cJSON_IsNumber(pts) ? (int64_t)pts->valuedouble : 0;
    cJSON_Delete(rec);
  }
  // the header fields
  char path[4200];
  snprintf(path, sizeof path, "%s/manifest.json", ds->dir);
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (st) {
    cJSON_Delete(labels);
    return -1;
  }
  FILE* fp = f.fp;
  int first = 1, ok = 1;
  fputc('{', fp);
  ok &= put_field(fp, &first, "format", cJSON_CreateString(DATASET_FORMAT));
  ok &= put_field(fp, &first, "version", cJSON_CreateNumber(DATASET_VERSION));
  ok &= put_field(fp, &first, "plant", cJSON_CreateString(po->path));
  ok &= put_field(fp, &first, "count", cJSON_CreateNumber(ds->count));
  char seedtxt[32];
  snprintf(seedtxt, sizeof seedtxt, "%llu", (unsigned long long)ds->master);
  if (ds->master < (1ull << 53))
    ok &= put_field(fp, &first, "master_seed", cJSON_CreateRaw(seedtxt));
  else  // beyond a double's integers: as text
    ok &= put_field(fp, &first, "master_seed", cJSON_CreateString(seedtxt));
  ok &= put_field(fp, &first, "cloud_format", cJSON_CreateString(ds->ext));
  ok &= put_field(fp, &first, "points", cJSON_CreateNumber((double)total));
  cJSON* par = cJSON_CreateObject();
  if (par) {
    cJSON_AddStringToObject(par, "id", ds->params);
    cJSON_AddItemToObject(par, "arguments", cJSON_Duplicate(ds->arguments, 1));
    cJSON* vv = cJSON_AddObjectToObject(par, "vary");
    for (int k = 0; k < ds->nvary; k++) {
      double ab[2] = {ds->vary[k].a, ds->vary[k].b};
      cJSON_AddItemToObject(vv, ds->vary[k].name, cJSON_CreateDoubleArray(ab, 2));
    }
  }
  ok &= put_field(fp, &first, "parameters", par);
  // how to make an item again: the argument list, {seed} and {vary.NAME} from the item's record
  cJSON* regen = recipe(ds, po->path, 0);
  ok &= regen != NULL;
  if (regen) {
    ok &= put_field(fp, &first, "regenerate", recipe_line(regen));
    ok &= put_field(fp, &first, "regenerate_argv", regen);
  }
  if (ds->images) {
    cJSON* im = cJSON_CreateObject();
    if (im) {
      cJSON_AddNumberToObject(im, "per_item", ds->images);
      cJSON_AddNumberToObject(im, "width", ds->img_w);
      cJSON_AddNumberToObject(im, "height", ds->img_h);
      cJSON_AddStringToObject(im, "depth", "16-bit grey PNG, millimetres along the optical axis, 0 = nothing");
      cJSON_AddStringToObject(im, "masks", "16-bit grey PNG ids: label (the labels table), instance; 0 = background");
      // one view: {azimuth} and {elevation} from the view's entry in the item's record
      cJSON* view = recipe(ds, po->path, 1);
      if (view) {
        cJSON_AddItemToObject(im, "regenerate", recipe_line(view));
        cJSON_AddItemToObject(im, "regenerate_argv", view);
      }
    }
    ok &= put_field(fp, &first, "images", im);
  }
  if (ds->instance_labels)
    cJSON_Delete(labels);  // in the items
  else
    ok &= put_field(fp, &first, "labels", labels);
  // second pass: the items, one line each
  fputs(",\n\t\"items\":\t[", fp);
  for (int i = 0; ok && i < ds->count; i++) {
    int mismatch = 0;
    cJSON* rec = complete_record(ds, i, &mismatch);
    if (!rec) {  // removed since the first pass
      vd_outfile_abort(&f);
      return 1;
    }
    if (!ds->instance_labels) cJSON_DeleteItemFromObjectCaseSensitive(rec, "labels");
    cJSON_DeleteItemFromObjectCaseSensitive(rec, "parameters");
    exact_numbers(rec);
    char* text = cJSON_PrintUnformatted(rec);
    cJSON_Delete(rec);
    if (!text) {
      ok = 0;
      break;
    }
    fprintf(fp, "%s\n\t\t%s", i ? "," : "", text);
    cJSON_free(text);
  }
  fputs("]\n}\n", fp);
  if (!ok) {
    vd_outfile_abort(&f);
    vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    return -1;
  }
  st = vd_outfile_commit(&f, err);
  return st ? -1 : 0;
}

// an item's files appear together or not at all: its cloud, its pictures and its record (a
// failed item leaves nothing, and an item made again over an old one keeps the old one if it fails)
static vd_status make_item(const dataset* ds, render_pool* pool, const cli_plant_opts* po0, const cli_cloud_opts* co,
                           int i, int64_t* points, int* out_failed, vd_error* err) {
  int n = 2 + 5 * ds->images;
  char** path = vd_calloc((size_t)n, sizeof(char*));
  if (!path) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  vd_status st = VD_OK;
  char buf[5][4200];
  item_path(ds, i, ds->ext, buf[0], sizeof buf[0]);
  item_path(ds, i, "json", buf[1], sizeof buf[1]);
  for (int k = 0; k < 2 && !st; k++)
    if (!(path[k] = vd_strdup(buf[k]))) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int v = 0; v < ds->images && !st; v++) {
    char png[4200];
    snprintf(png, sizeof png, "%s/item_%0*d_view%d.png", ds->dir, ds->width, i, v);
    cli_frame_files(png, 1, 1, buf);
    for (int k = 0; k < 5 && !st; k++)
      if (!(path[2 + 5 * v + k] = vd_strdup(buf[k]))) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  if (!st) {
    // a complete item is put in place now (an interrupted dataset resumes from it); a failed one
    // leaves the item of an earlier run as it was
    st = make_item_files(ds, pool, po0, co, i, points, out_failed, err);
    if (cli_out_publish((const char* const*)path, n, st == VD_OK) && !st) {
      st = vd_error_set(err, VD_ERR_IO, path[0], 0, 0, "cannot put the item's files in place");
      *out_failed = 1;
    }
  } else {
    *out_failed = st != VD_ERR_NOMEM;
  }
  for (int k = 0; k < n; k++)
    if (path[k]) vd_free(path[k], strlen(path[k]) + 1);
  vd_free(path, (size_t)n * sizeof(char*));
  return st;
}

// ---------------------------------------------------------------------------------------------
// the command

static int parse_vary(const char* s, vary* v) {
  const char* eq = strchr(s, '=');
  if (!eq || eq == s || (size_t)(eq - s) >= sizeof v->name) return 0;
  memcpy(v->name, s, (size_t)(eq - s));
  v->name[eq - s] = 0;
  char* end;
  errno = 0;
  v->a = strtod(eq + 1, &end);
  if (end == eq + 1 || *end != ':' || errno || !isfinite(v->a)) return 0;
  const char* p = end + 1;
  v->b = strtod(p, &end);
  if (end == p || *end || errno || !isfinite(v->b) || v->b < v->a) return 0;
  // integer bounds (no point, no exponent, within +-2^53) draw integers
  char a[64];
  size_t n = (size_t)(p - 1 - (eq + 1));
  int64_t ia, ib;
  snprintf(a, sizeof a, "%.*s", (int)(n < sizeof a ? n : sizeof a - 1), eq + 1);
  v->integer = cli_parse_i64(a, -(1LL << 53), 1LL << 53, &ia) && cli_parse_i64(p, -(1LL << 53), 1LL << 53, &ib);
  return 1;
}

// every --vary names a global of the .lpy file; prints and returns EXIT_USAGE if not
static int check_vary(const dataset* ds, const char* path) {
  vd_lsystem* ls;
  vd_error err = {0};
  vd_status st = vd_lsys_load(path, &ls, &err);
  if (st) return cli_report("dataset", &err, st);
  int code = 0;
  for (int k = 0; k < ds->nvary && !code; k++) {
    vd_error e = {0};
    if (vd_lsys_set_global(ls, ds->vary[k].name, "0", &e) == VD_ERR_NAME)
      code = cli_usage_error("dataset", "--vary %s: %s defines no global '%s'", ds->vary[k].name, path,
                             ds->vary[k].name);
  }
  vd_lsys_destroy(ls);
  return code;
}

// options that do not change what an item holds: left out of the parameter id
static int neutral_option(const char* a, int* takes_value) {
  static const char* with_value[] = {"-o", "--output", "--jobs", "--shard", "--threads", "-K", "--count"};
  static const char* flags[] = {"--force", "--no-progress", "--stats", "--profile"};
  for (size_t k = 0; k < sizeof with_value / sizeof *with_value; k++)
    if (!strcmp(a, with_value[k])) return *takes_value = 1, 1;
  for (size_t k = 0; k < sizeof flags / sizeof *flags; k++)
    if (!strcmp(a, flags[k])) return *takes_value = 0, 1;
  return 0;
}

int cli_dataset(int argc, char** argv) {
  double t0 = cli_now();
  cli_plant_opts po;
  cli_plant_opts_init(&po);
  cli_cloud_opts co;
  cli_cloud_opts_init(&co);
  dataset ds;
  memset(&ds, 0, sizeof ds);
  ds.jobs = 1, ds.nshard = 1, ds.ext = "ply", ds.count = -1;
  ds.img_w = 640, ds.img_h = 480;
  cli_view_opts_init(&ds.view);
  ds.argc = argc, ds.argv = argv;
  int image_size_given = 0;
  ds.progress = po.progress;
  int stats = 0, profile = 0;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      fputs(dataset_usage, stdout);
      fputs(cli_view_help, stdout);
      fputs(cli_cloud_help, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
    int r = cli_plant_opt(&po, "dataset", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    r = cli_cloud_opt(&co, "dataset", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    r = cli_view_opt(&ds.view, "dataset", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    const char* val = i + 1 < argc ? argv[i + 1] : NULL;
    char* end;
    if (!strcmp(a, "-K") || !strcmp(a, "--count")) {
      long v = val ? (errno = 0, strtol(val, &end, 10)) : 0;
      if (!val || errno || *end || v < 1 || v > 100000000)
        return cli_usage_error("dataset", "%s expects an integer in 1..100000000", a);
      ds.count = (int)v, i++;
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (!val) return cli_usage_error("dataset", "%s needs a folder", a);
      ds.dir = val, i++;
    } else if (!strcmp(a, "--format")) {
      if (!val || (strcmp(val, "ply") != 0 && strcmp(val, "pcd") != 0 && strcmp(val, "xyz") != 0 && strcmp(val, "csv") != 0 && strcmp(val, "las") != 0))
        return cli_usage_error("dataset", "--format expects ply, pcd, xyz, csv or las");
      ds.ext = val, i++;
    } else if (!strcmp(a, "--jobs")) {
      long v = val ? (errno = 0, strtol(val, &end, 10)) : 0;
      if (!val || errno || *end || v < 1 || v > 1024) return cli_usage_error("dataset", "--jobs expects an integer in 1..1024");
      ds.jobs = (int)v, i++;
    } else if (!strcmp(a, "--shard")) {
      int64_t si, sn;
      if (!cli_parse_i64_pair(val, '/', 0, INT_MAX, &si, &sn) || sn < 1 || si >= sn)
        return cli_usage_error("dataset", "--shard expects I/N with 0 <= I < N, got '%s'", val ? val : "");
      ds.shard = (int)si, ds.nshard = (int)sn, i++;
    } else if (!strcmp(a, "--vary")) {
      if (ds.nvary == MAX_VARY) return cli_usage_error("dataset", "too many --vary options (%d at most)", MAX_VARY);
      if (!val || !parse_vary(val, &ds.vary[ds.nvary]))
        return cli_usage_error("dataset", "--vary expects NAME=A:B with A <= B, got '%s'", val ? val : "");
      ds.nvary++, i++;
    } else if (!strcmp(a, "--images")) {
      long v = val ? (errno = 0, strtol(val, &end, 10)) : 0;
      if (!val || errno || *end || v < 1 || v > 1000) return cli_usage_error("dataset", "--images expects an integer in 1..1000");
      ds.images = (int)v, i++;
    } else if (!strcmp(a, "--image-size")) {
      int64_t w, h;
      if (!cli_parse_i64_pair(val, 'x', 1, 8192, &w, &h))
        return cli_usage_error("dataset", "--image-size expects WxH with 1..8192 pixels each, got '%s'", val ? val : "");
      ds.img_w = (int)w, ds.img_h = (int)h, image_size_given = 1, i++;
    } else if (!strcmp(a, "--force")) {
      ds.force = 1;
    } else if (!strcmp(a, "--stats")) {
      stats = 1;
    } else if (!strcmp(a, "--profile")) {
      profile = 1;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error("dataset", "unknown option '%s'", a);
    } else if (!po.path) {
      po.path = a;
    } else {
      return cli_usage_error("dataset", "unexpected argument '%s'", a);
    }
  }
  if (!po.path) return cli_usage_error("dataset", "missing PLANT (an .lpy or plant .json file)");
  if (ds.count < 0) return cli_usage_error("dataset", "missing --count K");
  if (!ds.dir) return cli_usage_error("dataset", "missing -o DIR");
  if (profile && !stats) return cli_usage_error("dataset", "--profile adds timings to --stats; give --stats");
  if (ds.nvary && !cli_has_ext(po.path, ".lpy")) return cli_usage_error("dataset", "--vary applies to .lpy files only");
  if (cli_cloud_check(&co, "dataset") || cli_cloud_check_output(&co, "dataset", ds.ext)) return EXIT_USAGE;
  if (co.has_cloud_seed)
    return cli_usage_error("dataset", "--cloud-seed does not apply to a dataset: each item's cloud is seeded by its "
                           "item seed (from --seed)");
  if (image_size_given && !ds.images) return cli_usage_error("dataset", "--image-size goes with --images N");
  if (ds.view.given && !ds.images)
    return cli_usage_error("dataset", "the picture options (--no-shadows, --palette, --view-*, --vary-light, "
                                      "--vary-background, ...) go with --images N");
  // the files: the plant and the scanners read; the dataset folder written (manifest.json and
  // item_*; complete items are kept, so an interrupted dataset resumes)
  static const char* const members[] = {"manifest.json", "item_*"};
  cli_out_plant_opts(&po);
  cli_out_input("--scanners", co.scanners_file);
  cli_out_folder("-o", ds.dir, members, 2, 0);
  if (cli_out_check("dataset")) return EXIT_USAGE;
  ds.master = po.seed;
  ds.instance_labels = co.labels_instance;
  ds.progress = po.progress;
  ds.width = 6;
  for (int c = ds.count - 1; c >= 1000000; c /= 10) ds.width++;
  // the parameter id: the arguments that shape an item, in order (the plant path included)
  ds.arguments = cJSON_CreateArray();
  if (!ds.arguments) return EXIT_FAIL;
  uint64_t h = 1469598103934665603ull;
  for (int i = 1; i < argc; i++) {
    int takes = 0;
    if (neutral_option(argv[i], &takes)) {
      i += takes;
      continue;
    }
    cJSON_AddItemToArray(ds.arguments, cJSON_CreateString(argv[i]));
    h = fnv1a(h, argv[i], strlen(argv[i]) + 1);
  }
  h = fnv1a(h, ds.ext, strlen(ds.ext) + 1);
  snprintf(ds.params, sizeof ds.params, "%016llx", (unsigned long long)h);
  if (ds.nvary && check_vary(&ds, po.path)) {
    cJSON_Delete(ds.arguments);
    return EXIT_USAGE;
  }
  vd_error derr = {0};
  vd_status dst = vd_outdir_make(ds.dir, &derr);
  if (dst) {
    cJSON_Delete(ds.arguments);
    cli_report("dataset", &derr, dst);
    return EXIT_FAIL;
  }
  remove_stale(&ds);
  // this shard's items that are not complete yet
  int* todo = vd_malloc((size_t)ds.count * sizeof(int));
  if (!todo) {
    cJSON_Delete(ds.arguments);
    fprintf(stderr, "verdant dataset: out of memory\n");
    return EXIT_FAIL;
  }
  int ntodo = 0, skipped = 0, mismatch_at = -1;
  for (int i = ds.shard; i < ds.count; i += ds.nshard) {
    int mismatch = 0;
    cJSON* rec = ds.force ? NULL : complete_record(&ds, i, &mismatch);
    if (mismatch && mismatch_at < 0) mismatch_at = i;
    if (rec) {
      skipped++;
      cJSON_Delete(rec);
    } else {
      todo[ntodo++] = i;
    }
  }
  if (mismatch_at >= 0) {
    vd_free(todo, (size_t)ds.count * sizeof(int));
    cJSON_Delete(ds.arguments);
    fprintf(stderr, "verdant dataset: %s: item %d was made with other options; use another folder or --force\n",
            ds.dir, mismatch_at);
    return EXIT_USAGE;
  }
  // the items, --jobs at a time; the first failure (lowest item) stops the rest
  int done = 0, failed_item = -1, failed_output = 0;
  int64_t points = 0;
  vd_error first = {0};
  vd_status first_st = VD_OK;
  // pictures need an OpenGL context: make the first renderer now, so that its absence is one
  // clear failure before any item
  render_pool pool;
  memset(&pool, 0, sizeof pool);
  if (ds.images && ntodo) {
    int slot;
    vd_status st = pool_take(&pool, &ds, 16, &slot, &first);
    if (st) {
      vd_free(todo, (size_t)ds.count * sizeof(int));
      cJSON_Delete(ds.arguments);
      cli_report("dataset", &first, st);
      return EXIT_FAIL;
    }
    pool_put(&pool, slot);
  }
  progress(&ds, 0, ntodo, t0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(ds.jobs)
  for (int k = 0; k < ntodo; k++) {
    int stop;
#pragma omp atomic read
    stop = failed_item;
    if (stop >= 0) continue;
    vd_error err = {0};
    int64_t n = 0;
    int out_failed = 0;
    vd_status st = make_item(&ds, &pool, &po, &co, todo[k], &n, &out_failed, &err);
#pragma omp critical(dataset_progress)
    {
      if (st && (failed_item < 0 || todo[k] < failed_item)) {
        failed_item = todo[k];
        first = err;
        first_st = st;
        failed_output = out_failed;
      }
      if (!st) {
        done++;
        points += n;
        progress(&ds, done, ntodo, t0);
      }
    }
  }
  vd_free(todo, (size_t)ds.count * sizeof(int));
  pool_free(&pool);
  if (failed_item >= 0) {
    cJSON_Delete(ds.arguments);
    if (ds.progress) cli_progress_clear();
    char buf[1024];
    fprintf(stderr, "verdant dataset: item %d: %s\n", failed_item,
            first.status ? vd_error_format(&first, buf, sizeof buf) : vd_status_str(first_st));
    // writing the dataset failed (disk full, unwritable) or memory ran out: a failed run;
    // anything else is bad input
    return failed_output || first_st == VD_ERR_NOMEM ? EXIT_FAIL : cli_exit_code(first_st);
  }
  // the manifest, once the whole dataset (every shard) is complete
  vd_error err = {0};
  int m = write_manifest(&ds, &po, &err);
  cJSON_Delete(ds.arguments);
  if (m < 0) return cli_report("dataset", &err, err.status);
  double el = cli_now() - t0;
  if (stats) {
    printf("{\n\t\"made\":\t%d,\n\t\"skipped\":\t%d,\n\t\"points\":\t%lld,\n\t\"manifest\":\t%s", done, skipped,
           (long long)points, m == 0 ? "true" : "false");
    if (profile) printf(",\n\t\"seconds\":\t%.6f,\n\t\"items_per_second\":\t%.3f", el, el > 0 ? done / el : 0.0);
    printf("\n}\n");
  }
  return EXIT_OK;
}
