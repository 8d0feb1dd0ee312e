#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of `verdant sim` and `verdant validate`: exit codes, errors that name what
# is wrong, the outputs (frames, rod topology, events, final plant, stats) and no partial
# output on failure. Usage: cli_sim_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_sim "$@"
# json_check NAME PYTHON-EXPRESSION-ON-d: the last run's stdout is JSON satisfying the expression
json_check() {
  if python3 -c "import json,sys; d=json.load(open('$T/out')); sys.exit(0 if ($2) else 1)" 2>/dev/null; then
    ok "$1"
  else
    bad "$1 ($(head -c 300 "$T/out"))"
  fi
}

# a small plant: two internodes, a leaf, a fruit on a pedicel with a knuckle
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

expect "sim help" 0 "$V" sim --help
expect "validate help" 0 "$V" validate --help
expect "sim without plant" 2 "$V" sim --stats
expect "sim nothing to do" 2 "$V" sim "$T/p.lpy"
expect "sim unknown option" 2 "$V" sim "$T/p.lpy" --stats --bogus
expect "sim bad dt" 2 "$V" sim "$T/p.lpy" --stats --dt -1
expect_err "bad dt named" "--dt"
expect "sim bad solver" 2 "$V" sim "$T/p.lpy" --stats --solver magic
# batches: items seeded from (--seed, i), the same bytes with any number of jobs; --jobs alone is
# a usage error
expect "sim jobs without batch" 2 "$V" sim "$T/p.lpy" --stats --jobs 2
expect "sim batch one job" 0 "$V" sim "$SRC/data/arabidopsis.lpy" --batch 3 --jobs 1 --duration 0.05 -o "$T/b1" --stats
json_check "sim batch records" "len(d['items']) == 3 and all(i['ok'] and i['steps'] == 50 for i in d['items']) and len({i['segments'] for i in d['items']}) > 1"
expect "sim batch two jobs" 0 "$V" sim "$SRC/data/arabidopsis.lpy" --batch 3 --jobs 2 --duration 0.05 -o "$T/b2"
if cmp -s "$T/b1/item_000002/plant.json" "$T/b2/item_000002/plant.json" && cmp -s "$T/b1/item_000000/events.csv" "$T/b2/item_000000/events.csv"; then
  ok "sim batch same bytes for 1 and 2 jobs"
else
  bad "sim batch same bytes for 1 and 2 jobs"
fi
expect "sim threads same bytes" 0 "$V" sim "$SRC/data/tomato.lpy" --sag-free --duration 0.03 --threads 2 --final "$T/t2.json"
expect "sim one thread" 0 "$V" sim "$SRC/data/tomato.lpy" --sag-free --duration 0.03 --threads 1 --final "$T/t1.json"
if cmp -s "$T/t1.json" "$T/t2.json"; then ok "sim 1 and 2 threads same bytes"; else bad "sim 1 and 2 threads same bytes"; fi
expect "sim bad bend measure" 2 "$V" sim "$T/p.lpy" --stats --bend-measure darboux
expect_err "bad bend measure named" "--bend-measure"
expect "sim quat bend measure" 0 "$V" sim "$T/p.lpy" --stats --bend-measure quat --duration 0.01
expect "sim bad class" 2 "$V" sim "$T/p.lpy" --stats --young bark=1e9
expect_err "bad class named" "unknown class 'bark'"
expect "sim bad young" 2 "$V" sim "$T/p.lpy" --stats --young -5
expect "sim bad vector" 2 "$V" sim "$T/p.lpy" --stats --wind 1,2
expect "sim bad probe" 2 "$V" sim "$T/p.lpy" --stats --probe 0.1:0,0,0
expect "sim bad pull" 2 "$V" sim "$T/p.lpy" --stats --pull fruit
expect "sim unknown organ" 2 "$V" sim "$T/p.lpy" --stats --pull cherry=0,0,1
expect_err "unknown organ named" "no organ 'cherry'"
expect "sim missing plant" 2 "$V" sim "$T/none.lpy" --stats
expect "sim bad poisson" 2 "$V" sim "$T/p.lpy" --stats --poisson 0.7
expect_err "bad poisson says why" "Poisson"
printf 't,vx,vy,vz\n0,0,1,0\n1,0,x,0\n' >"$T/badwind.csv"
expect "sim bad wind file" 2 "$V" sim "$T/p.lpy" --stats --wind-file "$T/badwind.csv"
expect_err "wind file line named" "badwind.csv:3:"

# stats: the documented fields
expect "sim stats" 0 "$V" sim "$T/p.lpy" --duration 0.05 --stats --profile
json_check "stats fields" "all(k in d for k in ['max_displacement','tip_displacement','kinetic_energy','events','steps_per_second','steps','time'])"
json_check "stats steps" "d['steps'] == 50 and abs(d['time'] - 0.05) < 1e-9"

