#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of `verdant sim --grow` (growth with physics between the age steps) and of
# the soil for `verdant sim`: exit codes, errors that name what is wrong, the run folder
# (snapshots with stress, events, index), --stats, PLY with per-vertex stress, determinism, and
# `verdant render RUN/` of a growth run. Usage: cli_growth_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_growth "$@"
PY=/usr/bin/python3
json_check() {
  if $PY -c "import json,sys; d=json.load(open('$T/out')); sys.exit(0 if ($2) else 1)" 2>/dev/null; then
    ok "$1"
  else
    bad "$1 ($(head -c 300 "$T/out"))"
  fi
}
TREE="$SRC/data/tree.lpy"

expect "grow help" 0 "$V" sim --grow --help
expect "grow nothing to do" 2 "$V" sim "$TREE" --grow
expect "grow needs an lpy" 2 "$V" sim "$T/p.json" --grow --stats
expect_err "lpy needed named" "needs an .lpy"
expect "grow bad model" 2 "$V" sim "$TREE" --grow --stats --model spring
expect_err "bad model named" "--model"
expect "grow zero substeps" 2 "$V" sim "$TREE" --grow --stats --substeps 0
expect_err "zero substeps named" "--substeps"
expect "grow negative density" 2 "$V" sim "$TREE" --grow --stats --density 1000,-900
expect_err "density named" "--density"
expect "grow bad soil" 2 "$V" sim "$TREE" --grow --stats --soil mud
expect_err "bad soil named" "--soil"
expect "grow bad species" 2 "$V" sim "$TREE" --grow --stats --species oak
expect_err "species listed" "hopea-odorata"
expect "grow light inside the tree" 2 "$V" sim "$TREE" --grow --stats --ages 2 --substeps 2 --light 0,0,0.5
expect_err "light inside named" "light point .* inside the plant"
expect "grow bad gravitropism" 2 "$V" sim "$TREE" --grow --stats --gravitropism up
expect "sim bad soil" 2 "$V" sim "$TREE" --stats --soil mud

# the issue's command, shortened: a rooted tree under gravity and wind, stress and breaks
expect "grow mrl wind stats" 0 "$V" sim "$TREE" --grow --model mrl --wind 15,0,0 --ages 4 --stats
json_check "stats fields" "all(k in d for k in ['height','max_displacement','max_stress','broken_branches','uprooted','collapsed','momentum_error','events'])"
json_check "grown without collapse" "d['ages'] == 4 and not d['collapsed'] and d['height'] > 2 and d['max_stress'] > 0"
json_check "momentum kept" "d['momentum_error'] < 1e-12"
json_check "rigid part" "d['rigid_nodes'] > 0 and d['model'] == 'mrl'"

# a run folder: a snapshot per age with stress, events, the index
expect "grow run folder" 0 "$V" sim "$TREE" --grow --model mss --ages 3 --substeps 10 --wind 8,0,0 --ply -o "$T/run"
for f in growth.json age_000.json age_001.json age_002.json age_003.json age_003.ply events.csv plant.json; do
  [ -f "$T/run/$f" ] && ok "run has $f" || bad "run lacks $f"
done
if $PY - "$T/run" <<'PYEOF'
import json, sys, math
d = sys.argv[1]
idx = json.load(open(d + "/growth.json"))
assert idx["format"] == "verdant-growth" and idx["version"] == 1 and idx["ages"] == 3
assert [s["age"] for s in idx["snapshots"]] == [0, 1, 2, 3]
p = json.load(open(d + "/age_003.json"))
st = p["stress"]
assert st["unit"] == "Pa" and len(st["segment"]) == len(p["segments"]["node0"]) and len(st["node"]) * 3 == len(p["nodes"])
vals = [v for v in st["segment"] if v is not None]
assert len(vals) > 20 and all(v >= 0 for v in vals) and max(vals) > 1e4
PYEOF
then ok "snapshot stress and index"; else bad "snapshot stress and index"; fi
head -c 2000 "$T/run/age_003.ply" | grep -q "property float stress" && ok "ply stress property" || bad "ply stress property"

# the same seed gives the same bytes
expect "grow again" 0 "$V" sim "$TREE" --grow --model mss --ages 3 --substeps 10 --wind 8,0,0 -o "$T/run2"
cmp -s "$T/run/age_003.json" "$T/run2/age_003.json" && ok "deterministic snapshot" || bad "deterministic snapshot"

