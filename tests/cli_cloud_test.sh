#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of `verdant cloud` and `verdant dataset`: exit codes, formats other tools
# read (PCL's converters and Open3D when installed), determinism across thread counts, dataset
# manifests, checksums, shards, resuming and regenerating one item alone.
# Usage: cli_cloud_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cloud_cli "$@"
check() {  # check NAME CMD...: the command succeeds
  local name="$1"
  shift
  if "$@" >"$T/chk" 2>&1; then ok "$name"; else bad "$name ($(head -c 300 "$T/chk"))"; fi
}
A="$SRC/data/arabidopsis.lpy"
TOM="$SRC/data/tomato.lpy"

# usage and input faults: exit 2, nothing written
expect "cloud help" 0 "$V" cloud --help
expect "dataset help" 0 "$V" dataset --help
expect "cloud without plant" 2 "$V" cloud -o "$T/x.ply"
expect "cloud unknown option" 2 "$V" cloud "$A" --bogus -o "$T/x.ply"
expect "cloud bad points" 2 "$V" cloud "$A" -N 0 -o "$T/x.ply"
expect "cloud bad sensor" 2 "$V" cloud "$A" --sensor lidar -o "$T/x.ply"
expect "cloud bad scanner" 2 "$V" cloud "$A" --scanner 1,2 -o "$T/x.ply"
expect "cloud distance without scanner" 2 "$V" cloud "$A" --sensor distance -o "$T/x.ply"
expect "cloud law without distance" 2 "$V" cloud "$A" --density-law linear -o "$T/x.ply"
expect "cloud bad table" 2 "$V" cloud "$A" --sensor distance --scanner 1,0,0 --density-law table:1:2 -o "$T/x.ply"
expect "cloud negative noise" 2 "$V" cloud "$A" --noise -1 -o "$T/x.ply"
expect "cloud occlusion without scanner" 2 "$V" cloud "$A" --occlusion -o "$T/x.ply"
expect "cloud unknown format" 2 "$V" cloud "$A" -o "$T/x.obj"
expect "cloud missing preset" 2 "$V" cloud "$A" --scanners "$T/none.json" -o "$T/x.ply"
expect_err() { if grep -Eq "$2" "$T/err"; then ok "$1"; else bad "$1 (stderr: $(head -c 300 "$T/err"))"; fi; }
expect_err "missing preset named" "none.json"
printf 'Axiom: A\nproduction:\nA --> B(1 +)\n' >"$T/bad.lpy"
expect "cloud syntax error" 2 "$V" cloud "$T/bad.lpy" -o "$T/bad.ply"
expect_err "syntax error location" "bad.lpy:3:[0-9]+: "
if ls "$T"/bad.ply* >/dev/null 2>&1; then bad "no output after error"; else ok "no output after error"; fi
expect "cloud unwritable output" 2 "$V" cloud "$A" -N 100 -o /nonexistent-dir/x.ply

# a cloud, its stats, every format
expect "cloud stats" 0 "$V" cloud "$A" -N 5000 --seed 3 -o "$T/a.ply" --stats --profile
if python3 - "$T/out" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["points"] == 5000, d["points"]
assert sum(d["labels"].values()) == 5000
for k in ["instances", "bbox_min", "bbox_max", "area", "rejected", "seconds", "points_per_second"]:
    assert k in d, k
for k in ["load", "tessellate", "build", "sample", "write", "total"]:
    assert k in d["seconds"], k
PY
then ok "stats fields"; else bad "stats fields"; fi
if head -c 2000 "$T/a.ply" | grep -aq '^element vertex 5000$' && head -c 2000 "$T/a.ply" | grep -aq '^property int label$' &&
  head -c 2000 "$T/a.ply" | grep -aq '^comment label 2 leaf$'; then ok "ply header"; else bad "ply header"; fi
