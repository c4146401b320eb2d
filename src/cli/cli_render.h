// What the parts of the render command share: `drt SCENE...` renders each scene (cli_render.cpp),
// several of them as a batch with a summary table and a report (cli_batch.cpp), and writes
// statistics as JSON (cli_stats.cpp). Internal to the command line, like cli_common.h.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "cli_common.h"
#include "drt/goal/goal_render.h"
#include "drt/render/renderer.h"
#include "drt/scene/scene.h"

namespace drt::cli {

// What rendering one scene came to, for the batch's summary, its report and --stats.
struct SceneOutcome {
    std::string scene;
    std::filesystem::path output;
    int status = kOk;
    int width = 0, height = 0, samples = 0;
    double seconds = 0;
    double mrays_per_second = 0;
    std::string json;
};

// -o names a folder (it exists, or ends in '/'): each scene's image goes into it.
bool is_folder_target(const std::string& output);

// One line per scene: size, samples, seconds, rays per second, status.
void print_summary(const std::vector<SceneOutcome>& outcomes, std::ostream& out);

// --report with --reference-dir: a batch's images against references of the same names.
struct BatchReport {
    bool wanted = false;
    std::string reference_dir;
    double max_rmse = 0;

    void add_to(CLI::App& app);
    // Writes the report of the batch in `folder` and returns the status it adds: 1 when an image
    // differs beyond --max-rmse or could not be made, 2 when a reference is missing or unreadable.
    int write(const std::vector<SceneOutcome>& outcomes, const std::filesystem::path& folder,
              bool quiet, std::ostream& err) const;
};

// The --stats JSON of one scene's render; `goal`: goal_json's lines, or nothing.
std::string stats_json(const Scene& scene, const RenderResult& r, const std::string& goal = {});

// The rounds of a render to a goal (--target-error, --time-limit), as lines of stats_json.
std::string goal_json(const GoalResult& p, const std::optional<double>& target,
                      const std::optional<double>& limit);

}  // namespace drt::cli
