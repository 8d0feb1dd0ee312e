#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# make demo: grow the bundled tomato and write its plant file, labelled meshes and stats to out/.
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
for p in arabidopsis tree lilac; do
  echo "== growing data/$p.lpy"
  "$V" grow "data/$p.lpy" --seed 1 -o "out/$p.obj" --stats > "out/$p-stats.json"
done
echo "== rendering pictures (headless: EGL, software rendering without a GPU)"
"$V" render data/tomato.lpy --seed 1 -o out/tomato.png --masks --depth
"$V" render data/tomato.lpy --seed 1 -o out/tomato-instance.png --color-by instance --camera orbit:-30:25
"$V" render data/tomato.lpy --seed 1 -o out/tomato-arm.png --robot data/robots/arm6.xml --camera orbit:-60:20
# a labelled cloud: until `verdant cloud` lands, the mesh's vertices with the label and instance
# of their faces stand in for a sampled cloud
"$V" grow data/tomato.lpy --seed 1 -o out/tomato-mesh.ply --ascii
python3 - out/tomato-mesh.ply out/tomato-points.ply <<'PY'
import sys
lines = open(sys.argv[1]).read().split("\n")
end = lines.index("end_header")
nv = int(next(l.split()[2] for l in lines if l.startswith("element vertex")))
nf = int(next(l.split()[2] for l in lines if l.startswith("element face")))
verts = [l.split()[:3] for l in lines[end + 1:end + 1 + nv]]
lab = [None] * nv
for l in lines[end + 1 + nv:end + 1 + nv + nf]:
    w = l.split()
    k = int(w[0])
    for v in w[1:1 + k]:
        lab[int(v)] = (w[1 + k], w[2 + k])
pts = [(v, l) for v, l in zip(verts, lab) if l]
with open(sys.argv[2], "w") as f:
    f.write("ply\nformat ascii 1.0\n")
    f.write("".join(l + "\n" for l in lines[:end] if l.startswith("comment label ")))
    f.write("element vertex %d\nproperty float x\nproperty float y\n" % len(pts))
    f.write("property float z\nproperty int label\nproperty int instance\nend_header\n")
    for v, l in pts:
        f.write(" ".join(v) + " %s %s\n" % l)
PY
"$V" render out/tomato-points.ply -o out/tomato-cloud.png --camera orbit:-30:25 --point-size 0.004
echo "   out/tomato.png (+ .label.png, .instance.png, .depth.png, .json), tomato-instance.png,"
echo "   tomato-arm.png, tomato-cloud.png"
echo "== results in out/: tomato.obj (+ .mtl, one group and material per label), tomato.ply,"
echo "   tomato.json (plant file), *-stats.json, pictures; open the OBJ in any mesh viewer"
