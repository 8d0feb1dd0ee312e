// SPDX-License-Identifier: MIT
// Validation of growth runs (docs/validation.md, "Growth"): momentum kept at every growth event
// (eq. 1, the mass update, eqs. 6-7) to round-off, and, with --full, the seed's findings as
// numbers on the bundled tree (data/tree.lpy, 8 years): MRL stiffer than ML under gravity, both
// bending toward a light and upward under gravitropism, eq. 3 stable over a wider range of
// spring constants and damping than eq. 4, the soil's method 2 steadier than method 1; then the
// improved models (standing in wind) and the rods on the same tree (standing, their sag beside
// MRL's).
// A finding passes when the measured number is on the finding's side of its threshold.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "growth_hopea_lpy.h"  // data/hopea.lpy as a string
#include "growth_tree_lpy.h"   // data/tree.lpy as a string (cmake/embed.cmake)
#include "verdant/growth.h"

typedef struct gv {
  const vd_validate_def* def;
  vd_validate_list list;
  vd_status st;
  vd_error* err;
  vd_lsystem* ls;     // data/tree.lpy
  vd_lsystem* hopea;  // data/hopea.lpy (the seed's species, 25 years)
} gv;

// name: the case's results, separated by spaces (a filter matching any of them runs the case)
static int want(gv* v, const char* name) {
  if (v->st) return 0;
  if (v->def->filter && !strstr(name, v->def->filter)) return 0;
  if (v->def->progress) {
    char first[64];
    snprintf(first, sizeof first, "%.*s", (int)strcspn(name, " "), name);
    v->def->progress(v->def->user, first);
  }
  return 1;
}

// a finding: pass when measured is above (sign 1) or below (sign -1) the threshold
static void finding(gv* v, const char* name, const char* qty, double measured, double threshold, int sign,
                    const char* note) {
  if (!vd_validate_add(&v->list, name, "finding", qty, measured, threshold, 0, 1, "%s", note)) {
    v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
    return;
  }
  vd_validate_result* r = &v->list.r[v->list.n - 1];
  r->error = sign * (threshold - measured);  // <= 0 when on the finding's side
  r->tolerance = 0;
  r->pass = isfinite(measured) && (sign > 0 ? measured > threshold : measured < threshold);
}

// grow the tree with def and return its summary (and the tips' mean position); 0 on failure
typedef struct result {
  vd_growth_stats s;
  vd_vec3 tip_mean;  // mean position of the buds that are not on the main stem (m)
  vd_vec3 tip_mean0; // ... at rest
  int ok;
} result;

static result grow_on(vd_lsystem* ls, const vd_growth_def* def, int ages) {
  result r;
  memset(&r, 0, sizeof r);
  vd_growth* g = NULL;
  vd_error e = {0};
  if (!ls || vd_growth_create(ls, def, &g, &e)) return r;
  int ok = 1;
  for (int k = 0; k < ages && ok; k++) ok = vd_growth_step(g, &e) == VD_OK;
  if (ok) {
    vd_growth_get_stats(g, &r.s);
    const vd_mss_data* d = NULL;
    const vd_mss_model* m = vd_growth_mss(g, &d);
    int n = 0;
    for (int i = 0; m && i < m->nnode; i++) {
      if (!(m->node_flags[i] & VD_MSS_TIP) || (m->node_flags[i] & VD_MSS_ROOT) || d->removed[i] || i == m->main_tip) continue;
      r.tip_mean = vd_add(r.tip_mean, d->pos[i]);
      r.tip_mean0 = vd_add(r.tip_mean0, m->node_rest[i]);
      n++;
    }
    if (n) r.tip_mean = vd_scale(r.tip_mean, 1.0 / n), r.tip_mean0 = vd_scale(r.tip_mean0, 1.0 / n);
    r.ok = 1;
  }
  vd_growth_destroy(g);
  return r;
}

static result grow(gv* v, const vd_growth_def* def, int ages) { return grow_on(v->ls, def, ages); }

static vd_growth_def base_def(vd_growth_model model, int paper) {
  vd_growth_def d = vd_growth_def_default();
  d.model = model;
  if (paper) vd_growth_def_paper(&d);
  d.opt.breaking = 0;  // the findings are about shape and stability
  return d;
}

