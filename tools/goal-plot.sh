#!/usr/bin/env bash
# Draws the prediction of a goal render against what the render then took and reached, from
# tools/goal-study.sh's CSV (docs/accuracy.md, section 6): left, the predicted seconds (drt info
# --target-error E) against the goal render's seconds; right, the target E against the goal
# render's true RMSE (against a 4096-spp reference) and its own estimate. The plot places the
# thesis scenes (test1 .. test6) side by side; rows of other scenes are left out, and said so.
# Needs gnuplot (tools/install-deps.sh --study).
#
# usage: tools/goal-plot.sh CSV [PNG]   (default PNG: docs/images/accuracy-goal.png)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
csv=${1:?usage: tools/goal-plot.sh CSV [PNG]}
png=${2:-$root/docs/images/accuracy-goal.png}
command -v gnuplot >/dev/null || {
    echo "goal-plot: gnuplot is missing; run tools/install-deps.sh --study" >&2
    exit 2
}
thesis_rows=$(mktemp)
trap 'rm -f "$thesis_rows"' EXIT
awk -F, 'NR == 1 || $1 ~ /^test[1-6]$/' "$csv" >"$thesis_rows"
others=$(awk -F, 'NR > 1 && $1 !~ /^test[1-6]$/' "$csv" | wc -l)
[ "$others" -eq 0 ] || echo "goal-plot: $others rows of other scenes left out (the plot places test1 .. test6)" >&2
if [ "$(wc -l <"$thesis_rows")" -le 1 ]; then
    echo "goal-plot: no rows of thesis scenes in $csv to plot" >&2
    exit 2
fi
csv=$thesis_rows
# Columns (goal-study.sh): 1 scene, 2 target, 3 predicted_spp, 4 predicted_s, 5 goal_spp,
# 6 goal_rounds, 7 goal_s, 8 goal_render_s, 9 goal_estimated, 10 goal_true, 11 fixed_spp,
# 12 fixed_s, 13 fixed_render_s, 14 fixed_true, 15 load.
gnuplot <<EOF
set terminal pngcairo size 1200,520 font "sans,10"
set output "$png"
set datafile separator ","
set key top left
set multiplot layout 1,2
scene(s) = int(substr(s, 5, 5))
# Each scene a little to the side of its target, so that the six points of one E do not overlap.
beside(e, s) = e * (1 + 0.035 * (scene(s) - 3.5))

set title "Time: drt info's prediction against the goal render (one core)"
set logscale xy
set xlabel "predicted seconds (pilots + predicted final round)"
set ylabel "goal render's seconds (all rounds)"
set grid
plot [0.1:20] [0.1:20] \
    x title "measured = predicted" lc rgb "#888888", \
    1.3 * x title "1.3 x predicted" dt 2 lc rgb "#888888", \
    x / 1.3 notitle dt 2 lc rgb "#888888", \
    "$csv" every ::1 using (\$2 == 0.01 ? \$4 : 1/0):8 title "E = 0.01" pt 7 ps 1.2 lc rgb "#1f77b4", \
    "$csv" every ::1 using (\$2 == 0.005 ? \$4 : 1/0):8 title "E = 0.005" pt 5 ps 1.2 lc rgb "#d62728", \
    "$csv" every ::1 using 4:8:(substr(strcol(1), 5, 5)) with labels offset 0.9,0.4 font "sans,8" notitle

set title "Error: the target E against what the goal render reached"
set xlabel "target E (each scene drawn a little to the side: Test1 left ... Test6 right)"
set ylabel "RMSE of the goal render"
plot [0.0035:0.014] [0.001:0.02] \
    x title "RMSE = E" lc rgb "#888888", \
    1.25 * x title "1.25 E (the issue's bound)" dt 2 lc rgb "#888888", \
    "$csv" every ::1 using (beside(\$2, strcol(1))):10 title "true RMSE (4096-spp reference)" pt 7 ps 1.2 lc rgb "#2ca02c", \
    "$csv" every ::1 using (beside(\$2, strcol(1))):9 title "its own estimate" pt 6 ps 1.2 lc rgb "#9467bd", \
    "$csv" every ::1 using (beside(\$2, strcol(1))):10:(substr(strcol(1), 5, 5)) with labels offset 0,-0.8 font "sans,8" notitle
unset multiplot
EOF
echo "goal-plot: wrote $png" >&2
