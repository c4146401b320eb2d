// The tree a TriangleMesh traverses, made from the binary tree of mesh_build.h: up to eight
// children a node, their boxes side by side so that one 8-wide SIMD test (AVX; two 4-wide ones
// elsewhere) tests them all, as Embree does for single rays (Wald, Benthin & Boulos 2008;
// Dammertz et al. 2008): half the levels of a 4-wide tree. A leaf's triangles are tested four at
// a time through a float filter, then by the watertight double test, which alone decides.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "drt/accel/float3.h"
#include "drt/accel/mesh_build.h"
#include "drt/geometry/triangle.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

struct MeshHit {
    double t;
    std::uint32_t triangle;
    Barycentrics b;
};

// The triangles a MeshTree holds, in its leaf order, and the vertices they index.
struct MeshGeometry {
    std::span<const Float3> positions;
    std::span<const std::array<std::uint32_t, 3>> triangles;
};

class MeshTree {
  public:
    // A tree of no triangles, which no ray meets.
    MeshTree() = default;
    // The tree over `binary` (BinaryTree::nodes), whose leaf order (BinaryTree::order) the
    // triangles of every query's MeshGeometry must follow.
    explicit MeshTree(std::vector<BinaryNode> binary);

    // The box of every triangle; empty for a tree of none.
    Bounds bounds() const;

    // Nearest hit inside `range` of a ray given in the mesh's own coordinates.
    std::optional<MeshHit> intersect(const Ray& ray, Interval range, MeshGeometry geometry) const;
    // Whether any triangle meets the ray inside `range` (stops at the first).
    bool occluded(const Ray& ray, Interval range, MeshGeometry geometry) const;
    // How many triangles the query (nearest hit, or any hit) tests on its way, counting every
    // triangle of a batch of up to four tested together.
    std::uint64_t triangle_tests(const Ray& ray, Interval range, MeshGeometry geometry,
                                 bool any_hit) const;

    // The nodes as bytes, for telling whether two builds made the same tree.
    std::span<const std::byte> bytes() const { return std::as_bytes(std::span(nodes_)); }
    // Memory held for the nodes.
    std::size_t memory() const { return nodes_.capacity() * sizeof(Node); }

  private:
    // 256 bytes a node, aligned to start a cache line: the boxes are its first three lines. A
    // child is a node (`count` 0, `child` its index) or a leaf (`count` triangles from `child`);
    // the first `children` slots are used.
    static constexpr int kWidth = 8;
    struct alignas(64) Node {
        float box[2][3][kWidth];  // [low side, high side][axis][child]
        std::uint32_t child[kWidth];
        std::uint16_t count[kWidth];
        std::uint32_t children;
        std::uint32_t unused[3];  // 0: a node has no padding bytes of unknown value
    };

    // Turns every inner node whose subtree holds few triangles into a leaf of them all.
    static void collapse_small_subtrees(std::vector<BinaryNode>& binary);
    // Turns the binary subtree at `node` into wide nodes appended to nodes_; returns the index
    // of the one made for `node`.
    std::uint32_t widen(const std::vector<BinaryNode>& binary, std::uint32_t node);
    // What a query answers: whether any triangle is hit, or the nearest hit.
    template <bool kAnyHit>
    using Answer = std::conditional_t<kAnyHit, bool, std::optional<MeshHit>>;
    // `tests`, when given, counts the triangles tested.
    template <bool kAnyHit>
    Answer<kAnyHit> traverse(const Ray& ray, Interval range, MeshGeometry geometry,
                             std::uint64_t* tests = nullptr) const;

    std::vector<Node> nodes_;
    Float3 lo_{}, hi_{};        // bounds of every triangle
    bool filter_fits_ = false;  // coordinates small enough for the float filter
};

}  // namespace drt
