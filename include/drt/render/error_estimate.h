// A render's estimate of its own error, from its own samples and no reference: how far each
// pixel's mean is expected to lie from the converged value, and what that makes of the image's
// RMSE and relative MSE (the measures drt converge takes against a reference, converge.h).
//
// Each pixel keeps a spread per channel, a guess at the variance of its mean. For independent
// samples (the random sampler) it is their sample variance over n (pixel_spread), which is that
// variance. For a stratified or Sobol pattern the sample variance ignores the stratification and
// overstates the error several times; their spread is the strata spread
// (strata_spread), from differences of neighbouring strata, which credits the stratification but
// cannot see correlations between strata. There the spread only says where the error is, and the
// image calibrates how large it is: a few pixels of each tile, chosen at random with odds that
// grow with the spread around them (calibration_odds), are rendered a second time with an
// independent pattern of the same sampler and count. Half the squared difference of the two
// means has the variance of the mean as its expectation, whatever the pattern; summed over the
// chosen pixels, each weighted by 1 / its odds, against the same weighted sum of their spreads,
// it gives the factor (`scale`) that turns every pixel's spread into the variance of its mean.
// The second renders only calibrate: the image is the first render's, unchanged.
//
// The spreads and the tile's sums are pure functions of the tile like its pixels, so they are
// the same for any threads, tile order, process or resume; the image's estimate adds the tiles'
// sums up in tile order.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drt/io/image.h"
#include "drt/util/color.h"
#include "drt/util/math.h"

namespace drt {

// kIndependent: the spread is the variance of the mean. kCalibrated: a stratified or Sobol pattern,
// calibrated by second renders.
enum class SpreadKind { kIndependent, kCalibrated };

// The share of an image's pixels rendered a second time, on average: the calibration's cost.
inline constexpr double kCalibrationShare = 0.08;
// A calibration of this many pixels pins the estimate's scale to a few per cent (the relative
// spread of a variance from N independent differences is about sqrt(2 / N)); more would only
// add cost, so a large image renders this many twice rather than kCalibrationShare of its pixels.
inline constexpr double kMaxCalibrationPixels = 4096;
// Fewer pixels rendered twice than this leave the calibration too noisy to state a number.
inline constexpr double kMinCalibrationPixels = 24;
// A small image renders at least this many pixels twice (all of them below it): the
// calibration's noise depends on how many pixels it takes, not on their share, and a small
// image's error sits in few pixels.
inline constexpr double kMinSmallImageCalibration = 512;
// The share for an image of `pixels` pixels: kCalibrationShare, capped at kMaxCalibrationPixels
// pixels, or more for a small image, so that kMinSmallImageCalibration pixels are rendered twice
// on average (all of them below that).
double calibration_share(double pixels);

// What the image's estimate adds up over the pixels rendered twice (kCalibrated).
struct ErrorSums {
    double variance = 0;  // half the squared difference of the two means, over channels, / odds
    double spread = 0;    // the first render's spread, summed over channels, / odds
    double pixels = 0;    // how many pixels were rendered twice
    double samples = 0;   // the camera samples that took

