// Large arrays allocated and then filled at once (a mesh's triangles, its hierarchy, the build's
// working arrays) cost a page fault for every 4 KiB page they touch, a large share of a mesh's
// build. Asked for, Linux backs them with 2 MiB pages instead (transparent huge pages in
// "madvise" mode, the usual default): 512 times fewer faults.
#pragma once

#include <cstddef>
#include <vector>

namespace drt {

// Asks for the whole 2 MiB pages inside [data, data + bytes) to be huge pages when first
// touched. Only a hint: nothing changes where the system does not offer them, and pages already
// touched stay as they are. Regions too small to hold one are left alone.
void prefer_huge_pages(void* data, std::size_t bytes);

// The same for a vector's whole capacity: call it after reserve() and before filling.
template <class T>
void prefer_huge_pages(std::vector<T>& v) {
    prefer_huge_pages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace drt
