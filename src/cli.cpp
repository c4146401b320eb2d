#include "drt/cli.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "drt/atomic_file.h"
#include "drt/checkpoint.h"
#include "drt/compare.h"
#include "drt/converge.h"
#include "drt/error_estimate.h"
#include "drt/image.h"
#include "drt/interrupt.h"
#include "drt/limits.h"
#include "drt/mpi_work.h"
#include "drt/progressive.h"
#include "drt/render_job.h"
#include "drt/render_plan.h"
#include "drt/renderer.h"
#include "drt/report.h"
#include "drt/sampler.h"
#include "drt/scene_loader.h"
#include "drt/text.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

constexpr int kOk = 0;
constexpr int kFailed = 1;
constexpr int kBadInput = 2;
// A render stopped by SIGINT (or by --stop-after-tiles, which stands for one): 128 + 2.
constexpr int kInterrupted = 130;

// A setting past one of the limits of limits.h once the options are applied: bad input.
class LimitError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// An integer option from `lowest` to `limit` (messages are made printable where they are shown).
// CLI11's own range checks print a double's bounds in full (309 digits) and its unsigned conversion
// takes -1 for 2^64 - 1.
CLI::Validator integer_in(long long lowest, unsigned long long limit) {
    const std::string rule =
        "must be an integer from " + std::to_string(lowest) + " to " + std::to_string(limit);
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            const char* end = text.data() + text.size();
            bool ok = false;
            if (lowest >= 0) {
                unsigned long long v = 0;
                const auto [ptr, ec] = std::from_chars(text.data(), end, v);
                ok = ec == std::errc() && ptr == end &&
                     v >= static_cast<unsigned long long>(lowest) && v <= limit;
            } else {
                long long v = 0;
                const auto [ptr, ec] = std::from_chars(text.data(), end, v);
                ok = ec == std::errc() && ptr == end && v >= lowest &&
                     static_cast<unsigned long long>(v) <= limit;
            }
            return ok ? std::string() : rule + ", got " + abbreviated(text);
        },
        "INT in [" + std::to_string(lowest) + ", " + std::to_string(limit) + "]");
}

// A finite number above zero (CLI::PositiveNumber lets "nan" and "inf" through).
CLI::Validator finite_positive() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            const bool ok = !text.empty() && *end == '\0' && std::isfinite(v) && v > 0;
            return ok ? std::string()
                      : "must be a finite positive number, got " + abbreviated(text);
        },
        "POSITIVE");
}

// Command-line settings that override the scene's <Image> and <Render>.
struct Overrides {
    std::optional<int> spp, shadow_rays, width, height, glossy_rays, max_depth;
    std::optional<std::uint64_t> seed;  // from a text the validator has checked, not CLI11's
    std::optional<std::string> sampler;
    std::optional<double> scale;

    void add_to(CLI::App& app) {
        app.add_option("--spp", spp, "Camera samples per pixel (overrides Render Samples)")
            ->check(integer_in(1, kMaxSamples));
        app.add_option("--shadow-rays", shadow_rays, "Overrides Render ShadowRays")
            ->check(integer_in(1, kMaxRaysPerPoint));
        app.add_option("--width", width, "Overrides Image Width")
            ->check(integer_in(1, kMaxImageSide));
        app.add_option("--height", height, "Overrides Image Height")
            ->check(integer_in(1, kMaxImageSide));
        app.add_option("--scale", scale,
                       "Multiplies the image size, keeping the framing (applied after --width and "
                       "--height)")
            ->check(finite_positive());
        // Like the scene's Seed: a negative number is an error, not 2^64 minus it.
        app.add_option("--seed", seed, "Overrides Render Seed")
            ->check(integer_in(0, std::numeric_limits<std::uint64_t>::max()));
        app.add_option("--glossy-rays", glossy_rays, "Overrides Render GlossyRays")
            ->check(integer_in(1, kMaxRaysPerPoint));
        app.add_option("--max-depth", max_depth, "Overrides Render MaxDepth")
            ->check(integer_in(0, kMaxDepthLimit));
        app.add_option("--sampler", sampler, "Sampler: stratified (default), random or sobol")
            ->check(CLI::IsMember(sampler_names()));
    }

    void apply(RenderSettings& s) const {
        if (spp) s.samples = *spp;
        if (shadow_rays) s.shadow_rays = *shadow_rays;
        if (width) s.width = *width;
        if (height) s.height = *height;
        if (scale) {
            // In double, checked before converting: 1e9 times a side does not fit an int.
            const double w = std::max(1.0, std::round(s.width * *scale));
            const double h = std::max(1.0, std::round(s.height * *scale));
            if (w > kMaxImageSide || h > kMaxImageSide) {
                throw LimitError("--scale " + short_number(*scale) + " makes the image " +
                                 short_number(w) + "x" + short_number(h) + ", past the limit of " +
                                 std::to_string(kMaxImageSide) + " pixels a side");
            }
            s.width = static_cast<int>(w);
            s.height = static_cast<int>(h);
            s.pixel_plane_unit /= *scale;
        }
        if (seed) s.seed = *seed;
        if (glossy_rays) s.glossy_rays = *glossy_rays;
        if (max_depth) s.max_depth = *max_depth;
        if (sampler) s.sampler = *sampler;
    }
};

std::string format_duration(double seconds) {
    const auto total = static_cast<long long>(std::llround(std::max(0.0, seconds)));
    std::ostringstream s;
    if (total >= 3600)
        s << total / 3600 << ":" << std::setw(2) << std::setfill('0') << (total / 60) % 60;
    else
        s << total / 60;
    s << ":" << std::setw(2) << std::setfill('0') << total % 60;
    return s.str();
}

// A one-line progress display on a terminal: percent, elapsed and estimated remaining time.
class ProgressDisplay {
  public:
    ProgressDisplay(std::ostream& err, std::string label) : err_(err), label_(std::move(label)) {}
    void operator()(double done) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        const double left = done > 0 ? elapsed * (1 - done) / done : 0;
        err_ << "\r" << label_ << " " << std::setw(3) << static_cast<int>(done * 100) << "%  "
             << format_duration(elapsed) << " elapsed";
        if (done > 0 && done < 1)
            err_ << ", " << format_duration(left) << " left ";
        else
            err_ << "         ";
        if (done >= 1) err_ << "\n";
        err_ << std::flush;
    }

  private:
    std::ostream& err_;
    std::string label_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

std::string json_bool(bool b) {
    return b ? "true" : "false";
}

