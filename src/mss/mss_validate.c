// SPDX-License-Identifier: MIT
// Validation of the mass-spring trees and their rigid part against closed forms
// (docs/validation.md, "Mass-spring trees"): a damped two-mass oscillator (period and decay),
// critical damping at c = 1 for equal masses (eq. 5), a cantilever under its own weight (the
// discrete model's exact sag and the continuum's), the rigid body's torque-free precession and
// RK4's energy drift, eq. 8 printed and corrected, the steady shape of Bastien et al.'s AC model,
// and the default pedotransfer function against its published form.
#include <stdarg.h>
#include <stdio.h>

#include "mss_internal.h"

// ---------------------------------------------------------------------------------------------

typedef struct vx {
  const vd_validate_def* def;
  vd_validate_list list;
  int nomem;
} vx;

static int want(vx* v, const char* name) {
  if (v->def->filter && !strstr(name, v->def->filter)) return 0;
  if (v->def->progress) v->def->progress(v->def->user, name);
  return 1;
}

#define ADD(...)                                                                                  \
  do {                                                                                            \
    if (!vd_validate_add(&v->list, __VA_ARGS__)) v->nomem = 1;                                    \
  } while (0)

// a chain of n internodes of length len and radius r from the origin along dir, age `age`;
// its first node is clamped
static vd_model* chain(int n, double len, double r, vd_vec3 dir, double age) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return NULL;
  vd_plant_set_label(s, 1, "trunk");
  int prev = vd_plant_add_node(s, vd_v3(0, 0, 0)), ps = -1;
  for (int i = 1; i <= n; i++) {
    int nd = vd_plant_add_node(s, vd_scale(dir, len * i / n));
    vd_segment_spec g = vd_segment_spec_default();
    g.node0 = prev, g.node1 = nd, g.r0 = g.r1 = r, g.parent = ps, g.label = 1, g.instance = 1, g.age = age;
    ps = vd_plant_add_segment(s, &g);
    prev = nd;
  }
  vd_model* m = NULL;
  vd_error e = {0};
  vd_plant_compile(s, &m, &e);
  vd_plant_spec_destroy(s);
  return m;
}

typedef struct sys {
  vd_model* p;
  vd_mss_model* m;
  vd_mss_data* d;
} sys;

static void sys_free(sys* x) {
  vd_mss_data_destroy(x->d);
  vd_mss_model_destroy(x->m);
  vd_model_destroy(x->p);
  memset(x, 0, sizeof *x);
}

// two equal free masses on one spring (the clamp lifted): a damped oscillator of reduced mass
// m / 2 and damping c sqrt(2 k m), i.e. zeta = c
static int oscillator(sys* x, double c, vd_mss_integrator integ, double dt) {
  memset(x, 0, sizeof *x);
  vd_mss_def def = vd_mss_def_default();
  def.springs = VD_MSS_PAPER;
  def.damping = c;
  vd_error e = {0};
  x->p = chain(1, 0.2, 0.01, vd_v3(1, 0, 0), 5);
  if (!x->p || vd_mss_build(x->p, &def, NULL, &x->m, &e)) return 0;
  x->m->node_flags[0] &= ~VD_MSS_FIXED;
  x->m->opt.integrator = integ, x->m->opt.dt = dt, x->m->opt.gravity = vd_v3(0, 0, 0);
  x->m->opt.drag = VD_MSS_DRAG_NONE, x->m->opt.strain_limit = 0;
  x->d = vd_mss_data_create(x->m);
  if (!x->d) return 0;
  x->d->mass[0] = x->d->mass[1];
  return 1;
}

