#include "drt/shading/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>

#include "drt/geometry/sphere.h"
#include "drt/util/rng.h"
#include "test_math.h"

namespace drt {
namespace {

using testing::unit_vector;

Vec3 random_point(std::uint64_t seed, std::uint64_t i, double extent) {
    return {extent * (2 * to_unit(hash_of(seed, i, 0)) - 1),
            extent * (2 * to_unit(hash_of(seed, i, 1)) - 1),
            extent * (2 * to_unit(hash_of(seed, i, 2)) - 1)};
}

TEST(TexturePerlinNoise, VanishesOnTheIntegerLattice) {
    for (int x = -3; x <= 3; ++x) {
        for (int y = -3; y <= 3; ++y) {
            for (int z = -3; z <= 3; ++z)
                EXPECT_EQ(perlin_noise({double(x), double(y), double(z)}), 0.0);
        }
    }
    EXPECT_EQ(perlin_noise({255, 256, 257}), 0.0);
    EXPECT_EQ(perlin_noise({-1000, 12345, 1e6}), 0.0);
}

TEST(TexturePerlinNoise, IsBoundedAndNotTrivial) {
    double lo = 0, hi = 0, sum_abs = 0, sum = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        const double v = perlin_noise(random_point(1, i, 300));
        ASSERT_TRUE(std::isfinite(v));
        lo = std::min(lo, v), hi = std::max(hi, v);
        sum_abs += std::abs(v), sum += v;
    }
    EXPECT_GE(lo, -1.1);
    EXPECT_LE(hi, 1.1);
    // It does vary: typical magnitude ~0.2, both signs, roughly zero mean.
    EXPECT_GT(sum_abs / n, 0.1);
    EXPECT_LT(lo, -0.5);
    EXPECT_GT(hi, 0.5);
    EXPECT_NEAR(sum / n, 0, 0.02);
}

TEST(TexturePerlinNoise, IsContinuousIncludingAcrossCellFacesAndTheWrap) {
    for (int i = 0; i < 2000; ++i) {
        const Vec3 p = random_point(2, i, 50);
        const Vec3 step = unit_vector(3, i) * 1e-7;
        EXPECT_NEAR(perlin_noise(p + step), perlin_noise(p), 1e-5) << i;
    }
    // Across lattice faces (where the gradient selection changes) and the 256-periodic wrap.
    for (const double face : {-1.0, 0.0, 1.0, 17.0, 255.0, 256.0, -256.0}) {
        for (int i = 0; i < 50; ++i) {
            const Vec3 q = random_point(4, i, 10);
            for (int axis = 0; axis < 3; ++axis) {
                Vec3 below = q, above = q;
                double* b = axis == 0 ? &below.x : axis == 1 ? &below.y : &below.z;
                double* a = axis == 0 ? &above.x : axis == 1 ? &above.y : &above.z;
                *b = face - 1e-9, *a = face + 1e-9;
                EXPECT_NEAR(perlin_noise(below), perlin_noise(above), 1e-7)
                    << "face " << face << " axis " << axis;
            }
        }
    }
}

TEST(TexturePerlinNoise, IsPeriodic) {
    for (int i = 0; i < 100; ++i) {
        const Vec3 p = random_point(5, i, 100);
        // The lattice hash repeats every 256 cells.
        EXPECT_NEAR(perlin_noise(p + Vec3{256, 0, 0}), perlin_noise(p), 1e-9);
        EXPECT_NEAR(perlin_noise(p - Vec3{0, 512, 0}), perlin_noise(p), 1e-9);
    }
    // Not the same value everywhere in a cell.
    EXPECT_NE(perlin_noise({0.5, 0.5, 0.5}), perlin_noise({0.3, 0.6, 0.2}));
}

// The gradient of the noise by central differences of step h (error O(h^2)).
Vec3 noise_gradient(const Vec3& p, double h = 1e-6) {
    return Vec3{perlin_noise(p + Vec3{h, 0, 0}) - perlin_noise(p - Vec3{h, 0, 0}),
                perlin_noise(p + Vec3{0, h, 0}) - perlin_noise(p - Vec3{0, h, 0}),
                perlin_noise(p + Vec3{0, 0, h}) - perlin_noise(p - Vec3{0, 0, h})} /
           (2 * h);
}

// Whether v is, to tol, one of the 12 lattice gradients: two components +-1, the third 0.
bool is_cube_edge_direction(const Vec3& v, double tol) {
    int ones = 0, zeros = 0;
    for (const double c : {v.x, v.y, v.z}) {
        ones += std::abs(std::abs(c) - 1) < tol;
        zeros += std::abs(c) < tol;
    }
    return ones == 2 && zeros == 1;
}

TEST(TexturePerlinNoise, GradientAtALatticePointIsOneOfTheTwelveCubeEdgeDirections) {
    // At a lattice point the fade curves have zero slope, so only that corner's gradient
    // counts: the noise's gradient there is the lattice gradient itself.
    int seen_x0 = 0, seen_z0 = 0;
    for (int i = 0; i < 200; ++i) {
        const Vec3 p{std::floor(random_point(15, i, 300).x), std::floor(random_point(16, i, 300).y),
                     std::floor(random_point(17, i, 300).z)};
        const Vec3 g = noise_gradient(p);
        EXPECT_TRUE(is_cube_edge_direction(g, 1e-6)) << g.x << " " << g.y << " " << g.z;
        seen_x0 += std::abs(g.x) < 0.5, seen_z0 += std::abs(g.z) < 0.5;
    }
    EXPECT_GT(seen_x0, 20);  // the hash picks among them
    EXPECT_GT(seen_z0, 20);
}

TEST(TextureTurbulence, IsNonNegativeAndBounded) {
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p = random_point(6, i, 100);
        const double t = turbulence(p);
        EXPECT_GE(t, 0.0) << i;
        EXPECT_LE(t, 1.1) << i;
    }
    // One octave is |noise| / 2.
    const Vec3 p{0.3, 1.7, -2.2};
    EXPECT_DOUBLE_EQ(turbulence(p, 1), 0.5 * std::abs(perlin_noise(p)));
    EXPECT_EQ(turbulence({1, 2, 3}), 0.0);  // every octave lands on the lattice
}

