// The cost guess that orders the tiles: shaded rays the probes trace, scaled to the tile, and the
// order it gives (which changes no pixel: renderer_test.cpp renders tiles in any order); requests
// against one context: without the error estimate, one pixel per block, listed pixels paired;
// a tile's pixels shared with a helping thread; a pixel's samples in parts, and a stop heard
// within a pixel.
#include "drt/render/render_context.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "drt/render/pixel_integrator.h"
#include "drt/render/render_plan.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/light.h"
#include "test_scenes.h"

namespace drt {
namespace {

// A mirror sphere filling the middle of a 96 × 96 image: a camera ray there traces one
// reflection (which leaves the convex sphere for the background); the corner tiles see only
// background, one camera ray a pixel.
Scene mirror_ball() {
    return testing::lone_sphere_scene(testing::mirror({0.5, 0.5, 0.5}), {0.1, 0.2, 0.3}, 96);
}

TEST(TileCost, CountsTheProbesShadedRaysScaledToTheTile) {
    const Scene scene = mirror_ball();
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    const std::vector<Tile>& tiles = context.tiles();
    ASSERT_EQ(tiles.size(), 36u);
    EXPECT_EQ(context.tile_cost(tiles[0], request), 256u);  // top left: background only
    EXPECT_EQ(context.tile_cost(tiles[35], request), 256u);
    EXPECT_EQ(context.tile_cost(tiles[14], request), 512u);  // beside the centre: all mirror
    EXPECT_EQ(context.tile_cost(tiles[21], request), 512u);
    // An edge tile of 8 × 16 pixels, background only: half the cost.
    const Scene narrow =
        testing::lone_sphere_scene(testing::mirror({0.5, 0.5, 0.5}), {0.1, 0.2, 0.3}, 88);
    const RenderContext cut(narrow);
    EXPECT_EQ(cut.tiles()[5].width(), 8);
    EXPECT_EQ(cut.tile_cost(cut.tiles()[5], request), 128u);
}

TEST(TileCost, LeavesShadowRaysOut) {
    // A grey ball lit through 8 shadow rays a shading point: the tiles on the ball trace 9 rays a
    // camera sample, those of the background 1, yet both count one shaded ray a pixel — a shading
    // point's own work, not its shadow rays, is what a tile's time follows (design.md).
    Scene scene = testing::lone_sphere_scene(testing::grey_lambert(), {0.1, 0.2, 0.3}, 96);
    scene.settings.shadow_rays = 8;
    scene.lights.push_back(
        std::make_unique<SphereLight>(Vec3{0, 5, -10}, 1.0, Color{1, 1, 1}, false));
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    const TileBuffer ball = context.render_tile(context.tiles()[14], request);
    ASSERT_EQ(ball.rays.shadow, 8u * ball.rays.camera);  // every pixel on the lit side
    EXPECT_EQ(context.tile_cost(context.tiles()[14], request), 256u);
    EXPECT_EQ(context.tile_cost(context.tiles()[0], request), 256u);
}

TEST(CostlyFirst, OrdersByFallingCostAndKeepsIndexOrderAmongEquals) {
    const Scene scene = mirror_ball();
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    const std::vector<Tile> order = costly_first(context, request, context.tiles(), 2);
    ASSERT_EQ(order.size(), context.tiles().size());
    EXPECT_TRUE(std::is_permutation(order.begin(), order.end(), context.tiles().begin()));
    EXPECT_EQ(order.front().index, 7u);  // the first of the all-mirror tiles
    EXPECT_EQ(order.back().index, 35u);  // the last of the background-only ones
    for (std::size_t i = 1; i < order.size(); ++i) {
        const auto before = context.tile_cost(order[i - 1], request);
        const auto after = context.tile_cost(order[i], request);
        EXPECT_GE(before, after) << i;
        if (before == after) {
            EXPECT_LT(order[i - 1].index, order[i].index) << i;
        }
    }
}

TEST(CostlyFirst, ThePilotsThreadsChangeNoPlace) {
    const Scene scene = testing::scaled_scene("thesis/test4.xml", 80, 4);
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    const std::vector<Tile> one = costly_first(context, request, context.tiles(), 2, 1);
    ASSERT_NE(one, context.tiles());
    EXPECT_EQ(costly_first(context, request, context.tiles(), 2, 3), one);
    EXPECT_EQ(costly_first(context, request, context.tiles(), 2, 64),
              one);  // more threads than tiles
}

TEST(CostlyFirst, LeavesOneWorkersTilesAlone) {
    const Scene scene = mirror_ball();
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    EXPECT_EQ(costly_first(context, request, context.tiles(), 1), context.tiles());
}

TEST(RenderContext, WithoutTheEstimateRendersTheSamePixelsAndNoneTwice) {
    Scene scene = mirror_ball();
    scene.settings.samples = 4;  // the stratified sampler: calibrated by second renders
    const RenderContext context(scene);
    const RenderRequest with = RenderRequest::whole_image(scene.settings);
    RenderRequest without = with;
    without.estimate_error = false;
    ErrorSums calibrated;
    for (const Tile& tile : context.tiles()) {
        const TileBuffer a = context.render_tile(tile, with);
        const TileBuffer b = context.render_tile(tile, without);
        EXPECT_EQ(a.pixels.rgb, b.pixels.rgb) << tile.index;
        EXPECT_EQ(a.rays.total(), b.rays.total()) << tile.index;
        EXPECT_EQ(b.error_sums, ErrorSums{}) << tile.index;
        calibrated += a.error_sums;
    }
    EXPECT_GE(calibrated.pixels, 64);  // 8 % of 9,216 pixels rendered twice on average
}

TEST(RenderContext, HelpersRenderATilesPixelsAsItsOwnThreadWould) {
    // Area lights, glass, depth of field: every sample of a pixel differs.
    Scene scene = testing::scaled_scene("thesis/test6.xml", 16, 64);
    const RenderContext context(scene);
    ASSERT_EQ(context.tiles().size(), 1u);
    const Tile& tile = context.tiles()[0];
    // The estimate's second renders of some pixels (the stratified sampler's calibration), and
    // a paired request's second render of every pixel: both shared with the helper too.
    const RenderRequest estimated = RenderRequest::whole_image(scene.settings);
    RenderRequest paired = estimated;
    paired.pixels = PixelChoice::kListed;
    for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; x += 2) paired.listed.push_back(y * 16 + x);
    }
    paired.paired = true;
    for (const RenderRequest& request : {estimated, paired}) {
        SCOPED_TRACE(request.paired ? "paired" : "estimated");
        const TileBuffer alone = context.render_tile(tile, request);
        if (!request.paired) {
            EXPECT_GT(alone.error_sums.pixels, 0);
        }
        // A helper that wakes only after the owner has taken every pixel renders none: on a
        // busy machine that can happen, so the owner renders the tile again until one did.
        std::size_t helped = 0;
        for (int attempt = 0; attempt < 20 && helped == 0; ++attempt) {
            RenderContext::Workbench bench;
            // The owner's, taken before the helper looks and given up once the tile is done.
            std::optional<RenderContext::Workbench::Taker> taker(std::in_place, bench);
            std::optional<TileBuffer> shared;
            {
                const std::jthread owner([&] {
                    shared = context.render_tile(tile, request, {}, &bench);
                    taker.reset();
                });
                // Waits for the owner's tile, helps with it, and returns once the owner takes
                // no more.
                helped = context.help(bench, {});
            }
            ASSERT_TRUE(shared);
            EXPECT_EQ(shared->pixels.rgb, alone.pixels.rgb);
            EXPECT_EQ(shared->spread.rgb, alone.spread.rgb);
            EXPECT_EQ(shared->pixel_samples, alone.pixel_samples);
            EXPECT_EQ(shared->error_sums, alone.error_sums);
            EXPECT_EQ(shared->samples, alone.samples);
            EXPECT_EQ(shared->rays.camera, alone.rays.camera);
            EXPECT_EQ(shared->rays.reflection, alone.rays.reflection);
            EXPECT_EQ(shared->rays.total(), alone.rays.total());
        }
        EXPECT_GT(helped, 0u);
    }
}

