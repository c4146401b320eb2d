// Arbitrary output variables (`--aov`): what a pixel's camera rays first meet — the surface's
// albedo (diffuse·kd, texture applied), its shading normal facing the camera, and the distance
// to it — averaged over the pixel's camera samples, for compositing and external denoisers. They
// are found by tracing the same camera rays as the integrators, apart from them, so a render
// without AOVs runs exactly the code and gives exactly the bits it did before.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/render/render_plan.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/camera.h"
#include "drt/scene/scene.h"

namespace drt {

enum class Aov { kAlbedo, kNormal, kDepth };

// "albedo,normal,depth" (any order, each at most once) as a list; throws std::invalid_argument
// naming an unknown or repeated entry, or an empty list.
std::vector<Aov> parse_aovs(std::string_view list);

// The channels `aovs` add to an image, in order: albedo.R/G/B, normal.X/Y/Z, depth.Z.
std::vector<std::string> aov_channel_names(std::span<const Aov> aovs);
std::size_t aov_channel_count(std::span<const Aov> aovs);

class AovTracer {
  public:
    // Reads the plan (which camera dimensions are sampled), BVH and sampler it is given, which
    // must outlive it.
    AovTracer(const Scene& scene, const RenderPlan& plan, const Bvh& bvh, const Sampler& sampler);

    // The mean of `aovs` over camera samples s.index … s.index + s.count − 1 of pixel (x, y),
    // the camera rays the integrators trace for them: aov_channel_count(aovs) values into out.
    // A ray that meets nothing, or a visible light first, counts 0.
    void pixel_mean(int x, int y, const PixelSample& s, std::span<const Aov> aovs,
                    std::span<float> out) const;

  private:
    const Scene& scene_;
    const RenderPlan& plan_;
    const Bvh& bvh_;
    const Sampler& sampler_;
    Camera camera_;
    bool any_visible_light_ = false;
};

}  // namespace drt
