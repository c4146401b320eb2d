#include "drt/sampling/sobol.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "drt/sampling/stratified.h"
#include "drt/util/rng.h"
#include "sampler_checks.h"

namespace drt {
namespace {

using testing::correlation;
using testing::in_unit;

// True when the 2^m points form a (t,m,2)-net: every 2^a x 2^b grid with a + b = m - t has
// exactly 2^t points in each cell (t = 0: one point in each cell of every such grid).
::testing::AssertionResult is_net(const std::vector<Vec2>& points, int t = 0) {
    const auto n = static_cast<std::uint32_t>(points.size());
    const int m = std::countr_zero(n);
    if (n == 0 || (n & (n - 1)) != 0) return ::testing::AssertionFailure() << n << " points";
    for (int a = 0; a <= m - t; ++a) {
        const double cols = std::ldexp(1.0, a), rows = std::ldexp(1.0, m - t - a);
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> cells;
        for (const Vec2& p : points) {
            if (!in_unit(p.x) || !in_unit(p.y)) {
                return ::testing::AssertionFailure()
                       << "point (" << p.x << ", " << p.y << ") outside";
            }
            ++cells[{static_cast<std::uint32_t>(p.x * cols),
                     static_cast<std::uint32_t>(p.y * rows)}];
        }
        for (const auto& [cell, count] : cells) {
            if (count != 1u << t) {
                return ::testing::AssertionFailure()
                       << n << " points: " << count << " in cell (" << cell.first << ", "
                       << cell.second << ") of the " << cols << "x" << rows << " grid";
            }
        }
    }
    return ::testing::AssertionSuccess();
}

// Warnock's formula for the L2 star discrepancy of points in the unit square.
double l2_star_discrepancy(const std::vector<Vec2>& p) {
    const double n = static_cast<double>(p.size());
    double single = 0, pairs = 0;
    for (const Vec2& a : p) {
        single += (1 - a.x * a.x) * (1 - a.y * a.y) / 4;
        for (const Vec2& b : p) pairs += (1 - std::max(a.x, b.x)) * (1 - std::max(a.y, b.y));
    }
    return std::sqrt(1.0 / 9 - 2 * single / n + pairs / (n * n));
}

std::vector<Vec2> pixel_points(const Sampler& sampler, std::uint32_t pixel, std::uint32_t count,
                               std::uint32_t d = dim::kPixel) {
    std::vector<Vec2> points;
    for (std::uint32_t index = 0; index < count; ++index) {
        points.push_back(sampler.get_2d({21, pixel, index, count}, d));
    }
    return points;
}

// Least-squares slope of log(y) against log(x).
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double lx = std::log(x[i]), ly = std::log(y[i]);
        sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

TEST(SamplerSobol, FirstPointsAreTheSobolSequence) {
    // Points 0..7 (in index order, not Gray-code order) follow from the first direction numbers
    // v_b = m_b / 2^(b+1): dimension 1 (x + 1) has m = 1, 3, 5, dimension 2 (x^2 + x + 1)
    // 1, 3, 3, dimension 3 (x^3 + x + 1) 1, 3, 1, dimension 4 (x^3 + x^2 + 1) 1, 1, 1 and
    // dimension 5 (x^4 + x + 1) 1, 1, 3. E.g. index 5 = 0b101 is v_0 xor v_2.
    const double expected[kSobolDimensions][8] = {
        {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875},
        {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875},
        {0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125},
        {0, 0.5, 0.75, 0.25, 0.125, 0.625, 0.875, 0.375},
        {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875},
        {0, 0.5, 0.25, 0.75, 0.375, 0.875, 0.125, 0.625},
    };
    for (int d = 0; d < kSobolDimensions; ++d) {
        for (std::uint32_t i = 0; i < 8; ++i) {
            EXPECT_EQ(sobol(i, d) * 0x1.0p-32, expected[d][i])
                << "dimension " << d << " index " << i;
        }
    }
    // The first direction numbers the recurrence makes rather than the table gives, m_4
    // (m_5 for degree 4): 2 a_1 m_3 ^ 4 m_2 ^ m_2 (degree 2), 2 a_1 m_3 ^ 4 a_2 m_2 ^ 8 m_1 ^ m_1
    // (degree 3), 2 a_1 m_4 ^ 4 a_2 m_3 ^ 8 a_3 m_2 ^ 16 m_1 ^ m_1 (degree 4).
    EXPECT_EQ(sobol(8, 1) * 0x1.0p-32, 15.0 / 16);   // 2*5 ^ 5
    EXPECT_EQ(sobol(8, 2) * 0x1.0p-32, 9.0 / 16);    // 2*3 ^ 4*3 ^ 3
    EXPECT_EQ(sobol(8, 3) * 0x1.0p-32, 5.0 / 16);    // 4*3 ^ 8 ^ 1
    EXPECT_EQ(sobol(8, 4) * 0x1.0p-32, 11.0 / 16);   // 2*1 ^ 8 ^ 1
    EXPECT_EQ(sobol(8, 5) * 0x1.0p-32, 3.0 / 16);    // the fourth initial m
    EXPECT_EQ(sobol(16, 5) * 0x1.0p-32, 25.0 / 32);  // 8 a_3 m_2 ^ 16 m_1 ^ m_1 = 8 ^ 16 ^ 1
}

TEST(SamplerSobol, EveryDimensionPutsOnePointInEachStratum) {
    for (int d = 0; d < kSobolDimensions; ++d) {
        for (int m = 1; m <= 12; ++m) {
            std::set<std::uint32_t> strata;
            for (std::uint32_t i = 0; i < (1u << m); ++i) strata.insert(sobol(i, d) >> (32 - m));
            EXPECT_EQ(strata.size(), 1u << m) << "dimension " << d << ", 2^" << m << " points";
        }
    }
}

TEST(SamplerSobol, EveryAlignedBlockOfTheFirstTwoDimensionsIsANet) {
    for (int m = 0; m <= 10; ++m) {
        const std::uint32_t n = 1u << m;
        for (const std::uint32_t block : {0u, 1u, 7u, 1000u}) {
            std::vector<Vec2> points;
            for (std::uint32_t j = 0; j < n; ++j) {
                const std::uint32_t i = block * n + j;
                points.push_back({sobol(i, 0) * 0x1.0p-32, sobol(i, 1) * 0x1.0p-32});
            }
            EXPECT_TRUE(is_net(points)) << "block " << block << " of " << n;
        }
    }
}

TEST(SamplerSobol, NestedScrambleMapsAlignedBlocksToAlignedBlocks) {
    for (std::uint32_t key = 0; key < 50; ++key) {
        for (int m = 1; m <= 12; m += 3) {
            for (const std::uint32_t block : {0u, 5u, 0xfffffu >> m}) {
                std::set<std::uint32_t> low, high;
                for (std::uint32_t j = 0; j < (1u << m); ++j) {
                    const std::uint32_t v = nested_scramble((block << m) + j, key * 0x9e3779b9u);
                    low.insert(v & ((1u << m) - 1));
                    high.insert(v >> m);
                }
                EXPECT_EQ(low.size(), 1u << m) << "key " << key << " m " << m;
                EXPECT_EQ(high.size(), 1u) << "key " << key << " m " << m;
            }
        }
    }
}

// Owen scrambling flips digit d of a point by an independent fair coin for each value of the
// digits before it. Over many keys, each flip must be fair and two prefixes' flips unrelated.
TEST(SamplerSobol, NestedScrambleFlipsAreFairAndIndependent) {
    const int keys = 20000;
    for (int depth = 0; depth < 5; ++depth) {
        const std::uint32_t prefixes = 1u << depth;
        std::vector<std::vector<int>> flips(prefixes, std::vector<int>(keys));
        for (int k = 0; k < keys; ++k) {
            const auto key = static_cast<std::uint32_t>(mix64(k));
            for (std::uint32_t p = 0; p < prefixes; ++p) {
                // Prefix p in digits 0 .. depth-1, digit `depth` zero: the result's digit
                // `depth` is the flip.
                const std::uint32_t x = depth == 0 ? 0 : p << (32 - depth);
                flips[p][k] = (nested_scramble(x, key) >> (31 - depth)) & 1;
            }
        }
        // Standard deviation of a mean of 20000 coins: 0.0035.
        for (std::uint32_t p = 0; p < prefixes; ++p) {
            double ones = 0;
            for (const int f : flips[p]) ones += f;
            EXPECT_NEAR(ones / keys, 0.5, 0.02) << "depth " << depth << " prefix " << p;
            for (std::uint32_t q = p + 1; q < prefixes; ++q) {
                double differ = 0;
                for (int k = 0; k < keys; ++k) differ += flips[p][k] != flips[q][k];
                EXPECT_NEAR(differ / keys, 0.5, 0.02) << "depth " << depth << " " << p << "," << q;
            }
        }
    }
}

TEST(SamplerSobol, PowerOfTwoCountsAreNetsInEveryPixelAndDimension) {
    const SobolSampler sampler;
    for (const std::uint32_t count : {1u, 2u, 4u, 8u, 16u, 64u, 256u, 1024u}) {
        for (const std::uint32_t pixel : {0u, 1u, 999u}) {
            // The lens takes Sobol dimensions 2 and 3, a (2,2)-sequence, to be stratified
            // jointly with the pixel area; the rest are (0,2)-sequences.
            for (const std::uint32_t d : {dim::kPixel, dim::kLens, dim::light(1, 2)}) {
                const int t = d == dim::kLens ? std::min(2, std::countr_zero(count)) : 0;
                EXPECT_TRUE(is_net(pixel_points(sampler, pixel, count, d), t))
                    << "count " << count << " pixel " << pixel << " dim " << d;
                std::set<std::uint32_t> strata, times;
                for (std::uint32_t index = 0; index < count; ++index) {
                    strata.insert(static_cast<std::uint32_t>(
                        sampler.get_1d({21, pixel, index, count}, d) * count));
                    times.insert(static_cast<std::uint32_t>(
                        sampler.get_1d({21, pixel, index, count}, dim::kTime) * count));
                }
                EXPECT_EQ(strata.size(), count) << "1-D, count " << count;
                EXPECT_EQ(times.size(), count) << "time, count " << count;
            }
        }
    }
}

// Pixel area and lens come from one 4-D sequence: over a pixel's samples every cell of a grid
// that splits each of the four axes alike is visited (when 2^m is a fourth power, 16 or 4096),
// where independent 2-D patterns leave about a third of the cells empty.
TEST(SamplerSobol, PixelAreaAndLensAreStratifiedTogether) {
    const SobolSampler sampler;
    for (const std::uint32_t count : {16u, 4096u}) {
        const int g = count == 16 ? 2 : 8;
        for (std::uint32_t pixel = 0; pixel < 3; ++pixel) {
            std::set<int> cells;
            for (std::uint32_t index = 0; index < count; ++index) {
                const PixelSample s{1, pixel, index, count};
                const Vec2 a = sampler.get_2d(s, dim::kPixel), b = sampler.get_2d(s, dim::kLens);
                cells.insert(((int(a.x * g) * g + int(a.y * g)) * g + int(b.x * g)) * g +
                             int(b.y * g));
            }
            EXPECT_EQ(cells.size(), count) << "count " << count << " pixel " << pixel;
        }
    }
}

TEST(SamplerSobol, MoreSamplesContinueTheSamePattern) {
    const SobolSampler sampler;
    EXPECT_TRUE(sampler.extensible());
    EXPECT_FALSE(StratifiedSampler().extensible());
    EXPECT_FALSE(IndependentSampler().extensible());
    for (std::uint32_t index = 0; index < 16; ++index) {
        const Vec2 a = sampler.get_2d({4, 8, index, 16}, dim::kLens);
        const Vec2 b = sampler.get_2d({4, 8, index, 64}, dim::kLens);
        EXPECT_EQ(a.x, b.x);
        EXPECT_EQ(a.y, b.y);
    }
    // Samples 16..31 fill the other cells of the 32-point net the first 16 began.
    std::vector<Vec2> points = pixel_points(sampler, 8, 32);
    points.resize(16);
    EXPECT_TRUE(is_net(points));
    EXPECT_TRUE(is_net(pixel_points(sampler, 8, 32)));
}

TEST(SamplerSobol, SetsArePowerOfTwoNetsAndRefineAcrossSamples) {
    const SobolSampler sampler;
    const std::uint32_t d = dim::light(0, 1);
    for (const std::uint32_t k : {2u, 4u, 8u, 16u, 64u}) {
        std::vector<Vec2> all;
        for (std::uint32_t index = 0; index < 8; ++index) {
            std::vector<Vec2> set;
            for (std::uint32_t j = 0; j < k; ++j) {
                set.push_back(sampler.get_2d_in_set({6, 31, index, 8}, d, j, k));
            }
            EXPECT_TRUE(is_net(set)) << "set of " << k << " of sample " << index;
            all.insert(all.end(), set.begin(), set.end());
        }
        EXPECT_TRUE(is_net(all)) << "8 sets of " << k;
    }
    // Other sizes: the first points up to a power of two are a net.
    for (const std::uint32_t k : {3u, 5u, 10u, 20u}) {
        std::vector<Vec2> set;
        for (std::uint32_t j = 0; j < std::bit_floor(k); ++j) {
            set.push_back(sampler.get_2d_in_set({6, 31, 2, 8}, d, j, k));
        }
        EXPECT_TRUE(is_net(set)) << "set of " << k;
    }
}

// A set of k < K points leaves K - k points of its block unused. Over a pixel's samples the
// unused ones must vary, or every set misses the same strata of the light: all points of a
// pixel's sets together must fill the square evenly, for every set size.
TEST(SamplerSobol, SetsOfAnySizeTogetherFillThePixelsSquareEvenly) {
    const SobolSampler sampler;
    for (const std::uint32_t k : {3u, 5u, 6u, 7u, 10u, 8u}) {
        for (std::uint32_t pixel = 0; pixel < 4; ++pixel) {
            std::vector<int> x_strata(8, 0), y_strata(8, 0);
            const std::uint32_t count = 256;
            for (std::uint32_t index = 0; index < count; ++index) {
                for (std::uint32_t j = 0; j < k; ++j) {
                    const Vec2 p =
                        sampler.get_2d_in_set({2, pixel, index, count}, dim::light(0, 0), j, k);
                    ++x_strata[static_cast<int>(p.x * 8)];
                    ++y_strata[static_cast<int>(p.y * 8)];
                }
            }
            // 32k points per stratum; independent points would spread by sqrt(28k) ~ 5 sqrt(k).
            const double expected = count * k / 8.0;
            for (int b = 0; b < 8; ++b) {
                EXPECT_NEAR(x_strata[b], expected, 0.2 * expected) << "k " << k << " x " << b;
                EXPECT_NEAR(y_strata[b], expected, 0.2 * expected) << "k " << k << " y " << b;
            }
        }
    }
}

TEST(SamplerSobol, UniformOverThePixelForAnyCount) {
    const SobolSampler sampler;
    for (const std::uint32_t count : {1u, 3u, 10u, 16u, 100u}) {
        const int bins = 8;
        std::vector<int> histogram(bins * bins, 0);
        double sum_x = 0, sum_y = 0, sum_xy = 0, sum_t = 0;
        const std::uint32_t pixels = 400000 / count;
        for (std::uint32_t pixel = 0; pixel < pixels; ++pixel) {
            for (std::uint32_t index = 0; index < count; ++index) {
                const PixelSample s{3, pixel, index, count};
                const Vec2 p = sampler.get_2d(s, dim::kLens);
                sum_x += p.x, sum_y += p.y, sum_xy += p.x * p.y;
                sum_t += sampler.get_1d(s, dim::kTime);
                ++histogram[static_cast<int>(p.x * bins) * bins + static_cast<int>(p.y * bins)];
            }
        }
        const double n = double(pixels) * count;
        EXPECT_NEAR(sum_x / n, 0.5, 0.003) << count;
        EXPECT_NEAR(sum_y / n, 0.5, 0.003) << count;
        EXPECT_NEAR(sum_t / n, 0.5, 0.003) << count;
        EXPECT_NEAR(sum_xy / n, 0.25, 0.002) << count;
        const double expected = n / (bins * bins);  // 6250, standard deviation ~80 if independent
        for (int b = 0; b < bins * bins; ++b) {
            EXPECT_NEAR(histogram[b], expected, 0.08 * expected)
                << "count " << count << " bin " << b / bins << ", " << b % bins;
        }
    }
}

TEST(SamplerSobol, DimensionsAndPixelsAreDecorrelated) {
    const SobolSampler sampler;
    const std::uint32_t count = 4096;
    std::vector<double> px, py, lx, ly, t, other_pixel, set0, set1;
    for (std::uint32_t index = 0; index < count; ++index) {
        const PixelSample s{17, 321, index, count};
        const Vec2 p = sampler.get_2d(s, dim::kPixel);
        const Vec2 l = sampler.get_2d(s, dim::kLens);
        px.push_back(p.x), py.push_back(p.y), lx.push_back(l.x), ly.push_back(l.y);
        t.push_back(sampler.get_1d(s, dim::kTime));
        other_pixel.push_back(sampler.get_2d({17, 322, index, count}, dim::kPixel).x);
        set0.push_back(sampler.get_2d_in_set(s, 20, 0, 4).x);
        set1.push_back(sampler.get_2d_in_set(s, 21, 0, 4).x);
    }
    EXPECT_LT(std::abs(correlation(px, py)), 0.06);
    EXPECT_LT(std::abs(correlation(px, lx)), 0.06);
    EXPECT_LT(std::abs(correlation(py, ly)), 0.06);
    EXPECT_LT(std::abs(correlation(px, t)), 0.06);
    EXPECT_LT(std::abs(correlation(px, other_pixel)), 0.06);
    EXPECT_LT(std::abs(correlation(set0, set1)), 0.06);
    // Pixel and lens points of the same samples must not fall into paired strata: with the same
    // index order both would put sample i in the same 4x4 cell of each square.
    int same_cell = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
        same_cell += static_cast<int>(px[i] * 4) == static_cast<int>(lx[i] * 4) &&
                     static_cast<int>(py[i] * 4) == static_cast<int>(ly[i] * 4);
    }
    EXPECT_NEAR(same_cell, count / 16.0, 4 * std::sqrt(count / 16.0));
}

TEST(SamplerSobol, LowerDiscrepancyThanRandomAndStratified) {
    const IndependentSampler random;
    const StratifiedSampler stratified;
    const SobolSampler sobol;
    for (const std::uint32_t count : {16u, 64u, 256u}) {
        double d_random = 0, d_stratified = 0, d_sobol = 0;
        for (std::uint32_t pixel = 0; pixel < 40; ++pixel) {
            d_random += l2_star_discrepancy(pixel_points(random, pixel, count));
            d_stratified += l2_star_discrepancy(pixel_points(stratified, pixel, count));
            d_sobol += l2_star_discrepancy(pixel_points(sobol, pixel, count));
        }
        // Random points have an expected squared L2 star discrepancy of (1/4 - 1/9)/N, i.e.
        // about 0.37/sqrt(N); stratified ones fall like N^-3/4, nets faster still.
        EXPECT_NEAR(d_random / 40, 0.37 / std::sqrt(count), 0.15 / std::sqrt(count)) << count;
        EXPECT_LT(d_stratified, 0.6 * d_random) << count;
        EXPECT_LT(d_sobol, 0.6 * d_random) << count;
        // At 16 points the two are level; beyond, nets pull ahead of jittered strata.
        if (count >= 64) {
            EXPECT_LT(d_sobol, 0.9 * d_stratified) << count;
        }
    }
}

// The RMS error over many pixels of estimating the integral of a smooth function on the square,
// f = exp(x) * cos(y) with integral (e - 1) * sin(1), falls as N^-1/2 for random points and
// much faster for jittered strata and faster still for scrambled nets (N^-3/2 in theory for
// smooth integrands).
TEST(SamplerSobol, IntegrationErrorOfASmoothFunctionFallsFasterThanRandom) {
    const double exact = (std::exp(1.0) - 1) * std::sin(1.0);
    const std::vector<double> counts = {16, 64, 256, 1024};
    auto rms_errors = [&](const Sampler& sampler) {
        std::vector<double> errors;
        for (const double count : counts) {
            double sum_sq = 0;
            const int pixels = 200;
            for (int pixel = 0; pixel < pixels; ++pixel) {
                double sum = 0;
                const auto n = static_cast<std::uint32_t>(count);
                for (const Vec2& p : pixel_points(sampler, pixel, n)) {
                    sum += std::exp(p.x) * std::cos(p.y);
                }
                sum_sq += (sum / count - exact) * (sum / count - exact);
            }
            errors.push_back(std::sqrt(sum_sq / pixels));
        }
        return errors;
    };
    const std::vector<double> random = rms_errors(IndependentSampler());
    const std::vector<double> stratified = rms_errors(StratifiedSampler());
    const std::vector<double> sobol = rms_errors(SobolSampler());
    EXPECT_NEAR(loglog_slope(counts, random), -0.5, 0.1);
    EXPECT_LT(loglog_slope(counts, stratified), -0.7);
    EXPECT_LT(loglog_slope(counts, sobol), -1.2);
    for (std::size_t i = 0; i < counts.size(); ++i) {
        EXPECT_LT(sobol[i], random[i] / 4) << counts[i];
    }
}

}  // namespace
}  // namespace drt
