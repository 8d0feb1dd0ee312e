#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of `verdant export`: URDF, SDF and MJCF files of the tomato; the MJCF loads in
# MuJoCo alone and beside the arm (--check, --check-with: always run, no OpenGL needed); the URDF
# passes check_urdf (liburdfdom-tools) and the SDF `ign sdf -k` (ignition-tools, libsdformat)
# when they are installed; bad usage and an unwritable output are exit 2, nothing left.
# Usage: cli_export_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_export "$@"

expect "export help" 0 "$V" export --help
expect "export without output" 2 "$V" export "$SRC/data/tomato.lpy"
expect "export unknown format" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.stl"
expect "export check on urdf" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.urdf" --check
expect "export bad pos" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.xml" --pos 1,2
expect "export bad thickness" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.xml" --leaf-thickness 0
expect "export bad name" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.xml" --name "a b"
expect "export two outputs" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.xml" -o "$T/y.xml"
expect "export missing plant" 2 "$V" export "$T/missing.lpy" -o "$T/x.xml"
expect_err "missing plant named" "missing.lpy"
if ls "$T"/x.* >/dev/null 2>&1; then bad "nothing written after errors"; else ok "nothing written after errors"; fi

# MJCF: loads in MuJoCo; beside the arm the plant touches it (the arm's reference pose reaches in)
expect "export mjcf" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/plant.xml" --check
cp "$T/out" "$T/alone.json"
expect "export mjcf with the arm" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/plant.xml" \
  --check-with "$SRC/data/robots/arm6.xml"
cp "$T/out" "$T/arm.json"
expect "export mjcf moved away" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/far.xml" --pos 3,0,0 \
  --check-with "$SRC/data/robots/arm6.xml"
cp "$T/out" "$T/far.json"
if python3 - "$T" <<'PY'
import json, sys
t = sys.argv[1]
alone, arm, far = (json.load(open(f"{t}/{n}.json")) for n in ("alone", "arm", "far"))
# flexible: three hinge springs per link; plant geoms never touch each other (contype 2,
# conaffinity 1) but do touch the arm's
assert alone["joints"] == 3 * (alone["plant_bodies"] - 1) and alone["plant_bodies"] == alone["bodies"] - 2 > 50, alone
assert alone["plant_geoms"] == alone["geoms"] and alone["meshes"] > 20 and alone["contacts"] == 0, alone
assert arm["plant_bodies"] == alone["plant_bodies"] and arm["joints"] > alone["joints"], arm
assert arm["plant_robot_contacts"] > 0 and far["plant_robot_contacts"] == 0, (arm, far)
PY
then ok "mjcf loads, alone and with the arm"; else bad "mjcf loads, alone and with the arm"; fi
# --static: the drawn plant, one rigid body per organ, no joints
expect "export mjcf static" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/static.xml" --static \
  --check-with "$SRC/data/robots/arm6.xml"
cp "$T/out" "$T/static.json"
# rigid links per organ: masses and no plant joints; 2 links per organ: fewer bodies than auto
expect "export mjcf rigid" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/rigid.xml" \
  --links-per-organ rigid --check
cp "$T/out" "$T/rigid.json"
expect "export mjcf two links per organ" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/two.xml" \
  --links-per-organ 2 --check
