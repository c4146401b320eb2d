#include "drt/plane.h"

#include <cmath>
#include <limits>

namespace drt {

namespace {

// In-plane axes that follow the world axes where possible, so a floor's checker cells line up
// with x and z rather than with an arbitrary rotation.
Frame plane_frame(const Vec3& n) {
    const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int least = 0;
    for (int i = 1; i < 3; ++i) {
        if (std::abs(n[i]) < std::abs(n[least])) least = i;
    }
    const Vec3 u = normalize(axes[least] - n * dot(axes[least], n));
    return {u, cross(n, u), n};
}

}  // namespace

Plane::Plane(Vec3 point, Vec3 normal, const Material& material, SurfaceDetail detail)
    : Object(material, std::move(detail)),
      point_(point),
      frame_(plane_frame(normalize(normal))),
      offset_(dot(frame_.n, point)) {}

std::optional<double> Plane::intersect(const Ray& ray, Interval range) const {
    const double denom = dot(ray.dir, frame_.n);
    if (denom == 0) return std::nullopt;
    double distance = dot(point_ - ray.origin, frame_.n);
    // An origin on the plane up to rounding (a ray leaving a hit point) is at distance exactly 0,
    // so the root t = 0 is excluded by a range starting at 0 instead of landing ~1e-16 away.
    const double on_plane_tolerance = 8.0 * std::numeric_limits<double>::epsilon() *
                                      (max_abs_component(ray.origin) + max_abs_component(point_));
    if (std::abs(distance) <= on_plane_tolerance) distance = 0;
    const double t = distance / denom;
    if (!range.surrounds(t)) return std::nullopt;
    return t;
}

Vec3 Plane::project_to_surface(const Vec3& p, double) const {
    return p - frame_.n * (dot(p, frame_.n) - offset_);
}

Vec3 Plane::texture_point(const Vec3& point, double) const {
    return {dot(point, frame_.t), dot(point, frame_.b), 0};
}

}  // namespace drt
