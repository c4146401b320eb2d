#!/usr/bin/env bash
# Renders every thesis scene and prints, per scene: seconds, million rays per second by kind
# (from --stats), and peak memory (GNU time's maximum resident set size).
# Usage: bench/render-thesis.sh [--scale F] [--threads N] [--drt PATH] [extra drt options...]
# Needs GNU time (Debian package `time`: tools/install-deps.sh --bench).
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
scale=1
threads=
extra=()
while [ $# -gt 0 ]; do
    case "$1" in
        --scale) scale=$2; shift 2 ;;
        --threads) threads=$2; shift 2 ;;
        --drt) drt=$2; shift 2 ;;
        *) extra+=("$1"); shift ;;
    esac
done
[ -x "$drt" ] || { echo "render-thesis: no $drt; build first (tools/quickstart.sh)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "render-thesis: needs GNU time: tools/install-deps.sh --bench" >&2; exit 2; }
[ -n "$threads" ] && extra+=(--threads "$threads")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# One JSON number: the value after "key": in the file.
field() { grep -o "\"$1\": *[0-9.e+-]*" "$2" | head -1 | sed 's/.*: *//'; }

printf '%-10s %9s %8s %8s %8s %8s %8s %9s\n' scene seconds total camera shadow reflect refract 'peak MiB'
printf '%-10s %9s %8s %8s %8s %8s %8s %9s\n' '' '' 'Mray/s' 'Mray/s' 'Mray/s' 'Mray/s' 'Mray/s' ''
for scene in scenes/thesis/*.xml; do
    name=$(basename "$scene" .xml)
    /usr/bin/time -v -o "$out/$name.time" "$drt" "$scene" --scale "$scale" -q \
        --stats "$out/$name.json" -o "$out/$name.pfm" "${extra[@]}"
    seconds=$(field seconds "$out/$name.json")
    rss_kib=$(grep 'Maximum resident set size' "$out/$name.time" | awk '{print $NF}')
    rate() { awk -v n="$(field "$1" "$out/$name.json")" -v s="$seconds" 'BEGIN { printf "%.2f", n / s / 1e6 }'; }
    printf '%-10s %9.2f %8s %8s %8s %8s %8s %9.1f\n' "$name" "$seconds" "$(rate total)" \
        "$(rate camera)" "$(rate shadow)" "$(rate reflection)" "$(rate refraction)" \
        "$(awk -v k="$rss_kib" 'BEGIN { print k / 1024 }')"
done
