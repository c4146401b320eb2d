// OpenEXR files: linear RGB in half or 32-bit float channels, with header attributes that say how
// the image was made. image.h dispatches to these by extension.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "drt/io/image.h"

namespace drt {

// The whole .exr file in memory (scan lines, ZIP compression), so that write_image can write it
// atomically like every other format. Throws ImageError naming `path` if OpenEXR refuses.
std::vector<unsigned char> encode_exr(const Image& image, const ImageWriteOptions& options,
                                      const std::filesystem::path& path);

// Reads the R, G and B channels (or Y alone, as grey) of the first part of an .exr file in
// memory, whatever their stored type. Anything OpenEXR cannot read becomes an ImageError that
// names `path`.
Image decode_exr(const std::vector<unsigned char>& data, const std::filesystem::path& path);

// One named channel (such as "depth.Z") of the first part, row by row, as floats; an ImageError
// naming `path` if the file has no such channel.
std::vector<float> decode_exr_channel(const std::vector<unsigned char>& data,
                                      const std::string& name, const std::filesystem::path& path);

}  // namespace drt
