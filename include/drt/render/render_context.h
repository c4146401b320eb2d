// What a render builds once from the scene — the sampler, the plan, the acceleration structure,
// the integrator and the tile grid — and the one function that turns a tile into its buffer.
// A tile's buffer depends on nothing but the scene, the adaptive settings and the tile, so any
// process holding the same scene renders the same bits for it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/render/integrator.h"
#include "drt/render/pixel_integrator.h"
#include "drt/render/render_plan.h"
#include "drt/render/tile.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/scene.h"

namespace drt {

// Adaptive sampling: each pixel takes samples in rounds, each round as many as it has so far,
// and stops once the estimated standard error of its mean luminance falls below the threshold,
// or at the scene's sample count. The estimate is the sample deviation over sqrt(n), or for a
// progressive sampler the spread of the means of 8 consecutive runs over sqrt(8), which credits
// stratification. The decision reads only the pixel's own samples, so the image stays
// independent of the thread count.
struct AdaptiveSampling {
    double noise_threshold = 0;  // in linear luminance units
    int min_samples = 16;        // taken before the estimate is trusted; capped at the maximum
};

class RenderContext {
  public:
    // Throws std::invalid_argument for an unknown sampler name. `estimate_error` false skips the
    // error estimate's calibration (its second renders), for a render whose estimate nobody reads.
    // `pixel_block` above 1 renders one pixel of each pixel_block x pixel_block square of the
    // image (see renders()) and leaves the others 0: a pilot that measures the whole image's
    // error per pixel at a fraction of its cost (progressive.h). `top_up`, when not empty, the
    // indices y * width + x of the only pixels rendered (a top-up round, progressive.h): each
    // twice, with independent patterns, and the two averaged; a pixel's spread is then a quarter
    // of the pair's squared difference, whose expectation is the variance of their mean whatever
    // the sampler (spread_kind() kIndependent): the estimate is the top-up pixels' own.
    RenderContext(const Scene& scene, std::optional<AdaptiveSampling> adaptive,
                  bool estimate_error = true, int pixel_block = 1,
                  std::span<const std::uint32_t> top_up = {});
    // The integrator refers to the sampler, plan and BVH held here: the context stays put.
    RenderContext(const RenderContext&) = delete;
    RenderContext& operator=(const RenderContext&) = delete;

    const Scene& scene() const { return scene_; }
    const RenderPlan& plan() const { return plan_; }
    // As applied: the minimum capped at the scene's sample count.
    const std::optional<AdaptiveSampling>& adaptive() const { return adaptive_; }
    // The whole image's tiles, row by row; a tile's index is its position here.
    const std::vector<Tile>& tiles() const { return tiles_; }

    // How the sampler's samples tell their error (error_estimate.h).
    SpreadKind spread_kind() const;

    // Whether pixel (x, y) is rendered: every pixel, or with a pixel block of b, the one pixel of
    // its b x b square (squares aligned to the image's corner) that a hash of the seed and the
    // square picks among b x b places; a square cut by the image's edge may then have none, so
    // that every pixel has the same odds, 1 / b^2, and the rendered pixels' mean error is an
    // unbiased guess at the image's. With top-up pixels, those.
    bool renders(int x, int y) const;
    // How many pixels renders() picks.
    std::uint64_t rendered_pixels() const { return rendered_pixels_; }

    // Renders the pixels of `tile` that renders() picks (every one without a pixel block). Safe
    // to call from several threads at once.
    TileBuffer render_tile(const Tile& tile) const;

    // A guess at what render_tile(tile) costs, in shaded rays (camera, reflection and refraction
    // rays: shadow rays left out, cheap beside the shading they serve): those one camera sample
    // traces at a pilot pixel in each 4 × 4 block of the tile (8 × 8 under 16 samples per
    // pixel), scaled to the tile's pixels. Ray counts, not clock time, so the guess is the same
    // on every machine and in every run; the pilot costs 1/16 of one sample per pixel (under
    // 0.4 % of the render at 16 samples or more, 1.6 % at 1) and changes no pixel.
    std::uint64_t estimate_cost(const Tile& tile) const;

  private:
    // With a pixel block of b, the place (y % b) * b + x % b of the pixel that renders() picks in
    // square (sx, sy), counted from the square's corner.
    std::uint64_t picked_place(std::uint64_t sx, std::uint64_t sy) const;

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

    // One pixel on ray-tree path `path` (0 for the image's own render), adaptively or not; they
    // add their rays to `rays`.
    Pixel render_pixel(int x, int y, std::uint64_t path, Scratch& scratch, RayCounts& rays) const;
    Pixel plain_pixel(int x, int y, std::uint64_t path, Scratch& scratch, RayCounts& rays) const;
    Pixel adaptive_pixel(int x, int y, std::uint64_t path, Scratch& scratch, RayCounts& rays) const;
    // The pixels of `tile` that renders() picks, as indices row by row into the tile.
    std::vector<std::size_t> rendered_in(const Tile& tile) const;
    // Renders some of the tile's `rendered` pixels a second time for the error estimate
    // (error_estimate.h) and adds them to the buffer's error sums; `pixels` are all the tile's,
    // row by row.
    void calibrate(const Tile& tile, std::span<const Pixel> pixels,
                   std::span<const std::size_t> rendered, Scratch& scratch,
                   TileBuffer& buffer) const;
    // A top-up's second render of each of the tile's `rendered` pixels: averaged into the
    // buffer's pixels, the pair's difference its spread.
    void render_again(const Tile& tile, std::span<const Pixel> pixels,
                      std::span<const std::size_t> rendered, Scratch& scratch,
                      TileBuffer& buffer) const;

    const Scene& scene_;
    std::unique_ptr<Sampler> sampler_;
    RenderPlan plan_;
    Bvh bvh_;
    std::unique_ptr<const PixelIntegrator> integrator_;  // the one the scene names
    std::optional<AdaptiveSampling> adaptive_;
    bool estimate_error_;
    int pixel_block_;
    std::vector<bool> top_up_;  // per pixel, row by row; empty: not a top-up
    std::uint64_t rendered_pixels_ = 0;
    std::vector<Tile> tiles_;
};

// `tiles` with the costliest by estimate_cost first (equal guesses in index order): handed out in
// this order, the slow tiles start early and the render's tail, when some workers have nothing
// left while others finish, is one cheap tile long rather than one costly one. A render of one
// worker gains nothing from it and gets `tiles` back untouched. `threads` (this process's)
// share the pilot; an exception on any of them is rethrown here.
std::vector<Tile> costly_first(const RenderContext& context, std::vector<Tile> tiles, int workers,
                               int threads = 1);

}  // namespace drt
