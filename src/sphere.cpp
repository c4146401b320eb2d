#include "drt/sphere.h"

#include <cmath>
#include <limits>

namespace drt {

Sphere::Sphere(std::vector<Vec3> path, double radius, const Material& material, SurfaceDetail detail)
    : Object(material, std::move(detail)), path_(std::move(path)), radius_(radius) {}

Vec3 Sphere::centre_at(double time) const {
    if (path_.size() == 1 || time <= 0) return path_.front();
    const double last = static_cast<double>(path_.size() - 1);
    if (time >= last) return path_.back();
    const auto k = static_cast<std::size_t>(time);
    return lerp(path_[k], path_[k + 1], time - static_cast<double>(k));
}

std::optional<double> intersect_sphere(const Vec3& centre, double radius, const Ray& ray,
                                       Interval range) {
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
    const double on_surface_tolerance = 16.0 * std::numeric_limits<double>::epsilon() * radius *
                                        (max_abs_component(ray.origin) + radius);
    if (std::abs(c) <= on_surface_tolerance) c = 0;
    // q has the sign of -b, so no cancellation; the two roots are q and c/q.
    const double q = -b - std::copysign(std::sqrt(disc), b);
    double t0 = q, t1 = q != 0 ? c / q : 0;
    if (t0 > t1) std::swap(t0, t1);
    if (range.surrounds(t0)) return t0;
    if (range.surrounds(t1)) return t1;
    return std::nullopt;
}

std::optional<double> Sphere::intersect(const Ray& ray, Interval range) const {
    return intersect_sphere(centre_at(ray.time), radius_, ray, range);
}

std::vector<TimedBounds> Sphere::motion_bounds() const {
    const Vec3 r{radius_, radius_, radius_};
    if (path_.size() == 1) return {{Bounds{}.grow(path_[0] - r).grow(path_[0] + r)}};  // all time
    std::vector<TimedBounds> segments;
    for (std::size_t k = 0; k + 1 < path_.size(); ++k) {
        Bounds b;
        b.grow(path_[k] - r).grow(path_[k] + r).grow(path_[k + 1] - r).grow(path_[k + 1] + r);
        // The first and last segments also cover all time before and after the path.
        const double t0 = k == 0 ? -kInfinity : static_cast<double>(k);
        const double t1 = k + 2 == path_.size() ? kInfinity : static_cast<double>(k + 1);
        segments.push_back({b, {t0, t1}});
    }
    return segments;
}

Vec3 Sphere::project_to_surface(const Vec3& p, double time) const {
    const Vec3 c = centre_at(time);
    return c + normalize(p - c) * radius_;
}

Vec3 Sphere::outward_normal(const Vec3& point, double time) const {
    return normalize(point - centre_at(time));
}

Vec3 Sphere::texture_point(const Vec3& point, double time) const { return point - centre_at(time); }
Vec3 Sphere::bump_point(const Vec3& point, double time) const { return point - centre_at(time); }

}  // namespace drt
