// SPDX-License-Identifier: MIT
// bvh: tree invariants and determinism, ray casts and box overlaps against brute force, and the
// solids' analytic inside tests against the winding number of the tessellated polyhedra.
#include <stdlib.h>

#include "test.h"
#include "verdant/geom.h"
#include "verdant/plant.h"

// ---------------------------------------------------------------------------------------------
// helpers

static vd_model* compile(vd_plant_spec* s) {
  vd_model* m = NULL;
  vd_error err = {0};
  if (vd_plant_compile(s, &m, &err) != VD_OK) return NULL;
  return m;
}

// a small plant: a bent chain of frustums, a lateral branch, a sphere at a tip, a leaf, a box
static vd_plant_spec* small_plant(void) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  vd_vec3 pts[4] = {{0, 0, 0}, {0, 0, 0.1}, {0.01, 0, 0.2}, {0.03, 0.01, 0.28}};
  int nodes[4];
  for (int i = 0; i < 4; i++)
    nodes[i] = vd_plant_add_node(s, pts[i]);
  int prev = -1;
  for (int i = 0; i < 3; i++) {
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = nodes[i], g.node1 = nodes[i + 1];
    g.r0 = 0.01 - 0.002 * i, g.r1 = 0.008 - 0.002 * i;
    g.parent = prev, g.label = 1, g.instance = 1 + i, g.slices = 7;
    g.up = vd_v3(1, 0, 0);
    prev = vd_plant_add_segment(s, &g);
  }
  int nb = vd_plant_add_node(s, vd_v3(0.08, 0.02, 0.15));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = nodes[1], g.node1 = nb, g.r0 = 0.005, g.r1 = 0.004, g.parent = 0;
  g.label = 1, g.instance = 4, g.slices = 6, g.up = vd_v3(0, 0, 1);
  vd_plant_add_segment(s, &g);
  vd_sphere_spec sp = vd_sphere_spec_default();
  sp.center = vd_v3(0.08, 0.02, 0.15), sp.radius = 0.015, sp.label = 3, sp.instance = 5, sp.slices = 10;
  vd_plant_add_sphere(s, &sp);
  // a leaf (thin) through the stem and a closed box around the stem's base
  vd_vec3 lv[3] = {{-0.05, -0.002, 0.05}, {0.05, -0.002, 0.05}, {0, 0.003, 0.09}};
  int lt[3] = {0, 1, 2};
  vd_mesh_spec ms;
  memset(&ms, 0, sizeof ms);
  ms.node = ms.parent = -1, ms.label = 2, ms.instance = 6, ms.module = -1;
  vd_plant_add_mesh(s, &ms, lv, 3, lt, 1);
  vd_vec3 bv[8];
  for (int i = 0; i < 8; i++)
    bv[i] = vd_v3(i & 1 ? 0.02 : -0.02, i & 2 ? 0.02 : -0.02, i & 4 ? 0.03 : -0.01);
  int bt[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  ms.closed = 1, ms.label = 4, ms.instance = 7;
  vd_plant_add_mesh(s, &ms, bv, 8, bt, 12);
  return s;
}

static double urand(unsigned* state) {
  *state = *state * 1664525u + 1013904223u;
  return (*state >> 8) / 16777216.0;
}

// ---------------------------------------------------------------------------------------------
// tree

