#include "drt/accel/bvh.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "drt/accel/triangle_mesh.h"
#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "drt/util/float_rounding.h"

namespace drt {

namespace {

constexpr std::uint32_t kMaxLeafSize = 4;
// Above this many primitives a node splits even where the SAH would rather keep a leaf
// (primitives piled on one spot), so no leaf grows without bound.
constexpr std::uint32_t kMaxSahLeafSize = 16;
constexpr int kBins = 16;
constexpr double kTraversalCost = 1.0;  // relative to one primitive test
// Past this depth nodes split at the median, which bounds the depth of any tree by
// kMedianDepth + log2(n) and so keeps the traversal stack below kStackSize.
constexpr int kMedianDepth = 64;
// Slab distances are rounded; stretching the far one by a few ulps keeps a box whose surface a
// ray grazes from being missed (pbrt's 1 + 2γ₃).
constexpr double kFarStretch = 1.0 + 4.0 * std::numeric_limits<double>::epsilon();

Interval span(const Interval& a, const Interval& b) {
    return {std::min(a.min, b.min), std::max(a.max, b.max)};
}

}  // namespace

// What every box test of one ray shares. A box is read as box[0..2] = lo, box[3..5] = hi, so
// the slab the ray enters first on each axis is picked by index instead of by a swap.
struct Bvh::RayData {
    double origin[3];
    double inv_dir[3];  // 1/dir, infinite for an axis-parallel ray
    int near[3], far[3];
    double time;

