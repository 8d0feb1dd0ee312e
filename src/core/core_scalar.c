// SPDX-License-Identifier: MIT
// Binary scalars of PLY, PCD and LAS files: type names and little-endian values (the mesh reader
// of geom and the cloud readers share them).
#include <stdint.h>
#include <string.h>

#include "verdant/core.h"

vd_scalar vd_scalar_ply(const char* name) {
  static const struct {
    const char* name;
    vd_scalar t;
  } tab[] = {{"char", VD_SCALAR_I8},      {"int8", VD_SCALAR_I8},       {"uchar", VD_SCALAR_U8},
             {"uint8", VD_SCALAR_U8},     {"short", VD_SCALAR_I16},     {"int16", VD_SCALAR_I16},
             {"ushort", VD_SCALAR_U16},   {"uint16", VD_SCALAR_U16},    {"int", VD_SCALAR_I32},
             {"int32", VD_SCALAR_I32},    {"uint", VD_SCALAR_U32},      {"uint32", VD_SCALAR_U32},
             {"float", VD_SCALAR_F32},    {"float32", VD_SCALAR_F32},   {"double", VD_SCALAR_F64},
             {"float64", VD_SCALAR_F64}};
  for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++)
    if (!strcmp(name, tab[i].name)) return tab[i].t;
  return VD_SCALAR_BAD;
}

double vd_scalar_get_le(const unsigned char* p, vd_scalar t) {
  uint64_t u = 0;
  for (int k = vd_scalar_size(t) - 1; k >= 0; k--)
    u = (u << 8) | p[k];
  switch (t) {
    case VD_SCALAR_I8: return (double)(int8_t)u;
    case VD_SCALAR_U8: return (double)(uint8_t)u;
    case VD_SCALAR_I16: return (double)(int16_t)u;
    case VD_SCALAR_U16: return (double)(uint16_t)u;
    case VD_SCALAR_I32: return (double)(int32_t)u;
    case VD_SCALAR_U32: return (double)(uint32_t)u;
    case VD_SCALAR_I64: return (double)(int64_t)u;
    case VD_SCALAR_U64: return (double)u;
    case VD_SCALAR_F32: {
      uint32_t w = (uint32_t)u;
      float f;
      memcpy(&f, &w, 4);
      return (double)f;
    }
    default: {
      double d;
      memcpy(&d, &u, 8);
      return d;
    }
  }
}