// JSON has no NaN or infinity: those become null.
std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    std::ostringstream text;
    text << std::setprecision(6) << v;
    return text.str();
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\')
            out += '\\', out += c;
        else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else
            out += c;
    }
    return out + "\"";
}

// The rounds of a render to a goal (--target-error, --time-limit).
std::string goal_json(const ProgressiveResult& p, const std::optional<double>& target,
                      const std::optional<double>& limit, std::uint64_t seed) {
    std::ostringstream j;
    j << "  \"goal\": {\"target_error\": " << (target ? json_number(*target) : "null")
      << ", \"time_limit\": " << (limit ? json_number(*limit) : "null")
      << ", \"target_met\": " << json_bool(p.target_met)
      << ", \"combined\": " << json_bool(p.combined) << ", \"rounds\": [";
    for (std::size_t i = 0; i < p.rounds.size(); ++i) {
        const ProgressiveRound& r = p.rounds[i];
        j << (i ? ", " : "") << "{\"spp\": " << r.spp;
        // The seed renders the round alone (--spp N --seed S): a string, as 64 bits are beyond
        // a JSON number's exact range.
        if (p.combined) j << ", \"seed\": \"" << round_seed(seed, i) << "\"";
        j << ", \"seconds\": " << json_number(r.seconds)
          << ", \"estimated_rmse\": " << (r.error ? json_number(*r.error) : "null") << "}";
    }
    j << "]},\n";
    return j.str();
}

std::string stats_json(const Scene& scene, const RenderResult& r, const std::string& goal = {}) {
    const RayCounts& rays = r.stats.rays;
    const Effects& e = r.plan.effects;
    const RenderSettings& s = scene.settings;
    std::ostringstream j;
    j << std::setprecision(6);
    j << "{\n  \"scene\": " << json_string(scene.path) << ",\n"
      << "  \"seconds\": " << json_number(r.stats.seconds) << ",\n"
      << "  \"width\": " << s.width << ", \"height\": " << s.height
      << ", \"samples_per_pixel\": " << s.samples << ",\n"
      << "  \"shadow_rays\": " << s.shadow_rays << ", \"glossy_rays\": " << s.glossy_rays
      << ", \"max_depth\": " << s.max_depth << ", \"seed\": " << s.seed
      << ", \"sampler\": " << json_string(s.sampler) << ", \"threads\": " << r.stats.threads
      << ", \"processes\": " << r.stats.processes << ",\n"
      << "  \"tail_seconds\": " << json_number(r.stats.tail_seconds) << ",\n";
    if (r.stats.tile_messages > 0) {
        const double n = double(r.stats.tile_messages);
        j << "  \"tile_messages\": " << r.stats.tile_messages
          << ", \"microseconds_per_message\": {\"receive\": "
          << json_number(r.stats.receive_seconds / n * 1e6)
          << ", \"assemble\": " << json_number(r.stats.assemble_seconds / n * 1e6) << "},\n";
    }
    j << "  \"rays\": {\"camera\": " << rays.camera << ", \"shadow\": " << rays.shadow
      << ", \"reflection\": " << rays.reflection << ", \"refraction\": " << rays.refraction
      << ", \"total\": " << rays.total() << "},\n"
      << "  \"million_rays_per_second\": "
      << json_number(r.stats.seconds > 0 ? rays.total() / r.stats.seconds / 1e6 : 0.0) << ",\n"
      << "  \"mean_spp\": " << json_number(double(r.stats.samples) / (double(s.width) * s.height))
      << ",\n";
    const ErrorEstimate& error = r.stats.error;
    if (error.available()) {
        j << "  \"estimated_rmse\": " << json_number(*error.rmse)
          << ", \"estimated_relmse\": " << json_number(*error.relmse)
          << ", \"estimate_cost\": " << json_number(error.cost) << ",\n";
    } else {
        j << "  \"estimated_rmse\": null, \"estimated_relmse\": null, \"estimate_unavailable\": "
          << json_string(error.unavailable) << ",\n";
    }
    if (const auto& a = r.stats.adaptive) {
        j << "  \"adaptive\": {\"noise_threshold\": " << json_number(a->noise_threshold)
          << ", \"min_spp\": " << a->min_samples << ", \"max_spp\": " << s.samples
          << ", \"pixels_converged\": " << r.stats.pixels_converged << "},\n";
    }
    j << goal;
    j << "  \"effects\": {\"antialiasing\": " << json_bool(e.antialiasing)
      << ", \"soft_shadows\": " << json_bool(e.soft_shadows)
      << ", \"glossy_reflection\": " << json_bool(e.glossy_reflection)
      << ", \"glossy_refraction\": " << json_bool(e.glossy_refraction)
      << ", \"depth_of_field\": " << json_bool(e.depth_of_field)
      << ", \"motion_blur\": " << json_bool(e.motion_blur) << "}\n}";
    return j.str();
}

// Writes text and a final newline through a temporary file and a rename, like the images.
void write_text_atomically(const fs::path& path, const std::string& text) {
    replace_file(path, text + "\n");
}

struct SceneOutcome {
    std::string scene;
    fs::path output;
    int status = kOk;
    int width = 0, height = 0, samples = 0;
    double seconds = 0;
    double mrays_per_second = 0;
    std::string json;
};

// --noise-threshold and --min-spp: adaptive sampling, with --spp (or Render Samples) the maximum.
struct AdaptiveFlags {
    std::optional<double> noise_threshold;
    int min_spp = 16;

    CLI::Option* add_to(CLI::App& app) {
        CLI::Option* threshold =
            app.add_option("--noise-threshold", noise_threshold,
                           "Adaptive sampling: a pixel stops once the standard error of its mean "
                           "luminance is below X; --spp is the maximum")
                ->check(finite_positive());
        app.add_option("--min-spp", min_spp,
                       "Adaptive sampling: samples every pixel takes first (default 16)")
            ->check(integer_in(1, kMaxSamples))
            ->needs(threshold);
        return threshold;
    }
    std::optional<AdaptiveSampling> settings() const {
        if (!noise_threshold) return std::nullopt;
        return AdaptiveSampling{*noise_threshold, min_spp};
    }
};

// --target-error and --time-limit: rounds of renders until the goal (progressive.h).
struct GoalFlags {
    std::optional<double> target_error, time_limit;

