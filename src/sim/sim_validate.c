// SPDX-License-Identifier: MIT
// Validation against analytic references (anchors-physics.md section 4; docs/validation.md).
// Every static case is checked twice: against the exact solution of the discrete model (a
// separate reduced-coordinate solver: joint angles as unknowns, forces from statics), with a
// tight tolerance, and against the continuum formula, with a tolerance that knows the
// discretisation error (second order in 1/N for loads without an end moment, first order in
// 1/N with one). Dynamic cases compare with the discrete eigenvalue seen through implicit
// Euler, and with the continuum frequency.
#include <stdarg.h>
#include <stdio.h>

#include "sim_internal.h"

// ---------------------------------------------------------------------------------------------
// result list

typedef struct vctx {
  const vd_validate_def* def;
  vd_validate_result* r;
  int n, cap;
  vd_status st;
  vd_error* err;
} vctx;

static vd_validate_result* push(vctx* v, const char* name, const char* form, const char* qty) {
  if (v->st) return NULL;
  if (!vd_grow((void**)&v->r, &v->cap, v->n + 1, sizeof(vd_validate_result))) {
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return NULL;
  }
  vd_validate_result* r = &v->r[v->n++];
  memset(r, 0, sizeof *r);
  snprintf(r->name, sizeof r->name, "%s", name);
  snprintf(r->form, sizeof r->form, "%s", form);
  snprintf(r->quantity, sizeof r->quantity, "%s", qty);
  return r;
}

// relative error check (absolute when reference is 0 or abs_err is set)
static void check(vctx* v, const char* name, const char* form, const char* qty, double meas, double ref,
                  double tol, int abs_err, const char* fmt, ...) __attribute__((format(printf, 9, 10)));
static void check(vctx* v, const char* name, const char* form, const char* qty, double meas, double ref,
                  double tol, int abs_err, const char* fmt, ...) {
  if (v->st) return;
  vd_validate_list l = {v->r, v->n, v->cap};
  va_list ap;
  va_start(ap, fmt);
  int ok = vd_validate_addv(&l, name, form, qty, meas, ref, tol, abs_err, fmt, ap);
  va_end(ap);
  v->r = l.r, v->n = l.n, v->cap = l.cap;
  if (!ok) v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
}

// a control: a case that means something only if the measured value reaches a minimum (a run
// without the feature must show the effect); the table prints the measured value, the minimum as
// the reference and how far below it the value fell as the error (tolerance 0)
static void check_at_least(vctx* v, const char* name, const char* form, const char* qty, double meas, double minimum,
                           const char* note) {
  vd_validate_result* r = push(v, name, form, qty);
  if (!r) return;
  r->measured = meas;
  r->reference = minimum;
  r->error = meas >= minimum ? 0 : minimum - meas;
  r->tolerance = 0;
  r->pass = isfinite(meas) && meas >= minimum;
  snprintf(r->note, sizeof r->note, "%s", note);
}

static int want(const vctx* v, const char* name) {
  return !v->def->filter || strstr(name, v->def->filter) != NULL;
}

static void progress(const vctx* v, const char* name) {
  if (v->def->progress) v->def->progress(v->def->user, name);
}

// ---------------------------------------------------------------------------------------------
// test rods: a clamped segment of length l behind the origin, then a straight rod of N
// segments of length L along dir; optionally a sphere of mass mt centred on the tip

typedef struct rod {
  int n;           // free segments
  double len;      // free length L (m)
  double r;        // radius (m)
  double e, nu, rho;
  vd_vec3 dir;     // axis (unit)
  double tip_mass; // kg, 0 for none
} rod;

typedef struct built {
  vd_model* pm;
  vd_sim_model* m;
  vd_sim_data* d;
} built;

static void built_free(built* b) {
  vd_sim_data_destroy(b->d);
  vd_sim_model_destroy(b->m);
  vd_model_destroy(b->pm);
  memset(b, 0, sizeof *b);
}

static vd_status build_rod(const rod* rd, built* out, vd_error* err) {
  memset(out, 0, sizeof *out);
  double l = rd->len / rd->n;
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  vd_vec3 up = fabs(rd->dir.z) < 0.9 ? vd_v3(0, 0, 1) : vd_v3(1, 0, 0);
  int a = vd_plant_add_node(s, vd_scale(rd->dir, -l));
  int b = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(s, vd_scale(rd->dir, rd->len));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = rd->r, g.label = 1, g.instance = 1, g.up = up;
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  vd_plant_add_segment(s, &g);
  vd_status st = vd_plant_set_label(s, 1, "stem");
  double rs = 0;
  if (!st && rd->tip_mass > 0) {
    vd_sphere_spec f = vd_sphere_spec_default();
    rs = 0.01;
    f.center = vd_scale(rd->dir, rd->len), f.radius = rs, f.node = c, f.parent = 1, f.label = 2, f.instance = 3;
    vd_plant_add_sphere(s, &f);
    st = vd_plant_set_label(s, 2, "fruit");
  }
  if (!st) st = vd_plant_compile(s, &out->pm, err);
  vd_plant_spec_destroy(s);
  if (st) return st;
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = l;
  def.clamp_length = l;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) {
    def.material[k].young = rd->e, def.material[k].poisson = rd->nu, def.material[k].density = rd->rho;
    def.material[k].break_force = def.material[k].break_moment = INFINITY;
  }
  if (rd->tip_mass > 0) def.material[VD_SIM_FRUIT].density = rd->tip_mass / (4.0 / 3.0 * VD_PI * rs * rs * rs);
  st = vd_sim_build(out->pm, &def, &out->m, err);
  if (st) {
    built_free(out);
    return st;
  }
  out->m->opt.drag = 0;
  out->m->opt.gravity = vd_v3(0, 0, 0);
  out->m->opt.contacts = 0;
  out->d = vd_sim_data_create(out->m);
  if (!out->d) {
    built_free(out);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
  return VD_OK;
}

// static equilibrium by the direct solver; 0 if it did not converge
static int statics(const vd_sim_model* m, vd_sim_data* d, double tol) {
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.statics = 1;
  s.disp_tol = tol;
  s.max_steps = 3000;
  int ok = 0;
  vd_sim_settle(m, d, &s, &ok, NULL);
  return ok;
}

// the tip node of a rod (end of the free part)
static int tip_node(const built* b) { return b->m->main_tip; }  // NOLINT(clang-analyzer-core.NullDereference): built rods always hold a model

// node k (0 = clamp end, n = tip) of a test rod, by position along the axis
static double rod_ei(const rod* rd) { return rd->e * VD_PI * pow(rd->r, 4) / 4; }
static double rod_g(const rod* rd) { return rd->e / (2 * (1 + rd->nu)); }
static double rod_kappa(const rod* rd) { return 6 * (1 + rd->nu) / (7 + 6 * rd->nu); }
static double rod_area(const rod* rd) { return VD_PI * rd->r * rd->r; }

// ---------------------------------------------------------------------------------------------
// discrete reference: planar chain in reduced coordinates. Segment i (1..n) has direction
// angle phi_i (phi_0 = 0, the clamp); joint j sits between segments j-1 and j with
// flexibility flex[j-1] and elastic moment theta / flex with theta = phi_j - phi_{j-1} (the log
// bend-twist measure; sin(theta) / flex with the quat measure). With dead loads the segment
// forces follow from statics, F_i = -sum_{k>=i} f_k, the segment vectors are
// e_i = l ((1 + G_ax) t_i + G_sh n_i) with G = -R^T F / (EA, kGA), and joint j balances
//   theta_j / flex_j = M - sum_{i>=j} e_i x F_i.
// Newton on the angles with a finite-difference Jacobian, loads ramped in steps.

typedef struct planar {
  int n;
  double l, kax, ksh;
  const double* flex;  // n joint flexibilities (rad / N m)
  const double* f;     // n nodal loads (x, y) (n x 2)
  double moment;       // end moment (N m), counter-clockwise
  int quat;            // 1: joint moment sin(theta) / flex (quat measure), else theta / flex
} planar;

// 1 when the validation builds (vd_sim_def_default) use the quat bend-twist measure
static int quat_measure(void) { return vd_sim_def_default().bend_measure == VD_SIM_BEND_QUAT; }

static void planar_geom(const planar* p, const double* phi, double scale, double* x, double* fseg) {
  int n = p->n;
  // segment forces from the tip
  double fx = 0, fy = 0;
  for (int i = n - 1; i >= 0; i--) {
    fx -= scale * p->f[2 * i], fy -= scale * p->f[2 * i + 1];
    fseg[2 * i] = fx, fseg[2 * i + 1] = fy;
  }
  x[0] = x[1] = 0;
  for (int i = 0; i < n; i++) {
    double c = cos(phi[i]), s = sin(phi[i]);
    double ft = fseg[2 * i] * c + fseg[2 * i + 1] * s, fn = -fseg[2 * i] * s + fseg[2 * i + 1] * c;
    double gax = -ft / p->kax, gsh = -fn / p->ksh;
    x[2 * (i + 1)] = x[2 * i] + p->l * ((1 + gax) * c - gsh * s);
    x[2 * (i + 1) + 1] = x[2 * i + 1] + p->l * ((1 + gax) * s + gsh * c);
  }
}

