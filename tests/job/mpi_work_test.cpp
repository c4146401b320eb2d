// Several processes (mpi_work.h): how drt knows mpirun started it, and the command line under
// `mpirun -n K`, which must give the single process's bits, ray counts and exit status for any K
// and any thread count, keep its checkpoints interchangeable with a single process's, and leave
// no half-written output when a process is killed. Skipped only where mpirun is not installed.
#include "drt/job/mpi_work.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "drt/io/image.h"
#include "drt/util/atomic_file.h"
#include "run_drt.h"
#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;
using namespace test;

TEST(LaunchedByMpirun, OnlyALaunchersVariablesCount) {
    const auto with = [](std::map<std::string, std::string> env) {
        return launched_by_mpirun([&](const char* name) -> const char* {
            const auto it = env.find(name);
            return it == env.end() ? nullptr : it->second.c_str();
        });
    };
    EXPECT_FALSE(with({}));
    EXPECT_FALSE(with({{"OMPI_COMM_WORLD_SIZE", ""}, {"HOME", "/root"}}));
    EXPECT_TRUE(with({{"OMPI_COMM_WORLD_SIZE", "2"}}));  // Open MPI's mpirun
    EXPECT_TRUE(with({{"PMIX_RANK", "0"}}));             // PMIx: srun --mpi=pmix
    EXPECT_TRUE(with({{"PMI_RANK", "1"}}));              // MPICH's hydra
}

TEST(BoundByMpirunDefault, OnlyMpirunsOwnBindingIsUndone) {
    const auto with = [](std::map<std::string, std::string> env) {
        return bound_by_mpirun_default([&](const char* name) -> const char* {
            const auto it = env.find(name);
            return it == env.end() ? nullptr : it->second.c_str();
        });
    };
    EXPECT_FALSE(with({}));  // not bound by mpirun (a plain run, srun, --bind-to none)
    EXPECT_TRUE(with({{"OMPI_MCA_orte_bound_at_launch", "1"}}));  // mpirun's default
    EXPECT_TRUE(
        with({{"OMPI_MCA_orte_bound_at_launch", "1"}, {"OMPI_MCA_hwloc_base_binding_policy", ""}}));
    // The user asked: mpirun --bind-to core (or the MCA variable) is kept.
    EXPECT_FALSE(with(
        {{"OMPI_MCA_orte_bound_at_launch", "1"}, {"OMPI_MCA_hwloc_base_binding_policy", "core"}}));
    EXPECT_FALSE(with({{"OMPI_MCA_orte_bound_at_launch", "0"}}));
}

// Motion blur, depth of field, glossy reflection, soft shadows.
const std::string kMotion = (kSourceDir / "scenes/thesis/test5.xml").string();
// Glossy reflection and refraction, depth of field, soft shadows.
const std::string kGlossy = (kSourceDir / "scenes/thesis/test6.xml").string();

using MpiModule = TempFolderTest;

TEST_F(MpiModule, APlainRunLoadsNoMpiLibrary) {
    // The dynamic loader lists every library it loads; a drt linked with MPI would list libmpi.
    const Outcome r = run_process({"env", "LD_DEBUG=libs", DRT_BINARY, "info", kGlossy}, dir_);
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_NE(r.err.find("find library=libstdc++"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("libmpi"), std::string::npos) << r.err;
}

TEST_F(MpiModule, UnderALauncherWithoutItDrtSaysWhatIsMissingAndExits2) {
    const fs::path alone = dir_ / "drt";
    fs::copy_file(DRT_BINARY, alone);
    const std::vector<std::string> argv{"env", "OMPI_COMM_WORLD_SIZE=1", alone.string(), "info",
                                        kGlossy};
    Outcome r = run_process(argv, dir_);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.out, "");
    const std::string missing =
        "drt: started by mpirun, but the MPI module is missing or broken (" +
        (dir_ / "drt_mpi.so").string() + ": cannot open shared object file";
    EXPECT_EQ(r.err.find(missing), 0u) << r.err;
    EXPECT_NE(r.err.find("keep drt_mpi.so beside the drt binary"), std::string::npos) << r.err;
    write_bytes(dir_ / "drt_mpi.so", "not a shared object");
    r = run_process(argv, dir_);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err.find("drt: started by mpirun, but the MPI module is missing or broken (" +
                         (dir_ / "drt_mpi.so").string() + ": "),
              0u)
        << r.err;
}

