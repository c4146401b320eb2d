#include "drt/object.h"

namespace drt {

SurfaceHit Object::surface_at(const Ray& ray, double t) const {
    SurfaceHit hit;
    hit.point = project_to_surface(ray.at(t), ray.time);
    hit.normal = outward_normal(hit.point, ray.time);
    hit.shading_normal = hit.normal;
    if (detail_.bump) {
        hit.shading_normal = detail_.bump->perturb(hit.normal, bump_point(hit.point, ray.time));
    }
    hit.kd = detail_.texture ? detail_.texture->value(texture_point(hit.point, ray.time))
                             : material_->kd;
    return hit;
}

}  // namespace drt
