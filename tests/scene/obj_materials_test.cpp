#include "drt/scene/obj_materials.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "drt/accel/mesh.h"
#include "drt/scene/scene_loader.h"
#include "temp_folder.h"
#include "test_math.h"

namespace drt {
namespace {

using testing::expect_color;

// --- the MTL -> thesis material mapping ---

TEST(MtlMapping, KdIsTheDiffuseColourAtFullWeight) {
    MtlMaterial mtl;
    mtl.kd = Color{0.9, 0.1, 0.2};
    const Material m = material_from_mtl(mtl);
    EXPECT_EQ(m.diffuse, 1);
    expect_color(m.kd, 0.9, 0.1, 0.2);
    EXPECT_EQ(m.reflective, 0);
    EXPECT_EQ(m.transmit, 0);
    EXPECT_FALSE(m.emits());
}

TEST(MtlMapping, KsAndNsAreTheReflectivePartAndItsSharpness) {
    MtlMaterial mtl;
    mtl.ks = Color{0.5, 0.4, 0.3};
    mtl.ns = 400;
    const Material m = material_from_mtl(mtl);
    EXPECT_EQ(m.reflective, 1);
    expect_color(m.ks, 0.5, 0.4, 0.3);
    ASSERT_TRUE(m.sharpness);
    EXPECT_DOUBLE_EQ(*m.sharpness, 20);  // sqrt(Ns)
    mtl.ns.reset();
    EXPECT_FALSE(material_from_mtl(mtl).sharpness);  // no Ns: an ideal mirror
    mtl.ns = 0;
    EXPECT_DOUBLE_EQ(*material_from_mtl(mtl).sharpness, 1);
    mtl.illum = 1;  // no highlight: Ks is not used
    EXPECT_EQ(material_from_mtl(mtl).reflective, 0);
    mtl.illum = 3;
    EXPECT_EQ(material_from_mtl(mtl).reflective, 1);
}

TEST(MtlMapping, DissolveAndNiAreTheTransparentPartAndItsIndex) {
    MtlMaterial mtl;
    mtl.kd = Color{0.2, 0.2, 0.2};
    mtl.dissolve = 0.25;
    mtl.ni = 1.33;
    Material m = material_from_mtl(mtl);
    EXPECT_DOUBLE_EQ(m.diffuse, 0.25);
    EXPECT_DOUBLE_EQ(m.transmit, 0.75);
    expect_color(m.kt, 1, 1, 1);
    EXPECT_DOUBLE_EQ(m.index, 1.33);
    mtl.ni = 0;  // written by some exporters: no bending
    EXPECT_DOUBLE_EQ(material_from_mtl(mtl).index, 1);
    mtl.dissolve = 1.5;  // clamped to opaque
    m = material_from_mtl(mtl);
    EXPECT_EQ(m.transmit, 0);
    EXPECT_EQ(m.diffuse, 1);
}

TEST(MtlMapping, KeIsTheEmission) {
    MtlMaterial mtl;
    mtl.ke = Color{2, 3, -1};
    expect_color(material_from_mtl(mtl).emission, 2, 3, 0);
}

TEST(MtlMapping, TheDefaultIsGreyDiffuse) {
    const Material m = default_obj_material();
    EXPECT_EQ(m.diffuse, 1);
    expect_color(m.kd, 0.8, 0.8, 0.8);
    EXPECT_EQ(m.reflective, 0);
    EXPECT_EQ(m.transmit, 0);
}

// --- one part per material ---

TEST(SplitByMaterial, GroupsTrianglesAndKeepsOnlyTheirVertices) {
    const ObjMesh obj = parse_obj(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 1\n"
        "vt 0.5 0.5\n"
        "f 1 2 3\n"
        "usemtl a\nf 1 3 4\n"
        "usemtl b\nf 2 5 3/1\n"
        "usemtl a\nf 1 2 4\n",
        "m.obj");
    const std::vector<ObjPart> parts = split_by_material(obj, false);
    ASSERT_EQ(parts.size(), 3u);
    EXPECT_EQ(parts[0].material, ObjMesh::kNoMaterial);
    EXPECT_EQ(parts[1].material, 0u);
    EXPECT_EQ(parts[2].material, 1u);
    EXPECT_EQ(parts[1].mesh.triangle_count(), 2u);
    EXPECT_EQ(parts[1].mesh.positions.size(), 4u);  // 1 3 4 2
    EXPECT_EQ(parts[1].mesh.position_indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 3, 2}));
    EXPECT_EQ(parts[2].mesh.positions.size(), 3u);
    EXPECT_EQ(parts[2].mesh.positions[1], (Vec3{2, 0, 1}));
    EXPECT_EQ(parts[2].mesh.texcoord_indices,
              (std::vector<std::uint32_t>{ObjMesh::kNoTexcoord, ObjMesh::kNoTexcoord, 0}));
    EXPECT_EQ(parts[2].mesh.texcoords.size(), 1u);
}

