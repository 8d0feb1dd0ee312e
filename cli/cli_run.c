// SPDX-License-Identifier: MIT
// Simulation runs on disk (`verdant sim -o DIR`): the rod build settings kept in rod.json, the
// collider poses of colliders.jsonl, and reading a run back: the initial plant is compiled, the
// rod model rebuilt with the run's settings (and checked against rod.json), and each frame
// loaded into a rod state and a plant state. The writers and the readers sit together here so
// that the two cannot drift apart.
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

// ---------------------------------------------------------------------------------------------
// build settings (rod.json "build")

// a number, or null for an infinite threshold
static cJSON* num_or_inf(double v) {
  return isinf(v) && v > 0 ? cJSON_CreateNull() : cJSON_CreateNumber(v);
}

cJSON* cli_sim_def_json(const vd_sim_def* def) {
  cJSON* o = cJSON_CreateObject();
  if (!o) return NULL;
  cJSON_AddNumberToObject(o, "segment_length", def->segment_length);
  cJSON_AddNumberToObject(o, "clamp_length", def->clamp_length);
  cJSON_AddNumberToObject(o, "clamp_roots", def->clamp_roots);
  cJSON_AddNumberToObject(o, "leaf_areal_density", def->leaf_areal_density);
  cJSON_AddNumberToObject(o, "leaf_vein_ratio", def->leaf_vein_ratio);
  cJSON_AddNumberToObject(o, "leaf_plate_cd", def->leaf_plate_cd);
  cJSON_AddNumberToObject(o, "leaf_graphs", def->leaf_graphs);
  cJSON_AddNumberToObject(o, "sag_free", def->sag_free);
  double g[3] = {def->gravity.x, def->gravity.y, def->gravity.z};
  cJSON_AddItemToObject(o, "gravity", cJSON_CreateDoubleArray(g, 3));
  cJSON_AddNumberToObject(o, "stake_spacing", def->stake_spacing);
  cJSON_AddNumberToObject(o, "stake_stiffness", def->stake_stiffness);
  // model choices of issue 13 (optional when read: runs made before have the defaults)
  cJSON_AddStringToObject(o, "bend_measure", vd_sim_bend_name(def->bend_measure));
  cJSON_AddNumberToObject(o, "leaf_segments", def->leaf_segments);
  cJSON* csl = cJSON_AddObjectToObject(o, "class_segment_length");
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++)
    if (def->class_segment_length[c] > 0)
      cJSON_AddNumberToObject(csl, vd_sim_class_name((vd_sim_class)c), def->class_segment_length[c]);
  cJSON* mats = cJSON_AddObjectToObject(o, "materials");
  for (int c = 0; c < VD_SIM_CLASS_COUNT; c++) {
    const vd_sim_material* mt = &def->material[c];
    cJSON* e = cJSON_AddObjectToObject(mats, vd_sim_class_name((vd_sim_class)c));
    cJSON_AddNumberToObject(e, "young", mt->young);
    cJSON_AddNumberToObject(e, "poisson", mt->poisson);
    cJSON_AddNumberToObject(e, "density", mt->density);
    cJSON_AddItemToObject(e, "break_force", num_or_inf(mt->break_force));
    cJSON_AddItemToObject(e, "break_moment", num_or_inf(mt->break_moment));
    cJSON_AddItemToObject(e, "break_cs", num_or_inf(mt->break_cs));
    cJSON_AddItemToObject(e, "break_cb", num_or_inf(mt->break_cb));
    cJSON_AddNumberToObject(e, "drag_cd", mt->drag_cd);
  }
  return o;
}

// read number key of o into *v (null: +infinity when inf_ok); an error names the field
static vd_status get_num(const cJSON* o, const char* key, int inf_ok, double* v, const char* path,
                         const char* where, vd_error* err) {
  const cJSON* x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (inf_ok && cJSON_IsNull(x)) {
    *v = INFINITY;
    return VD_OK;
  }
  if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble))
    return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "%s.%s: expected a number%s", where, key,
                        inf_ok ? " or null" : "");
  *v = x->valuedouble;
  return VD_OK;
}

