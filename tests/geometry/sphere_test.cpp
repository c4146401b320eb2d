#include "drt/geometry/sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "drt/util/rng.h"
#include "test_math.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::kEps;
using testing::near;
using testing::plain_material;
using testing::unit_vector;

// The rounding a coordinate of the magnitude of `p` carries, as an absolute distance.
double coordinate_ulps(const Vec3& p, double radius) {
    return 8.0 * kEps * (max_abs_component(p) + radius);
}

struct SphereCase {
    Vec3 centre;
    double radius;
};

const std::vector<SphereCase>& sphere_cases() {
    static const std::vector<SphereCase> cases = {
        {{0, 0, 0}, 1.0},
        {{3, 4, 5}, 100.0},
        {{1e5, -1e5, 1e5}, 1.0},
        {{1e5, -1e5, 1e5}, 1e-3},
        {{-2.5e-3, 7e-3, 1e-3}, 1e-3},
    };
    return cases;
}

TEST(Sphere, HitDistanceIsAnalytic) {
    const std::vector<Vec3> at{{0, 0, 5}};
    const Sphere sphere(at, 1.0, plain_material());

    const auto head_on = sphere.intersect({{0, 0, 0}, {0, 0, 1}}, {});
    ASSERT_TRUE(head_on);
    EXPECT_DOUBLE_EQ(head_on->t, 4.0);

    // Offset by 0.6 from the axis: the chord's half-length is sqrt(1 - 0.36) = 0.8.
    const auto offset = sphere.intersect({{0.6, 0, 0}, {0, 0, 1}}, {});
    ASSERT_TRUE(offset);
    EXPECT_NEAR(offset->t, 4.2, 1e-14);

    // An oblique ray towards (0, 0.6, 4.2): the near root is that point's distance, 4.2426...
    const Vec3 target{0, 0.6, 4.2};
    const auto oblique = sphere.intersect({{0, 0, 0}, normalize(target)}, {});
    ASSERT_TRUE(oblique);
    EXPECT_NEAR(oblique->t, length(target), 1e-14);
}

TEST(Sphere, RangeSelectsTheRoot) {
    const Sphere sphere({{0, 0, 5}}, 1.0, plain_material());
    const Ray ray{{0, 0, 0}, {0, 0, 1}};
    EXPECT_FALSE(sphere.intersect(ray, {0, 3.9}));
    const auto far = sphere.intersect(ray, {4.5, kInfinity});
    ASSERT_TRUE(far);
    EXPECT_DOUBLE_EQ(far->t, 6.0);
    EXPECT_FALSE(sphere.intersect(ray, {6.5, kInfinity}));
}

TEST(Sphere, MissesRaysPointingAwayOrPassingBeside) {
    const Sphere sphere({{0, 0, 5}}, 1.0, plain_material());
    EXPECT_FALSE(sphere.intersect({{0, 0, 0}, {0, 0, -1}}, {}));
    EXPECT_FALSE(sphere.intersect({{1.5, 0, 0}, {0, 0, 1}}, {}));
    EXPECT_FALSE(sphere.intersect({{0, 0, 10}, {0, 0, 1}}, {}));
}

TEST(Sphere, RayFromInsideHitsTheFarSide) {
    const Vec3 c{1, -2, 3};
    const double r = 2.0;
    for (std::uint64_t i = 0; i < 200; ++i) {
        const Vec3 d = unit_vector(1, i);
        const auto from_centre = intersect_sphere(c, r, {c, d}, {});
        ASSERT_TRUE(from_centre) << i;
        EXPECT_NEAR(*from_centre, r, 1e-14) << i;

        // From an off-centre point inside: the hit lies on the sphere, ahead, on the exit side.
        const Vec3 o = c + unit_vector(2, i) * (0.9 * r);
        const auto t = intersect_sphere(c, r, {o, d}, {});
        ASSERT_TRUE(t) << i;
        EXPECT_GT(*t, 0) << i;
        const Vec3 p = o + d * *t;
        EXPECT_NEAR(length(p - c), r, 1e-13) << i;
        EXPECT_GT(dot(p - c, d), 0) << i;
    }
}

