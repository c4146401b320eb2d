#include "drt/io/image.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "encoded_bytes.h"
#include "temp_folder.h"

namespace drt {
namespace {

using testing::be32;
using testing::le32;

namespace fs = std::filesystem;

using test::read_bytes, test::write_bytes;

class ImageFileTest : public test::TempFolderTest {
  protected:
    fs::path file(const std::string& name) const { return dir_ / name; }
    std::vector<fs::path> entries() const {
        return {fs::directory_iterator(dir_), fs::directory_iterator()};
    }
};

// A small image with distinct, awkward values: above 1, negative, tiny, and a different top row.
Image test_pattern(int w = 5, int h = 3) {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            image.set(x, y, {0.1 * x + 0.37 * y, 1.0 - 0.2 * x, y == 0 ? 3.5 : -0.25 * x});
        }
    }
    image.set(0, 0, {1e-7, 1e30, -7.125});
    return image;
}

TEST(FormatForPath, KnowsTheFourExtensionsInAnyCase) {
    EXPECT_EQ(format_for_path("a.png"), ImageFormat::kPng);
    EXPECT_EQ(format_for_path("dir.x/a.PnG"), ImageFormat::kPng);
    EXPECT_EQ(format_for_path("a.BMP"), ImageFormat::kBmp);
    EXPECT_EQ(format_for_path("/tmp/a.pfm"), ImageFormat::kPfm);
    EXPECT_EQ(format_for_path("a.Pfm"), ImageFormat::kPfm);
    EXPECT_EQ(format_for_path("a.eXr"), ImageFormat::kExr);
}

TEST(FormatForPath, RejectsOtherExtensionsNamingTheFile) {
    try {
        format_for_path("out/render.jpg");
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_STREQ(
            e.what(),
            "out/render.jpg: unsupported image format '.jpg' (use .png, .bmp, .pfm or .exr)");
    }
    EXPECT_THROW(format_for_path("render"), ImageError);
    EXPECT_THROW(format_for_path("render.png.tmp"), ImageError);
}

TEST(EncodeSrgb8, KnownValues) {
    EXPECT_EQ(encode_srgb8(0.0), 0);
    EXPECT_EQ(encode_srgb8(1.0), 255);
    EXPECT_EQ(encode_srgb8(0.5), 188);
    EXPECT_EQ(encode_srgb8(0.18), 118);  // 117.65: photographic mid grey
    EXPECT_EQ(encode_srgb8(0.001), 3);   // linear segment: 12.92 * 0.001 * 255 = 3.29
    EXPECT_EQ(encode_srgb8(0.002), 7);   // 6.59, rounded up, not truncated
}

TEST(EncodeSrgb8, ClampsAndMapsNanToBlack) {
    EXPECT_EQ(encode_srgb8(-1.0), 0);
    EXPECT_EQ(encode_srgb8(7.0), 255);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<double>::infinity()), 255);
    EXPECT_EQ(encode_srgb8(-std::numeric_limits<double>::infinity()), 0);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<double>::quiet_NaN()), 0);
}

TEST(EncodeSrgb8, IsContinuousAndMonotonicAcrossTheLinearSegment) {
    // Both pieces of the curve give 0.04045 at the joint (10.31 in 8 bits).
    const double b = 0.0031308;
    EXPECT_EQ(encode_srgb8(std::nextafter(b, 0.0)), 10);
    EXPECT_EQ(encode_srgb8(b), 10);
    unsigned char previous = 0;
    for (int i = 0; i <= 10000; ++i) {
        const unsigned char v = encode_srgb8(i / 10000.0);
        ASSERT_GE(v, previous) << i;
        previous = v;
    }
}

TEST_F(ImageFileTest, PfmRoundTripIsBitExact) {
    Image image = test_pattern();
    image.rgb[4] = std::numeric_limits<float>::infinity();
    image.rgb[5] = -0.0f;
    image.rgb[7] = std::numeric_limits<float>::denorm_min();
    write_image(image, file("a.pfm"));
    const Image back = read_image(file("a.pfm"));
    ASSERT_EQ(back.width, image.width);
    ASSERT_EQ(back.height, image.height);
    ASSERT_EQ(back.rgb.size(), image.rgb.size());
    EXPECT_EQ(std::memcmp(back.rgb.data(), image.rgb.data(), 4 * image.rgb.size()), 0);
}

