// drt_golden: makes and inspects the golden references of tests/golden/ (docs/testing.md).
// tools/refresh-goldens.sh is the way to run it.
//
//   drt_golden refresh SCENES GOLDEN [--renders K] [SCENE...]   remake references, report changes
//   drt_golden check SCENES GOLDEN [--seed S] [--sampler NAME] [SCENE...]   run the test verdicts
//
// SCENE names a file inside SCENES (e.g. thesis/test1.xml); none means every scene.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "golden.h"

namespace fs = std::filesystem;
using namespace drt;

namespace {

struct Options {
    std::string command;
    fs::path scenes, golden;
    int renders = golden::kDefaultRenders;
    std::uint64_t seed = golden::kTestSeed;
    std::optional<std::string> sampler;
    std::vector<fs::path> only;
};

int usage() {
    std::cerr << "usage: drt_golden refresh SCENES GOLDEN [--renders K] [SCENE...]\n"
                 "       drt_golden check SCENES GOLDEN [--seed S] [--sampler NAME] [SCENE...]\n";
    return 2;
}

fs::path base_for(const Options& o, const fs::path& scene) {
    fs::path base = o.golden / scene;
    base.replace_extension();
    return base;
}

std::string fixed(double v, int digits) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

// Remakes one reference and prints a row: the test render against the old reference (before) and
// the new one (after), and whether the expected image itself moved.
bool refresh(const Options& o, const fs::path& scene) {
    const fs::path path = o.scenes / scene, base = base_for(o, scene);
    const std::vector<std::string> args = golden::default_args(path);
    const fs::path scratch = fs::temp_directory_path();
    const auto start = std::chrono::steady_clock::now();

    golden::Accumulator sum;
    for (int k = 0; k < o.renders; ++k) {
        sum.add(golden::render(path, args, golden::kReferenceSeed + k, scratch));
    }
    const golden::Reference fresh = sum.result(args);
    for (std::size_t i = 0; i < fresh.mean.rgb.size(); ++i) {
        if (!std::isfinite(fresh.mean.rgb[i]) || !std::isfinite(fresh.variance.rgb[i])) {
            std::cerr << scene.string() << ": the renders have NaN or infinite pixels; "
                      << "not writing a reference\n";
            return false;
        }
    }
    const Image test = golden::render(path, args, golden::kTestSeed, scratch);
    const golden::Verdict after = golden::check(test, fresh);

    std::string before = "-", moved = "new";
    try {
        const golden::Reference old = golden::load_reference(base);
        if (old.args != args || old.mean.width != fresh.mean.width ||
            old.mean.height != fresh.mean.height) {
            moved = "new options";
        } else {
            const golden::Verdict was = golden::check(test, old);
            before = fixed(was.rmse, 5) + " z" + fixed(was.max_abs_z, 1);
            const golden::Verdict shift = golden::check_references(old, fresh);
            moved = shift.pass ? "same (within noise)"
                               : "CHANGED: max |z| " + fixed(shift.max_abs_z, 1) + ", rmse " +
                                     fixed(shift.rmse, 5);
        }
    } catch (const std::exception&) {
        // No usable old reference: this one is new.
    }
    golden::save_reference(fresh, base);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%-34s %-18s %-18s %6.1f  %s\n", scene.c_str(), before.c_str(),
                (fixed(after.rmse, 5) + " z" + fixed(after.max_abs_z, 1)).c_str(), seconds,
                moved.c_str());
    std::fflush(stdout);
    if (!after.pass) {
        std::cerr << scene.string() << ": the test render fails its own new reference ("
                  << after.summary() << "): the test is too tight for this scene\n";
        return false;
    }
    return true;
}

bool check(const Options& o, const fs::path& scene) {
    const golden::Reference ref = golden::load_reference(base_for(o, scene));
    std::vector<std::string> args = ref.args;
    if (o.sampler) args.insert(args.end(), {"--sampler", *o.sampler});
    const Image test = golden::render(o.scenes / scene, args, o.seed, fs::temp_directory_path());
    const golden::Verdict v = golden::check(test, ref);
    std::printf("%-34s %s\n", scene.c_str(), v.summary().c_str());
    return v.pass;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> words(argv + 1, argv + argc);
    if (words.size() < 3) return usage();
    Options o;
    o.command = words[0], o.scenes = words[1], o.golden = words[2];
    for (std::size_t i = 3; i < words.size(); ++i) {
        const bool has_value = i + 1 < words.size();
        if (words[i] == "--renders" && has_value)
            o.renders = std::stoi(words[++i]);
        else if (words[i] == "--seed" && has_value)
            o.seed = std::stoull(words[++i]);
        else if (words[i] == "--sampler" && has_value)
            o.sampler = words[++i];
        else if (words[i].starts_with("-"))
            return usage();
        else
            o.only.push_back(words[i]);
    }
    if ((o.command != "refresh" && o.command != "check") || o.renders < 2) return usage();
    const std::vector<fs::path> scenes = o.only.empty() ? golden::scene_files(o.scenes) : o.only;

    if (o.command == "refresh") {
        std::printf("%-34s %-18s %-18s %6s  %s\n", "scene", "before: rmse z", "after: rmse z",
                    "sec", "expected image");
    }
    int failures = 0;
    for (const fs::path& scene : scenes) {
        try {
            failures += !(o.command == "refresh" ? refresh(o, scene) : check(o, scene));
        } catch (const std::exception& e) {
            std::cerr << scene.string() << ": " << e.what() << "\n";
            ++failures;
        }
    }
    return failures ? 1 : 0;
}
