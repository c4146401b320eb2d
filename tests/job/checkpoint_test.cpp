// Checkpoint files (checkpoint.h) and resumed renders (render_job.h): what is kept is exactly
// what was rendered, damage and foreign checkpoints are refused, and a render stopped and
// resumed at any point, any number of times, gives the bits and ray counts of one never stopped.
#include "drt/job/checkpoint.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "drt/io/image.h"
#include "drt/job/render_job.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/atomic_file.h"
#include "run_drt.h"
#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;
using namespace test;

// Motion blur, depth of field, glossy reflection and soft shadows in one scene.
const fs::path kEffects = kSourceDir / "scenes/thesis/test5.xml";

Scene small_scene(const fs::path& file = kEffects) {
    LoadedScene loaded = load_scene(file);
    loaded.scene.settings.width = 40;
    loaded.scene.settings.height = 28;
    loaded.scene.settings.samples = 4;
    return std::move(loaded.scene);
}

using TempDir = TempFolderTest;

TileBuffer some_tile(const Tile& tile, float base) {
    TileBuffer t;
    t.tile = tile;
    t.pixels = Image(tile.width(), tile.height());
    for (std::size_t i = 0; i < t.pixels.rgb.size(); ++i) t.pixels.rgb[i] = base + float(i) / 7;
    t.pixel_samples.assign(static_cast<std::size_t>(tile.width()) * tile.height(), 5);
    t.spread = Image(tile.width(), tile.height());
    for (std::size_t i = 0; i < t.spread.rgb.size(); ++i) t.spread.rgb[i] = base * 1e-3f + float(i);
    t.error_sums = {0.1 + base, 1e-300, 12, 3.5};
    t.rays = {11, 22, 33, 44};
    t.samples = 5 * t.pixel_samples.size();
    t.converged = 3;
    return t;
}

RenderIdentity identity_of(const std::vector<Tile>& grid) {
    return {"9.9.9",    {{"scene.xml", 0x1234}, {"models/mesh.obj", 0x9abc}}, 0x5678, 40, 28,
            grid.size()};
}

TEST(Checkpoint, TilesComeBackWithEveryBitAndCount) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    const std::vector<TileBuffer> tiles{some_tile(grid[4], 0.25f), some_tile(grid[0], -1e-30f)};
    const std::vector<unsigned char> bytes = encode_checkpoint(identity_of(grid), tiles);
    const Checkpoint c = decode_checkpoint(bytes, grid, "c", DiffuseCount::kOmitted);
    EXPECT_EQ(c.identity, identity_of(grid));
    ASSERT_EQ(c.tiles.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(c.tiles[i].tile, tiles[i].tile);
        EXPECT_EQ(c.tiles[i].pixels.rgb, tiles[i].pixels.rgb);
        EXPECT_EQ(c.tiles[i].pixel_samples, tiles[i].pixel_samples);
        EXPECT_EQ(c.tiles[i].spread.rgb, tiles[i].spread.rgb);
        EXPECT_EQ(c.tiles[i].error_sums, tiles[i].error_sums);
        EXPECT_EQ(c.tiles[i].rays.total(), 110u);
        EXPECT_EQ(c.tiles[i].rays.refraction, 44u);
        EXPECT_EQ(c.tiles[i].samples, tiles[i].samples);
        EXPECT_EQ(c.tiles[i].converged, 3u);
    }
}

TEST(Checkpoint, EveryDamagedByteAndEveryTruncationIsRefused) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    const std::vector<unsigned char> bytes =
        encode_checkpoint(identity_of(grid), std::vector{some_tile(grid[1], 2.0f)});
    for (std::size_t i = 0; i < bytes.size(); i += 7) {
        std::vector<unsigned char> damaged = bytes;
        damaged[i] ^= 0x10;
        EXPECT_THROW(decode_checkpoint(damaged, grid, "c", DiffuseCount::kOmitted), CheckpointError)
            << "byte " << i;
        const std::vector<unsigned char> cut(bytes.begin(), bytes.begin() + i);
        EXPECT_THROW(decode_checkpoint(cut, grid, "c", DiffuseCount::kOmitted), CheckpointError)
            << "length " << i;
    }
    try {
        std::vector<unsigned char> damaged = bytes;
        damaged[bytes.size() / 2] ^= 1;
        decode_checkpoint(damaged, grid, "ck.bin", DiffuseCount::kOmitted);
        FAIL();
    } catch (const CheckpointError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "ck.bin: damaged or truncated checkpoint (checksum does not match)");
    }
}

