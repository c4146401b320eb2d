// The `drt` command line as outside users drive it (docs/usage.md): every test runs the
// built binary in a fresh folder and checks exit status, messages and the files left behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "drt/io/compare.h"
#include "drt/io/image.h"
#include "encoded_bytes.h"
#include "regex_match.h"
#include "run_drt.h"
#include "sanitizers.h"
#include "temp_folder.h"

namespace drt {
namespace {

using testing::be32;

namespace fs = std::filesystem;
using namespace test;

// Runs drt with stdout and stderr on a pseudo-terminal and returns what the terminal showed.
std::string run_drt_on_terminal(const std::vector<std::string>& args, const fs::path& cwd) {
    int master = -1;
    const pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
    if (pid == 0) {
        if (chdir(cwd.c_str()) != 0) _exit(127);
        std::vector<char*> argv{const_cast<char*>(DRT_BINARY)};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(DRT_BINARY, argv.data());
        _exit(127);
    }
    std::string screen;
    char buf[4096];
    for (;;) {  // read until the child closes the terminal (EIO on Linux)
        const ssize_t n = read(master, buf, sizeof buf);
        if (n <= 0) break;
        screen.append(buf, static_cast<std::size_t>(n));
    }
    close(master);
    int wstatus = 0;
    waitpid(pid, &wstatus, 0);
    EXPECT_TRUE(WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0) << screen;
    return screen;
}

// ---- a minimal JSON reader, strict enough to catch malformed output ---------------------------

struct Json;
using JsonObject = std::map<std::string, Json>;
using JsonArray = std::vector<Json>;
struct Json {
    std::variant<std::nullptr_t, bool, double, std::string, JsonArray, JsonObject> value;
    const Json& operator[](const std::string& key) const {
        const auto& object = std::get<JsonObject>(value);
        const auto it = object.find(key);
        if (it == object.end()) throw std::runtime_error("missing key '" + key + "'");
        return it->second;
    }
    bool has(const std::string& key) const { return std::get<JsonObject>(value).contains(key); }
    double number() const { return std::get<double>(value); }
    bool boolean() const { return std::get<bool>(value); }
};

class JsonParser {
  public:
    explicit JsonParser(std::string text) : s_(std::move(text)) {}
    Json parse_document() {
        Json j = parse();
        skip();
        if (pos_ != s_.size()) fail("trailing characters");
        return j;
    }

  private:
    [[noreturn]] void fail(const std::string& what) const {
        throw std::runtime_error("JSON: " + what + " at offset " + std::to_string(pos_));
    }
    void skip() {
        while (pos_ < s_.size() && std::strchr(" \t\r\n", s_[pos_])) ++pos_;
    }
    bool eat(char c) {
        skip();
        if (pos_ < s_.size() && s_[pos_] == c) return ++pos_, true;
        return false;
    }
    void expect(char c) {
        if (!eat(c)) fail(std::string("expected '") + c + "'");
    }
    std::string parse_string() {
        expect('"');
        std::string out;
        while (pos_ < s_.size() && s_[pos_] != '"') {
            if (s_[pos_] == '\\') ++pos_;  // escapes are kept verbatim: tests compare ASCII only
            out += s_[pos_++];
        }
        expect('"');
        return out;
    }
    Json parse() {
        skip();
        if (pos_ >= s_.size()) fail("unexpected end");
        const char c = s_[pos_];
        if (c == '{') {
            ++pos_;
            JsonObject object;
            if (eat('}')) return {object};
            do {
                const std::string key = parse_string();
                expect(':');
                object[key] = parse();
            } while (eat(','));
            expect('}');
            return {object};
        }
        if (c == '[') {
            ++pos_;
            JsonArray array;
            if (eat(']')) return {array};
            do array.push_back(parse());
            while (eat(','));
            expect(']');
            return {array};
        }
        if (c == '"') return {parse_string()};
        for (const auto& [word, value] : {std::pair<const char*, Json>{"true", {true}},
                                          {"false", {false}},
                                          {"null", {nullptr}}}) {
            if (s_.compare(pos_, std::strlen(word), word) == 0) {
                pos_ += std::strlen(word);
                return value;
            }
        }
        // JSON numbers only: no inf, nan, hex or leading plus.
        const std::string rest = s_.substr(pos_, 64);
        const long length =
            regex_match_length(rest, R"(^-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
        if (length <= 0) fail("bad value");
        pos_ += static_cast<std::size_t>(length);
        return {std::stod(rest.substr(0, static_cast<std::size_t>(length)))};
    }

    std::string s_;
    std::size_t pos_ = 0;
};

Json parse_json(const std::string& text) {
    return JsonParser(text).parse_document();
}

// ---- fixture ------------------------------------------------------------------------------------

// A small scene that calls for antialiasing and soft shadows and has a mirror and glass: every ray
// kind is traced, and it renders in milliseconds.
constexpr const char* kScene = R"(<?xml version="1.0"?>
<Scene>
  <Image Width="24" Height="16"/>
  <Render Samples="4" ShadowRays="2" Seed="3"/>
  <Background r="0.1" g="0.2" b="0.3"/>
  <Camera Ex="0" Ey="2" Ez="-8" Lx="0" Ly="1" Lz="0" Fov="40"/>
  <Materials>
    <Grey kdr="0.7" kdg="0.7" kdb="0.7" diffuse="1"/>
    <Mirror reflective="1" ksr="0.9" ksg="0.9" ksb="0.9"/>
    <Glass transmitt="1" index="1.5"/>
  </Materials>
  <Light Px="2" Py="6" Pz="-2" Radius="0.8" Ir="1" Ig="1" Ib="1"/>
  <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Grey"/>
  <Sphere Px="-1.2" Py="1" Pz="0" Radius="1" Material="Mirror"/>
  <Sphere Px="1.2" Py="1" Pz="0" Radius="1" Material="Glass"/>
</Scene>
)";

class CliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("drt_cli_test_" + std::to_string(getpid()) + "_" +
                                            info->test_suite_name() + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        write_bytes(dir_ / "scene.xml", kScene);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }

    Outcome run(const std::vector<std::string>& args, rlim_t address_space = 0) const {
        return run_drt(args, dir_, address_space);
    }
    fs::path file(const std::string& name) const { return dir_ / name; }
    // Every name in the folder, so a test can see that nothing (not even a temporary) was left.
    std::vector<std::string> entries(const fs::path& folder) const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path dir_;
};

// ---- usage -------------------------------------------------------------------------------------

TEST_F(CliTest, HelpListsTheContractOptionsAndExitsZero) {
    for (const char* flag : {"--help", "-h"}) {
        const Outcome r = run({flag});
        EXPECT_EQ(r.status, 0) << flag;
        EXPECT_EQ(r.err, "");
        for (const char* option : {"--output", "--spp", "--shadow-rays", "--width", "--height",
                                   "--seed", "--threads", "--stats", "--quiet", "--version"}) {
            EXPECT_NE(r.out.find(option), std::string::npos) << flag << " lacks " << option;
        }
    }
    const Outcome compare = run({"compare", "--help"});
    EXPECT_EQ(compare.status, 0);
    for (const char* option : {"--max-rmse", "--min-psnr", "--diff"}) {
        EXPECT_NE(compare.out.find(option), std::string::npos) << option;
    }
}

TEST_F(CliTest, VersionPrintsNameAndVersion) {
    const Outcome r = run({"--version"});
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.out, std::string("drt ") + DRT_VERSION + "\n");
}

TEST_F(CliTest, BadUsageExitsTwoAndWritesNothing) {
    const std::vector<std::vector<std::string>> cases{
        {},
        {"scene.xml", "--bogus"},
        {"scene.xml", "--spp", "0"},
        {"scene.xml", "--spp", "many"},
        {"scene.xml", "--threads", "0"},
        {"scene.xml", "--width", "-5"},
        {"scene.xml", "-o", "out.jpg"},  // unknown format: refused before rendering
        {"compare", "only-one.png"},
        {"info"},
    };
    for (const auto& args : cases) {
        const Outcome r = run(args);
        std::string joined;
        for (const auto& a : args) joined += a + " ";
        EXPECT_EQ(r.status, 2) << joined << "\n" << r.err;
        EXPECT_NE(r.err, "") << joined;
    }
    EXPECT_EQ(entries(dir_), std::vector<std::string>{"scene.xml"});
}

// ---- malformed scenes -------------------------------------------------------------------------

struct BadScene {
    const char* name;
    std::string content;
    std::string message;  // the whole first line of stderr after "FILE:"
};

