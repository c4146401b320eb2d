#include "drt/renderer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <span>
#include <stdexcept>
#include <thread>
#include <vector>

#include "drt/bvh.h"
#include "drt/rng.h"

namespace drt {

namespace {

constexpr int kTileSize = 16;

struct Tile {
    int x0, y0, x1, y1;
};

struct PixelTally {
    std::uint64_t samples = 0, converged = 0;
};

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

std::vector<Tile> make_tiles(int width, int height) {
    std::vector<Tile> tiles;
    for (int y = 0; y < height; y += kTileSize) {
        for (int x = 0; x < width; x += kTileSize) {
            tiles.push_back(
                {x, y, std::min(x + kTileSize, width), std::min(y + kTileSize, height)});
        }
    }
    return tiles;
}

}  // namespace

RenderResult render(const Scene& scene, const RenderOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const RenderSettings& settings = scene.settings;
    const auto sampler = make_sampler(settings.sampler);
    if (!sampler) throw std::invalid_argument("unknown sampler '" + settings.sampler + "'");

    RenderResult result;
    result.plan = plan_render(scene);
    const Bvh bvh(scene.objects);
    const Integrator integrator(scene, result.plan, bvh, *sampler);
    result.image = Image(settings.width, settings.height);

    const std::vector<Tile> tiles = make_tiles(settings.width, settings.height);
    const int threads =
        std::max(1, std::min<int>(options.threads > 0
                                      ? options.threads
                                      : static_cast<int>(std::thread::hardware_concurrency()),
                                  static_cast<int>(tiles.size())));
    std::atomic<std::size_t> next_tile{0};
    std::atomic<std::size_t> tiles_done{0};
    std::vector<RayCounts> counts(threads);
    std::vector<PixelTally> tallies(threads);
    std::mutex mutex;
    std::condition_variable finished;
    int running = threads;

    const auto spp = static_cast<std::uint32_t>(settings.samples);
    std::optional<AdaptiveSampling> adaptive = options.adaptive;
    if (adaptive) {
        adaptive->min_samples = std::clamp(adaptive->min_samples, 1, settings.samples);
        result.pixel_samples.assign(static_cast<std::size_t>(settings.width) * settings.height, 0);
    }
    // One pixel, adaptively: rounds of as many samples as taken so far, until the standard error
    // of the mean luminance is below the threshold. A progressive sampler continues one pattern;
    // any other starts a new pattern of the round's size, on its own ray-tree path, in each round
    // (the first round is exactly a plain render at the minimum count).
    auto adaptive_pixel = [&](int x, int y, RayCounts& rays, PixelTally& tally,
                              std::vector<Color>& colors, std::vector<double>& luminances) {
        const auto min_spp = static_cast<std::uint32_t>(adaptive->min_samples);
        const auto pixel = static_cast<std::uint32_t>(y * settings.width + x);
        Color sum;
        luminances.clear();
        for (std::uint32_t round = 0;; ++round) {
            const auto n = static_cast<std::uint32_t>(luminances.size());
            const std::uint32_t batch = std::min(round == 0 ? min_spp : n, spp - n);
            PixelSample s{settings.seed, pixel, 0, sampler->progressive() ? spp : batch};
            if (!sampler->progressive() && round > 0) s.path = hash_of(0xada9717eULL, round);
            s.index = sampler->progressive() ? n : 0;
            colors.resize(batch);
            integrator.sample_pixel(x, y, s, colors, rays);
            for (const Color& c : colors) {
                sum += c;
                luminances.push_back(luminance(c));
            }
            if (luminances.size() >= spp) break;
            if (standard_error(luminances, sampler->progressive()) < adaptive->noise_threshold) {
                ++tally.converged;
                break;
            }
        }
        const auto n = static_cast<std::uint32_t>(luminances.size());
        tally.samples += n;
        result.pixel_samples[pixel] = n;
        result.image.set(x, y, sum / n);
    };

    auto worker = [&](int id) {
        RayCounts local;  // summed once at the end: shared counters would contend on every ray
        PixelTally tally;
        std::vector<Color> colors(spp);  // of the pixel in hand, reused
        std::vector<double> luminances;  // of the adaptive pixel in hand, reused
        for (std::size_t t; (t = next_tile.fetch_add(1)) < tiles.size();) {
            const Tile& tile = tiles[t];
            for (int y = tile.y0; y < tile.y1; ++y) {
                for (int x = tile.x0; x < tile.x1; ++x) {
                    if (adaptive) {
                        adaptive_pixel(x, y, local, tally, colors, luminances);
                        continue;
                    }
                    PixelSample s{settings.seed, static_cast<std::uint32_t>(y * settings.width + x),
                                  0, spp};
                    integrator.sample_pixel(x, y, s, colors, local);
                    Color sum;
                    for (const Color& c : colors) sum += c;
                    tally.samples += spp;
                    result.image.set(x, y, sum / spp);
                }
            }
            tiles_done.fetch_add(1);
        }
        const std::lock_guard lock(mutex);
        counts[id] = local;
        tallies[id] = tally;
        if (--running == 0) finished.notify_all();
    };

    std::vector<std::jthread> pool;
    for (int id = 0; id < threads; ++id) pool.emplace_back(worker, id);
    {
        std::unique_lock lock(mutex);
        while (!finished.wait_for(lock, std::chrono::milliseconds(250),
                                  [&] { return running == 0; })) {
            if (options.on_progress) {
                lock.unlock();
                options.on_progress(double(tiles_done.load()) / tiles.size());
                lock.lock();
            }
        }
    }
    pool.clear();
    if (options.on_progress) options.on_progress(1.0);

    result.stats.threads = threads;
    result.stats.adaptive = adaptive;
    for (const RayCounts& c : counts) result.stats.rays += c;
    for (const PixelTally& t : tallies) {
        result.stats.samples += t.samples;
        result.stats.pixels_converged += t.converged;
    }
    result.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace drt
