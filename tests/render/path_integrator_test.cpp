// The path integrator against closed forms, the distributed integrator's emitters and physical
// lights against the same closed forms, and the estimators of emitted light against each other.
#include "drt/render/path_integrator.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "drt/accel/mesh.h"
#include "drt/render/integrator.h"
#include "drt/render/renderer.h"
#include "drt/scene/scene_loader.h"
#include "test_math.h"
#include "test_meshes.h"
#include "test_render.h"
#include "test_scenes.h"

namespace drt {
namespace {

using testing::expect_relative;
using testing::from_xml;
using testing::image_mean;
using testing::render_with;

// A camera inside a closed sphere of emission Le, diffuse 1, kd rho: every path sees Le at each
// of its up to MaxDepth + 1 surface points, weighed by rho per scattering event.
std::string furnace(double le, double rho, int max_depth, const std::string& sampler = "random") {
    const std::string e = std::to_string(le), r = std::to_string(rho);
    return R"(<Scene><Image Width="8" Height="8"/>
      <Render Integrator="path" Samples="256" MaxDepth=")" +
           std::to_string(max_depth) + R"(" Sampler=")" + sampler + R"("/>
      <Camera Ex="0" Ey="0" Ez="0" Lx="0" Ly="0" Lz="1" Fov="90"/>
      <Materials><Wall diffuse="1" kdr=")" +
           r + "\" kdg=\"" + r + "\" kdb=\"" + r + "\" ker=\"" + e + "\" keg=\"" + e + "\" keb=\"" +
           e + R"("/></Materials>
      <Sphere Px="1" Py="2" Pz="3" Radius="10" Material="Wall"/></Scene>)";
}

double geometric_sum(double rho, int terms) {
    double sum = 0, power = 1;
    for (int k = 0; k < terms; ++k, power *= rho) sum += power;
    return sum;
}

// The furnace's mean over 64 pixels of 256 paths each is within about 0.3 % of the closed form
// (measured spread), so a 2 % change of the emission, of the Russian-roulette compensation
// (which deep paths compound) or of a scattering weight fails here.
TEST(PathIntegrator, FurnaceConvergesToTheGeometricSeries) {
    struct Case {
        double le, rho;
        int max_depth;
    };
    for (const Case c : {Case{1.0, 0.5, 0}, Case{1.0, 0.5, 1}, Case{0.7, 0.5, 3},
                         Case{1.0, 0.9, 64}, Case{2.0, 0.8, 12}}) {
        const RenderResult r = render_with(from_xml(furnace(c.le, c.rho, c.max_depth)));
        const double expected = c.le * geometric_sum(c.rho, c.max_depth + 1);
        const Color mean = image_mean(r.image);
        EXPECT_NEAR(mean.r, expected, 0.01 * expected) << c.rho << " " << c.max_depth;
        EXPECT_NEAR(mean.g, expected, 0.01 * expected);
        EXPECT_NEAR(mean.b, expected, 0.01 * expected);
        EXPECT_EQ(r.stats.rays.diffuse > 0, c.max_depth > 0);
    }
}

// Every sampler gives each scattering event dimensions of its own: a pattern shared between
// bounces would correlate them and bias the sum.
TEST(PathIntegrator, FurnaceConvergesWithEverySampler) {
    for (const std::string sampler : {"stratified", "sobol"}) {
        const Color mean = image_mean(render_with(from_xml(furnace(1.0, 0.8, 16, sampler))).image);
        const double expected = geometric_sum(0.8, 17);
        EXPECT_NEAR(mean.r, expected, 0.01 * expected) << sampler;
    }
}

// An emitting plane has no area to sample: the path integrator finds its light by scattered
// rays, the distributed one by rays in cosine-weighted directions, and every one of either meets
// it here, so a floor under it shows exactly diffuse·kd·Le in both.
TEST(Emitters, EmittingPlaneLightsAFloorByCosineRaysInBothIntegrators) {
    for (const std::string integrator : {"distributed", "path"}) {
        const Scene scene = from_xml(R"(<Scene><Image Width="4" Height="4"/>
          <Render Integrator=")" + integrator +
                                     R"(" Samples="16" MaxDepth="1"/>
          <Camera Ex="0" Ey="5" Ez="0" Lx="0" Ly="0" Lz="0" Uz="1" Fov="30"/>
          <Materials><Floor diffuse="0.5" kdr="1" kdg="0.5" kdb="0.25"/>
            <Sky ker="2" keg="2" keb="2"/></Materials>
          <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
          <Plane Px="0" Py="10" Pz="0" Vu="0" Vv="-1" Vw="0" Material="Sky"/></Scene>)");
        const RenderResult r = render_with(scene);
        EXPECT_EQ(r.plan.emitters.size(), 0u);
        const Color floor = r.image.at(2, 2);
        EXPECT_NEAR(floor.r, 0.5 * 2 * 1, 1e-9) << integrator;
        EXPECT_NEAR(floor.g, 0.5 * 2 * 0.5, 1e-9) << integrator;
        EXPECT_NEAR(floor.b, 0.5 * 2 * 0.25, 1e-9) << integrator;
    }
}

// An emitting sphere under an emitting sky plane, over a floor point: the sphere covers (r/h)²
// of the point's cosine-weighted sky, and shows its own radiance there. The distributed
// integrator samples the sphere by its cone and the plane by cosine rays, which count only the
// plane: a ray that meets the sphere adds nothing, or the sphere would count twice.
TEST(Emitters, AnEmittingPlaneBehindAnEmittingSphereCountsEachOnce) {
    for (const std::string integrator : {"distributed", "path"}) {
        const Scene scene = from_xml(R"(<Scene><Image Width="1" Height="1"/>
          <Render Integrator=")" + integrator +
                                     R"(" Samples="16384" MaxDepth="1"/>
          <Camera Ex="30" Ey="4" Ez="0" Lx="0" Ly="0" Lz="0" Fov="0.001"/>
          <Materials><Floor diffuse="0.9" kdr="0.5" kdg="0.25" kdb="1"/>
            <Glow ker="2" keg="3" keb="4"/><Sky ker="1" keg="1" keb="1"/></Materials>
          <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
          <Plane Px="0" Py="20" Pz="0" Vu="0" Vv="-1" Vw="0" Material="Sky"/>
          <Sphere Px="0" Py="10" Pz="0" Radius="5" Material="Glow"/></Scene>)");
        const Color floor = render_with(scene).image.at(0, 0);
        const Color expected =
            0.9 * Color{0.5, 0.25, 1} * (0.75 * Color{1, 1, 1} + 0.25 * Color{2, 3, 4});
        // The cosine rays' share that meets the sky scatters by 0.3 % over 16384 samples.
        testing::expect_relative(floor, expected, 0.015, integrator);
    }
}

TEST(PathIntegrator, WhiteDiffuseSphereInUniformBackgroundShowsTheBackground) {
    for (const double kd : {1.0, 0.5}) {
        Material m = testing::grey_lambert(kd);
        const Color sky{1.0, 0.5, 0.25};
        Scene scene = testing::lone_sphere_scene(m, sky, 16);
        scene.settings.integrator = IntegratorKind::kPath;
        scene.settings.samples = 4;
        const RenderResult r = render_with(scene);
        // A convex sphere: every scattered ray escapes, so each sample is exact.
        const Color centre = r.image.at(8, 8);
        EXPECT_NEAR(centre.r, kd * sky.r, 1e-6);
        EXPECT_NEAR(centre.g, kd * sky.g, 1e-6);
        EXPECT_NEAR(centre.b, kd * sky.b, 1e-6);
        EXPECT_NEAR(r.image.at(0, 0).r, sky.r, 1e-12);  // the background itself
    }
}

// A floor (diffuse d, kd k) under an emitting sphere of radius r whose centre is h above the
// floor point seen: that point shows d·k·Le·(r/h)² (irradiance π·Le·(r/h)², Lambert's 1/π).
std::string floor_under_sphere(const std::string& integrator, const std::string& sampler,
                               int samples, int shadow_rays) {
    return R"(<Scene><Image Width="1" Height="1"/>
      <Render Integrator=")" +
           integrator + R"(" Samples=")" + std::to_string(samples) + R"(" ShadowRays=")" +
           std::to_string(shadow_rays) + R"(" Sampler=")" + sampler + R"("/>
      <Camera Ex="30" Ey="4" Ez="0" Lx="0" Ly="0" Lz="0" Fov="0.001"/>
      <Materials>
        <Floor diffuse="0.9" kdr="0.5" kdg="0.25" kdb="1"/>
        <Glow ker="2" keg="3" keb="4"/>
      </Materials>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
      <Sphere Px="0" Py="10" Pz="0" Radius="5" Material="Glow"/></Scene>)";
}

