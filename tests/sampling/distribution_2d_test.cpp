// Piecewise-constant distributions: densities that integrate to 1, samples that land in each
// cell as often as the density says, also for a full-size 4096 x 2048 environment map.
#include "drt/sampling/distribution_2d.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "drt/util/rng.h"
#include "test_math.h"

namespace drt {
namespace {

using testing::unit;

// Pearson's chi-square statistic of `counts` against `expected` counts.
double chi_square(const std::vector<double>& counts, const std::vector<double>& expected) {
    double sum = 0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        if (expected[i] > 0)
            sum += (counts[i] - expected[i]) * (counts[i] - expected[i]) / expected[i];
    }
    return sum;
}

TEST(Distribution1D, DensityFollowsTheFunctionAndSamplesMatchIt) {
    const std::vector<float> f{1, 0, 3, 6};
    const Distribution1D d(f);
    EXPECT_DOUBLE_EQ(d.integral(), 2.5);
    EXPECT_DOUBLE_EQ(d.pdf(0), 0.4);
    EXPECT_DOUBLE_EQ(d.pdf(1), 0.0);
    EXPECT_DOUBLE_EQ(d.pdf(3), 2.4);
    constexpr int kSamples = 100000;
    std::vector<double> counts(4, 0);
    for (int i = 0; i < kSamples; ++i) {
        const auto s = d.sample(unit(1, i));
        ASSERT_GE(s.x, 0.0);
        ASSERT_LT(s.x, 1.0);
        ASSERT_EQ(s.index, static_cast<std::size_t>(s.x * 4));
        ASSERT_DOUBLE_EQ(s.pdf, d.pdf(s.index));
        ++counts[s.index];
    }
    EXPECT_EQ(counts[1], 0);
    // 2 degrees of freedom: chi-square above 13.8 has probability 0.001.
    EXPECT_LT(chi_square(counts, {0.1 * kSamples, 0, 0.3 * kSamples, 0.6 * kSamples}), 13.8);
}

TEST(Distribution1D, ZeroFunctionIsSampledUniformly) {
    const std::vector<float> f(5, 0.0f);
    const Distribution1D d(f);
    EXPECT_EQ(d.integral(), 0);
    for (std::size_t i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(d.pdf(i), 1.0);
    EXPECT_NEAR(d.sample(0.5).x, 0.5, 1e-6);
}

// A random 16 x 8 grid with some empty cells and rows: the density integrates to 1 over the unit
// square, sample() reports the density pdf() gives at its point, and the samples fall into the
// cells in proportion to the density (chi-square over the cells). A density 2 % off fails the
// integral.
TEST(Distribution2D, DensityIntegratesToOneAndSamplesMatchIt) {
    constexpr std::size_t nu = 16, nv = 8;
    std::vector<float> f(nu * nv);
    for (std::size_t k = 0; k < f.size(); ++k) {
        f[k] = unit(7, k) < 0.2 ? 0.0f : static_cast<float>(10 * unit(8, k));
    }
    for (std::size_t i = 0; i < nu; ++i) f[3 * nu + i] = 0;  // an empty row
    const Distribution2D d(f, nu, nv);
    double total = 0;
    std::vector<double> expected(nu * nv);
    constexpr int kSamples = 400000;
    for (std::size_t j = 0; j < nv; ++j) {
        for (std::size_t i = 0; i < nu; ++i) {
            const double p = d.pdf({(i + 0.5) / nu, (j + 0.5) / nv});
            EXPECT_NEAR(p, f[j * nu + i] / (d.integral() * 1.0), 1e-5 * (1 + p));
            total += p / (nu * nv);
            expected[j * nu + i] = p / (nu * nv) * kSamples;
        }
    }
    EXPECT_NEAR(total, 1.0, 1e-6);
    std::vector<double> counts(nu * nv, 0);
    for (int k = 0; k < kSamples; ++k) {
        const auto s = d.sample({unit(2, k), unit(3, k)});
        ASSERT_NEAR(s.pdf, d.pdf(s.uv), 1e-9 * s.pdf);
        ++counts[static_cast<std::size_t>(s.uv.y * nv) * nu +
                 static_cast<std::size_t>(s.uv.x * nu)];
    }
    // About 100 non-empty cells: chi-square with ~100 degrees of freedom stays below 160 with
    // probability above 0.9999.
    EXPECT_LT(chi_square(counts, expected), 160);
}

// A full-size 4096 x 2048 map builds a distribution whose integral is the mean of the function
// (its cells are 1/nu by 1/nv) and whose brightest cell is the most probable. Its build time is a
// benchmark (BM_Distribution2DBuild), not a test.
TEST(Distribution2D, AFullSizeEnvironmentMapHasTheMeanAsIntegralAndPeaksAtItsBrightestCell) {
    constexpr std::size_t nu = 4096, nv = 2048;
    std::vector<float> f(nu * nv, 1.0f);
    constexpr std::size_t peak_u = 3000, peak_v = 100;
    f[peak_v * nu + peak_u] = 1.0e6f;
    const Distribution2D d(f, nu, nv);
    const double mean = (static_cast<double>(nu * nv) - 1.0 + 1.0e6) / static_cast<double>(nu * nv);
    EXPECT_NEAR(d.integral(), mean, 1e-6 * mean);
    const double u = (peak_u + 0.5) / nu, v = (peak_v + 0.5) / nv;
    EXPECT_NEAR(d.pdf({u, v}), 1.0e6 / mean, 1e-3 * 1.0e6 / mean);
    EXPECT_NEAR(d.pdf({0.5 / nu, 0.5 / nv}), 1.0 / mean, 1e-6 / mean);
}

}  // namespace
}  // namespace drt
