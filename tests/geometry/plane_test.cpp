#include "drt/geometry/plane.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "test_math.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::kEps;
using testing::near;
using testing::plain_material;
using testing::unit_vector;

// Reports the texture coordinates it is evaluated at as its colour.
class RecordingTexture final : public Texture {
  public:
    Color value(const TexturePoint& at) const override {
        return {at.local.x, at.local.y, at.local.z};
    }
};

Vec3 as_vec(const Color& c) {
    return {c.r, c.g, c.b};
}

// The surface at world point p of `plane`, reached by a ray coming down its normal.
SurfaceHit surface_at_point(const Plane& plane, const Vec3& p) {
    const Ray ray{p + plane.normal() * 10.0, -plane.normal()};
    const auto t = plane.intersect(ray, {});
    EXPECT_TRUE(t);
    return plane.surface_at(ray, t.value_or(Hit{10.0, &plane, 0, {}}));
}

TEST(Plane, HitDistanceIsAnalytic) {
    const Plane floor({0, 0, 0}, {0, 1, 0}, plain_material());
    const auto down = floor.intersect({{1, 5, 2}, {0, -1, 0}}, {});
    ASSERT_TRUE(down);
    EXPECT_DOUBLE_EQ(down->t, 5.0);
    // A 3-4-5 triangle.
    const auto oblique = floor.intersect({{0, 4, 0}, {0.6, -0.8, 0}}, {});
    ASSERT_TRUE(oblique);
    EXPECT_NEAR(oblique->t, 5.0, 1e-15);
    // No back-face culling: a ray from below meets it too.
    const auto up = floor.intersect({{7, -3, 1}, {0, 1, 0}}, {});
    ASSERT_TRUE(up);
    EXPECT_DOUBLE_EQ(up->t, 3.0);

    // Through (1, 2, 3) with normal along (1, 1, 1): distance from the origin 6/sqrt(3).
    const Plane tilted({1, 2, 3}, {1, 1, 1}, plain_material());
    const auto diagonal = tilted.intersect({{0, 0, 0}, normalize(Vec3{1, 1, 1})}, {});
    ASSERT_TRUE(diagonal);
    EXPECT_NEAR(diagonal->t, 2.0 * std::sqrt(3.0), 1e-14);
}

TEST(Plane, PlaneBehindOrBeyondTheRangeIsMissed) {
    const Plane floor({0, 0, 0}, {0, 1, 0}, plain_material());
    EXPECT_FALSE(floor.intersect({{0, 5, 0}, {0, 1, 0}}, {}));
    EXPECT_FALSE(floor.intersect({{0, 5, 0}, {0, -1, 0}}, {0, 4.5}));
    EXPECT_TRUE(floor.intersect({{0, 5, 0}, {0, -1, 0}}, {0, 5.5}));
}

TEST(Plane, ParallelRayMisses) {
    const Plane floor({0, 0, 0}, {0, 1, 0}, plain_material());
    EXPECT_FALSE(floor.intersect({{0, 5, 0}, {1, 0, 0}}, {}));
    EXPECT_FALSE(floor.intersect({{0, -5, 0}, normalize(Vec3{1, 0, 1})}, {}));
    // Lying in the plane.
    EXPECT_FALSE(floor.intersect({{3, 0, 4}, {0, 0, 1}}, {}));

    const Plane tilted({1, 2, 3}, {1, 1, 1}, plain_material());
    EXPECT_FALSE(tilted.intersect({{0, 0, 0}, normalize(Vec3{1, -1, 0})}, {}));
}

TEST(Plane, NormalIsNormalisedAndKeepsItsDirection) {
    const Plane scaled({0, 0, 0}, {0, 3, 0}, plain_material());
    EXPECT_EQ(scaled.normal(), (Vec3{0, 1, 0}));
    const Plane tilted({1, 2, 3}, {1, 2, -2}, plain_material());
    EXPECT_TRUE(near(tilted.normal(), {1.0 / 3, 2.0 / 3, -2.0 / 3}, 1e-15));

    // The geometric normal is the plane's, whichever side the ray comes from.
    const Ray above{{10, 10, -10}, normalize(Vec3{-1, -2, 2})};
    const auto t_above = tilted.intersect(above, {});
    ASSERT_TRUE(t_above);
    EXPECT_TRUE(near(tilted.surface_at(above, *t_above).normal, tilted.normal(), 0));
    const Ray below{{-10, -10, 10}, normalize(Vec3{1, 2, -2})};
    const auto t = tilted.intersect(below, {});
    ASSERT_TRUE(t);
    const SurfaceHit hit = tilted.surface_at(below, *t);
    EXPECT_TRUE(near(hit.normal, tilted.normal(), 0));
    EXPECT_EQ(hit.shading_normal, hit.normal);
    EXPECT_NEAR(length(hit.normal), 1.0, 1e-15);
}

TEST(Plane, SurfaceAtProjectsOntoThePlane) {
    const Vec3 p{1e3, -2.7e3, 0.4};
    const Plane plane(p, {0.3, 1, -0.2}, plain_material());
    const Vec3 n = plane.normal();
    for (std::uint64_t i = 0; i < 500; ++i) {
        const Vec3 start = p + unit_vector(1, i) * 1e4;
        const Vec3 d = unit_vector(2, i);
        const auto t = plane.intersect({start, d}, {});
        if (!t) continue;
        const SurfaceHit hit = plane.surface_at({start, d}, *t);
        EXPECT_NEAR(dot(hit.point - p, n), 0.0, 8 * kEps * max_abs_component(hit.point)) << i;
        EXPECT_LT(length(hit.point - (start + d * t->t)), 1e-9 * (t->t + length(start))) << i;
    }
}

