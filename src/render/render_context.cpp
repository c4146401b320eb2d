#include "drt/render/render_context.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "drt/render/error_estimate.h"
#include "drt/util/parallel.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

// The standard error of the mean of a pixel's sample values. Independent samples: the sample
// deviation over sqrt(n). A progressive sampler's samples split into 8 consecutive runs that are
// each a stratified pattern of their own, so the spread of the 8 run means over sqrt(8) measures
// the error stratification leaves; the spread of single samples would overstate it at every edge
// (by n^(1/4) for an edge, whose stratified error falls as n^(-3/4)).
double standard_error(std::span<const double> v, bool progressive) {
    constexpr std::size_t kRuns = 8;
    const std::size_t n = v.size();
    if (n < 2) return std::numeric_limits<double>::infinity();
    const auto spread = [](std::span<const double> x) {  // sample variance
        double mean = 0, m2 = 0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            const double delta = x[i] - mean;
            mean += delta / double(i + 1);
            m2 += delta * (x[i] - mean);
        }
        return m2 / double(x.size() - 1);
    };
    if (!progressive || n < 2 * kRuns) return std::sqrt(spread(v) / double(n));
    std::array<double, kRuns> means{};
    for (std::size_t g = 0; g < kRuns; ++g) {
        const std::size_t begin = g * n / kRuns, end = (g + 1) * n / kRuns;
        for (std::size_t i = begin; i < end; ++i) means[g] += v[i];
        means[g] /= double(end - begin);
    }
    return std::sqrt(spread(means) / double(kRuns));
}

std::unique_ptr<Sampler> sampler_named(const std::string& name) {
    auto sampler = make_sampler(name);
    if (!sampler) throw std::invalid_argument("unknown sampler '" + name + "'");
    return sampler;
}

}  // namespace

RenderContext::RenderContext(const Scene& scene, std::optional<AdaptiveSampling> adaptive,
                             bool estimate_error, int pixel_block,
                             std::span<const std::uint32_t> top_up)
    : scene_(scene),
      sampler_(sampler_named(scene.settings.sampler)),
      plan_(plan_render(scene)),
      bvh_(scene.objects),
      integrator_(make_integrator(scene, plan_, bvh_, *sampler_)),
      adaptive_(adaptive),
      estimate_error_(estimate_error),
      pixel_block_(std::max(1, pixel_block)),
      tiles_(tile_grid(scene.settings.width, scene.settings.height)) {
    if (adaptive_) {
        adaptive_->min_samples = std::clamp(adaptive_->min_samples, 1, scene.settings.samples);
    }
    // A plain render (block 1) counts every pixel at once; a pilot takes one hash a square.
    const auto width = static_cast<std::uint64_t>(scene.settings.width);
    const auto height = static_cast<std::uint64_t>(scene.settings.height);
    const auto b = static_cast<std::uint64_t>(pixel_block_);
    if (!top_up.empty()) {
        if (b != 1) throw std::invalid_argument("a top-up round with a pixel block");
        top_up_.assign(width * height, false);
        for (const std::uint32_t i : top_up) {
            if (i >= top_up_.size() || top_up_[i]) {
                throw std::invalid_argument("a top-up pixel outside the image or named twice");
            }
            top_up_[i] = true;
        }
        rendered_pixels_ = top_up.size();
        return;
    }
    if (b == 1) rendered_pixels_ = width * height;
    for (std::uint64_t sy = 0; b > 1 && sy * b < height; ++sy) {
        for (std::uint64_t sx = 0; sx * b < width; ++sx) {
            const std::uint64_t place = picked_place(sx, sy);
            rendered_pixels_ += sx * b + place % b < width && sy * b + place / b < height ? 1 : 0;
        }
    }
}

// Keeps the pilot's choice of pixels apart from other hashes of the seed.
constexpr std::uint64_t kPixelBlockStream = 0x706c6f74ULL;

std::uint64_t RenderContext::picked_place(std::uint64_t sx, std::uint64_t sy) const {
    if (pixel_block_ == 1) return 0;
    const auto b = static_cast<std::uint64_t>(pixel_block_);
    return hash_of(scene_.settings.seed, kPixelBlockStream, sx, sy) % (b * b);
}

