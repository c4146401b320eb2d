#include "drt/io/compare.h"

#include <gtest/gtest.h>

#include <algorithm>
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

// Flat images have no variance, so only SSIM's luminance term is left: (2ab + C1) / (a² + b² + C1)
// with C1 = 0.01², for greys a and b (grey's luminance is its value).
TEST(CompareImages, SsimOfFlatGreysIsItsLuminanceTerm) {
    const auto flat = [](float v) {
        Image image(16, 12);
        std::fill(image.rgb.begin(), image.rgb.end(), v);
        return image;
    };
    const double c1 = 0.01 * 0.01;
    EXPECT_NEAR(compare_images(flat(0.5f), flat(0.25f)).ssim,
                (2 * 0.5 * 0.25 + c1) / (0.25 + 0.0625 + c1), 1e-12);
    EXPECT_NEAR(compare_images(flat(0.0f), flat(1.0f)).ssim, c1 / (1 + c1), 1e-12);
    // Values beyond [0, 1] are clamped first: 4 counts as 1.
    EXPECT_NEAR(compare_images(flat(4.0f), flat(0.5f)).ssim, (1 + c1) / (1.25 + c1), 1e-12);
}

// A flat image against one with texture of the same mean: the luminance term is 1 and the
// contrast-structure term C2 / (σ² + C2), C2 = 0.03², with σ² the texture's local variance. A
// checkerboard of 0.5 ± d has σ² = d² in every window (weights summing to 1 over equal numbers of
// each square only approximately, so the bound is loose).
TEST(CompareImages, SsimOfAFlatImageAgainstACheckerboardIsItsContrastTerm) {
    Image flat(32, 32), checker(32, 32);
    const double d = 0.1;
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 32; ++x) {
            const double v = 0.5 + ((x + y) % 2 ? d : -d);
            flat.set(x, y, {0.5, 0.5, 0.5});
            checker.set(x, y, {v, v, v});
        }
    }
    const double c2 = 0.03 * 0.03;
    EXPECT_NEAR(compare_images(flat, checker).ssim, c2 / (d * d + c2), 2e-3);
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
