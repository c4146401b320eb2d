#include "drt/io/obj_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace drt {
namespace {

using Indices = std::vector<std::uint32_t>;
constexpr std::uint32_t kNone = ObjMesh::kNoNormal;

ObjMesh obj_of(std::string_view text) {
    return parse_obj(text, "m.obj");
}

// The message a file fails with, or "parsed".
std::string obj_error(std::string_view text) {
    try {
        obj_of(text);
    } catch (const ObjError& e) {
        return e.what();
    }
    return "parsed";
}

constexpr std::string_view kSquare =
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n";

TEST(ObjReader, ReadsPositionsAndNormals) {
    const ObjMesh m = obj_of("# a comment\nv 1 -2.5 3e2\nv +4 5 6 1\nvn 0 0 1\nv .5 -0 7\n");
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.positions[0], (Vec3{1, -2.5, 300}));
    EXPECT_EQ(m.positions[1], (Vec3{4, 5, 6}));  // the optional weight is read and dropped
    EXPECT_EQ(m.positions[2], (Vec3{0.5, 0, 7}));
    ASSERT_EQ(m.normals.size(), 1u);
    EXPECT_EQ(m.normals[0], (Vec3{0, 0, 1}));
    EXPECT_EQ(m.triangle_count(), 0u);
}

TEST(ObjReader, SplitsAPolygonIntoAFan) {
    const ObjMesh m = obj_of(std::string(kSquare) + "v 0.5 2 0\nf 1 2 3 5 4\n");
    EXPECT_EQ(m.position_indices, (Indices{0, 1, 2, 0, 2, 4, 0, 4, 3}));
    EXPECT_EQ(m.normal_indices, Indices(9, kNone));
}

TEST(ObjReader, ReadsEveryCornerForm) {
    const ObjMesh m = obj_of(std::string(kSquare) +
                             "vt 0 0\nvt 1 0\nvn 0 0 1\nvn 0 0 -1\n"
                             "f 1/1 2/2 3/1\n"
                             "f 1//2 3//1 4//2\n"
                             "f 2/1/1 3/2/2 4/1/1\n"
                             "f 1 2/2 3//2\n");
    EXPECT_EQ(m.position_indices, (Indices{0, 1, 2, 0, 2, 3, 1, 2, 3, 0, 1, 2}));
    EXPECT_EQ(m.normal_indices, (Indices{kNone, kNone, kNone, 1, 0, 1, 0, 1, 0, kNone, kNone, 1}));
}

TEST(ObjReader, NegativeIndicesCountBackFromTheLatest) {
    const ObjMesh m = obj_of(
        "v 0 0 0\nv 1 0 0\nvn 1 0 0\nv 0 1 0\nf -3 -2 -1//-1\nv 5 5 5\n"
        "f -4 -1 2\n");
    EXPECT_EQ(m.position_indices, (Indices{0, 1, 2, 0, 3, 1}));
    EXPECT_EQ(m.normal_indices, (Indices{kNone, kNone, 0, kNone, kNone, kNone}));
}

TEST(ObjReader, IgnoresOtherStatementsAndLineEndings) {
    const ObjMesh m = obj_of(
        "mtllib x.mtl\r\no thing\r\ng group\r\ns 1\r\nusemtl red\r\nv 0 0 0\r\nv 1 0 0\r\n"
        "v 0 1 0 # trailing comment\r\n\r\n   \r\nl 1 2\r\nf 1 2 3\r\nvp 0.5\r\n"
        "\tf\t1 3 2");  // no newline at the end
    EXPECT_EQ(m.position_indices, (Indices{0, 1, 2, 0, 2, 1}));
}

