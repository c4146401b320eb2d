#include "drt/image.h"

#include <fcntl.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <system_error>

namespace drt {

namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<unsigned char>;

// Larger images are taken for corrupt headers (stb's own limit).
constexpr int kMaxSide = 1 << 24;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw ImageError(path.string() + ": " + what);
}

std::string errno_text(int err) {
    return std::generic_category().message(err);
}

// ---- encoding -------------------------------------------------------------------------------

// stb's writers hand over the encoded file in pieces through this callback.
void append_to_bytes(void* context, void* data, int size) {
    const auto* p = static_cast<const unsigned char*>(data);
    static_cast<Bytes*>(context)->insert(static_cast<Bytes*>(context)->end(), p, p + size);
}

Bytes encode_8bit(const Image& image, ImageFormat format, const fs::path& path) {
    Bytes pixels(image.rgb.size());
    std::transform(image.rgb.begin(), image.rgb.end(), pixels.begin(),
                   [](float v) { return encode_srgb8(v); });
    Bytes file;
    const int ok = format == ImageFormat::kPng
                       ? stbi_write_png_to_func(append_to_bytes, &file, image.width, image.height,
                                                3, pixels.data(), 3 * image.width)
                       : stbi_write_bmp_to_func(append_to_bytes, &file, image.width, image.height,
                                                3, pixels.data());
    if (!ok) fail(path, "cannot encode image");
    return file;
}

void put_le32(Bytes& out, std::uint32_t v) {
    for (int shift = 0; shift < 32; shift += 8) {
        out.push_back(static_cast<unsigned char>(v >> shift));
    }
}

// PFM stores rows bottom-up; a negative scale marks little-endian data, which we always write
// so the bytes do not depend on the host.
Bytes encode_pfm(const Image& image) {
    const std::string header =
        "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
    Bytes file(header.begin(), header.end());
    file.reserve(file.size() + 4 * image.rgb.size());
    const std::size_t row_floats = 3 * static_cast<std::size_t>(image.width);
    for (int y = image.height - 1; y >= 0; --y) {
        const float* row = image.rgb.data() + y * row_floats;
        for (std::size_t i = 0; i < row_floats; ++i) {
            put_le32(file, std::bit_cast<std::uint32_t>(row[i]));
        }
    }
    return file;
}

// ---- atomic file replacement ----------------------------------------------------------------

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
            fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
            err = errno;
            if (fd_ >= 0 || err != EEXIST) break;
        }
        if (fd_ < 0) fail(target, "cannot create file: " + errno_text(err));
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;
    ~TempFile() {
        if (fd_ >= 0) ::close(fd_);
        if (!committed_) ::unlink(path_.c_str());
    }

    // Returns 0 or the errno of the first failure.
    int write_all(const Bytes& data) {
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
        std::error_code ec;
        fs::rename(path_, target, ec);
        if (ec) fail(target, "cannot write file: " + ec.message());
        committed_ = true;
    }

  private:
    fs::path path_;
    int fd_ = -1;
    bool committed_ = false;
};

void replace_file(const fs::path& path, const Bytes& data) {
    TempFile tmp(path);
    if (const int err = tmp.write_all(data)) fail(path, "cannot write file: " + errno_text(err));
    tmp.commit_as(path);
}

// ---- decoding -------------------------------------------------------------------------------

Bytes read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open file: " + errno_text(errno));
    Bytes data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) fail(path, "cannot read file");
    return data;
}

bool starts_with(const Bytes& data, std::string_view magic) {
    return data.size() >= magic.size() && std::memcmp(data.data(), magic.data(), magic.size()) == 0;
}

// stb fills the missing rows of a truncated BMP with black instead of failing, so check that
// the pixel rows the header promises are all there.
bool bmp_is_truncated(const Bytes& data) {
    const auto u16 = [&](std::size_t i) { return std::uint32_t{data[i]} | data[i + 1] << 8; };
    const auto u32 = [&](std::size_t i) { return u16(i) | u16(i + 2) << 16; };
    if (data.size() < 26) return true;
    const bool core = u32(14) == 12;  // the old OS/2 header, with 16-bit fields
    if (!core && data.size() < 34) return true;
    // Compressed rows have no fixed size; stb refuses those anyway, as it does huge images.
    if (!core && u32(30) != 0 && u32(30) != 3) return false;
    const std::uint64_t w = core ? u16(18) : u32(18);
    const std::uint64_t h = core ? u16(20) : std::abs(std::int64_t{std::int32_t(u32(22))});
    const std::uint64_t bits = core ? u16(24) : u16(28);
    if (w > kMaxSide || h > kMaxSide) return false;
    const std::uint64_t row_bytes = (w * bits + 31) / 32 * 4;
    return data.size() < u32(10) + row_bytes * h;
}

