#include "drt/io/exr.h"

#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <half.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <new>
#include <string>

#include "drt/io/exr_header.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<unsigned char>;

// OpenEXR writes through this: a byte vector that grows as written and may be seeked back into
// (the offset table is filled in last).
class MemoryOStream final : public Imf::OStream {
  public:
    MemoryOStream(Bytes& out, const fs::path& path) : Imf::OStream(path.c_str()), out_(out) {}
    void write(const char c[], int n) override {
        const std::size_t end = pos_ + static_cast<std::size_t>(n);
        if (end > out_.size()) out_.resize(end);
        std::memcpy(out_.data() + pos_, c, static_cast<std::size_t>(n));
        pos_ = end;
    }
    uint64_t tellp() override { return pos_; }
    void seekp(uint64_t pos) override { pos_ = pos; }

  private:
    Bytes& out_;
    std::size_t pos_ = 0;
};

// OpenEXR reads through this; running past the end throws as a file stream's would.
class MemoryIStream final : public Imf::IStream {
  public:
    MemoryIStream(const Bytes& in, const fs::path& path) : Imf::IStream(path.c_str()), in_(in) {}
    bool read(char c[], int n) override {
        if (n < 0 || pos_ > in_.size() || in_.size() - pos_ < static_cast<std::size_t>(n)) {
            throw Iex::InputExc("unexpected end of file");
        }
        std::memcpy(c, in_.data() + pos_, static_cast<std::size_t>(n));
        pos_ += static_cast<std::size_t>(n);
        return pos_ < in_.size();
    }
    uint64_t tellg() override { return pos_; }
    void seekg(uint64_t pos) override { pos_ = pos; }

  private:
    const Bytes& in_;
    uint64_t pos_ = 0;
};

void add_attribute(Imf::Header& header, const ImageAttribute& a) {
    if (const auto* s = std::get_if<std::string>(&a.value)) {
        header.insert(a.name, Imf::StringAttribute(*s));
    } else if (const auto* i = std::get_if<int>(&a.value)) {
        header.insert(a.name, Imf::IntAttribute(*i));
    } else {
        header.insert(a.name, Imf::DoubleAttribute(std::get<double>(a.value)));
    }
}

}  // namespace

Bytes encode_exr(const Image& image, const ImageWriteOptions& options, const fs::path& path) {
    const Imf::PixelType type = options.half ? Imf::HALF : Imf::FLOAT;
    // Half channels are written from half values; float ones straight from the image.
    std::vector<half> halves;
    if (options.half) halves.assign(image.rgb.begin(), image.rgb.end());
    const char* const base = options.half ? reinterpret_cast<const char*>(halves.data())
                                          : reinterpret_cast<const char*>(image.rgb.data());
    const std::size_t value_size = options.half ? sizeof(half) : sizeof(float);

    Bytes file;
    try {
        // Lossless ZIP keeps float values bit-exact and is read by every OpenEXR reader.
        Imf::Header header(image.width, image.height, 1.0f, Imath::V2f(0, 0), 1.0f,
                           Imf::INCREASING_Y, Imf::ZIP_COMPRESSION);
        for (const ImageAttribute& a : options.attributes) add_attribute(header, a);
        Imf::FrameBuffer frame;
        const std::size_t x_stride = 3 * value_size, y_stride = x_stride * image.width;
        const char* const names[] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c) {
            header.channels().insert(names[c], Imf::Channel(type));
            frame.insert(names[c], Imf::Slice(type, const_cast<char*>(base + c * value_size),
                                              x_stride, y_stride));
        }
        const std::size_t extra = options.extra.names.size();
        std::vector<half> extra_halves;
        if (options.half)
            extra_halves.assign(options.extra.values.begin(), options.extra.values.end());
        const char* const extra_base =
            options.half ? reinterpret_cast<const char*>(extra_halves.data())
                         : reinterpret_cast<const char*>(options.extra.values.data());
        for (std::size_t c = 0; c < extra; ++c) {
            const std::string& name = options.extra.names[c];
            header.channels().insert(name, Imf::Channel(type));
            frame.insert(name, Imf::Slice(type, const_cast<char*>(extra_base + c * value_size),
                                          extra * value_size, extra * value_size * image.width));
        }
        MemoryOStream stream(file, path);
        Imf::OutputFile out(stream, header, 0);
        out.setFrameBuffer(frame);
        out.writePixels(image.height);
    } catch (const std::exception& e) {
        throw ImageError(printable(path.string()) +
                         ": cannot encode OpenEXR image: " + printable(e.what()));
    }
    return file;
}

