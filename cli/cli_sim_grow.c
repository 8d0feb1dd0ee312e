// SPDX-License-Identifier: MIT
// verdant sim PLANT --grow: grow a plant by its L-system with physics between the age steps
// (mass-spring tree, with a rigid part, or rods); a snapshot per age step, events, a summary.
#define _POSIX_C_SOURCE 200809L
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

static const char* grow_help =
    "usage: verdant sim PLANT.lpy --grow [-o RUN/] [--stats] [options]\n"
    "\n"
    "Grow the plant by its L-system, one derivation step per unit of age, with physics between\n"
    "the steps (Lim & Gobeawan 2024, ML-Tree and MRL-Tree): each age step is followed by\n"
    "--substeps physics substeps, the state carried to the grown plant; stress per node and\n"
    "internode, branches that break, roots that give way. 'verdant render RUN/' draws the ages.\n"
    "\n"
    "Options apply in any order (--paper, --soil and --species are presets applied first);\n"
    "an option that does not apply to the run (--clay without a soil, --k0 without --springs\n"
    "paper, --rigid-age without --model mrl, ...) is an error.\n"
    "\n"
    "growth:\n"
    "      --grow              this mode\n"
    "      --ages N            age steps, default the file's derivation length (or -n)\n"
    "      --substeps S        physics substeps per age step, default 50 (the paper's)\n"
    "      --dt H              substep (s), default 0.01\n"
    "      --model M           mrl (mass-spring with a rigid part, MRL-Tree; default), mss\n"
    "                          (mass-spring, ML-Tree) or rods (verdant's Cosserat rods)\n"
    "      --paper             the paper's own choices: --springs paper --integrator eq3\n"
    "                          --wind-model paper --drag stokes, eq. 8 as printed, no strain\n"
    "                          limit, no stress-free growth, C_d 1, masses updated at the end\n"
    "                          of each age step (other options override it wherever they are)\n"
    "      --springs S         material (E A / l and hinges E I / l; default) or paper (k0 d / l\n"
    "                          and springs between alternate nodes)\n"
    "      --integrator I      implicit (default), eq3 (Kang 2001) or eq4 (Kang 2000)\n"
    "      --rigid-age A       mrl: nodes at least A years old join the rigid body, default 3\n"
    "      --woody-age A       internodes at least A years old are wood, default 1\n"
    "      --k0 GREEN,WOOD     paper springs: k0 of eq. 2 (N/m), default 1e4,1e5\n"
    "      --damping C         c of eq. 5, default 1 (critical for equal masses)\n"
    "      --species NAME      wood: generic-broadleaf (default) or hopea-odorata (E, density,\n"
    "                          modulus of rupture; sources in docs/physics.md)\n"
    "      --young GREEN,WOOD  Young's modulus (Pa), default 1e9,1e10\n"
    "      --density GREEN,WOOD  density (kg/m^3), default 1000,900\n"
    "      --mor GREEN,WOOD    modulus of rupture (Pa), default 1.5e7,5.5e7; 'inf' never breaks\n"
    "      --no-breaking       nothing breaks\n"
    "      --eq8 F             mrl: paper (eq. 8 as printed) or corrected (default)\n"
    "      --no-stress-free    carry deformation into new wood as elastic (default: new wood\n"
    "                          grows without stress on the bent tree)\n"
    "      --strain-limit E    internodes stretched more than E after a substep are put back\n"
    "                          (default 1e-4; 0 off)\n"
    ;
static const char* grow_help_forces =
    "forces:\n"
    "      --gravity X,Y,Z     gravity (m/s^2), default 0,0,-9.81\n"
    "      --wind X,Y,Z        mean wind (m/s); pressure 0.613 |v|^2 Pa (eq. 9)\n"
    "      --gust A,P          gusts: wind * (1 + A sin(2 pi t / P)), P in s\n"
    "      --wind-file CSV     wind time series t,vx,vy,vz (s, m/s), as 'verdant sim'\n"
    "      --wind-model M      area (default: internodes' projected area and leaves, relative\n"
    "                          air velocity) or paper (eq. 10 on each node's cross-section)\n"
    "      --drag D            quadratic (default), stokes (eq. 11) or none\n"
    "      --cd C, --leaf-cd C drag coefficients of internodes (1.2) and leaf area (0.1)\n"
    "      --light X,Y,Z[:K]   phototropism toward a light point, K / d^2 on buds (K N m^2, 1)\n"
    "      --gravitropism G    none (default), sine[:K] (the paper: K sin A across internodes, K\n"
    "                          N, default 0.1) or bastien[:BETA,GAMMA] (Bastien et al. 2013:\n"
    "                          dC/dt = -BETA sin A - GAMMA C on the rest shape; 0.5,1 per m and\n"
    "                          year)\n"
    "soil (roots below the ground):\n"
    "      --soil S            clamp (roots held; default), loam, sandy-loam, clay,\n"
    "                          singapore-residual\n"
    "      --soil-method M     imhoff (eqs. 13-14; default for a soil) or pang (eq. 12)\n"
    "      --clay P, --organic P, --water THETA, --bulk-density BD, --poisson MU\n"
    "                          the soil's composition (%, %, m^3/m^3, Mg/m^3, -)\n"
    "      --ptf C0,C1,C2,D0,D1,D2,E0,E1  method 2 coefficients (ln SR in MPa)\n"
    "      --uproot-tilt DEG   a base tilted this far after its roots gave way is uprooted (10)\n";
