// Shadow-ray culling: what may block the segments from one shading point to the points of one
// light (a ball) at one time — the planes and primitives that meet the cone those segments
// fill — found once for a point and a light, so that each of the point's shadow rays to that
// light tests only them, or none at all. Culling never changes an answer, only its cost.
#pragma once

#include <array>
#include <cstdint>

#include "drt/accel/bvh.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

class Occluders {
  public:
    // Planes are kept or culled one bit each in a single machine word: scenes have a handful
    // (a room has six), a word is set and walked without branches, and planes past the 64th
    // are simply always tested (correct, only slower).
    static constexpr std::size_t kPlaneBits = 64;
    // Primitives listed at most; more, and the rays traverse the tree instead. Fewer would send
    // scenes of many primitives to the tree too often, more lengthen the list without saving
    // traversals. A fixed array keeps the culling on the stack (no allocation per shading point).
    static constexpr int kMaxListed = 16;

    // What a ray to the light must be tested against.
    enum class Reach : std::uint8_t {
        kNothing,   // nothing may block: every ray reaches the light, none need be traced
        kListed,    // only the planes of the mask and the listed primitives
        kTraverse,  // the planes of the mask and the whole tree
    };

    // Everything may block: always correct.
    Occluders() = default;
    // What may block segments from `origin` to points of `target` at `time`. `target_sphere`:
    // the target is that object's sphere, and the segments end short of the part of it seen
    // from `origin`, so that it cannot block them itself.
    Occluders(const Bvh& bvh, const Vec3& origin, const Ball& target, double time,
              const Object* target_sphere = nullptr);

    Reach reach() const { return reach_; }
    // Whether every ray reaches the light, so that shading needs only the cosines.
    bool every_ray_reaches() const { return reach_ == Reach::kNothing; }
    // Whether something blocks `ray` (from the origin, to a point of the target, at the time
    // the occluders were gathered for) within `range`; the triangle `leaving` is skipped (bvh.h).
    bool occluded(const Bvh& bvh, const Ray& ray, Interval range, Leaving leaving = {}) const;

    std::uint64_t planes() const { return planes_; }
    int count() const { return count_; }

  private:
    Reach reach_ = Reach::kTraverse;
    std::uint64_t planes_ = ~std::uint64_t{0};  // bit i: plane i may block
    int count_ = 0;
    std::array<std::uint32_t, kMaxListed> primitives_{};
};

// Whether a shading point's `rays` shadow rays to one light are worth culling before they are
// traced, rather than each traversing the tree: from two rays on, whatever the scene. The one
// place that decides; it takes `bvh` so that a rule by scene size has somewhere to go.
bool worth_culling(int rays, const Bvh& bvh);

}  // namespace drt
