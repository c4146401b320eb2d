#include "drt/util/limits.h"

#include <algorithm>
#include <thread>

namespace drt {

std::string too_many_pixels(std::uint64_t width, std::uint64_t height) {
    return "image of " + std::to_string(width) + "x" + std::to_string(height) +
           " pixels exceeds the limit of " + std::to_string(kMaxPixels) + " pixels";
}

int worker_threads(int threads) {
    return threads > 0 ? threads
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace drt
