#include "drt/compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace drt {
namespace {

// A smooth gradient with some texture, values in [0, 0.8].
Image gradient(int w, int h) {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double u = double(x) / w, v = double(y) / h;
            image.set(x, y, {0.8 * u, 0.4 + 0.4 * std::sin(6 * u + 3 * v), 0.8 * v});
        }
    }
    return image;
}

// Deterministic noise in [-amplitude, amplitude] per value.
Image with_noise(Image image, double amplitude) {
    std::uint64_t state = 12345;
    for (float& v : image.rgb) {
        state = state * 6364136223846793005u + 1442695040888963407u;
        const double u = double(state >> 11) / double(std::uint64_t{1} << 53);
        v += static_cast<float>(amplitude * (2 * u - 1));
    }
    return image;
}

TEST(CompareImages, IdenticalImages) {
    const Image a = gradient(32, 24);
    const Comparison c = compare_images(a, a);
    EXPECT_EQ(c.rmse, 0);
    EXPECT_EQ(c.max_abs, 0);
    EXPECT_TRUE(std::isinf(c.psnr) && c.psnr > 0);
    EXPECT_DOUBLE_EQ(c.ssim, 1);
}

TEST(CompareImages, ConstantOffsetGivesItsRmseAndPsnr) {
    const Image a = gradient(20, 10);
    Image b = a;
    for (float& v : b.rgb) v += 0.1f;
    const Comparison c = compare_images(a, b);
    EXPECT_NEAR(c.rmse, 0.1, 1e-6);
    EXPECT_NEAR(c.psnr, 20, 1e-4);
    EXPECT_NEAR(c.max_abs, 0.1, 1e-6);
    EXPECT_LT(c.ssim, 1);
}

TEST(CompareImages, RmseUsesTheStoredValuesUnclamped) {
    Image a(2, 1), b(2, 1);
    a.set(0, 0, {3, 0, 0});  // one error of 3 among six values
    const Comparison c = compare_images(a, b);
    EXPECT_NEAR(c.rmse, std::sqrt(9.0 / 6), 1e-12);
    EXPECT_EQ(c.max_abs, 3);
}

TEST(CompareImages, SizeMismatchThrows) {
    try {
        compare_images(Image(4, 3), Image(3, 4));
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_STREQ(e.what(), "image sizes differ: 4x3 vs 3x4");
    }
    EXPECT_THROW(difference_image(Image(4, 3), Image(4, 2)), ImageError);
}

TEST(CompareImages, SsimOfANoisyCopyIsBetweenZeroAndOne) {
    const Image a = gradient(64, 48);
    const double slight = compare_images(a, with_noise(a, 0.02)).ssim;
    const double strong = compare_images(a, with_noise(a, 0.3)).ssim;
    EXPECT_LT(slight, 1);
    EXPECT_GT(slight, 0);
    EXPECT_LT(strong, slight);
    EXPECT_GT(strong, 0);
}

TEST(CompareImages, SsimWorksForImagesSmallerThanTheWindow) {
    const Image a = gradient(5, 3);
    EXPECT_DOUBLE_EQ(compare_images(a, a).ssim, 1);
    const double s = compare_images(a, with_noise(a, 0.2)).ssim;
    EXPECT_TRUE(s > 0 && s < 1) << s;
}

TEST(DifferenceImage, EqualImagesGiveBlack) {
    const Image a = gradient(8, 6);
    const Image d = difference_image(a, a);
    ASSERT_EQ(d.width, 8);
    ASSERT_EQ(d.height, 6);
    for (float v : d.rgb) ASSERT_EQ(v, 0);
}

TEST(DifferenceImage, LargestErrorIsRedAndSmallerOnesFollowTheRamp) {
    const Image a(4, 1);
    Image b(4, 1);
    b.set(0, 0, {0.5, 0.5, 0.5});     // largest error
    b.set(1, 0, {0.25, 0.25, 0.25});  // half of it: the middle of the ramp, green
    b.set(2, 0, {0, 0, -0.125});      // RMS over channels 0.072, below a quarter of the maximum
    const Image d = difference_image(a, b);
    EXPECT_EQ(d.at(0, 0), (Color{1, 0, 0}));
    EXPECT_EQ(d.at(1, 0), (Color{0, 1, 0}));
    const Color low = d.at(2, 0);  // between black and blue
    EXPECT_EQ(low.r, 0);
    EXPECT_EQ(low.g, 0);
    EXPECT_GT(low.b, 0);
    EXPECT_LT(low.b, 1);
    EXPECT_EQ(d.at(3, 0), (Color{0, 0, 0}));
}

TEST(DifferenceImage, NonFiniteErrorsShowAsRed) {
    const Image a(2, 1);
    Image b(2, 1);
    b.rgb[0] = std::numeric_limits<float>::quiet_NaN();
    const Image d = difference_image(a, b);
    EXPECT_EQ(d.at(0, 0), (Color{1, 0, 0}));
    EXPECT_EQ(d.at(1, 0), (Color{0, 0, 0}));
}

}  // namespace
}  // namespace drt
