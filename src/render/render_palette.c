// SPDX-License-Identifier: MIT
// Label colours in pictures. The label table's own colours follow the organ (every leaf-like
// label green, every stem brown), so two labels of one organ kind (trunk and branch; peduncle
// and pedicel) look alike. The distinct palette gives every label its own colour from a fixed set
// of 15 that lie at least 29 CIE76 units apart in L*a*b*, organ-like where it can: each label, in
// id order, takes the first free colour its organ prefers, then the first free one at all.
#include <math.h>
#include <string.h>

#include "render_internal.h"

// the distinct colours, in the order labels without a preference take them
enum { GREEN, RED, BROWN, YELLOW, BLUE, PURPLE, ORANGE, TEAL, PINK, LIME, TAN, NAVY, MAGENTA,
       GREY, OLIVE, NCOLOR };
static const float distinct[NCOLOR][3] = {
    [GREEN] = {0.30f, 0.69f, 0.29f},   [RED] = {0.89f, 0.10f, 0.11f},
    [BROWN] = {0.50f, 0.31f, 0.14f},   [YELLOW] = {1.00f, 0.85f, 0.10f},
    [BLUE] = {0.20f, 0.45f, 0.85f},    [PURPLE] = {0.55f, 0.30f, 0.70f},
    [ORANGE] = {1.00f, 0.55f, 0.05f},  [TEAL] = {0.05f, 0.70f, 0.70f},
    [PINK] = {0.97f, 0.55f, 0.78f},    [LIME] = {0.70f, 0.90f, 0.25f},
    [TAN] = {0.85f, 0.72f, 0.52f},     [NAVY] = {0.12f, 0.18f, 0.50f},
    [MAGENTA] = {0.80f, 0.10f, 0.55f}, [GREY] = {0.55f, 0.55f, 0.55f},
    [OLIVE] = {0.45f, 0.45f, 0.10f}};

// the colours each organ kind prefers, best first (-1 ends a list)
static const int prefer[VD_ORGAN_COUNT][4] = {
    [VD_ORGAN_OTHER] = {-1},
    [VD_ORGAN_STEM] = {BROWN, ORANGE, TAN, -1},
    [VD_ORGAN_LEAF] = {GREEN, LIME, TEAL, -1},
    [VD_ORGAN_FLOWER] = {YELLOW, PINK, MAGENTA, -1},
    [VD_ORGAN_FRUIT] = {RED, MAGENTA, PINK, -1},
    [VD_ORGAN_PEDICEL] = {PURPLE, ORANGE, TEAL, -1},
    [VD_ORGAN_ROOT] = {TAN, OLIVE, GREY, -1}};

void vd_render_label_colors(const vd_label* labels, int nlabel, vd_palette palette,
                            float (*rgb)[3]) {
  if (palette == VD_PALETTE_NATURAL) {
    for (int i = 0; i < nlabel; i++)
      memcpy(rgb[i], labels[i].rgb, sizeof rgb[i]);
    return;
  }
  int used[NCOLOR] = {0}, extra = 0;
  for (int i = 0; i < nlabel; i++) {
    int o = (int)labels[i].organ, pick = -1;
    if (o < 0 || o >= VD_ORGAN_COUNT) o = VD_ORGAN_OTHER;
    for (int k = 0; k < 4 && prefer[o][k] >= 0 && pick < 0; k++)
      if (!used[prefer[o][k]]) pick = prefer[o][k];
    for (int c = 0; c < NCOLOR && pick < 0; c++)
      if (!used[c]) pick = c;
    if (pick >= 0) {
      used[pick] = 1;
      memcpy(rgb[i], distinct[pick], sizeof rgb[i]);
      continue;
    }
    // more labels than colours: hues by the golden ratio, mid saturation and value
    double h = fmod(0.13 + 0.6180339887498949 * extra++, 1.0) * 6, s = 0.55, v = 0.8;
    int j = (int)h;
    double f = h - j, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double c[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
    for (int k = 0; k < 3; k++)
      rgb[i][k] = (float)c[j % 6][k];
  }
}