static void case_momentum(gv* v) {
  const char* name = "growth_momentum";
  if (!want(v, name)) return;
  for (int model = VD_GROWTH_MSS; model <= VD_GROWTH_MRL; model++) {
    vd_growth_def d = vd_growth_def_default();
    d.model = (vd_growth_model)model;
    d.substeps = 20;
    d.opt.wind = vd_v3(10, 0, 0);
    result r = grow(v, &d, 5);
    if (!vd_validate_add(&v->list, name, "discrete", "relative momentum change", r.ok ? r.s.momentum_error : NAN, 0,
                         1e-12, 1, "%s, data/tree.lpy 5 years in 10 m/s wind: eq. 1 at growth, mass update%s",
                         vd_growth_model_name(d.model), model == VD_GROWTH_MRL ? ", eqs. 6-7 at joins" : ""))
      v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  }
}

// A straight stem grown in one age step (40 internodes, 1 m, radius 1 cm, green wood: E 1 GPa,
// 1000 kg/m^3), clamped at its base. Sideways gravity makes it a horizontal cantilever under its
// own weight q = rho pi r^2 g: tip sag q L^4 / (8 E I) and clamp stress (q L^2 / 2) r / I
// (Euler-Bernoulli); a uniform wind on its projected area w = rho_air C_d r u^2 gives the clamp
// stress (w L^2 / 2) r / I. The masses it carries in its first year are those it has (the seed
// keeps new nodes at the smallest mass for the whole age step: 1.3 % of the sag).
static const char stem_lpy[] =
    "N = 40\nL = 1.0\nR = 0.01\nLABELS = {1: \"trunk\"}\nmodule A, I\nAxiom: SetWidth(R) A\n"
    "derivation length: 1\nproduction:\nA :\n    for k in range(N):\n        nproduce I(L / N)\n    produce\n"
    "interpretation:\nI(l) --> SetAge(0) ;(1) F(l, R)\nendlsystem\n";

static void case_grown_stem(gv* v) {
  if (!want(v, "growth_stem_self_weight growth_stem_wind")) return;
  vd_lsystem* ls = NULL;
  vd_error e = {0};
  if (vd_lsys_parse(stem_lpy, strlen(stem_lpy), "stem.lpy", &ls, &e)) {
    v->st = vd_error_set(v->err, e.status ? e.status : VD_ERR_VALUE, "", 0, 0, "validate: the stem: %s", e.msg);
    return;
  }
  const double len = 1, r = 0.01, g = 9.81, u = 10;
  vd_growth_def d = vd_growth_def_default();
  d.model = VD_GROWTH_MSS;
  d.substeps = 500;
  d.opt.breaking = 0;
  double ei = d.mss.young_green * VD_PI * r * r * r * r / 4, in = VD_PI * r * r * r * r / 4;
  d.opt.gravity = vd_v3(g, 0, 0);
  result a = grow_on(ls, &d, 1);
  double q = d.mss.density_green * VD_PI * r * r * g;
  int ok = 1;
  ok &= vd_validate_add(&v->list, "growth_stem_self_weight", "continuum", "tip sag (m)", a.ok ? a.s.tip_displacement : NAN,
                        q * pow(len, 4) / (8 * ei), 0.05, 0,
                        "straight stem grown sideways in 1 year, 40 internodes, 500 substeps: q L^4 / (8 E I) (mass "
                        "lumped at internode ends, ~1/N)");
  ok &= vd_validate_add(&v->list, "growth_stem_self_weight", "continuum", "clamp stress (Pa)", a.ok ? a.s.max_stress : NAN,
                        q * len * len / 2 * r / in, 0.05, 0, "the same: (q L^2 / 2) r / I");
  d.opt.gravity = vd_v3(0, 0, 0);
  d.opt.wind = vd_v3(u, 0, 0);
  result b = grow_on(ls, &d, 1);
  double w = 0.5 * d.opt.air_density * d.opt.drag_cd * 2 * r * u * u;
  ok &= vd_validate_add(&v->list, "growth_stem_wind", "continuum", "clamp stress (Pa)", b.ok ? b.s.max_stress : NAN,
                        w * len * len / 2 * r / in, 0.02, 0,
                        "the stem upright in a uniform 10 m/s wind, C_d 1.2 on 2 r l: (w L^2 / 2) r / I");
  ok &= vd_validate_add(&v->list, "growth_stem_wind", "continuum", "tip deflection (m)", b.ok ? b.s.tip_displacement : NAN,
                        w * pow(len, 4) / (8 * ei), 0.02, 0, "the same: w L^4 / (8 E I)");
  if (!ok) v->st = vd_error_set(v->err, VD_ERR_NOMEM, "", 0, 0, "validate: out of memory");
  vd_lsys_destroy(ls);
}

