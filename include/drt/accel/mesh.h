// A triangle mesh as drt stores and intersects it: vertex positions in single precision relative
// to the mesh's own origin (the centre of its bounds), one index buffer, vertex normals for
// smooth shading, and a bounding-volume hierarchy of its own over its triangles. A scene places
// the mesh by translating that origin (and moves it by moving the translation), so a mesh keeps
// its single-precision detail however far from the world's origin it stands.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "drt/accel/mesh_build.h"
#include "drt/geometry/motion.h"
#include "drt/geometry/object.h"
#include "drt/geometry/triangle.h"
#include "drt/io/obj_reader.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

// How a file's vertices are turned: scaled by `scale` (positive), then rotated about x, y and z
// in that order by `rotate_degrees` (right-handed rotations of the vertex), before the scene
// translates them.
struct MeshTransform {
    double scale = 1;
    Vec3 rotate_degrees;

    Vec3 apply(const Vec3& v) const;
    // The same rotation for a direction (a uniform positive scale leaves directions alone).
    Vec3 rotate(const Vec3& v) const;
};

struct MeshHit {
    double t;
    std::uint32_t triangle;
    Barycentrics b;
};

class TriangleMesh {
  public:
    // Transforms the file's vertices and builds the hierarchy. Triangles of zero area are left
    // out (dropped() counts them). With `smooth`, vertex normals are the file's `vn` where a
    // corner has one, else the angle-weighted normals of the faces around the vertex. Throws
    // std::domain_error if a transformed coordinate does not fit in single precision. The
    // hierarchy is built on `build_threads` threads (0: one per core); the tree is the same
    // whatever their number.
    TriangleMesh(const ObjMesh& obj, const MeshTransform& transform, bool smooth,
                 int build_threads = 0);
    // The same, emptying `obj` before the hierarchy is built, which lowers the peak memory.
    TriangleMesh(ObjMesh&& obj, const MeshTransform& transform, bool smooth, int build_threads = 0);

    std::size_t triangle_count() const { return triangles_.size(); }
    std::size_t dropped() const { return dropped_; }
    // Where the mesh's own coordinates have their origin, in the coordinates of the transform.
    const Vec3& origin() const { return origin_; }
    // Bounds in the mesh's own coordinates.
    Bounds bounds() const;

    // Nearest hit inside `range` of a ray given in the mesh's own coordinates.
    std::optional<MeshHit> intersect(const Ray& ray, Interval range) const;
    // Whether any triangle meets the ray inside `range` (stops at the first).
    bool occluded(const Ray& ray, Interval range) const;
    // How many triangles the query (nearest hit, or any hit) tests on its way, counting every
    // triangle of a batch of up to four tested together: what the hierarchy saves, for tests
    // and benchmarks.
    std::uint64_t triangle_tests(const Ray& ray, Interval range, bool any_hit) const;

    std::array<Vec3, 3> corners(std::uint32_t triangle) const;
    // Unit (p1 - p0) × (p2 - p0): outward for a closed mesh wound counter-clockwise.
    Vec3 geometric_normal(std::uint32_t triangle) const;
    // Unit interpolated vertex normal, or the geometric normal for a flat mesh; may face either
    // way relative to the geometric normal.
    Vec3 shading_normal(std::uint32_t triangle, const Barycentrics& b) const;
    bool smooth() const { return !normals_.empty(); }
    // For a smooth mesh, the point at `b` moved out onto the curved surface that the vertex
    // normals describe (SurfaceHit::light_point in object.h).
    Vec3 lifted(std::uint32_t triangle, const Barycentrics& b) const;

    // Memory held for geometry and hierarchy.
    std::size_t bytes() const;

    using Float3 = std::array<float, 3>;
    // The geometry as stored, for handing the same triangles to another kernel (bench/): the
    // positions relative to origin(), and each triangle's vertices, in the order whose index
    // MeshHit::triangle gives.
    std::span<const Float3> positions() const { return positions_; }
    std::span<const std::array<std::uint32_t, 3>> triangles() const { return triangles_; }
    // The hierarchy's nodes as bytes, for telling whether two builds made the same tree.
    std::span<const std::byte> hierarchy() const { return std::as_bytes(std::span(nodes_)); }