TEST(TextureBumpMap, ZeroStrengthKeepsTheNormal) {
    const BumpMap bump{20, 0};
    for (int i = 0; i < 200; ++i) {
        const Vec3 n = unit_vector(7, i);
        const Vec3 out = bump.perturb(n, random_point(8, i, 100));
        EXPECT_NEAR(out.x, n.x, 1e-15);
        EXPECT_NEAR(out.y, n.y, 1e-15);
        EXPECT_NEAR(out.z, n.z, 1e-15);
    }
}

TEST(TextureBumpMap, PerturbedNormalsAreUnitAndOnTheNormalsSide) {
    for (const double strength : {0.3, 1.0, 5.0}) {
        const BumpMap bump{20, strength};
        double max_tilt = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 n = unit_vector(9, i);
            const Vec3 out = bump.perturb(n, random_point(10, i, 200));
            EXPECT_NEAR(length(out), 1.0, 1e-14) << i;
            EXPECT_GT(dot(out, n), 0) << i;
            max_tilt = std::max(max_tilt, 1 - dot(out, n));
        }
        EXPECT_GT(max_tilt, 1e-3) << strength;  // it does perturb
    }
}

TEST(TextureBumpMap, TiltFollowsTheNoiseGradient) {
    // On a surface facing +z, the shading normal leans towards decreasing noise.
    const BumpMap bump{1, 0.3};
    for (int i = 0; i < 200; ++i) {
        const Vec3 p = random_point(11, i, 20);
        const double h = 1e-5;
        const double gx =
            (perlin_noise(p + Vec3{h, 0, 0}) - perlin_noise(p - Vec3{h, 0, 0})) / (2 * h);
        const Vec3 out = bump.perturb({0, 0, 1}, p);
        if (std::abs(gx) < 0.05) continue;
        EXPECT_LT(out.x * gx, 0) << i;
    }
}

TEST(TextureBumpMap, TiltAtALatticePointIsTheStrengthAlongTheLatticeGradient) {
    // At local = scale k (k on the integer lattice) the noise's gradient is a cube-edge
    // direction g; the normal of a surface facing +z leans to normalize((-s g.x, -s g.y, 1)),
    // s the strength, so its slopes -out.x/out.z and -out.y/out.z are each 0 or +-s. A 2 %
    // error in the strength moves a slope by 0.02 s; one in the scale samples the noise off the
    // lattice, where the slopes are anything. (The bump map's own difference step leaves
    // about 1e-5.)
    for (const auto& [scale, strength] : {std::pair{20.0, 0.3}, std::pair{3.5, 1.7}}) {
        const BumpMap bump{scale, strength};
        for (int i = 0; i < 100; ++i) {
            const Vec3 k{std::floor(random_point(18, i, 100).x),
                         std::floor(random_point(19, i, 100).y), 0};
            const Vec3 out = bump.perturb({0, 0, 1}, k * scale);
            const Vec3 g = noise_gradient(k);
            EXPECT_NEAR(-out.x / out.z, strength * g.x, 1e-4 * strength) << i;
            EXPECT_NEAR(-out.y / out.z, strength * g.y, 1e-4 * strength) << i;
            EXPECT_TRUE(is_cube_edge_direction(g, 1e-6));
        }
    }
}

