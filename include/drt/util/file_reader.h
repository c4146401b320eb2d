// Reading a whole file into memory, refusing one larger than a stated bound while it is read, so
// that an endless input (/dev/zero) or a huge file ends in a message, not in exhausted memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace drt {

enum class FileProblem { cannot_open, cannot_read, is_folder, not_regular_file, too_large };

// A file that could not be read whole. Each caller words the message in its own terms from
// problem() and reason(); what() is a plain wording for those that do not.
class FileReadError : public std::runtime_error {
  public:
    FileReadError(FileProblem problem, int system_error);
    FileProblem problem() const { return problem_; }
    // The system's reason ("No such file or directory") for cannot_open and cannot_read; empty
    // for the other problems.
    std::string reason() const;

  private:
    FileProblem problem_;
    int system_error_;  // errno, or 0
};

// Which files a read accepts: any (a folder then fails as cannot_read, as reading it does), or
// only regular files (anything else fails before reading, as is_folder or not_regular_file).
enum class FileKinds { any, regular_only };

// The whole of `path`, at most `max_bytes` of it; throws FileReadError.
std::string read_text_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                           FileKinds kinds = FileKinds::any);
std::vector<unsigned char> read_binary_file(const std::filesystem::path& path,
                                            std::uint64_t max_bytes,
                                            FileKinds kinds = FileKinds::any);

}  // namespace drt
