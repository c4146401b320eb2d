#include "drt/sampler.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include "drt/rng.h"

namespace drt {

namespace {

std::uint32_t key32(std::uint64_t h) {
    return static_cast<std::uint32_t>(h ^ (h >> 32));
}

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
// its constants were chosen by measuring, over 40000 keys, that every flip is a fair coin and
// the flips of any two prefixes are uncorrelated to within sampling error (depths 0 to 7).
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

constexpr double unit32(std::uint32_t x) {
    return x * 0x1.0p-32;
}

// The keys of one dimension's sequence: an index shuffle and a scramble per coordinate.
struct SobolKeys {
    std::uint32_t shuffle, x, y;
};

// One sequence per (seed, pixel, dimension, ray-tree branch).
SobolKeys sobol_keys(const PixelSample& s, std::uint32_t dim) {
    const std::uint64_t h = hash_of(s.seed, s.pixel, dim, s.path);
    return {static_cast<std::uint32_t>(h), static_cast<std::uint32_t>(h >> 32),
            static_cast<std::uint32_t>(mix64(h))};
}

// Van der Corput's point is reverse_bits(i), whose nested scramble reverse_bits(flip(reverse_bits(
// reverse_bits(i)))) is reverse_bits(flip(i)).
double scrambled_x(std::uint32_t i, std::uint32_t key) {
    return unit32(reverse_bits(flip_by_lower_bits(i, key)));
}

// Sample `index` of one dimension's copy of the 2-D Sobol sequence.
Vec2 sobol_point(std::uint32_t index, const SobolKeys& k) {
    const std::uint32_t i = nested_scramble(index, k.shuffle);
    return {scrambled_x(i, k.x), unit32(nested_scramble(sobol(i, 1), k.y))};
}

// The camera's dimensions (pixel area, lens, time) share one index shuffle and take Sobol
// dimensions 2*dim and 2*dim + 1 of one sequence, so that they are stratified jointly: a pixel's
// samples then spread over pixel area and lens together, not over each alone. Each Sobol
// dimension has its own scramble.
bool is_camera_dim(std::uint32_t dim) {
    return dim <= dim::kTime;
}

struct CameraSample {
    std::uint32_t i;  // the shuffled index
    std::uint64_t h;  // the pixel's camera key
};

CameraSample camera_sample(const PixelSample& s) {
    const std::uint64_t h = hash_of(s.seed, s.pixel, s.path, 0xca3e7aULL);
    return {nested_scramble(s.index, static_cast<std::uint32_t>(h)), h};
}

double camera_coordinate(const CameraSample& c, int d) {
    const auto key = static_cast<std::uint32_t>(mix64(c.h + static_cast<std::uint64_t>(d) + 1));
    return unit32(nested_scramble(sobol(c.i, d), key));
}

}  // namespace

void Sampler::get_2d_run(const PixelSample& s, std::uint32_t dim, std::span<Vec2> out) const {
    PixelSample sample = s;
    for (Vec2& point : out) {
        point = get_2d(sample, dim);
        ++sample.index;
    }
}

void Sampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k,
                         std::uint32_t first, std::span<Vec2> out) const {
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = get_2d_in_set(s, dim, first + static_cast<std::uint32_t>(i), k);
    }
}

Vec2 RunPoints::get_2d(const PixelSample& s, std::uint32_t dim) {
    const std::uint32_t at = s.index - first_.index;
    const bool in_run = s.seed == first_.seed && s.pixel == first_.pixel &&
                        s.count == first_.count && s.index >= first_.index && at < length_;
    if (!in_run) return sampler_.get_2d(s, dim);
    auto found = std::find_if(remembered_.begin(), remembered_.end(), [&](const Remembered& r) {
        return r.dim == dim && r.path == s.path;
    });
    if (found == remembered_.end()) {
        if (remembered_.size() == kMaxRemembered) return sampler_.get_2d(s, dim);
        found = remembered_.insert(remembered_.end(), Remembered{dim, s.path, 0, {}});
    }
    if (!found->points.empty()) return found->points[at];
    if (++found->requests < kDrawAfter) return sampler_.get_2d(s, dim);
    PixelSample run = first_;
    run.path = s.path;
    found->points.resize(length_);
    sampler_.get_2d_run(run, dim, found->points);
    return found->points[at];
}

PixelSample PixelSample::branch(std::uint64_t kind, std::uint64_t j) const {
    PixelSample child = *this;
    child.path = hash_of(path, kind, j);
    return child;
}

double IndependentSampler::get_1d(const PixelSample& s, std::uint32_t dim) const {
    return to_unit(hash_of(s.seed, s.pixel, s.index, dim, s.path));
}

