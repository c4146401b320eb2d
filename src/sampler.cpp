#include "drt/sampler.h"

#include <cmath>

#include "drt/rng.h"

namespace drt {

namespace {

std::uint32_t key32(std::uint64_t h) { return static_cast<std::uint32_t>(h ^ (h >> 32)); }

}  // namespace

PixelSample PixelSample::branch(std::uint64_t kind, std::uint64_t j) const {
    PixelSample child = *this;
    child.path = hash_of(path, kind, j);
    return child;
}

double IndependentSampler::get_1d(const PixelSample& s, std::uint32_t dim) const {
    return to_unit(hash_of(s.seed, s.pixel, s.index, dim, s.path));
}

Vec2 IndependentSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    const std::uint64_t h = hash_of(s.seed, s.pixel, s.index, dim, s.path);
    return {to_unit(h), to_unit(mix64(h))};
}

Vec2 IndependentSampler::get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                                       std::uint32_t) const {
    const std::uint64_t h = hash_of(s.seed, s.pixel, s.index, dim, s.path, j);
    return {to_unit(h), to_unit(mix64(h))};
}

Vec2 multi_jittered(std::uint32_t j, std::uint32_t k, std::uint32_t key) {
    // Kensler's pattern for any k: an m x n grid of cells, m*n >= k, as square as possible. Point
    // s (a shuffled j) takes its own stratum of y among k strata, and its own column sx and
    // sub-column sy of x among m*n; when k = m*n each cell of the grid holds exactly one point.
    // Which of the m*n sub-columns stay empty when k < m*n is left to the shuffles, so every
    // point is uniform over the square (a fixed choice would leave a corner unsampled).
    const auto m = static_cast<std::uint32_t>(std::max(1.0, std::floor(std::sqrt(double(k)))));
    const std::uint32_t n = (k + m - 1) / m;
    const std::uint32_t s = permute(j, k, key * 0x51633e2du);
    const std::uint32_t sx = permute(s % m, m, key * 0x68bc21ebu);
    const std::uint32_t sy = permute(s / m, n, key * 0x02e5be93u);
    const double jx = to_unit(hash_of(key, s, 1));
    const double jy = to_unit(hash_of(key, s, 2));
    return {(sx + (sy + jx) / n) / m, (s + jy) / k};
}

double StratifiedSampler::get_1d(const PixelSample& s, std::uint32_t dim) const {
    const std::uint32_t key = key32(hash_of(s.seed, s.pixel, dim, s.path));
    const double jitter = to_unit(hash_of(s.seed, s.pixel, s.index, dim, s.path));
    return (permute(s.index, s.count, key) + jitter) / s.count;
}

Vec2 StratifiedSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    return multi_jittered(s.index, s.count, key32(hash_of(s.seed, s.pixel, dim, s.path)));
}

Vec2 StratifiedSampler::get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                                      std::uint32_t k) const {
    return multi_jittered(j, k, key32(hash_of(s.seed, s.pixel, s.index, dim, s.path)));
}

std::unique_ptr<Sampler> make_sampler(std::string_view name) {
    if (name == "random") return std::make_unique<IndependentSampler>();
    if (name == "stratified") return std::make_unique<StratifiedSampler>();
    return nullptr;
}

std::vector<std::string> sampler_names() { return {"random", "stratified"}; }

}  // namespace drt
