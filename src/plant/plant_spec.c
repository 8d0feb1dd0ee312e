// SPDX-License-Identifier: MIT
// The editable plant spec: growable element arrays, the label table kept sorted by id, organ
// kinds from label names, default label colours and the summary statistics.
#include "plant_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

// ---------------------------------------------------------------------------------------------
// lifetime

vd_plant_spec* vd_plant_spec_create(void) {
  vd_plant_spec* s = vd_calloc(1, sizeof *s);
  return s;
}

void vd_plant_spec_destroy(vd_plant_spec* s) {
  if (!s) return;
  // every array was grown by vd_grow, so its size is capacity x element size
  vd_free(s->node, (size_t)s->cap_node * sizeof *s->node);
  vd_free(s->seg, (size_t)s->cap_seg * sizeof *s->seg);
  vd_free(s->sphere, (size_t)s->cap_sphere * sizeof *s->sphere);
  vd_free(s->mesh, (size_t)s->cap_mesh * sizeof *s->mesh);
  vd_free(s->vert, (size_t)s->cap_vert * sizeof *s->vert);
  vd_free(s->tri, (size_t)s->cap_tri * 3 * sizeof *s->tri);
  vd_free(s->label, (size_t)s->cap_label * sizeof *s->label);
  vd_plant_set_stress(s, NULL, NULL);
  vd_free(s, sizeof *s);
}

vd_status vd_plant_set_stress(vd_plant_spec* s, const double* node, const double* seg) {
  vd_free(s->node_stress, (size_t)s->nstress_node * sizeof(double));
  vd_free(s->seg_stress, (size_t)s->nstress_seg * sizeof(double));
  s->node_stress = s->seg_stress = NULL;
  s->nstress_node = s->nstress_seg = 0;
  if (!node && !seg) return VD_OK;
  size_t nn = (size_t)(s->nnode ? s->nnode : 1), ns = (size_t)(s->nseg ? s->nseg : 1);
  double* a = vd_malloc(nn * sizeof(double));
  double* b = vd_malloc(ns * sizeof(double));
  if (!a || !b) {
    vd_free(a, nn * sizeof(double));
    vd_free(b, ns * sizeof(double));
    return VD_ERR_NOMEM;
  }
  for (int i = 0; i < s->nnode; i++) a[i] = node ? node[i] : NAN;
  for (int i = 0; i < s->nseg; i++) b[i] = seg ? seg[i] : NAN;
  s->node_stress = a, s->nstress_node = (int)nn;
  s->seg_stress = b, s->nstress_seg = (int)ns;
  return VD_OK;
}

int vd_plant_join_bases(vd_plant_spec* s) {
  int joined = 0;
  for (int j = 0; j < s->nseg; j++) {
    if (s->seg[j].parent >= 0) continue;
    int n = s->seg[j].node0;
    for (int k = 0; k < j; k++) {
      if (s->seg[k].parent >= 0) continue;
      int b = s->seg[k].node0;
      if (b == n) break;
      vd_vec3 x = s->node[n], y = s->node[b];
      if (x.x == y.x && x.y == y.y && x.z == y.z) {
        // n stays in the node list (indices of everything else are kept), unused by this segment
        s->seg[j].node0 = b;
        joined++;
        break;
      }
    }
  }
  return joined;
}

int vd_plant_has_stress(const vd_plant_spec* s) {
  return s->node_stress && s->seg_stress && s->nstress_node == (s->nnode ? s->nnode : 1) &&
         s->nstress_seg == (s->nseg ? s->nseg : 1);
}

// copy n elements of size elem into a new block of exactly n (capacity n); 1 on success
static int copy_array(void** dst, int* cap, const void* src, int n, size_t elem) {
  *dst = NULL;
  *cap = 0;
  if (n <= 0) return 1;
  *dst = vd_malloc((size_t)n * elem);
  if (!*dst) return 0;
  memcpy(*dst, src, (size_t)n * elem);
  *cap = n;
  return 1;
}

