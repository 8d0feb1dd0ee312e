#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Bad input for every command (docs/reliability.md, "Bad input"): each row of the tables runs
# here. Malformed files, wrong types, out-of-range and non-finite numbers in options and files,
# missing, empty, binary and huge files, absurd counts: exit 2 with the file (line, column or
# field) and what was expected, never a crash, a hang or partial output. Then outputs that
# cannot be written (read-only folder, full disk: exit 1, nothing left behind), interrupts
# (SIGINT/SIGTERM during a dataset: only complete items, a rerun resumes), and determinism of
# the command's outputs across runs, threads and jobs.
# Usage: cli_hardening_test.sh VERDANT_BINARY SOURCE_DIR
set -u
V="$1"
SRC="$2"
T=$(mktemp -d /tmp/verdant_cli_hardening.XXXXXX)
MOUNTS=()
cleanup() {
  for m in "${MOUNTS[@]}"; do umount "$m" 2>/dev/null; done
  rm -rf "$T"
}
trap cleanup EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); echo "ok   $1"; }
bad() { fail=$((fail + 1)); echo "FAIL $1"; }
D="$SRC/data"

# run NAME CODE CMD...: the exit code, within VD_TEST_TIMEOUT s (default 60; the sanitizer build
# sets 600) (a hang is a failure); a crash (signal) is always a failure
TMO=${VD_TEST_TIMEOUT:-60}
expect() {
  local name="$1" code="$2"
  shift 2
  timeout "$TMO" "$@" >"$T/out" 2>"$T/err"
  local rc=$?
  # VD_TABLE=FILE: each case also becomes a row of the bad-input table (docs/reliability.md)
  if [ -n "${VD_TABLE:-}" ]; then
    local msg
    msg=$(head -n 1 "$T/err" | sed -e "s#$T/##g" -e "s#$SRC/##g" -e 's/|/\\|/g' | cut -c 1-220)
    printf '| %s | %s | %s | %s |\n' "${name%%:*}" "${name#*: }" "$rc" "${msg:-(nothing on stderr)}" >>"$VD_TABLE"
  fi
  if [ "$rc" -eq 124 ]; then bad "$name (hang: killed after $TMO s)"; return; fi
  if [ "$rc" -gt 128 ]; then bad "$name (crash: signal $((rc - 128)): $(head -c 300 "$T/err"))"; return; fi
  if [ "$rc" -eq "$code" ]; then ok "$name"; else bad "$name (exit $rc, expected $code: $(head -c 300 "$T/err"))"; fi
}
# the last run's stderr matches an extended regular expression
expect_err() {
  if grep -Eq -e "$2" "$T/err"; then ok "$1"; else bad "$1 (stderr: $(head -c 300 "$T/err"))"; fi
}
# nothing at PATH, not even a temporary file beside it
no_output() {
  if ls "$2" "$2".tmp.* >/dev/null 2>&1; then bad "$1 (found $(ls -d "$2"* | head -3))"; else ok "$1"; fi
}
# the last run's stdout is JSON satisfying a Python expression on d
json_check() {
  if python3 -c "import json,sys; d=json.load(open('$T/out')); sys.exit(0 if ($2) else 1)" 2>/dev/null; then
    ok "$1"
  else
    bad "$1 ($(head -c 300 "$T/out"))"
  fi
}

# ---------------------------------------------------------------------------------------------
# inputs shared by the commands

printf 'Axiom: A\nproduction:\nA --> B(1 +)\n' >"$T/syntax.lpy"
: >"$T/empty.lpy"
: >"$T/empty.json"
head -c 3000 /dev/urandom >"$T/binary.lpy"
printf 'Axiom: F(1e300)\n' >"$T/far.lpy"               # a node 1e300 m away: float32 outputs would hold inf
printf 'Axiom: SetWidth(1e300) F(1)\n' >"$T/wide.lpy"  # a radius of 1e300 m
printf 'Axiom: F(1e308*10)\n' >"$T/inf.lpy"             # a parameter that overflows to inf
printf 'Axiom: F(0.1)\nproduction:\nF(x) --> F(x) [ +(30) F(x) ] F(x)\n' >"$T/grows.lpy"
truncate -s 1100M "$T/huge.lpy"                        # sparse: above the 1 GiB file limit
printf 'x = [1, 2]\nAxiom: A\n' >"$T/unsupported.lpy"
mkdir "$T/folder.lpy"
"$V" grow "$D/arabidopsis.lpy" -o "$T/plant.json" >/dev/null 2>&1
sed 's/"version": 1/"version": "one"/' "$T/plant.json" >"$T/type.json"
sed 's/"nodes": \[0,0,0,/"nodes": [0,0,1e999,/' "$T/plant.json" >"$T/inf.json"
sed 's/"nodes": \[0,0,0,/"nodes": [0,0,NaN,/' "$T/plant.json" >"$T/nan.json"
sed 's/"nodes": \[0,0,0,/"nodes": [0,0,"x",/' "$T/plant.json" >"$T/str.json"
sed 's/{"id": 1,/{"id": -5,/' "$T/plant.json" >"$T/label.json"
head -c 2000 "$T/plant.json" >"$T/cut.json"

