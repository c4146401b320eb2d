// Whether a scene's render settings fit the limits of util/limits.h: checked before anything is
// allocated, so that a render past them is bad input (exit 2) rather than a machine out of memory.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "drt/scene/scene.h"

namespace drt {

// The memory the photon maps of a render with these settings may take at most (none without
// <Photons>): every pass's map, each photon stored at most once.
std::uint64_t photon_bytes(const RenderSettings& settings);

// Why the photon maps of these settings would not fit their share of the budget, or nothing.
// The loader asks it of the scene's own settings (to name the <Photons> line), a render of the
// settings the command line leaves.
std::optional<std::string> photon_budget_problem(const RenderSettings& settings);

// The memory a render of these settings on `threads` worker threads needs at its peak, with
// `aov_channels` AOV values a pixel (--aov) besides its colour.
std::uint64_t estimated_render_bytes(const RenderSettings& settings, int threads,
                                     int aov_channels = 0);

// Why these settings cannot be rendered on `threads` threads (0 = all cores), or nothing: a size
// or count past its limit, or an estimate past kMemoryBudget. One line, naming the limit. The
// budget also bounds the checkpoint a render writes, which holds what its pixels hold.
std::optional<std::string> render_limit_problem(const RenderSettings& settings, int threads,
                                                int aov_channels = 0);

}  // namespace drt
