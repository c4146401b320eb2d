#include "drt/scene/render_limits.h"
#include "drt/util/limits.h"

#include <gtest/gtest.h>

#include <string>

namespace drt {
namespace {

RenderSettings small() {
    RenderSettings s;
    s.width = 24, s.height = 16, s.samples = 4;
    return s;
}

std::string problem(const RenderSettings& s, int threads = 2) {
    return render_limit_problem(s, threads).value_or("");
}

TEST(Limits, PixelLimitIsTheLargestPowerOfTwoWithinTheBudget) {
    EXPECT_LE(kMaxPixels * kBytesPerPixel, kMemoryBudget);
    EXPECT_GT(2 * kMaxPixels * kBytesPerPixel, kMemoryBudget);
}

TEST(Limits, EstimateCountsPixelsAndEachThreadsSamples) {
    RenderSettings s = small();
    EXPECT_EQ(estimated_render_bytes(s, 3), 24u * 16 * 28 + 3u * 4 * 576);
}

// AOV channels (--aov) add to every pixel's memory, and so to what a checkpoint of the image
// holds: the largest image with all seven is refused, naming them; with none it renders.
TEST(Limits, AovChannelsCountInEveryPixel) {
    RenderSettings s = small();
    EXPECT_EQ(estimated_render_bytes(s, 3, 7), 24u * 16 * (28 + 7 * 8) + 3u * 4 * 576);
    s.width = 16384, s.height = 8192, s.samples = 1;
    EXPECT_FALSE(render_limit_problem(s, 2, 0));
    EXPECT_EQ(render_limit_problem(s, 2, 7).value_or(""),
              "the render needs an estimated 10752 MiB (134217728 pixels x (28 + 7 AOV channels x "
              "8) B + 2 threads x 1 samples x 576 B), more than the 4096 MiB budget");
    s.height = 4096;  // half the pixels: with one channel within the budget
    EXPECT_FALSE(render_limit_problem(s, 2, 1));
}

TEST(Limits, ImageSideAtAndPastTheLimit) {
    RenderSettings s = small();
    s.width = 65536, s.height = 1;
    EXPECT_EQ(problem(s), "");
    s.width = 65537;
    EXPECT_EQ(problem(s), "image size 65537x1 exceeds the limit of 65536 pixels a side");
    s.width = 1, s.height = 65537;
    EXPECT_EQ(problem(s), "image size 1x65537 exceeds the limit of 65536 pixels a side");
}

TEST(Limits, PixelCountAtAndPastTheLimit) {
    RenderSettings s = small();
    s.width = 16384, s.height = 8192, s.samples = 1;
    EXPECT_EQ(problem(s), "");
    s.width = 16385;
    EXPECT_EQ(problem(s),
              "image size 16385x8192 (134225920 pixels) exceeds the limit of 134217728 pixels");
}

TEST(Limits, CountsAtAndPastTheirLimits) {
    RenderSettings s = small();
    s.samples = 65536, s.shadow_rays = 65536, s.glossy_rays = 65536, s.max_depth = 512;
    EXPECT_EQ(problem(s), "");
    RenderSettings t = s;
    t.samples = 65537;
    EXPECT_EQ(problem(t), "samples per pixel 65537 exceeds the limit of 65536");
    t = s, t.shadow_rays = 65537;
    EXPECT_EQ(problem(t), "shadow rays 65537 exceeds the limit of 65536");
    t = s, t.glossy_rays = 65537;
    EXPECT_EQ(problem(t), "glossy rays 65537 exceeds the limit of 65536");
    t = s, t.max_depth = 513;
    EXPECT_EQ(problem(t), "max depth 513 exceeds the limit of 512");
}

TEST(Limits, MemoryBudgetCountsThreads) {
    // The largest image with the most samples fits on a few threads, not on many.
    RenderSettings s = small();
    s.width = 16384, s.height = 8192, s.samples = 65536;
    EXPECT_EQ(problem(s, 14), "");
    EXPECT_EQ(problem(s, 15),
              "the render needs an estimated 4124 MiB (134217728 pixels x 28 B + 15 threads x "
              "65536 samples x 576 B), more than the 4096 MiB budget");
    EXPECT_LE(estimated_render_bytes(s, 14), kMemoryBudget);
    EXPECT_GT(estimated_render_bytes(s, 15), kMemoryBudget);
}

}  // namespace
}  // namespace drt
