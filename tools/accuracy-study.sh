#!/usr/bin/env bash
# The accuracy study of docs/accuracy.md: renders the study and thesis scenes with `drt converge`,
# writes the measurements as CSV and a summary of tables, and draws docs/images/accuracy-*.png
# with gnuplot (tools/install-deps.sh --study installs it).
#
# Usage: tools/accuracy-study.sh [--build DIR] [--work DIR] [--threads N] [--repeat N] [--plots-only]
#   --build DIR    where drt is built (default build/; built there in Release if missing)
#   --work DIR     where references, CSV files and summary.md go (default build/study)
#   --threads N    render threads (default: all cores)
#   --repeat N     time every measured render N times and keep the fastest (default 2)
#   --plots-only   redraw the plots and the summary from the CSV files of an earlier run
#
# Takes about 10 minutes on 2 free cores. Other programs running at the same time slow some
# renders down, so every measurement is timed twice and the faster time kept, and the study
# compares ratios of times measured in the same run.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build
work=
threads=()
repeat=2
plots_only=0
while [ $# -gt 0 ]; do
    case "$1" in
        --build) build=$2; shift 2 ;;
        --work) work=$2; shift 2 ;;
        --threads) threads=(--threads "$2"); shift 2 ;;
        --repeat) repeat=$2; shift 2 ;;
        --plots-only) plots_only=1; shift ;;
        -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
        *) echo "accuracy-study: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
work=${work:-$build/study}
images=$root/docs/images
drt=$build/drt

command -v gnuplot >/dev/null || {
    echo "accuracy-study: gnuplot is missing; run tools/install-deps.sh --study" >&2
    exit 2
}
if [ ! -x "$drt" ]; then
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$build" -j "$(nproc)" --target drt >/dev/null
fi
mkdir -p "$work" "$images"

study=$root/scenes/study
thesis=$root/scenes/thesis
effects=(antialiasing penumbra glossy depth-of-field motion-blur)
samplers=(random stratified sobol)
study_scale=0.4     # 320x240 -> 128x96
thesis_scale=0.125  # 800x600 -> 100x75
counts=4,16,64,256
log() { echo "[$(date +%H:%M:%S)] $*" >&2; }

# converge NAME ARGS...: drt converge ARGS, table to NAME.txt, rows to NAME.csv, each row with
# the fastest of $repeat timings (the errors are the same every time: renders are deterministic).
converge() {
    local name=$1 k
    shift
    for ((k = 1; k <= repeat; k++)); do
        "$drt" converge "$@" "${threads[@]}" --csv "$work/$name.csv.$k" >"$work/$name.txt"
    done
    awk -F, -v OFS=, 'FNR == 1 { header = $0; next }
        !(FNR in best) || $6 < best[FNR] { best[FNR] = $6; row[FNR] = $0 }
        END { print header; for (i = 2; i in row; i++) print row[i] }' \
        "$work/$name.csv".* >"$work/$name.csv"
    rm -f "$work/$name.csv".*
}
# reference OUT ARGS...: one high-count render, independent of the measured ones (seed 1; the
# measured renders use the scenes' seed 0), with the Sobol sampler, which converges fastest.
reference() {
    local out=$1
    shift
    "$drt" "$@" "${threads[@]}" --sampler sobol --seed 1 -q -o "$work/$out"
}

