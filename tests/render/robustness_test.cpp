// Hard cases that must stay numerically stable: far from the origin, grazing angles, rays that
// start inside glass, chains of total internal reflection, extreme glossiness, index 1, shading
// points inside light spheres, and every scene in scenes/ rendered small.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "drt/render/integrator.h"
#include "drt/render/renderer.h"
#include "drt/sampling/multi_jittered.h"
#include "drt/scene/scene_loader.h"
#include "test_render.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::add_material;
using testing::floor_scene;
using testing::lone_sphere_scene;
using testing::render_with;

// Traces single rays through a scene, outside the renderer, in double precision.
class Tracer {
  public:
    explicit Tracer(const Scene& scene)
        : plan_(plan_render(scene)),
          bvh_(scene.objects),
          sampler_(make_sampler("stratified")),
          integrator_(scene, plan_, bvh_, *sampler_) {}

    Color trace(const Ray& ray, RayCounts& counts, std::uint32_t pixel = 0) const {
        return integrator_.radiance(ray, PixelSample{0, pixel, 0, 1}, 0, counts);
    }
    Color trace(const Ray& ray) const {
        RayCounts counts;
        return trace(ray, counts);
    }

  private:
    RenderPlan plan_;
    Bvh bvh_;
    std::unique_ptr<Sampler> sampler_;
    Integrator integrator_;
};

// Nearest positive root of a ray against a sphere, solved independently of the renderer.
std::optional<double> hit_sphere(const Vec3& o, const Vec3& d, const Vec3& c, double r) {
    const Vec3 oc = o - c;
    const double b = dot(oc, d);
    const double disc = b * b - (dot(oc, oc) - r * r);
    if (disc < 0) return std::nullopt;
    const double t = -b - std::sqrt(disc);
    if (t > 0) return t;
    return std::nullopt;
}

// A floor, a diffuse sphere and a point light low to one side, all moved by `offset`: the
// terminator of the sphere and the shadow rays near it graze the surfaces they leave.
Scene sphere_on_floor(const Vec3& offset) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = 64;
    scene.settings.height = 64;
    scene.settings.samples = 1;
    scene.view = LookAt{offset + Vec3{0, 50, 0}, offset, {0, 0, 1}, 60};
    const Material& grey = add_material(scene, testing::grey_lambert());
    scene.objects.push_back(std::make_unique<Plane>(offset, Vec3{0, 1, 0}, grey));
    scene.objects.push_back(
        std::make_unique<Sphere>(std::vector<Vec3>{offset + Vec3{0, 10, 0}}, 8.0, grey));
    scene.lights.push_back(std::make_unique<PointLight>(offset + Vec3{40, 15, 0}, Color{1, 1, 1}));
    return scene;
}

TEST(Robustness, FarFromTheOriginShadingIsExactlyLambert) {
    // The same local scene at the origin and 1e5 away along every axis: each pixel must be the
    // analytic Lambert value, including at the sphere's terminator, where shadow rays leave the
    // surface almost tangentially and any self-intersection would darken the pixel.
    for (const Vec3 offset : {Vec3{0, 0, 0}, Vec3{1e5, 1e5, -1e5}, Vec3{-1e5, 3e4, 1e5}}) {
        const Scene scene = sphere_on_floor(offset);
        const RenderResult r = render_with(scene);
        const Camera camera = scene.camera();
        const Vec3 light{40, 15, 0}, centre{0, 10, 0};
        int terminator_pixels = 0, shadow_pixels = 0;
        for (int y = 0; y < 64; ++y) {
            for (int x = 0; x < 64; ++x) {
                const Ray ray = camera.generate_ray({x + 0.5, y + 0.5}, {0.5, 0.5}, 0);
                const Vec3 o = ray.origin - offset;  // exact: both are sums of the same offset
                double expected;
                if (const auto t = hit_sphere(o, ray.dir, centre, 8.0)) {
                    const Vec3 p = o + ray.dir * *t;
                    const double cosine = dot(normalize(p - centre), normalize(light - p));
                    expected = 0.8 * std::max(0.0, cosine);
                    terminator_pixels += cosine > 0 && cosine < 0.1;
                } else {
                    const Vec3 p = o + ray.dir * (-o.y / ray.dir.y);
                    const Vec3 to_light = light - p;
                    const auto blocked = hit_sphere(p, normalize(to_light), centre, 8.0);
                    // The shadow's outline is where the analytic answer is ill-conditioned.
                    const Vec3 closest =
                        p + normalize(to_light) * dot(centre - p, normalize(to_light));
                    if (std::abs(length(closest - centre) - 8.0) < 1e-6) continue;
                    expected = blocked ? 0.0 : 0.8 * normalize(to_light).y;
                    shadow_pixels += blocked.has_value();
                }
                const double got = r.image.at(x, y).r;
                ASSERT_NEAR(got, expected, 1e-6 * expected + 1e-12)
                    << "pixel " << x << "," << y << " offset " << offset.x;
            }
        }
        EXPECT_GT(terminator_pixels, 5);
        EXPECT_GT(shadow_pixels, 20);
    }
}

