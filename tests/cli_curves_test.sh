#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of curves files in `verdant grow`: the bundled tomato, the --curve-* options,
# errors that name the file and field (exit 2, no output). Usage: cli_curves_test.sh VERDANT SRC
source "$(dirname "$0")/cli_lib.sh" cli_curves "$@"
# json_field FILE EXPR: evaluate a Python expression over the JSON in FILE (d)
json_check() {
  python3 -c "import json,sys; d=json.load(open('$1')); sys.exit(0 if ($2) else 1)"
}

C="$SRC/data/curves_tomato.json"
expect "curves stats" 0 "$V" grow "$C" --stats
if json_check "$T/out" "d['labels']['fruit'] == 7 and d['labels']['pedicel'] == 7 and d['spheres'] == 8"; then
  ok "curves stats: fruits and pedicels"
else
  bad "curves stats: fruits and pedicels ($(head -c 300 "$T/out"))"
fi
cp "$T/out" "$T/default.stats"

# outputs: plant JSON that reads back as a plant file, meshes
expect "curves to plant json" 0 "$V" grow "$C" -o "$T/tomato.json"
expect "plant json of curves reads back" 0 "$V" grow "$T/tomato.json" -o "$T/tomato2.json"
if cmp -s "$T/tomato.json" "$T/tomato2.json"; then ok "identical after re-read"; else bad "identical after re-read"; fi
expect "curves to obj" 0 "$V" grow "$C" -o "$T/tomato.obj"
expect "curves to ply" 0 "$V" grow "$C" -o "$T/tomato.ply"

# sigma_distance: longer segments, fewer of them
expect "curve distance" 0 "$V" grow "$C" --curve-distance 0.05 --stats
if python3 -c "import json,sys; a=json.load(open('$T/default.stats')); b=json.load(open('$T/out')); sys.exit(0 if b['segments'] < a['segments'] and b['total_length'] > 0.95 * a['total_length'] else 1)"; then
  ok "larger sigma_distance, fewer segments"
else
  bad "larger sigma_distance, fewer segments"
fi
expect "bad curve distance" 2 "$V" grow "$C" --curve-distance -1 --stats
expect "bad curve step" 2 "$V" grow "$C" --curve-step abc --stats
expect "curve option on an lpy" 2 "$V" grow "$SRC/data/tomato.lpy" --curve-distance 0.05 --stats
expect "set on curves" 2 "$V" grow "$C" --set N=1 --stats
# sigma_connect too small: the first branch that does not reach is named
expect "connect too small" 2 "$V" grow "$C" --curve-connect 0.0001 --stats -o "$T/nc.json"
expect_err "unconnected curve named" "curves_tomato.json: curves\[[0-9]+\] \(.*\): not connected"
if ls "$T"/nc.json* >/dev/null 2>&1; then bad "no output after error"; else ok "no output after error"; fi

# malformed files: exit 2, the file and the field named, nothing written
printf '{"format": "verdant-curves", "version": 1, "curves": [{"points": [[0,0,0],[0,0,1]], "radius": [0.1, -2]}]}' >"$T/neg.json"
expect "negative radius" 2 "$V" grow "$T/neg.json" -o "$T/neg.obj"
expect_err "negative radius named" "neg.json: curves\[0\]\.radius\[1\]"
if ls "$T"/neg.obj* >/dev/null 2>&1; then bad "no mesh after error"; else ok "no mesh after error"; fi
printf '{"format": "verdant-curves",\n "version": 1,\n "curves": [\n' >"$T/trunc.json"
expect "truncated json" 2 "$V" grow "$T/trunc.json" --stats
expect_err "truncated json location" "trunc.json:[0-9]+:[0-9]+: invalid JSON"
printf '{"format": "verdant-curves", "version": 1, "curves": [{"points": [[0,0,0],[0,0,1]]}], "fruits": [{"at": [0,0,1], "raduis": 1}]}' >"$T/typo.json"
expect "unknown key" 2 "$V" grow "$T/typo.json" --stats
expect_err "unknown key named" "fruits\[0\]\.raduis: unknown key"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
