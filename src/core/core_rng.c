// SPDX-License-Identifier: MIT
// MT19937 (Matsumoto & Nishimura 1998) with CPython's seeding (init_by_array over the 32-bit
// words of |n|) and CPython's random(), uniform(), gauss() and randint() algorithms, so that
// an L-Py model calling seed(n) draws the same numbers here as under CPython.
#include "verdant/core.h"

#include <math.h>

#define MT_N 624
#define MT_M 397

static void init_genrand(vd_rng* r, uint32_t s) {
  r->mt[0] = s;
  for (int i = 1; i < MT_N; i++)
    r->mt[i] = 1812433253u * (r->mt[i - 1] ^ (r->mt[i - 1] >> 30)) + (uint32_t)i;
  r->mti = MT_N;
}

void vd_rng_seed_array(vd_rng* r, const uint32_t* key, int len) {
  static const uint32_t zero = 0;
  if (len <= 0) {
    key = &zero;
    len = 1;
  }
  init_genrand(r, 19650218u);
  int i = 1, j = 0;
  for (int k = MT_N > len ? MT_N : len; k; k--) {
    // cppcheck-suppress objectIndex ; j stays below len, which is 1 when key is &zero
    r->mt[i] = (r->mt[i] ^ ((r->mt[i - 1] ^ (r->mt[i - 1] >> 30)) * 1664525u)) + key[j] + (uint32_t)j;
    i++;
    j++;
    if (i >= MT_N) {
      r->mt[0] = r->mt[MT_N - 1];
      i = 1;
    }
    if (j >= len) j = 0;
  }
  for (int k = MT_N - 1; k; k--) {
    r->mt[i] = (r->mt[i] ^ ((r->mt[i - 1] ^ (r->mt[i - 1] >> 30)) * 1566083941u)) - (uint32_t)i;
    i++;
    if (i >= MT_N) {
      r->mt[0] = r->mt[MT_N - 1];
      i = 1;
    }
  }
  r->mt[0] = 0x80000000u;
  r->mti = MT_N;
  r->has_gauss = 0;
  r->gauss_next = 0;
}

void vd_rng_seed(vd_rng* r, uint64_t n) {
  uint32_t key[2] = {(uint32_t)(n & 0xffffffffu), (uint32_t)(n >> 32)};
  vd_rng_seed_array(r, key, key[1] ? 2 : 1);
}

void vd_rng_stream(vd_rng* r, uint64_t master, uint64_t index) {
  // a distinct init_by_array key per (master, index): streams are independent MT states
  uint32_t key[5] = {(uint32_t)master, (uint32_t)(master >> 32), (uint32_t)index,
                     (uint32_t)(index >> 32), 0x76657264u /* "verd" */};
  vd_rng_seed_array(r, key, 5);
}

// the next 624 words of the state at once (the matrix's lowest bit picks 0x9908b0df, branch-free)
static void twist(vd_rng* r) {
  uint32_t* mt = r->mt;
  int kk;
  uint32_t y;
  for (kk = 0; kk < MT_N - MT_M; kk++) {
    y = (mt[kk] & 0x80000000u) | (mt[kk + 1] & 0x7fffffffu);
    mt[kk] = mt[kk + MT_M] ^ (y >> 1) ^ (-(y & 1u) & 0x9908b0dfu);
  }
  for (; kk < MT_N - 1; kk++) {
    y = (mt[kk] & 0x80000000u) | (mt[kk + 1] & 0x7fffffffu);
    mt[kk] = mt[kk + (MT_M - MT_N)] ^ (y >> 1) ^ (-(y & 1u) & 0x9908b0dfu);
  }
  y = (mt[MT_N - 1] & 0x80000000u) | (mt[0] & 0x7fffffffu);
  mt[MT_N - 1] = mt[MT_M - 1] ^ (y >> 1) ^ (-(y & 1u) & 0x9908b0dfu);
  r->mti = 0;
}

static inline uint32_t temper(uint32_t y) {
  y ^= (y >> 11);
  y ^= (y << 7) & 0x9d2c5680u;
  y ^= (y << 15) & 0xefc60000u;
  y ^= (y >> 18);
  return y;
}

static inline uint32_t next_u32(vd_rng* r) {
  if (r->mti >= MT_N) twist(r);
  return temper(r->mt[r->mti++]);
}

uint32_t vd_rng_u32(vd_rng* r) { return next_u32(r); }

double vd_rng_random(vd_rng* r) {
  uint32_t a = next_u32(r) >> 5, b = next_u32(r) >> 6;
  return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
}

void vd_rng_fill(vd_rng* r, double* out, int n) {
  int i = 0;
  while (i < n) {
    // whole pairs of words left in the state: one tight loop without the refill check
    if (r->mti >= MT_N) twist(r);
    int m = (MT_N - r->mti) / 2;
    if (m > n - i) m = n - i;
    const uint32_t* w = r->mt + r->mti;
    for (int k = 0; k < m; k++) {
      uint32_t a = temper(w[2 * k]) >> 5, b = temper(w[2 * k + 1]) >> 6;
      out[i + k] = (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
    }
    r->mti += 2 * m;
    i += m;
    // a pair straddling a refill
    if (m == 0 && i < n) {
      uint32_t a = next_u32(r) >> 5, b = next_u32(r) >> 6;
      out[i++] = (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
    }
  }
}

double vd_rng_uniform(vd_rng* r, double a, double b) { return a + (b - a) * vd_rng_random(r); }

double vd_rng_gauss(vd_rng* r, double mu, double sigma) {
  double z;
  if (r->has_gauss) {
    z = r->gauss_next;
    r->has_gauss = 0;
  } else {
    double x2pi = vd_rng_random(r) * (2.0 * VD_PI);
    double g2rad = sqrt(-2.0 * log(1.0 - vd_rng_random(r)));
    z = cos(x2pi) * g2rad;
    r->gauss_next = sin(x2pi) * g2rad;
    r->has_gauss = 1;
  }
  return mu + z * sigma;
}

// CPython getrandbits(k) for k <= 64, built from 32-bit words, least significant first
static uint64_t getrandbits(vd_rng* r, int k) {
  if (k <= 32) return vd_rng_u32(r) >> (32 - k);
  uint64_t lo = vd_rng_u32(r);
  uint64_t hi = vd_rng_u32(r) >> (64 - k);
  return lo | (hi << 32);
}

int64_t vd_rng_randint(vd_rng* r, int64_t a, int64_t b) {
  if (b <= a) return a;
  // the width in unsigned arithmetic: b - a overflows int64 for far-apart bounds
  uint64_t n = (uint64_t)b - (uint64_t)a + 1u;
  if (n == 0) return (int64_t)getrandbits(r, 64);  // the whole int64 range
  int k = 0;
  for (uint64_t t = n; t; t >>= 1) k++;  // n.bit_length()
  uint64_t v = getrandbits(r, k);
  while (v >= n) v = getrandbits(r, k);
  return (int64_t)((uint64_t)a + v);
}
