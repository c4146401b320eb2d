// Pinhole and thin-lens cameras.
#pragma once

#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

// Thin lens: lens radius and the distance, along the view direction, to the plane in focus.
struct Lens {
    double radius = 0;
    double focal = 0;
    bool is_pinhole() const { return radius <= 0; }
};

// An explicit look-at camera as the scene file gives it.
struct LookAt {
    Vec3 eye;
    Vec3 target;
    Vec3 up{0, 1, 0};
    double fov_degrees = 45;  // vertical
};

class Camera {
  public:
    static Camera look_at(const LookAt& view, int width, int height, Lens lens);
    // The thesis's pixel-plane camera: pixel (i, j) at world (i + ½, height − j − ½, 0), the eye
    // at (width/2, height/2, −width), looking along +z with y up. `pixel_size` ≠ 1 scales that
    // world geometry, so a resized render (drt --scale) keeps the scene's framing.
    static Camera thesis_default(int width, int height, Lens lens, double pixel_size = 1);

    // The ray through film position `film` (pixel units, x right, y down, pixel (i, j) covering
    // [i, i+1] x [j, j+1]); `lens_u` picks the lens point and is ignored by a pinhole.
    Ray generate_ray(Vec2 film, Vec2 lens_u, double time) const;
    // The differentials of a ray from generate_ray: the rays from the same lens point through
    // the film positions `step` pixels right and down of its own.
    RayDifferential differential(const Ray& ray, double step) const;
    bool has_lens() const { return !lens_.is_pinhole(); }
    const Vec3& eye() const { return eye_; }
    const Vec3& forward() const { return forward_; }

  private:
    Camera(Vec3 eye, Vec3 forward, Vec3 up_hint, double half_height, int width, int height,
           Lens lens);

    Vec3 eye_, right_, up_, forward_;
    double pixel_size_;  // on the image plane at distance 1
    int width_, height_;
    Lens lens_;
};

// Maps the unit square onto the unit disk keeping strata compact (Shirley & Chiu 1997), so a
// stratified lens sample stays stratified on the lens.
Vec2 concentric_disk(Vec2 u);

}  // namespace drt
