// What one finished tile costs an MPI job's leader besides the transport: decoding the message
// (the checkpoint's tile format) and adding it to the image, which bounds how many workers one
// leader can keep up with. Tiles are taken in turn from a whole encoded image, so each arrives
// in memory the cache has not seen lately, as a message from another process would.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <optional>
#include <vector>

#include "drt/job/tile_codec.h"
#include "drt/render/tile.h"

namespace drt::bench {
namespace {

constexpr int kWidth = 800, kHeight = 600;

// A tile's buffer with every field filled, as a 100-sample render leaves it.
TileBuffer full_tile(const Tile& t) {
    TileBuffer b{t, Image(t.width(), t.height()), {}, Image(t.width(), t.height()), {}, {}, 0, 0,
                 {}};
    for (int y = 0; y < t.height(); ++y) {
        for (int x = 0; x < t.width(); ++x) {
            const float v = float(t.index % 97) / 97.0F + float(x * y) * 1e-4F;
            b.pixels.set(x, y, {v, v * 0.5F, v * 0.25F});
            b.spread.set(x, y, {v * 1e-3F, v * 2e-3F, v * 3e-3F});
            b.pixel_samples.push_back(100);
        }
    }
    b.samples = 100 * b.pixel_samples.size();
    b.rays.camera = b.samples;
    b.rays.shadow = 3 * b.samples;
    return b;
}

struct Messages {
    std::vector<Tile> grid = tile_grid(kWidth, kHeight);
    std::vector<std::vector<unsigned char> > encoded;
    Messages() {
        for (const Tile& t : grid)
            encoded.push_back(encode_tile(full_tile(t), DiffuseCount::kOmitted));
    }
};

void BM_TileMessageDecode(benchmark::State& state) {
    const Messages m;
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(decode_tile(m.encoded[i], m.grid, DiffuseCount::kOmitted));
        i = (i + 1) % m.grid.size();
    }
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(m.encoded[0].size()));
}
BENCHMARK(BM_TileMessageDecode);

// Decoded and added to the image: what the leader's communication thread does per message.
void BM_TileMessageDecodeAndAssemble(benchmark::State& state) {
    const Messages m;
    std::optional<ImageSink> sink;
    std::size_t i = 0;
    for (auto _ : state) {
        if (i == 0) {  // a fresh image once every tile is in: a tile may not come twice
            state.PauseTiming();
            sink.emplace(kWidth, kHeight, m.grid);
            state.ResumeTiming();
        }
        sink->add(decode_tile(m.encoded[i], m.grid, DiffuseCount::kOmitted));
        i = (i + 1) % m.grid.size();
    }
}
BENCHMARK(BM_TileMessageDecodeAndAssemble);

}  // namespace
}  // namespace drt::bench
