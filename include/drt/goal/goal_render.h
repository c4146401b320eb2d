// Rendering to a goal instead of a sample count: until the image's estimated error reaches a
// target (--target-error), or for as long as a time budget allows (--time-limit). The scene is
// set up once; each round is a request (render_request.h) against it.
//
// To a target error the rounds add up. Each full round renders the whole image with its own
// seed (round_seed), an independent stratified or Sobol pattern of its count, and the image is
// the mean of the rounds weighted by round_weight, whose variance is the sum of the rounds'
// variances times their weights squared: what the combined estimate states, pixel by pixel.
// On an image of at least 16 x kPilotPixels pixels the first round is a pilot: one pixel in b x b
// (pilot_block) at kFirstRoundSpp samples, each rendered twice, which measures the error per pixel
// for 2 / b^2 of a full round's cost and is then dropped; on a smaller image the first round is
// the full render `--spp 8`, kept. Then next_round sizes each round from the errors so far: the
// predicted count when it is near, or an intermediate round that measures the slope over a wide
// span. The first full round is the plain render `--spp N` of its count; where it meets the
// target alone, the image is that render's bit for bit. A near miss is made up, where it costs
// less than a full round, by a top-up (plan_top_up): the last full round's count, twice, on the
// pixels next to the most estimated variance only, with a seed of its own like a full round.
// The leader decides every round and shares it with every process, so the same command gives
// the same bits for any --threads and any number of processes.
//
// To a time limit alone, each round is a complete render at one sample count that replaces the
// last, so the image kept is bit-identical to the plain render `--spp N` of the count N it
// reached; where the rounds stop depends on the machine's speed.
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

struct RenderGoal {
    std::optional<double> target_error;  // estimated RMSE to reach
    std::optional<double> time_limit;    // seconds from `start`
    int max_samples = 0;                 // per pixel, never more (--spp)
    // A target error stops before its final round: what drt info --target-error renders to
    // predict the rest.
    bool stop_before_final = false;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

// kFull renders the whole image; kPilot one pixel in pixel_block x pixel_block, measured and not
// kept; kTopUp some pixels twice (plan_top_up).
enum class RoundKind { kFull, kPilot, kTopUp };

// One complete round.
struct GoalRound {
    int spp = 0;
    double seconds = 0;           // its wall-clock time
    std::optional<double> error;  // its own estimated RMSE; absent where it cannot be estimated
    // The estimated RMSE of the image kept after it: of the rounds so far combined (a target
    // error), or its own (a time limit alone); absent after a pilot.
    std::optional<double> combined;
    RoundKind kind = RoundKind::kFull;
    int pixel_block = 1;  // a pilot's; its error stands for the whole image's at its count
    // The camera samples its error estimate took beyond the image's, over the image's (1 for a
    // pilot or a top-up, which render each of their pixels twice).
    double estimate_cost = 0;
    // Of `seconds`, what went before and after its tiles (RenderStats::setup_seconds).
    double setup_seconds = 0;
    double top_up_share = 0;  // a top-up's share of the image's pixels
    std::uint64_t seed = 0;   // the request's; a combined full round's renders it alone (--seed)