// A unit vector from two numbers in [0, 1).
Vec3 direction_from(double a, double b) {
    const double z = 1 - 2 * a, r = std::sqrt(std::max(0.0, 1 - z * z));
    return {r * std::cos(2 * kPi * b), r * std::sin(2 * kPi * b), z};
}

TEST(Robustness, SpawnedRaysNeverReHitTheirSurfaceAtAnyMagnitude) {
    // Rays leaving sphere and plane hit points, at magnitudes from 1e-2 to 1e7, outwards (down
    // to 1e-6 from tangent) must not meet the surface again; inwards they must cross the whole
    // chord.
    const Material m = testing::grey_lambert();
    for (const double scale : {1e-2, 1.0, 1e3, 1e5, 1e7}) {
        const Vec3 centre = Vec3{1, -0.7, 0.3} * scale;
        for (const double radius : {scale * 1e-2, scale}) {
            const Sphere sphere({centre}, radius, m);
            const Plane plane(centre, direction_from(0.3, 0.7), m);
            for (int i = 0; i < 256; ++i) {
                const Vec2 u = multi_jittered(i, 256, 17), v = multi_jittered(i, 256, 29);
                const Vec3 target = centre + direction_from(v.x, v.y) * (0.9 * radius);
                const Vec3 origin = centre + direction_from(u.x, u.y) * (4 * radius);
                const Ray ray{origin, normalize(target - origin), 0};
                for (const Object* object :
                     {static_cast<const Object*>(&sphere), static_cast<const Object*>(&plane)}) {
                    const auto t = object->intersect(ray, {0, kInfinity});
                    // Every ray aims into the sphere; a few run away from the plane.
                    if (!t && object == &plane) continue;
                    ASSERT_TRUE(t) << scale << " " << i;
                    const SurfaceHit hit = object->surface_at(ray, *t);
                    const Vec3 n = dot(hit.normal, ray.dir) < 0 ? hit.normal : -hit.normal;
                    const Frame frame = Frame::around(n);
                    const double tilt = std::pow(10.0, -6 + 6 * u.x);  // cosine to the normal
                    const double sin_t = std::sqrt(1 - tilt * tilt);
                    const Vec3 side =
                        frame.t * std::cos(2 * kPi * v.y) + frame.b * std::sin(2 * kPi * v.y);
                    const Vec3 out = normalize(side * sin_t + n * tilt);
                    EXPECT_FALSE(object->intersect(spawn_ray(hit.point, n, out, 0), {0, kInfinity}))
                        << "scale " << scale << " radius " << radius << " ray " << i;
                    const Vec3 in = normalize(side * sin_t - n * tilt);
                    const auto through =
                        object->intersect(spawn_ray(hit.point, n, in, 0), {0, kInfinity});
                    if (object == &plane) {
                        EXPECT_FALSE(through) << "scale " << scale << " ray " << i;
                    } else if (tilt > 1e-2) {
                        // Across the chord of a direction at cosine `tilt` to the inward normal
                        // (shortened by the offset), to a point on the far side.
                        ASSERT_TRUE(through) << scale << " " << i;
                        EXPECT_GT(through->t, 0.99 * 2 * radius * tilt) << scale << " " << i;
                        const Vec3 exit = spawn_ray(hit.point, n, in, 0).at(through->t);
                        EXPECT_NEAR(length(exit - centre), radius, 1e-12 * scale)
                            << scale << " " << i;
                    }
                }
            }
        }
    }
}

