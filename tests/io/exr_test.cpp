// OpenEXR files through write_image/read_image, checked against the OpenEXR library itself.
#include "drt/io/exr.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <half.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "run_drt.h"
#include "sanitizers.h"

namespace drt {
namespace {

namespace fs = std::filesystem;
using test::read_bytes, test::write_bytes;

class ExrTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("drt_exr_test_" + std::to_string(getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path file(const std::string& name) const { return dir_ / name; }

    fs::path dir_;
};

// Values a float round trip could lose: above half's range, below its precision, negative,
// subnormal, infinite and NaN, and a different value in every channel of every pixel.
Image awkward_image(int w = 7, int h = 5) {
    Image image(w, h);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        image.rgb[i] = static_cast<float>(std::sin(0.37 * i) * std::pow(10.0, int(i % 9) - 4));
    }
    image.rgb[0] = 1e30f;
    image.rgb[1] = std::numeric_limits<float>::denorm_min();
    image.rgb[2] = -0.0f;
    image.rgb[3] = std::numeric_limits<float>::infinity();
    image.rgb[4] = std::numeric_limits<float>::quiet_NaN();
    image.rgb[5] = 1.0f + std::numeric_limits<float>::epsilon();
    return image;
}

TEST(ExrFormat, IsLinear) {
    EXPECT_TRUE(is_linear(ImageFormat::kExr));
    EXPECT_TRUE(is_linear(ImageFormat::kPfm));
    EXPECT_FALSE(is_linear(ImageFormat::kPng));
    EXPECT_FALSE(is_linear(ImageFormat::kBmp));
}

TEST_F(ExrTest, FloatRoundTripIsBitExact) {
    const Image image = awkward_image();
    write_image(image, file("a.exr"));
    const Image back = read_image(file("a.exr"));
    ASSERT_EQ(back.width, image.width);
    ASSERT_EQ(back.height, image.height);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(back.rgb[i]),
                  std::bit_cast<std::uint32_t>(image.rgb[i]))
            << "value " << i << ": " << image.rgb[i];
    }
}

TEST_F(ExrTest, HalfRoundTripIsWithinHalfPrecision) {
    Image image = awkward_image();
    image.rgb[0] = 60000.0f;  // within half's range (largest 65504)
    ImageWriteOptions options;
    options.half = true;
    write_image(image, file("h.exr"), options);
    const Image back = read_image(file("h.exr"));
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        const float x = image.rgb[i], y = back.rgb[i];
        if (std::isnan(x)) {
            EXPECT_TRUE(std::isnan(y)) << i;
        } else if (std::isinf(x)) {
            EXPECT_EQ(y, x) << i;
        } else {
            // Rounding to nearest: half of an ulp, 2^-11 relative for normal halves; below
            // half's smallest normal (2^-14) the spacing is fixed at 2^-24.
            const double bound = std::max(std::abs(double(x)) * 0x1p-11, 0x1p-25);
            EXPECT_LE(std::abs(double(y) - x), bound) << "value " << i << ": " << x;
        }
    }
    // Half is half the size: the channels really are 16-bit.
    Imf::InputFile in(file("h.exr").c_str());
    EXPECT_EQ(in.header().channels().findChannel("R")->type, Imf::HALF);
    write_image(image, file("f.exr"));
    EXPECT_EQ(Imf::InputFile(file("f.exr").c_str()).header().channels().findChannel("G")->type,
              Imf::FLOAT);
}

TEST_F(ExrTest, AttributesAreReadableWithOpenExr) {
    ImageWriteOptions options;
    options.attributes = {
        {"scene", std::string("scenes/x.xml")}, {"samplesPerPixel", 16}, {"renderSeconds", 1.25}};
    write_image(awkward_image(), file("a.exr"), options);
    Imf::InputFile in(file("a.exr").c_str());
    const Imf::Header& h = in.header();
    ASSERT_NE(h.findTypedAttribute<Imf::StringAttribute>("scene"), nullptr);
    EXPECT_EQ(h.findTypedAttribute<Imf::StringAttribute>("scene")->value(), "scenes/x.xml");
    ASSERT_NE(h.findTypedAttribute<Imf::IntAttribute>("samplesPerPixel"), nullptr);
    EXPECT_EQ(h.findTypedAttribute<Imf::IntAttribute>("samplesPerPixel")->value(), 16);
    ASSERT_NE(h.findTypedAttribute<Imf::DoubleAttribute>("renderSeconds"), nullptr);
    EXPECT_EQ(h.findTypedAttribute<Imf::DoubleAttribute>("renderSeconds")->value(), 1.25);
}