// A ray spawned at a refined hit point must not find the same plane again at t ~ 1e-16, with
// the plain range (0, inf).
TEST(Plane, RayFromAPointOnThePlaneDoesNotRehit) {
    struct Case {
        Vec3 point, normal;
    };
    const Case cases[] = {
        {{0, 0, 0}, {0, 1, 0}},
        {{1.3, -2.7, 0.4}, {0.3, 1, -0.2}},
        {{1e5, -1e5, 3e4}, {-0.7, 0.1, 0.2}},
        {{0, 0, 0}, {1, 1, 1}},
    };
    int rehits = 0;
    for (std::size_t k = 0; k < std::size(cases); ++k) {
        const Plane plane(cases[k].point, cases[k].normal, plain_material());
        for (std::uint64_t i = 0; i < 2000; ++i) {
            const Vec3 start = cases[k].point + unit_vector(10 + k, i) * 50.0;
            const Vec3 d = unit_vector(20 + k, i);
            const auto t = plane.intersect({start, d}, {});
            if (!t) continue;
            const SurfaceHit hit = plane.surface_at({start, d}, *t);
            Vec3 out = unit_vector(30 + k, i);
            if (std::abs(dot(out, hit.normal)) < 0.05) continue;
            const auto again = plane.intersect({hit.point, out}, {0, kInfinity});
            if (again) {
                ++rehits;
                ADD_FAILURE() << "case " << k << " ray " << i << ": re-hit at t = " << again->t;
                if (rehits > 10) return;
            }
        }
    }
}

TEST(Plane, CheckerOnAFloorThroughTheOriginHasCleanSquares) {
    const Color a{1, 1, 1}, b{0.1, 0.1, 0.1};
    SurfaceDetail detail;
    detail.texture = std::make_shared<CheckerTexture>(a, b, 50.0);
    const Plane floor({0, 0, 0}, {0, 1, 0}, plain_material(), detail);
    const auto colour = [&](double x, double z) { return surface_at_point(floor, {x, 0, z}).kd; };

    EXPECT_NE(colour(25, 25), colour(75, 25));
    EXPECT_EQ(colour(25, 25), colour(75, 75));
    EXPECT_NE(colour(25, 25), colour(25, 75));
    // Across the origin too (no mirrored double-width cells around the axes).
    EXPECT_NE(colour(25, 25), colour(-25, 25));
    EXPECT_NE(colour(25, 25), colour(25, -25));
    EXPECT_EQ(colour(25, 25), colour(-25, -25));
    EXPECT_NE(colour(-25, 25), colour(-75, 25));

    // Each cell is one colour right up to its edges, and the cell corners lie on multiples of 50.
    for (int cx = -2; cx < 2; ++cx) {
        for (int cz = -2; cz < 2; ++cz) {
            const Color expected = colour(50 * cx + 25, 50 * cz + 25);
            for (const double fx : {0.01, 0.3, 0.5, 0.99}) {
                for (const double fz : {0.01, 0.7, 0.99}) {
                    EXPECT_EQ(colour(50 * (cx + fx), 50 * (cz + fz)), expected)
                        << "cell " << cx << ", " << cz;
                }
            }
        }
    }
}

TEST(Plane, TextureCoordinatesAreAnIsometryOfThePlane) {
    SurfaceDetail detail;
    detail.texture = std::make_shared<RecordingTexture>();
    const Plane plane({4, -2, 7}, {0.3, 1, -0.2}, plain_material(), detail);
    const Vec3 n = plane.normal();
    const Vec3 axis_u = normalize(cross(n, Vec3{1, 0, 0}));
    const Vec3 axis_v = cross(n, axis_u);
    const Vec3 foot = n * dot(n, Vec3{4, -2, 7});  // the world origin's projection

    const Vec3 at_foot = as_vec(surface_at_point(plane, foot).kd);
    EXPECT_TRUE(near(at_foot, {0, 0, 0}, 1e-12));
    for (std::uint64_t i = 0; i < 100; ++i) {
        const Vec3 p = foot + axis_u * (200 * testing::unit(3, i) - 100) +
                       axis_v * (200 * testing::unit(4, i) - 100);
        const Vec3 q = foot + axis_u * (200 * testing::unit(5, i) - 100) +
                       axis_v * (200 * testing::unit(6, i) - 100);
        const Vec3 tp = as_vec(surface_at_point(plane, p).kd);
        const Vec3 tq = as_vec(surface_at_point(plane, q).kd);
        EXPECT_EQ(tp.z, 0.0);
        EXPECT_NEAR(length(tp - tq), length(p - q), 1e-11) << i;
        EXPECT_NEAR(length(tp), length(p - foot), 1e-11) << i;
    }
}

TEST(Plane, FloorTextureAxesFollowWorldXAndZ) {
    SurfaceDetail detail;
    detail.texture = std::make_shared<RecordingTexture>();
    const Plane floor({0, 0, 0}, {0, 1, 0}, plain_material(), detail);
    const Vec3 tp = as_vec(surface_at_point(floor, {30, 0, -70}).kd);
    EXPECT_DOUBLE_EQ(std::abs(tp.x), 30.0);
    EXPECT_DOUBLE_EQ(std::abs(tp.y), 70.0);
}

}  // namespace
}  // namespace drt
