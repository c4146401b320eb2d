#include "drt/geometry/object.h"

#include <algorithm>
#include <cmath>

namespace drt {

namespace {

// The (u, v) step to where `ray` meets the plane through `point` with normal `normal`: the step
// on the plane is solved for in the least-squares sense over dp_du and dp_dv (as pbrt-v4 does),
// and is zero where either is undefined.
Vec2 uv_step(const Ray& ray, const Vec3& point, const Vec3& normal, const SurfaceUv& at) {
    const double facing = dot(normal, ray.dir);
    if (facing == 0) return {};
    const Vec3 step = ray.at(dot(normal, point - ray.origin) / facing) - point;
    const double a00 = dot(at.dp_du, at.dp_du), a01 = dot(at.dp_du, at.dp_dv);
    const double a11 = dot(at.dp_dv, at.dp_dv);
    const double det = a00 * a11 - a01 * a01;
    if (!(std::abs(det) > 0)) return {};
    const double b0 = dot(at.dp_du, step), b1 = dot(at.dp_dv, step);
    const Vec2 duv{(a11 * b0 - a01 * b1) / det, (a00 * b1 - a01 * b0) / det};
    if (!std::isfinite(duv.x) || !std::isfinite(duv.y)) return {};
    return duv;
}

Vec2 mapped(const std::array<Vec2, 3>& m, Vec2 d) {
    return {(m[1].x - m[0].x) * d.x + (m[2].x - m[0].x) * d.y,
            (m[1].y - m[0].y) * d.x + (m[2].y - m[0].y) * d.y};
}

// (u, v) given as barycentrics (b1, b2), taken through a triangle's corner coordinates.
SurfaceUv through_corners(const SurfaceUv& at, const std::array<Vec2, 3>& corners) {
    const Vec2 d = mapped(corners, at.uv);
    SurfaceUv out{{corners[0].x + d.x, corners[0].y + d.y}, {}, {}};
    const double m00 = corners[1].x - corners[0].x, m01 = corners[2].x - corners[0].x;
    const double m10 = corners[1].y - corners[0].y, m11 = corners[2].y - corners[0].y;
    const double det = m00 * m11 - m01 * m10;
    if (det != 0) {
        out.dp_du = (at.dp_du * m11 - at.dp_dv * m10) / det;
        out.dp_dv = (at.dp_dv * m00 - at.dp_du * m01) / det;
    }
    return out;
}

}  // namespace

bool Object::travels() const {
    const Shapes all = shapes();
    return std::ranges::any_of(all.spheres, [](const auto& s) { return s.path->travels(); }) ||
           std::ranges::any_of(all.meshes, [](const auto& m) { return m.path->travels(); });
}

SurfaceUv Object::surface_uv(const Ray&, const Hit&, const SurfaceHit&) const {
    return {};
}

SurfaceHit Object::surface_at(const Ray& ray, const Hit& hit,
                              const RayDifferential* differential) const {
    SurfaceHit surface;
    const SurfaceCoordinates at = locate(ray, hit, surface);
    if (!reads_uv_) {
        if (detail_.bump)
            surface.shading_normal = detail_.bump->perturb(surface.shading_normal, at.bump_point);
        surface.kd = detail_.texture ? detail_.texture->value({at.texture_point, {}, {}, {}})
                                     : material_->kd;
        return surface;
    }

    const SurfaceUv own = surface_uv(ray, hit, surface);
    TexturePoint point{at.texture_point, own.uv, {}, {}};
    if (differential) {
        point.duv_dx = uv_step(differential->dx, surface.point, surface.normal, own);
        point.duv_dy = uv_step(differential->dy, surface.point, surface.normal, own);
    }
    SurfaceUv uv = own;
    if (detail_.corner_uv) {
        uv = through_corners(own, *detail_.corner_uv);
        point.uv = uv.uv;
        point.duv_dx = mapped(*detail_.corner_uv, point.duv_dx);
        point.duv_dy = mapped(*detail_.corner_uv, point.duv_dy);
    }
    if (detail_.height_map) {
        surface.shading_normal =
            detail_.height_map->perturb(surface.shading_normal, point, uv.dp_du, uv.dp_dv);
    } else if (detail_.bump) {
        surface.shading_normal = detail_.bump->perturb(surface.shading_normal, at.bump_point);
    }
    surface.kd = detail_.texture ? detail_.texture->value(point) : material_->kd;
    return surface;
}

}  // namespace drt