std::vector<BadScene> bad_scenes() {
    const std::string head =
        "<?xml version=\"1.0\"?>\n<Scene>\n  <Image Width=\"8\" Height=\"6\"/>\n";
    const std::string grey = "  <Materials><Grey kdr=\"0.5\"/></Materials>\n";
    return {
        {"truncated_mid_tag", head + "  <Sphere Px=\"1\" Py=\"2\" Pz=\"3\" Rad",
         "4: XML: malformed or repeated attribute"},
        {"truncated_unclosed",
         head + grey +
             "  <Objects>\n    <Sphere Px=\"0\" Py=\"0\" Pz=\"5\" "
             "Radius=\"1\" Material=\"Grey\"/>\n",
         "5: XML: malformed xml"},
        {"bad_number",
         head + grey +
             "  <Sphere Px=\"1\" Py=\"2\" Pz=\"3\" Radius=\"0.5abc\" "
             "Material=\"Grey\"/>\n</Scene>\n",
         "5: Sphere: attribute 'Radius' is not a number: \"0.5abc\""},
        {"nan_number", head + "  <Light Px=\"nan\" Py=\"2\" Pz=\"3\"/>\n</Scene>\n",
         "4: Light: attribute 'Px' is not a number: \"nan\""},
        {"empty_number", head + "  <Render Samples=\"\"/>\n</Scene>\n",
         "4: Render: attribute 'Samples' is not an integer: \"\""},
        {"negative_radius",
         head + grey +
             "\n\n  <Sphere Px=\"1\" Py=\"2\" Pz=\"3\" Radius=\"-1\" "
             "Material=\"Grey\"/>\n</Scene>\n",
         "7: Sphere: negative radius -1"},
        {"negative_light_radius",
         head + "  <Light Px=\"1\" Py=\"1\" Pz=\"1\" Radius=\"-2\"/>\n</Scene>",
         "4: Light: negative radius -2"},
        {"unknown_material",
         head + grey +
             "  <Sphere Px=\"1\" Py=\"2\" Pz=\"3\" Radius=\"1\"\n"
             "          Material=\"Glass\"/>\n</Scene>\n",
         "5: Sphere: unknown material 'Glass'"},
        {"zero_normal",
         head + grey +
             "  <Plane Px=\"0\" Py=\"0\" Pz=\"0\" Vu=\"0\" Vv=\"0\" Vw=\"0\" "
             "Material=\"Grey\"/>\n</Scene>\n",
         "5: Plane: zero-length normal"},
        {"zero_width", "<Scene>\n\n  <Image Width=\"0\" Height=\"6\"/>\n</Scene>\n",
         "3: Image: Width must be positive, got 0"},
        {"missing_attribute",
         head + grey + "  <Sphere Px=\"1\" Py=\"2\" Pz=\"3\" Material=\"Grey\"/>\n</Scene>\n",
         "5: Sphere: missing required attribute 'Radius'"},
        {"wrong_root", "<?xml version=\"1.0\"?>\n<Scena/>\n",
         "2: Scena: root element must be <Scene>"},
        {"empty_file", "", "1: XML: empty document"},
        {"blank_file", "\n\n   \n", "1: XML: empty document"},
        {"binary_file", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\x01\x02", 20),
         "3: XML: nul byte in input (not a text file?)"},
    };
}

TEST_F(CliTest, EveryMalformedSceneExitsTwoNamingFileAndLineAndWritesNothing) {
    const std::string existing = "precious bytes\n";
    for (const BadScene& bad : bad_scenes()) {
        SCOPED_TRACE(bad.name);
        const fs::path folder = dir_ / bad.name;
        fs::create_directory(folder);
        const std::string scene = std::string(bad.name) + ".xml";
        write_bytes(folder / scene, bad.content);
        write_bytes(folder / "kept.png", existing);
        write_bytes(folder / "kept.pfm", existing);
        write_bytes(folder / "stats.json", existing);

        for (const char* out : {"kept.png", "kept.pfm", "new.png", "new.bmp"}) {
            const Outcome r = run_drt({scene, "-o", out, "--stats", "stats.json"}, folder);
            EXPECT_EQ(r.status, 2) << out;
            EXPECT_EQ(r.err.substr(0, r.err.find('\n')), scene + ":" + bad.message) << out;
            EXPECT_EQ(r.out, "");
        }
        // Without -o the default output would be <name>.png in the current folder.
        const Outcome r = run_drt({scene}, folder);
        EXPECT_EQ(r.status, 2);
        EXPECT_EQ(read_bytes(folder / "kept.png"), existing);
        EXPECT_EQ(read_bytes(folder / "kept.pfm"), existing);
        EXPECT_EQ(read_bytes(folder / "stats.json"), existing);
        std::vector<std::string> expected{"kept.pfm", "kept.png", scene, "stats.json"};
        std::sort(expected.begin(), expected.end());
        EXPECT_EQ(entries(folder), expected);
    }
}

TEST_F(CliTest, MissingOrUnreadableSceneExitsTwoNamingIt) {
    write_bytes(file("kept.png"), "x");
    fs::create_directory(file("folder.xml"));
    for (const char* scene : {"missing.xml", "folder.xml"}) {
        const Outcome r = run({scene, "-o", "kept.png"});
        EXPECT_EQ(r.status, 2) << scene;
        EXPECT_EQ(r.err.rfind(std::string(scene) + ": cannot open scene: ", 0), 0u) << r.err;
        EXPECT_EQ(read_bytes(file("kept.png")), "x");
    }
}

TEST_F(CliTest, InfoDescribesAGoodSceneAndRejectsABadOne) {
    const Outcome good = run({"info", "scene.xml"});
    EXPECT_EQ(good.status, 0) << good.err;
    EXPECT_NE(good.out.find("soft"), std::string::npos) << good.out;
    write_bytes(file("bad.xml"), "<Scene>\n<Sphere Px=\"1\"/>\n</Scene>\n");
    const Outcome bad = run({"info", "bad.xml"});
    EXPECT_EQ(bad.status, 2);
    EXPECT_EQ(bad.err.rfind("bad.xml:2: Sphere: ", 0), 0u) << bad.err;
}

// ---- image files -------------------------------------------------------------------------------

std::int32_t signed_le32(const std::string& s, std::size_t at) {
    return static_cast<std::int32_t>(testing::le32(s, at));
}

TEST_F(CliTest, PngBmpAndPfmHeadersCarryTheRequestedSize) {
    ASSERT_EQ(run({"scene.xml", "-q", "--width", "19", "--height", "7", "-o", "a.png"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--width", "19", "--height", "7", "-o", "a.bmp"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--width", "19", "--height", "7", "-o", "a.pfm"}).status, 0);

    const std::string png = read_bytes(file("a.png"));
    ASSERT_GE(png.size(), 33u);
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(png.substr(12, 4), "IHDR");
    EXPECT_EQ(be32(png, 16), 19u);
    EXPECT_EQ(be32(png, 20), 7u);
    EXPECT_EQ(png[24], 8);  // bits per channel
    EXPECT_EQ(png[25], 2);  // colour type RGB

    const std::string bmp = read_bytes(file("a.bmp"));
    ASSERT_GE(bmp.size(), 54u);
    EXPECT_EQ(bmp.substr(0, 2), "BM");
    EXPECT_EQ(signed_le32(bmp, 2), static_cast<std::int32_t>(bmp.size()));
    EXPECT_EQ(signed_le32(bmp, 18), 19);
    EXPECT_EQ(std::abs(signed_le32(bmp, 22)), 7);

    const std::string pfm = read_bytes(file("a.pfm"));
    const std::string header = "PF\n19 7\n-1.0\n";
    EXPECT_EQ(pfm.substr(0, header.size()), header);
    EXPECT_EQ(pfm.size(), header.size() + 19 * 7 * 3 * 4);

    // The 8-bit files hold the sRGB encoding of the linear .pfm values.
    const Image linear = read_image(file("a.pfm"));
    const Image encoded = read_image(file("a.png"));
    const Image bmp_image = read_image(file("a.bmp"));
    ASSERT_EQ(encoded.rgb.size(), linear.rgb.size());
    for (std::size_t i = 0; i < linear.rgb.size(); ++i) {
        EXPECT_EQ(std::lround(encoded.rgb[i] * 255), encode_srgb8(linear.rgb[i])) << i;
        EXPECT_EQ(bmp_image.rgb[i], encoded.rgb[i]) << i;
    }
}

