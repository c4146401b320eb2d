#include "drt/render/render_plan.h"

#include <gtest/gtest.h>

#include <optional>

#include "drt/render/renderer.h"
#include "test_render.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::floor_scene;
using testing::lone_sphere_scene;
using testing::render_with;

void add_sphere_light(Scene& scene, Vec3 centre, double radius, Color intensity = {1, 1, 1}) {
    scene.lights.push_back(std::make_unique<SphereLight>(centre, radius, intensity, false));
}

// An 8 x 8 floor scene with a sphere of radius 1 along `path` (one point: a still sphere).
Scene floor_with_sphere(std::vector<Vec3> path) {
    Scene scene = floor_scene(8, 8);
    scene.objects.push_back(
        std::make_unique<Sphere>(std::move(path), 1.0, *scene.materials.front()));
    return scene;
}

TEST(RenderPlan, PointLightGetsExactlyOneShadowRay) {
    Scene scene = floor_scene(8, 8);
    scene.settings.shadow_rays = 10;
    scene.lights.push_back(std::make_unique<PointLight>(Vec3{0, 100, 0}, Color{1, 1, 1}));
    const RenderPlan plan = plan_render(scene);
    EXPECT_EQ(plan.shadow_rays, std::vector<int>{1});
    EXPECT_FALSE(plan.effects.soft_shadows);
    const RenderResult r = render_with(scene);
    EXPECT_EQ(r.stats.rays.camera, 64u);
    EXPECT_EQ(r.stats.rays.shadow, 64u);
}

TEST(RenderPlan, AreaLightsShareShadowRaysInProportionToPower) {
    Scene scene = floor_scene(4, 4);
    scene.settings.shadow_rays = 8;
    add_sphere_light(scene, {0, 100, 0}, 5, {3, 3, 3});
    add_sphere_light(scene, {10, 100, 0}, 5, {1, 1, 1});
    scene.lights.push_back(std::make_unique<PointLight>(Vec3{0, 100, 0}, Color{1, 1, 1}));
    const RenderPlan plan = plan_render(scene);
    EXPECT_EQ(plan.shadow_rays, (std::vector<int>{6, 2, 1}));
    EXPECT_TRUE(plan.effects.soft_shadows);
    const RenderResult r = render_with(scene);
    EXPECT_EQ(r.stats.rays.shadow, 16u * 9u);
}

TEST(RenderPlan, AShareThatIsAWholeNumberOfRaysIsGivenExactly) {
    // Powers 1 and 3: a quarter and three quarters of the rays, whichever light comes first.
    for (const int rays : {8, 16, 100}) {
        for (const bool weak_first : {true, false}) {
            Scene scene = floor_scene(4, 4);
            scene.settings.shadow_rays = rays;
            add_sphere_light(scene, {0, 100, 0}, 5, weak_first ? Color{1, 1, 1} : Color{3, 3, 3});
            add_sphere_light(scene, {10, 100, 0}, 5, weak_first ? Color{3, 3, 3} : Color{1, 1, 1});
            const std::vector<int> quarter{rays / 4, 3 * rays / 4};
            const std::vector<int> expected =
                weak_first ? quarter : std::vector<int>{quarter[1], quarter[0]};
            EXPECT_EQ(plan_render(scene).shadow_rays, expected) << rays << " rays";
        }
    }
}

TEST(RenderPlan, LightsUnderOneRayGetOneAndTheOthersShareTheRestInProportion) {
    // Shares 3.33, 1 and 0.67 of 5 rays: the last gets one, which leaves the middle one
    // 4 × 3/13 = 0.92, so it gets one too, and the first the remaining three (where one ray
    // each and the two left by power would give 2, 2 and 1).
    Scene scene = floor_scene(4, 4);
    scene.settings.shadow_rays = 5;
    add_sphere_light(scene, {0, 100, 0}, 5, {10, 10, 10});
    add_sphere_light(scene, {10, 100, 0}, 5, {3, 3, 3});
    add_sphere_light(scene, {20, 100, 0}, 5, {2, 2, 2});
    EXPECT_EQ(plan_render(scene).shadow_rays, (std::vector<int>{3, 1, 1}));
}