// A secondary ray starts at the refined hit point. Leaving the sphere it must not find the
// sphere again at t ~ 1e-16 (shadow acne, rays trapped in glass); entering it must reach the far
// side at the chord length 2 r cos(theta). The intersection routine promises this for rays that
// start on the sphere, with the plain range (0, inf) and no epsilon.
TEST(Sphere, RayLeavingTheRefinedHitPointDoesNotRehitAndEnteringOneCrosses) {
    int outward_rehits = 0, inward_misses = 0;
    for (std::size_t k = 0; k < sphere_cases().size(); ++k) {
        const auto [c, r] = sphere_cases()[k];
        const Sphere sphere({c}, r, plain_material());
        for (std::uint64_t i = 0; i < 2000; ++i) {
            // A primary ray from outside towards a random point of the sphere.
            const Vec3 start = c + unit_vector(10 + k, i) * (3 * r);
            const Vec3 aim = c + unit_vector(20 + k, i) * (0.5 * r);
            const Ray primary{start, normalize(aim - start)};
            const auto t = sphere.intersect(primary, {});
            ASSERT_TRUE(t) << k << " " << i;
            const SurfaceHit hit = sphere.surface_at(primary, *t);

            Vec3 d = unit_vector(30 + k, i);
            const double cos_n = dot(d, hit.normal);
            if (std::abs(cos_n) < 0.05) continue;  // near-tangent chords are ill-conditioned
            if (cos_n > 0) {
                const auto again = sphere.intersect({hit.point, d}, {0, kInfinity});
                if (again) {
                    ++outward_rehits;
                    ADD_FAILURE() << "case " << k << " ray " << i
                                  << ": outward ray re-hit at t = " << again->t;
                }
            } else {
                const auto far = sphere.intersect({hit.point, d}, {0, kInfinity});
                const double chord = -2.0 * r * cos_n;
                if (!far || std::abs(far->t - chord) > 1e-9 * r + coordinate_ulps(c, r)) {
                    ++inward_misses;
                    ADD_FAILURE() << "case " << k << " ray " << i << ": inward ray gave "
                                  << (far ? far->t : -1.0) << ", chord " << chord;
                }
            }
            if (outward_rehits + inward_misses > 10) return;
        }
    }
}

TEST(Sphere, RayStartingExactlyOnTheSurfaceGoingOutwardMisses) {
    const Vec3 c{0, 0, 0};
    EXPECT_FALSE(intersect_sphere(c, 2.0, {{0, 2, 0}, {0, 1, 0}}, {0, kInfinity}));
    EXPECT_FALSE(intersect_sphere(c, 2.0, {{0, 2, 0}, normalize(Vec3{1, 1, 0})}, {0, kInfinity}));
    // Going inward it crosses the sphere: straight down 2r, at 45 degrees 2r cos 45.
    const auto down = intersect_sphere(c, 2.0, {{0, 2, 0}, {0, -1, 0}}, {0, kInfinity});
    ASSERT_TRUE(down);
    EXPECT_DOUBLE_EQ(*down, 4.0);
    const auto slant = intersect_sphere(c, 2.0, {{0, 2, 0}, normalize(Vec3{1, -1, 0})}, {});
    ASSERT_TRUE(slant);
    EXPECT_NEAR(*slant, 4.0 * std::sqrt(0.5), 1e-14);
}

TEST(Sphere, TangentRayHasAtMostADoubleRootAndNoNaN) {
    const Vec3 c{0, 0, 0};
    const double r = 1.5;
    // Exactly tangent: grazes (0, r, 0) at t = 5.
    const auto graze = intersect_sphere(c, r, {{-5, r, 0}, {1, 0, 0}}, {});
    if (graze) {
        EXPECT_FALSE(std::isnan(*graze));
        EXPECT_NEAR(*graze, 5.0, 1e-6);
    }
    // Starting at the tangent point and moving along the tangent.
    const auto at_point = intersect_sphere(c, r, {{0, r, 0}, {1, 0, 0}}, {});
    if (at_point) {
        EXPECT_FALSE(std::isnan(*at_point));
    }

    // Tangent rays in random orientations, computed with rounding: any hit is a (near) double
    // root at the tangent point.
    for (std::uint64_t i = 0; i < 500; ++i) {
        const Vec3 n = unit_vector(40, i);
        const Vec3 d = normalize(cross(n, unit_vector(41, i)));
        const Vec3 o = c + n * r - d * 3.0;
        const Ray ray{o, d};
        const auto t0 = intersect_sphere(c, r, ray, {});
        if (!t0) continue;
        ASSERT_FALSE(std::isnan(*t0)) << i;
        EXPECT_NEAR(*t0, 3.0, 1e-6) << i;
        const auto t1 = intersect_sphere(c, r, ray, {*t0, kInfinity});
        if (t1) {
            ASSERT_FALSE(std::isnan(*t1)) << i;
            EXPECT_LE(*t1 - *t0, 1e-6) << i;
        }
    }
}

