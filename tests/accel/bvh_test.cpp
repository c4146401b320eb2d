// The BVH against brute force: nearest hits and any-hit answers must be exactly those of
// testing every object. Also the fast kernels those rays use: quarter-turn sines and batched
// light samples.
#include "drt/accel/bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "drt/accel/mesh.h"
#include "drt/accel/triangle_mesh.h"
#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "drt/render/integrator.h"
#include "drt/sampling/multi_jittered.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/light.h"
#include "drt/util/rng.h"
#include "test_math.h"
#include "test_meshes.h"
#include "test_world.h"

namespace drt {
namespace {

using testing::direction;
using testing::point_in;
using testing::unit;
using testing::World;

TEST(Bvh, NearestHitIsThatOfTestingEveryObject) {
    for (const int count : {1, 3, 40, 600}) {
        const World world(count, 11);
        const Bvh bvh(world.objects);
        int hits = 0;
        for (std::uint64_t i = 0; i < 3000; ++i) {
            const Ray ray{point_in(20, i, -20, 120), direction(21, i), 2.5 * unit(22, i)};
            const auto expected = world.brute_nearest(ray, {0, kInfinity});
            const auto got = bvh.intersect(ray, {0, kInfinity});
            ASSERT_EQ(got.has_value(), expected.has_value()) << count << " ray " << i;
            if (!got) continue;
            ++hits;
            EXPECT_EQ(got->t, expected->t) << count << " ray " << i;
            EXPECT_EQ(got->object, expected->object) << count << " ray " << i;
            EXPECT_EQ(got->primitive, expected->primitive) << count << " ray " << i;
        }
        EXPECT_GT(hits, 1000) << count;
    }
}

TEST(Bvh, AnyHitIsThatOfTestingEveryObject) {
    for (const int count : {1, 40, 600}) {
        const World world(count, 12);
        const Bvh bvh(world.objects);
        int blocked = 0;
        for (std::uint64_t i = 0; i < 3000; ++i) {
            const Ray ray{point_in(30, i, 1, 99), direction(31, i), 2.5 * unit(32, i)};
            const Interval range{0, 60 * unit(33, i)};
            const bool expected = world.brute_occluded(ray, range);
            ASSERT_EQ(bvh.occluded(ray, range), expected) << count << " ray " << i;
            blocked += expected;
        }
        EXPECT_GT(blocked, 300) << count;
        EXPECT_LT(blocked, 2900) << count;
    }
}

TEST(Bvh, AxisParallelRaysAndRaysAlongSlabPlanesFindTheirHits) {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    for (int i = 0; i < 8; ++i) {
        objects.push_back(
            std::make_unique<Sphere>(std::vector<Vec3>{{10.0 * i, 0, 0}}, 1.0, material));
    }
    const Bvh bvh(objects);
    // Along +x and -x (directions with zero and negative-zero components), from the middle of
    // the row, and along the top of the spheres' boxes.
    for (const Vec3 dir : {Vec3{1, 0, 0}, Vec3{-1, 0, 0}, Vec3{1, -0.0, -0.0}, Vec3{-1, -0.0, 0}}) {
        const auto hit = bvh.intersect({{35, 0, 0}, dir, 0}, {0, kInfinity});
        ASSERT_TRUE(hit);
        EXPECT_DOUBLE_EQ(hit->t, 4.0);
    }
    EXPECT_FALSE(bvh.intersect({{-5, 1.5, 0}, {1, 0, 0}, 0}, {0, kInfinity}));
    const auto top = bvh.intersect({{20, 5, 0}, {0, -1, 0}, 0}, {0, kInfinity});
    ASSERT_TRUE(top);
    EXPECT_DOUBLE_EQ(top->t, 4.0);
}

TEST(Bvh, MovingSphereIsHitOnlyWhereItIsAtTheRaysTime) {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    // Present at x = 0, one time unit ago at x = 10, two ago at x = 20.
    objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{0, 0, 0}, {10, 0, 0}, {20, 0, 0}},
                                               1.0, material));
    const Bvh bvh(objects);
    for (const double time : {0.0, 0.5, 1.0, 1.25, 2.0, 3.0}) {
        const double x = 10 * std::min(time, 2.0);
        const auto hit = bvh.intersect({{x, 0, -10}, {0, 0, 1}, time}, {0, kInfinity});
        ASSERT_TRUE(hit) << time;
        EXPECT_NEAR(hit->t, 9.0, 1e-12) << time;
        EXPECT_FALSE(bvh.occluded({{x + 3, 0, -10}, {0, 0, 1}, time}, {0, kInfinity})) << time;
    }
}