// seed sec. 4.1: MRL-Tree markedly more rigid than ML-Tree under gravity
static void case_stiffer(gv* v) {
  const char* name = "finding_mrl_stiffer";
  if (!want(v, "finding_mrl_stiffer improved_rods_sag improved_rods_standing")) return;
  vd_growth_def ml = base_def(VD_GROWTH_MSS, 1), mrl = base_def(VD_GROWTH_MRL, 1);
  result a = grow(v, &ml, 8), b = grow(v, &mrl, 8);
  double ratio = a.ok && b.ok && b.s.max_displacement > 0 ? a.s.max_displacement / b.s.max_displacement : NAN;
  char note[160];
  snprintf(note, sizeof note, "paper settings, gravity, 8 years: largest sag ML %.4f m, MRL %.4f m", a.s.max_displacement,
           b.s.max_displacement);
  finding(v, name, "sag ML / sag MRL", ratio, 1, 1, note);
  // the improved models, side by side
  vd_growth_def mli = base_def(VD_GROWTH_MSS, 0), mrli = base_def(VD_GROWTH_MRL, 0), rods = base_def(VD_GROWTH_RODS, 0);
  result c = grow(v, &mli, 8), e = grow(v, &mrli, 8), f = grow(v, &rods, 8);
  snprintf(note, sizeof note, "improved, gravity: tip sag ML %.4f m, MRL %.4f m, rods %.4f m", c.s.tip_displacement,
           e.s.tip_displacement, f.s.tip_displacement);
  finding(v, "improved_rods_sag", "tip sag rods / tip sag MRL", e.ok && f.ok && e.s.tip_displacement > 0 ? f.s.tip_displacement / e.s.tip_displacement : NAN, 1, 1, note);
  finding(v, "improved_rods_standing", "height / rest height, rods", f.ok && f.s.height0 > 0 ? f.s.height / f.s.height0 : NAN,
          0.5, 1, "the rods on the same tree under gravity do not collapse (above half the rest height)");
}

// seed sec. 4.2: both models bend toward a light and upward under gravitropism
static void case_tropisms(gv* v) {
  const char* name = "finding_tropisms finding_phototropism finding_gravitropism";
  if (!want(v, name)) return;
  for (int model = VD_GROWTH_MSS; model <= VD_GROWTH_MRL; model++) {
    vd_growth_def d0 = base_def((vd_growth_model)model, 1);
    result r0 = grow(v, &d0, 6);
    vd_growth_def dl = d0;
    dl.opt.light = 1, dl.opt.light_pos = vd_v3(10, 0, 3), dl.opt.light_k = 20;
    result rl = grow(v, &dl, 6);
    vd_growth_def dg = d0;
    dg.opt.gravitropism = VD_MSS_GRAVI_SINE, dg.opt.gravi_k = 0.05;
    result rg = grow(v, &dg, 6);
    char note[160];
    snprintf(note, sizeof note, "%s, paper settings, 6 years, light at (10, 0, 3) m, K 20 N m^2: buds' mean x vs none",
             vd_growth_model_name(d0.model));
    finding(v, "finding_phototropism", "buds' mean shift toward the light (m)", rl.ok && r0.ok ? rl.tip_mean.x - r0.tip_mean.x : NAN, 0, 1,
            note);
    snprintf(note, sizeof note, "%s, paper settings, 6 years, sine law K 0.05 N: buds' mean height vs none",
             vd_growth_model_name(d0.model));
    finding(v, "finding_gravitropism", "buds' mean rise (m)", rg.ok && r0.ok ? rg.tip_mean.z - r0.tip_mean.z : NAN, 0, 1, note);
  }
}

// height over the height the turtle draws (collapse is judged on it)
static double rel_height(const result* r) {
  return r->ok && r->s.drawn_height > 0 && !r->s.diverged ? r->s.height / r->s.drawn_height : NAN;
}

