// SPDX-License-Identifier: MIT
// The MuJoCo peer of the rod solver: what a robotics user builds instead of a Cosserat rod, a
// chain (or tree) of capsule bodies joined by ball joints with springs, in MuJoCo 2.2.2.
//
// Joint stiffness from the beam (docs/benchmarks.md): a piece of rod of length l bent to a
// uniform curvature kappa stores U = EI kappa^2 l / 2 and turns its ends by theta = kappa l, so
// U = (EI / l) theta^2 / 2: a joint that lumps the bending of a length l has k = EI / l (N m/rad).
// A joint between bodies of lengths la and lb lumps half of each: l = (la + lb) / 2. The root
// joint of a cantilever lumps only the half body beside the wall: l = l1 / 2, k = 2 EI / l1
// ("root 2EI/l"); the plain chain a user writes gives every joint EI / l ("uniform").
//
// Measured in one run:
//  1. cantilever statics (anchors-physics.md sec. 3.1: L = 1 m, r = 5 mm, rho = 1000 kg/m^3,
//     E = 10 GPa) under self-weight and a 0.5 N tip load, for N bodies: the settled tip
//     deflection against the discrete model's exact (nonlinear) equilibrium and the continuum
//     one (linear Euler-Bernoulli qL^4/8EI, PL^3/3EI, and the nonlinear continuum limit);
//  2. cantilever dynamics: the largest stable time step with light damping (2 % of critical on
//     the first mode), steps/s there and at 1 ms, real-time factors;
//  3. plants (the bundled tomato; the tree with --plants) as body trees of 0.02 m pieces with
//     the sim's draft materials: the largest stable step, steps/s, real-time factor.
// Results: bench/results/mujoco-chain-<tag>.csv. `--selftest` checks the error trap instead.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <mujoco/mujoco.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mjtrap/mjtrap.h"
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

// ---------------------------------------------------------------------------------------------
// MJCF text and loading from memory

typedef struct text {
  char* s;
  size_t n, cap;
} text;

static void put(text* t, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text* t, const char* fmt, ...) {
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(t->s ? t->s + t->n : NULL, t->s ? t->cap - t->n : 0, fmt, ap);
    va_end(ap);
    if (k >= 0 && t->s && t->n + (size_t)k < t->cap) {
      t->n += (size_t)k;
      return;
    }
    size_t cap = t->cap ? 2 * t->cap : 1 << 16;
    while (cap < t->n + (size_t)k + 1)
      cap *= 2;
    char* s = realloc(t->s, cap);
    if (!s) {
      fprintf(stderr, "out of memory\n");
      exit(1);
    }
    t->s = s, t->cap = cap;
  }
}

// compile MJCF text through MuJoCo's virtual file system; NULL and a message on failure
static mjModel* load_xml(const text* t, char* msg, int cap) {
  mjVFS* vfs = malloc(sizeof *vfs);
  if (!vfs) return NULL;
  mj_defaultVFS(vfs);
  mjModel* m = NULL;
  if (mj_makeEmptyFileVFS(vfs, "model.xml", (int)t->n) == 0) {
    memcpy(vfs->filedata[vfs->nfile - 1], t->s, t->n);
    m = mj_loadXML("model.xml", vfs, msg, cap);
  } else {
    snprintf(msg, (size_t)cap, "could not make a VFS file");
  }
  mj_deleteVFS(vfs);
  free(vfs);
  return m;
}

// ---------------------------------------------------------------------------------------------
// the cantilever

typedef struct beam {
  double L, r, rho, E, g; // length (m), radius (m), density (kg/m^3), Young (Pa), gravity
  double P;               // tip load (N), applied with gravity off
} beam;

static double beam_EI(const beam* b) {
  return b->E * VD_PI * pow(b->r, 4) / 4;
}
static double beam_q(const beam* b) {
  return b->rho * VD_PI * b->r * b->r * b->g;
}

