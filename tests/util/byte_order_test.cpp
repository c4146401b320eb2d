#include "drt/util/byte_order.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace drt {
namespace {

TEST(ByteOrder, AChunkLengthReadsHighestByteFirst) {
    // IHDR's length as every PNG stores it, and bytes whose two orders read differently.
    const unsigned char ihdr[] = {0x00, 0x00, 0x00, 0x0d};
    EXPECT_EQ(read_big_endian(ihdr, 4), 13u);
    const unsigned char mixed[] = {0x52, 0x00, 0x00, 0x18};
    EXPECT_EQ(read_big_endian(mixed, 4), 0x52000018u);
    EXPECT_EQ(read_little_endian(mixed, 4), 0x18000052u);
}

TEST(ByteOrder, LittleEndianRoundTripsEveryWidth) {
    const std::uint64_t value = 0x0123456789abcdefu;
    for (int width = 1; width <= 8; ++width) {
        std::vector<unsigned char> bytes;
        append_little_endian(bytes, value, width);
        ASSERT_EQ(bytes.size(), std::size_t(width));
        const std::uint64_t mask =
            width == 8 ? ~std::uint64_t{0} : (std::uint64_t{1} << (8 * width)) - 1;
        EXPECT_EQ(read_little_endian(bytes.data(), width), value & mask) << width;
        EXPECT_EQ(bytes[0], 0xef);
    }
}

}  // namespace
}  // namespace drt
