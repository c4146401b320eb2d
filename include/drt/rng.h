// Counter-based randomness: every random number is a pure function of its coordinates
// (seed, pixel, sample, dimension, index), so images never depend on thread scheduling
// or on the order in which a renderer happens to consume numbers.
#pragma once

#include <cstdint>

namespace drt {

// SplitMix64's finaliser: a bijective 64-bit mix with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

constexpr std::uint64_t hash_combine(std::uint64_t h, std::uint64_t v) {
    return mix64(h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2)));
}

template <typename... Ts>
constexpr std::uint64_t hash_of(std::uint64_t first, Ts... rest) {
    std::uint64_t h = mix64(first + 0x632be59bd9b4e019ULL);
    ((h = hash_combine(h, static_cast<std::uint64_t>(rest))), ...);
    return h;
}

// A uniform double in [0, 1) from the top 53 bits of a hash.
constexpr double to_unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

// A pseudo-random permutation of [0, n) evaluated at i, by cycle-walking a keyed bijection on
// the smallest power-of-two domain that holds n (the idea of Kensler's "Correlated Multi-Jittered
// Sampling", 2013).
constexpr std::uint32_t permute(std::uint32_t i, std::uint32_t n, std::uint32_t key) {
    if (n <= 1) return 0;
    std::uint32_t mask = n - 1;
    mask |= mask >> 1, mask |= mask >> 2, mask |= mask >> 4, mask |= mask >> 8, mask |= mask >> 16;
    do {
        // Each step is invertible on [0, mask]: xor with a constant, multiplication by an odd
        // number modulo 2^k, and xor with a right shift of itself.
        i ^= key & mask;
        i = (i * 0x9e3779b1u) & mask;
        i ^= (i & mask) >> 3;
        i ^= (key >> 8) & mask;
        i = (i * 0x85ebca6bu) & mask;
        i ^= (i & mask) >> 7;
        i = (i * 0xc2b2ae35u) & mask;
        i ^= (key >> 16) & mask;
        i ^= (i & mask) >> 5;
    } while (i >= n);
    return i;
}

}  // namespace drt