    // `conflicting`: options that cannot go with a goal.
    void add_to(CLI::App& app, const std::vector<CLI::Option*>& conflicting) {
        CLI::Option* target =
            app.add_option("--target-error", target_error,
                           "Render until the image's estimated RMSE is at most E; --spp is then "
                           "the maximum")
                ->check(finite_positive());
        CLI::Option* limit =
            app.add_option("--time-limit", time_limit,
                           "Render the best image that S seconds allow; --spp is then the maximum")
                ->check(finite_positive());
        for (CLI::Option* other : conflicting) {
            target->excludes(other);
            limit->excludes(other);
        }
    }
    bool wanted() const { return target_error || time_limit; }
};

struct RenderJob {
    Overrides overrides;
    AdaptiveFlags adaptive;
    GoalFlags goal;
    int threads = 0;
    bool quiet = false;
    bool progress = false;
    bool exr_half = false;
    // Something shows the error estimate besides an .exr output's attributes (render_one adds
    // those): the finish line, --stats, --error-image, a goal, a report.
    bool estimate_shown = true;
    std::string checkpoint;   // a file, or with several scenes a folder of <scene>.checkpoint
    std::string error_image;  // one scene only: where its per-pixel standard error goes
    double checkpoint_seconds = 30;
    std::optional<std::size_t> stop_after_tiles;
    bool grid_order = false;
    std::stop_token stop;
    const MpiJob* mpi = nullptr;

    bool leader() const { return mpi == nullptr || mpi->leader(); }
    // Under MPI: the highest status of all processes, so that all exit alike.
    int agree(int status) const { return mpi ? mpi->highest(status) : status; }
};

// What an .exr header records about the render, so that the file says how it was made, and how
// good it is: `estimatedError`, the estimated RMSE, when there is one.
ImageWriteOptions output_options(const Scene& scene, const RenderResult& result,
                                 const RenderJob& job) {
    const RenderSettings& s = scene.settings;
    ImageWriteOptions options;
    options.half = job.exr_half;
    options.attributes = {{"scene", scene.path},
                          {"software", std::string("drt ") + DRT_VERSION},
                          {"samplesPerPixel", s.samples},
                          {"seed", std::to_string(s.seed)},  // 64 bits: no EXR number holds it
                          {"sampler", s.sampler},
                          {"renderSeconds", result.stats.seconds}};
    if (const auto& a = result.stats.adaptive) {
        options.attributes.push_back({"noiseThreshold", a->noise_threshold});
        options.attributes.push_back({"minSamplesPerPixel", a->min_samples});
    }
    if (const auto& rmse = result.stats.error.rmse) {
        options.attributes.push_back({"estimatedError", *rmse});
        options.attributes.push_back({"estimatedRelMSE", *result.stats.error.relmse});
    }
    return options;
}

// Channel values that are NaN or infinite: radiance beyond the float range (a light of 1e39).
std::size_t count_nonfinite(const Image& image) {
    return static_cast<std::size_t>(std::count_if(image.rgb.begin(), image.rgb.end(),
                                                  [](float v) { return !std::isfinite(v); }));
}

// Turns a signal (interrupt.h) into a stop request for the render in progress. The handler may
// only set a flag, so it is polled here; a second signal still ends drt at once.
class SignalStop {
  public:
    SignalStop()
        : poller_([this](std::stop_token done) {
              while (!done.stop_requested()) {
                  if (stop_signal().load() != 0) {
                      source_.request_stop();
                      return;
                  }
                  std::this_thread::sleep_for(std::chrono::milliseconds(20));
              }
          }) {}
    std::stop_token token() const { return source_.get_token(); }

  private:
    CooperativeStop cooperative_;
    std::stop_source source_;
    std::jthread poller_;  // last: stopped and joined before the rest goes
};

// What a render to a goal reached, and how to render the same image again.
std::string goal_summary(const std::string& name, const ProgressiveResult& p, const GoalFlags& goal,
                         double seconds) {
    std::ostringstream line;
    line << "drt: " << name << ": " << p.samples << " spp after rounds of ";
    for (std::size_t i = 0; i < p.rounds.size(); ++i) line << (i ? ", " : "") << p.rounds[i].spp;
    line << " spp; estimated rmse " << (p.error ? short_number(*p.error) : std::string("n/a"));
    if (goal.target_error) {
        line << " (target " << short_number(*goal.target_error)
             << (p.target_met ? " met)" : " not met)");
    }
    if (goal.time_limit) {
        line << "; " << std::fixed << std::setprecision(2) << seconds << " s of the "
             << short_number(*goal.time_limit) << " s limit" << std::defaultfloat;
    }
    if (!p.combined) {
        line << "\ndrt: " << name << ": --spp " << p.samples
             << " renders the same image (bit-identical) without a goal\n";
    } else {
        line << "\ndrt: " << name
             << ": the rounds' images combined (weighted by 1 / estimated variance); the same "
                "command renders the same image "
             << (goal.time_limit ? "where it completes the same rounds\n"
                                 : "(bit-identical) every run\n");
    }
    return line.str();
}

// `<stem>.partial.<ext>` beside the output: an interrupted render's finished tiles.
fs::path partial_path(const fs::path& output) {
    return output.parent_path() /
           (output.stem().string() + ".partial" + output.extension().string());
}

// Runs `step`, turning every exception into a message and a status.
template <typename Step>
int guarded(const std::string& name, std::ostream& err, Step&& step) {
    try {
        step();
        return kOk;
    } catch (const SceneError& e) {
        err << e.what() << "\n";
    } catch (const ImageError& e) {
        err << "drt: " << e.what() << "\n";
    } catch (const CheckpointError& e) {
        err << "drt: " << printable(e.what()) << "\n";
    } catch (const LimitError& e) {
        err << "drt: " << name << ": " << e.what() << "\n";
    } catch (const std::bad_alloc&) {
        err << "drt: " << name << ": out of memory\n";
        return kFailed;
    } catch (const std::exception& e) {
        err << "drt: " << name << ": " << printable(e.what()) << "\n";
        return kFailed;
    }
    return kBadInput;
}

