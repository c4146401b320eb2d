#include "golden.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "drt/cli/cli.h"
#include "drt/io/compare.h"
#include "drt/scene/scene_loader.h"

namespace drt::golden {

namespace fs = std::filesystem;

namespace {

constexpr int kWidth = 96;
constexpr int kMaxSamples = 32;
constexpr int kMaxShadowRays = 4;
constexpr int kMaxGlossyRays = 4;
constexpr double kRelativeFloor = 1e-3;
constexpr double kAbsoluteFloor = 1e-4;
constexpr std::array kBlockSides{4, 8, 16, 32};
constexpr int kPoolRadius = 2;
constexpr double kClip = 5;
constexpr double kMaxNoiseScale = 2;

fs::path with_suffix(const fs::path& base, const std::string& suffix) {
    return base.parent_path() / (base.filename().string() + suffix);
}

std::string format_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

// Sums over rectangles in O(1) after one pass: entry (x, y) holds the sum over [0, x) × [0, y).
class SummedArea {
  public:
    SummedArea(int width, int height) : w_(width + 1), sums_(std::size_t(w_) * (height + 1), 0.0) {}
    void build(int width, int height, const auto& value) {
        for (int y = 0; y < height; ++y) {
            double row = 0;
            for (int x = 0; x < width; ++x) {
                row += value(x, y);
                at(x + 1, y + 1) = at(x + 1, y) + row;
            }
        }
    }
    double sum(int x0, int y0, int x1, int y1) const {
        return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
    }

  private:
    double& at(int x, int y) { return sums_[std::size_t(y) * w_ + x]; }
    double at(int x, int y) const { return sums_[std::size_t(y) * w_ + x]; }
    int w_;
    std::vector<double> sums_;
};

// Standardised residuals u = clamp(d / σ, ±kClip) per pixel and channel, summed over blocks:
// z = Σu / sqrt(n). Clipping bounds what one pixel can add, so a rare event that the reference
// renders happened to miss cannot fail a block alone; a real change moves many pixels at once.
Verdict test_blocks(int width, int height, const std::vector<double>& u, double max_z) {
    struct Block {
        int side, x0, y0, x1, y1, channel;
        double z;
    };
    std::vector<Block> blocks;
    std::vector<int> sides(kBlockSides.begin(), kBlockSides.end());
    if (std::max(width, height) > sides.back()) sides.push_back(std::max(width, height));
    for (int c = 0; c < 3; ++c) {
        SummedArea sum(width, height);
        sum.build(width, height,
                  [&](int x, int y) { return u[3 * (std::size_t(y) * width + x) + c]; });
        for (const int side : sides) {
            for (int y0 = 0; y0 < height; y0 += side) {
                for (int x0 = 0; x0 < width; x0 += side) {
                    const int x1 = std::min(x0 + side, width), y1 = std::min(y0 + side, height);
                    const double n = double(x1 - x0) * (y1 - y0);
                    blocks.push_back(
                        {side, x0, y0, x1, y1, c, sum.sum(x0, y0, x1, y1) / std::sqrt(n)});
                }
            }
        }
    }

    // The spread of the finest blocks' z about their median, robustly (1.4826 × the median
    // absolute deviation): 1 for an estimator as noisy as the reference's, larger for a noisier
    // one, and hardly moved by a change confined to some blocks or shifting all alike.
    std::vector<double> finest, deviations;
    for (const Block& b : blocks) {
        if (b.side == sides.front()) finest.push_back(b.z);
    }
    const auto median = [](std::vector<double> values) {
        const auto middle = values.begin() + values.size() / 2;
        std::nth_element(values.begin(), middle, values.end());
        return *middle;
    };
    const double centre = median(finest);
    for (const double z : finest) deviations.push_back(std::abs(z - centre));
    Verdict v;
    v.noise_scale = 1.4826 * median(deviations);
    const double scale = std::clamp(v.noise_scale, 1.0, kMaxNoiseScale);

    v.z_map = Image(width, height);
    for (const Block& b : blocks) {
        const double abs_z = std::abs(b.z) / scale;
        if (abs_z > max_z) ++v.failing_blocks;
        if (abs_z > v.max_abs_z) {
            v.max_abs_z = abs_z;
            v.block = b.side, v.x = b.x0, v.y = b.y0, v.channel = b.channel;
        }
        if (b.side != sides.front()) continue;  // the map shows the finest blocks
        for (int y = b.y0; y < b.y1; ++y) {
            for (int x = b.x0; x < b.x1; ++x) {
                float& m = v.z_map.rgb[3 * (std::size_t(y) * width + x)];
                m = std::max(m, static_cast<float>(abs_z));
            }
        }
    }
    for (std::size_t i = 0; i < v.z_map.rgb.size(); i += 3) {
        v.z_map.rgb[i + 1] = v.z_map.rgb[i + 2] = v.z_map.rgb[i];
    }
    v.pass = v.failing_blocks == 0;
    return v;
}

// K renders can all miss an event that is rare in one pixel but happens around it, so a pixel's
// variance is taken as at least the mean variance of its 5 × 5 neighbourhood.
std::vector<double> pooled_variance(const Image& variance) {
    const int w = variance.width, h = variance.height;
    std::vector<double> pooled(variance.rgb.size());
    for (int c = 0; c < 3; ++c) {
        SummedArea sum(w, h);
        sum.build(w, h, [&](int x, int y) {
            return double(variance.rgb[3 * (std::size_t(y) * w + x) + c]);
        });
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                const int x0 = std::max(0, x - kPoolRadius), x1 = std::min(w, x + kPoolRadius + 1);
                const int y0 = std::max(0, y - kPoolRadius), y1 = std::min(h, y + kPoolRadius + 1);
                const double mean = sum.sum(x0, y0, x1, y1) / ((x1 - x0) * (y1 - y0));
                const std::size_t i = 3 * (std::size_t(y) * w + x) + c;
                pooled[i] = std::max(double(variance.rgb[i]), mean);
            }
        }
    }
    return pooled;
}