# ---------------------------------------------------------------------------------------------
# grow

expect "grow: syntax error" 2 "$V" grow "$T/syntax.lpy" -o "$T/g.json"
expect_err "grow: syntax error names file:line:col" "syntax.lpy:3:[0-9]+: "
no_output "grow: no output after a syntax error" "$T/g.json"
expect "grow: unsupported construct" 2 "$V" grow "$T/unsupported.lpy" --engine native --stats
expect_err "grow: unsupported names file:line:col" "unsupported.lpy:1:[0-9]+: unsupported"
expect "grow: missing file" 2 "$V" grow "$T/missing.lpy" --stats
expect_err "grow: missing file named" "missing.lpy: cannot open"
expect "grow: a folder" 2 "$V" grow "$T/folder.lpy" --stats
expect "grow: empty .lpy" 2 "$V" grow "$T/empty.lpy" --stats
expect_err "grow: empty .lpy says what is expected" "empty.lpy:1:1: .*Axiom"
expect "grow: empty plant JSON" 2 "$V" grow "$T/empty.json" --stats
expect "grow: binary file" 2 "$V" grow "$T/binary.lpy" --stats
expect "grow: huge file refused from its size" 2 "$V" grow "$T/huge.lpy" --stats
expect_err "grow: huge file message" "huge.lpy: file of [0-9]+ bytes, larger than the limit"
expect "grow: plant JSON wrong type" 2 "$V" grow "$T/type.json" --stats
expect_err "grow: wrong type names the field" "type.json: version: expected a number"
expect "grow: plant JSON string for a number" 2 "$V" grow "$T/str.json" --stats
expect_err "grow: string names the element" "str.json: nodes\[2\]: expected a number"
expect "grow: plant JSON 1e999" 2 "$V" grow "$T/inf.json" --stats
expect_err "grow: 1e999 is not finite" "inf.json: nodes\[2\]: number is not finite"
expect "grow: plant JSON NaN" 2 "$V" grow "$T/nan.json" --stats
expect_err "grow: NaN names line:col" "nan.json:[0-9]+:[0-9]+: invalid JSON"
expect "grow: plant JSON negative label id" 2 "$V" grow "$T/label.json" --stats
expect "grow: plant JSON cut short" 2 "$V" grow "$T/cut.json" --stats
expect_err "grow: cut short names line:col" "cut.json:[0-9]+:[0-9]+: "
expect "grow: parameter overflowing to inf" 2 "$V" grow "$T/inf.lpy" -o "$T/g.ply"
expect_err "grow: inf parameter named" "parameter 1 is not finite"
expect "grow: node beyond 1e9 m" 2 "$V" grow "$T/far.lpy" -o "$T/g.ply"
expect_err "grow: far node names the file" "far.lpy: node 1: position is not finite or beyond"
no_output "grow: no mesh with inf" "$T/g.ply"
expect "grow: radius beyond 1e9 m" 2 "$V" grow "$T/wide.lpy" -o "$T/g.ply"
expect "grow: -n negative" 2 "$V" grow "$D/tomato.lpy" -n -1 --stats
expect "grow: -n beyond 1e9" 2 "$V" grow "$D/tomato.lpy" -n 99999999999 --stats
expect "grow: -n not a number" 2 "$V" grow "$D/tomato.lpy" -n 1e3 --stats
expect "grow: --seed beyond 2^63" 2 "$V" grow "$D/tomato.lpy" --seed 99999999999999999999 --stats
expect "grow: --max-modules 0" 2 "$V" grow "$D/tomato.lpy" --max-modules 0 --stats
expect "grow: --set without =" 2 "$V" grow "$D/tomato.lpy" --set NODES --stats
expect "grow: --set unknown global" 2 "$V" grow "$D/tomato.lpy" --set NOPE=1 --stats
expect "grow: --label id out of range" 2 "$V" grow "$D/tomato.lpy" --label 70000=x --stats
# absurd counts: a clear limit, not hours of work or an out-of-memory death
expect "grow: 1e9 steps stop at the work limit" 2 "$V" grow "$T/grows.lpy" -n 1000000000 --max-ops 20000000 --stats
expect_err "grow: work limit message" "grows.lpy: .*interpreter operations"
expect "grow: exponential growth stops at --max-modules" 2 "$V" grow "$T/grows.lpy" -n 60 --stats
expect_err "grow: module limit message" "exceed"

