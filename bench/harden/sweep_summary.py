#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Summary of a physics sweep CSV (bench/harden/sim_sweep.c) as the Markdown tables of
# docs/reliability.md, "Numerical robustness sweep": totals, warnings by kind, outcomes by plant
# and solver, by solver and dt, and at the largest dt by Young's modulus.
# Usage: bench/harden/sweep_summary.py [CSV]   (default bench/results/sweep-2core.csv)
import csv
import sys
from collections import Counter, OrderedDict

OUTCOMES = ["clean", "retaken", "stretched", "failed", "capped"]
SOLVER = {"direct": "direct", "gs": "Gauss–Seidel"}


def table(rows, key, title):
    groups = OrderedDict()
    for r in rows:
        groups.setdefault(key(r), Counter())[r["outcome"]] += 1
    print(f"| {title} | runs | " + " | ".join(OUTCOMES) + " |")
    print("|---|---:|" + "---:|" * len(OUTCOMES))
    for k, c in groups.items():
        print(f"| {k} | {sum(c.values())} | " + " | ".join(str(c[o]) for o in OUTCOMES) + " |")
    print()


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "bench/results/sweep-2core.csv"
    rows = list(csv.DictReader(open(path)))
    kinds = [c[5:] for c in rows[0] if c.startswith("warn_")]
    steps = sum(int(r["steps"]) for r in rows)
    nonfinite = sum(int(r["nonfinite_states"]) for r in rows)
    warn = {k: sum(int(r["warn_" + k]) for r in rows) for k in kinds}
    secs = sum(float(r["seconds"]) for r in rows)
    print(f"{len(rows)} runs, {steps} steps, {secs:.0f} s of run time, **{nonfinite} non-finite states**.")
    print("Warnings summed over all runs: " + ", ".join(f"{k} {v}" for k, v in warn.items()) +
          f" ({sum(warn.values())} in all).\n")
    table(rows, lambda r: f"{r['plant']}, {SOLVER[r['solver']]}", "plant, solver")
    table(rows, lambda r: f"{SOLVER[r['solver']]}, {float(r['dt_s']):g}", "solver, dt (s)")
    dtmax = max(float(r["dt_s"]) for r in rows)
    big = sorted((r for r in rows if float(r["dt_s"]) == dtmax),
                 key=lambda r: (r["solver"], float(r["young_pa"])))
    print(f"At dt = {dtmax:g} s by Young's modulus (all plants):\n")
    table(big, lambda r: f"{SOLVER[r['solver']]}, E = {float(r['young_pa']):g} Pa", "solver, E")


if __name__ == "__main__":
    main()