vd_plant_spec* vd_plant_spec_copy(const vd_plant_spec* s) {
  if (!s) return NULL;
  vd_plant_spec* c = vd_plant_spec_create();
  if (!c) return NULL;
  // each array at its exact size; capacities say so, so destroy frees the right sizes
  int ok = copy_array((void**)&c->node, &c->cap_node, s->node, s->nnode, sizeof *s->node) &&
           copy_array((void**)&c->seg, &c->cap_seg, s->seg, s->nseg, sizeof *s->seg) &&
           copy_array((void**)&c->sphere, &c->cap_sphere, s->sphere, s->nsphere, sizeof *s->sphere) &&
           copy_array((void**)&c->mesh, &c->cap_mesh, s->mesh, s->nmesh, sizeof *s->mesh) &&
           copy_array((void**)&c->vert, &c->cap_vert, s->vert, s->nvert, sizeof *s->vert) &&
           copy_array((void**)&c->tri, &c->cap_tri, s->tri, s->ntri, 3 * sizeof *s->tri) &&
           copy_array((void**)&c->label, &c->cap_label, s->label, s->nlabel, sizeof *s->label);
  if (!ok) {
    vd_plant_spec_destroy(c);
    return NULL;
  }
  c->nnode = s->nnode, c->nseg = s->nseg, c->nsphere = s->nsphere, c->nmesh = s->nmesh;
  c->nvert = s->nvert, c->ntri = s->ntri, c->nlabel = s->nlabel, c->ninstance = s->ninstance;
  // the stress a simulation attached comes along
  if (vd_plant_has_stress(s) && vd_plant_set_stress(c, s->node_stress, s->seg_stress)) {
    vd_plant_spec_destroy(c);
    return NULL;
  }
  return c;
}

void vd_plant_spec_clear(vd_plant_spec* s) {
  if (!s) return;
  s->nnode = s->nseg = s->nsphere = s->nmesh = s->nvert = s->ntri = s->nlabel = 0;
  s->ninstance = 0;
  vd_plant_set_stress(s, NULL, NULL);
}

// ---------------------------------------------------------------------------------------------
// defaults

vd_segment_spec vd_segment_spec_default(void) {
  vd_segment_spec g;
  memset(&g, 0, sizeof g);
  g.node0 = g.node1 = -1;
  g.r0 = g.r1 = 0.1;
  g.up = vd_v3(1, 0, 0);
  g.parent = -1;
  g.slices = 8;
  g.module = -1;
  return g;
}

vd_beam_def vd_beam_def_default(void) {
  vd_beam_def d;
  memset(&d, 0, sizeof d);
  d.dir = vd_v3(1, 0, 0);
  d.length = 0.1;
  d.radius = 0.001;
  d.clamp = 0.01;
  d.fruit_on_node = 1;
  d.label = "stem";
  return d;
}

vd_status vd_plant_beam(const vd_beam_def* d, vd_plant_spec** out, vd_error* err) {
  *out = NULL;
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "beam: out of memory");
  vd_vec3 up = fabs(d->dir.z) < 0.9 ? vd_v3(0, 0, 1) : vd_v3(1, 0, 0);
  int a = vd_plant_add_node(s, vd_madd(d->origin, d->dir, -d->clamp)), b = vd_plant_add_node(s, d->origin);
  int c = vd_plant_add_node(s, vd_madd(d->origin, d->dir, d->length));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = d->radius, g.label = 1, g.instance = 1, g.up = up;
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = d->one_instance ? 1 : 2;
  int s1 = vd_plant_add_segment(s, &g);
  vd_status st = a < 0 || b < 0 || c < 0 || s0 < 0 || s1 < 0 ? VD_ERR_NOMEM : vd_plant_set_label(s, 1, d->label);
  if (!st && d->fruit_radius > 0) {
    vd_sphere_spec f = vd_sphere_spec_default();
    f.center = vd_madd(d->origin, d->dir, d->length + d->fruit_offset), f.radius = d->fruit_radius;
    f.node = d->fruit_on_node ? c : -1, f.parent = s1, f.label = 2, f.instance = 3;
    st = vd_plant_add_sphere(s, &f) < 0 ? VD_ERR_NOMEM : vd_plant_set_label(s, 2, "fruit");
  }
  if (st) {
    vd_plant_spec_destroy(s);
    return vd_error_set(err, st, "", 0, 0, "beam: out of memory");
  }
  *out = s;
  return VD_OK;
}

vd_status vd_plant_beam_model(const vd_beam_def* d, vd_model** out, vd_error* err) {
  vd_plant_spec* s;
  *out = NULL;
  vd_status st = vd_plant_beam(d, &s, err);
  if (!st) st = vd_plant_compile(s, out, err);
  vd_plant_spec_destroy(s);
  return st;
}

vd_sphere_spec vd_sphere_spec_default(void) {
  vd_sphere_spec g;
  memset(&g, 0, sizeof g);
  g.radius = 0.1;
  g.node = g.parent = -1;
  g.slices = 8;
  g.module = -1;
  return g;
}

// ---------------------------------------------------------------------------------------------
// appending elements

