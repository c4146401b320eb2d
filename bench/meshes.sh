#!/usr/bin/env bash
# drt's mesh hierarchy against Embree 3 (docs/performance.md, "Meshes against Embree"): on the Stanford bunny
# (69k triangles) and on the bunny subdivided twice (1.1 M triangles, written to a temporary
# folder, not kept), the same camera and shadow rays of scenes/meshes/glass-bunny.xml traced by
# both on 2 threads, alternating round after round; then the peak memory of a render of the
# 1.1 M-triangle bunny in that scene under GNU time.
# Usage: bench/meshes.sh [BUILD_DIR] [--spp N] [--rounds N]
#   BUILD_DIR configured with -DDRT_BUILD_BENCH=ON and Embree installed (tools/install-deps.sh --bench)
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
args=()
while [ $# -gt 0 ]; do
    case "$1" in
        --spp | --rounds) args+=("$1" "$2"); shift 2 ;;
        *) build=$1; shift ;;
    esac
done
race=$build/bench/drt_mesh_race
[ -x "$race" ] || { echo "no $race: configure with -DDRT_BUILD_BENCH=ON and install libembree-dev" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=scenes/meshes/glass-bunny.xml
# High priority on both cores, so that neighbours' work disturbs the two sides alike.
fast=(nice -n -20 taskset -c 0,1)
[ "$(id -u)" -eq 0 ] || fast=(taskset -c 0,1)

echo "== bunny (69k triangles)"
"${fast[@]}" "$race" "$scene" --spp 4 "${args[@]}"
echo "== bunny subdivided twice"
"${fast[@]}" "$race" "$scene" --spp 4 --subdivide 2 --write-obj "$tmp/bunny-1m.obj" "${args[@]}"

# The same room with the subdivided bunny, placed by its file (written in the scene's coordinates).
sed -E "s|<Mesh File=\"[^\"]*\"([^/]*) Scale=\"[^\"]*\" RotateY=\"[^\"]*\" Tx=\"[^\"]*\" Ty=\"[^\"]*\" Tz=\"[^\"]*\"|<Mesh File=\"$tmp/bunny-1m.obj\"\1|" \
    "$scene" > "$tmp/bunny-1m.xml"
grep -q "bunny-1m.obj" "$tmp/bunny-1m.xml" || { echo "could not place the subdivided bunny" >&2; exit 1; }
echo "== render of the 1.1 M-triangle bunny (800 x 600, 4 spp, 2 threads)"
/usr/bin/time -v "${fast[@]}" "$build/drt" "$tmp/bunny-1m.xml" --spp 4 --threads 2 -o "$tmp/bunny-1m.png" \
    2> "$tmp/time.txt" >/dev/null
awk -F': ' '/Maximum resident/ { printf "peak memory %.1f MiB\n", $2 / 1024 }
            /Elapsed \(wall/ { print "wall clock " $2 }' "$tmp/time.txt"
