// SPDX-License-Identifier: MIT
// Soil: how much a root node can resist before the soil gives way (docs/physics.md, "Soil").
//
// Method 1 is eq. 12 of the seed (Lim & Gobeawan 2024), their reading of Pang et al. 2023
// (cone penetration by spherical cavity expansion): B = (gamma / 1000)^12 (0.5 - mu)^(1/3) / 2.8,
// |F| = sqrt(P_a / 1e4 * gamma 9.8 / 1e6 * 2/3 pi r^3) * h * 100 * B, with gamma the soil density
// (kg/m^3), mu its Poisson ratio, P_a the "remaining pressure", r the cone radius and h the depth.
// The seed states no units for P_a, r and h; we take SI (Pa, m) and say so.
//
// Method 2 is eqs. 13-14: a pedotransfer function for the soil resistance to penetration SR (MPa)
// from clay and organic matter (%), volumetric water content theta (m^3/m^3) and bulk density BD
// (Mg/m^3), and |F| = 1e6 SR A over the area A the node holds by. Imhoff et al. 2016 (PLoS ONE
// 11(4):e0153827) fitted such a function (R^2 = 0.84), but its coefficient table could not be
// read for this project; the coefficients are therefore parameters, and the default set is the
// same-form function of da Silva & Kay 1997 (Soil Sci. Soc. Am. J. 61:877-883, as implemented in
// the CRAN package soilphysics, llwrPTF): ln SR = -3.6733 - 0.1447 clay + 0.7653 OC
// + (-0.4805 - 0.1239 clay + 0.208 OC) ln theta + (3.8521 + 0.0963 clay) ln BD, with organic
// carbon OC = OM / 1.72 (van Bemmelen). Two of its terms (OC in the exponent of theta, clay in the
// exponent of BD) are beyond the five of eq. 13, hence the two extra coefficients d2 and e1.
#include "phys_internal.h"

// coefficients of the default pedotransfer function (da Silva & Kay 1997, OM = 1.72 OC)
static const double silva_kay_1997[8] = {-3.6733, -0.1447, 0.7653 / 1.72, -0.4805,
                                         -0.1239, 0.208 / 1.72,  3.8521,       0.0963};

typedef struct soil_preset {
  const char* name;
  double clay, organic, water, bulk, poisson;
} soil_preset;

// typical compositions of USDA texture classes (illustrative values, not measurements of a site)
// and the range midpoints quoted for Singapore's residual soils (facts-robot-trees.md section 3,
// [recalled] there: bulk density 1.3-1.7 Mg/m^3, clay 10-50 %, organic matter < 2 %, Poisson
// 0.3-0.35); Rezaur et al. 2003's Yishun, Mandai and NTU numbers could not be read
static const soil_preset presets[] = {
    {"loam", 20, 2.5, 0.25, 1.35, 0.30},
    {"sandy-loam", 10, 1.5, 0.18, 1.50, 0.30},
    {"clay", 45, 3.0, 0.35, 1.20, 0.40},
    {"singapore-residual", 30, 1.0, 0.30, 1.50, 0.33},
};

vd_status vd_soil_preset(const char* name, vd_soil* out) {
  vd_soil s;
  memset(&s, 0, sizeof s);
  s.method = VD_SOIL_IMHOFF2016;
  s.residual_pressure = 101325;  // atmospheric pressure: our reading of "remaining pressure"
  s.cone_radius = 0;
  memcpy(s.ptf, silva_kay_1997, sizeof s.ptf);
  s.sr_max = 10;       // MPa: beyond the calibration of any penetration PTF
  s.stiffness = 1e5;   // N/m: a node moves 1 mm under 100 N before the soil gives way
  if (!strcmp(name, "clamp")) {
    const soil_preset* p = &presets[0];
    s.method = VD_SOIL_CLAMP;
    s.clay = p->clay, s.organic = p->organic, s.water = p->water, s.bulk_density = p->bulk,
    s.poisson = p->poisson;
    *out = s;
    return VD_OK;
  }
  for (size_t k = 0; k < sizeof presets / sizeof presets[0]; k++)
    if (!strcmp(name, presets[k].name)) {
      const soil_preset* p = &presets[k];
      s.clay = p->clay, s.organic = p->organic, s.water = p->water, s.bulk_density = p->bulk,
      s.poisson = p->poisson;
      *out = s;
      return VD_OK;
    }
  return VD_ERR_NAME;
}

double vd_soil_max_force(const vd_soil* s, double depth, double radius, double area) {
  if (depth <= 0) return 0;
  switch (s->method) {
    case VD_SOIL_CLAMP: return INFINITY;
    case VD_SOIL_PANG2023: {
      // eq. 12 as the seed prints it (gamma in kg/m^3)
      double gamma = 1000 * s->bulk_density;
      double b = pow(gamma / 1000, 12) * cbrt(0.5 - s->poisson) / 2.8;
      double r = s->cone_radius > 0 ? s->cone_radius : radius;
      double inner = s->residual_pressure / 10000 * gamma * 9.8 / 1e6 * (2.0 / 3.0) * VD_PI * r * r * r;
      return sqrt(fmax(inner, 0)) * depth * 100 * b;
    }
    case VD_SOIL_IMHOFF2016: {
      // eqs. 13-14 with the two extra terms of the default coefficients
      const double* c = s->ptf;
      double lt = log(s->water), lb = log(s->bulk_density);
      double lsr = c[0] + c[1] * s->clay + c[2] * s->organic + (c[3] + c[4] * s->clay + c[5] * s->organic) * lt +
                   (c[6] + c[7] * s->clay) * lb;
      double sr = fmin(exp(lsr), s->sr_max);
      return 1e6 * sr * area;
    }
  }
  return 0;
}

vd_status vd_soil_check(const vd_soil* s, vd_error* err) {
  const char* f = NULL;
  if (s->method < VD_SOIL_CLAMP || s->method > VD_SOIL_IMHOFF2016) f = "method";
  else if (!isfinite(s->ground)) f = "ground (m)";
  else if (!(s->clay >= 0 && s->clay <= 100)) f = "clay (% in [0, 100])";
  else if (!(s->organic >= 0 && s->organic <= 100)) f = "organic matter (% in [0, 100])";
  else if (!(s->water > 0 && s->water <= 1)) f = "water content (m^3/m^3 in (0, 1])";
  else if (!(s->bulk_density > 0 && s->bulk_density < 3)) f = "bulk density (Mg/m^3 in (0, 3))";
  else if (!(s->poisson >= 0 && s->poisson < 0.5)) f = "Poisson ratio (in [0, 0.5))";
  else if (!(s->residual_pressure >= 0 && isfinite(s->residual_pressure))) f = "residual pressure (Pa >= 0)";
  else if (!(s->cone_radius >= 0 && isfinite(s->cone_radius))) f = "cone radius (m >= 0)";
  else if (!(s->sr_max > 0)) f = "largest soil resistance (MPa > 0)";
  else if (!(s->stiffness > 0 && isfinite(s->stiffness))) f = "soil stiffness (N/m > 0)";
  for (int k = 0; !f && k < 8; k++)
    if (!isfinite(s->ptf[k])) f = "pedotransfer coefficients (finite)";
  if (f) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "soil: bad %s", f);
  return VD_OK;
}
