// Rendering to a goal (goal_render.h): the prediction's arithmetic, and --target-error and
// --time-limit as a user runs them.
#include "drt/goal/goal_render.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "drt/goal/converge.h"
#include "drt/io/image.h"
#include "drt/job/render_job.h"
#include "drt/scene/scene_loader.h"
#include "regex_match.h"
#include "run_drt.h"
#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;
using test::Outcome;
using test::read_bytes;
using test::regex_all_groups;
using test::regex_groups;
using test::run_drt;

// The combined estimate of rounds weighted by round_weight: 1 / c^2 = sum of 1 / e^2.
double combined(std::initializer_list<double> errors) {
    double inverse = 0;
    for (const double e : errors) inverse += 1 / (e * e);
    return 1 / std::sqrt(inverse);
}

// The whole image at `spp` samples and `seed`: a round rendered alone.
RenderRequest alone_at(int spp, std::uint64_t seed) {
    RenderRequest request;
    request.samples = spp;
    request.seed = seed;
    return request;
}

// The error one more round must have for rounds combined to `c` to reach 98 % of `target`.
double wanted(double target, double c) {
    const double goal = 0.98 * target;
    return 1 / std::sqrt(1 / (goal * goal) - 1 / (c * c));
}

TEST(RoundWeight, TheInverseOfTheEstimatedVarianceOrTheCount) {
    EXPECT_DOUBLE_EQ(round_weight(0.01, 8), 1e4);
    EXPECT_DOUBLE_EQ(round_weight(0.5, 8), 4.0);
    EXPECT_DOUBLE_EQ(round_weight(std::nullopt, 8), 8.0);
    EXPECT_DOUBLE_EQ(round_weight(0.0, 12), 12.0);
}

TEST(RoundSeed, TheFirstRoundsIsTheScenesAndTheOthersDiffer) {
    EXPECT_EQ(round_seed(3, 0), 3u);
    EXPECT_NE(round_seed(3, 1), 3u);
    EXPECT_NE(round_seed(3, 1), 4u);  // not the next seed, which references often take
    EXPECT_NE(round_seed(3, 1), round_seed(3, 2));
    EXPECT_NE(round_seed(3, 1), round_seed(4, 1));
    EXPECT_EQ(round_seed(3, 2), round_seed(3, 2));
}

TEST(Predict, FromOneRoundAlongTheSteepestSlope) {
    // One pilot at 0.04 against a target of 0.01: one more round must have the error
    // 1 / sqrt(1 / 0.0098^2 - 1 / 0.04^2) = 0.010108, which along -1 is 8 * 0.04 / 0.010108 =
    // 31.66 samples.
    const std::vector<GoalRound> one{{8, 1.0, 0.04, 0.04}};
    const auto p = predict(one, 0.01, 65536);
    ASSERT_TRUE(p);
    EXPECT_NEAR(8 * 0.04 / wanted(0.01, 0.04), 31.66, 0.01);
    EXPECT_EQ(p->spp, 32);
    EXPECT_DOUBLE_EQ(p->seconds, 32 / 8.0);
    // Along -1/2 instead: 8 * (0.04 / 0.010108)^2 = 125.3.
    EXPECT_EQ(predict(one, 0.01, 65536, -0.5)->spp, 126);
    // Met already, or no samples left: nothing more; capped at what is left of the maximum.
    EXPECT_EQ(predict(one, 0.05, 65536)->spp, 0);
    EXPECT_EQ(predict(one, 0.01, 9)->spp, 0);
    EXPECT_EQ(predict(one, 0.01, 20)->spp, 12);
    // Rounds without an estimate are skipped.
    EXPECT_EQ(predict({{4, 1, std::nullopt, std::nullopt}, {8, 1, 0.04, 0.04}}, 0.01, 65536)->spp,
              32);
}

TEST(Predict, TakesTheSlopeOverAtLeastThreefoldTheSamplesHeldBetweenMinusOneAndAQuarter) {
    // 8 to 32 samples, error 0.08 to 0.04: slope -1/2, and the two combine to 0.0358. The next
    // round needs the error wanted(0.01, 0.0358) = 0.0102: 32 * (0.04 / 0.0102)^2 = 493.1.
    const double c = combined({0.08, 0.04});
    EXPECT_NEAR(c, 0.0358, 1e-4);
    const std::vector<GoalRound> rounds{{8, 1.0, 0.08, std::nullopt}, {32, 2.5, 0.04, c}};
    const auto p = predict(rounds, 0.01, 65536);
    ASSERT_TRUE(p);
    EXPECT_NEAR(32 * std::pow(0.04 / wanted(0.01, c), 2), 493.1, 0.1);
    EXPECT_EQ(p->spp, 494);
    // Time: 0.5 s of set-up and 1.5 s / 24 samples = 0.0625 s a sample.
    EXPECT_DOUBLE_EQ(p->seconds, 0.5 + 0.0625 * 494);
    // A flat pair (slope 0) is taken as -1/4: 32 * (0.08 / wanted(0.02, 0.0566))^4 = 6877.04.
    const double flat = combined({0.08, 0.08});
    EXPECT_EQ(predict({{8, 1, 0.08, std::nullopt}, {32, 2, 0.08, flat}}, 0.02, 65536)->spp, 6878);
    // A slope of -2 (luck) is taken as -1: 32 * 0.01 / wanted(0.005, 0.00998) = 56.9; held at
    // -1/2, 32 * (0.01 / wanted)^2 = 101.2.
    const std::vector<GoalRound> steep{{8, 1, 0.16, std::nullopt},
                                       {32, 2, 0.01, combined({0.16, 0.01})}};
    EXPECT_EQ(predict(steep, 0.005, 65536)->spp, 57);
    EXPECT_EQ(predict(steep, 0.005, 65536, -0.5)->spp, 102);
    // 100 to 120 samples is too narrow a span to measure a slope (their -0.1 would be taken as
    // -1/4): the steepest, -1, from the larger round, as from one round: 120 * 0.011 / 0.00627 =
    // 210.4 (along -1/4, 1135).
    const std::vector<GoalRound> narrow{{100, 1, 0.0112, std::nullopt},
                                        {120, 1, 0.011, combined({0.0112, 0.011})}};
    EXPECT_NEAR(120 * 0.011 / wanted(0.005, combined({0.0112, 0.011})), 210.4, 0.05);
    EXPECT_EQ(predict(narrow, 0.005, 65536)->spp, 211);
}