for f in b.pcd c.xyz d.csv e.las; do expect "write $f" 0 "$V" cloud "$A" -N 5000 --seed 3 -o "$T/$f"; done
expect "write ascii ply" 0 "$V" cloud "$A" -N 5000 --seed 3 --ascii -o "$T/f.ply"
expect "scalar prefix" 0 "$V" cloud "$A" -N 500 --ply-scalar-prefix -o "$T/g.ply"
if head -c 2000 "$T/g.ply" | grep -aq '^property int scalar_label$'; then ok "scalar_label property"; else bad "scalar_label property"; fi
if python3 - "$T" <<'PY'
import struct, sys
t = sys.argv[1]
b = open(t + "/e.las", "rb").read()
assert b[:4] == b"LASF" and b[24:26] == bytes([1, 4]) and b[104] == 6
off = struct.unpack_from("<I", b, 96)[0]
rl = struct.unpack_from("<H", b, 105)[0]
n = struct.unpack_from("<Q", b, 247)[0]
assert n == 5000 and len(b) == off + n * rl, (n, len(b), off, rl)
classes = {b[off + i * rl + 16] for i in range(n)}
assert classes <= {65, 66, 67, 68}, classes  # user classes 64 + label (docs/formats.md)
lines = open(t + "/d.csv").read().splitlines()
hdr = [l for l in lines if not l.startswith("#")][0]
assert hdr.startswith("x,y,z,nx,ny,nz,label,instance"), hdr
assert len([l for l in lines if not l.startswith("#")]) == 5001
PY
then ok "las and csv layouts"; else bad "las and csv layouts"; fi
# LAS (issue 12, item 18): label, instance and view as extra bytes, verdant's label table VLR
if python3 - "$T/e.las" <<'PY'
import struct, sys
b = open(sys.argv[1], "rb").read()
hs, off, nv = struct.unpack_from("<HII", b, 94)
pos, names, table = hs, [], None
for _ in range(nv):
    user = b[pos + 2:pos + 18].rstrip(b"\0")
    rec, ln = struct.unpack_from("<HH", b, pos + 18)
    body = b[pos + 54:pos + 54 + ln]
    if user == b"LASF_Spec" and rec == 4:
        names = [body[k + 4:k + 36].rstrip(b"\0").decode() for k in range(0, ln, 192)]
    if user == b"verdant" and rec == 1:
        table = {struct.unpack_from("<i", body, k)[0]: (body[k + 4], body[k + 8:k + 56].rstrip(b"\0").decode())
                 for k in range(0, ln, 56)}
    pos += 54 + ln
assert names[:3] == ["label", "instance", "view"], names
assert table == {1: (65, "internode"), 2: (66, "leaf"), 3: (67, "flower"), 4: (68, "silique")}, table
PY
then ok "las extra bytes and label table"; else bad "las extra bytes and label table"; fi
# XYZ and CSV that numpy's genfromtxt(names=True) names and Open3D's XYZ reader reads; scanner
# poses in the headers and PCD's VIEWPOINT (issue 12, item 19)
"$V" cloud "$TOM" --sensor distance --scanner 1.5,0.5,0.8 -N 3000 --seed 2 -o "$T/v1.pcd" &&
  "$V" cloud "$TOM" --sensor distance --scanner 1.5,0.5,0.8 --scanner -1,1,1 -N 3000 --seed 2 -o "$T/v2.xyz" &&
  "$V" cloud "$TOM" --sensor distance --scanner 1.5,0.5,0.8 --scanner -1,1,1 -N 3000 --seed 2 -o "$T/v2.csv" &&
  "$V" cloud "$TOM" --sensor distance --scanner 1.5,0.5,0.8 --scanner -1,1,1 -N 3000 --seed 2 -o "$T/v2.ply"
if python3 - "$T" <<'PY'
import math, sys
t = sys.argv[1]
head = open(t + "/v1.pcd", "rb").read(3000).decode("latin-1").splitlines()
vp = [float(x) for x in next(l for l in head if l.startswith("VIEWPOINT ")).split()[1:]]
pose = next(l for l in head if l.startswith("# view 0 position")).split()
target = [float(x) for x in pose[8:11]]
assert vp[:3] == [1.5, 0.5, 0.8], vp
w, x, y, z = vp[3:]
assert abs(w * w + x * x + y * y + z * z - 1) < 1e-6
# the frame's z axis (third column of the rotation) points at the target
zc = [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)]
d = [target[k] - vp[k] for k in range(3)]
dl = math.sqrt(sum(v * v for v in d))
assert all(abs(zc[k] - d[k] / dl) < 1e-6 for k in range(3)), (zc, d)
# its x axis is horizontal (camera right, world up +z)
assert abs(2 * (x * z - w * y)) < 1e-6
for f in ["v2.xyz", "v2.csv"]:
    lines = open(t + "/" + f).read().splitlines()
    assert sum(l.startswith("# view ") for l in lines) == 2, f
    assert any(l.startswith("# view 1 position -1 1 1 target") for l in lines), f
