#include "drt/sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "drt/rng.h"

namespace drt {
namespace {

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
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

bool in_unit(double v) {
    return v >= 0.0 && v < 1.0;
}

// The grid multi_jittered uses for k points: m columns by n rows, m*n >= k.
std::pair<std::uint32_t, std::uint32_t> grid_of(std::uint32_t k) {
    const auto m = static_cast<std::uint32_t>(std::max(1.0, std::floor(std::sqrt(double(k)))));
    return {m, (k + m - 1) / m};
}

// Checks that k points are stratified as a correlated multi-jittered pattern (Kensler 2013)
// promises for any k: with an m x n grid (m*n >= k), y has exactly one point in each of k strata
// and x at most one in each of m*n strata; when k = m*n, each cell of the grid holds one point.
::testing::AssertionResult multi_jittered_strata(const std::vector<Vec2>& points) {
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

const std::uint32_t kCounts[] = {1, 2, 3, 4, 5, 7, 10, 12, 16, 17, 20, 64, 100, 256, 1000};

TEST(Sampler, MakeSamplerKnowsExactlyItsNames) {
    const std::vector<std::string> names = sampler_names();
    ASSERT_EQ(names.size(), 3u);
    for (const std::string& name : names) {
        const std::unique_ptr<Sampler> sampler = make_sampler(name);
        ASSERT_NE(sampler, nullptr) << name;
        EXPECT_EQ(sampler->name(), name);
    }
    EXPECT_EQ(make_sampler("random")->name(), "random");
    EXPECT_EQ(make_sampler("stratified")->name(), "stratified");
    EXPECT_EQ(make_sampler("sobol")->name(), "sobol");
    EXPECT_EQ(make_sampler(""), nullptr);
    EXPECT_EQ(make_sampler("Stratified"), nullptr);
    EXPECT_EQ(make_sampler("halton"), nullptr);
    EXPECT_EQ(make_sampler("Sobol"), nullptr);
}

TEST(Sampler, EverySamplerIsDeterministic) {
    for (const std::string& name : sampler_names()) {
        const auto first = make_sampler(name);
        const auto second = make_sampler(name);
        for (std::uint32_t i = 0; i < 64; ++i) {
            const PixelSample s{12345, 678 + i, i % 16, 16};
            EXPECT_EQ(first->get_1d(s, 3), second->get_1d(s, 3)) << name;
            EXPECT_EQ(first->get_1d(s, 3), first->get_1d(s, 3)) << name;
            const Vec2 a = first->get_2d(s, dim::kLens), b = second->get_2d(s, dim::kLens);
            EXPECT_EQ(a.x, b.x) << name;
            EXPECT_EQ(a.y, b.y) << name;
            const Vec2 c = first->get_2d_in_set(s, dim::bounce(1, dim::kLight), 2, 5);
            const Vec2 d = second->get_2d_in_set(s, dim::bounce(1, dim::kLight), 2, 5);
            EXPECT_EQ(c.x, d.x) << name;
            EXPECT_EQ(c.y, d.y) << name;
        }
        // A different seed gives different numbers.
        const PixelSample s0{0, 5, 1, 4}, s1{1, 5, 1, 4};
        EXPECT_NE(first->get_1d(s0, 0), first->get_1d(s1, 0)) << name;
    }
}

TEST(Sampler, SetsAtOnceEqualPointsOneByOne) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t k : {1u, 3u, 8u, 10u}) {
            const PixelSample s{9, 40, 5, 16};
            std::vector<Vec2> points(k - k / 3);
            sampler->get_2d_set(s, dim::light(0, 1), k, k / 3, points);
            for (std::uint32_t j = k / 3; j < k; ++j) {
                const Vec2 p = sampler->get_2d_in_set(s, dim::light(0, 1), j, k);
                EXPECT_EQ(points[j - k / 3].x, p.x) << name << " k " << k << " j " << j;
                EXPECT_EQ(points[j - k / 3].y, p.y) << name << " k " << k << " j " << j;
            }
        }
    }
}

TEST(Sampler, RunsAtOnceEqualPointsOneByOne) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t count : {1u, 7u, 82u, 100u, 1000u}) {
            const PixelSample first{9, 40, count / 4, count, 77};
            std::vector<Vec2> points(count - count / 4);
            sampler->get_2d_run(first, dim::kPixel, points);
            PixelSample s = first;
            for (const Vec2& point : points) {
                const Vec2 p = sampler->get_2d(s, dim::kPixel);
                EXPECT_EQ(point.x, p.x) << name << " count " << count << " index " << s.index;
                EXPECT_EQ(point.y, p.y) << name << " count " << count << " index " << s.index;
                ++s.index;
            }
        }
    }
}

