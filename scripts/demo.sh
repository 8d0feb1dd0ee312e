#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# make demo: grow the bundled tomato and write its plant file, labelled meshes, labelled point
# clouds and stats to out/, then a robot harvest of one of its fruits.
set -euo pipefail
V="${1:-./build/verdant}"
mkdir -p out
echo "== growing data/tomato.lpy (seed 1)"
"$V" grow data/tomato.lpy --seed 1 -o out/tomato.obj --stats > out/tomato-stats.json
"$V" grow data/tomato.lpy --seed 1 -o out/tomato.ply
"$V" grow data/tomato.lpy --seed 1 -o out/tomato.json
python3 - out/tomato-stats.json <<'PY' || cat out/tomato-stats.json
import json, sys
d = json.load(open(sys.argv[1]))
print(f"   {d['modules']} modules, {d['segments']} segments, {d['spheres']} spheres, {d['leaves']} leaves")
print("   organs by label: " + ", ".join(f"{k} {v}" for k, v in d["labels"].items()))
lo, hi = d["bbox_min"], d["bbox_max"]
print(f"   size {hi[0]-lo[0]:.2f} x {hi[1]-lo[1]:.2f} x {hi[2]-lo[2]:.2f} m, {d['total_length']:.2f} m of segments in all")
PY
echo "== a labelled point cloud of the tomato (200k points, interior points removed)"
"$V" cloud data/tomato.lpy --seed 1 --points 200000 -o out/tomato-cloud.ply --stats --profile > out/tomato-cloud-stats.json
"$V" cloud data/tomato.lpy --seed 1 --sensor scan --scanners data/scanners/turntable8.json --noise 0.001 \
  -o out/tomato-scan.ply
python3 - out/tomato-cloud-stats.json <<'PY' || cat out/tomato-cloud-stats.json
import json, sys
d = json.load(open(sys.argv[1]))
print(f"   {d['points']} points, {d['instances']} organs: " + ", ".join(f"{k} {v}" for k, v in d["labels"].items()))
print(f"   {d['rejected']['interior']} candidates inside other organs replaced; {d['points_per_second']['total']:.0f} points/s in all")
PY
for p in arabidopsis tree lilac; do
  echo "== growing data/$p.lpy"
  "$V" grow "data/$p.lpy" --seed 1 -o "out/$p.obj" --stats > "out/$p-stats.json"
done
echo "== rendering pictures (headless: EGL, software rendering without a GPU)"
"$V" render data/tomato.lpy --seed 1 -o out/tomato.png --masks --depth
"$V" render data/tomato.lpy --seed 1 -o out/tomato-instance.png --color-by instance --camera orbit:-30:25
"$V" render data/tomato.lpy --seed 1 -o out/tomato-arm.png --robot data/robots/arm6.xml --camera orbit:-60:20
# the labelled cloud written above (200k sampled points)
"$V" render out/tomato-cloud.ply -o out/tomato-cloud.png --camera orbit:-30:25 --point-size 0.004
echo "   out/tomato.png (+ .label.png, .instance.png, .depth.png, .png.json), tomato-instance.png,"
echo "   tomato-arm.png, tomato-cloud.png"
echo "== physics: the tomato settles under gravity, then (sag-free) a probe pushes through it"
"$V" sim data/tomato.lpy --seed 1 --settle --no-progress --stats > out/tomato-settle.json
"$V" sim data/tomato.lpy --seed 1 --sag-free --duration 1.5 --no-progress \
  --probe 0.04:0.4,0,0.8:-0.4,0,0.8 -o out/tomato-run --final out/tomato-pushed.obj --stats --profile > out/tomato-probe.json
python3 - out/tomato-settle.json out/tomato-probe.json <<'PY' || cat out/tomato-settle.json out/tomato-probe.json
import json, sys
s, p = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
print(f"   settling: {s['segments']} rod segments, {s['total_mass']:.3f} kg, still after {s['time']:.2f} s; "
      f"sagged {100 * s['max_displacement']:.1f} cm at most, stem tip {100 * s['tip_displacement']:.1f} cm")
print(f"   probe: pushed the plant up to {100 * p['max_displacement']:.1f} cm, {p['nevents']} fractures, "
      f"penetration {p['max_penetration']:.1e} m, {p['steps_per_second']:.0f} steps/s")
PY
echo "== pictures of the run: the push at t = 1 s, coloured by displacement (docs/img/tomato-probe.png)"
"$V" render out/tomato-run -o out/tomato-probe.png --time 1.0 --camera front --color-by displacement
if command -v ffmpeg >/dev/null 2>&1; then
  "$V" render out/tomato-run --mp4 out/tomato-probe.mp4 --camera front --color-by displacement --no-progress
  echo "   out/tomato-probe.png, out/tomato-probe.mp4 (every frame)"
else
  echo "   out/tomato-probe.png (install Debian's ffmpeg for a video: verdant render out/tomato-run --mp4 x.mp4)"
fi
echo "== harvest: the Lite 6 grasps the nearest reachable cherry tomato and pulls it off"
"$V" harvest data/scenes/tomato_pull.json -o out/harvest --stats --profile --no-progress > out/harvest-summary.json
python3 - out/harvest-summary.json <<'PY' || cat out/harvest-summary.json
import json, sys
d = json.load(open(sys.argv[1]))
print(f"   fruit {d['target_instance']}: grasped {d['grasped']}, detached {d['detached']} at t = {d['detach_time']:.2f} s, "
      f"site {d['site']}, pedicel force {d['pedicel_force']:.2f} N (published 0.58-2.46 N at the calyx, 5-8 N at the "
      f"abscission node), gripper force sensor {d['pull_force']:.2f} N, {d['real_time_factor']:.2f}x real time")
PY
# the frame of the grasp (the first grasp event), close up
tg=$(awk -F, '$2 == "grasp" {print $1; exit}' out/harvest/events.csv)
"$V" render out/harvest -o out/harvest-grasp.png --time "${tg:-4.5}" --eye 0.45,-0.5,0.75 --lookat 0.27,0,0.5 --fov 40
echo "   out/harvest/ (summary.json, events.csv, trajectory.csv, frames), out/harvest-grasp.png (t = ${tg:-4.5} s)"
echo "== results in out/: tomato.obj (+ .mtl, one group and material per label), tomato.ply,"
echo "   tomato.json (plant file), *-stats.json, pictures; open the OBJ in any mesh viewer;"
echo "   tomato-cloud.ply (labelled points: label, instance), tomato-scan.ply (8 scans, view and"
echo "   range per point): open them in CloudCompare, Open3D or MeshLab;"
echo "   tomato-run/ (frames, events, final plant) and tomato-pushed.obj from the simulation,"
echo "   tomato-probe.png (a frame of it); harvest/ and harvest-grasp.png from the robot harvest"
