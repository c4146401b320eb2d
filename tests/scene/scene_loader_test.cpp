#include "drt/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <array>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

#include "drt/accel/bvh.h"
#include "drt/accel/mesh.h"
#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "test_math.h"

namespace drt {
namespace {

using testing::expect_color;

using namespace std::literals;

LoadedScene load(std::string_view xml) {
    return load_scene_from_string(xml, "t.xml");
}

// The body goes between <Scene> (line 1) and </Scene>, so its first line is line 2.
std::string in_scene(std::string_view body) {
    return "<Scene>\n" + std::string(body) + "\n</Scene>\n";
}

// The message a scene fails with, or "loaded" if it does not fail.
std::string error_of(std::string_view xml) {
    try {
        load(xml);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "loaded";
}
std::string body_error(std::string_view body) {
    return error_of(in_scene(body));
}

std::vector<std::string> warnings_of(std::string_view body) {
    return load(in_scene(body)).warnings;
}

constexpr std::string_view kGray = "<Materials><Gray/></Materials>";

const Sphere& sphere(const Scene& scene, std::size_t i) {
    return dynamic_cast<const Sphere&>(*scene.objects.at(i));
}
const Plane& plane(const Scene& scene, std::size_t i) {
    return dynamic_cast<const Plane&>(*scene.objects.at(i));
}

void expect_vec(const Vec3& v, double x, double y, double z) {
    EXPECT_DOUBLE_EQ(v.x, x);
    EXPECT_DOUBLE_EQ(v.y, y);
    EXPECT_DOUBLE_EQ(v.z, z);
}
// ---------------------------------------------------------------------------------------------
// Defaults

TEST(SceneLoaderDefaults, EmptySceneTakesEverySettingsDefault) {
    const LoadedScene loaded = load("<Scene/>");
    const Scene& s = loaded.scene;
    EXPECT_EQ(s.path, "t.xml");
    EXPECT_EQ(s.settings.width, 640);
    EXPECT_EQ(s.settings.height, 480);
    EXPECT_EQ(s.settings.samples, 16);
    EXPECT_EQ(s.settings.shadow_rays, 1);
    EXPECT_EQ(s.settings.max_depth, 8);
    EXPECT_EQ(s.settings.glossy_rays, 1);
    EXPECT_EQ(s.settings.seed, 0u);
    EXPECT_EQ(s.settings.sampler, "stratified");
    expect_color(s.background, 0, 0, 0);
    expect_color(s.ambient, 0, 0, 0);
    EXPECT_FALSE(s.view.has_value());
    EXPECT_TRUE(s.lens.is_pinhole());
    EXPECT_TRUE(s.materials.empty());
    EXPECT_TRUE(s.lights.empty());
    EXPECT_TRUE(s.objects.empty());
    EXPECT_TRUE(loaded.warnings.empty());
}

TEST(SceneLoaderDefaults, WithoutCameraTheThesisPixelPlaneCameraIsUsed) {
    const Scene s = load(in_scene(R"(<Image Width="200" Height="100"/>)")).scene;
    EXPECT_FALSE(s.view.has_value());
    const Camera c = s.camera();
    expect_vec(c.eye(), 100, 50, -200);
    expect_vec(c.forward(), 0, 0, 1);
    // Pixel (0, 0)'s centre lies at world (0.5, 99.5, 0) on the image plane z = 0.
    const Ray r = c.generate_ray({0.5, 0.5}, {0.5, 0.5}, 0);
    const Vec3 hit = r.at(-r.origin.z / r.dir.z);
    EXPECT_NEAR(hit.x, 0.5, 1e-9);
    EXPECT_NEAR(hit.y, 99.5, 1e-9);
}

TEST(SceneLoaderDefaults, CameraUpAndFovDefault) {
    const Scene s = load(in_scene(R"(<Camera Ex="1" Ey="2" Ez="3" Lx="4" Ly="5" Lz="6"/>)")).scene;
    ASSERT_TRUE(s.view.has_value());
    expect_vec(s.view->eye, 1, 2, 3);
    expect_vec(s.view->target, 4, 5, 6);
    expect_vec(s.view->up, 0, 1, 0);
    EXPECT_DOUBLE_EQ(s.view->fov_degrees, 45);
}

TEST(SceneLoaderDefaults, MaterialDefaults) {
    const Scene s = load(in_scene("<Materials><Plain/></Materials>")).scene;
    ASSERT_EQ(s.materials.size(), 1u);
    const Material& m = *s.materials[0];
    EXPECT_EQ(m.name, "Plain");
    EXPECT_DOUBLE_EQ(m.diffuse, 0);
    expect_color(m.kd, 0.8, 0.8, 0.8);
    EXPECT_DOUBLE_EQ(m.reflective, 0);
    expect_color(m.ks, 1, 1, 1);
    EXPECT_DOUBLE_EQ(m.transmit, 0);
    expect_color(m.kt, 1, 1, 1);
    EXPECT_DOUBLE_EQ(m.index, 1.5);
    EXPECT_FALSE(m.sharpness.has_value());
}

TEST(SceneLoaderDefaults, LightWithoutRadiusIsAWhitePointLight) {
    const Scene s = load(in_scene(R"(<Light Px="1" Py="2" Pz="3"/>)")).scene;
    ASSERT_EQ(s.lights.size(), 1u);
    const Light& l = *s.lights[0];
    EXPECT_TRUE(l.is_point());
    ASSERT_NE(dynamic_cast<const PointLight*>(&l), nullptr);
    expect_color(l.intensity(), 1, 1, 1);
    EXPECT_FALSE(l.visible());
    const LightSample toward = l.sample({1, 2, 0}, {0.5, 0.5});
    expect_vec(toward.dir, 0, 0, 1);
    EXPECT_DOUBLE_EQ(toward.distance, 3);
}

TEST(SceneLoaderDefaults, LightWithRadiusIsAnInvisibleSphereLight) {
    const Scene s = load(in_scene(R"(<Light Px="1" Py="2" Pz="3" Radius="4"/>)")).scene;
    const auto* l = dynamic_cast<const SphereLight*>(s.lights.at(0).get());
    ASSERT_NE(l, nullptr);
    expect_vec(l->centre(), 1, 2, 3);
    EXPECT_DOUBLE_EQ(l->radius(), 4);
    expect_color(l->intensity(), 1, 1, 1);
    EXPECT_FALSE(l->visible());
}

TEST(SceneLoaderDefaults, ObjectsHaveNoTextureOrBumpUnlessEnabled) {
    const Scene s = load(in_scene(std::string(kGray) + R"(
        <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Gray" TextureScale="7"/>
        <Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Gray" BumpScale="3"/>)"))
                        .scene;
    ASSERT_EQ(s.objects.size(), 2u);
    for (const auto& o : s.objects) {
        EXPECT_EQ(o->detail().texture, nullptr);
        EXPECT_FALSE(o->detail().bump.has_value());
    }
    EXPECT_FALSE(s.objects[1]->moves());
}

TEST(SceneLoaderDefaults, EnabledTextureIsACheckerOfScale50BetweenKdAndDarkGray) {
    const Scene s = load(in_scene(R"(<Materials><Red kdr="1" kdg="0" kdb="0"/></Materials>
        <Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Red" EnableTexture="1"/>)"))
                        .scene;
    const auto& texture = s.objects.at(0)->detail().texture;
    ASSERT_NE(texture, nullptr);
    ASSERT_NE(dynamic_cast<const CheckerTexture*>(texture.get()), nullptr);
    expect_color(texture->value({{49, 1, 1}, {}, {}, {}}), 1, 0, 0);
    expect_color(texture->value({{51, 1, 1}, {}, {}, {}}), 0.1, 0.1, 0.1);
}

TEST(SceneLoaderDefaults, EnabledBumpHasScale20AndStrength03) {
    const Scene s = load(in_scene(std::string(kGray) +
                                  R"(<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Gray"
                                             bumpEnable="1"/>)"))
                        .scene;
    const auto& bump = s.objects.at(0)->detail().bump;
    ASSERT_TRUE(bump.has_value());
    EXPECT_DOUBLE_EQ(bump->scale, 20);
    EXPECT_DOUBLE_EQ(bump->strength, 0.3);
}

// ---------------------------------------------------------------------------------------------
// Everything given

TEST(SceneLoader, ReadsTheContractExample) {
    const LoadedScene loaded = load(R"(<?xml version="1.0"?>
<Scene>
  <Image Width="600" Height="500"/>
  <Render Samples="100" ShadowRays="10" MaxDepth="5" GlossyRays="3" Seed="42"/>
  <Background r="0.1" g="0.2" b="0.3"/>
  <Ambient r="0.4" g="0.5" b="0.6"/>
  <Camera Ex="300" Ey="250" Ez="-600" Lx="300" Ly="250" Lz="0" Ux="1" Uy="1" Uz="0" Fov="30"/>
  <DepthOfField Radius="15" Focal="800"/>
  <Materials>
    <GrayLambert kdr="0.7" kdg="0.6" kdb="0.5" diffuse="1.0" reflective="0.25" transmitt="0.125"
                 ksr="0.1" ksg="0.2" ksb="0.3" ktr="0.4" ktg="0.5" ktb="0.6" index="1.3" n="500"/>
  </Materials>
  <Lights>
    <Light Px="300" Py="450" Pz="300" Radius="40" Ir="0.5" Ig="0.25" Ib="2" Visible="1"/>
  </Lights>
  <Objects>
    <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="GrayLambert"/>
    <Sphere Px="300" Py="100" Pz="300" Radius="100" Material="GrayLambert"/>
  </Objects>
</Scene>)");
    EXPECT_TRUE(loaded.warnings.empty());
    const Scene& s = loaded.scene;
    EXPECT_EQ(s.settings.width, 600);
    EXPECT_EQ(s.settings.height, 500);
    EXPECT_EQ(s.settings.samples, 100);
    EXPECT_EQ(s.settings.shadow_rays, 10);
    EXPECT_EQ(s.settings.max_depth, 5);
    EXPECT_EQ(s.settings.glossy_rays, 3);
    EXPECT_EQ(s.settings.seed, 42u);
    expect_color(s.background, 0.1, 0.2, 0.3);
    expect_color(s.ambient, 0.4, 0.5, 0.6);
    ASSERT_TRUE(s.view.has_value());
    expect_vec(s.view->eye, 300, 250, -600);
    expect_vec(s.view->target, 300, 250, 0);
    expect_vec(s.view->up, 1, 1, 0);
    EXPECT_DOUBLE_EQ(s.view->fov_degrees, 30);
    EXPECT_DOUBLE_EQ(s.lens.radius, 15);
    EXPECT_DOUBLE_EQ(s.lens.focal, 800);

    ASSERT_EQ(s.materials.size(), 1u);
    const Material& m = *s.materials[0];
    EXPECT_EQ(m.name, "GrayLambert");
    EXPECT_DOUBLE_EQ(m.diffuse, 1.0);
    expect_color(m.kd, 0.7, 0.6, 0.5);
    EXPECT_DOUBLE_EQ(m.reflective, 0.25);
    expect_color(m.ks, 0.1, 0.2, 0.3);
    EXPECT_DOUBLE_EQ(m.transmit, 0.125);
    expect_color(m.kt, 0.4, 0.5, 0.6);
    EXPECT_DOUBLE_EQ(m.index, 1.3);
    ASSERT_TRUE(m.sharpness.has_value());
    EXPECT_DOUBLE_EQ(*m.sharpness, 500);

    const auto* light = dynamic_cast<const SphereLight*>(s.lights.at(0).get());
    ASSERT_NE(light, nullptr);
    expect_vec(light->centre(), 300, 450, 300);
    EXPECT_DOUBLE_EQ(light->radius(), 40);
    expect_color(light->intensity(), 0.5, 0.25, 2);
    EXPECT_TRUE(light->visible());

    ASSERT_EQ(s.objects.size(), 2u);
    expect_vec(plane(s, 0).normal(), 0, 1, 0);
    EXPECT_EQ(&plane(s, 0).material(), &m);
    expect_vec(sphere(s, 1).path().points().at(0), 300, 100, 300);
    EXPECT_EQ(sphere(s, 1).path().points().size(), 1u);
    EXPECT_DOUBLE_EQ(sphere(s, 1).radius(), 100);
    EXPECT_EQ(&sphere(s, 1).material(), &m);
}

TEST(SceneLoader, RenderAcceptsASamplerName) {
    EXPECT_EQ(load(in_scene(R"(<Render Sampler="random"/>)")).scene.settings.sampler, "random");
    EXPECT_EQ(load(in_scene(R"(<Render Sampler="sobol"/>)")).scene.settings.sampler, "sobol");
}

TEST(SceneLoader, SeedTakesTheFull64BitRange) {
    const Scene s = load(in_scene(R"(<Render Seed="18446744073709551615"/>)")).scene;
    EXPECT_EQ(s.settings.seed, 18446744073709551615u);
}

TEST(SceneLoader, NumbersMayHaveSurroundingSpaceALeadingPlusAndAnExponent) {
    const Scene s = load(in_scene(R"(<Image Width=" +64 " Height="	48
"/><Background r="+0.5" g=" 1e-1" b="-2.5E1 "/>)"))
                        .scene;
    EXPECT_EQ(s.settings.width, 64);
    EXPECT_EQ(s.settings.height, 48);
    expect_color(s.background, 0.5, 0.1, -25);
}

TEST(SceneLoader, BothMaterialStylesDefineNamedMaterials) {
    const Scene s = load(in_scene(R"(<Materials>
        <Glass ktr="0.1" transmitt="1" index="1.6" n="1000"/>
        <Material Name="Mirror" ksg="0.5" reflective="1" transmit="0.5"/>
    </Materials>)"))
                        .scene;
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[0]->name, "Glass");
    EXPECT_DOUBLE_EQ(s.materials[0]->kt.r, 0.1);
    EXPECT_DOUBLE_EQ(s.materials[0]->transmit, 1);
    EXPECT_DOUBLE_EQ(s.materials[0]->index, 1.6);
    EXPECT_DOUBLE_EQ(*s.materials[0]->sharpness, 1000);
    EXPECT_EQ(s.materials[1]->name, "Mirror");
    EXPECT_DOUBLE_EQ(s.materials[1]->ks.g, 0.5);
    EXPECT_DOUBLE_EQ(s.materials[1]->reflective, 1);
    EXPECT_DOUBLE_EQ(s.materials[1]->transmit, 0.5);  // the single-t spelling
    EXPECT_EQ(s.find_material("Mirror"), s.materials[1].get());
}

TEST(SceneLoader, MaterialsMayBeDefinedAfterTheObjectsUsingThem) {
    const Scene s = load(in_scene(R"(
        <Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Late"/>
        <Materials><Early/></Materials>
        <Materials><Late kdr="0.25"/></Materials>)"))
                        .scene;
    ASSERT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(s.objects[0]->material().name, "Late");
    EXPECT_EQ(&s.objects[0]->material(), s.find_material("Late"));
    EXPECT_DOUBLE_EQ(s.objects[0]->material().kd.r, 0.25);
}

TEST(SceneLoader, WrappersAreOptionalAndDocumentOrderIsKept) {
    const LoadedScene loaded = load(in_scene(std::string(kGray) + R"(
        <Light Px="1" Py="0" Pz="0"/>
        <Sphere Px="1" Py="0" Pz="0" Radius="1" Material="Gray"/>
        <Lights><Light Px="2" Py="0" Pz="0" Radius="1"/></Lights>
        <Objects><Plane Px="0" Py="2" Pz="0" Vu="0" Vv="0" Vw="1" Material="Gray"/></Objects>
        <Plane Px="0" Py="3" Pz="0" Vu="1" Vv="0" Vw="0" Material="Gray"/>)"));
    EXPECT_TRUE(loaded.warnings.empty());
    const Scene& s = loaded.scene;
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_TRUE(s.lights[0]->is_point());
    EXPECT_FALSE(s.lights[1]->is_point());
    ASSERT_EQ(s.objects.size(), 3u);
    expect_vec(sphere(s, 0).path().points()[0], 1, 0, 0);
    expect_vec(plane(s, 1).normal(), 0, 0, 1);
    expect_vec(plane(s, 2).normal(), 1, 0, 0);
}

TEST(SceneLoader, PlaneNormalIsNormalised) {
    const Scene s = load(in_scene(std::string(kGray) + R"(
        <Plane Px="0" Py="0" Pz="0" Vu="3" Vv="4" Vw="0" Material="Gray"/>
        <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="0" Vw="1e-300" Material="Gray"/>)"))
                        .scene;
    EXPECT_NEAR(plane(s, 0).normal().x, 0.6, 1e-15);
    EXPECT_NEAR(plane(s, 0).normal().y, 0.8, 1e-15);
    EXPECT_NEAR(plane(s, 0).normal().z, 0.0, 1e-15);
    expect_vec(plane(s, 1).normal(), 0, 0, 1);
}

TEST(SceneLoader, MotionBlurPositionsFollowThePresentPositionInOrder) {
    const Scene s = load(in_scene(std::string(kGray) + R"(
        <Sphere Px="10" Py="20" Pz="30" Radius="5" Material="Gray">
            <MotionBlurPosition Px="11" Py="20" Pz="30"/>
            <MotionBlurPosition Px="13" Py="21" Pz="30"/>
            <MotionBlurPosition Px="16" Py="22" Pz="31"/>
        </Sphere>)"))
                        .scene;
    const Sphere& sp = sphere(s, 0);
    ASSERT_EQ(sp.path().points().size(), 4u);
    expect_vec(sp.path().points()[0], 10, 20, 30);
    expect_vec(sp.path().points()[1], 11, 20, 30);
    expect_vec(sp.path().points()[2], 13, 21, 30);
    expect_vec(sp.path().points()[3], 16, 22, 31);
    EXPECT_DOUBLE_EQ(sp.motion_end(), 3);
    EXPECT_DOUBLE_EQ(s.shutter_end(), 3);
}

TEST(SceneLoader, TextureAttributesAreRead) {
    const Scene s = load(in_scene(R"(<Materials><Blue kdr="0" kdg="0" kdb="1"/></Materials>
        <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Blue" EnableTexture="1"
               Texture="checker" TextureScale="10" k2r="1" k2g="0.5" k2b="0.25"/>
        <Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Blue" EnableTexture="1"
                Texture="marble" TextureScale="3"/>)"))
                        .scene;
    const auto& checker = s.objects.at(0)->detail().texture;
    ASSERT_NE(dynamic_cast<const CheckerTexture*>(checker.get()), nullptr);
    expect_color(checker->value({{9, 1, 1}, {}, {}, {}}), 0, 0, 1);
    expect_color(checker->value({{11, 1, 1}, {}, {}, {}}), 1, 0.5, 0.25);

    const auto& marble = s.objects.at(1)->detail().texture;
    ASSERT_NE(dynamic_cast<const MarbleTexture*>(marble.get()), nullptr);
    // Marble blends between kd and the default k2, so every value lies between the two.
    const MarbleTexture expected({0, 0, 1}, {0.1, 0.1, 0.1}, 3);
    for (const Vec3 p : {Vec3{0.3, 1.7, 2.2}, Vec3{5, -4, 1.1}}) {
        const Color c = marble->value({p, {}, {}, {}}), e = expected.value({p, {}, {}, {}});
        EXPECT_DOUBLE_EQ(c.r, e.r);
        EXPECT_DOUBLE_EQ(c.b, e.b);
    }
}

TEST(SceneLoader, BumpAttributesAreRead) {
    const Scene s = load(in_scene(std::string(kGray) + R"(
        <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Gray" bumpEnable="1"
               BumpScale="5" BumpStrength="0.75"/>)"))
                        .scene;
    const auto& bump = s.objects.at(0)->detail().bump;
    ASSERT_TRUE(bump.has_value());
    EXPECT_DOUBLE_EQ(bump->scale, 5);
    EXPECT_DOUBLE_EQ(bump->strength, 0.75);
}

TEST(SceneLoader, ZeroMaxDepthAndLensRadiusAreAllowed) {
    const Scene s =
        load(in_scene(R"(<Render MaxDepth="0"/><DepthOfField Radius="0" Focal="5"/>)")).scene;
    EXPECT_EQ(s.settings.max_depth, 0);
    EXPECT_TRUE(s.lens.is_pinhole());
    EXPECT_DOUBLE_EQ(s.lens.focal, 5);
}

TEST(SceneLoader, IndexBelowOneIsAllowed) {
    const Scene s = load(in_scene(R"(<Materials><Odd index="0.5"/></Materials>)")).scene;
    EXPECT_DOUBLE_EQ(s.materials.at(0)->index, 0.5);
}

// ---------------------------------------------------------------------------------------------
// Errors: malformed input

TEST(SceneLoaderErrors, MalformedXmlNamesTheLine) {
    EXPECT_EQ(error_of("<Scene>\n<Image Width=\"1\">\n</Scene>"),
              "t.xml:2: XML: mismatched end tag");
    EXPECT_EQ(error_of("<Scene>\n\n<Image Width=\"1/>\n</Scene>"),
              "t.xml:3: XML: malformed or repeated attribute");
    EXPECT_EQ(error_of("<Scene>\n<Image Width=\"1\" Width=\"2\"/>\n</Scene>"),
              "t.xml:2: XML: malformed or repeated attribute");
    EXPECT_EQ(error_of("<Scene>\n<Image>\n"), "t.xml:2: XML: malformed xml");
}

TEST(SceneLoaderErrors, EmptyOrBlankInputIsAnEmptyDocument) {
    EXPECT_EQ(error_of(""), "t.xml:1: XML: empty document");
    EXPECT_EQ(error_of("  \n\t\n"), "t.xml:1: XML: empty document");
}

TEST(SceneLoaderErrors, BinaryGarbageIsRejected) {
    EXPECT_EQ(error_of("\x89PNG\r\n\x1a\n\0\0\0\rIHDR"sv),
              "t.xml:3: XML: nul byte in input (not a text file?)");
    EXPECT_EQ(error_of("\x89PNG\r\n\x1a\x01\x02"), "t.xml:1: XML: text outside the root element");
    // A scene followed by garbage must not load as the scene alone.
    EXPECT_EQ(error_of("<Scene/>\n\0junk"sv), "t.xml:2: XML: nul byte in input (not a text file?)");
}

TEST(SceneLoaderErrors, RootMustBeOneScene) {
    EXPECT_EQ(error_of("<!-- nothing -->"), "t.xml:1: XML: no <Scene> element");
    EXPECT_EQ(error_of("\n<Scena/>"), "t.xml:2: Scena: root element must be <Scene>");
    EXPECT_EQ(error_of("<Scene/>\n<Scene/>"), "t.xml:2: Scene: second root element after <Scene>");
}

// ---------------------------------------------------------------------------------------------
// Errors: missing attributes

TEST(SceneLoaderErrors, MissingRequiredAttributesAreNamed) {
    EXPECT_EQ(body_error(R"(<Light Px="1" Pz="0"/>)"),
              "t.xml:2: Light: missing required attribute 'Py'");
    EXPECT_EQ(body_error(R"(<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Material="M"/>)"),
              "t.xml:2: Plane: missing required attribute 'Vw'");
    EXPECT_EQ(body_error(R"(<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0"/>)"),
              "t.xml:2: Plane: missing required attribute 'Material'");
    EXPECT_EQ(body_error(R"(<Sphere Px="0" Py="0" Pz="0" Material="M"/>)"),
              "t.xml:2: Sphere: missing required attribute 'Radius'");
    EXPECT_EQ(body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="1"/>)"),
              "t.xml:2: Sphere: missing required attribute 'Material'");
    EXPECT_EQ(body_error(R"(<Sphere Py="0" Pz="0" Radius="1" Material="M"/>)"),
              "t.xml:2: Sphere: missing required attribute 'Px'");
    EXPECT_EQ(body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="M">
                                <MotionBlurPosition Px="1" Py="0"/>
                            </Sphere>)"),
              "t.xml:3: MotionBlurPosition: missing required attribute 'Pz'");
    EXPECT_EQ(body_error(R"(<Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="0"/>)"),
              "t.xml:2: Camera: missing required attribute 'Lz'");
    EXPECT_EQ(body_error(R"(<Camera Ey="0" Ez="0" Lx="0" Ly="0" Lz="1"/>)"),
              "t.xml:2: Camera: missing required attribute 'Ex'");
    EXPECT_EQ(body_error(R"(<DepthOfField Focal="10"/>)"),
              "t.xml:2: DepthOfField: missing required attribute 'Radius'");
    EXPECT_EQ(body_error(R"(<DepthOfField Radius="1"/>)"),
              "t.xml:2: DepthOfField: missing required attribute 'Focal'");
    EXPECT_EQ(body_error("<Materials>\n<Material kdr=\"1\"/></Materials>"),
              "t.xml:3: Material: missing required attribute 'Name'");
}

TEST(SceneLoaderErrors, LineIsTheElementsFirstLine) {
    EXPECT_EQ(body_error("\n\n<Sphere Px=\"0\" Py=\"0\" Pz=\"0\"\n        Radius=\"-3\"\n/>"),
              "t.xml:4: Sphere: negative radius -3");
}

// ---------------------------------------------------------------------------------------------
// Errors: numbers

TEST(SceneLoaderErrors, AttributeMustBeWhollyOneFiniteNumber) {
    const auto radius = [](std::string_view value) {
        return body_error(R"(<Light Px="0" Py="0" Pz="0" Radius=")" + std::string(value) + "\"/>");
    };
    EXPECT_EQ(radius("0.5abc"), "t.xml:2: Light: attribute 'Radius' is not a number: \"0.5abc\"");
    EXPECT_EQ(radius(""), "t.xml:2: Light: attribute 'Radius' is not a number: \"\"");
    EXPECT_EQ(radius("  "), "t.xml:2: Light: attribute 'Radius' is not a number: \"  \"");
    EXPECT_EQ(radius("nan"), "t.xml:2: Light: attribute 'Radius' is not a number: \"nan\"");
    EXPECT_EQ(radius("inf"), "t.xml:2: Light: attribute 'Radius' is not a number: \"inf\"");
    EXPECT_EQ(radius("-infinity"),
              "t.xml:2: Light: attribute 'Radius' is not a number: \"-infinity\"");
    EXPECT_EQ(radius("+-1"), "t.xml:2: Light: attribute 'Radius' is not a number: \"+-1\"");
    EXPECT_EQ(radius("0x10"), "t.xml:2: Light: attribute 'Radius' is not a number: \"0x10\"");
    EXPECT_EQ(radius("1 2"), "t.xml:2: Light: attribute 'Radius' is not a number: \"1 2\"");
    EXPECT_EQ(radius("1,5"), "t.xml:2: Light: attribute 'Radius' is not a number: \"1,5\"");
    EXPECT_EQ(radius("1e999"), "t.xml:2: Light: attribute 'Radius' is out of range: \"1e999\"");
}

TEST(SceneLoaderErrors, NonNumbersAreCaughtInEveryKindOfElement) {
    EXPECT_EQ(body_error(R"(<Background r="0" g="x" b="0"/>)"),
              "t.xml:2: Background: attribute 'g' is not a number: \"x\"");
    EXPECT_EQ(body_error(R"(<Materials><Glass index="1.5.1"/></Materials>)"),
              "t.xml:2: Glass: attribute 'index' is not a number: \"1.5.1\"");
    EXPECT_EQ(body_error(R"(<Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="0" Lz="1" Fov="wide"/>)"),
              "t.xml:2: Camera: attribute 'Fov' is not a number: \"wide\"");
}

TEST(SceneLoaderErrors, IntegerSettingsMustBeIntegers) {
    EXPECT_EQ(body_error(R"(<Image Width="6.5"/>)"),
              "t.xml:2: Image: attribute 'Width' is not an integer: \"6.5\"");
    EXPECT_EQ(body_error(R"(<Image Height="1e3"/>)"),
              "t.xml:2: Image: attribute 'Height' is not an integer: \"1e3\"");
    EXPECT_EQ(body_error(R"(<Render Samples="many"/>)"),
              "t.xml:2: Render: attribute 'Samples' is not an integer: \"many\"");
    EXPECT_EQ(body_error(R"(<Render ShadowRays="2.0"/>)"),
              "t.xml:2: Render: attribute 'ShadowRays' is not an integer: \"2.0\"");
    EXPECT_EQ(body_error(R"(<Render MaxDepth="3.5"/>)"),
              "t.xml:2: Render: attribute 'MaxDepth' is not an integer: \"3.5\"");
    EXPECT_EQ(body_error(R"(<Render GlossyRays=""/>)"),
              "t.xml:2: Render: attribute 'GlossyRays' is not an integer: \"\"");
    EXPECT_EQ(body_error(R"(<Render Seed="-1"/>)"),
              "t.xml:2: Render: attribute 'Seed' is not a non-negative integer: \"-1\"");
    EXPECT_EQ(body_error(R"(<Image Width="99999999999"/>)"),
              "t.xml:2: Image: attribute 'Width' is out of range: \"99999999999\"");
}

TEST(SceneLoaderErrors, SwitchesMustBeZeroOrOne) {
    EXPECT_EQ(body_error(R"(<Light Px="0" Py="0" Pz="0" Radius="1" Visible="yes"/>)"),
              "t.xml:2: Light: Visible must be 0 or 1, got \"yes\"");
    EXPECT_EQ(
        body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="M" EnableTexture="2"/>)"),
        "t.xml:2: Sphere: EnableTexture must be 0 or 1, got \"2\"");
    EXPECT_EQ(
        body_error(
            R"(<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="M" bumpEnable="1.0"/>)"),
        "t.xml:2: Plane: bumpEnable must be 0 or 1, got \"1.0\"");
}

// ---------------------------------------------------------------------------------------------
// Errors: values out of their range

TEST(SceneLoaderErrors, NegativeRadius) {
    EXPECT_EQ(body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="-3" Material="M"/>)"),
              "t.xml:2: Sphere: negative radius -3");
    EXPECT_EQ(body_error(R"(<Light Px="0" Py="0" Pz="0" Radius="-0.5"/>)"),
              "t.xml:2: Light: negative radius -0.5");
    EXPECT_EQ(body_error(R"(<DepthOfField Radius="-2" Focal="10"/>)"),
              "t.xml:2: DepthOfField: negative radius -2");
}

TEST(SceneLoaderErrors, SphereRadiusMustBePositive) {
    EXPECT_EQ(body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="0" Material="M"/>)"),
              "t.xml:2: Sphere: Radius must be positive, got 0");
}

TEST(SceneLoaderErrors, NonPositiveSizes) {
    EXPECT_EQ(body_error(R"(<Image Width="0"/>)"), "t.xml:2: Image: Width must be positive, got 0");
    EXPECT_EQ(body_error(R"(<Image Height="-480"/>)"),
              "t.xml:2: Image: Height must be positive, got -480");
    EXPECT_EQ(body_error(R"(<Render Samples="0"/>)"),
              "t.xml:2: Render: Samples must be positive, got 0");
    EXPECT_EQ(body_error(R"(<Render ShadowRays="-1"/>)"),
              "t.xml:2: Render: ShadowRays must be positive, got -1");
    EXPECT_EQ(body_error(R"(<Render GlossyRays="0"/>)"),
              "t.xml:2: Render: GlossyRays must be positive, got 0");
    EXPECT_EQ(
        body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="M" TextureScale="0"/>)"),
        "t.xml:2: Sphere: TextureScale must be positive, got 0");
    EXPECT_EQ(
        body_error(
            R"(<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="M" BumpScale="-2"/>)"),
        "t.xml:2: Plane: BumpScale must be positive, got -2");
    EXPECT_EQ(body_error(R"(<DepthOfField Radius="1" Focal="0"/>)"),
              "t.xml:2: DepthOfField: Focal must be positive, got 0");
    EXPECT_EQ(body_error(R"(<Materials><Glass index="0"/></Materials>)"),
              "t.xml:2: Glass: index must be positive, got 0");
    EXPECT_EQ(body_error(R"(<Materials><Glass n="-10"/></Materials>)"),
              "t.xml:2: Glass: n must be positive, got -10");
}

TEST(SceneLoaderErrors, NegativeMaxDepth) {
    EXPECT_EQ(body_error(R"(<Render MaxDepth="-1"/>)"),
              "t.xml:2: Render: MaxDepth must be non-negative, got -1");
}

TEST(SceneLoaderErrors, FovMustLieStrictlyBetween0And180) {
    const auto fov = [](std::string_view value) {
        return body_error(R"(<Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="0" Lz="1" Fov=")" +
                          std::string(value) + "\"/>");
    };
    EXPECT_EQ(fov("0"), "t.xml:2: Camera: Fov must be between 0 and 180, got 0");
    EXPECT_EQ(fov("180"), "t.xml:2: Camera: Fov must be between 0 and 180, got 180");
    EXPECT_EQ(fov("-30"), "t.xml:2: Camera: Fov must be between 0 and 180, got -30");
    EXPECT_EQ(fov("179.5"), "loaded");
}

TEST(SceneLoaderErrors, DegenerateCamera) {
    EXPECT_EQ(body_error(R"(<Camera Ex="1" Ey="2" Ez="3" Lx="1" Ly="2" Lz="3"/>)"),
              "t.xml:2: Camera: eye and look-at point coincide");
    EXPECT_EQ(body_error(R"(<Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="5" Lz="0"/>)"),
              "t.xml:2: Camera: up is parallel to the view direction");
    EXPECT_EQ(
        body_error(R"(<Camera Ex="0" Ey="0" Ez="0" Lx="1" Ly="1" Lz="0" Ux="-2" Uy="-2" Uz="0"/>)"),
        "t.xml:2: Camera: up is parallel to the view direction");
    EXPECT_EQ(
        body_error(R"(<Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="0" Lz="1" Ux="0" Uy="0" Uz="0"/>)"),
        "t.xml:2: Camera: up is parallel to the view direction");
}

TEST(SceneLoaderErrors, ZeroLengthPlaneNormal) {
    EXPECT_EQ(body_error(R"(<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="0" Vw="0" Material="M"/>)"),
              "t.xml:2: Plane: zero-length normal");
}

// ---------------------------------------------------------------------------------------------
// Errors: names

TEST(SceneLoaderErrors, UnknownMaterialSuggestsTheNearestDefinedOne) {
    EXPECT_EQ(body_error(R"(<Materials><Glass/><Mirror/></Materials>

<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Glas"/>)"),
              "t.xml:4: Sphere: unknown material 'Glas'; did you mean 'Glass'?");
    EXPECT_EQ(body_error(R"(<Materials><Glass/></Materials>
<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Velvet"/>)"),
              "t.xml:3: Plane: unknown material 'Velvet'");
    // Names are case-sensitive: a case slip is an error, though the suggestion finds it.
    EXPECT_EQ(body_error(R"(<Materials><Glass/></Materials>
<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="glass"/>)"),
              "t.xml:3: Sphere: unknown material 'glass'; did you mean 'Glass'?");
}

TEST(SceneLoaderErrors, DuplicateMaterialNames) {
    EXPECT_EQ(body_error("<Materials>\n<Glass/>\n<Glass index=\"1.2\"/>\n</Materials>"),
              "t.xml:4: Glass: duplicate material 'Glass' (first defined on line 3)");
    EXPECT_EQ(body_error("<Materials><Glass/></Materials>\n"
                         "<Materials><Material Name=\"Glass\"/></Materials>"),
              "t.xml:3: Material: duplicate material 'Glass' (first defined on line 2)");
}

TEST(SceneLoaderErrors, BothTransmitSpellingsAtOnce) {
    EXPECT_EQ(body_error(R"(<Materials><Glass transmitt="1" transmit="0.5"/></Materials>)"),
              "t.xml:2: Glass: give 'transmitt' or 'transmit', not both");
}

TEST(SceneLoaderErrors, UnknownSamplerListsTheKnownOnes) {
    EXPECT_EQ(body_error(R"(<Render Sampler="halton"/>)"),
              "t.xml:2: Render: unknown sampler 'halton'; known: random, stratified, sobol");
}

TEST(SceneLoaderErrors, UnknownTextureEvenWhenDisabled) {
    EXPECT_EQ(
        body_error(R"(<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="M" Texture="wood"/>)"),
        "t.xml:2: Sphere: unknown texture 'wood'");
    EXPECT_EQ(body_error(R"(<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="M"
                                EnableTexture="1" Texture="Checker"/>)"),
              "t.xml:2: Plane: unknown texture 'Checker'");
}

// ---------------------------------------------------------------------------------------------
// Warnings

TEST(SceneLoaderWarnings, UnknownAttributeSuggestsTheNearestKnownOne) {
    const auto w =
        warnings_of(std::string(kGray) + "\n" +
                    R"(<Sphere Px="0" Py="0" Pz="0" Radius="1" Radus="2" Material="Gray"/>)");
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0],
              "t.xml:3: warning: unknown attribute 'Radus' on <Sphere>; did you mean 'Radius'?");
}