vd_status cli_sim_def_parse(const cJSON* o, const char* path, vd_sim_def* def, vd_error* err) {
  *def = vd_sim_def_default();
  if (!cJSON_IsObject(o))
    return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0,
                        "no \"build\" settings (a run of an older 'verdant sim': make it again)");
  double flags[4] = {0};
  vd_status st = VD_OK;
  static const char* ints[4] = {"clamp_roots", "leaf_graphs", "sag_free", NULL};
  st = get_num(o, "segment_length", 0, &def->segment_length, path, "build", err);
  if (!st) st = get_num(o, "clamp_length", 0, &def->clamp_length, path, "build", err);
  for (int k = 0; !st && ints[k]; k++)
    st = get_num(o, ints[k], 0, &flags[k], path, "build", err);
  if (!st)
    def->clamp_roots = (int)flags[0], def->leaf_graphs = (int)flags[1],
    def->sag_free = (int)flags[2];
  if (!st) st = get_num(o, "leaf_areal_density", 0, &def->leaf_areal_density, path, "build", err);
  if (!st) st = get_num(o, "leaf_vein_ratio", 0, &def->leaf_vein_ratio, path, "build", err);
  if (!st) st = get_num(o, "leaf_plate_cd", 0, &def->leaf_plate_cd, path, "build", err);
  if (!st) st = get_num(o, "stake_spacing", 0, &def->stake_spacing, path, "build", err);
  if (!st) st = get_num(o, "stake_stiffness", 0, &def->stake_stiffness, path, "build", err);
  if (st) return st;
  const cJSON* bm = cJSON_GetObjectItemCaseSensitive(o, "bend_measure");
  if (bm) {
    int k = cJSON_IsString(bm) ? vd_sim_bend_parse(bm->valuestring) : -1;
    if (k < 0) return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "build.bend_measure: expected \"log\" or \"quat\"");
    def->bend_measure = (vd_sim_bend)k;
  } else {
    def->bend_measure = VD_SIM_BEND_QUAT;  // runs made before the log measure
  }
  if (cJSON_GetObjectItemCaseSensitive(o, "leaf_segments")) {
    double ls = 0;
    if ((st = get_num(o, "leaf_segments", 0, &ls, path, "build", err))) return st;
    def->leaf_segments = (int)ls;
  }
  const cJSON* csl = cJSON_GetObjectItemCaseSensitive(o, "class_segment_length");
  for (int c = 0; csl && c < VD_SIM_CLASS_COUNT; c++) {
    const char* name = vd_sim_class_name((vd_sim_class)c);
    if (cJSON_GetObjectItemCaseSensitive(csl, name) &&
        (st = get_num(csl, name, 0, &def->class_segment_length[c], path, "build.class_segment_length", err)))
      return st;
  }
  const cJSON* g = cJSON_GetObjectItemCaseSensitive(o, "gravity");
  if (!cJSON_IsArray(g) || cJSON_GetArraySize(g) != 3)
    return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0,
                        "build.gravity: expected [x, y, z] (m/s^2)");
  double gv[3];
  for (int k = 0; k < 3; k++) {
    const cJSON* x = cJSON_GetArrayItem(g, k);
    if (!cJSON_IsNumber(x))
      return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0,
                          "build.gravity: expected [x, y, z] (m/s^2)");
    gv[k] = x->valuedouble;
  }
  def->gravity = vd_v3(gv[0], gv[1], gv[2]);
  const cJSON* mats = cJSON_GetObjectItemCaseSensitive(o, "materials");
  for (int c = 0; c < VD_SIM_CLASS_COUNT && !st; c++) {
    const char* name = vd_sim_class_name((vd_sim_class)c);
    const cJSON* e = cJSON_GetObjectItemCaseSensitive(mats, name);
    char where[64];
    snprintf(where, sizeof where, "build.materials.%s", name);
    if (!cJSON_IsObject(e))
      return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "%s: missing", where);
    vd_sim_material* mt = &def->material[c];
    st = get_num(e, "young", 0, &mt->young, path, where, err);
    if (!st) st = get_num(e, "poisson", 0, &mt->poisson, path, where, err);
    if (!st) st = get_num(e, "density", 0, &mt->density, path, where, err);
    if (!st) st = get_num(e, "break_force", 1, &mt->break_force, path, where, err);
    if (!st) st = get_num(e, "break_moment", 1, &mt->break_moment, path, where, err);
    if (!st) st = get_num(e, "break_cs", 1, &mt->break_cs, path, where, err);
    if (!st) st = get_num(e, "break_cb", 1, &mt->break_cb, path, where, err);
    if (!st) st = get_num(e, "drag_cd", 0, &mt->drag_cd, path, where, err);
  }
  return st;
}

