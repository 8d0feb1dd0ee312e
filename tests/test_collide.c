// SPDX-License-Identifier: MIT
// collide: point and capsule distances against analytic values for every shape, brute-force
// minima along the axis, signed distance grids of a sphere mesh against the sphere, mesh checks,
// the narrow phase between plant primitives, the broad phase against all pairs, neighbour
// exclusion, collider contact lists, determinism and out-of-memory behaviour.
#include <stdlib.h>

#include "test.h"
#include "verdant/collide.h"
#include "verdant/geom.h"
#include "verdant/plant.h"

static vd_pose pose_of(vd_vec3 pos, vd_vec3 axis, double angle) {
  vd_pose p;
  p.pos = pos;
  p.rot = vd_quat_axis_angle(vd_normalize(axis), angle);
  return p;
}

// distance from p to segment a-b
static double seg_dist(vd_vec3 p, vd_vec3 a, vd_vec3 b) {
  vd_vec3 d = vd_sub(b, a);
  double t = vd_dot(vd_sub(p, a), d) / vd_dot(d, d);
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  return vd_norm(vd_sub(p, vd_madd(a, d, t)));
}

// an independent box distance: outside by clamping, inside by the nearest face
static double box_dist(vd_pose pose, vd_vec3 h, vd_vec3 p) {
  vd_vec3 l = vd_quat_rotate(vd_quat_conj(pose.rot), vd_sub(p, pose.pos));
  double c[3] = {l.x, l.y, l.z}, hh[3] = {h.x, h.y, h.z}, q[3];
  int inside = 1;
  for (int a = 0; a < 3; a++) {
    q[a] = c[a] < -hh[a] ? -hh[a] : (c[a] > hh[a] ? hh[a] : c[a]);
    if (q[a] != c[a]) inside = 0;
  }
  if (!inside) return vd_norm(vd_sub(vd_v3(c[0], c[1], c[2]), vd_v3(q[0], q[1], q[2])));
  double m = HUGE_VAL;
  for (int a = 0; a < 3; a++)
    m = fmin(m, hh[a] - fabs(c[a]));
  return -m;
}

static vd_vec3 rand_point(vd_rng* r, double s) {
  return vd_v3(vd_rng_uniform(r, -s, s), vd_rng_uniform(r, -s, s), vd_rng_uniform(r, -s, s));
}

TEST(collide, point_distances) {
  vd_vec3 o = vd_v3(0.1, -0.2, 0.3);
  vd_vec3 n = vd_normalize(vd_v3(1, 1, 1));
  vd_collider plane = vd_collider_plane(o, n);
  vd_collider sph = vd_collider_sphere(o, 0.05);
  vd_vec3 ca = vd_v3(0, 0, 0), cb = vd_v3(0.2, 0.1, -0.05);
  vd_collider cap = vd_collider_capsule(ca, cb, 0.02);
  vd_pose bp = pose_of(vd_v3(0.05, 0.02, -0.01), vd_v3(1, 2, 3), 0.7);
  vd_vec3 bh = vd_v3(0.04, 0.06, 0.02);
  vd_collider box = vd_collider_box(bp, bh);
  vd_rng r;
  vd_rng_seed(&r, 5);
  for (int k = 0; k < 2000; k++) {
    vd_vec3 p = rand_point(&r, 0.3);
    // distances
    vd_collide_hit h = vd_collide_point(&plane, p);
    CHECK_NEAR(h.dist, vd_dot(vd_sub(p, o), n), 1e-14);
    CHECK_NEAR(vd_dot(h.normal, n), 1, 1e-14);
    h = vd_collide_point(&sph, p);
    CHECK_NEAR(h.dist, vd_norm(vd_sub(p, o)) - 0.05, 1e-14);
    h = vd_collide_point(&cap, p);
    CHECK_NEAR(h.dist, seg_dist(p, ca, cb) - 0.02, 1e-14);
    h = vd_collide_point(&box, p);
    CHECK_NEAR(h.dist, box_dist(bp, bh, p), 1e-14);
    // every shape: unit normal, closest point on the surface, normal = gradient of the distance
    const vd_collider* all[4] = {&plane, &sph, &cap, &box};
    for (int s = 0; s < 4; s++) {
      vd_collide_hit g = vd_collide_point(all[s], p);
      CHECK_NEAR(vd_norm(g.normal), 1, 1e-12);
      CHECK_NEAR(vd_collide_point(all[s], g.point).dist, 0, 1e-12);
      vd_vec3 q = vd_madd(p, g.normal, 1e-7);
      CHECK_NEAR(vd_collide_point(all[s], q).dist - g.dist, 1e-7, 1e-11);
    }
  }
  // exact values at chosen points: box face, edge, corner, inside
  vd_collider ab = vd_collider_box(vd_pose_identity(), vd_v3(1, 2, 3));
  CHECK_NEAR(vd_collide_point(&ab, vd_v3(1.5, 0, 0)).dist, 0.5, 1e-15);
  CHECK_NEAR(vd_collide_point(&ab, vd_v3(4, 6, 0)).dist, 5, 1e-15);
  CHECK_NEAR(vd_collide_point(&ab, vd_v3(2, 3, 4)).dist, sqrt(3), 1e-15);
  vd_collide_hit in = vd_collide_point(&ab, vd_v3(0.5, 0.1, -2.9));
  CHECK_NEAR(in.dist, -0.1, 1e-15);
  CHECK(in.normal.z == -1);
  // sphere helper: reduced by the radius; the centre of a sphere collider has a defined normal
  CHECK_NEAR(vd_collide_sphere(&sph, vd_add(o, vd_v3(0, 0.2, 0)), 0.03).dist, 0.12, 1e-15);
  CHECK_NEAR(vd_norm(vd_collide_point(&sph, o).normal), 1, 1e-15);
  CHECK_NEAR(vd_collide_point(&cap, ca).dist, -0.02, 1e-15);
}

// brute force: the minimum over n+1 axis samples of distance minus radius (above the true one by
// at most the slope bound |b - a| + |rb - ra| times the half spacing)
static double brute_capsule(const vd_collider* c, vd_vec3 a, vd_vec3 b, double ra, double rb,
                            int n) {
  double best = HUGE_VAL;
  for (int i = 0; i <= n; i++) {
    double t = (double)i / n;
    double f = vd_collide_point(c, vd_madd(a, vd_sub(b, a), t)).dist - (ra + t * (rb - ra));
    best = fmin(best, f);
  }
  return best;
}

