#!/usr/bin/env bash
# How honest the render's own error estimate is (docs/accuracy.md, "The image's own error
# estimate"): every scene in scenes/, every sampler, 4 to 1024 spp, the estimated RMSE against
# the true RMSE measured by drt converge against a converged reference.
#
# Usage: tools/estimate-study.sh [--build DIR] [--work DIR] [--threads N] [--size WxH]
#                                [--spp LIST] [--reference-spp N] [--scenes 'GLOB ...']
#   --build DIR          where drt is built (default build/)
#   --work DIR           where references, CSV files and summary.md go (default build/estimate)
#   --size WxH           every scene at this size (default 48x36)
#   --spp LIST           sample counts (default 4,16,64,256,1024)
#   --reference-spp N    the references' samples (default 16384), sobol, seed + 1
#
# The true error is the RMSE against the reference with the reference's own (estimated) error
# taken out: true^2 = measured^2 - reference^2, since the two are independent. Writes
# WORK/summary.md: the worst ratio estimated / true per scene and sampler, and every ratio.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build
work=
threads=()
size=48x36
counts=4,16,64,256,1024
reference_spp=16384
scenes="$root/scenes/thesis/*.xml $root/scenes/figures/*.xml $root/scenes/meshes/*.xml $root/scenes/study/*.xml"
while [ $# -gt 0 ]; do
    case "$1" in
        --build) build=$2; shift 2 ;;
        --work) work=$2; shift 2 ;;
        --threads) threads=(--threads "$2"); shift 2 ;;
        --size) size=$2; shift 2 ;;
        --spp) counts=$2; shift 2 ;;
        --reference-spp) reference_spp=$2; shift 2 ;;
        --scenes) scenes=$2; shift 2 ;;
        -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
        *) echo "estimate-study: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
work=${work:-$build/estimate}
drt=$build/drt
mkdir -p "$work"
dims=(--width "${size%x*}" --height "${size#*x}")
log() { echo "[$(date +%H:%M:%S)] $*" >&2; }

rows=$work/ratios.csv
echo "scene,sampler,spp,rmse,true_rmse,estimated_rmse,ratio" >"$rows"
for scene in $scenes; do
    name=$(basename "$(dirname "$scene")")/$(basename "$scene" .xml)
    tag=${name//\//-}
    ref=$work/ref-$tag.pfm
    if [ ! -s "$ref" ]; then
        log "$name: reference, $reference_spp spp"
        seed=$(grep -o 'Seed="[0-9]*"' "$scene" | grep -o '[0-9]*' || echo 0)
        "$drt" "$scene" "${dims[@]}" "${threads[@]}" -q --sampler sobol --spp "$reference_spp" \
            --seed $((seed + 1)) -o "$ref" --stats "$work/ref-$tag.json"
    fi
    ref_rmse=$(grep -o '"estimated_rmse": [^,]*' "$work/ref-$tag.json" | awk '{print $2}')
    for sampler in stratified sobol random; do
        log "$name: $sampler"
        csv=$work/$tag-$sampler.csv
        "$drt" converge "$scene" "${dims[@]}" "${threads[@]}" --sampler "$sampler" \
            --spp "$counts" --reference "$ref" --csv "$csv" >/dev/null
        # spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,estimated_rmse,estimated_relmse
        awk -F, -v scene="$name" -v sampler="$sampler" -v ref="$ref_rmse" 'NR > 1 {
            t = $3 * $3 - ref * ref; t = t > 0 ? sqrt(t) : 0
            ratio = ($8 == "" || t == 0) ? "n/a" : sprintf("%.3f", $8 / t)
            printf "%s,%s,%d,%.6g,%.6g,%s,%s\n", scene, sampler, $1, $3, t, ($8 == "" ? "n/a" : $8), ratio
        }' "$csv" >>"$rows"
    done
done

summary=$work/summary.md
{
    echo "| scene | stratified | sobol | random |"
    echo "|---|---|---|---|"
    # The ratio furthest from 1 (in log) per scene and sampler, with its spp.
    awk -F, 'NR > 1 && $7 != "n/a" {
        key = $1 SUBSEP $2; l = log($7); if (l < 0) l = -l
        if (!(key in worst) || l > worst[key]) { worst[key] = l; text[key] = sprintf("%.2f (%d)", $7, $3) }
        scenes[$1] = 1
    } END {
        n = split("stratified sobol random", s, " ")
        for (scene in scenes) {
            line = "| " scene
            for (i = 1; i <= n; ++i) line = line " | " text[scene, s[i]]
            print line " |"
        }
    }' "$rows" | sort
    echo
    awk -F, 'NR > 1 && $7 != "n/a" { l = log($7); if (l < 0) l = -l; ++all; if (l > log(1.25)) ++out }
        END { printf "%d of %d ratios outside [0.8, 1.25]\n", out, all }' "$rows"
} >"$summary"
cat "$summary"
