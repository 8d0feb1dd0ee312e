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

# --- a command's outputs appear together or not at all (issue 12, item 3) ---
# an output that cannot be written (a folder in its place) stops the command before anything:
# exit 2, one rule for every output (docs/reliability.md)
mkdir out.obj
expect "grow .obj onto a folder" 2 "$V" grow tom.json -o out.obj
expect_err "the folder is named" "cannot write 'out.obj' \(-o\): it is a folder"
if [ ! -e out.mtl ]; then ok "no .mtl without its .obj"; else bad "no .mtl without its .obj"; fi
rmdir out.obj && mkdir out.mtl
expect "grow .obj with a folder for its .mtl" 2 "$V" grow tom.json -o out.obj
if [ ! -e out.obj ]; then ok "no .obj without its .mtl"; else bad "no .obj without its .mtl"; fi
rmdir out.mtl
mkdir r.label.png
expect "render with a folder for its mask" 2 "$V" render tom.json -o r.png --masks --depth --size 64x48
if ls r.png r.depth.png r.instance.png r.png.json 2>/dev/null; then bad "no image without its masks"; else ok "no image without its masks"; fi
expect "grow into a missing folder" 2 "$V" grow tom.json -o nowhere/t.obj
# a run that fails half way (unstable) takes back every file it wrote: a new folder goes, an
# earlier run in the folder comes back as it was
A="$SRC/data/arabidopsis.lpy"
UNSTABLE=(--young 1e6 --density 100 --dt 0.02 --duration 1 --wind 5,0,0 --gust 0.5,0.5 --self-collision)
expect "unstable run into a new folder" 1 "$V" sim "$A" -o newrun "${UNSTABLE[@]}"
if [ ! -e newrun ]; then ok "no run folder after a failed run"; else bad "no run folder after a failed run ($(ls newrun))"; fi
expect "a run" 0 "$V" sim "$A" -o oldrun --duration 0.01 --final oldrun.obj
md5sum oldrun/* oldrun.obj oldrun.mtl >before.md5
expect "unstable run over it" 1 "$V" sim "$A" -o oldrun --final oldrun.obj "${UNSTABLE[@]}"
if md5sum -c --quiet before.md5 && [ "$(ls oldrun | wc -l)" -eq 6 ]; then ok "the earlier run kept"; else bad "the earlier run kept"; fi
# a run with other frames removes the earlier run's frames with the rest of its files
expect "a run with JSON Lines frames" 0 "$V" sim "$A" -o oldrun --duration 0.01 --frames jsonl
if [ -s oldrun/frames.jsonl ] && [ ! -e oldrun/frames.bin ]; then ok "no stale frames.bin"; else bad "no stale frames.bin"; fi
if ls oldrun/*.bak.* oldrun/*.tmp.* 2>/dev/null; then bad "nothing kept aside"; else ok "nothing kept aside"; fi
# a full disk half way through a run's files: the earlier run comes back (hard links take no room)
if mkdir full && mount -t tmpfs -o size=1m tmpfs full 2>/dev/null; then
  trap 'umount "$T/full" 2>/dev/null; rm -rf "$T"' EXIT
  expect "a small run on a small disk" 0 "$V" sim "$A" -o full/run --duration 0.01
  md5sum full/run/* >full.md5
  expect "a run too large for the disk" 1 "$V" sim "$A" -o full/run --duration 2 --fps 1000
  if md5sum -c --quiet full.md5 && [ "$(ls full/run | wc -l)" -eq 6 ]; then ok "disk full: earlier run kept"; else bad "disk full: earlier run kept"; fi
  expect "a dataset too large for the disk" 1 "$V" dataset "$A" --count 20 -N 50000 -o full/ds
  if ls full/ds/*.tmp.* full/ds/*.bak.* 2>/dev/null; then bad "disk full: no partial item"; else ok "disk full: no partial item"; fi
  for r in full/ds/item_*.json; do
    [ -e "$r" ] || continue
    c="${r%.json}.ply"
    if [ -s "$c" ]; then ok "item $(basename "$r") whole"; else bad "item $(basename "$r") whole"; fi
  done
  for c in full/ds/item_*.ply; do
    [ -e "$c" ] || continue
    if [ -e "${c%.ply}.json" ]; then ok "cloud $(basename "$c") has its record"; else bad "cloud $(basename "$c") has its record"; fi
  done
  umount full
else
  echo "skip full-disk cases (mounting a tmpfs is not permitted here)"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
