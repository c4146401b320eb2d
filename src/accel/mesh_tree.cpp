#include "drt/accel/mesh_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "drt/geometry/triangle_batch.h"
#include "drt/util/huge_pages.h"

namespace drt {

namespace {

// The traversal tests up to four triangles of a leaf at once (triangle_batch.h), for about what
// one box test costs: a subtree of this many triangles or fewer is visited as one leaf.
constexpr std::uint32_t kCollapsedLeaf = 4;

}  // namespace

MeshTree::MeshTree(std::vector<BinaryNode> binary) {
    lo_ = binary[0].lo;
    hi_ = binary[0].hi;
    filter_fits_ = true;
    for (int a = 0; a < 3; ++a) {
        filter_fits_ = filter_fits_ &&
                       std::max(std::abs(lo_[a]), std::abs(hi_[a])) <= FloatShearedRay::kLargest;
    }
    collapse_small_subtrees(binary);
    // Each wide node takes the place of at least three binary ones (but a root that is a leaf).
    nodes_.reserve(binary.size() / 3 + 1);
    prefer_huge_pages(nodes_);
    widen(binary, 0);
    nodes_.shrink_to_fit();
}

Bounds MeshTree::bounds() const {
    if (nodes_.empty()) return {};
    return {to_vec3(lo_), to_vec3(hi_)};
}

void MeshTree::collapse_small_subtrees(std::vector<BinaryNode>& binary) {
    // A node's children come after it (the first right after), so one pass from the end sees
    // every subtree before its root. A subtree's triangles are one run of the leaf order.
    std::vector<std::uint32_t> first(binary.size()), size(binary.size());
    for (std::size_t n = binary.size(); n-- > 0;) {
        BinaryNode& node = binary[n];
        if (node.count > 0) {
            first[n] = node.offset;
            size[n] = node.count;
            continue;
        }
        first[n] = first[n + 1];
        size[n] = size[n + 1] + size[node.offset];
        if (size[n] <= kCollapsedLeaf) node = {node.lo, node.hi, first[n], size[n]};
    }
}

std::uint32_t MeshTree::widen(const std::vector<BinaryNode>& binary, std::uint32_t node) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    // The node's binary children, then, while there is room, the inner one of largest surface
    // area replaced by its two children: what a wide node saves is the most boxes entered.
    std::array<std::uint32_t, kWidth> kids{};
    int n = 0;
    if (binary[node].count > 0) {
        kids[n++] = node;  // the whole tree is one leaf
    } else {
        kids[n++] = node + 1;
        kids[n++] = binary[node].offset;
    }
    const auto area = [&](std::uint32_t k) {
        return Bounds{to_vec3(binary[k].lo), to_vec3(binary[k].hi)}.surface_area();
    };
    while (n < kWidth) {
        int open = -1;
        for (int k = 0; k < n; ++k) {
            if (binary[kids[k]].count == 0 && (open < 0 || area(kids[k]) > area(kids[open])))
                open = k;
        }
        if (open < 0) break;
        const std::uint32_t opened = kids[open];
        kids[open] = opened + 1;
        kids[n++] = binary[opened].offset;
    }
    // Unused slots keep boxes at +∞ on both sides, which no ray enters, but `children` is what
    // the traversal reads.
    for (int a = 0; a < 3; ++a) {
        for (int k = 0; k < kWidth; ++k) {
            nodes_[index].box[0][a][k] = nodes_[index].box[1][a][k] =
                std::numeric_limits<float>::infinity();
        }
    }
    nodes_[index].children = static_cast<std::uint32_t>(n);
    for (int k = 0; k < n; ++k) {
        const BinaryNode& child = binary[kids[k]];
        for (int a = 0; a < 3; ++a) {
            nodes_[index].box[0][a][k] = child.lo[a];
            nodes_[index].box[1][a][k] = child.hi[a];
        }
        // (widen appends to nodes_: no reference into it is held across the call.)
        const std::uint32_t target = child.count > 0 ? child.offset : widen(binary, kids[k]);
        nodes_[index].child[k] = target;
        nodes_[index].count[k] = static_cast<std::uint16_t>(child.count);
    }
    return index;
}

}  // namespace drt