TEST(collide, capsule_distances) {
  // analytic cases
  vd_collider ground = vd_collider_plane(vd_v3(0, 0, 0), vd_v3(0, 0, 1));
  vd_collide_hit h = vd_collide_capsule(&ground, vd_v3(0, 0, 0.1), vd_v3(1, 0, 0.1), 0.02, 0.02);
  CHECK_NEAR(h.dist, 0.08, 1e-15);
  CHECK_NEAR(h.t, 0.5, 1e-12); // flat: the middle
  h = vd_collide_capsule(&ground, vd_v3(0, 0, 0.1), vd_v3(1, 0, 0.3), 0.02, 0.01);
  CHECK_NEAR(h.dist, 0.08, 1e-15);
  CHECK(h.t == 0);
  h = vd_collide_capsule(&ground, vd_v3(0, 0, 0.1), vd_v3(0, 1, -0.05), 0.01, 0.01);
  CHECK_NEAR(h.dist, -0.06, 1e-15);
  CHECK(h.t == 1);
  CHECK_NEAR(h.point.z, 0, 1e-15);
  // a segment passing at distance 0.3 from a sphere's centre
  vd_collider s = vd_collider_sphere(vd_v3(1, 2, 3), 0.1);
  h = vd_collide_capsule(&s, vd_v3(0, 2.3, 3), vd_v3(3, 2.3, 3), 0.05, 0.05);
  CHECK_NEAR(h.dist, 0.15, 1e-12);
  CHECK_NEAR(h.t, 1.0 / 3, 1e-9);
  CHECK_NEAR(h.normal.y, 1, 1e-12);
  // perpendicular skew capsules 0.5 apart
  vd_collider c = vd_collider_capsule(vd_v3(-1, 0, 0), vd_v3(1, 0, 0), 0.1);
  h = vd_collide_capsule(&c, vd_v3(0.3, -1, 0.5), vd_v3(0.3, 1, 0.5), 0.05, 0.05);
  CHECK_NEAR(h.dist, 0.35, 1e-12);
  CHECK_NEAR(h.t, 0.5, 1e-9);
  CHECK_NEAR(h.point.x, 0.3, 1e-9);
  CHECK_NEAR(h.point.z, 0.1, 1e-9);
  // a capsule lying 0.2 above a box's top face, overlapping it over x in [0.5, 1]
  vd_collider box = vd_collider_box(vd_pose_identity(), vd_v3(1, 1, 1));
  h = vd_collide_capsule(&box, vd_v3(0.5, 0, 1.2), vd_v3(2.5, 0, 1.2), 0.05, 0.05);
  CHECK_NEAR(h.dist, 0.15, 1e-12);
  CHECK_NEAR(h.t, 0.125, 1e-9); // middle of the flat part x in [0.5, 1]
  // a capsule through a box: the deepest point is the box centre region
  h = vd_collide_capsule(&box, vd_v3(-3, 0.2, 0), vd_v3(3, 0.2, 0), 0.05, 0.05);
  CHECK_NEAR(h.dist, -0.85, 1e-12);

  // random tapered capsules against every convex shape, posed: equal to the brute-force minimum
  vd_rng r;
  vd_rng_seed(&r, 11);
  vd_collider shapes[4];
  shapes[0] = vd_collider_plane(vd_v3(0.01, 0.02, -0.03), vd_v3(0.2, -0.3, 1));
  shapes[1] = vd_collider_sphere(vd_v3(0.02, -0.01, 0.0), 0.06);
  shapes[2] = vd_collider_capsule(vd_v3(-0.05, 0, 0), vd_v3(0.08, 0.04, 0.02), 0.03);
  shapes[3] =
      vd_collider_box(pose_of(vd_v3(0, 0.01, 0.02), vd_v3(3, -1, 2), 0.9), vd_v3(0.05, 0.03, 0.07));
  for (int k = 0; k < 200; k++) {
    vd_vec3 a = rand_point(&r, 0.15), b = rand_point(&r, 0.15);
    double ra = vd_rng_uniform(&r, 0.001, 0.02), rb = vd_rng_uniform(&r, 0.001, 0.02);
    for (int q = 0; q < 4; q++) {
      double ref = brute_capsule(&shapes[q], a, b, ra, rb, 10000);
      h = vd_collide_capsule(&shapes[q], a, b, ra, rb);
      // the minimum is never above the brute-force one, and not below it by more than sampling
      CHECK(h.dist <= ref + 1e-12);
      CHECK(h.dist >= ref - (vd_norm(vd_sub(b, a)) + fabs(rb - ra)) / 10000);
      // the hit's own numbers agree with a point query at its axis point
      vd_vec3 x = vd_madd(a, vd_sub(b, a), h.t);
      CHECK_NEAR(vd_collide_point(&shapes[q], x).dist - (ra + h.t * (rb - ra)), h.dist, 1e-12);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// an icosphere: closed, counter-clockwise seen from outside

typedef struct icos {
  int nv, nt;
  double v[3 * 2562];
  int t[3 * 5120];
} icos;

static int midpoint(icos* s, int a, int b, int* cache_a, int* cache_b, int* cache_m, int* nc) {
  for (int k = 0; k < *nc; k++)
    if ((cache_a[k] == a && cache_b[k] == b) || (cache_a[k] == b && cache_b[k] == a))
      return cache_m[k];
  vd_vec3 p = vd_normalize(vd_v3(s->v[3 * a] + s->v[3 * b], s->v[3 * a + 1] + s->v[3 * b + 1],
                                 s->v[3 * a + 2] + s->v[3 * b + 2]));
  s->v[3 * s->nv] = p.x, s->v[3 * s->nv + 1] = p.y, s->v[3 * s->nv + 2] = p.z;
  cache_a[*nc] = a, cache_b[*nc] = b, cache_m[*nc] = s->nv;
  (*nc)++;
  return s->nv++;
}

// unit icosphere subdivided `level` times (level <= 4), then scaled by radius
static void make_icosphere(icos* s, int level, double radius) {
  double p = (1 + sqrt(5)) / 2;
  double v0[12][3] = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                      {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  int t0[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  s->nv = 12, s->nt = 20;
  for (int i = 0; i < 12; i++) {
    vd_vec3 q = vd_normalize(vd_v3(v0[i][0], v0[i][1], v0[i][2]));
    s->v[3 * i] = q.x, s->v[3 * i + 1] = q.y, s->v[3 * i + 2] = q.z;
  }
  memcpy(s->t, t0, sizeof t0);
  static int ca[8000], cb[8000], cm[8000];
  static int nt2[3 * 5120];
  for (int l = 0; l < level; l++) {
    int nc = 0, n2 = 0;
    for (int t = 0; t < s->nt; t++) {
      int a = s->t[3 * t], b = s->t[3 * t + 1], c = s->t[3 * t + 2];
      int ab = midpoint(s, a, b, ca, cb, cm, &nc), bc = midpoint(s, b, c, ca, cb, cm, &nc);
      int ac = midpoint(s, a, c, ca, cb, cm, &nc);
      int q[4][3] = {{a, ab, ac}, {b, bc, ab}, {c, ac, bc}, {ab, bc, ac}};
      memcpy(nt2 + 3 * n2, q, sizeof q);
      n2 += 4;
    }
    memcpy(s->t, nt2, (size_t)n2 * 3 * sizeof(int));
    s->nt = n2;
  }
  for (int i = 0; i < 3 * s->nv; i++)
    s->v[i] *= radius;
}

// exact distance from p to the polyhedron by brute force over its triangles (unsigned)
static double brute_mesh_dist(const icos* s, vd_vec3 p) {
  double best = HUGE_VAL;
  for (int t = 0; t < s->nt; t++) {
    vd_vec3 a = vd_v3(s->v[3 * s->t[3 * t]], s->v[3 * s->t[3 * t] + 1], s->v[3 * s->t[3 * t] + 2]);
    vd_vec3 b = vd_v3(s->v[3 * s->t[3 * t + 1]], s->v[3 * s->t[3 * t + 1] + 1],
                      s->v[3 * s->t[3 * t + 1] + 2]);
    vd_vec3 c = vd_v3(s->v[3 * s->t[3 * t + 2]], s->v[3 * s->t[3 * t + 2] + 1],
                      s->v[3 * s->t[3 * t + 2] + 2]);
    // sample-free exact: minimise over the triangle by projecting and clamping to edges
    vd_vec3 n = vd_normalize(vd_cross(vd_sub(b, a), vd_sub(c, a)));
    vd_vec3 q = vd_madd(p, n, -vd_dot(vd_sub(p, a), n));
    int inside = vd_dot(vd_cross(vd_sub(b, a), vd_sub(q, a)), n) >= 0 &&
                 vd_dot(vd_cross(vd_sub(c, b), vd_sub(q, b)), n) >= 0 &&
                 vd_dot(vd_cross(vd_sub(a, c), vd_sub(q, c)), n) >= 0;
    double d = inside ? fabs(vd_dot(vd_sub(p, a), n))
                      : fmin(seg_dist(p, a, b), fmin(seg_dist(p, b, c), seg_dist(p, c, a)));
    best = fmin(best, d);
  }
  return best;
}

static icos ico; // big: static storage

TEST(collide, sdf_sphere) {
  double R = 0.05;
  make_icosphere(&ico, 3, R);
  CHECK_INT(ico.nv, 642);
  CHECK_INT(ico.nt, 1280);
  vd_sdf_def def = vd_sdf_def_default(); // 2 mm cells, 6 mm band, full grid
  vd_sdf* g = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &def, &g, &err), VD_OK, err);
  REQUIRE(g);
  CHECK_INT(g->ntri, 1280);
  CHECK(g->nx == 61 && g->ny == 61 && g->nz == 61);
  // nodes: exact polyhedron distance in the band, close to it beyond (sweeps), sign right
  double worst_band = 0, worst_far = 0;
  int nn = g->nx * g->ny * g->nz, wrong_sign = 0;
  for (int id = 0; id < nn; id += 31) {
    int i = id % g->nx, j = (id / g->nx) % g->ny, k = id / (g->nx * g->ny);
    vd_vec3 p = vd_add(g->origin, vd_scale(vd_v3(i, j, k), g->cell));
    double ref = brute_mesh_dist(&ico, p);
    double v = g->value[id];
    // the polyhedron's inside: closer to the centre than the inscribed-sphere radius is certain
    if ((vd_norm(p) < 0.99 * R && v >= 0) || (vd_norm(p) > R && v <= 0)) wrong_sign++;
    double e = fabs(fabs(v) - ref);
    if (ref <= def.band)
      worst_band = fmax(worst_band, e);
    else
      worst_far = fmax(worst_far, e);
  }
  CHECK_INT(wrong_sign, 0);
  CHECK(worst_band < 1e-12);

  CHECK(worst_far < 0.1 * def.cell); // 0.055 cells at worst over all nodes
  // interpolated distances against the analytic sphere: within the polyhedron's sag plus the
  // trilinear error (cell^2 / R) away from the centre
  // the polyhedron's largest gap to the sphere: R less the nearest face plane's distance
  double sag = 0;
  for (int t = 0; t < ico.nt; t++) {
    vd_vec3 v[3];
    for (int k = 0; k < 3; k++)
      v[k] = vd_v3(ico.v[3 * ico.t[3 * t + k]], ico.v[3 * ico.t[3 * t + k] + 1],
                   ico.v[3 * ico.t[3 * t + k] + 2]);
    vd_vec3 n = vd_normalize(vd_cross(vd_sub(v[1], v[0]), vd_sub(v[2], v[0])));
    sag = fmax(sag, R - vd_dot(v[0], n));
  }
  vd_rng r;
  vd_rng_seed(&r, 3);
  double worst = 0, worst_angle = 0;
  for (int k = 0; k < 5000; k++) {
    vd_vec3 p = rand_point(&r, 0.055);
    vd_vec3 gr;
    double d = vd_sdf_eval(g, p, &gr);
    double ref = vd_norm(p) - R;
    // away from the medial axis (the centre), where the distance has a kink the grid rounds off
    if (vd_norm(p) > 0.3 * R) worst = fmax(worst, fabs(d - ref));
    if (vd_norm(p) > 0.3 * R && fabs(ref) < def.band) {
      double c = vd_dot(vd_normalize(gr), vd_normalize(p));
      worst_angle = fmax(worst_angle, acos(c > 1 ? 1 : c));
    }
  }
  CHECK(worst < sag + def.cell * def.cell / R);
  CHECK(worst_angle < 0.1);
  // outside the grid: the value at the box plus the distance to it
  vd_vec3 gr;
  double far = vd_sdf_eval(g, vd_v3(0.5, 0, 0), &gr);
  CHECK_NEAR(far, 0.5 - R, 1e-3);
  CHECK_NEAR(gr.x, 1, 1e-9);

  // narrow band: the same values in the band, clamped beyond
  vd_sdf* nb = NULL;
  def.full = 0;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &def, &nb, &err), VD_OK, err);
  REQUIRE(nb);
  int same = 1;
  for (int id = 0; id < nn; id++)
    if (fabs(g->value[id]) <= def.band && g->value[id] != nb->value[id]) same = 0;
  CHECK(same);
  CHECK_NEAR(vd_sdf_eval(nb, vd_v3(0, 0, 0), NULL), -def.band, 1e-15);
  CHECK_NEAR(vd_sdf_eval(nb, vd_v3(0.059, 0.059, 0.059), NULL), def.band, 1e-15);

  // a mesh collider posed in the world against the analytic sphere collider at the same place
  vd_pose pose = pose_of(vd_v3(0.3, -0.1, 0.2), vd_v3(1, -2, 0.5), 1.1);
  vd_collider cm = vd_collider_sdf(pose, g), cs = vd_collider_sphere(pose.pos, R);
  for (int k = 0; k < 300; k++) {
    vd_vec3 a = vd_add(pose.pos, rand_point(&r, 0.07)), b = vd_add(pose.pos, rand_point(&r, 0.07));
    vd_collide_hit hm = vd_collide_capsule(&cm, a, b, 0.004, 0.003);
    vd_collide_hit hs = vd_collide_capsule(&cs, a, b, 0.004, 0.003);
    // near the surface (where contacts are) the two agree; farther out, beyond the grid, the
    // grid's distance is an upper bound
    if (hs.dist < def.band)
      CHECK_NEAR(hm.dist, hs.dist, sag + 2 * def.cell * def.cell / R);
    else
      CHECK(hm.dist > hs.dist - sag - 2 * def.cell * def.cell / R);
    if (hs.dist < 0.01 && vd_norm(vd_sub(vd_madd(a, vd_sub(b, a), hs.t), pose.pos)) > 0.3 * R)
      CHECK(vd_dot(hm.normal, hs.normal) > 0.98);
  }
  vd_vec3 lo, hi;
  vd_collider_bounds(&cm, &lo, &hi);
  CHECK(lo.x < pose.pos.x - R && hi.x > pose.pos.x + R);
  vd_sdf_destroy(nb);
  vd_sdf_destroy(g);
  vd_sdf_destroy(NULL);
}

TEST(collide, sdf_errors) {
  make_icosphere(&ico, 1, 0.05);
  vd_error err = {0};
  vd_sdf* g = NULL;
  // an open mesh, a flipped triangle, an index out of range, no triangles
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt - 1, NULL, &g, &err), VD_ERR_VALUE, err);
  CHECK(strstr(err.msg, "not closed") != NULL);
  int save = ico.t[0];
  ico.t[0] = ico.t[1], ico.t[1] = save;
  err = (vd_error){0}; // an error record keeps its first error
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, NULL, &g, &err), VD_ERR_VALUE, err);
  CHECK(strstr(err.msg, "oriented") != NULL);
  ico.t[1] = ico.t[0], ico.t[0] = save;
  ico.t[5] = 9999;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, NULL, &g, &err), VD_ERR_VALUE, err);
  make_icosphere(&ico, 1, 0.05);
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, 0, NULL, &g, &err), VD_ERR_VALUE, err);
  // bad settings, a grid above the limit
  vd_sdf_def def = vd_sdf_def_default();
  def.band = def.cell;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &def, &g, &err), VD_ERR_ARG, err);
  def = vd_sdf_def_default();
  def.cell = 0;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &def, &g, &err), VD_ERR_ARG, err);
  def = vd_sdf_def_default();
  def.max_nodes = 1000;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &def, &g, &err), VD_ERR_LIMIT, err);
  ico.v[4] = NAN;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, NULL, &g, &err), VD_ERR_VALUE, err);
  CHECK(g == NULL);
  make_icosphere(&ico, 1, 0.05);
  // out of memory at every allocation: a status, nothing leaked
  def = vd_sdf_def_default();
  def.cell = 0.005, def.band = 0.01;
  for (int budget = 0; budget < 12; budget++) {
    int64_t before = vd_alloc_bytes();
    vdt_oom_begin(budget);
    vd_status st = vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &def, &g, &err);
    vdt_oom_end();
    if (st == VD_OK) {
      vd_sdf_destroy(g);
      g = NULL;
    } else {
      CHECK_INT(st, VD_ERR_NOMEM);
    }
    CHECK_INT(vd_alloc_bytes(), before);
  }
}

