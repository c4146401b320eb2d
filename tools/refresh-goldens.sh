#!/usr/bin/env bash
# Remakes the golden references in tests/golden/ and prints, per scene, how the test render compared
# with the old reference (before) and the new one (after), and whether the expected image itself
# changed or only its noise. See docs/testing.md. Run it on purpose, after a change that alters
# images, and commit what it wrote together with that change.
#
#   tools/refresh-goldens.sh                          every scene in scenes/
#   tools/refresh-goldens.sh thesis/test1.xml …       only these (paths inside scenes/, or scenes/…)
#   tools/refresh-goldens.sh --renders 128 …          more seeds per reference (default 64)
#
# Environment: DRT_GOLDEN_BUILD, the build folder to use (default build, Release).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${DRT_GOLDEN_BUILD:-build}

args=()
scenes=()
while (($#)); do
    case $1 in
        --renders) args+=("$1" "$2"); shift 2 ;;
        -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
        -*) echo "refresh-goldens: unknown option $1" >&2; exit 2 ;;
        *) scenes+=("${1#scenes/}"); shift ;;
    esac
done

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)" --target drt_golden >/dev/null

status=0
"$build/tests/drt_golden" refresh scenes tests/golden "${args[@]}" "${scenes[@]}" || status=$?

# A full refresh also drops the references of scenes that no longer exist.
if ((${#scenes[@]} == 0)); then
    while IFS= read -r description; do
        base=${description%.txt}
        if [[ ! -f scenes/${base#tests/golden/}.xml ]]; then
            echo "removed ${base}.{pfm,var.pfm,txt}: scenes/${base#tests/golden/}.xml is gone"
            rm -f "$base.pfm" "$base.var.pfm" "$base.txt"
        fi
    done < <(find tests/golden -name '*.txt' | sort)
fi

if command -v git >/dev/null && git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    echo
    echo "files that differ from the last commit:"
    git status --short tests/golden
fi
exit "$status"
