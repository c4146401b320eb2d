#include "drt/shading/mipmap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "drt/shading/image_texture.h"

namespace drt {
namespace {

void expect_color_near(const Color& c, double r, double g, double b, double tolerance = 1e-6) {
    EXPECT_NEAR(c.r, r, tolerance);
    EXPECT_NEAR(c.g, g, tolerance);
    EXPECT_NEAR(c.b, b, tolerance);
}

// 2 x 2, as an image file stores it (row 0 on top): red, green over blue, white.
Image two_by_two() {
    Image image(2, 2);
    image.set(0, 0, {1, 0, 0});
    image.set(1, 0, {0, 1, 0});
    image.set(0, 1, {0, 0, 1});
    image.set(1, 1, {1, 1, 1});
    return image;
}

// (0, 0) is the image's bottom-left corner and v grows upwards: a flipped v reads red at the
// bottom, and texel centres off by half a texel blend colours at the centres.
TEST(MipMap, OriginIsTheBottomLeftAndTexelCentresAreAtHalves) {
    const MipMap map(two_by_two());
    expect_color_near(map.texel(0, 0, 0), 0, 0, 1);  // bottom-left: blue
    expect_color_near(map.bilinear(0, {0.25, 0.25}), 0, 0, 1);
    expect_color_near(map.bilinear(0, {0.75, 0.25}), 1, 1, 1);
    expect_color_near(map.bilinear(0, {0.25, 0.75}), 1, 0, 0);
    expect_color_near(map.bilinear(0, {0.75, 0.75}), 0, 1, 0);
    ImageTexture texture(std::make_shared<const MipMap>(two_by_two()));
    TexturePoint at;
    at.uv = {0.25, 0.25};
    expect_color_near(texture.value(at), 0, 0, 1);
}

// A ramp 0, 1, 2, 3 along u: bilinear lookups are linear between texel centres and wrap
// around the edge (the image repeats).
TEST(MipMap, BilinearRampsAndRepeats) {
    Image ramp(4, 1);
    for (int i = 0; i < 4; ++i) ramp.set(i, 0, {double(i), 0, 0});
    const MipMap map(ramp);
    EXPECT_NEAR(map.bilinear(0, {0.125, 0.5}).r, 0, 1e-12);
    EXPECT_NEAR(map.bilinear(0, {0.375, 0.5}).r, 1, 1e-12);
    EXPECT_NEAR(map.bilinear(0, {0.5, 0.5}).r, 1.5, 1e-12);
    EXPECT_NEAR(map.bilinear(0, {0.4375, 0.5}).r, 1.25, 1e-12);
    EXPECT_NEAR(map.bilinear(0, {0.0, 0.5}).r, 1.5, 1e-12);  // between texel 3 and texel 0
    EXPECT_NEAR(map.bilinear(0, {1.375, 0.5}).r, 1, 1e-12);
    EXPECT_NEAR(map.bilinear(0, {-0.625, 7.5}).r, 1, 1e-12);
    EXPECT_NEAR(map.bilinear(0, {1e9 + 0.375, 0.5}).r, 1, 1e-6);
}

TEST(MipMap, LevelsAreBoxFilteredDownToOneTexel) {
    const MipMap map(two_by_two());
    ASSERT_EQ(map.level_count(), 2);
    expect_color_near(map.texel(1, 0, 0), 0.5, 0.5, 0.5);
    EXPECT_EQ(map.bytes(), 12u * 5);
    // 4096² over 13 levels: 12 bytes × (4^13 − 1) / 3 texels.
    EXPECT_EQ(MipMap::bytes_for(4096, 4096), 12u * ((std::uint64_t{1} << 26) - 1) / 3);

    // Odd sides: 3 x 1 -> 1 x 1 weighs each texel by its overlap, a third each.
    Image odd(3, 1);
    odd.set(0, 0, {3, 0, 0});
    odd.set(2, 0, {6, 0, 0});
    const MipMap small(odd);
    ASSERT_EQ(small.level_count(), 2);
    EXPECT_NEAR(small.texel(1, 0, 0).r, 3, 1e-6);

    // 4 x 2 -> 2 x 1 -> 1 x 1.
    Image wide(4, 2);
    for (int i = 0; i < 4; ++i) wide.set(i, 0, {double(i), 0, 0});
    const MipMap w(wide);
    ASSERT_EQ(w.level_count(), 3);
    EXPECT_NEAR(w.texel(1, 0, 0).r, 0.25, 1e-6);
    EXPECT_NEAR(w.texel(1, 1, 0).r, 1.25, 1e-6);
    EXPECT_NEAR(w.texel(2, 0, 0).r, 0.75, 1e-6);
}

// The footprint's width picks the level whose texels are that wide, blending the two around it.
TEST(MipMap, TrilinearPicksTheLevelOfTheFootprint) {
    Image checker(4, 4);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) checker.set(i, j, Color{double((i + j) % 2), 0, 0});
    const MipMap map(checker);
    ASSERT_EQ(map.level_count(), 3);
    EXPECT_EQ(map.filtered({0.125, 0.125}, 0).r, map.bilinear(0, {0.125, 0.125}).r);
    EXPECT_EQ(map.filtered({0.125, 0.125}, 0.25).r, map.bilinear(0, {0.125, 0.125}).r);
    EXPECT_NEAR(map.filtered({0.125, 0.125}, 0.5).r, 0.5, 1e-6);  // level 1: all grey
    EXPECT_NEAR(map.filtered({0.125, 0.125}, 100).r, 0.5, 1e-6);
    // Width 2^-1.5 lies half way (in log2) between level 0 and level 1 (grey).
    const double texel00 = map.bilinear(0, {0.125, 0.125}).r;
    EXPECT_NEAR(map.filtered({0.125, 0.125}, std::pow(2.0, -1.5)).r, 0.5 * (texel00 + 0.5), 1e-6);
}

// Horizontal stripes (rows alternate black and white) seen with a footprint long along u and
// one texel high: anisotropic probes along u keep the stripe, one trilinear square as wide as
// the long side blurs it to grey.
TEST(MipMap, AnisotropicProbesBlurAlongTheLongSideOnly) {
    Image stripes(8, 8);
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) stripes.set(i, j, Color{double(j % 2), 0, 0});
    const MipMap map(stripes);
    const Vec2 bottom_row{0.3, 1.0 / 16};  // the centre of texel row 0 from the bottom: white
    EXPECT_NEAR(map.filtered(bottom_row, {0.5, 0}, {0, 1.0 / 8}).r, 1, 1e-6);
    EXPECT_NEAR(map.filtered(bottom_row, 0.5).r, 0.5, 1e-6);
    // A square footprint is the trilinear one.
    EXPECT_EQ(map.filtered(bottom_row, {0.25, 0}, {0, 0.25}).r, map.filtered(bottom_row, 0.25).r);
    // A footprint of zero reads level 0.
    EXPECT_EQ(map.filtered({0.4, 0.3}, {}, {}).r, map.bilinear(0, {0.4, 0.3}).r);
}

