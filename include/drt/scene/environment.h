// An equirectangular (latitude-longitude) radiance map around the scene (docs/scene-format.md,
// "Image textures, UV coordinates, OBJ materials, environment"): the radiance of every escaping
// ray, and a light sampled in proportion to its luminance. A direction d maps to
// u = (φ − RotateY)/2π with φ = atan2(−dz, dx), and v = 1 − θ/π with θ = acos(dy).
#pragma once

#include <memory>
#include <optional>

#include "drt/sampling/distribution_2d.h"
#include "drt/shading/mipmap.h"
#include "drt/util/color.h"
#include "drt/util/math.h"

namespace drt {

class Environment {
  public:
    // How sample() draws directions: in proportion to luminance (the renderer's), or uniformly
    // over the sphere, which tests compare it with.
    enum class Sampling { kLuminance, kUniform };

    // `image`: the map (its finest level is read); `rotate_y`: radians, right-handed about +y.
    Environment(std::shared_ptr<const MipMap> image, double intensity, double rotate_y,
                Sampling sampling = Sampling::kLuminance);

    // Radiance arriving along -dir, i.e. seen by a ray going in unit direction `dir`: the map
    // read bilinearly (across the seam in u, not across the poles), times the intensity.
    Color radiance(const Vec3& dir) const;

    struct Sample {
        Vec3 dir;  // unit
        Color radiance;
        double pdf;  // per unit solid angle
    };
    // A direction drawn in proportion to the map's luminance (dilated by one texel, so that
    // every direction the bilinear lookup gives light has a positive density) from a point u
    // of the unit square; nothing at the poles, where the density is undefined.
    std::optional<Sample> sample(Vec2 u) const;
    double pdf(const Vec3& dir) const;

    // ∫ luminance(radiance) dω / 2π: what a surface facing up would receive (as irradiance/π)
    // from a uniform sky of the same total, to share shadow rays with other lights by.
    double power() const { return power_; }
    double intensity() const { return intensity_; }

  private:
    Vec2 uv_of(const Vec3& dir) const;

    std::shared_ptr<const MipMap> image_;
    double intensity_;
    double rotate_y_;
    double power_ = 0;
    Distribution2D distribution_;
};

}  // namespace drt
