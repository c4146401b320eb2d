// Reproducible worlds of random spheres and rays for the micro-benchmarks: every number is a
// hash of its index, so each run (and each build being compared) sees the same data.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "drt/geometry/object.h"
#include "drt/geometry/sphere.h"
#include "drt/shading/material.h"
#include "drt/util/ray.h"
#include "drt/util/rng.h"

namespace drt::bench {

inline double unit(std::uint64_t stream, std::uint64_t i) {
    return to_unit(hash_of(stream, i));
}

inline Vec3 point_in_cube(std::uint64_t stream, std::uint64_t i, double size) {
    return {size * unit(stream, 3 * i), size * unit(stream, 3 * i + 1),
            size * unit(stream, 3 * i + 2)};
}

// `count` spheres in a cube of edge 1000 filling about 5% of its volume whatever the count, so a
// ray meets a similar number of them; a moving sphere travels about its own diameter over one
// time unit, as in a motion-blurred frame.
struct SphereWorld {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;

    SphereWorld(int count, bool moving) {
        material.diffuse = 1;
        constexpr double kEdge = 1000, kFill = 0.05;
        const double radius = std::cbrt(kFill * kEdge * kEdge * kEdge / (count * 4.18879));
        for (int i = 0; i < count; ++i) {
            std::vector<Vec3> path{point_in_cube(1, i, kEdge)};
            if (moving) {
                const Vec3 step =
                    point_in_cube(2, i, 4 * radius) - Vec3{2 * radius, 2 * radius, 2 * radius};
                path.push_back(path[0] + step);
            }
            objects.push_back(std::make_unique<Sphere>(std::move(path), radius, material));
        }
    }
};

// Rays from outside the cube towards points inside it (like camera rays), or between two points
// inside it (like shadow rays, with their length as `lengths`), at random times in [0, 1].
struct RaySet {
    std::vector<Ray> rays;
    std::vector<double> lengths;

    RaySet(int count, bool inside) {
        for (int i = 0; i < count; ++i) {
            const Vec3 target = point_in_cube(3, i, 1000);
            Vec3 origin = point_in_cube(4, i, 1000);
            if (!inside) origin = (origin - Vec3{500, 500, 500}) * 3.0 + Vec3{500, 500, 500};
            const Vec3 d = target - origin;
            rays.push_back({origin, d / length(d), unit(5, i)});
            lengths.push_back(length(d));
        }
    }
};

}  // namespace drt::bench