// One scene, start to end. Everything that can go wrong ends here as a message and a status, so
// that a batch goes on with its other scenes: this is the job boundary. Under MPI every process
// runs it, and all agree on the status after each step, so that none waits for another that
// gave up.
SceneOutcome render_one(const std::string& scene_path, const fs::path& output,
                        const std::optional<fs::path>& checkpoint, const RenderJob& job,
                        std::ostream& err) {
    const auto start = std::chrono::steady_clock::now();  // a time limit counts from here
    SceneOutcome outcome;
    outcome.scene = scene_path;
    const std::string name = printable(scene_path);
    std::optional<LoadedScene> loaded;
    int status = guarded(name, err, [&] {
        format_for_path(output);  // refuse an unknown extension before spending time rendering
        loaded.emplace(load_scene(scene_path));
        for (const std::string& w : loaded->warnings) err << w << "\n";
        job.overrides.apply(loaded->scene.settings);
        RenderSettings largest = loaded->scene.settings;
        if (job.goal.wanted() && !job.overrides.spp) largest.samples = kMaxSamples;
        if (const auto problem = render_limit_problem(largest, job.threads)) {
            throw LimitError(*problem);
        }
    });
    if (const int agreed = job.agree(status); agreed != kOk) {
        if (status == kOk) err << "drt: " << name << ": failed in another process\n";
        outcome.status = agreed;
        return outcome;
    }
    const Scene& scene = loaded->scene;
    RenderJobOptions options;
    options.threads = job.threads;
    options.adaptive = job.adaptive.settings();
    options.checkpoint = checkpoint;
    options.scene_files = {scene_path};
    options.scene_files.insert(options.scene_files.end(), loaded->files_read.begin(),
                               loaded->files_read.end());
    options.checkpoint_interval = std::chrono::duration<double>(job.checkpoint_seconds);
    options.stop_after_tiles = job.stop_after_tiles;
    options.costly_first = !job.grid_order;
    options.estimate_error = job.estimate_shown || format_for_path(output) == ImageFormat::kExr;
    options.stop = job.stop;
    options.mpi = job.mpi;
    std::optional<ProgressDisplay> display;
    if (job.progress && job.leader()) {
        display.emplace(err, printable(fs::path(scene_path).filename().string()));
        options.on_progress = [&](double done) { (*display)(done); };
    }
    RenderJobResult r;
    std::optional<ProgressiveResult> rounds;
    status = guarded(name, err, [&] {
        if (!job.goal.wanted()) {
            r = run_render_job(scene, options);
            return;
        }
        ProgressiveGoal goal;
        goal.target_error = job.goal.target_error;
        goal.time_limit = job.goal.time_limit;
        goal.max_samples = job.overrides.spp.value_or(kMaxSamples);
        goal.start = start;
        rounds = render_progressively(loaded->scene, options, goal);
        r = std::move(rounds->job);
        loaded->scene.settings.samples = rounds->samples;
        r.render.stats.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    });
    if (status != kOk || !job.leader()) {
        outcome.status = job.agree(status);
        return outcome;
    }
    const RenderResult& result = r.render;
    outcome.width = scene.settings.width;
    outcome.height = scene.settings.height;
    outcome.samples = scene.settings.samples;
    outcome.seconds = result.stats.seconds;
    outcome.mrays_per_second =
        result.stats.seconds > 0 ? result.stats.rays.total() / result.stats.seconds / 1e6 : 0;
    const fs::path target = r.complete() ? output : partial_path(output);
    try {
        write_image(result.image, target, output_options(scene, result, job));
    } catch (const ImageError& e) {
        err << "drt: " << e.what() << "\n";
        outcome.status = job.agree(kFailed);
        return outcome;
    }
    if (!r.complete()) {
        const int sig = stop_signal().load();
        err << "drt: " << name << ": interrupted with " << r.done << " of " << r.tiles
            << " tiles done; wrote " << printable(target.string());
        if (checkpoint) {
            err << " and " << printable(checkpoint->string())
                << "\ndrt: run the same command again to resume\n";
        } else {
            err << "\ndrt: with --checkpoint FILE an interrupted render can be resumed\n";
        }
        outcome.status = job.agree(sig != 0 ? 128 + sig : kInterrupted);
        return outcome;
    }
    outcome.json = stats_json(
        scene, result,
        rounds ? goal_json(*rounds, job.goal.target_error, job.goal.time_limit, scene.settings.seed)
               : std::string());
    if (!job.error_image.empty()) {
        try {
            write_image(standard_error_image(result.spread, result.stats.error), job.error_image,
                        output_options(scene, result, job));
        } catch (const ImageError& e) {
            err << "drt: " << e.what() << "\n";
            outcome.status = job.agree(kFailed);
            return outcome;
        }
    }
    if (checkpoint) {
        std::error_code ignored;
        fs::remove(*checkpoint, ignored);
        // What an earlier, interrupted run left is superseded by the image.
        if (r.resumed > 0) fs::remove(partial_path(output), ignored);
    }
    if (!job.quiet) {
        err << "drt: wrote " << printable(output.string()) << " (" << outcome.width << "x"
            << outcome.height << ", " << outcome.samples << " spp, " << std::fixed
            << std::setprecision(2) << outcome.seconds << " s";
        if (r.resumed > 0) err << ", " << r.resumed << " of " << r.tiles << " tiles resumed";
        err << ", estimated RMSE "
            << format_estimate(result.stats.error.rmse, result.stats.error.unavailable) << ")\n"
            << std::defaultfloat;
        if (rounds) err << goal_summary(name, *rounds, job.goal, outcome.seconds);
    }
    if (rounds && rounds->stopped) {
        // Interrupted between or during rounds: the image is the complete rounds'.
        const int sig = stop_signal().load();
        err << "drt: " << name << ": interrupted; kept "
            << (rounds->combined ? "the complete rounds combined\n" : "the last complete round\n");
        outcome.status = job.agree(sig != 0 ? 128 + sig : kInterrupted);
        return outcome;
    }
    // Written all the same, for inspection, but not a success: no pixel may be silently lost.
    if (const std::size_t bad = count_nonfinite(result.image)) {
        err << "drt: " << name << ": " << bad << " of " << result.image.rgb.size()
            << " channel values are not finite (radiance beyond the float range: a light, "
               "background or ambient too bright?)\n";
        status = kBadInput;
    }
    outcome.status = job.agree(status);
    return outcome;
}

void print_summary(const std::vector<SceneOutcome>& outcomes, std::ostream& out) {
    out << std::left << std::setw(32) << "scene" << std::right << std::setw(11) << "size"
        << std::setw(9) << "samples" << std::setw(10) << "seconds" << std::setw(10) << "Mrays/s"
        << "  status\n";
    for (const SceneOutcome& o : outcomes) {
        std::ostringstream size;
        if (o.width > 0) size << o.width << "x" << o.height;
        out << std::left << std::setw(32) << printable(fs::path(o.scene).filename().string())
            << std::right << std::setw(11) << size.str() << std::setw(9)
            << (o.samples ? std::to_string(o.samples) : "") << std::fixed << std::setprecision(2)
            << std::setw(10) << o.seconds << std::setw(10) << o.mrays_per_second
            << std::defaultfloat << "  "
            << (o.status == kOk       ? "ok"
                : o.status == kFailed ? "failed"
                                      : "bad input")
            << "\n";
    }
}

