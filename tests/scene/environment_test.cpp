// The environment map: its orientation (docs/scene-format.md, "Sphere and Environment"), its
// intensity, its sampling density, and how a scene loads it.
#include "drt/scene/environment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>

#include "drt/io/image.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/rng.h"
#include "temp_folder.h"
#include "test_math.h"

namespace drt {
namespace {

using testing::unit;

// The direction of (u, v) by the contract: φ = 2πu + rotation, θ = π(1 − v).
Vec3 direction_of(double u, double v, double rotate_y = 0) {
    const double phi = 2 * kPi * u + rotate_y, theta = kPi * (1 - v);
    return {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
}

// A w x h map, black but for one texel (i, j counted from the bottom) of radiance `bright`.
std::shared_ptr<const MipMap> one_bright_texel(int w, int h, int i, int j, Color bright) {
    Image image(w, h);
    image.set(i, h - 1 - j, bright);  // Image rows run from the top
    return std::make_shared<const MipMap>(image);
}

std::shared_ptr<const MipMap> uniform_map(int w, int h, Color c) {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) image.set(x, y, c);
    }
    return std::make_shared<const MipMap>(image);
}

// The contract's fixed points: the left edge at the horizon is +x, a quarter of the way across
// is −z (u grows counter-clockwise seen from above), the top row is +y.
TEST(Environment, DirectionsMapToTheContractsCoordinates) {
    // 4 x 3: texel centres at u = 1/8, 3/8, ... and v = 1/6, 1/2, 5/6.
    Image image(4, 3);
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 3; ++j) image.set(i, 2 - j, Color{double(i), double(j), 1});
    }
    const Environment env(std::make_shared<const MipMap>(image), 1, 0);
    // Texel (1, 1) (u = 3/8, the horizon) lies at φ = 135°: between −z and −x.
    const Color c = env.radiance(normalize(Vec3{-1, 0, -1}));
    EXPECT_NEAR(c.r, 1, 1e-6);
    EXPECT_NEAR(c.g, 1, 1e-6);
    // Straight up reads the top row (j = 2).
    EXPECT_NEAR(env.radiance({0, 1, 0}).g, 2, 1e-6);
    EXPECT_NEAR(env.radiance({0, -1, 0}).g, 0, 1e-6);
    // Texel (0, 1) at φ = 45°: between +x and −z.
    EXPECT_NEAR(env.radiance(normalize(Vec3{1, 0, -1})).r, 0, 1e-6);
    EXPECT_NEAR(env.radiance(normalize(Vec3{-1, 0, 1})).r, 2, 1e-6);  // φ = 225°: texel 2
    EXPECT_NEAR(env.radiance(normalize(Vec3{1, 0, 1})).r, 3, 1e-6);   // φ = 315°: texel 3
}

// One bright texel is seen in its direction and sampled towards it; RotateY of 90° turns it
// by 90° counter-clockwise seen from above (right-handed about +y): from φ to φ + 90°.
TEST(Environment, OneBrightTexelAppearsWhereExpectedAndRotateYTurnsIt) {
    constexpr int w = 32, h = 16, i = 5, j = 11;
    const double u = (i + 0.5) / w, v = (j + 0.5) / h;
    for (const double degrees : {0.0, 90.0, -30.0}) {
        const double rotation = degrees * kPi / 180;
        const Environment env(one_bright_texel(w, h, i, j, {100, 100, 100}), 1, rotation);
        const Vec3 expected = direction_of(u, v, rotation);
        EXPECT_NEAR(env.radiance(expected).r, 100, 1e-4) << degrees;
        EXPECT_NEAR(env.radiance(direction_of(u, v, -rotation)).r, degrees == 0 ? 100 : 0, 1e-4);
        // Samples go to the bright texel's neighbourhood (its light spreads half a texel by
        // the bilinear lookup) and nowhere else.
        for (int k = 0; k < 1000; ++k) {
            const auto s = env.sample({unit(4, k), unit(5, k)});
            ASSERT_TRUE(s);
            EXPECT_GT(dot(s->dir, expected), std::cos(2.5 * kPi / h)) << degrees;
        }
    }
    // 90° about +y takes the texel at φ = 2πu to φ + 90°: explicitly, +x goes to −z.
    const Environment plus_x(one_bright_texel(w, h, 0, h / 2, {1, 1, 1}), 1, kPi / 2);
    EXPECT_NEAR(plus_x.radiance(direction_of(0.5 / w, (h / 2 + 0.5) / h, kPi / 2)).r, 1, 1e-6);
    const Vec3 turned = direction_of(0.5 / w, (h / 2 + 0.5) / h, kPi / 2);
    EXPECT_LT(turned.z, -0.99);
}

// Intensity scales the radiance exactly (a 2 % change fails here).
TEST(Environment, IntensityScalesTheRadiance) {
    const Environment env(uniform_map(8, 4, {0.5, 1, 2}), 3, 0.7);
    for (int k = 0; k < 20; ++k) {
        const Vec3 d = direction_of(unit(6, k), unit(7, k));
        const Color c = env.radiance(d);
        EXPECT_NEAR(c.r, 1.5, 1e-6);
        EXPECT_NEAR(c.g, 3, 1e-6);
        EXPECT_NEAR(c.b, 6, 1e-6);
    }
}