// ---------------------------------------------------------------------------------------------
// frames (frames.bin or frames.jsonl, with colliders.jsonl) and the rod topology (rod.json)

static void put_u32(unsigned char* b, uint32_t v) {
  for (int k = 0; k < 4; k++) b[k] = (unsigned char)(v >> (8 * k));
}

static void put_f64(unsigned char* b, double d) {
  uint64_t u;
  memcpy(&u, &d, 8);
  for (int k = 0; k < 8; k++) b[k] = (unsigned char)(u >> (8 * k));
}

static void put_f32(unsigned char* b, float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  put_u32(b, u);
}

const char* const cli_run_members[] = {"frames.bin",         "frames.jsonl", "colliders.jsonl",
                                       "rod.json",           "plant_initial.json", "events.csv",
                                       "plant.json",         "item_*/plant.json",  "item_*/events.csv"};
const int cli_run_nmember = (int)(sizeof cli_run_members / sizeof *cli_run_members);

vd_status cli_frames_begin(cli_frames* o, const vd_sim_model* m, const char* dir, int jsonl, vd_error* err) {
  char path[4096];
  snprintf(path, sizeof path, "%s/frames.%s", dir, jsonl ? "jsonl" : "bin");
  vd_status st = vd_outfile_open(&o->frames, path, err);
  if (st) return st;
  o->frames_open = 1;
  o->jsonl = jsonl;
  // the colliders' poses at the same instants (for pictures of the run)
  snprintf(path, sizeof path, "%s/colliders.jsonl", dir);
  if ((st = vd_outfile_open(&o->colliders, path, err))) return st;
  o->colliders_open = 1;
  if (!jsonl) {
    // header: magic, version, node count, segment count, reserved (little-endian)
    unsigned char h[24];
    memcpy(h, "VDSIMFRM", 8);  // NOLINT(bugprone-not-null-terminated-result): an 8-byte magic, no NUL
    put_u32(h + 8, VD_SIM_FRAMES_VERSION);
    put_u32(h + 12, (uint32_t)m->nnode_all);
    put_u32(h + 16, (uint32_t)m->nseg);
    put_u32(h + 20, 0);
    fwrite(h, 1, sizeof h, o->frames.fp);
    o->fbuf_n = 8 + 4 * (3 * (size_t)m->nnode_all + 4 * (size_t)m->nseg) + (size_t)m->nseg;
    o->bbuf = vd_malloc(o->fbuf_n);
    if (!o->bbuf) return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  }
  return VD_OK;
}