bool RenderContext::renders(int x, int y) const {
    if (!top_up_.empty()) {
        return top_up_[static_cast<std::size_t>(y) * std::size_t(scene_.settings.width) +
                       static_cast<std::size_t>(x)];
    }
    if (pixel_block_ == 1) return true;
    const auto b = static_cast<std::uint64_t>(pixel_block_);
    const auto ux = static_cast<std::uint64_t>(x), uy = static_cast<std::uint64_t>(y);
    return picked_place(ux / b, uy / b) == (uy % b) * b + ux % b;
}

SpreadKind RenderContext::spread_kind() const {
    // A top-up's spreads are its pairs' own (render_again): the variance of their mean.
    if (!top_up_.empty()) return SpreadKind::kIndependent;
    return sampler_->independent() ? SpreadKind::kIndependent : SpreadKind::kCalibrated;
}

std::vector<std::size_t> RenderContext::rendered_in(const Tile& tile) const {
    const auto width = static_cast<std::size_t>(tile.width());
    std::vector<std::size_t> rendered;
    if (!top_up_.empty()) {
        for (int y = tile.y0; y < tile.y1; ++y) {
            for (int x = tile.x0; x < tile.x1; ++x) {
                if (renders(x, y)) {
                    rendered.push_back(static_cast<std::size_t>(y - tile.y0) * width +
                                       static_cast<std::size_t>(x - tile.x0));
                }
            }
        }
        return rendered;
    }
    if (pixel_block_ == 1) {
        rendered.resize(width * static_cast<std::size_t>(tile.height()));
        std::iota(rendered.begin(), rendered.end(), std::size_t{0});
        return rendered;
    }
    // One hash a square rather than one a pixel: a pilot's tile holds a few of its pixels among
    // hundreds, and testing each with renders() took a third of the pilot's time.
    const int b = pixel_block_;
    for (int sy = tile.y0 / b; sy * b < tile.y1; ++sy) {
        for (int sx = tile.x0 / b; sx * b < tile.x1; ++sx) {
            const auto place = static_cast<int>(picked_place(std::uint64_t(sx), std::uint64_t(sy)));
            const int x = sx * b + place % b, y = sy * b + place / b;
            if (x >= tile.x0 && x < tile.x1 && y >= tile.y0 && y < tile.y1) {
                rendered.push_back(static_cast<std::size_t>(y - tile.y0) * width +
                                   static_cast<std::size_t>(x - tile.x0));
            }
        }
    }
    // Row by row, as a full render takes them: the error sums add up in that order.
    std::sort(rendered.begin(), rendered.end());
    return rendered;
}

TileBuffer RenderContext::render_tile(const Tile& tile) const {
    TileBuffer buffer{
        tile, Image(tile.width(), tile.height()), {}, Image(tile.width(), tile.height()), {}, {}, 0,
        0};
    const auto width = static_cast<std::size_t>(tile.width());
    Scratch scratch;
    std::vector<Pixel> pixels(width * static_cast<std::size_t>(tile.height()));
    const std::vector<std::size_t> rendered = rendered_in(tile);
    for (const std::size_t i : rendered) {
        pixels[i] = render_pixel(tile.x0 + static_cast<int>(i % width),
                                 tile.y0 + static_cast<int>(i / width), 0, scratch, buffer.rays);
    }
    buffer.pixel_samples.reserve(pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const Pixel& pixel = pixels[i];
        const auto x = static_cast<int>(i % width), y = static_cast<int>(i / width);
        buffer.pixels.set(x, y, pixel.value);
        buffer.spread.set(x, y, pixel.spread);
        buffer.pixel_samples.push_back(pixel.samples);
        buffer.samples += pixel.samples;
        buffer.converged += pixel.converged ? 1 : 0;
    }
    if (!top_up_.empty()) {
        render_again(tile, pixels, rendered, scratch, buffer);
    } else if (estimate_error_ && spread_kind() == SpreadKind::kCalibrated &&
               scene_.settings.samples >= 2) {
        calibrate(tile, pixels, rendered, scratch, buffer);
    }
    return buffer;
}