TEST(Robustness, GrazingLightOnAFarFloorIsNotSelfShadowed) {
    // A light a hair above the horizon: shadow rays run almost parallel to the floor for
    // thousands of units, 1e5 from the origin.
    const Vec3 offset{1e5, -1e5, 1e5};
    Scene scene = floor_scene(16, 16);
    scene.view = LookAt{offset + Vec3{0, 50, 0}, offset, {0, 0, 1}, 60};
    const Material& grey = *scene.materials.front();
    scene.objects.clear();
    scene.objects.push_back(std::make_unique<Plane>(offset, Vec3{0, 1, 0}, grey));
    const Vec3 light{5000, 0.5, 0};
    scene.lights.push_back(std::make_unique<PointLight>(offset + light, Color{1, 1, 1}));
    const RenderResult r = render_with(scene);
    const Camera camera = scene.camera();
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            const Ray ray = camera.generate_ray({x + 0.5, y + 0.5}, {0.5, 0.5}, 0);
            const Vec3 o = ray.origin - offset;
            const Vec3 p = o + ray.dir * (-o.y / ray.dir.y);
            const double expected = 0.8 * normalize(light - p).y;  // about 8e-5 (N.L about 1e-4)
            ASSERT_NEAR(r.image.at(x, y).r, expected, 1e-6 * expected) << x << "," << y;
        }
    }
}

TEST(Robustness, MirrorAndGlassFarFromTheOriginKeepEnergy) {
    const Color background{0.2, 0.4, 0.6};
    const Vec3 far{1e5, -1e5, 1e5};
    // A convex mirror reflects every ray into the background once: ks x background exactly.
    Scene mirror = lone_sphere_scene(testing::mirror({0.5, 0.5, 0.5}), background);
    mirror.view = LookAt{far + Vec3{0, 0, -10}, far, {0, 1, 0}, 20};
    mirror.objects.front() =
        std::make_unique<Sphere>(std::vector<Vec3>{far}, 1.5, mirror.objects.front()->material());
    const RenderResult rm = render_with(mirror);
    int hits = 0;
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 32; ++x) {
            const float g = rm.image.at(x, y).g;
            if (g == 0.4f) continue;
            ++hits;
            ASSERT_FLOAT_EQ(g, 0.2f) << x << "," << y;
        }
    }
    EXPECT_EQ(rm.stats.rays.reflection, static_cast<std::uint64_t>(hits));
    EXPECT_GT(hits, 100);

    // Clear glass loses only what chains longer than MaxDepth carry, which at MaxDepth 32 is
    // below 1e-6 of the background (at 8 it reaches 2% in the rim's longest chains).
    Scene glass = lone_sphere_scene(testing::glass(1.5), background);
    glass.settings.max_depth = 32;
    glass.view = mirror.view;
    glass.objects.front() =
        std::make_unique<Sphere>(std::vector<Vec3>{far}, 1.5, glass.objects.front()->material());
    const RenderResult rg = render_with(glass);
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 32; ++x) ASSERT_NEAR(rg.image.at(x, y).b, 0.6, 1e-5) << x << "," << y;
    }
}

