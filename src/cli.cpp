#include "drt/cli.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "drt/compare.h"
#include "drt/image.h"
#include "drt/render_plan.h"
#include "drt/renderer.h"
#include "drt/sampler.h"
#include "drt/scene_loader.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

constexpr int kOk = 0;
constexpr int kFailed = 1;
constexpr int kBadInput = 2;

// Command-line settings that override the scene's <Image> and <Render>.
struct Overrides {
    std::optional<int> spp, shadow_rays, width, height, glossy_rays, max_depth;
    std::optional<std::uint64_t> seed;
    std::optional<std::string> sampler;
    std::optional<double> scale;

    void add_to(CLI::App& app) {
        app.add_option("--spp", spp, "Camera samples per pixel (overrides Render Samples)")
            ->check(CLI::PositiveNumber);
        app.add_option("--shadow-rays", shadow_rays, "Overrides Render ShadowRays")
            ->check(CLI::PositiveNumber);
        app.add_option("--width", width, "Overrides Image Width")->check(CLI::PositiveNumber);
        app.add_option("--height", height, "Overrides Image Height")->check(CLI::PositiveNumber);
        app.add_option("--scale", scale,
                       "Multiplies the image size, keeping the framing (applied after --width and "
                       "--height)")
            ->check(CLI::PositiveNumber);
        app.add_option("--seed", seed, "Overrides Render Seed");
        app.add_option("--glossy-rays", glossy_rays, "Overrides Render GlossyRays")
            ->check(CLI::PositiveNumber);
        app.add_option("--max-depth", max_depth, "Overrides Render MaxDepth")
            ->check(CLI::NonNegativeNumber);
        app.add_option("--sampler", sampler, "Sampler: random or stratified (default)")
            ->check(CLI::IsMember(sampler_names()));
    }

    void apply(RenderSettings& s) const {
        if (spp) s.samples = *spp;
        if (shadow_rays) s.shadow_rays = *shadow_rays;
        if (width) s.width = *width;
        if (height) s.height = *height;
        if (scale) {
            s.width = std::max(1, static_cast<int>(std::lround(s.width * *scale)));
            s.height = std::max(1, static_cast<int>(std::lround(s.height * *scale)));
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
    if (total >= 3600) s << total / 3600 << ":" << std::setw(2) << std::setfill('0') << (total / 60) % 60;
    else s << total / 60;
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
        if (done > 0 && done < 1) err_ << ", " << format_duration(left) << " left ";
        else err_ << "         ";
        if (done >= 1) err_ << "\n";
        err_ << std::flush;
    }

private:
    std::ostream& err_;
    std::string label_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

std::string json_bool(bool b) { return b ? "true" : "false"; }

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\', out += c;
        else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else out += c;
    }
    return out + "\"";
}

std::string stats_json(const Scene& scene, const RenderResult& r) {
    const RayCounts& rays = r.stats.rays;
    const Effects& e = r.plan.effects;
    const RenderSettings& s = scene.settings;
    std::ostringstream j;
    j << std::setprecision(6);
    j << "{\n  \"scene\": " << json_string(scene.path) << ",\n"
      << "  \"seconds\": " << r.stats.seconds << ",\n"
      << "  \"width\": " << s.width << ", \"height\": " << s.height
      << ", \"samples_per_pixel\": " << s.samples << ",\n"
      << "  \"shadow_rays\": " << s.shadow_rays << ", \"glossy_rays\": " << s.glossy_rays
      << ", \"max_depth\": " << s.max_depth << ", \"seed\": " << s.seed
      << ", \"sampler\": " << json_string(s.sampler) << ", \"threads\": " << r.stats.threads << ",\n"
      << "  \"rays\": {\"camera\": " << rays.camera << ", \"shadow\": " << rays.shadow
      << ", \"reflection\": " << rays.reflection << ", \"refraction\": " << rays.refraction
      << ", \"total\": " << rays.total() << "},\n"
      << "  \"million_rays_per_second\": "
      << (r.stats.seconds > 0 ? rays.total() / r.stats.seconds / 1e6 : 0.0) << ",\n"
      << "  \"effects\": {\"antialiasing\": " << json_bool(e.antialiasing)
      << ", \"soft_shadows\": " << json_bool(e.soft_shadows)
      << ", \"glossy_reflection\": " << json_bool(e.glossy_reflection)
      << ", \"glossy_refraction\": " << json_bool(e.glossy_refraction)
      << ", \"depth_of_field\": " << json_bool(e.depth_of_field)
      << ", \"motion_blur\": " << json_bool(e.motion_blur) << "}\n}";
    return j.str();
}

