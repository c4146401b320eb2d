#include "drt/sampling/sampler.h"

#include <algorithm>
#include <vector>

#include "drt/sampling/sobol.h"
#include "drt/sampling/stratified.h"
#include "drt/util/rng.h"

namespace drt {

void Sampler::get_2d_run(const PixelSample& s, std::uint32_t dim, std::span<Vec2> out) const {
    PixelSample sample = s;
    for (Vec2& point : out) {
        point = get_2d(sample, dim);
        ++sample.index;
    }
}

void Sampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k,
                         std::uint32_t first, std::span<Vec2> out) const {
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = get_2d_in_set(s, dim, first + static_cast<std::uint32_t>(i), k);
    }
}

Vec2 RunPoints::get_2d(const PixelSample& s, std::uint32_t dim) {
    const std::uint32_t at = s.index - first_.index;
    const bool in_run = s.seed == first_.seed && s.pixel == first_.pixel &&
                        s.count == first_.count && s.index >= first_.index && at < length_;
    if (!in_run) return sampler_.get_2d(s, dim);
    auto found = std::find_if(remembered_.begin(), remembered_.end(), [&](const Remembered& r) {
        return r.dim == dim && r.path == s.path;
    });
    if (found == remembered_.end()) {
        if (remembered_.size() == kMaxRemembered) return sampler_.get_2d(s, dim);
        found = remembered_.insert(remembered_.end(), Remembered{dim, s.path, 0, {}});
    }
    if (!found->points.empty()) return found->points[at];
    if (++found->requests < kDrawAfter) return sampler_.get_2d(s, dim);
    PixelSample run = first_;
    run.path = s.path;
    found->points.resize(length_);
    sampler_.get_2d_run(run, dim, found->points);
    return found->points[at];
}

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

void IndependentSampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t,
                                    std::uint32_t first, std::span<Vec2> out) const {
    // hash_of folds left, so the hash of (..., path, j) continues the one of (..., path).
    const std::uint64_t set = hash_of(s.seed, s.pixel, s.index, dim, s.path);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const std::uint64_t h = hash_combine(set, static_cast<std::uint32_t>(first + i));
        out[i] = {to_unit(h), to_unit(mix64(h))};
    }
}

std::unique_ptr<Sampler> make_sampler(std::string_view name) {
    if (name == "random") return std::make_unique<IndependentSampler>();
    if (name == "stratified") return std::make_unique<StratifiedSampler>();
    if (name == "sobol") return std::make_unique<SobolSampler>();
    return nullptr;
}

std::vector<std::string> sampler_names() {
    return {"random", "stratified", "sobol"};
}

}  // namespace drt
