// Work units: the image cut into tiles, what rendering one tile produces, where tiles come from
// and where their results go. Every pixel is a pure function of the scene, the options and the
// seed, so a tile's buffer is the same whoever renders it, whenever, in whatever order; the
// assembled image cannot depend on how the tiles were handed out.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "drt/io/image.h"
#include "drt/render/error_estimate.h"
#include "drt/render/integrator.h"

namespace drt {

// Pixels x0 <= x < x1, y0 <= y < y1 of the image; `index` numbers the tiles of one image row by
// row, so a tile can be named across processes and in a checkpoint.
struct Tile {
    std::size_t index = 0;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    friend bool operator==(const Tile&, const Tile&) = default;
};

// A width × height image cut into squares of `size` pixels (smaller at the right and bottom
// edges), row by row. 16 keeps a tile's pixels in cache and gives every thread many tiles.
inline constexpr int kTileSize = 16;
std::vector<Tile> tile_grid(int width, int height, int size = kTileSize);

// What rendering one tile produced. The counts are integers, so buffers add up to the same
// totals in any order.
struct TileBuffer {
    Tile tile;
    Image pixels;                              // the tile's own width × height, row 0 at its top
    std::vector<std::uint32_t> pixel_samples;  // camera samples each pixel took, row by row
    Image spread;          // of each pixel's samples, per channel (error_estimate.h)
    ErrorSums error_sums;  // the tile's pixels' shares of the image's error estimate
    RayCounts rays;
    std::uint64_t samples = 0;    // camera samples over the tile's pixels
    std::uint64_t converged = 0;  // adaptive: pixels that stopped before the maximum
    // The request's AOVs: aov_channel_count values a pixel, row by row; empty without them.
    std::vector<float> aovs;
};

// Hands out tiles to render. next() is called from several worker threads at once and returns
// nothing once there is no more work for the caller. A source decides only which tiles are
// rendered and by whom, never what they contain.
class TileSource {
  public:
    virtual ~TileSource() = default;
    virtual std::optional<Tile> next() = 0;
    // Tiles this source expects to hand out in all: scales progress.
    virtual std::size_t size() const = 0;
    // A tile handed out and then abandoned by a stop. Left alone it is simply missing from the
    // image (the render's unfinished tiles); a source serving another process returns it there.
    virtual void give_back(const Tile& /*tile*/) {}
};

// Takes finished tiles. add() is called from several worker threads at once.
class TileSink {
  public:
    virtual ~TileSink() = default;
    virtual void add(TileBuffer buffer) = 0;
};

// A fixed list of tiles handed out in order, one at a time, to whichever thread asks first: the
// whole grid for a plain render, the tiles a checkpoint lacks for a resumed one, or any order
// (costly tiles first, say).
class TileQueue final : public TileSource {
  public:
    explicit TileQueue(std::vector<Tile> tiles) : tiles_(std::move(tiles)) {}

    std::optional<Tile> next() override;
    std::size_t size() const override { return tiles_.size(); }

    // When the last tile was handed out, if it was: the start of the render's tail, when workers
    // run out of work one by one while the others finish theirs. Read once the workers are done.
    std::optional<std::chrono::steady_clock::time_point> emptied() const { return emptied_; }

  private:
    std::vector<Tile> tiles_;
    std::atomic<std::size_t> next_{0};
    std::optional<std::chrono::steady_clock::time_point> emptied_;  // by the last tile's taker
};

// Assembles tile buffers into the image, the per-pixel sample counts and spreads and the totals,
// and remembers which tiles it has. A tile given twice is an error: its counts would be summed
// twice.
class ImageSink final : public TileSink {
  public:
    // `aov_channels`: the AOV values each pixel of a tile carries (aov.h), 0 for none.
    ImageSink(int width, int height, std::vector<Tile> grid, std::size_t aov_channels = 0);

    void add(TileBuffer buffer) override;

    // The tiles of the grid not added yet, in grid order.
    std::vector<Tile> missing() const;
    std::size_t tiles_done() const;
    std::size_t tile_count() const { return grid_.size(); }

    // The assembly so far; read them once no thread is adding any more.
    const Image& image() const { return image_; }
    const std::vector<std::uint32_t>& pixel_samples() const { return pixel_samples_; }
    const Image& spread() const { return spread_; }
    const std::vector<float>& aovs() const { return aovs_; }  // per pixel, row by row
    // Added up in tile order, so the same whatever order the tiles came in.
    ErrorSums error_sums() const;
    const RayCounts& rays() const { return rays_; }
    std::uint64_t samples() const { return samples_; }
    std::uint64_t converged() const { return converged_; }

  private:
    std::vector<Tile> grid_;
    Image image_;
    std::vector<std::uint32_t> pixel_samples_;
    Image spread_;
    std::size_t aov_channels_;
    std::vector<float> aovs_;
    std::vector<ErrorSums> error_sums_;  // by tile index
    RayCounts rays_;
    std::uint64_t samples_ = 0, converged_ = 0;
    std::vector<bool> done_;  // by tile index
    std::size_t tiles_done_ = 0;
    mutable std::mutex mutex_;
};

}  // namespace drt
