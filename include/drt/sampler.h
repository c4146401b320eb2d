// Where the random numbers of every Monte Carlo dimension come from.
//
// A pixel's value is a nested integral over independent dimensions (pixel area, lens, time,
// light, gloss). Each dimension has its own number, so a sampler can distribute every
// dimension well across a pixel's camera samples, and an effect the scene does not call for
// simply never asks for its dimension.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "drt/math.h"

namespace drt {

// Identifies one camera sample: the sampler's output is a pure function of this and the dimension.
struct PixelSample {
    std::uint64_t seed = 0;
    std::uint32_t pixel = 0;  // y * width + x
    std::uint32_t index = 0;  // which camera sample of the pixel, 0 .. count-1
    std::uint32_t count = 1;  // camera samples the pixel takes
    // Which branch of the ray tree is asking (0 for the camera ray's first hit): rays spawned
    // side by side, such as the glossy rays of one hit, must not reuse each other's numbers.
    std::uint64_t path = 0;

    PixelSample branch(std::uint64_t kind, std::uint64_t j) const;
};

namespace dim {
// Camera dimensions, drawn once per camera sample.
inline constexpr std::uint32_t kPixel = 0;
inline constexpr std::uint32_t kLens = 1;
inline constexpr std::uint32_t kTime = 2;
// Dimensions of a shading point at bounce depth d: bounce(d, kLight) etc.
inline constexpr std::uint32_t kLight = 0;
inline constexpr std::uint32_t kLightPick = 1;
inline constexpr std::uint32_t kGlossReflect = 2;
inline constexpr std::uint32_t kGlossRefract = 3;
inline constexpr std::uint32_t kGlassReflect = 4;
inline constexpr std::uint32_t kPerBounce = 5;
constexpr std::uint32_t bounce(int depth, std::uint32_t kind) {
    return 16 + static_cast<std::uint32_t>(depth) * kPerBounce + kind;
}
// Each area light has its own light dimension, so lights are sampled independently.
constexpr std::uint32_t light(int depth, std::size_t light_index) {
    return bounce(depth, kLight) + (static_cast<std::uint32_t>(light_index) << 16);
}
}  // namespace dim

class Sampler {
public:
    virtual ~Sampler() = default;
    virtual std::string_view name() const = 0;

    // One point of dimension `dim` for this camera sample. Across the `count` camera samples of
    // a pixel the points are distributed as well as the sampler can; dimensions are decorrelated.
    virtual double get_1d(const PixelSample& s, std::uint32_t dim) const = 0;
    virtual Vec2 get_2d(const PixelSample& s, std::uint32_t dim) const = 0;

    // Point j of a set of k taken within one camera sample (the shadow rays of one shading point,
    // the glossy rays of one hit): the k points are distributed well together.
    virtual Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                               std::uint32_t k) const = 0;
};

// Independent uniform random numbers: the Monte Carlo baseline.
class IndependentSampler final : public Sampler {
public:
    std::string_view name() const override { return "random"; }
    double get_1d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                       std::uint32_t k) const override;
};

// Jittered strata in every dimension: multi-jittered patterns (after Kensler 2013) in 2-D and
// shuffled jittered strata in 1-D. A 2-D pattern of k points always stratifies y into k strata;
// x and the m x n cells of the square are fully stratified only when k = m*n (e.g. square k).
// Each dimension's pattern is keyed separately, so dimensions are decorrelated.
class StratifiedSampler final : public Sampler {
public:
    std::string_view name() const override { return "stratified"; }
    double get_1d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                       std::uint32_t k) const override;
};

// Point j of a correlated multi-jittered pattern of k points keyed by `key`.
Vec2 multi_jittered(std::uint32_t j, std::uint32_t k, std::uint32_t key);

// The sampler of that name, or nullptr; sampler_names() lists the valid names.
std::unique_ptr<Sampler> make_sampler(std::string_view name);
std::vector<std::string> sampler_names();

}  // namespace drt
