#!/usr/bin/env bash
# Installs what is missing, builds drt (Release) and renders the default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target drt
build/drt scenes/example.xml -o build/example.png
echo "rendered: $(pwd)/build/example.png"
