// What both integrators and the photon maps do where a ray meets a surface: leave it without
// meeting it again, reflect and refract about a shading normal without crossing the geometric
// surface, perturb a direction for glossy parts, reach an emitter by a shadow ray, and read the
// surface with the footprint a camera ray has.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "drt/accel/bvh.h"
#include "drt/accel/occluders.h"
#include "drt/geometry/object.h"
#include "drt/render/pixel_integrator.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/camera.h"
#include "drt/scene/emitters.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

// Moves a ray origin off the surface it starts on, to the side `dir` leaves by, far enough that
// rounding in the hit point cannot make the ray hit that surface again. The distance scales with
// the point's magnitude (|p|·2⁻³² + 1e-9), a million times the double-precision rounding
// error of a re-projected hit point, and still invisible (2.3e-5 at 1e5 from the origin).
Ray spawn_ray(const Vec3& point, const Vec3& normal, const Vec3& dir, double time);

// The triangle a hit's shadow rays skip (bvh.h): its own, unless they leave from a smooth mesh's
// lifted point or along its shading normal, from where they may meet it.
inline Leaving shadow_leaving(const SurfaceHit& surface, const Hit& hit) {
    const bool from_facet =
        surface.light_point == surface.point && surface.light_normal == surface.normal;
    return from_facet ? Bvh::leaving(hit) : Leaving{};
}

// A shadow ray towards a point on an emitting surface (which the BVH holds) ends this fraction of
// the way there, so that rounding cannot make the emitter block its own light; and far enough
// short (about 100 float roundings) that a mesh's float filter rules the emitter's triangles
// out without the double-precision test.
inline constexpr double kShortOfEmitter = 1 - 1e-5;

// A next-event sample of emitter `emitter` that lights `point`: its sample, the cosine it arrives
// at, and whether the emitter is a point (a single direction, no density).
struct ReachingEmitter {
    EmitterSample sample;
    double cosine;
    bool point_light;
};
// Both integrators' shadow ray towards an emitter along its next-event sample (none: it cannot
// reach the point), from `origin` (spawned off the shading point), skipping the
// triangle `leaving`, stopped short of an emitting surface (kShortOfEmitter); nothing when the
// sample cannot light the point or is blocked, as `occluders` (gathered from `origin` for the
// emitter's extent, or everything) tell. Counts the ray if one is traced.
std::optional<ReachingEmitter> reach_emitter(const Emitters& emitters, const Bvh& bvh,
                                             const Occluders& occluders, std::size_t emitter,
                                             const std::optional<EmitterSample>& sample,
                                             const Vec3& origin, Leaving leaving,
                                             const Vec3& geometric, const Vec3& shading,
                                             double time, RayCounts& counts);
// What can block the shadow rays of one shading point to emitter i, gathered once for them
// when `rays` of them are worth it (occluders.h), else everything.
Occluders emitter_occluders(const Emitters& emitters, const Bvh& bvh, std::size_t emitter, int rays,
                            const Vec3& origin, double time);

// Hands `each` the next-event samples of a shading point's `rays` rays to `emitter` from
// `point`, in ray order: their unit-square points from the sampler's `dimension` as
// get_2d_for_ray draws them, and the samples drawn a chunk at a time, so that what a set shares
// (its key, a sphere's cone) is worked out once. The same numbers as drawn one by one.
template <class Each>
void for_each_emitter_sample(const Emitters& emitters, const Sampler& sampler, const PixelSample& s,
                             std::uint32_t dimension, std::size_t emitter, int rays,
                             const Vec3& point, double time, Each&& each) {
    constexpr int kChunk = 16;
    std::array<Vec2, kChunk> points;
    std::array<std::optional<EmitterSample>, kChunk> drawn;
    for (int first = 0; first < rays; first += kChunk) {
        const auto n = static_cast<std::size_t>(std::min(kChunk, rays - first));
        sampler.get_2d_for_rays(s, dimension, rays, first, std::span(points).first(n));
        emitters.sample(emitter, point, std::span<const Vec2>(points).first(n), time,
                        std::span(drawn).first(n));
        for (std::size_t j = 0; j < n; ++j) each(drawn[j]);
    }
}

// A direction about `ideal` whose angle from it is Rayleigh-distributed with scale sigma, i.e.
// a 2-D normal distribution of standard deviation sigma (radians) on the tangent plane.
Vec3 perturb_direction(const Vec3& ideal, double sigma, Vec2 u);

// The ideal mirror and refracted directions of `d` (arriving against `geometric`) about the
// shading normal, unless that would send the ray to the wrong side of the geometric surface —
// as a bump or a mesh's interpolated normals can at grazing angles, where a reflected ray would
// enter the object or a refracted one stay outside. Then the geometric normal decides, as for a
// flat surface. refract_below is empty under total internal reflection.
Vec3 reflect_above(const Vec3& d, const Vec3& shading, const Vec3& geometric);
std::optional<Vec3> refract_below(const Vec3& d, const Vec3& shading, const Vec3& geometric,
                                  double eta);

// The surface at a hit. A camera ray (depth 0) filters image textures over the footprint of one
// of its pixel's `samples` camera samples; deeper rays, whose spread the camera does not know,
// read the finest level.
SurfaceHit surface_of(const Ray& ray, const Hit& hit, int depth, const Camera& camera, int samples);

// Attempts at drawing a perturbed direction on the right side of a surface before falling back
// to the ideal one; at grazing incidence about half the draws land on the wrong side, so the
// fallback is taken with probability about 2^-32.
inline constexpr int kRedrawAttempts = 32;

// perturb_direction from `u`, redrawn from redraw(1), redraw(2), … until the direction leaves on
// the `side` (+1 or -1) of the surface of normal `geometric`; the ideal direction after
// kRedrawAttempts draws.
template <class Redraw>
Vec3 perturb_on_side(const Vec3& ideal, double sigma, double side, const Vec3& geometric, Vec2 u,
                     Redraw&& redraw) {
    for (int attempt = 1;; ++attempt) {
        const Vec3 dir = perturb_direction(ideal, sigma, u);
        if (side * dot(dir, geometric) > 0) return dir;
        if (attempt == kRedrawAttempts) return ideal;
        u = redraw(attempt);
    }
}

// Scattering events a path (or a photon's path) takes before Russian roulette may end it: the
// first bounces carry most of the light and are never cut short.
inline constexpr int kRouletteStart = 3;

}  // namespace drt
