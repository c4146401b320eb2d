#include "drt/accel/occluders.h"

#include <cmath>

namespace drt {

namespace {

// Slack, relative to the scene's coordinates and to cosines, by which the culling errs on the
// side of keeping: far above rounding (1e-16), far below anything a scene could notice.
constexpr double kSlack = 1e-9;
// How far from a plane, relative to the coordinates, the origin must be to count as on one side
// of it: far above rounding, and far below the offset a spawned ray starts at
// (spawn_ray: |p| · 2⁻³² ≈ 2.3e-10 |p|), so an origin spawned off a plane is on its side.
constexpr double kOffPlane = 1e-12;
// Fewer shadow rays than this to a light from a point are traced through the tree as they are:
// for a single ray, gathering the occluders costs about what it saves; the saving grows with
// every ray that shares them.
constexpr int kMinRaysToCull = 2;

// The cone of segments from an apex to the points of a ball, and whether a ball may meet one.
struct SegmentCone {
    Vec3 apex, axis;
    double sin_a, cos_a;  // of its half-angle
    double reach;         // no segment is longer
    double slack;         // absolute, for distances

    // Whether some segment may pass through the ball (centre, radius): conservative.
    bool may_meet(const Ball& ball) const {
        const Vec3 v = ball.centre - apex;
        const double d2 = dot(v, v);
        if (d2 <= ball.radius * ball.radius) return true;  // the apex is in it
        const double r = ball.radius + slack;
        const double along = dot(v, axis);
        if (along - r > reach) return false;  // wholly beyond the farthest segment's end
        // Within the sum of the half-angles a of the cone and b of the ball about the axis:
        // angle(v, axis) <= a + b, that is along >= |v| cos(a + b) = cos a |v| cos b - sin a r,
        // where |v| cos b = sqrt(|v|² - r²) (0 when the apex is within the slack of the ball,
        // which then looks like a half-space: missed when the whole light is above its plane).
        const double tangent = std::sqrt(positive_part(d2 - r * r));
        return along >= cos_a * tangent - sin_a * r - kSlack * (tangent + r);
    }
};

}  // namespace

Occluders::Occluders(const Bvh& bvh, const Vec3& origin, const Ball& target, double time,
                     const Object* target_sphere) {
    const double slack =
        kSlack * (max_abs_component(origin) + max_abs_component(target.centre) + target.radius);
    const Vec3 w = target.centre - origin;
    const double d2 = dot(w, w);
    // The distance and the tangent's length side by side rather than one after the other: the
    // cone's cosine sqrt(1 - sin²) would wait on the sine, which waits on the distance.
    const double reach = std::sqrt(d2);
    const double tangent = std::sqrt(positive_part(d2 - target.radius * target.radius));
    // From inside the ball, or next to it, segments go every way: keep everything.
    if (!(reach > target.radius + slack)) return;
    const double inverse = 1.0 / reach;
    const SegmentCone cone{origin,
                           w * inverse,
                           target.radius * inverse,
                           tangent * inverse,
                           reach + target.radius + slack,
                           slack};

    // A plane can block only if the origin and the ball are not both strictly on one side of it.
    planes_ = 0;
    const double origin_scale = max_abs_component(origin);
    const auto planes = bvh.planes();
    for (std::size_t i = 0; i < planes.size() && i < kPlaneBits; ++i) {
        const Bvh::PlaneData& p = planes[i];
        // The origin is held to kOffPlane; the ball to the coarser slack.
        const double near = kOffPlane * (origin_scale + p.point_scale);
        const double margin = slack + kSlack * p.point_scale;
        const double from = dot(origin, p.normal) - p.offset;
        const double to = dot(target.centre, p.normal) - p.offset;
        // Without branches: which planes separate varies from point to point, unpredictably.
        const bool apart = ((from > near) & (to - target.radius > margin)) |
                           ((from < -near) & (to + target.radius < -margin));
        planes_ |= std::uint64_t{!apart} << i;
    }

    const bool listed = bvh.visit_near(
        time, [&](const Ball& ball) { return cone.may_meet(ball); },
        [&](std::uint32_t primitive) {
            if (target_sphere && bvh.is_sphere_of(primitive, target_sphere)) return true;
            if (count_ == kMaxListed) return false;  // too many: traverse instead
            primitives_[count_++] = primitive;
            return true;
        });
    if (!listed) return;
    const bool every_plane_masked = planes.size() <= kPlaneBits;
    reach_ = every_plane_masked && planes_ == 0 && count_ == 0 ? Reach::kNothing : Reach::kListed;
}

bool Occluders::occluded(const Bvh& bvh, const Ray& ray, Interval range, Leaving leaving) const {
    switch (reach_) {
        case Reach::kNothing:
            return false;
        case Reach::kListed:
            return bvh.occluded_by(ray, range, planes_,
                                   std::span<const std::uint32_t>(primitives_).first(count_),
                                   leaving);
        case Reach::kTraverse:
            break;
    }
    return bvh.occluded(ray, range, planes_, leaving);
}

bool worth_culling(int rays, const Bvh& /*bvh*/) {
    return rays >= kMinRaysToCull;
}

}  // namespace drt
