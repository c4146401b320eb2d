#include "drt/scene/light.h"

#include <cmath>

#include "drt/geometry/sphere.h"

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
    Frame frame;  // n towards the centre

    Cone(const Vec3& x, const Vec3& centre, double radius, double d2_)
        : d(std::sqrt(d2_)),
          d2(d2_),
          r2(radius * radius),
          cos_max(std::sqrt(std::max(0.0, 1.0 - r2 / d2))),
          frame(Frame::around((centre - x) / d)) {}

    // A sample's direction is t x + b y + n cos θ in the cone's frame.
    ConeCoordinates coordinates(Vec2 u) const { return cone_coordinates(u, cos_max); }

    Vec3 direction(const ConeCoordinates& c) const {
        const Vec3& t = frame.t;
        const Vec3& b = frame.b;
        const Vec3& n = frame.n;
        return {t.x * c.x + b.x * c.y + n.x * c.cos_t, t.y * c.x + b.y * c.y + n.y * c.cos_t,
                t.z * c.x + b.z * c.y + n.z * c.cos_t};
    }

    // Distance to the near side of the sphere along the direction: b - sqrt(r² - (d² - b²))
    // with b = d cos θ, the distance to the point nearest the centre. It depends on θ alone, so
    // its square root need not wait for the azimuth. At the cone's rim the ray grazes the
    // sphere and rounding may miss, where b itself is exact enough.
    double distance(const ConeCoordinates& c) const {
        return d * c.cos_t - std::sqrt(positive_part(r2 - d2 * c.sin2_t));
    }

    LightSample sample(Vec2 u) const {
        const ConeCoordinates c = coordinates(u);
        return {direction(c), distance(c)};
    }
};

// Cone::sample for every point. Vectorised, it does the same IEEE operations (no fused
// multiply-adds) several lanes at a time, so its results are bit-identical to the scalar
// sample's (tests/scene/light_test.cpp checks) and images do not depend on the machine.
DRT_VECTORISED void sample_cone_batch(const Cone& cone, const Vec2* u, LightSample* out,
                                      std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) out[i] = cone.sample(u[i]);
}

// lit_cosine for every point. The cosine with a normal N is N·t x + N·b y + N·n cos θ: three
// products per normal, where building the direction first would take nine more. (So the last
// bits may differ from those of lit_cosine(sample(...).dir, ...).)
DRT_VECTORISED void lit_cosine_batch(const Cone& cone, const Vec3& shading, const Vec3& geometric,
                                     const Vec2* u, double* out, std::size_t count) {
    const Frame& f = cone.frame;
    const Vec3 s{dot(shading, f.t), dot(shading, f.b), dot(shading, f.n)};
    const Vec3 g{dot(geometric, f.t), dot(geometric, f.b), dot(geometric, f.n)};
    for (std::size_t i = 0; i < count; ++i) {
        const ConeCoordinates c = cone.coordinates(u[i]);
        const double cosine = s.x * c.x + s.y * c.y + s.z * c.cos_t;
        out[i] = ((cosine > 0) & (g.x * c.x + g.y * c.y + g.z * c.cos_t > 0)) ? cosine : 0.0;
    }
}

}  // namespace

void Light::sample(const Vec3& x, std::span<const Vec2> u, std::span<LightSample> out) const {
    for (std::size_t i = 0; i < u.size(); ++i) out[i] = sample(x, u[i]);
}

void Light::lit_cosines(const Vec3& x, const Vec3& shading, const Vec3& geometric,
                        std::span<const Vec2> u, std::span<double> out) const {
    for (std::size_t i = 0; i < u.size(); ++i)
        out[i] = lit_cosine(sample(x, u[i]).dir, shading, geometric);
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
    sample_cone_batch(Cone(x, centre_, radius_, d2), u.data(), out.data(), u.size());
}

std::optional<double> SphereLight::intersect(const Ray& ray, Interval range) const {
    return intersect_sphere(centre_, radius_, ray, range);
}

void SphereLight::lit_cosines(const Vec3& x, const Vec3& shading, const Vec3& geometric,
                              std::span<const Vec2> u, std::span<double> out) const {
    const Vec3 to_centre = centre_ - x;
    const double d2 = dot(to_centre, to_centre);
    if (d2 <= radius_ * radius_) {
        Light::lit_cosines(x, shading, geometric, u, out);
        return;
    }
    lit_cosine_batch(Cone(x, centre_, radius_, d2), shading, geometric, u.data(), out.data(),
                     u.size());
}

}  // namespace drt