TEST(Robustness, RaysStartingInsideGlassLoseOnlyWhatMaxDepthCuts) {
    // From the centre every hit is at normal incidence: F = ((n-1)/(n+1))^2 goes back through
    // the centre, 1-F leaves. Summed over MaxDepth hits: background x (1 - F^MaxDepth).
    const Color background{0.3, 0.6, 0.9};
    for (const int max_depth : {1, 2, 8}) {
        Scene scene = lone_sphere_scene(testing::glass(1.5), background);
        scene.settings.max_depth = max_depth;
        const Tracer tracer(scene);
        const double fresnel = std::pow(0.5 / 2.5, 2);
        const double expected = 1 - std::pow(fresnel, max_depth);
        for (int i = 0; i < 64; ++i) {
            const Vec3 dir =
                normalize(Vec3{std::cos(i * 0.7), std::sin(i * 1.3), std::cos(i * 2.9)});
            RayCounts counts;
            const Color c = tracer.trace({{0, 0, 0}, dir, 0}, counts);
            ASSERT_NEAR(c.r, 0.3 * expected, 1e-12) << i;
            ASSERT_NEAR(c.b, 0.9 * expected, 1e-12) << i;
            EXPECT_EQ(counts.refraction, static_cast<std::uint64_t>(max_depth));
        }
    }

    // Off centre, in every direction: finite, never more than the background.
    Scene scene = lone_sphere_scene(testing::glass(1.5), background);
    const Tracer tracer(scene);
    for (int i = 0; i < 256; ++i) {
        const Vec3 origin = Vec3{std::sin(i * 0.37), std::cos(i * 0.91), std::sin(i * 1.71)} * 0.8;
        const Vec3 dir = normalize(Vec3{std::cos(i * 0.53), std::sin(i * 1.19), std::cos(i * 2.3)});
        const Color c = tracer.trace({origin, dir, 0});
        ASSERT_TRUE(is_finite(c)) << i;
        ASSERT_GE(c.g, 0.0);
        ASSERT_LE(c.g, 0.6 * (1 + 1e-12)) << i;
    }

    // A camera at the centre of a glass sphere sees the same thing through every pixel.
    scene.view = LookAt{{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 90};
    const RenderResult r = render_with(scene);
    const double all = 0.6 * (1 - std::pow(0.04, 8));
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 32; ++x) ASSERT_NEAR(r.image.at(x, y).g, all, 1e-6) << x << "," << y;
    }
}

// A ray inside a glass sphere (index 1.5, radius 1.5) along a chord whose incidence angle, 64
// degrees, exceeds the critical angle (41.8): by symmetry every bounce meets the surface at the
// same angle, so it is reflected totally, forever.
Ray trapped_ray() {
    const double h = 0.9 * 1.5;
    return {{-0.2, h, 0}, {1, 0, 0}, 0};
}

TEST(Robustness, TotalInternalReflectionChainsStopAtMaxDepth) {
    for (const int max_depth : {1, 8, 64}) {
        Scene scene = lone_sphere_scene(testing::glass(1.5), {1, 1, 1});
        scene.settings.max_depth = max_depth;
        const Tracer tracer(scene);
        RayCounts counts;
        const Color c = tracer.trace(trapped_ray(), counts);
        // No light escapes: a ray that slipped out (or re-hit the surface it left from outside)
        // would bring in the white background.
        EXPECT_EQ(c, Color{}) << max_depth;
        EXPECT_EQ(counts.reflection, static_cast<std::uint64_t>(max_depth));
        EXPECT_EQ(counts.refraction, 0u);
    }
}

TEST(Robustness, TotalInternalReflectionChainEnergyIsBounded) {
    // Half diffuse under unit ambient, half glass: every hit adds 0.5 and passes half of the
    // rest on, the hit at MaxDepth adding its diffuse part only: 1 - 0.5^(MaxDepth+1) < 1.
    for (const int max_depth : {4, 8, 50}) {
        Material m = testing::glass(1.5);
        m.diffuse = 0.5;
        m.kd = {1, 1, 1};
        m.transmit = 0.5;
        Scene scene = lone_sphere_scene(m, {0, 0, 0});
        scene.ambient = {1, 1, 1};
        scene.settings.max_depth = max_depth;
        const Tracer tracer(scene);
        const Color c = tracer.trace(trapped_ray());
        EXPECT_NEAR(c.r, 1 - std::pow(0.5, max_depth + 1), 1e-12) << max_depth;
    }
}

