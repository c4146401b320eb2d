#include "drt/util/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

namespace drt {
namespace {

static_assert(to_unit(std::uint64_t{0}) == 0.0);
static_assert(permute(0, 1, 1234) == 0);
static_assert(mix64(1) != 1);

// The multiplicative inverse of an odd number modulo 2^64 (Newton's iteration doubles the
// number of correct low bits each step).
constexpr std::uint64_t inverse_mod_2_64(std::uint64_t a) {
    std::uint64_t x = a;  // correct to 3 bits for odd a
    for (int i = 0; i < 6; ++i) x *= 2 - a * x;
    return x;
}

// Undoes z ^= z >> s.
constexpr std::uint64_t unxorshift(std::uint64_t z, int s) {
    std::uint64_t x = z;
    for (int i = s; i < 64; i += s) x = z ^ (x >> s);
    return x;
}

constexpr std::uint64_t unmix64(std::uint64_t z) {
    z = unxorshift(z, 31);
    z *= inverse_mod_2_64(0x94d049bb133111ebULL);
    z = unxorshift(z, 27);
    z *= inverse_mod_2_64(0xbf58476d1ce4e5b9ULL);
    return unxorshift(z, 30);
}

TEST(Rng, ToUnitCoversTheHalfOpenUnitInterval) {
    EXPECT_EQ(to_unit(std::uint64_t{0}), 0.0);
    EXPECT_EQ(to_unit(~std::uint64_t{0}), 1.0 - 0x1.0p-53);
    EXPECT_LT(to_unit(~std::uint64_t{0}), 1.0);
    EXPECT_EQ(to_unit(std::uint64_t{1} << 63), 0.5);
    EXPECT_EQ(to_unit(std::uint64_t{1} << 11), 0x1.0p-53);
    // The low 11 bits do not matter.
    EXPECT_EQ(to_unit(std::uint64_t{0x7ff}), 0.0);
    // A 32-bit word converts exactly.
    EXPECT_EQ(to_unit(std::uint32_t{0}), 0.0);
    EXPECT_EQ(to_unit(std::uint32_t{1} << 31), 0.5);
    EXPECT_EQ(to_unit(std::uint32_t{1}), 0x1.0p-32);
    EXPECT_EQ(to_unit(~std::uint32_t{0}), 1.0 - 0x1.0p-32);

    double sum = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        const double u = to_unit(hash_of(1, i));
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        sum += u;
    }
    EXPECT_NEAR(sum / n, 0.5, 0.0045);  // 5 standard errors
}

TEST(Rng, HashOfIsOrderSensitive) {
    for (std::uint64_t a = 0; a < 50; ++a) {
        for (std::uint64_t b = 0; b < 50; ++b) {
            if (a == b) continue;
            EXPECT_NE(hash_of(a, b), hash_of(b, a)) << a << ", " << b;
            EXPECT_NE(hash_of(7, a, b), hash_of(7, b, a)) << a << ", " << b;
            EXPECT_NE(hash_of(a, b, 7), hash_of(b, a, 7)) << a << ", " << b;
        }
    }
    // Appending a coordinate, even a zero, changes the hash.
    for (std::uint64_t a = 0; a < 100; ++a) {
        EXPECT_NE(hash_of(a), hash_of(a, 0));
        EXPECT_NE(hash_of(a, 1), hash_of(a, 1, 0));
    }
}

TEST(Rng, HashOfHasNoCollisionsOverASampleGrid) {
    // (seed, pixel, sample, dimension) as the samplers use it.
    std::vector<std::uint64_t> hashes;
    for (std::uint64_t pixel = 0; pixel < 100; ++pixel) {
        for (std::uint64_t index = 0; index < 100; ++index) {
            for (std::uint64_t d = 0; d < 10; ++d) hashes.push_back(hash_of(0, pixel, index, d));
        }
    }
    std::sort(hashes.begin(), hashes.end());
    EXPECT_EQ(std::adjacent_find(hashes.begin(), hashes.end()), hashes.end());
}

TEST(Rng, Mix64HasNoCollisionsOverConsecutiveInputs) {
    std::vector<std::uint64_t> out;
    for (std::uint64_t z = 0; z < 100000; ++z) out.push_back(mix64(z));
    std::sort(out.begin(), out.end());
    EXPECT_EQ(std::adjacent_find(out.begin(), out.end()), out.end());
}

TEST(Rng, Mix64IsABijection) {
    static_assert(inverse_mod_2_64(0x94d049bb133111ebULL) * 0x94d049bb133111ebULL == 1);
    for (std::uint64_t i = 0; i < 10000; ++i) {
        const std::uint64_t z = i * 0x9e3779b97f4a7c15ULL + (i << 50);
        ASSERT_EQ(unmix64(mix64(z)), z) << z;
    }
}

TEST(Rng, Mix64Avalanches) {
    // Flipping any one input bit flips each output bit with probability 1/2: 32 bits on average.
    double total = 0;
    int trials = 0;
    for (int bit = 0; bit < 64; ++bit) {
        double per_bit = 0;
        for (std::uint64_t i = 0; i < 1000; ++i) {
            const std::uint64_t z = mix64(i + 0x1234567);
            const int flipped = std::popcount(mix64(z) ^ mix64(z ^ (std::uint64_t{1} << bit)));
            per_bit += flipped, total += flipped, ++trials;
        }
        EXPECT_NEAR(per_bit / 1000, 32.0, 1.0) << "input bit " << bit;  // ~8 standard errors
    }
    EXPECT_NEAR(total / trials, 32.0, 0.15);
}

TEST(Permute, IsABijectionOnZeroToN) {
    const std::uint32_t keys[] = {0u, 1u, 12345u, 0xdeadbeefu, 0xffffffffu, 0x80000000u};
    for (const std::uint32_t n : {1u, 2u, 3u, 10u, 82u, 100u, 256u, 1000u, 1024u, 65537u}) {
        for (const std::uint32_t key : keys) {
            std::vector<bool> seen(n, false);
            for (std::uint32_t i = 0; i < n; ++i) {
                const std::uint32_t p = permute(i, n, key);
                ASSERT_LT(p, n) << "n " << n << " key " << key << " i " << i;
                ASSERT_FALSE(seen[p]) << "n " << n << " key " << key << " repeats " << p;
                seen[p] = true;
            }
        }
    }
}

TEST(Permute, DifferentKeysGiveDifferentPermutations) {
    for (const std::uint32_t n : {10u, 82u, 1000u}) {
        std::set<std::vector<std::uint32_t>> distinct;
        int identities = 0;
        for (std::uint32_t k = 0; k < 50; ++k) {
            const auto key = static_cast<std::uint32_t>(hash_of(99, k));
            std::vector<std::uint32_t> perm;
            for (std::uint32_t i = 0; i < n; ++i) perm.push_back(permute(i, n, key));
            identities += std::is_sorted(perm.begin(), perm.end());
            distinct.insert(perm);
        }
        EXPECT_EQ(distinct.size(), 50u) << n;
        EXPECT_EQ(identities, 0) << n;
    }
}

TEST(Permute, ImageOfAnElementIsUniformOverKeys) {
    // Over random keys, where an element goes is uniform on [0, n): what makes a shuffled
    // stratified pattern uniform over the pixel rather than biased towards some strata.
    for (const std::uint32_t n : {3u, 10u, 82u}) {
        const int keys = 20000;
        std::vector<int> count0(n, 0), count2(n, 0);
        for (int k = 0; k < keys; ++k) {
            const auto key = static_cast<std::uint32_t>(hash_of(7, k));
            ++count0[permute(0, n, key)];
            ++count2[permute(2, n, key)];
        }
        const double expected = double(keys) / n;
        const double tolerance = 5 * std::sqrt(expected * (1 - 1.0 / n));  // 5 standard deviations
        for (std::uint32_t v = 0; v < n; ++v) {
            EXPECT_NEAR(count0[v], expected, tolerance) << "n " << n << ": 0 -> " << v;
            EXPECT_NEAR(count2[v], expected, tolerance) << "n " << n << ": 2 -> " << v;
        }
    }
}

}  // namespace
}  // namespace drt
