// Each distributed effect rendered and compared with what geometry alone predicts: the umbra and
// penumbra of a sphere under a spherical light, the hard shadow of a point light, the blur
// circle of a thin lens, the streak of a sphere moving under uniform time; and the effect
// flags and ray counts `drt --stats` reports for scenes calling for some effects but not others.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "drt/render/renderer.h"
#include "drt/shading/texture.h"
#include "test_render.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::add_material;
using testing::render_with;

// Where a floor pixel's camera ray lands (the floor is y = 0).
Vec3 on_floor(const Camera& camera, Vec2 film) {
    const Ray ray = camera.generate_ray(film, {0.5, 0.5}, 0);
    return ray.at(-ray.origin.y / ray.dir.y);
}

// --- Shadows -----------------------------------------------------------------------------------

// A floor (kd 0.8) under ambient 0.1, a sphere of radius 10 at height 40 and a light at height
// 200 straight above it; the camera hangs at height 20, below the sphere, looking down at the
// shadow, so nothing hides it. 64 x 64 pixels span 40 x 40 floor units (0.625 a pixel).
constexpr double kLightHeight = 200, kOccluderHeight = 40, kOccluderRadius = 10;
constexpr double kAmbient = 0.08;  // diffuse x kd x ambient
constexpr int kShadowSize = 64;

Scene shadow_scene(double light_radius, int samples, int shadow_rays) {
    Scene scene = testing::floor_scene(kShadowSize, kShadowSize, 20);
    scene.view->fov_degrees = 90;
    scene.settings.samples = samples;
    scene.settings.shadow_rays = shadow_rays;
    scene.ambient = {0.1, 0.1, 0.1};
    const Material& grey = *scene.materials.front();
    scene.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{0, kOccluderHeight, 0}},
                                                     kOccluderRadius, grey));
    const Vec3 light{0, kLightHeight, 0};
    if (light_radius > 0) {
        scene.lights.push_back(
            std::make_unique<SphereLight>(light, light_radius, Color{1, 1, 1}, false));
    } else {
        scene.lights.push_back(std::make_unique<PointLight>(light, Color{1, 1, 1}));
    }
    return scene;
}

// How a floor point sees the light past the occluder, from the angular radii of the two spheres
// and the angle between their centres: -1 inside the umbra, +1 fully lit, 0 in the penumbra,
// each with `margin` radians to spare.
int shadow_class(const Vec3& p, double light_radius, double margin) {
    const Vec3 to_light = Vec3{0, kLightHeight, 0} - p,
               to_occluder = Vec3{0, kOccluderHeight, 0} - p;
    const double light_angle = std::asin(light_radius / length(to_light));
    const double occluder_angle = std::asin(kOccluderRadius / length(to_occluder));
    const double between =
        std::acos(std::min(1.0, dot(normalize(to_light), normalize(to_occluder))));
    if (between + light_angle < occluder_angle - margin) return -1;
    if (between > light_angle + occluder_angle + margin) return +1;
    return 0;
}

// Unoccluded light on the floor at p: (1/Omega) times the integral of N.w over the light's cap,
// which is (1 + cos alpha)/2 times N.c for a cap of half-angle alpha about c.
double lit_value(const Vec3& p, double light_radius) {
    const Vec3 to_light = Vec3{0, kLightHeight, 0} - p;
    const double cos_alpha = std::sqrt(1 - std::pow(light_radius / length(to_light), 2));
    return kAmbient + 0.8 * (1 + cos_alpha) / 2 * normalize(to_light).y;
}