// At the ends of a path's segments, where two BVH pieces meet and the time within a segment
// rounds, the BVH places a moving sphere exactly where the sphere itself says it is: the same
// hit to the bit, for rays grazing its edge as well as through its middle.
TEST(Bvh, MovingSphereAtSegmentEndsIsWhereTheSphereSaysToTheBit) {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    objects.push_back(std::make_unique<Sphere>(
        std::vector<Vec3>{{0.1, 0.2, 0.3}, {10.7, -0.9, 1e-3}, {20.3, 3.1, -2.9}}, 1.3, material));
    const auto& sphere = *objects[0];
    const Bvh bvh(objects);
    int hits = 0;
    for (const double end : {0.0, 1.0, 2.0}) {
        for (const double time :
             {std::nextafter(end, -kInfinity), end, std::nextafter(end, kInfinity)}) {
            const Vec3 c = dynamic_cast<const Sphere&>(sphere).path().at(time);
            for (const double off : {0.0, 0.7, 1.2999999}) {
                const Ray ray{c + Vec3{off, 0, -10}, {0, 0, 1}, time};
                const auto expected = sphere.intersect(ray, {0, kInfinity});
                const auto got = bvh.intersect(ray, {0, kInfinity});
                ASSERT_TRUE(expected) << time << " " << off;
                ASSERT_TRUE(got) << time << " " << off;
                EXPECT_EQ(got->t, expected->t) << time << " " << off;
                ++hits;
            }
        }
    }
    EXPECT_EQ(hits, 27);
}

// The hit record names the object and its shape, and the surface worked out from it lies where
// the ray met it: on the sphere (at the ray's time) or the plane, at ray.at(t).
TEST(Bvh, SurfaceOfAHitRecordIsWhereTheRayMetTheShape) {
    const World world(40, 13);
    const Bvh bvh(world.objects);
    int spheres = 0, planes = 0;
    for (std::uint64_t i = 0; i < 2000; ++i) {
        const Ray ray{point_in(23, i, 1, 99), direction(24, i), 2.5 * unit(25, i)};
        const auto hit = bvh.intersect(ray, {0, kInfinity});
        if (!hit) continue;
        ASSERT_NE(hit->object, nullptr);
        EXPECT_EQ(hit->primitive, 0u);  // each object here is one shape
        const SurfaceHit surface = hit->object->surface_at(ray, *hit);
        EXPECT_LT(length(surface.point - ray.at(hit->t)), 1e-12 * (100 + hit->t)) << i;
        EXPECT_NEAR(length(surface.normal), 1.0, 1e-15) << i;
        if (const auto* sphere = dynamic_cast<const Sphere*>(hit->object)) {
            const Vec3 c = sphere->path().at(ray.time);
            EXPECT_NEAR(length(surface.point - c), sphere->radius(), 1e-13 * 100) << i;
            EXPECT_LT(length(surface.normal - (surface.point - c) / sphere->radius()), 1e-13);
            ++spheres;
        } else {
            const auto& plane = dynamic_cast<const Plane&>(*hit->object);
            EXPECT_NEAR(dot(surface.point - plane.point(), plane.normal()), 0, 1e-13) << i;
            EXPECT_EQ(surface.normal, plane.normal());
            ++planes;
        }
    }
    EXPECT_GT(spheres, 100);
    EXPECT_GT(planes, 100);
}