bool is_folder_target(const std::string& output) {
    std::error_code ignored;  // a name that cannot be examined is not a folder
    return !output.empty() && (output.back() == '/' || fs::is_directory(output, ignored));
}

// --report with --reference-dir: a batch's images against references of the same names.
struct BatchReport {
    bool wanted = false;
    std::string reference_dir;
    double max_rmse = 0;

    void add_to(CLI::App& app) {
        CLI::Option* refs =
            app.add_option("--reference-dir", reference_dir,
                           "Batch report: the folder of reference images, one per output name");
        app.add_flag("--report", wanted,
                     "Batch: compare each image with --reference-dir's and write DIR/report/"
                     "index.html, worst first")
            ->needs(refs);
        app.add_option("--max-rmse", max_rmse,
                       "Batch report: a case fails when its RMSE exceeds X (default 0: any change)")
            ->check(CLI::NonNegativeNumber)
            ->needs(refs);
    }

    // Writes the report of the batch in `folder` and returns the status it adds: 1 when an image
    // differs beyond --max-rmse or could not be made, 2 when a reference is missing or unreadable.
    int write(const std::vector<SceneOutcome>& outcomes, const fs::path& folder, bool quiet,
              std::ostream& err) const {
        int status = kOk;
        std::vector<ReportCase> cases;
        for (const SceneOutcome& o : outcomes) {
            const fs::path reference_file = fs::path(reference_dir) / o.output.filename();
            std::optional<Image> reference, render;
            std::string note;
            try {
                reference = read_image(reference_file);
            } catch (const ImageError& e) {
                note = std::string("no reference: ") + e.what();
                status = std::max(status, kBadInput);
            }
            if (o.status == kOk) {
                try {
                    render = read_image(o.output);
                } catch (const ImageError& e) {
                    note += (note.empty() ? "" : "\n") + std::string(e.what());
                    status = std::max(status, kFailed);
                }
            } else {
                note += (note.empty() ? "" : "\n") + std::string("the render failed (status ") +
                        std::to_string(o.status) + ")";
            }
            ReportCase c = compare_case(o.output.stem().string(), reference_file.string(),
                                        o.output.string(), std::move(reference), std::move(render),
                                        is_linear(format_for_path(o.output)));
            if (c.measures && !(c.measures->rmse <= max_rmse)) {
                note += "rmse " + format_measure(c.measures->rmse) + " exceeds --max-rmse " +
                        format_measure(max_rmse);
                status = std::max(status, kFailed);
            } else if (!c.measures && reference && render) {
                status = std::max(status, kBadInput);  // sizes differ: compare_case says so
            }
            c.failed = o.status != kOk || !c.measures || !(c.measures->rmse <= max_rmse);
            c.note = note + (note.empty() || c.note.empty() ? "" : "\n") + c.note;
            cases.push_back(std::move(c));
        }
        try {
            const fs::path page = write_report(folder / "report", "drt batch report", cases);
            if (!quiet) err << "drt: wrote report " << printable(page.string()) << "\n";
        } catch (const std::exception& e) {
            err << "drt: report: " << printable(e.what()) << "\n";
            status = std::max(status, kFailed);
        }
        return status;
    }
};

