#include "drt/sampling/multi_jittered.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "drt/util/rng.h"
#include "sampler_checks.h"

namespace drt {
namespace {

using testing::correlation;
using testing::equally_likely;
using testing::grid_of;
using testing::in_unit;
using testing::multi_jittered_strata;
using testing::uniform_by_ks;

// Square, rectangular (k = m*n) and ragged counts, the largest grids whose sides are both listed
// orders (20, 25) and one between them whose rows are dealt (24), and counts past the dealt
// shuffles (1024) and the small grid sides (64).
const std::uint32_t kPatternCounts[] = {1,  2,  3,  4,  5,  7,   9,   10,   12,   16,   17,
                                        20, 24, 25, 64, 82, 100, 256, 1000, 1025, 1500, 4100};

std::vector<Vec2> run_of(std::uint32_t k, std::uint32_t key) {
    std::vector<Vec2> points(k);
    multi_jittered(0, k, key, points);
    return points;
}

std::vector<Vec2> set_of(std::uint32_t k, std::uint32_t key) {
    std::vector<Vec2> points(k);
    multi_jittered_set(0, k, key, points);
    return points;
}

std::uint32_t key_of(std::uint32_t i) {
    return static_cast<std::uint32_t>(mix64(i + 0x5eedULL));
}

TEST(MultiJittered, EveryStratumExactlyOnceForAnyCountAndKey) {
    for (const std::uint32_t k : kPatternCounts) {
        for (std::uint32_t i = 0; i < (k > 1000 ? 3u : 20u); ++i) {
            EXPECT_TRUE(multi_jittered_strata(run_of(k, key_of(i)))) << "run, k " << k;
            EXPECT_TRUE(multi_jittered_strata(set_of(k, key_of(i)))) << "set, k " << k;
        }
    }
}

// Within its stratum (of y among k, of x among m*n) a point is jittered uniformly: without
// jitter every point would sit at its stratum's corner, and a jitter scaled or offset would
// push points into their neighbours' strata or leave part of every stratum empty.
TEST(MultiJittered, JitterIsUniformWithinTheStrata) {
    for (const std::uint32_t k : {1u, 5u, 16u, 82u, 1500u}) {
        const auto [m, n] = grid_of(k);
        std::vector<double> run_x, run_y, set_x, set_y;
        for (std::uint32_t i = 0; run_x.size() < 20000; ++i) {
            for (const Vec2& p : run_of(k, key_of(i))) {
                run_x.push_back(p.x * m * n - std::floor(p.x * m * n));
                run_y.push_back(p.y * k - std::floor(p.y * k));
            }
            for (const Vec2& p : set_of(k, key_of(i))) {
                set_x.push_back(p.x * m * n - std::floor(p.x * m * n));
                set_y.push_back(p.y * k - std::floor(p.y * k));
            }
        }
        EXPECT_TRUE(uniform_by_ks(run_x)) << "run, x, k " << k;
        EXPECT_TRUE(uniform_by_ks(run_y)) << "run, y, k " << k;
        EXPECT_TRUE(uniform_by_ks(set_x)) << "set, x, k " << k;
        EXPECT_TRUE(uniform_by_ks(set_y)) << "set, y, k " << k;
        // The two jitters of a point are independent.
        EXPECT_LT(std::abs(correlation(run_x, run_y)), 0.03) << "k " << k;
    }
}

// Over keys, every point of a pattern, whatever its label, is uniform over the square: the
// labels must be a uniformly random order of the strata (a fixed order would put point 0 always
// in the bottom stratum).
TEST(MultiJittered, EveryPointIsUniformOverTheSquare) {
    for (const std::uint32_t k : {2u, 5u, 9u, 10u, 82u}) {
        for (const std::uint32_t j : {0u, k / 2, k - 1}) {
            const int bins = 4;
            std::vector<int> run(bins * bins, 0), set(bins * bins, 0);
            for (std::uint32_t i = 0; i < 16000; ++i) {
                const Vec2 p = multi_jittered(j, k, key_of(i));
                ++run[static_cast<int>(p.x * bins) * bins + static_cast<int>(p.y * bins)];
                Vec2 q;
                multi_jittered_set(j, k, key_of(i), {&q, 1});
                ++set[static_cast<int>(q.x * bins) * bins + static_cast<int>(q.y * bins)];
            }
            EXPECT_TRUE(equally_likely(run)) << "run, k " << k << " j " << j;
            EXPECT_TRUE(equally_likely(set)) << "set, k " << k << " j " << j;
        }
    }
}

// The columns and sub-columns are uniformly random orders: over keys, the point in a given y
// stratum lies in every column, and in every sub-column of x, equally often. (A shuffle that
// never leaves an element in place, or no shuffle, fails; stratification alone would not.)
TEST(MultiJittered, ColumnShufflesAreUniform) {
    for (const std::uint32_t k : {4u, 9u, 12u, 36u, 82u, 1500u}) {
        const auto [m, n] = grid_of(k);
        for (const std::uint32_t stratum : {0u, k - 1}) {
            std::vector<int> columns(m, 0), sub_columns(n, 0);
            for (std::uint32_t i = 0; i < (k > 1000 ? 2000u : 8000u); ++i) {
                for (const Vec2& p : set_of(k, key_of(i))) {
                    if (static_cast<std::uint32_t>(p.y * k) != stratum) continue;
                    const auto x = static_cast<std::uint32_t>(p.x * m * n);
                    ++columns[x / n];
                    ++sub_columns[x % n];
                }
            }
            EXPECT_TRUE(equally_likely(columns)) << "k " << k << " stratum " << stratum;
            EXPECT_TRUE(equally_likely(sub_columns)) << "k " << k << " stratum " << stratum;
        }
    }
}

// Within one pattern x and y are unrelated: averaged over keys, their correlation is zero.
// (Columns in stratum order, for one, would make x rise with y within every row.)
TEST(MultiJittered, CoordinatesAreUncorrelatedWithinAPattern) {
    for (const std::uint32_t k : {9u, 16u, 64u}) {
        double sum = 0;
        const int keys = 4000;
        for (std::uint32_t i = 0; i < keys; ++i) {
            std::vector<double> x, y;
            for (const Vec2& p : run_of(k, key_of(i))) x.push_back(p.x), y.push_back(p.y);
            sum += correlation(x, y);
        }
        // One pattern's correlation spreads by about 1/sqrt(k); the mean over 4000 by 1/(63
        // sqrt(k)).
        EXPECT_NEAR(sum / keys, 0.0, 4.0 / (63 * std::sqrt(double(k)))) << "k " << k;
    }
}

// A run of any length from any first label is exactly the points one by one, across the batches
// a long run is drawn in.
TEST(MultiJittered, ARunIsThePointsOneByOne) {
    for (const std::uint32_t k : {1u, 7u, 82u, 1000u, 5000u}) {
        for (const std::uint32_t first : {0u, k / 3}) {
            std::vector<Vec2> run(k - first);
            multi_jittered(first, k, 77, run);
            for (std::uint32_t j = first; j < k; ++j) {
                const Vec2 p = multi_jittered(j, k, 77);
                ASSERT_EQ(run[j - first].x, p.x) << "k " << k << " j " << j;
                ASSERT_EQ(run[j - first].y, p.y) << "k " << k << " j " << j;
            }
        }
    }
}

TEST(MultiJittered, ASetIsThePointsOneByOne) {
    for (const std::uint32_t k : {1u, 7u, 82u, 300u}) {
        for (const std::uint32_t first : {0u, k / 3}) {
            std::vector<Vec2> set(k - first);
            multi_jittered_set(first, k, 77, set);
            for (std::uint32_t j = first; j < k; ++j) {
                Vec2 p;
                multi_jittered_set(j, k, 77, {&p, 1});
                ASSERT_EQ(set[j - first].x, p.x) << "k " << k << " j " << j;
                ASSERT_EQ(set[j - first].y, p.y) << "k " << k << " j " << j;
            }
        }
    }
}

// One pattern, two labellings: a whole set holds exactly the points of the run with the same
// key, and its labels take the strata of y in order from a random one on, wrapping around.
TEST(MultiJittered, ASetIsTheRunsPatternLabelledByARotation) {
    auto less = [](const Vec2& a, const Vec2& b) { return a.y < b.y || (a.y == b.y && a.x < b.x); };
    for (const std::uint32_t k : {1u, 5u, 9u, 82u, 1500u}) {
        for (std::uint32_t i = 0; i < 5; ++i) {
            std::vector<Vec2> run = run_of(k, key_of(i)), set = set_of(k, key_of(i));
            const auto first = static_cast<std::uint32_t>(set[0].y * k);
            for (std::uint32_t j = 0; j < k; ++j) {
                EXPECT_EQ(static_cast<std::uint32_t>(set[j].y * k), (first + j) % k) << k;
            }
            std::sort(run.begin(), run.end(), less);
            std::sort(set.begin(), set.end(), less);
            for (std::uint32_t j = 0; j < k; ++j) {
                EXPECT_EQ(run[j].x, set[j].x) << "k " << k << " stratum " << j;
                EXPECT_EQ(run[j].y, set[j].y) << "k " << k << " stratum " << j;
            }
        }
    }
}

// Past 2^20 points the jitter's 32 bits no longer fit below the stratum's width in a double; the
// last stratum's points must still stay below 1.
TEST(MultiJittered, PointsStayInsideTheSquareForHugeCounts) {
    const std::uint32_t k = (1u << 22) + 3;
    for (std::uint32_t i = 0; i < 50; ++i) {
        Vec2 p;
        multi_jittered_set(k - 1 - i, k, key_of(i), {&p, 1});
        EXPECT_TRUE(in_unit(p.x) && in_unit(p.y)) << p.x << ", " << p.y;
        const Vec2 q = multi_jittered(k - 1 - i, k, key_of(i));
        EXPECT_TRUE(in_unit(q.x) && in_unit(q.y)) << q.x << ", " << q.y;
    }
}

TEST(MultiJittered, KeysGiveIndependentPatterns) {
    // The x of point 0 under two neighbouring keys: related keys must not give related points.
    std::vector<double> a, b;
    for (std::uint32_t key = 0; key < 4096; ++key) {
        a.push_back(multi_jittered(0, 16, key).x);
        b.push_back(multi_jittered(0, 16, key + 1).x);
    }
    EXPECT_LT(std::abs(correlation(a, b)), 0.06);  // standard error 1/64
}

}  // namespace
}  // namespace drt