std::uint64_t RenderContext::estimate_cost(const Tile& tile) const {
    const int block = scene_.settings.samples >= 16 ? 4 : 8;
    RayCounts rays;
    std::uint64_t pilots = 0;
    std::array<Color, 1> color;
    for (int y = tile.y0; y < tile.y1; y += block) {
        for (int x = tile.x0; x < tile.x1; x += block) {
            const int px = std::min(x + block / 2, tile.x1 - 1);
            const int py = std::min(y + block / 2, tile.y1 - 1);
            const PixelSample s{scene_.settings.seed,
                                static_cast<std::uint32_t>(py * scene_.settings.width + px), 0, 1};
            integrator_->sample_pixel(px, py, s, color, rays);
            ++pilots;
        }
    }
    // Shadow rays left out: a shading point's own work (its light sampling, textures, bump
    // maps) dwarfs what its shadow rays add (docs/design.md, "costliest first").
    const std::uint64_t shaded = rays.camera + rays.reflection + rays.refraction + rays.diffuse;
    const auto pixels = static_cast<std::uint64_t>(tile.width()) * tile.height();
    return pilots == 0 ? 0 : shaded * pixels / pilots;
}

// The key of the second, independent pattern of a pixel rendered twice: a ray-tree path of its
// own, which every sampler folds into every number it draws.
constexpr std::uint64_t kCalibrationPath = 0xca11b4a7e5eedULL;

void RenderContext::calibrate(const Tile& tile, std::span<const Pixel> pixels,
                              std::span<const std::size_t> rendered, Scratch& scratch,
                              TileBuffer& buffer) const {
    // A pilot renders every one of its pixels twice: its estimate is then their own mean squared
    // difference, not a scale taken from some of them times the spreads of all, which at 8
    // samples follow a pixel's error too loosely (at one pixel in 25 on Test5 at --scale 0.25
    // the log scatter against the true RMSE fell from 0.166 to 0.116, close to the 0.108 that
    // the choice of pixels alone leaves; docs/accuracy-history.md). It costs the pilot 40-85 %
    // more samples, at most a fifth of one sample per image pixel (0.18 at 200 x 150, 0.05 at
    // 400 x 300 and at 800 x 600).
    const std::vector<double> odds =
        pixel_block_ == 1
            ? calibration_odds(buffer.spread, calibration_share(double(rendered_pixels_)))
            : std::vector<double>(pixels.size(), 1.0);
    // The second renders' rays stay out of the image's ray counts: they are the estimate's cost,
    // which the sums count in camera samples.
    RayCounts rays;
    const auto width = static_cast<std::size_t>(tile.width());
    for (const std::size_t i : rendered) {
        const int x = tile.x0 + static_cast<int>(i % width);
        const int y = tile.y0 + static_cast<int>(i / width);
        const auto pixel = static_cast<std::uint32_t>(y * scene_.settings.width + x);
        if (to_unit(hash_of(scene_.settings.seed, pixel, kCalibrationPath)) >= odds[i]) continue;
        const Pixel again = render_pixel(x, y, kCalibrationPath, scratch, rays);
        add_calibration(buffer.error_sums, pixels[i].value, again.value, pixels[i].spread, odds[i],
                        again.samples);
    }
}

void RenderContext::render_again(const Tile& tile, std::span<const Pixel> pixels,
                                 std::span<const std::size_t> rendered, Scratch& scratch,
                                 TileBuffer& buffer) const {
    const auto width = static_cast<std::size_t>(tile.width());
    for (const std::size_t i : rendered) {
        const int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
        const Pixel again =
            render_pixel(tile.x0 + x, tile.y0 + y, kCalibrationPath, scratch, buffer.rays);
        const Color first = pixels[i].value;
        const Color difference = first - again.value;
        buffer.pixels.set(x, y, (first + again.value) * 0.5);
        // (a - b)^2 / 4 has the variance of (a + b) / 2 as its expectation, whatever the pattern.
        buffer.spread.set(x, y, difference * difference * 0.25);
        buffer.pixel_samples[i] += again.samples;
        buffer.samples += again.samples;
    }
}

RenderContext::Pixel RenderContext::render_pixel(int x, int y, std::uint64_t path, Scratch& scratch,
                                                 RayCounts& rays) const {
    return adaptive_ ? adaptive_pixel(x, y, path, scratch, rays)
                     : plain_pixel(x, y, path, scratch, rays);
}

