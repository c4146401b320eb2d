// The default sampler: jittered strata in every dimension.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "drt/sampling/sampler.h"

namespace drt {

// Jittered strata in every dimension: multi-jittered patterns (multi_jittered.h) in 2-D and
// shuffled jittered strata in 1-D. A 2-D pattern of k points always stratifies y into k strata;
// x and the m x n cells of the square are fully stratified only when k = m*n (e.g. square k).
// Each dimension's pattern is keyed separately, so dimensions are decorrelated. A pixel's camera
// samples are the points of one pattern per dimension, labelled by the sample index; a set is a
// pattern of its own per camera sample (multi_jittered_set).
class StratifiedSampler final : public Sampler {
  public:
    std::string_view name() const override { return "stratified"; }
    double get_1d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d(const PixelSample& s, std::uint32_t dim) const override;
    void get_2d_run(const PixelSample& s, std::uint32_t dim, std::span<Vec2> out) const override;
    Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                       std::uint32_t k) const override;
    void get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k, std::uint32_t first,
                    std::span<Vec2> out) const override;
};

}  // namespace drt
