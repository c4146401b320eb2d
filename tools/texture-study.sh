#!/usr/bin/env bash
# The texture-filtering study of docs/accuracy.md ("Image texture filtering"): renders
# scenes/assets/tiled-floor.xml at 4 samples per pixel with each TextureFilter (anisotropic, the
# default; trilinear; bilinear from the finest level alone) for three seeds, and prints each
# image's RMSE against a 4096-spp reference (bilinear, whose pixel means converge to the
# texture's true pixel averages).
#
# Usage: tools/texture-study.sh [DRT]   (default build/drt; about 15 s on 2 cores)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
drt=${1:-$root/build/drt}
work=$(mktemp -d)
scene=$root/scenes/assets/tiled-floor.xml
# The variants stand beside the original, so that TextureFile resolves the same.
variant() {
    local file=$root/scenes/assets/.study-$1.xml
    sed "s/TextureScale=\"4\"/TextureScale=\"4\" TextureFilter=\"$1\"/" "$scene" >"$file"
    echo "$file"
}
cleanup() { rm -f "$root"/scenes/assets/.study-*.xml; rm -rf "$work"; }
trap cleanup EXIT
"$drt" "$(variant bilinear)" --spp 4096 --seed 1000 -q -o "$work/reference.pfm"
echo "filter       seed  rmse (4 spp against 4096 spp)"
for filter in anisotropic trilinear bilinear; do
    file=$(variant "$filter")
    for seed in 1 2 3; do
        "$drt" "$file" --seed "$seed" -q -o "$work/$filter-$seed.pfm"
        rmse=$("$drt" compare "$work/$filter-$seed.pfm" "$work/reference.pfm" | sed 's/rmse=\([^ ]*\).*/\1/')
        printf '%-12s %4d  %s\n' "$filter" "$seed" "$rmse"
    done
done