TEST(RenderPlan, EveryAreaLightGetsAtLeastOneRay) {
    Scene scene = floor_scene(4, 4);
    scene.settings.shadow_rays = 3;
    add_sphere_light(scene, {0, 100, 0}, 5, {100, 100, 100});
    add_sphere_light(scene, {10, 100, 0}, 5, {1, 1, 1});
    EXPECT_EQ(plan_render(scene).shadow_rays, (std::vector<int>{2, 1}));
}

TEST(RenderPlan, FewerRaysThanAreaLightsPickLightsByPower) {
    Scene scene = floor_scene(16, 16);
    scene.settings.shadow_rays = 1;
    add_sphere_light(scene, {0, 100, 0}, 5, {3, 3, 3});
    add_sphere_light(scene, {10, 100, 0}, 5, {1, 1, 1});
    const RenderPlan plan = plan_render(scene);
    EXPECT_EQ(plan.shared_rays, 1);
    ASSERT_EQ(plan.light_pick_cdf.size(), 2u);
    EXPECT_DOUBLE_EQ(plan.light_pick_cdf[0], 0.75);
    const RenderResult r = render_with(scene);
    EXPECT_EQ(r.stats.rays.shadow, 256u);
    // Unbiased: the mean equals that of the same scene with enough rays for every light.
    Scene reference = floor_scene(16, 16);
    reference.settings.shadow_rays = 64;
    add_sphere_light(reference, {0, 100, 0}, 5, {3, 3, 3});
    add_sphere_light(reference, {10, 100, 0}, 5, {1, 1, 1});
    const RenderResult ref = render_with(reference);
    double a = 0, b = 0;
    for (int i = 0; i < 256; ++i) a += r.image.rgb[3 * i], b += ref.image.rgb[3 * i];
    EXPECT_NEAR(a / 256, b / 256, 0.01 * b / 256);
}

TEST(RenderPlan, SoftShadowRaysPerShadingPoint) {
    Scene scene = floor_scene(8, 8);
    scene.settings.shadow_rays = 10;
    add_sphere_light(scene, {0, 100, 0}, 5);
    const RenderResult r = render_with(scene);
    EXPECT_EQ(r.stats.rays.camera, 64u);
    EXPECT_EQ(r.stats.rays.shadow, 640u);
}

TEST(RenderPlan, OneSamplePerPixelMeansNoAntialiasing) {
    Scene scene = floor_scene(8, 8);
    EXPECT_FALSE(plan_render(scene).effects.antialiasing);
    scene.settings.samples = 2;
    EXPECT_TRUE(plan_render(scene).effects.antialiasing);
}

TEST(RenderPlan, EffectsFollowTheScene) {
    Scene scene = lone_sphere_scene(testing::mirror({1, 1, 1}), {1, 1, 1});
    Effects e = plan_render(scene).effects;
    EXPECT_FALSE(e.glossy_reflection || e.glossy_refraction || e.depth_of_field || e.motion_blur ||
                 e.soft_shadows || e.antialiasing);

    scene.lens = {0.5, 10};
    EXPECT_TRUE(plan_render(scene).effects.depth_of_field);

    Scene glossy = lone_sphere_scene(testing::mirror({1, 1, 1}, 100.0), {1, 1, 1});
    e = plan_render(glossy).effects;
    EXPECT_TRUE(e.glossy_reflection);
    EXPECT_FALSE(e.glossy_refraction);
    // A sharpness so high that sigma is below 1e-4 is an ideal mirror.
    Scene sharp = lone_sphere_scene(testing::mirror({1, 1, 1}, 20000.0), {1, 1, 1});
    EXPECT_FALSE(plan_render(sharp).effects.glossy_reflection);

    Scene blurry_glass = lone_sphere_scene(testing::glass(1.5, 50.0), {1, 1, 1});
    EXPECT_TRUE(plan_render(blurry_glass).effects.glossy_refraction);

    const Scene moving = floor_with_sphere({{0, 5, 0}, {1, 5, 0}, {2, 5, 0}});
    const RenderPlan plan = plan_render(moving);
    EXPECT_TRUE(plan.effects.motion_blur);
    EXPECT_EQ(plan.shutter_end, 2.0);
}

