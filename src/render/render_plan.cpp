#include "drt/render/render_plan.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "drt/render/photon_map.h"

namespace drt {

namespace {

// Splits `total` rays among lights in proportion to `powers` (Cook), at least one each: a light
// whose share is under one ray gets one, and the others share the rest in proportion, again
// and again until every share left is at least one. Whole rays by largest remainder (the more
// powerful light first among equal remainders), so that the counts add up to `total` exactly
// and a share that is a whole number is given exactly (1:3 of 8 rays is 2 and 6).
std::vector<int> share_rays(int total, const std::vector<double>& powers) {
    const std::size_t n = powers.size();
    std::vector<int> counts(n, 0);
    if (total <= static_cast<int>(n)) return std::vector<int>(n, 1);
    // Unfixed lights' shares of `left` rays; every power 0 shares equally.
    int left = total;
    const auto shares = [&] {
        double sum = 0;
        std::size_t unfixed = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (counts[i] == 0) sum += powers[i], ++unfixed;
        }
        std::vector<double> share(n, 0.0);
        for (std::size_t i = 0; i < n; ++i) {
            if (counts[i] == 0)
                share[i] =
                    sum > 0 && std::isfinite(sum) ? left * powers[i] / sum : double(left) / unfixed;
        }
        return share;
    };
    std::vector<double> share = shares();
    for (bool fixed_one = true; fixed_one;) {
        fixed_one = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (counts[i] == 0 && share[i] < 1) counts[i] = 1, --left, fixed_one = true;
        }
        if (fixed_one) share = shares();
    }
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < n; ++i) {
        if (counts[i] != 0) continue;
        counts[i] = static_cast<int>(std::floor(share[i]));
        left -= counts[i];
        share[i] -= counts[i];
        order.push_back(i);
    }
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return share[a] != share[b] ? share[a] > share[b] : powers[a] > powers[b];
    });
    for (std::size_t k = 0; left > 0; ++k, --left) ++counts[order[k % order.size()]];
    return counts;
}

}  // namespace

RenderPlan plan_render(const Scene& scene) {
    RenderPlan plan;
    const RenderSettings& s = scene.settings;
    Effects& e = plan.effects;
    e.antialiasing = s.samples > 1;
    e.depth_of_field = !scene.lens.is_pinhole();
    plan.shutter_end = scene.shutter_end();
    e.motion_blur = plan.shutter_end > 0;
    e.indirect_light = s.integrator == IntegratorKind::kPath;
    plan.emitters = Emitters(scene);

    bool diffuse_used = false, focusing = false;
    for (const auto& object : scene.objects) {
        const Material& m = object->material();
        diffuse_used = diffuse_used || m.has_diffuse();
        focusing = focusing || m.reflects() || m.transmits();
        if (s.max_depth > 0 && m.is_glossy()) {
            // Glass reflects part of the light too, so a glossy transparent material also
            // perturbs reflections.
            e.glossy_reflection = e.glossy_reflection || m.reflects() || m.transmits();
            e.glossy_refraction = e.glossy_refraction || m.transmits();
        }
    }

    std::vector<double> area_powers;
    for (const auto& light : scene.lights) {
        if (!light->is_point()) area_powers.push_back(std::max(0.0, light->power()));
    }
    for (std::size_t i = 0; i < plan.emitters.size(); ++i) {
        if (plan.emitters.is_point(i)) continue;
        area_powers.push_back(plan.emitters[i].power);
        plan.area_emitters.push_back(i);
    }
    e.soft_shadows = diffuse_used && !area_powers.empty();
    bool photon_source = false;
    for (std::size_t i = 0; i < plan.emitters.size(); ++i) {
        photon_source = photon_source || (plan.emitters[i].kind != Emitters::Kind::kEnvironment &&
                                          plan.emitters[i].power > 0);
    }
    e.caustics = s.photons && s.max_depth > 0 && diffuse_used && focusing && photon_source;

    const int area_count = static_cast<int>(area_powers.size());
    std::vector<int> area_rays;
    if (area_count > 0 && s.shadow_rays >= area_count) {
        area_rays = share_rays(s.shadow_rays, area_powers);
    } else if (area_count > 0) {
        plan.shared_rays = s.shadow_rays;
        area_rays.assign(area_powers.size(), 0);
        const double sum = std::accumulate(area_powers.begin(), area_powers.end(), 0.0);
        double running = 0;
        for (double p : area_powers) {
            running += sum > 0 ? p / sum : 1.0 / area_count;
            plan.light_pick_cdf.push_back(running);
        }
        plan.light_pick_cdf.back() = 1.0;
    }
    std::size_t next_area = 0;
    for (const auto& light : scene.lights) {
        plan.shadow_rays.push_back(light->is_point() ? 1 : area_rays[next_area++]);
    }
    for (std::size_t i = 0; i < plan.emitters.size(); ++i) {
        plan.emitter_rays.push_back(plan.emitters.is_point(i) ? 1 : area_rays[next_area++]);
    }
    return plan;
}

