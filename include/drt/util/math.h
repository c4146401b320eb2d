// Plain value types for geometry: Vec2, Vec3, Interval, Bounds.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace drt {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Vec2 {
    double x = 0, y = 0;
};

struct Vec3 {
    double x = 0, y = 0, z = 0;

    constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3& operator+=(const Vec3& v) {
        x += v.x, y += v.y, z += v.z;
        return *this;
    }
    constexpr Vec3& operator-=(const Vec3& v) {
        x -= v.x, y -= v.y, z -= v.z;
        return *this;
    }
    constexpr Vec3& operator*=(double s) {
        x *= s, y *= s, z *= s;
        return *this;
    }
    friend constexpr bool operator==(const Vec3&, const Vec3&) = default;
};

constexpr Vec3 operator+(Vec3 a, const Vec3& b) {
    return a += b;
}
constexpr Vec3 operator-(Vec3 a, const Vec3& b) {
    return a -= b;
}
constexpr Vec3 operator*(Vec3 a, double s) {
    return a *= s;
}
constexpr Vec3 operator*(double s, Vec3 a) {
    return a *= s;
}
constexpr Vec3 operator/(const Vec3& a, double s) {
    return a * (1.0 / s);
}
constexpr double dot(const Vec3& a, const Vec3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& v) {
    return std::sqrt(dot(v, v));
}
inline Vec3 normalize(const Vec3& v) {
    return v / length(v);
}
constexpr Vec3 min(const Vec3& a, const Vec3& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3 max(const Vec3& a, const Vec3& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
constexpr Vec3 lerp(const Vec3& a, const Vec3& b, double t) {
    return a + (b - a) * t;
}
inline double max_abs_component(const Vec3& v) {
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

// Marks a function whose loops vectorise. A portable build (no -march=native) compiles it twice,
// for AVX2 and for any x86-64, and the processor's version is chosen at run time; both do the
// same IEEE operations, so results do not depend on which runs. A build for this machine's
// processor needs neither the copy nor the indirect call that keeps it from being inlined.
#if defined(DRT_VECTOR_CLONES)
#define DRT_VECTORISED __attribute__((target_clones("avx2", "default")))
#else
#define DRT_VECTORISED
#endif

// max(0, v) on the bits (negative numbers have the sign bit set and become +0): with a
// comparison, the compiler moves a following square root into a branch, which keeps a loop
// from vectorising and is mispredicted where the sign varies.
inline double positive_part(double v) {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    return std::bit_cast<double>(bits & ((bits >> 63) - 1));
}

struct SinCos {
    double sin, cos;
};

// sin and cos of an angle a in [-π/4, π/4], within an ulp or two: the Taylor series in x = a²
// up to the first term below 1e-16 (a^15 for sin, a^16 for cos), summed by Estrin's scheme,
// pairs and then pairs of pairs, so that its terms need not wait on one another.
constexpr SinCos sincos_eighth(double a) {
    const double x = a * a, x2 = x * x, x4 = x2 * x2;
    const double sin_series = (1 - x * (1.0 / 6)) + x2 * (1.0 / 120 - x * (1.0 / 5040)) +
                              x4 * ((1.0 / 362880 - x * (1.0 / 39916800)) +
                                    x2 * (1.0 / 6227020800 - x * (1.0 / 1307674368000)));
    const double cos_series =
        (1 - x * 0.5) + x2 * (1.0 / 24 - x * (1.0 / 720)) +
        x4 * ((1.0 / 40320 - x * (1.0 / 3628800)) +
              x2 * (1.0 / 479001600 - x * (1.0 / 87178291200)) + x4 * (1.0 / 20922789888000));
    return {a * sin_series, cos_series};
}

// An angle 2π·turns, turns in [0, 1], as q quarter turns (0 .. 4) plus a in [-π/4, π/4].
struct QuarterTurns {
    int q;
    double a;
};
constexpr QuarterTurns quarter_turns(double turns) {
    const double quarters = turns * 4;
    const auto q = static_cast<int>(quarters + 0.5);
    return {q, (quarters - q) * (kPi / 2)};
}

// sin and cos of the angle 2π·turns, within an ulp or two, for turns in [0, 1] (exact at
// multiples of a quarter turn). Sampling takes one per glossy ray, and std::sin and std::cos,
// built for any argument, cost several times as much.
constexpr SinCos sincos_turns(double turns) {
    const auto [q, a] = quarter_turns(turns);
    // Rotating by q quarter turns swaps the two for odd q and flips their signs by (q & 2) and
    // ((q + 1) & 2); done on the bits, because a branch on a random quadrant is mispredicted
    // three times in four.
    const SinCos r = sincos_eighth(a);
    const std::uint64_t s = std::bit_cast<std::uint64_t>(r.sin);
    const std::uint64_t c = std::bit_cast<std::uint64_t>(r.cos);
    const std::uint64_t odd = 0 - static_cast<std::uint64_t>(q & 1);  // all ones for odd q
    const auto sign = [](int bit) { return static_cast<std::uint64_t>(bit & 2) << 62; };
    return {std::bit_cast<double>(((s & ~odd) | (c & odd)) ^ sign(q)),
            std::bit_cast<double>(((c & ~odd) | (s & odd)) ^ sign(q + 1))};
}

// Mirror direction of d about the normal n (both unit length).
constexpr Vec3 reflect(const Vec3& d, const Vec3& n) {
    return d - n * (2.0 * dot(d, n));
}

// An orthonormal basis around a unit vector, continuous except at one pole (Duff et al. 2017).
struct Frame {
    Vec3 t, b, n;
    static Frame around(const Vec3& n) {
        const double sign = std::copysign(1.0, n.z);
        const double a = -1.0 / (sign + n.z);
        const double k = n.x * n.y * a;
        return {{1.0 + sign * n.x * n.x * a, sign * k, -sign * n.x},
                {k, sign + n.y * n.y * a, -n.y},
                n};
    }
    constexpr Vec3 to_world(const Vec3& v) const { return t * v.x + b * v.y + n * v.z; }
};

// A direction about unit `n` with density cos θ / π, from a uniform point u of the unit square.
inline Vec3 cosine_direction(const Vec3& n, Vec2 u) {
    const double r = std::sqrt(u.x);
    const SinCos phi = sincos_turns(u.y);
    const Vec3 local{r * phi.cos, r * phi.sin, std::sqrt(std::max(0.0, 1 - u.x))};
    return normalize(Frame::around(n).to_world(local));
}

struct Interval {
    double min = 0, max = kInfinity;
    constexpr bool contains(double v) const { return min <= v && v <= max; }
    constexpr bool surrounds(double v) const { return min < v && v < max; }
};

// A solid sphere, as a region of space (the extent of a light, the bound of a box).
struct Ball {
    Vec3 centre;
    double radius = 0;
};

// Axis-aligned box; the default is empty so that union-growing works from it.
struct Bounds {
    Vec3 lo{kInfinity, kInfinity, kInfinity};
    Vec3 hi{-kInfinity, -kInfinity, -kInfinity};

    constexpr bool empty() const { return lo.x > hi.x; }
    constexpr Bounds& grow(const Vec3& p) {
        lo = min(lo, p), hi = max(hi, p);
        return *this;
    }
    constexpr Bounds& grow(const Bounds& b) {
        lo = min(lo, b.lo), hi = max(hi, b.hi);
        return *this;
    }
    constexpr Vec3 centre() const { return (lo + hi) * 0.5; }
    constexpr Vec3 extent() const { return hi - lo; }
    constexpr double surface_area() const {
        if (empty()) return 0;
        const Vec3 e = extent();
        return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
};

}  // namespace drt
