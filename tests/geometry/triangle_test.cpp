#include "drt/geometry/triangle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "test_math.h"
#include "test_meshes.h"

namespace drt {
namespace {

using testing::TestMesh;

constexpr Interval kAhead{0, kInfinity};

// A deterministic, uniformly distributed point of a triangle.
Vec3 point_in_triangle(std::uint64_t seed, std::uint64_t i, const Vec3& p0, const Vec3& p1,
                       const Vec3& p2) {
    const double u = to_unit(hash_of(seed, i, 0)), w = to_unit(hash_of(seed, i, 1));
    const double b1 = std::min(u, w), b2 = 1 - std::max(u, w);
    return p0 * (1 - b1 - b2) + p1 * b1 + p2 * b2;
}

TEST(Triangle, HitsAtTheRightPointWithItsBarycentrics) {
    const Vec3 p0{0, 0, 0}, p1{1, 0, 0}, p2{0, 1, 0};
    const auto hit = intersect_triangle(Ray{{0.25, 0.5, 2}, {0, 0, -1}}, p0, p1, p2, kAhead);
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 2);
    EXPECT_DOUBLE_EQ(hit->b.b0, 0.25);
    EXPECT_DOUBLE_EQ(hit->b.b1, 0.25);
    EXPECT_DOUBLE_EQ(hit->b.b2, 0.5);
    // Both sides are seen, at any angle.
    const Vec3 d = normalize({1, 2, 3});
    const Vec3 target{0.125, 0.375, 0};
    const auto back = intersect_triangle(Ray{target - d * 3, d}, p0, p1, p2, kAhead);
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->t, 3, 1e-15);
    EXPECT_NEAR(back->b.b1, 0.125, 1e-15);
    EXPECT_NEAR(back->b.b2, 0.375, 1e-15);
}

TEST(Triangle, MissesOutsideItsEdgesAndItsRange) {
    const Vec3 p0{0, 0, 0}, p1{1, 0, 0}, p2{0, 1, 0};
    const Vec3 down{0, 0, -1};
    EXPECT_FALSE(intersect_triangle(Ray{{0.5001, 0.5, 1}, down}, p0, p1, p2, kAhead));
    EXPECT_FALSE(intersect_triangle(Ray{{-1e-9, 0.5, 1}, down}, p0, p1, p2, kAhead));
    EXPECT_FALSE(intersect_triangle(Ray{{0.2, 0.2, 1}, down}, p0, p1, p2, {0, 0.999}));
    EXPECT_FALSE(intersect_triangle(Ray{{0.2, 0.2, -1}, down}, p0, p1, p2, kAhead));
    EXPECT_FALSE(intersect_triangle(Ray{{0.2, 0.2, 1}, {1, 0, 0}}, p0, p1, p2, kAhead));
}

TEST(Triangle, ARayLeavingTheTriangleDoesNotMeetItAgain) {
    // From points of a tilted triangle at any scale, in directions leaving it at any angle.
    for (const double scale : {1e-3, 1.0, 1e3, 1e7}) {
        const Vec3 p0 = Vec3{0.3, -0.2, 0.1} * scale, p1 = Vec3{1.1, 0.4, -0.3} * scale,
                   p2 = Vec3{-0.2, 0.9, 0.5} * scale;
        for (std::uint64_t i = 0; i < 2000; ++i) {
            const Vec3 on = point_in_triangle(7, i, p0, p1, p2);
            const Ray ray{on, testing::unit_vector(8, i)};
            EXPECT_FALSE(intersect_triangle(ray, p0, p1, p2, kAhead))
                << "scale " << scale << ", ray " << i;
        }
    }
}

// One event along a ray through a closed mesh: hits at the same point (on a shared edge or
// vertex every triangle there is hit) form one crossing, entering or leaving by the faces'
// outward normals, or a touch when the ray grazes the surface there.
enum class Crossing { kEnter, kLeave, kTouch };

std::vector<Crossing> crossings(const TestMesh& mesh, const Ray& ray) {
    struct Hit {
        double t;
        bool entering;
    };
    std::vector<Hit> hits;
    const ShearedRay sheared(ray);
    for (const auto& [a, b, c] : mesh.triangles) {
        const Vec3 &p0 = mesh.vertices[a], &p1 = mesh.vertices[b], &p2 = mesh.vertices[c];
        if (const auto hit = intersect_triangle(sheared, p0, p1, p2, kAhead)) {
            EXPECT_TRUE(std::isfinite(hit->t));
            hits.push_back({hit->t, dot(cross(p1 - p0, p2 - p0), ray.dir) < 0});
        }
    }
    std::ranges::sort(hits, {}, &Hit::t);
    std::vector<Crossing> out;
    for (std::size_t i = 0; i < hits.size();) {
        std::size_t j = i;
        bool enter = false, leave = false;
        for (; j < hits.size() && hits[j].t - hits[i].t <= 1e-9 * hits[i].t; ++j)
            (hits[j].entering ? enter : leave) = true;
        out.push_back(enter && leave ? Crossing::kTouch
                                     : (enter ? Crossing::kEnter : Crossing::kLeave));
        i = j;
    }
    return out;
}