// Tiles the checksum cannot catch, written so by a faulty writer: the tile codec's findings
// come back in the checkpoint's words.
TEST(Checkpoint, ARepeatedOrShortTileBehindAGoodChecksumIsRefusedInTheCheckpointsWords) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    const auto message = [&](const std::vector<TileBuffer>& tiles) {
        try {
            decode_checkpoint(encode_checkpoint(identity_of(grid), tiles), grid, "ck.bin",
                              DiffuseCount::kOmitted);
        } catch (const CheckpointError& e) {
            return std::string(e.what());
        }
        return std::string("decoded");
    };
    EXPECT_EQ(message({some_tile(grid[1], 1.0f), some_tile(grid[1], 2.0f)}),
              "ck.bin: damaged checkpoint (bad tile index)");
    TileBuffer short_tile = some_tile(grid[1], 1.0f);
    short_tile.pixels = Image(1, 1);  // encodes fewer pixels than its tile has
    EXPECT_EQ(message({short_tile}), "ck.bin: truncated checkpoint");
}

TEST(Checkpoint, IdentityCoversTheSceneBytesAndEverySettingButNotHowTheWorkIsDone) {
    const Scene scene = small_scene();
    const std::vector<fs::path> files{kEffects};
    const RenderIdentity base = identify_render(files, scene.settings, std::nullopt, 12);
    EXPECT_EQ(base, identify_render(files, scene.settings, std::nullopt, 12));
    EXPECT_EQ(base.version, DRT_VERSION);
    const auto differs = [&](auto change) {
        RenderSettings s = scene.settings;
        std::optional<AdaptiveSampling> adaptive;
        change(s, adaptive);
        return identify_render(files, s, adaptive, 12).options != base.options;
    };
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.seed += 1; }));
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.samples += 1; }));
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.shadow_rays += 1; }));
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.glossy_rays += 1; }));
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.max_depth += 1; }));
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.sampler = "sobol"; }));
    EXPECT_TRUE(differs([](RenderSettings& s, auto&) { s.pixel_plane_unit *= 1 + 1e-15; }));
    EXPECT_TRUE(differs([](auto&, auto& a) { a = AdaptiveSampling{0.01, 16}; }));
    const fs::path other = kSourceDir / "scenes/thesis/test6.xml";
    EXPECT_NE(identify_render(std::vector{other}, scene.settings, std::nullopt, 12).files,
              base.files);
    // Every file the scene reads, on its own and by its bytes alone.
    const RenderIdentity two =
        identify_render(std::vector{kEffects, other}, scene.settings, std::nullopt, 12);
    ASSERT_EQ(two.files.size(), 2u);
    EXPECT_EQ(two.files[0], base.files[0]);
    EXPECT_EQ(two.files[1].name, other.string());
    EXPECT_NE(two.files[1].hash, two.files[0].hash);
    const std::string bytes = read_bytes(other);
    EXPECT_EQ(two.files[1].hash,
              hash_bytes({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}));
}