bool have_mpirun() {
    std::istringstream path(std::getenv("PATH") ? std::getenv("PATH") : "");
    for (std::string dir; std::getline(path, dir, ':');) {
        if (!dir.empty() && fs::exists(fs::path(dir) / "mpirun")) return true;
    }
    return false;
}

// The "rays" object of a --stats file, as text.
std::string rays_of(const fs::path& json) {
    const std::string text = read_bytes(json);
    const std::size_t at = text.find("\"rays\"");
    return at == std::string::npos ? "no rays in " + text
                                   : text.substr(at, text.find('}', at) - at);
}

// The image's own error estimate in a --stats file ("estimated_rmse": ... to the line's end), as
// text: a sum over tiles that must not depend on who rendered them.
std::string estimate_of(const fs::path& json) {
    const std::string text = read_bytes(json);
    const std::size_t at = text.find("\"estimated_rmse\"");
    return at == std::string::npos ? "no estimate in " + text
                                   : text.substr(at, text.find('\n', at) - at);
}

class MpiCli : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!have_mpirun()) GTEST_SKIP() << "mpirun is not installed";
        // Open MPI's own allocations are not ours to check in a sanitizer build.
        setenv("ASAN_OPTIONS", "detect_leaks=0", 0);
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string(info->test_suite_name()) + "_" + info->name();
        for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
        dir_ = fs::temp_directory_path() / ("drt_mpi_test_" + std::to_string(getpid()) + name);
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        // Each test's mpirun keeps its session files apart: two mpiruns starting at once (ctest
        // -j2) raced to create the shared /tmp/ompi.HOST.UID and one failed ("File exists").
        // A short path: Open MPI's sockets live under it.
        session_ = fs::temp_directory_path() / ("drt-ompi-" + std::to_string(getpid()));
        fs::remove_all(session_);
        fs::create_directories(session_);
        setenv("OMPI_MCA_orte_tmpdir_base", session_.c_str(), 1);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
        fs::remove_all(session_);
    }
    std::vector<std::string> mpirun(int processes, const std::vector<std::string>& args) const {
        std::vector<std::string> argv{"mpirun", "--allow-run-as-root",     "--oversubscribe",
                                      "-n",     std::to_string(processes), DRT_BINARY};
        argv.insert(argv.end(), args.begin(), args.end());
        return argv;
    }
    Outcome run_mpi(int processes, const std::vector<std::string>& args) const {
        return run_process(mpirun(processes, args), dir_);
    }
    Outcome run(const std::vector<std::string>& args) const { return run_drt(args, dir_); }
    std::string bytes(const std::string& name) const { return read_bytes(dir_ / name); }

    fs::path dir_;
    fs::path session_;
};

// A small render of `scene` into `output` with the given extra options.
std::vector<std::string> small(const std::string& scene, const std::string& output,
                               std::vector<std::string> more = {},
                               const std::string& size = "48x32") {
    const std::size_t x = size.find('x');
    std::vector<std::string> args{
        scene, "--width", size.substr(0, x), "--height", size.substr(x + 1), "-o", output};
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

class MpiProcessesAndThreads : public MpiCli,
                               public ::testing::WithParamInterface<std::pair<int, int>> {};

TEST_P(MpiProcessesAndThreads, AdaptiveRenderIsTheSingleProcesssBitsAndRayCounts) {
    const auto [processes, threads] = GetParam();
    const std::vector<std::string> adaptive{"--spp", "32", "--noise-threshold", "0.02", "--min-spp",
                                            "4",     "-q"};
    std::vector<std::string> plain = small(kMotion, "plain.pfm", adaptive);
    plain.insert(plain.end(), {"--stats", "plain.json"});
    ASSERT_EQ(run(plain).status, 0);
    std::vector<std::string> args = small(kMotion, "mpi.pfm", adaptive);
    args.insert(args.end(), {"--threads", std::to_string(threads), "--stats", "mpi.json"});
    const Outcome r = run_mpi(processes, args);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("mpi.pfm"), bytes("plain.pfm"));
    EXPECT_EQ(rays_of(dir_ / "mpi.json"), rays_of(dir_ / "plain.json"));
    EXPECT_EQ(estimate_of(dir_ / "mpi.json"), estimate_of(dir_ / "plain.json"));
    EXPECT_NE(estimate_of(dir_ / "mpi.json").find("\"estimated_rmse\": 0."), std::string::npos);
    EXPECT_NE(bytes("mpi.json").find("\"processes\": " + std::to_string(processes)),
              std::string::npos);
    EXPECT_EQ(r.out + r.err, "");  // -q: nothing from any process
}