static const char* grow_help_output =
    "output:\n"
    "  -o, --output RUN/       RUN/growth.json (index), RUN/age_000.json ... (the plant at each\n"
    "                          age with stress per node and segment), RUN/events.csv,\n"
    "                          RUN/plant.json (the final plant)\n"
    "      --ply               also RUN/age_NNN.ply meshes with a per-vertex stress property\n"
    "      --final FILE        also write the final plant as .json, .obj or .ply\n"
    "      --stats             JSON summary on stdout: height, max_displacement, max_stress,\n"
    "                          broken_branches, uprooted, collapsed, momentum_error, ...; the\n"
    "                          same bytes for the same inputs\n"
    "      --profile           --stats adds wall_seconds (a timing, which differs per run)\n";

// options given (for the checks that each applies to the run, whatever their order)
enum {
  G_SOIL_METHOD, G_CLAY, G_ORGANIC, G_WATER, G_BULK, G_POISSON, G_PTF, G_UPROOT, G_RIGID_AGE, G_EQ8, G_K0,
  G_SPRINGS, G_INTEGRATOR, G_DAMPING, G_STRAIN, G_WIND_MODEL, G_DRAG, G_LIGHT, G_GRAVI, G_YOUNG, G_LEAF_CD,
  G_PAPER, G_CD, G_NOPT
};
static const char* const g_names[G_NOPT] = {
    "--soil-method", "--clay", "--organic", "--water", "--bulk-density", "--poisson", "--ptf", "--uproot-tilt",
    "--rigid-age", "--eq8", "--k0", "--springs", "--integrator", "--damping", "--strain-limit", "--wind-model",
    "--drag", "--light", "--gravitropism", "--young", "--leaf-cd", "--paper", "--cd"};

typedef struct grow_opts {
  cli_plant_opts po;
  const char* out;
  const char* final;
  const char* wind_file;
  int stats, ply, ages, profile;
  vd_growth_def def;
  // presets, applied before every other option (pass 0 finds them)
  int paper;
  const char* soil;
  const char* species;
  int seen[G_NOPT];
} grow_opts;

// "a,b" or "a,b,c" -> numbers; 'inf' allowed where inf is set
static int nums(const char* s, double* v, int n, int inf) {
  char buf[256];
  if (!s || strlen(s) >= sizeof buf) return 0;
  strcpy(buf, s);
  char* p = buf;
  for (int i = 0; i < n; i++) {
    char* c = i < n - 1 ? strchr(p, ',') : NULL;
    if (i < n - 1 && !c) return 0;
    if (c) *c = 0;
    if (inf && (!strcmp(p, "inf") || !strcmp(p, "INF"))) v[i] = INFINITY;
    else if (!cli_parse_num(p, &v[i]) || !isfinite(v[i])) return 0;
    p = c ? c + 1 : p + strlen(p);
  }
  return 1;
}

