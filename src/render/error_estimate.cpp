#include "drt/render/error_estimate.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

namespace drt {

namespace {

double sum(const Color& c) {
    return c.r + c.g + c.b;
}

}  // namespace

ErrorSums& ErrorSums::operator+=(const ErrorSums& o) {
    variance += o.variance;
    spread += o.spread;
    pixels += o.pixels;
    samples += o.samples;
    return *this;
}

Color pixel_spread(std::span<const Color> samples) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    const std::size_t n = samples.size();
    if (n < 2) return {inf, inf, inf};
    // Welford's update, steady for many similar values.
    Color mean, m2;
    for (std::size_t i = 0; i < n; ++i) {
        const Color delta = samples[i] - mean;
        mean += delta / double(i + 1);
        m2 += delta * (samples[i] - mean);
    }
    return m2 / (double(n - 1) * double(n));
}

Color strata_spread(std::span<const Vec2> positions, std::span<const Color> samples,
                    StrataScratch& scratch) {
    const std::size_t n = samples.size();
    if (n < 2) return pixel_spread(samples);
    const auto columns = std::max<std::size_t>(1, std::size_t(std::sqrt(double(n))));
    const std::size_t rows = (n + columns - 1) / columns;
    Color sum;
    double terms = 0;
    // The samples band by band (rows across x, or columns across y), each band in order along it,
    // ties by index, so the order is a pure function of the samples: dealt into their bands in
    // index order, then each band (about sqrt(n) samples) sorted on its own, which costs far less
    // than sorting all n at once.
    // (References, not a structured binding: clang 14, the fuzz build's compiler, cannot capture
    // a binding in the lambda below.)
    auto& band = scratch.band;
    auto& start = scratch.start;
    auto& order = scratch.order;
    band.resize(n);
    order.resize(n);
    const auto differences = [&](std::size_t bands, auto across, auto along) {
        start.assign(bands + 1, 0);
        for (std::uint32_t i = 0; i < n; ++i) {
            const double t = std::max(0.0, across(positions[i])) * double(bands);
            band[i] = static_cast<std::uint32_t>(std::min(bands - 1, std::size_t(t)));
            ++start[band[i] + 1];
        }
        for (std::size_t b = 0; b < bands; ++b) start[b + 1] += start[b];
        for (std::uint32_t i = 0; i < n; ++i) {
            order[start[band[i]]++] = {along(positions[i]), i};
        }
        // Each band's start was advanced to the next's: shift them back.
        for (std::size_t b = bands; b > 0; --b) start[b] = start[b - 1];
        start[0] = 0;
        const auto value = [&](std::size_t k) { return samples[order[k].index]; };
        for (std::size_t b = 0; b < bands; ++b) {
            const std::size_t begin = start[b], end = start[b + 1];
            std::sort(order.begin() + begin, order.begin() + end,
                      [](const StrataScratch::Entry& l, const StrataScratch::Entry& r) {
                          return l.along < r.along || (!(r.along < l.along) && l.index < r.index);
                      });
            if (end - begin == 2) {
                const Color d = value(begin + 1) - value(begin);
                sum += d * d / 2.0;
                terms += 1;
            }
            for (std::size_t k = begin + 1; end - begin >= 3 && k + 1 < end; ++k) {
                const Color d = value(k - 1) - 2.0 * value(k) + value(k + 1);
                sum += d * d / 6.0;
                terms += 1;
            }
        }
    };
    differences(
        rows, [](const Vec2& p) { return p.y; }, [](const Vec2& p) { return p.x; });
    differences(
        columns, [](const Vec2& p) { return p.x; }, [](const Vec2& p) { return p.y; });
    if (terms == 0) return pixel_spread(samples);
    return sum / (terms * double(n));
}

double calibration_share(double pixels) {
    const double n = std::max(1.0, pixels);
    return std::min(1.0, std::max(kMinSmallImageCalibration / n,
                                  std::min(kCalibrationShare, kMaxCalibrationPixels / n)));
}

std::vector<double> largest_around(std::span<const double> values, int width, int height,
                                   Around which) {
    std::vector<double> out(std::size_t(width) * std::size_t(height), 0.0);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            double most = 0;
            for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny) {
                for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
                    if (which == Around::kWithSelf || nx != x || ny != y) {
                        most = std::max(most, values[std::size_t(ny) * width + nx]);
                    }
                }
            }
            out[std::size_t(y) * width + x] = most;
        }
    }
    return out;
}

double pick_odds(double scale, double even, double weight, double total) {
    constexpr double kEven = 0.25;
    return std::min(1.0, scale * (kEven * even + (1 - kEven) * weight / total));
}