static void planar_residual(const planar* p, const double* phi, double scale, double* res, double* x, double* fs) {
  int n = p->n;
  planar_geom(p, phi, scale, x, fs);
  // sum_{i>=j} e_i x F_i from the tip
  double acc = 0;
  for (int j = n - 1; j >= 0; j--) {
    double ex = x[2 * (j + 1)] - x[2 * j], ey = x[2 * (j + 1) + 1] - x[2 * j + 1];
    acc += ex * fs[2 * j + 1] - ey * fs[2 * j];
    double th = phi[j] - (j ? phi[j - 1] : 0.0);
    res[j] = (p->quat ? sin(th) : th) / p->flex[j] - scale * p->moment + acc;
  }
}

// solve; phi (n) in/out, x gets the n+1 node positions (2 each). Returns 0 on failure.
static int planar_solve(const planar* p, double* phi, double* x, int ramps) {
  int n = p->n;
  size_t sz = (size_t)n * sizeof(double);
  double* res = vd_malloc(sz);
  double* r2 = vd_malloc(sz);
  double* jac = vd_malloc(sz * (size_t)n);
  double* fs = vd_malloc(2 * sz);
  double* xs = vd_malloc(2 * sz + 2 * sizeof(double));
  double* dphi = vd_malloc(sz);
  int ok = res && r2 && jac && fs && xs && dphi;
  for (int rs = 1; ok && rs <= ramps; rs++) {
    double scale = (double)rs / ramps;
    int conv = 0;
    for (int it = 0; it < 100 && !conv; it++) {
      planar_residual(p, phi, scale, res, xs, fs);
      double nr = 0;
      for (int j = 0; j < n; j++) nr += res[j] * res[j] * p->flex[j] * p->flex[j];
      if (sqrt(nr) < 1e-15) {
        conv = 1;
        break;
      }
      // Jacobian by central differences
      for (int k = 0; k < n; k++) {
        double h = 1e-7, save = phi[k];
        phi[k] = save + h;
        planar_residual(p, phi, scale, r2, xs, fs);
        for (int j = 0; j < n; j++) jac[j * n + k] = r2[j];
        phi[k] = save - h;
        planar_residual(p, phi, scale, r2, xs, fs);
        for (int j = 0; j < n; j++) jac[j * n + k] = (jac[j * n + k] - r2[j]) / (2 * h);
        phi[k] = save;
      }
      // Gaussian elimination with partial pivoting: jac dphi = -res
      for (int j = 0; j < n; j++) dphi[j] = -res[j];
      for (int c = 0; c < n && ok; c++) {
        int piv = c;
        for (int i = c + 1; i < n; i++)
          if (fabs(jac[i * n + c]) > fabs(jac[piv * n + c])) piv = i;
        if (fabs(jac[piv * n + c]) < 1e-300) ok = 0;
        if (!ok) break;
        if (piv != c) {
          for (int k = 0; k < n; k++) {
            double t = jac[c * n + k];
            jac[c * n + k] = jac[piv * n + k];
            jac[piv * n + k] = t;
          }
          double t = dphi[c];
          dphi[c] = dphi[piv];
          dphi[piv] = t;
        }
        for (int i = c + 1; i < n; i++) {
          double f = jac[i * n + c] / jac[c * n + c];
          if (f == 0) continue;
          for (int k = c; k < n; k++) jac[i * n + k] -= f * jac[c * n + k];
          dphi[i] -= f * dphi[c];
        }
      }
      for (int c = n - 1; ok && c >= 0; c--) {
        double s = dphi[c];
        for (int k = c + 1; k < n; k++) s -= jac[c * n + k] * dphi[k];
        dphi[c] = s / jac[c * n + c];
      }
      if (!ok) break;
      // damped step: halve until the residual shrinks
      double step = 1;
      for (int ls = 0; ls < 30; ls++) {
        for (int j = 0; j < n; j++) r2[j] = phi[j] + step * dphi[j];
        planar_residual(p, r2, scale, res, xs, fs);
        double nn = 0;
        for (int j = 0; j < n; j++) nn += res[j] * res[j] * p->flex[j] * p->flex[j];
        if (nn < nr || ls == 29) break;
        step *= 0.5;
      }
      for (int j = 0; j < n; j++) phi[j] += step * dphi[j];
    }
    if (!conv) {
      // accept a tiny residual that stalled at round-off
      planar_residual(p, phi, scale, res, xs, fs);
      double nr = 0;
      for (int j = 0; j < n; j++) nr = fmax(nr, fabs(res[j] * p->flex[j]));
      if (nr > 1e-10) ok = 0;
    }
  }
  if (ok) planar_geom(p, phi, 1.0, x, fs);
  vd_free(res, sz);
  vd_free(r2, sz);
  vd_free(jac, sz * (size_t)n);
  vd_free(fs, 2 * sz);
  vd_free(xs, 2 * sz + 2 * sizeof(double));
  vd_free(dphi, sz);
  return ok;
}

// joint flexibilities of a uniform test rod: the clamp joint sees half a segment
static void rod_flex(const rod* rd, double* flex, int twist) {
  double l = rd->len / rd->n, k = twist ? rod_g(rd) * 2 * rod_ei(rd) / rd->e : rod_ei(rd);
  for (int j = 0; j < rd->n; j++) flex[j] = (j ? l : 0.5 * l) / k;
}

// nodal masses of a uniform test rod as the model lumps them (half of each segment)
static double rod_node_mass(const rod* rd, int k) {
  double ms = rd->rho * rod_area(rd) * rd->len / rd->n;
  return (k == rd->n ? 0.5 * ms : ms) + (k == rd->n ? rd->tip_mass : 0.0);
}

// ---------------------------------------------------------------------------------------------
// continuum references

// Euler elastica of a cantilever with a dead vertical tip load, alpha = P L^2 / EI:
// theta'' = -alpha cos(theta), theta(0) = 0, theta'(1) = 0; returns tip drop v/L and
// shortening u/L (Bisshopp & Drucker 1945), by shooting with RK4.
static void elastica_tip(double alpha, double* v, double* u) {
  double lo = 0, hi = alpha * 1.0000001;
  int ns = 4000;
  for (int it = 0; it < 200; it++) {
    double k0 = 0.5 * (lo + hi), th = 0, om = k0, hs = 1.0 / ns, sx = 0, sy = 0;
    for (int i = 0; i < ns; i++) {
      // RK4 on (theta, omega, x, y)
      double k1t = om, k1o = -alpha * cos(th);
      double k2t = om + 0.5 * hs * k1o, k2o = -alpha * cos(th + 0.5 * hs * k1t);
      double k3t = om + 0.5 * hs * k2o, k3o = -alpha * cos(th + 0.5 * hs * k2t);
      double k4t = om + hs * k3o, k4o = -alpha * cos(th + hs * k3t);
      double c1 = cos(th), s1 = sin(th);
      double c2 = cos(th + 0.5 * hs * k1t), s2 = sin(th + 0.5 * hs * k1t);
      double c3 = cos(th + 0.5 * hs * k2t), s3 = sin(th + 0.5 * hs * k2t);
      double c4 = cos(th + hs * k3t), s4 = sin(th + hs * k3t);
      sx += hs / 6 * (c1 + 2 * c2 + 2 * c3 + c4);
      sy += hs / 6 * (s1 + 2 * s2 + 2 * s3 + s4);
      th += hs / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
      om += hs / 6 * (k1o + 2 * k2o + 2 * k3o + k4o);
    }
    if (om > 0) hi = k0; else lo = k0;
    *v = sy, *u = 1 - sx;
  }
}

// post-buckled cantilever column (dead axial tip load, p = P L^2 / EI > pi^2 / 4):
// theta'' = -p sin(theta), theta(0) = 0, theta'(1) = 0; returns the tip deflection / L
static double elastica_column(double p, double* theta, int nth) {
  double lo = 1e-9, hi = 2 * sqrt(p);
  int ns = 4000;
  double y = 0;
  for (int it = 0; it < 200; it++) {
    double k0 = 0.5 * (lo + hi), th = 0, om = k0, hs = 1.0 / ns, sy = 0;
    for (int i = 0; i < ns; i++) {
      double k1t = om, k1o = -p * sin(th);
      double k2t = om + 0.5 * hs * k1o, k2o = -p * sin(th + 0.5 * hs * k1t);
      double k3t = om + 0.5 * hs * k2o, k3o = -p * sin(th + 0.5 * hs * k2t);
      double k4t = om + hs * k3o, k4o = -p * sin(th + hs * k3t);
      sy += hs / 6 * (sin(th) + 2 * sin(th + 0.5 * hs * k1t) + 2 * sin(th + 0.5 * hs * k2t) + sin(th + hs * k3t));
      // sample theta at the middle of each of nth segments
      if (theta && nth > 0) {
        int seg = (int)((double)i * nth / ns);
        if (i == (int)((seg + 0.5) * ns / nth)) theta[seg] = th;
      }
      th += hs / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
      om += hs / 6 * (k1o + 2 * k2o + 2 * k3o + k4o);
    }
    if (om < 0) lo = k0; else hi = k0;
    y = sy;
  }
  return y;
}