Vec2 IndependentSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    const std::uint64_t h = hash_of(s.seed, s.pixel, s.index, dim, s.path);
    return {to_unit(h), to_unit(mix64(h))};
}

Vec2 IndependentSampler::get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                                       std::uint32_t) const {
    const std::uint64_t h = hash_of(s.seed, s.pixel, s.index, dim, s.path, j);
    return {to_unit(h), to_unit(mix64(h))};
}

void IndependentSampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t,
                                    std::uint32_t first, std::span<Vec2> out) const {
    // hash_of folds left, so the hash of (..., path, j) continues the one of (..., path).
    const std::uint64_t set = hash_of(s.seed, s.pixel, s.index, dim, s.path);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const std::uint64_t h = hash_combine(set, static_cast<std::uint32_t>(first + i));
        out[i] = {to_unit(h), to_unit(mix64(h))};
    }
}

namespace {

// Exactly double(x) for x < 2^52, in integer operations that vectorise (x86 before AVX-512 has
// no instruction converting 64-bit integers to doubles).
double small_to_double(std::uint64_t x) {
    return std::bit_cast<double>(x | 0x4330000000000000ULL) - 0x1.0p52;
}

// to_unit(h), in operations that vectorise: h >> 11 < 2^53 in two exact halves, whose sum is
// exact too.
double unit_of(std::uint64_t h) {
    const std::uint64_t x = h >> 11;
    return (small_to_double(x >> 32) * 0x1.0p32 + small_to_double(x & 0xffffffffu)) * 0x1.0p-53;
}

// Kensler's pattern for any k: an m x n grid of cells, m*n >= k, as square as possible. Point
// s (a shuffled j) takes its own stratum of y among k strata, and its own column sx and
// sub-column sy of x among m*n; when k = m*n each cell of the grid holds exactly one point.
// Which of the m*n sub-columns stay empty when k < m*n is left to the shuffles, so every point
// is uniform over the square (a fixed choice would leave a corner unsampled).
struct JitteredGrid {
    std::uint32_t k, m, n, key;
    JitteredGrid(std::uint32_t k_, std::uint32_t key_)
        : k(k_),
          m(std::max(1u, static_cast<std::uint32_t>(std::sqrt(double(k_))))),  // floor
          n((k_ + m - 1) / m),
          key(key_) {}

    std::uint32_t stratum(std::uint32_t j) const { return permute(j, k, stratum_key()); }
    std::uint32_t stratum_key() const { return key * 0x51633e2du; }
    std::uint32_t column(std::uint32_t c) const { return permute(c, m, column_key()); }
    std::uint32_t sub_column(std::uint32_t r) const { return permute(r, n, sub_column_key()); }
    std::uint32_t column_key() const { return key * 0x68bc21ebu; }
    std::uint32_t sub_column_key() const { return key * 0x02e5be93u; }

    // The hash the points' jitters continue: hash_of(key, s, c) = hash_combine(hash_combine(
    // key_hash(), s), c).
    std::uint64_t key_hash() const { return hash_of(key); }

    // The point of stratum s in column sx and sub-column sy, in operations that vectorise.
    Vec2 point(std::uint64_t key_hash, std::uint32_t s, std::uint32_t sx, std::uint32_t sy) const {
        const std::uint64_t h = hash_combine(key_hash, s);
        const double jx = unit_of(hash_combine(h, 1));
        const double jy = unit_of(hash_combine(h, 2));
        return {(small_to_double(sx) + (small_to_double(sy) + jx) / n) / m,
                (small_to_double(s) + jy) / k};
    }
};

// permute(first + i, n, key) into out[i]. Every index takes a step, and then those still
// outside [0, n) another, pass after pass over all of them (the others left as they are) until
// none is: the same walks as permute's, in loops that vectorise, where a walk per index would
// mispredict its end about once per index.
DRT_VECTORISED void permute_run(std::uint32_t first, std::uint32_t n, std::uint32_t key,
                                std::uint32_t* out, std::size_t count) {
    const std::uint32_t w = permute_mask(n);
    std::uint32_t walking = 0;  // an integer: a bool's |= keeps the loop from vectorising
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t x = permute_step(first + static_cast<std::uint32_t>(i), w, key);
        out[i] = x;
        walking |= static_cast<std::uint32_t>(x >= n);
    }
    while (walking != 0) {
        walking = 0;
        for (std::size_t i = 0; i < count; ++i) {
            const std::uint32_t stepped = permute_step(out[i], w, key);
            const std::uint32_t x = out[i] >= n ? stepped : out[i];
            out[i] = x;
            walking |= static_cast<std::uint32_t>(x >= n);
        }
    }
    for (std::size_t i = 0; i < count; ++i) out[i] = permute_rotate(out[i], n, key);
}

