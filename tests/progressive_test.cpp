// Rendering to a goal (progressive.h): the prediction's arithmetic, and --target-error and
// --time-limit as a user runs them.
#include "drt/progressive.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "drt/converge.h"
#include "drt/image.h"
#include "regex_match.h"
#include "run_drt.h"
#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;
using test::Outcome;
using test::read_bytes;
using test::regex_groups;
using test::run_drt;

TEST(Predict, ExtrapolatesTheLastTwoErrorsAlongTheirSlopeWithATwentiethToSpare) {
    // Error halving from 8 to 32 samples: slope -1/2, so a quarter of the error needs 16 times
    // the samples: 32 * 16 * 1.05 = 537.6.
    const std::vector<ProgressiveRound> rounds{{8, 1.0, 0.08}, {32, 2.5, 0.04}};
    const auto p = predict(rounds, 0.01, 65536);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->spp, 538);
    // Time: 0.5 s of set-up and 1.5 s / 24 samples = 0.0625 s a sample.
    EXPECT_DOUBLE_EQ(p->seconds, 0.5 + 0.0625 * 538);
    // Met already: the last count.
    EXPECT_EQ(predict(rounds, 0.05, 65536)->spp, 32);
    // Capped at the maximum.
    EXPECT_EQ(predict(rounds, 0.01, 100)->spp, 100);
}

TEST(Predict, HoldsTheSlopeBetweenMinusOneAndMinusAQuarter) {
    // A flat pair of pilots (slope 0) is taken as -1/4: half the error needs 16 times the samples.
    const std::vector<ProgressiveRound> flat{{8, 1, 0.08}, {32, 2, 0.08}};
    EXPECT_EQ(predict(flat, 0.04, 65536)->spp, static_cast<int>(std::ceil(32 * 16 * 1.05)));
    // A slope of -2 (luck) is taken as -1: half the error needs twice the samples.
    const std::vector<ProgressiveRound> steep{{8, 1, 0.16}, {32, 2, 0.01}};
    EXPECT_EQ(predict(steep, 0.005, 65536)->spp, static_cast<int>(std::ceil(32 * 2 * 1.05)));
    // Held at -1/2 instead: a quarter of the error needs 16 times the samples.
    EXPECT_EQ(predict(steep, 0.0025, 65536, -0.5)->spp,
              static_cast<int>(std::ceil(32 * 16 * 1.05)));
}

TEST(Predict, FromOneRoundTakesTheSlopeOfIndependentSamples) {
    // Slope -1/2: an eighth of the error needs 64 times the samples: 8 * 64 * 1.05 = 537.6.
    const auto p = predict({{8, 1.0, 0.08}}, 0.01, 65536);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->spp, 538);
    EXPECT_DOUBLE_EQ(p->seconds, 538 / 8.0);
    // Rounds without an estimate are skipped: the slope is still the assumed one.
    EXPECT_EQ(predict({{4, 1, std::nullopt}, {8, 1, 0.08}}, 0.01, 65536)->spp, 538);
}

TEST(Predict, TakesTheSlopeOverAtLeastThreefoldTheSamples) {
    // 100 to 120 samples: too narrow a span for a slope, so -1/2 from the last round:
    // 120 * 1.21 * 1.05 = 152.46.
    EXPECT_EQ(predict({{100, 1, 0.2}, {120, 1, 0.011}}, 0.01, 65536)->spp, 153);
    // With a round a third as large before them, the slope from it: 40 to 120 samples, error
    // 0.022 to 0.011, slope -0.63; 120 * 1.1^(1 / 0.63) * 1.05 = 146.5.
    const std::vector<ProgressiveRound> rounds{{40, 1, 0.022}, {100, 1, 0.2}, {120, 1, 0.011}};
    EXPECT_EQ(predict(rounds, 0.01, 65536)->spp, 147);
}

TEST(Predict, NeedsARoundWithAPositiveEstimate) {
    EXPECT_FALSE(predict({{8, 1, std::nullopt}}, 0.01, 65536));
    EXPECT_FALSE(predict({{8, 1, 0.0}, {32, 2, 0.0}}, 0.01, 65536));
}