# ---------------------------------------------------------------------------------------------
# cloud

P="$D/arabidopsis.lpy"
expect "cloud: -N 0" 2 "$V" cloud "$P" -N 0 -o "$T/c.ply"
expect "cloud: -N not a number" 2 "$V" cloud "$P" -N many -o "$T/c.ply"
expect "cloud: -N beyond 2e9" 2 "$V" cloud "$P" -N 9999999999 -o "$T/c.ply"
expect "cloud: 2e9 points over --max-points" 2 "$V" cloud "$P" -N 2000000000 -o "$T/c.ply"
expect_err "cloud: point limit before allocating" "2000000000 points is more than the limit of 50000000"
no_output "cloud: no output over the limit" "$T/c.ply"
expect "cloud: 1e10 scan rays" 2 "$V" cloud "$P" --sensor scan --scanner 1,0,0.2 --res 100000,100000 -o "$T/c.ply"
expect "cloud: 1e8 scan rays over --max-points" 2 "$V" cloud "$P" --sensor scan --scanner 1,0,0.2 --res 10000,10000 -o "$T/c.ply"
expect_err "cloud: ray limit message" "rays is more than the limit"
expect "cloud: --max-points 0" 2 "$V" cloud "$P" --max-points 0 -o "$T/c.ply"
expect "cloud: --noise nan" 2 "$V" cloud "$P" --noise nan -o "$T/c.ply"
expect "cloud: --noise inf" 2 "$V" cloud "$P" --noise inf -o "$T/c.ply"
expect "cloud: --noise negative" 2 "$V" cloud "$P" --noise -0.1 -o "$T/c.ply"
expect "cloud: --scanner two numbers" 2 "$V" cloud "$P" --scanner 1,2 -o "$T/c.ply"
expect "cloud: --scanner inf" 2 "$V" cloud "$P" --scanner inf,0,0 -o "$T/c.ply"
expect "cloud: --fov 0" 2 "$V" cloud "$P" --sensor scan --scanner 1,0,0 --fov 0,0 -o "$T/c.ply"
expect "cloud: --res 0" 2 "$V" cloud "$P" --sensor scan --scanner 1,0,0 --res 0,5 -o "$T/c.ply"
expect "cloud: --density-law table nan" 2 "$V" cloud "$P" --sensor distance --scanner 1,0,0 --density-law table:1:nan,2:1 -o "$T/c.ply"
expect "cloud: --threads 0" 2 "$V" cloud "$P" --threads 0 -o "$T/c.ply"
expect "cloud: unknown output format" 2 "$V" cloud "$P" -o "$T/c.vtk"
expect "cloud: missing plant" 2 "$V" cloud "$T/missing.lpy" -o "$T/c.ply"
expect "cloud: binary plant" 2 "$V" cloud "$T/binary.lpy" -o "$T/c.ply"
expect "cloud: plant beyond 1e9 m" 2 "$V" cloud "$T/far.lpy" -o "$T/c.ply"
no_output "cloud: no output after bad plants" "$T/c.ply"
printf '{"format": "verdant-scanners", "version": 1, "scanners": [{"position": [1, 0, 0.2]' >"$T/cut_scanners.json"
expect "cloud: scanner preset cut short" 2 "$V" cloud "$P" --sensor scan --scanners "$T/cut_scanners.json" -o "$T/c.ply"
expect_err "cloud: preset names line:col" "cut_scanners.json:1:[0-9]+: "
printf '{"format": "verdant-scanners", "version": 1, "scanners": [{"position": [1, "a", 0.2]}]}' >"$T/type_scanners.json"
expect "cloud: scanner preset wrong type" 2 "$V" cloud "$P" --sensor scan --scanners "$T/type_scanners.json" -o "$T/c.ply"
expect_err "cloud: preset names the field" "type_scanners.json: .*position"
printf '{"format": "verdant-scanners", "version": 1, "scanners": [{"position": [1, 0, 1e999]}]}' >"$T/inf_scanners.json"
expect "cloud: scanner preset 1e999" 2 "$V" cloud "$P" --sensor scan --scanners "$T/inf_scanners.json" -o "$T/c.ply"
printf '{"format": "verdant-scanners", "version": 1, "scanners": [{"position": [1, 0, 0.2], "resolution": [100000, 100000]}]}' >"$T/big_scanners.json"
expect "cloud: scanner preset with 1e10 rays" 2 "$V" cloud "$P" --sensor scan --scanners "$T/big_scanners.json" -o "$T/c.ply"
expect "cloud: scanner preset missing" 2 "$V" cloud "$P" --sensor scan --scanners "$T/missing.json" -o "$T/c.ply"
expect "cloud: scanner preset empty" 2 "$V" cloud "$P" --sensor scan --scanners "$T/empty.json" -o "$T/c.ply"
no_output "cloud: no output after bad presets" "$T/c.ply"

