// Next-event estimation's sampling of emitting triangles: the directions reach the mesh and
// carry the density pdf() gives for them (the density MIS weighs scattered rays with), that
// density integrates to 1 over the sphere of directions, it is the triangle's pick probability
// over its solid angle (by area where the solid angle is too small), and it estimates the
// irradiance under a triangle (Lambert's closed form) with less variance than area sampling.
#include "drt/scene/emitters.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "drt/accel/mesh.h"
#include "drt/geometry/sphere.h"
#include "drt/scene/scene_loader.h"
#include "test_math.h"
#include "test_meshes.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::unit;

// A quad in the plane y = 1 split into two triangles of unequal area (2.5 and 2.375), both
// sides emitting radiance 1. Its corners are exact in single precision, as a mesh keeps them.
const std::array<Vec3, 4> kQuad = {Vec3{-1, 1, -1}, Vec3{1.5, 1, -1}, Vec3{1, 1, 1},
                                   Vec3{-1, 1, 1.25}};
const std::array<std::array<int, 3>, 2> kQuadTriangles = {{{0, 1, 2}, {0, 2, 3}}};
const Vec3 kUp{0, 1, 0};

struct QuadScene {
    Scene scene;
    std::unique_ptr<Emitters> emitters;
};

// `triangles`: how many of kQuadTriangles the mesh has (1: the first alone).
std::unique_ptr<QuadScene> quad_scene(int triangles = 2) {
    auto q = std::make_unique<QuadScene>();
    q->scene = testing::blank_scene(1, 1, 1);
    Material glow;
    glow.name = "glow";
    glow.emission = {1, 1, 1};
    const Material& m = testing::add_material(q->scene, glow);
    testing::TestMesh quad;
    quad.vertices.assign(kQuad.begin(), kQuad.end());
    for (int t = 0; t < triangles; ++t) {
        const auto& c = kQuadTriangles[t];
        quad.triangles.push_back({static_cast<std::uint32_t>(c[0]),
                                  static_cast<std::uint32_t>(c[1]),
                                  static_cast<std::uint32_t>(c[2])});
    }
    auto mesh = std::make_shared<const TriangleMesh>(testing::obj_of(quad), MeshTransform{}, false);
    q->scene.objects.push_back(std::make_unique<Mesh>(mesh, std::vector<Vec3>{Vec3{}}, m));
    q->emitters = std::make_unique<Emitters>(q->scene);
    return q;
}

std::array<Vec3, 3> corners(int triangle) {
    const auto& c = kQuadTriangles[triangle];
    return {kQuad[c[0]], kQuad[c[1]], kQuad[c[2]]};
}

double area(const std::array<Vec3, 3>& p) {
    return 0.5 * length(cross(p[1] - p[0], p[2] - p[0]));
}

// Which triangle of the quad holds `point` (in the plane y = 1), if any.
std::optional<std::uint32_t> triangle_at(const Vec3& point, double slack = 0) {
    for (std::uint32_t t = 0; t < 2; ++t) {
        const auto p = corners(static_cast<int>(t));
        const double whole = area(p);
        const double parts =
            area({point, p[1], p[2]}) + area({p[0], point, p[2]}) + area({p[0], p[1], point});
        if (parts <= whole * (1 + 1e-12) + slack) return t;
    }
    return std::nullopt;
}

// Viewpoints: just under the quad, under it further off, beside it almost in its plane, above
// its other side, and farther from its plane than its edges are long, where it is sampled by
// area: 5 under it and far above (under 1e-4 sr besides).
const std::array<Vec3, 6> kViews = {Vec3{0.2, 0.9, 0.1},  Vec3{0.5, -1, 0.3},  Vec3{3, 0.95, 0},
                                    Vec3{-0.3, 1.5, 0.4}, Vec3{0.2, -4, -0.1}, Vec3{0.1, 300, 0.2}};

// Whether the triangle is sampled by solid angle from x: x nearer its plane than its longest
// edge is long, and the solid angle at least 1e-4 sr.
bool by_solid_angle(const Vec3& x, const std::array<Vec3, 3>& p, double omega) {
    double longest = 0;
    for (int k = 0; k < 3; ++k) longest = std::max(longest, length(p[(k + 1) % 3] - p[k]));
    return std::abs(x.y - 1) < longest && omega >= 1e-4;
}

double solid_angle(const Vec3& x, const std::array<Vec3, 3>& p) {
    const Vec3 a = normalize(p[0] - x), b = normalize(p[1] - x), c = normalize(p[2] - x);
    const auto angle = [](const Vec3& at, const Vec3& u, const Vec3& v) {
        return testing::angle_between(cross(at, u), cross(at, v));
    };
    return angle(a, b, c) + angle(b, c, a) + angle(c, a, b) - kPi;
}