cp "$T/out" "$T/two.json"
if python3 - "$T" <<'PY'
import json, sys
t = sys.argv[1]
alone, st, rigid, two = (json.load(open(f"{t}/{n}.json")) for n in ("alone", "static", "rigid", "two"))
assert st["plant_robot_contacts"] > 0 and st["plant_bodies"] < alone["plant_bodies"], st
assert rigid["joints"] == 0 and rigid["plant_bodies"] < two["plant_bodies"] < alone["plant_bodies"], (rigid, two)
assert two["joints"] == 3 * (two["plant_bodies"] - 1), two
PY
then ok "static, rigid and coarser links"; else bad "static, rigid and coarser links"; fi
expect "export bad links per organ" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.xml" --links-per-organ 0
expect "export bad damping ratio" 2 "$V" export "$SRC/data/tomato.lpy" -o "$T/x.xml" --damping-ratio -1
if ls "$T"/*.scene.xml >/dev/null 2>&1; then bad "no scene left behind"; else ok "no scene left behind"; fi
# the Lite 6, whose MJCF includes its gripper's; its keyframe covers its own joints, so the
# plant comes rigid (MuJoCo 2.2.2 wants a key's qpos to cover every joint of the scene)
if [ -f "$SRC/data/robots/lite6.xml" ]; then
  expect "export mjcf with the Lite 6" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/plant.xml" \
    --links-per-organ rigid --check-with "$SRC/data/robots/lite6.xml"
  if grep -Eq '"plant_bodies":[[:space:]]+[1-9]' "$T/out" && grep -Eq '"joints":[[:space:]]+[1-9]' "$T/out"; then ok "Lite 6 scene loads"; else bad "Lite 6 scene loads: $(head -c 300 "$T/out")"; fi
fi

# URDF and SDF, with their meshes as OBJ files; the standard checkers when installed
expect "export urdf" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/plant.urdf"
expect "export sdf" 0 "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/plant.sdf"
n=$(ls "$T"/plant_meshes/*.obj 2>/dev/null | wc -l)
if [ "$n" -gt 20 ]; then ok "mesh files written ($n)"; else bad "mesh files written ($n)"; fi
if command -v check_urdf >/dev/null 2>&1; then
  expect "check_urdf accepts the URDF" 0 check_urdf "$T/plant.urdf"
else
  echo "skip: check_urdf is not installed (Debian: liburdfdom-tools)"
fi
if command -v ign >/dev/null 2>&1 && ign sdf --help >/dev/null 2>&1; then
  expect "ign sdf -k accepts the SDF" 0 ign sdf -k "$T/plant.sdf"
  if grep -q "^Valid" "$T/out"; then ok "ign sdf says valid"; else bad "ign sdf says valid: $(head -c 300 "$T/out")"; fi
  # the URDF as Gazebo reads it: every link kept (sdformat drops a massless link with its
  # subtree and lumps fixed joints), flexible and rigid; the springs become SDF springs
  for mode in auto rigid; do
    "$V" export "$SRC/data/tomato.lpy" --seed 2 -o "$T/g_$mode.urdf" --links-per-organ $mode >/dev/null 2>&1
    ign sdf -p "$T/g_$mode.urdf" >"$T/g_$mode.sdf" 2>/dev/null
    nu=$(grep -c '<link name=' "$T/g_$mode.urdf"); ns=$(grep -c "<link name=" "$T/g_$mode.sdf")
    if [ "$ns" -eq $((nu - 1)) ] && [ "$ns" -gt 50 ]; then ok "ign sdf -p keeps every link ($mode: $ns)"
    else bad "ign sdf -p keeps every link ($mode: $ns of $((nu - 1)))"; fi
  done
  nj=$(grep -c "springStiffness" "$T/g_auto.urdf"); nk=$(grep -c "<spring_stiffness>" "$T/g_auto.sdf")
  if [ "$nj" -eq "$nk" ] && [ "$nk" -gt 50 ]; then ok "URDF springs reach the SDF ($nk)"; else bad "URDF springs reach the SDF ($nk of $nj)"; fi
else
  echo "skip: ign sdf is not installed (Debian: ignition-tools, libsdformat-dev)"
fi

# the exported plant in MuJoCo bends as the rods do (self-weight and tip load within 5 %)
expect "validate the flexible export" 0 "$V" validate --case export_flex --no-progress

# an unwritable output: exit 2 (found before the run), nothing left (no mesh folder either)
expect "unwritable export" 2 "$V" export "$SRC/data/tomato.lpy" -o "/nonexistent-dir/p.urdf"
if [ -e /nonexistent-dir ]; then bad "nothing left after a failed export"; else ok "nothing left after a failed export"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
