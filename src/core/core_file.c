// SPDX-License-Identifier: MIT
// Whole-file reads and atomic writes: output goes to a temporary name beside the final path
// and is renamed only when complete, so a failed or interrupted run leaves nothing that looks
// whole.
#define _POSIX_C_SOURCE 200809L
#include "verdant/core.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

// the process's output guard (vd_outfile_set_guard), unset: plain atomic files
static vd_outfile_guard guard;
static int guard_set;

void vd_outfile_set_guard(const vd_outfile_guard* g) {
  guard_set = g != NULL;
  if (g) guard = *g;
}

void vd_outfile_tmp_path(const char* path, char* buf, size_t cap) {
  snprintf(buf, cap, "%s.tmp.%ld", path, (long)getpid());
}

vd_status vd_outfile_open(vd_outfile* f, const char* path, vd_error* err) {
  memset(f, 0, sizeof *f);
  if (!path || !path[0]) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "empty output path");
  if (strlen(path) >= sizeof f->path)
    return vd_error_set(err, VD_ERR_ARG, path, 0, 0, "output path too long");
  snprintf(f->path, sizeof f->path, "%s", path);
  vd_outfile_tmp_path(path, f->tmp, sizeof f->tmp);
  // the guard sees the output before its first byte (and may refuse it)
  if (guard_set && guard.open) {
    vd_status st = guard.open(guard.user, f->path, f->tmp, err);
    if (st) {
      f->tmp[0] = 0;
      return st;
    }
  }
  f->fp = fopen(f->tmp, "wb");
  if (!f->fp) {
    int e = errno;
    if (guard_set && guard.abort) guard.abort(guard.user, f->path, f->tmp);
    f->tmp[0] = 0;
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot write: %s", strerror(e));
  }
  return VD_OK;
}

vd_status vd_outfile_commit(vd_outfile* f, vd_error* err) {
  if (!f->fp) return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "output file is not open");
  int bad = ferror(f->fp);
  if (fflush(f->fp) != 0) bad = 1;
  int e = errno;
  if (fclose(f->fp) != 0) bad = 1, e = errno;
  f->fp = NULL;
  if (bad) {
    vd_outfile_abort(f);
    return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "write failed: %s", strerror(e));
  }
  // a guard puts the file in place when the whole program succeeded
  if (guard_set && guard.commit) {
    vd_status st = guard.commit(guard.user, f->path, f->tmp, err);
    if (st) vd_outfile_abort(f);
    f->tmp[0] = 0;
    return st;
  }
  if (rename(f->tmp, f->path) != 0) {
    e = errno;
    remove(f->tmp);
    f->tmp[0] = 0;
    return vd_error_set(err, VD_ERR_IO, f->path, 0, 0, "cannot rename into place: %s", strerror(e));
  }
  f->tmp[0] = 0;
  return VD_OK;
}

void vd_outfile_abort(vd_outfile* f) {
  if (f->fp) fclose(f->fp);
  f->fp = NULL;
  if (f->tmp[0]) {
    remove(f->tmp);
    if (guard_set && guard.abort) guard.abort(guard.user, f->path, f->tmp);
  }
  f->tmp[0] = 0;
}

vd_status vd_outdir_make(const char* path, vd_error* err) {
  if (guard_set && guard.mkdir) return guard.mkdir(guard.user, path, err);
  if (mkdir(path, 0777) != 0 && errno != EEXIST)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot create the folder: %s", strerror(errno));
  struct stat sb;
  if (stat(path, &sb) != 0 || !S_ISDIR(sb.st_mode))
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot create the folder: a file of that name is there");
  return VD_OK;
}

vd_status vd_file_read(const char* path, char** text, size_t* len, vd_error* err) {
  *text = NULL;
  *len = 0;
  struct stat st;
  if (stat(path, &st) != 0)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot open: %s", strerror(errno));
  if (S_ISDIR(st.st_mode)) return vd_error_set(err, VD_ERR_IO, path, 0, 0, "is a directory");
  // a regular file too large is refused before a byte is read
  if (S_ISREG(st.st_mode) && (uint64_t)st.st_size > (uint64_t)VD_FILE_MAX)
    return vd_error_set(err, VD_ERR_LIMIT, path, 0, 0, "file of %lld bytes, larger than the limit of %zu bytes",
                        (long long)st.st_size, (size_t)VD_FILE_MAX);
  FILE* fp = fopen(path, "rb");
  if (!fp) return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot open: %s", strerror(errno));
  // read in chunks: works for pipes and files whose size changes
  size_t cap = 65536, n = 0;
  char* buf = vd_malloc(cap + 1);
  if (!buf) {
    fclose(fp);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory reading file");
  }
  for (;;) {
    if (n == cap) {
      if (cap >= VD_FILE_MAX) {
        vd_free(buf, cap + 1);
        fclose(fp);
        return vd_error_set(err, VD_ERR_LIMIT, path, 0, 0, "file larger than %zu bytes",
                            (size_t)VD_FILE_MAX);
      }
      char* nb = vd_realloc(buf, cap + 1, cap * 2 + 1);
      if (!nb) {
        vd_free(buf, cap + 1);
        fclose(fp);
        return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory reading file");
      }
      buf = nb;
      cap *= 2;
    }
    size_t got = fread(buf + n, 1, cap - n, fp);
    n += got;
    if (got == 0) break;
  }
  int bad = ferror(fp);
  fclose(fp);
  if (bad) {
    vd_free(buf, cap + 1);
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "read error");
  }
  // shrink to exact size so the caller frees with len + 1
  char* exact = vd_realloc(buf, cap + 1, n + 1);
  if (!exact) {
    vd_free(buf, cap + 1);
    return vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory reading file");
  }
  exact[n] = 0;
  *text = exact;
  *len = n;
  return VD_OK;
}

int vd_text_line(vd_text* t, const char** ls, size_t* ll) {
  if (t->pos >= t->len) return 0;
  const char* start = t->s + t->pos;
  const char* nl = memchr(start, '\n', t->len - t->pos);
  size_t n = nl ? (size_t)(nl - start) : t->len - t->pos;
  t->pos += n + (nl != NULL);
  t->line++;
  *ls = start;
  *ll = n && start[n - 1] == '\r' ? n - 1 : n;
  return 1;
}

void vd_outfile_remove(const char* path) {
  if (!guard_set) {
    remove(path);
    return;
  }
  char tmp[4200];
  vd_outfile_tmp_path(path, tmp, sizeof tmp);
  remove(tmp);
  if (guard.abort) guard.abort(guard.user, path, tmp);
}

void vd_outdir_remove(const char* path) {
  if (!guard_set) rmdir(path);  // only when empty
}
