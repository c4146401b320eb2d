// The tile codec (tile_codec.h): exact round trips, and damaged messages refused as the codec's
// own error, whoever sent them.
#include "drt/job/tile_codec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <stdexcept>
#include <vector>

#include "drt/job/checkpoint.h"

namespace drt {
namespace {

TileBuffer filled_tile(const Tile& tile) {
    TileBuffer t;
    t.tile = tile;
    t.pixels = Image(tile.width(), tile.height());
    for (std::size_t i = 0; i < t.pixels.rgb.size(); ++i) t.pixels.rgb[i] = 0.5f + float(i) / 3;
    t.pixel_samples.assign(static_cast<std::size_t>(tile.width()) * tile.height(), 7);
    t.spread = Image(tile.width(), tile.height());
    for (std::size_t i = 0; i < t.spread.rgb.size(); ++i) t.spread.rgb[i] = -float(i) * 1e-3f;
    t.error_sums = {0.25, 1e-300, 9, 4.5};
    t.rays = {1, 2, 3, 4};
    t.samples = 7 * t.pixel_samples.size();
    t.converged = 2;
    return t;
}

TileCodecError::Problem problem_of(const std::vector<unsigned char>& bytes,
                                   const std::vector<Tile>& grid) {
    try {
        decode_tile(bytes, grid, DiffuseCount::kOmitted);
    } catch (const TileCodecError& e) {
        return e.problem();
    }
    ADD_FAILURE() << "decoded";
    return TileCodecError::Problem::bytes_after;
}

TEST(TileCodec, ATileComesBackWithEveryBitAndCount) {
    const std::vector<Tile> grid = tile_grid(40, 28);  // a 3 x 2 grid with narrower edge tiles
    const TileBuffer sent = filled_tile(grid[5]);
    const std::vector<unsigned char> bytes = encode_tile(sent, DiffuseCount::kOmitted);
    // The index, 8 x 12 pixels of three floats, their counts and spreads, 4 doubles, 6 counts.
    EXPECT_EQ(bytes.size(), 8u + 96 * (12 + 4 + 12) + 4 * 8 + 6 * 8);
    const TileBuffer got = decode_tile(bytes, grid, DiffuseCount::kOmitted);
    EXPECT_EQ(got.tile, grid[5]);
    EXPECT_EQ(got.pixels.rgb, sent.pixels.rgb);
    EXPECT_EQ(got.pixel_samples, sent.pixel_samples);
    EXPECT_EQ(got.spread.rgb, sent.spread.rgb);
    EXPECT_EQ(got.error_sums, sent.error_sums);
    EXPECT_EQ(got.rays.total(), 10u);
    EXPECT_EQ(got.samples, 672u);
    EXPECT_EQ(got.converged, 2u);
}

// A render with AOVs: each pixel's values follow the layout without them, exactly.
TEST(TileCodec, AovsTravelAfterTheTileAndOnlyWhenTheLayoutHasThem) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    TileBuffer sent = filled_tile(grid[2]);
    const std::size_t without = encode_tile(sent, DiffuseCount::kOmitted).size();
    sent.aovs.resize(7 * sent.pixel_samples.size());
    for (std::size_t i = 0; i < sent.aovs.size(); ++i) sent.aovs[i] = float(i) * 0.125f - 3;
    const std::vector<unsigned char> bytes = encode_tile(sent, DiffuseCount::kOmitted, 7);
    EXPECT_EQ(bytes.size(), without + 4 * sent.aovs.size());
    EXPECT_EQ(decode_tile(bytes, grid, DiffuseCount::kOmitted, 7).aovs, sent.aovs);
    EXPECT_THROW(encode_tile(sent, DiffuseCount::kOmitted), std::invalid_argument);
    EXPECT_THROW(decode_tile(bytes, grid, DiffuseCount::kOmitted, 8), TileCodecError);
}

TEST(TileCodec, ATruncatedMessageIsTheCodecsErrorNotACheckpoints) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    const std::vector<unsigned char> bytes =
        encode_tile(filled_tile(grid[1]), DiffuseCount::kOmitted);
    for (std::size_t n = 0; n < bytes.size(); n += 97) {
        const std::vector<unsigned char> cut(bytes.begin(), bytes.begin() + n);
        EXPECT_EQ(problem_of(cut, grid), TileCodecError::Problem::truncated) << n;
    }
    const std::vector<unsigned char> last_missing(bytes.begin(), bytes.end() - 1);
    EXPECT_EQ(problem_of(last_missing, grid), TileCodecError::Problem::truncated);
    try {
        decode_tile(last_missing, grid, DiffuseCount::kOmitted);
    } catch (const CheckpointError&) {
        ADD_FAILURE() << "a tile message is no checkpoint";
    } catch (const TileCodecError& e) {
        EXPECT_STREQ(e.what(), "truncated tile");
    }
}

