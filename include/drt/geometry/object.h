// The abstract scene object: something a ray can hit, made of a material, optionally textured
// and bump-mapped. An object hands the BVH its geometry as typed shapes (spheres, planes), which
// the BVH copies into flat arrays and tests inline; the object itself is asked again only about
// the one hit a ray keeps, for its surface.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "drt/geometry/motion.h"
#include "drt/shading/image_texture.h"
#include "drt/shading/material.h"
#include "drt/shading/texture.h"
#include "drt/util/color.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

class Object;

// Where a ray met a primitive (pbrt-v4's and Mitsuba 3's preliminary intersection): what the
// intersection test knows, from which Object::surface_at works out the rest for the one hit a
// ray keeps.
struct Hit {
    double t = kInfinity;            // ray parameter
    const Object* object = nullptr;  // the object hit
    std::uint32_t primitive = 0;     // which of the object's shapes (a mesh's triangle number)
    // The primitive's own coordinates of the hit where its test yields them (a triangle's
    // barycentrics b1, b2, from which a mesh interpolates normals). Spheres and planes leave
    // them 0: their surface follows exactly from the point ray.at(t) projected onto them.
    Vec2 uv;
    // The accelerator's own number for the piece of geometry hit, by which a ray leaving the hit
    // skips it (Bvh::Leaving); kNoPiece where no accelerator found the hit.
    static constexpr std::uint32_t kNoPiece = ~std::uint32_t{0};
    std::uint32_t piece = kNoPiece;
};

// What the integrator needs to know about the point a ray hit.
struct SurfaceHit {
    Vec3 point;           // on the surface, refined after intersection
    Vec3 normal;          // geometric, unit, pointing out of the object
    Vec3 shading_normal;  // normal after bump mapping, same side as `normal`
    Color kd;             // diffuse colour after texturing
    // Where shadow rays leave, and the normal that says which lights are above: `point` and
    // `normal`, except on a smooth mesh, where rays from the flat facet would black out facets
    // along the shadow terminator. There they leave from the point lifted onto the curved surface
    // the vertex normals describe (Hanika, Ray Tracing Gems II, 2021), and that normal decides.
    Vec3 light_point, light_normal;
};

// A hit's normals turned to the side a ray of direction `dir` arrived on, as every integrator
// shades them: `outside` when that is the side `normal` points to.
struct FacingNormals {
    bool outside;
    Vec3 geometric;
    // The shading normal, or the geometric one where a bump tilted it past the viewer.
    Vec3 shading;
    Vec3 light;  // light_normal, which says which lights are above
};

inline FacingNormals facing_normals(const SurfaceHit& surface, const Vec3& dir) {
    const bool outside = dot(dir, surface.normal) < 0;
    const Vec3 geometric = outside ? surface.normal : -surface.normal;
    Vec3 shading = outside ? surface.shading_normal : -surface.shading_normal;
    if (dot(shading, dir) >= 0) shading = geometric;
    return {outside, geometric, shading, outside ? surface.light_normal : -surface.light_normal};
}

// A sphere as the BVH stores it: the BVH splits its path into one piece per segment, each bounded
// over that segment's time span only.
struct SphereShape {
    const MotionPath* path;  // owned by the object, which outlives the BVH
    double radius;
};
struct PlaneShape {
    Vec3 point, normal;  // normal of unit length
};
class TriangleMesh;
// A triangle mesh enters the BVH whole (one piece per segment of its path), and the BVH's leaf
// test runs the mesh's own hierarchy on the ray moved into the mesh's coordinates.
// Several objects may share one mesh, each its own part of it (TriangleMesh::parts): the BVH
// enters the mesh once and gives each hit to the object of the hit triangle's part.
struct MeshShape {
    static constexpr std::uint32_t kWhole = ~std::uint32_t{0};
    const TriangleMesh* mesh;     // owned by the object, which outlives the BVH
    const MotionPath* path;       // where the mesh's own origin is at each time
    std::uint32_t part = kWhole;  // the object's part of the mesh; kWhole: every triangle
    Bounds bounds = {};           // of the object's triangles, in the mesh's coordinates
};
// An object's geometry in the typed forms the BVH tests inline (no virtual call and no pointer
// chase per ray). A new kind of primitive gets its array here, its Kind and case in the BVH's
// one leaf test (Bvh::hit) and its bounds in the BVH's build; Hit::primitive is its index in
// its array.
struct Shapes {
    std::vector<SphereShape> spheres;
    std::vector<PlaneShape> planes;  // unbounded: tested outside the tree
    std::vector<MeshShape> meshes = {};
};

