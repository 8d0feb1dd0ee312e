#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of pictures of simulation runs and datasets of images: `verdant sim -o RUN/`
# then `verdant render RUN/` (one frame, every frame into a folder, an MP4 when ffmpeg is
# installed), masks of every frame checked against the frame's state and colliders read from
# the run's own files; bad runs are clear errors; `verdant dataset --images N` records its views
# in the manifest and one view made again by `verdant render` has the same bytes.
# Usage: cli_render_run_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_render_run "$@"
check() {  # check NAME PYTHON-FILE ARGS...: the script exits 0
  local name="$1"
  shift
  if python3 "$@" >"$T/py" 2>&1; then ok "$name"; else bad "$name: $(tail -c 400 "$T/py")"; fi
}

# a small plant: a stem with a leaf and a fruit on a pedicel
cat >"$T/p.lpy" <<'EOF'
LABELS = {1: "stem", 2: "leaf", 3: "pedicel", 4: "fruit"}
module I, Leaf, Ped, Fruit
Axiom: SetWidth(0.004) I(0.1) [ +(50) Leaf(0.08) ] I(0.1) [ &(70) Ped(0.01) Ped(0.01) Fruit(0.012) ] I(0.08)
interpretation:
I(l) --> ;(1) F(l, 0.004)
Leaf(s) --> ;(2) F(0.03, 0.001) ~l(s)
Ped(l) --> ;(3) F(l, 0.0009)
Fruit(r) --> ;(4) f(r) @O(r)
endlsystem
EOF

