#include "drt/scene/scene.h"

#include <algorithm>

namespace drt {

Camera Scene::camera() const {
    if (view) return Camera::look_at(*view, settings.width, settings.height, lens);
    return Camera::thesis_default(settings.width, settings.height, lens, settings.pixel_plane_unit);
}

double Scene::shutter_end() const {
    double end = 0;
    bool any_travels = false;
    for (const auto& object : objects) {
        end = std::max(end, object->motion_end());
        any_travels = any_travels || object->travels();
    }
    // Paths that all stay in one place blur nothing, so no shutter time is drawn; where anything
    // moves, the longest path sets the shutter, a still one included.
    return any_travels ? end : 0;
}

const Material* Scene::find_material(const std::string& name) const {
    for (const auto& m : materials) {
        if (m->name == name) return m.get();
    }
    return nullptr;
}

}  // namespace drt