// a tessellated plant (frustum with caps, sphere): side and cap vertices are separate copies,
// welding makes the surfaces closed
TEST(collide, sdf_welded_mesh) {
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0.1));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.02, g.slices = 16;
  vd_plant_add_segment(s, &g);
  vd_model* m = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_plant_compile(s, &m, &err), VD_OK, err);
  vd_mesh mesh;
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  vd_sdf_def def = vd_sdf_def_default();
  vd_sdf* sdf = NULL;
  CHECK_STATUS(vd_sdf_build(mesh.pos, mesh.nvert, mesh.tri, mesh.ntri, &def, &sdf, &err), VD_OK,
               err);
  if (sdf) {
    CHECK(sdf->nvert < mesh.nvert); // welded
    // inside: distance to the nearest of side (polygon apothem) and caps; outside above the cap
    double apothem = 0.02 * cos(VD_PI / 16);
    CHECK_NEAR(vd_sdf_eval(sdf, vd_v3(0, 0, 0.05), NULL), -apothem, 1e-12);
    CHECK_NEAR(vd_sdf_eval(sdf, vd_v3(0, 0, 0.104), NULL), 0.004, 1e-12);
    CHECK_NEAR(vd_sdf_eval(sdf, vd_v3(0, 0, 0.006), NULL), -0.006, 1e-12);
  }
  vd_sdf_destroy(sdf);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