// A height ramp h = (i + ½)/8 over 8 texels along u rises by 1 per unit of u: strength ½ tilts
// the normal (0, 0, 1) against the slope to normalize(−½, 0, 1), whatever the scale of ∂p/∂u
// (only its direction counts); a flat v leaves y alone.
TEST(HeightMap, TiltsTheNormalAgainstTheSlopeTimesStrength) {
    Image ramp(8, 1);
    for (int i = 0; i < 8; ++i) ramp.set(i, 0, Color{1, 1, 1} * ((i + 0.5) / 8));
    const HeightMap bumps(std::make_shared<const MipMap>(ramp), 0.5);
    TexturePoint at;
    at.uv = {0.5, 0.5};
    const Vec3 n = bumps.perturb({0, 0, 1}, at, {3, 0, 0}, {0, 2, 0});
    const Vec3 expected = normalize(Vec3{-0.5, 0, 1});
    EXPECT_NEAR(n.x, expected.x, 1e-6);
    EXPECT_NEAR(n.y, 0, 1e-12);
    EXPECT_NEAR(n.z, expected.z, 1e-6);
    // The tangent direction carries the tilt: u growing along −y tilts towards +y.
    const Vec3 turned = bumps.perturb({0, 0, 1}, at, {0, -1, 0}, {1, 0, 0});
    EXPECT_NEAR(turned.y, -expected.x, 1e-6);
    EXPECT_NEAR(turned.x, 0, 1e-12);
}

}  // namespace
}  // namespace drt
