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
    EXPECT_EQ(exr_attribute_past_end(encode_exr(image, options, "a.exr")), std::nullopt);
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
    EXPECT_EQ(exr_attribute_past_end(b),
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
    EXPECT_EQ(exr_attribute_past_end(b),
              "OpenEXR attribute note claims 1000 bytes, more than the file holds");
}

// A preview is as large as its width and height say; a string or an unknown type as declared.
TEST(ExrHeader, APreviewOrStringLargerThanTheRestOfTheFileIsNamed) {
    Bytes preview = start();
    add_attribute(preview, "preview", "preview", 8);
    add_int(preview, 100000);
    add_int(preview, 100000);
    preview.resize(preview.size() + 64, 0);
    EXPECT_EQ(exr_attribute_past_end(preview),
              "OpenEXR attribute preview claims a preview of 100000x100000 pixels, more than the "
              "file holds");

    for (const std::string type : {"string", "someStudioType"}) {
        Bytes fits = start();
        add_attribute(fits, "a", type, 5);
        fits.resize(fits.size() + 5, 'x');
        EXPECT_EQ(exr_attribute_past_end(fits), std::nullopt) << type;
        Bytes past = fits;
        past.pop_back();
        EXPECT_EQ(exr_attribute_past_end(past),
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
    EXPECT_EQ(exr_attribute_past_end(b),
              "OpenEXR attribute name claims 500 bytes, more than the file holds");
    b[5] = 0;  // single part: what follows its header is the offset table
    EXPECT_EQ(exr_attribute_past_end(b), std::nullopt);
}

}  // namespace
}  // namespace drt
