// SPDX-License-Identifier: MIT
// The allocation hook with its byte counter, and the arena built on it.
#include "verdant/core.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

static void* libc_realloc(void* user, void* ptr, size_t old_size, size_t new_size) {
  (void)user;
  (void)old_size;
  if (new_size == 0) {
    free(ptr);
    return NULL;
  }
  return realloc(ptr, new_size);
}

static vd_realloc_fn alloc_fn = libc_realloc;
static void* alloc_user;
static _Atomic int64_t alloc_bytes;

void vd_set_allocator(vd_realloc_fn fn, void* user) {
  alloc_fn = fn ? fn : libc_realloc;
  alloc_user = fn ? user : NULL;
}

int64_t vd_alloc_bytes(void) { return atomic_load(&alloc_bytes); }

void* vd_malloc(size_t size) {
  if (size == 0) return NULL;
  void* p = alloc_fn(alloc_user, NULL, 0, size);
  if (p) atomic_fetch_add(&alloc_bytes, (int64_t)size);
  return p;
}

void* vd_calloc(size_t n, size_t size) {
  if (n == 0 || size == 0) return NULL;
  if (n > SIZE_MAX / size) return NULL;
  if (alloc_fn == libc_realloc) {
    // libc's calloc does not clear memory fresh from the system (it is zero already): a large
    // block's pages are then touched only where they are written
    void* p = calloc(n, size);
    if (p) atomic_fetch_add(&alloc_bytes, (int64_t)(n * size));
    return p;
  }
  void* p = vd_malloc(n * size);
  if (p) memset(p, 0, n * size);
  return p;
}

void* vd_realloc(void* ptr, size_t old_size, size_t new_size) {
  if (!ptr) return vd_malloc(new_size);
  if (new_size == 0) {
    vd_free(ptr, old_size);
    return NULL;
  }
  void* p = alloc_fn(alloc_user, ptr, old_size, new_size);
  if (p) atomic_fetch_add(&alloc_bytes, (int64_t)new_size - (int64_t)old_size);
  return p;
}

void vd_free(void* ptr, size_t size) {
  if (!ptr) return;
  alloc_fn(alloc_user, ptr, size, 0);
  atomic_fetch_sub(&alloc_bytes, (int64_t)size);
}

int vd_grow(void** ptr, int* cap, int need, size_t elem_size) {
  if (need <= *cap) return 1;
  if (need < 0) return 0;
  int64_t ncap = *cap < 16 ? 16 : (int64_t)*cap;
  while (ncap < need) ncap *= 2;
  if (ncap > INT32_MAX) ncap = INT32_MAX;
  if (ncap < need) return 0;
  if ((uint64_t)ncap > SIZE_MAX / elem_size) return 0;
  void* p = vd_realloc(*ptr, (size_t)*cap * elem_size, (size_t)ncap * elem_size);
  if (!p) return 0;
  *ptr = p;
  *cap = (int)ncap;
  return 1;
}

char* vd_strdup(const char* s) {
  size_t n = strlen(s) + 1;
  char* d = vd_malloc(n);
  if (d) memcpy(d, s, n);
  return d;
}

// arena: a list of blocks, newest first; reset keeps one block for reuse
typedef struct vd_arena_block {
  struct vd_arena_block* next;
  size_t size;  // usable bytes after the header
  size_t top;   // bytes used
} vd_arena_block;

#define ARENA_HDR ((sizeof(vd_arena_block) + 15) & ~(size_t)15)

void vd_arena_init(vd_arena* a, size_t block_size) {
  a->head = NULL;
  a->block_size = block_size ? block_size : 65536;
  a->used = 0;
}

void* vd_arena_alloc(vd_arena* a, size_t size) {
  size = (size + 15) & ~(size_t)15;
  vd_arena_block* b = a->head;
  if (!b || b->top + size > b->size) {
    size_t bs = a->block_size > size ? a->block_size : size;
    vd_arena_block* nb = vd_malloc(ARENA_HDR + bs);
    if (!nb) return NULL;
    nb->next = b;
    nb->size = bs;
    nb->top = 0;
    a->head = b = nb;
  }
  void* p = (char*)b + ARENA_HDR + b->top;
  b->top += size;
  a->used += size;
  return p;
}

void vd_arena_reset(vd_arena* a) {
  // keep the largest block, free the rest
  vd_arena_block* keep = NULL;
  for (vd_arena_block* b = a->head; b; b = b->next)
    if (!keep || b->size > keep->size) keep = b;
  vd_arena_block* b = a->head;
  while (b) {
    vd_arena_block* n = b->next;
    if (b != keep) vd_free(b, ARENA_HDR + b->size);
    b = n;
  }
  if (keep) {
    keep->next = NULL;
    keep->top = 0;
  }
  a->head = keep;
  a->used = 0;
}

void vd_arena_free(vd_arena* a) {
  vd_arena_block* b = a->head;
  while (b) {
    vd_arena_block* n = b->next;
    vd_free(b, ARENA_HDR + b->size);
    b = n;
  }
  a->head = NULL;
  a->used = 0;
}
