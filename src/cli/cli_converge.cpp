#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_common.h"
#include "drt/goal/converge.h"
#include "drt/io/image.h"
#include "drt/render/error_estimate.h"
#include "drt/scene/render_limits.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/atomic_file.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt::cli {

namespace {

struct ConvergeFlags {
    std::string scene_path, counts_text = "1,4,16,64,256", reference_path, save_reference, csv;
    std::optional<int> reference_spp;
    Overrides overrides;
    AdaptiveFlags adaptive;
    int threads = 0;
    std::optional<double> target;

    void add_to(CLI::App& app) {
        app.add_option("scene", scene_path, "Scene file")->required();
        overrides.add_to(app);
        app.remove_option(app.get_option("--spp"));  // here a list, not one count
        app.add_option("--target-error", target,
                       "Predict from pilot renders what reaching this estimated RMSE takes, and "
                       "show it next to where the measured RMSE reaches it")
            ->check(finite_positive());
        app.add_option("--spp", counts_text,
                       "Comma-separated sample counts (default 1,4,16,64,256)");
        CLI::Option* reference = app.add_option(
            "--reference", reference_path,
            "Reference image (.pfm or .exr) to measure against; default: render one");
        app.add_option("--reference-spp", reference_spp,
                       "Samples of the rendered reference (default 16 x the largest count, at "
                       "most " +
                           std::to_string(kMaxSamples) + ")")
            ->check(integer_in(1, kMaxSamples))
            ->excludes(reference);
        app.add_option("--save-reference", save_reference,
                       "Write the rendered reference to FILE (.pfm or .exr)")
            ->excludes(reference);
        app.add_option("--csv", csv,
                       "Write spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,"
                       "estimated_rmse,estimated_relmse rows to FILE");
        adaptive.add_to(app);
        app.add_option("--threads", threads, "Worker threads (default: all cores)")
            ->check(integer_in(1, kMaxThreads));
    }
};

// The reference the counts are measured against: read, or rendered (and saved) here.
Image reference_image(const Scene& scene, const ConvergeFlags& flags,
                      const std::vector<int>& counts, const RenderOptions& options,
                      std::ostream& out) {
    const RenderSettings& s = scene.settings;
    if (!flags.reference_path.empty()) {
        Image reference = read_image(flags.reference_path);
        if (reference.width != s.width || reference.height != s.height) {
            throw ImageError(flags.reference_path + ": reference is " +
                             std::to_string(reference.width) + "x" +
                             std::to_string(reference.height) + ", the render " +
                             std::to_string(s.width) + "x" + std::to_string(s.height));
        }
        out << "reference: " << flags.reference_path << "\n";
        return reference;
    }
    const int spp = flags.reference_spp.value_or(default_reference_spp(counts));
    const std::uint64_t seed = reference_seed(s.seed);
    out << "reference: " << spp << " spp, seed " << seed
        << " (seed + 1: its noise is independent of the measured renders) ..." << std::flush;
    RenderOptions plain = options;
    plain.adaptive.reset();
    RenderResult r = render(scene, request_at(spp, seed, plain), plain);
    out << " " << std::fixed << std::setprecision(2) << r.stats.seconds << " s\n"
        << std::defaultfloat;
    if (!flags.save_reference.empty()) write_image(r.image, flags.save_reference);
    return std::move(r.image);
}

void print_header(std::ostream& out) {
    out << std::setw(8) << "spp" << std::setw(11) << "seconds" << std::setw(13) << "rmse"
        << std::setw(13) << "relmse" << std::setw(10) << "mean_spp" << std::setw(13)
        << "cpu_seconds" << std::setw(15) << "estimated_rmse" << std::setw(8) << "ratio"
        << "\n";
}

void print_point(std::ostream& out, const ConvergencePoint& p) {
    out << std::setw(8) << p.spp << std::fixed << std::setprecision(3) << std::setw(11) << p.seconds
        << std::defaultfloat << std::setprecision(5) << std::setw(13) << p.rmse << std::setw(13)
        << p.relmse << std::setprecision(4) << std::setw(10) << p.mean_spp << std::fixed
        << std::setprecision(3) << std::setw(13) << p.cpu_seconds << std::defaultfloat
        << std::setprecision(5);
    if (p.estimate.available()) {
        out << std::setw(15) << *p.estimate.rmse << std::setprecision(3) << std::setw(8)
            << *p.estimate.rmse / p.rmse;
    } else {
        out << "  estimate " << format_estimate({}, p.estimate.unavailable);
    }
    out << std::defaultfloat << (p.fitted ? "" : "  (pixel centres: not in the slopes)") << "\n"
        << std::flush;
}

// The slopes, and with a target where the measured RMSE reaches it.
void print_summary(std::ostream& out, const Convergence& c, const std::optional<double>& target) {
    const auto slope = [](double v) {
        if (std::isnan(v)) return std::string("n/a (needs two fitted counts)");
        std::ostringstream text;
        text << std::fixed << std::setprecision(3) << v;
        return text.str();
    };
    out << "slope of log RMSE against log samples: " << slope(c.slope_vs_spp) << "\n"
        << "slope of log RMSE against log seconds: " << slope(c.slope_vs_seconds) << "\n";
    if (!target) return;
    out << "measured for rmse " << short_number(*target) << ": ";
    if (const auto reach = measured_reach(c, *target)) {
        out << std::fixed << std::setprecision(0) << reach->spp << " spp, " << std::setprecision(2)
            << reach->seconds << " s" << std::defaultfloat
            << " (interpolated between the counts above)\n";
    } else {
        out << "not reached by the counts above\n";
    }
}

// Everything after the arguments are parsed; throws what the command reports.
void converge(const ConvergeFlags& flags, const std::vector<int>& counts, std::ostream& out,
              std::ostream& err) {
    LoadedScene loaded = load_scene(flags.scene_path);
    for (const std::string& w : loaded.warnings) err << w << "\n";
    Scene& scene = loaded.scene;
    flags.overrides.apply(scene.settings);
    const RenderSettings& s = scene.settings;
    // Checked with the most samples any render here will take.
    RenderSettings largest = s;
    largest.samples = std::max(*std::max_element(counts.begin(), counts.end()),
                               flags.reference_spp.value_or(default_reference_spp(counts)));
    if (const auto problem = render_limit_problem(largest, flags.threads)) {
        throw LimitError(*problem);
    }
    RenderOptions options;
    options.threads = flags.threads;
    options.adaptive = flags.adaptive.settings();
    out << flags.scene_path << ": " << s.width << "x" << s.height << ", sampler " << s.sampler
        << ", seed " << s.seed;
    if (options.adaptive) {
        out << ", noise threshold " << options.adaptive->noise_threshold << ", min spp "
            << options.adaptive->min_samples;
    }
    out << "\n";
    if (flags.target) {
        out << goal_forecast(scene, *flags.target, flags.threads, kMaxSamples);
    }
    const Image reference = reference_image(scene, flags, counts, options, out);
    print_header(out);
    const Convergence c = measure_convergence(
        scene, counts, reference, options, [&](const ConvergencePoint& p) { print_point(out, p); });
    print_summary(out, c, flags.target);
    if (!flags.csv.empty()) {
        std::string text = convergence_csv(c);
        text.pop_back();  // write_text_atomically ends the file with its own newline
        write_text_atomically(flags.csv, text);
    }
}

}  // namespace

int converge_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{
        "Render a scene at several sample counts and show how its error against a "
        "reference falls with samples and with time",
        "drt converge"};
    ConvergeFlags flags;
    flags.add_to(app);
    const std::string& scene_path = flags.scene_path;
    std::vector<int> counts;
    try {
        app.parse(argc, argv);
        counts = parse_counts(flags.counts_text);
        // Only linear floats measure the renderer's error; 8-bit files measure the tone curve.
        for (const std::string& f : {flags.reference_path, flags.save_reference}) {
            if (!f.empty() && !is_linear(format_for_path(f))) {
                throw CLI::ValidationError(f +
                                           ": the reference must be a linear .pfm or .exr image");
            }
        }
        // Before anything renders, so that no render is spent on a file with nowhere to go.
        for (const std::string& f : {flags.save_reference, flags.csv}) {
            if (!f.empty()) check_replaceable(f);
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
        converge(flags, counts, out, err);
    } catch (const std::exception& e) {
        return report_failure(e, "drt converge", printable(scene_path), err);
    }
    return kOk;
}

}  // namespace drt::cli