// A path render's tile messages carry their diffuse ray counts to the leader.
TEST_F(MpiCli, PathRenderIsTheSingleProcesssBitsAndDiffuseRays) {
    const std::string cornell = (kSourceDir / "scenes/gi/cornell-box.xml").string();
    const std::vector<std::string> options{"--spp", "4", "-q"};
    std::vector<std::string> plain = small(cornell, "plain.pfm", options);
    plain.insert(plain.end(), {"--stats", "plain.json"});
    ASSERT_EQ(run(plain).status, 0);
    std::vector<std::string> args = small(cornell, "mpi.pfm", options);
    args.insert(args.end(), {"--threads", "1", "--stats", "mpi.json"});
    const Outcome r = run_mpi(3, args);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("mpi.pfm"), bytes("plain.pfm"));
    EXPECT_EQ(rays_of(dir_ / "mpi.json"), rays_of(dir_ / "plain.json"));
    EXPECT_NE(rays_of(dir_ / "mpi.json").find("\"diffuse\": "), std::string::npos);
    EXPECT_EQ(rays_of(dir_ / "mpi.json").find("\"diffuse\": 0,"), std::string::npos);
}

// Photon maps are functions of (seed, pass) alone, built by every process for itself: the caustic
// is the single process's to the bit, and every process counts the photons it traced once.
TEST_F(MpiCli, CausticRenderIsTheSingleProcesssBitsAndPhotons) {
    const std::string caustic = (kSourceDir / "scenes/caustics/test1-caustic.xml").string();
    const std::vector<std::string> options{"--spp", "4", "-q"};
    std::vector<std::string> plain = small(caustic, "plain.pfm", options);
    plain.insert(plain.end(), {"--stats", "plain.json"});
    ASSERT_EQ(run(plain).status, 0);
    std::vector<std::string> args = small(caustic, "mpi.pfm", options);
    args.insert(args.end(), {"--threads", "1", "--stats", "mpi.json"});
    const Outcome r = run_mpi(3, args);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("mpi.pfm"), bytes("plain.pfm"));
    EXPECT_EQ(rays_of(dir_ / "mpi.json"), rays_of(dir_ / "plain.json"));
    const std::string stats = bytes("mpi.json");
    EXPECT_NE(stats.find("\"photons\": 80000,"), std::string::npos) << stats;  // 4 passes of 20000
    EXPECT_NE(stats.find("\"caustics\": true"), std::string::npos) << stats;
}

// AOVs travel with the tiles: the leader's file has one process's channels.
TEST_F(MpiCli, AovsAreTheSingleProcesssValues) {
    const std::vector<std::string> options{"--spp", "4", "-q", "--aov", "albedo,normal,depth"};
    ASSERT_EQ(run(small(kGlossy, "one.exr", options)).status, 0);
    std::vector<std::string> args = small(kGlossy, "mpi.exr", options);
    args.insert(args.end(), {"--threads", "1"});
    const Outcome r = run_mpi(3, args);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(read_image(dir_ / "mpi.exr").rgb, read_image(dir_ / "one.exr").rgb);
    for (const char* channel :
         {"albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z", "depth.Z"}) {
        const std::vector<float> one = read_exr_channel(dir_ / "one.exr", channel);
        EXPECT_EQ(read_exr_channel(dir_ / "mpi.exr", channel), one) << channel;
        EXPECT_TRUE(std::any_of(one.begin(), one.end(), [](float v) { return v != 0; })) << channel;
    }
}

