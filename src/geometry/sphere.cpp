#include "drt/geometry/sphere.h"

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

}  // namespace drt
