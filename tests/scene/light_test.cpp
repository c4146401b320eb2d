#include "drt/scene/light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "drt/sampling/multi_jittered.h"
#include "drt/sampling/sampler.h"
#include "drt/util/rng.h"
#include "test_math.h"

namespace drt {
namespace {

using testing::angle_between;
using testing::unit_vector;

constexpr Color kWhite{1, 1, 1};

// k well-distributed points of the unit square.
std::vector<Vec2> stratified_square(std::uint32_t k, std::uint32_t key) {
    std::vector<Vec2> points;
    for (std::uint32_t j = 0; j < k; ++j) points.push_back(multi_jittered(j, k, key));
    return points;
}

TEST(LightPoint, SampleIsTheExactDirectionAndDistance) {
    const PointLight light({4, 6, 3}, kWhite);
    EXPECT_TRUE(light.is_point());
    EXPECT_FALSE(light.visible());
    for (const Vec2 u : {Vec2{0, 0}, Vec2{0.3, 0.9}, Vec2{0.99, 0.5}}) {
        const LightSample s = light.sample({1, 2, 3}, u);
        EXPECT_DOUBLE_EQ(s.distance, 5.0);
        EXPECT_DOUBLE_EQ(s.dir.x, 0.6);
        EXPECT_DOUBLE_EQ(s.dir.y, 0.8);
        EXPECT_EQ(s.dir.z, 0.0);
    }
    EXPECT_FALSE(light.intersect({{0, 0, 0}, {0.8, 0.6, 0}}, {}));
}

// The batch is vectorised (and in a portable build has an AVX2 clone): it must give exactly
// the scalar answers, or images would depend on the machine and on how rays are grouped.
TEST(LightSphere, BatchSamplesAreBitIdenticalToSingleOnes) {
    const SphereLight light({300, 450, 300}, 40, kWhite, false);
    for (const Vec3 x : {Vec3{12, 0, -7}, Vec3{299, 0, 301}, Vec3{-1000, 2000, 5}}) {
        // Odd counts leave a remainder for the vector loop's scalar tail; u.y covers all four
        // quarter turns, their boundaries and both ends of the square.
        for (const std::uint32_t k : {1u, 7u, 9u, 64u}) {
            std::vector<Vec2> u = stratified_square(k, k);
            u.insert(u.end(),
                     {{0, 0}, {1, 1}, {0.5, 0.125}, {0.25, 0.375}, {0.75, 0.625}, {0.999, 0.875}});
            std::vector<LightSample> batch(u.size());
            light.sample(x, u, batch);
            for (std::size_t i = 0; i < u.size(); ++i) {
                const LightSample one = light.sample(x, u[i]);
                EXPECT_EQ(batch[i].dir.x, one.dir.x) << i;
                EXPECT_EQ(batch[i].dir.y, one.dir.y) << i;
                EXPECT_EQ(batch[i].dir.z, one.dir.z) << i;
                EXPECT_EQ(batch[i].distance, one.distance) << i;
            }
        }
    }
}

// The shortcut for shadow rays nothing blocks: the same cosines as sampling the direction and
// taking lit_cosine of it, to rounding, and zero for the same directions away from the horizon.
TEST(LightSphere, LitCosinesAreThoseOfTheSampledDirections) {
    const SphereLight light({0, 10, 0}, 3, kWhite, false);
    const std::vector<Vec2> u = stratified_square(256, 3);
    std::vector<double> cosines(u.size());
    int lit = 0, dark = 0;
    for (int k = 0; k < 50; ++k) {
        // Normals from straight at the light to past the horizon, and a geometric normal tilted
        // away from the shading one, as on a bump-mapped surface.
        const double tilt = 0.05 * k;
        const Vec3 shading{std::sin(tilt), std::cos(tilt), 0};
        const Vec3 geometric = normalize(Vec3{0, std::cos(0.8 * tilt), std::sin(0.8 * tilt)});
        light.lit_cosines({0, 0, 0}, shading, geometric, u, cosines);
        for (std::size_t i = 0; i < u.size(); ++i) {
            const Vec3 dir = light.sample({0, 0, 0}, u[i]).dir;
            const double expected = lit_cosine(dir, shading, geometric);
            const bool near_horizon =
                std::abs(dot(shading, dir)) < 1e-12 || std::abs(dot(geometric, dir)) < 1e-12;
            if (!near_horizon) {
                ASSERT_EQ(cosines[i] > 0, expected > 0) << k << " " << i;
            }
            EXPECT_NEAR(cosines[i], expected, 1e-15) << k << " " << i;
            (expected > 0 ? lit : dark) += 1;
        }
    }
    EXPECT_GT(lit, 1000);  // both cases occur
    EXPECT_GT(dark, 1000);
}

TEST(LightSphere, PowerIsTheLuminanceOfTheIntensity) {
    const SphereLight light({0, 0, 0}, 1, {1, 0, 0}, false);
    EXPECT_DOUBLE_EQ(light.power(), 0.2126);
    EXPECT_FALSE(light.is_point());
}

TEST(LightSphere, SamplesLieInTheSubtendedConeAndLandOnTheSphere) {
    struct Case {
        Vec3 centre;
        double radius;
        Vec3 x;
    };
    const Case cases[] = {
        {{0, 10, 0}, 1, {0, 0, 0}},       {{300, 450, 300}, 40, {12, 0, -7}},
        {{0, 0, 0}, 1, {0, 0, 1.0001}},    // almost touching: a nearly hemispherical cone
        {{5, 5, 5}, 1e-3, {-100, 3, 40}},  // tiny and far
        {{0, 0, -3}, 2, {0.5, 0.5, 0}},
    };
    for (std::size_t k = 0; k < std::size(cases); ++k) {
        const auto& [c, r, x] = cases[k];
        const SphereLight light(c, r, kWhite, false);
        const double d = length(c - x);
        const double half_angle = std::asin(r / d);
        double widest = 0;
        for (const Vec2 u : stratified_square(1024, static_cast<std::uint32_t>(k))) {
            const LightSample s = light.sample(x, u);
            ASSERT_NEAR(length(s.dir), 1.0, 1e-14) << k;
            const double angle = angle_between(s.dir, c - x);
            EXPECT_LE(angle, half_angle + 1e-12) << k;
            widest = std::max(widest, angle);
            // On the near side of the sphere.
            EXPECT_NEAR(length(x + s.dir * s.distance - c), r, 1e-9 * (r + d)) << k;
            EXPECT_LE(s.distance, dot(c - x, s.dir) + 1e-9 * d) << k;
            EXPECT_GT(s.distance, 0) << k;
        }
        EXPECT_GT(widest, 0.95 * half_angle) << k;  // and they do fill the cone
    }
}

TEST(LightSphere, AverageCosineOverTheCapMatchesTheAnalyticValue) {
    // Uniform over a cap of half-angle alpha, cos(theta) is uniform on [cos alpha, 1], so
    // (1/Omega) Int_cap cos(theta) dw = (1 + cos alpha) / 2. A cap tilted by beta from the normal,
    // still wholly above the horizon, averages N . (mean direction) = cos(beta) (1 + cos alpha)/2.
    const double r = 40, height = 150;
    const Vec3 x{3, -2, 1};
    const SphereLight light(x + Vec3{0, height, 0}, r, kWhite, false);
    const double cos_alpha = std::sqrt(1 - (r / height) * (r / height));
    const std::uint32_t k = 4096;
    for (const double beta : {0.0, 0.3, 1.0}) {
        const Vec3 normal{std::sin(beta), std::cos(beta), 0};
        double sum = 0;
        for (const Vec2 u : stratified_square(k, 7)) {
            sum += std::max(0.0, dot(normal, light.sample(x, u).dir));
        }
        EXPECT_NEAR(sum / k, std::cos(beta) * (1 + cos_alpha) / 2, 1e-4) << beta;
    }
    // A small light is a point light: the average is N . L.
    const SphereLight small(x + Vec3{0, height, 0}, 1e-3, kWhite, false);
    const Vec3 normal = normalize(Vec3{1, 2, 0});
    double sum = 0;
    for (const Vec2 u : stratified_square(256, 3)) sum += dot(normal, small.sample(x, u).dir);
    EXPECT_NEAR(sum / 256, normal.y, 1e-6);
}

TEST(LightSphere, LightCentredOnTheHorizonAveragesTheAnalyticHalfCapCosine) {
    // With the light's centre on the shading point's horizon, half its cap lies below and adds
    // nothing; over the upper half N . w = sin(theta) cos(phi) about the axis, so
    // (1/Omega) Int_cap max(0, N . w) dw = (alpha - sin alpha cos alpha) / (2 pi (1 - cos alpha)),
    // about 2 alpha / (3 pi): proportional to the cap's angular radius alpha, so a light 2 % too
    // big or too small, or a cone 2 % too wide, moves it by 2 %. A 512 x 512 midpoint grid of
    // the unit square integrates it to within 1e-5 (the error is that of the kink at the horizon,
    // O(1/512^1.5) relative).
    const Vec3 x{-2, 5, 1};
    const Vec3 normal = normalize(Vec3{0, 1, 1});
    const Vec3 along = normalize(Vec3{1, 2, -2});  // on the horizon: N . along = 0
    constexpr int kGrid = 512;
    for (const auto& [distance, radius] : {std::pair{50.0, 5.0}, std::pair{10.0, 6.0}}) {
        const SphereLight light(x + along * distance, radius, kWhite, false);
        const double alpha = std::asin(radius / distance);
        const double expected =
            (alpha - std::sin(alpha) * std::cos(alpha)) / (2 * kPi * (1 - std::cos(alpha)));
        double sum = 0;
        for (int i = 0; i < kGrid; ++i) {
            for (int j = 0; j < kGrid; ++j) {
                const Vec2 u{(i + 0.5) / kGrid, (j + 0.5) / kGrid};
                sum += lit_cosine(light.sample(x, u).dir, normal, normal);
            }
        }
        EXPECT_NEAR(sum / (kGrid * kGrid), expected, 1e-4 * expected) << radius;
    }
}

TEST(LightSphere, ShadingPointInsideOrOnTheSphereGetsFiniteSamples) {
    const Vec3 c{1, 2, 3};
    const double r = 2;
    const SphereLight light(c, r, kWhite, false);
    const Vec3 inside_points[] = {c, c + Vec3{0.5, -1, 0.3}};
    for (const Vec3& x : inside_points) {
        for (const Vec2 u : stratified_square(256, 1)) {
            const LightSample s = light.sample(x, u);
            ASSERT_TRUE(std::isfinite(s.dir.x) && std::isfinite(s.dir.y) && std::isfinite(s.dir.z));
            ASSERT_TRUE(std::isfinite(s.distance));
            EXPECT_NEAR(length(s.dir), 1.0, 1e-14);
            EXPECT_GT(s.distance, 0);
            EXPECT_NEAR(length(x + s.dir * s.distance - c), r, 1e-12);
        }
    }
    // Exactly on the surface, and within rounding of it from outside.
    const Vec3 on_surface[] = {c + Vec3{0, r, 0}, c + Vec3{0, 0, -r}, c + unit_vector(5, 0) * r,
                               c + Vec3{r * (1 + 4e-16), 0, 0}};
    for (const Vec3& x : on_surface) {
        for (const Vec2 u : stratified_square(256, 2)) {
            const LightSample s = light.sample(x, u);
            ASSERT_TRUE(std::isfinite(s.dir.x) && std::isfinite(s.dir.y) && std::isfinite(s.dir.z));
            ASSERT_TRUE(std::isfinite(s.distance));
            EXPECT_NEAR(length(s.dir), 1.0, 1e-14);
            EXPECT_GE(s.distance, 0);
            EXPECT_LE(s.distance, 2 * r + 1e-12);
        }
    }
}

TEST(LightSphere, IntersectFindsTheSphere) {
    const SphereLight light({0, 0, 10}, 2, kWhite, true);
    EXPECT_TRUE(light.visible());
    const auto t = light.intersect({{0, 0, 0}, {0, 0, 1}}, {});
    ASSERT_TRUE(t);
    EXPECT_DOUBLE_EQ(*t, 8.0);
    EXPECT_FALSE(light.intersect({{0, 0, 0}, {0, 0, 1}}, {0, 7.5}));
    EXPECT_FALSE(light.intersect({{0, 0, 0}, {0, 1, 0}}, {}));
}

TEST(LightSampleCone, DirectionsStayInTheConeAndAreUniformInSolidAngle) {
    for (const double cos_max : {-1.0, 0.0, 0.5, 0.9, 0.999}) {
        const std::uint32_t k = 4096;
        double sum_cos = 0, sum_x = 0, sum_y = 0, sum_cos2 = 0;
        for (const Vec2 u : stratified_square(k, 11)) {
            const Vec3 w = sample_cone(u, cos_max);
            ASSERT_NEAR(length(w), 1.0, 1e-14);
            ASSERT_GE(w.z, cos_max - 1e-15);
            sum_cos += w.z, sum_cos2 += w.z * w.z;
            sum_x += w.x, sum_y += w.y;
        }
        // Uniform in solid angle: cos(theta) uniform on [cos_max, 1].
        const double mean = (1 + cos_max) / 2;
        const double mean_sq = (1 + cos_max + cos_max * cos_max) / 3;
        EXPECT_NEAR(sum_cos / k, mean, 1e-4) << cos_max;
        EXPECT_NEAR(sum_cos2 / k, mean_sq, 1e-4) << cos_max;
        // Symmetric about the axis.
        EXPECT_NEAR(sum_x / k, 0, 2e-3) << cos_max;
        EXPECT_NEAR(sum_y / k, 0, 2e-3) << cos_max;
    }
    // The rim and the axis.
    EXPECT_NEAR(sample_cone({1, 0}, 0.5).z, 0.5, 1e-15);
    EXPECT_EQ(sample_cone({0, 0.3}, 0.5).z, 1.0);
}

// A ray sees the nearest visible light in front of its hit; invisible lights and points are not
// seen at all.
TEST(FirstVisibleLight, TheNearestVisibleLightBeforeTheHit) {
    std::vector<std::unique_ptr<Light>> lights;
    lights.push_back(std::make_unique<SphereLight>(Vec3{0, 0, 10}, 1, Color{1, 0, 0}, true));
    lights.push_back(std::make_unique<SphereLight>(Vec3{0, 0, 5}, 1, Color{0, 1, 0}, true));
    lights.push_back(std::make_unique<SphereLight>(Vec3{0, 0, 2}, 0.5, Color{0, 0, 1}, false));
    lights.push_back(std::make_unique<PointLight>(Vec3{0, 0, 1}, Color{1, 1, 1}));
    const Ray ray{{0, 0, 0}, {0, 0, 1}, 0};
    EXPECT_EQ(first_visible_light(lights, ray, kInfinity), lights[1].get());  // enters at 4
    EXPECT_EQ(first_visible_light(lights, ray, 4.5), lights[1].get());
    EXPECT_EQ(first_visible_light(lights, ray, 3.5), nullptr);  // the hit is nearer
    const Ray aside{{3, 0, 0}, {0, 0, 1}, 0};
    EXPECT_EQ(first_visible_light(lights, aside, kInfinity), nullptr);
}

}  // namespace
}  // namespace drt
