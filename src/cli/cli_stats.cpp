#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <string>

#include "cli_render.h"
#include "drt/goal/goal_render.h"
#include "drt/render/error_estimate.h"
#include "drt/render/render_plan.h"

namespace drt::cli {

namespace {

std::string json_bool(bool b) {
    return b ? "true" : "false";
}

// JSON has no NaN or infinity: those become null.
std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    std::ostringstream text;
    text << std::setprecision(6) << v;
    return text.str();
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\')
            out += '\\', out += c;
        else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else
            out += c;
    }
    return out + "\"";
}

}  // namespace

std::string goal_json(const GoalResult& p, const std::optional<double>& target,
                      const std::optional<double>& limit) {
    std::ostringstream j;
    j << "  \"goal\": {\"target_error\": " << (target ? json_number(*target) : "null")
      << ", \"time_limit\": " << (limit ? json_number(*limit) : "null")
      << ", \"target_met\": " << json_bool(p.target_met)
      << ", \"combined\": " << json_bool(p.combined) << ", \"rounds\": [";
    for (std::size_t i = 0; i < p.rounds.size(); ++i) {
        const GoalRound& r = p.rounds[i];
        j << (i ? ", " : "") << "{\"spp\": " << r.spp;
        // A combined full round's seed renders it alone (--spp N --seed S): a string, as 64 bits
        // are beyond a JSON number's exact range. A top-up's pattern covers only some pixels and
        // a pilot is not part of the image: no plain render repeats them.
        if (r.kind == RoundKind::kTopUp) {
            j << ", \"top_up_share\": " << json_number(r.top_up_share);
        } else if (r.kind == RoundKind::kPilot) {
            j << ", \"pilot_pixel_block\": " << r.pixel_block;
        } else if (p.combined) {
            j << ", \"seed\": \"" << r.seed << "\"";
        }
        j << ", \"seconds\": " << json_number(r.seconds)
          << ", \"estimated_rmse\": " << (r.error ? json_number(*r.error) : "null") << "}";
    }
    j << "]},\n";
    return j.str();
}

std::string stats_json(const Scene& scene, const RenderResult& r, const std::string& goal) {
    const RayCounts& rays = r.stats.rays;
    const Effects& e = r.plan.effects;
    const RenderSettings& s = scene.settings;
    std::ostringstream j;
    j << std::setprecision(6);
    j << "{\n  \"scene\": " << json_string(scene.path) << ",\n"
      << "  \"seconds\": " << json_number(r.stats.seconds) << ",\n"
      << "  \"width\": " << s.width << ", \"height\": " << s.height
      << ", \"samples_per_pixel\": " << s.samples << ",\n"
      << "  \"shadow_rays\": " << s.shadow_rays << ", \"glossy_rays\": " << s.glossy_rays
      << ", \"max_depth\": " << s.max_depth << ", \"seed\": " << s.seed
      << ", \"sampler\": " << json_string(s.sampler) << ", \"threads\": " << r.stats.threads
      << ", \"processes\": " << r.stats.processes << ",\n"
      << "  \"tail_seconds\": " << json_number(r.stats.tail_seconds) << ",\n";
    if (r.stats.tile_messages > 0) {
        const double n = double(r.stats.tile_messages);
        j << "  \"tile_messages\": " << r.stats.tile_messages
          << ", \"microseconds_per_message\": {\"receive\": "
          << json_number(r.stats.receive_seconds / n * 1e6)
          << ", \"assemble\": " << json_number(r.stats.assemble_seconds / n * 1e6) << "},\n";
    }
    j << "  \"rays\": {\"camera\": " << rays.camera << ", \"shadow\": " << rays.shadow
      << ", \"reflection\": " << rays.reflection << ", \"refraction\": " << rays.refraction;
    j << ", \"diffuse\": " << rays.diffuse;
    j << ", \"total\": " << rays.total() << "},\n"
      << "  \"million_rays_per_second\": "
      << json_number(r.stats.seconds > 0 ? rays.total() / r.stats.seconds / 1e6 : 0.0) << ",\n"
      << "  \"mean_spp\": " << json_number(double(r.stats.samples) / (double(s.width) * s.height))
      << ",\n";
    if (s.photons) j << "  \"photons\": " << r.stats.photons << ",\n";
    const ErrorEstimate& error = r.stats.error;
    if (error.available()) {
        j << "  \"estimated_rmse\": " << json_number(*error.rmse)
          << ", \"estimated_relmse\": " << json_number(*error.relmse)
          << ", \"estimate_cost\": " << json_number(error.cost)
          << ", \"error_pixels\": " << json_number(error.error_pixels)
          << ", \"rmse_scatter\": " << json_number(error.rmse_scatter()) << ",\n";
    } else {
        j << "  \"estimated_rmse\": null, \"estimated_relmse\": null, \"estimate_unavailable\": "
          << json_string(error.unavailable) << ",\n";
    }
    if (const auto& a = r.stats.adaptive) {
        j << "  \"adaptive\": {\"noise_threshold\": " << json_number(a->noise_threshold)
          << ", \"min_spp\": " << a->min_samples << ", \"max_spp\": " << s.samples
          << ", \"pixels_converged\": " << r.stats.pixels_converged << "},\n";
    }
    j << goal;
    j << "  \"effects\": {\"antialiasing\": " << json_bool(e.antialiasing)
      << ", \"soft_shadows\": " << json_bool(e.soft_shadows)
      << ", \"glossy_reflection\": " << json_bool(e.glossy_reflection)
      << ", \"glossy_refraction\": " << json_bool(e.glossy_refraction)
      << ", \"depth_of_field\": " << json_bool(e.depth_of_field)
      << ", \"motion_blur\": " << json_bool(e.motion_blur);
    j << ", \"indirect_light\": " << json_bool(e.indirect_light);
    if (s.photons) j << ", \"caustics\": " << json_bool(e.caustics);
    j << "}\n}";
    return j.str();
}

}  // namespace drt::cli
