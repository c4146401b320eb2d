// Linear RGB radiance/reflectance, a plain value type.
#pragma once

#include <algorithm>
#include <cmath>

namespace drt {

struct Color {
    double r = 0, g = 0, b = 0;

    constexpr Color& operator+=(const Color& c) {
        r += c.r, g += c.g, b += c.b;
        return *this;
    }
    constexpr Color& operator*=(double s) {
        r *= s, g *= s, b *= s;
        return *this;
    }
    constexpr Color& operator*=(const Color& c) {
        r *= c.r, g *= c.g, b *= c.b;
        return *this;
    }
    friend constexpr bool operator==(const Color&, const Color&) = default;
};

constexpr Color operator+(Color a, const Color& b) {
    return a += b;
}
constexpr Color operator-(const Color& a, const Color& b) {
    return {a.r - b.r, a.g - b.g, a.b - b.b};
}
constexpr Color operator*(Color a, double s) {
    return a *= s;
}
constexpr Color operator*(double s, Color a) {
    return a *= s;
}
constexpr Color operator*(Color a, const Color& b) {
    return a *= b;
}
constexpr Color operator/(const Color& a, double s) {
    return a * (1.0 / s);
}
constexpr Color lerp(const Color& a, const Color& b, double t) {
    return a * (1.0 - t) + b * t;
}
// Rec. 709 luminance, used to weigh lights by power.
constexpr double luminance(const Color& c) {
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}
constexpr double max_component(const Color& c) {
    return std::max({c.r, c.g, c.b});
}
constexpr bool is_black(const Color& c) {
    return c.r == 0 && c.g == 0 && c.b == 0;
}
inline bool is_finite(const Color& c) {
    return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
}

}  // namespace drt
