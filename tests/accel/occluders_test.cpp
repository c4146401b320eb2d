// Shadow-ray culling against brute force: the occluders gathered for a shading point and a
// light must never change a shadow ray's answer, must keep an occluder that reaches into the
// cone of segments to the light by 1 % of its radius (or just touches it), and must drop one
// that stays 1 % of its radius outside.
#include "drt/accel/occluders.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "drt/render/integrator.h"
#include "test_world.h"

namespace drt {
namespace {

using testing::direction;
using testing::point_in;
using testing::unit;
using testing::World;

// Shadow rays from points on and off the surfaces to points of a light: the gathered occluders
// must give exactly the answer of the whole scene, from a floor point, a sphere's surface, a
// point in free space, and with more spheres in the way than the list holds.
TEST(Occluders, NeverChangeAShadowRaysAnswer) {
    for (const int count : {2, 12, 200}) {
        const World world(count, 40 + count);
        const Bvh bvh(world.objects);
        int gathered = 0, blocked = 0, rays = 0;
        for (std::uint64_t p = 0; p < 300; ++p) {
            const double time = 2.5 * unit(41, p);
            const Ball light{point_in(42, p, 10, 90), 2 + 10 * unit(43, p)};
            Vec3 point = point_in(44, p, 5, 95), normal = direction(45, p);
            if (p % 3 == 0) point.y = 0, normal = {0, 1, 0};  // on the floor
            if (p % 3 == 1) {
                // On a sphere (at the ray's time), as a hit point would be.
                const auto* sphere =
                    dynamic_cast<const Sphere*>(world.objects[3 + p % count].get());
                normal = direction(46, p);
                point = sphere->path().at(time) + normal * sphere->radius();
            }
            const Ray leaving = spawn_ray(point, normal, normal, time);
            const Occluders occluders(bvh, leaving.origin, light, time);
            gathered += occluders.reach() != Occluders::Reach::kTraverse;
            for (std::uint64_t j = 0; j < 40; ++j) {
                const Vec3 target = light.centre + direction(47, p * 40 + j) *
                                                       (light.radius * unit(48, p * 40 + j));
                const Vec3 d = target - leaving.origin;
                const Ray ray{leaving.origin, d / length(d), time};
                if (dot(ray.dir, normal) <= 0) continue;  // shadow rays leave above the surface
                const Interval range{0, length(d)};
                const bool expected = bvh.occluded(ray, range);
                ASSERT_EQ(occluders.occluded(bvh, ray, range), expected)
                    << count << " point " << p << " ray " << j;
                blocked += expected, ++rays;
            }
        }
        // Both answers occur (few with two spheres in a large room), and the lists are used.
        EXPECT_GT(blocked, count < 10 ? 5 : rays / 50) << count;
        EXPECT_LT(blocked, rays - rays / 50) << count;
        if (count <= 12) {
            EXPECT_GT(gathered, 150) << count;
        }
    }
}

TEST(Occluders, FromInsideTheLightEverythingIsKept) {
    const World world(5, 3);
    const Bvh bvh(world.objects);
    const Occluders inside(bvh, {50, 50, 50}, {{50, 52, 50}, 5}, 0);
    EXPECT_EQ(inside.reach(), Occluders::Reach::kTraverse);
    EXPECT_FALSE(inside.every_ray_reaches());
    EXPECT_EQ(inside.planes(), ~std::uint64_t{0});
    // Far from every plane and sphere, towards a light in open space, nothing needs testing.
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, material));
    objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{100, 10, 0}}, 5.0, material));
    const Bvh room(objects);
    const Occluders none(room, {0, 10, 0}, {{0, 50, 0}, 5}, 0);
    EXPECT_EQ(none.reach(), Occluders::Reach::kNothing);
    EXPECT_EQ(none.planes(), 0u);
    EXPECT_EQ(none.count(), 0);
    EXPECT_TRUE(none.every_ray_reaches());
    // Towards a light beyond the plane, the plane may block.
    const Occluders plane(room, {0, 10, 0}, {{0, -50, 0}, 5}, 0);
    EXPECT_EQ(plane.reach(), Occluders::Reach::kListed);
    EXPECT_FALSE(plane.every_ray_reaches());
    EXPECT_EQ(plane.planes(), 1u);
    EXPECT_EQ(plane.count(), 0);
}

