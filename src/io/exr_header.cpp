#include "drt/io/exr_header.h"

#include <algorithm>
#include <cstdint>
#include <string_view>

#include "drt/util/little_endian.h"
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
    const std::size_t end = std::min(file.size(), at + 256);
    const auto zero = std::find(file.begin() + static_cast<std::ptrdiff_t>(at),
                                file.begin() + static_cast<std::ptrdiff_t>(end), 0);
    if (zero == file.begin() + static_cast<std::ptrdiff_t>(end)) return std::nullopt;
    return static_cast<std::size_t>(zero - (file.begin() + static_cast<std::ptrdiff_t>(at)));
}

// A channel list: entries of a name and 16 bytes, up to an empty name; OpenEXR reads it to its
// end whatever size is declared. The bytes it reads, or nothing where the file ends first.
std::optional<std::uint64_t> channel_list_size(std::span<const unsigned char> file,
                                               std::size_t at) {
    std::size_t p = at;
    while (true) {
        const auto length = name_length(file, p);
        if (!length) return std::nullopt;
        p += *length + 1;
        if (*length == 0) return p - at;
        p += 16;
    }
}

}  // namespace

std::optional<std::string> exr_attribute_past_end(std::span<const unsigned char> file) {
    if (file.size() < 8) return std::nullopt;
    const bool multipart = (file[5] & 0x10) != 0;  // version flag 0x1000
    std::size_t at = 8;
    while (at < file.size()) {
        const auto name = name_length(file, at);
        if (!name) return std::nullopt;
        if (*name == 0) {  // the end of a header
            ++at;
            if (!multipart || at >= file.size() || file[at] == 0) return std::nullopt;
            continue;
        }
        const std::size_t type_at = at + *name + 1;
        const auto type_length = name_length(file, type_at);
        if (!type_length) return std::nullopt;
        const std::size_t size_at = type_at + *type_length + 1;
        if (size_at + 4 > file.size()) return std::nullopt;
        const auto declared = static_cast<std::int32_t>(read_little_endian(&file[size_at], 4));
        if (declared < 0) return std::nullopt;
        const std::size_t value = size_at + 4;
        const std::uint64_t left = file.size() - value;
        const std::string_view type(reinterpret_cast<const char*>(&file[type_at]), *type_length);
        const auto name_text = [&] {
            return printable(std::string(reinterpret_cast<const char*>(&file[at]), *name));
        };

        // What OpenEXR reserves for the value, and how far it reads.
        std::uint64_t reserved = 0, read = static_cast<std::uint64_t>(declared);
        if (const auto fixed = fixed_size(type)) {
            read = *fixed;
        } else if (type == "chlist") {
            const auto size = channel_list_size(file, value);
            if (!size) return std::nullopt;
            read = *size;
        } else if (type == "preview") {  // width and height, then 4 bytes a pixel
            if (left < 8) return std::nullopt;
            const std::uint64_t w = read_little_endian(&file[value], 4);
            const std::uint64_t h = read_little_endian(&file[value + 4], 4);
            if (w * h > (left - 8) / 4) {
                return "OpenEXR attribute " + name_text() + " claims a preview of " +
                       std::to_string(w) + "x" + std::to_string(h) +
                       " pixels, more than the file holds";
            }
            reserved = 4 * w * h;
            read = 8 + reserved;
        } else if (type == "floatvector") {
            reserved = read = declared / 4 * 4;
        } else {  // string, stringvector, idmanifest and any type OpenEXR does not know
            reserved = read;
        }
        if (reserved > left) {
            return "OpenEXR attribute " + name_text() + " claims " + std::to_string(reserved) +
                   " bytes, more than the file holds";
        }
        at = value + read;
    }
    return std::nullopt;
}

}  // namespace drt
