// SPDX-License-Identifier: MIT
// geom: tessellation counts, watertightness and outward orientation (signed volumes against
// analytic ones), generalised cylinders, labels per triangle, state vs rest shape, OBJ/MTL and
// PLY output read back.
#include <stdlib.h>

#include "test.h"
#include "verdant/geom.h"
#include "verdant/plant.h"

// ---------------------------------------------------------------------------------------------
// helpers

// compile a spec into a model, or NULL
static vd_model* compile(vd_plant_spec* s) {
  vd_model* m = NULL;
  vd_error err = {0};
  if (vd_plant_compile(s, &m, &err) != VD_OK) return NULL;
  return m;
}

// one frustum from a to b
static vd_plant_spec* one_segment(vd_vec3 a, vd_vec3 b, double r0, double r1, int slices) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = vd_plant_add_node(s, a);
  g.node1 = vd_plant_add_node(s, b);
  g.r0 = r0, g.r1 = r1, g.slices = slices, g.label = 1, g.instance = 1;
  g.up = vd_v3(0, 1, 0);
  vd_plant_add_segment(s, &g);
  return s;
}

// signed volume enclosed by the triangles of mesh (divergence theorem)
static double signed_volume(const vd_mesh* mesh) {
  double v = 0;
  for (int t = 0; t < mesh->ntri; t++) {
    const double* a = mesh->pos + 3 * mesh->tri[3 * t];
    const double* b = mesh->pos + 3 * mesh->tri[3 * t + 1];
    const double* c = mesh->pos + 3 * mesh->tri[3 * t + 2];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6.0;
}

typedef struct wv {
  double x, y, z;
  int idx;
} wv;
static int cmp_wv(const void* a, const void* b) {
  const wv *p = a, *q = b;
  if (p->x != q->x) return p->x < q->x ? -1 : 1;
  if (p->y != q->y) return p->y < q->y ? -1 : 1;
  if (p->z != q->z) return p->z < q->z ? -1 : 1;
  return 0;
}
typedef struct edge {
  int a, b;
} edge;
static int cmp_edge(const void* x, const void* y) {
  const edge *p = x, *q = y;
  if (p->a != q->a) return p->a < q->a ? -1 : 1;
  return (p->b > q->b) - (p->b < q->b);
}

// 1 when, after welding vertices at equal positions, every directed edge occurs exactly once and
// its reverse exactly once: each edge is shared by two consistently oriented triangles
static int watertight(const vd_mesh* mesh) {
  int nv = mesh->nvert, nt = mesh->ntri, ok = 1;
  wv* w = vd_malloc((size_t)nv * sizeof *w);
  int* weld = vd_malloc((size_t)nv * sizeof *weld);
  edge* e = vd_malloc((size_t)nt * 3 * sizeof *e);
  if (!w || !weld || !e) ok = 0;
  for (int i = 0; ok && i < nv; i++)
    w[i] = (wv){mesh->pos[3 * i], mesh->pos[3 * i + 1], mesh->pos[3 * i + 2], i};
  if (ok) qsort(w, (size_t)nv, sizeof *w, cmp_wv);
  for (int i = 0, id = -1; ok && i < nv; i++) {
    if (i == 0 || cmp_wv(&w[i], &w[i - 1]) != 0) id++;
    weld[w[i].idx] = id;
  }
  for (int t = 0; ok && t < nt; t++)
    for (int k = 0; k < 3; k++) {
      e[3 * t + k].a = weld[mesh->tri[3 * t + k]];
      e[3 * t + k].b = weld[mesh->tri[3 * t + (k + 1) % 3]];
      if (e[3 * t + k].a == e[3 * t + k].b) ok = 0; // degenerate edge
    }
  if (ok) qsort(e, (size_t)nt * 3, sizeof *e, cmp_edge);
  for (int i = 0; ok && i < 3 * nt; i++) {
    if (i > 0 && cmp_edge(&e[i], &e[i - 1]) == 0) ok = 0; // same directed edge twice
    edge r = {e[i].b, e[i].a};
    if (!bsearch(&r, e, (size_t)nt * 3, sizeof *e, cmp_edge)) ok = 0; // open edge
  }
  vd_free(w, (size_t)nv * sizeof *w);
  vd_free(weld, (size_t)nv * sizeof *weld);
  vd_free(e, (size_t)nt * 3 * sizeof *e);
  return ok;
}

// area of a regular n-gon of circumradius r
static double ngon_area(int n, double r) {
  return 0.5 * n * r * r * sin(2 * VD_PI / n);
}

// ---------------------------------------------------------------------------------------------
// frustums

TEST(geom, frustum_counts) {
  vd_plant_spec* s = one_segment(vd_v3(0, 0, 0), vd_v3(0, 0, 1), 0.1, 0.05, 8);
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  // s slices: two side rings (2s), two caps (s + 1 each); 2s side and s per cap triangles
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, 4 * 8 + 2);
  CHECK_INT(mesh.ntri, 4 * 8);
  vd_mesh_free(&mesh);
  CHECK(mesh.pos == NULL && mesh.nvert == 0);
  // override the slices, no caps
  vd_mesh_def def = vd_mesh_def_default();
  def.slices = 5;
  def.caps = 0;
  CHECK_STATUS(vd_geom_tessellate(m, NULL, &def, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, 10);
  CHECK_INT(mesh.ntri, 10);
  int nv = 0, nt = 0;
  CHECK_STATUS(vd_geom_count(m, NULL, &def, &nv, &nt, &err), VD_OK, err);
  CHECK(nv == mesh.nvert && nt == mesh.ntri);
  vd_mesh_free(&mesh);
  // bad settings
  def.slices = 2;
  CHECK_STATUS(vd_geom_tessellate(m, NULL, &def, &mesh, &err), VD_ERR_ARG, err);
  def = vd_mesh_def_default();
  def.sphere_stacks = 1;
  memset(&err, 0, sizeof err);
  CHECK_STATUS(vd_geom_tessellate(m, NULL, &def, &mesh, &err), VD_ERR_ARG, err);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

TEST(geom, frustum_closed_and_outward) {
  // a tilted, tapered frustum: watertight, positive volume equal to the polygonal frustum's
  vd_vec3 a = vd_v3(0.1, -0.2, 0.3), b = vd_v3(0.5, 0.4, 1.1);
  double r0 = 0.2, r1 = 0.07, len = vd_norm(vd_sub(b, a));
  for (int n = 3; n <= 24; n += 7) {
    vd_plant_spec* s = one_segment(a, b, r0, r1, n);
    REQUIRE(s);
    vd_model* m = compile(s);
    REQUIRE(m);
    vd_mesh mesh;
    vd_error err = {0};
    CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
    CHECK(watertight(&mesh));
    double a0 = ngon_area(n, r0), a1 = ngon_area(n, r1);
    double expect = len / 3 * (a0 + a1 + sqrt(a0 * a1));
    CHECK_NEAR(signed_volume(&mesh), expect, 1e-12);
    // unit normals; side normals point away from the axis, cap normals along it
    vd_vec3 axis = vd_normalize(vd_sub(b, a));
    for (int v = 0; v < mesh.nvert; v++) {
      vd_vec3 nrm = vd_v3(mesh.normal[3 * v], mesh.normal[3 * v + 1], mesh.normal[3 * v + 2]);
      CHECK_NEAR(vd_norm(nrm), 1, 1e-12);
      vd_vec3 p = vd_v3(mesh.pos[3 * v], mesh.pos[3 * v + 1], mesh.pos[3 * v + 2]);
      vd_vec3 mid = vd_scale(vd_add(a, b), 0.5);
      CHECK(vd_dot(nrm, vd_sub(p, mid)) > 0 || fabs(vd_dot(nrm, axis)) > 0.999);
    }
    // the first ring vertex lies toward the segment's up vector (angular origin)
    vd_vec3 p0 = vd_v3(mesh.pos[0], mesh.pos[1], mesh.pos[2]);
    vd_vec3 d0 = vd_normalize(vd_sub(p0, a));
    vd_vec3 up = vd_normalize(vd_madd(vd_v3(0, 1, 0), axis, -axis.y));
    CHECK_NEAR(vd_dot(d0, up), 1, 1e-12);
    for (int t = 0; t < mesh.ntri; t++) {
      CHECK(mesh.tri_label[t] == 1 && mesh.tri_instance[t] == 1);
      CHECK(mesh.tri_kind[t] == VD_PRIM_SEGMENT && mesh.tri_prim[t] == 0);
    }
    vd_mesh_free(&mesh);
    vd_model_destroy(m);
    vd_plant_spec_destroy(s);
  }
}

// a bent generalised cylinder of k segments (GC flags), plus an unflagged side branch
static vd_plant_spec* gc_tube(int k, int slices) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  vd_vec3 p = vd_v3(0, 0, 0);
  int prev = vd_plant_add_node(s, p), parent = -1;
  for (int i = 0; i < k; i++) {
    p = vd_add(p, vd_v3(0.1 * i, 0.05 * i * i, 0.3));
    int n = vd_plant_add_node(s, p);
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = prev, g.node1 = n, g.parent = parent, g.flags = VD_SEG_GC;
    g.r0 = 0.1 - 0.02 * i, g.r1 = 0.1 - 0.02 * (i + 1), g.slices = slices, g.label = 1;
    g.instance = 1, g.up = vd_v3(1, 0, 0);
    parent = vd_plant_add_segment(s, &g);
    prev = n;
  }
  return s;
}

TEST(geom, generalised_cylinder) {
  int k = 4, n = 10;
  vd_plant_spec* s = gc_tube(k, n);
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  // k + 1 rings shared along the tube, caps only at its two ends
  CHECK_INT(mesh.nvert, (k + 1) * n + 2 * (n + 1));
  CHECK_INT(mesh.ntri, k * 2 * n + 2 * n);
  CHECK(watertight(&mesh));
  CHECK(signed_volume(&mesh) > 0);
  // a joint vertex normal is the average of both sides: unit and away from the node
  const double* nrm = mesh.normal + 3 * (n + 0);
  CHECK_NEAR(sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]), 1, 1e-12);
  vd_mesh_free(&mesh);
  // a broken joint splits the tube into two closed pieces
  vd_data* d = vd_data_create(m);
  REQUIRE(d);
  d->seg_broken[2] = 1;
  CHECK_STATUS(vd_geom_tessellate(m, d, NULL, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, (k + 2) * n + 4 * (n + 1));
  CHECK(watertight(&mesh));
  vd_mesh_free(&mesh);
  vd_data_destroy(d);
  vd_model_destroy(m);
  // segments without the flag keep their own rings and caps
  for (int i = 0; i < s->nseg; i++)
    s->seg[i].flags = 0;
  m = compile(s);
  REQUIRE(m);
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, k * (4 * n + 2));
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

