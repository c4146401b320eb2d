// The (u, v) of planes and spheres, exactly as docs/scene-format.md ("Image textures") states
// them.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::plain_material;

// Shows the (u, v) it is looked up at as its colour (u, v, 0).
class UvTexture final : public Texture {
  public:
    Color value(const TexturePoint& at) const override { return {at.uv.x, at.uv.y, 0}; }
    bool reads_uv() const override { return true; }
};

SurfaceDetail uv_detail(double texture_scale = 1) {
    SurfaceDetail detail;
    detail.texture = std::make_shared<const UvTexture>();
    detail.texture_scale = texture_scale;
    return detail;
}

// (u, v) where a ray from `from` towards `to` first meets `object`.
Vec2 uv_seen(const Object& object, const Vec3& from, const Vec3& to) {
    const Ray ray{from, normalize(to - from)};
    const auto hit = object.intersect(ray, {0, kInfinity});
    EXPECT_TRUE(hit);
    if (!hit) return {};
    const Color c = object.surface_at(ray, *hit).kd;
    return {c.r, c.g};
}

// A floor (normal +y): x and z tie for the smallest component, x wins, so e_u = +x and
// e_v = N × e_u = −z; TextureScale 2 puts one image per 2 × 2 square.
TEST(SurfaceUv, PlaneFollowsTheLeastAxisAndItsCrossProduct) {
    const Plane floor({0, -1, 0}, {0, 1, 0}, plain_material(), uv_detail(2));
    const Vec2 uv = uv_seen(floor, {3, 5, 5}, {3, -1, 5});
    EXPECT_NEAR(uv.x, 1.5, 1e-12);
    EXPECT_NEAR(uv.y, -2.5, 1e-12);

    // Normal (1, 1, 0)/√2: z is smallest, e_u = +z, e_v = N × z = (1, −1, 0)/√2.
    const Plane tilted({0, 0, 0}, {1, 1, 0}, plain_material(), uv_detail(1));
    const Vec3 p{1, -1, 4};  // on the plane
    const Vec2 t = uv_seen(tilted, p + Vec3{1, 1, 0}, p);
    EXPECT_NEAR(t.x, 4, 1e-12);
    EXPECT_NEAR(t.y, std::sqrt(2.0), 1e-12);

    // A wall facing −z: x and y tie, x wins: e_u = +x, e_v = (0, 0, −1) × x = −y.
    const Plane wall({0, 0, 10}, {0, 0, -1}, plain_material(), uv_detail(4));
    const Vec2 w = uv_seen(wall, {2, 6, 0}, {2, 6, 10});
    EXPECT_NEAR(w.x, 0.5, 1e-12);
    EXPECT_NEAR(w.y, -1.5, 1e-12);
}

// u = φ/2π, φ = atan2(−dz, dx) in [0, 2π); v = 1 − θ/π, θ = acos(dy): +x is the image's left
// edge, u grows counter-clockwise seen from above (+x, then −z), the top row is +y.
TEST(SurfaceUv, SphereMapsLongitudeAndLatitude) {
    const Vec3 c{1, 2, 3};
    const Sphere sphere({c}, 2, plain_material(), uv_detail());
    const auto seen_from = [&](const Vec3& d) { return uv_seen(sphere, c + d * 10.0, c); };
    const Vec2 px = seen_from({1, 0, 0});
    EXPECT_NEAR(px.x, 0, 1e-12);
    EXPECT_NEAR(px.y, 0.5, 1e-12);
    EXPECT_NEAR(seen_from({0, 0, -1}).x, 0.25, 1e-12);
    EXPECT_NEAR(seen_from({-1, 0, 0}).x, 0.5, 1e-12);
    EXPECT_NEAR(seen_from({0, 0, 1}).x, 0.75, 1e-12);
    EXPECT_NEAR(seen_from({0, 1, 0}).y, 1, 1e-6);
    EXPECT_NEAR(seen_from({0, -1, 0}).y, 0, 1e-6);
    const Vec3 d = normalize(Vec3{0.3, 0.5, -0.8});
    const Vec2 uv = seen_from(d);
    EXPECT_NEAR(uv.x, std::atan2(0.8, 0.3) / (2 * kPi), 1e-12);
    EXPECT_NEAR(uv.y, 1 - std::acos(d.y) / kPi, 1e-12);
    // Just below the seam at +x, u is near 1, not near 0.
    EXPECT_NEAR(seen_from(normalize(Vec3{1, 0, 0.01})).x, 1 - 0.01 / (2 * kPi), 1e-6);
}

}  // namespace
}  // namespace drt