// ---------------------------------------------------------------------------------------------
// plant primitives

typedef struct soup {
  int nnode, ncap, nsph;
  double node[3 * 1200];
  int cap_node[2 * 600];
  double cap_r[2 * 600];
  double sph[3 * 100];
  double sph_r[100];
} soup;

static vd_collide_prims prims_of(const soup* s) {
  vd_collide_prims p;
  memset(&p, 0, sizeof p);
  p.nnode = s->nnode, p.ncapsule = s->ncap, p.nsphere = s->nsph;
  p.node_pos = s->node, p.capsule_node = s->cap_node, p.capsule_radius = s->cap_r;
  p.sphere_pos = s->sph, p.sphere_radius = s->sph_r;
  return p;
}

TEST(collide, pairs) {
  soup s;
  memset(&s, 0, sizeof s);
  // capsule 0 along x, capsule 1 along y 0.5 above, capsule 2 parallel to 0 and 0.1 beside it
  double nodes[] = {-1, 0, 0, 1, 0, 0, 0.3, -1, 0.5, 0.3, 1, 0.5, 0.5, 0.1, 0, 3, 0.1, 0};
  memcpy(s.node, nodes, sizeof nodes);
  s.nnode = 6, s.ncap = 3, s.nsph = 2;
  int cn[] = {0, 1, 2, 3, 4, 5};
  memcpy(s.cap_node, cn, sizeof cn);
  for (int i = 0; i < 6; i++)
    s.cap_r[i] = 0.03;
  double sp[] = {0, 0, -0.2, 0.1, 0, -0.35};
  memcpy(s.sph, sp, sizeof sp);
  s.sph_r[0] = 0.1, s.sph_r[1] = 0.06;
  vd_collide_prims p = prims_of(&s);
  vd_contact c;
  // skew capsules: closest axis points (0.3, 0, 0) and (0.3, 0, 0.5)
  CHECK_INT(vd_collide_pair(&p, 1, 0, 1.0, &c), 1);
  CHECK(c.a == 0 && c.b == 1 && c.collider == 0);
  CHECK_NEAR(c.dist, 0.44, 1e-14);
  CHECK_NEAR(c.ta, 0.65, 1e-14);
  CHECK_NEAR(c.tb, 0.5, 1e-14);
  CHECK_NEAR(c.normal.z, -1, 1e-14); // from b (above) toward a
  CHECK_NEAR(c.pa.z, 0.03, 1e-14);
  CHECK_NEAR(c.pb.z, 0.47, 1e-14);
  CHECK_INT(vd_collide_pair(&p, 0, 1, 0.4, &c), 0); // beyond the margin
  // parallel overlapping capsules: the middle of the overlap x in [0.5, 1]
  CHECK_INT(vd_collide_pair(&p, 0, 2, 0.1, &c), 1);
  CHECK_NEAR(c.dist, 0.04, 1e-14);
  CHECK_NEAR(c.ta, 0.875, 1e-12);
  CHECK_NEAR(c.tb, 0.1, 1e-12);
  CHECK_NEAR(c.normal.y, -1, 1e-14);
  // capsule-sphere: the sphere 0.2 below capsule 0's middle
  CHECK_INT(vd_collide_pair(&p, 0, 3, 0.1, &c), 1);
  CHECK(c.a == 0 && c.b == 3);
  CHECK_NEAR(c.dist, 0.07, 1e-12);
  CHECK_NEAR(c.ta, 0.5, 1e-9);
  CHECK_NEAR(c.normal.z, 1, 1e-12);
  CHECK_NEAR(c.pb.z, -0.1, 1e-12);
  CHECK_NEAR(c.pa.z, -0.03, 1e-12);
  // sphere-sphere within the margin
  CHECK_INT(vd_collide_pair(&p, 4, 3, 0.05, &c), 1);
  CHECK(c.a == 3 && c.b == 4);
  double d = vd_norm(vd_v3(0.1, 0, -0.15));
  CHECK_NEAR(c.dist, d - 0.16, 1e-14);
  CHECK_NEAR(vd_dot(c.normal, vd_normalize(vd_v3(-0.1, 0, 0.15))), 1, 1e-14);
  // crossing axes: the common perpendicular as normal, overlap of both radii
  s.node[3 * 2 + 2] = 0, s.node[3 * 3 + 2] = 0;
  CHECK_INT(vd_collide_pair(&p, 0, 1, 0, &c), 1);
  CHECK_NEAR(c.dist, -0.06, 1e-14);
  CHECK_NEAR(fabs(c.normal.z), 1, 1e-14);
}

