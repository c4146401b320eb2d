// Where the random numbers of every Monte Carlo dimension come from.
//
// A pixel's value is a nested integral over independent dimensions (pixel area, lens, time,
// light, gloss). Each dimension has its own number, so a sampler can distribute every
// dimension well across a pixel's camera samples, and an effect the scene does not call for
// simply never asks for its dimension.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drt/util/math.h"

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
    // The pixel's camera sample this is, counted over the whole pixel, is pass_base + index: a
    // renderer that starts a new pattern for more samples (index from 0 again) says where it
    // continues. Photon maps are per such pass (photon_map.h); samplers do not read it.
    std::uint32_t pass_base = 0;

    std::uint32_t pass() const { return pass_base + index; }
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
    // get_2d for camera samples s.index, s.index + 1, ... of the pixel, into out, at once: a
    // sampler can work out what a pixel's samples share (the pattern's shuffles) only once.
    virtual void get_2d_run(const PixelSample& s, std::uint32_t dim, std::span<Vec2> out) const;

    // Point j of a set of k taken within one camera sample (the shadow rays of one shading point,
    // the glossy rays of one hit): the k points are distributed well together.
    virtual Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                               std::uint32_t k) const = 0;
    // Ray j of `rays` taken at one shading point: the camera sample's own point of `dim` for a
    // lone ray (stratified across the pixel's samples), point j of the set for several.
    Vec2 get_2d_for_ray(const PixelSample& s, std::uint32_t dim, int j, int rays) const {
        return rays == 1 ? get_2d(s, dim)
                         : get_2d_in_set(s, dim, static_cast<std::uint32_t>(j),
                                         static_cast<std::uint32_t>(rays));
    }
    // get_2d_for_ray for rays first .. first + out.size() - 1 of `rays`, at once.
    void get_2d_for_rays(const PixelSample& s, std::uint32_t dim, int rays, int first,
                         std::span<Vec2> out) const {
        if (rays == 1) {
            out[0] = get_2d(s, dim);
        } else {
            get_2d_set(s, dim, static_cast<std::uint32_t>(rays), static_cast<std::uint32_t>(first),
                       out);
        }
    }
    // Points first .. first + out.size() - 1 of that set of k, exactly as get_2d_in_set gives
    // them, at once: a sampler can work out what the points share (the set's key) only once.
    virtual void get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k,
                            std::uint32_t first, std::span<Vec2> out) const;

    // True when a pixel's samples form one sequence that ignores PixelSample::count: samples
    // count .. 2*count-1 then refine the pattern of the first count instead of repeating it, so
    // a renderer may add samples to a pixel by continuing the index.
    virtual bool extensible() const { return false; }
    // True when every number is independent of every other: a pixel's samples are then
    // independent, and their sample variance over n is the variance of their mean.
    virtual bool independent() const { return false; }
};

// get_2d for the samples of one run of a pixel (first.index, first.index + 1, ...), remembering
// the run's points of the dimensions its samples keep asking for one at a time: a glossy
// bounce's, which every camera ray of the pixel that reaches the glossy surface along the same
// branch of the ray tree asks for. From the kDrawAfter-th request for a dimension on, the whole
// run's points of it are drawn at once (get_2d_run, cheaper per point) and then looked up. The
// points are exactly get_2d's.
class RunPoints {
  public:
    RunPoints(const Sampler& sampler, const PixelSample& first, std::uint32_t length)
        : sampler_(sampler), first_(first), length_(length) {}

    Vec2 get_2d(const PixelSample& s, std::uint32_t dim);

  private:
    static constexpr std::uint32_t kDrawAfter = 3;
    static constexpr std::size_t kMaxRemembered = 32;  // dimension and branch pairs
    struct Remembered {
        std::uint32_t dim;
        std::uint64_t path;
        std::uint32_t requests = 0;
        std::vector<Vec2> points;  // the run's, once drawn
    };

    const Sampler& sampler_;
    PixelSample first_;
    std::uint32_t length_;
    std::vector<Remembered> remembered_;
};

// Independent uniform random numbers: the Monte Carlo baseline.
class IndependentSampler final : public Sampler {
  public:
    std::string_view name() const override { return "random"; }
    bool independent() const override { return true; }
    double get_1d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d(const PixelSample& s, std::uint32_t dim) const override;
    Vec2 get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                       std::uint32_t k) const override;
    void get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k, std::uint32_t first,
                    std::span<Vec2> out) const override;
};

// The sampler of that name (random, stratified.h's or sobol.h's), or nullptr; sampler_names()
// lists the valid names.
std::unique_ptr<Sampler> make_sampler(std::string_view name);
std::vector<std::string> sampler_names();

}  // namespace drt
