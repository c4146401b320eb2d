#!/usr/bin/env bash
# Usage: tools/compare-modes.sh A B      (A, B: two drt binaries, e.g. a baseline build and this one)
#
# Whether two drt builds behave identically over the render modes: each case runs the same
# command line with A and with B in two fresh folders and compares, byte for byte, every file
# left behind (images as .pfm, checkpoints, partial images), the --stats JSON with its timing
# values blanked, stdout and stderr with times ("0.63 s") blanked, and the exit status.
# Modes: plain (every scene), adaptive (--noise-threshold), --target-error (pilots and top-ups;
# the tool fails if no case made either), each --sampler, --threads 1 and 2, mpirun -n 1..3,
# an interrupted render's checkpoint, its resumption (by the same build, by the other
# build, and under mpirun), a batch, and the messages of bad inputs and of compare and info.
# Left out: --time-limit (its rounds depend on the clock), .exr (its header holds the render
# time) and non-finite pixels (drt after dbec1c4 keeps their image apart, on purpose).
# Prints one line per case and a count; exits 1 on any difference. Small scales: a few minutes.
set -uo pipefail
if [ $# -ne 2 ]; then
    echo "usage: tools/compare-modes.sh A B   (two drt binaries; compares their renders and messages)" >&2
    exit 2
fi
repo=$(cd "$(dirname "$0")/.." && pwd)
bin_a=$(realpath "$1") && bin_b=$(realpath "$2") || exit 2
for b in "$bin_a" "$bin_b"; do
    [ -x "$b" ] || { echo "compare-modes: $b is not an executable" >&2; exit 2; }
done
cases=0 differ=0 skipped=0
work=$(mktemp -d /tmp/compare-modes.XXXXXX)
# Kept when something differs, to look into: $work/a/CASE and $work/b/CASE.
trap '[ "$differ" -eq 0 ] && rm -rf "$work"' EXIT
# Each mpirun keeps its session files here, apart from any other mpirun on the machine.
export OMPI_MCA_orte_tmpdir_base="$work/ompi"
mkdir -p "$work/ompi" "$work/in"
have_mpirun=0
command -v mpirun >/dev/null && have_mpirun=1

# Run-to-run values: wall-clock times and rates, and how many tiles travelled between processes
# (which process renders a tile is scheduling; the image is not).
filter_stats() {
    sed -E 's/"(seconds|tail_seconds|million_rays_per_second)": [^,}]*/"\1": T/g
            s/"tile_messages": [0-9]+/"tile_messages": T/
            s/"microseconds_per_message": \{[^}]*\}/"microseconds_per_message": T/' "$1"
}
# Times in messages ("0.63 s", "0.145 s"; "100 spp" is left alone) and the seconds and Mrays/s
# columns of a batch's table.
filter_text() {
    sed -E 's/[0-9]+(\.[0-9]+)?(e[-+]?[0-9]+)? s\b/T s/g
            s/^(\S+\s+[0-9]+x[0-9]+\s+[0-9]+)\s+[0-9.]+\s+[0-9.]+\s/\1 T T /' "$1"
}

# run SIDE CASE STEP BINARY [mpi K] -- ARGS: runs in $work/SIDE/CASE, keeping STEP's stdout,
# stderr and status there as STEP.out, STEP.err, STEP.rc.
run() {
    local side=$1 name=$2 step=$3 bin=$4
    shift 4
    local launcher=()
    if [ "$1" = mpi ]; then
        launcher=(mpirun --allow-run-as-root --oversubscribe -n "$2")
        shift 2
    fi
    shift # --
    local dir="$work/$side/$name"
    mkdir -p "$dir"
    (cd "$dir" && "${launcher[@]}" "$bin" "$@" >"$step.out" 2>"$step.err"; echo $? >"$step.rc")
}