double floor_variance(double mean) {
    const double f = kRelativeFloor * std::abs(mean) + kAbsoluteFloor;
    return f * f;
}

double clipped(double d, double variance) {
    return std::clamp(d / std::sqrt(variance), -kClip, kClip);
}

void require_same_size(const Image& a, const Image& b, const std::string& what) {
    if (a.width != b.width || a.height != b.height) {
        throw std::runtime_error(what + ": size " + std::to_string(a.width) + "x" +
                                 std::to_string(a.height) + " differs from " +
                                 std::to_string(b.width) + "x" + std::to_string(b.height));
    }
}

}  // namespace

std::vector<std::string> default_args(const fs::path& scene) {
    const RenderSettings s = load_scene(scene).scene.settings;
    return {"--scale",       format_number(double(kWidth) / s.width),
            "--spp",         std::to_string(std::min(s.samples, kMaxSamples)),
            "--shadow-rays", std::to_string(std::min(s.shadow_rays, kMaxShadowRays)),
            "--glossy-rays", std::to_string(std::min(s.glossy_rays, kMaxGlossyRays))};
}

Image render(const fs::path& scene, const std::vector<std::string>& args, std::uint64_t seed,
             const fs::path& scratch) {
    const fs::path output =
        scratch / ("golden-" + std::to_string(getpid()) + "-" + std::to_string(seed) + ".pfm");
    std::vector<std::string> words{"drt", scene.string()};
    words.insert(words.end(), args.begin(), args.end());
    for (const std::string& w : {std::string("--seed"), std::to_string(seed), std::string("-q"),
                                 std::string("-o"), output.string()}) {
        words.push_back(w);
    }
    std::vector<const char*> argv;
    for (const std::string& w : words) argv.push_back(w.c_str());
    std::ostringstream out, err;
    const int status = run_cli(static_cast<int>(argv.size()), argv.data(), out, err);
    if (status != 0) {
        std::string command;
        for (const std::string& w : words) command += w + " ";
        throw std::runtime_error(command + "exited " + std::to_string(status) + ": " + err.str());
    }
    Image image = read_image(output);
    fs::remove(output);
    return image;
}

Reference load_reference(const fs::path& base) {
    Reference r;
    const fs::path text = with_suffix(base, ".txt");
    std::ifstream in(text);
    if (!in) throw std::runtime_error(text.string() + ": cannot open golden description");
    for (std::string line; std::getline(in, line);) {
        std::istringstream words(line);
        std::string key;
        words >> key;
        if (key == "args:") {
            for (std::string w; words >> w;) r.args.push_back(w);
        } else if (key == "renders:") {
            words >> r.renders;
        }
    }
    if (r.renders < 2) throw std::runtime_error(text.string() + ": no 'renders:' count");
    r.mean = read_image(with_suffix(base, ".pfm"));
    r.variance = read_image(with_suffix(base, ".var.pfm"));
    require_same_size(r.variance, r.mean, with_suffix(base, ".var.pfm").string());
    return r;
}

