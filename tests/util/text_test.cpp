#include "drt/util/text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace drt {
namespace {

TEST(Text, PrintableEscapesWhatATerminalWouldActOn) {
    EXPECT_EQ(printable("plain text, é and ✓"), "plain text, é and ✓");
    EXPECT_EQ(printable("\x1b[31mred"), "\\x1b[31mred");
    EXPECT_EQ(printable("two\nlines\ttab\r"), "two\\x0alines\\x09tab\\x0d");
    EXPECT_EQ(printable(std::string("nul\0byte", 8)), "nul\\x00byte");
    EXPECT_EQ(printable("del\x7f"), "del\\x7f");
    // C1 controls as UTF-8 (U+009B is CSI), but not the letters that share their first byte.
    EXPECT_EQ(printable("\xc2\x9b"
                        "2J"),
              "\\xc2\\x9b2J");
    EXPECT_EQ(printable("\xc2\xa0"), "\xc2\xa0");
    // A C1 control's C2 escaped, then the C1 byte left alone is no character either.
    EXPECT_EQ(printable("\xc2\x85"), "\\xc2\\x85");
    // Bytes of no UTF-8 character (a raw CSI, a cut sequence, an overlong form, a surrogate),
    // each escaped; the well-formed characters around them kept.
    EXPECT_EQ(printable("a\x9b"
                        "2J"),
              "a\\x9b2J");
    EXPECT_EQ(printable("\xe2\x9c"), "\\xe2\\x9c");
    EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");
    EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");
    EXPECT_EQ(printable("\xf0\x9f\x98\x80 \xff"), "\xf0\x9f\x98\x80 \\xff");
    // A backslash is doubled, so that an escape in the output can only have come from us.
    EXPECT_EQ(printable("a\\x1b"), "a\\\\x1b");
}

TEST(Text, AbbreviatedKeepsShortValuesAndCutsLongOnes) {
    EXPECT_EQ(abbreviated("-3"), "-3");
    const std::string at_limit(24, '7');
    EXPECT_EQ(abbreviated(at_limit), at_limit);
    const std::string huge = "-1" + std::string(308, '0');
    EXPECT_EQ(abbreviated(huge), "-1000000000000000000... (310 characters)");
    EXPECT_EQ(abbreviated(std::string(25, '9')), "99999999999999999999... (25 characters)");
}

TEST(Text, ShortNumberHasAtMostSixDigits) {
    EXPECT_EQ(short_number(1e39), "1e+39");
    EXPECT_EQ(short_number(0.5), "0.5");
    EXPECT_EQ(short_number(65544), "65544");
    EXPECT_EQ(short_number(std::numeric_limits<double>::max()), "1.79769e+308");
    EXPECT_EQ(short_number(std::nan("")), "nan");
}

}  // namespace
}  // namespace drt