# Compares everything in the two folders of CASE; prints one line.
compare() {
    local name=$1 what=$2
    local da="$work/a/$name" db="$work/b/$name" found=()
    cases=$((cases + 1))
    local la lb
    la=$(cd "$da" && find . -type f | sort) lb=$(cd "$db" && find . -type f | sort)
    [ "$la" = "$lb" ] || found+=("files: ${la//$'\n'/ } vs ${lb//$'\n'/ }")
    local f
    for f in $la; do
        [ -f "$db/$f" ] || continue
        case "$f" in
        *.json) cmp -s <(filter_stats "$da/$f") <(filter_stats "$db/$f") || found+=("${f#./}") ;;
        *.err | *.out) cmp -s <(filter_text "$da/$f") <(filter_text "$db/$f") || found+=("${f#./}") ;;
        *) cmp -s "$da/$f" "$db/$f" || found+=("${f#./}") ;;
        esac
    done
    if [ ${#found[@]} -eq 0 ]; then
        printf 'same     %-22s %s\n' "$name" "$what"
    else
        differ=$((differ + 1))
        printf 'DIFFER   %-22s %s: %s\n' "$name" "$what" "${found[*]}"
    fi
}

# Names the next case's folders: a number and a kind.
n=0 id=
next() {
    n=$((n + 1))
    id=$(printf '%03d-%s' $n "$1")
}

# both KIND [mpi K] -- ARGS: one step with A and with B, then the comparison.
both() {
    next "$1"
    shift
    run a "$id" run "$bin_a" "$@"
    run b "$id" run "$bin_b" "$@"
    local args=("$@")
    [ "${args[0]}" = mpi ] && args=("mpirun -n ${args[1]}" "${args[@]:3}") || args=("${args[@]:1}")
    local shown=${args[*]//$repo\//}
    compare "$id" "${shown//$work\//}"
}

skip() {
    skipped=$((skipped + 1))
    printf 'skipped  %-22s %s\n' "$1" "$2"
}

s() { echo "$repo/scenes/$1"; }

echo "compare-modes: A = $bin_a"
echo "compare-modes: B = $bin_b"

# Plain: every scene, with statistics and messages.
for scene in "$repo"/scenes/*.xml "$repo"/scenes/*/*.xml; do
    both plain -- "$scene" --scale 0.1 --threads 2 -o out.pfm --stats stats.json
done

# Adaptive sampling.
for t in 1 2 3 4 5 6; do
    both adaptive -- "$(s thesis/test$t.xml)" --scale 0.1 --noise-threshold 0.02 \
        -o out.pfm --stats stats.json
done
both adaptive -- "$(s example.xml)" --scale 0.25 --noise-threshold 0.01 --min-spp 4 \
    -o out.pfm --stats stats.json

# Target error: a pilot of one pixel in b x b (at 0.25), full rounds and top-ups.
for scale in 0.1 0.25; do
    for e in 0.01 0.005; do
        for t in 1 2 3 4 5 6; do
            both target -- "$(s thesis/test$t.xml)" --scale $scale --target-error $e \
                -o out.pfm --stats stats.json
        done
    done
done
both target -- "$(s thesis/test2.xml)" --scale 0.1 --target-error 0.01 --spp 20 \
    -o out.pfm --stats stats.json --error-image error.pfm
pilots=$(cat "$work"/a/*-target/*.json | grep -o '"pilot_pixel_block"' | wc -l)
top_ups=$(cat "$work"/a/*-target/*.json | grep -o '"top_up_share"' | wc -l)
echo "compare-modes: the target-error cases made $pilots pilot and $top_ups top-up rounds (A)"
if [ "$pilots" -eq 0 ] || [ "$top_ups" -eq 0 ]; then
    echo "compare-modes: no pilot or no top-up: the target-error cases prove too little" >&2
    differ=$((differ + 1))
fi

# Samplers, plain, adaptive and with a target error.
for sampler in stratified sobol random; do
    for scene in thesis/test2.xml example.xml figures/depth-of-field.xml meshes/moving-teapot.xml; do
        both sampler -- "$(s $scene)" --scale 0.1 --sampler $sampler -o out.pfm \
            --stats stats.json
    done
    both sampler -- "$(s thesis/test3.xml)" --scale 0.1 --sampler $sampler \
        --noise-threshold 0.02 -o out.pfm --stats stats.json
    both sampler -- "$(s thesis/test6.xml)" --scale 0.25 --sampler $sampler \
        --target-error 0.01 -o out.pfm --stats stats.json
done

# Threads.
for threads in 1 2; do
    for scene in thesis/test4.xml meshes/glass-bunny.xml; do
        both threads -- "$(s $scene)" --scale 0.1 --threads $threads -o out.pfm \
            --stats stats.json
    done
    both threads -- "$(s thesis/test2.xml)" --scale 0.25 --threads $threads \
        --target-error 0.01 -o out.pfm --stats stats.json
done

# Several processes.
for k in 1 2 3; do
    if [ $have_mpirun -eq 0 ]; then
        skip "mpi" "mpirun -n $k: mpirun is not installed"
        continue
    fi
    both mpi mpi $k -- "$(s thesis/test2.xml)" --scale 0.1 --threads 1 -o out.pfm \
        --stats stats.json
    both mpi mpi $k -- "$(s thesis/test3.xml)" --scale 0.1 --threads 1 \
        --noise-threshold 0.02 -o out.pfm --stats stats.json
    both mpi mpi $k -- "$(s thesis/test2.xml)" --scale 0.25 --threads 1 \
        --target-error 0.01 -o out.pfm --stats stats.json
    both mpi mpi $k -- "$(s thesis/test6.xml)" --scale 0.1 --threads 1 --sampler sobol \
        -o out.pfm --stats stats.json
done

# A batch into a folder.
both batch -- "$(s thesis/test1.xml)" "$(s figures/glass-rim.xml)" \
    "$(s meshes/checker-teapot.xml)" --scale 0.1 -o batch/ --stats stats.json

# Checkpoints: interrupted after some tiles (one thread, so that which tiles are done is the same
# every run), then resumed by the same build, by the other build, and under mpirun.
checkpoint() {
    local name=$1
    shift
    next "$name"
    local c=$id
    local args=("$@" --threads 1 -o out.pfm --checkpoint ck --checkpoint-every 0)
    run a "$c" interrupt "$bin_a" -- "${args[@]}" --stop-after-tiles 5
    run b "$c" interrupt "$bin_b" -- "${args[@]}" --stop-after-tiles 5
    compare "$c" "interrupted: ${*//$repo\//} (checkpoint, partial image)"
    for side in a b; do
        for to in cross mpi; do
            mkdir -p "$work/$side/$c-$to"
            cp "$work/$side/$c"/{ck,out.partial.pfm} "$work/$side/$c-$to/"
        done
    done
    run a "$c" resume "$bin_a" -- "${args[@]}" --stats stats.json
    run b "$c" resume "$bin_b" -- "${args[@]}" --stats stats.json
    compare "$c" "resumed by the same build"
    run a "$c-cross" resume "$bin_b" -- "${args[@]}"
    run b "$c-cross" resume "$bin_a" -- "${args[@]}"
    compare "$c-cross" "A's checkpoint resumed by B, B's by A"
    cases=$((cases + 1))
    if cmp -s "$work/a/$c/out.pfm" "$work/a/$c-cross/out.pfm"; then
        printf 'same     %-22s %s\n' "$c-cross" "B's image from A's checkpoint is A's own resumed image"
    else
        differ=$((differ + 1))
        printf 'DIFFER   %-22s %s\n' "$c-cross" "B's image from A's checkpoint is not A's own resumed image"
    fi
    if [ $have_mpirun -eq 1 ]; then
        run a "$c-mpi" resume "$bin_a" mpi 2 -- "${args[@]}"
        run b "$c-mpi" resume "$bin_b" mpi 2 -- "${args[@]}"
        compare "$c-mpi" "resumed under mpirun -n 2"
    else
        skip "$c-mpi" "resumed under mpirun: mpirun is not installed"
    fi
}
checkpoint checkpoint "$(s thesis/test2.xml)" --scale 0.1
checkpoint checkpoint "$(s thesis/test3.xml)" --scale 0.1 --noise-threshold 0.02
checkpoint checkpoint "$(s thesis/test6.xml)" --scale 0.1 --sampler sobol

# Bad inputs, and the other commands: messages, output and exit status. The input files are
# shared by both sides.
printf '<Scene>\n  <Image Width="4" Height="4"\n</Scene>\n' >"$work/in/broken.xml"
sed 's/<Sphere /<Sphere Bogus="1" /' "$repo/scenes/example.xml" >"$work/in/unknown.xml"
sed 's/Material="[^"]*"/Material="nothing"/' "$repo/scenes/example.xml" >"$work/in/material.xml"
bad=("$work/in/missing.xml"
    "$work/in/broken.xml"
    "$work/in/unknown.xml --scale 0.25 -o out.pfm"
    "$work/in/material.xml"
    "$(s example.xml) --bogus"
    "$(s example.xml) --spp 0"
    "$(s example.xml) --threads many"
    "$(s example.xml) -o out.jpg"
    "$(s example.xml) --scale nan"
    "$(s example.xml) --width 70000"
    "$(s example.xml) --target-error 0.01 --checkpoint ck"
    "$(s example.xml) --min-spp 4"
    "$(s example.xml) --aov albedo -o out.pfm"
    "$(s example.xml) --stats $work/in/no/such/folder/s.json"
    "compare $work/in/missing.pfm $work/in/missing.pfm"
    "compare $repo/docs/images/aa-10spp.png $repo/docs/images/aa-1spp.png --diff diff.png"
    "compare $repo/docs/images/aa-10spp.png $repo/docs/images/checker-teapot.png"
    "compare $repo/docs/images/aa-10spp.png $repo/docs/images/aa-1spp.png --max-rmse 0.01"
    "info $work/in/broken.xml"
    "info $(s thesis/test2.xml) --scale 0.1 --target-error 0.01"
    "--version")
for line in "${bad[@]}"; do
    read -r -a args <<<"$line"
    both message -- "${args[@]}"
done

echo "compare-modes: $((cases - differ)) of $cases cases identical, $differ differ, $skipped skipped" \
    "(A $bin_a, B $bin_b)"
[ "$differ" -eq 0 ] || echo "compare-modes: each case's files are kept in $work/{a,b}/CASE"
[ "$differ" -eq 0 ]
