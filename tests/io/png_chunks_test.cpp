#include "drt/io/png_chunks.h"

#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <iterator>
#include <string>
#include <vector>

#include "encoded_bytes.h"

namespace drt {
namespace {

using testing::append;
using testing::Bytes;

// stb's 3 x 2 RGB PNG: signature, IHDR (bytes 8-32), IDAT from byte 33, IEND (the last 12).
Bytes small_png() {
    const unsigned char rgb[18] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18};
    Bytes png;
    stbi_write_png_to_func(append, &png, 3, 2, 3, rgb, 9);
    return png;
}

void set_be32(Bytes& bytes, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<unsigned char>(v >> (24 - 8 * i));
}

TEST(PngChunks, AWholeFileHasNoChunkPastItsEnd) {
    EXPECT_EQ(png_chunk_past_end(small_png()), std::nullopt);
}

// The IDAT's data may reach the file's last byte (stb does not read the CRC), not one further.
TEST(PngChunks, AChunkLongerThanTheRestOfTheFileIsNamedWithItsLength) {
    Bytes png = small_png();
    const std::size_t idat = 33;
    ASSERT_EQ(std::string(png.begin() + idat + 4, png.begin() + idat + 8), "IDAT");
    const auto rest = static_cast<std::uint32_t>(png.size() - (idat + 8));
    set_be32(png, idat, rest);
    EXPECT_EQ(png_chunk_past_end(png), std::nullopt);
    set_be32(png, idat, rest + 1);
    EXPECT_EQ(png_chunk_past_end(png), "PNG chunk IDAT claims " + std::to_string(rest + 1) +
                                           " bytes, more than the file holds");
    set_be32(png, idat, 0xFFFFFFFF);
    EXPECT_EQ(png_chunk_past_end(png),
              "PNG chunk IDAT claims 4294967295 bytes, more than the file holds");
}

// Bytes after IEND are not chunks; a type that is not text is shown escaped.
TEST(PngChunks, OnlyChunksUpToIendAreReadAndOddTypesAreEscaped) {
    Bytes png = small_png();
    const unsigned char junk[] = {0xFF, 0xFF, 0xFF, 0xFF, 'J', 'U', 'N', 'K'};
    png.insert(png.end(), std::begin(junk), std::end(junk));
    EXPECT_EQ(png_chunk_past_end(png), std::nullopt);

    Bytes odd = small_png();
    odd[33 + 4] = '\n';
    set_be32(odd, 33, 1000);
    EXPECT_EQ(png_chunk_past_end(odd),
              std::string("PNG chunk \\x0aDAT claims 1000 bytes, more than the file holds"));
}

}  // namespace
}  // namespace drt
