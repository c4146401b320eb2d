#include "drt/mesh_build.h"

#include <algorithm>
#include <thread>

#include "drt/math.h"

namespace drt {

namespace {

using Float3 = std::array<float, 3>;

constexpr std::uint32_t kMaxLeaf = 8;
constexpr int kBins = 16;
// Past this depth a node is split at its median, so that no path is longer than 40 + log2(n)
// nodes, which the traversal's stack holds.
constexpr int kSahDepth = 40;
// Subtrees of fewer triangles are built on the thread that reached them: a thread costs about
// what building a few thousand triangles does.
constexpr std::uint32_t kParallelBuild = 16384;

Vec3 to_vec3(const Float3& f) {
    return {f[0], f[1], f[2]};
}

struct BuildItem {
    Float3 lo, hi;
    std::uint32_t triangle;

    float centre(int axis) const { return (lo[axis] + hi[axis]) * 0.5f; }
};

// Builds the subtree of items [begin, end) into `nodes` (its root at the end of `nodes`, node
// indices relative to the start of `nodes`); `tasks` > 1 builds second subtrees on threads of
// their own, that many at a time at most.
std::uint32_t build(std::vector<BuildItem>& items, std::uint32_t begin, std::uint32_t end,
                    int depth, std::vector<BinaryNode>& nodes, int tasks) {
    const auto index = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({});
    Float3 lo = items[begin].lo, hi = items[begin].hi;
    Float3 centre_lo{}, centre_hi{};
    for (int a = 0; a < 3; ++a) centre_lo[a] = centre_hi[a] = items[begin].centre(a);
    for (std::uint32_t i = begin; i < end; ++i) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], items[i].lo[a]);
            hi[a] = std::max(hi[a], items[i].hi[a]);
            centre_lo[a] = std::min(centre_lo[a], items[i].centre(a));
            centre_hi[a] = std::max(centre_hi[a], items[i].centre(a));
        }
    }
    nodes[index].lo = lo;
    nodes[index].hi = hi;
    const std::uint32_t count = end - begin;
    const auto make_leaf = [&] {
        nodes[index].offset = begin;
        nodes[index].count = count;
        return index;
    };
    if (count <= 2) return make_leaf();

    int axis = 0;
    for (int a = 1; a < 3; ++a) {
        if (centre_hi[a] - centre_lo[a] > centre_hi[axis] - centre_lo[axis]) axis = a;
    }
    const float extent = centre_hi[axis] - centre_lo[axis];
    std::uint32_t mid = begin + count / 2;
    bool split = extent > 0 && depth < kSahDepth;
    if (split) {
        // Binned surface-area heuristic (Wald 2007): cost of a split ∝ area × triangles on each
        // side, against a leaf's cost ∝ its triangles.
        struct Bin {
            Bounds box;
            std::uint32_t count = 0;
        };
        std::array<Bin, kBins> bins{};
        const double to_bin = kBins / static_cast<double>(extent);
        const auto bin_of = [&](const BuildItem& item) {
            return std::min(kBins - 1,
                            static_cast<int>((item.centre(axis) - centre_lo[axis]) * to_bin));
        };
        for (std::uint32_t i = begin; i < end; ++i) {
            Bin& bin = bins[bin_of(items[i])];
            bin.box.grow(to_vec3(items[i].lo)).grow(to_vec3(items[i].hi));
            ++bin.count;
        }
        std::array<double, kBins> right_cost{};
        Bounds right;
        std::uint32_t right_count = 0;
        for (int b = kBins - 1; b > 0; --b) {
            right.grow(bins[b].box);
            right_count += bins[b].count;
            right_cost[b] = right.surface_area() * right_count;
        }
        Bounds left;
        std::uint32_t left_count = 0;
        double best = kInfinity;
        int best_bin = 0;
        for (int b = 0; b + 1 < kBins; ++b) {
            left.grow(bins[b].box);
            left_count += bins[b].count;
            const double cost = left.surface_area() * left_count + right_cost[b + 1];
            if (left_count > 0 && left_count < count && cost < best) best = cost, best_bin = b;
        }
        const double area = Bounds{to_vec3(lo), to_vec3(hi)}.surface_area();
        // One box test costs about as much as one triangle test.
        const bool worth_it = area * (count - 1) > best || count > kMaxLeaf;
        if (!worth_it) return make_leaf();
        mid = static_cast<std::uint32_t>(
            std::partition(items.begin() + begin, items.begin() + end,
                           [&](const BuildItem& item) { return bin_of(item) <= best_bin; }) -
            items.begin());
        split = mid != begin && mid != end;
    }
    if (!split) {
        if (count <= kMaxLeaf && extent == 0) return make_leaf();
        mid = begin + count / 2;
        std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                         [axis](const BuildItem& a, const BuildItem& b) {
                             return a.centre(axis) < b.centre(axis);
                         });
    }
    std::uint32_t second = 0;
    if (tasks > 1 && count >= kParallelBuild) {
        // The second subtree on a thread of its own, into nodes of its own, then appended after
        // the first: where the sequential build would have put it, node for node.
        std::vector<BinaryNode> second_nodes;
        {
            const std::jthread worker([&] {
                second_nodes.reserve(end - mid);
                build(items, mid, end, depth + 1, second_nodes, tasks / 2);
            });
            build(items, begin, mid, depth + 1, nodes, tasks - tasks / 2);
        }
        second = static_cast<std::uint32_t>(nodes.size());
        for (BinaryNode n : second_nodes) {
            if (n.count == 0) n.offset += second;
            nodes.push_back(n);
        }
    } else {
        build(items, begin, mid, depth + 1, nodes, 1);
        second = build(items, mid, end, depth + 1, nodes, 1);
    }
    nodes[index].offset = second;
    nodes[index].count = 0;
    return index;
}

}  // namespace

BinaryTree build_binary_tree(std::span<const Float3> positions,
                             std::span<const std::array<std::uint32_t, 3>> triangles, int threads) {
    std::vector<BuildItem> items(triangles.size());
    for (std::uint32_t i = 0; i < items.size(); ++i) {
        BuildItem& item = items[i];
        item.triangle = i;
        item.lo = item.hi = positions[triangles[i][0]];
        for (int k = 1; k < 3; ++k) {
            const Float3& p = positions[triangles[i][k]];
            for (int a = 0; a < 3; ++a) {
                item.lo[a] = std::min(item.lo[a], p[a]);
                item.hi[a] = std::max(item.hi[a], p[a]);
            }
        }
    }
    BinaryTree tree;
    // At most 2n - 1 nodes; a leaf holds two triangles or more unless it is alone.
    tree.nodes.reserve(items.size());
    // More tasks than threads, so that the unequal halves SAH splits make still keep every
    // thread busy to the end.
    build(items, 0, static_cast<std::uint32_t>(items.size()), 0, tree.nodes,
          threads > 1 ? 4 * threads : 1);
    tree.order.resize(items.size());
    for (std::size_t i = 0; i < items.size(); ++i) tree.order[i] = items[i].triangle;
    return tree;
}

}  // namespace drt
