#include "drt/bvh.h"

#include <algorithm>
#include <array>

namespace drt {

namespace {

constexpr std::uint32_t kMaxLeafSize = 4;
constexpr int kBins = 16;
constexpr double kTraversalCost = 1.0;  // relative to one primitive test
// Past this depth nodes split at the median, which bounds the depth of any tree by
// kMedianDepth + log2(n) and so keeps the traversal stack below kStackSize.
constexpr int kMedianDepth = 64;
constexpr int kStackSize = 128;

Interval span(const Interval& a, const Interval& b) {
    return {std::min(a.min, b.min), std::max(a.max, b.max)};
}

// Slab test against a box; inv_dir holds 1/dir per axis (infinite for axis-parallel rays).
bool hits_box(const Bounds& b, const Vec3& origin, const Vec3& inv_dir, double t_min, double t_max) {
    for (int axis = 0; axis < 3; ++axis) {
        double t0 = (b.lo[axis] - origin[axis]) * inv_dir[axis];
        double t1 = (b.hi[axis] - origin[axis]) * inv_dir[axis];
        if (t0 > t1) std::swap(t0, t1);
        // NaN (0 * inf for an origin on a slab plane) must not shrink the interval.
        if (t0 > t_min) t_min = t0;
        if (t1 < t_max) t_max = t1;
        if (t_min > t_max) return false;
    }
    return true;
}

}  // namespace

Bvh::Bvh(const std::vector<std::unique_ptr<Object>>& objects) {
    for (const auto& object : objects) {
        const auto pieces = object->motion_bounds();
        if (pieces.empty()) unbounded_.push_back(object.get());
        for (const auto& piece : pieces) primitives_.push_back({object.get(), piece.bounds, piece.time});
    }
    if (!primitives_.empty()) {
        nodes_.reserve(2 * primitives_.size());
        build(0, static_cast<std::uint32_t>(primitives_.size()), 0);
    }
}

std::uint32_t Bvh::build(std::uint32_t begin, std::uint32_t end, int depth) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    Bounds bounds, centres;
    Interval time{kInfinity, -kInfinity};
    for (std::uint32_t i = begin; i < end; ++i) {
        bounds.grow(primitives_[i].bounds);
        centres.grow(primitives_[i].bounds.centre());
        time = span(time, primitives_[i].time);
    }
    nodes_[index].bounds = bounds;
    nodes_[index].time = time;
    const std::uint32_t count = end - begin;

    // Binned surface-area heuristic over the centroids' longest axis.
    const Vec3 extent = centres.extent();
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const double lo = centres.lo[axis], width = extent[axis];
    std::uint32_t mid = begin;
    if (count > kMaxLeafSize && width > 0 && depth < kMedianDepth) {
        std::array<Bounds, kBins> bin_bounds{};
        std::array<std::uint32_t, kBins> bin_counts{};
        auto bin_of = [&](const Primitive& p) {
            const int b = static_cast<int>(kBins * (p.bounds.centre()[axis] - lo) / width);
            return std::clamp(b, 0, kBins - 1);
        };
        for (std::uint32_t i = begin; i < end; ++i) {
            const int b = bin_of(primitives_[i]);
            bin_bounds[b].grow(primitives_[i].bounds);
            ++bin_counts[b];
        }
        double best_cost = kInfinity;
        int best_split = -1;
        for (int split = 1; split < kBins; ++split) {
            Bounds left, right;
            std::uint32_t n_left = 0, n_right = 0;
            for (int b = 0; b < split; ++b) left.grow(bin_bounds[b]), n_left += bin_counts[b];
            for (int b = split; b < kBins; ++b) right.grow(bin_bounds[b]), n_right += bin_counts[b];
            if (n_left == 0 || n_right == 0) continue;
            const double cost = kTraversalCost + (left.surface_area() * n_left +
                                                  right.surface_area() * n_right) /
                                                     bounds.surface_area();
            if (cost < best_cost) best_cost = cost, best_split = split;
        }
        if (best_split > 0 && best_cost < count) {
            mid = static_cast<std::uint32_t>(
                std::partition(primitives_.begin() + begin, primitives_.begin() + end,
                               [&](const Primitive& p) { return bin_of(p) < best_split; }) -
                primitives_.begin());
        } else if (count > 255) {
            mid = median_split(begin, end, axis);  // a leaf must stay small enough to count in 16 bits
        }
    } else if (count > kMaxLeafSize && (depth >= kMedianDepth || count > 255)) {
        mid = median_split(begin, end, axis);
    }
    if (mid == begin || mid == end) {
        nodes_[index].offset = begin;
        nodes_[index].count = static_cast<std::uint16_t>(count);
        return index;
    }
    build(begin, mid, depth + 1);
    const std::uint32_t second = build(mid, end, depth + 1);
    nodes_[index].offset = second;
    nodes_[index].count = 0;
    nodes_[index].axis = static_cast<std::uint8_t>(axis);
    return index;
}

std::uint32_t Bvh::median_split(std::uint32_t begin, std::uint32_t end, int axis) {
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(primitives_.begin() + begin, primitives_.begin() + mid,
                     primitives_.begin() + end, [&](const Primitive& a, const Primitive& b) {
                         return a.bounds.centre()[axis] < b.bounds.centre()[axis];
                     });
    return mid;
}

template <bool kAnyHit>
std::optional<Intersection> Bvh::traverse(const Ray& ray, Interval range) const {
    std::optional<Intersection> nearest;
    for (const Object* object : unbounded_) {
        if (auto t = object->intersect(ray, range)) {
            nearest = Intersection{*t, object};
            if constexpr (kAnyHit) return nearest;
            range.max = *t;
        }
    }
    if (nodes_.empty()) return nearest;

    const Vec3 inv_dir{1.0 / ray.dir.x, 1.0 / ray.dir.y, 1.0 / ray.dir.z};
    const bool negative[3] = {ray.dir.x < 0, ray.dir.y < 0, ray.dir.z < 0};
    std::array<std::uint32_t, kStackSize> stack;
    int top = 0;
    std::uint32_t current = 0;
    while (true) {
        const Node& node = nodes_[current];
        if (node.time.contains(ray.time) &&
            hits_box(node.bounds, ray.origin, inv_dir, range.min, range.max)) {
            if (node.count > 0) {
                for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
                    const Primitive& p = primitives_[i];
                    if (!p.time.contains(ray.time)) continue;
                    if (auto t = p.object->intersect(ray, range)) {
                        nearest = Intersection{*t, p.object};
                        if constexpr (kAnyHit) return nearest;
                        range.max = *t;
                    }
                }
            } else {
                // Visit the child nearer along the split axis first, so hits shrink the range early.
                const std::uint32_t first = current + 1, second = node.offset;
                if (negative[node.axis]) {
                    stack[top++] = first;
                    current = second;
                } else {
                    stack[top++] = second;
                    current = first;
                }
                continue;
            }
        }
        if (top == 0) break;
        current = stack[--top];
    }
    return nearest;
}

std::optional<Intersection> Bvh::intersect(const Ray& ray, Interval range) const {
    return traverse<false>(ray, range);
}

bool Bvh::occluded(const Ray& ray, Interval range) const {
    return traverse<true>(ray, range).has_value();
}

std::size_t Bvh::depth() const {
    std::size_t deepest = 0;
    std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0, 1}};
    if (nodes_.empty()) return 0;
    while (!stack.empty()) {
        const auto [node, d] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, d);
        if (nodes_[node].count == 0) {
            stack.push_back({node + 1, d + 1});
            stack.push_back({nodes_[node].offset, d + 1});
        }
    }
    return deepest;
}

}  // namespace drt