// ---------------------------------------------------------------------------------------------
// spheres and meshes

TEST(geom, sphere) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(1, 2, 3), f.radius = 0.5, f.slices = 8, f.label = 3, f.instance = 5;
  vd_plant_add_sphere(s, &f);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  // 8 longitudes, 4 stacks: 2 poles + 3 rings of 8; 2 x 8 x 3 triangles
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, 26);
  CHECK_INT(mesh.ntri, 48);
  CHECK(watertight(&mesh));
  for (int t = 0; t < mesh.ntri; t++)
    CHECK(mesh.tri_label[t] == 3 && mesh.tri_instance[t] == 5 &&
          mesh.tri_kind[t] == VD_PRIM_SPHERE);
  vd_mesh_free(&mesh);
  // finer: volume within the tessellation error below the analytic one, normals outward
  vd_mesh_def def = vd_mesh_def_default();
  def.slices = 64;
  CHECK_STATUS(vd_geom_tessellate(m, NULL, &def, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, 2 + 31 * 64);
  CHECK(watertight(&mesh));
  double exact = 4.0 / 3.0 * VD_PI * 0.125, vol = signed_volume(&mesh);
  CHECK(vol < exact);
  CHECK(vol > 0.98 * exact);
  for (int v = 0; v < mesh.nvert; v++) {
    vd_vec3 p = vd_v3(mesh.pos[3 * v] - 1, mesh.pos[3 * v + 1] - 2, mesh.pos[3 * v + 2] - 3);
    vd_vec3 nrm = vd_v3(mesh.normal[3 * v], mesh.normal[3 * v + 1], mesh.normal[3 * v + 2]);
    CHECK_NEAR(vd_norm(p), 0.5, 1e-12);
    CHECK_NEAR(vd_dot(nrm, vd_scale(p, 2)), 1, 1e-12);
  }
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

TEST(geom, meshes) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  // a unit cube, closed and outward
  vd_vec3 cv[8];
  for (int i = 0; i < 8; i++)
    cv[i] = vd_v3(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  int ct[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  vd_mesh_spec box = {0};
  box.closed = 1, box.label = 4, box.instance = 2, box.node = -1, box.parent = -1;
  vd_plant_add_mesh(s, &box, cv, 8, ct, 12);
  // a leaf quad
  vd_vec3 lv[4] = {{0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}};
  int lt[6] = {0, 1, 2, 0, 2, 3};
  vd_mesh_spec leaf = {0};
  leaf.label = 2, leaf.instance = 9, leaf.node = -1, leaf.parent = -1;
  vd_plant_add_mesh(s, &leaf, lv, 4, lt, 2);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  CHECK_INT(mesh.nvert, 12);
  CHECK_INT(mesh.ntri, 14);
  // the box alone: its 12 triangles enclose a unit volume
  vd_mesh cube = mesh;
  cube.ntri = 12;
  CHECK(watertight(&cube));
  CHECK_NEAR(signed_volume(&cube), 1, 1e-15);
  // the leaf keeps its vertices (re-indexed) and faces up
  CHECK_INT(mesh.tri[3 * 12], 8);
  CHECK(mesh.tri_label[13] == 2 && mesh.tri_instance[13] == 9 && mesh.tri_prim[13] == 1);
  CHECK(mesh.tri_kind[13] == VD_PRIM_MESH);
  CHECK_NEAR(mesh.normal[3 * 8 + 2], 1, 1e-15);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

TEST(geom, follows_state) {
  vd_plant_spec* s = one_segment(vd_v3(0, 0, 0), vd_v3(0, 0, 1), 0.1, 0.1, 6);
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_data* d = vd_data_create(m);
  REQUIRE(d);
  // move the tip: the end ring follows the node
  d->node_pos[5] = 2;
  vd_mesh mesh;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, d, NULL, &mesh, &err), VD_OK, err);
  CHECK_NEAR(mesh.pos[3 * 6 + 2], 2, 1e-15);
  CHECK_NEAR(signed_volume(&mesh), 2 * ngon_area(6, 0.1), 1e-12);
  vd_mesh_free(&mesh);
  // a state of another model is refused
  vd_model* m2 = NULL;
  vd_plant_spec* e = vd_plant_spec_create();
  REQUIRE(e);
  REQUIRE(vd_plant_compile(e, &m2, &err) == VD_OK);
  vd_data* d2 = vd_data_create(m2);
  CHECK_STATUS(vd_geom_tessellate(m, d2, NULL, &mesh, &err), VD_ERR_ARG, err);
  // an empty model gives an empty mesh
  memset(&err, 0, sizeof err);
  CHECK_STATUS(vd_geom_tessellate(m2, d2, NULL, &mesh, &err), VD_OK, err);
  CHECK(mesh.nvert == 0 && mesh.ntri == 0 && mesh.pos == NULL);
  vd_mesh_free(&mesh);
  vd_data_destroy(d2);
  vd_model_destroy(m2);
  vd_plant_spec_destroy(e);
  vd_data_destroy(d);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

// ---------------------------------------------------------------------------------------------
// writers

// a plant with two labelled organs of two instances each, tessellated
static vd_model* labelled_plant(vd_mesh* mesh) {
  vd_plant_spec* s = gc_tube(2, 6);
  if (!s) return NULL;
  vd_sphere_spec f = vd_sphere_spec_default();
  f.slices = 6, f.label = 3, f.instance = 2;
  vd_plant_add_sphere(s, &f);
  f.center = vd_v3(1, 0, 0), f.instance = 3;
  vd_plant_add_sphere(s, &f);
  vd_plant_set_label(s, 1, "main stem");
  vd_plant_set_label(s, 3, "fruit");
  vd_model* m = compile(s);
  vd_plant_spec_destroy(s);
  vd_error err = {0};
  if (m && vd_geom_tessellate(m, NULL, NULL, mesh, &err) != VD_OK) {
    vd_model_destroy(m);
    return NULL;
  }
  return m;
}

static int count_prefix(const char* text, const char* prefix) {
  int n = 0;
  size_t len = strlen(prefix);
  for (const char* l = text; l && *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL)
    if (strncmp(l, prefix, len) == 0) n++;
  return n;
}

static char* slurp(const char* path, size_t* len) {
  char* t = NULL;
  vd_error err = {0};
  if (vd_file_read(path, &t, len, &err) != VD_OK) return NULL;
  return t;
}

TEST(geom, write_obj) {
  vd_mesh mesh;
  vd_model* m = labelled_plant(&mesh);
  REQUIRE(m);
  char path[300], mtl[300];
  snprintf(path, sizeof path, "%s/plant.obj", vdt_tmpdir());
  snprintf(mtl, sizeof mtl, "%s/plant.mtl", vdt_tmpdir());
  vd_error err = {0};
  CHECK_STATUS(vd_geom_write_obj(&mesh, m->labels, m->nlabel, path, &err), VD_OK, err);
  size_t n = 0, nm = 0;
  char* t = slurp(path, &n);
  char* mt = slurp(mtl, &nm);
  REQUIRE(t && mt);
  CHECK_INT(count_prefix(t, "v "), mesh.nvert);
  CHECK_INT(count_prefix(t, "vn "), mesh.nvert);
  CHECK_INT(count_prefix(t, "f "), mesh.ntri);
  // one object per (label, instance), one material per label; names made safe
  CHECK_INT(count_prefix(t, "o "), 3);
  CHECK_INT(count_prefix(t, "usemtl "), 3);
  CHECK(strstr(t, "\no main_stem_1\ng main_stem\nusemtl main_stem\n") != NULL);
  CHECK(strstr(t, "\no fruit_2\n") && strstr(t, "\no fruit_3\n"));
  CHECK(strstr(t, "mtllib plant.mtl\n") != NULL);
  CHECK(strstr(t, "# label 1 main stem\n") && strstr(t, "# label 3 fruit\n"));
  CHECK(strstr(t, "format version 1") != NULL);
  CHECK_INT(count_prefix(mt, "newmtl "), 2);
  CHECK(strstr(mt, "newmtl fruit\n") && strstr(mt, "newmtl main_stem\n"));
  CHECK_INT(count_prefix(mt, "Kd "), 2);
  // faces grouped: every face line after "o fruit_2" up to the next "o" is a sphere face
  const char* f2 = strstr(t, "o fruit_2\n");
  const char* f3 = strstr(t, "o fruit_3\n");
  CHECK(f2 && f3 && f2 < f3);
  // a face references valid 1-based indices with normals
  const char* f = strstr(t, "\nf ");
  REQUIRE(f);
  int a, an, b, bn, c, cn;
  CHECK_INT(sscanf(f + 3, "%d//%d %d//%d %d//%d", &a, &an, &b, &bn, &c, &cn), 6);
  CHECK(a >= 1 && a <= mesh.nvert && a == an && b == bn && c == cn);
  vd_free(t, n + 1);
  vd_free(mt, nm + 1);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
}

TEST(geom, write_ply) {
  vd_mesh mesh;
  vd_model* m = labelled_plant(&mesh);
  REQUIRE(m);
  char path[300];
  snprintf(path, sizeof path, "%s/plant.ply", vdt_tmpdir());
  vd_error err = {0};
  // binary: header fields, then exactly 24 bytes per vertex and 21 per face
  CHECK_STATUS(vd_geom_write_ply(&mesh, m->labels, m->nlabel, path, 1, &err), VD_OK, err);
  size_t n = 0;
  char* t = slurp(path, &n);
  REQUIRE(t);
  char* end = strstr(t, "end_header\n");
  REQUIRE(end);
  size_t hdr = (size_t)(end - t) + strlen("end_header\n");
  CHECK(strncmp(t, "ply\nformat binary_little_endian 1.0\n", 36) == 0);
  char line[64];
  snprintf(line, sizeof line, "element vertex %d\n", mesh.nvert);
  CHECK(strstr(t, line) != NULL);
  snprintf(line, sizeof line, "element face %d\n", mesh.ntri);
  CHECK(strstr(t, line) != NULL);
  CHECK(strstr(
      t, "property list uchar int vertex_indices\nproperty int label\nproperty int instance\n"));
  CHECK(strstr(t, "property float nz\n") && strstr(t, "comment label 3 fruit\n"));
  CHECK_INT(n, hdr + 24 * (size_t)mesh.nvert + 21 * (size_t)mesh.ntri);
  // the last face record: 3, its indices, label 3, instance 3
  const unsigned char* r = (const unsigned char*)t + n - 21;
  int32_t vals[5];
  for (int k = 0; k < 5; k++) {
    const unsigned char* q = r + 1 + 4 * k;
    vals[k] = (int32_t)((uint32_t)q[0] | (uint32_t)q[1] << 8 | (uint32_t)q[2] << 16 |
                        (uint32_t)q[3] << 24);
  }
  int last = mesh.ntri - 1;
  CHECK_INT(r[0], 3);
  CHECK(vals[0] == mesh.tri[3 * last] && vals[2] == mesh.tri[3 * last + 2]);
  CHECK(vals[3] == 3 && vals[4] == 3);
  // the first vertex as little-endian floats
  const unsigned char* v = (const unsigned char*)t + hdr;
  uint32_t u = (uint32_t)v[0] | (uint32_t)v[1] << 8 | (uint32_t)v[2] << 16 | (uint32_t)v[3] << 24;
  float x;
  memcpy(&x, &u, sizeof x);
  CHECK(x == (float)mesh.pos[0]);
  vd_free(t, n + 1);
  // ASCII: one line per vertex and per face after the header
  CHECK_STATUS(vd_geom_write_ply(&mesh, m->labels, m->nlabel, path, 0, &err), VD_OK, err);
  t = slurp(path, &n);
  REQUIRE(t);
  CHECK(strncmp(t, "ply\nformat ascii 1.0\n", 21) == 0);
  end = strstr(t, "end_header\n");
  REQUIRE(end);
  int lines = 0;
  for (const char* c = end + strlen("end_header\n"); *c; c++)
    lines += *c == '\n';
  CHECK_INT(lines, mesh.nvert + mesh.ntri);
  CHECK_INT(count_prefix(end, "3 "), mesh.ntri);
  vd_free(t, n + 1);
  // an unwritable path is an I/O error and leaves nothing
  memset(&err, 0, sizeof err);
  CHECK_STATUS(vd_geom_write_ply(&mesh, NULL, 0, "/nonexistent-dir/x.ply", 1, &err), VD_ERR_IO,
               err);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
}

TEST(geom, out_of_memory) {
  vd_plant_spec* s = gc_tube(3, 8);
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  char path[300];
  snprintf(path, sizeof path, "%s/oom.obj", vdt_tmpdir());
  int done = 0;
  for (int64_t b = 0; b < 20 && !done; b++) {
    vdt_oom_begin(b);
    vd_mesh mesh;
    vd_error err = {0};
    vd_status st = vd_geom_tessellate(m, NULL, NULL, &mesh, &err);
    if (st == VD_OK) st = vd_geom_write_obj(&mesh, m->labels, m->nlabel, path, &err);
    done = st == VD_OK;
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    vd_mesh_free(&mesh);
    vdt_oom_end();
  }
  CHECK(done);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}
