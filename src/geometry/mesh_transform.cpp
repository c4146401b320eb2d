#include "drt/geometry/mesh_transform.h"

#include <cmath>

namespace drt {

namespace {

// sin and cos of an angle in degrees, exact at multiples of 90 degrees.
SinCos sincos_degrees(double degrees) {
    const double turns = degrees / 90;
    if (turns == std::round(turns)) {
        switch (static_cast<long long>(std::fmod(std::round(turns), 4.0) + 4) % 4) {
            case 0:
                return {0, 1};
            case 1:
                return {1, 0};
            case 2:
                return {0, -1};
            default:
                return {-1, 0};
        }
    }
    const double radians = degrees * (kPi / 180);
    return {std::sin(radians), std::cos(radians)};
}

Vec3 rotate_x(const Vec3& v, SinCos r) {
    return {v.x, v.y * r.cos - v.z * r.sin, v.y * r.sin + v.z * r.cos};
}
Vec3 rotate_y(const Vec3& v, SinCos r) {
    return {v.x * r.cos + v.z * r.sin, v.y, v.z * r.cos - v.x * r.sin};
}
Vec3 rotate_z(const Vec3& v, SinCos r) {
    return {v.x * r.cos - v.y * r.sin, v.x * r.sin + v.y * r.cos, v.z};
}

}  // namespace

Rotation::Rotation(const Vec3& degrees)
    : x_(sincos_degrees(degrees.x)), y_(sincos_degrees(degrees.y)), z_(sincos_degrees(degrees.z)) {}

Vec3 Rotation::operator()(const Vec3& v) const {
    return rotate_z(rotate_y(rotate_x(v, x_), y_), z_);
}

Vec3 MeshTransform::apply(const Vec3& v) const {
    return rotate(v * scale);
}

Vec3 MeshTransform::rotate(const Vec3& v) const {
    return Rotation(rotate_degrees)(v);
}

}  // namespace drt
