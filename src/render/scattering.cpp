#include "drt/render/scattering.h"

#include <algorithm>
#include <cmath>

#include "drt/scene/light.h"

namespace drt {

// A camera ray's footprint is 1/√samples of a pixel across, as pbrt-v4 scales its
// differentials, but at least an eighth.
SurfaceHit surface_of(const Ray& ray, const Hit& hit, int depth, const Camera& camera,
                      int samples) {
    if (depth > 0 || !hit.object->reads_uv()) return hit.object->surface_at(ray, hit);
    const double step = std::max(0.125, 1 / std::sqrt(std::max(samples, 1)));
    const RayDifferential differential = camera.differential(ray, step);
    return hit.object->surface_at(ray, hit, &differential);
}

Vec3 reflect_above(const Vec3& d, const Vec3& shading, const Vec3& geometric) {
    const Vec3 r = reflect(d, shading);
    return dot(r, geometric) > 0 ? r : reflect(d, geometric);
}

std::optional<Vec3> refract_below(const Vec3& d, const Vec3& shading, const Vec3& geometric,
                                  double eta) {
    const auto through = refract(d, shading, eta);
    if (through && dot(*through, geometric) < 0) return through;
    return refract(d, geometric, eta);
}

Ray spawn_ray(const Vec3& point, const Vec3& normal, const Vec3& dir, double time) {
    const double offset = max_abs_component(point) * 0x1.0p-32 + 1e-9;
    const Vec3 towards = dot(dir, normal) >= 0 ? normal : -normal;
    return {point + towards * offset, dir, time};
}

Vec3 perturb_direction(const Vec3& ideal, double sigma, Vec2 u) {
    // Box-Muller radius: the length of a 2-D normal vector with per-axis deviation sigma.
    const double theta = sigma * std::sqrt(-2.0 * std::log1p(-u.x));
    const SinCos phi = sincos_turns(u.y);
    const double sin_t = std::sin(theta);
    const Vec3 local{sin_t * phi.cos, sin_t * phi.sin, std::cos(theta)};
    return normalize(Frame::around(ideal).to_world(local));
}

std::optional<ReachingEmitter> reach_emitter(const Emitters& emitters, const Bvh& bvh,
                                             const Occluders& occluders, std::size_t emitter,
                                             const std::optional<EmitterSample>& sample,
                                             const Vec3& origin, Leaving leaving,
                                             const Vec3& geometric, const Vec3& shading,
                                             double time, RayCounts& counts) {
    if (!sample) return std::nullopt;
    const double cosine = lit_cosine(sample->dir, shading, geometric);
    if (cosine == 0) return std::nullopt;
    ++counts.shadow;
    const bool point_light = emitters.is_point(emitter);
    // An emitting surface is in the BVH: the ray stops just short of it.
    const double reach = point_light ? sample->distance : sample->distance * kShortOfEmitter;
    if (occluders.occluded(bvh, {origin, sample->dir, time}, {0, reach}, leaving)) {
        return std::nullopt;
    }
    return ReachingEmitter{*sample, cosine, point_light};
}

Occluders emitter_occluders(const Emitters& emitters, const Bvh& bvh, std::size_t emitter, int rays,
                            const Vec3& origin, double time) {
    if (!worth_culling(rays, bvh)) return {};
    const auto extent = emitters.extent(emitter, time);
    if (!extent) return {};
    // A sphere's samples lie on the part of it seen from the point (or, from inside, where a
    // ray leaves it), and the rays stop short of them: the sphere cannot block its own light.
    const Emitters::Emitter& e = emitters[emitter];
    const Object* sphere = e.kind == Emitters::Kind::kSphere ? e.object : nullptr;
    return Occluders(bvh, origin, *extent, time, sphere);
}

}  // namespace drt