// A pixel's samples are rendered kSamplesBetweenStops at a time (RenderContext::sample), which
// gives the bits of one run only because each sample is a function of its own index: for both
// integrators and every sampler, a run of 700 samples and the same samples in parts agree.
TEST(RenderContext, APixelsSamplesInPartsAreThoseOfOneRun) {
    for (const std::string name : {"thesis/test6.xml", "gi/cornell-box.xml"}) {
        for (const std::string sampler_name : {"stratified", "sobol", "random"}) {
            SCOPED_TRACE(name + " " + sampler_name);
            Scene scene = testing::scaled_scene(name, 8, 700);
            scene.settings.sampler = sampler_name;
            const RenderPlan plan = plan_render(scene);
            const Bvh bvh(scene.objects);
            const auto sampler = make_sampler(sampler_name);
            const auto integrator = make_integrator(scene, plan, bvh, *sampler);
            const int x = 3, y = scene.settings.height / 2;
            PixelSample s{5, static_cast<std::uint32_t>(y * scene.settings.width + x), 0, 700};
            std::vector<Color> whole(700), parts(700);
            RayCounts rays_whole, rays_parts;
            integrator->sample_pixel(x, y, s, whole, rays_whole);
            for (const std::size_t part : {256u, 256u, 188u}) {
                integrator->sample_pixel(x, y, s, std::span(parts).subspan(s.index, part),
                                         rays_parts);
                s.index += static_cast<std::uint32_t>(part);
            }
            for (std::size_t i = 0; i < whole.size(); ++i) {
                ASSERT_EQ(whole[i].r, parts[i].r) << i;
                ASSERT_EQ(whole[i].g, parts[i].g) << i;
                ASSERT_EQ(whole[i].b, parts[i].b) << i;
            }
            EXPECT_EQ(rays_whole.total(), rays_parts.total());
            EXPECT_GT(rays_whole.total(), 700u);
        }
    }
}

