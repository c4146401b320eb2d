// What the commands of the `drt` command line (cli.h) share: exit statuses, option validators,
// the options that override a scene's settings, and each command's entry point. Internal to the
// command line: nothing outside src/cli*.cpp includes it.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "drt/goal/goal_render.h"
#include "drt/render/render_context.h"
#include "drt/scene/scene.h"

namespace drt {

class MpiJob;

namespace cli {

// Exit statuses (cli.h).
constexpr int kOk = 0;
constexpr int kFailed = 1;
constexpr int kBadInput = 2;
// A render stopped by SIGINT (or by --stop-after-tiles, which stands for one): 128 + 2.
constexpr int kInterrupted = 130;

// A setting past one of the limits of limits.h once the options are applied: bad input.
class LimitError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// The status a command exits with after `error`, whose message it writes on `err`: bad input
// (kBadInput) for a scene, image, checkpoint or limit error, a failure (kFailed) for any other,
// out of memory included. Messages start with `command` ("drt converge"); a limit error and a
// failure also name `subject` (printable: the scene the command works on) unless it is empty.
int report_failure(const std::exception& error, const std::string& command,
                   const std::string& subject, std::ostream& err);

// The status of a render stopped before its end: 128 + the signal that stopped it, or
// kInterrupted when --stop-after-tiles stood for one.
int interrupted_status();

// An integer option from `lowest` to `limit` (messages are made printable where they are shown).
// CLI11's own range checks print a double's bounds in full (309 digits) and its unsigned conversion
// takes -1 for 2^64 - 1.
CLI::Validator integer_in(long long lowest, unsigned long long limit);

// A finite number above zero (CLI::PositiveNumber lets "nan" and "inf" through).
CLI::Validator finite_positive();
// A finite number of zero or more (CLI::NonNegativeNumber's message prints a double's bounds in
// full, 309 digits).
CLI::Validator finite_non_negative();

// Parses a subcommand's arguments: its help on `out` (exit kOk), or a parse error on `err` with a
// pointer to `COMMAND --help` (exit kBadInput); nothing when the command should go on.
std::optional<int> parse_arguments(CLI::App& app, int argc, const char* const* argv,
                                   const std::string& command, std::ostream& out,
                                   std::ostream& err);

// Command-line settings that override the scene's <Image> and <Render>.
struct Overrides {
    std::optional<int> spp, shadow_rays, width, height, glossy_rays, max_depth;
    std::optional<std::uint64_t> seed;  // from a text the validator has checked, not CLI11's
    std::optional<std::string> sampler;
    std::optional<double> scale;

    void add_to(CLI::App& app);
    // Throws LimitError when --scale makes the image too large.
    void apply(RenderSettings& s) const;
};

// --noise-threshold and --min-spp: adaptive sampling, with --spp (or Render Samples) the maximum.
struct AdaptiveFlags {
    std::optional<double> noise_threshold;
    int min_spp = 16;

    // Returns --noise-threshold, for options that exclude it.
    CLI::Option* add_to(CLI::App& app);
    std::optional<AdaptiveSampling> settings() const;
};

// Writes text and a final newline through a temporary file and a rename, like the images.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

// The rounds before the final one that a render of `scene` to `target` takes (goal_render.h) and
// what they predict
// for its final round: `drt info --target-error`, and `drt converge --target-error` beside what
// it measures (cli_info.cpp).
struct GoalForecast {
    std::vector<GoalRound> rounds;
    int final_round = 0;              // the final round's count; 0 when the rounds reach it
    std::optional<Prediction> total;  // all rounds together
    // All rounds together if the final round's error falls only as N^-1/2 (that of independent
    // samples): the final round is sized on the short side, so where it falls short this is the
    // better guess.
    std::optional<Prediction> slow;
};

// The goal render's pilots, and what they predict for a target error within `max_samples`.
GoalForecast forecast(const Scene& scene, double target, int threads, int max_samples);
std::string forecast_text(const GoalForecast& f, double target);
// forecast_text, or why no forecast can be made (caustics, which refuse a goal).
std::string goal_forecast(const Scene& scene, double target, int threads, int max_samples);

// The commands, each in a file of its own. argv as CLI11 parses it: argv[0] names the program or
// the command, the options follow.
// `drt SCENE...` (cli_render.cpp; batches in cli_batch.cpp, --stats in cli_stats.cpp).
int render_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
                   const MpiJob* mpi);
// `drt compare A B` (cli_compare.cpp).
int compare_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err);
// `drt info SCENE` (cli_info.cpp).
int info_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err);
// `drt converge SCENE` (cli_converge.cpp).
int converge_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace cli
}  // namespace drt
