#include "drt/sampling/multi_jittered.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include "drt/util/rng.h"

namespace drt {

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

// A uniformly random one of the listed orders of 0 .. size-1, size <= kListedOrders.
std::uint32_t listed_order(std::uint32_t size, Digits& digits) {
    const std::uint32_t start = kOrderListStart[size];
    return kOrders[start + digits.below(kOrderListStart[size + 1] - start)];
}

// A uniformly random order of 0 .. out.size()-1: one of the listed orders when they are few,
// else dealt by Fisher-Yates.
void shuffle(std::span<std::uint32_t> out, Digits& digits) {
    const auto size = static_cast<std::uint32_t>(out.size());
    if (size <= kListedOrders) {
        const std::uint32_t order = listed_order(size, digits);
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

// The grid of k points: m = floor(sqrt(k)) columns by n rows, m*n >= k, and the reciprocals the
// points are scaled by. Tabulated for the counts that sets and pixels use, because the square
// root and three divisions cost as much as a small set's points; a constant expression rounds
// each reciprocal exactly as the run-time division does.
struct Shape {
    std::uint32_t m = 1, n = 0;
    double inv_cells = 0, inv_k = 0;
};

constexpr Shape shape_of(std::uint32_t k, std::uint32_t m) {
    const std::uint32_t n = (k + m - 1) / m;
    return {m, n, 1.0 / (double(m) * n), 1.0 / k};
}

constexpr std::uint32_t kTabledShapes = 512;
constexpr std::array<Shape, kTabledShapes> kShapes = [] {
    std::array<Shape, kTabledShapes> shapes{};
    for (std::uint32_t k = 1, m = 1; k < kTabledShapes; ++k) {
        if ((m + 1) * (m + 1) <= k) ++m;  // floor(sqrt(k))
        shapes[k] = shape_of(k, m);
    }
    return shapes;
}();

Shape shape_for(std::uint32_t k) {
    if (k > 0 && k < kTabledShapes) return kShapes[k];
    return shape_of(k, std::max(1u, static_cast<std::uint32_t>(std::sqrt(double(k)))));  // floor
}

// Grids whose sides both have at most kListedOrders elements (k <= 25) keep each side's order as
// a word of hexadecimal digits. Stratum s = row * m + col finds its column's and row's digit at
// the shifts 4 col (low byte) and 4 row (next byte), listed for s < k and again at s + k so that
// a rotated run reads them in order, in a loop that vectorises (32-bit entries: narrower don't).
constexpr std::uint32_t kPackedUpTo = kListedOrders * kListedOrders;
using Places = std::array<std::uint32_t, 2 * kPackedUpTo>;
constexpr std::array<Places, kPackedUpTo + 1> kPlaces = [] {
    std::array<Places, kPackedUpTo + 1> places{};
    for (std::uint32_t k = 1; k <= kPackedUpTo; ++k) {
        const std::uint32_t m = kShapes[k].m;
        for (std::uint32_t j = 0; j < 2 * k; ++j) {
            places[k][j] = 4 * (j % k % m) | 4 * (j % k / m) << 8;
        }
    }
    return places;
}();

// The cell column * n + sub_column of the stratum at `place` of a grid whose sides are packed.
struct PackedSides {
    std::uint32_t columns, sub_columns, n;
    const std::uint32_t* places;

    std::uint32_t cell(std::uint32_t place) const {
        const std::uint32_t shifts = places[place];
        return ((columns >> (shifts & 255u)) & 15u) * n + ((sub_columns >> (shifts >> 8)) & 15u);
    }
};

// Past this many points a grid's sides are Kensler's permutation per element.
constexpr std::uint32_t kDealtUpTo = 1024;

// The hash every part of a grid keyed by `key` derives from, and its jitters' key.
std::uint64_t grid_hash(std::uint32_t key) {
    return mix64(key ^ 0x7f4a7c159e3779b9ULL);
}
std::uint64_t jitter_key_of(std::uint64_t grid_hash) {
    return mix64(grid_hash);
}
std::uint32_t column_key(std::uint32_t key) {
    return key * 0x68bc21ebu;
}
std::uint32_t sub_column_key(std::uint32_t key) {
    return key * 0x02e5be93u;
}

// permute(first + i, n, key) into out[i]. Every label takes a step, and then those still outside
// [0, n) another, pass after pass over all of them (the others left as they are) until none is:
// the same walks as permute's, in loops that vectorise, where a walk per label would mispredict
// its end about once per label.
DRT_VECTORISED void permute_run(std::uint32_t first, std::uint32_t n, std::uint32_t key,
                                std::uint32_t* out, std::size_t count) {
    if (n <= 1) {
        std::fill_n(out, count, 0u);
        return;
    }
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

// The grid of a pattern of k points keyed by `key`, its shuffled columns and sub-columns, the
// jitters' key and a set's rotation: what every point of the pattern shares. A side of at most
// five elements picks from the list of all orders; others are dealt by Fisher-Yates from as few
// hashes as they need, or past kDealtUpTo points are Kensler's permutation per element. All are
// uniformly random orders; dealing is cheapest for the small sets every shading point draws.
class Grid {
    static constexpr std::uint32_t kSmallSide = 64;  // the sides of k up to 4032 points
    using Small = std::array<std::uint32_t, kSmallSide>;
    static std::span<std::uint32_t> side(Small& small, std::vector<std::uint32_t>& large,
                                         std::uint32_t size) {
        if (size <= kSmallSide) return std::span(small).first(size);
        large.resize(size);
        return large;
    }

    // Declared first: the spans below point into them.
    Small column_small_, sub_column_small_;
    std::vector<std::uint32_t> column_large_, sub_column_large_;

  public:
    std::uint32_t k;
    Shape shape;
    std::uint64_t jitter_key;
    std::uint32_t rotation;
    // Both sides listed: their orders packed, and `column` and `sub_column` left empty.
    bool packed;
    PackedSides packed_sides{};
    std::span<std::uint32_t> column, sub_column;

    Grid(std::uint32_t k_, std::uint32_t key)
        : k(k_),
          shape(shape_for(k_)),
          packed(shape.m <= kListedOrders && shape.n <= kListedOrders) {
        const std::uint64_t h = grid_hash(key);
        jitter_key = jitter_key_of(h);
        Digits digits(static_cast<std::uint32_t>(h >> 32), h ^ 0x68bc21ebu);
        if (packed) {
            const std::uint32_t columns = listed_order(shape.m, digits);
            packed_sides = {columns, listed_order(shape.n, digits), shape.n, kPlaces[k].data()};
        } else {
            column = side(column_small_, column_large_, shape.m);
            sub_column = side(sub_column_small_, sub_column_large_, shape.n);
            if (k <= kDealtUpTo) {
                shuffle(column, digits);
                shuffle(sub_column, digits);
            } else {
                permute_run(0, shape.m, column_key(key), column.data(), shape.m);
                permute_run(0, shape.n, sub_column_key(key), sub_column.data(), shape.n);
            }
        }
        rotation = k <= 4096 ? digits.below(k) : static_cast<std::uint32_t>(((h >> 32) * k) >> 32);
    }
    Grid(const Grid&) = delete;
    Grid& operator=(const Grid&) = delete;

    // The cell of stratum s = row * m + col: column[col] * n + sub_column[row].
    std::uint32_t cell(std::uint32_t s) const {
        if (packed) return packed_sides.cell(s);
        return column[s % shape.m] * shape.n + sub_column[s / shape.m];
    }
};

// Every stratum's cell, tabulated once for the points of a set or a run, so that their loop
// looks up one table instead of two (and needs no division by m).
class Cells {
    static constexpr std::uint32_t kSmall = 1024;
    std::array<std::uint32_t, kSmall> small_;
    std::vector<std::uint32_t> large_;
    std::uint32_t* cells_;

  public:
    explicit Cells(const Grid& grid) {
        const std::uint32_t k = grid.k, m = grid.shape.m, n = grid.shape.n;
        if (k > kSmall) large_.resize(k);
        cells_ = k > kSmall ? large_.data() : small_.data();
        if (grid.packed) {
            for (std::uint32_t s = 0; s < k; ++s) cells_[s] = grid.packed_sides.cell(s);
            return;
        }
        for (std::uint32_t row = 0, s = 0; s < k; ++row) {
            const std::uint32_t sub_column = grid.sub_column[row];
            for (std::uint32_t col = 0; col < m && s < k; ++col, ++s) {
                cells_[s] = grid.column[col] * n + sub_column;
            }
        }
    }
    Cells(const Cells&) = delete;
    Cells& operator=(const Cells&) = delete;
    const std::uint32_t* data() const { return cells_; }
};

// The point of stratum s in cell `cell` of the grid: x = (cell + jx) / (m n) and
// y = (s + jy) / k. The jitters' 32 bits keep both below 1 for any k < 2^20, and the clamp
// beyond. The divisions are products so that loops of points vectorise.
struct Jitter {
    std::uint32_t key_x, key_y;
    double inv_cells, inv_k;

    Jitter(std::uint64_t jitter_key, const Shape& shape)
        : key_x(static_cast<std::uint32_t>(jitter_key)),
          key_y(static_cast<std::uint32_t>(jitter_key >> 32)),
          inv_cells(shape.inv_cells),
          inv_k(shape.inv_k) {}
    explicit Jitter(const Grid& grid) : Jitter(grid.jitter_key, grid.shape) {}

    Vec2 point(std::uint32_t s, std::uint32_t cell) const {
        constexpr double kBelowOne = 0x1.fffffffffffffp-1;
        const std::uint32_t jx = hash32(s + key_x);
        const std::uint32_t jy = hash32(jx ^ key_y);
        const double x = (static_cast<double>(cell) + to_unit(jx)) * inv_cells;
        const double y = (static_cast<double>(s) + to_unit(jy)) * inv_k;
        return {x < kBelowOne ? x : kBelowOne, y < kBelowOne ? y : kBelowOne};
    }
};

// The points of strata strata[i] into out[i].
DRT_VECTORISED void grid_points(const Jitter& jitter, const std::uint32_t* cells,
                                const std::uint32_t* strata, Vec2* out, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) out[i] = jitter.point(strata[i], cells[strata[i]]);
}

// Points of the strata start, start + 1, ... (count <= k, wrapping around once past k - 1) into
// out.
DRT_VECTORISED void rotated_points(const Jitter& jitter, const std::uint32_t* cells,
                                   std::uint32_t start, std::uint32_t k, Vec2* out,
                                   std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
        std::uint32_t s = start + static_cast<std::uint32_t>(i);
        s = s < k ? s : s - k;
        out[i] = jitter.point(s, cells[s]);
    }
}

// rotated_points for a grid whose sides are packed, the cells worked out with the points.
DRT_VECTORISED void packed_rotated_points(const Jitter& jitter, const PackedSides& sides,
                                          std::uint32_t start, std::uint32_t k, Vec2* out,
                                          std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t place = start + static_cast<std::uint32_t>(i);
        out[i] = jitter.point(place < k ? place : place - k, sides.cell(place));
    }
}

// The sides of the grids of single points (multi_jittered(j, k, key)) this thread drew lately,
// by key. A pixel's camera samples are drawn one at a time, and every sample along the same
// branch asks for the same dimensions, so drawing a grid's sides once per pixel and dimension
// instead of once per point saves a shuffle of sqrt(k) elements a point, or two permutations
// past kDealtUpTo. The points are the same either way: the sides are a pure function of (k, key).
// Two-way set associative, since a path keeps some 20 dimensions in play at once.
class RememberedGrids {
  public:
    struct Sides {
        std::uint32_t key = 0, k = 0;  // k = 0: empty
        // Past kDealtUpTo the sides are only drawn when the key comes back, since drawing them
        // whole costs sqrt(k) permutations against two for the point itself.
        bool drawn = false;
        std::uint64_t jitter_key = 0;
        Shape shape;
        std::vector<std::uint32_t> sides;  // the m columns' places, then the n sub-columns'

