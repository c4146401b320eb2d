#include "drt/scene/render_limits.h"

#include <algorithm>

#include "drt/util/limits.h"

namespace drt {

std::uint64_t photon_bytes(const RenderSettings& settings) {
    if (!settings.photons) return 0;
    return std::uint64_t(std::max(settings.samples, 0)) *
           std::uint64_t(std::max(settings.photons->count, 0)) * kBytesPerPhoton;
}

std::optional<std::string> photon_budget_problem(const RenderSettings& s) {
    const std::uint64_t bytes = photon_bytes(s);
    if (bytes <= kMaxPhotonBytes) return std::nullopt;
    return "the photon maps need an estimated " + std::to_string(bytes >> 20) + " MiB (" +
           std::to_string(s.samples) + " passes x " + std::to_string(s.photons->count) +
           " photons x " + std::to_string(kBytesPerPhoton) + " B), more than their " +
           std::to_string(kMaxPhotonBytes >> 20) +
           " MiB share of the budget: lower Samples or the Photons Count";
}

std::uint64_t estimated_render_bytes(const RenderSettings& settings, int threads,
                                     int aov_channels) {
    const std::uint64_t pixels =
        std::uint64_t(std::max(settings.width, 0)) * std::uint64_t(std::max(settings.height, 0));
    const std::uint64_t samples = std::uint64_t(std::max(settings.samples, 0));
    return pixels *
               (kBytesPerPixel + kBytesPerAovChannel * std::uint64_t(std::max(aov_channels, 0))) +
           std::uint64_t(std::max(threads, 1)) * samples * kBytesPerSample + photon_bytes(settings);
}

std::optional<std::string> render_limit_problem(const RenderSettings& s, int threads,
                                                int aov_channels) {
    const auto over = [](const std::string& what, std::uint64_t value, std::uint64_t limit) {
        return what + " " + std::to_string(value) + " exceeds the limit of " +
               std::to_string(limit);
    };
    if (s.width > kMaxImageSide || s.height > kMaxImageSide) {
        return "image size " + std::to_string(s.width) + "x" + std::to_string(s.height) +
               " exceeds the limit of " + std::to_string(kMaxImageSide) + " pixels a side";
    }
    const std::uint64_t pixels = std::uint64_t(s.width) * std::uint64_t(s.height);
    if (pixels > kMaxPixels) {
        return "image size " + std::to_string(s.width) + "x" + std::to_string(s.height) + " (" +
               std::to_string(pixels) + " pixels) exceeds the limit of " +
               std::to_string(kMaxPixels) + " pixels";
    }
    if (s.samples > kMaxSamples) return over("samples per pixel", s.samples, kMaxSamples);
    if (s.shadow_rays > kMaxRaysPerPoint)
        return over("shadow rays", s.shadow_rays, kMaxRaysPerPoint);
    if (s.glossy_rays > kMaxRaysPerPoint)
        return over("glossy rays", s.glossy_rays, kMaxRaysPerPoint);
    if (s.max_depth > kMaxDepthLimit) return over("max depth", s.max_depth, kMaxDepthLimit);
    if (auto photons = photon_budget_problem(s)) return photons;
    const int workers = worker_threads(threads);
    const std::uint64_t bytes = estimated_render_bytes(s, workers, aov_channels);
    if (bytes > kMemoryBudget) {
        std::string per_pixel = std::to_string(kBytesPerPixel);
        if (aov_channels > 0) {
            per_pixel.insert(0, "(");
            per_pixel += " + " + std::to_string(aov_channels) + " AOV channels x " +
                         std::to_string(kBytesPerAovChannel) + ")";
        }
        return "the render needs an estimated " + std::to_string(bytes >> 20) + " MiB (" +
               std::to_string(pixels) + " pixels x " + per_pixel + " B + " +
               std::to_string(workers) + " threads x " + std::to_string(s.samples) + " samples x " +
               std::to_string(kBytesPerSample) + " B), more than the " +
               std::to_string(kMemoryBudget >> 20) + " MiB budget";
    }
    return std::nullopt;
}

}  // namespace drt