void save_reference(const Reference& r, const fs::path& base) {
    fs::create_directories(base.parent_path());
    write_image(r.mean, with_suffix(base, ".pfm"));
    write_image(r.variance, with_suffix(base, ".var.pfm"));
    std::ostringstream text;
    text << "# Golden reference: made by tools/refresh-goldens.sh (docs/testing.md); do not edit.\n"
         << "args:";
    for (const std::string& a : r.args) text << " " << a;
    text << "\nrenders: " << r.renders << "\ntest-seed: " << kTestSeed
         << "\nreference-seeds: " << kReferenceSeed << " .. " << kReferenceSeed + r.renders - 1
         << "\n";
    const fs::path path = with_suffix(base, ".txt"), tmp = with_suffix(base, ".txt.tmp");
    std::ofstream(tmp) << text.str();
    fs::rename(tmp, path);
}

void Accumulator::add(const Image& image) {
    if (count_ == 0) {
        width_ = image.width, height_ = image.height;
        mean_.assign(image.rgb.size(), 0.0);
        m2_.assign(image.rgb.size(), 0.0);
    }
    if (image.width != width_ || image.height != height_) {
        throw std::runtime_error("renders of one scene differ in size");
    }
    ++count_;
    for (std::size_t i = 0; i < mean_.size(); ++i) {
        const double delta = image.rgb[i] - mean_[i];
        mean_[i] += delta / count_;
        m2_[i] += delta * (image.rgb[i] - mean_[i]);
    }
}

Reference Accumulator::result(std::vector<std::string> args) const {
    if (count_ < 2) throw std::runtime_error("a reference needs at least two renders");
    Reference r;
    r.args = std::move(args);
    r.renders = count_;
    r.mean = Image(width_, height_);
    r.variance = Image(width_, height_);
    for (std::size_t i = 0; i < mean_.size(); ++i) {
        r.mean.rgb[i] = static_cast<float>(mean_[i]);
        r.variance.rgb[i] = static_cast<float>(m2_[i] / (count_ - 1));
    }
    return r;
}

std::string Verdict::summary() const {
    std::ostringstream s;
    s.precision(3);
    s << (pass ? "pass" : "FAIL") << ": max |z| " << max_abs_z << " (block " << block << " px at "
      << x << "," << y << ", channel "
      << "rgb"[channel] << "), " << failing_blocks << " blocks over the bound, rmse " << rmse
      << ", noise " << noise_scale << " × reference's";
    if (nonfinite) s << ", " << nonfinite << " non-finite values";
    return s.str();
}

Verdict check(const Image& render, const Reference& reference, double max_z) {
    require_same_size(render, reference.mean, "render");
    const std::vector<double> pooled = pooled_variance(reference.variance);
    std::vector<double> u(render.rgb.size());
    long long nonfinite = 0;
    for (std::size_t i = 0; i < u.size(); ++i) {
        const double t = render.rgb[i], m = reference.mean.rgb[i];
        nonfinite += !std::isfinite(t);
        // A non-finite value is counted apart and fails alone; 0 keeps it from hiding the rest.
        u[i] = std::isfinite(t)
                   ? clipped(t - m, pooled[i] * (1 + 1.0 / reference.renders) + floor_variance(m))
                   : 0;
    }
    Verdict v = test_blocks(render.width, render.height, u, max_z);
    v.nonfinite = nonfinite;
    v.pass = v.pass && nonfinite == 0;
    v.rmse = compare_images(render, reference.mean).rmse;
    return v;
}

Verdict check_references(const Reference& before, const Reference& after, double max_z) {
    require_same_size(after.mean, before.mean, "new reference");
    const std::vector<double> pooled_before = pooled_variance(before.variance);
    const std::vector<double> pooled_after = pooled_variance(after.variance);
    std::vector<double> u(after.mean.rgb.size());
    for (std::size_t i = 0; i < u.size(); ++i) {
        const double variance = pooled_before[i] / before.renders +
                                pooled_after[i] / after.renders +
                                floor_variance(before.mean.rgb[i]);
        u[i] = clipped(double(after.mean.rgb[i]) - before.mean.rgb[i], variance);
    }
    Verdict v = test_blocks(after.mean.width, after.mean.height, u, max_z);
    v.rmse = compare_images(after.mean, before.mean).rmse;
    return v;
}

Image z_image(const Verdict& verdict, double max_z) {
    Image image(verdict.z_map.width, verdict.z_map.height);
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
            image.set(x, y, false_colour(verdict.z_map.at(x, y).r / max_z));
        }
    }
    return image;
}

std::vector<fs::path> scene_files(const fs::path& scenes) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(scenes)) {
        if (entry.is_regular_file() && entry.path().extension() == ".xml") {
            files.push_back(fs::relative(entry.path(), scenes));
        }
    }
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace drt::golden