// The density integrates to 1 over the sphere (quadrature in (u, v)), sample() reports
// pdf(dir) of its direction, and ∫ luminance dω estimated by importance sampling equals the
// quadrature. The estimate's standard error is about 0.12 % (0.6 % is five of them): a density
// 2 % off fails by either check.
TEST(Environment, DensityIntegratesToOneAndImportanceSamplingIsUnbiased) {
    Image image(64, 32);
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 64; ++x) {
            const double l =
                0.2 + unit(9, y * 64 + x) + (x > 40 && x < 44 && y > 8 && y < 11 ? 500 : 0);
            image.set(x, y, {l, 0.5 * l, 0.25 * l});
        }
    }
    const Environment env(std::make_shared<const MipMap>(image), 2, 1.0);
    constexpr int nu = 1024, nv = 512;
    double total = 0, integral = 0;
    for (int b = 0; b < nv; ++b) {
        const double v = (b + 0.5) / nv;
        const double sin_theta = std::sin(kPi * (1 - v));
        for (int a = 0; a < nu; ++a) {
            const Vec3 d = direction_of((a + 0.5) / nu, v);
            const double solid_angle = 2 * kPi * kPi * sin_theta / (double(nu) * nv);
            total += env.pdf(d) * solid_angle;
            integral += luminance(env.radiance(d)) * solid_angle;
        }
    }
    EXPECT_NEAR(total, 1.0, 2e-3);
    {
        constexpr int stream = 20;
        double estimate = 0, square = 0;
        constexpr int kSamples = 800000;
        for (int k = 0; k < kSamples; ++k) {
            const auto s = env.sample({unit(stream, k), unit(stream + 1, k)});
            ASSERT_TRUE(s);
            ASSERT_NEAR(s->pdf, env.pdf(s->dir), 1e-6 * s->pdf);
            const double f = luminance(s->radiance) / s->pdf;
            estimate += f;
            square += f * f;
        }
        estimate /= kSamples;
        const double error = std::sqrt((square / kSamples - estimate * estimate) / kSamples);
        EXPECT_LT(error / integral, 0.0015);
        EXPECT_NEAR(estimate / integral, 1.0, 0.006);
    }
}

// Everything the environment works out from a 4096 x 2048 map (its luminance, the dilation, the
// distribution, its power) stays well under a second; the mip-map is the texture cache's.
// A full-size map of one radiance: every direction is as likely as any other (the pixels' solid
// angles weighed in; near the poles a row's sin θ varies across it, so they are left out), and
// the map is read back as it was.
TEST(Environment, AUniformFullSizeMapIsSampledUniformlyOverTheSphere) {
    constexpr int w = 4096, h = 2048;
    Image image(w, h);
    std::fill(image.rgb.begin(), image.rgb.end(), 2.0f);
    const Environment env(std::make_shared<const MipMap>(image), 1, 0);
    EXPECT_GT(env.power(), 0);
    for (const Vec3& d :
         {Vec3{0, 0.6, 0.8}, Vec3{1, 0, 0}, Vec3{0.3, -0.8, 0.52}, Vec3{-1, 0.1, 0.2}}) {
        const Vec3 dir = normalize(d);
        EXPECT_NEAR(env.pdf(dir) * 4 * kPi, 1.0, 2e-3) << dir.x << " " << dir.y << " " << dir.z;
        EXPECT_NEAR(env.radiance(dir).g, 2.0, 1e-6);
    }
}

class EnvironmentScene : public test::TempFolderTest {
  protected:
    LoadedScene load(const std::string& environment) {
        const std::string xml =
            "<Scene><Image Width=\"4\" Height=\"4\"/>\n" + environment + "\n</Scene>";
        std::ofstream(dir_ / "scene.xml") << xml;
        return load_scene(dir_ / "scene.xml");
    }
};

TEST_F(EnvironmentScene, LoadsTheMapWithIntensityAndRotation) {
    Image image(8, 4);
    image.set(0, 1, {4, 4, 4});  // u = 1/16, v = 5/8
    write_image(image, dir_ / "sky.exr");
    const LoadedScene loaded =
        load("<Environment File=\"sky.exr\" Intensity=\"0.5\" RotateY=\"90\"/>");
    ASSERT_TRUE(loaded.scene.environment);
    const Vec3 d = direction_of(0.5 / 8, 2.5 / 4, kPi / 2);
    EXPECT_NEAR(loaded.scene.environment->radiance(d).r, 2, 1e-6);
    EXPECT_EQ(loaded.files_read.size(), 1u);
}

TEST_F(EnvironmentScene, BadFilesAndValuesAreErrorsAtTheirLine) {
    EXPECT_THROW(
        {
            try {
                load("<Environment File=\"missing.hdr\"/>");
            } catch (const SceneError& e) {
                EXPECT_NE(std::string(e.what()).find("scene.xml:2:"), std::string::npos)
                    << e.what();
                throw;
            }
        },
        SceneError);
    std::ofstream(dir_ / "junk.hdr") << "not an image";
    EXPECT_THROW(load("<Environment File=\"junk.hdr\"/>"), SceneError);
    write_image(Image(2, 2), dir_ / "ok.exr");
    EXPECT_THROW(load("<Environment File=\"ok.exr\" Intensity=\"-1\"/>"), SceneError);
    EXPECT_THROW(load("<Environment/>"), SceneError);
    EXPECT_FALSE(load("").scene.environment);
}

}  // namespace
}  // namespace drt
