// SPDX-License-Identifier: MIT
// What a frame shows: plants tessellated into one display list per organ instance (so that the
// id pass writes exact label and instance masks), point clouds grouped the same way and splatted
// as camera-facing squares, colours by label, instance, stress or displacement, and the legend.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"

// ---------------------------------------------------------------------------------------------
// colours

// viridis at 9 evenly spaced points (matplotlib's colour map, sampled)
static const float viridis[9][3] = {
    {0.267f, 0.005f, 0.329f}, {0.279f, 0.175f, 0.483f}, {0.230f, 0.322f, 0.546f},
    {0.173f, 0.449f, 0.558f}, {0.128f, 0.567f, 0.551f}, {0.153f, 0.683f, 0.502f},
    {0.369f, 0.789f, 0.383f}, {0.678f, 0.864f, 0.190f}, {0.993f, 0.906f, 0.144f}};

void render_colormap(double t, float rgb[3]) {
  if (!(t >= 0)) t = 0; // NaN too
  if (t > 1) t = 1;
  double x = t * 8;
  int i = (int)x;
  if (i > 7) i = 7;
  double f = x - i;
  for (int k = 0; k < 3; k++)
    rgb[k] = (float)(viridis[i][k] * (1 - f) + viridis[i + 1][k] * f);
}

// a distinct colour per instance: hues by the golden ratio
static void instance_rgb(int inst, float rgb[3]) {
  double h = fmod(inst * 0.6180339887498949, 1.0) * 6, s = 0.65, v = 0.92;
  int i = (int)h;
  double f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double c[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  for (int k = 0; k < 3; k++)
    rgb[k] = (float)c[i % 6][k];
}

// grey for primitives without a value (leaves and fruits under colour by stress)
static const float no_value_rgb[3] = {0.62f, 0.62f, 0.62f};

// ---------------------------------------------------------------------------------------------
// tables

// append an item; NULL when out of memory
static item* new_item(vd_renderer* r) {
  if (r->nitem == r->cap_item) {
    int cap = r->cap_item;
    if (!vd_grow((void**)&r->items, &cap, r->nitem + 1, sizeof(item))) return NULL;
    r->cap_item = cap;
  }
  item* it = &r->items[r->nitem++];
  memset(it, 0, sizeof *it);
  it->cloud = -1;
  it->rgba[3] = 1;
  return it;
}

// add a label to the legend (sorted by id; the first name given for an id stays)
static vd_status legend_add(vd_renderer* r, int id, const char* name, const float rgb[3]) {
  int lo = 0, hi = r->nlegend;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (r->legend[mid].id < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (lo < r->nlegend && r->legend[lo].id == id) return VD_OK;
  if (r->nlegend == r->cap_legend) {
    int cap = r->cap_legend;
    if (!vd_grow((void**)&r->legend, &cap, r->nlegend + 1, sizeof(vd_legend_entry)))
      return VD_ERR_NOMEM;
    r->cap_legend = cap;
  }
  memmove(r->legend + lo + 1, r->legend + lo, sizeof(vd_legend_entry) * (size_t)(r->nlegend - lo));
  vd_legend_entry* e = &r->legend[lo];
  memset(e, 0, sizeof *e);
  e->id = id;
  if (name) {
    strncpy(e->name, name, VD_LABEL_NAME_MAX - 1);
  } else {
    char buf[32];
    snprintf(buf, sizeof buf, "label_%d", id);
    memcpy(e->name, buf, strlen(buf) + 1);
  }
  memcpy(e->rgb, rgb, sizeof e->rgb);
  r->nlegend++;
  return VD_OK;
}

// grow the bounds of everything added, and of what is above the floor
static void bounds_add(vd_renderer* r, vd_vec3 p) {
  r->lo = r->has_bounds ? vd_vmin(r->lo, p) : p;
  r->hi = r->has_bounds ? vd_vmax(r->hi, p) : p;
  r->has_bounds = 1;
  if (p.z >= 0) {
    r->lo_up = r->has_bounds_up ? vd_vmin(r->lo_up, p) : p;
    r->hi_up = r->has_bounds_up ? vd_vmax(r->hi_up, p) : p;
    r->has_bounds_up = 1;
  }
}

int vd_render_bounds(const vd_renderer* r, vd_vec3* lo, vd_vec3* hi) {
  // with a floor, what lies under it (roots) is hidden: the bounds are those of what is above
  int up = r->def.floor && r->has_bounds_up;
  int any = r->has_bounds;
  *lo = up ? r->lo_up : any ? r->lo : vd_v3(0, 0, 0);
  *hi = up ? r->hi_up : any ? r->hi : vd_v3(0, 0, 0);
  // the robot's geoms (bounding spheres), world geoms such as its floor left out
  if (r->def.robot_mjcf)
    for (int g = 0; g < r->m->ngeom; g++) {
      if (r->m->geom_bodyid[g] == 0) continue;
      const double* p = r->d->geom_xpos + 3 * g;
      double s = r->m->geom_rbound[g];
      vd_vec3 a = vd_v3(p[0] - s, p[1] - s, p[2] - s), b = vd_v3(p[0] + s, p[1] + s, p[2] + s);
      *lo = any ? vd_vmin(*lo, a) : a;
      *hi = any ? vd_vmax(*hi, b) : b;
      any = 1;
    }
  return any;
}

void render_items_free(vd_renderer* r) {
  for (int i = 0; i < r->nitem; i++) {
    gl_list_free(&r->gl, r->items[i].list);
    gl_list_free(&r->gl, r->items[i].list_rgb);
  }
  r->nitem = 0;
  for (int c = 0; c < r->ncloud; c++) {
    vd_free(r->clouds[c].xyz, sizeof(double) * 3 * (size_t)r->clouds[c].n);
    vd_free(r->clouds[c].order, sizeof(int) * (size_t)r->clouds[c].n);
  }
  r->ncloud = 0;
  r->cloud_lists_valid = 0;
}

void vd_render_clear(vd_renderer* r) {
  vd_error ignore;
  if (r->gl.ctx) gl_current(&r->gl, &ignore);
  render_items_free(r);
  r->nlegend = 0;
  r->nadded = 0;
  r->has_bounds = r->has_bounds_up = 0;
  r->range_min = r->range_max = 0;
  r->log_scale = 0;
}

// check a style for a plant (nseg segments) or a cloud (nseg < 0)
static vd_status check_style(const vd_render_style* s, int nseg, vd_error* err) {
  if ((int)s->color_by < VD_COLOR_LABEL || s->color_by > VD_COLOR_DISPLACEMENT)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "unknown colouring %d", (int)s->color_by);
  if (nseg < 0 && s->color_by != VD_COLOR_LABEL && s->color_by != VD_COLOR_INSTANCE)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        "a point cloud or a mesh file is coloured by label or instance only");
  if (s->color_by == VD_COLOR_STRESS && !s->seg_stress)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        "colour by stress needs a stress per segment (a simulation state)");
  if (!isfinite(s->range_min) || !isfinite(s->range_max))
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "colour range is not finite");
  if (s->slices < 0 || s->slices == 1 || s->slices == 2 || s->slices > 1024)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "slices must be 0 or 3..1024, got %d",
                        s->slices);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// plants

