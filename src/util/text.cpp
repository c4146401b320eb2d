#include "drt/util/text.h"

#include <cstdio>

namespace drt {

namespace {

void append_hex(std::string& out, unsigned char byte) {
    char buffer[8];
    std::snprintf(buffer, sizeof buffer, "\\x%02x", byte);
    out += buffer;
}

// How many bytes the well-formed UTF-8 sequence starting at text[i] takes (RFC 3629: no overlong
// forms, no surrogates, nothing past U+10FFFF), or 0 when none starts there.
std::size_t utf8_length(std::string_view text, std::size_t i) {
    const auto at = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char lead = at(i);
    std::size_t n = 0;
    unsigned char low = 0x80, high = 0xbf;  // the second byte's range
    if (lead >= 0xc2 && lead <= 0xdf) {
        n = 2;
    } else if (lead >= 0xe0 && lead <= 0xef) {
        n = 3;
        if (lead == 0xe0) low = 0xa0;
        if (lead == 0xed) high = 0x9f;
    } else if (lead >= 0xf0 && lead <= 0xf4) {
        n = 4;
        if (lead == 0xf0) low = 0x90;
        if (lead == 0xf4) high = 0x8f;
    }
    if (n == 0 || i + n > text.size() || at(i + 1) < low || at(i + 1) > high) return 0;
    for (std::size_t k = 2; k < n; ++k) {
        if (at(i + k) < 0x80 || at(i + k) > 0xbf) return 0;
    }
    return n;
}

}  // namespace

std::string printable(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto byte = static_cast<unsigned char>(text[i]);
        if (byte < 0x20 || byte == 0x7f) {
            append_hex(out, byte);
        } else if (byte == '\\') {
            out += "\\\\";
        } else if (byte < 0x80) {
            out += text[i];
        } else if (const std::size_t n = utf8_length(text, i);
                   n > 0 && !(byte == 0xc2 && static_cast<unsigned char>(text[i + 1]) <= 0x9f)) {
            out.append(text.substr(i, n));
            i += n - 1;
        } else {
            // A C1 control as UTF-8 encodes it, or a byte of no character, which a terminal in
            // an 8-bit mode may take for one (0x9b is CSI).
            append_hex(out, byte);
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