// the chain: N capsule bodies along +x, ball joints with stiffness k and damping beta * k
static mjModel* chain_model(const beam* b, int N, int root2, double beta, double dt, double g,
                            char* msg, int cap) {
  double l = b->L / N, m = b->rho * VD_PI * b->r * b->r * l, EI = beam_EI(b);
  text t = {0};
  put(&t, "<mujoco model=\"cantilever\">\n<compiler angle=\"radian\"/>\n");
  put(&t, "<option timestep=\"%.17g\" gravity=\"0 0 %.17g\" integrator=\"Euler\"/>\n", dt, -g);
  put(&t, "<worldbody>\n");
  for (int i = 0; i < N; i++) {
    double k = EI / l * (i == 0 && root2 ? 2 : 1);
    double Iax = 0.5 * m * b->r * b->r, Iperp = m * (3 * b->r * b->r + l * l) / 12;
    put(&t, "<body pos=\"%.17g 0 0\"><joint type=\"ball\" stiffness=\"%.17g\" damping=\"%.17g\"/>",
        i ? l : 0.0, k, beta * k);
    put(&t, "<inertial pos=\"%.17g 0 0\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>", l / 2,
        m, Iax, Iperp, Iperp);
    put(&t,
        "<geom type=\"capsule\" fromto=\"0 0 0 %.17g 0 0\" size=\"%.17g\" contype=\"0\" "
        "conaffinity=\"0\"/>\n",
        l, b->r);
  }
  for (int i = 0; i < N; i++)
    put(&t, "</body>");
  put(&t, "\n</worldbody>\n</mujoco>\n");
  mjModel* mm = load_xml(&t, msg, cap);
  free(t.s);
  return mm;
}

// tip of the chain (end of the last body) after mj_forward
static void chain_tip(const mjModel* M, const mjData* d, double l, double tip[3]) {
  int b = M->nbody - 1;
  const double* R = d->xmat + 9 * b;
  for (int a = 0; a < 3; a++)
    tip[a] = d->xpos[3 * b + a] + R[3 * a] * l;
}

// the tip load as a force at the tip: force at the centre of mass plus its moment
static void apply_tip_load(const mjModel* M, mjData* d, double l, double P) {
  int b = M->nbody - 1;
  double tip[3];
  chain_tip(M, d, l, tip);
  double arm[3] = {tip[0] - d->xipos[3 * b], tip[1] - d->xipos[3 * b + 1],
                   tip[2] - d->xipos[3 * b + 2]};
  double F[3] = {0, 0, -P};
  double* x = d->xfrc_applied + 6 * b;
  x[0] = F[0], x[1] = F[1], x[2] = F[2];
  x[3] = arm[1] * F[2] - arm[2] * F[1];
  x[4] = arm[2] * F[0] - arm[0] * F[2];
  x[5] = arm[0] * F[1] - arm[1] * F[0];
}

// the discrete model's exact planar equilibrium: rigid bodies, joint i at the start of body i
// with stiffness k_i, weights at body centres and P at the tip; fixed-point iteration on the
// joint angles with O(N) moments by suffix sums. Returns the tip's downward deflection (m).
static double discrete_tip(const beam* b, int N, int root2, int selfweight) {
  double l = b->L / N, EI = beam_EI(b), w = selfweight ? beam_q(b) * l : 0;
  double P = selfweight ? 0 : b->P;
  double* phi = calloc((size_t)N, sizeof(double));   // absolute angle of body i (down positive)
  double* x = calloc((size_t)N + 1, sizeof(double)); // joint x positions, x[N] the tip
  double tip = 0;
  for (int it = 0; it < 200; it++) {
    // positions from the angles
    double z = 0;
    x[0] = 0;
    for (int i = 0; i < N; i++)
      x[i + 1] = x[i] + l * cos(phi[i]), z += l * sin(phi[i]);
    // moments about each joint: weights at the body centres, P at the tip
    double S = P, SX = P * x[N], change = 0, ang = 0;
    double* M = calloc((size_t)N, sizeof(double));
    for (int i = N - 1; i >= 0; i--) {
      double xc = x[i] + 0.5 * l * cos(phi[i]);
      S += w, SX += w * xc;
      M[i] = SX - S * x[i];
    }
    for (int i = 0; i < N; i++) {
      double k = EI / l * (i == 0 && root2 ? 2 : 1);
      ang += M[i] / k;
      change = fmax(change, fabs(ang - phi[i]));
      phi[i] = ang;
    }
    free(M);
    tip = z;
    if (change < 1e-15) break;
  }
  double z = 0;
  for (int i = 0; i < N; i++)
    z += l * sin(phi[i]);
  tip = z;
  free(phi);
  free(x);
  return tip;
}

