#include "drt/io/exr_header.h"

#include <algorithm>
#include <cstdint>
#include <string_view>

#include "drt/util/byte_order.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace {

// The bytes OpenEXR 3.1 reads for a value of these types, whatever size the file declares for
// it: a file that declares another size sends the reader on among the value's bytes as though
// they were the next attribute's name, so the walk must follow the reader, not the sizes.
std::optional<std::uint64_t> fixed_size(std::string_view type) {
    struct Fixed {
        std::string_view type;
        std::uint64_t bytes;
    };
    static constexpr Fixed kFixed[] = {
        {"box2f", 16},
        {"box2i", 16},
        {"chromaticities", 32},
        {"compression", 1},
        {"deepImageState", 1},
        {"double", 8},
        {"envmap", 1},
        {"float", 4},
        {"int", 4},
        {"keycode", 28},
        {"lineOrder", 1},
        {"m33d", 72},
        {"m33f", 36},
        {"m44d", 128},
        {"m44f", 64},
        {"rational", 8},
        {"tiledesc", 9},
        {"timecode", 8},
        {"v2d", 16},
        {"v2f", 8},
        {"v2i", 8},
        {"v3d", 24},
        {"v3f", 12},
        {"v3i", 12},
    };
    for (const Fixed& f : kFixed) {
        if (f.type == type) return f.bytes;
    }
    return std::nullopt;
}

// A name as OpenEXR reads it: at most 255 bytes and a terminating zero; its length, or nothing
// where OpenEXR refuses it (or the file ends first).
std::optional<std::size_t> name_length(std::span<const unsigned char> file, std::size_t at) {
    if (at >= file.size()) return std::nullopt;
    const auto begin = file.begin() + static_cast<std::ptrdiff_t>(at);
    const auto end = file.begin() + static_cast<std::ptrdiff_t>(std::min(file.size(), at + 256));
    const auto zero = std::find(begin, end, 0);
    if (zero == end) return std::nullopt;
    return static_cast<std::size_t>(zero - begin);
}

std::int64_t signed32(std::span<const unsigned char> file, std::size_t at) {
    return static_cast<std::int32_t>(read_little_endian(&file[at], 4));
}

// A channel list: entries of a name, a pixel type, flags and sampling (16 bytes), up to an empty
// name; OpenEXR reads it to its end whatever size is declared.
struct ChannelList {
    std::uint64_t size = 0;         // the bytes OpenEXR reads
    std::uint64_t pixel_bytes = 0;  // all channels' bytes a pixel, as if none were subsampled
};

std::optional<ChannelList> channel_list(std::span<const unsigned char> file, std::size_t at) {
    ChannelList list;
    std::size_t p = at;
    while (true) {
        const auto length = name_length(file, p);
        if (!length) return std::nullopt;
        p += *length + 1;
        if (*length == 0) break;
        if (p + 16 > file.size()) return std::nullopt;
        list.pixel_bytes += signed32(file, p) == 1 ? 2 : 4;  // half, else uint or float
        p += 16;
    }
    list.size = p - at;
    return list;
}

// The scan lines in one block of each compression (0 = none, 1 RLE, 2 ZIPS, 3 ZIP, 4 PIZ,
// 5 PXR24, 6 B44, 7 B44A, 8 DWAA, 9 DWAB); OpenEXR refuses any other.
std::uint64_t lines_per_block(int compression) {
    static constexpr std::uint64_t kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    return compression >= 0 && compression < 10 ? kLines[compression] : 256;
}

// What one header declares about its pixels (OpenEXR's defaults where it declares nothing).
struct Layout {
    std::optional<std::pair<std::int64_t, std::int64_t>> size;  // of the data window
    std::uint64_t pixel_bytes = 0;
    int compression = 0;
    std::optional<std::pair<std::uint64_t, std::uint64_t>> tile;

