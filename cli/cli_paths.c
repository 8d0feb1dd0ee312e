// SPDX-License-Identifier: MIT
// The output layer: every file the verdant command writes goes through here.
//
// A command declares its inputs and outputs before the first byte is written (cli_out_input,
// cli_out_file, cli_out_folder), and cli_out_check compares them: no output may be an input
// (same device and inode, so another spelling, a hard link or a symbolic link is caught as well
// as the same name), no input may lie in an output folder under a name the command writes there,
// no two outputs may be one file, and every output must be writable (else exit 2, before
// anything runs). The library's writers (vd_outfile, vd_outdir_make) then ask this layer through
// the output guard: a path that was not declared is refused; each file is written under a
// temporary name beside its target and stays there until the whole command succeeded
// (cli_out_finish renames them all into place, and removes the files of an earlier run that
// this one replaces but does not write). On an error, SIGINT or SIGTERM every temporary file and
// every folder made goes, so an earlier run folder is left byte-identical. Batches that resume
// (dataset items, harvest episodes) put each complete item in place with cli_out_publish.
#define _DEFAULT_SOURCE  // realpath (XSI) beside POSIX 2008
#include <dirent.h>
#include <errno.h>
#include <fnmatch.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

int cli_same_file(const char* a, const char* b) {
  struct stat sa, sb;
  if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

// ---------------------------------------------------------------------------------------------
// paths

// the folder part of a path ("." when it has none)
static void parent_of(const char* path, char* buf, size_t cap) {
  size_t n = strlen(path);
  while (n > 1 && path[n - 1] == '/') n--;  // "dir/" is dir
  const char* slash = NULL;
  for (size_t k = 0; k < n; k++)
    if (path[k] == '/') slash = path + k;
  if (!slash)
    snprintf(buf, cap, ".");
  else if (slash == path)
    snprintf(buf, cap, "/");
  else
    snprintf(buf, cap, "%.*s", (int)(slash - path), path);
}

// the absolute path with every existing folder resolved (symbolic links, "..", "//"): the
// longest existing prefix through realpath, the rest appended; 0 when it does not fit
static int canon(const char* path, char* out, size_t cap) {
  char rest[PATH_MAX * 2] = "", cur[PATH_MAX * 2];
  snprintf(cur, sizeof cur, "%s", path[0] ? path : ".");
  for (;;) {
    size_t n = strlen(cur);
    while (n > 1 && cur[n - 1] == '/') cur[--n] = 0;
    char real[PATH_MAX];
    if (realpath(cur, real)) {
      int w = snprintf(out, cap, "%s%s%s", real, rest[0] && strcmp(real, "/") != 0 ? "/" : "", rest);
      return w > 0 && (size_t)w < cap;
    }
    // not there (yet): take the last part into rest and try the folder above
    char* slash = strrchr(cur, '/');
    const char* base = slash ? slash + 1 : cur;
    char tmp[PATH_MAX * 2];
    snprintf(tmp, sizeof tmp, "%s%s%s", base, rest[0] ? "/" : "", rest);
    snprintf(rest, sizeof rest, "%s", tmp);
    if (!slash)
      snprintf(cur, sizeof cur, ".");
    else if (slash == cur)
      snprintf(cur, sizeof cur, "/");
    else
      *slash = 0;
  }
}

// the part of path below folder dir (both canonical), NULL when it is not below it
static const char* below(const char* dir, const char* path) {
  size_t n = strlen(dir);
  if (!strcmp(dir, "/")) return path[0] == '/' ? path + 1 : NULL;
  return !strncmp(dir, path, n) && path[n] == '/' ? path + n + 1 : NULL;
}

static char* dup_str(const char* s) {
  size_t n = strlen(s) + 1;
  char* c = malloc(n);
  if (c) memcpy(c, s, n);
  return c;
}

// ---------------------------------------------------------------------------------------------
// declarations (made on the main thread before any output is open)

#define IO_MAX_OUT 64
#define IO_MAX_MEMBER 16

typedef struct io_in {
  const char* what;     // the option or role ("PLANT", "--wind-file", "the scene's robot")
  char* path;           // as given
  char canon[PATH_MAX]; // canonical
  struct stat sb;       // when it exists
  int exists;
} io_in;

typedef struct io_out {
  const char* what;                     // the option ("-o", "--lstring")
  char* path;                           // as given
  const char* shown;                    // the name messages give (path, or a --frames pattern)
  char canon[PATH_MAX];                 // canonical
  int folder;                           // a folder of files (members), else one file
  int replace;                          // folder: its members of an earlier run this one does not write go
  char* member[IO_MAX_MEMBER];          // folder: fnmatch patterns of the files written, relative
  int nmember;
} io_out;

static io_in* io_ins;  // grown as needed (a growth run's ages)
static int io_nin, io_capin;
static io_out io_outs[IO_MAX_OUT];
static int io_nout;
static int io_overflow;  // more declarations than fit: the check fails

void cli_out_input(const char* what, const char* path) {
  if (!path || !path[0]) return;
  if (io_nin == io_capin) {
    int cap = io_capin ? 2 * io_capin : 16;
    io_in* more = realloc(io_ins, (size_t)cap * sizeof *more);
    if (!more) {
      io_overflow = 1;
      return;
    }
    io_ins = more, io_capin = cap;
  }
  io_in* in = &io_ins[io_nin];
  memset(in, 0, sizeof *in);
  in->what = what;
  in->path = dup_str(path);
  if (!in->path || !canon(path, in->canon, sizeof in->canon)) {
    io_overflow = 1;
    return;
  }
  in->exists = stat(path, &in->sb) == 0;
  io_nin++;
}

static io_out* add_out(const char* what, const char* path) {
  if (!path || !path[0]) return NULL;
  if (io_nout == IO_MAX_OUT) {
    io_overflow = 1;
    return NULL;
  }
  io_out* o = &io_outs[io_nout];
  memset(o, 0, sizeof *o);
  o->what = what;
  o->path = dup_str(path);
  o->shown = o->path;
  if (!o->path || !canon(path, o->canon, sizeof o->canon)) {
    io_overflow = 1;
    return NULL;
  }
  io_nout++;
  return o;
}

void cli_out_file(const char* what, const char* path) {
  add_out(what, path);
}

void cli_out_folder(const char* what, const char* dir, const char* const* members, int nmember, int replace) {
  cli_out_pattern(what, NULL, dir, members, nmember, replace);
}

void cli_out_pattern(const char* what, const char* shown, const char* dir, const char* const* members, int nmember,
                     int replace) {
  io_out* o = add_out(what, dir);
  if (!o) return;
  if (shown && !(o->shown = dup_str(shown))) io_overflow = 1;
  o->folder = 1;
  o->replace = replace;
  for (int k = 0; k < nmember && k < IO_MAX_MEMBER; k++)
    if (!(o->member[o->nmember++] = dup_str(members[k]))) io_overflow = 1;
  if (nmember > IO_MAX_MEMBER) io_overflow = 1;
}

// is the canonical path rel (below an output folder) one of its members?
static int is_member(const io_out* o, const char* rel) {
  for (int k = 0; k < o->nmember; k++)
    if (fnmatch(o->member[k], rel, FNM_PATHNAME) == 0) return 1;
  return 0;
}

// the output (index) that declares the canonical path c, -1 none
static int declared(const char* c) {
  for (int k = 0; k < io_nout; k++) {
    const io_out* o = &io_outs[k];
    if (!o->folder && !strcmp(o->canon, c)) return k;
    const char* rel = o->folder ? below(o->canon, c) : NULL;
    if (rel && is_member(o, rel)) return k;
  }
  return -1;
}

// is the canonical folder c an output folder, or a folder inside one that holds members?
static int declared_dir(const char* c) {
  for (int k = 0; k < io_nout; k++) {
    const io_out* o = &io_outs[k];
    if (!o->folder) continue;
    if (!strcmp(o->canon, c)) return 1;
    const char* rel = below(o->canon, c);
    if (!rel) continue;
    // some member pattern starts with this folder's part: "item_*/plant.json" holds "item_000001"
    for (int m = 0; m < o->nmember; m++) {
      const char* slash = strrchr(o->member[m], '/');
      if (!slash) continue;
      char head[PATH_MAX];
      snprintf(head, sizeof head, "%.*s", (int)(slash - o->member[m]), o->member[m]);
      if (fnmatch(head, rel, FNM_PATHNAME) == 0) return 1;
    }
  }
  return 0;
}

// can path be written (not a folder, in a folder that exists and takes files)? 0, or the reason
static int writable(const io_out* o, char* why, size_t cap) {
  struct stat sb;
  char parent[PATH_MAX];
  if (o->folder) {
    if (stat(o->path, &sb) == 0) {
      if (!S_ISDIR(sb.st_mode)) return snprintf(why, cap, "it is a file, not a folder"), 1;
      if (access(o->path, W_OK | X_OK) != 0) return snprintf(why, cap, "%s", strerror(errno)), 1;
      return 0;
    }
  } else if (stat(o->path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
    return snprintf(why, cap, "it is a folder"), 1;
  }
  parent_of(o->path, parent, sizeof parent);
  if (stat(parent, &sb) != 0) return snprintf(why, cap, "the folder %s does not exist", parent), 1;
  if (!S_ISDIR(sb.st_mode)) return snprintf(why, cap, "%s is not a folder", parent), 1;
  if (access(parent, W_OK | X_OK) != 0)
    return snprintf(why, cap, "the folder %s does not take files: %s", parent, strerror(errno)), 1;
  return 0;
}

// would output o replace input in?
static int replaces(const io_out* o, const io_in* in) {
  struct stat sb;
  if (!o->folder) {
    if (!strcmp(o->canon, in->canon)) return 1;
    return in->exists && stat(o->path, &sb) == 0 && sb.st_dev == in->sb.st_dev && sb.st_ino == in->sb.st_ino;
  }
  // a folder: the input folder itself, or an input it holds under a name written there (the input
  // canonical, or through a hard link: every file of the folder with the input's inode)
  if (in->exists && stat(o->path, &sb) == 0 && sb.st_dev == in->sb.st_dev && sb.st_ino == in->sb.st_ino) return 1;
  const char* rel = below(o->canon, in->canon);
  if (rel && is_member(o, rel)) return 1;
  if (!in->exists || !S_ISREG(in->sb.st_mode) || in->sb.st_nlink < 2) return 0;
  DIR* d = opendir(o->path);
  int hit = 0;
  struct dirent* e;
  while (d && !hit && (e = readdir(d))) {
    char p[PATH_MAX * 2];
    snprintf(p, sizeof p, "%s/%s", o->path, e->d_name);
    hit = is_member(o, e->d_name) && stat(p, &sb) == 0 && sb.st_dev == in->sb.st_dev && sb.st_ino == in->sb.st_ino;
  }
  if (d) closedir(d);
  return hit;
}

// do outputs a and b name one file (or a file a folder writes)?
static int collide(const io_out* a, const io_out* b) {
  if (!a->folder && !b->folder) {
    struct stat sa, sb;
    if (!strcmp(a->canon, b->canon)) return 1;
    return stat(a->path, &sa) == 0 && stat(b->path, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  }
  if (a->folder && b->folder) return !strcmp(a->canon, b->canon);
  const io_out* f = a->folder ? a : b;
  const io_out* o = a->folder ? b : a;
  const char* rel = below(f->canon, o->canon);
  return !strcmp(f->canon, o->canon) || (rel && is_member(f, rel));
}

int cli_out_check(const char* cmd) {
  if (io_overflow) return cli_usage_error(cmd, "too many inputs or outputs, or a path too long");
  for (int i = 0; i < io_nout; i++) {
    const io_out* o = &io_outs[i];
    for (int k = 0; k < io_nin; k++)
      if (replaces(o, &io_ins[k])) {
        if (o->folder && strcmp(o->canon, io_ins[k].canon) != 0)
          return cli_usage_error(cmd, "the output%s '%s' (%s) would replace the input '%s' (%s), a name it writes "
                                 "there; choose another output %s", o->shown == o->path ? " folder" : "s", o->shown,
                                 o->what, io_ins[k].path, io_ins[k].what, o->shown == o->path ? "folder" : "name");
        return cli_usage_error(cmd, "the output '%s' (%s) would replace the input '%s' (%s); choose another output name",
                               o->shown, o->what, io_ins[k].path, io_ins[k].what);
      }
    for (int k = 0; k < i; k++)
      if (collide(&io_outs[k], o))
        return cli_usage_error(cmd, "the outputs '%s' (%s) and '%s' (%s) are one file; choose two names",
                               io_outs[k].shown, io_outs[k].what, o->shown, o->what);
  }
  // one rule: an output that cannot be written is bad usage (2), found before anything runs; a
  // write that fails during the run (a full disk) is a failed run (1)
  for (int i = 0; i < io_nout; i++) {
    char why[PATH_MAX + 128];
    if (writable(&io_outs[i], why, sizeof why))
      return cli_usage_error(cmd, "cannot write '%s' (%s): %s", io_outs[i].shown, io_outs[i].what, why);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// what is being written: temporary files and folders made, read by the signal handler

enum { ENT_FREE, ENT_OPEN, ENT_PENDING, ENT_DONE };

typedef struct io_ent {
  char* path;         // the final name, as the writer gave it
  char* tmp;          // the temporary name beside it
  atomic_int state;   // ENT_*
} io_ent;

#define ENT_CHUNK 1024
#define ENT_CHUNKS 4096  // up to 4 million files in one command
static io_ent* ent_chunk[ENT_CHUNKS];
static atomic_int ent_n;
#define DIR_MAX 65536
static char* dir_made[DIR_MAX];  // folders this run made (removed again, deepest last made first)
static atomic_int dir_n;
static pthread_mutex_t io_lock = PTHREAD_MUTEX_INITIALIZER;

static io_ent* ent_at(int i) {
  return &ent_chunk[i / ENT_CHUNK][i % ENT_CHUNK];
}

// the entry of tmp (newest first), -1 none; under io_lock
static int ent_find(const char* tmp) {
  for (int i = atomic_load(&ent_n) - 1; i >= 0; i--) {
    io_ent* e = ent_at(i);
    int s = atomic_load(&e->state);
    if ((s == ENT_OPEN || s == ENT_PENDING) && !strcmp(e->tmp, tmp)) return i;
  }
  return -1;
}

// make folder path (canonical c) and the folders above it inside an output folder; under io_lock
static vd_status make_dirs(const char* path, vd_error* err) {
  struct stat sb;
  if (stat(path, &sb) == 0) {
    if (S_ISDIR(sb.st_mode)) return VD_OK;
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot create the folder: a file of that name is there");
  }
  char parent[PATH_MAX], c[PATH_MAX];
  parent_of(path, parent, sizeof parent);
  if (canon(parent, c, sizeof c) && declared_dir(c)) {
    vd_status st = make_dirs(parent, err);
    if (st) return st;
  }
  if (mkdir(path, 0777) != 0 && errno != EEXIST)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "cannot create the folder: %s", strerror(errno));
  int n = atomic_load(&dir_n);
  if (n < DIR_MAX && (dir_made[n] = dup_str(path))) atomic_store(&dir_n, n + 1);
  return VD_OK;
}

static vd_status guard_mkdir(void* user, const char* path, vd_error* err) {
  (void)user;
  char c[PATH_MAX];
  if (!canon(path, c, sizeof c) || !declared_dir(c))
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "internal error: the folder was not declared as an output");
  pthread_mutex_lock(&io_lock);
  vd_status st = make_dirs(path, err);
  pthread_mutex_unlock(&io_lock);
  return st;
}

static vd_status guard_open(void* user, const char* path, const char* tmp, vd_error* err) {
  (void)user;
  char c[PATH_MAX], parent[PATH_MAX];
  if (!canon(path, c, sizeof c) || declared(c) < 0)
    return vd_error_set(err, VD_ERR_IO, path, 0, 0, "internal error: the file was not declared as an output");
  vd_status st = VD_OK;
  pthread_mutex_lock(&io_lock);
  // its folder, when it is an output folder (or inside one) not made yet
  parent_of(path, parent, sizeof parent);
  struct stat sb;
  if (stat(parent, &sb) != 0 && canon(parent, c, sizeof c) && declared_dir(c)) st = make_dirs(parent, err);
  // the same file written again (its temporary file is there): its entry is reused
  int i = st || access(tmp, F_OK) != 0 ? -1 : ent_find(tmp);
  if (!st && i >= 0) {
    atomic_store(&ent_at(i)->state, ENT_OPEN);
  } else if (!st) {
    int n = atomic_load(&ent_n);
    if (n == ENT_CHUNK * ENT_CHUNKS || (!ent_chunk[n / ENT_CHUNK] && !(ent_chunk[n / ENT_CHUNK] = calloc(ENT_CHUNK, sizeof(io_ent))))) {
      st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory for the outputs");
    } else {
      io_ent* e = ent_at(n);
      e->path = dup_str(path);
      e->tmp = dup_str(tmp);
      if (!e->path || !e->tmp) {
        free(e->path), free(e->tmp);
        e->path = e->tmp = NULL;
        st = vd_error_set(err, VD_ERR_NOMEM, path, 0, 0, "out of memory for the outputs");
      } else {
        atomic_store(&e->state, ENT_OPEN);
        atomic_store(&ent_n, n + 1);  // now seen by the signal handler
      }
    }
  }
  pthread_mutex_unlock(&io_lock);
  return st;
}

static vd_status guard_commit(void* user, const char* path, const char* tmp, vd_error* err) {
  (void)user;
  pthread_mutex_lock(&io_lock);
  int i = ent_find(tmp);
  if (i >= 0) atomic_store(&ent_at(i)->state, ENT_PENDING);
  pthread_mutex_unlock(&io_lock);
  if (i < 0) return vd_error_set(err, VD_ERR_IO, path, 0, 0, "internal error: the file was not opened as an output");
  return VD_OK;
}

static void guard_abort(void* user, const char* path, const char* tmp) {
  (void)user, (void)path;
  pthread_mutex_lock(&io_lock);
  int i = ent_find(tmp);
  if (i >= 0) atomic_store(&ent_at(i)->state, ENT_FREE);
  pthread_mutex_unlock(&io_lock);
}

void cli_out_init(void) {
  vd_outfile_guard g = {guard_open, guard_commit, guard_abort, guard_mkdir, NULL};
  vd_outfile_set_guard(&g);
}

const char* cli_out_current(const char* path, char* buf, size_t cap) {
  char tmp[PATH_MAX + 64];
  vd_outfile_tmp_path(path, tmp, sizeof tmp);
  pthread_mutex_lock(&io_lock);
  int i = ent_find(tmp);
  pthread_mutex_unlock(&io_lock);
  snprintf(buf, cap, "%s", i >= 0 ? tmp : path);
  return buf;
}

// put entry i in place (ok) or drop its temporary file
static int settle(int i, int ok) {
  io_ent* e = ent_at(i);
  int s = atomic_load(&e->state);
  if (s == ENT_PENDING && ok) {
    if (rename(e->tmp, e->path) != 0) {
      fprintf(stderr, "verdant: cannot put '%s' in place: %s\n", e->path, strerror(errno));
      unlink(e->tmp);
      atomic_store(&e->state, ENT_FREE);
      return 1;
    }
    atomic_store(&e->state, ENT_DONE);
  } else if (s == ENT_OPEN || s == ENT_PENDING) {
    unlink(e->tmp);
    atomic_store(&e->state, ENT_FREE);
  }
  return 0;
}

int cli_out_publish(const char* const* paths, int n, int ok) {
  int bad = 0;
  pthread_mutex_lock(&io_lock);
  for (int k = 0; k < n; k++) {
    char tmp[PATH_MAX + 64];
    vd_outfile_tmp_path(paths[k], tmp, sizeof tmp);
    int i = ent_find(tmp);
    if (i >= 0) bad |= settle(i, ok);
  }
  pthread_mutex_unlock(&io_lock);
  return bad;
}

// the files this run put in place, by device and inode
typedef struct written {
  dev_t* dev;
  ino_t* ino;
  int n;
} written;

static int was_written(const written* w, const struct stat* sb) {
  for (int k = 0; k < w->n; k++)
    if (w->dev[k] == sb->st_dev && w->ino[k] == sb->st_ino) return 1;
  return 0;
}

// remove the members of folder dir (output o, rel its part below it) of an earlier run that
// this run did not write; empty member folders go too
static void drop_stale(const io_out* o, const char* dir, const char* rel, const written* w, int depth) {
  DIR* d = opendir(dir);
  if (!d) return;
  struct dirent* e;
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    char p[PATH_MAX * 2], r[PATH_MAX * 2];
    snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
    snprintf(r, sizeof r, "%s%s%s", rel, rel[0] ? "/" : "", e->d_name);
    struct stat sb;
    if (lstat(p, &sb) != 0) continue;
    if (S_ISDIR(sb.st_mode)) {
      char c[PATH_MAX * 3];
      snprintf(c, sizeof c, "%s/%s", o->canon, r);
      if (depth < 4 && declared_dir(c)) {
        drop_stale(o, p, r, w, depth + 1);
        rmdir(p);  // only when empty
      }
    } else if (is_member(o, r) && !was_written(w, &sb)) {
      unlink(p);
    }
  }
  closedir(d);
}

int cli_out_drop_orphan(const char* path) {
  // "<name>.tmp.<pid>" (or ".bak.<pid>", what earlier versions kept aside) of no process here
  const char* base = strrchr(path, '/');
  base = base ? base + 1 : path;
  const char* t = strstr(base, ".tmp.");
  if (!t) t = strstr(base, ".bak.");
  if (!t) return 0;
  char* end;
  long pid = strtol(t + 5, &end, 10);
  if (*end || pid <= 0 || pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH) return 0;
  return unlink(path) == 0;
}

// every temporary file and folder made goes (async-signal-safe: atomics, unlink, rmdir)
void cli_out_rollback(void) {
  int n = atomic_load(&ent_n);
  for (int i = 0; i < n; i++) {
    io_ent* e = ent_at(i);
    int s = atomic_load(&e->state);
    if (s == ENT_OPEN || s == ENT_PENDING) unlink(e->tmp);
  }
  for (int k = atomic_load(&dir_n) - 1; k >= 0; k--) rmdir(dir_made[k]);  // only when empty
}

int cli_out_finish(const char* cmd, int rc) {
  // nothing interrupts the commit: it is all of the renames or none of the run
  sigset_t block, old;
  sigemptyset(&block);
  sigaddset(&block, SIGINT);
  sigaddset(&block, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &block, &old);
  int n = atomic_load(&ent_n), bad = 0;
  if (rc == EXIT_OK) {
    for (int i = 0; i < n; i++) bad |= settle(i, !bad);
    if (bad) rc = EXIT_FAIL;
  }
  if (rc != EXIT_OK) {
    cli_out_rollback();
  } else {
    // an earlier run's files that this run replaces and did not write
    written w = {calloc((size_t)n + 1, sizeof(dev_t)), calloc((size_t)n + 1, sizeof(ino_t)), 0};
    for (int i = 0; w.dev && w.ino && i < n; i++) {
      struct stat sb;
      io_ent* e = ent_at(i);
      if (atomic_load(&e->state) == ENT_DONE && stat(e->path, &sb) == 0)
        w.dev[w.n] = sb.st_dev, w.ino[w.n++] = sb.st_ino;
    }
    for (int k = 0; w.dev && w.ino && k < io_nout; k++)
      if (io_outs[k].folder && io_outs[k].replace) drop_stale(&io_outs[k], io_outs[k].path, "", &w, 0);
    free(w.dev);
    free(w.ino);
  }
  pthread_sigmask(SIG_SETMASK, &old, NULL);
  if (bad) fprintf(stderr, "verdant %s: the outputs could not be put in place; nothing was changed after the first failure\n", cmd);
  return rc;
}