TEST(ObjReader, RejectsCoordinatesThatAreNotFiniteNumbers) {
    EXPECT_EQ(obj_error("v 0 0 0\nv 0 abc 0\n"), "m.obj:2: v: \"abc\" is not a number");
    EXPECT_EQ(obj_error("v 0 0.5x 0\n"), "m.obj:1: v: \"0.5x\" is not a number");
    EXPECT_EQ(obj_error("v 0 +-1 0\n"), "m.obj:1: v: \"+-1\" is not a number");
    EXPECT_EQ(obj_error("\n\nv 0 nan 0\n"), "m.obj:3: v: \"nan\" is not a finite number");
    EXPECT_EQ(obj_error("v -inf 0 0\n"), "m.obj:1: v: \"-inf\" is not a finite number");
    EXPECT_EQ(obj_error("v 1e999 0 0\n"), "m.obj:1: v: \"1e999\" is out of range");
    EXPECT_EQ(obj_error("vn 0 0 NaN\n"), "m.obj:1: vn: \"NaN\" is not a finite number");
    EXPECT_EQ(obj_error("v 0 0 0 red\n"), "m.obj:1: v: \"red\" is not a number");
    EXPECT_EQ(obj_error("v 0 1\n"), "m.obj:1: v: 3 coordinates needed, got 2");
    // What the file holds is shown safely: control characters escaped, a long value cut.
    EXPECT_EQ(obj_error("v 0 \x1b[2J 0\n"), "m.obj:1: v: \"\\x1b[2J\" is not a number");
    EXPECT_EQ(obj_error("v 0 " + std::string(400, '7') + "x 0\n"),
              "m.obj:1: v: \"77777777777777777777... (401 characters)\" is not a number");
    EXPECT_EQ(obj_error("vn 0 1 0 1\n"), "m.obj:1: vn: more than 3 coordinates: \"1\"");
}

TEST(ObjReader, RejectsIndicesOutOfRange) {
    const std::string v(kSquare);
    EXPECT_EQ(obj_error(v + "f 0 1 2\n"),
              "m.obj:5: f: vertex index 0 in \"0\"; indices start at 1");
    EXPECT_EQ(obj_error(v + "f 1 2 5\n"),
              "m.obj:5: f: vertex index 5 is out of range; 4 defined above");
    EXPECT_EQ(obj_error(v + "f 1 2 -5\n"),
              "m.obj:5: f: vertex index -5 is out of range; 4 defined above");
    EXPECT_EQ(obj_error(v + "f 1 2 99999999999999999999\n"),
              "m.obj:5: f: vertex index 99999999999999999999 is out of range; 4 defined above");
    // A vertex defined after the face does not count.
    EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"),
              "m.obj:3: f: vertex index 3 is out of range; 2 defined above");
    EXPECT_EQ(obj_error(v + "vn 0 0 1\nf 1//1 2//2 3//1\n"),
              "m.obj:6: f: normal index 2 is out of range; 1 defined above");
    EXPECT_EQ(obj_error(v + "vn 0 0 1\nf 1//1 2//0 3//1\n"),
              "m.obj:6: f: normal index 0 in \"2//0\"; indices start at 1");
    EXPECT_EQ(obj_error(v + "vt 0 0\nf 1/1 2/2 3/1\n"),
              "m.obj:6: f: texture index 2 is out of range; 1 defined above");
}

TEST(ObjReader, RejectsMalformedFaces) {
    const std::string v(kSquare);
    EXPECT_EQ(obj_error(v + "f 1 2\n"), "m.obj:5: f: a face needs at least 3 vertices, got 2");
    EXPECT_EQ(obj_error(v + "f\n"), "m.obj:5: f: a face needs at least 3 vertices, got 0");
    EXPECT_EQ(obj_error(v + "f 1 2 3x\n"), "m.obj:5: f: \"3x\" is not a vertex reference");
    EXPECT_EQ(obj_error(v + "f 1 2 3/\n"), "m.obj:5: f: \"3/\" is not a vertex reference");
    EXPECT_EQ(obj_error(v + "f 1 2 /3\n"), "m.obj:5: f: \"/3\" is not a vertex reference");
    EXPECT_EQ(obj_error(v + "vn 0 0 1\nf 1 2 3//\n"),
              "m.obj:6: f: \"3//\" is not a vertex reference");
    EXPECT_EQ(obj_error(v + "vn 0 0 1\nf 1 2 3//1/1\n"),
              "m.obj:6: f: \"3//1/1\" is not a vertex reference");
}

TEST(ObjReader, NamesAFileThatCannotBeOpened) {
    try {
        read_obj("/nonexistent/x.obj");
        FAIL() << "read a missing file";
    } catch (const ObjOpenError& e) {
        EXPECT_STREQ(e.what(), "No such file or directory");
    }
    EXPECT_THROW(read_obj("/"), ObjOpenError);  // a folder
}

TEST(ObjReader, FileSizePastTheLimitIsRefusedBeforeReading) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("drt_obj_limit_" + std::to_string(::getpid()) + ".obj");
    { std::ofstream(path) << "v 0 0 0\n"; }
    std::filesystem::resize_file(path, (std::uint64_t{1} << 30) + 1);  // sparse: nothing is read
    try {
        read_obj(path);
        ADD_FAILURE() << "read a file past the limit";
    } catch (const ObjError& e) {
        EXPECT_EQ(std::string(e.what()),
                  path.string() + ": file larger than the 1024 MiB limit for a mesh");
    }
    std::filesystem::remove(path);
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

