// AOVs (aov.h): the first surface's albedo, facing normal and distance on a floor whose values are
// known in closed form, 0 for escaping rays, the mean over a pixel's camera samples, in both
// integrators, the same on any number of threads, and the image untouched by asking for them.
#include "drt/render/aov.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "drt/render/renderer.h"
#include "test_render.h"

namespace drt {
namespace {

// A floor y = 0 (diffuse 0.5, kd 0.8 0.4 0.2) seen from (0, 1, 0) looking slightly down: the
// upper rows see the sky. `normal_down` turns the plane's normal away from the camera.
Scene floor_scene(const std::string& integrator, int samples, bool normal_down = false) {
    const std::string xml = R"(<Scene>
      <Image Width="24" Height="16"/>
      <Render Integrator=")" +
                            integrator + R"(" Samples=")" + std::to_string(samples) +
                            R"(" ShadowRays="1" MaxDepth="2"/>
      <Background r="0.3" g="0.5" b="0.9"/>
      <Camera Ex="0" Ey="1" Ez="0" Lx="0" Ly="0.7" Lz="10" Fov="40"/>
      <Materials><Floor kdr="0.8" kdg="0.4" kdb="0.2" diffuse="0.5"/></Materials>
      <Lights><Light Px="2" Py="5" Pz="3"/></Lights>
      <Objects><Plane Px="0" Py="0" Pz="0" Vu="0" Vv=")" +
                            std::string(normal_down ? "-1" : "1") +
                            R"(" Vw="0" Material="Floor"/></Objects>
    </Scene>)";
    return testing::from_xml(xml);
}

RenderResult render_aovs(const Scene& scene, int threads = 2) {
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    request.aovs = {Aov::kAlbedo, Aov::kNormal, Aov::kDepth};
    RenderOptions options;
    options.threads = threads;
    return render(scene, request, options);
}

// The 7 values of pixel (x, y): albedo R G B, normal X Y Z, depth.
const float* at(const RenderResult& r, int x, int y) {
    return r.aovs.data() + 7 * (static_cast<std::size_t>(y) * r.image.width + x);
}

// Where the ray through film point (fx, fy) of the floor scene's camera meets y = 0, by the
// look-at camera's definition: its distance, or 0 if it rises.
double floor_distance(double fx, double fy) {
    const Vec3 eye{0, 1, 0};
    const Vec3 forward = normalize(Vec3{0, 0.7, 10} - eye);
    const Vec3 right = normalize(cross(Vec3{0, 1, 0}, forward));
    const Vec3 up = cross(forward, right);
    const double pixel = 2 * std::tan(20 * kPi / 180) / 16;
    const Vec3 dir = normalize(forward + right * ((fx - 12) * pixel) + up * ((8 - fy) * pixel));
    return dir.y < 0 ? -eye.y / dir.y : 0;
}

TEST(Aov, ParsesTheContractsNamesAndRefusesOthers) {
    EXPECT_EQ(parse_aovs("depth,albedo"), (std::vector<Aov>{Aov::kDepth, Aov::kAlbedo}));
    EXPECT_EQ(aov_channel_names(parse_aovs("albedo,normal,depth")),
              (std::vector<std::string>{"albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y",
                                        "normal.Z", "depth.Z"}));
    EXPECT_EQ(aov_channel_count(parse_aovs("normal,depth")), 4u);
    for (const char* bad : {"", "albedo,", "Albedo", "albedo,albedo", "position"}) {
        EXPECT_THROW(parse_aovs(bad), std::invalid_argument) << bad;
    }
}

// One sample per pixel: the pixel centre's ray, whose values are known exactly.
TEST(Aov, FloorGivesExactAlbedoNormalAndAnalyticDepthInBothIntegrators) {
    for (const std::string integrator : {"distributed", "path"}) {
        for (const bool normal_down : {false, true}) {
            const RenderResult r = render_aovs(floor_scene(integrator, 1, normal_down));
            ASSERT_EQ(r.aovs.size(), 7u * 24 * 16);
            int floor = 0, sky = 0;
            for (int y = 0; y < 16; ++y) {
                for (int x = 0; x < 24; ++x) {
                    const float* v = at(r, x, y);
                    const double depth = floor_distance(x + 0.5, y + 0.5);
                    const std::string where =
                        integrator + " " + std::to_string(x) + "," + std::to_string(y);
                    if (depth == 0) {
                        ++sky;
                        for (int c = 0; c < 7; ++c) EXPECT_EQ(v[c], 0.0f) << where;
                        continue;
                    }
                    ++floor;
                    EXPECT_EQ(v[0], 0.4f) << where;  // diffuse · kd
                    EXPECT_EQ(v[1], 0.2f) << where;
                    EXPECT_EQ(v[2], 0.1f) << where;
                    EXPECT_EQ(v[3], 0.0f) << where;  // up, towards the camera, either way
                    EXPECT_EQ(v[4], 1.0f) << where;
                    EXPECT_EQ(v[5], 0.0f) << where;
                    EXPECT_NEAR(v[6], depth, 1e-5 * depth) << where;
                }
            }
            EXPECT_GT(floor, 100);
            EXPECT_GT(sky, 50);
        }
    }
}

// Many samples: a pixel below the horizon has the same albedo and normal in every sample and a
// depth between its corners'; a pixel the horizon crosses averages hits and escapes, so its
// albedo and normal are the floor's times the share of its samples that hit.
TEST(Aov, ValuesAreTheMeanOverThePixelsCameraSamples) {
    const RenderResult r = render_aovs(floor_scene("distributed", 16));
    int crossed = 0;
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 24; ++x) {
            const float* v = at(r, x, y);
            const double corners[] = {floor_distance(x, y), floor_distance(x + 1, y),
                                      floor_distance(x, y + 1), floor_distance(x + 1, y + 1)};
            const bool below =
                std::all_of(std::begin(corners), std::end(corners), [](double d) { return d > 0; });
            const bool above = std::all_of(std::begin(corners), std::end(corners),
                                           [](double d) { return d == 0; });
            if (below) {
                EXPECT_NEAR(v[0], 0.4, 1e-6);
                EXPECT_NEAR(v[4], 1.0, 1e-6);
                EXPECT_GE(v[6], *std::min_element(std::begin(corners), std::end(corners)) - 1e-6);
                EXPECT_LE(v[6], *std::max_element(std::begin(corners), std::end(corners)) + 1e-6);
            } else if (above) {
                EXPECT_EQ(v[0], 0.0f);
            } else {
                ++crossed;
                const double share = v[4];  // of the 16 samples that hit
                EXPECT_GT(share, 0.0);
                EXPECT_LT(share, 1.0);
                EXPECT_NEAR(share * 16, std::round(share * 16), 1e-4);
                EXPECT_NEAR(v[0], 0.4 * share, 1e-6);
                EXPECT_NEAR(v[2], 0.1 * share, 1e-6);
            }
        }
    }
    EXPECT_GT(crossed, 0);
}

TEST(Aov, AskingForThemLeavesTheImageBitsAndTheyDoNotDependOnThreads) {
    for (const std::string integrator : {"distributed", "path"}) {
        const Scene scene = floor_scene(integrator, 4);
        const RenderResult one = render_aovs(scene, 1);
        const RenderResult three = render_aovs(scene, 3);
        EXPECT_EQ(one.aovs, three.aovs) << integrator;
        RenderOptions options;
        options.threads = 2;
        const RenderResult plain = render(scene, options);
        EXPECT_EQ(plain.image.rgb, one.image.rgb) << integrator;
        EXPECT_TRUE(plain.aovs.empty());
    }
}

}  // namespace
}  // namespace drt
