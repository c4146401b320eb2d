// Caustics from photon maps against an independent model: a glass ball under a distant light
// focuses it on a floor; the model traces parallel rays through the ball in its meridional
// plane with Snell's law and the Fresnel equations written out here, and bins where they land.
#include "drt/render/photon_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "drt/render/integrator.h"
#include "drt/render/path_integrator.h"
#include "drt/render/renderer.h"
#include "drt/scene/scene_loader.h"
#include "test_render.h"

namespace drt {
namespace {

using testing::from_xml;

// --- the model ---

// Unpolarised Fresnel reflectance from a medium of index n1 into one of n2.
double fresnel(double cos_i, double n1, double n2) {
    const double sin_t = n1 / n2 * std::sqrt(std::max(0.0, 1 - cos_i * cos_i));
    if (sin_t >= 1) return 1;
    const double cos_t = std::sqrt(1 - sin_t * sin_t);
    const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    const double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    return (rs * rs + rp * rp) / 2;
}

struct V2 {
    double x, y;
};
V2 operator+(V2 a, V2 b) {
    return {a.x + b.x, a.y + b.y};
}
V2 operator-(V2 a, V2 b) {
    return {a.x - b.x, a.y - b.y};
}
V2 operator*(V2 a, double s) {
    return {a.x * s, a.y * s};
}
double dot2(V2 a, V2 b) {
    return a.x * b.x + a.y * b.y;
}

// Refracts unit d at unit normal n (facing d) from index n1 into n2.
V2 refract2(V2 d, V2 n, double n1, double n2) {
    const double eta = n1 / n2, cos_i = -dot2(d, n);
    const double cos_t = std::sqrt(1 - eta * eta * (1 - cos_i * cos_i));
    return d * eta + n * (eta * cos_i - cos_t);
}

// Where light falling straight down on a ball (radius R, index n, centre at height H above the
// floor y = 0) lands on the floor: the sum of lights (irradiance over π) of 1 far away, in
// radial bins of width `bin`, each bin's mean. Also the share of the intercepted light that
// reaches the floor, through it or off its outside (transmission).
struct Model {
    std::vector<double> bins;
    double transmission = 0;
    // Where the light reaching the floor crossed the axis, as depth below the centre, and its
    // share of the intercepted light.
    std::vector<std::pair<double, double>> crossings;
};
Model ball_model(double R, double n, double H, double bin, int bins, int max_events) {
    Model model;
    model.bins.assign(static_cast<std::size_t>(bins), 0.0);
    constexpr int kRays = 400000;
    const double db = R / kRays;
    for (int i = 0; i < kRays; ++i) {
        const double b = (i + 0.5) * db;
        const double ring = 2 * kPi * b * db;  // the light through this ring, at 1 per area
        V2 p{b, H + std::sqrt(R * R - b * b)};
        V2 normal = (p - V2{0, H}) * (1 / R);
        V2 d{0, -1};
        const auto land = [&](V2 from, V2 dir, double weight) {
            if (dir.y >= 0) return;  // up and away
            const double x = from.x + dir.x * (-from.y / dir.y);
            const double cross_y = from.y - dir.y * (from.x / dir.x);
            model.crossings.push_back({H - cross_y, weight * ring / (kPi * R * R)});
            const auto k = static_cast<std::size_t>(std::abs(x) / bin);
            if (k < model.bins.size()) model.bins[k] += weight * ring;
            model.transmission += weight * ring;
        };
        // Reflected off the outside: beyond 45° from the top, down to the floor.
        const double f0 = fresnel(-dot2(d, normal), 1, n);
        land(p, d - normal * (2 * dot2(d, normal)), f0);
        double w = 1 - f0;
        d = refract2(d, normal, 1, n);
        for (int event = 1; event < max_events && w > 1e-9; ++event) {
            // The far side of the ball along d from p.
            const V2 o = p - V2{0, H};
            const double t = -2 * dot2(o, d);
            p = p + d * t;
            const V2 inward = (V2{0, H} - p) * (1 / R);
            const double cos_i = -dot2(d, inward);
            const double f = fresnel(cos_i, n, 1);
            if (f < 1) land(p, refract2(d, inward, n, 1), w * (1 - f));
            w *= f;
            d = d - inward * (2 * dot2(d, inward));
        }
    }
    for (std::size_t k = 0; k < model.bins.size(); ++k) {
        const double r0 = k * bin, r1 = (k + 1) * bin;
        model.bins[k] /= kPi * (r1 * r1 - r0 * r0);
    }
    model.transmission /= kPi * R * R;
    return model;
}

// A glass ball (R 1, index 1.5, kt 1) with its centre H above a white floor, under a point
// light of Falloff 1 so far above that its light is parallel and gives the floor 1.
std::string ball_scene(double H, int count, double radius, int samples = 4) {
    return R"(<Scene><Image Width="8" Height="8"/>
      <Render Samples=")" +
           std::to_string(samples) + R"(" MaxDepth="8"/>
      <Photons Count=")" +
           std::to_string(count) + "\" Radius=\"" + std::to_string(radius) + R"("/>
      <Camera Ex="0" Ey="10" Ez="-10" Lx="0" Ly="0" Lz="0"/>
      <Materials><Floor diffuse="1" kdr="1" kdg="1" kdb="1"/>
        <Glass transmitt="1" ktr="1" ktg="1" ktb="1" index="1.5"/></Materials>
      <Light Px="0" Py="100000" Pz="0" Falloff="1" Ir="1e10" Ig="1e10" Ib="1e10"/>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
      <Sphere Px="0" Py=")" +
           std::to_string(H) + R"(" Pz="0" Radius="1" Material="Glass"/></Scene>)";
}

struct Maps {
    Scene scene;
    RenderPlan plan;
    Bvh bvh;
    PhotonMaps maps;
    explicit Maps(const std::string& xml)
        : scene(from_xml(xml)),
          plan(plan_render(scene)),
          bvh(scene.objects),
          maps(scene, plan, bvh) {}
};

TEST(PhotonMap, RadiusShrinksByTheProbabilisticRule) {
    // r_{k+1}² / r_k² = (k + α) / (k + 1), k counted from 1 (Knaus & Zwicker 2011, eq. 20).
    EXPECT_DOUBLE_EQ(photon_radius2_factor(0), 1.0);
    EXPECT_DOUBLE_EQ(photon_radius2_factor(1), (1 + 2.0 / 3) / 2);
    EXPECT_DOUBLE_EQ(photon_radius2_factor(2), (1 + 2.0 / 3) / 2 * (2 + 2.0 / 3) / 3);
    // Γ(k + 1 + α) / (Γ(1 + α) Γ(k + 2)), about k^(α − 1) / Γ(1 + α) for large k.
    const double k = 1000;
    const double closed =
        std::exp(std::lgamma(k + 1 + 2.0 / 3) - std::lgamma(1 + 2.0 / 3) - std::lgamma(k + 2));
    EXPECT_NEAR(photon_radius2_factor(1000), closed, 1e-12);
    Maps m(ball_scene(1.5, 100, 0.2));
    EXPECT_DOUBLE_EQ(m.maps.pass(0, 7)->radius(), 0.2 * std::sqrt(photon_radius2_factor(7)));
}

// Without a Radius the first gather radius is 1/100 of the box around the objects that make and
// catch caustics: a far Falloff-1 sphere light or emitting sphere does not widen it (it made the
// radius 10 here, and the caustic a blur). With nothing but emitters, their box it is.
TEST(PhotonMap, TheDefaultRadiusLeavesFarEmittersOut) {
    const std::string ball = R"(<Scene><Materials><Glass transmitt="1" index="1.5"/>
      <Lamp ker="1e5" keg="1e5" keb="1e5"/></Materials>
      <Sphere Px="0" Py="0" Pz="0" Radius="1" Material="Glass"/>)";
    const double ball_box = std::sqrt(12.0) / 100;  // the diagonal of a 2 x 2 x 2 box
    EXPECT_DOUBLE_EQ(
        default_photon_radius(
            from_xml(ball + R"(<Light Px="0" Py="1000" Pz="0" Radius="10" Falloff="1"/></Scene>)")),
        ball_box);
    EXPECT_DOUBLE_EQ(
        default_photon_radius(from_xml(
            ball + R"(<Sphere Px="0" Py="900" Pz="0" Radius="0.1" Material="Lamp"/></Scene>)")),
        ball_box);
    EXPECT_DOUBLE_EQ(default_photon_radius(from_xml(
                         R"(<Scene><Materials><Lamp ker="1"/></Materials>
      <Sphere Px="0" Py="0" Pz="0" Radius="50" Material="Lamp"/></Scene>)")),
                     std::sqrt(3.0) * 100 / 100);
    // Planes, unbounded, are no box: beside them the emitters' box it is (it was 1).
    EXPECT_DOUBLE_EQ(default_photon_radius(from_xml(
                         R"(<Scene><Materials><Lamp ker="1"/><Mirror reflective="1"/></Materials>
      <Sphere Px="0" Py="0" Pz="0" Radius="50" Material="Lamp"/>
      <Plane Px="0" Py="-60" Pz="0" Vu="0" Vv="1" Vw="0" Material="Mirror"/></Scene>)")),
                     std::sqrt(3.0) * 100 / 100);
}

// Transmission through the ball: the photons' power on the floor is the light the ball
// intercepts times the model's transmission, to 1 % (the noise is 0.1 %).
TEST(PhotonMap, BallPassesTheInterceptedLightTimesItsTransmission) {
    Maps m(ball_scene(3, 20000, 0.05));
    const Model model = ball_model(1, 1.5, 3, 0.1, 40, 8);
    double power = 0;
    constexpr int kPasses = 8;
    for (std::uint32_t pass = 0; pass < kPasses; ++pass) {
        for (const Photon& p : m.maps.trace(0, pass)) {
            EXPECT_NEAR(p.position[1], 0, 1e-4);
            power += p.power[0];
        }
    }
    power /= kPasses;
    const double intercepted = kPi * 1 * 1;
    EXPECT_NEAR(power / (intercepted * model.transmission), 1, 0.01);
    // Through the ball 0.84 (two Fresnel losses, more at grazing incidence), and 0.07 more
    // reflected off its outside, beyond 45° from the top, down to the floor.
    EXPECT_NEAR(model.transmission, 0.9126, 0.001);
}

// The caustic's radial profile on the floor, as the density estimate gives it at points of each
// ring, against the model's, at the paraxial focus n·R/(2(n − 1)) = 1.5 below the centre and
// twice as far.
void expect_profile(double H, double tolerance) {
    constexpr double kBin = 0.1;
    constexpr int kBins = 20;
    Maps m(ball_scene(H, 20000, 0.02));
    const Model model = ball_model(1, 1.5, H, kBin, kBins, 8);
    constexpr int kPasses = 16, kRadii = 4, kAngles = 8;
    double worst = 0;
    // At the focus the central ring's spike is narrower than the gather radius: the crossings
    // below check it.
    for (int k = H < 2 ? 1 : 0; k < kBins; ++k) {
        double sum = 0;
        for (std::uint32_t pass = 0; pass < kPasses; ++pass) {
            for (int i = 0; i < kRadii; ++i) {
                // Equal areas of the ring.
                const double r0 = k * kBin, r1 = (k + 1) * kBin;
                const double r = std::sqrt(r0 * r0 + (i + 0.5) / kRadii * (r1 * r1 - r0 * r0));
                for (int j = 0; j < kAngles; ++j) {
                    const double phi = 2 * kPi * (j + 0.5 * (pass % 2)) / kAngles;
                    sum +=
                        m.maps
                            .caustic(0, pass, {r * std::cos(phi), 0, r * std::sin(phi)}, {0, 1, 0})
                            .r;
                }
            }
        }
        const double mean = sum / (kPasses * kRadii * kAngles);
        worst = std::max(worst, std::abs(mean - model.bins[k]) / std::max(model.bins[k], 0.2));
    }
    EXPECT_LT(worst, tolerance) << "floor " << H << " below the centre";
}

// The estimate spreads each photon's power evenly over the disc of the pass's radius: summed
// over a fine grid of gather points, it gives back the power of the photons stored there.
TEST(PhotonMap, EstimateSpreadsEachPhotonOverItsDisc) {
    Maps m(ball_scene(3, 20000, 0.1));
    constexpr double kHalf = 3, kStep = 0.025;
    for (const std::uint32_t pass : {0u, 5u}) {
        const double radius = m.maps.pass(0, pass)->radius();
        double stored = 0;
        for (const Photon& p : m.maps.trace(0, pass)) {
            if (std::abs(p.position[0]) < kHalf && std::abs(p.position[2]) < kHalf) {
                stored += p.power[1];
            }
        }
        double gathered = 0;
        for (double x = -kHalf + kStep / 2; x < kHalf; x += kStep) {
            for (double z = -kHalf + kStep / 2; z < kHalf; z += kStep) {
                gathered += m.maps.caustic(0, pass, {x, 0, z}, {0, 1, 0}).g * kStep * kStep;
            }
        }
        EXPECT_NEAR(gathered / stored, 1, 0.005) << "pass " << pass << ", radius " << radius;
    }
}

// A pixel's mean over its samples, pass by pass, converges to the model: near the focus, where
// the first passes' wide radius blurs the steep profile most, the error of the rings' means
// falls as passes are added.
TEST(PhotonMap, CausticConvergesAsPassesAreAdded) {
    constexpr double kBin = 0.05;
    constexpr int kBins = 12;
    const double H = 1.5;
    Maps m(ball_scene(H, 5000, 0.1));
    const Model model = ball_model(1, 1.5, H, kBin, kBins, 8);
    const auto error_after = [&](std::uint32_t passes) {
        double squares = 0;
        for (int k = 2; k < kBins; ++k) {
            const double r = (k + 0.5) * kBin;
            double sum = 0;
            for (std::uint32_t pass = 0; pass < passes; ++pass) {
                const double phi = 2 * kPi * (pass * 0.618034);
                sum +=
                    m.maps.caustic(7, pass, {r * std::cos(phi), 0, r * std::sin(phi)}, {0, 1, 0}).r;
            }
            const double e = sum / passes - model.bins[k];
            squares += e * e;
        }
        return std::sqrt(squares / (kBins - 2));
    };
    const double e4 = error_after(4), e32 = error_after(32), e256 = error_after(256);
    EXPECT_LT(e32, 0.7 * e4);
    EXPECT_LT(e256, 0.7 * e32);
}

TEST(PhotonMap, CausticProfileMatchesTheBallLensModel) {
    expect_profile(1.5, 0.1);
    expect_profile(3, 0.1);
}

// Each photon on the floor, followed back along its last direction, crosses the axis where
// the ball focused it: paraxial light at n·R/(2(n − 1)) = 1.5 below the centre, light through
// the ball's outer zones nearer (spherical aberration). The share of the floor's light that
// crossed beyond each depth matches the model's.
TEST(PhotonMap, FocusIsParaxialWithTheBallLensSphericalAberration) {
    const double H = 3;
    Maps m(ball_scene(H, 20000, 0.02));
    const Model model = ball_model(1, 1.5, H, 0.1, 40, 8);
    const std::vector<double> depths = {0.5, 1.0, 1.2, 1.3, 1.4, 1.45, 1.49, 1.5, 1.51};
    std::vector<double> photons(depths.size(), 0.0), modelled(depths.size(), 0.0);
    double total = 0;
    for (std::uint32_t pass = 0; pass < 8; ++pass) {
        for (const Photon& p : m.maps.trace(0, pass)) {
            const double radial = std::hypot(p.position[0], p.position[2]);
            const double outward =
                (p.position[0] * p.dir[0] + p.position[2] * p.dir[2]) / std::max(radial, 1e-30);
            if (outward == 0) continue;
            // Back along the direction to radius 0.
            const double depth = H - (p.position[1] - p.dir[1] * radial / outward);
            total += p.power[0];
            for (std::size_t i = 0; i < depths.size(); ++i) {
                if (depth > depths[i]) photons[i] += p.power[0];
            }
        }
    }
    double model_total = 0;
    for (const auto& [depth, share] : model.crossings) {
        model_total += share;
        for (std::size_t i = 0; i < depths.size(); ++i) {
            if (depth > depths[i]) modelled[i] += share;
        }
    }
    for (std::size_t i = 0; i < depths.size(); ++i) {
        EXPECT_NEAR(photons[i] / total, modelled[i] / model_total, 0.005) << "beyond " << depths[i];
    }
    // Light piles up just before the paraxial focus (2.4 % of it within 0.01) and none crosses
    // just beyond it; the 0.2 % beyond is light reflected inside the ball.
    const auto share = [&](std::size_t i, std::size_t j) {
        return (photons[i] - photons[j]) / total;
    };
    EXPECT_GT(share(6, 7), 0.02);
    EXPECT_LT(share(7, 8), 1e-4);
}

}  // namespace
}  // namespace drt

