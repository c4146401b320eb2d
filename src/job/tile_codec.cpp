#include "drt/job/tile_codec.h"

#include <bit>
#include <cstdint>
#include <stdexcept>

#include "drt/util/byte_order.h"

namespace drt {

namespace {

std::string wording(TileCodecError::Problem problem) {
    switch (problem) {
        case TileCodecError::Problem::truncated:
            return "truncated tile";
        case TileCodecError::Problem::unknown_tile:
            return "damaged tile (bad tile index)";
        case TileCodecError::Problem::bytes_after:
            break;
    }
    return "damaged tile (bytes after its end)";
}

class Writer {
  public:
    explicit Writer(std::vector<unsigned char>& bytes) : bytes_(bytes) {}
    void u32(std::uint32_t v) { append_little_endian(bytes_, v, 4); }
    void u64(std::uint64_t v) { append_little_endian(bytes_, v, 8); }
    void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
    void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }

  private:
    std::vector<unsigned char>& bytes_;
};

[[noreturn]] void truncated() {
    throw TileCodecError(TileCodecError::Problem::truncated);
}

}  // namespace

TileCodecError::TileCodecError(Problem problem)
    : std::runtime_error(wording(problem)), problem_(problem) {}

DiffuseCount diffuse_count_for(const RenderSettings& settings) {
    return settings.integrator == IntegratorKind::kPath ? DiffuseCount::kCarried
                                                        : DiffuseCount::kOmitted;
}

void append_tile(std::vector<unsigned char>& bytes, const TileBuffer& t, DiffuseCount diffuse,
                 std::size_t aov_channels) {
    if (diffuse == DiffuseCount::kOmitted && t.rays.diffuse != 0) {
        throw std::invalid_argument("a tile's diffuse rays in a layout without them");
    }
    if (t.aovs.size() != aov_channels * t.pixel_samples.size()) {
        throw std::invalid_argument("a tile's AOVs do not match the layout");
    }
    Writer w(bytes);
    w.u64(t.tile.index);
    for (float v : t.pixels.rgb) w.f32(v);
    for (std::uint32_t n : t.pixel_samples) w.u32(n);
    for (float v : t.spread.rgb) w.f32(v);
    w.f64(t.error_sums.variance);
    w.f64(t.error_sums.spread);
    w.f64(t.error_sums.pixels);
    w.f64(t.error_sums.samples);
    w.u64(t.rays.camera);
    w.u64(t.rays.shadow);
    w.u64(t.rays.reflection);
    w.u64(t.rays.refraction);
    if (diffuse == DiffuseCount::kCarried) w.u64(t.rays.diffuse);
    w.u64(t.samples);
    w.u64(t.converged);
    for (float v : t.aovs) w.f32(v);
}

std::vector<unsigned char> encode_tile(const TileBuffer& tile, DiffuseCount diffuse,
                                       std::size_t aov_channels) {
    std::vector<unsigned char> bytes;
    append_tile(bytes, tile, diffuse, aov_channels);
    return bytes;
}

TileBuffer take_tile(std::span<const unsigned char>& bytes, std::span<const Tile> grid,
                     std::vector<bool>& seen, DiffuseCount diffuse, std::size_t aov_channels) {
    ByteReader r(bytes, truncated);
    const std::uint64_t index = r.u64();
    if (index >= grid.size() || seen[index]) {
        throw TileCodecError(TileCodecError::Problem::unknown_tile);
    }
    seen[index] = true;
    TileBuffer t;
    t.tile = grid[index];
    t.pixels = Image(t.tile.width(), t.tile.height());
    r.need(t.pixels.rgb.size() * 4);
    for (float& v : t.pixels.rgb) v = r.f32();
    t.pixel_samples.resize(static_cast<std::size_t>(t.tile.width()) * t.tile.height());
    for (std::uint32_t& n : t.pixel_samples) n = r.u32();
    t.spread = Image(t.tile.width(), t.tile.height());
    r.need(t.spread.rgb.size() * 4);
    for (float& v : t.spread.rgb) v = r.f32();
    t.error_sums.variance = r.f64();
    t.error_sums.spread = r.f64();
    t.error_sums.pixels = r.f64();
    t.error_sums.samples = r.f64();
    t.rays.camera = r.u64();
    t.rays.shadow = r.u64();
    t.rays.reflection = r.u64();
    t.rays.refraction = r.u64();
    if (diffuse == DiffuseCount::kCarried) t.rays.diffuse = r.u64();
    t.samples = r.u64();
    t.converged = r.u64();
    t.aovs.resize(aov_channels * t.pixel_samples.size());
    r.need(t.aovs.size() * 4);
    for (float& v : t.aovs) v = r.f32();
    bytes = r.rest();
    return t;
}

TileBuffer decode_tile(std::span<const unsigned char> bytes, std::span<const Tile> grid,
                       DiffuseCount diffuse, std::size_t aov_channels) {
    std::vector<bool> seen(grid.size(), false);
    TileBuffer t = take_tile(bytes, grid, seen, diffuse, aov_channels);
    if (!bytes.empty()) throw TileCodecError(TileCodecError::Problem::bytes_after);
    return t;
}

}  // namespace drt
