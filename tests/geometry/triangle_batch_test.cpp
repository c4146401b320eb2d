#include "drt/geometry/triangle_batch.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "drt/util/rng.h"
#include "test_math.h"

namespace drt {
namespace {

constexpr float kNoFar = std::numeric_limits<float>::infinity();

Vec3 to_float(const Vec3& v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

// The four triangles of `tris` in the filter's layout for `ray`.
TriangleBatch batch_of(const FloatShearedRay& ray, const std::array<std::array<Vec3, 3>, 4>& tris) {
    TriangleBatch batch;
    for (int v = 0; v < 3; ++v) {
        for (int a = 0; a < 3; ++a) {
            const int k = ray.axis(a);
            batch.corners[v][a] =
                _mm_setr_ps(static_cast<float>(tris[0][v][k]), static_cast<float>(tris[1][v][k]),
                            static_cast<float>(tris[2][v][k]), static_cast<float>(tris[3][v][k]));
        }
    }
    return batch;
}

float float_up(double x) {
    const auto f = static_cast<float>(x);
    return f < x ? std::nextafter(f, kNoFar) : f;
}
float float_down(double x) {
    const auto f = static_cast<float>(x);
    return f > x ? std::nextafter(f, -kNoFar) : f;
}

// Rays aimed exactly at corners, at points on edges (not representable in float, so that the
// origin's rounding to float counts) and inside random triangles, slivers among them, at every
// scale and from near and far: wherever the double test hits, the filter must let the triangle
// through, also when the range ends just past the hit or starts just before it. The triangle
// sits in each of the four lanes in turn, beside three others.
TEST(TriangleBatch, NeverRulesOutATriangleTheDoubleTestHits) {
    int hits = 0;
    for (const double scale : {1e-3, 1.0, 1e3, 1e7}) {
        for (std::uint64_t i = 0; i < 3000; ++i) {
            std::array<Vec3, 3> tri;
            for (int k = 0; k < 3; ++k)
                tri[k] = to_float(testing::unit_vector(20, 3 * i + k) * scale);
            if (i % 3 == 0) {
                // A sliver: the third corner a hair off the line of the first two.
                tri[2] = to_float(tri[0] * 0.5 + tri[1] * 0.5 +
                                  testing::unit_vector(21, i) * (scale * 1e-6));
            }
            const double w = to_unit(hash_of(22, i, 0));
            const Vec3 targets[] = {tri[i % 3], tri[0] * (1 - w) + tri[1] * w,
                                    tri[1] * 0.375 + tri[2] * 0.625,
                                    (tri[0] + tri[1] + tri[2]) / 3};
            const double distance = scale * (i % 2 ? 3 : 1e5);
            for (const Vec3& target : targets) {
                const Vec3 dir = testing::unit_vector(23, i);
                const Ray ray{target - dir * distance, dir};
                const ShearedRay sheared(ray);
                const auto hit =
                    intersect_triangle(sheared, tri[0], tri[1], tri[2], {0, kInfinity});
                if (!hit) continue;
                ++hits;
                const FloatShearedRay filter(sheared);
                ASSERT_TRUE(filter.usable());
                const double just_after = std::nextafter(hit->t, kInfinity);
                const double just_before = std::nextafter(hit->t, 0.0);
                ASSERT_TRUE(intersect_triangle(sheared, tri[0], tri[1], tri[2], {0, just_after}));
                ASSERT_TRUE(
                    intersect_triangle(sheared, tri[0], tri[1], tri[2], {just_before, kInfinity}));
                for (int lane = 0; lane < 4; ++lane) {
                    std::array<std::array<Vec3, 3>, 4> tris;
                    for (int k = 0; k < 4; ++k) {
                        const Vec3 shift = testing::unit_vector(24, 4 * i + k) * scale;
                        tris[k] = {to_float(tri[0] + shift), to_float(tri[1] + shift),
                                   to_float(tri[2] + shift)};
                    }
                    tris[lane] = tri;
                    const TriangleBatch batch = batch_of(filter, tris);
                    const int bit = 1 << lane;
                    EXPECT_TRUE(filter.maybe_hits(batch, 0, kNoFar) & bit)
                        << "scale " << scale << " triangle " << i << " lane " << lane;
                    EXPECT_TRUE(filter.maybe_hits(batch, 0, float_up(just_after)) & bit)
                        << "scale " << scale << " triangle " << i << " (range ends past the hit)";
                    EXPECT_TRUE(filter.maybe_hits(batch, float_down(just_before), kNoFar) & bit)
                        << "scale " << scale << " triangle " << i << " (range starts before it)";
                }
            }
        }
    }
    EXPECT_GT(hits, 25000);
}

// The other side of the filter: where it is certain of a hit (what lets an any-hit query skip
// the double test), the double test must hit, whatever the range. Rays aimed at corners, at
// points on edges and a hair either side of them, and inside, at triangles of every scale and
// shape; ranges that end just past or just short of the hit, or start just before or after it.
TEST(TriangleBatch, IsCertainOfAHitOnlyWhereTheDoubleTestHits) {
    int certain = 0, hits = 0, clear_hits = 0, certain_clear = 0;
    for (const double scale : {1e-3, 1.0, 1e3, 1e7}) {
        for (std::uint64_t i = 0; i < 3000; ++i) {
            std::array<Vec3, 3> tri;
            for (int k = 0; k < 3; ++k)
                tri[k] = to_float(testing::unit_vector(40, 3 * i + k) * scale);
            if (i % 3 == 0) {
                tri[2] = to_float(tri[0] * 0.5 + tri[1] * 0.5 +
                                  testing::unit_vector(41, i) * (scale * 1e-6));
            }
            const double w = to_unit(hash_of(42, i, 0));
            const Vec3 edge = tri[0] * (1 - w) + tri[1] * w;
            const Vec3 off = (tri[2] - edge) * 1e-7;
            const Vec3 targets[] = {tri[i % 3], edge, edge + off, edge - off,
                                    (tri[0] + tri[1] + tri[2]) / 3};
            // From near and from far; and, every fourth, along a direction of length 1e-18,
            // where the double test's bound on the error of its own t (which grows as 1 / |d|²,
            // t as 1 / |d|) exceeds t and the hit is missed.
            const double distance = scale * (i % 2 ? 3 : 1e5);
            const double length = i % 4 == 3 ? 1e-18 : 1;
            for (int n = 0; n < 5; ++n) {
                const Vec3& target = targets[n];
                const Vec3 dir = testing::unit_vector(43, i);
                const Ray ray{target - dir * distance, dir * length};
                const ShearedRay sheared(ray);
                const FloatShearedRay filter(sheared);
                ASSERT_TRUE(filter.usable());
                const auto hit =
                    intersect_triangle(sheared, tri[0], tri[1], tri[2], {0, kInfinity});
                hits += hit.has_value();
                const double t = hit ? hit->t : distance;
                const Interval ranges[] = {{0, kInfinity}, {0, std::nextafter(t, kInfinity)},
                                           {0, t},         {std::nextafter(t, 0.0), kInfinity},
                                           {t, kInfinity}, {t * 0.5, t * 2}};
                std::array<std::array<Vec3, 3>, 4> tris{tri, tri, tri, tri};
                const TriangleBatch batch = batch_of(filter, tris);
                for (const Interval& range : ranges) {
                    const auto verdict =
                        filter.classify(batch, float_down(range.min), float_up(range.max),
                                        float_up(range.min), float_down(range.max));
                    // The centre of a triangle that is not a sliver, seen from near, in a
                    // range with room either side of the hit: a hit the filter should be sure
                    // of (from far, the origin's rounding to float blurs what it sees).
                    const bool clear = hit && n == 4 && i % 3 != 0 && i % 4 == 1 &&
                                       (range.max == kInfinity || range.max == t * 2) &&
                                       range.min < t * 0.75;
                    clear_hits += clear;
                    if (verdict.certain == 0) continue;
                    certain_clear += clear;
                    EXPECT_EQ(verdict.certain, 0xf);
                    EXPECT_EQ(verdict.maybe, 0xf);
                    ++certain;
                    EXPECT_TRUE(intersect_triangle(sheared, tri[0], tri[1], tri[2], range))
                        << "scale " << scale << " triangle " << i << " range " << range.min
                        << " .. " << range.max;
                }
            }
        }
    }
    EXPECT_GT(hits, 25000);
    EXPECT_GT(clear_hits, 3500);
    EXPECT_EQ(certain_clear, clear_hits);
}

// The filter is worth running only if it rules out what is clearly missed: rays passing a
// triangle by a tenth of its size, a triangle beyond the range's end, one behind the origin.
TEST(TriangleBatch, RulesOutClearMissesAndHitsOutsideTheRange) {
    const std::array<Vec3, 3> tri{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}};
    std::array<std::array<Vec3, 3>, 4> tris{tri, tri, tri, tri};
    for (std::uint64_t i = 0; i < 1000; ++i) {
        // Beside the hypotenuse, outside by 0.1 to 1.1 of the legs' length, from above.
        const double along = to_unit(hash_of(30, i, 0));
        const double out = 0.1 + to_unit(hash_of(30, i, 1));
        const Vec3 beside = Vec3{along, 1 - along, 0} + Vec3{1, 1, 0} * (out / std::sqrt(2.0));
        const Vec3 dir = normalize(Vec3{0.2, -0.1, -1} + testing::unit_vector(31, i) * 0.1);
        const Ray ray{beside - dir * 5, dir};
        const ShearedRay sheared(ray);
        ASSERT_FALSE(intersect_triangle(sheared, tri[0], tri[1], tri[2], {0, kInfinity}));
        const FloatShearedRay filter(sheared);
        EXPECT_EQ(filter.maybe_hits(batch_of(filter, tris), 0, kNoFar), 0) << "ray " << i;
    }
    // Straight down onto the triangle at t = 5: in [0, 4.9] and [5.1, ∞) it is ruled out.
    const Ray down{{0.25, 0.25, 5}, {0, 0, -1}};
    const ShearedRay sheared(down);
    const FloatShearedRay filter(sheared);
    const TriangleBatch batch = batch_of(filter, tris);
    EXPECT_EQ(filter.maybe_hits(batch, 0, kNoFar), 0xf);
    EXPECT_EQ(filter.maybe_hits(batch, 0, 4.9f), 0);
    EXPECT_EQ(filter.maybe_hits(batch, 5.1f, kNoFar), 0);
    const Ray up{{0.25, 0.25, 5}, {0, 0, 1}};
    const FloatShearedRay away(ShearedRay{up});
    EXPECT_EQ(away.maybe_hits(batch_of(away, tris), 0, kNoFar), 0);
}

// Where float cannot hold the ray (an origin beyond kLargest, a direction whose 1 / d
// overflows a float), the filter declares itself unusable, and the caller tests in double.
TEST(TriangleBatch, IsUnusableForRaysBeyondItsBounds) {
    EXPECT_TRUE(FloatShearedRay(ShearedRay(Ray{{1e14, 0, 0}, {0, 0, 1}})).usable());
    EXPECT_FALSE(FloatShearedRay(ShearedRay(Ray{{1e16, 0, 0}, {0, 0, 1}})).usable());
    EXPECT_FALSE(FloatShearedRay(ShearedRay(Ray{{0, 0, 0}, {0, 0, 1e-40}})).usable());
}

}  // namespace
}  // namespace drt
