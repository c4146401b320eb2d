// What a render asks of an integrator: the radiance of a pixel's camera samples. Two integrators
// answer it: the thesis's distributed ray tracer (integrator.h) and the path tracer
// (path_integrator.h); the scene's Render Integrator chooses.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/render/photon_map.h"
#include "drt/render/render_plan.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/camera.h"
#include "drt/scene/scene.h"
#include "drt/util/color.h"

namespace drt {

// Rays actually traced, by kind.
struct RayCounts {
    std::uint64_t camera = 0, shadow = 0, reflection = 0, refraction = 0;
    std::uint64_t diffuse = 0;  // scattered by diffuse events (the path integrator's)

    std::uint64_t total() const { return camera + shadow + reflection + refraction + diffuse; }
    RayCounts& operator+=(const RayCounts& o) {
        camera += o.camera, shadow += o.shadow, reflection += o.reflection,
            refraction += o.refraction, diffuse += o.diffuse;
        return *this;
    }
};

// The camera rays of samples s.index, s.index + 1, ... of pixel (x, y), as both integrators trace
// them: the film and lens points drawn as one run (so that a stratified or Sobol pattern spreads
// a run over the pixel and the lens together), the pixel's centre without antialiasing, the
// lens's centre without depth of field, and a time only with motion blur.
class CameraRays {
  public:
    CameraRays(const Camera& camera, const Sampler& sampler, const RenderPlan& plan, int x, int y,
               const PixelSample& s, std::size_t count);
    // The ray of the run's i-th sample, `sample` (s with index s.index + i).
    Ray at(std::size_t i, const PixelSample& sample) const;

  private:
    const Camera& camera_;
    const Sampler& sampler_;
    const RenderPlan& plan_;
    std::vector<Vec2> film_, lens_;
};

class PixelIntegrator {
  public:
    virtual ~PixelIntegrator() = default;
    // Camera samples s.index, s.index + 1, ... of pixel (x, y): the radiance along each camera
    // ray, into out. Safe to call from several threads at once.
    virtual void sample_pixel(int x, int y, const PixelSample& s, std::span<Color> out,
                              RayCounts& counts) const = 0;
};

// The integrator scene.settings.integrator names, reading the plan, BVH, sampler and photon maps
// (null: no caustics) it is given, which must outlive it.
std::unique_ptr<PixelIntegrator> make_integrator(const Scene& scene, const RenderPlan& plan,
                                                 const Bvh& bvh, const Sampler& sampler,
                                                 const PhotonMaps* photons = nullptr);

}  // namespace drt
