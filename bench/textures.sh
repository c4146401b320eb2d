#!/usr/bin/env bash
# The cost of a texture lookup (issue 32): Spot the cow (/work/shared/models/spot.obj, with its
# own vt) untextured, with the procedural marble, and with a 1024 x 1024 image texture at its vt
# (generated: the model's own texture is not in the collection), rendered in turn round after
# round by each binary given (--drt, and --base for a second build, e.g. main before image
# textures, to show that an untextured scene's speed is unchanged: both render the untextured
# Spot and scenes/thesis/test1.xml at --scale 0.25, its procedural checker only). A point
# light and one shadow ray keep the shading cheap, so the lookup's share shows; the cost per textured hit is
# (textured - untextured) / the camera rays that hit Spot, counted from a render in which Spot
# emits 1 and nothing else shows. Times are CPU seconds (user + system, GNU time) on one thread
# by default: on a shared machine they drift less than wall-clock times.
# Usage: bench/textures.sh [--drt PATH] [--base PATH] [--model OBJ] [--rounds N] [--threads N]
#        [--spp N] [--keep DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
base=
model=/work/shared/models/spot.obj
rounds=3
threads=1
spp=32
keep=
while [ $# -gt 0 ]; do
    case "$1" in
        --drt) drt=$2; shift 2 ;;
        --base) base=$2; shift 2 ;;
        --model) model=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --threads) threads=$2; shift 2 ;;
        --spp) spp=$2; shift 2 ;;
        --keep) keep=$2; shift 2 ;;
        *) echo "textures: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$drt" ] || { echo "textures: no $drt; build first" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "textures: needs GNU time: tools/install-deps.sh --bench" >&2; exit 2; }
[ -f "$model" ] || { echo "textures: no model $model (--model OBJ with vt)" >&2; exit 2; }
if [ -n "$keep" ]; then out=$(realpath -m "$keep"); mkdir -p "$out"; else out=$(mktemp -d); trap 'rm -rf "$out"' EXIT; fi
drt=$(realpath "$drt")
[ -z "$base" ] || base=$(realpath "$base")
cp "$model" "$out/spot.obj"
cp scenes/thesis/test1.xml "$out/test1.xml"

# A 1024 x 1024 8-bit texture: colour bands across u, a grid every 32 texels.
python3 - "$out/spot-texture.png" <<'PY'
import math, struct, sys, zlib
n = 1024
rows = bytearray()
for y in range(n):
    rows.append(0)
    for x in range(n):
        if x % 32 == 0 or y % 32 == 0:
            rows.extend((30, 30, 30))
        else:
            rows.extend((int(127 + 120 * math.sin(x / 40)), int(127 + 120 * math.sin(y / 55)),
                         int(127 + 120 * math.cos((x + y) / 70))))
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0))
                              + chunk(b"IDAT", zlib.compress(bytes(rows), 6)) + chunk(b"IEND", b""))
PY

scene() {  # name material-attributes mesh-attributes ambient
    cat >"$out/$1.xml" <<XML
<?xml version="1.0"?>
<Scene>
  <Image Width="400" Height="300"/>
  <Render Samples="$spp" ShadowRays="1" MaxDepth="2" Seed="0"/>
  <Background r="0" g="0" b="0"/>
  <Ambient r="$4" g="$4" b="$4"/>
  <Camera Ex="2.0" Ey="0.45" Ez="1.3" Lx="0" Ly="0.08" Lz="0.19" Fov="32"/>
  <Materials>
    <Cow $2/>
  </Materials>
  <Lights>
    <Light Px="3" Py="4" Pz="3" Radius="0" Ir="0.9" Ig="0.9" Ib="0.9"/>
  </Lights>
  <Objects>
    <Mesh File="spot.obj" Material="Cow" $3/>
  </Objects>
</Scene>
XML
}
scene plain 'diffuse="1" kdr="0.8" kdg="0.7" kdb="0.6"' '' 0.1
scene marble 'diffuse="1" kdr="0.8" kdg="0.7" kdb="0.6"' \
    'EnableTexture="1" Texture="marble" TextureScale="0.2" k2r="0.2" k2g="0.2" k2b="0.3"' 0.1
scene image 'diffuse="1" kdr="0.8" kdg="0.7" kdb="0.6"' \
    'EnableTexture="1" Texture="image" TextureFile="spot-texture.png"' 0.1
scene coverage 'diffuse="0" ker="1" keg="1" keb="1"' '' 0

# The share of camera rays that hit Spot: the mean of an image where only Spot shows, as 1.
"$drt" "$out/coverage.xml" --spp "$spp" --threads "$threads" -q -o "$out/coverage.pfm"
coverage=$(python3 bench/cycles/pfm.py mean "$out/coverage.pfm" | awk '{ print $4 }')
hits=$(awk -v c="$coverage" -v s="$spp" 'BEGIN { printf "%.0f", c * 400 * 300 * s }')
echo "textures: Spot at 400 x 300, $spp spp, $threads threads, $rounds rounds; $hits camera hits on Spot (coverage $coverage)"
echo "$(date -u '+%F %T') UTC, $(git rev-parse --short HEAD), load $(cut -d' ' -f1-3 /proc/loadavg)"

binaries=("drt=$drt")
[ -z "$base" ] || binaries+=("base=$base")
for round in $(seq "$rounds"); do
    line="round $round:"
    for b in "${binaries[@]}"; do
        for s in plain marble image test1; do
            [ "${b%%=*}" = base ] && [ "$s" = marble -o "$s" = image ] && continue
            [ -z "$base" ] && [ "$s" = test1 ] && continue
            /usr/bin/time -f "%U %S" -o "$out/time" "${b#*=}" "$out/$s.xml" --threads "$threads" -q \
                -o "$out/$s.png" $([ "$s" = test1 ] && echo --scale 0.25)
            seconds=$(awk '{ printf "%.2f", $1 + $2 }' "$out/time")
            line="$line ${b%%=*}/$s $seconds"
            echo "${b%%=*} $s $seconds" >>"$out/times"
        done
    done
    echo "$line"
done
awk -v hits="$hits" '
    { t[$1 " " $2] = t[$1 " " $2] " " $3 }
    END {
        for (k in t) {
            n = split(substr(t[k], 2), v, " "); for (i = 2; i <= n; i++) for (j = i; j > 1 && v[j - 1] > v[j]; j--) { x = v[j]; v[j] = v[j - 1]; v[j - 1] = x }
            med[k] = (n % 2) ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
            printf "%-12s median %.3f s (%.3f-%.3f)\n", k, med[k], v[1], v[n]
        }
        p = med["drt plain"]
        printf "marble / plain %.3f, image / plain %.3f, image / marble %.3f\n", med["drt marble"] / p, med["drt image"] / p, med["drt image"] / med["drt marble"]
        printf "per textured camera hit (CPU time): marble +%.0f ns, image +%.0f ns\n", 1e9 * (med["drt marble"] - p) / hits, 1e9 * (med["drt image"] - p) / hits
        if ("base plain" in med) printf "untextured: this build / base: Spot %.3f, Test1 %.3f\n", p / med["base plain"], med["drt test1"] / med["base test1"]
    }' "$out/times"
