#include "drt/sampling/stratified.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "sampler_checks.h"

namespace drt {
namespace {

using testing::correlation;
using testing::grid_of;
using testing::in_unit;
using testing::multi_jittered_strata;

const std::uint32_t kCounts[] = {1, 2, 3, 4, 5, 7, 10, 12, 16, 17, 20, 64, 100, 256, 1000};

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

// Each pixel, dimension and ray-tree branch shuffles its strata on its own: how often two
// patterns put the same sample in the same 1-D stratum is chance, 1 in 16, not more. (One
// shared permutation, for pixels or for dimensions, would make it 16 in 16.)
TEST(SamplerStratified, PatternsOfPixelsDimensionsAndBranchesAreIndependent) {
    const StratifiedSampler sampler;
    const std::uint32_t count = 16;
    int same_pixel = 0, same_dim = 0, same_branch = 0, same_2d = 0;
    const int pixels = 1000;
    for (std::uint32_t pixel = 0; pixel < pixels; ++pixel) {
        for (std::uint32_t index = 0; index < count; ++index) {
            const PixelSample s{1, pixel, index, count};
            PixelSample next_pixel = s, branch = s.branch(2, 0);
            ++next_pixel.pixel;
            auto stratum = [&](const PixelSample& t, std::uint32_t d) {
                return static_cast<int>(sampler.get_1d(t, d) * count);
            };
            const int a = stratum(s, 5);
            same_pixel += a == stratum(next_pixel, 5);
            same_dim += a == stratum(s, 6);
            same_branch += a == stratum(branch, 5);
            same_2d += static_cast<int>(sampler.get_2d(s, 7).y * count) ==
                       static_cast<int>(sampler.get_2d(s, 8).y * count);
        }
    }
    // 16000 pairs, 1000 expected, standard deviation 31.
    for (const int same : {same_pixel, same_dim, same_branch, same_2d}) {
        EXPECT_NEAR(same, pixels, 150);
    }
}

// Within its stratum a 1-D number is jittered uniformly.
TEST(SamplerStratified, Get1dIsJitteredUniformlyWithinItsStratum) {
    const StratifiedSampler sampler;
    for (const std::uint32_t count : {1u, 7u, 64u}) {
        std::vector<double> within;
        for (std::uint32_t pixel = 0; within.size() < 20000; ++pixel) {
            for (std::uint32_t index = 0; index < count; ++index) {
                const double v = sampler.get_1d({3, pixel, index, count}, dim::kTime);
                within.push_back(v * count - std::floor(v * count));
            }
        }
        EXPECT_TRUE(testing::uniform_by_ks(within)) << "count " << count;
    }
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