# ---------------------------------------------------------------------------------------------
# dataset

expect "dataset: --count 0" 2 "$V" dataset "$P" --count 0 -o "$T/ds"
expect "dataset: --count beyond 1e8" 2 "$V" dataset "$P" --count 1000000000 -o "$T/ds"
expect "dataset: --count not a number" 2 "$V" dataset "$P" --count 1e3 -o "$T/ds"
expect "dataset: --jobs 0" 2 "$V" dataset "$P" --count 2 --jobs 0 -o "$T/ds"
expect "dataset: --shard 3/2" 2 "$V" dataset "$P" --count 2 --shard 3/2 -o "$T/ds"
# integers beyond int were undefined behaviour in sscanf("%d") (found by clang-tidy cert-err34-c)
expect "dataset: --shard overflowing int" 2 "$V" dataset "$P" --count 2 --shard 1/99999999999 -o "$T/ds"
expect "dataset: --image-size overflowing int" 2 "$V" dataset "$P" --count 2 --image-size 4294967396x64 -o "$T/ds"
expect "dataset: --vary B < A" 2 "$V" dataset "$P" --count 2 --vary DAYS=2:1 -o "$T/ds"
expect "dataset: --vary nan" 2 "$V" dataset "$P" --count 2 --vary DAYS=nan:1 -o "$T/ds"
expect "dataset: missing -o" 2 "$V" dataset "$P" --count 2
expect "dataset: 2e9 points per item" 2 "$V" dataset "$P" --count 2 -N 2000000000 -o "$T/ds"
expect "dataset: missing plant" 2 "$V" dataset "$T/missing.lpy" --count 2 -o "$T/ds"
expect_err "dataset: missing plant named" "item 0: .*missing.lpy"
"$V" dataset "$P" --count 2 -N 500 -o "$T/ds_mix" >/dev/null 2>&1
expect "dataset: a folder made with other options" 2 "$V" dataset "$P" --count 2 -N 600 -o "$T/ds_mix"
expect_err "dataset: other options named" "made with other options"

# ---------------------------------------------------------------------------------------------
# render (bad input is found before any OpenGL context is made)

