#pragma once

#include <cmath>
#include <limits>
#include <optional>

#include "drt/geometry/object.h"

namespace drt {

// Ray parameter inside `range` where the ray meets the plane through `point` with unit normal
// `normal`. `point_scale` and `origin_scale` are max_abs_component of the point and of the ray's
// origin, which a caller testing many planes or rays works out once. Inline because the BVH runs
// it for every plane and every ray.
inline std::optional<double> intersect_plane(const Vec3& point, const Vec3& normal,
                                             double point_scale, const Ray& ray,
                                             double origin_scale, Interval range) {
    const double denom = dot(ray.dir, normal);
    if (denom == 0) return std::nullopt;
    double distance = dot(point - ray.origin, normal);
    // An origin on the plane up to rounding (a ray leaving a hit point) is at distance exactly 0,
    // so the root t = 0 is excluded by a range starting at 0 instead of landing ~1e-16 away.
    const double on_plane_tolerance =
        8.0 * std::numeric_limits<double>::epsilon() * (origin_scale + point_scale);
    if (std::abs(distance) <= on_plane_tolerance) distance = 0;
    // A plane behind the ray (or NaN) gives t <= 0, which a range from 0 up excludes: decided by
    // the signs, without the division, for the half of a room's walls a ray moves away from.
    const bool ahead = distance > 0 ? denom > 0 : distance < 0 && denom < 0;
    if (!ahead && range.min >= 0) return std::nullopt;
    const double t = distance / denom;
    if (!range.surrounds(t)) return std::nullopt;
    return t;
}

// An infinite plane through `point` with unit normal `normal`.
class Plane final : public Object {
  public:
    Plane(Vec3 point, Vec3 normal, const Material& material, SurfaceDetail detail = {});

    std::optional<Hit> intersect(const Ray& ray, Interval range) const override;
    Shapes shapes() const override { return {{}, {PlaneShape{point_, frame_.n}}}; }

    const Vec3& normal() const { return frame_.n; }
    const Vec3& point() const { return point_; }

  protected:
    // Textures are evaluated in the plane's own 2-D coordinates (about the world origin's
    // projection), so a checker on a plane through the origin has a cell corner there.
    SurfaceCoordinates locate(const Ray& ray, const Hit& hit, SurfaceHit& surface) const override;
    // (u, v) are the point's coordinates along the in-plane axes over TextureScale.
    SurfaceUv surface_uv(const Ray& ray, const Hit& hit, const SurfaceHit& surface) const override;

  private:
    Vec3 point_;
    Frame frame_;
    double offset_;  // dot(normal, point)
};

}  // namespace drt