int cli_frames_write(cli_frames* o, const vd_sim_model* m, const vd_sim_data* d) {
  FILE* f = o->frames.fp;
  cli_colliders_write(o->colliders.fp, d);
  if (o->jsonl) {
    fprintf(f, "{\"t\":%.9g,\"pos\":[", d->time);
    for (int i = 0; i < m->nnode_all; i++)
      fprintf(f, "%s%.7g,%.7g,%.7g", i ? "," : "", d->node_pos[i].x, d->node_pos[i].y, d->node_pos[i].z);
    fputs("],\"quat\":[", f);
    for (int t = 0; t < m->nseg; t++)
      fprintf(f, "%s%.7g,%.7g,%.7g,%.7g", t ? "," : "", d->seg_quat[t].w, d->seg_quat[t].x, d->seg_quat[t].y,
              d->seg_quat[t].z);
    fputs("],\"broken\":[", f);
    int first = 1;
    for (int t = 0; t < m->nseg; t++)
      if (d->seg_broken[t]) fprintf(f, "%s%d", first ? "" : ",", t), first = 0;
    fputs("]}\n", f);
    return ferror(f) || ferror(o->colliders.fp);
  }
  unsigned char* b = o->bbuf;
  put_f64(b, d->time);
  b += 8;
  for (int i = 0; i < m->nnode_all; i++, b += 12)
    put_f32(b, (float)d->node_pos[i].x), put_f32(b + 4, (float)d->node_pos[i].y), put_f32(b + 8, (float)d->node_pos[i].z);
  for (int t = 0; t < m->nseg; t++, b += 16) {
    vd_quat q = d->seg_quat[t];
    put_f32(b, (float)q.w), put_f32(b + 4, (float)q.x), put_f32(b + 8, (float)q.y), put_f32(b + 12, (float)q.z);
  }
  for (int t = 0; t < m->nseg; t++) *b++ = (unsigned char)(d->seg_broken[t] ? 1 : 0);  // NOLINT(clang-analyzer-core.NullDereference): bbuf exists for binary frames; JSONL returned above
  fwrite(o->bbuf, 1, o->fbuf_n, f);
  return ferror(f) || ferror(o->colliders.fp);
}

vd_status cli_rod_json_write(const vd_sim_model* m, const vd_model* plant, const vd_sim_def* def, const char* dir,
                                vd_error* err) {
  cJSON* root = cJSON_CreateObject();
  if (!root) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  cJSON_AddStringToObject(root, "format", "verdant-rod");
  cJSON_AddNumberToObject(root, "version", VD_SIM_FRAMES_VERSION);
  cJSON_AddNumberToObject(root, "nodes", m->nnode_all);
  cJSON_AddNumberToObject(root, "segments", m->nseg);
  cJSON* np = cJSON_AddArrayToObject(root, "node_pos0");
  for (int i = 0; i < m->nnode_all; i++) {
    cJSON_AddItemToArray(np, cJSON_CreateNumber(m->node_pos0[i].x));
    cJSON_AddItemToArray(np, cJSON_CreateNumber(m->node_pos0[i].y));
    cJSON_AddItemToArray(np, cJSON_CreateNumber(m->node_pos0[i].z));
  }
  cJSON_AddItemToObject(root, "node_sphere", cJSON_CreateDoubleArray(m->node_sphere, m->nnode_all));
  cJSON_AddItemToObject(root, "seg_node", cJSON_CreateIntArray(m->seg_node, 2 * m->nseg));
  cJSON_AddItemToObject(root, "seg_spare", cJSON_CreateIntArray(m->seg_spare, m->nseg));
  cJSON_AddItemToObject(root, "seg_radius", cJSON_CreateDoubleArray(m->seg_radius, m->nseg));
  cJSON_AddItemToObject(root, "seg_label", cJSON_CreateIntArray(m->seg_label, m->nseg));
  cJSON_AddItemToObject(root, "seg_instance", cJSON_CreateIntArray(m->seg_instance, m->nseg));
  cJSON* cls = cJSON_AddArrayToObject(root, "seg_class");
  for (int t = 0; t < m->nseg; t++) cJSON_AddItemToArray(cls, cJSON_CreateString(vd_sim_class_name(m->seg_class[t])));
  cJSON* labels = cJSON_AddObjectToObject(root, "labels");
  for (int k = 0; k < plant->nlabel; k++) {
    char id[16];
    snprintf(id, sizeof id, "%d", plant->labels[k].id);
    cJSON_AddStringToObject(labels, id, plant->labels[k].name);
  }
  // what rebuilds this rod model: the initial plant and the build settings
  cJSON_AddStringToObject(root, "initial_plant", "plant_initial.json");
  cJSON_AddItemToObject(root, "build", cli_sim_def_json(def));
  char* text = cJSON_PrintUnformatted(root);
  cJSON_Delete(root);
  if (!text) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  char path[4096];
  snprintf(path, sizeof path, "%s/rod.json", dir);
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (!st) {
    fputs(text, f.fp);
    fputc('\n', f.fp);
    st = vd_outfile_commit(&f, err);
  }
  cJSON_free(text);
  return st;
}

