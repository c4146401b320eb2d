#include "drt/render/integrator.h"
#include "drt/sampling/multi_jittered.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "drt/render/render_plan.h"
#include "drt/render/renderer.h"
#include "drt/sampling/sampler.h"
#include "sanitizers.h"
#include "test_render.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::floor_scene;
using testing::lone_sphere_scene;
using testing::render_with;

TEST(Integrator, GreyFloorUnderPointLightIsLambertExactly) {
    Scene scene = floor_scene(24, 16);
    const Vec3 light{7, 30, -3};
    const Color intensity{1.0, 0.5, 0.25};
    scene.lights.push_back(std::make_unique<PointLight>(light, intensity));
    const RenderResult r = render_with(scene);
    const Camera camera = scene.camera();
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 24; ++x) {
            const Ray ray = camera.generate_ray({x + 0.5, y + 0.5}, {0.5, 0.5}, 0);
            const Vec3 p = ray.at(-ray.origin.y / ray.dir.y);
            const double cosine = normalize(light - p).y;
            const Color expected = 0.8 * intensity * cosine;
            const Color got = r.image.at(x, y);
            ASSERT_NEAR(got.r, expected.r, 1e-6) << x << "," << y;
            ASSERT_NEAR(got.g, expected.g, 1e-6);
            ASSERT_NEAR(got.b, expected.b, 1e-6);
        }
    }
}

TEST(Integrator, AmbientAddsToTheLightsInTheDiffusePart) {
    Scene scene = floor_scene(4, 4);
    scene.ambient = {0.25, 0.25, 0.25};
    const RenderResult r = render_with(scene);
    EXPECT_NEAR(r.image.at(1, 1).r, 0.8 * 0.25, 1e-7);
}

TEST(Integrator, IdealMirrorOfUniformBackgroundReturnsKsTimesBackground) {
    const Color background{0.2, 0.4, 0.6};
    const Color ks{0.5, 0.7, 0.9};
    const RenderResult r = render_with(lone_sphere_scene(testing::mirror(ks), background));
    int mirror_pixels = 0;
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            const Color c = r.image.at(x, y);
            if (c == Color{float(background.r), float(background.g), float(background.b)}) continue;
            ++mirror_pixels;
            EXPECT_FLOAT_EQ(c.r, ks.r * background.r);
            EXPECT_FLOAT_EQ(c.g, ks.g * background.g);
            EXPECT_FLOAT_EQ(c.b, ks.b * background.b);
        }
    }
    EXPECT_GT(mirror_pixels, 100);
    EXPECT_EQ(r.stats.rays.reflection, static_cast<std::uint64_t>(mirror_pixels));
}

TEST(Integrator, GlossyMirrorOfUniformBackgroundConservesEnergy) {
    const Color background{0.3, 0.3, 0.3};
    Scene scene = lone_sphere_scene(testing::mirror({0.6, 0.6, 0.6}, 10.0), background);
    scene.settings.glossy_rays = 4;
    const RenderResult r = render_with(scene);
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            const double v = r.image.at(x, y).r;
            // Every perturbed ray escapes a convex mirror, so each pixel is exactly one of two
            // values.
            ASSERT_TRUE(std::abs(v - 0.3) < 1e-6 || std::abs(v - 0.18) < 1e-6) << v;
        }
    }
}

TEST(Integrator, GlassSphereWithIndexOneVanishesExactly) {
    const Color background{0.1, 0.5, 0.9};
    const RenderResult r = render_with(lone_sphere_scene(testing::glass(1.0), background));
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            const Color c = r.image.at(x, y);
            ASSERT_FLOAT_EQ(c.r, 0.1f);
            ASSERT_FLOAT_EQ(c.g, 0.5f);
            ASSERT_FLOAT_EQ(c.b, 0.9f);
        }
    }
}

