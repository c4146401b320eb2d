#include "drt/geometry/motion.h"

#include <algorithm>
#include <utility>

namespace drt {

MotionPath::MotionPath(std::vector<Vec3> points) : points_(std::move(points)) {}

Vec3 MotionPath::moving_at(double time) const {
    if (time >= end()) return points_.back();
    return segment(static_cast<std::size_t>(time)).at(time);
}

bool MotionPath::travels() const {
    return std::ranges::any_of(points_, [&](const Vec3& p) { return p != points_[0]; });
}

Interval MotionPath::segment_time(std::size_t k) const {
    const double t0 = k == 0 ? -kInfinity : static_cast<double>(k);
    const double t1 = k + 1 == segment_count() ? kInfinity : static_cast<double>(k + 1);
    return {t0, t1};
}

}  // namespace drt
