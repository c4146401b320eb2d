#include "drt/light.h"

#include <array>
#include <cmath>

#include "drt/sphere.h"

namespace drt {

LightSample PointLight::sample(const Vec3& x, Vec2) const {
    const Vec3 d = position_ - x;
    const double dist = length(d);
    return {d / dist, dist};
}

namespace {

// The cone of directions a sphere subtends from a point outside it: what every sample from that
// point shares.
struct Cone {
    double d, d2, r2;  // distance to the centre, its square, the radius squared
    double cos_max;
    Vec3 axis;  // towards the centre
    // The frame's tangents about the axis turned by 0, 1, 2, 3 quarter turns: sample_cone's
    // azimuth is turned by whole quarters here, so that only a fraction of one needs a sine.
    std::array<Vec3, 4> along, across;

    Cone(const Vec3& x, const Vec3& centre, double radius, double d2_)
        : d(std::sqrt(d2_)), d2(d2_), r2(radius * radius) {
        const double sin2_max = r2 / d2;
        cos_max = std::sqrt(std::max(0.0, 1.0 - sin2_max));
        const Frame frame = Frame::around((centre - x) / d);
        axis = frame.n;
        along = {frame.t, frame.b, -frame.t, -frame.b};
        across = {frame.b, -frame.t, -frame.b, frame.t};
    }

    // sample_cone(u, cos_max) in the frame, and the distance to the sphere along it.
    LightSample sample(Vec2 u) const {
        const double cos_t = 1.0 - u.x * (1.0 - cos_max);
        const double sin2_t = std::max(0.0, 1.0 - cos_t * cos_t);
        const double sin_t = std::sqrt(sin2_t);
        // Distance to the near side of the sphere along the direction: b - sqrt(r² - (d² - b²))
        // with b = d cos θ, the distance to the point nearest the centre. It depends on θ alone,
        // so its square root need not wait for the azimuth. At the cone's rim the ray grazes
        // the sphere and rounding may miss, where b itself is exact enough.
        const double dist = d * cos_t - std::sqrt(std::max(0.0, r2 - d2 * sin2_t));
        const auto [q, a] = quarter_turns(u.y);
        const SinCos phi = sincos_eighth(a);
        const auto k = static_cast<std::size_t>(q & 3);
        const Vec3 dir =
            along[k] * (sin_t * phi.cos) + across[k] * (sin_t * phi.sin) + axis * cos_t;
        return {dir, dist};
    }
};

}  // namespace

void Light::sample(const Vec3& x, std::span<const Vec2> u, std::span<LightSample> out) const {
    for (std::size_t i = 0; i < u.size(); ++i) out[i] = sample(x, u[i]);
}

LightSample SphereLight::sample(const Vec3& x, Vec2 u) const {
    const Vec3 to_centre = centre_ - x;
    const double d2 = dot(to_centre, to_centre);
    if (d2 <= radius_ * radius_) {
        const Vec3 dir = sample_cone(u, -1.0);
        const Ray ray{x, dir, 0};
        // From inside, the ray leaves through the far root; on the surface it may meet nothing.
        const auto t = intersect_sphere(centre_, radius_, ray, {0, kInfinity});
        return {dir, t.value_or(0.0)};
    }
    return Cone(x, centre_, radius_, d2).sample(u);
}

void SphereLight::sample(const Vec3& x, std::span<const Vec2> u, std::span<LightSample> out) const {
    const Vec3 to_centre = centre_ - x;
    const double d2 = dot(to_centre, to_centre);
    if (d2 <= radius_ * radius_) {
        Light::sample(x, u, out);
        return;
    }
    const Cone cone(x, centre_, radius_, d2);
    for (std::size_t i = 0; i < u.size(); ++i) out[i] = cone.sample(u[i]);
}

std::optional<double> SphereLight::intersect(const Ray& ray, Interval range) const {
    return intersect_sphere(centre_, radius_, ray, range);
}

}  // namespace drt
