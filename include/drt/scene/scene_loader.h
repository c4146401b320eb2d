// Reads the thesis's XML scene format (docs/scene-format.md) into a Scene.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "drt/scene/scene.h"

namespace drt {

// A scene that cannot be rendered. what() is the whole message: "FILE:LINE: Element: message".
class SceneError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

struct LoadedScene {
    Scene scene;
    // "FILE:LINE: warning: ..." for every unknown element or attribute, naming the nearest known
    // one.
    std::vector<std::string> warnings;
    // Every file the scene file made the loader read (the OBJ files of its meshes), in the order
    // read: with the scene file, what a checkpoint's fingerprint covers (checkpoint.h).
    std::vector<std::filesystem::path> files_read;
};

LoadedScene load_scene(const std::filesystem::path& path);
// `name` stands for the file in messages.
LoadedScene load_scene_from_string(std::string_view xml, const std::string& name);

}  // namespace drt