Color floor_under_sphere_expected() {
    const double factor = 0.9 * 0.25;  // diffuse · (r/h)²
    return {factor * 0.5 * 2, factor * 0.25 * 3, factor * 1 * 4};
}

TEST(Emitters, EmittingSphereLightsAFloorAsTheClosedFormInBothIntegrators) {
    const Color expected = floor_under_sphere_expected();
    expect_relative(render_with(from_xml(floor_under_sphere("distributed", "stratified", 64, 64)))
                        .image.at(0, 0),
                    expected, 0.002, "distributed");
    expect_relative(
        render_with(from_xml(floor_under_sphere("path", "stratified", 4096, 4))).image.at(0, 0),
        expected, 0.005, "path");
}

// A closed box of 12 emitting triangles (emission Le, diffuse 1, kd rho) around the camera: the
// furnace again, now sampled by area over triangles. The loader makes the twelve one emitter
// (scene_loader.cpp groups <Triangle>s by material): ShadowRays 12 all sample it, as does 1.
std::string emitting_box(const std::string& integrator, int shadow_rays, int max_depth,
                         int samples = 256) {
    std::string triangles;
    // Corner i of the cube has coordinate `bit` at +5 where that bit of i is set.
    const auto coordinate = [](int corner, int bit) { return (corner >> bit & 1) ? "5" : "-5"; };
    const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
        for (const auto& t : {std::array<int, 3>{f[0], f[1], f[2]}, {f[0], f[2], f[3]}}) {
            triangles += "<Triangle";
            for (int k = 0; k < 3; ++k) {
                for (int bit = 0; bit < 3; ++bit) {
                    triangles += std::string(" ") + char('A' + k) + "xyz"[bit] + "=\"" +
                                 coordinate(t[k], bit) + "\"";
                }
            }
            triangles += " Material=\"Wall\"/>\n";
        }
    }
    return R"(<Scene><Image Width="8" Height="8"/>
      <Render Integrator=")" +
           integrator + R"(" Samples=")" + std::to_string(samples) + R"(" ShadowRays=")" +
           std::to_string(shadow_rays) + R"(" MaxDepth=")" + std::to_string(max_depth) +
           R"(" Sampler="random"/>
      <Camera Ex="0.3" Ey="0.2" Ez="0.1" Lx="1" Ly="0.5" Lz="3" Fov="90"/>
      <Materials><Wall diffuse="1" kdr="0.5" kdg="0.5" kdb="0.5" ker="2" keg="2" keb="2"/>
      </Materials>)" +
           triangles + "</Scene>";
}

