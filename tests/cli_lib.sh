#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Shared helpers of the end-to-end CLI tests. A test script starts with
#   source "$(dirname "$0")/cli_lib.sh" NAME "$@"     # NAME names its scratch folder
# and ends by printing "$pass passed, $fail failed". It gets V (the verdant binary), SRC (the
# source tree), T (a scratch folder removed on exit), and:
#   ok NAME / bad NAME        count a passed / failed check
#   expect NAME CODE CMD...   run CMD (stdout to $T/out, stderr to $T/err), check its exit code
#   expect_err NAME PATTERN   the last run's stderr matches the extended regular expression
set -u
V="$2"
SRC="$3"
T=$(mktemp -d "/tmp/verdant_$1.XXXXXX")
trap 'rm -rf "$T"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); echo "ok   $1"; }
bad() { fail=$((fail + 1)); echo "FAIL $1"; }
expect() {
  local name="$1" code="$2"
  shift 2
  "$@" >"$T/out" 2>"$T/err"
  local rc=$?
  if [ "$rc" -eq "$code" ]; then ok "$name"; else bad "$name (exit $rc, expected $code: $(head -c 300 "$T/err"))"; fi
}
expect_err() {
  if grep -Eq -e "$2" "$T/err"; then ok "$1"; else bad "$1 (stderr: $(head -c 300 "$T/err"))"; fi
}
# have_pty WHAT: util-linux's script can give a run a pseudo-terminal here (a container may have
# no script or no /dev/ptmx to open); else prints "skip WHAT (why)" and fails
have_pty() {
  if ! command -v script >/dev/null 2>&1; then
    echo "skip $1 (no script command: util-linux)"
    return 1
  fi
  if ! script -qc true /dev/null >/dev/null 2>&1; then
    echo "skip $1 (no pseudo-terminal can be opened here: $(script -qc true /dev/null 2>&1 | head -c 200))"
    return 1
  fi
}
