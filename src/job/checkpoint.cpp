#include "drt/job/checkpoint.h"

#include <bit>
#include <cstring>
#include <iterator>
#include <sstream>
#include <system_error>

#include "drt/job/tile_codec.h"
#include "drt/util/atomic_file.h"
#include "drt/util/byte_order.h"
#include "drt/util/file_reader.h"
#include "drt/util/limits.h"
#include "drt/util/rng.h"
#include "drt/util/text.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<unsigned char>;

// "DRTCKPT" and a format number, raised whenever the layout changes (the tile codec's included):
// a reader refuses a format it does not know instead of guessing. Format 5 is format 4 with each
// tile's diffuse ray count (DiffuseCount::kCarried): a path render's; a distributed render writes
// format 4. Formats 6 and 7 are 4 and 5 with AOVs (--aov): the count of each pixel's AOV values
// after the tile count, and the values in each tile.
constexpr char kMagic[8] = {'D', 'R', 'T', 'C', 'K', 'P', 'T', '4'};
constexpr char kFormatWithoutDiffuse = '4', kFormatWithDiffuse = '5';
constexpr char kAovFormatWithoutDiffuse = '6', kAovFormatWithDiffuse = '7';

char format_of(DiffuseCount diffuse, std::uint32_t aov_channels) {
    if (aov_channels > 0) {
        return diffuse == DiffuseCount::kCarried ? kAovFormatWithDiffuse : kAovFormatWithoutDiffuse;
    }
    return diffuse == DiffuseCount::kCarried ? kFormatWithDiffuse : kFormatWithoutDiffuse;
}

// The longest version string a reader accepts, so a damaged length cannot ask for gigabytes.
constexpr std::uint32_t kMaxVersionLength = 256;
// Likewise for a file's name (PATH_MAX on Linux).
constexpr std::uint32_t kMaxNameLength = 4096;

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
    throw CheckpointError(file.string() + ": " + what);
}

class Writer {
  public:
    void u32(std::uint32_t v) { append_little_endian(bytes, v, 4); }
    void u64(std::uint64_t v) { append_little_endian(bytes, v, 8); }
    void text(const std::string& s) {
        u32(static_cast<std::uint32_t>(s.size()));
        bytes.insert(bytes.end(), s.begin(), s.end());
    }
    Bytes bytes;
};

class Reader {
  public:
    Reader(std::span<const unsigned char> bytes, const fs::path& file)
        : bytes_(bytes, Truncated{&file}), file_(file) {}
    std::uint32_t u32() { return bytes_.u32(); }
    std::uint64_t u64() { return bytes_.u64(); }
    std::string text(std::uint32_t max) {
        const std::uint32_t n = u32();
        if (n > max) fail(file_, "damaged checkpoint (bad text length)");
        const auto text = bytes_.take(n);
        return {text.begin(), text.end()};
    }
    // A tile of `grid`, not one of those marked in `seen`, which it then marks.
    TileBuffer tile(std::span<const Tile> grid, std::vector<bool>& seen, DiffuseCount diffuse,
                    std::uint32_t aov_channels) {
        std::span<const unsigned char> rest = bytes_.rest();
        try {
            TileBuffer t = take_tile(rest, grid, seen, diffuse, aov_channels);
            bytes_.take(left() - rest.size());
            return t;
        } catch (const TileCodecError& e) {
            if (e.problem() == TileCodecError::Problem::truncated)
                fail(file_, "truncated checkpoint");
            fail(file_, "damaged checkpoint (bad tile index)");
        }
    }
    std::size_t left() const { return bytes_.rest().size(); }

  private:
    struct Truncated {
        const fs::path* file;
        void operator()() const { fail(*file, "truncated checkpoint"); }
    };
    ByteReader<Truncated> bytes_;
    const fs::path& file_;
};

// A format byte as printed: the digit, or its code when it is not one.
std::string printable_format(unsigned char c) {
    if (c >= '0' && c <= '9') return std::string(1, static_cast<char>(c));
    return "byte " + std::to_string(c);
}

