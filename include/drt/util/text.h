// Safe text for messages: whatever a user feeds in (scene values, file names) is shown with its
// control characters escaped, and numbers in a short form.
#pragma once

#include <string>
#include <string_view>

namespace drt {

// `text` with every byte a terminal would act on rather than show escaped as \xNN: the C0 controls
// (newline and tab too, so that a message stays one line), DEL, the C1 controls as UTF-8 encodes
// them (U+0080..U+009F, which some terminals take as escape sequences), and every byte that is
// not part of a well-formed UTF-8 character (a raw 0x9b is CSI to an 8-bit terminal); backslash
// as \\.
std::string printable(std::string_view text);

// A value as the user wrote it, for messages: when longer than 24 bytes cut to its first 20 with
// "..." and the length appended, so that a 309-digit number stays short. Not yet printable.
std::string abbreviated(std::string_view text);

// `value` in at most 6 significant digits ("1e+39", "0.5", "nan").
std::string short_number(double value);

}  // namespace drt