// Rays spawned from mesh hits, as the integrators spawn them, skip the triangle they leave
// (Leaving) and find exactly what they find without skipping it: the skip saves a test and
// changes no answer. Inside a closed sphere of triangles, every spawned ray meets another.
TEST(Bvh, RaysLeavingAMeshTriangleFindWhatTheyFindWithoutSkippingIt) {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    const auto sphere = std::make_shared<const TriangleMesh>(
        testing::obj_of(testing::icosphere(3, 50, {3, -2, 7})), MeshTransform{}, false);
    objects.push_back(std::make_unique<Mesh>(sphere, std::vector<Vec3>{Vec3{}}, material));
    objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{13, -2, 7}}, 8.0, material));
    const Bvh bvh(objects);
    int nearest = 0, blocked = 0;
    for (std::uint64_t i = 0; i < 3000; ++i) {
        const Ray ray{Vec3{3, -2, 7} + testing::unit_vector(40, i) * 20, direction(41, i)};
        const auto hit = bvh.intersect(ray, {0, kInfinity});
        ASSERT_TRUE(hit) << i;
        if (hit->object != objects[0].get()) continue;
        ASSERT_NE(hit->piece, Hit::kNoPiece);
        const SurfaceHit surface = hit->object->surface_at(ray, *hit);
        const Ray next = spawn_ray(surface.point, surface.normal, direction(42, i), 0);
        const auto expected = bvh.intersect(next, {0, kInfinity});
        const auto got = bvh.intersect(next, {0, kInfinity}, Bvh::leaving(*hit));
        ASSERT_EQ(got.has_value(), expected.has_value()) << i;
        if (!got) continue;
        ++nearest;
        EXPECT_EQ(got->t, expected->t) << i;
        EXPECT_EQ(got->object, expected->object) << i;
        EXPECT_EQ(got->primitive, expected->primitive) << i;
        if (got->object == hit->object) {
            EXPECT_NE(got->primitive, hit->primitive) << i;
        }
        const Interval range{0, 2 * expected->t * unit(43, i)};
        const bool occluded = bvh.occluded(next, range);
        EXPECT_EQ(bvh.occluded(next, range, Bvh::leaving(*hit)), occluded) << i;
        blocked += occluded;
    }
    EXPECT_GT(nearest, 1000);
    EXPECT_GT(blocked, 300);
    EXPECT_LT(blocked, nearest - 300);
}

// The skip names a triangle of one placed piece: the same mesh placed again, one unit above,
// is met by the ray leaving the first placement's copy of the same triangle.
TEST(Bvh, ALeavingRaySkipsItsOwnPlacementOfASharedMeshAlone) {
    const testing::StackedTriangles stacked;
    const auto& [material, objects, bvh, up] = stacked;
    const auto first = bvh.intersect(up, {0, kInfinity});
    ASSERT_TRUE(first);
    EXPECT_EQ(first->object, objects[0].get());
    const Ray on = spawn_ray(up.at(first->t), {0, 0, 1}, {0, 0, 1}, 0);
    const auto second = bvh.intersect(on, {0, kInfinity}, Bvh::leaving(*first));
    ASSERT_TRUE(second);
    EXPECT_EQ(second->object, objects[1].get());
    EXPECT_EQ(second->primitive, first->primitive);
    EXPECT_NEAR(second->t, 1.0, 1e-8);
    EXPECT_TRUE(bvh.occluded(on, {0, 2}, Bvh::leaving(*first)));
    // Told to skip it, even a ray that does meet the first triangle passes it untested.
    const auto past = bvh.intersect(up, {0, kInfinity}, Bvh::leaving(*first));
    ASSERT_TRUE(past);
    EXPECT_EQ(past->object, objects[1].get());
    EXPECT_FALSE(bvh.occluded(up, {0, 3.5}, Bvh::leaving(*first)));
    EXPECT_TRUE(bvh.occluded(up, {0, 3.5}));
}

