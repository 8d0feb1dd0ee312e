#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of `verdant harvest` on the bundled tomato scenes (issue 10, "Done when"): the
# pull grasps the target and detaches it at a named site with a pedicel force inside the published
# 0.58-2.46 N (calyx) or 5-8 N (abscission node); bend and twist detach too, the bend with less
# force than the pull; the second robot (the gantry) pulls. Frames are off (--frames none).
# Usage: cli_harvest_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" cli_harvest "$@"

for m in pull bend twist; do
  expect "harvest $m" 0 "$V" harvest "$SRC/data/scenes/tomato_$m.json" -o "$T/$m" --frames none --stats --no-progress
  cp "$T/out" "$T/$m.json"
done
# the second robot (a three-axis gantry, data/robots/gantry3.xml) pulls too
expect "harvest gantry" 0 "$V" harvest "$SRC/data/scenes/gantry_pull.json" --frames none --stats --no-progress
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(not (d['grasped'] and d['detached'] and d['site'] == 'calyx' and 0.58 <= d['pedicel_force'] <= 2.46))" "$T/out" &&
  ok "gantry: calyx in the published range" || bad "gantry: calyx in the published range ($(head -c 400 "$T/out"))"
python3 - "$T" <<'PY' && ok "bundled scenes: sites and forces" || bad "bundled scenes: sites and forces"
import json, sys
t = sys.argv[1]
r = {m: json.load(open(f"{t}/{m}.json")) for m in ("pull", "bend", "twist")}
bad = []
for m, d in r.items():
    if not (d["grasped"] and d["detached"] and d["site"] in ("calyx", "abscission")):
        bad.append(f"{m}: grasped {d['grasped']} detached {d['detached']} site {d['site']} ({d['reason']})")
    if json.load(open(f"{t}/{m}/summary.json"))["site"] != d["site"]:
        bad.append(f"{m}: summary.json and --stats differ")
p = r["pull"]
lo, hi = (0.58, 2.46) if p["site"] == "calyx" else (5.0, 8.0)
if not lo <= p["pedicel_force"] <= hi:
    bad.append(f"pull: pedicel force {p['pedicel_force']:.3f} N outside {lo}-{hi} N at the {p['site']}")
if not p["max_pull_force"] >= p["pull_force"] - 1e-12:
    bad.append(f"pull: max_pull_force {p['max_pull_force']} below pull_force {p['pull_force']}")
if r["bend"]["detached"] and not r["bend"]["pedicel_force"] < p["pedicel_force"]:
    bad.append(f"bend {r['bend']['pedicel_force']:.3f} N not below pull {p['pedicel_force']:.3f} N")
print("\n".join(bad) or "pull %.3f N at the %s, bend %.3f N, twist %.3f N" % (
    p["pedicel_force"], p["site"], r["bend"]["pedicel_force"], r["twist"]["pedicel_force"]))
sys.exit(1 if bad else 0)
PY
for f in summary.json events.csv trajectory.csv; do
  [ -s "$T/pull/$f" ] && ok "pull wrote $f" || bad "pull wrote $f"
done
grep -q ',detach,' "$T/pull/events.csv" && ok "events: detach" || bad "events: detach"
# forces.csv: every plant step of the last 0.5 s before the break, ending with the fracture's load
python3 - "$T" <<'PY' && ok "forces.csv: plant steps up to the break" || bad "forces.csv: plant steps up to the break"
import csv, json, sys
t = sys.argv[1]
s = json.load(open(f"{t}/pull/summary.json"))
rows = list(csv.DictReader(open(f"{t}/pull/forces.csv")))
times = [float(r["time_s"]) for r in rows]
steps = [b - a for a, b in zip(times, times[1:])]
last = rows[-1]
col = "calyx_force_N" if s["site"] == "calyx" else "abscission_force_N"
bad = []
if not rows or last["broke"] != "1" or sum(r["broke"] == "1" for r in rows) != 1:
    bad.append("the last row, and only it, is the break")
if steps and not (max(steps) < 1.5 * min(steps) and max(steps) <= 0.002):
    bad.append(f"rows every plant step ({min(steps)}-{max(steps)} s)")
if not times[-1] - times[0] <= 0.5 + 1e-9:
    bad.append(f"span {times[-1] - times[0]} s over 0.5 s")
if abs(float(last[col]) - s["pedicel_force"]) > 1e-4 * max(1.0, s["pedicel_force"]):
    bad.append(f"break row {last[col]} N against the summary's {s['pedicel_force']} N")
print("\n".join(bad) or f"{len(rows)} rows over {times[-1] - times[0]:.3f} s, {col} {last[col]} N at the break")
sys.exit(1 if bad else 0)
PY

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
