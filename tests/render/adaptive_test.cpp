// Adaptive sampling in the renderer: pixels stop taking samples once their noise is low enough.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "drt/render/renderer.h"
#include "test_scenes.h"

namespace drt {
namespace {

// A flat-coloured sphere (ambient light only) on a flat background: pixels wholly inside or
// outside have no noise at all, pixels on the edge have plenty.
Scene edge_scene(const std::string& sampler, int samples) {
    Scene scene = testing::lone_sphere_scene(testing::grey_lambert(0.8), {0.1, 0.2, 0.3}, 32);
    scene.ambient = {1, 1, 1};
    scene.settings.sampler = sampler;
    scene.settings.samples = samples;
    scene.settings.seed = 3;
    return scene;
}

RenderOptions adaptive(double threshold, int min_samples, int threads = 0) {
    RenderOptions o;
    o.threads = threads;
    o.adaptive = AdaptiveSampling{threshold, min_samples};
    return o;
}

std::uint32_t samples_at(const RenderResult& r, int x, int y) {
    return r.pixel_samples[static_cast<std::size_t>(y) * r.image.width + x];
}

TEST(Adaptive, SameImageAndSamplesForAnyThreadCount) {
    for (const std::string sampler : {"random", "stratified", "sobol"}) {
        const Scene scene = edge_scene(sampler, 64);
        const RenderResult one = render(scene, adaptive(0.01, 8, 1));
        for (const int threads : {2, 3, 7}) {
            const RenderResult many = render(scene, adaptive(0.01, 8, threads));
            EXPECT_EQ(many.image.rgb, one.image.rgb) << sampler << " " << threads;
            EXPECT_EQ(many.pixel_samples, one.pixel_samples) << sampler << " " << threads;
            EXPECT_EQ(many.stats.samples, one.stats.samples);
        }
    }
}

TEST(Adaptive, FlatPixelsStopAtTheMinimumAndEdgesTakeMore) {
    for (const std::string sampler : {"random", "stratified", "sobol"}) {
        const Scene scene = edge_scene(sampler, 256);
        const RenderResult r = render(scene, adaptive(0.005, 16));
        // The sphere's centre and the image corners are flat.
        EXPECT_EQ(samples_at(r, 16, 16), 16u) << sampler;
        EXPECT_EQ(samples_at(r, 0, 0), 16u) << sampler;
        EXPECT_EQ(samples_at(r, 31, 31), 16u) << sampler;
        // Somewhere along the edge the luminance jumps by 0.6: 16 samples cannot reach 0.005.
        const std::uint32_t most =
            *std::max_element(r.pixel_samples.begin(), r.pixel_samples.end());
        EXPECT_GT(most, 16u) << sampler;
        std::size_t edge_pixels = 0;
        for (const std::uint32_t n : r.pixel_samples) {
            EXPECT_GE(n, 16u);
            EXPECT_LE(n, 256u);
            edge_pixels += n > 16;
        }
        // The circle is about 27 pixels across: its rim crosses some 80 pixels, not the whole
        // image.
        EXPECT_GT(edge_pixels, 40u) << sampler;
        EXPECT_LT(edge_pixels, 200u) << sampler;
        EXPECT_EQ(r.stats.samples, std::accumulate(r.pixel_samples.begin(), r.pixel_samples.end(),
                                                   std::uint64_t{0}));
        const auto at_max = std::count(r.pixel_samples.begin(), r.pixel_samples.end(), 256u);
        EXPECT_EQ(r.stats.pixels_converged, r.pixel_samples.size() - at_max) << sampler;
        ASSERT_TRUE(r.stats.adaptive);
        EXPECT_EQ(r.stats.adaptive->min_samples, 16);
    }
}

// Rounds double the count: 16, 32, 64, ...; a smaller threshold never takes fewer samples.
TEST(Adaptive, SamplesComeInDoublingRoundsAndGrowAsTheThresholdFalls) {
    const Scene scene = edge_scene("stratified", 200);
    const RenderResult loose = render(scene, adaptive(0.02, 16));
    const RenderResult tight = render(scene, adaptive(0.002, 16));
    for (std::size_t i = 0; i < loose.pixel_samples.size(); ++i) {
        const std::uint32_t n = loose.pixel_samples[i];
        EXPECT_TRUE(n == 16 || n == 32 || n == 64 || n == 128 || n == 200) << n;
        EXPECT_GE(tight.pixel_samples[i], n);
    }
    EXPECT_GT(tight.stats.samples, loose.stats.samples);
}

// A pixel that stops at the minimum holds exactly what a plain render at the minimum gives it,
// and with the extensible Sobol sampler a pixel that runs to the maximum holds exactly what a
// plain render at the maximum gives it.
TEST(Adaptive, PixelsMatchPlainRendersAtTheCountTheyStoppedAt) {
    for (const std::string sampler : {"stratified", "sobol"}) {
        Scene scene = edge_scene(sampler, 64);
        const RenderResult r = render(scene, adaptive(0.01, 16));
        scene.settings.samples = 16;
        const RenderResult at_min = render(scene, {});
        scene.settings.samples = 64;
        const RenderResult at_max = render(scene, {});
        int compared_min = 0, compared_max = 0;
        for (int y = 0; y < 32; ++y) {
            for (int x = 0; x < 32; ++x) {
                const std::uint32_t n = samples_at(r, x, y);
                if (n == 16) {
                    EXPECT_EQ(r.image.at(x, y), at_min.image.at(x, y)) << sampler << x << "," << y;
                    ++compared_min;
                } else if (n == 64 && sampler == "sobol") {
                    EXPECT_EQ(r.image.at(x, y), at_max.image.at(x, y)) << x << "," << y;
                    ++compared_max;
                }
            }
        }
        EXPECT_GT(compared_min, 500) << sampler;
        if (sampler == "sobol") {
            EXPECT_GT(compared_max, 10);
        }
    }
}

// Independent samples are judged by their sample deviation; an extensible sampler's by the
// spread of the means of 8 consecutive runs, each run a stratified pattern, which credits
// stratification: at the same threshold edges stop far earlier, yet the image is more accurate.
TEST(Adaptive, StratificationIsCreditedForAnExtensibleSampler) {
    Scene scene = edge_scene("sobol", 4096);
    scene.settings.seed = 11;
    const Image reference = render(scene, {}).image;
    const auto error = [&](const Image& image) {
        double sum = 0;
        for (std::size_t i = 0; i < image.rgb.size(); ++i) {
            sum += (image.rgb[i] - reference.rgb[i]) * (image.rgb[i] - reference.rgb[i]);
        }
        return std::sqrt(sum / image.rgb.size());
    };
    const RenderResult random = render(edge_scene("random", 1024), adaptive(0.005, 16));
    const RenderResult sobol = render(edge_scene("sobol", 1024), adaptive(0.005, 16));
    EXPECT_LT(sobol.stats.samples, random.stats.samples * 6 / 10);  // measured: 0.49
    EXPECT_LT(error(sobol.image), error(random.image));
}

TEST(Adaptive, MinimumAboveTheMaximumTakesTheMaximumEverywhere) {
    const Scene scene = edge_scene("stratified", 8);
    const RenderResult r = render(scene, adaptive(1.0, 64));
    EXPECT_EQ(r.stats.samples, 8u * 32 * 32);
    EXPECT_EQ(r.stats.adaptive->min_samples, 8);
    EXPECT_EQ(r.image.rgb, render(scene, {}).image.rgb);
}

TEST(Adaptive, PlainRendersCountTheirSamplesAndKeepNoMap) {
    const Scene scene = edge_scene("random", 4);
    const RenderResult r = render(scene, {});
    EXPECT_EQ(r.stats.samples, 4u * 32 * 32);
    EXPECT_EQ(r.stats.pixels_converged, 0u);
    EXPECT_FALSE(r.stats.adaptive);
    EXPECT_TRUE(r.pixel_samples.empty());
}

}  // namespace
}  // namespace drt
