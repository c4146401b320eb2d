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

// The one way random bits become a number in [0, 1): a word read as a binary fraction,
// word / 2^bits, to the 53 bits a double holds. A 64-bit hash keeps its top 53 bits; a 32-bit
// word converts exactly, in an operation that vectorises (x86 before AVX-512 has no vector
// conversion of 64-bit integers).
constexpr double to_unit(std::uint64_t word) {
    return static_cast<double>(word >> 11) * 0x1.0p-53;
}
constexpr double to_unit(std::uint32_t word) {
    return static_cast<double>(word) * 0x1.0p-32;
}

// One step of permute's cycle walk: a keyed bijection of [0, w] for w = 2^b - 1.
constexpr std::uint32_t permute_step(std::uint32_t i, std::uint32_t w, std::uint32_t key) {
    // Xor with a constant, multiplication by an odd number and xor with a right shift of the
    // masked bits all leave the low bits a bijection of the low bits.
    i ^= key;
    i *= 0xe170893du;
    i ^= key >> 16;
    i ^= (i & w) >> 4;
    i ^= key >> 8;
    i *= 0x0929eb3fu;
    i ^= key >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | key >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
    return i;
}

// The smallest 2^b - 1 >= n - 1: the domain permute_step walks for a permutation of [0, n).
constexpr std::uint32_t permute_mask(std::uint32_t n) {
    std::uint32_t w = n - 1;
    w |= w >> 1, w |= w >> 2, w |= w >> 4, w |= w >> 8, w |= w >> 16;
    return w;
}

// The rotation by the key that ends permute, (i + key) mod n for i < n, in 64 bits: Kensler's
// 32-bit (i + key) % n wraps for large keys and maps two elements to one.
constexpr std::uint32_t permute_rotate(std::uint32_t i, std::uint32_t n, std::uint32_t key) {
    const std::uint64_t r = std::uint64_t{i} + key % n;
    return static_cast<std::uint32_t>(r >= n ? r - n : r);
}

// A pseudo-random permutation of [0, n) evaluated at i: Kensler's function from "Correlated
// Multi-Jittered Sampling" (2013), which cycle-walks a keyed bijection on the smallest
// power-of-two domain that holds n. Each step is invertible on the low bits, and every key bit
// takes part, so over random keys each element is sent to every position equally often.
constexpr std::uint32_t permute(std::uint32_t i, std::uint32_t n, std::uint32_t key) {
    if (n <= 1) return 0;
    const std::uint32_t w = permute_mask(n);
    do {
        i = permute_step(i, w, key);
    } while (i >= n);
    return permute_rotate(i, n, key);
}

}  // namespace drt
