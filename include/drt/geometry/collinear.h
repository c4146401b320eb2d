// Whether three points lie on one line, decided exactly on their double coordinates: no
// rounding can make collinear points look apart or points apart look collinear. A triangle of
// zero area in a mesh file is one whose corners are collinear (scene-format.md).
#pragma once

#include "drt/util/math.h"

namespace drt {

// True when a, b and c lie exactly on one line, two or three of them coinciding included.
// Coordinates must be finite.
bool collinear(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace drt
