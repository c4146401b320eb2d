// A render's estimate of its own error, from its own samples and no reference: how far each
// pixel's mean is expected to lie from the converged value, and what that makes of the image's
// RMSE and relative MSE (the measures drt converge takes against a reference, converge.h).
//
// Each pixel keeps a spread of its samples, per channel (TileBuffer::spread), and adds to a few
// sums over its tile (TileBuffer::error_sums); both are pure functions of the pixel like its
// value, so they are the same for any threads, tile order, process or resume. The image's
// estimate (estimate_error) turns the sums, added up in tile order, into one scale that makes
// every pixel's spread the variance of its mean.
//
// How the spread is made depends on the sampler (SpreadKind):
// - independent samples: the sample variance over n is the variance of the mean, scale 1.
// - a progressive sampler (sobol): its samples split into B consecutive runs that are each a
//   stratified pattern of their own and exchangeable, and then E[spread of the B run means] =
//   B/(B-1) (var of a run's mean - var of the whole mean). With var(mean of n/B) = var(mean of n)
//   * B^beta, the spreads at B = 2, 4, 8 give beta (the image's convergence rate: 1 for random
//   noise, 1.5 at edges, more where smooth) and the variance. Plain batch means (beta = 1) would
//   overstate the error of a stratified pattern by up to B^((beta-1)/2).
// - any other sampler: the sample variance over n, scale 1, which overstates stratified samples.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>

#include "drt/color.h"
#include "drt/image.h"

namespace drt {

enum class SpreadKind { kIndependent, kProgressive, kOther };

// What the image's estimate adds up over all pixels and channels.
struct ErrorSums {
    // Progressive: (B-1)/B x the sample variance of the means of B consecutive runs, for B = 2, 4,
    // 8, and the pixels that had samples for each B (B at most the pixel's count).
    std::array<double, 3> runs{};
    std::array<double, 3> runs_pixels{};

    ErrorSums& operator+=(const ErrorSums& o);
    friend bool operator==(const ErrorSums&, const ErrorSums&) = default;
};

// One pixel's samples (in the order taken) as the estimate uses them: `spread`, per channel, is
// the sample variance over n (independent, other) or the (B-1)/B-scaled spread of the means of
// the most runs B <= 8 (progressive); infinite for fewer than two samples. `sums` gets the
// pixel's share.
Color pixel_spread(std::span<const Color> samples, SpreadKind kind, ErrorSums& sums);

struct ErrorEstimate {
    // Both present, or neither: then `unavailable` says why.
    std::optional<double> rmse;    // over all pixels and channels, as drt compare and converge
    std::optional<double> relmse;  // mean of err^2 / (ref^2 + 0.01), the converged value unknown
    std::string unavailable;
    // A pixel's spread times `scale` is the estimated variance of its mean (when available).
    double scale = 1;
    // Progressive: the fitted convergence rate beta (variance of the mean ~ n^-beta); 1 otherwise.
    double beta = 1;

    bool available() const { return rmse.has_value(); }
};

// The expected RMSE and relative MSE of `image` against the converged image from the per-pixel
// spreads (the same size) and the image's sums. relMSE stands x^2 - variance (at least 0) for
// the unknown ref^2. `spp` is the samples per pixel asked for: with 1 the pixel centre is taken
// and nothing can be estimated, and a progressive sampler needs 8 (three sizes of run). Throws
// ImageError when the sizes differ.
ErrorEstimate estimate_error(const Image& image, const Image& spread, const ErrorSums& sums,
                             int spp, SpreadKind kind);

// The per-pixel standard error, per channel: sqrt(spread x scale); 0 where there is no estimate.
Image standard_error_image(const Image& spread, const ErrorEstimate& estimate);

// "0.00123" or "n/a (reason)", as the finish line and drt converge print it.
std::string format_estimate(const std::optional<double>& value, const std::string& unavailable);

}  // namespace drt
