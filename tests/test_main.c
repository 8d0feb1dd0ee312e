// SPDX-License-Identifier: MIT
// Test runner: `verdant_tests [FILTER...]` runs the tests whose "group.name" starts with a
// filter (all when none) and ends with the line "N passed, N failed".
#define _POSIX_C_SOURCE 200809L
#include "test.h"

#include "verdant/plant.h"

#include <stdarg.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct {
  const char* group;
  const char* name;
  vdt_fn fn;
} vdt_case;

static vdt_case cases[1024];
static int ncase;
static int cur_failed;

void vdt_register(const char* group, const char* name, vdt_fn fn) {
  if (ncase < (int)(sizeof cases / sizeof cases[0])) cases[ncase++] = (vdt_case){group, name, fn};
}

void vdt_fail(const char* file, int line, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "  %s:%d: ", file, line);
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\n");
  va_end(ap);
  cur_failed = 1;
}

const char* vdt_path(const char* rel) {
  static char buf[8][4096];
  static int k;
  char* b = buf[k++ & 7];
  snprintf(b, 4096, "%s/%s", VD_SOURCE_DIR, rel);
  return b;
}

const char* vdt_tmpdir(void) {
  static char dir[256];
  if (!dir[0]) {
    snprintf(dir, sizeof dir, "/tmp/verdant_tests.%ld", (long)getpid());
    mkdir(dir, 0700);
  }
  return dir;
}

// out-of-memory injection: an allocator that fails after a budget of allocations
static int64_t oom_budget;
static void* oom_realloc(void* user, void* ptr, size_t old_size, size_t new_size) {
  (void)user;
  (void)old_size;
  if (new_size == 0) {
    free(ptr);
    return NULL;
  }
  if (oom_budget-- <= 0) return NULL;
  return realloc(ptr, new_size);
}

void vdt_oom_begin(int64_t budget) {
  oom_budget = budget;
  vd_set_allocator(oom_realloc, NULL);
}

void vdt_oom_end(void) { vd_set_allocator(NULL, NULL); }

vd_model* vdt_compile(vd_plant_spec* s) {
  vd_model* m = NULL;
  vd_error e = {0};
  vd_plant_compile(s, &m, &e);
  vd_plant_spec_destroy(s);
  return m;
}

static int cmp_case(const void* a, const void* b) {
  const vdt_case *x = a, *y = b;
  int c = strcmp(x->group, y->group);
  return c ? c : strcmp(x->name, y->name);
}

static int matches(const vdt_case* c, int argc, char** argv) {
  if (argc < 2) return 1;
  char full[256];
  snprintf(full, sizeof full, "%s.%s", c->group, c->name);
  for (int i = 1; i < argc; i++) {
    size_t n = strlen(argv[i]);
    if (strncmp(full, argv[i], n) == 0 && (full[n] == 0 || full[n] == '.' || argv[i][n - 1] == '.' ||
                                           strchr(argv[i], '.')))
      return 1;
  }
  return 0;
}

int main(int argc, char** argv) {
  qsort(cases, (size_t)ncase, sizeof cases[0], cmp_case);
  int passed = 0, failed = 0;
  for (int i = 0; i < ncase; i++) {
    if (!matches(&cases[i], argc, argv)) continue;
    cur_failed = 0;
    int64_t before = vd_alloc_bytes();
    cases[i].fn();
    int64_t leaked = vd_alloc_bytes() - before;
    if (leaked != 0) vdt_fail(__FILE__, __LINE__, "%lld bytes not freed", (long long)leaked);
    printf("%s %s.%s\n", cur_failed ? "FAIL" : "ok  ", cases[i].group, cases[i].name);
    if (cur_failed)
      failed++;
    else
      passed++;
  }
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", vdt_tmpdir());
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", vdt_tmpdir());
  if (passed + failed == 0) {
    fprintf(stderr, "no test matched the filter\n");
    failed = 1;
  }
  printf("%d passed, %d failed\n", passed, failed);
  return failed ? 1 : 0;
}