// A stop is heard between a pixel's samples, not only between its pixels: a tile of one pixel
// of 65,536 samples (most of a second, more under the sanitizers) stopped 20 ms in
// comes back empty, plainly and adaptively; before, the pixel was finished, and with it the tile.
TEST(RenderContext, AStopIsHeardWithinAPixel) {
    using namespace std::chrono_literals;
    Scene scene = testing::scaled_scene("thesis/test6.xml", 1, 65536);
    scene.settings.shadow_rays = 512;  // a pixel of most of a second: the stop comes inside it
    ASSERT_EQ(scene.settings.height, 1);
    const RenderContext context(scene);
    RenderRequest plain = RenderRequest::whole_image(scene.settings);
    plain.estimate_error = false;
    RenderRequest adaptive = plain;
    adaptive.adaptive = AdaptiveSampling{1e-12, 16};  // never met: rounds up to 65,536
    for (const RenderRequest& request : {plain, adaptive}) {
        SCOPED_TRACE(request.adaptive ? "adaptive" : "plain");
        std::stop_source stop;
        const auto start = std::chrono::steady_clock::now();
        std::optional<TileBuffer> tile;
        {
            const std::jthread stopper([&] {
                std::this_thread::sleep_for(20ms);
                stop.request_stop();
            });
            tile = context.render_tile(context.tiles()[0], request, stop.get_token());
        }
        EXPECT_FALSE(tile)
            << "finished in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s";
    }
}

// A request of one sample a pixel and one of more have plans of their own (pixel centres or
// areas), which share one copy of the emitters: an emitting mesh's per-triangle data is kept once.
TEST(RenderContext, ThePlansForCentresAndAreasShareTheirEmitters) {
    const Scene scene = testing::scaled_scene("gi/cornell-box.xml", 8, 4);
    const RenderContext context(scene);
    RenderRequest areas = RenderRequest::whole_image(scene.settings);
    RenderRequest centres = areas;
    centres.samples = 1;
    const Emitters& a = context.plan(areas).emitters;
    const Emitters& c = context.plan(centres).emitters;
    ASSERT_EQ(a.size(), 1u);  // the lamp
    EXPECT_TRUE(context.plan(areas).effects.antialiasing);
    EXPECT_FALSE(context.plan(centres).effects.antialiasing);
    EXPECT_EQ(&a[0], &c[0]);
    EXPECT_EQ(a[0].triangles.size(), 2u);
}

// One pixel in block x block of `scene`'s image.
RenderRequest one_per_block(const Scene& scene, int block) {
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    request.pixels = PixelChoice::kOnePerBlock;
    request.pixel_block = block;
    return request;
}