// Writes text through a temporary file and a rename, like the images.
void write_text_atomically(const fs::path& path, const std::string& text) {
    const fs::path tmp = path.parent_path() /
                         ("." + path.filename().string() + ".tmp-" + std::to_string(getpid()));
    {
        std::ofstream f(tmp, std::ios::binary);
        f << text << "\n";
        f.close();
        if (!f) {
            std::error_code ignored;
            fs::remove(tmp, ignored);
            throw std::runtime_error(path.string() + ": cannot write file");
        }
    }
    fs::rename(tmp, path);
}

struct SceneOutcome {
    std::string scene;
    int status = kOk;
    int width = 0, height = 0, samples = 0;
    double seconds = 0;
    double mrays_per_second = 0;
    std::string json;
};

struct RenderJob {
    Overrides overrides;
    int threads = 0;
    bool quiet = false;
    bool progress = false;
};

SceneOutcome render_one(const std::string& scene_path, const fs::path& output, const RenderJob& job,
                        std::ostream& err) {
    SceneOutcome outcome;
    outcome.scene = scene_path;
    try {
        format_for_path(output);  // refuse an unknown extension before spending time rendering
        LoadedScene loaded = load_scene(scene_path);
        for (const std::string& w : loaded.warnings) err << w << "\n";
        Scene& scene = loaded.scene;
        job.overrides.apply(scene.settings);
        RenderOptions options;
        options.threads = job.threads;
        std::optional<ProgressDisplay> display;
        if (job.progress) {
            display.emplace(err, fs::path(scene_path).filename().string());
            options.on_progress = [&](double done) { (*display)(done); };
        }
        const RenderResult result = render(scene, options);
        outcome.width = scene.settings.width;
        outcome.height = scene.settings.height;
        outcome.samples = scene.settings.samples;
        outcome.seconds = result.stats.seconds;
        outcome.mrays_per_second =
            result.stats.seconds > 0 ? result.stats.rays.total() / result.stats.seconds / 1e6 : 0;
        outcome.json = stats_json(scene, result);
        try {
            write_image(result.image, output);
        } catch (const ImageError& e) {
            err << "drt: " << e.what() << "\n";
            outcome.status = kFailed;
            return outcome;
        }
        if (!job.quiet) {
            err << "drt: wrote " << output.string() << " (" << outcome.width << "x" << outcome.height
                << ", " << outcome.samples << " spp, " << std::fixed << std::setprecision(2)
                << outcome.seconds << " s)\n"
                << std::defaultfloat;
        }
    } catch (const SceneError& e) {
        err << e.what() << "\n";
        outcome.status = kBadInput;
    } catch (const ImageError& e) {
        err << "drt: " << e.what() << "\n";
        outcome.status = kBadInput;
    } catch (const std::exception& e) {
        err << "drt: " << scene_path << ": " << e.what() << "\n";
        outcome.status = kFailed;
    }
    return outcome;
}

void print_summary(const std::vector<SceneOutcome>& outcomes, std::ostream& out) {
    out << std::left << std::setw(32) << "scene" << std::right << std::setw(11) << "size"
        << std::setw(9) << "samples" << std::setw(10) << "seconds" << std::setw(10) << "Mrays/s"
        << "  status\n";
    for (const SceneOutcome& o : outcomes) {
        std::ostringstream size;
        if (o.width > 0) size << o.width << "x" << o.height;
        out << std::left << std::setw(32) << fs::path(o.scene).filename().string() << std::right
            << std::setw(11) << size.str() << std::setw(9) << (o.samples ? std::to_string(o.samples) : "")
            << std::fixed << std::setprecision(2) << std::setw(10) << o.seconds << std::setw(10)
            << o.mrays_per_second << std::defaultfloat << "  "
            << (o.status == kOk ? "ok" : o.status == kFailed ? "failed" : "bad input") << "\n";
    }
}

bool is_folder_target(const std::string& output) {
    return !output.empty() && (output.back() == '/' || fs::is_directory(output));
}