// one pass over the options: the first checks them all and finds the presets (--paper, --soil,
// --species), the second applies every other option over the presets, so order never matters
static int parse_pass(int argc, char** argv, grow_opts* o) {
  const char* cmd = "sim --grow";
  vd_growth_def* d = &o->def;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    int r = cli_plant_opt(&o->po, "sim", argc, argv, &i);
    if (r < 0) return EXIT_USAGE;
    if (r > 0) continue;
    const char* val = NULL;
#define PAIR(d0, d1, cond, what, inf)                                                              \
  do {                                                                                             \
    CLI_VAL();                                                                                     \
    double v_[2];                                                                                  \
    if (!nums(val, v_, 2, inf) || !(cond))                                                         \
      return cli_usage_error(cmd, "%s expects %s, got '%s'", a, what, val);                        \
    (d0) = v_[0], (d1) = v_[1];                                                                    \
  } while (0)
    if (!strcmp(a, "--grow")) {
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      CLI_VAL();
      o->out = val;
    } else if (!strcmp(a, "--final")) {
      CLI_VAL();
      if (!cli_has_ext(val, ".json") && !cli_has_ext(val, ".obj") && !cli_has_ext(val, ".ply"))
        return cli_usage_error(cmd, "--final '%s': unknown format (use .json, .obj or .ply)", val);
      o->final = val;
    } else if (!strcmp(a, "--stats")) {
      o->stats = 1;
    } else if (!strcmp(a, "--profile")) {
      o->profile = 1;
    } else if (!strcmp(a, "--ply")) {
      o->ply = 1;
    } else if (!strcmp(a, "--ages")) {
      double x;
      CLI_NUM(x, x_ >= 0 && x_ <= 10000 && x_ == floor(x_),
              "a whole number of age steps in 0..10000");
      o->ages = (int)x;
    } else if (!strcmp(a, "--substeps")) {
      double x;
      CLI_NUM(x, x_ >= 1 && x_ <= 1e7 && x_ == floor(x_), "a whole number of substeps >= 1");
      d->substeps = (int)x;
    } else if (!strcmp(a, "--dt")) {
      CLI_NUM(d->opt.dt, x_ > 0 && x_ <= 1e6, "a time step > 0 (s)");
      d->rod_opt.dt = d->opt.dt;
    } else if (!strcmp(a, "--model")) {
      CLI_VAL();
      if (!strcmp(val, "mss")) d->model = VD_GROWTH_MSS;
      else if (!strcmp(val, "mrl")) d->model = VD_GROWTH_MRL;
      else if (!strcmp(val, "rods")) d->model = VD_GROWTH_RODS;
      else return cli_usage_error(cmd, "--model expects mss, mrl or rods, got '%s'", val);
    } else if (!strcmp(a, "--paper")) {
      o->seen[G_PAPER] = 1;
      o->paper = 1;
    } else if (!strcmp(a, "--springs")) {
      o->seen[G_SPRINGS] = 1;
      CLI_VAL();
      if (!strcmp(val, "material")) d->mss.springs = VD_MSS_MATERIAL;
      else if (!strcmp(val, "paper")) d->mss.springs = VD_MSS_PAPER;
      else return cli_usage_error(cmd, "--springs expects material or paper, got '%s'", val);
    } else if (!strcmp(a, "--integrator")) {
      o->seen[G_INTEGRATOR] = 1;
      CLI_VAL();
      if (!strcmp(val, "implicit")) d->opt.integrator = VD_MSS_IMPLICIT;
      else if (!strcmp(val, "eq3")) d->opt.integrator = VD_MSS_EQ3;
      else if (!strcmp(val, "eq4")) d->opt.integrator = VD_MSS_EQ4;
      else return cli_usage_error(cmd, "--integrator expects implicit, eq3 or eq4, got '%s'", val);
    } else if (!strcmp(a, "--rigid-age")) {
      o->seen[G_RIGID_AGE] = 1;
      CLI_NUM(d->mss.rigid_age, x_ >= 0, "an age >= 0 (years)");
    } else if (!strcmp(a, "--woody-age")) {
      CLI_NUM(d->mss.woody_age, x_ >= 0, "an age >= 0 (years)");
    } else if (!strcmp(a, "--k0")) {
      o->seen[G_K0] = 1;
      PAIR(d->mss.k0_green, d->mss.k0_wood, v_[0] > 0 && v_[1] > 0, "GREEN,WOOD spring constants > 0 (N/m)", 0);
    } else if (!strcmp(a, "--damping")) {
      o->seen[G_DAMPING] = 1;
      CLI_NUM(d->mss.damping, x_ >= 0, "a damping constant c >= 0");
    } else if (!strcmp(a, "--species")) {
      CLI_VAL();
      vd_wood w;
      if (vd_wood_species(val, &w) != VD_OK) {
        char list[256] = "";
        for (int k = 0; k < vd_wood_count(); k++)
          snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", vd_wood_get(k)->name);
        return cli_usage_error(cmd, "--species: unknown species '%s' (known: %s)", val, list);
      }
      o->species = val;
    } else if (!strcmp(a, "--young")) {
      o->seen[G_YOUNG] = 1;
      PAIR(d->mss.young_green, d->mss.young_wood, v_[0] > 0 && v_[1] > 0, "GREEN,WOOD moduli > 0 (Pa)", 0);
    } else if (!strcmp(a, "--density")) {
      PAIR(d->mss.density_green, d->mss.density_wood, v_[0] > 0 && v_[1] > 0, "GREEN,WOOD densities > 0 (kg/m^3)", 0);
    } else if (!strcmp(a, "--mor")) {
      PAIR(d->mss.mor_green, d->mss.mor, v_[0] > 0 && v_[1] > 0, "GREEN,WOOD strengths > 0 (Pa) or inf", 1);
    } else if (!strcmp(a, "--no-breaking")) {
      d->opt.breaking = 0;
    } else if (!strcmp(a, "--eq8")) {
      o->seen[G_EQ8] = 1;
      CLI_VAL();
      if (!strcmp(val, "paper")) d->paper_eq8 = 1;
      else if (!strcmp(val, "corrected")) d->paper_eq8 = 0;
      else return cli_usage_error(cmd, "--eq8 expects paper or corrected, got '%s'", val);
    } else if (!strcmp(a, "--no-stress-free")) {
      d->stress_free = 0;
    } else if (!strcmp(a, "--strain-limit")) {
      o->seen[G_STRAIN] = 1;
      CLI_NUM(d->opt.strain_limit, x_ >= 0 && x_ < 1, "a relative stretch in [0, 1)");
    } else if (!strcmp(a, "--gravity") || !strcmp(a, "--wind")) {
      CLI_VAL();
      double v[3];
      int g = a[2] == 'g';
      double lim = g ? 1e4 : VD_SIM_MAX_WIND;
      if (!nums(val, v, 3, 0) || fabs(v[0]) > lim || fabs(v[1]) > lim || fabs(v[2]) > lim)
        return cli_usage_error(cmd, "%s expects X,Y,Z within +-%g %s, got '%s'", a, lim, g ? "m/s^2" : "m/s", val);
      if (g) d->opt.gravity = d->rods.gravity = d->rod_opt.gravity = vd_v3(v[0], v[1], v[2]);
      else d->opt.wind = d->rod_opt.wind = vd_v3(v[0], v[1], v[2]);
    } else if (!strcmp(a, "--gust")) {
      PAIR(d->opt.gust_amplitude, d->opt.gust_period, v_[1] > 0, "AMPLITUDE,PERIOD (-, s > 0)", 0);
      d->rod_opt.gust_amplitude = d->opt.gust_amplitude, d->rod_opt.gust_period = d->opt.gust_period;
    } else if (!strcmp(a, "--wind-file")) {
      CLI_VAL();
      o->wind_file = val;
    } else if (!strcmp(a, "--wind-model")) {
      o->seen[G_WIND_MODEL] = 1;
      CLI_VAL();
      if (!strcmp(val, "area")) d->opt.wind_model = VD_MSS_WIND_AREA;
      else if (!strcmp(val, "paper")) d->opt.wind_model = VD_MSS_WIND_PAPER;
      else return cli_usage_error(cmd, "--wind-model expects area or paper, got '%s'", val);
    } else if (!strcmp(a, "--drag")) {
      o->seen[G_DRAG] = 1;
      CLI_VAL();
      if (!strcmp(val, "quadratic")) d->opt.drag = VD_MSS_DRAG_QUADRATIC;
      else if (!strcmp(val, "stokes")) d->opt.drag = VD_MSS_DRAG_STOKES;
      else if (!strcmp(val, "none")) d->opt.drag = VD_MSS_DRAG_NONE;
      else return cli_usage_error(cmd, "--drag expects quadratic, stokes or none, got '%s'", val);
      d->rod_opt.drag = d->opt.drag == VD_MSS_DRAG_QUADRATIC;
    } else if (!strcmp(a, "--cd")) {
      o->seen[G_CD] = 1;
      CLI_NUM(d->opt.drag_cd, x_ >= 0, "a drag coefficient >= 0");
    } else if (!strcmp(a, "--leaf-cd")) {
      o->seen[G_LEAF_CD] = 1;
      CLI_NUM(d->opt.leaf_cd, x_ >= 0, "a drag coefficient >= 0");
    } else if (!strcmp(a, "--light")) {
      o->seen[G_LIGHT] = 1;
      CLI_VAL();
      char buf[256];
      if (strlen(val) >= sizeof buf) return cli_usage_error(cmd, "--light: value too long");
      strcpy(buf, val);
      char* colon = strchr(buf, ':');
      double k = 1, v[3];
      if (colon) *colon = 0;
      if (!nums(buf, v, 3, 0) || (colon && (!cli_parse_num(colon + 1, &k) || !isfinite(k))))
        return cli_usage_error(cmd, "--light expects X,Y,Z[:K] (m, N m^2), got '%s'", val);
      d->opt.light = 1, d->opt.light_pos = vd_v3(v[0], v[1], v[2]), d->opt.light_k = k;
    } else if (!strcmp(a, "--gravitropism")) {
      o->seen[G_GRAVI] = 1;
      CLI_VAL();
      double v[2];
      if (!strcmp(val, "none")) {
        d->opt.gravitropism = VD_MSS_GRAVI_NONE;
      } else if (!strncmp(val, "sine", 4) && (!val[4] || (val[4] == ':' && cli_parse_num(val + 5, &v[0]) && isfinite(v[0])))) {
        d->opt.gravitropism = VD_MSS_GRAVI_SINE;
        if (val[4]) d->opt.gravi_k = v[0];
      } else if (!strncmp(val, "bastien", 7) && (!val[7] || (val[7] == ':' && nums(val + 8, v, 2, 0) && v[0] >= 0 && v[1] >= 0))) {
        d->opt.gravitropism = VD_MSS_GRAVI_BASTIEN;
        if (val[7]) d->opt.bastien_beta = v[0], d->opt.bastien_gamma = v[1];
      } else {
        return cli_usage_error(cmd, "--gravitropism expects none, sine[:K] or bastien[:BETA,GAMMA], got '%s'", val);
      }
    } else if (!strcmp(a, "--soil")) {
      CLI_VAL();
      vd_soil so;
      if (vd_soil_preset(val, &so) != VD_OK)
        return cli_usage_error(cmd, "--soil expects clamp, loam, sandy-loam, clay or singapore-residual, got '%s'", val);
      o->soil = val;
    } else if (!strcmp(a, "--soil-method")) {
      o->seen[G_SOIL_METHOD] = 1;
      CLI_VAL();
      if (!strcmp(val, "imhoff")) d->mss.soil.method = VD_SOIL_IMHOFF2016;
      else if (!strcmp(val, "pang")) d->mss.soil.method = VD_SOIL_PANG2023;
      else return cli_usage_error(cmd, "--soil-method expects imhoff or pang, got '%s'", val);
    } else if (!strcmp(a, "--clay")) {
      o->seen[G_CLAY] = 1;
      CLI_NUM(d->mss.soil.clay, x_ >= 0 && x_ <= 100, "a clay content in [0, 100] (%)");
    } else if (!strcmp(a, "--organic")) {
      o->seen[G_ORGANIC] = 1;
      CLI_NUM(d->mss.soil.organic, x_ >= 0 && x_ <= 100,
              "an organic matter content in [0, 100] (%)");
    } else if (!strcmp(a, "--water")) {
      o->seen[G_WATER] = 1;
      CLI_NUM(d->mss.soil.water, x_ > 0 && x_ <= 1,
              "a volumetric water content in (0, 1] (m^3/m^3)");
    } else if (!strcmp(a, "--bulk-density")) {
      o->seen[G_BULK] = 1;
      CLI_NUM(d->mss.soil.bulk_density, x_ > 0 && x_ < 3, "a bulk density in (0, 3) (Mg/m^3)");
    } else if (!strcmp(a, "--poisson")) {
      o->seen[G_POISSON] = 1;
      CLI_NUM(d->mss.soil.poisson, x_ >= 0 && x_ < 0.5, "a Poisson ratio in [0, 0.5)");
    } else if (!strcmp(a, "--ptf")) {
      o->seen[G_PTF] = 1;
      CLI_VAL();
      if (!nums(val, d->mss.soil.ptf, 8, 0)) return cli_usage_error(cmd, "--ptf expects 8 numbers C0,C1,C2,D0,D1,D2,E0,E1, got '%s'", val);
    } else if (!strcmp(a, "--uproot-tilt")) {
      o->seen[G_UPROOT] = 1;
      double deg;
      CLI_NUM(deg, x_ > 0 && x_ < 180, "an angle in (0, 180) (degrees)");
      d->uproot_tilt = deg * VD_PI / 180;
    } else if (a[0] == '-' && a[1]) {
      return cli_usage_error(cmd, "unknown option '%s'", a);
    } else if (!o->po.path) {
      o->po.path = a;
    } else {
      return cli_usage_error(cmd, "unexpected argument '%s'", a);
    }
#undef PAIR
  }
  return EXIT_OK;
}

