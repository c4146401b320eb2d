#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.h"
#include "cli_render.h"
#include "drt/goal/goal_render.h"
#include "drt/io/image.h"
#include "drt/job/checkpoint.h"
#include "drt/job/mpi_work.h"
#include "drt/job/render_job.h"
#include "drt/render/aov.h"
#include "drt/render/error_estimate.h"
#include "drt/render/render_plan.h"
#include "drt/scene/render_limits.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/atomic_file.h"
#include "drt/util/interrupt.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt::cli {

namespace fs = std::filesystem;

namespace {

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
// It never goes back: the share of a tile's pixels counts until the tile is handed in, and a
// tile between the two counts nothing for a moment.
class ProgressDisplay {
  public:
    ProgressDisplay(std::ostream& err, std::string label) : err_(err), label_(std::move(label)) {}
    void operator()(double done) {
        done = shown_ = std::max(shown_, done);
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
    double shown_ = 0;
};

// --target-error and --time-limit: rounds of renders until the goal (goal_render.h).
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

// What the render command was asked, shared by every scene it renders.
struct RenderCommand {
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
    std::vector<Aov> aovs;    // --aov: one scene with an .exr output only
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
                                 const RenderCommand& job) {
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

bool is_exr_path(const std::string& path) {
    try {
        return format_for_path(path) == ImageFormat::kExr;
    } catch (const ImageError&) {
        return false;
    }
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
std::string goal_summary(const std::string& name, const GoalResult& p, const GoalFlags& goal,
                         double seconds) {
    std::ostringstream line;
    line << "drt: " << name << ": " << p.samples << " spp after ";
    const char* separator = "rounds of ";
    // In the order they ran: "rounds of 8, 18 spp", then any top-up, and a full round after a
    // top-up (a time limit's cut) as "a round of N spp".
    bool listing = false;  // inside the list of full rounds, " spp" still to come
    bool topped = false;
    for (const GoalRound& r : p.rounds) {
        if (r.kind == RoundKind::kPilot) {
            line << "a pilot of " << r.spp << " spp on 1 pixel in " << r.pixel_block * r.pixel_block
                 << ", ";
        } else if (r.top_up()) {
            line << (listing ? " spp" : "") << ", a top-up of 2 x " << r.spp << " spp on "
                 << std::fixed << std::setprecision(2) << 100 * r.top_up_share << std::defaultfloat
                 << " % of the pixels";
            listing = false;
            topped = true;
        } else if (topped) {
            line << ", a round of " << r.spp << " spp";
        } else {
            line << separator << r.spp;
            separator = ", ";
            listing = true;
        }
    }
    line << (listing ? " spp" : "") << "; estimated rmse "
         << (p.error ? short_number(*p.error) : std::string("n/a"));
    if (goal.target_error) {
        line << " (target " << short_number(*goal.target_error)
             << (p.target_met ? " met)"
                 : p.error    ? " not met)"
                              : " not met: without an estimate no more samples can be judged)");
    }
    if (goal.time_limit) {
        line << "; " << std::fixed << std::setprecision(2) << seconds << " s of the "
             << short_number(*goal.time_limit) << " s limit" << std::defaultfloat;
    }
    const auto full = std::count_if(p.rounds.begin(), p.rounds.end(),
                                    [](const GoalRound& r) { return r.kind != RoundKind::kPilot; });
    if (!p.combined || full == 1) {
        // A target error's one full round is the plain render of its count (goal_render.h).
        line << "\ndrt: " << name << ": --spp " << p.samples
             << " renders the same image (bit-identical) without a goal\n";
    } else {
        // Stopped, the same command would go on to more rounds: only their start is the same.
        line << "\ndrt: " << name
             << ": the rounds' images combined (weighted by 1 / estimated variance); the same "
                "command renders the same image "
             << (goal.time_limit || p.stopped ? "where it completes the same rounds\n"
                                              : "(bit-identical) every run\n");
    }
    return line.str();
}

// `<stem>.partial.<ext>` beside the output: an interrupted render's finished tiles.
fs::path partial_path(const fs::path& output) {
    return output.parent_path() /
           (output.stem().string() + ".partial" + output.extension().string());
}

// `<stem>.nonfinite.pfm` beside the output: a render with non-finite pixels fails (exit 2) and
// leaves the output as it was; the image is kept here, as a .pfm since it holds NaN and infinity.
fs::path nonfinite_path(const fs::path& output) {
    return output.parent_path() / (output.stem().string() + ".nonfinite.pfm");
}

// Runs `step`, turning every exception into a message and a status.
template <typename Step>
int guarded(const std::string& name, std::ostream& err, Step&& step) {
    try {
        step();
        return kOk;
    } catch (const std::exception& e) {
        return report_failure(e, "drt", name, err);
    }
}

// One scene, start to end. Everything that can go wrong ends here as a message and a status, so
// that a batch goes on with its other scenes: this is the job boundary. Under MPI every process
// runs it, and all agree on the status after each step, so that none waits for another that
// gave up.
SceneOutcome render_one(const std::string& scene_path, const fs::path& output,
                        const std::optional<fs::path>& checkpoint, const RenderCommand& job,
                        std::ostream& err) {
    const auto start = std::chrono::steady_clock::now();  // a time limit counts from here
    SceneOutcome outcome;
    outcome.scene = scene_path;
    const std::string name = printable(scene_path);
    std::optional<LoadedScene> loaded;
    std::vector<fs::path> scene_files;
    std::uint64_t scene_files_hash = 0;
    int status = guarded(name, err, [&] {
        format_for_path(output);  // refuse an unknown extension before spending time rendering
        loaded.emplace(load_scene(scene_path));
        scene_files = {scene_path};
        scene_files.insert(scene_files.end(), loaded->files_read.begin(), loaded->files_read.end());
        // Once a scene, where a failure is still agreed on: the processes compare it before
        // each render (run_render_job).
        if (job.mpi && job.mpi->size() > 1) scene_files_hash = hash_files(scene_files);
        for (const std::string& w : loaded->warnings) err << w << "\n";
        job.overrides.apply(loaded->scene.settings);
        // The error estimate measures noise; a photon-mapped caustic is also biased at every
        // finite gather radius, so no goal can rest on it (docs/accuracy.md).
        if (job.goal.wanted() && plan_render(loaded->scene).effects.caustics) {
            throw LimitError(
                std::string(job.goal.target_error ? "--target-error" : "--time-limit") +
                " cannot be used with <Photons>: caustics from photon maps are "
                "biased at every finite gather radius, which the error estimate "
                "does not see; give Samples instead (docs/accuracy.md)");
        }
        RenderSettings largest = loaded->scene.settings;
        if (job.goal.wanted() && !job.overrides.spp) largest.samples = kMaxSamples;
        if (const auto problem = render_limit_problem(
                largest, job.threads, static_cast<int>(aov_channel_count(job.aovs)))) {
            throw LimitError(*problem);
        }
    });
    if (status == kOk && job.leader()) {
        // Before the render, so that no work is spent (nor a checkpoint lost) on an image with
        // nowhere to go; a failed write, as it would be after the render (status 1).
        try {
            check_replaceable(output);
        } catch (const FileWriteError& e) {
            err << "drt: " << e.what() << "\n";
            status = kFailed;
        }
    }
    if (const int agreed = job.agree(status); agreed != kOk) {
        if (status == kOk) err << "drt: " << name << ": failed in another process\n";
        outcome.status = agreed;
        return outcome;
    }
    const Scene& scene = loaded->scene;
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    request.adaptive = job.adaptive.settings();
    // Photon-mapped caustics get no estimate (renderer.h): its second renders would be wasted.
    request.estimate_error = (job.estimate_shown || format_for_path(output) == ImageFormat::kExr) &&
                             !plan_render(scene).effects.caustics;
    request.aovs = job.aovs;
    RenderJobOptions options;
    options.threads = job.threads;
    options.checkpoint = checkpoint;
    options.scene_files = std::move(scene_files);
    options.scene_files_hash = scene_files_hash;
    options.checkpoint_interval = std::chrono::duration<double>(job.checkpoint_seconds);
    options.stop_after_tiles = job.stop_after_tiles;
    options.costly_first = !job.grid_order;
    options.stop = job.stop;
    options.mpi = job.mpi;
    std::optional<ProgressDisplay> display;
    if (job.progress && job.leader()) {
        display.emplace(err, printable(fs::path(scene_path).filename().string()));
        options.on_progress = [&](double done) { (*display)(done); };
    }
    RenderJobResult r;
    std::optional<GoalResult> rounds;
    status = guarded(name, err, [&] {
        if (!job.goal.wanted()) {
            r = run_render_job(scene, request, options);
            return;
        }
        RenderGoal goal;
        goal.target_error = job.goal.target_error;
        goal.time_limit = job.goal.time_limit;
        goal.max_samples = job.overrides.spp.value_or(kMaxSamples);
        goal.start = start;
        rounds = render_to_goal(scene, options, goal);
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
    const std::size_t nonfinite = r.complete() ? count_nonfinite(result.image) : 0;
    const fs::path target = !r.complete()   ? partial_path(output)
                            : nonfinite > 0 ? nonfinite_path(output)
                                            : output;
    ImageWriteOptions written = output_options(scene, result, job);
    if (!result.aov_list.empty() && format_for_path(target) == ImageFormat::kExr) {
        written.extra = {aov_channel_names(result.aov_list), result.aovs};
    }
    try {
        write_image(result.image, target, written);
    } catch (const ImageError& e) {
        err << "drt: " << e.what() << "\n";
        outcome.status = job.agree(kFailed);
        return outcome;
    }
    if (!r.complete()) {
        err << "drt: " << name << ": interrupted with " << r.done << " of " << r.tiles
            << " tiles done; wrote " << printable(target.string());
        if (checkpoint && !r.checkpoint_failure.empty()) {
            // The rendered tiles are in the partial image, but no run can resume them.
            err << "\ndrt: " << printable(r.checkpoint_failure)
                << "\ndrt: the checkpoint could not be written: this render cannot be resumed\n";
            outcome.status = job.agree(kFailed);
            return outcome;
        }
        if (checkpoint) {
            err << " and " << printable(checkpoint->string())
                << "\ndrt: run the same command again to resume\n";
        } else if (job.goal.wanted()) {
            // A goal's rounds keep no checkpoint (--checkpoint excludes them): no hint to one.
            err << " (the goal's first round; a goal render cannot be resumed)\n";
        } else {
            err << "\ndrt: with --checkpoint FILE an interrupted render can be resumed\n";
        }
        outcome.status = job.agree(interrupted_status());
        return outcome;
    }
    outcome.json = stats_json(
        scene, result,
        rounds ? goal_json(*rounds, job.goal.target_error, job.goal.time_limit) : std::string());
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
        err << "drt: wrote " << printable(target.string()) << " (" << outcome.width << "x"
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
        err << "drt: " << name << ": interrupted; kept "
            << (rounds->combined ? "the complete rounds combined\n" : "the last complete round\n");
        outcome.status = job.agree(interrupted_status());
        return outcome;
    }
    // Kept for inspection, but not a success: no pixel may be silently lost.
    if (nonfinite > 0) {
        err << "drt: " << name << ": " << nonfinite << " of " << result.image.rgb.size()
            << " channel values are not finite (radiance beyond the float range: a light, "
               "background or ambient too bright?)\ndrt: "
            << name << ": " << printable(output.string())
            << " not written; the image is kept for inspection in " << printable(target.string())
            << "\n";
        status = kBadInput;
    }
    outcome.status = job.agree(status);
    return outcome;
}

// Where one scene's image and checkpoint go: with several scenes (or -o DIR/), each is named
// after its scene file inside the -o and --checkpoint folders.
struct SceneFiles {
    fs::path image;
    std::optional<fs::path> checkpoint;
};

SceneFiles files_of(const std::string& scene, const std::string& output,
                    const std::string& checkpoint, bool batch) {
    const std::string stem = fs::path(scene).stem().string();
    SceneFiles f{stem + ".png", std::nullopt};
    if (!checkpoint.empty()) f.checkpoint = fs::path(checkpoint);
    if (batch) {
        if (!output.empty()) f.image = fs::path(output) / f.image;
        if (f.checkpoint) *f.checkpoint /= stem + ".checkpoint";
    } else if (!output.empty()) {
        f.image = output;
    }
    return f;
}

// What names one file, worked out once per path: its device and inode where it exists (so any
// link to it has the same key), else its path made absolute and normal, with the symbolic links
// of the part that exists resolved.
std::string file_key(const fs::path& path) {
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0) {
        return std::to_string(info.st_dev) + ":" + std::to_string(info.st_ino);
    }
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(path, error), error);
    return (error ? fs::absolute(path).lexically_normal() : canonical).string();
}

// Two of the files a command writes that are one file, which would destroy each other (a
// checkpoint is removed once the image is written; a batch's second image replaces the first).
// A scene given twice writes the same image twice, which destroys nothing.
std::optional<std::string> clashing_files(const std::vector<std::string>& scenes,
                                          const std::string& output, const std::string& stats,
                                          const RenderCommand& job, bool batch) {
    struct Written {
        std::string what;  // what writes it, for the message
        fs::path file;
        std::string key;        // file_key(file)
        std::string scene_key;  // file_key of the scene whose image or checkpoint it is, if any
        bool checkpoint;        // a scene's checkpoint, not its image
    };
    std::vector<Written> files;
    for (const std::string& scene : scenes) {
        const SceneFiles f = files_of(scene, output, job.checkpoint, batch);
        const std::string of = batch ? " of " + printable(scene) : "";
        const std::string scene_key = file_key(scene);
        files.push_back({std::string(batch || output.empty() ? "the image" : "-o") + of, f.image,
                         file_key(f.image), scene_key, false});
        if (f.checkpoint) {
            files.push_back({std::string(batch ? "the checkpoint" : "--checkpoint") + of,
                             *f.checkpoint, file_key(*f.checkpoint), scene_key, true});
        }
    }
    if (!job.error_image.empty()) {
        files.push_back({"--error-image", job.error_image, file_key(job.error_image), "", false});
    }
    if (!stats.empty() && stats != "-") {
        files.push_back({"--stats", stats, file_key(stats), "", false});
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
        for (std::size_t j = i + 1; j < files.size(); ++j) {
            const Written &a = files[i], &b = files[j];
            if (a.key != b.key) continue;
            const bool one_scene_twice =
                !a.scene_key.empty() && a.scene_key == b.scene_key && a.checkpoint == b.checkpoint;
            if (one_scene_twice) continue;
            return a.what + " and " + b.what + " are one file, " + printable(b.file.string()) +
                   ": one would destroy the other";
        }
    }
    return std::nullopt;
}

}  // namespace

int render_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
                   const MpiJob* mpi) {
    CLI::App app{
        "drt: distributed ray tracer (Cook, Porter & Carpenter 1984).\n"
        "Also: drt compare A B [--max-rmse X] [--diff D.png] | drt info SCENE.xml | "
        "drt converge SCENE.xml --spp 1,4,16",
        "drt"};
    std::vector<std::string> scenes;
    std::string output, stats, aov_list;
    RenderCommand job;
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
    CLI::Option* aov = app.add_option(
        "--aov", aov_list,
        "With an .exr output, also write first-hit AOVs as extra channels: a comma-separated "
        "list of albedo, normal, depth");
    app.add_flag("-q,--quiet", job.quiet, "No progress display or messages besides errors");
    app.add_flag("--progress", force_progress, "Show progress even when stderr is not a terminal");
    CLI::Option* checkpoint =
        app.add_option("--checkpoint", job.checkpoint,
                       "Keep finished work in FILE (with several scenes, a folder); running the "
                       "same command again resumes from it; removed when the render completes");
    job.goal.add_to(app, {threshold, checkpoint, aov});
    app.add_option("--checkpoint-every", job.checkpoint_seconds,
                   "Seconds between checkpoint writes (default 30)")
        ->check(finite_non_negative());
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
    if (aov->count() > 0) {
        try {
            job.aovs = parse_aovs(aov_list);
        } catch (const std::invalid_argument& e) {
            err << "drt: --aov: " << e.what() << "\nRun 'drt --help' for usage.\n";
            return kBadInput;
        }
        std::string refused;
        if (batch) {
            refused = "takes one scene, not a batch";
        } else if (output.empty() || fs::path(output).extension().string().empty() ||
                   !is_exr_path(output)) {
            refused =
                "needs an .exr output (-o FILE.exr): only OpenEXR holds the extra "
                "channels";
        }
        if (!refused.empty()) {
            err << "drt: --aov " << refused << "\nRun 'drt --help' for usage.\n";
            return kBadInput;
        }
    }
    if (report.wanted && !(batch && !output.empty())) {
        err << "drt: --report needs a batch: -o DIR/\nRun 'drt --help' for usage.\n";
        return kBadInput;
    }
    if (const auto clash = clashing_files(scenes, output, stats, job, batch)) {
        err << "drt: " << *clash << "\nRun 'drt --help' for usage.\n";
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
        const SceneFiles files = files_of(scene, output, job.checkpoint, batch);
        outcomes.push_back(render_one(scene, files.image, files.checkpoint, job, err));
        outcomes.back().output = files.image;
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

}  // namespace drt::cli