// a random soup of capsules and spheres
static void make_soup(soup* s, vd_rng* r, int ncap, int nsph) {
  memset(s, 0, sizeof *s);
  s->ncap = ncap, s->nsph = nsph, s->nnode = 2 * ncap;
  for (int i = 0; i < ncap; i++) {
    vd_vec3 a = rand_point(r, 0.3);
    vd_vec3 b = vd_add(a, rand_point(r, 0.04));
    memcpy(s->node + 6 * i, &a, sizeof a);
    memcpy(s->node + 6 * i + 3, &b, sizeof b);
    s->cap_node[2 * i] = 2 * i, s->cap_node[2 * i + 1] = 2 * i + 1;
    s->cap_r[2 * i] = vd_rng_uniform(r, 0.002, 0.01);
    s->cap_r[2 * i + 1] = vd_rng_uniform(r, 0.002, 0.01);
  }
  for (int i = 0; i < nsph; i++) {
    vd_vec3 c = rand_point(r, 0.3);
    memcpy(s->sph + 3 * i, &c, sizeof c);
    s->sph_r[i] = vd_rng_uniform(r, 0.005, 0.02);
  }
}

static soup sp; // big: static storage

// is j in i's excluded row?
static int pair_excluded(const vd_collide_exclusion* ex, int i, int j) {
  for (int e = ex->start[i]; e < ex->start[i + 1]; e++)
    if (ex->exclude[e] == j) return 1;
  return 0;
}

