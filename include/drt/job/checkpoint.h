// Checkpoints: the finished tiles of a render kept in a file, so that running the same command
// again after an interrupt, a crash or a killed job resumes where the render stopped and ends
// with the very bits of an uninterrupted render. A tile's buffer is a pure function of the scene,
// the options and the tile, so a resumed tile is exactly the tile a new render would make.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "drt/job/tile_codec.h"
#include "drt/render/aov.h"
#include "drt/render/renderer.h"
#include "drt/render/tile.h"
#include "drt/scene/scene.h"

namespace drt {

// A checkpoint that cannot be read or belongs to another render; the message names the file.
class CheckpointError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// One file a render reads: its name as the run that read it gave it, for messages, and a hash of
// its bytes. Only the bytes count: the same files reached from another folder are the same render.
struct FileFingerprint {
    std::string name;
    std::uint64_t hash = 0;

    friend bool operator==(const FileFingerprint& a, const FileFingerprint& b) {
        return a.hash == b.hash;
    }
};

// What a render's pixels depend on. A checkpoint resumes only a render with the same identity.
struct RenderIdentity {
    std::string version;  // drt's
    // The scene file, then every file it reads (its meshes' OBJ files), in the order read.
    std::vector<FileFingerprint> files;
    std::uint64_t options = 0;  // hash of every setting that shapes the image, the seed included
    int width = 0, height = 0;
    std::uint64_t tiles = 0;  // how many tiles the image is cut into
    // Whether its tiles count diffuse rays: the file's format (4 without, 5 with).
    DiffuseCount diffuse = DiffuseCount::kOmitted;
    // The AOV values each pixel of a tile carries (--aov): formats 6 (without diffuse counts)
    // and 7 (with) hold them; 0 keeps formats 4 and 5.
    std::uint32_t aov_channels = 0;

    friend bool operator==(const RenderIdentity&, const RenderIdentity&) = default;
};

// A 64-bit hash of bytes, for fingerprints and for the checksum that catches a damaged file.
std::uint64_t hash_bytes(std::span<const unsigned char> bytes);

// One hash of the bytes of all `files`, in order; throws CheckpointError when one cannot be read.
std::uint64_t hash_files(std::span<const std::filesystem::path> files);

// `files` are the scene file and whatever it reads; throws CheckpointError when one cannot be
// read. Options that only change how the work is done (threads, processes, output, progress)
// are not part of the identity.
RenderIdentity identify_render(std::span<const std::filesystem::path> files,
                               const RenderSettings& settings,
                               const std::optional<AdaptiveSampling>& adaptive, std::uint64_t tiles,
                               std::span<const Aov> aovs = {});

struct Checkpoint {
    RenderIdentity identity;
    std::vector<TileBuffer> tiles;  // finished, in any order
};

// The file's bytes: a header, the identity, each tile as tile_codec.h encodes it, and a checksum
// of all that.
std::vector<unsigned char> encode_checkpoint(const RenderIdentity& identity,
                                             std::span<const TileBuffer> tiles);

// Throws CheckpointError (naming `file`) for bytes that are not a whole, undamaged checkpoint
// whose tiles lie on `grid`. Either format is read; a refusal of another format names the one a
// render of tiles laid out as `expected` writes.
Checkpoint decode_checkpoint(std::span<const unsigned char> bytes, std::span<const Tile> grid,
                             const std::filesystem::path& file, DiffuseCount expected);

// The checkpoint in `file` for the render `expected` over `grid`; nothing when there is no such
// file. Throws CheckpointError when the file cannot be read, is damaged or truncated, or was
// made by another render (the message says which part of the identity differs).
std::optional<Checkpoint> read_checkpoint(const std::filesystem::path& file,
                                          const RenderIdentity& expected,
                                          std::span<const Tile> grid);

// The resumed tile to render again before resuming, so that a checkpoint written by a build of
// drt that renders the scene otherwise is caught (the identity's version does not change with
// every build): the one that took the most rays, which exercises the most of the renderer (the
// lowest index among equals). `tiles` must not be empty.
const TileBuffer& tile_to_render_again(std::span<const TileBuffer> tiles);

// Throws CheckpointError (naming `file`) unless `again`, `kept` rendered again by this build, has
// every bit and count of it.
void check_rendered_alike(const std::filesystem::path& file, const TileBuffer& kept,
                          const TileBuffer& again, DiffuseCount diffuse, std::size_t aov_channels);

// Passes finished tiles on to another sink and keeps them, writing the checkpoint file
// atomically whenever `interval` has passed since the last write (as a tile arrives), and on
// request. Only a requested write reports failure: a periodic one is simply tried again.
class CheckpointSink final : public TileSink {
  public:
    // `resumed`: the tiles of the checkpoint being resumed, passed on to `next` at once.
    CheckpointSink(TileSink& next, std::filesystem::path file, RenderIdentity identity,
                   std::chrono::duration<double> interval, std::vector<TileBuffer> resumed = {});

    void add(TileBuffer buffer) override;
    // Writes the file now; throws CheckpointError when it cannot.
    void write();
    // The finished tiles so far, as the file would hold them.
    std::size_t tiles_done() const;

  private:
    TileSink& next_;
    std::filesystem::path file_;
    RenderIdentity identity_;
    std::chrono::duration<double> interval_;
    std::chrono::steady_clock::time_point last_write_ = std::chrono::steady_clock::now();
    std::vector<TileBuffer> tiles_;
    mutable std::mutex mutex_;  // guards tiles_ and last_write_
    std::mutex writing_;        // one write at a time
};

}  // namespace drt
