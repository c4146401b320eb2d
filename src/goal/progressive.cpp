#include "drt/goal/progressive.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <numeric>
#include <span>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "drt/util/rng.h"

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
// The slope a round smaller than the largest is extrapolated along (toward fewer samples): the
// true RMSE of the thesis scenes' stratified renders at --scale 0.1 falls along -0.60 (Test2)
// to -0.83 (Test4) from 2 to 8 spp, where these small rounds lie; -1, taken before, assumed a
// steeper rise than any scene's and so sized them larger than needed (docs/accuracy-history.md).
constexpr double kSmallRoundSlope = -0.75;
// The first full round after a pilot of some pixels aims at this share of the target, and toward
// more samples than the pilot's along kPilotSlope (toward fewer along kSmallRoundSlope, as any
// smaller round): the pilot's estimate scatters a little more than a full round's (0.82-1.14 of
// the true RMSE on Test2, Test4 and Test5 at --scale 0.25 with 1,200 pixels and 20 seeds, the
// full render's own 0.86-1.12), and a full round that falls short is made up by a second
// pattern, now mostly a top-up of some pixels (plan_top_up), which costs little. -0.8 is
// steeper than the thesis scenes' estimated slopes from 8 to 32 spp at 200 x 150 and 400 x 300
// (-0.51 to -0.75), so the round errs on the short side: along -0.65 or -0.7 the rounds that
// land overshoot by about what the second rounds they spared cost, along -0.9 more of them miss
// (the samples' geometric means within 4 % of -0.8's; measured before the top-ups). Measured
// against other shares, slopes and pilot sizes in docs/accuracy-history.md.
constexpr double kPilotSpareShare = 0.95;
constexpr double kPilotSlope = -0.8;
// Of the time left, what a round may be predicted to take: the rest absorbs the prediction's
// error.
constexpr double kTimeShare = 0.9;
// A round adds at least this share of the samples so far: a smaller one is not worth its
// set-up.
constexpr double kMinAddedShare = 0.1;
// The fewest samples of a round with an error estimate.
constexpr int kMinRound = 2;
// Keeps round_seed's streams apart from other hashes of the seed.
constexpr std::uint64_t kRoundStream = 0x726f756e64ULL;

// The image's estimated RMSE, where the render can estimate it.
std::optional<double> estimated_error(const RenderResult& r) {
    return r.stats.error.rmse;
}

struct Line {
    double setup = 0, per_sample = 0;
};