TEST(RenderContext, OnePixelPerBlockRendersOnePixelOfEachSquareAsTheFullRenderDoes) {
    // 90 x 90 in squares of 4: 22 x 22 whole squares and a row and a column of squares that the
    // image's edge cuts to 2 pixels across.
    Scene scene = testing::scaled_scene("thesis/test1.xml", 90, 4);
    scene.settings.height = 90;
    const RenderContext context(scene);
    const RenderRequest full = RenderRequest::whole_image(scene.settings);
    const RenderRequest pilot = one_per_block(scene, 4);
    std::uint64_t picked = 0, in_cut_squares = 0;
    for (int sy = 0; sy < 90; sy += 4) {
        for (int sx = 0; sx < 90; sx += 4) {
            int in_square = 0;
            for (int y = sy; y < std::min(sy + 4, 90); ++y) {
                for (int x = sx; x < std::min(sx + 4, 90); ++x) {
                    in_square += context.renders(pilot, x, y);
                }
            }
            // One in a whole square; at most one in a cut square, whose place may lie outside
            // the image, so that every pixel has the same odds.
            if (sx + 4 <= 90 && sy + 4 <= 90) {
                EXPECT_EQ(in_square, 1) << sx << " " << sy;
            } else {
                EXPECT_LE(in_square, 1) << sx << " " << sy;
                in_cut_squares += static_cast<std::uint64_t>(in_square);
            }
            picked += static_cast<std::uint64_t>(in_square);
        }
    }
    EXPECT_EQ(context.rendered_pixels(pilot), picked);
    EXPECT_EQ(context.rendered_pixels(full), 8100u);
    // 45 cut squares hold 8 (or 4) of their 16 places inside: about 22 picked; 1 in 16 each
    // would make at least 3 and at most 43 all but impossible.
    EXPECT_GE(in_cut_squares, 3u);
    EXPECT_LE(in_cut_squares, 43u);
    // Another seed picks other places: the same as this one's in about 1 square in 16.
    RenderRequest other = pilot;
    other.seed = pilot.seed + 1;
    int same = 0;
    for (int y = 0; y < 88; ++y) {
        for (int x = 0; x < 88; ++x) {
            same += context.renders(pilot, x, y) && context.renders(other, x, y);
        }
    }
    EXPECT_LT(same, 484 / 4);
    // A picked pixel has the full render's bits and takes the tile's only samples; the others
    // are 0 with no spread.
    std::uint64_t samples = 0;
    for (const Tile& tile : context.tiles()) {
        const TileBuffer a = context.render_tile(tile, full);
        const TileBuffer b = context.render_tile(tile, pilot);
        samples += b.samples;
        for (int y = tile.y0; y < tile.y1; ++y) {
            for (int x = tile.x0; x < tile.x1; ++x) {
                const int tx = x - tile.x0, ty = y - tile.y0;
                const bool rendered = context.renders(pilot, x, y);
                EXPECT_EQ(b.pixels.at(tx, ty), rendered ? a.pixels.at(tx, ty) : Color{})
                    << x << " " << y;
                EXPECT_EQ(b.spread.at(tx, ty), rendered ? a.spread.at(tx, ty) : Color{})
                    << x << " " << y;
            }
        }
    }
    EXPECT_EQ(samples, 4 * picked);
}

TEST(RenderContext, OnePixelPerBlockRendersThePickedPixelsOfSquaresThatCrossATilesEdges) {
    // Squares of 5 and 7 do not divide the tiles of 16: a tile holds parts of squares whose
    // picked pixel may lie in it or in a neighbour.
    Scene scene = testing::scaled_scene("thesis/test1.xml", 90, 2);
    scene.settings.height = 61;
    const RenderContext context(scene);
    for (const int block : {5, 7}) {
        const RenderRequest pilot = one_per_block(scene, block);
        std::uint64_t rendered = 0;
        for (const Tile& tile : context.tiles()) {
            const TileBuffer buffer = context.render_tile(tile, pilot);
            for (int y = tile.y0; y < tile.y1; ++y) {
                for (int x = tile.x0; x < tile.x1; ++x) {
                    const std::uint32_t samples =
                        buffer.pixel_samples[std::size_t(y - tile.y0) * std::size_t(tile.width()) +
                                             std::size_t(x - tile.x0)];
                    EXPECT_EQ(samples, context.renders(pilot, x, y) ? 2u : 0u)
                        << block << ": " << x << " " << y;
                    rendered += samples / 2;
                }
            }
        }
        EXPECT_EQ(rendered, context.rendered_pixels(pilot)) << block;
    }
}