    bool full() const { return kind == RoundKind::kFull; }
    bool top_up() const { return kind == RoundKind::kTopUp; }
    // The camera samples it traced per pixel of the image, its estimate's included: what its
    // time paid for.
    double cost() const {
        const double share = top_up() ? top_up_share : 1 / double(pixel_block * pixel_block);
        return spp * share * (1 + estimate_cost);
    }
};

// A pilot takes at least this many pixels, so that its error estimate stands for the image's.
inline constexpr double kPilotPixels = 1024;
// A pilot takes at most one pixel in kMinPilotBlock squared: a costlier one, not kept, loses more
// than a full first round, kept, does.
inline constexpr int kMinPilotBlock = 4;
// And at least one in kMaxPilotBlock squared: beyond, it costs too little to matter.
inline constexpr int kMaxPilotBlock = 12;
// The side b of the squares of which a render to a target error pilots one pixel: the largest
// with at least kPilotPixels squares, at most kMaxPilotBlock; 1 (a full first round, kept) where
// that is under kMinPilotBlock.
int pilot_block(int width, int height);

// The seed of round `round` (from 0, pilots not counted, top-ups counted) of a render to a
// target error: the scene's for the first, so that it is the plain render of its count, and a
// hash of it for the others, whose patterns are then independent of the first's.
std::uint64_t round_seed(std::uint64_t seed, std::size_t round);

// A round's weight in the combined image: the inverse of its estimated variance, 1 / error^2,
// which gives the mean with the least variance (a stratified or Sobol round's samples are worth
// more the more of them it has, so weighting by count would undervalue the largest). Its count
// where it has no positive estimate.
double round_weight(const std::optional<double>& error, int spp);

// The samples per pixel of all full rounds together: the image's.
int total_samples(const std::vector<GoalRound>& rounds);
// The most samples a pixel can have had: the full rounds', and twice each top-up's, should it
// be in them all. The maximum (--spp) bounds this, so that no pixel passes it.
int most_pixel_samples(const std::vector<GoalRound>& rounds);

// Samples per pixel and time a render needs to reach an error, extrapolated from rounds.
struct Prediction {
    int spp = 0;
    double seconds = 0;
};

// The count of one more full round at which the rounds combined reach `target` (with kSpareShare
// of it to spare), at most `max_samples` in all rounds together (0 when none is left or `target`
// is met), and its time (predicted_seconds). A round's error is extrapolated from the largest
// round with an estimate along the log-log slope from the largest earlier one at most a third of
// its count, held between `steepest` and -1/4; without one, along `steepest` (short rather than
// long: a shortfall costs only one small round more). Toward fewer samples than that round's,
// along -3/4 whatever the slope. With round_weight's weights, one more round of error e makes
// 1 / c'^2 = 1 / c^2 + 1 / e^2. After a pilot alone, along -0.8 toward a 0.95 share of the
// target. At least 2 samples. Absent when no round has a positive estimate or the last full
// round has no combined one.
std::optional<Prediction> predict(const std::vector<GoalRound>& rounds, double target,
                                  int max_samples, double steepest = -1.0);

// Seconds a full round of `spp` samples takes, from a line (set-up plus a cost per camera sample
// traced per pixel) through the last two rounds' times and costs (from the last round alone when
// there is one), with the last full round's estimate cost (none before one).
double predicted_seconds(const std::vector<GoalRound>& rounds, int spp);

// The count of the round after `rounds` on the way to `target` (with all rounds at most
// `max_samples`; 0 when the combined estimate meets the target or fewer than 2 samples are left):
// the predicted count when it is at most kFinalStep times the last round's (`final`), otherwise
// an intermediate round a kFinalStep-th of it (at least 4 times the last round), whose error
// against the last round's measures the slope over a wide span. After a final round that missed,
// the prediction along a slope no steeper than -1/2. A round adds at least a tenth of the samples
// so far, and at least 2 (a round of 1 sample has no estimate).
struct NextRound {
    int spp = 0;
    bool final = false;
};
NextRound next_round(const std::vector<GoalRound>& rounds, double target, int max_samples);

// A top-up round: `spp` samples in each of `pixels` and `spot_checks` (indices y * width + x,
// ascending), twice.
struct TopUp {
    int spp = 0;
    std::vector<std::uint32_t> pixels;
    // Pixels picked at random among the others, whose pairs measure the true error there, and the
    // odds each had.
    std::vector<std::uint32_t> spot_checks;
    std::vector<double> spot_check_odds;
    // What the round renders: `pixels` and `spot_checks` together, ascending.
    std::vector<std::uint32_t> rendered() const;
    // Its camera samples per pixel of the image.
    double cost(std::size_t image_pixels) const {
        return 2.0 * spp * double(pixels.size() + spot_checks.size()) / double(image_pixels);
    }
};

// A top-up takes this many spot checks on average, at most a sixteenth of the image's pixels.
inline constexpr double kTopUpSpotChecks = 512;

// A top-up round takes at least this many pixels: its own estimate, which weights it against the
// rounds before, then rests on as many pairs.
inline constexpr std::size_t kMinTopUpPixels = 64;

// The pixels a top-up round of `spp` samples, twice, needs to bring an image whose estimated
// variances of the pixels' means are `variance` (per channel) to an RMSE of `goal`, where the
// mean of a pixel's two renders is predicted to have the variance `pair_variance`; absent when
// even every pixel does not, or the goal is met. The pixels are taken in order of the largest
// variance among their (up to) eight neighbours, not their own, so that a pixel's own samples do
// not decide whether it is topped up and its mean stays unbiased. Combined with the rounds by
// inverse variance, a pixel's v falls to v t / (v + t). At least kMinTopUpPixels. With
// `spot_check_seed`, also the spot checks: kTopUpSpotChecks of the others on average, each picked
// by a hash of the seed and the pixel with pick_odds by its neighbours' largest variance. With
// `most_pixels` (at least kMinTopUpPixels), at most that many, the first in that order, even
// where they fall short of `goal` (a top-up cut to the time left).
std::optional<TopUp> plan_top_up(const Image& variance, const Image& pair_variance, int spp,
                                 double goal,
                                 std::optional<std::uint64_t> spot_check_seed = std::nullopt,
                                 std::size_t most_pixels = std::numeric_limits<std::size_t>::max());

struct GoalResult {
    RenderJobResult job;    // the image kept: the rounds combined, or a time limit's last round
    int samples = 0;        // its samples per pixel, all rounds kept together
    bool combined = false;  // a target error: the rounds are combined
    std::optional<double> error;  // its estimated RMSE
    std::vector<GoalRound> rounds;
    bool target_met = false;
    bool stopped = false;  // a signal (options.stop) ended it; job may be incomplete
};

// The first round's count: little next to the render, and samples enough for the estimate.
inline constexpr int kFirstRoundSpp = 8;
// A final round at most this many times the last round's count; see next_round.
inline constexpr int kFinalStep = 12;
// A round meant as the last aims at this share of the target error: a miss costs only a small
// round more, since the rounds add up.
inline constexpr double kSpareShare = 0.98;

// Collective under MPI. Sets the scene up once and renders rounds against it until the goal is
// met, the budget is spent or max_samples reached. For a target error, the rounds next_round
// sizes, or a top-up where it costs fewer samples than a final round (also under a time limit,
// which may cut them); for a time budget alone, the largest round predicted to fit (with a tenth
// to spare). A round still running when the budget runs out is stopped and dropped, except the
// first full round. options.checkpoint must be absent.
GoalResult render_to_goal(const Scene& scene, const RenderJobOptions& options,
                          const RenderGoal& goal);

}  // namespace drt
