// SPDX-License-Identifier: MIT
// cloud: exact point counts, uniformity (chi-square per triangle and inside a triangle, with the
// paper's barycentric draws as a negative control), points on their own primitive's surface,
// no point inside another closed primitive (brute force over every solid, bundled plants),
// noisy points checked too, density laws and noise sigma measured against the request, a leaf
// behind an opaque sphere never seen, scans, determinism across thread counts, writers read
// back, LAS layout, malformed files, scanner presets, bad settings, out of memory.
#include <stdlib.h>

#include "test.h"
#include "verdant/cloud.h"
#include "verdant/lsys.h"

// ---------------------------------------------------------------------------------------------
// helpers

static vd_model* compile(vd_plant_spec* s) {
  vd_model* m = NULL;
  vd_error err = {0};
  if (!s || vd_plant_compile(s, &m, &err) != VD_OK) m = NULL;
  vd_plant_spec_destroy(s);
  return m;
}

static vd_plant_spec* grow(const char* rel, uint64_t seed) {
  vd_lsystem* ls;
  vd_error e = {0};
  if (vd_lsys_load(vdt_path(rel), &ls, &e)) return NULL;
  vd_plant_spec* p = vd_plant_spec_create();
  vd_lsys_def d = vd_lsys_def_default();
  d.seed = seed;
  vd_status st = p ? vd_lsys_grow(ls, &d, NULL, p, &e) : VD_ERR_NOMEM;
  vd_lsys_destroy(ls);
  if (st) {
    vd_plant_spec_destroy(p);
    return NULL;
  }
  return p;
}

// add a mesh of triangles (thin unless closed) with one label and instance
static void add_mesh(vd_plant_spec* s, const vd_vec3* v, int nv, const int* t, int nt, int label,
                     int instance, int closed) {
  vd_mesh_spec ms;
  memset(&ms, 0, sizeof ms);
  ms.node = ms.parent = -1, ms.module = -1;
  ms.label = label, ms.instance = instance, ms.closed = closed;
  vd_plant_add_mesh(s, &ms, v, nv, t, nt);
}

// a flat square [-h, h]^2 in the plane z = 0 (two triangles), label 2
static void add_square(vd_plant_spec* s, double h, int instance) {
  vd_vec3 v[4] = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
  int t[6] = {0, 1, 2, 0, 2, 3};
  add_mesh(s, v, 4, t, 2, 2, instance, 0);
}

static void add_sphere(vd_plant_spec* s, vd_vec3 c, double r, int label, int instance, int slices) {
  vd_sphere_spec sp = vd_sphere_spec_default();
  sp.center = c, sp.radius = r, sp.label = label, sp.instance = instance, sp.slices = slices;
  vd_plant_add_sphere(s, &sp);
}

// 0.999 quantile of chi-square with k degrees of freedom (Wilson-Hilferty)
static double chi2_crit(int k) {
  double z = 3.090, a = 2.0 / (9.0 * k);
  double c = 1 - a + z * sqrt(a);
  return k * c * c * c;
}

static vd_vec3 pt(const vd_cloud* c, int64_t i) {
  return vd_v3(c->pos[3 * i], c->pos[3 * i + 1], c->pos[3 * i + 2]);
}

// distance from p to triangle t of a mesh (brute force, for checks)
static double dist_tri(const vd_mesh* m, int t, vd_vec3 p) {
  const double *pa = m->pos + 3 * m->tri[3 * t], *pb = m->pos + 3 * m->tri[3 * t + 1];
  const double* pc = m->pos + 3 * m->tri[3 * t + 2];
  vd_vec3 a = vd_v3(pa[0], pa[1], pa[2]), b = vd_v3(pb[0], pb[1], pb[2]), c = vd_v3(pc[0], pc[1], pc[2]);
  vd_vec3 n = vd_cross(vd_sub(b, a), vd_sub(c, a));
  double nn = vd_norm(n);
  if (nn == 0) return INFINITY;
  n = vd_scale(n, 1 / nn);
  double h = vd_dot(vd_sub(p, a), n);
  vd_vec3 q = vd_madd(p, n, -h);
  // inside test by edge signs; outside the triangle the distance only grows (a point off the
  // triangle returns infinity, enough to find its own triangle)
  double s1 = vd_dot(vd_cross(vd_sub(b, a), vd_sub(q, a)), n), s2 = vd_dot(vd_cross(vd_sub(c, b), vd_sub(q, b)), n);
  double s3 = vd_dot(vd_cross(vd_sub(a, c), vd_sub(q, c)), n);
  double tol = -1e-12 * nn;
  if (s1 < tol || s2 < tol || s3 < tol) return INFINITY;
  return fabs(h);
}

// ---------------------------------------------------------------------------------------------
// counts and uniformity

TEST(cloud, exact_count) {
  vd_model* m = compile(grow("data/arabidopsis.lpy", 2));
  REQUIRE(m);
  int64_t ns[5] = {1, 4095, 4096, 4097, 30001};
  for (int k = 0; k < 5; k++) {
    vd_cloud_def def = vd_cloud_def_default();
    def.points = ns[k];
    def.seed = (uint64_t)k;
    vd_cloud c;
    vd_cloud_stats st;
    vd_error err = {0};
    CHECK_STATUS(vd_cloud_sample(m, NULL, &def, &c, &st, &err), VD_OK, err);
    CHECK_INT(c.n, ns[k]);
    CHECK_INT(st.drawn, ns[k] + st.rejected_interior);
    for (int64_t i = 0; i < c.n; i++)
      CHECK(vd_model_find_label(m, c.label[i]) != NULL);
    CHECK_INT(c.nlabel, m->nlabel);
    vd_cloud_free(&c);
  }
  vd_model_destroy(m);
}

