#pragma once

#include <vector>

#include "drt/object.h"

namespace drt {

// A sphere, optionally moving along a polyline: path[0] is its position at time 0 (the
// present), path[k] at time k (the past), linear in between, resting at the last position after.
class Sphere final : public Object {
public:
    Sphere(std::vector<Vec3> path, double radius, const Material& material, SurfaceDetail detail = {});

    std::optional<double> intersect(const Ray& ray, Interval range) const override;
    std::vector<TimedBounds> motion_bounds() const override;
    double motion_end() const override { return static_cast<double>(path_.size() - 1); }

    Vec3 centre_at(double time) const;
    double radius() const { return radius_; }
    const std::vector<Vec3>& path() const { return path_; }

protected:
    Vec3 project_to_surface(const Vec3& p, double time) const override;
    Vec3 outward_normal(const Vec3& point, double time) const override;
    Vec3 texture_point(const Vec3& point, double time) const override;
    Vec3 bump_point(const Vec3& point, double time) const override;

private:
    std::vector<Vec3> path_;
    double radius_;
};

// Nearest root of |o + t d - c|^2 = r^2 inside `range` (d unit length), computed so that it
// stays accurate far from the origin and for rays that start on the sphere.
std::optional<double> intersect_sphere(const Vec3& centre, double radius, const Ray& ray,
                                       Interval range);

}  // namespace drt
