#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of `verdant render`: exit codes, files written (colour, depth, masks, sidecar),
# masks read back, point clouds, no context → a clear error and exit 1, no partial output.
# Usage: cli_render_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_render "$@"

# usage errors, checked before any work
expect "render help" 0 "$V" render --help
expect "render without input" 2 "$V" render -o "$T/x.png"
expect "render without output" 2 "$V" render "$SRC/data/tomato.lpy"
expect "render output not png" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.jpg"
expect "render bad camera" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --camera diagonal
expect "render bad orbit" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --camera orbit:10:100
expect "render bad size" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --size 640by480
expect "render bad color-by" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --color-by taste
expect "render stress without a run" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --color-by stress
expect_err "stress message" "simulation"
expect "render eye without lookat" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --eye 0,-2,1
expect "render bad eye" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --eye 0,-2 --lookat 0,0,1
expect "render a folder that is not a run" 2 "$V" render "$T" -o "$T/x.png"
expect_err "not a run: rod.json named" "rod.json"
expect "render missing plant" 2 "$V" render "$T/missing.lpy" -o "$T/x.png"
expect_err "missing plant named" "missing.lpy"
printf 'Axiom: A\nproduction:\nA --> B(1 +)\n' >"$T/bad.lpy"
expect "render syntax error" 2 "$V" render "$T/bad.lpy" -o "$T/bad.png"
expect_err "syntax error location" "bad.lpy:3:[0-9]+: "
if ls "$T"/bad*.png >/dev/null 2>&1; then bad "no output after error"; else ok "no output after error"; fi

# no OpenGL context (no EGL vendor): a clear error, exit 1, nothing written
__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json expect "no context exit 1" 1 "$V" render "$SRC/data/tomato.lpy" -o "$T/noctx.png"
expect_err "no context message" "no OpenGL context"
if ls "$T"/noctx* >/dev/null 2>&1; then bad "no output without context"; else ok "no output without context"; fi

# can this machine make a context? (the unit tests say why when it cannot)
if ! "$V" render "$SRC/data/tomato.lpy" -o "$T/probe.png" --size 32x24 --supersample 1 2>"$T/err"; then
  if grep -q "no OpenGL context" "$T/err"; then
    echo "skip: no OpenGL context here: $(cat "$T/err")"
    echo "$pass passed, $fail failed"
    [ "$fail" -eq 0 ]
    exit
  fi
fi

# the tomato with masks and depth: five files, masks 16-bit, sidecar names them
expect "render tomato" 0 "$V" render "$SRC/data/tomato.lpy" --seed 2 -o "$T/tomato.png" --masks --depth --size 320x240
for f in tomato.png tomato.label.png tomato.instance.png tomato.depth.png tomato.png.json; do
  if [ -s "$T/$f" ]; then ok "wrote $f"; else bad "wrote $f"; fi
done
if python3 - "$T" <<'PY'
import json, struct, sys, zlib
d = sys.argv[1]
def png(path):
    b = open(path, "rb").read()
    assert b[:8] == b"\x89PNG\r\n\x1a\n"
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
meta = json.load(open(f"{d}/tomato.png.json"))
assert meta["version"] == 1 and meta["width"] == 320 and meta["height"] == 240
assert abs(meta["intrinsics"]["cx"] - 159.5) < 1e-9
names = {l["id"]: l["name"] for l in meta["labels"]}
assert "leaf" in names.values() and "fruit" in names.values()
w, h, bits, ch, lab = png(f"{d}/tomato.label.png")
assert (w, h, bits, ch) == (320, 240, 16, 1)
_, _, _, _, inst = png(f"{d}/tomato.instance.png")
_, _, _, _, dep = png(f"{d}/tomato.depth.png")
used = set(lab) - {0}
assert used and used <= set(names), (used, names)
# an instance has one label; background has neither label nor instance
pairs = {}
for l, i in zip(lab, inst):
    assert (l == 0) == (i == 0)
    if i: assert pairs.setdefault(i, l) == l
# depth: plant pixels between 1 and 5 m
plant = [z for z, l in zip(dep, lab) if l]
assert plant and min(plant) > 1000 and max(plant) < 5000, (min(plant), max(plant))
w, h, bits, ch, rgb = png(f"{d}/tomato.png")
assert (w, h, bits, ch) == (320, 240, 8, 3)
PY
then ok "masks, depth and sidecar agree"; else bad "masks, depth and sidecar agree"; fi
# the sidecar names the OpenGL that drew the picture, as --info does (GPU or llvmpipe)
expect "render with info" 0 "$V" render "$SRC/data/tomato.lpy" --seed 2 -o "$T/info.png" --depth --size 64x48 --info
if python3 - "$T/info.png.json" "$T/err" <<'PY'
import json, sys
gl = json.load(open(sys.argv[1]))["opengl"]
info = open(sys.argv[2]).read()
assert gl["vendor"] and gl["renderer"] and gl["version"] and "?" not in (gl["vendor"], gl["renderer"])
assert gl["renderer"] in info and gl["version"] in info, (gl, info)
assert gl["egl_platform"] in ("surfaceless", "device", "default display")
assert gl["software"] == any(s in gl["renderer"] for s in ("llvmpipe", "softpipe", "swrast", "Software"))
PY
then ok "sidecar names the OpenGL renderer"; else bad "sidecar names the OpenGL renderer"; fi

