#include "drt/mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>

namespace drt {

namespace {

// sin and cos of an angle in degrees, exact at multiples of 90 degrees, so that a quarter turn
// maps a float vertex onto float coordinates instead of leaving 6e-17 crumbs.
SinCos sincos_degrees(double degrees) {
    const double turns = degrees / 90;
    if (turns == std::round(turns)) {
        switch (static_cast<long long>(std::fmod(std::round(turns), 4.0) + 4) % 4) {
            case 0:
                return {0, 1};
            case 1:
                return {1, 0};
            case 2:
                return {0, -1};
            default:
                return {-1, 0};
        }
    }
    const double radians = degrees * (kPi / 180);
    return {std::sin(radians), std::cos(radians)};
}

Vec3 rotate_x(const Vec3& v, SinCos r) {
    return {v.x, v.y * r.cos - v.z * r.sin, v.y * r.sin + v.z * r.cos};
}
Vec3 rotate_y(const Vec3& v, SinCos r) {
    return {v.x * r.cos + v.z * r.sin, v.y, v.z * r.cos - v.x * r.sin};
}
Vec3 rotate_z(const Vec3& v, SinCos r) {
    return {v.x * r.cos - v.y * r.sin, v.x * r.sin + v.y * r.cos, v.z};
}

Vec3 to_vec3(const std::array<float, 3>& f) {
    return {f[0], f[1], f[2]};
}

// The angle at corner a of triangle a, b, c.
double corner_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 u = b - a, v = c - a;
    return std::atan2(length(cross(u, v)), dot(u, v));
}

// Slab test of a box against a ray with precomputed reciprocal direction. A NaN from 0 · ∞ (the
// origin on a slab the ray runs along) leaves the interval as it was, which keeps the box.
// The far end is widened by the test's own rounding (Pharr, Jakob & Humphreys, section 6.8.2 of
// the 4th edition), so that a box never misses a ray its triangle meets.
struct BoxRay {
    Vec3 origin, inv_dir;

    bool hits(const std::array<float, 3>& lo, const std::array<float, 3>& hi, Interval range,
              double& entry) const {
        double near = range.min, far = range.max;
        for (int k = 0; k < 3; ++k) {
            double t0 = (lo[k] - origin[k]) * inv_dir[k];
            double t1 = (hi[k] - origin[k]) * inv_dir[k];
            if (t0 > t1) std::swap(t0, t1);
            near = std::max(near, t0);
            far = std::min(far, t1 * (1 + 2 * detail::gamma(3)));
        }
        entry = near;
        return near <= far;
    }
};

constexpr std::uint32_t kMaxLeaf = 8;
constexpr int kBins = 16;
// Past this depth a node is split at its median, so that no path is longer than 40 + log2(n)
// nodes, which the traversal's stack holds.
constexpr int kSahDepth = 40;
constexpr int kStackSize = 128;
// Subtrees of fewer triangles are built on the thread that reached them: a thread costs about
// what building a few thousand triangles does.
constexpr std::uint32_t kParallelBuild = 16384;

}  // namespace

Vec3 MeshTransform::apply(const Vec3& v) const {
    return rotate(v * scale);
}

Vec3 MeshTransform::rotate(const Vec3& v) const {
    return rotate_z(
        rotate_y(rotate_x(v, sincos_degrees(rotate_degrees.x)), sincos_degrees(rotate_degrees.y)),
        sincos_degrees(rotate_degrees.z));
}

struct TriangleMesh::BuildItem {
    Float3 lo, hi;
    std::uint32_t triangle;

    float centre(int axis) const { return (lo[axis] + hi[axis]) * 0.5f; }
};