// ---------------------------------------------------------------------------------------------
// helpers for the static cantilever cases

typedef struct planar_ref {
  double tip[2];  // tip position (x, z) of the discrete reference (m)
  int ok;
} planar_ref;

// discrete reference of a test rod along +x under nodal loads (x, z) and an end moment
// (counter-clockwise in the x-z plane, i.e. about -y)
static planar_ref rod_reference(const rod* rd, const double* loads, double moment, double* phi_out,
                                const double* guess) {
  planar_ref pr = {{0, 0}, 0};
  int n = rd->n;
  double* flex = vd_malloc((size_t)n * sizeof(double));
  double* phi = vd_calloc((size_t)n, sizeof(double));
  if (phi && guess) memcpy(phi, guess, (size_t)n * sizeof(double));
  double* x = vd_malloc((size_t)(n + 1) * 2 * sizeof(double));
  if (flex && phi && x) {
    rod_flex(rd, flex, 0);
    planar p = {n, rd->len / n, rd->e * rod_area(rd), rod_kappa(rd) * rod_g(rd) * rod_area(rd), flex, loads, moment,
                quat_measure()};
    pr.ok = planar_solve(&p, phi, x, guess ? 1 : 20);
    pr.tip[0] = x[2 * n], pr.tip[1] = x[2 * n + 1];
    if (phi_out) memcpy(phi_out, phi, (size_t)n * sizeof(double));
  }
  vd_free(flex, (size_t)n * sizeof(double));
  vd_free(phi, (size_t)n * sizeof(double));
  vd_free(x, (size_t)(n + 1) * 2 * sizeof(double));
  return pr;
}

// statics of a built rod with loads ramped in steps (large deflections); tip node position
static vd_vec3 rod_statics(built* b, vd_vec3 tip_force, vd_vec3 tip_torque, int gravity, double rho_g, int ramps,
                           int* ok) {
  int tip = tip_node(b), ts = b->m->node_owner[tip];
  *ok = 1;
  for (int k = 1; k <= ramps; k++) {
    double s = (double)k / ramps;
    b->d->node_force[tip] = vd_scale(tip_force, s);
    b->d->seg_torque[ts] = vd_scale(tip_torque, s);
    if (gravity) b->m->opt.gravity = vd_v3(0, 0, -rho_g * s);
    *ok &= statics(b->m, b->d, 1e-12);
  }
  return b->d->node_pos[tip];
}

static double* alloc_loads(int n) { return vd_calloc((size_t)n * 2, sizeof(double)); }
static void free_loads(double* f, int n) { vd_free(f, (size_t)n * 2 * sizeof(double)); }

// ---------------------------------------------------------------------------------------------
// cases

static void case_tip_load(vctx* v) {
  const char* nm = "cantilever_tip_load";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 20;
  rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {1, 0, 0}, 0};
  double ei = rod_ei(&rd), p = 1e-3 * ei / (rd.len * rd.len);
  built b;
  if ((v->st = build_rod(&rd, &b, v->err))) return;
  int ok;
  vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, -p), vd_v3(0, 0, 0), 0, 0, 1, &ok);
  double* f = alloc_loads(n);
  if (!f) {
    built_free(&b);
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return;
  }
  f[2 * (n - 1) + 1] = -p;
  planar_ref pr = rod_reference(&rd, f, 0, NULL, NULL);
  free_loads(f, n);
  double meas = -tip.z;
  check(v, nm, "discrete", "tip deflection (m)", meas, -pr.tip[1], 1e-6, 0,
        "N = %d, PL^2/EI = 1e-3; exact solution of the discrete model (reduced coordinates)%s", n,
        ok && pr.ok ? "" : " [not converged]");
  double kga = rod_kappa(&rd) * rod_g(&rd) * rod_area(&rd);
  double cont = p * pow(rd.len, 3) / (3 * ei) + p * rd.len / kga;
  check(v, nm, "continuum", "tip deflection (m)", meas, cont, 1.0 / (n * n), 0,
        "PL^3/3EI + PL/(kappa G A) (Timoshenko); tolerance 1/N^2, second-order discretisation");
  built_free(&b);
}

static void case_self_weight(vctx* v) {
  const char* nm = "cantilever_self_weight";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 20;
  rod rd = {n, 1.0, 0.005, 1e10, 0.3, 50, {1, 0, 0}, 0};
  double ei = rod_ei(&rd), g = 9.81, q = rd.rho * rod_area(&rd) * g;
  built b;
  if ((v->st = build_rod(&rd, &b, v->err))) return;
  int ok;
  vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, 0), vd_v3(0, 0, 0), 1, g, 1, &ok);
  double* f = alloc_loads(n);
  if (!f) {
    built_free(&b);
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return;
  }
  for (int k = 1; k <= n; k++) f[2 * (k - 1) + 1] = -g * rod_node_mass(&rd, k);
  planar_ref pr = rod_reference(&rd, f, 0, NULL, NULL);
  free_loads(f, n);
  double meas = -tip.z;
  check(v, nm, "discrete", "tip deflection (m)", meas, -pr.tip[1], 1e-6, 0,
        "N = %d, qL^3/EI = %.2g; masses lumped half a segment per node%s", n, q * pow(rd.len, 3) / ei,
        ok && pr.ok ? "" : " [not converged]");
  double kga = rod_kappa(&rd) * rod_g(&rd) * rod_area(&rd);
  double cont = q * pow(rd.len, 4) / (8 * ei) + q * rd.len * rd.len / (2 * kga);
  check(v, nm, "continuum", "tip deflection (m)", meas, cont, 1.0 / (n * n), 0,
        "qL^4/8EI + qL^2/(2 kappa G A); tolerance 1/N^2");
  built_free(&b);
}

static void case_end_moment(vctx* v) {
  const char* nm = "cantilever_end_moment";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 20;
  rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {1, 0, 0}, 0};
  double ei = rod_ei(&rd);
  // small moment: deflection and end rotation
  {
    double mo = 1e-3 * ei / rd.len;
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    int ok;
    vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, 0), vd_v3(0, -mo, 0), 0, 0, 1, &ok);
    double* f = alloc_loads(n);
    double* phi = vd_calloc((size_t)n, sizeof(double));
    if (!f || !phi) {
      free_loads(f, n);
      vd_free(phi, (size_t)n * sizeof(double));
      built_free(&b);
      v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
      return;
    }
    planar_ref pr = rod_reference(&rd, f, mo, phi, NULL);
    check(v, nm, "discrete", "tip deflection (m)", tip.z, pr.tip[1], 1e-6, 0, "N = %d, ML/EI = 1e-3%s", n,
          ok && pr.ok ? "" : " [not converged]");
    check(v, nm, "continuum", "tip deflection (m)", tip.z, mo * rd.len * rd.len / (2 * ei), 1.0 / (n * n), 0,
          "ML^2/2EI; tolerance 1/N^2");
    vd_vec3 d3 = quat_d3(b.d->seg_quat[b.m->node_owner[tip_node(&b)]]);
    double th = atan2(d3.z, d3.x);
    check(v, nm, "discrete", "end rotation (rad)", th, phi[n - 1], 1e-6, 0, "rotation of the last segment");
    check(v, nm, "continuum", "end rotation (rad)", th, mo * rd.len / ei, 1.0 / n, 0,
          "ML/EI; the last half segment carries no joint: -1/(2N), tolerance 1/N");
    free_loads(f, n);
    vd_free(phi, (size_t)n * sizeof(double));
    built_free(&b);
  }
  // M = 2 pi EI / L rolls the rod into a full circle
  {
    const char* nc = "cantilever_full_circle";
    double mo = 2 * VD_PI * ei / rd.len;
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    int ok;
    vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, 0), vd_v3(0, -mo, 0), 0, 0, 16, &ok);
    double* f = alloc_loads(n);
    if (!f) {
      built_free(&b);
      v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
      return;
    }
    planar_ref pr = rod_reference(&rd, f, mo, NULL, NULL);
    free_loads(f, n);
    double dd = sqrt((tip.x - pr.tip[0]) * (tip.x - pr.tip[0]) + (tip.z - pr.tip[1]) * (tip.z - pr.tip[1]));
    check(v, nc, "discrete", "tip distance to reference (m)", dd, 0, 1e-6 * rd.len, 1,
          "N = %d, M = 2 pi EI/L; joint moments %s/flexibility%s", n, quat_measure() ? "sin(theta)" : "theta",
          ok && pr.ok ? "" : " [not converged]");
    check(v, nc, "continuum", "tip distance from root / L", v_norm(tip) / rd.len, 0, 1.0 / n, 1,
          "a full circle brings the tip back to the root; tolerance 1/N (end half segment%s)",
          quat_measure() ? ", sin law" : "");
    built_free(&b);
  }
}

