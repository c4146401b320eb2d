#include "drt/sphere.h"

#include <cmath>

namespace drt {

Sphere::Sphere(std::vector<Vec3> path, double radius, const Material& material,
               SurfaceDetail detail)
    : Object(material, std::move(detail)), path_(std::move(path)), radius_(radius) {}

Vec3 Sphere::centre_at(double time) const {
    if (path_.size() == 1 || time <= 0) return path_.front();
    const double last = static_cast<double>(path_.size() - 1);
    if (time >= last) return path_.back();
    const auto k = static_cast<std::size_t>(time);
    return lerp(path_[k], path_[k + 1], time - static_cast<double>(k));
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

Vec3 Sphere::texture_point(const Vec3& point, double time) const {
    return point - centre_at(time);
}
Vec3 Sphere::bump_point(const Vec3& point, double time) const {
    return point - centre_at(time);
}

}  // namespace drt
