#include "drt/io/image.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

#include "drt/io/exr.h"
#include "drt/io/png_chunks.h"
#include "drt/util/atomic_file.h"
#include "drt/util/byte_order.h"
#include "drt/util/file_reader.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<unsigned char>;

// Larger images are taken for corrupt headers (stb's own limit).
constexpr int kMaxSide = 1 << 24;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw ImageError(printable(path.string()) + ": " + what);
}

// ---- encoding -------------------------------------------------------------------------------

// stb's writers hand over the encoded file in pieces through this callback.
void append_to_bytes(void* context, void* data, int size) {
    const auto* p = static_cast<const unsigned char*>(data);
    static_cast<Bytes*>(context)->insert(static_cast<Bytes*>(context)->end(), p, p + size);
}

Bytes encode_8bit(const Image& image, ImageFormat format, const fs::path& path) {
    Bytes pixels(image.rgb.size());
    std::transform(image.rgb.begin(), image.rgb.end(), pixels.begin(),
                   [](float v) { return encode_srgb8(v); });
    Bytes file;
    const int ok = format == ImageFormat::kPng
                       ? stbi_write_png_to_func(append_to_bytes, &file, image.width, image.height,
                                                3, pixels.data(), 3 * image.width)
                       : stbi_write_bmp_to_func(append_to_bytes, &file, image.width, image.height,
                                                3, pixels.data());
    if (!ok) fail(path, "cannot encode image");
    return file;
}

// PFM stores rows bottom-up; a negative scale marks little-endian data, which we always write
// so the bytes do not depend on the host.
Bytes encode_pfm(const Image& image) {
    const std::string header =
        "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
    Bytes file(header.begin(), header.end());
    file.reserve(file.size() + 4 * image.rgb.size());
    const std::size_t row_floats = 3 * static_cast<std::size_t>(image.width);
    for (int y = image.height - 1; y >= 0; --y) {
        const float* row = image.rgb.data() + y * row_floats;
        for (std::size_t i = 0; i < row_floats; ++i) {
            append_little_endian(file, std::bit_cast<std::uint32_t>(row[i]), 4);
        }
    }
    return file;
}

// ---- decoding -------------------------------------------------------------------------------

bool starts_with(const Bytes& data, std::string_view magic) {
    return data.size() >= magic.size() && std::memcmp(data.data(), magic.data(), magic.size()) == 0;
}

// stb fills the missing rows of a truncated BMP with black instead of failing, so check that
// the pixel rows the header promises are all there.
bool bmp_is_truncated(const Bytes& data) {
    const auto u16 = [&](std::size_t i) { return std::uint32_t{data[i]} | data[i + 1] << 8; };
    const auto u32 = [&](std::size_t i) { return u16(i) | u16(i + 2) << 16; };
    if (data.size() < 26) return true;
    const bool core = u32(14) == 12;  // the old OS/2 header, with 16-bit fields
    if (!core && data.size() < 34) return true;
    // Compressed rows have no fixed size; stb refuses those anyway, as it does huge images.
    if (!core && u32(30) != 0 && u32(30) != 3) return false;
    const std::uint64_t w = core ? u16(18) : u32(18);
    const std::uint64_t h = core ? u16(20) : std::abs(std::int64_t{std::int32_t(u32(22))});
    const std::uint64_t bits = core ? u16(24) : u16(28);
    if (w > kMaxSide || h > kMaxSide) return false;
    const std::uint64_t row_bytes = (w * bits + 31) / 32 * 4;
    return data.size() < u32(10) + row_bytes * h;
}

Image decode_8bit(const Bytes& data, ImageFormat format, const fs::path& path) {
    // Check the signature ourselves: stb would happily decode a JPEG named .png.
    const bool is_png = format == ImageFormat::kPng;
    if (!starts_with(data, is_png ? std::string_view("\x89PNG\r\n\x1a\n", 8) : "BM")) {
        fail(path, is_png ? "not a PNG file" : "not a BMP file");
    }
    if (!is_png && bmp_is_truncated(data)) fail(path, "truncated BMP file");
    if (is_png) {
        if (const auto problem = png_chunk_past_end(data)) fail(path, *problem);
    }
    if (data.size() > static_cast<std::size_t>(INT32_MAX)) fail(path, "file too large");
    int w = 0, h = 0, channels = 0;
    // The size from the header, before stb allocates for it.
    if (stbi_info_from_memory(data.data(), static_cast<int>(data.size()), &w, &h, &channels) &&
        std::uint64_t(w) * std::uint64_t(h) > kMaxPixels) {
        fail(path, image_limit_message(w, h));
    }
    const std::unique_ptr<stbi_uc, decltype(&stbi_image_free)> pixels(
        stbi_load_from_memory(data.data(), static_cast<int>(data.size()), &w, &h, &channels, 3),
        &stbi_image_free);
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        fail(path, std::string("cannot decode image: ") + (reason ? reason : "unknown error"));
    }
    Image image(w, h);
    std::transform(pixels.get(), pixels.get() + image.rgb.size(), image.rgb.begin(),
                   [](stbi_uc v) { return static_cast<float>(v / 255.0); });
    return image;
}

// Reads the whitespace-separated tokens of a PFM header without running past the data.
class HeaderReader {
  public:
    HeaderReader(const Bytes& data, const fs::path& path) : data_(data), path_(path) {}

    std::string_view token() {
        while (pos_ < data_.size() && std::isspace(data_[pos_])) ++pos_;
        const std::size_t start = pos_;
        while (pos_ < data_.size() && !std::isspace(data_[pos_]) && pos_ - start < 32) ++pos_;
        if (pos_ == start) fail(path_, "truncated PFM header");
        return {reinterpret_cast<const char*>(data_.data()) + start, pos_ - start};
    }