int vd_plant_add_node(vd_plant_spec* s, vd_vec3 p) {
  if (!s || !vd_grow((void**)&s->node, &s->cap_node, s->nnode + 1, sizeof *s->node)) return -1;
  s->node[s->nnode] = p;
  return s->nnode++;
}

int vd_plant_add_segment(vd_plant_spec* s, const vd_segment_spec* g) {
  if (!s || !g || !vd_grow((void**)&s->seg, &s->cap_seg, s->nseg + 1, sizeof *s->seg)) return -1;
  s->seg[s->nseg] = *g;
  if (g->instance > s->ninstance) s->ninstance = g->instance;
  return s->nseg++;
}

int vd_plant_add_sphere(vd_plant_spec* s, const vd_sphere_spec* g) {
  if (!s || !g || !vd_grow((void**)&s->sphere, &s->cap_sphere, s->nsphere + 1, sizeof *s->sphere))
    return -1;
  s->sphere[s->nsphere] = *g;
  if (g->instance > s->ninstance) s->ninstance = g->instance;
  return s->nsphere++;
}

int vd_plant_add_mesh(vd_plant_spec* s, const vd_mesh_spec* m, const vd_vec3* verts, int nvert,
                      const int* tris, int ntri) {
  if (!s || !m || nvert < 0 || ntri < 0 || (nvert > 0 && !verts) || (ntri > 0 && !tris)) return -1;
  if (nvert > INT32_MAX - s->nvert || ntri > INT32_MAX / 3 - s->ntri) return -1;
  // grow all three arrays before touching any count, so a failure leaves the spec unchanged
  if (!vd_grow((void**)&s->mesh, &s->cap_mesh, s->nmesh + 1, sizeof *s->mesh)) return -1;
  if (!vd_grow((void**)&s->vert, &s->cap_vert, s->nvert + nvert, sizeof *s->vert)) return -1;
  // tri is (ntri x 3): its capacity counts triangles
  if (!vd_grow((void**)&s->tri, &s->cap_tri, s->ntri + ntri, 3 * sizeof *s->tri)) return -1;
  vd_mesh_spec* d = &s->mesh[s->nmesh];
  *d = *m;
  d->vert_start = s->nvert;
  d->nvert = nvert;
  d->tri_start = s->ntri;
  d->ntri = ntri;
  if (nvert > 0) memcpy(s->vert + s->nvert, verts, (size_t)nvert * sizeof *verts);
  // local indices become indices into the spec's vertex array; bad ones become -1 so that
  // compile reports them
  for (int k = 0; k < 3 * ntri; k++)
    s->tri[3 * s->ntri + k] = (tris[k] >= 0 && tris[k] < nvert) ? s->nvert + tris[k] : -1;
  s->nvert += nvert;
  s->ntri += ntri;
  if (m->instance > s->ninstance) s->ninstance = m->instance;
  return s->nmesh++;
}

// ---------------------------------------------------------------------------------------------
// organ kinds

static const char* organ_names[VD_ORGAN_COUNT] = {"other", "stem",    "leaf", "flower",
                                                  "fruit", "pedicel", "root"};

// keyword lists in priority order: fruit stalks before stem words, leaf stalks before stems
static const struct {
  vd_organ organ;
  const char* words[8];
} organ_words[] = {
    {VD_ORGAN_PEDICEL, {"pedicel", "peduncle"}},
    {VD_ORGAN_LEAF, {"leaf", "leaflet", "petiole", "cotyledon", "needle"}},
    {VD_ORGAN_FLOWER, {"flower", "petal", "bud", "inflorescence", "sepal"}},
    {VD_ORGAN_FRUIT, {"fruit", "berry", "silique", "pod", "seed", "tomato", "apple"}},
    {VD_ORGAN_ROOT, {"root"}},
    {VD_ORGAN_STEM, {"stem", "internode", "trunk", "branch", "shoot", "stalk"}},
};

vd_organ vd_organ_from_name(const char* name) {
  if (!name) return VD_ORGAN_OTHER;
  // lower-case copy of the name, bounded like a label name
  char low[VD_LABEL_NAME_MAX * 2];
  size_t n = 0;
  for (; name[n] && n + 1 < sizeof low; n++)
    low[n] = (char)tolower((unsigned char)name[n]);
  low[n] = 0;
  // first keyword group with a word contained in the name wins
  for (size_t g = 0; g < sizeof organ_words / sizeof organ_words[0]; g++)
    for (int w = 0; w < 8 && organ_words[g].words[w]; w++)
      if (strstr(low, organ_words[g].words[w])) return organ_words[g].organ;
  return VD_ORGAN_OTHER;
}

