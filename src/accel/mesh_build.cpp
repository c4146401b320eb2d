#include "drt/accel/mesh_build.h"

#include <immintrin.h>
#include <algorithm>
#include <limits>
#include <optional>

#include "drt/util/huge_pages.h"
#include "drt/util/parallel.h"

namespace drt {

namespace {

constexpr std::uint32_t kMaxLeaf = 8;
constexpr int kBins = 16;
// Past this depth a node is split at its median, so that no path is longer than 40 + log2(n)
// nodes, which the traversal's stack holds.
constexpr int kSahDepth = 40;
// Subtrees of fewer triangles are built on the thread that reached them: a thread costs about
// what building a few thousand triangles does.
constexpr std::uint32_t kParallelBuild = 16384;

// A triangle's box, 32 bytes so that each half is one aligned SIMD load; the triangle's index
// rides in the lane the box does not use.
struct alignas(16) Item {
    float lo[3];
    std::uint32_t triangle;
    float hi[3];
    float unused;

    float centre(int axis) const { return (lo[axis] + hi[axis]) * 0.5f; }
};

// Boxes kept as SIMD registers, x y z in the first three lanes (the fourth is never read):
// min and max are exact, so boxes grown in any order and merged in any way are the same box.
struct Box {
    __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());

    void grow(__m128 l, __m128 h) { lo = _mm_min_ps(lo, l), hi = _mm_max_ps(hi, h); }
    void grow(const Box& b) { grow(b.lo, b.hi); }
    float lo_at(int axis) const { return lane(lo, axis); }
    float hi_at(int axis) const { return lane(hi, axis); }
    // In double, as 2 (xy + yz + zx) of the extents. The tree depends on these costs bit for
    // bit, so a change to this arithmetic changes the images. An empty box has none.
    double surface_area() const {
        if (lo_at(0) > hi_at(0)) return 0;
        double e[3];
        for (int a = 0; a < 3; ++a) e[a] = static_cast<double>(hi_at(a)) - lo_at(a);
        return 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
    }

    static float lane(__m128 v, int axis) {
        alignas(16) float f[4];
        _mm_store_ps(f, v);
        return f[axis];
    }
};

// What a subtree's root needs to know of its items: their box, and the box of their centres.
struct Extent {
    Box bounds, centres;

    void grow(const Item& item) {
        const __m128 l = _mm_load_ps(item.lo), h = _mm_load_ps(item.hi);
        bounds.grow(l, h);
        const __m128 c = _mm_mul_ps(_mm_add_ps(l, h), _mm_set1_ps(0.5f));
        centres.grow(c, c);
    }
    void grow(const Extent& e) { bounds.grow(e.bounds), centres.grow(e.centres); }
};

Extent extent_of(const std::vector<Item>& items, std::uint32_t begin, std::uint32_t end) {
    Extent e;
    for (std::uint32_t i = begin; i < end; ++i) e.grow(items[i]);
    return e;
}

class Builder {
  public:
    explicit Builder(std::vector<Item>& items) : items_(items) {}

    // Builds the subtree of items [begin, end), whose extent is `extent`, into `nodes` (its root
    // at the end of `nodes`, node indices relative to the start of `nodes`); `tasks` > 1 builds
    // second subtrees on threads of their own, that many at a time at most.
    std::uint32_t build(std::uint32_t begin, std::uint32_t end, const Extent& extent, int depth,
                        std::vector<BinaryNode>& nodes, int tasks) const {
        const auto index = static_cast<std::uint32_t>(nodes.size());
        nodes.push_back({});
        for (int a = 0; a < 3; ++a) {
            nodes[index].lo[a] = extent.bounds.lo_at(a);
            nodes[index].hi[a] = extent.bounds.hi_at(a);
        }
        const std::uint32_t count = end - begin;
        const auto make_leaf = [&] {
            nodes[index].offset = begin;
            nodes[index].count = count;
            return index;
        };
        if (count <= 2) return make_leaf();

        float centre_lo[3], centre_extent[3];
        int axis = 0;
        for (int a = 0; a < 3; ++a) {
            centre_lo[a] = extent.centres.lo_at(a);
            centre_extent[a] = extent.centres.hi_at(a) - centre_lo[a];
            if (centre_extent[a] > centre_extent[axis]) axis = a;
        }
        std::uint32_t mid = begin + count / 2;
        Extent first, second;
        bool known = false;  // whether first and second are the halves' extents
        if (centre_extent[axis] > 0 && depth < kSahDepth) {
            const auto split =
                split_by_area(begin, end, centre_lo, centre_extent, extent.bounds.surface_area());
            if (!split) return make_leaf();
            mid = split->mid;
            first = split->first;
            second = split->second;
            known = true;
        } else {
            if (count <= kMaxLeaf && centre_extent[axis] == 0) return make_leaf();
            std::nth_element(
                items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                [axis](const Item& a, const Item& b) { return a.centre(axis) < b.centre(axis); });
        }
        std::uint32_t second_index = 0;
        if (tasks > 1 && count >= kParallelBuild) {
            // The first subtree on this thread, the second on a new one into nodes of its own,
            // then appended after the first: node for node where the sequential build puts it.
            // fork_join brings an exception on either thread (std::bad_alloc) back to the caller.
            std::vector<BinaryNode> second_nodes;
            fork_join(
                [&] {
                    if (!known) first = extent_of(items_, begin, mid);
                    build(begin, mid, first, depth + 1, nodes, tasks - tasks / 2);
                },
                [&] {
                    if (!known) second = extent_of(items_, mid, end);
                    second_nodes.reserve(2 * (end - mid));
                    prefer_huge_pages(second_nodes);
                    build(mid, end, second, depth + 1, second_nodes, tasks / 2);
                });
            second_index = static_cast<std::uint32_t>(nodes.size());
            for (BinaryNode n : second_nodes) {
                if (n.count == 0) n.offset += second_index;
                nodes.push_back(n);
            }
        } else {
            if (!known) first = extent_of(items_, begin, mid), second = extent_of(items_, mid, end);
            build(begin, mid, first, depth + 1, nodes, 1);
            second_index = build(mid, end, second, depth + 1, nodes, 1);
        }
        nodes[index].offset = second_index;
        nodes[index].count = 0;
        return index;
    }