static void case_timoshenko(vctx* v) {
  const char* nm = "timoshenko_shear";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 20;
  rod rd = {n, 0.1, 0.02, 1e7, 0.3, 1000, {1, 0, 0}, 0};
  double ei = rod_ei(&rd), p = 1e-3 * ei / (rd.len * rd.len);
  built b;
  if ((v->st = build_rod(&rd, &b, v->err))) return;
  int ok;
  vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, -p), vd_v3(0, 0, 0), 0, 0, 1, &ok);
  double* f = alloc_loads(n);
  if (!f) {
    built_free(&b);
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return;
  }
  f[2 * (n - 1) + 1] = -p;
  planar_ref pr = rod_reference(&rd, f, 0, NULL, NULL);
  free_loads(f, n);
  double kga = rod_kappa(&rd) * rod_g(&rd) * rod_area(&rd);
  double eb = p * pow(rd.len, 3) / (3 * ei), sh = p * rd.len / kga;
  check(v, nm, "discrete", "tip deflection (m)", -tip.z, -pr.tip[1], 1e-6, 0, "N = %d, r/L = 0.2%s", n,
        ok && pr.ok ? "" : " [not converged]");
  check(v, nm, "continuum", "tip deflection (m)", -tip.z, eb + sh, 1.0 / (n * n), 0,
        "PL^3/3EI + PL/(kappa G A), kappa = 6(1+nu)/(7+6nu); shear is %.1f %% of it", 100 * sh / (eb + sh));
  built_free(&b);
}

static void case_torsion(vctx* v) {
  const char* nm = "pure_torsion";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 20;
  rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {1, 0, 0}, 0};
  double gj = rod_g(&rd) * 2 * rod_ei(&rd) / rd.e, t = 1e-2 * gj / rd.len;
  built b;
  if ((v->st = build_rod(&rd, &b, v->err))) return;
  int ok;
  vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, 0), vd_v3(t, 0, 0), 0, 0, 1, &ok);
  int ts = b.m->node_owner[tip_node(&b)];
  vd_vec3 rot = quat_log(q_mul(b.d->seg_quat[ts], q_conj(b.m->seg_quat0[ts])));
  double* flex = vd_malloc((size_t)n * sizeof(double));
  if (!flex) {
    built_free(&b);
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return;
  }
  rod_flex(&rd, flex, 1);
  double disc = 0;
  // each joint's twist balances T: twist / flex = T (log measure), sin(twist) / flex = T (quat)
  for (int j = 0; j < n; j++) disc += quat_measure() ? asin(t * flex[j]) : t * flex[j];
  vd_free(flex, (size_t)n * sizeof(double));
  check(v, nm, "discrete", "end twist (rad)", rot.x, disc, 1e-6, 0, "N = %d, TL/GJ = 1e-2; sum of the joints' T l/GJ%s", n,
        ok ? "" : " [not converged]");
  check(v, nm, "continuum", "end twist (rad)", rot.x, t * rd.len / gj, 0.5 / n + 1e-4, 0,
        "TL/GJ; the last half segment carries no joint: -1/(2N)");
  double leak = sqrt(tip.y * tip.y + tip.z * tip.z) / rd.len;
  check(v, nm, "discrete", "twist-to-bend leakage / L", leak, 0, 1e-9, 1, "transverse tip motion under pure torque");
  built_free(&b);
}

static void case_large_deflection(vctx* v) {
  const char* nm = "large_deflection";
  if (!want(v, nm)) return;
  progress(v, nm);
  static const double alphas[4] = {1, 2, 5, 10};
  static const double table_v[4] = {0.3017, 0.4935, 0.7138, 0.8106};  // recalled, anchors 4.7
  int n = v->def->full ? 160 : 40;
  for (int k = 0; k < 4; k++) {
    rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {1, 0, 0}, 0};
    double ei = rod_ei(&rd), p = alphas[k] * ei / (rd.len * rd.len);
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    int ok;
    vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, -p), vd_v3(0, 0, 0), 0, 0, 10, &ok);
    double* f = alloc_loads(n);
    if (!f) {
      built_free(&b);
      v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
      return;
    }
    f[2 * (n - 1) + 1] = -p;
    planar_ref pr = rod_reference(&rd, f, 0, NULL, NULL);
    free_loads(f, n);
    double ev, eu;
    elastica_tip(alphas[k], &ev, &eu);
    char name[64];
    snprintf(name, sizeof name, "%s_alpha%g", nm, alphas[k]);
    check(v, name, "discrete", "tip drop v/L", -tip.z / rd.len, -pr.tip[1] / rd.len, 1e-6, 0,
          "N = %d, PL^2/EI = %g%s", n, alphas[k], ok && pr.ok ? "" : " [not converged]");
    check(v, name, "continuum", "tip drop v/L", -tip.z / rd.len, ev, 0.01, 0,
          "Euler elastica by shooting (table value %.4f, Bisshopp & Drucker 1945); tolerance 1 %%", table_v[k]);
    check(v, name, "continuum", "shortening u/L", 1 - tip.x / rd.len, eu, 0.01, 0, "Euler elastica by shooting");
    built_free(&b);
  }
}

// ---------------------------------------------------------------------------------------------
// dynamics: first natural frequency

// largest eigenvalue of F M (1 / omega^2) by power iteration for a uniform test rod
static double rod_omega(const rod* rd) {
  int n = rd->n;
  double l = rd->len / n, ei = rod_ei(rd), kga = rod_kappa(rd) * rod_g(rd) * rod_area(rd);
  double* fm = vd_malloc((size_t)n * n * sizeof(double));
  double* x = vd_malloc((size_t)n * sizeof(double));
  double* y = vd_malloc((size_t)n * sizeof(double));
  double lam = 0;
  if (fm && x && y) {
    // transverse flexibility: joints at k l (k < min(i, j)) with flexibility l/EI (half at
    // the clamp), plus shear of every segment between the root and the nearer node
    for (int i = 1; i <= n; i++)
      for (int j = 1; j <= n; j++) {
        int mn = i < j ? i : j;
        double s = mn * l / kga;
        for (int k = 0; k < mn; k++) s += (k ? l : 0.5 * l) / ei * (j - k) * (i - k) * l * l;
        fm[(i - 1) * n + (j - 1)] = s * rod_node_mass(rd, j);
      }
    for (int i = 0; i < n; i++) x[i] = 1;
    for (int it = 0; it < 2000; it++) {
      double nrm = 0;
      for (int i = 0; i < n; i++) {
        double s = 0;
        for (int j = 0; j < n; j++) s += fm[i * n + j] * x[j];
        y[i] = s;
        nrm = fmax(nrm, fabs(s));
      }
      double prev = lam;
      lam = nrm;
      for (int i = 0; i < n; i++) x[i] = y[i] / nrm;
      if (fabs(lam - prev) < 1e-15 * lam) break;
    }
  }
  vd_free(fm, (size_t)n * n * sizeof(double));
  vd_free(x, (size_t)n * sizeof(double));
  vd_free(y, (size_t)n * sizeof(double));
  return lam > 0 ? 1 / sqrt(lam) : 0;
}

// released from a small static deflection: frequency from zero crossings, damping ratio from
// the decay of successive extremes
static void measure_frequency(built* b, double p, double h, double t_end, double* freq, double* zeta) {
  int tip = tip_node(b);
  int ok;
  rod_statics(b, vd_v3(0, 0, -p), vd_v3(0, 0, 0), 0, 0, 1, &ok);
  b->d->node_force[tip] = vd_v3(0, 0, 0);
  b->m->opt.dt = h;
  double tc[64], ext[64];
  int nc = 0, ne = 0;
  double zp = b->d->node_pos[tip].z, zpp = zp, tp = b->d->time;
  while (b->d->time < t_end && nc < 64) {
    vd_sim_step(b->m, b->d);
    double z = b->d->node_pos[tip].z, t = b->d->time;
    if ((zp < 0) != (z < 0) && nc < 64) tc[nc++] = tp + (t - tp) * zp / (zp - z);
    if (((zp - zpp) * (z - zp) < 0) && ne < 64) ext[ne++] = fabs(zp);
    zpp = zp, zp = z, tp = t;
  }
  *freq = nc >= 4 ? 0.5 * (nc - 2) / (tc[nc - 1] - tc[1]) : 0;
  *zeta = 0;
  if (ne >= 3 && *freq > 0) {
    // logarithmic decrement over whole cycles (every second extreme is the same side)
    int k = (ne - 1) / 2 * 2;
    double dec = log(ext[0] / ext[k]) / (k / 2.0);  // k is even
    *zeta = dec / sqrt(4 * VD_PI * VD_PI + dec * dec);
  }
}

