#include "drt/render/renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>

#include "drt/util/limits.h"
#include "drt/util/parallel.h"

namespace drt {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

int render_tiles(const RenderContext& context, const RenderRequest& request, TileSource& source,
                 TileSink& sink, const RenderOptions& options) {
    context.check(request);
    // Threads beyond the tiles help render their pixels.
    const int threads = source.size() > 0 ? worker_threads(options.threads) : 1;
    std::atomic<std::size_t> tiles_done{0};
    const double total = static_cast<double>(std::max<std::size_t>(1, source.size()));
    // A thread out of tiles helps render the pixels of those still in hand. On one thread the
    // bench only shows the progress within them.
    RenderContext::Workbench bench;
    const auto progress = [&] {
        const double done = double(tiles_done.load());
        options.on_progress(std::min(done + bench.tiles_in_hand(), total) / total);
    };
    run_on_threads(
        threads,
        [&](const std::atomic<bool>& failed) {
            bool out_of_tiles = false;
            {
                const RenderContext::Workbench::Taker taker(bench);
                while (!failed.load(std::memory_order_relaxed) && !options.stop.stop_requested()) {
                    const std::optional<Tile> tile = source.next();
                    if (!tile) {
                        out_of_tiles = true;
                        break;
                    }
                    std::optional<TileBuffer> done =
                        context.render_tile(*tile, request, options.stop, &bench);
                    if (!done) {
                        source.give_back(*tile);
                        break;
                    }
                    sink.add(std::move(*done));
                    tiles_done.fetch_add(1, std::memory_order_relaxed);
                }
            }
            if (out_of_tiles && threads > 1) context.help(bench, options.stop);
        },
        options.on_progress ? std::function<void()>(progress) : nullptr);
    if (options.on_progress) progress();
    return threads;
}

RenderResult complete_render(const RenderContext& context, const RenderRequest& request,
                             ImageSink& sink, const RenderOptions& options) {
    const auto start = Clock::now();
    TileQueue source(sink.missing());
    RenderOptions run = options;
    if (options.on_progress) {
        // Progress over the whole image, counting the tiles the sink already had.
        const double all = double(std::max<std::size_t>(1, sink.tile_count()));
        const double before = double(sink.tiles_done()) / all;
        const double share = double(source.size()) / all;
        run.on_progress = [&, before, share](double done) {
            options.on_progress(before + share * done);
        };
    }
    const int threads = render_tiles(context, request, source, sink, run);
    RenderResult result = assembled(context, request, sink);
    result.stats.threads = threads;
    result.stats.seconds = seconds_since(start);
    return result;
}

RenderResult assembled(const RenderContext& context, const RenderRequest& request,
                       const ImageSink& sink) {
    RenderResult result;
    result.image = sink.image();
    result.plan = context.plan(request);
    result.stats.adaptive = request.applied_adaptive();
    if (request.adaptive) result.pixel_samples = sink.pixel_samples();
    result.stats.rays = sink.rays();
    if (result.plan.effects.caustics) {
        result.stats.photons =
            std::uint64_t(context.scene().settings.photons->count) * std::uint64_t(request.samples);
    }
    result.stats.samples = sink.samples();
    result.stats.pixels_converged = sink.converged();
    result.unfinished = sink.missing();
    result.spread = sink.spread();
    result.aov_list = request.aovs;
    result.aovs = sink.aovs();
    if (result.plan.effects.caustics) {
        result.stats.error.unavailable =
            "caustics from photon maps are biased at any finite gather radius: no estimate";
    } else if (result.unfinished.empty()) {
        result.stats.error = estimate_error(
            result.image, result.spread, sink.error_sums(), sink.samples(), request.samples,
            context.spread_kind(request), context.rendered_pixels(request));
    } else {
        result.stats.error.unavailable = "the render is unfinished";
    }
    return result;
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    request.adaptive = options.adaptive;
    return render(scene, request, options);
}

RenderResult render(const Scene& scene, const RenderRequest& request,
                    const RenderOptions& options) {
    const auto start = Clock::now();
    const RenderContext context(scene);
    ImageSink sink(scene.settings.width, scene.settings.height, context.tiles(),
                   aov_channel_count(request.aovs));
    RenderResult result = complete_render(context, request, sink, options);
    result.stats.seconds = seconds_since(start);
    return result;
}

}  // namespace drt
