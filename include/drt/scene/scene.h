// The scene graph the loader builds and the integrator reads: settings, camera, materials,
// lights and objects.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drt/geometry/object.h"
#include "drt/scene/camera.h"
#include "drt/scene/environment.h"
#include "drt/scene/light.h"
#include "drt/shading/material.h"
#include "drt/util/color.h"

namespace drt {

// How light is carried: the thesis's distributed ray tracer, or unbiased path tracing
// (docs/scene-format.md, "Light transport").
enum class IntegratorKind { kDistributed, kPath };

// <Photons>: caustics from photon maps (docs/scene-format.md, "Caustics: photon maps"). Each
// progressive pass (one per camera sample index) traces `count` photons; the first pass gathers
// within `radius`, 0 meaning drt's default (photon_map.h).
struct PhotonSettings {
    static constexpr int kDefaultCount = 10000;
    int count = kDefaultCount;
    double radius = 0;
};

struct RenderSettings {
    int width = 640;
    int height = 480;
    int samples = 16;     // camera rays per pixel
    int shadow_rays = 1;  // per shading point, shared among the area lights
    int max_depth = 8;    // longest chain of reflection/refraction bounces
    int glossy_rays = 1;  // rays per glossy reflection/refraction at the first hit
    std::uint64_t seed = 0;
    std::string sampler = "stratified";
    IntegratorKind integrator = IntegratorKind::kDistributed;
    // The path integrator's opt-in clamp: a camera sample's radiance whose luminance exceeds it
    // is scaled down to it (biased: it hides fireflies by losing light). 0: off.
    double clamp = 0;
    // World units per pixel of the thesis's pixel-plane camera: 1 as the scene format defines
    // it; drt --scale changes it so a smaller or larger image keeps the same framing.
    double pixel_plane_unit = 1;
    std::optional<PhotonSettings> photons;  // absent: no <Photons>, no photons traced
};

// A point light with Falloff 1: it adds I·max(0, N·L)/r² to the thesis's sum of lights. (A sphere
// light with Falloff 1 becomes an emitting sphere among the objects instead.)
struct InverseSquareLight {
    Vec3 position;
    Color intensity;
};

struct Scene {
    std::string path;  // the file it came from, for messages
    RenderSettings settings;
    Color background;
    // <Environment>: when present, escaping rays see it instead of Background, and it lights
    // diffuse surfaces as an emitter (emitters.h).
    std::shared_ptr<const Environment> environment;
    Color ambient;
    std::optional<LookAt> view;  // absent: the thesis's pixel-plane camera
    Lens lens;
    // Objects refer to materials by address, so materials live behind stable pointers.
    std::vector<std::unique_ptr<Material>> materials;
    std::vector<std::unique_ptr<Light>> lights;
    std::vector<std::unique_ptr<Object>> objects;
    std::vector<InverseSquareLight> inverse_square_lights;

    // The camera for the current settings (the default camera depends on the image size).
    Camera camera() const;
    // Shutter times run over [0, shutter_end()]: the longest motion path in segments; 0 when no
    // path goes anywhere.
    double shutter_end() const;
    const Material* find_material(const std::string& name) const;
};

}  // namespace drt
