#include "drt/sampling/cdf_pick.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace drt {
namespace {

TEST(CdfPick, PicksByProbabilityAndStretchesTheRestOverTheUnitInterval) {
    const std::vector<double> cdf{0.25, 0.25, 1.0};  // the second choice has probability 0
    const CdfPick first = pick_from_cdf(cdf, 0.125);
    EXPECT_EQ(first.index, 0u);
    EXPECT_EQ(first.probability, 0.25);
    EXPECT_EQ(first.rest, 0.5);
    // The boundary belongs to the next choice with room: never to one of probability 0.
    const CdfPick boundary = pick_from_cdf(cdf, 0.25);
    EXPECT_EQ(boundary.index, 2u);
    EXPECT_EQ(boundary.probability, 0.75);
    EXPECT_EQ(boundary.rest, 0.0);
    const CdfPick last = pick_from_cdf(cdf, std::nextafter(1.0, 0.0));
    EXPECT_EQ(last.index, 2u);
    EXPECT_LT(last.rest, 1.0);
    EXPECT_EQ(pick_from_cdf(cdf, 0.0).index, 0u);
}

// Uniform numbers give each choice its share, and the rests within a choice stay uniform.
TEST(CdfPick, UniformNumbersGiveEachChoiceItsShareAndUniformRests) {
    const std::vector<double> cdf{0.1, 0.4, 1.0};
    constexpr int kN = 6000;
    std::vector<int> count(3);
    std::vector<double> rest_sum(3);
    for (int i = 0; i < kN; ++i) {
        const CdfPick pick = pick_from_cdf(cdf, (i + 0.5) / kN);
        ++count[pick.index];
        rest_sum[pick.index] += pick.rest;
    }
    EXPECT_EQ(count, (std::vector<int>{600, 1800, 3600}));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(rest_sum[k] / count[k], 0.5, 1e-9) << k;
}

}  // namespace
}  // namespace drt