TEST(Integrator, GlassSphereInUniformBackgroundShowsTheBackground) {
    const Color background{0.5, 0.5, 0.5};
    Scene scene = lone_sphere_scene(testing::glass(1.5), background, 48);
    scene.settings.max_depth = 32;
    const RenderResult r = render_with(scene);
    double sum = 0;
    double worst = 0;
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            sum += r.image.at(x, y).g;
            worst = std::max(worst, std::abs(r.image.at(x, y).g - 0.5));
        }
    }
    EXPECT_NEAR(sum / (48 * 48), 0.5, 1e-4);
    EXPECT_LT(worst, 1e-3);  // only chains of internal reflection longer than MaxDepth lose light
}

TEST(Integrator, BlurryGlassSphereInUniformBackgroundShowsTheBackground) {
    // The Fresnel weights of the two branches add up to 1 whichever way the perturbed rays go,
    // and every path ends in the background: only chains cut by MaxDepth lose anything, and no
    // pixel may ever gain. Blurry glass traps rays in long random walks of total internal
    // reflection (at n = 10 a few pixels lose 10-20% at MaxDepth 32, none at 512); at n = 2 the
    // walks are short enough for MaxDepth 128 to lose nothing visible.
    const Color background{0.5, 0.5, 0.5};
    for (const auto& [n, max_depth, pixel_tolerance] :
         {std::tuple{2.0, 128, 1e-3}, std::tuple{10.0, 32, 0.25}}) {
        Scene scene = lone_sphere_scene(testing::glass(1.5, n), background, 16);
        scene.settings.max_depth = max_depth;
        scene.settings.samples = 4;
        scene.settings.glossy_rays = 2;
        const RenderResult r = render_with(scene);
        ASSERT_GT(r.stats.rays.refraction, 4u * 2 * 50);
        double sum = 0;
        for (int y = 0; y < r.image.height; ++y) {
            for (int x = 0; x < r.image.width; ++x) {
                const double v = r.image.at(x, y).g;
                sum += v;
                ASSERT_LE(v, 0.5 + 1e-6) << n << " " << x << "," << y;
                ASSERT_GT(v, 0.5 - pixel_tolerance) << n << " " << x << "," << y;
            }
        }
        EXPECT_NEAR(sum / (16 * 16), 0.5, 0.01) << n;
    }
}

TEST(Integrator, MaxDepthZeroMakesMirrorsBlack) {
    Scene scene = lone_sphere_scene(testing::mirror({1, 1, 1}), {1, 1, 1});
    scene.settings.max_depth = 0;
    const RenderResult r = render_with(scene);
    EXPECT_EQ(r.image.at(16, 16).r, 0.0f);
    EXPECT_EQ(r.stats.rays.reflection, 0u);
}

TEST(Integrator, EachBounceUpToMaxDepthAddsItsShareAndNoMore) {
    // The eye at the centre of a sphere both Lambert (kd 1) and mirror (ks 1/2), under ambient
    // light a and nothing else: every ray returns through the centre to the sphere, each hit adds
    // a, and the mirror passes on half of what the next hit sees, for MaxDepth bounces:
    // a (1 + 1/2 + ... + 1/2^D) = a (2 - 2^-D), one reflection ray per bounce.
    constexpr int kSize = 4;
    const double ambient = 0.25;
    for (const int max_depth : {0, 1, 3}) {
        Scene scene;
        scene.path = "test";
        scene.settings.width = scene.settings.height = kSize;
        scene.settings.samples = 1;
        scene.settings.max_depth = max_depth;
        scene.ambient = {ambient, ambient, ambient};
        scene.view = LookAt{{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 60};
        Material m = testing::grey_lambert(1.0);
        m.reflective = 1;
        m.ks = {0.5, 0.5, 0.5};
        const Material& material = testing::add_material(scene, m);
        scene.objects.push_back(
            std::make_unique<Sphere>(std::vector<Vec3>{{0, 0, 0}}, 10.0, material));
        const RenderResult r = render_with(scene);
        const double expected = ambient * (2 - std::ldexp(1.0, -max_depth));
        for (int y = 0; y < kSize; ++y) {
            for (int x = 0; x < kSize; ++x) {
                ASSERT_NEAR(r.image.at(x, y).r, expected, 1e-6) << max_depth;
            }
        }
        EXPECT_EQ(r.stats.rays.reflection, std::uint64_t{kSize * kSize} * max_depth);
    }
}

// A glossy mirror floor (sharpness n) seen straight down from above reflects about the vertical,
// where a visible light of unit intensity, far away, subtends the half-angle rho; the sky is
// black.
Scene glossy_floor_under_light(double sharpness, double rho, int glossy_rays) {
    Scene scene;
    scene.path = "test";
    scene.settings.width = scene.settings.height = 1;
    scene.settings.samples = 1;
    scene.settings.glossy_rays = glossy_rays;
    scene.view = LookAt{{0, 50, 0}, {0, 0, 0}, {0, 0, 1}, 10};
    const Material& m = testing::add_material(scene, testing::mirror({1, 1, 1}, sharpness));
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, m));
    const double distance = 1000;
    scene.lights.push_back(std::make_unique<SphereLight>(
        Vec3{0, distance, 0}, distance * std::sin(rho), Color{1, 1, 1}, true));
    return scene;
}

