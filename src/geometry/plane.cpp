#include "drt/geometry/plane.h"

#include <cmath>

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

std::optional<Hit> Plane::intersect(const Ray& ray, Interval range) const {
    const auto t = intersect_plane(point_, frame_.n, max_abs_component(point_), ray,
                                   max_abs_component(ray.origin), range);
    if (!t) return std::nullopt;
    return Hit{*t, this, 0, {}};
}

Object::SurfaceCoordinates Plane::locate(const Ray& ray, const Hit& hit,
                                         SurfaceHit& surface) const {
    const Vec3 p = ray.at(hit.t);
    const Vec3 point = p - frame_.n * (dot(p, frame_.n) - offset_);
    surface.point = surface.light_point = point;
    surface.normal = surface.shading_normal = surface.light_normal = frame_.n;
    return {{dot(point, frame_.t), dot(point, frame_.b), 0}, point};
}

SurfaceUv Plane::surface_uv(const Ray&, const Hit&, const SurfaceHit& surface) const {
    const double scale = detail().texture_scale;
    return {{dot(surface.point, frame_.t) / scale, dot(surface.point, frame_.b) / scale},
            frame_.t * scale,
            frame_.b * scale};
}

}  // namespace drt
