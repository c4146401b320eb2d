#!/usr/bin/env bash
# The race with Blender's Cycles (issue 31): drt's path integrator (with its default stratified
# sampler, and with --sampler sobol) and Cycles 3.4 on the Cornell box
# (scenes/gi/cornell-box.xml) and the Test1 room (bench/cycles/test1-room.xml), each scene's
# Cycles twin built from the same XML by bench/cycles/twin.py. For each renderer: a converged
# reference of its own (--ref-spp, another seed; drt's is rendered with the Sobol sampler, and
# serves every drt run), then renders at each of --levels spp, drt, drt-sobol, on the room
# drt-sr2 (a shadow ray to each of its two lights), then Cycles, round after round on
# --threads threads; bench/cycles/analyse.py prints each one's
# relative RMSE against its own reference and the time to reach 2 %, 1 % and 0.5 %, start-up
# included (the excluded time plus the median of each run's wall clock less its excluded time)
# and excluded (Cycles: its log, from the first sample to
# Finished; drt: the wall clock less that of the same command at 1 spp, run each round: drt
# runs without --stats, which would add its error estimate's renders, 30 % of the samples on
# an image this small), and the two references' agreement.
# Usage: bench/cycles/race.sh [--scale F] [--levels "64 256 1024 2048"] [--ref-spp N]
#        [--rounds N] [--threads N] [--drt PATH] [--keep DIR]
# The scenes render small (the Cornell box at 40 x 40, the room at 40 x 30: 0.5 % takes tens of
# thousands of samples a pixel); --scale F multiplies those sizes (same framing). Needs blender
# (tools/install-deps.sh --bench) and python3.
set -euo pipefail
cd "$(dirname "$0")/../.."
drt=build/drt
scale=1
levels="64 256 1024 2048"
ref_spp=8192
rounds=3
threads=2
keep=
while [ $# -gt 0 ]; do
    case "$1" in
        --scale) scale=$2; shift 2 ;;
        --levels) levels=$2; shift 2 ;;
        --ref-spp) ref_spp=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --threads) threads=$2; shift 2 ;;
        --drt) drt=$2; shift 2 ;;
        --keep) keep=$2; shift 2 ;;
        *) echo "cycles race: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$drt" ] || { echo "cycles race: no $drt; build first (tools/quickstart.sh)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "cycles race: needs GNU time: tools/install-deps.sh --bench" >&2; exit 2; }
command -v blender >/dev/null || { echo "cycles race: needs blender: tools/install-deps.sh --bench" >&2; exit 2; }
drt=$(realpath "$drt")
twin=$(realpath bench/cycles/twin.py)
if [ -n "$keep" ]; then out=$(realpath -m "$keep"); mkdir -p "$out"; else out=$(mktemp -d); trap 'rm -rf "$out"' EXIT; fi
runs=$out/runs.tsv
printf 'scene\trenderer\tspp\tround\twall\trender\tcpu\timage\n' >"$runs"

now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }'; }