// Seconds against samples per image pixel through the last two rounds; set-up and a cost per
// sample, neither negative, so a noisy pair of times never predicts a free sample. After a pilot
// of some pixels, its own set-up and the rest of its time: at 400 x 300 its set-up is a quarter
// of its time, and counted as samples it predicted 1.6 times a full round's time.
Line time_line(std::vector<ProgressiveRound> rounds) {
    // A top-up's time is mostly its set-up: it says little of a full round's.
    std::erase_if(rounds, [](const ProgressiveRound& r) { return r.top_up(); });
    const ProgressiveRound& last = rounds.back();
    if (!last.full()) {
        const double setup = std::clamp(last.setup_seconds, 0.0, last.seconds);
        return {setup, (last.seconds - setup) / last.cost()};
    }
    Line line{0, last.seconds / last.cost()};
    if (rounds.size() < 2) return line;
    const ProgressiveRound& before = rounds[rounds.size() - 2];
    if (last.cost() <= before.cost()) return line;
    const double slope = (last.seconds - before.seconds) / (last.cost() - before.cost());
    const double setup = last.seconds - slope * last.cost();
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

// A top-up's pixel variance (two renders of m samples averaged) over the same pixel's at n
// samples: along kSmallRoundSlope below n, along kIndependentSlope above.
double top_up_variance_ratio(int n, int m) {
    const double slope = m < n ? kSmallRoundSlope : kIndependentSlope;
    return std::pow(double(m) / n, 2 * slope) / 2;
}

// A first top-up's recalibration of the pixels outside it, from a few hundred picked at random,
// stays within these factors: beyond, a few pixels' noise would decide it.
constexpr double kLeastRescale = 0.25;
constexpr double kMostRescale = 4;
// Keeps a top-up's choice of calibrating pixels apart from other hashes of the seed.
constexpr std::uint64_t kTopUpCalibrationStream = 0x746f7075ULL;

// A top-up's pixels picked at random to calibrate the others, and their odds.
struct Calibrating {
    std::span<const std::uint32_t> pixels;
    std::span<const double> odds;
};

// The rounds of a render to a target error added up: each pixel the mean of the rounds' values
// weighted by round_weight, and the variance of that mean, the rounds' variances (spread x
// scale) times their weights squared. Sums in double, in round order: the same bits however the
// rounds were rendered.
class Combination {
  public:
    Combination(int width, int height)
        : width_(width),
          height_(height),
          sum_(3 * std::size_t(width) * height),
          variance_(sum_.size()),
          weights_(sum_.size() / 3) {}

    void add(const RenderResult& r, int spp) {
        const double scale = r.stats.error.available() ? r.stats.error.scale : 0;
        const double weight = round_weight(r.stats.error.rmse, spp);
        for (std::size_t i = 0; i < sum_.size(); ++i) {
            sum_[i] += weight * r.image.rgb[i];
            variance_[i] += weight * weight * scale * r.spread.rgb[i];
        }
        for (double& w : weights_) w += weight;
        samples_ += spp;
        last_spp_ = spp;
        last_variance_.resize(sum_.size());
        for (std::size_t i = 0; i < sum_.size(); ++i) last_variance_[i] = scale * r.spread.rgb[i];
        count(r);
        calibration_ += r.stats.error.cost * double(r.stats.samples);
        if (!r.stats.error.available()) unavailable_ = r.stats.error.unavailable;
    }

    // A top-up round of `spp` samples twice on `topped` and `calibrating` (its pixels' spreads
    // the variance of their means, RenderContext). On each of the two sets its weight against the
    // rounds before is the ratio of their mean variance there to its own: one weight for all of
    // a set, which no pixel's own samples decide. Where it has no variance to weigh by, along
    // top_up_variance_ratio. The first top-up of the last full round's count also recalibrates
    // the rounds' estimate (recalibrate).
    void add_top_up(const RenderResult& r, int spp, std::span<const std::uint32_t> topped,
                    const Calibrating& calibrating) {
        if (!recalibrated_ && spp == last_spp_) {
            recalibrate(r, topped, calibrating);
            recalibrated_ = true;
        }
        combine(r, spp, topped);
        combine(r, spp, calibrating.pixels);
        count(r);
    }

    // The estimated variance of the mean of two renders of `spp` samples, per pixel and channel:
    // the last full round's (recalibrated) times top_up_variance_ratio.
    Image pair_variance(int spp) const {
        Image out(width_, height_);
        const double ratio = top_up_variance_ratio(last_spp_, spp);
        for (std::size_t i = 0; i < last_variance_.size(); ++i) {
            out.rgb[i] = static_cast<float>(last_variance_[i] * ratio);
        }
        return out;
    }

    // The image so far, with `last`'s plan and per-process figures.
    RenderResult result(const RenderResult& last) const {
        RenderResult out;
        out.plan = last.plan;
        out.stats = stats_;
        out.stats.threads = last.stats.threads;
        out.stats.processes = last.stats.processes;
        out.stats.tail_seconds = last.stats.tail_seconds;
        out.image = Image(width_, height_);
        out.spread = Image(width_, height_);
        for (std::size_t i = 0; i < sum_.size(); ++i) {
            const double n = weights_[i / 3];
            out.image.rgb[i] = static_cast<float>(sum_[i] / n);
            out.spread.rgb[i] = static_cast<float>(variance_[i] / (n * n));
        }
        if (unavailable_.empty()) {
            out.stats.error = estimate_error(out.image, out.spread, ErrorSums{}, stats_.samples,
                                             samples_, SpreadKind::kIndependent);
            out.stats.error.cost = stats_.samples > 0 ? calibration_ / stats_.samples : 0;
        } else {
            out.stats.error.unavailable = unavailable_;
        }
        return out;
    }

  private:
    // A full round's calibration is one scale for the whole image: right for the image's sum, but
    // the spreads that share it out overstate the error where it is largest, where a top-up goes,
    // and understate it elsewhere (on the thesis scenes at 400 x 300, 1.24-1.37 times the true
    // variance over the top-up's pixels of Test1, Test2 and Test5, 0.75-0.96 over the others),
    // and the scale itself is off by the calibration's noise (at 200 x 150 a 43-spp round of
    // Test2 estimated 0.91 of its true RMSE). Once a top-up has taken off most of the error where
    // it is largest, the estimate would be mostly what the scale says of the rest, and off by
    // more than the round's own. A top-up of the last full round's count measures that round's
    // true variance directly, from its pairs: on its pixels, and on `calibrating`, pixels picked
    // at random among the others. Each set's sum over the last round's estimate there scales
    // the rounds' estimate: on the top-up's pixels, and (from `calibrating`) everywhere else.
    void recalibrate(const RenderResult& r, std::span<const std::uint32_t> topped,
                     const Calibrating& calibrating) {
        const auto measured = [&](std::span<const std::uint32_t> pixels,
                                  std::span<const double> odds) {
            double pairs = 0, estimated = 0;
            for (std::size_t i = 0; i < pixels.size(); ++i) {
                const double weight = odds.empty() ? 1 : 1 / odds[i];
                const std::size_t p = pixels[i];
                for (std::size_t c = 3 * p; c < 3 * p + 3; ++c) {
                    // One render's variance, not the pair's mean's.
                    pairs += weight * 2 * double(r.spread.rgb[c]);
                    estimated += weight * last_variance_[c];
                }
            }
            return estimated > 0 && std::isfinite(pairs) ? pairs / estimated : 1.0;
        };
        const double inside = measured(topped, {});
        const double outside =
            std::clamp(measured(calibrating.pixels, calibrating.odds), kLeastRescale, kMostRescale);
        std::vector<bool> in(weights_.size(), false);
        for (const std::uint32_t p : topped) in[p] = true;
        for (std::size_t c = 0; c < variance_.size(); ++c) {
            variance_[c] *= in[c / 3] ? inside : outside;
            last_variance_[c] *= in[c / 3] ? inside : outside;
        }
    }

    void combine(const RenderResult& r, int spp, std::span<const std::uint32_t> pixels) {
        double before = 0, own = 0;
        for (const std::uint32_t p : pixels) {
            for (std::size_t c = 3 * std::size_t(p); c < 3 * std::size_t(p) + 3; ++c) {
                before += variance_[c] / (weights_[p] * weights_[p]);
                own += r.spread.rgb[c];
            }
        }
        const bool estimated = own > 0 && before > 0 && std::isfinite(own);
        const double predicted = top_up_variance_ratio(samples_, spp);
        const double ratio = estimated ? before / own : 1 / predicted;
        for (const std::uint32_t p : pixels) {
            const double weight = ratio * weights_[p];
            for (std::size_t c = 3 * std::size_t(p); c < 3 * std::size_t(p) + 3; ++c) {
                const double variance =
                    estimated ? double(r.spread.rgb[c])
                              : predicted * variance_[c] / (weights_[p] * weights_[p]);
                sum_[c] += weight * r.image.rgb[c];
                variance_[c] += weight * weight * variance;
            }
            weights_[p] += weight;
        }
    }

    void count(const RenderResult& r) {
        stats_.rays += r.stats.rays;
        stats_.samples += r.stats.samples;
        stats_.seconds += r.stats.seconds;
    }

    int width_, height_;
    std::vector<double> sum_, variance_;  // per channel: sum of weight x value, weight^2 x variance
    std::vector<double> weights_;         // per pixel
    int last_spp_ = 0;                    // the last full round's count
    std::vector<double> last_variance_;   // and its estimated variance, per channel
    bool recalibrated_ = false;
    int samples_ = 0;
    RenderStats stats_;
    double calibration_ = 0;   // camera samples the rounds' calibrations took
    std::string unavailable_;  // why a round had no estimate
};

// The calibration share of the last full round; 0 before one.
double full_round_calibration(const std::vector<ProgressiveRound>& rounds) {
    const auto last = std::find_if(rounds.rbegin(), rounds.rend(),
                                   [](const ProgressiveRound& r) { return r.full(); });
    return last == rounds.rend() ? 0 : last->calibration;
}

}  // namespace

