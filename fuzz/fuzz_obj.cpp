// libFuzzer target: the OBJ reader (a mesh file a scene names).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drt/io/obj_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const drt::ObjMesh mesh =
            drt::parse_obj(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.obj");
        // Every index the reader hands out must point into its arrays.
        for (const std::uint32_t i : mesh.position_indices) {
            if (i >= mesh.positions.size()) __builtin_trap();
        }
        for (const std::uint32_t i : mesh.normal_indices) {
            if (i != drt::ObjMesh::kNoNormal && i >= mesh.normals.size()) __builtin_trap();
        }
        for (const std::uint32_t i : mesh.texcoord_indices) {
            if (i != drt::ObjMesh::kNoTexcoord && i >= mesh.texcoords.size()) __builtin_trap();
        }
        if (!mesh.texcoord_indices.empty() &&
            mesh.texcoord_indices.size() != mesh.position_indices.size())
            __builtin_trap();
        if (!mesh.triangle_materials.empty() &&
            mesh.triangle_materials.size() != mesh.triangle_count())
            __builtin_trap();
        for (const std::uint32_t i : mesh.triangle_materials) {
            if (i != drt::ObjMesh::kNoMaterial && i >= mesh.material_names.size()) __builtin_trap();
        }
    } catch (const drt::ObjError&) {
    }
    return 0;
}
