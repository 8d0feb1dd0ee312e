// SPDX-License-Identifier: MIT
// The verdant command: git-style subcommands. The only place that prints or exits.
#include <stdio.h>
#include <string.h>

#include "cli.h"

static void log_to_stderr(void* user, int level, const char* msg) {
  (void)user;
  fprintf(stderr, "%s%s\n", level ? "warning: " : "", msg);
}

static const char* main_help =
    "usage: verdant <command> [options]\n"
    "\n"
    "Virtual plants: L-systems in the L-Py file syntax grown into labelled geometry.\n"
    "\n"
    "commands:\n"
    "  grow      L-system (.lpy) or plant file → plant JSON, OBJ or PLY, with --stats\n"
    "  cloud     plant → labelled point cloud (PLY, PCD, XYZ/CSV, LAS), scanner effects\n"
    "  dataset   many plants of one model → labelled clouds (+ images) + manifest, --jobs\n"
    "  render    plant, point cloud or sim run → PNG colour, depth, label/instance masks, MP4\n"
    "  sim       plant physics (Cosserat rods): gravity, wind, probes, fracture → frames, events\n"
    "  validate  the physics against analytic references (--json, --full)\n"
    "  harvest   a MuJoCo robot picks a fruit (pull, bend, twist) → summary, events, frames\n"
    "  export    plant → URDF, SDF or MuJoCo MJCF for robot simulators\n"
    "\n"
    "Run 'verdant <command> --help' or 'verdant help <command>' for the options of a command;\n"
    "'verdant --version' prints the version. Options take their value as '--opt value' or\n"
    "'--opt=value'; after '--' every argument is a file name.\n"
    "Exit codes: 0 success, 1 failed run, 2 bad usage or bad input.\n";

int main(int argc, char** argv) {
  vd_set_log(log_to_stderr, NULL);
  cli_signals_init();
  cli_out_init();  // every output through one layer: declared, checked, in place only on success
  if (argc < 2) {
    fputs(main_help, stderr);
    return EXIT_USAGE;
  }
  int rc = cli_args_normalize(&argc, &argv);  // --opt=value, --, help CMD, a repeated -o
  if (rc) return rc;
  const char* cmd = argv[1];
  if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
    fputs(main_help, stdout);
    return EXIT_OK;
  }
  if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
    printf("verdant %s\n", VD_VERSION_STRING);
    return EXIT_OK;
  }
  static const struct {
    const char* name;
    int (*run)(int, char**);
  } cmds[] = {{"grow", cli_grow},         {"cloud", cli_cloud}, {"dataset", cli_dataset},
              {"render", cli_render},     {"sim", cli_sim},     {"validate", cli_validate},
              {"harvest", cli_harvest},   {"export", cli_export}};
  for (size_t k = 0; k < sizeof cmds / sizeof *cmds; k++)
    if (!strcmp(cmd, cmds[k].name)) {
      fflush(stdout);
      // the outputs go in place only when the whole command succeeded
      return cli_out_finish(cmd, cmds[k].run(argc - 1, argv + 1));
    }
  fprintf(stderr, "verdant: unknown command '%s'\n", cmd);
  fputs(main_help, stderr);
  return EXIT_USAGE;
}
