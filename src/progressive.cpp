#include "drt/progressive.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <stop_token>
#include <thread>

namespace drt {

namespace {

using Clock = std::chrono::steady_clock;

// Under a time budget, a round's count at most this many times the last one's: an
// extrapolation from a round a hundred times smaller is too uncertain to bet the whole budget
// on, and a round a sixteenth of the next costs little.
constexpr double kMaxGrowth = 16;
// A pilot at least this many times the last round's count: a narrower span measures no slope.
constexpr int kMinPilotGrowth = 4;
// A slope only from rounds at least this many times apart: a narrower span measures noise.
constexpr int kMinSlopeSpan = 3;
// The error's log-log slope against samples for independent samples.
constexpr double kIndependentSlope = -0.5;
// Of the time left, what a round may be predicted to take: the rest absorbs the prediction's
// error.
constexpr double kTimeShare = 0.9;
// Predicted counts are raised by this much: a round that misses the target costs a whole
// round more.
constexpr double kSpare = 1.05;
// A round after a final round that missed: at least this many times its count.
constexpr double kRetryGrowth = 1.1;

// The image's estimated RMSE, where the render can estimate it.
std::optional<double> estimated_error(const RenderResult& r) {
    return r.stats.error.rmse;
}

struct Line {
    double setup = 0, per_sample = 0;
};

// Seconds against samples through the last two rounds; set-up and a cost per sample, neither
// negative, so a noisy pair of times never predicts a free sample.
Line time_line(const std::vector<ProgressiveRound>& rounds) {
    const ProgressiveRound& last = rounds.back();
    Line line{0, last.seconds / std::max(1, last.spp)};
    if (rounds.size() < 2) return line;
    const ProgressiveRound& before = rounds[rounds.size() - 2];
    if (last.spp <= before.spp) return line;
    const double slope = (last.seconds - before.seconds) / (last.spp - before.spp);
    const double setup = last.seconds - slope * last.spp;
    if (slope <= 0 || setup < 0) return line;
    return {setup, slope};
}

// Waits in its own thread until `deadline`, then requests `stop`; gives up when destroyed first.
class Alarm {
  public:
    Alarm(Clock::time_point deadline, std::stop_source stop)
        : thread_([deadline, stop](std::stop_token cancelled) mutable {
              std::mutex mutex;
              std::condition_variable_any wake;
              std::unique_lock lock(mutex);
              wake.wait_until(lock, cancelled, deadline, [] { return false; });
              if (!cancelled.stop_requested()) stop.request_stop();
          }) {}