// sort key of a triangle or point: one group per (label, instance), input order inside
typedef struct key {
  int label, instance, index;
} key;
static int cmp_key(const void* a, const void* b) {
  const key *x = a, *y = b;
  if (x->label != y->label) return x->label < y->label ? -1 : 1;
  if (x->instance != y->instance) return x->instance < y->instance ? -1 : 1;
  return (x->index > y->index) - (x->index < y->index);
}

// distance of a point of state d from the same point at rest (m)
static double moved(const double* now, const double* rest) {
  double dx = now[0] - rest[0], dy = now[1] - rest[1], dz = now[2] - rest[2];
  return sqrt(dx * dx + dy * dy + dz * dz);
}

// value of each primitive for colour by stress or displacement (NaN: no value); displacement is
// from the style's reference state, or from the rest shape
static void prim_values(const vd_model* m, const vd_data* d, const vd_render_style* s, double* seg,
                        double* sph, double* msh) {
  const vd_data* ref = s->ref;
  const double* node0 = ref ? ref->node_pos : m->node_pos0;
  const double* sph0 = ref ? ref->sphere_pos : m->sphere_pos0;
  const double* vert0 = ref ? ref->vert_pos : m->vert_pos0;
  // without a state the plant is drawn at rest: displacement 0 unless a reference says otherwise
  const double* node = d ? d->node_pos : m->node_pos0;
  const double* sphp = d ? d->sphere_pos : m->sphere_pos0;
  const double* vert = d ? d->vert_pos : m->vert_pos0;
  for (int i = 0; i < m->nseg; i++) {
    if (s->color_by == VD_COLOR_STRESS) {
      seg[i] = s->seg_stress[i];
    } else {
      int a = m->seg_node[2 * i], b = m->seg_node[2 * i + 1];
      seg[i] = 0.5 * (moved(node + 3 * a, node0 + 3 * a) + moved(node + 3 * b, node0 + 3 * b));
    }
  }
  for (int i = 0; i < m->nsphere; i++)
    sph[i] = s->color_by == VD_COLOR_STRESS ? NAN : moved(sphp + 3 * i, sph0 + 3 * i);
  for (int i = 0; i < m->nmesh; i++) {
    if (s->color_by == VD_COLOR_STRESS) {
      msh[i] = NAN;
      continue;
    }
    double sum = 0;
    int v0 = m->mesh_vert[2 * i], nv = m->mesh_vert[2 * i + 1];
    for (int v = v0; v < v0 + nv; v++)
      sum += moved(vert + 3 * v, vert0 + 3 * v);
    msh[i] = nv ? sum / nv : 0;
  }
}

