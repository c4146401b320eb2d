// The tree over a TriangleMesh's triangles, made from the binary tree of mesh_build.h: up to
// eight children a node, their boxes side by side so that one 8-wide SIMD test (AVX; two 4-wide
// ones elsewhere) tests them all, as Embree does for single rays (Wald, Benthin & Boulos 2008;
// Dammertz et al. 2008): half the levels of a 4-wide tree. The traversal is TriangleMesh's own
// (mesh_traversal.cpp), so that a query reaches nodes and triangles through the one mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "drt/accel/float3.h"
#include "drt/accel/mesh_build.h"
#include "drt/util/math.h"

namespace drt {

class MeshTree {
  public:
    static constexpr int kWidth = 8;
    // 256 bytes a node, aligned to start a cache line: the boxes are its first three lines. A
    // child is a node (`count` 0, `child` its index) or a leaf (`count` triangles from `child`
    // in the leaf order); the first `children` slots are used, the others have boxes at +∞ on
    // both sides, which no ray enters.
    struct alignas(64) Node {
        float box[2][3][kWidth];  // [low side, high side][axis][child]
        std::uint32_t child[kWidth];
        std::uint16_t count[kWidth];
        std::uint32_t children;
        std::uint32_t unused[3];  // 0: a node has no padding bytes of unknown value
    };

    // A tree of no triangles.
    MeshTree() = default;
    // The tree over `binary` (BinaryTree::nodes), whose leaf order (BinaryTree::order) the
    // triangles it is traversed with must follow.
    explicit MeshTree(std::vector<BinaryNode> binary);

    bool empty() const { return nodes_.empty(); }
    // The root is node 0.
    const Node& node(std::uint32_t index) const { return nodes_[index]; }
    // The box of every triangle; empty for a tree of none.
    Bounds bounds() const;
    // Whether every coordinate is small enough for the float filter of the leaf test
    // (FloatShearedRay::kLargest in triangle_batch.h).
    bool filter_fits() const { return filter_fits_; }

    // The nodes as bytes, for telling whether two builds made the same tree.
    std::span<const std::byte> bytes() const { return std::as_bytes(std::span(nodes_)); }
    // Memory held for the nodes.
    std::size_t memory() const { return nodes_.capacity() * sizeof(Node); }

  private:
    // Turns every inner node whose subtree holds few triangles into a leaf of them all.
    static void collapse_small_subtrees(std::vector<BinaryNode>& binary);
    // Turns the binary subtree at `node` into wide nodes appended to nodes_; returns the index
    // of the one made for `node`.
    std::uint32_t widen(const std::vector<BinaryNode>& binary, std::uint32_t node);

    std::vector<Node> nodes_;
    Float3 lo_{}, hi_{};        // bounds of every triangle
    bool filter_fits_ = false;  // coordinates small enough for the float filter
};

}  // namespace drt