// grid.point(s, column_of[s], sub_column_of[s]) for each stratum s = strata[i], into out[i].
DRT_VECTORISED void grid_points(const JitteredGrid& grid, const std::uint32_t* strata,
                                const std::uint32_t* column_of, const std::uint32_t* sub_column_of,
                                Vec2* out, std::size_t count) {
    const std::uint64_t key_hash = grid.key_hash();
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t s = strata[i];
        out[i] = grid.point(key_hash, s, column_of[s], sub_column_of[s]);
    }
}

}  // namespace

Vec2 multi_jittered(std::uint32_t j, std::uint32_t k, std::uint32_t key) {
    const JitteredGrid grid(k, key);
    const std::uint32_t s = grid.stratum(j);
    return grid.point(grid.key_hash(), s, grid.column(s % grid.m), grid.sub_column(s / grid.m));
}

void multi_jittered_run(std::uint32_t first, std::uint32_t k, std::uint32_t key,
                        std::span<Vec2> out) {
    const JitteredGrid grid(k, key);
    // Tabulating costs m + n shuffle evaluations, worth it once a run has more points than that.
    constexpr std::uint32_t kTabulated = 64;
    if (grid.n > kTabulated || out.size() < grid.m + grid.n) {
        for (std::size_t i = 0; i < out.size(); ++i) {
            out[i] = multi_jittered(first + static_cast<std::uint32_t>(i), k, key);
        }
        return;
    }
    std::array<std::uint32_t, kTabulated> columns, sub_columns;
    permute_run(0, grid.m, grid.column_key(), columns.data(), grid.m);
    permute_run(0, grid.n, grid.sub_column_key(), sub_columns.data(), grid.n);
    // Each stratum's column and sub-column, and the run's strata, a batch at a time.
    constexpr std::size_t kBatch = 256;
    std::array<std::uint32_t, kTabulated * kTabulated> column_of, sub_column_of;  // k <= m n
    for (std::uint32_t row = 0, s = 0; row < grid.n; ++row) {
        for (std::uint32_t col = 0; col < grid.m && s < k; ++col, ++s) {
            column_of[s] = columns[col];
            sub_column_of[s] = sub_columns[row];
        }
    }
    std::array<std::uint32_t, kBatch> strata;
    for (std::size_t done = 0; done < out.size(); done += kBatch) {
        const std::size_t count = std::min(kBatch, out.size() - done);
        permute_run(first + static_cast<std::uint32_t>(done), k, grid.stratum_key(), strata.data(),
                    count);
        grid_points(grid, strata.data(), column_of.data(), sub_column_of.data(), out.data() + done,
                    count);
    }
}

namespace {

// Uniform random choices from few hashes: each choice of one of c takes the next digit of a
// 32-bit random fraction f in radix c (the digit floor(f c), and f becomes frac(f c)), so one
// hash serves several choices. A new hash is drawn before the digits taken so far would leave
// under 12 bits of the fraction, which keeps every choice within 2^-12 of its share in relative
// terms (and the sets the choices make are averaged over millions of shading points).
class Digits {
  public:
    // The first digits come from `first`, later ones from hashes of `seed`.
    Digits(std::uint32_t first, std::uint64_t seed) : seed_(seed), fraction_(first) {}

    // Uniform in [0, c), for 1 <= c <= 2^12.
    std::uint32_t below(std::uint32_t c) {
        if (used_ * c > kMaxUsed) fraction_ = fresh(), used_ = 1;
        used_ *= c;
        const std::uint64_t product = std::uint64_t{fraction_} * c;
        fraction_ = static_cast<std::uint32_t>(product);
        return static_cast<std::uint32_t>(product >> 32);
    }

  private:
    static constexpr std::uint64_t kMaxUsed = 1u << 20;  // of the fraction's 32 bits
    std::uint32_t fresh() { return static_cast<std::uint32_t>(mix64(seed_ + ++draws_) >> 32); }

