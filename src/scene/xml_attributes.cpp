#include "drt/scene/xml_attributes.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <type_traits>
#include <utility>

#include "drt/scene/scene_loader.h"
#include "drt/util/text.h"

namespace drt {

namespace {

// Optimal-string-alignment distance: insertions, deletions, substitutions and swaps of two
// neighbours each cost one, since a swap ("Nmae") is as common a typo as a wrong letter. Case is
// ignored, so that "radius" finds "Radius" and "bumpenable" finds "bumpEnable".
std::size_t edit_distance(std::string_view a, std::string_view b) {
    const auto same = [](char x, char y) {
        return std::tolower(static_cast<unsigned char>(x)) ==
               std::tolower(static_cast<unsigned char>(y));
    };
    const std::size_t w = b.size() + 1;
    std::vector<std::size_t> d((a.size() + 1) * w);
    for (std::size_t i = 0; i <= a.size(); ++i) d[i * w] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        for (std::size_t j = 1; j <= b.size(); ++j) {
            std::size_t best =
                std::min({d[(i - 1) * w + j] + 1, d[i * w + j - 1] + 1,
                          d[(i - 1) * w + j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
            if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1])) {
                best = std::min(best, d[(i - 2) * w + j - 2] + 1);
            }
            d[i * w + j] = best;
        }
    }
    return d[a.size() * w + b.size()];
}

// std::errc{} on success; invalid_argument for anything that is not wholly a finite number of
// type T; result_out_of_range when it is one but T cannot hold it.
template <class T>
std::errc parse_whole(std::string_view text, T& out) {
    // from_chars rejects a leading '+', which people write; "+-1" must stay an error.
    if (!text.empty() && text.front() == '+') {
        text.remove_prefix(1);
        if (!text.empty() && text.front() == '-') return std::errc::invalid_argument;
    }
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, out);
    if (ec != std::errc{}) return ec;
    if (ptr != end) return std::errc::invalid_argument;
    if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(out)) return std::errc::invalid_argument;  // "inf", "nan"
    }
    return {};
}

std::string quoted(std::string_view name) {
    std::string text(1, '\'');
    text.append(name);
    text += '\'';
    return text;
}

}  // namespace

std::optional<std::string_view> nearest_name(std::string_view name,
                                             std::span<const std::string_view> known) {
    const std::size_t allowed = (name.size() + 2) / 3;
    std::optional<std::string_view> best;
    std::size_t best_distance = allowed + 1;
    for (const std::string_view candidate : known) {
        const std::size_t d = edit_distance(name, candidate);
        if (d < best_distance) best = candidate, best_distance = d;
    }
    return best;
}

std::string_view trimmed(std::string_view text) {
    constexpr std::string_view kSpace = " \t\r\n";
    const std::size_t first = text.find_first_not_of(kSpace);
    if (first == std::string_view::npos) return {};
    return text.substr(first, text.find_last_not_of(kSpace) - first + 1);
}

// --- LoadContext ---

void LoadContext::fail(const tinyxml2::XMLElement& element, const std::string& message) const {
    fail_at(element.GetLineNum(), element.Name(), message);
}

void LoadContext::fail_at(int line, std::string_view element, const std::string& message) const {
    throw SceneError(printable(file_ + ":" + std::to_string(std::max(line, 1)) + ": " +
                               std::string(element) + ": " + message));
}

void LoadContext::warn(const tinyxml2::XMLElement& element, const std::string& message) {
    warn_at(element.GetLineNum(), message);
}

void LoadContext::warn_in(const std::string& file, int line, const std::string& message) {
    warnings_.push_back(printable(file + ":" + std::to_string(line) + ": warning: " + message));
}

// --- Attributes ---

std::optional<std::string_view> Attributes::find(std::string_view name) {
    known_.push_back(name);
    const char* value = element_.Attribute(std::string(name).c_str());
    return value ? std::optional<std::string_view>(value) : std::nullopt;
}

std::string Attributes::text(std::string_view name) {
    if (const auto value = find(name)) return std::string(*value);
    fail_missing(name);
}

std::string Attributes::text(std::string_view name, std::string_view fallback) {
    return std::string(find(name).value_or(fallback));
}

std::optional<double> Attributes::optional_number(std::string_view name) {
    const auto value = find(name);
    if (!value) return std::nullopt;
    return convert<double>(name, *value, "a number");
}

double Attributes::number(std::string_view name) {
    if (const auto value = optional_number(name)) return *value;
    fail_missing(name);
}

double Attributes::number(std::string_view name, double fallback) {
    return optional_number(name).value_or(fallback);
}

Vec3 Attributes::vec3(std::string_view x, std::string_view y, std::string_view z) {
    return {number(x), number(y), number(z)};
}

Vec3 Attributes::vec3(std::string_view x, std::string_view y, std::string_view z, Vec3 fallback) {
    return {number(x, fallback.x), number(y, fallback.y), number(z, fallback.z)};
}

Color Attributes::color(std::string_view r, std::string_view g, std::string_view b,
                        Color fallback) {
    return {number(r, fallback.r), number(g, fallback.g), number(b, fallback.b)};
}

int Attributes::integer(std::string_view name, int fallback) {
    const auto value = find(name);
    if (!value) return fallback;
    return convert<int>(name, *value, "an integer");
}

std::uint64_t Attributes::integer(std::string_view name, std::uint64_t fallback) {
    const auto value = find(name);
    if (!value) return fallback;
    return convert<std::uint64_t>(name, *value, "a non-negative integer");
}

bool Attributes::flag(std::string_view name, bool fallback) {
    const auto value = find(name);
    if (!value) return fallback;
    const std::string_view t = trimmed(*value);
    if (t != "0" && t != "1") {
        fail(std::string(name) + " must be 0 or 1, got \"" + abbreviated(*value) + "\"");
    }
    return t == "1";
}

void Attributes::check(bool ok, std::string_view name, std::string_view rule) const {
    if (!ok) fail(std::string(name) + " must be " + std::string(rule) + ", got " + shown(name));
}

void Attributes::check_radiance(const Color& c, std::string_view r, std::string_view g,
                                std::string_view b) const {
    for (const auto& [value, name] : {std::pair{c.r, r}, {c.g, g}, {c.b, b}}) {
        check(std::abs(value) <= kLargestPixelValue, name, kLargestPixelValueText);
    }
}

std::string Attributes::shown(std::string_view name) const {
    const char* value = element_.Attribute(std::string(name).c_str());
    return value ? abbreviated(trimmed(value)) : "(default)";
}

void Attributes::warn_unknown() {
    for (const auto* a = element_.FirstAttribute(); a; a = a->Next()) {
        const std::string_view name = a->Name();
        if (std::ranges::find(known_, name) != known_.end()) continue;
        std::string message = "unknown attribute " + quoted(name) + " on <" + element_.Name() + ">";
        if (const auto guess = nearest_name(name, known_))
            message += "; did you mean " + quoted(*guess) + "?";
        context_.warn(element_, message);
    }
}

void Attributes::fail_missing(std::string_view name) const {
    fail("missing required attribute " + quoted(name));
}

template <class T>
T Attributes::convert(std::string_view name, std::string_view value, std::string_view kind) const {
    T out{};
    const std::errc ec = parse_whole(trimmed(value), out);
    if (ec == std::errc{}) return out;
    const std::string problem =
        ec == std::errc::result_out_of_range ? "is out of range" : "is not " + std::string(kind);
    fail("attribute " + quoted(name) + " " + problem + ": \"" + abbreviated(value) + "\"");
}

}  // namespace drt
