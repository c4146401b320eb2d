#include "drt/scene/xml_attributes.h"

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <array>
#include <string>
#include <string_view>

#include "drt/scene/scene_loader.h"

namespace drt {
namespace {

using namespace std::literals;

constexpr std::array kNames = {"Radius"sv, "Name"sv, "bumpEnable"sv, "Px"sv};

TEST(NearestName, OneEditInThreeCharactersCaseIgnored) {
    EXPECT_EQ(nearest_name("Radus", kNames), "Radius");  // a letter left out
    EXPECT_EQ(nearest_name("Nmae", kNames), "Name");     // two neighbours swapped: one edit
    EXPECT_EQ(nearest_name("bumpenable", kNames), "bumpEnable");  // case only: no edit
    EXPECT_EQ(nearest_name("Py", kNames), "Px");                  // two characters allow one edit
    EXPECT_EQ(nearest_name("Teapot", kNames), std::nullopt);      // nothing close enough
    EXPECT_EQ(nearest_name("Rxxxus", kNames), std::nullopt);      // three edits in six: too many
}

TEST(Trimmed, SpacesTabsAndLineEndsAroundOnly) {
    EXPECT_EQ(trimmed(" \t1.5 cm\r\n"), "1.5 cm");
    EXPECT_EQ(trimmed(" \n "), "");
}

// One element on line 2 of "t.xml", read with a fresh context.
class AttributesTest : public ::testing::Test {
  protected:
    Attributes read(const char* element) {
        xml_ = "<Scene>\n"s + element + "\n</Scene>";
        EXPECT_EQ(doc_.Parse(xml_.c_str()), tinyxml2::XML_SUCCESS);
        return Attributes(*doc_.RootElement()->FirstChildElement(), context_);
    }
    static std::string error_of(auto&& read_value) {
        try {
            read_value();
        } catch (const SceneError& e) {
            return e.what();
        }
        return "read";
    }

    std::string xml_;
    tinyxml2::XMLDocument doc_;
    LoadContext context_{"t.xml"};
};

TEST_F(AttributesTest, NumbersMustBeWhollyFiniteNumbers) {
    Attributes in = read(R"(<E a=" +1.5 " b="1.5cm" c="inf" d="+-1" e="1e999"/>)");
    EXPECT_EQ(in.number("a"), 1.5);  // a leading '+' and spaces around are accepted
    EXPECT_EQ(error_of([&] { in.number("b"); }),
              "t.xml:2: E: attribute 'b' is not a number: \"1.5cm\"");
    EXPECT_EQ(error_of([&] { in.number("c"); }),
              "t.xml:2: E: attribute 'c' is not a number: \"inf\"");
    EXPECT_EQ(error_of([&] { in.number("d"); }),
              "t.xml:2: E: attribute 'd' is not a number: \"+-1\"");
    EXPECT_EQ(error_of([&] { in.number("e"); }),
              "t.xml:2: E: attribute 'e' is out of range: \"1e999\"");
    EXPECT_EQ(in.number("f", 7), 7);
    EXPECT_EQ(error_of([&] { in.number("f"); }), "t.xml:2: E: missing required attribute 'f'");
}

TEST_F(AttributesTest, IntegersFlagsAndRules) {
    Attributes in = read(R"(<E n="-3" s="-3" big="4294967296" f="2" w="0"/>)");
    EXPECT_EQ(in.integer("n", 0), -3);
    EXPECT_EQ(error_of([&] { in.integer("s", std::uint64_t{0}); }),
              "t.xml:2: E: attribute 's' is not a non-negative integer: \"-3\"");
    EXPECT_EQ(error_of([&] { in.integer("big", 0); }),
              "t.xml:2: E: attribute 'big' is out of range: \"4294967296\"");
    EXPECT_EQ(in.integer("big", std::uint64_t{0}), 4294967296u);
    EXPECT_EQ(error_of([&] { in.flag("f", false); }), "t.xml:2: E: f must be 0 or 1, got \"2\"");
    EXPECT_EQ(error_of([&] { in.check(in.number("w") > 0, "w", "positive"); }),
              "t.xml:2: E: w must be positive, got 0");
    EXPECT_EQ(error_of([&] { in.check(false, "absent", "positive"); }),
              "t.xml:2: E: absent must be positive, got (default)");
}

TEST_F(AttributesTest, AttributesNeverAskedForAreWarnedAboutWithTheNearestAskedFor) {
    Attributes in = read(R"(<E Radius="1" Raduis="2" Teapot="3"/>)");
    in.number("Radius");
    in.find("Name");
    in.warn_unknown();
    EXPECT_EQ(context_.take_warnings(),
              (std::vector<std::string>{
                  "t.xml:2: warning: unknown attribute 'Raduis' on <E>; did you mean 'Radius'?",
                  "t.xml:2: warning: unknown attribute 'Teapot' on <E>"}));
}

}  // namespace
}  // namespace drt