TEST_F(ImageFileTest, PfmIsLittleEndianFloatRowsBottomUp) {
    Image image(2, 2);
    image.set(0, 0, {1, 2, 3});  // top row
    image.set(1, 0, {4, 5, 6});
    image.set(0, 1, {-0.5, 0.25, 100});  // bottom row
    image.set(1, 1, {7, 8, 9});
    write_image(image, file("a.pfm"));
    const std::string bytes = read_bytes(file("a.pfm"));
    const std::string header = "PF\n2 2\n-1.0\n";
    ASSERT_EQ(bytes.size(), header.size() + 2 * 2 * 3 * 4);
    EXPECT_EQ(bytes.substr(0, header.size()), header);
    const std::vector<float> expected{-0.5f, 0.25f, 100, 7, 8, 9, 1, 2, 3, 4, 5, 6};
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(le32(bytes, header.size() + 4 * i), std::bit_cast<std::uint32_t>(expected[i]))
            << "float " << i;
    }
}

std::string be32_bytes(float f) {
    const auto v = std::bit_cast<std::uint32_t>(f);
    return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
            static_cast<char>(v)};
}

TEST_F(ImageFileTest, ReadsBigEndianAndGreyscalePfm) {
    // Greyscale with a positive scale (big-endian); rows in the file are bottom-up.
    std::string bytes = "Pf\n2 2\n1.0\n";
    for (float v : {1.0f, 2.0f, 3.0f, -4.0f}) bytes += be32_bytes(v);
    write_bytes(file("g.pfm"), bytes);
    const Image image = read_image(file("g.pfm"));
    ASSERT_EQ(image.width, 2);
    ASSERT_EQ(image.height, 2);
    EXPECT_EQ(image.at(0, 0), (Color{3, 3, 3}));
    EXPECT_EQ(image.at(1, 0), (Color{-4, -4, -4}));
    EXPECT_EQ(image.at(0, 1), (Color{1, 1, 1}));
    EXPECT_EQ(image.at(1, 1), (Color{2, 2, 2}));

    bytes = "PF 1 1 +2.5\n";  // any whitespace between header fields
    for (float v : {0.5f, -1.5f, 1e20f}) bytes += be32_bytes(v);
    write_bytes(file("c.pfm"), bytes);
    EXPECT_EQ(read_image(file("c.pfm")).at(0, 0), (Color{0.5, -1.5, 1e20f}));
}

TEST_F(ImageFileTest, PfmDataMayStartWithAWhitespaceByte) {
    // 0x0a0a0a0a as a little-endian float: the reader must not skip it as header whitespace.
    const std::string bytes = "PF\n1 1\n-1\n" + std::string(12, '\n');
    write_bytes(file("w.pfm"), bytes);
    const Image image = read_image(file("w.pfm"));
    EXPECT_EQ(std::bit_cast<std::uint32_t>(image.rgb[0]), 0x0a0a0a0au);
}

TEST_F(ImageFileTest, PngAndBmpStoreSrgbEncodedBytes) {
    Image image = test_pattern(7, 4);
    image.rgb[2] = std::numeric_limits<float>::quiet_NaN();
    for (const char* name : {"a.png", "a.bmp", "A.PNG"}) {
        SCOPED_TRACE(name);
        write_image(image, file(name));
        const Image back = read_image(file(name));
        ASSERT_EQ(back.width, image.width);
        ASSERT_EQ(back.height, image.height);
        for (std::size_t i = 0; i < image.rgb.size(); ++i) {
            const float expected = static_cast<float>(encode_srgb8(image.rgb[i]) / 255.0);
            ASSERT_NEAR(back.rgb[i], expected, 1e-7) << "value " << i;
        }
    }
}

