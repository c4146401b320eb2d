// Reads Wavefront MTL material libraries: the statements docs/scene-format.md ("OBJ materials")
// lists — `newmtl`, `Kd`, `Ks`, `Ns`, `Ni`, `d`, `Tr`, `Ke`, `illum`, `map_Kd`, `map_d`,
// `bump`/`map_Bump` — as written in the file; what they mean for drt's material is the scene
// layer's mapping. Every other statement is ignored. A malformed number is an error naming the
// file and line.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "drt/util/color.h"

namespace drt {

// A file whose contents break the contract. what() is "MTLFILE:LINE: message".
class MtlError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// An image a material names: its path with `\` turned into `/`, relative to the MTL file's
// folder as written, and the line naming it (a missing image is warned about there).
struct MtlTexture {
    std::string path;
    int line = 0;
    double bump_multiplier = 1;  // `-bm`, for bump maps
};

struct MtlMaterial {
    std::string name;
    int line = 0;  // of its `newmtl`
    std::optional<Color> kd, ks, ke;
    std::optional<double> ns, ni;
    // Opacity: `d`, or 1 - `Tr`, whichever comes last.
    std::optional<double> dissolve;
    std::optional<int> illum;
    std::optional<MtlTexture> map_kd, map_d, bump;
};

// `name` stands for the file in messages. Statements before the first `newmtl` are ignored.
std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name);
// Throws ObjOpenError (obj_reader.h) if the file cannot be read, MtlError if it is malformed.
std::vector<MtlMaterial> read_mtl(const std::filesystem::path& path);

}  // namespace drt
