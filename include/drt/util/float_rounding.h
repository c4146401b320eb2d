// Doubles rounded to single precision in a chosen direction, for float bounds that must still
// contain the double they stand for (a box's time span, a ray's range in a float box test).
// On the bits rather than by std::nextafter: cheap enough for a traversal's inner loop.
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

namespace drt {

// The next float above f, for an f that is not +∞ or NaN (-0 and +0 alike go to the smallest
// positive float).
inline float next_float_up(float f) {
    if (f == 0) return std::numeric_limits<float>::denorm_min();
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0 ? bits + 1 : bits - 1);
}

// The least float no smaller than x (NaN stays NaN).
inline float to_float_up(double x) {
    const auto f = static_cast<float>(x);
    return f < x ? next_float_up(f) : f;
}

// The greatest float no larger than x (NaN stays NaN).
inline float to_float_down(double x) {
    const auto f = static_cast<float>(x);
    return f > x ? -next_float_up(-f) : f;
}

}  // namespace drt
