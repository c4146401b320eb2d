// Math and colour helpers shared by the unit tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "drt/util/color.h"
#include "drt/util/math.h"
#include "drt/util/rng.h"

namespace drt::testing {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();

// The i-th number of a reproducible uniform stream in [0, 1).
inline double unit(std::uint64_t stream, std::uint64_t i) {
    return to_unit(hash_of(stream, i));
}

// Each channel exactly as given.
inline void expect_color(const Color& c, double r, double g, double b) {
    EXPECT_DOUBLE_EQ(c.r, r);
    EXPECT_DOUBLE_EQ(c.g, g);
    EXPECT_DOUBLE_EQ(c.b, b);
}

// Succeeds when no component of a and b differs by more than tol, and says by how much otherwise.
inline ::testing::AssertionResult near(const Vec3& a, const Vec3& b, double tol) {
    const double d = max_abs_component(a - b);
    if (d <= tol) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "(" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", " << b.y << ", "
           << b.z << ") differ by " << d << " > " << tol;
}

// A deterministic, uniformly distributed unit vector.
inline Vec3 unit_vector(std::uint64_t seed, std::uint64_t i) {
    const double z = 1.0 - 2.0 * to_unit(hash_of(seed, i, 0));
    const double phi = 2.0 * kPi * to_unit(hash_of(seed, i, 1));
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {s * std::cos(phi), s * std::sin(phi), z};
}

// The angle between two vectors, accurate also when it is tiny.
inline double angle_between(const Vec3& a, const Vec3& b) {
    return std::atan2(length(cross(a, b)), dot(a, b));
}

// Irradiance at x, normal n, from a triangle of radiance 1 wholly above x's horizon: Lambert's
// formula for a uniform polygon, E = ½ Σ θ_i n·(v_i × v_i+1)/|v_i × v_i+1| over its edges, v_i
// the unit vectors to the corners and θ_i the angle between them; the winding only flips the sign.
inline double triangle_irradiance(const Vec3& x, const Vec3& n, const Vec3& p0, const Vec3& p1,
                                  const Vec3& p2) {
    const Vec3 v[3] = {normalize(p0 - x), normalize(p1 - x), normalize(p2 - x)};
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3& a = v[i];
        const Vec3& b = v[(i + 1) % 3];
        sum += angle_between(a, b) * dot(n, normalize(cross(a, b)));
    }
    return 0.5 * std::abs(sum);
}

}  // namespace drt::testing