TEST(Predict, ARoundSmallerThanTheLargestAlongThreeQuarters) {
    // Just missed at 40 samples: one more round needs only the error wanted(0.01, 0.0102) =
    // 0.0353, above 0.0102, so fewer samples than 40, along -3/4: 40 * (0.0353 / 0.0102)^(-4/3)
    // = 7.63 (along -1, as before, 11.5).
    EXPECT_NEAR(40 * std::pow(wanted(0.01, 0.0102) / 0.0102, -4.0 / 3), 7.63, 0.01);
    EXPECT_EQ(predict({{40, 1, 0.0102, 0.0102}}, 0.01, 65536)->spp, 8);
    // The largest round is extrapolated from, not the latest; along -3/4 whatever the slope
    // measured from 8 to 40 samples (-0.67 here): 40 * (0.0421 / 0.0102)^(-4/3) = 6.36.
    const std::vector<GoalRound> rounds{
        {8, 1, 0.03, std::nullopt}, {40, 1, 0.0102, std::nullopt}, {12, 1, 0.05, 0.0101}};
    EXPECT_NEAR(40 * std::pow(wanted(0.01, 0.0101) / 0.0102, -4.0 / 3), 6.36, 0.01);
    EXPECT_EQ(predict(rounds, 0.01, 65536)->spp, 7);
}

TEST(Predict, NeedsARoundWithAPositiveEstimate) {
    EXPECT_FALSE(predict({{8, 1, std::nullopt, std::nullopt}}, 0.01, 65536));
    EXPECT_FALSE(predict({{8, 1, 0.0, 0.0}, {32, 2, 0.0, 0.0}}, 0.01, 65536));
    // Nor without the combined estimate.
    EXPECT_FALSE(predict({{8, 1, 0.04, std::nullopt}}, 0.01, 65536));
}

TEST(NextRound, ThePredictedCountWhenWithinTheFinalStep) {
    const std::vector<GoalRound> one{{8, 1.0, 0.04, 0.04}};
    const NextRound n = next_round(one, 0.01, 65536);
    EXPECT_EQ(n.spp, 32);
    EXPECT_TRUE(n.final);
    // Capped at what is left of the maximum, and nothing once fewer than 2 samples are left or
    // the target is met.
    EXPECT_EQ(next_round(one, 0.01, 20).spp, 12);
    EXPECT_EQ(next_round(one, 0.01, 9).spp, 0);
    EXPECT_EQ(next_round(one, 0.04, 65536).spp, 0);
}

TEST(NextRound, APilotATwelfthOfAPredictionFurtherAway) {
    // 8 * 0.08 / wanted(0.001, 0.08) = 653.0, more than 12 times 8: a pilot of 55.
    EXPECT_NEAR(8 * 0.08 / wanted(0.001, 0.08), 653.0, 0.1);
    const NextRound n = next_round({{8, 1.0, 0.08, 0.08}}, 0.001, 65536);
    EXPECT_EQ(n.spp, 55);
    EXPECT_FALSE(n.final);
    // A twelfth that is less than 4 times the last round is raised to 4 times: 8 * 0.08 /
    // wanted(0.004, 0.08) = 163.3, a twelfth 14, raised to 32.
    EXPECT_EQ(next_round({{8, 1.0, 0.08, 0.08}}, 0.004, 65536).spp, 32);
    // A pilot without an estimate: another 4 times its count.
    GoalRound pilot{8, 1, std::nullopt, std::nullopt};
    pilot.kind = RoundKind::kPilot;
    pilot.pixel_block = 4;
    const NextRound blind = next_round({pilot}, 0.01, 65536);
    EXPECT_EQ(blind.spp, 32);
    EXPECT_FALSE(blind.final);
    // A full round without one (too few pixels to calibrate, radiance past the floats): more
    // samples cannot be judged against the target, so the render ends there.
    EXPECT_EQ(next_round({{8, 1, std::nullopt, std::nullopt}}, 0.01, 65536).spp, 0);
    EXPECT_EQ(next_round({pilot, {32, 1, std::nullopt, std::nullopt}}, 0.01, 65536).spp, 0);
}

// --spp bounds every pixel: one in a top-up has had twice its count more than the full rounds,
// so what is left for the next round counts the top-ups too.
TEST(NextRound, TopUpsCountTowardsTheMaximumOfAPixel) {
    const GoalRound full{32, 1, 0.02, 0.02};
    GoalRound top{16, 1, 0.01, 0.015};
    top.kind = RoundKind::kTopUp;
    EXPECT_EQ(total_samples({full, top}), 32);
    EXPECT_EQ(most_pixel_samples({full, top}), 64);
    EXPECT_EQ(next_round({full, top}, 0.001, 64).spp, 0);
    const NextRound n = next_round({full, top}, 0.001, 80);
    EXPECT_GE(n.spp, 2);
    EXPECT_LE(n.spp, 16);
}

TEST(NextRound, AtLeastATenthOfTheSamplesSoFarAndTwo) {
    // Eight rounds of 25 samples at 0.02829 combine to 0.010002, just over 0.01: one more round of
    // 25 * (wanted(0.01, 0.010002) / 0.02829)^(-4/3) = 12.02 samples would do, raised to a tenth
    // of 200.
    const std::vector<GoalRound> eight(
        8, {25, 1, 0.02829,
            combined({0.02829, 0.02829, 0.02829, 0.02829, 0.02829, 0.02829, 0.02829, 0.02829})});
    EXPECT_EQ(predict(eight, 0.01, 65536)->spp, 13);
    EXPECT_EQ(next_round(eight, 0.01, 65536).spp, 20);
    // At 8 samples a tenth is 1: raised to 2, the fewest with an estimate.
    EXPECT_EQ(next_round({{8, 2, 0.0100001, 0.0100001}}, 0.01, 65536).spp, 2);
}

TEST(NextRound, AfterAFinalRoundThatMissedASlopeNoSteeperThanMinusAHalf) {
    // From one pilot, along -1: 32 samples, meant as the last round. It misses (its own error
    // 0.016, the two combined 0.0149), and 8 to 32 samples measure the slope -0.66; the next
    // round goes along -1/2 from the 32-sample round instead: 32 * (0.016 / 0.0130)^2 = 48.2.
    const std::vector<GoalRound> pilot{{8, 1, 0.04, 0.04}};
    ASSERT_TRUE(next_round(pilot, 0.01, 65536).final);
    std::vector<GoalRound> missed = pilot;
    missed.push_back({32, 1, 0.016, combined({0.04, 0.016})});
    EXPECT_EQ(next_round(missed, 0.01, 65536).spp, 49);
    // A pilot that is not meant as the last round is no miss: the measured slope holds, -0.71
    // from 8 to 32 samples: 32 * (wanted(0.006, 0.0281) / 0.03)^(1 / -0.71) = 310.3.
    const std::vector<GoalRound> far{{8, 1, 0.08, 0.08}};
    ASSERT_FALSE(next_round(far, 0.006, 65536).final);
    const std::vector<GoalRound> pilots{{8, 1, 0.08, 0.08}, {32, 1, 0.03, combined({0.08, 0.03})}};
    EXPECT_EQ(next_round(pilots, 0.006, 65536).spp, 311);
}

