#include "drt/shading/texture.h"

#include <array>
#include <cmath>
#include <cstdint>

#include "drt/util/rng.h"

namespace drt {

namespace {

constexpr std::array<std::uint8_t, 256> make_permutation() {
    std::array<std::uint8_t, 256> p{};
    for (std::uint32_t i = 0; i < 256; ++i)
        p[i] = static_cast<std::uint8_t>(permute(i, 256, 0x5eed1u));
    return p;
}
constexpr std::array<std::uint8_t, 256> kPermutation = make_permutation();

constexpr int hash3(int x, int y, int z) {
    return kPermutation[(kPermutation[(kPermutation[x & 255] + y) & 255] + z) & 255];
}

// Dot product of the lattice gradient picked by h (one of the 12 cube-edge directions) with d.
constexpr double gradient_dot(int h, double x, double y, double z) {
    switch (h % 12) {
        case 0:
            return x + y;
        case 1:
            return -x + y;
        case 2:
            return x - y;
        case 3:
            return -x - y;
        case 4:
            return x + z;
        case 5:
            return -x + z;
        case 6:
            return x - z;
        case 7:
            return -x - z;
        case 8:
            return y + z;
        case 9:
            return -y + z;
        case 10:
            return y - z;
        default:
            return -y - z;
    }
}

constexpr double fade(double t) {
    return t * t * t * (t * (t * 6 - 15) + 10);
}
constexpr double mix(double a, double b, double t) {
    return a + t * (b - a);
}

// floor(v) as an integer modulo 2^62 (v already whole), 0 for NaN: every double of magnitude 2^62
// or more is a multiple of 2^10, so its low bits, all that the lattice hash and the checker parity
// read, are exactly 0. A plain conversion would be undefined behaviour there (a tiny scale).
long long lattice(double whole) {
    constexpr double kBound = 0x1p62;
    return whole > -kBound && whole < kBound ? static_cast<long long>(whole) : 0;
}

}  // namespace

double perlin_noise(const Vec3& p) {
    const double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    const int X = static_cast<int>(lattice(fx) & 255);
    const int Y = static_cast<int>(lattice(fy) & 255);
    const int Z = static_cast<int>(lattice(fz) & 255);
    const double x = p.x - fx, y = p.y - fy, z = p.z - fz;
    const double u = fade(x), v = fade(y), w = fade(z);
    auto g = [&](int dx, int dy, int dz) {
        return gradient_dot(hash3(X + dx, Y + dy, Z + dz), x - dx, y - dy, z - dz);
    };
    return mix(mix(mix(g(0, 0, 0), g(1, 0, 0), u), mix(g(0, 1, 0), g(1, 1, 0), u), v),
               mix(mix(g(0, 0, 1), g(1, 0, 1), u), mix(g(0, 1, 1), g(1, 1, 1), u), v), w);
}

double turbulence(const Vec3& p, int octaves) {
    double sum = 0, amplitude = 0.5, frequency = 1;
    for (int i = 0; i < octaves; ++i) {
        sum += amplitude * std::abs(perlin_noise(p * frequency));
        amplitude *= 0.5, frequency *= 2;
    }
    return sum;
}

Color CheckerTexture::value(const TexturePoint& at) const {
    const Vec3& local = at.local;
    const auto cell = [&](double c) { return lattice(std::floor(c / scale_)); };
    // The parity of the sum from the parities: the sum itself could overflow.
    const long long parity = cell(local.x) ^ cell(local.y) ^ cell(local.z);
    return (parity & 1) == 0 ? a_ : b_;
}

Color MarbleTexture::value(const TexturePoint& at) const {
    const Vec3 p = at.local / scale_;
    const double t = 0.5 + 0.5 * std::sin(p.x + 5.0 * turbulence(p));
    return lerp(a_, b_, t);
}

std::unique_ptr<Texture> make_texture(std::string_view name, Color a, Color b, double scale) {
    if (name == "checker") return std::make_unique<CheckerTexture>(a, b, scale);
    if (name == "marble") return std::make_unique<MarbleTexture>(a, b, scale);
    return nullptr;
}

Vec3 BumpMap::perturb(const Vec3& normal, const Vec3& local) const {
    // Central differences of the noise field; the tangential part of its gradient tilts the normal.
    const Vec3 p = local / scale;
    constexpr double h = 1e-3;
    const Vec3 grad{perlin_noise(p + Vec3{h, 0, 0}) - perlin_noise(p - Vec3{h, 0, 0}),
                    perlin_noise(p + Vec3{0, h, 0}) - perlin_noise(p - Vec3{0, h, 0}),
                    perlin_noise(p + Vec3{0, 0, h}) - perlin_noise(p - Vec3{0, 0, h})};
    const Vec3 g = grad / (2 * h);
    const Vec3 tangential = g - normal * dot(g, normal);
    return normalize(normal - tangential * strength);
}

}  // namespace drt