// How an object's surface departs from its material's plain colour.
struct SurfaceDetail {
    std::shared_ptr<const Texture> texture;  // replaces the material's kd; null = none
    std::optional<BumpMap> bump;
    // Image-mapped surfaces (docs/scene-format.md, "Image textures").
    std::shared_ptr<const HeightMap> height_map;  // bumps instead of `bump`'s noise; null = none
    double texture_scale = 1;                     // a plane's (u, v) are its coordinates over this
    // A lone triangle's corner (u, v) for A, B, C: its own (u, v) are the barycentrics (b1, b2),
    // which these map affinely.
    std::optional<std::array<Vec2, 3>> corner_uv;

    bool reads_uv() const { return height_map || (texture && texture->reads_uv()); }
};

// A surface's texture coordinates at a point and how the point moves as they grow.
struct SurfaceUv {
    Vec2 uv;
    Vec3 dp_du, dp_dv;
};

class Object {
  public:
    Object(const Material& material, SurfaceDetail detail)
        : material_(&material), detail_(std::move(detail)), reads_uv_(detail_.reads_uv()) {}
    virtual ~Object() = default;
    Object(const Object&) = delete;
    Object& operator=(const Object&) = delete;

    // The nearest intersection inside `range`, if any, tested on this object alone (the BVH
    // tests the same shapes with the same arithmetic and must find the same hit).
    virtual std::optional<Hit> intersect(const Ray& ray, Interval range) const = 0;
    virtual Shapes shapes() const = 0;

    const Material& material() const { return *material_; }
    const SurfaceDetail& detail() const { return detail_; }
    // Whether the surface's texture or height map reads (u, v): detail().reads_uv(), kept.
    bool reads_uv() const { return reads_uv_; }
    // Shutter time at which the object's motion path ends; 0 for an object that stays put.
    virtual double motion_end() const { return 0; }
    bool moves() const { return motion_end() > 0; }
    // Whether it goes anywhere: a motion path whose points are not all one place.
    bool travels() const;

    // Surface information at a hit on this object by `ray`. An image texture is filtered over
    // the footprint of `differential` where given (camera rays), else read at its finest level.
    SurfaceHit surface_at(const Ray& ray, const Hit& hit,
                          const RayDifferential* differential = nullptr) const;

  protected:
    // Where a texture and a bump map are evaluated at a hit: coordinates fixed to a moving
    // object for the texture, world-aligned ones for bump noise.
    struct SurfaceCoordinates {
        Vec3 texture_point, bump_point;
    };
    // Where on the surface a hit lies, before texture and bump, written into `surface`: the point
    // on the surface nearest ray.at(t) (rid of most of a hit point's rounding error), the
    // geometric normal (unit, outward), the shading normal before bump mapping (a mesh's is
    // interpolated) and where shadow rays leave. In place, so the record is not copied per hit.
    virtual SurfaceCoordinates locate(const Ray& ray, const Hit& hit,
                                      SurfaceHit& surface) const = 0;
    // The surface's (u, v) at a hit that `locate` has filled `surface` for, asked only of an
    // object with an image texture or height map. The default has no coordinates: (0, 0).
    virtual SurfaceUv surface_uv(const Ray& ray, const Hit& hit, const SurfaceHit& surface) const;

  private:
    const Material* material_;
    SurfaceDetail detail_;
    bool reads_uv_;
};

}  // namespace drt