TEST_F(CliTest, DefaultOutputIsTheScenesNameAsPngInTheCurrentFolder) {
    fs::create_directory(file("sub"));
    fs::copy_file(file("scene.xml"), file("sub/room.xml"));
    const Outcome r = run({"sub/room.xml", "-q"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");  // -q: no progress, no "wrote" message
    EXPECT_TRUE(fs::exists(file("room.png")));
    EXPECT_FALSE(fs::exists(file("sub/room.png")));
}

TEST_F(CliTest, RerenderReplacesAnExistingOutputAndLeavesNoTemporaries) {
    write_bytes(file("out.pfm"), "old");
    ASSERT_EQ(run({"scene.xml", "-q", "-o", "out.pfm"}).status, 0);
    EXPECT_EQ(read_image(file("out.pfm")).width, 24);
    EXPECT_EQ(entries(dir_), (std::vector<std::string>{"out.pfm", "scene.xml"}));
}

TEST_F(CliTest, UnwritableOutputExitsOne) {
    const Outcome r = run({"scene.xml", "-q", "-o", "no/such/folder/out.png"});
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("no/such/folder/out.png"), std::string::npos) << r.err;
}

// ---- determinism
// ---------------------------------------------------------------------------------

TEST_F(CliTest, PfmIsBitIdenticalForAnyThreadCountAndRunAndChangesWithTheSeed) {
    ASSERT_EQ(run({"scene.xml", "-q", "--threads", "1", "-o", "t1.pfm"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--threads", "2", "-o", "t2.pfm"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--threads", "7", "-o", "t7.pfm"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--threads", "2", "-o", "again.pfm"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--seed", "3", "-o", "seed3.pfm"}).status, 0);
    ASSERT_EQ(run({"scene.xml", "-q", "--seed", "4", "-o", "seed4.pfm"}).status, 0);
    const std::string reference = read_bytes(file("t1.pfm"));
    ASSERT_EQ(reference.size(), std::string("PF\n24 16\n-1.0\n").size() + 24 * 16 * 12);
    EXPECT_EQ(read_bytes(file("t2.pfm")), reference);
    EXPECT_EQ(read_bytes(file("t7.pfm")), reference);
    EXPECT_EQ(read_bytes(file("again.pfm")), reference);
    EXPECT_EQ(read_bytes(file("seed3.pfm")), reference);  // the scene's own Seed is 3
    // Another seed draws other samples: most pixels change, though each only by noise.
    const Image a = read_image(file("seed3.pfm")), b = read_image(file("seed4.pfm"));
    int changed = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) changed += a.rgb[i] != b.rgb[i];
    EXPECT_GT(changed, static_cast<int>(a.rgb.size() / 4));
}

// ---- statistics -------------------------------------------------------------------------------

TEST_F(CliTest, StatsJsonHasEveryContractKeyAndRaysAddUp) {
    const Outcome r = run({"scene.xml", "-q", "--spp", "3", "--stats", "-", "-o", "a.pfm"});
    ASSERT_EQ(r.status, 0) << r.err;
    const Json j = parse_json(r.out);
    EXPECT_GE(j["seconds"].number(), 0);
    EXPECT_EQ(j["width"].number(), 24);
    EXPECT_EQ(j["height"].number(), 16);
    EXPECT_EQ(j["samples_per_pixel"].number(), 3);
    const Json& rays = j["rays"];
    EXPECT_EQ(rays["camera"].number(), 24 * 16 * 3);
    EXPECT_GT(rays["shadow"].number(), 0);
    EXPECT_GT(rays["reflection"].number(), 0);
    EXPECT_GT(rays["refraction"].number(), 0);
    // drt's own keys besides the contract's: the total and the settings the render used.
    EXPECT_EQ(rays["total"].number(), rays["camera"].number() + rays["shadow"].number() +
                                          rays["reflection"].number() +
                                          rays["refraction"].number());
    EXPECT_EQ(j["shadow_rays"].number(), 2);
    EXPECT_EQ(j["glossy_rays"].number(), 1);
    EXPECT_EQ(j["max_depth"].number(), 8);
    EXPECT_EQ(j["seed"].number(), 3);
    EXPECT_EQ(std::get<std::string>(j["sampler"].value), "stratified");
    EXPECT_EQ(j["mean_spp"].number(), 3);
    EXPECT_GE(j["million_rays_per_second"].number(), 0);
    // The tail is part of the render; a single process receives no tile messages.
    EXPECT_GE(j["tail_seconds"].number(), 0);
    EXPECT_LE(j["tail_seconds"].number(), j["seconds"].number());
    EXPECT_EQ(r.out.find("tile_messages"), std::string::npos) << r.out;
    const Json& effects = j["effects"];
    EXPECT_TRUE(effects["antialiasing"].boolean());
    EXPECT_TRUE(effects["soft_shadows"].boolean());
    EXPECT_FALSE(effects["glossy_reflection"].boolean());
    EXPECT_FALSE(effects["glossy_refraction"].boolean());
    EXPECT_FALSE(effects["depth_of_field"].boolean());
    EXPECT_FALSE(effects["motion_blur"].boolean());

    // To a file, the same keys; the count of camera rays does not depend on the thread count.
    const Outcome to_file = run({"scene.xml", "-q", "--spp", "3", "--threads", "1", "--stats",
                                 "stats.json", "-o", "b.pfm"});
    ASSERT_EQ(to_file.status, 0) << to_file.err;
    EXPECT_EQ(to_file.out, "");
    const Json f = parse_json(read_bytes(file("stats.json")));
    for (const char* kind : {"camera", "shadow", "reflection", "refraction"}) {
        EXPECT_EQ(f["rays"][kind].number(), rays[kind].number()) << kind;
    }
}