# PLY: the per-view table in the header comments
ply = open(t + "/v2.ply", "rb").read(4000).split(b"end_header")[0].decode().splitlines()
views = [l.split() for l in ply if l.startswith("comment view ")]
assert [v[2] for v in views] == ["0", "1"] and views[0][4:7] == ["1.5", "0.5", "0.8"], views
PY
then ok "scanner poses: PCD viewpoint, view lines"; else bad "scanner poses: PCD viewpoint, view lines"; fi
NPY=""
for p in python3 /usr/bin/python3; do
  if "$p" -c "import numpy" >/dev/null 2>&1; then NPY="$p"; break; fi
done
if [ -n "$NPY" ]; then
  if "$NPY" - "$T" <<'PY'
import sys, numpy as np
t = sys.argv[1]
x = np.genfromtxt(t + "/v2.xyz", names=True)
c = np.genfromtxt(t + "/v2.csv", delimiter=",", names=True)
for a in (x, c):
    assert a.dtype.names == ("x", "y", "z", "nx", "ny", "nz", "label", "instance", "view", "range"), a.dtype.names
    assert len(a) == 3000 and not np.isnan(a["x"]).any() and set(np.unique(a["view"])) == {0, 1}
assert np.allclose(x["x"], c["x"]) and (x["label"] == c["label"]).all()
PY
  then ok "numpy genfromtxt(names=True) reads XYZ and CSV"; else bad "numpy genfromtxt(names=True) reads XYZ and CSV"; fi
else
  echo "skip numpy check (numpy not installed)"
fi
O3D=""
for p in python3 /usr/bin/python3; do
  if "$p" -c "import open3d" >/dev/null 2>&1; then O3D="$p"; break; fi
done
if [ -n "$O3D" ]; then
  if "$O3D" - "$T" <<'PY'
import sys, numpy as np, open3d as o3d
t = sys.argv[1]
pc = o3d.io.read_point_cloud(t + "/v2.xyz", format="xyz")
ref = np.genfromtxt(t + "/v2.xyz", names=True)
p = np.asarray(pc.points)
assert p.shape == (3000, 3), p.shape
assert np.allclose(p[:, 0], ref["x"]) and np.allclose(p[:, 2], ref["z"])
PY
  then ok "open3d reads XYZ"; else bad "open3d reads XYZ"; fi
else
  echo "skip Open3D XYZ check (python3-open3d not installed)"
fi
# PDAL reads the file (optional: Debian 12 has no pdal package; skipped without it)
if command -v pdal >/dev/null 2>&1; then
  if pdal info --summary "$T/e.las" >"$T/pdal.json" 2>"$T/pdal.err" && python3 - "$T/pdal.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["summary"]
assert s["num_points"] == 5000, s
dims = s["dimensions"]
dims = dims if isinstance(dims, list) else [d.strip() for d in dims.split(",")]
for d in ["Classification", "label", "instance", "view"]:
    assert d in dims, (d, dims)
PY
  then ok "pdal info reads our LAS"; else bad "pdal info reads our LAS ($(head -c 300 "$T/pdal.err"))"; fi
else
  echo "skip pdal check (pdal not installed)"
fi

# determinism: the same bytes with 1 and 2 threads, and run to run
"$V" cloud "$A" -N 20000 --seed 9 --threads 1 -o "$T/t1.ply" && "$V" cloud "$A" -N 20000 --seed 9 --threads 2 -o "$T/t2.ply"
if cmp -s "$T/t1.ply" "$T/t2.ply"; then ok "same bytes with 1 and 2 threads"; else bad "same bytes with 1 and 2 threads"; fi
"$V" cloud "$TOM" --sensor distance --scanner 1.5,0,0.8 --scanner -1,1,1 --occlusion --noise 0.0005,0.001 -N 8000 --threads 1 -o "$T/s1.las"
"$V" cloud "$TOM" --sensor distance --scanner 1.5,0,0.8 --scanner -1,1,1 --occlusion --noise 0.0005,0.001 -N 8000 --threads 2 -o "$T/s2.las"
if cmp -s "$T/s1.las" "$T/s2.las"; then ok "sensor run: same bytes with 1 and 2 threads"; else bad "sensor run: same bytes with 1 and 2 threads"; fi