vd_status cli_frames_end(cli_frames* o, vd_error* err) {
  vd_status st = VD_OK;
  if (o->frames_open) st = vd_outfile_commit(&o->frames, err);
  o->frames_open = 0;
  if (o->colliders_open) {  // kept only beside complete frames
    vd_status s2 = VD_OK;
    if (st) vd_outfile_abort(&o->colliders);
    else s2 = vd_outfile_commit(&o->colliders, err);
    st = st ? st : s2;
    o->colliders_open = 0;
  }
  cli_frames_abort(o);
  return st;
}

void cli_frames_abort(cli_frames* o) {
  if (o->frames_open) vd_outfile_abort(&o->frames);
  if (o->colliders_open) vd_outfile_abort(&o->colliders);
  o->frames_open = o->colliders_open = 0;
  vd_free(o->bbuf, o->fbuf_n);
  o->bbuf = NULL;
}

// ---------------------------------------------------------------------------------------------
// colliders (colliders.jsonl: one line per frame)

// (a mesh collider is named but not drawn: its distance grid is not in the run)
static const char* shape_names[5] = {"plane", "sphere", "capsule", "box", "mesh"};

void cli_colliders_write(FILE* fp, const vd_sim_data* d) {
  fprintf(fp, "{\"t\":%.9g,\"colliders\":[", d->time);
  for (int i = 0; i < d->ncollider; i++) {
    const vd_sim_collider* c = &d->collider[i];
    fprintf(fp,
            "%s{\"shape\":\"%s\",\"size\":[%.9g,%.9g,%.9g],\"pos\":[%.9g,%.9g,%.9g],\"quat\":[%.9g,"
            "%.9g,%.9g,%.9g]}",
            i ? "," : "", shape_names[c->shape], c->size[0], c->size[1], c->size[2], c->pos.x,
            c->pos.y, c->pos.z, c->quat.w, c->quat.x, c->quat.y, c->quat.z);
  }
  fputs("]}\n", fp);
}

// n numbers of array key of o into v; 0 when missing, short or not numbers
static int get_vec(const cJSON* o, const char* key, double* v, int n) {
  const cJSON* a = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return 0;
  int k = 0;
  const cJSON* x;
  cJSON_ArrayForEach(x, a) {
    if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) return 0;
    v[k++] = x->valuedouble;
  }
  return 1;
}

