#include "drt/render/scattering.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "drt/sampling/multi_jittered.h"

namespace drt {
namespace {

TEST(SpawnRay, LeavesTheSurfaceOnTheSideOfTheDirection) {
    const Vec3 p{1e5, 0, -1e5};
    const Ray up = spawn_ray(p, {0, 1, 0}, normalize(Vec3{1, 1e-3, 0}), 0);
    EXPECT_GT(up.origin.y, 0);
    const Ray down = spawn_ray(p, {0, 1, 0}, normalize(Vec3{1, -1e-3, 0}), 0);
    EXPECT_LT(down.origin.y, 0);
}

TEST(PerturbDirection, AngularSpreadMatchesSigma) {
    const Vec3 ideal = normalize(Vec3{0.3, 1, -0.2});
    const double sigma = 0.05;
    double sum_sq = 0;
    const int n = 64 * 64;
    for (int i = 0; i < n; ++i) {
        const Vec2 u = multi_jittered(i, n, 99);
        const double angle =
            std::acos(std::min(1.0, dot(perturb_direction(ideal, sigma, u), ideal)));
        sum_sq += angle * angle;
    }
    // The angle of a 2-D normal offset with per-axis deviation sigma has E[angle^2] = 2 sigma^2.
    EXPECT_NEAR(sum_sq / n, 2 * sigma * sigma, 0.02 * 2 * sigma * sigma);
}

// A draw on the wrong side is redrawn, and after kRedrawAttempts draws the ideal direction is
// taken: at sigma 3 about the horizon many draws go below it.
TEST(PerturbOnSide, RedrawsUntilTheDirectionLeavesOnItsSide) {
    const Vec3 up{0, 1, 0};
    const Vec3 ideal = normalize(Vec3{1, 1e-3, 0});
    int redraws = 0;
    const auto redraw = [&](int attempt) {
        EXPECT_EQ(attempt, ++redraws);
        return multi_jittered(static_cast<std::uint32_t>(attempt), 64, 5);
    };
    const Vec3 dir = perturb_on_side(ideal, 3.0, 1.0, up, multi_jittered(0, 64, 5), redraw);
    EXPECT_GT(dot(dir, up), 0);
    EXPECT_LT(redraws, kRedrawAttempts);
    EXPECT_GT(redraws, 0) << "the first draw was already above: no redraw tested";
    // A narrow lobe about a direction into the surface: every draw is on the wrong side, and the
    // ideal direction comes after exactly kRedrawAttempts draws.
    redraws = 0;
    const Vec3 never =
        perturb_on_side(ideal, 0.01, 1.0, -ideal, multi_jittered(0, 64, 5), [&](int attempt) {
            ++redraws;
            return multi_jittered(static_cast<std::uint32_t>(attempt), 64, 5);
        });
    EXPECT_EQ(redraws, kRedrawAttempts - 1);
    EXPECT_EQ(never, ideal);
}

}  // namespace
}  // namespace drt
