#include "drt/io/mtl_reader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "drt/io/obj_reader.h"
#include "drt/util/file_reader.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace {

constexpr bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

std::string_view trimmed(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

// The first blank-separated token of `rest`, removed from it.
std::string_view take_token(std::string_view& rest) {
    rest = trimmed(rest);
    std::size_t end = 0;
    while (end < rest.size() && !is_blank(rest[end])) ++end;
    const std::string_view token = rest.substr(0, end);
    rest.remove_prefix(end);
    return token;
}

// Whether `text` starts with a number rather than an option ("-o 1 -blendu") or a file name.
bool starts_numeric(std::string_view text) {
    if (!text.empty() && (text[0] == '-' || text[0] == '+')) text.remove_prefix(1);
    if (!text.empty() && text[0] == '.') text.remove_prefix(1);
    return !text.empty() && std::isdigit(static_cast<unsigned char>(text[0]));
}

class MtlParser {
  public:
    MtlParser(std::string_view text, const std::string& name) : text_(text), name_(name) {}

    std::vector<MtlMaterial> parse() {
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
        return std::move(materials_);
    }

  private:
    void statement(std::string_view rest) {
        const std::string_view keyword = take_token(rest);
        if (keyword == "newmtl") {
            materials_.push_back({});
            materials_.back().name = std::string(trimmed(rest));
            materials_.back().line = line_;
            return;
        }
        if (materials_.empty()) return;
        MtlMaterial& m = materials_.back();
        if (keyword == "Kd") {
            m.kd = color(rest, keyword);
        } else if (keyword == "Ks") {
            m.ks = color(rest, keyword);
        } else if (keyword == "Ke") {
            m.ke = color(rest, keyword);
        } else if (keyword == "Ns") {
            m.ns = single(rest, keyword);
        } else if (keyword == "Ni") {
            m.ni = single(rest, keyword);
        } else if (keyword == "d") {
            // "d -halo f" is d's rarely written variant: the same factor.
            if (trimmed(rest).starts_with("-halo")) take_token(rest);
            m.dissolve = single(rest, keyword);
        } else if (keyword == "Tr") {
            m.dissolve = 1 - single(rest, keyword);
        } else if (keyword == "illum") {
            const double x = single(rest, keyword);
            if (x != std::floor(x) || x < 0 || x > 10)
                fail("illum: \"" + abbreviated(trimmed(rest)) + "\" is not a model from 0 to 10");
            m.illum = static_cast<int>(x);
        } else if (keyword == "map_Kd") {
            m.map_kd = texture(rest, keyword);
        } else if (keyword == "map_d") {
            m.map_d = texture(rest, keyword);
        } else if (keyword == "bump" || keyword == "map_Bump" || keyword == "map_bump") {
            m.bump = texture(rest, keyword);
        }
    }

    // "K r [g b]": one value stands for all three. The spectral and xyz forms are not read.
    std::optional<Color> color(std::string_view rest, std::string_view keyword) const {
        const std::string_view first = trimmed(rest);
        if (first.starts_with("spectral") || first.starts_with("xyz")) return std::nullopt;
        double c[3];
        int count = 0;
        for (std::string_view t = take_token(rest); !t.empty(); t = take_token(rest)) {
            if (count == 3) fail(std::string(keyword) + ": more than 3 values");
            c[count++] = number(t, keyword);
        }
        if (count == 0) fail(std::string(keyword) + ": a colour needed");
        if (count == 2) fail(std::string(keyword) + ": 1 or 3 values needed, got 2");
        if (count == 1) c[1] = c[2] = c[0];
        return Color{c[0], c[1], c[2]};
    }

    double single(std::string_view rest, std::string_view keyword) const {
        const std::string_view token = take_token(rest);
        if (token.empty()) fail(std::string(keyword) + ": a number needed");
        const double x = number(token, keyword);
        if (const std::string_view extra = take_token(rest); !extra.empty())
            fail(std::string(keyword) + ": unexpected \"" + abbreviated(extra) + "\"");
        return x;
    }

    // "map_X [-option values]... file name": the options drt does not use are skipped by their
    // count of values; the rest of the line is the file's name, spaces and all.
    MtlTexture texture(std::string_view rest, std::string_view keyword) const {
        MtlTexture t;
        t.line = line_;
        rest = trimmed(rest);
        while (rest.starts_with("-")) {
            const std::string_view option = take_token(rest);
            if (option == "-bm") {
                t.bump_multiplier = number(take_token(rest), keyword);
            } else if (option == "-o" || option == "-s" || option == "-t") {
                for (int i = 0; i < 3 && starts_numeric(trimmed(rest)); ++i)
                    number(take_token(rest), keyword);
            } else if (option == "-mm") {
                number(take_token(rest), keyword);
                number(take_token(rest), keyword);
            } else if (option == "-boost" || option == "-texres") {
                number(take_token(rest), keyword);
            } else {
                take_token(rest);  // -blendu, -blendv, -clamp, -cc: on/off; -imfchan, -type
            }
            rest = trimmed(rest);
        }
        if (rest.empty()) fail(std::string(keyword) + ": a file name needed");
        t.path = std::string(rest);
        std::ranges::replace(t.path, '\\', '/');
        return t;
    }

    double number(std::string_view token, std::string_view keyword) const {
        std::string_view digits = token;
        if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-') digits.remove_prefix(1);
        double x = 0;
        const char* end = digits.data() + digits.size();
        const auto [ptr, ec] = std::from_chars(digits.data(), end, x);
        if (token.empty() || ec == std::errc::invalid_argument || ptr != end)
            fail(std::string(keyword) + ": \"" + abbreviated(token) + "\" is not a number");
        if (ec == std::errc::result_out_of_range || !std::isfinite(x))
            fail(std::string(keyword) + ": \"" + abbreviated(token) + "\" is not a finite number");
        return x;
    }

    [[noreturn]] void fail(const std::string& message) const {
        throw MtlError(printable(name_ + ":" + std::to_string(line_) + ": " + message));
    }

    std::string_view text_;
    const std::string& name_;
    std::vector<MtlMaterial> materials_;
    int line_ = 0;
};

}  // namespace

std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name) {
    return MtlParser(text, name).parse();
}

std::vector<MtlMaterial> read_mtl(const std::filesystem::path& path) {
    std::string text;
    try {
        text = read_text_file(path, kMaxObjBytes);
    } catch (const FileReadError& e) {
        if (e.problem() == FileProblem::too_large) {
            throw MtlError(printable(path.string()) + ": file larger than the " +
                           std::to_string(kMaxObjBytes >> 20) +
                           " MiB limit for a material library");
        }
        throw ObjOpenError(e.reason());
    }
    return parse_mtl(text, path.string());
}

}  // namespace drt
