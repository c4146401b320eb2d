// Kensler's correlated multi-jittered pattern ("Correlated Multi-Jittered Sampling", 2013), for
// any number of points k: the 2-D pattern of the stratified sampler.
//
// The square is divided into an m x n grid of cells, m*n >= k, as square as possible
// (m = floor(sqrt(k))). Every point takes its own one of k strata of y, and its own column and
// sub-column, i.e. one of m*n strata of x; when k = m*n every cell holds exactly one point.
// Stratum s = row * m + col lies in column shuffle(col) and sub-column shuffle'(row), both
// shuffles keyed, and is jittered within its cell. Which of the m*n sub-columns stay empty when
// k < m*n is left to the shuffles, so every point is uniform over the square (a fixed choice would
// leave a corner unsampled).
//
// Points are labelled j = 0 .. k-1. Point j is a pure function of (j, k, key): a single point is
// a run of one, and a run of any length is the points one by one.
#pragma once

#include <cstdint>
#include <span>

#include "drt/util/math.h"

namespace drt {

// Point j of the pattern of k points keyed by `key`: stratum permute(j, k, ...).
Vec2 multi_jittered(std::uint32_t j, std::uint32_t k, std::uint32_t key);
// Points first .. first + out.size() - 1 of that pattern into out, with what the points share
// (the grid's shuffles) worked out once.
void multi_jittered(std::uint32_t first, std::uint32_t k, std::uint32_t key, std::span<Vec2> out);

// Points first .. first + out.size() - 1 of a set of k points keyed by `key`: the same pattern,
// labelled by a keyed rotation of the strata, j -> (j + r) mod k, instead of a permutation. A set
// (the shadow rays of one shading point, the glossy rays of one hit) is used whole, so how its
// points are labelled does not matter as long as each is uniform over the square, which the
// rotation keeps, and a rotation is cheaper than a permutation.
void multi_jittered_set(std::uint32_t first, std::uint32_t k, std::uint32_t key,
                        std::span<Vec2> out);

}  // namespace drt
