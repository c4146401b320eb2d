#include "drt/scene/surface_spec.h"

#include "drt/util/text.h"

namespace drt {

bool SurfaceSpec::same_as(const SurfaceSpec& other) const {
    const auto same_bump = [](const std::optional<BumpMap>& a, const std::optional<BumpMap>& b) {
        return a.has_value() == b.has_value() &&
               (!a || (a->scale == b->scale && a->strength == b->strength));
    };
    const auto same_corners = [](const std::optional<std::array<Vec2, 3>>& a,
                                 const std::optional<std::array<Vec2, 3>>& b) {
        if (a.has_value() != b.has_value()) return false;
        for (std::size_t k = 0; a && k < 3; ++k) {
            if ((*a)[k].x != (*b)[k].x || (*a)[k].y != (*b)[k].y) return false;
        }
        return true;
    };
    return textured == other.textured && texture == other.texture &&
           texture_scale == other.texture_scale && k2.r == other.k2.r && k2.g == other.k2.g &&
           k2.b == other.k2.b && same_bump(bump, other.bump) &&
           texture_file == other.texture_file && bump_file == other.bump_file &&
           image == other.image && height == other.height && bump_strength == other.bump_strength &&
           filter == other.filter && same_corners(corner_uv, other.corner_uv);
}

SurfaceDetail SurfaceSpec::build(const Material& material) const {
    SurfaceDetail detail;
    if (image) {
        detail.texture = std::make_shared<const ImageTexture>(image, filter);
    } else if (textured) {
        detail.texture = make_texture(texture, material.kd, k2, texture_scale);
    }
    detail.bump = bump;
    if (height)
        detail.height_map = std::make_shared<const HeightMap>(height, bump_strength, filter);
    detail.texture_scale = texture_scale;
    detail.corner_uv = corner_uv;
    return detail;
}

SurfaceSpec read_surface(Attributes& in) {
    SurfaceSpec s;
    s.textured = in.flag("EnableTexture", false);
    s.texture = in.text("Texture", "checker");
    s.texture_scale = in.number("TextureScale", 50);
    in.check(s.texture_scale > 0, "TextureScale", "positive");
    s.k2 = in.color("k2r", "k2g", "k2b", {0.1, 0.1, 0.1});
    // Checked even when disabled, so that a misspelt name does not wait to be found until the
    // texture is switched on.
    if (s.texture != SurfaceSpec::kImageTexture && !make_texture(s.texture, {}, {}, 1))
        in.fail("unknown texture '" + abbreviated(s.texture) + "'");
    if (s.image_texture()) {
        s.texture_file = in.text("TextureFile");
    } else {
        in.find("TextureFile");  // known, unused while the image texture is off
    }
    s.bump_file = in.text("BumpFile", "");
    const std::string filter = in.text("TextureFilter", "anisotropic");
    if (filter == "trilinear") {
        s.filter = TextureFilter::kTrilinear;
    } else if (filter == "bilinear") {
        s.filter = TextureFilter::kBilinear;
    } else if (filter != "anisotropic") {
        in.fail("TextureFilter must be anisotropic, trilinear or bilinear, got \"" +
                abbreviated(filter) + "\"");
    }

    const bool bumped = in.flag("bumpEnable", false);
    BumpMap bump;
    bump.scale = in.number("BumpScale", bump.scale);
    in.check(bump.scale > 0, "BumpScale", "positive");
    bump.strength = in.number("BumpStrength", bump.strength);
    s.bump_strength = bump.strength;
    if (bumped && s.bump_file.empty()) s.bump = bump;
    return s;
}

}  // namespace drt
