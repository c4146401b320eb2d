#include "drt/scene/emitters.h"

#include <algorithm>
#include <cmath>

#include "drt/geometry/sphere.h"
#include "drt/sampling/cdf_pick.h"
#include "drt/sampling/spherical_triangle.h"
#include "drt/scene/light.h"

namespace drt {

namespace {

// A point this close to a sphere (relative to its radius squared) is on it: the cone it subtends
// is then the whole half-space, which uniform directions over the sphere of directions cover.
constexpr double kOnSphere = 1e-7;

bool inside_sphere(double d2, double radius) {
    return d2 <= radius * radius * (1 + kOnSphere);
}

double triangle_area(const std::array<Vec3, 3>& p) {
    return 0.5 * length(cross(p[1] - p[0], p[2] - p[0]));
}

// A triangle is sampled by the solid angle it subtends from a point closer to its plane than its
// longest edge is long: only there does area sampling's density in solid angle, d²/(area·cos),
// vary much over the triangle; farther off it varies by a small factor (d³ over the triangle
// from a point at height h ≥ every edge: about 1.5 below its middle) and area sampling is as
// good and half the cost. Solid-angle sampling also needs an angle between these bounds: below
// 1e-4 sr (a triangle about 0.6° across, or one seen edge-on) the angle at a corner and the
// arcs Arvo's mapping builds lose digits; within 0.1 sr of 2π the point is nearly on the
// triangle, the angles at its corners near π and their sines, by which the mapping divides,
// are lost to rounding. Elsewhere the triangle is sampled by area.
constexpr double kMinSolidAngle = 1e-4;
constexpr double kMaxSolidAngle = 2 * kPi - 0.1;

// The spherical triangle of t seen from the point at `offset` from the mesh's origin, if it is
// to be sampled by solid angle. sample and pdf both decide by this one function, so that the
// density a scattered ray is weighed with is the one the light sample would have had.
std::optional<SphericalTriangle> by_solid_angle(const Emitters::Emitter::Triangle& t,
                                                const Vec3& offset) {
    const double height = dot(t.corners[0] - offset, t.normal);
    if (!(height * height < t.longest_edge2)) return std::nullopt;
    const SphericalTriangle s =
        spherical_triangle(t.corners[0] - offset, t.corners[1] - offset, t.corners[2] - offset);
    // NaN (a corner at the point) fails both tests.
    if (s.area >= kMinSolidAngle && s.area <= kMaxSolidAngle) return s;
    return std::nullopt;
}

// The cone of directions a sphere of radius r subtends from a point outside it, at squared
// distance d2 from its centre along `to_centre`: what every sample from that point shares.
struct SphereCone {
    double d, d2, r, cos_max, pdf;
    Frame frame;  // n towards the centre

    SphereCone(const Vec3& to_centre, double d2_, double radius)
        : d(std::sqrt(d2_)),
          d2(d2_),
          r(radius),
          cos_max(std::sqrt(std::max(0.0, 1 - radius * radius / d2_))),
          pdf(1 / (2 * kPi * sphere_cone_one_minus_cos(d2_, radius))),
          frame(Frame::around(to_centre / d)) {}