TEST(Effects, UmbraAndPenumbraFallWhereTheSpheresTangentConesPutThem) {
    for (const double light_radius : {10.0, 20.0}) {
        SCOPED_TRACE(light_radius);
        const Scene scene = shadow_scene(light_radius, 1, 64);
        const RenderResult r = render_with(scene);
        const Camera camera = scene.camera();
        int umbra = 0, lit = 0, penumbra = 0;
        for (int y = 0; y < kShadowSize; ++y) {
            for (int x = 0; x < kShadowSize; ++x) {
                // One sample per pixel: the ray goes through the pixel centre.
                const Vec3 p = on_floor(camera, {x + 0.5, y + 0.5});
                const double v = r.image.at(x, y).r;
                switch (shadow_class(p, light_radius, 1e-6)) {
                    case -1:  // every shadow ray meets the sphere: ambient light only
                        ++umbra;
                        ASSERT_FLOAT_EQ(v, kAmbient) << x << "," << y;
                        break;
                    case +1:
                        ++lit;
                        ASSERT_NEAR(v, lit_value(p, light_radius), 5e-4) << x << "," << y;
                        break;
                    default:
                        // Near its edges the partly hidden light may escape every shadow ray.
                        ++penumbra;
                        ASSERT_GE(v, static_cast<float>(kAmbient)) << x << "," << y;
                        ASSERT_LT(v, lit_value(p, light_radius) + 5e-4) << x << "," << y;
                }
            }
        }
        EXPECT_GT(umbra, 100);
        EXPECT_GT(penumbra, 200);
        EXPECT_GT(lit, 500);

        // Along the middle row, the penumbra is the band where the light is partly hidden. Similar
        // triangles through the spheres' rims (treated as disks facing the floor) put its inner
        // and outer edges at (a H -+ R h) / (H - h) from the centre, R the light's radius, a the
        // occluder's, H and h their heights.
        const double units_per_pixel = 40.0 / kShadowSize;
        const double h = kOccluderHeight, H = kLightHeight, a = kOccluderRadius;
        const double inner = (a * H - light_radius * h) / (H - h) / units_per_pixel;
        const double outer = (a * H + light_radius * h) / (H - h) / units_per_pixel;
        const int row = kShadowSize / 2;
        double measured_inner = 0, measured_outer = 0;
        for (int x = kShadowSize / 2; x < kShadowSize; ++x) {
            const double v = r.image.at(x, row).r;
            const double from_centre = x + 0.5 - kShadowSize / 2.0;
            if (v == static_cast<float>(kAmbient)) measured_inner = from_centre;
            if (v < lit_value(on_floor(camera, {x + 0.5, row + 0.5}), light_radius) - 1e-3) {
                measured_outer = from_centre;
            }
        }
        // The last pixel centres inside each edge lie within a pixel of it.
        EXPECT_NEAR(measured_inner, inner, 1.0);
        EXPECT_NEAR(measured_outer, outer, 1.0);
        EXPECT_NEAR(measured_outer - measured_inner, outer - inner, 1.5);
    }
}

// The light on a floor point at the origin (normal +y) from a light past a sphere:
// (1/Omega) Int_cap N . w V dw, integrated in the test by a midpoint rule over the cap (uniform
// in solid angle) with an exact ray-sphere test for V.
double light_past_sphere(const Vec3& light, double light_radius, const Vec3& occluder,
                         double occluder_radius) {
    const double cos_alpha = std::sqrt(1 - std::pow(light_radius / length(light), 2));
    const Vec3 axis = normalize(light);
    const Vec3 t = normalize(cross(axis, Vec3{0, 0, 1})), b = cross(axis, t);
    constexpr int kGrid = 600;
    double sum = 0;
    for (int i = 0; i < kGrid; ++i) {
        const double cos_theta = 1 - (i + 0.5) / kGrid * (1 - cos_alpha);
        const double sin_theta = std::sqrt(1 - cos_theta * cos_theta);
        for (int j = 0; j < kGrid; ++j) {
            const double phi = 2 * kPi * (j + 0.5) / kGrid;
            const Vec3 w = t * (sin_theta * std::cos(phi)) + b * (sin_theta * std::sin(phi)) +
                           axis * cos_theta;
            const double along = dot(occluder, w);
            const double miss2 = dot(occluder, occluder) - along * along;
            if (!(along > 0 && miss2 < occluder_radius * occluder_radius)) sum += w.y;
        }
    }
    return sum / (kGrid * kGrid);
}