TEST(Emitters, EmittingTrianglesLightTheInsideOfAClosedBoxInBothIntegrators) {
    for (const int shadow_rays : {12, 1}) {
        // Distributed: the emission seen plus its direct light, Le·(1 + rho). The box's twelve
        // triangles are one emitter: with one shadow ray, area sampling's long tail (points near
        // an edge) needs more samples than the path integrator's bounces for 1 %.
        const Color direct = image_mean(
            render_with(from_xml(emitting_box("distributed", shadow_rays, 8, 1024))).image);
        EXPECT_NEAR(direct.r, 2 * 1.5, 0.01 * 3) << shadow_rays;
        // Path: every bounce, Le·(1 + rho + ... + rho^MaxDepth).
        const Color path =
            image_mean(render_with(from_xml(emitting_box("path", shadow_rays, 8))).image);
        const double expected = 2 * geometric_sum(0.5, 9);
        EXPECT_NEAR(path.r, expected, 0.01 * expected) << shadow_rays;
    }
}

// The furnace inside one emitting mesh of 320 triangles of unequal area: next-event estimation
// picks its triangles by area.
TEST(Emitters, EmittingMeshFurnaceInBothIntegrators) {
    for (const IntegratorKind kind : {IntegratorKind::kDistributed, IntegratorKind::kPath}) {
        Scene scene = testing::blank_scene(8, 8, 256);
        scene.settings.integrator = kind;
        scene.settings.sampler = "random";
        scene.settings.max_depth = 6;
        scene.view = LookAt{{0.5, 0.25, 0}, {1, 1, 3}, {0, 1, 0}, 90};
        Material wall = testing::grey_lambert(0.5);
        wall.emission = {2, 2, 2};
        const Material& m = testing::add_material(scene, wall);
        auto mesh = std::make_shared<const TriangleMesh>(testing::obj_of(testing::icosphere(2, 10)),
                                                         MeshTransform{}, false);
        scene.objects.push_back(std::make_unique<Mesh>(mesh, std::vector<Vec3>{Vec3{}}, m));
        const RenderPlan plan = plan_render(scene);
        ASSERT_EQ(plan.emitters.size(), 1u);
        ASSERT_EQ(plan.emitters[0].mesh->triangle_count(), 320u);
        const double expected = 2 * (kind == IntegratorKind::kPath ? geometric_sum(0.5, 7) : 1.5);
        EXPECT_NEAR(image_mean(render_with(scene).image).g, expected, 0.01 * expected);
    }
}

