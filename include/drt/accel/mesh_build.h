// The binary bounding-volume hierarchy a TriangleMesh is built from: a binned surface-area
// heuristic over the triangles' boxes (Wald 2007), built in parallel and the same tree whatever
// the number of threads. MeshTree (mesh_tree.h) turns it into the nodes it traverses.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "drt/accel/float3.h"

namespace drt {

// A node of the binary tree, 32 bytes: its box, and either its triangles (a leaf: `count` of
// them from `offset` in BinaryTree::order) or its second child (an inner node: `count` 0, the
// first child follows it).
struct BinaryNode {
    Float3 lo, hi;
    std::uint32_t offset;
    std::uint32_t count;
};

struct BinaryTree {
    std::vector<BinaryNode> nodes;  // the root first
    // The triangles in leaf order: a leaf's triangles are order[offset .. offset + count).
    std::vector<std::uint32_t> order;
};

// The tree over `triangles` (indices into `positions`), at least one. No leaf holds more than
// 8 triangles, and no path from the root is longer than 40 + log2(triangles) nodes. Built on
// `threads` threads; the tree is the same for any number.
BinaryTree build_binary_tree(std::span<const Float3> positions,
                             std::span<const std::array<std::uint32_t, 3>> triangles, int threads);

}  // namespace drt