TEST_F(TempDir, ACheckpointOfAnotherRenderIsRefusedSayingWhatDiffers) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    const RenderIdentity id = identity_of(grid);
    const fs::path file = dir_ / "c.ckpt";
    EXPECT_FALSE(read_checkpoint(file, id, grid).has_value());  // none yet: start afresh
    replace_file(file, encode_checkpoint(id, std::vector{some_tile(grid[2], 1.0f)}));
    EXPECT_EQ(read_checkpoint(file, id, grid)->tiles.size(), 1u);
    const auto message = [&](RenderIdentity other) {
        try {
            read_checkpoint(file, other, grid);
        } catch (const CheckpointError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    RenderIdentity other = id;
    other.version = "9.9.10";
    EXPECT_NE(message(other).find("made by drt 9.9.9, not drt 9.9.10"), std::string::npos);
    other = id;
    other.files[0].hash += 1;
    EXPECT_NE(message(other).find("made by another scene file (its contents differ)"),
              std::string::npos);
    other = id;
    other.files[1] = {"meshes/mesh.obj", other.files[1].hash + 1};
    EXPECT_EQ(message(other), file.string() +
                                  ": checkpoint of another render: made by another version of "
                                  "meshes/mesh.obj (a file the scene reads: its contents differ); "
                                  "not resumed and nothing written (delete it or name another "
                                  "--checkpoint file)");
    other = id;
    other.files.pop_back();
    EXPECT_NE(message(other).find("made by a scene reading another number of files (1, not 0)"),
              std::string::npos);
    // The same bytes reached by other names (from another folder): the same render.
    other = id;
    other.files[0].name = "../elsewhere/scene.xml";
    other.files[1].name = "../elsewhere/models/mesh.obj";
    EXPECT_EQ(message(other), "accepted");
    other = id;
    other.options += 1;
    EXPECT_EQ(message(other),
              file.string() +
                  ": checkpoint of another render: made by other options (samples, seed, sampler "
                  "or another setting differs); not resumed and nothing written (delete it or "
                  "name another --checkpoint file)");
}

// A checkpoint of another image size whose grid has as many tiles (40 x 24 and 24 x 40, six
// tiles each) is refused as one of another size, before its tiles are read against this grid.
TEST_F(TempDir, ACheckpointOfAnotherSizeWithAsManyTilesIsRefusedAsSuch) {
    const std::vector<Tile> wide = tile_grid(40, 24), tall = tile_grid(24, 40);
    ASSERT_EQ(wide.size(), tall.size());
    RenderIdentity made = identity_of(wide);
    made.width = 40;
    made.height = 24;
    RenderIdentity wanted = made;
    wanted.width = 24;
    wanted.height = 40;
    const fs::path file = dir_ / "c.ckpt";
    replace_file(file, encode_checkpoint(made, std::vector{some_tile(wide[1], 1.0f)}));
    try {
        read_checkpoint(file, wanted, tall);
        ADD_FAILURE() << "accepted";
    } catch (const CheckpointError& e) {
        EXPECT_EQ(std::string(e.what()),
                  file.string() +
                      ": checkpoint of another render: made by another image size (40x24); not "
                      "resumed and nothing written (delete it or name another --checkpoint file)");
    }
    EXPECT_EQ(read_checkpoint(file, made, wide)->tiles.size(), 1u);
}

// A stopped render whose checkpoint cannot be written (its folder gone) still returns the tiles
// it rendered, saying why nothing was kept, so that the caller can write the partial image.
TEST_F(TempDir, AStoppedRenderWhoseCheckpointCannotBeWrittenStillReturnsItsImage) {
    const Scene scene = small_scene();
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    RenderJobOptions options;
    options.threads = 1;
    fs::create_directory(dir_ / "gone");
    options.checkpoint = dir_ / "gone" / "c.ckpt";
    options.scene_files = {kEffects};
    options.stop_after_tiles = 2;
    options.on_progress = [&](double) { fs::remove_all(dir_ / "gone"); };
    const RenderJobResult r = run_render_job(scene, request, options);
    EXPECT_FALSE(r.complete());
    EXPECT_EQ(r.done, 2u);
    EXPECT_NE(r.checkpoint_failure.find("c.ckpt: cannot create file"), std::string::npos)
        << r.checkpoint_failure;
    EXPECT_EQ(r.render.image.width, scene.settings.width);
    EXPECT_GT(*std::max_element(r.render.image.rgb.begin(), r.render.image.rgb.end()), 0.0f);
    // With its folder there, the same render keeps its checkpoint and says nothing.
    options.on_progress = nullptr;
    fs::create_directory(dir_ / "gone");
    const RenderJobResult kept = run_render_job(scene, request, options);
    EXPECT_TRUE(kept.checkpoint_failure.empty()) << kept.checkpoint_failure;
    EXPECT_TRUE(fs::exists(*options.checkpoint));
}

// A distributed render writes format 4, whose tiles have no diffuse count; a path render format 5,
// whose tiles have one. Either is read back, and a render of the other kind refuses it.
TEST_F(TempDir, APathRendersCheckpointIsFormatFiveWithDiffuseCounts) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    RenderIdentity distributed = identity_of(grid);
    const std::vector<unsigned char> four =
        encode_checkpoint(distributed, std::vector{some_tile(grid[1], 1.0f)});
    EXPECT_EQ(four[7], '4');
    RenderIdentity path = distributed;
    path.diffuse = DiffuseCount::kCarried;
    TileBuffer tile = some_tile(grid[1], 1.0f);
    tile.rays.diffuse = 55;
    const std::vector<unsigned char> five = encode_checkpoint(path, std::vector{tile});
    EXPECT_EQ(five[7], '5');
    EXPECT_EQ(five.size(), four.size() + 8);
    const Checkpoint c = decode_checkpoint(five, grid, "c", DiffuseCount::kOmitted);
    EXPECT_EQ(c.identity, path);
    ASSERT_EQ(c.tiles.size(), 1u);
    EXPECT_EQ(c.tiles[0].rays.diffuse, 55u);
    EXPECT_EQ(c.tiles[0].rays.total(), 165u);
    EXPECT_EQ(decode_checkpoint(four, grid, "c", DiffuseCount::kCarried).identity, distributed);

    const fs::path file = dir_ / "ck.bin";
    replace_file(file, five);
    try {
        read_checkpoint(file, distributed, grid);
        ADD_FAILURE() << "a path render's checkpoint resumed a distributed render";
    } catch (const CheckpointError& e) {
        EXPECT_NE(std::string(e.what()).find("made by the other integrator"), std::string::npos)
            << e.what();
    }
    std::vector<unsigned char> unknown = five;
    unknown[7] = '8';
    try {
        decode_checkpoint(unknown, grid, "c", DiffuseCount::kCarried);
        ADD_FAILURE() << "format 8 decoded";
    } catch (const CheckpointError& e) {
        EXPECT_NE(std::string(e.what()).find("checkpoint format 8 of another drt version, this "
                                             "one reads format 5"),
                  std::string::npos)
            << e.what();
    }
}