// A mirror floor seen at grazing angles, over a second floor 1 below that is lit by ambient
// light alone: a reflected ray that went through the mirror would bring 1 from the lower floor
// instead of the 0.25 of the background.
Scene grazing_mirror(Material mirror, SurfaceDetail detail = {}) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = 32;
    scene.settings.height = 16;
    scene.settings.samples = 4;
    scene.settings.glossy_rays = 4;
    scene.background = {0.25, 0.25, 0.25};
    scene.ambient = {1, 1, 1};
    scene.view = LookAt{{0, 0.05, 0}, {0, 0.05, 100}, {0, 1, 0}, 2};
    const Material& m = add_material(scene, std::move(mirror));
    Material lower = testing::grey_lambert(1.0);
    lower.name = "lower";
    const Material& l = add_material(scene, lower);
    scene.objects.push_back(
        std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, m, std::move(detail)));
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, -1, 0}, Vec3{0, 1, 0}, l));
    return scene;
}

void expect_background_or_mirrored(const RenderResult& r, double ks) {
    int mirrored = 0;
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            const float v = r.image.at(x, y).r;
            if (v == 0.25f) continue;
            ++mirrored;
            ASSERT_FLOAT_EQ(v, static_cast<float>(ks * 0.25)) << x << "," << y;
        }
    }
    EXPECT_GT(mirrored, r.image.width * r.image.height / 4);
}

TEST(Robustness, GlossyMirrorAtGrazingIncidenceStaysAboveTheSurface) {
    // n = 10 (sigma 0.1 rad against incidence angles below 0.03 rad: most draws land below and
    // are redrawn) and n = 0.001 (sigma 1000 rad: directions all over the sphere).
    for (const double n : {10.0, 0.001}) {
        const RenderResult r = render_with(grazing_mirror(testing::mirror({0.6, 0.6, 0.6}, n)));
        SCOPED_TRACE(n);
        expect_background_or_mirrored(r, 0.6);
        for (const float v : r.image.rgb) ASSERT_TRUE(std::isfinite(v));
    }
}

TEST(Robustness, BumpedMirrorAtGrazingIncidenceStaysAboveTheSurface) {
    // A bump-tilted shading normal can put the ideal reflection below the geometric surface;
    // the reflection must still leave on the viewer's side, ideal or glossy.
    for (const std::optional<double> n : {std::optional<double>{}, std::optional<double>{50.0}}) {
        SurfaceDetail bumps;
        bumps.bump = BumpMap{0.5, 2.0};
        const RenderResult r =
            render_with(grazing_mirror(testing::mirror({0.6, 0.6, 0.6}, n), std::move(bumps)));
        SCOPED_TRACE(n.value_or(0));
        expect_background_or_mirrored(r, 0.6);
    }
}

TEST(Robustness, PerturbedDirectionsAreFiniteUnitVectorsForExtremeInputs) {
    const Vec3 grazing = normalize(Vec3{1, 1e-12, 0});
    const double biggest = std::nextafter(1.0, 0.0);
    for (const double sigma : {1e-9, 1e-4, 0.1, 1.0, 1e3, 1e9}) {
        for (const Vec2 u :
             {Vec2{0, 0}, Vec2{biggest, biggest}, Vec2{0.5, 0.25}, Vec2{biggest, 0}}) {
            for (const Vec3 ideal : {grazing, Vec3{0, 0, -1}, Vec3{0, 0, 1}}) {
                const Vec3 d = perturb_direction(ideal, sigma, u);
                ASSERT_TRUE(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z))
                    << sigma;
                ASSERT_NEAR(length(d), 1.0, 1e-12) << sigma;
            }
        }
    }
    // A tiny spread stays within a few sigma of the ideal direction.
    for (int i = 0; i < 64; ++i) {
        const Vec3 d = perturb_direction(grazing, 1e-9, multi_jittered(i, 64, 5));
        EXPECT_LT(std::acos(std::min(1.0, dot(d, grazing))), 1e-8);
    }
}