Image decode_8bit(const Bytes& data, ImageFormat format, const fs::path& path) {
    // Check the signature ourselves: stb would happily decode a JPEG named .png.
    const bool is_png = format == ImageFormat::kPng;
    if (!starts_with(data, is_png ? std::string_view("\x89PNG\r\n\x1a\n", 8) : "BM")) {
        fail(path, is_png ? "not a PNG file" : "not a BMP file");
    }
    if (!is_png && bmp_is_truncated(data)) fail(path, "truncated BMP file");
    if (data.size() > static_cast<std::size_t>(INT32_MAX)) fail(path, "file too large");
    int w = 0, h = 0, channels = 0;
    const std::unique_ptr<stbi_uc, decltype(&stbi_image_free)> pixels(
        stbi_load_from_memory(data.data(), static_cast<int>(data.size()), &w, &h, &channels, 3),
        &stbi_image_free);
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        fail(path, std::string("cannot decode image: ") + (reason ? reason : "unknown error"));
    }
    Image image(w, h);
    std::transform(pixels.get(), pixels.get() + image.rgb.size(), image.rgb.begin(),
                   [](stbi_uc v) { return static_cast<float>(v / 255.0); });
    return image;
}

// Reads the whitespace-separated tokens of a PFM header without running past the data.
class HeaderReader {
  public:
    HeaderReader(const Bytes& data, const fs::path& path) : data_(data), path_(path) {}

    std::string_view token() {
        while (pos_ < data_.size() && std::isspace(data_[pos_])) ++pos_;
        const std::size_t start = pos_;
        while (pos_ < data_.size() && !std::isspace(data_[pos_]) && pos_ - start < 32) ++pos_;
        if (pos_ == start) fail(path_, "truncated PFM header");
        return {reinterpret_cast<const char*>(data_.data()) + start, pos_ - start};
    }

    template <typename T>
    T number(const char* what) {
        std::string_view t = token();
        // from_chars takes no plus sign, which some writers put before the scale.
        if (t.starts_with('+') && !t.substr(1).starts_with('-')) t.remove_prefix(1);
        T value{};
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
        if (ec != std::errc() || end != t.data() + t.size()) {
            fail(path_, "bad PFM " + std::string(what) + " '" + std::string(t) + "'");
        }
        return value;
    }

    // Exactly one whitespace byte separates the header from the data, which may itself start
    // with bytes that look like whitespace.
    std::size_t data_start() {
        if (pos_ >= data_.size() || !std::isspace(data_[pos_])) fail(path_, "truncated PFM header");
        return pos_ + 1;
    }

  private:
    const Bytes& data_;
    const fs::path& path_;
    std::size_t pos_ = 0;
};

Image decode_pfm(const Bytes& data, const fs::path& path) {
    HeaderReader header(data, path);
    const std::string_view kind = header.token();
    if (kind != "PF" && kind != "Pf") fail(path, "not a PFM file");
    const int channels = kind == "PF" ? 3 : 1;
    const int w = header.number<int>("width");
    const int h = header.number<int>("height");
    const double scale = header.number<double>("scale");
    if (w <= 0 || h <= 0 || w > kMaxSide || h > kMaxSide) fail(path, "bad PFM size");
    if (scale == 0 || !std::isfinite(scale)) fail(path, "bad PFM scale");
    const std::size_t start = header.data_start();

    const std::size_t count = static_cast<std::size_t>(channels) * w * h;
    if (data.size() - start < 4 * count) fail(path, "truncated PFM data");
    // The sign of the scale gives the byte order: negative is little-endian.
    const bool little = scale < 0;
    const auto value_at = [&](std::size_t i) {
        const unsigned char* b = data.data() + start + 4 * i;
        std::uint32_t bits = 0;
        for (int k = 0; k < 4; ++k) bits |= std::uint32_t{b[little ? k : 3 - k]} << (8 * k);
        return std::bit_cast<float>(bits);
    };

    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        const std::size_t file_row = static_cast<std::size_t>(h - 1 - y) * w;  // bottom-up
        for (int x = 0; x < w; ++x) {
            float* out = image.rgb.data() + 3 * (static_cast<std::size_t>(y) * w + x);
            for (int c = 0; c < 3; ++c) out[c] = value_at(channels * (file_row + x) + c % channels);
        }
    }
    return image;
}

}  // namespace

ImageFormat format_for_path(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png") return ImageFormat::kPng;
    if (ext == ".bmp") return ImageFormat::kBmp;
    if (ext == ".pfm") return ImageFormat::kPfm;
    fail(path,
         "unsupported image format '" + path.extension().string() + "' (use .png, .bmp or .pfm)");
}

unsigned char encode_srgb8(double linear) {
    const double v = std::isnan(linear) ? 0.0 : std::clamp(linear, 0.0, 1.0);
    const double encoded = v < 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    return static_cast<unsigned char>(std::lround(encoded * 255));
}

void write_image(const Image& image, const fs::path& path) {
    const ImageFormat format = format_for_path(path);
    if (image.width <= 0 || image.height <= 0) fail(path, "cannot write an empty image");
    if (image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
        fail(path, "image data does not match its size");
    }
    replace_file(
        path, format == ImageFormat::kPfm ? encode_pfm(image) : encode_8bit(image, format, path));
}

Image read_image(const fs::path& path) {
    const ImageFormat format = format_for_path(path);
    const Bytes data = read_file(path);
    return format == ImageFormat::kPfm ? decode_pfm(data, path) : decode_8bit(data, format, path);
}

}  // namespace drt
