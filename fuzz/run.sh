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
TARGETS=${*:-"fuzz_lsys fuzz_plant_json fuzz_expr fuzz_cloud fuzz_curves fuzz_frames"}
CC=${FUZZ_CC:-clang}
OUT=build-fuzz
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CFLAGS="-std=c11 -g -O1 -ffp-contract=off -Iinclude -Isrc $(pkg-config --cflags libcjson) $SAN"
LIBS="$(pkg-config --libs libcjson) -lm"

# library objects, rebuilt when the source or any header is newer
mkdir -p "$OUT/obj"
newest_h=$(ls -t include/verdant/*.h src/*/*.h fuzz/*.h | head -1)
objs=()
for src in src/core/*.c src/plant/*.c src/lsys/*.c src/geom/*.c src/cloud/*.c src/sim/*.c; do
  obj="$OUT/obj/$(basename "${src%.c}").o"
  objs+=("$obj")
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ "$newest_h" -nt "$obj" ]; then
    $CC $CFLAGS -fsanitize=fuzzer-no-link -c "$src" -o "$obj" || exit 2
  fi
done

status=0
printf '%-16s %10s %8s %8s %9s\n' target execs seconds corpus findings
for t in $TARGETS; do
  bin="$OUT/$t"
  $CC $CFLAGS -fsanitize=fuzzer "fuzz/$t.c" "${objs[@]}" $LIBS -o "$bin" || exit 2
  mkdir -p "$OUT/corpus/$t" "$OUT/findings/$t" fuzz/corpus/$t
  log="$OUT/$t.log"
  touch "$OUT/$t.stamp"
  # the first crash, leak or timeout stops the run; its input is saved in findings/<target>/
  dict=lsys.dict; [ "$t" = fuzz_plant_json ] && dict=plant_json.dict; [ "$t" = fuzz_cloud ] && dict=cloud.dict
  [ "$t" = fuzz_curves ] && dict=curves.dict
  [ "$t" = fuzz_frames ] && dict=frames.dict
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