// an option given where it does not apply: exit 2 naming it and why
static int not_here(const grow_opts* o, int opt, const char* why) {
  if (!o->seen[opt]) return 0;
  cli_usage_error("sim --grow", "%s does not apply here: %s", g_names[opt], why);
  return 1;
}

static int parse_args(int argc, char** argv, grow_opts* o) {
  grow_opts scan = *o;
  int rc = parse_pass(argc, argv, &scan);
  if (rc) return rc;
  // the presets first, in a fixed order; then every other option over them
  vd_growth_def* d = &o->def;
  if (scan.paper) vd_growth_def_paper(d);
  if (scan.soil) {
    double ground = d->mss.soil.ground;
    vd_soil_preset(scan.soil, &d->mss.soil);
    d->mss.soil.ground = ground;
  }
  if (scan.species) {
    vd_wood w;
    vd_wood_species(scan.species, &w);
    d->mss.young_wood = w.young, d->mss.density_wood = w.density, d->mss.mor = w.mor;
  }
  rc = parse_pass(argc, argv, o);
  if (rc) return rc;
  o->paper = scan.paper, o->soil = scan.soil, o->species = scan.species;
  // options that do not apply to this run are errors, not silently ignored
  int soil = o->soil && strcmp(o->soil, "clamp") != 0, rods = d->model == VD_GROWTH_RODS;
  int mrl = d->model == VD_GROWTH_MRL;
  const char* nosoil = "it describes roots in a soil: give --soil loam, sandy-loam, clay or singapore-residual "
                       "(clamp, the default, holds the roots fixed)";
  int opts_soil[] = {G_SOIL_METHOD, G_CLAY, G_ORGANIC, G_WATER, G_BULK, G_POISSON, G_PTF, G_UPROOT};
  for (size_t k = 0; k < sizeof opts_soil / sizeof *opts_soil; k++)
    if (!soil && not_here(o, opts_soil[k], nosoil)) return EXIT_USAGE;
  if (soil && d->mss.soil.method == VD_SOIL_PANG2023) {
    const char* why = "eq. 12 (--soil-method pang) reads only the bulk density and Poisson's ratio";
    if (not_here(o, G_CLAY, why) || not_here(o, G_ORGANIC, why) || not_here(o, G_WATER, why) || not_here(o, G_PTF, why))
      return EXIT_USAGE;
  }
  if (soil && d->mss.soil.method == VD_SOIL_IMHOFF2016 &&
      not_here(o, G_POISSON, "Poisson's ratio is read by eq. 12 only (--soil-method pang)"))
    return EXIT_USAGE;
  if (!mrl && (not_here(o, G_RIGID_AGE, "the rigid part is MRL's: give --model mrl") ||
               not_here(o, G_EQ8, "eq. 8 joins nodes to MRL's rigid part: give --model mrl")))
    return EXIT_USAGE;
  if (rods) {
    const char* why = "it is a setting of the mass-spring models (--model mss or mrl), not of the rods";
    int opts_mss[] = {G_PAPER, G_SPRINGS, G_INTEGRATOR, G_K0, G_DAMPING, G_STRAIN, G_LIGHT, G_GRAVI, G_UPROOT};
    for (size_t k = 0; k < sizeof opts_mss / sizeof *opts_mss; k++)
      if (not_here(o, opts_mss[k], why)) return EXIT_USAGE;
    if (d->opt.wind_model == VD_MSS_WIND_PAPER &&
        not_here(o, G_WIND_MODEL, "the rods load the wind on each segment's projected area (--wind-model area)"))
      return EXIT_USAGE;
    int wind = vd_norm(d->opt.wind) > 0 || o->wind_file;
    if (d->opt.drag == VD_MSS_DRAG_STOKES &&
        not_here(o, G_DRAG, "the rods' air load is quadratic drag on the air's velocity relative to each segment; "
                            "use --drag quadratic (or none without wind)"))
      return EXIT_USAGE;
    if (d->opt.drag == VD_MSS_DRAG_NONE && wind &&
        not_here(o, G_DRAG, "--drag none turns the rods' air load off, wind included: drop --wind or --drag none"))
      return EXIT_USAGE;
  } else {
    if (d->mss.springs != VD_MSS_PAPER &&
        not_here(o, G_K0, "k0 sets the paper's springs (eq. 2, k = k0 d / l): add --springs paper"))
      return EXIT_USAGE;
    if (d->mss.springs == VD_MSS_PAPER &&
        not_here(o, G_YOUNG, "--springs paper takes its stiffness from --k0, not from Young's modulus"))
      return EXIT_USAGE;
  }
  // the seed's wind load (eqs. 9-10) takes C_drag 1 (sec. 3.3) unless --cd says otherwise
  if (d->opt.wind_model == VD_MSS_WIND_PAPER && !o->seen[G_CD]) d->opt.drag_cd = 1;
  // the rods' leaves are plates: --leaf-cd sets their drag coefficient
  if (rods && o->seen[G_LEAF_CD]) d->rods.leaf_plate_cd = d->opt.leaf_cd;
  return EXIT_OK;
}

