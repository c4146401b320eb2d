// What one render of a scene set up once (RenderContext) asks for: its samples and seed, which
// pixels, whether each pixel is rendered twice and whether the error is estimated. A plain render
// is one request; a render to a goal (goal_render.h) is a request per round.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "drt/render/aov.h"
#include "drt/scene/scene.h"

namespace drt {

// Adaptive sampling: each pixel takes samples in rounds, each round as many as it has so far,
// and stops once the estimated standard error of its mean luminance falls below the threshold,
// or at the request's sample count. The estimate is the sample deviation over sqrt(n), or for an
// extensible sampler the spread of the means of 8 consecutive runs over sqrt(8), which credits
// stratification. The decision reads only the pixel's own samples, so the image stays
// independent of the thread count.
struct AdaptiveSampling {
    double noise_threshold = 0;  // in linear luminance units
    int min_samples = 16;        // taken before the estimate is trusted; capped at the maximum
};

// Which pixels a request renders; the others are left 0.
enum class PixelChoice {
    kAll,
    // One pixel of each pixel_block x pixel_block square, picked by a hash of the seed and the
    // square (RenderContext::renders): a sample of the image whose mean error is an unbiased
    // guess at the whole image's.
    kOnePerBlock,
    kListed,  // the pixels in RenderRequest::listed
};

struct RenderRequest {
    int samples = 16;  // camera samples per pixel (the most, when adaptive)
    std::uint64_t seed = 0;
    std::optional<AdaptiveSampling> adaptive;
    // False skips the error estimate's calibration (its second renders of some pixels), for a
    // render whose estimate nobody reads.
    bool estimate_error = true;
    PixelChoice pixels = PixelChoice::kAll;
    int pixel_block = 1;                // kOnePerBlock: the side of the squares, at least 2
    std::vector<std::uint32_t> listed;  // kListed: indices y * width + x, ascending, distinct
    // Every rendered pixel twice, with independent patterns, and the two averaged: its spread is
    // then a quarter of the pair's squared difference, whose expectation is the variance of their
    // mean whatever the sampler, so the estimate is the pixels' own and needs no calibration.
    bool paired = false;
    // First-hit values each rendered pixel also gets (aov.h): the mean over as many camera
    // samples as the pixel took, the first ones of its pattern.
    std::vector<Aov> aovs;

    // The whole image at the settings' samples and seed.
    static RenderRequest whole_image(const RenderSettings& settings) {
        RenderRequest request;
        request.samples = settings.samples;
        request.seed = settings.seed;
        return request;
    }
    // Adaptive sampling as applied: the minimum between 1 and the sample count.
    std::optional<AdaptiveSampling> applied_adaptive() const {
        std::optional<AdaptiveSampling> applied = adaptive;
        if (applied) applied->min_samples = std::clamp(applied->min_samples, 1, samples);
        return applied;
    }
};

}  // namespace drt