TEST(SceneLoaderWarnings, UnknownAttributeFarFromEveryKnownNameGetsNoSuggestion) {
    const auto w = warnings_of(R"(<Light Px="0" Py="0" Pz="0" Colour="red"/>)");
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0], "t.xml:2: warning: unknown attribute 'Colour' on <Light>");
}

TEST(SceneLoaderWarnings, CaseSlipsAreSuggested) {
    const auto w = warnings_of(R"(<Image width="10" HEIGHT="20"/>)");
    ASSERT_EQ(w.size(), 2u);
    EXPECT_EQ(w[0],
              "t.xml:2: warning: unknown attribute 'width' on <Image>; did you mean 'Width'?");
    EXPECT_EQ(w[1],
              "t.xml:2: warning: unknown attribute 'HEIGHT' on <Image>; did you mean 'Height'?");
}

TEST(SceneLoaderWarnings, UnknownAttributesOnEveryElement) {
    const auto w =
        warnings_of(R"(<Materials a="1"><Glass kdx="1"/><Material Name="M" Nmae="x"/></Materials>
<Render Sampels="4"/>
<Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="0" Lz="1" Fvo="40"/>
<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="M" TextureScael="3">
  <MotionBlurPosition Px="0" Py="0" Pz="1" Pw="1"/>
</Sphere>
<Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="M" bumpenable="1"/>)");
    ASSERT_EQ(w.size(), 8u);
    EXPECT_EQ(w[0], "t.xml:2: warning: unknown attribute 'a' on <Materials>");
    EXPECT_EQ(w[1], "t.xml:2: warning: unknown attribute 'kdx' on <Glass>; did you mean 'kdr'?");
    EXPECT_EQ(w[2],
              "t.xml:2: warning: unknown attribute 'Nmae' on <Material>; did you mean 'Name'?");
    EXPECT_EQ(w[3],
              "t.xml:3: warning: unknown attribute 'Sampels' on <Render>; did you mean 'Samples'?");
    EXPECT_EQ(w[4], "t.xml:4: warning: unknown attribute 'Fvo' on <Camera>; did you mean 'Fov'?");
    EXPECT_EQ(w[5],
              "t.xml:5: warning: unknown attribute 'TextureScael' on <Sphere>; did you mean "
              "'TextureScale'?");
    EXPECT_EQ(
        w[6],
        "t.xml:6: warning: unknown attribute 'Pw' on <MotionBlurPosition>; did you mean 'Px'?");
    EXPECT_EQ(
        w[7],
        "t.xml:8: warning: unknown attribute 'bumpenable' on <Plane>; did you mean 'bumpEnable'?");
}

