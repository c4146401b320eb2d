#include "drt/job/render_job.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <stdexcept>
#include <string>

#include "drt/job/checkpoint.h"
#include "drt/job/tile_codec.h"
#include "drt/render/render_context.h"
#include "drt/render/tile.h"
#include "drt/util/atomic_file.h"
#include "drt/util/limits.h"
#include "drt/util/rng.h"

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

// Keeps the one tile a check renders (of a checkpoint, of MPI processes).
class KeptTile final : public TileSink {
  public:
    void add(TileBuffer buffer) override { tile = std::move(buffer); }
    std::optional<TileBuffer> tile;
};

// `tile` of `request` on this process's workers, for a check; nothing when a stop cut it short.
std::optional<TileBuffer> render_for_check(const RenderContext& context,
                                           const RenderRequest& request, const Tile& tile,
                                           const RenderJobOptions& options) {
    TileQueue queue({tile});
    KeptTile kept;
    RenderOptions run;
    run.threads = options.mpi ? options.mpi->threads_for(options.threads) : options.threads;
    run.stop = options.stop;
    render_tiles(context, request, queue, kept, run);
    return std::move(kept.tile);
}

// Renders one of the resumed tiles again (tile_to_render_again) and throws CheckpointError
// unless it comes back with every bit: a checkpoint of the same scene and options written by a
// build of drt that renders them otherwise would end in an image of two renderers' tiles. A stop
// requested meanwhile leaves the check to the next run, which resumes the same tiles.
void check_resumed_tiles(const RenderContext& context, const RenderRequest& request,
                         std::span<const TileBuffer> resumed, const RenderJobOptions& options) {
    if (resumed.empty()) return;
    const TileBuffer& kept = tile_to_render_again(resumed);
    const std::optional<TileBuffer> again = render_for_check(context, request, kept.tile, options);
    if (!again) return;
    check_rendered_alike(*options.checkpoint, kept, *again,
                         diffuse_count_for(context.scene().settings),
                         aov_channel_count(request.aovs));
}

// Under MPI, every process renders the 4 x 4 pixels at the middle of the image and fingerprints
// them with its settings, its version and the hash of the files it read; the render goes ahead
// only where every process's fingerprint is the leader's. The pixels catch another build that
// renders them otherwise (the version number does not tell builds apart), the files a stale
// copy, the settings another command line. A sample, not a proof: a build that differs only
// elsewhere in the image passes. Every process takes part in both collectives whatever happens
// to it, so that a process that fails here (out of memory, say) cannot leave the others waiting.
void check_processes_agree(const RenderContext& context, const RenderRequest& request,
                           const RenderJobOptions& options) {
    const MpiJob* mpi = options.mpi;
    if (mpi == nullptr || mpi->size() == 1) return;
    std::uint64_t fingerprint = 0;
    bool stopped = false;  // before the probe was done: the render that follows stops too
    std::exception_ptr failure;
    try {
        const RenderSettings& settings = context.scene().settings;
        constexpr int kProbe = 4;
        const int x0 = std::max(0, settings.width / 2 - kProbe / 2);
        const int y0 = std::max(0, settings.height / 2 - kProbe / 2);
        const std::optional<TileBuffer> probe =
            render_for_check(context, request,
                             Tile{0, x0, y0, std::min(settings.width, x0 + kProbe),
                                  std::min(settings.height, y0 + kProbe)},
                             options);
        stopped = !probe;
        if (probe) {
            fingerprint = hash_bytes(
                encode_tile(*probe, diffuse_count_for(settings), aov_channel_count(request.aovs)));
        }
        const RenderIdentity id = identify_render({}, settings, request.applied_adaptive(),
                                                  context.tiles().size(), request.aovs);
        const auto* version = reinterpret_cast<const unsigned char*>(id.version.data());
        fingerprint = hash_of(fingerprint, id.options, hash_bytes({version, id.version.size()}),
                              options.scene_files_hash);
    } catch (...) {
        failure = std::current_exception();
    }
    // A probe cut short by a stop is no evidence either way.
    const std::vector<std::uint32_t> leaders =
        mpi->broadcast({static_cast<std::uint32_t>(fingerprint),
                        static_cast<std::uint32_t>(fingerprint >> 32), stopped ? 1u : 0u});
    const bool differs =
        leaders.size() != 3 || (!stopped && leaders[2] == 0 &&
                                (leaders[0] != static_cast<std::uint32_t>(fingerprint) ||
                                 leaders[1] != static_cast<std::uint32_t>(fingerprint >> 32)));
    // Agreed by all: a failed process (size + its rank) outranks one that differs (its rank).
    const int size = mpi->size(), rank = mpi->rank();
    const int worst = mpi->highest(failure ? size + rank : differs ? rank : 0);
    if (failure) std::rethrow_exception(failure);
    if (worst >= size) {
        throw std::runtime_error("process " + std::to_string(worst - size) + " of the " +
                                 std::to_string(size) +
                                 " failed before rendering (only process 0's messages are shown)");
    }
    if (worst != 0) {
        throw ProcessesDisagree(
            "process " + std::to_string(worst) + " of the " + std::to_string(size) +
            " renders this scene differently from process 0 (another scene or OBJ file, other "
            "options or another build of drt there); every process must read the same files "
            "with the same command and drt");
    }
}

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
}