TEST_F(MpiCli, TargetErrorGivesTheSingleProcesssBits) {
    // Every round's count and weight is decided on the leader and shared, and so are a top-up
    // round's pixels: the same rounds as one process (here 8 spp and a top-up, combined).
    const std::vector<std::string> goal{"--target-error", "0.01", "--stats", "s.json", "-q"};
    ASSERT_EQ(run(small(kMotion, "one.pfm", goal, "32x24")).status, 0);
    const std::string one = bytes("s.json");
    EXPECT_NE(one.find("\"top_up_share\": "), std::string::npos) << one;
    const Outcome r = run_mpi(2, small(kMotion, "two.pfm", goal, "32x24"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("two.pfm"), bytes("one.pfm"));
    EXPECT_EQ(r.out + r.err, "");
}

TEST_F(MpiCli, TargetErrorWithAPilotOfSomePixelsGivesTheSingleProcesssBits) {
    // 128 x 128: the first round renders one pixel in 4 x 4 on every process's tiles; its estimate,
    // assembled on the leader, sizes the full rounds.
    const std::vector<std::string> goal{"--target-error", "0.01", "--stats", "s.json", "-q"};
    ASSERT_EQ(run(small(kMotion, "one.pfm", goal, "128x128")).status, 0);
    const std::string one = bytes("s.json");
    EXPECT_NE(one.find("\"pilot_pixel_block\": 4"), std::string::npos) << one;
    const Outcome r = run_mpi(3, small(kMotion, "three.pfm", goal, "128x128"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("three.pfm"), bytes("one.pfm"));
    const auto rounds = [](const std::string& stats) {
        return stats.substr(stats.find("\"rounds\""), stats.find("]}") - stats.find("\"rounds\""));
    };
    // The same rounds, their estimates included (their seconds differ).
    const auto without_seconds = [&](std::string text) {
        text = rounds(text);
        for (std::size_t at; (at = text.find("\"seconds\": ")) != std::string::npos;) {
            text.erase(at, text.find(',', at) + 1 - at);
        }
        return text;
    };
    EXPECT_EQ(without_seconds(bytes("s.json")), without_seconds(one));
    EXPECT_EQ(r.out + r.err, "");
}

INSTANTIATE_TEST_SUITE_P(KProcessesByThreads, MpiProcessesAndThreads,
                         ::testing::Values(std::pair{1, 1}, std::pair{1, 2}, std::pair{2, 1},
                                           std::pair{2, 2}, std::pair{3, 1}, std::pair{3, 2}));

TEST_F(MpiCli, EverySamplerGivesTheSameBitsAndOneProcessReports) {
    for (const std::string sampler : {"stratified", "sobol", "random"}) {
        ASSERT_EQ(run(small(kGlossy, "plain.pfm", {"--sampler", sampler, "--spp", "8"})).status, 0);
        const Outcome r = run_mpi(
            3, small(kGlossy, "mpi.pfm", {"--sampler", sampler, "--spp", "8", "--threads", "1"}));
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(bytes("mpi.pfm"), bytes("plain.pfm")) << sampler;
        // One "wrote" line: the leader's.
        EXPECT_EQ(r.err.find("drt: wrote mpi.pfm"), r.err.rfind("drt: wrote")) << r.err;
        EXPECT_NE(r.err.find("drt: wrote mpi.pfm"), std::string::npos) << r.err;
    }
}

TEST_F(MpiCli, BatchRendersEveryScenesImageOnceWithTheHighestStatus) {
    write_bytes(dir_ / "bad.xml", "<Scene><Image Width=\"-3\"/></Scene>");
    const std::vector<std::string> scenes{kMotion, "bad.xml", kGlossy};
    std::vector<std::string> args = scenes;
    args.insert(args.end(), {"--width", "32", "--height", "24", "--spp", "4", "-o"});
    std::vector<std::string> plain = args, mpi = args;
    plain.push_back("plain/");
    mpi.insert(mpi.end(), {"mpi/", "--threads", "1"});
    EXPECT_EQ(run(plain).status, 2);
    const Outcome r = run_mpi(2, mpi);
    EXPECT_EQ(r.status, 2) << r.err;
    for (const std::string image : {"test5.png", "test6.png"}) {
        ASSERT_TRUE(fs::exists(dir_ / "mpi" / image)) << r.out << r.err;
        EXPECT_EQ(bytes("mpi/" + image), bytes("plain/" + image)) << image;
    }
    EXPECT_FALSE(fs::exists(dir_ / "mpi/bad.png"));
    // The summary and the scene's error, each once.
    EXPECT_EQ(r.out.find("status"), r.out.rfind("status")) << r.out;
    EXPECT_EQ(r.err.find("bad.xml"), r.err.rfind("bad.xml")) << r.err;
}

TEST_F(MpiCli, StoppedUnderOneSplitResumedUnderAnotherGivesTheSameBits) {
    // 24 tiles: a stop after 2 or 6 leaves work, however many tiles are in hand elsewhere.
    const std::string kSize = "128x128";
    const std::vector<std::string> more{"--spp", "8", "--checkpoint", "c.ckpt"};
    ASSERT_EQ(
        run(small(kMotion, "plain.pfm", {"--spp", "8", "--stats", "plain.json"}, kSize)).status, 0);
    std::vector<std::string> args = small(kMotion, "out.pfm", more, kSize);
    args.insert(args.end(), {"--threads", "1", "--stop-after-tiles", "2"});
    Outcome r = run_mpi(2, args);
    EXPECT_EQ(r.status, 130) << r.err;
    EXPECT_TRUE(fs::exists(dir_ / "out.partial.pfm"));
    EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
    args.back() = "6";
    r = run_mpi(3, args);
    EXPECT_EQ(r.status, 130) << r.err;
    EXPECT_NE(r.err.find("run the same command again to resume"), std::string::npos) << r.err;
    std::vector<std::string> last = small(kMotion, "out.pfm", more, kSize);
    last.insert(last.end(), {"--stats", "out.json"});
    r = run(last);  // and the last part in a single process
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("out.pfm"), bytes("plain.pfm"));
    EXPECT_EQ(rays_of(dir_ / "out.json"), rays_of(dir_ / "plain.json"));
    EXPECT_EQ(estimate_of(dir_ / "out.json"), estimate_of(dir_ / "plain.json"));
}

TEST_F(MpiCli, ForeignCheckpointIsRefusedByEveryProcessWithOneMessage) {
    ASSERT_EQ(run(small(kMotion, "out.pfm",
                        {"--spp", "4", "--checkpoint", "c.ckpt", "--stop-after-tiles", "1"}))
                  .status,
              130);
    const std::string before = bytes("c.ckpt");
    const Outcome r =
        run_mpi(2, small(kMotion, "out.pfm", {"--spp", "5", "--checkpoint", "c.ckpt"}));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.find("checkpoint of another render"),
              r.err.rfind("checkpoint of another render"))
        << r.err;
    EXPECT_NE(r.err.find("checkpoint of another render"), std::string::npos) << r.err;
    EXPECT_EQ(bytes("c.ckpt"), before);
    EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
}

