// Unsigned numbers as bytes in a stated order whatever the host's, so that files and messages
// written on one machine read the same on another: drt's own in little-endian, PNG's in big.
#pragma once

#include <cstdint>
#include <vector>

namespace drt {

// Appends the low `width` bytes of `value`, lowest first.
inline void append_little_endian(std::vector<unsigned char>& out, std::uint64_t value, int width) {
    for (int i = 0; i < width; ++i) out.push_back(static_cast<unsigned char>(value >> (8 * i)));
}

// The number in the `width` bytes at `bytes`, lowest first.
inline std::uint64_t read_little_endian(const unsigned char* bytes, int width) {
    std::uint64_t value = 0;
    for (int i = 0; i < width; ++i) value |= std::uint64_t{bytes[i]} << (8 * i);
    return value;
}

// The number in the `width` bytes at `bytes`, highest first.
inline std::uint64_t read_big_endian(const unsigned char* bytes, int width) {
    std::uint64_t value = 0;
    for (int i = 0; i < width; ++i) value = value << 8 | bytes[i];
    return value;
}

}  // namespace drt
