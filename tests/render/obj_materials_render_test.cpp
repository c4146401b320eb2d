// A Mesh without a Material attribute, rendered: each face shows its own MTL material.
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

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

// A 16 x 16 image in four 8 x 8 blocks, top rows first as images are stored: blue, white over
// red, green. (0, 0) is the bottom-left corner, so red is around (u, v) = (0.25, 0.25) and blue
// around (0.25, 0.75). Blocks rather than single texels: a pixel's sample lies anywhere in it,
// and inside a block any filter reads the block's colour.
void write_quadrants(const std::filesystem::path& path) {
    constexpr int kSize = 16;
    std::vector<unsigned char> rgb;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const bool top = y < kSize / 2, left = x < kSize / 2;
            const std::array<unsigned char, 3> c =
                top ? (left ? std::array<unsigned char, 3>{0, 0, 255}
                            : std::array<unsigned char, 3>{255, 255, 255})
                    : (left ? std::array<unsigned char, 3>{255, 0, 0}
                            : std::array<unsigned char, 3>{0, 255, 0});
            rgb.insert(rgb.end(), c.begin(), c.end());
        }
    }
    ASSERT_TRUE(stbi_write_png(path.c_str(), kSize, kSize, 3, rgb.data(), 3 * kSize));
}

void expect_rgb(const Color& c, double r, double g, double b) {
    EXPECT_NEAR(c.r, r, 0.01);
    EXPECT_NEAR(c.g, g, 0.01);
    EXPECT_NEAR(c.b, b, 0.01);
}

// A unit quad (x, y in [-1, 1]) whose corners' vt span [0, 1]^2, seen head-on: its four
// quarters show the image's four texels, in the image's orientation, v upwards.
void expect_quadrants(const Image& image) {
    const Color top_left = image.at(2, 2), top_right = image.at(5, 2);
    const Color bottom_left = image.at(2, 5), bottom_right = image.at(5, 5);
    // Which side is u = 0 follows the camera's convention; up is v's direction either way.
    const bool u_rises_rightwards = bottom_left.r > 0.5;
    expect_rgb(u_rises_rightwards ? bottom_left : bottom_right, 1, 0, 0);
    expect_rgb(u_rises_rightwards ? bottom_right : bottom_left, 0, 1, 0);
    expect_rgb(u_rises_rightwards ? top_left : top_right, 0, 0, 1);
    expect_rgb(u_rises_rightwards ? top_right : top_left, 1, 1, 1);
}

constexpr std::string_view kUvQuad =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";

std::string uv_scene(std::string_view mesh_attributes) {
    return "<Scene><Image Width=\"8\" Height=\"8\"/><Render Samples=\"1\"/>\n"
           "<Ambient r=\"1\" g=\"1\" b=\"1\"/><Materials><White diffuse=\"1\" kdr=\"1\" "
           "kdg=\"1\" kdb=\"1\"/></Materials>\n"
           "<Camera Ex=\"0\" Ey=\"0\" Ez=\"5\" Lx=\"0\" Ly=\"0\" Lz=\"0\" Fov=\"30\"/>\n"
           "<Mesh File=\"m.obj\" Smooth=\"0\" " +
           std::string(mesh_attributes) + "/></Scene>\n";
}

Image render_file(const std::filesystem::path& scene) {
    RenderOptions options;
    options.threads = 1;
    return render(load_scene(scene).scene, options).image;
}

TEST_F(ObjMaterialsRender, AnImageTextureOnAMeshFollowsItsVt) {
    write_quadrants(dir_ / "q.png");
    write("m.obj", std::string(kUvQuad) + "f 1/1 2/2 3/3 4/4\n");
    write("s.xml", uv_scene("Material=\"White\" EnableTexture=\"1\" Texture=\"image\" "
                            "TextureFile=\"q.png\" TextureFilter=\"bilinear\""));
    expect_quadrants(render_file(dir_ / "s.xml"));
}

TEST_F(ObjMaterialsRender, MapKdOfAnMtlMaterialIsItsColour) {
    std::filesystem::create_directories(dir_ / "tex");
    write_quadrants(dir_ / "tex" / "four texels.png");
    write("m.obj", std::string(kUvQuad) + "mtllib m.mtl\nusemtl textured\nf 1/1 2/2 3/3 4/4\n");
    write("m.mtl", "newmtl textured\nKd 1 1 1\nmap_Kd -s 1 1 1 tex\\four texels.png\n");
    write("s.xml", uv_scene(""));
    const LoadedScene loaded = load_scene(dir_ / "s.xml");
    EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
    expect_quadrants(render_file(dir_ / "s.xml"));
}

