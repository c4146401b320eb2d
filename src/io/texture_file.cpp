#include "drt/io/texture_file.h"

#include <stb_image.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

#include "drt/io/exr.h"
#include "drt/io/png_chunks.h"
#include "drt/util/byte_order.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<unsigned char>;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw ImageError(printable(path.string()) + ": " + what);
}

bool starts_with(const Bytes& data, std::string_view magic) {
    return data.size() >= magic.size() && std::memcmp(data.data(), magic.data(), magic.size()) == 0;
}

enum class Kind { kPng, kJpeg, kBmp, kTga, kHdr, kExr };

// The format from the file's first bytes. TGA has no signature: a file none of the others claim
// is taken for one if stb's TGA header check accepts it.
Kind kind_of(const Bytes& data, const fs::path& path) {
    if (starts_with(data, std::string_view("\x89PNG\r\n\x1a\n", 8))) return Kind::kPng;
    if (starts_with(data, "\xff\xd8\xff")) return Kind::kJpeg;
    if (starts_with(data, "BM")) return Kind::kBmp;
    if (starts_with(data, "#?RADIANCE") || starts_with(data, "#?RGBE")) return Kind::kHdr;
    if (starts_with(data, "\x76\x2f\x31\x01")) return Kind::kExr;
    int w = 0, h = 0, channels = 0;
    if (data.size() >= 18 &&
        stbi_info_from_memory(data.data(), static_cast<int>(data.size()), &w, &h, &channels))
        return Kind::kTga;
    fail(path, "not a PNG, JPEG, BMP, TGA, Radiance HDR or OpenEXR image");
}

// stb reads through these callbacks and sees a zero byte past the end of the data, which for
// several formats decodes a truncated file as black pixels instead of failing; the reader
// remembers being asked for bytes that are not there.
struct CallbackReader {
    const Bytes& data;
    std::size_t pos = 0;
    bool past_end = false;

    static int read(void* user, char* out, int size) {
        auto& r = *static_cast<CallbackReader*>(user);
        const std::size_t left = r.data.size() - r.pos;
        const std::size_t n = std::min(left, static_cast<std::size_t>(size));
        if (n == 0 && size > 0) r.past_end = true;
        std::memcpy(out, r.data.data() + r.pos, n);
        r.pos += n;
        return static_cast<int>(n);
    }
    static void skip(void* user, int n) {
        auto& r = *static_cast<CallbackReader*>(user);
        if (n < 0) {
            r.pos -= std::min(r.pos, static_cast<std::size_t>(-static_cast<long long>(n)));
            return;
        }
        if (static_cast<std::size_t>(n) > r.data.size() - r.pos) r.past_end = true;
        r.pos = std::min(r.data.size(), r.pos + static_cast<std::size_t>(n));
    }
    static int eof(void* user) {
        const auto& r = *static_cast<CallbackReader*>(user);
        return r.pos >= r.data.size() ? 1 : 0;
    }
};

const char* name_of(Kind kind) {
    switch (kind) {
        case Kind::kPng:
            return "PNG";
        case Kind::kJpeg:
            return "JPEG";
        case Kind::kBmp:
            return "BMP";
        case Kind::kTga:
            return "TGA";
        case Kind::kHdr:
            return "Radiance HDR";
        case Kind::kExr:
            return "OpenEXR";
    }
    return "image";
}

// The most pixels one byte of a valid file can carry, from each format's densest encoding.
std::uint64_t densest_pixels_per_byte(Kind kind) {
    switch (kind) {
        case Kind::kPng:
            return 8 * 1032;  // 1-bit pixels, deflate's 1032:1 at best
        case Kind::kJpeg:
            return 64 * 8;  // at least one bit per 8x8 block
        case Kind::kBmp:
            return 8;  // stb reads only uncompressed rows: 1 bit per pixel
        case Kind::kTga:
            return 64;  // a run of 128 pixels takes a count and a 1-byte pixel
        case Kind::kHdr:
            return 16;  // a run of 127 pixels' values of one of their 4 bytes takes 2 bytes
        case Kind::kExr:
            break;  // read by OpenEXR, never by stb
    }
    return 0;
}

using StbPixels = std::unique_ptr<void, decltype(&stbi_image_free)>;

// Linear value of every 8-bit code under the sRGB curve, or code / 255 for data.
std::array<float, 256> table_8bit(TextureEncoding encoding) {
    std::array<float, 256> table{};
    for (int i = 0; i < 256; ++i) {
        const double v = i / 255.0;
        table[static_cast<std::size_t>(i)] =
            static_cast<float>(encoding == TextureEncoding::kColor ? decode_srgb(v) : v);
    }
    return table;
}

