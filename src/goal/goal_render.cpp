#include "drt/goal/goal_render.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <numeric>
#include <span>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "drt/render/error_estimate.h"
#include "drt/render/render_context.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

using Clock = std::chrono::steady_clock;

// Under a time budget, a round's count at most this many times the last one's: an
// extrapolation over a wider span is too uncertain to bet the whole budget on.
constexpr double kMaxGrowth = 16;
// An intermediate round at least this many times the last round's count: a narrower span
// measures no slope.
constexpr int kMinIntermediateGrowth = 4;
// A slope only from rounds at least this many times apart: a narrower span measures noise.
constexpr int kMinSlopeSpan = 3;
// The error's log-log slope against samples for independent samples.
constexpr double kIndependentSlope = -0.5;
// The slope a round smaller than the largest is extrapolated along (toward fewer samples): a
// stratified pixel's error still rises steeper than 1 / sqrt(n) at few samples, but less steeply
// than -1.
constexpr double kSmallRoundSlope = -0.75;
// The first full round after a pilot aims at this share of the target, and toward more samples
// than the pilot's along kPilotSlope: the pilot's estimate scatters a little more than a full
// round's, and a steep slope errs on the short side, which a top-up makes up cheaply.
constexpr double kPilotSpareShare = 0.95;
constexpr double kPilotSlope = -0.8;
// A time limit at least this long (seconds, some 32 years) sets no alarm: the steady clock's
// nanoseconds would overflow not far past it, putting the alarm in the past.
constexpr double kLongestAlarm = 1e9;
// Of the time left, what a round may be predicted to take: the rest absorbs the prediction's
// error.
constexpr double kTimeShare = 0.9;
// A round adds at least this share of the samples so far: a smaller one is not worth its time.
constexpr double kMinAddedShare = 0.1;
// The fewest samples of a round with an error estimate.
constexpr int kMinRound = 2;
// Keeps round_seed's streams apart from other hashes of the seed.
constexpr std::uint64_t kRoundStream = 0x726f756e64ULL;

struct Line {
    double setup = 0, per_sample = 0;
};

// Seconds against samples per image pixel through the last two rounds; set-up and a cost per
// sample, neither negative, so a noisy pair of times never predicts a free sample. After a pilot
// alone, its own set-up and the rest of its time: counted as samples, a pilot's fixed costs
// would predict too slow a full round.
Line time_line(std::vector<GoalRound> rounds) {
    // A top-up's time is mostly its fixed costs: it says little of a full round's.
    std::erase_if(rounds, [](const GoalRound& r) { return r.top_up(); });
    const GoalRound& last = rounds.back();
    if (!last.full()) {
        const double setup = std::clamp(last.setup_seconds, 0.0, last.seconds);
        return {setup, (last.seconds - setup) / last.cost()};
    }
    Line line{0, last.seconds / last.cost()};
    if (rounds.size() < 2) return line;
    const GoalRound& before = rounds[rounds.size() - 2];
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

// A first top-up's rescaling of the estimate outside it, from a few hundred spot checks, stays
// within these factors: beyond, a few pixels' noise would decide it.
constexpr double kLeastRescale = 0.25;
constexpr double kMostRescale = 4;
// Keeps a top-up's choice of spot checks apart from other hashes of the seed.
constexpr std::uint64_t kSpotCheckStream = 0x746f7075ULL;

// A top-up's spot checks and their odds.
struct SpotChecks {
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
        estimate_samples_ += r.stats.error.cost * double(r.stats.samples);
        if (!r.stats.error.available()) unavailable_ = r.stats.error.unavailable;
    }

    // A top-up round of `spp` samples twice on `topped` and `spot_checks` (its pixels' spreads
    // the variance of their means, RenderRequest::paired). On each of the two sets its weight
    // against the rounds before is the ratio of their mean variance there to its own: one weight
    // for all of a set, which no pixel's own samples decide. Where it has no variance to weigh by,
    // along top_up_variance_ratio. The first top-up of the last full round's count also rescales
    // the rounds' estimate (rescale_estimate).
    void add_top_up(const RenderResult& r, int spp, std::span<const std::uint32_t> topped,
                    const SpotChecks& spot_checks) {
        if (!rescaled_ && spp == last_spp_) {
            rescale_estimate(r, topped, spot_checks);
            rescaled_ = true;
        }
        combine(r, spp, topped);
        combine(r, spp, spot_checks.pixels);
        count(r);
    }

    // The estimated variance of the mean of two renders of `spp` samples, per pixel and channel:
    // the last full round's (rescaled) times top_up_variance_ratio.
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
            out.stats.error.cost = stats_.samples > 0 ? estimate_samples_ / stats_.samples : 0;
        } else {
            out.stats.error.unavailable = unavailable_;
        }
        return out;
    }

  private:
    // A full round's calibration is one scale for the whole image: right for the image's sum, but
    // the spreads that share it out overstate the error where it is largest, where a top-up goes,
    // and understate it elsewhere, and the scale itself is off by the calibration's noise. A
    // top-up of the last full round's count measures that round's true variance directly, from
    // its pairs: each set's (the top-up's pixels, the spot checks) sum over the last round's
    // estimate there rescales the rounds' estimate on the top-up's pixels and everywhere else.
    void rescale_estimate(const RenderResult& r, std::span<const std::uint32_t> topped,
                          const SpotChecks& spot_checks) {
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
            std::clamp(measured(spot_checks.pixels, spot_checks.odds), kLeastRescale, kMostRescale);
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
        stats_.photons += r.stats.photons;
        stats_.samples += r.stats.samples;
        stats_.seconds += r.stats.seconds;
    }

    int width_, height_;
    std::vector<double> sum_, variance_;  // per channel: sum of weight x value, weight^2 x variance
    std::vector<double> weights_;         // per pixel
    int last_spp_ = 0;                    // the last full round's count
    std::vector<double> last_variance_;   // and its estimated variance, per channel
    bool rescaled_ = false;
    int samples_ = 0;
    RenderStats stats_;
    double estimate_samples_ = 0;  // camera samples the rounds' estimates took
    std::string unavailable_;      // why a round had no estimate
};

