// Geometry helpers shared by the unit tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "drt/util/math.h"
#include "drt/util/rng.h"

namespace drt::testing {

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

}  // namespace drt::testing
