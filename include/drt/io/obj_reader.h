// Reads the subset of Wavefront OBJ that docs/scene-format.md ("Meshes", "OBJ materials") defines:
// `v`, `vn`, `vt`, `f` (polygons split into fans), indices in the forms v, v/vt, v//vn and v/vt/vn,
// positive or negative (relative), and the material statements `mtllib` and `usemtl`. Every other
// statement is ignored. A malformed number or index is an error naming the file and line, never a
// silent zero.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "drt/util/math.h"

namespace drt {

// A file whose contents break the contract. what() is "OBJFILE:LINE: message".
class ObjError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// A file that cannot be read at all. what() is the system's reason ("No such file or
// directory"), so that the scene loader can name the element that asked for it.
class ObjOpenError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// A statement's argument and the line it stands on, for messages about it.
struct ObjReference {
    std::string name;  // the rest of the line, trimmed: names may hold spaces
    int line = 0;
};

struct ObjMesh {
    static constexpr std::uint32_t kNoNormal = UINT32_MAX;
    static constexpr std::uint32_t kNoTexcoord = UINT32_MAX;
    static constexpr std::uint32_t kNoMaterial = UINT32_MAX;

    std::vector<Vec3> positions;  // the `v` statements, in order
    std::vector<Vec3> normals;    // the `vn` statements, as written (not normalised)
    // Three corners per triangle, in the file's order; a polygon of n corners gives the n - 2
    // triangles (0, i, i + 1). Indices are 0-based.
    std::vector<std::uint32_t> position_indices;
    std::vector<std::uint32_t> normal_indices;  // parallel to position_indices; kNoNormal if none
    std::vector<Vec2> texcoords;                // the `vt` statements' (u, v), in order
    // Parallel to position_indices once any corner has a `vt` (empty before): kNoTexcoord if none.
    std::vector<std::uint32_t> texcoord_indices;

    std::vector<ObjReference> material_libraries;  // the `mtllib` statements, in order
    // The names that `usemtl` selects, each once, at the line of its first `usemtl`.
    std::vector<ObjReference> material_names;
    // Per triangle, the index into material_names of the material in force, or kNoMaterial
    // before the first `usemtl`. Empty when the file has no `usemtl`.
    std::vector<std::uint32_t> triangle_materials;
    int first_face_without_material = 0;  // its line, or 0 if every face follows a `usemtl`

    std::size_t triangle_count() const { return position_indices.size() / 3; }
};

// `name` stands for the file in messages.
ObjMesh parse_obj(std::string_view text, const std::string& name);
// Throws ObjOpenError if the file cannot be read, ObjError if it is malformed.
ObjMesh read_obj(const std::filesystem::path& path);

}  // namespace drt
