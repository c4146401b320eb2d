#!/usr/bin/env bash
# Whether one image's error estimate misses its true error by more than the image's own
# statistics allow (docs/accuracy.md, "The error estimate and --target-error on path scenes"):
# one scene rendered with several seeds, each render's estimated RMSE against its true RMSE
# (measured against a converged reference, the reference's own error taken out), next to the
# relative scatter of the true RMSE that the render reports (`rmse_scatter` in --stats,
# from `error_pixels`, the pixels the error sits in).
#
# Usage: tools/estimate-scatter.sh SCENE [--build DIR] [--work DIR] [--size WxH] [--spp N]
#                                 [--seeds LIST] [--sampler S] [--reference-spp N]
#   --build DIR          where drt is built (default build/)
#   --work DIR           where the reference and renders go (default build/estimate-scatter)
#   --size WxH           (default 32x24)
#   --spp N              the renders' samples (default 64)
#   --seeds LIST         (default 0,1,2,3,4,5,6,7)
#   --sampler S          (default stratified)
#   --reference-spp N    the reference's samples (default 8192; sobol, seed 1000)
#
# Prints, per seed, estimated / true and z = ln(estimated / true) / scatter, then how many ratios
# lie outside [0.8, 1.25] and the RMS of z (about 1 when the image's statistics account for the
# misses), and the true RMSE's relative deviation over the seeds against the mean reported
# scatter (which it should not exceed by much: the scatter is an estimate on the high side).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 1 ] || { sed -n '2,20p' "$0"; exit 2; }
scene=$1
shift
build=$root/build
work=
size=32x24
spp=64
seeds=0,1,2,3,4,5,6,7
sampler=stratified
reference_spp=8192
while [ $# -gt 0 ]; do
    case "$1" in
        --build) build=$2; shift 2 ;;
        --work) work=$2; shift 2 ;;
        --size) size=$2; shift 2 ;;
        --spp) spp=$2; shift 2 ;;
        --seeds) seeds=$2; shift 2 ;;
        --sampler) sampler=$2; shift 2 ;;
        --reference-spp) reference_spp=$2; shift 2 ;;
        -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
        *) echo "estimate-scatter: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
[ -f "$scene" ] || { echo "estimate-scatter: no scene '$scene'" >&2; exit 2; }
work=${work:-$build/estimate-scatter}
drt=$build/drt
mkdir -p "$work"
dims=(--width "${size%x*}" --height "${size#*x}")
json_number() { grep -o "\"$1\": [^,}]*" "$2" | awk '{print $2}'; }

tag=$(basename "$scene" .xml)-$size
ref=$work/ref-$tag-$reference_spp.pfm
if [ ! -s "$ref" ]; then
    "$drt" "$scene" "${dims[@]}" -q --sampler sobol --spp "$reference_spp" --seed 1000 \
        -o "$ref.part.pfm" --stats "$ref.json"
    mv "$ref.part.pfm" "$ref"
fi
ref_rmse=$(json_number estimated_rmse "$ref.json")

echo "$(basename "$scene") at $size, $spp spp, $sampler; reference $reference_spp spp"
echo "seed  estimated  true       est/true  error_pixels  scatter z"
for seed in ${seeds//,/ }; do
    out=$work/$tag-$sampler-$spp-$seed
    "$drt" "$scene" "${dims[@]}" -q --sampler "$sampler" --spp "$spp" --seed "$seed" \
        -o "$out.pfm" --stats "$out.json"
    measured=$("$drt" compare "$out.pfm" "$ref" | grep -o 'rmse=[^ ]*' | cut -d= -f2)
    awk -v seed="$seed" -v m="$measured" -v ref="$ref_rmse" \
        -v est="$(json_number estimated_rmse "$out.json")" \
        -v pixels="$(json_number error_pixels "$out.json")" \
        -v scatter="$(json_number rmse_scatter "$out.json")" 'BEGIN {
        t = m * m - ref * ref; t = t > 0 ? sqrt(t) : 0
        r = t > 0 ? est / t : 0
        z = (r > 0 && scatter > 0) ? log(r) / scatter : 0
        printf "%-5s %-10.4g %-10.4g %-9.3f %-13.1f %-7.3f %.2f\n", seed, est, t, r, pixels, scatter, z
    }'
done | tee "$work/$tag-$sampler-$spp.txt"
awk '{ r = $4; z = $7; n++; out += (r < 0.8 || r > 1.25); sz += z * z
       t += $3; tt += $3 * $3; sc += $6 }
     END { m = t / n; d = tt / n - m * m; d = d > 0 ? sqrt(d) / m : 0
           printf "%d of %d ratios outside [0.8, 1.25]; RMS of z %.2f\n", out, n, sqrt(sz / n)
           printf "true RMSE over the seeds: relative deviation %.3f; reported scatter %.3f\n", d, sc / n }' \
    "$work/$tag-$sampler-$spp.txt"
