#include "drt/util/float_rounding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace drt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// What the rounding must give, by std::nextafter: the float at or beyond x nearest to it.
float reference_up(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x) f = std::nextafter(f, kInf);
    return f;
}
float reference_down(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = std::nextafter(f, -kInf);
    return f;
}

TEST(FloatRounding, BoundsTheDoubleByTheNearestFloatOnEachSide) {
    const double max = std::numeric_limits<float>::max();
    const double tiny = std::numeric_limits<float>::denorm_min();
    for (const double x : {0.0,
                           -0.0,
                           0.1,
                           -0.1,
                           1.0,
                           -1.0,
                           1.0 / 3,
                           -2.0 / 3,
                           1e-40,
                           -1e-40,
                           tiny * 0.5,
                           -tiny * 0.5,
                           tiny,
                           3e38,
                           -3e38,
                           max,
                           -max,
                           max * 1.0000001,
                           -max * 1.0000001,
                           1e39,
                           -1e39,
                           16777217.0,
                           -16777217.0}) {
        const float up = to_float_up(x), down = to_float_down(x);
        EXPECT_GE(up, x) << x;
        EXPECT_LE(down, x) << x;
        EXPECT_EQ(up, reference_up(x)) << x;
        EXPECT_EQ(down, reference_down(x)) << x;
        // Nearest: the next float inwards is already on the wrong side.
        if (up != down) {
            EXPECT_LT(std::nextafter(up, -kInf), x) << x;
            EXPECT_GT(std::nextafter(down, kInf), x) << x;
        }
    }
}

TEST(FloatRounding, KeepsFloatsInfinitiesAndNaN) {
    for (const float f : {0.0f, 1.5f, -7.25f, 1e-45f, kInf, -kInf}) {
        EXPECT_EQ(to_float_up(f), f);
        EXPECT_EQ(to_float_down(f), f);
    }
    EXPECT_TRUE(std::isnan(to_float_up(std::nan(""))));
    EXPECT_TRUE(std::isnan(to_float_down(std::nan(""))));
    EXPECT_EQ(to_float_up(1 + 0x1p-30), 1 + 0x1p-23f);
    EXPECT_EQ(to_float_down(1 + 0x1p-30), 1.0f);
    EXPECT_EQ(to_float_up(-1e-50), -0.0f);
    EXPECT_EQ(to_float_down(1e-50), 0.0f);
    EXPECT_EQ(to_float_up(1e-50), std::numeric_limits<float>::denorm_min());
}

TEST(FloatRounding, NextFloatUpStepsOneFloat) {
    EXPECT_EQ(next_float_up(0.0f), std::numeric_limits<float>::denorm_min());
    EXPECT_EQ(next_float_up(-0.0f), std::numeric_limits<float>::denorm_min());
    EXPECT_EQ(next_float_up(1.0f), 1 + 0x1p-23f);
    EXPECT_EQ(next_float_up(-1.0f), -1 + 0x1p-24f);
    EXPECT_EQ(next_float_up(-std::numeric_limits<float>::denorm_min()), 0.0f);
    EXPECT_EQ(next_float_up(std::numeric_limits<float>::max()), kInf);
}

}  // namespace
}  // namespace drt
