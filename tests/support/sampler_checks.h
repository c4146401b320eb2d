// Statistical checks shared by the sampler tests: exact stratification, uniformity (chi-square and
// Kolmogorov-Smirnov bounds) and correlation.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "drt/util/math.h"

namespace drt::testing {

inline bool in_unit(double v) {
    return v >= 0.0 && v < 1.0;
}

inline double correlation(const std::vector<double>& a, const std::vector<double>& b) {
    const double n = static_cast<double>(a.size());
    double sa = 0, sb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) sa += a[i], sb += b[i];
    const double ma = sa / n, mb = sb / n;
    double cab = 0, caa = 0, cbb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        cab += (a[i] - ma) * (b[i] - mb);
        caa += (a[i] - ma) * (a[i] - ma);
        cbb += (b[i] - mb) * (b[i] - mb);
    }
    return cab / std::sqrt(caa * cbb);
}

// The grid a multi-jittered pattern of k points uses: m columns by n rows, m = floor(sqrt(k)),
// m*n >= k.
inline std::pair<std::uint32_t, std::uint32_t> grid_of(std::uint32_t k) {
    const auto m = static_cast<std::uint32_t>(std::max(1.0, std::floor(std::sqrt(double(k)))));
    return {m, (k + m - 1) / m};
}

// Checks that k points are stratified exactly as a multi-jittered pattern (Kensler 2013)
// promises for any k: with its m x n grid, y has exactly one point in each of k strata and x at
// most one in each of m*n strata; when k = m*n, each cell of the grid holds exactly one point.
inline ::testing::AssertionResult multi_jittered_strata(const std::vector<Vec2>& points) {
    const auto k = static_cast<std::uint32_t>(points.size());
    const auto [m, n] = grid_of(k);
    std::set<std::pair<std::uint32_t, std::uint32_t>> cells;
    std::set<std::uint32_t> xs, ys;
    for (const Vec2& p : points) {
        if (!in_unit(p.x) || !in_unit(p.y)) {
            return ::testing::AssertionFailure() << "point (" << p.x << ", " << p.y << ") outside";
        }
        cells.insert({static_cast<std::uint32_t>(p.x * m), static_cast<std::uint32_t>(p.y * n)});
        xs.insert(static_cast<std::uint32_t>(p.x * m * n));
        ys.insert(static_cast<std::uint32_t>(p.y * k));
    }
    if (xs.size() != k || ys.size() != k || (k == m * n && cells.size() != k)) {
        return ::testing::AssertionFailure()
               << k << " points on a " << m << "x" << n << " grid: " << cells.size()
               << " distinct cells, " << xs.size() << " distinct x strata of " << m * n << ", "
               << ys.size() << " distinct y strata of " << k;
    }
    return ::testing::AssertionSuccess();
}

// The Kolmogorov-Smirnov test of values against the uniform distribution on [0, 1): the largest
// gap between their empirical distribution and the identity must stay below 1.95 / sqrt(N), which
// uniform values exceed with probability 0.001.
inline ::testing::AssertionResult uniform_by_ks(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const double n = static_cast<double>(values.size());
    double gap = 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        gap = std::max({gap, values[i] - double(i) / n, double(i + 1) / n - values[i]});
    }
    const double bound = 1.95 / std::sqrt(n);
    if (gap < bound) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "KS distance " << gap << " from uniform over "
                                         << values.size() << " values (bound " << bound << ")";
}

// Pearson's chi-square test that counts are equally likely: the statistic must stay below
// df + 5 sqrt(2 df) (df = bins - 1), about five standard deviations above its mean.
inline ::testing::AssertionResult equally_likely(const std::vector<int>& counts) {
    double total = 0;
    for (const int c : counts) total += c;
    const double expected = total / static_cast<double>(counts.size());
    double chi2 = 0;
    for (const int c : counts) chi2 += (c - expected) * (c - expected) / expected;
    const double df = static_cast<double>(counts.size()) - 1;
    const double bound = df + 5 * std::sqrt(2 * df);
    if (chi2 < bound) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "chi-square " << chi2 << " over " << counts.size() << " bins (bound " << bound << ")";
}

}  // namespace drt::testing