TEST(Integrator, GlossyLobeWidthIsOneOverTheSharpness) {
    // A perturbed ray leaves at an angle from the ideal one that is Rayleigh-distributed with
    // scale sigma, so a share 1 - exp(-rho^2 / (2 sigma^2)) of the glossy rays meets the light:
    // that is the pixel's value, and sigma = rho / sqrt(-2 ln(1 - value)) reads the lobe's width
    // back from the image. The angle grows with the first coordinate of a glossy point alone, so
    // the share is a threshold on it, which 1024 stratified points place to within 1/1024: the
    // width comes out within about 0.15 % (measured over seeds 0-5: at most 0.15 %), and 0.5 %
    // is allowed, where a lobe 2 % too wide or narrow is caught.
    for (const auto& [sharpness, share_of_sigma] : {std::pair{20.0, 1.0}, std::pair{5.0, 2.0}}) {
        const double sigma = 1 / sharpness, rho = share_of_sigma * sigma;
        const RenderResult r = render_with(glossy_floor_under_light(sharpness, rho, 1024));
        const double value = r.image.at(0, 0).g;
        EXPECT_NEAR(value, 1 - std::exp(-rho * rho / (2 * sigma * sigma)), 2e-3);
        const double measured = rho / std::sqrt(-2 * std::log(1 - value));
        EXPECT_NEAR(measured, sigma, 5e-3 * sigma) << "n " << sharpness << ", rho " << rho;
    }
}

TEST(Integrator, GlassSurfaceBendsBySnellsLawAndTransmitsWhatFresnelLeaves) {
    // Camera rays meet a glass floor (index 1.5, from 25 to 60 degrees): what each reflects
    // goes up to a black sky, what it transmits goes on into the glass, to a visible light of unit
    // intensity below or to nothing. So a pixel is 1 - F where the refracted ray meets the light
    // and 0 elsewhere, F the Fresnel reflectance for unpolarised light: both the direction
    // (Snell: the component along the surface shrinks by the index) and F depend on the index,
    // and no sampling is involved, so a pixel misses its value only by rounding.
    const double index = 1.5;
    constexpr int kSize = 32;
    Scene scene;
    scene.path = "test";
    scene.settings.width = scene.settings.height = kSize;
    scene.settings.samples = 1;
    scene.view = LookAt{{0, 30, -30}, {0, 0, 0}, {0, 1, 0}, 24};
    const Material& glass = testing::add_material(scene, testing::glass(index));
    scene.objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, glass));
    // Below where the central ray, refracted from 45 degrees, reaches the depth 20.
    const double depth = 20, radius = 5;
    const double sin_t = std::sin(kPi / 4) / index;
    const Vec3 centre{0, -depth, depth * sin_t / std::sqrt(1 - sin_t * sin_t)};
    scene.lights.push_back(std::make_unique<SphereLight>(centre, radius, Color{1, 1, 1}, true));
    const RenderResult r = render_with(scene);
    const Camera camera = scene.camera();
    int lit = 0, dark = 0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const Ray ray = camera.generate_ray({x + 0.5, y + 0.5}, {0.5, 0.5}, 0);
            const Vec3 p = ray.at(-ray.origin.y / ray.dir.y);
            const Vec3 along_surface{ray.dir.x / index, 0, ray.dir.z / index};
            const Vec3 t =
                along_surface - Vec3{0, std::sqrt(1 - dot(along_surface, along_surface)), 0};
            const double cos_i = -ray.dir.y, cos_t = -t.y;
            const double rs = (cos_i - index * cos_t) / (cos_i + index * cos_t);
            const double rp = (index * cos_i - cos_t) / (index * cos_i + cos_t);
            const double fresnel = (rs * rs + rp * rp) / 2;
            const Vec3 to_centre = centre - p;
            const double miss = length(to_centre - t * dot(to_centre, t));
            if (std::abs(miss - radius) < 1e-6) continue;  // too close to the light's rim to tell
            const double expected = miss < radius ? 1 - fresnel : 0;
            (miss < radius ? lit : dark) += 1;
            ASSERT_NEAR(r.image.at(x, y).g, expected, 1e-6) << x << "," << y;
        }
    }
    EXPECT_GT(lit, 100);
    EXPECT_GT(dark, 100);
}