// seed sec. 3.1.3: eq. 3 realistic over a wider range of spring constants and damping than eq. 4
static void case_stability(gv* v) {
  const char* name = "finding_eq3_wider_than_eq4";
  if (!want(v, name)) return;
  double k0s[4] = {1e3, 1e4, 1e5, 1e6}, cs[4] = {0, 0.3, 1, 3};
  int stable[2] = {0, 0};
  for (int q = 0; q < 2; q++)
    for (int a = 0; a < 4; a++)
      for (int b = 0; b < 4; b++) {
        vd_growth_def d = base_def(VD_GROWTH_MSS, 1);
        d.opt.integrator = q ? VD_MSS_EQ4 : VD_MSS_EQ3;
        d.mss.k0_wood = k0s[a], d.mss.k0_green = k0s[a] / 10, d.mss.damping = cs[b];
        result r = grow(v, &d, 5);
        // realistic: no non-finite substep, standing, sag below a tenth of the height
        stable[q] += r.ok && !r.s.unstable && !r.s.collapsed && r.s.max_displacement < 0.1 * r.s.height0;
      }
  char note[160];
  snprintf(note, sizeof note, "paper springs, 5 years, k0 1e3..1e6 N/m x c 0..3 (16 pairs): eq. 3 %d, eq. 4 %d realistic",
           stable[0], stable[1]);
  finding(v, name, "realistic pairs eq. 3 - eq. 4", stable[0] - stable[1], 0, 1, note);
}

// under wind (roots in loam, 15 m/s): the improved models stand (the seed's ML-Tree collapsed;
// with its own settings ours sways as much as MRL and stands: docs/validation.md)
static void case_wind(gv* v) {
  const char* name = "improved_wind";
  if (!want(v, name)) return;
  vd_growth_def mli = base_def(VD_GROWTH_MSS, 0), mrli = base_def(VD_GROWTH_MRL, 0);
  vd_soil_preset("loam", &mli.mss.soil), vd_soil_preset("loam", &mrli.mss.soil);
  mli.opt.wind = mrli.opt.wind = vd_v3(15, 0, 0);
  result c = grow(v, &mli, 8), e = grow(v, &mrli, 8);
  double hc = rel_height(&c), he = rel_height(&e);
  char note[160];
  snprintf(note, sizeof note, "improved, loam, 15 m/s, 8 years: height / drawn ML %.2f, MRL %.2f", hc, he);
  finding(v, name, "smaller height / drawn of ML and MRL", fmin(hc, he), VD_GROWTH_COLLAPSE, 1, note);
}

// the soil's anchorage: in 15 m/s the tree in loam (method 2) stands with its crown's anchorage
// far from used; in the same loam by method 1 (eq. 12 gives millinewtons per node) the root
// plate gives way, the tree tips over and is uprooted
static void case_anchorage(gv* v) {
  if (!want(v, "improved_anchorage_loam improved_anchorage_weak")) return;
  vd_growth_def a = base_def(VD_GROWTH_MRL, 0), b = base_def(VD_GROWTH_MRL, 0);
  vd_soil_preset("loam", &a.mss.soil), vd_soil_preset("loam", &b.mss.soil);
  b.mss.soil.method = VD_SOIL_PANG2023;
  a.opt.wind = b.opt.wind = vd_v3(15, 0, 0);
  result ra = grow(v, &a, 8), rb = grow(v, &b, 8);
  char note[200];
  snprintf(note, sizeof note, "improved MRL, 15 m/s, 8 years: loam method 2 anchorage used %.2g, height / drawn %.2f",
           ra.s.anchor_load, rel_height(&ra));
  finding(v, "improved_anchorage_loam", "largest share of the anchorage used", ra.ok && !ra.s.anchor_failed ? ra.s.anchor_load : NAN,
          1, -1, note);
  snprintf(note, sizeof note, "improved MRL, 15 m/s, 8 years: loam method 1 anchorage used %.3g, uprooted %d, height / drawn %.2f",
           rb.s.anchor_load, rb.s.uprooted, rel_height(&rb));
  finding(v, "improved_anchorage_weak", "height / drawn height, uprooted", rb.ok && rb.s.uprooted ? rel_height(&rb) : NAN,
          VD_GROWTH_COLLAPSE, -1, note);
}

