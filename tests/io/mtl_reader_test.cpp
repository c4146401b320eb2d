#include "drt/io/mtl_reader.h"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

namespace drt {
namespace {

std::vector<MtlMaterial> mtl_of(std::string_view text) {
    return parse_mtl(text, "m.mtl");
}

std::string mtl_error(std::string_view text) {
    try {
        mtl_of(text);
    } catch (const MtlError& e) {
        return e.what();
    }
    return "parsed";
}

void expect_present_color(const std::optional<Color>& c, double r, double g, double b) {
    ASSERT_TRUE(c.has_value());
    EXPECT_DOUBLE_EQ(c->r, r);
    EXPECT_DOUBLE_EQ(c->g, g);
    EXPECT_DOUBLE_EQ(c->b, b);
}

TEST(MtlReader, ReadsTheStatementsOfEachMaterial) {
    const auto m = mtl_of(
        "Kd 9 9 9\n"  // before any newmtl: ignored
        "# comment\n"
        "newmtl red paint\n"
        "Kd 0.9 0.1 0.2\n"
        "Ks 0.5\n"
        "Ns 100\n"
        "Ni 1.33\n"
        "d 0.75\n"
        "Ke 1 2 3\n"
        "illum 2\n"
        "Ka 1 1 1\n"
        "map_Ka whatever.png\n"
        "newmtl glass\r\n"
        "Tr 0.25\r\n"
        "map_Kd -s 2 2 1 -o 0.5 -blendu on my textures\\wood grain.jpg\r\n"
        "map_d alpha.png\n"
        "bump -bm 0.3 maps\\height.png\n");
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m[0].name, "red paint");
    EXPECT_EQ(m[0].line, 3);
    expect_present_color(m[0].kd, 0.9, 0.1, 0.2);
    expect_present_color(m[0].ks, 0.5, 0.5, 0.5);
    expect_present_color(m[0].ke, 1, 2, 3);
    EXPECT_EQ(m[0].ns, 100);
    EXPECT_EQ(m[0].ni, 1.33);
    EXPECT_EQ(m[0].dissolve, 0.75);
    EXPECT_EQ(m[0].illum, 2);
    EXPECT_FALSE(m[0].map_kd);

    EXPECT_EQ(m[1].name, "glass");
    EXPECT_EQ(m[1].dissolve, 0.75);
    EXPECT_FALSE(m[1].kd);
    ASSERT_TRUE(m[1].map_kd);
    EXPECT_EQ(m[1].map_kd->path, "my textures/wood grain.jpg");
    EXPECT_EQ(m[1].map_kd->line, 15);
    ASSERT_TRUE(m[1].map_d);
    EXPECT_EQ(m[1].map_d->path, "alpha.png");
    ASSERT_TRUE(m[1].bump);
    EXPECT_EQ(m[1].bump->path, "maps/height.png");
    EXPECT_DOUBLE_EQ(m[1].bump->bump_multiplier, 0.3);
    EXPECT_EQ(m[1].bump->line, 17);
}

TEST(MtlReader, TheLaterOfDAndTrCounts) {
    EXPECT_EQ(mtl_of("newmtl a\nd 0.2\nTr 0.1\n")[0].dissolve, 0.9);
    EXPECT_EQ(mtl_of("newmtl a\nTr 0.1\nd 0.2\n")[0].dissolve, 0.2);
}

TEST(MtlReader, AMalformedNumberIsAnErrorAtItsLine) {
    EXPECT_EQ(mtl_error("newmtl a\n\nKd 0.5 abc 1\n"), "m.mtl:3: Kd: \"abc\" is not a number");
    EXPECT_EQ(mtl_error("newmtl a\nKd 0.5 0.5\n"), "m.mtl:2: Kd: 1 or 3 values needed, got 2");
    EXPECT_EQ(mtl_error("newmtl a\nKs\n"), "m.mtl:2: Ks: a colour needed");
    EXPECT_EQ(mtl_error("newmtl a\nNs\n"), "m.mtl:2: Ns: a number needed");
    EXPECT_EQ(mtl_error("newmtl a\nNs 1e999\n"), "m.mtl:2: Ns: \"1e999\" is not a finite number");
    EXPECT_EQ(mtl_error("newmtl a\nd nan\n"), "m.mtl:2: d: \"nan\" is not a finite number");
    EXPECT_EQ(mtl_error("newmtl a\r\nNi 1.5x\r\n"), "m.mtl:2: Ni: \"1.5x\" is not a number");
    EXPECT_EQ(mtl_error("newmtl a\nillum 2.5\n"),
              "m.mtl:2: illum: \"2.5\" is not a model from 0 to 10");
    EXPECT_EQ(mtl_error("newmtl a\nmap_Kd -bm x f.png\n"),
              "m.mtl:2: map_Kd: \"x\" is not a number");
    EXPECT_EQ(mtl_error("newmtl a\nmap_Kd -s 1 1 1\n"), "m.mtl:2: map_Kd: a file name needed");
    EXPECT_EQ(mtl_error("newmtl a\nKd 1 1 1 1\n"), "m.mtl:2: Kd: more than 3 values");
}

}  // namespace
}  // namespace drt