RenderContext::Pixel RenderContext::plain_pixel(int x, int y, std::uint64_t path, Scratch& scratch,
                                                RayCounts& rays) const {
    const auto spp = static_cast<std::uint32_t>(scene_.settings.samples);
    const PixelSample s{scene_.settings.seed,
                        static_cast<std::uint32_t>(y * scene_.settings.width + x), 0, spp, path};
    scratch.colors.resize(spp);
    integrator_->sample_pixel(x, y, s, scratch.colors, rays);
    Color sum;
    for (const Color& c : scratch.colors) sum += c;
    if (sampler_->independent() || !plan_.effects.antialiasing || !estimate_error_) {
        return {sum / spp, pixel_spread(scratch.colors), spp, false};
    }
    // The samples' places in the pixel, as the integrator drew them: the strata they fell in.
    // Only for an estimate someone reads: it costs a sort of the samples.
    scratch.positions.resize(spp);
    sampler_->get_2d_run(s, dim::kPixel, scratch.positions);
    return {sum / spp, strata_spread(scratch.positions, scratch.colors, scratch.strata), spp,
            false};
}

// Rounds of as many samples as taken so far, until the standard error of the mean luminance is
// below the threshold. A progressive sampler continues one pattern; any other starts a new
// pattern of the round's size, on its own ray-tree path, in each round (the first round is
// exactly a plain render at the minimum count). A second render for the calibration (`path`
// not 0) does all that on paths of its own.
RenderContext::Pixel RenderContext::adaptive_pixel(int x, int y, std::uint64_t path,
                                                   Scratch& scratch, RayCounts& rays) const {
    const auto spp = static_cast<std::uint32_t>(scene_.settings.samples);
    const auto min_spp = static_cast<std::uint32_t>(adaptive_->min_samples);
    const auto pixel = static_cast<std::uint32_t>(y * scene_.settings.width + x);
    const bool progressive = sampler_->progressive();
    std::vector<double>& luminances = scratch.luminances;
    Color sum;
    bool converged = false;
    luminances.clear();
    scratch.taken.clear();
    for (std::uint32_t round = 0;; ++round) {
        const auto n = static_cast<std::uint32_t>(luminances.size());
        const std::uint32_t batch = std::min(round == 0 ? min_spp : n, spp - n);
        PixelSample s{scene_.settings.seed, pixel, 0, progressive ? spp : batch, path};
        if (!progressive && round > 0) {
            s.path = path == 0 ? hash_of(0xada9717eULL, round) : hash_of(path, round);
        }
        s.index = progressive ? n : 0;
        scratch.colors.resize(batch);
        integrator_->sample_pixel(x, y, s, scratch.colors, rays);
        for (const Color& c : scratch.colors) {
            sum += c;
            luminances.push_back(luminance(c));
            scratch.taken.push_back(c);
        }
        if (luminances.size() >= spp) break;
        if (standard_error(luminances, progressive) < adaptive_->noise_threshold) {
            converged = true;
            break;
        }
    }
    const auto n = static_cast<std::uint32_t>(luminances.size());
    return {sum / n, pixel_spread(scratch.taken), n, converged};
}

std::vector<Tile> costly_first(const RenderContext& context, std::vector<Tile> tiles, int workers,
                               int threads) {
    if (workers <= 1 || tiles.size() <= 1) return tiles;
    std::vector<std::pair<std::uint64_t, Tile> > costed(tiles.size());
    // The pilot runs before any worker starts: spread over the threads, it keeps them waiting
    // for a share of it only.
    std::atomic<std::size_t> next{0};
    const auto most = static_cast<int>(std::min<std::size_t>(tiles.size(), INT_MAX));
    run_on_threads(std::min(threads, most), [&](const std::atomic<bool>& failed) {
        for (std::size_t i = next++; i < tiles.size() && !failed.load(); i = next++) {
            costed[i] = {context.estimate_cost(tiles[i]), tiles[i]};
        }
    });
    std::stable_sort(costed.begin(), costed.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t i = 0; i < tiles.size(); ++i) tiles[i] = costed[i].second;
    return tiles;
}

}  // namespace drt