TEST(PredictedSeconds, ALineThroughTheLastTwoRoundsOrProportionalToOne) {
    EXPECT_DOUBLE_EQ(predicted_seconds({{10, 2.0, {}, {}}}, 100), 20.0);
    EXPECT_DOUBLE_EQ(predicted_seconds({{10, 2.0, {}, {}}, {20, 3.0, {}, {}}}, 100),
                     1.0 + 0.1 * 100);
    // Times that fall with samples (noise) never predict a free sample: the last round's rate.
    EXPECT_DOUBLE_EQ(predicted_seconds({{10, 3.0, {}, {}}, {20, 2.0, {}, {}}}, 100), 10.0);
}

TEST(PredictedSeconds, CountsTheCameraSamplesTracedPerPixelCalibrationIncluded) {
    // A pilot of 8 spp in one pixel of 16 that rendered all its pixels twice: 1 sample per pixel
    // of the image in 1 s. Before a full round, a full round's calibration is not known.
    const GoalRound pilot{8, 1.0, {}, {}, RoundKind::kPilot, 4, 1.0};
    EXPECT_DOUBLE_EQ(predicted_seconds({pilot}, 10), 10.0);
    // Its set-up (before and after its tiles) is paid once, not per sample.
    const GoalRound set_up{8, 1.0, {}, {}, RoundKind::kPilot, 4, 1.0, 0.2};
    EXPECT_DOUBLE_EQ(predicted_seconds({set_up}, 10), 0.2 + 0.8 * 10);
    // A full round of 10 spp with a tenth more for its calibration, 11 samples a pixel in 3 s:
    // the line through both, 0.2 s a sample after 0.8 s, and that calibration share.
    const GoalRound full{10, 3.0, {}, {}, RoundKind::kFull, 1, 0.1};
    EXPECT_DOUBLE_EQ(predicted_seconds({pilot, full}, 20), 0.8 + 0.2 * 20 * 1.1);
}

// ---- the command line --------------------------------------------------------------------------

// Soft shadows and antialiasing; renders in milliseconds.
constexpr const char* kGoalScene = R"(<?xml version="1.0"?>
<Scene>
  <Image Width="24" Height="16"/>
  <Render Samples="4" ShadowRays="1" Seed="3"/>
  <Background r="0.1" g="0.2" b="0.3"/>
  <Camera Ex="0" Ey="2" Ez="-8" Lx="0" Ly="1" Lz="0" Fov="40"/>
  <Materials>
    <Grey kdr="0.7" kdg="0.7" kdb="0.7" diffuse="1"/>
  </Materials>
  <Light Px="2" Py="6" Pz="-2" Radius="0.8" Ir="1" Ig="1" Ib="1"/>
  <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Grey"/>
  <Sphere Px="0" Py="1" Pz="0" Radius="1" Material="Grey"/>
</Scene>
)";

class GoalCli : public test::TempFolderTest {
  protected:
    void SetUp() override {
        TempFolderTest::SetUp();
        test::write_bytes(dir_ / "scene.xml", kGoalScene);
    }
    Outcome run(const std::vector<std::string>& args) const { return run_drt(args, dir_); }
    std::string bytes(const std::string& name) const { return read_bytes(dir_ / name); }
    // N of the "--spp N renders the same image" line.
    static int reached(const std::string& err) {
        const auto groups = regex_groups(err, ": --spp ([0-9]+) renders the same image");
        return groups.empty() ? -1 : std::stoi(groups[1]);
    }
};

TEST_F(GoalCli, BadGoalsExitTwoWithTheReasonAndWriteNothing) {
    for (const std::string option : {"--target-error", "--time-limit"}) {
        for (const std::string value : {"0", "-1", "nan", "inf", "x"}) {
            const Outcome r =
                run({"scene.xml", option, value, "-o", "out.pfm", "--stats", "s.json"});
            EXPECT_EQ(r.status, 2) << option << " " << value;
            EXPECT_EQ(r.err, "drt: " + option + ": must be a finite positive number, got " + value +
                                 "\nRun 'drt --help' for usage.\n");
        }
    }
    // A goal decides the sample counts itself: no per-pixel threshold, no checkpoint of rounds.
    const Outcome threshold =
        run({"scene.xml", "--target-error", "0.01", "--noise-threshold", "0.1", "-o", "out.pfm"});
    EXPECT_EQ(threshold.status, 2);
    EXPECT_EQ(threshold.err,
              "drt: --noise-threshold excludes --target-error\nRun 'drt --help' for usage.\n");
    const Outcome checkpoint =
        run({"scene.xml", "--time-limit", "1", "--checkpoint", "c.ckpt", "-o", "out.pfm"});
    EXPECT_EQ(checkpoint.status, 2);
    EXPECT_EQ(checkpoint.err,
              "drt: --checkpoint excludes --time-limit\nRun 'drt --help' for usage.\n");
    EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
    EXPECT_FALSE(fs::exists(dir_ / "s.json"));
    EXPECT_FALSE(fs::exists(dir_ / "c.ckpt"));
}

