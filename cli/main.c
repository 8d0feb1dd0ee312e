// SPDX-License-Identifier: MIT
#include <stdio.h>
#include "verdant/core.h"
int main(void) { printf("verdant %s\n", VD_VERSION_STRING); return 0; }
