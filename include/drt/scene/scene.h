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
#include "drt/scene/light.h"
#include "drt/shading/material.h"
#include "drt/util/color.h"

namespace drt {

struct RenderSettings {
    int width = 640;
    int height = 480;
    int samples = 16;     // camera rays per pixel
    int shadow_rays = 1;  // per shading point, shared among the area lights
    int max_depth = 8;    // longest chain of reflection/refraction bounces
    int glossy_rays = 1;  // rays per glossy reflection/refraction at the first hit
    std::uint64_t seed = 0;
    std::string sampler = "stratified";
    // World units per pixel of the thesis's pixel-plane camera: 1 as the scene format defines
    // it; drt --scale changes it so a smaller or larger image keeps the same framing.
    double pixel_plane_unit = 1;
};

struct Scene {
    std::string path;  // the file it came from, for messages
    RenderSettings settings;
    Color background;
    Color ambient;
    std::optional<LookAt> view;  // absent: the thesis's pixel-plane camera
    Lens lens;
    // Objects refer to materials by address, so materials live behind stable pointers.
    std::vector<std::unique_ptr<Material>> materials;
    std::vector<std::unique_ptr<Light>> lights;
    std::vector<std::unique_ptr<Object>> objects;

    // The camera for the current settings (the default camera depends on the image size).
    Camera camera() const;
    // Shutter times run over [0, shutter_end()]: the longest motion path in segments.
    double shutter_end() const;
    const Material* find_material(const std::string& name) const;
};

}  // namespace drt
