// One of n choices picked by a uniform number from their cumulative probabilities, and what is
// left of the number: its share within the pick, stretched back over [0, 1), so that one
// well-spread number serves both the pick and the sample that follows it (a light, then a point
// on it).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

namespace drt {

struct CdfPick {
    std::size_t index;
    double probability;  // of the pick: cdf[index] - cdf[index - 1]
    double rest;         // in [0, 1)
};

// `cdf`: non-decreasing, the last exactly 1; `u` in [0, 1).
inline CdfPick pick_from_cdf(std::span<const double> cdf, double u) {
    const std::size_t k = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()),
        cdf.size() - 1);
    const double lo = k == 0 ? 0.0 : cdf[k - 1];
    const double p = cdf[k] - lo;
    return {k, p, std::clamp((u - lo) / p, 0.0, std::nextafter(1.0, 0.0))};
}

}  // namespace drt