TEST(Effects, SphereGrazingTheLightsConeHidesItsShareOfTheLight) {
    // A light of angular radius alpha = 0.01 straight above a floor point, and a sphere of
    // angular radius beta = asin(1/3) (radius 10 at 30) whose silhouette overlaps the light's
    // disk by 0.6 or 0.3 alpha. A shading point finds what may block its shadow rays once for all
    // of them, from the cone they fill: a sphere only grazing that cone must still be found,
    // where one 2 % smaller (beta 0.007 = 0.7 alpha less) would not be. The 1024 stratified
    // shadow rays give kd I times the share of the light they reach; only the few dozen strata
    // the sphere's edge crosses are uncertain, each by at most 1/1024 (measured: within 0.2 % of
    // the unoccluded value), and 1 % is allowed, where the 0.3 alpha overlap hides 9 %.
    const Vec3 light{0, 100, 0};
    const double light_radius = 1, occluder_radius = 10, occluder_distance = 30;
    const double alpha = std::asin(light_radius / length(light));
    const double beta = std::asin(occluder_radius / occluder_distance);
    for (const double overlap : {0.6, 0.3}) {
        SCOPED_TRACE(overlap);
        Scene scene = testing::floor_scene(1, 1);
        scene.view = LookAt{{-40, 30, 0}, {0, 0, 0}, {0, 1, 0}, 1};
        scene.settings.shadow_rays = 1024;
        scene.lights.push_back(
            std::make_unique<SphereLight>(light, light_radius, Color{1, 1, 1}, false));
        const double between = beta + alpha - overlap * alpha;  // the centres' directions
        const Vec3 occluder = Vec3{std::sin(between), std::cos(between), 0} * occluder_distance;
        const Material& grey = *scene.materials.front();
        scene.objects.push_back(
            std::make_unique<Sphere>(std::vector<Vec3>{occluder}, occluder_radius, grey));
        const double unoccluded = light_past_sphere(light, light_radius, occluder, 0);
        const double expected = light_past_sphere(light, light_radius, occluder, occluder_radius);
        EXPECT_LT(expected, 0.95 * unoccluded);  // it does hide a part
        const double v = render_with(scene).image.at(0, 0).r;
        EXPECT_NEAR(v, 0.8 * expected, 0.01 * 0.8 * unoccluded);
    }
}

TEST(Effects, PointLightCastsAHardShadowWhoseEdgeTakesAtMostOnePixel) {
    // The tangent cone from the light: the shadow is a disk of radius H tan(asin(a / (H - h))).
    const double shadow_radius =
        kLightHeight * std::tan(std::asin(kOccluderRadius / (kLightHeight - kOccluderHeight)));
    const auto in_shadow = [&](const Vec3& p) { return std::hypot(p.x, p.z) < shadow_radius; };

    // One sample per pixel: each pixel is exactly ambient or exactly lit, as its centre lies.
    {
        const Scene scene = shadow_scene(0, 1, 16);
        const RenderResult r = render_with(scene);
        EXPECT_EQ(r.stats.rays.shadow, static_cast<std::uint64_t>(kShadowSize * kShadowSize));
        const Camera camera = scene.camera();
        for (int y = 0; y < kShadowSize; ++y) {
            for (int x = 0; x < kShadowSize; ++x) {
                const Vec3 p = on_floor(camera, {x + 0.5, y + 0.5});
                const double expected = in_shadow(p) ? kAmbient : lit_value(p, 0);
                ASSERT_NEAR(r.image.at(x, y).r, expected, 1e-6) << x << "," << y;
            }
        }
    }

    // Sixteen samples per pixel: a pixel whose floor square lies wholly inside or outside the
    // shadow is still exactly ambient or lit; only pixels the edge crosses take values between.
    const Scene scene = shadow_scene(0, 16, 16);
    const RenderResult r = render_with(scene);
    const Camera camera = scene.camera();
    int crossed = 0;
    for (int y = 0; y < kShadowSize; ++y) {
        int between = 0;
        for (int x = 0; x < kShadowSize; ++x) {
            const Vec3 a = on_floor(camera, {double(x), double(y)});
            const Vec3 b = on_floor(camera, {x + 1.0, y + 1.0});
            const double lo_x = std::min(a.x, b.x), hi_x = std::max(a.x, b.x);
            const double lo_z = std::min(a.z, b.z), hi_z = std::max(a.z, b.z);
            const double far = std::hypot(std::max(-lo_x, hi_x), std::max(-lo_z, hi_z));
            const double near =
                std::hypot(std::clamp(0.0, lo_x, hi_x), std::clamp(0.0, lo_z, hi_z));
            const double v = r.image.at(x, y).r;
            const double lit = lit_value(on_floor(camera, {x + 0.5, y + 0.5}), 0);
            if (far < shadow_radius) {
                ASSERT_FLOAT_EQ(v, kAmbient) << x << "," << y;
            } else if (near > shadow_radius) {
                ASSERT_NEAR(v, lit, 1e-4) << x << "," << y;
            } else {
                ++crossed;
                between += v > kAmbient + 1e-6 && v < lit - 1e-4;
            }
        }
        // The two rows through the middle of the disk cross its edge square-on: one pixel of
        // transition on each side.
        if (std::abs(y + 0.5 - kShadowSize / 2.0) < 1) {
            EXPECT_LE(between, 2) << y;
        }
    }
    EXPECT_GT(crossed, 50);
}

// --- Depth of field ------------------------------------------------------------------------------

// A wall at distance `depth` in front of a thin-lens camera, black left of x = 0 and white right
// of it (a checker with cells far larger than the view), lit by unit ambient light.
constexpr int kLensWidth = 48, kLensHeight = 3;
constexpr double kFov = 2.0;  // vertical, degrees
constexpr double kLensRadius = 13, kFocal = 100;