static void case_oscillator(vx* v) {
  const char* name = "mss_oscillator";
  if (!want(v, name)) return;
  vd_mss_integrator integ[3] = {VD_MSS_IMPLICIT, VD_MSS_EQ3, VD_MSS_EQ4};
  const char* iname[3] = {"implicit", "eq. 3", "eq. 4"};
  for (int q = 0; q < 3; q++) {
    sys x;
    double c = 0.02;
    if (!oscillator(&x, c, integ[q], 2e-6)) {
      sys_free(&x);
      v->nomem = 1;
      return;
    }
    double k = x.m->spring_k[0], mu = x.d->mass[0] / 2, w0 = sqrt(k / mu), wd = w0 * sqrt(1 - c * c);
    x.d->pos[1].x += 0.001;
    double prev = 0.001, t_up[3] = {0}, peaks[3] = {0}, last = 0.001, last2 = 0.001;
    int nup = 0, np = 0;
    for (int s = 0; s < 2000000 && (nup < 3 || np < 3); s++) {
      vd_mss_step(x.m, x.d);
      double y = x.d->pos[1].x - x.d->pos[0].x - 0.2;
      if (prev < 0 && y >= 0 && nup < 3) t_up[nup++] = x.d->time - x.m->opt.dt * y / (y - prev);
      if (last > last2 && last > y && last > 0 && np < 3) peaks[np++] = last;
      last2 = last, last = y, prev = y;
    }
    // the implicit step adds numerical damping omega h / 2; eqs. 3 and 4 are explicit in it
    double zn = integ[q] == VD_MSS_IMPLICIT ? w0 * x.m->opt.dt / 2 : 0;
    double ratio_ref = exp(-2 * VD_PI * (c + zn) / sqrt(1 - c * c));
    ADD(name, "continuum", "period (s)", nup == 3 ? t_up[2] - t_up[1] : NAN, 2 * VD_PI / wd, 0.002, 0,
        "%s, two equal masses on a spring, zeta = c = %.2f, h = %.0e s: 2 pi / omega_d", iname[q], c, x.m->opt.dt);
    ADD(name, "continuum", "amplitude ratio per period", np == 3 ? peaks[2] / peaks[1] : NAN, ratio_ref, 0.01, 1,
        "%s: exp(-2 pi (zeta + zeta_num) / sqrt(1 - zeta^2)), zeta_num = omega h / 2 for implicit", iname[q]);
    sys_free(&x);
  }
}

static void case_critical(vx* v) {
  const char* name = "mss_critical_damping";
  if (!want(v, name)) return;
  // c = 1 is critical for equal masses: a stretched spring comes back without overshoot; c = 0.9
  // overshoots (eq. 5: c sqrt(k (m1 + m2)) = 2 sqrt(k mu) for m1 = m2)
  double over[2];
  for (int pass = 0; pass < 2; pass++) {
    sys x;
    if (!oscillator(&x, pass ? 0.9 : 1.0, VD_MSS_IMPLICIT, 1e-5)) {
      sys_free(&x);
      v->nomem = 1;
      return;
    }
    x.d->pos[1].x += 0.001;
    double lo = 0;
    for (int k = 0; k < 20000; k++) {
      vd_mss_step(x.m, x.d);
      lo = fmin(lo, x.d->pos[1].x - x.d->pos[0].x - 0.2);
    }
    over[pass] = -lo / 0.001;
    sys_free(&x);
  }
  ADD(name, "continuum", "overshoot / initial stretch, c = 1", over[0], 0, 1e-9, 1,
      "two equal masses: c = 1 is critical (zeta = c (m1 + m2) / (2 sqrt(m1 m2)) = 1), h = 1e-5 s");
  // a slightly underdamped spring overshoots by exp(-pi zeta / sqrt(1 - zeta^2)) (0.0015 at 0.9)
  ADD(name, "continuum", "overshoot / initial stretch, c = 0.9", over[1], exp(-VD_PI * 0.9 / sqrt(1 - 0.81)), 0.1, 0,
      "underdamped at zeta = 0.9: exp(-pi zeta / sqrt(1 - zeta^2)), implicit damping of h included in the tolerance");
}