namespace {

struct DataWindow {
    Imath::Box2i box;
    long long width, height;
};

using Fail = std::function<ImageError(const std::string&)>;

// The file's data window, refused when empty or larger than drt reads: compression lets a small
// file claim a huge image, so this comes before any allocation.
DataWindow data_window(const Imf::InputFile& in, const Fail& fail) {
    const Imath::Box2i box = in.header().dataWindow();
    const long long w = static_cast<long long>(box.max.x) - box.min.x + 1;
    const long long h = static_cast<long long>(box.max.y) - box.min.y + 1;
    if (w <= 0 || h <= 0) throw fail("bad OpenEXR data window");
    if (past_image_limits(w, h)) throw fail(image_limit_message(w, h));
    return {box, w, h};
}

// Opens `data` as an OpenEXR file whose header, data window and offset table are sound, and
// returns what `read` makes of it; every failure, which OpenEXR reports by throwing anything
// from a bad magic number to a truncated tile, becomes an ImageError naming `path`.
template <class Read>
auto read_exr(const Bytes& data, const fs::path& path, const Read& read) {
    const Fail fail = [&](const std::string& what) {
        return ImageError(printable(path.string()) + ": " + what);
    };
    try {
        if (const auto problem = exr_header_problem(data)) throw fail(*problem);
        MemoryIStream stream(data, path);
        // No worker threads: a pool costs a thread start per file and one worker gains nothing.
        Imf::InputFile in(stream, 0);
        const DataWindow window = data_window(in, fail);
        // A file cut short can still have a readable header and offset table.
        if (!in.isComplete()) throw fail("truncated OpenEXR file");
        return read(in, window, fail);
    } catch (const ImageError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw fail("OpenEXR image too large");
    } catch (const std::exception& e) {
        throw fail("cannot read OpenEXR image: " + printable(e.what()));
    }
}

}  // namespace

Image decode_exr(const Bytes& data, const fs::path& path) {
    return read_exr(data, path, [](Imf::InputFile& in, const DataWindow& window, const Fail& fail) {
        const long long w = window.width, h = window.height;
        const Imf::ChannelList& channels = in.header().channels();
        const bool rgb =
            channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
        if (!rgb && !channels.findChannel("Y")) {
            throw fail("OpenEXR image has neither R, G, B nor Y channels");
        }
        // Uninitialised, so that a header claiming a huge image costs only the pages the decoder
        // writes before it finds the data wrong; the image is made once everything decoded.
        const std::size_t count = 3 * static_cast<std::size_t>(w * h);
        const auto pixels = std::make_unique_for_overwrite<float[]>(count);
        Imf::FrameBuffer frame;
        const std::size_t x_stride = 3 * sizeof(float), y_stride = x_stride * w;
        const char* const names[] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c) {
            // A Y-only (luminance) image fills all three from the one channel.
            frame.insert(rgb ? names[c] : "Y", Imf::Slice::Make(Imf::FLOAT, pixels.get() + c,
                                                                window.box, x_stride, y_stride));
            if (!rgb) break;
        }
        in.setFrameBuffer(frame);
        in.readPixels(window.box.min.y, window.box.max.y);
        if (!rgb) {
            for (std::size_t i = 0; i < count; i += 3) pixels[i + 1] = pixels[i + 2] = pixels[i];
        }
        Image image;
        image.width = static_cast<int>(w);
        image.height = static_cast<int>(h);
        image.rgb.assign(pixels.get(), pixels.get() + count);
        return image;
    });
}

std::vector<float> decode_exr_channel(const Bytes& data, const std::string& name,
                                      const fs::path& path) {
    return read_exr(
        data, path, [&](Imf::InputFile& in, const DataWindow& window, const Fail& fail) {
            if (!in.header().channels().findChannel(name)) {
                throw fail("OpenEXR image has no channel " + printable(name));
            }
            std::vector<float> values(static_cast<std::size_t>(window.width * window.height));
            Imf::FrameBuffer frame;
            frame.insert(name,
                         Imf::Slice::Make(Imf::FLOAT, values.data(), window.box, sizeof(float),
                                          sizeof(float) * static_cast<std::size_t>(window.width)));
            in.setFrameBuffer(frame);
            in.readPixels(window.box.min.y, window.box.max.y);
            return values;
        });
}

}  // namespace drt