# settle and sag-free
expect "sim settle" 0 "$V" sim "$T/p.lpy" --settle --stats
json_check "settled" "d['settled'] is True and d['kinetic_energy'] < 1e-6"
expect "sim sag-free" 0 "$V" sim "$T/p.lpy" --sag-free --settle --stats
json_check "sag-free stays" "d['max_displacement'] < 1e-3"
expect "sim statics" 0 "$V" sim "$T/p.lpy" --statics --stats
json_check "statics converged" "d['settled'] is True"

# outputs: frames (binary and JSON Lines), rod topology, events, final plant
expect "sim outputs" 0 "$V" sim "$T/p.lpy" --duration 0.1 --fps 100 -o "$T/run" --final "$T/final.ply"
for f in frames.bin rod.json events.csv plant.json; do
  if [ -s "$T/run/$f" ]; then ok "wrote $f"; else bad "wrote $f"; fi
done
if [ -s "$T/final.ply" ]; then ok "wrote final ply"; else bad "wrote final ply"; fi
if python3 - "$T/run" <<'PY'
import json, struct, sys
d = sys.argv[1]
rod = json.load(open(d + "/rod.json"))
b = open(d + "/frames.bin", "rb").read()
magic, ver, nn, ns, _ = struct.unpack("<8sIIII", b[:24])
assert magic == b"VDSIMFRM" and ver == 1 and nn == rod["nodes"] and ns == rod["segments"]
size = 8 + 12 * nn + 16 * ns + ns
assert (len(b) - 24) % size == 0 and (len(b) - 24) // size == 11, (len(b) - 24) / size
t0 = struct.unpack("<d", b[24:32])[0]
assert t0 == 0.0
json.load(open(d + "/plant.json"))
PY
then ok "frame layout"; else bad "frame layout"; fi
expect "sim jsonl" 0 "$V" sim "$T/p.lpy" --duration 0.02 --frames jsonl -o "$T/runj"
if python3 -c "
import json; lines = open('$T/runj/frames.jsonl').read().splitlines()
f = [json.loads(l) for l in lines]; assert len(f) >= 1 and all(k in f[0] for k in ('t','pos','quat','broken'))"; then
  ok "jsonl frames"
else
  bad "jsonl frames"
fi

# a pull on the fruit breaks its calyx once; the event is in the stats and the CSV
expect "sim pull fracture" 0 "$V" sim "$T/p.lpy" --duration 0.5 --pull fruit=0,0,-4 --ramp 0.4 -o "$T/runp" --stats
json_check "one fracture" "d['nevents'] == 1 and d['events'][0]['label'] in ('fruit', 'pedicel')"
if [ "$(wc -l <"$T/runp/events.csv")" -eq 2 ]; then ok "events csv row"; else bad "events csv row"; fi

# the README's pull in wind, with calyx joints that do not break, breaks a pedicel at its
# abscission node (by moment): in the final plant the part that came off is a piece of its own,
# no segment spans the gap, labels and instances kept
expect "tomato pull in wind" 0 "$V" sim "$SRC/data/tomato.lpy" --sag-free --duration 1 --pull fruit=0,0.5,-3 --wind 5,0,0 --break-force fruit=inf -o "$T/runw"
if python3 - "$T/runw" <<'PY'
import csv, json, math, sys
d = sys.argv[1]
a, b = json.load(open(d + "/plant_initial.json")), json.load(open(d + "/plant.json"))
events = list(csv.DictReader(open(d + "/events.csv")))
assert len(events) >= 1, events
def lengths(p):
    n, s = p["nodes"], p["segments"]
    return [math.dist(n[3 * i:3 * i + 3], n[3 * k:3 * k + 3]) for i, k in zip(s["node0"], s["node1"])]
la, lb = lengths(a), lengths(b)
assert max(l1 - 1.5 * l0 for l0, l1 in zip(la, lb)) < 1e-3, max(l1 / l0 for l0, l1 in zip(la, lb) if l0 > 0)
roots = lambda p: sum(1 for q in p["segments"]["parent"] if q < 0)
assert roots(b) == roots(a) + len(events), (roots(a), roots(b), len(events))
pairs = lambda p: {(l, i) for k in ("segments", "spheres") for l, i in zip(p[k]["label"], p[k]["instance"])}
assert pairs(a) == pairs(b)
PY
then ok "fracture pieces in plant.json"; else bad "fracture pieces in plant.json"; fi