// 1 for each primitive still joined to the plant's root, 0 for parts that came off (att:
// nseg + nsphere + nmesh; stack: nseg scratch). A broken segment and everything beyond it are
// off; so is a sphere or mesh whose parent is off, or a sphere that moved away from its
// attachment node or its parent's end (a fruit fallen at its calyx: the joint is not one of the
// plant's segments)
static void prim_attached(const vd_model* m, const vd_data* d, unsigned char* att, int* stack) {
  int ns = m->nseg;
  memset(att, 0, (size_t)ns); // 0 unknown, 1 attached, 2 off
  for (int i = 0; i < ns; i++) {
    // walk up to a known segment or the root, then set the path from the top down
    int n = 0, j = i, state = 1;
    while (j >= 0 && !att[j] && n < ns) {
      if (d && d->seg_broken[j]) {
        att[j] = 2;
        break;
      }
      stack[n++] = j;
      j = m->seg_parent[j];
    }
    if (j >= 0 && att[j]) state = att[j];
    while (n > 0)
      att[stack[--n]] = (unsigned char)state;
  }
  for (int i = 0; i < ns; i++)
    att[i] = att[i] == 1;
  unsigned char* sph = att + ns;
  unsigned char* msh = sph + m->nsphere;
  for (int k = 0; k < m->nsphere; k++) {
    // its attachment node, or the end of its parent segment
    int par = m->sphere_parent[k], node = m->sphere_node[k];
    if (node < 0 && par >= 0) node = m->seg_node[2 * par + 1];
    sph[k] = par < 0 || att[par];
    if (sph[k] && d && node >= 0) {
      // still as near its node as at rest, give or take its radius
      double rest = moved(m->sphere_pos0 + 3 * k, m->node_pos0 + 3 * node);
      double now = moved(d->sphere_pos + 3 * k, d->node_pos + 3 * node);
      sph[k] = now <= rest + m->sphere_radius[k] + 1e-3;
    }
  }
  for (int k = 0; k < m->nmesh; k++)
    msh[k] = m->mesh_parent[k] < 0 || att[m->mesh_parent[k]];
}

// colour scale of values (nseg + nsphere + nmesh; NaN: none) over the attached primitives (the
// whole plant when none of them has a value); 0, 0 when nothing has one
static void value_range(const vd_model* m, const double* val, const unsigned char* att, double* lo,
                        double* hi, int log_scale) {
  int n = m->nseg + m->nsphere + m->nmesh;
  for (int pass = 0; pass < 2; pass++) {
    *lo = INFINITY, *hi = -INFINITY;
    for (int i = 0; i < n; i++)
      if (isfinite(val[i]) && (pass || att[i]) && (!log_scale || val[i] > 0))
        *lo = fmin(*lo, val[i]), *hi = fmax(*hi, val[i]);
    if (*hi >= *lo) {
      if (log_scale) *lo = fmax(*lo, *hi * 1e-4);  // four decades: round-off sits near zero
      return;
    }
  }
  *lo = *hi = 0;
}

// position of a value on the colour scale lo..hi, linear or logarithmic, in [0, 1]
static double scale_pos(double v, double lo, double hi, int log_scale) {
  if (!(hi > lo)) return 0;
  if (!log_scale) return (v - lo) / (hi - lo);
  if (!(v > 0) || !(lo > 0)) return 0;
  return (log(v) - log(lo)) / (log(hi) - log(lo));
}

