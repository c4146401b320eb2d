#!/bin/sh
# Rendering to a goal, measured: for each thesis scene, drt converge --target-error E prints the
# pilots' prediction (spp, seconds) and where the measured RMSE reaches E (the cheapest fixed
# count), and drt SCENE --target-error E renders to it; the table compares prediction, the goal
# render and the cheapest fixed count, and the goal render's true RMSE against the reference.
# usage: tools/goal-study.sh [DRT] [E] [SCALE] > table.md   (docs/accuracy.md, section 6)
set -eu
drt=${1:-build/drt}
target=${2:-0.005}
scale=${3:-0.1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| scene | predicted spp | predicted s | goal spp | goal s | goal estimated RMSE | goal true RMSE | true / E | cheapest fixed spp | its s | goal s / fixed s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for scene in scenes/thesis/test*.xml; do
    name=$(basename "$scene" .xml)
    "$drt" converge "$scene" --scale "$scale" --spp 16,32,64,128,256,512,1024 --reference-spp 4096 \
        --target-error "$target" --save-reference "$work/ref.pfm" > "$work/converge.txt"
    "$drt" "$scene" --scale "$scale" --target-error "$target" -o "$work/goal.pfm" \
        --stats "$work/goal.json" -q
    predicted=$(sed -n 's/^predicted for --target-error [^:]*: \([0-9]*\) spp, \([0-9.]*\) s.*/\1 | \2/p' "$work/converge.txt")
    measured=$(sed -n 's/^measured for rmse [^:]*: \([0-9]*\) spp, \([0-9.]*\) s.*/\1 | \2/p' "$work/converge.txt")
    goal_spp=$(sed -n 's/.*"samples_per_pixel": \([0-9]*\).*/\1/p' "$work/goal.json")
    goal_s=$(sed -n 's/^  "seconds": \([0-9.e-]*\).*/\1/p' "$work/goal.json")
    goal_est=$(sed -n 's/.*"estimated_rmse": \([0-9.e-]*\).*/\1/p' "$work/goal.json" | head -1)
    true_rmse=$("$drt" compare "$work/goal.pfm" "$work/ref.pfm" | sed 's/rmse=\([^ ]*\).*/\1/')
    fixed_s=${measured#*| }
    echo "| $name | $predicted | $goal_spp | $goal_s | $goal_est | $true_rmse | $(echo "$true_rmse / $target" | bc -l | cut -c1-4) | $measured | $(echo "$goal_s / $fixed_s" | bc -l | cut -c1-4) |"
    cp "$work/converge.txt" "/tmp/goal-study-$name.txt" 2>/dev/null || true
done