namespace drt {
namespace {

// A floor lit by a sphere light of Falloff 1 through a clear pane (index 1, kt 1), seen from
// between the pane and the floor. Shadow rays stop at the pane, so all the floor's light is
// caustic: photons must bring exactly the light the floor gets without the pane, in both
// integrators, and the path integrator must not count the light its own paths find through the
// pane as well.
std::string pane_scene(const std::string& integrator, bool pane, bool photons, int samples) {
    return R"(<Scene><Image Width="8" Height="8"/>
      <Render Samples=")" +
           std::to_string(samples) + R"(" MaxDepth="4" Sampler="random" Integrator=")" +
           integrator + R"("/>)" + (photons ? R"(<Photons Count="20000" Radius="0.2"/>)" : "") +
           R"(<Camera Ex="0" Ey="1" Ez="0" Lx="0" Ly="0" Lz="0" Ux="0" Uy="0" Uz="1" Fov="90"/>
      <Materials><Floor diffuse="1" kdr="0.5" kdg="0.5" kdb="0.5"/>
        <Pane transmitt="1" ktr="1" ktg="1" ktb="1" index="1"/></Materials>
      <Light Px="0.3" Py="2" Pz="0" Radius="0.25" Falloff="1" Ir="4" Ig="4" Ib="4"/>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>)" +
           (pane ? R"(<Plane Px="0" Py="1.5" Pz="0" Vu="0" Vv="1" Vw="0" Material="Pane"/>)" : "") +
           "</Scene>";
}