// A render with AOVs keeps them in format 6 (7 for a path render): their count after the tile
// count, their values after each tile's.
TEST_F(TempDir, ARenderWithAovsKeepsThemInFormatSix) {
    const std::vector<Tile> grid = tile_grid(40, 28);
    RenderIdentity id = identity_of(grid);
    const std::vector<unsigned char> four =
        encode_checkpoint(id, std::vector{some_tile(grid[1], 1.0f)});
    id.aov_channels = 4;
    TileBuffer tile = some_tile(grid[1], 1.0f);
    tile.aovs.assign(4 * tile.pixel_samples.size(), 0.5f);
    tile.aovs.back() = -2;
    const std::vector<unsigned char> six = encode_checkpoint(id, std::vector{tile});
    EXPECT_EQ(six[7], '6');
    EXPECT_EQ(six.size(), four.size() + 4 + 4 * tile.aovs.size());
    const Checkpoint c = decode_checkpoint(six, grid, "c", DiffuseCount::kOmitted);
    EXPECT_EQ(c.identity, id);
    ASSERT_EQ(c.tiles.size(), 1u);
    EXPECT_EQ(c.tiles[0].aovs, tile.aovs);
    id.diffuse = DiffuseCount::kCarried;
    EXPECT_EQ(encode_checkpoint(id, std::vector{tile})[7], '7');
}

// A plain render's image and ray counts, for the resumed ones to match.
RenderResult plain(const Scene& scene, const std::optional<AdaptiveSampling>& adaptive) {
    RenderOptions options;
    options.threads = 2;
    options.adaptive = adaptive;
    return render(scene, options);
}

TEST_F(TempDir, RendersStoppedAndResumedAtSeveralPointsGiveThePlainRendersBits) {
    const Scene scene = small_scene();
    for (const auto& adaptive : {std::optional<AdaptiveSampling>{},
                                 std::optional<AdaptiveSampling>{AdaptiveSampling{0.05, 2}}}) {
        const RenderResult reference = plain(scene, adaptive);
        RenderRequest request = RenderRequest::whole_image(scene.settings);
        request.adaptive = adaptive;
        RenderJobOptions options;
        options.threads = 1;  // stops after exactly the given count (two threads may overshoot)
        options.checkpoint = dir_ / "c.ckpt";
        options.scene_files = {kEffects};
        RenderJobResult r;
        std::size_t resumed = 0;
        for (const std::size_t stop : {1, 2, 5}) {  // of 6 tiles
            options.stop_after_tiles = stop;
            r = run_render_job(scene, request, options);
            ASSERT_FALSE(r.complete());
            EXPECT_EQ(r.resumed, resumed);
            EXPECT_EQ(r.done, stop);
            resumed = r.done;
            ASSERT_TRUE(fs::exists(*options.checkpoint));
        }
        options.stop_after_tiles.reset();
        options.threads = 2;
        r = run_render_job(scene, request, options);
        ASSERT_TRUE(r.complete());
        EXPECT_EQ(r.resumed, resumed);
        EXPECT_EQ(r.render.image.rgb, reference.image.rgb);
        EXPECT_EQ(r.render.pixel_samples, reference.pixel_samples);
        EXPECT_EQ(r.render.stats.rays.total(), reference.stats.rays.total());
        EXPECT_EQ(r.render.stats.rays.shadow, reference.stats.rays.shadow);
        EXPECT_EQ(r.render.stats.samples, reference.stats.samples);
        EXPECT_EQ(r.render.stats.pixels_converged, reference.stats.pixels_converged);
        fs::remove(*options.checkpoint);
    }
}

