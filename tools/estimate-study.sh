#!/usr/bin/env bash
# How honest the render's own error estimate is (docs/accuracy.md, "The image's own error
# estimate"): every scene in scenes/, every sampler, 4 to 1024 spp, the estimated RMSE against
# the true RMSE measured by drt converge against a converged reference.
#
# Usage: tools/estimate-study.sh [--build DIR] [--work DIR] [--threads N] [--size WxH]
#                                [--spp LIST] [--seeds LIST] [--samplers LIST]
#                                [--reference-spp N] [--reference-seed N] [--scenes 'GLOB ...']
#   --build DIR          where drt is built (default build/)
#   --work DIR           where references, rows and summary.md go (default build/estimate)
#   --size WxH           every scene at this size (default 48x36)
#   --spp LIST           sample counts (default 4,16,64,256,1024)
#   --seeds LIST         the renders' seeds (default 0,1)
#   --samplers LIST      (default stratified,sobol,random)
#   --reference-spp N    the references' samples (default 8192), sobol
#   --reference-seed N   the references' seed (default 1000: none of the renders' patterns)
#
# The true error is the RMSE against the reference with the reference's own (estimated) error
# taken out: true^2 = measured^2 - reference^2, since the two are independent. References and
# each scene/sampler/seed's rows are kept in WORK and not rendered again (delete them after a
# change to drt's estimate or images), so an interrupted study resumes where it stopped.
# Writes WORK/ratios.csv (every ratio) and WORK/summary.md: per scene and sampler the lowest and
# highest ratio estimated / true (at which spp and seed) and how many lie outside [0.8, 1.25].
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build
work=
threads=()
size=48x36
counts=4,16,64,256,1024
seeds=0,1
samplers=stratified,sobol,random
reference_spp=8192
reference_seed=1000
scenes="$root/scenes/thesis/*.xml $root/scenes/figures/*.xml $root/scenes/meshes/*.xml $root/scenes/study/*.xml"
while [ $# -gt 0 ]; do
    case "$1" in
        --build) build=$2; shift 2 ;;
        --work) work=$2; shift 2 ;;
        --threads) threads=(--threads "$2"); shift 2 ;;
        --size) size=$2; shift 2 ;;
        --spp) counts=$2; shift 2 ;;
        --seeds) seeds=$2; shift 2 ;;
        --samplers) samplers=$2; shift 2 ;;
        --reference-spp) reference_spp=$2; shift 2 ;;
        --reference-seed) reference_seed=$2; shift 2 ;;
        --scenes) scenes=$2; shift 2 ;;
        -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
        *) echo "estimate-study: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
work=${work:-$build/estimate}
drt=$build/drt
mkdir -p "$work/rows"
dims=(--width "${size%x*}" --height "${size#*x}")
log() { echo "[$(date +%H:%M:%S)] $*" >&2; }

tags=()
for scene in $scenes; do
    name=$(basename "$(dirname "$scene")")/$(basename "$scene" .xml)
    tag=${name//\//-}
    tags+=("$tag")
    ref=$work/ref-$tag.pfm
    if [ ! -s "$ref" ]; then
        log "$name: reference, $reference_spp spp"
        "$drt" "$scene" "${dims[@]}" "${threads[@]}" -q --sampler sobol --spp "$reference_spp" \
            --seed "$reference_seed" -o "$ref.part.pfm" --stats "$work/ref-$tag.json"
        mv "$ref.part.pfm" "$ref"
    fi
    ref_rmse=$(grep -o '"estimated_rmse": [^,]*' "$work/ref-$tag.json" | awk '{print $2}')
    for sampler in ${samplers//,/ }; do
        for seed in ${seeds//,/ }; do
            out=$work/rows/$tag-$sampler-$seed.csv
            [ -s "$out" ] && continue
            log "$name: $sampler, seed $seed"
            csv=$out.converge.csv
            "$drt" converge "$scene" "${dims[@]}" "${threads[@]}" --sampler "$sampler" \
                --seed "$seed" --spp "$counts" --reference "$ref" --csv "$csv" >/dev/null
            # spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,estimated_rmse,estimated_relmse
            awk -F, -v scene="$name" -v sampler="$sampler" -v seed="$seed" -v ref="$ref_rmse" '
                NR > 1 {
                t = $3 * $3 - ref * ref; t = t > 0 ? sqrt(t) : 0
                ratio = ($8 == "" || t == 0) ? "n/a" : sprintf("%.3f", $8 / t)
                printf "%s,%s,%s,%d,%.6g,%.6g,%s,%s\n", scene, sampler, seed, $1, $3, t,
                       ($8 == "" ? "n/a" : $8), ratio
            }' "$csv" >"$out.part"
            mv "$out.part" "$out"
            rm -f "$csv"
        done
    done
done

rows=$work/ratios.csv
echo "scene,sampler,seed,spp,rmse,true_rmse,estimated_rmse,ratio" >"$rows"
for tag in "${tags[@]}"; do
    for sampler in ${samplers//,/ }; do
        for seed in ${seeds//,/ }; do cat "$work/rows/$tag-$sampler-$seed.csv"; done
    done
done >>"$rows"

summary=$work/summary.md
{
    echo "Ratio estimated / true RMSE: lowest and highest (spp/seed), how many outside [0.8, 1.25]."
    echo
    echo "| scene | stratified | sobol | random |"
    echo "|---|---|---|---|"
    awk -F, 'NR > 1 && $8 != "n/a" {
        key = $1 SUBSEP $2; r = $8 + 0
        if (!(key in lo) || r < lo[key]) { lo[key] = r; at_lo[key] = $4 "/" $3 }
        if (!(key in hi) || r > hi[key]) { hi[key] = r; at_hi[key] = $4 "/" $3 }
        out[key] += (r < 0.8 || r > 1.25); scenes[$1] = 1
    } END {
        n = split("stratified sobol random", s, " ")
        for (scene in scenes) {
            line = "| " scene
            for (i = 1; i <= n; ++i) {
                key = scene SUBSEP s[i]
                cell = (key in lo) ? sprintf("%.2f (%s) – %.2f (%s), %d out", lo[key], at_lo[key],
                                             hi[key], at_hi[key], out[key]) : ""
                line = line " | " cell
            }
            print line " |"
        }
    }' "$rows" | sort
    echo
    echo "| sampler | ratios | lowest | highest | outside [0.8, 1.25] | n/a |"
    echo "|---|---|---|---|---|---|"
    awk -F, 'NR > 1 {
        k = $2; if ($8 == "n/a") { ++na[k]; seen[k] = 1; next }
        r = $8 + 0; ++n[k]; seen[k] = 1
        if (!(k in lo) || r < lo[k]) lo[k] = r
        if (!(k in hi) || r > hi[k]) hi[k] = r
        out[k] += (r < 0.8 || r > 1.25)
    } END {
        for (k in seen) printf "| %s | %d | %.2f | %.2f | %d | %d |\n", k, n[k], lo[k], hi[k], out[k], na[k]
    }' "$rows" | sort
    echo
    echo "Outside [0.8, 1.25]:"
    awk -F, 'NR > 1 && $8 != "n/a" && ($8 < 0.8 || $8 > 1.25) {
        printf "- %s %s %s spp seed %s: %s\n", $1, $2, $4, $3, $8 }' "$rows"
} >"$summary"
cat "$summary"