double mean_of(const std::string& xml, int threads = 2) {
    RenderOptions options;
    options.threads = threads;
    const Image image = render(from_xml(xml), options).image;
    double sum = 0;
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) sum += image.at(x, y).r;
    }
    return sum / (image.width * image.height);
}

TEST(PhotonMap, ClearPaneLetsPhotonsBringTheDirectLightInBothIntegrators) {
    const double open = mean_of(pane_scene("distributed", false, false, 64));
    EXPECT_GT(open, 0.1);
    // Without photons the pane's shadow is black in the distributed integrator.
    EXPECT_EQ(mean_of(pane_scene("distributed", true, false, 4)), 0.0);
    EXPECT_NEAR(mean_of(pane_scene("distributed", true, true, 32)) / open, 1, 0.02);
    // The path integrator's paths through the pane to the light are left to the photons: counted
    // by both, the floor would be twice as bright.
    const double path_open = mean_of(pane_scene("path", false, false, 64));
    EXPECT_NEAR(path_open / open, 1, 0.02);
    EXPECT_NEAR(mean_of(pane_scene("path", true, true, 32)) / open, 1, 0.02);
}

// An emitting <Triangle> grouped into one mesh with the pane's triangles (its part comes
// second): its photons leave from its own triangles, not from the mesh's first ones (the pane's),
// and bring the direct light through the pane as the clear pane's test does for a sphere light.
std::string lamp_and_pane_scene(bool pane, bool photons, int samples) {
    // Two triangles: the square of half-side h about (x0, y, 0).
    const auto quad = [](double y, double h, double x0, const std::string& material) {
        const auto corner = [y](const char* name, double x, double z) {
            const std::string n(name);
            return " " + n + "x=\"" + std::to_string(x) + "\" " + n + "y=\"" + std::to_string(y) +
                   "\" " + n + "z=\"" + std::to_string(z) + "\"";
        };
        return "<Triangle" + corner("A", x0 - h, -h) + corner("B", x0 + h, -h) +
               corner("C", x0 + h, h) + " Material=\"" + material + "\"/><Triangle" +
               corner("A", x0 - h, -h) + corner("B", x0 + h, h) + corner("C", x0 - h, h) +
               " Material=\"" + material + "\"/>";
    };
    return R"(<Scene><Image Width="8" Height="8"/>
      <Render Samples=")" +
           std::to_string(samples) + R"(" MaxDepth="4" Sampler="random"/>)" +
           (photons ? R"(<Photons Count="20000" Radius="0.2"/>)" : "") +
           R"(<Camera Ex="0" Ey="1" Ez="0" Lx="0" Ly="0" Lz="0" Ux="0" Uy="0" Uz="1" Fov="90"/>
      <Materials><Floor diffuse="1" kdr="0.5" kdg="0.5" kdb="0.5"/>
        <Pane transmitt="1" ktr="1" ktg="1" ktb="1" index="1"/>
        <Lamp ker="40" keg="40" keb="40"/></Materials>
      <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>)" +
           (pane ? quad(1.5, 4, 0, "Pane") : "") + quad(2, 0.25, 0.3, "Lamp") + "</Scene>";
}

