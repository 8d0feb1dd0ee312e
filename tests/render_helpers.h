// SPDX-License-Identifier: MIT
// Helpers shared by the render tests (test_render.c, test_picture.c): a renderer or a skip, small
// settings, a one-quad plant, the bundled tomato.
#ifndef VERDANT_RENDER_HELPERS_H
#define VERDANT_RENDER_HELPERS_H

#include "verdant/verdant.h"

// A renderer, or NULL after printing why the test is skipped (no OpenGL context here).
vd_renderer* vdt_renderer(vd_render_def* def);
// Small, fast settings: w x h, no shadows, no legend, no supersampling.
vd_render_def vdt_small_def(int w, int h);
// A plant of one quad (two triangles, an open surface) with corners v, a label named "leaf".
vd_model* vdt_quad_plant(const vd_vec3 v[4], int label, int instance);
// The bundled tomato for a seed, compiled; NULL on failure.
vd_model* vdt_tomato(uint64_t seed);

#endif
