// A triangle mesh as drt stores and intersects it: vertex positions in single precision relative
// to the mesh's own origin (the centre of its bounds), one index buffer, vertex normals for
// smooth shading, and a tree of its own over its triangles (mesh_tree.h, mesh_traversal.cpp). A
// scene places the mesh by translating that origin (and moves it by moving the translation), so a
// mesh keeps its single-precision detail however far from the world's origin it stands.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "drt/accel/float3.h"
#include "drt/accel/mesh_tree.h"
#include "drt/geometry/mesh_transform.h"
#include "drt/geometry/triangle.h"
#include "drt/io/obj_reader.h"
#include "drt/shading/mipmap.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

struct MeshHit {
    double t;
    std::uint32_t triangle;
    Barycentrics b;
};

class TriangleMesh {
  public:
    // Transforms the file's vertices and builds the hierarchy. Triangles of zero area in the
    // file's own coordinates are left out (dropped() counts them), and so are those that
    // single precision flattens (collapsed() counts them). With `smooth`, vertex normals are the
    // file's `vn` where a corner has one, else the angle-weighted normals of the faces around the
    // vertex. Throws std::domain_error if a transformed coordinate does not fit in single
    // precision. The hierarchy is built on `build_threads` threads (0: one per core); the tree is
    // the same whatever their number.
    TriangleMesh(const ObjMesh& obj, const MeshTransform& transform, bool smooth,
                 int build_threads = 0);
    // The same, emptying `obj` before the hierarchy is built, which lowers the peak memory.
    TriangleMesh(ObjMesh&& obj, const MeshTransform& transform, bool smooth, int build_threads = 0);

    // Whether a mesh whose origin is `origin` keeps a triangle of non-zero area with corners
    // a, b, c (in the transform's coordinates): they fit in single precision about the origin,
    // and rounded to it they still span an area.
    static bool holds(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& origin);

    std::size_t triangle_count() const { return triangles_.size(); }
    std::size_t dropped() const { return dropped_; }
    // Triangles of non-zero area whose corners, in single precision, lie on a line: no ray
    // meets them at a well-defined point and they have no normal to shade with.
    std::size_t collapsed() const { return collapsed_; }
    // Where the mesh's own coordinates have their origin, in the coordinates of the transform.
    const Vec3& origin() const { return origin_; }
    // Bounds in the mesh's own coordinates.
    Bounds bounds() const { return tree_.bounds(); }

    // An alpha cut-out (an MTL map_d): a point whose alpha (the map's first channel, bilinear at
    // the point's (u, v)) is below ½ is not there, and every ray, shadow rays included, passes
    // it. A mesh without one runs the queries exactly as before.
    void set_alpha(std::shared_ptr<const MipMap> alpha) { alpha_ = std::move(alpha); }
    bool has_alpha() const { return alpha_ != nullptr; }
    bool opaque(std::uint32_t triangle, const Barycentrics& b) const;

    // A ray that leaves a triangle from just off its plane, heading away from it, cannot meet
    // it, but the float filter cannot tell so from that close: the queries skip the triangle
    // named `leaving` untested (kNoTriangle: none), which changes no answer.
    static constexpr std::uint32_t kNoTriangle = ~std::uint32_t{0};
    // Nearest hit inside `range` of a ray given in the mesh's own coordinates.
    std::optional<MeshHit> intersect(const Ray& ray, Interval range,
                                     std::uint32_t leaving = kNoTriangle) const;
    // Whether any triangle meets the ray inside `range` (stops at the first).
    bool occluded(const Ray& ray, Interval range, std::uint32_t leaving = kNoTriangle) const;
    // How many triangles the query (nearest hit, or any hit) tests on its way, counting every
    // triangle of a batch of up to four tested together: what the hierarchy saves, for tests
    // and benchmarks.
    std::uint64_t triangle_tests(const Ray& ray, Interval range, bool any_hit) const;