// From the origin to a light of radius 10 centred 100 up the y axis, the segments fill a cone
// of half-angle a, sin a = 0.1, whose side in the x-y plane is the line along (sin a, cos a).
// An occluder of radius 5 centred 50 up, at distance `gap` from that line on its outer side.
struct TangentCase {
    static constexpr double kRadius = 5, kHeight = 50;
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    Ball light{{0, 100, 0}, 10};
    Vec3 side{0.1, std::sqrt(0.99), 0};  // unit, along the cone's side

    explicit TangentCase(double gap) {
        const double x = (gap + kHeight * side.x) / side.y;
        objects.push_back(
            std::make_unique<Sphere>(std::vector<Vec3>{{x, kHeight, 0}}, kRadius, material));
    }
};

TEST(Occluders, KeepAnOccluderReachingIntoTheConeAndDropOneJustOutside) {
    // 1 % of the radius inside the cone: kept, and the ray along the cone's side to the point
    // where it touches the light is blocked by it.
    {
        const TangentCase c(0.99 * TangentCase::kRadius);
        const Bvh bvh(c.objects);
        const Occluders occluders(bvh, {0, 0, 0}, c.light, 0);
        EXPECT_EQ(occluders.reach(), Occluders::Reach::kListed);
        EXPECT_EQ(occluders.count(), 1);
        const Ray along{{0, 0, 0}, c.side, 0};
        const Interval to_light{0, std::sqrt(100.0 * 100.0 - 10.0 * 10.0)};
        EXPECT_TRUE(bvh.occluded(along, to_light));
        EXPECT_TRUE(occluders.occluded(bvh, along, to_light));
    }
    // Exactly tangent to the cone: a segment grazes it, so it is kept.
    {
        const TangentCase c(TangentCase::kRadius);
        const Bvh bvh(c.objects);
        const Occluders occluders(bvh, {0, 0, 0}, c.light, 0);
        EXPECT_EQ(occluders.reach(), Occluders::Reach::kListed);
        EXPECT_EQ(occluders.count(), 1);
    }
    // 1 % of the radius outside: nothing can block, and only cosines are needed.
    {
        const TangentCase c(1.01 * TangentCase::kRadius);
        const Bvh bvh(c.objects);
        const Occluders occluders(bvh, {0, 0, 0}, c.light, 0);
        EXPECT_EQ(occluders.reach(), Occluders::Reach::kNothing);
        EXPECT_TRUE(occluders.every_ray_reaches());
    }
}

// More candidates than the list holds: the rays traverse the tree, still skipping the planes
// that cannot block.
TEST(Occluders, TooManyCandidatesFallBackToTraversal) {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, material));
    for (int i = 0; i <= Occluders::kMaxListed; ++i) {
        objects.push_back(
            std::make_unique<Sphere>(std::vector<Vec3>{{0, 20.0 + 2 * i, 0}}, 0.5, material));
    }
    const Bvh bvh(objects);
    const Occluders full(bvh, {0, 10, 0}, {{0, 80, 0}, 5}, 0);
    EXPECT_EQ(full.reach(), Occluders::Reach::kTraverse);
    EXPECT_EQ(full.planes(), 0u);
    EXPECT_TRUE(full.occluded(bvh, {{0, 10, 0}, {0, 1, 0}, 0}, {0, 65}));
}

TEST(Occluders, ALoneRayIsTracedWithoutCulling) {
    const World world(5, 3);
    const Bvh bvh(world.objects);
    EXPECT_FALSE(worth_culling(1, bvh));
    EXPECT_TRUE(worth_culling(2, bvh));
    EXPECT_TRUE(worth_culling(3, bvh));
}

