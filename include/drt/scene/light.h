// Lights: spheres of uniform radiance (the thesis's round lights) and their limit, the point light.
#pragma once

#include <cmath>
#include <memory>
#include <optional>
#include <span>

#include "drt/util/color.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

// A direction to shadow-test from a shading point, and how far the light lies along it.
struct LightSample {
    Vec3 dir;  // unit, from the shading point towards the light
    double distance;
};

class Light {
  public:
    explicit Light(Color intensity, bool visible) : intensity_(intensity), visible_(visible) {}
    virtual ~Light() = default;

    // A direction towards the light from `x`, from a uniform point `u` of the unit square.
    // Light reaching x is intensity() * max(0, N·dir) * visibility, averaged over such samples:
    // that is the contract's I·(1/Ω)∫cap max(0, N·ω) V dω, estimated with pdf 1/Ω.
    virtual LightSample sample(const Vec3& x, Vec2 u) const = 0;
    // sample(x, u[i]) for every i, into out[i]: a light can work out what the samples of one
    // shading point share (for a sphere, the cone it subtends) only once. Same results.
    virtual void sample(const Vec3& x, std::span<const Vec2> u, std::span<LightSample> out) const;
    // For each u[i], lit_cosine of sample(x, u[i]).dir into out[i] (to rounding): what each
    // shadow ray of a shading point would bring if nothing blocked the light, without the
    // distances.
    virtual void lit_cosines(const Vec3& x, const Vec3& shading, const Vec3& geometric,
                             std::span<const Vec2> u, std::span<double> out) const;
    // A ball holding every point sample() aims at from outside it, so that what can block the
    // shadow rays of a shading point can be found once for all of them (Occluders, occluders.h).
    virtual Ball extent() const = 0;
    // A point light needs exactly one shadow ray; an area light's penumbra needs many.
    virtual bool is_point() const = 0;
    // Distance along `ray` at which it enters the light, for lights visible to rays.
    virtual std::optional<double> intersect(const Ray& ray, Interval range) const = 0;

    const Color& intensity() const { return intensity_; }
    bool visible() const { return visible_; }
    // What Cook shares shadow rays by.
    double power() const { return luminance(intensity_); }

  private:
    Color intensity_;
    bool visible_;
};

// The visible light `ray` enters first, nearer than `nearest` (the ray's hit), if any: what a
// camera or reflected ray sees of the thesis's lights, which are not in the BVH.
inline const Light* first_visible_light(std::span<const std::unique_ptr<Light>> lights,
                                        const Ray& ray, double nearest) {
    const Light* seen = nullptr;
    for (const auto& light : lights) {
        if (!light->visible()) continue;
        if (auto t = light->intersect(ray, {0, nearest})) nearest = *t, seen = light.get();
    }
    return seen;
}

class PointLight final : public Light {
  public:
    PointLight(Vec3 position, Color intensity) : Light(intensity, false), position_(position) {}
    using Light::sample;
    LightSample sample(const Vec3& x, Vec2 u) const override;
    Ball extent() const override { return {position_, 0}; }
    bool is_point() const override { return true; }
    std::optional<double> intersect(const Ray&, Interval) const override { return std::nullopt; }

  private:
    Vec3 position_;
};

class SphereLight final : public Light {
  public:
    SphereLight(Vec3 centre, double radius, Color intensity, bool visible)
        : Light(intensity, visible), centre_(centre), radius_(radius) {}
    // Uniform over the cone of directions the sphere subtends from x; from inside or on the
    // sphere, where that cone is ill-defined, uniform over all directions.
    LightSample sample(const Vec3& x, Vec2 u) const override;
    void sample(const Vec3& x, std::span<const Vec2> u, std::span<LightSample> out) const override;
    void lit_cosines(const Vec3& x, const Vec3& shading, const Vec3& geometric,
                     std::span<const Vec2> u, std::span<double> out) const override;
    Ball extent() const override { return {centre_, radius_}; }
    bool is_point() const override { return false; }
    std::optional<double> intersect(const Ray& ray, Interval range) const override;

    const Vec3& centre() const { return centre_; }
    double radius() const { return radius_; }

  private:
    Vec3 centre_;
    double radius_;
};

// The cosine between a direction towards a light and the shading normal, when the direction
// leaves above both the shading normal's horizon and the surface itself, and 0 otherwise: light
// from behind either adds nothing, and no shadow ray is cast for it.
inline double lit_cosine(const Vec3& dir, const Vec3& shading, const Vec3& geometric) {
    const double cosine = dot(shading, dir);
    return ((cosine > 0) & (dot(geometric, dir) > 0)) ? cosine : 0.0;
}

// A direction in the cone of half-angle acos(cos_max) about +z, uniformly distributed over it
// for u uniform over the square, as its coordinates x, y, cos θ, with sin²θ besides (a light's
// distance needs it). Inline and without a branch or a table look-up: one per shadow ray, in
// loops that vectorise.
struct ConeCoordinates {
    double x, y, cos_t, sin2_t;
};
inline ConeCoordinates cone_coordinates(Vec2 u, double cos_max) {
    // Uniform in solid angle means uniform in cos(theta) between cos_max and 1.
    const double cos_t = 1.0 - u.x * (1.0 - cos_max);
    const double sin2_t = positive_part(1.0 - cos_t * cos_t);
    const double sin_t = std::sqrt(sin2_t);
    const SinCos phi = sincos_turns(u.y);
    return {sin_t * phi.cos, sin_t * phi.sin, cos_t, sin2_t};
}

// The same direction as a vector.
inline Vec3 sample_cone(Vec2 u, double cos_max) {
    const ConeCoordinates c = cone_coordinates(u, cos_max);
    return {c.x, c.y, c.cos_t};
}

// 1 − cos of the half-angle of the cone a sphere subtends from a point d² away from its centre
// (outside it), without the cancellation of 1 − sqrt(1 − r²/d²) for a small, distant sphere.
inline double sphere_cone_one_minus_cos(double d2, double radius) {
    const double sin2 = radius * radius / d2;
    return sin2 / (1 + std::sqrt(positive_part(1 - sin2)));
}

}  // namespace drt
