#include "drt/sampling/stratified.h"

#include "drt/sampling/dimension_memo.h"
#include "drt/sampling/multi_jittered.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

std::uint32_t key32(std::uint64_t h) {
    return static_cast<std::uint32_t>(h ^ (h >> 32));
}

// What one dimension's pattern over a pixel's camera samples on one ray-tree branch derives from:
// its key, and the hash of (seed, pixel) that its 1-D jitters continue.
struct PatternKeys {
    std::uint32_t key;
    std::uint64_t pixel_hash;
};

PatternKeys pattern_keys(const PixelSample& s, std::uint32_t dim) {
    thread_local DimensionMemo<PatternKeys> memo;
    return memo.get(s, dim, [&] {
        return PatternKeys{key32(hash_of(s.seed, s.pixel, dim, s.path)), hash_of(s.seed, s.pixel)};
    });
}

std::uint32_t pattern_key(const PixelSample& s, std::uint32_t dim) {
    return pattern_keys(s, dim).key;
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
    const PatternKeys keys = pattern_keys(s, dim);
    // hash_of(seed, pixel, index, dim, path), continued from the pixel's part (hash_of folds left).
    const std::uint64_t h =
        hash_combine(hash_combine(hash_combine(keys.pixel_hash, s.index), dim), s.path);
    const double jitter = to_unit(h);
    return (permute(s.index, s.count, keys.key) + jitter) / s.count;
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
