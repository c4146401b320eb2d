#include "drt/geometry/collinear.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace drt {

namespace {

// A finite double as ±m·2^e, m a whole number below 2^53 (0 for zero).
struct Dyadic {
    std::uint64_t m;
    int e;
    bool negative;
};

Dyadic dyadic(double x) {
    int e = 0;
    const double f = std::frexp(std::abs(x), &e);  // |x| = f·2^e, f in [0.5, 1)
    return {static_cast<std::uint64_t>(std::ldexp(f, 53)), e - 53, std::signbit(x)};
}

// The full 128-bit product a·b as {low word, high word}.
std::array<std::uint64_t, 2> product(std::uint64_t a, std::uint64_t b) {
    constexpr std::uint64_t kLow = 0xffffffff;
    const std::uint64_t a0 = a & kLow, a1 = a >> 32, b0 = b & kLow, b1 = b >> 32;
    const std::uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    const std::uint64_t middle = (p00 >> 32) + (p01 & kLow) + (p10 & kLow);
    return {(middle << 32) | (p00 & kLow), p11 + (p01 >> 32) + (p10 >> 32) + (middle >> 32)};
}

// A whole number of up to 68 64-bit words, least significant first: enough for three products
// of two mantissas (106 bits each) shifted by up to the whole range of a product's exponent
// (2 · 971 - 2 · -1126 = 4194 bits).
using Wide = std::array<std::uint64_t, 68>;

// sum += (hi·2^64 + lo)·2^shift
void add_shifted(Wide& sum, std::array<std::uint64_t, 2> value, int shift) {
    const auto [lo, hi] = value;
    const int word = shift / 64, bit = shift % 64;
    const std::uint64_t parts[3] = {lo << bit, bit == 0 ? hi : (hi << bit) | (lo >> (64 - bit)),
                                    bit == 0 ? 0 : hi >> (64 - bit)};
    std::uint64_t carry = 0;
    for (std::size_t k = static_cast<std::size_t>(word); k < sum.size(); ++k) {
        const std::size_t part = k - static_cast<std::size_t>(word);
        const std::uint64_t add = part < 3 ? parts[part] : 0;
        if (part >= 3 && carry == 0) break;
        const std::uint64_t with_part = sum[k] + add;
        const std::uint64_t total = with_part + carry;
        carry = (with_part < add ? 1u : 0u) + (total < with_part ? 1u : 0u);
        sum[k] = total;
    }
}

// Whether u_a v_b - v_a u_b + u_b v_c - v_b u_c + u_c v_a - v_c u_a, twice the signed area of
// the triangle (u, v)_a, (u, v)_b, (u, v)_c of the plane, is exactly zero.
bool zero_area_exactly(double ua, double va, double ub, double vb, double uc, double vc) {
    struct Term {
        double x, y;
        bool subtracted;
    };
    const Term terms[6] = {{ua, vb, false}, {va, ub, true},  {ub, vc, false},
                           {vb, uc, true},  {uc, va, false}, {vc, ua, true}};
    Dyadic factors[6][2];
    int lowest = std::numeric_limits<int>::max();
    for (int k = 0; k < 6; ++k) {
        factors[k][0] = dyadic(terms[k].x);
        factors[k][1] = dyadic(terms[k].y);
        if (factors[k][0].m != 0 && factors[k][1].m != 0)
            lowest = std::min(lowest, factors[k][0].e + factors[k][1].e);
    }
    // The positive and the negative terms summed apart, in units of 2^lowest.
    Wide positive{}, negative{};
    for (int k = 0; k < 6; ++k) {
        const auto& [x, y] = factors[k];
        if (x.m == 0 || y.m == 0) continue;
        const bool below = (x.negative != y.negative) != terms[k].subtracted;
        add_shifted(below ? negative : positive, product(x.m, y.m), x.e + y.e - lowest);
    }
    return positive == negative;
}

// The same, first in double, which settles all but (nearly) collinear points: the computed
// value is off by at most about 3u (|left| + |right|), u = 2^-53 (Shewchuk 1997, orient2d), plus
// a few smallest subnormals where a product underflows; `bound` is well above both.
bool zero_area(double ua, double va, double ub, double vb, double uc, double vc) {
    const double left = (ua - uc) * (vb - vc), right = (va - vc) * (ub - uc);
    const double bound =
        4 * std::numeric_limits<double>::epsilon() * (std::abs(left) + std::abs(right)) + 0x1p-1000;
    // (An overflow makes bound infinite or the difference NaN: decided exactly.)
    if (std::abs(left - right) > bound) return false;
    return zero_area_exactly(ua, va, ub, vb, uc, vc);
}

}  // namespace

bool collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
    // Collinear in space exactly when collinear seen down each of the three axes.
    return zero_area(a.x, a.y, b.x, b.y, c.x, c.y) && zero_area(a.y, a.z, b.y, b.z, c.y, c.z) &&
           zero_area(a.z, a.x, b.z, b.x, c.z, c.x);
}

}  // namespace drt