TEST(cloud, uniform_over_triangles) {
  // twelve separate triangles of areas 1..12 (relative), one instance each
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  double area[12], total = 0;
  for (int i = 0; i < 12; i++) {
    double w = 0.01 * (1 + i), x = 0.1 * i;
    vd_vec3 v[3] = {{x, 0, 0}, {x + w, 0, 0}, {x, 0.02 + 0.01 * (i % 3), 0.01}};
    int t[3] = {0, 1, 2};
    add_mesh(s, v, 3, t, 1, 2, i + 1, 0);
    area[i] = 0.5 * vd_norm(vd_cross(vd_sub(v[1], v[0]), vd_sub(v[2], v[0])));
    total += area[i];
  }
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 200000;
  def.seed = 5;
  vd_cloud c;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  int64_t count[12] = {0};
  for (int64_t i = 0; i < c.n; i++)
    count[c.instance[i] - 1]++;
  double chi2 = 0;
  for (int i = 0; i < 12; i++) {
    double e = def.points * area[i] / total;
    chi2 += (count[i] - e) * (count[i] - e) / e;
  }
  if (!(chi2 < chi2_crit(11))) vdt_fail(__FILE__, __LINE__, "chi2 %g >= %g", chi2, chi2_crit(11));
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

// cell of the 4 x 4 barycentric lattice (16 equal-area sub-triangles) of weights (b, c)
static int lattice_cell(double b, double c) {
  int i = (int)(4 * b), j = (int)(4 * c);
  if (i > 3) i = 3;
  if (j > 3) j = 3;
  if (i + j > 3) i = 3 - j;
  int upper = (4 * b - i) + (4 * c - j) > 1;
  // cells of row j: 2 (3 - j) + 1 triangles; index within the row
  int base = 0;
  for (int r = 0; r < j; r++)
    base += 2 * (3 - r) + 1;
  return base + 2 * i + upper;
}

static double lattice_chi2(const int64_t* cnt, int64_t n) {
  double chi2 = 0, e = n / 16.0;
  for (int k = 0; k < 16; k++)
    chi2 += (cnt[k] - e) * (cnt[k] - e) / e;
  return chi2;
}

TEST(cloud, uniform_inside_a_triangle) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  vd_vec3 a = vd_v3(0, 0, 0), b = vd_v3(0.3, 0.05, 0), c = vd_v3(0.1, 0.2, 0.02);
  vd_vec3 v[3] = {a, b, c};
  int t[3] = {0, 1, 2};
  add_mesh(s, v, 3, t, 1, 2, 1, 0);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 160000;
  def.seed = 9;
  vd_cloud cl;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &cl, NULL, &err) == VD_OK);
  // barycentric weights of each point by least squares on the two edges
  vd_vec3 e1 = vd_sub(b, a), e2 = vd_sub(c, a);
  double d11 = vd_dot(e1, e1), d12 = vd_dot(e1, e2), d22 = vd_dot(e2, e2), den = d11 * d22 - d12 * d12;
  int64_t cnt[16] = {0};
  for (int64_t i = 0; i < cl.n; i++) {
    vd_vec3 q = vd_sub(pt(&cl, i), a);
    double q1 = vd_dot(q, e1), q2 = vd_dot(q, e2);
    double wb = (d22 * q1 - d12 * q2) / den, wc = (d11 * q2 - d12 * q1) / den;
    CHECK(wb >= -1e-12 && wc >= -1e-12 && wb + wc <= 1 + 1e-12);
    cnt[lattice_cell(wb, wc)]++;
  }
  double chi2 = lattice_chi2(cnt, cl.n);
  if (!(chi2 < chi2_crit(15))) vdt_fail(__FILE__, __LINE__, "chi2 %g >= %g", chi2, chi2_crit(15));
  // negative controls: the paper's draws (three uniforms over their sum) crowd the centroid, and
  // a3 = 1 - a1 - a2 leaves the triangle about half the time
  vd_rng rng;
  vd_rng_seed(&rng, 1);
  int64_t bad[16] = {0}, outside = 0;
  for (int64_t i = 0; i < cl.n; i++) {
    double x = vd_rng_random(&rng), y = vd_rng_random(&rng), z = vd_rng_random(&rng), sum = x + y + z;
    bad[lattice_cell(y / sum, z / sum)]++;
    outside += vd_rng_random(&rng) + vd_rng_random(&rng) > 1;
  }
  CHECK(lattice_chi2(bad, cl.n) > 10 * chi2_crit(15));
  CHECK_NEAR((double)outside / cl.n, 0.5, 0.01);
  vd_cloud_free(&cl);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// surface and interior, by brute force over every triangle and every solid

static void check_surface_and_interior(const char* rel, uint64_t seed, int64_t n, int* inside_without) {
  vd_model* m = compile(grow(rel, seed));
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = n;
  def.seed = seed;
  vd_cloud c;
  vd_cloud_stats st;
  vd_mesh mesh;
  vd_solids so;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, &st, &err) == VD_OK);
  REQUIRE(vd_geom_tessellate(m, NULL, NULL, &mesh, &err) == VD_OK);
  REQUIRE(vd_solids_build(m, NULL, NULL, &so, &err) == VD_OK);
  CHECK(st.rejected_interior > 0);
  // triangles grouped by instance
  int maxi = 0;
  for (int t = 0; t < mesh.ntri; t++)
    if (mesh.tri_instance[t] > maxi) maxi = mesh.tri_instance[t];
  int* start = vd_calloc((size_t)maxi + 2, sizeof(int));
  int* order = vd_malloc((size_t)mesh.ntri * sizeof(int));
  REQUIRE(start && order);
  for (int t = 0; t < mesh.ntri; t++)
    start[mesh.tri_instance[t] + 1]++;
  for (int i = 0; i <= maxi; i++)
    start[i + 1] += start[i];
  int* fill = vd_calloc((size_t)maxi + 1, sizeof(int));
  REQUIRE(fill);
  for (int t = 0; t < mesh.ntri; t++)
    order[start[mesh.tri_instance[t]] + fill[mesh.tri_instance[t]]++] = t;
  int off_surface = 0, wrong_label = 0, inside = 0;
  for (int64_t i = 0; i < c.n; i++) {
    vd_vec3 p = pt(&c, i);
    // its own triangle: on the surface of a triangle of its instance, with its label
    int own = -1;
    double best = INFINITY;
    for (int k = start[c.instance[i]]; k < start[c.instance[i] + 1]; k++) {
      double d = dist_tri(&mesh, order[k], p);
      if (d < best) best = d, own = order[k];
    }
    if (!(best <= 1e-12)) {
      off_surface++;
      continue;
    }
    if (mesh.tri_label[own] != c.label[i]) wrong_label++;
    // no solid but its own primitive's (and tube neighbours') contains it
    int os = vd_solids_own(&so, mesh.tri_kind[own], mesh.tri_prim[own]);
    for (int k = 0; k < so.nsolid; k++) {
      if (k == os || (os >= 0 && (k == so.solid[os].joined[0] || k == so.solid[os].joined[1]))) continue;
      if (vd_solid_contains(&so, k, p)) {
        inside++;
        break;
      }
    }
  }
  if (off_surface) vdt_fail(__FILE__, __LINE__, "%s: %d points off their instance's surface", rel, off_surface);
  if (wrong_label) vdt_fail(__FILE__, __LINE__, "%s: %d points with another label", rel, wrong_label);
  if (inside) vdt_fail(__FILE__, __LINE__, "%s: %d points inside another solid", rel, inside);
  // without interior removal the same check finds points inside (the check can fail)
  def.interior = 0;
  vd_cloud_free(&c);
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  *inside_without = 0;
  for (int64_t i = 0; i < c.n; i++) {
    vd_vec3 p = pt(&c, i);
    int own = -1;
    double best = INFINITY;
    for (int k = start[c.instance[i]]; k < start[c.instance[i] + 1]; k++) {
      double d = dist_tri(&mesh, order[k], p);
      if (d < best) best = d, own = order[k];
    }
    if (own < 0) continue;
    int os = vd_solids_own(&so, mesh.tri_kind[own], mesh.tri_prim[own]);
    for (int k = 0; k < so.nsolid; k++)
      if (k != os && (os < 0 || (k != so.solid[os].joined[0] && k != so.solid[os].joined[1])) &&
          vd_solid_contains(&so, k, p)) {
        (*inside_without)++;
        break;
      }
  }
  vd_free(fill, ((size_t)maxi + 1) * sizeof(int));
  vd_free(order, (size_t)mesh.ntri * sizeof(int));
  vd_free(start, ((size_t)maxi + 2) * sizeof(int));
  vd_solids_free(&so);
  vd_mesh_free(&mesh);
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