Image decode_stb(const Bytes& data, const fs::path& path, Kind kind, TextureEncoding encoding) {
    if (data.size() > static_cast<std::size_t>(INT32_MAX)) fail(path, "file too large");
    const int size = static_cast<int>(data.size());
    const auto check_size = [&](std::uint64_t w, std::uint64_t h) {
        if (past_image_limits(w, h)) fail(path, image_limit_message(w, h));
    };
    // stb refuses a huge PNG from its header too, but says only "too large": read the size.
    if (kind == Kind::kPng && data.size() >= 24) {
        check_size(read_big_endian(data.data() + 16, 4), read_big_endian(data.data() + 20, 4));
        if (const auto problem = png_chunk_past_end(data)) fail(path, *problem);
    }
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(data.data(), size, &w, &h, &channels) || w <= 0 || h <= 0) {
        const char* reason = stbi_failure_reason();
        fail(path, std::string("cannot decode image header: ") +
                       (reason && *reason ? reason : "corrupt"));
    }
    // The size from the header alone, before stb allocates for it.
    check_size(static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h));
    // stb decodes a file that ends early to the image's last pixel, reading zeros past the end:
    // a 69-byte Radiance file claiming 40000x3000 pixels took 8 s to refuse, and a 664-byte
    // JPEG claiming 65535x2048 decoded as grey. A header that promises more pixels than the
    // format's densest encoding fits in the file is refused before any decoding.
    if (static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) >
        densest_pixels_per_byte(kind) * data.size()) {
        fail(path, std::string(name_of(kind)) + " image of " + std::to_string(w) + "x" +
                       std::to_string(h) + " pixels cannot fit in " + std::to_string(data.size()) +
                       " bytes: the file is truncated or corrupt");
    }
    CallbackReader reader{data};
    const stbi_io_callbacks callbacks{&CallbackReader::read, &CallbackReader::skip,
                                      &CallbackReader::eof};
    const bool hdr = kind == Kind::kHdr;
    const bool wide = !hdr && stbi_is_16_bit_from_memory(data.data(), size);
    StbPixels pixels(nullptr, &stbi_image_free);
    const bool alpha = encoding == TextureEncoding::kAlpha;
    const int wanted = alpha ? 4 : 3;
    if (hdr) {
        pixels.reset(stbi_loadf_from_callbacks(&callbacks, &reader, &w, &h, &channels, wanted));
    } else if (wide) {
        pixels.reset(stbi_load_16_from_callbacks(&callbacks, &reader, &w, &h, &channels, wanted));
    } else {
        pixels.reset(stbi_load_from_callbacks(&callbacks, &reader, &w, &h, &channels, wanted));
    }
    if (!pixels) {
        // A file cut short often leaves stb no reason to give.
        if (reader.past_end) fail(path, "truncated image file");
        const char* reason = stbi_failure_reason();
        fail(path, std::string("cannot decode image: ") +
                       (reason && *reason ? reason : "corrupt image data"));
    }
    if (reader.past_end) fail(path, "truncated image file");
    Image image(w, h);
    if (alpha) {
        const auto value = [&](std::size_t i) -> double {
            if (hdr) return static_cast<const float*>(pixels.get())[i];
            if (wide) return static_cast<const stbi_us*>(pixels.get())[i] / 65535.0;
            return static_cast<const stbi_uc*>(pixels.get())[i] / 255.0;
        };
        // Grey with alpha, or colour with alpha: the alpha channel; otherwise the luminance.
        const bool has_alpha = channels == 2 || channels == 4;
        for (std::size_t p = 0; p < static_cast<std::size_t>(w) * h; ++p) {
            const double a = has_alpha
                                 ? value(4 * p + 3)
                                 : luminance({value(4 * p), value(4 * p + 1), value(4 * p + 2)});
            const auto x = static_cast<int>(p % static_cast<std::size_t>(w));
            image.set(x, static_cast<int>(p / static_cast<std::size_t>(w)), {a, a, a});
        }
    } else if (hdr) {
        const float* p = static_cast<const float*>(pixels.get());
        std::copy(p, p + image.rgb.size(), image.rgb.begin());
    } else if (wide) {
        const auto* p = static_cast<const stbi_us*>(pixels.get());
        std::transform(p, p + image.rgb.size(), image.rgb.begin(), [&](stbi_us v) {
            const double x = v / 65535.0;
            return static_cast<float>(encoding == TextureEncoding::kColor ? decode_srgb(x) : x);
        });
    } else {
        const std::array<float, 256> table = table_8bit(encoding);
        const auto* p = static_cast<const stbi_uc*>(pixels.get());
        std::transform(p, p + image.rgb.size(), image.rgb.begin(),
                       [&](stbi_uc v) { return table[v]; });
    }
    for (const float v : image.rgb) {
        if (!std::isfinite(v)) fail(path, "image holds a value that is not a finite number");
    }
    return image;
}

}  // namespace

Image decode_texture(const Bytes& data, const fs::path& path, TextureEncoding encoding) {
    const Kind kind = kind_of(data, path);
    if (kind != Kind::kExr) return decode_stb(data, path, kind, encoding);
    Image image = decode_exr(data, path);
    if (encoding == TextureEncoding::kAlpha) {
        for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
            const auto a =
                static_cast<float>(luminance({image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]}));
            image.rgb[i] = image.rgb[i + 1] = image.rgb[i + 2] = a;
        }
    }
    for (const float v : image.rgb) {
        if (!std::isfinite(v)) fail(path, "image holds a value that is not a finite number");
    }
    return image;
}

Image read_texture(const fs::path& path, TextureEncoding encoding) {
    return decode_texture(read_image_file(path), path, encoding);
}

}  // namespace drt
