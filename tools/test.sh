#!/usr/bin/env bash
# Builds and runs the whole test suite twice: a Release build for this machine's processor (GCC),
# then a portable ASan+UBSan build (clang); then checks that both render every scene to the same
# bits; then fuzzes every libFuzzer target briefly with the second build (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
jobs=$(nproc)

# A failing golden test adds its scene to one report page; say where it is.
run_tests() {
    if ! (cd "$1" && ctest --output-on-failure -j"$jobs"); then
        if [ -f "$1/golden-diffs/index.html" ]; then
            echo "golden-image report: $PWD/$1/golden-diffs/index.html" >&2
        fi
        exit 1
    fi
}

# The benchmarks are compiled too where Google Benchmark is installed, so that a change of an
# interface they use cannot leave them broken; they are not run here.
bench=OFF
dpkg-query -W -f='${Status}' libbenchmark-dev 2>/dev/null | grep -q "install ok installed" && bench=ON
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DDRT_BUILD_BENCH=$bench >/dev/null
cmake --build build -j"$jobs"
run_tests build

# The sanitizer build: clang with ASan+UBSan and libFuzzer's instrumentation (DRT_FUZZ), for any
# x86-64, at -O1 -g1 (the sanitizers find the same faults and reports keep file and line, at about
# half of -O2 -g's compile time). One build serves three checks: the tests under the sanitizers,
# the same bits as the Release build's from another compiler, instruction set and optimisation
# level, and the fuzz targets (docs/testing.md).
cxx=$(command -v clang++-14 || command -v clang++)
# A build-sanitize/ configured for another compiler starts afresh: CMake cannot switch a build
# folder to another compiler.
if [ -f build-sanitize/CMakeCache.txt ] &&
    ! grep -q "^CMAKE_CXX_COMPILER:.*clang" build-sanitize/CMakeCache.txt; then
    rm -rf build-sanitize
fi
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$cxx" \
    -DDRT_FUZZ=ON -DDRT_PORTABLE=ON -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" >/dev/null
cmake --build build-sanitize -j"$jobs"
run_tests build-sanitize

tools/compare-builds.sh build/drt build-sanitize/drt

# Each fuzz target for 30 s, two at a time: a minute and a half.
fuzz_pair() {
    DRT_FUZZ_DIR=build-sanitize DRT_FUZZ_BUILT=1 tools/fuzz.sh "$1" 30 &
    local first=$!
    DRT_FUZZ_DIR=build-sanitize DRT_FUZZ_BUILT=1 tools/fuzz.sh "$2" 30
    wait "$first"
}
fuzz_pair scene image
fuzz_pair cli obj
fuzz_pair texture mtl
