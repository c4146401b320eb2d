#include "drt/scene/obj_materials.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace drt {

namespace {

Color clamped(const Color& c) {
    return {std::max(0.0, c.r), std::max(0.0, c.g), std::max(0.0, c.b)};
}

double angle_between(const Vec3& a, const Vec3& b) {
    return std::atan2(length(cross(a, b)), dot(a, b));
}

// Angle-weighted vertex normals over the file's faces, in the file's coordinates; zero for a
// vertex that only faces of zero area touch.
std::vector<Vec3> vertex_normals(const ObjMesh& obj) {
    std::vector<Vec3> normals(obj.positions.size());
    for (std::size_t c = 0; c < obj.position_indices.size(); c += 3) {
        const std::uint32_t* p = &obj.position_indices[c];
        const Vec3 a = obj.positions[p[0]], b = obj.positions[p[1]], d = obj.positions[p[2]];
        const Vec3 n = cross(b - a, d - a);
        if (n == Vec3{}) continue;
        const Vec3 unit = normalize(n);
        normals[p[0]] += unit * angle_between(b - a, d - a);
        normals[p[1]] += unit * angle_between(d - b, a - b);
        normals[p[2]] += unit * angle_between(a - d, b - d);
    }
    return normals;
}

}  // namespace

Material material_from_mtl(const MtlMaterial& mtl) {
    Material m;
    m.name = mtl.name;
    const double opacity = std::clamp(mtl.dissolve.value_or(1.0), 0.0, 1.0);
    m.diffuse = opacity;
    m.kd = clamped(mtl.kd.value_or(Color{0.8, 0.8, 0.8}));
    // illum 0 and 1 are the models without a highlight: Ks has no say there.
    const bool specular = !mtl.illum || *mtl.illum >= 2;
    const Color ks = clamped(mtl.ks.value_or(Color{0, 0, 0}));
    if (specular && !is_black(ks)) {
        m.reflective = 1;
        m.ks = ks;
        // A Phong lobe cos^Ns spreads like a Gaussian of standard deviation 1/sqrt(Ns) radians;
        // the thesis's n is one over that spread. No Ns: an ideal mirror.
        if (mtl.ns) m.sharpness = std::sqrt(std::max(*mtl.ns, 1.0));
    }
    if (opacity < 1) {
        m.transmit = 1 - opacity;
        m.kt = {1, 1, 1};
        // Ni 0 (written by some exporters) or none: no bending, as a see-through film.
        m.index = mtl.ni && *mtl.ni > 0 ? *mtl.ni : 1.0;
    }
    m.emission = clamped(mtl.ke.value_or(Color{0, 0, 0}));
    return m;
}

Material default_obj_material() {
    Material m;
    m.name = "(OBJ default grey)";
    m.diffuse = 1;
    m.kd = {0.8, 0.8, 0.8};
    return m;
}

std::vector<ObjPart> split_by_material(const ObjMesh& obj, bool smooth) {
    const std::size_t triangles = obj.triangle_count();
    const auto material_of = [&](std::size_t t) {
        return obj.triangle_materials.empty() ? ObjMesh::kNoMaterial : obj.triangle_materials[t];
    };
    std::vector<std::uint32_t> order;              // materials in order of first appearance
    std::map<std::uint32_t, std::size_t> part_of;  // material -> index into order
    for (std::size_t t = 0; t < triangles; ++t) {
        if (part_of.try_emplace(material_of(t), order.size()).second)
            order.push_back(material_of(t));
    }
    std::vector<Vec3> computed;
    if (smooth && order.size() > 1) computed = vertex_normals(obj);

    std::vector<ObjPart> parts(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) parts[i].material = order[i];
    // Per part, the file's vertex -> the part's, and the file's normal -> the part's.
    std::vector<std::map<std::uint32_t, std::uint32_t>> positions(order.size()),
        normals(order.size()), texcoords(order.size());
    const auto renumbered = [](std::map<std::uint32_t, std::uint32_t>& map, std::uint32_t i,
                               auto& into, const auto& value) {
        const auto [it, added] = map.try_emplace(i, static_cast<std::uint32_t>(into.size()));
        if (added) into.push_back(value);
        return it->second;
    };
    for (std::size_t t = 0; t < triangles; ++t) {
        const std::size_t k = part_of.at(material_of(t));
        ObjMesh& part = parts[k].mesh;
        for (std::size_t c = 3 * t; c < 3 * t + 3; ++c) {
            const std::uint32_t p = obj.position_indices[c];
            part.position_indices.push_back(
                renumbered(positions[k], p, part.positions, obj.positions[p]));
            const std::uint32_t n = obj.normal_indices[c];
            if (n != ObjMesh::kNoNormal) {
                part.normal_indices.push_back(
                    renumbered(normals[k], n, part.normals, obj.normals[n]));
            } else if (!computed.empty()) {
                // Numbered past the file's normals, so as not to meet them in the map.
                const auto key = static_cast<std::uint32_t>(obj.normals.size() + p);
                part.normal_indices.push_back(
                    renumbered(normals[k], key, part.normals, computed[p]));
            } else {
                part.normal_indices.push_back(ObjMesh::kNoNormal);
            }
            if (!obj.texcoord_indices.empty()) {
                const std::uint32_t uv = obj.texcoord_indices[c];
                part.texcoord_indices.push_back(
                    uv == ObjMesh::kNoTexcoord
                        ? ObjMesh::kNoTexcoord
                        : renumbered(texcoords[k], uv, part.texcoords, obj.texcoords[uv]));
            }
        }
    }
    return parts;
}

}  // namespace drt