double predicted_seconds(const std::vector<ProgressiveRound>& rounds, int spp) {
    if (rounds.empty()) return 0;
    const Line line = time_line(rounds);
    return line.setup + line.per_sample * spp * (1 + full_round_calibration(rounds));
}

std::vector<std::uint32_t> TopUp::rendered() const {
    std::vector<std::uint32_t> all = pixels;
    all.insert(all.end(), calibration.begin(), calibration.end());
    std::sort(all.begin(), all.end());
    return all;
}

std::optional<TopUp> plan_top_up(const Image& variance, const Image& pair_variance, int spp,
                                 double goal, std::optional<std::uint64_t> calibration_seed,
                                 std::size_t most_pixels) {
    const auto width = static_cast<std::size_t>(variance.width);
    const auto height = static_cast<std::size_t>(variance.height);
    const std::size_t count = width * height;
    if (count < kMinTopUpPixels || spp < kMinRound || pair_variance.width != variance.width ||
        pair_variance.height != variance.height) {
        return std::nullopt;
    }
    const auto mean = [](const Image& image, std::size_t i) {
        return (double(image.rgb[3 * i]) + image.rgb[3 * i + 1] + image.rgb[3 * i + 2]) / 3;
    };
    std::vector<double> v(count);
    double total = 0;
    for (std::size_t i = 0; i < count; ++i) {
        v[i] = mean(variance, i);
        total += v[i];
    }
    const double need = total - goal * goal * double(count);
    if (!(need > 0) || !std::isfinite(total)) return std::nullopt;
    std::vector<double> around(count, 0.0);
    for (std::size_t y = 0; y < height; ++y) {
        for (std::size_t x = 0; x < width; ++x) {
            double& most = around[y * width + x];
            for (std::size_t ny = y == 0 ? 0 : y - 1; ny <= std::min(y + 1, height - 1); ++ny) {
                for (std::size_t nx = x == 0 ? 0 : x - 1; nx <= std::min(x + 1, width - 1); ++nx) {
                    if (nx != x || ny != y) most = std::max(most, v[ny * width + nx]);
                }
            }
        }
    }
    std::vector<std::uint32_t> order(count);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return around[a] > around[b]; });
    // Two estimates combined by inverse variance take v^2 / (v + t) off a pixel's v.
    std::size_t taken = 0;
    double made = 0;
    const std::size_t most = std::min(count, most_pixels);
    for (; taken < most && made < need; ++taken) {
        const std::uint32_t p = order[taken];
        const double t = mean(pair_variance, p);
        made += v[p] + t > 0 ? v[p] * v[p] / (v[p] + t) : 0;
    }
    if (made < need && (taken == count || taken < kMinTopUpPixels)) return std::nullopt;
    TopUp plan{spp, {}, {}, {}};
    taken = std::max(taken, kMinTopUpPixels);
    plan.pixels.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(taken));
    std::sort(plan.pixels.begin(), plan.pixels.end());
    if (calibration_seed && taken < count) {
        // Odds a quarter shared equally and the rest in proportion to the neighbours' largest
        // variance (not the pixel's own: its pairs then stay unbiased), so that the pixels that
        // hold the error are calibrated most often, weighted by 1 / odds.
        std::vector<bool> topped(count, false);
        for (const std::uint32_t p : plan.pixels) topped[p] = true;
        double rest = 0;
        for (std::size_t i = 0; i < count; ++i) rest += topped[i] ? 0 : around[i];
        const double wanted = std::min(kTopUpCalibrationPixels, double(count) / 16);
        const double others = double(count - taken);
        for (std::uint32_t p = 0; p < count; ++p) {
            if (topped[p]) continue;
            const double share = rest > 0 ? 0.25 / others + 0.75 * around[p] / rest : 1 / others;
            const double odds = std::min(1.0, wanted * share);
            if (to_unit(hash_of(*calibration_seed, kTopUpCalibrationStream, std::uint64_t{p})) <
                odds) {
                plan.calibration.push_back(p);
                plan.calibration_odds.push_back(odds);
            }
        }
    }
    return plan;
}