TEST(SceneLoaderWarnings, UnknownElementSuggestsTheNearestAllowedOne) {
    const LoadedScene loaded = load(in_scene(std::string(kGray) + R"(
<Spere Px="0" Py="0" Pz="0" Radius="1" Material="Gray"/>
<Objects><Plain/></Objects>
<Lights><Lihgt/></Lights>
<Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Gray"><MotionBlurPos/></Sphere>
<Teapot/>)"));
    const auto& w = loaded.warnings;
    ASSERT_EQ(w.size(), 5u);
    EXPECT_EQ(w[0], "t.xml:3: warning: unknown element <Spere>; did you mean <Sphere>?");
    EXPECT_EQ(w[1], "t.xml:4: warning: unknown element <Plain>; did you mean <Plane>?");
    EXPECT_EQ(w[2], "t.xml:5: warning: unknown element <Lihgt>; did you mean <Light>?");
    EXPECT_EQ(
        w[3],
        "t.xml:6: warning: unknown element <MotionBlurPos>; did you mean <MotionBlurPosition>?");
    EXPECT_EQ(w[4], "t.xml:7: warning: unknown element <Teapot>");
    // Unknown elements are skipped, not guessed at.
    EXPECT_EQ(loaded.scene.objects.size(), 1u);
}

TEST(SceneLoaderWarnings, KnownElementInTheWrongPlaceIsIgnored) {
    const LoadedScene loaded =
        load(in_scene(R"(<Image Width="10"><Light Px="0" Py="0" Pz="0"/></Image>
<MotionBlurPosition Px="0" Py="0" Pz="0"/>)"));
    ASSERT_EQ(loaded.warnings.size(), 2u);
    EXPECT_EQ(loaded.warnings[0], "t.xml:2: warning: <Light> does not belong in <Image>; ignored");
    EXPECT_EQ(loaded.warnings[1],
              "t.xml:3: warning: <MotionBlurPosition> does not belong in <Scene>; ignored");
    EXPECT_TRUE(loaded.scene.lights.empty());
}

TEST(SceneLoaderWarnings, MaterialTagsAreNamesNotUnknownElements) {
    const LoadedScene loaded = load(in_scene("<Materials><Spere/><Teapot/><Lights/></Materials>"));
    EXPECT_TRUE(loaded.warnings.empty());
    EXPECT_EQ(loaded.scene.materials.size(), 3u);
}

TEST(SceneLoaderWarnings, RepeatedSettingOverridesWithAWarning) {
    const LoadedScene loaded = load(in_scene("<Image Width=\"10\"/>\n<Image Height=\"20\"/>"));
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_EQ(loaded.warnings[0], "t.xml:3: warning: <Image> repeated; this one overrides line 2");
    // Each attribute is a setting of its own: the second element changes only what it gives.
    EXPECT_EQ(loaded.scene.settings.width, 10);
    EXPECT_EQ(loaded.scene.settings.height, 20);
}

TEST(SceneLoaderWarnings, VisiblePointLightIsWarnedAbout) {
    const LoadedScene loaded = load(in_scene(R"(<Light Px="0" Py="0" Pz="0" Visible="1"/>)"));
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_EQ(loaded.warnings[0],
              "t.xml:2: warning: a point light (Radius 0) cannot be visible; Visible ignored");
    EXPECT_TRUE(loaded.scene.lights.at(0)->is_point());
    // A Falloff-1 point light cannot be seen either; a Falloff-1 sphere light cannot be hidden.
    const LoadedScene physical_point =
        load(in_scene(R"(<Light Px="0" Py="0" Pz="0" Falloff="1" Visible="1"/>)"));
    EXPECT_EQ(physical_point.warnings,
              std::vector<std::string>{
                  "t.xml:2: warning: a point light (Radius 0) cannot be visible; Visible ignored"});
    const LoadedScene hidden =
        load(in_scene(R"(<Light Px="0" Py="0" Pz="0" Radius="1" Falloff="1" Visible="0"/>)"));
    EXPECT_EQ(hidden.warnings,
              std::vector<std::string>{"t.xml:2: warning: a Falloff 1 light of Radius > 0 is an "
                                       "emitting sphere, which every ray sees; Visible=\"0\" "
                                       "ignored"});
    EXPECT_EQ(hidden.scene.objects.size(), 1u);  // seen all the same
    for (const char* quiet : {R"(<Light Px="0" Py="0" Pz="0" Radius="1" Falloff="1"/>)",
                              R"(<Light Px="0" Py="0" Pz="0" Radius="1" Falloff="1" Visible="1"/>)",
                              R"(<Light Px="0" Py="0" Pz="0" Radius="1" Visible="0"/>)"}) {
        EXPECT_TRUE(load(in_scene(quiet)).warnings.empty()) << quiet;
    }
}

TEST(SceneLoaderWarnings, TextInsideAnElementIsIgnored) {
    const LoadedScene loaded =
        load(in_scene("<Image>600</Image>\n<Materials>Glass</Materials>\n"
                      "<Render>\n  <!-- a comment is fine -->\n</Render>"));
    ASSERT_EQ(loaded.warnings.size(), 2u);
    EXPECT_EQ(loaded.warnings[0], "t.xml:2: warning: text inside <Image> ignored");
    EXPECT_EQ(loaded.warnings[1], "t.xml:3: warning: text inside <Materials> ignored");
    EXPECT_EQ(loaded.scene.settings.width, 640);
}

TEST(SceneLoaderWarnings, AttributeOnSceneRoot) {
    const LoadedScene loaded = load(R"(<Scene version="2"/>)");
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_EQ(loaded.warnings[0], "t.xml:1: warning: unknown attribute 'version' on <Scene>");
}

TEST(SceneLoaderWarnings, ThesisStyleMaterialWithNameAttributeWarns) {
    const auto w = warnings_of(R"(<Materials><Glass Name="Other"/></Materials>)");
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0], "t.xml:2: warning: unknown attribute 'Name' on <Glass>");
}

