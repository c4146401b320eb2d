// Golden-image regression tests (docs/testing.md): every scene in scenes/ rendered small at a
// fixed seed must agree with its reference in tests/golden/ within noise, block by block. On a
// failure the scene joins the report page golden-diffs/index.html in the build folder (reference,
// render, difference, measures), whose path the failure message gives.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "drt/io/compare.h"
#include "drt/io/report.h"
#include "golden.h"

namespace drt {
namespace {

namespace fs = std::filesystem;

// A reference of 64 renders of a flat grey square of the given size and per-pixel variance.
golden::Reference flat_reference(int size, float variance) {
    golden::Reference r;
    r.renders = 64;
    r.mean = Image(size, size);
    r.variance = Image(size, size);
    std::fill(r.mean.rgb.begin(), r.mean.rgb.end(), 0.5f);
    std::fill(r.variance.rgb.begin(), r.variance.rgb.end(), variance);
    return r;
}

const fs::path kScenes = fs::path(DRT_SOURCE_DIR) / "scenes";
const fs::path kGolden = fs::path(DRT_SOURCE_DIR) / "tests" / "golden";
const fs::path kDiffs = DRT_GOLDEN_DIFF_DIR;
constexpr const char* kReportTitle = "drt golden tests: failing scenes";

fs::path without_extension(fs::path p) {
    return p.replace_extension();
}

class Golden : public ::testing::TestWithParam<fs::path> {};

TEST_P(Golden, MatchesItsReferenceWithinNoise) {
    const fs::path scene = GetParam();
    const fs::path base = kGolden / without_extension(scene);
    const fs::path diff_base = kDiffs / without_extension(scene);
    for (const char* suffix : {".render.pfm", ".z.png"}) {
        fs::remove(diff_base.string() + suffix);  // nothing stale from an earlier failure
    }

    golden::Reference reference;
    try {
        reference = golden::load_reference(base);
    } catch (const std::exception& e) {
        FAIL() << "no golden reference for scenes/" << scene.string() << " (" << e.what()
               << "): run tools/refresh-goldens.sh " << scene.string();
    }
    const Image render = golden::render(kScenes / scene, reference.args, golden::kTestSeed,
                                        fs::temp_directory_path());
    ASSERT_EQ(render.width, reference.mean.width) << "the golden's options no longer give its size";
    ASSERT_EQ(render.height, reference.mean.height);

    const golden::Verdict verdict = golden::check(render, reference);
    EXPECT_EQ(verdict.nonfinite, 0) << "NaN or infinite pixels in scenes/" << scene.string();
    const std::string name = without_extension(scene).string();
    if (verdict.pass) {
        remove_report_case(kDiffs, kReportTitle, name);
        return;
    }
    fs::create_directories(diff_base.parent_path());
    write_image(render, diff_base.string() + ".render.pfm");
    write_image(golden::z_image(verdict), diff_base.string() + ".z.png");
    // The report shares the page with every other failing scene's, worst first.
    ReportCase c = compare_case(name, (base.string() + ".pfm"), diff_base.string() + ".render.pfm",
                                reference.mean, render, true);
    c.failed = true;
    c.note = verdict.summary() +
             "\nz map (each 4 x 4 block by its |z|, red at the bound): " + diff_base.string() +
             ".z.png";
    const fs::path page = add_report_case(kDiffs, kReportTitle, c);
    ADD_FAILURE() << "scenes/" << scene.string() << " no longer matches tests/golden/" << name
                  << ".pfm: " << verdict.summary() << "\n  report: " << page.string()
                  << "\n  if the change is intended, run tools/refresh-goldens.sh "
                  << scene.string() << " and commit what it prints";
}

std::string test_name(const ::testing::TestParamInfo<fs::path>& info) {
    std::string name = without_extension(info.param).string();
    for (char& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    }
    return name;
}

INSTANTIATE_TEST_SUITE_P(Scenes, Golden, ::testing::ValuesIn(golden::scene_files(kScenes)),
                         test_name);

// Every reference belongs to a scene: a renamed or removed scene takes its golden with it.
TEST(GoldenFiles, EveryReferenceHasAScene) {
    int references = 0;
    for (const auto& entry : fs::recursive_directory_iterator(kGolden)) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file() || !name.ends_with(".txt")) continue;
        ++references;
        fs::path scene = fs::relative(entry.path(), kGolden);
        scene.replace_extension(".xml");
        EXPECT_TRUE(fs::exists(kScenes / scene))
            << entry.path().string() << " has no scene scenes/" << scene.string();
    }
    EXPECT_EQ(references, static_cast<int>(golden::scene_files(kScenes).size()));
}

