#include "drt/sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

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
    ASSERT_EQ(names.size(), 2u);
    for (const std::string& name : names) {
        const std::unique_ptr<Sampler> sampler = make_sampler(name);
        ASSERT_NE(sampler, nullptr) << name;
        EXPECT_EQ(sampler->name(), name);
    }
    EXPECT_EQ(make_sampler("random")->name(), "random");
    EXPECT_EQ(make_sampler("stratified")->name(), "stratified");
    EXPECT_EQ(make_sampler(""), nullptr);
    EXPECT_EQ(make_sampler("Stratified"), nullptr);
    EXPECT_EQ(make_sampler("halton"), nullptr);
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

}  // namespace
}  // namespace drt