vd_status vd_render_value_range(const vd_model* m, const vd_data* d, const vd_render_style* style,
                                double* lo, double* hi, vd_error* err) {
  *lo = *hi = 0;
  vd_render_style s = style ? *style : vd_render_style_default();
  vd_status st = check_style(&s, m->nseg, err);
  if (st) return st;
  if (s.color_by != VD_COLOR_STRESS && s.color_by != VD_COLOR_DISPLACEMENT) return VD_OK;
  size_t n = (size_t)m->nseg + (size_t)m->nsphere + (size_t)m->nmesh + 1;
  double* val = vd_malloc(sizeof(double) * n);
  unsigned char* att = vd_malloc(n);
  int* stack = vd_malloc(sizeof(int) * ((size_t)m->nseg + 1));
  if (val && att && stack) {
    prim_values(m, d, &s, val, val + m->nseg, val + m->nseg + m->nsphere);
    prim_attached(m, d, att, stack);
    value_range(m, val, att, lo, hi, s.log_scale);
  } else {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  vd_free(val, sizeof(double) * n);
  vd_free(att, n);
  vd_free(stack, sizeof(int) * ((size_t)m->nseg + 1));
  return st;
}

// half thickness given to open surfaces (leaves) drawn from both sides (m): the two faces lie
// apart, so neither shadows nor depth-tests the other (real leaves are 0.1-0.5 mm thick)
#define LEAF_HALF_THICKNESS 1e-4

// emit triangle t of mesh into the float arrays at slot k; side 0: as is, 1 or -1: a face of
// an open surface moved along its normal by side x LEAF_HALF_THICKNESS (-1 reversed, facing back)
static void put_tri(const vd_mesh* mesh, int t, int side, const float* rgb, float* pos, float* nrm,
                    float* col, int k) {
  int flip = side < 0;
  for (int c = 0; c < 3; c++) {
    int v = mesh->tri[3 * t + (flip ? 2 - c : c)];
    for (int x = 0; x < 3; x++) {
      pos[9 * k + 3 * c + x] =
          (float)(mesh->pos[3 * v + x] + side * LEAF_HALF_THICKNESS * mesh->normal[3 * v + x]);
      nrm[9 * k + 3 * c + x] = (float)(flip ? -mesh->normal[3 * v + x] : mesh->normal[3 * v + x]);
      if (col) col[9 * k + 3 * c + x] = rgb[x];
    }
  }
}

// label table order
static int cmp_label(const void* a, const void* b) {
  const vd_label *x = a, *y = b;
  return (x->id > y->id) - (x->id < y->id);
}

// label id in a table sorted by id; an unnamed entry of the default colour (*spare) when the
// table lacks it
static const vd_label* find_label(const vd_label* l, int n, int id, vd_label* spare) {
  int lo = 0, hi = n;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (l[mid].id < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (lo < n && l[lo].id == id) return &l[lo];
  vd_label_init(spare, id, "");
  return spare;
}

// the label table of what is added, coloured by the palette: the table given (Nullable, any
// order, the first entry of an id kept) and an unnamed entry for each id of ids (nid, ascending)
// it lacks, sorted by id; free *out with vd_free(*out, *n * sizeof(vd_label))
static vd_status palette_table(const vd_label* tab, int ntab, const int* ids, int nid,
                               vd_palette palette, vd_label** out, int* n) {
  *out = NULL, *n = 0;
  size_t cap = (size_t)ntab + (size_t)nid + 1;
  vd_label* l = vd_malloc(sizeof(vd_label) * cap);
  float(*rgb)[3] = vd_malloc(sizeof *rgb * cap);
  if (!l || !rgb) {
    vd_free(l, sizeof(vd_label) * cap);
    vd_free(rgb, sizeof *rgb * cap);
    return VD_ERR_NOMEM;
  }
  int k = 0;
  for (int i = 0; i < ntab; i++) {
    int dup = 0;
    for (int j = 0; j < k && !dup; j++)
      dup = l[j].id == tab[i].id;
    if (!dup) l[k++] = tab[i];
  }
  qsort(l, (size_t)k, sizeof *l, cmp_label);
  int known = k;
  for (int j = 0; j < nid; j++)
    if (find_label(l, known, ids[j], &l[k]) == &l[k]) k++;
  qsort(l, (size_t)k, sizeof *l, cmp_label);
  vd_render_label_colors(l, k, palette, rgb);
  for (int i = 0; i < k; i++)
    memcpy(l[i].rgb, rgb[i], sizeof l[i].rgb);
  vd_free(rgb, sizeof *rgb * cap);
  // give back the unused tail (the caller frees n entries)
  vd_label* fit = vd_realloc(l, sizeof(vd_label) * cap, sizeof(vd_label) * (size_t)(k ? k : 1));
  if (!fit) {
    vd_free(l, sizeof(vd_label) * cap);
    return VD_ERR_NOMEM;
  }
  *out = fit, *n = k ? k : 1;
  if (!k) memset(fit, 0, sizeof *fit), fit->id = -1;
  return VD_OK;
}

// Add labelled triangles as one item per (label, instance), coloured by s (label colours from the
// table tab of ntab entries, Nullable, in s's palette): tri_rgb (Nullable) gives a colour per
// triangle for the value colourings, open (Nullable) marks the triangles of open surfaces, drawn
// as two faces apart, each facing its own side.
static vd_status add_triangles(vd_renderer* r, const vd_mesh* mesh, const unsigned char* open,
                               const float* tri_rgb, const vd_label* tab, int ntab,
                               const vd_render_style* s, vd_error* err) {
  for (int t = 0; t < mesh->ntri; t++)
    if (mesh->tri_label[t] < 0 || mesh->tri_label[t] >= VD_RENDER_ROBOT_LABEL ||
        mesh->tri_instance[t] < 0 || mesh->tri_instance[t] > 65535)
      return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                          "label %d / instance %d do not fit the 16-bit masks (labels 0..65534, "
                          "instances 0..65535)",
                          mesh->tri_label[t], mesh->tri_instance[t]);
  // scratch: triangle order, label ids present, one group's vertex arrays (x2 for back faces)
  vd_status st = VD_OK;
  size_t nt = (size_t)mesh->ntri;
  key* order = vd_malloc(nt ? nt * sizeof(key) : 1);
  int* ids = vd_malloc(nt ? nt * sizeof(int) : 1);
  float* buf = vd_malloc(nt ? sizeof(float) * 2 * nt * 27 : 1);
  vd_label* lab = NULL;
  int nlab = 0, nid = 0;
  if (!order || !ids || !buf) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    goto done;
  }
  for (size_t t = 0; t < nt; t++)
    order[t] = (key){mesh->tri_label[t], mesh->tri_instance[t], (int)t};
  if (nt) qsort(order, nt, sizeof(key), cmp_key);
  for (size_t t = 0; t < nt; t++)
    if (!nid || ids[nid - 1] != order[t].label) ids[nid++] = order[t].label;
  if (palette_table(tab, ntab, ids, nid, s->palette, &lab, &nlab)) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    goto done;
  }
  for (int v = 0; v < mesh->nvert; v++)
    bounds_add(r, vd_v3(mesh->pos[3 * v], mesh->pos[3 * v + 1], mesh->pos[3 * v + 2]));
  if (r->nadded == 0) r->color_by = s->color_by, r->palette = s->palette;
  // one item per (label, instance)
  for (size_t g0 = 0, g1; g0 < nt; g0 = g1) {
    int label = order[g0].label, inst = order[g0].instance;
    for (g1 = g0 + 1; g1 < nt && order[g1].label == label && order[g1].instance == inst; g1++) {
    }
    item* it = new_item(r);
    if (!it) {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      goto done;
    }
    it->kind = ITEM_PLANT;
    it->label = label;
    it->instance = inst;
    vd_label spare;
    const vd_label* l = find_label(lab, nlab, label, &spare);
    if (s->color_by == VD_COLOR_LABEL)
      memcpy(it->rgba, l->rgb, sizeof l->rgb);
    else if (s->color_by == VD_COLOR_INSTANCE)
      instance_rgb(inst, it->rgba);
    else
      it->rgba[0] = it->rgba[1] = it->rgba[2] = 1;
    if (legend_add(r, label, l->name[0] ? l->name : NULL, l->rgb)) {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      goto done;
    }
    // the group's triangles; open surfaces twice, the second copy facing back
    size_t cap = 2 * (g1 - g0);
    float* pos = buf;
    float* nrm = buf + 9 * cap;
    float* col = tri_rgb ? buf + 18 * cap : NULL;
    int k = 0;
    for (size_t j = g0; j < g1; j++) {
      int t = order[j].index;
      const float* rgb = tri_rgb ? tri_rgb + 3 * t : NULL;
      int two = open && open[t];
      put_tri(mesh, t, two, rgb, pos, nrm, col, k++);
      if (two) put_tri(mesh, t, -1, rgb, pos, nrm, col, k++);
    }
    gl_tris tris = {k, pos, nrm, NULL};
    it->list = gl_list(&r->gl, &tris);
    if (tri_rgb) {
      tris.rgb = col;
      it->list_rgb = gl_list(&r->gl, &tris);
    }
    if (!it->list || (tri_rgb && !it->list_rgb)) {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "OpenGL could not store the geometry");
      goto done;
    }
  }
  r->nadded++;
