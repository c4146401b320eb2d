// The render's own error estimate: the per-pixel spreads and the fit on known numbers, the
// estimate against the true error of real renders, and its independence of threads and tile order.
#include "drt/error_estimate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "drt/converge.h"
#include "drt/render_context.h"
#include "drt/renderer.h"
#include "drt/scene_loader.h"

namespace drt {
namespace {

TEST(PixelSpread, IndependentSamplesGiveTheSampleVarianceOverN) {
    const std::vector<Color> samples{{1, 0, 2}, {3, 0, 2}, {5, 0, 2}, {7, 0, 2}};
    ErrorSums sums;
    const Color s = pixel_spread(samples, SpreadKind::kIndependent, sums);
    EXPECT_DOUBLE_EQ(s.r, (20.0 / 3) / 4);  // sample variance of 1, 3, 5, 7 is 20/3
    EXPECT_EQ(s.g, 0);
    EXPECT_EQ(s.b, 0);
    EXPECT_EQ(sums, ErrorSums{});  // only progressive samples add to the sums
}

TEST(PixelSpread, ProgressiveSamplesGiveTheSpreadsOfRunMeans) {
    // Run means: 2 runs {2.5, 6.5}; 4 runs {1.5, 3.5, 5.5, 7.5}; 8 runs 1..8.
    std::vector<Color> samples;
    for (int i = 1; i <= 8; ++i) samples.push_back({double(i), 0, 0});
    ErrorSums sums;
    const Color s = pixel_spread(samples, SpreadKind::kProgressive, sums);
    // (B-1)/B x sample variance = mean squared deviation of the B run means.
    EXPECT_DOUBLE_EQ(sums.runs[0], 4.0);   // deviations of 2
    EXPECT_DOUBLE_EQ(sums.runs[1], 5.0);   // (9 + 1 + 1 + 9) / 4
    EXPECT_DOUBLE_EQ(sums.runs[2], 5.25);  // (49 + 25 + 9 + 1) * 2 / 4 / 8
    EXPECT_EQ(s.r, sums.runs[2]);          // the pixel keeps the most runs' spread
    EXPECT_EQ(sums.runs_pixels, (std::array<double, 3>{1, 1, 1}));
}

TEST(PixelSpread, OneSampleHasNoSpread) {
    ErrorSums sums;
    const std::vector<Color> one{{1, 1, 1}};
    EXPECT_TRUE(std::isinf(pixel_spread(one, SpreadKind::kOther, sums).r));
}

TEST(EstimateError, OneSampleAndTooFewRunsAreNotANumber) {
    const Image image(2, 1), spread(2, 1);
    const ErrorEstimate one = estimate_error(image, spread, {}, 1, SpreadKind::kOther);
    EXPECT_FALSE(one.available());
    EXPECT_EQ(one.unavailable, "1 spp takes the pixel centre: no spread to measure");
    EXPECT_EQ(format_estimate(one.rmse, one.unavailable),
              "n/a (1 spp takes the pixel centre: no spread to measure)");
    ErrorSums two_runs;
    two_runs.runs = {1, 0, 0};
    two_runs.runs_pixels = {2, 0, 0};
    const ErrorEstimate sobol =
        estimate_error(image, spread, two_runs, 2, SpreadKind::kProgressive);
    EXPECT_EQ(sobol.unavailable, "the sobol estimate needs 8 spp or more");
}

TEST(EstimateError, IndependentSpreadsAverageOverPixelsAndChannels) {
    Image image(2, 1), spread(2, 1);
    image.rgb = {0.5f, 0.5f, 0.5f, 0, 0, 0};
    spread.rgb = {0.01f, 0.02f, 0.03f, 0.04f, 0.05f, 0.06f};
    const ErrorEstimate e = estimate_error(image, spread, {}, 16, SpreadKind::kIndependent);
    ASSERT_TRUE(e.available());
    EXPECT_NEAR(*e.rmse, std::sqrt(0.21 / 6), 1e-7);
    // relMSE: v / (max(0, x^2 - v) + 0.01).
    const double rel =
        0.01 / 0.25 + 0.02 / 0.24 + 0.03 / 0.23 + 0.04 / 0.01 + 0.05 / 0.01 + 0.06 / 0.01;
    EXPECT_NEAR(*e.relmse, rel / 6, 1e-6);
}

TEST(EstimateError, ProgressiveFitFindsTheRateAndTheVariance) {
    // Spreads made exactly as E[T_B] = sigma2 (B^beta - 1) says, for beta 1 (random noise), 1.5
    // (edges) and 3 (smooth).
    for (const double beta : {1.0, 1.5, 3.0}) {
        const double sigma2 = 0.003;  // summed over 1 pixel x 3 channels
        ErrorSums sums;
        for (std::size_t k = 0; k < 3; ++k) {
            sums.runs[k] = sigma2 * (std::pow(2.0 * (1 << k), beta) - 1);
            sums.runs_pixels[k] = 1;
        }
        Image image(1, 1), spread(1, 1);
        spread.rgb = {float(sums.runs[2] / 3), float(sums.runs[2] / 3), float(sums.runs[2] / 3)};
        const ErrorEstimate e = estimate_error(image, spread, sums, 64, SpreadKind::kProgressive);
        ASSERT_TRUE(e.available());
        EXPECT_NEAR(e.beta, beta, 0.003);
        EXPECT_NEAR(*e.rmse, std::sqrt(sigma2 / 3), 0.01 * std::sqrt(sigma2 / 3)) << beta;
    }
}

Scene small_scene(const std::string& file, const std::string& sampler, int spp,
                  std::uint64_t seed) {
    Scene scene = load_scene(std::string(DRT_SOURCE_DIR) + "/scenes/" + file).scene;
    scene.settings.width = 32;
    scene.settings.height = 24;
    scene.settings.sampler = sampler;
    scene.settings.samples = spp;
    scene.settings.seed = seed;
    return scene;
}

// The estimate against the error measured against a 4096-spp sobol reference (its own error,
// 1/64 of the renders' variance or less, taken out), for three seeds.
TEST(EstimateError, WithinAQuarterOfTheTrueErrorOnAPenumbraAndEdges) {
    RenderOptions options;
    options.threads = 2;
    const RenderResult reference =
        render(small_scene("study/penumbra.xml", "sobol", 4096, 100), options);
    ASSERT_TRUE(reference.stats.error.available());
    const double ref_mse = std::pow(*reference.stats.error.rmse, 2);
    for (const std::string sampler : {"sobol", "random"}) {
        for (const std::uint64_t seed : {1, 2, 3}) {
            const RenderResult r =
                render(small_scene("study/penumbra.xml", sampler, 64, seed), options);
            ASSERT_TRUE(r.stats.error.available());
            const double truth = std::sqrt(std::pow(rmse(r.image, reference.image), 2) - ref_mse);
            const double ratio = *r.stats.error.rmse / truth;
            EXPECT_GT(ratio, 0.8) << sampler << " seed " << seed;
            EXPECT_LT(ratio, 1.25) << sampler << " seed " << seed;
        }
    }
}

TEST(EstimateError, SameForAnyThreadsAndTileOrder) {
    for (const std::string sampler : {"stratified", "sobol", "random"}) {
        const Scene scene = small_scene("thesis/test1.xml", sampler, 16, 0);
        RenderOptions one;
        one.threads = 1;
        const RenderResult a = render(scene, one);
        // Two threads, the tiles backwards.
        const RenderContext context(scene, std::nullopt);
        ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
        std::vector<Tile> backwards = context.tiles();
        std::reverse(backwards.begin(), backwards.end());
        TileQueue source(backwards);
        RenderOptions two;
        two.threads = 2;
        render_tiles(context, source, sink, two);
        const RenderResult b = assembled(context, sink);
        EXPECT_EQ(a.image.rgb, b.image.rgb);
        EXPECT_EQ(a.spread.rgb, b.spread.rgb) << sampler;
        ASSERT_TRUE(a.stats.error.available() && b.stats.error.available()) << sampler;
        EXPECT_EQ(*a.stats.error.rmse, *b.stats.error.rmse) << sampler;
        EXPECT_EQ(*a.stats.error.relmse, *b.stats.error.relmse) << sampler;
    }
}

}  // namespace
}  // namespace drt