        std::uint32_t cell(std::uint32_t s) const {
            return sides[s % shape.m] * shape.n + sides[shape.m + s / shape.m];
        }
    };

    // The sides of the grid of k points keyed by `key`, or nullptr where they are not drawn
    // (yet): then the point is worked out on its own.
    const Sides* find(std::uint32_t k, std::uint32_t key) {
        const std::uint32_t set = (key ^ k) & (kSets - 1);
        auto& ways = sets_[set];
        for (std::uint32_t w = 0; w < 2; ++w) {
            Sides& sides = ways[w];
            if (sides.key != key || sides.k != k) continue;
            recent_[set] = static_cast<std::uint8_t>(w);
            if (!sides.drawn) draw(sides);
            return &sides;
        }
        const std::uint32_t w = 1u - recent_[set];
        recent_[set] = static_cast<std::uint8_t>(w);
        Sides& sides = ways[w];
        sides.key = key;
        sides.k = k;
        sides.drawn = false;
        if (k > kDealtUpTo) return nullptr;
        draw(sides);
        return &sides;
    }

  private:
    static constexpr std::uint32_t kSets = 64;

    static void draw(Sides& sides) {
        const std::uint32_t k = sides.k, key = sides.key;
        if (k <= kDealtUpTo) {
            const Grid grid(k, key);
            sides.shape = grid.shape;
            sides.jitter_key = grid.jitter_key;
            sides.sides.assign(grid.column.begin(), grid.column.end());
            sides.sides.insert(sides.sides.end(), grid.sub_column.begin(), grid.sub_column.end());
        } else {
            const Shape shape = shape_for(k);
            sides.shape = shape;
            sides.jitter_key = jitter_key_of(grid_hash(key));
            sides.sides.resize(shape.m + shape.n);
            permute_run(0, shape.m, column_key(key), sides.sides.data(), shape.m);
            permute_run(0, shape.n, sub_column_key(key), sides.sides.data() + shape.m, shape.n);
        }
        sides.drawn = true;
    }

