// Piecewise-constant densities over the unit interval and the unit square, sampled by inverting
// their cumulative distributions: a 1-D one over n equal cells, and a 2-D one over an nu x nv
// grid as a marginal over rows times a conditional within each row (Pharr, Jakob and Humphreys,
// "Physically Based Rendering", 13.6.7). A function that is zero everywhere is sampled uniformly.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "drt/util/math.h"

namespace drt {

class Distribution1D {
  public:
    // `f`: the non-negative value of each cell (at least one cell).
    explicit Distribution1D(std::span<const float> f);

    struct Sample {
        double x;           // in [0, 1)
        double pdf;         // density at x over [0, 1]
        std::size_t index;  // the cell x is in
    };
    // The point whose cumulative probability is u in [0, 1).
    Sample sample(double u) const;
    // Density over [0, 1] in cell i.
    double pdf(std::size_t i) const { return func_[i] * density_scale_; }
    std::size_t size() const { return func_.size(); }
    // ∫ f over [0, 1] (the cells' mean); 0 for f = 0, which is then sampled as if it were 1.
    double integral() const { return integral_; }

  private:
    std::vector<float> func_;
    std::vector<float> cdf_;  // size() + 1 entries from 0 to exactly 1
    double integral_ = 0;
    double density_scale_ = 1;  // 1 / ∫ of what is sampled
};

class Distribution2D {
  public:
    // `f`: nu x nv values, row by row (f[j·nu + i] is cell i of row j; row j covers
    // v ∈ [j/nv, (j+1)/nv)).
    Distribution2D(std::span<const float> f, std::size_t nu, std::size_t nv);

    struct Sample {
        Vec2 uv;     // in [0, 1)²
        double pdf;  // density over the unit square
    };
    Sample sample(Vec2 u) const;
    double pdf(Vec2 uv) const;
    // ∫∫ f over the unit square.
    double integral() const { return marginal_.integral(); }

  private:
    std::vector<Distribution1D> rows_;
    Distribution1D marginal_;
};

}  // namespace drt
