#pragma once

#include "drt/util/math.h"

namespace drt {

// A ray carries its shutter time so every object it meets is placed where it was at that moment.
struct Ray {
    Vec3 origin;
    Vec3 dir;  // unit length
    double time = 0;

    constexpr Vec3 at(double t) const { return origin + dir * t; }
};

// The rays through the neighbouring camera samples, one step right and one step down the image
// from a camera ray (ray differentials, as in pbrt): where they meet a surface's tangent plane
// gives the footprint over which a texture is filtered.
struct RayDifferential {
    Ray dx, dy;
};

}  // namespace drt