    std::array<std::array<Sides, 2>, kSets> sets_;
    std::array<std::uint8_t, kSets> recent_{};
};

// Labels are handled a batch at a time, so that a run of any length needs no allocation.
constexpr std::size_t kBatch = 256;

}  // namespace

void multi_jittered(std::uint32_t first, std::uint32_t k, std::uint32_t key, std::span<Vec2> out) {
    const Grid grid(k, key);
    const Cells cells(grid);
    const Jitter jitter(grid);
    const std::uint32_t stratum_key = key * 0x51633e2du;
    std::array<std::uint32_t, kBatch> strata;
    for (std::size_t done = 0; done < out.size(); done += kBatch) {
        const std::size_t count = std::min(kBatch, out.size() - done);
        permute_run(first + static_cast<std::uint32_t>(done), k, stratum_key, strata.data(), count);
        grid_points(jitter, cells.data(), strata.data(), out.data() + done, count);
    }
}

Vec2 multi_jittered(std::uint32_t j, std::uint32_t k, std::uint32_t key) {
    const std::uint32_t s = permute(j, k, key * 0x51633e2du);
    if (k > kPackedUpTo) {
        thread_local RememberedGrids remembered;
        if (const auto* sides = remembered.find(k, key)) {
            return Jitter(sides->jitter_key, sides->shape).point(s, sides->cell(s));
        }
    }
    if (k > kDealtUpTo) {
        // Sides permuted per element: this point needs only its own column's and sub-column's
        // entries. A pixel's samples are drawn one at a time, and working out both whole sides
        // for each would cost 2 sqrt(k) permutations a point (5x Sobol's time at 2048 spp).
        const Shape shape = shape_for(k);
        const std::uint32_t cell = permute(s % shape.m, shape.m, column_key(key)) * shape.n +
                                   permute(s / shape.m, shape.n, sub_column_key(key));
        return Jitter(jitter_key_of(grid_hash(key)), shape).point(s, cell);
    }
    const Grid grid(k, key);
    return Jitter(grid).point(s, grid.cell(s));
}

void multi_jittered_set(std::uint32_t first, std::uint32_t k, std::uint32_t key,
                        std::span<Vec2> out) {
    const Grid grid(k, key);
    const Jitter jitter(grid);
    // At most k points at a time, so that the strata wrap around at most once. `at % k` only
    // where at >= k: sets are drawn at every shading point, and a compare is cheaper.
    const auto passes = [&](const auto& points) {
        for (std::size_t done = 0; done < out.size(); done += k) {
            const std::uint32_t at = first + static_cast<std::uint32_t>(done);
            std::uint32_t start = (at < k ? at : at % k) + grid.rotation;
            if (start >= k) start -= k;
            points(start, out.data() + done, std::min<std::size_t>(k, out.size() - done));
        }
    };
    if (grid.packed) {
        passes([&](std::uint32_t start, Vec2* to, std::size_t count) {
            packed_rotated_points(jitter, grid.packed_sides, start, k, to, count);
        });
    } else {
        const Cells cells(grid);
        passes([&](std::uint32_t start, Vec2* to, std::size_t count) {
            rotated_points(jitter, cells.data(), start, k, to, count);
        });
    }
}

}  // namespace drt