TEST(cloud, on_surface_and_not_inside_arabidopsis) {
  int without = 0;
  check_surface_and_interior("data/arabidopsis.lpy", 4, 12000, &without);
  CHECK(without > 100);
}

TEST(cloud, on_surface_and_not_inside_tomato) {
  int without = 0;
  check_surface_and_interior("data/tomato.lpy", 1, 8000, &without);
  CHECK(without > 50);
}

TEST(cloud, joint_caps_removed) {
  // two segments in line, same frame: the caps where they meet are inside each other and go;
  // the outer caps stay
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0.1));
  int c = vd_plant_add_node(s, vd_v3(0, 0, 0.2));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.02, g.label = 1, g.instance = 1, g.up = vd_v3(1, 0, 0);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  vd_plant_add_segment(s, &g);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 20000;
  vd_cloud cl;
  vd_cloud_stats st;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &cl, &st, &err) == VD_OK);
  int inner = 0, outer = 0;
  for (int64_t i = 0; i < cl.n; i++) {
    if (fabs(cl.normal[3 * i + 2]) < 0.99) continue;
    double z = cl.pos[3 * i + 2];
    inner += fabs(z - 0.1) < 1e-9;
    outer += fabs(z) < 1e-9 || fabs(z - 0.2) < 1e-9;
  }
  CHECK_INT(inner, 0);
  CHECK(outer > 500);
  CHECK(st.rejected_interior > 500);
  vd_cloud_free(&cl);
  vd_model_destroy(m);
}

TEST(cloud, noisy_points_checked) {
  // a leaf through a fruit: noisy leaf points never end inside the fruit
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  add_square(s, 0.1, 1);
  add_sphere(s, vd_v3(0, 0, 0), 0.05, 3, 2, 16);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 40000;
  def.noise_sigma = 0.01;
  vd_cloud c;
  vd_cloud_stats st;
  vd_solids so;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, &st, &err) == VD_OK);
  REQUIRE(vd_solids_build(m, NULL, NULL, &so, &err) == VD_OK);
  CHECK(st.rejected_interior > 0 && st.rejected_noise > 0);
  int inside = 0, off = 0;
  for (int64_t i = 0; i < c.n; i++) {
    if (c.label[i] != 2) continue;
    inside += vd_solid_contains(&so, so.sphere_solid[0], pt(&c, i));
    off += fabs(c.pos[3 * i + 2]) > 1e-9;
  }
  CHECK_INT(inside, 0);
  CHECK(off > 1000);
  vd_solids_free(&so);
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// scanner effects measured against the request

// chi-square of the points' distance histogram (10 bins over [d0, d1]) against the density law
// integrated over the square [-1, 1]^2 on a fine grid
static double density_chi2(const vd_cloud* c, const vd_cloud_def* def, vd_vec3 s, double d0,
                           double d1, double dfar) {
  double expect[10] = {0}, total = 0;
  int g = 1000;
  for (int i = 0; i < g; i++)
    for (int j = 0; j < g; j++) {
      vd_vec3 p = vd_v3(-1 + (i + 0.5) * 2.0 / g, -1 + (j + 0.5) * 2.0 / g, 0);
      double d = vd_norm(vd_sub(p, s)), gam;
      if (def->density == VD_DENSITY_INVERSE_SQUARE) gam = (d0 / d) * (d0 / d);
      else if (def->density == VD_DENSITY_LINEAR) gam = 1 - (d - d0) / (dfar - d0);
      else {
        int k = 1;
        while (k < def->ntable - 1 && def->table_d[k] < d) k++;
        double f = (d - def->table_d[k - 1]) / (def->table_d[k] - def->table_d[k - 1]);
        f = f < 0 ? 0 : f > 1 ? 1 : f;
        gam = def->table_g[k - 1] + f * (def->table_g[k] - def->table_g[k - 1]);
      }
      int b = (int)((d - d0) / (d1 - d0) * 10);
      if (b > 9) b = 9;
      expect[b] += gam;
      total += gam;
    }
  int64_t cnt[10] = {0};
  for (int64_t i = 0; i < c->n; i++) {
    int b = (int)((vd_norm(vd_sub(pt(c, i), s)) - d0) / (d1 - d0) * 10);
    cnt[b < 0 ? 0 : b > 9 ? 9 : b]++;
  }
  double chi2 = 0;
  for (int b = 0; b < 10; b++) {
    double e = c->n * expect[b] / total;
    chi2 += (cnt[b] - e) * (cnt[b] - e) / e;
  }
  return chi2;
}