TEST(Emitters, EmittingSphereIsSeenByCameraRaysInBothIntegrators) {
    for (const std::string integrator : {"distributed", "path"}) {
        const Scene scene = from_xml(R"(<Scene><Image Width="3" Height="3"/>
          <Render Integrator=")" + integrator +
                                     R"(" Samples="1"/>
          <Camera Ex="0" Ey="0" Ez="-10" Lx="0" Ly="0" Lz="0" Fov="5"/>
          <Materials><Glow ker="2" keg="3" keb="4"/></Materials>
          <Sphere Px="0" Py="0" Pz="0" Radius="2" Material="Glow"/></Scene>)");
        const Color centre = render_with(scene).image.at(1, 1);
        EXPECT_EQ(centre, (Color{2, 3, 4})) << integrator;
    }
}

// Falloff 1: a point light adds I·cos/r² to the thesis's sum, so a floor point shows
// diffuse·kd·I·cosθ/r²; a sphere light of radius R is an emitter of radiance I/R², which seen
// from straight below gives exactly the same (its irradiance is π·(I/R²)·(R/h)²).
TEST(PhysicalLights, FalloffOneFollowsTheInverseSquareLawInBothIntegrators) {
    for (const std::string integrator : {"distributed", "path"}) {
        for (const std::string radius : {"0", "2"}) {
            const Scene scene = from_xml(R"(<Scene><Image Width="1" Height="1"/>
              <Render Integrator=")" + integrator +
                                         R"(" Samples=")" + (radius == "0" ? "1" : "256") +
                                         R"(" ShadowRays="16"/>
              <Camera Ex="30" Ey="4" Ez="0" Lx="3" Ly="0" Lz="0" Fov="0.001"/>
              <Materials><Floor diffuse="0.5" kdr="0.8" kdg="0.8" kdb="0.8"/></Materials>
              <Light Px="0" Py="20" Pz="0" Radius=")" +
                                         radius +
                                         R"(" Falloff="1" Ir="400" Ig="200" Ib="100"/>
              <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/></Scene>)");
            const Color got = render_with(scene).image.at(0, 0);
            // The floor point (3, 0, 0): r² = 409, cos θ = 20/√409. A uniform sphere wholly above
            // a surface's horizon lights it exactly as a point at its centre would.
            const double r2 = 409, cosine = 20 / std::sqrt(r2);
            const Color expected = Color{400, 200, 100} * (0.5 * 0.8 * cosine / r2);
            expect_relative(got, expected, radius == "0" ? 1e-9 : 0.01,
                            integrator + " radius " + radius);
        }
    }
}

TEST(PhysicalLights, FalloffOneSphereLightStraightAboveMatchesThePointLightExactly) {
    const Scene scene = from_xml(R"(<Scene><Image Width="1" Height="1"/>
      <Render Samples="64" ShadowRays="64"/>
      <Camera Ex="30" Ey="4" Ez="0" Lx="0" Ly="0" Lz="0" Fov="0.001"/>
      <Materials><Floor diffuse="1" kdr="1" kdg="1" kdb="1"/></Materials>
      <Light Px="0" Py="20" Pz="0" Radius="8" Falloff="1" Ir="400" Ig="400" Ib="400"/>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/></Scene>)");
    EXPECT_NEAR(render_with(scene).image.at(0, 0).r, 400.0 / 400.0, 0.002);
}

// The mean over n paths of the floor point under the emitting sphere, by one strategy, and its
// standard error.
struct Estimate {
    Color mean;
    double standard_error;  // of the mean's luminance
};
Estimate estimate(PathIntegrator::Strategy strategy, int n,
                  const std::string& xml = floor_under_sphere("path", "random", 1, 1)) {
    const Scene scene = from_xml(xml);
    const RenderPlan plan = plan_render(scene);
    const Bvh bvh(scene.objects);
    const auto sampler = make_sampler("random");
    const PathIntegrator integrator(scene, plan, bvh, *sampler, strategy);
    const Ray ray = scene.camera().generate_ray({0.5, 0.5}, {0.5, 0.5}, 0);
    RayCounts counts;
    Color sum;
    double sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const PixelSample s{7, 0, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(n)};
        const Color c = integrator.radiance(ray, s, counts);
        sum += c;
        sum2 += luminance(c) * luminance(c);
    }
    const Color mean = sum / n;
    const double variance = sum2 / n - luminance(mean) * luminance(mean);
    return {mean, std::sqrt(variance / n)};
}

