#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Build the libFuzzer targets with clang into build-fuzz/ and run each for SECONDS on its
# corpus. Usage: fuzz/run.sh SECONDS [target...]   (called by `make fuzz` and `make fuzz-smoke`)
#
# The library sources are compiled directly (the CMake build is not touched). Inputs found
# during a run go to build-fuzz/corpus/<target> (fuzz/corpus/<target> is only read); crashes,
# leaks and timeouts go to build-fuzz/findings/<target>/. Exit status 1 when anything was found.
set -u
cd "$(dirname "$0")/.."
SECONDS_PER=${1:-30}
shift || true
# every fuzz/fuzz_*.c is a target unless some are named
TARGETS=${*:-$(cd fuzz && ls fuzz_*.c | sed 's/\.c$//' | tr '\n' ' ')}
CC=${FUZZ_CC:-clang}
OUT=build-fuzz
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
# lsys's Python engine: CPython's headers and library, the shim compiled in (build-fuzz/gen); the
# targets run the native engine only (fuzz input is never executed as Python)
mkdir -p "$OUT/gen"
cmake -DDIR=src/lsys/py/lpyshim -DOUT="$OUT/gen/lpyshim.h" -DNAME=lpyshim_files -P cmake/embed_package.cmake || exit 2
PYINC=$(pkg-config --cflags-only-I python3-embed | sed 's/-I/-isystem /g')
CFLAGS="-std=c11 -g -O1 -ffp-contract=off -Iinclude -Isrc -I$OUT/gen $PYINC $(pkg-config --cflags libcjson) $SAN"
LIBS="$(pkg-config --libs libcjson) $(pkg-config --libs python3-embed) -lm"

# library objects, rebuilt when the source or any header is newer (on every core at once)
mkdir -p "$OUT/obj"
newest_h=$(ls -t include/verdant/*.h src/*/*.h src/lsys/py/*.h fuzz/*.h "$OUT/gen/lpyshim.h" | head -1)
objs=()
jobs=$(nproc 2>/dev/null || echo 2)
# (the robot module only for its scene parser: MuJoCo is not linked)
for src in src/core/*.c src/plant/*.c src/lsys/*.c src/lsys/py/*.c src/geom/*.c src/collide/*.c src/cloud/*.c src/phys/*.c src/sim/*.c src/mss/*.c src/robot/robot_scene.c; do
  obj="$OUT/obj/$(basename "${src%.c}").o"
  objs+=("$obj")
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ "$newest_h" -nt "$obj" ]; then
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
    # the direct solver's inlined lane kernels take clang 14 over 12 minutes at -O1 with ASan and
    # UBSan together (4 s at -O0); no fuzz target reaches them
    opt=; [ "$src" = src/sim/sim_direct.c ] && opt=-O0
    $CC $CFLAGS $opt -fsanitize=fuzzer-no-link -c "$src" -o "$obj" &
  fi
done
fail=0
for p in $(jobs -rp); do wait "$p" || fail=1; done
wait || true
for o in "${objs[@]}"; do [ -f "$o" ] || fail=1; done
[ $fail -eq 0 ] || exit 2

status=0
# CPython's own allocations (fuzz_pysrc compiles the inputs) are not findings: tests/lsan.supp
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
printf '%-16s %10s %8s %8s %9s\n' target execs seconds corpus findings
for t in $TARGETS; do
  bin="$OUT/$t"
  $CC $CFLAGS -fsanitize=fuzzer "fuzz/$t.c" "${objs[@]}" $LIBS -o "$bin" || exit 2
  mkdir -p "$OUT/corpus/$t" "$OUT/findings/$t" fuzz/corpus/$t
  log="$OUT/$t.log"
  touch "$OUT/$t.stamp"
  # the first crash, leak or timeout stops the run; its input is saved in findings/<target>/
  # the dictionary fuzz/<name>.dict of fuzz_<name>, else the L-Py one (fuzz_expr)
  dict=lsys.dict; [ -f "fuzz/${t#fuzz_}.dict" ] && dict="${t#fuzz_}.dict"
  "$bin" -max_len=4096 -timeout=5 -rss_limit_mb=2048 -max_total_time="$SECONDS_PER" \
    -dict="fuzz/$dict" -print_final_stats=1 -artifact_prefix="$OUT/findings/$t/" \
    "$OUT/corpus/$t" "fuzz/corpus/$t" >"$log" 2>&1
  rc=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  ncorp=$(find "$OUT/corpus/$t" "fuzz/corpus/$t" -type f | wc -l)
  nfind=$(find "$OUT/findings/$t" -type f -newer "$OUT/$t.stamp" | wc -l)
  printf '%-16s %10s %8s %8s %9s\n' "$t" "${execs:-?}" "$SECONDS_PER" "$ncorp" "$nfind"
  if [ $rc -ne 0 ] || [ "$nfind" -ne 0 ]; then
    status=1
    grep -m3 -E 'ERROR|runtime error|fuzz:' "$log" | sed 's/^/    /'
    echo "    log: $log, findings: $OUT/findings/$t/"
  fi
done
exit $status
