#!/usr/bin/env bash
# Rendering to a goal, measured (docs/accuracy.md, section 6). For each thesis scene and target E:
# - the prediction: drt info SCENE --target-error E (its predicted count and seconds);
# - the goal render: drt SCENE --target-error E (its count, rounds, estimated and true RMSE);
# - the cheapest fixed count whose true RMSE reaches E, found by doubling and then bisecting
#   --spp N against a 4096-spp reference of another seed (assumes the error falls with N);
# - the time of the goal render and of that fixed count, timed side by side and alternating,
#   pinned to one core at high priority (run as root for nice -20), --repeat times each; with
#   --repeat 0 the goal render runs once, untimed (its rounds and errors are deterministic, so
#   "goal samples / fixed" and the true error need no timing).
# --sampler renders the goal and the fixed counts with that sampler (the reference is the same
# for every sampler: the default one's at 4096 spp).
# Writes goal-study.csv to the work folder and prints a markdown table;
# tools/goal-plot.sh draws docs/images/accuracy-goal.png from the CSV.
#
# usage: tools/goal-study.sh [--drt BIN] [--scale S] [--targets E1,E2,..] [--work DIR]
#                            [--repeat N] [--cpu C] [--scenes "test1 test2 .."] [--sampler S]
# --scenes names thesis scenes (test1) or others by their path inside scenes/ (gi/cornell-box).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
drt=$root/build/drt
scale=0.1
targets=0.01,0.005
work=$root/build/goal-study
repeat=3
cpu=1
scenes="test1 test2 test3 test4 test5 test6"
sampler=stratified
while [ $# -gt 0 ]; do
    case "$1" in
        --drt) drt=$(realpath "$2"); shift 2 ;;
        --scale) scale=$2; shift 2 ;;
        --targets) targets=$2; shift 2 ;;
        --work) work=$2; shift 2 ;;
        --repeat) repeat=$2; shift 2 ;;
        --cpu) cpu=$2; shift 2 ;;
        --scenes) scenes=$2; shift 2 ;;
        --sampler) sampler=$2; shift 2 ;;
        *) echo "goal-study: unknown option $1" >&2; exit 2 ;;
    esac