TEST(SplitByMaterial, SmoothNormalsAreTheWholeFilesAcrossAChangeOfMaterial) {
    // Two faces of a roof, one per material: their shared ridge vertices get the normal of both.
    const ObjMesh obj = parse_obj(
        "v 0 0 0\nv 0 0 1\nv 1 1 0\nv 1 1 1\nv 2 0 0\nv 2 0 1\n"
        "usemtl a\nf 1 2 4\nf 1 4 3\nusemtl b\nf 3 4 6\nf 3 6 5\n",
        "m.obj");
    const std::vector<ObjPart> parts = split_by_material(obj, true);
    ASSERT_EQ(parts.size(), 2u);
    for (const ObjPart& part : parts) {
        for (std::size_t c = 0; c < part.mesh.position_indices.size(); ++c) {
            const Vec3 p = part.mesh.positions[part.mesh.position_indices[c]];
            ASSERT_NE(part.mesh.normal_indices[c], ObjMesh::kNoNormal);
            const Vec3 n = normalize(part.mesh.normals[part.mesh.normal_indices[c]]);
            if (p.x == 1) {  // the ridge: straight up
                EXPECT_NEAR(n.x, 0, 1e-12);
                EXPECT_NEAR(n.y, 1, 1e-12);
            } else {  // an eave: its own face's normal
                EXPECT_NEAR(std::abs(n.x), std::sqrt(0.5), 1e-12);
            }
        }
    }
}

// --- a Mesh without Material in a scene ---

class ObjMaterialsScene : public test::TempFolderTest {
  protected:
    std::string write(const std::string& name, std::string_view contents) const {
        std::filesystem::create_directories((dir_ / name).parent_path());
        std::ofstream(dir_ / name, std::ios::binary)
            .write(contents.data(), static_cast<std::streamsize>(contents.size()));
        return (dir_ / name).string();
    }
    LoadedScene load_mesh(std::string_view attributes = "File=\"m.obj\"") const {
        const std::string scene =
            write("s.xml", "<Scene><Materials><Gray/></Materials>\n<Mesh " +
                               std::string(attributes) + " Smooth=\"0\"/></Scene>\n");
        return load_scene(scene);
    }
    std::string error_loading() const {
        try {
            load_mesh();
        } catch (const SceneError& e) {
            return e.what();
        }
        return "loaded";
    }
    static const Material& material_of(const LoadedScene& loaded, std::size_t object) {
        return loaded.scene.objects.at(object)->material();
    }
};

constexpr std::string_view kTwoQuads =
    "v -2 -1 0\nv 0 -1 0\nv 0 1 0\nv -2 1 0\nv 2 -1 0\nv 2 1 0\n"
    "g quads\n"
    "mtllib two colours.mtl\n"
    "usemtl red\n"
    "f 1 2 3 4\n"
    "usemtl green\n"
    "f 2 5 6 3\n";

constexpr std::string_view kTwoColours =
    "newmtl red\nKd 0.9 0.1 0.1\n"
    "newmtl green\nKd 0.1 0.9 0.1\nKs 0.2\nNs 25\n";

TEST_F(ObjMaterialsScene, EachFaceHasItsMaterial) {
    write("m.obj", kTwoQuads);
    write("two colours.mtl", kTwoColours);
    const LoadedScene loaded = load_mesh();
    EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
    ASSERT_EQ(loaded.scene.objects.size(), 2u);
    expect_color(material_of(loaded, 0).kd, 0.9, 0.1, 0.1);
    expect_color(material_of(loaded, 1).kd, 0.1, 0.9, 0.1);
    EXPECT_DOUBLE_EQ(*material_of(loaded, 1).sharpness, 5);
    const auto& red = dynamic_cast<const Mesh&>(*loaded.scene.objects[0]);
    const auto& green = dynamic_cast<const Mesh&>(*loaded.scene.objects[1]);
    EXPECT_EQ(red.mesh().triangle_count(), 2u);
    EXPECT_EQ(green.mesh().triangle_count(), 2u);
    // One origin for both parts: the file's centre.
    EXPECT_EQ(red.mesh().origin(), green.mesh().origin());
    EXPECT_EQ(red.mesh().origin(), (Vec3{0, 0, 0}));
    // The shared edge x = 0 is in both, at the same single-precision coordinates.
    const auto [a, b, c] = red.mesh().corners(0);
    EXPECT_TRUE(a.x == 0 || b.x == 0 || c.x == 0);
    EXPECT_EQ(loaded.files_read.size(), 2u);
}