if [ "$plots_only" -eq 0 ]; then
    start=$(date +%s)
    # 1. Each effect alone, each sampler: error against samples and time.
    for e in "${effects[@]}"; do
        log "effect $e: reference (4096 spp)"
        reference "ref-$e.pfm" "$study/$e.xml" --scale $study_scale --spp 4096
        for s in "${samplers[@]}"; do
            log "effect $e: $s"
            converge "effect-$e-$s" "$study/$e.xml" --scale $study_scale --sampler "$s" \
                --spp $counts --reference "$work/ref-$e.pfm"
        done
    done

    # 2. Thesis scenes: references at 2048 spp for the three measured in depth, four times the
    #    thesis's own count for the others.
    for t in 1 2 3 4 5 6; do
        case $t in 1|5|6) spp=2048 ;; 4) spp=1600 ;; 2|3) spp=400 ;; esac
        log "test$t: reference ($spp spp)"
        reference "ref-test$t.pfm" "$thesis/test$t.xml" --scale $thesis_scale --spp $spp
    done
    for s in "${samplers[@]}"; do
        log "test1: $s"
        converge "test1-$s" "$thesis/test1.xml" --scale $thesis_scale --sampler "$s" \
            --spp $counts --reference "$work/ref-test1.pfm"
    done

    # 3. Camera samples against shadow rays on Test1 (the thesis: 100 x 10).
    for sr in 1 3 10 30; do
        case $sr in 1) list=10,30,100,300,1000 ;; 3) list=10,30,100,300 ;;
                    10) list=3,10,30,100 ;; 30) list=3,10,30 ;; esac
        log "test1: $sr shadow rays"
        converge "shadow-$sr" "$thesis/test1.xml" --scale $thesis_scale --shadow-rays $sr \
            --spp $list --reference "$work/ref-test1.pfm"
    done

    # 4. The thesis's own settings (the scenes' Samples and ShadowRays).
    for t in 1 2 3 4 5 6; do
        spp=$(sed -n 's/.*<Render Samples="\([0-9]*\)".*/\1/p' "$thesis/test$t.xml")
        log "test$t: thesis settings ($spp spp)"
        converge "thesis-test$t" "$thesis/test$t.xml" --scale $thesis_scale --spp "$spp" \
            --reference "$work/ref-test$t.pfm"
    done

    # ... and one full-size render, to check that time grows with the pixel count.
    log "test1: thesis settings at full size"
    TIMEFORMAT='%R %U %S'
    { time "$drt" "$thesis/test1.xml" "${threads[@]}" -q -o "$work/test1-full.png"; } \
        2>"$work/test1-full.time"
    unset TIMEFORMAT

    # 5. Adaptive sampling against plain sampling with the same sampler on Test1, Test5, Test6.
    for t in 1 5 6; do
        for s in stratified sobol; do
            log "test$t: $s, plain"
            converge "plain-test$t-$s" "$thesis/test$t.xml" --scale $thesis_scale --sampler $s \
                --spp 16,32,64,128,256,512 --reference "$work/ref-test$t.pfm"
            csv=$work/adaptive-test$t-$s.csv
            echo "threshold,spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,estimated_rmse,estimated_relmse" >"$csv"
            for x in 0.02 0.01 0.005 0.0025 0.00125; do
                log "test$t: $s, adaptive, noise threshold $x"
                converge "adaptive-test$t-$s-$x" "$thesis/test$t.xml" --scale $thesis_scale \
                    --sampler $s --spp 1024 --noise-threshold $x --min-spp 16 \
                    --reference "$work/ref-test$t.pfm"
                tail -n +2 "$work/adaptive-test$t-$s-$x.csv" | sed "s/^/$x,/" >>"$csv"
            done
        done
    done
    log "measured in $(( $(date +%s) - start )) s"
fi

# --- summary tables ---

# seconds_at FILE RMSE [TIME_COL RMSE_COL]: the time at which the curve in FILE (rows by
# increasing samples) reaches the RMSE, interpolated in log-log; "~" marks an extrapolation
# beyond the measured range along the last two points.
seconds_at() {
    awk -F, -v e="$2" -v tc="${3:-6}" -v ec="${4:-3}" '
        BEGIN { n = 0 }
        NR == 1 { for (i = 1; i <= NF; i++) if ($i == "fitted") fc = i }
        NR > 1 && $fc == 1 { t[n] = $tc; r[n] = $ec; n++ }
        END {
            for (i = 0; i + 1 < n; i++) {
                if (r[i] >= e && e >= r[i + 1]) {
                    f = log(e / r[i]) / log(r[i + 1] / r[i])
                    printf "%.3g\n", exp(log(t[i]) + f * log(t[i + 1] / t[i])); exit
                }
            }
            i = (e < r[n - 1]) ? n - 2 : 0
            f = log(e / r[i]) / log(r[i + 1] / r[i])
            printf "~%.3g\n", exp(log(t[i]) + f * log(t[i + 1] / t[i]))
        }' "$1"
}
field() { awk -F, -v row="$2" -v col="$3" 'NR == row + 1 { printf "%.3g", $col }' "$1"; }
g3() { awk -v v="$1" 'BEGIN { printf "%.3g", v }'; }
# slope FILE COLUMN: least-squares slope of log RMSE against log COLUMN over the fitted rows.
slope() {
    awk -F, -v c="$2" 'BEGIN { n = 0 }
        NR == 1 { for (i = 1; i <= NF; i++) if ($i == "fitted") fc = i }
        NR > 1 && $fc == 1 { x = log($c); y = log($3); n++; sx += x; sy += y; sxx += x * x; sxy += x * y }
        END { printf "%.2f", (n * sxy - sx * sy) / (n * sxx - sx * sx) }' "$1"
}
ratio() { awk -v a="${1#\~}" -v b="${2#\~}" 'BEGIN { printf "%.2f", a / b }'; }

