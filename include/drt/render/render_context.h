// What a render builds once from the scene — the sampler, the plan, the acceleration structure,
// the integrator and the tile grid — and the one function that turns a tile of a request
// (render_request.h) into its buffer. A tile's buffer depends on nothing but the scene, the
// request and the tile, so any process holding the same scene renders the same bits for it.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stop_token>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/render/aov.h"
#include "drt/render/pixel_integrator.h"
#include "drt/render/render_plan.h"
#include "drt/render/render_request.h"
#include "drt/render/tile.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/scene.h"

namespace drt {

class RenderContext {
    // A tile's pixels, handed out one at a time to the thread rendering it and to helpers.
    struct PixelRun;

  public:
    // Throws std::invalid_argument for an unknown sampler name. The scene's samples and seed are
    // not read: each request brings its own.
    explicit RenderContext(const Scene& scene);
    // The integrators refer to the sampler, plans and BVH held here: the context stays put.
    RenderContext(const RenderContext&) = delete;
    RenderContext& operator=(const RenderContext&) = delete;

    const Scene& scene() const { return scene_; }
    // What `request` samples: one sample per pixel takes the pixel's centre, more its area.
    const RenderPlan& plan(const RenderRequest& request) const;
    // The whole image's tiles, row by row; a tile's index is its position here.
    const std::vector<Tile>& tiles() const { return tiles_; }

    // Throws std::invalid_argument unless the context can render `request`: at least one
    // sample, a pixel block of at least 2, listed pixels inside the image, ascending, distinct.
    void check(const RenderRequest& request) const;

    // Photons traced so far (0 without caustics).
    std::uint64_t photons_traced() const { return photons_ ? photons_->traced() : 0; }

    // How the request's samples tell their error (error_estimate.h).
    SpreadKind spread_kind(const RenderRequest& request) const;

    // Whether `request` renders pixel (x, y). With one pixel per block of b, the one pixel of its
    // b x b square (squares aligned to the image's corner) that a hash of the seed and the square
    // picks among b x b places; a square cut by the image's edge may then have none, so that
    // every pixel has the same odds, 1 / b^2.
    bool renders(const RenderRequest& request, int x, int y) const;
    // How many pixels renders() picks.
    std::uint64_t rendered_pixels(const RenderRequest& request) const;

    // Tiles whose pixels are being rendered, open to threads that have no tile of their own
    // left: rather than wait idle for the last tiles to finish (the render's tail, a good part
    // of a small image's few tiles), they render some of those tiles' pixels (help). A pixel is
    // the same whichever thread renders it, and a tile's buffer the same however many helped.
    class Workbench {
      public:
        Workbench() = default;
        Workbench(const Workbench&) = delete;
        Workbench& operator=(const Workbench&) = delete;

        // Held by a thread that takes tiles of its own for as long as it may take another,
        // from before it asks for its first: while any is held, a helper with nothing to do
        // waits for tiles still to come rather than leave. A thread that never started holds
        // none, so no helper waits for it.
        class Taker {
          public:
            explicit Taker(Workbench& bench);
            ~Taker();
            Taker(const Taker&) = delete;
            Taker& operator=(const Taker&) = delete;

          private:
            Workbench& bench_;
        };

        // How much of the tiles open here is handed out, in tiles (a tile half done adds 0.5): a
        // progress display's steps within tiles, which at thousands of samples a pixel take
        // minutes. The estimate's second renders of a tile count nothing.
        double tiles_in_hand() const;

      private:
        friend class RenderContext;
        mutable std::mutex mutex_;
        std::condition_variable_any changed_;  // a tile opened, or a taker left
        std::vector<std::shared_ptr<PixelRun>> open_;
        int takers_ = 0;
    };

    // Renders the pixels of `tile` that `request` picks. Safe to call from several threads.
    TileBuffer render_tile(const Tile& tile, const RenderRequest& request) const;
    // The same, abandoned within 256 samples once `stop` is requested: a tile of thousands of
    // samples a pixel takes seconds, too long to keep a person who stopped the render waiting.
    // With a workbench, the tile's pixels are open there to helpers while it renders them.
    std::optional<TileBuffer> render_tile(const Tile& tile, const RenderRequest& request,
                                          const std::stop_token& stop,
                                          Workbench* bench = nullptr) const;
    // Renders pixels of the tiles open on `bench` until no tile has any left to hand out and no
    // taker will open another, or until `stop` is requested; returns how many it rendered.
    std::size_t help(Workbench& bench, const std::stop_token& stop) const;

    // A guess at what render_tile(tile, request) costs, in shaded rays (camera, reflection,
    // refraction and diffuse rays: shadow rays left out, cheap beside the shading they serve):
    // those one camera sample traces at a probe pixel in each 4 × 4 block of the tile (8 × 8
    // under 16 samples per pixel), scaled to the tile's pixels. Ray counts, not clock time, so
    // the guess is the same on every machine and in every run; the probes cost 1/16 of one
    // sample per pixel and change no pixel.
    std::uint64_t tile_cost(const Tile& tile, const RenderRequest& request) const;

