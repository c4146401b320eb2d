#include "drt/goal/converge.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "drt/cli/cli.h"
#include "test_scenes.h"

namespace drt {
namespace {

namespace fs = std::filesystem;

// Antialiasing is the only integral: a flat-coloured sphere (ambient light only, no lights)
// against a flat background, so every pixel's error comes from how its area is sampled across
// the sphere's edge.
Scene edge_scene(const std::string& sampler) {
    Scene scene = testing::lone_sphere_scene(testing::grey_lambert(0.8), {0.1, 0.2, 0.3}, 32);
    scene.ambient = {1, 1, 1};
    scene.settings.sampler = sampler;
    return scene;
}

Image reference_for(const std::string& sampler) {
    Scene scene = edge_scene(sampler);
    return render(scene, request_at(2048, 99, {}), {}).image;
}

TEST(Converge, RmseAndRelativeMseOfKnownImages) {
    Image a(2, 1), b(2, 1);
    a.set(0, 0, {0.5, 0.5, 0.5});
    a.set(1, 0, {1, 1, 1});
    b.set(0, 0, {0.5, 0.5, 0.5});
    b.set(1, 0, {0, 0, 0});
    // Three of six channels differ by 1.
    EXPECT_DOUBLE_EQ(rmse(a, b), std::sqrt(0.5));
    // Against b: 1 / (0 + 0.01) for three channels of six. Against a: 1 / (1 + 0.01).
    EXPECT_NEAR(relative_mse(a, b), 3 * 100.0 / 6, 1e-9);
    EXPECT_NEAR(relative_mse(b, a), 3 / 1.01 / 6, 1e-9);
    EXPECT_EQ(rmse(a, a), 0);
    EXPECT_THROW(rmse(a, Image(1, 2)), ImageError);
    EXPECT_THROW(relative_mse(a, Image(2, 2)), ImageError);
}

TEST(Converge, LogLogSlopeOfAPowerLaw) {
    const std::vector<double> x = {1, 4, 16, 64, 256};
    std::vector<double> y, z;
    for (const double v : x) y.push_back(3 / std::sqrt(v)), z.push_back(0.2 * std::pow(v, -0.75));
    EXPECT_NEAR(loglog_slope(x, y), -0.5, 1e-12);
    EXPECT_NEAR(loglog_slope(x, z), -0.75, 1e-12);
    // Zero or negative values cannot be logged and are left out.
    y.push_back(0);
    std::vector<double> x2 = x;
    x2.push_back(1024);
    EXPECT_NEAR(loglog_slope(x2, y), -0.5, 1e-12);
    EXPECT_TRUE(std::isnan(loglog_slope({4}, {1})));
    EXPECT_TRUE(std::isnan(loglog_slope({4, 4}, {1, 2})));
}

TEST(Converge, ParsesCountLists) {
    EXPECT_EQ(parse_counts("1,4,16"), (std::vector<int>{1, 4, 16}));
    EXPECT_EQ(parse_counts("7"), (std::vector<int>{7}));
    EXPECT_EQ(parse_counts("1,65536"), (std::vector<int>{1, 65536}));  // kMaxSamples
    for (const char* bad : {"", "1,,4", "1,4,", "0", "-1", "1.5", "4x", "99999999999", "65537"}) {
        EXPECT_THROW(parse_counts(bad), std::invalid_argument) << bad;
    }
    try {
        parse_counts("1,x,4");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "'x' in '1,x,4' is not a sample count from 1 to 65536");
    }
}

TEST(Converge, DefaultReferenceIsSixteenTimesTheLargestCountWithAnotherSeed) {
    EXPECT_EQ(default_reference_spp({1, 4, 256, 16}), 4096);
    // Capped at kMaxSamples, computed without overflow (16 x 2^31 - 1 wrapped before).
    EXPECT_EQ(default_reference_spp({4096}), 65536);
    EXPECT_EQ(default_reference_spp({4097}), 65536);
    EXPECT_EQ(default_reference_spp({2147483647}), 65536);
    EXPECT_EQ(reference_seed(0), 1u);
    EXPECT_EQ(reference_seed(41), 42u);
}

TEST(Converge, MeasuresEachCountAndRestoresTheScene) {
    Scene scene = edge_scene("stratified");
    scene.settings.samples = 3;
    scene.settings.seed = 5;
    const Image reference = reference_for("stratified");
    std::vector<int> seen;
    const Convergence c =
        measure_convergence(scene, {1, 4, 16}, reference, {},
                            [&](const ConvergencePoint& p) { seen.push_back(p.spp); });
    EXPECT_EQ(seen, (std::vector<int>{1, 4, 16}));
    ASSERT_EQ(c.points.size(), 3u);
    EXPECT_EQ(scene.settings.samples, 3);
    EXPECT_EQ(scene.settings.seed, 5u);
    // Each point is the error of a plain render with the scene's seed at that count.
    const Image at4 = render(scene, request_at(4, 5, {}), {}).image;
    EXPECT_EQ(c.points[1].rmse, rmse(at4, reference));
    EXPECT_EQ(c.points[1].relmse, relative_mse(at4, reference));
    EXPECT_EQ(c.points[1].mean_spp, 4);
    EXPECT_GT(c.points[1].seconds, 0);
    EXPECT_GT(c.points[2].cpu_seconds, 0);
    Image wrong(31, 32);
    EXPECT_THROW(measure_convergence(scene, {1}, wrong, {}), ImageError);
}

// What outside checks require: on an antialiasing-only scene the RMSE of independent samples
// falls at least as fast as N^-1/2, and stratified and Sobol samples fall clearly faster
// (N^-3/4 in theory for an edge) and beat independent ones at equal samples.
TEST(Converge, ErrorFallsAsMonteCarloTheorySaysForEverySampler) {
    const Image reference = reference_for("sobol");
    const std::vector<int> counts = {1, 4, 16, 64, 256};
    Convergence by[3];
    const char* names[3] = {"random", "stratified", "sobol"};
    for (int i = 0; i < 3; ++i) {
        Scene scene = edge_scene(names[i]);
        by[i] = measure_convergence(scene, counts, reference, {});
    }
    const Convergence &random = by[0], &stratified = by[1], &sobol = by[2];
    // 1 spp takes the pixel centre in every sampler: the same image, left out of the slopes.
    EXPECT_FALSE(random.points[0].fitted);
    EXPECT_EQ(random.points[0].rmse, sobol.points[0].rmse);
    EXPECT_TRUE(random.points[1].fitted);
    // Measured: -0.53, -0.79 and -0.75.
    EXPECT_LE(random.slope_vs_spp, -0.45);
    EXPECT_GE(random.slope_vs_spp, -0.6);  // independent samples cannot beat N^-1/2 by much
    EXPECT_LE(stratified.slope_vs_spp, -0.65);
    EXPECT_LE(sobol.slope_vs_spp, -0.65);
    for (std::size_t i = 1; i < counts.size(); ++i) {
        EXPECT_LT(stratified.points[i].rmse, 0.75 * random.points[i].rmse) << counts[i];
        EXPECT_LT(sobol.points[i].rmse, 0.75 * random.points[i].rmse) << counts[i];
    }
}

struct CliRun {
    int status;
    std::string out, err;
};

CliRun run(std::vector<std::string> args) {
    args.insert(args.begin(), "drt");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    std::ostringstream out, err;
    const int status = run_cli(static_cast<int>(argv.size()), argv.data(), out, err);
    return {status, out.str(), err.str()};
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ConvergeCli, PrintsOneRowPerCountAndWritesTheCsv) {
    const fs::path dir = fs::temp_directory_path() / ("drt_converge_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string scene = std::string(DRT_SOURCE_DIR) + "/scenes/figures/aa-10spp.xml";
    const CliRun r = run({"converge", scene, "--scale", "0.05", "--spp", "2,8", "--sampler",
                          "sobol", "--seed", "7", "--csv", (dir / "c.csv").string(),
                          "--save-reference", (dir / "ref.pfm").string(), "--threads", "2"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("20x15, sampler sobol, seed 7"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("reference: 128 spp, seed 8"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("slope of log RMSE against log samples: -"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("slope of log RMSE against log seconds: "), std::string::npos) << r.out;
    const std::string csv = read_text(dir / "c.csv");
    ASSERT_EQ(csv.rfind("spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,estimated_rmse,"
                        "estimated_relmse\n2,",
                        0),
              0u)
        << csv;
    EXPECT_NE(csv.find("\n8,"), std::string::npos) << csv;
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;

    // The saved reference is the image measured against: given back, the rows are the same.
    const fs::path csv2 = dir / "c2.csv";
    const CliRun again =
        run({"converge", scene, "--scale", "0.05", "--spp", "2,8", "--sampler", "sobol", "--seed",
             "7", "--csv", csv2.string(), "--reference", (dir / "ref.pfm").string()});
    ASSERT_EQ(again.status, 0) << again.err;
    const auto rmse_column = [](const std::string& text) {
        std::vector<std::string> values;
        std::istringstream lines(text);
        std::string line;
        std::getline(lines, line);
        while (std::getline(lines, line)) {
            std::istringstream fields(line);
            std::string f;
            for (int i = 0; i < 3; ++i) std::getline(fields, f, ',');
            values.push_back(f);
        }
        return values;
    };
    EXPECT_EQ(rmse_column(read_text(csv2)), rmse_column(csv));

    // The same reference as an OpenEXR file measures the same.
    write_image(read_image(dir / "ref.pfm"), dir / "ref.exr");
    const CliRun exr =
        run({"converge", scene, "--scale", "0.05", "--spp", "2,8", "--sampler", "sobol", "--seed",
             "7", "--csv", csv2.string(), "--reference", (dir / "ref.exr").string()});
    ASSERT_EQ(exr.status, 0) << exr.err;
    EXPECT_EQ(rmse_column(read_text(csv2)), rmse_column(csv));
    fs::remove_all(dir);
}

TEST(ConvergeCli, RefusesBadInput) {
    const std::string scene = std::string(DRT_SOURCE_DIR) + "/scenes/figures/aa-10spp.xml";
    CliRun r = run({"converge", scene, "--spp", "1,0,4"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("'0' in '1,0,4' is not a sample count from 1 to 65536"), std::string::npos)
        << r.err;
    r = run({"converge", scene, "--reference", "ref.png"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("ref.png: the reference must be a linear .pfm or .exr image"),
              std::string::npos)
        << r.err;
    r = run({"converge", scene, "--reference", "/nonexistent/ref.pfm", "--scale", "0.05"});
    EXPECT_EQ(r.status, 2);
    r = run({"converge", scene, "--min-spp", "4"});  // needs --noise-threshold
    EXPECT_EQ(r.status, 2);
    r = run({"converge", "/nonexistent.xml"});
    EXPECT_EQ(r.status, 2);
    // Files with nowhere to go, before anything renders; a reference given, and one to render.
    r = run({"converge", scene, "--csv", "/nonexistent/c.csv", "--scale", "0.05"});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("/nonexistent/c.csv: cannot create file"), std::string::npos) << r.err;
    r = run({"converge", scene, "--save-reference", "/nonexistent/r.pfm", "--scale", "0.05"});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.out, "");
    r = run({"converge", scene, "--reference", "r.pfm", "--reference-spp", "3"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--reference excludes --reference-spp"), std::string::npos) << r.err;
    r = run({"converge", scene, "--reference", "r.pfm", "--save-reference", "s.pfm"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--reference excludes --save-reference"), std::string::npos) << r.err;
}

TEST(Converge, MeasuredReachInterpolatesLogLogBetweenTheCountsAroundTheTarget) {
    Convergence c;
    // 1 spp (pixel centres) is left out even though it is below every target here.
    const auto point = [](int spp, double seconds, double rmse, bool fitted) {
        ConvergencePoint p;
        p.spp = spp, p.seconds = seconds, p.rmse = rmse, p.fitted = fitted;
        return p;
    };
    c.points = {point(1, 0.1, 0.0001, false), point(4, 1, 0.04, true), point(16, 4, 0.02, true),
                point(64, 16, 0.01, true)};
    // Halfway (in log) between 0.02 and 0.01: halfway between 16 and 64 spp, 4 and 16 s.
    const auto mid = measured_reach(c, 0.01 * std::sqrt(2.0));
    ASSERT_TRUE(mid);
    EXPECT_NEAR(mid->spp, 32, 1e-9);
    EXPECT_NEAR(mid->seconds, 8, 1e-9);
    const auto first = measured_reach(c, 0.05);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->spp, 4);
    EXPECT_EQ(first->seconds, 1);
    EXPECT_FALSE(measured_reach(c, 0.001));
    // The counts listed largest first: the same reach.
    std::reverse(c.points.begin(), c.points.end());
    EXPECT_NEAR(measured_reach(c, 0.01 * std::sqrt(2.0))->spp, 32, 1e-9);
    EXPECT_EQ(measured_reach(c, 0.05)->spp, 4);
}

// Path tracing is unbiased: its error against a converged reference falls as N^-1/2 for
// independent samples, with no floor where a bias would show. The Cornell box at 32 x 32 pixels
// against 2048 spp of another seed, whose own error (its squared RMSE is 4/2048 of the 4-spp
// image's) is taken out of each point. Measured: -0.53 (-0.44 from 4 to 16 spp, -0.62 from 16 to
// 64: bright rare paths move one point a lot, so the fit takes three).
TEST(Converge, PathTracedErrorFallsAsOneOverTheSquareRootOfSamples) {
    Scene scene = testing::scaled_scene("gi/cornell-box.xml", 32, 1);
    scene.settings.sampler = "random";
    const Image reference = render(scene, request_at(2048, 1000, {}), {}).image;
    const Convergence c = measure_convergence(scene, {4, 16, 64}, reference, {});
    const double reference2 = c.points[0].rmse * c.points[0].rmse * 4 / 2048;
    std::vector<double> spp, error;
    for (const ConvergencePoint& p : c.points) {
        spp.push_back(p.spp);
        error.push_back(std::sqrt(p.rmse * p.rmse - reference2));
    }
    EXPECT_NEAR(loglog_slope(spp, error), -0.5, 0.04);
}

}  // namespace
}  // namespace drt