// Files drt does not write itself: a luminance-only image, and a data window not at the origin.
TEST_F(ExrTest, ReadsLuminanceOnlyAndOffsetDataWindows) {
    const int w = 3, h = 2;
    std::vector<float> y{0.5f, 1.5f, 2.5f, 3.5f, 4.5f, 5.5f};
    {
        Imf::Header header(w, h);
        header.dataWindow() = Imath::Box2i({10, -4}, {10 + w - 1, -4 + h - 1});
        header.displayWindow() = header.dataWindow();
        header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
        Imf::FrameBuffer frame;
        frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, y.data(), header.dataWindow()));
        Imf::OutputFile out(file("y.exr").c_str(), header);
        out.setFrameBuffer(frame);
        out.writePixels(h);
    }
    const Image image = read_image(file("y.exr"));
    ASSERT_EQ(image.width, w);
    ASSERT_EQ(image.height, h);
    EXPECT_EQ(image.at(0, 0), (Color{0.5, 0.5, 0.5}));
    EXPECT_EQ(image.at(2, 1), (Color{5.5, 5.5, 5.5}));
}

TEST_F(ExrTest, AnImageWithoutColourChannelsIsRefused) {
    {
        Imf::Header header(2, 2);
        header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
        std::vector<float> z(4, 1.0f);
        Imf::FrameBuffer frame;
        frame.insert("Z", Imf::Slice::Make(Imf::FLOAT, z.data(), header.dataWindow()));
        Imf::OutputFile out(file("z.exr").c_str(), header);
        out.setFrameBuffer(frame);
        out.writePixels(2);
    }
    try {
        read_image(file("z.exr"));
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_EQ(std::string(e.what()),
                  file("z.exr").string() + ": OpenEXR image has neither R, G, B nor Y channels");
    }
}

// An attribute that claims more bytes than the file holds is refused before OpenEXR, which would
// first make room for all of them (a 2 GB string from a file of 40 bytes, found by fuzzing).
TEST(ExrDecode, AnAttributeLargerThanTheFileIsRefusedBeforeOpenExrReadsIt) {
    std::vector<unsigned char> data{0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
    for (const char c : std::string("comments")) data.push_back(static_cast<unsigned char>(c));
    data.push_back(0);
    for (const char c : std::string("string")) data.push_back(static_cast<unsigned char>(c));
    data.insert(data.end(), {0, 0xff, 0xff, 0xff, 0x7f, 'a', 'b', 0});
    try {
        decode_exr(data, "claims.exr");
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "claims.exr: OpenEXR attribute comments claims "
                  "2147483647 bytes, more than the file holds");
    }
    // The same attribute with the size it has is only an incomplete header to OpenEXR.
    data[data.size() - 7] = 3, data[data.size() - 6] = data[data.size() - 5] = 0;
    data[data.size() - 4] = 0;
    try {
        decode_exr(data, "claims.exr");
        FAIL() << "no exception";
    } catch (const ImageError& e) {
        EXPECT_EQ(std::string(e.what()).find("claims "), std::string::npos) << e.what();
    }
}

