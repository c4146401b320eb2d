// The OBJ reader. It is drt's own rather than tinyobjloader's, because tinyobjloader reads
// "abc", "nan" and "inf" as 0, keeps a face whose index is out of range with a warning that
// names no line, and accepts "3x" as 3 — all of which the scene format calls errors.
#include "drt/io/obj_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <string>

#include "drt/util/file_reader.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace {

constexpr bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

// Splits a line into its space-separated tokens, one at a time.
class Tokens {
  public:
    explicit Tokens(std::string_view line) : rest_(line) {}

    // The next token, or an empty view at the end of the line.
    std::string_view next() {
        std::size_t i = 0;
        while (i < rest_.size() && is_blank(rest_[i])) ++i;
        std::size_t j = i;
        while (j < rest_.size() && !is_blank(rest_[j])) ++j;
        const std::string_view token = rest_.substr(i, j - i);
        rest_.remove_prefix(j);
        return token;
    }

    // The rest of the line without its leading and trailing blanks: a name that may hold spaces.
    std::string_view rest() const {
        std::string_view r = rest_;
        while (!r.empty() && is_blank(r.front())) r.remove_prefix(1);
        while (!r.empty() && is_blank(r.back())) r.remove_suffix(1);
        return r;
    }

  private:
    std::string_view rest_;
};

class ObjParser {
  public:
    ObjParser(std::string_view text, const std::string& name) : text_(text), name_(name) {
        // About one statement per 30 bytes, two triangles per vertex: reserving keeps a large
        // file from being copied several times over as the arrays grow.
        mesh_.positions.reserve(text.size() / 100);
        mesh_.position_indices.reserve(text.size() / 8);
        mesh_.normal_indices.reserve(text.size() / 8);
    }

    ObjMesh parse() {
        std::size_t start = 0;
        while (start < text_.size()) {
            ++line_;
            std::size_t end = text_.find('\n', start);
            if (end == std::string_view::npos) end = text_.size();
            std::string_view line = text_.substr(start, end - start);
            if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
                line = line.substr(0, hash);
            statement(line);
            start = end + 1;
        }
        return std::move(mesh_);
    }

  private:
    struct Corner {
        std::uint32_t position, normal, texcoord;
    };

    void statement(std::string_view line) {
        Tokens tokens(line);
        const std::string_view keyword = tokens.next();
        if (keyword == "v") {
            mesh_.positions.push_back(point(tokens, "v"));
            // An optional weight, or the colour some programs append: numbers, but unused.
            for (std::string_view t = tokens.next(); !t.empty(); t = tokens.next()) number(t, "v");
        } else if (keyword == "vn") {
            mesh_.normals.push_back(point(tokens, "vn"));
            if (const std::string_view extra = tokens.next(); !extra.empty())
                fail("vn: more than 3 coordinates: \"" + abbreviated(extra) + "\"");
        } else if (keyword == "vt") {
            mesh_.texcoords.push_back(texcoord(tokens));
        } else if (keyword == "f") {
            face(tokens);
        } else if (keyword == "mtllib") {
            mesh_.material_libraries.push_back({std::string(tokens.rest()), line_});
        } else if (keyword == "usemtl") {
            use_material(tokens.rest());
        }
    }

    // "vt u [v [w]]": v is 0 when absent, w (a 3-D texture's) is read but unused.
    Vec2 texcoord(Tokens& tokens) {
        double c[3] = {0, 0, 0};
        int count = 0;
        for (std::string_view t = tokens.next(); !t.empty(); t = tokens.next()) {
            if (count == 3) fail("vt: more than 3 coordinates: \"" + abbreviated(t) + "\"");
            c[count++] = number(t, "vt");
        }
        if (count == 0) fail("vt: 1 to 3 coordinates needed, got 0");
        return {c[0], c[1]};
    }

    void use_material(std::string_view name) {
        const auto known = material_slots_.find(name);
        if (known != material_slots_.end()) {
            current_material_ = known->second;
        } else {
            current_material_ = static_cast<std::uint32_t>(mesh_.material_names.size());
            mesh_.material_names.push_back({std::string(name), line_});
            material_slots_.emplace(std::string(name), current_material_);
        }
        if (!material_used_)
            mesh_.triangle_materials.assign(mesh_.triangle_count(), ObjMesh::kNoMaterial);
        material_used_ = true;
    }

    Vec3 point(Tokens& tokens, std::string_view keyword) {
        double c[3];
        for (double& x : c) {
            const std::string_view token = tokens.next();
            if (token.empty())
                fail(std::string(keyword) + ": 3 coordinates needed, got " +
                     std::to_string(&x - c));
            x = number(token, keyword);
        }
        return {c[0], c[1], c[2]};
    }