TEST(Integrator, ImageIsIdenticalForOneAndTwoThreads) {
    Scene scene = floor_scene(40, 30);
    scene.settings.samples = 4;
    scene.settings.shadow_rays = 3;
    scene.lights.push_back(
        std::make_unique<SphereLight>(Vec3{5, 20, 5}, 6.0, Color{1, 1, 1}, false));
    const Material& m = testing::add_material(scene, testing::mirror({0.9, 0.9, 0.9}, 20.0));
    scene.objects.push_back(
        std::make_unique<Sphere>(std::vector<Vec3>{{0, 5, 0}, {3, 5, 0}}, 5.0, m));
    const RenderResult one = render_with(scene, 1);
    const RenderResult two = render_with(scene, 2);
    EXPECT_EQ(one.image.rgb, two.image.rgb);
    EXPECT_EQ(one.stats.rays.total(), two.stats.rays.total());
    scene.settings.seed = 7;
    EXPECT_NE(render_with(scene, 2).image.rgb, one.image.rgb);
}

// Integrator runs with a plan whose effect flags may be changed from what plan_render decides.
class PlannedIntegrator {
  public:
    PlannedIntegrator(const Scene& scene, const std::function<void(Effects&)>& change)
        : scene_(scene),
          plan_(plan_render(scene)),
          bvh_(scene.objects),
          sampler_(make_sampler(scene.settings.sampler)) {
        change(plan_.effects);
        integrator_.emplace(scene, plan_, bvh_, *sampler_);
    }
    // Every camera sample of pixel (x, y).
    std::vector<Color> pixel(int x, int y, RayCounts& rays) const {
        const auto spp = static_cast<std::uint32_t>(scene_.settings.samples);
        std::vector<Color> colors(spp);
        const PixelSample s{scene_.settings.seed,
                            static_cast<std::uint32_t>(y * scene_.settings.width + x), 0, spp};
        integrator_->sample_pixel(x, y, s, colors, rays);
        return colors;
    }
    // Whether any pixel's camera samples differ from one another.
    bool samples_vary() const {
        RayCounts rays;
        for (int y = 0; y < scene_.settings.height; ++y) {
            for (int x = 0; x < scene_.settings.width; ++x) {
                const std::vector<Color> c = pixel(x, y, rays);
                if (std::any_of(c.begin(), c.end(), [&](const Color& v) { return v != c[0]; }))
                    return true;
            }
        }
        return false;
    }

  private:
    const Scene& scene_;
    RenderPlan plan_;
    Bvh bvh_;
    std::unique_ptr<Sampler> sampler_;
    std::optional<Integrator> integrator_;
};

