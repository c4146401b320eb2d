// The render split into work units: tiles rendered in any order, by any number of threads, in
// parts or after a stop, assemble into the same image bits and the same counts as one render.
#include "drt/render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <mutex>
#include <new>
#include <optional>
#include <random>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "drt/render/tile.h"
#include "test_scenes.h"

namespace drt {
namespace {

Scene small_scene(const std::string& name, int width) {
    return testing::scaled_scene(name, width, 4);
}

RenderOptions on_threads(int threads) {
    RenderOptions options;
    options.threads = threads;
    return options;
}

bool same_bits(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

void expect_same_counts(const RayCounts& a, const RayCounts& b) {
    EXPECT_EQ(a.camera, b.camera);
    EXPECT_EQ(a.shadow, b.shadow);
    EXPECT_EQ(a.reflection, b.reflection);
    EXPECT_EQ(a.refraction, b.refraction);
}

// Area lights, glass with blurry refraction, depth of field; and glossy reflection.
const std::vector<std::string> kTestScenes = {"thesis/test6.xml", "figures/glossy-n10.xml"};

TEST(TileGrid, CutsTheImageRowByRowWithSmallerTilesAtTheEdges) {
    const std::vector<Tile> tiles = tile_grid(40, 20);
    const std::vector<Tile> expected = {{0, 0, 0, 16, 16},   {1, 16, 0, 32, 16},
                                        {2, 32, 0, 40, 16},  {3, 0, 16, 16, 20},
                                        {4, 16, 16, 32, 20}, {5, 32, 16, 40, 20}};
    EXPECT_EQ(tiles, expected);
}

TEST(ImageSink, RefusesATileTwiceAndATileOfAnotherGrid) {
    const Scene scene = small_scene("thesis/test6.xml", 20);
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
    sink.add(context.render_tile(context.tiles()[0], request));
    EXPECT_THROW(sink.add(context.render_tile(context.tiles()[0], request)), std::logic_error);
    TileBuffer other = context.render_tile(context.tiles()[1], request);
    other.tile.x1 -= 1;
    EXPECT_THROW(sink.add(std::move(other)), std::invalid_argument);
    EXPECT_EQ(sink.tiles_done(), 1u);
    EXPECT_EQ(sink.missing().size(), context.tiles().size() - 1);
}

TEST(Renderer, TilesInAnyOrderGiveTheWholeRendersBits) {
    for (const std::string& name : kTestScenes) {
        SCOPED_TRACE(name);
        const Scene scene = small_scene(name, 72);
        const RenderResult whole = render(scene, on_threads(2));
        const RenderContext context(scene);
        const RenderRequest request = RenderRequest::whole_image(scene.settings);
        ASSERT_GT(context.tiles().size(), 4u);
        std::vector<Tile> order = context.tiles();
        std::shuffle(order.begin(), order.end(), std::mt19937(7));
        ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
        TileQueue source(order);
        EXPECT_EQ(render_tiles(context, request, source, sink, on_threads(1)), 1);
        EXPECT_TRUE(same_bits(sink.image(), whole.image));
        expect_same_counts(sink.rays(), whole.stats.rays);
        EXPECT_EQ(sink.samples(), whole.stats.samples);
    }
}

TEST(Renderer, ThreadsBeyondTheTilesHelpWithTheirPixelsAndChangeNoBit) {
    Scene scene = small_scene("thesis/test6.xml", 16);  // one tile
    scene.settings.samples = 16;
    const RenderContext context(scene);
    ASSERT_EQ(context.tiles().size(), 1u);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ImageSink alone(scene.settings.width, scene.settings.height, context.tiles());
    ImageSink helped(scene.settings.width, scene.settings.height, context.tiles());
    TileQueue one(context.tiles()), three(context.tiles());
    EXPECT_EQ(render_tiles(context, request, one, alone, on_threads(1)), 1);
    EXPECT_EQ(render_tiles(context, request, three, helped, on_threads(3)), 3);
    EXPECT_TRUE(same_bits(helped.image(), alone.image()));
    EXPECT_TRUE(same_bits(helped.spread(), alone.spread()));
    expect_same_counts(helped.rays(), alone.rays());
    EXPECT_EQ(helped.rays().diffuse, alone.rays().diffuse);
    EXPECT_EQ(helped.samples(), alone.samples());
    EXPECT_EQ(helped.error_sums(), alone.error_sums());
}

TEST(Renderer, TileBuffersRayCountsSumToTheWholeRenders) {
    for (const std::string& name : kTestScenes) {
        SCOPED_TRACE(name);
        const Scene scene = small_scene(name, 72);
        const RenderResult whole = render(scene, on_threads(2));
        const RenderContext context(scene);
        const RenderRequest request = RenderRequest::whole_image(scene.settings);
        RayCounts sum;
        std::uint64_t samples = 0;
        for (const Tile& tile : context.tiles()) {
            const TileBuffer buffer = context.render_tile(tile, request);
            EXPECT_GT(buffer.rays.camera, 0u);
            sum += buffer.rays;
            samples += buffer.samples;
        }
        expect_same_counts(sum, whole.stats.rays);
        EXPECT_GT(sum.shadow, 0u);
        EXPECT_GT(sum.reflection + sum.refraction, 0u);
        EXPECT_EQ(samples, 4u * scene.settings.width * scene.settings.height);
        EXPECT_EQ(whole.stats.samples, samples);
    }
}

TEST(Renderer, ASubsetThenTheRestGiveTheWholeRendersBits) {
    for (const bool adaptive : {false, true}) {
        SCOPED_TRACE(adaptive ? "adaptive" : "plain");
        Scene scene = small_scene("thesis/test6.xml", 72);
        scene.settings.samples = 16;
        RenderOptions options = on_threads(2);
        if (adaptive) options.adaptive = AdaptiveSampling{0.01, 4};
        const RenderResult whole = render(scene, options);

        const RenderContext context(scene);
        RenderRequest request = RenderRequest::whole_image(scene.settings);
        request.adaptive = options.adaptive;
        ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
        std::vector<Tile> every_third;
        for (const Tile& t : context.tiles()) {
            if (t.index % 3 == 1) every_third.push_back(t);
        }
        TileQueue first(every_third);
        render_tiles(context, request, first, sink, options);
        EXPECT_EQ(sink.missing().size(), context.tiles().size() - every_third.size());
        const RenderResult rest = complete_render(context, request, sink, options);

        EXPECT_TRUE(same_bits(rest.image, whole.image));
        expect_same_counts(rest.stats.rays, whole.stats.rays);
        EXPECT_EQ(rest.stats.samples, whole.stats.samples);
        EXPECT_EQ(rest.stats.pixels_converged, whole.stats.pixels_converged);
        EXPECT_EQ(rest.pixel_samples, whole.pixel_samples);
        EXPECT_TRUE(rest.unfinished.empty());
        if (adaptive) {
            EXPECT_GT(whole.stats.pixels_converged, 0u);
        }
    }
}

// Passes tiles on to an ImageSink and requests a stop once it has `after` of them. One tile at a
// time, so that a worker adding a tile after the stop request sees it once add() returns.
class StopAfter final : public TileSink {
  public:
    StopAfter(ImageSink& sink, std::stop_source stop, std::size_t after)
        : sink_(sink), stop_(std::move(stop)), after_(after) {}
    void add(TileBuffer buffer) override {
        const std::lock_guard lock(mutex_);
        sink_.add(std::move(buffer));
        if (++added_ == after_) stop_.request_stop();
    }

  private:
    ImageSink& sink_;
    std::stop_source stop_;
    std::size_t after_;
    std::size_t added_ = 0;
    std::mutex mutex_;
};

TEST(Renderer, AStopLeavesWholeTilesDoneAndTheRestUntouched) {
    const Scene scene = small_scene("thesis/test6.xml", 72);
    const RenderResult whole = render(scene, on_threads(2));
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
    std::stop_source stop;
    StopAfter stopping(sink, stop, 3);
    TileQueue source(context.tiles());
    RenderOptions options = on_threads(2);
    options.stop = stop.get_token();
    render_tiles(context, request, source, stopping, options);

    // The other worker abandons the tile it holds when the stop comes (unless it finished it
    // first), and takes no other.
    const std::vector<Tile> missing = sink.missing();
    const std::size_t done = context.tiles().size() - missing.size();
    EXPECT_GE(done, 3u);
    EXPECT_LE(done, 4u);
    RayCounts expected_rays;
    for (const Tile& t : context.tiles()) {
        const bool is_missing = std::find(missing.begin(), missing.end(), t) != missing.end();
        if (!is_missing) expected_rays += context.render_tile(t, request).rays;
        for (int y = t.y0; y < t.y1; ++y) {
            for (int x = t.x0; x < t.x1; ++x) {
                const Color want = is_missing ? Color{} : whole.image.at(x, y);
                ASSERT_EQ(sink.image().at(x, y), want) << x << "," << y;
            }
        }
    }
    expect_same_counts(sink.rays(), expected_rays);

    // Resumed from the finished tiles: the rest are rendered, and the image is the whole one.
    const RenderResult resumed = complete_render(context, request, sink, on_threads(2));
    EXPECT_TRUE(same_bits(resumed.image, whole.image));
    expect_same_counts(resumed.stats.rays, whole.stats.rays);
}

TEST(Renderer, AStopBeforeTheStartRendersNothingAndSaysSo) {
    const Scene scene = small_scene("thesis/test6.xml", 40);
    std::stop_source stop;
    stop.request_stop();
    RenderOptions options = on_threads(2);
    options.stop = stop.get_token();
    const RenderResult r = render(scene, options);
    EXPECT_EQ(r.unfinished, tile_grid(scene.settings.width, scene.settings.height));
    EXPECT_EQ(r.stats.rays.total(), 0u);
    EXPECT_EQ(r.stats.samples, 0u);
    EXPECT_TRUE(
        std::all_of(r.image.rgb.begin(), r.image.rgb.end(), [](float v) { return v == 0; }));
}

// Hands out the tiles of `tiles` one by one, requesting a stop right after handing out the
// `stop_at`-th (1-based), and records the tiles given back.
class StopWhileHandingOut final : public TileSource {
  public:
    StopWhileHandingOut(std::vector<Tile> tiles, std::stop_source stop, std::size_t stop_at)
        : queue_(std::move(tiles)), stop_(std::move(stop)), stop_at_(stop_at) {}
    std::optional<Tile> next() override {
        std::optional<Tile> t = queue_.next();
        if (t && ++handed_ == stop_at_) stop_.request_stop();
        return t;
    }
    std::size_t size() const override { return queue_.size(); }
    void give_back(const Tile& tile) override { given_back.push_back(tile); }

    std::vector<Tile> given_back;

  private:
    TileQueue queue_;
    std::stop_source stop_;
    std::size_t stop_at_;
    std::size_t handed_ = 0;
};

TEST(Renderer, ATileInHandWhenTheStopComesIsAbandonedAndGivenBack) {
    const Scene scene = small_scene("thesis/test6.xml", 72);
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
    std::stop_source stop;
    StopWhileHandingOut source(context.tiles(), stop, 2);
    RenderOptions options = on_threads(1);
    options.stop = stop.get_token();
    render_tiles(context, request, source, sink, options);
    ASSERT_EQ(source.given_back.size(), 1u);
    EXPECT_EQ(source.given_back[0], context.tiles()[1]);
    EXPECT_EQ(sink.tiles_done(), 1u);
    expect_same_counts(sink.rays(), context.render_tile(context.tiles()[0], request).rays);
}

// A point light 100 above the origin whose sampling the tests below instrument.
class PointAbove : public Light {
  public:
    PointAbove() : Light({1, 1, 1}, false) {}
    using Light::sample;
    Ball extent() const override { return {kAt, 0}; }
    bool is_point() const override { return true; }
    std::optional<double> intersect(const Ray&, Interval) const override { return std::nullopt; }

  protected:
    static LightSample towards(const Vec3& x) {
        const Vec3 to = kAt - x;
        return {normalize(to), length(to)};
    }

  private:
    static constexpr Vec3 kAt{0, 100, 0};
};

// A point light whose first sample requests a stop: the tile is left between two pixels.
class StoppingLight final : public PointAbove {
  public:
    explicit StoppingLight(std::stop_source stop) : stop_(std::move(stop)) {}
    LightSample sample(const Vec3& x, Vec2) const override {
        stop_.request_stop();
        return towards(x);
    }

  private:
    mutable std::stop_source stop_;
};

TEST(Renderer, AStopInsideATileAbandonsItBeforeItsNextPixel) {
    Scene scene = testing::floor_scene(16, 16);
    std::stop_source stop;
    scene.lights.clear();
    scene.lights.push_back(std::make_unique<StoppingLight>(stop));
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ASSERT_EQ(context.tiles().size(), 1u);
    EXPECT_FALSE(context.render_tile(context.tiles()[0], request, stop.get_token()));
    // Without a stop token the same tile renders whole.
    EXPECT_EQ(context.render_tile(context.tiles()[0], request).samples, 256u);
}

// A point light that cannot be sampled: every shading point's shadow ray throws.
class FailingLight final : public PointAbove {
  public:
    LightSample sample(const Vec3&, Vec2) const override { throw std::bad_alloc(); }
};

// A point light that throws on every thread but the first to sample it, and is slow on that
// one: on an image of one tile, the thread helping with it throws while its owner still works.
class FailingElsewhereLight final : public PointAbove {
  public:
    LightSample sample(const Vec3& x, Vec2) const override {
        {
            const std::lock_guard lock(mutex_);
            if (!first_) first_ = std::this_thread::get_id();
            if (*first_ != std::this_thread::get_id()) throw std::bad_alloc();
        }
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        return towards(x);
    }

  private:
    mutable std::mutex mutex_;
    mutable std::optional<std::thread::id> first_;
};

TEST(Renderer, AnExceptionOnAHelpingThreadReachesTheCallerAndLeavesNoOneWaiting) {
    Scene scene = testing::floor_scene(16, 16);
    scene.lights.clear();
    scene.lights.push_back(std::make_unique<FailingElsewhereLight>());
    ASSERT_EQ(RenderContext(scene).tiles().size(), 1u);
    EXPECT_THROW(render(scene, on_threads(2)), std::bad_alloc);
}

TEST(Renderer, AnExceptionInsideATileReachesTheCaller) {
    Scene scene = testing::floor_scene(48, 32);
    scene.lights.push_back(std::make_unique<FailingLight>());
    EXPECT_THROW(render(scene, on_threads(2)), std::bad_alloc);
}

// Counts the tiles handed out.
class CountingSource final : public TileSource {
  public:
    explicit CountingSource(std::vector<Tile> tiles) : queue_(std::move(tiles)) {}
    std::optional<Tile> next() override {
        auto tile = queue_.next();
        if (tile) ++handed_out;
        return tile;
    }
    std::size_t size() const override { return queue_.size(); }
    std::atomic<std::size_t> handed_out{0};

  private:
    TileQueue queue_;
};

// Fails on its second tile.
class FailingSink final : public TileSink {
  public:
    void add(TileBuffer) override {
        if (++added_ == 2) throw std::runtime_error("sink failed on tile 2");
    }

  private:
    std::atomic<int> added_{0};
};

TEST(Renderer, AnExceptionInAWorkerStopsTheOthersAndIsRethrown) {
    const Scene scene = testing::floor_scene(160, 64);
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ASSERT_EQ(context.tiles().size(), 40u);
    for (const int threads : {1, 2}) {
        CountingSource source(context.tiles());
        FailingSink sink;
        try {
            render_tiles(context, request, source, sink, on_threads(threads));
            ADD_FAILURE() << "no exception";
        } catch (const std::runtime_error& e) {
            EXPECT_STREQ(e.what(), "sink failed on tile 2");
        }
        // Alone, the worker takes no tile after the one that failed. With two, the other one
        // stops too, though when it sees the failure depends on the timing.
        if (threads == 1) {
            EXPECT_EQ(source.handed_out.load(), 2u);
        }
        EXPECT_LT(source.handed_out.load(), context.tiles().size());
    }
}

TEST(Renderer, ProgressEndsAtOneAndCountsTilesAlreadyDone) {
    const Scene scene = small_scene("thesis/test6.xml", 40);
    const RenderContext context(scene);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
    const std::size_t n = context.tiles().size();
    ASSERT_EQ(n, 6u);
    for (std::size_t i = 0; i < 3; ++i) sink.add(context.render_tile(context.tiles()[i], request));
    std::vector<double> reported;
    RenderOptions options = on_threads(1);
    options.on_progress = [&](double done) { reported.push_back(done); };
    complete_render(context, request, sink, options);
    ASSERT_FALSE(reported.empty());
    EXPECT_GE(reported.front(), 0.5);
    EXPECT_EQ(reported.back(), 1.0);
}

// Progress moves within a tile: a one-tile render of 16,384 samples a pixel (seconds) reports a
// share above 0 and below 1 while the tile is in hand, which is stopped once it does.
TEST(Renderer, ProgressCountsThePixelsOfTheTileInHand) {
    Scene scene = small_scene("thesis/test6.xml", 16);
    scene.settings.samples = 16384;
    const RenderContext context(scene);
    ASSERT_EQ(context.tiles().size(), 1u);
    RenderRequest request = RenderRequest::whole_image(scene.settings);
    request.estimate_error = false;
    for (const int threads : {1, 2}) {
        SCOPED_TRACE(threads);
        ImageSink sink(scene.settings.width, scene.settings.height, context.tiles());
        std::stop_source stop;
        std::vector<double> reported;
        RenderOptions options = on_threads(threads);
        options.stop = stop.get_token();
        options.on_progress = [&](double done) {
            reported.push_back(done);
            if (done > 0 && done < 1) stop.request_stop();
        };
        complete_render(context, request, sink, options);
        EXPECT_TRUE(std::ranges::any_of(reported, [](double d) { return d > 0 && d < 1; }));
        EXPECT_EQ(sink.tiles_done(), 0u);
    }
}

}  // namespace
}  // namespace drt
