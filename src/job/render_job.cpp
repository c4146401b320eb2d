#include "drt/job/render_job.h"

#include <atomic>
#include <chrono>
#include <string>

#include "drt/job/checkpoint.h"
#include "drt/render/render_context.h"
#include "drt/render/tile.h"
#include "drt/util/atomic_file.h"
#include "drt/util/limits.h"

namespace drt {

namespace {

// Requests a stop once `limit` tiles are done, counting those the sink had before.
class StopAfter final : public TileSink {
  public:
    StopAfter(TileSink& next, std::size_t done, std::size_t limit, std::stop_source stop)
        : next_(next), done_(done), limit_(limit), stop_(std::move(stop)) {
        if (done_ >= limit_) stop_.request_stop();
    }
    void add(TileBuffer buffer) override {
        next_.add(std::move(buffer));
        if (done_.fetch_add(1) + 1 >= limit_) stop_.request_stop();
    }

  private:
    TileSink& next_;
    std::atomic<std::size_t> done_;
    std::size_t limit_;
    std::stop_source stop_;
};

}  // namespace

RenderJobResult run_render_job(const Scene& scene, const RenderJobOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const RenderContext context(scene, options.adaptive,
                                options.estimate_error || options.checkpoint.has_value(),
                                options.pixel_block, options.top_up);
    const bool leader = options.mpi == nullptr || options.mpi->leader();
    RenderJobResult out;
    out.tiles = context.tiles().size();

    // Only the leader assembles the image and keeps the checkpoint.
    std::optional<ImageSink> image;
    std::optional<CheckpointSink> kept;
    std::string refused;
    if (leader) {
        image.emplace(scene.settings.width, scene.settings.height, context.tiles());
        if (options.checkpoint) {
            try {
                const RenderIdentity id = identify_render(options.scene_files, scene.settings,
                                                          context.adaptive(), out.tiles);
                try {
                    check_replaceable(*options.checkpoint);
                } catch (const FileWriteError& e) {
                    throw CheckpointError(e.what());
                }
                std::optional<Checkpoint> resumed =
                    read_checkpoint(*options.checkpoint, id, context.tiles());
                if (resumed) out.resumed = resumed->tiles.size();
                kept.emplace(*image, *options.checkpoint, id, options.checkpoint_interval,
                             resumed ? std::move(resumed->tiles) : std::vector<TileBuffer>{});
            } catch (const CheckpointError& e) {
                refused = e.what();
            }
        }
    }
    const bool refuse =
        options.mpi ? options.mpi->leaders(refused.empty() ? 0 : 1) != 0 : !refused.empty();
    if (refuse) throw CheckpointError(leader ? refused : "the leader refused the checkpoint");

    std::stop_source stopper;
    const std::stop_callback relay(options.stop, [&] { stopper.request_stop(); });
    std::optional<StopAfter> stop_after;
    TileSink* into = nullptr;
    std::vector<Tile> todo;
    RenderOptions run;
    run.threads = options.threads;
    run.stop = stopper.get_token();
    if (leader) {
        into = kept ? static_cast<TileSink*>(&*kept) : &*image;
        if (options.stop_after_tiles) {
            into =
                &stop_after.emplace(*into, image->tiles_done(), *options.stop_after_tiles, stopper);
        }
        todo = image->missing();
        if (options.on_progress) {
            run.on_progress = [&](double) {
                options.on_progress(double(image->tiles_done()) / double(image->tile_count()));
            };
        }
    }
    if (leader && options.costly_first) {
        const int threads = worker_threads(run.threads);
        todo = costly_first(context, std::move(todo),
                            threads * (options.mpi ? options.mpi->size() : 1), threads);
    }
    const auto tiles_start = std::chrono::steady_clock::now();
    MpiShare share;
    if (options.mpi) {
        // Elsewhere than on the leader, tiles go to the leader instead of a sink.
        ImageSink unused(0, 0, {});
        share = options.mpi->render(context, std::move(todo), into ? *into : unused, run);
    } else {
        TileQueue queue(std::move(todo));
        share.threads = render_tiles(context, queue, *into, run);
        share.emptied = queue.emptied();
    }
    const auto finished = std::chrono::steady_clock::now();
    if (!leader) {
        out.done = out.tiles;
        return out;
    }
    out.render = assembled(context, *image);
    out.done = image->tiles_done();
    RenderStats& stats = out.render.stats;
    stats.threads = share.threads;
    if (share.emptied) {
        stats.tail_seconds = std::chrono::duration<double>(finished - *share.emptied).count();
    }
    stats.tile_messages = share.messages;
    stats.receive_seconds = share.receive_seconds;
    stats.assemble_seconds = share.assemble_seconds;
    stats.processes = options.mpi ? options.mpi->size() : 1;
    if (kept && !out.complete()) kept->write();
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats.setup_seconds =
        stats.seconds - std::chrono::duration<double>(finished - tiles_start).count();
    return out;
}

}  // namespace drt