TEST_F(TempDir, APathRenderStoppedAndResumedGivesThePlainRendersBitsAndDiffuseRays) {
    const fs::path cornell = kSourceDir / "scenes/gi/cornell-box.xml";
    const Scene scene = small_scene(cornell);
    const RenderResult reference = plain(scene, std::nullopt);
    ASSERT_GT(reference.stats.rays.diffuse, 0u);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    RenderJobOptions options;
    options.threads = 1;
    options.checkpoint = dir_ / "c.ckpt";
    options.scene_files = {cornell};
    options.stop_after_tiles = 2;
    RenderJobResult r = run_render_job(scene, request, options);
    ASSERT_FALSE(r.complete());
    ASSERT_TRUE(fs::exists(*options.checkpoint));
    EXPECT_EQ(read_bytes(*options.checkpoint).substr(0, 8), "DRTCKPT5");
    options.stop_after_tiles.reset();
    r = run_render_job(scene, request, options);
    ASSERT_TRUE(r.complete());
    EXPECT_EQ(r.resumed, 2u);
    EXPECT_EQ(r.render.image.rgb, reference.image.rgb);
    EXPECT_EQ(r.render.stats.rays.diffuse, reference.stats.rays.diffuse);
    EXPECT_EQ(r.render.stats.rays.shadow, reference.stats.rays.shadow);
    EXPECT_EQ(r.render.stats.rays.total(), reference.stats.rays.total());
}

// A checkpoint of the same scene and options from a build of drt that renders them differently
// (made here by moving one value of one tile by a float step, the checksum made anew) is refused
// and left as it is: before resuming, the tile that took the most rays is rendered again and must
// come back with every bit. Put back, the checkpoint resumes.
TEST_F(TempDir, ACheckpointOfABuildThatRendersDifferentlyIsRefusedAndLeftAsItIs) {
    const Scene scene = small_scene();
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    RenderJobOptions options;
    options.threads = 1;
    options.checkpoint = dir_ / "c.ckpt";
    options.scene_files = {kEffects};
    options.stop_after_tiles = 3;  // of 6
    ASSERT_FALSE(run_render_job(scene, request, options).complete());
    const fs::path file = *options.checkpoint;
    const std::string written = read_bytes(file);
    const std::vector<Tile> grid = tile_grid(scene.settings.width, scene.settings.height);
    Checkpoint c = decode_checkpoint(std::vector<unsigned char>(written.begin(), written.end()),
                                     grid, file, DiffuseCount::kOmitted);
    ASSERT_EQ(c.tiles.size(), 3u);
    const std::size_t checked = tile_to_render_again(c.tiles).tile.index;
    TileBuffer* changed = nullptr;
    for (TileBuffer& t : c.tiles) {
        if (t.tile.index == checked) changed = &t;
    }
    for (const TileBuffer& t : c.tiles) EXPECT_LE(t.rays.total(), changed->rays.total());
    float& value = changed->pixels.rgb[7];
    value = std::nextafter(value, 2 * value + 1);
    replace_file(file, encode_checkpoint(c.identity, c.tiles));
    const std::string foreign = read_bytes(file);
    options.stop_after_tiles.reset();
    try {
        run_render_job(scene, request, options);
        ADD_FAILURE() << "resumed";
    } catch (const CheckpointError& e) {
        EXPECT_EQ(std::string(e.what()),
                  file.string() +
                      ": checkpoint of another render: made by a drt that renders "
                      "this scene differently (tile " +
                      std::to_string(checked) +
                      ", rendered again, differs); not resumed and nothing written (delete it "
                      "or name another --checkpoint file)");
    }
    EXPECT_EQ(read_bytes(file), foreign);
    replace_file(file, std::vector<unsigned char>(written.begin(), written.end()));
    const RenderJobResult r = run_render_job(scene, request, options);
    EXPECT_TRUE(r.complete());
    EXPECT_EQ(r.resumed, 3u);
    EXPECT_EQ(r.render.image.rgb, plain(scene, std::nullopt).image.rgb);
}