# the paper's own choices, the rods, soils
expect "grow paper ml" 0 "$V" sim "$TREE" --grow --model mss --paper --ages 3 --substeps 20 --stats
json_check "paper ml ran" "d['ages'] == 3"
expect "grow stress without breaking" 0 "$V" sim "$TREE" --grow --model mss --paper --ages 3 --substeps 20 --no-breaking --stats
json_check "stress without breaking" "d['max_stress'] > 0 and d['broken_branches'] == 0 and not d['diverged']"
# the seed's eq. 5 with eq. 3 on its own species: a new bud on a heavy node diverges (reported)
expect "grow paper hopea diverges" 0 "$V" sim "$SRC/data/hopea.lpy" --grow --model mss --paper --species hopea-odorata --ages 3 --no-breaking --stats
json_check "divergence reported" "d['diverged'] and d['collapsed']"
expect "grow rods" 0 "$V" sim "$TREE" --grow --model rods --ages 3 --substeps 10 --stats
json_check "rods grown" "d['model'] == 'rods' and d['height'] > 1.5 and not d['collapsed']"
expect "grow soil loam" 0 "$V" sim "$TREE" --grow --model mrl --soil loam --ages 3 --substeps 10 --stats
json_check "loam holds" "not d['uprooted'] and d['height'] > 1.5"
# the soil's anchorage in 15 m/s wind: loam (method 2) stands, loam by eq. 12 gives way and the
# tree is uprooted (an event), collapsed against its drawn height
expect "grow wind loam" 0 "$V" sim "$TREE" --grow --model mrl --soil loam --wind 15,0,0 --ages 3 --stats
json_check "wind loam stands" "not d['uprooted'] and not d['anchorage_failed'] and 0 < d['anchorage_load'] < 0.01 and not d['collapsed'] and d['height'] > 0.8 * d['drawn_height']"
expect "grow wind pang" 0 "$V" sim "$TREE" --grow --model mrl --soil loam --soil-method pang --wind 15,0,0 --ages 3 --stats
json_check "wind pang uproots" "d['uprooted'] and d['anchorage_failed'] and d['collapsed'] and [e['kind'] for e in d['events']][:2] == ['anchorage', 'uproot']"
expect "grow bastien" 0 "$V" sim "$TREE" --grow --model mss --gravitropism bastien --ages 3 --substeps 10 --stats
expect "grow hopea" 0 "$V" sim "$SRC/data/hopea.lpy" --grow --model mrl --species hopea-odorata --ages 12 --substeps 5 --stats
json_check "hopea grown" "d['ages'] == 12 and d['height'] > 6 and not d['collapsed'] and not d['uprooted']"
expect "sim soil rods" 0 "$V" sim "$TREE" --soil loam --duration 0.05 --stats
json_check "rods in soil stand" "d['max_displacement'] < 0.5"

# the closed forms in verdant validate
expect "validate mass-spring" 0 "$V" validate --case mss_ --no-progress
expect "validate rigid" 0 "$V" validate --case rigid --no-progress
expect "validate bastien" 0 "$V" validate --case bastien --no-progress
expect "validate growth momentum" 0 "$V" validate --case growth_momentum --json --no-progress
json_check "validate json" "len(d) == 2 and all(r['pass'] for r in d)"
expect "validate grown stem" 0 "$V" validate --case growth_stem --json --no-progress
json_check "grown stem sags as Euler-Bernoulli" "len(d) == 4 and all(r['pass'] for r in d)"

# options that do not apply are errors naming the option and why; order never matters (issue
# 19 item 4, issue 26 defect 4)
expect "soil method without a soil" 2 "$V" sim "$TREE" --grow --stats --ages 1 --soil-method pang
expect_err "soil method named" "--soil-method does not apply.*--soil"
for opt in "--clay 30" "--organic 2" "--water 0.3" "--bulk-density 1.3" "--poisson 0.3" "--uproot-tilt 20"; do
  expect "$opt without a soil" 2 "$V" sim "$TREE" --grow --stats --ages 1 $opt
  expect_err "$opt named" "${opt%% *} does not apply"
