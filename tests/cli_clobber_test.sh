#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# No output may replace an input (issue 19, docs/reliability.md "One output layer"): every option
# that names a file to read, against every option that writes, as the same path, another
# spelling, a symbolic link and a hard link: exit 2, a message naming both, the input's bytes
# unchanged. Then SIGINT 0.5 s into a run over an earlier run folder leaves it byte-identical,
# for every command that writes a folder. Every option of every command's --help must be in the
# table below (R reads a file, W writes one, D writes a folder, P a pattern of files, N neither):
# a new option that is not classified fails this test.
# Usage: cli_clobber_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_clobber "$@"
cd "$T" || exit 1

# --- the table: every option of every command ---
PLANT_OPTS="-n=N --steps=N --seed=N --set=N --label=N --max-modules=N --max-ops=N --engine=N --lstring=W
  --curve-step=N --curve-connect=N --curve-distance=N --instances=N --no-progress=N"
CLOUD_OPTS="-N=N --points=N --max-points=N --sensor=N --scanner=N --scanners=R --density-law=N --noise=N
  --occlusion=N --no-interior=N --pattern=N --fov=N --res=N --labels=N --slices=N --cloud-seed=N --threads=N
  --ascii=N --ply-scalar-prefix=N"
declare -A TABLE
TABLE[grow]="-o=W --output=W --ascii=N --stats=N --profile=N --traits=W --animate=N --frames=P --call=N $PLANT_OPTS"
TABLE[cloud]="-o=W --output=W --stats=N --profile=N $CLOUD_OPTS $PLANT_OPTS"
TABLE[dataset]="-K=N --count=N -o=D --output=D --seed=N --format=N --jobs=N --shard=N --vary=N --images=N
  --image-size=N --force=N --stats=N --profile=N --no-shadows=N --palette=N --supersample=N --view-elevation=N
  --view-distance=N --view-jitter=N --vary-light=N --vary-background=N $CLOUD_OPTS $PLANT_OPTS"
TABLE[render]="-o=W --output=W --camera=N --eye=N --lookat=N --up=N --fov=N --size=N --color-by=N --palette=N
  --range=N --depth=W --masks=W --supersample=N --point-size=N --robot=R --no-floor=N --light=N --sky-rgb=N
  --floor-rgb=N --info=N --time=N --mp4=W --fps=N --displacement-from=N $PLANT_OPTS"
TABLE[sim]="-o=D --output=D --duration=N --dt=N --iterations=N --threads=N --solver=N --settle=N --statics=N
  --ke-tol=N --sag-free=N --stake=N --max-steps=N --segment-length=N --active-radius=N --active-center=N
  --leaves=N --leaf-segments=N --clamp=N --max-segments=N --bend-measure=N --young=N --density=N
  --break-force=N --break-moment=N --break-strain=N --no-fracture=N --gravity=N --wind=N --gust=N
  --wind-file=R --no-drag=N --stokes=N --damping=N --mass-damping=N --ground=N --collider-mesh=R
  --self-collision=N --probe=N --pull=N --move=N --ramp=N --soil=N --frames=N --fps=N --final=W --stats=N
  --batch=N --jobs=N --profile=N $PLANT_OPTS"
TABLE[sim --grow]="--grow=N --ages=N --substeps=N --dt=N --model=N --paper=N --wind-model=N --springs=N
  --integrator=N --rigid-age=N --woody-age=N --k0=N --damping=N --species=N --young=N --density=N --mor=N
  --no-breaking=N --eq8=N --no-stress-free=N --strain-limit=N --gravity=N --wind=N --gust=N --wind-file=R
  --drag=N --cd=N --light=N --gravitropism=N --soil=N --soil-method=N --clay=N --ptf=N --uproot-tilt=N
  -o=D --output=D --ply=N --final=W --stats=N --profile=N $PLANT_OPTS"
TABLE[validate]="--json=N --full=N --case=N --plant=R"
TABLE[harvest]="-o=D --output=D --stats=N --profile=N --episodes=N --jobs=N --seed=N --frames=N --duration=N --two-way=N
  --one-way=N --no-progress=N"
TABLE[export]="-o=W --output=W --name=N --pos=N --leaf-thickness=N --links-per-organ=N --damping-ratio=N --static=N --check=N --check-with=R $PLANT_OPTS"