# same seed, same bytes; presets and explicit poses; other colourings
expect "render again" 0 "$V" render "$SRC/data/tomato.lpy" --seed 2 -o "$T/again.png" --masks --depth --size 320x240
if cmp -s "$T/tomato.png" "$T/again.png" && cmp -s "$T/tomato.label.png" "$T/again.label.png"; then
  ok "deterministic images"
else
  bad "deterministic images"
fi
for cam in front side top orbit orbit:30 orbit:120:45; do
  expect "camera $cam" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/cam.png" --camera "$cam" --size 160x120
done
expect "explicit pose" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/pose.png" --eye 1.5,-1.5,1.2 --lookat 0,0,0.6 --fov 40 --size 160x120
expect "color by instance" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/inst.png" --color-by instance --size 160x120
expect "color by displacement" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/disp.png" --color-by displacement --size 160x120
# the look: lights, sky and floor colours (what dataset views vary)
expect "render without a look" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/nolook.png" --size 64x48
expect "render with a look" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/look.png" --size 64x48 --light 60,30,0.8,0.2,0.2 \
  --sky-rgb 1,0.8,0.6,0.3,0.2,0.5 --floor-rgb 0.2,0.5,0.2
if cmp -s "$T/look.png" "$T/nolook.png"; then bad "the look changes the picture"; else ok "the look changes the picture"; fi
expect "light out of range" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --light 0,95
expect "light intensity out of range" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --light 0,45,2
expect "sky colour out of range" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --sky-rgb 1,2,3
expect "floor colour malformed" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --floor-rgb 1,0
# label colours: distinct by default, the label table's with --palette natural (sidecar says which)
expect "palette natural" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/nat.png" --palette natural --masks --size 64x48
expect "palette bad" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/x.png" --palette pastel
expect "grow for palette" 0 "$V" grow "$SRC/data/tomato.lpy" -o "$T/labels.json"
if python3 - "$T/tomato.png.json" "$T/nat.png.json" "$T/labels.json" <<'PY'
import json, sys
dist, nat, plant = (json.load(open(p)) for p in sys.argv[1:])
assert dist["palette"] == "distinct" and nat["palette"] == "natural"
table = {l["id"]: l["rgb"] for l in plant["labels"]}
for l in nat["labels"]:
    assert all(abs(a - b) < 1e-6 for a, b in zip(l["rgb"], table[l["id"]])), (l, table[l["id"]])
rgb = [tuple(round(c, 3) for c in l["rgb"]) for l in dist["labels"]]
assert len(set(rgb)) == len(rgb), rgb
PY
then ok "palettes in the sidecar"; else bad "palettes in the sidecar"; fi
expect "plant file" 0 "$V" grow "$SRC/data/tomato.lpy" -o "$T/tomato.json"
expect "render plant file" 0 "$V" render "$T/tomato.json" -o "$T/fromjson.png" --size 160x120

# point clouds: ASCII and binary PLY with label and instance
{
  printf 'ply\nformat ascii 1.0\nelement vertex 200\nproperty float x\nproperty float y\nproperty float z\n'
  printf 'property int label\nproperty int instance\nend_header\n'
  for i in $(seq 0 199); do echo "0.$((i % 10)) 0.0 0.$((i / 10 % 10)) $((1 + i / 100)) $((1 + i / 50))"; done
} >"$T/cloud.ply"
expect "render ascii cloud" 0 "$V" render "$T/cloud.ply" -o "$T/cloud.png" --masks --size 160x120
expect "render cloud by instance" 0 "$V" render "$T/cloud.ply" -o "$T/cloudi.png" --color-by instance --size 160x120
# meshes that grow wrote (per-face labels) render as meshes, not as grey points: the same masks as
# the plant file within edge pixels (float coordinates), the same label names
expect "grow binary ply" 0 "$V" grow "$SRC/data/tomato.lpy" --seed 2 -o "$T/mesh.ply"
expect "grow obj" 0 "$V" grow "$SRC/data/tomato.lpy" --seed 2 -o "$T/mesh.obj"
expect "grow ascii ply" 0 "$V" grow "$SRC/data/tomato.lpy" --seed 2 -o "$T/mesha.ply" --ascii
expect "grow json" 0 "$V" grow "$SRC/data/tomato.lpy" --seed 2 -o "$T/mesh.json"
for m in mesh.ply mesh.obj mesha.ply mesh.json; do
  expect "render $m" 0 "$V" render "$T/$m" -o "$T/r_${m%.*}_${m##*.}.png" --masks --size 320x240