    explicit RayData(const Ray& ray) : time(ray.time) {
        const double d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
        const double o[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
        for (int a = 0; a < 3; ++a) {
            origin[a] = o[a];
            inv_dir[a] = 1.0 / d[a];
            // signbit, not < 0: a direction of -0 has an inverse of -inf and must enter at hi.
            const bool negative = std::signbit(d[a]);
            near[a] = negative ? 3 + a : a;
            far[a] = negative ? a : 3 + a;
        }
    }

    // Whether the ray is in the box at its time within [t_min, t_max]; `entry` is where it enters.
    bool enters(const Node& node, double t_min, double t_max, double& entry) const {
        if (!(node.time_min <= time && time <= node.time_max)) return false;
        for (int a = 0; a < 3; ++a) {
            const double t_near = (node.box[near[a]] - origin[a]) * inv_dir[a];
            const double t_far = (node.box[far[a]] - origin[a]) * inv_dir[a] * kFarStretch;
            // Written so that NaN (0 * inf for an origin on a slab plane) leaves the bound alone.
            t_min = t_near > t_min ? t_near : t_min;
            t_max = t_far < t_max ? t_far : t_max;
        }
        entry = t_min;
        return t_min <= t_max;
    }
};

Bvh::Bvh(const std::vector<std::unique_ptr<Object>>& objects) {
    std::vector<Primitive> pieces;
    std::vector<Build> items;
    auto add = [&](const Primitive& p, const Bounds& bounds) {
        items.push_back({bounds, p.time, static_cast<std::uint32_t>(pieces.size())});
        pieces.push_back(p);
    };
    for (const auto& owned : objects) {
        const auto object = static_cast<std::uint32_t>(objects_.size());
        objects_.push_back(owned.get());
        const Shapes shapes = owned->shapes();
        for (std::uint32_t i = 0; i < shapes.planes.size(); ++i) {
            const PlaneShape& plane = shapes.planes[i];
            planes_.push_back({plane.point, plane.normal, max_abs_component(plane.point),
                               dot(plane.point, plane.normal), object, i});
        }
        for (const MeshShape& shape : shapes.meshes) {
            if (shape.mesh->triangle_count() == 0) continue;
            // A part of a shared mesh already entered is only told which object it is.
            if (shape.part != MeshShape::kWhole) {
                const auto shared = std::ranges::find_if(meshes_, [&](const MeshData& m) {
                    return m.mesh == shape.mesh && !m.part_objects.empty();
                });
                if (shared != meshes_.end()) {
                    if (shape.part >= shared->part_objects.size())
                        shared->part_objects.resize(shape.part + 1, kNoObject);
                    shared->part_objects[shape.part] = object;
                    continue;
                }
            }
            const Bounds local = shape.mesh->bounds();
            const auto index = static_cast<std::uint32_t>(meshes_.size());
            meshes_.push_back({shape.mesh, local.centre()});
            if (shape.part != MeshShape::kWhole) {
                const auto parts = shape.mesh->parts();
                meshes_.back().part_objects.assign(
                    std::max(*std::ranges::max_element(parts), shape.part) + 1, kNoObject);
                meshes_.back().part_objects[shape.part] = object;
            }
            const double radius = length(local.extent()) * 0.5;
            const MotionPath& path = *shape.path;
            if (!path.moves()) {
                const Vec3 o = path.at(0);
                add({o, radius, {-kInfinity, kInfinity}, object, index, Kind::kStillMesh, 0},
                    Bounds{o + local.lo, o + local.hi});
                continue;
            }
            for (std::size_t k = 0; k < path.segment_count(); ++k) {
                const PathSegment segment = path.segment(k);
                const auto motion = static_cast<std::uint32_t>(motions_.size());
                motions_.push_back(segment);
                add({segment.from, radius, path.segment_time(k), object, index, Kind::kMovingMesh,
                     motion},
                    Bounds{segment.from + local.lo, segment.from + local.hi}.grow(
                        Bounds{segment.to + local.lo, segment.to + local.hi}));
            }
        }
        for (std::uint32_t i = 0; i < shapes.spheres.size(); ++i) {
            const MotionPath& path = *shapes.spheres[i].path;
            const double radius = shapes.spheres[i].radius;
            const Vec3 r{radius, radius, radius};
            if (!path.moves()) {
                const Vec3 c = path.at(0);
                add({c, radius, {-kInfinity, kInfinity}, object, i, Kind::kStillSphere, 0},
                    Bounds{}.grow(c - r).grow(c + r));
                continue;
            }
            // One piece per segment, bounded over the segment's time span only.
            for (std::size_t k = 0; k < path.segment_count(); ++k) {
                const PathSegment segment = path.segment(k);
                const auto motion = static_cast<std::uint32_t>(motions_.size());
                motions_.push_back(segment);
                add({segment.from, radius, path.segment_time(k), object, i, Kind::kMovingSphere,
                     motion},
                    Bounds{}
                        .grow(segment.from - r)
                        .grow(segment.from + r)
                        .grow(segment.to - r)
                        .grow(segment.to + r));
            }
        }
    }
    if (items.empty()) return;
    nodes_.reserve(2 * items.size());
    build(items, 0, static_cast<std::uint32_t>(items.size()), 0);
    primitives_.reserve(items.size());
    for (const Build& item : items) primitives_.push_back(pieces[item.primitive]);
}

std::uint32_t Bvh::build(std::vector<Build>& items, std::uint32_t begin, std::uint32_t end,
                         int depth) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    Bounds bounds, centres;
    Interval time{kInfinity, -kInfinity};
    for (std::uint32_t i = begin; i < end; ++i) {
        bounds.grow(items[i].bounds);
        centres.grow(items[i].bounds.centre());
        time = span(time, items[i].time);
    }
    {
        Node& node = nodes_[index];
        for (int a = 0; a < 3; ++a) node.box[a] = bounds.lo[a], node.box[3 + a] = bounds.hi[a];
        node.time_min = to_float_down(time.min);
        node.time_max = to_float_up(time.max);
    }
    const std::uint32_t count = end - begin;

