#include "drt/util/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <system_error>

#include "drt/util/interrupt.h"
#include "drt/util/text.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const fs::path& path, const std::string& what, int err) {
    throw FileWriteError(printable(path.string()) + ": " + what + ": " +
                         std::generic_category().message(err));
}

// Closes the descriptor and removes the temporary file unless the write was committed, so
// every failure path leaves the folder as it was.
class TempFile {
  public:
    explicit TempFile(const fs::path& target) {
        const fs::path dir = target.parent_path();
        std::random_device seed;
        std::mt19937_64 rng((std::uint64_t{seed()} << 32) ^ seed());
        // O_EXCL makes the name ours alone; retry in the unlikely event of a clash.
        int err = 0;
        for (int attempt = 0; attempt < 16; ++attempt) {
            std::string name = ".";
            name += target.filename().string();
            name += ".tmp-";
            name += std::to_string(getpid());
            name += '-';
            name += std::to_string(rng());
            path_ = dir / name;
            guard_.emplace(path_);
            fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
            err = errno;
            if (fd_ >= 0) return;
            guard_.reset();
            if (err != EEXIST) break;
        }
        fail(target, "cannot create file", err);
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;
    ~TempFile() {
        if (fd_ >= 0) ::close(fd_);
        if (!committed_) ::unlink(path_.c_str());
    }

    // Returns 0 or the errno of the first failure.
    int write_all(std::span<const unsigned char> data) {
        std::size_t done = 0;
        while (done < data.size()) {
            const ssize_t n = ::write(fd_, data.data() + done, data.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) return n < 0 ? errno : EIO;
            done += static_cast<std::size_t>(n);
        }
        // fsync before the rename, or a crash could leave the new name on an empty file.
        if (::fsync(fd_) != 0) return errno;
        const int fd = fd_;
        fd_ = -1;
        return ::close(fd) != 0 ? errno : 0;
    }

    void commit_as(const fs::path& target) {
        if (::rename(path_.c_str(), target.c_str()) != 0) fail(target, "cannot write file", errno);
        committed_ = true;
    }

  private:
    fs::path path_;
    std::optional<TemporaryFileGuard> guard_;  // destroyed after the file is gone or renamed
    int fd_ = -1;
    bool committed_ = false;
};

}  // namespace

void replace_file(const fs::path& path, std::span<const unsigned char> bytes) {
    TempFile tmp(path);
    if (const int err = tmp.write_all(bytes)) fail(path, "cannot write file", err);
    tmp.commit_as(path);
}

void replace_file(const fs::path& path, std::string_view text) {
    replace_file(path, std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

void check_replaceable(const fs::path& path) {
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) {
        fail(path, "cannot write file", EISDIR);
    }
    TempFile probe(path);  // removed again as it goes out of scope
}

}  // namespace drt
