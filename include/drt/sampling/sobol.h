// Owen-scrambled Sobol points: the sampler and the sequence it draws from.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "drt/sampling/sampler.h"

namespace drt {

// Owen-scrambled Sobol points (after Burley 2020, "Practical Hash-based Owen Scrambling"). The
// camera's dimensions (pixel area, lens, time) are Sobol dimensions 0-1, 2-3 and 4 of one
// sequence per pixel, so they are stratified jointly. Every other dimension draws from its own
// copy of the 2-D Sobol (0,2)-sequence. Each sequence has its sample index shuffled and its
// digits scrambled by keys hashed from (seed, pixel, dimension, path), so sequences are
// decorrelated and pixels independent. Any aligned block of 2^m consecutive samples of a
// (0,2)-sequence is a (0,m,2)-net: one point in every elementary interval of area 2^-m, in
// particular in every cell of a 2^a x 2^b grid with a + b = m. The shuffle keeps that true of
// the first 2^m samples, so every power-of-two count is a net and other counts are the first
// points of the next one. A set of k points within camera sample i takes the first k points of
// the aligned block of K indices (K = k rounded up to a power of two) that the shuffle sends
// indices i*K .. i*K+K-1 to, so a set of K is itself a net and the sets of a pixel's samples
// together refine one another.
class SobolSampler final : public Sampler {
  public:
    std::string_view name() const override { return "sobol"; }
    double get_1d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                       std::uint32_t k) const override;
    void get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k, std::uint32_t first,
                    std::span<Vec2> out) const override;
    bool extensible() const override { return true; }
};

// A keyed permutation of 32-bit words standing in for Owen's nested uniform scrambling of base-2
// digits: digit d (from the most significant) of x is flipped by a pseudo-random function of the
// key and of digits 0 .. d-1 only. It therefore maps every aligned block of 2^m words onto an
// aligned block of 2^m words.
std::uint32_t nested_scramble(std::uint32_t x, std::uint32_t key);

// Coordinate `dimension` (0 .. kSobolDimensions-1) of the i-th point of the Sobol sequence, in
// 32-bit fixed point (Joe and Kuo's direction numbers; dimension 0 is van der Corput).
inline constexpr int kSobolDimensions = 6;
std::uint32_t sobol(std::uint32_t i, int dimension);

}  // namespace drt
