#include "drt/renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "drt/bvh.h"

namespace drt {

namespace {

constexpr int kTileSize = 16;

struct Tile {
    int x0, y0, x1, y1;
};

std::vector<Tile> make_tiles(int width, int height) {
    std::vector<Tile> tiles;
    for (int y = 0; y < height; y += kTileSize) {
        for (int x = 0; x < width; x += kTileSize) {
            tiles.push_back({x, y, std::min(x + kTileSize, width), std::min(y + kTileSize, height)});
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
    const int threads = std::max(
        1, std::min<int>(options.threads > 0 ? options.threads
                                             : static_cast<int>(std::thread::hardware_concurrency()),
                         static_cast<int>(tiles.size())));
    std::atomic<std::size_t> next_tile{0};
    std::atomic<std::size_t> tiles_done{0};
    std::vector<RayCounts> counts(threads);
    std::mutex mutex;
    std::condition_variable finished;
    int running = threads;

    auto worker = [&](int id) {
        RayCounts local;  // summed once at the end: shared counters would contend on every ray
        const auto spp = static_cast<std::uint32_t>(settings.samples);
        for (std::size_t t; (t = next_tile.fetch_add(1)) < tiles.size();) {
            const Tile& tile = tiles[t];
            for (int y = tile.y0; y < tile.y1; ++y) {
                for (int x = tile.x0; x < tile.x1; ++x) {
                    PixelSample s{settings.seed,
                                  static_cast<std::uint32_t>(y * settings.width + x), 0, spp};
                    Color sum;
                    for (s.index = 0; s.index < spp; ++s.index) {
                        sum += integrator.sample_pixel(x, y, s, local);
                    }
                    result.image.set(x, y, sum / spp);
                }
            }
            tiles_done.fetch_add(1);
        }
        const std::lock_guard lock(mutex);
        counts[id] = local;
        if (--running == 0) finished.notify_all();
    };

    std::vector<std::jthread> pool;
    for (int id = 0; id < threads; ++id) pool.emplace_back(worker, id);
    {
        std::unique_lock lock(mutex);
        while (!finished.wait_for(lock, std::chrono::milliseconds(250), [&] { return running == 0; })) {
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
    for (const RayCounts& c : counts) result.stats.rays += c;
    result.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace drt
