#!/usr/bin/env bash
# The cost per ray of the path integrator against the distributed one (issue 31): the same
# scene rendered by both, in turn, round after round: Test1 (scenes/thesis/test1.xml, and the
# same with Integrator="path"; its Ambient is then ignored) and the Cornell box
# (scenes/gi/cornell-box.xml, and the same with the distributed integrator, where the lamp
# lights the walls by shadow rays only). Rays per CPU second (user + system, GNU time; one
# thread by default: on a shared machine CPU time drifts less than wall-clock time): --stats'
# rays.total over the CPU seconds less the share spent on the error estimate's extra samples
# (estimate_cost, whose rays rays.total leaves out): seconds / (1 + estimate_cost).
# Usage: bench/integrators.sh [--drt PATH] [--scale F] [--spp N] [--rounds N] [--threads N]
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
scale=0.25
spp=16
rounds=3
threads=1
while [ $# -gt 0 ]; do
    case "$1" in
        --drt) drt=$2; shift 2 ;;
        --scale) scale=$2; shift 2 ;;
        --spp) spp=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --threads) threads=$2; shift 2 ;;
        *) echo "integrators: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$drt" ] || { echo "integrators: no $drt; build first" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
sed 's/<Render /<Render Integrator="path" /' scenes/thesis/test1.xml >"$out/test1-path.xml"
cp scenes/thesis/test1.xml "$out/test1-distributed.xml"
cp scenes/gi/cornell-box.xml "$out/cornell-path.xml"
sed 's/ Integrator="path"//' scenes/gi/cornell-box.xml >"$out/cornell-distributed.xml"
echo "integrators: scale $scale, $spp spp, $threads threads, $rounds rounds"
echo "$(date -u '+%F %T') UTC, $(git rev-parse --short HEAD), load $(cut -d' ' -f1-3 /proc/loadavg)"
for round in $(seq "$rounds"); do
    for s in test1 cornell; do
        for i in distributed path; do
            /usr/bin/time -f "%U %S" -o "$out/time" "$drt" "$out/$s-$i.xml" --scale "$scale" --spp "$spp" --threads "$threads" -q \
                -o "$out/img.pfm" --stats "$out/stats.json" 2>/dev/null
            { awk '{ printf "%.3f ", $1 + $2 }' "$out/time"; tr -d '\n ' <"$out/stats.json"; } |
                sed 's/^\([0-9.]*\) .*"rays":{\([^}]*\)}.*"estimate_cost":\([^,}]*\).*/\1 \2 \3/' |
                awk -v s="$s" -v i="$i" -v r="$round" '{
                    n = split($2, kv, ","); line = ""; total = 0
                    for (k = 1; k <= n; k++) { split(kv[k], p, ":"); gsub(/"/, "", p[1]); c[p[1]] = p[2] }
                    $1 = $1 / (1 + $3)
                    printf "%s %s %s %.3f %.2f camera %d shadow %d diffuse %d reflection %d refraction %d\n",
                        r, s, i, $1, c["total"] / $1 / 1e6, c["camera"], c["shadow"], c["diffuse"] + 0,
                        c["reflection"], c["refraction"] }' | tee -a "$out/runs"
        done
    done
done
echo "round scene integrator CPU-seconds-without-estimate Mrays/s ... (above); medians:"
awk '{ k = $2 " " $3; v[k] = v[k] " " $5 }
     END { for (k in v) { n = split(substr(v[k], 2), a, " "); for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j - 1] > a[j]; j--) { x = a[j]; a[j] = a[j - 1]; a[j - 1] = x }
                          m[k] = (n % 2) ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
                          printf "%-20s %.2f Mrays/s (%.2f-%.2f)\n", k, m[k], a[1], a[n] }
           for (s in m) { split(s, p, " "); if (p[2] == "path") printf "%s: path / distributed rays per second %.3f\n", p[1], m[s] / m[p[1] " distributed"] } }' "$out/runs"
