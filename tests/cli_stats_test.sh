#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# --stats is a contract (issue 19, item 5): the same inputs print the same bytes (timings only
# with --profile), and every key each command prints -- with --profile, so the timings too --
# and every key and column of the growth run folder is in docs/formats.md's key contract
# (tests/stats_keys.py names each key that is not).
source "$(dirname "$0")/cli_lib.sh" stats "$@"
DOC="$SRC/docs/formats.md"

# a small plant whose fruit comes off when pulled (as in cli_sim_test.sh)
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

# same NAME A B: files A and B hold the same bytes
same() {
  if cmp -s "$2" "$3"; then ok "$1: the same bytes twice"; else bad "$1: the same bytes twice ($(diff "$2" "$3" | head -c 300))"; fi
}
# documented NAME SECTION FILE...: every key of the files is in the section
documented() {
  local name="$1" section="$2"
  shift 2
  if python3 "$SRC/tests/stats_keys.py" "$DOC" "$section" "$@" >"$T/keys" 2>&1; then
    ok "$name: every key documented"
  else
    bad "$name: every key documented"
    cat "$T/keys"
  fi
}
# contract NAME SECTION CMD...: CMD --stats twice gives the same bytes; CMD --stats --profile's
# keys are documented
contract() {
  local name="$1" section="$2"
  shift 2
  expect "$name" 0 "$@" --stats && cp "$T/out" "$T/a.json"
  expect "$name again" 0 "$@" --stats && cp "$T/out" "$T/b.json"
  same "$name" "$T/a.json" "$T/b.json"
  expect "$name --profile" 0 "$@" --stats --profile && cp "$T/out" "$T/p.json"
  documented "$name" "$section" "$T/p.json"
}

contract "grow" '`verdant grow --stats`' "$V" grow "$SRC/data/tomato.lpy" --seed 2
expect "a plant file" 0 "$V" grow "$SRC/data/tomato.lpy" -n 2 -o "$T/t.json"
contract "grow plant file" '`verdant grow --stats`' "$V" grow "$T/t.json"
# any thread count: the same bytes
expect "cloud, 1 thread" 0 "$V" cloud "$SRC/data/tomato.lpy" -N 3000 --seed 1 --threads 1 --stats && cp "$T/out" "$T/c1.json"
expect "cloud, 2 threads" 0 "$V" cloud "$SRC/data/tomato.lpy" -N 3000 --seed 1 --threads 2 --stats && cp "$T/out" "$T/c2.json"
same "cloud on 1 and 2 threads" "$T/c1.json" "$T/c2.json"
contract "cloud scan" '`verdant cloud --stats`' "$V" cloud "$SRC/data/tomato.lpy" --sensor scan \
  --scanners "$SRC/data/scanners/turntable8.json" --noise 0.001
contract "sim with a fracture" '`verdant sim --stats`' "$V" sim "$T/p.lpy" --duration 0.5 --pull fruit=0,0,-4 --ramp 0.4 --no-progress
if grep -q '"cause"' "$T/p.json"; then ok "sim: a fracture event listed"; else bad "sim: a fracture event listed"; fi
contract "sim settled" '`verdant sim --stats`' "$V" sim "$T/p.lpy" --settle --duration 0.02 --no-progress
contract "sim batch" '`verdant sim --batch N --stats`' "$V" sim "$T/p.lpy" --batch 2 --duration 0.02
contract "sim --grow" '`verdant sim --grow --stats`' "$V" sim "$SRC/data/tree.lpy" --grow --ages 2 -o "$T/g/" --no-progress
documented "growth.json" 'Growth run folder: `RUN/growth.json`' "$T/g/growth.json"
documented "age files" 'Growth run folder: `RUN/age_NNN.json`' "$T/g"/age_*.json
documented "growth events.csv" 'Growth run folder: `RUN/events.csv`' "$T/g/events.csv"
contract "harvest" '`verdant harvest --stats` (and `RUN/summary.json`)' "$V" harvest "$SRC/data/scenes/mini_pick.json" \
  --duration 0.3 --no-progress
expect "harvest -o" 0 "$V" harvest "$SRC/data/scenes/mini_pick.json" --duration 0.3 --no-progress -o "$T/h1"
expect "harvest -o again" 0 "$V" harvest "$SRC/data/scenes/mini_pick.json" --duration 0.3 --no-progress -o "$T/h2"
same "harvest RUN/summary.json" "$T/h1/summary.json" "$T/h2/summary.json"
same "harvest RUN/summary.json is --stats" "$T/h1/summary.json" "$T/a.json"
for d in b1 b2; do
  expect "harvest batch $d" 0 "$V" harvest "$SRC/data/scenes/mini_pick.json" --episodes 2 --duration 0.3 --no-progress -o "$T/$d"
done
same "harvest batch summary.json" "$T/b1/summary.json" "$T/b2/summary.json"
expect "harvest batch --profile" 0 "$V" harvest "$SRC/data/scenes/mini_pick.json" --episodes 2 --duration 0.3 \
  --no-progress -o "$T/b3" --profile
documented "harvest batch" '`verdant harvest --episodes N` (`RUN/summary.json`, `--stats`)' "$T/b3/summary.json"
for d in d1 d2; do
  expect "dataset $d" 0 "$V" dataset "$SRC/data/tomato.lpy" --count 2 -N 500 --no-progress -o "$T/$d" --stats
  cp "$T/out" "$T/$d.json"
done
same "dataset" "$T/d1.json" "$T/d2.json"
expect "dataset --profile" 0 "$V" dataset "$SRC/data/tomato.lpy" --count 2 -N 500 --no-progress -o "$T/d3" --stats --profile
documented "dataset" '`verdant dataset --stats`' "$T/out"
# --profile alone has nothing to add to
expect "grow --profile without --stats" 2 "$V" grow "$SRC/data/tomato.lpy" --profile -o "$T/x.json"
expect "cloud --profile without --stats" 2 "$V" cloud "$SRC/data/tomato.lpy" --profile -o "$T/x.ply"

# the checker itself: a key printed but not documented is named
printf '{"engine": "native", "brand_new_key": 1, "organs": {"stem": {"count": 1, "odd": 2}}}\n' >"$T/new.json"
python3 "$SRC/tests/stats_keys.py" "$DOC" '`verdant grow --stats`' "$T/new.json" >"$T/keys" 2>&1
rc=$?
if [ "$rc" -eq 1 ] && grep -q "prints 'brand_new_key'" "$T/keys" && grep -q "prints 'organs.stem.odd'" "$T/keys" &&
  ! grep -q "'engine'\|'organs.stem.count'" "$T/keys"; then
  ok "an undocumented key is named"
else
  bad "an undocumented key is named (exit $rc: $(head -c 300 "$T/keys"))"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