TEST_F(ObjMaterialsScene, WindowsLineEndingsAndSeparators) {
    std::string obj(kTwoQuads);
    obj.replace(obj.find("two colours.mtl"), 15, "lib\\two colours.mtl");
    std::string crlf;
    for (const char ch : obj) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
    write("m.obj", crlf);
    write("lib/two colours.mtl", "newmtl red\r\nKd 0.9 0.1 0.1\r\nnewmtl green\r\nKd 0 1 0\r\n");
    const LoadedScene loaded = load_mesh();
    EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
    ASSERT_EQ(loaded.scene.objects.size(), 2u);
    expect_color(material_of(loaded, 1).kd, 0, 1, 0);
}

TEST_F(ObjMaterialsScene, SeveralLibrariesOnOneLine) {
    std::string obj(kTwoQuads);
    obj.replace(obj.find("two colours.mtl"), 15, "a.mtl b.mtl");
    write("m.obj", obj);
    write("a.mtl", "newmtl red\nKd 1 0 0\n");
    write("b.mtl", "newmtl green\nKd 0 1 0\n");
    const LoadedScene loaded = load_mesh();
    EXPECT_TRUE(loaded.warnings.empty());
    expect_color(material_of(loaded, 0).kd, 1, 0, 0);
    expect_color(material_of(loaded, 1).kd, 0, 1, 0);
}

TEST_F(ObjMaterialsScene, FacesWithoutAKnownMaterialAreGreyWithOneWarning) {
    write("m.obj",
          "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
          "mtllib l.mtl\n"
          "f 1 2 3\n"  // line 6: no usemtl yet
          "usemtl nowhere\nf 1 3 4\n"
          "usemtl red\nf 2 3 4\n"
          "usemtl elsewhere\nf 1 2 4\n");
    write("l.mtl", "newmtl red\nKd 1 0 0\n");
    const LoadedScene loaded = load_mesh();
    EXPECT_EQ(loaded.warnings, std::vector<std::string>{
                                   (dir_ / "m.obj").string() +
                                   ":6: warning: faces without a material from the file's mtllib "
                                   "are grey (diffuse 1, kd 0.8)"});
    ASSERT_EQ(loaded.scene.objects.size(), 4u);
    for (const std::size_t grey : {0u, 1u, 3u}) {
        expect_color(material_of(loaded, grey).kd, 0.8, 0.8, 0.8);
        EXPECT_EQ(material_of(loaded, grey).diffuse, 1);
    }
    expect_color(material_of(loaded, 2).kd, 1, 0, 0);
}

TEST_F(ObjMaterialsScene, AMissingLibraryIsAWarningAtItsLine) {
    write("m.obj", kTwoQuads);
    const LoadedScene loaded = load_mesh();
    const std::string obj = (dir_ / "m.obj").string();
    EXPECT_EQ(loaded.warnings,
              (std::vector<std::string>{
                  obj + ":8: warning: cannot open " + (dir_ / "two colours.mtl").string() +
                      ": No such file or directory; its materials are grey",
                  obj + ":9: warning: faces without a material from the file's mtllib are grey "
                        "(diffuse 1, kd 0.8)"}));
    ASSERT_EQ(loaded.scene.objects.size(), 2u);
    expect_color(material_of(loaded, 0).kd, 0.8, 0.8, 0.8);
}

TEST_F(ObjMaterialsScene, AMalformedNumberInTheLibraryIsAnError) {
    write("m.obj", kTwoQuads);
    write("two colours.mtl", "newmtl red\nKd 0.9 0.1 0.1\nnewmtl green\nKd 0.1 O.9 0.1\n");
    EXPECT_EQ(error_loading(),
              (dir_ / "two colours.mtl").string() + ":4: Kd: \"O.9\" is not a number");
}

TEST_F(ObjMaterialsScene, AMissingTextureIsAWarningAndTheColourStands) {
    write("m.obj", kTwoQuads);
    write("two colours.mtl", std::string(kTwoColours) + "map_Kd tex\\wood.jpg\n");
    const LoadedScene loaded = load_mesh();
    EXPECT_EQ(loaded.warnings,
              std::vector<std::string>{
                  (dir_ / "two colours.mtl").string() + ":7: warning: cannot open " +
                  (dir_ / "tex/wood.jpg").string() + "; the material's constant colour is used"});
    expect_color(material_of(loaded, 1).kd, 0.1, 0.9, 0.1);
}

TEST_F(ObjMaterialsScene, AMaterialAttributeOverridesTheFilesMaterials) {
    write("m.obj", kTwoQuads);  // its library is missing, and not looked for
    const LoadedScene loaded = load_mesh("File=\"m.obj\" Material=\"Gray\"");
    EXPECT_TRUE(loaded.warnings.empty());
    ASSERT_EQ(loaded.scene.objects.size(), 1u);
    EXPECT_EQ(material_of(loaded, 0).name, "Gray");
    EXPECT_EQ(dynamic_cast<const Mesh&>(*loaded.scene.objects[0]).mesh().triangle_count(), 4u);
}

}  // namespace
}  // namespace drt