TEST(Emitters, SampledDirectionsReachTheMeshWithTheDensityPdfGives) {
    const auto q = quad_scene();
    ASSERT_EQ(q->emitters->size(), 1u);
    for (const Vec3& x : kViews) {
        for (std::uint64_t i = 0; i < 4000; ++i) {
            const auto s = q->emitters->sample(0, x, {unit(1, i), unit(2, i)}, 0);
            ASSERT_TRUE(s);
            const Vec3 point = x + s->dir * s->distance;
            ASSERT_NEAR(point.y, 1, 1e-9 * (1 + s->distance));
            const auto t = triangle_at(point, 1e-9 * s->distance);
            ASSERT_TRUE(t) << "from (" << x.x << ", " << x.y << ", " << x.z << ") sample " << i;
            const double pdf = q->emitters->pdf(0, x, point, kUp, *t, 0);
            ASSERT_NEAR(s->pdf, pdf, 1e-9 * pdf) << i;
        }
    }
}

// An emitting part of a shared mesh (the <Triangle>s of a scene, one part per material) is
// sampled on its own triangles only: every direction reaches the lamp, never the floor beside
// it in the same mesh, and a hit on the floor's triangle has density 0 from the lamp.
TEST(Emitters, AnEmittingPartOfASharedMeshSamplesOnlyItsOwnTriangles) {
    const LoadedScene loaded = load_scene_from_string(R"(<Scene>
        <Camera Ex="0" Ey="0" Ez="-5" Lx="0" Ly="0" Lz="0" Fov="40"/>
        <Materials><Lamp ker="1" keg="1" keb="1"/><Floor diffuse="1"/></Materials>
        <Triangle Ax="-1" Ay="2" Az="-1" Bx="1" By="2" Bz="-1" Cx="0" Cy="2" Cz="1"
          Material="Lamp"/>
        <Triangle Ax="-4" Ay="0" Az="-4" Bx="4" By="0" Bz="-4" Cx="0" Cy="0" Cz="4"
          Material="Floor"/></Scene>)",
                                                      "parts.xml");
    ASSERT_EQ(loaded.scene.objects.size(), 2u);
    const auto& lamp = dynamic_cast<const Mesh&>(*loaded.scene.objects[0]);
    ASSERT_EQ(lamp.mesh().triangle_count(), 2u);
    const Emitters emitters(loaded.scene);
    ASSERT_EQ(emitters.size(), 1u);
    EXPECT_EQ(emitters[0].triangles.size(), 1u);
    EXPECT_DOUBLE_EQ(emitters[0].area, 2);
    std::uint32_t lamp_triangle = 0, floor_triangle = 1;
    if (lamp.mesh().parts()[0] != lamp.part()) std::swap(lamp_triangle, floor_triangle);
    const Vec3 x{0.1, 1, 0.2};
    for (std::uint64_t i = 0; i < 1000; ++i) {
        const auto s = emitters.sample(0, x, {unit(3, i), unit(4, i)}, 0);
        ASSERT_TRUE(s);
        const Vec3 point = x + s->dir * s->distance;
        ASSERT_NEAR(point.y, 2, 1e-9);
        EXPECT_NEAR(emitters.pdf(0, x, point, kUp, lamp_triangle, 0), s->pdf, 1e-9 * s->pdf);
    }
    EXPECT_EQ(emitters.pdf(0, x, {0, 0, 0}, kUp, floor_triangle, 0), 0);
}

// Triangle t's pick probability (its share of the area) over the solid angle it subtends; by
// area farther off, where the two agree to 1e-3 for a triangle seen face on 300 away and to
// 0.05 five away (measured: 8.6e-6 and 0.029).
TEST(Emitters, TrianglesDensityIsItsPickOverItsSolidAngle) {
    const auto q = quad_scene();
    const double total = area(corners(0)) + area(corners(1));
    for (int t = 0; t < 2; ++t) {
        const double pick = area(corners(t)) / total;
        for (const Vec3& x : kViews) {
            const auto p = corners(t);
            const Vec3 centroid = (p[0] + p[1] + p[2]) / 3;
            const double omega = solid_angle(x, p);
            const double pdf = q->emitters->pdf(0, x, centroid, kUp, t, 0);
            if (by_solid_angle(x, p, omega)) {
                EXPECT_NEAR(pdf, pick / omega, 1e-9 * pdf) << t << " " << x.y;
            } else {
                const Vec3 v = centroid - x;
                const double by_area = dot(v, v) / (total * std::abs(dot(kUp, normalize(v))));
                EXPECT_NEAR(pdf, by_area, 1e-12 * pdf) << t << " " << x.y;
                EXPECT_NEAR(pdf, pick / omega, (x.y > 10 ? 1e-3 : 0.05) * pdf) << t << " " << x.y;
            }
        }
    }
    // A triangle alone is picked with probability 1.
    const auto single = quad_scene(1);
    const Vec3 x = kViews[0];
    const double omega = solid_angle(x, corners(0));
    EXPECT_NEAR(single->emitters->pdf(0, x, corners(0)[0], kUp, 0, 0), 1 / omega, 1e-9 / omega);
}