std::string describe(const Scene& scene, const RenderPlan& plan) {
    const RenderSettings& s = scene.settings;
    std::ostringstream out;
    std::size_t moving = 0;
    for (const auto& object : scene.objects) moving += object->travels() ? 1 : 0;
    out << "scene: " << scene.path << "\n"
        << "image: " << s.width << "x" << s.height << "\n"
        << "samples per pixel: " << s.samples << "\n"
        << "shadow rays: " << s.shadow_rays << "\n"
        << "max depth: " << s.max_depth << "\n"
        << "glossy rays: " << s.glossy_rays << "\n"
        << "seed: " << s.seed << "\n"
        << "sampler: " << s.sampler << "\n";
    const bool path = s.integrator == IntegratorKind::kPath;
    out << "integrator: "
        << (path ? "path (unbiased path tracing)" : "distributed (Cook's distributed ray tracing)")
        << "\n";
    out << "camera: " << (scene.view ? "look-at" : "thesis pixel plane")
        << (scene.lens.is_pinhole() ? ", pinhole" : ", thin lens") << "\n"
        << "materials: " << scene.materials.size() << "\n"
        << "objects: " << scene.objects.size() << " (" << moving << " moving)\n"
        << "lights: " << scene.lights.size() << "\n";
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        out << "  light " << i << ": " << (scene.lights[i]->is_point() ? "point" : "sphere")
            << ", power " << scene.lights[i]->power() << ", shadow rays per shading point "
            << plan.shadow_rays[i] << "\n";
    }
    std::size_t emitting_planes = 0;
    for (const auto& object : scene.objects) {
        const Shapes shapes = object->shapes();
        emitting_planes += object->material().emits() ? shapes.planes.size() : 0;
    }
    out << "emitters: " << plan.emitters.size() << "\n";
    for (std::size_t i = 0; i < plan.emitters.size(); ++i) {
        const Emitters::Emitter& e = plan.emitters[i];
        out << "  emitter " << i << ": ";
        switch (e.kind) {
            case Emitters::Kind::kPoint:
                out << "point light with Falloff 1";
                break;
            case Emitters::Kind::kSphere:
                out << "emitting sphere of radius " << e.radius;
                break;
            case Emitters::Kind::kTriangles:
                out << "emitting triangles (" << e.triangles.size() << ")";
                break;
            case Emitters::Kind::kEnvironment:
                out << "environment map, intensity " << e.environment->intensity();
                break;
        }
        out << ", power " << e.power << ", shadow rays per shading point " << plan.emitter_rays[i]
            << "\n";
    }
    if (emitting_planes > 0) {
        out << "  emitting planes: " << emitting_planes
            << " (seen by rays; their light found by rays in cosine-weighted directions)\n";
    }
    if (plan.shared_rays > 0) {
        out << "  fewer shadow rays than area lights: each of " << plan.shared_rays
            << " rays picks an area light in proportion to power\n";
    }
    const Effects& e = plan.effects;
    auto flag = [](bool on) { return on ? "sampled" : "off"; };
    out << "effects:\n"
        << "  antialiasing: " << flag(e.antialiasing) << "\n"
        << "  soft_shadows: " << flag(e.soft_shadows) << "\n"
        << "  glossy_reflection: " << flag(e.glossy_reflection) << "\n"
        << "  glossy_refraction: " << flag(e.glossy_refraction) << "\n"
        << "  depth_of_field: " << flag(e.depth_of_field) << "\n"
        << "  motion_blur: " << flag(e.motion_blur);
    if (e.motion_blur) out << " (shutter 0.." << plan.shutter_end << ")";
    out << "\n";
    out << "  indirect_light: " << flag(e.indirect_light) << "\n";
    if (s.photons) {
        out << "  caustics: " << flag(e.caustics);
        if (e.caustics) {
            out << " (photon maps: " << s.photons->count
                << " photons a pass, one pass a sample; first gather radius "
                << first_photon_radius(scene) << ")";
        } else if (s.max_depth == 0) {
            out << " (<Photons> given, but MaxDepth 0 lets no light reflect or refract)";
        } else {
            out << " (<Photons> given, but no Falloff-1 light or emitter, reflective or "
                   "transparent surface and diffuse surface together)";
        }
        out << "\n";
    }
    return out.str();
}

}  // namespace drt
