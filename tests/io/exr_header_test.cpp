#include "drt/io/exr_header.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "drt/io/exr.h"

namespace drt {
namespace {

using Bytes = std::vector<unsigned char>;

// The magic number and a single-part scan-line version field.
Bytes start() {
    return {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
}

void add_text(Bytes& b, const std::string& text) {
    b.insert(b.end(), text.begin(), text.end());
    b.push_back(0);
}

void add_int(Bytes& b, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

// An attribute's name, type and declared size; its value is appended by the caller.
void add_attribute(Bytes& b, const std::string& name, const std::string& type,
                   std::uint32_t declared) {
    add_text(b, name);
    add_text(b, type);
    add_int(b, declared);
}

TEST(ExrHeader, AFileOpenExrWroteHasNoAttributePastItsEnd) {
    Image image(4, 3);
    ImageWriteOptions options;
    options.attributes.push_back({"sampler", std::string("stratified")});
    options.attributes.push_back({"samplesPerPixel", 16});
    EXPECT_EQ(exr_header_problem(encode_exr(image, options, "a.exr")), std::nullopt);
}

// OpenEXR reads an int's 4 bytes whatever size is declared, and takes what follows for the next
// attribute: here a string claiming 2 GB, hidden inside the int's declared 40 bytes from a walk
// that trusts the declared sizes.
TEST(ExrHeader, TheWalkFollowsTheReaderNotTheDeclaredSizes) {
    Bytes b = start();
    add_attribute(b, "count", "int", 40);
    add_int(b, 7);
    add_attribute(b, "hidden", "string", 0x7fffffff);
    b.resize(b.size() + 40, 'x');
    EXPECT_EQ(exr_header_problem(b),
              "OpenEXR attribute hidden claims 2147483647 bytes, more than the file holds");
}

// A channel list is read to its empty name whatever its declared size (here 0).
TEST(ExrHeader, AChannelListIsReadToItsEnd) {
    Bytes b = start();
    add_attribute(b, "channels", "chlist", 0);
    add_text(b, "R");
    b.resize(b.size() + 16, 0);
    b.push_back(0);
    add_attribute(b, "note", "string", 1000);
    b.resize(b.size() + 10, 'x');
    EXPECT_EQ(exr_header_problem(b),
              "OpenEXR attribute note claims 1000 bytes, more than the file holds");
}

// A preview is as large as its width and height say; a string or an unknown type as declared.
TEST(ExrHeader, APreviewOrStringLargerThanTheRestOfTheFileIsNamed) {
    Bytes preview = start();
    add_attribute(preview, "preview", "preview", 8);
    add_int(preview, 100000);
    add_int(preview, 100000);
    preview.resize(preview.size() + 64, 0);
    EXPECT_EQ(exr_header_problem(preview),
              "OpenEXR attribute preview claims a preview of 100000x100000 pixels, more than the "
              "file holds");

    for (const std::string type : {"string", "someStudioType"}) {
        Bytes fits = start();
        add_attribute(fits, "a", type, 5);
        fits.resize(fits.size() + 5, 'x');
        EXPECT_EQ(exr_header_problem(fits), std::nullopt) << type;
        Bytes past = fits;
        past.pop_back();
        EXPECT_EQ(exr_header_problem(past),
                  "OpenEXR attribute a claims 5 bytes, more than the file holds")
            << type;
    }
}

// A second part's header is walked too; a single-part file ends at its header's end.
TEST(ExrHeader, EveryHeaderOfAMultiPartFileIsWalked) {
    Bytes b = start();
    b[5] = 0x10;  // multi-part
    add_attribute(b, "name", "string", 1);
    b.push_back('a');
    b.push_back(0);  // the end of the first header
    add_attribute(b, "name", "string", 500);
    b.resize(b.size() + 20, 'x');
    EXPECT_EQ(exr_header_problem(b),
              "OpenEXR attribute name claims 500 bytes, more than the file holds");
    b[5] = 0;  // single part: what follows its header is the offset table
    EXPECT_EQ(exr_header_problem(b), std::nullopt);
}

// A header of `channels` float channels, a data window of w x h and a compression, as OpenEXR's
// reader would allocate its blocks from; `tile`: a tile size, making the file tiled.
Bytes header(std::uint32_t w, std::uint32_t h, int channels, unsigned char compression,
             std::uint32_t tile = 0) {
    Bytes b = start();
    if (tile) b[5] = 0x02;  // tiled
    add_attribute(b, "channels", "chlist", 18 * channels + 1);
    for (int c = 0; c < channels; ++c) {
        add_text(b, std::string(1, static_cast<char>('A' + c)));
        add_int(b, 2);  // float
        add_int(b, 0);
        add_int(b, 1);
        add_int(b, 1);
    }
    b.push_back(0);
    add_attribute(b, "compression", "compression", 1);
    b.push_back(compression);
    add_attribute(b, "dataWindow", "box2i", 16);
    for (const std::uint32_t v : {0u, 0u, w - 1, h - 1}) add_int(b, v);
    if (tile) {
        add_attribute(b, "tiles", "tiledesc", 9);
        add_int(b, tile);
        add_int(b, tile);
        b.push_back(0);
    }
    b.push_back(0);  // the end of the header
    b.resize(b.size() + 64, 0);
    return b;
}

// The reader allocates a decoded block from the header alone: the data window is held to the
// image limits (pixels and sides), and a block (DWAB's 256 lines, or a tile) to 512 MiB, before it
// does.
TEST(ExrHeader, TheDataWindowAndTheBlocksAreHeldToTheLimitsBeforeOpenExrAllocates) {
    EXPECT_EQ(exr_header_problem(header(5963780, 3, 3, 3)),
              "image of 5963780x3 pixels exceeds the limit of 65536 pixels a side");
    EXPECT_EQ(exr_header_problem(header(16385, 8192, 3, 3)),
              "image of 16385x8192 pixels exceeds the limit of 134217728 pixels");
    EXPECT_EQ(exr_header_problem(header(65536, 2048, 3, 3)), std::nullopt);
    // 65536 x 256 pixels of 8 floats is 512 MiB exactly; of 9, past it.
    EXPECT_EQ(exr_header_problem(header(65536, 2048, 8, 9)), std::nullopt);
    EXPECT_EQ(exr_header_problem(header(65536, 2048, 9, 9)),
              "OpenEXR block of 256 lines of 65536 pixels at 36 bytes a pixel exceeds the limit "
              "of 536870912 bytes");
    // ZIP's 16 lines of the same image are well within it.
    EXPECT_EQ(exr_header_problem(header(65536, 2048, 9, 3)), std::nullopt);
    EXPECT_EQ(exr_header_problem(header(4, 3, 3, 0, 100000)),
              "OpenEXR block of a tile of 100000x100000 pixels at 12 bytes a pixel exceeds the "
              "limit of 536870912 bytes");
    EXPECT_EQ(exr_header_problem(header(4, 3, 3, 0, 64)), std::nullopt);
}

}  // namespace
}  // namespace drt
