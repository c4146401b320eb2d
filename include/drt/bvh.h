// A bounding-volume hierarchy over the scene's bounded objects, aware of motion: a moving
// sphere enters once per segment of its path, bounded over that segment's time span only, and
// every node knows the time span of what it holds, so rays skip objects that are elsewhere at
// their time. Unbounded objects (planes) are tested separately.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "drt/object.h"

namespace drt {

struct Intersection {
    double t;
    const Object* object;
};

class Bvh {
public:
    explicit Bvh(const std::vector<std::unique_ptr<Object>>& objects);

    std::optional<Intersection> intersect(const Ray& ray, Interval range) const;
    // Whether anything blocks the ray within range (any hit will do, so it stops at the first).
    bool occluded(const Ray& ray, Interval range) const;

    std::size_t node_count() const { return nodes_.size(); }
    std::size_t depth() const;

private:
    struct Primitive {
        const Object* object;
        Bounds bounds;
        Interval time;
    };
    struct Node {
        Bounds bounds;
        Interval time;
        std::uint32_t offset;  // leaf: first primitive; inner: index of the second child
        std::uint16_t count;   // primitives in a leaf, 0 for an inner node
        std::uint8_t axis;     // split axis of an inner node, for front-to-back order
    };

    std::uint32_t build(std::uint32_t begin, std::uint32_t end, int depth);
    std::uint32_t median_split(std::uint32_t begin, std::uint32_t end, int axis);
    template <bool kAnyHit>
    std::optional<Intersection> traverse(const Ray& ray, Interval range) const;

    std::vector<Primitive> primitives_;
    std::vector<Node> nodes_;
    std::vector<const Object*> unbounded_;
};

}  // namespace drt