const char* vd_organ_name(vd_organ o) {
  if ((int)o < 0 || o >= VD_ORGAN_COUNT) return "other";
  return organ_names[o];
}

vd_organ vd_organ_parse(const char* name) {
  for (int o = 0; o < VD_ORGAN_COUNT; o++)
    if (name && strcmp(name, organ_names[o]) == 0) return (vd_organ)o;
  return VD_ORGAN_COUNT;
}

// ---------------------------------------------------------------------------------------------
// labels

void vd_plant_default_rgb(int id, float rgb[3]) {
  // L-Py-like palette for the first ids
  static const float palette[7][3] = {
      {0.60f, 0.60f, 0.60f}, // 0 grey
      {0.55f, 0.35f, 0.17f}, // 1 brown
      {0.30f, 0.65f, 0.20f}, // 2 green
      {0.85f, 0.20f, 0.15f}, // 3 red
      {0.95f, 0.85f, 0.20f}, // 4 yellow
      {0.20f, 0.40f, 0.85f}, // 5 blue
      {0.55f, 0.25f, 0.70f}, // 6 purple
  };
  if (id >= 0 && id < 7) {
    memcpy(rgb, palette[id], sizeof palette[id]);
    return;
  }
  // later ids: a hashed hue at fixed saturation and value, so colours are stable and distinct
  uint32_t h = (uint32_t)id * 2654435761u;
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  double hue = (double)(h % 360u) / 60.0, sat = 0.55 + 0.3 * (double)((h >> 9) % 100u) / 100.0;
  double val = 0.75 + 0.2 * (double)((h >> 17) % 100u) / 100.0;
  double c = val * sat, x = c * (1 - fabs(fmod(hue, 2.0) - 1)), m = val - c;
  double r = 0, g = 0, b = 0;
  switch ((int)hue) {
  case 0:
    r = c, g = x;
    break;
  case 1:
    r = x, g = c;
    break;
  case 2:
    g = c, b = x;
    break;
  case 3:
    g = x, b = c;
    break;
  case 4:
    r = x, b = c;
    break;
  default:
    r = c, b = x;
    break;
  }
  rgb[0] = (float)(r + m);
  rgb[1] = (float)(g + m);
  rgb[2] = (float)(b + m);
}