// Each figure scene calls for antialiasing and one or two other effects. With antialiasing and
// those effects turned off in the plan, a pixel's samples are all the same; with one of them
// left on, they are not. So each flag is read, and nothing is sampled behind a flag's back.
TEST(Integrator, SamplesEveryEffectItsPlanCallsForAndNoOther) {
    struct Case {
        std::string scene;
        std::function<void(Effects&)> off;  // besides antialiasing
        bool samples_vary;
    };
    const auto nothing = [](Effects&) {};
    const std::vector<Case> cases = {
        {"figures/aa-10spp.xml", nothing, false},
        {"figures/depth-of-field.xml", nothing, true},
        {"figures/depth-of-field.xml", [](Effects& e) { e.depth_of_field = false; }, false},
        {"figures/motion-blur.xml", nothing, true},
        {"figures/motion-blur.xml", [](Effects& e) { e.motion_blur = false; }, false},
        {"figures/soft-shadow-one-light.xml", nothing, true},
        {"figures/soft-shadow-one-light.xml", [](Effects& e) { e.soft_shadows = false; }, false},
        {"figures/glossy-n10.xml", nothing, true},
        {"figures/glossy-n10.xml", [](Effects& e) { e.glossy_reflection = false; }, false},
        {"figures/refraction-n10.xml", [](Effects& e) { e.glossy_reflection = false; }, true},
        {"figures/refraction-n10.xml", [](Effects& e) { e.glossy_refraction = false; }, true},
        {"figures/refraction-n10.xml",
         [](Effects& e) { e.glossy_reflection = e.glossy_refraction = false; }, false},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.scene);
        const Scene scene = testing::scaled_scene(c.scene, 24, 8);
        EXPECT_TRUE(PlannedIntegrator(scene, nothing).samples_vary());
        const PlannedIntegrator reduced(scene, [&](Effects& e) {
            e.antialiasing = false;
            c.off(e);
        });
        EXPECT_EQ(reduced.samples_vary(), c.samples_vary);
    }
}

// Glossy rays are traced as the plan says: GlossyRays at the first hit when the effect is on,
// exactly one ideal ray per hit when it is off, whatever the material's sharpness.
TEST(Integrator, GlossyRaysFollowThePlansFlags) {
    const auto glossy_rays = [](const Material& material,
                                const std::function<void(Effects&)>& change) {
        Scene scene = testing::lone_sphere_scene(material, {0.2, 0.4, 0.6});
        scene.settings.samples = 4;
        scene.settings.glossy_rays = 8;
        scene.settings.max_depth = 1;  // no second bounce inside the glass
        RayCounts rays;
        PlannedIntegrator(scene, change).pixel(16, 16, rays);  // the sphere's middle
        EXPECT_EQ(rays.camera, 4u);
        return std::pair{rays.reflection, rays.refraction};
    };
    const auto as_planned = [](Effects&) {};
    const auto no_glossy_reflection = [](Effects& e) { e.glossy_reflection = false; };
    const auto no_glossy_refraction = [](Effects& e) { e.glossy_refraction = false; };
    const Material mirror = testing::mirror({0.9, 0.9, 0.9}, 10);
    EXPECT_EQ(glossy_rays(mirror, as_planned), std::pair(32ul, 0ul));
    EXPECT_EQ(glossy_rays(mirror, no_glossy_reflection), std::pair(4ul, 0ul));
    const Material glass = testing::glass(1.5, 10);
    EXPECT_EQ(glossy_rays(glass, as_planned), std::pair(32ul, 32ul));
    EXPECT_EQ(glossy_rays(glass, no_glossy_reflection), std::pair(4ul, 32ul));
    EXPECT_EQ(glossy_rays(glass, no_glossy_refraction), std::pair(32ul, 4ul));

    // Off, the one ray is the ideal one: the same radiance as an ideal mirror's.
    Scene glossy = testing::lone_sphere_scene(mirror, {0.2, 0.4, 0.6});
    Scene ideal = testing::lone_sphere_scene(testing::mirror({0.9, 0.9, 0.9}), {0.2, 0.4, 0.6});
    RayCounts rays;
    EXPECT_EQ(PlannedIntegrator(glossy, no_glossy_reflection).pixel(12, 13, rays),
              PlannedIntegrator(ideal, as_planned).pixel(12, 13, rays));
}