std::vector<double> calibration_odds(const Image& spread, double share) {
    const std::size_t pixels = std::size_t(spread.width) * spread.height;
    std::vector<double> own(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        own[i] = double(spread.rgb[3 * i]) + spread.rgb[3 * i + 1] + spread.rgb[3 * i + 2];
    }
    const std::vector<double> spreads =
        largest_around(own, spread.width, spread.height, Around::kWithSelf);
    double total = 0;
    for (const double s : spreads) total += s;
    std::vector<double> odds(pixels, std::min(share, 1.0));
    // A small image is rendered twice whole: odds following the spread would drop some pixels.
    if (share >= 1 || !(total > 0) || !std::isfinite(total)) return odds;
    const double mean = total / double(pixels);
    for (std::size_t i = 0; i < pixels; ++i) odds[i] = pick_odds(share, 1.0, spreads[i], mean);
    return odds;
}

void add_calibration(ErrorSums& sums, const Color& first, const Color& second, const Color& spread,
                     double odds, std::uint32_t samples) {
    const Color d = first - second;
    sums.variance += 0.5 * sum(d * d) / odds;
    sums.spread += sum(spread) / odds;
    sums.pixels += 1;
    sums.samples += samples;
}

ErrorEstimate estimate_error(const Image& image, const Image& spread, const ErrorSums& sums,
                             std::uint64_t samples, int spp, SpreadKind kind,
                             std::uint64_t pixels) {
    if (image.width != spread.width || image.height != spread.height) {
        throw ImageError("the spread image is " + std::to_string(spread.width) + "x" +
                         std::to_string(spread.height) + ", the image " +
                         std::to_string(image.width) + "x" + std::to_string(image.height));
    }
    ErrorEstimate e;
    if (spp < 2) {
        e.unavailable = "1 spp takes the pixel centre: no spread to measure";
        return e;
    }
    if (kind == SpreadKind::kCalibrated) {
        e.cost = samples > 0 ? sums.samples / double(samples) : 0;
        const bool flat = sums.variance == 0 && std::all_of(spread.rgb.begin(), spread.rgb.end(),
                                                            [](float v) { return v == 0; });
        if (flat) {
            e.scale = 0;
        } else if (sums.pixels < kMinCalibrationPixels) {
            std::ostringstream why;
            why << "the image is too small to calibrate the estimate: " << sums.pixels
                << " pixels rendered twice, " << kMinCalibrationPixels << " needed";
            e.unavailable = why.str();
            return e;
        } else if (sums.spread > 0) {
            e.scale = sums.variance / sums.spread;
        } else if (sums.variance > 0) {
            e.unavailable = "the pixels rendered twice differ but their samples do not spread";
            return e;
        } else {
            e.scale = 0;  // the pixels rendered twice alike, and their samples too
        }
    }
    // mse channel by channel; the concentration from each pixel's sum over its channels.
    double mse = 0, relmse = 0, pixel_sum = 0, pixel_squares = 0;
    for (std::size_t p = 0; p < image.rgb.size(); p += 3) {
        double pixel = 0;
        for (std::size_t i = p; i < p + 3; ++i) {
            const double v = e.scale * spread.rgb[i], x = image.rgb[i];
            if (!std::isfinite(v)) {
                // A pixel of one sample has an infinite spread, and so does one whose samples
                // differ by more than a float holds.
                e.unavailable =
                    "a pixel's spread is not finite (fewer than 2 samples, or radiance past the "
                    "float range)";
                return e;
            }
            mse += v;
            pixel += v;
            relmse += v / (std::max(0.0, x * x - v) + 0.01);
        }
        pixel_sum += pixel;
        pixel_squares += pixel * pixel;
    }
    if (pixel_squares > 0 && std::isfinite(pixel_squares))
        e.error_pixels = pixel_sum * pixel_sum / pixel_squares;
    const double count =
        std::max(1.0, 3.0 * (pixels > 0 ? double(pixels) : double(image.width) * image.height));
    e.rmse = std::sqrt(mse / count);
    e.relmse = relmse / count;
    return e;
}

Image standard_error_image(const Image& spread, const ErrorEstimate& estimate) {
    Image out = spread;
    for (float& v : out.rgb) v = estimate.available() ? float(std::sqrt(estimate.scale * v)) : 0.0f;
    return out;
}

std::string format_estimate(const std::optional<double>& value, const std::string& unavailable) {
    if (!value) return "n/a (" + unavailable + ")";
    std::ostringstream text;
    text << std::setprecision(3) << *value;
    return text.str();
}

}  // namespace drt
