#include "drt/shading/material.h"

#include <gtest/gtest.h>

#include <cmath>

namespace drt {
namespace {

TEST(Fresnel, NormalIncidenceOnGlassReflectsFourPercent) {
    EXPECT_NEAR(fresnel_dielectric(1.0, 1.0 / 1.5), 0.04, 1e-12);
}

TEST(Fresnel, PPolarisedVanishesAtBrewstersAngle) {
    const double brewster = std::atan(1.5);
    const FresnelSP f = fresnel_dielectric_sp(std::cos(brewster), 1.0 / 1.5);
    EXPECT_NEAR(f.p, 0.0, 1e-15);
    EXPECT_GT(f.s, 0.1);
}

TEST(Fresnel, TotalInternalReflectionBeyondTheCriticalAngle) {
    const double critical = std::asin(1.0 / 1.5);
    EXPECT_EQ(fresnel_dielectric(std::cos(critical + 1e-6), 1.5), 1.0);
    EXPECT_LT(fresnel_dielectric(std::cos(critical - 1e-3), 1.5), 1.0);
}

TEST(Fresnel, IndexOneTransmitsEverything) {
    for (double c : {0.0, 0.1, 0.5, 1.0}) EXPECT_EQ(fresnel_dielectric(c, 1.0), 0.0) << c;
}

TEST(Fresnel, GrazingIncidenceReflectsEverything) {
    EXPECT_NEAR(fresnel_dielectric(0.0, 1.0 / 1.5), 1.0, 1e-12);
}

TEST(Refract, SnellsLawHolds) {
    const double theta = 0.5;
    const Vec3 d{std::sin(theta), -std::cos(theta), 0};
    const auto t = refract(d, {0, 1, 0}, 1.0 / 1.5);
    ASSERT_TRUE(t);
    EXPECT_NEAR(std::sin(theta) / 1.5, t->x, 1e-14);
    EXPECT_LT(t->y, 0);
    EXPECT_NEAR(length(*t), 1.0, 1e-14);
}

TEST(Refract, NoDirectionUnderTotalInternalReflection) {
    const Vec3 d = normalize(Vec3{1, -0.2, 0});
    EXPECT_FALSE(refract(d, {0, 1, 0}, 1.5));
}

// A path picks a part in proportion to the luminance of what it passes on; a part the material
// lacks (its factor 0, or a black colour) weighs nothing.
TEST(Material, PartWeightsAreTheLuminanceOfWhatEachPartPassesOn) {
    Material m;
    m.diffuse = 0.5;
    m.reflective = 0.25;
    m.ks = {1, 0, 0};
    m.transmit = 0.75;
    m.kt = {0, 0, 0};                                           // black: no transparent part
    const Material::PartWeights w = m.part_weights({0, 1, 0});  // the point's kd, textured
    EXPECT_DOUBLE_EQ(w.diffuse, 0.5 * 0.7152);
    EXPECT_DOUBLE_EQ(w.reflect, 0.25 * 0.2126);
    EXPECT_EQ(w.transmit, 0);
    m.diffuse = 0;
    EXPECT_EQ(m.part_weights({1, 1, 1}).diffuse, 0);
}

}  // namespace
}  // namespace drt
