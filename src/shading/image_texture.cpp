#include "drt/shading/image_texture.h"

#include <algorithm>
#include <cmath>

namespace drt {

namespace {

double length2(Vec2 v) {
    return std::hypot(v.x, v.y);
}

// A height map reads one trilinear square per lookup, as its central differences take four.
Color read(const MipMap& image, TextureFilter filter, Vec2 uv, double width) {
    return filter == TextureFilter::kBilinear ? image.bilinear(0, uv) : image.filtered(uv, width);
}

}  // namespace

double footprint_width(const TexturePoint& at) {
    return std::max(length2(at.duv_dx), length2(at.duv_dy));
}

Color ImageTexture::value(const TexturePoint& at) const {
    switch (filter_) {
        case TextureFilter::kAnisotropic:
            return image_->filtered(at.uv, at.duv_dx, at.duv_dy);
        case TextureFilter::kTrilinear:
            return image_->filtered(at.uv, footprint_width(at));
        case TextureFilter::kBilinear:
            break;
    }
    return image_->bilinear(0, at.uv);
}

double HeightMap::height(const TexturePoint& at, Vec2 uv) const {
    return luminance(read(*image_, filter_, uv, footprint_width(at)));
}

Vec3 HeightMap::perturb(const Vec3& normal, const TexturePoint& at, const Vec3& dp_du,
                        const Vec3& dp_dv) const {
    // Central differences one texel (or one footprint, if wider) either side.
    const double width = filter_ == TextureFilter::kBilinear ? 0 : footprint_width(at);
    const double du = std::max(1.0 / image_->width(), width);
    const double dv = std::max(1.0 / image_->height(), width);
    const Vec2 uv = at.uv;
    const double slope_u =
        (height(at, {uv.x + du, uv.y}) - height(at, {uv.x - du, uv.y})) / (2 * du);
    const double slope_v =
        (height(at, {uv.x, uv.y + dv}) - height(at, {uv.x, uv.y - dv})) / (2 * dv);
    const auto tangent = [&](const Vec3& d) {
        const Vec3 t = d - normal * dot(d, normal);
        const double l = length(t);
        return l > 0 ? t / l : Vec3{};
    };
    const Vec3 tilt = tangent(dp_du) * slope_u + tangent(dp_dv) * slope_v;
    return normalize(normal - tilt * strength_);
}

}  // namespace drt