static void case_cantilever(vx* v) {
  const char* name = "mss_cantilever_self_weight";
  if (!want(v, name)) return;
  int n = v->def->full ? 40 : 10;
  double r = 0.005, e = 1e10, len = 1.0, l = len / n, rho = 1000;
  double ei = e * VD_PI * r * r * r * r / 4, w = rho * VD_PI * r * r * l * 9.81, q = rho * VD_PI * r * r * 9.81;
  sys x;
  memset(&x, 0, sizeof x);
  vd_mss_def def = vd_mss_def_default();
  def.density_wood = rho, def.young_wood = e;
  vd_error er = {0};
  x.p = chain(n, len, r, vd_v3(1, 0, 0), 5);
  if (!x.p || vd_mss_build(x.p, &def, NULL, &x.m, &er) || !(x.d = vd_mss_data_create(x.m))) {
    sys_free(&x);
    v->nomem = 1;
    return;
  }
  x.m->opt.drag = VD_MSS_DRAG_NONE;
  for (int k = 0; k < 600; k++) vd_mss_step(x.m, x.d);
  double sag = -x.d->pos[x.m->main_tip].z;
  vd_mss_stress(x.m, x.d);
  double s0 = x.d->spring_stress[0];
  // the discrete model: hinges k_i = E I / l-bar (l / 2 at the clamp), each node carrying its
  // internode's weight; small-angle sag sum_i M_i / k_i (L - x_i)
  double ref = 0;
  for (int i = 0; i < n; i++) {
    double mi = 0;
    for (int j = i + 1; j <= n; j++) mi += w * (j - i) * l;
    ref += mi / (ei / (i == 0 ? l / 2 : l)) * (len - i * l);
  }
  ADD(name, "discrete", "tip sag (m)", sag, ref, 0.005, 0, "material springs, N = %d, implicit, 600 substeps of 10 ms", n);
  ADD(name, "continuum", "tip sag (m)", sag, q * len * len * len * len / (8 * ei), 2.5 / n, 0,
      "q L^4 / (8 E I), lumping biases it by about 1/N (N = %d)", n);
  double m0 = w * l * n * (n + 1) / 2.0;
  ADD(name, "discrete", "clamp stress (Pa)", s0, 4 * m0 / (VD_PI * r * r * r), 0.005, 0,
      "stress by sections: 4 M / (pi r^3), M = w l n (n + 1) / 2 of the nodes' weights");
  sys_free(&x);
}

// a free symmetric top: the body-frame angular velocity precesses about the symmetry axis at
// (I3 - I1) / I1 omega3
static void case_precession(vx* v) {
  const char* name = "rigid_precession";
  if (!want(v, name)) return;
  vd_rigid b;
  memset(&b, 0, sizeof b);
  b.n = 1, b.mass = 1, b.q = vd_quat_identity();
  double i1 = 1, i3 = 2;
  b.ibody[0] = i1, b.ibody[4] = i1, b.ibody[8] = i3;
  b.ibody_inv[0] = 1 / i1, b.ibody_inv[4] = 1 / i1, b.ibody_inv[8] = 1 / i3;
  vd_vec3 w0 = vd_v3(0.3, 0, 2.0);
  b.L = vd_v3(i1 * w0.x, i1 * w0.y, i3 * w0.z);
  double h = 1e-3, angle = 0, prev = 0;
  int steps = 5000;
  for (int k = 0; k < steps; k++) {
    vd_rigid_step(&b, vd_v3(0, 0, 0), vd_v3(0, 0, 0), h);
    vd_vec3 lb = vd_quat_rotate(vd_quat_conj(b.q), b.L);  // L in the body frame
    double a = atan2(lb.y / i1, lb.x / i1);
    double da = a - prev;
    while (da > VD_PI) da -= 2 * VD_PI;
    while (da < -VD_PI) da += 2 * VD_PI;
    angle += da, prev = a;
  }
  // Euler's equations: the body-frame omega turns about e3 at (I3 - I1) / I1 omega3
  double rate = angle / (steps * h);
  ADD(name, "continuum", "precession rate (rad/s)", rate, (i3 - i1) / i1 * w0.z, 1e-6, 0,
      "torque-free symmetric top I = (1, 1, 2) kg m^2, omega = (0.3, 0, 2) rad/s, RK4, h = 1 ms, 5 s");
}

// kinetic energy drift of a free asymmetric body over 10 s at h and h / 2: RK4 is fourth order
static double drift(double h) {
  vd_rigid b;
  memset(&b, 0, sizeof b);
  b.n = 1, b.mass = 1, b.q = vd_quat_identity();
  double in[3] = {1, 2, 3};
  for (int k = 0; k < 3; k++) b.ibody[4 * k] = in[k], b.ibody_inv[4 * k] = 1 / in[k];
  b.L = vd_v3(1 * 1.0, 2 * 0.1, 3 * 0.5);
  double e0 = vd_rigid_energy(&b);
  int n = (int)floor(10 / h + 0.5);
  for (int k = 0; k < n; k++) vd_rigid_step(&b, vd_v3(0, 0, 0), vd_v3(0, 0, 0), h);
  return fabs(vd_rigid_energy(&b) - e0) / e0;
}

