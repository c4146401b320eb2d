// Triangle meshes built in code for the tests: closed, convex, with vertices that are exact
// single-precision numbers (as a mesh stores them), so that points on their edges can be
// written exactly in double.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "drt/io/obj_reader.h"
#include "drt/util/math.h"

namespace drt::testing {

struct TestMesh {
    std::vector<Vec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from outside
};

inline Vec3 to_float(const Vec3& v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

// The octahedron with vertices ±1 on each axis.
inline TestMesh octahedron() {
    TestMesh m;
    m.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                   {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return m;
}

// An icosahedron whose triangles are split `levels` times into four, every vertex pushed out to
// the sphere of `radius` about `centre`, then rounded to float.
inline TestMesh icosphere(int levels, double radius = 1, Vec3 centre = {}) {
    const double g = (1 + std::sqrt(5.0)) / 2;
    std::vector<Vec3> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                           {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                           {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (Vec3& p : v) p = normalize(p);
    std::vector<std::array<std::uint32_t, 3>> t = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middles;
        const auto middle = [&](std::uint32_t a, std::uint32_t b) {
            const auto [it, added] = middles.try_emplace({std::min(a, b), std::max(a, b)},
                                                         static_cast<std::uint32_t>(v.size()));
            if (added) v.push_back(normalize(v[a] + v[b]));
            return it->second;
        };
        std::vector<std::array<std::uint32_t, 3>> split;
        for (const auto& [a, b, c] : t) {
            const std::uint32_t ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
            split.insert(split.end(), {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}});
        }
        t = std::move(split);
    }
    TestMesh m;
    for (const Vec3& p : v) m.vertices.push_back(to_float(centre + p * radius));
    m.triangles = std::move(t);
    return m;
}

// The mesh as the OBJ reader would give it, without normals.
inline ObjMesh obj_of(const TestMesh& m) {
    ObjMesh obj;
    obj.positions = m.vertices;
    for (const auto& t : m.triangles) {
        obj.position_indices.insert(obj.position_indices.end(), t.begin(), t.end());
        obj.normal_indices.insert(obj.normal_indices.end(), 3, ObjMesh::kNoNormal);
    }
    return obj;
}

}  // namespace drt::testing