TEST(collide, broad_phase_equals_brute_force) {
  vd_rng r;
  vd_rng_seed(&r, 21);
  make_soup(&sp, &r, 500, 80);
  // shared nodes: capsule 2k+1 starts where capsule 2k ends (a chain of pairs)
  for (int i = 0; i + 1 < sp.ncap; i += 2)
    sp.cap_node[2 * (i + 1)] = sp.cap_node[2 * i + 1];
  vd_collide_prims p = prims_of(&sp);
  int skip[580] = {0};
  skip[7] = skip[520] = 1;
  p.skip = skip;
  vd_collide_exclusion ex;
  vd_error err = {0};
  // an exclusion for the capsules alone does not fit the primitives
  CHECK_STATUS(vd_collide_exclusion_build(sp.nnode, sp.ncap, sp.cap_node, 0, NULL, 0, &ex, &err),
               VD_OK, err);
  vd_collide_prims_set_exclusion(&p, &ex);
  vd_arena scratch;
  vd_arena_init(&scratch, 0);
  vd_contact_list wrong;
  err = (vd_error){0};
  CHECK_STATUS(vd_collide_self(&p, NULL, &scratch, &wrong, &err), VD_ERR_ARG, err);
  vd_arena_free(&scratch);
  vd_collide_exclusion_free(&ex);
  CHECK_STATUS(
      vd_collide_exclusion_build(sp.nnode, sp.ncap, sp.cap_node, sp.nsph, NULL, 0, &ex, &err),
      VD_OK, err);
  vd_collide_prims_set_exclusion(&p, &ex);
  vd_collide_def def = vd_collide_def_default();
  def.margin = 0.005;
  vd_arena arena;
  vd_arena_init(&arena, 0);
  vd_contact_list L;
  CHECK_STATUS(vd_collide_self(&p, &def, &arena, &L, &err), VD_OK, err);
  // brute force over every pair
  int n = sp.ncap + sp.nsph, nb = 0, match = 1, excluded_pairs = 0;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) {
      if (skip[i] || skip[j]) continue;
      int is_ex = 0;
      for (int e = ex.start[i]; e < ex.start[i + 1]; e++)
        is_ex |= ex.exclude[e] == j;
      vd_contact c;
      if (!vd_collide_pair(&p, i, j, def.margin, &c)) continue;
      if (is_ex) {
        excluded_pairs++;
        continue;
      }
      if (nb >= L.n || L.c[nb].a != i || L.c[nb].b != j || memcmp(&L.c[nb], &c, sizeof c) != 0)
        match = 0;
      nb++;
    }
  CHECK_INT(L.n, nb);
  CHECK(match);
  CHECK(nb > 20);                                  // the soup is dense enough to test something
  CHECK(excluded_pairs > 100);                     // chained capsules touch and are left out
  CHECK(L.ntested < (int64_t)n * (n - 1) / 2 / 5); // the broad phase prunes
  CHECK_INT(L.ndropped, 0);
  // a contact cap keeps the first ones in sweep order and counts the rest
  def.max_contacts = 5;
  vd_contact_list L2;
  CHECK_STATUS(vd_collide_self(&p, &def, &arena, &L2, &err), VD_OK, err);
  CHECK_INT(L2.n, 5);
  CHECK_INT(L2.ndropped, nb - 5);
  // the broad phase alone with a larger growth, reused after small moves: the same contacts as
  // a full query on the moved plant
  def.max_contacts = 1000000;
  vd_arena keep;
  vd_arena_init(&keep, 0);
  vd_pair_list pairs;
  CHECK_STATUS(vd_collide_self_pairs(&p, 0.015, &keep, &pairs, &err), VD_OK, err);
  CHECK(pairs.n > nb);
  int sorted = 1;
  for (int k = 1; k < pairs.n; k++)
    sorted &= pairs.pair[2 * k - 2] < pairs.pair[2 * k] ||
              (pairs.pair[2 * k - 2] == pairs.pair[2 * k] &&
               pairs.pair[2 * k - 1] < pairs.pair[2 * k + 1]);
  CHECK(sorted);
  for (int i = 0; i < 3 * sp.nnode; i++)
    sp.node[i] += vd_rng_uniform(&r, -0.0028, 0.0028) / sqrt(3);
  for (int i = 0; i < 3 * sp.nsph; i++)
    sp.sph[i] += vd_rng_uniform(&r, -0.0028, 0.0028) / sqrt(3);
  vd_contact_list full, reused;
  vd_arena_reset(&arena);
  CHECK_STATUS(vd_collide_self(&p, &def, &arena, &full, &err), VD_OK, err);
  CHECK_STATUS(vd_collide_pairs(&p, &pairs, &def, &arena, &reused, &err), VD_OK, err);
  CHECK(full.n > 20 && full.n == reused.n &&
        memcmp(full.c, reused.c, (size_t)full.n * sizeof *full.c) == 0);
  CHECK(reused.ntested < pairs.n); // the current boxes cull most candidates first
  // primitives' own margins: pair i, j within def.margin + margin[i] + margin[j], as brute force
  static double own[580];
  for (int i = 0; i < n; i++)
    own[i] = i % 50 == 0 ? 0.05 : vd_rng_uniform(&r, 0, 0.001);
  p.margin = own;
  vd_contact_list wide;
  CHECK_STATUS(vd_collide_self(&p, &def, &arena, &wide, &err), VD_OK, err);
  int nw = 0, wmatch = 1;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) {
      vd_contact c;
      if (skip[i] || skip[j] || pair_excluded(&ex, i, j) ||
          !vd_collide_pair(&p, i, j, def.margin + own[i] + own[j], &c))
        continue;
      wmatch &= nw < wide.n && wide.c[nw].a == i && wide.c[nw].b == j;
      nw++;
    }
  CHECK_INT(wide.n, nw);
  CHECK(wmatch && nw > full.n);
  own[3] = -1;
  CHECK_STATUS(vd_collide_self(&p, &def, &arena, &wide, &err), VD_ERR_ARG, err);
  p.margin = NULL;
  // a bad pair list is refused
  int bad[2] = {3, 3};
  vd_pair_list bl = {1, bad};
  CHECK_STATUS(vd_collide_pairs(&p, &bl, &def, &arena, &reused, &err), VD_ERR_ARG, err);
  vd_arena_free(&keep);
  vd_arena_free(&arena);
  vd_collide_exclusion_free(&ex);
}