// A scene with a bit of everything the sharpness affects: a mirror sphere and a glass sphere
// over a lit floor.
Scene mirror_and_glass(std::optional<double> sharpness) {
    Scene scene = floor_scene(24, 24);
    scene.settings.samples = 2;
    scene.settings.shadow_rays = 2;
    scene.view = LookAt{{0, 20, -40}, {0, 3, 0}, {0, 1, 0}, 40};
    scene.background = {0.1, 0.2, 0.3};
    scene.lights.push_back(
        std::make_unique<SphereLight>(Vec3{10, 40, -10}, 4.0, Color{1, 1, 1}, false));
    const Material& m = add_material(scene, testing::mirror({0.9, 0.9, 0.9}, sharpness));
    const Material& g = add_material(scene, testing::glass(1.5, sharpness));
    scene.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{-5, 4, 0}}, 4.0, m));
    scene.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{5, 4, 0}}, 4.0, g));
    return scene;
}

TEST(Robustness, TinySigmaIsTheIdealMirrorAndRefraction) {
    // n = 1e9 (sigma 1e-9) is below the 1e-4 threshold: bit-identical to the ideal material,
    // with the same single ray per hit.
    const RenderResult ideal = render_with(mirror_and_glass(std::nullopt));
    const RenderResult tiny = render_with(mirror_and_glass(1e9));
    EXPECT_EQ(tiny.image.rgb, ideal.image.rgb);
    EXPECT_EQ(tiny.stats.rays.reflection, ideal.stats.rays.reflection);
    EXPECT_EQ(tiny.stats.rays.refraction, ideal.stats.rays.refraction);
    EXPECT_FALSE(tiny.plan.effects.glossy_reflection || tiny.plan.effects.glossy_refraction);
    // Just above the threshold (sigma 1.25e-4) the material is sampled, and differs from the
    // ideal one only by the slightest blur.
    const RenderResult sharp = render_with(mirror_and_glass(8000.0));
    EXPECT_TRUE(sharp.plan.effects.glossy_reflection && sharp.plan.effects.glossy_refraction);
    double total = 0;
    for (std::size_t i = 0; i < ideal.image.rgb.size(); ++i) {
        total += std::abs(sharp.image.rgb[i] - ideal.image.rgb[i]);
    }
    EXPECT_LT(total / ideal.image.rgb.size(), 2e-3);
}

TEST(Robustness, HugeSigmaStaysFiniteAndBounded) {
    // n = 0.001: directions spread over the whole sphere, half redrawn. Every value stays
    // finite and below what a perfectly white environment could give.
    const RenderResult r = render_with(mirror_and_glass(0.001));
    for (const float v : r.image.rgb) {
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.0f);
        ASSERT_LE(v, 1.0f);
    }
}

TEST(Robustness, GlassOfIndexOneVanishesFromATexturedScene) {
    // Index 1 bends nothing and reflects nothing, so a clear sphere of it leaves the image as
    // if it were not there (it is lit by ambient light only: spheres cast opaque shadows).
    auto scene_with = [](bool sphere) {
        Scene scene = floor_scene(40, 30);
        scene.view = LookAt{{0, 20, -40}, {0, 3, 0}, {0, 1, 0}, 40};
        scene.settings.samples = 4;
        scene.background = {0.1, 0.2, 0.3};
        scene.ambient = {0.7, 0.7, 0.7};
        SurfaceDetail checker;
        checker.texture = make_texture("checker", {0.9, 0.5, 0.1}, {0.1, 0.3, 0.8}, 3.0);
        const Material& floor = *scene.materials.front();
        scene.objects.front() =
            std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, floor, checker);
        if (sphere) {
            const Material& g = add_material(scene, testing::glass(1.0));
            scene.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{0, 5, 0}}, 5.0, g));
        }
        return scene;
    };
    const RenderResult without = render_with(scene_with(false));
    const RenderResult with = render_with(scene_with(true));
    ASSERT_GT(with.stats.rays.refraction, 100u);
    EXPECT_EQ(with.stats.rays.reflection, 0u);  // F is exactly 0 at index 1
    EXPECT_EQ(with.image.rgb, without.image.rgb);
}