    std::uint64_t seed_;
    std::uint64_t draws_ = 0, used_ = 1;
    std::uint32_t fraction_;
};

// Every order of 0 .. n-1 for n up to kListedOrders, as n hexadecimal digits (digit c is the
// c-th element), in lexicographic order.
constexpr std::uint32_t kListedOrders = 5;
using OrderList = std::array<std::uint32_t, 1 + 1 + 2 + 6 + 24 + 120>;  // sum of n! for n <= 5
constexpr std::array<std::uint32_t, kListedOrders + 2> kOrderListStart = {0, 1, 2, 4, 10, 34, 154};
constexpr OrderList kOrders = [] {
    OrderList list{};
    for (std::uint32_t n = 0; n <= kListedOrders; ++n) {
        std::array<std::uint32_t, kListedOrders> order{};
        for (std::uint32_t c = 0; c < n; ++c) order[c] = c;
        for (std::uint32_t i = kOrderListStart[n]; i < kOrderListStart[n + 1]; ++i) {
            for (std::uint32_t c = 0; c < n; ++c) list[i] |= order[c] << (4 * c);
            std::next_permutation(order.begin(), order.begin() + n);
        }
    }
    return list;
}();

// A uniformly random order of 0 .. out.size()-1: one of the listed orders when they are few,
// else dealt by Fisher-Yates.
void shuffle(std::span<std::uint32_t> out, Digits& digits) {
    const auto size = static_cast<std::uint32_t>(out.size());
    if (size <= kListedOrders) {
        const std::uint32_t start = kOrderListStart[size];
        const std::uint32_t order =
            kOrders[start + digits.below(kOrderListStart[size + 1] - start)];
        for (std::uint32_t c = 0; c < size; ++c) out[c] = (order >> (4 * c)) & 15u;
        return;
    }
    for (std::uint32_t c = 0; c < out.size(); ++c) out[c] = c;
    for (auto c = static_cast<std::uint32_t>(out.size()); c > 1; --c) {
        std::swap(out[c - 1], out[digits.below(c)]);
    }
}

// A 32-bit bijective hash with full avalanche (Wellons' "lowbias32" constants); 32-bit
// multiplies, unlike 64-bit ones, vectorise on x86 before AVX-512.
constexpr std::uint32_t hash32(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    return x ^ (x >> 16);
}

// `count` points of a set of k strata in which stratum s has the cell cell_of[s] of the m x n
// grid, from stratum `start` on: x = (cell + jx) / (m n), y = (s + jy) / k, the jitters keyed by
// `key`. The jitters' 32 bits keep both below 1 for any k < 2^20, and the clamp beyond.
// Vectorised, it does the same operations several lanes at a time: its points are bit-identical.
DRT_VECTORISED void jittered_points(std::uint64_t key, std::uint32_t start, std::uint32_t k,
                                    const std::uint32_t* cell_of, double inv_cells, double inv_k,
                                    Vec2* out, std::size_t count) {
    constexpr double kBelowOne = 0x1.fffffffffffffp-1;
    const auto key_x = static_cast<std::uint32_t>(key),
               key_y = static_cast<std::uint32_t>(key >> 32);
    for (std::size_t i = 0; i < count; ++i) {
        std::uint32_t s = start + static_cast<std::uint32_t>(i);
        s = s < k ? s : s - k;  // start < k and count <= k
        const std::uint32_t jx = hash32(s + key_x);
        const std::uint32_t jy = hash32(jx ^ key_y);
        const double x =
            (small_to_double(cell_of[s]) + small_to_double(jx) * 0x1.0p-32) * inv_cells;
        const double y = (small_to_double(s) + small_to_double(jy) * 0x1.0p-32) * inv_k;
        out[i] = {x < kBelowOne ? x : kBelowOne, y < kBelowOne ? y : kBelowOne};
    }
}

}  // namespace

