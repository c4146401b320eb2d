#include "drt/util/text.h"

#include <cstdio>

namespace drt {

namespace {

void append_hex(std::string& out, unsigned char byte) {
    char buffer[8];
    std::snprintf(buffer, sizeof buffer, "\\x%02x", byte);
    out += buffer;
}

}  // namespace

std::string printable(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto byte = static_cast<unsigned char>(text[i]);
        if (byte < 0x20 || byte == 0x7f) {
            append_hex(out, byte);
        } else if (byte == 0xc2 && i + 1 < text.size() &&
                   static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
                   static_cast<unsigned char>(text[i + 1]) <= 0x9f) {
            append_hex(out, byte);
            append_hex(out, static_cast<unsigned char>(text[++i]));
        } else if (byte == '\\') {
            out += "\\\\";
        } else {
            out += text[i];
        }
    }
    return out;
}

std::string abbreviated(std::string_view text) {
    constexpr std::size_t kLongest = 24, kKept = 20;
    if (text.size() <= kLongest) return std::string(text);
    return std::string(text.substr(0, kKept)) + "... (" + std::to_string(text.size()) +
           " characters)";
}

std::string short_number(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", value);
    return buffer;
}

}  // namespace drt
