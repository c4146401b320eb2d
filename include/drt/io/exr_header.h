// An OpenEXR file's headers, walked as OpenEXR 3.1's reader will walk them, before it does.
#pragma once

#include <optional>
#include <span>
#include <string>

namespace drt {

// OpenEXR makes room for a variable-sized attribute value (a string, a preview image, an
// attribute of unknown type) by the size the file declares before it reads the value: a file of
// a few hundred bytes that declares a 2 GB string costs 2 GB and seconds. Returns "OpenEXR
// attribute NAME claims N bytes, more than the file holds" for the first attribute of any
// header that would make it reserve more than the rest of the file, or nothing. What OpenEXR
// itself refuses (a name without its end, a negative size, a header cut short) is left to it.
std::optional<std::string> exr_attribute_past_end(std::span<const unsigned char> file);

}  // namespace drt
