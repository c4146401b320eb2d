// Procedural textures (replacing a material's kd) and Perlin-noise bump mapping.
#pragma once

#include <memory>
#include <optional>
#include <string_view>

#include "drt/util/color.h"
#include "drt/util/math.h"

namespace drt {

// Gradient noise in the manner of Perlin (2002): smooth, about [-1, 1], zero on the integer
// lattice. Its permutation is fixed at compile time, so every run sees the same noise.
double perlin_noise(const Vec3& p);
// Sum of |noise| over octaves (Perlin's turbulence), about [0, 1).
double turbulence(const Vec3& p, int octaves = 6);

// Where a texture is looked up: the point in the object's own 3-D texture coordinates, which
// procedural textures read, and the surface's (u, v) with the footprint of the sample around it,
// which image textures read (both are filled only for a texture that asks for them).
struct TexturePoint {
    Vec3 local;
    Vec2 uv;
    // Change of (u, v) to the neighbouring camera samples across and down the image; zero when
    // unknown, which reads the image's finest level.
    Vec2 duv_dx, duv_dy;
};

class Texture {
  public:
    virtual ~Texture() = default;
    virtual Color value(const TexturePoint& at) const = 0;
    // Whether value() reads the surface's (u, v), which the object then works out.
    virtual bool reads_uv() const { return false; }
};

// Cells of edge `scale` alternating between two colours.
class CheckerTexture final : public Texture {
  public:
    CheckerTexture(Color a, Color b, double scale) : a_(a), b_(b), scale_(scale) {}
    Color value(const TexturePoint& at) const override;

  private:
    Color a_, b_;
    double scale_;
};

// Veins of a sine wave disturbed by turbulence, blending between two colours.
class MarbleTexture final : public Texture {
  public:
    MarbleTexture(Color a, Color b, double scale) : a_(a), b_(b), scale_(scale) {}
    Color value(const TexturePoint& at) const override;

  private:
    Color a_, b_;
    double scale_;
};

// The texture called `name` ("checker", "marble"), or nullptr for an unknown name.
std::unique_ptr<Texture> make_texture(std::string_view name, Color a, Color b, double scale);

// Perturbs a shading normal by the gradient of Perlin noise of feature size `scale`.
struct BumpMap {
    double scale = 20;
    double strength = 0.3;
    Vec3 perturb(const Vec3& normal, const Vec3& local) const;
};

}  // namespace drt