// Corners without vt are all at (0, 0): the repeating image's corner, where a bilinear lookup
// averages the four blocks' texels there.
TEST_F(ObjMaterialsRender, CornersWithoutVtAreAtTheOrigin) {
    write_quadrants(dir_ / "q.png");
    // A second quad without vt, nearer the camera, in front of the first.
    write("m.obj", std::string(kUvQuad) +
                       "v -1 -1 0.5\nv 1 -1 0.5\nv 1 1 0.5\nv -1 1 0.5\n"
                       "f 1/1 2/2 3/3 4/4\nf 5 6 7 8\n");
    write("s.xml", uv_scene("Material=\"White\" EnableTexture=\"1\" Texture=\"image\" "
                            "TextureFile=\"q.png\" TextureFilter=\"bilinear\""));
    const Image image = render_file(dir_ / "s.xml");
    for (const int x : {2, 5}) {
        for (const int y : {2, 5}) expect_rgb(image.at(x, y), 0.5, 0.5, 0.5);
    }
}

// So are they in a file without any vt (the Triangle's default corners are for <Triangle>s).
TEST_F(ObjMaterialsRender, AFileWithoutVtIsAtTheOriginToo) {
    write_quadrants(dir_ / "q.png");
    write("m.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n");
    write("s.xml", uv_scene("Material=\"White\" EnableTexture=\"1\" Texture=\"image\" "
                            "TextureFile=\"q.png\" TextureFilter=\"bilinear\""));
    const Image image = render_file(dir_ / "s.xml");
    for (const int x : {2, 5}) {
        for (const int y : {2, 5}) expect_rgb(image.at(x, y), 0.5, 0.5, 0.5);
    }
}

// A 16 x 16 mask, left half (u < ½) one value, right half another: as the alpha channel of a
// red RGBA image, or as the grey level of an image without alpha (then its luminance counts).
void write_half_mask(const std::filesystem::path& path, bool with_alpha) {
    constexpr int kSize = 16;
    std::vector<unsigned char> pixels;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const unsigned char on = x < kSize / 2 ? 0 : 255;
            if (with_alpha) {
                pixels.insert(pixels.end(), {255, 0, 0, on});
            } else {
                pixels.push_back(on);
            }
        }
    }
    const int channels = with_alpha ? 4 : 1;
    ASSERT_TRUE(
        stbi_write_png(path.c_str(), kSize, kSize, channels, pixels.data(), channels * kSize));
}

// A red quad at y = 1 over x, z in [-1, 1], its u along +x, above a white floor, seen from
// straight above, lit by a point light at (0, 3, 0) and ambient 0.1. With `map_d`, the quad's
// half u < ½ is cut out.
std::string cut_out_scene(bool with_map_d) {
    return std::string("<Scene><Image Width=\"16\" Height=\"16\"/><Render Samples=\"1\"/>\n") +
           "<Ambient r=\"0.1\" g=\"0.1\" b=\"0.1\"/><Materials><White diffuse=\"1\" "
           "kdr=\"1\" kdg=\"1\" kdb=\"1\"/></Materials>\n"
           "<Camera Ex=\"0\" Ey=\"5\" Ez=\"0\" Lx=\"0\" Ly=\"0\" Lz=\"0\" Ux=\"0\" Uy=\"0\" "
           "Uz=\"1\" Fov=\"40\"/>\n<Light Px=\"0\" Py=\"3\" Pz=\"0\"/>\n"
           "<Plane Px=\"0\" Py=\"0\" Pz=\"0\" Vu=\"0\" Vv=\"1\" Vw=\"0\" Material=\"White\"/>\n"
           "<Mesh File=\"" +
           (with_map_d ? "cut.obj" : "solid.obj") + "\" Smooth=\"0\"/></Scene>\n";
}

constexpr std::string_view kLevelQuad =
    "v -1 1 1\nv 1 1 1\nv 1 1 -1\nv -1 1 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";