TEST(bvh, build_invariants_and_determinism) {
  unsigned seed = 7;
  int n = 1000;
  double* box = vd_malloc((size_t)n * 6 * sizeof(double));
  REQUIRE(box);
  for (int i = 0; i < n; i++) {
    for (int k = 0; k < 3; k++) {
      double c = urand(&seed), e = 0.05 * urand(&seed);
      box[6 * i + k] = c - e, box[6 * i + 3 + k] = c + e;
    }
  }
  // a run of identical boxes, which no plane separates
  for (int i = 900; i < 1000; i++)
    for (int k = 0; k < 6; k++)
      box[6 * i + k] = box[6 * 900 + k];
  vd_bvh a, b;
  vd_error err = {0};
  CHECK_STATUS(vd_bvh_build(box, n, NULL, &a, &err), VD_OK, err);
  CHECK_STATUS(vd_bvh_build(box, n, NULL, &b, &err), VD_OK, err);
  CHECK_INT(a.nnode, b.nnode);
  CHECK(memcmp(a.node, b.node, (size_t)a.nnode * sizeof(vd_bvh_node)) == 0);
  CHECK(memcmp(a.item, b.item, (size_t)n * sizeof(int)) == 0);
  // every item once; leaves within the leaf size; boxes nest
  int* seen = vd_calloc((size_t)n, sizeof(int));
  REQUIRE(seen);
  int leaves = 0;
  for (int i = 0; i < a.nnode; i++) {
    const vd_bvh_node* nd = &a.node[i];
    if (nd->count) {
      leaves++;
      CHECK(nd->count <= 4);
      for (int j = nd->first; j < nd->first + nd->count; j++) {
        seen[a.item[j]]++;
        for (int k = 0; k < 3; k++) {
          CHECK(box[6 * a.item[j] + k] >= nd->lo[k]);
          CHECK(box[6 * a.item[j] + 3 + k] <= nd->hi[k]);
        }
      }
    } else {
      for (int c = nd->first; c <= nd->first + 1; c++)
        for (int k = 0; k < 3; k++) {
          CHECK(a.node[c].lo[k] >= nd->lo[k]);
          CHECK(a.node[c].hi[k] <= nd->hi[k]);
        }
    }
  }
  for (int i = 0; i < n; i++)
    CHECK_INT(seen[i], 1);
  CHECK_INT(a.nnode, 2 * leaves - 1);
  // box overlap against brute force
  for (int q = 0; q < 50; q++) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++)
      lo[k] = urand(&seed) - 0.1, hi[k] = lo[k] + 0.2 * urand(&seed);
    int items[1000];
    int m = vd_bvh_overlap(&a, lo, hi, items, 1000);
    REQUIRE(m <= 1000);
    for (int i = 0; i < n; i++) {
      int hit = 1;
      for (int k = 0; k < 3; k++)
        hit &= !(lo[k] > box[6 * i + 3 + k] || hi[k] < box[6 * i + k]);
      int found = 0;
      for (int j = 0; j < m; j++)
        found |= items[j] == i;
      if (hit) CHECK(found);
    }
  }
  vd_free(seen, (size_t)n * sizeof(int));
  vd_free(box, (size_t)n * 6 * sizeof(double));
  vd_bvh_free(&a);
  vd_bvh_free(&b);
  // bad settings
  vd_bvh_def def = vd_bvh_def_default();
  def.bins = 1;
  CHECK_STATUS(vd_bvh_build(NULL, 0, &def, &a, &err), VD_ERR_ARG, err);
}

