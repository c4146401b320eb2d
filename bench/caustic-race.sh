#!/usr/bin/env bash
# The caustic race with POV-Ray 3.7: scenes/caustics/test1-caustic.xml against its twin
# bench/test1-caustic.pov (POV-Ray's photon mapping), both at 200 x 150 on 2 threads with both
# lights dimmed to 0.1 (POV-Ray's 16-bit output clips at 1). Each renderer is measured against
# its own converged reference (drt: 1024 samples with another seed; POV-Ray: 4 million photons,
# 5 x 5 antialiasing), over the 28 x 12 pixels around the caustic on the floor; the error is that
# window's RMSE over the reference window's RMS. Prints one line per render: renderer, setting,
# seconds, relative caustic error.
# Usage: bench/caustic-race.sh [--drt PATH]   (needs povray and python3)
set -euo pipefail
cd "$(dirname "$0")/.."
drt=build/drt
[ "${1:-}" = --drt ] && drt=$2
drt=$(realpath "$drt")
command -v povray >/dev/null || { echo "caustic-race: needs povray: tools/install-deps.sh --bench" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
sed 's|Ir="0.4" Ig="0.4" Ib="0.4"|Ir="0.04" Ig="0.04" Ib="0.04"|; s|Ir="4e4" Ig="4e4" Ib="4e4"|Ir="4e3" Ig="4e3" Ib="4e3"|' \
    scenes/caustics/test1-caustic.xml >"$out/scene.xml"
pov=$(realpath bench/test1-caustic.pov)
now() { date +%s.%N; }

# window_error REFERENCE IMAGE: the caustic window's RMSE over the reference window's RMS.
window_error() {
    python3 - "$1" "$2" <<'PY'
import math, struct, sys
def read(path):
    d = open(path, 'rb').read()
    if d[:2] == b'PF':  # drt's .pfm: bottom row first
        lines = d.split(b'\n', 3)
        w, h = map(int, lines[1].split()); scale = float(lines[2])
        v = struct.unpack(('<' if scale < 0 else '>') + '%df' % (w * h * 3), lines[3][:w * h * 12])
        rows = [[v[(y * w + x) * 3:(y * w + x) * 3 + 3] for x in range(w)] for y in range(h)]
        return rows[::-1]
    fields, i = [], 2  # POV-Ray's 16-bit .ppm
    while len(fields) < 3:
        while d[i:i + 1].isspace(): i += 1
        if d[i:i + 1] == b'#':  # a comment runs to the end of its line
            i = d.index(b'\n', i)
            continue
        j = i
        while not d[j:j + 1].isspace(): j += 1
        fields.append(int(d[i:j])); i = j
    w, h, top = fields; i += 1
    v = struct.unpack('>%dH' % (w * h * 3), d[i:i + w * h * 6])
    return [[[v[(y * w + x) * 3 + c] / top for c in range(3)] for x in range(w)] for y in range(h)]
ref, img = read(sys.argv[1]), read(sys.argv[2])
se = ss = n = 0
for y in range(138, 150):
    for x in range(98, 126):
        for c in range(3):
            se += (img[y][x][c] - ref[y][x][c]) ** 2; ss += ref[y][x][c] ** 2; n += 1
print('%.4f' % math.sqrt(se / ss))
PY
}

render_drt() {  # SPP [SEED] -> out/drt-SPP.pfm, prints seconds
    local t0; t0=$(now)
    "$drt" "$out/scene.xml" --scale 0.25 --spp "$1" --seed "${2:-0}" --threads 2 -q -o "$out/drt-$1.pfm"
    awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'
}
render_pov() {  # PHOTONS R -> out/pov-PHOTONS-R.ppm, prints seconds
    local t0; t0=$(now)
    povray +I"$pov" +W200 +H150 Declare=Photons="$1" Declare=Dim=0.1 +AM1 +A0.0 +R"$2" -D \
        +FP16 File_Gamma=1.0 +O"$out/pov-$1-$2.ppm" +WT2 >/dev/null 2>&1
    awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'
}

echo "references (not timed against each other)"
render_drt 1024 1 >/dev/null && mv "$out/drt-1024.pfm" "$out/drt-ref.pfm"
render_pov 4000000 5 >/dev/null && mv "$out/pov-4000000-5.ppm" "$out/pov-ref.ppm"
for spp in 4 16 64 256; do
    s=$(render_drt "$spp")
    echo "drt spp $spp: $s s, caustic error $(window_error "$out/drt-ref.pfm" "$out/drt-$spp.pfm")"
done
for p in 20000 100000 500000; do
    for r in 2 3; do
        s=$(render_pov "$p" "$r")
        echo "povray photons $p +R$r: $s s, caustic error $(window_error "$out/pov-ref.ppm" "$out/pov-$p-$r.ppm")"
    done
done
