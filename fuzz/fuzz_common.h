// SPDX-License-Identifier: MIT
// Shared pieces of the libFuzzer targets: a checking allocator hook and the leak check.
//
// Every block handed out through the verdant hook carries a header with its size; a free or
// resize whose old_size disagrees with the header aborts, so size bookkeeping bugs are findings
// as well as leaks (vd_alloc_bytes must come back to its value before the input ran).
#ifndef VERDANT_FUZZ_COMMON_H
#define VERDANT_FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "verdant/verdant.h"

// header in front of every block: the size the library asked for and a magic word
typedef struct fuzz_hdr {
  size_t size;
  size_t magic;
} fuzz_hdr;

#define FUZZ_MAGIC ((size_t)0x7665726461ee7421ull)

static void* fuzz_realloc(void* user, void* ptr, size_t old_size, size_t new_size) {
  (void)user;
  fuzz_hdr* h = ptr ? (fuzz_hdr*)ptr - 1 : NULL;
  // the caller's idea of the block's size must match what it asked for
  if (h && (h->magic != FUZZ_MAGIC || h->size != old_size)) {
    fprintf(stderr, "fuzz: allocator size mismatch: block of %zu freed/resized as %zu\n",
            h->magic == FUZZ_MAGIC ? h->size : (size_t)0, old_size);
    abort();
  }
  if (new_size == 0) {
    free(h);
    return NULL;
  }
  if (new_size > SIZE_MAX - sizeof(fuzz_hdr)) return NULL;
  fuzz_hdr* n = realloc(h, sizeof(fuzz_hdr) + new_size);
  if (!n) return NULL;
  n->size = new_size;
  n->magic = FUZZ_MAGIC;
  return n + 1;
}

// install the checking hook once (from LLVMFuzzerInitialize)
static void fuzz_install_allocator(void) { vd_set_allocator(fuzz_realloc, NULL); }

// abort when the bytes allocated through verdant differ from the value before the input
static void fuzz_check_leak(int64_t before, const char* what) {
  int64_t after = vd_alloc_bytes();
  if (after != before) {
    fprintf(stderr, "fuzz: %s leaked %lld bytes through the verdant allocator\n", what,
            (long long)(after - before));
    abort();
  }
}

// a programmer-error assert inside the library is a finding too
static void fuzz_assert(const char* expr, const char* file, int line) {
  fprintf(stderr, "fuzz: VD_ASSERT(%s) failed at %s:%d\n", expr, file, line);
  abort();
}

// the LLVMFuzzerInitialize of most targets: the checking allocator and the assert hook
#define FUZZ_DEFAULT_INITIALIZE                                  \
  int LLVMFuzzerInitialize(int* argc, char*** argv);             \
  int LLVMFuzzerInitialize(int* argc, char*** argv) {            \
    (void)argc;                                                  \
    (void)argv;                                                  \
    fuzz_install_allocator();                                    \
    vd_set_assert_handler(fuzz_assert);                          \
    return 0;                                                    \
  }

#endif
