// The lights that are physical: emitting surfaces (a material's ker keg keb on a sphere or a
// triangle mesh) and Falloff-1 point lights, as next-event estimation samples them. Spheres are
// sampled by the solid angle they subtend; a mesh's triangle is picked by area (one emitted
// radiance per mesh, so area is its power distribution) and then sampled by the solid angle it
// subtends (sampling/spherical_triangle.h) from points near it, by area from farther off or
// where that angle is too small or too close to a hemisphere to be sampled soundly (the rule is
// in emitters.cpp); a Falloff-1 point light is a point.
// Emitting planes are infinite: they are seen by rays and found by rays in cosine-weighted
// directions (scattered ones, or the distributed integrator's plane_light), not here. The
// scene's environment, if any, is the last emitter, sampled by its own distribution
// (environment.h) at an infinite distance.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "drt/accel/mesh.h"
#include "drt/geometry/motion.h"
#include "drt/scene/scene.h"

namespace drt {

// A direction from a shading point towards an emitter and what arrives along it.
struct EmitterSample {
    Vec3 dir;         // unit
    double distance;  // to the emitter along dir
    Color radiance;   // emitted radiance; for a point, its intensity over distance squared
    double pdf;       // of dir, per unit solid angle; 0 for a point (a single direction)
};

class Emitters {
  public:
    enum class Kind { kPoint, kSphere, kTriangles, kEnvironment };
    struct Emitter {
        Kind kind = Kind::kPoint;
        Color radiance;                    // a surface's radiance; a point's intensity I
        const Object* object = nullptr;    // the emitting object; null for a point
        Vec3 position;                     // a point's
        const MotionPath* path = nullptr;  // a sphere's centre, a mesh's origin, over time
        double radius = 0;                 // a sphere's
        const TriangleMesh* mesh = nullptr;
        std::vector<double> area_cdf;  // a mesh's triangles by area, the last exactly 1
        // A mesh's triangles as sampling needs them, worked out once rather than per ray.
        struct Triangle {
            std::array<Vec3, 3> corners;  // in the mesh's own coordinates, as the mesh has them
            Vec3 normal;                  // TriangleMesh::geometric_normal
            double pick = 0;              // its probability: its share of the mesh's area
            double longest_edge2 = 0;     // the square of its longest edge's length
        };
        std::vector<Triangle> triangles;
        // For one part of a shared mesh (MeshShape::part): each mesh triangle's index into
        // `triangles`, kNotEmitting for another part's; empty when `triangles` is the whole mesh.
        std::vector<std::uint32_t> index_of_triangle;
        static constexpr std::uint32_t kNotEmitting = ~std::uint32_t{0};
        double area = 0;  // a sphere's or mesh's whole surface
        const Environment* environment = nullptr;
        // What next-event estimation shares shadow rays by, in the units of a thesis light's
        // luminance(I): luminance(I) for a point, luminance(radiance)·area/(4π) for a surface
        // (so a Falloff-1 sphere light of intensity I has the power of a point light of I);
        // Environment::power for the environment.
        double power = 0;
    };

    // Every Falloff-1 point light, in scene order, then every emitting sphere and mesh (not
    // plane), in object order, then the environment.
    Emitters() = default;
    explicit Emitters(const Scene& scene);

    std::size_t size() const { return data_->emitters.size(); }
    const Emitter& operator[](std::size_t i) const { return data_->emitters[i]; }
    bool is_point(std::size_t i) const { return data_->emitters[i].kind == Kind::kPoint; }

    // A direction towards emitter i from x at `time`, from a uniform point u of the unit square;
    // nothing when the sample cannot reach x (an edge-on triangle).
    std::optional<EmitterSample> sample(std::size_t i, const Vec3& x, Vec2 u, double time) const;
    // sample(i, x, u[k], time) for every k, into out[k]: what the samples share (a sphere's
    // cone) is worked out once.
    void sample(std::size_t i, const Vec3& x, std::span<const Vec2> u, double time,
                std::span<std::optional<EmitterSample>> out) const;
    // The density per unit solid angle with which sample(i, x, ·, time) picks the direction
    // from x to `point` on the emitter, whose geometric normal there is `normal`, on its
    // primitive `primitive` (a mesh's triangle: Hit::primitive).
    double pdf(std::size_t i, const Vec3& x, const Vec3& point, const Vec3& normal,
               std::uint32_t primitive, double time) const;
    // A ball holding every point sample(i, ·, ·, time) aims at (a point light's position alone),
    // so that what can block shadow rays to it can be gathered once (occluders.h). None for the
    // environment, at infinity, nor for a mesh: its triangles are one mesh with the scene's
    // other <Triangle>s, which a gathering would always find.
    std::optional<Ball> extent(std::size_t i, double time) const;
    // Which emitter an object is, if it is sampled as one.
    std::optional<std::size_t> index_of(const Object* object) const;
    // Which emitter the environment is, if there is one.
    std::optional<std::size_t> environment_index() const {
        const std::vector<Emitter>& all = data_->emitters;
        if (all.empty() || all.back().kind != Kind::kEnvironment) return std::nullopt;
        return all.size() - 1;
    }

  private:
    struct Data {
        std::vector<Emitter> emitters;
        std::unordered_map<const Object*, std::size_t> by_object;
    };
    // Shared by copies: a render's two plans (render_context.h) hold the same emitters, whose
    // data for an emitting mesh is over a hundred bytes a triangle.
    std::shared_ptr<const Data> data_ = std::make_shared<const Data>();
};

}  // namespace drt