// `rows` rows of pixels of the same size as those of kLensHeight rows under kFov.
Scene edge_scene(double depth, double lens_radius, int rows = kLensHeight) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = kLensWidth;
    scene.settings.height = rows;
    scene.settings.samples = 256;
    scene.ambient = {1, 1, 1};
    const double fov = 2 * std::atan(std::tan(kFov * kPi / 360) * rows / kLensHeight) * 180 / kPi;
    scene.view = LookAt{{0, -500, 0}, {0, -500, 1}, {0, 1, 0}, fov};
    scene.lens = {lens_radius, kFocal};
    Material white = testing::grey_lambert(1.0);
    const Material& m = add_material(scene, white);
    SurfaceDetail detail;
    detail.texture = make_texture("checker", {1, 1, 1}, {0, 0, 0}, 1000);
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, 0, depth}, Vec3{0, 0, -1}, m, detail));
    return scene;
}

// Fraction of a unit disk left of the vertical line at s (|s| <= 1).
double disk_fraction(double s) {
    s = std::clamp(s, -1.0, 1.0);
    return 0.5 + (s * std::sqrt(1 - s * s) + std::asin(s)) / kPi;
}

// The blur circle's diameter measured from the mean columns of an image of the edge alone: the
// steps between columns are the disk's chord profile (variance (coc/4)^2) smoothed twice by a
// pixel's width (1/12 each).
double blur_diameter(const std::vector<double>& columns) {
    double weight = 0, mean = 0, spread = 0;
    for (std::size_t x = 0; x + 1 < columns.size(); ++x) {
        const double step = columns[x + 1] - columns[x];
        weight += step, mean += step * static_cast<double>(x);
    }
    mean /= weight;
    for (std::size_t x = 0; x + 1 < columns.size(); ++x) {
        const double off = static_cast<double>(x) - mean;
        spread += (columns[x + 1] - columns[x]) * off * off;
    }
    return 4 * std::sqrt(spread / weight - 1.0 / 6);
}

// The thin-lens circle of confusion of a point at `depth`, in pixels of kLensHeight rows under
// kFov: a point at distance d spreads, in the focal plane, over a disk of diameter
// 2 R |d - f| / d, and that plane's pixel is f times the pixel at distance 1.
double circle_of_confusion(double depth) {
    const double pixel = 2 * std::tan(kFov * kPi / 360) / kLensHeight;
    return 2 * kLensRadius * std::abs(depth - kFocal) / depth / (kFocal * pixel);
}

TEST(Effects, ThinLensBlurWidthIsTheCircleOfConfusionToAPercent) {
    // The measure of the test above, over 32 rows at one depth: its noise (from the 256 lens
    // points of each pixel) is about 0.5 % of the diameter on 3 rows, so 0.17 % on 32 (measured
    // over seeds 0-7: at most 0.3 %); 1 % is allowed, where a lens radius 2 % off is caught.
    constexpr int kRows = 32;
    const double depth = 250;
    const RenderResult r = render_with(edge_scene(depth, kLensRadius, kRows));
    std::vector<double> columns(kLensWidth);
    for (int x = 0; x < kLensWidth; ++x) {
        for (int y = 0; y < kRows; ++y) columns[x] += r.image.at(x, y).r / kRows;
    }
    EXPECT_NEAR(blur_diameter(columns), circle_of_confusion(depth),
                0.01 * circle_of_confusion(depth));
}

// What column x of an image of the edge shows when blurred over a circle of confusion `coc`:
// the edge projects onto the boundary between pixels 23 and 24, and a film point u pixels right
// of it sees white through the part of the lens disk on one side of a line u / (coc/2) radii off
// centre; a pixel averages that over its width (box filter).
double edge_profile(int x, double coc) {
    const double left = x - kLensWidth / 2.0;
    double expected = 0;
    constexpr int kSteps = 1000;
    for (int i = 0; i < kSteps; ++i) {
        expected += disk_fraction((left + (i + 0.5) / kSteps) / (coc / 2)) / kSteps;
    }
    return expected;
}

