// Rendering to a goal instead of a sample count: until the image's estimated error reaches a
// target (--target-error), or for as long as a time budget allows (--time-limit).
//
// To a target error, the rounds add up: each round is a complete render of the whole image with
// its own seed (round_seed), an independent stratified or Sobol pattern of its count, and the
// image is the weighted mean of the rounds' images (round_weight), so no round's samples are
// thrown away. Independent rounds make the variance of that mean the sum of the rounds'
// variances times their weights squared, which is what the combined estimate states, pixel by
// pixel. The counts are chosen on the leader from the rounds' estimated errors and shared with
// every process, so the same command gives the same bits for any --threads and any number of
// processes. On an image of at least 16 x kPilotPixels pixels the first round is a pilot of one
// pixel in b x b (pilot_block) at kFirstPilot samples, each rendered twice, which measures the
// image's error per pixel for 2 / b^2 of a full round's cost and is then dropped; on a smaller
// one it is the full render `--spp 8`, kept. The first full round is the plain render `--spp N`
// of its count; where it meets the target alone, the image is that render's bit for bit.
// Otherwise the image is no plain render's (a stratified pattern of N samples does not extend
// one of fewer). A near miss is made up, where it costs fewer samples than a full round, by a
// top-up (plan_top_up): the last full round's count, twice, on the pixels next to the most
// estimated variance only, with a seed of its own like a full round; the leader shares its
// pixels with every process.
//
// To a time limit alone, each round is a complete render at one sample count that replaces the
// last, so the image kept is bit-identical to the plain render `--spp N` of the count N it
// reached and can be rendered again without the clock; where the rounds stop depends on the
// machine's speed.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "drt/job/render_job.h"
#include "drt/scene/scene.h"

namespace drt {

struct ProgressiveGoal {
    std::optional<double> target_error;  // estimated RMSE to reach
    std::optional<double> time_limit;    // seconds from `start`
    int max_samples = 0;                 // per pixel, never more (--spp)
    bool pilots_only = false;            // see render_progressively
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

// One complete render of the sequence.
struct ProgressiveRound {
    int spp = 0;
    double seconds = 0;           // its wall-clock time
    std::optional<double> error;  // its own estimated RMSE; absent where it cannot be estimated
    // The estimated RMSE of the image kept after it: of the rounds so far combined (a target
    // error), or its own (a time limit alone); absent after a pilot of some pixels.
    std::optional<double> combined;
    // Above 1: a pilot that rendered one pixel in pixel_block x pixel_block and is not part of
    // the image (its error still stands for the whole image's at its count).
    int pixel_block = 1;
    // The camera samples its error estimate's calibration traced, over its own (1 for a pilot of
    // some pixels, which renders each of its pixels twice).
    double calibration = 0;
    // Of `seconds`, what went before and after its tiles (RenderStats::setup_seconds).
    double setup_seconds = 0;
    // Above 0: a top-up round (plan_top_up) on this share of the image's pixels, each rendered
    // twice (calibration 1), part of the image there; its `error` is its pixels' own.
    double top_up_share = 0;

