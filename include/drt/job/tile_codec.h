// One finished tile's buffer as bytes: what the processes of an MPI job send each other, and
// what a checkpoint file stores for each tile. Little-endian whatever the host, so the bytes
// move between machines, and exact: a decoded tile has every bit and count of the encoded one.
// A change to the layout is a new checkpoint format (checkpoint.cpp numbers them).
#pragma once

#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "drt/render/tile.h"
#include "drt/scene/scene.h"

namespace drt {

// Bytes that are not a tile of the grid expected; what() says which problem.
class TileCodecError : public std::runtime_error {
  public:
    enum class Problem {
        truncated,     // the bytes end inside the tile
        unknown_tile,  // its index is not a tile of the grid, or one already decoded
        bytes_after,   // a message holds more than its one tile
    };
    explicit TileCodecError(Problem problem);
    Problem problem() const { return problem_; }

  private:
    Problem problem_;
};

// Whether a tile's bytes hold its count of diffuse rays. Only the path integrator traces them, so
// only a path render's tiles carry the count and a distributed render's keep the layout without
// it. Writer and reader agree from the scene, which every process of a render knows.
enum class DiffuseCount { kOmitted, kCarried };

// The layout of the tiles of a render with these settings.
DiffuseCount diffuse_count_for(const RenderSettings& settings);

// Appends `tile`'s bytes to `bytes`. Omitting the diffuse count requires it to be 0. A render
// with AOVs (aov.h) appends each pixel's `aov_channels` values, which the tile must hold; the
// layout without them is unchanged.
void append_tile(std::vector<unsigned char>& bytes, const TileBuffer& tile, DiffuseCount diffuse,
                 std::size_t aov_channels = 0);
std::vector<unsigned char> encode_tile(const TileBuffer& tile, DiffuseCount diffuse,
                                       std::size_t aov_channels = 0);

// Decodes the tile at the front of `bytes` and drops its bytes from the view. The tile must be
// one of `grid` not yet marked in `seen` (grid.size() flags), which it then marks.
TileBuffer take_tile(std::span<const unsigned char>& bytes, std::span<const Tile> grid,
                     std::vector<bool>& seen, DiffuseCount diffuse, std::size_t aov_channels = 0);

// A message of exactly one tile of `grid`.
TileBuffer decode_tile(std::span<const unsigned char> bytes, std::span<const Tile> grid,
                       DiffuseCount diffuse, std::size_t aov_channels = 0);

}  // namespace drt
