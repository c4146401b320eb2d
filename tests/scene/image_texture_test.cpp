// Image textures as a scene uses them: Triangle corner coordinates, the footprint camera rays
// filter over, and the loader's errors and cache.
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <cmath>
#include <memory>
#include <string>

#include "drt/accel/mesh.h"
#include "drt/geometry/plane.h"
#include "drt/io/image.h"
#include "drt/scene/camera.h"
#include "drt/scene/scene_loader.h"
#include "drt/scene/texture_cache.h"
#include "run_drt.h"
#include "temp_folder.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::plain_material;

using test::TempFolderTest;

// Shows what it is looked up with as its colour: (u, v, 0), or with `footprint` the lengths of
// the two (u, v) steps and 0.
class LookupTexture final : public Texture {
  public:
    explicit LookupTexture(bool footprint = false) : footprint_(footprint) {}
    Color value(const TexturePoint& at) const override {
        if (!footprint_) return {at.uv.x, at.uv.y, 0};
        return {std::hypot(at.duv_dx.x, at.duv_dx.y), std::hypot(at.duv_dy.x, at.duv_dy.y), 0};
    }
    bool reads_uv() const override { return true; }

  private:
    bool footprint_;
};

std::shared_ptr<const TriangleMesh> one_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    ObjMesh obj;
    obj.positions = {a, b, c};
    obj.position_indices = {0, 1, 2};
    obj.normal_indices.assign(3, ObjMesh::kNoNormal);
    return std::make_shared<const TriangleMesh>(obj, MeshTransform{}, false);
}

// The corners' (u, v) are interpolated with the barycentrics: at A + 0.2 (B − A) + 0.3 (C − A)
// the texture sees uvA + 0.2 (uvB − uvA) + 0.3 (uvC − uvA).
TEST(TriangleUv, CornerCoordinatesAreInterpolated) {
    const Vec3 a{1, 0, 5}, b{4, 1, 5}, c{0, 3, 5};
    SurfaceDetail detail;
    detail.texture = std::make_shared<const LookupTexture>();
    detail.corner_uv = {{{0.1, 0.9}, {0.7, 0.2}, {-1.5, 2.0}}};
    const Mesh mesh(one_triangle(a, b, c), {Vec3{}}, plain_material(), detail);
    const Vec3 p = a + (b - a) * 0.2 + (c - a) * 0.3;
    const Ray ray{p - Vec3{0, 0, 4}, {0, 0, 1}};
    const auto hit = mesh.intersect(ray, {0, kInfinity});
    ASSERT_TRUE(hit);
    const Color uv = mesh.surface_at(ray, *hit).kd;
    EXPECT_NEAR(uv.r, 0.1 + 0.2 * (0.7 - 0.1) + 0.3 * (-1.5 - 0.1), 1e-9);
    EXPECT_NEAR(uv.g, 0.9 + 0.2 * (0.2 - 0.9) + 0.3 * (2.0 - 0.9), 1e-9);
}