// MotionBlurPosition children at the object's own place move nothing: no shutter, no time drawn,
// the same image as without them. Beside a moving object, the still path's length still sets
// the shutter, as it always has.
TEST(RenderPlan, APathThatStaysInOnePlaceBlursNothing) {
    Scene still = floor_with_sphere({{0, 5, 0}, {0, 5, 0}, {0, 5, 0}});
    const RenderPlan plan = plan_render(still);
    EXPECT_FALSE(plan.effects.motion_blur);
    EXPECT_EQ(plan.shutter_end, 0.0);
    EXPECT_NE(describe(still, plan).find("(0 moving)"), std::string::npos);
    EXPECT_EQ(render_with(still).image.rgb, render_with(floor_with_sphere({{0, 5, 0}})).image.rgb);

    still.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{3, 5, 0}, {4, 5, 0}}, 1.0,
                                                     *still.materials.front()));
    const RenderPlan mixed = plan_render(still);
    EXPECT_TRUE(mixed.effects.motion_blur);
    EXPECT_EQ(mixed.shutter_end, 2.0);
}

TEST(RenderPlan, IdealMirrorTracesOneRayGlossyTracesGlossyRaysAtFirstHit) {
    Scene ideal = lone_sphere_scene(testing::mirror({1, 1, 1}), {1, 1, 1});
    ideal.settings.glossy_rays = 5;
    const RenderResult r_ideal = render_with(ideal);
    Scene glossy = lone_sphere_scene(testing::mirror({1, 1, 1}, 20.0), {1, 1, 1});
    glossy.settings.glossy_rays = 5;
    const RenderResult r_glossy = render_with(glossy);
    ASSERT_GT(r_ideal.stats.rays.reflection, 0u);
    EXPECT_EQ(r_glossy.stats.rays.reflection, 5 * r_ideal.stats.rays.reflection);
}

// A camera looking down at a glass floor over a second glass floor 5 below: each camera ray's
// refractions meet the lower floor at depth 1, whose reflections come back to the upper floor
// at depth 2.
Scene two_glass_floors(std::optional<double> sharpness, int glossy_rays) {
    Scene scene = floor_scene(6, 4);
    scene.settings.max_depth = 2;
    scene.settings.glossy_rays = glossy_rays;
    const Material& glass = testing::add_material(scene, testing::glass(1.5, sharpness));
    scene.objects.clear();
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, glass));
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, -5, 0}, Vec3{0, 1, 0}, glass));
    return scene;
}

TEST(RenderPlan, IdealGlassTracesOneRayEachWayAtEveryDepth) {
    // Depth 0: one reflection (escapes) and one refraction; depth 1: the same at the lower
    // floor; depth 2 is MaxDepth and spawns nothing. GlossyRays does not apply.
    const RenderResult r = render_with(two_glass_floors(std::nullopt, 5));
    EXPECT_EQ(r.stats.rays.camera, 24u);
    EXPECT_EQ(r.stats.rays.reflection, 2u * 24);
    EXPECT_EQ(r.stats.rays.refraction, 2u * 24);
    EXPECT_EQ(r.stats.rays.shadow, 0u);
    EXPECT_FALSE(r.plan.effects.glossy_reflection || r.plan.effects.glossy_refraction);
}

TEST(RenderPlan, BlurryGlassTracesGlossyRaysAtTheFirstHitAndOneDeeper) {
    // Depth 0: G reflections and G refractions; each refraction meets the lower floor at depth
    // 1 and spawns one of each.
    const RenderResult r = render_with(two_glass_floors(30.0, 3));
    EXPECT_EQ(r.stats.rays.reflection, (3u + 3u) * 24);
    EXPECT_EQ(r.stats.rays.refraction, (3u + 3u) * 24);
    EXPECT_TRUE(r.plan.effects.glossy_reflection && r.plan.effects.glossy_refraction);
}