// ---------------------------------------------------------------------------------------------
// outputs

static vd_status write_text(const char* path, const char* text, vd_error* err) {
  vd_outfile f;
  vd_status st = vd_outfile_open(&f, path, err);
  if (!st) {
    fputs(text, f.fp);
    st = vd_outfile_commit(&f, err);
  }
  return st;
}

static const char* kind_name(int k) { return k == VD_MSS_UPROOT ? "uproot" : k == VD_MSS_ANCHOR ? "anchorage" : "break"; }

static vd_status write_events(const vd_growth* g, const char* dir, vd_error* err) {
  int n;
  const vd_growth_event* ev = vd_growth_events(g, &n);
  size_t cap = 128 + (size_t)n * 160;
  char* text = vd_malloc(cap);
  if (!text) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  size_t len = (size_t)snprintf(text, cap, "kind,age,time_s,node,segment,label,stress_Pa_or_tilt_rad_or_share,limit,removed_nodes\n");
  for (int k = 0; k < n && len < cap; k++)
    len += (size_t)snprintf(text + len, cap - len, "%s,%d,%.6f,%d,%d,%s,%.6g,%.6g,%d\n", kind_name(ev[k].kind), ev[k].age,
                            ev[k].time, ev[k].node, ev[k].segment, ev[k].label, ev[k].stress, ev[k].limit, ev[k].removed);
  char path[4200];
  snprintf(path, sizeof path, "%s/events.csv", dir);
  vd_status st = write_text(path, text, err);
  vd_free(text, cap);
  return st;
}