static void case_frequency(vctx* v) {
  const char* nm = "first_frequency";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 20;
  double h = 1e-3;
  for (int withmass = 0; withmass < 2; withmass++) {
    rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {1, 0, 0}, 0};
    double mrod = rd.rho * rod_area(&rd) * rd.len;
    if (withmass) rd.tip_mass = 0.5 * mrod;
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    double ei = rod_ei(&rd), f, zeta;
    measure_frequency(&b, 1e-3 * ei / (rd.len * rd.len), h, 5.0, &f, &zeta);
    double w = rod_omega(&rd);
    double fd = atan(w * h) / (2 * VD_PI * h);
    const char* name = withmass ? "first_frequency_fruit" : nm;
    check(v, name, "discrete", "frequency (Hz)", f, fd, 2e-3, 0,
          "N = %d, h = %g s; eigenvalue of the lumped discrete model, phase atan(wh)/h of implicit Euler", n, h);
    if (!withmass) {
      double fc = 1.8751 * 1.8751 / (2 * VD_PI * rd.len * rd.len) * sqrt(ei / (rd.rho * rod_area(&rd)));
      check(v, name, "continuum", "frequency (Hz)", f, fc, 1.0 / (n * n) + 3e-3, 0,
            "(1.8751^2 / 2 pi L^2) sqrt(EI / rho A); tolerance 1/N^2 + (wh)^2/3 + rotary inertia");
      double zr = 0.5 * w * h;
      check(v, name, "discrete", "numerical damping ratio", zeta, zr, 0.1, 0,
            "implicit Euler damps a mode by zeta ~ w h / 2 (no material damping, h = %g s)", h);
    } else {
      double fr = sqrt(3 * ei / (pow(rd.len, 3) * (rd.tip_mass + 0.2357 * mrod))) / (2 * VD_PI);
      check(v, name, "continuum", "frequency (Hz)", f, fr, 0.02, 0,
            "tip mass M = %.3g kg (half the rod): Rayleigh sqrt(3EI / (L^3 (M + 0.2357 m))) / 2 pi", rd.tip_mass);
    }
    built_free(&b);
  }
}

// ---------------------------------------------------------------------------------------------
// buckling

static void case_buckling(vctx* v) {
  const char* nm = "buckling";
  if (!want(v, nm)) return;
  progress(v, nm);
  int n = v->def->full ? 80 : 40;
  rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {1, 0, 0}, 0};
  double ei = rod_ei(&rd), pcr = VD_PI * VD_PI * ei / (4 * rd.len * rd.len);
  static const double fac[2] = {0.97, 1.03};
  for (int k = 0; k < 2; k++) {
    double p = fac[k] * pcr, hl = 1e-4 * p;
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    int ok;
    vd_vec3 tip = rod_statics(&b, vd_v3(-p, 0, -hl), vd_v3(0, 0, 0), 0, 0, 8, &ok);
    double* f = alloc_loads(n);
    if (!f) {
      built_free(&b);
      v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
      return;
    }
    f[2 * (n - 1)] = -p, f[2 * (n - 1) + 1] = -hl;
    // above the critical load the straight shape is an equilibrium too: start the reference
    // from the continuum elastica so it finds the buckled branch
    double* guess = k ? vd_calloc((size_t)n, sizeof(double)) : NULL;
    if (guess) {
      elastica_column(fac[k] * VD_PI * VD_PI / 4, guess, n);
      for (int i = 0; i < n; i++) guess[i] = -guess[i];
    }
    planar_ref pr = rod_reference(&rd, f, 0, NULL, guess);
    vd_free(guess, (size_t)n * sizeof(double));
    free_loads(f, n);
    char name[64];
    snprintf(name, sizeof name, "buckling_%s", k ? "above" : "below");
    check(v, name, "discrete", "tip deflection / L", -tip.z / rd.len, -pr.tip[1] / rd.len, 1e-5, 0,
          "N = %d, P = %.2f P_cr with a lateral imperfection of 1e-4 P%s", n, fac[k], ok && pr.ok ? "" : " [not converged]");
    if (!k) {
      // below: the beam-column amplification of the imperfection, P_cr = pi^2 EI / 4 L^2
      double kk = sqrt(p / ei), lin = hl / (p * kk) * (tan(kk * rd.len) - kk * rd.len);
      check(v, name, "continuum", "tip deflection / L", -tip.z / rd.len, lin / rd.len, 0.03 / (1 - fac[k]) / (n * n) + 0.01,
            0, "beam-column (H/(Pk))(tan kL - kL): straight under 0.97 P_cr (amplified imperfection)");
    } else {
      double y = elastica_column(fac[k] * VD_PI * VD_PI / 4, NULL, 0);
      check(v, name, "continuum", "tip deflection / L", -tip.z / rd.len, y, 0.1, 0,
            "post-buckled elastica at 1.03 P_cr (P_cr = pi^2 EI / 4 L^2); tolerance 10 %% (imperfection, 1/N^2 near the bifurcation)");
    }
    built_free(&b);
  }
}

// self-weight column (Greenhill): buckles when q L^3 / EI exceeds 7.837
static void case_greenhill(vctx* v) {
  const char* nm = "greenhill_column";
  if (!want(v, nm) || !v->def->full) return;
  progress(v, nm);
  int n = 40;
  static const double fac[2] = {0.97, 1.03};
  for (int k = 0; k < 2; k++) {
    rod rd = {n, 1.0, 0.005, 1e10, 0.3, 1000, {0, 0, 1}, 0};
    double ei = rod_ei(&rd), g = 9.81;
    double lcr3 = 7.837 * ei / (rd.rho * rod_area(&rd) * g);  // L_cr^3 at rho
    rd.rho *= pow(fac[k], 3) * lcr3 / pow(rd.len, 3) / 1.0;    // q L^3 / EI = 7.837 fac^3
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    int tip = tip_node(&b), ok;
    b.d->node_force[tip] = vd_v3(1e-6 * rd.rho * rod_area(&rd) * g * rd.len, 0, 0);
    vd_vec3 p = rod_statics(&b, b.d->node_force[tip], vd_v3(0, 0, 0), 1, g, 8, &ok);
    char name[64];
    snprintf(name, sizeof name, "greenhill_%s", k ? "above" : "below");
    vd_validate_result* r = push(v, name, "continuum", "tip sway / L");
    if (r) {
      r->measured = fabs(p.x) / rd.len;
      r->reference = k ? 0.1 : 0.0;
      r->tolerance = k ? 0.0 : 0.02;
      r->error = k ? (r->measured >= 0.1 ? 0 : 0.1 - r->measured) : r->measured;
      r->pass = isfinite(r->measured) && r->error <= r->tolerance;
      snprintf(r->note, sizeof r->note, "qL^3/EI = %.3f (critical 7.837, Greenhill 1881): %s expected%s", 7.837 * pow(fac[k], 3),
               k ? "buckled, sway >= 0.1 L" : "straight", ok ? "" : " [not converged]");
    }
    built_free(&b);
  }
}

// ---------------------------------------------------------------------------------------------
// fracture