done:
  vd_free(order, nt ? nt * sizeof(key) : 1);
  vd_free(ids, nt ? nt * sizeof(int) : 1);
  vd_free(buf, nt ? sizeof(float) * 2 * nt * 27 : 1);
  vd_free(lab, sizeof(vd_label) * (size_t)nlab);
  return st;
}

vd_status vd_render_add_plant(vd_renderer* r, const vd_model* m, const vd_data* d,
                              const vd_render_style* style, vd_error* err) {
  vd_render_style s = style ? *style : vd_render_style_default();
  vd_status st = check_style(&s, m->nseg, err);
  if (st) return st;
  if (d && (d->nnode != m->nnode || d->nseg != m->nseg || d->nsphere != m->nsphere ||
            d->nvert != m->nvert))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        "the state does not belong to this model (sizes differ)");
  if (s.ref && (s.ref->nnode != m->nnode || s.ref->nseg != m->nseg ||
                s.ref->nsphere != m->nsphere || s.ref->nvert != m->nvert))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        "the reference state does not belong to this model (sizes differ)");
  if (s.color_by == VD_COLOR_STRESS)
    for (int i = 0; i < m->nseg; i++)
      if (isinf(s.seg_stress[i]))
        return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "stress of segment %d is infinite", i);
  if ((st = gl_current(&r->gl, err))) return st;
  // the plant as labelled triangles
  vd_mesh mesh;
  vd_mesh_def md = vd_mesh_def_default();
  md.slices = s.slices;
  if ((st = vd_geom_tessellate(m, d, &md, &mesh, err))) return st;
  // scratch: per-primitive values, per-triangle colours and open-surface flags
  size_t nt = (size_t)mesh.ntri, nval = (size_t)m->nseg + (size_t)m->nsphere + (size_t)m->nmesh + 1;
  int value_mode = s.color_by == VD_COLOR_STRESS || s.color_by == VD_COLOR_DISPLACEMENT;
  double* val = vd_malloc(sizeof(double) * nval);
  float* tri_rgb = value_mode ? vd_malloc(sizeof(float) * 3 * (nt + 1)) : NULL;
  unsigned char* open = vd_malloc(nt + 1);
  if (!val || !open || (value_mode && !tri_rgb)) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    goto done;
  }
  double* vseg = val;
  double* vsph = val + m->nseg;
  double* vmsh = vsph + m->nsphere;
  double lo = s.range_min, hi = s.range_max;
  if (value_mode) {
    prim_values(m, d, &s, vseg, vsph, vmsh);
    // without a fixed range, the scale spans the plant still attached: a fruit that fell or a
    // branch that broke off lies beyond it (in the end colour) instead of washing out the plant
    if (!(hi > lo)) {
      unsigned char* att = vd_malloc(nval);
      int* stack = vd_malloc(sizeof(int) * ((size_t)m->nseg + 1));
      if (!att || !stack) {
        vd_free(att, nval);
        vd_free(stack, sizeof(int) * ((size_t)m->nseg + 1));
        st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
        goto done;
      }
      prim_attached(m, d, att, stack);
      value_range(m, val, att, &lo, &hi, s.log_scale);
      vd_free(att, nval);
      vd_free(stack, sizeof(int) * ((size_t)m->nseg + 1));
    }
    r->range_min = lo;
    r->range_max = hi;
    r->log_scale = s.log_scale;
  }
  for (size_t t = 0; t < nt; t++) {
    int prim = mesh.tri_prim[t], kind = mesh.tri_kind[t];
    // leaves are open surfaces: two faces 0.2 mm apart, each lit from its side
    open[t] = kind == VD_PRIM_MESH && !m->mesh_closed[prim];
    if (!value_mode) continue;
    double v = kind == VD_PRIM_SEGMENT  ? vseg[prim]
               : kind == VD_PRIM_SPHERE ? vsph[prim]
                                        : vmsh[prim];
    if (isfinite(v))
      render_colormap(scale_pos(v, lo, hi, s.log_scale), tri_rgb + 3 * t);
    else
      memcpy(tri_rgb + 3 * t, no_value_rgb, sizeof no_value_rgb);
  }
  st = add_triangles(r, &mesh, open, tri_rgb, m->labels, m->nlabel, &s, err);
done:
  vd_free(val, sizeof(double) * nval);
  vd_free(tri_rgb, value_mode ? sizeof(float) * 3 * (nt + 1) : 0);
  vd_free(open, nt + 1);
  vd_mesh_free(&mesh);
  return st;
}