TriangleMesh::TriangleMesh(const ObjMesh& obj, const MeshTransform& transform, bool smooth,
                           int build_threads) {
    std::vector<Vec3> placed(obj.positions.size());
    Bounds box;
    for (std::size_t i = 0; i < placed.size(); ++i) {
        placed[i] = transform.apply(obj.positions[i]);
        box.grow(placed[i]);
    }
    origin_ = box.empty() ? Vec3{} : box.centre();

    // A vertex is a position, or with smooth shading a position and the file's normal there:
    // one index buffer serves both.
    const bool file_normals =
        smooth && std::ranges::any_of(obj.normal_indices,
                                      [](std::uint32_t n) { return n != ObjMesh::kNoNormal; });
    std::vector<std::uint32_t> vertex_position;  // vertex -> position
    std::vector<std::uint32_t> vertex_normal;    // vertex -> file normal or kNoNormal
    std::unordered_map<std::uint64_t, std::uint32_t> vertex_of;
    const auto vertex = [&](std::uint32_t p, std::uint32_t n) {
        if (!file_normals) return p;
        const auto [it, added] = vertex_of.try_emplace(
            (std::uint64_t{p} << 32) | n, static_cast<std::uint32_t>(vertex_position.size()));
        if (added) vertex_position.push_back(p), vertex_normal.push_back(n);
        return it->second;
    };
    if (!file_normals) {
        vertex_position.resize(placed.size());
        std::iota(vertex_position.begin(), vertex_position.end(), 0u);
    }

    const auto local = [&](std::uint32_t p) {
        const Vec3 v = placed[p] - origin_;
        const Float3 f{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
        if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
            throw std::domain_error("vertex " + std::to_string(p + 1) +
                                    " is beyond single precision (±3.4e38) once transformed");
        }
        return f;
    };
    std::vector<Float3> local_positions(placed.size());
    for (std::uint32_t p = 0; p < placed.size(); ++p) local_positions[p] = local(p);

    const std::size_t corners = obj.position_indices.size();
    triangles_.reserve(corners / 3);
    for (std::size_t c = 0; c < corners; c += 3) {
        const std::uint32_t* p = &obj.position_indices[c];
        const Vec3 a = to_vec3(local_positions[p[0]]), b = to_vec3(local_positions[p[1]]),
                   d = to_vec3(local_positions[p[2]]);
        if (cross(b - a, d - a) == Vec3{}) {
            ++dropped_;
            continue;
        }
        const std::uint32_t* n = &obj.normal_indices[c];
        triangles_.push_back({vertex(p[0], n[0]), vertex(p[1], n[1]), vertex(p[2], n[2])});
    }

    positions_.resize(vertex_position.size());
    for (std::size_t v = 0; v < positions_.size(); ++v)
        positions_[v] = local_positions[vertex_position[v]];

    if (smooth) {
        // Angle-weighted face normals (Thürmer & Wüthrich 1998): unlike area weights they do not
        // change when a neighbouring face is split in two.
        std::vector<Vec3> computed(placed.size());
        for (const auto& t : triangles_) {
            const std::array<std::uint32_t, 3> p{vertex_position[t[0]], vertex_position[t[1]],
                                                 vertex_position[t[2]]};
            const Vec3 a = to_vec3(local_positions[p[0]]), b = to_vec3(local_positions[p[1]]),
                       c = to_vec3(local_positions[p[2]]);
            const Vec3 n = normalize(cross(b - a, c - a));
            computed[p[0]] += n * corner_angle(a, b, c);
            computed[p[1]] += n * corner_angle(b, c, a);
            computed[p[2]] += n * corner_angle(c, a, b);
        }
        normals_.resize(positions_.size());
        for (std::size_t v = 0; v < normals_.size(); ++v) {
            Vec3 n = computed[vertex_position[v]];
            if (file_normals && vertex_normal[v] != ObjMesh::kNoNormal) {
                const Vec3 given = transform.rotate(obj.normals[vertex_normal[v]]);
                if (max_abs_component(given) > 0) n = given;
            }
            // A normal that cancelled out stays zero; shading falls back to the face's.
            const double m = max_abs_component(n);
            if (m > 0) n = normalize(n / m);
            normals_[v] = {static_cast<float>(n.x), static_cast<float>(n.y),
                           static_cast<float>(n.z)};
        }
    }
    build_hierarchy(build_threads > 0
                        ? build_threads
                        : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

Vec3 TriangleMesh::position(std::uint32_t vertex) const {
    return to_vec3(positions_[vertex]);
}

std::array<Vec3, 3> TriangleMesh::corners(std::uint32_t triangle) const {
    const auto& t = triangles_[triangle];
    return {position(t[0]), position(t[1]), position(t[2])};
}

Vec3 TriangleMesh::geometric_normal(std::uint32_t triangle) const {
    const auto [a, b, c] = corners(triangle);
    const Vec3 n = cross(b - a, c - a);
    // Scaled first: the cross product of a tiny triangle can underflow when squared.
    return normalize(n / max_abs_component(n));
}

Vec3 TriangleMesh::shading_normal(std::uint32_t triangle, const Barycentrics& b) const {
    if (normals_.empty()) return geometric_normal(triangle);
    const auto& t = triangles_[triangle];
    const Vec3 n = to_vec3(normals_[t[0]]) * b.b0 + to_vec3(normals_[t[1]]) * b.b1 +
                   to_vec3(normals_[t[2]]) * b.b2;
    // Opposite normals at the corners can cancel: the face's own normal is then the answer.
    if (!(dot(n, n) > 1e-12)) return geometric_normal(triangle);
    return normalize(n);
}

Vec3 TriangleMesh::lifted(std::uint32_t triangle, const Barycentrics& b) const {
    const auto& t = triangles_[triangle];
    const auto [p0, p1, p2] = corners(triangle);
    const Vec3 p = p0 * b.b0 + p1 * b.b1 + p2 * b.b2;
    // Each corner's tangent plane lifts the point onto it where the point is below it; the
    // lifts are blended by the barycentrics, which gives a smooth surface through the corners.
    Vec3 lift;
    const double weights[3] = {b.b0, b.b1, b.b2};
    const Vec3 vertices[3] = {p0, p1, p2};
    for (int k = 0; k < 3; ++k) {
        const Vec3 n = to_vec3(normals_[t[k]]);
        lift -= n * (weights[k] * std::min(0.0, dot(p - vertices[k], n)));
    }
    return p + lift;
}

Bounds TriangleMesh::bounds() const {
    if (nodes_.empty()) return {};
    return {to_vec3(nodes_[0].lo), to_vec3(nodes_[0].hi)};
}

std::size_t TriangleMesh::bytes() const {
    return positions_.capacity() * sizeof(Float3) + normals_.capacity() * sizeof(Float3) +
           triangles_.capacity() * sizeof(triangles_[0]) + nodes_.capacity() * sizeof(Node) +
           sizeof(*this);
}

void TriangleMesh::build_hierarchy(int threads) {
    if (triangles_.empty()) return;
    std::vector<BuildItem> items(triangles_.size());
    for (std::uint32_t i = 0; i < items.size(); ++i) {
        BuildItem& item = items[i];
        item.triangle = i;
        item.lo = item.hi = positions_[triangles_[i][0]];
        for (int k = 1; k < 3; ++k) {
            const Float3& p = positions_[triangles_[i][k]];
            for (int a = 0; a < 3; ++a) {
                item.lo[a] = std::min(item.lo[a], p[a]);
                item.hi[a] = std::max(item.hi[a], p[a]);
            }
        }
    }
    // At most 2n - 1 nodes; a leaf holds two triangles or more unless it is alone.
    nodes_.reserve(items.size());
    // More tasks than threads, so that the unequal halves SAH splits make still keep every
    // thread busy to the end.
    build(items, 0, static_cast<std::uint32_t>(items.size()), 0, nodes_,
          threads > 1 ? 4 * threads : 1);
    nodes_.shrink_to_fit();
    std::vector<std::array<std::uint32_t, 3>> ordered(triangles_.size());
    for (std::size_t i = 0; i < items.size(); ++i) ordered[i] = triangles_[items[i].triangle];
    triangles_ = std::move(ordered);
}

std::uint32_t TriangleMesh::build(std::vector<BuildItem>& items, std::uint32_t begin,
                                  std::uint32_t end, int depth, std::vector<Node>& nodes,
                                  int tasks) {
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
        std::vector<Node> second_nodes;
        {
            const std::jthread worker([&] {
                second_nodes.reserve(end - mid);
                build(items, mid, end, depth + 1, second_nodes, tasks / 2);
            });
            build(items, begin, mid, depth + 1, nodes, tasks - tasks / 2);
        }
        second = static_cast<std::uint32_t>(nodes.size());
        for (Node n : second_nodes) {
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

template <bool kAnyHit>
std::optional<MeshHit> TriangleMesh::traverse(const Ray& ray, Interval range,
                                              std::uint64_t* tests) const {
    if (nodes_.empty()) return std::nullopt;
    const ShearedRay sheared(ray);
    const BoxRay box_ray{ray.origin, {1 / ray.dir.x, 1 / ray.dir.y, 1 / ray.dir.z}};
    std::optional<MeshHit> best;
    // Nodes still to visit, with where the ray enters their boxes: one that a nearer hit has
    // since put out of range is skipped.
    struct Pending {
        std::uint32_t node;
        double entry;
    };
    std::array<Pending, kStackSize> stack;
    int top = 0;
    double entry = 0;
    if (!box_ray.hits(nodes_[0].lo, nodes_[0].hi, range, entry)) return std::nullopt;
    std::uint32_t node = 0;
    for (;;) {
        const Node& n = nodes_[node];
        if (n.count > 0) {
            if (tests) *tests += n.count;
            for (std::uint32_t i = n.offset; i < n.offset + n.count; ++i) {
                const auto [a, b, c] = corners(i);
                if (const auto hit = intersect_triangle(sheared, a, b, c, range)) {
                    best = MeshHit{hit->t, i, hit->b};
                    if constexpr (kAnyHit) return best;
                    range.max = hit->t;
                }
            }
        } else {
            const std::uint32_t first = node + 1, second = n.offset;
            double first_entry = 0, second_entry = 0;
            const bool hit_first =
                box_ray.hits(nodes_[first].lo, nodes_[first].hi, range, first_entry);
            const bool hit_second =
                box_ray.hits(nodes_[second].lo, nodes_[second].hi, range, second_entry);
            if (hit_first && hit_second) {
                const bool first_nearer = first_entry <= second_entry;
                stack[top++] =
                    first_nearer ? Pending{second, second_entry} : Pending{first, first_entry};
                node = first_nearer ? first : second;
                continue;
            }
            if (hit_first || hit_second) {
                node = hit_first ? first : second;
                continue;
            }
        }
        do {
            if (top == 0) return best;
            --top;
        } while (stack[top].entry > range.max);
        node = stack[top].node;
    }
}

std::optional<MeshHit> TriangleMesh::intersect(const Ray& ray, Interval range) const {
    return traverse<false>(ray, range);
}

bool TriangleMesh::occluded(const Ray& ray, Interval range) const {
    return traverse<true>(ray, range).has_value();
}

std::uint64_t TriangleMesh::triangle_tests(const Ray& ray, Interval range, bool any_hit) const {
    std::uint64_t tests = 0;
    if (any_hit) {
        traverse<true>(ray, range, &tests);
    } else {
        traverse<false>(ray, range, &tests);
    }
    return tests;
}

namespace {

std::vector<Vec3> shifted(std::vector<Vec3> points, const Vec3& by) {
    for (Vec3& p : points) p += by;
    return points;
}

}  // namespace

Mesh::Mesh(std::shared_ptr<const TriangleMesh> mesh, const std::vector<Vec3>& translations,
           const Material& material, SurfaceDetail detail)
    : Object(material, std::move(detail)),
      mesh_(std::move(mesh)),
      path_(shifted(translations, mesh_->origin())) {}

std::optional<Hit> Mesh::intersect(const Ray& ray, Interval range) const {
    const auto hit = mesh_->intersect(ray_in_mesh(ray, path_.at(ray.time)), range);
    if (!hit) return std::nullopt;
    return Hit{hit->t, this, hit->triangle, {hit->b.b1, hit->b.b2}};
}

Object::SurfacePoint Mesh::locate(const Ray& ray, const Hit& hit) const {
    const Vec3 origin = path_.at(ray.time);
    const auto [a, b, c] = mesh_->corners(hit.primitive);
    const Barycentrics w{1 - hit.uv.x - hit.uv.y, hit.uv.x, hit.uv.y};
    // From the barycentrics rather than ray.at(t): on the triangle's plane to rounding in the
    // mesh's own coordinates, whatever distance the ray came from.
    const Vec3 point = origin + (a * w.b0 + b * w.b1 + c * w.b2);
    const Vec3 normal = mesh_->geometric_normal(hit.primitive);
    // Textures and bumps stay where the mesh is at time 0, the present: world coordinates for
    // a mesh that does not move.
    const Vec3 fixed = point - (origin - path_.at(0));
    const Vec3 shading = mesh_->shading_normal(hit.primitive, w);
    if (!mesh_->smooth()) return {point, normal, shading, fixed, fixed};
    return {point, normal, shading,
            fixed, fixed,  LightStart{origin + mesh_->lifted(hit.primitive, w), shading}};
}

}  // namespace drt
