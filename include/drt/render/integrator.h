// The recursive tracer: the thesis's shading (Lambert direct light, mirror and Fresnel glass),
// with every integral Cook distributes — pixel area, lens, time, light area, glossy
// directions — sampled only where the render plan says the scene calls for it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/accel/occluders.h"
#include "drt/render/photon_map.h"
#include "drt/render/pixel_integrator.h"
#include "drt/render/render_plan.h"
#include "drt/render/scattering.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/camera.h"
#include "drt/scene/emitters.h"
#include "drt/scene/scene.h"

namespace drt {

// A camera sample's ray tree is traced whole up to this many reflected and refracted rays. Past
// them a new hit follows one of its rays, picked in proportion to its weight, and every ray
// survives Russian roulette by its throughput (both divided by their odds: unbiased). Glass
// between mirrors doubles the tree at each bounce, 2^MaxDepth rays a sample, which no render
// could trace at MaxDepth 512; the trees of the repository's scenes stay below the bound, so
// none of them reaches the roulette.
inline constexpr std::uint64_t kWholeTreeRays = 4096;

class Integrator final : public PixelIntegrator {
  public:
    // With `photons`, diffuse parts add the caustic light the photon maps estimate.
    // `whole_tree_rays`: the bound above (tests set others).
    Integrator(const Scene& scene, const RenderPlan& plan, const Bvh& bvh, const Sampler& sampler,
               const PhotonMaps* photons = nullptr, std::uint64_t whole_tree_rays = kWholeTreeRays);

    // Camera samples s.index, s.index + 1, ... of pixel (x, y): the radiance along each camera
    // ray, into out. A run of a pixel's samples shares the work of drawing their camera points.
    void sample_pixel(int x, int y, const PixelSample& s, std::span<Color> out,
                      RayCounts& counts) const override;

    // Radiance arriving along `ray`, which is `depth` reflections/refractions from the camera.
    Color radiance(const Ray& ray, const PixelSample& s, int depth, RayCounts& counts) const;

  private:
    // What the paths of one run of a pixel's samples share.
    struct PixelWork {
        RayCounts& counts;
        RunPoints points;             // of the glossy dimensions
        std::uint64_t tree_rays = 0;  // reflected and refracted rays of the current camera sample
    };

    // `leaving`: the triangle the ray leaves from, which it skips (bvh.h); `throughput`: the
    // largest channel of the product of the weights from the camera to this ray, which only a
    // tree past kWholeTreeRays reads.
    Color radiance(const Ray& ray, const PixelSample& s, int depth, PixelWork& work,
                   Leaving leaving = {}, double throughput = 1) const;
    // Σ lights at a point: I · max(0, N·ω) · visibility, averaged over each light's shadow rays,
    // and the emitters' and emitting planes' light in the same units; every ray skips the
    // triangle `leaving`.
    Color direct_light(const Vec3& point, const Vec3& geometric, const Vec3& shading,
                       Leaving leaving, double time, const PixelSample& s, int depth,
                       RayCounts& counts) const;
    // The light of the emitting planes at a point, from ShadowRays rays leaving `origin` in
    // cosine-weighted directions (an infinite plane has no area to sample), in the units of
    // direct_light.
    Color plane_light(const Vec3& origin, Leaving leaving, const Vec3& geometric,
                      const Vec3& shading, double time, const PixelSample& s, int depth,
                      RayCounts& counts) const;
    // One shadow ray from `origin` (spawned off the shading point) along a light sample.
    Color light_ray(const Light& light, const LightSample& ls, const Vec3& origin, Leaving leaving,
                    const Vec3& geometric, const Vec3& shading, double time,
                    const Occluders& occluders, RayCounts& counts) const;
    // One shadow ray towards emitter `emitter` (emitters.h) along its sample `drawn`, tested
    // against `occluders`, in the units of direct_light.
    Color emitter_ray(std::size_t emitter, const std::optional<EmitterSample>& drawn,
                      const Vec3& origin, Leaving leaving, const Vec3& geometric,
                      const Vec3& shading, double time, const Occluders& occluders,
                      RayCounts& counts) const;
    // A hit's point and its normals facing the ray that arrived (facing_normals).
    struct Facing {
        Vec3 point, geometric, shading;
    };
    // A reflected or refracted ray to trace from a hit: its ideal direction, perturbed by `sigma`
    // (0: exactly ideal) and redrawn until it leaves on the `side` of the surface (+1: the
    // normal's), and its sampler dimension's `kind`.
    struct Scatter {
        Vec3 ideal;
        double sigma;
        double side;
        std::uint32_t kind;
        bool refraction;
    };
    // The reflected and refracted rays material m calls for at a hit that `dir` arrived at
    // (from outside the surface or not), as the whole tree traces them, and the Fresnel factor
    // that weighs the glass's two.
    struct Scatterings {
        std::optional<Scatter> mirror, glass_reflection, refraction;
        double fresnel = 0;
    };
    Scatterings scatterings(const Vec3& dir, const Material& m, const Facing& at,
                            bool outside) const;
    // The reflected and refracted light of material m at a hit along one of `rays`, picked in
    // proportion to its weight (past kWholeTreeRays); `leaving`: the hit's triangle.
    Color one_branch(const Scatterings& rays, const Material& m, double time, const PixelSample& s,
                     int depth, PixelWork& work, const Facing& at, Leaving leaving,
                     double throughput) const;
    // Average radiance along the scattered rays of `how` (GlossyRays of them for a perturbed
    // direction at the first hit, else one), skipping the triangle `leaving`.
    Color scattered(const Facing& at, Leaving leaving, const Scatter& how, double throughput,
                    double time, const PixelSample& s, int depth, PixelWork& work) const;

    const Scene& scene_;
    const RenderPlan& plan_;
    const Bvh& bvh_;
    const Sampler& sampler_;
    const PhotonMaps* photons_;
    Camera camera_;
    std::vector<const Light*> area_lights_;  // in scene order, as plan_.light_pick_cdf
    bool any_visible_light_ = false;
    std::vector<const Object*> emitting_planes_;  // objects with an emitting plane
    std::uint64_t whole_tree_rays_;
};

}  // namespace drt