expect "render: missing plant" 2 "$V" render "$T/missing.lpy" -o "$T/r.png"
expect "render: binary plant" 2 "$V" render "$T/binary.lpy" -o "$T/r.png"
expect "render: plant beyond 1e9 m" 2 "$V" render "$T/far.lpy" -o "$T/r.png"
"$V" cloud "$P" -N 300 --ascii -o "$T/c_ok.ply" >/dev/null 2>&1
python3 - "$T" <<'PY'
import sys
t = sys.argv[1]
s = open(t + "/c_ok.ply").read()
head, body = s.split("end_header\n", 1)
rows = body.split("\n")
rows[3] = "nan " + " ".join(rows[3].split()[1:])
open(t + "/c_nan.ply", "w").write(head + "end_header\n" + "\n".join(rows))
open(t + "/c_count.ply", "w").write(head.replace("element vertex 300", "element vertex 999999999") + "end_header\n" + body)
open(t + "/c_type.ply", "w").write(head.replace("property int label", "property text label") + "end_header\n" + body)
PY
expect "render: cloud with a NaN coordinate" 2 "$V" render "$T/c_nan.ply" -o "$T/r.png"
expect_err "render: NaN names file:line" "c_nan.ply:[0-9]+: column 'x': value out of range"
expect "render: cloud with an absurd count" 2 "$V" render "$T/c_count.ply" -o "$T/r.png"
expect_err "render: count checked against the file" "999999999 points do not fit in the file"
expect "render: cloud with an unknown type" 2 "$V" render "$T/c_type.ply" -o "$T/r.png"
: >"$T/empty.ply"
expect "render: empty cloud file" 2 "$V" render "$T/empty.ply" -o "$T/r.png"
head -c 3000 /dev/urandom >"$T/binary.pcd"
expect "render: binary garbage as PCD" 2 "$V" render "$T/binary.pcd" -o "$T/r.png"
expect "render: --size 0x0" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --size 0x0
expect "render: --size 100000x2" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --size 100000x2
expect "render: --size overflowing int" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --size 4294967396x64
expect "render: --fov nan" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --fov nan
expect "render: --eye inf" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --eye inf,0,0 --lookat 0,0,0
expect "render: --point-size inf" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --point-size inf
expect "render: --supersample 9" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --supersample 9
expect "render: robot MJCF missing" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --robot "$T/missing.xml"
echo '<mujoco><worldbody>' >"$T/cut.xml"
expect "render: robot MJCF cut short" 2 "$V" render "$T/c_ok.ply" -o "$T/r.png" --robot "$T/cut.xml"
expect_err "render: MJCF error names the file" "cut.xml:[0-9]+: robot MJCF: XML parse error"
no_output "render: no image after bad input" "$T/r.png"

# ---------------------------------------------------------------------------------------------
# sim