// Rays aimed exactly at every vertex and at points exactly on every edge (halfway, a quarter
// and three eighths along: exact in double for float vertices), from several directions
// through the inside (within atan(wobble_length) of the way to the centre, which must stay
// inside the cone of directions into the solid at a vertex). Each direction has small dyadic
// components, and the origin is the target minus four directions, so the ray passes exactly through
// the target with no rounding; it need not be unit length for the test. Each must enter once and
// leave once.
void expect_watertight(const TestMesh& mesh, double wobble_length) {
    for (const auto& [a, b, c] : mesh.triangles) {
        const Vec3 n =
            cross(mesh.vertices[b] - mesh.vertices[a], mesh.vertices[c] - mesh.vertices[a]);
        ASSERT_GT(dot(n, mesh.vertices[a]), 0) << "the test mesh's winding";
    }
    std::vector<Vec3> targets = mesh.vertices;
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (const auto& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
    }
    for (const auto& [i, j] : edges) {
        const Vec3 &p = mesh.vertices[i], &q = mesh.vertices[j];
        for (const double f : {0.5, 0.25, 0.375}) targets.push_back(p * (1 - f) + q * f);
    }
    const auto dyadic = [](double x) { return std::round(x * 16) / 16; };
    int rays = 0;
    for (const Vec3& target : targets) {
        for (std::uint64_t k = 0; k < 6; ++k) {
            const Vec3 wobble = testing::unit_vector(3, rays) * wobble_length;
            const Vec3 d0 = normalize(wobble - normalize(target));
            const Vec3 d{dyadic(d0.x), dyadic(d0.y), dyadic(d0.z)};
            const Ray ray{target - d * 4, d};
            ASSERT_EQ(ray.origin + d * 4, target);  // the ray passes exactly through it
            const auto seen = crossings(mesh, ray);
            EXPECT_EQ(seen, (std::vector{Crossing::kEnter, Crossing::kLeave}))
                << "ray " << rays << " at (" << target.x << ", " << target.y << ", " << target.z
                << ") meets the surface " << seen.size() << " times";
            ++rays;
        }
    }
}

TEST(Triangle, RaysThroughSharedEdgesAndVerticesOfAnOctahedronEnterOnceAndLeaveOnce) {
    TestMesh mesh = testing::octahedron();
    // Stretched and each corner moved a little (by multiples of 1/64, so that they stay exact),
    // so that the edges are not on coordinate planes.
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Vec3 move = testing::unit_vector(4, i) * 8;
        mesh.vertices[i] = mesh.vertices[i] * 1.5 +
                           Vec3{std::round(move.x), std::round(move.y), std::round(move.z)} / 64;
    }
    expect_watertight(mesh, 0.35);
}

TEST(Triangle, RaysThroughSharedEdgesAndVerticesOfAnIcosphereEnterOnceAndLeaveOnce) {
    expect_watertight(testing::icosphere(2), 0.7);
}

TEST(Triangle, DegenerateAndSliverTrianglesNeverGiveNaN) {
    const std::vector<std::array<Vec3, 3>> triangles = {
        {{{0, 0, 0}, {0, 0, 0}, {0, 1, 0}}},            // two corners alike
        {{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}},            // a line
        {{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}},            // a point
        {{{0, 0, 0}, {1, 0, 0}, {0.5, 1e-300, 0}}},     // a sliver thinner than any ray
        {{{0, 0, 0}, {1, 0, 0}, {0.5, 1e-12, 1e-13}}},  // a needle
        {{{0, 0, 0}, {1e-300, 0, 0}, {0, 1e-300, 0}}},  // a speck
        {{{-1e300, -1e300, 0}, {1e300, -1e300, 0}, {0, 1e300, 1e300}}},  // overflows the test
    };
    int hits = 0;
    for (const auto& [p0, p1, p2] : triangles) {
        // Rays from all around at points of the triangle.
        const double size = std::max(max_abs_component(p1 - p0), max_abs_component(p2 - p0));
        for (std::uint64_t i = 0; i < 4000; ++i) {
            const Vec3 toward = point_in_triangle(9, i, p0, p1, p2);
            const Vec3 origin = toward + testing::unit_vector(5, i) * std::max(size, 1.0);
            const Ray ray{origin, normalize(toward - origin)};
            const auto hit = intersect_triangle(ray, p0, p1, p2, kAhead);
            if (!hit) continue;
            ++hits;
            EXPECT_TRUE(std::isfinite(hit->t) && hit->t > 0);
            for (const double b : {hit->b.b0, hit->b.b1, hit->b.b2}) {
                EXPECT_TRUE(b >= 0 && b <= 1) << b;
            }
            EXPECT_NEAR(hit->b.b0 + hit->b.b1 + hit->b.b2, 1, 1e-12);
        }
    }
    EXPECT_GT(hits, 1000);  // the needle is met
}

}  // namespace
}  // namespace drt
