#pragma once

#include "drt/object.h"

namespace drt {

// An infinite plane through `point` with unit normal `normal`.
class Plane final : public Object {
public:
    Plane(Vec3 point, Vec3 normal, const Material& material, SurfaceDetail detail = {});

    std::optional<double> intersect(const Ray& ray, Interval range) const override;
    std::vector<TimedBounds> motion_bounds() const override { return {}; }

    const Vec3& normal() const { return frame_.n; }

protected:
    Vec3 project_to_surface(const Vec3& p, double time) const override;
    Vec3 outward_normal(const Vec3&, double) const override { return frame_.n; }
    // The plane's own 2-D coordinates (about the world origin's projection), so a checker on a
    // plane through the origin has a cell corner there.
    Vec3 texture_point(const Vec3& point, double time) const override;
    Vec3 bump_point(const Vec3& point, double) const override { return point; }

private:
    Vec3 point_;
    Frame frame_;
    double offset_;  // dot(normal, point)
};

}  // namespace drt
