// Image files read as textures: PNG, JPEG, BMP, TGA, Radiance HDR and OpenEXR, told apart by
// their contents rather than their names, decoded to linear RGB.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "drt/io/image.h"

namespace drt {

// How an image's 8- or 16-bit values are meant: colours are sRGB-encoded (decoded to linear),
// data such as a height map is linear already. HDR and EXR files hold linear floats either way.
// An alpha map (MTL map_d) is the image's alpha channel where it has one, else the luminance of
// its linear values, in all three channels.
enum class TextureEncoding { kColor, kData, kAlpha };

// Decodes a texture file held in memory into linear RGB (row 0 at the top), its pixels refused
// past kMaxPixels from the header alone, before anything is allocated for them. Throws
// ImageError naming `path` for anything unreadable: an unknown format, a corrupt or truncated
// file, a hostile size.
Image decode_texture(const std::vector<unsigned char>& data, const std::filesystem::path& path,
                     TextureEncoding encoding);

// Reads and decodes the texture file at `path` (see decode_texture).
Image read_texture(const std::filesystem::path& path, TextureEncoding encoding);

}  // namespace drt
