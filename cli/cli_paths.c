// SPDX-License-Identifier: MIT
// Inputs and outputs of a command: no output may replace an input (files are compared by
// device and inode, so another spelling of the same path, a hard link or a symbolic link to an
// input is caught as well as the same name), and a command's outputs appear together or not at
// all (output sets: checked before anything is written, the files they replace kept aside until
// every output is there, everything put back when one fails or a signal ends the run).
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

int cli_same_file(const char* a, const char* b) {
  struct stat sa, sb;
  if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int cli_check_outputs(const char* cmd, const char* const* out, int nout, const char* const* in, int nin) {
  for (int i = 0; i < nout; i++)
    for (int k = 0; k < nin; k++)
      if (out[i] && in[k] && cli_same_file(out[i], in[k]))
        return cli_usage_error(cmd, "the output '%s' would replace the input '%s'; choose another output name",
                               out[i], in[k]);
  return 0;
}

// the folder part of a path ("." when it has none)
static void parent_of(const char* path, char* buf, size_t cap) {
  const char* slash = strrchr(path, '/');
  if (!slash)
    snprintf(buf, cap, ".");
  else if (slash == path)
    snprintf(buf, cap, "/");
  else
    snprintf(buf, cap, "%.*s", (int)(slash - path), path);
}

int cli_in_folder(const char* dir, const char* path) {
  char parent[4200];
  if (!dir || !path) return 0;
  parent_of(path, parent, sizeof parent);
  return cli_same_file(dir, parent);
}

// ---------------------------------------------------------------------------------------------
// output sets: a command's outputs appear together or not at all

// output sets in progress, for the signal handler (published with an atomic store once complete)
#define OUTSET_SLOTS 1088  // one per dataset job (--jobs 1024) and a few more
static _Atomic(cli_outset*) outset_live[OUTSET_SLOTS];

// put output k back as it was: the file it replaced, or nothing (async-signal-safe)
static void outset_undo(const cli_outset* s, int k) {
  if (s->backup[k] && s->backup[k][0]) {
    (void)rename(s->backup[k], s->path[k]);
    (void)unlink(s->backup[k]);  // rename does nothing when both names are links to one file
  } else if (s->fresh[k]) {
    unlink(s->path[k]);
  }
}

void cli_outsets_rollback(void) {
  for (int i = 0; i < OUTSET_SLOTS; i++) {
    cli_outset* s = atomic_load(&outset_live[i]);
    if (s)
      for (int k = 0; k < s->n; k++) outset_undo(s, k);
  }
}

static char* dup_str(const char* s) {
  size_t n = strlen(s) + 1;
  char* c = vd_malloc(n);
  if (c) memcpy(c, s, n);
  return c;
}

static void free_str(char* s) {
  if (s) vd_free(s, strlen(s) + 1);
}

static void outset_free(cli_outset* s) {
  for (int k = 0; k < s->n; k++) {
    if (s->path) free_str(s->path[k]);
    if (s->backup) free_str(s->backup[k]);
  }
  vd_free(s->path, (size_t)s->cap * sizeof(char*));
  vd_free(s->backup, (size_t)s->cap * sizeof(char*));
  vd_free(s->fresh, (size_t)s->cap);
  vd_free(s->stale, (size_t)s->cap);
  memset(s, 0, sizeof *s);
  s->slot = -1;
}

// can path be written: not a folder, in a folder that exists and takes files?
static vd_status check_output(const char* path, vd_error* err) {
  struct stat sb;
  if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot write: it is a folder");
  char parent[4200];
  parent_of(path, parent, sizeof parent);
  if (stat(parent, &sb) != 0)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot write: the folder %s does not exist", parent);
  if (!S_ISDIR(sb.st_mode))
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot write: %s is not a folder", parent);
  if (access(parent, W_OK | X_OK) != 0)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot write into the folder %s: %s", parent, strerror(errno));
  return VD_OK;
}

vd_status cli_outset_begin(cli_outset* s, const char* const* paths, int n, const unsigned char* stale, vd_error* err) {
  memset(s, 0, sizeof *s);
  s->slot = -1;
  // every output checked before anything is touched
  for (int k = 0; k < n; k++) {
    vd_status st = check_output(paths[k], err);
    if (st) return st;
  }
  s->cap = n ? n : 1;
  s->path = vd_calloc((size_t)s->cap, sizeof(char*));
  s->backup = vd_calloc((size_t)s->cap, sizeof(char*));
  s->fresh = vd_calloc((size_t)s->cap, 1);
  s->stale = vd_calloc((size_t)s->cap, 1);
  if (!s->path || !s->backup || !s->fresh || !s->stale) {
    outset_free(s);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  // the files the outputs replace wait under another name (a hard link, or the file itself
  // moved where links are not supported) until the set is complete
  for (int k = 0; k < n; k++) {
    s->path[k] = dup_str(paths[k]);
    s->n = k + 1;
    s->stale[k] = stale && stale[k];
    if (!s->path[k]) {
      cli_outset_end(s, 0);
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
    struct stat sb;
    if (lstat(paths[k], &sb) != 0) {
      s->fresh[k] = 1;
      continue;
    }
    char bak[4300];
    snprintf(bak, sizeof bak, "%s.bak.%ld", paths[k], (long)getpid());
    s->backup[k] = dup_str(bak);
    if (!s->backup[k]) {
      cli_outset_end(s, 0);
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
    unlink(bak);
    if (link(paths[k], bak) != 0 && rename(paths[k], bak) != 0) {
      int e = errno;
      s->backup[k][0] = 0;
      cli_outset_end(s, 0);
      return vd_error_set(err, VD_ERR_IO, paths[k], 0, 0, "cannot keep the file it replaces aside: %s", strerror(e));
    }
  }
  // visible to the signal handler
  for (int i = 0; i < OUTSET_SLOTS; i++) {
    cli_outset* none = NULL;
    if (atomic_compare_exchange_strong(&outset_live[i], &none, s)) {
      s->slot = i;
      break;
    }
  }
  return VD_OK;
}

void cli_outset_end(cli_outset* s, int ok) {
  if (s->slot >= 0) atomic_store(&outset_live[s->slot], NULL);
  for (int k = 0; k < s->n; k++) {
    if (!ok) {
      outset_undo(s, k);
      continue;
    }
    if (s->stale[k]) unlink(s->path[k]);  // an earlier run's file this run does not write
    if (s->backup[k] && s->backup[k][0]) unlink(s->backup[k]);
  }
  outset_free(s);
}