// the continuum limit of the nonlinear equilibrium: Richardson on the 1/N error of the
// discrete model (root 2EI/l makes the error O(1/N^2); extrapolate at that order)
static double continuum_tip(const beam* b, int selfweight) {
  double d1 = discrete_tip(b, 20000, 1, selfweight), d2 = discrete_tip(b, 40000, 1, selfweight);
  return (4 * d2 - d1) / 3;
}

typedef struct statics {
  double tip;      // settled downward tip deflection (m)
  double settle_s; // simulated time to settle (s)
  double steps_s;  // steps per wall-clock second while settling
  int ok;          // settled without a MuJoCo warning or error
} statics;

// settle the chain with heavy damping and read the tip
static statics chain_statics(const beam* b, int N, int root2, int selfweight) {
  statics out = {0, 0, 0, 0};
  char msg[1000] = "";
  double dt = 1e-3, beta = 0.05;
  mjModel* M = chain_model(b, N, root2, beta, dt, selfweight ? b->g : 0, msg, sizeof msg);
  if (!M) {
    fprintf(stderr, "MuJoCo load failed: %s\n", msg);
    return out;
  }
  mjData* d = mj_makeData(M);
  vd_mj_trap trap;
  double l = b->L / N;
  if (VD_MJ_TRY(&trap)) {
    int steps = 0;
    double t0 = bench_cpu();
    for (; steps < 60000; steps++) {
      if (!selfweight) apply_tip_load(M, d, l, b->P);
      mj_step(M, d);
      if (steps > 200 && steps % 50 == 0) {
        double v = 0;
        for (int i = 0; i < M->nv; i++)
          v = fmax(v, fabs(d->qvel[i]));
        if (v < 1e-12) break;
      }
    }
    out.steps_s = steps / (bench_cpu() - t0);
    out.settle_s = steps * dt;
    mj_forward(M, d);
    double tip[3];
    chain_tip(M, d, l, tip);
    out.tip = -tip[2];
    out.ok = d->warning[mjWARN_BADQACC].number == 0 && trap.nwarning == 0 && steps < 60000;
    vd_mj_trap_end(&trap);
  } else {
    fprintf(stderr, "MuJoCo error: %s\n", trap.error);
  }
  mj_deleteData(d);
  mj_deleteModel(M);
  return out;
}

// ---------------------------------------------------------------------------------------------
// stability and speed of any model

// run `seconds` from rest; stable when no warning, every value finite and the bodies stay
// within `reach` (m) of where they started
static int run_stable(const mjModel* M, mjData* d, double seconds, double reach) {
  mj_resetData(M, d);
  mj_forward(M, d);
  double* x0 = malloc(sizeof(double) * 3 * (size_t)M->nbody);
  memcpy(x0, d->xpos, sizeof(double) * 3 * (size_t)M->nbody);
  vd_mj_trap trap;
  int ok = 0;
  if (VD_MJ_TRY(&trap)) {
    int n = (int)ceil(seconds / M->opt.timestep);
    ok = 1;
    for (int s = 0; s < n && ok; s++) {
      mj_step(M, d);
      if (d->warning[mjWARN_BADQACC].number || trap.nwarning) ok = 0;
      if (s % 20 == 0 || s == n - 1) {
        for (int i = 0; i < 3 * M->nbody && ok; i++)
          if (!isfinite(d->xpos[i]) || fabs(d->xpos[i] - x0[i]) > reach) ok = 0;
      }
    }
    vd_mj_trap_end(&trap);
  }
  free(x0);
  return ok;
}

// steps per second of stepping from rest, at least `min_s` wall seconds
static double steps_per_second(const mjModel* M, mjData* d, double min_s) {
  mj_resetData(M, d);
  vd_mj_trap trap;
  double rate = 0;
  if (VD_MJ_TRY(&trap)) {
    int steps = 0;
    double t0 = bench_cpu(), t = 0;
    do {
      mj_step(M, d);
      steps++;
      t = bench_cpu() - t0;
    } while (t < min_s || steps < 3);
    rate = steps / t;
    vd_mj_trap_end(&trap);
  }
  return rate;
}

static const double dt_ladder[] = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4,
                                   5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6};
#define NLADDER ((int)(sizeof dt_ladder / sizeof dt_ladder[0]))

// the largest stable step of the ladder (0 when none), for a model built per step by make()
typedef mjModel* (*make_fn)(void* user, double dt, char* msg, int cap);

