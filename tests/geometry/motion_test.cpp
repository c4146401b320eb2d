// The one motion path: positions at and between the path points, and the segments the BVH and
// the shadow-ray culling evaluate instead, which must give the path's very bits at every time
// their span covers (a BVH piece placed a rounding away from the object would miss or add hits).
#include "drt/geometry/motion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace drt {
namespace {

const std::vector<Vec3> kPath{{0, 0, 0}, {10, 0, 0}, {10, 20, -4}, {-3, 0.5, 7}};

TEST(MotionPath, IsAtItsPointsAtIntegerTimesAndLinearBetween) {
    const MotionPath path(kPath);
    EXPECT_EQ(path.end(), 3.0);
    EXPECT_TRUE(path.moves());
    for (std::size_t k = 0; k < kPath.size(); ++k) EXPECT_EQ(path.at(k), kPath[k]) << k;
    EXPECT_EQ(path.at(0.25), (Vec3{2.5, 0, 0}));
    EXPECT_EQ(path.at(1.75), (Vec3{10, 15, -3}));
    // Resting at the ends outside the path's time.
    EXPECT_EQ(path.at(-1e9), kPath.front());
    EXPECT_EQ(path.at(3.5), kPath.back());
    const MotionPath still({{1, 2, 3}});
    EXPECT_FALSE(still.moves());
    EXPECT_EQ(still.end(), 0.0);
    EXPECT_EQ(still.at(0.7), (Vec3{1, 2, 3}));
}

TEST(MotionPath, SegmentsCoverAllTimeAndAgreeWithThePathToTheBit) {
    const MotionPath path(kPath);
    ASSERT_EQ(path.segment_count(), 3u);
    EXPECT_EQ(path.segment_time(0).min, -kInfinity);
    EXPECT_EQ(path.segment_time(0).max, 1.0);
    EXPECT_EQ(path.segment_time(1).min, 1.0);
    EXPECT_EQ(path.segment_time(1).max, 2.0);
    EXPECT_EQ(path.segment_time(2).min, 2.0);
    EXPECT_EQ(path.segment_time(2).max, kInfinity);
    std::vector<double> times{-1e300, -1, -0.0, 0.0, 3, 4, 1e300};
    // Both sides of every segment end, where a formula of the time within the segment rounds.
    for (const double end : {0.0, 1.0, 2.0, 3.0}) {
        times.push_back(std::nextafter(end, -kInfinity));
        times.push_back(end);
        times.push_back(std::nextafter(end, kInfinity));
    }
    for (int i = 0; i <= 300; ++i) times.push_back(i / 100.0 + 1e-3 * std::sin(i));
    for (const double time : times) {
        int covering = 0;
        for (std::size_t k = 0; k < path.segment_count(); ++k) {
            if (!path.segment_time(k).contains(time)) continue;
            ++covering;
            EXPECT_EQ(path.segment(k).at(time), path.at(time)) << "time " << time << " seg " << k;
        }
        EXPECT_GE(covering, 1) << "no segment covers time " << time;
    }
}

TEST(PathSegment, IsExactAtItsEndsAndRestsBeyondThem) {
    const PathSegment s{{0.1, 0.2, 0.3}, {0.7, -0.9, 1e-17}, 5};
    EXPECT_EQ(s.at(5), s.from);
    EXPECT_EQ(s.at(6), s.to);  // not 0.1 + (0.7 - 0.1) · 1, which rounds
    EXPECT_EQ(s.at(4), s.from);
    EXPECT_EQ(s.at(7), s.to);
    const Vec3 half = s.at(5.5);
    EXPECT_NEAR(half.x, 0.4, 1e-16);
    EXPECT_NEAR(half.y, -0.35, 1e-16);
    EXPECT_NEAR(half.z, 0.15, 1e-16);
}

}  // namespace
}  // namespace drt