// RunPoints in the order a renderer asks: sample by sample, each asking for several dimensions
// on several branches, some only now and then, more pairs than it remembers, and samples from
// outside the run.
TEST(Sampler, RunPointsAreExactlyGet2dsInAnyOrder) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        const PixelSample first{3, 123, 16, 48};
        RunPoints run(*sampler, first, 24);
        int asked = 0;
        for (std::uint32_t index = 10; index < 48; ++index) {
            for (std::uint32_t d = 0; d < 40; ++d) {
                const std::uint32_t dimension = dim::bounce(static_cast<int>(d % 8), d / 8);
                if ((index * 7 + d) % (d < 20 ? 1 : 5) != 0) continue;
                PixelSample s = first;
                s.index = index;
                s.path = first.branch(d % 3, d).path;
                const Vec2 expected = sampler->get_2d(s, dimension);
                const Vec2 got = run.get_2d(s, dimension);
                EXPECT_EQ(got.x, expected.x) << name << " index " << index << " d " << d;
                EXPECT_EQ(got.y, expected.y) << name << " index " << index << " d " << d;
                ++asked;
            }
        }
        EXPECT_GT(asked, 900);
        // Another pixel, seed or count is not the run's.
        for (PixelSample other : {PixelSample{3, 124, 20, 48}, PixelSample{4, 123, 20, 48},
                                  PixelSample{3, 123, 20, 47}}) {
            const Vec2 expected = sampler->get_2d(other, dim::bounce(0, 2));
            const Vec2 got = run.get_2d(other, dim::bounce(0, 2));
            EXPECT_EQ(got.x, expected.x) << name;
            EXPECT_EQ(got.y, expected.y) << name;
        }
    }
}

TEST(Sampler, ValuesLieInTheHalfOpenUnitInterval) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t count : {1u, 3u, 16u, 100u}) {
            for (std::uint32_t pixel = 0; pixel < 20; ++pixel) {
                for (std::uint32_t index = 0; index < count; ++index) {
                    const PixelSample s{7, pixel, index, count};
                    for (std::uint32_t d = 0; d < 24; ++d) {
                        ASSERT_TRUE(in_unit(sampler->get_1d(s, d))) << name;
                        const Vec2 p = sampler->get_2d(s, d);
                        ASSERT_TRUE(in_unit(p.x) && in_unit(p.y)) << name;
                        const Vec2 q = sampler->get_2d_in_set(s, d, index % 5, 5);
                        ASSERT_TRUE(in_unit(q.x) && in_unit(q.y)) << name;
                    }
                }
            }
        }
    }
}

TEST(SamplerIndependent, MeanAndVarianceAreThoseOfTheUniformDistribution) {
    const IndependentSampler sampler;
    const int n = 100000;
    double sum = 0, sum_sq = 0, sum2 = 0, sum2_sq = 0;
    for (int i = 0; i < n; ++i) {
        const PixelSample s{99, static_cast<std::uint32_t>(i), 0, 1};
        const double v = sampler.get_1d(s, 0);
        sum += v, sum_sq += v * v;
        const Vec2 p = sampler.get_2d(s, 1);
        sum2 += p.y, sum2_sq += p.y * p.y;
    }
    // Standard errors: 0.0009 for the mean, 0.00024 for the variance.
    EXPECT_NEAR(sum / n, 0.5, 0.0045);
    EXPECT_NEAR(sum_sq / n - (sum / n) * (sum / n), 1.0 / 12, 0.0012);
    EXPECT_NEAR(sum2 / n, 0.5, 0.0045);
    EXPECT_NEAR(sum2_sq / n - (sum2 / n) * (sum2 / n), 1.0 / 12, 0.0012);
}

TEST(SamplerIndependent, DimensionsAreDecorrelated) {
    const IndependentSampler sampler;
    std::vector<double> d0, d1, x, y, time, set0, set1;
    for (std::uint32_t i = 0; i < 4096; ++i) {
        // Across the samples of one pixel and across pixels.
        const PixelSample s{3, i / 64, i % 64, 64};
        d0.push_back(sampler.get_1d(s, 0));
        d1.push_back(sampler.get_1d(s, 1));
        const Vec2 p = sampler.get_2d(s, dim::kPixel);
        x.push_back(p.x), y.push_back(p.y);
        time.push_back(sampler.get_1d(s, dim::kTime));
        set0.push_back(sampler.get_2d_in_set(s, 20, 0, 2).x);
        set1.push_back(sampler.get_2d_in_set(s, 20, 1, 2).x);
    }
    // The standard error of a correlation over 4096 pairs is 1/64 = 0.016. (A dimension number is
    // used either as 1-D or as 2-D, so get_1d(s, 0) and get_2d(s, 0).x need not differ.)
    EXPECT_LT(std::abs(correlation(d0, d1)), 0.06);
    EXPECT_LT(std::abs(correlation(x, y)), 0.06);
    EXPECT_LT(std::abs(correlation(time, x)), 0.06);
    EXPECT_LT(std::abs(correlation(set0, set1)), 0.06);
}

