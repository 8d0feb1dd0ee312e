#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Peak memory against the size of the work, per command (docs/reliability.md, "Resource
# limits"): derivations (modules), clouds (points), simulations (rod segments), datasets (items).
# Each run's peak resident set comes from GNU time (%M, KiB); a least-squares line through the
# points gives the bytes per unit and the fixed part, and the largest relative deviation from
# the line says whether the growth is linear.
# Usage: bench/harden/peak_rss.sh VERDANT_BINARY [CSV]   (default bench/results/memory-2core.csv)
set -u
V="$1"
SRC="$(cd "$(dirname "$0")/../.." && pwd)"
CSV="${2:-$SRC/bench/results/memory-2core.csv}"
T=$(mktemp -d /tmp/verdant_rss.XXXXXX)
trap 'rm -rf "$T"' EXIT
[ -x /usr/bin/time ] || { echo "needs GNU time (/usr/bin/time)"; exit 1; }

echo "command,unit,size,peak_rss_kib,seconds" >"$CSV"
# run CMD..., record the size read by SIZE_CMD from its stdout (python expression on d = JSON)
measure() {
  local cmd="$1" unit="$2" expr="$3"
  shift 3
  /usr/bin/time -f "%M %e" -o "$T/time" "$@" >"$T/out" 2>"$T/err" || { echo "failed: $* ($(head -c 200 "$T/err"))"; return; }
  local size
  size=$(python3 -c "import json,sys; d=json.load(open('$T/out')); print($expr)")
  read -r kib secs <"$T/time"
  echo "$cmd,$unit,$size,$kib,$secs" >>"$CSV"
  printf '%-8s %-9s %12s  %9s KiB  %6s s\n' "$cmd" "$unit" "$size" "$kib" "$secs"
}

# derivations: a binary branching grammar, 2^(n+1) modules after n steps
cat >"$T/branch.lpy" <<'EOF'
Axiom: A
production:
A --> F(0.01) [ +(30) A ] [ -(30) A ]
interpretation:
endlsystem
EOF
for n in 12 14 15 16 17 18; do
  measure grow modules "d['modules']" "$V" grow "$T/branch.lpy" -n $n --stats --no-progress
done
# clouds: the tomato at more and more points (one thread: the output block dominates)
for n in 250000 1000000 2000000 4000000 8000000; do
  measure cloud points "d['points']" "$V" cloud "$SRC/data/tomato.lpy" -N $n --threads 1 --stats -o "$T/c.ply"
done
# simulations: the tree at finer and finer rod segments, 10 steps
for s in 0.4 0.2 0.1 0.05 0.025; do
  measure sim segments "d['segments']" "$V" sim "$SRC/data/tree.lpy" --segment-length $s --duration 0.01 --stats \
    --no-progress
done
# datasets: more and more items of 2000 points (the manifest is streamed)
for k in 10 100 400 1600; do
  rm -rf "$T/ds"
  measure dataset items "d['made']" "$V" dataset "$SRC/data/arabidopsis.lpy" --count $k -N 2000 -o "$T/ds" --stats \
    --no-progress
done

# the fit per command: peak = a + b * size
python3 - "$CSV" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("\ncommand   unit       bytes/unit    fixed (MiB)   largest deviation from the line")
for cmd in dict.fromkeys(r["command"] for r in rows):
    pts = [(float(r["size"]), 1024.0 * float(r["peak_rss_kib"])) for r in rows if r["command"] == cmd]
    n = len(pts)
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    b = sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx else 0.0
    a = my - b * mx
    dev = max(abs(p[1] - (a + b * p[0])) / p[1] for p in pts)
    unit = [r["unit"] for r in rows if r["command"] == cmd][0]
    print(f"{cmd:9s} {unit:9s} {b:12.1f}   {a / 2**20:10.1f}     {100 * dev:5.1f} %")
PY