    // Binned surface-area heuristic over the centroids' longest axis.
    const Vec3 extent = centres.extent();
    const int axis =
        extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const double lo = centres.lo[axis], width = extent[axis];
    auto by_centre = [&](const Build& a, const Build& b) {
        return a.bounds.centre()[axis] < b.bounds.centre()[axis];
    };
    std::uint32_t mid = begin;
    if (count > kMaxLeafSize && width > 0 && depth < kMedianDepth) {
        std::array<Bounds, kBins> bin_bounds{};
        std::array<std::uint32_t, kBins> bin_counts{};
        auto bin_of = [&](const Build& item) {
            // Clamped before the conversion, which would be undefined for an infinite or NaN
            // position (bounds of astronomically large objects); NaN goes to bin 0.
            const double b = kBins * (item.bounds.centre()[axis] - lo) / width;
            return b < kBins - 1 ? (b > 0 ? static_cast<int>(b) : 0) : kBins - 1;
        };
        for (std::uint32_t i = begin; i < end; ++i) {
            const int b = bin_of(items[i]);
            bin_bounds[b].grow(items[i].bounds);
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
            const double cost =
                kTraversalCost + (left.surface_area() * n_left + right.surface_area() * n_right) /
                                     bounds.surface_area();
            if (cost < best_cost) best_cost = cost, best_split = split;
        }
        if (best_split > 0 && best_cost < count) {
            mid = static_cast<std::uint32_t>(
                std::partition(items.begin() + begin, items.begin() + end,
                               [&](const Build& item) { return bin_of(item) < best_split; }) -
                items.begin());
        }
    }
    if ((mid == begin || mid == end) && count > kMaxLeafSize &&
        (depth >= kMedianDepth || count > kMaxSahLeafSize)) {
        mid = begin + count / 2;
        std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                         by_centre);
    }
    if (mid == begin || mid == end) {
        nodes_[index].offset = begin;
        nodes_[index].count = count;
        return index;
    }
    build(items, begin, mid, depth + 1);
    const std::uint32_t second = build(items, mid, end, depth + 1);
    nodes_[index].offset = second;
    nodes_[index].count = 0;
    return index;
}

// Still spheres, the common case, inline; a moving sphere's segment and meshes out of line.
template <bool kAnyHit>
inline std::optional<double> Bvh::hit(const Primitive& p, const Ray& ray, double origin_scale,
                                      Interval range, std::uint32_t skip, std::uint32_t& triangle,
                                      Vec2& uv) const {
    if (p.kind == Kind::kStillSphere) {
        return intersect_sphere(p.centre, p.radius, ray, origin_scale, range);
    }
    return hit_segment<kAnyHit>(p, ray, origin_scale, range, skip, triangle, uv);
}

template <bool kAnyHit>
std::optional<double> Bvh::hit_segment(const Primitive& p, const Ray& ray, double origin_scale,
                                       Interval range, std::uint32_t skip, std::uint32_t& triangle,
                                       Vec2& uv) const {
    if (!p.time.contains(ray.time)) return std::nullopt;
    if (p.kind == Kind::kMovingSphere) {
        return intersect_sphere(motions_[p.motion].at(ray.time), p.radius, ray, origin_scale,
                                range);
    }
    const Vec3 origin = p.kind == Kind::kStillMesh ? p.centre : motions_[p.motion].at(ray.time);
    const TriangleMesh& mesh = *meshes_[p.index].mesh;
    if constexpr (kAnyHit) {
        // A shadow ray needs no nearest hit: the mesh's first hit found ends its traversal.
        if (!mesh.occluded(ray_in_mesh(ray, origin), range, skip)) return std::nullopt;
        return range.max;
    } else {
        const auto hit = mesh.intersect(ray_in_mesh(ray, origin), range, skip);
        if (!hit) return std::nullopt;
        triangle = hit->triangle;
        uv = {hit->b.b1, hit->b.b2};
        return hit->t;
    }
}

std::uint32_t Bvh::object_of(const Primitive& p, std::uint32_t triangle) const {
    if (!is_mesh(p.kind)) return p.object;
    const MeshData& data = meshes_[p.index];
    if (data.part_objects.empty()) return p.object;
    const std::uint32_t object = data.part_objects[data.mesh->parts()[triangle]];
    return object == kNoObject ? p.object : object;
}