TEST(SamplerStratified, Get1dPutsOneSampleInEachStratum) {
    const StratifiedSampler sampler;
    for (const std::uint32_t count : kCounts) {
        for (std::uint32_t pixel : {0u, 1u, 4711u}) {
            for (std::uint32_t d : {0u, 2u, dim::bounce(3, dim::kLightPick)}) {
                std::vector<int> hits(count, 0);
                for (std::uint32_t index = 0; index < count; ++index) {
                    const double v = sampler.get_1d({42, pixel, index, count}, d);
                    ASSERT_TRUE(in_unit(v));
                    ++hits[static_cast<std::uint32_t>(v * count)];
                }
                for (std::uint32_t k = 0; k < count; ++k) {
                    ASSERT_EQ(hits[k], 1) << "count " << count << " stratum " << k << " pixel "
                                          << pixel << " dim " << d;
                }
            }
        }
    }
}

TEST(SamplerStratified, Get2dIsAMultiJitteredPatternOverThePixelsSamples) {
    const StratifiedSampler sampler;
    for (const std::uint32_t count : kCounts) {
        for (std::uint32_t pixel : {0u, 77u}) {
            for (std::uint32_t d : {dim::kPixel, dim::kLens}) {
                std::vector<Vec2> points;
                for (std::uint32_t index = 0; index < count; ++index) {
                    points.push_back(sampler.get_2d({5, pixel, index, count}, d));
                }
                EXPECT_TRUE(multi_jittered_strata(points))
                    << "count " << count << " pixel " << pixel << " dim " << d;
            }
        }
    }
}

TEST(SamplerStratified, Get2dFillsEveryStratumWhenTheCountIsARectangle) {
    const StratifiedSampler sampler;
    for (const std::uint32_t count : {4u, 12u, 16u, 20u, 64u, 100u}) {
        const auto [m, n] = grid_of(count);
        ASSERT_EQ(m * n, count);
        std::vector<int> cols(count, 0), rows(count, 0);
        for (std::uint32_t index = 0; index < count; ++index) {
            const Vec2 p = sampler.get_2d({5, 9, index, count}, dim::kPixel);
            ++cols[static_cast<std::uint32_t>(p.x * count)];
            ++rows[static_cast<std::uint32_t>(p.y * count)];
        }
        for (std::uint32_t k = 0; k < count; ++k) {
            EXPECT_EQ(cols[k], 1) << "count " << count << " x stratum " << k;
            EXPECT_EQ(rows[k], 1) << "count " << count << " y stratum " << k;
        }
    }
}

// Stratification must not bias: over many pixels, every point of a pattern is uniform over the
// square, whatever the count. (A pattern that always leaves the same cells of a 3x4 grid empty
// for 10 samples, or shuffles that favour some positions, fail this.)
TEST(SamplerStratified, Get2dIsUniformOverThePixelForAnyCount) {
    const StratifiedSampler sampler;
    for (const std::uint32_t count : {2u, 3u, 5u, 9u, 10u, 17u, 25u, 100u}) {
        const int bins = 8;
        std::vector<int> histogram(bins * bins, 0);
        double sum_x = 0, sum_y = 0, sum_xy = 0;
        const std::uint32_t pixels = 400000 / count;
        for (std::uint32_t pixel = 0; pixel < pixels; ++pixel) {
            for (std::uint32_t index = 0; index < count; ++index) {
                const Vec2 p = sampler.get_2d({3, pixel, index, count}, dim::kLens);
                sum_x += p.x, sum_y += p.y, sum_xy += p.x * p.y;
                ++histogram[static_cast<int>(p.x * bins) * bins + static_cast<int>(p.y * bins)];
            }
        }
        const double n = double(pixels) * count;
        // Independent points would give standard errors 0.0005 (means) and 0.00035 (E[xy]).
        EXPECT_NEAR(sum_x / n, 0.5, 0.003) << count;
        EXPECT_NEAR(sum_y / n, 0.5, 0.003) << count;
        EXPECT_NEAR(sum_xy / n, 0.25, 0.002) << count;
        const double expected = n / (bins * bins);  // 6250, standard deviation ~80
        for (int b = 0; b < bins * bins; ++b) {
            EXPECT_NEAR(histogram[b], expected, 0.08 * expected)
                << "count " << count << " bin " << b / bins << ", " << b % bins;
        }
    }
}