# scanner presets and scans
expect "turntable scan" 0 "$V" cloud "$TOM" --sensor scan --scanners "$SRC/data/scanners/turntable8.json" --noise 0.001 -o "$T/scan.pcd" --stats
if python3 -c "import json,sys; d=json.load(open('$T/out')); sys.exit(0 if d['views']==8 and d['points']>1000 else 1)"; then ok "turntable: 8 views"; else bad "turntable: 8 views"; fi
expect "depth camera scan" 0 "$V" cloud "$A" --sensor scan --scanners "$SRC/data/scanners/topdown_depth.json" -o "$T/depth.ply"
expect "instance labels" 0 "$V" cloud "$TOM" -N 3000 --labels instance -o "$T/inst.ply"
if head -c 20000 "$T/inst.ply" | grep -aEq '^comment label [0-9]+ fruit_[0-9]+$'; then ok "instance label table"; else bad "instance label table"; fi

# other tools: PCL's converters, Open3D (optional: only when installed)
if command -v pcl_ply2pcd >/dev/null 2>&1; then
  check "pcl_ply2pcd reads our PLY" pcl_ply2pcd "$T/a.ply" "$T/pcl.pcd"
  if grep -aq '^FIELDS x y z normal_x normal_y normal_z label instance' "$T/pcl.pcd"; then ok "pcl keeps label and instance"; else bad "pcl keeps label and instance"; fi
  check "pcl_pcd2ply reads our PCD" pcl_pcd2ply "$T/b.pcd" "$T/pcl.ply"
  if head -c 2000 "$T/pcl.ply" | grep -aq 'property uint label'; then ok "pcl PCD label field"; else bad "pcl PCD label field"; fi
  check "pcl_pcd2ply reads our scan PCD" pcl_pcd2ply "$T/scan.pcd" "$T/pcl2.ply"
else
  echo "skip PCL checks (pcl-tools not installed)"
fi
PY3=""
for p in python3 /usr/bin/python3; do
  if "$p" -c "import open3d" >/dev/null 2>&1; then PY3="$p"; break; fi
done
if [ -n "$PY3" ]; then
  # the issue's acceptance run: 1M labelled points that Open3D reads with label and instance
  expect "1M points" 0 "$V" cloud "$A" --points 1000000 -o "$T/big.ply"
  if "$PY3" - "$T" <<'PY'
import sys, numpy as np, open3d as o3d
t = sys.argv[1]
pc = o3d.t.io.read_point_cloud(t + "/big.ply")
assert pc.point.positions.shape[0] == 1000000
lab = pc.point["label"].numpy().ravel()
inst = pc.point["instance"].numpy().ravel()
assert set(np.unique(lab)) <= {1, 2, 3, 4} and inst.min() >= 1
for f in ["a.ply", "f.ply", "b.pcd"]:
    p = o3d.t.io.read_point_cloud(t + "/" + f)
    assert p.point.positions.shape[0] == 5000, f
    assert "label" in p.point and "instance" in p.point, f
legacy = o3d.io.read_point_cloud(t + "/a.ply")
assert len(legacy.points) == 5000 and legacy.has_normals()
PY
  then ok "open3d reads label and instance"; else bad "open3d reads label and instance"; fi
  if command -v pcl_ply2pcd >/dev/null 2>&1; then
    check "pcl reads the 1M cloud" pcl_ply2pcd "$T/big.ply" "$T/big.pcd"
    if grep -aq '^POINTS 1000000$' "$T/big.pcd"; then ok "pcl: 1M points"; else bad "pcl: 1M points"; fi
  fi
else
  echo "skip Open3D checks (python3-open3d not installed)"
fi

# datasets: items, manifest, checksums, resuming, shards, one item made again alone
D="$T/ds"
expect "dataset" 0 "$V" dataset "$A" --count 5 -N 2000 --seed 4 --jobs 2 --vary ROSETTE_LEAF=0.025:0.045 -o "$D" --stats
if python3 - "$D" <<'PY'
import hashlib, json, os, sys
d = sys.argv[1]
m = json.load(open(d + "/manifest.json"))
assert m["format"] == "verdant-dataset" and m["count"] == 5 and len(m["items"]) == 5
assert [l["name"] for l in m["labels"]] == ["internode", "leaf", "flower", "silique"]
seeds = set()
for it in m["items"]:
    b = open(os.path.join(d, it["file"]), "rb").read()
    assert hashlib.sha256(b).hexdigest() == it["sha256"] and len(b) == it["bytes"]
    assert it["points"] == 2000 and sum(it["label_points"].values()) == 2000
    assert 0.025 <= it["vary"]["ROSETTE_LEAF"] <= 0.045
    seeds.add(it["seed"])