  private:
    std::jthread thread_;
};

}  // namespace

double predicted_seconds(const std::vector<ProgressiveRound>& rounds, int spp) {
    if (rounds.empty()) return 0;
    const Line line = time_line(rounds);
    return line.setup + line.per_sample * spp;
}

std::optional<Prediction> predict(const std::vector<ProgressiveRound>& rounds, double target,
                                  int max_samples, double steepest) {
    std::vector<const ProgressiveRound*> measured;
    for (const ProgressiveRound& r : rounds) {
        if (r.error && *r.error > 0 && std::isfinite(*r.error)) measured.push_back(&r);
    }
    if (measured.empty()) return std::nullopt;
    const ProgressiveRound& b = *measured.back();
    double slope = kIndependentSlope;
    // The latest earlier round kMinSlopeSpan times fewer: over a narrower span (a final round
    // that just missed after one only a little smaller) the errors' noise decides the slope.
    const auto a = std::find_if(measured.rbegin() + 1, measured.rend(),
                                [&](const auto* r) { return r->spp * kMinSlopeSpan <= b.spp; });
    if (a != measured.rend()) {
        slope = std::clamp(std::log(*b.error / *(*a)->error) / std::log(double(b.spp) / (*a)->spp),
                           steepest, -0.25);
    }
    double spp = b.spp;
    if (*b.error > target) spp = b.spp * std::pow(target / *b.error, 1 / slope) * kSpare;
    const int count = static_cast<int>(std::clamp(std::ceil(spp), 1.0, double(max_samples)));
    return Prediction{count, predicted_seconds(rounds, count)};
}

NextRound next_round(const std::vector<ProgressiveRound>& rounds, double target, int max_samples) {
    const ProgressiveRound& last = rounds.back();
    if ((last.error && *last.error <= target) || last.spp >= max_samples) return {};
    // After a round meant as the last that missed, no slope steeper than -1/2: the errors' curves
    // flatten with samples (a pattern's gain over independent samples shrinks), so the slope
    // that led there was too steep, and a second miss costs a whole round more.
    const std::vector<ProgressiveRound> before(rounds.begin(), rounds.end() - 1);
    const bool missed = !before.empty() && next_round(before, target, max_samples).final;
    const auto p = predict(rounds, target, max_samples, missed ? kIndependentSlope : -1.0);
    NextRound next{p ? p->spp : kMinPilotGrowth * last.spp, p.has_value()};
    if (next.spp > kFinalStep * last.spp) {
        next = {std::max((next.spp + kFinalStep - 1) / kFinalStep, kMinPilotGrowth * last.spp),
                false};
    }
    // At least a quarter more, or the round is not worth its time; after a near miss a tenth
    // more, since the estimate's noise alone (some 10 % a round on small images) decides many a
    // miss, and a quarter more would often overshoot.
    next.spp = std::max<double>(next.spp, std::ceil((missed ? kRetryGrowth : 1.25) * last.spp));
    next.spp = static_cast<int>(std::min<double>(next.spp, max_samples));
    return next;
}

ProgressiveResult render_progressively(Scene& scene, const RenderJobOptions& options,
                                       const ProgressiveGoal& goal) {
    const SettingsGuard guard(scene);
    const bool leader = options.mpi == nullptr || options.mpi->leader();
    const auto seconds_left = [&] {
        return *goal.time_limit - std::chrono::duration<double>(Clock::now() - goal.start).count();
    };
    ProgressiveResult out;
    int spp = std::min(kFirstPilot, goal.max_samples);
    for (std::size_t round = 0; spp > 0; ++round) {
        scene.settings.samples = spp;
        // Dropped when the budget runs out before it is done, except the first: without it
        // there would be no image at all.
        std::stop_source stopper;
        const std::stop_callback relay(options.stop, [&] { stopper.request_stop(); });
        std::optional<Alarm> alarm;
        if (goal.time_limit && leader && round > 0) {
            alarm.emplace(goal.start + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(*goal.time_limit)),
                          stopper);
        }
        RenderJobOptions run = options;
        run.stop = stopper.get_token();
        RenderJobResult job = run_render_job(scene, run);
        alarm.reset();
        int next = 0;
        if (!leader) {
            out.job = std::move(job);
        } else if (!job.complete()) {
            out.stopped = options.stop.stop_requested();
            if (out.rounds.empty()) out.job = std::move(job);
        } else {
            const ProgressiveRound done{spp, job.render.stats.seconds, estimated_error(job.render)};
            out.rounds.push_back(done);
            out.job = std::move(job);
            out.samples = spp;
            out.error = done.error;
            out.target_met = goal.target_error && done.error && *done.error <= *goal.target_error;
            if (goal.target_error) {
                const NextRound n = next_round(out.rounds, *goal.target_error, goal.max_samples);
                next = n.final && goal.pilots_only ? 0 : n.spp;
            } else if (spp < goal.max_samples) {
                next = static_cast<int>(std::min(kMaxGrowth * spp, double(goal.max_samples)));
            }
            if (goal.time_limit && next > 0) {
                const Line line = time_line(out.rounds);
                const double fits =
                    std::floor((kTimeShare * seconds_left() - line.setup) / line.per_sample);
                if (fits < next) next = fits >= 1.25 * spp ? static_cast<int>(fits) : 0;
            }
        }
        spp = options.mpi ? options.mpi->leaders(next) : next;
    }
    return out;
}

}  // namespace drt