// The estimate cost of the last full round; 0 before one.
double full_round_estimate_cost(const std::vector<GoalRound>& rounds) {
    const auto last =
        std::find_if(rounds.rbegin(), rounds.rend(), [](const GoalRound& r) { return r.full(); });
    return last == rounds.rend() ? 0 : last->estimate_cost;
}

}  // namespace

double predicted_seconds(const std::vector<GoalRound>& rounds, int spp) {
    if (rounds.empty()) return 0;
    const Line line = time_line(rounds);
    return line.setup + line.per_sample * spp * (1 + full_round_estimate_cost(rounds));
}

std::vector<std::uint32_t> TopUp::rendered() const {
    std::vector<std::uint32_t> all = pixels;
    all.insert(all.end(), spot_checks.begin(), spot_checks.end());
    std::sort(all.begin(), all.end());
    return all;
}

namespace {

// The mean of a pixel's three channels.
double channel_mean(const Image& image, std::size_t i) {
    return (double(image.rgb[3 * i]) + image.rgb[3 * i + 1] + image.rgb[3 * i + 2]) / 3;
}

// Adds to `plan` its spot checks: pixels outside it, each picked by a hash of `seed` with
// pick_odds by `around` (the largest variance among its neighbours, not its own, so that its
// pairs stay unbiased), so that the pixels that hold the error are checked most often.
void pick_spot_checks(TopUp& plan, std::span<const double> around, std::uint64_t seed) {
    const std::size_t count = around.size();
    std::vector<bool> topped(count, false);
    for (const std::uint32_t p : plan.pixels) topped[p] = true;
    double rest = 0;
    for (std::size_t i = 0; i < count; ++i) rest += topped[i] ? 0 : around[i];
    const double wanted = std::min(kTopUpSpotChecks, double(count) / 16);
    const double others = double(count - plan.pixels.size());
    for (std::uint32_t p = 0; p < count; ++p) {
        if (topped[p]) continue;
        const double odds = rest > 0 ? pick_odds(wanted, 1 / others, around[p], rest)
                                     : std::min(1.0, wanted * (1 / others));
        if (to_unit(hash_of(seed, kSpotCheckStream, std::uint64_t{p})) < odds) {
            plan.spot_checks.push_back(p);
            plan.spot_check_odds.push_back(odds);
        }
    }
}

}  // namespace

