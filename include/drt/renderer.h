// Renders a scene into an image: tiles handed out to worker threads, each pixel a pure function
// of the scene, the options and the seed, so the image never depends on the thread count.
#pragma once

#include <functional>

#include "drt/image.h"
#include "drt/integrator.h"
#include "drt/render_plan.h"
#include "drt/scene.h"

namespace drt {

struct RenderOptions {
    int threads = 0;  // 0 = all cores
    // Called now and then from the rendering thread with the fraction done (0..1).
    std::function<void(double)> on_progress;
};

struct RenderStats {
    double seconds = 0;
    int threads = 1;
    RayCounts rays;
};

struct RenderResult {
    Image image;
    RenderPlan plan;
    RenderStats stats;
};

RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace drt