// Processes that would render different images, because one was given another seed or read
// another scene file (here with a brighter light), are refused before any tile is rendered:
// exit 2, one message naming the process, no image. The same command on both renders.
TEST_F(MpiCli, ProcessesThatWouldRenderDifferentlyAreRefusedBeforeRendering) {
    const auto two_commands = [&](const std::vector<std::string>& first,
                                  const std::vector<std::string>& second) {
        std::vector<std::string> argv{
            "mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "1", DRT_BINARY};
        argv.insert(argv.end(), first.begin(), first.end());
        argv.insert(argv.end(), {":", "-n", "1", DRT_BINARY});
        argv.insert(argv.end(), second.begin(), second.end());
        return run_process(argv, dir_);
    };
    const std::string scene = read_bytes(kMotion);
    const std::string bright = "Ir=\"1.0\"";
    const std::size_t light = scene.find(bright);
    ASSERT_NE(light, std::string::npos);
    replace_file(dir_ / "a.xml", scene);
    replace_file(dir_ / "b.xml",
                 scene.substr(0, light) + "Ir=\"1.5\"" + scene.substr(light + bright.size()));
    const std::string refused =
        ": process 1 of the 2 renders this scene differently from process 0 (another scene or "
        "OBJ file, other options or another build of drt there); every process must read the "
        "same files with the same command and drt\n";
    for (const auto& second : {small("a.xml", "out.pfm", {"--spp", "2", "--seed", "1"}),
                               small("b.xml", "out.pfm", {"--spp", "2"})}) {
        const Outcome r = two_commands(small("a.xml", "out.pfm", {"--spp", "2"}), second);
        EXPECT_EQ(r.status, 2) << r.err;
        // Once, from the leader (mpirun adds its own report of the exit status).
        EXPECT_NE(r.err.find("drt: a.xml" + refused), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find(refused), r.err.rfind(refused)) << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "out.pfm"));
    }
    const Outcome same = two_commands(small("a.xml", "out.pfm", {"--spp", "2"}),
                                      small("a.xml", "out.pfm", {"--spp", "2"}));
    EXPECT_EQ(same.status, 0) << same.err;
    EXPECT_TRUE(fs::exists(dir_ / "out.pfm"));
}

