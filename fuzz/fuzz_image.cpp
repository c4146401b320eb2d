// libFuzzer target: the image readers behind `drt compare`, then the comparison itself. The first
// byte picks the format (the file name's extension, as for compare); the rest is the file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "drt/io/compare.h"
#include "drt/io/image.h"

namespace {

// A private folder for the one file each input becomes.
const std::filesystem::path& folder() {
    static const std::filesystem::path dir = [] {
        std::string pattern =
            (std::filesystem::temp_directory_path() / "drt-fuzz-image-XXXXXX").string();
        if (!mkdtemp(pattern.data())) __builtin_trap();
        return std::filesystem::path(pattern);
    }();
    return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    static const char* const kExtensions[] = {".pfm", ".png", ".bmp", ".exr"};
    const std::filesystem::path file =
        folder() / (std::string("input") + kExtensions[data[0] % std::size(kExtensions)]);
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
    }
    try {
        const drt::Image image = drt::read_image(file);
        if (image.rgb.size() != 3 * std::size_t(image.width) * std::size_t(image.height)) {
            __builtin_trap();
        }
        // Small images only: the comparison is linear in the pixels, but SSIM's windows make a
        // large image slow enough to starve the fuzzer of inputs.
        if (image.rgb.size() <= 3 * 256 * 256) {
            drt::compare_images(image, image);
            drt::difference_image(image, image);
        }
    } catch (const drt::ImageError&) {
    }
    return 0;
}