static void case_rk4(vx* v) {
  const char* name = "rigid_rk4_energy";
  if (!want(v, name)) return;
  double d1 = drift(0.02), d2 = drift(0.01);
  ADD(name, "discrete", "order of the energy drift", log(d1 / d2) / log(2), 4, 0.5, 1,
      "free body I = (1, 2, 3) kg m^2, 10 s at h = 20 and 10 ms: drift %.2e and %.2e", d1, d2);
  ADD(name, "discrete", "relative energy drift, h = 10 ms", d2, 0, 1e-6, 1, "RK4 with a renormalised quaternion, 10 s");
}

// eq. 8 printed against corrected: a spinning body of three nodes takes a fourth
static void case_eq8(vx* v) {
  const char* name = "rigid_eq8";
  if (!want(v, name)) return;
  double lc[2][6] = {{0}};
  double spin = 0;
  for (int paper = 0; paper < 2; paper++) {
    sys x;
    memset(&x, 0, sizeof x);
    vd_mss_def def = vd_mss_def_default();
    vd_error er = {0};
    x.p = chain(4, 1.0, 0.02, vd_v3(0, 0, 1), 5);
    if (!x.p || vd_mss_build(x.p, &def, NULL, &x.m, &er) || !(x.d = vd_mss_data_create(x.m))) {
      sys_free(&x);
      v->nomem = 1;
      return;
    }
    // nodes 0..2 spin about z through (0.1, 0, 0) and drift; node 3 joins with its own velocity
    unsigned char join[5] = {1, 1, 1, 0, 0};
    vd_vec3 w = vd_v3(0.2, 0.5, 1.0), c = vd_v3(0.1, 0, 0);
    for (int i = 0; i < 3; i++) x.d->vel[i] = vd_add(vd_v3(0.05, 0, 0), vd_cross(w, vd_sub(x.d->pos[i], c)));
    x.d->vel[3] = vd_v3(0, 0.3, 0);
    vd_mss_rigid_join(x.m, x.d, join, 0, NULL);
    // the old body's own angular momentum about its centre (its points; what the printed eq. 8
    // counts twice)
    vd_vec3 lo = vd_v3(0, 0, 0);
    for (int i = 0; i < 3; i++)
      lo = vd_add(lo, vd_cross(vd_sub(x.d->pos[i], x.d->rb.x), vd_scale(x.d->vel[i], x.d->mass[i])));
    spin = vd_norm(lo);
    unsigned char j2[5] = {0, 0, 0, 1, 0};
    vd_mss_rigid_join(x.m, x.d, j2, paper, lc[paper]);
    sys_free(&x);
  }
  double lt = sqrt(lc[0][0] * lc[0][0] + lc[0][1] * lc[0][1] + lc[0][2] * lc[0][2]);
  double e_cor = sqrt(pow(lc[0][3] - lc[0][0], 2) + pow(lc[0][4] - lc[0][1], 2) + pow(lc[0][5] - lc[0][2], 2)) / lt;
  double e_pap = sqrt(pow(lc[1][3] - lc[1][0], 2) + pow(lc[1][4] - lc[1][1], 2) + pow(lc[1][5] - lc[1][2], 2));
  ADD(name, "discrete", "|L - L_true| / |L_true|, corrected", e_cor, 0, 1e-12, 1,
      "L^t + (x - x') x p^t + sum_j (x_j - x') x m_j v_j: the union's angular momentum");
  ADD(name, "discrete", "|L - L_true| (kg m^2/s), printed", e_pap, spin, 1e-6, 0,
      "eq. 8 as printed adds the old body's own angular momentum (about its centre) once more");
}

