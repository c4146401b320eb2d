#include "drt/io/png_chunks.h"

#include <cstdint>

#include "drt/util/byte_order.h"
#include "drt/util/text.h"

namespace drt {

std::optional<std::string> png_chunk_past_end(std::span<const unsigned char> file) {
    // Each chunk: a big-endian length, a 4-letter type, the data, a CRC.
    std::size_t at = 8;
    while (at + 8 <= file.size()) {
        const std::uint64_t length = read_big_endian(file.data() + at, 4);
        const std::string type(reinterpret_cast<const char*>(file.data() + at + 4), 4);
        if (length > file.size() - (at + 8)) {
            return "PNG chunk " + printable(type) + " claims " + std::to_string(length) +
                   " bytes, more than the file holds";
        }
        if (type == "IEND") break;
        at += 12 + length;
    }
    return std::nullopt;
}

}  // namespace drt
