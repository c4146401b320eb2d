#include "drt/goal/converge.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace {

void require_same_size(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height) {
        throw ImageError("image is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                         " but the reference is " + std::to_string(b.width) + "x" +
                         std::to_string(b.height));
    }
}

}  // namespace

double rmse(const Image& image, const Image& reference) {
    require_same_size(image, reference);
    double sum = 0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        const double d = double(image.rgb[i]) - reference.rgb[i];
        sum += d * d;
    }
    return image.rgb.empty() ? 0.0 : std::sqrt(sum / image.rgb.size());
}

double relative_mse(const Image& image, const Image& reference) {
    require_same_size(image, reference);
    double sum = 0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        const double r = reference.rgb[i], d = image.rgb[i] - r;
        sum += d * d / (r * r + 0.01);
    }
    return image.rgb.empty() ? 0.0 : sum / image.rgb.size();
}

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
        if (!(x[i] > 0) || !(y[i] > 0)) continue;
        const double lx = std::log(x[i]), ly = std::log(y[i]);
        n += 1, sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    }
    const double spread = n * sxx - sx * sx;
    // Relative to the scale of sxx, so equal x values count as equal despite rounding.
    if (n < 2 || !(spread > 1e-12 * n * sxx)) return std::numeric_limits<double>::quiet_NaN();
    return (n * sxy - sx * sy) / spread;
}

int default_reference_spp(const std::vector<int>& spps) {
    const int largest = spps.empty() ? 1 : *std::max_element(spps.begin(), spps.end());
    // In 64 bits, then capped: 16 x a count near 2^31 would overflow an int.
    return static_cast<int>(std::min<std::int64_t>(16 * std::int64_t{largest}, kMaxSamples));
}

std::uint64_t reference_seed(std::uint64_t seed) {
    return seed + 1;
}

RenderRequest request_at(int spp, std::uint64_t seed, const RenderOptions& options) {
    RenderRequest request;
    request.samples = spp;
    request.seed = seed;
    request.adaptive = options.adaptive;
    return request;
}

Convergence measure_convergence(const Scene& scene, const std::vector<int>& spps,
                                const Image& reference, const RenderOptions& options,
                                const std::function<void(const ConvergencePoint&)>& on_point) {
    require_same_size(Image(scene.settings.width, scene.settings.height), reference);
    Convergence c;
    const int largest = spps.empty() ? 1 : *std::max_element(spps.begin(), spps.end());
    for (const int spp : spps) {
        const std::clock_t cpu_start = std::clock();
        const RenderResult r =
            render(scene, request_at(spp, scene.settings.seed, options), options);
        ConvergencePoint p;
        p.spp = spp;
        p.seconds = r.stats.seconds;
        p.cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
        p.rmse = rmse(r.image, reference);
        p.relmse = relative_mse(r.image, reference);
        const double pixels = double(r.image.width) * r.image.height;
        p.mean_spp = pixels > 0 ? r.stats.samples / pixels : 0;
        p.fitted = r.plan.effects.antialiasing || largest == 1;
        p.estimate = r.stats.error;
        c.points.push_back(p);
        if (on_point) on_point(p);
    }
    std::vector<double> samples, seconds, errors;
    for (const ConvergencePoint& p : c.points) {
        if (!p.fitted) continue;
        samples.push_back(p.mean_spp);
        seconds.push_back(p.seconds);
        errors.push_back(p.rmse);
    }
    c.slope_vs_spp = loglog_slope(samples, errors);
    c.slope_vs_seconds = loglog_slope(seconds, errors);
    return c;
}

std::optional<Reach> measured_reach(const Convergence& c, double target) {
    // The counts as listed may come in any order; the reach is along growing counts.
    std::vector<const ConvergencePoint*> fitted;
    for (const ConvergencePoint& p : c.points) {
        if (p.fitted) fitted.push_back(&p);
    }
    std::stable_sort(fitted.begin(), fitted.end(),
                     [](const auto* a, const auto* b) { return a->spp < b->spp; });
    const ConvergencePoint* before = nullptr;
    for (const ConvergencePoint* point : fitted) {
        const ConvergencePoint& p = *point;
        if (p.rmse <= target) {
            if (!before || before->rmse <= 0 || p.rmse <= 0) return Reach{double(p.spp), p.seconds};
            // Log-linear in both: t in [0, 1] from `before` to `p`.
            const double t = std::log(target / before->rmse) / std::log(p.rmse / before->rmse);
            const auto between = [t](double a, double b) {
                return a > 0 && b > 0 ? std::exp(std::log(a) + t * (std::log(b) - std::log(a)))
                                      : a + t * (b - a);
            };
            return Reach{between(before->spp, p.spp), between(before->seconds, p.seconds)};
        }
        before = &p;
    }
    return std::nullopt;
}

std::string convergence_csv(const Convergence& c) {
    std::ostringstream out;
    out << std::setprecision(9);
    out << "spp,seconds,rmse,relmse,mean_spp,cpu_seconds,fitted,estimated_rmse,estimated_relmse\n";
    for (const ConvergencePoint& p : c.points) {
        out << p.spp << "," << p.seconds << "," << p.rmse << "," << p.relmse << "," << p.mean_spp
            << "," << p.cpu_seconds << "," << (p.fitted ? 1 : 0) << ",";
        if (p.estimate.available())
            out << *p.estimate.rmse << "," << *p.estimate.relmse;
        else
            out << ",";
        out << "\n";
    }
    return out.str();
}

std::vector<int> parse_counts(const std::string& list) {
    std::vector<int> counts;
    std::size_t start = 0;
    while (true) {
        const std::size_t end = std::min(list.find(',', start), list.size());
        const std::string item = list.substr(start, end - start);
        int value = 0;
        const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
        if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || value <= 0 ||
            value > kMaxSamples) {
            throw std::invalid_argument("'" + abbreviated(item) + "' in '" + abbreviated(list) +
                                        "' is not a sample count from 1 to " +
                                        std::to_string(kMaxSamples));
        }
        counts.push_back(value);
        if (end == list.size()) break;
        start = end + 1;
    }
    return counts;
}

}  // namespace drt