TEST(NextRound, ThePredictedCountWhenWithinTheFinalStep) {
    // 32 * 4 * 1.05 = 134.4: at most 12 times 32, so the round the target is predicted to need.
    const std::vector<ProgressiveRound> rounds{{8, 1.0, 0.08}, {32, 2.5, 0.04}};
    const NextRound n = next_round(rounds, 0.02, 65536);
    EXPECT_EQ(n.spp, 135);
    EXPECT_TRUE(n.final);
    // Capped at the maximum, and nothing once it is reached or the target is met.
    EXPECT_EQ(next_round(rounds, 0.02, 100).spp, 100);
    EXPECT_EQ(next_round(rounds, 0.02, 32).spp, 0);
    EXPECT_EQ(next_round(rounds, 0.04, 65536).spp, 0);
}

TEST(NextRound, APilotATwelfthOfAPredictionFurtherAway) {
    // 32 * 256 * 1.05 = 8601.6 -> 8602, more than 12 times 32: a pilot of 8602 / 12 = 717.
    const std::vector<ProgressiveRound> rounds{{8, 1.0, 0.08}, {32, 2.5, 0.04}};
    const NextRound n = next_round(rounds, 0.0025, 65536);
    EXPECT_EQ(n.spp, 717);
    EXPECT_FALSE(n.final);
    // From the first pilot alone (slope -1/2): 8 * 441 * 1.05 = 3704.4 -> a pilot of 309.
    EXPECT_EQ(next_round({{8, 1.0, 0.21}}, 0.01, 65536).spp, 309);
    // A twelfth that is less than 4 times the last round is raised to 4 times: 32 * 16 * 1.05 =
    // 537.6 -> 538, a twelfth 45, raised to 128.
    EXPECT_EQ(next_round(rounds, 0.01, 65536).spp, 128);
}

TEST(NextRound, AtLeastAQuarterMoreAndFourTimesWithoutAnEstimate) {
    // Just over the target: 100 * 1.05 would be 106, raised to 125.
    EXPECT_EQ(next_round({{100, 2, 0.0100001}}, 0.01, 65536).spp, 125);
    const NextRound blind = next_round({{8, 1, std::nullopt}}, 0.01, 65536);
    EXPECT_EQ(blind.spp, 32);
    EXPECT_FALSE(blind.final);
}

TEST(NextRound, AfterAFinalRoundThatMissedASlopeNoSteeperThanMinusAHalf) {
    // The pilots 8 and 32 measure -0.87, which predicts 120 spp as the final round. It misses:
    // from 32 to 120 the slope was -0.80, but the next round goes along -1/2, 120 * 1.04^2 *
    // 1.05 = 136.3 (-0.80 and a quarter more, as before a miss, would have been 150).
    const std::vector<ProgressiveRound> pilots{{8, 1, 0.1}, {32, 1, 0.03}};
    const NextRound final = next_round(pilots, 0.01, 65536);
    EXPECT_EQ(final.spp, 120);
    EXPECT_TRUE(final.final);
    std::vector<ProgressiveRound> missed = pilots;
    missed.push_back({120, 1, 0.0104});
    EXPECT_EQ(next_round(missed, 0.01, 65536).spp, 137);
    // A near miss: at least a tenth more (51 * 1.1 = 56.1), not a quarter (64).
    const NextRound near = next_round({{40, 1, 0.011}}, 0.01, 65536);
    EXPECT_EQ(near.spp, 51);
    EXPECT_TRUE(near.final);
    EXPECT_EQ(next_round({{40, 1, 0.011}, {51, 1, 0.0101}}, 0.01, 65536).spp, 57);
    // A pilot that is not the last round is no miss: the quarter still holds.
    EXPECT_EQ(next_round({{8, 1, 0.2}, {32, 1, 0.0101}}, 0.01, 65536).spp, 40);
}