vd_status vd_render_add_mesh(vd_renderer* r, const vd_mesh* mesh, const vd_label* labels,
                             int nlabel, const vd_render_style* style, vd_error* err) {
  vd_render_style s = style ? *style : vd_render_style_default();
  vd_status st = check_style(&s, -1, err);
  if (st) return st;
  if (nlabel < 0 || (nlabel > 0 && !labels))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bad label table");
  for (int t = 0; t < mesh->ntri; t++)
    for (int c = 0; c < 3; c++)
      if (mesh->tri[3 * t + c] < 0 || mesh->tri[3 * t + c] >= mesh->nvert)
        return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "triangle %d: vertex index out of range", t);
  for (int i = 0; i < 3 * mesh->nvert; i++)
    if (!isfinite(mesh->pos[i]) || !isfinite(mesh->normal[i]))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "vertex %d is not finite", i / 3);
  if ((st = gl_current(&r->gl, err))) return st;
  // which surfaces are open is not known: every triangle is drawn from both sides
  unsigned char* open = vd_malloc((size_t)mesh->ntri + 1);
  if (!open) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  memset(open, 1, (size_t)mesh->ntri + 1);
  st = add_triangles(r, mesh, open, NULL, labels, nlabel, &s, err);
  vd_free(open, (size_t)mesh->ntri + 1);
  return st;
}

// ---------------------------------------------------------------------------------------------
// solids (probes, colliders)

// resolution of shapes: sides around, rings from pole to pole (even: capsules split at the
// equator)
#define SHAPE_SIDES 32
#define SHAPE_RINGS 16

// unit-sphere point at ring i (0 north pole .. SHAPE_RINGS south) and side j
static vd_vec3 sphere_dir(int i, int j) {
  double th = VD_PI * i / SHAPE_RINGS, ph = 2 * VD_PI * j / SHAPE_SIDES;
  return vd_v3(sin(th) * cos(ph), sin(th) * sin(ph), cos(th));
}

// append triangle (a, b, c) with normals (na, nb, nc) in the local frame, placed by (pos, q)
static void shape_tri(float* pos, float* nrm, int* k, vd_vec3 p, vd_quat q, const vd_vec3 v[3],
                      const vd_vec3 n[3]) {
  for (int c = 0; c < 3; c++) {
    vd_vec3 w = vd_add(p, vd_quat_rotate(q, v[c])), wn = vd_quat_rotate(q, n[c]);
    float* o = pos + 9 * *k + 3 * c;
    float* on = nrm + 9 * *k + 3 * c;
    o[0] = (float)w.x, o[1] = (float)w.y, o[2] = (float)w.z;
    on[0] = (float)wn.x, on[1] = (float)wn.y, on[2] = (float)wn.z;
  }
  (*k)++;
}

// triangles of a shape (at most 2 x SHAPE_RINGS x SHAPE_SIDES + 2 x SHAPE_SIDES + 12)
static int shape_tris(const vd_render_shape* s, vd_quat q, float* pos, float* nrm) {
  int k = 0;
  if (s->kind == VD_RENDER_BOX) {
    // six faces, two triangles each, counter-clockwise seen from outside
    for (int axis = 0; axis < 3; axis++)
      for (int sign = -1; sign <= 1; sign += 2) {
        double e[3] = {0, 0, 0};
        e[axis] = sign;
        vd_vec3 n = vd_v3(e[0], e[1], e[2]);
        int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        vd_vec3 c[4];
        static const double uv[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int i = 0; i < 4; i++) {
          double x[3];
          x[axis] = sign * s->size[axis];
          x[a1] = uv[i][0] * s->size[a1];
          x[a2] = uv[i][1] * s->size[a2] * sign;
          c[i] = vd_v3(x[0], x[1], x[2]);
        }
        vd_vec3 n3[3] = {n, n, n}, t0[3] = {c[0], c[1], c[2]}, t1[3] = {c[0], c[2], c[3]};
        shape_tri(pos, nrm, &k, s->pos, q, t0, n3);
        shape_tri(pos, nrm, &k, s->pos, q, t1, n3);
      }
    return k;
  }
  // sphere or capsule: a UV sphere whose northern half (equator included) moves up by the
  // half-length and southern half down; ring e of RINGS + 2 is latitude ring lat[e]
  double r = s->size[0], hl = s->kind == VD_RENDER_CAPSULE ? s->size[1] : 0;
  for (int e = 0; e <= SHAPE_RINGS; e++) {
    int a = e <= SHAPE_RINGS / 2 ? e : e - 1, b = e + 1 <= SHAPE_RINGS / 2 ? e + 1 : e;
    double za = e <= SHAPE_RINGS / 2 ? hl : -hl, zb = e + 1 <= SHAPE_RINGS / 2 ? hl : -hl;
    if (a == b && hl <= 0) continue; // a sphere has no cylinder band
    for (int j = 0; j < SHAPE_SIDES; j++) {
      vd_vec3 d00 = sphere_dir(a, j), d01 = sphere_dir(a, j + 1);
      vd_vec3 d10 = sphere_dir(b, j), d11 = sphere_dir(b, j + 1);
      vd_vec3 p00 = vd_v3(r * d00.x, r * d00.y, r * d00.z + za);
      vd_vec3 p01 = vd_v3(r * d01.x, r * d01.y, r * d01.z + za);
      vd_vec3 p10 = vd_v3(r * d10.x, r * d10.y, r * d10.z + zb);
      vd_vec3 p11 = vd_v3(r * d11.x, r * d11.y, r * d11.z + zb);
      // the quad (00, 10, 11, 01) runs counter-clockwise seen from outside; at a pole it is one
      // triangle
      if (b < SHAPE_RINGS) {
        vd_vec3 v[3] = {p00, p10, p11}, n[3] = {d00, d10, d11};
        shape_tri(pos, nrm, &k, s->pos, q, v, n);
      }
      if (a > 0) {
        vd_vec3 v[3] = {p00, p11, p01}, n[3] = {d00, d11, d01};
        shape_tri(pos, nrm, &k, s->pos, q, v, n);
      }
    }
  }
  return k;
}

