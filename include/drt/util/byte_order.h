// Unsigned numbers as bytes in a stated order whatever the host's, so that files and messages
// written on one machine read the same on another: drt's own in little-endian, PNG's in big.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
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

// Little-endian numbers read one after another from the front of `bytes`. A read past the end
// calls `on_short` first, which must throw: each format says "truncated" in its own words.
template <class OnShort>
class ByteReader {
  public:
    ByteReader(std::span<const unsigned char> bytes, OnShort on_short)
        : bytes_(bytes), on_short_(on_short) {}
    std::uint32_t u32() { return static_cast<std::uint32_t>(get(4)); }
    std::uint64_t u64() { return get(8); }
    float f32() { return std::bit_cast<float>(u32()); }
    double f64() { return std::bit_cast<double>(u64()); }
    // The next n bytes as they are.
    std::span<const unsigned char> take(std::size_t n) {
        need(n);
        const auto taken = bytes_.subspan(pos_, n);
        pos_ += n;
        return taken;
    }
    void need(std::size_t n) const {
        if (rest().size() < n) on_short_();
    }
    std::span<const unsigned char> rest() const { return bytes_.subspan(pos_); }

  private:
    std::uint64_t get(int size) {
        return read_little_endian(take(static_cast<std::size_t>(size)).data(), size);
    }
    std::span<const unsigned char> bytes_;
    OnShort on_short_;
    std::size_t pos_ = 0;
};

}  // namespace drt