summary=$work/summary.md
{
    echo "# Accuracy study: measurements"
    echo
    echo "drt $("$drt" --version | cut -d' ' -f2), commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?'), $(date -u +%Y-%m-%d), $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
    echo
    echo "## Samplers: slopes of log RMSE against log samples / log seconds (4..256 spp)"
    echo
    echo "| scene | random | stratified | sobol | RMSE at 64 spp: random / stratified / sobol |"
    echo "|---|---|---|---|---|"
    for e in "${effects[@]}" test1; do
        f=effect-$e; [ "$e" = test1 ] && f=test1
        row="| $e"
        for s in "${samplers[@]}"; do
            row+=" | $(slope "$work/$f-$s.csv" 5) / $(slope "$work/$f-$s.csv" 6)"
        done
        row+=" | $(field "$work/$f-random.csv" 3 3) / $(field "$work/$f-stratified.csv" 3 3) / $(field "$work/$f-sobol.csv" 3 3) |"
        echo "$row"
    done
    echo
    echo "## Cost of each effect: seconds to reach an RMSE, and the ratio to antialiasing alone"
    echo
    echo "| scene | stratified, 0.01 | stratified, 0.004 | sobol, 0.01 | sobol, 0.004 |"
    echo "|---|---|---|---|---|"
    for e in "${effects[@]}"; do
        row="| $e"
        for s in stratified sobol; do
            for target in 0.01 0.004; do
                base=$(seconds_at "$work/effect-antialiasing-$s.csv" $target)
                t=$(seconds_at "$work/effect-$e-$s.csv" $target)
                row+=" | $t s, × $(ratio "$t" "$base")"
            done
        done
        echo "$row |"
    done
    echo
    echo "## Test1: camera samples × shadow rays (stratified)"
    echo
    echo "| spp × shadow rays | CPU seconds | RMSE |"
    echo "|---|---|---|"
    for sr in 1 3 10 30; do
        tail -n +2 "$work/shadow-$sr.csv" | while IFS=, read -r spp _ err _ _ sec _; do
            echo "| $spp × $sr | $(g3 "$sec") | $(g3 "$err") |"
        done
    done
    echo
    echo "CPU seconds to reach RMSE 0.01 / 0.005: $(for sr in 1 3 10 30; do printf '%s shadow rays %s / %s; ' $sr "$(seconds_at "$work/shadow-$sr.csv" 0.01)" "$(seconds_at "$work/shadow-$sr.csv" 0.005)"; done)"
    echo
    echo "## The thesis's own settings (stratified, ${thesis_scale} × 800x600 = 100x75)"
    echo
    echo "| scene | spp × shadow rays | RMSE | relMSE | CPU seconds at 100x75 | × 64 = CPU seconds at 800x600 | wall seconds at 100x75 |"
    echo "|---|---|---|---|---|---|---|"
    for t in 1 2 3 4 5 6; do
        sr=$(sed -n 's/.*ShadowRays="\([0-9]*\)".*/\1/p' "$thesis/test$t.xml")
        IFS=, read -r spp wall err rel _ sec _ < <(tail -n 1 "$work/thesis-test$t.csv")
        echo "| test$t | $spp × $sr | $(g3 "$err") | $(g3 "$rel") | $(g3 "$sec") | $(awk -v s="$sec" 'BEGIN { printf "%.0f", s * 64 }') | $(g3 "$wall") |"
    done
    echo
    read -r wall user sys <"$work/test1-full.time"
    echo "Test1 at its full 800x600 with the thesis's settings: $wall s wall-clock, $(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.1f", u + s }') CPU seconds."
    echo
    echo "## Adaptive sampling (min 16 spp, max 1024) against plain sampling with the same sampler"
    echo
    echo "| scene | sampler | noise threshold | mean spp | CPU seconds | RMSE | plain: spp to that RMSE | plain: CPU seconds | samples saved | time saved |"
    echo "|---|---|---|---|---|---|---|---|---|---|"
    for t in 1 5 6; do
        for s in stratified sobol; do
            tail -n +2 "$work/adaptive-test$t-$s.csv" | while IFS=, read -r x _ _ err _ mean sec _; do
                plain=$(seconds_at "$work/plain-test$t-$s.csv" "$err")
                plain_spp=$(seconds_at "$work/plain-test$t-$s.csv" "$err" 5)
                saved=$(awk -v a="$sec" -v p="${plain#\~}" 'BEGIN { printf "%.0f%%", 100 * (1 - a / p) }')
                fewer=$(awk -v a="$mean" -v p="${plain_spp#\~}" 'BEGIN { printf "%.0f%%", 100 * (1 - a / p) }')
                echo "| test$t | $s | $x | $(g3 "$mean") | $(g3 "$sec") | $(g3 "$err") | $plain_spp | $plain | $fewer | $saved |"
            done
        done
    done
} >"$summary"
cat "$summary"

# --- plots ---

