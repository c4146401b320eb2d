// How a mesh file's vertices are turned into the scene's coordinates (before the scene
// translates them): a uniform scale, then rotations about x, y and z in that order.
#pragma once

#include <optional>

#include "drt/util/math.h"

namespace drt {

// Scaled by `scale` (positive), then rotated about x, y and z in that order by `rotate_degrees`
// (right-handed rotations of the vertex).
struct MeshTransform {
    double scale = 1;
    Vec3 rotate_degrees;
    // Where the mesh keeps the origin of its own (single-precision) coordinates, in transformed
    // coordinates; none: the centre of its bounds. Parts of one file given the same origin round
    // their shared vertices alike, so no crack opens between them.
    std::optional<Vec3> origin = std::nullopt;

    Vec3 apply(const Vec3& v) const;
    // The same rotation for a direction (a uniform positive scale leaves directions alone).
    Vec3 rotate(const Vec3& v) const;
};

// The rotation of a MeshTransform, its sines and cosines worked out once for many vectors.
// Exact at multiples of 90 degrees, so that a quarter turn maps float coordinates onto float
// coordinates instead of leaving crumbs of rounding.
class Rotation {
  public:
    explicit Rotation(const Vec3& degrees);
    Vec3 operator()(const Vec3& v) const;

  private:
    SinCos x_, y_, z_;
};

}  // namespace drt
