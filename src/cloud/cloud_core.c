// SPDX-License-Identifier: MIT
// Cloud basics: settings with their defaults, the one-block point arrays, relabelling by
// instance.
#if defined(__linux__)
#define _DEFAULT_SOURCE  // madvise
#include <sys/mman.h>
#endif
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloud_internal.h"

vd_scanner vd_scanner_default(void) {
  vd_scanner s;
  memset(&s, 0, sizeof s);
  s.pos = vd_v3(1, 0, 0.5);
  s.target = vd_v3(0, 0, 0.5);
  s.pattern = VD_SCAN_ANGULAR;
  s.fov_h = 60.0 * VD_PI / 180.0;
  s.fov_v = 45.0 * VD_PI / 180.0;
  s.res_h = 320;
  s.res_v = 240;
  return s;
}

vd_cloud_def vd_cloud_def_default(void) {
  vd_cloud_def def;
  memset(&def, 0, sizeof def);
  def.points = 100000;
  def.seed = 0;
  def.sensor = VD_SENSOR_UNIFORM;
  def.density = VD_DENSITY_INVERSE_SQUARE;
  def.ntable = 0;
  def.noise_sigma = 0;
  def.noise_slope = 0;
  def.occlusion = 0;
  def.interior = 1;
  def.nscanner = 0;
  def.scanner = NULL;
  def.mesh = vd_mesh_def_default();
  def.threads = 0;
  def.max_points = VD_CLOUD_MAX_POINTS;
  def.max_attempts = 100000;
  return def;
}

// bytes of the point block for n points: pos, normal, range (doubles), label, instance, view
static size_t block_size(int64_t n) { return (size_t)n * (7 * sizeof(double) + 3 * sizeof(int)); }

// ask for transparent huge pages over a large block: its first touch then faults once per 2 MiB
// instead of once per 4 KiB (1M points: 68 MB, 17,000 faults). Advice only; nothing changes
// where the kernel or the allocator says no.
static void advise_huge(void* block, size_t nbytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const uintptr_t huge = (uintptr_t)2 << 20;
  // the whole huge pages inside the block, by offsets from its start (no integer-to-pointer cast)
  uintptr_t start = (uintptr_t)block;
  size_t head = (size_t)((huge - start % huge) % huge);
  if (nbytes <= head) return;
  size_t len = (nbytes - head) & ~(size_t)(huge - 1);
  if (len) (void)madvise((char*)block + head, len, MADV_HUGEPAGE);
#else
  (void)block, (void)nbytes;
#endif
}

vd_status cloud_alloc(vd_cloud* c, int64_t n, const vd_label* labels, int nlabel, int zero,
                      vd_error* err) {
  if (!c) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "cloud: null output");
  memset(c, 0, sizeof *c);
  if (n < 0 || n > VD_CLOUD_MAX_POINTS)
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "cloud: %lld points (at most %lld)",
                        (long long)n, (long long)VD_CLOUD_MAX_POINTS);
  if (nlabel < 0 || (nlabel > 0 && !labels))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "cloud: bad label table");
  size_t nbytes = block_size(n);
  char* block = nbytes ? (zero ? vd_calloc(1, nbytes) : vd_malloc(nbytes)) : NULL;
  vd_label* lt = nlabel ? vd_malloc((size_t)nlabel * sizeof(vd_label)) : NULL;
  if ((nbytes && !block) || (nlabel && !lt)) {
    vd_free(block, nbytes);
    vd_free(lt, (size_t)nlabel * sizeof(vd_label));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory for %lld points",
                        (long long)n);
  }
  if (nbytes >= (size_t)4 << 20) advise_huge(block, nbytes);
  if (nlabel) memcpy(lt, labels, (size_t)nlabel * sizeof(vd_label));
  c->n = n;
  c->nbytes = nbytes;
  if (n > 0) {
    c->pos = (double*)block;
    c->normal = c->pos + 3 * n;
    c->range = c->normal + 3 * n;
    c->label = (int*)(c->range + n);
    c->instance = c->label + n;
    c->view = c->instance + n;
  }
  c->nlabel = nlabel;
  c->labels = lt;
  return VD_OK;
}

