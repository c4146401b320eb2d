// Rendering to a goal instead of a sample count: until the image's estimated error reaches a
// target (--target-error), or for as long as a time budget allows (--time-limit). Each round is
// a complete render at one sample count, so the image kept is always bit-identical to the plain
// render `--spp N` of the count N it reached, for every sampler (a stratified pattern of N
// samples does not extend one of fewer, so rounds do not continue one another's samples). The
// counts are chosen on the leader from the rounds' estimated errors and times and shared with
// every process, so a goal of error alone gives the same bits for any --threads and any number
// of processes; a time budget stops where the machine's speed lets it.
#pragma once

#include <chrono>
#include <optional>
#include <vector>

#include "drt/render_job.h"
#include "drt/scene.h"

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
    std::optional<double> error;  // its estimated RMSE; absent where it cannot be estimated
};

// Samples per pixel and time a render needs to reach an error, extrapolated from rounds.
struct Prediction {
    int spp = 0;
    double seconds = 0;
};

// The count at which the error of the last round, extrapolated along the log-log slope from the
// latest round with an estimate and at most a third of its count (held between `steepest` and
// -1/4: rounds are noisy), falls to `target`, with 5 % to spare, at most `max_samples`; the time
// from a line through the rounds' times. Without such a round the slope is taken as -1/2, that
// of independent samples, which no sampler drt has falls short of (stratified and Sobol patterns
// converge faster), so the count errs on the large side. Absent when no round has a positive
// estimate.
std::optional<Prediction> predict(const std::vector<ProgressiveRound>& rounds, double target,
                                  int max_samples, double steepest = -1.0);

// Seconds a render of `spp` samples takes, from a line (set-up plus a cost per sample) through
// the last two rounds' times; from the last round alone when there is one.
double predicted_seconds(const std::vector<ProgressiveRound>& rounds, int spp);

// The count of the round after `rounds` on the way to `target` (at most `max_samples`, 0 when
// the target is met or max_samples reached): the predicted count itself when it is at most
// kFinalStep times the last round's (`final`), otherwise a pilot a kFinalStep-th of it (at least 4
// times the last round), whose error against the last round's measures the slope over a wide span,
// so that the next prediction extrapolates only kFinalStep-fold and lands on the count in one step.
// After a final round that missed (the estimate's noise decides many), the prediction along a
// slope no steeper than -1/2, and at least a tenth more samples (otherwise a quarter).
struct NextRound {
    int spp = 0;
    bool final = false;
};
NextRound next_round(const std::vector<ProgressiveRound>& rounds, double target, int max_samples);

struct ProgressiveResult {
    RenderJobResult job;          // the image kept: the last complete round's
    int samples = 0;              // its samples per pixel: `--spp samples` renders the same bits
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

// Collective under MPI. A round at kFirstPilot, then for a target error the rounds next_round
// sizes, for a time budget the largest predicted to fit (with a tenth to spare), until the goal
// is met, the budget is spent or the next round would pass max_samples; with goal.pilots_only,
// a target error stops before its final round (what drt info --target-error renders). A round still
// running when the budget runs out is stopped and dropped. options.checkpoint must be absent. The
// scene's sample count is changed during the rounds and restored afterwards.
ProgressiveResult render_progressively(Scene& scene, const RenderJobOptions& options,
                                       const ProgressiveGoal& goal);

}  // namespace drt