// A sphere light whose area is not sampled shines as a point light at its centre.
TEST(Integrator, SoftShadowsOffLightsFromTheLightsCentre) {
    const Scene area = testing::scaled_scene("figures/soft-shadow-one-light.xml", 24, 1);
    Scene point = testing::scaled_scene("figures/soft-shadow-one-light.xml", 24, 1);
    const Ball ball = point.lights[0]->extent();
    point.lights[0] = std::make_unique<PointLight>(ball.centre, point.lights[0]->intensity());
    const PlannedIntegrator area_as_point(area, [](Effects& e) { e.soft_shadows = false; });
    const PlannedIntegrator point_light(point, [](Effects&) {});
    const PlannedIntegrator soft(area, [](Effects&) {});
    int differ_when_soft = 0;
    for (int y = 0; y < area.settings.height; ++y) {
        for (int x = 0; x < area.settings.width; ++x) {
            RayCounts rays;
            const Color got = area_as_point.pixel(x, y, rays)[0];
            const Color want = point_light.pixel(x, y, rays)[0];
            ASSERT_NEAR(got.r, want.r, 1e-12) << x << "," << y;
            ASSERT_NEAR(got.b, want.b, 1e-12) << x << "," << y;
            differ_when_soft += std::abs(soft.pixel(x, y, rays)[0].r - want.r) > 1e-3;
        }
    }
    EXPECT_GT(differ_when_soft, 10);
}

// Glass in a closed box of mirrors: every hit on the glass splits into a reflected and a
// refracted ray and the mirrors send both back, so the whole tree grows with every bounce until
// MaxDepth. An emitting ball beside the glass gives the tree's rays different values.
std::string glass_among_mirrors(int max_depth, int size, int samples) {
    std::string planes;
    for (const char* p : {R"(Px="0" Py="-3" Pz="0" Vu="0" Vv="1" Vw="0")",
                          R"(Px="0" Py="3" Pz="0" Vu="0" Vv="-1" Vw="0")",
                          R"(Px="-3" Py="0" Pz="0" Vu="1" Vv="0" Vw="0")",
                          R"(Px="3" Py="0" Pz="0" Vu="-1" Vv="0" Vw="0")",
                          R"(Px="0" Py="0" Pz="-5" Vu="0" Vv="0" Vw="1")",
                          R"(Px="0" Py="0" Pz="5" Vu="0" Vv="0" Vw="-1")"}) {
        planes += std::string("  <Plane ") + p + R"( Material="Mirror"/>)" + "\n";
    }
    return R"(<Scene>
  <Image Width=")" +
           std::to_string(size) + R"(" Height=")" + std::to_string(size) + R"("/>
  <Render Samples=")" +
           std::to_string(samples) + R"(" MaxDepth=")" + std::to_string(max_depth) + R"("/>
  <Camera Ex="0" Ey="0" Ez="-4" Lx="0" Ly="0" Lz="0" Fov="40"/>
  <Materials>
    <Mirror reflective="0.8" ksr="1" ksg="0.8" ksb="0.9"/>
    <Glass transmitt="1" index="1.5"/>
    <Lamp ker="2" keg="1.5" keb="0.5"/>
  </Materials>
)" + planes +
           R"(  <Sphere Px="0" Py="0" Pz="1" Radius="1.5" Material="Glass"/>
  <Sphere Px="1.8" Py="1.5" Pz="3" Radius="0.6" Material="Lamp"/>
</Scene>)";
}