static double largest_stable_dt(make_fn make, void* user, double seconds, double reach) {
  for (int k = 0; k < NLADDER; k++) {
    char msg[1000] = "";
    mjModel* M = make(user, dt_ladder[k], msg, sizeof msg);
    if (!M) {
      fprintf(stderr, "MuJoCo load failed: %s\n", msg);
      return 0;
    }
    mjData* d = mj_makeData(M);
    int ok = run_stable(M, d, seconds, reach);
    mj_deleteData(d);
    mj_deleteModel(M);
    if (ok) return dt_ladder[k];
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// plants as body trees

#define MAX_NEST 95 // deepest body nesting MuJoCo 2.2.2 + tinyxml2 9 accept (with margin)

typedef struct plant_mj {
  const vd_model* m;
  double piece; // target body length (m)
  double beta;  // damping / stiffness (s)
  int nbody, njoint;
  const char* save; // write the MJCF here when not NULL
} plant_mj;

// the sim's draft materials by organ (wt-sim vd_sim_def_default): E (Pa), rho (kg/m^3)
static void material(const vd_label* lab, double* E, double* rho, int* clamp) {
  vd_organ o = lab ? lab->organ : VD_ORGAN_OTHER;
  const char* n = lab ? lab->name : "";
  *clamp = 0;
  *E = 5e7, *rho = 1000; // green stem
  if (o == VD_ORGAN_STEM && (strstr(n, "trunk") || strstr(n, "branch") || strstr(n, "wood") ||
                             strstr(n, "twig") || strstr(n, "bole")))
    *E = 1e10, *rho = 900;
  else if (o == VD_ORGAN_PEDICEL)
    *E = 2.25e7, *rho = 1000;
  else if (o == VD_ORGAN_LEAF)
    *E = 2e7, *rho = 900;
  else if (o == VD_ORGAN_FLOWER)
    *E = 1e7, *rho = 500;
  else if (o == VD_ORGAN_ROOT)
    *E = 1e10, *rho = 900, *clamp = 1;
}

static vd_vec3 v3at(const double* a, int i) {
  return vd_v3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
}

// pieces of segment s at the target length (0 for a zero-length segment)
static int pieces(const vd_model* m, int s, double piece) {
  double len = vd_norm(
      vd_sub(v3at(m->node_pos0, m->seg_node[2 * s + 1]), v3at(m->node_pos0, m->seg_node[2 * s])));
  return len > 0 ? (int)fmax(1, floor(len / piece + 0.5)) : 0;
}

// deepest body nesting of the plant at a piece length
static int max_depth(const vd_model* m, double piece) {
  int deepest = 0;
  for (int s = 0; s < m->nseg; s++) {
    int d = 0;
    for (int q = s; q >= 0; q = m->seg_parent[q])
      d += pieces(m, q, piece);
    deepest = d > deepest ? d : deepest;
  }
  return deepest;
}

// write segment s's pieces (and everything hanging from it) as nested bodies
static void plant_body(plant_mj* P, text* t, int s, const int* cstart, const int* child,
                       vd_vec3 parent_origin, double parent_len, int welded, double dt) {
  const vd_model* m = P->m;
  (void)dt;
  vd_vec3 a = v3at(m->node_pos0, m->seg_node[2 * s]),
          b = v3at(m->node_pos0, m->seg_node[2 * s + 1]);
  double len = vd_norm(vd_sub(b, a));
  const vd_label* lab = vd_model_find_label(m, m->seg_label[s]);
  double E, rho;
  int clamp;
  material(lab, &E, &rho, &clamp);
  int n = pieces(m, s, P->piece);
  double l = n ? len / n : 0;
  vd_vec3 origin = parent_origin;
  int open = 0;
  for (int j = 0; j < n; j++) {
    vd_vec3 p0 = vd_madd(a, vd_sub(b, a), (double)j / n);
    double r0 = m->seg_radius[2 * s] + (m->seg_radius[2 * s + 1] - m->seg_radius[2 * s]) * j / n;
    double r1 =
        m->seg_radius[2 * s] + (m->seg_radius[2 * s + 1] - m->seg_radius[2 * s]) * (j + 1) / n;
    double rm = 0.5 * (r0 + r1), mass = rho * VD_PI * rm * rm * l;
    vd_vec3 rel = vd_sub(p0, origin);
    put(t, "<body pos=\"%.9g %.9g %.9g\">", rel.x, rel.y, rel.z);
    P->nbody++;
    open++;
    // a ball joint lumping half of this piece and half of the one before; roots are clamped
    int joint = !(clamp || (welded && j == 0));
    if (joint) {
      double lbar = 0.5 * ((j ? l : parent_len) + l);
      double k = E * VD_PI * pow(r0, 4) / 4 / lbar;
      put(t, "<joint type=\"ball\" stiffness=\"%.9g\" damping=\"%.9g\"/>", k, P->beta * k);
      P->njoint++;
    }
    vd_vec3 d = vd_sub(b, a);
    put(t,
        "<geom type=\"capsule\" fromto=\"0 0 0 %.9g %.9g %.9g\" size=\"%.9g\" mass=\"%.9g\" "
        "contype=\"0\" conaffinity=\"0\"/>\n",
        d.x / n, d.y / n, d.z / n, fmax(rm, 1e-5), mass);
    origin = p0;
  }
  double last_len = n ? l : parent_len;
  // fruits and leaves on this segment: rigid masses on its last piece
  for (int i = 0; i < m->nsphere; i++) {
    if (m->sphere_parent[i] != s) continue;
    vd_vec3 c = vd_sub(v3at(m->sphere_pos0, i), origin);
    double r = m->sphere_radius[i], mass = 800 * 4.0 / 3 * VD_PI * r * r * r;
    put(t,
        "<geom type=\"sphere\" pos=\"%.9g %.9g %.9g\" size=\"%.9g\" mass=\"%.9g\" "
        "contype=\"0\" conaffinity=\"0\"/>\n",
        c.x, c.y, c.z, fmax(r, 1e-4), mass);
  }
  for (int i = 0; i < m->nmesh; i++) {
    if (m->mesh_parent[i] != s) continue;
    // lamina mass 0.22 kg/m^2 (the sim's leaf_areal_density) at the area centroid
    double area = 0;
    vd_vec3 cen = vd_v3(0, 0, 0);
    for (int q = m->mesh_tri[2 * i]; q < m->mesh_tri[2 * i] + m->mesh_tri[2 * i + 1]; q++) {
      vd_vec3 p0 = v3at(m->vert_pos0, m->tri_vert[3 * q]),
              p1 = v3at(m->vert_pos0, m->tri_vert[3 * q + 1]);
      vd_vec3 p2 = v3at(m->vert_pos0, m->tri_vert[3 * q + 2]);
      double ar = 0.5 * vd_norm(vd_cross(vd_sub(p1, p0), vd_sub(p2, p0)));
      area += ar;
      cen = vd_madd(cen, vd_add(p0, vd_add(p1, p2)), ar / 3);
    }
    if (!(area > 0)) continue;
    cen = vd_sub(vd_scale(cen, 1 / area), origin);
    put(t,
        "<geom type=\"sphere\" pos=\"%.9g %.9g %.9g\" size=\"0.005\" mass=\"%.9g\" "
        "contype=\"0\" conaffinity=\"0\"/>\n",
        cen.x, cen.y, cen.z, 0.22 * area);
  }
  // children continue from the end of this segment's last piece
  for (int e = cstart[s]; e < cstart[s + 1]; e++)
    plant_body(P, t, child[e], cstart, child, origin, last_len, welded && n == 0, dt);
  for (int j = 0; j < open; j++)
    put(t, "</body>");
  put(t, "\n");
}

static mjModel* plant_model(void* user, double dt, char* msg, int cap) {
  plant_mj* P = user;
  const vd_model* m = P->m;
  P->nbody = P->njoint = 0;
  // MJCF states the kinematic tree only by nesting, and Debian's MuJoCo 2.2.2 parses it with
  // tinyxml2 9, which rejects elements nested deeper than 100: lengthen the pieces until the
  // deepest path fits
  while (max_depth(m, P->piece) > MAX_NEST)
    P->piece *= 1.05;
  // children of every segment, in index order
  int* cstart = calloc((size_t)m->nseg + 2, sizeof(int));
  int* child = malloc(sizeof(int) * ((size_t)m->nseg + 1));
  for (int s = 0; s < m->nseg; s++)
    if (m->seg_parent[s] >= 0) cstart[m->seg_parent[s] + 1]++;
  for (int s = 0; s < m->nseg; s++)
    cstart[s + 1] += cstart[s];
  int* fill = malloc(sizeof(int) * ((size_t)m->nseg + 1));
  for (int s = 0; s <= m->nseg; s++)
    fill[s] = cstart[s];
  for (int s = 0; s < m->nseg; s++)
    if (m->seg_parent[s] >= 0) child[fill[m->seg_parent[s]]++] = s;
  text t = {0};
  put(&t, "<mujoco model=\"plant\">\n<compiler angle=\"radian\" inertiafromgeom=\"true\"/>\n");
  put(&t, "<size njmax=\"10\" nconmax=\"10\"/>\n");
  put(&t, "<option timestep=\"%.17g\" gravity=\"0 0 -9.81\" integrator=\"Euler\"/>\n", dt);
  put(&t, "<worldbody>\n");
  // every root segment hangs from the world, its first piece clamped (a stem in a pot)
  for (int s = 0; s < m->nseg; s++)
    if (m->seg_parent[s] < 0) plant_body(P, &t, s, cstart, child, vd_v3(0, 0, 0), 0, 1, dt);
  put(&t, "</worldbody>\n</mujoco>\n");
  mjModel* M = load_xml(&t, msg, cap);
  if (P->save) {
    FILE* f = fopen(P->save, "w");
    if (f) fwrite(t.s, 1, t.n, f), fclose(f);
  }
  free(t.s);
  free(cstart);
  free(child);
  free(fill);
  return M;
}

// ---------------------------------------------------------------------------------------------
// the self-test of the error trap (registered in CTest)

static int selftest(void) {
  volatile int fail = 0;
#define EXPECT(c)                                                                                  \
  do {                                                                                             \
    if (!(c)) fprintf(stderr, "FAIL %s:%d: %s\n", __FILE__, __LINE__, #c), fail++;                 \
  } while (0)
  vd_mj_trap_install();
  char msg[1000] = "";
  text t = {0};
  put(&t, "<mujoco><worldbody><body><freejoint/><geom size=\"0.1\"/></body></worldbody></mujoco>");
  mjModel* M = load_xml(&t, msg, sizeof msg);
  EXPECT(M != NULL);
  if (!M) return 1;
  // an engine error deep inside mj_step (its stack made too small) comes back as a status
  int keep = M->nstack;
  M->nstack = 10;
  mjData* volatile d = mj_makeData(M);
  vd_mj_trap trap;
  volatile int reached = 0;
  if (VD_MJ_TRY(&trap)) {
    mj_step(M, d);
    reached = 1;
    vd_mj_trap_end(&trap);
  } else {
    vd_error err = {0};
    EXPECT(vd_mj_trap_status(&trap, &err) == VD_ERR_VALUE);
    EXPECT(strstr(err.msg, "MuJoCo: ") == err.msg && strlen(err.msg) > 8);
  }
  EXPECT(!reached);
  EXPECT(vd_mj_trap_current() == NULL);
  mj_deleteData(d);
  // a healthy model steps afterwards; a NaN is a counted warning, not an exit or a print
  M->nstack = keep;
  d = mj_makeData(M);
  if (VD_MJ_TRY(&trap)) {
    mj_step(M, d);
    d->qpos[0] = NAN;
    mj_step(M, d);
    vd_mj_trap_end(&trap);
    EXPECT(trap.nwarning == 1 && strstr(trap.warning, "QPOS") != NULL);
  } else {
    EXPECT(0 && "unexpected MuJoCo error");
  }
  // nested traps: the inner one catches, the outer stays open
  vd_mj_trap outer, inner;
  if (VD_MJ_TRY(&outer)) {
    if (VD_MJ_TRY(&inner)) {
      mju_error("inner");
      vd_mj_trap_end(&inner);
    }
    EXPECT(strcmp(inner.error, "inner") == 0);
    EXPECT(vd_mj_trap_current() == &outer);
    vd_mj_trap_end(&outer);
  }
  EXPECT(vd_mj_trap_current() == NULL);
  // a bad model is a load message, not an error jump
  t.n = 0;
  put(&t, "<mujoco><worldbody><body><bogus/></body></worldbody></mujoco>");
  EXPECT(load_xml(&t, msg, sizeof msg) == NULL && strstr(msg, "bogus") != NULL);
  free(t.s);
  mj_deleteData(d);
  mj_deleteModel(M);
  printf("%d passed, %d failed\n", fail ? 0 : 1, fail ? 1 : 0);
  return fail ? 1 : 0;
#undef EXPECT
}

// ---------------------------------------------------------------------------------------------

typedef struct chain_user {
  const beam* b;
  int N, root2;
  double beta;
} chain_user;

static mjModel* chain_make(void* user, double dt, char* msg, int cap) {
  chain_user* u = user;
  return chain_model(u->b, u->N, u->root2, u->beta, dt, u->b->g, msg, cap);
}

int main(int argc, char** argv) {
  int quick = 0;
  const char* plants = "tomato"; // the tree (13 k bodies) takes MuJoCo minutes to compile
  const char* csv_path = NULL;
  const char* xml_dir = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--selftest")) return selftest();
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--plants") && i + 1 < argc)
      plants = argv[++i];
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
    else if (!strcmp(argv[i], "--xml") && i + 1 < argc)
      xml_dir = argv[++i];
    else {
      fprintf(stderr,
              "usage: verdant_bench_mujoco [--quick] [--plants a,b (data/*.lpy; \"\" none)] "
              "[--csv PATH] [--xml DIR] [--selftest]\n");
      return 2;
    }
  }
  vd_mj_trap_install();
  printf("MuJoCo %s (header %d), Euler integrator, one thread\n", mj_versionString(),
         mjVERSION_HEADER);
  double cal = calibration_ns();
  printf("calibration: %.2f ns per dependent add\n", cal);
  FILE* csv = NULL;
  if (csv_path) {
    csv = fopen(csv_path, "w");
    if (!csv) {
      fprintf(stderr, "cannot write %s\n", csv_path);
      return 1;
    }
    fprintf(csv, "case,variant,N,bodies,dt_s,damping_beta_s,tip_m,discrete_m,continuum_m,"
                 "linear_m,err_continuum,err_discrete,steps_per_s,realtime\n");
    fprintf(csv, "calibration,ns_per_dependent_add,,,,,,,,,,,%.6g,\n", cal);
  }
  beam b = {1.0, 0.005, 1000, 1e10, 9.81, 0.5};
  double EI = beam_EI(&b), q = beam_q(&b);
  double lin[2] = {b.P * pow(b.L, 3) / (3 * EI), q * pow(b.L, 4) / (8 * EI)};
  double cont[2] = {continuum_tip(&b, 0), continuum_tip(&b, 1)};
  printf("\ncantilever L = 1 m, r = 5 mm, rho = 1000 kg/m^3, E = 10 GPa; EI = %.4f N m^2\n", EI);
  printf("continuum: tip load %.2f N: %.3f mm (linear %.3f mm); self-weight: %.3f mm (linear "
         "%.3f mm)\n",
         b.P, 1e3 * cont[0], 1e3 * lin[0], 1e3 * cont[1], 1e3 * lin[1]);

  // 1. statics
  int Ns[] = {5, 10, 20, 40, 80};
  int nN = quick ? 3 : 5;
  printf("\nstatics (settled with damping 0.05 s x stiffness, dt 1 ms)\n");
  printf("%-10s %-8s %5s %12s %12s %10s %10s\n", "case", "root k", "N", "tip (mm)", "exact (mm)",
         "err exact", "err cont.");
  for (int root2 = 0; root2 < 2; root2++)
    for (int sw = 0; sw < 2; sw++)
      for (int k = 0; k < nN; k++) {
        int N = Ns[k];
        statics s = chain_statics(&b, N, root2, sw);
        double ex = discrete_tip(&b, N, root2, sw);
        double ec = (s.tip - cont[sw]) / cont[sw], ed = (s.tip - ex) / ex;
        printf("%-10s %-8s %5d %12.4f %12.4f %10.1e %+9.2f%%%s\n", sw ? "self-wt" : "tip-load",
               root2 ? "2EI/l" : "EI/l", N, 1e3 * s.tip, 1e3 * ex, ed, 100 * ec,
               s.ok ? "" : "  (not settled)");
        if (csv)
          fprintf(csv, "%s,%s,%d,%d,0.001,0.05,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,\n",
                  sw ? "cantilever_selfweight" : "cantilever_tipload",
                  root2 ? "root_2EI_l" : "uniform_EI_l", N, N, s.tip, ex, cont[sw], lin[sw], ec, ed,
                  s.steps_s);
      }

  // 2. dynamics: the largest stable step with light damping, speed there and at 1 ms
  double w1 = 1.8751 * 1.8751 * sqrt(EI / (b.rho * VD_PI * b.r * b.r * pow(b.L, 4)));
  double beta = 2 * 0.02 / w1;
  printf("\ndynamics (light damping %.3g s x stiffness: 2 %% of critical on the first mode, "
         "f1 = %.2f Hz)\n",
         beta, w1 / (2 * VD_PI));
  printf("%5s %12s %14s %10s %14s %10s\n", "N", "largest dt", "steps/s there", "x realtime",
         "steps/s 1 ms*", "x realtime");
  for (int k = 0; k < nN; k++) {
    chain_user u = {&b, Ns[k], 1, beta};
    double dt = largest_stable_dt(chain_make, &u, quick ? 0.2 : 0.5, 0.5);
    double rate = 0, rate1 = 0;
    char msg[1000];
    if (dt > 0) {
      mjModel* M = chain_make(&u, dt, msg, sizeof msg);
      mjData* d = mj_makeData(M);
      rate = steps_per_second(M, d, quick ? 0.2 : 0.5);
      mj_deleteData(d);
      mj_deleteModel(M);
    }
    // 1 ms with heavy damping: stable, for the cost of a step alone
    chain_user h = {&b, Ns[k], 1, 0.05};
    mjModel* M = chain_make(&h, 1e-3, msg, sizeof msg);
    mjData* d = mj_makeData(M);
    rate1 = steps_per_second(M, d, quick ? 0.2 : 0.5);
    mj_deleteData(d);
    mj_deleteModel(M);
    printf("%5d %12.0e %14.0f %10.2f %14.0f %10.1f\n", Ns[k], dt, rate, rate * dt, rate1,
           rate1 * 1e-3);
    if (csv) {
      fprintf(csv, "cantilever_dynamics,light_damping,%d,%d,%g,%.6g,,,,,,,%.6g,%.6g\n", Ns[k],
              Ns[k], dt, beta, rate, rate * dt);
      fprintf(csv, "cantilever_dynamics,heavy_damping,%d,%d,0.001,0.05,,,,,,,%.6g,%.6g\n", Ns[k],
              Ns[k], rate1, rate1 * 1e-3);
    }
  }
  printf("* heavy damping (0.05 s x stiffness) keeps 1 ms stable but overdamps every mode\n");

  // 3. plants
  if (plants[0]) {
    printf("\nplants as body trees (pieces of about 0.02 m, light damping 1e-3 s x stiffness)\n");
    printf("%-8s %9s %7s %7s %12s %14s %10s\n", "plant", "piece (m)", "bodies", "joints",
           "largest dt", "steps/s there", "x realtime");
    char list[256];
    snprintf(list, sizeof list, "%s", plants);
    for (char* name = strtok(list, ","); name; name = strtok(NULL, ",")) {
      char path[4096];
      snprintf(path, sizeof path, "%s/data/%s.lpy", VD_SOURCE_DIR, name);
      vd_model* m = bench_grow(path);
      if (!m) continue;
      char xml_path[4200];
      if (xml_dir) snprintf(xml_path, sizeof xml_path, "%s/%s_chain.xml", xml_dir, name);
      plant_mj P = {m, 0.02, 1e-3, 0, 0, xml_dir ? xml_path : NULL};
      // a large plant steps slowly: a shorter stability check and timing
      int big = m->nseg > 2000;
      double dt = largest_stable_dt(plant_model, &P, big ? 0.01 : 0.3, 0.5);
      double rate = 0;
      char msg[1000];
      mjModel* M = plant_model(&P, dt > 0 ? dt : 1e-3, msg, sizeof msg);
      if (M && dt > 0) {
        mjData* d = mj_makeData(M);
        rate = steps_per_second(M, d, quick || big ? 0.2 : 1.0);
        mj_deleteData(d);
      }
      printf("%-8s %9.4f %7d %7d %12.0e %14.1f %10.4f\n", name, P.piece, P.nbody, P.njoint, dt,
             rate, rate * dt);
      if (csv)
        fprintf(csv, "plant_%s,light_damping_piece_%.4g_m,,%d,%g,0.001,,,,,,,%.6g,%.6g\n", name,
                P.piece, P.nbody, dt, rate, rate * dt);
      mj_deleteModel(M);
      vd_model_destroy(m);
    }
  }
  if (csv) fclose(csv);
  return 0;
}
