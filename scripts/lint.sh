#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Static analysis (`make lint`): clang-tidy with the checks of .clang-tidy and cppcheck over every
# .c in src/ and cli/, with the compile flags of the CMake build (compile_commands.json of a
# configure-only build in build-lint/). Any finding fails the run (exit 1); a missing tool exits 2.
# `scripts/lint.sh FILE.c ...` checks only the files named (a quick check before a commit);
# `scripts/lint.sh --changed` the .c files of src/ and cli/ that differ from main.
# Needs the Debian packages clang-tidy and cppcheck. docs/reliability.md, "Static analysis".
set -u
cd "$(dirname "$0")/.."
root=$PWD

# The output layer (docs/reliability.md, "One output layer"): every file a command writes goes
# through vd_outfile / vd_outdir_make (src/core/core_file.c), which hand it to the CLI's layer
# (cli/cli_paths.c). Anywhere else, a call that creates, replaces or removes a file or folder
# by name is a finding: fopen/freopen with a mode that writes, open/openat without O_RDONLY,
# creat, mkdir, mkdtemp, mkstemp, tmpfile, rename, link, symlink, unlink, remove, rmdir,
# truncate. Comments and string literals are not searched. `scripts/lint.sh --outputs [FILE.c ...]`
# runs only this check (no tools needed; exit 1 on a finding).
output_allowed=(
  src/core/core_file.c       # the library's writer: temporary name, then the guard or a rename
  cli/cli_paths.c            # the CLI's output layer: declarations, commit, rollback on signals
  src/robot/robot_validate.c # `verdant validate`: a scratch robot in a private mkdtemp folder,
                             # removed before it returns; never an output
  src/robot/robot_export_check.c # `verdant validate --case export_flex`: an exported beam in a
                             # private mkdtemp folder, removed before it returns; never an output
)
output_check() {
  local calls='(open|openat|creat|mkdir|mkdirat|mkdtemp|mkstemp|mkostemp|tmpfile|rename|renameat|link|linkat|symlink|unlink|unlinkat|remove|rmdir|truncate|ftruncate)'
  local f a hits found=0
  for f in "$@"; do
    for a in "${output_allowed[@]}"; do [ "$f" = "$a" ] && continue 2; done
    hits=$({
      sed -E -e 's://.*$::' -e 's/"([^"\\]|\\.)*"/""/g' "$f" | grep -nE "(^|[^.>_[:alnum:]])$calls[[:space:]]*\(" |
        grep -vE "(^|[^_[:alnum:]])open(at)?[[:space:]]*\(.*O_RDONLY"
      sed -E -e 's://.*$::' "$f" | grep -nE "(^|[^.>_[:alnum:]])f(re)?open[[:space:]]*\([^;]*\"[^\"]*[wa+][^\"]*\""
    } | sort -n -u)
    if [ -n "$hits" ]; then
      found=1
      while IFS= read -r h; do
        echo "$f:${h%%:*}: a file written outside the output layer (use vd_outfile_open / vd_outdir_make; docs/reliability.md): ${h#*:}"
      done <<<"$hits"
    fi
  done
  return $found
}
if [ "${1:-}" = "--outputs" ]; then
  shift
  if [ $# -eq 0 ]; then mapfile -t ofiles < <(find src cli python/src -name '*.c' | sort); else ofiles=("$@"); fi
  output_check "${ofiles[@]}" && echo "lint: outputs: every file is written through the output layer (${#ofiles[@]} files)" >&2
  exit $?
fi

out=${LINT_BUILD:-build-lint}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}
for tool in clang-tidy cppcheck cmake; do
  command -v "$tool" >/dev/null || { echo "lint: $tool not found (Debian: apt-get install clang-tidy cppcheck)" >&2; exit 2; }
done

# the compile commands: configure only, nothing is built
if [ ! -f "$out/compile_commands.json" ] || [ CMakeLists.txt -nt "$out/compile_commands.json" ]; then
  cmake -S . -B "$out" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >/dev/null || exit 2
fi
if [ "${1:-}" = "--changed" ]; then
  mapfile -t files < <({ git diff --name-only main -- src cli; git ls-files --others --exclude-standard src cli; } |
    grep '\.c$' | sort -u | while read -r f; do [ -f "$f" ] && echo "$f"; done)
  [ ${#files[@]} -gt 0 ] || { echo "lint: no changed .c files" >&2; exit 0; }
elif [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(find src cli -name '*.c' | sort)
fi
filters=()
if [ $# -gt 0 ]; then
  for f in "${files[@]}"; do filters+=(--file-filter="$f" --file-filter="$root/$f"); done
else
  filters=(--file-filter="src/*" --file-filter="cli/*" --file-filter="$root/src/*" --file-filter="$root/cli/*")
fi
start=$(date +%s)
fail=0

# the output layer first (a moment, no tools)
echo "lint: outputs through the output layer" >&2
output_check "${files[@]}" || fail=1

# clang-tidy: one file per process, $jobs at a time; the notes it prints on stderr go away
echo "lint: clang-tidy $(clang-tidy --version | sed -n 's/.*version \([0-9.]*\).*/\1/p') on ${#files[@]} files, $jobs jobs" >&2
printf '%s\n' "${files[@]}" |
  xargs -P "$jobs" -n 1 bash -c 'clang-tidy -p "$0" --quiet "$1" 2>&1 |
    grep -v "warnings\? generated\.$\|warnings\? treated as errors\.$"; exit "${PIPESTATUS[0]}"' "$out" ||
  fail=1

# cppcheck: the same flags and defines, through the compile database. One check is off:
# invalidPointerCast flags every typed array carved out of a one-allocation char block
# (vd_model, vd_data, vd_sim_model: STYLE.md "sizes first, then arrays in one allocation"),
# whose offsets are aligned for their types.
echo "lint: $(cppcheck --version) on src/ and cli/" >&2
mkdir -p "$out/cppcheck"
cppcheck --project="$out/compile_commands.json" "${filters[@]}" \
  --cppcheck-build-dir="$out/cppcheck" --enable=warning,performance,portability --std=c11 --inline-suppr \
  --suppress=invalidPointerCast --error-exitcode=1 -j "$jobs" --quiet --template='{file}:{line}:{column}: {severity}: {message} [{id}]' ||
  fail=1

# the module dependency rules (docs/architecture.md, scripts/check_includes.py)
python3 scripts/check_includes.py . || fail=1

echo "lint: $([ $fail = 0 ] && echo clean || echo FINDINGS) in $(($(date +%s) - start)) s" >&2
exit $fail