// read colliders.jsonl: one line per frame (nframe lines), each a list of colliders
static vd_status read_colliders(cli_run* run, const char* path, vd_error* err) {
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  run->col_start = vd_calloc((size_t)run->nframe + 1, sizeof(int));
  if (!run->col_start) st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory");
  int frame = 0, line = 0;
  for (char* p = text; !st && *p;) {
    line++;
    char* e = strchr(p, '\n');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    char* next = e ? e + 1 : p + n;
    size_t blank = strspn(p, " \t\r");
    if (blank >= n) {
      p = next;
      continue;
    }
    if (frame >= run->nframe) {
      st = vd_error_set(err, VD_ERR_FORMAT, path, line, 0, "more lines than the run's %d frames",
                        run->nframe);
      break;
    }
    cJSON* o = cJSON_ParseWithLength(p, n);
    const cJSON* list = cJSON_GetObjectItemCaseSensitive(o, "colliders");
    if (!cJSON_IsArray(list))
      st = vd_error_set(err, VD_ERR_FORMAT, path, line, 0,
                        "expected {\"t\": T, \"colliders\": [...]}");
    const cJSON* c;
    int idx = 0;
    cJSON_ArrayForEach(c, list) {
      if (st) break;
      vd_sim_collider col;
      memset(&col, 0, sizeof col);
      const cJSON* shape = cJSON_GetObjectItemCaseSensitive(c, "shape");
      int kind = -1;
      for (int k = 0; k < 5 && cJSON_IsString(shape); k++)
        if (!strcmp(shape->valuestring, shape_names[k])) kind = k;
      double q[4] = {0}, pos[3] = {0};
      if (kind < 0 || !get_vec(c, "size", col.size, 3) || !get_vec(c, "pos", pos, 3) ||
          !get_vec(c, "quat", q, 4)) {
        st = vd_error_set(err, VD_ERR_FORMAT, path, line, 0,
                          "collider %d: expected shape (plane, sphere, capsule, box, mesh), size [3], "
                          "pos [3], quat [4]",
                          idx);
        break;
      }
      if (kind == VD_SIM_MESH) {
        idx++;
        continue;
      }
      col.shape = (vd_sim_shape)kind;
      col.pos = vd_v3(pos[0], pos[1], pos[2]);
      col.quat = (vd_quat){q[0], q[1], q[2], q[3]};
      int cap = run->cap_col;
      if (!vd_grow((void**)&run->col, &cap, run->ncol + 1, sizeof(vd_sim_collider))) {
        st = vd_error_set(err, VD_ERR_NOMEM, path, line, 0, "out of memory");
        break;
      }
      run->cap_col = cap;
      run->col[run->ncol++] = col;
      idx++;
    }
    cJSON_Delete(o);
    run->col_start[++frame] = run->ncol;  // NOLINT(clang-analyzer-core.NullDereference): col_start holds nframe + 1 entries; frame < nframe here
    p = next;
  }
  vd_free(text, len + 1);
  if (!st && frame != run->nframe)
    st = vd_error_set(err, VD_ERR_FORMAT, path, line, 0, "%d lines for the run's %d frames", frame,
                      run->nframe);
  return st;
}

// ---------------------------------------------------------------------------------------------
// reading a run

// rod.json's sizes and rest positions against the rebuilt model
static vd_status check_rod(const cJSON* rod, const vd_sim_model* m, const char* path,
                           vd_error* err) {
  const cJSON* nodes = cJSON_GetObjectItemCaseSensitive(rod, "nodes");
  const cJSON* segs = cJSON_GetObjectItemCaseSensitive(rod, "segments");
  const cJSON* pos0 = cJSON_GetObjectItemCaseSensitive(rod, "node_pos0");
  int ok = cJSON_IsNumber(nodes) && cJSON_IsNumber(segs) && nodes->valuedouble == m->nnode_all &&
           segs->valuedouble == m->nseg && cJSON_IsArray(pos0) &&
           cJSON_GetArraySize(pos0) == 3 * m->nnode_all;
  const cJSON* x = ok ? pos0->child : NULL;
  for (int i = 0; ok && i < m->nnode_all; i++) {
    double p[3] = {m->node_pos0[i].x, m->node_pos0[i].y, m->node_pos0[i].z};
    for (int k = 0; k < 3 && ok; k++, x = x->next)
      ok = cJSON_IsNumber(x) && fabs(x->valuedouble - p[k]) <= 1e-9;
  }
  if (!ok)
    return vd_error_set(
        err, VD_ERR_FORMAT, path, 0, 0,
        "the rod model rebuilt from plant_initial.json and the build settings differs from "
        "this file (%d nodes, %d segments rebuilt): was the run made by another verdant?",
        m->nnode_all, m->nseg);
  return VD_OK;
}