TEST_F(TempDir, ACausticRenderStoppedAndResumedGivesThePlainRendersBits) {
    // The resumed run builds its photon maps anew: they are functions of (seed, pass) alone.
    const fs::path caustic = kSourceDir / "scenes/caustics/test1-caustic.xml";
    const Scene scene = small_scene(caustic);
    const RenderResult reference = plain(scene, std::nullopt);
    ASSERT_GT(reference.stats.photons, 0u);
    const RenderRequest request = RenderRequest::whole_image(scene.settings);
    RenderJobOptions options;
    options.threads = 1;
    options.checkpoint = dir_ / "c.ckpt";
    options.scene_files = {caustic};
    options.stop_after_tiles = 3;
    RenderJobResult r = run_render_job(scene, request, options);
    ASSERT_FALSE(r.complete());
    options.stop_after_tiles.reset();
    options.threads = 2;
    r = run_render_job(scene, request, options);
    ASSERT_TRUE(r.complete());
    EXPECT_EQ(r.resumed, 3u);
    EXPECT_EQ(r.render.image.rgb, reference.image.rgb);
    EXPECT_EQ(r.render.stats.rays.total(), reference.stats.rays.total());
}

// ---- the command line -------------------------------------------------------------------------

class CheckpointCli : public TempDir {
  protected:
    std::vector<std::string> command(const std::string& output, std::vector<std::string> more = {},
                                     const std::string& spp = "4",
                                     const std::string& threads = "2") const {
        std::vector<std::string> args{
            kEffects.string(), "--width", "48", "--height", "32", "--spp", spp, "-o", output,
            "--threads",       threads};
        args.insert(args.end(), more.begin(), more.end());
        return args;
    }
    Outcome run(const std::vector<std::string>& args) const { return run_drt(args, dir_); }
};

TEST_F(CheckpointCli, InterruptedRunsWritePartialAndCheckpointAndTheLastOneTheSameBits) {
    ASSERT_EQ(run(command("plain.pfm", {"--stats", "plain.json"})).status, 0);
    const std::vector<std::string> resumable =
        command("out.pfm", {"--checkpoint", "c.ckpt", "--stats", "out.json"});
    for (const std::string stop : {"1", "3"}) {
        std::vector<std::string> args = resumable;
        args.insert(args.end(), {"--stop-after-tiles", stop});
        const Outcome r = run(args);
        EXPECT_EQ(r.status, 130) << r.err;
        EXPECT_NE(r.err.find("wrote out.partial.pfm and c.ckpt\ndrt: run the same command again "
                             "to resume"),
                  std::string::npos)
            << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
        EXPECT_TRUE(fs::exists(dir_ / "out.partial.pfm"));
        EXPECT_TRUE(fs::exists(dir_ / "c.ckpt"));
    }
    const Outcome r = run(resumable);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("tiles resumed"), std::string::npos) << r.err;
    EXPECT_EQ(read_bytes(dir_ / "out.pfm"), read_bytes(dir_ / "plain.pfm"));
    EXPECT_FALSE(fs::exists(dir_ / "c.ckpt"));  // removed once the image is written
    EXPECT_FALSE(fs::exists(dir_ / "out.partial.pfm"));
    const auto rays = [&](const std::string& json) {
        const std::string text = read_bytes(dir_ / json);
        return text.substr(text.find("\"rays\""),
                           text.find('}', text.find("\"rays\"")) - text.find("\"rays\""));
    };
    EXPECT_EQ(rays("out.json"), rays("plain.json"));
}

