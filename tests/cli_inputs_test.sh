#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of what the commands take in: files of the wrong kind say what they are, a
# UTF-8 byte-order mark is skipped (issue 12, item 9); options that do not apply are refused, a
# repeated -o is an error, --opt=value and -- work, 'verdant help CMD' (item 10).
# Usage: cli_inputs_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_inputs "$@"
TOM="$SRC/data/tomato.lpy"
cd "$T" || exit 1

# --- a file of the wrong kind says what it is (item 9) ---
"$V" grow "$TOM" -o tom.ply >/dev/null 2>&1
"$V" grow "$TOM" -o tom.obj >/dev/null 2>&1
"$V" cloud "$TOM" -N 500 -o c.ply >/dev/null 2>&1
"$V" cloud "$TOM" -N 500 -o c.pcd >/dev/null 2>&1
"$V" cloud "$TOM" -N 500 -o c.las >/dev/null 2>&1
"$V" sim "$TOM" --duration 0.002 -o run >/dev/null 2>&1
printf '{"format": "verdant-image", "version": 1}\n' >side.json
printf '{"format": "something-else"}\n' >other.json
printf '\x89PNG\r\n\x1a\n0000' >img.png
cp tom.ply mesh.lpy  # a mesh under a plant's name: its bytes tell
for f in "tom.ply:a mesh .PLY." "tom.obj:a mesh .OBJ." "c.ply:a point cloud .PLY." "c.pcd:a point cloud .PCD." \
         "c.las:a point cloud .LAS." "img.png:an image" "side.json:an image sidecar" "other.json:another format" \
         "run:a simulation run" "run/rod.json:rod model" "mesh.lpy:a mesh .PLY." "$SRC/data/robots/arm6.xml:MJCF"; do
  file="${f%%:*}" what="${f#*:}"
  expect "grow $file" 2 "$V" grow "$file" --stats
  expect_err "$file says what it is" "$(basename "$file"): .*$what.*not a plant"
done
expect "cloud of a mesh" 2 "$V" cloud tom.ply -o x.ply
expect_err "cloud names the kind" "tom.ply: a mesh"
expect "sim of a cloud" 2 "$V" sim c.las --stats
expect_err "sim names the kind" "c.las: a point cloud"
# a UTF-8 byte-order mark at the start of an .lpy file is skipped
printf '\xef\xbb\xbfAxiom: F(1)\n' >bom.lpy
printf 'Axiom: F(1)\n' >plain.lpy
expect "grow an .lpy with a BOM" 0 "$V" grow bom.lpy -o bom.json
expect "grow it without" 0 "$V" grow plain.lpy -o plain.json
if cmp -s bom.json plain.json; then ok "the BOM changes nothing"; else bad "the BOM changes nothing"; fi
printf '\xef\xbb\xbfAxiom: F(1 +)\n' >bomerr.lpy
printf 'Axiom: F(1 +)\n' >err.lpy
expect "an error after a BOM" 2 "$V" grow bomerr.lpy --stats
sed 's/bomerr.lpy/err.lpy/g' "$T/err" >bom.err
expect "the same error without" 2 "$V" grow err.lpy --stats
if cmp -s bom.err "$T/err" && grep -q "err.lpy:1:[0-9]" bom.err; then ok "same line and column with a BOM"; else bad "same line and column with a BOM ($(cat bom.err))"; fi

# --- options that do not apply are refused (item 10) ---
expect "grow --ascii with .obj" 2 "$V" grow "$TOM" -o x.obj --ascii
expect_err "says where --ascii applies" "ascii applies to a .ply"
expect "grow --ascii with .json" 2 "$V" grow "$TOM" -o x.json --ascii
expect "grow --ascii with .ply" 0 "$V" grow "$TOM" -o x.ply --ascii
expect "cloud --ascii with .las" 2 "$V" cloud "$TOM" -N 100 -o x.las --ascii
expect "cloud --ascii with .xyz" 2 "$V" cloud "$TOM" -N 100 -o x.xyz --ascii
expect "cloud --ascii with .pcd" 0 "$V" cloud "$TOM" -N 100 -o x.pcd --ascii
expect "cloud --ply-scalar-prefix with .pcd" 2 "$V" cloud "$TOM" -N 100 -o x.pcd --ply-scalar-prefix
expect_err "says where the prefix applies" "ply-scalar-prefix applies to PLY"
expect "cloud --ascii without output" 2 "$V" cloud "$TOM" -N 100 --stats --ascii
expect "dataset --ascii with las" 2 "$V" dataset "$TOM" --count 1 -N 100 --format las --ascii -o ds1
expect "sim --frames without -o" 2 "$V" sim "$TOM" --stats --frames jsonl
expect "sim --fps with --frames none" 2 "$V" sim "$TOM" -o r2 --frames none --fps 10
expect "sim --ramp without a pull" 2 "$V" sim "$TOM" --stats --ramp 0.1
expect "sim --ke-tol without --settle" 2 "$V" sim "$TOM" --stats --ke-tol 1e-6
expect "sim --gust without wind" 2 "$V" sim "$TOM" --stats --gust 0.3,1
# --- a repeated -o, --opt=value, --, help (item 10) ---
expect "repeated -o" 2 "$V" grow "$TOM" -o a.json -o b.json
expect_err "repeated -o named" "output given 2 times"
expect "repeated --output=" 2 "$V" grow "$TOM" --output=a.json -o b.json
if [ ! -e a.json ] && [ ! -e b.json ]; then ok "nothing written"; else bad "nothing written"; fi
expect "--opt=value" 0 "$V" grow "$TOM" --seed=3 --set=NODES=6 --output=eq.json
expect "--opt value" 0 "$V" grow "$TOM" --seed 3 --set NODES=6 -o sp.json
if cmp -s eq.json sp.json; then ok "--opt=value is --opt value"; else bad "--opt=value is --opt value"; fi
cp "$TOM" ./-dash.lpy
expect "a file named -dash.lpy after --" 0 "$V" grow --seed 3 --set NODES=6 -o dash.json -- -dash.lpy
expect "the same without --" 2 "$V" grow -dash.lpy --stats
expect "help CMD" 0 "$V" help sim
if grep -q "usage: verdant sim" "$T/out"; then ok "help CMD shows the command's help"; else bad "help CMD shows the command's help"; fi
expect "help lists --version" 0 "$V" --help
if grep -q -- "--version" "$T/out" && grep -q "help <command>" "$T/out"; then ok "--version and help listed"; else bad "--version and help listed"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