// a pedicel-like rod with a fruit hanging off its end by a breakable calyx joint
static vd_status build_fruit_rod(double fbreak, built* out, vd_error* err) {
  memset(out, 0, sizeof *out);
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  double len = 0.1, l = len / 10, rs = 0.012;
  int a = vd_plant_add_node(s, vd_v3(-l, 0, 0)), b = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int c = vd_plant_add_node(s, vd_v3(len, 0, 0));
  vd_segment_spec g = vd_segment_spec_default();
  g.node0 = a, g.node1 = b, g.r0 = g.r1 = 0.001, g.label = 1, g.instance = 1, g.up = vd_v3(0, 0, 1);
  int s0 = vd_plant_add_segment(s, &g);
  g.node0 = b, g.node1 = c, g.parent = s0, g.instance = 2;
  int s1 = vd_plant_add_segment(s, &g);
  vd_sphere_spec f = vd_sphere_spec_default();
  f.center = vd_v3(len + rs, 0, 0), f.radius = rs, f.parent = s1, f.label = 2, f.instance = 3;
  vd_plant_add_sphere(s, &f);
  vd_status st = vd_plant_set_label(s, 1, "stem");
  if (!st) st = vd_plant_set_label(s, 2, "fruit");
  if (!st) st = vd_plant_compile(s, &out->pm, err);
  vd_plant_spec_destroy(s);
  if (st) return st;
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = l;
  def.clamp_length = l;
  def.material[VD_SIM_GREEN].young = 5e8;
  def.material[VD_SIM_FRUIT].break_force = fbreak;
  def.material[VD_SIM_FRUIT].break_moment = INFINITY;
  st = vd_sim_build(out->pm, &def, &out->m, err);
  if (st) {
    built_free(out);
    return st;
  }
  out->m->opt.drag = 0;
  out->d = vd_sim_data_create(out->m);
  if (!out->d) {
    built_free(out);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
  return VD_OK;
}

static void case_fracture(vctx* v) {
  const char* nm = "fracture_once";
  if (!want(v, nm)) return;
  progress(v, nm);
  double fb = 1.0, rate = 2.0, h = 1e-3;
  built b;
  if ((v->st = build_fruit_rod(fb, &b, v->err))) return;
  b.m->opt.gravity = vd_v3(0, 0, 0);  // NOLINT(clang-analyzer-core.NullDereference): build_fruit_rod sets b.m when it returns VD_OK
  b.m->opt.dt = h;
  int fruit = b.m->bind_sphere_node[0];
  while (b.d->time < 1.0 - 1e-12) {
    b.d->node_force[fruit] = vd_v3(rate * b.d->time, 0, 0);
    vd_sim_step(b.m, b.d);
  }
  double te = b.d->nevent ? b.d->event[0].time : -1;
  check(v, nm, "discrete", "fracture events", b.d->nevent, 1, 0, 1,
        "calyx joint of %.1f N, axial pull ramped at %.1f N/s for 1 s: the joint breaks once", fb, rate);
  check(v, nm, "continuum", "fracture time (s)", te, fb / rate, 2 * h, 1,
        "constraint force |lambda| / h^2 reaches the threshold at F/rate = %.3f s; tolerance 2 steps", fb / rate);
  built_free(&b);
  // the detached fruit falls freely: its acceleration is g
  const char* nf = "detached_free_fall";
  if ((v->st = build_fruit_rod(1e-6, &b, v->err))) return;
  b.m->opt.dt = h;  // NOLINT(clang-analyzer-core.NullDereference): build_fruit_rod sets b.m when it returns VD_OK
  double z[3] = {0, 0, 0};
  for (int i = 0; i < 200; i++) {
    vd_sim_step(b.m, b.d);
    z[0] = z[1], z[1] = z[2], z[2] = b.d->node_pos[b.m->bind_sphere_node[0]].z;
  }
  double acc = (z[2] - 2 * z[1] + z[0]) / (h * h);
  check(v, nf, "continuum", "fruit acceleration (m/s^2)", acc, -9.81, 1e-6, 0,
        "after the calyx breaks (%d event) the fruit and its stalk fall as a free body", b.d->nevent);
  built_free(&b);
}

// ---------------------------------------------------------------------------------------------
// contacts: no penetration

static void case_contacts(vctx* v) {
  const char* nm = "no_penetration";
  if (!want(v, nm)) return;
  progress(v, nm);
  static const char* what[4] = {"ground plane", "moving sphere probe", "moving box",
                                 "moving closed cube mesh through its signed distance grid"};
  // the mesh: a cube of half size 0.04 m as 12 triangles, wound counter-clockwise from outside
  double cv[24];
  int ct[36];
  for (int i = 0; i < 8; i++)
    cv[3 * i] = i & 1 ? 0.04 : -0.04, cv[3 * i + 1] = i & 2 ? 0.04 : -0.04, cv[3 * i + 2] = i & 4 ? 0.04 : -0.04;
  static const int quad[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  for (int f = 0; f < 6; f++)
    for (int h = 0; h < 2; h++) {
      int* t = ct + 6 * f + 3 * h;
      t[0] = quad[f][0], t[1] = quad[f][1 + h], t[2] = quad[f][2 + h];
      // outward: the normal points away from the centre
      vd_vec3 a = vd_v3(cv[3 * t[0]], cv[3 * t[0] + 1], cv[3 * t[0] + 2]);
      vd_vec3 b = vd_v3(cv[3 * t[1]], cv[3 * t[1] + 1], cv[3 * t[1] + 2]);
      vd_vec3 c = vd_v3(cv[3 * t[2]], cv[3 * t[2] + 1], cv[3 * t[2] + 2]);
      if (vd_dot(vd_cross(vd_sub(b, a), vd_sub(c, a)), vd_add(vd_add(a, b), c)) < 0) {
        int x = t[1];
        t[1] = t[2], t[2] = x;
      }
    }
  vd_sdf* sdf = NULL;
  if ((v->st = vd_sdf_build(cv, 8, ct, 12, NULL, &sdf, v->err))) return;
  for (int k = 0; k < 4 && !v->st; k++) {
    rod rd = {20, 0.5, 0.003, k ? 1e8 : 2e6, 0.3, 1000, {1, 0, 0}, 0};
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    b.m->opt.contacts = 1;
    b.m->opt.gravity = vd_v3(0, 0, -9.81);
    vd_sim_collider c;
    memset(&c, 0, sizeof c);
    c.quat = vd_quat_identity();
    vd_vec3 p0 = vd_v3(0, 0, 0), p1 = p0;
    if (k == 0) {
      c.shape = VD_SIM_PLANE;
      c.pos = vd_v3(0, 0, -0.05);
    } else if (k == 1) {
      c.shape = VD_SIM_SPHERE;
      c.size[0] = 0.03;
      p0 = vd_v3(0.35, 0, 0.1), p1 = vd_v3(0.3, 0, -0.3);
    } else {
      c.shape = VD_SIM_BOX;
      c.size[0] = c.size[1] = 0.04, c.size[2] = 0.02;
      c.quat = vd_quat_axis_angle(vd_v3(0, 1, 0), 0.3);
      p0 = vd_v3(0.4, 0, 0.1), p1 = vd_v3(0.3, 0, -0.3);
      if (k == 3) {
        c.shape = VD_SIM_MESH;
        c.sdf = sdf;
        c.quat = vd_quat_axis_angle(vd_v3(1, 1, 0.3), 0.5);
        p0 = vd_v3(0.4, 0, 0.12);
      }
    }
    if (k) c.pos = p0;
    int id = vd_sim_add_collider(b.d, &c);
    double maxpen = 0, t_end = 1.0;
    int touched = 0;
    while (b.d->time < t_end - 1e-12) {
      if (k) {
        double s = b.d->time / t_end;
        vd_sim_set_collider_pose(b.m, b.d, id, vd_add(p0, vd_scale(vd_sub(p1, p0), s)), c.quat);
      }
      vd_sim_step(b.m, b.d);
      if (b.d->max_penetration > maxpen) maxpen = b.d->max_penetration;
      touched |= b.d->ncontact > 0;
    }
    char name[64];
    snprintf(name, sizeof name, "no_penetration_%s", k == 0 ? "ground" : k == 1 ? "sphere" : k == 2 ? "box" : "mesh");
    check(v, name, "continuum", "deepest penetration (m)", maxpen, 0, 1e-4, 1,
          "cantilever of %s against a %s (signed distance), 1 s, h = 1 ms%s",
          k ? "capsules" : "flat-ended cylinders", what[k], touched ? "" : " [no contact]");
    built_free(&b);
  }
  vd_sdf_destroy(sdf);
}

// closest distance between the segments a-b and c-d (Ericson 2004, 5.1.9)
static double seg_seg_dist(vd_vec3 a, vd_vec3 b, vd_vec3 c, vd_vec3 dd) {
  vd_vec3 d1 = vd_sub(b, a), d2 = vd_sub(dd, c), r = vd_sub(a, c);
  double aa = vd_dot(d1, d1), e = vd_dot(d2, d2), f = vd_dot(d2, r), s = 0, t = 0;
  if (aa <= 1e-30 && e <= 1e-30) return v_norm(r);
  if (aa <= 1e-30) {
    t = f / e;
  } else {
    double cc = vd_dot(d1, r);
    if (e <= 1e-30) {
      s = -cc / aa;
    } else {
      double bb = vd_dot(d1, d2), den = aa * e - bb * bb;
      s = den > 1e-30 ? (bb * f - cc * e) / den : 0;
      s = s < 0 ? 0 : s > 1 ? 1 : s;
      t = (bb * s + f) / e;
      if (t < 0) t = 0, s = -cc / aa;
      else if (t > 1) t = 1, s = (bb - cc) / aa;
    }
  }
  s = s < 0 ? 0 : s > 1 ? 1 : s;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return v_norm(vd_sub(vd_madd(a, d1, s), vd_madd(c, d2, t)));
}

// two crossing cantilevers, the upper one pushed down through the lower one; the deepest
// overlap of their capsules (exact segment-segment distances over all pairs of the two rods)
static double crossing_rods(vctx* v, int self, int* ncontact_max) {
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) {
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return NAN;
  }
  const double r = 0.004, z = 0.02, l = 0.3;
  vd_segment_spec g = vd_segment_spec_default();
  g.r0 = g.r1 = r, g.label = 1, g.up = vd_v3(0, 0, 1);
  // rod A along +x at height 0, rod B along +y at height z crossing A's middle
  int a0 = vd_plant_add_node(s, vd_v3(-0.01, 0, 0)), a1 = vd_plant_add_node(s, vd_v3(0, 0, 0));
  int a2 = vd_plant_add_node(s, vd_v3(l, 0, 0));
  int b0 = vd_plant_add_node(s, vd_v3(l / 2, -l / 2 - 0.01, z)), b1 = vd_plant_add_node(s, vd_v3(l / 2, -l / 2, z));
  int b2 = vd_plant_add_node(s, vd_v3(l / 2, l / 2, z));
  g.node0 = a0, g.node1 = a1, g.instance = 1;
  int sa = vd_plant_add_segment(s, &g);
  g.node0 = a1, g.node1 = a2, g.parent = sa, g.instance = 2;
  vd_plant_add_segment(s, &g);
  g.node0 = b0, g.node1 = b1, g.parent = -1, g.instance = 3, g.up = vd_v3(1, 0, 0);
  int sb = vd_plant_add_segment(s, &g);
  g.node0 = b1, g.node1 = b2, g.parent = sb, g.instance = 4;
  vd_plant_add_segment(s, &g);
  built b;
  memset(&b, 0, sizeof b);
  vd_status st = vd_plant_set_label(s, 1, "stem");
  if (!st) st = vd_plant_compile(s, &b.pm, v->err);
  vd_plant_spec_destroy(s);
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.02, def.clamp_length = 0.01;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) {
    def.material[k].young = 1e8, def.material[k].density = 1000;
    def.material[k].break_force = def.material[k].break_moment = INFINITY;
  }
  if (!st) st = vd_sim_build(b.pm, &def, &b.m, v->err);
  if (!st && !(b.d = vd_sim_data_create(b.m))) st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  if (st) {
    v->st = st;
    built_free(&b);
    return NAN;
  }
  vd_sim_model* m = b.m;
  m->opt.drag = 0, m->opt.gravity = vd_v3(0, 0, 0), m->opt.contacts = 1, m->opt.self_collision = self;
  m->opt.mass_damping = 5;
  // the node of rod B nearest the crossing, pushed down by a force ramped over 0.5 s
  int push = -1;
  double best = 1e300;
  for (int i = 0; i < m->nnode; i++) {
    double e = v_norm(vd_sub(m->node_pos0[i], vd_v3(l / 2, 0, z)));
    if (e < best) best = e, push = i;
  }
  double deepest = 0;
  *ncontact_max = 0;
  while (b.d->time < 1.0 - 1e-12) {
    double ramp = b.d->time < 0.5 ? b.d->time / 0.5 : 1.0;
    b.d->node_force[push] = vd_v3(0, 0, -1.0 * ramp);
    vd_sim_step(m, b.d);
    if (b.d->ncontact > *ncontact_max) *ncontact_max = b.d->ncontact;
    for (int i = 0; i < m->nseg; i++) {
      if (m->seg_instance[i] > 2) continue;
      for (int j = 0; j < m->nseg; j++) {
        if (m->seg_instance[j] <= 2) continue;
        double dist = seg_seg_dist(b.d->node_pos[b.d->seg_start[i]], b.d->node_pos[m->seg_node[2 * i + 1]],
                                   b.d->node_pos[b.d->seg_start[j]], b.d->node_pos[m->seg_node[2 * j + 1]]);
        double pen = m->seg_radius[i] + m->seg_radius[j] - dist;
        if (pen > deepest) deepest = pen;
      }
    }
  }
  built_free(&b);
  return deepest;
}