TEST(PredictedSeconds, ALineThroughTheLastTwoRoundsOrProportionalToOne) {
    EXPECT_DOUBLE_EQ(predicted_seconds({{10, 2.0, {}}}, 100), 20.0);
    EXPECT_DOUBLE_EQ(predicted_seconds({{10, 2.0, {}}, {20, 3.0, {}}}, 100), 1.0 + 0.1 * 100);
    // Times that fall with samples (noise) never predict a free sample: the last round's rate.
    EXPECT_DOUBLE_EQ(predicted_seconds({{10, 3.0, {}}, {20, 2.0, {}}}, 100), 10.0);
}

// ---- the command line --------------------------------------------------------------------------

// Soft shadows and antialiasing; renders in milliseconds.
constexpr const char* kScene = R"(<?xml version="1.0"?>
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
        test::write_bytes(dir_ / "scene.xml", kScene);
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

TEST_F(GoalCli, SppIsTheMaximumAndTheImageIsThePlainRenderOfTheCountReached) {
    // An error no 40 samples reach: the rounds stop at the maximum (the pilot after the first
    // would be far more).
    const Outcome r = run({"scene.xml", "--target-error", "1e-9", "--spp", "40", "-o", "goal.pfm",
                           "--stats", "s.json"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(reached(r.err), 40) << r.err;
    EXPECT_NE(r.err.find("after rounds of 8, 40 spp"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(target 1e-09 not met)"), std::string::npos) << r.err;
    EXPECT_NE(bytes("s.json").find("\"samples_per_pixel\": 40"), std::string::npos);
    EXPECT_NE(bytes("s.json").find("\"target_met\": false"), std::string::npos);
    ASSERT_EQ(run({"scene.xml", "--spp", "40", "-o", "plain.pfm", "-q"}).status, 0);
    EXPECT_EQ(bytes("goal.pfm"), bytes("plain.pfm"));
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
    std::vector<std::string> images;
    for (const std::string threads : {"1", "2"}) {
        const Outcome r = run({"scene.xml", "--target-error", "0.01", "--width", "32", "--height",
                               "24", "-o", "t" + threads + ".pfm", "--threads", threads});
        ASSERT_EQ(r.status, 0) << r.err;
        images.push_back(bytes("t" + threads + ".pfm"));
    }
    EXPECT_EQ(images[0], images[1]);
}

TEST_F(GoalCli, InfoPredictsTheSamplesAndTimeFromPilots) {
    const Outcome r = run({"info", "scene.xml", "--target-error", "0.005"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto groups = regex_groups(
        r.out,
        "\npilots: 8 spp [0-9.]+ s, estimated rmse [0-9.e-]+;( [0-9]+ spp [0-9.]+ s, estimated "
        "rmse [0-9.e-]+;)*\npredicted for --target-error 0.005: ([0-9]+) spp, [0-9.]+ s on this "
        "machine \\(--spp ([0-9]+) alone: [0-9.]+ s\\)\n$");
    ASSERT_EQ(groups.size(), 4u) << r.out;
    EXPECT_EQ(groups[2], groups[3]) << r.out;
    // The render to the target takes the same pilots (its rounds' errors are the same bits) and
    // then the predicted count, and more only where that count's estimate misses the target (here
    // it lands just above it, 0.00514, and one more round follows).
    ASSERT_EQ(
        run({"scene.xml", "--target-error", "0.005", "-o", "g.pfm", "--stats", "s.json", "-q"})
            .status,
        0);
    const std::string stats = bytes("s.json");
    EXPECT_NE(stats.find("\"target_met\": true"), std::string::npos) << stats;
    EXPECT_NE(stats.find("{\"spp\": " + groups[2] + ", \"seconds\""), std::string::npos) << stats;
    const auto spp = regex_groups(stats, "\"samples_per_pixel\": ([0-9]+),");
    ASSERT_EQ(spp.size(), 2u) << stats;
    EXPECT_GE(std::stoi(spp[1]), std::stoi(groups[2])) << stats;
    const Outcome bad = run({"info", "scene.xml", "--target-error", "0"});
    EXPECT_EQ(bad.status, 2);
    EXPECT_EQ(bad.err,
              "drt info: --target-error: must be a finite positive number, got 0\n"
              "Run 'drt info --help' for usage.\n");
}

}  // namespace
}  // namespace drt