TEST(Robustness, ShadingPointsInsideOrTouchingALightSphereAreFiniteAndSane) {
    // A light sphere of radius 10 centred on the floor. Inside it every direction reaches the
    // light: the contract's average of max(0, N.w) over the whole sphere is 1/4. Outside, the
    // cap of directions shrinks from a hemisphere about the horizontal (again 1/4) to nothing.
    Scene scene = floor_scene(32, 32);
    scene.settings.shadow_rays = 64;
    scene.lights.push_back(
        std::make_unique<SphereLight>(Vec3{0, 0, 0}, 10.0, Color{1, 1, 1}, false));
    const RenderResult r = render_with(scene);
    const Camera camera = scene.camera();
    int inside = 0;
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 32; ++x) {
            const Ray ray = camera.generate_ray({x + 0.5, y + 0.5}, {0.5, 0.5}, 0);
            const Vec3 p = ray.at(-ray.origin.y / ray.dir.y);
            const double v = r.image.at(x, y).r;
            ASSERT_TRUE(std::isfinite(v));
            if (length(p) < 9) {
                ++inside;
                ASSERT_NEAR(v, 0.8 / 4, 0.01) << x << "," << y;
            } else {
                ASSERT_GE(v, 0);
                ASSERT_LE(v, 0.8 / 4 + 0.01) << x << "," << y;
            }
        }
    }
    EXPECT_GT(inside, 60);

    // A light sphere resting on the floor: at the point of contact, and just beside it.
    Scene resting = floor_scene(4, 4);
    resting.settings.shadow_rays = 64;
    resting.lights.push_back(
        std::make_unique<SphereLight>(Vec3{0, 10, 0}, 10.0, Color{1, 1, 1}, false));
    const Tracer tracer(resting);
    for (const double x : {0.0, 1e-12, 1e-6, 1e-3, 0.1}) {
        const Color c = tracer.trace({{x, 50, 0}, {0, -1, 0}, 0});
        ASSERT_TRUE(is_finite(c)) << x;
        EXPECT_GE(c.r, 0.8 / 4 - 0.01) << x;
        EXPECT_LE(c.r, 0.8 / 2 + 0.01) << x;
    }
}

TEST(Robustness, EverySceneInTheRepositoryRendersFinite) {
    // Small and with few samples: the geometry, materials and effects are what matter here.
    int scenes = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(
             std::filesystem::path(DRT_SOURCE_DIR) / "scenes")) {
        if (entry.path().extension() != ".xml") continue;
        ++scenes;
        Scene scene = load_scene(entry.path()).scene;
        RenderSettings& s = scene.settings;
        const double scale = 24.0 / std::max(s.width, s.height);
        s.width = std::max(1, static_cast<int>(std::lround(s.width * scale)));
        s.height = std::max(1, static_cast<int>(std::lround(s.height * scale)));
        s.pixel_plane_unit /= scale;
        s.samples = std::min(s.samples, 4);
        s.shadow_rays = std::min(s.shadow_rays, 4);
        s.glossy_rays = std::min(s.glossy_rays, 2);
        const RenderResult r = render_with(scene);
        for (const float v : r.image.rgb) {
            ASSERT_TRUE(std::isfinite(v)) << entry.path();
            ASSERT_GE(v, 0.0f) << entry.path();
        }
    }
    EXPECT_GE(scenes, 7);
}

}  // namespace
}  // namespace drt