vd_status vd_render_add_shape(vd_renderer* r, const vd_render_shape* s, vd_error* err) {
  int nsize = s->kind == VD_RENDER_SPHERE ? 1 : s->kind == VD_RENDER_CAPSULE ? 2 : 3;
  if ((int)s->kind < VD_RENDER_SPHERE || s->kind > VD_RENDER_BOX)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "unknown shape kind %d", (int)s->kind);
  for (int k = 0; k < nsize; k++)
    if (!isfinite(s->size[k]) ||
        !(s->size[k] > 0 || (s->kind == VD_RENDER_CAPSULE && k == 1 && s->size[k] >= 0)))
      return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                          "shape size %d is %g: must be finite and > 0", k, s->size[k]);
  if (!isfinite(s->pos.x + s->pos.y + s->pos.z) ||
      !isfinite(s->quat.w + s->quat.x + s->quat.y + s->quat.z))
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "shape pose is not finite");
  vd_quat q = vd_quat_normalize(s->quat);
  vd_status st = gl_current(&r->gl, err);
  if (st) return st;
  size_t cap = 2 * SHAPE_RINGS * SHAPE_SIDES + 2 * SHAPE_SIDES + 12;
  float* pos = vd_malloc(sizeof(float) * 18 * cap);
  if (!pos) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  float* nrm = pos + 9 * cap;
  int n = shape_tris(s, q, pos, nrm);
  item* it = new_item(r);
  if (!it) {
    vd_free(pos, sizeof(float) * 18 * cap);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  it->kind = ITEM_SHAPE;
  it->label = VD_RENDER_ROBOT_LABEL;
  it->instance = 0;
  for (int c = 0; c < 3; c++)
    it->rgba[c] = s->rgb[c] < 0 ? 0 : s->rgb[c] > 1 ? 1 : s->rgb[c];
  for (int v = 0; v < 3 * n; v++)
    bounds_add(r, vd_v3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]));
  gl_tris tris = {n, pos, nrm, NULL};
  it->list = gl_list(&r->gl, &tris);
  vd_free(pos, sizeof(float) * 18 * cap);
  if (!it->list)
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "OpenGL could not store the shape");
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// point clouds