// ---------------------------------------------------------------------------------------------
// Real files

class SceneFile : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() /
               (std::string("drt_scene_loader_") + info->name() + "_" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    std::string write(const std::string& name, std::string_view contents) const {
        const auto path = dir_ / name;
        std::ofstream(path, std::ios::binary)
            .write(contents.data(), static_cast<std::streamsize>(contents.size()));
        return path.string();
    }
    std::string error_loading(const std::filesystem::path& path) const {
        try {
            load_scene(path);
        } catch (const SceneError& e) {
            return e.what();
        }
        return "loaded";
    }

    std::filesystem::path dir_;
};

TEST_F(SceneFile, LoadsAFileAndRemembersItsPath) {
    const std::string path =
        write("ok.xml", "<Scene>\n<Image Width=\"32\"/>\n<Bogus/>\n</Scene>\n");
    const LoadedScene loaded = load_scene(path);
    EXPECT_EQ(loaded.scene.path, path);
    EXPECT_EQ(loaded.scene.settings.width, 32);
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_EQ(loaded.warnings[0], path + ":3: warning: unknown element <Bogus>");
}

TEST_F(SceneFile, MissingFile) {
    const std::string path = (dir_ / "missing.xml").string();
    EXPECT_EQ(error_loading(path), path + ": cannot open scene: No such file or directory");
}

