#include "drt/object.h"

namespace drt {

SurfaceHit Object::surface_at(const Ray& ray, const Hit& hit) const {
    const SurfacePoint at = locate(ray, hit);
    SurfaceHit surface;
    surface.point = at.point;
    surface.normal = at.normal;
    surface.shading_normal =
        detail_.bump ? detail_.bump->perturb(at.shading_normal, at.bump_point) : at.shading_normal;
    surface.kd = detail_.texture ? detail_.texture->value(at.texture_point) : material_->kd;
    const LightStart light = at.light_start.value_or(LightStart{at.point, at.normal});
    surface.light_point = light.point;
    surface.light_normal = light.normal;
    return surface;
}

}  // namespace drt