// Light from an emitter found by shadow rays alone, by scattered rays alone and by both weighed
// with the power heuristic has one mean, the closed form. The sphere fills a quarter of the
// floor point's sky, where both strategies matter: a 2 % change of either MIS weight moves the
// weighed estimate by about 1 %, five of its standard errors.
TEST(PathIntegrator, ShadowRaysScatteredRaysAndTheirWeighingAgree) {
    const Color expected = floor_under_sphere_expected();
    const int n = 400000;
    for (const auto strategy :
         {PathIntegrator::Strategy::kMis, PathIntegrator::Strategy::kLightOnly,
          PathIntegrator::Strategy::kScatterOnly}) {
        const Estimate e = estimate(strategy, n);
        const double relative_error = e.standard_error / luminance(expected);
        EXPECT_LT(relative_error, 0.004);
        expect_relative(e.mean, expected, 5 * relative_error,
                        "strategy " + std::to_string(static_cast<int>(strategy)));
    }
}

// The floor point under a tilted emitting triangle that fills much of its sky, sampled by the
// solid angle it subtends: its irradiance is Lambert's closed form for a polygon.
const std::array<Vec3, 3> kTilted = {Vec3{-3, 1, -2}, Vec3{3, 1.5, -1}, Vec3{0, 2, 3}};

std::string floor_under_triangle() {
    std::string corners;
    for (int k = 0; k < 3; ++k) {
        const Vec3& p = kTilted[k];
        const std::string name(1, char('A' + k));
        corners += " " + name + "x=\"" + std::to_string(p.x) + "\" " + name + "y=\"" +
                   std::to_string(p.y) + "\" " + name + "z=\"" + std::to_string(p.z) + "\"";
    }
    return R"(<Scene><Image Width="1" Height="1"/>
      <Render Integrator="path" Samples="1" ShadowRays="1" Sampler="random"/>
      <Camera Ex="30" Ey="4" Ez="0" Lx="0" Ly="0" Lz="0" Fov="0.001"/>
      <Materials>
        <Floor diffuse="0.9" kdr="0.5" kdg="0.25" kdb="1"/>
        <Glow ker="2" keg="3" keb="4"/>
      </Materials>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
      <Triangle)" +
           corners + R"( Material="Glow"/></Scene>)";
}

// The same agreement for an emitting triangle: the light sample's density (the pick over the
// triangle's solid angle) and the one a scattered ray is weighed with must be the same, or the
// weighed estimate leaves the closed form.
TEST(PathIntegrator, ShadowRaysScatteredRaysAndTheirWeighingAgreeForATriangle) {
    const double irradiance =
        testing::triangle_irradiance({0, 0, 0}, {0, 1, 0}, kTilted[0], kTilted[1], kTilted[2]);
    const Color expected = Color{0.5 * 2, 0.25 * 3, 1 * 4} * (0.9 * irradiance / kPi);
    const int n = 200000;
    for (const auto strategy :
         {PathIntegrator::Strategy::kMis, PathIntegrator::Strategy::kLightOnly,
          PathIntegrator::Strategy::kScatterOnly}) {
        const Estimate e = estimate(strategy, n, floor_under_triangle());
        const double relative_error = e.standard_error / luminance(expected);
        EXPECT_LT(relative_error, 0.004);
        expect_relative(e.mean, expected, 5 * relative_error,
                        "strategy " + std::to_string(static_cast<int>(strategy)));
    }
}