done
expect "mesh by displacement refused" 2 "$V" render "$T/mesh.obj" -o "$T/x.png" --color-by displacement
if python3 - "$T" "$SRC/tests" <<'PY'
import json, sys
d = sys.argv[1]
sys.path.insert(0, sys.argv[2])
from png_util import png
def png16(path):
    return png(path)[4]
ref = {k: png16(f"{d}/r_mesh_json.{k}.png") for k in ("label", "instance")}
names = {l["id"]: l["name"] for l in json.load(open(f"{d}/r_mesh_json.png.json"))["labels"]}
fg = sum(1 for v in ref["label"] if v)
for m in ("mesh_ply", "mesh_obj", "mesha_ply"):
    meta = json.load(open(f"{d}/r_{m}.png.json"))
    assert {l["id"]: l["name"] for l in meta["labels"]} == names, (m, meta["labels"])
    for k in ("label", "instance"):
        got = png16(f"{d}/r_{m}.{k}.png")
        diff = sum(1 for a, b in zip(got, ref[k]) if a != b)
        assert fg > 1000 and diff < 0.03 * fg, (m, k, diff, fg)
PY
then ok "meshes render like the plant"; else bad "meshes render like the plant"; fi
expect "cloud by displacement refused" 2 "$V" render "$T/cloud.ply" -o "$T/x.png" --color-by displacement
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n0 0\n1 1\n' >"$T/noz.ply"
expect "cloud without z" 2 "$V" render "$T/noz.ply" -o "$T/x.png"
expect_err "cloud error names file" "noz.ply"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 1\n' >"$T/short.ply"
expect "truncated cloud" 2 "$V" render "$T/short.ply" -o "$T/x.png"
printf 'PLY?' >"$T/junk.ply"
expect "not a ply" 2 "$V" render "$T/junk.ply" -o "$T/x.png"

# a robot from MJCF: its pixels carry label 65535; a broken MJCF is bad input
expect "render with robot" 0 "$V" render "$SRC/data/tomato.lpy" -o "$T/arm.png" --robot "$SRC/data/robots/arm6.xml" --masks --size 160x120
if python3 - "$T/arm.label.png" <<'PY'
import struct, sys, zlib
b = open(sys.argv[1], "rb").read()
pos, idat = 8, b""
while pos < len(b):
    n, kind = struct.unpack(">I4s", b[pos:pos + 8])
    if kind == b"IHDR": w, h = struct.unpack(">II", b[pos + 8:pos + 16])
    if kind == b"IDAT": idat += b[pos + 8:pos + 8 + n]
    pos += 12 + n
raw, stride, prev, found = zlib.decompress(idat), 2 * w + 1, bytearray(2 * w), False
for y in range(h):
    f, line = raw[y * stride], bytearray(raw[y * stride + 1:(y + 1) * stride])
    for i in range(len(line)):
        a = line[i - 2] if i >= 2 else 0
        c = prev[i - 2] if i >= 2 else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + prev[i]) & 255
        elif f == 3: line[i] = (line[i] + (a + prev[i]) // 2) & 255
        elif f == 4:
            p = a + prev[i] - c; pa, pb, pc = abs(p - a), abs(p - prev[i]), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else prev[i] if pb <= pc else c)) & 255
    found |= 65535 in struct.unpack(">%dH" % w, line)
    prev = line
sys.exit(0 if found else 1)
PY
then ok "robot pixels labelled 65535"; else bad "robot pixels labelled 65535"; fi
printf '<mujoco><worldbody><geom type="sphere"/></worldbody>' >"$T/badrobot.xml"
expect "broken robot MJCF" 2 "$V" render "$SRC/data/tomato.lpy" -o "$T/badrobot.png" --robot "$T/badrobot.xml"
expect_err "robot error names file" "badrobot.xml"

# an empty plant still gives a picture
printf 'Axiom: A\n' >"$T/empty.lpy"
expect "empty plant" 0 "$V" render "$T/empty.lpy" -o "$T/empty.png" --masks --size 64x48

# an unwritable output: exit 2 (found before the run), nothing left
expect "unwritable output" 2 "$V" render "$SRC/data/tomato.lpy" -o "/nonexistent-dir/x.png" --size 64x48

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
