// What a scene calls for, worked out once before rendering: which Monte Carlo dimensions must be
// sampled and how the shadow rays are shared. Everything the scene does not call for is skipped
// (no lens sample without a lens, no time sample without motion, ...), so it costs nothing.
#pragma once

#include <string>
#include <vector>

#include "drt/scene/emitters.h"
#include "drt/scene/scene.h"

namespace drt {

// Whether each effect is sampled. The integrator reads these and nothing else to decide; how
// much (σ, lens radius, shutter, shadow rays) still comes from the scene and the plan below.
struct Effects {
    bool antialiasing = false;       // more than one camera ray per pixel
    bool soft_shadows = false;       // an area light and a diffuse surface to cast its penumbra on
    bool glossy_reflection = false;  // a reflecting material with finite sharpness
    bool glossy_refraction = false;  // a transparent material with finite sharpness
    bool depth_of_field = false;     // a lens of non-zero radius
    bool motion_blur = false;        // a moving object
    bool indirect_light = false;     // the path integrator: light scattered by diffuse surfaces
    // <Photons>, a photon source (a Falloff-1 light or an emitting sphere or mesh), a reflective
    // or transparent surface to focus its light and a diffuse one to receive it (photon_map.h).
    bool caustics = false;
};

struct RenderPlan {
    Effects effects;
    // Shadow rays for each light per shading point: 1 for a point light; for area lights the
    // scene's ShadowRays shared in proportion to power (every area light gets at least one).
    // When there are more area lights than shadow rays, each ray instead picks a light at
    // random in proportion to power: shared_rays > 0 then and the per-light counts are 0.
    std::vector<int> shadow_rays;
    int shared_rays = 0;
    std::vector<double> light_pick_cdf;  // over the area lights' powers, for shared rays
    // The physical lights (emitters.h), which share the shadow rays with the lights as area
    // lights do (a Falloff-1 point light gets exactly one): their rays per shading point, 0 when
    // shared; a shared ray's pick beyond the area lights is area_emitters[pick - area lights].
    Emitters emitters;
    std::vector<int> emitter_rays;
    std::vector<std::size_t> area_emitters;
    double shutter_end = 0;
};

RenderPlan plan_render(const Scene& scene);

// Human-readable account of the scene and the plan, for `drt info`.
std::string describe(const Scene& scene, const RenderPlan& plan);

}  // namespace drt