constexpr std::uint32_t kNoUv = ObjMesh::kNoTexcoord;

TEST(ObjReaderUv, ReadsTextureCoordinatesPerCorner) {
    const ObjMesh m = parse_obj(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "f 1 2 3\n"  // before any vt: the corners have none
        "vt 0.25 0.5\nvt 0.75\nvt 1 0 0\n"
        "f 1/1 2/2 3/-1\n"
        "f 1/3 3 4\n",
        "m.obj");
    ASSERT_EQ(m.texcoords.size(), 3u);
    EXPECT_EQ(m.texcoords[0].x, 0.25);
    EXPECT_EQ(m.texcoords[0].y, 0.5);
    EXPECT_EQ(m.texcoords[1].x, 0.75);
    EXPECT_EQ(m.texcoords[1].y, 0);  // v defaults to 0
    EXPECT_EQ(m.texcoord_indices,
              (std::vector<std::uint32_t>{kNoUv, kNoUv, kNoUv, 0, 1, 2, 2, kNoUv, kNoUv}));
}

TEST(ObjReaderUv, RejectsMalformedTextureCoordinates) {
    const auto error = [](std::string_view text) {
        try {
            parse_obj(text, "m.obj");
        } catch (const ObjError& e) {
            return std::string(e.what());
        }
        return std::string("parsed");
    };
    EXPECT_EQ(error("v 0 0 0\nvt\n"), "m.obj:2: vt: 1 to 3 coordinates needed, got 0");
    EXPECT_EQ(error("vt 1 2 3 4\n"), "m.obj:1: vt: more than 3 coordinates: \"4\"");
    EXPECT_EQ(error("vt 0.5 x\n"), "m.obj:1: vt: \"x\" is not a number");
    EXPECT_EQ(error("vt 0.5 inf\n"), "m.obj:1: vt: \"inf\" is not a finite number");
    EXPECT_EQ(error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n"),
              "m.obj:5: f: texture index 2 is out of range; 1 defined above");
}

TEST(ObjReaderMaterials, ReadsLibrariesAndTheMaterialOfEachTriangle) {
    const ObjMesh m = parse_obj(
        "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n"
        "g first\r\n"
        "f 1 2 3\r\n"  // line 6: before any usemtl
        "mtllib my materials.mtl\r\n"
        "usemtl dark red\r\n"
        "f 1 2 3 4\r\n"  // two triangles
        "usemtl green  \r\n"
        "f 1 3 4\r\n"
        "usemtl dark red\r\n"
        "f 2 3 4\r\n"
        "mtllib sub\\more.mtl\n",
        "m.obj");
    ASSERT_EQ(m.material_libraries.size(), 2u);
    EXPECT_EQ(m.material_libraries[0].name, "my materials.mtl");
    EXPECT_EQ(m.material_libraries[0].line, 7);
    EXPECT_EQ(m.material_libraries[1].name, "sub\\more.mtl");
    ASSERT_EQ(m.material_names.size(), 2u);
    EXPECT_EQ(m.material_names[0].name, "dark red");
    EXPECT_EQ(m.material_names[0].line, 8);
    EXPECT_EQ(m.material_names[1].name, "green");
    EXPECT_EQ(m.material_names[1].line, 10);
    const std::uint32_t none = ObjMesh::kNoMaterial;
    EXPECT_EQ(m.triangle_materials, (std::vector<std::uint32_t>{none, 0, 0, 1, 0}));
    EXPECT_EQ(m.first_face_without_material, 6);
    EXPECT_EQ(m.triangle_count(), 5u);
}

TEST(ObjReaderUv, TheFirstFaceMayNameTextureCoordinates) {
    const ObjMesh m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nf 1/1 2 3/1\n", "m.obj");
    EXPECT_EQ(m.texcoord_indices, (std::vector<std::uint32_t>{0, kNoUv, 0}));
}

TEST(ObjReaderMaterials, AFileWithoutUsemtlKeepsNoPerTriangleMaterials) {
    const ObjMesh m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "m.obj");
    EXPECT_TRUE(m.triangle_materials.empty());
    EXPECT_TRUE(m.texcoord_indices.empty());
    EXPECT_EQ(m.first_face_without_material, 4);
}

}  // namespace
}  // namespace drt
