#include "drt/light.h"

#include <cmath>

#include "drt/sphere.h"

namespace drt {

Vec3 sample_cone(Vec2 u, double cos_max) {
    // Uniform in solid angle means uniform in cos(theta) between cos_max and 1.
    const double cos_t = 1.0 - u.x * (1.0 - cos_max);
    const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
    const double phi = 2.0 * kPi * u.y;
    return {sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t};
}

LightSample PointLight::sample(const Vec3& x, Vec2) const {
    const Vec3 d = position_ - x;
    const double dist = length(d);
    return {d / dist, dist};
}

LightSample SphereLight::sample(const Vec3& x, Vec2 u) const {
    const Vec3 to_centre = centre_ - x;
    const double d2 = dot(to_centre, to_centre);
    if (d2 <= radius_ * radius_) {
        const Vec3 dir = sample_cone(u, -1.0);
        const Ray ray{x, dir, 0};
        // From inside, the ray leaves through the far root; on the surface it may meet nothing.
        const auto t = intersect_sphere(centre_, radius_, ray, {0, kInfinity});
        return {dir, t.value_or(0.0)};
    }
    const double d = std::sqrt(d2);
    const double sin2_max = radius_ * radius_ / d2;
    const double cos_max = std::sqrt(std::max(0.0, 1.0 - sin2_max));
    const Vec3 dir = Frame::around(to_centre / d).to_world(sample_cone(u, cos_max));
    // Distance to the near side of the sphere along dir; at the cone's rim the ray grazes it
    // and rounding may miss, in which case the tangent point's distance is exact enough.
    const double b = dot(to_centre, dir);
    const double disc = radius_ * radius_ - (d2 - b * b);
    const double dist = b - std::sqrt(std::max(0.0, disc));
    return {dir, dist};
}

std::optional<double> SphereLight::intersect(const Ray& ray, Interval range) const {
    return intersect_sphere(centre_, radius_, ray, range);
}

}  // namespace drt