# every option a command's --help lists is in its row
for cmd in "${!TABLE[@]}"; do
  # shellcheck disable=SC2086
  opts=$("$V" $cmd --help 2>/dev/null | grep -oE '^ +(-[a-zA-Z], )?--[a-z0-9-]+' | tr ',' '\n' | tr -d ' ' | sort -u)
  [ -n "$opts" ] || { bad "$cmd --help lists options"; continue; }
  missing=""
  for o in $opts; do
    case " ${TABLE[$cmd]} " in *[[:space:]]"$o="[RWDPN]*) ;; *) missing="$missing $o" ;; esac
  done
  if [ -z "$missing" ]; then ok "$cmd: every option classified"; else bad "$cmd: options not in the table (R, W, D, P or N):$missing"; fi
done

# --- inputs ---
TOM="$SRC/data/tomato.lpy"
"$V" grow "$TOM" -n 2 -o plant.json >/dev/null 2>&1 || bad "a plant file"
printf 't_s,vx,vy,vz\n0,1,0,0\n1,2,0,0\n' >wind.csv
printf '0.5 0 0.3\n-0.5 0 0.3\n' >scan.xyz
cp "$SRC/data/robots/gantry3.xml" robot.xml
obj=$(ls "$SRC"/data/colliders/*.obj 2>/dev/null | head -1)
[ -n "$obj" ] && cp "$obj" mesh.obj
sed "s#\"\\.\\./tomato.lpy\"#\"$T/plant.json\"#; s#\"\\.\\./robots/#\"$SRC/data/robots/#" "$SRC/data/scenes/gantry_pull.json" >scene.json
"$V" sim plant.json --duration 0.01 -o run >/dev/null 2>&1 || bad "a run folder"
"$V" sim "$SRC/data/tree.lpy" --grow --ages 2 -o grun/ >/dev/null 2>&1 || bad "a growth run folder"

n=0
# the bytes of a file, or of every file in a folder (names, sizes, contents)
content() {
  if [ -d "$1" ]; then (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r md5sum); else md5sum <"$1"; fi
}
# check CMD... (@IN@ and @OUT@ replaced): exit 2, stderr names IN and OUT, IN's bytes unchanged
check() {
  local name=$1 in=$2 out=$3
  shift 3
  local args=() a
  for a in "$@"; do a=${a//@IN@/$in}; args+=("${a//@OUT@/$out}"); done
  local before after
  before=$(content "$in")
  "${args[@]}" >"$T/out" 2>"$T/err"
  local rc=$?
  after=$(content "$in")
  if [ "$rc" -ne 2 ]; then
    bad "$name (exit $rc, expected 2: $(head -c 300 "$T/err"))"
  elif ! grep -qF "'$out'" "$T/err" || ! grep -qF "'$in'" "$T/err"; then
    bad "$name (the message does not name '$in' and '$out': $(head -c 300 "$T/err"))"
  elif [ "$before" != "$after" ]; then
    bad "$name (the input changed)"
  else
    ok "$name"
  fi
}

# two outputs that are one file: exit 2, "are one file", nothing written
collide() {
  local name=$1
  shift
  "$@" >"$T/out" 2>"$T/err"
  local rc=$?
  if [ "$rc" -eq 2 ] && grep -q "are one file" "$T/err" && [ ! -e same.json ] && [ ! -e two ]; then ok "$name"; else bad "$name (exit $rc: $(head -c 300 "$T/err"))"; fi
}

# a file read (SRC copied as INNAME) against a file written (its format's extension EXT): the same
# path and another spelling (when the extensions allow it: SAME=1), a symbolic link, a hard link
file_case() {
  local name=$1 src=$2 inname=$3 ext=$4 same=$5
  shift 5
  local d="$T/f$((n += 1))"
  mkdir -p "$d/sub" && cd "$d" || return
  cp "$T/$src" "$inname"
  if [ "$same" = 1 ]; then
    check "$name: the same path" "$inname" "$inname" "$@"
    check "$name: another spelling" "$inname" "sub/../$inname" "$@"
  fi
  ln -s "$inname" "lnk$ext" && check "$name: a symbolic link" "$inname" "lnk$ext" "$@"
  ln "$inname" "hard$ext" && check "$name: a hard link" "$inname" "hard$ext" "$@"
  cd "$T" || exit 1
}

# a file read (SRC) against a folder written, the input under a name the command writes there
# (MEMBER): in the folder, the folder spelled otherwise, a symbolic link to the folder, a hard link
# of the input in the folder
dir_case() {
  local name=$1 src=$2 member=$3
  shift 3
  local d="$T/d$((n += 1))"
  mkdir -p "$d/out" "$d/other" && cd "$d" || return
  cp "$T/$src" "out/$member"
  check "$name: in the folder" "out/$member" "out" "$@"
  check "$name: another spelling" "out/$member" "./out//" "$@"
  ln -s out lout && check "$name: a symbolic link to the folder" "out/$member" "lout" "$@"
  cp "$T/$src" "x_$member" && ln "x_$member" "other/$member" && check "$name: a hard link in the folder" "x_$member" "other" "$@"
  cd "$T" || exit 1
}

# a folder read (a run) against a folder written: the same folder, spelled otherwise, a link to it
run_dir_case() {
  local name=$1 src=$2
  shift 2
  local d="$T/r$((n += 1))"
  mkdir -p "$d" && cd "$d" || return
  cp -r "$T/$src" in
  check "$name: the same folder" "in" "in/" "$@"
  check "$name: another spelling" "in" "./in//" "$@"
  ln -s in lin && check "$name: a symbolic link" "in" "lin/" "$@"
  cd "$T" || exit 1
}

# grow: PLANT, --lstring, -o, --traits, --frames
file_case "grow PLANT as -o" plant.json p.json .json 1 "$V" grow @IN@ -o @OUT@
file_case "grow PLANT as --traits" plant.json p.json .csv 1 "$V" grow @IN@ --traits @OUT@
file_case "grow PLANT as --lstring" plant.json p.json .json 1 "$V" grow @IN@ --lstring @OUT@ --stats
cp "$TOM" m.lpy
file_case "grow .lpy as --lstring" m.lpy m.lpy .lpy 1 "$V" grow @IN@ -n 1 --lstring @OUT@ --stats
file_case "grow .lpy as -o" m.lpy m.lpy .json 0 "$V" grow @IN@ -n 1 -o @OUT@
# (the check comes before the file is read: a model named like a frame is refused whatever it holds)
mkdir -p fr && cp "$TOM" fr/f_3.json
check "grow PLANT as a --frames name" fr/f_3.json "fr/f_%d.json" "$V" grow @IN@ -n 1 --animate --frames @OUT@
check "grow PLANT as a --frames name, another spelling" fr/f_3.json "./fr//f_%d.json" "$V" grow @IN@ -n 1 --animate --frames @OUT@
ln -s fr lfr && check "grow PLANT as a --frames name, a linked folder" fr/f_3.json "lfr/f_%d.json" "$V" grow @IN@ -n 1 --animate --frames @OUT@
mkdir -p fr2 && cp "$TOM" g.lpy && ln g.lpy fr2/f_5.json && check "grow PLANT as a --frames name, a hard link" g.lpy "fr2/f_%d.json" "$V" grow @IN@ -n 1 --animate --frames @OUT@
# two outputs of one name
collide "grow --lstring and -o one file" "$V" grow "$TOM" -n 1 --lstring same.json -o same.json
collide "grow --lstring and -o one file, another spelling" "$V" grow "$TOM" -n 1 --lstring ./same.json -o "$T/same.json"
# cloud: PLANT, --scanners against -o, --lstring
file_case "cloud PLANT as -o" plant.json p.json .ply 0 "$V" cloud @IN@ -N 100 -o @OUT@
file_case "cloud --scanners as -o" scan.xyz s.xyz .xyz 1 "$V" cloud plant.json --sensor scan --scanners @IN@ -o @OUT@
file_case "cloud .lpy as --lstring" m.lpy m.lpy .lpy 1 "$V" cloud @IN@ -n 1 -N 100 --lstring @OUT@ --stats
# dataset: PLANT, --scanners against the dataset folder
dir_case "dataset PLANT in -o" plant.json item_000000.json "$V" dataset @IN@ --count 1 -N 100 -o @OUT@
dir_case "dataset --scanners in -o" scan.xyz manifest.json "$V" dataset "$T/plant.json" --sensor scan --scanners @IN@ --count 1 -o @OUT@
# render: PLANT, --robot, a run, a growth run against -o (its layers), -o DIR/, --mp4
file_case "render PLANT as -o" plant.json p.json .png 0 "$V" render @IN@ -o @OUT@ --size 32x24
cp plant.json r.png.json
check "render PLANT as the --depth sidecar" r.png.json r.png.json "$V" render @IN@ -o r.png --depth --size 32x24
file_case "render --robot as -o" robot.xml robot.xml .png 0 "$V" render "$T/plant.json" --robot @IN@ -o @OUT@ --size 32x24
for f in rod.json plant_initial.json frames.bin colliders.jsonl; do
  ln -s "run/$f" "lnk-$f.png" && check "render a run: its $f as -o, a symbolic link" "run/$f" "lnk-$f.png" "$V" render run -o @OUT@ --size 32x24
  ln "run/$f" "hard-$f.png" && check "render a run: its $f as -o, a hard link" "run/$f" "hard-$f.png" "$V" render run -o @OUT@ --size 32x24
done
ln -s run/frames.bin lnk.mp4 && check "render a run: its frames as --mp4" run/frames.bin lnk.mp4 "$V" render run --mp4 @OUT@ --size 32x24
run_dir_case "render a run as -o DIR/" run "$V" render @IN@ -o @OUT@ --size 32x24
run_dir_case "render a growth run as -o DIR/" grun "$V" render @IN@ -o @OUT@ --size 32x24
ln -s grun/age_002.json lnk2.png && check "render a growth run: an age as -o" grun/age_002.json lnk2.png "$V" render grun -o @OUT@ --size 32x24
# sim: PLANT, --wind-file, --collider-mesh against the run folder, --final, --lstring
dir_case "sim PLANT in -o" plant.json plant.json "$V" sim @IN@ --duration 0.01 -o @OUT@
dir_case "sim --wind-file in -o" wind.csv events.csv "$V" sim "$T/plant.json" --wind-file @IN@ --duration 0.01 -o @OUT@
dir_case "sim --wind-file in -o (--batch)" wind.csv rod.json "$V" sim "$T/plant.json" --wind-file @IN@ --duration 0.01 --batch 2 -o @OUT@
file_case "sim PLANT as --final" plant.json p.json .json 1 "$V" sim @IN@ --duration 0.01 --final @OUT@
file_case "sim --wind-file as --final" wind.csv w.json .json 1 "$V" sim "$T/plant.json" --wind-file @IN@ --duration 0.01 --final @OUT@
file_case "sim .lpy as --lstring" m.lpy m.lpy .lpy 1 "$V" sim @IN@ -n 1 --duration 0.01 --lstring @OUT@ --stats
if [ -f mesh.obj ]; then
  dir_case "sim --collider-mesh in -o" mesh.obj events.csv "$V" sim "$T/plant.json" --collider-mesh @IN@ --duration 0.01 -o @OUT@
  file_case "sim --collider-mesh as --final" mesh.obj c.obj .obj 1 "$V" sim "$T/plant.json" --collider-mesh @IN@ --duration 0.01 --final @OUT@
fi
collide "sim -o and --final one file" "$V" sim plant.json --duration 0.01 -o two --final two/plant.json
# sim --grow: the model, --wind-file against the growth run folder, --final
dir_case "sim --grow --wind-file in -o" wind.csv events.csv "$V" sim "$TOM" --grow --ages 1 --wind-file @IN@ -o @OUT@
dir_case "sim --grow --wind-file as an age" wind.csv age_001.json "$V" sim "$TOM" --grow --ages 1 --wind-file @IN@ -o @OUT@
file_case "sim --grow .lpy as --final" m.lpy m.lpy .json 0 "$V" sim @IN@ --grow --ages 1 --final @OUT@
file_case "sim --grow --wind-file as --final" wind.csv w.json .json 1 "$V" sim "$TOM" --grow --ages 1 --wind-file @IN@ --final @OUT@
# harvest: the scene, its plant and its robot against the run folder (one run, a batch)
dir_case "harvest SCENE in -o" scene.json summary.json "$V" harvest @IN@ --duration 0.1 -o @OUT@
dir_case "harvest SCENE in -o (--episodes)" scene.json episodes.csv "$V" harvest @IN@ --episodes 1 --duration 0.1 -o @OUT@
d="$T/h$((n += 1))"
mkdir -p "$d/out" && sed "s#\"$T/plant.json\"#\"$d/out/plant_initial.json\"#" scene.json >"$d/scene.json" && cp plant.json "$d/out/plant_initial.json"
(cd "$d" && check "harvest the scene's plant in -o" "$d/out/plant_initial.json" out "$V" harvest scene.json --duration 0.1 -o @OUT@)
sed "s#\"$SRC/data/robots/gantry3.xml\"#\"$d/out/trajectory.csv\"#" scene.json >"$d/scene2.json" && cp robot.xml "$d/out/trajectory.csv"
(cd "$d" && check "harvest the scene's robot in -o" "$d/out/trajectory.csv" out "$V" harvest scene2.json --duration 0.1 -o @OUT@)
# export: PLANT, --check-with against -o, --lstring
file_case "export PLANT as -o" plant.json p.json .urdf 0 "$V" export @IN@ -o @OUT@
file_case "export --check-with as -o" robot.xml r.xml .xml 1 "$V" export "$T/plant.json" -o @OUT@ --check-with @IN@
file_case "export .lpy as --lstring" m.lpy m.lpy .lpy 1 "$V" export @IN@ -n 1 -o e.xml --lstring @OUT@

# --- SIGINT 0.5 s into a run over an earlier run folder leaves it byte-identical ---
# a folder's names, kinds, modes and file bytes (a folder's own size and time change with any
# temporary name made and removed in it: not its bytes)
snap() { (cd "$1" && find . -printf '%y %m %s %p\n' | grep -v '^d' | sort && find . -type d | sort && content .); }
interrupt() {
  local name=$1 dir=$2
  shift 2
  local before after rc
  before=$(snap "$dir")
  "$@" >/dev/null 2>&1 &
  local pid=$!
  sleep 0.5
  kill -INT "$pid" 2>/dev/null
  wait "$pid"
  rc=$?
  after=$(snap "$dir")
  if [ "$rc" -ne 130 ]; then
    bad "$name: interrupted (exit $rc, expected 130: the run ended before 0.5 s)"
  elif [ "$before" != "$after" ]; then
    bad "$name: the earlier run folder changed ($(diff <(echo "$before") <(echo "$after") | head -5 | tr '\n' ' '))"
  else
    ok "$name: SIGINT leaves the earlier run folder byte-identical"
  fi
}
"$V" sim plant.json --duration 0.01 --frames jsonl -o s1 >/dev/null 2>&1
interrupt "sim" s1 "$V" sim "$TOM" -n 3 --duration 20 -o s1
interrupt "sim --batch" s1 "$V" sim "$TOM" -n 3 --duration 20 --batch 2 -o s1
interrupt "sim --grow" grun "$V" sim "$SRC/data/tree.lpy" --grow --ages 30 -o grun/
"$V" harvest scene.json --duration 0.05 --frames none -o h1 --no-progress >/dev/null 2>&1
sed "s#\"\\.\\./tomato.lpy\"#\"$TOM\"#; s#\"\\.\\./robots/#\"$SRC/data/robots/#" "$SRC/data/scenes/gantry_pull.json" >scene_tomato.json
interrupt "harvest" h1 "$V" harvest scene_tomato.json --duration 20 -o h1 --no-progress
"$V" render run -o fr1/ --size 32x24 >/dev/null 2>&1
interrupt "render a run into a folder" fr1 "$V" render "$T/s1" -o fr1/ --size 1600x1200 --supersample 3
"$V" render grun -o fr2/ --size 32x24 >/dev/null 2>&1
interrupt "render a growth run into a folder" fr2 "$V" render "$T/grun" -o fr2/ --size 2000x1500 --supersample 4
"$V" dataset plant.json --count 1 -N 50 -o ds1 >/dev/null 2>&1
interrupt "dataset" ds1 "$V" dataset "$TOM" --count 1 -N 3000000 --force -o ds1
mkdir -p exd && "$V" export plant.json -o exd/ex.urdf >/dev/null 2>&1
interrupt "export" exd "$V" export "$SRC/data/tree.lpy" -o exd/ex.urdf

# a run that fails half way over an earlier run folder leaves it byte-identical too
fails() {
  local name=$1 dir=$2
  shift 2
  local before after rc
  before=$(snap "$dir")
  "$@" >/dev/null 2>"$T/err"
  rc=$?
  after=$(snap "$dir")
  if [ "$rc" -eq 0 ]; then
    bad "$name: failed (exit 0)"
  elif [ "$before" != "$after" ]; then
    bad "$name: the earlier run folder changed ($(diff <(echo "$before") <(echo "$after") | head -5 | tr '\n' ' '))"
  else
    ok "$name: a failure leaves the earlier run folder byte-identical"
  fi
}
# (an earlier run of other settings, so that its ages differ from the new run's)
"$V" sim "$SRC/data/tree.lpy" --grow --ages 4 --wind 3,0,0 -o g2/ >/dev/null 2>&1 || bad "a growth run in the wind"
fails "sim --grow past --max-modules" g2 "$V" sim "$SRC/data/tree.lpy" --grow --ages 6 --max-modules 3000 -o g2/
fails "sim, unstable" s1 "$V" sim "$SRC/data/arabidopsis.lpy" -o s1 --young 1e6 --density 100 --dt 0.02 --duration 1 --wind 5,0,0 --gust 0.5,0.5 --self-collision
fails "export --check-with a missing robot" exd "$V" export plant.json -o exd/ex.xml --check-with nosuch.xml

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
