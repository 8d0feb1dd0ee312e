// SPDX-License-Identifier: MIT
// verdant dataset (placeholder until the next commit).
#include "cli.h"
int cli_dataset(int argc, char** argv) { (void)argc; (void)argv; return EXIT_USAGE; }
