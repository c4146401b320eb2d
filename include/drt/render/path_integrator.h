// Unbiased path tracing (Kajiya 1986) of the thesis's material: its diffuse part is the Lambertian
// BRDF diffuse·kd/π, which scatters light in every direction; its reflective and transparent
// parts scatter exactly as in the distributed integrator (ideal, or glossy about the ideal
// direction with σ = 1/n; Fresnel; total internal reflection). One scattered ray per event, the
// part that scatters it picked in proportion to its weight. At each diffuse event, next-event
// estimation sends ShadowRays shadow rays to the lights and emitters (shared by power as in the
// distributed integrator); light from an emitter is found both by them and by the scattered ray,
// and the two estimates are weighed by Veach's power heuristic, so nothing is counted twice.
// Background, or the environment when there is one, is the radiance of every escaping ray; the
// environment is also an emitter, weighed the same way. Ambient is not used. Paths end after
// MaxDepth scattering events, or earlier by Russian roulette, whose survivors carry 1/(survival
// probability) more so that the mean stays exact.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "drt/render/photon_map.h"
#include "drt/render/pixel_integrator.h"
#include "drt/scene/camera.h"

namespace drt {

class Occluders;

class PathIntegrator final : public PixelIntegrator {
  public:
    // How light from emitters reaching a diffuse surface is found: by both next-event estimation
    // and the scattered ray, weighed (the renderer's), or by one alone. Every strategy has the
    // same mean: tests compare them.
    enum class Strategy { kMis, kLightOnly, kScatterOnly };

    // With `photons`, each diffuse event adds the caustic light the photon maps estimate, and an
    // emitter that photons are traced from, reached after a diffuse event and only reflective
    // or transparent events since, adds nothing: that light is the photons'.
    PathIntegrator(const Scene& scene, const RenderPlan& plan, const Bvh& bvh,
                   const Sampler& sampler, Strategy strategy = Strategy::kMis,
                   const PhotonMaps* photons = nullptr);

    void sample_pixel(int x, int y, const PixelSample& s, std::span<Color> out,
                      RayCounts& counts) const override;

    // Radiance arriving along a camera ray, for camera sample s.
    Color radiance(const Ray& camera_ray, const PixelSample& s, RayCounts& counts) const;

  private:
    // Light from the lights and emitters reaching `point` (the shading point shadow rays leave
    // from) by one shadow ray each, in the units of the thesis's sum of lights (irradiance over
    // π), emitters' weighed against a diffuse scattered ray chosen with probability
    // `diffuse_pick`. Shadow rays skip the triangle `leaving` (bvh.h).
    Color next_event(const Vec3& point, const Vec3& geometric, const Vec3& shading, Leaving leaving,
                     double time, const PixelSample& s, int depth, double diffuse_pick,
                     RayCounts& counts) const;
    Color light_ray(const Light& light, const LightSample& ls, const Vec3& origin, Leaving leaving,
                    const Vec3& geometric, const Vec3& shading, double time,
                    const Occluders& occluders, RayCounts& counts) const;
    Color emitter_ray(std::size_t emitter, const std::optional<EmitterSample>& drawn,
                      const Vec3& origin, Leaving leaving, const Vec3& geometric,
                      const Vec3& shading, double time, double diffuse_pick,
                      const Occluders& occluders, RayCounts& counts) const;
    // A direction about `ideal` with angular spread sigma (exactly `ideal` for 0) leaving on the
    // `side` of the surface (+1: the normal's), redrawn as the distributed integrator does.
    Vec3 perturbed(const Vec3& ideal, double sigma, double side, const Vec3& geometric,
                   const PixelSample& s, std::uint32_t dimension) const;

    const Scene& scene_;
    const RenderPlan& plan_;
    const Bvh& bvh_;
    const Sampler& sampler_;
    Strategy strategy_;
    const PhotonMaps* photons_;
    Camera camera_;
    std::vector<const Light*> area_lights_;  // in scene order, as plan_.light_pick_cdf
    // For each emitter, the expected number of its shadow rays per diffuse event: what the
    // density of its light samples is multiplied by when weighed against the scattered ray.
    std::vector<double> expected_emitter_rays_;
    bool any_visible_light_ = false;
};

}  // namespace drt
