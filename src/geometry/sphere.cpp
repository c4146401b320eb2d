#include "drt/geometry/sphere.h"

#include <algorithm>
#include <cmath>

namespace drt {

Sphere::Sphere(std::vector<Vec3> path, double radius, const Material& material,
               SurfaceDetail detail)
    : Object(material, std::move(detail)), path_(std::move(path)), radius_(radius) {}

std::optional<Hit> Sphere::intersect(const Ray& ray, Interval range) const {
    const auto t = intersect_sphere(path_.at(ray.time), radius_, ray, range);
    if (!t) return std::nullopt;
    return Hit{*t, this, 0, {}};
}

Object::SurfaceCoordinates Sphere::locate(const Ray& ray, const Hit& hit,
                                          SurfaceHit& surface) const {
    const Vec3 c = path_.at(ray.time);
    const Vec3 point = c + normalize(ray.at(hit.t) - c) * radius_;
    const Vec3 normal = normalize(point - c);
    surface.point = surface.light_point = point;
    surface.normal = surface.shading_normal = surface.light_normal = normal;
    // Textures and bumps move with the sphere.
    return {point - c, point - c};
}

SurfaceUv Sphere::surface_uv(const Ray&, const Hit&, const SurfaceHit& surface) const {
    const Vec3& d = surface.normal;
    double phi = std::atan2(-d.z, d.x);
    if (phi < 0) phi += 2 * kPi;
    const double u = phi / (2 * kPi);
    const double v = 1 - std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
    // ∂p/∂φ = r (dz, 0, −dx); ∂p/∂θ = r (cos θ cos φ, −sin θ, −cos θ sin φ), θ = π (1 − v).
    const double sin_theta = std::sqrt(d.x * d.x + d.z * d.z);
    const Vec3 dp_du = Vec3{d.z, 0, -d.x} * (2 * kPi * radius_);
    const Vec3 dp_dv =
        sin_theta > 0
            ? Vec3{d.y * d.x / sin_theta, -sin_theta, d.y * d.z / sin_theta} * (-kPi * radius_)
            : Vec3{};
    return {{u, v}, dp_du, dp_dv};
}

}  // namespace drt
