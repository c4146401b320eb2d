// Reading the elements of a scene file: attributes whose whole value must be what they claim
// ("1.5", not "1.5cm"), errors thrown as "FILE:LINE: Element: message", and names the reader did
// not ask for warned about with the nearest known one as a suggestion.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drt/util/color.h"
#include "drt/util/math.h"

namespace tinyxml2 {
class XMLElement;
}

namespace drt {

// The known name closest to `name`, when it is close enough to be what the user meant: about
// one edit per three characters (case ignored, a swap of neighbours one edit), so "Radus" gets
// "Radius" but "Teapot" gets nothing.
std::optional<std::string_view> nearest_name(std::string_view name,
                                             std::span<const std::string_view> known);

// `text` without the spaces, tabs and line ends around it.
std::string_view trimmed(std::string_view text);

// Where the messages about one scene file go: errors are thrown (SceneError), warnings kept; the
// user's text in them is made printable.
class LoadContext {
  public:
    explicit LoadContext(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const tinyxml2::XMLElement& element, const std::string& message) const;
    [[noreturn]] void fail_at(int line, std::string_view element, const std::string& message) const;
    void warn(const tinyxml2::XMLElement& element, const std::string& message);
    void warn_at(int line, const std::string& message) { warn_in(file_, line, message); }
    // About a line of another file that the scene reads (an OBJ or MTL file).
    void warn_in(const std::string& file, int line, const std::string& message);

    const std::string& file() const { return file_; }
    std::vector<std::string> take_warnings() { return std::move(warnings_); }

  private:
    std::string file_;
    std::vector<std::string> warnings_;
};

// The attributes of one element. Every accessor records the name it was asked for, so after an
// element has been read completely, the recorded names are exactly the attributes it knows:
// anything else on the element is unknown, and the recorded names are the suggestions.
class Attributes {
  public:
    Attributes(const tinyxml2::XMLElement& element, LoadContext& context)
        : element_(element), context_(context) {}

    [[noreturn]] void fail(const std::string& message) const { context_.fail(element_, message); }

    std::optional<std::string_view> find(std::string_view name);

    std::string text(std::string_view name);
    std::string text(std::string_view name, std::string_view fallback);

    std::optional<double> optional_number(std::string_view name);
    double number(std::string_view name);
    double number(std::string_view name, double fallback);
    Vec3 vec3(std::string_view x, std::string_view y, std::string_view z);
    Vec3 vec3(std::string_view x, std::string_view y, std::string_view z, Vec3 fallback);
    Color color(std::string_view r, std::string_view g, std::string_view b, Color fallback);
    int integer(std::string_view name, int fallback);
    std::uint64_t integer(std::string_view name, std::uint64_t fallback);
    // "0" or "1".
    bool flag(std::string_view name, bool fallback);

    // Fails with "NAME must be RULE, got VALUE" unless `ok`.
    void check(bool ok, std::string_view name, std::string_view rule) const;
    // A radiance that rays see as it is must fit the float channels of an image.
    void check_radiance(const Color& c, std::string_view r, std::string_view g,
                        std::string_view b) const;
    static constexpr double kLargestPixelValue = std::numeric_limits<float>::max();
    static constexpr std::string_view kLargestPixelValueText =
        "at most 3.40282e+38 (the largest value a float image holds)";
    // The attribute's value as the user wrote it, for messages.
    std::string shown(std::string_view name) const;

    // Call once the element has been read completely.
    void warn_unknown();

  private:
    [[noreturn]] void fail_missing(std::string_view name) const;
    template <class T>
    T convert(std::string_view name, std::string_view value, std::string_view kind) const;

    const tinyxml2::XMLElement& element_;
    LoadContext& context_;
    std::vector<std::string_view> known_;
};

}  // namespace drt