TEST(cloud, density_laws) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  add_square(s, 1, 1);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_scanner sc = vd_scanner_default();
  sc.pos = vd_v3(0, 0, 0.5);
  sc.target = vd_v3(0, 0, 0);
  double d0 = 0.5, d1 = 1.5, dfar = 1.5;
  vd_density_law laws[3] = {VD_DENSITY_INVERSE_SQUARE, VD_DENSITY_LINEAR, VD_DENSITY_TABLE};
  for (int l = 0; l < 3; l++) {
    vd_cloud_def def = vd_cloud_def_default();
    def.points = 100000;
    def.seed = 3 + (uint64_t)l;
    def.sensor = VD_SENSOR_DISTANCE;
    def.density = laws[l];
    def.nscanner = 1;
    def.scanner = &sc;
    def.ntable = 3;
    def.table_d[0] = 0.5, def.table_d[1] = 1.0, def.table_d[2] = 1.5;
    def.table_g[0] = 1.0, def.table_g[1] = 0.2, def.table_g[2] = 0.6;
    vd_cloud c;
    vd_cloud_stats st;
    vd_error err = {0};
    CHECK_STATUS(vd_cloud_sample(m, NULL, &def, &c, &st, &err), VD_OK, err);
    CHECK(st.rejected_density > 0);
    double chi2 = density_chi2(&c, &def, sc.pos, d0, d1, dfar);
    if (!(chi2 < chi2_crit(9))) vdt_fail(__FILE__, __LINE__, "law %d: chi2 %g >= %g", l, chi2, chi2_crit(9));
    // a uniform cloud fails the same test: it has teeth
    vd_cloud u;
    vd_cloud_def ud = def;
    ud.sensor = VD_SENSOR_UNIFORM;
    CHECK_STATUS(vd_cloud_sample(m, NULL, &ud, &u, NULL, &err), VD_OK, err);
    CHECK(density_chi2(&u, &def, sc.pos, d0, d1, dfar) > 10 * chi2_crit(9));
    // view and range recorded
    CHECK_INT(c.nview, 1);
    CHECK_NEAR(c.range[0], vd_norm(vd_sub(pt(&c, 0), sc.pos)), 1e-12);
    vd_cloud_free(&u);
    vd_cloud_free(&c);
  }
  vd_model_destroy(m);
}

TEST(cloud, noise_sigma) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  add_square(s, 1, 1);
  vd_model* m = compile(s);
  REQUIRE(m);
  // constant sigma: the spread across the plane is sigma
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 100000;
  def.noise_sigma = 0.01;
  vd_cloud c;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  double sum = 0, sum2 = 0;
  for (int64_t i = 0; i < c.n; i++)
    sum += c.pos[3 * i + 2], sum2 += c.pos[3 * i + 2] * c.pos[3 * i + 2];
  double mean = sum / c.n, sd = sqrt(sum2 / c.n - mean * mean);
  CHECK_NEAR(sd / 0.01, 1, 0.01);
  CHECK(fabs(mean) < 4 * 0.01 / sqrt((double)c.n));
  vd_cloud_free(&c);
  // sigma growing with distance: z / sigma(d) has unit spread near and far
  vd_scanner sc = vd_scanner_default();
  sc.pos = vd_v3(-3, 0, 0);
  sc.target = vd_v3(0, 0, 0);
  def.noise_sigma = 0.002;
  def.noise_slope = 0.005;
  def.nscanner = 1;
  def.scanner = &sc;
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  double s2[2] = {0, 0};
  int64_t n[2] = {0, 0};
  for (int64_t i = 0; i < c.n; i++) {
    vd_vec3 p = pt(&c, i);
    double d = vd_norm(vd_sub(vd_v3(p.x, p.y, 0), sc.pos)), sig = 0.002 + 0.005 * d;
    int h = p.x > 0;
    s2[h] += (p.z / sig) * (p.z / sig), n[h]++;
  }
  CHECK_NEAR(sqrt(s2[0] / n[0]), 1, 0.015);
  CHECK_NEAR(sqrt(s2[1] / n[1]), 1, 0.015);
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

TEST(cloud, occluded_behind_sphere) {
  // a leaf behind an opaque sphere, seen from the other side
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  add_sphere(s, vd_v3(0, 0, 0), 0.2, 3, 1, 24);
  vd_vec3 v[3] = {{0.5, -0.05, -0.05}, {0.5, 0.05, -0.05}, {0.5, 0, 0.06}};
  int t[3] = {0, 1, 2};
  add_mesh(s, v, 3, t, 1, 2, 2, 0);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_scanner sc = vd_scanner_default();
  sc.pos = vd_v3(-2, 0, 0);
  sc.target = vd_v3(0, 0, 0);
  sc.res_h = sc.res_v = 200;
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 20000;
  def.nscanner = 1;
  def.scanner = &sc;
  vd_cloud c;
  vd_cloud_stats st;
  vd_error err = {0};
  // without occlusion the leaf gets its share
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  int leaf = 0;
  for (int64_t i = 0; i < c.n; i++)
    leaf += c.label[i] == 2;
  CHECK(leaf > 10);
  vd_cloud_free(&c);
  // with it: never, and only the sphere's near side
  for (int sensor = 0; sensor < 3; sensor++) {
    def.occlusion = 1;
    def.sensor = (vd_sensor)sensor;
    CHECK_STATUS(vd_cloud_sample(m, NULL, &def, &c, &st, &err), VD_OK, err);
    CHECK(c.n > 1000);
    int hidden = 0, far_side = 0;
    for (int64_t i = 0; i < c.n; i++) {
      hidden += c.label[i] == 2;
      far_side += c.pos[3 * i] > 0.0 + 1e-9;
    }
    CHECK_INT(hidden, 0);
    // points past the tangent circle of the scanner's view are back faces
    if (far_side) vdt_fail(__FILE__, __LINE__, "sensor %d: %d points on the far side", sensor, far_side);
    if (sensor != VD_SENSOR_SCAN) CHECK(st.rejected_occluded > 0 && st.rejected_backface > 0);
    vd_cloud_free(&c);
  }
  vd_model_destroy(m);
}

TEST(cloud, scan_hits_and_range_noise) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  add_sphere(s, vd_v3(0, 0, 0), 0.2, 3, 1, 32);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_scanner sc[2];
  sc[0] = vd_scanner_default();
  sc[0].pos = vd_v3(-1, 0, 0), sc[0].target = vd_v3(0, 0, 0), sc[0].res_h = sc[0].res_v = 100;
  sc[1] = sc[0];
  sc[1].pos = vd_v3(0, 0, 1.5), sc[1].pattern = VD_SCAN_PINHOLE, sc[1].res_h = 160, sc[1].res_v = 120;
  vd_cloud_def def = vd_cloud_def_default();
  def.sensor = VD_SENSOR_SCAN;
  def.nscanner = 2;
  def.scanner = sc;
  vd_cloud a, b;
  vd_cloud_stats st;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &a, &st, &err) == VD_OK);
  CHECK_INT(st.drawn, 100 * 100 + 160 * 120);
  CHECK_INT(a.n + st.missed, st.drawn);
  // every hit on the tessellated sphere, facing its scanner, with its range
  int views[2] = {0, 0}, away = 0;
  for (int64_t i = 0; i < a.n; i++) {
    vd_vec3 p = pt(&a, i), o = sc[a.view[i]].pos;
    double r = vd_norm(p);
    CHECK(r <= 0.2 + 1e-12 && r >= 0.2 * cos(VD_PI / 32) * cos(VD_PI / 32) - 1e-12);
    CHECK_NEAR(a.range[i], vd_norm(vd_sub(p, o)), 1e-12);
    // smooth normals lean at most about one facet (11 degrees) past the silhouette
    vd_vec3 nrm = vd_v3(a.normal[3 * i], a.normal[3 * i + 1], a.normal[3 * i + 2]);
    double facing = vd_dot(nrm, vd_normalize(vd_sub(o, p)));
    CHECK(facing > -0.2);
    away += facing < 0;
    views[a.view[i]]++;
  }
  // the sphere covers about (asin(0.2) / 30 deg)^2 * pi / 4 ... of the angular grid: some hits
  CHECK(views[0] > 500 && views[1] > 500);
  CHECK(away < a.n / 50);
  // range noise: the same rays hit, the ranges differ by sigma
  def.noise_sigma = 0.005;
  REQUIRE(vd_cloud_sample(m, NULL, &def, &b, NULL, &err) == VD_OK);
  REQUIRE(b.n == a.n);
  double s2 = 0;
  for (int64_t i = 0; i < a.n; i++)
    s2 += (b.range[i] - a.range[i]) * (b.range[i] - a.range[i]);
  CHECK_NEAR(sqrt(s2 / a.n) / 0.005, 1, 0.05);
  vd_cloud_free(&a);
  vd_cloud_free(&b);
  vd_model_destroy(m);
}