TEST(RenderPlan, EffectsThatCannotShowAreOff) {
    // A lens of radius 0 is a pinhole: no lens sample, and the very same image.
    Scene pinhole = floor_scene(8, 8);
    pinhole.lights.push_back(std::make_unique<PointLight>(Vec3{3, 40, 2}, Color{1, 1, 1}));
    Scene zero_lens = floor_scene(8, 8);
    zero_lens.lights.push_back(std::make_unique<PointLight>(Vec3{3, 40, 2}, Color{1, 1, 1}));
    zero_lens.lens = {0, 25};
    const RenderResult a = render_with(pinhole), b = render_with(zero_lens);
    EXPECT_FALSE(b.plan.effects.depth_of_field);
    EXPECT_EQ(a.image.rgb, b.image.rgb);

    // An area light with nothing diffuse to shade casts no penumbra anywhere.
    Scene mirror_only = lone_sphere_scene(testing::mirror({1, 1, 1}), {0.5, 0.5, 0.5});
    add_sphere_light(mirror_only, {0, 10, 0}, 2);
    mirror_only.settings.shadow_rays = 8;
    const RenderResult m = render_with(mirror_only);
    EXPECT_FALSE(m.plan.effects.soft_shadows);
    EXPECT_EQ(m.stats.rays.shadow, 0u);

    // With MaxDepth 0 no reflection is ever traced, so glossy materials are not sampled.
    Scene flat = lone_sphere_scene(testing::glass(1.5, 10.0), {1, 1, 1});
    flat.settings.max_depth = 0;
    const RenderResult f = render_with(flat);
    EXPECT_FALSE(f.plan.effects.glossy_reflection || f.plan.effects.glossy_refraction);
    EXPECT_EQ(f.stats.rays.reflection + f.stats.rays.refraction, 0u);
}

TEST(RenderPlan, MotionAndLensAddNoRays) {
    // Time and lens samples change where rays go, never how many there are.
    Scene still = floor_scene(8, 8);
    still.settings.samples = 3;
    add_sphere_light(still, {0, 100, 0}, 5);
    still.settings.shadow_rays = 4;
    Scene moving = floor_scene(8, 8);
    moving.settings.samples = 3;
    add_sphere_light(moving, {0, 100, 0}, 5);
    moving.settings.shadow_rays = 4;
    moving.lens = {2, 50};
    const Material& m = *moving.materials.front();
    moving.objects.push_back(
        std::make_unique<Sphere>(std::vector<Vec3>{{0, 200, 0}, {5, 200, 0}}, 1.0, m));
    const RenderResult a = render_with(still), b = render_with(moving);
    EXPECT_TRUE(b.plan.effects.motion_blur && b.plan.effects.depth_of_field);
    EXPECT_FALSE(a.plan.effects.motion_blur || a.plan.effects.depth_of_field);
    EXPECT_EQ(a.stats.rays.camera, 3u * 64);
    EXPECT_EQ(a.stats.rays.shadow, 4u * 3 * 64);
    EXPECT_EQ(b.stats.rays.camera, a.stats.rays.camera);
    EXPECT_EQ(b.stats.rays.shadow, a.stats.rays.shadow);
}

TEST(RenderPlan, DescribeNamesTheSampledEffects) {
    Scene scene = floor_scene(4, 4);
    scene.lens = {1, 10};
    const std::string text = describe(scene, plan_render(scene));
    EXPECT_NE(text.find("depth_of_field: sampled"), std::string::npos);
    EXPECT_NE(text.find("motion_blur: off"), std::string::npos);
    // Which integrator, and what it leaves out, whichever it is.
    EXPECT_NE(text.find("integrator: distributed"), std::string::npos) << text;
    EXPECT_NE(text.find("indirect_light: off"), std::string::npos) << text;
    EXPECT_NE(text.find("emitters: 0"), std::string::npos) << text;
    scene.settings.integrator = IntegratorKind::kPath;
    const std::string path = describe(scene, plan_render(scene));
    EXPECT_NE(path.find("integrator: path"), std::string::npos) << path;
    EXPECT_NE(path.find("indirect_light: sampled"), std::string::npos) << path;
}

}  // namespace
}  // namespace drt
