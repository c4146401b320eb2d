#include "drt/geometry/triangle.h"

#include <cmath>
#include <utility>

namespace drt {

ShearedRay::ShearedRay(const Ray& ray) : origin(ray.origin) {
    const Vec3& d = ray.dir;
    const Axes axes = axes_of(d);
    kx = axes.kx, ky = axes.ky, kz = axes.kz;
    sx = d[kx] / d[kz];
    sy = d[ky] / d[kz];
    sz = 1 / d[kz];
}

}  // namespace drt
