// A bounding-volume hierarchy over the scene's bounded shapes, aware of motion: a moving sphere
// enters once per segment of its path, bounded over that segment's time span only, and every
// node knows the time span of what it holds, so rays skip shapes that are elsewhere at their
// time. Unbounded shapes (planes) are tested separately.
//
// Objects hand over their geometry as typed shapes (Object::shapes), copied here into flat
// arrays and tested inline by one leaf test (Bvh::hit) with the same arithmetic as the objects'
// own intersect, so a traversal makes no virtual call and chases no pointer.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "drt/geometry/object.h"

namespace drt {

// The mesh triangle a ray leaves from, which a Bvh's queries skip untested
// (TriangleMesh::kNoTriangle): only for a ray that starts just off the plane of a triangle the
// Bvh hit, heading away from it, as spawn_ray makes them. Other rays leave nothing.
struct Leaving {
    std::uint32_t piece = Hit::kNoPiece;
    std::uint32_t triangle = 0;
};

class Bvh {
  public:
    explicit Bvh(const std::vector<std::unique_ptr<Object>>& objects);

    // The triangle a ray leaves from, skipped untested (Leaving).
    static Leaving leaving(const Hit& hit) { return {hit.piece, hit.primitive}; }
    std::optional<Hit> intersect(const Ray& ray, Interval range, Leaving leaving = {}) const;
    // Whether anything blocks the ray within range (any hit will do, so it stops at the first).
    bool occluded(const Ray& ray, Interval range, Leaving leaving = {}) const {
        return occluded(ray, range, kAllPlanes, leaving);
    }

    std::size_t node_count() const { return nodes_.size(); }

    // What the shadow-ray culling (occluders.h) reads and tests.
    struct PlaneData {
        Vec3 point, normal;
        double point_scale;  // max_abs_component(point)
        double offset;       // dot(point, normal)
        std::uint32_t object, index;
    };
    static constexpr std::uint64_t kAllPlanes = ~std::uint64_t{0};
    std::span<const PlaneData> planes() const { return planes_; }
    // Whether the ray is blocked within range by a plane whose bit is set in `planes` (planes
    // past the 64th always count) or by anything in the tree.
    bool occluded(const Ray& ray, Interval range, std::uint64_t planes, Leaving leaving = {}) const;
    // The same, testing only the listed primitives (as visit_near names them) of the tree.
    bool occluded_by(const Ray& ray, Interval range, std::uint64_t planes,
                     std::span<const std::uint32_t> primitives, Leaving leaving = {}) const;
    // Whether primitive i (as visit_near names them) is a sphere of `object`, or a segment of
    // one's path.
    bool is_sphere_of(std::uint32_t primitive, const Object* object) const {
        const Primitive& p = primitives_[primitive];
        return !is_mesh(p.kind) && objects_[p.object] == object;
    }
    // Calls visit(i) for each primitive i present at `time` whose ball at that time passes
    // `may_meet` (a conservative test of a Ball), skipping subtrees whose bounding ball fails
    // it; stops, returning false, as soon as visit returns false.
    template <class MayMeet, class Visit>
    bool visit_near(double time, const MayMeet& may_meet, const Visit& visit) const;

  private:
    enum class Kind : std::uint32_t { kStillSphere, kMovingSphere, kStillMesh, kMovingMesh };

    // One still sphere or mesh, or one segment of a moving one's path, in leaf order.
    struct alignas(64) Primitive {
        // A still sphere's centre, or a still mesh's own origin (a moving one's is
        // motions_[motion].at(time))
        Vec3 centre;
        double radius;         // a mesh's: of a ball about meshes_[index].ball_offset from centre
        Interval time;         // shutter times at which this piece is where the bounds say
        std::uint32_t object;  // index into objects_
        std::uint32_t index;   // a sphere's Hit::primitive; a mesh's index into meshes_
        Kind kind;
        std::uint32_t motion;  // index into motions_ for a moving sphere or mesh
    };
    static constexpr bool is_mesh(Kind kind) {
        return kind == Kind::kStillMesh || kind == Kind::kMovingMesh;
    }
    struct MeshData {
        const TriangleMesh* mesh;
        Vec3 ball_offset;  // centre of the mesh's bounds in its own coordinates
        // A mesh shared by several objects (MeshShape::part): the object (index into objects_)
        // of each part, kNoObject for a part no object claimed; empty for a mesh of one object.
        std::vector<std::uint32_t> part_objects = {};
    };
    static constexpr std::uint32_t kNoObject = ~std::uint32_t{0};
    // The object a hit on `triangle` of primitive p belongs to.
    std::uint32_t object_of(const Primitive& p, std::uint32_t triangle) const;
    // A node is one cache line: its box, the time span of what it holds (rounded outwards to
    // float), and its primitives (leaf) or its second child (inner; the first follows it).
    struct alignas(64) Node {
        double box[6];  // lo x, y, z then hi x, y, z
        float time_min, time_max;
        std::uint32_t offset;  // leaf: first primitive; inner: index of the second child
        std::uint32_t count;   // primitives in a leaf, 0 for an inner node
    };
    struct Build {
        Bounds bounds;
        Interval time;
        std::uint32_t primitive;
    };
    struct RayData;