static void case_self_contacts(vctx* v) {
  const char* nm = "no_penetration_self";
  if (!want(v, nm)) return;
  progress(v, nm);
  int nc_on = 0, nc_off = 0;
  double on = crossing_rods(v, 1, &nc_on);
  if (v->st) return;
  double off = crossing_rods(v, 0, &nc_off);
  if (v->st) return;
  check(v, nm, "continuum", "deepest penetration (m)", on, 0, 1e-4, 1,
        "two crossing cantilevers (r 4 mm, E 1e8 Pa) pushed together by 1 N, 1 s, h = 1 ms; "
        "%.4g m without self-collision", off);
  // the case means something only if the rods do pass through each other without it
  check_at_least(v, "no_penetration_self_off", "continuum", "penetration without self-collision (m)", off, 2e-3,
                 "control: the same run with self-collision off must overlap by at least 2 mm");
}

// ---------------------------------------------------------------------------------------------
// a plant like Gazebo Plants' (a stem with side branches and two fruits), for the independence
// tests, the seed figures and sag-free

static vd_status build_branched(double e, double rho, double sigma, int sag_free, built* out, int* tipnode,
                                vd_error* err) {
  memset(out, 0, sizeof *out);
  vd_plant_spec* s = vd_plant_spec_create();
  if (!s) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  vd_segment_spec g = vd_segment_spec_default();
  g.label = 1, g.up = vd_v3(1, 0, 0);
  int prev = vd_plant_add_node(s, vd_v3(0, 0, 0)), pseg = -1, tip = -1, inst = 1;
  static const double hz[4] = {0.15, 0.30, 0.45, 0.60};
  static const double blen[3] = {0.30, 0.25, 0.20};
  for (int i = 0; i < 4; i++) {
    int n = vd_plant_add_node(s, vd_v3(0, 0, hz[i]));
    g.node0 = prev, g.node1 = n, g.parent = pseg, g.r0 = 0.006 - 0.0005 * i, g.r1 = 0.0055 - 0.0005 * i;
    g.instance = inst++, g.label = 1;
    pseg = vd_plant_add_segment(s, &g);
    prev = n;
    if (i == 3) break;
    // side branch at 30 degrees above the horizontal, turning 120 degrees each time
    double az = 2.0 * VD_PI / 3.0 * i, el = VD_PI / 6;
    vd_vec3 dir = vd_v3(cos(el) * cos(az), cos(el) * sin(az), sin(el));
    int half = vd_plant_add_node(s, vd_add(vd_v3(0, 0, hz[i]), vd_scale(dir, 0.5 * blen[i])));
    int end = vd_plant_add_node(s, vd_add(vd_v3(0, 0, hz[i]), vd_scale(dir, blen[i])));
    vd_segment_spec bg = g;
    bg.node0 = n, bg.node1 = half, bg.parent = pseg, bg.r0 = 0.005, bg.r1 = 0.0045, bg.instance = inst++, bg.label = 2;
    int b1 = vd_plant_add_segment(s, &bg);
    bg.node0 = half, bg.node1 = end, bg.parent = b1, bg.r0 = 0.0045, bg.r1 = 0.004, bg.instance = inst++;
    int b2 = vd_plant_add_segment(s, &bg);
    if (i == 0) tip = end;
    if (i < 2) {
      vd_sphere_spec f = vd_sphere_spec_default();
      f.radius = 0.012, f.center = vd_add(s->node[end], vd_scale(dir, 0.012)), f.parent = b2, f.label = 3;
      f.instance = inst++;
      vd_plant_add_sphere(s, &f);
    }
  }
  vd_status st = vd_plant_set_label(s, 1, "stem");
  if (!st) st = vd_plant_set_label(s, 2, "branch shoot");
  if (!st) st = vd_plant_set_label(s, 3, "fruit");
  if (!st) st = vd_plant_compile(s, &out->pm, err);
  vd_plant_spec_destroy(s);
  if (st) return st;
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = sigma;
  def.clamp_length = 0.01;
  def.sag_free = sag_free;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) {
    def.material[k].young = e;
    if (k != VD_SIM_FRUIT) def.material[k].density = rho;
    def.material[k].break_force = def.material[k].break_moment = INFINITY;
  }
  st = vd_sim_build(out->pm, &def, &out->m, err);
  if (st) {
    built_free(out);
    return st;
  }
  out->m->opt.drag = 0;
  out->d = vd_sim_data_create(out->m);
  if (!out->d) {
    built_free(out);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
  *tipnode = out->m->bind_node_ref[tip];
  return VD_OK;
}

// vertical sag of the first branch tip at static equilibrium (m)
static double branched_sag(vctx* v, double e, double rho, double sigma, int* ok) {
  built b;
  int tip;
  *ok = 0;
  if ((v->st = build_branched(e, rho, sigma, 0, &b, &tip, v->err))) return NAN;
  *ok = statics(b.m, b.d, 1e-13);
  double sag = b.m->node_pos0[tip].z - b.d->node_pos[tip].z;
  built_free(&b);
  return sag;
}

// settle by damped dynamics with a given solver setup; tip sag of a soft test cantilever
static double settle_sag(vctx* v, int iterations, double h, int* ok) {
  rod rd = {10, 0.5, 0.004, 2e7, 0.3, 600, {1, 0, 0}, 0};
  built b;
  *ok = 0;
  if ((v->st = build_rod(&rd, &b, v->err))) return NAN;
  b.m->opt.gravity = vd_v3(0, 0, -9.81);
  b.m->opt.iterations = iterations;
  b.m->opt.dt = h;
  vd_sim_settle_def s = vd_sim_settle_def_default();
  s.ke_tol = 1e-14;
  s.extra_damping = 20;
  s.max_time = 20;
  vd_sim_settle(b.m, b.d, &s, ok, NULL);
  double sag = -b.d->node_pos[tip_node(&b)].z;
  built_free(&b);
  return sag;
}