TEST(cloud, deterministic_across_threads) {
  vd_model* m = compile(grow("data/arabidopsis.lpy", 6));
  REQUIRE(m);
  vd_scanner sc[2];
  sc[0] = vd_scanner_default();
  sc[0].pos = vd_v3(0.3, 0, 0.15), sc[0].target = vd_v3(0, 0, 0.1);
  sc[1] = sc[0];
  sc[1].pos = vd_v3(-0.2, 0.2, 0.3);
  for (int mode = 0; mode < 2; mode++) {
    vd_cloud_def def = vd_cloud_def_default();
    def.points = 30000;
    def.seed = 77;
    def.sensor = mode ? VD_SENSOR_SCAN : VD_SENSOR_DISTANCE;
    def.occlusion = !mode;
    def.noise_sigma = 0.0005, def.noise_slope = 0.001;
    def.nscanner = 2;
    def.scanner = sc;
    vd_cloud c1, c2;
    vd_error err = {0};
    def.threads = 1;
    REQUIRE(vd_cloud_sample(m, NULL, &def, &c1, NULL, &err) == VD_OK);
    def.threads = 2;
    REQUIRE(vd_cloud_sample(m, NULL, &def, &c2, NULL, &err) == VD_OK);
    REQUIRE(c1.n == c2.n && c1.n > 0);
    CHECK(memcmp(c1.pos, c2.pos, c1.nbytes) == 0);  // the whole point block
    // and the files
    char p1[512], p2[512];
    snprintf(p1, sizeof p1, "%s/det1.ply", vdt_tmpdir());
    snprintf(p2, sizeof p2, "%s/det2.ply", vdt_tmpdir());
    CHECK(vd_cloud_write(&c1, p1, NULL, &err) == VD_OK && vd_cloud_write(&c2, p2, NULL, &err) == VD_OK);
    char *t1, *t2;
    size_t l1, l2;
    REQUIRE(vd_file_read(p1, &t1, &l1, &err) == VD_OK && vd_file_read(p2, &t2, &l2, &err) == VD_OK);
    CHECK(l1 == l2 && memcmp(t1, t2, l1) == 0);
    vd_free(t1, l1 + 1);
    vd_free(t2, l2 + 1);
    // another seed, another cloud
    def.seed = 78;
    vd_cloud_free(&c2);
    REQUIRE(vd_cloud_sample(m, NULL, &def, &c2, NULL, &err) == VD_OK);
    CHECK(c1.n != c2.n || memcmp(c1.pos, c2.pos, (size_t)c1.n * 3 * sizeof(double)) != 0);
    vd_cloud_free(&c1);
    vd_cloud_free(&c2);
  }
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// files

static void compare(const vd_cloud* a, const vd_cloud* b, double tol_pos, double tol_n, int las) {
  REQUIRE(a->n == b->n);
  CHECK_INT(b->nview, a->nview);
  CHECK_INT(b->nlabel, a->nlabel);
  for (int l = 0; l < a->nlabel && l < b->nlabel; l++) {
    CHECK_INT(b->labels[l].id, a->labels[l].id);
    if (las)
      CHECK(strncmp(b->labels[l].name, a->labels[l].name, 15) == 0);
    else
      CHECK_STR(b->labels[l].name, a->labels[l].name);
  }
  int bad = 0;
  for (int64_t i = 0; i < a->n && bad < 5; i++) {
    for (int k = 0; k < 3; k++) {
      if (!(fabs(a->pos[3 * i + k] - b->pos[3 * i + k]) <= tol_pos)) bad++;
      if (!(fabs(a->normal[3 * i + k] - b->normal[3 * i + k]) <= tol_n)) bad++;
    }
    if (a->label[i] != b->label[i] || a->instance[i] != b->instance[i] || a->view[i] != b->view[i]) bad++;
    if (!(fabs(a->range[i] - b->range[i]) <= tol_pos)) bad++;
  }
  CHECK_INT(bad, 0);
}

TEST(cloud, writers_read_back) {
  vd_model* m = compile(grow("data/tomato.lpy", 2));
  REQUIRE(m);
  vd_scanner sc[2];
  sc[0] = vd_scanner_default();
  sc[0].pos = vd_v3(1.5, 0, 0.7), sc[0].target = vd_v3(0, 0, 0.6);
  sc[1] = sc[0];
  sc[1].pos = vd_v3(-1.5, 0.2, 0.9);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 5000;
  def.nscanner = 2;
  def.scanner = sc;
  def.noise_sigma = 0.001;
  vd_cloud c;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  struct {
    const char* name;
    int ascii;
    const char* prefix;
    double tol_pos, tol_n;
    int las;
  } cases[] = {
      {"a.ply", 0, NULL, 1e-6, 1e-6, 0},      {"b.ply", 1, NULL, 1e-6, 1e-6, 0},
      {"c.ply", 0, "scalar_", 1e-6, 1e-6, 0}, {"d.pcd", 0, NULL, 1e-6, 1e-6, 0},
      {"e.pcd", 1, NULL, 1e-6, 1e-6, 0},      {"f.xyz", 0, NULL, 1e-8, 1e-6, 0},
      {"g.csv", 0, NULL, 1e-8, 1e-6, 0},      {"h.las", 0, NULL, 6e-7, 1e-6, 1},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s", vdt_tmpdir(), cases[k].name);
    vd_cloud_write_def wd = vd_cloud_write_def_default();
    wd.ascii = cases[k].ascii;
    wd.ply_prefix = cases[k].prefix;
    wd.comment = "a test\nwith a line break";
    CHECK_STATUS(vd_cloud_write(&c, path, &wd, &err), VD_OK, err);
    vd_cloud r;
    CHECK_STATUS(vd_cloud_read(path, &r, &err), VD_OK, err);
    if (r.n == c.n) compare(&c, &r, cases[k].tol_pos, cases[k].tol_n, cases[k].las);
    else vdt_fail(__FILE__, __LINE__, "%s: %lld points read back", cases[k].name, (long long)r.n);
    vd_cloud_free(&r);
  }
  // instance labels: the table follows
  CHECK_STATUS(vd_cloud_relabel(&c, &err), VD_OK, err);
  for (int64_t i = 0; i < c.n; i++)
    CHECK_INT(c.label[i], c.instance[i]);
  CHECK(c.nlabel > 10);
  char path[512];
  snprintf(path, sizeof path, "%s/inst.ply", vdt_tmpdir());
  CHECK_STATUS(vd_cloud_write(&c, path, NULL, &err), VD_OK, err);
  vd_cloud r;
  CHECK_STATUS(vd_cloud_read(path, &r, &err), VD_OK, err);
  compare(&c, &r, 1e-6, 1e-6, 0);
  vd_cloud_free(&r);
  // a bad prefix and an unknown extension are refused, nothing is left behind
  vd_cloud_write_def wd = vd_cloud_write_def_default();
  wd.ply_prefix = "bad prefix";
  snprintf(path, sizeof path, "%s/bad.ply", vdt_tmpdir());
  CHECK_STATUS(vd_cloud_write(&c, path, &wd, &err), VD_ERR_ARG, err);
  snprintf(path, sizeof path, "%s/bad.txt", vdt_tmpdir());
  CHECK_STATUS(vd_cloud_write(&c, path, NULL, &err), VD_ERR_ARG, err);
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

static uint64_t rd(const unsigned char* p, int n) {
  uint64_t u = 0;
  for (int k = n - 1; k >= 0; k--)
    u = (u << 8) | p[k];
  return u;
}

TEST(cloud, las_layout) {
  vd_model* m = compile(grow("data/arabidopsis.lpy", 1));
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 1000;
  vd_cloud c;
  vd_error err = {0};
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  char path[512];
  snprintf(path, sizeof path, "%s/l.las", vdt_tmpdir());
  REQUIRE(vd_cloud_write(&c, path, NULL, &err) == VD_OK);
  char* t;
  size_t len;
  REQUIRE(vd_file_read(path, &t, &len, &err) == VD_OK);
  const unsigned char* b = (const unsigned char*)t;
  CHECK(memcmp(b, "LASF", 4) == 0);
  CHECK_INT(b[24], 1);
  CHECK_INT(b[25], 4);
  CHECK_INT(rd(b + 94, 2), 375);
  CHECK_INT(b[104], 6);
  CHECK_INT(rd(b + 105, 2), 58);
  CHECK_INT(rd(b + 107, 4), 0);  // legacy count: 0 for format 6
  CHECK_INT(rd(b + 247, 8), 1000);
  CHECK_INT(rd(b + 100, 4), 3);
  uint64_t off = rd(b + 96, 4);
  CHECK_INT(len, off + 1000 * 58);
  // classification lookup, extra bytes (7 descriptors of 192 bytes), verdant's label table
  CHECK(memcmp(b + 375 + 2, "LASF_Spec", 9) == 0);
  CHECK_INT(rd(b + 375 + 18, 2), 0);
  size_t v2 = 375 + 54 + rd(b + 375 + 20, 2);
  CHECK_INT(rd(b + v2 + 18, 2), 4);
  CHECK_INT(rd(b + v2 + 20, 2), 7 * 192);
  CHECK(memcmp(b + v2 + 54 + 4, "label", 5) == 0);
  CHECK(memcmp(b + v2 + 54 + 192 + 4, "instance", 8) == 0);
  size_t v3 = v2 + 54 + 7 * 192;
  CHECK(memcmp(b + v3 + 2, "verdant", 8) == 0);
  CHECK_INT(rd(b + v3 + 20, 2), c.nlabel * 56);
  // first point: classification 64 + label (a user class), synthetic, return 1 of 1; the label,
  // instance and view in extra bytes
  CHECK_INT(b[off + 16], 64 + c.label[0]);
  CHECK_INT(b[off + 15], 1);
  CHECK_INT(b[off + 14], 0x11);
  CHECK_INT(rd(b + off + 30, 4), c.label[0]);
  CHECK_INT(rd(b + off + 34, 4), c.instance[0]);
  vd_free(t, len + 1);
  // labels beyond the user classes: unclassified, the id in the extra bytes; read back whole
  c.label[0] = 300;
  CHECK_STATUS(vd_cloud_write(&c, path, NULL, &err), VD_OK, err);
  vd_cloud back;
  CHECK_STATUS(vd_cloud_read(path, &back, &err), VD_OK, err);
  CHECK_INT(back.n, c.n);
  if (back.n == c.n) CHECK(back.label[0] == 300 && back.label[1] == c.label[1] && back.instance[5] == c.instance[5]);
  CHECK_INT(back.nlabel, c.nlabel);
  vd_cloud_free(&back);
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

// LAS classes (issue 12, item 18): ASPRS 1 for no organ, 2 for ground, user classes 64 + id for
// the organs, 1 beyond; the label table survives in verdant's VLR, or in an extended VLR after
// the points when it is longer than a VLR holds
TEST(cloud, las_classes_and_label_table) {
  vd_error err = {0};
  for (int big = 0; big < 2; big++) {
    int nl = big ? 1500 : 4;
    vd_label* labels = vd_calloc((size_t)nl, sizeof(vd_label));
    REQUIRE(labels);
    vd_label_init(&labels[0], 0, "none");
    vd_label_init(&labels[1], 3, "Ground");
    vd_label_init(&labels[2], 7, "leaf");
    vd_label_init(&labels[3], 250, "fruit");
    for (int i = 4; i < nl; i++) {
      char name[32];
      snprintf(name, sizeof name, "leaf_%d", i);
      vd_label_init(&labels[i], 1000 + i, name);
    }
    vd_cloud c;
    REQUIRE(vd_cloud_alloc(&c, nl, labels, nl, &err) == VD_OK);
    for (int i = 0; i < nl; i++) {
      c.pos[3 * i] = 0.01 * i, c.pos[3 * i + 1] = -0.5, c.pos[3 * i + 2] = 1;
      c.normal[3 * i + 2] = 1;
      c.label[i] = labels[i].id, c.instance[i] = i + 1;
    }
    char path[512];
    snprintf(path, sizeof path, "%s/classes%d.las", vdt_tmpdir(), big);
    CHECK_STATUS(vd_cloud_write(&c, path, NULL, &err), VD_OK, err);
    char* t;
    size_t len;
    REQUIRE(vd_file_read(path, &t, &len, &err) == VD_OK);
    const unsigned char* b = (const unsigned char*)t;
    uint64_t off = rd(b + 96, 4), rl = rd(b + 105, 2);
    static const int want[4] = {1, 2, 64 + 7, 1};
    for (int i = 0; i < 4; i++)
      CHECK_INT(b[off + rl * (uint64_t)i + 16], want[i]);
    if (big) {
      CHECK_INT(b[off + rl * 4 + 16], 1);  // id 1004: no user class
      CHECK_INT(rd(b + 243, 4), 1);        // one extended VLR: the label table
      uint64_t ev = rd(b + 235, 8);
      CHECK_INT(ev, off + rl * (uint64_t)nl);
      CHECK(ev + 60 <= len && memcmp(b + ev + 2, "verdant", 8) == 0);
      CHECK_INT(rd(b + ev + 20, 8), (uint64_t)nl * 56);
    } else {
      CHECK_INT(rd(b + 243, 4), 0);
    }
    vd_free(t, len + 1);
    vd_cloud r;
    CHECK_STATUS(vd_cloud_read(path, &r, &err), VD_OK, err);
    CHECK_INT(r.nlabel, nl);
    for (int i = 0; i < nl && i < r.nlabel; i++) {
      CHECK_INT(r.labels[i].id, labels[i].id);
      CHECK_STR(r.labels[i].name, labels[i].name);
    }
    for (int64_t i = 0; i < r.n && i < nl; i++)
      if (r.label[i] != labels[i].id || r.instance[i] != (int)i + 1) {
        CHECK_INT(r.label[i], labels[i].id);
        break;
      }
    vd_cloud_free(&r);
    vd_cloud_free(&c);
    vd_free(labels, (size_t)nl * sizeof(vd_label));
  }
}

static void write_text_file(const char* path, const char* s, size_t n) {
  FILE* f = fopen(path, "wb");
  if (!f) return;
  fwrite(s, 1, n, f);
  fclose(f);
}

TEST(cloud, reader_rejects_bad_files) {
  struct {
    const char* name;
    const char* text;
    vd_status want;
  } cases[] = {
      {"a.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n\1\2\3", VD_ERR_FORMAT},
      {"b.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n", VD_ERR_FORMAT},
      {"c.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                "end_header\n1 2 3\n4 five 6\n", VD_ERR_FORMAT},
      {"d.ply", "ply\nformat binary_big_endian 1.0\nelement vertex 0\nend_header\n", VD_ERR_UNSUPPORTED},
      {"e.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quux x\nend_header\n", VD_ERR_FORMAT},
      {"f.ply", "not a ply\n", VD_ERR_FORMAT},
      {"g.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n", VD_ERR_FORMAT},
      {"h.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 3\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
                "DATA ascii\n1 2 3\n", VD_ERR_UNSUPPORTED},
      {"i.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
                "DATA binary_compressed\n", VD_ERR_UNSUPPORTED},
      {"j.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n", VD_ERR_FORMAT},
      {"k.csv", "x,y,z,label\n1,2,3,4.5\n", VD_ERR_FORMAT},
      {"l.csv", "a,b,c\n1,2,3\n", VD_ERR_FORMAT},
      {"m.xyz", "# x y z\n1 2\n", VD_ERR_FORMAT},
      {"n.las", "LASF", VD_ERR_FORMAT},
      {"o.ply", "ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n1 2 3\n", VD_ERR_FORMAT},
      {"p.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1000000000\nDATA ascii\n1 2 3\n",
       VD_ERR_FORMAT},
      {"q.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nproperty int view\nend_header\n1 2 3 2147483647\n", VD_ERR_FORMAT},
  };
  vd_error err = {0};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s", vdt_tmpdir(), cases[k].name);
    write_text_file(path, cases[k].text, strlen(cases[k].text));
    vd_cloud c;
    vd_status st = vd_cloud_read(path, &c, &err);
    if (st != cases[k].want)
      vdt_fail(__FILE__, __LINE__, "%s: %s, expected %s", cases[k].name, vd_status_str(st), vd_status_str(cases[k].want));
    CHECK(c.n == 0 && c.pos == NULL);
  }
  // an empty cloud reads (no arrays), in memory too (fuzzing found null + 0 here)
  vd_cloud ec;
  const char* empty = "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n";
  memset(&err, 0, sizeof err);
  CHECK_STATUS(vd_cloud_parse(empty, strlen(empty), VD_CLOUD_PLY, "empty.ply", &ec, &err), VD_OK, err);
  CHECK(ec.n == 0 && ec.pos == NULL && ec.label == NULL);
  vd_cloud_free(&ec);
  // good files cut short or with bytes flipped: an error or a cloud, never a crash
  vd_model* m = compile(grow("data/arabidopsis.lpy", 1));
  REQUIRE(m);
  vd_cloud_def def = vd_cloud_def_default();
  def.points = 50;
  vd_cloud c;
  REQUIRE(vd_cloud_sample(m, NULL, &def, &c, NULL, &err) == VD_OK);
  const char* exts[] = {"ply", "pcd", "xyz", "csv", "las"};
  unsigned seed = 1;
  for (int e = 0; e < 5; e++) {
    char path[512], bad[512];
    snprintf(path, sizeof path, "%s/good.%s", vdt_tmpdir(), exts[e]);
    snprintf(bad, sizeof bad, "%s/bad.%s", vdt_tmpdir(), exts[e]);
    REQUIRE(vd_cloud_write(&c, path, NULL, &err) == VD_OK);
    char* t;
    size_t len;
    REQUIRE(vd_file_read(path, &t, &len, &err) == VD_OK);
    for (int trial = 0; trial < 200; trial++) {
      seed = seed * 1664525u + 1013904223u;
      size_t cut = (seed >> 8) % (len + 1);
      char* copy = vd_malloc(len + 1);
      REQUIRE(copy);
      memcpy(copy, t, len);
      size_t n = trial % 2 ? cut : len;
      if (!(trial % 2))
        for (int f = 0; f < 4; f++) {
          seed = seed * 1664525u + 1013904223u;
          copy[(seed >> 8) % len] = (char)(seed >> 3);
        }
      write_text_file(bad, copy, n);
      vd_cloud r;
      vd_status st = vd_cloud_read(bad, &r, &err);
      CHECK(st == VD_OK || st == VD_ERR_FORMAT || st == VD_ERR_UNSUPPORTED);
      vd_cloud_free(&r);
      vd_free(copy, len + 1);
    }
    vd_free(t, len + 1);
  }
  vd_cloud_free(&c);
  vd_model_destroy(m);
}

// ---------------------------------------------------------------------------------------------
// presets, settings, failures

TEST(cloud, scanner_presets) {
  vd_scanner* sc;
  int n;
  vd_error err = {0};
  CHECK_STATUS(vd_cloud_read_scanners(vdt_path("data/scanners/turntable8.json"), vd_v3(-1, -1, 0),
                                      vd_v3(1, 1, 2), &sc, &n, &err), VD_OK, err);
  REQUIRE(n == 8);
  for (int i = 0; i < n; i++) {
    CHECK_NEAR(hypot(sc[i].pos.x, sc[i].pos.y), 2.4, 1e-5);
    CHECK_NEAR(sc[i].pos.z, 1.5, 1e-12);
    CHECK_NEAR(sc[i].target.z, 1, 1e-12);
    CHECK_INT(sc[i].res_h, 400);
  }
  vd_free(sc, (size_t)n * sizeof *sc);
  CHECK_STATUS(vd_cloud_read_scanners(vdt_path("data/scanners/topdown_depth.json"), vd_v3(0, 0, 0),
                                      vd_v3(1, 1, 1), &sc, &n, &err), VD_OK, err);
  REQUIRE(n == 1);
  CHECK_INT(sc[0].pattern, VD_SCAN_PINHOLE);
  CHECK_NEAR(sc[0].fov_h, 58 * VD_PI / 180, 1e-12);
  vd_free(sc, (size_t)n * sizeof *sc);
  // faults: file, JSON with its place, fields
  char path[512];
  snprintf(path, sizeof path, "%s/bad.json", vdt_tmpdir());
  const char* bad[] = {"{\"format\": \"verdant-scanners\", \"version\": 1,\n \"scanners\": [ {\"position\": [1, 2]} ]}",
                       "{\"format\": \"x\", \"version\": 1, \"scanners\": []}",
                       "{\"format\": \"verdant-scanners\",\n \"version\": 1, \"scanners\": [,]}"};
  vd_status want[] = {VD_ERR_FORMAT, VD_ERR_FORMAT, VD_ERR_SYNTAX};
  for (int k = 0; k < 3; k++) {
    memset(&err, 0, sizeof err);  // vd_error keeps the first error
    write_text_file(path, bad[k], strlen(bad[k]));
    CHECK_STATUS(vd_cloud_read_scanners(path, vd_v3(0, 0, 0), vd_v3(1, 1, 1), &sc, &n, &err), want[k], err);
    if (want[k] == VD_ERR_SYNTAX) CHECK_INT(err.line, 2);
  }
}

TEST(cloud, bad_settings) {
  vd_model* m = compile(grow("data/arabidopsis.lpy", 1));
  REQUIRE(m);
  vd_scanner sc = vd_scanner_default();
  vd_cloud c;
  vd_error err = {0};
  for (int k = 0; k < 9; k++) {
    vd_cloud_def def = vd_cloud_def_default();
    def.points = 10;
    switch (k) {
      case 0: def.points = 0; break;
      case 1: def.sensor = VD_SENSOR_DISTANCE; break;
      case 2: def.occlusion = 1; break;
      case 3: def.noise_sigma = -1; break;
      case 4: def.noise_slope = 0.1; break;
      case 5: def.sensor = VD_SENSOR_SCAN; break;
      case 6: def.sensor = VD_SENSOR_DISTANCE, def.density = VD_DENSITY_TABLE, def.ntable = 1, def.nscanner = 1, def.scanner = &sc; break;
      case 7: def.sensor = VD_SENSOR_SCAN, def.nscanner = 1, sc.fov_h = 0, def.scanner = &sc; break;
      default: def.nscanner = 1, sc = vd_scanner_default(), sc.target = sc.pos, def.scanner = &sc; break;
    }
    vd_status st = vd_cloud_sample(m, NULL, &def, &c, NULL, &err);
    if (st != VD_ERR_ARG) vdt_fail(__FILE__, __LINE__, "case %d: %s", k, vd_status_str(st));
  }
  // a scanner inside a closed sphere sees only back faces: a clear failure, not a hang
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  add_sphere(s, vd_v3(0, 0, 0), 1, 3, 1, 8);
  vd_model* ms = compile(s);
  REQUIRE(ms);
  vd_cloud_def def = vd_cloud_def_default();
  sc = vd_scanner_default();
  sc.pos = vd_v3(0, 0, 0), sc.target = vd_v3(1, 0, 0);
  def.points = 10, def.occlusion = 1, def.nscanner = 1, def.scanner = &sc, def.max_attempts = 1000;
  CHECK_STATUS(vd_cloud_sample(ms, NULL, &def, &c, NULL, &err), VD_ERR_VALUE, err);
  vd_model_destroy(ms);
  vd_model_destroy(m);
}

TEST(cloud, out_of_memory) {
  vd_model* m = compile(grow("data/arabidopsis.lpy", 1));
  REQUIRE(m);
  vd_scanner sc = vd_scanner_default();
  sc.pos = vd_v3(0.3, 0, 0.1), sc.target = vd_v3(0, 0, 0.1), sc.res_h = sc.res_v = 20;
  char path[512];
  snprintf(path, sizeof path, "%s/oom.las", vdt_tmpdir());
  for (int mode = 0; mode < 2; mode++) {
    int ok = 0;
    for (int budget = 0; budget < 200 && !ok; budget++) {
      vd_cloud_def def = vd_cloud_def_default();
      def.points = 5000;
      def.sensor = mode ? VD_SENSOR_SCAN : VD_SENSOR_UNIFORM;
      def.occlusion = !mode;
      def.nscanner = 1;
      def.scanner = &sc;
      if (mode) def.points = 1;
      vd_cloud c;
      vd_error err = {0};
      vdt_oom_begin(budget);
      vd_status a = vd_cloud_sample(m, NULL, &def, &c, NULL, &err);
      vd_status b = a ? a : vd_cloud_write(&c, path, NULL, &err);
      vd_cloud r;
      vd_status d = b ? b : vd_cloud_read(path, &r, &err);
      vdt_oom_end();
      CHECK(a == VD_OK || a == VD_ERR_NOMEM);
      CHECK(b == VD_OK || b == VD_ERR_NOMEM);
      CHECK(d == VD_OK || d == VD_ERR_NOMEM);
      if (!a) vd_cloud_free(&c);
      if (!d) vd_cloud_free(&r);
      ok = !d;
    }
    CHECK(ok);
  }
  vd_model_destroy(m);
}