int render_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
                   const MpiJob* mpi) {
    CLI::App app{
        "drt: distributed ray tracer (Cook, Porter & Carpenter 1984).\n"
        "Also: drt compare A B [--max-rmse X] [--diff D.png] | drt info SCENE.xml | "
        "drt converge SCENE.xml --spp 1,4,16",
        "drt"};
    std::vector<std::string> scenes;
    std::string output, stats;
    RenderJob job;
    bool force_progress = false;
    app.add_option("scenes", scenes, "Scene file(s) in the thesis XML format")->required();
    app.add_option("-o,--output", output,
                   "Output image (.png, .bmp, .pfm, .exr); with several scenes, a folder");
    app.add_flag("--exr-half", job.exr_half,
                 "Write .exr channels as 16-bit half floats instead of 32-bit floats");
    job.overrides.add_to(app);
    CLI::Option* threshold = job.adaptive.add_to(app);
    app.add_option("--threads", job.threads, "Worker threads (default: all cores)")
        ->check(integer_in(1, kMaxThreads));
    app.add_option("--stats", stats, "Write render statistics as JSON to FILE (- = stdout)");
    app.add_option("--error-image", job.error_image,
                   "Write each pixel's estimated standard error (per channel, linear) to FILE "
                   "(.png, .bmp, .pfm, .exr)");
    app.add_flag("-q,--quiet", job.quiet, "No progress display or messages besides errors");
    app.add_flag("--progress", force_progress, "Show progress even when stderr is not a terminal");
    CLI::Option* checkpoint =
        app.add_option("--checkpoint", job.checkpoint,
                       "Keep finished work in FILE (with several scenes, a folder); running the "
                       "same command again resumes from it; removed when the render completes");
    job.goal.add_to(app, {threshold, checkpoint});
    app.add_option("--checkpoint-every", job.checkpoint_seconds,
                   "Seconds between checkpoint writes (default 30)")
        ->check(CLI::NonNegativeNumber);
    // For tests: stop as SIGINT would once N tiles are done.
    app.add_option("--stop-after-tiles", job.stop_after_tiles)->group("");
    // For bench/mpi.sh: hand tiles out row by row, to measure what costly-first saves.
    app.add_flag("--grid-order", job.grid_order)->group("");
    BatchReport report;
    report.add_to(app);
    app.set_version_flag("--version", std::string("drt ") + DRT_VERSION);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::CallForVersion&) {
        out << "drt " << DRT_VERSION << "\n";
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << "drt: " << printable(e.what()) << "\nRun 'drt --help' for usage.\n";
        return kBadInput;
    }
    // Before any image replaces its output, so that a run never ends half done for want of it.
    job.mpi = mpi;
    if (!stats.empty() && stats != "-" && job.leader()) {
        try {
            check_replaceable(stats);
        } catch (const FileWriteError& e) {
            err << "drt: --stats " << e.what() << "\n";
            return job.agree(kBadInput);
        }
    }
    if (!job.error_image.empty() && job.leader()) {
        try {
            format_for_path(job.error_image);
            check_replaceable(job.error_image);
        } catch (const ImageError& e) {
            err << "drt: --error-image " << e.what() << "\n";
            return job.agree(kBadInput);
        } catch (const FileWriteError& e) {
            err << "drt: --error-image " << e.what() << "\n";
            return job.agree(kBadInput);
        }
    }
    if (job.agree(kOk) != kOk) return kBadInput;
    job.progress = !job.quiet && (force_progress || isatty(STDERR_FILENO));
    job.estimate_shown = !job.quiet || !stats.empty() || !job.error_image.empty() ||
                         job.goal.wanted() || report.wanted;

    const bool batch = scenes.size() > 1 || is_folder_target(output);
    if (batch && !job.error_image.empty()) {
        err << "drt: --error-image takes one scene, not a batch\nRun 'drt --help' for usage.\n";
        return kBadInput;
    }
    if (report.wanted && !(batch && !output.empty())) {
        err << "drt: --report needs a batch: -o DIR/\nRun 'drt --help' for usage.\n";
        return kBadInput;
    }
    int made = kOk;
    if (job.leader()) {
        for (const std::string& folder : {batch ? output : "", batch ? job.checkpoint : ""}) {
            if (folder.empty()) continue;
            std::error_code ec;
            fs::create_directories(folder, ec);
            if (ec) {
                err << "drt: " << printable(folder) << ": cannot create folder: " << ec.message()
                    << "\n";
                made = kFailed;
            }
        }
    }
    if (job.agree(made) != kOk) return kFailed;
    const SignalStop signals;
    job.stop = signals.token();
    std::vector<SceneOutcome> outcomes;
    for (const std::string& scene : scenes) {
        fs::path target = fs::path(scene).stem().string() + ".png";
        std::optional<fs::path> checkpoint;
        if (!job.checkpoint.empty()) checkpoint = job.checkpoint;
        if (batch) {
            if (!output.empty()) target = fs::path(output) / target;
            if (checkpoint) *checkpoint /= fs::path(scene).stem().string() + ".checkpoint";
        } else if (!output.empty()) {
            target = output;
        }
        outcomes.push_back(render_one(scene, target, checkpoint, job, err));
        outcomes.back().output = target;
        // An interrupt ends the batch: the scenes after it are not started.
        if (outcomes.back().status > kBadInput) break;
    }

    int status = kOk;
    for (const SceneOutcome& o : outcomes) status = std::max(status, o.status);
    if (!job.leader()) return status;  // the leader reports for all
    if (!stats.empty()) {
        std::string json;
        if (!batch) {
            json = outcomes.front().json;
        } else {
            json = "{\"scenes\": [";
            bool first = true;
            for (const SceneOutcome& o : outcomes) {
                if (o.json.empty()) continue;
                json += (first ? "\n" : ",\n") + o.json;
                first = false;
            }
            json += "]}";
        }
        if (!json.empty()) {
            if (stats == "-") {
                out << json << "\n";
            } else {
                try {
                    write_text_atomically(stats, json);
                } catch (const std::exception& e) {
                    err << "drt: " << e.what() << "\n";
                    status = std::max(status, kFailed);
                }
            }
        }
    }
    if (batch) print_summary(outcomes, stats == "-" ? err : out);
    if (report.wanted)
        status = std::max(status, report.write(outcomes, fs::path(output), job.quiet, err));
    return status;
}

int compare_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"Compare two images (.png, .bmp, .pfm, .exr) of equal size", "drt compare"};
    std::string a, b, diff;
    std::optional<double> max_rmse, min_psnr;
    app.add_option("A", a, "First image")->required();
    app.add_option("B", b, "Second image")->required();
    app.add_option("--max-rmse", max_rmse, "Exit 1 when the RMSE exceeds X")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--min-psnr", min_psnr, "Exit 1 when the PSNR falls below Y (dB)");
    app.add_option("--diff", diff,
                   "Write a false-colour difference image to D (.png, .bmp, .pfm, .exr)");
    std::string report_dir;
    app.add_option("--report", report_dir,
                   "Write DIR/index.html showing B (the reference), A (the render) and their "
                   "difference with the measures");
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << "drt compare: " << printable(e.what()) << "\nRun 'drt compare --help' for usage.\n";
        return kBadInput;
    }
    Comparison c;
    Image image_a, image_b;
    try {
        // Check every name before reading, so a typo costs nothing and writes nothing.
        const bool linear_a = is_linear(format_for_path(a));
        if (linear_a != is_linear(format_for_path(b))) {
            // Linear floats against sRGB-encoded bytes would measure the tone curve, not the image.
            throw ImageError("cannot compare " + printable(linear_a ? a : b) + " (linear) with " +
                             printable(linear_a ? b : a) + " (8-bit sRGB): convert one first");
        }
        if (!diff.empty()) format_for_path(diff);
        image_a = read_image(a);
        image_b = read_image(b);
        c = compare_images(image_a, image_b);
    } catch (const ImageError& e) {
        err << "drt compare: " << e.what() << "\n";
        return kBadInput;
    } catch (const std::bad_alloc&) {
        err << "drt compare: out of memory\n";
        return kFailed;
    }
    out << comparison_fields(c) << "\n";
    int status = kOk;
    if (!diff.empty()) {
        try {
            write_image(difference_image(image_a, image_b), diff);
        } catch (const ImageError& e) {
            err << "drt compare: " << e.what() << "\n";
            status = kFailed;
        }
    }
    // Written as "not within" so that a NaN error (a NaN pixel) fails instead of passing.
    std::string verdict;
    if (max_rmse && !(c.rmse <= *max_rmse)) {
        verdict =
            "rmse " + format_measure(c.rmse) + " exceeds --max-rmse " + format_measure(*max_rmse);
    }
    if (min_psnr && !(c.psnr >= *min_psnr)) {
        verdict += (verdict.empty() ? "" : "\n") + std::string("psnr ") + format_measure(c.psnr) +
                   " is below --min-psnr " + format_measure(*min_psnr);
    }
    if (!verdict.empty()) {
        std::istringstream lines(verdict);
        for (std::string line; std::getline(lines, line);) err << "drt compare: " << line << "\n";
        status = kFailed;
    }
    if (!report_dir.empty()) {
        ReportCase rc{printable(a) + " against " + printable(b),
                      b,
                      a,
                      !verdict.empty(),
                      verdict,
                      std::move(image_b),
                      std::move(image_a),
                      is_linear(format_for_path(a)),
                      c};
        try {
            const fs::path page = write_report(report_dir, "drt compare", {rc});
            err << "drt compare: wrote report " << printable(page.string()) << "\n";
        } catch (const std::exception& e) {
            err << "drt compare: report: " << printable(e.what()) << "\n";
            status = kFailed;
        }
    }
    return status;
}