static void case_independence(vctx* v) {
  if (want(v, "iteration_independence")) {
    progress(v, "iteration_independence");
    int ok1, ok2;
    double s5 = settle_sag(v, 5, 1e-3, &ok1);
    double s50 = settle_sag(v, 50, 1e-3, &ok2);
    check(v, "iteration_independence", "continuum", "tip sag (m)", s5, s50, 0.01, 0,
          "settled sag with 5 vs %d Newton iterations per step (direct solver), soft cantilever%s",
          50, ok1 && ok2 ? "" : " [not settled]");
    int ok3;
    double s1 = settle_sag(v, 1, 1e-3, &ok3);
    check(v, "iteration_independence_1", "continuum", "tip sag (m)", s1, s50, 0.01, 0,
          "settled sag with 1 vs %d iterations%s", 50, ok3 ? "" : " [not settled]");
  }
  if (want(v, "timestep_independence")) {
    progress(v, "timestep_independence");
    rod rd = {10, 0.5, 0.004, 2e7, 0.3, 600, {1, 0, 0}, 0};
    built b;
    if ((v->st = build_rod(&rd, &b, v->err))) return;
    int ok;
    vd_vec3 tip = rod_statics(&b, vd_v3(0, 0, 0), vd_v3(0, 0, 0), 1, 9.81, 4, &ok);
    built_free(&b);
    double ref = -tip.z, worst = 0;
    static const double hs[4] = {5e-4, 1e-3, 2e-3, 5e-3};
    int all = ok;
    for (int k = 0; k < 4; k++) {
      int okk;
      double s = settle_sag(v, 2, hs[k], &okk);
      all &= okk;
      double e = fabs(s - ref) / ref;
      if (!(e <= worst)) worst = e;
    }
    check(v, "timestep_independence", "continuum", "largest sag deviation (rel.)", worst, 0, 1e-3, 1,
          "settled sag at h = 0.5, 1, 2, 5 ms against the static solution %.5f m%s", ref, all ? "" : " [not settled]");
  }
  if (want(v, "discretisation")) {
    // the branch tip sag at Gazebo Plants' sigma_distance values (fig. 5: the PBD sag changes
    // with it) and at finer ones: the sigma -> 0 limit by Richardson extrapolation of the two
    // finest (second order), the observed order from the three finest, and each value's error
    progress(v, "discretisation");
    static const double sig[6] = {0.0025, 0.005, 0.01, 0.02, 0.035, 0.05};
    double sag[6];
    int all = 1;
    for (int k = 0; k < 6; k++) {
      int ok;
      sag[k] = branched_sag(v, 2e7, 300, sig[k], &ok);
      all &= ok;
      if (v->st) return;
    }
    double lim = (4 * sag[0] - sag[1]) / 3;
    double order = log2(fabs((sag[2] - sag[1]) / (sag[1] - sag[0])));
    double lo = fmin(sag[3], fmin(sag[4], sag[5])), hi = fmax(sag[3], fmax(sag[4], sag[5]));
    check(v, "discretisation_order", "continuum", "convergence order in sigma", order, 2, 0.125, 0,
          "branch tip sag at sigma_distance 0.0025 / 0.005 / 0.01 m: %.6f / %.6f / %.6f m%s", sag[0], sag[1], sag[2],
          all ? "" : " [not converged]");
    check(v, "discretisation_independence", "continuum", "branch tip sag at sigma 0.02 m (m)", sag[3], lim, 0.03, 0,
          "against the sigma -> 0 limit %.5f m (Richardson); sigma 0.035 / 0.05 m: %.4f / %.4f m (%+.1f / %+.1f %%), "
          "spread over 0.02-0.05 m %.1f %% (Gazebo Plants fig. 5)%s",
          lim, sag[4], sag[5], 100 * (sag[4] - lim) / lim, 100 * (sag[5] - lim) / lim, 100 * (hi - lo) / hi,
          all ? "" : " [not converged]");
  }
}

// Gazebo Plants figures 6 and 7 as numbers on a plant like theirs (full sweep only)
static void case_seed_figures(vctx* v) {
  if (!v->def->full || !want(v, "seed_fig")) return;
  progress(v, "seed_figures");
  int ok;
  double base = branched_sag(v, 2e7, 300, 0.02, &ok);
  static const double es[3] = {1e7, 2e7, 3e7}, rhos[3] = {300, 600, 900};
  for (int k = 0; k < 3; k++) {
    char name[64];
    double s = branched_sag(v, es[k], 300, 0.02, &ok);
    snprintf(name, sizeof name, "seed_fig6_E%.0fe7", es[k] / 1e7);
    check(v, name, "continuum", "branch tip sag (m)", s, base * 2e7 / es[k], 0.5, 0,
          "E = %.0e Pa, rho = 300 kg/m^3, sigma 0.02 m; reference: linear scaling sag ~ 1/E from E = 2e7", es[k]);
    s = branched_sag(v, 2e7, rhos[k], 0.02, &ok);
    snprintf(name, sizeof name, "seed_fig7_rho%.0f", rhos[k]);
    check(v, name, "continuum", "branch tip sag (m)", s, base * rhos[k] / 300, 0.5, 0,
          "rho = %.0f kg/m^3, E = 2e7 Pa; reference: linear scaling sag ~ rho from rho = 300 (fruits keep 800)", rhos[k]);
    if (v->st) return;
  }
}

// sag-free: the modelled shape is the equilibrium
static void sagfree_plant(vctx* v, const vd_model* pm, const vd_sim_def* base, const char* name, const char* what,
                          double gate) {
  for (int on = 1; on >= 0; on--) {
    vd_sim_def def = *base;
    def.sag_free = on;
    vd_sim_model* m = NULL;
    vd_sim_data* d = NULL;
    if ((v->st = vd_sim_build(pm, &def, &m, v->err))) return;
    d = vd_sim_data_create(m);
    if (!d) {
      vd_sim_model_destroy(m);
      v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
      return;
    }
    vd_sim_settle_def s = vd_sim_settle_def_default();
    s.max_time = 3;
    int ok;
    vd_sim_settle(m, d, &s, &ok, NULL);
    double md = vd_sim_max_displacement(m, d, NULL);
    char nm[64];
    snprintf(nm, sizeof nm, "%s_%s", name, on ? "on" : "off");
    char note[160];
    snprintf(note, sizeof note, "%s, settled %s (%d joints out of reach): %s", what, ok ? "yes" : "no",
             m->nsagfree_clamped, on ? "must stay within the gate" : "control: must visibly sag (>= 1 cm)");
    if (on)
      check(v, nm, "continuum", "largest node move after settling (m)", md, 0, gate, 1, "%s", note);
    else
      check_at_least(v, nm, "continuum", "largest node move after settling (m)", md, 0.01, note);
    if (on && m->main_tip >= 0) {
      // a stable equilibrium: pushed sideways by 2 % of the plant's weight for 0.2 s, the plant
      // comes back to its modelled shape
      double w = 0.02 * m->total_mass * 9.81;
      double t0 = d->time;
      while (d->time - t0 < 0.2) {
        d->node_force[m->main_tip] = vd_v3(w, 0, 0);
        vd_sim_step(m, d);
      }
      d->node_force[m->main_tip] = vd_v3(0, 0, 0);
      double pushed = vd_sim_max_displacement(m, d, NULL);
      s.max_time = 5;
      vd_sim_settle(m, d, &s, &ok, NULL);
      snprintf(nm, sizeof nm, "%s_pushed", name);
      check(v, nm, "continuum", "largest node move after a push (m)", vd_sim_max_displacement(m, d, NULL), 0, gate, 1,
            "%s: pushed %.1f mm by 2 %% of its weight, then settled (%s): it must come back", what, 1e3 * pushed,
            ok ? "settled" : "not settled");
    }
    vd_sim_data_destroy(d);
    vd_sim_model_destroy(m);
  }
}

static void case_sagfree(vctx* v) {
  if (!want(v, "sag_free")) return;
  progress(v, "sag_free");
  built b;
  int tip;
  if ((v->st = build_branched(2e7, 300, 0.02, 0, &b, &tip, v->err))) return;
  vd_sim_def def = vd_sim_def_default();
  def.segment_length = 0.02;
  for (int k = 0; k < VD_SIM_CLASS_COUNT; k++) {
    def.material[k].young = 1e8;
    if (k != VD_SIM_FRUIT) def.material[k].density = 1000;
  }
  sagfree_plant(v, b.pm, &def, "sag_free_branched", "branched test plant, E = 1e8 Pa", 1e-3);
  built_free(&b);
  def = vd_sim_def_default();
  if (v->def->plant && !v->st) sagfree_plant(v, v->def->plant, &def, "sag_free_plant", "the given plant, default materials", 1e-3);
}

// ---------------------------------------------------------------------------------------------

vd_status vd_sim_validate(const vd_validate_def* def, vd_validate_result** out, int* n, vd_error* err) {
  vctx v;
  memset(&v, 0, sizeof v);
  v.def = def;
  v.err = err;
  *out = NULL;
  *n = 0;
  void (*cases[])(vctx*) = {case_tip_load,    case_self_weight, case_end_moment, case_timoshenko,
                            case_torsion,     case_large_deflection, case_frequency, case_buckling,
                            case_greenhill,   case_fracture,    case_contacts,   case_self_contacts,
                            case_independence,
                            case_seed_figures, case_sagfree};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0] && !v.st; k++) cases[k](&v);
  if (v.st) {
    vd_free(v.r, (size_t)v.cap * sizeof(vd_validate_result));
    return v.st;
  }
  // hand back an array of exactly n entries
  if (!v.n) {
    vd_free(v.r, (size_t)v.cap * sizeof(vd_validate_result));
    return VD_OK;
  }
  if (v.cap != v.n) {
    vd_validate_result* r = vd_realloc(v.r, (size_t)v.cap * sizeof *r, (size_t)v.n * sizeof *r);
    if (!r) {
      vd_free(v.r, (size_t)v.cap * sizeof(vd_validate_result));
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    }
    v.r = r;
  }
  *out = v.r;
  *n = v.n;
  return VD_OK;
}