TEST(SamplerStratified, Get2dInSetIsAMultiJitteredPatternOverTheSet) {
    const StratifiedSampler sampler;
    for (const std::uint32_t k : kCounts) {
        for (std::uint32_t index = 0; index < 3; ++index) {
            std::vector<Vec2> points;
            for (std::uint32_t j = 0; j < k; ++j) {
                points.push_back(
                    sampler.get_2d_in_set({8, 1234, index, 3}, dim::bounce(0, dim::kLight), j, k));
            }
            EXPECT_TRUE(multi_jittered_strata(points)) << "set of " << k;
        }
    }
}

// Sets of more than 1024 points take the shuffles from Kensler's permutation rather than from
// a tabulated deal, and beyond 4096 the rotation from the hash's high bits: the same pattern.
TEST(SamplerStratified, LargeSetsAreMultiJitteredPatternsToo) {
    const StratifiedSampler sampler;
    for (const std::uint32_t k : {1025u, 1500u, 4100u}) {
        std::vector<Vec2> points(k);
        sampler.get_2d_set({8, 1234, 1, 3}, dim::bounce(0, dim::kLight), k, 0, points);
        EXPECT_TRUE(multi_jittered_strata(points)) << "set of " << k;
    }
}

TEST(SamplerStratified, MultiJitteredIsStratifiedForManyKeys) {
    for (const std::uint32_t k : kCounts) {
        for (std::uint32_t key = 0; key < 20; ++key) {
            std::vector<Vec2> points;
            for (std::uint32_t j = 0; j < k; ++j) points.push_back(multi_jittered(j, k, key));
            EXPECT_TRUE(multi_jittered_strata(points)) << "k " << k << " key " << key;
        }
    }
}

TEST(SamplerStratified, PatternsDifferBetweenPixelsAndDimensions) {
    const StratifiedSampler sampler;
    int same_pixel = 0, same_dim = 0;
    for (std::uint32_t index = 0; index < 16; ++index) {
        const double a = sampler.get_1d({1, 10, index, 16}, 0);
        same_pixel += static_cast<int>(a * 16) ==
                      static_cast<int>(sampler.get_1d({1, 11, index, 16}, 0) * 16);
        same_dim += static_cast<int>(a * 16) ==
                    static_cast<int>(sampler.get_1d({1, 10, index, 16}, 1) * 16);
    }
    // Identical permutations would put all 16 in the same strata.
    EXPECT_LT(same_pixel, 16);
    EXPECT_LT(same_dim, 16);
}

TEST(SamplerStratified, DimensionsAreDecorrelated) {
    const StratifiedSampler sampler;
    const std::uint32_t count = 4096;
    std::vector<double> d0, d1, px, py, lx, set0, set1;
    for (std::uint32_t index = 0; index < count; ++index) {
        const PixelSample s{17, 321, index, count};
        d0.push_back(sampler.get_1d(s, 0));
        d1.push_back(sampler.get_1d(s, 1));
        const Vec2 p = sampler.get_2d(s, dim::kPixel);
        px.push_back(p.x), py.push_back(p.y);
        lx.push_back(sampler.get_2d(s, dim::kLens).x);
        set0.push_back(sampler.get_2d_in_set(s, 20, 0, 4).x);
        set1.push_back(sampler.get_2d_in_set(s, 21, 0, 4).x);
    }
    EXPECT_LT(std::abs(correlation(d0, d1)), 0.06);
    EXPECT_LT(std::abs(correlation(px, py)), 0.06);
    EXPECT_LT(std::abs(correlation(px, lx)), 0.06);
    EXPECT_LT(std::abs(correlation(d0, px)), 0.06);
    EXPECT_LT(std::abs(correlation(set0, set1)), 0.06);

    // Stratification makes the mean over the pixel's samples very nearly exact.
    double sum = 0;
    for (const double v : d0) sum += v;
    EXPECT_NEAR(sum / count, 0.5, 1.0 / count);
}

// --- Owen-scrambled Sobol ---

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
    EXPECT_TRUE(sampler.progressive());
    EXPECT_FALSE(StratifiedSampler().progressive());
    EXPECT_FALSE(IndependentSampler().progressive());
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
// smooth integrands; measured -0.5, -0.8 and -1.45).
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
