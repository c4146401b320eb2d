// An OpenEXR file's headers, walked as OpenEXR 3.1's reader will walk them, before it does.
#pragma once

#include <optional>
#include <span>
#include <string>

namespace drt {

// What OpenEXR would allocate for a header is checked against the file and drt's limits
// (util/limits.h) before OpenEXR reads it. It makes room for a variable-sized attribute (a
// string, a preview image, an attribute of unknown type) by the size the file declares before
// it reads the value, so a file of a few hundred bytes that declares a 2 GB string costs 2 GB;
// and it allocates two decoded blocks of pixels from the data window, the channels and the
// compression (or tile size) alone. Returns, for the first header with such a problem, one of
//   "OpenEXR attribute NAME claims N bytes, more than the file holds"
//   "OpenEXR attribute NAME claims a preview of WxH pixels, more than the file holds"
//   "image of WxH pixels exceeds the limit of 134217728 pixels"
//   "OpenEXR block of 16 lines of W pixels at B bytes a pixel exceeds the limit of N bytes"
// or nothing. What OpenEXR itself refuses (a name without its end, a negative size, a header
// cut short) is left to it.
std::optional<std::string> exr_header_problem(std::span<const unsigned char> file);

}  // namespace drt