    double number(std::string_view token, std::string_view keyword) const {
        std::string_view digits = token;
        // from_chars rejects the '+' that people write; "+-1" must stay an error.
        if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-') digits.remove_prefix(1);
        double x = 0;
        const char* end = digits.data() + digits.size();
        const auto [ptr, ec] = std::from_chars(digits.data(), end, x);
        if (ec == std::errc::invalid_argument || ptr != end)
            fail(std::string(keyword) + ": \"" + abbreviated(token) + "\" is not a number");
        if (ec == std::errc::result_out_of_range)
            fail(std::string(keyword) + ": \"" + abbreviated(token) + "\" is out of range");
        if (!std::isfinite(x))
            fail(std::string(keyword) + ": \"" + abbreviated(token) + "\" is not a finite number");
        return x;
    }

    void face(Tokens& tokens) {
        corners_.clear();
        for (std::string_view t = tokens.next(); !t.empty(); t = tokens.next())
            corners_.push_back(corner(t));
        if (corners_.size() < 3)
            fail("f: a face needs at least 3 vertices, got " + std::to_string(corners_.size()));
        const bool has_texcoords = std::ranges::any_of(
            corners_, [](const Corner& c) { return c.texcoord != ObjMesh::kNoTexcoord; });
        if (has_texcoords && !texcoords_used_) {
            mesh_.texcoord_indices.assign(mesh_.position_indices.size(), ObjMesh::kNoTexcoord);
            texcoords_used_ = true;
        }
        if (current_material_ == ObjMesh::kNoMaterial && mesh_.first_face_without_material == 0)
            mesh_.first_face_without_material = line_;
        for (std::size_t i = 1; i + 1 < corners_.size(); ++i) {
            for (const Corner& c : {corners_[0], corners_[i], corners_[i + 1]}) {
                mesh_.position_indices.push_back(c.position);
                mesh_.normal_indices.push_back(c.normal);
                if (texcoords_used_) mesh_.texcoord_indices.push_back(c.texcoord);
            }
            if (material_used_) mesh_.triangle_materials.push_back(current_material_);
        }
    }

    // "v", "v/vt", "v//vn" or "v/vt/vn".
    Corner corner(std::string_view token) {
        const std::size_t slash1 = token.find('/');
        const std::string_view position = token.substr(0, slash1);
        Corner c{index(position, mesh_.positions.size(), "vertex", token), ObjMesh::kNoNormal,
                 ObjMesh::kNoTexcoord};
        if (slash1 == std::string_view::npos) return c;
        const std::string_view rest = token.substr(slash1 + 1);
        const std::size_t slash2 = rest.find('/');
        const std::string_view texture = rest.substr(0, slash2);
        if (!texture.empty() || slash2 == std::string_view::npos)
            c.texcoord = index(texture, mesh_.texcoords.size(), "texture", token);
        if (slash2 == std::string_view::npos) return c;
        c.normal = index(rest.substr(slash2 + 1), mesh_.normals.size(), "normal", token);
        return c;
    }

    // The 0-based index that a 1-based or negative (counted back from the latest) index names
    // among the `count` items defined so far.
    std::uint32_t index(std::string_view digits, std::size_t count, std::string_view kind,
                        std::string_view token) const {
        long long i = 0;
        const char* end = digits.data() + digits.size();
        const auto [ptr, ec] = std::from_chars(digits.data(), end, i);
        if (digits.empty() || ec == std::errc::invalid_argument || ptr != end)
            fail("f: \"" + abbreviated(token) + "\" is not a vertex reference");
        const auto n = static_cast<long long>(count);
        const bool beyond = ec == std::errc::result_out_of_range || i > n || i < -n;
        if (!beyond && i == 0) {
            fail("f: " + std::string(kind) + " index 0 in \"" + abbreviated(token) +
                 "\"; indices start at 1");
        }
        if (beyond) {
            fail("f: " + std::string(kind) + " index " + abbreviated(digits) +
                 " is out of range; " + std::to_string(count) + " defined above");
        }
        return static_cast<std::uint32_t>(i > 0 ? i - 1 : n + i);
    }

    [[noreturn]] void fail(const std::string& message) const {
        throw ObjError(printable(name_ + ":" + std::to_string(line_) + ": " + message));
    }

    std::string_view text_;
    const std::string& name_;
    ObjMesh mesh_;
    std::map<std::string, std::uint32_t, std::less<>> material_slots_;  // name -> its index
    std::uint32_t current_material_ = ObjMesh::kNoMaterial;
    bool material_used_ = false;   // whether a `usemtl` has been read
    bool texcoords_used_ = false;  // whether a face corner has named a `vt`
    int line_ = 0;
    std::vector<Corner> corners_;  // of the current face, kept to reuse its memory
};

std::string read_text(const std::filesystem::path& path) {
    try {
        return read_text_file(path, kMaxObjBytes);
    } catch (const FileReadError& e) {
        if (e.problem() == FileProblem::too_large) {
            throw ObjError(printable(path.string()) + ": file larger than the " +
                           std::to_string(kMaxObjBytes >> 20) + " MiB limit for a mesh");
        }
        throw ObjOpenError(e.reason());
    }
}

}  // namespace

ObjMesh parse_obj(std::string_view text, const std::string& name) {
    return ObjParser(text, name).parse();
}

ObjMesh read_obj(const std::filesystem::path& path) {
    return parse_obj(read_text(path), path.string());
}

}  // namespace drt
