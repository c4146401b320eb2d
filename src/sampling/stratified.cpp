#include "drt/sampling/stratified.h"

#include "drt/sampling/multi_jittered.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

std::uint32_t key32(std::uint64_t h) {
    return static_cast<std::uint32_t>(h ^ (h >> 32));
}

// The key of one dimension's pattern over a pixel's camera samples on one ray-tree branch.
std::uint32_t pattern_key(const PixelSample& s, std::uint32_t dim) {
    return key32(hash_of(s.seed, s.pixel, dim, s.path));
}

// The key of one camera sample's set in one dimension of one ray-tree branch: (seed, pixel,
// sample, dimension, branch) folded into three hashes rather than five, since sets are drawn
// at every shading point.
std::uint32_t set_key(const PixelSample& s, std::uint32_t dim) {
    const std::uint64_t sample = (std::uint64_t{s.pixel} << 32) | s.index;
    return key32(hash_of(s.seed, sample, s.path ^ (std::uint64_t{dim} * 0x9e3779b97f4a7c15ULL)));
}

}  // namespace

double StratifiedSampler::get_1d(const PixelSample& s, std::uint32_t dim) const {
    const double jitter = to_unit(hash_of(s.seed, s.pixel, s.index, dim, s.path));
    return (permute(s.index, s.count, pattern_key(s, dim)) + jitter) / s.count;
}

Vec2 StratifiedSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    return multi_jittered(s.index, s.count, pattern_key(s, dim));
}

void StratifiedSampler::get_2d_run(const PixelSample& s, std::uint32_t dim,
                                   std::span<Vec2> out) const {
    multi_jittered(s.index, s.count, pattern_key(s, dim), out);
}

Vec2 StratifiedSampler::get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                                      std::uint32_t k) const {
    Vec2 point;
    multi_jittered_set(j, k, set_key(s, dim), {&point, 1});
    return point;
}

void StratifiedSampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k,
                                   std::uint32_t first, std::span<Vec2> out) const {
    multi_jittered_set(first, k, set_key(s, dim), out);
}

}  // namespace drt