// The test itself: it must pass the reference's own mean and catch a small, uniform change,
// and it must not be fooled by a NaN.
TEST(GoldenCheck, AcceptsTheMeanAndRejectsAShiftOfAFewStandardErrors) {
    const golden::Reference r = flat_reference(32, 0.01f);  // σ = 0.1 per pixel
    EXPECT_TRUE(golden::check(r.mean, r).pass);

    // The whole image 0.012 brighter in red: u = 0.012 / sqrt(0.01 · (1 + 1/64) + (1e-3 · 0.5 +
    // 1e-4)²) per pixel, z = u · sqrt(1024) = 3.81 for the whole image: below the bound of 6.
    Image shifted = r.mean;
    for (std::size_t i = 0; i < shifted.rgb.size(); i += 3) shifted.rgb[i] += 0.012f;
    golden::Verdict v = golden::check(shifted, r);
    EXPECT_TRUE(v.pass);
    EXPECT_NEAR(v.max_abs_z, 0.012 / std::sqrt(0.01 * (1 + 1.0 / 64) + 3.6e-7) * 32, 1e-3);
    EXPECT_EQ(v.block, 32);
    EXPECT_EQ(v.channel, 0);

    // 0.02: z = 6.35 over the whole image; no smaller block reaches the bound.
    for (std::size_t i = 0; i < shifted.rgb.size(); i += 3) shifted.rgb[i] += 0.008f;
    v = golden::check(shifted, r);
    EXPECT_FALSE(v.pass);
    EXPECT_EQ(v.failing_blocks, 1);

    Image nan = r.mean;
    nan.rgb[100] = std::numeric_limits<float>::quiet_NaN();
    v = golden::check(nan, r);
    EXPECT_FALSE(v.pass);
    EXPECT_EQ(v.nonfinite, 1);
}

TEST(GoldenCheck, DeterministicPixelsMayOnlyMoveByRounding) {
    const golden::Reference r = flat_reference(8, 0);  // zero variance: every render agreed
    Image close = r.mean;
    for (float& v : close.rgb) v += 1e-5f;  // float rounding of 0.5 is 3e-8; this is 300 times more
    EXPECT_TRUE(golden::check(close, r).pass);

    // A 3 × 3 patch 2 % brighter in red: each pixel is 0.01 / 6e-4 = 17 σ off, clipped to 5, so
    // the 4 × 4 block holding it has z = 9 · 5 / 4 = 11.25.
    Image patch = r.mean;
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 3; ++x) patch.rgb[3 * (y * 8 + x)] += 0.01f;
    }
    const golden::Verdict v = golden::check(patch, r);
    EXPECT_FALSE(v.pass);
    EXPECT_DOUBLE_EQ(v.max_abs_z, 11.25);
    EXPECT_EQ(v.block, 4);

    // One pixel alone is below the test's resolution: 5 / 4 at most.
    Image one = r.mean;
    one.rgb[0] += 0.01f;
    EXPECT_TRUE(golden::check(one, r).pass);
}

// Noise added per pixel from a fixed stream: Gaussian with standard deviation `sigma`.
Image noisy(const Image& mean, double sigma, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal(0.0, sigma);
    Image image = mean;
    for (float& v : image.rgb) v += static_cast<float>(normal(rng));
    return image;
}

TEST(GoldenCheck, ToleratesANoisierEstimatorButNotAShiftHiddenInIt) {
    const golden::Reference r = flat_reference(64, 0.01f);  // σ = 0.1 per pixel

    const golden::Verdict same = golden::check(noisy(r.mean, 0.1, 1), r);
    EXPECT_TRUE(same.pass) << same.summary();
    EXPECT_NEAR(same.noise_scale, 1.0, 0.1);

    // Twice the noise: the finest blocks spread twice as wide and the test allows for it.
    const Image twice = noisy(r.mean, 0.2, 2);
    const golden::Verdict noisier = golden::check(twice, r);
    EXPECT_TRUE(noisier.pass) << noisier.summary();
    EXPECT_NEAR(noisier.noise_scale, 2.0, 0.2);

    // The same noise over an 8 × 8 patch made 0.2 brighter in green (1 σ of the reference, 0.5 σ
    // of this noise per pixel): z ≈ 0.2 / 0.1 · 8 / 2 = 8 once scaled.
    Image shifted = twice;
    for (int y = 16; y < 24; ++y) {
        for (int x = 40; x < 48; ++x) shifted.rgb[3 * (y * 64 + x) + 1] += 0.2f;
    }
    const golden::Verdict v = golden::check(shifted, r);
    EXPECT_FALSE(v.pass) << v.summary();
    EXPECT_EQ(v.channel, 1);
    EXPECT_NEAR(v.noise_scale, 2.0, 0.2);
}

TEST(GoldenCheck, AccumulatorGivesMeanAndUnbiasedVariance) {
    golden::Accumulator sum;
    for (const float v : {1.0f, 2.0f, 6.0f}) {
        Image image(1, 1);
        std::fill(image.rgb.begin(), image.rgb.end(), v);
        sum.add(image);
    }
    const golden::Reference r = sum.result({"--spp", "2"});
    EXPECT_EQ(r.renders, 3);
    EXPECT_FLOAT_EQ(r.mean.rgb[0], 3.0f);
    EXPECT_FLOAT_EQ(r.variance.rgb[0], 7.0f);  // ((1-3)² + (2-3)² + (6-3)²) / 2
}

}  // namespace
}  // namespace drt
