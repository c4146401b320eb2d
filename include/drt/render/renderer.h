// Renders a scene into an image: tiles from a TileSource rendered by worker threads
// (RenderContext::render_tile) and handed to a TileSink. Each pixel is a pure function of the
// scene and the request (render_request.h), so the image never depends on the thread count, the
// order of the tiles or which process rendered them.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <stop_token>
#include <vector>

#include "drt/io/image.h"
#include "drt/render/error_estimate.h"
#include "drt/render/integrator.h"
#include "drt/render/render_context.h"
#include "drt/render/render_plan.h"
#include "drt/render/render_request.h"
#include "drt/render/tile.h"
#include "drt/scene/scene.h"

namespace drt {

struct RenderOptions {
    int threads = 0;  // 0 = all cores
    // Called now and then from the rendering thread with the fraction done (0..1).
    std::function<void(double)> on_progress;
    // For render(scene, options) alone (a request says its own): absent, every pixel takes the
    // scene's samples.
    std::optional<AdaptiveSampling> adaptive;
    // Checked between pixels: once a stop is requested, each worker abandons the tile in hand
    // (TileSource::give_back) and takes no other, so only whole tiles are done
    // (RenderResult::unfinished lists the rest).
    std::stop_token stop;
};

struct RenderStats {
    double seconds = 0;
    // Of those, what went before and after rendering the tiles (building the context where the
    // render built one, ordering the tiles, assembling the image). Set by run_render_job.
    double setup_seconds = 0;
    int threads = 1;    // worker threads of one process
    int processes = 1;  // processes of an MPI job (mpi_work.h)
    // From the last tile handed out to the last one finished: the tail, when workers run out of
    // work one by one. Set by run_render_job (render_job.h).
    double tail_seconds = 0;
    // An MPI job's leader: the finished tiles other processes sent it, and the time its
    // communication thread spent receiving them and adding them to the image.
    std::uint64_t tile_messages = 0;
    double receive_seconds = 0, assemble_seconds = 0;
    RayCounts rays;
    // Photons a render of the request traces: Count for each pass, one pass per camera sample
    // index (photon_map.h), whichever process or thread traced them; 0 without caustics.
    std::uint64_t photons = 0;
    std::uint64_t samples = 0;           // camera samples taken over all pixels
    std::uint64_t pixels_converged = 0;  // adaptive: pixels that stopped before the maximum
    // Adaptive sampling as applied, the minimum capped at the maximum; absent for a plain render.
    std::optional<AdaptiveSampling> adaptive;
    // The image's own estimate of its error against the converged image (error_estimate.h).
    ErrorEstimate error;
};

struct RenderResult {
    Image image;
    RenderPlan plan;
    RenderStats stats;
    // Adaptive sampling only: the camera samples each pixel took, row by row.
    std::vector<std::uint32_t> pixel_samples;
    // The spread of each pixel's samples, per channel: times stats.error.scale, the variance of
    // the pixel's mean.
    Image spread;
    // The request's AOVs (aov.h): aov_channel_count values a pixel, row by row.
    std::vector<Aov> aov_list;
    std::vector<float> aovs;
    // Tiles not rendered because a stop was requested (their pixels are 0); empty otherwise.
    std::vector<Tile> unfinished;
};

// The whole image at the scene's samples and seed, with options.adaptive.
RenderResult render(const Scene& scene, const RenderOptions& options);
// `request` on `scene` set up for it alone; options.adaptive is ignored: the request's applies.
RenderResult render(const Scene& scene, const RenderRequest& request, const RenderOptions& options);

// The tiles of `request` that `sink` does not have yet, then the result of all of them: a render
// resumed from tiles finished earlier (added to the sink first) gives the same bits as one never
// stopped. options.adaptive is ignored: the request's applies.
RenderResult complete_render(const RenderContext& context, const RenderRequest& request,
                             ImageSink& sink, const RenderOptions& options);

// What the tiles of `request` in `sink` make: the image, the per-pixel sample counts and spreads,
// the totals, the error estimate and the tiles still missing (stats.seconds and stats.threads are
// left for the caller).
RenderResult assembled(const RenderContext& context, const RenderRequest& request,
                       const ImageSink& sink);

// Renders tiles of `request` from `source` on options.threads workers (capped at source.size())
// into `sink` until the source runs dry or a stop is requested. Throws std::invalid_argument for
// a request the context cannot render (RenderContext::check). An exception in a worker (from the
// source, the tile or the sink) stops the other workers after their tile in hand and is rethrown
// here. options.on_progress gets the fraction of source.size() done. Returns the threads used.
int render_tiles(const RenderContext& context, const RenderRequest& request, TileSource& source,
                 TileSink& sink, const RenderOptions& options);

}  // namespace drt