assert len(seeds) == 5
PY
then ok "manifest, checksums, seeds"; else bad "manifest, checksums, seeds"; fi
expect "dataset resume" 0 "$V" dataset "$A" --count 5 -N 2000 --seed 4 --vary ROSETTE_LEAF=0.025:0.045 -o "$D" --stats
if grep -q '"skipped":.5' "$T/out"; then ok "complete items skipped"; else bad "complete items skipped ($(cat "$T/out"))"; fi
# an interrupted item: its record is gone, a temporary file lies around
rm "$D/item_000002.json"
: >"$D/item_000002.ply.tmp"
expect "dataset resume after interruption" 0 "$V" dataset "$A" --count 5 -N 2000 --seed 4 --vary ROSETTE_LEAF=0.025:0.045 -o "$D" --stats
if grep -q '"made":.1' "$T/out" && [ -f "$D/item_000002.json" ]; then ok "interrupted item remade"; else bad "interrupted item remade"; fi
expect "dataset other options refused" 2 "$V" dataset "$A" --count 5 -N 3000 --seed 4 -o "$D"
# item 3 alone with verdant cloud
read -r S VAL < <(python3 -c "import json; r=json.load(open('$D/item_000003.json')); print(r['seed'], repr(r['vary']['ROSETTE_LEAF']))")
"$V" cloud "$A" -N 2000 --seed "$S" --set "ROSETTE_LEAF=$VAL" -o "$T/regen.ply"
if cmp -s "$T/regen.ply" "$D/item_000003.ply"; then ok "item made again alone"; else bad "item made again alone"; fi
# the manifest's recipe, followed for every item, makes the same bytes (issue 12, item 4): a
# dataset with every kind of option (plant, cloud, dataset-only ones, images when a context is
# there); {seed}, {vary.NAME}, {azimuth}, {elevation} come from the item's record
R="$T/recipe"
IMG=()
if "$V" render "$A" -o "$T/ctx.png" --size 16x16 >/dev/null 2>&1; then IMG=(--images 1 --image-size 80x60); fi
expect "dataset for the recipe" 0 "$V" dataset "$A" --count 3 -N 1500 --seed 7 -n 6 --vary ROSETTE_LEAF=0.025:0.045 --labels instance --noise 0.001 --format pcd --jobs 2 --threads 1 "${IMG[@]}" -o "$R"
if python3 - "$V" "$R" "$T" <<'PY'
import filecmp, json, subprocess, sys
v, d, t = sys.argv[1:4]
m = json.load(open(d + "/manifest.json"))
def fill(argv, fields, out):
    a = [v] + argv[1:-1] + [out]
    for key, val in fields.items():
        a = [x.replace("{" + key + "}", val) for x in a]
    assert not any("{" in x for x in a), a
    return a
for item in m["items"]:
    rec = json.load(open(f"{d}/item_{item['index']:06d}.json"))  # exact numbers, as the manifest's
    fields = {"seed": str(item["seed"])}
    for name in item["vary"]:
        fields["vary." + name] = "%.17g" % rec["vary"][name]
    out = f"{t}/regen_{item['index']}.pcd"
    subprocess.run(fill(m["regenerate_argv"], fields, out), check=True)
    assert filecmp.cmp(out, f"{d}/{item['file']}", shallow=False), item["file"]
    for view in item.get("images", []):
        f = dict(fields, azimuth=repr(view["azimuth"]), elevation=repr(view["elevation"]))
        out = f"{t}/regen_{item['index']}_view.png"
        subprocess.run(fill(m["images"]["regenerate_argv"], f, out), check=True)
        for role, ext in (("color", "png"), ("label", "label.png"), ("depth", "depth.png")):
            assert filecmp.cmp(out[:-3] + ext, f"{d}/{view[role]}", shallow=False), view[role]
