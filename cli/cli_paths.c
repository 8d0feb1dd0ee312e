// SPDX-License-Identifier: MIT
// Inputs and outputs of a command: no output may replace an input. Files are compared by
// device and inode, so another spelling of the same path, a hard link or a symbolic link to
// an input is caught as well as the same name.
#define _POSIX_C_SOURCE 200809L
#include <string.h>
#include <sys/stat.h>

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