// Opens the leader's checkpoint of `request` into `kept`, its resumed tiles added to `image`.
// A refusal is agreed by every process: then all throw CheckpointError.
void open_checkpoint(const RenderContext& context, const RenderRequest& request,
                     const RenderJobOptions& options, bool leader, ImageSink* image,
                     std::optional<CheckpointSink>& kept, std::size_t& resumed_tiles) {
    if (!options.checkpoint) return;
    const RenderSettings& settings = context.scene().settings;
    if (request.pixels != PixelChoice::kAll || request.paired ||
        request.samples != settings.samples || request.seed != settings.seed) {
        throw std::invalid_argument("a checkpoint of a request other than the scene's image");
    }
    std::string refused;
    std::exception_ptr failure;  // anything else that went wrong on the leader
    if (leader) {
        try {
            const RenderIdentity id =
                identify_render(options.scene_files, settings, request.applied_adaptive(),
                                context.tiles().size(), request.aovs);
            try {
                check_replaceable(*options.checkpoint);
            } catch (const FileWriteError& e) {
                throw CheckpointError(e.what());
            }
            std::optional<Checkpoint> resumed =
                read_checkpoint(*options.checkpoint, id, context.tiles());
            if (resumed) {
                check_resumed_tiles(context, request, resumed->tiles, options);
                resumed_tiles = resumed->tiles.size();
            }
            kept.emplace(*image, *options.checkpoint, id, options.checkpoint_interval,
                         resumed ? std::move(resumed->tiles) : std::vector<TileBuffer>{});
        } catch (const CheckpointError& e) {
            refused = e.what();
        } catch (...) {
            failure = std::current_exception();
        }
    }
    // Every process takes part in the broadcast, whatever happened on the leader.
    const bool ok = refused.empty() && !failure;
    const bool refuse = options.mpi ? options.mpi->broadcast(ok ? 0 : 1) != 0 : !ok;
    if (failure) std::rethrow_exception(failure);
    if (refuse) throw CheckpointError(leader ? refused : "the leader refused the checkpoint");
}

// Renders `todo` into `into` (the leader's; absent elsewhere) across the job's processes.
MpiShare render_share(const RenderContext& context, const RenderRequest& request,
                      std::vector<Tile> todo, TileSink* into, const RenderOptions& run,
                      const MpiJob* mpi) {
    if (mpi) {
        // Elsewhere than on the leader, tiles go to the leader instead of a sink.
        ImageSink unused(0, 0, {});
        return mpi->render_tiles(context, request, std::move(todo), into ? *into : unused, run);
    }
    MpiShare share;
    TileQueue queue(std::move(todo));
    share.threads = render_tiles(context, request, queue, *into, run);
    share.emptied = queue.emptied();
    return share;
}

// The leader's figures of how the job's processes shared the tiles, `finished` when they had.
void add_share(RenderStats& stats, const MpiShare& share, Clock::time_point finished,
               const MpiJob* mpi) {
    stats.threads = share.threads;
    if (share.emptied) stats.tail_seconds = seconds_between(*share.emptied, finished);
    stats.tile_messages = share.messages;
    stats.receive_seconds = share.receive_seconds;
    stats.assemble_seconds = share.assemble_seconds;
    stats.processes = mpi ? mpi->size() : 1;
}

RenderJobResult run_job(const RenderContext& context, const RenderRequest& asked,
                        const RenderJobOptions& options, Clock::time_point start) {
    // A checkpoint keeps the estimate's sums: a render with one always estimates.
    RenderRequest request = asked;
    request.estimate_error = request.estimate_error || options.checkpoint.has_value();
    context.check(request);
    check_processes_agree(context, request, options);
    const Scene& scene = context.scene();
    const bool leader = options.mpi == nullptr || options.mpi->leader();
    RenderJobResult out;
    out.tiles = context.tiles().size();

    // Only the leader assembles the image and keeps the checkpoint.
    std::optional<ImageSink> image;
    if (leader) {
        image.emplace(scene.settings.width, scene.settings.height, context.tiles(),
                      aov_channel_count(request.aovs));
    }
    std::optional<CheckpointSink> kept;
    open_checkpoint(context, request, options, leader, image ? &*image : nullptr, kept,
                    out.resumed);

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
            // This process's share counts the pixels handed out of its tiles in hand
            // (render_tiles); the image counts the tiles resumed and those other processes sent.
            const double before = double(image->tiles_done());
            const double share = double(todo.size());
            const double all = double(image->tile_count());
            run.on_progress = [&, before, share, all](double done) {
                options.on_progress(std::max(double(image->tiles_done()), before + done * share) /
                                    all);
            };
        }
    }
    if (leader && options.costly_first) {
        const int threads = worker_threads(run.threads);
        todo = costly_first(context, request, std::move(todo),
                            threads * (options.mpi ? options.mpi->size() : 1), threads);
    }
    const auto tiles_start = Clock::now();
    const MpiShare share = render_share(context, request, std::move(todo), into, run, options.mpi);
    const auto finished = Clock::now();
    if (!leader) {
        out.done = out.tiles;
        return out;
    }
    out.render = assembled(context, request, *image);
    out.done = image->tiles_done();
    RenderStats& stats = out.render.stats;
    add_share(stats, share, finished, options.mpi);
    if (kept && !out.complete()) {
        try {
            kept->write();
        } catch (const CheckpointError& e) {
            out.checkpoint_failure = e.what();
        }
    }
    stats.seconds = seconds_between(start, Clock::now());
    stats.setup_seconds = stats.seconds - seconds_between(tiles_start, finished);
    return out;
}

}  // namespace

RenderJobResult run_render_job(const Scene& scene, const RenderRequest& request,
                               const RenderJobOptions& options) {
    const auto start = Clock::now();
    const RenderContext context(scene);
    return run_job(context, request, options, start);
}

RenderJobResult run_render_job(const RenderContext& context, const RenderRequest& request,
                               const RenderJobOptions& options) {
    return run_job(context, request, options, Clock::now());
}

}  // namespace drt