// A shadow ray leaving a mesh triangle skips it however the occluders send it on: through the
// list of primitives near the cone or through the whole tree.
TEST(Occluders, PassTheTriangleARayLeavesOnToTheTree) {
    const testing::StackedTriangles stacked;
    const auto& [material, objects, bvh, up] = stacked;
    const auto first = bvh.intersect(up, {0, kInfinity});
    ASSERT_TRUE(first && first->object == objects[0].get());
    const Leaving skip_first = Bvh::leaving(*first);
    const Occluders listed(bvh, up.origin, Ball{{1, 1, 6}, 0.5}, 0);
    ASSERT_EQ(listed.reach(), Occluders::Reach::kListed);
    ASSERT_EQ(listed.count(), 2);
    for (const Occluders& occluders : {listed, Occluders{}}) {
        EXPECT_TRUE(occluders.occluded(bvh, up, {0, 3.5}));
        EXPECT_FALSE(occluders.occluded(bvh, up, {0, 3.5}, skip_first));
        EXPECT_TRUE(occluders.occluded(bvh, up, {0, 4.5}, skip_first));
    }
}

// Shadow rays to points on the side of an emitting sphere seen from the shading point, stopped
// short of it as next-event estimation stops them: with the sphere named as the target it is
// not gathered as an occluder of its own light, and the answers stay the tree's; a sphere alone
// in a room then needs no ray at all.
TEST(Occluders, ATargetSphereIsNotItsOwnOccluder) {
    const World world(12, 70);
    const Bvh bvh(world.objects);
    int rays = 0, blocked = 0, fewer = 0;
    for (std::uint64_t p = 0; p < 300; ++p) {
        const auto* sphere = dynamic_cast<const Sphere*>(world.objects[3 + p % 12].get());
        const double time = 2.5 * unit(71, p);
        const Ball target{sphere->path().at(time), sphere->radius()};
        const Vec3 origin = point_in(72, p, 5, 95);
        const Vec3 to_centre = target.centre - origin;
        const double d = length(to_centre);
        if (d <= target.radius * 1.01) continue;
        const Occluders all(bvh, origin, target, time);
        const Occluders others(bvh, origin, target, time, sphere);
        fewer += others.count() < all.count() || others.reach() != all.reach();
        for (std::uint64_t j = 0; j < 20; ++j) {
            // A point of the visible cap: a direction within the sphere's cone, to its near hit.
            const double cos_max = std::sqrt(1 - target.radius * target.radius / (d * d));
            const double cos_t = 1 - unit(73, p * 20 + j) * (1 - cos_max);
            const Vec3 local = direction(74, p * 20 + j);
            const Frame frame = Frame::around(to_centre / d);
            const Vec3 side = normalize(frame.to_world({local.x, local.y, 0}));
            const Vec3 dir =
                normalize(frame.n * cos_t + side * std::sqrt(std::max(0.0, 1 - cos_t * cos_t)));
            const auto hit = sphere->intersect({origin, dir, time}, {0, kInfinity});
            if (!hit) continue;
            const Ray ray{origin, dir, time};
            const Interval range{0, hit->t * (1 - 1e-5)};
            const bool expected = bvh.occluded(ray, range);
            ASSERT_EQ(others.occluded(bvh, ray, range), expected) << p << " " << j;
            blocked += expected, ++rays;
        }
    }
    EXPECT_GT(rays, 3000);
    EXPECT_GT(blocked, rays / 50);
    EXPECT_GT(fewer, 200);

    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, material));
    objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{0, 50, 0}}, 5.0, material));
    const Bvh room(objects);
    const Ball lamp{{0, 50, 0}, 5};
    EXPECT_EQ(Occluders(room, {20, 1, 0}, lamp, 0).reach(), Occluders::Reach::kListed);
    EXPECT_EQ(Occluders(room, {20, 1, 0}, lamp, 0, objects[1].get()).reach(),
              Occluders::Reach::kNothing);
}

}  // namespace
}  // namespace drt
