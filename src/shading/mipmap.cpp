#include "drt/shading/mipmap.h"

#include <algorithm>
#include <cmath>

namespace drt {

namespace {

// Box-filters `rgb` (w x h, 3 floats a texel) to `to` texels along x: output texel i averages
// the source over [i, i + 1) · w / to, each source texel weighted by its overlap.
std::vector<float> shrink_rows(const std::vector<float>& rgb, int w, int h, int to) {
    std::vector<float> out(static_cast<std::size_t>(3) * to * h, 0.0f);
    const double step = static_cast<double>(w) / to;
    for (int y = 0; y < h; ++y) {
        const float* src = rgb.data() + 3 * static_cast<std::size_t>(y) * w;
        float* dst = out.data() + 3 * static_cast<std::size_t>(y) * to;
        for (int i = 0; i < to; ++i) {
            const double lo = i * step, hi = (i + 1) * step;
            double sum[3] = {0, 0, 0};
            for (int s = static_cast<int>(lo); s < w && s < hi; ++s) {
                const double weight =
                    (std::min<double>(s + 1, hi) - std::max<double>(s, lo)) / step;
                for (int c = 0; c < 3; ++c) sum[c] += weight * src[3 * s + c];
            }
            for (int c = 0; c < 3; ++c) dst[3 * i + c] = static_cast<float>(sum[c]);
        }
    }
    return out;
}

// The same along y.
std::vector<float> shrink_columns(const std::vector<float>& rgb, int w, int h, int to) {
    std::vector<float> out(static_cast<std::size_t>(3) * w * to, 0.0f);
    const double step = static_cast<double>(h) / to;
    for (int j = 0; j < to; ++j) {
        const double lo = j * step, hi = (j + 1) * step;
        for (int s = static_cast<int>(lo); s < h && s < hi; ++s) {
            const double weight = (std::min<double>(s + 1, hi) - std::max<double>(s, lo)) / step;
            if (weight <= 0) continue;
            const std::size_t src = 3 * static_cast<std::size_t>(s) * w;
            const std::size_t dst = 3 * static_cast<std::size_t>(j) * w;
            for (std::size_t k = 0; k < 3 * static_cast<std::size_t>(w); ++k)
                out[dst + k] += static_cast<float>(weight * rgb[src + k]);
        }
    }
    return out;
}

int wrap(int i, int n) {
    const int r = i % n;
    return r < 0 ? r + n : r;
}

}  // namespace

MipMap::MipMap(const Image& image) {
    Level base{image.width, image.height, std::vector<float>(image.rgb.size())};
    const std::size_t row = 3 * static_cast<std::size_t>(image.width);
    for (int y = 0; y < image.height; ++y) {
        const auto from = image.rgb.begin() + static_cast<std::ptrdiff_t>(y * row);
        std::copy(from, from + static_cast<std::ptrdiff_t>(row),
                  base.rgb.begin() + static_cast<std::ptrdiff_t>((image.height - 1 - y) * row));
    }
    levels_.push_back(std::move(base));
    while (levels_.back().width > 1 || levels_.back().height > 1) {
        const Level& last = levels_.back();
        const int w = std::max(1, last.width / 2), h = std::max(1, last.height / 2);
        std::vector<float> rows = shrink_rows(last.rgb, last.width, last.height, w);
        levels_.push_back({w, h, shrink_columns(rows, w, last.height, h)});
    }
}

std::uint64_t MipMap::bytes_for(int width, int height) {
    std::uint64_t total = 0;
    for (;;) {
        total += std::uint64_t{12} * static_cast<std::uint64_t>(width) *
                 static_cast<std::uint64_t>(height);
        if (width == 1 && height == 1) return total;
        width = std::max(1, width / 2), height = std::max(1, height / 2);
    }
}

std::uint64_t MipMap::bytes() const {
    return bytes_for(width(), height());
}

Color MipMap::texel(int level, int i, int j) const {
    const Level& l = levels_[static_cast<std::size_t>(level)];
    const std::size_t k =
        3 * (static_cast<std::size_t>(wrap(j, l.height)) * l.width + wrap(i, l.width));
    return {l.rgb[k], l.rgb[k + 1], l.rgb[k + 2]};
}

Color MipMap::bilinear(int level, Vec2 uv) const {
    const Level& l = levels_[static_cast<std::size_t>(level)];
    // Only the fraction matters, which keeps far coordinates from overflowing int.
    const double x = (uv.x - std::floor(uv.x)) * l.width - 0.5;
    const double y = (uv.y - std::floor(uv.y)) * l.height - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const int i = static_cast<int>(fx), j = static_cast<int>(fy);
    const double ax = x - fx, ay = y - fy;
    return (texel(level, i, j) * (1 - ax) + texel(level, i + 1, j) * ax) * (1 - ay) +
           (texel(level, i, j + 1) * (1 - ax) + texel(level, i + 1, j + 1) * ax) * ay;
}

Color MipMap::filtered(Vec2 uv, double width) const {
    const int last = level_count() - 1;
    const double texels = width * std::max(levels_.front().width, levels_.front().height);
    if (!(texels > 1)) return bilinear(0, uv);
    const double level = std::log2(texels);
    if (level >= last) return bilinear(last, uv);
    const int below = static_cast<int>(level);
    const double t = level - below;
    return bilinear(below, uv) * (1 - t) + bilinear(below + 1, uv) * t;
}

Color MipMap::filtered(Vec2 uv, Vec2 dx, Vec2 dy) const {
    const double lx = std::hypot(dx.x, dx.y), ly = std::hypot(dy.x, dy.y);
    const Vec2 major = lx >= ly ? dx : dy;
    const double major_length = std::max(lx, ly);
    const double minor_length = std::max(std::min(lx, ly), major_length / kMaxAnisotropy);
    if (!(minor_length > 0)) return bilinear(0, uv);
    const int probes =
        std::min(kMaxAnisotropy, static_cast<int>(std::ceil(major_length / minor_length)));
    if (probes <= 1) return filtered(uv, major_length);
    Color sum;
    for (int k = 0; k < probes; ++k) {
        const double t = (k + 0.5) / probes - 0.5;
        sum += filtered({uv.x + major.x * t, uv.y + major.y * t}, minor_length);
    }
    return sum * (1.0 / probes);
}

}  // namespace drt
