#include "cli_common.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <ostream>

#include "drt/io/image.h"
#include "drt/job/checkpoint.h"
#include "drt/job/render_job.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/atomic_file.h"
#include "drt/util/interrupt.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt::cli {

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

namespace {

CLI::Validator finite_at_least_zero(bool zero_allowed) {
    return CLI::Validator(
        [zero_allowed](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            const bool ok = !text.empty() && *end == '\0' && std::isfinite(v) &&
                            (v > 0 || (zero_allowed && v == 0));
            const std::string rule = zero_allowed ? "non-negative" : "positive";
            return ok ? std::string()
                      : "must be a finite " + rule + " number, got " + abbreviated(text);
        },
        zero_allowed ? "NONNEGATIVE" : "POSITIVE");
}

}  // namespace

CLI::Validator finite_positive() {
    return finite_at_least_zero(false);
}

CLI::Validator finite_non_negative() {
    return finite_at_least_zero(true);
}

void Overrides::add_to(CLI::App& app) {
    app.add_option("--spp", spp, "Camera samples per pixel (overrides Render Samples)")
        ->check(integer_in(1, kMaxSamples));
    app.add_option("--shadow-rays", shadow_rays, "Overrides Render ShadowRays")
        ->check(integer_in(1, kMaxRaysPerPoint));
    app.add_option("--width", width, "Overrides Image Width")->check(integer_in(1, kMaxImageSide));
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

void Overrides::apply(RenderSettings& s) const {
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

CLI::Option* AdaptiveFlags::add_to(CLI::App& app) {
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

std::optional<AdaptiveSampling> AdaptiveFlags::settings() const {
    if (!noise_threshold) return std::nullopt;
    return AdaptiveSampling{*noise_threshold, min_spp};
}

void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
    replace_file(path, text + "\n");
}

std::optional<int> parse_arguments(CLI::App& app, int argc, const char* const* argv,
                                   const std::string& command, std::ostream& out,
                                   std::ostream& err) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << command << ": " << printable(e.what()) << "\nRun '" << command
            << " --help' for usage.\n";
        return kBadInput;
    }
    return std::nullopt;
}

int report_failure(const std::exception& error, const std::string& command,
                   const std::string& subject, std::ostream& err) {
    const std::string about = subject.empty() ? command + ": " : command + ": " + subject + ": ";
    if (dynamic_cast<const SceneError*>(&error)) {
        err << error.what() << "\n";  // names the file and the line itself
    } else if (dynamic_cast<const ImageError*>(&error)) {
        err << command << ": " << error.what() << "\n";
    } else if (dynamic_cast<const CheckpointError*>(&error)) {
        err << command << ": " << printable(error.what()) << "\n";
    } else if (dynamic_cast<const LimitError*>(&error) ||
               dynamic_cast<const ProcessesDisagree*>(&error)) {
        err << about << error.what() << "\n";
    } else if (dynamic_cast<const std::bad_alloc*>(&error)) {
        err << about << "out of memory\n";
        return kFailed;
    } else {
        err << about << printable(error.what()) << "\n";
        return kFailed;
    }
    return kBadInput;
}

int interrupted_status() {
    const int signal = stop_signal().load();
    return signal != 0 ? 128 + signal : kInterrupted;
}

}  // namespace drt::cli
