// SPDX-License-Identifier: MIT
// Cost of the collision geometry the rod solver calls every step: single queries against each
// collider shape, signed distance grid builds, and whole-plant queries (self-collision and a
// robot-like set of colliders) on the bundled tomato at the rod model's 0.02 m segments.
// Results: bench/results/collide-<tag>.csv.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "verdant/verdant.h"
#include "bench_util.h"

// a machine-speed reference measured in the same run (the machine is shared): nanoseconds per
// step of a dependent chain of floating-point adds through memory, best of 5
static double calibration_ns(void) {
  volatile double x = 0;
  double best = HUGE_VAL;
  for (int b = 0; b < 5; b++) {
    double t0 = bench_cpu();
    for (int k = 0; k < 10000000; k++)
      x += 1e-9;
    best = fmin(best, bench_cpu() - t0);
  }
  return best / 1e7 * 1e9;
}

static FILE* csv;

static void row(const char* what, const char* detail, double count, double seconds,
                const char* unit) {
  printf("%-34s %-28s %12.3g %-10s\n", what, detail, count / seconds, unit);
  if (csv) fprintf(csv, "%s,%s,%.6g,%s\n", what, detail, count / seconds, unit);
}

// an icosphere (closed, counter-clockwise from outside) of `level` subdivisions
typedef struct sphere_mesh {
  int nv, nt;
  double* v;
  int* t;
} sphere_mesh;

static void icosphere(sphere_mesh* s, int level, double radius) {
  int nv_max = 12, nt_max = 20;
  for (int l = 0; l < level; l++)
    nv_max += 3 * nt_max / 2, nt_max *= 4;
  s->v = malloc(sizeof(double) * 3 * (size_t)nv_max);
  s->t = malloc(sizeof(int) * 3 * (size_t)nt_max);
  int* edge_a = malloc(sizeof(int) * 3 * (size_t)nt_max);
  int* edge_b = malloc(sizeof(int) * 3 * (size_t)nt_max);
  int* edge_m = malloc(sizeof(int) * 3 * (size_t)nt_max);
  int* t2 = malloc(sizeof(int) * 3 * (size_t)nt_max);
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
  for (int l = 0; l < level; l++) {
    int ne = 0, n2 = 0;
    for (int t = 0; t < s->nt; t++) {
      int c[3] = {s->t[3 * t], s->t[3 * t + 1], s->t[3 * t + 2]}, mid[3];
      for (int k = 0; k < 3; k++) {
        int a = c[k], b = c[(k + 1) % 3], found = -1;
        for (int e = 0; e < ne && found < 0; e++)
          if ((edge_a[e] == a && edge_b[e] == b) || (edge_a[e] == b && edge_b[e] == a))
            found = edge_m[e];
        if (found < 0) {
          vd_vec3 q =
              vd_normalize(vd_v3(s->v[3 * a] + s->v[3 * b], s->v[3 * a + 1] + s->v[3 * b + 1],
                                 s->v[3 * a + 2] + s->v[3 * b + 2]));
          s->v[3 * s->nv] = q.x, s->v[3 * s->nv + 1] = q.y, s->v[3 * s->nv + 2] = q.z;
          edge_a[ne] = a, edge_b[ne] = b, edge_m[ne++] = found = s->nv++;
        }
        mid[k] = found;
      }
      int q[4][3] = {{c[0], mid[0], mid[2]},
                     {c[1], mid[1], mid[0]},
                     {c[2], mid[2], mid[1]},
                     {mid[0], mid[1], mid[2]}};
      memcpy(t2 + 3 * n2, q, sizeof q);
      n2 += 4;
    }
    memcpy(s->t, t2, sizeof(int) * 3 * (size_t)n2);
    s->nt = n2;
  }
  for (int i = 0; i < 3 * s->nv; i++)
    s->v[i] *= radius;
  free(edge_a);
  free(edge_b);
  free(edge_m);
  free(t2);
}