    std::optional<std::string> problem() const {
        if (!size) return std::nullopt;
        const auto [w, h] = *size;
        if (w <= 0 || h <= 0) return std::nullopt;  // OpenEXR's to refuse
        if (past_image_limits(w, h)) return image_limit_message(w, h);
        const std::uint64_t pixels =
            tile ? tile->first * tile->second
                 : static_cast<std::uint64_t>(w) * lines_per_block(compression);
        // Tiles up to 2^32 a side: compare without overflowing.
        if (pixel_bytes > 0 && pixels > kMaxExrBlockBytes / pixel_bytes) {
            const std::string block = tile ? "a tile of " + std::to_string(tile->first) + "x" +
                                                 std::to_string(tile->second) + " pixels"
                                           : std::to_string(lines_per_block(compression)) +
                                                 " lines of " + std::to_string(w) + " pixels";
            return "OpenEXR block of " + block + " at " + std::to_string(pixel_bytes) +
                   " bytes a pixel exceeds the limit of " + std::to_string(kMaxExrBlockBytes) +
                   " bytes";
        }
        return std::nullopt;
    }
};

}  // namespace

std::optional<std::string> exr_header_problem(std::span<const unsigned char> file) {
    if (file.size() < 8) return std::nullopt;
    const bool multipart = (file[5] & 0x10) != 0;  // version flag 0x1000
    std::size_t at = 8;
    Layout layout;
    while (at < file.size()) {
        const auto name = name_length(file, at);
        if (!name) return std::nullopt;
        if (*name == 0) {  // the end of a header
            if (auto problem = layout.problem()) return problem;
            layout = {};
            ++at;
            if (!multipart || at >= file.size() || file[at] == 0) return std::nullopt;
            continue;
        }
        const std::size_t type_at = at + *name + 1;
        const auto type_length = name_length(file, type_at);
        if (!type_length) return std::nullopt;
        const std::size_t size_at = type_at + *type_length + 1;
        if (size_at + 4 > file.size()) return std::nullopt;
        const std::int64_t declared = signed32(file, size_at);
        if (declared < 0) return std::nullopt;
        const std::size_t value = size_at + 4;
        const std::uint64_t left = file.size() - value;
        const std::string_view name_view(reinterpret_cast<const char*>(&file[at]), *name);
        const std::string_view type(reinterpret_cast<const char*>(&file[type_at]), *type_length);
        const auto claims = [&](const std::string& what) {
            return "OpenEXR attribute " + printable(name_view) + " claims " + what +
                   ", more than the file holds";
        };

        // What OpenEXR reserves for the value, and how far it reads.
        std::uint64_t reserved = 0, read = static_cast<std::uint64_t>(declared);
        if (const auto fixed = fixed_size(type)) {
            read = *fixed;
            if (left < read) return std::nullopt;  // OpenEXR's to refuse
            if (name_view == "dataWindow" && type == "box2i") {
                layout.size = {signed32(file, value + 8) - signed32(file, value) + 1,
                               signed32(file, value + 12) - signed32(file, value + 4) + 1};
            } else if (name_view == "compression" && type == "compression") {
                layout.compression = file[value];
            } else if (name_view == "tiles" && type == "tiledesc") {
                layout.tile = {read_little_endian(&file[value], 4),
                               read_little_endian(&file[value + 4], 4)};
            }
        } else if (type == "chlist") {
            const auto list = channel_list(file, value);
            if (!list) return std::nullopt;
            read = list->size;
            if (name_view == "channels") layout.pixel_bytes = list->pixel_bytes;
        } else if (type == "preview") {  // width and height, then 4 bytes a pixel
            if (left < 8) return std::nullopt;
            const std::uint64_t w = read_little_endian(&file[value], 4);
            const std::uint64_t h = read_little_endian(&file[value + 4], 4);
            if (w * h > (left - 8) / 4) {
                return claims("a preview of " + std::to_string(w) + "x" + std::to_string(h) +
                              " pixels");
            }
            reserved = 4 * w * h;
            read = 8 + reserved;
        } else if (type == "floatvector") {
            reserved = read = read / 4 * 4;
        } else {  // string, stringvector, idmanifest and any type OpenEXR does not know
            reserved = read;
        }
        if (reserved > left) return claims(std::to_string(reserved) + " bytes");
        at = value + read;
    }
    return std::nullopt;
}

}  // namespace drt
