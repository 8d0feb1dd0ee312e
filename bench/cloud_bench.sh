#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs bench/cloud_bench.py with a Python that has Open3D when one is installed (Debian's
# python3-open3d lives in /usr/bin/python3's path); installs nothing.
# Usage: cloud_bench.sh VERDANT_BINARY [--quick] [--reps R] [--dataset-count K]
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
py=python3
for p in python3 /usr/bin/python3; do
  if "$p" -c "import open3d" >/dev/null 2>&1; then py="$p"; break; fi
done
exec "$py" "$here/cloud_bench.py" "$@"
