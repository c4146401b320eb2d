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

}  // namespace drt