  private:
    // What one pixel's render leaves: its value, the spread of its samples, the camera samples it
    // took, whether adaptive sampling stopped it early.
    struct Pixel {
        Color value;
        Color spread;
        std::uint32_t samples = 0;
        bool converged = false;
    };
    // Reused from pixel to pixel of a tile: the radiance of each camera sample of the pixel in
    // hand and their places in the pixel, and for adaptive sampling all the pixel's samples so
    // far and their luminances, and the strata spread's sort buffer.
    struct Scratch {
        std::vector<Color> colors;
        std::vector<Vec2> positions;
        StrataScratch strata;
        std::vector<Color> taken;
        std::vector<double> luminances;
    };

    const PixelIntegrator& integrator(const RenderRequest& request) const;
    // One pixel on ray-tree path `path` (0 for the image's own render), adaptively or not; they
    // add their rays to `rays`. Nothing if `stop` came first.
    std::optional<Pixel> render_pixel(const RenderRequest& request, int x, int y,
                                      std::uint64_t path, Scratch& scratch, RayCounts& rays,
                                      const std::stop_token& stop) const;
    std::optional<Pixel> plain_pixel(const RenderRequest& request, int x, int y, std::uint64_t path,
                                     Scratch& scratch, RayCounts& rays,
                                     const std::stop_token& stop) const;
    std::optional<Pixel> adaptive_pixel(const RenderRequest& request, int x, int y,
                                        std::uint64_t path, Scratch& scratch, RayCounts& rays,
                                        const std::stop_token& stop) const;
    // The pixel's camera samples s.index, s.index + 1, ... into `out`, kSamplesBetweenStops at a
    // time, so that a stop is heard within a few milliseconds rather than a pixel of 65,536
    // samples (seconds); every sample is a function of its own index, so the bits are those of
    // one run. False if `stop` came first.
    bool sample(const RenderRequest& request, int x, int y, PixelSample s, std::span<Color> out,
                RayCounts& rays, const std::stop_token& stop) const;
    static constexpr std::size_t kSamplesBetweenStops = 256;
    // The pixels of `tile` that renders() picks, as indices row by row into the tile.
    std::vector<std::size_t> rendered_in(const Tile& tile, const RenderRequest& request) const;
    // Renders the run's pixels on this thread and, with a bench, on any helping; adds their
    // rays to `rays`. False if `stop` came first.
    bool render_run(const std::shared_ptr<PixelRun>& run, Workbench* bench,
                    const std::stop_token& stop, Scratch& scratch, RayCounts& rays) const;
    // Renders some of the tile's `rendered` pixels a second time for the error estimate's
    // calibration (error_estimate.h) and adds them to the buffer's error sums; `pixels` are all
    // the tile's, row by row. False if `stop` came first.
    bool calibrate(const RenderRequest& request, const Tile& tile, std::span<const Pixel> pixels,
                   std::span<const std::size_t> rendered, Scratch& scratch, TileBuffer& buffer,
                   const std::stop_token& stop, Workbench* bench) const;
    // A paired request's second render of each of the tile's `rendered` pixels: averaged into
    // the buffer's pixels, the pair's difference its spread. False if `stop` came first.
    bool render_again(const RenderRequest& request, const Tile& tile, std::span<const Pixel> pixels,
                      std::span<const std::size_t> rendered, Scratch& scratch, TileBuffer& buffer,
                      const std::stop_token& stop, Workbench* bench) const;

    const Scene& scene_;
    std::unique_ptr<Sampler> sampler_;
    Bvh bvh_;
    // For requests of more than one sample per pixel, and for those of one (pixel centres).
    RenderPlan area_plan_, centre_plan_;
    // When the scene calls for caustics; the two plans trace the same photons.
    std::unique_ptr<const PhotonMaps> photons_;
    // The integrator the scene names (make_integrator), over each plan.
    std::unique_ptr<const PixelIntegrator> area_integrator_, centre_integrator_;
    AovTracer area_aovs_, centre_aovs_;  // the camera rays of each plan
    std::vector<Tile> tiles_;
};

// `tiles` with the costliest by tile_cost first (equal guesses in index order): handed out in
// this order, the slow tiles start early and the render's tail, when some workers have nothing
// left while others finish, is one cheap tile long rather than one costly one. A render of one
// worker gains nothing from it and gets `tiles` back untouched. `threads` (this process's)
// share the probes; an exception on any of them is rethrown here.
std::vector<Tile> costly_first(const RenderContext& context, const RenderRequest& request,
                               std::vector<Tile> tiles, int workers, int threads = 1);

}  // namespace drt