// ∫ pdf dω over the sphere of directions, on a grid of 1200 x 1200 cells equal in solid angle
// over a cone that holds the quad: 1 to within the cells the quad's outline cuts (measured:
// 2.7e-3 off from just under the quad, where the cone is widest, 3e-5 from the others). Leaving out
// the pick probability makes it about 2. The view beside the quad, which it sees nearly edge on, is
// too thin for such a grid; the next test covers it.
TEST(Emitters, DensityIntegratesToOneOverTheSphere) {
    const auto q = quad_scene();
    for (const Vec3& x : kViews) {
        if (x.x == 3) continue;
        Vec3 axis;
        for (const Vec3& p : kQuad) axis += normalize(p - x);
        axis = normalize(axis);
        double cos_max = 1;
        for (const Vec3& p : kQuad) cos_max = std::min(cos_max, dot(axis, normalize(p - x)));
        cos_max = cos_max - 0.01 * (1 - cos_max);  // a margin
        const Frame frame = Frame::around(axis);
        const int n = 1200;
        const double cell = 2 * kPi * (1 - cos_max) / (double(n) * n);
        double integral = 0;
        for (int i = 0; i < n; ++i) {
            const double cos_t = 1 - (i + 0.5) / n * (1 - cos_max);
            const double sin_t = std::sqrt(1 - cos_t * cos_t);
            for (int j = 0; j < n; ++j) {
                const double phi = 2 * kPi * (j + 0.5) / n;
                const Vec3 d =
                    frame.to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t});
                if (!(std::abs(d.y) > 0)) continue;
                const double t = (1 - x.y) / d.y;
                if (!(t > 0)) continue;
                const Vec3 point = x + d * t;
                if (const auto k = triangle_at(point)) {
                    integral += q->emitters->pdf(0, x, point, kUp, *k, 0) * cell;
                }
            }
        }
        EXPECT_NEAR(integral, 1, 5e-3) << "from y " << x.y;
    }
}

// The same integral over the quad's surface, dω = cos/d² dA, on a grid of 1000 x 1000 cells
// per triangle (p = p0 + s(p1 − p0) + st(p2 − p1), dA = 2·area·s ds dt), which resolves every
// view: 1 to 1e-5 (measured: 5e-7 at most).
TEST(Emitters, DensityIntegratesToOneOverTheQuadsSurface) {
    const auto q = quad_scene();
    for (const Vec3& x : kViews) {
        double integral = 0;
        for (std::uint32_t k = 0; k < 2; ++k) {
            const auto p = corners(static_cast<int>(k));
            const int n = 1000;
            for (int i = 0; i < n; ++i) {
                const double s = (i + 0.5) / n;
                for (int j = 0; j < n; ++j) {
                    const double t = (j + 0.5) / n;
                    const Vec3 point = p[0] + (p[1] - p[0]) * s + (p[2] - p[1]) * (s * t);
                    const Vec3 v = point - x;
                    const double d2 = dot(v, v);
                    const double cosine = std::abs(v.y) / std::sqrt(d2);
                    integral += q->emitters->pdf(0, x, point, kUp, k, 0) * cosine / d2 * 2 *
                                area(p) * s / (double(n) * n);
                }
            }
        }
        EXPECT_NEAR(integral, 1, 1e-5) << "from y " << x.y;
    }
}

struct Irradiance {
    double mean, variance;  // of one sample's estimate
};

// Irradiance at x (normal up) from the first triangle of the quad, estimated by n samples of
// next-event estimation's directions, or by points uniform over the triangle's area.
Irradiance estimate(const Emitters& emitters, const Vec3& x, bool by_area, int n) {
    const auto p = corners(0);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const Vec2 u{unit(5, i), unit(6, i)};
        double value = 0;
        if (by_area) {
            const double su = std::sqrt(u.x);
            const Vec3 point = p[0] * (1 - su) + p[1] * (su * (1 - u.y)) + p[2] * (su * u.y);
            const Vec3 v = point - x;
            const double d2 = dot(v, v);
            const Vec3 dir = v / std::sqrt(d2);
            value = area(p) * std::max(0.0, dir.y) * std::abs(dot(kUp, dir)) / d2;
        } else if (const auto s = emitters.sample(0, x, u, 0)) {
            value = s->radiance.g * std::max(0.0, s->dir.y) / s->pdf;
        }
        sum += value;
        sum2 += value * value;
    }
    const double mean = sum / n;
    return {mean, sum2 / n - mean * mean};
}