TEST(TileCodec, AnIndexOffTheGridOrAByteTooManyIsRefused) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    std::vector<unsigned char> bytes = encode_tile(filled_tile(grid[2]), DiffuseCount::kOmitted);
    std::vector<unsigned char> longer = bytes;
    longer.push_back(0);
    EXPECT_EQ(problem_of(longer, grid), TileCodecError::Problem::bytes_after);
    bytes[0] = 6;  // one past the last tile, the index being little-endian
    EXPECT_EQ(problem_of(bytes, grid), TileCodecError::Problem::unknown_tile);
    bytes[0] = 2;
    bytes[7] = 1;  // the top byte: 2^56 + 2
    EXPECT_EQ(problem_of(bytes, grid), TileCodecError::Problem::unknown_tile);
}

TEST(TileCodec, TilesTakenOneAfterAnotherComeOnceEach) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    std::vector<unsigned char> bytes;
    append_tile(bytes, filled_tile(grid[3]), DiffuseCount::kOmitted);
    append_tile(bytes, filled_tile(grid[0]), DiffuseCount::kOmitted);
    append_tile(bytes, filled_tile(grid[3]), DiffuseCount::kOmitted);
    std::span<const unsigned char> rest = bytes;
    std::vector<bool> seen(grid.size(), false);
    EXPECT_EQ(take_tile(rest, grid, seen, DiffuseCount::kOmitted).tile, grid[3]);
    EXPECT_EQ(take_tile(rest, grid, seen, DiffuseCount::kOmitted).tile, grid[0]);
    EXPECT_EQ(rest.size(), encode_tile(filled_tile(grid[3]), DiffuseCount::kOmitted).size());
    try {
        take_tile(rest, grid, seen, DiffuseCount::kOmitted);
        ADD_FAILURE() << "a tile taken twice";
    } catch (const TileCodecError& e) {
        EXPECT_EQ(e.problem(), TileCodecError::Problem::unknown_tile);
    }
    EXPECT_EQ(seen, (std::vector<bool>{true, false, false, true, false, false}));
}

// A path render's tiles carry their diffuse ray count; a distributed render's layout has no room
// for one, and refuses to drop a count that is not 0.
TEST(TileCodec, OnlyTheCarriedLayoutHoldsTheDiffuseCount) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    TileBuffer sent = filled_tile(grid[2]);
    const std::size_t without = encode_tile(sent, DiffuseCount::kOmitted).size();
    sent.rays.diffuse = 5;
    const std::vector<unsigned char> bytes = encode_tile(sent, DiffuseCount::kCarried);
    EXPECT_EQ(bytes.size(), without + 8);
    const TileBuffer got = decode_tile(bytes, grid, DiffuseCount::kCarried);
    EXPECT_EQ(got.rays.diffuse, 5u);
    EXPECT_EQ(got.rays.total(), 15u);
    EXPECT_EQ(got.samples, sent.samples);
    EXPECT_EQ(got.converged, 2u);
    EXPECT_THROW(encode_tile(sent, DiffuseCount::kOmitted), std::invalid_argument);
    // Read in the other layout, the bytes are a tile of the wrong length.
    EXPECT_EQ(problem_of(bytes, grid), TileCodecError::Problem::bytes_after);
}

// A checkpoint holds its tiles as the codec encodes them, so a tile's bytes are the same in a
// file and in a message.
TEST(TileCodec, ACheckpointHoldsEachTileAsItsMessage) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    const TileBuffer tile = filled_tile(grid[4]);
    const std::vector<unsigned char> message = encode_tile(tile, DiffuseCount::kOmitted);
    const RenderIdentity id{"1.0", {{"s.xml", 1}}, 2, 40, 28, grid.size()};
    const std::vector<unsigned char> file = encode_checkpoint(id, std::vector<TileBuffer>{tile});
    // The tile ends just before the 8-byte checksum.
    ASSERT_GT(file.size(), message.size() + 8);
    const auto at = file.end() - 8 - static_cast<std::ptrdiff_t>(message.size());
    EXPECT_TRUE(std::equal(message.begin(), message.end(), at));
}

}  // namespace
}  // namespace drt
