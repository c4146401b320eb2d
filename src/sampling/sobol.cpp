#include "drt/sampling/sobol.h"

#include <algorithm>
#include <array>
#include <bit>

#include "drt/sampling/dimension_memo.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

constexpr std::uint32_t reverse_bits(std::uint32_t x) {
    x = (x >> 16) | (x << 16);
    x = ((x & 0xff00ff00u) >> 8) | ((x & 0x00ff00ffu) << 8);
    x = ((x & 0xf0f0f0f0u) >> 4) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x & 0xccccccccu) >> 2) | ((x & 0x33333333u) << 2);
    return ((x & 0xaaaaaaaau) >> 1) | ((x & 0x55555555u) << 1);
}

// A keyed bijection in which bit b of the result is bit b of x flipped by a function of the key
// and of bits 0 .. b-1 of x: adding a number, multiplying by an odd number and xoring with a
// product by an even number each have that form, and so has any chain of them. The chain and
// its constants are chosen so that, over keys, every flip is a fair coin and the flips of any two
// prefixes are uncorrelated, as sobol_test checks.
constexpr std::uint32_t flip_by_lower_bits(std::uint32_t x, std::uint32_t key) {
    const std::uint32_t key2 = (key * 0x9e3779b9u) ^ (key >> 15);
    x ^= x * 0x3b9f2e5cu;
    x += key;
    x *= key2 | 1u;
    x ^= x * 0x7e1d9a34u;
    x += (key2 >> 7) ^ (key << 9);
    x ^= x * 0x4f0c6a28u;
    x *= 0x2c8fb3d5u;
    x ^= x * 0xa61e7b52u;
    return x;
}

// Direction numbers v_b = m_b / 2^(b+1) of the first Sobol dimensions, from Bratley and Fox's
// recurrence m_b = 2 a_1 m_(b-1) ^ 4 a_2 m_(b-2) ^ ... ^ 2^s m_(b-s) ^ m_(b-s) for a primitive
// polynomial x^s + a_1 x^(s-1) + ... + 1 and initial odd m_b < 2^(b+1) (Joe and Kuo's table).
// Dimension 0 is van der Corput (v_b = 2^-(b+1)).
struct SobolPolynomial {
    unsigned degree, middle;         // s, and a_1 .. a_(s-1) as the bits of `middle`
    std::array<std::uint32_t, 4> m;  // the first s values of m
};
constexpr SobolPolynomial kSobolPolynomials[kSobolDimensions - 1] = {
    {1, 0, {1}},           // x + 1
    {2, 1, {1, 3}},        // x^2 + x + 1
    {3, 1, {1, 3, 1}},     // x^3 + x + 1
    {3, 2, {1, 1, 1}},     // x^3 + x^2 + 1
    {4, 1, {1, 1, 3, 3}},  // x^4 + x + 1
};
using Directions = std::array<std::array<std::uint32_t, 32>, kSobolDimensions>;
constexpr Directions kSobolDirections = [] {
    Directions v{};
    for (std::size_t b = 0; b < 32; ++b) v[0][b] = 1u << (31 - b);
    for (std::size_t d = 1; d < kSobolDimensions; ++d) {
        const SobolPolynomial& p = kSobolPolynomials[d - 1];
        std::array<std::uint32_t, 32> m{};
        for (std::size_t b = 0; b < 32; ++b) {
            if (b < p.degree) {
                m[b] = p.m[b];
                continue;
            }
            m[b] = m[b - p.degree] ^ (m[b - p.degree] << p.degree);
            for (unsigned k = 1; k < p.degree; ++k) {
                if ((p.middle >> (p.degree - 1 - k)) & 1u) m[b] ^= m[b - k] << k;
            }
        }
        for (std::size_t b = 0; b < 32; ++b) v[d][b] = m[b] << (31 - b);
    }
    return v;
}();

// sobol(i, d) = xor of the direction numbers of i's set bits, tabulated per byte of i: the index
// shuffle sets high bits, so a loop over bits would run 32 times.
using ByteTables = std::array<std::array<std::array<std::uint32_t, 256>, 4>, kSobolDimensions>;
constexpr ByteTables kSobolBytes = [] {
    ByteTables t{};
    for (std::size_t d = 0; d < kSobolDimensions; ++d) {
        for (std::size_t byte = 0; byte < 4; ++byte) {
            for (std::size_t v = 0; v < 256; ++v) {
                std::uint32_t x = 0;
                for (std::size_t b = 0; b < 8; ++b) {
                    if ((v >> b) & 1u) x ^= kSobolDirections[d][8 * byte + b];
                }
                t[d][byte][v] = x;
            }
        }
    }
    return t;
}();

// The keys of one dimension's sequence: an index shuffle and a scramble per coordinate.
struct SobolKeys {
    std::uint32_t shuffle, x, y;
};

// One sequence per (seed, pixel, dimension, ray-tree branch).
SobolKeys sobol_keys(const PixelSample& s, std::uint32_t dim) {
    thread_local DimensionMemo<SobolKeys> memo;
    return memo.get(s, dim, [&] {
        const std::uint64_t h = hash_of(s.seed, s.pixel, dim, s.path);
        return SobolKeys{static_cast<std::uint32_t>(h), static_cast<std::uint32_t>(h >> 32),
                         static_cast<std::uint32_t>(mix64(h))};
    });
}

// Van der Corput's point is reverse_bits(i), whose nested scramble reverse_bits(flip(reverse_bits(
// reverse_bits(i)))) is reverse_bits(flip(i)).
double scrambled_x(std::uint32_t i, std::uint32_t key) {
    return to_unit(reverse_bits(flip_by_lower_bits(i, key)));
}

