// A PNG file's chunk lengths, checked before stb_image reads them.
#pragma once

#include <optional>
#include <span>
#include <string>

namespace drt {

// stb_image makes room for a chunk by the length the chunk declares before it reads the chunk,
// so a 90-byte file whose IDAT claims 1.4 GB costs 1.4 GB of address space (and, in a sanitizer
// build, a second per read). Returns "PNG chunk TYPE claims N bytes, more than the file holds"
// for the first chunk that runs past the end of `file` (after the 8-byte signature), or nothing.
std::optional<std::string> png_chunk_past_end(std::span<const unsigned char> file);

}  // namespace drt