    template <typename T>
    T number(const char* what) {
        std::string_view t = token();
        // from_chars takes no plus sign, which some writers put before the scale.
        if (t.starts_with('+') && !t.substr(1).starts_with('-')) t.remove_prefix(1);
        T value{};
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
        if (ec != std::errc() || end != t.data() + t.size()) {
            fail(path_, "bad PFM " + std::string(what) + " '" + std::string(t) + "'");
        }
        return value;
    }

    // Exactly one whitespace byte separates the header from the data, which may itself start
    // with bytes that look like whitespace.
    std::size_t data_start() {
        if (pos_ >= data_.size() || !std::isspace(data_[pos_])) fail(path_, "truncated PFM header");
        return pos_ + 1;
    }

  private:
    const Bytes& data_;
    const fs::path& path_;
    std::size_t pos_ = 0;
};

Image decode_pfm(const Bytes& data, const fs::path& path) {
    HeaderReader header(data, path);
    const std::string_view kind = header.token();
    if (kind != "PF" && kind != "Pf") fail(path, "not a PFM file");
    const int channels = kind == "PF" ? 3 : 1;
    const int w = header.number<int>("width");
    const int h = header.number<int>("height");
    const double scale = header.number<double>("scale");
    if (w <= 0 || h <= 0 || w > kMaxSide || h > kMaxSide) fail(path, "bad PFM size");
    if (std::uint64_t(w) * std::uint64_t(h) > kMaxPixels) fail(path, image_limit_message(w, h));
    if (scale == 0 || !std::isfinite(scale)) fail(path, "bad PFM scale");
    const std::size_t start = header.data_start();

    const std::size_t count = static_cast<std::size_t>(channels) * w * h;
    if (data.size() - start < 4 * count) fail(path, "truncated PFM data");
    // The sign of the scale gives the byte order: negative is little-endian.
    const bool little = scale < 0;
    const auto value_at = [&](std::size_t i) {
        const unsigned char* b = data.data() + start + 4 * i;
        std::uint32_t bits = 0;
        for (int k = 0; k < 4; ++k) bits |= std::uint32_t{b[little ? k : 3 - k]} << (8 * k);
        return std::bit_cast<float>(bits);
    };

    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        const std::size_t file_row = static_cast<std::size_t>(h - 1 - y) * w;  // bottom-up
        for (int x = 0; x < w; ++x) {
            float* out = image.rgb.data() + 3 * (static_cast<std::size_t>(y) * w + x);
            for (int c = 0; c < 3; ++c) out[c] = value_at(channels * (file_row + x) + c % channels);
        }
    }
    return image;
}

}  // namespace

std::vector<unsigned char> read_image_file(const fs::path& path) {
    try {
        return read_binary_file(path, kMaxImageFileBytes, FileKinds::regular_only);
    } catch (const FileReadError& e) {
        switch (e.problem()) {
            case FileProblem::cannot_open:
                fail(path, "cannot open file: " + e.reason());
            case FileProblem::cannot_read:
                fail(path, "cannot read file: " + e.reason());
            case FileProblem::is_folder:
                fail(path, "is a folder, not an image file");
            case FileProblem::not_regular_file:
                fail(path, "not a regular file");
            case FileProblem::too_large:
                break;
        }
        fail(path, "file larger than the " + std::to_string(kMaxImageFileBytes >> 20) +
                       " MiB limit for an image");
    }
}

ImageFormat format_for_path(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png") return ImageFormat::kPng;
    if (ext == ".bmp") return ImageFormat::kBmp;
    if (ext == ".pfm") return ImageFormat::kPfm;
    if (ext == ".exr") return ImageFormat::kExr;
    fail(path, "unsupported image format '" + path.extension().string() +
                   "' (use .png, .bmp, .pfm or .exr)");
}

bool is_linear(ImageFormat format) {
    return format == ImageFormat::kPfm || format == ImageFormat::kExr;
}

unsigned char encode_srgb8(double linear) {
    const double v = std::isnan(linear) ? 0.0 : std::clamp(linear, 0.0, 1.0);
    const double encoded = v < 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    return static_cast<unsigned char>(std::lround(encoded * 255));
}

double decode_srgb(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

void write_image(const Image& image, const fs::path& path, const ImageWriteOptions& options) {
    const ImageFormat format = format_for_path(path);
    if (image.width <= 0 || image.height <= 0) fail(path, "cannot write an empty image");
    if (image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
        fail(path, "image data does not match its size");
    }
    if (!options.extra.names.empty() && format != ImageFormat::kExr) {
        fail(path, "only an .exr file holds channels besides R, G and B");
    }
    if (options.extra.values.size() !=
        options.extra.names.size() * static_cast<std::size_t>(image.width) * image.height) {
        fail(path, "extra channel data does not match the image's size");
    }
    const Bytes file = format == ImageFormat::kPfm   ? encode_pfm(image)
                       : format == ImageFormat::kExr ? encode_exr(image, options, path)
                                                     : encode_8bit(image, format, path);
    try {
        replace_file(path, file);
    } catch (const FileWriteError& e) {
        throw ImageError(e.what());
    }
}

std::vector<float> read_exr_channel(const fs::path& path, const std::string& name) {
    return decode_exr_channel(read_image_file(path), name, path);
}

Image read_image(const fs::path& path) {
    const ImageFormat format = format_for_path(path);
    const Bytes data = read_image_file(path);
    switch (format) {
        case ImageFormat::kPfm:
            return decode_pfm(data, path);
        case ImageFormat::kExr:
            return decode_exr(data, path);
        default:
            return decode_8bit(data, format, path);
    }
}

}  // namespace drt