// A checkpoint of the largest image the limits allow fits the memory budget, as do the scene and
// mesh files whose fingerprints it holds.
Bytes read_all(const fs::path& file) {
    try {
        return read_binary_file(file, kMemoryBudget);
    } catch (const FileReadError& e) {
        switch (e.problem()) {
            case FileProblem::cannot_open:
                fail(file, "cannot open file: " + e.reason());
            case FileProblem::too_large:
                fail(file,
                     "file larger than the " + std::to_string(kMemoryBudget >> 20) + " MiB limit");
            default:
                fail(file, "cannot read file");
        }
    }
}

// What differs between the files a checkpoint's render read (`got`) and this render's.
std::string files_differing(const std::vector<FileFingerprint>& got,
                            const std::vector<FileFingerprint>& expected) {
    if (got.empty() || expected.empty() || !(got[0] == expected[0])) {
        return "another scene file (its contents differ)";
    }
    if (got.size() != expected.size()) {
        return "a scene reading another number of files (" + std::to_string(got.size() - 1) +
               ", not " + std::to_string(expected.size() - 1) + ")";
    }
    for (std::size_t i = 1; i < got.size(); ++i) {
        if (!(got[i] == expected[i])) {
            return "another version of " + printable(expected[i].name) +
                   " (a file the scene reads: its contents differ)";
        }
    }
    return "other files";
}

// Doubles by their bits, so that two settings that print alike but differ still differ.
std::string exact(double v) {
    return std::to_string(std::bit_cast<std::uint64_t>(v));
}

}  // namespace

std::uint64_t hash_bytes(std::span<const unsigned char> bytes) {
    std::uint64_t h = hash_of(bytes.size());
    std::size_t i = 0;
    for (; i + 8 <= bytes.size(); i += 8) {
        std::uint64_t word = 0;
        for (int b = 0; b < 8; ++b) word |= std::uint64_t{bytes[i + b]} << (8 * b);
        h = hash_combine(h, word);
    }
    std::uint64_t tail = 0;
    for (int b = 0; i < bytes.size(); ++i, ++b) tail |= std::uint64_t{bytes[i]} << (8 * b);
    return hash_combine(h, tail);
}

std::uint64_t hash_files(std::span<const fs::path> files) {
    std::uint64_t h = files.size();
    for (const fs::path& f : files) h = hash_combine(h, hash_bytes(read_all(f)));
    return h;
}

RenderIdentity identify_render(std::span<const fs::path> files, const RenderSettings& settings,
                               const std::optional<AdaptiveSampling>& adaptive, std::uint64_t tiles,
                               std::span<const Aov> aovs) {
    RenderIdentity id;
    id.version = DRT_VERSION;
    for (const fs::path& f : files) {
        try {
            id.files.push_back({f.string(), hash_bytes(read_all(f))});
        } catch (const CheckpointError& e) {
            throw CheckpointError(std::string(e.what()) + " (needed for the checkpoint)");
        }
    }
    std::ostringstream options;
    options << "width " << settings.width << " height " << settings.height << " samples "
            << settings.samples << " shadow_rays " << settings.shadow_rays << " max_depth "
            << settings.max_depth << " glossy_rays " << settings.glossy_rays << " seed "
            << settings.seed << " sampler " << settings.sampler << " pixel_plane_unit "
            << exact(settings.pixel_plane_unit);
    // Only when set, so that checkpoints of renders without it keep their identity.
    if (settings.clamp > 0) options << " clamp " << exact(settings.clamp);
    if (adaptive) {
        options << " noise_threshold " << exact(adaptive->noise_threshold) << " min_spp "
                << adaptive->min_samples;
    }
    // Only a render with AOVs names them, so that other renders keep their identity.
    if (!aovs.empty()) {
        options << " aovs";
        for (const std::string& name : aov_channel_names(aovs)) options << " " << name;
    }
    const std::string text = options.str();
    id.options = hash_bytes({reinterpret_cast<const unsigned char*>(text.data()), text.size()});
    id.width = settings.width;
    id.height = settings.height;
    id.tiles = tiles;
    id.diffuse = diffuse_count_for(settings);
    id.aov_channels = static_cast<std::uint32_t>(aov_channel_count(aovs));
    return id;
}

