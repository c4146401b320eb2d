#include "drt/sampling/distribution_2d.h"

#include <algorithm>
#include <cmath>

namespace drt {

namespace {

std::vector<float> row_integrals(std::span<const float> f, std::size_t nu, std::size_t nv,
                                 std::vector<Distribution1D>& rows) {
    std::vector<float> integrals;
    integrals.reserve(nv);
    rows.reserve(nv);
    for (std::size_t j = 0; j < nv; ++j) {
        rows.emplace_back(f.subspan(j * nu, nu));
        integrals.push_back(static_cast<float>(rows.back().integral()));
    }
    return integrals;
}

}  // namespace

Distribution1D::Distribution1D(std::span<const float> f)
    : func_(f.begin(), f.end()), cdf_(f.size() + 1) {
    const std::size_t n = func_.size();
    // Sums in double: a float running sum over thousands of cells would drift.
    double running = 0;
    std::vector<double> cdf(n + 1, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        func_[i] = std::max(0.0f, func_[i]);  // also turns NaN into 0
        running += func_[i];
        cdf[i + 1] = running;
    }
    integral_ = running / static_cast<double>(n);
    if (!(running > 0)) {
        std::fill(func_.begin(), func_.end(), 1.0f);
        for (std::size_t i = 0; i <= n; ++i) cdf[i] = static_cast<double>(i);
        running = static_cast<double>(n);
    }
    density_scale_ = static_cast<double>(n) / running;
    for (std::size_t i = 0; i <= n; ++i) cdf_[i] = static_cast<float>(cdf[i] / running);
    cdf_[n] = 1.0f;
}

Distribution1D::Sample Distribution1D::sample(double u) const {
    // The last cell whose start is at or below u, skipping empty cells.
    const auto above = std::upper_bound(cdf_.begin(), cdf_.end(), static_cast<float>(u));
    const std::size_t i = std::min<std::size_t>(
        static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, above - cdf_.begin() - 1)),
        func_.size() - 1);
    const double lo = cdf_[i];
    const double width = static_cast<double>(cdf_[i + 1]) - lo;
    const double within = width > 0 ? std::clamp((u - lo) / width, 0.0, 1.0) : 0.5;
    const double x = std::min((static_cast<double>(i) + within) / static_cast<double>(size()),
                              std::nextafter(1.0, 0.0));
    return {x, pdf(i), i};
}

Distribution2D::Distribution2D(std::span<const float> f, std::size_t nu, std::size_t nv)
    : marginal_(row_integrals(f, nu, nv, rows_)) {}

Distribution2D::Sample Distribution2D::sample(Vec2 u) const {
    const Distribution1D::Sample v = marginal_.sample(u.y);
    const Distribution1D::Sample w = rows_[v.index].sample(u.x);
    return {{w.x, v.x}, v.pdf * w.pdf};
}

double Distribution2D::pdf(Vec2 uv) const {
    const auto cell = [](double t, std::size_t n) {
        return std::min(static_cast<std::size_t>(std::max(0.0, t * static_cast<double>(n))), n - 1);
    };
    const std::size_t j = cell(uv.y, rows_.size());
    const Distribution1D& row = rows_[j];
    return marginal_.pdf(j) * row.pdf(cell(uv.x, row.size()));
}

}  // namespace drt