int render_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"drt: distributed ray tracer (Cook, Porter & Carpenter 1984).\n"
                 "Also: drt compare A B [--max-rmse X] [--diff D.png] | drt info SCENE.xml",
                 "drt"};
    std::vector<std::string> scenes;
    std::string output, stats;
    RenderJob job;
    bool force_progress = false;
    app.add_option("scenes", scenes, "Scene file(s) in the thesis XML format")->required();
    app.add_option("-o,--output", output,
                   "Output image (.png, .bmp, .pfm); with several scenes, a folder");
    job.overrides.add_to(app);
    app.add_option("--threads", job.threads, "Worker threads (default: all cores)")
        ->check(CLI::PositiveNumber);
    app.add_option("--stats", stats, "Write render statistics as JSON to FILE (- = stdout)");
    app.add_flag("-q,--quiet", job.quiet, "No progress display or messages besides errors");
    app.add_flag("--progress", force_progress, "Show progress even when stderr is not a terminal");
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
        err << "drt: " << e.what() << "\nRun 'drt --help' for usage.\n";
        return kBadInput;
    }
    job.progress = !job.quiet && (force_progress || isatty(STDERR_FILENO));

    const bool batch = scenes.size() > 1 || is_folder_target(output);
    std::vector<SceneOutcome> outcomes;
    for (const std::string& scene : scenes) {
        fs::path target = fs::path(scene).stem().string() + ".png";
        if (batch && !output.empty()) {
            std::error_code ec;
            fs::create_directories(output, ec);
            if (ec) {
                err << "drt: " << output << ": cannot create folder: " << ec.message() << "\n";
                return kFailed;
            }
            target = fs::path(output) / target;
        } else if (!output.empty()) {
            target = output;
        }
        outcomes.push_back(render_one(scene, target, job, err));
    }

    int status = kOk;
    for (const SceneOutcome& o : outcomes) status = std::max(status, o.status);
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
    return status;
}

int compare_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"Compare two images (.png, .bmp, .pfm) of equal size", "drt compare"};
    std::string a, b, diff;
    std::optional<double> max_rmse, min_psnr;
    app.add_option("A", a, "First image")->required();
    app.add_option("B", b, "Second image")->required();
    app.add_option("--max-rmse", max_rmse, "Exit 1 when the RMSE exceeds X")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--min-psnr", min_psnr, "Exit 1 when the PSNR falls below Y (dB)");
    app.add_option("--diff", diff, "Write a false-colour difference image to D (.png, .bmp, .pfm)");
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << "drt compare: " << e.what() << "\nRun 'drt compare --help' for usage.\n";
        return kBadInput;
    }
    Comparison c;
    try {
        const Image image_a = read_image(a);
        const Image image_b = read_image(b);
        c = compare_images(image_a, image_b);
        if (!diff.empty()) write_image(difference_image(image_a, image_b), diff);
    } catch (const ImageError& e) {
        err << "drt compare: " << e.what() << "\n";
        return kBadInput;
    }
    out << std::setprecision(6) << "rmse=" << c.rmse << " psnr=" << c.psnr << " ssim=" << c.ssim
        << " max=" << c.max_abs << "\n";
    if (max_rmse && c.rmse > *max_rmse) {
        err << "drt compare: rmse " << c.rmse << " exceeds --max-rmse " << *max_rmse << "\n";
        return kFailed;
    }
    if (min_psnr && c.psnr < *min_psnr) {
        err << "drt compare: psnr " << c.psnr << " is below --min-psnr " << *min_psnr << "\n";
        return kFailed;
    }
    return kOk;
}

int info_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"Show what a scene contains and which effects it calls for", "drt info"};
    std::string scene_path;
    Overrides overrides;
    app.add_option("scene", scene_path, "Scene file")->required();
    overrides.add_to(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kOk;
    } catch (const CLI::ParseError& e) {
        err << "drt info: " << e.what() << "\nRun 'drt info --help' for usage.\n";
        return kBadInput;
    }
    try {
        LoadedScene loaded = load_scene(scene_path);
        for (const std::string& w : loaded.warnings) err << w << "\n";
        overrides.apply(loaded.scene.settings);
        out << describe(loaded.scene, plan_render(loaded.scene));
    } catch (const SceneError& e) {
        err << e.what() << "\n";
        return kBadInput;
    }
    return kOk;
}

}  // namespace

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    if (argc >= 2) {
        const std::string command = argv[1];
        // CLI11 takes the program name from argv[0]; hand it "drt compare" and the rest.
        if (command == "compare") return compare_command(argc - 1, argv + 1, out, err);
        if (command == "info") return info_command(argc - 1, argv + 1, out, err);
    }
    return render_command(argc, argv, out, err);
}

}  // namespace drt
