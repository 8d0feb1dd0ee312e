// SPDX-License-Identifier: MIT
// Wood of a few species for mass-spring trees: modulus of elasticity, density and modulus of
// rupture, with their sources (docs/physics.md, "Wood and breaking").
#include "phys_internal.h"

// Sources. Hopea odorata (merawan, the seed's species): density 620-930 kg/m^3 at 15 % moisture
// (PROSEA 5(1) Timber trees, via GlobinMed; facts-robot-trees.md section 6), the middle taken;
// bending strength (MOR) 140-160 MPa air-dry from a timber database (a secondary, low-authority
// source: the Malaysian Timber Council table could not be read), the low end taken; its modulus
// of elasticity was not found, 14 GPa is the middle of the 12-16 GPa usual for merawan (recalled,
// not sourced). Generic broadleaf: green (living) hardwood values of the USDA Wood Handbook
// (FPL-GTR-190), recalled, not read here: E ~ 10 GPa, MOR ~ 55 MPa green, density ~ 900 kg/m^3
// with its water (the rods' wood class uses the same E and density).
static const vd_wood table[] = {
    {"generic-broadleaf", 1e10, 900, 5.5e7,
     "USDA Wood Handbook FPL-GTR-190, green hardwoods (recalled): E 10 GPa, MOR 55 MPa, 900 kg/m^3 green"},
    {"hopea-odorata", 1.4e10, 775, 1.4e8,
     "density 620-930 kg/m^3 (PROSEA 5(1)); MOR 140-160 MPa air-dry (timber database, secondary); "
     "E 12-16 GPa (recalled)"},
};

int vd_wood_count(void) { return (int)(sizeof table / sizeof table[0]); }

const vd_wood* vd_wood_get(int i) { return i >= 0 && i < vd_wood_count() ? &table[i] : NULL; }

vd_status vd_wood_species(const char* name, vd_wood* out) {
  for (int i = 0; i < vd_wood_count(); i++)
    if (!strcmp(name, table[i].name)) {
      *out = table[i];
      return VD_OK;
    }
  return VD_ERR_NAME;
}