TEST(TextureChecker, AlternatesByCellOfTheScale) {
    const Color a{1, 0, 0}, b{0, 0, 1};
    const CheckerTexture checker(a, b, 10);
    EXPECT_EQ(checker.value({{5, 5, 5}, {}, {}, {}}), a);
    EXPECT_EQ(checker.value({{15, 5, 5}, {}, {}, {}}), b);
    EXPECT_EQ(checker.value({{15, 15, 5}, {}, {}, {}}), a);
    EXPECT_EQ(checker.value({{15, 15, 15}, {}, {}, {}}), b);
    // Cells are half-open [k s, (k+1) s) and continue through negative coordinates.
    EXPECT_EQ(checker.value({{0, 0, 0}, {}, {}, {}}), a);
    EXPECT_EQ(checker.value({{-0.001, 0, 0}, {}, {}, {}}), b);
    EXPECT_EQ(checker.value({{-9.999, 0, 0}, {}, {}, {}}), b);
    EXPECT_EQ(checker.value({{-10.001, 0, 0}, {}, {}, {}}), a);
    EXPECT_EQ(checker.value({{9.999, 0, 0}, {}, {}, {}}), a);
    EXPECT_EQ(checker.value({{10, 0, 0}, {}, {}, {}}), b);
}

TEST(TextureChecker, OnASphereIsRelativeToItsCentre) {
    const Color a{1, 1, 1}, b{0, 0, 0};
    SurfaceDetail detail;
    detail.texture = std::make_shared<CheckerTexture>(a, b, 5.0);
    const Material material;
    // Centre at x = 7: in world coordinates the top point (7, 10, 0) has cells 1 + 2 + 0 (odd),
    // relative to the centre (0, 10, 0) it has 0 + 2 + 0 (even).
    const Sphere sphere({{7, 0, 0}}, 10, material, detail);
    const Ray down{{7, 30, 0}, {0, -1, 0}};
    const auto t = sphere.intersect(down, {});
    ASSERT_TRUE(t);
    EXPECT_EQ(sphere.surface_at(down, *t).kd, a);

    const CheckerTexture checker(a, b, 5.0);
    for (int i = 0; i < 200; ++i) {
        const Vec3 start = Vec3{7, 0, 0} + unit_vector(12, i) * 30;
        const Ray ray{start, normalize(Vec3{7, 0, 0} + unit_vector(13, i) * 5 - start)};
        const auto ti = sphere.intersect(ray, {});
        ASSERT_TRUE(ti) << i;
        const SurfaceHit hit = sphere.surface_at(ray, *ti);
        EXPECT_EQ(hit.kd, checker.value({hit.point - Vec3{7, 0, 0}, {}, {}, {}})) << i;
    }

    // A moving sphere carries its texture along.
    const Sphere moving({{7, 0, 0}, {57, 0, 0}}, 10, material, detail);
    for (const double time : {0.0, 0.37, 1.0}) {
        const Vec3 c = moving.path().at(time);
        const Ray ray{c + Vec3{1.3, 30, 2.1}, {0, -1, 0}, time};
        const auto ti = moving.intersect(ray, {});
        ASSERT_TRUE(ti) << time;
        const SurfaceHit hit = moving.surface_at(ray, *ti);
        EXPECT_EQ(hit.kd, checker.value({hit.point - c, {}, {}, {}})) << time;
        EXPECT_EQ(hit.kd,
                  sphere.surface_at({Vec3{7, 0, 0} + Vec3{1.3, 30, 2.1}, {0, -1, 0}}, *ti).kd)
            << time;
    }
}

