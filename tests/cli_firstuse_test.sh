#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# What a newcomer hit (issue 19, item 4), each as a check: a huge harvest batch starts at once;
# harvest errors name their cause (a missing scene, a broken relative plant path); a harvest
# without --stats says its outcome off a terminal; batch messages ("1 episode", no "//");
# render of a run refuses a picture name that is not PNG and a --time outside the run; a file
# without Axiom: warns with file:line; a progress bar leaves nothing on screen. (The quartiles:
# core.quantiles_interpolate; the engine fallback: cli_test.sh and pyengine.)
source "$(dirname "$0")/cli_lib.sh" firstuse "$@"
S="$SRC/data/scenes/mini_pick.json"

# harvest: a scene that is not there is named (it said "nothing to do")
expect "harvest: a missing scene" 2 "$V" harvest "$T/nosuch.json"
expect_err "the missing scene is named" "nosuch.json"
if grep -q "nothing to do" "$T/err"; then bad "no 'nothing to do' for a missing scene"; else ok "no 'nothing to do' for a missing scene"; fi
expect "harvest: nothing to do" 2 "$V" harvest "$S"
expect_err "nothing to do, for a good scene" "nothing to do"

# a relative plant path that does not resolve names the key, the path and the folder
mkdir "$T/sc"
sed -e 's|"\.\./tomato\.lpy"|"../nosuch.lpy"|' -e "s|\"\.\./robots/lite6\.xml\"|\"$SRC/data/robots/lite6.xml\"|" "$S" >"$T/sc/scene.json"
expect "harvest: a broken plant path" 2 "$V" harvest "$T/sc/scene.json" --stats
expect_err "plant.file named with the folder it is relative to" \
  "scene.json: plant\.file: '.*sc/\.\./nosuch\.lpy' does not exist \(.*relative path is read from the scene's folder\)"

# harvest -o RUN/ without --stats, stderr not a terminal: the outcome in one line
expect "harvest -o without --stats" 0 "$V" harvest "$S" --duration 0.05 --frames none -o "$T/run/"
expect_err "the outcome on stderr" "verdant harvest: [a-z ]+: fruit -?[0-9]+ (grasped|not grasped).*run/"

# a one-episode batch: "1 episode", and RUN/ joins without a double slash
expect "harvest: a batch of one" 0 "$V" harvest "$S" --episodes 1 --duration 0.05 -o "$T/batch/"
expect_err "1 episode, not 1 episodes" "verdant harvest: 1 episode: "
if grep -q "//" "$T/err"; then bad "no // in the summary's path ($(cat "$T/err"))"; else ok "no // in the summary's path"; fi

# a batch of ten million starts at once: its first episode within a minute (it used to check
# ten million names first, silent for minutes)
timeout 60 "$V" harvest "$S" --episodes 10000000 --duration 0.05 --no-progress -o "$T/huge" >/dev/null 2>&1
n=$(find "$T/huge/episodes" -name '*.json' 2>/dev/null | wc -l)
if [ "$n" -ge 1 ]; then ok "a huge batch starts at once ($n episodes in 60 s)"; else bad "a huge batch starts at once (no episode in 60 s)"; fi

# render of a run: -o g.jpg is not a folder of frames; --time outside the run is refused
printf 'Axiom: SetWidth(0.004) F(0.1) F(0.1)\n' >"$T/p.lpy"
expect "a short run" 0 "$V" sim "$T/p.lpy" --duration 0.1 -o "$T/simrun" --no-progress
expect "render RUN -o g.jpg" 2 "$V" render "$T/simrun" -o "$T/g.jpg"
expect_err "render says PNG or DIR/" "g\.jpg: a run is drawn as PNG"
if [ -e "$T/g.jpg" ]; then bad "no g.jpg folder made"; else ok "no g.jpg folder made"; fi
for t in -5 1e9; do
  expect "render --time $t" 2 "$V" render "$T/simrun" -o "$T/t.png" --time "$t"
  expect_err "--time $t: the run's range named" "--time .*: the run .* has frames from 0 to 0\.1 s"
done

# a file without Axiom: grows an empty plant, with a warning at file:line
printf 'derivation length: 2\nproduction:\nA --> A B\n' >"$T/noax.lpy"
expect "no Axiom: still grows" 0 "$V" grow "$T/noax.lpy" --stats
expect_err "no Axiom: warned with file:line" "noax\.lpy:1:1: warning: .*no Axiom:"
expect "an Axiom: no warning" 0 "$V" grow "$T/p.lpy" --stats
if [ -s "$T/err" ]; then bad "an Axiom: no warning ($(head -c 200 "$T/err"))"; else ok "an Axiom: no warning"; fi

# a progress bar is cleared when it ends (a terminal only)
if have_pty "progress bar cleared on a terminal"; then
  script -qc "'$V' sim '$T/p.lpy' --settle --duration 0.05 --stats" /dev/null >"$T/tty" 2>&1
  if python3 - "$T/tty" <<'PY'
import sys
d = open(sys.argv[1], "rb").read()
i = d.rfind(b"simulating [")
sys.exit(0 if i >= 0 and d.find(b"\r\x1b[K", i) > i else 1)
PY
  then ok "progress bar cleared on a terminal"; else bad "progress bar cleared on a terminal ($(tr '\r' '\n' <"$T/tty" | tail -c 200))"; fi
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
