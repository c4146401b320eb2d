// Small scenes built in code, for tests that must not depend on the loader.
#pragma once

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "drt/scene/scene.h"
#include "drt/scene/scene_loader.h"

namespace drt::testing {

inline Material& add_material(Scene& scene, Material m) {
    scene.materials.push_back(std::make_unique<Material>(std::move(m)));
    return *scene.materials.back();
}

// The default material, for objects whose material a test does not look at.
inline const Material& plain_material() {
    static const Material material{};
    return material;
}

inline Material grey_lambert(double kd = 0.8) {
    Material m;
    m.name = "grey";
    m.diffuse = 1;
    m.kd = {kd, kd, kd};
    return m;
}

inline Material mirror(Color ks, std::optional<double> sharpness = std::nullopt) {
    Material m;
    m.name = "mirror";
    m.reflective = 1;
    m.ks = ks;
    m.sharpness = sharpness;
    return m;
}

inline Material glass(double index, std::optional<double> sharpness = std::nullopt) {
    Material m;
    m.name = "glass";
    m.transmit = 1;
    m.kt = {1, 1, 1};
    m.index = index;
    m.sharpness = sharpness;
    return m;
}

// A scene of `width` x `height` pixels and `samples` samples per pixel, with nothing in it yet.
inline Scene blank_scene(int width, int height, int samples) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = width;
    scene.settings.height = height;
    scene.settings.samples = samples;
    return scene;
}

// A camera at height `height` above the floor y = 0, looking straight down.
inline Scene floor_scene(int width, int height, double eye_height = 50) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = width;
    scene.settings.height = height;
    scene.settings.samples = 1;
    scene.view = LookAt{{0, eye_height, 0}, {0, 0, 0}, {0, 0, 1}, 60};
    const Material& floor = add_material(scene, grey_lambert());
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, floor));
    return scene;
}

// A single sphere of `material` at the origin seen from z = -10 against a uniform background.
inline Scene lone_sphere_scene(Material material, Color background, int size = 32) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = size;
    scene.settings.height = size;
    scene.settings.samples = 1;
    scene.background = background;
    scene.view = LookAt{{0, 0, -10}, {0, 0, 0}, {0, 1, 0}, 20};
    const Material& m = add_material(scene, std::move(material));
    scene.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{0, 0, 0}}, 1.5, m));
    return scene;
}

// A scene of scenes/ (`name` relative to it) at `width` pixels across, framed as drt --scale
// frames it, with `samples` camera samples per pixel.
inline Scene scaled_scene(const std::string& name, int width, int samples) {
    Scene scene = load_scene(std::filesystem::path(DRT_SOURCE_DIR) / "scenes" / name).scene;
    RenderSettings& s = scene.settings;
    const double scale = double(width) / s.width;
    s.width = width;
    s.height = static_cast<int>(std::lround(s.height * scale));
    s.pixel_plane_unit /= scale;
    s.samples = samples;
    return scene;
}

}  // namespace drt::testing