int pilot_block(int width, int height) {
    const auto b = static_cast<int>(std::sqrt(double(width) * height / kPilotPixels));
    return b < kMinPilotBlock ? 1 : std::min(b, kMaxPilotBlock);
}

std::uint64_t round_seed(std::uint64_t seed, std::size_t round) {
    return round == 0 ? seed : hash_of(seed, kRoundStream, std::uint64_t{round});
}

double round_weight(const std::optional<double>& error, int spp) {
    return error && *error > 0 && std::isfinite(*error) ? 1 / (*error * *error) : spp;
}

int total_samples(const std::vector<ProgressiveRound>& rounds) {
    int total = 0;
    for (const ProgressiveRound& r : rounds) total += r.full() ? r.spp : 0;
    return total;
}

std::optional<Prediction> predict(const std::vector<ProgressiveRound>& rounds, double target,
                                  int max_samples, double steepest) {
    // The image's estimate so far; none before the first full round.
    std::optional<double> now;
    bool image = false;
    for (const ProgressiveRound& r : rounds) {
        if (r.full() || r.top_up()) {
            image = true;
            now = r.combined;
        }
    }
    // A pilot of some pixels only until a full round measures the image: its estimate scatters
    // more, and a slope from it to a full round's would carry that scatter (30 % low, a slope of
    // -0.29 and a last round 3 times too large on a soft-shadow scene at 128 x 128).
    std::vector<const ProgressiveRound*> measured;
    for (const ProgressiveRound& r : rounds) {
        if (r.full() == image && r.error && *r.error > 0 && std::isfinite(*r.error)) {
            measured.push_back(&r);
        }
    }
    if (measured.empty() || (image && !now)) return std::nullopt;
    // The largest round's error is the least noisy to extrapolate from, and the largest of
    // those at most a kMinSlopeSpan-th of its count gives the slope: over a narrower span the
    // errors' noise decides it. Stable sorts keep the latest of equal counts last.
    std::stable_sort(measured.begin(), measured.end(),
                     [](const auto* x, const auto* y) { return x->spp < y->spp; });
    const ProgressiveRound& b = *measured.back();
    double slope = steepest;
    const auto a = std::find_if(measured.rbegin() + 1, measured.rend(),
                                [&](const auto* r) { return r->spp * kMinSlopeSpan <= b.spp; });
    if (a != measured.rend()) {
        slope = std::clamp(std::log(*b.error / *(*a)->error) / std::log(double(b.spp) / (*a)->spp),
                           steepest, -0.25);
    }
    const double total = total_samples(rounds);
    const double left = max_samples - total;
    if ((now && *now <= target) || left < kMinRound) return Prediction{0, 0};
    // Rounds weighted by the inverse of their estimated variance combine to 1 / c^2, the sum of
    // 1 / e^2 over the rounds: the next reaches the goal with the error `wanted`.
    // The first full round after a pilot of some pixels: see kPilotSpareShare.
    if (!image && a == measured.rend()) slope = kPilotSlope;
    const double goal = (image ? kSpareShare : kPilotSpareShare) * target;
    const double wanted = now ? 1 / std::sqrt(1 / (goal * goal) - 1 / (*now * *now)) : goal;
    // Along the slope from b's error, or for a round smaller than b's along kSmallRoundSlope,
    // whatever the slope measured above it: a pattern's gain over independent samples is smallest
    // at few samples, yet a stratified pixel's error still rises steeper than 1 / sqrt(n) below
    // 8 samples.
    const double n =
        b.spp * std::pow(wanted / *b.error, 1 / (wanted >= *b.error ? kSmallRoundSlope : slope));
    const double hi = std::min(std::ceil(n), left);
    const int count = static_cast<int>(std::max<double>(hi, kMinRound));
    return Prediction{count, predicted_seconds(rounds, count)};
}

