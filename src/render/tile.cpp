#include "drt/render/tile.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace drt {

std::vector<Tile> tile_grid(int width, int height, int size) {
    std::vector<Tile> tiles;
    for (int y = 0; y < height; y += size) {
        for (int x = 0; x < width; x += size) {
            tiles.push_back(
                {tiles.size(), x, y, std::min(x + size, width), std::min(y + size, height)});
        }
    }
    return tiles;
}

std::optional<Tile> TileQueue::next() {
    const std::size_t i = next_.fetch_add(1, std::memory_order_relaxed);
    if (i >= tiles_.size()) return std::nullopt;
    if (i + 1 == tiles_.size()) emptied_ = std::chrono::steady_clock::now();
    return tiles_[i];
}

ImageSink::ImageSink(int width, int height, std::vector<Tile> grid, std::size_t aov_channels)
    : grid_(std::move(grid)),
      image_(width, height),
      pixel_samples_(static_cast<std::size_t>(width) * height, 0),
      spread_(width, height),
      aov_channels_(aov_channels),
      aovs_(aov_channels * static_cast<std::size_t>(width) * height, 0.0f),
      error_sums_(grid_.size()),
      done_(grid_.size(), false) {}

void ImageSink::add(TileBuffer buffer) {
    const Tile& t = buffer.tile;
    if (t.index >= grid_.size() || !(grid_[t.index] == t)) {
        throw std::invalid_argument("tile " + std::to_string(t.index) + " is not in the grid");
    }
    if (buffer.pixels.width != t.width() || buffer.pixels.height != t.height() ||
        buffer.pixel_samples.size() != buffer.pixels.rgb.size() / 3 ||
        buffer.spread.rgb.size() != buffer.pixels.rgb.size() ||
        buffer.aovs.size() != aov_channels_ * buffer.pixel_samples.size()) {
        throw std::invalid_argument("tile " + std::to_string(t.index) +
                                    ": buffer does not match the tile's size");
    }
    const std::lock_guard lock(mutex_);
    if (done_[t.index]) {
        throw std::logic_error("tile " + std::to_string(t.index) + " was added twice");
    }
    done_[t.index] = true;
    ++tiles_done_;
    const auto row = static_cast<std::size_t>(t.width());
    for (int y = t.y0; y < t.y1; ++y) {
        const std::size_t from = static_cast<std::size_t>(y - t.y0) * row;
        const std::size_t to = static_cast<std::size_t>(y) * image_.width + t.x0;
        std::copy_n(buffer.pixels.rgb.begin() + 3 * from, 3 * row, image_.rgb.begin() + 3 * to);
        std::copy_n(buffer.spread.rgb.begin() + 3 * from, 3 * row, spread_.rgb.begin() + 3 * to);
        std::copy_n(buffer.pixel_samples.begin() + from, row, pixel_samples_.begin() + to);
        if (aov_channels_ > 0) {
            std::copy_n(buffer.aovs.begin() + static_cast<std::ptrdiff_t>(aov_channels_ * from),
                        aov_channels_ * row,
                        aovs_.begin() + static_cast<std::ptrdiff_t>(aov_channels_ * to));
        }
    }
    error_sums_[t.index] = buffer.error_sums;
    rays_ += buffer.rays;
    samples_ += buffer.samples;
    converged_ += buffer.converged;
}

std::vector<Tile> ImageSink::missing() const {
    const std::lock_guard lock(mutex_);
    std::vector<Tile> tiles;
    for (const Tile& t : grid_) {
        if (!done_[t.index]) tiles.push_back(t);
    }
    return tiles;
}

ErrorSums ImageSink::error_sums() const {
    const std::lock_guard lock(mutex_);
    ErrorSums total;
    for (const ErrorSums& s : error_sums_) total += s;
    return total;
}

std::size_t ImageSink::tiles_done() const {
    const std::lock_guard lock(mutex_);
    return tiles_done_;
}

}  // namespace drt
