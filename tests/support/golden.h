// Golden-image regression testing with a statistical test (docs/testing.md): each scene in
// scenes/ is rendered small at a fixed seed and compared with a reference made of many renders
// at other seeds: their per-pixel mean and the per-pixel variance of one render. Shared by the
// golden tests and the drt_golden tool that tools/refresh-goldens.sh runs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "drt/io/image.h"

namespace drt::golden {

// The seed of the render under test; references use seeds kReferenceSeed, kReferenceSeed + 1, ….
inline constexpr std::uint64_t kTestSeed = 7;
inline constexpr std::uint64_t kReferenceSeed = 1000;
inline constexpr int kDefaultRenders = 64;

// Family-wise bound on |z| for every block at every scale (see check()).
inline constexpr double kMaxZ = 6.0;

// The render options a new golden uses for a scene: about 96 pixels wide with the scene's own
// framing, and capped sample counts that keep every effect the scene calls for.
std::vector<std::string> default_args(const std::filesystem::path& scene);

// Renders through the command line in-process (the same code path as the drt binary).
// Throws std::runtime_error with drt's messages when it fails.
Image render(const std::filesystem::path& scene, const std::vector<std::string>& args,
             std::uint64_t seed, const std::filesystem::path& scratch);

struct Reference {
    std::vector<std::string> args;  // render options, without seed and output
    int renders = 0;                // how many seeds the mean and variance come from
    Image mean;                     // per-pixel mean of the renders
    Image variance;                 // per-pixel sample variance of one render
};

// Files: <base>.pfm (mean), <base>.var.pfm (variance), <base>.txt (options and render count).
// `base` is the golden folder joined with the scene's path inside scenes/, less ".xml".
Reference load_reference(const std::filesystem::path& base);
void save_reference(const Reference& reference, const std::filesystem::path& base);

// Adds renders one at a time (Welford's update, in double) and yields the mean and variance.
class Accumulator {
  public:
    void add(const Image& image);
    Reference result(std::vector<std::string> args) const;

  private:
    int count_ = 0, width_ = 0, height_ = 0;
    std::vector<double> mean_, m2_;
};

struct Verdict {
    bool pass = true;
    long long nonfinite = 0;  // NaN or infinite channel values in the render
    double max_abs_z = 0;     // the largest |z| over all blocks, scales and channels
    int block = 0, x = 0, y = 0, channel = 0;  // where: block side in pixels and its top-left
    int failing_blocks = 0;                    // blocks over the bound, all scales and channels
    double rmse = 0;                           // of the render against the mean, for people
    double noise_scale = 1;  // the render's noise over the reference's, from the spread of z
    Image z_map;             // per pixel, |z| of the 4 × 4 block containing it
    std::string summary() const;
};

// The statistical test. Each pixel and channel gives a standardised residual
// u = clamp((render − mean) / σ, ±5) with σ² = v · (1 + 1/renders) + floor², where v is the
// pixel's variance or, when larger, the mean variance of its 5 × 5 neighbourhood (K renders can
// all miss an event that is rare in one pixel), and floor = 1e-3 · |mean| + 1e-4 stands for
// rounding where the renders agreed exactly. For every square block of side 4, 8, 16, 32 pixels
// and the whole image, z = Σu / sqrt(n): under "same expected image, other random numbers" each
// z is close to standard normal (pixels are independent). The z are divided by the spread of the
// 4 × 4 blocks' z about their median (robustly, kept within [1, 2]), so a sampler up to twice as
// noisy as the reference's still passes while a shift of the expected image does not. The render
// passes when every |z| ≤ max_z and every value is finite. Clipping bounds what one pixel can
// add, so a change must move several pixels to fail: one deviating pixel is below the resolution.
Verdict check(const Image& render, const Reference& reference, double max_z = kMaxZ);

// The same test between two references, each mean carrying variance/renders: did refreshing
// change the expected image, or only its noise?
Verdict check_references(const Reference& before, const Reference& after, double max_z = kMaxZ);

// A false-colour image of z_map: black at 0, red at max_z and beyond.
Image z_image(const Verdict& verdict, double max_z = kMaxZ);

// Every scene file below `scenes`, as paths relative to it, sorted.
std::vector<std::filesystem::path> scene_files(const std::filesystem::path& scenes);

}  // namespace drt::golden