// An image without an estimate (16 pixels, fewer than the 24 a calibration needs) stops after
// its first round instead of growing rounds to --spp, which no estimate could judge; a time
// limit past the steady clock's range is no limit rather than one already past, and --stats
// counts the rays of all its rounds.
TEST_F(GoalCli, NoEstimateEndsTheRoundsAndAnEndlessTimeLimitIsNoLimit) {
    Outcome r = run({"scene.xml", "--width", "4", "--height", "4", "--target-error", "0.001",
                     "--spp", "4096", "-o", "tiny.pfm"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(": 8 spp after rounds of 8 spp; estimated rmse n/a (target 0.001 not "
                         "met: without an estimate no more samples can be judged)"),
              std::string::npos)
        << r.err;
    r = run({"scene.xml", "--width", "8", "--height", "6", "--time-limit", "1e10", "--spp", "40",
             "-o", "long.pfm", "--stats", "long.json"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(reached(r.err), 40) << r.err;
    // Its rays are those of every round, the replaced one of 8 spp included.
    EXPECT_NE(bytes("long.json").find("\"rounds\": [{\"spp\": 8, "), std::string::npos);
    EXPECT_NE(bytes("long.json").find("\"camera\": " + std::to_string((8 + 40) * 8 * 6) + ","),
              std::string::npos)
        << bytes("long.json");
}

TEST_F(GoalCli, SppIsTheMaximumOfAllRoundsTogether) {
    // An error no 40 samples reach: the rounds stop at the maximum (the pilot after the first
    // would be far more, and is cut to the 32 samples left).
    const Outcome r = run({"scene.xml", "--target-error", "1e-9", "--spp", "40", "-o", "goal.pfm",
                           "--stats", "s.json"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(": 40 spp after rounds of 8, 32 spp"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(target 1e-09 not met)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("the same command renders the same image (bit-identical) every run"),
              std::string::npos)
        << r.err;
    EXPECT_NE(bytes("s.json").find("\"samples_per_pixel\": 40"), std::string::npos);
    EXPECT_NE(bytes("s.json").find("\"target_met\": false"), std::string::npos);
    EXPECT_NE(bytes("s.json").find("\"combined\": true"), std::string::npos);
    // Each round's seed, to render it alone.
    EXPECT_NE(bytes("s.json").find("{\"spp\": 8, \"seed\": \"3\", "), std::string::npos);
    EXPECT_NE(bytes("s.json").find("{\"spp\": 32, \"seed\": \"" + std::to_string(round_seed(3, 1)) +
                                   "\", "),
              std::string::npos)
        << bytes("s.json");
}

TEST(RenderToGoal, TheImageIsTheRoundsWeightedByTheirInverseEstimatedVariance) {
    LoadedScene loaded = load_scene_from_string(kGoalScene, "scene.xml");
    Scene& scene = loaded.scene;
    RenderGoal goal;
    goal.target_error = 1e-9;
    goal.max_samples = 40;
    RenderJobOptions options;
    options.threads = 2;
    const RenderSettings before = scene.settings;
    const GoalResult p = render_to_goal(scene, options, goal);
    // The rounds are requests: the scene's own settings are never touched.
    EXPECT_EQ(scene.settings.samples, before.samples);
    EXPECT_EQ(scene.settings.seed, before.seed);
    ASSERT_EQ(p.rounds.size(), 2u);
    EXPECT_EQ(p.rounds[0].spp, 8);
    EXPECT_EQ(p.rounds[1].spp, 32);
    EXPECT_EQ(p.samples, 40);
    EXPECT_TRUE(p.combined);
    // Each round alone: the plain render of its count and seed.
    std::vector<RenderResult> alone;
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(p.rounds[i].seed, round_seed(3, i));
        alone.push_back(
            run_render_job(scene, alone_at(p.rounds[i].spp, p.rounds[i].seed), options).render);
        ASSERT_TRUE(alone.back().stats.error.rmse);
        EXPECT_EQ(p.rounds[i].error, alone.back().stats.error.rmse);
    }
    const double w0 = round_weight(alone[0].stats.error.rmse, 8);
    const double w1 = round_weight(alone[1].stats.error.rmse, 32);
    // The 32-sample round weighs more than 4 times the 8-sample one: its stratified error is
    // more than halved.
    EXPECT_GT(w1, 4 * w0);
    const Image& image = p.job.render.image;
    ASSERT_EQ(image.rgb.size(), alone[0].image.rgb.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        const double mean = (w0 * alone[0].image.rgb[i] + w1 * alone[1].image.rgb[i]) / (w0 + w1);
        differ += image.rgb[i] != static_cast<float>(mean);
    }
    EXPECT_EQ(differ, 0u);
    // The combined estimate: the variance of that mean, 1 / (w0 + w1).
    ASSERT_TRUE(p.error);
    EXPECT_NEAR(*p.error, 1 / std::sqrt(w0 + w1), 1e-5 / std::sqrt(w0 + w1));
    EXPECT_EQ(p.job.render.stats.samples, alone[0].stats.samples + alone[1].stats.samples);
    EXPECT_EQ(p.job.render.stats.rays.total(),
              alone[0].stats.rays.total() + alone[1].stats.rays.total());
}

// ---- a top-up round on some pixels
// -------------------------------------------------------------

// A 16 x 16 variance image (the same in every channel): 1e-6 everywhere but at `spikes`.
Image variances(std::initializer_list<std::pair<int, double>> spikes) {
    Image v(16, 16);
    for (float& x : v.rgb) x = 1e-6f;
    for (const auto& [pixel, value] : spikes) {
        for (int c = 0; c < 3; ++c) v.rgb[3 * std::size_t(pixel) + c] = static_cast<float>(value);
    }
    return v;
}

// The goal whose shortfall, the variance summed over pixels above goal^2 per pixel, is `need`.
double goal_short_by(const Image& v, double need) {
    double total = 0;
    for (const float x : v.rgb) total += x / 3.0;
    return std::sqrt((total - need) / (double(v.width) * v.height));
}

// `v` times `factor`: a top-up's predicted variance where it is proportional to the image's.
Image times(Image v, float factor) {
    for (float& x : v.rgb) x *= factor;
    return v;
}

TEST(PlanTopUp, TakesPixelsByTheirNeighboursVarianceNotTheirOwn) {
    // One pixel, (8, 8), holds most of the variance; a shortfall of 1.47e-5 (14.7 quiet pixels).
    const int spike = 8 * 16 + 8;
    const Image v = variances({{spike, 1e-3}});
    // A top-up of variance 4 v (two renders of 2 where the image has 8 along -3/4: (8/2)^1.5 / 2)
    // takes v^2 / (v + 4 v) = v / 5 off a pixel: its 8 neighbours and then quiet pixels in index
    // order, 74 in all (74 / 5 > 14.7 quiet pixels' worth).
    const auto plan = plan_top_up(v, times(v, 4), 2, goal_short_by(v, 1.47e-5));
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->spp, 2);
    ASSERT_EQ(plan->pixels.size(), 74u);
    EXPECT_TRUE(std::is_sorted(plan->pixels.begin(), plan->pixels.end()));
    EXPECT_TRUE(plan->spot_checks.empty());  // none asked for
    const auto has = [&](int pixel) {
        return std::binary_search(plan->pixels.begin(), plan->pixels.end(),
                                  static_cast<std::uint32_t>(pixel));
    };
    for (const int d : {-17, -16, -15, -1, 1, 15, 16, 17}) EXPECT_TRUE(has(spike + d)) << d;
    // Its own samples do not decide it: their neighbours are quiet.
    EXPECT_FALSE(has(spike));
    EXPECT_TRUE(has(0));
    EXPECT_DOUBLE_EQ(plan->cost(256), 2.0 * 2 * 74 / 256);
    // Two renders of the image's own count, v / 2, take two thirds of v off: 4.63e-5 takes 70
    // quiet pixels.
    EXPECT_EQ(plan_top_up(v, times(v, 0.5), 8, goal_short_by(v, 4.63e-5))->pixels.size(), 70u);
    // Two spikes side by side: each is the other's neighbour, so both are taken first.
    const Image pair = variances({{spike, 1e-3}, {spike + 1, 1e-3}});
    const auto both = plan_top_up(pair, times(pair, 0.5), 8, goal_short_by(pair, 1e-3));
    ASSERT_TRUE(both);
    EXPECT_TRUE(std::binary_search(both->pixels.begin(), both->pixels.end(), spike));
    EXPECT_TRUE(std::binary_search(both->pixels.begin(), both->pixels.end(), spike + 1));
}

TEST(PlanTopUp, AtLeast64PixelsOrNone) {
    const Image v = variances({{8 * 16 + 8, 1e-3}});
    const Image half = times(v, 0.5);
    // A shortfall the spike's neighbours alone make up still takes 64 pixels.
    const auto least = plan_top_up(v, half, 8, goal_short_by(v, 1e-6));
    ASSERT_TRUE(least);
    EXPECT_EQ(least->pixels.size(), kMinTopUpPixels);
    // No top-up of 1 sample (no estimate), none when the goal is met, none out of reach even
    // with every pixel topped up (here two thirds of the variance at most), none on an image of
    // fewer than 64 pixels or with a prediction of another size.
    EXPECT_EQ(plan_top_up(v, half, 1, goal_short_by(v, 1e-6)), std::nullopt);
    EXPECT_EQ(plan_top_up(v, half, 8, 1), std::nullopt);
    EXPECT_EQ(plan_top_up(v, half, 8, goal_short_by(v, 0.9e-3)), std::nullopt);
    EXPECT_TRUE(plan_top_up(v, half, 8, goal_short_by(v, 0.8e-3)));
    EXPECT_EQ(plan_top_up(Image(7, 9), Image(7, 9), 8, 0), std::nullopt);
    EXPECT_EQ(plan_top_up(v, Image(16, 15), 8, goal_short_by(v, 1e-6)), std::nullopt);
    // Cut to what the time left pays for: the first pixels in order, short of the goal, but
    // never fewer than 64.
    const double goal = goal_short_by(v, 4.63e-5);  // 70 pixels (above)
    const auto cut = plan_top_up(v, half, 8, goal, std::nullopt, 66);
    ASSERT_TRUE(cut);
    EXPECT_EQ(cut->pixels.size(), 66u);
    const auto whole = plan_top_up(v, half, 8, goal, std::nullopt, 1000);
    ASSERT_TRUE(whole);
    EXPECT_EQ(whole->pixels.size(), 70u);
    EXPECT_TRUE(std::includes(whole->pixels.begin(), whole->pixels.end(), cut->pixels.begin(),
                              cut->pixels.end()));
    EXPECT_EQ(plan_top_up(v, half, 8, goal, std::nullopt, 63), std::nullopt);
}

TEST(PlanTopUp, CalibratesTheOtherPixelsAtRandomMostOftenNextToTheirVariance) {
    // A variance rising to the right, a sixteenth of the 1,024 pixels asked for: 64 at most.
    Image v(32, 32);
    for (int y = 0; y < 32; ++y) {
        for (int x = 0; x < 32; ++x) {
            for (int c = 0; c < 3; ++c) v.rgb[3 * std::size_t(y * 32 + x) + c] = 1e-6f * (1 + x);
        }
    }
    const double goal = goal_short_by(v, 1e-3);
    const auto plan = plan_top_up(v, times(v, 0.5), 8, goal, 7);
    ASSERT_TRUE(plan);
    ASSERT_EQ(plan->spot_checks.size(), plan->spot_check_odds.size());
    EXPECT_TRUE(std::is_sorted(plan->spot_checks.begin(), plan->spot_checks.end()));
    std::vector<std::uint32_t> both;
    std::set_intersection(plan->pixels.begin(), plan->pixels.end(), plan->spot_checks.begin(),
                          plan->spot_checks.end(), std::back_inserter(both));
    EXPECT_TRUE(both.empty());
    // About 64 (the odds sum to 64 over the others): a binomial's 5 sigma either way.
    EXPECT_GT(plan->spot_checks.size(), 25u);
    EXPECT_LT(plan->spot_checks.size(), 105u);
    double left = 0, right = 0;
    for (std::size_t i = 0; i < plan->spot_checks.size(); ++i) {
        EXPECT_GT(plan->spot_check_odds[i], 0);
        EXPECT_LE(plan->spot_check_odds[i], 1);
        (plan->spot_checks[i] % 32 < 16 ? left : right) += 1;
    }
    EXPECT_GT(right, left);
    // The same seed picks the same pixels; another, others.
    EXPECT_EQ(plan_top_up(v, times(v, 0.5), 8, goal, 7)->spot_checks, plan->spot_checks);
    EXPECT_NE(plan_top_up(v, times(v, 0.5), 8, goal, 8)->spot_checks, plan->spot_checks);
    EXPECT_DOUBLE_EQ(plan->cost(1024),
                     2.0 * 8 * double(plan->pixels.size() + plan->spot_checks.size()) / 1024);
}

TEST(RenderToGoal, ATopUpIsWeightedByTheRatioOfTheMeanVariancesOverItsPixels) {
    LoadedScene loaded = load_scene_from_string(kGoalScene, "scene.xml");
    Scene& scene = loaded.scene;
    scene.settings.width = 32;
    scene.settings.height = 24;
    RenderGoal goal;
    goal.target_error = 0.005;
    goal.max_samples = 1000;
    RenderJobOptions options;
    options.threads = 2;
    const GoalResult p = render_to_goal(scene, options, goal);
    // As GoalCli.TargetErrorGivesTheSameBitsForAnyThreadCount: 8, 15, then 2 x 15 on some pixels.
    ASSERT_EQ(p.rounds.size(), 3u);
    ASSERT_TRUE(p.rounds[2].top_up());
    EXPECT_EQ(p.samples, 23);
    // The two full rounds combined, as the image before the top-up.
    std::vector<RenderResult> alone;
    for (std::size_t i = 0; i < 2; ++i) {
        alone.push_back(
            run_render_job(scene, alone_at(p.rounds[i].spp, round_seed(3, i)), options).render);
    }
    const double w0 = round_weight(alone[0].stats.error.rmse, 8);
    const double w1 = round_weight(alone[1].stats.error.rmse, 15);
    const std::size_t n = alone[0].image.rgb.size();
    std::vector<double> mean(n), variance(n);
    Image before(32, 24);
    for (std::size_t i = 0; i < n; ++i) {
        mean[i] = (w0 * alone[0].image.rgb[i] + w1 * alone[1].image.rgb[i]) / (w0 + w1);
        variance[i] = (w0 * w0 * alone[0].stats.error.scale * alone[0].spread.rgb[i] +
                       w1 * w1 * alone[1].stats.error.scale * alone[1].spread.rgb[i]) /
                      ((w0 + w1) * (w0 + w1));
        before.rgb[i] = static_cast<float>(variance[i]);
    }
    // Of the last full round's count, predicted from its variance; it calibrates the rest.
    Image pair(32, 24);
    std::vector<double> last(n);
    for (std::size_t i = 0; i < n; ++i) {
        last[i] = alone[1].stats.error.scale * alone[1].spread.rgb[i];
        pair.rgb[i] = static_cast<float>(last[i] / 2);
    }
    const auto plan = plan_top_up(before, pair, 15, 0.98 * 0.005, round_seed(3, 2));
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->spp, p.rounds[2].spp);
    EXPECT_FALSE(plan->spot_checks.empty());
    EXPECT_DOUBLE_EQ(p.rounds[2].top_up_share,
                     double(plan->pixels.size() + plan->spot_checks.size()) / (32 * 24));
    // The top-up alone: its pixels, each the mean of two renders, its spread their variance.
    std::vector<std::uint32_t> all = plan->pixels;
    all.insert(all.end(), plan->spot_checks.begin(), plan->spot_checks.end());
    std::sort(all.begin(), all.end());
    RenderRequest top_up = alone_at(plan->spp, round_seed(3, 2));
    top_up.pixels = PixelChoice::kListed;
    top_up.listed = all;
    top_up.paired = true;
    EXPECT_EQ(p.rounds[2].seed, top_up.seed);
    const RenderResult t = run_render_job(scene, top_up, options).render;
    ASSERT_TRUE(t.stats.error.available());
    EXPECT_EQ(p.rounds[2].error, t.stats.error.rmse);
    std::vector<int> set(n / 3, 0);  // 1: topped up, 2: calibrating
    for (const std::uint32_t pixel : plan->pixels) set[pixel] = 1;
    for (const std::uint32_t pixel : plan->spot_checks) set[pixel] = 2;
    // The rounds' estimate recalibrated by what the pairs measure against the last round's
    // estimate: on the top-up's pixels, and (from the calibrating ones, by 1 / their odds)
    // everywhere else.
    double pairs[3] = {}, estimated[3] = {};
    for (std::size_t i = 0; i < plan->spot_checks.size(); ++i) {
        for (std::size_t c = 3 * plan->spot_checks[i]; c < 3 * plan->spot_checks[i] + 3; ++c) {
            pairs[2] += 2 * double(t.spread.rgb[c]) / plan->spot_check_odds[i];
            estimated[2] += last[c] / plan->spot_check_odds[i];
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (set[i / 3] == 1) {
            pairs[1] += 2 * double(t.spread.rgb[i]);
            estimated[1] += last[i];
        }
    }
    const double inside = pairs[1] / estimated[1];
    const double outside = std::clamp(pairs[2] / estimated[2], 0.25, 4.0);
    EXPECT_NE(inside, 1.0);
    EXPECT_NE(outside, 1.0);
    double before_in[3] = {}, own[3] = {};
    for (std::size_t i = 0; i < n; ++i) {
        variance[i] *= set[i / 3] == 1 ? inside : outside;
        before_in[set[i / 3]] += variance[i];
        own[set[i / 3]] += t.spread.rgb[i];
    }
    // Each set's weight against the rounds before it: the ratio of their variances there.
    const double ratio[3] = {0, before_in[1] / own[1], before_in[2] / own[2]};
    std::size_t differ = 0;
    double mse = 0;
    for (std::size_t i = 0; i < n; ++i) {
        double expected = mean[i], var = variance[i];
        if (const double r = ratio[set[i / 3]]; r > 0) {
            expected = (mean[i] + r * t.image.rgb[i]) / (1 + r);
            var = (var + r * r * t.spread.rgb[i]) / ((1 + r) * (1 + r));
        } else {
            EXPECT_EQ(t.image.rgb[i], 0.0f);  // not rendered
        }
        differ += std::abs(p.job.render.image.rgb[i] - expected) > 1e-6 * (1 + std::abs(expected));
        mse += var;
    }
    EXPECT_EQ(differ, 0u);
    // The estimate: the mean of the pixels' variances, the top-up's included.
    ASSERT_TRUE(p.error);
    EXPECT_NEAR(*p.error, std::sqrt(mse / double(n)), 1e-6);
    EXPECT_LE(*p.error, 0.005);
    // Every camera sample counted: the top-up's two renders of 15 on its pixels.
    EXPECT_EQ(p.job.render.stats.samples,
              alone[0].stats.samples + alone[1].stats.samples + 2 * 15 * all.size());
}

TEST_F(GoalCli, TimeLimitStopsByTheLimitWithThePlainRenderOfTheCountReached) {
    // The random sampler's time per sample is constant, and 12 tiles let a round be stopped
    // between tiles. The largest count, 65536 spp, takes minutes: the limit stops the rounds.
    const std::vector<std::string> size{"--width", "64", "--height", "48", "--sampler", "random"};
    const double limit = 3.0;  // room for more than the pilots on a loaded machine
    std::vector<std::string> args{"scene.xml",   "--time-limit", "3", "-o",
                                  "limited.pfm", "--threads",    "2"};
    args.insert(args.end(), size.begin(), size.end());
    const auto start = std::chrono::steady_clock::now();
    const Outcome r = run(args);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(r.status, 0) << r.err;
    // The limit with 5 % over and a generous allowance for the process's start and end on a
    // loaded machine; and more than the pilots' 8 + 32 samples.
    EXPECT_LT(wall, limit * 1.05 + 2.0) << r.err;
    const int spp = reached(r.err);
    EXPECT_GT(spp, 32) << r.err;
    std::vector<std::string> plain{"scene.xml", "--spp",     std::to_string(spp),
                                   "-o",        "plain.pfm", "-q"};
    plain.insert(plain.end(), size.begin(), size.end());
    ASSERT_EQ(run(plain).status, 0);
    EXPECT_EQ(bytes("limited.pfm"), bytes("plain.pfm"));
}

TEST_F(GoalCli, TargetErrorIsMetAgainstAHighSampleReference) {
    // The estimate is honest to within 1.25 (accuracy.md), and the rounds stop at or below E.
    const double target = 0.01;
    for (const std::string sampler : {"stratified", "random", "sobol"}) {
        const std::vector<std::string> common{"--width",   "32",    "--height", "24",
                                              "--sampler", sampler, "-q"};
        std::vector<std::string> goal{"scene.xml", "--target-error", "0.01",  "-o",
                                      "goal.pfm",  "--stats",        "s.json"};
        goal.insert(goal.end(), common.begin(), common.end());
        ASSERT_EQ(run(goal).status, 0);
        EXPECT_NE(bytes("s.json").find("\"target_met\": true"), std::string::npos) << sampler;
        // Seed 4, not the render's 3: the reference's noise is independent of the render's.
        std::vector<std::string> reference{"scene.xml", "--spp", "2048",   "--seed",
                                           "4",         "-o",    "ref.pfm"};
        reference.insert(reference.end(), common.begin(), common.end());
        ASSERT_EQ(run(reference).status, 0);
        const double error = rmse(read_image(dir_ / "goal.pfm"), read_image(dir_ / "ref.pfm"));
        EXPECT_LE(error, 1.25 * target) << sampler;
        // And not far below it: the rounds did not overshoot to a needlessly large count.
        EXPECT_GE(error, 0.4 * target) << sampler;
    }
}

TEST_F(GoalCli, TargetErrorGivesTheSameBitsForAnyThreadCount) {
    // A target three rounds reach, so the rounds' weights and sums count: 8, 15 and a top-up of
    // 2 x 15 spp on the pixels around the most variance (a third full round of 7 spp before
    // 2026-12-03).
    std::vector<std::string> images;
    std::optional<double> estimate;
    for (const std::string threads : {"1", "2", "3"}) {
        const Outcome r = run({"scene.xml", "--target-error", "0.005", "--width", "32", "--height",
                               "24", "-o", "t" + threads + ".pfm", "--threads", threads});
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.err.find("after rounds of 8, 15 spp, a top-up of 2 x 15 spp on 14.32 % of the "
                             "pixels;"),
                  std::string::npos)
            << r.err;
        const auto stated = regex_groups(r.err, "estimated rmse ([0-9.e-]+)");
        ASSERT_EQ(stated.size(), 2u) << r.err;
        estimate = std::stod(stated[1]);
        images.push_back(bytes("t" + threads + ".pfm"));
    }
    EXPECT_EQ(images[0], images[1]);
    EXPECT_EQ(images[0], images[2]);
    // The top-up leaves the estimate honest and the target met against a reference of another
    // seed.
    ASSERT_EQ(run({"scene.xml", "--spp", "2048", "--seed", "4", "--width", "32", "--height", "24",
                   "-o", "ref.pfm", "-q"})
                  .status,
              0);
    const double error = rmse(read_image(dir_ / "t1.pfm"), read_image(dir_ / "ref.pfm"));
    EXPECT_LE(error, 1.25 * 0.005);
    EXPECT_GT(*estimate, error / 1.25);
    EXPECT_LT(*estimate, error * 1.25);
}

TEST_F(GoalCli, InfoPredictsTheSamplesAndTimeFromPilots) {
    const Outcome r = run({"info", "scene.xml", "--target-error", "0.005"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto groups = regex_groups(
        r.out,
        "\npilots: 8 spp [0-9.]+ s, estimated rmse [0-9.e-]+;( [0-9]+ spp [0-9.]+ s, estimated "
        "rmse [0-9.e-]+;)*\npredicted for --target-error 0.005: ([0-9]+) spp, [0-9.]+ s on this "
        "machine \\(rounds of (8(, [0-9]+)*) spp\\)(; if the error falls only as N\\^-1/2: "
        "([0-9]+) spp, [0-9.]+ s)?\n$");
    ASSERT_EQ(groups.size(), 7u) << r.out;
    // The predicted samples are the rounds' together.
    int predicted = 0;
    for (const auto& count : regex_all_groups(groups[3], "([0-9]+)")) predicted += std::stoi(count);
    EXPECT_EQ(std::to_string(predicted), groups[2]) << r.out;
    // The render to the target takes the same rounds first (their errors are the same bits) and
    // more only where the predicted final round misses the target.
    ASSERT_EQ(
        run({"scene.xml", "--target-error", "0.005", "-o", "g.pfm", "--stats", "s.json", "-q"})
            .status,
        0);
    const std::string stats = bytes("s.json");
    EXPECT_NE(stats.find("\"target_met\": true"), std::string::npos) << stats;
    std::string rounds;
    for (const auto& count : regex_all_groups(stats, "\\{\"spp\": ([0-9]+),")) {
        rounds += (rounds.empty() ? "" : ", ") + count;
    }
    EXPECT_EQ(rounds.substr(0, groups[3].size()), groups[3]) << stats;
    const auto spp = regex_groups(stats, "\"samples_per_pixel\": ([0-9]+),");
    ASSERT_EQ(spp.size(), 2u) << stats;
    EXPECT_GE(std::stoi(spp[1]), predicted) << stats;
    // Along -1/2 the last round is larger; no bound (here the goal takes 40 spp, 34 predicted).
    if (!groups[6].empty()) {
        EXPECT_GT(std::stoi(groups[6]), predicted) << r.out;
    }
    const Outcome bad = run({"info", "scene.xml", "--target-error", "0"});
    EXPECT_EQ(bad.status, 2);
    EXPECT_EQ(bad.err,
              "drt info: --target-error: must be a finite positive number, got 0\n"
              "Run 'drt info --help' for usage.\n");
}

// ---- a pilot of some pixels
// ----------------------------------------------------------------------

TEST(PilotBlock, TheLargestSquareWithEnoughPilotPixelsUpToTwelve) {
    EXPECT_EQ(kPilotPixels, 1024);
    EXPECT_EQ(pilot_block(32, 24), 1);     // 768 pixels: all of them
    EXPECT_EQ(pilot_block(80, 60), 1);     // squares of 2 would fit, but cost too much: all
    EXPECT_EQ(pilot_block(127, 128), 1);   // squares of 3.99
    EXPECT_EQ(pilot_block(128, 128), 4);   // 1,024 of 16,384 pixels
    EXPECT_EQ(pilot_block(200, 150), 5);   // 1,200 of 30,000
    EXPECT_EQ(pilot_block(400, 300), 10);  // squares of 10.8: 1,200 of 120,000
    EXPECT_EQ(pilot_block(800, 600), 12);  // squares of 21.7 held at 12: 3,350 of 480,000
    EXPECT_EQ(pilot_block(1600, 1200), 12);
}

TEST(Predict, AfterAPilotOfSomePixelsAimsAt95PercentAlongMinusFourFifthsUp) {
    // No image yet: the round alone must reach 0.95 E, from the pilot's error.
    const GoalRound pilot{8, 0.5, 0.02, std::nullopt, RoundKind::kPilot, 4};
    EXPECT_EQ(predict({pilot}, 0.01, 65536)->spp,
              static_cast<int>(std::ceil(8 * std::pow(0.0095 / 0.02, -1 / 0.8))));  // 21
    const GoalRound low{8, 0.5, 0.005, std::nullopt, RoundKind::kPilot, 4};
    // Toward fewer samples along -3/4, as every smaller round: 8 x (0.0095 / 0.005)^(-4/3) = 3.4.
    EXPECT_EQ(predict({low}, 0.01, 65536)->spp,
              static_cast<int>(std::ceil(8 * std::pow(0.0095 / 0.005, -1 / 0.75))));
    // A pilot's error under E is no image meeting E.
    EXPECT_GT(next_round({low}, 0.01, 65536).spp, 0);
    EXPECT_EQ(total_samples({pilot}), 0);
}

// kGoalScene at 128 x 128: a pilot of one pixel in 4 x 4.
LoadedScene pilot_scene() {
    LoadedScene loaded = load_scene_from_string(kGoalScene, "scene.xml");
    loaded.scene.settings.width = 128;
    loaded.scene.settings.height = 128;
    return loaded;
}

TEST(RenderToGoal, APilotOfSomePixelsMeasuresTheImageAndIsNotKept) {
    LoadedScene loaded = pilot_scene();
    Scene& scene = loaded.scene;
    ASSERT_EQ(pilot_block(128, 128), 4);
    RenderJobOptions options;
    options.threads = 2;
    const RenderResult eight = run_render_job(scene, alone_at(8, 3), options).render;
    ASSERT_TRUE(eight.stats.error.rmse);
    // A target three times the error of 8 spp: one full round of a few samples meets it.
    RenderGoal goal;
    goal.target_error = 3 * *eight.stats.error.rmse;
    goal.max_samples = 1000;
    const GoalResult p = render_to_goal(scene, options, goal);
    ASSERT_EQ(p.rounds.size(), 2u);
    const GoalRound& pilot = p.rounds[0];
    EXPECT_EQ(pilot.spp, 8);
    EXPECT_EQ(pilot.pixel_block, 4);
    EXPECT_FALSE(pilot.full());
    EXPECT_FALSE(pilot.combined);
    // Its estimate is of the whole image's error per pixel: near the full render's (its 1,024
    // pixels scatter; here 0.71 of it), not a quarter (its pixels' errors spread over all
    // pixels) or four times it.
    ASSERT_TRUE(pilot.error);
    EXPECT_GT(*pilot.error, 0.5 * *eight.stats.error.rmse);
    EXPECT_LT(*pilot.error, 2.0 * *eight.stats.error.rmse);
    // Its cost: 8 samples in one pixel of 16, each of its 1,024 pixels rendered twice for its
    // estimate.
    EXPECT_DOUBLE_EQ(pilot.estimate_cost, 1.0);
    EXPECT_DOUBLE_EQ(pilot.cost(), 1.0);
    // The one full round is the plain render of its count and the scene's seed, bit for bit;
    // the image's samples are its own.
    const GoalRound& full = p.rounds[1];
    EXPECT_TRUE(full.full());
    EXPECT_LT(full.spp, 8);
    EXPECT_TRUE(p.target_met);
    EXPECT_EQ(p.samples, full.spp);
    const RenderResult plain = run_render_job(scene, alone_at(full.spp, 3), options).render;
    EXPECT_EQ(p.job.render.image.rgb, plain.image.rgb);
    // Its estimate, recomputed as the rounds' combination, agrees to rounding.
    ASSERT_TRUE(p.error && plain.stats.error.rmse);
    EXPECT_NEAR(*p.error, *plain.stats.error.rmse, 1e-6 * *p.error);
    EXPECT_EQ(p.job.render.stats.samples, plain.stats.samples);
}

TEST_F(GoalCli, APilotOfSomePixelsThenOneRoundIsThePlainRenderOfItsCount) {
    const std::vector<std::string> size{"--width", "128", "--height", "128"};
    std::vector<std::string> goal{"scene.xml", "--target-error", "0.03",  "-o",
                                  "goal.pfm",  "--stats",        "s.json"};
    goal.insert(goal.end(), size.begin(), size.end());
    const Outcome r = run(goal);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto rounds = regex_groups(
        r.err, ": ([0-9]+) spp after a pilot of 8 spp on 1 pixel in 16, rounds of ([0-9]+) spp;");
    ASSERT_EQ(rounds.size(), 3u) << r.err;
    EXPECT_EQ(rounds[1], rounds[2]);
    EXPECT_EQ(reached(r.err), std::stoi(rounds[1])) << r.err;
    EXPECT_NE(bytes("s.json").find("{\"spp\": 8, \"pilot_pixel_block\": 4, \"seconds\": "),
              std::string::npos)
        << bytes("s.json");
    EXPECT_NE(bytes("s.json").find("{\"spp\": " + rounds[1] + ", \"seed\": \"3\", "),
              std::string::npos)
        << bytes("s.json");
    std::vector<std::string> plain{"scene.xml", "--spp", rounds[1], "-o", "plain.pfm", "-q"};
    plain.insert(plain.end(), size.begin(), size.end());
    ASSERT_EQ(run(plain).status, 0);
    EXPECT_EQ(bytes("goal.pfm"), bytes("plain.pfm"));
}

TEST_F(GoalCli, AGoalStoppedInItsFirstRoundKeepsItsTilesAndPointsToNoCheckpoint) {
    // With a pilot of some pixels (128 x 128) and without: the first round's finished tiles (one
    // thread, so exactly one: two would each finish the tile in hand).
    for (const std::string side : {"24", "128"}) {
        const Outcome r = run({"scene.xml", "--target-error", "0.01", "--width", side, "--height",
                               side, "--stop-after-tiles", "1", "--threads", "1", "-o", "s.pfm"});
        EXPECT_EQ(r.status, 130) << r.err;
        EXPECT_EQ(regex_groups(r.err,
                               ": interrupted with 1 of [0-9]+ tiles done; wrote "
                               "s\\.partial\\.pfm \\(the goal's first round; a goal render "
                               "cannot be resumed\\)\n")
                      .size(),
                  1u)
            << r.err;
        // --checkpoint excludes a goal: no hint to it.
        EXPECT_EQ(r.err.find("--checkpoint"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "s.pfm"));
        EXPECT_TRUE(fs::exists(dir_ / "s.partial.pfm"));
        fs::remove(dir_ / "s.partial.pfm");
    }
}

TEST_F(GoalCli, TargetErrorWithAPilotGivesTheSameBitsForAnyThreadCount) {
    // A target the first full round after the pilot misses (19 spp), and a top-up of 2 x 19 spp
    // on some pixels meets.
    std::vector<std::string> images;
    std::string summary;
    for (const std::string threads : {"1", "2", "3"}) {
        const Outcome r = run({"scene.xml", "--target-error", "0.003", "--width", "128", "--height",
                               "128", "-o", "t" + threads + ".pfm", "--threads", threads});
        ASSERT_EQ(r.status, 0) << r.err;
        const auto line = regex_groups(r.err,
                                       "(after a pilot of 8 spp on 1 pixel in 16, rounds of "
                                       "[0-9]+ spp(, a top-up of 2 x [0-9]+ spp on [0-9.]+ % of "
                                       "the pixels)+;)");
        ASSERT_EQ(line.size(), 3u) << r.err;
        if (summary.empty()) summary = line[1];
        EXPECT_EQ(line[1], summary);
        images.push_back(bytes("t" + threads + ".pfm"));
    }
    EXPECT_EQ(images[0], images[1]);
    EXPECT_EQ(images[0], images[2]);
}

}  // namespace
}  // namespace drt
