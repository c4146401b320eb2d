// libFuzzer target: the MTL reader (a material library an OBJ file names).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drt/io/mtl_reader.h"

namespace {

bool finite(const std::optional<drt::Color>& c) {
    return !c || (std::isfinite(c->r) && std::isfinite(c->g) && std::isfinite(c->b));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const auto materials =
            drt::parse_mtl(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.mtl");
        // A value the reader accepts is a finite number: never a silent NaN or infinity.
        for (const drt::MtlMaterial& m : materials) {
            if (!finite(m.kd) || !finite(m.ks) || !finite(m.ke)) __builtin_trap();
            if ((m.ns && !std::isfinite(*m.ns)) || (m.dissolve && !std::isfinite(*m.dissolve)))
                __builtin_trap();
            if (m.map_kd && m.map_kd->path.empty()) __builtin_trap();
        }
    } catch (const drt::MtlError&) {
    }
    return 0;
}