TEST_F(SceneFile, DirectoryIsNotAScene) {
    EXPECT_EQ(error_loading(dir_), dir_.string() + ": cannot open scene: Is a directory");
}

TEST_F(SceneFile, EmptyFile) {
    const std::string path = write("empty.xml", "");
    EXPECT_EQ(error_loading(path), path + ":1: XML: empty document");
}

TEST_F(SceneFile, BinaryFile) {
    std::string bytes;
    for (int i = 0; i < 4096; ++i) bytes += static_cast<char>((i * 7919 + 13) % 256);
    const std::string path = write("noise.bin", bytes);
    const std::string error = error_loading(path);
    EXPECT_EQ(error.rfind(path + ":", 0), 0u) << error;
    EXPECT_NE(error.find(": XML: "), std::string::npos) << error;
}

TEST_F(SceneFile, ErrorsNameTheFileAsGiven) {
    const std::string path = write("bad.xml", "<Scene>\n<Image Width=\"0\"/>\n</Scene>");
    EXPECT_EQ(error_loading(path), path + ":2: Image: Width must be positive, got 0");
}

// ---- limits (limits.h) and safe messages -------------------------------------------------------

TEST(SceneLoaderLimits, ImageSidesAtAndPastTheLimit) {
    EXPECT_EQ(body_error(R"(<Image Width="65536" Height="1"/>)"), "loaded");
    EXPECT_EQ(body_error(R"(<Image Width="1" Height="65536"/>)"), "loaded");
    EXPECT_EQ(body_error(R"(<Image Width="65537" Height="1"/>)"),
              "t.xml:2: Image: Width must be at most 65536, got 65537");
    EXPECT_EQ(body_error(R"(<Image Width="1" Height="65537"/>)"),
              "t.xml:2: Image: Height must be at most 65536, got 65537");
}

