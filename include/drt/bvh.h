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
#include <vector>

#include "drt/object.h"

namespace drt {

// What may block the segments from one origin to the points of one ball (a light) at one time:
// the planes and primitives that meet the cone those segments fill. Bvh::gather_occluders finds
// them once for a shading point and a light; each of the point's shadow rays then tests only
// them. The default holds everything, which is always correct.
struct Occluders {
    static constexpr int kMaxListed = 16;
    std::uint64_t planes = ~std::uint64_t{0};  // bit i: plane i may block (from the 65th, all may)
    bool everything = true;                    // whether to traverse the tree instead of the list
    bool nothing = false;                      // nothing at all may block: no ray need be traced
    int count = 0;
    std::array<std::uint32_t, kMaxListed> primitives{};
};

class Bvh {
  public:
    explicit Bvh(const std::vector<std::unique_ptr<Object>>& objects);

    std::optional<Hit> intersect(const Ray& ray, Interval range) const;
    // Whether anything blocks the ray within range (any hit will do, so it stops at the first).
    bool occluded(const Ray& ray, Interval range) const;
    // The same for a ray from `origin` to a point of the ball the occluders were gathered for,
    // at their time, testing only them.
    bool occluded(const Ray& ray, Interval range, const Occluders& occluders) const;
    Occluders gather_occluders(const Vec3& origin, const Ball& target, double time) const;

    std::size_t node_count() const { return nodes_.size(); }

  private:
    enum class Kind : std::uint32_t { kStillSphere, kMovingSphere };

    // One still sphere or one segment of a moving sphere's path, in leaf order.
    struct alignas(64) Primitive {
        Vec3 centre;  // a still sphere's (a moving one's is motions_[motion].at(time))
        double radius;
        Interval time;         // shutter times at which this piece is where the bounds say
        std::uint32_t object;  // index into objects_
        std::uint32_t index;   // Hit::primitive: which of the object's shapes
        Kind kind;
        std::uint32_t motion;  // index into motions_ for a moving sphere
    };
    struct PlaneData {
        Vec3 point, normal;
        double point_scale;  // max_abs_component(point)
        double offset;       // dot(point, normal)
        std::uint32_t object, index;
    };
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

    std::uint32_t build(std::vector<Build>& items, std::uint32_t begin, std::uint32_t end,
                        int depth);
    // What a traversal keeps of the nearest hit so far (its t is the range's end).
    struct Nearest {
        std::uint32_t object = 0, index = 0;
        Vec2 uv;
    };
    // Whether the ray hits anything within range; the nearest hit (or, for kAnyHit, the first
    // found) shrinks range.max to its t and is described in `nearest`.
    template <bool kAnyHit>
    bool traverse(const Ray& ray, Interval& range, const Occluders& occluders,
                  Nearest& nearest) const;
    // The one leaf test: the ray parameter inside `range` at which the ray meets primitive p at
    // the ray's time. `uv` receives the primitive's own coordinates where its test yields them.
    std::optional<double> hit(const Primitive& p, const Ray& ray, double origin_scale,
                              Interval range, Vec2& uv) const;
    std::optional<double> hit_segment(const Primitive& p, const Ray& ray, double origin_scale,
                                      Interval range) const;
    // Where primitive p is at `time`, as a ball (for the shadow-ray culling).
    Ball ball_at(const Primitive& p, double time) const;

    std::vector<const Object*> objects_;
    std::vector<Primitive> primitives_;  // in leaf order
    std::vector<PathSegment> motions_;
    std::vector<Node> nodes_;
    std::vector<PlaneData> planes_;
};

}  // namespace drt