// --aov with --checkpoint: the resumed render's AOV channels are the uninterrupted one's, and a
// checkpoint without them does not resume a render with them.
TEST_F(CheckpointCli, AovsAreKeptAndResumed) {
    const std::vector<std::string> aov{"--aov", "albedo,depth"};
    std::vector<std::string> plain_args = command("plain.exr", aov);
    ASSERT_EQ(run(plain_args).status, 0);
    std::vector<std::string> resumable = command("out.exr", {"--checkpoint", "c.ckpt"});
    std::vector<std::string> stopped = resumable;
    stopped.insert(stopped.end(), {"--stop-after-tiles", "2"});
    ASSERT_EQ(run(stopped).status, 130);  // without AOVs
    resumable.insert(resumable.end(), aov.begin(), aov.end());
    const Outcome foreign = run(resumable);
    EXPECT_EQ(foreign.status, 2);
    EXPECT_NE(foreign.err.find("checkpoint of another render"), std::string::npos) << foreign.err;
    fs::remove(dir_ / "c.ckpt");
    stopped = resumable;
    stopped.insert(stopped.end(), {"--stop-after-tiles", "2"});
    ASSERT_EQ(run(stopped).status, 130);
    EXPECT_EQ(read_bytes(dir_ / "c.ckpt")[7], '6');
    const Outcome r = run(resumable);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("tiles resumed"), std::string::npos) << r.err;
    EXPECT_EQ(read_image(dir_ / "out.exr").rgb, read_image(dir_ / "plain.exr").rgb);
    for (const char* channel : {"albedo.R", "albedo.G", "albedo.B", "depth.Z"}) {
        EXPECT_EQ(read_exr_channel(dir_ / "out.exr", channel),
                  read_exr_channel(dir_ / "plain.exr", channel))
            << channel;
    }
}

TEST_F(CheckpointCli, DamagedTruncatedAndForeignCheckpointsExitTwoAndChangeNothing) {
    std::vector<std::string> args = command("out.pfm", {"--checkpoint", "c.ckpt"});
    args.insert(args.end(), {"--stop-after-tiles", "2"});
    ASSERT_EQ(run(args).status, 130);
    const std::string good = read_bytes(dir_ / "c.ckpt");
    std::string damaged = good;
    damaged[damaged.size() / 2] ^= 0x40;
    std::string format2 = good;  // written by a drt before each file had its own fingerprint
    format2[7] = '2';
    const std::vector<std::pair<std::string, std::string>> cases{
        {format2,
         "checkpoint format 2 of another drt version, this one reads format 4: not resumed and "
         "nothing written (delete it or name another --checkpoint file)"},
        {damaged, "checksum does not match"},
        {good.substr(0, good.size() - 100), "checksum does not match"},
        {good.substr(0, 5), "not a drt checkpoint"},
        {"hello", "not a drt checkpoint"}};
    for (const auto& [bytes, why] : cases) {
        write_bytes(dir_ / "bad.ckpt", bytes);
        const Outcome r = run(command("out.pfm", {"--checkpoint", "bad.ckpt"}));
        EXPECT_EQ(r.status, 2) << why;
        EXPECT_NE(r.err.find("bad.ckpt: "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
        EXPECT_EQ(read_bytes(dir_ / "bad.ckpt"), bytes);
        EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
    }
    // The same checkpoint for another seed, and for another scene.
    Outcome r = run(command("out.pfm", {"--checkpoint", "c.ckpt", "--seed", "7"}));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("checkpoint of another render: made by other options"), std::string::npos)
        << r.err;
    std::vector<std::string> other = command("out.pfm", {"--checkpoint", "c.ckpt"});
    other[0] = (kSourceDir / "scenes/thesis/test6.xml").string();
    r = run(other);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("made by another scene file"), std::string::npos) << r.err;
    EXPECT_EQ(read_bytes(dir_ / "c.ckpt"), good);
    EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
}

TEST_F(CheckpointCli, AnEditedMeshFileIsRefusedNamingItAndTheOriginalResumes) {
    write_bytes(dir_ / "scene.xml",
                "<Scene><Image Width=\"48\" Height=\"32\"/><Materials><Gray/></Materials>"
                "<Mesh File=\"models/tri.obj\" Material=\"Gray\"/></Scene>");
    fs::create_directories(dir_ / "models");
    const std::string obj = "v -5 -5 20\nv 5 -5 20\nv 0 5 20\nf 1 2 3\n";
    write_bytes(dir_ / "models/tri.obj", obj);
    const std::vector<std::string> args{"scene.xml", "-o", "out.pfm", "--checkpoint", "c.ckpt"};
    std::vector<std::string> stopped = args;
    stopped.insert(stopped.end(), {"--stop-after-tiles", "1"});
    ASSERT_EQ(run(stopped).status, 130);
    const std::string kept = read_bytes(dir_ / "c.ckpt");
    write_bytes(dir_ / "models/tri.obj", "v -5 -5 20\nv 5 -5 20\nv 0 6 20\nf 1 2 3\n");
    Outcome r = run(args);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err, "drt: c.ckpt: checkpoint of another render: made by another version of " +
                         (fs::path("models") / "tri.obj").string() +
                         " (a file the scene reads: its contents differ); not resumed and "
                         "nothing written (delete it or name another --checkpoint file)\n");
    EXPECT_EQ(read_bytes(dir_ / "c.ckpt"), kept);
    EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
    write_bytes(dir_ / "models/tri.obj", obj);
    r = run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("tiles resumed"), std::string::npos) << r.err;
}

