// A Mesh without a Material attribute, rendered: each face shows its own MTL material.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "drt/render/renderer.h"
#include "drt/scene/scene_loader.h"
#include "temp_folder.h"

namespace drt {
namespace {

class ObjMaterialsRender : public test::TempFolderTest {
  protected:
    void write(const std::string& name, std::string_view contents) const {
        std::ofstream(dir_ / name, std::ios::binary)
            .write(contents.data(), static_cast<std::streamsize>(contents.size()));
    }
};

// Two unit-height quads side by side at z = 0, seen head-on under white ambient light alone, so
// that a pixel shows its face's kd exactly.
TEST_F(ObjMaterialsRender, EachFaceShowsItsMaterialsColour) {
    write("m.obj",
          "v -2 -1 0\nv 0 -1 0\nv 0 1 0\nv -2 1 0\nv 2 -1 0\nv 2 1 0\n"
          "mtllib m.mtl\nusemtl left\nf 1 2 3 4\nusemtl right\nf 2 5 6 3\n");
    write("m.mtl", "newmtl left\nKd 0.9 0.1 0.1\nnewmtl right\nKd 0.1 0.9 0.1\n");
    write("s.xml",
          "<Scene><Image Width=\"8\" Height=\"4\"/><Render Samples=\"1\"/>\n"
          "<Ambient r=\"1\" g=\"1\" b=\"1\"/>\n"
          "<Camera Ex=\"0\" Ey=\"0\" Ez=\"5\" Lx=\"0\" Ly=\"0\" Lz=\"0\" Fov=\"30\"/>\n"
          "<Mesh File=\"m.obj\" Smooth=\"0\"/></Scene>\n");
    const LoadedScene loaded = load_scene(dir_ / "s.xml");
    RenderOptions options;
    options.threads = 1;
    const Image image = render(loaded.scene, options).image;
    // Pixel columns 1 and 6 look at x = ±1.67 on the quads; which one is on the image's left
    // follows the camera's convention, so only the pair is asserted, and that they differ.
    for (const int y : {1, 2}) {
        const Color a = image.at(1, y), b = image.at(6, y);
        const Color& red = a.r > b.r ? a : b;
        const Color& green = a.r > b.r ? b : a;
        EXPECT_NEAR(red.r, 0.9, 1e-6);
        EXPECT_NEAR(red.g, 0.1, 1e-6);
        EXPECT_NEAR(red.b, 0.1, 1e-6);
        EXPECT_NEAR(green.r, 0.1, 1e-6);
        EXPECT_NEAR(green.g, 0.9, 1e-6);
        EXPECT_NEAR(green.b, 0.1, 1e-6);
    }
}

}  // namespace
}  // namespace drt