std::vector<unsigned char> encode_checkpoint(const RenderIdentity& id,
                                             std::span<const TileBuffer> tiles) {
    Writer w{Bytes(std::begin(kMagic), std::end(kMagic))};
    w.bytes.back() = static_cast<unsigned char>(format_of(id.diffuse, id.aov_channels));
    w.text(id.version);
    w.u64(id.files.size());
    for (const FileFingerprint& f : id.files) {
        w.text(f.name);
        w.u64(f.hash);
    }
    w.u64(id.options);
    w.u32(static_cast<std::uint32_t>(id.width));
    w.u32(static_cast<std::uint32_t>(id.height));
    w.u64(id.tiles);
    w.u64(tiles.size());
    if (id.aov_channels > 0) w.u32(id.aov_channels);
    for (const TileBuffer& t : tiles) append_tile(w.bytes, t, id.diffuse, id.aov_channels);
    w.u64(hash_bytes(w.bytes));
    return std::move(w.bytes);
}

namespace {

[[noreturn]] void fail_another_render(const fs::path& file, const std::string& differs) {
    fail(file, "checkpoint of another render: made by " + differs +
                   "; not resumed and nothing written (delete it or name another "
                   "--checkpoint file)");
}

std::string another_size(const RenderIdentity& id) {
    return "another image size (" + std::to_string(id.width) + "x" + std::to_string(id.height) +
           ")";
}

}  // namespace

Checkpoint decode_checkpoint(std::span<const unsigned char> bytes, std::span<const Tile> grid,
                             const fs::path& file, DiffuseCount expected) {
    if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic - 1) != 0) {
        fail(file, "not a drt checkpoint");
    }
    const unsigned char format = bytes[sizeof kMagic - 1];
    if (format != kFormatWithoutDiffuse && format != kFormatWithDiffuse &&
        format != kAovFormatWithoutDiffuse && format != kAovFormatWithDiffuse) {
        fail(file, std::string("checkpoint format ") + printable_format(format) +
                       " of another drt version, this one reads format " + format_of(expected, 0) +
                       ": not resumed and nothing written (delete it or name another "
                       "--checkpoint file)");
    }
    if (bytes.size() < sizeof kMagic + 8) fail(file, "truncated checkpoint");
    const auto body = bytes.first(bytes.size() - 8);
    Reader tail(bytes.last(8), file);
    if (tail.u64() != hash_bytes(body)) {
        fail(file, "damaged or truncated checkpoint (checksum does not match)");
    }
    Reader r(body.subspan(sizeof kMagic), file);
    Checkpoint c;
    RenderIdentity& id = c.identity;
    id.diffuse = format == kFormatWithDiffuse || format == kAovFormatWithDiffuse
                     ? DiffuseCount::kCarried
                     : DiffuseCount::kOmitted;
    id.version = r.text(kMaxVersionLength);
    const std::uint64_t files = r.u64();
    // Each takes at least 12 bytes, so a damaged count soon runs out of file.
    for (std::uint64_t i = 0; i < files; ++i) {
        FileFingerprint& f = id.files.emplace_back();
        f.name = r.text(kMaxNameLength);
        f.hash = r.u64();
    }
    id.options = r.u64();
    id.width = static_cast<int>(r.u32());
    id.height = static_cast<int>(r.u32());
    id.tiles = r.u64();
    // The tiles are decoded against this image's grid: a checkpoint of another size is refused
    // as such first, even where its grid has as many tiles.
    int grid_width = 0, grid_height = 0;
    for (const Tile& t : grid)
        grid_width = std::max(grid_width, t.x1), grid_height = std::max(grid_height, t.y1);
    if (id.tiles != grid.size() || id.width != grid_width || id.height != grid_height) {
        fail_another_render(file, another_size(id));
    }
    const std::uint64_t count = r.u64();
    if (count > grid.size()) fail(file, "damaged checkpoint (more tiles than the image has)");
    if (format == kAovFormatWithoutDiffuse || format == kAovFormatWithDiffuse) {
        id.aov_channels = r.u32();
        if (id.aov_channels == 0 || id.aov_channels > 7) {
            fail(file, "damaged checkpoint (bad AOV channel count)");
        }
    }
    std::vector<bool> seen(grid.size(), false);
    for (std::uint64_t i = 0; i < count; ++i) {
        c.tiles.push_back(r.tile(grid, seen, id.diffuse, id.aov_channels));
    }
    if (r.left() != 0) fail(file, "damaged checkpoint (bytes after the last tile)");
    return c;
}