TEST(SceneLoaderLimits, PixelCountAtAndPastTheLimit) {
    EXPECT_EQ(body_error(R"(<Image Width="16384" Height="8192"/>)"), "loaded");
    EXPECT_EQ(body_error(R"(<Image Width="16385" Height="8192"/>)"),
              "t.xml:2: Image: image of 16385x8192 pixels exceeds the limit of 134217728 pixels "
              "(docs/scene-format.md#limits)");
    // A size given in two elements is checked as a whole.
    EXPECT_EQ(body_error("<Image Width=\"65536\"/>\n<Image Height=\"2049\"/>"),
              "t.xml:3: Image: image of 65536x2049 pixels exceeds the limit of 134217728 pixels "
              "(docs/scene-format.md#limits)");
}

// Every pass's photon map is kept: Samples x Count x 48 B must fit 1024 MiB, whichever of the
// two elements comes first; the message names <Photons>.
TEST(SceneLoaderLimits, PhotonMapsAtAndPastTheirShareOfTheBudget) {
    EXPECT_EQ(body_error("<Render Samples=\"65536\"/>\n<Photons Count=\"341\"/>"), "loaded");
    const std::string past =
        ": Photons: the photon maps need an estimated 1026 MiB (65536 passes x 342 photons x "
        "48 B), more than their 1024 MiB share of the budget: lower Samples or the Photons Count";
    EXPECT_EQ(body_error("<Render Samples=\"65536\"/>\n<Photons Count=\"342\"/>"),
              "t.xml:3" + past);
    EXPECT_EQ(body_error("<Photons Count=\"342\"/>\n<Render Samples=\"65536\"/>"),
              "t.xml:2" + past);
}

TEST(SceneLoaderLimits, CountsAtAndPastTheirLimits) {
    EXPECT_EQ(body_error(R"(<Render Samples="65536" ShadowRays="65536" GlossyRays="65536"
                                 MaxDepth="512"/>)"),
              "loaded");
    EXPECT_EQ(body_error(R"(<Render Samples="65537"/>)"),
              "t.xml:2: Render: Samples must be at most 65536, got 65537");
    EXPECT_EQ(body_error(R"(<Render ShadowRays="65537"/>)"),
              "t.xml:2: Render: ShadowRays must be at most 65536, got 65537");
    EXPECT_EQ(body_error(R"(<Render GlossyRays="65537"/>)"),
              "t.xml:2: Render: GlossyRays must be at most 65536, got 65537");
    EXPECT_EQ(body_error(R"(<Render MaxDepth="513"/>)"),
              "t.xml:2: Render: MaxDepth must be at most 512, got 513");
    // Past an int: out of range, not wrapped.
    EXPECT_EQ(body_error(R"(<Render Samples="2147483648"/>)"),
              "t.xml:2: Render: attribute 'Samples' is out of range: \"2147483648\"");
}

TEST(SceneLoaderLimits, SceneFileSizeAtAndPastTheLimit) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("drt_loader_limit_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    const std::string scene = "<Scene/>";
    {
        std::ofstream(dir / "at.xml", std::ios::binary)
            << scene << std::string((64u << 20) - scene.size(), ' ');
    }
    EXPECT_NO_THROW(load_scene(dir / "at.xml"));
    std::filesystem::resize_file(dir / "at.xml", (64u << 20) + 1);  // one nul byte more
    try {
        load_scene(dir / "at.xml");
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  (dir / "at.xml").string() + ": scene file larger than the 64 MiB limit");
    }
    std::filesystem::remove_all(dir);
    // An endless input stops at the limit too.
    EXPECT_THROW(load_scene("/dev/zero"), SceneError);
}

TEST(SceneLoaderErrors, ControlCharactersFromTheSceneAreEscapedInMessages) {
    EXPECT_EQ(body_error("<Gray/>\n<Sphere Px=\"0\" Py=\"0\" Pz=\"0\" Radius=\"1\" "
                         "Material=\"&#27;]0;owned&#7;\x1b[2J\"/>"),
              "t.xml:3: Sphere: unknown material '\\x1b]0;owned\\x07\\x1b[2J'");
    EXPECT_EQ(body_error("<Render Sampler=\"a&#10;b\"/>"),
              "t.xml:2: Render: unknown sampler 'a\\x0ab'; known: random, stratified, sobol");
    const auto warnings = warnings_of(
        "<Image W\xc2\x9b"
        "dth=\"3\"/>");
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("W\\xc2\\x9bdth"), std::string::npos) << warnings[0];
}