// seed sec. 3.4: method 2 (pedotransfer) steadier than method 1 (cone penetration)
static void case_soil(gv* v) {
  const char* name = "finding_soil_methods";
  if (!want(v, name)) return;
  double disp[2] = {NAN, NAN};
  for (int meth = 0; meth < 2; meth++) {
    vd_growth_def d = base_def(VD_GROWTH_MSS, 1);
    vd_soil_preset("singapore-residual", &d.mss.soil);
    d.mss.soil.method = meth ? VD_SOIL_IMHOFF2016 : VD_SOIL_PANG2023;
    result r = grow(v, &d, 8);
    if (r.ok) disp[meth] = r.s.max_displacement;
  }
  char note[160];
  snprintf(note, sizeof note, "paper settings, Singapore residual soil, gravity, 8 years: largest move method 1 %.3f m, 2 %.3f m",
           disp[0], disp[1]);
  finding(v, name, "move with method 1 / with method 2", disp[1] > 0 ? disp[0] / disp[1] : NAN, 1, 1, note);
}

// the seed's own tree: Hopea odorata, 25 years (data/hopea.lpy, one internode a year, the
// seed's unit of age), the wood of the species, roots in Singapore's residual soil
static vd_growth_def hopea_def(vd_growth_model model, int paper) {
  vd_growth_def d = base_def(model, paper);
  vd_wood w;
  if (vd_wood_species("hopea-odorata", &w) == VD_OK)
    d.mss.young_wood = w.young, d.mss.density_wood = w.density, d.mss.mor = w.mor;
  vd_soil_preset("singapore-residual", &d.mss.soil);
  return d;
}

// parse data/hopea.lpy once; 0 on failure
static int hopea_ready(gv* v) {
  vd_error e = {0};
  if (!v->hopea && vd_lsys_parse(growth_hopea_lpy, strlen(growth_hopea_lpy), "data/hopea.lpy", &v->hopea, &e)) {
    v->st = vd_error_set(v->err, e.status ? e.status : VD_ERR_VALUE, "", 0, 0, "validate: data/hopea.lpy: %s", e.msg);
    return 0;
  }
  return 1;
}

// seed sec. 3.1.3: eq. 5 "not always able to achieve stability across all portions of the
// tree". With c sqrt(k (m1 + m2)) a new bud (the smallest mass) on a heavy node is damped far
// beyond critical (zeta = c (m1 + m2) / (2 sqrt(m1 m2))), and eq. 3 takes damping explicitly
static void case_hopea_eq5(gv* v) {
  if (!want(v, "finding_hopea_eq5_unstable") || !hopea_ready(v)) return;
  char note[200];
  vd_growth_def d = hopea_def(VD_GROWTH_MSS, 1);
  result a = grow_on(v->hopea, &d, 3);
  d.mss.damping = 0;
  result b = grow_on(v->hopea, &d, 3);
  snprintf(note, sizeof note, "paper settings (eq. 3, eq. 5 c = 1), 3 years: largest move %.3g m of %.2f m; with c = 0 %.3g m",
           a.s.max_displacement, a.s.height0, b.s.max_displacement);
  double q = a.ok && a.s.height0 > 0 ? (isfinite(a.s.max_displacement) ? a.s.max_displacement / a.s.height0 : INFINITY) : NAN;
  finding(v, "finding_hopea_eq5_unstable", "largest move / rest height", q, 2, 1, note);
}

// the rest with the paper's springs, wind load, Stokes drag and eq. 8, stepped implicitly (eq. 3
// diverges on this tree)
static void hopea_paper_pair(vd_growth_def* ml, vd_growth_def* mrl) {
  *ml = hopea_def(VD_GROWTH_MSS, 1), *mrl = hopea_def(VD_GROWTH_MRL, 1);
  ml->opt.integrator = mrl->opt.integrator = VD_MSS_IMPLICIT;
}

// seed sec. 4.1 on its own tree: MRL more rigid than ML under gravity
static void case_hopea_stiffer(gv* v) {
  if (!want(v, "finding_hopea_mrl_stiffer") || !hopea_ready(v)) return;
  char note[200];
  vd_growth_def ml, mrl;
  hopea_paper_pair(&ml, &mrl);
  result gm = grow_on(v->hopea, &ml, 25), gr = grow_on(v->hopea, &mrl, 25);
  snprintf(note, sizeof note, "paper springs, implicit, gravity, 25 years: largest move ML %.3f m, MRL %.3f m (height %.1f m)",
           gm.s.max_displacement, gr.s.max_displacement, gm.s.height0);
  finding(v, "finding_hopea_mrl_stiffer", "move ML / move MRL", gm.ok && gr.ok && gr.s.max_displacement > 0 ? gm.s.max_displacement / gr.s.max_displacement : NAN, 1, 1, note);
}

