#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of what every command writes: no output replaces an input; a command's
# outputs appear together or not at all. Usage: cli_outputs_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_outputs "$@"
TOM="$SRC/data/tomato.lpy"
cd "$T" || exit 1

# --- no output may replace an input (issue 12, item 1) ---
expect "grow a plant file" 0 "$V" grow "$TOM" -o tom.json
cp tom.json tom.keep
# the image sidecar is named after the whole image name: it never takes the plant file's name
if "$V" render tom.json -o tom.png --masks --size 64x48 >/dev/null 2>&1; then
  if cmp -s tom.json tom.keep && [ -s tom.png.json ]; then ok "render keeps its input plant"; else bad "render keeps its input plant"; fi
  expect "the plant still grows" 0 "$V" grow tom.json --stats
  expect "render with depth keeps a plant file of the image's name" 0 "$V" render "$TOM" -o tom.png --depth --size 64x48
  if cmp -s tom.json tom.keep; then ok "sidecar beside a plant file"; else bad "sidecar beside a plant file"; fi
else
  echo "skip render checks (no OpenGL context)"
fi
# an output that is the input: by name, by another spelling, by a link
expect "grow onto its input" 2 "$V" grow tom.json -o tom.json
expect_err "clash named" "would replace the input"
expect "grow onto its input, another spelling" 2 "$V" grow tom.json -o ./tom.json
ln -s tom.json link.json
expect "grow onto a link to its input" 2 "$V" grow tom.json -o link.json
if cmp -s tom.json tom.keep && [ -L link.json ]; then ok "input untouched"; else bad "input untouched"; fi
# render: the masks and the sidecar of the image are outputs (a robot file in their way)
cp "$SRC/data/robots/arm6.xml" t.label.png
expect "render onto its robot" 2 "$V" render tom.json -o t.png --masks --size 64x48 --robot t.label.png
if cmp -s t.label.png "$SRC/data/robots/arm6.xml"; then ok "robot untouched"; else bad "robot untouched"; fi
# sim: the run folder's files and --final
expect "sim a run" 0 "$V" sim tom.json --duration 0.002 -o run
expect "sim onto its own run" 2 "$V" sim run/plant.json --duration 0.002 -o run/
expect_err "sim clash named" "run/plant.json"
expect "sim --final onto its input" 2 "$V" sim tom.json --duration 0.002 --final tom.json
printf 't,vx,vy,vz\n0,1,0,0\n' >run/events.csv
expect "sim onto its wind file" 2 "$V" sim tom.json --duration 0.002 --wind-file run/events.csv -o run
if cmp -s tom.json tom.keep && [ -s run/plant.json ]; then ok "sim inputs untouched"; else bad "sim inputs untouched"; fi
# cloud: the scanner preset is an input
cp "$SRC/data/scanners/turntable8.json" scan.xyz
expect "cloud onto its preset" 2 "$V" cloud tom.json --sensor scan --scanners scan.xyz -o scan.xyz
if cmp -s scan.xyz "$SRC/data/scanners/turntable8.json"; then ok "preset untouched"; else bad "preset untouched"; fi
# dataset: an input inside the folder under a name the dataset writes
mkdir ds && cp tom.json ds/item_000000.json
expect "dataset over its input" 2 "$V" dataset ds/item_000000.json --count 1 -N 100 -o ds
if cmp -s ds/item_000000.json tom.keep; then ok "dataset input untouched"; else bad "dataset input untouched"; fi
cp tom.json ds/plant.json
expect "dataset beside its input" 0 "$V" dataset ds/plant.json --count 1 -N 100 -o ds

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