// A reference hit distance in extended precision from the same (double) inputs.
long double reference_hit(const Vec3& c, double r, const Ray& ray) {
    const long double ox = static_cast<long double>(ray.origin.x) - c.x;
    const long double oy = static_cast<long double>(ray.origin.y) - c.y;
    const long double oz = static_cast<long double>(ray.origin.z) - c.z;
    const long double dx = ray.dir.x, dy = ray.dir.y, dz = ray.dir.z;
    const long double dd = dx * dx + dy * dy + dz * dz;
    const long double b = (ox * dx + oy * dy + oz * dz) / dd;
    const long double px = ox - b * dx, py = oy - b * dy, pz = oz - b * dz;
    const long double disc = (static_cast<long double>(r) * r - (px * px + py * py + pz * pz)) / dd;
    return -b - std::sqrt(disc);
}

TEST(Sphere, HitsFarFromTheOriginAreAccurate) {
    for (const double r : {1.0, 1e-3}) {
        const Vec3 c{1e5, 1e5, -1e5};
        const Sphere sphere({c}, r, plain_material());
        const Vec3 eye{0, 0, 0};
        const Vec3 towards_eye = normalize(eye - c);
        int tested = 0;
        for (std::uint64_t i = 0; tested < 500; ++i) {
            // Aim at a point of the visible side, away from the silhouette.
            const Vec3 u = unit_vector(50, i);
            if (dot(u, towards_eye) < 0.2) continue;
            ++tested;
            const Ray ray{eye, normalize(c + u * r - eye)};
            const auto t = sphere.intersect(ray, {});
            ASSERT_TRUE(t) << "r " << r << " ray " << i;
            // The textbook b^2 - c discriminant is off by ~1e-3 absolute here; this one by ~1e-10.
            EXPECT_NEAR(t->t, static_cast<double>(reference_hit(c, r, ray)), 1e-6 * r)
                << "r " << r << " ray " << i;
            EXPECT_NEAR(length(ray.at(t->t) - c), r, 1e-6 * r) << "r " << r << " ray " << i;

            // Re-projected onto the surface the point is as exact as coordinates of magnitude
            // 1e5 can be (their spacing is 1.5e-11): within 1e-9 of r for r = 1, and within a few
            // units in the last place of the coordinates (~1e-8 of r) for r = 1e-3.
            const SurfaceHit hit = sphere.surface_at(ray, *t);
            EXPECT_NEAR(length(hit.point - c), r, 1e-9 * r + coordinate_ulps(c, r))
                << "r " << r << " ray " << i;
        }
    }
}

TEST(Sphere, SurfaceAtGivesTheOutwardUnitNormal) {
    const Vec3 c{2, -1, 4};
    const double r = 3;
    Material material;
    material.kd = {0.1, 0.2, 0.3};
    const Sphere sphere({c}, r, material);
    for (std::uint64_t i = 0; i < 200; ++i) {
        const Vec3 start = c + unit_vector(60, i) * (4 * r);
        const Ray outside{start, normalize(c + unit_vector(61, i) * (0.7 * r) - start)};
        const auto t = sphere.intersect(outside, {});
        ASSERT_TRUE(t) << i;
        const SurfaceHit hit = sphere.surface_at(outside, *t);
        EXPECT_NEAR(length(hit.normal), 1.0, 1e-15) << i;
        EXPECT_TRUE(near(hit.normal, (hit.point - c) / r, 1e-14)) << i;
        EXPECT_LT(dot(hit.normal, outside.dir), 0) << i;
        EXPECT_EQ(hit.shading_normal, hit.normal) << i;
        EXPECT_EQ(hit.kd, material.kd) << i;

        // Seen from inside, the geometric normal still points out of the sphere.
        const Ray inside{c, unit_vector(62, i)};
        const auto t_in = sphere.intersect(inside, {});
        ASSERT_TRUE(t_in) << i;
        const SurfaceHit exit = sphere.surface_at(inside, *t_in);
        EXPECT_TRUE(near(exit.normal, inside.dir, 1e-14)) << i;
    }
}