// Every camera sample of a small image through the integrator with the given tree bound: the
// mean of all samples, and how many reflected and refracted rays they took.
std::pair<Color, std::uint64_t> tree_render(const Scene& scene, std::uint64_t whole_tree_rays) {
    const RenderPlan plan = plan_render(scene);
    const Bvh bvh(scene.objects);
    const auto sampler = make_sampler(scene.settings.sampler);
    const Integrator integrator(scene, plan, bvh, *sampler, nullptr, whole_tree_rays);
    const auto spp = static_cast<std::uint32_t>(scene.settings.samples);
    std::vector<Color> colors(spp);
    RayCounts rays;
    Color sum;
    for (int y = 0; y < scene.settings.height; ++y) {
        for (int x = 0; x < scene.settings.width; ++x) {
            const PixelSample s{scene.settings.seed,
                                static_cast<std::uint32_t>(y * scene.settings.width + x), 0, spp};
            integrator.sample_pixel(x, y, s, colors, rays);
            for (const Color& c : colors) sum += c;
        }
    }
    const double n = double(spp) * scene.settings.width * scene.settings.height;
    return {sum / n, rays.reflection + rays.refraction};
}

// Past the bound a hit follows one ray, picked by weight, and rays survive Russian roulette by
// their throughput, each divided by its odds: the mean of many camera samples is the whole
// tree's, for a quarter of the rays. (Each seed's mean scatters by about 3 % about the whole
// tree's; sixteen seeds' by about 0.4 %, four seeds' by 0.8 %: the sanitizer build, 30 times
// slower, takes four and a wider bound.)
TEST(Integrator, ATreePastItsBoundFollowsOneRayWithoutBias) {
#if defined(DRT_TEST_ASAN)
    constexpr std::uint64_t kSeeds = 4;
    constexpr double kTolerance = 0.03;
#else
    constexpr std::uint64_t kSeeds = 16;
    constexpr double kTolerance = 0.015;
#endif
    Color whole, bounded;
    std::uint64_t whole_rays = 0, bounded_rays = 0;
    for (std::uint64_t seed = 0; seed < kSeeds; ++seed) {
        Scene scene = testing::from_xml(glass_among_mirrors(6, 32, 16));
        scene.settings.seed = seed;
        const auto [w, w_rays] = tree_render(scene, ~std::uint64_t{0});
        const auto [b, b_rays] = tree_render(scene, 2);
        whole += w, bounded += b;
        whole_rays += w_rays, bounded_rays += b_rays;
    }
    EXPECT_GT(whole_rays, 3 * bounded_rays);
    testing::expect_relative(bounded, whole, kTolerance, "bounded tree against the whole tree");
}

// Glass between two glossy mirrors, which send back both rays of every split: the whole tree
// would double with each of MaxDepth 512 bounces. With the bound a camera sample takes a few
// thousand rays at most, and the image stays finite.
TEST(Integrator, GlassBetweenMirrorsAtTheDeepestMaxDepthTakesBoundedWork) {
    const Scene scene = testing::from_xml(R"(<Scene>
  <Image Width="8" Height="8"/>
  <Render Samples="4" MaxDepth="512"/>
  <Background r="0.2" g="0.3" b="0.4"/>
  <Camera Ex="0" Ey="0.001" Ez="-5" Lx="0" Ly="0" Lz="100" Fov="40"/>
  <Materials>
    <Mirror reflective="1" n="1"/>
    <Glass transmitt="1" index="1.5" n="1"/>
    <Lamp ker="100" keg="100" keb="100"/>
  </Materials>
  <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Mirror"/>
  <Plane Px="0" Py="3" Pz="0" Vu="0" Vv="-1" Vw="0" Material="Mirror"/>
  <Sphere Px="0" Py="1" Pz="10" Radius="1" Material="Glass"/>
  <Sphere Px="2" Py="1" Pz="10" Radius="0.3" Material="Lamp"/>
</Scene>)");
    const auto [mean, rays] = tree_render(scene, kWholeTreeRays);
    EXPECT_TRUE(is_finite(mean));
    EXPECT_GT(mean.r, 0.2);
    EXPECT_LT(rays, 256u * (kWholeTreeRays + 4 * 512));
}

}  // namespace
}  // namespace drt