std::optional<TopUp> plan_top_up(const Image& variance, const Image& pair_variance, int spp,
                                 double goal, std::optional<std::uint64_t> spot_check_seed,
                                 std::size_t most_pixels) {
    const std::size_t count = std::size_t(variance.width) * std::size_t(variance.height);
    if (count < kMinTopUpPixels || spp < kMinRound || pair_variance.width != variance.width ||
        pair_variance.height != variance.height) {
        return std::nullopt;
    }
    std::vector<double> v(count);
    double total = 0;
    for (std::size_t i = 0; i < count; ++i) {
        v[i] = channel_mean(variance, i);
        total += v[i];
    }
    const double need = total - goal * goal * double(count);
    if (!(need > 0) || !std::isfinite(total)) return std::nullopt;
    const std::vector<double> around =
        largest_around(v, variance.width, variance.height, Around::kNeighboursOnly);
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
        const double t = channel_mean(pair_variance, p);
        made += v[p] + t > 0 ? v[p] * v[p] / (v[p] + t) : 0;
    }
    if (made < need && (taken == count || taken < kMinTopUpPixels)) return std::nullopt;
    TopUp plan{spp, {}, {}, {}};
    taken = std::max(taken, kMinTopUpPixels);
    plan.pixels.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(taken));
    std::sort(plan.pixels.begin(), plan.pixels.end());
    if (spot_check_seed && taken < count) pick_spot_checks(plan, around, *spot_check_seed);
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

int total_samples(const std::vector<GoalRound>& rounds) {
    int total = 0;
    for (const GoalRound& r : rounds) total += r.full() ? r.spp : 0;
    return total;
}

int most_pixel_samples(const std::vector<GoalRound>& rounds) {
    int most = 0;
    for (const GoalRound& r : rounds) most += r.full() ? r.spp : r.top_up() ? 2 * r.spp : 0;
    return most;
}