vd_status cli_run_open(const char* dir, cli_run* run, vd_error* err) {
  memset(run, 0, sizeof *run);
  snprintf(run->dir, sizeof run->dir, "%s", dir);
  size_t n = strlen(run->dir);
  while (n > 1 && run->dir[n - 1] == '/')
    run->dir[--n] = 0;
  char path[4200];
  // rod.json: the build settings
  snprintf(path, sizeof path, "%s/rod.json", run->dir);
  char* text;
  size_t len;
  vd_status st = vd_file_read(path, &text, &len, err);
  if (st) return st;
  cJSON* rod = cJSON_ParseWithLength(text, len);
  vd_free(text, len + 1);
  const cJSON* format = cJSON_GetObjectItemCaseSensitive(rod, "format");
  if (!cJSON_IsString(format) || strcmp(format->valuestring, "verdant-rod") != 0) {
    cJSON_Delete(rod);
    return vd_error_set(err, VD_ERR_FORMAT, path, 0, 0,
                        "not a verdant rod file (\"format\": \"verdant-rod\")");
  }
  vd_sim_def def;
  st = cli_sim_def_parse(cJSON_GetObjectItemCaseSensitive(rod, "build"), path, &def, err);
  // the initial plant, compiled; the rod model rebuilt from it
  char ppath[4200];
  snprintf(ppath, sizeof ppath, "%s/plant_initial.json", run->dir);
  if (!st) st = vd_plant_read_json(ppath, &run->spec, err);
  if (!st) st = vd_plant_compile(run->spec, &run->plant, err);
  if (!st) st = vd_sim_build(run->plant, &def, &run->sim, err);
  if (!st) st = check_rod(rod, run->sim, path, err);
  cJSON_Delete(rod);
  if (!st) {
    run->state = vd_sim_data_create(run->sim);
    run->pstate = vd_data_create(run->plant);
    if (!run->state || !run->pstate)
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  // the frames: binary or JSON Lines
  if (!st) {
    snprintf(path, sizeof path, "%s/frames.bin", run->dir);
    if (access(path, F_OK) != 0) snprintf(path, sizeof path, "%s/frames.jsonl", run->dir);
    if (access(path, F_OK) != 0)
      st = vd_error_set(err, VD_ERR_IO, run->dir, 0, 0,
                        "no frames.bin or frames.jsonl (made with --frames none?)");
    else
      st = vd_sim_frames_open(path, &run->frames, err);
  }
  if (!st) {
    run->nframe = vd_sim_frames_count(run->frames);
    if (!run->nframe) st = vd_error_set(err, VD_ERR_FORMAT, path, 0, 0, "no frames in the file");
  }
  // the colliders, when recorded
  snprintf(path, sizeof path, "%s/colliders.jsonl", run->dir);
  if (!st && access(path, F_OK) == 0) st = read_colliders(run, path, err);
  if (st) cli_run_close(run);
  return st;
}

vd_status cli_run_load(cli_run* run, int k, vd_error* err) {
  vd_status st = vd_sim_frames_load(run->frames, k, run->sim, run->state, err);
  if (!st) vd_sim_to_plant(run->sim, run->state, run->plant, run->pstate);
  return st;
}

int cli_run_colliders(const cli_run* run, int k, const vd_sim_collider** out) {
  if (!run->col_start) {
    *out = NULL;
    return 0;
  }
  *out = run->col + run->col_start[k];
  return run->col_start[k + 1] - run->col_start[k];
}

void cli_run_close(cli_run* run) {
  vd_sim_frames_close(run->frames);
  vd_data_destroy(run->pstate);
  vd_sim_data_destroy(run->state);
  vd_sim_model_destroy(run->sim);
  vd_model_destroy(run->plant);
  vd_plant_spec_destroy(run->spec);
  vd_free(run->col_start, run->col_start ? ((size_t)run->nframe + 1) * sizeof(int) : 0);
  vd_free(run->col, (size_t)run->cap_col * sizeof(vd_sim_collider));
  memset(run, 0, sizeof *run);
}