// the AC model's steady shape: a horizontal axis bends up to tip angle 2 atan(tan(A0/2) e^-B)
static void case_bastien(vx* v) {
  const char* name = "bastien_steady_shape";
  if (!want(v, name)) return;
  int n = v->def->full ? 400 : 100;
  double bvals[2] = {1, 3};
  for (int k = 0; k < 2; k++) {
    sys x;
    memset(&x, 0, sizeof x);
    vd_mss_def def = vd_mss_def_default();
    vd_error er = {0};
    x.p = chain(n, 1.0, 0.005, vd_v3(1, 0, 0), 0);
    if (!x.p || vd_mss_build(x.p, &def, NULL, &x.m, &er) || !(x.d = vd_mss_data_create(x.m))) {
      sys_free(&x);
      v->nomem = 1;
      return;
    }
    x.m->opt.bastien_beta = bvals[k], x.m->opt.bastien_gamma = 1, x.m->opt.growth_zone_age = 1;
    vd_vec3* rest = vd_malloc(sizeof(vd_vec3) * (size_t)x.m->nnode);
    if (!rest) {
      sys_free(&x);
      v->nomem = 1;
      return;
    }
    vd_mss_bastien(x.m, x.d, 30, 3000, rest);
    int t = x.m->main_tip, p = x.m->node_parent[t];
    vd_vec3 e = vd_normalize(vd_sub(rest[t], rest[p]));
    double tip = acos(fmax(-1.0, fmin(1.0, e.z))) * 180 / VD_PI;
    double ref = 2 * atan(tan(VD_PI / 4) * exp(-bvals[k])) * 180 / VD_PI;
    ADD(name, "continuum", "tip angle to the vertical (deg)", tip, ref, 1.5 * 90.0 / n + 0.05, 1,
        "Bastien et al. 2013 AC model, horizontal start, B = beta L / gamma = %.0f, N = %d hinges, 30 time units",
        bvals[k], n);
    vd_free(rest, sizeof(vd_vec3) * (size_t)x.m->nnode);
    sys_free(&x);
  }
}

// the default pedotransfer function against the same-form function it implements
static void case_soil(vx* v) {
  const char* name = "soil_ptf";
  if (!want(v, name)) return;
  vd_soil s;
  vd_soil_preset("loam", &s);
  s.clay = 20, s.organic = 2 * 1.72, s.water = 0.25, s.bulk_density = 1.2;
  double sr = vd_soil_max_force(&s, 0.1, 0.01, 1e-6);  // 1e-6 m^2: F (N) = SR (MPa)
  double ref = exp(-3.6733 - 0.1447 * 20 + 0.7653 * 2 + (-0.4805 - 0.1239 * 20 + 0.208 * 2) * log(0.25) +
                   (3.8521 + 0.0963 * 20) * log(1.2));
  ADD(name, "discrete", "soil resistance SR (MPa)", sr, ref, 1e-12, 0,
      "da Silva & Kay 1997 (soilphysics llwrPTF) at clay 20 %%, OC 2 %%, theta 0.25, BD 1.2: about 0.63 MPa");
  s.method = VD_SOIL_PANG2023;
  double f = vd_soil_max_force(&s, 0.3, 0.01, 0);
  double g = 1200, bb = pow(g / 1000, 12) * cbrt(0.5 - s.poisson) / 2.8;
  double fr = sqrt(s.residual_pressure / 10000 * g * 9.8 / 1e6 * 2.0 / 3.0 * VD_PI * 1e-6) * 0.3 * 100 * bb;
  ADD(name, "discrete", "Pang et al. eq. 12 force (N)", f, fr, 1e-12, 0,
      "gamma 1200 kg/m^3, mu %.2f, P_a %.0f Pa, r 0.01 m, h 0.3 m (SI: the seed gives no units)", s.poisson,
      s.residual_pressure);
}

vd_status vd_mss_validate(const vd_validate_def* def, vd_validate_result** out, int* n, vd_error* err) {
  vx v;
  memset(&v, 0, sizeof v);
  v.def = def;
  void (*cases[])(vx*) = {case_oscillator, case_critical, case_cantilever, case_precession,
                          case_rk4,        case_eq8,      case_bastien,    case_soil};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0] && !v.nomem; k++) cases[k](&v);
  if (v.nomem) {
    vd_free(v.list.r, (size_t)v.list.cap * sizeof(vd_validate_result));
    *out = NULL;
    *n = 0;
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
  return vd_validate_finish(&v.list, out, n, err);
}
