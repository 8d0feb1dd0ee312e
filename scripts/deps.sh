#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian packages verdant needs, when missing. As root it runs apt-get itself;
# otherwise it prints the exact command and fails.
set -eu
# build and test: cmake make gcc pkg-config; JSON: libcjson-dev; PNG: libpng-dev;
# robot simulation: libmujoco-dev (+ libqhull-dev, which its CMake package names); tests: python3;
# headless rendering: EGL and GL headers (libegl-dev, libgl-dev), the EGL loader (libegl1), Mesa's
# EGL and its software/DRI drivers (libegl-mesa0, libgl1-mesa-dri); dataset checksums (SHA-256):
# nettle-dev; the Python package (python/): python3-dev, python3-numpy, python3-pytest for its
# tests, python3-setuptools and python3-venv for `pip install ./python` (offline); the L-system
# Python engine: embedded CPython (libpython3.11-dev), numpy, pandas and scipy for the models that
# import them (L-Py models read tables with pandas and fit curves with scipy)
need=(cmake make gcc pkg-config libcjson-dev libpng-dev libmujoco-dev libqhull-dev python3
  libegl-dev libgl-dev libegl1 libegl-mesa0 libgl1-mesa-dri nettle-dev
  python3-dev python3-numpy python3-pytest python3-setuptools python3-venv libpython3.11-dev
  python3-pandas python3-scipy)
# --dev adds the tools of CI's hardening runs: clang with libFuzzer (make fuzz, fuzz-smoke),
# clang-tidy and cppcheck (make lint); and the Python package's optional peers, so that CI runs
# their tests: python3-torch (verdant.torch's DataLoader test) and python3-open3d (to_open3d, the
# Open3D peer of make bench); about 3 minutes of installing on 2 busy cores, 0.5 GB; and the
# robot-format checkers that `verdant export`'s tests use when installed: check_urdf
# (liburdfdom-tools) and `ign sdf -k` (ignition-tools with libsdformat-dev's command plugin)
if [ "${1:-}" = "--dev" ]; then
  need+=(clang libclang-rt-14-dev clang-tidy cppcheck python3-torch python3-open3d
    liburdfdom-tools ignition-tools libsdformat-dev)
fi
missing=()
for p in "${need[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
cmd="apt-get install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "verdant needs these Debian packages: ${missing[*]}" >&2
  echo "run as root:  apt-get update && $cmd" >&2
  exit 1
fi
echo "installing: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null
$cmd >/dev/null