// seed sec. 4.3: in wind the ML-Tree collapses where the MRL-Tree holds (wind on the
// internodes' projected areas and the leaves: eq. 10 on node cross-sections barely loads a tree)
static void case_hopea_wind(gv* v) {
  if (!want(v, "finding_hopea_wind_ml_collapses finding_hopea_wind_mrl_holds") || !hopea_ready(v)) return;
  char note[200];
  vd_growth_def ml, mrl;
  hopea_paper_pair(&ml, &mrl);
  ml.opt.wind_model = mrl.opt.wind_model = VD_MSS_WIND_AREA;
  ml.opt.wind = mrl.opt.wind = vd_v3(15, 0, 0);
  result wm = grow_on(v->hopea, &ml, 25), wr = grow_on(v->hopea, &mrl, 25);
  snprintf(note, sizeof note, "paper springs, implicit, 15 m/s, 25 years: height / drawn ML %.2f (%.1f of %.1f m), MRL %.2f",
           rel_height(&wm), wm.s.height, wm.s.drawn_height, rel_height(&wr));
  finding(v, "finding_hopea_wind_ml_collapses", "height / drawn height, ML", rel_height(&wm), VD_GROWTH_COLLAPSE, -1, note);
  finding(v, "finding_hopea_wind_mrl_holds", "height / drawn height, MRL", rel_height(&wr), VD_GROWTH_COLLAPSE, 1, note);
}

// the improved models in the same wind and soil
static void case_hopea_improved(gv* v) {
  if (!want(v, "improved_hopea_wind") || !hopea_ready(v)) return;
  char note[200];
  vd_growth_def mli = hopea_def(VD_GROWTH_MSS, 0), mrli = hopea_def(VD_GROWTH_MRL, 0);
  mli.opt.wind = mrli.opt.wind = vd_v3(15, 0, 0);
  mli.opt.breaking = mrli.opt.breaking = 1;
  result im = grow_on(v->hopea, &mli, 25), ir = grow_on(v->hopea, &mrli, 25);
  snprintf(note, sizeof note, "improved, 15 m/s, breaking on, 25 years: height / drawn ML %.2f, MRL %.2f; tip sway ML %.2f m, MRL %.3f m",
           rel_height(&im), rel_height(&ir), im.s.tip_displacement, ir.s.tip_displacement);
  finding(v, "improved_hopea_wind", "smaller height / drawn of ML and MRL", fmin(rel_height(&im), rel_height(&ir)), VD_GROWTH_COLLAPSE, 1,
          note);
}

vd_status vd_growth_validate(const vd_validate_def* def, vd_validate_result** out, int* n, vd_error* err) {
  gv v;
  memset(&v, 0, sizeof v);
  v.def = def;
  v.err = err;
  *out = NULL;
  *n = 0;
  int any = 0;
  const char* names[] = {"growth_momentum", "growth_stem_self_weight", "growth_stem_wind", "finding_mrl_stiffer", "improved_rods_sag", "improved_rods_standing",
                         "finding_phototropism", "finding_gravitropism", "finding_tropisms",
                         "finding_eq3_wider_than_eq4", "improved_wind", "improved_anchorage_loam",
                         "improved_anchorage_weak", "finding_soil_methods",
                         "finding_hopea_eq5_unstable", "finding_hopea_mrl_stiffer", "finding_hopea_wind_ml_collapses",
                         "finding_hopea_wind_mrl_holds", "improved_hopea_wind"};
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) any |= !def->filter || strstr(names[k], def->filter);
  if (!any) return VD_OK;
  vd_status st = vd_lsys_parse(growth_tree_lpy, strlen(growth_tree_lpy), "data/tree.lpy", &v.ls, err);
  if (st) return st;
  case_momentum(&v);
  case_grown_stem(&v);
  if (def->full) {
    case_stiffer(&v);
    case_tropisms(&v);
    case_stability(&v);
    case_wind(&v);
    case_anchorage(&v);
    case_soil(&v);
    case_hopea_eq5(&v);
    case_hopea_stiffer(&v);
    case_hopea_wind(&v);
    case_hopea_improved(&v);
  }
  vd_lsys_destroy(v.ls);
  vd_lsys_destroy(v.hopea);
  if (v.st) {
    vd_free(v.list.r, (size_t)v.list.cap * sizeof(vd_validate_result));
    return v.st;
  }
  return vd_validate_finish(&v.list, out, n, err);
}