log "plots"
gnuplot <<EOF
set terminal pngcairo size 1200,760 font "sans,10"
set datafile separator ","
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set grid
set key bottom left
w = "$work"
set output "$images/accuracy-samplers.png"
set multiplot layout 2,3 title "RMSE against render time (processor seconds, log-log), 4 to 256 samples per pixel"
do for [e in "antialiasing penumbra glossy depth-of-field motion-blur test1"] {
    f = (e eq "test1") ? w."/test1-" : w."/effect-".e."-"
    set title (e eq "test1") ? "thesis Test1 (100x75, 10 shadow rays)" : e." (128x96)"
    set xlabel "CPU seconds"
    set ylabel "RMSE"
    plot f."random.csv" every ::1 using 6:3 with linespoints pt 7 title "random", \
         f."stratified.csv" every ::1 using 6:3 with linespoints pt 5 title "stratified", \
         f."sobol.csv" every ::1 using 6:3 with linespoints pt 9 title "sobol"
}
unset multiplot

set output "$images/accuracy-samplers-spp.png"
set multiplot layout 2,3 title "RMSE against samples per pixel (log-log); dashed: slopes -1/2 and -3/4"
do for [e in "antialiasing penumbra glossy depth-of-field motion-blur test1"] {
    f = (e eq "test1") ? w."/test1-" : w."/effect-".e."-"
    set title (e eq "test1") ? "thesis Test1 (100x75, 10 shadow rays)" : e." (128x96)"
    set xlabel "samples per pixel"
    set ylabel "RMSE"
    stats f."random.csv" every ::1::1 using 3 nooutput
    r4 = STATS_max
    plot f."random.csv" every ::1 using 1:3 with linespoints pt 7 title "random", \
         f."stratified.csv" every ::1 using 1:3 with linespoints pt 5 title "stratified", \
         f."sobol.csv" every ::1 using 1:3 with linespoints pt 9 title "sobol", \
         [4:256] 1.3 * r4 * (x / 4) ** -0.5 with lines dt 2 lc rgb "gray" notitle, \
         [4:256] 0.45 * r4 * (x / 4) ** -0.75 with lines dt 2 lc rgb "gray" notitle
}
unset multiplot

set terminal pngcairo size 1200,500 font "sans,10"
set output "$images/accuracy-effects.png"
set multiplot layout 1,2 title "Cost of each effect: RMSE against processor time, 4 to 256 samples per pixel, 128x96"
set xlabel "CPU seconds"
set ylabel "RMSE"
set linetype 11 lc rgb "black"
set linetype 12 lc rgb "#e41a1c"
set linetype 13 lc rgb "#377eb8"
set linetype 14 lc rgb "#4daf4a"
set linetype 15 lc rgb "#984ea3"
do for [s in "stratified sobol"] {
    set title s." sampler"
    plot for [i = 1:5] w."/effect-".word("antialiasing penumbra glossy depth-of-field motion-blur", i)."-".s.".csv" \
        every ::1 using 6:3 with linespoints lt 10 + i title word("antialiasing penumbra glossy depth-of-field motion-blur", i)
}
unset multiplot

set output "$images/accuracy-shadow-rays.png"
set title "Test1 (100x75): camera samples against shadow rays per shading point"
set key top right
plot for [sr in "1 3 10 30"] w."/shadow-".sr.".csv" every ::1 using 6:3 with linespoints \
         title sr." shadow ray".(sr eq "1" ? "" : "s"), \
     w."/shadow-10.csv" every ::4::4 using 6:3:("100 x 10") with labels offset 0,1.2 notitle, \
     w."/shadow-1.csv" every ::5::5 using 6:3:("1000 x 1") with labels offset 0,-1.2 notitle

set terminal pngcairo size 1200,420 font "sans,10"
set key bottom left
set output "$images/accuracy-adaptive.png"
set multiplot layout 1,3 title "Adaptive sampling (noise thresholds 0.02 ... 0.00125, 16 to 1024 spp) against plain sampling (16 ... 512 spp), 100x75"
do for [t in "1 5 6"] {
    set title "Test".t
    plot w."/plain-test".t."-stratified.csv" every ::1 using 6:3 with linespoints pt 7 lc 1 title "stratified, plain", \
         w."/adaptive-test".t."-stratified.csv" every ::1 using 7:4 with linespoints pt 6 lc 1 dt 2 title "stratified, adaptive", \
         w."/plain-test".t."-sobol.csv" every ::1 using 6:3 with linespoints pt 5 lc 3 title "sobol, plain", \
         w."/adaptive-test".t."-sobol.csv" every ::1 using 7:4 with linespoints pt 4 lc 3 dt 2 title "sobol, adaptive"
}
unset multiplot
EOF
log "wrote $summary and $images/accuracy-*.png"
