// A point as a mesh stores it: three single-precision coordinates.
#pragma once

#include <array>

#include "drt/util/math.h"

namespace drt {

using Float3 = std::array<float, 3>;

inline Vec3 to_vec3(const Float3& f) {
    return {f[0], f[1], f[2]};
}

}  // namespace drt
