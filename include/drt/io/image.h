// In-memory images and the image files drt reads and writes.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "drt/util/color.h"

namespace drt {

// Linear RGB floats, row 0 at the top.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;  // 3 * width * height

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(3) * w * h, 0.0f) {}
    Color at(int x, int y) const {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
    void set(int x, int y, const Color& c) {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
        rgb[i] = static_cast<float>(c.r), rgb[i + 1] = static_cast<float>(c.g),
        rgb[i + 2] = static_cast<float>(c.b);
    }
};

enum class ImageFormat { kPng, kBmp, kPfm, kExr };

// .pfm and .exr hold linear values; .png and .bmp hold 8-bit sRGB-encoded ones.
bool is_linear(ImageFormat format);

// A named value stored in the file's header. Only .exr files have a place for these; the other
// formats ignore them.
struct ImageAttribute {
    std::string name;
    std::variant<std::string, int, double> value;
};

// Channels besides R, G and B, which only .exr files hold: `names.size()` values a pixel, row by
// row, in the order of `names` (such as "albedo.R").
struct ExtraChannels {
    std::vector<std::string> names;
    std::vector<float> values;
};

struct ImageWriteOptions {
    bool half = false;  // .exr: 16-bit half floats instead of 32-bit floats
    std::vector<ImageAttribute> attributes;
    ExtraChannels extra;  // .exr only: another format with extra channels is refused
};

// A file that cannot be read, written or understood; the message names the file.
class ImageError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// The format named by the path's extension (case-insensitive); throws ImageError otherwise.
ImageFormat format_for_path(const std::filesystem::path& path);

// sRGB transfer curve of a linear value clamped to [0, 1], rounded to 8 bits.
unsigned char encode_srgb8(double linear);

// The inverse of the sRGB curve: the linear value of an encoded one in [0, 1].
double decode_srgb(double encoded);

// Writes .png/.bmp (8-bit sRGB-encoded), .pfm or .exr (linear float). The file appears complete or
// not at all: data goes to a temporary file in the same folder, which is then renamed.
void write_image(const Image& image, const std::filesystem::path& path,
                 const ImageWriteOptions& options = {});

// The bytes of an image file (at most kMaxImageFileBytes); a folder, a device, a pipe or a file
// that cannot be read throws ImageError naming the file, before any decoding.
std::vector<unsigned char> read_image_file(const std::filesystem::path& path);

// Reads .png/.bmp as stored values / 255 (still sRGB-encoded), .pfm and .exr as their floats.
Image read_image(const std::filesystem::path& path);

// One named channel of an .exr file (such as "albedo.R"), row by row.
std::vector<float> read_exr_channel(const std::filesystem::path& path, const std::string& name);

}  // namespace drt