NextRound next_round(const std::vector<ProgressiveRound>& rounds, double target, int max_samples) {
    const ProgressiveRound& last = rounds.back();
    const int total = total_samples(rounds);
    const int left = max_samples - total;
    if ((last.combined && *last.combined <= target) || left < kMinRound) return {};
    // After a round meant as the last that missed, no slope steeper than -1/2: the errors' curves
    // flatten with samples (a pattern's gain over independent samples shrinks), so the slope
    // that led there was too steep.
    const std::vector<ProgressiveRound> before(rounds.begin(), rounds.end() - 1);
    const bool missed = !before.empty() && next_round(before, target, max_samples).final;
    const auto p = predict(rounds, target, max_samples, missed ? kIndependentSlope : -1.0);
    NextRound next{p ? p->spp : kMinPilotGrowth * last.spp, p.has_value()};
    if (next.spp > kFinalStep * last.spp) {
        next = {std::max((next.spp + kFinalStep - 1) / kFinalStep, kMinPilotGrowth * last.spp),
                false};
    }
    next.spp = std::max<int>(next.spp, static_cast<int>(std::ceil(kMinAddedShare * total)));
    next.spp = std::clamp(next.spp, kMinRound, left);
    return next;
}

ProgressiveResult render_progressively(Scene& scene, const RenderJobOptions& options,
                                       const ProgressiveGoal& goal) {
    const SettingsGuard guard(scene);
    const std::uint64_t seed = scene.settings.seed;
    const bool leader = options.mpi == nullptr || options.mpi->leader();
    const auto seconds_left = [&] {
        return *goal.time_limit - std::chrono::duration<double>(Clock::now() - goal.start).count();
    };
    ProgressiveResult out;
    out.combined = goal.target_error.has_value();
    std::optional<Combination> combination;
    // A pilot of some pixels first, where the image is large enough; never under a time limit
    // alone, whose rounds replace one another.
    int block = out.combined && goal.max_samples >= kFirstPilot
                    ? pilot_block(scene.settings.width, scene.settings.height)
                    : 1;
    std::size_t full_rounds = 0;
    int spp = std::min(kFirstPilot, goal.max_samples);
    std::vector<std::uint32_t> top_up;  // a top-up round's pixels, on every process
    std::optional<TopUp> planned;       // and what they are for, on the leader
    while (spp > 0) {
        scene.settings.samples = spp;
        if (out.combined) scene.settings.seed = round_seed(seed, full_rounds);
        // Dropped when the budget runs out before it is done, except the first full round:
        // without it there would be no image at all.
        std::stop_source stopper;
        const std::stop_callback relay(options.stop, [&] { stopper.request_stop(); });
        std::optional<Alarm> alarm;
        if (goal.time_limit && leader && full_rounds > 0) {
            alarm.emplace(goal.start + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(*goal.time_limit)),
                          stopper);
        }
        RenderJobOptions run = options;
        run.stop = stopper.get_token();
        run.pixel_block = block;
        run.top_up = top_up;
        // Ordering a pilot's tiles by cost would trace a sixteenth of a sample in every pixel:
        // a fifth of what the pilot itself traces at one pixel in 25. A top-up's likewise.
        run.costly_first = options.costly_first && block == 1 && top_up.empty();
        RenderJobResult job = run_render_job(scene, run);
        alarm.reset();
        int next = 0;
        std::optional<TopUp> next_plan;             // the next round's, when a top-up
        std::optional<std::uint64_t> planned_seed;  // its calibrating pixels' seed
        int full_next = 0;                          // the full round a top-up replaces
        if (!leader) {
            if (block == 1) out.job = std::move(job);
        } else if (!job.complete()) {
            out.stopped = options.stop.stop_requested();
            if (full_rounds == 0) out.job = std::move(job);
        } else {
            const RenderStats& stats = job.render.stats;
            ProgressiveRound done{
                spp,   stats.seconds,    estimated_error(job.render), std::nullopt,
                block, stats.error.cost, stats.setup_seconds};
            const auto image_pixels = std::size_t(job.render.image.width) * job.render.image.height;
            if (!top_up.empty()) {
                done.top_up_share = double(top_up.size()) / double(image_pixels);
                done.calibration = 1;
            }
            // A pilot of some pixels is measured, not kept.
            if (done.full() || done.top_up()) {
                if (out.combined) {
                    if (!combination)
                        combination.emplace(job.render.image.width, job.render.image.height);
                    if (done.top_up()) {
                        combination->add_top_up(job.render, spp, planned->pixels,
                                                {planned->calibration, planned->calibration_odds});
                    } else {
                        combination->add(job.render, spp);
                    }
                    job.render = combination->result(job.render);
                }
                done.combined = estimated_error(job.render);
                out.job = std::move(job);
                out.error = done.combined;
                out.target_met =
                    goal.target_error && done.combined && *done.combined <= *goal.target_error;
            }
            out.rounds.push_back(done);
            out.samples = out.combined ? total_samples(out.rounds) : spp;
            if (goal.target_error) {
                const NextRound n = next_round(out.rounds, *goal.target_error, goal.max_samples);
                next = n.final && goal.pilots_only ? 0 : n.spp;
                // A final round that would only make up a near miss: where a few pixels carry
                // most of the shortfall, a top-up of those costs less than a whole round.
                if (next > 0 && n.final && combination) {
                    const int total = total_samples(out.rounds);
                    const auto last = std::find_if(out.rounds.rbegin(), out.rounds.rend(),
                                                   [](const auto& r) { return r.full(); });
                    const int count = std::min(last->spp, (goal.max_samples - total) / 2);
                    // The first top-up of the last round's count also calibrates the pixels it
                    // leaves (Combination), picked with the seed the top-up renders with.
                    const bool first = count == last->spp &&
                                       std::none_of(out.rounds.begin(), out.rounds.end(),
                                                    [](const auto& r) { return r.top_up(); });
                    planned_seed =
                        first ? std::optional(round_seed(seed, full_rounds + 1)) : std::nullopt;
                    std::optional<TopUp> t =
                        plan_top_up(out.job.render.spread, combination->pair_variance(count), count,
                                    kSpareShare * *goal.target_error, planned_seed);
                    if (t &&
                        t->cost(image_pixels) < next * (1 + full_round_calibration(out.rounds))) {
                        next = t->spp;
                        full_next = n.spp;
                        next_plan = std::move(t);
                    }
                }
            } else if (spp < goal.max_samples) {
                next = static_cast<int>(std::min(kMaxGrowth * spp, double(goal.max_samples)));
            }
            if (goal.time_limit && next > 0) {
                const Line line = time_line(out.rounds);
                const double fits =
                    std::floor((kTimeShare * seconds_left() - line.setup) / line.per_sample /
                               (1 + full_round_calibration(out.rounds)));
                // Combined rounds: whatever fits adds samples. A round replacing the last: only
                // one a quarter larger is worth its time. After a pilot, the first full round
                // whatever the time: the image.
                const double least = out.combined ? kMinRound : 1.25 * spp;
                // A top-up that does not fit takes the pixels that do, first in its order, if
                // they are enough; otherwise a full round as large as fits.
                const double affordable = fits * (1 + full_round_calibration(out.rounds));
                if (next_plan && next_plan->cost(image_pixels) > affordable) {
                    const double pixels = affordable * double(image_pixels) / (2.0 * next) -
                                          double(next_plan->calibration.size());
                    next_plan =
                        pixels >= double(kMinTopUpPixels)
                            ? plan_top_up(out.job.render.spread, combination->pair_variance(next),
                                          next, kSpareShare * *goal.target_error, planned_seed,
                                          static_cast<std::size_t>(pixels))
                            : std::nullopt;
                    if (!next_plan) next = full_next;
                }
                if (!next_plan && fits < next) {
                    next = fits >= least ? static_cast<int>(fits) : 0;
                }
                if (done.pixel_block > 1) next = std::max(next, kMinRound);
            }
        }
        spp = options.mpi ? options.mpi->leaders(next) : next;
        planned = std::move(next_plan);
        top_up = planned ? planned->rendered() : std::vector<std::uint32_t>{};
        if (options.mpi) top_up = options.mpi->leaders(std::move(top_up));
        if (block == 1) ++full_rounds;
        block = 1;
    }
    return out;
}

}  // namespace drt