TEST(SphereMotion, CentreAtEqualsPathPointsAtIntegerTimes) {
    const std::vector<Vec3> path{{0, 0, 0}, {10, 0, 0}, {10, 20, -4}, {-3, 0.5, 7}};
    const Sphere sphere(path, 1.0, plain_material());
    EXPECT_EQ(sphere.motion_end(), 3.0);
    EXPECT_TRUE(sphere.moves());
    for (std::size_t k = 0; k < path.size(); ++k) {
        EXPECT_EQ(sphere.path().at(static_cast<double>(k)), path[k]) << k;
    }
}

TEST(SphereMotion, CentreAtInterpolatesLinearlyBetweenPathPoints) {
    const std::vector<Vec3> path{{0, 0, 0}, {10, 0, 0}, {10, 20, -4}};
    const Sphere sphere(path, 1.0, plain_material());
    EXPECT_TRUE(near(sphere.path().at(0.5), {5, 0, 0}, 1e-14));
    EXPECT_TRUE(near(sphere.path().at(0.25), {2.5, 0, 0}, 1e-14));
    EXPECT_TRUE(near(sphere.path().at(1.5), {10, 10, -2}, 1e-14));
    EXPECT_TRUE(near(sphere.path().at(1.75), {10, 15, -3}, 1e-14));
    // One time unit per segment whatever its length: speed differs between segments.
    EXPECT_TRUE(near(sphere.path().at(1.0 - 1e-9), {10, 0, 0}, 1e-7));
    EXPECT_TRUE(near(sphere.path().at(1.0 + 1e-9), {10, 0, 0}, 1e-7));
}

TEST(SphereMotion, CentreAtClampsOutsideTheShutter) {
    const std::vector<Vec3> path{{1, 2, 3}, {4, 5, 6}, {7, 8, 10}};
    const Sphere sphere(path, 1.0, plain_material());
    EXPECT_EQ(sphere.path().at(-0.5), path.front());
    EXPECT_EQ(sphere.path().at(-1e9), path.front());
    EXPECT_EQ(sphere.path().at(2.5), path.back());
    EXPECT_EQ(sphere.path().at(1e9), path.back());

    const Sphere still({{1, 2, 3}}, 1.0, plain_material());
    EXPECT_EQ(still.motion_end(), 0.0);
    EXPECT_FALSE(still.moves());
    for (const double time : {-1.0, 0.0, 0.5, 7.0}) EXPECT_EQ(still.path().at(time), path[0]);
}

TEST(SphereMotion, IntersectPlacesTheSphereAtTheRayTime) {
    const Sphere sphere({{0, 0, 5}, {3, 0, 5}}, 1.0, plain_material());
    const Ray at_start{{0, 0, 0}, {0, 0, 1}, 0.0};
    const Ray at_end{{3, 0, 0}, {0, 0, 1}, 1.0};
    const Ray halfway{{1.5, 0, 0}, {0, 0, 1}, 0.5};
    ASSERT_TRUE(sphere.intersect(at_start, {}));
    EXPECT_DOUBLE_EQ(sphere.intersect(at_start, {})->t, 4.0);
    ASSERT_TRUE(sphere.intersect(at_end, {}));
    EXPECT_DOUBLE_EQ(sphere.intersect(at_end, {})->t, 4.0);
    ASSERT_TRUE(sphere.intersect(halfway, {}));
    EXPECT_NEAR(sphere.intersect(halfway, {})->t, 4.0, 1e-14);
    // The start position is empty at the end of the shutter.
    EXPECT_FALSE(sphere.intersect({{0, 0, 0}, {0, 0, 1}, 1.0}, {}));

    const SurfaceHit hit = sphere.surface_at(halfway, Hit{4.0, &sphere, 0, {}});
    EXPECT_TRUE(near(hit.normal, {0, 0, -1}, 1e-14));
}

}  // namespace
}  // namespace drt
