#!/usr/bin/env bash
# Writes a scene of N moving spheres to stdout: a floor and a back wall lit by one round light,
# the spheres scattered through the same box whatever N, each moving about its own radius over
# the shutter, their radii shrinking as N grows so that together they cover about the same share
# of the image. Used by bench/ratios.sh to compare the cost per camera ray of 10 and 1,000.
# Usage: bench/spheres.sh N [WIDTH HEIGHT SPP SHADOW_RAYS]
set -euo pipefail
n=${1:?usage: spheres.sh N [WIDTH HEIGHT SPP SHADOW_RAYS]}
width=${2:-400}
height=${3:-300}
spp=${4:-16}
shadow=${5:-4}
awk -v n="$n" -v w="$width" -v h="$height" -v spp="$spp" -v shadow="$shadow" 'BEGIN {
    printf "<?xml version=\"1.0\"?>\n<Scene>\n"
    printf "  <Image Width=\"%d\" Height=\"%d\"/>\n", w, h
    printf "  <Render Samples=\"%d\" ShadowRays=\"%d\" MaxDepth=\"4\" Seed=\"1\"/>\n", spp, shadow
    printf "  <Ambient r=\"0.05\" g=\"0.05\" b=\"0.05\"/>\n"
    printf "  <Camera Ex=\"0\" Ey=\"300\" Ez=\"-900\" Lx=\"0\" Ly=\"200\" Lz=\"300\" Fov=\"45\"/>\n"
    printf "  <Materials>\n"
    printf "    <Floor kdr=\"0.7\" kdg=\"0.7\" kdb=\"0.7\" diffuse=\"1\"/>\n"
    printf "    <Red kdr=\"0.8\" kdg=\"0.2\" kdb=\"0.1\" diffuse=\"1\"/>\n"
    printf "    <Blue kdr=\"0.1\" kdg=\"0.3\" kdb=\"0.8\" diffuse=\"1\"/>\n"
    printf "  </Materials>\n"
    printf "  <Light Px=\"-200\" Py=\"900\" Pz=\"-200\" Radius=\"60\" Ir=\"0.9\" Ig=\"0.9\" Ib=\"0.9\"/>\n"
    printf "  <Plane Px=\"0\" Py=\"0\" Pz=\"0\" Vu=\"0\" Vv=\"1\" Vw=\"0\" Material=\"Floor\"/>\n"
    printf "  <Plane Px=\"0\" Py=\"0\" Pz=\"900\" Vu=\"0\" Vv=\"0\" Vw=\"-1\" Material=\"Floor\"/>\n"
    # The spheres fill 3% of a 800 x 400 x 600 box, so a ray meets a similar number whatever n.
    r = (0.03 * 800 * 400 * 600 / (n * 4.18879)) ^ (1 / 3)
    seed = 12345
    for (i = 0; i < n; ++i) {
        x = -400 + 800 * rnd(); y = r + (400 - 2 * r) * rnd(); z = 600 * rnd()
        printf "  <Sphere Px=\"%.3f\" Py=\"%.3f\" Pz=\"%.3f\" Radius=\"%.3f\" Material=\"%s\">", x, y, z, r, (i % 2 ? "Red" : "Blue")
        printf "<MotionBlurPosition Px=\"%.3f\" Py=\"%.3f\" Pz=\"%.3f\"/></Sphere>\n", x + r * (2 * rnd() - 1), y, z + r * (2 * rnd() - 1)
    }
    printf "</Scene>\n"
}
# A fixed linear congruential sequence, so every run writes the same scene.
function rnd() { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648 }'
