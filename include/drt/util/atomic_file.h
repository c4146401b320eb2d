// Files that appear complete or not at all: the data goes to a temporary file beside the target
// (registered for removal should a signal arrive), then a rename replaces the target.
#pragma once

#include <filesystem>
#include <span>
#include <stdexcept>
#include <string_view>

namespace drt {

// A file that could not be written; what() is "PATH: cannot ...: REASON".
class FileWriteError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Replaces `path` with `bytes`, or throws FileWriteError and leaves the folder as it was.
void replace_file(const std::filesystem::path& path, std::span<const unsigned char> bytes);
void replace_file(const std::filesystem::path& path, std::string_view text);

// Throws FileWriteError unless a file could now be created beside `path` and then renamed to it:
// checked before work whose result would go there, so that a later write is unlikely to fail.
void check_replaceable(const std::filesystem::path& path);

}  // namespace drt
