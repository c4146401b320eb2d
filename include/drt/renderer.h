// Renders a scene into an image: tiles handed out to worker threads, each pixel a pure function
// of the scene, the options and the seed, so the image never depends on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "drt/image.h"
#include "drt/integrator.h"
#include "drt/render_plan.h"
#include "drt/scene.h"

namespace drt {

// Adaptive sampling: each pixel takes samples in rounds, each round as many as it has so far,
// and stops once the estimated standard error of its mean luminance falls below the threshold,
// or at the scene's sample count. The estimate is the sample deviation over sqrt(n), or for a
// progressive sampler the spread of the means of 8 consecutive runs over sqrt(8), which credits
// stratification. The decision reads only the pixel's own samples, so the image stays
// independent of the thread count.
struct AdaptiveSampling {
    double noise_threshold = 0;  // in linear luminance units
    int min_samples = 16;        // taken before the estimate is trusted; capped at the maximum
};

struct RenderOptions {
    int threads = 0;  // 0 = all cores
    // Called now and then from the rendering thread with the fraction done (0..1).
    std::function<void(double)> on_progress;
    std::optional<AdaptiveSampling> adaptive;  // absent: every pixel takes the scene's samples
};

struct RenderStats {
    double seconds = 0;
    int threads = 1;
    RayCounts rays;
    std::uint64_t samples = 0;           // camera samples taken over all pixels
    std::uint64_t pixels_converged = 0;  // adaptive: pixels that stopped before the maximum
    // Adaptive sampling as applied, the minimum capped at the maximum; absent for a plain render.
    std::optional<AdaptiveSampling> adaptive;
};

struct RenderResult {
    Image image;
    RenderPlan plan;
    RenderStats stats;
    // Adaptive sampling only: the camera samples each pixel took, row by row.
    std::vector<std::uint32_t> pixel_samples;
};

RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace drt