done
mkdir -p "$work"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
log() { echo "[$(date +%H:%M:%S)] $*" >&2; }
# Pinned and at high priority, so that the compared runs see the same core.
pinned() { nice -n -20 taskset -c "$cpu" "$@"; }
# wall SECONDS_VAR COMMAND...: runs it pinned and stores its wall-clock seconds.
wall() {
    local -n out=$1
    shift
    local t0 t1
    t0=$(date +%s.%N)
    pinned "$@" >/dev/null 2>&1
    t1=$(date +%s.%N)
    out=$(echo "$t1 - $t0" | bc -l)
}
json() { sed -n "s/.*\"$1\": \\([0-9.e+-]*\\).*/\\1/p" "$2" | head -1; }
median() { tr ' ' '\n' | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

csv=$work/goal-study.csv
echo "scene,target,predicted_spp,predicted_s,goal_spp,goal_rounds,goal_s,goal_render_s,goal_estimated,goal_true,fixed_spp,fixed_s,fixed_render_s,fixed_true,load" >"$csv"
for name in $scenes; do
    # A thesis scene by its name (test1), any other by its path inside scenes/ (gi/cornell-box).
    case $name in
        */*) scene=$root/scenes/$name.xml ;;
        *) scene=$root/scenes/thesis/$name.xml ;;
    esac
    key=${name//\//-}
    ref=$work/$key-$scale-ref.pfm
    if [ ! -f "$ref" ]; then
        log "$name: reference (4096 spp, seed 1)"
        "$drt" "$scene" --scale "$scale" --spp 4096 --seed 1 -q -o "$ref"
    fi
    # rmse_at N: the true RMSE of --spp N (kept in the work folder: it is called in subshells,
    # and the images of --spp N are the same for every build that renders them bit-identically).
    rmse_at() {
        local kept=$work/$key-$scale-$sampler.$1.rmse
        if [ ! -f "$kept" ]; then
            "$drt" "$scene" --scale "$scale" --sampler "$sampler" --spp "$1" -q -o "$tmp/fixed.pfm"
            "$drt" compare "$tmp/fixed.pfm" "$ref" | sed 's/rmse=\([^ ]*\).*/\1/' >"$kept"
        fi
        cat "$kept"
    }
    meets() { [ "$(echo "$(rmse_at "$1") <= $2" | bc -l)" = 1 ]; }
    for target in ${targets//,/ }; do
        lo=1 hi=4
        until meets "$hi" "$target"; do lo=$hi; hi=$((hi * 2)); done
        while [ $((hi - lo)) -gt 1 ]; do
            mid=$(((lo + hi) / 2))
            if meets "$mid" "$target"; then hi=$mid; else lo=$mid; fi
        done
        fixed=$hi
        log "$name E=$target: cheapest fixed count $fixed (true RMSE $(rmse_at "$fixed"))"
        pinned "$drt" info "$scene" --scale "$scale" --sampler "$sampler" --threads 1 \
            --target-error "$target" >"$tmp/info.txt"
        predicted=$(sed -n 's/^predicted for --target-error [^:]*: \([0-9]*\) spp, \([0-9.]*\) s.*/\1,\2/p' "$tmp/info.txt")
        goal_times="" fixed_times=""
        for ((k = 1; k <= repeat; k++)); do
            wall t "$drt" "$scene" --scale "$scale" --sampler "$sampler" --threads 1 \
                --target-error "$target" -o "$tmp/goal.pfm" --stats "$tmp/goal.json"
            goal_times+=" $t"
            wall t "$drt" "$scene" --scale "$scale" --sampler "$sampler" --threads 1 --spp "$fixed" \
                -o "$tmp/fixed.pfm" --stats "$tmp/fixed.json"
            fixed_times+=" $t"
        done
        if [ "$repeat" -eq 0 ]; then
            "$drt" "$scene" --scale "$scale" --sampler "$sampler" --target-error "$target" \
                -o "$tmp/goal.pfm" --stats "$tmp/goal.json" 2>/dev/null
            "$drt" "$scene" --scale "$scale" --sampler "$sampler" --spp "$fixed" \
                -o "$tmp/fixed.pfm" --stats "$tmp/fixed.json" 2>/dev/null
        fi
        goal_s=nan fixed_s=nan
        if [ "$repeat" -gt 0 ]; then
            goal_s=$(echo $goal_times | median)
            fixed_s=$(echo $fixed_times | median)
        fi
        goal_spp=$(json samples_per_pixel "$tmp/goal.json")
        # A pilot of one pixel in b x b counts as spp/(b*b) samples per pixel of the image, a top-up
        # of 2 x m samples on a share s of the pixels, shown as 2xm@s, as 2 m s.
        rounds=$(grep -o '{"spp": [0-9]*\(, "pilot_pixel_block": [0-9]*\|, "top_up_share": [0-9.e-]*\)\?' "$tmp/goal.json" |
            sed -e 's/{"spp": //' -e 's/, "pilot_pixel_block": \([0-9]*\)/\/(\1*\1)/' \
                -e 's/^\([0-9]*\), "top_up_share": \(.*\)/2x\1@\2/' | paste -sd' ')
        estimated=$(json estimated_rmse "$tmp/goal.json")
        goal_true=$("$drt" compare "$tmp/goal.pfm" "$ref" | sed 's/rmse=\([^ ]*\).*/\1/')
        echo "$name,$target,$predicted,$goal_spp,$rounds,$goal_s,$(json seconds "$tmp/goal.json"),$estimated,$goal_true,$fixed,$fixed_s,$(json seconds "$tmp/fixed.json"),$(rmse_at "$fixed"),$(cut -d' ' -f1 /proc/loadavg)" >>"$csv"
        log "$name E=$target: goal $goal_s s ($rounds spp), fixed $fixed_s s"
    done
done

# "goal samples / fixed": every round's samples against the fixed count's (free of the machine's
# noise; a pilot of one pixel in b x b, shown as 8/(b*b), counts its share, a top-up of 2 x m
# samples on a share s of the pixels, shown as 2xm@s, 2 m s); "load" the 1-minute
# load average when the case was timed.
echo "| scene | E | predicted spp | predicted s | goal rounds (spp) | goal s | goal estimated RMSE | goal true RMSE | true / E | cheapest fixed spp (true RMSE ≤ E) | its s | goal samples / fixed | goal s / fixed s | load |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
tail -n +2 "$csv" | while IFS=, read -r name target pspp ps gspp rounds gs grs gest gtrue fspp fs frs ftrue load; do
    samples=$(echo "$rounds" | tr ' ' '\n' | awk '
        /@/ { split($0, t, /[x@]/); sum += 2 * t[2] * t[3]; next }
        /\// { split($0, p, /[\/(*)]+/); sum += p[1] / (p[2] * p[3]); next }
        { sum += $0 } END { printf "%.3f", sum }')
    walls=nan
    [ "$gs" = nan ] || walls=$(echo "$gs / $fs" | bc -l)
    printf '| %s | %s | %s | %.2f | %s | %.2f | %.5f | %.5f | %.2f | %s | %.2f | %.2f | %.2f | %s |\n' \
        "$name" "$target" "$pspp" "$ps" "${rounds// /, }" "$gs" "$gest" "$gtrue" \
        "$(echo "$gtrue / $target" | bc -l)" "$fspp" "$fs" "$(echo "$samples / $fspp" | bc -l)" \
        "$walls" "$load"
done