TEST(collide, exclusion_topology) {
  // a chain of 4 capsules over nodes 0-1-2-3-4, a branch 2-5, a fruit sphere at node 4
  int cap_node[] = {0, 1, 1, 2, 2, 3, 3, 4, 2, 5};
  int sph_node[] = {4, -1};
  vd_collide_exclusion ex;
  vd_error err = {0};
  CHECK_STATUS(vd_collide_exclusion_build(6, 5, cap_node, 2, sph_node, 0, &ex, &err), VD_OK, err);
  CHECK_INT(ex.nprim, 7);
  // hops 0: sharing a node
  int row1[] = {0, 2, 4}; // capsule 1 (1-2) meets 0 at node 1, 2 and 4 at node 2
  CHECK_INT(ex.start[2] - ex.start[1], 3);
  for (int k = 0; k < 3; k++)
    CHECK_INT(ex.exclude[ex.start[1] + k], row1[k]);
  CHECK_INT(ex.start[6] - ex.start[5], 1); // the fruit meets capsule 3 only
  CHECK_INT(ex.exclude[ex.start[5]], 3);
  CHECK_INT(ex.start[7] - ex.start[6], 0); // a free sphere meets nothing
  vd_collide_exclusion_free(&ex);
  // hops 1: capsule 0 also meets the capsules one node further (2, 4)
  CHECK_STATUS(vd_collide_exclusion_build(6, 5, cap_node, 2, sph_node, 1, &ex, &err), VD_OK, err);
  int row0[] = {1, 2, 4};
  CHECK_INT(ex.start[1] - ex.start[0], 3);
  for (int k = 0; k < 3; k++)
    CHECK_INT(ex.exclude[ex.start[0] + k], row0[k]);
  // symmetric
  int sym = 1;
  for (int i = 0; i < ex.nprim; i++)
    for (int e = ex.start[i]; e < ex.start[i + 1]; e++) {
      int j = ex.exclude[e], found = 0;
      for (int f = ex.start[j]; f < ex.start[j + 1]; f++)
        found |= ex.exclude[f] == i;
      sym &= found;
    }
  CHECK(sym);
  vd_collide_exclusion_free(&ex);
  // a straight chain of touching capsules: every neighbour overlaps, none is reported when
  // excluded; without the exclusion each joint is a contact
  soup s;
  memset(&s, 0, sizeof s);
  s.nnode = 11, s.ncap = 10;
  for (int i = 0; i <= 10; i++)
    s.node[3 * i + 2] = 0.01 * i;
  for (int i = 0; i < 10; i++)
    s.cap_node[2 * i] = i, s.cap_node[2 * i + 1] = i + 1,
                   s.cap_r[2 * i] = s.cap_r[2 * i + 1] = 0.004;
  vd_collide_prims p = prims_of(&s);
  vd_arena arena;
  vd_arena_init(&arena, 0);
  vd_contact_list L;
  CHECK_STATUS(vd_collide_self(&p, NULL, &arena, &L, &err), VD_OK, err);
  CHECK_INT(L.n, 9);
  CHECK_STATUS(vd_collide_exclusion_build(11, 10, s.cap_node, 0, NULL, 0, &ex, &err), VD_OK, err);
  vd_collide_prims_set_exclusion(&p, &ex);
  vd_arena_reset(&arena);
  CHECK_STATUS(vd_collide_self(&p, NULL, &arena, &L, &err), VD_OK, err);
  CHECK_INT(L.n, 0);
  vd_collide_exclusion_free(&ex);
  // a fruit on the chain's tip node overlaps the capsule before the last one too: excluded once
  // it is marked as touching in the modelled shape; contacts that come later are still found
  s.nsph = 1;
  s.sph[0] = 0.006, s.sph[1] = 0, s.sph[2] = 0.1, s.sph_r[0] = 0.015;
  int tip_node[1] = {10};
  p = prims_of(&s);
  CHECK_STATUS(vd_collide_exclusion_build(11, 10, s.cap_node, 1, tip_node, 0, &ex, &err), VD_OK,
               err);
  vd_collide_prims_set_exclusion(&p, &ex);
  vd_arena_reset(&arena);
  CHECK_STATUS(vd_collide_self(&p, NULL, &arena, &L, &err), VD_OK, err);
  CHECK_INT(L.n, 1); // the fruit against capsule 8 (nodes 8-9)
  CHECK_STATUS(vd_collide_exclusion_add_touching(&ex, &p, 0.001, &err), VD_OK, err);
  vd_collide_prims_set_exclusion(&p, &ex);
  vd_arena_reset(&arena);
  CHECK_STATUS(vd_collide_self(&p, NULL, &arena, &L, &err), VD_OK, err);
  CHECK_INT(L.n, 0);
  s.sph[2] = 0.05; // the fruit swings down onto capsule 4
  vd_arena_reset(&arena);
  CHECK_STATUS(vd_collide_self(&p, NULL, &arena, &L, &err), VD_OK, err);
  CHECK(L.n >= 1 && L.c[0].b == 10);
  vd_collide_exclusion_free(&ex);
  // bad input
  cap_node[3] = 9;
  CHECK_STATUS(vd_collide_exclusion_build(6, 5, cap_node, 0, NULL, 0, &ex, &err), VD_ERR_ARG, err);
  vd_arena_free(&arena);
}

