#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "drt/geometry/object.h"

namespace drt {

// A sphere, optionally moving along a path (MotionPath: path[0] is its position at time 0, the
// present, path[k] at time k, the past).
class Sphere final : public Object {
  public:
    Sphere(std::vector<Vec3> path, double radius, const Material& material,
           SurfaceDetail detail = {});

    std::optional<Hit> intersect(const Ray& ray, Interval range) const override;
    Shapes shapes() const override { return {{SphereShape{&path_, radius_}}, {}}; }
    double motion_end() const override { return path_.end(); }

    double radius() const { return radius_; }
    const MotionPath& path() const { return path_; }

  protected:
    SurfaceCoordinates locate(const Ray& ray, const Hit& hit, SurfaceHit& surface) const override;
    // u = φ/2π with φ = atan2(−dz, dx) in [0, 2π), v = 1 − θ/π with θ = acos(dy), for the unit
    // direction d from the centre: the image's top row is +y, its left edge +x.
    SurfaceUv surface_uv(const Ray& ray, const Hit& hit, const SurfaceHit& surface) const override;

  private:
    MotionPath path_;
    double radius_;
};

// Nearest root of |o + t d - c|^2 = r^2 inside `range` (d unit length), computed so that it
// stays accurate far from the origin and for rays that start on the sphere. `origin_scale` is
// max_abs_component(ray.origin), which a caller testing many spheres works out once per ray.
// Inline because the BVH runs it for every sphere a ray reaches.
inline std::optional<double> intersect_sphere(const Vec3& centre, double radius, const Ray& ray,
                                              double origin_scale, Interval range) {
    // Hearn-Baker style discriminant (as in Ray Tracing Gems ch. 7): r^2 - |oc - b d|^2 avoids
    // the cancellation of b^2 - c when the ray starts far from a small sphere.
    const Vec3 oc = ray.origin - centre;
    const double b = dot(oc, ray.dir);
    const Vec3 closest = oc - ray.dir * b;
    const double disc = radius * radius - dot(closest, closest);
    if (disc < 0) return std::nullopt;
    double c = dot(oc, oc) - radius * radius;
    // An origin on the sphere up to rounding (a ray leaving a hit point) has its near root at
    // exactly 0, which a range starting at 0 excludes, rather than a root of either sign ~1e-16
    // away that would re-hit the sphere going out or stop short of the far side going in.
    const double on_surface_tolerance =
        16.0 * std::numeric_limits<double>::epsilon() * radius * (origin_scale + radius);
    if (std::abs(c) <= on_surface_tolerance) c = 0;
    // q has the sign of -b, so no cancellation; the two roots are q and c/q.
    const double q = -b - std::copysign(std::sqrt(disc), b);
    double t0 = q, t1 = q != 0 ? c / q : 0;
    if (t0 > t1) std::swap(t0, t1);
    if (range.surrounds(t0)) return t0;
    if (range.surrounds(t1)) return t1;
    return std::nullopt;
}

inline std::optional<double> intersect_sphere(const Vec3& centre, double radius, const Ray& ray,
                                              Interval range) {
    return intersect_sphere(centre, radius, ray, max_abs_component(ray.origin), range);
}

}  // namespace drt
