#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The numerical robustness sweep of docs/reliability.md, sized for a 40-minute budget on one
# core (25 minutes of run time on the 2-core VM): the full grid on arabidopsis (both solvers)
# and tomato (direct solver), the tree on the E and rho corners, Gauss-Seidel on the tomato's
# corners; 20 steps per run, each run capped at 30 wall seconds. The slices below are in the
# order they first ran (the first five, then the extension).
# Usage: bench/harden/sweep_2core.sh [BIN] [CSV]   (defaults build/verdant_bench_sweep,
# bench/results/sweep-2core.csv); every row is flushed as its run ends.
set -euo pipefail
bin=${1:-build/verdant_bench_sweep}
csv=${2:-bench/results/sweep-2core.csv}
common=(--steps 20 --max-seconds 30 --csv "$csv")
rm -f "$csv"
# arabidopsis: E 1e6..1e11 x rho 100..1500 x dt 1e-4..1e-2 x iterations 1,10,100 (216 runs)
"$bin" "${common[@]}" --plant arabidopsis --solver direct
# tomato: E and rho extremes, every dt and iteration count (36 runs)
"$bin" "${common[@]}" --append --plant tomato --solver direct --young 1e6,1e11 --density 100,1500
# tree (sigma 0.1 m, the costliest): E and rho extremes at dt 1e-4 and 1e-2, 1 and 10 iterations (16 runs)
"$bin" "${common[@]}" --append --plant tree --solver direct --young 1e6,1e11 --density 100,1500 \
  --dt 1e-4,1e-2 --iterations 1,10
# Gauss-Seidel: arabidopsis at E 1e6, 1e8, 1e11 and rho extremes (54 runs), tomato corners (16 runs)
"$bin" "${common[@]}" --append --plant arabidopsis --solver gs --young 1e6,1e8,1e11 --density 100,1500
"$bin" "${common[@]}" --append --plant tomato --solver gs --young 1e6,1e11 --density 100,1500 \
  --dt 1e-4,1e-2 --iterations 1,100
# extension: the rest of the arabidopsis grid with Gauss-Seidel (144 runs)
"$bin" "${common[@]}" --append --plant arabidopsis --solver gs --young 1e7,1e9,1e10
"$bin" "${common[@]}" --append --plant arabidopsis --solver gs --young 1e6,1e8,1e11 --density 500,1000
# the rest of the tomato grid, direct solver (180 runs)
"$bin" "${common[@]}" --append --plant tomato --solver direct --young 1e7,1e8,1e9,1e10
"$bin" "${common[@]}" --append --plant tomato --solver direct --young 1e6,1e11 --density 500,1000
# the tree at dt 1e-3, and with 100 iterations (16 runs)
"$bin" "${common[@]}" --append --plant tree --solver direct --young 1e6,1e11 --density 100,1500 \
  --dt 1e-3 --iterations 1,10
"$bin" "${common[@]}" --append --plant tree --solver direct --young 1e6,1e11 --density 100,1500 \
  --dt 1e-4,1e-2 --iterations 100