// Veach's plates (scenes/gi/glossy-mis.xml: four glossy plates with a dim diffuse part under four
// emitting spheres of equal power, radius 0.05 to 1.35) rendered small by each strategy with the
// same random numbers: the paths are then the same and only the weights of the emitted light
// found at diffuse events differ. Shadow rays alone agree with the weighed estimate to 1e-6 of
// each band's mean (for a diffuse part the light sample's weight is nearly 1 here). The
// scattered ray alone finds the two small spheres with probability about 1e-6 per diffuse event,
// far too rarely for a test, so that comparison darkens them: measured over 8 seeds, every band
// within 1 % of the weighed estimate (without the darkening it misses their light, 1 to 2 % of
// a band, in most seeds).
TEST(PathIntegrator, StrategiesAgreeOnVeachsPlates) {
    using Strategy = PathIntegrator::Strategy;
    for (const bool dark_small_spheres : {false, true}) {
        Scene scene = testing::scaled_scene("gi/glossy-mis.xml", 32, 1);
        for (auto& m : scene.materials) {
            if (dark_small_spheres && m->emission.r > 50) m->emission = {};
        }
        const RenderPlan plan = plan_render(scene);
        const Bvh bvh(scene.objects);
        const auto sampler = make_sampler("random");
        const PathIntegrator mis(scene, plan, bvh, *sampler, Strategy::kMis);
        const PathIntegrator other(
            scene, plan, bvh, *sampler,
            dark_small_spheres ? Strategy::kScatterOnly : Strategy::kLightOnly);
        const int width = scene.settings.width, height = scene.settings.height, n = 192;
        constexpr int kBands = 4;  // rows of the image: the spheres, then about a plate each
        std::array<double, kBands> weighed{}, alone{};
        std::vector<Color> a(n), b(n);
        for (int y = 0; y < height; ++y) {
            const auto band = static_cast<std::size_t>(y * kBands / height);
            for (int x = 0; x < width; ++x) {
                const PixelSample s{3, static_cast<std::uint32_t>(y * width + x), 0,
                                    static_cast<std::uint32_t>(n)};
                RayCounts counts;
                mis.sample_pixel(x, y, s, a, counts);
                other.sample_pixel(x, y, s, b, counts);
                for (int i = 0; i < n; ++i) {
                    ASSERT_TRUE(std::isfinite(luminance(a[i])) && std::isfinite(luminance(b[i])));
                    weighed[band] += luminance(a[i]);
                    alone[band] += luminance(b[i]);
                }
            }
        }
        const double tolerance = dark_small_spheres ? 0.02 : 1e-4;
        for (std::size_t k = 1; k < kBands; ++k) {
            EXPECT_GT(weighed[k], 0);
            EXPECT_NEAR(alone[k], weighed[k], tolerance * weighed[k])
                << "band " << k << (dark_small_spheres ? ": scattered rays" : ": shadow rays")
                << " alone against both weighed";
        }
    }
}

// Light reaching the eye by glossy reflections of an emitter alone: the distributed integrator
// follows the same lobes, so both integrators have one mean (nothing found twice).
TEST(PathIntegrator, GlossyOnlySceneHasTheDistributedIntegratorsMean) {
    const auto scene = [](const std::string& integrator) {
        return from_xml(R"(<Scene><Image Width="16" Height="16"/>
          <Render Integrator=")" +
                        integrator + R"(" Samples="1024" MaxDepth="3" Sampler="random"/>
          <Camera Ex="0" Ey="6" Ez="-12" Lx="0" Ly="0" Lz="0" Fov="50"/>
          <Materials><Metal reflective="0.9" ksr="1" ksg="0.8" ksb="0.6" n="4"/>
            <Glow ker="3" keg="2" keb="1"/></Materials>
          <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Metal"/>
          <Sphere Px="0" Py="3" Pz="4" Radius="2" Material="Glow"/></Scene>)");
    };
    const Color distributed = image_mean(render_with(scene("distributed")).image);
    const Color path = image_mean(render_with(scene("path")).image);
    expect_relative(path, distributed, 0.01, "glossy");
}

// Hard cases: none may give a NaN or an infinite pixel, and where a closed form exists the image
// must still show it.
int non_finite(const Image& image) {
    int count = 0;
    for (const float v : image.rgb) count += std::isfinite(v) ? 0 : 1;
    return count;
}

std::string with_objects(std::string scene, const std::string& materials,
                         const std::string& objects) {
    scene.insert(scene.find("</Materials>"), materials);
    scene.insert(scene.rfind("</Scene>"), objects);
    return scene;
}