    ErrorSums& operator+=(const ErrorSums& o);
    friend bool operator==(const ErrorSums&, const ErrorSums&) = default;
};

// The sample variance of one pixel's samples over their count, per channel; infinite for fewer
// than two samples.
Color pixel_spread(std::span<const Color> samples);

// strata_spread's sort buffers, kept from pixel to pixel by its caller (one per thread) so that a
// pixel's spread allocates nothing once the buffers have grown to the pixel's samples.
struct StrataScratch {
    struct Entry {
        double along;  // the sample's place along its band
        std::uint32_t index;
    };
    std::vector<std::uint32_t> band;   // each sample's band
    std::vector<std::uint32_t> start;  // where each band's samples begin in `order`
    std::vector<Entry> order;          // the samples band by band, each band in order along it
};

// The spread of a stratified or Sobol pixel (the calibrated samplers): the variance of its mean
// guessed from differences between neighbouring strata, per channel, from each sample's value and
// position in the pixel (in [0, 1)^2). The pixel is cut into C = floor(sqrt(n)) columns and
// R = ceil(n / C) rows, the cells of both samplers' patterns; along each row the samples in x
// order and along each column in y order give, for three neighbours a, b, c, the term
// (a - 2b + c)^2 / 6 (two neighbours, a band of two: (a - b)^2 / 2), whose expectation is one
// stratum's variance where the pixel's value is linear across them plus noise. The mean term over
// n is the variance of the mean if every stratum had that variance. A smooth gradient cancels,
// unlike in the sample variance, which counts it whole and so overstated an edge's stratified
// error about sqrt(n)-fold; an edge across a band counts about twice its variance, one along a
// band once. The calibration then scales what is left. Infinite for fewer than two samples.
Color strata_spread(std::span<const Vec2> positions, std::span<const Color> samples,
                    StrataScratch& scratch);

// For each pixel of a width x height image of `values` (row by row), the largest value among its
// (up to) 8 neighbours, and with kWithSelf its own too: a pixel whose few samples all fell on one
// side of an edge shows no spread, though its neighbours along the edge do.
enum class Around { kWithSelf, kNeighboursOnly };
std::vector<double> largest_around(std::span<const double> values, int width, int height,
                                   Around which);

// The odds of picking a pixel when `scale` picks go a quarter equally (`even`, each pixel's part
// of that quarter as a share of the unit) and three quarters in proportion to the pixel's
// `weight` out of `total`; at most 1. Every pixel keeps some odds, so sums weighted by 1 / odds
// stay unbiased, and the pixels that carry most of the error are picked most often.
double pick_odds(double scale, double even, double weight, double total);

// For each pixel of a tile (its spread image, row by row), the odds of rendering it a second
// time: `share` on average over the tile, by pick_odds with the largest spread (summed over
// channels) of the pixel and its neighbours in the tile as the weight (largest_around).
std::vector<double> calibration_odds(const Image& spread, double share);

// Adds a pixel rendered twice: `first` the image's mean and `spread` its spread, `second` the
// mean of the independent render of `samples` camera samples, `odds` its calibration odds.
void add_calibration(ErrorSums& sums, const Color& first, const Color& second, const Color& spread,
                     double odds, std::uint32_t samples);

struct ErrorEstimate {
    // Both present, or neither: then `unavailable` says why.
    std::optional<double> rmse;    // over all pixels and channels, as drt compare and converge
    std::optional<double> relmse;  // mean of err^2 / (ref^2 + 0.01), the converged value unknown
    std::string unavailable;
    // A pixel's spread times `scale` is the estimated variance of its mean (when available).
    double scale = 1;
    // The camera samples the calibration took, over the image's: its cost.
    double cost = 0;
    // How many pixels the estimated squared error effectively sits in: (sum v)^2 / sum v^2 over
    // the pixels, v a pixel's estimated variance summed over its channels (N for N equal pixels,
    // about 1 when one pixel carries it all); 0 when the estimate is 0. One image's true error
    // is a sum of that many pixels' random errors, so it scatters about the expected error
    // however good the estimate is: by rmse_scatter(). Noise in the v, and a stratified edge's
    // spread counting twice (strata_spread), make the count low and so the scatter high.
    double error_pixels = 0;

    // The relative standard deviation of one image's true RMSE about its expected value, for
    // normally distributed pixel errors: the squared error of error_pixels independent pixels
    // has a relative deviation of sqrt(2 / error_pixels), its root half that. 0 without error.
    double rmse_scatter() const { return error_pixels > 0 ? 1 / std::sqrt(2 * error_pixels) : 0; }

    bool available() const { return rmse.has_value(); }
};

// The expected RMSE and relative MSE of `image` against the converged image from the per-pixel
// spreads (the same size), the image's sums and its camera `samples`. relMSE stands x^2 -
// variance (at least 0) for the unknown ref^2. `spp` is the samples per pixel asked for: with 1
// the pixel centre is taken and nothing can be estimated. Where no sample of any pixel spread and
// no pixel rendered twice differed, the estimate is 0 however few were rendered twice. `pixels`
// is how many pixels were rendered, the others left 0 (render_request.h): the mean is
// theirs; 0 for all. Throws ImageError when the sizes differ.
ErrorEstimate estimate_error(const Image& image, const Image& spread, const ErrorSums& sums,
                             std::uint64_t samples, int spp, SpreadKind kind,
                             std::uint64_t pixels = 0);

// The per-pixel standard error, per channel: sqrt(spread x scale); 0 where there is no estimate.
Image standard_error_image(const Image& spread, const ErrorEstimate& estimate);

// "0.00123" or "n/a (reason)", as the finish line and drt converge print it.
std::string format_estimate(const std::optional<double>& value, const std::string& unavailable);

}  // namespace drt
