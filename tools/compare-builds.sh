#!/usr/bin/env bash
# Whether two drt binaries render every scene in scenes/ to bit-identical .pfm images, e.g. the
# Release build for this machine's processor against the portable sanitizer build: rounding
# must not depend on the instruction set, the optimisation level or the instrumentation.
# Usage: tools/compare-builds.sh A B [--scale F]   (default scale 0.1, a few seconds per scene
# under the sanitizers). tools/compare-modes.sh compares the render modes, statistics,
# checkpoints and messages too.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: tools/compare-builds.sh A B [--scale F]" >&2; exit 2; }
a=$1 b=$2
scale=0.1
[ "${3:-}" = "--scale" ] && scale=$4
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
differ=0 count=0
for scene in scenes/*.xml scenes/*/*.xml; do
    "$a" "$scene" --scale "$scale" -q -o "$out/a.pfm"
    "$b" "$scene" --scale "$scale" -q -o "$out/b.pfm"
    count=$((count + 1))
    if ! cmp -s "$out/a.pfm" "$out/b.pfm"; then
        echo "compare-builds: $scene differs between $a and $b" >&2
        differ=$((differ + 1))
    fi
done
echo "compare-builds: $((count - differ)) of $count scenes bit-identical ($a, $b)"
[ "$differ" -eq 0 ]