# the one-line form names the same arguments
assert m["regenerate"].split() == m["regenerate_argv"], m["regenerate"]
PY
then ok "manifest recipe makes every item again"; else bad "manifest recipe makes every item again"; fi
expect "dataset --cloud-seed refused" 2 "$V" dataset "$A" --count 3 --cloud-seed 3 -o "$T/cs"

# --vary (issue 12, item 5): integer bounds draw integers (the tomato's NODES is a derivation
# length, randint bounds elsewhere); an unknown name is reported as --vary; a failed dataset
# leaves no empty folder
expect "dataset --vary of an integer global" 0 "$V" dataset "$TOM" --count 4 -N 200 --vary NODES=8:24 --vary INTERNODE=0.04:0.06 -o "$T/vi"
if python3 - "$T/vi" <<'PY'
import json, sys
items = json.load(open(sys.argv[1] + "/manifest.json"))["items"]
n = [i["vary"]["NODES"] for i in items]
assert all(isinstance(x, int) and 8 <= x <= 24 for x in n), n
assert len(set(n)) > 1, n
assert all(isinstance(i["vary"]["INTERNODE"], float) for i in items)
PY
then ok "integer bounds draw integers"; else bad "integer bounds draw integers"; fi
expect "dataset --vary unknown global" 2 "$V" dataset "$TOM" --count 2 -N 200 --vary NODEZ=8:24 -o "$T/vu"
expect_err "unknown --vary named as --vary" "[-]-vary NODEZ: .*no global 'NODEZ'"
if [ ! -e "$T/vu" ]; then ok "no folder for a refused dataset"; else bad "no folder for a refused dataset"; fi
expect "dataset whose items fail" 2 "$V" dataset "$TOM" --count 2 -N 200 --set NODES=-3 -o "$T/vf"
if [ ! -e "$T/vf" ]; then ok "no empty folder after a failed dataset"; else bad "no empty folder after a failed dataset"; fi

# two shards into another folder: the same items; the manifest comes with the last shard
E="$T/shards"
expect "shard 0/2" 0 "$V" dataset "$A" --count 5 -N 2000 --seed 4 --vary ROSETTE_LEAF=0.025:0.045 -o "$E" --shard 0/2
if [ ! -f "$E/manifest.json" ] && [ -f "$E/item_000004.ply" ] && [ ! -f "$E/item_000001.ply" ]; then ok "shard 0 made its items"; else bad "shard 0 made its items"; fi
expect "shard 1/2" 0 "$V" dataset "$A" --count 5 -N 2000 --seed 4 --vary ROSETTE_LEAF=0.025:0.045 -o "$E" --shard 1/2
if python3 - "$D" "$E" <<'PY'
import json, sys
a = json.load(open(sys.argv[1] + "/manifest.json"))["items"]
b = json.load(open(sys.argv[2] + "/manifest.json"))["items"]
assert [i["sha256"] for i in a] == [i["sha256"] for i in b]
PY
then ok "shards give the same dataset"; else bad "shards give the same dataset"; fi
expect "bad shard" 2 "$V" dataset "$A" --count 5 -o "$E" --shard 2/2
expect "bad vary" 2 "$V" dataset "$A" --count 5 -o "$E" --vary X=3:1
expect "vary unknown global" 2 "$V" dataset "$A" --count 1 -N 100 -o "$T/ds3" --vary NOPE=1:2
expect_err "unknown --vary named" "[-]-vary NOPE"

# progress bars where the time goes (issue 12, item 21): sampling and writing, on a terminal
# only (util-linux's script gives the run one)
if have_pty "progress bar checks on a terminal"; then
  script -qc "'$V' cloud '$A' -N 200000 -o '$T/bar.ply'" /dev/null >"$T/tty" 2>&1
  if grep -aq "sampling \[#*\] 100%" "$T/tty" && grep -aq "writing  \[#*\] 100%" "$T/tty" && [ -s "$T/bar.ply" ]; then
    ok "cloud progress bars on a terminal"
  else
    bad "cloud progress bars on a terminal ($(tr '\r' '\n' <"$T/tty" | tail -c 300))"
  fi
fi
"$V" cloud "$A" -N 20000 -o "$T/bar2.ply" 2>"$T/err"
if [ -s "$T/err" ]; then bad "no progress bar off a terminal ($(head -c 200 "$T/err"))"; else ok "no progress bar off a terminal"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