TEST(SceneLoaderErrors, LongValuesAreCutInMessages) {
    const std::string huge = "-1" + std::string(308, '0');
    EXPECT_EQ(body_error(std::string(kGray) + "<Light Px=\"0\" Py=\"0\" Pz=\"0\" Radius=\"" + huge +
                         "\"/>"),
              "t.xml:2: Light: negative radius -1000000000000000000... (310 characters)");
    EXPECT_EQ(body_error("<Sphere Px=\"1" + std::string(400, '0') + "\"/>"),
              "t.xml:2: Sphere: attribute 'Px' is out of range: \"10000000000000000000... (401 "
              "characters)\"");
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

// ---------------------------------------------------------------------------------------------
// Triangles and meshes

const Mesh& mesh(const Scene& scene, std::size_t i) {
    return dynamic_cast<const Mesh&>(*scene.objects.at(i));
}

TEST(SceneLoader, ReadsATriangle) {
    const LoadedScene loaded =
        load(in_scene(std::string(kGray) + "<Triangle Ax=\"1\" Ay=\"0\" Az=\"0\" Bx=\"3\" "
                                           "By=\"0\" Bz=\"0\" Cx=\"1\" Cy=\"2\" Cz=\"0\" "
                                           "Material=\"Gray\" EnableTexture=\"1\"/>"));
    const Mesh& m = mesh(loaded.scene, 0);
    ASSERT_EQ(m.mesh().triangle_count(), 1u);
    const auto [a, b, c] = m.mesh().corners(0);
    const Vec3 o = m.path().at(0);
    expect_vec(a + o, 1, 0, 0);
    expect_vec(b + o, 3, 0, 0);
    expect_vec(c + o, 1, 2, 0);
    expect_vec(m.mesh().geometric_normal(0), 0, 0, 1);
    EXPECT_TRUE(m.detail().texture);
    EXPECT_FALSE(m.moves());
}

TEST(SceneLoader, TriangleNeedsNineCoordinatesAndAMaterial) {
    EXPECT_EQ(body_error(std::string(kGray) + "\n<Triangle Ax=\"0\" Ay=\"0\" Az=\"0\" Bx=\"1\" "
                                              "By=\"0\" Bz=\"0\" Cx=\"0\" Cy=\"1\" "
                                              "Material=\"Gray\"/>"),
              "t.xml:3: Triangle: missing required attribute 'Cz'");
    EXPECT_EQ(body_error(std::string(kGray) + "\n<Triangle Ax=\"0\" Ay=\"0\" Az=\"0\" Bx=\"1\" "
                                              "By=\"0\" Bz=\"0\" Cx=\"0\" Cy=\"1\" Cz=\"0\"/>"),
              "t.xml:3: Triangle: missing required attribute 'Material'");
    EXPECT_EQ(body_error(std::string(kGray) + "\n<Triangle Ax=\"0\" Ay=\"0\" Az=\"nan\" Bx=\"1\" "
                                              "By=\"0\" Bz=\"0\" Cx=\"0\" Cy=\"1\" Cz=\"0\" "
                                              "Material=\"Gray\"/>"),
              "t.xml:3: Triangle: attribute 'Az' is not a number: \"nan\"");
}

TEST(SceneLoader, ATriangleOfZeroAreaIsDroppedWithAWarning) {
    const LoadedScene loaded =
        load(in_scene(std::string(kGray) + "\n<Triangle Ax=\"0\" Ay=\"0\" Az=\"0\" Bx=\"1\" "
                                           "By=\"1\" Bz=\"1\" Cx=\"2\" Cy=\"2\" Cz=\"2\" "
                                           "Material=\"Gray\"/>"));
    EXPECT_EQ(mesh(loaded.scene, 0).mesh().triangle_count(), 0u);
    EXPECT_EQ(loaded.warnings,
              std::vector<std::string>{"t.xml:3: warning: <Triangle> of zero area dropped"});
}

// A <Triangle> with the given corners (x y z, three times) and attributes.
std::string triangle(const std::array<double, 9>& c, std::string_view attributes) {
    static constexpr std::string_view kNames[] = {"Ax", "Ay", "Az", "Bx", "By",
                                                  "Bz", "Cx", "Cy", "Cz"};
    std::string xml = "<Triangle";
    for (std::size_t k = 0; k < 9; ++k) {
        char number[32];
        const auto end = std::to_chars(number, number + sizeof number, c[k]).ptr;
        xml.append(" ").append(kNames[k]).append("=\"").append(number, end).append("\"");
    }
    return xml + " " + std::string(attributes) + "/>\n";
}

// A mesh's per-ray set-up is paid once for all the <Triangle>s of one material and surface.
// The mesh triangles that are the object's own (its part of a shared mesh).
std::vector<std::uint32_t> own_triangles(const Mesh& m) {
    std::vector<std::uint32_t> own;
    for (std::uint32_t t = 0; t < m.mesh().triangle_count(); ++t) {
        if (m.part() == MeshShape::kWhole || m.mesh().parts()[t] == m.part()) own.push_back(t);
    }
    return own;
}

TEST(SceneLoader, TrianglesOfOneMaterialAndSurfaceAreOneObjectAndAllArePartsOfOneMesh) {
    const std::string body =
        "<Materials><Gray/><Red/></Materials>\n" +
        triangle({0, 0, 0, 1, 0, 0, 0, 1, 0}, "Material=\"Gray\"") +
        triangle({0, 0, 1, 1, 0, 1, 0, 1, 1}, "Material=\"Red\"") +
        triangle({0, 0, 2, 1, 0, 2, 0, 1, 2}, "Material=\"Gray\"") +
        triangle({0, 0, 3, 1, 0, 3, 0, 1, 3}, "Material=\"Gray\" EnableTexture=\"1\"") +
        triangle({0, 0, 4, 1, 0, 4, 0, 1, 4}, "Material=\"Red\"") +
        triangle({5, 0, 5, 7, 0, 5, 5, 3, 5}, "Material=\"Gray\"") +
        triangle({0, 0, 6, 1, 0, 6, 0, 1, 6}, "Material=\"Gray\" Au=\"0.5\"");
    const LoadedScene loaded = load(in_scene(body));
    EXPECT_TRUE(loaded.warnings.empty());
    // In the order of each group's first triangle, each a part of the one mesh.
    ASSERT_EQ(loaded.scene.objects.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(&mesh(loaded.scene, i).mesh(), &mesh(loaded.scene, 0).mesh());
        EXPECT_EQ(mesh(loaded.scene, i).part(), i);
    }
    EXPECT_EQ(mesh(loaded.scene, 0).mesh().triangle_count(), 7u);
    EXPECT_EQ(own_triangles(mesh(loaded.scene, 0)).size(), 3u);
    EXPECT_EQ(loaded.scene.objects[0]->material().name, "Gray");
    EXPECT_EQ(own_triangles(mesh(loaded.scene, 1)).size(), 2u);
    EXPECT_EQ(loaded.scene.objects[1]->material().name, "Red");
    EXPECT_EQ(own_triangles(mesh(loaded.scene, 2)).size(), 1u);
    EXPECT_TRUE(mesh(loaded.scene, 2).detail().texture);
    EXPECT_EQ(own_triangles(mesh(loaded.scene, 3)).size(), 1u);
    // Every triangle keeps its corners and its group, whichever the leaf order puts first.
    const Mesh& gray = mesh(loaded.scene, 0);
    const Vec3 o = gray.path().at(0);
    bool found = false;
    for (const std::uint32_t t : own_triangles(gray)) {
        const auto [a, b, c] = gray.mesh().corners(t);
        if (a + o == Vec3{5, 0, 5}) {
            found = true;
            expect_vec(b + o, 7, 0, 5);
            expect_vec(c + o, 5, 3, 5);
        }
    }
    EXPECT_TRUE(found);
    // A part's shape is bounded by its own triangles (what photons are aimed at), not the mesh's.
    const Shapes red_shapes = loaded.scene.objects[1]->shapes();
    ASSERT_EQ(red_shapes.meshes.size(), 1u);
    const Vec3 origin = mesh(loaded.scene, 1).path().at(0);
    expect_vec(red_shapes.meshes[0].bounds.lo + origin, 0, 0, 1);
    expect_vec(red_shapes.meshes[0].bounds.hi + origin, 1, 1, 4);
    // A part tested alone is hit only on its own triangles: the ray along z through every
    // triangle meets the Red part first at z = 1, the Gray part at z = 0 and then z = 2.
    const Ray ray{{0.25, 0.25, -1}, {0, 0, 1}};
    const auto red = loaded.scene.objects[1]->intersect(ray, {0, kInfinity});
    ASSERT_TRUE(red);
    EXPECT_DOUBLE_EQ(red->t, 2);
    EXPECT_EQ(red->object, loaded.scene.objects[1].get());
    const auto gray_hit = loaded.scene.objects[0]->intersect(ray, {1.5, kInfinity});
    ASSERT_TRUE(gray_hit);
    EXPECT_DOUBLE_EQ(gray_hit->t, 3);
    // The scene's BVH enters the mesh once and gives each hit to its triangle's part.
    const Bvh bvh(loaded.scene.objects);
    const double starts[] = {0, 1.5, 2.5, 3.5, 4.5};
    const std::size_t owners[] = {0, 1, 0, 2, 1};
    for (int k = 0; k < 5; ++k) {
        const auto hit = bvh.intersect(ray, {starts[k], kInfinity});
        ASSERT_TRUE(hit) << k;
        EXPECT_DOUBLE_EQ(hit->t, k + 1) << k;
        EXPECT_EQ(hit->object, loaded.scene.objects[owners[k]].get()) << k;
    }
}

// A <Triangle> scene of one material is one mesh of one part, as before parts existed.
TEST(SceneLoader, TrianglesOfOneGroupAreAMeshWithoutParts) {
    const LoadedScene loaded = load(in_scene(
        std::string(kGray) + "\n" + triangle({0, 0, 0, 1, 0, 0, 0, 1, 0}, "Material=\"Gray\"") +
        triangle({0, 0, 1, 1, 0, 1, 0, 1, 1}, "Material=\"Gray\"")));
    ASSERT_EQ(loaded.scene.objects.size(), 1u);
    EXPECT_EQ(mesh(loaded.scene, 0).part(), MeshShape::kWhole);
    EXPECT_TRUE(mesh(loaded.scene, 0).mesh().parts().empty());
}

// Warnings stay with their <Triangle>; one that the group's single precision would flatten
// (small and far from the others) is an object of its own instead of lost.
TEST(SceneLoader, GroupedTrianglesKeepTheirWarningsAndTheirDetail) {
    const std::string body =
        std::string(kGray) + "\n" + triangle({0, 0, 0, 1, 0, 0, 0, 1, 0}, "Material=\"Gray\"") +
        triangle({0, 0, 0, 1, 1, 1, 2, 2, 2}, "Material=\"Gray\"") +
        triangle({1e7, 0, 0, 1e7 + 0.01, 0, 0, 1e7, 0.01, 0}, "Material=\"Gray\"") +
        triangle({0, 0, 0, 1, 1, 0, 3, 3.0000000001, 0}, "Material=\"Gray\"");
    const LoadedScene loaded = load(in_scene(body));
    EXPECT_EQ(loaded.warnings,
              (std::vector<std::string>{
                  "t.xml:4: warning: <Triangle> of zero area dropped",
                  "t.xml:6: warning: <Triangle> too thin for single precision dropped"}));
    ASSERT_EQ(loaded.scene.objects.size(), 2u);
    EXPECT_EQ(mesh(loaded.scene, 0).mesh().triangle_count(), 1u);
    EXPECT_EQ(mesh(loaded.scene, 0).mesh().dropped(), 1u);
    const Mesh& far = mesh(loaded.scene, 1);
    ASSERT_EQ(far.mesh().triangle_count(), 1u);
    const Vec3 o = far.path().at(0);
    const auto [a, b, c] = far.mesh().corners(0);
    EXPECT_NEAR((b - a).x, 0.01, 1e-9);
    EXPECT_NEAR((c - a).y, 0.01, 1e-9);
    EXPECT_NEAR((a + o).x, 1e7, 1e-6);
}

constexpr std::string_view kTetrahedron =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST_F(SceneFile, ReadsAMeshRelativeToTheScenesFolder) {
    std::filesystem::create_directories(dir_ / "models");
    write("models/tet.obj", kTetrahedron);
    const std::string scene =
        write("s.xml",
              "<Scene><Materials><Gray/></Materials>\n"
              "<Mesh File=\"models/tet.obj\" Material=\"Gray\" Scale=\"2\" RotateZ=\"90\" "
              "Tx=\"10\" Ty=\"20\" Tz=\"30\" Smooth=\"0\" bumpEnable=\"1\">\n"
              "<MotionBlurPosition Tx=\"11\" Ty=\"20\" Tz=\"30\"/>\n"
              "</Mesh></Scene>\n");
    const LoadedScene loaded = load_scene(scene);
    EXPECT_TRUE(loaded.warnings.empty());
    const Mesh& m = mesh(loaded.scene, 0);
    ASSERT_EQ(m.mesh().triangle_count(), 4u);
    EXPECT_FALSE(m.mesh().smooth());
    EXPECT_TRUE(m.detail().bump);
    EXPECT_DOUBLE_EQ(m.motion_end(), 1);
    // Vertex (1, 0, 0) scaled to (2, 0, 0), turned a quarter about z to (0, 2, 0), moved by T.
    Bounds world;
    for (std::uint32_t t = 0; t < 4; ++t) {
        for (const Vec3& p : m.mesh().corners(t)) world.grow(p + m.path().at(0));
    }
    // (0, 1, 0) to (0, 2, 0) to (-2, 0, 0).
    expect_vec(world.lo, 8, 20, 30);
    expect_vec(world.hi, 10, 22, 32);
    expect_vec(m.path().at(1) - m.path().at(0), 1, 0, 0);
}

TEST_F(SceneFile, MeshErrors) {
    write("tet.obj", kTetrahedron);
    write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    const auto error_of_mesh = [&](std::string_view attributes) {
        return error_loading(write("s.xml", "<Scene><Materials><Gray/></Materials>\n<Mesh " +
                                                std::string(attributes) + "/></Scene>\n"));
    };
    const std::string s = (dir_ / "s.xml").string();
    EXPECT_EQ(error_of_mesh("File=\"nope.obj\" Material=\"Gray\""),
              s + ":2: Mesh: cannot open " + (dir_ / "nope.obj").string() +
                  ": No such file or directory");
    EXPECT_EQ(
        error_of_mesh("File=\"bad.obj\" Material=\"Gray\""),
        (dir_ / "bad.obj").string() + ":4: f: vertex index 4 is out of range; 3 defined above");
    EXPECT_EQ(error_of_mesh("Material=\"Gray\""),
              s + ":2: Mesh: missing required attribute 'File'");
    EXPECT_EQ(error_of_mesh("File=\"tet.obj\" Material=\"Gray\" Scale=\"0\""),
              s + ":2: Mesh: Scale must be positive, got 0");
    EXPECT_EQ(error_of_mesh("File=\"tet.obj\" Material=\"Gray\" Scale=\"-2\""),
              s + ":2: Mesh: Scale must be positive, got -2");
    EXPECT_EQ(error_of_mesh("File=\"tet.obj\" Material=\"Gray\" Smooth=\"2\""),
              s + ":2: Mesh: Smooth must be 0 or 1, got \"2\"");
    EXPECT_EQ(error_of_mesh("File=\"tet.obj\" Material=\"Gray\" Scale=\"1e300\""),
              s + ":2: Mesh: vertex 1 is beyond single precision (±3.4e38) once transformed");
    EXPECT_EQ(error_of_mesh("File=\"tet.obj\" Material=\"Grey\""),
              s + ":2: Mesh: unknown material 'Grey'; did you mean 'Gray'?");
}

TEST_F(SceneFile, ZeroAreaTrianglesOfAMeshAreCountedInOneWarning) {
    write("m.obj", std::string(kTetrahedron) + "f 1 1 2\nf 2 3 2\nf 1 2 2\n");
    const std::string s = write("s.xml",
                                "<Scene><Materials><Gray/></Materials>\n"
                                "<Mesh File=\"m.obj\" Material=\"Gray\"/></Scene>\n");
    const LoadedScene loaded = load_scene(s);
    EXPECT_EQ(mesh(loaded.scene, 0).mesh().triangle_count(), 4u);
    EXPECT_EQ(loaded.warnings,
              std::vector<std::string>{s + ":2: warning: 3 triangles of zero area in " +
                                       (dir_ / "m.obj").string() + " dropped"});
}

// A needle with area in the file that single precision flattens onto a line has no normal: it
// is left out, and said so apart from the zero-area ones.
TEST_F(SceneFile, TrianglesFlattenedBySinglePrecisionAreCountedInTheirOwnWarning) {
    write("m.obj", std::string(kTetrahedron) + "v 0 0 0\nv 1 1 0\nv 3 3.0000000001 0\nf 5 6 7\n");
    const std::string s = write("s.xml",
                                "<Scene><Materials><Gray/></Materials>\n"
                                "<Mesh File=\"m.obj\" Material=\"Gray\"/></Scene>\n");
    const LoadedScene loaded = load_scene(s);
    EXPECT_EQ(mesh(loaded.scene, 0).mesh().triangle_count(), 4u);
    EXPECT_EQ(loaded.warnings, std::vector<std::string>{s + ":2: warning: 1 triangle in " +
                                                        (dir_ / "m.obj").string() +
                                                        " too thin for single precision dropped"});
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

// Light transport (docs/scene-format.md, "Light transport").
TEST(SceneLoaderLightTransport, IntegratorIsDistributedUnlessPathIsNamed) {
    EXPECT_EQ(load(in_scene("")).scene.settings.integrator, IntegratorKind::kDistributed);
    EXPECT_EQ(load(in_scene(R"(<Render Integrator="path"/>)")).scene.settings.integrator,
              IntegratorKind::kPath);
    EXPECT_EQ(body_error(R"(<Render Integrator="photon"/>)"),
              "t.xml:2: Render: unknown integrator 'photon'; known: distributed, path");
}

TEST(SceneLoaderLightTransport, EmissionIsReadAndMustNotBeNegative) {
    const Scene scene =
        load(in_scene(R"(<Materials><Glow ker="1" keg="2.5" keb="0"/><Gray/></Materials>)")).scene;
    EXPECT_EQ(scene.materials[0]->emission, (Color{1, 2.5, 0}));
    EXPECT_TRUE(scene.materials[0]->emits());
    EXPECT_FALSE(scene.materials[1]->emits());
    EXPECT_EQ(body_error(R"(<Materials><Glow keg="-1"/></Materials>)"),
              "t.xml:2: Glow: keg must be non-negative, got -1");
}

// Radiance that a ray sees as it is must fit an image's floats: refused at its line, not found
// in the finished image.
TEST(SceneLoaderLightTransport, RadianceSeenDirectlyMustFitAFloat) {
    EXPECT_EQ(body_error(R"(<Materials><Glow keb="1e39"/></Materials>)"),
              "t.xml:2: Glow: keb must be at most 3.40282e+38 (the largest value a float image "
              "holds), got 1e39");
    EXPECT_EQ(body_error(R"(<Light Px="0" Py="0" Pz="0" Radius="1e-20" Falloff="1"/>)"),
              "t.xml:2: Light: a Falloff 1 light of radius 1e-20 is seen with radiance "
              "I/Radius^2 past the largest value a float image holds (3.40282e+38)");
    EXPECT_EQ(body_error(R"(<Background r="0" g="-1e39" b="0"/>)"),
              "t.xml:2: Background: g must be at most 3.40282e+38 (the largest value a float "
              "image holds), got -1e39");
    // At the limit is allowed, and a point light (its light falls off) may be brighter.
    EXPECT_NO_THROW(load(in_scene(R"(<Materials><Glow ker="3.4e38"/></Materials>
<Light Px="0" Py="0" Pz="0" Falloff="1" Ir="1e39"/>)")));
}

TEST(SceneLoaderLightTransport, FalloffOnePointLightIsInverseSquareAndSphereLightAnEmitter) {
    const Scene scene = load(in_scene(R"(<Light Px="1" Py="2" Pz="3" Falloff="1" Ir="4"/>
<Light Px="0" Py="0" Pz="0" Radius="2" Falloff="1" Ir="8" Ig="8" Ib="8"/>
<Light Px="0" Py="0" Pz="0" Radius="2"/>)"))
                            .scene;
    ASSERT_EQ(scene.inverse_square_lights.size(), 1u);
    EXPECT_EQ(scene.inverse_square_lights[0].intensity, (Color{4, 1, 1}));
    ASSERT_EQ(scene.lights.size(), 1u);  // the Falloff-0 one
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_DOUBLE_EQ(sphere(scene, 0).radius(), 2);
    EXPECT_EQ(scene.objects[0]->material().emission, (Color{2, 2, 2}));  // I / R²
    EXPECT_EQ(scene.objects[0]->material().diffuse, 0);
    EXPECT_EQ(body_error(R"(<Light Px="0" Py="0" Pz="0" Falloff="2"/>)"),
              "t.xml:2: Light: Falloff must be 0 or 1, got 2");
}

TEST(SceneLoaderLightTransport, AmbientIsIgnoredByThePathIntegratorWithAWarningNamingItsLine) {
    const auto warnings = warnings_of(R"(<Render Integrator="path"/>
<Ambient r="0.1"/>)");
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0].rfind("t.xml:3: warning: Ambient is ignored by the path integrator", 0),
              0u);
    EXPECT_TRUE(warnings_of(R"(<Ambient r="0.1"/>)").empty());
}

TEST(SceneLoaderLightTransport, ClampIsOffByDefaultNonNegativeAndForThePathIntegratorOnly) {
    EXPECT_EQ(load(in_scene("")).scene.settings.clamp, 0);
    EXPECT_EQ(load(in_scene(R"(<Render Integrator="path" Clamp="2.5"/>)")).scene.settings.clamp,
              2.5);
    EXPECT_EQ(body_error(R"(<Render Integrator="path" Clamp="-1"/>)"),
              "t.xml:2: Render: Clamp must be non-negative, got -1");
    EXPECT_EQ(body_error(R"(<Render Clamp="inf"/>)"),
              "t.xml:2: Render: attribute 'Clamp' is not a number: \"inf\"");
    const auto warnings = warnings_of(R"(<Render Clamp="3"/>)");
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0], "t.xml:2: warning: Clamp is used by the path integrator only");
    EXPECT_TRUE(warnings_of(R"(<Render Integrator="path" Clamp="3"/>)").empty());
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

TEST(SceneLoaderPhotons, CountAndRadiusAreCheckedWithTheirLine) {
    EXPECT_EQ(body_error(R"(<Photons Count="0"/>)"),
              "t.xml:2: Photons: Count must be positive, got 0");
    EXPECT_EQ(body_error(R"(<Photons Count="20000000"/>)"),
              "t.xml:2: Photons: Count must be at most 16777216, got 20000000");
    EXPECT_EQ(body_error(R"(<Photons Radius="-1"/>)"),
              "t.xml:2: Photons: Radius must be positive, got -1");
    EXPECT_EQ(body_error(R"(<Photons Count="1.5"/>)").substr(0, 18), "t.xml:2: Photons: ");
    const Scene defaults = load(in_scene("<Photons/>")).scene;
    ASSERT_TRUE(defaults.settings.photons);
    EXPECT_EQ(defaults.settings.photons->count, PhotonSettings::kDefaultCount);
    EXPECT_EQ(defaults.settings.photons->radius, 0);  // drt's default, worked out per scene
    EXPECT_FALSE(load(in_scene("")).scene.settings.photons);
}

}  // namespace
}  // namespace drt