    std::array<Vec3, 3> corners(std::uint32_t triangle) const {
        const auto& t = triangles_[triangle];
        return {position(t[0]), position(t[1]), position(t[2])};
    }
    // Unit (p1 - p0) × (p2 - p0): outward for a closed mesh wound counter-clockwise.
    Vec3 geometric_normal(std::uint32_t triangle) const;
    // Unit interpolated vertex normal, or the geometric normal for a flat mesh; may face either
    // way relative to the geometric normal.
    Vec3 shading_normal(std::uint32_t triangle, const Barycentrics& b) const;
    bool smooth() const { return !normals_.empty(); }
    // Whether the file gave texture coordinates (`vt`); only then are they kept.
    bool has_texcoords() const { return !texcoords_.empty(); }
    // The (u, v) of a triangle's corners: the file's `vt`, (0, 0) for a corner without one.
    std::array<Vec2, 3> corner_texcoords(std::uint32_t triangle) const {
        const auto& t = texcoords_[triangle];
        return {Vec2{t[0], t[1]}, Vec2{t[2], t[3]}, Vec2{t[4], t[5]}};
    }
    // Which part of the mesh each triangle belongs to, for a mesh that several objects share (one
    // material each, as the <Triangle>s of a scene): the file's `triangle_materials` in the
    // order of MeshHit::triangle; empty where the file has none.
    std::span<const std::uint32_t> parts() const { return parts_; }
    // For a smooth mesh, the point at `b` moved out onto the curved surface that the vertex
    // normals describe (SurfaceHit::light_point in object.h).
    Vec3 lifted(std::uint32_t triangle, const Barycentrics& b) const;

    // Memory held for geometry and hierarchy.
    std::size_t bytes() const;

    // The geometry as stored, for handing the same triangles to another kernel (bench/): the
    // positions relative to origin(), and each triangle's vertices, in the order whose index
    // MeshHit::triangle gives.
    std::span<const Float3> positions() const { return positions_; }
    std::span<const std::array<std::uint32_t, 3>> triangles() const { return triangles_; }
    // The hierarchy's nodes as bytes, for telling whether two builds made the same tree.
    std::span<const std::byte> hierarchy() const { return tree_.bytes(); }

  private:
    // The vertices, triangles and normals of the mesh from the file's.
    void take(const ObjMesh& obj, const MeshTransform& transform, bool smooth);
    Vec3 position(std::uint32_t vertex) const { return to_vec3(positions_[vertex]); }
    // `threads` 0: one per core.
    void build_hierarchy(int threads);
    // Numbers the vertices in the order the leaves first use them, so that a leaf's corners
    // are near each other in memory.
    void order_vertices_by_leaves();
    // corners_ and face_normals_, for a mesh of at most kCornerArrayLimit triangles.
    void make_corner_arrays();
    // What a query answers: whether any triangle is hit, or the nearest hit.
    template <bool kAnyHit>
    using Answer = std::conditional_t<kAnyHit, bool, std::optional<MeshHit>>;
    // The query (mesh_traversal.cpp); `tests`, when given, counts the triangles tested.
    // kAlpha: hits on cut-out points are passed over (set_alpha).
    template <bool kAnyHit, bool kAlpha = false>
    Answer<kAnyHit> traverse(const Ray& ray, Interval range, std::uint32_t leaving,
                             std::uint64_t* tests = nullptr) const;

    Vec3 origin_;
    std::vector<Float3> positions_;  // relative to origin_
    std::vector<Float3> normals_;    // per vertex, unit; empty for a flat mesh
    // Per vertex, whether its normal is the file's turned to its faces' winding (take()); empty
    // when none is. The lift towards the curved surface (lifted) keeps the file's side.
    std::vector<bool> turned_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;  // in leaf order
    // Per triangle, its corners' (u, v) in single precision; empty when the file has no `vt`.
    std::vector<std::array<float, 6>> texcoords_;
    std::vector<std::uint32_t> parts_;  // per triangle; empty for a mesh of one part
    // A small mesh's float corners once more, one array a coordinate ([corner][axis], `stride_`
    // floats apart) in the leaf order, so that the float filter loads a lane of four neighbouring
    // triangles with one load from whichever array the ray's axis order asks for, instead of
    // gathering them through the index buffer. Each array ends with three copies of the last
    // triangle, for lanes past the end. Empty for a larger mesh: 36 more bytes a triangle would
    // break the budget of 80 with the hierarchy, and a large mesh's time goes to memory, not to
    // the gather's instructions.
    static constexpr std::size_t kCornerArrayLimit = 4096;
    std::vector<float> corners_;
    std::size_t stride_ = 0;
    // A small mesh's unit face normals, worked out once as geometric_normal would for every hit
    // (a cross product, a division and a square root); empty beside an empty corners_.
    std::vector<Vec3> face_normals_;
    MeshTree tree_;
    std::shared_ptr<const MipMap> alpha_;  // null: no cut-outs
    std::size_t dropped_ = 0;
    std::size_t collapsed_ = 0;
};

// The ray moved into a mesh's own coordinates, whose origin is at `origin`: the BVH and
// Mesh::intersect both use it, so that they find the same hit.
inline Ray ray_in_mesh(const Ray& ray, const Vec3& origin) {
    return {ray.origin - origin, ray.dir, ray.time};
}

}  // namespace drt
