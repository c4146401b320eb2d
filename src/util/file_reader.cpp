#include "drt/util/file_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "drt/util/huge_pages.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

std::string plain_wording(FileProblem problem, int system_error) {
    const std::string reason = std::generic_category().message(system_error);
    switch (problem) {
        case FileProblem::cannot_open:
            return "cannot open file: " + reason;
        case FileProblem::cannot_read:
            return "cannot read file: " + reason;
        case FileProblem::is_folder:
            return "is a folder, not a file";
        case FileProblem::not_regular_file:
            return "not a regular file";
        case FileProblem::too_large:
            break;
    }
    return "file larger than the limit";
}

// Closes the descriptor on every way out.
struct Descriptor {
    int fd;
    ~Descriptor() {
        if (fd >= 0) ::close(fd);
    }
};

template <class Container>
Container read_whole(const fs::path& path, std::uint64_t max_bytes, FileKinds kinds) {
    // Opened without waiting where only a regular file will do, so that a named pipe with no
    // writer is refused below instead of blocking the open (a regular file ignores the flag).
    const int wait = kinds == FileKinds::regular_only ? O_NONBLOCK : 0;
    const Descriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC | wait)};
    if (file.fd < 0) throw FileReadError(FileProblem::cannot_open, errno);
    struct stat info {};
    if (::fstat(file.fd, &info) != 0) throw FileReadError(FileProblem::cannot_open, errno);
    const bool regular = S_ISREG(info.st_mode);
    if (kinds == FileKinds::regular_only && !regular) {
        throw FileReadError(
            S_ISDIR(info.st_mode) ? FileProblem::is_folder : FileProblem::not_regular_file, 0);
    }
    const auto size = static_cast<std::uint64_t>(info.st_size);
    if (regular && size > max_bytes) throw FileReadError(FileProblem::too_large, 0);
    Container data;
    if (regular) {
        // Room for the whole file at once: growing by doubling would copy it and hold it twice.
        data.reserve(static_cast<std::size_t>(size));
        prefer_huge_pages(data.data(), data.capacity());
    }
    // Checked as it is read too: a file may grow while read, and a device has no size.
    typename Container::value_type buffer[1 << 16];
    for (;;) {
        const ssize_t n = ::read(file.fd, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw FileReadError(FileProblem::cannot_read, errno);
        if (n == 0) break;
        if (data.size() + static_cast<std::uint64_t>(n) > max_bytes) {
            throw FileReadError(FileProblem::too_large, 0);
        }
        data.insert(data.end(), buffer, buffer + n);
    }
    return data;
}

}  // namespace

FileReadError::FileReadError(FileProblem problem, int system_error)
    : std::runtime_error(plain_wording(problem, system_error)),
      problem_(problem),
      system_error_(system_error) {}

std::string FileReadError::reason() const {
    if (system_error_ == 0) return {};
    return std::generic_category().message(system_error_);
}

std::string read_text_file(const fs::path& path, std::uint64_t max_bytes, FileKinds kinds) {
    return read_whole<std::string>(path, max_bytes, kinds);
}

std::vector<unsigned char> read_binary_file(const fs::path& path, std::uint64_t max_bytes,
                                            FileKinds kinds) {
    return read_whole<std::vector<unsigned char>>(path, max_bytes, kinds);
}

}  // namespace drt
