#include "drt/triangle.h"

#include <cmath>
#include <utility>

namespace drt {

ShearedRay::ShearedRay(const Ray& ray) : origin(ray.origin) {
    const Vec3& d = ray.dir;
    const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    kx = (kz + 1) % 3;
    ky = (kx + 1) % 3;
    // Looking down a negative axis mirrors the plane; swapping x and y mirrors it back, so that
    // every triangle keeps its winding.
    if (d[kz] < 0) std::swap(kx, ky);
    sx = d[kx] / d[kz];
    sy = d[ky] / d[kz];
    sz = 1 / d[kz];
}

}  // namespace drt