TEST(PhotonMap, AnEmittingPartOfASharedMeshSendsItsPhotonsFromItsOwnTriangles) {
    const Scene grouped = from_xml(lamp_and_pane_scene(true, false, 1));
    ASSERT_EQ(grouped.objects.size(), 3u);  // the floor, and the mesh's two parts
    const double open = mean_of(lamp_and_pane_scene(false, false, 64));
    EXPECT_GT(open, 0.1);
    EXPECT_EQ(mean_of(lamp_and_pane_scene(true, false, 4)), 0.0);
    EXPECT_NEAR(mean_of(lamp_and_pane_scene(true, true, 32)) / open, 1, 0.03);
}

// Photons are traced only when the scene calls for them: a Falloff-1 light or an emitter, a
// reflective or transparent surface, and a diffuse surface.
TEST(PhotonMap, TracedOnlyWhenTheSceneCallsForThem) {
    const std::string with = pane_scene("distributed", true, true, 2);
    const RenderResult on = render(from_xml(with), RenderOptions{});
    EXPECT_TRUE(on.plan.effects.caustics);
    EXPECT_EQ(on.stats.photons, 2u * 20000u);
    const auto off = [&](std::string xml, const std::string& from, const std::string& to) {
        xml.replace(xml.find(from), from.size(), to);
        const RenderResult r = render(from_xml(xml), RenderOptions{});
        EXPECT_FALSE(r.plan.effects.caustics) << to;
        EXPECT_EQ(r.stats.photons, 0u) << to;
    };
    off(with, R"(Falloff="1")", R"(Falloff="0")");  // the thesis's light has no power
    off(with, R"(transmitt="1")", R"(transmitt="0" diffuse="1")");  // nothing focuses
    off(with, R"(MaxDepth="4")", R"(MaxDepth="0")");  // no reflective or transparent event
}

TEST(PhotonMap, SameBitsOnAnyNumberOfThreads) {
    const Scene scene = from_xml(pane_scene("path", true, true, 8));
    RenderOptions one, three;
    one.threads = 1;
    three.threads = 3;
    const Image a = render(scene, one).image, b = render(scene, three).image;
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    for (std::size_t i = 0; i < a.rgb.size(); ++i) ASSERT_EQ(a.rgb[i], b.rgb[i]);
}

}  // namespace
}  // namespace drt