// The pilot rounds a render of `scene` to `target` takes (progressive.h) and what they predict
// for its final round.
struct GoalForecast {
    std::vector<ProgressiveRound> pilots;
    int final_round = 0;              // the final round's count; 0 when the pilots reach it
    std::optional<Prediction> total;  // all rounds together
    // All rounds together if the final round's error falls only as N^-1/2 (that of independent
    // samples): the final round is sized on the short side, so where it falls short this is the
    // better guess.
    std::optional<Prediction> slow;
};

GoalForecast forecast(Scene& scene, double target, int threads) {
    ProgressiveGoal goal;
    goal.target_error = target;
    goal.max_samples = kMaxSamples;
    goal.pilots_only = true;
    RenderJobOptions options;
    options.threads = threads;
    GoalForecast f;
    const ProgressiveResult pilots = render_progressively(scene, options, goal);
    f.pilots = pilots.rounds;
    if (pilots.rounds.empty()) return f;
    double seconds = 0;
    for (const ProgressiveRound& r : pilots.rounds) seconds += r.seconds;
    const NextRound last = next_round(pilots.rounds, target, kMaxSamples);
    if (last.spp == 0) {
        f.total = Prediction{pilots.samples, seconds};
    } else if (last.final) {
        f.final_round = last.spp;
        f.total = Prediction{pilots.samples + last.spp,
                             seconds + predicted_seconds(pilots.rounds, last.spp)};
        if (const auto slow = predict(pilots.rounds, target, kMaxSamples, -0.5);
            slow && slow->spp > last.spp) {
            f.slow = Prediction{pilots.samples + slow->spp, seconds + slow->seconds};
        }
    }
    return f;
}

std::string forecast_text(const GoalForecast& f, double target) {
    std::ostringstream text;
    text << "pilots:";
    for (const ProgressiveRound& r : f.pilots) {
        text << " " << r.spp << " spp " << std::fixed << std::setprecision(3) << r.seconds
             << " s, estimated rmse " << std::defaultfloat
             << (r.error ? short_number(*r.error) : std::string("n/a")) << ";";
    }
    text << "\npredicted for --target-error " << short_number(target) << ": ";
    if (f.total) {
        // The goal render repeats the pilots, then adds the final round to them.
        text << f.total->spp << " spp, " << std::fixed << std::setprecision(2) << f.total->seconds
             << " s on this machine (rounds of " << std::defaultfloat;
        for (const ProgressiveRound& r : f.pilots)
            text << (&r == &f.pilots[0] ? "" : ", ") << r.spp;
        if (f.final_round > 0) text << ", " << f.final_round;
        text << " spp)";
        if (f.slow) {
            text << "; if the error falls only as N^-1/2: " << f.slow->spp << " spp, " << std::fixed
                 << std::setprecision(2) << f.slow->seconds << " s" << std::defaultfloat;
        }
    } else {
        text << "n/a (the pilots give no error estimate to extrapolate)";
    }
    return text.str() + "\n";
}

int info_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"Show what a scene contains and which effects it calls for", "drt info"};
    std::string scene_path;
    Overrides overrides;
    std::optional<double> target;
    int threads = 0;
    app.add_option("scene", scene_path, "Scene file")->required();
    overrides.add_to(app);
    app.add_option("--target-error", target,
                   "Also predict the samples per pixel and the time a render to this estimated "
                   "RMSE takes here, from short pilot renders")
        ->check(finite_positive());
    app.add_option("--threads", threads, "Worker threads of the pilot renders (default: all cores)")
        ->check(integer_in(1, kMaxThreads));
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << "drt info: " << printable(e.what()) << "\nRun 'drt info --help' for usage.\n";
        return kBadInput;
    }
    try {
        LoadedScene loaded = load_scene(scene_path);
        for (const std::string& w : loaded.warnings) err << w << "\n";
        overrides.apply(loaded.scene.settings);
        out << describe(loaded.scene, plan_render(loaded.scene));
        if (target) out << forecast_text(forecast(loaded.scene, *target, threads), *target);
    } catch (const SceneError& e) {
        err << e.what() << "\n";
        return kBadInput;
    } catch (const LimitError& e) {
        err << "drt info: " << printable(scene_path) << ": " << e.what() << "\n";
        return kBadInput;
    }
    return kOk;
}

