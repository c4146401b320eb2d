#include "drt/scene/environment.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace drt {

namespace {

// sin θ of row j (counted from the bottom) of an h-row map: the solid angle its texels span is
// proportional to it.
double row_sine(int j, int h) {
    return std::sin(kPi * (1 - (j + 0.5) / h));
}

// Each texel's luminance times its row's sin θ, then the largest of each 3 x 3 neighbourhood
// (wrapping in u, clamped at the poles): bilinear reads spread a texel's light half a texel on
// every side, into cells whose own texel may be dark.
std::vector<float> sampling_weights(const MipMap& image, Environment::Sampling sampling) {
    const int w = image.width(), h = image.height();
    const auto at = [w](int i, int j) { return static_cast<std::size_t>(j) * w + i; };
    std::vector<float> lum(static_cast<std::size_t>(w) * h);
    for (int j = 0; j < h; ++j) {
        const double sine = row_sine(j, h);
        for (int i = 0; i < w; ++i) {
            const double weight = sampling == Environment::Sampling::kUniform
                                      ? 1.0
                                      : std::max(0.0, luminance(image.texel(0, i, j)));
            lum[at(i, j)] = static_cast<float>(weight * sine);
        }
    }
    if (sampling == Environment::Sampling::kUniform) return lum;
    std::vector<float> across(lum.size());
    for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
            across[at(i, j)] =
                std::max({lum[at((i + w - 1) % w, j)], lum[at(i, j)], lum[at((i + 1) % w, j)]});
        }
    }
    for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
            lum[at(i, j)] = std::max({across[at(i, std::max(j - 1, 0))], across[at(i, j)],
                                      across[at(i, std::min(j + 1, h - 1))]});
        }
    }
    return lum;
}

double map_power(const MipMap& image, double intensity) {
    const int w = image.width(), h = image.height();
    double sum = 0;
    for (int j = 0; j < h; ++j) {
        double row = 0;
        for (int i = 0; i < w; ++i) row += std::max(0.0, luminance(image.texel(0, i, j)));
        sum += row * row_sine(j, h);
    }
    // Each texel spans (2π/w)(π/h) sin θ of solid angle.
    const double texel_solid_angle = 2 * kPi * kPi / (double(w) * h);
    return intensity * sum * texel_solid_angle / (2 * kPi);
}

}  // namespace

Environment::Environment(std::shared_ptr<const MipMap> image, double intensity, double rotate_y,
                         Sampling sampling)
    : image_(std::move(image)),
      intensity_(intensity),
      rotate_y_(rotate_y),
      power_(map_power(*image_, intensity)),
      distribution_(sampling_weights(*image_, sampling), static_cast<std::size_t>(image_->width()),
                    static_cast<std::size_t>(image_->height())) {}

Vec2 Environment::uv_of(const Vec3& dir) const {
    const double theta = std::acos(std::clamp(dir.y, -1.0, 1.0));
    double u = (std::atan2(-dir.z, dir.x) - rotate_y_) / (2 * kPi);
    u -= std::floor(u);
    return {u, 1 - theta / kPi};
}

Color Environment::radiance(const Vec3& dir) const {
    Vec2 uv = uv_of(dir);
    const double half_texel = 0.5 / image_->height();
    uv.y = std::clamp(uv.y, half_texel, 1 - half_texel);
    return image_->bilinear(0, uv) * intensity_;
}

std::optional<Environment::Sample> Environment::sample(Vec2 u) const {
    const Distribution2D::Sample s = distribution_.sample(u);
    const double theta = kPi * (1 - s.uv.y);
    const double sin_theta = std::sin(theta);
    if (!(sin_theta > 0) || !(s.pdf > 0)) return std::nullopt;
    const double phi = 2 * kPi * s.uv.x + rotate_y_;
    const Vec3 dir{sin_theta * std::cos(phi), std::cos(theta), -sin_theta * std::sin(phi)};
    return Sample{dir, radiance(dir), s.pdf / (2 * kPi * kPi * sin_theta)};
}

double Environment::pdf(const Vec3& dir) const {
    const double sin_theta = std::sqrt(std::max(0.0, 1 - dir.y * dir.y));
    if (!(sin_theta > 0)) return 0;
    return distribution_.pdf(uv_of(dir)) / (2 * kPi * kPi * sin_theta);
}

}  // namespace drt