    EmitterSample sample(Vec2 u, const Color& radiance) const {
        const ConeCoordinates c = cone_coordinates(u, cos_max);
        const Vec3 dir = normalize(frame.to_world({c.x, c.y, c.cos_t}));
        const double distance = d * c.cos_t - std::sqrt(positive_part(r * r - d2 * c.sin2_t));
        return EmitterSample{dir, distance, radiance, pdf};
    }
};

}  // namespace

Emitters::Emitters(const Scene& scene) {
    auto data = std::make_shared<Data>();
    for (const InverseSquareLight& light : scene.inverse_square_lights) {
        Emitter e;
        e.kind = Kind::kPoint;
        e.radiance = light.intensity;
        e.position = light.position;
        e.power = std::max(0.0, luminance(light.intensity));
        data->emitters.push_back(std::move(e));
    }
    for (const auto& object : scene.objects) {
        const Material& m = object->material();
        if (!m.emits()) continue;
        const Shapes shapes = object->shapes();
        for (const SphereShape& sphere : shapes.spheres) {
            Emitter e;
            e.kind = Kind::kSphere;
            e.radiance = m.emission;
            e.object = object.get();
            e.path = sphere.path;
            e.radius = sphere.radius;
            e.area = 4 * kPi * sphere.radius * sphere.radius;
            data->emitters.push_back(std::move(e));
        }
        for (const MeshShape& shape : shapes.meshes) {
            Emitter e;
            e.kind = Kind::kTriangles;
            e.radiance = m.emission;
            e.object = object.get();
            e.path = shape.path;
            e.mesh = shape.mesh;
            if (shape.part != MeshShape::kWhole) {
                e.index_of_triangle.assign(shape.mesh->triangle_count(), Emitter::kNotEmitting);
            }
            for (std::uint32_t t = 0; t < shape.mesh->triangle_count(); ++t) {
                if (shape.part != MeshShape::kWhole) {
                    if (shape.mesh->parts()[t] != shape.part) continue;
                    e.index_of_triangle[t] = static_cast<std::uint32_t>(e.triangles.size());
                }
                const auto corners = shape.mesh->corners(t);
                const double area = triangle_area(corners);
                e.area += area;
                e.area_cdf.push_back(e.area);
                double longest_edge2 = 0;
                for (int k = 0; k < 3; ++k) {
                    const Vec3 edge = corners[(k + 1) % 3] - corners[k];
                    longest_edge2 = std::max(longest_edge2, dot(edge, edge));
                }
                e.triangles.push_back(
                    {corners, shape.mesh->geometric_normal(t), area, longest_edge2});
            }
            if (!(e.area > 0)) continue;
            for (double& c : e.area_cdf) c /= e.area;
            e.area_cdf.back() = 1.0;
            for (Emitter::Triangle& t : e.triangles) t.pick /= e.area;
            data->emitters.push_back(std::move(e));
        }
    }
    for (std::size_t i = 0; i < data->emitters.size(); ++i) {
        Emitter& e = data->emitters[i];
        if (e.kind != Kind::kPoint) {
            e.power = std::max(0.0, luminance(e.radiance)) * e.area / (4 * kPi);
            data->by_object.emplace(e.object, i);
        }
    }
    if (scene.environment) {
        Emitter e;
        e.kind = Kind::kEnvironment;
        e.environment = scene.environment.get();
        e.power = std::max(0.0, scene.environment->power());
        data->emitters.push_back(std::move(e));
    }
    data_ = std::move(data);
}

std::optional<Ball> Emitters::extent(std::size_t i, double time) const {
    const Emitter& e = data_->emitters[i];
    switch (e.kind) {
        case Kind::kPoint:
            return Ball{e.position, 0};
        case Kind::kSphere:
            return Ball{e.path->at(time), e.radius};
        case Kind::kTriangles:
        case Kind::kEnvironment:
            return std::nullopt;
    }
    return std::nullopt;
}

std::optional<std::size_t> Emitters::index_of(const Object* object) const {
    const auto it = data_->by_object.find(object);
    if (it == data_->by_object.end()) return std::nullopt;
    return it->second;
}

std::optional<EmitterSample> Emitters::sample(std::size_t i, const Vec3& x, Vec2 u,
                                              double time) const {
    const Emitter& e = data_->emitters[i];
    switch (e.kind) {
        case Kind::kPoint: {
            const Vec3 v = e.position - x;
            const double d2 = dot(v, v);
            if (!(d2 > 0)) return std::nullopt;
            const double d = std::sqrt(d2);
            return EmitterSample{v / d, d, e.radiance / d2, 0};
        }
        case Kind::kSphere: {
            const Vec3 centre = e.path->at(time);
            const Vec3 to_centre = centre - x;
            const double d2 = dot(to_centre, to_centre);
            if (inside_sphere(d2, e.radius)) {
                const Vec3 dir = sample_cone(u, -1.0);
                const auto t = intersect_sphere(centre, e.radius, {x, dir, time}, {0, kInfinity});
                if (!t) return std::nullopt;
                return EmitterSample{dir, *t, e.radiance, 1 / (4 * kPi)};
            }
            return SphereCone(to_centre, d2, e.radius).sample(u, e.radiance);
        }
        case Kind::kTriangles: {
            const auto [k, pick, v] = pick_from_cdf(e.area_cdf, u.x);
            const Emitter::Triangle& t = e.triangles[k];
            const Vec3 origin = e.path->at(time);
            if (const auto spherical = by_solid_angle(t, x - origin)) {
                const Vec3 dir = sample_spherical_triangle(*spherical, {v, u.y});
                // Where dir meets the triangle's plane; dir lies within the triangle, which is
                // not seen edge-on (its solid angle would be below the bound).
                const double distance =
                    dot(t.corners[0] - (x - origin), t.normal) / dot(dir, t.normal);
                if (!(distance > 0)) return std::nullopt;
                return EmitterSample{dir, distance, e.radiance, t.pick / spherical->area};
            }
            const auto& p = t.corners;
            const double su = std::sqrt(v);
            const double b1 = (1 - su), b2 = u.y * su;
            const Vec3 point = origin + (p[0] * (1 - b1 - b2) + p[1] * b1 + p[2] * b2);
            const Vec3 to_point = point - x;
            const double d2 = dot(to_point, to_point);
            if (!(d2 > 0)) return std::nullopt;
            const double d = std::sqrt(d2);
            const Vec3 dir = to_point / d;
            const double cosine = std::abs(dot(t.normal, dir));
            if (!(cosine > 0)) return std::nullopt;
            return EmitterSample{dir, d, e.radiance, d2 / (e.area * cosine)};
        }
        case Kind::kEnvironment: {
            const auto s = e.environment->sample(u);
            if (!s) return std::nullopt;
            return EmitterSample{s->dir, kInfinity, s->radiance, s->pdf};
        }
    }
    return std::nullopt;
}

void Emitters::sample(std::size_t i, const Vec3& x, std::span<const Vec2> u, double time,
                      std::span<std::optional<EmitterSample>> out) const {
    const Emitter& e = data_->emitters[i];
    if (e.kind == Kind::kSphere) {
        const Vec3 to_centre = e.path->at(time) - x;
        const double d2 = dot(to_centre, to_centre);
        if (!inside_sphere(d2, e.radius)) {
            const SphereCone cone(to_centre, d2, e.radius);
            for (std::size_t k = 0; k < u.size(); ++k) out[k] = cone.sample(u[k], e.radiance);
            return;
        }
    }
    for (std::size_t k = 0; k < u.size(); ++k) out[k] = sample(i, x, u[k], time);
}

double Emitters::pdf(std::size_t i, const Vec3& x, const Vec3& point, const Vec3& normal,
                     std::uint32_t primitive, double time) const {
    const Emitter& e = data_->emitters[i];
    switch (e.kind) {
        case Kind::kPoint:
            return 0;
        case Kind::kSphere: {
            const Vec3 to_centre = e.path->at(time) - x;
            const double d2 = dot(to_centre, to_centre);
            if (inside_sphere(d2, e.radius)) return 1 / (4 * kPi);
            return 1 / (2 * kPi * sphere_cone_one_minus_cos(d2, e.radius));
        }
        case Kind::kTriangles: {
            if (!e.index_of_triangle.empty()) {
                if (primitive >= e.index_of_triangle.size()) return 0;
                primitive = e.index_of_triangle[primitive];
            }
            if (primitive >= e.triangles.size()) return 0;
            const Emitter::Triangle& t = e.triangles[primitive];
            if (const auto spherical = by_solid_angle(t, x - e.path->at(time))) {
                return t.pick / spherical->area;
            }
            // Picked by area and sampled by area: the density of a point on the whole mesh.
            const Vec3 to_point = point - x;
            const double d2 = dot(to_point, to_point);
            const double cosine = std::abs(dot(normal, to_point)) / std::sqrt(d2);
            return cosine > 0 ? d2 / (e.area * cosine) : 0;
        }
        case Kind::kEnvironment:
            return e.environment->pdf(normalize(point - x));
    }
    return 0;
}

}  // namespace drt