  private:
    struct Split {
        std::uint32_t mid;
        Extent first, second;
    };

    // Binned surface-area heuristic (Wald 2007) on every axis whose centres spread, in one pass:
    // a split costs area × triangles on each side, a leaf its triangles. Three axes cost little
    // more than one and make a tree in which rays meet fewer boxes and triangles. Partitions the
    // items at the cheapest split and returns it with the halves' extents, or nothing if a leaf
    // is cheaper.
    std::optional<Split> split_by_area(std::uint32_t begin, std::uint32_t end,
                                       const float (&centre_lo)[3], const float (&centre_extent)[3],
                                       double area) const {
        const std::uint32_t count = end - begin;
        // Bins hold boxes alone: the halves' centre boxes are gathered as the items are
        // partitioned, for the chosen axis only.
        struct Bin {
            Box bounds;
            std::uint32_t count = 0;
        };
        std::array<std::array<Bin, kBins>, 3> bins{};
        // An item's bin along each axis: its centre's offset in float, scaled in double (the
        // offset times kBins / extent stays finite however small the extent), cut to an
        // integer and clamped to the last bin. An axis without extent scales by 0.
        double to_bin[3] = {};
        for (int a = 0; a < 3; ++a) {
            if (centre_extent[a] > 0) to_bin[a] = kBins / static_cast<double>(centre_extent[a]);
        }
        const auto bin_of = [&](const Item& item, int a) {
            return std::min(kBins - 1,
                            static_cast<int>((item.centre(a) - centre_lo[a]) * to_bin[a]));
        };
        for (std::uint32_t i = begin; i < end; ++i) {
            const Item& item = items_[i];
            const __m128 l = _mm_load_ps(item.lo), h = _mm_load_ps(item.hi);
            for (int a = 0; a < 3; ++a) {
                Bin& bin = bins[a][bin_of(item, a)];
                bin.bounds.grow(l, h);
                ++bin.count;
            }
        }
        double best = std::numeric_limits<double>::infinity();
        int best_bin = 0, best_axis = -1;
        for (int a = 0; a < 3; ++a) {
            if (!(centre_extent[a] > 0)) continue;
            std::array<double, kBins> right_cost{};
            Box right;
            std::uint32_t right_count = 0;
            for (int b = kBins - 1; b > 0; --b) {
                right.grow(bins[a][b].bounds);
                right_count += bins[a][b].count;
                right_cost[b] = right.surface_area() * right_count;
            }
            Box left;
            std::uint32_t left_count = 0;
            for (int b = 0; b + 1 < kBins; ++b) {
                left.grow(bins[a][b].bounds);
                left_count += bins[a][b].count;
                const double cost = left.surface_area() * left_count + right_cost[b + 1];
                if (left_count > 0 && left_count < count && cost < best)
                    best = cost, best_bin = b, best_axis = a;
            }
        }
        // One box test costs about as much as one triangle test.
        if (best_axis < 0 || !(area * (count - 1) > best || count > kMaxLeaf)) return std::nullopt;
        // Partitioned from both ends (as std::partition does), each item's extent grown into
        // its half's on the way.
        Split split;
        std::uint32_t lo = begin, hi = end;
        while (true) {
            while (lo < hi && bin_of(items_[lo], best_axis) <= best_bin)
                split.first.grow(items_[lo++]);
            while (lo < hi && bin_of(items_[hi - 1], best_axis) > best_bin)
                split.second.grow(items_[--hi]);
            if (lo == hi) break;
            std::swap(items_[lo], items_[hi - 1]);
        }
        split.mid = lo;
        return split;
    }

    std::vector<Item>& items_;
};

}  // namespace

BinaryTree build_binary_tree(std::span<const Float3> positions,
                             std::span<const std::array<std::uint32_t, 3>> triangles, int threads) {
    std::vector<Item> items;
    items.reserve(triangles.size());
    prefer_huge_pages(items);
    items.resize(triangles.size());
    Extent all;
    for (std::uint32_t i = 0; i < items.size(); ++i) {
        Item& item = items[i];
        item.triangle = i;
        item.unused = 0;
        for (int a = 0; a < 3; ++a) item.lo[a] = item.hi[a] = positions[triangles[i][0]][a];
        for (int k = 1; k < 3; ++k) {
            const Float3& p = positions[triangles[i][k]];
            for (int a = 0; a < 3; ++a) {
                item.lo[a] = std::min(item.lo[a], p[a]);
                item.hi[a] = std::max(item.hi[a], p[a]);
            }
        }
        all.grow(item);
    }
    BinaryTree tree;
    // At most 2n - 1 nodes: reserved, the pages not used are never touched.
    tree.nodes.reserve(2 * items.size());
    prefer_huge_pages(tree.nodes);
    // More tasks than threads, so that the unequal halves SAH splits make still keep every
    // thread busy to the end.
    Builder(items).build(0, static_cast<std::uint32_t>(items.size()), all, 0, tree.nodes,
                         threads > 1 ? 4 * threads : 1);
    tree.order.reserve(items.size());
    prefer_huge_pages(tree.order);
    tree.order.resize(items.size());
    for (std::size_t i = 0; i < items.size(); ++i) tree.order[i] = items[i].triangle;
    return tree;
}

}  // namespace drt
