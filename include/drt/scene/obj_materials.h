// An OBJ file's own materials (docs/scene-format.md, "OBJ materials"): what an MTL material
// means for the thesis's material, and a mesh split into one part per material.
#pragma once

#include <cstdint>
#include <vector>

#include "drt/io/mtl_reader.h"
#include "drt/io/obj_reader.h"
#include "drt/shading/material.h"

namespace drt {

// The thesis's material for an MTL material; docs/scene-format.md gives the mapping's reasons.
Material material_from_mtl(const MtlMaterial& mtl);
// For faces before any `usemtl` or naming a material no library defines: grey, diffuse 1, kd 0.8.
Material default_obj_material();

// The faces of one material, as a mesh of their own.
struct ObjPart {
    std::uint32_t material;  // index into ObjMesh::material_names, or ObjMesh::kNoMaterial
    ObjMesh mesh;
};

// The file's triangles grouped by the material in force, the groups in the order their materials
// first appear, each keeping only the vertices it uses. With `smooth`, a corner without a `vn`
// gets the angle-weighted normal of the whole file's faces around its vertex, so that shading is
// continuous across a change of material as it is within one.
std::vector<ObjPart> split_by_material(const ObjMesh& obj, bool smooth);

}  // namespace drt