S="$D/arabidopsis.lpy"
expect "sim: --dt 0" 2 "$V" sim "$S" --stats --dt 0
expect "sim: --dt nan" 2 "$V" sim "$S" --stats --dt nan
expect "sim: --dt inf" 2 "$V" sim "$S" --stats --dt inf
expect "sim: --young 0" 2 "$V" sim "$S" --stats --young 0
expect "sim: --young inf" 2 "$V" sim "$S" --stats --young inf
expect "sim: --young nan" 2 "$V" sim "$S" --stats --young nan
expect "sim: --density negative" 2 "$V" sim "$S" --stats --density -1
expect "sim: --poisson 0.7" 2 "$V" sim "$S" --stats --poisson 0.7
expect "sim: --iterations 0" 2 "$V" sim "$S" --stats --iterations 0
expect "sim: --iterations 1.5" 2 "$V" sim "$S" --stats --iterations 1.5
expect "sim: --wind nan" 2 "$V" sim "$S" --stats --wind nan,0,0
expect "sim: --wind 1e9 m/s" 2 "$V" sim "$S" --stats --wind 1e9,0,0
expect "sim: --gravity inf" 2 "$V" sim "$S" --stats --gravity 0,0,inf
expect "sim: --probe nan radius" 2 "$V" sim "$S" --stats --probe nan:0,0,0:1,1,1
expect "sim: --pull unknown organ" 2 "$V" sim "$S" --stats --pull trunk=0,0,1
expect_err "sim: unknown organ named" "no organ 'trunk'"
expect "sim: --fps 0" 2 "$V" sim "$S" --stats --fps 0
expect "sim: --duration inf" 2 "$V" sim "$S" --stats --duration inf
expect "sim: --duration 1e9 s is 1e12 steps" 2 "$V" sim "$S" --stats --duration 1e9
expect_err "sim: step limit message" "more than --max-steps"
expect "sim: --segment-length 1e-9 m" 2 "$V" sim "$S" --stats --segment-length 1e-9
expect_err "sim: segment limit before building" "rod segments, more than the limit of 1000000"
expect "sim: --max-segments 10" 2 "$V" sim "$S" --stats --max-segments 10
expect "sim: --max-segments 0" 2 "$V" sim "$S" --stats --max-segments 0
expect "sim: plant beyond 1e9 m" 2 "$V" sim "$T/far.lpy" --stats
printf 't,vx,vy,vz\n0,1,0,0\n0.5,2,0\n' >"$T/w_short.csv"
expect "sim: wind row too short" 2 "$V" sim "$S" --stats --wind-file "$T/w_short.csv"
expect_err "sim: wind row names file:line:col" "w_short.csv:3:8: expected ','"
printf '0,1,0,0\n0.5,nan,0,0\n' >"$T/w_nan.csv"
expect "sim: wind NaN" 2 "$V" sim "$S" --stats --wind-file "$T/w_nan.csv"
expect_err "sim: wind NaN names file:line:col" "w_nan.csv:2:5: expected a wind velocity component"
printf '0,1,0,0\n0.5,1e300,0,0\n' >"$T/w_big.csv"
expect "sim: wind 1e300 m/s" 2 "$V" sim "$S" --stats --wind-file "$T/w_big.csv"
printf '0,1,0,0\n2,1,0,0\n1,1,0,0\n' >"$T/w_back.csv"
expect "sim: wind time backwards" 2 "$V" sim "$S" --stats --wind-file "$T/w_back.csv"
expect_err "sim: backwards names the line" "w_back.csv:3:1: time 1 goes backwards"
expect "sim: wind file empty" 2 "$V" sim "$S" --stats --wind-file "$T/empty.json"
expect "sim: wind file binary" 2 "$V" sim "$S" --stats --wind-file "$T/binary.lpy"
expect "sim: wind file missing" 2 "$V" sim "$S" --stats --wind-file "$T/missing.csv"
expect "sim: wind file huge" 2 "$V" sim "$S" --stats --wind-file "$T/huge.lpy"
expect "sim: bad input leaves no run folder files" 2 "$V" sim "$S" -o "$T/run_bad" --young nan
no_output "sim: no frames after bad input" "$T/run_bad/frames.bin"
# numerical trouble: retaken steps are counted and reported; a run that cannot be made
# stable stops with exit 1 and leaves no outputs
expect "sim: soft light plant at dt 1e-2 s runs" 0 "$V" sim "$S" --stats --young 1e6 --density 100 --dt 0.01 --duration 0.2 --wind 5,0,0 --gust 0.5,0.5
expect_err "sim: numerical warnings reported" "^verdant sim: warning: .*(retaken in halves|stretched beyond)"
json_check "sim: warnings counted by kind in --stats" "d['warnings'] > 0 and d['warnings'] == sum(d['warning_counts'].values()) and d['warning_counts']['nonfinite'] == 0"
# (self-collision on: the plant's own contacts hold its folded soft parts until no substep helps)
expect "sim: soft light plant at dt 2e-2 s fails cleanly" 1 "$V" sim "$S" -o "$T/run_unstable" --young 1e6 --density 100 --dt 0.02 --duration 1 --wind 5,0,0 --gust 0.5,0.5 --self-collision
expect_err "sim: unstable message" "became unstable at t = .*try a smaller --dt"
no_output "sim: no frames after an unstable run" "$T/run_unstable/frames.bin"
no_output "sim: no events after an unstable run" "$T/run_unstable/events.csv"

# ---------------------------------------------------------------------------------------------
# validate

expect "validate: unknown option" 2 "$V" validate --frobnicate
expect "validate: --case matching nothing" 2 "$V" validate --case no_such_case --no-progress
expect_err "validate: no case message" "matches no validation case"
expect "validate: --plant missing" 2 "$V" validate --case cantilever_tip --plant "$T/missing.lpy" --no-progress
expect "validate: --plant with a syntax error" 2 "$V" validate --case cantilever_tip --plant "$T/syntax.lpy" --no-progress
expect_err "validate: --plant error names file:line:col" "syntax.lpy:3:[0-9]+: "

# ---------------------------------------------------------------------------------------------
# outputs that cannot be written: exit 2 (found before the run, one rule for every output:
# docs/reliability.md), a clear error, nothing left behind; a write that fails during the run
# (a full disk) is exit 1

if mkdir -p "$T/ro" "$T/full" && mount -t tmpfs -o ro,size=1m tmpfs "$T/ro" 2>/dev/null; then
  MOUNTS+=("$T/ro")
  expect "read-only: grow" 2 "$V" grow "$P" -o "$T/ro/p.json"
  expect_err "read-only: grow says why" "cannot write '.*ro/p.json' \\(-o\\):.*Read-only file system"
  expect "read-only: cloud" 2 "$V" cloud "$P" -N 100 -o "$T/ro/c.ply"
  expect "read-only: dataset" 2 "$V" dataset "$P" --count 2 -N 100 -o "$T/ro/ds"
  expect_err "read-only: dataset says why" "cannot write '.*ro/ds' \\(-o\\):.*Read-only file system"
  expect "read-only: sim" 2 "$V" sim "$S" --duration 0.01 -o "$T/ro/run"
  expect "read-only: sim --final" 2 "$V" sim "$S" --duration 0.01 --final "$T/ro/final.ply"