TEST(TextureMarble, StaysBetweenItsTwoColours) {
    const Color a{0.9, 0.8, 0.7}, b{0.1, 0.2, 0.3};
    const MarbleTexture marble(a, b, 50);
    bool near_a = false, near_b = false;
    for (int i = 0; i < 5000; ++i) {
        const Color c = marble.value({random_point(14, i, 500), {}, {}, {}});
        EXPECT_GE(c.r, 0.1 - 1e-12);
        EXPECT_LE(c.r, 0.9 + 1e-12);
        // A blend: the same weight in every channel.
        const double w = (c.r - a.r) / (b.r - a.r);
        EXPECT_NEAR(c.g, a.g + w * (b.g - a.g), 1e-12);
        near_a |= w<0.05, near_b |= w> 0.95;
    }
    EXPECT_TRUE(near_a && near_b);
}

TEST(TextureMarble, OnTheScaledLatticeIsTheBareSineWave) {
    // Turbulence vanishes where every octave lands on the lattice, so at local = scale (i, j, k)
    // the veins are undisturbed: the blend weight is 1/2 + sin(i)/2. A scale 2 % off samples
    // the turbulence off the lattice and the sine at 0.98 i.
    const Color a{0.9, 0.8, 0.7}, b{0.1, 0.2, 0.3};
    for (const double scale : {50.0, 7.25}) {
        const MarbleTexture marble(a, b, scale);
        for (int i = -20; i <= 20; i += 3) {
            const Vec3 lattice{double(i), double(i % 7), double(-2 * i)};
            const double w = 0.5 + 0.5 * std::sin(double(i));
            const Color c = marble.value({lattice * scale, {}, {}, {}});
            EXPECT_NEAR(c.r, a.r + w * (b.r - a.r), 1e-12) << scale << " " << i;
            EXPECT_NEAR(c.b, a.b + w * (b.b - a.b), 1e-12) << scale << " " << i;
        }
    }
}

TEST(TextureFactory, MakesKnownTexturesAndRejectsUnknownNames) {
    const Color a{1, 0, 0}, b{0, 1, 0};
    const auto checker = make_texture("checker", a, b, 10);
    ASSERT_NE(checker, nullptr);
    EXPECT_EQ(checker->value({{5, 5, 5}, {}, {}, {}}), a);
    EXPECT_EQ(checker->value({{15, 5, 5}, {}, {}, {}}), b);
    EXPECT_NE(make_texture("marble", a, b, 10), nullptr);
    EXPECT_EQ(make_texture("wood", a, b, 10), nullptr);
    EXPECT_EQ(make_texture("", a, b, 10), nullptr);
    EXPECT_EQ(make_texture("Checker", a, b, 10), nullptr);
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

// A tiny scale puts points in cells past 2^63, where a plain integer cell index would overflow
// (undefined behaviour the sanitizer build reports). Cells that far are whole multiples of 2^10,
// so even: the checker shows its first colour.
TEST(TextureRobustness, TinyScalesAndHugeCoordinatesStayDefined) {
    const Color a{1, 0, 0}, b{0, 0, 1};
    const auto checker = make_texture("checker", a, b, 1e-300);
    for (const Vec3 p : {Vec3{1, 2, 3}, Vec3{-1e10, 5e9, 1e-290}, Vec3{1e308, -1e308, 0}}) {
        const Color c = checker->value({p, {}, {}, {}});
        EXPECT_EQ(c.r, a.r) << p.x;
        EXPECT_EQ(c.b, a.b) << p.x;
    }
    // Within range the parity still alternates, including for negative cells.
    const auto unit = make_texture("checker", a, b, 1);
    EXPECT_EQ(unit->value({{0.5, 0.5, 0.5}, {}, {}, {}}).r, a.r);
    EXPECT_EQ(unit->value({{1.5, 0.5, 0.5}, {}, {}, {}}).r, b.r);
    EXPECT_EQ(unit->value({{-0.5, 0.5, 0.5}, {}, {}, {}}).r, b.r);
    EXPECT_EQ(unit->value({{-0.5, -0.5, 0.5}, {}, {}, {}}).r, a.r);
    for (const double v : {1e19, -1e19, 1e300, -1e300}) {
        EXPECT_TRUE(std::isfinite(perlin_noise({v, v, v}))) << v;
    }
    for (const double v : {1e19, -1e19}) {  // 1e29 in the noise's lattice units
        EXPECT_TRUE(
            std::isfinite(make_texture("marble", a, b, 1e-10)->value({{v, 1, 2}, {}, {}, {}}).r))
            << v;
    }
    BumpMap bump;
    bump.scale = 1e-10;
    const Vec3 n = bump.perturb({0, 0, 1}, {1e10, 3, 4});
    EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
}

}  // namespace
}  // namespace drt