int main(int argc, char** argv) {
  const char* csv_path = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
    else {
      fprintf(stderr, "usage: verdant_bench_collide [--csv PATH]\n");
      return 2;
    }
  }
  if (csv_path && !(csv = fopen(csv_path, "w"))) {
    fprintf(stderr, "cannot write %s\n", csv_path);
    return 1;
  }
  if (csv) fprintf(csv, "what,detail,rate,unit\n");
  double cal = calibration_ns();
  printf("calibration: %.2f ns per dependent add\n", cal);
  if (csv) fprintf(csv, "calibration,dependent add,%.6g,ns\n", cal);
  vd_rng rng;
  vd_rng_seed(&rng, 1);
  printf("%-34s %-28s %12s %-10s\n", "query", "detail", "rate", "unit");

  // signed distance grids of a sphere mesh: build time by mesh size and cell
  sphere_mesh sm[2];
  icosphere(&sm[0], 3, 0.05);
  icosphere(&sm[1], 5, 0.05);
  vd_sdf* grid = NULL;
  for (int m = 0; m < 2; m++)
    for (int full = 1; full >= 0; full--) {
      vd_sdf_def def = vd_sdf_def_default();
      def.full = full;
      vd_error err = {0};
      vd_sdf* g = NULL;
      double t0 = bench_cpu();
      if (vd_sdf_build(sm[m].v, sm[m].nv, sm[m].t, sm[m].nt, &def, &g, &err)) {
        fprintf(stderr, "sdf build failed: %s\n", err.msg);
        return 1;
      }
      double t = bench_cpu() - t0;
      char d[64];
      snprintf(d, sizeof d, "%d tris, %dx%dx%d, %s", sm[m].nt, g->nx, g->ny, g->nz,
               full ? "full" : "band");
      row("sdf build (grids/s)", d, 1, t, "grids/s");
      if (m == 0 && full)
        grid = g;
      else
        vd_sdf_destroy(g);
    }

  // single queries: a point and a tapered capsule against every shape, posed
  vd_pose pose = {vd_v3(0.01, -0.02, 0.03), vd_quat_axis_angle(vd_normalize(vd_v3(1, 2, 3)), 0.7)};
  vd_collider col[5];
  col[0] = vd_collider_plane(vd_v3(0, 0, -0.05), vd_v3(0.1, 0.2, 1));
  col[1] = vd_collider_sphere(vd_v3(0, 0, 0), 0.05);
  col[2] = vd_collider_capsule(vd_v3(-0.05, 0, 0), vd_v3(0.05, 0.02, 0.01), 0.03);
  col[3] = vd_collider_box(pose, vd_v3(0.04, 0.03, 0.05));
  col[4] = vd_collider_sdf(pose, grid);
  const char* names[5] = {"plane", "sphere", "capsule", "box", "sdf (level-3 icosphere)"};
  enum { NQ = 100000 };
  vd_vec3* pa = malloc(sizeof(vd_vec3) * NQ);
  vd_vec3* pb = malloc(sizeof(vd_vec3) * NQ);
  for (int i = 0; i < NQ; i++) {
    pa[i] = vd_v3(vd_rng_uniform(&rng, -0.08, 0.08), vd_rng_uniform(&rng, -0.08, 0.08),
                  vd_rng_uniform(&rng, -0.08, 0.08));
    pb[i] =
        vd_add(pa[i], vd_v3(vd_rng_uniform(&rng, -0.02, 0.02), vd_rng_uniform(&rng, -0.02, 0.02),
                            vd_rng_uniform(&rng, -0.02, 0.02)));
  }
  double sink = 0;
  for (int s = 0; s < 5; s++) {
    double best = HUGE_VAL;
    for (int batch = 0; batch < 5; batch++) {
      double t0 = bench_cpu();
      for (int i = 0; i < NQ; i++)
        sink += vd_collide_point(&col[s], pa[i]).dist;
      best = fmin(best, bench_cpu() - t0);
    }
    row("point query", names[s], NQ, best, "queries/s");
  }
  for (int s = 0; s < 5; s++) {
    int n = s == 4 ? NQ / 10 : NQ;
    double best = HUGE_VAL;
    for (int batch = 0; batch < 5; batch++) {
      double t0 = bench_cpu();
      for (int i = 0; i < n; i++)
        sink += vd_collide_capsule(&col[s], pa[i], pb[i], 0.003, 0.002).dist;
      best = fmin(best, bench_cpu() - t0);
    }
    row("capsule (0.02 m) query", names[s], n, best, "queries/s");
  }

  // the bundled tomato at 0.02 m segments: self-collision and colliders per step
  vd_lsystem* ls = NULL;
  vd_error err = {0};
  char path[4096];
  snprintf(path, sizeof path, "%s/data/tomato.lpy", VD_SOURCE_DIR);
  vd_plant_spec* spec = vd_plant_spec_create();
  vd_lsys_def ld = vd_lsys_def_default();
  vd_model* m = NULL;
  if (vd_lsys_load(path, &ls, &err) || vd_lsys_grow(ls, &ld, NULL, spec, &err) ||
      vd_plant_compile(spec, &m, &err)) {
    fprintf(stderr, "tomato: %s\n", err.msg);
    return 1;
  }
  // resample every segment into pieces of about 0.02 m (the rod model's default)
  int cap_nodes = 0, np = 0, nn = 0;
  for (int s = 0; s < m->nseg; s++) {
    const double* a = m->node_pos0 + 3 * m->seg_node[2 * s];
    const double* b = m->node_pos0 + 3 * m->seg_node[2 * s + 1];
    double len = vd_norm(vd_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
    cap_nodes += 2 * (int)fmax(1, floor(len / 0.02 + 0.5));
  }
  double* node = malloc(sizeof(double) * 3 * (size_t)cap_nodes);
  int* cnode = malloc(sizeof(int) * (size_t)cap_nodes);
  double* crad = malloc(sizeof(double) * (size_t)cap_nodes);
  int* first = malloc(sizeof(int) * (size_t)m->nnode);
  for (int i = 0; i < m->nnode; i++)
    first[i] = -1;
  for (int s = 0; s < m->nseg; s++) {
    int n0 = m->seg_node[2 * s], n1 = m->seg_node[2 * s + 1];
    const double* a = m->node_pos0 + 3 * n0;
    const double* b = m->node_pos0 + 3 * n1;
    double len = vd_norm(vd_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
    int k = (int)fmax(1, floor(len / 0.02 + 0.5));
    // nodes shared with the plant's own nodes at segment ends
    int prev;
    if (first[n0] < 0) first[n0] = nn, memcpy(node + 3 * nn++, a, sizeof(double) * 3);
    prev = first[n0];
    for (int j = 1; j <= k; j++) {
      int cur;
      if (j == k) {
        if (first[n1] < 0) first[n1] = nn, memcpy(node + 3 * nn++, b, sizeof(double) * 3);
        cur = first[n1];
      } else {
        for (int c = 0; c < 3; c++)
          node[3 * nn + c] = a[c] + (b[c] - a[c]) * j / k;
        cur = nn++;
      }
      cnode[2 * np] = prev, cnode[2 * np + 1] = cur;
      double r0 = m->seg_radius[2 * s], r1 = m->seg_radius[2 * s + 1];
      crad[2 * np] = r0 + (r1 - r0) * (j - 1) / k, crad[2 * np + 1] = r0 + (r1 - r0) * j / k;
      np++;
      prev = cur;
    }
  }
  int* snode = malloc(sizeof(int) * (size_t)(m->nsphere + 1));
  for (int i = 0; i < m->nsphere; i++)
    snode[i] = m->sphere_node[i] >= 0 ? first[m->sphere_node[i]] : -1;
  vd_collide_exclusion ex;
  if (vd_collide_exclusion_build(nn, np, cnode, m->nsphere, snode, 1, &ex, &err)) {
    fprintf(stderr, "exclusion: %s\n", err.msg);
    return 1;
  }
  vd_collide_prims P;
  memset(&P, 0, sizeof P);
  P.nnode = nn, P.ncapsule = np, P.nsphere = m->nsphere;
  P.node_pos = node, P.capsule_node = cnode, P.capsule_radius = crad;
  P.sphere_pos = m->sphere_pos0, P.sphere_radius = m->sphere_radius;
  // pairs touching in the modelled shape (a fruit against its pedicel) are not collisions
  if (vd_collide_exclusion_add_touching(&ex, &P, 0.001, &err)) {
    fprintf(stderr, "exclusion: %s\n", err.msg);
    return 1;
  }
  vd_collide_prims_set_exclusion(&P, &ex);
  vd_collide_def def = vd_collide_def_default();
  vd_arena arena;
  vd_arena_init(&arena, 1 << 20);
  vd_contact_list L;
  // best of 10 batches: the machine is shared, the fastest batch is the least disturbed
  int reps = 200;
  double t = HUGE_VAL, t0;
  for (int batch = 0; batch < 10; batch++) {
    t0 = bench_cpu();
    for (int r = 0; r < reps; r++) {
      vd_arena_reset(&arena);
      vd_collide_self(&P, &def, &arena, &L, &err);
    }
    t = fmin(t, bench_cpu() - t0);
  }
  char d[96];
  snprintf(d, sizeof d, "tomato %d caps + %d spheres", np, m->nsphere);
  row("self-collision (queries/s)", d, reps, t, "per s");
  printf("  %d candidate pairs, %d contacts, %.1f us per query\n", (int)L.ntested, L.n,
         1e6 * t / reps);
  // the broad phase every 10 steps with 0.01 m of growth, the narrow phase every step
  vd_arena keep;
  vd_arena_init(&keep, 1 << 20);
  vd_pair_list pairs;
  t = HUGE_VAL;
  for (int batch = 0; batch < 10; batch++) {
    t0 = bench_cpu();
    for (int r = 0; r < reps; r++) {
      if (r % 10 == 0) {
        vd_arena_reset(&keep);
        vd_collide_self_pairs(&P, 0.01, &keep, &pairs, &err);
      }
      vd_arena_reset(&arena);
      vd_collide_pairs(&P, &pairs, &def, &arena, &L, &err);
    }
    t = fmin(t, bench_cpu() - t0);
  }
  row("self-collision, pairs reused", "broad phase every 10 steps", reps, t, "per s");
  printf("  %d candidate pairs (grow 0.01 m), %d contacts, %.1f us per step\n", pairs.n, L.n,
         1e6 * t / reps);
  vd_arena_free(&keep);
  // a gripper-like set around a fruit: two finger capsules, a palm box, a mesh link, the ground
  int f = m->nsphere / 2;
  vd_vec3 fc = vd_v3(m->sphere_pos0[3 * f], m->sphere_pos0[3 * f + 1], m->sphere_pos0[3 * f + 2]);
  vd_collider g[5];
  g[0] = vd_collider_plane(vd_v3(0, 0, 0), vd_v3(0, 0, 1));
  g[1] = vd_collider_capsule(vd_add(fc, vd_v3(-0.02, 0.02, 0)), vd_add(fc, vd_v3(0.04, 0.02, 0)),
                             0.008);
  g[2] = vd_collider_capsule(vd_add(fc, vd_v3(-0.02, -0.02, 0)), vd_add(fc, vd_v3(0.04, -0.02, 0)),
                             0.008);
  vd_pose bp = {vd_add(fc, vd_v3(0.06, 0, 0)), vd_quat_identity()};
  g[3] = vd_collider_box(bp, vd_v3(0.015, 0.05, 0.02));
  vd_pose mp = {vd_add(fc, vd_v3(0.12, 0, 0)), vd_quat_identity()};
  g[4] = vd_collider_sdf(mp, grid);
  t = HUGE_VAL;
  for (int batch = 0; batch < 10; batch++) {
    t0 = bench_cpu();
    for (int r = 0; r < reps; r++) {
      vd_arena_reset(&arena);
      vd_collide_colliders(&P, g, 5, &def, &arena, &L, &err);
    }
    t = fmin(t, bench_cpu() - t0);
  }
  row("colliders (queries/s)", "tomato vs gripper (5 shapes)", reps, t, "per s");
  printf("  %d candidates, %d contacts, %.1f us per query\n", (int)L.ntested, L.n, 1e6 * t / reps);
  if (sink == 42) printf("\n"); // keep the queries observable
  vd_arena_free(&arena);
  vd_collide_exclusion_free(&ex);
  vd_sdf_destroy(grid);
  vd_model_destroy(m);
  vd_plant_spec_destroy(spec);
  vd_lsys_destroy(ls);
  free(node), free(cnode), free(crad), free(first), free(snode), free(pa), free(pb);
  for (int k = 0; k < 2; k++)
    free(sm[k].v), free(sm[k].t);
  if (csv) fclose(csv);
  return 0;
}
