#include "drt/scene/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_math.h"

namespace drt {
namespace {

using testing::angle_between;
using testing::near;

// Where `ray` crosses the plane at distance `distance` along `forward` from `eye`.
Vec3 on_plane(const Ray& ray, const Vec3& eye, const Vec3& forward, double distance) {
    const double s = (distance - dot(ray.origin - eye, forward)) / dot(ray.dir, forward);
    return ray.at(s);
}

constexpr Vec2 kLensCentre{0.5, 0.5};

TEST(CameraThesisDefault, PixelCentreRaysPassThroughThePixelPlane) {
    const int width = 600, height = 500;
    const Camera camera = Camera::thesis_default(width, height, {});
    EXPECT_TRUE(near(camera.eye(), {300, 250, -600}, 0));
    EXPECT_TRUE(near(camera.forward(), {0, 0, 1}, 0));
    EXPECT_FALSE(camera.has_lens());
    for (int j = 0; j < height; j += 7) {
        for (int i = 0; i < width; i += 11) {
            const Ray ray = camera.generate_ray({i + 0.5, j + 0.5}, kLensCentre, 0);
            EXPECT_NEAR(length(ray.dir), 1.0, 1e-15);
            // Where the ray crosses z = 0.
            const Vec3 p = ray.at(-ray.origin.z / ray.dir.z);
            EXPECT_TRUE(near(p, {i + 0.5, height - j - 0.5, 0}, 1e-9)) << i << ", " << j;
        }
    }
    // The corners of the image too.
    const Ray top_left = camera.generate_ray({0, 0}, kLensCentre, 0);
    EXPECT_TRUE(near(top_left.at(-top_left.origin.z / top_left.dir.z), {0, 500, 0}, 1e-9));
    const Ray bottom_right = camera.generate_ray({600, 500}, kLensCentre, 0);
    EXPECT_TRUE(
        near(bottom_right.at(-bottom_right.origin.z / bottom_right.dir.z), {600, 0, 0}, 1e-9));
}

TEST(CameraThesisDefault, ThinLensFocusesOnItsFocalPlane) {
    const Camera camera = Camera::thesis_default(64, 48, {5.0, 100.0});
    ASSERT_TRUE(camera.has_lens());
    const Vec3 expected = on_plane(camera.generate_ray({10.5, 20.5}, kLensCentre, 0), camera.eye(),
                                   camera.forward(), 100.0);
    EXPECT_NEAR(expected.z, camera.eye().z + 100.0, 1e-12);
    for (const double u : {0.05, 0.3, 0.8}) {
        for (const double v : {0.1, 0.6, 0.95}) {
            const Ray ray = camera.generate_ray({10.5, 20.5}, {u, v}, 0);
            EXPECT_TRUE(near(on_plane(ray, camera.eye(), camera.forward(), 100.0), expected, 1e-9));
        }
    }
}

TEST(CameraLookAt, ImageCentreLooksAtTheTarget) {
    const LookAt views[] = {
        {{300, 250, -600}, {300, 250, 0}, {0, 1, 0}, 45},
        {{1, 2, 3}, {-4, 7, 1}, {0, 1, 0}, 60},
        {{0, 0, 0}, {1, 1, 1}, {0, 0, 1}, 30},
    };
    for (const LookAt& view : views) {
        const Camera camera = Camera::look_at(view, 640, 480, {});
        const Ray ray = camera.generate_ray({320, 240}, kLensCentre, 0);
        EXPECT_TRUE(near(ray.origin, view.eye, 0));
        EXPECT_TRUE(near(ray.dir, normalize(view.target - view.eye), 1e-15));
        EXPECT_TRUE(near(camera.forward(), normalize(view.target - view.eye), 1e-15));
    }
}

TEST(CameraLookAt, PositiveXIsImageRightLookingAlongPositiveZ) {
    const Camera camera = Camera::look_at({{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 45}, 200, 100, {});
    const Ray centre = camera.generate_ray({100, 50}, kLensCentre, 0);
    const Ray right = camera.generate_ray({150, 50}, kLensCentre, 0);
    const Ray left = camera.generate_ray({50, 50}, kLensCentre, 0);
    const Ray top = camera.generate_ray({100, 10}, kLensCentre, 0);
    EXPECT_GT(right.dir.x, 0);
    EXPECT_LT(left.dir.x, 0);
    EXPECT_NEAR(right.dir.y, 0, 1e-15);
    EXPECT_GT(top.dir.y, 0);  // row 0 at the top
    EXPECT_NEAR(top.dir.x, 0, 1e-15);
    for (int i = 0; i + 1 < 200; i += 13) {
        const Ray a = camera.generate_ray({i + 0.5, 30.5}, kLensCentre, 0);
        const Ray b = camera.generate_ray({i + 1.5, 30.5}, kLensCentre, 0);
        EXPECT_GT(b.dir.x, a.dir.x) << i;
    }
    // Mirror symmetry about the image centre.
    EXPECT_NEAR(right.dir.x, -left.dir.x, 1e-15);
    EXPECT_DOUBLE_EQ(centre.dir.z, 1.0);
}

TEST(CameraLookAt, RightIsUpCrossForwardForATiltedView) {
    const LookAt view{{1, 2, 3}, {-4, 7, 1}, {0.2, 1, 0.1}, 50};
    const Camera camera = Camera::look_at(view, 300, 200, {});
    const Vec3 forward = normalize(view.target - view.eye);
    const Vec3 right = normalize(cross(view.up, forward));
    const Vec3 up = cross(forward, right);
    const Ray r = camera.generate_ray({250, 100}, kLensCentre, 0);
    const Ray u = camera.generate_ray({150, 20}, kLensCentre, 0);
    EXPECT_GT(dot(r.dir, right), 0);
    EXPECT_NEAR(dot(r.dir, up), 0, 1e-15);
    EXPECT_GT(dot(u.dir, up), 0);
    EXPECT_NEAR(dot(u.dir, right), 0, 1e-15);
}

TEST(CameraLookAt, VerticalFovIsTheAngleBetweenTopAndBottomEdges) {
    for (const double fov : {30.0, 45.0, 90.0, 120.0}) {
        const int width = 640, height = 480;
        const LookAt view{{1, 2, 3}, {-4, 7, 1}, {0, 1, 0}, fov};
        const Camera camera = Camera::look_at(view, width, height, {});
        const Vec3 forward = normalize(view.target - view.eye);
        const double half = fov * kPi / 360.0;
        const Ray top = camera.generate_ray({width / 2.0, 0}, kLensCentre, 0);
        const Ray bottom = camera.generate_ray({width / 2.0, height}, kLensCentre, 0);
        EXPECT_NEAR(angle_between(top.dir, forward), half, 1e-12) << fov;
        EXPECT_NEAR(angle_between(bottom.dir, forward), half, 1e-12) << fov;
        EXPECT_NEAR(angle_between(top.dir, bottom.dir), 2 * half, 1e-12) << fov;
        // Square pixels: horizontally the half-width is tan(fov/2) * width/height at distance 1.
        const Ray side = camera.generate_ray({0, height / 2.0}, kLensCentre, 0);
        EXPECT_NEAR(angle_between(side.dir, forward), std::atan(std::tan(half) * width / height),
                    1e-12)
            << fov;
    }
}

TEST(CameraLookAt, PixelsAreSquare) {
    const Camera camera = Camera::look_at({{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 40}, 320, 180, {});
    const Vec3 f = camera.forward(), e = camera.eye();
    const Vec3 p = on_plane(camera.generate_ray({100.5, 60.5}, kLensCentre, 0), e, f, 1.0);
    const Vec3 px = on_plane(camera.generate_ray({101.5, 60.5}, kLensCentre, 0), e, f, 1.0);
    const Vec3 py = on_plane(camera.generate_ray({100.5, 61.5}, kLensCentre, 0), e, f, 1.0);
    const double pixel = 2.0 * std::tan(40 * kPi / 360.0) / 180.0;
    EXPECT_NEAR(length(px - p), pixel, 1e-14);
    EXPECT_NEAR(length(py - p), pixel, 1e-14);
    EXPECT_NEAR(dot(px - p, py - p), 0, 1e-17);
}

TEST(CameraLookAt, PinholeIgnoresTheLensSampleAndKeepsTheTime) {
    const Camera camera = Camera::look_at({{1, 2, 3}, {-4, 7, 1}, {0, 1, 0}, 45}, 64, 48, {});
    const Ray a = camera.generate_ray({12.3, 45.6}, {0.1, 0.9}, 0.25);
    const Ray b = camera.generate_ray({12.3, 45.6}, {0.7, 0.2}, 1.75);
    EXPECT_EQ(a.origin, b.origin);
    EXPECT_EQ(a.dir, b.dir);
    EXPECT_EQ(a.time, 0.25);
    EXPECT_EQ(b.time, 1.75);
    // A zero radius with a focal distance is a pinhole too.
    const Camera zero = Camera::look_at({{1, 2, 3}, {-4, 7, 1}, {0, 1, 0}, 45}, 64, 48, {0, 500});
    EXPECT_FALSE(zero.has_lens());
    EXPECT_EQ(zero.generate_ray({12.3, 45.6}, {0.9, 0.1}, 0).dir, a.dir);
}

TEST(CameraLookAt, ThinLensRaysThroughOneFilmPointMeetOnTheFocalPlane) {
    const LookAt view{{300, 250, -600}, {310, 240, 0}, {0, 1, 0}, 45};
    const Lens lens{15, 800};
    const Camera camera = Camera::look_at(view, 600, 500, lens);
    const Camera pinhole = Camera::look_at(view, 600, 500, {});
    ASSERT_TRUE(camera.has_lens());
    const Vec3 f = camera.forward(), e = camera.eye();
    for (const Vec2 film : {Vec2{300, 250}, Vec2{12.25, 480.5}, Vec2{599, 3}}) {
        // The pinhole ray through that film point, at distance 800 along the view direction.
        const Vec3 focus = on_plane(pinhole.generate_ray(film, kLensCentre, 0), e, f, 800.0);
        double widest = 0;
        for (int a = 0; a < 8; ++a) {
            for (int b = 0; b < 8; ++b) {
                const Ray ray = camera.generate_ray(film, {(a + 0.5) / 8, (b + 0.5) / 8}, 0.5);
                EXPECT_NEAR(length(ray.dir), 1.0, 1e-15);
                EXPECT_EQ(ray.time, 0.5);
                // The origin lies on the lens: perpendicular to the view, within its radius.
                EXPECT_NEAR(dot(ray.origin - e, f), 0, 1e-12);
                EXPECT_LE(length(ray.origin - e), lens.radius * (1 + 1e-12));
                widest = std::max(widest, length(ray.origin - e));
                EXPECT_TRUE(near(on_plane(ray, e, f, 800.0), focus, 1e-9 * 800))
                    << film.x << ", " << film.y << " lens " << a << ", " << b;
            }
        }
        EXPECT_GT(widest, 0.8 * lens.radius);  // the samples do spread over the lens
    }
    // The lens centre is the pinhole.
    const Ray centre = camera.generate_ray({100, 100}, kLensCentre, 0);
    EXPECT_TRUE(near(centre.origin, e, 0));
    EXPECT_TRUE(near(centre.dir, pinhole.generate_ray({100, 100}, kLensCentre, 0).dir, 1e-15));
}

TEST(CameraConcentricDisk, MapsTheSquareIntoTheUnitDisk) {
    const int n = 256;
    for (int a = 0; a <= n; ++a) {
        for (int b = 0; b <= n; ++b) {
            const Vec2 p = concentric_disk({double(a) / n, double(b) / n});
            EXPECT_LE(p.x * p.x + p.y * p.y, 1.0 + 1e-15) << a << ", " << b;
        }
    }
    // Centre to centre, edges and corners to the rim.
    const Vec2 c = concentric_disk({0.5, 0.5});
    EXPECT_EQ(c.x, 0);
    EXPECT_EQ(c.y, 0);
    for (const Vec2 u :
         {Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}, Vec2{1, 1}, Vec2{0.3, 1}, Vec2{0, 0.8}}) {
        const Vec2 p = concentric_disk(u);
        EXPECT_NEAR(std::hypot(p.x, p.y), 1.0, 1e-15) << u.x << ", " << u.y;
    }
    // The corner (1, 1) lands at 45 degrees.
    const Vec2 corner = concentric_disk({1, 1});
    EXPECT_NEAR(corner.x, std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(corner.y, std::sqrt(0.5), 1e-15);
}

TEST(CameraConcentricDisk, IsAreaPreserving) {
    const int n = 512;
    double sum_r2 = 0;
    int inner = 0, first_quadrant = 0, wedge = 0;
    for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
            const Vec2 p = concentric_disk({(a + 0.5) / n, (b + 0.5) / n});
            const double r2 = p.x * p.x + p.y * p.y;
            sum_r2 += r2;
            inner += r2 < 0.25;
            first_quadrant += p.x > 0 && p.y > 0;
            const double phi = std::atan2(p.y, p.x);
            wedge += phi > 0.1 && phi < 0.6;
        }
    }
    const double count = double(n) * n;
    // Uniform over the disk: E[r^2] = 1/2, P(r < 1/2) = 1/4, P(phi in a wedge) = width / 2 pi.
    EXPECT_NEAR(sum_r2 / count, 0.5, 1e-4);
    EXPECT_NEAR(inner / count, 0.25, 2e-3);
    EXPECT_NEAR(first_quadrant / count, 0.25, 1e-3);
    EXPECT_NEAR(wedge / count, 0.5 / (2 * kPi), 2e-3);
}

TEST(CameraConcentricDisk, IsPointSymmetric) {
    for (int a = 0; a <= 20; ++a) {
        for (int b = 0; b <= 20; ++b) {
            const Vec2 p = concentric_disk({a / 20.0, b / 20.0});
            const Vec2 q = concentric_disk({1 - a / 20.0, 1 - b / 20.0});
            EXPECT_NEAR(p.x, -q.x, 1e-14) << a << ", " << b;
            EXPECT_NEAR(p.y, -q.y, 1e-14) << a << ", " << b;
        }
    }
}

}  // namespace
}  // namespace drt
