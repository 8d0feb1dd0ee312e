#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `verdant harvest` with targets that are not there (issue 19 item 4, issue 20 item 4): a fruit id
# the plant does not have exits 2 listing the fruit ids there are, before any output is written;
# an unreachable fruit is an outcome whose message names the fruit and its distance; in a batch
# both are outcomes with their reason in the table, and the batch runs to its end.
# Usage: cli_harvest_targets_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_harvest_targets "$@"

# the mini scene with its paths made absolute and JSON spliced in
scene() {  # scene OUT 'python expression editing d'
  python3 - "$SRC/data/scenes/mini_pick.json" "$1" "$2" <<'PY'
import json, os, sys
src, out, edit = sys.argv[1:]
d = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
d["plant"]["file"] = os.path.normpath(os.path.join(base, d["plant"]["file"]))
d["robot"]["mjcf"] = os.path.normpath(os.path.join(base, d["robot"]["mjcf"]))
exec(edit)
json.dump(d, open(out, "w"))
PY
}

scene "$T/nosuch.json" 'd["target"] = {"fruit": 9999}; d["episodes"].pop("target"); d["duration"] = 1'
expect "fruit 9999: exit 2" 2 "$V" harvest "$T/nosuch.json" -o "$T/r1" --frames none --no-progress
expect_err "fruit 9999: names the id and the fruits there are" "no fruit with instance 9999 \(its fruits: [0-9]+(, [0-9]+)*\)"
[ ! -e "$T/r1" ] && ok "fruit 9999: no run folder" || bad "fruit 9999: no run folder ($(ls "$T/r1"))"

scene "$T/far.json" 'd["robot"]["base"]["pos"] = [3.0, 0.0, 0.05]; d["duration"] = 1'
expect "far base: an outcome, exit 0" 0 "$V" harvest "$T/far.json" --stats --frames none --no-progress
expect_err "far base: names the nearest fruit and its distance" "the nearest, fruit [0-9]+, is [0-9.]+ m from the robot's base"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(not (d['reason'] == 'no reachable fruit' and 'fruit' in d['detail']))" "$T/out" &&
  ok "far base: reason and detail in the summary" || bad "far base: reason and detail in the summary ($(head -c 300 "$T/out"))"

# batches: missing and unreachable targets are rows of the table, the batch runs to the end
expect "batch, fruit 9999" 0 "$V" harvest "$T/nosuch.json" --episodes 2 --jobs 2 -o "$T/b1" --no-progress
[ "$(grep -c ',no such fruit$' "$T/b1/episodes.csv")" = 2 ] && ok "batch, fruit 9999: two 'no such fruit' rows" ||
  bad "batch, fruit 9999: two 'no such fruit' rows ($(cat "$T/b1/episodes.csv"))"
expect "batch, far base" 0 "$V" harvest "$T/far.json" --episodes 2 --jobs 2 -o "$T/b2" --no-progress
[ "$(grep -c ',no reachable fruit$' "$T/b2/episodes.csv")" = 2 ] && ok "batch, far base: two 'no reachable fruit' rows" ||
  bad "batch, far base: two 'no reachable fruit' rows ($(cat "$T/b2/episodes.csv"))"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
