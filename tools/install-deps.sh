#!/usr/bin/env bash
# Installs the Debian 12 packages drt needs to build and test; does nothing when all are present.
# Usage: tools/install-deps.sh [--study] [--bench] [extra-package ...]
#   --study  also gnuplot-nox, which tools/accuracy-study.sh needs to draw its plots, and python3
#            for tools/allocation-bound.py
#   --bench  also libbenchmark-dev, povray, time, libembree-dev, blender and python3, which bench/ needs
#            (docs/performance.md)
set -euo pipefail

# openexr (exrheader) and chromium (a headless browser loading the regression reports) are for the
# tests; clang-14 compiles the sanitizer build and its fuzz targets, clang-format-14 checks the
# sources' layout; Open MPI: drt runs under mpirun across processes and machines (docs/usage.md).
packages=(g++ cmake make pkg-config libtinyxml2-dev libstb-dev libcli11-dev libopenexr-dev
          libgtest-dev openexr chromium clang-14 libclang-rt-14-dev clang-format-14 libopenmpi-dev
          openmpi-bin)
for arg in "$@"; do
    case "$arg" in
        --study) packages+=(gnuplot-nox python3) ;;
        --bench) packages+=(libbenchmark-dev povray time libembree-dev blender python3) ;;
        *) packages+=("$arg") ;;
    esac
done
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "installing: ${missing[*]}" >&2
as_root=()
[ "$(id -u)" -eq 0 ] || as_root=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
