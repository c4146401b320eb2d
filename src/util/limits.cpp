#include "drt/util/limits.h"

#include <algorithm>
#include <thread>

namespace drt {

int worker_threads(int threads) {
    return threads > 0 ? threads
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace drt
