// Arvo's sampling of spherical triangles: the area against the sum of the angles, every
// direction inside the triangle, directions spread uniformly over it (counted in the four
// triangles of its midpoint subdivision, and the sixteen of theirs), and the unit square's
// edges carried onto its corners and arcs.
#include "drt/sampling/spherical_triangle.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "test_math.h"

namespace drt {
namespace {

using testing::unit;

// α + β + γ − π from the angles between the planes of the arcs: an independent area.
double angle_sum_area(const Vec3& a, const Vec3& b, const Vec3& c) {
    const auto angle = [](const Vec3& at, const Vec3& p, const Vec3& q) {
        return testing::angle_between(cross(at, p), cross(at, q));
    };
    return angle(a, b, c) + angle(b, c, a) + angle(c, a, b) - kPi;
}

bool inside(const SphericalTriangle& t, const Vec3& d) {
    const double s = dot(t.a, cross(t.b, t.c)) > 0 ? 1 : -1;
    const double slack = -1e-12;
    return s * dot(d, cross(t.a, t.b)) >= slack && s * dot(d, cross(t.b, t.c)) >= slack &&
           s * dot(d, cross(t.c, t.a)) >= slack;
}

// Triangles from a viewpoint at the origin, from a sliver to nearly a hemisphere.
std::vector<std::array<Vec3, 3>> triangles() {
    return {
        {Vec3{0, 0, 1}, Vec3{1, 0, 1}, Vec3{0, 1, 1}},
        {Vec3{-1, -1, 0.05}, Vec3{1, -1, 0.05}, Vec3{0, 2, 0.05}},        // nearly 2π
        {Vec3{0, 0, 100}, Vec3{1, 0, 100}, Vec3{0, 1, 100}},              // 5e-5 sr
        {Vec3{-3, 1, 2}, Vec3{3, 1.5, 1}, Vec3{0, 2, -3}},                // around the viewpoint
        {Vec3{0, 0, 1}, Vec3{5, 0.01, 1}, Vec3{-5, 0.02, 1}},             // a sliver
        {Vec3{2, 0.2, -0.3}, Vec3{2.1, -0.1, 0.2}, Vec3{1.9, 0.3, 0.4}},  // obtuse, far off-axis
    };
}

TEST(SphericalTriangle, AreaIsTheAngleSumLessPi) {
    for (const auto& p : triangles()) {
        const SphericalTriangle t = spherical_triangle(p[0], p[1], p[2]);
        EXPECT_NEAR(t.area, angle_sum_area(t.a, t.b, t.c), 1e-9 * (1 + t.area));
        EXPECT_GT(t.area, 0);
        EXPECT_LT(t.area, 2 * kPi);
    }
    // A triangle around the +z axis that fills its octant: a sphere's eighth, π/2.
    EXPECT_NEAR(spherical_triangle({1, 0, 0}, {0, 1, 0}, {0, 0, 1}).area, kPi / 2, 1e-14);
}

TEST(SphericalTriangle, EveryDirectionIsUnitAndInside) {
    for (const auto& p : triangles()) {
        const SphericalTriangle t = spherical_triangle(p[0], p[1], p[2]);
        for (std::uint64_t i = 0; i < 20000; ++i) {
            const Vec3 d = sample_spherical_triangle(t, {unit(1, i), unit(2, i)});
            ASSERT_NEAR(length(d), 1, 1e-12);
            ASSERT_TRUE(inside(t, d)) << "area " << t.area << " sample " << i;
        }
    }
}

TEST(SphericalTriangle, SquareEdgesGoToCornersAndArcs) {
    const SphericalTriangle t = spherical_triangle({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
    EXPECT_TRUE(testing::near(sample_spherical_triangle(t, {0.3, 0}), t.b, 1e-12));
    EXPECT_TRUE(testing::near(sample_spherical_triangle(t, {0, 1}), t.a, 1e-12));
    EXPECT_TRUE(testing::near(sample_spherical_triangle(t, {1, 1}), t.c, 1e-9));
    // u.y = 1 runs along the arc from a to c.
    const Vec3 d = sample_spherical_triangle(t, {0.5, 1});
    EXPECT_NEAR(dot(d, cross(t.a, t.c)), 0, 1e-12);
}

// The four triangles of the midpoint subdivision of (a, b, c), in which a direction is counted.
std::array<std::array<Vec3, 3>, 4> quarters(const std::array<Vec3, 3>& p) {
    const Vec3 ab = normalize(p[0] + p[1]), bc = normalize(p[1] + p[2]),
               ca = normalize(p[2] + p[0]);
    return {{{p[0], ab, ca}, {ab, p[1], bc}, {ca, bc, p[2]}, {ab, bc, ca}}};
}

// Directions fall into the 16 cells of two midpoint subdivisions as often as their areas say:
// Pearson's chi-square with 15 degrees of freedom stays under 37.7 (its 0.1 % tail). A mapping
// uniform in anything but area (say, in the arc's angle rather than its cosine) fails by far.
TEST(SphericalTriangle, DirectionsAreUniformInSolidAngle) {
    for (const auto& p : triangles()) {
        const SphericalTriangle t = spherical_triangle(p[0], p[1], p[2]);
        std::vector<SphericalTriangle> cells;
        for (const auto& q : quarters({t.a, t.b, t.c})) {
            for (const auto& r : quarters(q)) cells.push_back(spherical_triangle(r[0], r[1], r[2]));
        }
        const int n = 160000;
        std::vector<double> counts(cells.size(), 0);
        for (int i = 0; i < n; ++i) {
            const Vec3 d = sample_spherical_triangle(t, {unit(3, i), unit(4, i)});
            for (std::size_t k = 0; k < cells.size(); ++k) {
                if (inside(cells[k], d)) {
                    ++counts[k];
                    break;
                }
            }
        }
        double chi2 = 0, total = 0;
        for (std::size_t k = 0; k < cells.size(); ++k) {
            const double expected = n * cells[k].area / t.area;
            chi2 += (counts[k] - expected) * (counts[k] - expected) / expected;
            total += counts[k];
        }
        EXPECT_EQ(total, n) << "area " << t.area;
        EXPECT_LT(chi2, 37.7) << "area " << t.area;
    }
}

}  // namespace
}  // namespace drt
