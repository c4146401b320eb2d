#include "drt/geometry/mesh_transform.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_math.h"

namespace drt {
namespace {

using testing::near;

TEST(MeshTransform, ScalesThenRotatesAboutXThenYThenZ) {
    EXPECT_EQ((MeshTransform{2, {90, 0, 0}}.apply({0, 1, 0})), (Vec3{0, 0, 2}));
    EXPECT_EQ((MeshTransform{1, {0, 90, 0}}.apply({0, 0, 1})), (Vec3{1, 0, 0}));
    EXPECT_EQ((MeshTransform{1, {0, 0, 90}}.apply({1, 0, 0})), (Vec3{0, 1, 0}));
    EXPECT_EQ((MeshTransform{1, {0, 0, -270}}.apply({1, 0, 0})), (Vec3{0, 1, 0}));
    // x first: (0, 1, 0) goes to (0, 0, 1), which z leaves; z first would give (-1, 0, 0).
    EXPECT_EQ((MeshTransform{1, {90, 0, 90}}.apply({0, 1, 0})), (Vec3{0, 0, 1}));
    // y before z: (1, 0, 0) goes to (0, 0, -1), which z leaves; z first would give (0, 1, 0).
    EXPECT_EQ((MeshTransform{1, {0, 90, 90}}.apply({1, 0, 0})), (Vec3{0, 0, -1}));
    const Vec3 r = MeshTransform{3, {0, 0, 30}}.apply({1, 0, 0});
    EXPECT_TRUE(near(r, {3 * std::sqrt(3.0) / 2, 1.5, 0}, 1e-15));
}

TEST(Rotation, TurnsAsTheTransformDoesWithoutScaling) {
    const MeshTransform transform{1, {10, 20, 30}};
    const Rotation rotation(transform.rotate_degrees);
    for (const Vec3& v : {Vec3{1, 0, 0}, Vec3{0.3, -2, 5}, Vec3{-1e3, 1e-3, 7}}) {
        EXPECT_EQ(rotation(v), transform.apply(v));
        EXPECT_EQ(rotation(v), transform.rotate(v));
        EXPECT_NEAR(length(rotation(v)), length(v), 1e-12 * length(v));
    }
}

}  // namespace
}  // namespace drt