    // Deep enough for any tree: the build splits at the median past a depth of 64.
    static constexpr int kStackSize = 128;

    std::uint32_t build(std::vector<Build>& items, std::uint32_t begin, std::uint32_t end,
                        int depth);
    // What a traversal keeps of the nearest hit so far (its t is the range's end).
    struct Nearest {
        std::uint32_t object = 0, index = 0;
        Vec2 uv;
        std::uint32_t piece = Hit::kNoPiece;
    };
    // Whether the ray hits anything within range; the nearest hit (or, for kAnyHit, the first
    // found) shrinks range.max to its t and is described in `nearest`.
    template <bool kAnyHit>
    bool traverse(const Ray& ray, Interval& range, std::uint64_t planes, Leaving leaving,
                  Nearest& nearest) const;
    // The one leaf test: the ray parameter inside `range` at which the ray meets primitive p at
    // the ray's time. A mesh writes the triangle it hit and its barycentrics b1, b2 into
    // `triangle` and `uv`. For kAnyHit, a mesh answers with any hit, range.max for its t and
    // nothing written. A mesh skips triangle `skip` (TriangleMesh::kNoTriangle: none).
    template <bool kAnyHit>
    std::optional<double> hit(const Primitive& p, const Ray& ray, double origin_scale,
                              Interval range, std::uint32_t skip, std::uint32_t& triangle,
                              Vec2& uv) const;
    template <bool kAnyHit>
    std::optional<double> hit_segment(const Primitive& p, const Ray& ray, double origin_scale,
                                      Interval range, std::uint32_t skip, std::uint32_t& triangle,
                                      Vec2& uv) const;
    // Where primitive p is at `time`, as a ball (for the shadow-ray culling).
    Ball ball_at(const Primitive& p, double time) const {
        if (p.kind == Kind::kStillSphere) return {p.centre, p.radius};
        const Vec3 at = p.kind == Kind::kStillMesh ? p.centre : motions_[p.motion].at(time);
        if (p.kind == Kind::kMovingSphere) return {at, p.radius};
        return {at + meshes_[p.index].ball_offset, p.radius};
    }

    std::vector<const Object*> objects_;
    std::vector<Primitive> primitives_;  // in leaf order
    std::vector<PathSegment> motions_;
    std::vector<MeshData> meshes_;
    std::vector<Node> nodes_;
    std::vector<PlaneData> planes_;
};

template <class MayMeet, class Visit>
bool Bvh::visit_near(double time, const MayMeet& may_meet, const Visit& visit) const {
    if (nodes_.empty()) return true;
    std::array<std::uint32_t, kStackSize> stack;
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const std::uint32_t index = stack[--top];
        const Node& node = nodes_[index];
        if (!(node.time_min <= time && time <= node.time_max)) continue;
        // (A tree that is a single leaf goes straight to its few primitives.)
        if (nodes_.size() > 1) {
            const Vec3 lo{node.box[0], node.box[1], node.box[2]};
            const Vec3 hi{node.box[3], node.box[4], node.box[5]};
            if (!may_meet(Ball{(lo + hi) * 0.5, 0.5 * length(hi - lo)})) continue;
        }
        if (node.count == 0) {
            stack[top++] = node.offset;
            stack[top++] = index + 1;
            continue;
        }
        for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
            const Primitive& p = primitives_[i];
            if (!p.time.contains(time)) continue;
            if (may_meet(ball_at(p, time)) && !visit(i)) return false;
        }
    }
    return true;
}

}  // namespace drt