    // A round of the whole image.
    bool full() const { return pixel_block == 1 && top_up_share == 0; }
    bool top_up() const { return top_up_share > 0; }
    // The camera samples it traced per pixel of the image, its calibration's included: what its
    // time paid for.
    double cost() const {
        const double share = top_up() ? top_up_share : 1 / double(pixel_block * pixel_block);
        return spp * share * (1 + calibration);
    }
};

// A pilot takes at least this many pixels, so that its error estimate stands for the image's.
inline constexpr double kPilotPixels = 1024;
// A pilot of some pixels takes at most one pixel in kMinPilotBlock squared: a costlier one, not
// kept, loses more than a full pilot, kept, does (at --scale 0.1, 80 x 60, one pixel in 2 x 2
// made the thesis scenes' goal renders 4 % dearer, docs/accuracy-history.md).
inline constexpr int kMinPilotBlock = 4;
// And at least one in kMaxPilotBlock squared: beyond, it costs too little to matter. Its pixels
// rendered twice, one in 12 x 12 costs 0.11 samples per image pixel, under 4 % of the 3 spp that
// reach an RMSE of 0.01 on Test1 at 800 x 600 (one in 8 x 8, the cap before, cost 0.25, and Test1,
// Test4 and Test5 at 800 x 600 took 4 % more samples; docs/accuracy-history.md).
inline constexpr int kMaxPilotBlock = 12;
// The side b of the squares of which a render to a target error pilots one pixel: the largest
// with at least kPilotPixels squares, at most kMaxPilotBlock; 1 (a full pilot, kept) where that
// is under kMinPilotBlock, below 16 x kPilotPixels pixels (128 x 128).
int pilot_block(int width, int height);

// The seed of full round `round` (from 0; a pilot of some pixels has the scene's seed and is not
// counted) of a render to a target error: the scene's for the first, so that it is the plain
// render of its count, and a hash of it for the others, whose patterns are then independent of
// the first's and of every plain render's with a nearby seed.
std::uint64_t round_seed(std::uint64_t seed, std::size_t round);

// A round's weight in the combined image: the inverse of its estimated variance, 1 / error^2,
// which gives the mean with the least variance; a stratified or Sobol round's samples are worth
// more the more of them it has (their error falls faster than 1 / sqrt(n)), so weighting by count
// would undervalue the largest round. Its count where it has no positive estimate (where all
// rounds have none, the image is still the mean of their samples).
double round_weight(const std::optional<double>& error, int spp);

// The samples per pixel of all full rounds together: the image's.
int total_samples(const std::vector<ProgressiveRound>& rounds);

// Samples per pixel and time a render needs to reach an error, extrapolated from rounds.
struct Prediction {
    int spp = 0;
    double seconds = 0;
};

// The count of one more round at which the rounds combined reach `target` (with kSpareShare of
// it to spare), at most `max_samples` in all rounds together (0 when none is left or `target` is
// met), and its time from a line through the rounds' times. A round's own error is extrapolated
// from the latest round with an estimate along the log-log slope from the latest earlier one at
// most a third of its count (held between `steepest` and -1/4: rounds are noisy); without such a
// round the slope is `steepest` itself (-1 by default: the count errs on the short side, since a
// shortfall costs only one small round more; next_round passes -1/2 after a final round missed).
// A round smaller than that one's (after a near miss) is extrapolated along -3/4
// instead, whatever the measured slope: between 2 and 8 spp the thesis scenes' stratified errors
// fall along -0.6 to -0.83, and a pattern's gain over independent samples is smallest at few
// samples. With round_weight's weights the combined error c' of one more round of error e is
// 1 / c'^2 = 1 / c^2 + 1 / e^2, c the rounds' combined estimate so far. After a pilot of some
// pixels alone, e itself, reaching a 0.95 share of the target, and toward more samples than the
// pilot's along -0.8 (progressive.cpp, kPilotSpareShare). At least 2 samples. Absent when no
// round has a positive estimate or the last full round has no combined one.
std::optional<Prediction> predict(const std::vector<ProgressiveRound>& rounds, double target,
                                  int max_samples, double steepest = -1.0);

// Seconds a full render of `spp` samples takes, from a line (set-up plus a cost per camera sample
// traced per pixel) through the last two rounds' times and costs (from the last round alone when
// there is one), with the last full round's share of calibration (none before one).
double predicted_seconds(const std::vector<ProgressiveRound>& rounds, int spp);

// The count of the round after `rounds` on the way to `target` (with all rounds at most
// `max_samples`; 0 when the combined estimate meets the target or fewer than 2 samples are left):
// the predicted count itself when it is at most kFinalStep times the last round's (`final`),
// otherwise a pilot a kFinalStep-th of it (at least 4 times the last round), whose error against
// the last round's measures the slope over a wide span, so that the next prediction extrapolates
// only kFinalStep-fold. After a final round that missed (the estimate's noise decides many), the
// prediction along a slope no steeper than -1/2. A round adds at least a tenth of the samples so
// far, and at least 2 (a round of 1 sample has no estimate).
struct NextRound {
    int spp = 0;
    bool final = false;
};
NextRound next_round(const std::vector<ProgressiveRound>& rounds, double target, int max_samples);

// A top-up round: `spp` samples in each of `pixels` and `calibration` (indices y * width + x,
// ascending), twice.
struct TopUp {
    int spp = 0;
    std::vector<std::uint32_t> pixels;
    // Pixels picked at random among the others, whose pairs measure their true error, and the
    // odds each had.
    std::vector<std::uint32_t> calibration;
    std::vector<double> calibration_odds;
    // What the round renders: `pixels` and `calibration` together, ascending.
    std::vector<std::uint32_t> rendered() const;
    // Its camera samples per pixel of the image.
    double cost(std::size_t image_pixels) const {
        return 2.0 * spp * double(pixels.size() + calibration.size()) / double(image_pixels);
    }
};

// A top-up's calibration takes this many pixels on average, at most a sixteenth of the image's.
inline constexpr double kTopUpCalibrationPixels = 512;

// A top-up round takes at least this many pixels: its own estimate, which weights it against the
// rounds before, then rests on as many pairs (RenderContext).
inline constexpr std::size_t kMinTopUpPixels = 64;

// The pixels a top-up round of `spp` samples, twice, needs to bring an image whose estimated
// variances of the pixels' means are `variance` (per channel) to an RMSE of `goal`, where the
// mean of a pixel's two renders is predicted to have the variance `pair_variance`; absent when
// even every pixel does not, or the goal is met. The pixels are taken in order of the largest
// variance among their (up to) eight neighbours, not their own: a pixel's own samples then do not
// decide whether it is topped up, so the mean the rounds make of it stays unbiased (plan by its
// own variance and a pixel whose samples happened to agree would keep its error). Combined with
// the rounds by inverse variance, a pixel's v falls to v t / (v + t). At least kMinTopUpPixels.
// With `calibration_seed`, also `calibration`: kTopUpCalibrationPixels of the
// others on average (at most a sixteenth of the image), each picked by a hash of the seed and
// the pixel with odds a quarter shared equally, the rest in proportion to its neighbours'
// largest variance (at most 1). render_progressively takes the count of the last full round,
// so that its first top-up recalibrates that round's estimate (progressive.cpp, Combination).
// With `most_pixels` (at least kMinTopUpPixels), at most that many, the first in that order,
// even where they fall short of `goal` (a top-up cut to the time left).
std::optional<TopUp> plan_top_up(const Image& variance, const Image& pair_variance, int spp,
                                 double goal,
                                 std::optional<std::uint64_t> calibration_seed = std::nullopt,
                                 std::size_t most_pixels = std::numeric_limits<std::size_t>::max());

struct ProgressiveResult {
    RenderJobResult job;    // the image kept: the rounds combined, or a time limit's last round
    int samples = 0;        // its samples per pixel, all rounds kept together
    bool combined = false;  // a target error: the rounds are combined
    std::optional<double> error;  // its estimated RMSE
    std::vector<ProgressiveRound> rounds;
    bool target_met = false;
    bool stopped = false;  // a signal (options.stop) ended it; job may be incomplete
};

// The first round's count: a pilot that costs little next to the render and still has samples
// enough for the error estimate.
inline constexpr int kFirstPilot = 8;
// A final round at most this many times the last round's count; see next_round.
inline constexpr int kFinalStep = 12;
// A round meant as the last aims at this share of the target error: a miss costs only a small
// round more, since the rounds add up.
inline constexpr double kSpareShare = 0.98;

// Collective under MPI. A round at kFirstPilot, then for a target error the rounds next_round
// sizes, or a top-up (plan_top_up) where it costs fewer samples than a round meant as the last
// (combined; also under a time limit, which may end them early), for a time budget alone
// the largest predicted to fit (with a tenth to spare), until the goal is met, the budget is spent
// or max_samples reached; with goal.pilots_only, a target error stops before its final round
// (what drt info --target-error renders). A round still running when the budget runs out is
// stopped and dropped. options.checkpoint and options.adaptive must be absent. The scene's sample
// count and seed are changed during the rounds and restored afterwards.
ProgressiveResult render_progressively(Scene& scene, const RenderJobOptions& options,
                                       const ProgressiveGoal& goal);

}  // namespace drt
