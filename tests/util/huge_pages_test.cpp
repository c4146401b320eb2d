#include "drt/util/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sanitizers.h"

namespace drt {
namespace {

// Kernel memory in huge pages (kB) of the mapping that holds `address`, from /proc/self/smaps.
long huge_kb_at(const void* address) {
    const auto a = reinterpret_cast<std::uintptr_t>(address);
    std::ifstream smaps("/proc/self/smaps");
    bool inside = false;
    for (std::string line; std::getline(smaps, line);) {
        std::uintptr_t begin = 0, end = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> begin >> dash >> end && dash == '-') {
            inside = begin <= a && a < end;
        } else if (inside && line.starts_with("AnonHugePages:")) {
            return std::stol(line.substr(14));
        }
    }
    return -1;
}

std::string huge_page_mode() {
    std::ifstream f("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string mode;
    std::getline(f, mode);
    return mode;
}

// What a mesh's build relies on for its speed: an array asked for in huge pages gets them. Where
// the kernel does not offer them at all, the hint is a no-op and there is nothing to check.
TEST(HugePages, AnArrayAskedForHugePagesGetsThemWhereTheSystemOffersThem) {
#ifdef DRT_TEST_ASAN
    GTEST_SKIP() << "AddressSanitizer's allocator maps memory its own way";
#endif
    const std::string mode = huge_page_mode();
    if (mode.empty() || mode.find("[never]") != std::string::npos)
        GTEST_SKIP() << "no transparent huge pages here: " << mode;
    std::vector<std::uint64_t> v;
    v.reserve(std::size_t{16} << 17);  // 16 MiB
    prefer_huge_pages(v);
    v.assign(v.capacity(), 1);
    EXPECT_GE(huge_kb_at(v.data() + v.size() / 2), 2048) << mode;
    EXPECT_EQ(v[v.size() / 2], 1u);
}

}  // namespace
}  // namespace drt