done
expect "clay with eq. 12" 2 "$V" sim "$TREE" --grow --stats --ages 1 --soil loam --soil-method pang --clay 30
expect_err "clay with pang named" "--clay does not apply.*eq. 12"
expect "poisson with method 2" 2 "$V" sim "$TREE" --grow --stats --ages 1 --soil loam --poisson 0.3
expect "rigid age with mss" 2 "$V" sim "$TREE" --grow --stats --ages 1 --model mss --rigid-age 2
expect_err "rigid age named" "--rigid-age does not apply.*--model mrl"
expect "eq8 with rods" 2 "$V" sim "$TREE" --grow --stats --ages 1 --model rods --eq8 paper
expect "k0 without paper springs" 2 "$V" sim "$TREE" --grow --stats --ages 1 --k0 1e3,1e4
expect_err "k0 named" "--k0 does not apply.*--springs paper"
expect "k0 with paper springs" 0 "$V" sim "$TREE" --grow --stats --ages 1 --substeps 2 --springs paper --k0 1e3,1e4
expect "young with paper springs" 2 "$V" sim "$TREE" --grow --stats --ages 1 --springs paper --young 1e9,1e10
for opt in "--paper" "--springs paper" "--integrator eq3" "--damping 0.5" "--strain-limit 0" "--light 5,0,3" "--gravitropism sine" "--wind-model paper" "--drag stokes"; do
  expect "rods refuse $opt" 2 "$V" sim "$TREE" --grow --stats --ages 1 --model rods $opt
  expect_err "rods $opt named" "${opt%% *} does not apply"
done
expect "rods refuse drag none in wind" 2 "$V" sim "$TREE" --grow --stats --ages 1 --model rods --wind 10,0,0 --drag none
expect "rods drag none without wind" 0 "$V" sim "$TREE" --grow --stats --ages 1 --substeps 2 --model rods --drag none
# order: clay before or after the soil preset, species before or after --young, --paper anywhere
expect "clay after soil" 0 "$V" sim "$TREE" --grow --stats --ages 2 --substeps 5 --soil loam --clay 40
cp "$T/out" "$T/clay_after.json"
expect "clay before soil" 0 "$V" sim "$TREE" --grow --stats --ages 2 --substeps 5 --clay 40 --soil loam
# --stats without --profile is the same bytes for the same inputs
if cmp -s "$T/clay_after.json" "$T/out"; then ok "soil options in any order"; else bad "soil options in any order"; fi
expect "young after species" 0 "$V" sim "$TREE" --grow --stats --ages 1 --substeps 5 --model rods --species hopea-odorata --young 1e9,5e9
cp "$T/out" "$T/sp_after.json"
expect "young before species" 0 "$V" sim "$TREE" --grow --stats --ages 1 --substeps 5 --model rods --young 1e9,5e9 --species hopea-odorata
# --stats without --profile is the same bytes for the same inputs
if cmp -s "$T/sp_after.json" "$T/out"; then ok "species options in any order"; else bad "species options in any order"; fi
# the rods take the species: Hopea's wood is lighter than the generic one
expect "rods generic" 0 "$V" sim "$TREE" --grow --stats --ages 2 --substeps 2 --model rods
cp "$T/out" "$T/rods_generic.json"
expect "rods hopea" 0 "$V" sim "$TREE" --grow --stats --ages 2 --substeps 2 --model rods --species hopea-odorata --no-breaking
if $PY -c "import json,sys; a=json.load(open('$T/rods_generic.json')); b=json.load(open('$T/out')); sys.exit(0 if b['total_mass'] < a['total_mass'] and b['broken_branches'] == 0 else 1)"; then ok "rods take the species"; else bad "rods take the species"; fi

# issue 26 defect 8: the growth bench's --help prints its usage, runs nothing, writes no CSV
B="$(dirname "$V")/verdant_bench_growth"
if [ -x "$B" ]; then
  csv="$SRC/bench/results/growth-2core.csv"
  before=$(sha256sum < "$csv" 2>/dev/null)
  expect "bench growth help" 0 "$B" --help
  grep -q "usage: verdant_bench_growth" "$T/out" && ok "bench help is usage" || bad "bench help is usage"
  [ "$(sha256sum < "$csv" 2>/dev/null)" = "$before" ] && ok "bench help keeps the CSV" || bad "bench help rewrote the CSV"
  expect "bench growth bad argument" 2 "$B" --frobnicate
else
  echo "skip: verdant_bench_growth not built"
fi

# pictures of the ages
if "$V" render --help >/dev/null 2>&1; then
  expect "render growth run" 0 "$V" render "$T/run" -o "$T/last.png" --size 160x120 --color-by stress
  [ -s "$T/last.png" ] && ok "render last age" || bad "render last age"
  expect "render growth ages" 0 "$V" render "$T/run" -o "$T/ages/" --size 120x90
  [ -f "$T/ages/age_003.png" ] && ok "render every age" || bad "render every age"
  expect "render snapshot stress" 0 "$V" render "$T/run/age_002.json" -o "$T/s2.png" --size 120x90 --color-by stress
fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