// The circle of confusion whose profile fits the columns best (least squares), searched within
// a fifth of `guess`.
double fitted_coc(const std::vector<double>& columns, double guess) {
    const auto misfit = [&](double coc) {
        double sum = 0;
        for (int x = 0; x < kLensWidth; ++x) {
            const double d = columns[static_cast<std::size_t>(x)] - edge_profile(x, coc);
            sum += d * d;
        }
        return sum;
    };
    double lo = 0.8 * guess, hi = 1.2 * guess;
    for (int i = 0; i < 60; ++i) {  // golden-section search
        const double a = hi - (hi - lo) * 0.6180339887, b = lo + (hi - lo) * 0.6180339887;
        if (misfit(a) < misfit(b)) {
            hi = b;
        } else {
            lo = a;
        }
    }
    return (lo + hi) / 2;
}

TEST(Effects, ThinLensBlursAnEdgeOverTheCircleOfConfusion) {
    // Measured over seeds 0-10 (256 samples a pixel): a pixel strays from the profile by at most
    // 0.026 and a column's mean over the 3 rows by 0.014, the circle fitted to the columns by
    // 1.0 % at one depth and 0.52 % on average over the three; with the lens radius 2 % too
    // large the average is off by 1.4 % to 2.4 %. So the pixels and columns catch gross errors
    // with room to spare over any seed, and the average fit catches a 2 % radius.
    double fit_error = 0;
    for (const double depth : {150.0, 60.0, 250.0}) {
        SCOPED_TRACE(depth);
        const double coc = circle_of_confusion(depth);
        const RenderResult r = render_with(edge_scene(depth, kLensRadius));
        std::vector<double> columns;
        for (int x = 0; x < kLensWidth; ++x) {
            const double expected = edge_profile(x, coc);
            double column = 0;
            for (int y = 0; y < kLensHeight; ++y) {
                ASSERT_NEAR(r.image.at(x, y).r, expected, 0.06) << x << "," << y;
                column += r.image.at(x, y).r / kLensHeight;
            }
            EXPECT_NEAR(column, expected, 0.03) << x;
            columns.push_back(column);
        }
        EXPECT_NEAR(blur_diameter(columns), coc, 0.03 * coc) << "coc " << coc;
        EXPECT_NEAR(fitted_coc(columns, coc), coc, 0.03 * coc) << "coc " << coc;
        fit_error += (fitted_coc(columns, coc) / coc - 1) / 3;
        EXPECT_GT(coc, 7);
    }
    EXPECT_NEAR(fit_error, 0, 0.01);
    // In the focal plane the edge stays sharp, and a pinhole is sharp at any depth.
    for (const auto& [depth, radius] : {std::pair{kFocal, kLensRadius}, std::pair{60.0, 0.0}}) {
        const RenderResult r = render_with(edge_scene(depth, radius));
        EXPECT_EQ(r.plan.effects.depth_of_field, radius > 0);
        for (int x = 0; x < kLensWidth; ++x) {
            for (int y = 0; y < kLensHeight; ++y) {
                EXPECT_NEAR(r.image.at(x, y).r, x < kLensWidth / 2 ? 0.0 : 1.0, 1e-9) << x;
            }
        }
    }
}

TEST(Effects, ThinLensSpreadsAPointNoFurtherThanItsCircleOfConfusion) {
    // A small sphere on the axis, out of focus, under ambient light on black: every lit pixel
    // lies within the blur circle widened by the sphere's own image and half a pixel diagonal,
    // and the light is not lost, only spread (its sum over the pixels stays the sphere's area).
    constexpr int kSize = 16;
    const double pixel = 0.01;  // at distance 1
    const double depth = 150, radius = 1.5;
    auto scene_with = [&](double lens_radius) {
        Scene scene;
        scene.path = "test";
        scene.settings.width = kSize;
        scene.settings.height = kSize;
        scene.settings.samples = 1024;
        scene.ambient = {1, 1, 1};
        const double fov = 2 * std::atan(kSize * pixel / 2) * 180 / kPi;
        scene.view = LookAt{{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, fov};
        scene.lens = {lens_radius, kFocal};
        const Material& m = add_material(scene, testing::grey_lambert(1.0));
        scene.objects.push_back(
            std::make_unique<Sphere>(std::vector<Vec3>{{0, 0, depth}}, radius, m));
        return scene;
    };
    const double coc = 2 * kLensRadius * (depth - kFocal) / depth / (kFocal * pixel);  // 8.7
    const double image_radius = radius / depth / pixel;                                // 1
    const RenderResult blurred = render_with(scene_with(kLensRadius));
    const RenderResult sharp = render_with(scene_with(0));
    double sum_blurred = 0, sum_sharp = 0, farthest = 0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const double v = blurred.image.at(x, y).r;
            sum_blurred += v, sum_sharp += sharp.image.at(x, y).r;
            if (v > 0)
                farthest = std::max(farthest, std::hypot(x + 0.5 - kSize / 2, y + 0.5 - kSize / 2));
        }
    }
    EXPECT_LE(farthest, coc / 2 + image_radius + std::sqrt(0.5));
    EXPECT_GE(farthest, coc / 2 - 1);
    EXPECT_NEAR(sum_sharp, kPi * image_radius * image_radius, 0.01 * sum_sharp);
    EXPECT_NEAR(sum_blurred, sum_sharp, 0.02 * sum_sharp);
}

