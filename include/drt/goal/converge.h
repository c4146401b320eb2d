// Convergence measurement: how a scene's error against a reference falls with camera samples
// and with rendering time, and the log-log slopes Monte Carlo theory predicts (-1/2 for
// independent samples, steeper for stratified and low-discrepancy ones).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "drt/io/image.h"
#include "drt/render/error_estimate.h"
#include "drt/render/renderer.h"
#include "drt/scene/scene.h"

namespace drt {

struct ConvergencePoint {
    int spp = 0;          // camera samples per pixel asked for (the maximum when adaptive)
    double seconds = 0;   // wall-clock time of the render, scene set-up included
    double rmse = 0;      // over all pixels and channels, as drt compare
    double relmse = 0;    // mean of (x - ref)^2 / (ref^2 + 0.01) over all pixels and channels
    double mean_spp = 0;  // camera samples actually taken per pixel
    // Processor time of all threads: steadier than wall-clock time when other programs compete
    // for the cores (on an otherwise idle machine, about seconds x threads).
    double cpu_seconds = 0;
    // False for 1 spp among larger counts: one sample per pixel takes the pixel's centre instead
    // of sampling its area, a different (deterministic) estimator that the slopes leave out.
    bool fitted = true;
    // The image's own estimate of rmse and relmse, made without the reference (error_estimate.h).
    ErrorEstimate estimate;
};

struct Convergence {
    std::vector<ConvergencePoint> points;
    // Least-squares d log(RMSE) / d log(mean spp) and d log(RMSE) / d log(seconds) over the
    // fitted points.
    double slope_vs_spp = 0;
    double slope_vs_seconds = 0;
};

// Root-mean-square difference over all pixels and channels; throws ImageError on a size mismatch.
double rmse(const Image& image, const Image& reference);

// Mean over all pixels and channels of (x - ref)^2 / (ref^2 + 0.01): squared error relative to
// the reference's brightness, so dark and bright regions weigh alike; the 0.01 keeps black
// pixels from dominating. Throws ImageError on a size mismatch.
double relative_mse(const Image& image, const Image& reference);

// Least-squares slope of log(y) against log(x) over the pairs where both are positive; NaN when
// fewer than two such pairs have distinct x.
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

// The reference drt converge renders when given none: 16 times the largest count (at most
// kMaxSamples, limits.h), with seed + 1
// so that its noise is independent of every image it judges.
int default_reference_spp(const std::vector<int>& spps);
std::uint64_t reference_seed(std::uint64_t seed);

// The whole image at `spp` samples and `seed` instead of the scene's, with options.adaptive.
RenderRequest request_at(int spp, std::uint64_t seed, const RenderOptions& options);

// Renders the scene at each count in `spps` with its own seed and measures each image against
// `reference`; `on_point` sees each point as soon as it is measured.
Convergence measure_convergence(const Scene& scene, const std::vector<int>& spps,
                                const Image& reference, const RenderOptions& options,
                                const std::function<void(const ConvergencePoint&)>& on_point = {});

// Where the measured RMSE falls to `target`: the samples and seconds interpolated log-log
// between the two fitted points on either side of it (the first fitted point itself when it is
// already there); absent when no measured count reaches it.
struct Reach {
    double spp = 0, seconds = 0;
};
std::optional<Reach> measured_reach(const Convergence& c, double target);

// "spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,estimated_rmse,estimated_relmse" and one
// line per point; the estimates are empty where there are none.
std::string convergence_csv(const Convergence& c);

// Parses a comma-separated list of counts from 1 to kMaxSamples such as "1,4,16"; throws
// std::invalid_argument naming the offending item.
std::vector<int> parse_counts(const std::string& list);

}  // namespace drt
