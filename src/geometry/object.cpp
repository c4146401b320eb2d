#include "drt/geometry/object.h"

namespace drt {

SurfaceHit Object::surface_at(const Ray& ray, const Hit& hit) const {
    SurfaceHit surface;
    const SurfaceCoordinates at = locate(ray, hit, surface);
    if (detail_.bump)
        surface.shading_normal = detail_.bump->perturb(surface.shading_normal, at.bump_point);
    surface.kd = detail_.texture ? detail_.texture->value(at.texture_point) : material_->kd;
    return surface;
}

}  // namespace drt