// --- Motion blur ---------------------------------------------------------------------------------

// A sphere of radius 3 crossing `path` units (30 unless told) from right to left at distance 100
// before a pinhole camera whose pixel there is 1 unit, ambient-lit on black: one time unit for
// the whole path.
constexpr int kStreakWidth = 64, kStreakHeight = 9;
constexpr double kStreakDepth = 100, kStreakRadius = 3, kStreakPath = 30;

Scene streak_scene(int samples, double path = kStreakPath) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = kStreakWidth;
    scene.settings.height = kStreakHeight;
    scene.settings.samples = samples;
    scene.ambient = {1, 1, 1};
    const double fov = 2 * std::atan(kStreakHeight / 2.0 / kStreakDepth) * 180 / kPi;
    scene.view = LookAt{{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, fov};
    const Material& m = add_material(scene, testing::grey_lambert(1.0));
    // Present position first, then the past: time 0 at x = +path/2, time 1 at -path/2.
    const Vec3 present{path / 2, 0, kStreakDepth}, past{-path / 2, 0, kStreakDepth};
    scene.objects.push_back(
        std::make_unique<Sphere>(std::vector<Vec3>{present, past}, kStreakRadius, m));
    return scene;
}

// The fraction of the shutter during which the ray from the eye along `dir` meets the sphere:
// the times at which the centre lies within the radius of the ray's line, a quadratic in t.
double covered_time(const Vec3& dir) {
    const Vec3 from{kStreakPath / 2, 0, kStreakDepth}, to{-kStreakPath / 2, 0, kStreakDepth};
    const Vec3 motion = to - from;
    // |c - (c.d) d|^2 <= r^2 with c = from + t motion.
    const auto perpendicular = [&](const Vec3& v) { return v - dir * dot(v, dir); };
    const Vec3 p0 = perpendicular(from), p1 = perpendicular(motion);
    const double a = dot(p1, p1), b = 2 * dot(p0, p1),
                 c = dot(p0, p0) - kStreakRadius * kStreakRadius;
    const double disc = b * b - 4 * a * c;
    if (disc <= 0) return 0;
    const double t0 = (-b - std::sqrt(disc)) / (2 * a), t1 = (-b + std::sqrt(disc)) / (2 * a);
    return std::max(0.0, std::min(1.0, t1) - std::max(0.0, t0));
}

TEST(Effects, MotionStreakHasThePathsLengthAndAFlatMiddle) {
    const Scene scene = streak_scene(256);
    const RenderResult r = render_with(scene);
    ASSERT_TRUE(r.plan.effects.motion_blur);
    const Camera camera = scene.camera();
    // Predicted pixel values: the covered fraction of the shutter, averaged over the pixel.
    constexpr int kGrid = 12;
    for (int y = 0; y < kStreakHeight; ++y) {
        for (int x = 0; x < kStreakWidth; ++x) {
            double expected = 0;
            for (int i = 0; i < kGrid * kGrid; ++i) {
                const Vec2 film{x + (i % kGrid + 0.5) / kGrid, y + (i / kGrid + 0.5) / kGrid};
                expected += covered_time(camera.generate_ray(film, {0.5, 0.5}, 0).dir);
            }
            expected /= kGrid * kGrid;
            // Binomial noise bound of 256 samples; stratification only makes it smaller.
            const double tolerance = 4.5 * std::sqrt(expected * (1 - expected) / 256) + 0.005;
            ASSERT_NEAR(r.image.at(x, y).r, expected, tolerance) << x << "," << y;
        }
    }
    // On the middle row: the streak spans the path plus the diameter, 36 pixels, and in its
    // middle (at least a radius from either end of the path) every point is covered for the
    // diameter's share of the path, 6/30 of the time.
    const int row = kStreakHeight / 2;
    int first = -1, last = -1;
    for (int x = 0; x < kStreakWidth; ++x) {
        if (r.image.at(x, row).r > 0) last = x, first = first < 0 ? x : first;
    }
    EXPECT_NEAR(last - first + 1, kStreakPath + 2 * kStreakRadius, 1.0);
    EXPECT_NEAR((first + last + 1) / 2.0, kStreakWidth / 2.0, 0.5);
    double lo = 1, hi = 0, sum = 0;
    const int middle_begin = kStreakWidth / 2 - 11, middle_end = kStreakWidth / 2 + 11;
    for (int x = middle_begin; x < middle_end; ++x) {
        const double v = r.image.at(x, row).r;
        lo = std::min(lo, v), hi = std::max(hi, v), sum += v;
    }
    // The chord through a pixel's lower and upper edges is a little shorter than the diameter.
    const double chord = 2 * std::sqrt(kStreakRadius * kStreakRadius - 0.5 * 0.5 / 3);
    EXPECT_NEAR(sum / (middle_end - middle_begin), chord / kStreakPath, 0.01);
    // Each pixel's window of time slides by 1/30 of the shutter across it: a little noise.
    EXPECT_LT(hi - lo, 0.05);

    // The streak's centroid is where the sphere is on average over the shutter, the path's
    // middle, on the image's centre line by symmetry; a shutter 2 % short (or long, the sphere
    // then waiting at an end) moves it by 0.3 pixel. Its noise, from the 256 times of each pixel,
    // is about 0.02 pixel (measured over seeds 0-8: at most 0.047).
    double total = 0, moment = 0;
    for (int y = 0; y < kStreakHeight; ++y) {
        for (int x = 0; x < kStreakWidth; ++x) {
            total += r.image.at(x, y).r, moment += r.image.at(x, y).r * (x + 0.5);
        }
    }
    EXPECT_NEAR(moment / total, kStreakWidth / 2.0, 0.1);
}

