#!/usr/bin/env bash
# The race with POV-Ray 3.7 on Test1 at matched work: bench/test1.pov against
# scenes/thesis/test1.xml, both at 800 x 600 on 2 threads, with 82 camera rays per pixel
# (POV-Ray +AM1 +A0.0 +R9; drt --spp 82) and 9 shadow rays per light (POV-Ray 3 x 3 area
# lights; drt --shadow-rays 18 shared by the two lights). Renders alternate, POV-Ray then drt,
# for each round, so both see the same machine; the ratio is of the median wall-clock times.
# Usage: bench/race.sh [--scale F] [--rounds N] [--threads N] [--drt PATH]
# --scale renders both at F times the size (same framing) for a quick check.
# Needs POV-Ray 3.7 (Debian package `povray`: tools/install-deps.sh --bench).
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
scale=1
rounds=2
threads=2
while [ $# -gt 0 ]; do
    case "$1" in
        --scale) scale=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --threads) threads=$2; shift 2 ;;
        --drt) drt=$2; shift 2 ;;
        *) echo "race: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$drt" ] || { echo "race: no $drt; build first (tools/quickstart.sh)" >&2; exit 2; }
command -v povray >/dev/null || { echo "race: needs povray: tools/install-deps.sh --bench" >&2; exit 2; }
width=$(awk -v s="$scale" 'BEGIN { printf "%d", 800 * s + 0.5 }')
height=$(awk -v s="$scale" 'BEGIN { printf "%d", 600 * s + 0.5 }')
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
pov=$(realpath bench/test1.pov)
scene=$(realpath scenes/thesis/test1.xml)
drt=$(realpath "$drt")

now() { date +%s.%N; }
median() { sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "race: Test1 at ${width}x${height}, $threads threads, $rounds rounds"
pov_times=() drt_times=()
for round in $(seq "$rounds"); do
    # POV-Ray writes only under its working directory by default, hence the cd.
    start=$(now)
    (cd "$out" && povray +I"$pov" +Opov.png +W"$width" +H"$height" +AM1 +A0.0 +R9 \
        +WT"$threads" -D -GA 2>pov.log) || { cat "$out/pov.log" >&2; exit 1; }
    pov_times+=("$(awk -v a="$start" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')")
    start=$(now)
    "$drt" "$scene" --scale "$scale" --spp 82 --shadow-rays 18 --threads "$threads" -q \
        -o "$out/drt.png"
    drt_times+=("$(awk -v a="$start" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')")
    echo "round $round: povray ${pov_times[-1]} s, drt ${drt_times[-1]} s"
done
pov_median=$(printf '%s\n' "${pov_times[@]}" | median)
drt_median=$(printf '%s\n' "${drt_times[@]}" | median)
awk -v p="$pov_median" -v d="$drt_median" \
    'BEGIN { printf "median: povray %.2f s, drt %.2f s; drt is %.1fx as fast\n", p, d, p / d }'
