#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The output-layer lint (scripts/lint.sh --outputs, part of `make lint`): the sources are clean,
# and a file that writes outside the layer is a finding. Usage: lint_outputs_test.sh SOURCE_DIR
set -u
SRC=$1
T=$(mktemp -d /tmp/verdant_lint_outputs.XXXXXX)
trap 'rm -rf "$T"' EXIT
pass=0 fail=0
ok() { pass=$((pass + 1)); echo "ok   $1"; }
bad() { fail=$((fail + 1)); echo "FAIL $1"; }
if bash "$SRC/scripts/lint.sh" --outputs >"$T/out" 2>&1; then ok "src/, cli/ and python/src write only through the layer"; else bad "sources: $(cat "$T/out")"; fi
# every kind of write outside the layer is found; reads, comments and strings are not
cat >"$T/bad.c" <<'C'
#include <stdio.h>
void a(void) { FILE* f = fopen("x", "w"); (void)f; }
void b(void) { FILE* f = fopen("x", "ab"); (void)f; }
int c(void) { return rename("x", "y"); }
int d(void) { return unlink("x"); }
int e(void) { return mkdir("d", 0777); }
int g(void) { return open("x", O_WRONLY | O_CREAT, 0644); }
int h(void) { return remove("x"); }
C
cat >"$T/good.c" <<'C'
#include <stdio.h>
// rename( unlink( in a comment
void a(void) { FILE* f = fopen("x", "rb"); (void)f; puts("mkdir(x) in a string"); }
int b(void) { return open("x", O_RDONLY); }
int c(void) { return vd_outfile_remove("x") + tie_remove(0); }
C
bash "$SRC/scripts/lint.sh" --outputs "$T/bad.c" >"$T/out" 2>&1
n=$(grep -c "outside the output layer" "$T/out")
if [ "$n" -eq 7 ]; then ok "every write outside the layer found (7)"; else bad "writes outside the layer found: $n of 7: $(cat "$T/out")"; fi
if bash "$SRC/scripts/lint.sh" --outputs "$T/good.c" >"$T/out" 2>&1; then ok "reads, comments and strings are not findings"; else bad "false findings: $(cat "$T/out")"; fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
