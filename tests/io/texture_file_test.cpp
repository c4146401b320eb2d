#include "drt/io/texture_file.h"

#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "drt/io/exr.h"
#include "encoded_bytes.h"

// Part of libstb's stb_image_write, which its header declares only inside the implementation.
extern "C" unsigned char* stbi_zlib_compress(unsigned char* data, int data_len, int* out_len,
                                             int quality);

namespace drt {
namespace {

using testing::append;
using testing::Bytes;

// A 2 x 1 RGB image, pixel 0 = (a, b, c), pixel 1 = (c, b, a), in the format `kind`.
Bytes encoded(const std::string& kind, unsigned char a, unsigned char b, unsigned char c) {
    const unsigned char rgb[6] = {a, b, c, c, b, a};
    Bytes out;
    stbi_write_tga_with_rle = 0;
    if (kind == "png") stbi_write_png_to_func(append, &out, 2, 1, 3, rgb, 6);
    if (kind == "bmp") stbi_write_bmp_to_func(append, &out, 2, 1, 3, rgb);
    if (kind == "tga") stbi_write_tga_to_func(append, &out, 2, 1, 3, rgb);
    if (kind == "jpg") stbi_write_jpg_to_func(append, &out, 2, 1, 3, rgb, 100);
    return out;
}

// `file`, as `encoded` wrote it in the format `kind`, with its header promising w x h pixels.
void promise_size(Bytes& file, const std::string& kind, std::uint64_t w, std::uint64_t h) {
    const auto be16 = [&](std::size_t at, std::uint64_t v) {
        file.at(at) = static_cast<unsigned char>(v >> 8);
        file.at(at + 1) = static_cast<unsigned char>(v);
    };
    const auto le16 = [&](std::size_t at, std::uint64_t v) {
        file.at(at) = static_cast<unsigned char>(v);
        file.at(at + 1) = static_cast<unsigned char>(v >> 8);
    };
    if (kind == "png") be16(18, w), be16(22, h);  // IHDR's big-endian width and height
    if (kind == "bmp") le16(18, w), le16(22, h);
    if (kind == "tga") le16(12, w), le16(14, h);
    if (kind == "jpg") {
        const std::size_t sof = std::string(file.begin(), file.end()).find("\xff\xc0");
        ASSERT_NE(sof, std::string::npos);
        be16(sof + 5, h), be16(sof + 7, w);
    }
}

// A Radiance file of two white pixels whose header's size line reads `size` instead.
Bytes radiance_file(const std::string& size) {
    const float rgb[6] = {1, 1, 1, 1, 1, 1};
    Bytes two_pixels;
    stbi_write_hdr_to_func(append, &two_pixels, 2, 1, 3, rgb);
    std::string text(two_pixels.begin(), two_pixels.end());
    text.replace(text.find("-Y 1 +X 2"), 9, size);
    return Bytes(text.begin(), text.end());
}

Image decode(const Bytes& data, TextureEncoding encoding = TextureEncoding::kColor) {
    return decode_texture(data, "t.img", encoding);
}

std::string error_of(const Bytes& data) {
    try {
        decode(data);
    } catch (const ImageError& e) {
        return e.what();
    }
    return "no error";
}

// 8-bit colour is sRGB-encoded: 188 decodes to 0.5029 (a 2 % change of the curve misses the
// tolerance), 0 and 255 to exactly 0 and 1. Data maps keep code / 255.
TEST(TextureFile, EightBitColourIsDecodedFromSrgbAndDataIsLinear) {
    for (const std::string kind : {"png", "bmp", "tga"}) {
        const Image image = decode(encoded(kind, 188, 0, 255));
        ASSERT_EQ(image.width, 2) << kind;
        ASSERT_EQ(image.height, 1) << kind;
        EXPECT_NEAR(image.at(0, 0).r, 0.50289, 2e-4) << kind;
        EXPECT_EQ(image.at(0, 0).g, 0.0f) << kind;
        EXPECT_EQ(image.at(0, 0).b, 1.0f) << kind;
        EXPECT_EQ(image.at(1, 0).r, 1.0f) << kind;  // the second pixel: left to right
        const Image data = decode(encoded(kind, 188, 0, 255), TextureEncoding::kData);
        EXPECT_NEAR(data.at(0, 0).r, 188 / 255.0, 1e-7) << kind;
    }
}

// An alpha map (map_d) is the alpha channel where the image has one, linear (code / 255), and
// otherwise the luminance of the values taken as data; all three channels hold it.
TEST(TextureFile, AlphaIsTheAlphaChannelElseTheLuminance) {
    const unsigned char rgba[8] = {255, 255, 255, 64, 0, 0, 0, 200};
    Bytes with_alpha;
    stbi_write_png_to_func(append, &with_alpha, 2, 1, 4, rgba, 8);
    const Image a = decode(with_alpha, TextureEncoding::kAlpha);
    EXPECT_NEAR(a.at(0, 0).r, 64 / 255.0, 1e-7);
    EXPECT_NEAR(a.at(0, 0).b, 64 / 255.0, 1e-7);
    EXPECT_NEAR(a.at(1, 0).g, 200 / 255.0, 1e-7);
    const Image l = decode(encoded("png", 188, 0, 255), TextureEncoding::kAlpha);
    EXPECT_NEAR(l.at(0, 0).r, 0.2126 * 188 / 255.0 + 0.0722, 1e-6);
    EXPECT_NEAR(l.at(1, 0).r, 0.2126 + 0.0722 * 188 / 255.0, 1e-6);
}

TEST(TextureFile, JpegDecodesNearItsColours) {
    const Image image = decode(encoded("jpg", 188, 188, 188));
    EXPECT_NEAR(image.at(0, 0).g, 0.503, 0.02);
}

TEST(TextureFile, RadianceHdrAndExrAreLinear) {
    const float rgb[6] = {0.25f, 2.5f, 16.0f, 1, 1, 1};
    Bytes hdr;
    stbi_write_hdr_to_func(append, &hdr, 2, 1, 3, rgb);
    const Image h = decode(hdr);
    EXPECT_NEAR(h.at(0, 0).r, 0.25, 0.25 / 128);  // RGBE keeps 8 bits of mantissa
    EXPECT_NEAR(h.at(0, 0).g, 2.5, 2.5 / 128);
    EXPECT_NEAR(h.at(0, 0).b, 16.0, 16.0 / 128);

    Image image(2, 1);
    image.set(0, 0, {0.25, 2.5, 16});
    const Image e = decode(encode_exr(image, {}, "t.exr"));
    EXPECT_EQ(e.at(0, 0).r, 0.25f);
    EXPECT_EQ(e.at(0, 0).b, 16.0f);
}

TEST(TextureFile, SixteenBitPngIsDecodedFromSrgb) {
    // stb writes no 16-bit PNG: build one, 1 x 1 RGB, every channel 0xBCBC = 188 · 257.
    const auto chunk = [](Bytes& png, const char* kind, const Bytes& body) {
        for (const int shift : {24, 16, 8, 0})
            png.push_back(static_cast<unsigned char>(body.size() >> shift));
        png.insert(png.end(), kind, kind + 4);
        png.insert(png.end(), body.begin(), body.end());
        png.insert(png.end(), 4, 0);  // CRC, which stb does not check
    };
    Bytes png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    chunk(png, "IHDR", {0, 0, 0, 1, 0, 0, 0, 1, 16, 2, 0, 0, 0});
    unsigned char row[7] = {0, 0xBC, 0xBC, 0xBC, 0xBC, 0xBC, 0xBC};
    int size = 0;
    unsigned char* z = stbi_zlib_compress(row, 7, &size, 8);
    chunk(png, "IDAT", Bytes(z, z + size));
    std::free(z);
    chunk(png, "IEND", {});
    const Image image = decode(png);
    EXPECT_NEAR(image.at(0, 0).r, 0.50289, 2e-4);
    EXPECT_NEAR(decode(png, TextureEncoding::kData).at(0, 0).g, 188 / 255.0, 1e-7);
}

TEST(TextureFile, FormatsAreToldByContentNotName) {
    EXPECT_NE(error_of(Bytes{'h', 'e', 'l', 'l', 'o'}).find("not a PNG, JPEG, BMP, TGA"),
              std::string::npos);
    EXPECT_NE(error_of({}).find("t.img: "), std::string::npos);
}

// A header claiming 100000 x 100000 pixels is refused from the header, before stb allocates 30 GB.
TEST(TextureFile, HostileSizeIsRefusedFromTheHeader) {
    Bytes png = encoded("png", 1, 2, 3);
    // IHDR's width and height, big-endian at bytes 16 and 20; the CRC no longer matches,
    // which stb's header check does not look at.
    for (const int at : {16, 20}) {
        png[at] = 0, png[at + 1] = 0x01, png[at + 2] = 0x86, png[at + 3] = 0xA0;  // 100000
    }
    const std::string message = error_of(png);
    EXPECT_NE(message.find("100000x100000 pixels exceeds the limit"), std::string::npos) << message;

    Bytes tga = encoded("tga", 1, 2, 3);
    tga[12] = 0xA0, tga[13] = 0x86, tga[14] = 0xA0, tga[15] = 0x86;  // 34464 x 34464, > 2^27
    EXPECT_NE(error_of(tga).find("exceeds the limit"), std::string::npos) << error_of(tga);
}

// stb decodes a short file to the last pixel its header promises, reading zeros: a header that
// promises more pixels than the format can pack into the file is refused before decoding, with
// the numbers. 4096 x 4096 is within the pixel limit.
TEST(TextureFile, APromiseOfMorePixelsThanTheFileCanHoldIsRefused) {
    const auto message = [](const std::string& format, const Bytes& file) {
        return "t.img: " + format + " image of 4096x4096 pixels cannot fit in " +
               std::to_string(file.size()) + " bytes: the file is truncated or corrupt";
    };
    for (const auto& [kind, format] : {std::pair<std::string, std::string>{"png", "PNG"},
                                       {"bmp", "BMP"},
                                       {"tga", "TGA"},
                                       {"jpg", "JPEG"}}) {
        Bytes file = encoded(kind, 1, 2, 3);
        promise_size(file, kind, 4096, 4096);
        EXPECT_EQ(error_of(file), message(format, file));
    }
    const Bytes hdr = radiance_file("-Y 4096 +X 4096");
    EXPECT_EQ(error_of(hdr), message("Radiance HDR", hdr));
}

// Each format's bound exactly: a header promising bound x size pixels (width the bound, height
// the file's size in bytes) passes the check, one more column does not. A 2 % change of any
// bound fails here. What stb then makes of the file (zeros or an error) is not this test's.
TEST(TextureFile, TheDensityBoundOfEachFormatHoldsExactly) {
    const auto refused = [](const Bytes& file) {
        return error_of(file).find("cannot fit in") != std::string::npos;
    };
    struct Format {
        std::string kind;
        std::uint64_t bound;  // pixels a byte
    };
    for (const Format& f :
         {Format{"png", 8256}, Format{"jpg", 512}, Format{"bmp", 8}, Format{"tga", 64}}) {
        Bytes file = encoded(f.kind, 1, 2, 3);
        promise_size(file, f.kind, f.bound, file.size());
        EXPECT_FALSE(refused(file)) << f.kind << ": " << error_of(file);
        promise_size(file, f.kind, f.bound + 1, file.size());
        EXPECT_TRUE(refused(file)) << f.kind << ": " << error_of(file);
    }
    // A Radiance header is text, whose length changes with the digits written: the height is
    // found as the size of the file it ends up in.
    const auto hdr_promising = [](std::uint64_t w) {
        const auto promising = [w](std::uint64_t h) {
            return radiance_file("-Y " + std::to_string(h) + " +X " + std::to_string(w));
        };
        std::uint64_t h = 1;
        while (promising(h).size() != h) h = promising(h).size();
        return promising(h);
    };
    EXPECT_FALSE(refused(hdr_promising(16))) << error_of(hdr_promising(16));
    EXPECT_TRUE(refused(hdr_promising(17))) << error_of(hdr_promising(17));
}

// The bound is each format's densest encoding, which real files approach only for flat colour:
// flat images as stb writes them still load (a run-length TGA packs 32 pixels into a byte, a
// JPEG about 60, a Radiance file 13, against bounds of 64, 512 and 16).
TEST(TextureFile, FlatColourFilesAreWithinTheDensityBound) {
    constexpr int w = 512, h = 256;
    const std::vector<unsigned char> grey(3 * w * h, 128);
    const std::vector<float> flat(3 * w * h, 0.5f);
    for (const std::string kind : {"png", "jpg", "tga-rle", "hdr"}) {
        Bytes file;
        stbi_write_tga_with_rle = kind == "tga-rle" ? 1 : 0;
        if (kind == "png") stbi_write_png_to_func(append, &file, w, h, 3, grey.data(), 3 * w);
        if (kind == "jpg") stbi_write_jpg_to_func(append, &file, w, h, 3, grey.data(), 90);
        if (kind == "tga-rle") stbi_write_tga_to_func(append, &file, w, h, 3, grey.data());
        if (kind == "hdr") stbi_write_hdr_to_func(append, &file, w, h, 3, flat.data());
        EXPECT_EQ(error_of(file), "no error") << kind;
    }
}

// Files cut short are an error, never pixels made up from missing bytes.
TEST(TextureFile, TruncatedFilesAreErrors) {
    const unsigned char grey[3 * 64 * 64] = {};
    for (const std::string kind : {"png", "bmp", "tga", "tga-rle", "jpg", "hdr"}) {
        Bytes full;
        stbi_write_tga_with_rle = kind == "tga-rle" ? 1 : 0;
        if (kind == "tga-rle") stbi_write_tga_to_func(append, &full, 64, 64, 3, grey);
        if (kind == "png") stbi_write_png_to_func(append, &full, 64, 64, 3, grey, 3 * 64);
        if (kind == "bmp") stbi_write_bmp_to_func(append, &full, 64, 64, 3, grey);
        if (kind == "tga") stbi_write_tga_to_func(append, &full, 64, 64, 3, grey);
        if (kind == "jpg") stbi_write_jpg_to_func(append, &full, 64, 64, 3, grey, 90);
        if (kind == "hdr") {
            const std::vector<float> f(3 * 64 * 64, 0.5f);
            stbi_write_hdr_to_func(append, &full, 64, 64, 3, f.data());
        }
        EXPECT_NO_THROW(decode(full)) << kind;
        const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(full.size() / 2));
        EXPECT_THROW(decode(cut), ImageError) << kind;
    }
}

// A PNG cut just before its end chunk leaves stb without a reason; the message still has one.
TEST(TextureFile, APngWithoutItsEndChunkIsSaidToBeTruncated) {
    const unsigned char grey[3 * 8 * 8] = {};
    Bytes full;
    stbi_write_png_to_func(append, &full, 8, 8, 3, grey, 3 * 8);
    const Bytes cut(full.begin(), full.end() - 12);  // IEND: length, type and CRC
    try {
        decode(cut);
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.substr(what.rfind(": ") + 2), "truncated image file") << what;
    }
}

}  // namespace
}  // namespace drt