// Waits until `file` is written anew (the render is under way), up to a minute.
bool wait_for(const fs::path& file) {
    const auto written = [&] {
        std::error_code ec;
        const auto t = fs::last_write_time(file, ec);
        return ec ? fs::file_time_type::min() : t;
    };
    const auto before = written();
    for (int i = 0; i < 6000 && written() == before; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return written() != before;
}

TEST_F(CheckpointCli, SigintAndSigtermStopSaveAndExit130And143ThenTheRerunFinishesTheSameBits) {
    // Enough work that a signal arrives mid-render; a checkpoint after every tile shows when.
    const std::vector<std::string> more{"--checkpoint", "c.ckpt", "--checkpoint-every", "0"};
    ASSERT_EQ(run(command("plain.pfm", {}, "64", "1")).status, 0);
    for (const int sig : {SIGINT, SIGTERM}) {
        std::vector<std::string> argv{DRT_BINARY};
        for (const std::string& a : command("out.pfm", more, "64", "1")) argv.push_back(a);
        const pid_t pid = start_process(argv, dir_);
        ASSERT_TRUE(wait_for(dir_ / "c.ckpt"));
        kill(pid, sig);
        const Outcome r = finish_process(pid, dir_);
        if (r.status == 0) continue;  // finished before the signal: nothing to test this time
        EXPECT_EQ(r.status, 128 + sig) << r.err;
        EXPECT_NE(r.err.find("run the same command again to resume"), std::string::npos);
        EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
        EXPECT_TRUE(fs::exists(dir_ / "out.partial.pfm"));
    }
    const Outcome r = run(command("out.pfm", more, "64", "1"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(read_bytes(dir_ / "out.pfm"), read_bytes(dir_ / "plain.pfm"));
    EXPECT_FALSE(fs::exists(dir_ / "c.ckpt"));
}

// Files of one command that are one file are refused before anything is rendered or written:
// the image and the checkpoint (removed once the image is written, which would remove the image),
// the error image or the statistics, and two scenes of a batch with the same name (status 2). An
// output with nowhere to go fails before the render (status 1), so that no checkpoint is lost.
TEST_F(CheckpointCli, FilesThatAreOneFileAndAnOutputWithNowhereToGoFailBeforeRendering) {
    replace_file(dir_ / "same.pfm", std::string("kept"));
    Outcome r = run(command("same.pfm", {"--checkpoint", "same.pfm"}));
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err,
              "drt: -o and --checkpoint are one file, same.pfm: one would destroy the other\n"
              "Run 'drt --help' for usage.\n");
    EXPECT_EQ(read_bytes(dir_ / "same.pfm"), "kept");
    r = run(command("out.pfm", {"--error-image", "err.pfm", "--checkpoint", "sub/../err.pfm"}));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--checkpoint and --error-image are one file"), std::string::npos)
        << r.err;
    r = run(command("out.pfm", {"--stats", "./out.pfm"}));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("-o and --stats are one file"), std::string::npos) << r.err;
    fs::create_directories(dir_ / "a");
    fs::create_directories(dir_ / "b");
    fs::copy_file(kEffects, dir_ / "a/x.xml");
    fs::copy_file(kEffects, dir_ / "b/x.xml");
    r = run({"a/x.xml", "b/x.xml", "--width", "8", "--height", "6", "--spp", "1", "-o", "out/"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("the image of a/x.xml and the image of b/x.xml are one file"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
    r = run(command("nowhere/out.pfm", {"--checkpoint", "c.ckpt"}));
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "drt: nowhere/out.pfm: cannot create file: No such file or directory\n");
    EXPECT_FALSE(fs::exists(dir_ / "c.ckpt"));
    EXPECT_EQ(run(command("out.pfm", {"--checkpoint", "c.ckpt"})).status, 0);
}

}  // namespace
}  // namespace drt
