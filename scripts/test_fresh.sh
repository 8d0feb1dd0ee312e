#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `make test` as a fresh Debian 12 machine runs it (only what scripts/deps.sh installs, without
# --dev, and no pseudo-terminals), on a machine that has the optional parts installed: in a
# private mount namespace (util-linux's unshare; no root needed where user namespaces are
# allowed) each optional part is hidden and ctest runs on the build folder:
#   - the Python packages torch and open3d: their folders covered by one whose import raises
#     ImportError, as a missing package does;
#   - the tools check_urdf, ign, ffmpeg, pdal and PCL's pcl_*: PATH becomes a folder of links to
#     every other command;
#   - pseudo-terminals: /dev/ptmx and /dev/pts/ptmx covered by /dev/null (script fails).
# Every test must pass or be reported skipped (with its reason in its output), none fail.
#   bash scripts/test_fresh.sh [BUILD] [CTEST ARGS...]     (BUILD defaults to build)
set -eu
BUILD="${1:-build}"
shift || true
[ -f "$BUILD/CTestTestfile.cmake" ] || { echo "test_fresh: $BUILD is not a build folder (run make first)" >&2; exit 2; }
command -v unshare >/dev/null || { echo "test_fresh: needs unshare (util-linux)" >&2; exit 2; }
stub=$(mktemp -d /tmp/verdant_fresh.XXXXXX)
trap 'rm -rf "$stub"' EXIT
mkdir "$stub/pkg"
printf 'raise ImportError("hidden by scripts/test_fresh.sh (a machine without scripts/deps.sh --dev)")\n' \
  >"$stub/pkg/__init__.py"
# what to cover, found before the namespace hides it
pkgs=""
for m in torch open3d; do
  for py in /usr/bin/python3 python3; do
    d=$($py -c "import importlib.util as u; s = u.find_spec('$m'); print(s.submodule_search_locations[0] if s and s.submodule_search_locations else '')" 2>/dev/null || true)
    [ -n "$d" ] && pkgs="$pkgs $d"
  done
done
# PATH: one folder of links to every command of $PATH but the hidden tools (bash's command -v
# finds a covered file that is not executable, so the tools cannot be covered like the packages)
mkdir "$stub/bin"
IFS=: read -r -a dirs <<<"$PATH"
for d in "${dirs[@]}"; do
  [ -d "$d" ] || continue
  for f in "$d"/*; do
    n=${f##*/}
    case "$n" in check_urdf | ign | ffmpeg | pdal | pcl_*) continue ;; esac
    [ -x "$f" ] && [ ! -e "$stub/bin/$n" ] && ln -s "$f" "$stub/bin/$n"
  done
done
export VD_FRESH_STUB="$stub" VD_FRESH_PKGS="$pkgs" VD_FRESH_BUILD="$BUILD" PATH="$stub/bin"
rc=0
unshare -rm --propagation private bash -c '
set -eu
for d in $VD_FRESH_PKGS; do mount --bind "$VD_FRESH_STUB/pkg" "$d"; done
for p in /dev/ptmx /dev/pts/ptmx; do [ -e "$p" ] && mount --bind /dev/null "$p"; done
# the hiding worked, or this check proves nothing
for m in torch open3d; do
  for py in /usr/bin/python3 python3; do
    if $py -c "import $m" 2>/dev/null; then echo "test_fresh: $m still imports in $py" >&2; exit 2; fi
  done
done
for t in check_urdf ign ffmpeg pdal pcl_ply2pcd; do
  if command -v "$t" >/dev/null; then echo "test_fresh: $t still found" >&2; exit 2; fi
done
if script -qc true /dev/null >/dev/null 2>&1; then echo "test_fresh: a pseudo-terminal still opens" >&2; exit 2; fi
echo "test_fresh: hidden: torch, open3d, check_urdf, ign, ffmpeg, pdal, pcl_*, pseudo-terminals"
cd "$VD_FRESH_BUILD"
exec ctest --output-on-failure "$@"
' test_fresh "$@" || rc=$?
exit $rc
