#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "cli_common.h"
#include "drt/goal/goal_render.h"
#include "drt/job/render_job.h"
#include "drt/render/render_plan.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt::cli {

GoalForecast forecast(const Scene& scene, double target, int threads, int max_samples) {
    RenderGoal goal;
    goal.target_error = target;
    goal.max_samples = max_samples;
    goal.stop_before_final = true;
    RenderJobOptions options;
    options.threads = threads;
    GoalForecast f;
    const GoalResult before_final = render_to_goal(scene, options, goal);
    f.rounds = before_final.rounds;
    if (f.rounds.empty()) return f;
    double seconds = 0;
    for (const GoalRound& r : f.rounds) seconds += r.seconds;
    const NextRound last = next_round(f.rounds, target, max_samples);
    if (last.spp == 0) {
        f.total = Prediction{before_final.samples, seconds};
    } else if (last.final) {
        f.final_round = last.spp;
        f.total = Prediction{before_final.samples + last.spp,
                             seconds + predicted_seconds(f.rounds, last.spp)};
        if (const auto slow = predict(f.rounds, target, max_samples, -0.5);
            slow && slow->spp > last.spp) {
            f.slow = Prediction{before_final.samples + slow->spp, seconds + slow->seconds};
        }
    }
    return f;
}

std::string forecast_text(const GoalForecast& f, double target) {
    std::ostringstream text;
    text << "pilots:";
    for (const GoalRound& r : f.rounds) {
        text << " " << r.spp << " spp";
        if (r.kind == RoundKind::kPilot)
            text << " on 1 pixel in " << r.pixel_block * r.pixel_block << ",";
        text << " " << std::fixed << std::setprecision(3) << r.seconds << " s, estimated rmse "
             << std::defaultfloat << (r.error ? short_number(*r.error) : std::string("n/a")) << ";";
    }
    text << "\npredicted for --target-error " << short_number(target) << ": ";
    if (f.total) {
        // The goal render repeats these rounds, then adds the final round to them.
        text << f.total->spp << " spp, " << std::fixed << std::setprecision(2) << f.total->seconds
             << " s on this machine (rounds of " << std::defaultfloat;
        const char* separator = "";
        for (const GoalRound& r : f.rounds) {
            if (r.full()) text << std::exchange(separator, ", ") << r.spp;
        }
        if (f.final_round > 0) text << separator << f.final_round;
        text << " spp)";
        if (f.slow) {
            text << "; if the error falls only as N^-1/2: " << f.slow->spp << " spp, " << std::fixed
                 << std::setprecision(2) << f.slow->seconds << " s" << std::defaultfloat;
        }
    } else {
        text << "n/a (the pilots give no error estimate to extrapolate)";
    }
    return text.str() + "\n";
}

std::string goal_forecast(const Scene& scene, double target, int threads, int max_samples) {
    if (plan_render(scene).effects.caustics) {
        return "no forecast for --target-error: caustics from photon maps are biased at every "
               "finite gather radius, and a render refuses the goal (docs/accuracy.md)\n";
    }
    const GoalForecast f = forecast(scene, target, threads, max_samples);
    std::string text = forecast_text(f, target);
    if (f.total && f.total->spp >= max_samples) {
        text += "(--spp " + std::to_string(max_samples) +
                " caps the rounds: the target may not be reached)\n";
    }
    return text;
}

int info_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"Show what a scene contains and which effects it calls for", "drt info"};
    std::string scene_path;
    Overrides overrides;
    std::optional<double> target;
    int threads = 0;
    app.add_option("scene", scene_path, "Scene file")->required();
    overrides.add_to(app);
    app.add_option("--target-error", target,
                   "Also predict the samples per pixel and the time a render to this estimated "
                   "RMSE takes here, from short pilot renders")
        ->check(finite_positive());
    app.add_option("--threads", threads, "Worker threads of the pilot renders (default: all cores)")
        ->check(integer_in(1, kMaxThreads));
    if (const auto status = parse_arguments(app, argc, argv, "drt info", out, err)) return *status;
    try {
        LoadedScene loaded = load_scene(scene_path);
        for (const std::string& w : loaded.warnings) err << w << "\n";
        overrides.apply(loaded.scene.settings);
        const RenderPlan plan = plan_render(loaded.scene);
        out << describe(loaded.scene, plan);
        if (target) {
            out << goal_forecast(loaded.scene, *target, threads,
                                 overrides.spp.value_or(kMaxSamples));
        }
    } catch (const SceneError& e) {
        return report_failure(e, "drt info", printable(scene_path), err);
    } catch (const LimitError& e) {  // bad input only: a failure reaches run_cli's last guard
        return report_failure(e, "drt info", printable(scene_path), err);
    }
    return kOk;
}

}  // namespace drt::cli
