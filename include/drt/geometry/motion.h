// Where a moving thing is at a shutter time: the one motion path that objects, the BVH and the
// shadow-ray culling all evaluate, so a centre is computed by the same arithmetic everywhere
// (a hit point and the box that was meant to contain it cannot disagree by a rounding).
#pragma once

#include <cstddef>
#include <vector>

#include "drt/util/math.h"

namespace drt {

// One straight piece of a path: at `from` at time `start`, at `to` one time unit later, linear
// in between, and resting at its ends outside that unit.
struct PathSegment {
    Vec3 from, to;
    double start = 0;

    // The ends exactly (no rounding of from + (to - from) · 1), the interpolation in between.
    constexpr Vec3 at(double time) const {
        const double f = time - start;
        return f <= 0 ? from : (f >= 1 ? to : from + (to - from) * f);
    }
};

// A polyline in time: point k is the position at time k (time 0 is the present, the thesis's
// MotionBlurPosition k is k time units in the past), linear in between, resting at the first
// point before time 0 and at the last after the end. A single point stands still.
class MotionPath {
  public:
    explicit MotionPath(std::vector<Vec3> points);

    // Inline for the common still path: every hit on a sphere asks where its centre is.
    Vec3 at(double time) const {
        if (points_.size() == 1 || time <= 0) return points_.front();
        return moving_at(time);
    }
    // Time at which the path ends; 0 for a path that stays put.
    double end() const { return static_cast<double>(points_.size() - 1); }
    bool moves() const { return points_.size() > 1; }
    // Whether it goes anywhere: a path of several points may repeat one place throughout.
    bool travels() const;

    std::size_t segment_count() const { return points_.size() - 1; }
    PathSegment segment(std::size_t k) const {
        return {points_[k], points_[k + 1], static_cast<double>(k)};
    }
    // Shutter times over which segment k says where the path is: [k, k + 1], the first one
    // stretched back to -∞ and the last one on to +∞, where the path rests at its ends.
    Interval segment_time(std::size_t k) const;

    const std::vector<Vec3>& points() const { return points_; }

  private:
    Vec3 moving_at(double time) const;

    std::vector<Vec3> points_;
};

}  // namespace drt