// Glass inside the emitting box: a lossless glass sphere (clear, and blurry with n 3) neither
// makes nor takes light, so the furnace's value stays Le/(1 - rho) (MaxDepth 64 cuts 2^-65 of
// it). Paths that enter the glass at grazing angles and bounce inside it are the risk.
TEST(PathIntegratorHardCases, GlassInsideAnEmittingBoxKeepsTheFurnacesValue) {
    for (const std::string n : {"1000", "3"}) {
        const Scene scene = from_xml(with_objects(
            emitting_box("path", 1, 64),
            R"(<Glass diffuse="0" transmitt="1" ktr="1" ktg="1" ktb="1" index="1.5" n=")" + n +
                R"("/>)",
            R"(<Sphere Px="1" Py="0.5" Pz="3" Radius="1.5" Material="Glass"/>
               <Sphere Px="-2" Py="-1" Pz="2" Radius="0.7" Material="Glass"/>)"));
        const RenderResult r = render_with(scene);
        EXPECT_EQ(non_finite(r.image), 0) << n;
        EXPECT_NEAR(image_mean(r.image).g, 4.0, 0.02 * 4.0) << n;
    }
}

// A camera skimming a broad glossy floor (n 1: lobes that reach below the surface and are
// redrawn) and a glossy sphere seen at its rim, under an emitter and a sky.
TEST(PathIntegratorHardCases, GrazingGlossyLobesStayFinite) {
    const Scene scene = from_xml(R"(<Scene><Image Width="16" Height="16"/>
      <Render Integrator="path" Samples="64" MaxDepth="16" Sampler="random"/>
      <Background r="0.3" g="0.4" b="0.5"/>
      <Camera Ex="0" Ey="0.001" Ez="-20" Lx="0" Ly="0" Lz="0" Fov="30"/>
      <Materials><Floor diffuse="0.2" kdr="1" kdg="1" kdb="1" reflective="0.8" ksr="1" ksg="1" ksb="1" n="1"/>
        <Metal reflective="1" ksr="1" ksg="1" ksb="1" n="2"/><Glow ker="50" keg="50" keb="50"/></Materials>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
      <Sphere Px="0" Py="1" Pz="0" Radius="1" Material="Metal"/>
      <Sphere Px="3" Py="0.3" Pz="2" Radius="0.3" Material="Glow"/></Scene>)");
    const RenderResult r = render_with(scene);
    EXPECT_EQ(non_finite(r.image), 0);
    EXPECT_GT(image_mean(r.image).r, 0);
}