TEST_F(ImageFileTest, PngHeader) {
    write_image(test_pattern(300, 2), file("a.png"));
    const std::string bytes = read_bytes(file("a.png"));
    ASSERT_GE(bytes.size(), 33u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    EXPECT_EQ(be32(bytes, 16), 300u);  // width
    EXPECT_EQ(be32(bytes, 20), 2u);    // height
    EXPECT_EQ(bytes[24], 8);           // bit depth
    EXPECT_EQ(bytes[25], 2);           // colour type: RGB
}

TEST_F(ImageFileTest, BmpHeader) {
    write_image(test_pattern(300, 2), file("a.bmp"));
    const std::string bytes = read_bytes(file("a.bmp"));
    ASSERT_GE(bytes.size(), 54u);
    EXPECT_EQ(bytes.substr(0, 2), "BM");
    EXPECT_EQ(le32(bytes, 2), bytes.size());  // file size
    EXPECT_EQ(le32(bytes, 18), 300u);         // width
    EXPECT_EQ(le32(bytes, 22), 2u);           // height (positive: rows bottom-up)
    EXPECT_EQ(bytes[28], 24);                 // bits per pixel
}

TEST_F(ImageFileTest, OverwritingReplacesTheWholeFileAndLeavesNoTemporaries) {
    for (const char* name : {"a.pfm", "a.png", "a.bmp"}) {
        SCOPED_TRACE(name);
        write_image(test_pattern(40, 30), file(name));
        write_image(test_pattern(2, 1), file(name));
        const Image back = read_image(file(name));
        EXPECT_EQ(back.width, 2);
        EXPECT_EQ(back.height, 1);
    }
    EXPECT_EQ(read_bytes(file("a.pfm")).size(), std::string("PF\n2 1\n-1.0\n").size() + 24);
    EXPECT_EQ(entries().size(), 3u);
}

TEST_F(ImageFileTest, WriteIntoAMissingFolderThrowsAndCreatesNothing) {
    const fs::path target = file("missing/a.png");
    try {
        write_image(test_pattern(), target);
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(target.string() + ": ", 0), 0u) << e.what();
    }
    EXPECT_TRUE(entries().empty());
}

TEST_F(ImageFileTest, WriteBelowARegularFileThrowsAndLeavesNoTemporaries) {
    write_bytes(file("plain"), "x");
    EXPECT_THROW(write_image(test_pattern(), file("plain/a.pfm")), ImageError);
    ASSERT_EQ(entries().size(), 1u);
    EXPECT_EQ(read_bytes(file("plain")), "x");
}

TEST_F(ImageFileTest, FailedRenameRemovesTheTemporaryAndKeepsTheTarget) {
    // Renaming a file over a folder fails only after the data has been written.
    fs::create_directory(file("taken.png"));
    write_bytes(file("taken.png") / "inside", "keep");
    EXPECT_THROW(write_image(test_pattern(), file("taken.png")), ImageError);
    ASSERT_EQ(entries().size(), 1u);
    EXPECT_EQ(read_bytes(file("taken.png") / "inside"), "keep");
}

TEST_F(ImageFileTest, RefusedWriteLeavesAnExistingFileAlone) {
    write_image(test_pattern(), file("a.pfm"));
    const std::string before = read_bytes(file("a.pfm"));
    EXPECT_THROW(write_image(Image(), file("a.pfm")), ImageError);
    EXPECT_THROW(write_image(test_pattern(), file("a.jpg")), ImageError);
    EXPECT_EQ(read_bytes(file("a.pfm")), before);
    EXPECT_EQ(entries().size(), 1u);
}

TEST_F(ImageFileTest, MissingFileThrowsNamingIt) {
    try {
        read_image(file("none.png"));
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_NE(std::string(e.what()).find(file("none.png").string()), std::string::npos);
    }
}

TEST_F(ImageFileTest, TruncatedFilesThrow) {
    for (const char* name : {"a.pfm", "a.png", "a.bmp"}) {
        write_image(test_pattern(), file(name));  // 5 wide: BMP rows carry padding
        const std::string bytes = read_bytes(file(name));
        // Every cut, except into the checksum of a PNG's closing chunk, which stb does not read.
        for (std::size_t keep = 0; keep + 4 < bytes.size(); ++keep) {
            SCOPED_TRACE(std::string(name) + " cut to " + std::to_string(keep));
            write_bytes(file(name), bytes.substr(0, keep));
            ASSERT_THROW(read_image(file(name)), ImageError);
        }
    }
}

TEST_F(ImageFileTest, GarbageThrows) {
    const std::vector<std::string> garbage{
        "hello world",
        std::string(200, '\xff'),
        "PF\n",
        "PF\n2 2\n",
        "PF\n2 2\n-1.0",                           // no data separator
        "PF\n2 2\n-1.0\n" + std::string(47, 'a'),  // one byte short
        "PF\n-2 2\n-1.0\n" + std::string(48, 'a'),
        "PF\n2 0\n-1.0\n",
        "PF\n2x 2\n-1.0\n" + std::string(48, 'a'),
        "PF\n2 2\n0\n" + std::string(48, 'a'),
        "PF\n2 2\nnan\n" + std::string(48, 'a'),
        "PF\n99999999999 1\n-1\n" + std::string(48, 'a'),
        "PF\n1000000 1000000\n-1\n" + std::string(48, 'a'),
        "P6\n2 2\n255\n" + std::string(12, 'a'),
    };
    for (const char* name : {"g.pfm", "g.png", "g.bmp"}) {
        for (const std::string& bytes : garbage) {
            SCOPED_TRACE(std::string(name) + ": " + bytes.substr(0, 20));
            write_bytes(file(name), bytes);
            EXPECT_THROW(read_image(file(name)), ImageError);
        }
    }
}