TEST(FastKernels, SinCosOfTurnsIsWithinTwoUlpsAndExactAtQuarters) {
    double worst = 0;
    for (int i = 0; i <= 100000; ++i) {
        const double turns = i / 100000.0;
        const SinCos r = sincos_turns(turns);
        const long double angle = 2 * 3.141592653589793238462643383279502884L * turns;
        worst = std::max({worst, std::abs(double(r.sin - std::sin(angle))),
                          std::abs(double(r.cos - std::cos(angle)))});
    }
    EXPECT_LT(worst, 4.5e-16);
    EXPECT_EQ(sincos_turns(0).sin, 0.0);
    EXPECT_EQ(sincos_turns(0).cos, 1.0);
    EXPECT_EQ(sincos_turns(0.25).sin, 1.0);
    EXPECT_EQ(sincos_turns(0.5).cos, -1.0);
    EXPECT_EQ(sincos_turns(0.75).sin, -1.0);
    EXPECT_EQ(sincos_turns(1).cos, 1.0);
}

TEST(FastKernels, BatchedLightSamplesEqualSingleOnesAndReachTheSphere) {
    const SphereLight light({3, 40, -7}, 6, {1, 1, 1}, false);
    for (const Vec3 x : {Vec3{0, 0, 0}, Vec3{3, 30, -7}, Vec3{1e4, -2e3, 5e3}, Vec3{4, 41, -6}}) {
        std::vector<Vec2> u;
        for (std::uint64_t i = 0; i < 64; ++i) u.push_back({unit(50, i), unit(51, i)});
        std::vector<LightSample> batch(u.size());
        light.sample(x, u, batch);
        const bool inside = length(x - light.centre()) < light.radius();
        for (std::size_t i = 0; i < u.size(); ++i) {
            const LightSample one = light.sample(x, u[i]);
            EXPECT_EQ(one.dir, batch[i].dir);
            EXPECT_EQ(one.distance, batch[i].distance);
            EXPECT_NEAR(length(one.dir), 1.0, 1e-14);
            const Vec3 on = x + one.dir * one.distance;
            const double scale = 1e-9 * (length(x) + 50);
            EXPECT_NEAR(length(on - light.centre()), light.radius(), scale) << i;
            if (!inside) {
                // From outside, the near side: nothing of the sphere is closer along the ray.
                const auto t =
                    intersect_sphere(light.centre(), light.radius(), {x, one.dir, 0}, {});
                if (t) {
                    EXPECT_NEAR(*t, one.distance, scale) << i;
                }
            }
        }
    }
}

// Each point of a stratified set, over many keys, is uniform on the square, whatever its index.
TEST(FastKernels, EveryPointOfAMultiJitteredSetIsUniform) {
    for (const std::uint32_t k : {2u, 5u, 9u, 10u}) {
        for (const std::uint32_t j : {0u, k - 1}) {
            const int bins = 4, n = 64000;
            std::vector<int> histogram(bins * bins, 0);
            for (std::uint32_t key = 0; key < n; ++key) {
                Vec2 p;
                multi_jittered_set(j, k, static_cast<std::uint32_t>(mix64(key)), {&p, 1});
                ASSERT_TRUE(p.x >= 0 && p.x < 1 && p.y >= 0 && p.y < 1);
                ++histogram[static_cast<int>(p.x * bins) * bins + static_cast<int>(p.y * bins)];
            }
            for (const int h : histogram) {
                // 4000 expected, standard deviation 61.
                EXPECT_NEAR(h, n / (bins * bins), 300) << "k " << k << " j " << j;
            }
        }
    }
}

}  // namespace
}  // namespace drt
