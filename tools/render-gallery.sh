#!/usr/bin/env bash
# Renders every thesis scene, single-effect figure, mesh, caustic (scenes/caustics/) and path-traced
# scene (scenes/gi/) at its own settings into docs/images/ and rewrites docs/gallery.md with each
# image, its settings and its render time on this machine.
# Usage: tools/render-gallery.sh [extra drt options, e.g. --threads 2]
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target drt >/dev/null

declare -A caption=(
    [test1]="Test1: five diffuse planes (checker floor), a yellow diffuse sphere and the thesis's aqua glass sphere (index 1.6, n 1000), two spherical lights: soft shadows, glossy refraction, Fresnel reflection on the glass."
    [test2]="Test2: depth of field focused on the far white sphere; the near checker and marble spheres are blurred."
    [test3]="Test3: the same scene focused on the near spheres; the far sphere and the back wall blur."
    [test4]="Test4: bump-mapped walls, checker floor, a red diffuse sphere and a matte metal sphere (reflective 0.85, n 25) with blurry reflections."
    [test5]="Test5: the green sphere moves along a bouncing arc (motion blur, uniform time); glossy floor; mild depth of field."
    [test6]="Test6: a red transparent sphere tints what lies behind it; two lights behind it cast shadows whose penumbrae merge; depth of field."
    [aa-1spp]="One camera ray per pixel through the pixel centre: the checker floor aliases towards the horizon."
    [aa-10spp]="Ten jittered camera rays per pixel: the same scene antialiased."
    [soft-shadow-one-light]="A penumbra from one spherical light (radius 40)."
    [soft-shadow-two-lights]="Two spherical lights of half the power: two shadows whose penumbrae merge."
    [depth-of-field]="Thin lens (radius 15) focused on the two front spheres; the rest blurs with distance."
    [motion-blur]="A sphere moving along +x through eight past positions, time uniform over the shutter, beside a static sphere: a streak of even density."
    [glossy-n10]="A glossy floor with n = 10 (σ = 0.1): blurred reflections of three spheres and a checker wall, like sand-blasted metal."
    [glossy-n500]="The same floor with n = 500 (σ = 0.002): a nearly sharp reflection."
    [refraction-n10]="Blurry refraction through a clear sphere (index 1.5, n = 10) in front of a checker wall: frosted glass."
    [refraction-n500]="Refraction with n = 500: nearly clear glass."
    [glass-rim]="An ideal glass sphere (index 1.5) on a checker floor: the Fresnel reflection of the sky-blue background grows towards the rim."
    [glass-bunny]="Test1's room with the glass sphere replaced by the Stanford bunny (69 451 triangles) in the thesis's Glass made glossy (n 200): blurry refraction, soft shadows of a mesh from two lights."
    [spot-marble]="Spot the cow (5 856 triangles) in marble on a checker floor, depth of field focused on the cow; a near and a far sphere blur."
    [moving-teapot]="A porcelain Utah teapot (6 320 triangles) sliding to the right while the shutter is open (motion blur of a mesh), beside a glossy copper teapot standing still."
    [cornell-box]="The Cornell box path traced: lit only by its ceiling lamp (an emitting quad), every other light indirect; the red and green walls bleed their colours onto the white boxes and the ceiling."
    [test1-room]="Test1's room path traced (Integrator=\"path\", no Ambient): the same two thesis lights, now with the light that bounces off the walls (56 % of the image's light, docs/accuracy.md section 8), which makes the room far brighter (the thesis lights do not fall off with distance); compare test1 above, the distributed original."
    [glossy-mis]="Veach's plates: four glossy plates (n 5, 20, 80, 500) mirror four emitting spheres of equal power and growing size; the rough plates' reflections of the small bright spheres stay noisy, since glossy lobes are sampled by the scattered ray alone."
    [test1-caustic]="Test1's room with its second light made physical (Falloff 1, radius 10): the ideal aqua glass sphere focuses it into a caustic on the floor in front of it (photon maps, one pass per sample)."
    [ring-cardioid]="A gold mirror ring (an open cylinder, ring.obj) under a low Falloff-1 point light: the light reflected off its inside gathers into a cardioid on the floor."
    [glass-bunny-caustic]="The glass bunny in ideal aqua glass under Test1-caustic's Falloff-1 light: the bunny's caustic on the floor."
    [obj-house]="A house in its OBJ file's own MTL materials: textured glossy roof (map_Kd), see-through window, emitting lamp, and a picket fence cut out of two quads by map_d, whose shadow on the grass has the gaps between the pickets."
    [checker-teapot]="A checker-textured teapot under a red sphere whose soft shadow falls onto it, Spot in bump-mapped glossy gold, and a single Triangle as a glossy mirror behind them."
)

mkdir -p docs/images
stats=$(mktemp)
body=$(mktemp)
trap 'rm -f "$stats" "$body"' EXIT
field() { sed -n "s/.*\"$1\": *\([0-9.e+-]*\).*/\1/p" "$stats" | head -n1; }

for scene in scenes/thesis/*.xml scenes/figures/*.xml scenes/meshes/*.xml scenes/assets/obj-house.xml \
    scenes/gi/*.xml scenes/caustics/*.xml; do
    name=$(basename "$scene" .xml)
    build/drt "$scene" -o "docs/images/$name.png" --stats "$stats" -q "$@"
    seconds=$(printf '%.1f' "$(field seconds)")
    echo "rendered $scene in $seconds s"
    {
        echo "### $name"
        echo
        echo "![$name](images/$name.png)"
        echo
        echo "${caption[$name]:-}"
        echo
        photons=$(field photons)
        printf '`%s`: %sx%s, %s samples per pixel, %s shadow rays%s, %s s (%.1f million rays/s).\n\n' \
            "$scene" "$(field width)" "$(field height)" "$(field samples_per_pixel)" \
            "$(field shadow_rays)" "${photons:+, $photons photons}" "$seconds" \
            "$(field million_rays_per_second)"
    } >>"$body"
done

{
    echo "# Gallery"
    echo
    echo "Every thesis scene, single-effect figure, mesh, caustic and path-traced scene of \`scenes/\`, rendered at its own settings"
    echo "by \`tools/render-gallery.sh\` on $(nproc) cores of $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n1) ($(date -u +%F), commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown))."
    echo "Times are wall-clock for the whole render on this machine (compare them only with times from the same processor); see docs/performance.md for"
    echo "side-by-side measurements. Scene details: [scenes/README.md](../scenes/README.md)."
    echo
    cat "$body"
} >docs/gallery.md.tmp
mv docs/gallery.md.tmp docs/gallery.md
echo "wrote docs/images/*.png and docs/gallery.md"
