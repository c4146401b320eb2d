#include "drt/accel/mesh.h"

#include <cmath>
#include <utility>

namespace drt {

namespace {

std::vector<Vec3> shifted(std::vector<Vec3> points, const Vec3& by) {
    for (Vec3& p : points) p += by;
    return points;
}

}  // namespace

Mesh::Mesh(std::shared_ptr<const TriangleMesh> mesh, const std::vector<Vec3>& translations,
           const Material& material, SurfaceDetail detail, std::uint32_t part)
    : Object(material, std::move(detail)),
      mesh_(std::move(mesh)),
      path_(shifted(translations, mesh_->origin())),
      part_(mesh_->parts().empty() ? MeshShape::kWhole : part) {
    if (part_ == MeshShape::kWhole) {
        bounds_ = mesh_->bounds();
        return;
    }
    for (std::uint32_t t = 0; t < mesh_->triangle_count(); ++t) {
        if (mesh_->parts()[t] != part_) continue;
        for (const Vec3& p : mesh_->corners(t)) bounds_.grow(p);
    }
}

std::optional<Hit> Mesh::intersect(const Ray& ray, Interval range) const {
    const Ray local = ray_in_mesh(ray, path_.at(ray.time));
    if (part_ == MeshShape::kWhole) {
        const auto hit = mesh_->intersect(local, range);
        if (!hit) return std::nullopt;
        return Hit{hit->t, this, hit->triangle, {hit->b.b1, hit->b.b2}};
    }
    // One part of a shared mesh, tested alone: its triangles one by one with the test the
    // mesh's tree runs (the BVH enters the tree once for all parts instead).
    const ShearedRay sheared(local);
    std::optional<Hit> nearest;
    for (std::uint32_t t = 0; t < mesh_->triangle_count(); ++t) {
        if (mesh_->parts()[t] != part_) continue;
        const auto [a, b, c] = mesh_->corners(t);
        if (const auto hit = intersect_triangle(sheared, a, b, c, range)) {
            range.max = hit->t;
            nearest = Hit{hit->t, this, t, {hit->b.b1, hit->b.b2}};
        }
    }
    return nearest;
}

Object::SurfaceCoordinates Mesh::locate(const Ray& ray, const Hit& hit, SurfaceHit& surface) const {
    const Vec3 origin = path_.at(ray.time);
    const auto [a, b, c] = mesh_->corners(hit.primitive);
    const Barycentrics w{1 - hit.uv.x - hit.uv.y, hit.uv.x, hit.uv.y};
    // From the barycentrics rather than ray.at(t): on the triangle's plane to rounding in the
    // mesh's own coordinates, whatever distance the ray came from.
    surface.point = origin + (a * w.b0 + b * w.b1 + c * w.b2);
    surface.normal = mesh_->geometric_normal(hit.primitive);
    // A flat mesh's shading normal is the face's own, computed once.
    surface.shading_normal =
        mesh_->smooth() ? mesh_->shading_normal(hit.primitive, w) : surface.normal;
    if (mesh_->smooth()) {
        surface.light_point = origin + mesh_->lifted(hit.primitive, w);
        surface.light_normal = surface.shading_normal;
    } else {
        surface.light_point = surface.point;
        surface.light_normal = surface.normal;
    }
    // Textures and bumps stay where the mesh is at time 0, the present: world coordinates for
    // a mesh that does not move.
    const Vec3 fixed = surface.point - (origin - path_.at(0));
    return {fixed, fixed};
}

SurfaceUv Mesh::surface_uv(const Ray&, const Hit& hit, const SurfaceHit&) const {
    const auto [a, b, c] = mesh_->corners(hit.primitive);
    const Vec3 e1 = b - a, e2 = c - a;
    if (!mesh_->has_texcoords()) return {hit.uv, e1, e2};
    const auto [ta, tb, tc] = mesh_->corner_texcoords(hit.primitive);
    const double w0 = 1 - hit.uv.x - hit.uv.y, w1 = hit.uv.x, w2 = hit.uv.y;
    const Vec2 uv{ta.x * w0 + tb.x * w1 + tc.x * w2, ta.y * w0 + tb.y * w1 + tc.y * w2};
    // How the point moves along u and v: the edges solved against their (u, v) differences.
    const double du1 = tb.x - ta.x, dv1 = tb.y - ta.y, du2 = tc.x - ta.x, dv2 = tc.y - ta.y;
    const double det = du1 * dv2 - dv1 * du2;
    if (det == 0 || !std::isfinite(1 / det)) return {uv, e1, e2};  // corners share a (u, v)
    const double inv = 1 / det;
    return {uv, (e1 * dv2 - e2 * dv1) * inv, (e2 * du1 - e1 * du2) * inv};
}

}  // namespace drt