# One render each; appends a row to runs.tsv.
# A render no longer than its own 1-spp start-up (a tiny --scale, where the clocks' noise is the
# whole time) counts 0 s start-up excluded, never less.
render_drt() {  # scene name spp seed round scale sampler [shadow-rays]
    local name=drt extra=()
    [ "$7" = stratified ] || name=drt-$7
    [ -z "${8:-}" ] || { name=$name-sr$8; extra=(--shadow-rays "$8"); }
    local image=$out/$2-$name-$3-s$4.pfm start wall startup=0
    if [ "$5" != ref ]; then
        start=$(now)
        "$drt" "$1" --scale "$6" --spp 1 "${extra[@]}" --threads "$threads" -q -o "$out/startup.pfm"
        startup=$(since "$start")
    fi
    start=$(now)
    /usr/bin/time -f "%U %S" -o "$out/time" "$drt" "$1" --scale "$6" --spp "$3" --seed "$4" \
        --sampler "$7" "${extra[@]}" --threads "$threads" -q -o "$image"
    wall=$(since "$start")
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$2" "$name" "$3" "$5" "$wall" \
        "$(awk -v w="$wall" -v s="$startup" 'BEGIN { d = w - s; printf "%.3f", d > 0 ? d : 0 }')" \
        "$(awk '{ printf "%.2f", $1 + $2 }' "$out/time")" "$image" >>"$runs"
}
render_cycles() {  # scene name spp seed round scale
    local image=$out/$2-cycles-$3-s$4 start
    start=$(now)
    /usr/bin/time -f "%U %S" -o "$out/time" blender -b -t "$threads" --python "$twin" -- "$1" "$image.exr" "$3" --scale "$6" \
        --seed "$4" >"$out/blender.log" 2>&1 || { cat "$out/blender.log" >&2; exit 1; }
    local wall; wall=$(since "$start")
    # Cycles' own clock: from the first sample (after scene sync, BVH and kernels) to Finished.
    local seconds; seconds=$(awk -F'|' '
        function secs(s) { sub(/.*Time:/, "", s); n = split(s, p, ":"); return n == 3 ? p[1] * 3600 + p[2] * 60 + p[3] : p[1] * 60 + p[2] }
        /\| Sample 0\// && !t0 { t0 = secs($2) }
        /\| Finished/ { t1 = secs($2) }
        END { printf "%.3f", t1 - t0 }' "$out/blender.log")
    printf '%s\tcycles\t%s\t%s\t%s\t%s\t%s\t%s\n' "$2" "$3" "$5" "$wall" "$seconds" \
        "$(awk '{ printf "%.2f", $1 + $2 }' "$out/time")" "$image.pfm" >>"$runs"
    # The PFM copy for the analysis is written after the clock stops (once: the same seed and
    # spp give the same image every round).
    [ -f "$image.pfm" ] || blender -b --python-expr "
import array, bpy
img = bpy.data.images.load('$image.exr'); w, h = img.size
px = array.array('f', [0.0]) * (w * h * 4); img.pixels.foreach_get(px)
with open('$image.pfm', 'wb') as f:
    f.write(f'PF\n{w} {h}\n-1.0\n'.encode())
    array.array('f', (px[i] for i in range(len(px)) if i % 4 != 3)).tofile(f)
" >/dev/null 2>&1
}

# The fourth field: the room's light count, for a third drt run with a shadow ray per light at
# every diffuse event (--shadow-rays 2) where the scene's own ShadowRays="1" picks one light
# by power, as Cycles 3.4 does; "-" where there is one light only.
scenes=("scenes/gi/cornell-box.xml cornell $(awk -v f="$scale" 'BEGIN { print 0.1 * f }') -"
        "bench/cycles/test1-room.xml test1 $(awk -v f="$scale" 'BEGIN { print 0.05 * f }') 2")
echo "cycles race: scale $scale (${scenes[*]}), levels $levels, references $ref_spp spp, $rounds rounds, $threads threads"
echo "$(date -u '+%F %T') UTC, $(git rev-parse --short HEAD), load $(cut -d' ' -f1-3 /proc/loadavg)"
for s in "${scenes[@]}"; do
    set -- $s
    render_drt "$1" "$2" "$ref_spp" 1 ref "$3" sobol
    render_cycles "$1" "$2" "$ref_spp" 1 ref "$3"
    echo "$2: references done"
done
for round in $(seq "$rounds"); do
    for s in "${scenes[@]}"; do
        set -- $s
        for spp in $levels; do
            render_drt "$1" "$2" "$spp" 0 "$round" "$3" stratified
            render_drt "$1" "$2" "$spp" 0 "$round" "$3" sobol
            [ "$4" = - ] || render_drt "$1" "$2" "$spp" 0 "$round" "$3" stratified "$4"
            render_cycles "$1" "$2" "$spp" 0 "$round" "$3"
        done
    done
    echo "round $round done, load $(cut -d' ' -f1-3 /proc/loadavg)"
done
python3 bench/cycles/analyse.py "$runs" "$ref_spp"
