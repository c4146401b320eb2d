#include "drt/render/render_context.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
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
// deviation over sqrt(n). An extensible sampler's samples split into 8 consecutive runs that are
// each a stratified pattern of their own, so the spread of the 8 run means over sqrt(8) measures
// the error stratification leaves; the spread of single samples would overstate it at every edge
// (by n^(1/4) for an edge, whose stratified error falls as n^(-3/4)).
double standard_error(std::span<const double> v, bool extensible) {
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
    if (!extensible || n < 2 * kRuns) return std::sqrt(spread(v) / double(n));
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

// `plan` with pixel-area sampling on or off (a copy shares the plan's emitters).
RenderPlan plan_with(RenderPlan plan, bool antialiasing) {
    plan.effects.antialiasing = antialiasing;
    return plan;
}

// Keeps the choice of one pixel per block apart from other hashes of the seed.
constexpr std::uint64_t kPixelBlockStream = 0x706c6f74ULL;

// With one pixel per block of b, the place (y % b) * b + x % b of the pixel picked in square
// (sx, sy), counted from the square's corner.
std::uint64_t picked_place(const RenderRequest& request, std::uint64_t sx, std::uint64_t sy) {
    const auto b = static_cast<std::uint64_t>(request.pixel_block);
    return hash_of(request.seed, kPixelBlockStream, sx, sy) % (b * b);
}

std::size_t pixel_index(const Scene& scene, int x, int y) {
    return static_cast<std::size_t>(y) * std::size_t(scene.settings.width) +
           static_cast<std::size_t>(x);
}

}  // namespace

RenderContext::RenderContext(const Scene& scene)
    : scene_(scene),
      sampler_(sampler_named(scene.settings.sampler)),
      bvh_(scene.objects),
      area_plan_(plan_with(plan_render(scene), true)),
      centre_plan_(plan_with(area_plan_, false)),
      photons_(area_plan_.effects.caustics
                   ? std::make_unique<const PhotonMaps>(scene, area_plan_, bvh_)
                   : nullptr),
      area_integrator_(make_integrator(scene, area_plan_, bvh_, *sampler_, photons_.get())),
      centre_integrator_(make_integrator(scene, centre_plan_, bvh_, *sampler_, photons_.get())),
      area_aovs_(scene, area_plan_, bvh_, *sampler_),
      centre_aovs_(scene, centre_plan_, bvh_, *sampler_),
      tiles_(tile_grid(scene.settings.width, scene.settings.height)) {}

const RenderPlan& RenderContext::plan(const RenderRequest& request) const {
    return request.samples > 1 ? area_plan_ : centre_plan_;
}

const PixelIntegrator& RenderContext::integrator(const RenderRequest& request) const {
    return request.samples > 1 ? *area_integrator_ : *centre_integrator_;
}

void RenderContext::check(const RenderRequest& request) const {
    if (request.samples < 1) throw std::invalid_argument("a request of no samples");
    if (request.pixels == PixelChoice::kOnePerBlock && request.pixel_block < 2) {
        throw std::invalid_argument("one pixel per block of fewer than 2 x 2");
    }
    if (request.pixels != PixelChoice::kListed) return;
    const std::uint64_t count =
        std::uint64_t(scene_.settings.width) * std::uint64_t(scene_.settings.height);
    for (std::size_t i = 0; i < request.listed.size(); ++i) {
        if (request.listed[i] >= count || (i > 0 && request.listed[i] <= request.listed[i - 1])) {
            throw std::invalid_argument(
                "a listed pixel outside the image, out of order or named twice");
        }
    }
}

std::uint64_t RenderContext::rendered_pixels(const RenderRequest& request) const {
    const auto width = static_cast<std::uint64_t>(scene_.settings.width);
    const auto height = static_cast<std::uint64_t>(scene_.settings.height);
    if (request.pixels == PixelChoice::kAll) return width * height;
    if (request.pixels == PixelChoice::kListed) return request.listed.size();
    // One hash a square, as rendered_in takes them.
    const auto b = static_cast<std::uint64_t>(request.pixel_block);
    std::uint64_t rendered = 0;
    for (std::uint64_t sy = 0; sy * b < height; ++sy) {
        for (std::uint64_t sx = 0; sx * b < width; ++sx) {
            const std::uint64_t place = picked_place(request, sx, sy);
            rendered += sx * b + place % b < width && sy * b + place / b < height ? 1 : 0;
        }
    }
    return rendered;
}

