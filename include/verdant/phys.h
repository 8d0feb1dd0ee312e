// SPDX-License-Identifier: MIT
// verdant phys: what both physics engines (the rods of sim.h, the mass-spring trees of mss.h) use:
// soil resistance laws and presets, the wood table, wind (gusts and time series), and the
// validation list every module's reference cases report through (docs/validation.md). SI units.
#ifndef VERDANT_PHYS_H
#define VERDANT_PHYS_H

#include <stdarg.h>

#include "verdant/core.h"
#include "verdant/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---------------------------------------------------------------------------------------------
// validation against analytic references (docs/validation.md)

// One checked quantity.
typedef struct vd_validate_result {
  char name[64];     // case name ("cantilever_tip_load")
  char form[16];     // "discrete" (the discrete model's exact value) or "continuum"
  char quantity[48]; // what is compared ("tip deflection (m)")
  double measured;   // simulated value
  double reference;  // reference value
  double error;      // relative error |measured - reference| / |reference| (or absolute, see note)
  double tolerance;  // allowed error
  int pass;          // 1 when error <= tolerance
  char note[160];    // sizes and the reference's source
} vd_validate_result;

// Validation settings.
typedef struct vd_validate_def {
  int full;            // 1: the full sweep (finer rods, more cases), else the quick sizes
  const char* filter;  // Nullable: run only cases whose name contains this text
  void (*progress)(void* user, const char* name);  // Nullable: called before each case
  void* user;          // passed to progress
  const vd_model* plant;  // Nullable: also run the sag-free gate on this plant (e.g. the tomato)
} vd_validate_def;

// A growing list of validation results (for the modules' own cases).
typedef struct vd_validate_list {
  vd_validate_result* r;  // results (n, capacity cap)
  int n, cap;
} vd_validate_list;

// Append a checked quantity: error relative to the reference (absolute when abs_err is set or
// the reference is 0); pass when finite and within tol. note is printf-style. 0 when out of
// memory.
int vd_validate_add(vd_validate_list* l, const char* name, const char* form, const char* quantity,
                    double measured, double reference, double tol, int abs_err, const char* note,
                    ...) __attribute__((format(printf, 9, 10)));
// The same with the note's arguments in a va_list.
int vd_validate_addv(vd_validate_list* l, const char* name, const char* form, const char* quantity,
                     double measured, double reference, double tol, int abs_err, const char* note,
                     va_list ap);
// Hand the list's results to a caller as vd_sim_validate does (*out exactly n entries, or NULL).
vd_status vd_validate_finish(vd_validate_list* l, vd_validate_result** out, int* n, vd_error* err);

// How below-ground nodes are held.
typedef enum vd_soil_method {
  VD_SOIL_CLAMP = 0,      // fixed (a pot; no soil model)
  VD_SOIL_PANG2023,       // method 1: Pang et al. 2023 eq. 12 (cone penetration, depth h)
  VD_SOIL_IMHOFF2016      // method 2: ln SR pedotransfer function, F = 1e6 SR A (eqs. 13-14)
} vd_soil_method;

// Soil: composition, the resistance law and its coefficients (sources in docs/physics.md).
typedef struct vd_soil {
  vd_soil_method method;  // resistance law
  double ground;          // ground height z (m): nodes of roots below it are in the soil
  double clay;            // clay content (% by mass)
  double organic;         // organic matter content (% by mass)
  double water;           // volumetric water content theta (m^3/m^3), > 0
  double bulk_density;    // dry bulk density BD (Mg/m^3 = g/cm^3); gamma = 1000 BD kg/m^3
  double poisson;         // Poisson ratio mu of the soil, method 1 (-), < 0.5
  double residual_pressure; // P_a of method 1 (Pa)
  double cone_radius;     // r of method 1 (m); 0: the root's radius at the node
  double ptf[8];          // method 2: ln SR = c0 + c1 clay + c2 OM + (d0 + d1 clay + d2 OM) ln theta
                          //                   + (e0 + e1 clay) ln BD; order c0 c1 c2 d0 d1 d2 e0 e1
  double sr_max;          // method 2: SR is clamped to this (MPa)
  double stiffness;       // rods engine: stiffness of each node's hold in the soil (N/m)
} vd_soil;

// Soil presets: "clamp", "loam", "sandy-loam", "clay", "singapore-residual" (the composition of
// each and its source in docs/physics.md; method 2 with the da Silva & Kay 1997 coefficients,
// since Imhoff et al. 2016's could not be read). VD_ERR_NAME for an unknown name.
vd_status vd_soil_preset(const char* name, vd_soil* out);
// Maximum resistance of a soil node (N): depth below ground (m), root radius (m) and the lateral
// surface area the node holds by (m^2, method 2). 0 above ground; INFINITY for VD_SOIL_CLAMP.
double vd_soil_max_force(const vd_soil* s, double depth, double radius, double area);
// Check a soil's numbers (water > 0, density > 0, Poisson below 0.5, ...); errors name the field.
vd_status vd_soil_check(const vd_soil* s, vd_error* err);

// Wood of a species: stiffness, density and strength for mass-spring trees (docs/physics.md).
typedef struct vd_wood {
  const char* name;    // species name ("hopea-odorata")
  double young;        // modulus of elasticity along the grain (Pa)
  double density;      // density of the wood (kg/m^3)
  double mor;          // modulus of rupture, static bending strength (Pa)
  const char* source;  // where the numbers come from
} vd_wood;

// Wood of a species by name: "generic-broadleaf" (green hardwood), "hopea-odorata" (merawan,
// the seed's species). VD_ERR_NAME for an unknown name; vd_wood_count/vd_wood_get list them.
vd_status vd_wood_species(const char* name, vd_wood* out);
// Number of species in the table.
int vd_wood_count(void);
// Species i of the table (0 <= i < vd_wood_count()).
const vd_wood* vd_wood_get(int i);
// ---------------------------------------------------------------------------------------------
// wind

// Wind velocity at time t (m/s): a series (linear between rows, held at the ends) when given,
// else mean * (1 + gust_amplitude sin(2 pi t / gust_period)); the rods use the same function.
vd_vec3 vd_wind_at(vd_vec3 mean, double gust_amplitude, double gust_period, const double* series,
                   int nseries, double t);

// Largest wind velocity component of a time series (m/s) and most rows.
#define VD_SIM_MAX_WIND 1000.0
#define VD_SIM_MAX_WIND_ROWS 10000000
// Parse a wind time series (CSV rows t,vx,vy,vz in s and m/s, times not decreasing; a first
// line that is not numeric is a header; '#' starts a comment) for opt.wind_series; name
// (Nullable) is used in errors, which give line and column. *rows (nrows x 4) is allocated:
// free it with vd_free(*rows, *n * 4 * sizeof(double)).
vd_status vd_sim_parse_wind(const char* text, size_t len, const char* name, double** rows, int* n,
                            vd_error* err);
// Read and parse a wind time series file (see vd_sim_parse_wind).
vd_status vd_sim_read_wind(const char* path, double** rows, int* n, vd_error* err);

#ifdef __cplusplus
}
#endif
#endif
