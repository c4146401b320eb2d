#include "drt/geometry/collinear.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "drt/util/rng.h"

namespace drt {
namespace {

// The cross product of two edges as doubles compute it: what collinear() must not rely on.
Vec3 rounded_cross(const Vec3& a, const Vec3& b, const Vec3& c) {
    return cross(b - a, c - a);
}

TEST(Collinear, PointsOnALineAreCollinearWhereTheRoundedCrossProductIsNotZero) {
    // b = a + d and c = a + 1.5 d exactly, every coordinate a double.
    const Vec3 a{3.105, -4.48, -5.003};
    const Vec3 b{-1.0950000000000002, 0.8759999999999994, 3.42};
    const Vec3 c{-3.1950000000000003, 3.5539999999999994, 7.6315};
    ASSERT_NE(rounded_cross(a, b, c), Vec3{});
    EXPECT_TRUE(collinear(a, b, c));
    EXPECT_TRUE(collinear(c, a, b));
    EXPECT_TRUE(collinear(b, c, a));
    // One step of the last bit off the line.
    EXPECT_FALSE(collinear(a, b, {c.x, c.y, std::nextafter(c.z, 8.0)}));
    EXPECT_FALSE(collinear(a, {std::nextafter(b.x, 0.0), b.y, b.z}, c));
}

TEST(Collinear, CoincidentCornersAreCollinear) {
    const Vec3 p{0.1, -2.5, 1e7}, q{-3, 4, 5};
    EXPECT_TRUE(collinear(p, p, q));
    EXPECT_TRUE(collinear(p, q, p));
    EXPECT_TRUE(collinear(q, p, p));
    EXPECT_TRUE(collinear(p, p, p));
    EXPECT_TRUE(collinear({}, {}, {}));
    // On an axis, and in a plane of the axes.
    EXPECT_TRUE(collinear({0.1, 0, 0}, {0.2, 0, 0}, {-7.3, 0, 0}));
    EXPECT_TRUE(collinear({0, 1, 0}, {0, 2, 1}, {0, 4, 3}));
    EXPECT_FALSE(collinear({0, 1, 0}, {0, 2, 1}, {0, 4, 3.5}));
}

TEST(Collinear, ATinyTriangleWhoseCrossProductUnderflowsIsNotCollinear) {
    const Vec3 a{}, b{1e-200, 0, 0}, c{0, 1e-200, 0};
    ASSERT_EQ(rounded_cross(a, b, c), Vec3{});
    EXPECT_FALSE(collinear(a, b, c));
    EXPECT_TRUE(collinear(a, b, {3e-200, 0, 0}));
    const double tiny = std::numeric_limits<double>::denorm_min();
    EXPECT_FALSE(collinear({}, {tiny, 0, 0}, {0, tiny, 0}));
    EXPECT_TRUE(collinear({}, {tiny, tiny, tiny}, {2 * tiny, 2 * tiny, 2 * tiny}));
    EXPECT_FALSE(collinear({}, {tiny, tiny, tiny}, {2 * tiny, 3 * tiny, 2 * tiny}));
}

TEST(Collinear, AHugeTriangleWhoseCrossProductOverflowsIsDecidedToo) {
    const Vec3 a{-1e300, -1e300, -1e300}, b{}, c{1e300, 1e300, 1e300};
    EXPECT_TRUE(collinear(a, b, c));
    EXPECT_FALSE(collinear({}, {1e300, 1e300, 0}, {-1e300, 1e300, 0}));
    const double max = std::numeric_limits<double>::max();
    EXPECT_TRUE(collinear({-max, 0, max}, {0, 0, 0}, {max, 0, -max}));
    EXPECT_FALSE(collinear({-max, 0, max}, {0, 0, 0}, {max, 0, std::nextafter(-max, 0.0)}));
}

TEST(Collinear, ALineSpanningTheWholeRangeOfExponents) {
    const double tiny = std::numeric_limits<double>::denorm_min();
    const double max = std::numeric_limits<double>::max();
    // The origin, a smallest subnormal step and a largest double, all along (1, 2, -1).
    EXPECT_TRUE(collinear({}, {tiny, 2 * tiny, -tiny}, {max / 2, max, -max / 2}));
    EXPECT_FALSE(collinear({}, {tiny, 2 * tiny, -tiny}, {max / 2, max, -max / 4}));
    EXPECT_FALSE(collinear({tiny, 0, 0}, {0, tiny, 0}, {max, max, max}));
    // Far off the origin, a step of one ulp across the line at the middle point.
    const Vec3 a{1e15, 1e15, 1e15}, c{3e15, 3e15, 3e15};
    EXPECT_TRUE(collinear(a, {2e15, 2e15, 2e15}, c));
    EXPECT_FALSE(collinear(a, {2e15, 2e15, 2e15 + 0.25}, c));
}

// Points of small whole coordinates on a line, each axis then scaled by its own power of two
// anywhere from the subnormals to near overflow (which keeps them on their line, exactly): all
// collinear; the last corner moved by one ulp off the line: none.
TEST(Collinear, LinesScaledPerAxisAcrossTheWholeExponentRange) {
    int moved_off = 0;
    for (std::uint64_t i = 0; i < 3000; ++i) {
        const auto whole = [&](int k) {
            return static_cast<double>(static_cast<int>(hash_of(21, i, k) % 41) - 20);
        };
        const auto exponent = [&](int k) {
            return static_cast<int>(hash_of(22, i, k) % 2060) - 1060;
        };
        const Vec3 p{whole(0), whole(1), whole(2)}, d{whole(3), whole(4), whole(5)};
        const double t = static_cast<double>(hash_of(23, i, 0) % 7) - 3;
        const Vec3 q = p + d, r = p + d * t;
        const int ex = exponent(0), ey = exponent(1), ez = exponent(2);
        const auto scaled = [&](const Vec3& v) {
            return Vec3{std::ldexp(v.x, ex), std::ldexp(v.y, ey), std::ldexp(v.z, ez)};
        };
        const Vec3 a = scaled(p), b = scaled(q), c = scaled(r);
        ASSERT_TRUE(collinear(a, b, c)) << i;
        // Off the line unless the line runs along y (then moving y keeps it there) or the
        // corners coincide.
        const Vec3 off{c.x, std::nextafter(c.y, 1e300), c.z};
        const bool along_y = d.x == 0 && d.z == 0;
        if (!along_y) {
            EXPECT_FALSE(collinear(a, b, off)) << i;
            ++moved_off;
        }
    }
    EXPECT_GT(moved_off, 2900);
}

}  // namespace
}  // namespace drt