std::optional<Prediction> predict(const std::vector<GoalRound>& rounds, double target,
                                  int max_samples, double steepest) {
    // The image's estimate so far; none before the first full round.
    std::optional<double> now;
    bool image = false;
    for (const GoalRound& r : rounds) {
        if (r.full() || r.top_up()) {
            image = true;
            now = r.combined;
        }
    }
    // A pilot only until a full round measures the image: its estimate scatters more, and a
    // slope from it to a full round's would carry that scatter.
    std::vector<const GoalRound*> measured;
    for (const GoalRound& r : rounds) {
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
    const GoalRound& b = *measured.back();
    double slope = steepest;
    const auto a = std::find_if(measured.rbegin() + 1, measured.rend(),
                                [&](const auto* r) { return r->spp * kMinSlopeSpan <= b.spp; });
    if (a != measured.rend()) {
        slope = std::clamp(std::log(*b.error / *(*a)->error) / std::log(double(b.spp) / (*a)->spp),
                           steepest, -0.25);
    }
    const double left = max_samples - most_pixel_samples(rounds);
    if ((now && *now <= target) || left < kMinRound) return Prediction{0, 0};
    // Rounds weighted by the inverse of their estimated variance combine to 1 / c^2, the sum of
    // 1 / e^2 over the rounds: the next reaches the goal with the error `wanted`.
    // The first full round after a pilot: see kPilotSpareShare.
    if (!image && a == measured.rend()) slope = kPilotSlope;
    const double goal = (image ? kSpareShare : kPilotSpareShare) * target;
    const double wanted = now ? 1 / std::sqrt(1 / (goal * goal) - 1 / (*now * *now)) : goal;
    // Along the slope from b's error, or for a round smaller than b's along kSmallRoundSlope,
    // whatever the slope measured above it.
    const double n =
        b.spp * std::pow(wanted / *b.error, 1 / (wanted >= *b.error ? kSmallRoundSlope : slope));
    const double hi = std::min(std::ceil(n), left);
    const int count = static_cast<int>(std::max<double>(hi, kMinRound));
    return Prediction{count, predicted_seconds(rounds, count)};
}

NextRound next_round(const std::vector<GoalRound>& rounds, double target, int max_samples) {
    const GoalRound& last = rounds.back();
    const int total = total_samples(rounds);
    const int left = max_samples - most_pixel_samples(rounds);
    if ((last.combined && *last.combined <= target) || left < kMinRound) return {};
    // An image whose rounds give no estimate (too few pixels to calibrate, radiance past the
    // floats) cannot be judged against the target: more samples would only be guesses. (Pilots
    // come first, so a last round that is no pilot is the image's.)
    if (last.kind != RoundKind::kPilot && !last.combined) return {};
    // After a round meant as the last that missed, no slope steeper than -1/2: the errors' curves
    // flatten with samples (a pattern's gain over independent samples shrinks), so the slope
    // that led there was too steep.
    const std::vector<GoalRound> before(rounds.begin(), rounds.end() - 1);
    const bool missed = !before.empty() && next_round(before, target, max_samples).final;
    const auto p = predict(rounds, target, max_samples, missed ? kIndependentSlope : -1.0);
    NextRound next{p ? p->spp : kMinIntermediateGrowth * last.spp, p.has_value()};
    if (next.spp > kFinalStep * last.spp) {
        next = {
            std::max((next.spp + kFinalStep - 1) / kFinalStep, kMinIntermediateGrowth * last.spp),
            false};
    }
    next.spp = std::max<int>(next.spp, static_cast<int>(std::ceil(kMinAddedShare * total)));
    next.spp = std::clamp(next.spp, kMinRound, left);
    return next;
}

namespace {

// A round as every process renders it.
struct RoundPlan {
    RoundKind kind = RoundKind::kFull;
    int spp = 0;  // 0: no more rounds
    std::uint64_t seed = 0;
    int pixel_block = 1;                // a pilot's
    std::vector<std::uint32_t> listed;  // a top-up's pixels, spot checks included
};

// The next round as the leader decides it: a full round of `spp`, or `top_up` in its place.
struct NextPlan {
    int spp = 0;
    std::optional<TopUp> top_up;
    std::optional<std::uint64_t> spot_check_seed;
    int full_spp = 0;  // the full round a top-up replaces
};

// One render to a goal: the scene set up once, the rounds so far and, on the leader, their
// combination.
class GoalRender {
  public:
    GoalRender(const Scene& scene, const RenderJobOptions& options, const RenderGoal& goal)
        : context_(scene),
          options_(options),
          goal_(goal),
          seed_(scene.settings.seed),
          leader_(options.mpi == nullptr || options.mpi->leader()) {
        out_.combined = goal.target_error.has_value();
    }

    GoalResult run() {
        RoundPlan round = first_round();
        while (round.spp > 0) {
            RenderJobResult job = render(round);
            if (leader_) traced_ += job.render.stats.rays;
            NextPlan next;
            if (!leader_) {
                if (round.kind != RoundKind::kPilot) out_.job = std::move(job);
            } else if (!job.complete()) {
                out_.stopped = options_.stop.stop_requested();
                if (image_rounds_ == 0) out_.job = std::move(job);
            } else {
                record(round, std::move(job));
                next = plan_next(out_.rounds.back());
            }
            round = share(std::move(next), round);
        }
        // Every ray traced, pilots and dropped rounds included, as a render's --stats counts.
        if (leader_) out_.job.render.stats.rays = traced_;
        return std::move(out_);
    }

  private:
    // A pilot where the image is large enough; never under a time limit alone, whose rounds
    // replace one another.
    RoundPlan first_round() const {
        const Scene& scene = context_.scene();
        const int block = out_.combined && goal_.max_samples >= kFirstRoundSpp
                              ? pilot_block(scene.settings.width, scene.settings.height)
                              : 1;
        return {block > 1 ? RoundKind::kPilot : RoundKind::kFull,
                std::min(kFirstRoundSpp, goal_.max_samples),
                seed_,
                block,
                {}};
    }

    static RenderRequest request_of(const RoundPlan& round) {
        RenderRequest request;
        request.samples = round.spp;
        request.seed = round.seed;
        if (round.kind == RoundKind::kPilot) {
            request.pixels = PixelChoice::kOnePerBlock;
            request.pixel_block = round.pixel_block;
        } else if (round.kind == RoundKind::kTopUp) {
            request.pixels = PixelChoice::kListed;
            request.listed = round.listed;
            request.paired = true;
        }
        return request;
    }

    // Stopped when the budget runs out before it is done, except the first full round: without
    // it there would be no image at all.
    RenderJobResult render(const RoundPlan& round) const {
        std::stop_source stopper;
        const std::stop_callback relay(options_.stop, [&] { stopper.request_stop(); });
        std::optional<Alarm> alarm;
        if (goal_.time_limit && *goal_.time_limit < kLongestAlarm && leader_ && image_rounds_ > 0) {
            alarm.emplace(goal_.start + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(*goal_.time_limit)),
                          stopper);
        }
        RenderJobOptions run = options_;
        run.stop = stopper.get_token();
        // Ordering a pilot's or a top-up's tiles by cost would probe every pixel for a few.
        run.costly_first = options_.costly_first && round.kind == RoundKind::kFull;
        return run_render_job(context_, request_of(round), run);
    }

    // The leader's record of a complete round; a full round or a top-up joins the image.
    void record(const RoundPlan& round, RenderJobResult job) {
        const RenderStats& stats = job.render.stats;
        GoalRound done{.spp = round.spp,
                       .seconds = stats.seconds,
                       .error = stats.error.rmse,
                       .combined = std::nullopt,
                       .kind = round.kind,
                       .pixel_block = round.pixel_block,
                       .estimate_cost = stats.error.cost,
                       .setup_seconds = stats.setup_seconds,
                       .top_up_share = 0,
                       .seed = round.seed};
        if (round.kind == RoundKind::kTopUp) {
            done.top_up_share = double(round.listed.size()) / double(image_pixels());
            // Paired: each pixel rendered twice, the second render for the estimate.
            done.estimate_cost = 1;
        }
        if (round.kind != RoundKind::kPilot) {
            if (out_.combined) combine(round, job.render);
            done.combined = job.render.stats.error.rmse;
            out_.job = std::move(job);
            out_.error = done.combined;
            out_.target_met =
                goal_.target_error && done.combined && *done.combined <= *goal_.target_error;
        }
        out_.rounds.push_back(done);
        out_.samples = out_.combined ? total_samples(out_.rounds) : round.spp;
    }

    // Adds the round to the combination; `render` becomes the rounds combined.
    void combine(const RoundPlan& round, RenderResult& render) {
        if (!combination_) combination_.emplace(render.image.width, render.image.height);
        if (round.kind == RoundKind::kTopUp) {
            combination_->add_top_up(render, round.spp, top_up_->pixels,
                                     {top_up_->spot_checks, top_up_->spot_check_odds});
        } else {
            combination_->add(render, round.spp);
        }
        render = combination_->result(render);
    }

    NextPlan plan_next(const GoalRound& done) const {
        NextPlan next;
        if (goal_.target_error) {
            next = toward_target();
        } else if (done.spp < goal_.max_samples) {
            next.spp = static_cast<int>(std::min(kMaxGrowth * done.spp, double(goal_.max_samples)));
        }
        if (goal_.time_limit && next.spp > 0) fit_to_time(next, done);
        return next;
    }

    // The round next_round sizes, or where it is final and a few pixels carry most of the
    // shortfall, a top-up of those where it costs less.
    NextPlan toward_target() const {
        const NextRound n = next_round(out_.rounds, *goal_.target_error, goal_.max_samples);
        NextPlan next{n.final && goal_.stop_before_final ? 0 : n.spp, {}, {}, 0};
        if (next.spp == 0 || !n.final || !combination_) return next;
        const auto last = std::find_if(out_.rounds.rbegin(), out_.rounds.rend(),
                                       [](const GoalRound& r) { return r.full(); });
        // A pixel may be in every top-up: together they keep it within the maximum.
        const int count =
            std::min(last->spp, (goal_.max_samples - most_pixel_samples(out_.rounds)) / 2);
        if (count < kMinRound) return next;
        // The first top-up of the last round's count also rescales the estimate outside it
        // (Combination), from spot checks picked with the seed the top-up renders with.
        const bool first =
            count == last->spp && std::none_of(out_.rounds.begin(), out_.rounds.end(),
                                               [](const GoalRound& r) { return r.top_up(); });
        next.spot_check_seed =
            first ? std::optional(round_seed(seed_, image_rounds_ + 1)) : std::nullopt;
        std::optional<TopUp> t =
            plan_top_up(out_.job.render.spread, combination_->pair_variance(count), count,
                        kSpareShare * *goal_.target_error, next.spot_check_seed);
        if (t && t->cost(image_pixels()) < next.spp * (1 + full_round_estimate_cost(out_.rounds))) {
            next.full_spp = n.spp;
            next.spp = t->spp;
            next.top_up = std::move(t);
        }
        return next;
    }

    // Cuts `next` to the time left: a top-up to the pixels that fit, first in its order, if
    // they are enough (otherwise the full round it replaced), a full round to the samples that
    // fit, or none.
    void fit_to_time(NextPlan& next, const GoalRound& done) const {
        const double seconds_left =
            *goal_.time_limit - std::chrono::duration<double>(Clock::now() - goal_.start).count();
        const Line line = time_line(out_.rounds);
        const double estimate = 1 + full_round_estimate_cost(out_.rounds);
        const double fits =
            std::floor((kTimeShare * seconds_left - line.setup) / line.per_sample / estimate);
        // Combined rounds: whatever fits adds samples. A round replacing the last: only one a
        // quarter larger is worth its time.
        const double least = out_.combined ? kMinRound : 1.25 * done.spp;
        const double affordable = fits * estimate;
        if (next.top_up && next.top_up->cost(image_pixels()) > affordable) {
            const double pixels = affordable * double(image_pixels()) / (2.0 * next.spp) -
                                  double(next.top_up->spot_checks.size());
            next.top_up =
                pixels >= double(kMinTopUpPixels)
                    ? plan_top_up(out_.job.render.spread, combination_->pair_variance(next.spp),
                                  next.spp, kSpareShare * *goal_.target_error, next.spot_check_seed,
                                  static_cast<std::size_t>(pixels))
                    : std::nullopt;
            if (!next.top_up) next.spp = next.full_spp;
        }
        if (!next.top_up && fits < next.spp) next.spp = fits >= least ? static_cast<int>(fits) : 0;
        // After a pilot, the first full round whatever the time: the image.
        if (done.kind == RoundKind::kPilot) next.spp = std::max(next.spp, kMinRound);
    }

    // The leader's decision on every process, as the round it makes.
    RoundPlan share(NextPlan next, const RoundPlan& last) {
        RoundPlan round;
        round.spp = options_.mpi ? options_.mpi->broadcast(next.spp) : next.spp;
        top_up_ = std::move(next.top_up);
        round.listed = top_up_ ? top_up_->rendered() : std::vector<std::uint32_t>{};
        if (options_.mpi) round.listed = options_.mpi->broadcast(std::move(round.listed));
        round.kind = round.listed.empty() ? RoundKind::kFull : RoundKind::kTopUp;
        if (last.kind != RoundKind::kPilot) ++image_rounds_;
        round.seed = out_.combined ? round_seed(seed_, image_rounds_) : seed_;
        return round;
    }

    std::size_t image_pixels() const {
        const RenderSettings& s = context_.scene().settings;
        return std::size_t(s.width) * std::size_t(s.height);
    }

    const RenderContext context_;
    const RenderJobOptions& options_;
    const RenderGoal& goal_;
    const std::uint64_t seed_;
    const bool leader_;
    GoalResult out_;
    std::optional<Combination> combination_;  // the leader's, for a target error
    // Rounds done but the pilots, top-ups included: the next one's round_seed.
    std::size_t image_rounds_ = 0;
    std::optional<TopUp> top_up_;  // the round in hand's, when a top-up (leader)
    RayCounts traced_;             // by every round so far (leader)
};

}  // namespace

GoalResult render_to_goal(const Scene& scene, const RenderJobOptions& options,
                          const RenderGoal& goal) {
    return GoalRender(scene, options, goal).run();
}

}  // namespace drt