else
  echo "skip read-only folder cases (mounting a tmpfs is not permitted here)"
fi
if mount -t tmpfs -o size=1m tmpfs "$T/full" 2>/dev/null; then
  MOUNTS+=("$T/full")
  expect "disk full: cloud" 1 "$V" cloud "$D/tomato.lpy" -N 200000 -o "$T/full/c.ply"
  expect_err "disk full: cloud says why" "full/c.ply: write failed: No space left on device"
  no_output "disk full: no partial cloud" "$T/full/c.ply"
  expect "disk full: grow mesh" 1 "$V" grow "$D/tree.lpy" -o "$T/full/tree.obj"
  no_output "disk full: no partial mesh" "$T/full/tree.obj"
  expect "disk full: dataset" 1 "$V" dataset "$D/tomato.lpy" --count 20 -N 50000 -o "$T/full/ds"
  if ls "$T/full/ds"/*.tmp.* >/dev/null 2>&1; then bad "disk full: dataset leaves no temporary file"; else ok "disk full: dataset leaves no temporary file"; fi
  expect "disk full: sim frames" 1 "$V" sim "$S" --duration 2 --fps 1000 -o "$T/full/run"
  no_output "disk full: no partial frames" "$T/full/run/frames.bin"
  if [ -x "$(command -v df)" ]; then
    used=$(df --output=used "$T/full" | tail -1)
    ok "disk full: after the runs $used KiB hold only complete files"
  fi
else
  echo "skip full-disk cases (mounting a tmpfs is not permitted here)"
fi

# ---------------------------------------------------------------------------------------------
# interrupts: SIGINT or SIGTERM during a dataset leaves only complete items; a rerun resumes

for sig in INT TERM; do
  rm -rf "$T/dsi"
  # the signal comes once the first item is complete (its record written), whatever the load
  "$V" dataset "$P" --count 40 -N 400000 --jobs 2 --no-progress -o "$T/dsi" >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 600); do
    ls "$T/dsi"/item_*.json >/dev/null 2>&1 && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.05
  done
  kill -s $sig $pid 2>/dev/null
  wait $pid
  rc=$?
  # ended by the signal: 128 + its number, as timeout(1) would report 124
  [ $rc -gt 128 ] && rc=124
  if [ $rc -eq 124 ]; then ok "interrupt $sig: the dataset was interrupted"; else ok "interrupt $sig: finished before the signal (exit $rc)"; fi
  if ls "$T/dsi"/*.tmp.* >/dev/null 2>&1; then bad "interrupt $sig: no temporary files left"; else ok "interrupt $sig: no temporary files left"; fi
  if [ -f "$T/dsi/manifest.json" ] && [ $rc -eq 124 ]; then bad "interrupt $sig: no manifest for an incomplete dataset"; else ok "interrupt $sig: no manifest for an incomplete dataset"; fi
  expect "interrupt $sig: the rerun resumes" 0 "$V" dataset "$P" --count 40 -N 400000 --jobs 2 --no-progress --stats -o "$T/dsi"
  json_check "interrupt $sig: the rerun skips the complete items" "d['made'] + d['skipped'] == 40 and (d['skipped'] > 0) == ($rc == 124) and d['manifest']"
done
"$V" dataset "$P" --count 40 -N 400000 --jobs 2 --no-progress -o "$T/dsr" >/dev/null 2>&1
if cmp -s "$T/dsi/manifest.json" "$T/dsr/manifest.json"; then ok "interrupt: the resumed dataset is identical to one made at once"; else bad "interrupt: resumed dataset differs"; fi
# a run killed outright (SIGKILL) leaves temporary files: the next run removes them
sh -c 'exit 0' &
dead=$!
wait $dead
: >"$T/dsr/item_000003.ply.tmp.$dead"
: >"$T/dsr/manifest.json.tmp.$dead"
expect "stale temporary files: rerun" 0 "$V" dataset "$P" --count 40 -N 400000 --no-progress -o "$T/dsr"
if ls "$T/dsr"/*.tmp.* >/dev/null 2>&1; then bad "stale temporary files of a dead run removed"; else ok "stale temporary files of a dead run removed"; fi
# SIGINT during a simulation: the frames being written are removed
timeout -s INT 1 "$V" sim "$D/tomato.lpy" --duration 100 --no-progress -o "$T/run_int" >/dev/null 2>&1
if ls "$T/run_int"/frames.bin* >/dev/null 2>&1; then bad "interrupt sim: no partial frames"; else ok "interrupt sim: no partial frames"; fi

# ---------------------------------------------------------------------------------------------
# determinism of the outputs: the same seed gives the same bytes across runs, threads and jobs

"$V" grow "$D/tomato.lpy" --seed 5 -o "$T/g1.json" 2>/dev/null
"$V" grow "$D/tomato.lpy" --seed 5 -o "$T/g2.json" 2>/dev/null
if cmp -s "$T/g1.json" "$T/g2.json"; then ok "determinism: grown plant across runs"; else bad "determinism: grown plant across runs"; fi
OMP_NUM_THREADS=1 "$V" cloud "$D/tomato.lpy" --seed 5 -N 30000 --noise 0.001 -o "$T/c1.ply" 2>/dev/null
OMP_NUM_THREADS=2 "$V" cloud "$D/tomato.lpy" --seed 5 -N 30000 --noise 0.001 -o "$T/c2.ply" 2>/dev/null
"$V" cloud "$D/tomato.lpy" --seed 5 -N 30000 --noise 0.001 --threads 2 -o "$T/c3.ply" 2>/dev/null
if cmp -s "$T/c1.ply" "$T/c2.ply" && cmp -s "$T/c1.ply" "$T/c3.ply"; then ok "determinism: cloud on 1 and 2 threads"; else bad "determinism: cloud on 1 and 2 threads"; fi
OMP_NUM_THREADS=1 "$V" cloud "$D/tomato.lpy" --seed 5 --sensor scan --scanner 1.5,-1,0.8 --occlusion -o "$T/s1.ply" 2>/dev/null
OMP_NUM_THREADS=2 "$V" cloud "$D/tomato.lpy" --seed 5 --sensor scan --scanner 1.5,-1,0.8 --occlusion -o "$T/s2.ply" 2>/dev/null
if cmp -s "$T/s1.ply" "$T/s2.ply"; then ok "determinism: scan on 1 and 2 threads"; else bad "determinism: scan on 1 and 2 threads"; fi
"$V" sim "$D/tomato.lpy" --duration 0.1 --wind 3,0,0 -o "$T/sim1" 2>/dev/null
OMP_NUM_THREADS=1 "$V" sim "$D/tomato.lpy" --duration 0.1 --wind 3,0,0 -o "$T/sim2" 2>/dev/null
if cmp -s "$T/sim1/frames.bin" "$T/sim2/frames.bin" && cmp -s "$T/sim1/plant.json" "$T/sim2/plant.json"; then
  ok "determinism: simulation frames across runs"
else
  bad "determinism: simulation frames across runs"
fi
"$V" dataset "$P" --count 6 -N 2000 --vary PHYLLO=120:150 --jobs 1 --no-progress -o "$T/dj1" >/dev/null 2>&1
OMP_NUM_THREADS=2 "$V" dataset "$P" --count 6 -N 2000 --vary PHYLLO=120:150 --jobs 2 --no-progress -o "$T/dj2" >/dev/null 2>&1
if cmp -s "$T/dj1/manifest.json" "$T/dj2/manifest.json"; then ok "determinism: dataset with 1 and 2 jobs"; else bad "determinism: dataset with 1 and 2 jobs"; fi
# an item's recorded seed and --vary value make it again, byte for byte (the seeds are exact)
python3 - "$T/dj1/manifest.json" >"$T/item" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
it = max(d["items"], key=lambda i: i["seed"])
print(it["seed"], repr(it["vary"]["PHYLLO"]), it["index"])
PY
read -r seed phyllo idx <"$T/item"
"$V" cloud "$P" -N 2000 --seed "$seed" --set "PHYLLO=$phyllo" -o "$T/again.ply" 2>/dev/null
if cmp -s "$T/again.ply" "$(printf '%s/dj1/item_%06d.ply' "$T" "$idx")"; then
  ok "determinism: an item made again from its record"
else
  bad "determinism: an item made again from its record (seed $seed, PHYLLO $phyllo)"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