bool RenderContext::renders(const RenderRequest& request, int x, int y) const {
    switch (request.pixels) {
        case PixelChoice::kAll:
            return true;
        case PixelChoice::kListed:
            return std::binary_search(request.listed.begin(), request.listed.end(),
                                      pixel_index(scene_, x, y));
        case PixelChoice::kOnePerBlock:
            break;
    }
    const auto b = static_cast<std::uint64_t>(request.pixel_block);
    const auto ux = static_cast<std::uint64_t>(x), uy = static_cast<std::uint64_t>(y);
    return picked_place(request, ux / b, uy / b) == (uy % b) * b + ux % b;
}

SpreadKind RenderContext::spread_kind(const RenderRequest& request) const {
    // A paired request's spreads are its pairs' own (render_again): the variance of their mean.
    if (request.paired) return SpreadKind::kIndependent;
    return sampler_->independent() ? SpreadKind::kIndependent : SpreadKind::kCalibrated;
}

std::vector<std::size_t> RenderContext::rendered_in(const Tile& tile,
                                                    const RenderRequest& request) const {
    const auto width = static_cast<std::size_t>(tile.width());
    std::vector<std::size_t> rendered;
    if (request.pixels == PixelChoice::kListed) {
        for (int y = tile.y0; y < tile.y1; ++y) {
            const auto first = std::lower_bound(request.listed.begin(), request.listed.end(),
                                                pixel_index(scene_, tile.x0, y));
            const auto last =
                std::lower_bound(first, request.listed.end(), pixel_index(scene_, tile.x1, y));
            for (auto p = first; p != last; ++p) {
                rendered.push_back(static_cast<std::size_t>(y - tile.y0) * width +
                                   (*p - pixel_index(scene_, tile.x0, y)));
            }
        }
        return rendered;
    }
    if (request.pixels == PixelChoice::kAll) {
        rendered.resize(width * static_cast<std::size_t>(tile.height()));
        std::iota(rendered.begin(), rendered.end(), std::size_t{0});
        return rendered;
    }
    // One hash a square rather than one a pixel: a tile holds a few of the picked pixels among
    // hundreds.
    const int b = request.pixel_block;
    for (int sy = tile.y0 / b; sy * b < tile.y1; ++sy) {
        for (int sx = tile.x0 / b; sx * b < tile.x1; ++sx) {
            const auto place =
                static_cast<int>(picked_place(request, std::uint64_t(sx), std::uint64_t(sy)));
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

struct RenderContext::PixelRun {
    PixelRun(const RenderRequest& request_, const Tile& tile_, std::vector<std::size_t> rendered_,
             std::uint64_t path_)
        : request(request_),
          tile(tile_),
          rendered(std::move(rendered_)),
          path(path_),
          pixels(static_cast<std::size_t>(tile.width()) * static_cast<std::size_t>(tile.height())) {
    }

    // rendered[k]'s place in the image.
    int x(std::size_t k) const { return tile.x0 + static_cast<int>(rendered[k] % width()); }
    int y(std::size_t k) const { return tile.y0 + static_cast<int>(rendered[k] / width()); }
    std::size_t width() const { return static_cast<std::size_t>(tile.width()); }
    // The next of `rendered` to render, as its index there; none once all are handed out.
    std::optional<std::size_t> take() {
        const std::size_t k = next.fetch_add(1, std::memory_order_relaxed);
        return k < rendered.size() ? std::optional(k) : std::nullopt;
    }
    std::size_t handed() const {
        return std::min(next.load(std::memory_order_relaxed), rendered.size());
    }
    std::size_t left() const { return rendered.size() - handed(); }

    const RenderRequest& request;
    const Tile tile;
    const std::vector<std::size_t> rendered;  // the tile's pixels rendered, row by row
    const std::uint64_t path;                 // render_pixel's
    std::vector<Pixel> pixels;                // every pixel of the tile, row by row
    std::atomic<std::size_t> next{0};
    // Pixels the helpers have rendered; their values and rays are written before the count.
    std::atomic<std::size_t> helped{0};
    std::mutex mutex;
    RayCounts helpers_rays;    // guarded by mutex
    std::exception_ptr error;  // the first a helper threw; guarded by mutex
    bool stopped = false;      // a helper left a pixel unfinished for a stop; guarded by mutex
};

double RenderContext::Workbench::tiles_in_hand() const {
    const std::lock_guard lock(mutex_);
    double tiles = 0;
    for (const auto& run : open_) {
        if (run->path == 0 && !run->rendered.empty())
            tiles += double(run->handed()) / double(run->rendered.size());
    }
    return tiles;
}

bool RenderContext::render_run(const std::shared_ptr<PixelRun>& run, Workbench* bench,
                               const std::stop_token& stop, Scratch& scratch,
                               RayCounts& rays) const {
    std::size_t own = 0;
    {
        // On the bench while this thread takes pixels, however it leaves.
        const struct Opened {
            Workbench* bench;
            const std::shared_ptr<PixelRun>& run;
            Opened(Workbench* b, const std::shared_ptr<PixelRun>& r) : bench(b), run(r) {
                if (!bench) return;
                const std::lock_guard lock(bench->mutex_);
                bench->open_.push_back(run);
                bench->changed_.notify_all();
            }
            ~Opened() {
                if (!bench) return;
                const std::lock_guard lock(bench->mutex_);
                std::erase(bench->open_, run);
            }
            Opened(const Opened&) = delete;
            Opened& operator=(const Opened&) = delete;
        } opened(bench, run);
        while (const auto k = run->take()) {
            if (stop.stop_requested()) return false;
            auto pixel =
                render_pixel(run->request, run->x(*k), run->y(*k), run->path, scratch, rays, stop);
            if (!pixel) return false;
            run->pixels[run->rendered[*k]] = *pixel;
            ++own;
        }
    }
    // Every pixel is handed out: wait for those the helpers took. A helper counts every pixel it
    // takes, finished or left for a stop, so the count comes.
    const std::size_t helped = run->rendered.size() - own;
    for (std::size_t done; (done = run->helped.load(std::memory_order_acquire)) < helped;) {
        run->helped.wait(done, std::memory_order_acquire);
    }
    if (run->error) std::rethrow_exception(run->error);
    if (run->stopped) return false;
    rays += run->helpers_rays;
    return true;
}

TileBuffer RenderContext::render_tile(const Tile& tile, const RenderRequest& request) const {
    return *render_tile(tile, request, std::stop_token{});
}

std::optional<TileBuffer> RenderContext::render_tile(const Tile& tile, const RenderRequest& request,
                                                     const std::stop_token& stop,
                                                     Workbench* bench) const {
    TileBuffer buffer{tile, Image(tile.width(), tile.height()),
                      {},   Image(tile.width(), tile.height()),
                      {},   {},
                      0,    0,
                      {}};
    const auto width = static_cast<std::size_t>(tile.width());
    Scratch scratch;
    const auto run = std::make_shared<PixelRun>(request, tile, rendered_in(tile, request), 0);
    if (!render_run(run, bench, stop, scratch, buffer.rays)) return std::nullopt;
    const std::vector<Pixel>& pixels = run->pixels;
    const std::vector<std::size_t>& rendered = run->rendered;
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
    if (!request.aovs.empty()) {
        const std::size_t channels = aov_channel_count(request.aovs);
        const AovTracer& tracer = request.samples > 1 ? area_aovs_ : centre_aovs_;
        buffer.aovs.assign(channels * pixels.size(), 0.0f);
        for (const std::size_t i : rendered) {
            const int x = tile.x0 + static_cast<int>(i % width);
            const int y = tile.y0 + static_cast<int>(i / width);
            const PixelSample s{request.seed, static_cast<std::uint32_t>(pixel_index(scene_, x, y)),
                                0, pixels[i].samples};
            tracer.pixel_mean(x, y, s, request.aovs,
                              std::span<float>(buffer.aovs).subspan(channels * i, channels));
        }
    }
    if (request.paired) {
        if (!render_again(request, tile, pixels, rendered, scratch, buffer, stop, bench)) {
            return std::nullopt;
        }
    } else if (request.estimate_error && spread_kind(request) == SpreadKind::kCalibrated &&
               request.samples >= 2) {
        if (!calibrate(request, tile, pixels, rendered, scratch, buffer, stop, bench)) {
            return std::nullopt;
        }
    }
    return buffer;
}

RenderContext::Workbench::Taker::Taker(Workbench& bench) : bench_(bench) {
    const std::lock_guard lock(bench_.mutex_);
    ++bench_.takers_;
}

RenderContext::Workbench::Taker::~Taker() {
    const std::lock_guard lock(bench_.mutex_);
    --bench_.takers_;
    bench_.changed_.notify_all();
}

std::size_t RenderContext::help(Workbench& bench, const std::stop_token& stop) const {
    Scratch scratch;
    std::size_t rendered = 0;
    while (true) {
        std::shared_ptr<PixelRun> run;  // the open tile with the most pixels left
        {
            std::unique_lock lock(bench.mutex_);
            const auto pick = [&] {
                std::size_t most = 0;
                for (const auto& open : bench.open_) {
                    if (open->left() > most) most = open->left(), run = open;
                }
                return run != nullptr || bench.takers_ == 0;
            };
            bench.changed_.wait(lock, stop, pick);
        }
        if (!run || stop.stop_requested()) return rendered;
        while (!stop.stop_requested()) {
            const auto k = run->take();
            if (!k) break;
            RayCounts rays;
            std::exception_ptr error;
            bool stopped = false;
            try {
                auto pixel = render_pixel(run->request, run->x(*k), run->y(*k), run->path, scratch,
                                          rays, stop);
                if (pixel) run->pixels[run->rendered[*k]] = *pixel;
                stopped = !pixel;
            } catch (...) {
                error = std::current_exception();
            }
            {
                const std::lock_guard lock(run->mutex);
                run->helpers_rays += rays;
                if (error && !run->error) run->error = error;
                run->stopped = run->stopped || stopped;
            }
            // Counted even when it threw, so that the owner does not wait for it forever.
            run->helped.fetch_add(1, std::memory_order_release);
            run->helped.notify_one();
            if (error) std::rethrow_exception(error);
            if (stopped) return rendered;
            ++rendered;
        }
    }
}

std::uint64_t RenderContext::tile_cost(const Tile& tile, const RenderRequest& request) const {
    const int block = request.samples >= 16 ? 4 : 8;
    RayCounts rays;
    std::uint64_t probes = 0;
    std::array<Color, 1> color;
    for (int y = tile.y0; y < tile.y1; y += block) {
        for (int x = tile.x0; x < tile.x1; x += block) {
            const int px = std::min(x + block / 2, tile.x1 - 1);
            const int py = std::min(y + block / 2, tile.y1 - 1);
            const PixelSample s{request.seed,
                                static_cast<std::uint32_t>(pixel_index(scene_, px, py)), 0, 1};
            integrator(request).sample_pixel(px, py, s, color, rays);
            ++probes;
        }
    }
    // Shadow rays left out: a shading point's own work (its light sampling, textures, bump
    // maps) dwarfs what its shadow rays add.
    const std::uint64_t shaded = rays.camera + rays.reflection + rays.refraction + rays.diffuse;
    const auto pixels = static_cast<std::uint64_t>(tile.width()) * tile.height();
    return probes == 0 ? 0 : shaded * pixels / probes;
}

// The key of the second, independent pattern of a pixel rendered twice: a ray-tree path of its
// own, which every sampler folds into every number it draws.
constexpr std::uint64_t kSecondRenderPath = 0xca11b4a7e5eedULL;

// The ray-tree path of an adaptive round's new pattern (adaptive_pixel), hashed with the round.
constexpr std::uint64_t kAdaptiveRoundPath = 0xada9717eULL;

bool RenderContext::calibrate(const RenderRequest& request, const Tile& tile,
                              std::span<const Pixel> pixels, std::span<const std::size_t> rendered,
                              Scratch& scratch, TileBuffer& buffer, const std::stop_token& stop,
                              Workbench* bench) const {
    // One pixel per block: every one twice, so that the estimate is their own mean squared
    // difference; a scale taken from some of them times the spreads of all follows a pixel's
    // error too loosely at few samples.
    const std::vector<double> odds =
        request.pixels == PixelChoice::kOnePerBlock
            ? std::vector<double>(pixels.size(), 1.0)
            : calibration_odds(buffer.spread, calibration_share(double(rendered_pixels(request))));
    const auto width = static_cast<std::size_t>(tile.width());
    std::vector<std::size_t> picked;
    for (const std::size_t i : rendered) {
        const int x = tile.x0 + static_cast<int>(i % width);
        const int y = tile.y0 + static_cast<int>(i / width);
        const auto pixel = static_cast<std::uint32_t>(pixel_index(scene_, x, y));
        if (to_unit(hash_of(request.seed, pixel, kSecondRenderPath)) < odds[i]) picked.push_back(i);
    }
    // The second renders' rays stay out of the image's ray counts: they are the estimate's cost,
    // which the sums count in camera samples.
    RayCounts rays;
    const auto again =
        std::make_shared<PixelRun>(request, tile, std::move(picked), kSecondRenderPath);
    if (!render_run(again, bench, stop, scratch, rays)) return false;
    // Added up in the pixels' order, whoever rendered them.
    for (const std::size_t i : again->rendered) {
        add_calibration(buffer.error_sums, pixels[i].value, again->pixels[i].value,
                        pixels[i].spread, odds[i], again->pixels[i].samples);
    }
    return true;
}

bool RenderContext::render_again(const RenderRequest& request, const Tile& tile,
                                 std::span<const Pixel> pixels,
                                 std::span<const std::size_t> rendered, Scratch& scratch,
                                 TileBuffer& buffer, const std::stop_token& stop,
                                 Workbench* bench) const {
    const auto again = std::make_shared<PixelRun>(
        request, tile, std::vector<std::size_t>(rendered.begin(), rendered.end()),
        kSecondRenderPath);
    if (!render_run(again, bench, stop, scratch, buffer.rays)) return false;
    const auto width = static_cast<std::size_t>(tile.width());
    for (const std::size_t i : rendered) {
        const int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
        const Pixel& second = again->pixels[i];
        const Color first = pixels[i].value;
        const Color difference = first - second.value;
        buffer.pixels.set(x, y, (first + second.value) * 0.5);
        // (a - b)^2 / 4 has the variance of (a + b) / 2 as its expectation, whatever the pattern.
        buffer.spread.set(x, y, difference * difference * 0.25);
        buffer.pixel_samples[i] += second.samples;
        buffer.samples += second.samples;
    }
    return true;
}

std::optional<RenderContext::Pixel> RenderContext::render_pixel(const RenderRequest& request, int x,
                                                                int y, std::uint64_t path,
                                                                Scratch& scratch, RayCounts& rays,
                                                                const std::stop_token& stop) const {
    return request.adaptive ? adaptive_pixel(request, x, y, path, scratch, rays, stop)
                            : plain_pixel(request, x, y, path, scratch, rays, stop);
}

bool RenderContext::sample(const RenderRequest& request, int x, int y, PixelSample s,
                           std::span<Color> out, RayCounts& rays,
                           const std::stop_token& stop) const {
    for (std::size_t first = 0; first < out.size(); first += kSamplesBetweenStops) {
        if (first > 0 && stop.stop_requested()) return false;
        const std::span<Color> part =
            out.subspan(first, std::min(kSamplesBetweenStops, out.size() - first));
        integrator(request).sample_pixel(x, y, s, part, rays);
        s.index += static_cast<std::uint32_t>(part.size());
    }
    return true;
}

std::optional<RenderContext::Pixel> RenderContext::plain_pixel(const RenderRequest& request, int x,
                                                               int y, std::uint64_t path,
                                                               Scratch& scratch, RayCounts& rays,
                                                               const std::stop_token& stop) const {
    const auto spp = static_cast<std::uint32_t>(request.samples);
    const PixelSample s{request.seed, static_cast<std::uint32_t>(pixel_index(scene_, x, y)), 0, spp,
                        path};
    scratch.colors.resize(spp);
    if (!sample(request, x, y, s, scratch.colors, rays, stop)) return std::nullopt;
    Color sum;
    for (const Color& c : scratch.colors) sum += c;
    if (sampler_->independent() || !plan(request).effects.antialiasing || !request.estimate_error) {
        return Pixel{sum / spp, pixel_spread(scratch.colors), spp, false};
    }
    // The samples' places in the pixel, as the integrator drew them: the strata they fell in.
    // Only for an estimate someone reads: it costs a sort of the samples.
    scratch.positions.resize(spp);
    sampler_->get_2d_run(s, dim::kPixel, scratch.positions);
    return Pixel{sum / spp, strata_spread(scratch.positions, scratch.colors, scratch.strata), spp,
                 false};
}

// Rounds of as many samples as taken so far, until the standard error of the mean luminance is
// below the threshold. An extensible sampler continues one pattern; any other starts a new
// pattern of the round's size, on its own ray-tree path, in each round (the first round is
// exactly a plain render at the minimum count). A second render (`path` not 0) does all that on
// paths of its own.
std::optional<RenderContext::Pixel> RenderContext::adaptive_pixel(
    const RenderRequest& request, int x, int y, std::uint64_t path, Scratch& scratch,
    RayCounts& rays, const std::stop_token& stop) const {
    const auto spp = static_cast<std::uint32_t>(request.samples);
    const AdaptiveSampling adaptive = *request.applied_adaptive();
    const auto min_spp = static_cast<std::uint32_t>(adaptive.min_samples);
    const auto pixel = static_cast<std::uint32_t>(pixel_index(scene_, x, y));
    const bool extensible = sampler_->extensible();
    std::vector<double>& luminances = scratch.luminances;
    Color sum;
    bool converged = false;
    luminances.clear();
    scratch.taken.clear();
    for (std::uint32_t round = 0;; ++round) {
        const auto n = static_cast<std::uint32_t>(luminances.size());
        const std::uint32_t batch = std::min(round == 0 ? min_spp : n, spp - n);
        PixelSample s{request.seed, pixel, 0, extensible ? spp : batch, path};
        if (!extensible && round > 0) {
            s.path = path == 0 ? hash_of(kAdaptiveRoundPath, round) : hash_of(path, round);
        }
        s.index = extensible ? n : 0;
        s.pass_base = extensible ? 0 : n;
        scratch.colors.resize(batch);
        if (!sample(request, x, y, s, scratch.colors, rays, stop)) return std::nullopt;
        for (const Color& c : scratch.colors) {
            sum += c;
            luminances.push_back(luminance(c));
            scratch.taken.push_back(c);
        }
        if (luminances.size() >= spp) break;
        if (standard_error(luminances, extensible) < adaptive.noise_threshold) {
            converged = true;
            break;
        }
    }
    const auto n = static_cast<std::uint32_t>(luminances.size());
    return Pixel{sum / n, pixel_spread(scratch.taken), n, converged};
}

std::vector<Tile> costly_first(const RenderContext& context, const RenderRequest& request,
                               std::vector<Tile> tiles, int workers, int threads) {
    if (workers <= 1 || tiles.size() <= 1) return tiles;
    std::vector<std::pair<std::uint64_t, Tile> > costed(tiles.size());
    // The probes run before any worker starts: spread over the threads, they keep them waiting
    // for a share of them only.
    std::atomic<std::size_t> next{0};
    const auto most = static_cast<int>(std::min<std::size_t>(tiles.size(), INT_MAX));
    run_on_threads(std::min(threads, most), [&](const std::atomic<bool>& failed) {
        for (std::size_t i = next++; i < tiles.size() && !failed.load(); i = next++) {
            costed[i] = {context.tile_cost(tiles[i], request), tiles[i]};
        }
    });
    std::stable_sort(costed.begin(), costed.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t i = 0; i < tiles.size(); ++i) tiles[i] = costed[i].second;
    return tiles;
}

}  // namespace drt