TEST(collide, colliders_and_determinism) {
  vd_rng r;
  vd_rng_seed(&r, 8);
  make_soup(&sp, &r, 300, 40);
  vd_collide_prims p = prims_of(&sp);
  make_icosphere(&ico, 2, 0.08);
  vd_sdf* g = NULL;
  vd_error err = {0};
  vd_sdf_def sdef = vd_sdf_def_default();
  sdef.cell = 0.004, sdef.band = 0.008;
  CHECK_STATUS(vd_sdf_build(ico.v, ico.nv, ico.t, ico.nt, &sdef, &g, &err), VD_OK, err);
  REQUIRE(g);
  vd_collider col[5];
  col[0] = vd_collider_plane(vd_v3(0, 0, -0.2), vd_v3(0, 0, 1));
  col[1] = vd_collider_sphere(vd_v3(0.1, 0.1, 0), 0.1);
  col[2] = vd_collider_capsule(vd_v3(-0.2, 0, 0.1), vd_v3(0.2, 0.1, 0.1), 0.03);
  col[3] =
      vd_collider_box(pose_of(vd_v3(-0.1, -0.1, 0), vd_v3(0, 0, 1), 0.4), vd_v3(0.1, 0.05, 0.2));
  col[4] = vd_collider_sdf(pose_of(vd_v3(0.15, -0.15, 0.15), vd_v3(1, 0, 0), 0.3), g);
  vd_collide_def def = vd_collide_def_default();
  def.margin = 0.002;
  vd_arena arena;
  vd_arena_init(&arena, 1024); // small blocks: the list grows across blocks
  vd_contact_list L;
  CHECK_STATUS(vd_collide_colliders(&p, col, 5, &def, &arena, &L, &err), VD_OK, err);
  // brute force: every primitive against every collider
  int n = sp.ncap + sp.nsph, nb = 0, match = 1, per[5] = {0};
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 5; k++) {
      vd_collide_hit h;
      if (i < sp.ncap) {
        vd_vec3 a = vd_v3(sp.node[6 * i], sp.node[6 * i + 1], sp.node[6 * i + 2]);
        vd_vec3 b = vd_v3(sp.node[6 * i + 3], sp.node[6 * i + 4], sp.node[6 * i + 5]);
        h = vd_collide_capsule(&col[k], a, b, sp.cap_r[2 * i], sp.cap_r[2 * i + 1]);
      } else {
        int j = i - sp.ncap;
        h = vd_collide_sphere(&col[k], vd_v3(sp.sph[3 * j], sp.sph[3 * j + 1], sp.sph[3 * j + 2]),
                              sp.sph_r[j]);
      }
      if (!(h.dist < def.margin)) continue;
      if (nb >= L.n || L.c[nb].a != i || L.c[nb].b != k || !L.c[nb].collider ||
          L.c[nb].dist != h.dist)
        match = 0;
      per[k]++;
      nb++;
    }
  CHECK_INT(L.n, nb);
  CHECK(match);
  for (int k = 0; k < 5; k++)
    CHECK(per[k] > 0);
  // contacts push the primitive out along the normal
  for (int q = 0; q < L.n; q++) {
    const vd_contact* c = &L.c[q];
    CHECK_NEAR(vd_dot(vd_sub(c->pa, c->pb), c->normal), c->dist, 1e-9);
  }
  // the same query again, in a fresh arena with other block sizes: the same bytes
  vd_arena a2;
  vd_arena_init(&a2, 1 << 20);
  vd_contact_list L2;
  CHECK_STATUS(vd_collide_colliders(&p, col, 5, &def, &a2, &L2, &err), VD_OK, err);
  CHECK(L2.n == L.n && memcmp(L2.c, L.c, (size_t)L.n * sizeof *L.c) == 0);
  vd_contact_list S1, S2;
  CHECK_STATUS(vd_collide_self(&p, &def, &arena, &S1, &err), VD_OK, err);
  CHECK_STATUS(vd_collide_self(&p, &def, &a2, &S2, &err), VD_OK, err);
  CHECK(S1.n == S2.n && S1.n > 0 && memcmp(S1.c, S2.c, (size_t)S1.n * sizeof *S1.c) == 0);
  for (int q = 1; q < S1.n; q++)
    CHECK(S1.c[q - 1].a < S1.c[q].a || (S1.c[q - 1].a == S1.c[q].a && S1.c[q - 1].b < S1.c[q].b));
  // a moving pose: contacts follow the collider
  vd_pose moved = col[1].pose;
  moved.pos = vd_v3(5, 5, 5);
  vd_collider_set_pose(&col[1], moved);
  CHECK_STATUS(vd_collide_colliders(&p, col + 1, 1, &def, &a2, &L2, &err), VD_OK, err);
  CHECK_INT(L2.n, 0);
  // bad arguments
  CHECK_STATUS(vd_collide_colliders(&p, col, -1, &def, &a2, &L2, &err), VD_ERR_ARG, err);
  def.margin = -1;
  CHECK_STATUS(vd_collide_self(&p, &def, &a2, &L2, &err), VD_ERR_ARG, err);
  vd_arena_free(&arena);
  vd_arena_free(&a2);
  vd_sdf_destroy(g);
}

TEST(collide, out_of_memory) {
  vd_rng r;
  vd_rng_seed(&r, 4);
  make_soup(&sp, &r, 200, 20);
  vd_collide_prims p = prims_of(&sp);
  vd_error err = {0};
  for (int budget = 0; budget < 8; budget++) {
    int64_t before = vd_alloc_bytes();
    vd_arena arena;
    vd_arena_init(&arena, 4096);
    vd_contact_list L;
    vdt_oom_begin(budget);
    vd_status st = vd_collide_self(&p, NULL, &arena, &L, &err);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    vd_arena_free(&arena);
    CHECK_INT(vd_alloc_bytes(), before);
  }
  // extending an exclusion by the touching pairs
  for (int budget = 0; budget < 10; budget++) {
    int64_t before = vd_alloc_bytes();
    vd_collide_exclusion ex;
    CHECK_STATUS(
        vd_collide_exclusion_build(p.nnode, p.ncapsule, sp.cap_node, p.nsphere, NULL, 0, &ex, &err),
        VD_OK, err);
    vdt_oom_begin(budget);
    vd_status st = vd_collide_exclusion_add_touching(&ex, &p, 0.001, &err);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    vd_collide_exclusion_free(&ex);
    CHECK_INT(vd_alloc_bytes(), before);
  }
  int cap_node[] = {0, 1, 1, 2};
  for (int budget = 0; budget < 14; budget++) {
    int64_t before = vd_alloc_bytes();
    vd_collide_exclusion ex;
    vdt_oom_begin(budget);
    vd_status st = vd_collide_exclusion_build(3, 2, cap_node, 0, NULL, 1, &ex, &err);
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    vd_collide_exclusion_free(&ex);
    CHECK_INT(vd_alloc_bytes(), before);
  }
}