TEST(RenderContext, ListedPixelsPairedAreRenderedTwiceAndAveraged) {
    Scene scene = testing::scaled_scene("thesis/test1.xml", 40, 4);
    scene.settings.height = 30;
    // Pixels in three tiles, a corner and an edge among them.
    const std::vector<std::uint32_t> top_up{0, 17, 39, 40 * 16 + 20, 40 * 29 + 39};
    const RenderContext context(scene);
    const RenderRequest full = RenderRequest::whole_image(scene.settings);
    RenderRequest again = full;
    again.pixels = PixelChoice::kListed;
    again.listed = top_up;
    again.paired = true;
    EXPECT_EQ(context.rendered_pixels(again), top_up.size());
    std::uint64_t samples = 0;
    double pairs = 0;
    for (const Tile& tile : context.tiles()) {
        const TileBuffer a = context.render_tile(tile, full);
        const TileBuffer b = context.render_tile(tile, again);
        samples += b.samples;
        pairs += b.error_sums.pixels;
        for (int y = tile.y0; y < tile.y1; ++y) {
            for (int x = tile.x0; x < tile.x1; ++x) {
                const int tx = x - tile.x0, ty = y - tile.y0;
                const auto i = static_cast<std::uint32_t>(y * 40 + x);
                const bool listed = std::find(top_up.begin(), top_up.end(), i) != top_up.end();
                EXPECT_EQ(context.renders(again, x, y), listed) << x << " " << y;
                if (!listed) {
                    EXPECT_EQ(b.pixels.at(tx, ty), Color{}) << x << " " << y;
                    continue;
                }
                // The mean of the plain render's pixel and an independent second render of it,
                // and a quarter of their squared difference.
                const Color second = 2.0 * b.pixels.at(tx, ty) - a.pixels.at(tx, ty);
                EXPECT_NE(second, a.pixels.at(tx, ty)) << x << " " << y;
                const Color d = a.pixels.at(tx, ty) - second;
                const Color quarter = d * d * 0.25;
                const Color spread = b.spread.at(tx, ty);
                EXPECT_NEAR(spread.r, quarter.r, 1e-6 * (1 + quarter.r)) << x << " " << y;
                EXPECT_NEAR(spread.g, quarter.g, 1e-6 * (1 + quarter.g)) << x << " " << y;
                EXPECT_NEAR(spread.b, quarter.b, 1e-6 * (1 + quarter.b)) << x << " " << y;
                EXPECT_EQ(
                    b.pixel_samples[std::size_t(ty) * std::size_t(tile.width()) + std::size_t(tx)],
                    8u);
            }
        }
    }
    EXPECT_EQ(samples, 8 * top_up.size());
    // The spreads are the variance of the pairs' means: nothing to calibrate.
    EXPECT_EQ(context.spread_kind(again), SpreadKind::kIndependent);
    EXPECT_EQ(pairs, 0.0);
}

TEST(RenderContext, ChecksARequestBeforeRenderingIt) {
    Scene scene = testing::scaled_scene("thesis/test1.xml", 40, 4);
    scene.settings.height = 30;
    const RenderContext context(scene);
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    EXPECT_NO_THROW(context.check(request));
    request.samples = 0;
    EXPECT_THROW(context.check(request), std::invalid_argument);
    request = one_per_block(scene, 1);
    EXPECT_THROW(context.check(request), std::invalid_argument);
    request = RenderRequest::whole_image(scene.settings);
    request.pixels = PixelChoice::kListed;
    for (const auto& listed : std::vector<std::vector<std::uint32_t>>{{3, 3}, {5, 4}, {1200}}) {
        request.listed = listed;
        EXPECT_THROW(context.check(request), std::invalid_argument);
    }
    request.listed = {0, 1199};
    EXPECT_NO_THROW(context.check(request));
}

// Requests of other counts and seeds against one context: each the bits of a context set up for
// the scene with those settings, one sample per pixel (the pixel centre) included.
TEST(RenderContext, ARequestAgainstOneContextIsTheFreshRenderOfItsSettings) {
    Scene scene = testing::scaled_scene("thesis/test1.xml", 40, 4);
    scene.settings.height = 30;
    const RenderContext context(scene);
    for (const auto& [samples, seed] :
         std::vector<std::pair<int, std::uint64_t>>{{4, 0}, {1, 7}, {9, 123456789}, {2, 5}}) {
        Scene fresh = testing::scaled_scene("thesis/test1.xml", 40, 4);
        fresh.settings.height = 30;
        fresh.settings.samples = samples;
        fresh.settings.seed = seed;
        const RenderContext alone(fresh);
        const RenderRequest own = RenderRequest::whole_image(fresh.settings);
        EXPECT_EQ(context.plan(own).effects.antialiasing, samples > 1);
        EXPECT_EQ(context.plan(own).effects.antialiasing, plan_render(fresh).effects.antialiasing);
        for (const Tile& tile : context.tiles()) {
            const TileBuffer a = context.render_tile(tile, own);
            const TileBuffer b = alone.render_tile(tile, own);
            ASSERT_EQ(a.pixels.rgb, b.pixels.rgb) << samples << " " << tile.index;
            ASSERT_EQ(a.spread.rgb, b.spread.rgb) << samples << " " << tile.index;
            ASSERT_EQ(a.error_sums, b.error_sums) << samples << " " << tile.index;
        }
    }
}

}  // namespace
}  // namespace drt
