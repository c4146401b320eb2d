#!/usr/bin/env bash
# The scale-out measurements issue 13 asks for, side by side in one run (the variants alternate
# within each round, so a noisy machine slows each side alike; every ratio is of medians):
#   overhead: a render under `mpirun -n 1` against the same render without mpirun (want <= 1.02);
#   split:    2 processes x 1 thread against 1 process x 2 threads, as speed (want >= 0.95);
#   resume:   a render interrupted half way and resumed from its checkpoint against one run
#             straight through: the time lost to the cycle, in wall-clock seconds (a stopped
#             render writes no --stats, so it has no render seconds);
#   tail:     the seconds from the last tile handed out to the end (--stats tail_seconds), with
#             the costliest tiles handed out first (drt's order) and row by row (--grid-order);
#   message:  what one finished tile costs the leader of `mpirun -n 2`: receiving it, and adding
#             it to the image (--stats microseconds_per_message).
# Times are drt's own render seconds (--stats), which leave out process start-up; the wall-clock
# seconds of the whole command, mpirun's start-up included, are printed beside them. As root
# every run gets the highest priority, so that the machine's other work disturbs it less.
# Usage: setsid bench/mpi.sh [--scene FILE] [--scale F] [--rounds N] [--drt PATH]
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
scene=scenes/thesis/test1.xml
scale=0.25
rounds=3
while [ $# -gt 0 ]; do
    case "$1" in
        --scene) scene=$2; shift 2 ;;
        --scale) scale=$2; shift 2 ;;
        --rounds) rounds=$2; shift 2 ;;
        --drt) drt=$2; shift 2 ;;
        *) echo "mpi: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$drt" ] || { echo "mpi: no $drt; build first (tools/quickstart.sh)" >&2; exit 2; }
command -v mpirun >/dev/null || { echo "mpi: needs mpirun: tools/install-deps.sh" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
boost=()
if [ "$(id -u)" -eq 0 ]; then
    boost=(nice -n -20)
    # With autogroup scheduling (Linux's default for desktops and many servers) a nice value
    # orders threads only within their session; between sessions the session's own nice
    # counts, so without this the machine's other sessions get an equal share each and two
    # threads run no faster than one. Run the bench in a session of its own: setsid bench/mpi.sh
    if [ -w /proc/self/autogroup ]; then echo -20 >/proc/self/autogroup || true; fi
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

field() { grep -o "\"$1\": *[0-9.e+-]*" "$2" | head -1 | sed 's/.*: *//'; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
now() { date +%s.%N; }
# Runs drt (through the command words given before --) and prints "render-seconds wall-seconds
# tail-seconds receive-microseconds assemble-microseconds".
timed() {
    local launcher=()
    while [ "$1" != "--" ]; do launcher+=("$1"); shift; done
    shift
    local start status
    start=$(now)
    status=0
    rm -f "$out/s.json"  # a stopped render writes none: its render seconds are unknown (0)
    "${boost[@]}" "${launcher[@]}" "$drt" "$scene" --scale "$scale" -q --stats "$out/s.json" -o "$out/x.pfm" "$@" ||
        status=$?
    [ "$status" -eq 0 ] || [ "$status" -eq 130 ] || { echo "mpi: drt exited $status" >&2; exit 1; }
    local wall
    wall=$(awk -v a="$start" -v b="$(now)" 'BEGIN { print b - a }')
    local f v values=()
    for f in seconds tail_seconds receive assemble; do
        v=$(field "$f" "$out/s.json" 2>/dev/null || true)
        values+=("${v:-0}")
    done
    echo "${values[0]} $wall ${values[1]} ${values[2]} ${values[3]}"
}
mpi() { echo mpirun --oversubscribe -n "$1"; }

# Tiles in the image, for an interrupt half way.
size=$("$drt" info "$scene" --scale "$scale" | sed -n 's/^image: *\([0-9]*\)x\([0-9]*\).*/\1x\2/p')
width=${size%x*} height=${size#*x}
half=$(( ((width + 15) / 16) * ((height + 15) / 16) / 2 ))

variants="plain mpi1 one2 two1 one2g two1g straight cycle"
for v in $variants; do for k in r w t rx as; do : >"$out/$v.$k"; done; done
for round in $(seq "$rounds"); do
    echo "round $round of $rounds ..." >&2
    record() {
        read -r r w t rx as <<<"$2"
        echo "$r" >>"$out/$1.r"; echo "$w" >>"$out/$1.w"; echo "$t" >>"$out/$1.t"
        echo "$rx" >>"$out/$1.rx"; echo "$as" >>"$out/$1.as"
    }
    record plain "$(timed -- --threads 1)"
    record mpi1 "$(timed $(mpi 1) -- --threads 1)"
    record one2 "$(timed -- --threads 2)"
    record two1 "$(timed $(mpi 2) -- --threads 1)"
    record one2g "$(timed -- --threads 2 --grid-order)"
    record two1g "$(timed $(mpi 2) -- --threads 1 --grid-order)"
    record straight "$(timed -- --threads 2 --checkpoint "$out/c.ckpt")"
    read -r r1 w1 _ <<<"$(timed -- --threads 2 --checkpoint "$out/c.ckpt" --stop-after-tiles "$half")"
    read -r r2 w2 _ <<<"$(timed -- --threads 2 --checkpoint "$out/c.ckpt")"
    record cycle "$(awk -v a="$r1" -v b="$r2" -v c="$w1" -v d="$w2" 'BEGIN { print a + b, c + d }')"
done
m() { median <"$out/$1.$2"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a / b }'; }
echo "scene $scene at --scale $scale (${width}x${height}, $(( half * 2 )) tiles), $rounds rounds; medians"
printf '%-44s %10s %10s %10s\n' "" "render s" "wall s" "tail s"
for v in "plain:1 process x 1 thread, no mpirun" "mpi1:mpirun -n 1, 1 thread" \
         "one2:1 process x 2 threads" "two1:mpirun -n 2, 1 thread each" \
         "one2g:1 x 2, tiles in grid order" "two1g:mpirun -n 2 x 1, grid order" \
         "straight:straight through (--checkpoint)" "cycle:stopped half way + resumed"; do
    # The cycle is two runs: no one tail, and render seconds from the resumed run alone (a
    # stopped run writes no stats).
    tail_s=-
    [ "${v%%:*}" = cycle ] || tail_s=$(printf '%.3f' "$(m "${v%%:*}" t)")
    printf '%-44s %10.3f %10.3f %10s\n' "${v#*:}" "$(m "${v%%:*}" r)" "$(m "${v%%:*}" w)" "$tail_s"
done
echo "overhead: MPI path / plain (render seconds)           $(ratio "$(m mpi1 r)" "$(m plain r)")   want <= 1.02"
echo "split:    speed of 2 x 1 thread / 1 x 2 threads       $(ratio "$(m one2 r)" "$(m two1 r)")   want >= 0.95"
echo "resume:   interrupt-and-resume / straight (wall)      $(ratio "$(m cycle w)" "$(m straight w)")"
echo "resume:   seconds lost to the cycle (wall)            $(awk -v a="$(m cycle w)" -v b="$(m straight w)" 'BEGIN { printf "%.3f", a - b }')"
echo "tail:     1 x 2, costly first / grid order            $(m one2 t) / $(m one2g t) s"
echo "tail:     2 x 1, costly first / grid order            $(m two1 t) / $(m two1g t) s"
echo "message:  leader's microseconds per finished tile     receive $(m two1 rx), assemble $(m two1 as)"