  private:
    // The tree traversed has up to eight children a node, their boxes side by side so that one
    // 8-wide SIMD test (AVX; two 4-wide ones elsewhere) tests them all, as Embree does for
    // single rays (Wald, Benthin & Boulos 2008; Dammertz et al. 2008): half the levels of a
    // 4-wide tree. 256 bytes a node, aligned to start a cache line: the boxes are its first
    // three lines. A child is a node (`count` 0, `child` its index) or a leaf (`count` triangles
    // from `child`); the first `children` slots are used.
    static constexpr int kWidth = 8;
    struct alignas(64) Node {
        float box[2][3][kWidth];  // [low side, high side][axis][child]
        std::uint32_t child[kWidth];
        std::uint16_t count[kWidth];
        std::uint32_t children;
        std::uint32_t unused[3];  // 0: a node has no padding bytes of unknown value
    };

    // The vertices, triangles and normals of the mesh from the file's.
    void take(const ObjMesh& obj, const MeshTransform& transform, bool smooth);
    Vec3 position(std::uint32_t vertex) const;
    // `threads` 0: one per core.
    void build_hierarchy(int threads);
    // Numbers the vertices in the order the leaves first use them, so that a leaf's corners
    // are near each other in memory (on a large mesh they were a cache miss each).
    void order_vertices_by_leaves();
    // Turns every inner node whose subtree holds few triangles into a leaf of them all.
    static void collapse_small_subtrees(std::vector<BinaryNode>& binary);
    // Turns the binary subtree at `node` into wide nodes appended to nodes_; returns the index
    // of the one made for `node`.
    std::uint32_t widen(const std::vector<BinaryNode>& binary, std::uint32_t node);
    // What a query answers: whether any triangle is hit, or the nearest hit.
    template <bool kAnyHit>
    using Answer = std::conditional_t<kAnyHit, bool, std::optional<MeshHit>>;
    // `tests`, when given, counts the triangles tested.
    template <bool kAnyHit>
    Answer<kAnyHit> traverse(const Ray& ray, Interval range, std::uint64_t* tests = nullptr) const;

    Vec3 origin_;
    std::vector<Float3> positions_;  // relative to origin_
    std::vector<Float3> normals_;    // per vertex, unit; empty for a flat mesh
    std::vector<std::array<std::uint32_t, 3>> triangles_;  // in leaf order
    std::vector<Node> nodes_;
    Float3 lo_{}, hi_{};        // bounds of every triangle
    bool filter_fits_ = false;  // coordinates small enough for the float filter
    std::size_t dropped_ = 0;
};

// A mesh in the scene: a TriangleMesh translated by T, and moving like a sphere when given more
// translations (T at time 0, the present, then one per time unit into the past). Both sides of
// every triangle are seen; the winding tells outside from inside.
class Mesh final : public Object {
  public:
    Mesh(std::shared_ptr<const TriangleMesh> mesh, const std::vector<Vec3>& translations,
         const Material& material, SurfaceDetail detail = {});

    std::optional<Hit> intersect(const Ray& ray, Interval range) const override;
    Shapes shapes() const override { return {{}, {}, {MeshShape{mesh_.get(), &path_}}}; }
    double motion_end() const override { return path_.end(); }

    const TriangleMesh& mesh() const { return *mesh_; }
    // Where the mesh's own origin is at each time.
    const MotionPath& path() const { return path_; }

  protected:
    SurfaceCoordinates locate(const Ray& ray, const Hit& hit, SurfaceHit& surface) const override;
    // A triangle's own (u, v): the barycentrics (b1, b2) of the hit.
    SurfaceUv surface_uv(const Ray& ray, const Hit& hit, const SurfaceHit& surface) const override;

  private:
    std::shared_ptr<const TriangleMesh> mesh_;
    MotionPath path_;
};

// The ray moved into a mesh's own coordinates, whose origin is at `origin`: the BVH and
// Mesh::intersect both use it, so that they find the same hit.
inline Ray ray_in_mesh(const Ray& ray, const Vec3& origin) {
    return {ray.origin - origin, ray.dir, ray.time};
}

}  // namespace drt
