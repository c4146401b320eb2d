// The abstract scene object: something a ray can hit, made of a material, optionally textured
// and bump-mapped.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "drt/color.h"
#include "drt/material.h"
#include "drt/math.h"
#include "drt/ray.h"
#include "drt/texture.h"

namespace drt {

// What the integrator needs to know about the point a ray hit.
struct SurfaceHit {
    Vec3 point;           // on the surface, refined after intersection
    Vec3 normal;          // geometric, unit, pointing out of the object
    Vec3 shading_normal;  // normal after bump mapping, same side as `normal`
    Color kd;             // diffuse colour after texturing
};

// Bounds of an object over a span of shutter time; a moving object has one per path segment,
// so a BVH can skip it at times it is elsewhere.
struct TimedBounds {
    Bounds bounds;
    Interval time{-kInfinity, kInfinity};
};

// How an object's surface departs from its material's plain colour.
struct SurfaceDetail {
    std::shared_ptr<const Texture> texture;  // replaces the material's kd; null = none
    std::optional<BumpMap> bump;
};

class Object {
  public:
    Object(const Material& material, SurfaceDetail detail)
        : material_(&material), detail_(std::move(detail)) {}
    virtual ~Object() = default;
    Object(const Object&) = delete;
    Object& operator=(const Object&) = delete;

    // Ray parameter of the nearest intersection inside `range`, if any.
    virtual std::optional<double> intersect(const Ray& ray, Interval range) const = 0;
    // Bounding boxes over time; empty for an unbounded object (a plane).
    virtual std::vector<TimedBounds> motion_bounds() const = 0;

    const Material& material() const { return *material_; }
    const SurfaceDetail& detail() const { return detail_; }
    // Shutter time at which the object's motion path ends; 0 for an object that stays put.
    virtual double motion_end() const { return 0; }
    bool moves() const { return motion_end() > 0; }

    // Surface information at ray.at(t), where t came from intersect().
    SurfaceHit surface_at(const Ray& ray, double t) const;

  protected:
    // The exact point on the surface nearest to `p`, which removes most of the rounding error
    // a hit point picks up from ray.at(t).
    virtual Vec3 project_to_surface(const Vec3& p, double time) const = 0;
    virtual Vec3 outward_normal(const Vec3& point, double time) const = 0;
    // Coordinates a texture is evaluated in, and world-aligned coordinates for bump noise.
    virtual Vec3 texture_point(const Vec3& point, double time) const = 0;
    virtual Vec3 bump_point(const Vec3& point, double time) const = 0;

  private:
    const Material* material_;
    SurfaceDetail detail_;
};

}  // namespace drt
