// Worlds for the BVH's and the shadow-ray culling's tests: a random one of planes and (partly
// moving) spheres, to compare with testing every object, and two stacked triangles, for the skip
// of the triangle a ray leaves.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/accel/mesh.h"
#include "drt/accel/triangle_mesh.h"
#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "drt/util/rng.h"
#include "test_math.h"
#include "test_meshes.h"

namespace drt::testing {

inline Vec3 point_in(std::uint64_t stream, std::uint64_t i, double lo, double hi) {
    return {lo + (hi - lo) * unit(stream, 3 * i), lo + (hi - lo) * unit(stream, 3 * i + 1),
            lo + (hi - lo) * unit(stream, 3 * i + 2)};
}
inline Vec3 direction(std::uint64_t stream, std::uint64_t i) {
    const double z = 1 - 2 * unit(stream, 2 * i);
    const double phi = 2 * kPi * unit(stream, 2 * i + 1);
    const double s = std::sqrt(1 - z * z);
    return {s * std::cos(phi), s * std::sin(phi), z};
}

// A room of planes around spheres, some of them moving along paths of one or two segments.
struct World {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;

    World(int spheres, std::uint64_t seed) {
        material.diffuse = 1;
        objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, material));
        objects.push_back(std::make_unique<Plane>(Vec3{0, 100, 0}, Vec3{0, -1, 0}, material));
        objects.push_back(std::make_unique<Plane>(Vec3{-5, 0, 0}, Vec3{1, 0.2, 0}, material));
        for (int i = 0; i < spheres; ++i) {
            std::vector<Vec3> path{point_in(seed, i, 5, 95)};
            const int segments = i % 3;  // still, one segment, two segments
            for (int k = 0; k < segments; ++k)
                path.push_back(path.back() + point_in(seed + 1, 3 * i + k, -6, 6));
            objects.push_back(
                std::make_unique<Sphere>(std::move(path), 1 + 6 * unit(seed + 2, i), material));
        }
    }

    std::optional<Hit> brute_nearest(const Ray& ray, Interval range) const {
        std::optional<Hit> nearest;
        for (const auto& object : objects) {
            if (auto hit = object->intersect(ray, range)) {
                nearest = hit;
                range.max = hit->t;
            }
        }
        return nearest;
    }
    bool brute_occluded(const Ray& ray, Interval range) const {
        for (const auto& object : objects) {
            if (object->intersect(ray, range)) return true;
        }
        return false;
    }
};

// One triangle, (0, 0, 0), (4, 0, 0), (0, 4, 0), placed twice: objects[0] where it is, objects[1]
// one unit above it (z + 1), two Mesh objects sharing one TriangleMesh, and their BVH. The ray
// `up` meets the first at t = 3 and the second at t = 4; told to skip the first (Leaving), only
// the second.
struct StackedTriangles {
    Material material;
    std::vector<std::unique_ptr<Object>> objects = placed_twice(material);
    Bvh bvh{objects};
    Ray up{{1, 1, -3}, {0, 0, 1}};

    static std::vector<std::unique_ptr<Object>> placed_twice(const Material& material) {
        TestMesh flat;
        flat.vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
        flat.triangles = {{0, 1, 2}};
        const auto triangle =
            std::make_shared<const TriangleMesh>(obj_of(flat), MeshTransform{}, false);
        std::vector<std::unique_ptr<Object>> objects;
        objects.push_back(std::make_unique<Mesh>(triangle, std::vector<Vec3>{Vec3{}}, material));
        objects.push_back(
            std::make_unique<Mesh>(triangle, std::vector<Vec3>{Vec3{0, 0, 1}}, material));
        return objects;
    }
};

}  // namespace drt::testing