// Under the triangle, 0.1 below it near a corner and 0.02 below it near an edge's middle, and
// 2 under its centre (nearer its plane than its longest edge, 2.8, is long): both estimates agree
// with Lambert's formula within four standard errors, and the solid-angle one has a twentieth of
// area sampling's variance or less near the triangle (measured: 1/430 and 1/6000) and half or less
// under its centre (measured: 1/16); all it has left is the variation of the cosine at x.
TEST(Emitters, IrradianceUnderATriangleIsLambertsWithLessVarianceThanByArea) {
    const auto single = quad_scene(1);
    const auto p = corners(0);
    struct View {
        Vec3 x;
        bool near;
    };
    for (const View& view : {View{{-0.8, 0.9, -0.85}, true}, View{{1.25, 0.98, 0}, true},
                             View{{0.4, -1, -0.3}, false}}) {
        const double expected = testing::triangle_irradiance(view.x, kUp, p[0], p[1], p[2]);
        const int n = 40000;
        const Irradiance solid = estimate(*single->emitters, view.x, false, n);
        const Irradiance by_area = estimate(*single->emitters, view.x, true, n);
        EXPECT_NEAR(solid.mean, expected, 4 * std::sqrt(solid.variance / n) + 1e-12 * expected)
            << view.x.y;
        EXPECT_NEAR(by_area.mean, expected, 4 * std::sqrt(by_area.variance / n)) << view.x.y;
        EXPECT_LT(solid.variance, (view.near ? 0.05 : 0.5) * by_area.variance) << view.x.y;
    }
}

// A set of next-event samples drawn at once (what the integrators draw for several shadow rays)
// is the samples drawn one by one, bit for bit, for a moving emitting sphere seen from outside
// and from inside, a Falloff-1 point light and a mesh; and every point sampled on a sphere or a
// point light lies in the extent that shadow-ray culling gathers occluders for.
TEST(Emitters, ASetOfSamplesIsItsSamplesOneByOneWithinTheExtent) {
    auto q = quad_scene();
    Scene& scene = q->scene;
    Material glow;
    glow.name = "sphere glow";
    glow.emission = {2, 1, 0.5};
    const Material& m = testing::add_material(scene, glow);
    const double radius = 0.75;
    scene.objects.push_back(
        std::make_unique<Sphere>(std::vector<Vec3>{{1, 2, 3}, {2, 2.5, 3}}, radius, m));
    scene.inverse_square_lights.push_back({{-2, 4, 1}, {30, 30, 30}});
    const Emitters emitters(scene);
    ASSERT_EQ(emitters.size(), 3u);  // the point light, the quad, the sphere
    const std::size_t point = 0, quad = 1, sphere = 2;
    EXPECT_FALSE(emitters.extent(quad, 0).has_value());
    constexpr int kCount = 7;
    std::array<Vec2, kCount> u;
    std::array<std::optional<EmitterSample>, kCount> set;
    int outside = 0, inside = 0;
    for (std::uint64_t p = 0; p < 200; ++p) {
        const double time = unit(60, p);
        const Vec3 centre = Vec3{1, 2, 3} + Vec3{1, 0.5, 0} * time;
        // Every fourth point inside the sphere, the others around it.
        const Vec3 x = p % 4 == 0 ? centre + testing::unit_vector(61, p) * (0.9 * radius)
                                  : centre + Vec3{6 * unit(62, p) - 3, 6 * unit(63, p) - 3,
                                                  6 * unit(64, p) - 3};
        ++(length(x - centre) < radius ? inside : outside);
        for (int k = 0; k < kCount; ++k)
            u[k] = {unit(65, p * kCount + k), unit(66, p * kCount + k)};
        for (const std::size_t i : {point, quad, sphere}) {
            emitters.sample(i, x, u, time, set);
            const auto extent = emitters.extent(i, time);
            for (int k = 0; k < kCount; ++k) {
                const auto one = emitters.sample(i, x, u[k], time);
                ASSERT_EQ(one.has_value(), set[k].has_value()) << i << " " << p << " " << k;
                if (!one) continue;
                EXPECT_EQ(one->dir, set[k]->dir) << i << " " << p << " " << k;
                EXPECT_EQ(one->distance, set[k]->distance) << i << " " << p << " " << k;
                EXPECT_EQ(one->radiance, set[k]->radiance) << i << " " << p << " " << k;
                EXPECT_EQ(one->pdf, set[k]->pdf) << i << " " << p << " " << k;
                if (!extent) continue;
                const Vec3 sampled = x + one->dir * one->distance;
                EXPECT_LE(length(sampled - extent->centre), extent->radius * (1 + 1e-12) + 1e-12)
                    << i << " " << p << " " << k;
            }
        }
    }
    EXPECT_GT(inside, 40);
    EXPECT_GT(outside, 100);
}

}  // namespace
}  // namespace drt