TEST(Effects, EveryRayOfACameraSampleSharesItsTime) {
    // A sphere moving across its own width, lit from the eye: a shadow ray drawn at another time
    // than its camera ray would find the sphere elsewhere and often in the way, and its pixel
    // black. With the time shared, a pixel either misses (blue background) or is lit.
    Scene scene = streak_scene(1, 2 * kStreakRadius);
    scene.ambient = {};
    scene.background = {0, 0, 1};
    scene.lights.push_back(std::make_unique<PointLight>(Vec3{0, 0, 0}, Color{1, 1, 1}));
    const RenderResult r = render_with(scene);
    int hits = 0;
    for (int y = 0; y < kStreakHeight; ++y) {
        for (int x = 0; x < kStreakWidth; ++x) {
            const Color c = r.image.at(x, y);
            if (c.b == 1.0f) continue;
            ++hits;
            EXPECT_GT(c.r, 0.0f) << x << "," << y;
        }
    }
    EXPECT_GT(hits, 20);
    EXPECT_EQ(r.stats.rays.shadow, static_cast<std::uint64_t>(hits));
}

// --- drt --stats ---------------------------------------------------------------------------------

namespace fs = std::filesystem;

// Renders `xml` with the drt binary and returns its --stats JSON.
std::string stats_of(const std::string& xml, const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("drt_effects_test_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path scene = dir / (name + ".xml"), stats = dir / (name + ".json");
    std::ofstream(scene) << xml;
    const std::string command = std::string("'") + DRT_BINARY + "' '" + scene.string() +
                                "' -q -o '" + (dir / (name + ".pfm")).string() + "' --stats '" +
                                stats.string() + "' 2>/dev/null";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    std::ifstream in(stats);
    std::stringstream text;
    text << in.rdbuf();
    fs::remove_all(dir);
    return text.str();
}

// The number after "key": in a JSON text (each key used here occurs once).
long long json_number(const std::string& json, const std::string& key) {
    const auto at = json.find("\"" + key + "\":");
    if (at == std::string::npos) return -1;
    return std::stoll(json.substr(at + key.size() + 3));
}

bool json_flag(const std::string& json, const std::string& key) {
    const auto at = json.find("\"" + key + "\":");
    EXPECT_NE(at, std::string::npos) << key;
    return json.compare(at + key.size() + 3, 5, " true") == 0;
}

struct Expected {
    long long camera, shadow, reflection, refraction;
    bool antialiasing, soft_shadows, glossy_reflection, glossy_refraction, depth_of_field,
        motion_blur;
};

void expect_stats(const std::string& json, const Expected& e) {
    EXPECT_EQ(json_number(json, "camera"), e.camera);
    EXPECT_EQ(json_number(json, "shadow"), e.shadow);
    EXPECT_EQ(json_number(json, "reflection"), e.reflection);
    EXPECT_EQ(json_number(json, "refraction"), e.refraction);
    EXPECT_EQ(json_flag(json, "antialiasing"), e.antialiasing);
    EXPECT_EQ(json_flag(json, "soft_shadows"), e.soft_shadows);
    EXPECT_EQ(json_flag(json, "glossy_reflection"), e.glossy_reflection);
    EXPECT_EQ(json_flag(json, "glossy_refraction"), e.glossy_refraction);
    EXPECT_EQ(json_flag(json, "depth_of_field"), e.depth_of_field);
    EXPECT_EQ(json_flag(json, "motion_blur"), e.motion_blur);
}

// An 8 x 6 image of the thesis's pixel-plane camera (eye at (4, 3, -8) looking along +z) filled
// by a wall at z = 100 facing it, of material `wall`, with `extra` elements added.
std::string wall_scene(const std::string& render, const std::string& wall,
                       const std::string& extra) {
    std::string xml = R"(<?xml version="1.0"?>)"
                      "\n<Scene>\n"
                      R"(  <Image Width="8" Height="6"/>)"
                      "\n";
    xml += "  <Render " + render + "/>\n";
    xml += "  <Materials><Wall " + wall + "/></Materials>\n";
    xml += R"(  <Plane Px="0" Py="0" Pz="100" Vu="0" Vv="0" Vw="-1" Material="Wall"/>)";
    xml += "\n  " + extra + "\n</Scene>\n";
    return xml;
}

constexpr const char* kDiffuse = R"(diffuse="1" kdr="0.5" kdg="0.5" kdb="0.5")";
constexpr const char* kPointLight = R"(<Light Px="4" Py="3" Pz="0" Ir="1" Ig="1" Ib="1"/>)";

TEST(EffectsStats, PointLightOnlyAndOneSampleSampleNothing) {
    // ShadowRays asks for ten, but a point light gets exactly one per shading point.
    const std::string json =
        stats_of(wall_scene(R"(Samples="1" ShadowRays="10")", kDiffuse, kPointLight), "plain");
    expect_stats(json, {48, 48, 0, 0, false, false, false, false, false, false});
}

TEST(EffectsStats, LensAndAreaLightWithoutMotion) {
    const std::string json = stats_of(wall_scene(R"(Samples="4" ShadowRays="10")", kDiffuse,
                                                 R"(<DepthOfField Radius="2" Focal="50"/>
  <Light Px="4" Py="3" Pz="0" Radius="5" Ir="1" Ig="1" Ib="1"/>)"),
                                      "lens");
    expect_stats(json, {4 * 48, 10 * 4 * 48, 0, 0, true, true, false, false, true, false});
}

TEST(EffectsStats, MotionWithoutLensOrAreaLight) {
    // The moving sphere is behind the eye: it costs no ray, but time is sampled.
    const std::string json = stats_of(
        wall_scene(R"(Samples="1" ShadowRays="10")", kDiffuse, std::string(kPointLight) + R"(
  <Sphere Px="4" Py="3" Pz="-1000" Radius="1" Material="Wall">
    <MotionBlurPosition Px="6" Py="3" Pz="-1000"/>
  </Sphere>)"),
        "motion");
    expect_stats(json, {48, 48, 0, 0, false, false, false, false, false, true});
}

TEST(EffectsStats, GlossyMirrorTracesGlossyRaysAndNoShadowRays) {
    // No diffuse part, so no shadow rays even with an area light (and no soft shadows); the
    // reflections all escape.
    const std::string json = stats_of(
        wall_scene(R"(Samples="2" ShadowRays="10" GlossyRays="3")", R"(reflective="1" n="10")",
                   R"(<Light Px="4" Py="3" Pz="0" Radius="5" Ir="1" Ig="1" Ib="1"/>)"),
        "glossy");
    expect_stats(json, {2 * 48, 0, 3 * 2 * 48, 0, true, false, true, false, false, false});
}

TEST(EffectsStats, IdealGlassTracesOneReflectionAndOneRefraction) {
    const std::string json = stats_of(
        wall_scene(R"(Samples="1" GlossyRays="5")", R"(transmitt="1" index="1.5")", kPointLight),
        "glass");
    expect_stats(json, {48, 0, 48, 48, false, false, false, false, false, false});
}

TEST(EffectsStats, BlurryGlassTracesGlossyRaysOfBothKinds) {
    const std::string json =
        stats_of(wall_scene(R"(Samples="1" GlossyRays="4")", R"(transmitt="1" index="1.5" n="20")",
                            kPointLight),
                 "blurry");
    expect_stats(json, {48, 0, 4 * 48, 4 * 48, false, false, true, true, false, false});
}

}  // namespace
}  // namespace drt
