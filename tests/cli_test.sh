#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of the verdant command: exit codes, error locations, no partial output,
# outputs that other tools read. Usage: cli_test.sh VERDANT_BINARY SOURCE_DIR
set -u
V="$1"
SRC="$2"
T=$(mktemp -d /tmp/verdant_cli.XXXXXX)
trap 'rm -rf "$T"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); echo "ok   $1"; }
bad() { fail=$((fail + 1)); echo "FAIL $1"; }

# expect NAME CODE CMD...: run, check the exit code
expect() {
  local name="$1" code="$2"
  shift 2
  "$@" >"$T/out" 2>"$T/err"
  local rc=$?
  if [ "$rc" -eq "$code" ]; then ok "$name"; else bad "$name (exit $rc, expected $code: $(head -c 300 "$T/err"))"; fi
}
# expect_err NAME PATTERN: the last run's stderr matches
expect_err() {
  if grep -Eq "$2" "$T/err"; then ok "$1"; else bad "$1 (stderr: $(head -c 300 "$T/err"))"; fi
}

expect "help" 0 "$V" --help
expect "version" 0 "$V" --version
expect "no command" 2 "$V"
expect "unknown command" 2 "$V" frobnicate
expect "grow help" 0 "$V" grow --help
expect "grow without plant" 2 "$V" grow
expect "grow unknown option" 2 "$V" grow x.lpy --bogus
expect "grow bad steps" 2 "$V" grow x.lpy -n abc --stats
expect "grow bad seed" 2 "$V" grow x.lpy --seed -3 --stats
expect "grow bad set" 2 "$V" grow x.lpy --set NOEQUALS --stats
expect "grow unknown output format" 2 "$V" grow x.lpy -o out.xyz
expect "grow missing file" 2 "$V" grow "$T/missing.lpy" --stats
expect_err "missing file named" "missing.lpy"

# a syntax error: file:line:col and no output file
printf 'Axiom: A\nproduction:\nA --> B(1 +)\n' >"$T/bad.lpy"
expect "syntax error exit 2" 2 "$V" grow "$T/bad.lpy" -o "$T/bad.json"
expect_err "syntax error location" "bad.lpy:3:[0-9]+: "
if ls "$T"/bad.json* >/dev/null 2>&1; then bad "no output after error"; else ok "no output after error"; fi

# unsupported construct names its line
printf 'x = [1, 2]\nAxiom: A\n' >"$T/unsup.lpy"
expect "unsupported exit 2" 2 "$V" grow "$T/unsup.lpy" --stats
expect_err "unsupported message" "unsup.lpy:1:[0-9]+: unsupported"

# limits: a clear error, not an out-of-memory death
printf 'Axiom: A\nproduction:\nA --> AA\n' >"$T/exp.lpy"
expect "max modules" 2 "$V" grow "$T/exp.lpy" -n 40 --max-modules 100000 --stats
expect_err "max modules message" "exceed"

# --set overrides a global; an unknown global is an error
printf 'N = 1\nAxiom: A\nderivation length: N\nproduction:\nA --> AB\nB --> A\n' >"$T/set.lpy"
expect "set global" 0 "$V" grow "$T/set.lpy" --set N=5 --stats
if python3 -c "import json,sys; d=json.load(open('$T/out')); sys.exit(0 if d['modules']==13 else 1)"; then
  ok "set changes derivation"
else
  bad "set changes derivation ($(head -c 200 "$T/out"))"
fi
expect "set unknown global" 2 "$V" grow "$T/set.lpy" --set NOPE=5 --stats

# stats is valid JSON with the documented fields
expect "stats" 0 "$V" grow "$T/set.lpy" --stats
if python3 - "$T/out" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for k in ["modules", "module_counts", "segments", "spheres", "leaves", "labels", "bbox_min", "bbox_max", "total_length"]:
    assert k in d, k
PY
then ok "stats fields"; else bad "stats fields"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
