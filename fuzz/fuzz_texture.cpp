// libFuzzer target: the texture decoder (every format a scene's TextureFile or BumpFile may name,
// told by content), as colour and as data, then the mip-map and filtered lookups over the result.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "drt/io/texture_file.h"
#include "drt/shading/mipmap.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    // The first byte picks the encoding (even: colour; 1 mod 4: alpha; 3 mod 4: data); the rest
    // is the file.
    const auto encoding = data[0] % 2 == 0   ? drt::TextureEncoding::kColor
                          : data[0] % 4 == 1 ? drt::TextureEncoding::kAlpha
                                             : drt::TextureEncoding::kData;
    const std::vector<unsigned char> file(data + 1, data + size);
    try {
        const drt::Image image = drt::decode_texture(file, "input", encoding);
        if (image.width <= 0 || image.height <= 0 ||
            image.rgb.size() != 3 * std::size_t(image.width) * std::size_t(image.height)) {
            __builtin_trap();
        }
        // Small images only: the pyramid is linear in the pixels, and large ones would starve
        // the fuzzer of inputs.
        if (image.rgb.size() <= 3 * 256 * 256) {
            const drt::MipMap map(image);
            for (const double u : {-1.25, 0.0, 0.3, 0.999, 7.5}) {
                const drt::Color c = map.filtered({u, 1 - u}, {0.01, 0.2}, {0.3, 0});
                const drt::Color d = map.filtered({u, u}, 1e9);
                if (c.r != c.r || d.g != d.g) __builtin_trap();  // NaN from finite texels
            }
        }
    } catch (const drt::ImageError&) {
    }
    return 0;
}