static cJSON* stats_json(const vd_growth* g, const vd_growth_def* def, double wall) {
  vd_growth_stats s;
  vd_growth_get_stats(g, &s);
  cJSON* o = cJSON_CreateObject();
  if (!o) return NULL;
  cJSON_AddStringToObject(o, "model", vd_growth_model_name(def->model));
  cJSON_AddNumberToObject(o, "ages", s.age);
  cJSON_AddNumberToObject(o, "substeps_per_age", def->substeps);
  cJSON_AddNumberToObject(o, "time", s.time);
  cJSON_AddNumberToObject(o, "height", s.height);
  cJSON_AddNumberToObject(o, "rest_height", s.height0);
  cJSON_AddNumberToObject(o, "drawn_height", s.drawn_height);
  cJSON_AddNumberToObject(o, "max_displacement", s.max_displacement);
  cJSON_AddNumberToObject(o, "tip_displacement", s.tip_displacement);
  cJSON_AddNumberToObject(o, "max_stress", s.max_stress);
  cJSON_AddNumberToObject(o, "broken_branches", s.nbroken);
  cJSON_AddBoolToObject(o, "uprooted", s.uprooted);
  cJSON_AddBoolToObject(o, "anchorage_failed", s.anchor_failed);
  cJSON_AddNumberToObject(o, "anchorage_load", s.anchor_load);
  cJSON_AddBoolToObject(o, "collapsed", s.collapsed);
  cJSON_AddBoolToObject(o, "diverged", s.diverged);
  cJSON_AddNumberToObject(o, "momentum_error", s.momentum_error);
  cJSON_AddNumberToObject(o, "angular_momentum_error", s.angular_error);
  cJSON_AddNumberToObject(o, "nodes", s.nnode);
  cJSON_AddNumberToObject(o, "segments", s.nseg);
  cJSON_AddNumberToObject(o, "physics_nodes", s.nphys);
  cJSON_AddNumberToObject(o, "rigid_nodes", s.nrigid);
  cJSON_AddNumberToObject(o, "total_mass", s.total_mass);
  cJSON_AddNumberToObject(o, "kinetic_energy", s.kinetic_energy);
  cJSON_AddNumberToObject(o, "substeps", (double)s.substeps);
  cJSON_AddNumberToObject(o, "cg_iterations", (double)s.cg_iterations);
  cJSON_AddNumberToObject(o, "unstable_substeps", (double)s.unstable);
  if (wall >= 0) cJSON_AddNumberToObject(o, "wall_seconds", wall);  // --profile
  int n;
  const vd_growth_event* ev = vd_growth_events(g, &n);
  cJSON* arr = cJSON_AddArrayToObject(o, "events");
  for (int k = 0; k < n && k < 1000; k++) {
    cJSON* e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "kind", kind_name(ev[k].kind));
    cJSON_AddNumberToObject(e, "age", ev[k].age);
    cJSON_AddNumberToObject(e, "time", ev[k].time);
    cJSON_AddNumberToObject(e, "segment", ev[k].segment);
    cJSON_AddStringToObject(e, "label", ev[k].label);
    cJSON_AddNumberToObject(e, ev[k].kind == VD_MSS_UPROOT ? "tilt" : ev[k].kind == VD_MSS_ANCHOR ? "share" : "stress",
                            ev[k].stress);
    cJSON_AddNumberToObject(e, "limit", ev[k].limit);
    cJSON_AddItemToArray(arr, e);
  }
  return o;
}