vd_status vd_render_add_points(vd_renderer* r, const vd_points* p, const vd_render_style* style,
                               vd_error* err) {
  vd_render_style s = style ? *style : vd_render_style_default();
  vd_status st = check_style(&s, -1, err);
  if (st) return st;
  if (p->n < 0) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "negative point count");
  if (p->n > 0 && !p->xyz)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "points without positions");
  if (!isfinite(p->radius) || p->radius < 0)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "splat radius must be >= 0");
  if (p->nlabel < 0 || (p->nlabel > 0 && !p->labels))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "bad label table");
  for (int i = 0; i < p->n; i++) {
    for (int k = 0; k < 3; k++)
      if (!isfinite(p->xyz[3 * i + k]))
        return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "point %d is not finite", i);
    int l = p->label ? p->label[i] : 0, in = p->instance ? p->instance[i] : 0;
    if (l < 0 || l >= VD_RENDER_ROBOT_LABEL || in < 0 || in > 65535)
      return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0,
                          "point %d: label %d / instance %d do not fit the 16-bit masks", i, l, in);
  }
  // keep a copy: the splats face the camera, so their lists are made at draw time
  if (r->ncloud == r->cap_cloud) {
    int cap = r->cap_cloud;
    if (!vd_grow((void**)&r->clouds, &cap, r->ncloud + 1, sizeof(cloud)))
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    r->cap_cloud = cap;
  }
  cloud* c = &r->clouds[r->ncloud];
  memset(c, 0, sizeof *c);
  size_t n = (size_t)p->n;
  key* keys = n ? vd_malloc(n * sizeof(key)) : NULL;
  c->xyz = n ? vd_malloc(sizeof(double) * 3 * n) : NULL;
  c->order = n ? vd_malloc(sizeof(int) * n) : NULL;
  if (n && (!keys || !c->xyz || !c->order)) {
    vd_free(keys, n * sizeof(key));
    vd_free(c->xyz, sizeof(double) * 3 * n);
    vd_free(c->order, sizeof(int) * n);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  c->n = p->n;
  if (n) memcpy(c->xyz, p->xyz, sizeof(double) * 3 * n);
  r->ncloud++;
  vd_vec3 lo = vd_v3(0, 0, 0), hi = lo;
  for (int i = 0; i < p->n; i++) {
    vd_vec3 q = vd_v3(p->xyz[3 * i], p->xyz[3 * i + 1], p->xyz[3 * i + 2]);
    lo = i ? vd_vmin(lo, q) : q;
    hi = i ? vd_vmax(hi, q) : q;
    bounds_add(r, q);
    keys[i] = (key){p->label ? p->label[i] : 0, p->instance ? p->instance[i] : 0, i};
  }
  c->radius = p->radius > 0 ? p->radius : fmax(0.004 * vd_norm(vd_sub(hi, lo)), 1e-4);
  if (n) qsort(keys, n, sizeof(key), cmp_key);
  // the label ids present, ascending, and their colours
  int nid = 0, nlab = 0;
  int* ids = vd_malloc(sizeof(int) * (n + 1));
  for (int i = 0; i < p->n; i++) {
    c->order[i] = keys[i].index;
    if (ids && (!nid || ids[nid - 1] != keys[i].label)) ids[nid++] = keys[i].label;
  }
  vd_free(keys, n * sizeof(key));
  vd_label* lab = NULL;
  vd_status pst =
      ids ? palette_table(p->labels, p->nlabel, ids, nid, s.palette, &lab, &nlab) : VD_ERR_NOMEM;
  vd_free(ids, sizeof(int) * (n + 1));
  if (pst) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  if (r->nadded == 0) r->color_by = s.color_by, r->palette = s.palette;
  // one item per (label, instance); the order keeps the labels and instances
  for (int g0 = 0, g1; g0 < p->n; g0 = g1) {
    int i0 = c->order[g0];
    int label = p->label ? p->label[i0] : 0, inst = p->instance ? p->instance[i0] : 0;
    for (g1 = g0 + 1; g1 < p->n; g1++) {
      int j = c->order[g1];
      if ((p->label ? p->label[j] : 0) != label || (p->instance ? p->instance[j] : 0) != inst)
        break;
    }
    item* it = new_item(r);
    if (!it) {
      vd_free(lab, sizeof(vd_label) * (size_t)nlab);
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
    it->kind = ITEM_POINTS;
    it->label = label;
    it->instance = inst;
    it->cloud = r->ncloud - 1;
    it->start = g0;
    it->count = g1 - g0;
    vd_label spare;
    const vd_label* l = find_label(lab, nlab, label, &spare);
    if (s.color_by == VD_COLOR_INSTANCE)
      instance_rgb(inst, it->rgba);
    else
      memcpy(it->rgba, l->rgb, sizeof l->rgb);
    if (legend_add(r, label, l->name[0] ? l->name : NULL, l->rgb)) {
      vd_free(lab, sizeof(vd_label) * (size_t)nlab);
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
  }
  vd_free(lab, sizeof(vd_label) * (size_t)nlab);
  r->cloud_lists_valid = 0;
  r->nadded++;
  return VD_OK;
}

vd_status render_clouds_update(vd_renderer* r, const double eye[3], const double fwd[3],
                               const double right[3], const double up[3], vd_error* err) {
  if (r->cloud_lists_valid && !memcmp(eye, r->cloud_eye, sizeof r->cloud_eye) &&  // NOLINT(bugprone-suspicious-memory-comparison,cert-exp42-c,cert-flp37-c): bitwise equality is what a cache of the last view wants
      !memcmp(fwd, r->cloud_fwd, sizeof r->cloud_fwd) &&  // NOLINT(bugprone-suspicious-memory-comparison,cert-exp42-c,cert-flp37-c): bitwise equality is what a cache of the last view wants
      !memcmp(up, r->cloud_up, sizeof r->cloud_up))  // NOLINT(bugprone-suspicious-memory-comparison,cert-exp42-c,cert-flp37-c): bitwise equality is what a cache of the last view wants
    return VD_OK;
  // largest group, for one scratch buffer
  int most = 0;
  for (int i = 0; i < r->nitem; i++)
    if (r->items[i].kind == ITEM_POINTS && r->items[i].count > most) most = r->items[i].count;
  if (!most) return VD_OK;
  size_t nf = (size_t)most * 2 * 9;
  float* pos = vd_malloc(sizeof(float) * 2 * nf);
  if (!pos) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  float* nrm = pos + nf;
  vd_status st = VD_OK;
  for (int i = 0; i < r->nitem && !st; i++) {
    item* it = &r->items[i];
    if (it->kind != ITEM_POINTS) continue;
    const cloud* c = &r->clouds[it->cloud];
    double s = c->radius;
    // two triangles per point, a square facing the camera
    static const double corner[6][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}};
    for (int j = 0; j < it->count; j++) {
      const double* q = c->xyz + 3 * c->order[it->start + j];
      for (int v = 0; v < 6; v++)
        for (int x = 0; x < 3; x++) {
          pos[18 * j + 3 * v + x] =
              (float)(q[x] + s * (corner[v][0] * right[x] + corner[v][1] * up[x]));
          nrm[18 * j + 3 * v + x] = (float)-fwd[x];
        }
    }
    gl_list_free(&r->gl, it->list);
    gl_tris tris = {2 * it->count, pos, nrm, NULL};
    it->list = gl_list(&r->gl, &tris);
    if (!it->list)
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "OpenGL could not store the cloud");
  }
  vd_free(pos, sizeof(float) * 2 * nf);
  if (!st) {
    memcpy(r->cloud_eye, eye, sizeof r->cloud_eye);
    memcpy(r->cloud_fwd, fwd, sizeof r->cloud_fwd);
    memcpy(r->cloud_up, up, sizeof r->cloud_up);
    r->cloud_lists_valid = 1;
  }
  return st;
}
