// What a sampler works out from a camera sample's (seed, pixel, dimension, branch) alone, such as
// the keys of that dimension's pattern, remembered per dimension for the pixel in hand.
#pragma once

#include <array>
#include <cstdint>

#include "drt/sampling/sampler.h"

namespace drt {

// Every camera sample of a pixel asks for the same dimensions along the same branches, and the
// keys a sampler hashes from them are the same for all of the pixel's samples: remembered, they
// are hashed once per pixel instead of once per sample. A slot per dimension (folded to the low
// bits, branch mixed in), each holding the latest (seed, pixel, dimension, branch) it saw; a
// value is a pure function of those, so a slot taken over by another dimension only costs a
// recomputation. One per thread and sampler (a thread_local), since samplers are shared.
template <typename Value>
class DimensionMemo {
  public:
    // The value for (s.seed, s.pixel, dim, s.path): remembered, or make() and remembered.
    template <typename Make>
    const Value& get(const PixelSample& s, std::uint32_t dim, Make make) {
        const auto slot_index =
            (dim ^ (dim >> 16) ^ static_cast<std::uint32_t>(s.path)) & (kSlots - 1);
        Slot& slot = slots_[slot_index];
        if (!slot.taken || slot.seed != s.seed || slot.path != s.path || slot.pixel != s.pixel ||
            slot.dim != dim) {
            slot = {s.seed, s.path, s.pixel, dim, true, make()};
        }
        return slot.value;
    }

  private:
    // More than the dimensions a path of a few bounces keeps asking for.
    static constexpr std::uint32_t kSlots = 64;
    struct Slot {
        std::uint64_t seed = 0, path = 0;
        std::uint32_t pixel = 0, dim = 0;
        bool taken = false;
        Value value{};
    };
    std::array<Slot, kSlots> slots_{};
};

}  // namespace drt
