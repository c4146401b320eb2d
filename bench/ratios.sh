#!/usr/bin/env bash
# The ratios issue #5 asks for, measured side by side in one run (renders alternate, so a noisy
# machine slows both sides of each ratio alike; each ratio is of medians over the rounds):
#   threads: Test1 on 1 thread against 2 threads (want >= 1.85x);
#   motion:  seconds per camera ray of 1,000 moving spheres against 10 (want <= 3x);
#   memory:  peak resident memory of Test1 at its full 800 x 600 (want < 64 MiB).
# Usage: bench/ratios.sh [--scale F] [--rounds N] [--drt PATH]   (--scale applies to Test1)
# Needs GNU time (Debian package `time`: tools/install-deps.sh --bench).
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
scale=0.5
rounds=3
while [ $# -gt 0 ]; do
    case "$1" in
        --scale) scale=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --drt) drt=$2; shift 2 ;;
        *) echo "ratios: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$drt" ] || { echo "ratios: no $drt; build first (tools/quickstart.sh)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "ratios: needs GNU time: tools/install-deps.sh --bench" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
bench/spheres.sh 10 >"$out/spheres10.xml"
bench/spheres.sh 1000 >"$out/spheres1000.xml"

field() { grep -o "\"$1\": *[0-9.e+-]*" "$2" | head -1 | sed 's/.*: *//'; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
# Seconds drt reports for a render, and seconds per camera ray.
seconds() { "$drt" "$@" -q --stats "$out/s.json" -o "$out/x.pfm"; field seconds "$out/s.json"; }
per_ray() {
    "$drt" "$@" -q --stats "$out/s.json" -o "$out/x.pfm"
    awk -v s="$(field seconds "$out/s.json")" -v n="$(field camera "$out/s.json")" \
        'BEGIN { printf "%.4g", s / n }'
}

one=() two=() few=() many=()
for round in $(seq "$rounds"); do
    one+=("$(seconds scenes/thesis/test1.xml --scale "$scale" --threads 1)")
    two+=("$(seconds scenes/thesis/test1.xml --scale "$scale" --threads 2)")
    few+=("$(per_ray "$out/spheres10.xml")")
    many+=("$(per_ray "$out/spheres1000.xml")")
    echo "round $round: test1 x$scale 1 thread ${one[-1]} s, 2 threads ${two[-1]} s;" \
         "per camera ray 10 spheres ${few[-1]} s, 1000 spheres ${many[-1]} s"
done
/usr/bin/time -v -o "$out/time.txt" "$drt" scenes/thesis/test1.xml -q -o "$out/full.pfm"
peak=$(grep 'Maximum resident set size' "$out/time.txt" | awk '{ printf "%.1f", $NF / 1024 }')
awk -v a="$(printf '%s\n' "${one[@]}" | median)" -v b="$(printf '%s\n' "${two[@]}" | median)" \
    -v c="$(printf '%s\n' "${few[@]}" | median)" -v d="$(printf '%s\n' "${many[@]}" | median)" \
    -v m="$peak" 'BEGIN {
        printf "threads: 2 threads are %.2fx as fast as 1 (want >= 1.85)\n", a / b
        printf "motion: 1000 moving spheres cost %.2fx per camera ray what 10 cost (want <= 3)\n", d / c
        printf "memory: Test1 at 800x600 peaks at %.1f MiB (want < 64)\n", m
    }'