// the plant now into RUN/age_NNN.json (and .ply); an entry of the index
static vd_status snapshot(const vd_growth* g, const grow_opts* o, cJSON* list, vd_error* err) {
  vd_plant_spec* p = NULL;
  vd_status st = vd_growth_plant(g, &p, err);
  if (st) return st;
  for (int i = 0; !st && i < o->po.nlabel; i++) {
    const char* eq = strchr(o->po.label[i], '=');
    st = vd_plant_set_label(p, (int)strtol(o->po.label[i], NULL, 10), eq + 1);
  }
  char name[64], path[4200];
  int age = vd_growth_age(g);
  snprintf(name, sizeof name, "age_%03d.json", age);
  snprintf(path, sizeof path, "%s/%s", o->out, name);
  if (!st) st = cli_write_plant(p, path, 0, err);
  if (!st && o->ply) {
    snprintf(path, sizeof path, "%s/age_%03d.ply", o->out, age);
    st = cli_write_plant(p, path, 0, err);
  }
  vd_plant_spec_destroy(p);
  if (st) return st;
  vd_growth_stats s;
  vd_growth_get_stats(g, &s);
  cJSON* e = cJSON_CreateObject();
  cJSON_AddNumberToObject(e, "age", age);
  cJSON_AddNumberToObject(e, "time", s.time);
  cJSON_AddStringToObject(e, "file", name);
  cJSON_AddNumberToObject(e, "height", s.height);
  cJSON_AddNumberToObject(e, "max_stress", s.max_stress);
  cJSON_AddNumberToObject(e, "broken_branches", s.nbroken);
  cJSON_AddItemToArray(list, e);
  return VD_OK;
}

static void progress_bar(int age, int ages, const vd_growth* g) {
  int w = 30, fill = ages > 0 ? age * w / ages : w;
  char bar[64];
  for (int k = 0; k < w; k++) bar[k] = k < fill ? '#' : ' ';
  bar[w] = 0;
  vd_growth_stats s;
  vd_growth_get_stats(g, &s);
  fprintf(stderr, "\rgrowing [%s] age %d / %d, %d nodes", bar, age, ages, s.nphys);
  fflush(stderr);
}

