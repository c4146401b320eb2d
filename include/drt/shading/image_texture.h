// Image textures: a colour image that replaces a material's kd, and a height map that bumps the
// shading normal, both read through a mip-map at the surface's (u, v).
#pragma once

#include <memory>

#include "drt/shading/mipmap.h"
#include "drt/shading/texture.h"
#include "drt/util/math.h"

namespace drt {

// The width of the footprint that TexturePoint's two steps across (u, v) span: the larger of
// their lengths, as trilinear filtering takes one square for both.
double footprint_width(const TexturePoint& at);

// How an image is read: anisotropically over the sample's footprint (MipMap::filtered with both
// steps), trilinear over a square as wide as its longer step, or bilinear from the finest level
// whatever the footprint (which aliases in the distance). The last two are kept for comparison.
enum class TextureFilter { kAnisotropic, kTrilinear, kBilinear };

class ImageTexture final : public Texture {
  public:
    explicit ImageTexture(std::shared_ptr<const MipMap> image,
                          TextureFilter filter = TextureFilter::kAnisotropic)
        : image_(std::move(image)), filter_(filter) {}
    Color value(const TexturePoint& at) const override;
    bool reads_uv() const override { return true; }

  private:
    std::shared_ptr<const MipMap> image_;
    TextureFilter filter_;
};

// A height map: the image's luminance (linear) as a height h over the surface. The normal tilts
// against the height's slope: n' = normalize(n − strength · (∂h/∂u · t_u + ∂h/∂v · t_v)) with
// t_u, t_v the unit surface directions in which u and v grow, so that strength 1 tilts a
// slope of one unit of height per copy of the image by 45°.
class HeightMap {
  public:
    HeightMap(std::shared_ptr<const MipMap> image, double strength,
              TextureFilter filter = TextureFilter::kAnisotropic)
        : image_(std::move(image)), strength_(strength), filter_(filter) {}
    // `dp_du`, `dp_dv`: how the surface point moves with u and v.
    Vec3 perturb(const Vec3& normal, const TexturePoint& at, const Vec3& dp_du,
                 const Vec3& dp_dv) const;
    double height(const TexturePoint& at, Vec2 uv) const;

  private:
    std::shared_ptr<const MipMap> image_;
    double strength_;
    TextureFilter filter_;
};

}  // namespace drt