// OpenEXR throws its own exceptions for bad data; every one must arrive as an ImageError naming
// the file, whether the file is cut short anywhere or has any byte changed.
TEST_F(ExrTest, TruncatedOrCorruptFilesThrowImageErrors) {
    write_image(awkward_image(16, 8), file("a.exr"));
    const std::string bytes = read_bytes(file("a.exr"));
    // The thousands of variants are decoded from memory: the decoder is what they test, and
    // rewriting a file that many times is slow on some disks.
    const fs::path bad = file("bad.exr");
    const auto decode = [&](const std::string& data) {
        decode_exr(std::vector<unsigned char>(data.begin(), data.end()), bad);
    };
#if defined(DRT_TEST_ASAN)
    // Under ASan a variant is slow (it clears the shadow of the large tables OpenEXR allocates
    // from a corrupt header): the sanitizer build tries every 7th, Release all of them.
    constexpr std::size_t kEvery = 7;
#else
    constexpr std::size_t kEvery = 1;
#endif
    for (std::size_t keep = 0; keep < bytes.size(); keep += kEvery) {
        SCOPED_TRACE("cut to " + std::to_string(keep) + " of " + std::to_string(bytes.size()));
        try {
            decode(bytes.substr(0, keep));
            FAIL() << "no exception";
        } catch (const ImageError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(bad.string() + ": ", 0), 0u) << e.what();
        }
    }
    // Every byte of the header and offset table, and a sample of the pixel data, set to values
    // that break sizes, types and offsets. Some changes leave a readable image (a pixel value
    // changes); none may escape as anything but an ImageError.
    int refused = 0;
    for (std::size_t i = 0; i < bytes.size(); i += i < 400 ? kEvery : 37) {
        for (const unsigned char v : {0x00, 0x7f, 0xff}) {
            std::string changed = bytes;
            changed[i] = static_cast<char>(v);
            try {
                decode(changed);
            } catch (const ImageError&) {
                ++refused;
            }
        }
    }
    EXPECT_GT(refused, 50 / static_cast<int>(kEvery));
    // Through the file reader too: a cut file and garbage.
    for (const std::string& garbage :
         {bytes.substr(0, bytes.size() / 2), std::string("v/1\x01"), std::string(100, '\0'),
          std::string("hello"), std::string()}) {
        write_bytes(bad, garbage);
        EXPECT_THROW(read_image(bad), ImageError);
    }
}

// The image and a single channel are read through one opening, so they refuse a file alike: here
// one whose writer stopped after a quarter of its rows (OpenEXR leaves the offsets of the blocks
// it never wrote at 0).
TEST_F(ExrTest, TheChannelReaderRefusesWhatTheImageReaderRefuses) {
    {
        Imf::Header header(16, 64);
        for (const char* name : {"R", "G", "B"}) header.channels().insert(name, Imf::FLOAT);
        std::vector<float> values(3 * 16 * 64, 0.5f);
        Imf::FrameBuffer frame;
        for (int c = 0; c < 3; ++c) {
            frame.insert(c == 0   ? "R"
                         : c == 1 ? "G"
                                  : "B",
                         Imf::Slice::Make(Imf::FLOAT, values.data() + c, header.dataWindow(),
                                          3 * sizeof(float), 3 * sizeof(float) * 16));
        }
        Imf::OutputFile out(file("part.exr").c_str(), header);
        out.setFrameBuffer(frame);
        out.writePixels(16);
    }
    const std::string part = read_bytes(file("part.exr"));
    const std::vector<unsigned char> data(part.begin(), part.end());
    const auto message = [](const auto& read) {
        try {
            read();
        } catch (const ImageError& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    const std::string truncated = file("part.exr").string() + ": truncated OpenEXR file";
    EXPECT_EQ(message([&] { decode_exr(data, file("part.exr")); }), truncated);
    EXPECT_EQ(message([&] { decode_exr_channel(data, "G", file("part.exr")); }), truncated);
    write_image(awkward_image(16, 8), file("a.exr"));
    const std::string bytes = read_bytes(file("a.exr"));
    const std::vector<unsigned char> whole(bytes.begin(), bytes.end());
    EXPECT_EQ(message([&] { decode_exr_channel(whole, "depth.Z", file("a.exr")); }),
              file("a.exr").string() + ": OpenEXR image has no channel depth.Z");
    EXPECT_EQ(decode_exr_channel(whole, "G", file("a.exr")).size(), 16u * 8u);
}

TEST_F(ExrTest, WritingIsAtomicLikeTheOtherFormats) {
    write_bytes(file("a.exr"), "old");
    write_image(awkward_image(), file("a.exr"));
    EXPECT_EQ(read_image(file("a.exr")).width, 7);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
    EXPECT_THROW(write_image(awkward_image(), file("missing/a.exr")), ImageError);
}

}  // namespace
}  // namespace drt