// Emitters of radiance 1e6, a sphere and a triangle, small and bright enough to be fireflies: the
// floor's closed form kd·Le·(r/h)² still holds, and nothing overflows.
TEST(PathIntegratorHardCases, EmittersOfAMillionStayFiniteAndExact) {
    const Scene scene = from_xml(R"(<Scene><Image Width="1" Height="1"/>
      <Render Integrator="path" Samples="1024" ShadowRays="4" MaxDepth="6" Sampler="stratified"/>
      <Camera Ex="30" Ey="4" Ez="0" Lx="0" Ly="0" Lz="0" Fov="0.001"/>
      <Materials><Floor diffuse="1" kdr="0.5" kdg="0.5" kdb="0.5"/>
        <Glow ker="1e6" keg="1e6" keb="1e6"/></Materials>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
      <Sphere Px="0" Py="10" Pz="0" Radius="0.01" Material="Glow"/></Scene>)");
    const RenderResult r = render_with(scene);
    EXPECT_EQ(non_finite(r.image), 0);
    // Irradiance π·Le·(r/h)², one bounce off an infinite floor and nothing to return it.
    EXPECT_NEAR(r.image.at(0, 0).r, 0.5 * 1e6 * 1e-6, 0.01 * 0.5);

    const Scene box = from_xml(with_objects(
        emitting_box("path", 1, 8), R"(<Bright ker="1e6" keg="1e6" keb="1e6"/>)",
        R"(<Triangle Ax="0" Ay="4.9" Az="0" Bx="0.01" By="4.9" Bz="0" Cx="0" Cy="4.9" Cz="0.01" Material="Bright"/>
           <Sphere Px="2" Py="-4" Pz="3" Radius="0.001" Material="Bright"/>)"));
    EXPECT_EQ(non_finite(render_with(box).image), 0);
}

// MaxDepth 512 (the limit): in a furnace of albedo 1 roulette never ends a path, so every path
// has 513 surface points, each adding Le.
TEST(PathIntegratorHardCases, MaxDepthFiveHundredTwelveInALosslessFurnace) {
    Scene scene = from_xml(furnace(1.0, 1.0, 512));
    scene.settings.samples = 16;
    const RenderResult r = render_with(scene);
    EXPECT_EQ(non_finite(r.image), 0);
    EXPECT_NEAR(image_mean(r.image).r, 513.0, 0.01 * 513);
}

// The opt-in clamp: no camera sample's luminance exceeds it, so no pixel's does; the colour of a
// clamped sample is kept; a clamp no sample reaches changes no bit.
TEST(PathIntegrator, ClampBoundsEverySampleAndChangesNothingItDoesNotReach) {
    const std::string xml =
        with_objects(furnace(1.0, 0.5, 8), R"(<Hot ker="400000" keg="200000" keb="100000"/>)",
                     R"(<Sphere Px="2" Py="3" Pz="6" Radius="0.05" Material="Hot"/>)");
    const RenderResult plain = render_with(from_xml(xml));
    float brightest = 0;
    for (int y = 0; y < plain.image.height; ++y) {
        for (int x = 0; x < plain.image.width; ++x) {
            brightest = std::max(brightest, static_cast<float>(luminance(plain.image.at(x, y))));
        }
    }
    ASSERT_GT(brightest, 3.0);  // the hot sphere's fireflies
    const auto with_clamp = [&](const std::string& clamp) {
        std::string clamped = xml;
        clamped.insert(clamped.find("Integrator="), "Clamp=\"" + clamp + "\" ");
        return render_with(from_xml(clamped));
    };
    const RenderResult clamped = with_clamp("3");
    for (int y = 0; y < clamped.image.height; ++y) {
        for (int x = 0; x < clamped.image.width; ++x) {
            EXPECT_LE(luminance(clamped.image.at(x, y)), 3 + 1e-5);
        }
    }
    // Biased: light is lost, never gained.
    EXPECT_LT(luminance(image_mean(clamped.image)), luminance(image_mean(plain.image)));
    EXPECT_EQ(with_clamp("1e30").image.rgb, plain.image.rgb);
}

TEST(PathIntegrator, ImageIsTheSameOnAnyNumberOfThreads) {
    for (const std::string sampler : {"stratified", "sobol"}) {
        Scene scene = testing::scaled_scene("gi/cornell-box.xml", 24, 4);
        scene.settings.sampler = sampler;
        const RenderResult one = render_with(scene, 1);
        const RenderResult two = render_with(scene, 2);
        EXPECT_EQ(one.image.rgb, two.image.rgb) << sampler;
        EXPECT_EQ(one.stats.rays.diffuse, two.stats.rays.diffuse);
        EXPECT_GT(one.stats.rays.diffuse, 0u);
        EXPECT_TRUE(one.plan.effects.indirect_light);
    }
}

TEST(PathIntegrator, DistributedIntegratorTracesNoDiffuseRays) {
    Scene scene = testing::scaled_scene("gi/cornell-box.xml", 16, 2);
    scene.settings.integrator = IntegratorKind::kDistributed;
    const RenderResult r = render_with(scene);
    EXPECT_EQ(r.stats.rays.diffuse, 0u);
    EXPECT_GT(r.stats.rays.shadow, 0u);  // the lamp lights the box directly
    EXPECT_FALSE(r.plan.effects.indirect_light);
}

// A thesis light (Falloff 0) gives the same direct light in both integrators.
TEST(PathIntegrator, ThesisLightGivesTheDistributedIntegratorsDirectLight) {
    Scene scene = testing::floor_scene(6, 4);
    scene.lights.push_back(std::make_unique<PointLight>(Vec3{7, 30, -3}, Color{1, 0.5, 0.25}));
    const RenderResult distributed = render_with(scene);
    scene.settings.integrator = IntegratorKind::kPath;
    const RenderResult path = render_with(scene);
    for (std::size_t i = 0; i < path.image.rgb.size(); ++i) {
        EXPECT_NEAR(path.image.rgb[i], distributed.image.rgb[i], 1e-6) << i;
    }
}

// Camera rays filter image textures over their footprint in both integrators: the far tiles of
// a floor seen at a grazing angle (hundreds of tiles a pixel) look the same in both, where a
// path integrator reading the finest level would show them speckled.
TEST(PathIntegrator, CameraRaysFilterImageTexturesAsTheDistributedIntegratorsDo) {
    Scene scene = testing::scaled_scene("assets/tiled-floor.xml", 48, 4);
    scene.ambient = {};
    scene.background = {};  // a point light's direct light alone, the same in both
    const RenderResult distributed = render_with(scene);
    scene.settings.integrator = IntegratorKind::kPath;
    const RenderResult path = render_with(scene);
    for (std::size_t i = 0; i < path.image.rgb.size(); ++i) {
        EXPECT_NEAR(path.image.rgb[i], distributed.image.rgb[i], 1e-6) << i;
    }
}

}  // namespace
}  // namespace drt