TEST_F(ImageFileTest, ContentMustMatchTheExtension) {
    write_image(test_pattern(), file("a.png"));
    fs::rename(file("a.png"), file("a.bmp"));
    EXPECT_THROW(read_image(file("a.bmp")), ImageError);
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

// What reading `path` fails with, or "read".
std::string read_error(const fs::path& path) {
    try {
        read_image(path);
    } catch (const ImageError& e) {
        return e.what();
    }
    return "read";
}

std::string be32(std::uint32_t v) {
    return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

TEST_F(ImageFileTest, PixelLimitIsCheckedFromTheHeaderBeforeDecoding) {
    const auto pfm = [&](int w, int h) {
        write_bytes(file("big.pfm"),
                    "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n");
        return read_error(file("big.pfm"));
    };
    EXPECT_EQ(pfm(16384, 8192), file("big.pfm").string() + ": truncated PFM data");  // at it
    EXPECT_EQ(pfm(16385, 8192), file("big.pfm").string() +
                                    ": image of 16385x8192 pixels exceeds the limit of "
                                    "134217728 pixels");
    // A PNG header alone: stb would allocate for the size it gives.
    const auto png = [&](std::uint32_t w, std::uint32_t h) {
        write_bytes(file("big.png"), std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + "IHDR" +
                                         be32(w) + be32(h) + std::string("\x08\x02\0\0\0", 5) +
                                         be32(0));
        return read_error(file("big.png"));
    };
    EXPECT_EQ(png(16384, 8192).find("exceeds"), std::string::npos) << png(16384, 8192);
    EXPECT_EQ(png(16385, 8192), file("big.png").string() +
                                    ": image of 16385x8192 pixels exceeds the limit of "
                                    "134217728 pixels");
}

// Found by fuzzing: a 5 x 3 PNG whose IDAT claims 1.4 GB made stb reserve that much, a second per
// read under the sanitizers.
TEST_F(ImageFileTest, APngChunkLongerThanTheFileIsRefusedBeforeStbMakesRoomForIt) {
    write_image(test_pattern(), file("a.png"));
    std::string bytes = read_bytes(file("a.png"));
    ASSERT_EQ(bytes.substr(37, 4), "IDAT");
    bytes.replace(33, 4, be32(0x52000018));
    write_bytes(file("a.png"), bytes);
    EXPECT_EQ(read_error(file("a.png")),
              file("a.png").string() +
                  ": PNG chunk IDAT claims 1375731736 bytes, more than the file holds");
}

TEST_F(ImageFileTest, FileSizePastTheLimitIsRefusedBeforeReading) {
    write_bytes(file("huge.pfm"), "PF\n1 1\n-1.0\n");
    fs::resize_file(file("huge.pfm"), 12 * (std::uint64_t{1} << 27) + 4096 + 1);  // sparse
    EXPECT_EQ(read_error(file("huge.pfm")),
              file("huge.pfm").string() + ": file larger than the 1536 MiB limit for an image");
}

TEST_F(ImageFileTest, FoldersDevicesAndPipesNamedLikeImagesAreRefused) {
    fs::create_directories(file("folder.png"));
    EXPECT_EQ(read_error(file("folder.png")),
              file("folder.png").string() + ": is a folder, not an image file");
    fs::create_symlink("/dev/zero", file("zero.pfm"));
    EXPECT_EQ(read_error(file("zero.pfm")), file("zero.pfm").string() + ": not a regular file");
    fs::create_symlink("loop.png", file("loop.png"));
    EXPECT_EQ(read_error(file("loop.png")),
              file("loop.png").string() + ": cannot open file: Too many levels of symbolic links");
    // A named pipe nothing writes to: refused at once, where opening it to read would wait for
    // a writer forever.
    ASSERT_EQ(::mkfifo(file("pipe.pfm").c_str(), 0600), 0);
    EXPECT_EQ(read_error(file("pipe.pfm")), file("pipe.pfm").string() + ": not a regular file");
}

TEST_F(ImageFileTest, ControlCharactersInFileNamesAreEscaped) {
    EXPECT_EQ(read_error(file("a\x1b[2J.png")),
              file("a").string() + "\\x1b[2J.png: cannot open file: No such file or directory");
}

}  // namespace
}  // namespace drt