template <bool kAnyHit>
bool Bvh::traverse(const Ray& ray, Interval& range, std::uint64_t planes, Leaving leaving,
                   Nearest& nearest) const {
    const double origin_scale = max_abs_component(ray.origin);
    bool found = false;
    for (std::size_t i = 0; i < planes_.size(); ++i) {
        if (i < 64 && (planes >> i & 1) == 0) continue;
        const PlaneData& plane = planes_[i];
        if (auto t = intersect_plane(plane.point, plane.normal, plane.point_scale, ray,
                                     origin_scale, range)) {
            if constexpr (kAnyHit) return true;
            found = true, nearest = {plane.object, plane.index, {}};
            range.max = *t;
        }
    }
    if (nodes_.empty()) return found;
    // Tests a leaf's primitives; true when an any-hit query is answered.
    // Written only by primitives whose test yields them: a mesh's triangle and coordinates.
    std::uint32_t triangle = 0;
    Vec2 uv;
    auto leaf = [&](const Node& node) {
        for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
            const Primitive& p = primitives_[i];
            const std::uint32_t skip =
                leaving.piece == i ? leaving.triangle : TriangleMesh::kNoTriangle;
            if (auto t = hit<kAnyHit>(p, ray, origin_scale, range, skip, triangle, uv)) {
                if constexpr (kAnyHit) return true;
                found = true;
                nearest = is_mesh(p.kind) ? Nearest{object_of(p, triangle), triangle, uv, i}
                                          : Nearest{p.object, p.index, uv};
                range.max = *t;
            }
        }
        return false;
    };
    // A few primitives in all (a tree that is one leaf): testing them is cheaper than their box.
    if (nodes_[0].count > 0) {
        return leaf(nodes_[0]) || found;
    }

    const RayData r(ray);
    double entry = 0;
    if (!r.enters(nodes_[0], range.min, range.max, entry)) return found;
    struct Pending {
        std::uint32_t node;
        double entry;
    };
    std::array<Pending, kStackSize> stack;
    int top = 0;
    std::uint32_t current = 0;
    while (true) {
        const Node& node = nodes_[current];
        if (node.count == 0) {
            // Both children are tested here, and the nearer entered first, so that a hit in it
            // shrinks the range before the farther one is even opened.
            const std::uint32_t first = current + 1, second = node.offset;
            double t_first = 0, t_second = 0;
            const bool in_first = r.enters(nodes_[first], range.min, range.max, t_first);
            const bool in_second = r.enters(nodes_[second], range.min, range.max, t_second);
            if (in_first && in_second) {
                const bool second_nearer = t_second < t_first;
                stack[top++] = second_nearer ? Pending{first, t_first} : Pending{second, t_second};
                current = second_nearer ? second : first;
                continue;
            }
            if (in_first || in_second) {
                current = in_first ? first : second;
                continue;
            }
        } else if (leaf(node)) {
            return true;  // an any-hit query answered
        }
        // Next pending node the ray still reaches before the nearest hit so far.
        do {
            if (top == 0) return found;
            --top;
        } while (stack[top].entry > range.max);
        current = stack[top].node;
    }
}

std::optional<Hit> Bvh::intersect(const Ray& ray, Interval range, Leaving leaving) const {
    Nearest nearest;
    if (!traverse<false>(ray, range, kAllPlanes, leaving, nearest)) return std::nullopt;
    return Hit{range.max, objects_[nearest.object], nearest.index, nearest.uv, nearest.piece};
}

bool Bvh::occluded(const Ray& ray, Interval range, std::uint64_t planes, Leaving leaving) const {
    Nearest unused;
    return traverse<true>(ray, range, planes, leaving, unused);
}

bool Bvh::occluded_by(const Ray& ray, Interval range, std::uint64_t planes,
                      std::span<const std::uint32_t> primitives, Leaving leaving) const {
    const double origin_scale = max_abs_component(ray.origin);
    for (std::uint64_t left = planes; left != 0; left &= left - 1) {
        const PlaneData& p = planes_[static_cast<std::size_t>(std::countr_zero(left))];
        if (intersect_plane(p.point, p.normal, p.point_scale, ray, origin_scale, range))
            return true;
    }
    for (std::size_t i = 64; i < planes_.size(); ++i) {
        const PlaneData& p = planes_[i];
        if (intersect_plane(p.point, p.normal, p.point_scale, ray, origin_scale, range))
            return true;
    }
    std::uint32_t triangle = 0;
    Vec2 uv;
    for (const std::uint32_t i : primitives) {
        const std::uint32_t skip =
            leaving.piece == i ? leaving.triangle : TriangleMesh::kNoTriangle;
        if (hit<true>(primitives_[i], ray, origin_scale, range, skip, triangle, uv)) return true;
    }
    return false;
}

}  // namespace drt
