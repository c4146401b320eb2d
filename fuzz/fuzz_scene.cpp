// libFuzzer target: a scene file as deep as the renderer goes. Whatever loads is rendered, cut
// down to a few pixels and samples so that each input takes milliseconds: loading is fuzzed in
// full, rendering for every effect the scene calls for. A NaN pixel is a defect wherever it comes
// from; an infinite one may be the scene's own radiance past the float range.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drt/render/renderer.h"
#include "drt/scene/render_limits.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/limits.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    drt::LoadedScene loaded;
    try {
        loaded = drt::load_scene_from_string(
            std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.xml");
    } catch (const drt::SceneError&) {
        return 0;  // rejected with a message: what the loader should do
    }
    drt::RenderSettings& s = loaded.scene.settings;
    // Within the limits the loader has just checked, or it let something through.
    if (drt::render_limit_problem(s, 1)) __builtin_trap();
    // Keep the framing of a larger image (as --scale does) while rendering only a few pixels.
    const double scale = std::min(1.0, 4.0 / std::max(s.width, s.height));
    s.width = std::max(1, static_cast<int>(s.width * scale));
    s.height = std::max(1, static_cast<int>(s.height * scale));
    s.pixel_plane_unit /= scale;
    s.samples = std::min(s.samples, 4);
    s.shadow_rays = std::min(s.shadow_rays, 4);
    s.glossy_rays = std::min(s.glossy_rays, 4);
    s.max_depth = std::min(s.max_depth, 6);
    drt::RenderOptions options;
    options.threads = 1;
    const drt::RenderResult r = drt::render(loaded.scene, options);
    for (const float v : r.image.rgb) {
        if (std::isnan(v)) __builtin_trap();
    }
    return 0;
}