// A plane facing a pinhole camera 10 away, 90° field of view over 100 pixels: a pixel spans
// 0.2 on the plane, 0.1 in (u, v) at TextureScale 2; a step of half a pixel spans 0.05.
TEST(TextureFootprint, CameraRaysSpanOnePixelStepOnTheSurface) {
    const Camera camera = Camera::look_at({{0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 90}, 100, 100, {});
    SurfaceDetail detail;
    detail.texture = std::make_shared<const LookupTexture>(true);
    detail.texture_scale = 2;
    const Plane plane({0, 0, 0}, {0, 0, 1}, plain_material(), detail);
    const Ray ray = camera.generate_ray({50, 50}, {0.5, 0.5}, 0);
    const auto hit = plane.intersect(ray, {0, kInfinity});
    ASSERT_TRUE(hit);
    for (const double step : {1.0, 0.5}) {
        const RayDifferential differential = camera.differential(ray, step);
        const Color footprint = plane.surface_at(ray, *hit, &differential).kd;
        EXPECT_NEAR(footprint.r, 0.1 * step, 1e-9) << step;
        EXPECT_NEAR(footprint.g, 0.1 * step, 1e-9) << step;
    }
    // Without differentials (deeper rays) the footprint is zero: the finest level.
    EXPECT_EQ(plane.surface_at(ray, *hit).kd.r, 0);

    // Tilted 60° the footprint stretches along the tilt, to about 1/cos 60° = 2 times: exactly,
    // the ray one pixel down, direction (0, −0.02, −1), meets the plane y√3 + z = 0 at
    // t = 5 / (0.5 + 0.01√3), a distance |(0, −0.02 t, 10 − t)| from the centre's hit.
    const Plane tilted({0, 0, 0}, normalize(Vec3{0, std::sqrt(3.0), 1}), plain_material(), detail);
    const auto t = tilted.intersect(ray, {0, kInfinity});
    ASSERT_TRUE(t);
    const RayDifferential differential = camera.differential(ray, 1);
    const Color stretched = tilted.surface_at(ray, *t, &differential).kd;
    EXPECT_NEAR(stretched.r, 0.1, 1e-9);
    const double t_down = 5 / (0.5 + 0.01 * std::sqrt(3.0));
    EXPECT_NEAR(stretched.g, length(Vec3{0, -0.02 * t_down, 10 - t_down}) / 2, 1e-9);
}

class ImageTextureScene : public TempFolderTest {
  protected:
    // A 2 x 2 PNG: red, green over blue, white.
    void write_two_by_two(const std::string& name) const {
        const unsigned char rgb[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
        ASSERT_TRUE(stbi_write_png((dir_ / name).c_str(), 2, 2, 3, rgb, 6));
    }
    std::filesystem::path scene(const std::string& objects) const {
        const auto path = dir_ / "scene.xml";
        test::write_bytes(
            path,
            "<Scene>\n"
            "<Image Width=\"8\" Height=\"8\"/>\n"
            "<Materials><M kdr=\"1\" kdg=\"1\" kdb=\"1\" diffuse=\"1\"/></Materials>\n" +
                objects + "\n</Scene>\n");
        return path;
    }
    std::string load_error(const std::string& objects) const {
        try {
            load_scene(scene(objects));
        } catch (const SceneError& e) {
            return e.what();
        }
        return "no error";
    }
};

// A lone Triangle's corners default to (0, 0), (1, 0), (0, 1): at barycentrics (¼, ¼) it
// shows the centre of the bottom-left texel, blue.
TEST_F(ImageTextureScene, TriangleDefaultsPutTheImageOriginAtCornerA) {
    write_two_by_two("t.png");
    const LoadedScene loaded = load_scene(scene(
        "<Triangle Ax=\"0\" Ay=\"0\" Az=\"0\" Bx=\"4\" By=\"0\" Bz=\"0\" Cx=\"0\" Cy=\"4\" "
        "Cz=\"0\" Material=\"M\" EnableTexture=\"1\" Texture=\"image\" TextureFile=\"t.png\"/>"));
    const Object& triangle = *loaded.scene.objects.at(0);
    const Ray ray{{1, 1, -3}, {0, 0, 1}};
    const auto hit = triangle.intersect(ray, {0, kInfinity});
    ASSERT_TRUE(hit);
    const Color kd = triangle.surface_at(ray, *hit).kd;
    EXPECT_NEAR(kd.r, 0, 1e-6);
    EXPECT_NEAR(kd.g, 0, 1e-6);
    EXPECT_NEAR(kd.b, 1, 1e-6);
    const Ray top{{1, 3 - 1e-9, -3}, {0, 0, 1}};  // (u, v) = (¼, ¾): top-left, red
    const auto near_c = triangle.intersect(top, {0, kInfinity});
    ASSERT_TRUE(near_c);
    EXPECT_NEAR(triangle.surface_at(top, *near_c).kd.r, 1, 1e-6);
}

TEST_F(ImageTextureScene, EachFileIsReadOnce) {
    write_two_by_two("t.png");
    std::filesystem::create_directory(dir_ / "sub");
    const std::string sphere =
        "<Sphere Px=\"0\" Py=\"0\" Pz=\"0\" Radius=\"1\" Material=\"M\" "
        "EnableTexture=\"1\" Texture=\"image\" TextureFile=";
    const LoadedScene loaded =
        load_scene(scene(sphere + "\"t.png\"/>" + sphere + "\"sub/../t.png\"/>" + sphere +
                         "\"t.png\" " + "BumpFile=\"t.png\"/>"));
    // Once as colour, once as data for the height map.
    EXPECT_EQ(loaded.files_read.size(), 2u);
    // BumpFile bumps by the image without bumpEnable, and instead of Perlin noise.
    const SurfaceDetail& bumped = loaded.scene.objects.at(2)->detail();
    EXPECT_NE(bumped.height_map, nullptr);
    EXPECT_FALSE(bumped.bump);
    EXPECT_EQ(loaded.scene.objects.at(0)->detail().height_map, nullptr);
}

// A 2 x 2 image's mip-map takes 12 bytes × (4 + 1) texels = 60: two different files fit in 120
// bytes, a third is refused, the same file again costs nothing.
TEST_F(ImageTextureScene, TexturesStayWithinTheMemoryBudget) {
    write_two_by_two("a.png");
    write_two_by_two("b.png");
    write_two_by_two("c.png");
    TextureCache cache(120);
    const auto a = cache.get(dir_ / "a.png", TextureEncoding::kColor);
    cache.get(dir_ / "b.png", TextureEncoding::kColor);
    EXPECT_EQ(cache.bytes(), 120u);
    EXPECT_EQ(cache.get(dir_ / "a.png", TextureEncoding::kColor), a);
    try {
        cache.get(dir_ / "c.png", TextureEncoding::kColor);
        ADD_FAILURE() << "no error past the budget";
    } catch (const ImageError& e) {
        EXPECT_NE(std::string(e.what()).find("c.png: textures would take 180 bytes with this image "
                                             "of 2x2, past the texture memory budget of 120 bytes"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(cache.files_read(), 2u);
}

TEST_F(ImageTextureScene, MissingCorruptAndHostileImagesAreErrorsAtTheirLine) {
    const std::string plane =
        "<Plane Px=\"0\" Py=\"0\" Pz=\"0\" Vu=\"0\" Vv=\"1\" Vw=\"0\" "
        "Material=\"M\" EnableTexture=\"1\" Texture=\"image\" ";
    const std::string missing = load_error(plane + "TextureFile=\"none.png\"/>");
    EXPECT_NE(missing.find("scene.xml:4: Plane: "), std::string::npos) << missing;
    EXPECT_NE(missing.find("none.png: cannot open file"), std::string::npos) << missing;

    const std::string bump = load_error(
        "<Sphere Px=\"0\" Py=\"0\" Pz=\"0\" Radius=\"1\" Material=\"M\" BumpFile=\"h.exr\"/>");
    EXPECT_NE(bump.find("scene.xml:4: Sphere: "), std::string::npos) << bump;

    write_two_by_two("t.png");
    const std::string png = test::read_bytes(dir_ / "t.png");
    test::write_bytes(dir_ / "cut.png", png.substr(0, png.size() / 2));
    const std::string cut = load_error(plane + "TextureFile=\"cut.png\"/>");
    EXPECT_NE(cut.find("scene.xml:4: Plane: "), std::string::npos) << cut;
    EXPECT_NE(cut.find("cut.png: "), std::string::npos) << cut;

    std::string hostile = png;
    for (const std::size_t at : {16u, 20u}) hostile.replace(at, 4, "\x00\x01\x86\xA0", 4);
    test::write_bytes(dir_ / "huge.png", hostile);
    const std::string huge = load_error(plane + "TextureFile=\"huge.png\"/>");
    EXPECT_NE(huge.find("100000x100000 pixels exceeds the limit"), std::string::npos) << huge;

    EXPECT_NE(load_error(plane + "/>").find("missing required attribute 'TextureFile'"),
              std::string::npos);
    // A Mesh reads its images as every surface does: a missing one is an error naming it.
    const std::string mesh =
        load_error("<Mesh File=\"m.obj\" Material=\"M\" BumpFile=\"nope.png\"/>");
    EXPECT_NE(mesh.find("Mesh: "), std::string::npos) << mesh;
    EXPECT_NE(mesh.find("nope.png"), std::string::npos) << mesh;
}

// A rendered check of the whole path: a wall (normal +z) seen from +z through one copy of an
// 8 x 8 image of four coloured quadrants, 2 x 2 pixels. e_u = +x, e_v = +y, and seen from +z
// the image's +u runs to the screen's left: the top-left pixel shows the top-right quadrant.
TEST_F(ImageTextureScene, RenderShowsTheContractsOrientation) {
    unsigned char rgb[8 * 8 * 3];
    for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 8; ++x) {
            // Rows from the top: red | green over blue | white.
            const bool top = y < 4, left = x < 4;
            const unsigned char r = top == left ? 255 : 0;
            const unsigned char g = top && !left ? 255 : (!top && !left ? 255 : 0);
            const unsigned char b = !top ? 255 : 0;
            unsigned char* p = rgb + 3 * (y * 8 + x);
            p[0] = r, p[1] = g, p[2] = b;
        }
    }
    ASSERT_TRUE(stbi_write_png((dir_ / "q.png").c_str(), 8, 8, 3, rgb, 24));
    test::write_bytes(dir_ / "wall.xml",
                      "<Scene><Image Width=\"2\" Height=\"2\"/><Render Samples=\"16\"/>"
                      "<Ambient r=\"1\" g=\"1\" b=\"1\"/>"
                      "<Camera Ex=\"10\" Ey=\"10\" Ez=\"10\" Lx=\"10\" Ly=\"10\" Lz=\"0\" "
                      "Fov=\"90\"/>"
                      "<Materials><M kdr=\"1\" kdg=\"1\" kdb=\"1\" diffuse=\"1\"/></Materials>"
                      "<Plane Px=\"0\" Py=\"0\" Pz=\"0\" Vu=\"0\" Vv=\"0\" Vw=\"1\" Material=\"M\" "
                      "EnableTexture=\"1\" Texture=\"image\" TextureFile=\"q.png\" "
                      "TextureScale=\"20\"/></Scene>");
    const test::Outcome r = test::run_drt({"wall.xml", "-q", "-o", "wall.pfm"}, dir_);
    ASSERT_EQ(r.status, 0) << r.err;
    const Image image = read_image(dir_ / "wall.pfm");
    const Color top_left = image.at(0, 0), top_right = image.at(1, 0);
    const Color bottom_left = image.at(0, 1), bottom_right = image.at(1, 1);
    // Each pixel is mostly its quadrant's colour; bilinear lookups within a texel of the
    // quadrants' borders blend in a little of the neighbours.
    EXPECT_GT(top_left.g, 0.8);  // green: u in [½, 1], v in [½, 1]
    EXPECT_LT(top_left.r, 0.2);
    EXPECT_LT(top_left.b, 0.2);
    EXPECT_GT(top_right.r, 0.8);  // red: u in [0, ½]
    EXPECT_LT(top_right.g, 0.2);
    EXPECT_GT(bottom_left.r, 0.8);  // white
    EXPECT_GT(bottom_left.g, 0.8);
    EXPECT_GT(bottom_left.b, 0.8);
    EXPECT_GT(bottom_right.b, 0.8);  // blue
    EXPECT_LT(bottom_right.r, 0.2);
    EXPECT_LT(bottom_right.g, 0.2);
}

TEST_F(ImageTextureScene, TheCommandLineExitsWithStatusTwo) {
    scene(
        "<Plane Px=\"0\" Py=\"0\" Pz=\"0\" Vu=\"0\" Vv=\"1\" Vw=\"0\" Material=\"M\" "
        "EnableTexture=\"1\" Texture=\"image\" TextureFile=\"gone.jpg\"/>");
    const test::Outcome r = test::run_drt({"scene.xml", "-o", "out.pfm"}, dir_);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err.rfind("scene.xml:4: Plane: ", 0), 0u) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "out.pfm"));
}

}  // namespace
}  // namespace drt