// Sample `index` of one dimension's copy of the 2-D Sobol sequence.
Vec2 sobol_point(std::uint32_t index, const SobolKeys& k) {
    const std::uint32_t i = nested_scramble(index, k.shuffle);
    return {scrambled_x(i, k.x), to_unit(nested_scramble(sobol(i, 1), k.y))};
}

// The camera's dimensions (pixel area, lens, time) share one index shuffle and take Sobol
// dimensions 2*dim and 2*dim + 1 of one sequence, so that they are stratified jointly: a pixel's
// samples then spread over pixel area and lens together, not over each alone. Each Sobol
// dimension has its own scramble.
bool is_camera_dim(std::uint32_t dim) {
    return dim <= dim::kTime;
}

// The keys of camera dimension `dim`: the pixel's index shuffle (`shuffle`) and the scrambles of
// Sobol dimensions 2*dim (`x`) and 2*dim + 1 (`y`).
SobolKeys camera_keys(const PixelSample& s, std::uint32_t dim) {
    thread_local DimensionMemo<SobolKeys> memo;
    return memo.get(s, dim, [&] {
        const std::uint64_t h = hash_of(s.seed, s.pixel, s.path, 0xca3e7aULL);
        const auto key = [&](std::uint64_t d) {
            return static_cast<std::uint32_t>(mix64(h + d + 1));
        };
        return SobolKeys{static_cast<std::uint32_t>(h), key(2 * dim), key(2 * dim + 1)};
    });
}

double camera_coordinate(std::uint32_t i, int d, std::uint32_t key) {
    return to_unit(nested_scramble(sobol(i, d), key));
}

}  // namespace

std::uint32_t nested_scramble(std::uint32_t x, std::uint32_t key) {
    // Reversed, the most significant digit becomes bit 0, which the flips depend on first.
    return reverse_bits(flip_by_lower_bits(reverse_bits(x), key));
}

std::uint32_t sobol(std::uint32_t i, int dimension) {
    if (dimension == 0) return reverse_bits(i);
    const auto& t = kSobolBytes[static_cast<std::size_t>(dimension)];
    return t[0][i & 0xffu] ^ t[1][(i >> 8) & 0xffu] ^ t[2][(i >> 16) & 0xffu] ^ t[3][i >> 24];
}

double SobolSampler::get_1d(const PixelSample& s, std::uint32_t dim) const {
    if (is_camera_dim(dim)) {
        const SobolKeys k = camera_keys(s, dim);
        return camera_coordinate(nested_scramble(s.index, k.shuffle), 2 * static_cast<int>(dim),
                                 k.x);
    }
    const SobolKeys k = sobol_keys(s, dim);
    return scrambled_x(nested_scramble(s.index, k.shuffle), k.x);
}

Vec2 SobolSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    if (is_camera_dim(dim)) {
        const SobolKeys k = camera_keys(s, dim);
        const std::uint32_t i = nested_scramble(s.index, k.shuffle);
        const int d = 2 * static_cast<int>(dim);
        return {camera_coordinate(i, d, k.x), camera_coordinate(i, d + 1, k.y)};
    }
    return sobol_point(s.index, sobol_keys(s, dim));
}

namespace {

// The set of k points of camera sample s.index: from the aligned block of K = k rounded up to a
// power of two indices that the shuffle sends block s.index of size K to, the points
// start + (j xor c), j < k. Any such run of 2^m points is an aligned sub-block, so a net. The
// offset c, drawn per block, varies which K - k points go unused from one camera sample to the
// next: with c = 0 the same ones would, and the low index bits fix the top digits of a point, so
// a pixel's sets would all leave the same strata of the light empty.
struct SobolSet {
    SobolKeys keys;
    std::uint32_t start;        // the block's first index
    std::uint32_t offset;       // c
    std::uint32_t start_y_rev;  // reverse_bits(sobol(start, 1))
};

SobolSet sobol_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k) {
    const SobolKeys keys = sobol_keys(s, dim);
    const std::uint32_t stride = std::bit_ceil(std::max(k, 1u));
    const std::uint32_t start = nested_scramble(s.index * stride, keys.shuffle) & ~(stride - 1);
    // A full hash: a multiplicative one of consecutive starts is itself a low-discrepancy
    // sequence, correlated with the points' own strata.
    const auto offset = static_cast<std::uint32_t>(
        (mix64(std::uint64_t{start} ^ (std::uint64_t{keys.y} << 32)) >> 32) & (stride - 1));
    return {keys, start, offset, reverse_bits(sobol(start, 1))};
}

// Point j: the block's start and j xor c have no bit in common, so the Sobol coordinates are
// those of the start xor those of j xor c, and the y scramble can work on the reversed value.
Vec2 set_point(const SobolSet& set, std::uint32_t j) {
    const std::uint32_t low = j ^ set.offset;
    const std::uint32_t y_rev = set.start_y_rev ^ reverse_bits(sobol(low, 1));
    return {scrambled_x(set.start | low, set.keys.x),
            to_unit(reverse_bits(flip_by_lower_bits(y_rev, set.keys.y)))};
}

}  // namespace

Vec2 SobolSampler::get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                                 std::uint32_t k) const {
    return set_point(sobol_set(s, dim, k), j);
}

void SobolSampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k,
                              std::uint32_t first, std::span<Vec2> out) const {
    const SobolSet set = sobol_set(s, dim, k);
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = set_point(set, first + static_cast<std::uint32_t>(i));
    }
}

}  // namespace drt