// index of the first label with id >= the given id (binary search in the sorted table)
static int label_lower_bound(const vd_label* l, int n, int id) {
  int lo = 0, hi = n;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (l[mid].id < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

// copy name into a label entry, cut at a UTF-8 character boundary
static void label_set_name(vd_label* l, const char* name) {
  size_t n = strlen(name);
  if (n > VD_LABEL_NAME_MAX - 1) {
    n = VD_LABEL_NAME_MAX - 1;
    while (n > 0 && ((unsigned char)name[n] & 0xC0) == 0x80)
      n--;
  }
  memcpy(l->name, name, n);
  l->name[n] = 0;
  l->organ = vd_organ_from_name(l->name);
}

// colour of a label: by organ kind when the name tells it (fruit red, leaf green, ...), with a
// small brightness shift by id so two labels of one organ stay apart; else the palette by id
static void label_rgb(const vd_label* l, float rgb[3]) {
  static const float organ_rgb[VD_ORGAN_COUNT][3] = {
      [VD_ORGAN_STEM] = {0.45f, 0.30f, 0.16f},   [VD_ORGAN_LEAF] = {0.26f, 0.56f, 0.18f},
      [VD_ORGAN_FLOWER] = {0.93f, 0.80f, 0.25f}, [VD_ORGAN_FRUIT] = {0.86f, 0.16f, 0.10f},
      [VD_ORGAN_PEDICEL] = {0.45f, 0.65f, 0.25f}, [VD_ORGAN_ROOT] = {0.72f, 0.58f, 0.38f}};
  if (l->organ == VD_ORGAN_OTHER) {
    vd_plant_default_rgb(l->id, rgb);
    return;
  }
  float f = 0.8f + 0.4f * (float)(((uint32_t)l->id * 37u) % 10u) / 10.0f;  // unsigned: any id
  for (int k = 0; k < 3; k++) {
    float c = organ_rgb[l->organ][k] * f;
    rgb[k] = c > 1 ? 1 : c;
  }
}

void vd_label_init(vd_label* l, int id, const char* name) {
  memset(l, 0, sizeof *l);
  l->id = id;
  label_set_name(l, name ? name : "");
  label_rgb(l, l->rgb);
}

vd_status vd_plant_set_label(vd_plant_spec* s, int id, const char* name) {
  if (!s || !name || id < 0) return VD_ERR_ARG;
  int k = label_lower_bound(s->label, s->nlabel, id);
  // rename an existing entry (its colour stays)
  if (k < s->nlabel && s->label[k].id == id) {
    vd_organ before = s->label[k].organ;
    label_set_name(&s->label[k], name);
    if (s->label[k].organ != before && s->label[k].organ != VD_ORGAN_OTHER) label_rgb(&s->label[k], s->label[k].rgb);
    return VD_OK;
  }
  // insert a new entry at its sorted place
  if (!vd_grow((void**)&s->label, &s->cap_label, s->nlabel + 1, sizeof *s->label))
    return VD_ERR_NOMEM;
  memmove(s->label + k + 1, s->label + k, (size_t)(s->nlabel - k) * sizeof *s->label);
  vd_label* l = &s->label[k];
  memset(l, 0, sizeof *l);
  l->id = id;
  label_set_name(l, name);
  label_rgb(l, l->rgb);
  s->nlabel++;
  return VD_OK;
}

const vd_label* vd_plant_find_label(const vd_plant_spec* s, int id) {
  if (!s) return NULL;
  int k = label_lower_bound(s->label, s->nlabel, id);
  return (k < s->nlabel && s->label[k].id == id) ? &s->label[k] : NULL;
}

// add "label_<id>" unless the id already has an entry (negative ids are left to validation)
static vd_status label_ensure(vd_plant_spec* s, int id) {
  if (id < 0 || vd_plant_find_label(s, id)) return VD_OK;
  char name[32];
  snprintf(name, sizeof name, "label_%d", id);
  return vd_plant_set_label(s, id, name);
}

vd_status vd_plant_complete_labels(vd_plant_spec* s) {
  if (!s) return VD_ERR_ARG;
  // every element kind in a fixed order, so the table is the same for the same spec
  vd_status st = VD_OK;
  for (int i = 0; i < s->nseg && !st; i++)
    st = label_ensure(s, s->seg[i].label);
  for (int i = 0; i < s->nsphere && !st; i++)
    st = label_ensure(s, s->sphere[i].label);
  for (int i = 0; i < s->nmesh && !st; i++)
    st = label_ensure(s, s->mesh[i].label);
  return st;
}

// ---------------------------------------------------------------------------------------------
// statistics

// grow the box [lo, hi] by the cube of half-size r around p
static void box_add(vd_vec3* lo, vd_vec3* hi, int* empty, vd_vec3 p, double r) {
  vd_vec3 a = vd_v3(p.x - r, p.y - r, p.z - r), b = vd_v3(p.x + r, p.y + r, p.z + r);
  if (*empty) {
    *lo = a, *hi = b, *empty = 0;
    return;
  }
  *lo = vd_vmin(*lo, a);
  *hi = vd_vmax(*hi, b);
}

static int node_ok(const vd_plant_spec* s, int i) {
  return i >= 0 && i < s->nnode;
}

void vd_plant_spec_stats(const vd_plant_spec* s, vd_plant_stats* out) {
  memset(out, 0, sizeof *out);
  if (!s) return;
  int empty = 1;
  vd_vec3 lo = vd_v3(0, 0, 0), hi = lo;
  // nodes as points, then segment ends grown by their radii
  for (int i = 0; i < s->nnode; i++)
    box_add(&lo, &hi, &empty, s->node[i], 0);
  for (int i = 0; i < s->nseg; i++) {
    const vd_segment_spec* g = &s->seg[i];
    if (!node_ok(s, g->node0) || !node_ok(s, g->node1)) continue;
    vd_vec3 a = s->node[g->node0], b = s->node[g->node1];
    box_add(&lo, &hi, &empty, a, g->r0);
    box_add(&lo, &hi, &empty, b, g->r1);
    out->total_length += vd_norm(vd_sub(b, a));
  }
  // spheres by their extents, mesh vertices as points
  for (int i = 0; i < s->nsphere; i++)
    box_add(&lo, &hi, &empty, s->sphere[i].center, s->sphere[i].radius);
  for (int i = 0; i < s->nvert; i++)
    box_add(&lo, &hi, &empty, s->vert[i], 0);
  for (int i = 0; i < s->nmesh; i++)
    if (!s->mesh[i].closed) out->nleaf++;
  out->bbox_min = lo;
  out->bbox_max = hi;
  out->nseg = s->nseg;
  out->nsphere = s->nsphere;
}