int cli_sim_grow(int argc, char** argv) {
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
      fputs(grow_help, stdout);
      fputs(grow_help_forces, stdout);
      fputs(grow_help_output, stdout);
      fputs(cli_plant_help, stdout);
      return EXIT_OK;
    }
  grow_opts o;
  memset(&o, 0, sizeof o);
  cli_plant_opts_init(&o.po);
  o.def = vd_growth_def_default();
  o.ages = -1;
  int rc = parse_args(argc, argv, &o);
  if (rc) return rc;
  const char* cmd = "sim --grow";
  if (!o.po.path) return cli_usage_error(cmd, "missing PLANT (an .lpy file: the L-system grows it)");
  if (!cli_has_ext(o.po.path, ".lpy"))
    return cli_usage_error(cmd, "'%s': --grow needs an .lpy file (the L-system grows the plant step by step)", o.po.path);
  if (!o.out && !o.stats && !o.final) return cli_usage_error(cmd, "nothing to do: give -o RUN/, --final FILE and/or --stats");
  if (o.profile && !o.stats) return cli_usage_error(cmd, "--profile adds timings to --stats; give --stats");
  if (o.ply && !o.out) return cli_usage_error(cmd, "--ply writes into the run folder: give -o RUN/");
  // the files: the model and the wind series read; the growth run folder (an earlier run's ages
  // that this one does not write go when it completes) and --final written
  static const char* const members[] = {"growth.json", "events.csv", "plant.json", "age_*.json", "age_*.ply"};
  cli_out_plant_opts(&o.po);
  cli_out_input("--wind-file", o.wind_file);
  if (o.out) cli_out_folder("-o", o.out, members, 5, 1);
  if (o.final) cli_out_plant("--final", o.final);
  if (cli_out_check(cmd)) return EXIT_USAGE;
  vd_error err = {0};
  vd_lsystem* ls = NULL;
  vd_growth* g = NULL;
  double* wind = NULL;
  int nwind = 0, code = EXIT_OK;
  cJSON* index = NULL;
  vd_status st = cli_load_lsystem(&o.po, &ls, &err);
  if (!st && o.wind_file) st = vd_sim_read_wind(o.wind_file, &wind, &nwind, &err);
  int ages = o.ages >= 0 ? o.ages : o.po.steps >= 0 ? o.po.steps : st ? 0 : vd_lsys_derivation_length(ls);
  o.def.ages = ages;
  o.def.lsys.seed = o.po.seed;
  o.def.lsys.max_modules = o.po.max_modules;
  o.def.lsys.max_ops = o.po.max_ops;
  o.def.opt.wind_series = o.def.rod_opt.wind_series = wind;
  o.def.opt.nwind = o.def.rod_opt.nwind = nwind;
  if (!st) st = vd_growth_create(ls, &o.def, &g, &err);
  cli_blame_input(&err, o.po.path);
  if (st) {
    code = cli_report(cmd, &err, st);
    goto done;
  }
  index = cJSON_CreateObject();
  cJSON* snaps = cJSON_CreateArray();
  if (!index || !snaps) {
    cJSON_Delete(snaps);
    code = cli_report(cmd, &err, vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory"));
    goto done;
  }
  cJSON_AddItemToObject(index, "snapshots", snaps);
  // the run folder: failing to write is a failed run (exit 1), not bad input
  if (o.out && (st = vd_outdir_make(o.out, &err))) {
    cli_report(cmd, &err, st);
    code = EXIT_FAIL;
    goto done;
  }
  double t0 = cli_now();
  if (o.out && (st = snapshot(g, &o, snaps, &err))) goto failed;
  for (int k = 0; k < ages; k++) {
    if ((st = vd_growth_step(g, &err))) break;
    if (o.out && (st = snapshot(g, &o, snaps, &err))) goto failed;
    if (o.po.progress) progress_bar(k + 1, ages, g);
  }
  if (o.po.progress && ages > 0) cli_progress_clear();
  double wall = cli_now() - t0;
  if (st) {
    // a step that failed: bad settings found on the way (a light the tree grew around) or the
    // L-system's own error
    cli_blame_input(&err, o.po.path);
    code = cli_report(cmd, &err, st);
    goto done;
  }
  // the final plant, the events, the index
  if (o.out || o.final) {
    vd_plant_spec* p = NULL;
    st = vd_growth_plant(g, &p, &err);
    if (!st && o.out) {
      char path[4200];
      snprintf(path, sizeof path, "%s/plant.json", o.out);
      st = cli_write_plant(p, path, 0, &err);
    }
    if (!st && o.final) st = cli_write_plant(p, o.final, 0, &err);
    vd_plant_spec_destroy(p);
    if (st) goto failed;
  }
  if (o.out) {
    if ((st = write_events(g, o.out, &err))) goto failed;
    cJSON_AddStringToObject(index, "format", "verdant-growth");
    cJSON_AddNumberToObject(index, "version", VD_GROWTH_FORMAT_VERSION);
    cJSON_AddStringToObject(index, "plant", o.po.path);
    cJSON_AddStringToObject(index, "model", vd_growth_model_name(o.def.model));
    cJSON_AddNumberToObject(index, "ages", vd_growth_age(g));
    cJSON_AddNumberToObject(index, "substeps", o.def.substeps);
    cJSON_AddNumberToObject(index, "dt", o.def.model == VD_GROWTH_RODS ? o.def.rod_opt.dt : o.def.opt.dt);
    cJSON_AddStringToObject(index, "events", "events.csv");
    cJSON_AddStringToObject(index, "final", "plant.json");
    char* text = cJSON_Print(index);
    if (!text) {
      st = vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      goto failed;
    }
    char path[4200];
    snprintf(path, sizeof path, "%s/growth.json", o.out);
    size_t n = strlen(text);
    char* t2 = vd_malloc(n + 2);
    if (t2) memcpy(t2, text, n), t2[n] = '\n', t2[n + 1] = 0;
    st = t2 ? write_text(path, t2, &err) : vd_error_set(&err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    vd_free(t2, n + 2);
    cJSON_free(text);
    if (st) goto failed;
  }
  if (o.stats) {
    cJSON* s = stats_json(g, &o.def, o.profile ? wall : -1);
    char* text = s ? cJSON_Print(s) : NULL;
    cJSON_Delete(s);
    if (!text) {
      code = EXIT_FAIL;
      goto done;
    }
    fputs(text, stdout);
    fputc('\n', stdout);
    cJSON_free(text);
  }
  goto done;
failed:
  cli_report(cmd, &err, st);
  code = EXIT_FAIL;
done:
  cJSON_Delete(index);
  vd_growth_destroy(g);
  vd_lsys_destroy(ls);
  vd_free(wind, (size_t)nwind * 4 * sizeof(double));
  return code;
}
