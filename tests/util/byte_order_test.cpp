#include "drt/util/byte_order.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <stdexcept>
#include <string>
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

TEST(ByteOrder, AReaderTakesFieldsInTurnAndCallsItsHandlerBeforeReadingPastTheEnd) {
    std::vector<unsigned char> bytes;
    append_little_endian(bytes, 7, 4);
    append_little_endian(bytes, std::bit_cast<std::uint64_t>(-2.5), 8);
    append_little_endian(bytes, std::bit_cast<std::uint32_t>(0.25f), 4);
    bytes.insert(bytes.end(), {'a', 'b', 'c'});
    int short_reads = 0;
    ByteReader r(bytes, [&] {
        ++short_reads;
        throw std::out_of_range("short");
    });
    EXPECT_EQ(r.u32(), 7u);
    EXPECT_EQ(r.f64(), -2.5);
    EXPECT_EQ(r.f32(), 0.25f);
    EXPECT_EQ(r.rest().size(), 3u);
    EXPECT_THROW(r.u32(), std::out_of_range);  // three bytes left: nothing is read
    EXPECT_EQ(short_reads, 1);
    const auto text = r.take(3);
    EXPECT_EQ(std::string(text.begin(), text.end()), "abc");
    EXPECT_THROW(r.take(1), std::out_of_range);
    EXPECT_EQ(short_reads, 2);
}

}  // namespace
}  // namespace drt
