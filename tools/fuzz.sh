#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) in build-fuzz/ and runs one of them.
# Usage: tools/fuzz.sh TARGET [SECONDS]     TARGET: scene, image, cli, obj, texture or mtl; default 60 seconds
#        tools/fuzz.sh --build               only build
# The corpus grows in build-fuzz/corpus/TARGET, seeded from fuzz/corpus/TARGET (scene: scenes/).
# A crash leaves build-fuzz/crash-TARGET-* and makes the script fail: turn it into a regression
# test in the normal suite (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)  # absolute paths throughout: the cli target changes its working folder
target=${1:?usage: tools/fuzz.sh scene|image|cli|obj|texture|mtl [SECONDS] | --build}
seconds=${2:-60}

# DRT_FUZZ_BUILT=1 skips the build step; DRT_FUZZ_DIR names a build folder other than build-fuzz/
# (tools/test.sh fuzzes with its sanitizer build, which has the targets, and runs two side by side).
dir=${DRT_FUZZ_DIR:-build-fuzz}
if [ "${DRT_FUZZ_BUILT:-0}" != 1 ]; then
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    cxx=$(command -v clang++-14 || command -v clang++)
    # -O1 -g1 as for the sanitizer build in tools/test.sh: reports keep file and line, and the
    # build takes about half of -O2 -g's time.
    cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$cxx" \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DDRT_FUZZ=ON -DDRT_BUILD_TESTS=OFF -DDRT_PORTABLE=ON "${launcher[@]}" >/dev/null
    # Quiet unless it fails.
    if ! log=$(cmake --build "$dir" -j"$(nproc)" 2>&1); then
        grep -E "error" <<<"$log" >&2 || tail -20 <<<"$log" >&2
        echo "fuzz.sh: build failed" >&2
        exit 1
    fi
fi
[ "$target" = --build ] && exit 0

binary=$root/$dir/fuzz/fuzz_$target
[ -x "$binary" ] || { echo "fuzz.sh: no target '$target' (scene, image, cli, obj, texture, mtl)" >&2; exit 2; }
corpus=$root/$dir/corpus/$target
mkdir -p "$corpus"
if [ "$target" = scene ]; then
    cp -n scenes/*.xml scenes/*/*.xml "$corpus"/ 2>/dev/null || true
    dict=$root/fuzz/scene.dict
else
    cp -n fuzz/corpus/"$target"/* "$corpus"/ 2>/dev/null || true
    dict=$root/fuzz/$target.dict
fi
[ -f "$dict" ] || dict=
# -rss_limit_mb: above the largest allocation the limits allow, below what would trouble CI.
# -timeout: no input may take this long (the targets keep renders tiny).
"$binary" "$corpus" ${dict:+-dict="$dict"} -max_total_time="$seconds" -rss_limit_mb=4096 \
    -timeout=30 -print_final_stats=1 -artifact_prefix="$root/$dir/crash-$target-" 2>&1 |
    grep -E "^(#[0-9]+ *DONE|Done|stat::number_of_executed_units|stat::new_units_added)|ERROR|SUMMARY|Test unit written|crash-|timeout-|oom-|leak-|slow-unit" || true
# libFuzzer's own exit status is lost in the pipe; an artefact is the verdict. A slow unit (over
# 10 s) is named but does not fail the run: under a loaded sanitizer build one input's time varies
# several-fold, so only a timeout (30 s) fails; long hunts find slow inputs (docs/testing.md).
if compgen -G "$dir/crash-$target-slow-unit-*" >/dev/null; then
    echo "fuzz.sh: $target: slow input kept: $(ls "$dir"/crash-"$target"-slow-unit-*)" >&2
fi
failures=$(compgen -G "$dir/crash-$target-*" | grep -v -- "-slow-unit-" || true)
if [ -n "$failures" ]; then
    echo "fuzz.sh: $target found a failure: $failures" >&2
    exit 1
fi
echo "fuzz.sh: $target: no failure in ${seconds} s"