# PNG reading, shared by the checks
cat >"$T/png.py" <<'EOF'
import struct, zlib
def png(path):
    b = open(path, "rb").read()
    assert b[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, hdr = 8, b"", None
    while pos < len(b):
        n, kind = struct.unpack(">I4s", b[pos:pos + 8])
        data = b[pos + 8:pos + 8 + n]
        if kind == b"IHDR": hdr = struct.unpack(">IIBBBBB", data)
        if kind == b"IDAT": idat += data
        pos += 12 + n
    w, h, bits, ctype = hdr[:4]
    ch = {0: 1, 2: 3}[ctype]
    bpp = ch * bits // 8
    raw, rows, prev = zlib.decompress(idat), [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (w * bpp + 1)], bytearray(raw[y * (w * bpp + 1) + 1:(y + 1) * (w * bpp + 1)])
        for i in range(len(line)):
            a = line[i - bpp] if i >= bpp else 0
            b_, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b_) & 255
            elif f == 3: line[i] = (line[i] + (a + b_) // 2) & 255
            elif f == 4:
                p = a + b_ - c; pa, pb, pc = abs(p - a), abs(p - b_), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b_ if pb <= pc else c)) & 255
        rows.append(line); prev = line
    vals = [v for r in rows for v in (struct.unpack(">%dH" % (len(r) // 2), r) if bits == 16 else r)]
    return w, h, bits, ch, vals
EOF

# usage errors (no run needed)
mkdir -p "$T/notarun"
expect "render a folder that is not a run" 2 "$V" render "$T/notarun" -o "$T/x.png"
expect_err "missing rod.json named" "notarun/rod.json"
expect "run without output" 2 "$V" render "$T/notarun"
expect "time with a folder output" 2 "$V" render "$T/notarun" -o "$T/frames/" --time 0.1
expect "plant options on a run" 2 "$V" render "$T/notarun" -o "$T/x.png" --seed 3
expect "bad mp4 name" 2 "$V" render "$T/notarun" --mp4 "$T/x.avi"
expect "bad range" 2 "$V" render "$T/notarun" -o "$T/x.png" --range 5,1
expect "time on a plant" 2 "$V" render "$T/p.lpy" -o "$T/x.png" --time 1

# a run: gravity off, a probe sweeps through the fruit (at x = -3 cm, z = 21 cm) along +x;
# 0.3 s at 20 frames/s
expect "sim run" 0 "$V" sim "$T/p.lpy" --gravity 0,0,0 --duration 0.3 --fps 20 --no-progress \
  --probe 0.015:-0.15,0,0.21:0.15,0,0.21 -o "$T/run"
for f in rod.json plant_initial.json frames.bin colliders.jsonl events.csv plant.json; do
  if [ -s "$T/run/$f" ]; then ok "run has $f"; else bad "run has $f"; fi
done
check "rod.json carries the build settings" - "$T/run" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1] + "/rod.json"))
b = d["build"]
assert d["initial_plant"] == "plant_initial.json"
assert b["segment_length"] == 0.02 and b["gravity"] == [0, 0, 0], b
assert b["materials"]["green"]["break_force"] is None and b["materials"]["pedicel"]["break_force"] == 6.5
lines = open(sys.argv[1] + "/colliders.jsonl").read().split("\n")
assert len([l for l in lines if l.strip()]) == 7, len(lines)
EOF

# can this machine make a context? (the unit tests say why when it cannot)
if ! "$V" render "$T/run" -o "$T/probe.png" --size 32x24 --supersample 1 2>"$T/err"; then
  if grep -q "no OpenGL context" "$T/err"; then
    echo "skip: no OpenGL context here: $(cat "$T/err")"
    echo "$pass passed, $fail failed"
    [ "$fail" -eq 0 ]
    exit
  fi
fi

# every frame with masks, depth and sidecars, into a folder
expect "render every frame" 0 "$V" render "$T/run" -o "$T/frames/" --masks --depth --size 200x150 --camera front \
  --no-progress
check "masks of every frame agree with the frame's state" - "$T" <<'EOF'
import json, struct, sys
sys.path.insert(0, sys.argv[1])
from png import png
d = sys.argv[1]
rod = json.load(open(d + "/run/rod.json"))
idx = json.load(open(d + "/frames/frames.json"))
n, s = rod["nodes"], rod["segments"]
fruit_label = [int(k) for k, v in rod["labels"].items() if v == "fruit"][0]
fruit_nodes = [i for i, r in enumerate(rod["node_sphere"]) if r > 0]
assert len(fruit_nodes) == 1, fruit_nodes
b = open(d + "/run/frames.bin", "rb").read()
size = 8 + 12 * n + 17 * s
nframe = (len(b) - 24) // size
assert nframe == len(idx["frames"]) == 7, (nframe, len(idx["frames"]))
colliders = [json.loads(l) for l in open(d + "/run/colliders.jsonl") if l.strip()]
us, probe_hits = [], 0
def project(meta, p):
    R, t, K = meta["pose"]["R"], meta["pose"]["t"], meta["intrinsics"]
    q = [p[i] - t[i] for i in range(3)]
    X, Y, Z = (sum(R[3 * i + k] * q[i] for i in range(3)) for k in range(3))
    return K["fx"] * X / Z + K["cx"], K["fy"] * Y / Z + K["cy"]
for k, fr in enumerate(idx["frames"]):
    rec = b[24 + k * size: 24 + (k + 1) * size]
    t = struct.unpack("<d", rec[:8])[0]
    assert abs(t - fr["time"]) < 1e-12
    meta = json.load(open(d + "/frames/" + fr["camera"]))
    assert meta["files"]["label"] == fr["label"]  # siblings named without folders
    w, h, _, _, lab = png(d + "/frames/" + fr["label"])
    _, _, _, _, inst = png(d + "/frames/" + fr["instance"])
    # the fruit's centre, from this frame's node positions, is a fruit pixel
    i = fruit_nodes[0]
    p = struct.unpack("<3f", rec[8 + 12 * i: 20 + 12 * i])
    u, v = project(meta, p)
    px = int(round(v)) * w + int(round(u))
    assert lab[px] == fruit_label, (k, lab[px], u, v)
    assert inst[px] > 0
    us.append(u)
    # the probe's centre, from this frame's colliders, is a robot/tool pixel unless the plant hides it
    sph = [c for c in colliders[k]["colliders"] if c["shape"] == "sphere"][0]
    u, v = project(meta, sph["pos"])
    if 0 <= u < w and 0 <= v < h:
        l = lab[int(round(v)) * w + int(round(u))]
        assert l in (65535, 1, 2, 3, 4), l
        probe_hits += l == 65535
assert probe_hits >= 4, probe_hits
assert max(us) - min(us) > 3, us  # the probe moved the fruit
EOF

# one frame: --time picks the nearest frame, the same bytes as that frame in the folder
expect "render one frame" 0 "$V" render "$T/run" -o "$T/one.png" --time 0.16 --masks --depth --size 200x150 --camera front
if cmp -s "$T/one.png" "$T/frames/frame_00003.png" && cmp -s "$T/one.label.png" "$T/frames/frame_00003.label.png"; then
  ok "one frame equals the folder's frame"
else
  bad "one frame equals the folder's frame"
fi
expect "render last frame" 0 "$V" render "$T/run" -o "$T/last.png" --size 200x150 --camera front
if cmp -s "$T/last.png" "$T/frames/frame_00006.png"; then ok "default is the last frame"; else bad "default is the last frame"; fi

# colour by displacement and stress: one scale for the whole run, written in the index
expect "render by displacement" 0 "$V" render "$T/run" -o "$T/disp/" --color-by displacement --size 160x120 --no-progress
expect "render by stress" 0 "$V" render "$T/run" -o "$T/stress/" --color-by stress --size 160x120 --no-progress
expect "render by stress with a range" 0 "$V" render "$T/run" -o "$T/stress1.png" --color-by stress --range 0,1e6 --size 160x120
check "colour scales of the run" - "$T" <<'EOF'
import json, sys
d = sys.argv[1]
a = json.load(open(d + "/disp/frames.json"))
b = json.load(open(d + "/stress/frames.json"))
assert a["color_by"] == "displacement" and a["unit"] == "m" and a["range"][0] == 0 and 0.001 < a["range"][1] < 0.5, a["range"]
assert b["color_by"] == "stress" and b["unit"] == "Pa" and b["range"][1] > 1e3, b["range"]
EOF
if cmp -s "$T/disp/frame_00000.png" "$T/disp/frame_00006.png"; then bad "frames differ"; else ok "frames differ"; fi

# scales follow what the picture shows: a settled plant shows its sag from the plant as modelled
# (it showed "0 ... 0", measured from its only frame); --displacement-from first gives the
# timed motion alone; a fruit pulled off lies beyond the scale of the plant still attached
cat >"$T/sag.lpy" <<'EOF'
LABELS = {1: "stem", 2: "leaf"}
module I, B, Leaf
Axiom: SetWidth(0.004) I(0.1) [ +(90) B(0.3) Leaf(0.08) ] I(0.1)
interpretation:
I(l) --> ;(1) F(l, 0.004)
B(l) --> ;(1) F(l, 0.0012)
Leaf(s) --> ;(2) ~l(s)
endlsystem
EOF
expect "sim settle" 0 "$V" sim "$T/sag.lpy" --settle --no-progress -o "$T/settle" --stats
cp "$T/out" "$T/settle.stats"
expect "render settled sag" 0 "$V" render "$T/settle" -o "$T/sag.png" --color-by displacement --depth --size 96x72
expect "render settled from first" 0 "$V" render "$T/settle" -o "$T/sag0.png" --color-by displacement --depth --size 96x72 \
  --displacement-from first
expect "displacement-from on a plant" 2 "$V" render "$T/sag.lpy" -o "$T/x.png" --displacement-from first
expect "displacement-from bad" 2 "$V" render "$T/settle" -o "$T/x.png" --displacement-from last
expect "sim pull a fruit off" 0 "$V" sim "$T/p.lpy" --sag-free --duration 0.4 --pull fruit=0,0,-3 --no-progress -o "$T/pull"
expect "render pulled by displacement" 0 "$V" render "$T/pull" -o "$T/pull.png" --color-by displacement --masks --size 200x150 --camera front
check "scales follow the attached plant" - "$T" <<'EOF'
import json, sys
d = sys.argv[1]
stats = json.load(open(d + "/settle.stats"))
sag = json.load(open(d + "/sag.png.json"))["range"]
first = json.load(open(d + "/sag0.png.json"))["range"]
assert stats["max_displacement"] > 0.005, stats["max_displacement"]
assert 0.5 * stats["max_displacement"] < sag[1] <= 1.5 * stats["max_displacement"], (sag, stats["max_displacement"])
assert first[1] < 1e-9, first
events = open(d + "/pull/events.csv").read().splitlines()
assert len(events) >= 2, events
pull = json.load(open(d + "/pull.png.json"))["range"]
assert pull[1] < 0.02, pull
EOF

# an MP4 when ffmpeg is there; a clear message and no video when it is not
if command -v ffmpeg >/dev/null 2>&1; then
  expect "render mp4" 0 "$V" render "$T/run" --mp4 "$T/run.mp4" --size 161x121 --supersample 1 --no-progress
  if [ -s "$T/run.mp4" ] && head -c 12 "$T/run.mp4" | grep -q ftyp; then ok "mp4 written"; else bad "mp4 written"; fi
  if command -v ffprobe >/dev/null 2>&1; then
    frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$T/run.mp4")
    if [ "$frames" = "7" ]; then ok "mp4 has every frame"; else bad "mp4 has every frame ($frames)"; fi
  fi
  if ls "$T"/run.mp4.tmp* >/dev/null 2>&1; then bad "no temporary video left"; else ok "no temporary video left"; fi
else
  echo "skip: ffmpeg is not installed here; the MP4 path is not exercised"
fi
PATH=/nonexistent expect "mp4 without ffmpeg" 1 "$V" render "$T/run" --mp4 "$T/nope.mp4" --size 64x48
expect_err "mp4 without ffmpeg message" "ffmpeg is not installed"
PATH=/nonexistent expect "mp4 without ffmpeg, frames still made" 0 "$V" render "$T/run" --mp4 "$T/nope.mp4" -o "$T/still.png" --size 64x48
if [ -s "$T/still.png" ] && [ ! -e "$T/nope.mp4" ]; then ok "frame made, no video"; else bad "frame made, no video"; fi

# damaged runs: clear errors naming the file, exit 2, nothing written
cp -r "$T/run" "$T/cut"
head -c 1000 "$T/run/frames.bin" >"$T/cut/frames.bin"
expect "truncated frames" 2 "$V" render "$T/cut" -o "$T/cut.png"
expect_err "truncated frames named" "cut/frames.bin: .*truncated"
if [ -e "$T/cut.png" ]; then bad "nothing written for a bad run"; else ok "nothing written for a bad run"; fi
cp -r "$T/run" "$T/old" && rm "$T/old/plant_initial.json"
expect "run without its initial plant" 2 "$V" render "$T/old" -o "$T/old.png"
expect_err "initial plant named" "plant_initial.json"
cp -r "$T/run" "$T/nobuild" && python3 - "$T/nobuild/rod.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1])); del d["build"]; json.dump(d, open(sys.argv[1], "w"))
EOF
expect "run without build settings" 2 "$V" render "$T/nobuild" -o "$T/nb.png"
expect_err "build settings named" "rod.json: .*build"
cp -r "$T/run" "$T/other" && python3 - "$T/other/rod.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1])); d["build"]["segment_length"] = 0.05; json.dump(d, open(sys.argv[1], "w"))
EOF
expect "rod model that does not rebuild" 2 "$V" render "$T/other" -o "$T/ot.png"
expect_err "rebuild mismatch explained" "rebuilt"
cp -r "$T/run" "$T/col" && head -n 3 "$T/run/colliders.jsonl" >"$T/col/colliders.jsonl"
expect "colliders for fewer frames" 2 "$V" render "$T/col" -o "$T/col.png"
expect_err "colliders named" "colliders.jsonl"
# a run with JSON Lines frames and no colliders file renders too
expect "sim jsonl run" 0 "$V" sim "$T/p.lpy" --duration 0.05 --fps 40 --no-progress --frames jsonl -o "$T/runj"
rm "$T/runj/colliders.jsonl"
expect "render jsonl run" 0 "$V" render "$T/runj" -o "$T/j.png" --time 0.025 --size 80x60 --masks
# no context: exit 1 and a clear message
__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json expect "run without a context" 1 "$V" render "$T/run" -o "$T/noctx.png"
expect_err "no context message" "no OpenGL context"
expect "unwritable folder" 2 "$V" render "$T/run" -o "/nonexistent-dir/frames/" --size 32x24

# datasets of images: N views per item beside the clouds, in the manifest
expect "dataset with images" 0 "$V" dataset "$T/p.lpy" --count 2 --points 500 --images 2 --image-size 96x72 -o "$T/ds"
check "images in the records and the manifest" - "$T" <<'EOF'
import json, os, sys
sys.path.insert(0, sys.argv[1])
from png import png
d = sys.argv[1] + "/ds"
m = json.load(open(d + "/manifest.json"))
assert m["images"]["per_item"] == 2 and m["images"]["width"] == 96 and m["images"]["height"] == 72
labels = {l["id"] for l in m["labels"]}
for it in m["items"]:
    assert len(it["images"]) == 2
    for v in it["images"]:
        assert 10 <= v["elevation"] <= 40 and -180 <= v["azimuth"] <= 180
        for role in ("color", "depth", "label", "instance", "camera"):
            assert os.path.exists(d + "/" + v[role]), v[role]
        w, h, bits, ch, lab = png(d + "/" + v["label"])
        assert (w, h, bits, ch) == (96, 72, 16, 1)
        used = set(lab) - {0}
        assert used and used <= labels, (used, labels)
        cam = json.load(open(d + "/" + v["camera"]))
        assert cam["files"]["color"] == v["color"]
    a, b = it["images"]
    assert abs(((b["azimuth"] - a["azimuth"]) % 360) - 180) < 1e-9  # two views half a turn apart
open(sys.argv[1] + "/view.args", "w").write("%d %r %r\n" % (m["items"][1]["seed"], m["items"][1]["images"][0]["azimuth"], m["items"][1]["images"][0]["elevation"]))
EOF
read -r vseed vaz vel <"$T/view.args"
expect "a view made again by render" 0 "$V" render "$T/p.lpy" --seed "$vseed" --camera "orbit:$vaz:$vel" --size 96x72 \
  --no-legend --depth --masks -o "$T/again.png"
if cmp -s "$T/again.png" "$T/ds/item_000001_view0.png" && cmp -s "$T/again.label.png" "$T/ds/item_000001_view0.label.png" &&
  cmp -s "$T/again.depth.png" "$T/ds/item_000001_view0.depth.png"; then
  ok "the view has the same bytes"
else
  bad "the view has the same bytes"
fi
# a missing view makes its item incomplete: made again, the others skipped
rm "$T/ds/item_000000_view1.depth.png"
expect "dataset resumes" 0 "$V" dataset "$T/p.lpy" --count 2 --points 500 --images 2 --image-size 96x72 -o "$T/ds" --stats
if grep -q '"made":.*1' "$T/out" && grep -q '"skipped":.*1' "$T/out" && [ -s "$T/ds/item_000000_view1.depth.png" ]; then
  ok "incomplete item made again"
else
  bad "incomplete item made again ($(cat "$T/out"))"
fi
expect "dataset with other image options refused" 2 "$V" dataset "$T/p.lpy" --count 2 --points 500 --images 3 --image-size 96x72 -o "$T/ds"
expect "image size without images" 2 "$V" dataset "$T/p.lpy" --count 1 --image-size 96x72 -o "$T/ds2"
expect "bad image count" 2 "$V" dataset "$T/p.lpy" --count 1 --images 0 -o "$T/ds2"
__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json expect "dataset images without a context" 1 "$V" dataset "$T/p.lpy" \
  --count 1 --points 100 --images 1 -o "$T/ds3"
expect_err "dataset no context message" "no OpenGL context"
expect "dataset images in parallel" 0 "$V" dataset "$T/p.lpy" --count 4 --points 300 --images 1 --image-size 64x48 --jobs 2 -o "$T/ds4"
expect "dataset images one job" 0 "$V" dataset "$T/p.lpy" --count 4 --points 300 --images 1 --image-size 64x48 --jobs 1 -o "$T/ds5"
same=1
for i in 0 1 2 3; do
  for x in png label.png depth.png; do cmp -s "$T/ds4/item_00000${i}_view0.$x" "$T/ds5/item_00000${i}_view0.$x" || same=0; done
done
if [ "$same" = 1 ]; then ok "views do not depend on --jobs"; else bad "views do not depend on --jobs"; fi

# pictures for vision work: render options and views that vary (issue 12, item 16); every view is
# made again by the manifest's recipe with the fields of its record, byte for byte
expect "view options without images" 2 "$V" dataset "$T/p.lpy" --count 1 --vary-light -o "$T/dsx"
expect "bad view distance" 2 "$V" dataset "$T/p.lpy" --count 1 --images 1 --view-distance 2:1 -o "$T/dsx"
expect "bad view jitter" 2 "$V" dataset "$T/p.lpy" --count 1 --images 1 --view-jitter 3 -o "$T/dsx"
expect "bad view elevation" 2 "$V" dataset "$T/p.lpy" --count 1 --images 1 --view-elevation 10:95 -o "$T/dsx"
expect "dataset with varied views" 0 "$V" dataset "$T/p.lpy" --count 2 --points 300 --images 3 --image-size 80x60 \
  --view-elevation 5:60 --view-distance 0.7:1.5 --view-jitter 0.4 --vary-light --vary-background --palette natural \
  --no-shadows --supersample 1 --jobs 2 -o "$T/dsv"
check "varied views: records, recipe, same bytes" - "$V" "$T/dsv" "$T" <<'EOF'
import filecmp, json, subprocess, sys
v, d, t = sys.argv[1:4]
m = json.load(open(d + "/manifest.json"))
argv = m["images"]["regenerate_argv"]
for opt in ("--no-shadows", "--palette", "--supersample", "--eye", "--lookat", "--light", "--sky-rgb", "--floor-rgb"):
    assert opt in argv, (opt, argv)
lights, skies, n = set(), set(), 0
for item in m["items"]:
    rec = json.load(open(f"{d}/item_{item['index']:06d}.json"))  # exact numbers
    for view in rec["images"]:
        assert 5 <= view["elevation"] <= 60 and 0.7 <= view["distance"] <= 1.5, view
        assert -180 <= view["light"][0] <= 180 and 15 <= view["light"][1] <= 75, view["light"]
        assert all(0 <= c <= 1 for c in view["sky"] + view["floor"])
        lights.add(tuple(view["light"]))
        skies.add(tuple(view["sky"]))
        f = {"seed": str(item["seed"])}
        for k in ("eye", "lookat", "up", "light", "sky", "floor"):
            f[k] = ",".join(repr(float(x)) for x in view[k])
        a = [v] + argv[1:-1] + [f"{t}/vagain.png"]
        for key, val in f.items():
            a = [x.replace("{" + key + "}", val) for x in a]
        assert not any("{" in x for x in a), a
        subprocess.run(a, check=True)
        for role, ext in (("color", "png"), ("label", "label.png"), ("depth", "depth.png"), ("instance", "instance.png")):
            assert filecmp.cmp(f"{t}/vagain.{ext}", f"{d}/{view[role]}", shallow=False), view[role]
        side = json.load(open(f"{d}/{view['camera']}"))
        assert side["palette"] == "natural"
        n += 1
assert n == 6 and len(lights) == 6 and len(skies) == 6, (n, len(lights), len(skies))
EOF

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