# probes and wind run; a probe through the plant leaves no penetration
expect "sim probe" 0 "$V" sim "$T/p.lpy" --duration 0.3 --probe 0.03:0.1,0.1,0.15:-0.1,-0.1,0.15 --wind 3,0,0 --gust 0.3,0.5 --stats
json_check "probe no penetration" "d['max_penetration'] < 1e-4"

# failures leave nothing behind: an unwritable output folder
mkdir -p "$T/ro"
chmod 500 "$T/ro"
if [ "$(id -u)" -ne 0 ]; then
  expect "unwritable output" 2 "$V" sim "$T/p.lpy" --duration 0.01 -o "$T/ro/run"
else
  ok "unwritable output (skipped as root)"
fi

# mesh colliders and self-collision: a cube mesh on the tomato, no penetration; bad meshes exit 2
cat >"$T/cube.obj" <<'EOF'
# cube of half size 0.05 m, faces counter-clockwise from outside
v -0.05 -0.05 -0.05
v 0.05 -0.05 -0.05
v -0.05 0.05 -0.05
v 0.05 0.05 -0.05
v -0.05 -0.05 0.05
v 0.05 -0.05 0.05
v -0.05 0.05 0.05
v 0.05 0.05 0.05
f 1 3 4 2
f 5 6 8 7
f 1/1 2/2 6/3 5/4
f 3 7 8 4
f -8 -4 -2 -6
f 2 4 8 6
EOF
expect "sim mesh collider" 0 "$V" sim "$SRC/data/tomato.lpy" --duration 0.05 --stats --self-collision --collider-mesh "$T/cube.obj:0.08,0,0.25"
json_check "sim mesh collider contacts" "d['contacts'] > 2 and d['max_penetration'] < 1e-4 and d['warnings'] == 0"
expect "sim no self-collision" 0 "$V" sim "$SRC/data/tomato.lpy" --duration 0.02 --stats --no-self-collision --no-ground
json_check "sim no self-collision contacts" "d['contacts'] == 0"
head -9 "$T/cube.obj" >"$T/bad.obj"
echo "f 1 2 x" >>"$T/bad.obj"
expect "sim mesh bad index" 2 "$V" sim "$T/p.lpy" --stats --collider-mesh "$T/bad.obj"
expect_err "sim mesh bad index names line and column" "bad.obj:10:7: expected a vertex index"
head -14 "$T/cube.obj" >"$T/open.obj"
expect "sim mesh open" 2 "$V" sim "$T/p.lpy" --stats --collider-mesh "$T/open.obj"
expect_err "sim mesh open is named" "open.obj: .*not closed"
expect "sim mesh not obj" 2 "$V" sim "$T/p.lpy" --stats --collider-mesh "$T/cube.ply"

# validate: a subset as JSON, all passing, with the documented fields
expect "validate json" 0 "$V" validate --json --case cantilever_tip --no-progress
json_check "validate fields" "len(d) == 2 and all(set(r) >= {'name','measured','reference','error','tolerance','pass'} and r['pass'] for r in d)"
expect "validate table" 0 "$V" validate --case torsion --no-progress
expect "validate bad option" 2 "$V" validate --frobnicate
# a control check prints what it measured (issue 12, item 22): the penetration of the run without
# self-collision, against the 2 mm it must reach
expect "validate control" 0 "$V" validate --json --case no_penetration_self --no-progress
json_check "control prints its measured value" "[r for r in d if r['name'] == 'no_penetration_self_off'][0]['measured'] > 2e-3 and [r for r in d if r['name'] == 'no_penetration_self_off'][0]['reference'] == 2e-3"
# --clamp: 0 holds only the base node and its frame; a negative length is refused
expect "sim --clamp 0" 0 "$V" sim "$T/p.lpy" --clamp 0 --duration 0.05 --stats
expect "sim --clamp -1" 2 "$V" sim "$T/p.lpy" --clamp -1 --stats

# progress bars where the time goes (issue 12, item 21): settling and the timed steps, on a
# terminal only (util-linux's script gives the run one)
if have_pty "progress bar checks on a terminal"; then
  script -qc "'$V' sim '$T/p.lpy' --settle --duration 0.05 --stats" /dev/null >"$T/tty" 2>&1
  if grep -aq "settling \[#*\] [0-9]* steps" "$T/tty" && grep -aq "simulating \[#*\] 0.050 / 0.050 s simulated" "$T/tty"; then
    ok "sim progress bars on a terminal"
  else
    bad "sim progress bars on a terminal ($(tr '\r' '\n' <"$T/tty" | grep -a -m3 "ing \["))"
  fi
fi
"$V" sim "$T/p.lpy" --settle --duration 0.05 --stats >/dev/null 2>"$T/err"
if grep -q "\[" "$T/err"; then bad "no progress bar off a terminal"; else ok "no progress bar off a terminal"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