TEST_F(CliTest, StatsShowOnlyWhatASceneCallsFor) {
    // One sample per pixel and a point light: no antialiasing, one shadow ray per shading point.
    const Outcome r = run({"scene.xml", "-q", "--spp", "1", "--stats", "-", "-o", "a.pfm"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(parse_json(r.out)["effects"]["antialiasing"].boolean());
}

// The path integrator's keys are in its renders' statistics only: a distributed render's keys
// are those it had before that integrator existed.
// The distributed integrator traces no diffuse rays and says so: the keys are there, 0 and false.
TEST_F(CliTest, DiffuseRaysAndIndirectLightOnlyInAPathRendersStats) {
    const Outcome distributed =
        run({"scene.xml", "-q", "--spp", "2", "--stats", "-", "-o", "a.pfm"});
    ASSERT_EQ(distributed.status, 0) << distributed.err;
    const Json d = parse_json(distributed.out);
    EXPECT_EQ(d["rays"]["diffuse"].number(), 0);
    EXPECT_FALSE(d["effects"]["indirect_light"].boolean());

    std::string path_scene = kScene;
    path_scene.replace(path_scene.find("<Render "), 8, "<Render Integrator=\"path\" ");
    write_bytes(file("path.xml"), path_scene);
    const Outcome path = run({"path.xml", "-q", "--spp", "2", "--stats", "-", "-o", "b.pfm"});
    ASSERT_EQ(path.status, 0) << path.err;
    const Json p = parse_json(path.out);
    const Json& rays = p["rays"];
    EXPECT_GT(rays["diffuse"].number(), 0);
    EXPECT_EQ(rays["total"].number(), rays["camera"].number() + rays["shadow"].number() +
                                          rays["reflection"].number() +
                                          rays["refraction"].number() + rays["diffuse"].number());
    EXPECT_TRUE(p["effects"]["indirect_light"].boolean());
}

// ---- batch
// ----------------------------------------------------------------------------------------

TEST_F(CliTest, BatchRendersEveryGoodSceneReportsAndExitsWithTheHighestStatus) {
    fs::copy_file(file("scene.xml"), file("a.xml"));
    write_bytes(file("bad.xml"),
                "<Scene>\n  <Sphere Px=\"1\" Py=\"1\" Pz=\"1\" Radius=\"-3\" "
                "Material=\"Grey\"/>\n</Scene>\n");
    std::string c = kScene;
    c.replace(c.find("Width=\"24\""), 10, "Width=\"30\"");
    write_bytes(file("c.xml"), c);

    const Outcome r = run({"a.xml", "bad.xml", "c.xml", "-o", "out/renders/", "-q"});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(entries(file("out/renders")), (std::vector<std::string>{"a.png", "c.png"}));
    EXPECT_EQ(read_image(file("out/renders/a.png")).width, 24);
    EXPECT_EQ(read_image(file("out/renders/c.png")).width, 30);
    EXPECT_NE(r.err.find("bad.xml:2: Sphere: negative radius -3"), std::string::npos) << r.err;

    // The summary: a header, then one row per scene in the order given.
    std::vector<std::string> lines;
    for (std::size_t start = 0, end; (end = r.out.find('\n', start)) != std::string::npos;
         start = end + 1) {
        lines.push_back(r.out.substr(start, end - start));
    }
    ASSERT_EQ(lines.size(), 4u) << r.out;
    EXPECT_TRUE(regex_search(lines[0], "^scene +size +samples +seconds +Mrays/s +status$"))
        << lines[0];
    const char* good = R"(^(a|c)\.xml +(24|30)x16 +4 +[0-9]+\.[0-9]{2} +[0-9]+\.[0-9]{2} +ok$)";
    EXPECT_TRUE(regex_search(lines[1], good)) << lines[1];
    EXPECT_TRUE(regex_search(lines[3], good)) << lines[3];
    EXPECT_NE(lines[1].find("24x16"), std::string::npos);
    EXPECT_NE(lines[3].find("30x16"), std::string::npos);
    EXPECT_TRUE(regex_search(lines[2], R"(^bad\.xml .* bad input$)")) << lines[2];

    // All good: exit 0; an existing folder is fine.
    const Outcome ok = run({"a.xml", "c.xml", "-o", "out/renders", "-q"});
    EXPECT_EQ(ok.status, 0) << ok.err;

    // An interrupt ends the batch with the scene in hand, which the summary says.
    const Outcome stopped =
        run({"a.xml", "c.xml", "-o", "out/stopped/", "-q", "--stop-after-tiles", "1"});
    EXPECT_EQ(stopped.status, 130) << stopped.err;
    EXPECT_TRUE(regex_search(stopped.out, "\na\\.xml .* interrupted\n$")) << stopped.out;
    EXPECT_EQ(stopped.out.find("c.xml"), std::string::npos) << stopped.out;
}

TEST_F(CliTest, BatchStatsListEveryRenderedScene) {
    fs::copy_file(file("scene.xml"), file("a.xml"));
    fs::copy_file(file("scene.xml"), file("b.xml"));
    const Outcome r = run({"a.xml", "b.xml", "-o", "out", "-q", "--stats", "-"});
    ASSERT_EQ(r.status, 0) << r.err;
    const Json j = parse_json(r.out);  // the summary table goes to stderr here
    const auto& scenes = std::get<JsonArray>(j["scenes"].value);
    ASSERT_EQ(scenes.size(), 2u);
    for (const Json& s : scenes) EXPECT_EQ(s["rays"]["camera"].number(), 24 * 16 * 4);
    EXPECT_NE(r.err.find("a.xml"), std::string::npos);
}

// ---- compare -----------------------------------------------------------------------------------

class CompareCliTest : public CliTest {
  protected:
    void SetUp() override {
        CliTest::SetUp();
        write_image(constant(4, 3, 0.25f), file("quarter.pfm"));
        write_image(constant(4, 3, 0.25f), file("quarter2.pfm"));
        write_image(constant(4, 3, 0.5f), file("half.pfm"));
        write_image(constant(5, 3, 0.25f), file("wide.pfm"));
    }
    static Image constant(int w, int h, float v) {
        Image image(w, h);
        std::fill(image.rgb.begin(), image.rgb.end(), v);
        return image;
    }
};

TEST_F(CompareCliTest, EqualImagesExitZeroWithZeroError) {
    const Outcome r = run({"compare", "quarter.pfm", "quarter2.pfm", "--max-rmse", "0"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.rfind("rmse=0 psnr=inf ssim=1 ", 0), 0u) << r.out;
}

TEST_F(CompareCliTest, DifferentImagesPrintTheirErrorAndFailOnlyBeyondTolerance) {
    // Every value differs by 0.25: rmse 0.25, psnr 20 log10(4) = 12.0412 dB.
    const Outcome plain = run({"compare", "quarter.pfm", "half.pfm"});
    EXPECT_EQ(plain.status, 0);
    EXPECT_EQ(plain.out.rfind("rmse=0.25 psnr=12.0412 ", 0), 0u) << plain.out;

    EXPECT_EQ(run({"compare", "quarter.pfm", "half.pfm", "--max-rmse", "0.25"}).status, 0);
    const Outcome over = run({"compare", "quarter.pfm", "half.pfm", "--max-rmse", "0.2499"});
    EXPECT_EQ(over.status, 1);
    EXPECT_NE(over.err.find("exceeds --max-rmse"), std::string::npos) << over.err;
    EXPECT_EQ(run({"compare", "quarter.pfm", "half.pfm", "--min-psnr", "12"}).status, 0);
    EXPECT_EQ(run({"compare", "quarter.pfm", "half.pfm", "--min-psnr", "12.1"}).status, 1);
}

TEST_F(CompareCliTest, SizeMismatchAndUnreadableFilesExitTwo) {
    const Outcome size = run({"compare", "quarter.pfm", "wide.pfm", "--diff", "d.png"});
    EXPECT_EQ(size.status, 2);
    EXPECT_NE(size.err.find("4x3 vs 5x3"), std::string::npos) << size.err;
    write_bytes(file("garbage.png"), "not a png at all");
    write_image(constant(4, 3, 0.25f), file("quarter.png"));
    for (const auto& [a, b] :
         std::vector<std::pair<std::string, std::string>>{{"quarter.pfm", "missing.pfm"},
                                                          {"garbage.png", "quarter.png"},
                                                          {"quarter.pfm", "notes.txt"}}) {
        const Outcome r = run({"compare", a, b, "--diff", "d.png"});
        EXPECT_EQ(r.status, 2) << a << " " << b;
        EXPECT_NE(r.err.find(a == "garbage.png" ? a : b), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(file("d.png")));
    // 8-bit files of either kind compare with each other.
    write_image(constant(4, 3, 0.25f), file("quarter.bmp"));
    EXPECT_EQ(run({"compare", "quarter.png", "quarter.bmp", "--max-rmse", "0"}).status, 0);
}

TEST_F(CompareCliTest, NanNeverPassesATolerance) {
    Image nan_image = constant(4, 3, 0.25f);
    nan_image.rgb[5] = std::numeric_limits<float>::quiet_NaN();
    write_image(nan_image, file("nan.pfm"));
    const Outcome plain = run({"compare", "quarter.pfm", "nan.pfm"});
    EXPECT_EQ(plain.status, 0);
    EXPECT_NE(plain.out.find("rmse=nan"), std::string::npos) << plain.out;
    EXPECT_NE(plain.out.find("nonfinite=1"), std::string::npos) << plain.out;
    EXPECT_EQ(run({"compare", "quarter.pfm", "nan.pfm", "--max-rmse", "1e30"}).status, 1);
    EXPECT_EQ(run({"compare", "nan.pfm", "nan.pfm", "--max-rmse", "1e30"}).status, 1);
    EXPECT_EQ(run({"compare", "quarter.pfm", "nan.pfm", "--min-psnr", "-1e30"}).status, 1);

    Image inf_image = constant(4, 3, 0.25f);
    inf_image.rgb[0] = std::numeric_limits<float>::infinity();
    write_image(inf_image, file("inf.pfm"));
    EXPECT_EQ(run({"compare", "quarter.pfm", "inf.pfm", "--max-rmse", "1e30"}).status, 1);
}

TEST_F(CompareCliTest, DiffWritesAFalseColourImageOfTheSameSize) {
    Image spot = constant(4, 3, 0.25f);
    spot.set(2, 1, {0.9, 0.25, 0.25});
    write_image(spot, file("spot.pfm"));
    const Outcome r = run({"compare", "quarter.pfm", "spot.pfm", "--diff", "d.png"});
    EXPECT_EQ(r.status, 0) << r.err;
    const Image d = read_image(file("d.png"));
    ASSERT_EQ(d.width, 4);
    ASSERT_EQ(d.height, 3);
    EXPECT_EQ(d.at(2, 1), (Color{1, 0, 0}));  // the largest error: red
    EXPECT_EQ(d.at(0, 0), (Color{0, 0, 0}));  // equal: black
    // An unwritable diff is reported after the measures, with status 1.
    const Outcome bad = run({"compare", "quarter.pfm", "spot.pfm", "--diff", "no/such/d.png"});
    EXPECT_EQ(bad.status, 1);
    EXPECT_EQ(bad.out.rfind("rmse=", 0), 0u);
}

// ---- OpenEXR ------------------------------------------------------------------------------------

TEST_F(CliTest, ExrOutputHasTheRendersFloatsAndSaysHowItWasMade) {
    ASSERT_EQ(
        run({"scene.xml", "-q", "--spp", "3", "--seed", "11", "--sampler", "sobol", "-o", "a.exr"})
            .status,
        0);
    ASSERT_EQ(
        run({"scene.xml", "-q", "--spp", "3", "--seed", "11", "--sampler", "sobol", "-o", "a.pfm"})
            .status,
        0);
    const Image exr = read_image(file("a.exr")), pfm = read_image(file("a.pfm"));
    EXPECT_EQ(exr.rgb, pfm.rgb);  // the same floats as the .pfm, bit for bit

    // OpenEXR's own tool lists the attributes with their types.
    const std::string header = shell_output("exrheader " + file("a.exr").string() + " 2>&1");
    ASSERT_NE(header.find("file format version: 2"), std::string::npos)
        << "exrheader (Debian package openexr, tools/install-deps.sh) failed: " << header;
    for (const char* expected : {
             "scene (type string): \"scene.xml\"",
             "software (type string): \"drt " DRT_VERSION "\"",
             "samplesPerPixel (type int): 3",
             "seed (type string): \"11\"",
             "sampler (type string): \"sobol\"",
             "renderSeconds (type double): ",
             "R, 32-bit floating-point",
             "compression (type compression): zip",
         }) {
        EXPECT_NE(header.find(expected), std::string::npos) << expected << "\n" << header;
    }

    // --exr-half: 16-bit channels, values within half's precision.
    ASSERT_EQ(run({"scene.xml", "-q", "--spp", "3", "--seed", "11", "--sampler", "sobol",
                   "--exr-half", "-o", "h.exr"})
                  .status,
              0);
    EXPECT_NE(shell_output("exrheader " + file("h.exr").string()).find("R, 16-bit floating-point"),
              std::string::npos);
    const Image half = read_image(file("h.exr"));
    for (std::size_t i = 0; i < half.rgb.size(); ++i) {
        ASSERT_NEAR(half.rgb[i], pfm.rgb[i], std::abs(pfm.rgb[i]) * 0x1p-11 + 0x1p-25) << i;
    }
}

TEST_F(CliTest, AdaptiveRenderRecordsItsThresholdInTheExrHeader) {
    ASSERT_EQ(run({"scene.xml", "-q", "--spp", "32", "--noise-threshold", "0.05", "--min-spp", "4",
                   "-o", "a.exr"})
                  .status,
              0);
    const std::string header = shell_output("exrheader " + file("a.exr").string());
    EXPECT_NE(header.find("noiseThreshold (type double): 0.05"), std::string::npos) << header;
    EXPECT_NE(header.find("minSamplesPerPixel (type int): 4"), std::string::npos) << header;
    EXPECT_NE(header.find("samplesPerPixel (type int): 32"), std::string::npos) << header;
}

// --aov: the listed channels beside R, G and B; the image's own floats untouched; anything but
// one .exr output refused before rendering.
TEST_F(CliTest, AovsAreExtraExrChannelsAndOtherOutputsAreRefused) {
    ASSERT_EQ(run({"scene.xml", "-q", "-o", "plain.exr"}).status, 0);
    const Outcome r = run({"scene.xml", "-q", "--aov", "albedo,normal,depth", "-o", "a.exr"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(read_image(file("a.exr")).rgb, read_image(file("plain.exr")).rgb);
    const std::string header = shell_output("exrheader " + file("a.exr").string());
    for (const char* channel : {"albedo.R, 32", "albedo.G, 32", "albedo.B, 32", "normal.X, 32",
                                "normal.Y, 32", "normal.Z, 32", "depth.Z, 32"}) {
        EXPECT_NE(header.find(channel), std::string::npos) << channel << "\n" << header;
    }
    // The bottom-left pixel sees the grey floor (diffuse 1, kd 0.7), facing up; the top-left
    // one sees the sky: 0 in every channel.
    const std::size_t bottom = 15 * 24, top = 0;
    EXPECT_EQ(read_exr_channel(file("a.exr"), "albedo.G")[bottom], 0.7f);
    EXPECT_EQ(read_exr_channel(file("a.exr"), "normal.Y")[bottom], 1.0f);
    EXPECT_GT(read_exr_channel(file("a.exr"), "depth.Z")[bottom], 2.0f);
    for (const char* channel : {"albedo.R", "normal.Y", "depth.Z"}) {
        EXPECT_EQ(read_exr_channel(file("a.exr"), channel)[top], 0.0f) << channel;
    }
    EXPECT_THROW(read_exr_channel(file("plain.exr"), "depth.Z"), ImageError);

    const std::vector<std::pair<std::vector<std::string>, std::string>> refused = {
        {{"scene.xml", "--aov", "albedo", "-o", "a.png"},
         "drt: --aov needs an .exr output (-o FILE.exr): only OpenEXR holds the extra channels\n"},
        {{"scene.xml", "--aov", "albedo"},  // scene.png
         "drt: --aov needs an .exr output (-o FILE.exr): only OpenEXR holds the extra channels\n"},
        {{"scene.xml", "--aov", "albedo,z", "-o", "a.exr"},
         "drt: --aov: unknown AOV 'z' (known: albedo, normal, depth)\n"},
        {{"scene.xml", "scene.xml", "--aov", "depth", "-o", "out/"},
         "drt: --aov takes one scene, not a batch\n"},
        {{"scene.xml", "--aov", "depth", "--target-error", "0.1", "-o", "a.exr"},
         "drt: --aov excludes --target-error\n"},
    };
    for (const auto& [args, message] : refused) {
        fs::remove(file("a.exr"));
        const Outcome bad = run(args);
        EXPECT_EQ(bad.status, 2) << args.back();
        EXPECT_EQ(bad.err.rfind(message, 0), 0u) << bad.err;
        EXPECT_EQ(entries(dir_), (std::vector<std::string>{"plain.exr", "scene.xml"})) << bad.err;
    }
}

TEST_F(CompareCliTest, ExrComparesWithPfmAndWithEightBitFilesByTheirStoredValues) {
    write_image(constant(4, 3, 0.25f), file("quarter.exr"));
    const Outcome same = run({"compare", "quarter.exr", "quarter.pfm", "--max-rmse", "0"});
    EXPECT_EQ(same.status, 0) << same.err;
    EXPECT_EQ(same.out.rfind("rmse=0 psnr=inf ssim=1 ", 0), 0u) << same.out;
    const Outcome differ = run({"compare", "half.pfm", "quarter.exr", "--diff", "d.exr"});
    EXPECT_EQ(differ.out.rfind("rmse=0.25 psnr=12.0412 ", 0), 0u) << differ.out;
    EXPECT_EQ(read_image(file("d.exr")).width, 4);

    // Linear against 8-bit: the stored values, as the contract measures them (0.25 against the
    // sRGB code of 0.25, 137, as 137/255), with a warning that the tone curve is in them.
    write_image(constant(4, 3, 0.25f), file("quarter.png"));
    const Outcome mixed = run({"compare", "quarter.exr", "quarter.png", "--max-rmse", "0.3"});
    EXPECT_EQ(mixed.status, 0) << mixed.err;
    EXPECT_EQ(mixed.out.rfind("rmse=" + format_measure(137.0 / 255 - 0.25) + " ", 0), 0u)
        << mixed.out;
    EXPECT_EQ(mixed.err,
              "drt compare: warning: quarter.exr holds linear values and quarter.png "
              "sRGB-encoded 8-bit ones: the measures include the tone curve\n");
}

TEST_F(CompareCliTest, CorruptOrTruncatedExrExitsTwoNamingTheFile) {
    write_image(constant(40, 30, 0.25f), file("good.exr"));
    const std::string bytes = read_bytes(file("good.exr"));
    std::string flipped = bytes;
    for (std::size_t i = bytes.size() / 2; i < bytes.size(); i += 7) flipped[i] ^= 0x5a;
    const std::vector<std::pair<std::string, std::string>> bad{
        {"empty.exr", ""},
        {"text.exr", "not an exr file"},
        {"header-only.exr", bytes.substr(0, bytes.size() / 3)},
        {"cut.exr", bytes.substr(0, bytes.size() - 10)},
        {"flipped.exr", flipped},
    };
    for (const auto& [name, content] : bad) {
        write_bytes(file(name), content);
        const Outcome r = run({"compare", name, "good.exr", "--diff", "d.png"});
        EXPECT_EQ(r.status, 2) << name << ": " << r.err;
        EXPECT_EQ(r.err.rfind("drt compare: " + name + ": ", 0), 0u) << r.err;
        EXPECT_EQ(r.out, "");
    }
    EXPECT_FALSE(fs::exists(file("d.png")));
}

// ---- progress
// ------------------------------------------------------------------------------------

// Long enough on one thread that the display updates before the end (it does every 250 ms).
const std::vector<std::string> kSlowRender{"scene.xml", "--threads", "1",    "--width",
                                           "240",       "--height",  "160",  "--spp",
                                           "64",        "-o",        "p.png"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

TEST_F(CliTest, ProgressShowsPercentElapsedAndRemainingWhenForced) {
    const Outcome r = run(with(kSlowRender, {"--progress"}));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(regex_search(
        r.err, "\rscene\\.xml +[0-9]{1,2}%  [0-9]+:[0-9]{2} elapsed, [0-9]+:[0-9]{2} left"))
        << r.err;
    EXPECT_TRUE(regex_search(r.err, "\rscene\\.xml 100%  [0-9]+:[0-9]{2} elapsed *\n")) << r.err;
    EXPECT_EQ(r.out, "");  // never on stdout
}

TEST_F(CliTest, NoProgressWhenStderrIsNotATerminalOrWhenQuiet) {
    const Outcome piped = run({"scene.xml", "-o", "p.png"});
    EXPECT_EQ(piped.status, 0);
    EXPECT_EQ(piped.err.find('%'), std::string::npos) << piped.err;
    EXPECT_EQ(piped.err.rfind("drt: wrote p.png (24x16, 4 spp, ", 0), 0u) << piped.err;
    const Outcome quiet = run({"scene.xml", "-o", "p.png", "-q", "--progress"});
    EXPECT_EQ(quiet.status, 0);
    EXPECT_EQ(quiet.err, "");
}

TEST_F(CliTest, ProgressAppearsOnATerminalUnlessQuiet) {
    const std::string shown = run_drt_on_terminal(kSlowRender, dir_);
    EXPECT_NE(shown.find("100%"), std::string::npos) << shown;
    EXPECT_NE(shown.find("elapsed"), std::string::npos) << shown;
    const std::string quiet = run_drt_on_terminal(with(kSlowRender, {"-q"}), dir_);
    EXPECT_EQ(quiet, "");
}

// ---- robustness (issue 15): nothing a user types or feeds in crashes drt -----------------------

// kScene with `from` replaced by `to`.
std::string scene_with(const std::string& from, const std::string& to) {
    std::string scene = kScene;
    const std::size_t at = scene.find(from);
    if (at == std::string::npos) throw std::invalid_argument(from);
    return scene.replace(at, from.size(), to);
}

TEST_F(CliTest, OutputPathsThatCannotBeExaminedFailWithAMessage) {
    const std::string long_name(300, 'a');  // past NAME_MAX
    fs::create_symlink("loop", file("loop"));
    for (const std::string& out : std::vector<std::string>{long_name + "/x.png", "loop/x.png"}) {
        const Outcome r = run({"scene.xml", "-o", out, "-q"});
        EXPECT_EQ(r.status, 1) << out;
        EXPECT_TRUE(regex_search(r.err,
                                 "x\\.png: cannot create file: (File name too long|Too "
                                 "many levels of symbolic links)\n$"))
            << r.err;
    }
    // As a batch folder: refused before any render, with the reason.
    for (const std::string& out : std::vector<std::string>{long_name + "/", "loop/"}) {
        const Outcome r = run({"scene.xml", "scene.xml", "-o", out, "-q"});
        EXPECT_EQ(r.status, 1) << out;
        EXPECT_NE(r.err.find(": cannot create folder: "), std::string::npos) << r.err;
    }
    // A name too long to examine is taken for a file name, not a folder.
    const Outcome r = run({"scene.xml", "-o", long_name, "-q"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("unsupported image format"), std::string::npos) << r.err;
}

TEST_F(CliTest, OptionsAtTheirLimitsAreAcceptedAndJustPastThemRefused) {
    // `info` applies the overrides without rendering, so a limit can be tested at its value.
    const std::vector<std::pair<std::string, std::string>> at_and_past{
        {"--width", "65536"},
        {"--height", "65536"},
        {"--spp", "65536"},
        {"--shadow-rays", "65536"},
        {"--glossy-rays", "65536"},
        {"--max-depth", "512"},
        {"--seed", "18446744073709551615"}};
    for (const auto& [option, limit] : at_and_past) {
        const Outcome at = run({"info", "scene.xml", option, limit});
        EXPECT_EQ(at.status, 0) << option << at.err;
        const std::string past =
            option == "--seed" ? "18446744073709551616" : std::to_string(std::stoll(limit) + 1);
        const Outcome r = run({"scene.xml", option, past, "-o", "out.png"});
        EXPECT_EQ(r.status, 2) << option;
        const std::string lowest = option == "--max-depth" || option == "--seed" ? "0" : "1";
        EXPECT_EQ(r.err, "drt: " + option + ": must be an integer from " + lowest + " to " + limit +
                             ", got " + past + "\nRun 'drt --help' for usage.\n");
    }
    // --scale: the scaled size is checked (24x16 times 2730.66 is 65536 wide; 2731 is not).
    EXPECT_EQ(run({"info", "scene.xml", "--scale", "2730.66"}).status, 0);
    const Outcome scaled = run({"scene.xml", "--scale", "2731", "-o", "out.png"});
    EXPECT_EQ(scaled.status, 2);
    EXPECT_EQ(scaled.err,
              "drt: scene.xml: --scale 2731 makes the image 65544x43696, past the limit of 65536 "
              "pixels a side\n");
    const Outcome huge = run({"scene.xml", "--scale", "1e9", "-o", "out.png"});
    EXPECT_EQ(huge.err,
              "drt: scene.xml: --scale 1e+09 makes the image 2.4e+10x1.6e+10, past "
              "the limit of 65536 pixels a side\n");
    // Pixels: each side within the limit, the product past it.
    const Outcome pixels =
        run({"scene.xml", "--width", "16385", "--height", "8192", "-o", "o.png"});
    EXPECT_EQ(pixels.status, 2);
    EXPECT_EQ(pixels.err,
              "drt: scene.xml: image size 16385x8192 (134225920 pixels) exceeds the "
              "limit of 134217728 pixels\n");
    EXPECT_FALSE(fs::exists(file("out.png")));
    EXPECT_FALSE(fs::exists(file("o.png")));
}

TEST_F(CliTest, NonFiniteNumbersAndNegativeSeedsAreRefusedLikeTheScenesOwn) {
    for (const auto& [option, value] :
         std::vector<std::pair<std::string, std::string>>{{"--scale", "nan"},
                                                          {"--scale", "inf"},
                                                          {"--noise-threshold", "nan"},
                                                          {"--noise-threshold", "-inf"}}) {
        const Outcome r = run({"scene.xml", option, value, "--stats", "s.json"});
        EXPECT_EQ(r.status, 2) << option << value;
        EXPECT_EQ(r.err, "drt: " + option + ": must be a finite positive number, got " + value +
                             "\nRun 'drt --help' for usage.\n");
        EXPECT_FALSE(fs::exists(file("s.json")));
    }
    const Outcome seed = run({"scene.xml", "--seed", "-1"});
    EXPECT_EQ(seed.status, 2);
    EXPECT_EQ(seed.err,
              "drt: --seed: must be an integer from 0 to 18446744073709551615, got -1\n"
              "Run 'drt --help' for usage.\n");
    write_bytes(file("neg.xml"), scene_with("Seed=\"3\"", "Seed=\"-1\""));
    const Outcome scene_seed = run({"neg.xml"});
    EXPECT_EQ(scene_seed.status, 2);
    EXPECT_EQ(scene_seed.err,
              "neg.xml:4: Render: attribute 'Seed' is not a non-negative integer: \"-1\"\n");
    // Range errors print their bounds and values short, never 309 digits.
    const Outcome range = run({"scene.xml", "--scale", "-1e308"});
    EXPECT_EQ(range.err,
              "drt: --scale: must be a finite positive number, got -1e308\n"
              "Run 'drt --help' for usage.\n");
    // Options that may be zero say so, in the same words.
    const Outcome every = run({"scene.xml", "--checkpoint-every", "-1"});
    EXPECT_EQ(every.status, 2);
    EXPECT_EQ(every.err,
              "drt: --checkpoint-every: must be a finite non-negative number, got -1\n"
              "Run 'drt --help' for usage.\n");
    const Outcome rmse = run({"compare", "a.png", "b.png", "--max-rmse", "inf"});
    EXPECT_EQ(rmse.status, 2);
    EXPECT_EQ(rmse.err,
              "drt compare: --max-rmse: must be a finite non-negative number, got inf\n"
              "Run 'drt compare --help' for usage.\n");
}

TEST_F(CliTest, UnwritableStatsIsRefusedBeforeTheImageReplacesTheOutput) {
    write_bytes(file("out.png"), "old");
    fs::create_directories(file("stats.json"));
    for (const std::string stats : {"missing/s.json", "stats.json"}) {
        const Outcome r = run({"scene.xml", "-o", "out.png", "--stats", stats});
        EXPECT_EQ(r.status, 2) << stats;
        EXPECT_TRUE(regex_search(r.err,
                                 "^drt: --stats .*s\\.json: cannot (create|write) file: "
                                 "(No such file or directory|Is a directory)\n$"))
            << r.err;
        EXPECT_EQ(read_bytes(file("out.png")), "old");
    }
    EXPECT_EQ(entries(dir_), (std::vector<std::string>{"out.png", "scene.xml", "stats.json"}));
}

TEST_F(CliTest, NonFinitePixelsAreCountedAndFailTheRun) {
    // Finite in the scene, beyond a float in the image: 1e39 and a background of 1.7e308.
    write_bytes(file("bright.xml"), scene_with("Ir=\"1\"", "Ir=\"1e39\""));
    const Outcome r = run({"bright.xml", "-o", "bright.png", "-q"});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(regex_search(r.err,
                             "^drt: bright\\.xml: [0-9]+ of 1152 channel values are not "
                             "finite \\(radiance beyond the float range: a light, "
                             "background or ambient too bright\\?\\)\n"
                             "drt: bright\\.xml: .*bright\\.png not written; the image is kept "
                             "for inspection in .*bright\\.nonfinite\\.pfm\n$"))
        << r.err;
    // A radiance that rays see as it is, past a float, is refused where it is written.
    write_bytes(file("sky.xml"), scene_with("<Background r=\"0.1\"", "<Background r=\"1.7e308\""));
    const Outcome sky = run({"sky.xml", "-o", "sky.pfm", "-q"});
    EXPECT_EQ(sky.status, 2);
    EXPECT_TRUE(regex_search(sky.err,
                             "^sky\\.xml:[0-9]+: Background: r must be at most "
                             "3\\.40282e\\+38 \\(the largest value a float image "
                             "holds\\), got 1\\.7e308\n$"))
        << sky.err;
    EXPECT_FALSE(fs::exists(file("sky.pfm")));
    EXPECT_EQ(run({"scene.xml", "-o", "ok.pfm", "-q"}).status, 0);
}

TEST_F(CliTest, NonFinitePixelsLeaveTheOutputAsItWasAndKeepTheImageBesideIt) {
    write_bytes(file("bright.xml"), scene_with("Ir=\"1\"", "Ir=\"1e39\""));
    write_bytes(file("out.png"), "an earlier render");
    const Outcome r = run({"bright.xml", "-o", "out.png"});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(read_bytes(file("out.png")), "an earlier render");
    // The inspection image holds the very values the message counts.
    const Image kept = read_image(file("out.nonfinite.pfm"));
    EXPECT_EQ(kept.width * kept.height * 3, 1152);
    const auto bad =
        std::count_if(kept.rgb.begin(), kept.rgb.end(), [](float v) { return !std::isfinite(v); });
    EXPECT_GT(bad, 0);
    EXPECT_NE(r.err.find("drt: wrote out.nonfinite.pfm ("), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("estimated RMSE n/a (a pixel's spread is not finite (fewer than 2 "
                         "samples, or radiance past the float range))"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("drt: bright.xml: " + std::to_string(bad) +
                         " of 1152 channel values are not finite"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("drt: bright.xml: out.png not written; the image is kept for "
                         "inspection in out.nonfinite.pfm\n"),
              std::string::npos)
        << r.err;
    // No earlier output: none is made; in a batch, the image is kept beside the scene's output.
    const Outcome fresh = run({"bright.xml", "-o", "fresh.pfm", "-q"});
    EXPECT_EQ(fresh.status, 2);
    const Outcome batch = run({"bright.xml", "scene.xml", "-o", "batch/", "-q"});
    EXPECT_EQ(batch.status, 2);
    EXPECT_EQ(entries(dir_),
              (std::vector<std::string>{"batch", "bright.xml", "fresh.nonfinite.pfm",
                                        "out.nonfinite.pfm", "out.png", "scene.xml"}));
    EXPECT_EQ(entries(file("batch")),
              (std::vector<std::string>{"bright.nonfinite.pfm", "scene.png"}));
}

TEST_F(CliTest, ControlCharactersAreEscapedInEveryMessage) {
    write_bytes(file("esc.xml"), scene_with("Material=\"Grey\"", "Material=\"\x1b[2J\x07\""));
    const Outcome r = run({"esc.xml", "-o", "x.png"});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err, "esc.xml:13: Plane: unknown material '\\x1b[2J\\x07'\n");
    const Outcome name = run({"no\x1b]0;such.xml"});
    EXPECT_EQ(name.err, "no\\x1b]0;such.xml: cannot open scene: No such file or directory\n");
    const Outcome option = run({"scene.xml", "--width", "\x1b[31m"});
    EXPECT_EQ(option.err.find('\x1b'), std::string::npos) << option.err;
}

TEST_F(CompareCliTest, FoldersAndEndlessFilesNamedLikeImagesExitTwo) {
    fs::create_directories(file("folder.pfm"));
    const Outcome folder = run({"compare", "folder.pfm", "quarter.pfm"});
    EXPECT_EQ(folder.status, 2);
    EXPECT_EQ(folder.err, "drt compare: folder.pfm: is a folder, not an image file\n");
    fs::create_symlink("/dev/zero", file("zero.pfm"));
    const Outcome zero = run({"compare", "quarter.pfm", "zero.pfm"});
    EXPECT_EQ(zero.status, 2);
    EXPECT_EQ(zero.err, "drt compare: zero.pfm: not a regular file\n");
}

// A batch goes on past every kind of failure, in loading or in the render, and ends with its
// summary: a bad scene, one past the memory budget only once the thread count is known, and one
// whose allocation fails for want of memory.
TEST_F(CliTest, BatchGoesOnPastScenesThatFailInLoadingOrRenderingAndPrintsItsSummary) {
    fs::copy_file(file("scene.xml"), file("a.xml"));
    write_bytes(file("bad.xml"), scene_with("Radius=\"1\" Material=\"Mirror\"",
                                            "Radius=\"-1\" Material=\"Mirror\""));
    // 2^27 pixels at 65536 samples: within every limit of the scene format, but 64 threads
    // would need 5.8 GiB.
    write_bytes(file("budget.xml"),
                scene_with("<Image Width=\"24\" Height=\"16\"/>\n  <Render Samples=\"4\"",
                           "<Image Width=\"16384\" Height=\"8192\"/>\n  <Render "
                           "Samples=\"65536\""));
    fs::copy_file(file("scene.xml"), file("c.xml"));
    const Outcome r =
        run({"a.xml", "bad.xml", "budget.xml", "c.xml", "-o", "out/", "-q", "--threads", "64"});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(entries(file("out")), (std::vector<std::string>{"a.png", "c.png"}));
    EXPECT_NE(r.err.find("bad.xml:14: Sphere: negative radius -1\n"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("drt: budget.xml: the render needs an estimated 5888 MiB (134217728 "
                         "pixels x 28 B + 64 threads x 65536 samples x 576 B), more than the "
                         "4096 MiB budget\n"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(regex_search(r.out,
                             "\na\\.xml .* ok\nbad\\.xml .* bad input\nbudget\\.xml .* bad "
                             "input\nc\\.xml .* ok\n$"))
        << r.out;
}

// ---- the error estimate ------------------------------------------------------------------------

TEST_F(CliTest, ErrorImageHoldsEachPixelsStandardErrorAndZeroForAFlatScene) {
    const Outcome r = run({"scene.xml", "-o", "out.pfm", "--error-image", "err.exr", "--stats",
                           "s.json", "--sampler", "random"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("spp, "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(" s, estimated RMSE 0."), std::string::npos) << r.err;
    const Image error = read_image(file("err.exr"));
    EXPECT_EQ(error.width, 24);
    EXPECT_EQ(error.height, 16);
    // Some pixels are noisy (the penumbra, the edges), none negative or not finite.
    EXPECT_GT(*std::max_element(error.rgb.begin(), error.rgb.end()), 0.01f);
    for (const float v : error.rgb) EXPECT_TRUE(std::isfinite(v) && v >= 0) << v;
    const std::string json = read_bytes(file("s.json"));
    EXPECT_NE(json.find("\"estimated_rmse\": 0."), std::string::npos) << json;
    EXPECT_NE(json.find("\"estimated_relmse\": "), std::string::npos) << json;
    // How many pixels the error sits in, from the error image's variances as from the render's,
    // and the spread of one image's true RMSE that follows.
    double sum = 0, squares = 0;
    for (std::size_t p = 0; p < error.rgb.size(); p += 3) {
        const double v = double(error.rgb[p]) * error.rgb[p] +
                         double(error.rgb[p + 1]) * error.rgb[p + 1] +
                         double(error.rgb[p + 2]) * error.rgb[p + 2];
        sum += v;
        squares += v * v;
    }
    const Json stats = parse_json(json);
    const double error_pixels = stats["error_pixels"].number();
    EXPECT_NEAR(error_pixels, sum * sum / squares, 1e-4 * error_pixels);
    EXPECT_GT(error_pixels, 1);
    EXPECT_LT(error_pixels, 24 * 16);
    EXPECT_NEAR(stats["rmse_scatter"].number(), 1 / std::sqrt(2 * error_pixels), 1e-5);

    // A scene of nothing but background: every sample alike, no error anywhere.
    write_bytes(file("flat.xml"),
                "<Scene>\n  <Image Width=\"6\" Height=\"4\"/>\n"
                "  <Render Samples=\"4\"/>\n  <Background r=\"0.5\" g=\"0.2\" "
                "b=\"0.1\"/>\n</Scene>\n");
    const Outcome flat = run({"flat.xml", "-o", "flat.pfm", "--error-image", "flat-err.pfm"});
    ASSERT_EQ(flat.status, 0) << flat.err;
    EXPECT_NE(flat.err.find("estimated RMSE 0)"), std::string::npos) << flat.err;
    const Image zero = read_image(file("flat-err.pfm"));
    EXPECT_EQ(zero.width, 6);
    EXPECT_EQ(zero.rgb, std::vector<float>(6 * 4 * 3, 0.0f));
}

TEST_F(CliTest, OneSampleHasNoEstimateAndSaysWhy) {
    const Outcome r = run({"scene.xml", "-o", "out.pfm", "--spp", "1", "--stats", "-"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("estimated RMSE n/a (1 spp takes the pixel centre: no spread to measure)"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("\"estimated_rmse\": null, \"estimated_relmse\": null, "
                         "\"estimate_unavailable\": \"1 spp takes the pixel centre: no spread "
                         "to measure\""),
              std::string::npos)
        << r.out;
}

TEST_F(CliTest, ABadErrorImagePathExitsTwoBeforeRendering) {
    const std::vector<std::pair<std::string, std::string>> cases{
        {"missing/e.pfm",
         "drt: --error-image missing/e.pfm: cannot create file: No such file or "
         "directory\n"},
        {"e.txt",
         "drt: --error-image e.txt: unsupported image format '.txt' (use .png, .bmp, "
         ".pfm or .exr)\n"}};
    for (const auto& [path, message] : cases) {
        const Outcome r = run({"scene.xml", "-o", "out.pfm", "--error-image", path});
        EXPECT_EQ(r.status, 2) << path;
        EXPECT_EQ(r.err, message);
        EXPECT_FALSE(fs::exists(file("out.pfm"))) << path;
    }
    const Outcome batch = run({"scene.xml", "scene.xml", "-o", "dir/", "--error-image", "e.pfm"});
    EXPECT_EQ(batch.status, 2);
    EXPECT_EQ(batch.err,
              "drt: --error-image takes one scene, not a batch\nRun 'drt --help' for usage.\n");
}

#if !defined(DRT_TEST_ASAN)  // ASan reserves terabytes of address space up front
TEST_F(CliTest, AllocationFailureInARenderFailsThatSceneOnly) {
    // 8192 x 8192 pixels: within the limits, but its 768 MiB image cannot be had under a 512 MiB
    // cap on the address space.
    write_bytes(file("big.xml"),
                scene_with("Width=\"24\" Height=\"16\"", "Width=\"8192\" Height=\"8192\""));
    fs::copy_file(file("scene.xml"), file("a.xml"));
    fs::copy_file(file("scene.xml"), file("c.xml"));
    const Outcome r =
        run({"a.xml", "big.xml", "c.xml", "-o", "out/", "-q", "--threads", "2"}, rlim_t{512} << 20);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err, "drt: big.xml: out of memory\n");
    EXPECT_EQ(entries(file("out")), (std::vector<std::string>{"a.png", "c.png"}));
    EXPECT_TRUE(regex_search(r.out, "\nbig\\.xml .* failed\nc\\.xml .* ok\n$")) << r.out;
}
#endif

}  // namespace
}  // namespace drt

namespace drt {
namespace {

namespace fs = std::filesystem;
using namespace test;

// A glass ball over a floor under a Falloff-1 light, with photons: 4 x 4 pixels, 2 samples.
constexpr const char* kCausticScene = R"(<Scene><Image Width="4" Height="4"/>
  <Render Samples="2"/><Photons Count="1000" Radius="0.1"/>
  <Camera Ex="0" Ey="5" Ez="-5" Lx="0" Ly="0" Lz="0"/>
  <Materials><Floor diffuse="1"/><Glass transmitt="1" index="1.5"/></Materials>
  <Light Px="0" Py="100" Pz="0" Falloff="1" Ir="1e4" Ig="1e4" Ib="1e4"/>
  <Plane Px="0" Py="0" Pz="0" Vu="0" Vv="1" Vw="0" Material="Floor"/>
  <Sphere Px="0" Py="1.5" Pz="0" Radius="1" Material="Glass"/></Scene>)";

class CliPhotons : public TempFolderTest {};

TEST_F(CliPhotons, StatsCountPhotonsAndGoalsAreRefusedWithoutAnEstimate) {
    write_bytes(dir_ / "c.xml", kCausticScene);
    const Outcome r = run_drt({"c.xml", "-o", "c.pfm", "--stats", "s.json"}, dir_);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string stats = read_bytes(dir_ / "s.json");
    EXPECT_NE(stats.find("\"photons\": 2000,"), std::string::npos) << stats;
    EXPECT_NE(stats.find("\"caustics\": true"), std::string::npos) << stats;
    EXPECT_NE(stats.find("\"estimated_rmse\": null"), std::string::npos) << stats;
    EXPECT_NE(r.err.find("estimated RMSE n/a"), std::string::npos) << r.err;
    for (const std::string goal : {"--target-error", "--time-limit"}) {
        const Outcome g = run_drt({"c.xml", "-o", "g.pfm", goal, "1"}, dir_);
        EXPECT_EQ(g.status, 2);
        EXPECT_EQ(g.err, "drt: c.xml: " + goal +
                             " cannot be used with <Photons>: caustics from photon maps are biased "
                             "at every finite gather radius, which the error estimate does not "
                             "see; give Samples instead (docs/accuracy.md)\n");
        EXPECT_FALSE(fs::exists(dir_ / "g.pfm"));
    }
    // Every pass's map is kept: Samples x Count x 48 B must fit a quarter of the budget.
    const Outcome big = run_drt({"c.xml", "-o", "g.pfm", "--spp", "65536"}, dir_);
    EXPECT_EQ(big.status, 2);
    EXPECT_EQ(big.err,
              "drt: c.xml: the photon maps need an estimated 3000 MiB (65536 passes x 1000 photons "
              "x 48 B), more than their 1024 MiB share of the budget: lower Samples or the "
              "Photons Count\n");
    const Outcome info = run_drt({"info", "c.xml"}, dir_);
    EXPECT_NE(info.out.find("caustics: sampled (photon maps: 1000 photons a pass"),
              std::string::npos)
        << info.out;
    const Outcome no_depth = run_drt({"info", "c.xml", "--max-depth", "0"}, dir_);
    EXPECT_NE(no_depth.out.find("caustics: off (<Photons> given, but MaxDepth 0 lets no light "
                                "reflect or refract)"),
              std::string::npos)
        << no_depth.out;
}

}  // namespace
}  // namespace drt