int converge_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{
        "Render a scene at several sample counts and show how its error against a "
        "reference falls with samples and with time",
        "drt converge"};
    std::string scene_path, counts_text = "1,4,16,64,256", reference_path, save_reference, csv;
    std::optional<int> reference_spp;
    Overrides overrides;
    AdaptiveFlags adaptive;
    int threads = 0;
    std::optional<double> target;
    app.add_option("scene", scene_path, "Scene file")->required();
    overrides.add_to(app);
    app.remove_option(app.get_option("--spp"));  // here a list, not one count
    app.add_option("--target-error", target,
                   "Predict from pilot renders what reaching this estimated RMSE takes, and show "
                   "it next to where the measured RMSE reaches it")
        ->check(finite_positive());
    app.add_option("--spp", counts_text, "Comma-separated sample counts (default 1,4,16,64,256)");
    app.add_option("--reference", reference_path,
                   "Reference image (.pfm or .exr) to measure against; default: render one");
    app.add_option("--reference-spp", reference_spp,
                   "Samples of the rendered reference (default 16 x the largest count, at most " +
                       std::to_string(kMaxSamples) + ")")
        ->check(integer_in(1, kMaxSamples));
    app.add_option("--save-reference", save_reference,
                   "Write the rendered reference to FILE (.pfm or .exr)");
    app.add_option("--csv", csv,
                   "Write spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted rows to FILE");
    adaptive.add_to(app);
    app.add_option("--threads", threads, "Worker threads (default: all cores)")
        ->check(integer_in(1, kMaxThreads));
    std::vector<int> counts;
    try {
        app.parse(argc, argv);
        counts = parse_counts(counts_text);
        // Only linear floats measure the renderer's error; 8-bit files measure the tone curve.
        for (const std::string& f : {reference_path, save_reference}) {
            if (!f.empty() && !is_linear(format_for_path(f))) {
                throw CLI::ValidationError(f +
                                           ": the reference must be a linear .pfm or .exr image");
            }
        }
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << "drt converge: " << printable(e.what())
            << "\nRun 'drt converge --help' for usage.\n";
        return kBadInput;
    } catch (const std::exception& e) {  // a bad count list or image name
        err << "drt converge: " << printable(e.what()) << "\n";
        return kBadInput;
    }
    try {
        LoadedScene loaded = load_scene(scene_path);
        for (const std::string& w : loaded.warnings) err << w << "\n";
        Scene& scene = loaded.scene;
        overrides.apply(scene.settings);
        const RenderSettings& s = scene.settings;
        {
            // Checked with the most samples any render here will take.
            RenderSettings largest = s;
            largest.samples = std::max(*std::max_element(counts.begin(), counts.end()),
                                       reference_spp.value_or(default_reference_spp(counts)));
            if (const auto problem = render_limit_problem(largest, threads)) {
                throw LimitError(*problem);
            }
        }
        RenderOptions options;
        options.threads = threads;
        options.adaptive = adaptive.settings();

        out << scene_path << ": " << s.width << "x" << s.height << ", sampler " << s.sampler
            << ", seed " << s.seed;
        if (options.adaptive) {
            out << ", noise threshold " << options.adaptive->noise_threshold << ", min spp "
                << options.adaptive->min_samples;
        }
        out << "\n";
        std::optional<GoalForecast> goal;
        if (target) {
            goal = forecast(scene, *target, threads);
            out << forecast_text(*goal, *target);
        }
        Image reference;
        if (!reference_path.empty()) {
            reference = read_image(reference_path);
            if (reference.width != s.width || reference.height != s.height) {
                throw ImageError(reference_path + ": reference is " +
                                 std::to_string(reference.width) + "x" +
                                 std::to_string(reference.height) + ", the render " +
                                 std::to_string(s.width) + "x" + std::to_string(s.height));
            }
            out << "reference: " << reference_path << "\n";
        } else {
            const int spp = reference_spp.value_or(default_reference_spp(counts));
            const std::uint64_t seed = reference_seed(s.seed);
            out << "reference: " << spp << " spp, seed " << seed
                << " (seed + 1: its noise is independent of the measured renders) ..."
                << std::flush;
            RenderOptions plain = options;
            plain.adaptive.reset();
            RenderResult r = render_with(scene, spp, seed, plain);
            out << " " << std::fixed << std::setprecision(2) << r.stats.seconds << " s\n"
                << std::defaultfloat;
            if (!save_reference.empty()) write_image(r.image, save_reference);
            reference = std::move(r.image);
        }
        out << std::setw(8) << "spp" << std::setw(11) << "seconds" << std::setw(13) << "rmse"
            << std::setw(13) << "relmse" << std::setw(10) << "mean_spp" << std::setw(13)
            << "cpu_seconds" << std::setw(15) << "estimated_rmse" << std::setw(8) << "ratio"
            << "\n";
        const Convergence c =
            measure_convergence(scene, counts, reference, options, [&](const ConvergencePoint& p) {
                out << std::setw(8) << p.spp << std::fixed << std::setprecision(3) << std::setw(11)
                    << p.seconds << std::defaultfloat << std::setprecision(5) << std::setw(13)
                    << p.rmse << std::setw(13) << p.relmse << std::setprecision(4) << std::setw(10)
                    << p.mean_spp << std::fixed << std::setprecision(3) << std::setw(13)
                    << p.cpu_seconds << std::defaultfloat << std::setprecision(5);
                if (p.estimate.available()) {
                    out << std::setw(15) << *p.estimate.rmse << std::setprecision(3) << std::setw(8)
                        << *p.estimate.rmse / p.rmse;
                } else {
                    out << "  estimate " << format_estimate({}, p.estimate.unavailable);
                }
                out << std::defaultfloat << (p.fitted ? "" : "  (pixel centres: not in the slopes)")
                    << "\n"
                    << std::flush;
            });
        const auto slope = [](double v) {
            if (std::isnan(v)) return std::string("n/a (needs two fitted counts)");
            std::ostringstream text;
            text << std::fixed << std::setprecision(3) << v;
            return text.str();
        };
        out << "slope of log RMSE against log samples: " << slope(c.slope_vs_spp) << "\n"
            << "slope of log RMSE against log seconds: " << slope(c.slope_vs_seconds) << "\n";
        if (goal) {
            out << "measured for rmse " << short_number(*target) << ": ";
            if (const auto reach = measured_reach(c, *target)) {
                out << std::fixed << std::setprecision(0) << reach->spp << " spp, "
                    << std::setprecision(2) << reach->seconds << " s" << std::defaultfloat
                    << " (interpolated between the counts above)\n";
            } else {
                out << "not reached by the counts above\n";
            }
        }
        if (!csv.empty()) {
            std::string text = convergence_csv(c);
            text.pop_back();  // write_text_atomically ends the file with its own newline
            write_text_atomically(csv, text);
        }
    } catch (const SceneError& e) {
        err << e.what() << "\n";
        return kBadInput;
    } catch (const ImageError& e) {
        err << "drt converge: " << e.what() << "\n";
        return kBadInput;
    } catch (const LimitError& e) {
        err << "drt converge: " << printable(scene_path) << ": " << e.what() << "\n";
        return kBadInput;
    } catch (const std::bad_alloc&) {
        err << "drt converge: " << printable(scene_path) << ": out of memory\n";
        return kFailed;
    } catch (const std::exception& e) {
        err << "drt converge: " << printable(scene_path) << ": " << printable(e.what()) << "\n";
        return kFailed;
    }
    return kOk;
}

}  // namespace

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
            const MpiJob* mpi) {
    // The last guard: every command catches what it expects, and nothing may end in an abort.
    try {
        if (argc >= 2) {
            const std::string command = argv[1];
            // CLI11 takes the program name from argv[0]; hand it "drt compare" and the rest.
            if (command == "compare") return compare_command(argc - 1, argv + 1, out, err);
            if (command == "info") return info_command(argc - 1, argv + 1, out, err);
            if (command == "converge") return converge_command(argc - 1, argv + 1, out, err);
        }
        return render_command(argc, argv, out, err, mpi);
    } catch (const std::bad_alloc&) {
        err << "drt: out of memory\n";
    } catch (const std::exception& e) {
        err << "drt: " << printable(e.what()) << "\n";
    }
    return kFailed;
}

}  // namespace drt
