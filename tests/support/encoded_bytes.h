// Files encoded in memory, as stb_image_write's write-to-function callbacks fill them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "drt/util/byte_order.h"

namespace drt::testing {

using Bytes = std::vector<unsigned char>;

// An stbi_write_func: appends to the Bytes that `context` points to.
inline void append(void* context, void* data, int size) {
    const auto* p = static_cast<const unsigned char*>(data);
    static_cast<Bytes*>(context)->insert(static_cast<Bytes*>(context)->end(), p, p + size);
}

// The unsigned 32-bit number at `offset`, big-endian (PNG) and little-endian (BMP, EXR).
inline std::uint32_t be32(const std::string& s, std::size_t offset) {
    return static_cast<std::uint32_t>(
        read_big_endian(reinterpret_cast<const unsigned char*>(s.data() + offset), 4));
}
inline std::uint32_t le32(const std::string& s, std::size_t offset) {
    return static_cast<std::uint32_t>(
        read_little_endian(reinterpret_cast<const unsigned char*>(s.data() + offset), 4));
}

}  // namespace drt::testing
