#include "drt/util/limits.h"

#include <algorithm>
#include <thread>

namespace drt {

std::string image_limit_message(std::uint64_t width, std::uint64_t height) {
    const std::string image =
        "image of " + std::to_string(width) + "x" + std::to_string(height) + " pixels";
    if (width > kMaxImageSide || height > kMaxImageSide) {
        return image + " exceeds the limit of " + std::to_string(kMaxImageSide) + " pixels a side";
    }
    return image + " exceeds the limit of " + std::to_string(kMaxPixels) + " pixels";
}

int worker_threads(int threads) {
    return threads > 0 ? threads
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace drt