// brute-force nearest hit (Möller-Trumbore on every triangle)
static int brute_hit(const vd_mesh* mesh, vd_vec3 o, vd_vec3 d, double tmax, int cull,
                     const unsigned char* one_sided, double* tbest) {
  int best = -1;
  *tbest = tmax;
  for (int t = 0; t < mesh->ntri; t++) {
    const double* a = mesh->pos + 3 * mesh->tri[3 * t];
    const double* b = mesh->pos + 3 * mesh->tri[3 * t + 1];
    const double* c = mesh->pos + 3 * mesh->tri[3 * t + 2];
    vd_vec3 e1 = vd_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    vd_vec3 e2 = vd_v3(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
    vd_vec3 p = vd_cross(d, e2);
    double det = vd_dot(e1, p);
    if (det == 0 || (cull && one_sided[t] && det < 0)) continue;
    vd_vec3 s = vd_sub(o, vd_v3(a[0], a[1], a[2]));
    double u = vd_dot(s, p) / det;
    if (u < 0 || u > 1) continue;
    vd_vec3 q = vd_cross(s, e1);
    double v = vd_dot(d, q) / det;
    if (v < 0 || u + v > 1) continue;
    double tt = vd_dot(e2, q) / det;
    if (tt > 0 && tt < *tbest) *tbest = tt, best = t;
  }
  return best;
}

TEST(bvh, raycast_matches_brute_force) {
  vd_plant_spec* s = small_plant();
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  unsigned char* one = vd_malloc((size_t)mesh.ntri);
  REQUIRE(one);
  for (int t = 0; t < mesh.ntri; t++)
    one[t] = mesh.tri_kind[t] != VD_PRIM_MESH || m->mesh_closed[mesh.tri_prim[t]];
  vd_bvh bvh;
  CHECK_STATUS(vd_bvh_build_mesh(&mesh, one, NULL, &bvh, &err), VD_OK, err);
  unsigned seed = 3;
  int hits = 0;
  for (int q = 0; q < 2000; q++) {
    vd_vec3 o = vd_v3(0.4 * urand(&seed) - 0.2, 0.4 * urand(&seed) - 0.2, 0.4 * urand(&seed) - 0.05);
    vd_vec3 target = vd_v3(0.1 * urand(&seed) - 0.03, 0.06 * urand(&seed) - 0.03, 0.3 * urand(&seed));
    vd_vec3 d = vd_normalize(vd_sub(target, o));
    int cull = q & 1;
    double tb;
    int bt = brute_hit(&mesh, o, d, INFINITY, cull, one, &tb);
    vd_hit h;
    int got = vd_bvh_raycast(&bvh, o, d, 0, INFINITY, cull, -1, &h);
    CHECK_INT(got, bt >= 0);
    if (got && bt >= 0) {
      hits++;
      CHECK_NEAR(h.t, tb, 1e-12);
      CHECK_INT(h.label, mesh.tri_label[h.tri]);
      CHECK_INT(h.instance, mesh.tri_instance[h.tri]);
      // the hit point from (u, v) is the ray point
      const double* a = mesh.pos + 3 * mesh.tri[3 * h.tri];
      const double* b = mesh.pos + 3 * mesh.tri[3 * h.tri + 1];
      const double* c = mesh.pos + 3 * mesh.tri[3 * h.tri + 2];
      for (int k = 0; k < 3; k++) {
        double pk = (1 - h.u - h.v) * a[k] + h.u * b[k] + h.v * c[k];
        double rk = k == 0 ? o.x + h.t * d.x : k == 1 ? o.y + h.t * d.y : o.z + h.t * d.z;
        CHECK_NEAR(pk, rk, 1e-12);
      }
    }
    // any-hit within half the nearest distance finds nothing; within the full ray, something
    if (bt >= 0 && !cull) {
      CHECK(!vd_bvh_occluded(&bvh, o, d, 0, 0.5 * tb, -1));
      CHECK(vd_bvh_occluded(&bvh, o, d, 0, INFINITY, -1));
    }
  }
  CHECK(hits > 300);
  vd_bvh_free(&bvh);
  vd_free(one, (size_t)mesh.ntri);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

// ---------------------------------------------------------------------------------------------
// solids

// winding number of the triangles of one primitive of the tessellation (a closed polyhedron)
static double winding(const vd_mesh* mesh, int kind, int prim, vd_vec3 p) {
  double w = 0;
  for (int t = 0; t < mesh->ntri; t++) {
    if (mesh->tri_kind[t] != kind || mesh->tri_prim[t] != prim) continue;
    const double* v[3];
    for (int c = 0; c < 3; c++)
      v[c] = mesh->pos + 3 * mesh->tri[3 * t + c];
    vd_vec3 a = vd_sub(vd_v3(v[0][0], v[0][1], v[0][2]), p);
    vd_vec3 b = vd_sub(vd_v3(v[1][0], v[1][1], v[1][2]), p);
    vd_vec3 c = vd_sub(vd_v3(v[2][0], v[2][1], v[2][2]), p);
    double la = vd_norm(a), lb = vd_norm(b), lc = vd_norm(c);
    double num = vd_dot(a, vd_cross(b, c));
    double den = la * lb * lc + vd_dot(a, b) * lc + vd_dot(a, c) * lb + vd_dot(b, c) * la;
    w += 2 * atan2(num, den);
  }
  return w / (4 * VD_PI);
}

TEST(bvh, solids_match_tessellated_polyhedra) {
  vd_plant_spec* s = small_plant();
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_solids so;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  CHECK_STATUS(vd_solids_build(m, NULL, NULL, &so, &err), VD_OK, err);
  CHECK_INT(so.nsolid, m->nseg + m->nsphere + 1);  // the leaf is thin, the box closed
  CHECK_INT(so.mesh_solid[0], -1);
  // random points near each solid: the O(1) polygon tests agree with the polyhedron's winding
  // number wherever the point is not within 1e-7 m of its surface
  unsigned seed = 11;
  int inside = 0, tested = 0;
  for (int i = 0; i < so.nsolid; i++) {
    const vd_solid* sd = &so.solid[i];
    for (int q = 0; q < 3000; q++) {
      vd_vec3 p;
      double* pv = &p.x;
      for (int k = 0; k < 3; k++) {
        double span = sd->hi[k] - sd->lo[k];
        pv[k] = sd->lo[k] - 0.1 * span + 1.2 * span * urand(&seed);
      }
      double w = winding(&mesh, sd->kind, sd->prim, p);
      if (fabs(w - 0.5) < 0.49) continue;  // on or very near the surface
      int want = w > 0.5, got = vd_solid_contains(&so, i, p);
      if (want != got) {
        vdt_fail(__FILE__, __LINE__, "solid %d (kind %d): point (%g %g %g) winding %g, contains %d",
                 i, sd->kind, p.x, p.y, p.z, w, got);
        break;
      }
      inside += want, tested++;
    }
  }
  CHECK(inside > 1000 && tested - inside > 1000);
  // the query: a point inside the first segment is inside it, unless that is its own primitive
  vd_vec3 p = vd_v3(0.001, 0.001, 0.05);
  CHECK_INT(vd_solids_inside(&so, p, -1, -1), so.seg_solid[0]);
  CHECK_INT(vd_solids_inside(&so, p, VD_PRIM_SEGMENT, 0), -1);
  CHECK_INT(vd_solids_inside(&so, vd_v3(0.001, 0.001, 0.0), VD_PRIM_SEGMENT, 0), so.mesh_solid[1]);
  CHECK_INT(vd_solids_inside(&so, vd_v3(1, 1, 1), -1, -1), -1);
  // a point on the start plane of segment 1 (boundary) counts as inside it
  CHECK_INT(vd_solids_inside(&so, vd_v3(0, 0, 0.1), VD_PRIM_SEGMENT, 0), so.seg_solid[1]);
  vd_solids_free(&so);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

TEST(bvh, solids_tube_neighbours) {
  // a generalised-cylinder chain: joined segments do not test each other
  vd_plant_spec* s = vd_plant_spec_create();
  REQUIRE(s);
  int a = vd_plant_add_node(s, vd_v3(0, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0.1));
  int c = vd_plant_add_node(s, vd_v3(0.03, 0, 0.19));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.01, g.flags = VD_SEG_GC, g.label = 1, g.instance = 1;
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0;
  vd_plant_add_segment(s, &g);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_solids so;
  vd_error err = {0};
  CHECK_STATUS(vd_solids_build(m, NULL, NULL, &so, &err), VD_OK, err);
  CHECK_INT(so.solid[0].joined[1], 1);
  CHECK_INT(so.solid[1].joined[0], 0);
  // near the joint, inside both frustums: not inside anything for the other tube segment
  vd_vec3 p = vd_v3(0.002, 0, 0.1);
  CHECK(vd_solid_contains(&so, 0, p) && vd_solid_contains(&so, 1, p));
  CHECK_INT(vd_solids_inside(&so, p, VD_PRIM_SEGMENT, 0), -1);
  CHECK_INT(vd_solids_inside(&so, p, VD_PRIM_SEGMENT, 1), -1);
  CHECK(vd_solids_inside(&so, p, VD_PRIM_SPHERE, 0) >= 0);
  vd_solids_free(&so);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

TEST(bvh, out_of_memory) {
  vd_plant_spec* s = small_plant();
  REQUIRE(s);
  vd_model* m = compile(s);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  int ok = 0;
  for (int budget = 0; budget < 20 && !ok; budget++) {
    vd_solids so;
    vd_bvh bvh;
    vdt_oom_begin(budget);
    vd_status a = vd_solids_build(m, NULL, NULL, &so, &err);
    vd_status b = a ? a : vd_bvh_build_mesh(&mesh, NULL, NULL, &bvh, &err);
    vdt_oom_end();
    CHECK(a == VD_OK || a == VD_ERR_NOMEM);
    CHECK(b == VD_OK || b == VD_ERR_NOMEM);
    if (!a) vd_solids_free(&so);
    if (!b) vd_bvh_free(&bvh);
    ok = !a && !b;
  }
  CHECK(ok);
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}