vd_status vd_cloud_alloc(vd_cloud* c, int64_t n, const vd_label* labels, int nlabel,
                         vd_error* err) {
  return cloud_alloc(c, n, labels, nlabel, 1, err);
}

void vd_cloud_free(vd_cloud* c) {
  if (!c) return;
  vd_free(c->pos, c->nbytes);
  vd_free(c->labels, (size_t)c->nlabel * sizeof(vd_label));
  vd_free(c->view_pose, (size_t)c->nview * 6 * sizeof(double));
  memset(c, 0, sizeof *c);
}

static int cmp_int(const void* a, const void* b) {
  int x = *(const int*)a, y = *(const int*)b;
  return (x > y) - (x < y);
}

vd_status vd_cloud_relabel(vd_cloud* c, vd_error* err) {
  if (!c) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "cloud: null cloud");
  // the distinct instances, sorted, each with the semantic label of its first point
  int* ids = c->n ? vd_malloc((size_t)c->n * sizeof(int)) : NULL;
  if (c->n && !ids) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory relabelling");
  if (c->n) memcpy(ids, c->instance, (size_t)c->n * sizeof(int));
  if (c->n) qsort(ids, (size_t)c->n, sizeof(int), cmp_int);
  int64_t k = 0;
  for (int64_t i = 0; i < c->n; i++)
    if (i == 0 || ids[i] != ids[i - 1]) ids[k++] = ids[i];
  if (k > 1 << 24) {
    vd_free(ids, (size_t)c->n * sizeof(int));
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "too many instances (%lld)", (long long)k);
  }
  vd_label* lt = k ? vd_malloc((size_t)k * sizeof(vd_label)) : NULL;
  int* sem = k ? vd_malloc((size_t)k * sizeof(int)) : NULL;
  if (k && (!lt || !sem)) {
    vd_free(ids, (size_t)c->n * sizeof(int));
    vd_free(lt, (size_t)k * sizeof(vd_label));
    vd_free(sem, (size_t)k * sizeof(int));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory relabelling");
  }
  for (int64_t j = 0; j < k; j++)
    sem[j] = -1;
  for (int64_t i = 0; i < c->n; i++) {
    int* at = bsearch(&c->instance[i], ids, (size_t)k, sizeof(int), cmp_int);
    if (sem[at - ids] < 0) sem[at - ids] = c->label[i];
  }
  // table entries "<semantic name>_<instance>", organ and colour of the semantic label
  for (int64_t j = 0; j < k; j++) {
    vd_label* l = &lt[j];
    memset(l, 0, sizeof *l);
    l->id = ids[j];
    const vd_label* s = NULL;
    for (int t = 0; t < c->nlabel; t++)
      if (c->labels[t].id == sem[j]) s = &c->labels[t];
    char base[VD_LABEL_NAME_MAX];
    if (s)
      snprintf(base, sizeof base, "%s", s->name);
    else
      snprintf(base, sizeof base, "label_%d", sem[j]);
    snprintf(l->name, sizeof l->name, "%.30s_%d", base, ids[j]);
    l->organ = s ? s->organ : VD_ORGAN_OTHER;
    vd_plant_default_rgb(ids[j], l->rgb);
  }
  for (int64_t i = 0; i < c->n; i++)
    c->label[i] = c->instance[i];
  vd_free(c->labels, (size_t)c->nlabel * sizeof(vd_label));
  c->labels = lt;
  c->nlabel = (int)k;
  vd_free(sem, (size_t)k * sizeof(int));
  vd_free(ids, (size_t)c->n * sizeof(int));
  return VD_OK;
}
