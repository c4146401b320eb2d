// libFuzzer target: the command line. Each line of the input is one argument; drt runs in a
// private folder holding a tiny scene (s.xml) and images (a.png, b.png, c.pfm) for the arguments
// to name. Arguments that could reach outside that folder (a '/') or ask for a long render (a
// number above 64, or an exponent) are skipped as uninteresting: the limits themselves are tested
// in the normal suite.
#include <unistd.h>

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "drt/cli/cli.h"
#include "drt/io/image.h"

namespace {

constexpr const char* kScene = R"(<Scene>
  <Image Width="3" Height="2"/>
  <Render Samples="2" ShadowRays="2"/>
  <Materials><M kdr="0.5" kdg="0.5" kdb="0.5" diffuse="1"/><G transmitt="1" index="1.5" n="20"/></Materials>
  <Light Px="0" Py="5" Pz="-5" Radius="1"/>
  <Plane Px="0" Py="-1" Pz="0" Vu="0" Vv="1" Vw="0" Material="M"/>
  <Sphere Px="0" Py="0" Pz="3" Radius="1" Material="G"/>
</Scene>
)";

void enter_folder() {
    static const bool entered = [] {
        std::string pattern =
            (std::filesystem::temp_directory_path() / "drt-fuzz-cli-XXXXXX").string();
        if (!mkdtemp(pattern.data()) || chdir(pattern.c_str()) != 0) __builtin_trap();
        std::ofstream("s.xml") << kScene;
        drt::Image image(3, 2);
        for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = float(i) / 18;
        drt::write_image(image, "a.png");
        drt::write_image(image, "c.pfm");
        image.rgb[0] = 1;
        drt::write_image(image, "b.png");
        return true;
    }();
    (void)entered;
}

bool uninteresting(const std::string& arg) {
    if (arg.find('/') != std::string::npos) return true;
    long run = 0;
    for (std::size_t i = 0; i < arg.size(); ++i) {
        const char c = arg[i];
        if (std::isdigit(static_cast<unsigned char>(c))) {
            run = run * 10 + (c - '0');
            if (run > 64) return true;
        } else {
            if ((c == 'e' || c == 'E' || c == 'p' || c == 'P') && i > 0 &&
                std::isdigit(static_cast<unsigned char>(arg[i - 1])))
                return true;
            run = 0;
        }
    }
    return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    enter_folder();
    std::vector<std::string> args{"drt"};
    std::string current;
    for (std::size_t i = 0; i < size; ++i) {
        if (data[i] == '\n') {
            args.push_back(current);
            current.clear();
        } else if (data[i] != '\0') {
            current += static_cast<char>(data[i]);
        }
    }
    if (!current.empty()) args.push_back(current);
    if (args.size() > 24) return -1;
    for (const std::string& a : args) {
        if (uninteresting(a)) return -1;
    }
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    std::ostringstream out, err;
    const int status = drt::run_cli(static_cast<int>(argv.size()), argv.data(), out, err);
    if (status < 0 || status > 2) __builtin_trap();
    return 0;
}
