#include "drt/scene/camera.h"

#include <cmath>

namespace drt {

Camera::Camera(Vec3 eye, Vec3 forward, Vec3 up_hint, double half_height, int width, int height,
               Lens lens)
    : eye_(eye),
      right_(normalize(cross(up_hint, forward))),
      up_(cross(forward, right_)),
      forward_(forward),
      pixel_size_(2.0 * half_height / height),
      width_(width),
      height_(height),
      lens_(lens) {}

Camera Camera::look_at(const LookAt& view, int width, int height, Lens lens) {
    const double half_height = std::tan(view.fov_degrees * kPi / 360.0);
    return Camera(view.eye, normalize(view.target - view.eye), view.up, half_height, width, height,
                  lens);
}

Camera Camera::thesis_default(int width, int height, Lens lens, double pixel_size) {
    const Vec3 eye{width * pixel_size / 2, height * pixel_size / 2, -width * pixel_size};
    // The image plane z = 0 lies `width` in front of the eye and is `height` tall.
    const double half_height = 0.5 * height / width;
    return Camera(eye, {0, 0, 1}, {0, 1, 0}, half_height, width, height, lens);
}

Ray Camera::generate_ray(Vec2 film, Vec2 lens_u, double time) const {
    const double x = (film.x - 0.5 * width_) * pixel_size_;
    const double y = (0.5 * height_ - film.y) * pixel_size_;
    const Vec3 through = forward_ + right_ * x + up_ * y;  // the point at distance 1 along forward
    if (lens_.is_pinhole()) return {eye_, normalize(through), time};
    const Vec3 focus = eye_ + through * lens_.focal;  // on the focal plane
    const Vec2 disk = concentric_disk(lens_u);
    const Vec3 origin = eye_ + (right_ * disk.x + up_ * disk.y) * lens_.radius;
    return {origin, normalize(focus - origin), time};
}

RayDifferential Camera::differential(const Ray& ray, double step) const {
    // Every ray through one film position meets the others on the plane in focus (at distance 1
    // for a pinhole), where film steps are pixel_size_ · focal apart.
    const double focal = lens_.is_pinhole() ? 1.0 : lens_.focal;
    const Vec3 focus = ray.at(focal / dot(ray.dir, forward_));
    const double film_step = pixel_size_ * focal * step;
    return {{ray.origin, normalize(focus + right_ * film_step - ray.origin), ray.time},
            {ray.origin, normalize(focus - up_ * film_step - ray.origin), ray.time}};
}

Vec2 concentric_disk(Vec2 u) {
    const double a = 2 * u.x - 1, b = 2 * u.y - 1;
    if (a == 0 && b == 0) return {0, 0};
    double r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a, phi = (kPi / 4) * (b / a);
    } else {
        r = b, phi = (kPi / 2) - (kPi / 4) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

}  // namespace drt
