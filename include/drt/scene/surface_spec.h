// A surface's texture and bump attributes as the scene file gives them (docs/scene-format.md,
// "Textures" and "Image textures"), common to planes, spheres, triangles and meshes. They are
// kept as read until every material is known, since a procedural texture needs its material's kd.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "drt/geometry/object.h"
#include "drt/scene/xml_attributes.h"
#include "drt/shading/image_texture.h"
#include "drt/shading/material.h"
#include "drt/shading/mipmap.h"
#include "drt/shading/texture.h"
#include "drt/util/math.h"

namespace drt {

struct SurfaceSpec {
    bool textured = false;
    std::string texture;
    double texture_scale = 50;
    Color k2{0.1, 0.1, 0.1};
    std::optional<BumpMap> bump;
    // Image textures ("Image textures, UV coordinates, OBJ materials, environment").
    std::string texture_file, bump_file;  // as written in the scene; empty = none
    std::shared_ptr<const MipMap> image, height;
    double bump_strength = 0.3;
    TextureFilter filter = TextureFilter::kAnisotropic;
    std::optional<std::array<Vec2, 3>> corner_uv;

    bool image_texture() const { return textured && texture == kImageTexture; }

    // Whether objects of this surface and of `other` look alike in every attribute (images
    // compared by identity: the texture cache gives one file one image), so that they can share
    // one object.
    bool same_as(const SurfaceSpec& other) const;

    // The texture and bumps of an object of `material` with this surface.
    SurfaceDetail build(const Material& material) const;

    static constexpr std::string_view kImageTexture = "image";
};

// The surface attributes of an object's element; the images it names are not read here.
SurfaceSpec read_surface(Attributes& in);

}  // namespace drt