void multi_jittered_set(std::uint32_t first, std::uint32_t k, std::uint32_t key,
                        std::span<Vec2> out) {
    // Kensler's pattern as above, with economies for sets, which are always used whole: the
    // points are labelled by a rotation of the strata rather than a shuffle (each point is still
    // uniform over the square, and the set as a whole is the same pattern), and the shuffles of
    // the grid's columns and sub-columns, which every point shares, are dealt once by
    // Fisher-Yates from as few hashes as they need (one for k up to 20) and tabulated per
    // stratum.
    const JitteredGrid grid(k, key);
    const std::uint32_t m = grid.m, n = grid.n;
    const std::uint64_t h = mix64(key ^ 0x7f4a7c159e3779b9ULL);
    Digits digits(static_cast<std::uint32_t>(h >> 32), h ^ 0x68bc21ebu);
    // The cell sx * n + sy of each stratum s = row * m + col: sx a shuffled col, sy a shuffled row.
    constexpr std::uint32_t kSmall = 1024, kSides = 64;  // k <= 1024 has n <= 64
    std::array<std::uint32_t, kSmall> small_table;
    std::vector<std::uint32_t> large_table;
    if (k > kSmall) large_table.resize(k);
    const std::span<std::uint32_t> cell_of =
        k > kSmall ? std::span(large_table) : std::span(small_table).first(k);
    if (k <= kSmall) {
        std::array<std::uint32_t, kSides> column, sub_column;
        shuffle(std::span(column).first(m), digits);
        shuffle(std::span(sub_column).first(n), digits);
        for (std::uint32_t row = 0, s = 0; row < n; ++row) {
            for (std::uint32_t col = 0; col < m && s < k; ++col, ++s) {
                cell_of[s] = column[col] * n + sub_column[row];
            }
        }
    } else {
        for (std::uint32_t s = 0; s < k; ++s) {
            cell_of[s] = grid.column(s % m) * n + grid.sub_column(s / m);
        }
    }
    const std::uint32_t rotation =
        k <= 4096 ? digits.below(k) : static_cast<std::uint32_t>(((h >> 32) * k) >> 32);
    // x = (sx + (sy + jx) / n) / m and y = (s + jy) / k, with the divisions as products.
    const double inv_cells = 1.0 / (double(m) * n), inv_k = 1.0 / k;
    // A pass of at most k points at a time, so that the strata wrap around at most once.
    for (std::size_t done = 0; done < out.size(); done += k) {
        const std::uint32_t at = first + static_cast<std::uint32_t>(done);
        std::uint32_t start = (at < k ? at : at % k) + rotation;
        if (start >= k) start -= k;
        jittered_points(mix64(h), start, k, cell_of.data(), inv_cells, inv_k, out.data() + done,
                        std::min<std::size_t>(k, out.size() - done));
    }
}

double StratifiedSampler::get_1d(const PixelSample& s, std::uint32_t dim) const {
    const std::uint32_t key = key32(hash_of(s.seed, s.pixel, dim, s.path));
    const double jitter = to_unit(hash_of(s.seed, s.pixel, s.index, dim, s.path));
    return (permute(s.index, s.count, key) + jitter) / s.count;
}

Vec2 StratifiedSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    return multi_jittered(s.index, s.count, key32(hash_of(s.seed, s.pixel, dim, s.path)));
}

void StratifiedSampler::get_2d_run(const PixelSample& s, std::uint32_t dim,
                                   std::span<Vec2> out) const {
    multi_jittered_run(s.index, s.count, key32(hash_of(s.seed, s.pixel, dim, s.path)), out);
}

namespace {

// The key of one camera sample's set in one dimension of one ray-tree branch: (seed, pixel,
// sample, dimension, branch) folded into three hashes rather than five, since sets are drawn
// at every shading point.
std::uint32_t set_key(const PixelSample& s, std::uint32_t dim) {
    const std::uint64_t sample = (std::uint64_t{s.pixel} << 32) | s.index;
    return key32(hash_of(s.seed, sample, s.path ^ (std::uint64_t{dim} * 0x9e3779b97f4a7c15ULL)));
}

}  // namespace

Vec2 StratifiedSampler::get_2d_in_set(const PixelSample& s, std::uint32_t dim, std::uint32_t j,
                                      std::uint32_t k) const {
    Vec2 point;
    multi_jittered_set(j, k, set_key(s, dim), {&point, 1});
    return point;
}

void StratifiedSampler::get_2d_set(const PixelSample& s, std::uint32_t dim, std::uint32_t k,
                                   std::uint32_t first, std::span<Vec2> out) const {
    multi_jittered_set(first, k, set_key(s, dim), out);
}

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
    if (is_camera_dim(dim)) return camera_coordinate(camera_sample(s), 2 * static_cast<int>(dim));
    const SobolKeys k = sobol_keys(s, dim);
    return scrambled_x(nested_scramble(s.index, k.shuffle), k.x);
}

Vec2 SobolSampler::get_2d(const PixelSample& s, std::uint32_t dim) const {
    if (is_camera_dim(dim)) {
        const CameraSample c = camera_sample(s);
        const int d = 2 * static_cast<int>(dim);
        return {camera_coordinate(c, d), camera_coordinate(c, d + 1)};
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
            unit32(reverse_bits(flip_by_lower_bits(y_rev, set.keys.y)))};
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

std::unique_ptr<Sampler> make_sampler(std::string_view name) {
    if (name == "random") return std::make_unique<IndependentSampler>();
    if (name == "stratified") return std::make_unique<StratifiedSampler>();
    if (name == "sobol") return std::make_unique<SobolSampler>();
    return nullptr;
}

std::vector<std::string> sampler_names() {
    return {"random", "stratified", "sobol"};
}

}  // namespace drt
