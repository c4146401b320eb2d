#include "drt/io/compare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace drt {

namespace {

void require_same_size(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height) {
        throw ImageError("image sizes differ: " + std::to_string(a.width) + "x" +
                         std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                         std::to_string(b.height));
    }
}

// Luminance of the values clamped to [0, 1], the dynamic range the SSIM constants assume.
std::vector<double> clamped_luminance(const Image& image) {
    std::vector<double> y(static_cast<std::size_t>(image.width) * image.height);
    for (std::size_t i = 0; i < y.size(); ++i) {
        const float* p = image.rgb.data() + 3 * i;
        const auto c = [](float v) { return std::clamp(static_cast<double>(v), 0.0, 1.0); };
        y[i] = luminance({c(p[0]), c(p[1]), c(p[2])});
    }
    return y;
}

// Normalised Gaussian weights of width n (11 with sigma 1.5 as in Wang et al. 2004, narrower
// for images smaller than that so that they still get a window).
std::vector<double> gaussian_window(int n) {
    std::vector<double> w(n);
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        const double d = i - (n - 1) / 2.0;
        sum += w[i] = std::exp(-d * d / (2 * 1.5 * 1.5));
    }
    for (double& v : w) v /= sum;
    return w;
}

// Mean SSIM over every fully inside window position, filtering the five local moments
// separably: rows first, then columns.
double mean_ssim(const std::vector<double>& x, const std::vector<double>& y, int width,
                 int height) {
    constexpr double kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
    constexpr int kWindow = 11;
    const int wx = std::min(kWindow, width), wy = std::min(kWindow, height);
    const std::vector<double> gx = gaussian_window(wx), gy = gaussian_window(wy);
    const int out_w = width - wx + 1, out_h = height - wy + 1;

    using Moments = std::array<double, 5>;  // x, y, x^2, y^2, xy
    std::vector<Moments> rows(static_cast<std::size_t>(out_w) * height);
    for (int j = 0; j < height; ++j) {
        for (int i = 0; i < out_w; ++i) {
            Moments m{};
            for (int k = 0; k < wx; ++k) {
                const std::size_t p = static_cast<std::size_t>(j) * width + i + k;
                const double a = x[p], b = y[p];
                const Moments v{a, b, a * a, b * b, a * b};
                for (int q = 0; q < 5; ++q) m[q] += gx[k] * v[q];
            }
            rows[static_cast<std::size_t>(j) * out_w + i] = m;
        }
    }

    double total = 0;
    for (int j = 0; j < out_h; ++j) {
        for (int i = 0; i < out_w; ++i) {
            Moments m{};
            for (int k = 0; k < wy; ++k) {
                const Moments& r = rows[static_cast<std::size_t>(j + k) * out_w + i];
                for (int q = 0; q < 5; ++q) m[q] += gy[k] * r[q];
            }
            const double mx = m[0], my = m[1];
            const double vx = m[2] - mx * mx, vy = m[3] - my * my, cov = m[4] - mx * my;
            total += (2 * mx * my + kC1) * (2 * cov + kC2) /
                     ((mx * mx + my * my + kC1) * (vx + vy + kC2));
        }
    }
    return total / (static_cast<double>(out_w) * out_h);
}

// Root mean square over the three channels of pixel i.
double pixel_error(const Image& a, const Image& b, std::size_t i) {
    double sum = 0;
    for (std::size_t c = 3 * i; c < 3 * i + 3; ++c) {
        const double d = static_cast<double>(a.rgb[c]) - b.rgb[c];
        sum += d * d;
    }
    return std::sqrt(sum / 3);
}

}  // namespace

Color false_colour(double t) {
    static constexpr std::array<Color, 5> kStops{
        {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}};
    const double s = (t > 0 ? std::min(t, 1.0) : 0.0) * (kStops.size() - 1);  // NaN as 0
    const std::size_t k = std::min(static_cast<std::size_t>(s), kStops.size() - 2);
    const Color c = lerp(kStops[k], kStops[k + 1], s - k);
    // Stored linear, so that the colour shows as chosen once write_image encodes it again.
    return {decode_srgb(c.r), decode_srgb(c.g), decode_srgb(c.b)};
}

Comparison compare_images(const Image& a, const Image& b) {
    require_same_size(a, b);
    Comparison result;
    if (a.rgb.empty()) return result;

    double sum = 0;
    bool any_nan = false;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        const double d = static_cast<double>(a.rgb[i]) - b.rgb[i];
        sum += d * d;
        result.max_abs = std::max(result.max_abs, std::abs(d));
        any_nan = any_nan || std::isnan(d);
        result.nonfinite += !std::isfinite(a.rgb[i]) || !std::isfinite(b.rgb[i]);
    }
    if (any_nan) result.max_abs = std::numeric_limits<double>::quiet_NaN();
    result.rmse = std::sqrt(sum / a.rgb.size());
    result.psnr = result.rmse == 0 ? std::numeric_limits<double>::infinity()
                                   : 20 * std::log10(1 / result.rmse);
    result.ssim = mean_ssim(clamped_luminance(a), clamped_luminance(b), a.width, a.height);
    return result;
}

std::string format_measure(double value) {
    std::ostringstream s;
    s << std::setprecision(6) << value;
    return s.str();
}

std::string comparison_fields(const Comparison& c) {
    return "rmse=" + format_measure(c.rmse) + " psnr=" + format_measure(c.psnr) +
           " ssim=" + format_measure(c.ssim) + " max=" + format_measure(c.max_abs) +
           " nonfinite=" + std::to_string(c.nonfinite);
}

Image difference_image(const Image& a, const Image& b) {
    require_same_size(a, b);
    const std::size_t n = static_cast<std::size_t>(a.width) * a.height;
    std::vector<double> error(n);
    double max_error = 0;
    for (std::size_t i = 0; i < n; ++i) {
        error[i] = pixel_error(a, b, i);
        if (std::isfinite(error[i])) max_error = std::max(max_error, error[i]);
    }

    Image diff(a.width, a.height);
    for (std::size_t i = 0; i < n; ++i) {
        // A NaN or infinite error is as bad as it gets: show it at the top of the ramp.
        const double t = !std::isfinite(error[i]) ? 1.0 : max_error > 0 ? error[i] / max_error : 0;
        const Color c = false_colour(t);
        diff.rgb[3 * i] = static_cast<float>(c.r);
        diff.rgb[3 * i + 1] = static_cast<float>(c.g);
        diff.rgb[3 * i + 2] = static_cast<float>(c.b);
    }
    return diff;
}

}  // namespace drt