// Cut-outs: camera rays see the floor through the quad's cut-out half and the quad elsewhere,
// and shadow rays pass through it too: the floor beside the quad is lit beyond its cut-out half
// and in shadow beyond its solid half. Alpha from the alpha channel, or from the luminance.
TEST_F(ObjMaterialsRender, MapDCutsOutWhereAlphaIsBelowAHalfForEveryRay) {
    write("solid.obj", std::string(kLevelQuad) + "mtllib m.mtl\nusemtl solid\nf 1/1 2/2 3/3 4/4\n");
    write("cut.obj", std::string(kLevelQuad) + "mtllib m.mtl\nusemtl cut\nf 1/1 2/2 3/3 4/4\n");
    write("solid.xml", cut_out_scene(false));
    write("cut.xml", cut_out_scene(true));
    for (const bool with_alpha : {true, false}) {
        write_half_mask(dir_ / "mask.png", with_alpha);
        write("m.mtl", "newmtl solid\nKd 1 0 0\nnewmtl cut\nKd 1 0 0\nmap_d mask.png\n");
        const LoadedScene loaded = load_scene(dir_ / "cut.xml");
        EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
        const Image solid = render_file(dir_ / "solid.xml"), cut = render_file(dir_ / "cut.xml");
        // Pixels 2 and 13 of row 8 look at the floor at x = ±1.25, beside the quad; pixels 5
        // and 10 at the quad's two halves (x = ±0.57).
        const auto lit = [](const Color& c) { return c.g > 0.9; };
        EXPECT_NEAR(solid.at(2, 8).g, 0.1, 1e-6);  // the whole quad's shadow
        EXPECT_NEAR(solid.at(13, 8).g, 0.1, 1e-6);
        EXPECT_NEAR(solid.at(5, 8).g, 0, 1e-9);  // red quad
        EXPECT_NEAR(solid.at(10, 8).g, 0, 1e-9);
        // One side lit through the holes, the other in the solid half's shadow.
        EXPECT_TRUE(lit(cut.at(2, 8)) != lit(cut.at(13, 8))) << with_alpha;
        EXPECT_NEAR(std::min(cut.at(2, 8).g, cut.at(13, 8).g), 0.1, 1e-6);
        // Through the cut-out half the lit floor, on the same side as the lit floor beside it.
        const bool left_cut = lit(cut.at(2, 8));
        EXPECT_TRUE(lit(cut.at(left_cut ? 5 : 10, 8))) << with_alpha;
        EXPECT_NEAR(cut.at(left_cut ? 10 : 5, 8).g, 0, 1e-9) << with_alpha;
        EXPECT_GT(cut.at(left_cut ? 10 : 5, 8).r, 0.9) << with_alpha;
    }
}

// An MTL bump map with -bm: a height ramp h = u (one unit of height over the image) with
// strength 0.5 tilts a quad's normal (+z) against the slope: n = normalize((0, 0, 1) − 0.5 ·
// slope · (1, 0, 0)), read back from the normal AOV at the quad's middle.
TEST_F(ObjMaterialsRender, MtlBumpMapTiltsTheNormalAsTheRampPredicts) {
    constexpr int kWidth = 64;
    std::vector<unsigned char> ramp;
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < kWidth; ++x) ramp.push_back(static_cast<unsigned char>(4 * x));
    }
    ASSERT_TRUE(stbi_write_png((dir_ / "ramp.png").c_str(), kWidth, 4, 1, ramp.data(), kWidth));
    write("m.obj", std::string(kUvQuad) + "mtllib m.mtl\nusemtl bumpy\nf 1/1 2/2 3/3 4/4\n");
    write("m.mtl", "newmtl bumpy\nKd 1 1 1\nbump -bm 0.5 ramp.png\n");
    write("s.xml", uv_scene(""));
    const Scene scene = load_scene(dir_ / "s.xml").scene;
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    request.aovs = {Aov::kNormal};
    RenderOptions options;
    options.threads = 1;
    const RenderResult r = render(scene, request, options);
    const double slope = 4.0 / 255 * kWidth;  // height per unit of u
    const double tilt = 0.5 * slope, norm = std::sqrt(1 + tilt * tilt);
    for (const int x : {3, 4}) {
        for (const int y : {3, 4}) {
            const float* n = r.aovs.data() + 3 * (8 * y + x);
            EXPECT_NEAR(n[0], -tilt / norm, 2e-3) << x << "," << y;
            EXPECT_NEAR(n[1], 0, 2e-3);
            EXPECT_NEAR(n[2], 1 / norm, 2e-3);
        }
    }
}

}  // namespace
}  // namespace drt