const TileBuffer& tile_to_render_again(std::span<const TileBuffer> tiles) {
    const TileBuffer* chosen = &tiles.front();
    for (const TileBuffer& t : tiles) {
        const std::uint64_t rays = t.rays.total(), most = chosen->rays.total();
        if (rays > most || (rays == most && t.tile.index < chosen->tile.index)) chosen = &t;
    }
    return *chosen;
}

void check_rendered_alike(const fs::path& file, const TileBuffer& kept, const TileBuffer& again,
                          DiffuseCount diffuse, std::size_t aov_channels) {
    if (encode_tile(kept, diffuse, aov_channels) != encode_tile(again, diffuse, aov_channels)) {
        fail_another_render(file, "a drt that renders this scene differently (tile " +
                                      std::to_string(kept.tile.index) +
                                      ", rendered again, differs)");
    }
}

std::optional<Checkpoint> read_checkpoint(const fs::path& file, const RenderIdentity& expected,
                                          std::span<const Tile> grid) {
    std::error_code ec;
    const fs::file_status status = fs::status(file, ec);
    if (status.type() == fs::file_type::not_found) return std::nullopt;
    if (ec) fail(file, "cannot examine file: " + ec.message());
    if (status.type() != fs::file_type::regular) fail(file, "not a regular file");
    Checkpoint c = decode_checkpoint(read_all(file), grid, file, expected.diffuse);
    const RenderIdentity& got = c.identity;
    std::string differs;
    if (got.version != expected.version) {
        differs = "drt " + got.version + ", not drt " + expected.version;
    } else if (got.files != expected.files) {
        differs = files_differing(got.files, expected.files);
    } else if (got.diffuse != expected.diffuse) {
        differs = "the other integrator (its format counts diffuse rays differently)";
    } else if (got.width != expected.width || got.height != expected.height) {
        differs = another_size(got);
    } else if (got.options != expected.options || got.tiles != expected.tiles ||
               got.aov_channels != expected.aov_channels) {
        differs = "other options (samples, seed, sampler or another setting differs)";
    }
    if (!differs.empty()) fail_another_render(file, differs);
    return c;
}

CheckpointSink::CheckpointSink(TileSink& next, fs::path file, RenderIdentity identity,
                               std::chrono::duration<double> interval,
                               std::vector<TileBuffer> resumed)
    : next_(next),
      file_(std::move(file)),
      identity_(std::move(identity)),
      interval_(interval),
      tiles_(std::move(resumed)) {
    for (const TileBuffer& t : tiles_) next_.add(t);
}

void CheckpointSink::add(TileBuffer buffer) {
    next_.add(buffer);
    bool due = false;
    {
        const std::lock_guard lock(mutex_);
        tiles_.push_back(std::move(buffer));
        const auto now = std::chrono::steady_clock::now();
        if (now - last_write_ >= interval_) {
            last_write_ = now;
            due = true;
        }
    }
    if (!due) return;
    // A write that fails on the way (a signal removes the temporary file it was writing) is
    // tried again at the next interval and when the render stops, where a failure is reported.
    try {
        write();
    } catch (const CheckpointError&) {
    }
}

std::size_t CheckpointSink::tiles_done() const {
    const std::lock_guard lock(mutex_);
    return tiles_.size();
}

void CheckpointSink::write() {
    const std::lock_guard lock(writing_);
    std::vector<unsigned char> bytes;
    {
        const std::lock_guard tiles_lock(mutex_);
        bytes = encode_checkpoint(identity_, tiles_);
    }
    try {
        replace_file(file_, bytes);
    } catch (const FileWriteError& e) {
        throw CheckpointError(e.what());
    }
}

}  // namespace drt