// The process ids of `parent`'s children running drt with OMPI_COMM_WORLD_RANK=`rank`.
std::vector<pid_t> ranks_of(pid_t parent, int rank) {
    std::vector<pid_t> found;
    for (const auto& entry : fs::directory_iterator("/proc")) {
        const std::string name = entry.path().filename();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        const std::string stat = read_bytes(entry.path() / "stat");
        const std::size_t close = stat.rfind(')');
        if (close == std::string::npos) continue;
        std::istringstream rest(stat.substr(close + 2));
        char state = 0;
        pid_t ppid = 0;
        rest >> state >> ppid;
        if (ppid != parent) continue;
        const std::string env = read_bytes(entry.path() / "environ");
        if (env.find(std::string("OMPI_COMM_WORLD_RANK=") + std::to_string(rank) + '\0') !=
            std::string::npos) {
            found.push_back(std::stoi(name));
        }
    }
    return found;
}

TEST_F(MpiCli, AKilledProcessLeavesNoOutputAndTheRerunCompletesTheSameBits) {
    const std::vector<std::string> more{"--spp", "48", "--threads", "1"};
    ASSERT_EQ(run(small(kMotion, "plain.pfm", more)).status, 0);
    std::vector<std::string> args = small(kMotion, "out.pfm", more);
    args.insert(args.end(), {"--checkpoint", "c.ckpt", "--checkpoint-every", "0"});
    for (const int victim : {1, 0}) {
        fs::remove(dir_ / "c.ckpt");
        const pid_t mpirun_pid = start_process(mpirun(2, args), dir_);
        // A checkpoint shows that tiles are coming in; then one process dies without warning.
        for (int i = 0; i < 6000 && !fs::exists(dir_ / "c.ckpt"); ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        const std::vector<pid_t> pids = ranks_of(mpirun_pid, victim);
        ASSERT_EQ(pids.size(), 1u);
        kill(pids[0], SIGKILL);
        const Outcome r = finish_process(mpirun_pid, dir_);
        if (r.status == 0) continue;  // it had finished: nothing to test this time
        EXPECT_FALSE(fs::exists(dir_ / "out.pfm")) << r.err;
        for (const auto& e : fs::directory_iterator(dir_)) {
            EXPECT_EQ(e.path().filename().string().find(".out.pfm.tmp"), std::string::npos);
        }
        ASSERT_TRUE(fs::exists(dir_ / "c.ckpt"));
        const Outcome rerun = run(args);
        ASSERT_EQ(rerun.status, 0) << rerun.err;
        EXPECT_NE(rerun.err.find("tiles resumed"), std::string::npos) << rerun.err;
        EXPECT_EQ(bytes("out.pfm"), bytes("plain.pfm"));
        fs::remove(dir_ / "out.pfm");
    }
}

TEST_F(MpiCli, AWorkerStoppedOnItsOwnGivesBackTheTileInHandAndTheLeaderFinishesTheSameBits) {
    // Path tracing at 256 spp: a tile takes about a second, so the signal finds the worker
    // inside one, which it abandons between two pixels and gives back with those it holds.
    const std::string cornell = (kSourceDir / "scenes/gi/cornell-box.xml").string();
    const std::vector<std::string> more{"--spp", "256", "--threads", "1"};
    ASSERT_EQ(run(small(cornell, "plain.pfm", more)).status, 0);
    std::vector<std::string> args = small(cornell, "out.pfm", more);
    args.insert(args.end(), {"--checkpoint", "c.ckpt", "--checkpoint-every", "0"});
    const pid_t mpirun_pid = start_process(mpirun(2, args), dir_);
    for (int i = 0; i < 6000 && !fs::exists(dir_ / "c.ckpt"); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const std::vector<pid_t> pids = ranks_of(mpirun_pid, 1);
    ASSERT_EQ(pids.size(), 1u);
    kill(pids[0], SIGTERM);
    const Outcome r = finish_process(mpirun_pid, dir_);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(bytes("out.pfm"), bytes("plain.pfm"));
}

}  // namespace
}  // namespace drt
