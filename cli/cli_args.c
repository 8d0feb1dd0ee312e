// SPDX-License-Identifier: MIT
// The command line before a command sees it: `--opt=value` becomes `--opt value`; after `--`
// every argument is an operand (a file whose name starts with '-' is passed as ./-name, so no
// parser takes it for an option); `help CMD` is `CMD --help`; a repeated -o is an error.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

// the rewritten command line lives until the process ends
static char** args;

// "--name=value" with a name of letters, digits and dashes
static size_t option_with_value(const char* a) {
  if (strncmp(a, "--", 2) != 0 || !a[2]) return 0;
  const char* eq = strchr(a, '=');
  if (!eq || eq == a + 2) return 0;
  for (const char* p = a + 2; p < eq; p++)
    if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '-')) return 0;
  return (size_t)(eq - a);
}

int cli_args_normalize(int* argc, char*** argv) {
  int n = *argc;
  char** in = *argv;
  args = calloc((size_t)2 * (size_t)n + 2, sizeof(char*));
  if (!args) {
    fprintf(stderr, "verdant: out of memory\n");
    return EXIT_FAIL;
  }
  int m = 0, operands = 0, outputs = 0;
  for (int i = 0; i < n; i++) {
    const char* a = in[i];
    // verdant help CMD: the command's own help
    if (i == 1 && !strcmp(a, "help") && n > 2) {
      args[m++] = in[2], args[m++] = "--help";
      i = 2;
      continue;
    }
    if (i < 2 || operands) {
      if (operands && a[0] == '-' && a[1]) {
        // an operand that looks like an option: the same file by another name
        size_t len = strlen(a) + 3;
        char* p = malloc(len);
        if (!p) {
          fprintf(stderr, "verdant: out of memory\n");
          return EXIT_FAIL;
        }
        snprintf(p, len, "./%s", a);
        args[m++] = p;
      } else {
        args[m++] = in[i];
      }
      continue;
    }
    if (!strcmp(a, "--")) {
      operands = 1;
      continue;
    }
    size_t k = option_with_value(a);
    if (k) {
      char* name = malloc(k + 1);
      if (!name) {
        fprintf(stderr, "verdant: out of memory\n");
        return EXIT_FAIL;
      }
      memcpy(name, a, k);
      name[k] = 0;
      args[m++] = name;
      args[m++] = in[i] + k + 1;
      outputs += !strcmp(name, "--output");
      continue;
    }
    outputs += !strcmp(a, "-o") || !strcmp(a, "--output");
    args[m++] = in[i];
  }
  args[m] = NULL;
  if (outputs > 1) {
    fprintf(stderr, "verdant %s: -o/--output given %d times; one output per command (see 'verdant %s --help')\n",
            n > 1 ? in[1] : "", outputs, n > 1 ? in[1] : "");
    return EXIT_USAGE;
  }
  *argc = m;
  *argv = args;
  return 0;
}
